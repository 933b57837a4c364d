"""Cheng et al. 2020's planner: a command-chromosome GA per roadmap leg (the paper's configuration loop).

:func:`plan_ga` runs one optimisation per leg of the roadmap, each starting where (and when, for
moving obstacles) the previous leg's selected solution ended. The algorithm is the paper's
hTetro-GA by default, or one of pymoo's own (NSGA-II, NSGA-III, SMS-EMOA, AGE-MOEA) with the same
problem and operators. From each leg's final population it selects, as the paper does, the
leading-front individual with the largest sum of the four fitnesses (the "multi-objective based
solution") and the best-f_t, best-f_sm and best-f_sf ones; ``pick`` says which of the four the plan
chains (the next leg continues from it), the largest sum by default. With ``seed_exact`` each leg's
exact minimum-time plan joins its initial population.
"""

from __future__ import annotations

import time as _time
from typing import Mapping, Sequence

import numpy as np
from pymoo.optimize import minimize

from htetro_opt._progress import check_progress, report
from htetro_opt._validation import check_bool, check_int, check_seed, check_time_limit
from htetro_opt.algorithms import (
    CONVERGENCE_MEASURES,
    PICKS,
    ConvergenceRecorder,
    FrontConvergence,
    leading_front,
    make_algorithm,
    select_solutions,
)
from htetro_opt.errors import ParameterError
from htetro_opt.model.commands import SEED000_COMMANDS, Timing
from htetro_opt.model.robot import Pose
from htetro_opt.model.simulate import Simulator
from htetro_opt.model.workspace import Workspace, grid_distance
from htetro_opt.problems.command_path import CommandPathProblem
from htetro_opt.solvers.grid_paths._exact import plan_exact
from htetro_opt.solvers.grid_paths._result import FrontMember, LegResult, Plan, finish_plan, prepare
from htetro_opt.solvers.grid_paths._spec import GA_PATIENCE, SPEC

__all__ = ["plan_ga", "default_max_length", "DEFAULT_MAX_LENGTH"]


def _members(problem: CommandPathProblem, X: np.ndarray, F: np.ndarray) -> list[FrontMember]:
    """Front members of the rows of ``X`` (objectives ``F``), from one batch simulation."""
    result = problem.simulate([x[0] for x in X])
    return [FrontMember(commands=result.prefix(i), fitness=-np.asarray(F[i], dtype=float),
                        time=float(result.time[i]), reached=bool(result.reached[i]), poses=result.poses(i))
            for i in range(len(X))]


_DEFAULTS = SPEC.defaults("htetro-ga")  # the task's defaults, declared once in its spec

DEFAULT_MAX_LENGTH = 100
"""The paper's l_p,max, the least default of :func:`plan_ga`'s ``max_length``."""

_HEADROOM = 1.5  # t_max over the leg's exact minimum time, at least (see default_max_length)


def default_max_length(workspace: Workspace | Simulator, start: Pose, goal: Pose, *, t0: int = 0) -> int:
    """l_p,max for one leg, from its exact minimum time T*: the least multiple of
    :data:`DEFAULT_MAX_LENGTH` whose time budget t_max = l_p,max × t_translation is at least 1.5 T*.

    Cheng et al. 2020 use 100 on their maps and 200 on the spiral, whose optimum (112 s) exceeds 100 s:
    with t_max below T* every path has f_t < 0, and the initial chromosomes (Algorithm 1 fills t_max
    with translations) are too short to get anywhere near the goal. This rule gives the paper's 100
    on its other maps (T* ≤ 40 s) and its 200 on the spiral, and grows with the map. T* is the exact
    planner's (:func:`~htetro_opt.solvers.grid_paths.plan_exact`, from the leg's start at time ``t0``,
    moving obstacles included; 5 ms to 0.4 s on the bundled 24 × 24 maps). When the leg has no path
    at all: the larger of 100 and twice the 4-connected grid distance between the leg's B2 cells (the
    map's free cell count where even that is infinite).

    Parameters
    ----------
    workspace : Workspace or Simulator
        The map (Cheng et al. 2020's commands), or the GA's simulator.
    start, goal : Pose
    t0 : int, keyword-only
        Commands executed before the leg (the clock of moving obstacles).

    Examples
    --------
    >>> default_max_length(Workspace(np.zeros((60, 60), dtype=bool)), Pose(1, 1, "O", 0), Pose(50, 40, "O", 0))
    200
    """
    return _max_length(plan_exact(workspace, [start, goal], t0=t0), workspace, start, goal)


