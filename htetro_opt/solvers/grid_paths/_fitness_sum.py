"""The exact maximum of Cheng et al. 2020's fitness sum over one leg: the reference of the hTetro-GA's pick.

The hTetro-GA's output solution (its "multi-objective based solution", ``pick="balanced"``) is the
goal-reaching leading-front member with the largest sum ``f_gr + f_t + f_sm + f_sf`` of the paper's
eqs. 3–6 (:class:`~htetro_opt.problems.CommandPathProblem`). :func:`plan_max_fitness_sum` finds the
command sequence that maximises that sum exactly, under the GA's own objective: the same simulator,
child termination (a child stops at its first invalid command or its first arrival on the goal, and
is scored on the commands it executed) and t_max (the GA's default l_p,max, ``default_max_length``,
unless given). No GA run can have a goal-reaching member with a larger sum; the maximiser's time says
what the paper's objective asks of a path.

Why it is exact
---------------
A chromosome scores as its executed prefix, so the maximum over chromosomes that reach the goal is
the maximum over valid sequences c_1 … c_l (local ids; poses p_1 … p_l) whose first visit to the
goal is p_l. Such a sequence scores f_gr = 1 and

    sum = 4 − [ Σ_k dur(c_k) / t_max + Σ_{k≥2} [c_k ≠ c_{k−1}] / (l − 1) + Σ_k D(p_k) / (l λ_sp) ]

(no f_sm term for l = 1, where f_sm = 1), with D ≥ 0 the per-pose danger of eq. 6. For a fixed l the
bracket is a sum of per-command costs that depend only on (c_{k−1}, c_k, p_k), and whether c_k may
follow depends only on (p_{k−1}, c_k) and the obstacles' clock t0 + k − 1 (the simulator's check,
moving obstacles included). So the least bracket over the sequences of exactly l commands is a
shortest path through l layers of (pose, last command) nodes:
V_k(p′, c′) = min over (p, c) with next(p, c′) = p′ of V_{k−1}(p, c) + [c ≠ c′] / (l − 1)
+ dur(c′) / t_max + D(p′) / (l λ_sp). For each (p, c′) the inner minimum is
min(V_{k−1}(p, c′), min_c V_{k−1}(p, c) + 1 / (l − 1)): when the pose's best last command is c′
itself, keeping it is no worse than changing; otherwise the best other command is the pose's best.
A layer thus costs O(poses × commands). Child termination constrains the layers: the goal is
forbidden before the l-th (the child would have stopped there), and only the goal counts in the
l-th; a command that leaves the pose unchanged (``sO`` on an O) is a gene like any other and counts
in l.

Over lengths: f_sm ≤ 1, f_sf ≤ 1 and a sequence of l commands takes at least l × d_min (the shortest
command's duration), so nothing of l or more commands sums more than 4 − l d_min / t_max. Lengths
l = 1, 2, … are solved in turn until that bound is no larger than the best sum found; the best is
then the maximum over every length. The bound closes by ⌊t_max (4 − S_T) / d_min⌋ + 1, S_T being the
sum of the minimum-time plan (itself such a sequence). Lengths at which the goal cannot be first
reached at all (a forward reachability pass over the same layers) are skipped; a goal that the
exact planner's time-expanded search cannot reach has no such sequence at all.
"""

from __future__ import annotations

import math
import time as _time
from collections.abc import Sequence

import numpy as np

from htetro_opt._validation import check_int
from htetro_opt.errors import PlanningError
from htetro_opt.model.commands import SEED000_COMMANDS, Timing
from htetro_opt.model.robot import Pose, as_pose
from htetro_opt.model.simulate import Simulator, check_memory, size_text
from htetro_opt.model.workspace import Workspace
# The programme's kernels live among the operators: the hTetro-GA's balanced polish solves it over windows.
from htetro_opt.operators.commands._sum_dp import first_arrivals, min_bracket, usable_table
from htetro_opt.problems.command_path import SAFETY_COEFFICIENT, CommandPathProblem
from htetro_opt.problems.names import FITNESS_NAMES
from htetro_opt.solvers.grid_paths._exact import plan_exact
from htetro_opt.solvers.grid_paths._ga import _max_length
from htetro_opt.solvers.grid_paths._result import Plan, check_map, finish_plan, prepare

