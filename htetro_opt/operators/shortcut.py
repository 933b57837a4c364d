"""Shortcut (ours, optional): cut the longest loop out of each chromosome's path (conservative)."""

from __future__ import annotations

import numpy as np
from pymoo.core.mutation import Mutation

from htetro_opt.operators._chromosome import as_column, sequences

__all__ = ["CommandShortcut", "cut_longest_loop"]


def cut_longest_loop(trace: np.ndarray, executed: int) -> tuple[int, int] | None:
    """The commands ``[i, j)`` to cut so the path skips its longest loop, or None if it has none.

    ``trace`` holds the pose ids before and after each command; a loop is a pose visited at step i
    and again at step j > i, and the executed path with commands i … j − 1 removed passes through
    the same poses before i and from j on.

    Examples
    --------
    >>> cut_longest_loop(np.array([5, 6, 7, 6, 5, 8]), 5)
    (0, 4)
    """
    poses = np.asarray(trace[: executed + 1])
    if len(poses) < 3:
        return None
    values, first = np.unique(poses, return_index=True)
    last = len(poses) - 1 - np.unique(poses[::-1], return_index=True)[1]
    span = last - first
    k = int(np.argmax(span))
    return (int(first[k]), int(last[k])) if span[k] > 0 else None


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
        result = problem.simulator.run(seqs, problem.start_id, roadmap=[problem.goal], t0=problem.t0,
                                       stop_at_goal=True)
        trace = result.keys.T // problem.simulator.n_columns
        out = []
        for i, seq in enumerate(seqs):
            loop = cut_longest_loop(trace[i], int(result.executed[i]))
            out.append(seq if loop is None else np.concatenate([seq[: loop[0]], seq[loop[1]:]]))
        return as_column(out)
