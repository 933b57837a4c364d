"""The balanced polish (ours, optional): windows of a path re-planned for the largest fitness sum.

The hTetro-GA returns, per leg, the goal-reaching leading-front member with the largest sum
f_gr + f_t + f_sm + f_sf (the paper's multi-objective based solution). Its windowed exact
re-planning (:mod:`.replan`) makes windows as fast as they can be; this is the same step under the
sum itself, applied once, to that member, when a run ends: a window [i, j) of the path's executed
commands is replaced by the m commands from the pose before it to the pose after it that maximise
the *whole path's* sum.

Why a window is an exact sub-problem. With the new total length L = l − (j − i) + m fixed, the sum
is 4 − (Σ dur / t_max + changes / (L − 1) + Σ D / (L λ_sp)) (see
:func:`~htetro_opt.solvers.grid_paths.plan_max_fitness_sum`), additive over commands: the commands
outside the window contribute fixed terms, and the window's best m commands are a fixed-length
layered programme over (pose, last command) (:func:`._sum_dp.min_bracket`) that starts after the
command before the window and pays for the change into the command after it, validity checked at
the obstacles' clock (the window's first command runs at clock t0 + i), the goal forbidden inside
the window except as the path's final pose (a child stops at its first arrival). Each m in a range
is solved; the lengths are bounded above by the sum's time term (a path of L commands sums at most
4 − (fixed time + m d_min) / t_max) and below by the fewest commands between the window's ends.

A candidate is kept only when the whole new sequence, simulated by the problem (independently of the
programme), is valid, reaches the goal and sums strictly more: on a moving-obstacle map a changed m
shifts the clock of the rest of the path, which the programme does not see. When the path has at
most ``window`` commands, the window is the whole path and m is unrestricted: the polish then
returns a plan of the leg's largest sum S* (the exact maximiser's programme, started from the
member's sum as the bound). Longer paths are tiled by windows of ``window`` commands starting every
``window // 2``, each allowed ``span`` commands more or fewer than it replaces, in rounds until a
round improves nothing (at most ``max_rounds``). The polish draws no random numbers: the same
member gives the same result.
"""

from __future__ import annotations

import math
import time

import numpy as np

from htetro_opt._validation import check_int
from htetro_opt.errors import ParameterError
from htetro_opt.model.simulate import memory_budget
from htetro_opt.operators.commands._sum_dp import (
    backward_steps,
    min_bracket,
    reverse_graph,
    usable_table,
)
from htetro_opt.problems.command_path import SAFETY_COEFFICIENT, CommandPathProblem

__all__ = ["POLISH_WINDOW", "POLISH_SPAN", "POLISH_ROUNDS", "polish_sum", "fitness_sum"]

POLISH_WINDOW = 40
"""W, the default window (commands): the hTetro-GA's re-planning window."""

POLISH_SPAN = 6
"""How many commands more or fewer than it replaces a window of a longer path may take (see the
module docstring; chosen by measurement, see :func:`polish_sum`)."""

POLISH_ROUNDS = 4
"""The most rounds of windows over a path longer than the window."""

_IMPROVEMENT = 1e-9  # the programme's and the problem's float sums of one plan differ in the last bits
_TRIES = 3  # candidate lengths re-solved and simulated per window (the best predicted first)


def fitness_sum(problem: CommandPathProblem, sequence: np.ndarray) -> tuple[float, bool]:
    """The problem's f_gr + f_t + f_sm + f_sf of one chromosome and whether it reaches the goal.

    Examples
    --------
    >>> from htetro_opt.model import Pose, Workspace, parse_commands
    >>> problem = CommandPathProblem(Workspace(np.zeros((12, 12), dtype=bool)), Pose(4, 4, "O", 0),
    ...                              Pose(6, 4, "O", 0), max_length=10)
    >>> fitness_sum(problem, parse_commands("x+,x+"))
    (3.8, True)
    """
    result = problem.simulate([np.asarray(sequence, dtype=np.int64)])
    return float(problem.fitness(result)[0].sum()), bool(result.reached[0])