def _max_length(exact: Plan, workspace: Workspace | Simulator, start: Pose, goal: Pose) -> int:
    """:func:`default_max_length` from the leg's exact plan."""
    translation = (workspace.timing if isinstance(workspace, Simulator) else Timing()).translation
    if exact.reached:
        budget = _HEADROOM * exact.time / translation
        return DEFAULT_MAX_LENGTH * max(1, int(np.ceil(budget / DEFAULT_MAX_LENGTH - 1e-9)))
    ws = workspace.workspace if isinstance(workspace, Simulator) else workspace
    distance = grid_distance(ws, (goal.x, goal.y))[start.y, start.x]
    if not np.isfinite(distance):
        distance = int((~ws.occupancy).sum())
    return max(DEFAULT_MAX_LENGTH, int(np.ceil(2 * distance)))


def _check_reference(point) -> tuple[float, ...]:
    try:
        values = tuple(float(v) for v in point)
    except (TypeError, ValueError):
        values = ()
    if len(values) != 4 or not all(np.isfinite(values)):
        raise ParameterError(f"hv_reference must be four finite numbers (a point in F = −fitness), got {point!r}")
    return values


def _additions_of(algorithm) -> tuple[str, ...]:
    """The additions of ours an algorithm runs with: the hTetro-GA's own, or the mating steps ours add to
    pymoo's (the conservative offspring set, the re-planning)."""
    if hasattr(algorithm, "additions"):
        return algorithm.additions
    from htetro_opt.algorithms import ConservativeMating, ReplanMating

    found, mating = [], algorithm.mating
    while isinstance(mating, (ConservativeMating, ReplanMating)):
        found.append("conservative" if isinstance(mating, ConservativeMating) else "replanning")
        mating = mating.mating
    return tuple(sorted(found))


def _reporter(progress, leg: int, legs: int, max_gen: int):
    """The recorder's per-generation hook that reports to ``progress``."""
    if progress is None:
        return None

    def on_generation(generation: int, best_f_t: float | None, reached: bool) -> None:
        where = f"leg {leg + 1}/{legs}: " if legs > 1 else ""
        best = f"best f_t {best_f_t:.3f}" if best_f_t is not None else "goal not reached yet"
        report(progress, generation, max_gen, where + best)

    return on_generation


