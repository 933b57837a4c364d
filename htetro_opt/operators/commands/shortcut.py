"""Shortcut (ours, optional): cut the longest loop out of each chromosome's path (conservative)."""

from __future__ import annotations

import numpy as np
from pymoo.core.mutation import Mutation

from htetro_opt.model.simulate import SimulationResult
from htetro_opt.operators.commands._chromosome import as_column, sequences

__all__ = ["CommandShortcut", "cut_longest_loop", "longest_loops", "loop_cuts", "cut_sequences", "cut_result",
           "shortcut_sequences", "repair_and_shortcut", "repair_shortcut_evaluate"]


def cut_longest_loop(trace: np.ndarray, executed: int) -> tuple[int, int] | None:
    """The commands ``[i, j)`` to cut so the path skips its longest loop, or None if it has none.

    ``trace`` holds the pose ids before and after each command; a loop is a pose visited at step i
    and again at step j > i (the longest; the earliest among equally long ones), and the executed path with commands i … j − 1 removed passes through
    the same poses before i and from j on.

    Examples
    --------
    >>> cut_longest_loop(np.array([5, 6, 7, 6, 5, 8]), 5)
    (0, 4)
    """
    poses = np.asarray(trace[: executed + 1])
    if len(poses) < 2:
        return None
    values, first = np.unique(poses, return_index=True)
    last = len(poses) - 1 - np.unique(poses[::-1], return_index=True)[1]
    span = last - first
    if span.max() <= 0:
        return None
    k = int(np.argmin(np.where(span == span.max(), first, len(poses))))  # the earliest of the longest
    return int(first[k]), int(last[k])


