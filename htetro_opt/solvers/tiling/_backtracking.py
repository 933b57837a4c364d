"""``"backtracking"``, the paper's tiling algorithm (Le et al. 2018, its ref. 38: the classic
polyomino tiling backtracker).

Take the first uncovered free cell in scan order (top row first, then left to right), try each
allowed fixed tetromino anchored there (the pattern's first cell in scan order on that cell, so it
covers nothing before it), and go on; when no pattern fits, undo the previous placement and try its
next pattern. The search is an explicit stack, not recursion (a 64 × 64 grid is 1024 levels deep),
on a padded flat byte grid, so that a placement test is three look-ups. It is complete (when it
ends without a tiling, none exists) and pruned three ways:

- after each placement, a flood fill from the uncovered cells next to the new tile; a region that
  is enclosed (the fill ends before reaching the rows 4 below the anchor, where no tile lies yet,
  or before :data:`EXACT_LIMIT` cells when it does reach them) must have an area that is a
  multiple of 4, equal checkerboard colours without T, and must tile on its own: a search of that
  region alone, turned so that it runs along the region's long side, cached by the region's shape;
- everything before the anchor is covered and no tile reaches more than 3 rows below its anchor,
  so the anchor and the next ``3 W + 1`` cells are the whole state of the search: a state whose
  subtree held no tiling is remembered (as a 128-bit digest, up to :data:`MEMO_LIMIT` of them) and
  never searched again;
- the pre-checks of ``_prechecks``, which the caller runs first.

With ``shuffle=True`` the pattern order is shuffled once by the ``seed``'s generator (other
tilings); without it the order is that of :data:`~htetro_opt.model.tiles.PATTERNS` (I, O, L, J, Z,
S, T), which tiles a grid whose height is a multiple of 4 by vertical I's without a single
backtrack. It tiles 64 × 64 grids, free or with scattered obstacle blocks, in well under a second;
on cluttered maps with few allowed shapes (T with Z or I, say) it can still search for long, which
is what ``time_limit`` and CP-SAT are for.

The ``auto`` portfolio (``_portfolio``) runs it with a budget of steps (``work``), and on the
strips its sweep leaves at the end, turned to run along them.
"""

from __future__ import annotations

import time as _time
from hashlib import blake2b

import numpy as np

from htetro_opt.solvers.tiling._common import _PAD, _OutOfWork, _pattern_order, _shape_text, _TimeLimit
from htetro_opt.solvers.tiling._prechecks import _class_counts, _class_lattice, _in_lattice

__all__ = ["EXACT_LIMIT", "FLOOD_LIMIT", "MEMO_LIMIT"]

FLOOD_LIMIT = 4096
"""Most cells the backtracker's pruning flood fill visits before it treats a region as open."""

EXACT_LIMIT = 64
"""Regions of uncovered cells up to this size are checked exactly (a search of the region alone)
whenever a placement encloses them, however far they reach."""

MEMO_LIMIT = 1_000_000
"""Most failed search states the backtracker remembers (a 16-byte digest each, ~0.1 GB at the limit)."""

_CHECK_EVERY = 2048  # search steps between two looks at the clock