class _Leg:
    """What the windows of one problem share: the transition and validity tables, the per-pose
    danger, the reverse graph for the lower bounds on lengths, and the programme's scratch arrays."""

    def __init__(self, problem: CommandPathProblem) -> None:
        sim = problem.simulator
        self.problem, self.sim = problem, sim
        self.target = np.ascontiguousarray(sim.next[: sim.n_poses, : sim.n_commands])
        self.usable = usable_table(sim)
        self.period = self.usable.shape[0]
        self.durations = np.ascontiguousarray(sim.durations[: sim.n_commands], dtype=np.float64)
        self.shortest = float(self.durations.min())
        self.danger = np.ascontiguousarray(problem._pose_danger[: sim.n_poses])
        self.indptr, self.indices = reverse_graph(self.target, self.usable)
        self.steps = np.empty(sim.n_poses, dtype=np.int64)
        self.value, self.scratch = (np.full((sim.n_poses, sim.n_commands), np.inf) for _ in range(2))  # kept inf
        self.active, self.touched, self.stamp = (np.zeros(sim.n_poses, dtype=np.int64) for _ in range(3))
        self.no_parents = np.zeros((1, 1, 1), dtype=np.int32)
        self.layer_bytes = sim.n_poses * sim.n_commands * 4

    def weights(self, length: int) -> tuple[float, float, float]:
        """The bracket's weights for a path of ``length`` commands: time, change, danger."""
        return (1.0 / self.problem.t_max, 1.0 / (length - 1) if length > 1 else 0.0,
                1.0 / (length * SAFETY_COEFFICIENT))

    def solve(self, start, start_command, end, end_command, phase0, m, total_length, parents):
        """The least bracket of the window's m commands in a path of ``total_length`` (see
        :func:`._sum_dp.min_bracket`), with back pointers into ``parents`` unless it is None."""
        return min_bracket(self.target, self.usable, phase0, self.durations, self.danger, start, start_command, end,
                           end_command, self.problem.goal_id, m, *self.weights(total_length), self.steps,
                           self.value, self.scratch, self.active, self.touched, self.stamp,
                           self.no_parents if parents is None else parents, parents is not None)

    def window_commands(self, start, start_command, end, end_command, phase0, m, total_length) -> np.ndarray:
        """The best m local commands of the window (the programme with back pointers)."""
        # not initialised: the programme writes a back pointer wherever it sets a value, and the walk
        # reads only those (the untouched pages of an empty array are never allocated)
        parents = np.empty((m, self.sim.n_poses, self.sim.n_commands), dtype=np.int32)
        _, command = self.solve(start, start_command, end, end_command, phase0, m, total_length, parents)
        local, pose = [command], end
        for k in range(m - 1, 0, -1):  # walk the back pointers from the window's last command
            pose, previous = divmod(int(parents[k, pose, local[-1]]), self.sim.n_commands)
            local.append(previous)
        return np.array(local[::-1], dtype=np.int64)


