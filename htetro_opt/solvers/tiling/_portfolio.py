"""``"auto"``, the default tiling method: a portfolio of fixed, machine-independent budgets (a
choice of ours).

Each tiler has its tails (benchmarks/README.md, "Tiling without tails"): the backtracker can search
for minutes on a 10 × 10 map or a 64 × 64 one with scattered obstacles, which CP-SAT tiles in a
fraction of a second and a few seconds; CP-SAT needs minutes on 128 × 128 and larger maps that the
backtracker tiles in a second. Both thrash for the same reason: a choice made early in scan order
is found wrong only rows later. So ``auto`` runs, in turn:

1. the backtracker (``_backtracking``) for :data:`_AUTO_STEPS` search steps (a thousand plus 4 a
   tile): the paper's maps, free grids and ``tiling_64x64`` need fewer, so they keep its tiling;
2. on a map of :data:`_SWEEP_CELLS` free cells or more, the repaired sweep (one tiling): a
   compiled (numba) pass in the backtracker's scan and pattern order that never backtracks
   (``_sweep``, imported only when it runs). It keeps the first placement after which every
   uncovered cell within 3 cells still lies under a placement that fits and no enclosed pocket of
   up to :data:`_SWEEP_POCKET` cells has an area that is not a multiple of 4. Where no placement
   passes, the tiles inside a box of :data:`_REPAIR_BOXES` above the stuck cell are lifted and
   CP-SAT (:data:`_REPAIR_WORK`) covers their cells and the stuck cell exactly, the box's other
   uncovered cells at most once (and, where it leaves one of them under no tile that fits, that
   one too, :data:`_REPAIR_TRIES` times at most); the sweep then goes on. It leaves the last
   :data:`_SWEEP_FINAL` rows, where its greed would corner it against the wall, to one exact cover
   of that strip (lifting :data:`_STRIP_LIFTS` rows above while none is found): the backtracker
   turned to run along the strip, whose memo then holds the few states of a short cross-section,
   for :data:`_STRIP_STEPS` from one end and then from the other, then CP-SAT. A sweep that cannot
   go on proves nothing (the tiles around a box could lie otherwise), and the next stage runs;
3. on a map taller and wider than two bands, CP-SAT (``_cpsat``) band after band: the uncovered
   cells of :data:`_BAND_ROWS` rows from the top are covered exactly (and at most once the 3 rows
   below, which tiles of the band reach), the tiles whose first cell lies in the band's top
   :data:`_BAND_COMMIT` rows are kept, and the next band starts below them. Each band has
   :data:`_BAND_WORK` of CP-SAT's deterministic time. The bands run along the map's short side,
   and when a band fails, once more from the opposite side. A first band that cannot be covered
   proves that the map cannot be tiled (any tiling holds a cover of it); a later one proves nothing
   (the bands above might have been tiled otherwise), and the next stage runs;
4. CP-SAT on each 4-connected region of free cells on its own, the smallest first (a small region
   that cannot be tiled ends the search at once), until it finds a tiling, proves there is none,
   or the time limit (or ``max_deterministic_time``, when given) runs out: then the error says that
   neither was found.

Several tilings (:func:`~htetro_opt.solvers.tiling.enumerate_tilings`) go from stage 1 to CP-SAT
on the whole map. Every budget is counted in steps or CP-SAT's deterministic time, not seconds, so
a map gets the same tiling on every machine; only ``time_limit`` depends on the clock (with
``max_deterministic_time`` bounding the last stage, a call ends the same way on every machine).

The budgets are the private constants below, tuning choices rather than options; the tests set
some of them on this module to force a stage on small maps.
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage

from htetro_opt.solvers.tiling._backtracking import _backtracking_tilings
from htetro_opt.solvers.tiling._common import _PAD, _OutOfWork, _pattern_order
from htetro_opt.solvers.tiling._cpsat import _cpsat_covers, _cpsat_tilings

_AUTO_STEPS = (1_000, 4)
"""The backtracking stage of ``auto``: ``a + b × tiles`` search steps (deterministic), then the next
stage. The paper's maps take at most 626 steps, ``tiling_64x64`` 3095 (1004 tiles) and free grids
about 3 a tile, so they keep the backtracker's tiling; a small map it cannot tile at once goes to
CP-SAT after a fraction of a second (a thousand steps, not five, since 2026-11-26: on 10 × 10 maps
the rest was wasted)."""

_BAND_ROWS = 12
"""Rows of the cells a band of the ``auto`` portfolio's band stage covers exactly (3 more rows below
it may be covered, by tiles that stick out of it)."""

_BAND_COMMIT = 6
"""Rows from the top of a band whose tiles (by their first cell) are kept before the next band."""

_BAND_WORK = 2.0
"""CP-SAT's deterministic time (its own unit, about a second, the same on every machine) for one band."""