def _backtrack(occ: np.ndarray, patterns, order, deadline, cache: dict, work: list | None = None):
    """Generate the tilings of the free cells as lists of (anchor index, position in ``order``),
    depth first. ``cache`` maps enclosed regions (normalised) to whether they tile; share it.
    ``work``: None, or ``[steps left]``, shared with the region sub-searches; _OutOfWork when spent."""
    h, w = occ.shape
    stride = w + 2 * _PAD
    rows = h + 2 * _PAD
    size = stride * rows
    # internal row r = (h - 1 - y) + PAD, so increasing flat index is the scan order
    padded = np.ones((rows, stride), dtype=np.uint8)
    padded[_PAD:_PAD + h, _PAD:_PAD + w] = occ[::-1]
    filled = bytearray(padded.tobytes())
    colour = (np.add.outer(np.arange(rows), np.arange(stride)) & 1).astype(np.uint8).tobytes()
    offsets = [tuple(int(dx) - int(dy) * stride for dx, dy in patterns[k].cells[1:].tolist()) for k in order]
    n_pat = len(offsets)
    check_parity = "T" not in {p.shape for p in patterns}
    lattice = _class_lattice(_shape_text(patterns))
    exact, limit = EXACT_LIMIT, FLOOD_LIMIT
    neighbours = (1, -1, stride, -stride)

    def enclosed_ok(cells: tuple, far_from: int) -> bool:
        """False if an enclosed uncovered region next to the new tile cannot be tiled.

        A flood fill from each uncovered neighbour of the tile; it gives up (the region is open) on
        joining a region found open before, past ``exact`` cells when it has reached ``far_from``
        (rows no tile reaches yet), or past ``limit`` cells.
        """
        open_cells: set = set()
        closed_cells: set = set()
        for cell in cells:
            for d in neighbours:
                start = cell + d
                if filled[start] or start in open_cells or start in closed_cells:
                    continue
                local = {start}
                stack = [start]
                balance = 0
                far = opened = False
                while stack:
                    c = stack.pop()
                    if c >= far_from:
                        far = True
                    balance += 1 if colour[c] else -1
                    for e in neighbours:
                        n = c + e
                        if filled[n] or n in local:
                            continue
                        if n in open_cells:
                            opened = True
                            break
                        local.add(n)
                        stack.append(n)
                    if opened or len(local) > limit or (far and len(local) > exact):
                        opened = True
                        break
                if opened:
                    open_cells |= local
                elif len(local) % 4 or (check_parity and balance) or not region_tiles(local):
                    return False
                else:
                    closed_cells |= local
        return True

    def region_tiles(region: set) -> bool:
        """Whether an enclosed region tiles on its own: a search of the region alone, turned to
        run along its long side (so its memo stays small), cached by shape."""
        rc = [divmod(c, stride) for c in region]
        r0 = min(r for r, _ in rc)
        c0 = min(c for _, c in rc)
        small = np.ones((max(r for r, _ in rc) - r0 + 1, max(c for _, c in rc) - c0 + 1), dtype=bool)
        for r, c in rc:
            small[r - r0, c - c0] = False
        small = small[::-1]  # internal rows run downwards; occupancy rows upwards
        if small.shape[1] > small.shape[0]:
            small = np.rot90(small)  # a rotation maps each tetromino to one of its own shape
        key = (small.shape, small.tobytes())
        known = cache.get(key)
        if known is None:
            if deadline is not None and _time.perf_counter() > deadline:
                raise _TimeLimit("time limit")
            ys, xs = np.nonzero(~small)
            known = _in_lattice(lattice, _class_counts(xs, ys))
            if known:
                search = _backtrack(np.ascontiguousarray(small), patterns, order, deadline, cache, work)
                try:
                    known = next(search, None) is not None
                finally:
                    search.close()
            cache[key] = known
        return known

    # Everything before the anchor is covered and no tile reaches 3 rows past its anchor, so the
    # anchor and the cells [anchor, anchor + window) are the whole search state: a state whose
    # subtree held no tiling is remembered (as a 128-bit digest) and never searched again.
    window = 3 * stride + 1
    failed: set[bytes] = set()

    def state(at: int) -> bytes:
        return blake2b(filled[at:at + window], digest_size=16, salt=at.to_bytes(8, "little")).digest()

    first = 0
    while first < size and filled[first]:
        first += 1
    if first == size:
        return
    anchors: list[int] = []
    chosen: list[int] = []
    entered = [0]  # tilings found when each open level was entered
    found = 0
    anchor, k = first, 0
    steps = 0
    while True:
        if deadline is not None and steps % _CHECK_EVERY == 0 and _time.perf_counter() > deadline:
            raise _TimeLimit("time limit")
        steps += 1
        if work is not None:
            work[0] -= 1
            if work[0] < 0:
                raise _OutOfWork
        placed = False
        while k < n_pat:
            o1, o2, o3 = offsets[k]
            if not (filled[anchor + o1] or filled[anchor + o2] or filled[anchor + o3]):
                cells = (anchor, anchor + o1, anchor + o2, anchor + o3)
                for c in cells:
                    filled[c] = 1
                # no tile reaches 4 rows below the anchor's row: a fill that gets there is open
                if enclosed_ok(cells, (anchor // stride + 4) * stride):
                    nxt = anchor + 1
                    while nxt < size and filled[nxt]:
                        nxt += 1
                    if nxt == size:
                        found += 1
                        yield [(a, c) for a, c in zip(anchors + [anchor], chosen + [k])]
                    elif state(nxt) not in failed:
                        placed = True
                        break
                for c in cells:
                    filled[c] = 0
            k += 1
        if placed:
            anchors.append(anchor)
            chosen.append(k)
            entered.append(found)
            anchor, k = nxt, 0
            continue
        # every pattern at this anchor failed: remember the state if it held no tiling, backtrack
        if entered.pop() == found and len(failed) < MEMO_LIMIT:
            failed.add(state(anchor))
        if not anchors:
            return
        anchor, k = anchors.pop(), chosen.pop()
        o1, o2, o3 = offsets[k]
        for c in (anchor, anchor + o1, anchor + o2, anchor + o3):
            filled[c] = 0
        k += 1


def _backtracking_tilings(occ, patterns, seed, deadline, work=None):
    h, w = occ.shape
    stride = w + 2 * _PAD
    order = _pattern_order(len(patterns), seed)
    for solution in _backtrack(occ, patterns, order, deadline, {}, work):
        tiles = []
        for anchor, k in solution:
            r, c = divmod(anchor, stride)
            x, y = c - _PAD, h - 1 - (r - _PAD)
            tiles.append(np.array([x, y], dtype=np.int64) + patterns[order[k]].cells)
        yield tiles
