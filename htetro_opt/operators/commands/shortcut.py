"""Shortcut (ours, optional): cut the longest loop out of each chromosome's path (conservative)."""

from __future__ import annotations

import numpy as np
from pymoo.core.mutation import Mutation

from htetro_opt._jit import lazy_jit
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


@lazy_jit  # compiled on first use: importing the operators does not import numba
def _longest_loops(trace, executed, first_seen, cut_i, cut_j):
    """The loop of :func:`longest_loops`, row by row: ``first_seen`` (all -1, left so) holds each
    pose's first step in the row being read, indexed by pose id less the smallest."""
    for b in range(trace.shape[0]):
        end = min(executed[b], trace.shape[1] - 1)
        best_span, best_first = 0, 0
        for t in range(end + 1):
            p = trace[b, t]
            if first_seen[p] < 0:
                first_seen[p] = t
            span = t - first_seen[p]
            # The pose's last step gives its span; of equal spans, the earliest first step.
            if span > best_span or (span == best_span and span > 0 and first_seen[p] < best_first):
                best_span, best_first = span, first_seen[p]
        for t in range(end + 1):
            first_seen[trace[b, t]] = -1
        if best_span > 0:
            cut_i[b], cut_j[b] = best_first, best_first + best_span


@lazy_jit
def _cut_rows(local, keys, rows, cut_i, cut_j, pad, out_local, out_keys):
    """The rows of :func:`cut_result` with their loops cut, into ``out_local`` (B, L) and ``out_keys``
    (L + 1, B) (copies of ``local`` and ``keys``): command t of a cut row is command t + shift before
    from the cut on (``pad`` past the end), pose t is pose t + shift before after the cut (the last
    pose past the end)."""
    width = local.shape[1]
    for r in rows:
        start, shift = cut_i[r], cut_j[r] - cut_i[r]
        for t in range(start, width):
            out_local[r, t] = local[r, t + shift] if t + shift < width else pad
        for t in range(start + 1, width + 1):
            out_keys[t, r] = keys[min(t + shift, width), r]


def longest_loops(trace: np.ndarray, executed: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`cut_longest_loop` for a batch: ``trace`` (B, L + 1), ``executed`` (B,); returns the
    cut ``(i, j)`` of each row, ``i == j`` where a row has no loop.

    One pass over each row's executed poses, compiled (a generation's shortcut calls it on every
    conservative offspring); its scratch array spans the poses' ids, from the smallest to the largest.

    Examples
    --------
    >>> longest_loops(np.array([[5, 6, 7, 6, 5, 8], [1, 2, 3, 4, 5, 6]]), np.array([5, 5]))
    (array([0, 0]), array([4, 0]))
    """
    trace = np.asarray(trace)
    executed = np.asarray(executed).astype(np.int64)
    batch, width = trace.shape
    cut_i, cut_j = np.zeros(batch, dtype=np.int64), np.zeros(batch, dtype=np.int64)
    inside = np.arange(width)[None, :] <= executed[:, None]
    if not inside.any():
        return cut_i, cut_j
    # Poses past a row's executed part are never read, but may be any value: set to the smallest read.
    lowest = int(trace[inside].min())
    poses = np.where(inside, trace, lowest).astype(np.int64) - lowest
    first_seen = np.full(int(poses.max()) + 1, -1, dtype=np.int64)
    _longest_loops(poses, executed, first_seen, cut_i, cut_j)
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
    shift = (cut_j - cut_i)[rows][:, None]
    steps = np.arange(width)[None, :]
    local, keys = result.local.copy(), result.keys.copy()
    _cut_rows(result.local, result.keys, rows, np.asarray(cut_i, dtype=np.int64),
                         np.asarray(cut_j, dtype=np.int64), sim.pad, local, keys)
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