def _window(leg: _Leg, local: np.ndarray, poses: np.ndarray, i: int, j: int, current: float,
            span: int | None, deadline: float | None = None) -> tuple[np.ndarray, float] | None:
    """The best replacement of the window [i, j) of the path (local command ids ``local``, poses
    ``poses`` from the start), simulated: the new path's global ids and its sum, or None when no
    candidate sums more than ``current``. Past ``deadline`` (a ``time.perf_counter`` value) no further
    length is tried: the candidates found by then are the ones simulated."""
    if deadline is not None and time.perf_counter() >= deadline:
        return None
    problem, sim = leg.problem, leg.sim
    l = len(local)
    start, end = int(poses[i]), int(poses[j])
    start_command = int(local[i - 1]) if i > 0 else -1
    end_command = int(local[j]) if j < l else -1
    phase0 = (problem.t0 + i) % leg.period
    backward_steps(leg.indptr, leg.indices, end, problem.goal_id, leg.steps)
    fewest = int(leg.steps[start])
    outside = np.r_[local[:i], local[j:]]
    fixed_time = float(leg.durations[outside].sum())
    prefix, suffix = local[:i], local[j:]
    fixed_changes = int(np.count_nonzero(prefix[1:] != prefix[:-1]) + np.count_nonzero(suffix[1:] != suffix[:-1]))
    fixed_danger = float(leg.danger[poses[1: i + 1]].sum()) + float(leg.danger[poses[j + 1:]].sum())
    replaced = j - i
    lowest = max(1, fewest)
    highest = math.floor(problem.t_max * (4.0 - current) / leg.shortest - fixed_time / leg.shortest) + 1
    if span is not None:
        lowest, highest = max(lowest, replaced - span), min(highest, replaced + span)
    highest = min(highest, memory_budget() // (2 * leg.layer_bytes))  # the back pointers must fit
    predicted, best = [], current
    for m in range(lowest, highest + 1):
        total_length = l - replaced + m
        w_time, w_change, w_danger = leg.weights(total_length)
        # f_sm, f_sf ≤ 1: nothing longer sums more than this; measured against the best candidate so far,
        # as the exact maximiser closes its lengths (the candidates already found are the fallbacks)
        ceiling = 4.0 - (fixed_time + m * leg.shortest) * w_time
        if ceiling <= best + _IMPROVEMENT:
            break
        if deadline is not None and time.perf_counter() >= deadline:
            break  # a run's time limit: the lengths tried so far give the candidates
        bracket, _ = leg.solve(start, start_command, end, end_command, phase0, m, total_length, None)
        if bracket == np.inf:
            continue
        total = 4.0 - (fixed_time * w_time + fixed_changes * w_change + fixed_danger * w_danger + bracket)
        if total > current + _IMPROVEMENT:
            predicted.append((total, m))
            best = max(best, total)
    if start == end and replaced:  # the window is a loop: cutting it is a candidate too (m = 0)
        predicted.append((math.inf, 0))
    for _, m in sorted(predicted, key=lambda item: (-item[0], item[1]))[:_TRIES]:
        middle = (leg.window_commands(start, start_command, end, end_command, phase0, m, l - replaced + m)
                  if m else np.empty(0, dtype=np.int64))
        candidate = sim.command_ids[np.r_[local[:i], middle, local[j:]]]
        result = problem.simulate([candidate])  # the problem's own verdict, independent of the programme
        total = float(problem.fitness(result)[0].sum())
        if result.reached[0] and result.executed[0] == len(candidate) and total > current + _IMPROVEMENT:
            return candidate, total
    return None


def polish_sum(problem: CommandPathProblem, sequence, *, window: int = POLISH_WINDOW, span: int | None = POLISH_SPAN,
               max_rounds: int = POLISH_ROUNDS, deadline: float | None = None) -> np.ndarray:
    """A goal-reaching chromosome with windows of its path re-planned for the largest fitness sum.

    See the module docstring for the method. Deterministic: no random numbers are drawn.

    Parameters
    ----------
    problem : CommandPathProblem
        The leg (its simulator, start, goal, t0 and t_max).
    sequence : array of int
        Global command ids. Only its executed prefix counts; a chromosome that does not reach the
        goal is returned unchanged.
    window : int, keyword-only
        W: the most commands a window replaces (0: no polish). A path of at most W commands is one
        window, re-planned whole over every length, which gives the leg's largest sum S*.
    span : int or None, keyword-only
        How many commands more or fewer than it replaces a window of a longer path may take (None:
        every length the sum's time bound allows, as for the whole path). Measured on the balanced
        picks of 10 seeded hTetro-GA runs on each bundled 24 × 24 map (2026-11-26), the 32 windows of
        paths longer than W = 40 that improved (span 12) took 0 to 6 commands fewer than they replaced,
        never more; spans 2, 6, 12 and None gave the same sums, at 0.03, 0.07, 0.16 and 18 s a leg on
        zigzag (111 commands). The default, 6, covers every measured change at a few hundredths of a
        second a leg.
    max_rounds : int, keyword-only
        The most rounds of windows over a path longer than W (a round ends the polish when it
        improves nothing).
    deadline : float, optional, keyword-only
        A ``time.perf_counter()`` value (a run's time limit): past it no further window length is
        tried and no further window started; what was found by then is returned (the polish then
        depends on the machine's speed). None: no limit.

    Returns
    -------
    ndarray of int
        The polished chromosome (its executed commands, global ids), whose sum under ``problem`` is
        strictly larger than the input's; the input itself (the same object) when nothing improves,
        the chromosome does not reach the goal or ``window`` is 0.

    Raises
    ------
    ParameterError
        If ``window``, ``span`` or ``max_rounds`` is not a non-negative integer (``max_rounds`` at
        least 1), ``problem`` is not a CommandPathProblem, or ``sequence`` is not an array of the
        problem's command ids.

    Examples
    --------
    >>> from htetro_opt.model import Pose, Workspace, parse_commands
    >>> occupancy = np.zeros((6, 6), dtype=bool)
    >>> occupancy[2, 3] = True  # the cell (x, y) = (3, 2)
    >>> problem = CommandPathProblem(Workspace(occupancy), Pose(1, 1, "O", 0), Pose(3, 4, "O", 0), max_length=6)
    >>> path = parse_commands("y+,x-,y+,x+,y+,x+,x+")  # reaches in 7 s with five changes
    >>> polished = polish_sum(problem, path)  # one window, the whole path: the leg's largest sum
    >>> round(fitness_sum(problem, path)[0], 4), round(fitness_sum(problem, polished)[0], 4)
    (1.4629, 2.5194)
    """
    if not isinstance(problem, CommandPathProblem):
        raise ParameterError(f"problem must be a CommandPathProblem, got {type(problem).__name__}")
    window = check_int(window, "polish_window", minimum=0)
    span = check_int(span, "span", minimum=0, allow_none=True)
    max_rounds = check_int(max_rounds, "max_rounds", minimum=1)
    given = sequence
    try:
        sequence = np.asarray(sequence, dtype=np.int64).ravel()
    except (TypeError, ValueError):
        raise ParameterError(f"sequence must be an array of global command ids, got {sequence!r}") from None
    if not np.isin(sequence, problem.command_ids).all():
        raise ParameterError(f"sequence holds ids outside the problem's command alphabet: "
                             f"{sorted(set(sequence[~np.isin(sequence, problem.command_ids)].tolist()))[:5]}")
    result = problem.simulate([sequence])
    if not window or not result.reached[0] or result.executed[0] == 0:
        return given
    leg = _Leg(problem)
    current = float(problem.fitness(result)[0].sum())
    path = result.prefix(0)
    improved = False
    for _ in range(max_rounds):
        round_improved = False
        start = 0
        while True:
            sim_result = problem.simulate([path])
            local = sim_result.local[0, : len(path)].astype(np.int64)
            poses = (sim_result.keys[: len(path) + 1, 0] // leg.sim.n_columns).astype(np.int64)
            l = len(path)
            whole = l <= window
            i = 0 if whole else min(start, l - window)
            j = l if whole else i + window
            found = _window(leg, local, poses, i, j, current, None if whole else span, deadline)
            if found is not None:
                path, current = found
                improved = round_improved = True
            if whole or j >= l or (deadline is not None and time.perf_counter() >= deadline):
                break
            start = i + max(1, window // 2)
        if not round_improved or whole or (deadline is not None and time.perf_counter() >= deadline):
            break  # a whole-path window is exact: a second round would find nothing
    return path if improved else given