__all__ = ["MAX_FITNESS_SUM_METHOD", "plan_max_fitness_sum"]

MAX_FITNESS_SUM_METHOD = "max-fitness-sum"
"""The ``method`` of the plans :func:`plan_max_fitness_sum` returns."""

_SUM_TOLERANCE = 1e-9  # the DP's and the problem's float sums of the same plan differ in the last bits


def _parents_bytes(length: int, sim: Simulator) -> int:
    return length * sim.n_poses * sim.n_commands * 4


def plan_max_fitness_sum(
    workspace: Workspace | Simulator,
    start: Pose,
    goal: Pose,
    *,
    max_length: int | None = None,
    t0: int = 0,
    max_commands: int | None = None,
    commands: Sequence[str] | None = None,
    timing: Timing | None = None,
    clearance: float = 0.0,
) -> Plan:
    """The plan of one leg that maximises Cheng et al. 2020's fitness sum f_gr + f_t + f_sm + f_sf, exactly.

    The maximum is over every goal-reaching command sequence as the hTetro-GA scores it
    (:class:`~htetro_opt.problems.CommandPathProblem`: child termination at the first arrival on the
    goal, t_max = ``max_length`` × t_translation), so no member of any GA run on the leg has a larger
    sum. The module docstring proves the method: a dynamic programme over exactly l commands for each
    length l, until the bound 4 − l d_min / t_max can no longer beat the best sum found.

    Parameters
    ----------
    workspace : Workspace or Simulator
        The map, or an already compiled simulator (then ``commands``, ``timing`` and ``clearance``
        are taken from it).
    start, goal : Pose
        The leg's start (collision-free at time ``t0``) and goal.
    max_length : int, optional, keyword-only
        l_p,max, which sets t_max. Default: the hTetro-GA's own for this leg
        (:func:`~htetro_opt.solvers.grid_paths.default_max_length`, from the leg's exact minimum time).
    t0 : int, keyword-only
        Commands executed before the leg (the clock of moving obstacles).
    max_commands : int, optional, keyword-only
        The work cap: the longest sequence length the search may examine (the search solves each
        length l in O(l × poses × commands)). The bound is sure to close by ⌊t_max (4 − S_T) /
        d_min⌋ + 2 commands, with S_T the sum of the leg's minimum-time plan (a goal-reaching child,
        so the best sum is at least S_T); that is the default, and a larger cap changes nothing.
    commands : sequence of str, optional, keyword-only
        The command alphabet (default: Cheng et al. 2020's thirteen commands, as the GA's).
    timing : Timing, optional, keyword-only
    clearance : float, keyword-only
        δ in cells (MODEL.md §4).

    Returns
    -------
    Plan
        A plan of the largest sum (where several tie, the first found at the fewest commands: the
        sum is the proven quantity, not which of its plans is returned). ``method`` is
        ``"max-fitness-sum"``. ``info`` holds ``f_gr``, ``f_t``, ``f_sm``, ``f_sf`` and
        ``fitness_sum`` (computed by the problem from the plan's replay, not by the search),
        ``max_length``, ``t_max``, ``exact_time`` (the leg's minimum time T*), ``lengths_searched`` (the
        longest length solved before the bound closed) and ``n_commands``. ``reached`` is False (and
        the fitnesses None) when no sequence reaches the goal.

    Raises
    ------
    ParameterError
        If ``max_length`` or ``max_commands`` is not a positive integer, ``t0`` is negative, or
        ``workspace`` is neither a Workspace nor a Simulator.
    ConfigurationError
        If the start (at ``t0``) or the goal collides or lies outside the map, or is not a pose.
    PlanningError
        If some command takes no time (the bound over lengths would never close), the bound has not
        closed within ``max_commands``, or the search's tables would not fit the memory budget.

    Examples
    --------
    >>> occupancy = np.zeros((6, 6), dtype=bool)
    >>> occupancy[2, 3] = True  # the cell (x, y) = (3, 2)
    >>> plan = plan_max_fitness_sum(Workspace(occupancy), Pose(1, 1, "O", 0), Pose(3, 4, "O", 0), max_length=6)
    >>> plan.tokens, plan.time, round(plan.info["fitness_sum"], 4)  # one change, and away from the obstacle
    (['y+', 'y+', 'y+', 'x+', 'x+'], 5.0, 2.5194)
    """
    began = _time.perf_counter()
    check_map(workspace)
    t0 = check_int(t0, "t0", minimum=0)
    max_length = check_int(max_length, "max_length (l_p,max)", minimum=1, allow_none=True)
    max_commands = check_int(max_commands, "max_commands", minimum=1, allow_none=True)
    start, goal = as_pose(start, "start"), as_pose(goal, "goal")
    sim, _, (start_id, goal_id) = prepare(workspace, [start, goal], t0=t0,
                                          commands=commands if commands is not None else SEED000_COMMANDS,
                                          timing=timing, clearance=clearance)
    durations = np.ascontiguousarray(sim.durations[: sim.n_commands], dtype=np.float64)
    shortest = float(durations.min())
    if not shortest > 0:
        raise PlanningError("the exact fitness-sum search needs every command to take a positive time: with a "
                            "command of zero duration, longer sequences are never ruled out")
    period = sim.workspace.period if sim.workspace.moving else 1
    exact = plan_exact(sim, [start, goal], t0=t0)
    length_budget = max_length if max_length is not None else _max_length(exact, sim, start, goal)
    problem = CommandPathProblem(sim, start, goal, max_length=length_budget, t0=t0)
    t_max = problem.t_max
    work_bytes = period * sim.n_poses * sim.n_commands + 2 * sim.n_poses * sim.n_commands * 8 + 24 * sim.n_poses
    check_memory(work_bytes, f"the fitness-sum search's tables ({period} phases of {sim.n_poses} poses)",
                 "use a smaller map or coarser cells")
    info = {"max_length": length_budget, "t_max": t_max, "exact_time": exact.time if exact.reached else None,
            "lengths_searched": 0, "n_commands": 0, **{name: None for name in FITNESS_NAMES}, "fitness_sum": None}
    if not exact.reached:  # the exact planner's time-expanded search: no sequence of any length arrives
        return finish_plan(sim, np.empty(0, dtype=np.int64), start_id, t0=t0, method=MAX_FITNESS_SUM_METHOD,
                           leg_ends=[], failed_leg=0, began=began, info=info)
    if start_id == goal_id:  # a child standing on its goal stops before its first command
        return _finish(problem, sim, np.empty(0, dtype=np.int64), start_id, t0, 4.0, began, info)
    # The minimum-time plan is a goal-reaching child (with positive durations it cannot pass the goal
    # earlier), so the best sum is at least its sum S_T and the bound closes by t_max (4 − S_T) / d_min.
    # (One more length than that: the search's float sums may differ from the problem's in the last bits.)
    fastest_sum = float(problem.fitness(problem.simulate([exact.commands]))[0].sum())
    closes_by = math.floor(t_max * (4.0 - fastest_sum) / shortest) + 2
    cap = closes_by if max_commands is None else min(max_commands, closes_by)

    target = np.ascontiguousarray(sim.next[: sim.n_poses, : sim.n_commands])
    usable = usable_table(sim)
    phase0 = t0 % period
    danger = np.ascontiguousarray(problem._pose_danger[: sim.n_poses])
    arrivals = np.zeros(cap + 1, dtype=np.bool_)
    first_arrivals(target, usable, phase0, start_id, goal_id, arrivals)
    value, scratch = (np.full((sim.n_poses, sim.n_commands), np.inf) for _ in range(2))  # min_bracket keeps them inf
    active, touched, stamp = (np.zeros(sim.n_poses, dtype=np.int64) for _ in range(3))
    no_parents = np.zeros((1, 1, 1), dtype=np.int32)
    no_pruning = np.zeros(sim.n_poses, dtype=np.int64)  # every pose may still reach the goal in the layers left

    def weights(length: int) -> tuple[float, float, float]:
        return 1.0 / t_max, (1.0 / (length - 1) if length > 1 else 0.0), 1.0 / (length * SAFETY_COEFFICIENT)

    best_sum, best_length, length = -math.inf, 0, 0
    while True:
        length += 1
        if 4.0 - length * shortest / t_max <= best_sum:  # no sequence this long or longer can sum more
            break
        if length > cap:
            found = (f"the best sum so far is {best_sum:.6f} at {best_length} commands" if best_length
                     else "no goal-reaching sequence found yet")
            raise PlanningError(f"the exact fitness-sum search did not close within max_commands={cap} commands "
                                f"({found}; longer sequences could still sum up to "
                                f"{4.0 - length * shortest / t_max:.6f}): raise max_commands")
        if not arrivals[length]:
            continue
        bracket, _ = min_bracket(target, usable, phase0, durations, danger, start_id, -1, goal_id, -1, goal_id,
                                 length, *weights(length), no_pruning, value, scratch, active, touched, stamp,
                                 no_parents, False)
        if 4.0 - bracket > best_sum:  # strictly: of equal sums, the fewest commands
            best_sum, best_length = 4.0 - bracket, length
    info["lengths_searched"] = length - 1

    check_memory(_parents_bytes(best_length, sim) + work_bytes,
                 f"the fitness-sum search's back pointers ({best_length} layers of {sim.n_poses} poses; "
                 f"{size_text(_parents_bytes(best_length, sim))})", "use a smaller map or coarser cells")
    # not initialised: min_bracket writes a back pointer wherever it sets a value, and the walk below
    # reads only those (untouched pages of an empty array cost no memory)
    parents = np.empty((best_length, sim.n_poses, sim.n_commands), dtype=np.int32 if
                       sim.n_poses * sim.n_commands < 2**31 else np.int64)
    bracket, command = min_bracket(target, usable, phase0, durations, danger, start_id, -1, goal_id, -1, goal_id,
                                   best_length, *weights(best_length), no_pruning, value, scratch, active, touched,
                                   stamp, parents, True)
    local = [command]
    pose = goal_id
    for k in range(best_length - 1, 0, -1):  # walk the back pointers from the goal's last command
        key = int(parents[k, pose, local[-1]])
        pose, previous = divmod(key, sim.n_commands)
        local.append(previous)
    global_ids = sim.command_ids[np.array(local[::-1], dtype=np.int64)]
    return _finish(problem, sim, global_ids, start_id, t0, 4.0 - bracket, began, info)


def _finish(problem: CommandPathProblem, sim: Simulator, global_ids: np.ndarray, start_id: int, t0: int,
            searched_sum: float, began: float, info: dict) -> Plan:
    """The plan, re-validated in the simulator, with the problem's own fitnesses of its replay; a
    disagreement with the search's sum is an internal error."""
    result = problem.simulate([global_ids])
    if not (result.reached[0] and result.executed[0] == len(global_ids)):
        raise PlanningError("internal error: the max-fitness-sum plan does not reach the goal at its last command "
                            "under the GA's child termination")
    fitness = problem.fitness(result)[0]
    total = float(fitness.sum())
    if abs(total - searched_sum) > _SUM_TOLERANCE:
        raise PlanningError(f"internal error: the max-fitness-sum plan sums {total!r} in the problem, the search "
                            f"said {searched_sum!r}")
    info.update({name: float(v) for name, v in zip(FITNESS_NAMES, fitness)})
    info.update(fitness_sum=total, n_commands=len(global_ids))
    return finish_plan(sim, global_ids, start_id, t0=t0, method=MAX_FITNESS_SUM_METHOD,
                       leg_ends=[len(global_ids)], failed_leg=-1, began=began, info=info)