def _band_tiling(occ, patterns, seed, deadline, turns):
    """One tiling by CP-SAT, band after band of :data:`_BAND_ROWS` rows from the top; [] when the
    first band has no cover (a proof: any tiling restricted to the tiles touching it is one);
    _OutOfWork when a later band has none or CP-SAT spends :data:`_BAND_WORK` on one (no proof:
    the bands above could have been tiled otherwise)."""
    grid = np.rot90(occ, turns)  # a quarter turn maps each tetromino onto one of its own shape
    h = grid.shape[0]
    covered = grid.copy()
    tiles: list[np.ndarray] = []
    top = 0  # the rows y >= h - top are covered
    while True:
        lo, hi = max(0, h - top - _BAND_ROWS), h - top
        must = np.zeros_like(grid)
        must[lo:hi] = ~covered[lo:hi]
        may = np.zeros_like(grid)
        may[max(0, lo - _PAD):lo] = ~covered[max(0, lo - _PAD):lo]
        found = _cpsat_covers(must, may, patterns, seed, deadline, 1, work=_BAND_WORK)
        if not found:
            if top == 0:
                return []
            raise _OutOfWork
        band = found[0]
        if lo == 0:
            tiles += band
            break
        cut = h - top - _BAND_COMMIT  # keep the tiles whose first cell lies in the band's top rows
        for tile in band:
            if tile[:, 1].max() >= cut:
                tiles.append(tile)
                covered[tile[:, 1], tile[:, 0]] = True
        top += _BAND_COMMIT
    back = np.zeros(grid.shape, dtype=np.int64)  # cell (x', y') of grid → flat index (y, x) of occ
    back[:] = np.rot90(np.arange(occ.size).reshape(occ.shape), turns)
    w = occ.shape[1]
    return [[np.stack([back[t[:, 1], t[:, 0]] % w, back[t[:, 1], t[:, 0]] // w], axis=1) for t in tiles]]


_REPAIR_BOXES = ((4, 6), (8, 12), (16, 24))
"""The repairs of ``auto``'s sweep: (rows above, columns either side) of the cell it is stuck at, the
tiles inside the box re-covered exactly with that cell, each box tried in turn."""

_REPAIR_WORK = 1.0
"""CP-SAT's deterministic time (its own unit, the same on every machine) for one repair."""

_REPAIR_TRIES = 8
"""Most CP-SAT runs of one repair (each run adds the cells the previous cover left under no tile)."""

_SWEEP_CELLS = 1024
"""Free cells from which ``auto`` runs the sweep after the backtracker (smaller maps go to CP-SAT,
which takes well under a second on them, without loading numba)."""

_SWEEP_POCKET = 64
"""Largest enclosed pocket of uncovered cells whose area the sweep's look-ahead measures."""

_SWEEP_FINAL = 8
"""The last rows of the map, which the sweep leaves to one exact cover of a strip (lifting
:data:`_STRIP_LIFTS` more rows above while that finds none)."""

_STRIP_LIFTS = (0, 8, 16, 24)
"""Rows above the last :data:`_SWEEP_FINAL` whose tiles the final cover lifts, tried in turn."""

_STRIP_STEPS = (2_000, 4)
"""The backtracker's budget on a strip, from each end: ``a + b × tiles`` steps."""


def _in_scan_order(tiles) -> list[np.ndarray]:
    """The tiles sorted by their first cell in scan order (top row first, then left to right)."""
    def key(tile):
        first = min(map(tuple, tile.tolist()), key=lambda c: (-c[1], c[0]))
        return (-first[1], first[0])
    return sorted(tiles, key=key)


def _cropped(mask: np.ndarray, where) -> tuple[np.ndarray, np.ndarray]:
    """The part of ``mask`` inside the slices ``where`` (rows, columns), and its origin (x, y)."""
    rows, cols = where
    return mask[rows, cols], np.array([cols.start, rows.start], dtype=np.int64)


def _area_fits(must: np.ndarray, may: np.ndarray) -> bool:
    """Whether each 4-connected region of ``must | may`` can hold a cover of its ``must`` cells by
    area alone: enough ``may`` cells to round them up to a multiple of 4. CP-SAT is slow to prove
    this kind of count wrong (it cannot count), so the hopeless boxes never reach it."""
    labels, n = ndimage.label(must | may)
    need = np.bincount(labels[must], minlength=n + 1)
    spare = np.bincount(labels[may], minlength=n + 1)
    return bool(((-need) % 4 <= spare).all())


def _strip_cover(must: np.ndarray, patterns, seed, deadline, solver: str) -> list:
    """An exact cover of the ``must`` cells of a strip (a band of rows), [[tiles]] or [] if none was
    found within the budget: by the backtracker turned to run along the strip (its memo then holds
    the few states of a short cross-section, a dynamic programme in effect) for
    :data:`_STRIP_STEPS` from one end, then from the other, or by CP-SAT for :data:`_REPAIR_WORK`."""
    if solver == "cpsat":
        try:
            return _cpsat_covers(must, np.zeros_like(must), patterns, seed, deadline, 1, work=_REPAIR_WORK)
        except _OutOfWork:
            return []
    first = 1 if must.shape[1] > must.shape[0] else 0
    # from either end: one often takes a few hundred steps where the other needs millions (the
    # search meets the strip's hardest stretch early or late)
    for turns in (first, first + 2):
        turned = np.rot90(~must, turns)  # a quarter turn maps each tetromino onto one of its own shape
        budget = [_STRIP_STEPS[0] + _STRIP_STEPS[1] * int(must.sum()) // 4]
        generator = _backtracking_tilings(np.ascontiguousarray(turned), patterns, seed, deadline, budget)
        try:
            tiles = next(generator, None)
        except _OutOfWork:
            continue
        finally:
            generator.close()
        if tiles is None:
            return []  # the search is exhaustive: no cover exists
        back = np.rot90(np.arange(must.size).reshape(must.shape), turns)  # (y', x') → flat (y, x)
        w = must.shape[1]
        return [[np.stack([back[t[:, 1], t[:, 0]] % w, back[t[:, 1], t[:, 0]] // w], axis=1) for t in tiles]]
    return []


def _sweep_tiling(occ, patterns, seed, deadline):
    """A tiling by the compiled sweep, repaired where it is stuck; None when a repair fails.

    The sweep (``_sweep.sweep``) covers the cells in scan order with the first pattern that passes
    its look-ahead. Where none does, the tiles inside a box of :data:`_REPAIR_BOXES` above the stuck
    cell are lifted and CP-SAT (:data:`_REPAIR_WORK`) covers their cells and the stuck cell exactly,
    the box's uncovered cells below at most once; the sweep then goes on. Every cell before the
    stuck one stays covered, so the sweep only moves forward. A failed repair proves nothing (the
    tiles outside the box could lie otherwise).
    """
    from htetro_opt._interrupt import kernel_flag
    from htetro_opt.solvers.tiling._sweep import dead_cells, sweep  # numba, imported only when needed

    h, w = occ.shape
    stride = w + 2 * _PAD
    grid = np.ones((h + 2 * _PAD, stride), dtype=np.uint8)
    grid[_PAD:_PAD + h, _PAD:_PAD + w] = occ[::-1]  # internal rows top first: flat index = scan order
    filled = grid.ravel().copy()
    order = _pattern_order(len(patterns), seed)
    rel = np.array([patterns[k].cells.tolist() for k in order], dtype=np.int64)
    offsets = np.ascontiguousarray(rel[:, :, 0] - rel[:, :, 1] * stride)
    owner = np.full(filled.size, -1, dtype=np.int64)
    tiles: list[np.ndarray | None] = []  # flat cells of each tile; None once lifted

    def add(cells: np.ndarray) -> None:
        owner[cells] = len(tiles)
        filled[cells] = 1
        tiles.append(cells)

    def repair(at: int, up: int, side: int) -> bool:
        """Re-cover the tiles inside the box and the stuck cell ``at``; False if no cover was found."""
        row, col = divmod(at, stride)
        r0, r1 = max(_PAD, row - up), min(_PAD + h - 1, row + up)
        c0, c1 = max(_PAD, col - side), min(_PAD + w - 1, col + side)
        box = np.zeros(grid.shape, dtype=bool)
        box[r0:r1 + 1, c0:c1 + 1] = True
        box = box.ravel()
        ids = np.unique(owner[box & (owner >= 0)])
        inside = [i for i in ids.tolist() if box[tiles[i]].all()]
        must = np.zeros(filled.size, dtype=bool)
        for i in inside:
            must[tiles[i]] = True
        must[at] = True
        near = np.zeros(grid.shape, dtype=bool)  # the cells a tile placed in the box can starve
        near[r0 - _PAD:r1 + _PAD + 1, c0 - _PAD:c1 + _PAD + 1] = True
        near = np.flatnonzero(near.ravel())
        crop = (slice(r0, r1 + 1), slice(c0, c1 + 1))  # as occupancy (y upwards): row r1 is y = 0
        for _ in range(_REPAIR_TRIES):
            may = box & (filled == 0) & ~must
            must_xy, may_xy = must.reshape(grid.shape)[crop][::-1], may.reshape(grid.shape)[crop][::-1]
            if not _area_fits(must_xy, may_xy):
                return False
            try:
                found = _cpsat_covers(must_xy, may_xy, patterns, seed, deadline, 1, work=_REPAIR_WORK)
            except _OutOfWork:
                return False
            if not found:
                return False
            new = [(r1 - tile[:, 1]) * stride + c0 + tile[:, 0] for tile in found[0]]
            for i in inside:
                filled[tiles[i]] = 0
            for cells in new:
                filled[cells] = 1
            # the cover knows nothing of the cells it leaves uncovered: one that no tile fits over
            # any more would stop the sweep for good, so it must be covered too, and CP-SAT runs again
            dead = dead_cells(filled, near, offsets)
            for cells in new:
                filled[cells] = 0
            for i in inside:
                filled[tiles[i]] = 1
            if not len(dead):
                for i in inside:
                    owner[tiles[i]] = -1
                    tiles[i] = None
                for cells in new:
                    add(cells)
                return True
            if not box[dead].all():
                return False  # a cell outside the box: a larger box takes it in
            must[dead] = True
        return False

    last = max(0, h - _SWEEP_FINAL)  # first row (y counted from the top) left to the final cover
    stop = (_PAD + last) * stride
    at = 0
    halt = kernel_flag()  # a signal under the command line: the sweep returns at once
    while True:
        anchors, kinds, at = sweep(filled, offsets, stride, _SWEEP_POCKET, at, stop, halt)
        for anchor, k in zip(anchors.tolist(), kinds.tolist()):
            owner[anchor + offsets[k]] = len(tiles)
            tiles.append(anchor + offsets[k])
        if at < 0:
            break
        for up, side in _REPAIR_BOXES:
            if repair(at, up, side):
                break
        else:
            return None
    # the last rows: the sweep would leave them to its last tiles' whims; covered exactly instead,
    # with more rows above lifted while no cover is found, by the backtracker first (it rarely
    # needs CP-SAT, which is slower on these long strips)
    for solver in ("backtracking", "cpsat"):
        for lift in _STRIP_LIFTS:
            top = _PAD + max(0, last - lift)
            below = np.zeros(grid.shape, dtype=bool)
            below[top:_PAD + h, _PAD:_PAD + w] = True
            below = below.ravel()
            ids = np.unique(owner[below & (owner >= 0)])
            inside = [i for i in ids.tolist() if below[tiles[i]].all()]
            must = below & (filled == 0)
            for i in inside:
                must[tiles[i]] = True
            must_xy = must.reshape(grid.shape)[top:_PAD + h, _PAD:_PAD + w][::-1]
            found = _strip_cover(must_xy, patterns, seed, deadline, solver) if must_xy.any() else [[]]
            if found:
                for i in inside:
                    tiles[i] = None
                y0 = _PAD + h - 1  # the crop's y = 0 is internal row _PAD + h - 1
                for tile in found[0]:
                    tiles.append((y0 - tile[:, 1]) * stride + _PAD + tile[:, 0])
                break
        else:
            continue
        break
    else:
        return None
    out = []
    for cells in tiles:
        if cells is not None:
            r, c = np.divmod(cells, stride)
            out.append(np.stack([c - _PAD, h - 1 - (r - _PAD)], axis=1).astype(np.int64))
    return _in_scan_order(out)


def _component_tilings(occ, patterns, seed, deadline, budget=None):
    """One tiling by CP-SAT, each 4-connected region of free cells on its own (the smallest first,
    so that a small region that cannot be tiled ends the search at once); [] when one has none.
    ``budget``: the caller's ``max_deterministic_time`` left, shared by the regions (or None)."""
    labels, n = ndimage.label(~occ)
    if n == 1:
        return _cpsat_covers(~occ, np.zeros_like(occ), patterns, seed, deadline, 1, budget=budget)
    sizes = np.bincount(labels.ravel())
    where = ndimage.find_objects(labels)
    tiles: list[np.ndarray] = []
    for i in sorted(range(1, n + 1), key=lambda i: (int(sizes[i]), i)):
        region, origin = _cropped(labels == i, where[i - 1])
        found = _cpsat_covers(region, np.zeros_like(region), patterns, seed, deadline, 1, budget=budget)
        if not found:
            return []
        tiles += [t + origin for t in found[0]]
    return [_in_scan_order(tiles)]


def _auto_tilings(occ, patterns, seed, deadline, limit, budget=None):
    """The ``auto`` portfolio: backtracking for :data:`_AUTO_STEPS`; then (one tiling) the repaired
    sweep on a map of :data:`_SWEEP_CELLS` free cells or more, the band stage on a map taller and
    wider than two bands, and CP-SAT region by region; or (several tilings) CP-SAT on the whole map.
    ``budget``: None, or ``[max_deterministic_time]`` for the last stage, the only one without a
    budget of its own (with it, no stage depends on the clock but the time limit)."""
    tiles = int((~occ).sum()) // 4
    found = []
    generator = _backtracking_tilings(occ, patterns, seed, deadline, [_AUTO_STEPS[0] + _AUTO_STEPS[1] * tiles])
    try:
        for tiling in generator:
            found.append(tiling)
            if len(found) >= limit:
                return found
        return found
    except _OutOfWork:  # the backtracker's step budget is spent: the stages below take over
        pass
    finally:
        generator.close()
    if limit > 1:
        return _cpsat_tilings(occ, patterns, seed, deadline, limit, budget)
    if 4 * tiles >= _SWEEP_CELLS:
        swept = _sweep_tiling(occ, patterns, seed, deadline)
        if swept is not None:
            return [swept]
    if min(occ.shape) > 2 * _BAND_ROWS:
        # bands along the short side, from one end, then from the other (where the first try ended)
        first = 1 if occ.shape[1] > occ.shape[0] else 0
        for turns in (first, first + 2):
            try:
                return _band_tiling(occ, patterns, seed, deadline, turns)
            except _OutOfWork:  # these bands proved nothing: from the other end, then CP-SAT
                pass
    return _component_tilings(occ, patterns, seed, deadline, budget)