def plan_ga(
    workspace: Workspace | Simulator,
    roadmap: Sequence[Pose],
    *,
    algorithm: str = "htetro-ga",
    pop_size: int = _DEFAULTS["pop_size"],
    max_gen: int = _DEFAULTS["max_gen"],
    patience: int | None = None,
    convergence: str = _DEFAULTS["convergence"],
    max_length: int | None = None,
    seed=_DEFAULTS["seed"],
    sampling_weights: Mapping[str, float] | None = None,
    commands: Sequence[str] | None = None,
    timing: Timing | None = None,
    clearance: float = 0.0,
    verbose: bool = False,
    progress=None,
    hv_reference=None,
    replan_window: int | None = None,
    replan_members: int | None = None,
    seed_exact: bool = _DEFAULTS["seed_exact"],
    pick: str = _DEFAULTS["pick"],
    reach_share: float | None = None,
    conservative: bool | None = None,
    reach_patience: int | None = None,
    polish_window: int | None = None,
    time_limit: float | None = None,
    additions=None,
) -> Plan:
    """Plan through a roadmap with a command-chromosome GA, one optimisation per leg.

    Parameters
    ----------
    workspace : Workspace or Simulator
    roadmap : sequence of Pose
        Start first, goal last, at least two configurations.
    algorithm : str, keyword-only
        One of :data:`~htetro_opt.algorithms.GA_ALGORITHMS`: ``"htetro-ga"`` (the paper's hTetro-GA
        with our additions), ``"htetro-ga-paper"`` (as published), or pymoo's ``"nsga2"``,
        ``"nsga3"``, ``"smsemoa"``, ``"agemoea"``.
    pop_size : int, keyword-only
        n_pop.
    max_gen, patience : int, keyword-only
        Termination (:class:`~htetro_opt.algorithms.FrontConvergence`): at most ``max_gen``
        generations per leg, or ``patience`` generations without improvement once the goal is reached
        (default 100 with ``convergence="best"``, 20 with ``"hypervolume"``; ``"htetro-ga-paper"``: 10,
        our reading of the paper's "convergence of the solution",
        :data:`~htetro_opt.solvers.grid_paths._spec.PAPER_PATIENCE`).
    convergence : {"best", "hypervolume"}, keyword-only
        What counts as an improvement (:class:`~htetro_opt.algorithms.FrontConvergence`'s ``measure``):
        a rise of the best f_t, f_sm, f_sf or fitness sum among the goal-reaching individuals (the
        default), or of the best f_t or of the reaching front's hypervolume in the fixed box [0, 1]³
        (:func:`~htetro_opt.algorithms.reaching_hypervolume`) by more than 1e-5. Measured on four
        24 × 24 maps × 5 seeds (benchmarks/README.md), ``"hypervolume"`` with patience 20 ends the legs
        in half the generations with the same best time, and a front whose hypervolume is 3.7 %
        smaller on average (16 % at worst): the front keeps gaining smoothness and safety slowly for
        hundreds of generations.
    max_length : int, optional, keyword-only
        l_p,max, the length of the initial chromosomes and, through t_max, the scale of f_t (the
        paper: 100, 200 for its spiral map). ``"htetro-ga-paper"``: 100 by default
        (:data:`~htetro_opt.solvers.grid_paths._spec.PAPER_MAX_LENGTH`). Otherwise by default, per
        leg, from the leg's exact minimum time
        (:func:`default_max_length`: the paper's 100 and 200 on its maps, more on larger ones; ours: a
        fixed 100 is shorter than any path on a large map, and f_t goes negative).
    seed : None, int or numpy.random.Generator, keyword-only
        One seed for the whole run (each leg gets its own stream derived from it); the same int gives
        the same plan; None draws fresh entropy.
    sampling_weights : mapping, optional, keyword-only
        λ_mc of Algorithm 1.
    commands, timing, clearance : keyword-only
        As for :class:`~htetro_opt.model.Simulator` (commands default to Cheng et al. 2020's set).
    verbose : bool, keyword-only
        Print pymoo's per-generation log.
    progress : callable, optional, keyword-only
        ``progress(generation, max_gen, note)`` after every generation, the note giving the leg and
        the best f_t reached so far (see :mod:`htetro_opt._progress`).
    hv_reference : sequence of 4 float, optional, keyword-only
        Record each leg's hypervolume by generation against this reference point (in pymoo's
        minimisation space; see :class:`~htetro_opt.algorithms.ConvergenceRecorder`) as
        ``LegResult.hv_history``.
    replan_window, replan_members : int, optional, keyword-only
        The hTetro-GA's windowed exact re-planning: each generation a window of up to
        ``replan_window`` executed commands of the fastest goal-reaching member and of
        ``replan_members`` random reaching ones is replaced by the minimum-time path between its end
        poses (ours; :class:`~htetro_opt.operators.commands.CommandReplan`). None: the algorithm's
        default, W = 40 and 3 members for ``"htetro-ga"``, off for ``"htetro-ga-paper"``; 0 turns it
        off. pymoo's algorithms take the same step after their own mating when given a window
        (:class:`~htetro_opt.algorithms.ReplanMating`; off by default, K = 3 unless given).
    seed_exact : bool, keyword-only
        Put each leg's exact minimum-time plan (:func:`~htetro_opt.solvers.grid_paths.plan_exact`,
        from the leg's start at its time) into the leg's initial population, so that the GA spends its
        generations on the f_sm / f_sf trade-off; the plan's ``info["exact_times"]`` then lists each
        leg's optimum (None where a leg has no path). Off by default: the GA's own search is what is
        measured. Ours: ``"htetro-ga-paper"`` refuses it.
    pick : {"balanced", "fastest", "smoothest", "safest"}, keyword-only
        The solution each leg chains (:data:`~htetro_opt.algorithms.PICKS`): the leading-front member
        with the largest sum of the four fitnesses (the paper's multi-objective based solution; the
        paper also says "the smallest crowding distance", see :data:`~htetro_opt.algorithms.PICKS`),
        or the best f_t, f_sm or f_sf.
    reach_share : float, optional, keyword-only
        The hTetro-GA's cap on the goal-reaching section of its sort, a share in (0, 1] of n_pop
        (ours; :class:`~htetro_opt.algorithms.HTetroGA`). None: 1, no cap, the paper's sort (measured
        in benchmarks/README.md: 0.75 changes little once the re-planning is on). pymoo's algorithms
        refuse a share below 1.
    conservative : bool, optional, keyword-only
        pymoo's algorithms only: add the hTetro-GA's conservative offspring set (removal,
        rearrangement, shortcut) to their mating (:class:`~htetro_opt.algorithms.ConservativeMating`);
        None: off. Refused for the hTetro-GA, which always makes it.
    reach_patience : int, optional, keyword-only
        The hTetro-GA's reach repair (ours; :class:`~htetro_opt.algorithms.HTetroGA`): when no member
        reaches the goal and the best goal reachability has not risen for this many generations, the
        member nearest to the goal keeps its commands up to the pose nearest to the goal and gets the
        minimum-time path from there (:func:`~htetro_opt.operators.commands.reach_repair`). None: the
        algorithm's default, 100 for ``"htetro-ga"``, off for ``"htetro-ga-paper"``; 0 turns it off.
        Refused (unless 0) for pymoo's algorithms.
    polish_window : int, optional, keyword-only
        The hTetro-GA's balanced polish (ours; :class:`~htetro_opt.algorithms.HTetroGA`): when a leg's
        run ends, the leading-front member with the largest fitness sum (the ``"balanced"`` pick) has
        windows of up to this many commands of its path re-planned exactly for the largest sum, the
        whole path when it is no longer (:func:`~htetro_opt.operators.commands.polish_sum`). None: the
        algorithm's default, 40 for ``"htetro-ga"``, off for ``"htetro-ga-paper"``; 0 turns it off.
        Refused (unless 0) for pymoo's algorithms.
    additions : collection of str, optional, keyword-only
        The hTetro-GA's additions of ours switched on, exactly (names of
        :data:`~htetro_opt.algorithms.GA_ADDITIONS`): a window or patience above is the parameter of its
        addition, used when that one is on. None: the algorithm's own (``"htetro-ga"`` all of them,
        ``"htetro-ga-paper"`` none); pymoo's algorithms take none. The plan's ``info["additions"]`` lists
        those on (for pymoo's: ``conservative`` and ``replanning`` when their mating has them).
    time_limit : float, optional, keyword-only
        Seconds for the whole roadmap: past them each leg stops at its next generation (a leg started
        after the limit runs its initial population). None: no limit, the run ends by ``max_gen`` and
        ``patience`` alone and gives the same plan for the same seed on every machine; a limit that cuts
        the run short makes it depend on the machine's speed, and ``info["time_limited"]`` says so.

    Returns
    -------
    Plan
        ``method`` is the algorithm's name; ``info["pick"]`` the ``pick``; ``legs`` holds every
        leg's record (front, the four selected solutions, convergence). ``reached`` is False when a leg's final population holds
        no individual reaching its goal; the plan then holds the legs before it (not the failed
        leg's best attempt), ``failed_leg`` says which leg failed, and ``legs`` ends with its record.

    Raises
    ------
    PlanningError
        If the roadmap has fewer than two configurations.
    ConfigurationError
        If a configuration collides or lies outside the map.
    ParameterError
        If an option is out of range.

    Examples
    --------
    >>> ws = Workspace(np.zeros((10, 10), dtype=bool))
    >>> plan = plan_ga(ws, [Pose(2, 2, "O", 0), Pose(6, 5, "O", 0)], pop_size=20, max_gen=60,
    ...                max_length=20, seed=3)
    >>> plan.reached, plan.time
    (True, 7.0)
    """
    checked = make_algorithm(algorithm, pop_size, replan_window=replan_window, replan_members=replan_members,
                             reach_share=reach_share, conservative=conservative, reach_patience=reach_patience,
                             polish_window=polish_window, additions=additions)  # validates
    on = _additions_of(checked)
    seed_exact = check_bool(seed_exact, "seed_exact")
    if seed_exact and algorithm == "htetro-ga-paper":
        raise ParameterError("seed_exact puts the exact plan into the initial population, which the paper draws by its "
                             "Algorithm 1 alone: htetro-ga-paper refuses it, htetro-ga takes it")
    own = SPEC.method(algorithm).defaults  # the method's own defaults (htetro-ga-paper: the paper's l_p,max, patience)
    if patience is None:
        patience = own.get("patience")
    if max_length is None:
        max_length = own.get("max_length")
    if not isinstance(pick, str) or pick not in PICKS:
        raise ParameterError(f"pick must be one of {', '.join(PICKS)}, got {pick!r}")
    max_gen = check_int(max_gen, "max_gen", minimum=1)
    if not isinstance(convergence, str) or convergence not in CONVERGENCE_MEASURES:
        raise ParameterError(f"convergence must be one of {', '.join(CONVERGENCE_MEASURES)}, got {convergence!r}")
    patience = check_int(GA_PATIENCE[convergence] if patience is None else patience, "patience", minimum=1)
    max_length = check_int(max_length, "max_length", minimum=1, allow_none=True)
    progress = check_progress(progress)
    reference = None if hv_reference is None else _check_reference(hv_reference)
    seed = check_seed(seed)
    verbose = check_bool(verbose, "verbose")
    time_limit = check_time_limit(time_limit)
    began = _time.perf_counter()
    deadline = None if time_limit is None else began + time_limit
    time_limited = False
    sim, roadmap, ids = prepare(workspace, roadmap, commands=commands if commands is not None else SEED000_COMMANDS,
                                timing=timing, clearance=clearance)
    # One stream per leg, spawned from one seed: legs do not share draws, and the same seed gives the same plan.
    root = np.random.SeedSequence(seed.bit_generator.random_raw() if isinstance(seed, np.random.Generator) else seed)
    leg_seeds = root.generate_state(len(roadmap) - 1)
    chain: list[np.ndarray] = []
    legs: list[LegResult] = []
    leg_ends: list[int] = []
    exact_times: list[float | None] = []
    failed, start, t0 = -1, roadmap[0], 0
    for leg, goal in enumerate(roadmap[1:]):
        leg_began = _time.perf_counter()
        exact = plan_exact(sim, [start, goal], t0=t0) if seed_exact or max_length is None else None
        length = max_length if max_length is not None else _max_length(exact, sim, start, goal)
        problem = CommandPathProblem(sim, start, goal, max_length=length, t0=t0)
        include = []
        if seed_exact:
            exact_times.append(exact.time if exact.reached else None)
            include = [exact.commands] if exact.reached else []
        recorder = ConvergenceRecorder(leg_began, _reporter(progress, leg, len(roadmap) - 1, max_gen),
                                       hv_reference=reference)
        termination = FrontConvergence(max_gen=max_gen, patience=patience, measure=convergence, deadline=deadline)
        res = minimize(problem, make_algorithm(algorithm, pop_size, sampling_weights=sampling_weights,
                                               replan_window=replan_window, replan_members=replan_members,
                                               reach_share=reach_share, conservative=conservative,
                                               include=include, reach_patience=reach_patience,
                                               polish_window=polish_window, additions=additions),
                       termination, seed=int(leg_seeds[leg]), callback=recorder, verbose=verbose)
        time_limited = time_limited or bool(res.data.get("time_limited", False))
        X, F = res.pop.get("X"), res.pop.get("F")
        chosen = select_solutions(F)
        front_idx = leading_front(F)
        rows = np.array(list(chosen.values()), dtype=np.int64)
        selected = dict(zip(chosen, _members(problem, X[rows], F[rows])))
        reached = bool(selected["multi_objective"].reached)
        legs.append(LegResult(
            start=start, goal=goal, t0=t0, reached=reached,
            front=tuple(_members(problem, X[front_idx], F[front_idx])),
            selected=selected,
            reach_generation=recorder.reach_generation,
            reach_time_s=recorder.reach_time_s,
            generations=len(recorder.history),
            converged=bool(res.data.get("converged", False)),  # minimize runs a copy of the termination
            runtime_s=_time.perf_counter() - leg_began,
            history=np.array(recorder.history),
            hv_history=None if reference is None else np.array(recorder.hv_history),
        ))
        if not reached:
            failed = leg
            break
        chain.append(selected[PICKS[pick]].commands)
        t0 += len(chain[-1])
        leg_ends.append(t0)
        start = goal
    commands_all = np.concatenate(chain) if chain else np.empty(0, dtype=np.int64)
    info = {"pick": pick, "additions": list(on), **({"exact_times": exact_times} if seed_exact else {}),
            **({"time_limited": True} if time_limited else {})}
    return finish_plan(sim, commands_all, ids[0], method=algorithm, leg_ends=leg_ends, failed_leg=failed,
                       began=began, legs=legs, info=info)
