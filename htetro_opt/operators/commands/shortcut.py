"""Shortcut (ours, optional): cut the longest loop out of each chromosome's path (conservative)."""

from __future__ import annotations

import numpy as np
from pymoo.core.mutation import Mutation

from htetro_opt.operators.commands._chromosome import as_column, sequences

__all__ = ["CommandShortcut", "cut_longest_loop", "longest_loops", "shortcut_sequences", "repair_and_shortcut"]


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
    steps = np.broadcast_to(np.arange(width), trace.shape)
    rows = np.broadcast_to(np.arange(batch)[:, None], trace.shape)
    inside = steps <= np.asarray(executed)[:, None]
    r, p, k = rows[inside], trace[inside], steps[inside]
    order = np.lexsort((k, p, r))
    r, p, k = r[order], p[order], k[order]
    new_group = np.r_[True, (r[1:] != r[:-1]) | (p[1:] != p[:-1])]
    starts = np.flatnonzero(new_group)
    ends = np.r_[starts[1:], len(r)] - 1
    group_row, first, last = r[starts], k[starts], k[ends]
    span = last - first
    cut_i, cut_j = np.zeros(batch, dtype=np.int64), np.zeros(batch, dtype=np.int64)
    best = np.full(batch, -1, dtype=np.int64)
    # the longest span per row: sort groups by (row, span) and take each row's last
    by_span = np.lexsort((-first, span, group_row))
    last_of_row = np.r_[group_row[by_span][1:] != group_row[by_span][:-1], True]
    chosen = by_span[last_of_row]
    best[group_row[chosen]] = span[chosen]
    has_loop = group_row[chosen][span[chosen] > 0]
    keep = chosen[span[chosen] > 0]
    cut_i[has_loop], cut_j[has_loop] = first[keep], last[keep]
    return cut_i, cut_j


def shortcut_sequences(seqs: list[np.ndarray], result, count: int | None = None) -> list[np.ndarray]:
    """``seqs`` with the longest loop of each of the first ``count`` (default all) cut out, the loops
    found on ``result``, the :class:`~htetro_opt.model.SimulationResult` of running them."""
    count = len(seqs) if count is None else count
    trace = result.keys[:, :count].T // result.simulator.n_columns
    cut_i, cut_j = longest_loops(trace, result.executed[:count])
    out = list(seqs)
    for k in np.flatnonzero(cut_i != cut_j):
        out[k] = np.concatenate([seqs[k][: cut_i[k]], seqs[k][cut_j[k]:]])
    return out


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
    result = problem.simulator.run(seqs, problem.start_id, roadmap=[problem.goal], t0=problem.t0,
                                   stop_at_goal=True, repair=repair)
    if repair is not None:
        seqs = [result.sequence(i) for i in range(len(seqs))]
    return shortcut_sequences(seqs, result, shortcut) if shortcut else list(seqs)


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