def longest_loops(trace: np.ndarray, executed: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`cut_longest_loop` for a batch: ``trace`` (B, L + 1), ``executed`` (B,); returns the
    cut ``(i, j)`` of each row, ``i == j`` where a row has no loop.

    Examples
    --------
    >>> longest_loops(np.array([[5, 6, 7, 6, 5, 8], [1, 2, 3, 4, 5, 6]]), np.array([5, 5]))
    (array([0, 0]), array([4, 0]))
    """
    trace = np.asarray(trace)
    batch, width = trace.shape
    cut_i, cut_j = np.zeros(batch, dtype=np.int64), np.zeros(batch, dtype=np.int64)
    inside = np.arange(width)[None, :] <= np.asarray(executed)[:, None]
    if not inside.any():
        return cut_i, cut_j
    rows = np.broadcast_to(np.arange(batch, dtype=np.int64)[:, None], trace.shape)[inside]
    steps = np.broadcast_to(np.arange(width, dtype=np.int64), trace.shape)[inside]
    poses = trace[inside].astype(np.int64)
    n_poses = int(poses.max()) + 1
    # One sort of distinct keys (row, pose, step): each (row, pose) group's first and last step are
    # its ends, and no sort needs to be stable.
    key = np.sort((rows * n_poses + poses) * width + steps)
    group = key // width
    starts = np.flatnonzero(np.r_[True, group[1:] != group[:-1]])
    first = key[starts] % width
    last = key[np.r_[starts[1:], len(key)] - 1] % width
    row = group[starts] // n_poses
    # Per row, the longest span and the earliest of equals: the largest span * width + (width − 1 − first).
    score = (last - first) * width + (width - 1 - first)
    row_starts = np.flatnonzero(np.r_[True, row[1:] != row[:-1]])
    best = np.maximum.reduceat(score, row_starts)
    span, first = best // width, width - 1 - best % width
    has = span > 0
    looped = row[row_starts][has]
    cut_i[looped], cut_j[looped] = first[has], first[has] + span[has]
    return cut_i, cut_j


def loop_cuts(result, count: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """:func:`longest_loops` of the first ``count`` (default all) sequences of a
    :class:`~htetro_opt.model.SimulationResult`: the commands ``[i, j)`` to cut from each, ``i == j``
    where a path has no loop."""
    count = len(result) if count is None else count
    trace = result.keys[:, :count].T // result.simulator.n_columns
    return longest_loops(trace, result.executed[:count])


def cut_sequences(seqs: list[np.ndarray], cut_i: np.ndarray, cut_j: np.ndarray) -> list[np.ndarray]:
    """``seqs`` with the commands ``[cut_i[k], cut_j[k])`` cut out of each of the first ``len(cut_i)``."""
    out = list(seqs)
    for k in np.flatnonzero(cut_i != cut_j):
        out[k] = np.concatenate([seqs[k][: cut_i[k]], seqs[k][cut_j[k]:]])
    return out


def shortcut_sequences(seqs: list[np.ndarray], result, count: int | None = None) -> list[np.ndarray]:
    """``seqs`` with the longest loop of each of the first ``count`` (default all) cut out, the loops
    found on ``result``, the :class:`~htetro_opt.model.SimulationResult` of running them."""
    return cut_sequences(seqs, *loop_cuts(result, len(seqs) if count is None else count))


def cut_result(result, cut_i: np.ndarray, cut_j: np.ndarray) -> SimulationResult:
    """The simulation of the sequences of ``result`` with the loops ``[cut_i, cut_j)`` of
    :func:`loop_cuts` cut out, derived from ``result`` without simulating again.

    Valid on a static map only: the cut path passes through the same poses before ``cut_i`` and from
    ``cut_j`` on, so it stays valid, meets the goal where it met it, and fails (when it failed) at the
    same command; each row's keys and commands after the cut move ``cut_j − cut_i`` places forward.
    With moving obstacles the shortened path runs earlier, and only a new simulation tells.

    Examples
    --------
    >>> from htetro_opt.model import Pose, Simulator, Workspace, parse_commands
    >>> sim = Simulator(Workspace(np.zeros((8, 8), dtype=bool)))
    >>> seqs = [parse_commands("x+,y+,y-,x+"), parse_commands("x+")]
    >>> result = sim.run(seqs, Pose(2, 2, "O", 0))
    >>> cut = cut_result(result, *loop_cuts(result))
    >>> again = sim.run(cut_sequences(seqs, *loop_cuts(result)), Pose(2, 2, "O", 0))
    >>> cut.executed.tolist(), bool((cut.trace[:, :3] == again.trace[:, :3]).all()), cut.time.tolist()
    ([2, 1], True, [2.0, 1.0])
    """
    rows = np.flatnonzero(cut_i != cut_j)
    if not len(rows):
        return result
    sim = result.simulator
    width = result.local.shape[1]
    start, shift = cut_i[rows][:, None], (cut_j - cut_i)[rows][:, None]
    steps = np.arange(width)[None, :]
    source = steps + np.where(steps >= start, shift, 0)  # command t of a cut row is command source[t] before
    local = result.local.copy()
    local[rows] = np.where(source < width, np.take_along_axis(local[rows], source.clip(max=width - 1), axis=1), sim.pad)
    poses = np.arange(width + 1)[None, :]
    source = poses + np.where(poses > start, shift, 0)  # pose t after the cut is pose source[t] before
    keys = result.keys.copy()
    keys[:, rows] = np.take_along_axis(keys[:, rows], source.clip(max=width).T, axis=0)
    executed = result.executed.copy()
    executed[rows] -= shift[:, 0]
    first_invalid = result.first_invalid.copy()
    first_invalid[rows] = np.where(first_invalid[rows] >= 0, first_invalid[rows] - shift[:, 0], -1)
    durations = sim.durations[local[rows]]  # as the simulator sums them
    durations[steps >= executed[rows][:, None]] = 0.0
    time = result.time.copy()
    time[rows] = durations.sum(axis=1)
    return SimulationResult(valid=result.valid, first_invalid=first_invalid, executed=executed,
                            reached=result.reached, progress=result.progress, time=time, final=result.final,
                            simulator=sim, keys=keys, local=local)


def repair_and_shortcut(problem, seqs: list[np.ndarray], *, repair=None, shortcut: int = 0) -> list[np.ndarray]:
    """Repair every sequence and cut the longest loop of the first ``shortcut`` ones, from one simulation.

    The pure function behind :class:`~htetro_opt.operators.CommandRepair` (``repair`` a generator,
    ``shortcut=0``) and :class:`CommandShortcut` (no ``repair``, ``shortcut=len(seqs)``); the
    hTetro-GA calls it once for both, since the simulation costs more than everything else it does.
    The loops are found on the repaired paths, so a cut path stays valid on a static map.

    Parameters
    ----------
    problem : CommandPathProblem
        Provides ``simulator``, ``start_id``, ``goal`` and ``t0``.
    seqs : list of ndarray
        Global command ids.
    repair : numpy.random.Generator, optional, keyword-only
        Replace each command that would be invalid where it runs by a random valid one.
    shortcut : int, keyword-only
        How many sequences, from the first, get their longest loop cut.
    """
    if repair is None and not shortcut:
        return list(seqs)
    return repair_shortcut_evaluate(problem, seqs, repair=repair, shortcut=shortcut, evaluate=False)[0]


def repair_shortcut_evaluate(problem, seqs: list[np.ndarray], *, repair=None, shortcut: int = 0,
                             evaluate: bool = True) -> tuple[list[np.ndarray], dict | None]:
    """:func:`repair_and_shortcut`, and the problem's evaluation of the sequences it returns
    (:meth:`~htetro_opt.problems.CommandPathProblem.outcomes`), from the same simulation.

    On a static map nothing is simulated twice: the shortened paths' simulation is derived from the
    one that found their loops (:func:`cut_result`). With moving obstacles the shortened paths are
    simulated again (they run earlier, and may now collide).

    Returns
    -------
    (list of ndarray, dict or None)
        The sequences, and their outcomes (None without ``evaluate``).
    """
    result = problem.simulate(seqs, repair=repair)
    if repair is not None:  # the sequences as run: SimulationResult.sequence of each row, at once
        sim = result.simulator
        present = result.local != sim.pad  # padding only ever follows a row's commands
        genes = sim.command_ids[result.local[present]]
        ends = np.cumsum(present.sum(axis=1))
        seqs = [genes[a:b] for a, b in zip((ends - present.sum(axis=1)).tolist(), ends.tolist())]
    cut_i, cut_j = loop_cuts(result, shortcut) if shortcut else (np.zeros(0, np.int64),) * 2
    seqs = cut_sequences(seqs, cut_i, cut_j)
    if not evaluate:
        return seqs, None
    if not problem.simulator.workspace.moving:
        return seqs, problem.outcomes(cut_result(result, cut_i, cut_j))
    outcomes = problem.outcomes(result)
    cut = np.flatnonzero(cut_i != cut_j)
    if len(cut):
        again = problem.outcomes(problem.simulate([seqs[k] for k in cut]))
        for key, values in again.items():
            outcomes[key][cut] = values
    return seqs, outcomes


class CommandShortcut(Mutation):
    """Simulate each chromosome from the problem's start and cut its longest loop (the commands
    between two visits of the same pose), keeping the genes after the executed part.

    Like removal it keeps B2's displacement and the pose the path reaches; unlike it, it never
    breaks a path on a static map. With moving obstacles the shortened path runs earlier and may
    collide; evaluation tells. This is a memetic local step of ours, not part of the paper's
    hTetro-GA. The problem must provide ``simulator``, ``start_id``, ``goal`` and ``t0``.
    """

    def __init__(self) -> None:
        super().__init__(prob=1.0)

    def _do(self, problem, X, *args, random_state=None, **kwargs):
        seqs = sequences(X)
        return as_column(repair_and_shortcut(problem, seqs, shortcut=len(seqs)))
