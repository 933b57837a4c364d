"""The compiled sweep of the ``auto`` tiling portfolio: most of a tiling in one pass, without backtracking.

A scan-order sweep like the backtracker's (the first uncovered cell in scan order is the anchor, the
fixed tetrominoes tried in the pattern order), but it never backtracks: it keeps the first placement
that passes a look-ahead, and when none does it stops there and reports the cell (``_tiling``
repairs the tiling around it and calls the sweep again). The look-ahead rejects a placement after
which

- an uncovered cell within 3 cells of the new tile lies under no placement that still fits (a dead
  cell: a placement reaches 3 cells, so no farther cell can lose its last one), or
- an uncovered cell next to the new tile belongs to an enclosed pocket of at most ``pocket`` cells
  whose area is not a multiple of 4.

Compiled by numba (a core dependency; without it importing this module raises
:class:`~htetro_opt.errors.DependencyError`) so that a sweep takes milliseconds on a 256 × 256 grid;
it is deterministic: the same grid and pattern order give the same tiles. The grid is the
backtracker's padded flat byte grid (internal rows top first, so the flat index is the scan order).
"""

from __future__ import annotations

import numpy as np

from htetro_opt._jit import require_numba

_jit = require_numba().njit(cache=True, nogil=True)  # compiled at each kernel's first call

__all__ = ["sweep", "dead_cells"]


@_jit
def _fits(filled, at, cells, k):
    for i in range(4):
        if filled[at + cells[k, i]]:
            return False
    return True


@_jit
def _live(filled, cell, cells):
    """Whether some placement covering ``cell`` still fits."""
    for k in range(cells.shape[0]):
        for j in range(4):
            if _fits(filled, cell - cells[k, j], cells, k):
                return True
    return False


@_jit
def dead_cells(filled, candidates, cells):
    """The ``candidates`` (flat indices) that are uncovered and under no placement that fits."""
    out = np.empty(candidates.size, dtype=np.int64)
    n_dead = 0
    for n in candidates:
        if not filled[n] and not _live(filled, n, cells):
            out[n_dead] = n
            n_dead += 1
    return out[:n_dead].copy()


@_jit
def _pocket_ok(filled, start, stride, pocket, stamp, mark, stack):
    """False when the uncovered cells 4-connected to ``start`` are at most ``pocket`` and not a
    multiple of 4 (no tiling covers them); True when they are more (the pocket is open) or fit."""
    top = 0
    stack[top] = start
    top += 1
    stamp[start] = mark
    count = 0
    while top:
        top -= 1
        c = stack[top]
        count += 1
        if count > pocket:
            return True
        for d in (1, -1, stride, -stride):
            n = c + d
            if not filled[n] and stamp[n] != mark:
                stamp[n] = mark
                stack[top] = n
                top += 1
    return count % 4 == 0


@_jit
def _looks_ahead(filled, at, cells, k, stride, pocket, stamp, seen, stack):
    """Whether the placement just made (pattern k at ``at``, already in ``filled``) leaves every
    uncovered cell within 3 cells of it under some placement that fits, and no small pocket next to
    it whose area is not a multiple of 4. ``stamp[0]`` / ``seen[0]`` (a padding cell's entries,
    never visited) hold the current marks of the two searches, so that nothing is cleared."""
    seen[0] += 1
    for i in range(4):
        c = at + cells[k, i]
        for dr in range(-3, 4):
            for dc in range(-3, 4):
                n = c + dr * stride + dc
                if filled[n] or seen[n] == seen[0]:
                    continue
                seen[n] = seen[0]
                if not _live(filled, n, cells):
                    return False
    for i in range(4):
        c = at + cells[k, i]
        for d in (1, -1, stride, -stride):
            n = c + d
            if filled[n]:
                continue
            stamp[0] += 1
            if not _pocket_ok(filled, n, stride, pocket, stamp, stamp[0], stack):
                return False
    return True


@_jit
def sweep(filled, cells, stride, pocket, at, stop, halt):
    """Sweep from flat index ``at`` until every cell before ``stop`` is covered or the sweep is stuck.

    ``filled`` (uint8, the padded grid, 1 = obstacle or covered) is updated in place. Returns the
    placed tiles' anchors and pattern indices and the anchor it is stuck at (-1: done). When
    ``halt[0]`` is set (a signal: :func:`htetro_opt._interrupt.kernel_flag`) it returns before its next
    tile, as if stuck where it is; the caller, back in Python, raises the signal's exception.
    """
    size = filled.size
    anchors = np.empty(size // 4 + 1, dtype=np.int64)
    kinds = np.empty(size // 4 + 1, dtype=np.int64)
    stamp = np.zeros(size, dtype=np.int64)
    seen = np.zeros(size, dtype=np.int64)
    stack = np.empty(size, dtype=np.int64)
    n_tiles = 0
    while True:
        if halt[0]:  # one byte read a tile
            return anchors[:n_tiles].copy(), kinds[:n_tiles].copy(), at
        while at < stop and filled[at]:
            at += 1
        if at >= stop:
            return anchors[:n_tiles].copy(), kinds[:n_tiles].copy(), -1
        chosen = -1
        for k in range(cells.shape[0]):
            if not _fits(filled, at, cells, k):
                continue
            for i in range(4):
                filled[at + cells[k, i]] = 1
            ok = _looks_ahead(filled, at, cells, k, stride, pocket, stamp, seen, stack)
            if ok:
                chosen = k
                break
            for i in range(4):
                filled[at + cells[k, i]] = 0
        if chosen < 0:
            return anchors[:n_tiles].copy(), kinds[:n_tiles].copy(), at
        anchors[n_tiles] = at
        kinds[n_tiles] = chosen
        n_tiles += 1

