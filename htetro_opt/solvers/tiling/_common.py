"""What the tiling modules share: the grid's padding, the two ways a search stops early, the
placements of the patterns on a map and the order the patterns are tried in.

Cells are ``(x, y)``, ``occ[y, x]`` True for an obstacle, ``y`` upwards; the scan order is the top
row first, then left to right. The searches (``_backtracking``, the compiled sweep of ``_sweep`` in
``_portfolio``) work on a flat byte grid padded by :data:`_PAD` obstacle cells on every side, its
internal rows top first, so that the flat index increases in scan order and no pattern reads past
the edge.

Every module of the package may import this one; it imports none of them.
"""

from __future__ import annotations

import time as _time

import numpy as np

from htetro_opt.errors import TilingError

_PAD = 3  # a pattern reaches at most 3 cells from its anchor in x and y


class _TimeLimit(TilingError):
    """The time limit ran out (the map may still be tileable): never a reason to try a split."""


def _check_clock(deadline) -> None:
    if deadline is not None and _time.perf_counter() > deadline:
        raise _TimeLimit("time limit")


class _WorkLimit(_TimeLimit):
    """A work budget of the caller's (``max_steps``, ``max_deterministic_time``) ran out: handled as the
    time limit is (no proof, never a reason to try a split), reported with the budget's name."""

    def __init__(self, budget: str) -> None:
        super().__init__(budget)
        self.budget = budget


class _OutOfWork(Exception):
    """A stage of the ``auto`` portfolio used up its work budget: the next stage takes over."""


def _placements(free: np.ndarray, patterns) -> tuple[np.ndarray, np.ndarray]:
    """Every placement of the patterns on free cells: (pattern index per placement, cells (n, 4, 2))."""
    h, w = free.shape
    padded = np.zeros((h + 2 * _PAD, w + 2 * _PAD), dtype=bool)
    padded[_PAD:_PAD + h, _PAD:_PAD + w] = free
    which, cells = [], []
    for k, pattern in enumerate(patterns):
        ok = free.copy()
        for dx, dy in pattern.cells[1:].tolist():
            ok &= padded[_PAD + dy:_PAD + dy + h, _PAD + dx:_PAD + dx + w]
        ys, xs = np.nonzero(ok)
        if len(xs):
            anchor = np.stack([xs, ys], axis=1)
            cells.append(anchor[:, None, :] + pattern.cells[None, :, :])
            which.append(np.full(len(xs), k, dtype=np.int64))
    if not cells:
        return np.zeros(0, dtype=np.int64), np.zeros((0, 4, 2), dtype=np.int64)
    return np.concatenate(which), np.concatenate(cells).astype(np.int64)


def _shape_text(patterns) -> str:
    return "".join(s for s in "IOLJZST" if s in {p.shape for p in patterns})


def _pattern_order(n: int, seed) -> list[int]:
    """The order patterns are tried in: as given, or shuffled by the seed."""
    if seed is None:
        return list(range(n))
    return np.random.default_rng(seed).permutation(n).tolist()
