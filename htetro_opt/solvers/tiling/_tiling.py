"""Tiling a grid workspace with tetrominoes: the first phase of Le et al. 2018 (§3.1, Fig. 5).

The free cells of a workspace are covered exactly once by tetrominoes of the allowed morphologies
(all seven by default; the paper's Fig. 12c uses only Z and T, its Fig. 16c only O). Each tile then
becomes a waypoint: :func:`tile_workspace` hands the tiles to Algorithm 1
(:func:`~htetro_opt.problems.waypoint_sequencing.block_locations`), which numbers them in scan order
and labels their blocks a–d with a robot footprint.

Pre-checks
    Before any search both methods test the same necessary conditions, each failing with a
    :class:`~htetro_opt.errors.TilingError` that names what is wrong and where: a free cell exists;
    the free area is a multiple of 4; so is the area of every 4-connected region of free cells (a
    region of fewer than four cells is isolated); the colourings of tiling theory hold in every
    region — without T each tetromino covers 2 black and 2 white cells of a checkerboard (so the
    counts must be equal), T alone covers 3 + 1, L and J cover an odd number of cells of the even
    columns (and rows), I, O, S and Z an even one, and more generally the region's cell counts by
    ``(x mod 4, y mod 4)`` must be an integer combination of the allowed placements' counts (an
    integer-lattice test); and every free cell lies under some placement of an allowed shape.
    They are sound (never reject a tileable map) and catch most untileable maps at once.

``"backtracking"``, the paper's algorithm (its ref. 38, the classic polyomino tiling backtracker)
    Take the first uncovered free cell in scan order (top row first, then left to right), try each
    allowed fixed tetromino anchored there (the pattern's first cell in scan order on that cell, so
    it covers nothing before it), and go on; when no pattern fits, undo the previous placement and
    try its next pattern. The search is an explicit stack, not recursion (a 64 × 64 grid is 1024
    levels deep), on a padded flat byte grid, so that a placement test is three look-ups. It is
    complete (when it ends without a tiling, none exists) and pruned three ways:

    - after each placement, a flood fill from the uncovered cells next to the new tile; a region
      that is enclosed (the fill ends before reaching the rows 4 below the anchor, where no tile
      lies yet, or before :data:`EXACT_LIMIT` cells when it does reach them) must have an area that
      is a multiple of 4, equal checkerboard colours without T, and must tile on its own: a
      search of that region alone, turned so that it runs along the region's long side, cached by
      the region's shape;
    - everything before the anchor is covered and no tile reaches more than 3 rows below its
      anchor, so the anchor and the next ``3 W + 1`` cells are the whole state of the search: a
      state whose subtree held no tiling is remembered (as a 128-bit digest, up to
      :data:`MEMO_LIMIT` of them) and never searched again;
    - the pre-checks above.

    With ``shuffle=True`` the pattern order is shuffled once by the ``seed``'s generator (other
    tilings); without it the order is that of :data:`~htetro_opt.model.tiles.PATTERNS` (I, O, L, J,
    Z, S, T), which tiles a grid whose height is a multiple of 4 by vertical I's without a single
    backtrack. It tiles 64 × 64 grids, free or with scattered obstacle blocks, in well under a
    second; on cluttered maps with few allowed shapes (T with Z or I, say) it can still search for
    long, which is what ``time_limit`` and CP-SAT are for.

``"cpsat"``, OR-Tools CP-SAT on the exact-cover model
    One Boolean per placement (allowed pattern × anchor, all four cells free) and ``AddExactlyOne``
    over the placements covering each free cell. The placements are declared, in the backtracker's
    order, as a decision strategy, and CP-SAT's portfolio search takes turns between it and its own
    heuristics, with propagation and clause learning. Presolve, probing, symmetry detection and
    inprocessing are off: on 24 × 24 to 64 × 64 grids they cost seconds and find nothing. It runs
    on one worker with a ``random_seed`` (0, or drawn from ``seed`` with ``shuffle=True``) and the
    pattern order, so a seed gives one tiling, reproducibly, and other seeds others. It takes a few
    seconds on 64 × 64 grids and proves untileability where the backtracker would search for long.
    Building the model counts against ``time_limit`` (on a free 256 × 256 grid it takes seconds):
    the clock is read while it is built, and CP-SAT gets what is left.

``"auto"`` (the default), a portfolio of fixed, machine-independent budgets (a choice of ours)
    Each tiler has its tails (benchmarks/README.md, "Tiling without tails"): the backtracker can
    search for minutes on a 10 × 10 map or a 64 × 64 one with scattered obstacles, which CP-SAT
    tiles in a fraction of a second and a few seconds; CP-SAT needs minutes on 128 × 128 and larger
    maps that the backtracker tiles in a second. Both thrash for the same reason: a choice made
    early in scan order is found wrong only rows later. So ``auto`` runs, in turn:

    1. the backtracker for :data:`AUTO_STEPS` search steps (a thousand plus 4 a tile): the
       paper's maps, free grids and ``tiling_64x64`` need fewer, so they keep its tiling;
    2. on a map of :data:`SWEEP_CELLS` free cells or more, the repaired sweep (one tiling): a
       compiled (numba) pass in the backtracker's scan and pattern order that never backtracks. It
       keeps the first placement after which every uncovered cell within 3 cells still lies under a
       placement that fits and no enclosed pocket of up to :data:`SWEEP_POCKET` cells has an area
       that is not a multiple of 4. Where no placement passes, the tiles inside a box of
       :data:`REPAIR_BOXES` above the stuck cell are lifted and CP-SAT (:data:`REPAIR_WORK`) covers
       their cells and the stuck cell exactly, the box's other uncovered cells at most once (and,
       where it leaves one of them under no tile that fits, that one too, :data:`REPAIR_TRIES`
       times at most); the sweep then goes on. It leaves the last :data:`SWEEP_FINAL` rows, where
       its greed would corner it against the wall, to one exact cover of that strip (lifting
       :data:`STRIP_LIFTS` rows above while none is found): the backtracker turned to run along
       the strip, whose memo then holds the few states of a short cross-section, for
       :data:`STRIP_STEPS` from one end and then from the other, then CP-SAT. A sweep that cannot
       go on proves nothing (the tiles around a box could lie otherwise), and the next stage runs;
    3. on a map taller and wider than two bands, CP-SAT band after band: the uncovered cells of
       :data:`BAND_ROWS` rows from the top are covered exactly (and at most once the 3 rows below,
       which tiles of the band reach), the tiles whose first cell lies in the band's top
       :data:`BAND_COMMIT` rows are kept, and the next band starts below them. Each band has
       :data:`BAND_WORK` of CP-SAT's deterministic time. The bands run along the map's short side,
       and when a band fails, once more from the opposite side. A first band that cannot be
       covered proves that the map cannot be tiled (any tiling holds a cover of it); a later one
       proves nothing (the bands above might have been tiled otherwise), and the next stage runs;
    4. CP-SAT on each 4-connected region of free cells on its own, the smallest first (a small
       region that cannot be tiled ends the search at once), until it finds a tiling, proves
       there is none, or the time limit runs out: then the error says that neither was found.

    Several tilings (:func:`enumerate_tilings`) go from stage 1 to CP-SAT on the whole map. Every
    budget is counted in steps or CP-SAT's deterministic time, not seconds, so a map gets the same
    tiling on every machine; only ``time_limit`` depends on the clock.

Time limit
    Every method is exact, and a map can pass every pre-check, have no tiling, and take a search
    hours to prove it (a 64 × 62 rectangle with T alone, which has none since 4 does not divide 62).
    So a call is bounded: by ``time_limit``, or by :data:`DEFAULT_TIME_LIMIT` (60 s) when it is None.
    A search cut short raises :class:`TilingTimeLimitError`, a subclass of
    :class:`~htetro_opt.errors.TilingError` that says the map may still be tileable; a plain
    TilingError is a proof that it is not.

Overlapping sub-workspaces (§3.1, Fig. 5d–f)
    "If the size of the coverage area is not a multiple of hTetro blocks, we can segment this
    workspace into two partially overlapping sub-workspaces and both can be tiled." The paper gives
    no rule for the segmentation; ours: with ``overlap=True``, a map that does not tile as it is
    (a pre-check fails or no tiling exists) is split into two bands of rows, ``y < k2`` and
    ``y >= k1`` with ``1 <= k1 < k2 <= H - 1`` (so that both are proper sub-grids, sharing rows
    ``k1 … k2 − 1``), or two bands of columns likewise, whose free cells both tile; the split with
    the fewest shared free cells wins, ties going to rows before columns, then to the smaller
    ``k1`` (then ``k2``). Both bands' tiles are kept, so the shared cells are covered twice
    (:meth:`~htetro_opt.scenarios.tileset.Tileset.coverage` is 2 there): a free grid 6 wide and 7
    high (area 42) splits into rows 0–1 and rows 1–6, 12 tiles covering its 42 cells with the 6
    cells of row 1 covered twice.

Examples
--------
>>> tile_workspace(np.zeros((2, 4), dtype=bool)).shapes
('I', 'I')
>>> ts = tile_workspace(np.zeros((2, 4), dtype=bool), shapes="O")
>>> ts.ids, ts.shapes, ts.complete
((1, 2), ('O', 'O'), True)
"""

from __future__ import annotations

import functools
import reprlib
import time as _time
from hashlib import blake2b

import numpy as np
from scipy import ndimage

from htetro_opt._interrupt import on_signal
from htetro_opt._validation import (
    check_bool,
    check_int,
    check_seed,
    check_time_limit,
    derive_seed,
)
from htetro_opt.errors import ParameterError, ScenarioError, TilingError, TilingTimeLimitError
from htetro_opt.model.tiles import Pattern, patterns_of
from htetro_opt.model.workspace import Workspace
from htetro_opt.problems.waypoint_sequencing import (
    DEFAULT_BLOCK_WEIGHTS,
    block_locations,
    check_weights,
)
from htetro_opt.scenarios.tileset import Tileset

__all__ = [
    "AUTO_STEPS",
    "DEFAULT_TIME_LIMIT",
    "BAND_COMMIT",
    "BAND_ROWS",
    "BAND_WORK",
    "EXACT_LIMIT",
    "FLOOD_LIMIT",
    "MEMO_LIMIT",
    "REPAIR_BOXES",
    "REPAIR_TRIES",
    "REPAIR_WORK",
    "STRIP_LIFTS",
    "STRIP_STEPS",
    "SWEEP_CELLS",
    "SWEEP_FINAL",
    "SWEEP_POCKET",
    "TILING_METHODS",
    "TilingTimeLimitError",
    "enumerate_tilings",
    "find_tiles",
    "tile_workspace",
]

TILING_METHODS = ("auto", "backtracking", "cpsat")
"""The tiling methods: a portfolio of the others (the default), the paper's backtracking search and
OR-Tools CP-SAT."""

DEFAULT_TIME_LIMIT = 60.0
"""Seconds a tiling may take when ``time_limit`` is None (the library's, the CLI's and the study
runner's default). Every method is exact, so on a map that passes every pre-check but has no tiling
the search may have to go through a great many partial tilings before it proves so (a 64 × 64 map
with T and Z only, say): without a bound such a call could run for hours."""

FLOOD_LIMIT = 4096
"""Most cells the backtracker's pruning flood fill visits before it treats a region as open."""

EXACT_LIMIT = 64
"""Regions of uncovered cells up to this size are checked exactly (a search of the region alone)
whenever a placement encloses them, however far they reach."""

MEMO_LIMIT = 1_000_000
"""Most failed search states the backtracker remembers (a 16-byte digest each, ~0.1 GB at the limit)."""

_PAD = 3  # a pattern reaches at most 3 cells from its anchor in x and y
_CHECK_EVERY = 2048  # search steps between two looks at the clock
_BUILD_CHUNK = 1 << 15  # CP-SAT variables or constraints built between two looks (~0.1 s)
_LOAD_SHARE = 0.25  # CP-SAT's model load, as a share of the model's build time (see _cpsat_covers)


class _TimeLimit(TilingError):
    """The time limit ran out (the map may still be tileable): never a reason to try a split."""


def _check_clock(deadline) -> None:
    if deadline is not None and _time.perf_counter() > deadline:
        raise _TimeLimit("time limit")


class _OutOfWork(Exception):
    """A stage of the ``auto`` portfolio used up its work budget: the next stage takes over."""


# ------------------------------------------------------------------------------------------------
# Validation


def _as_occupancy(workspace, name: str) -> tuple[np.ndarray, float]:
    if isinstance(workspace, Workspace):
        return workspace.occupancy, workspace.cell_size
    try:
        return Workspace(workspace).occupancy, 1.0
    except ScenarioError as err:  # an argument here, not a file's content
        got = (f"an array of shape {workspace.shape}" if isinstance(workspace, np.ndarray)
               else f"{type(workspace).__name__} {reprlib.repr(workspace)}")
        raise ParameterError(f"{name} must be a Workspace or a non-empty 2-D (H, W) array of booleans "
                             f"(True = obstacle) or 0/1, got {got}") from err


def _check_shapes(shapes) -> tuple[Pattern, ...]:
    if shapes is not None:
        try:
            names = list(shapes)  # "TZ" -> ["T", "Z"]
        except TypeError as err:
            raise ParameterError(f"shapes must be morphology names such as 'TZ' or ['O'], got {shapes!r}") from err
        if not names:
            raise ParameterError("shapes is empty: allow at least one morphology (I, O, L, J, Z, S, T)")
        shapes = names
    return patterns_of(shapes)


def _check_options(method, shuffle, seed, time_limit) -> tuple[int | None, float, float]:
    """The search's order seed (None: the fixed order), its deadline and its time limit (None:
    :data:`DEFAULT_TIME_LIMIT`), all options checked (the seed too when ``shuffle`` is off and it
    goes unused: a bad value is a mistake either way)."""
    if method not in TILING_METHODS:
        raise ParameterError(f"unknown tiling method {method!r}: expected one of {', '.join(TILING_METHODS)}")
    seed = check_seed(seed)
    order_seed = derive_seed(seed) if check_bool(shuffle, "shuffle") else None
    time_limit = check_time_limit(time_limit)
    if time_limit is None:
        time_limit = DEFAULT_TIME_LIMIT
    return order_seed, _time.perf_counter() + time_limit, time_limit


# ------------------------------------------------------------------------------------------------
# Placements and pre-checks


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


def _cell_text(x, y) -> str:
    return f"({int(x)}, {int(y)})"


def _first_in_scan(mask: np.ndarray) -> tuple[int, int]:
    ys, xs = np.nonzero(mask)
    i = np.lexsort((xs, -ys))[0]
    return int(xs[i]), int(ys[i])


def _colour_rules(patterns) -> tuple:
    """What the colourings prove for this set of patterns.

    Returns (checkerboard, columns, rows): checkerboard is "equal" (every pattern covers 2 black and
    2 white cells: all but T), "T" (every pattern covers 3 of one colour and 1 of the other: T alone)
    or None; columns / rows are "odd" (every pattern covers an odd number of cells in even columns /
    rows: L and J), "even" (I, O, S, Z) or None (mixed; T has both).
    """
    diffs = {abs(int(((p.cells.sum(axis=1) % 2) == 0).sum()) * 2 - 4) for p in patterns}
    board = "equal" if diffs == {0} else "T" if diffs == {2} else None
    stripes = []
    for axis in (0, 1):
        parities = {int((p.cells[:, axis] % 2 == 0).sum()) % 2 for p in patterns}
        stripes.append("odd" if parities == {1} else "even" if parities == {0} else None)
    return (board, *stripes)


_PERIOD = 4  # cells are counted by (x mod 4, y mod 4): 16 classes


@functools.cache
def _class_lattice(shapes: str) -> tuple:
    """An echelon basis (over the integers) of the class counts that tilings by these shapes can have.

    A placement of a pattern adds one to the class of each of its cells; whatever the tiling, a
    region's class counts are a sum of such vectors, so they must lie in the lattice the vectors
    span (the colouring arguments of tiling theory, checkerboards and stripes among them).
    Returns (pivot column, row) pairs, rows as tuples of Python ints.
    """
    m = _PERIOD
    rows = []
    for pattern in patterns_of(shapes):
        for ax in range(m):
            for ay in range(m):
                v = [0] * (m * m)
                for dx, dy in pattern.cells.tolist():
                    v[((ax + dx) % m) * m + (ay + dy) % m] += 1
                rows.append(v)
    basis = []
    for col in range(m * m):
        live = [r for r in rows if r[col]]
        rows = [r for r in rows if not r[col]]
        while len(live) > 1:  # Euclid on the column
            live.sort(key=lambda r: abs(r[col]))
            pivot, rest = live[0], []
            for r in live[1:]:
                q = r[col] // pivot[col]
                r = [a - q * b for a, b in zip(r, pivot)]
                (rest if r[col] else rows).append(r)
            live = [pivot] + rest
        if live:
            pivot = live[0] if live[0][col] > 0 else [-a for a in live[0]]
            basis.append((col, tuple(pivot)))
        rows = [r for r in rows if any(r)]
    return tuple(basis)


def _class_counts(xs, ys) -> list[int]:
    counts = np.bincount((np.asarray(xs) % _PERIOD) * _PERIOD + np.asarray(ys) % _PERIOD, minlength=_PERIOD ** 2)
    return [int(c) for c in counts]


def _in_lattice(basis, counts) -> bool:
    t = list(counts)
    for col, row in basis:
        q, r = divmod(t[col], row[col])
        if r:
            return False
        if q:
            t = [a - q * b for a, b in zip(t, row)]
    return not any(t)


def _violation(occ: np.ndarray, patterns) -> str | None:
    """The first necessary condition for a tiling that the free cells fail, as a message, or None."""
    free = ~occ
    allowed = _shape_text(patterns)
    n_free = int(free.sum())
    if n_free == 0:
        return "the workspace has no free cell to tile"
    if n_free % 4:
        return (f"the free area is {n_free} cells, not a multiple of 4: no tetromino tiling covers it "
                "exactly (the overlap option, --overlap on the command line, covers it by two overlapping sub-workspaces)")
    labels, n = ndimage.label(free)  # 4-connected
    ys, xs = np.nonzero(free)
    scan = np.lexsort((xs, -ys))
    ids, first = np.unique(labels[ys[scan], xs[scan]], return_index=True)
    # each region named by its first cell in scan order, the regions in that order
    regions = sorted(((int(xs[scan[j]]), int(ys[scan[j]])), int(i)) for i, j in zip(ids, first))
    regions.sort(key=lambda r: (-r[0][1], r[0][0]))
    sizes = np.bincount(labels.ravel(), minlength=n + 1)
    for (x, y), i in regions:
        size = int(sizes[i])
        if size % 4 and size < 4:
            return (f"the region around cell {_cell_text(x, y)} has {size} free cell{'s' if size > 1 else ''}, "
                    "isolated and too small for a tetromino")
        if size % 4:
            return f"the region around cell {_cell_text(x, y)} has {size} free cells, not a multiple of 4"
    board, columns, rows = _colour_rules(patterns)
    for (x, y), i in regions:
        inside = labels[ys, xs] == i
        what = "the free cells" if n == 1 else f"the region around cell {_cell_text(x, y)}"
        tiles = int(sizes[i]) // 4
        black = int((((xs + ys) % 2 == 0) & inside).sum())
        white = int(sizes[i]) - black
        if board == "equal" and black != white:
            return (f"{what} hold {black} black and {white} white cells of a checkerboard; every tetromino but T "
                    f"covers 2 of each, so without T ({allowed} allowed) they must be equal")
        if board == "T" and (abs(black - white) // 2 - tiles) % 2:
            return (f"{what} hold {black} black and {white} white cells of a checkerboard; each T covers 3 of one "
                    f"colour and 1 of the other, so {tiles} T tiles need (black - white) / 2 to be "
                    f"{'odd' if tiles % 2 else 'even'}")
        for rule, coords, line in ((columns, xs, "column"), (rows, ys, "row")):
            even = int(((coords % 2 == 0) & inside).sum())
            if rule == "odd" and (even - tiles) % 2:
                return (f"{what} hold {even} cells in even {line}s; every allowed tetromino ({allowed}) covers an "
                        f"odd number of them, so {tiles} tiles need an {'odd' if tiles % 2 else 'even'} count")
            if rule == "even" and even % 2:
                return (f"{what} hold {even} cells in even {line}s; every allowed tetromino ({allowed}) covers an "
                        "even number of them, so the count must be even")
        if not _in_lattice(_class_lattice(allowed), _class_counts(xs[inside], ys[inside])):
            return (f"{what} cannot be tiled by {allowed}: counting its cells by (x mod 4, y mod 4) gives "
                    f"16 counts that no set of {allowed} tiles adds up to")
    _, cells = _placements(free, patterns)
    covered = np.zeros_like(free)
    covered[cells[..., 1].ravel(), cells[..., 0].ravel()] = True
    stuck = free & ~covered
    if stuck.any():
        x, y = _first_in_scan(stuck)
        more = int(stuck.sum()) - 1
        return (f"no tile of the allowed shapes ({allowed}) fits over cell {_cell_text(x, y)}"
                f"{f' (nor over {more} more cells)' if more else ''}")
    return None


def _precheck(occ: np.ndarray, patterns) -> None:
    """The necessary conditions every method checks first; TilingError naming the first that fails."""
    problem = _violation(occ, patterns)
    if problem is not None:
        raise TilingError(problem)


# ------------------------------------------------------------------------------------------------
# Backtracking


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


# ------------------------------------------------------------------------------------------------
# CP-SAT


def _pattern_order(n: int, seed) -> list[int]:
    """The order patterns are tried in: as given, or shuffled by the seed."""
    if seed is None:
        return list(range(n))
    return np.random.default_rng(seed).permutation(n).tolist()


def _cpsat_tilings(occ, patterns, seed, deadline, limit):
    """Up to ``limit`` tilings by CP-SAT; [] when infeasible; _TimeLimit when out of time with none."""
    return _cpsat_covers(~occ, np.zeros_like(occ), patterns, seed, deadline, limit)


def _cpsat_covers(must, may, patterns, seed, deadline, limit, work=None):
    """Up to ``limit`` sets of tiles covering each ``must`` cell exactly once and each ``may`` cell at
    most once (every tile touching a ``must`` cell), by CP-SAT; [] when there is none.

    Raises _TimeLimit when the deadline comes first, _OutOfWork when ``work`` (CP-SAT's
    deterministic seconds, the same on every machine) runs out first. The model's build counts
    against the deadline (on a free 256 × 256 grid, 1.2 million placements, it takes seconds in
    OR-Tools' Python layer), so the clock is read every :data:`_BUILD_CHUNK` variables or constraints
    and CP-SAT gets only what is left.
    """
    from ortools.sat.python import cp_model

    which, cells = _placements(must | may, patterns)
    touching = must[cells[..., 1], cells[..., 0]].any(axis=1)
    which, cells = which[touching], cells[touching]
    # placements in search order: anchor (cells[:, 0]) in scan order, then the seed's pattern order
    rank = np.empty(len(patterns), dtype=np.int64)
    rank[_pattern_order(len(patterns), seed)] = np.arange(len(patterns))
    by = np.lexsort((rank[which], cells[:, 0, 0], -cells[:, 0, 1]))
    cells = cells[by]
    began = _time.perf_counter()
    model = cp_model.CpModel()
    xs = []
    for start in range(0, len(cells), _BUILD_CHUNK):
        _check_clock(deadline)
        xs += [model.NewBoolVar("") for _ in range(min(_BUILD_CHUNK, len(cells) - start))]
    h, w = must.shape
    flat = (cells[..., 1] * w + cells[..., 0]).ravel()
    owner = np.repeat(np.arange(len(cells)), 4)
    by_cell = np.argsort(flat, kind="stable")
    bounds = np.searchsorted(flat[by_cell], np.arange(h * w + 1)).tolist()
    owner = owner[by_cell].tolist()
    for k, c in enumerate(np.flatnonzero(must.ravel()).tolist()):
        if k % _BUILD_CHUNK == 0:
            _check_clock(deadline)
        model.AddExactlyOne([xs[i] for i in owner[bounds[c]:bounds[c + 1]]])
    for k, c in enumerate(np.flatnonzero(may.ravel()).tolist()):
        if k % _BUILD_CHUNK == 0:
            _check_clock(deadline)
        if bounds[c + 1] - bounds[c] > 1:
            model.AddAtMostOne([xs[i] for i in owner[bounds[c]:bounds[c + 1]]])
    # The backtracker's order, declared as a search strategy: CP-SAT's portfolio (one worker) takes
    # turns between it and its own heuristics at each restart, with propagation and clause learning.
    # Declared in chunks with a look at the clock between them (one AddDecisionStrategy call over
    # 1.2 million variables takes seconds): consecutive CHOOSE_FIRST strategies branch exactly as
    # one over their concatenation, since CP-SAT moves to the next only when all of one are fixed.
    for start in range(0, len(xs), _BUILD_CHUNK):
        _check_clock(deadline)
        model.AddDecisionStrategy(xs[start:start + _BUILD_CHUNK], cp_model.CHOOSE_FIRST, cp_model.SELECT_MAX_VALUE)

    solver = cp_model.CpSolver()
    params = solver.parameters
    params.catch_sigint_signal = False  # Ctrl-C goes to Python (see htetro_opt._interrupt), not CP-SAT
    params.num_workers = 1  # one worker: the search, hence the tiling, is reproducible
    params.random_seed = 0 if seed is None else int(seed)
    params.search_branching = cp_model.PORTFOLIO_SEARCH
    # measured on 24 x 24 to 64 x 64 grids: presolve, probing and inprocessing cost seconds and
    # find nothing on an exact cover; the fixed search alone stalls on some maps (h_shape), and
    # CP-SAT's default parameters time out on 64 x 64 maps it solves in seconds like this
    params.cp_model_presolve = False
    params.cp_model_probing_level = 0
    params.linearization_level = 0
    params.symmetry_level = 0
    params.use_sat_inprocessing = False
    if work is not None:
        params.max_deterministic_time = work
    if deadline is not None:
        # CP-SAT loads the model without looking at its time limit: on the free 256 x 256 grid the
        # load took 0.8 s after a 6 s build (it overran a 3.8 s limit to 4.6 s), so a quarter of
        # the build's time, measured on this machine as it is loaded now, is set aside for it
        now = _time.perf_counter()
        left = deadline - now - _LOAD_SHARE * (now - began)
        if left <= 0:
            raise _TimeLimit("time limit")
        params.max_time_in_seconds = left

    found: list[list[np.ndarray]] = []

    def record(values) -> None:
        chosen = np.flatnonzero(np.asarray(values, dtype=np.int64)[:len(cells)])
        found.append([cells[i].copy() for i in chosen.tolist()])

    class _Collect(cp_model.CpSolverSolutionCallback):
        def on_solution_callback(self):  # OR-Tools' hook
            record(self.response_proto.solution)
            if len(found) >= limit:
                self.StopSearch()

    if limit > 1:
        params.enumerate_all_solutions = True
        with on_signal(solver.StopSearch):  # Ctrl-C stops CP-SAT now, not at its time limit
            status = solver.Solve(model, _Collect())
    else:
        with on_signal(solver.StopSearch):
            status = solver.Solve(model)
        if status in (cp_model.OPTIMAL, cp_model.FEASIBLE):
            record(solver.response_proto.solution)
    if found:
        return found
    if status == cp_model.INFEASIBLE:
        return []
    if status == cp_model.UNKNOWN:
        if deadline is not None and _time.perf_counter() >= deadline - 1e-3:
            raise _TimeLimit("time limit")
        if work is not None:
            raise _OutOfWork
        raise _TimeLimit("time limit")  # stopped by a signal handler that did not raise
    raise TilingError(f"CP-SAT ended with status {solver.StatusName(status)} on the tiling model")


# ------------------------------------------------------------------------------------------------
# The auto portfolio


AUTO_STEPS = (1_000, 4)
"""The backtracking stage of ``auto``: ``a + b × tiles`` search steps (deterministic), then the next
stage. The paper's maps take at most 626 steps, ``tiling_64x64`` 3095 (1004 tiles) and free grids
about 3 a tile, so they keep the backtracker's tiling; a small map it cannot tile at once goes to
CP-SAT after a fraction of a second (a thousand steps, not five, since 2026-11-26: on 10 × 10 maps
the rest was wasted)."""

BAND_ROWS = 12
"""Rows of the cells a band of the ``auto`` portfolio's band stage covers exactly (3 more rows below
it may be covered, by tiles that stick out of it)."""

BAND_COMMIT = 6
"""Rows from the top of a band whose tiles (by their first cell) are kept before the next band."""

BAND_WORK = 2.0
"""CP-SAT's deterministic time (its own unit, about a second, the same on every machine) for one band."""


def _band_tiling(occ, patterns, seed, deadline, turns):
    """One tiling by CP-SAT, band after band of :data:`BAND_ROWS` rows from the top; [] when the
    first band has no cover (a proof: any tiling restricted to the tiles touching it is one);
    _OutOfWork when a later band has none or CP-SAT spends :data:`BAND_WORK` on one (no proof:
    the bands above could have been tiled otherwise)."""
    grid = np.rot90(occ, turns)  # a quarter turn maps each tetromino onto one of its own shape
    h = grid.shape[0]
    covered = grid.copy()
    tiles: list[np.ndarray] = []
    top = 0  # the rows y >= h - top are covered
    while True:
        lo, hi = max(0, h - top - BAND_ROWS), h - top
        must = np.zeros_like(grid)
        must[lo:hi] = ~covered[lo:hi]
        may = np.zeros_like(grid)
        may[max(0, lo - _PAD):lo] = ~covered[max(0, lo - _PAD):lo]
        found = _cpsat_covers(must, may, patterns, seed, deadline, 1, work=BAND_WORK)
        if not found:
            if top == 0:
                return []
            raise _OutOfWork
        band = found[0]
        if lo == 0:
            tiles += band
            break
        cut = h - top - BAND_COMMIT  # keep the tiles whose first cell lies in the band's top rows
        for tile in band:
            if tile[:, 1].max() >= cut:
                tiles.append(tile)
                covered[tile[:, 1], tile[:, 0]] = True
        top += BAND_COMMIT
    back = np.zeros(grid.shape, dtype=np.int64)  # cell (x', y') of grid → flat index (y, x) of occ
    back[:] = np.rot90(np.arange(occ.size).reshape(occ.shape), turns)
    w = occ.shape[1]
    return [[np.stack([back[t[:, 1], t[:, 0]] % w, back[t[:, 1], t[:, 0]] // w], axis=1) for t in tiles]]


REPAIR_BOXES = ((4, 6), (8, 12), (16, 24))
"""The repairs of ``auto``'s sweep: (rows above, columns either side) of the cell it is stuck at, the
tiles inside the box re-covered exactly with that cell, each box tried in turn."""

REPAIR_WORK = 1.0
"""CP-SAT's deterministic time (its own unit, the same on every machine) for one repair."""

REPAIR_TRIES = 8
"""Most CP-SAT runs of one repair (each run adds the cells the previous cover left under no tile)."""

SWEEP_CELLS = 1024
"""Free cells from which ``auto`` runs the sweep after the backtracker (smaller maps go to CP-SAT,
which takes well under a second on them, without loading numba)."""

SWEEP_POCKET = 64
"""Largest enclosed pocket of uncovered cells whose area the sweep's look-ahead measures."""

SWEEP_FINAL = 8
"""The last rows of the map, which the sweep leaves to one exact cover of a strip (lifting
:data:`STRIP_LIFTS` more rows above while that finds none)."""

STRIP_LIFTS = (0, 8, 16, 24)
"""Rows above the last :data:`SWEEP_FINAL` whose tiles the final cover lifts, tried in turn."""

STRIP_STEPS = (2_000, 4)
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
    :data:`STRIP_STEPS` from one end, then from the other, or by CP-SAT for :data:`REPAIR_WORK`."""
    if solver == "cpsat":
        try:
            return _cpsat_covers(must, np.zeros_like(must), patterns, seed, deadline, 1, work=REPAIR_WORK)
        except _OutOfWork:
            return []
    first = 1 if must.shape[1] > must.shape[0] else 0
    # from either end: one often takes a few hundred steps where the other needs millions (the
    # search meets the strip's hardest stretch early or late)
    for turns in (first, first + 2):
        turned = np.rot90(~must, turns)  # a quarter turn maps each tetromino onto one of its own shape
        budget = [STRIP_STEPS[0] + STRIP_STEPS[1] * int(must.sum()) // 4]
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
    its look-ahead. Where none does, the tiles inside a box of :data:`REPAIR_BOXES` above the stuck
    cell are lifted and CP-SAT (:data:`REPAIR_WORK`) covers their cells and the stuck cell exactly,
    the box's uncovered cells below at most once; the sweep then goes on. Every cell before the
    stuck one stays covered, so the sweep only moves forward. A failed repair proves nothing (the
    tiles outside the box could lie otherwise).
    """
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
        for _ in range(REPAIR_TRIES):
            may = box & (filled == 0) & ~must
            must_xy, may_xy = must.reshape(grid.shape)[crop][::-1], may.reshape(grid.shape)[crop][::-1]
            if not _area_fits(must_xy, may_xy):
                return False
            try:
                found = _cpsat_covers(must_xy, may_xy, patterns, seed, deadline, 1, work=REPAIR_WORK)
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

    last = max(0, h - SWEEP_FINAL)  # first row (y counted from the top) left to the final cover
    stop = (_PAD + last) * stride
    at = 0
    while True:
        anchors, kinds, at = sweep(filled, offsets, stride, SWEEP_POCKET, at, stop)
        for anchor, k in zip(anchors.tolist(), kinds.tolist()):
            owner[anchor + offsets[k]] = len(tiles)
            tiles.append(anchor + offsets[k])
        if at < 0:
            break
        for up, side in REPAIR_BOXES:
            if repair(at, up, side):
                break
        else:
            return None
    # the last rows: the sweep would leave them to its last tiles' whims; covered exactly instead,
    # with more rows above lifted while no cover is found, by the backtracker first (it rarely
    # needs CP-SAT, which is slower on these long strips)
    for solver in ("backtracking", "cpsat"):
        for lift in STRIP_LIFTS:
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


def _component_tilings(occ, patterns, seed, deadline):
    """One tiling by CP-SAT, each 4-connected region of free cells on its own (the smallest first,
    so that a small region that cannot be tiled ends the search at once); [] when one has none."""
    labels, n = ndimage.label(~occ)
    if n == 1:
        return _cpsat_covers(~occ, np.zeros_like(occ), patterns, seed, deadline, 1)
    sizes = np.bincount(labels.ravel())
    where = ndimage.find_objects(labels)
    tiles: list[np.ndarray] = []
    for i in sorted(range(1, n + 1), key=lambda i: (int(sizes[i]), i)):
        region, origin = _cropped(labels == i, where[i - 1])
        found = _cpsat_covers(region, np.zeros_like(region), patterns, seed, deadline, 1)
        if not found:
            return []
        tiles += [t + origin for t in found[0]]
    return [_in_scan_order(tiles)]


def _auto_tilings(occ, patterns, seed, deadline, limit):
    """The ``auto`` portfolio: backtracking for :data:`AUTO_STEPS`; then (one tiling) the repaired
    sweep on a map of :data:`SWEEP_CELLS` free cells or more, the band stage on a map taller and
    wider than two bands, and CP-SAT region by region; or (several tilings) CP-SAT on the whole map."""
    tiles = int((~occ).sum()) // 4
    found = []
    generator = _backtracking_tilings(occ, patterns, seed, deadline, [AUTO_STEPS[0] + AUTO_STEPS[1] * tiles])
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
        return _cpsat_tilings(occ, patterns, seed, deadline, limit)
    if 4 * tiles >= SWEEP_CELLS:
        swept = _sweep_tiling(occ, patterns, seed, deadline)
        if swept is not None:
            return [swept]
    if min(occ.shape) > 2 * BAND_ROWS:
        # bands along the short side, from one end, then from the other (where the first try ended)
        first = 1 if occ.shape[1] > occ.shape[0] else 0
        for turns in (first, first + 2):
            try:
                return _band_tiling(occ, patterns, seed, deadline, turns)
            except _OutOfWork:  # these bands proved nothing: from the other end, then CP-SAT
                pass
    return _component_tilings(occ, patterns, seed, deadline)


# ------------------------------------------------------------------------------------------------
# Drivers


def _time_message(method, time_limit) -> str:
    if method == "backtracking":
        return (f"the backtracking search found no tiling and proved none impossible within the time limit of "
                f"{time_limit:g} s; try the auto or cpsat method or a longer time limit")
    if method == "auto":
        return (f"no tiling found and none proven impossible within the time limit of {time_limit:g} s "
                "(backtracking, bands, then CP-SAT); try a longer time limit")
    return (f"CP-SAT found no tiling and proved none impossible within the time limit of {time_limit:g} s "
            "(building its model included); try a longer time limit")


def _tilings(occ, patterns, method, seed, deadline, limit):
    """Pre-checks, then up to ``limit`` tilings (non-empty list) or TilingError / _TimeLimit."""
    _precheck(occ, patterns)
    if method == "backtracking":
        found = []
        generator = _backtracking_tilings(occ, patterns, seed, deadline)
        try:
            for tiles in generator:
                found.append(tiles)
                if len(found) >= limit:
                    break
        except _TimeLimit:
            if not found:
                raise
        finally:
            generator.close()
    elif method == "auto":
        found = _auto_tilings(occ, patterns, seed, deadline, limit)
    else:
        found = _cpsat_tilings(occ, patterns, seed, deadline, limit)
    if not found:
        raise TilingError(
            f"no tiling of the {int((~occ).sum())} free cells by {_shape_text(patterns)} tetrominoes exists "
            f"(the {method} search is exhaustive)"
        )
    return found


def _retime(method, time_limit) -> TilingTimeLimitError:
    """The error the caller sees when the time limit ran out."""
    return TilingTimeLimitError(_time_message(method, time_limit), time_limit=time_limit, method=method)


def find_tiles(occupancy, *, shapes=None, method: str = "auto", shuffle: bool = False, seed=None,
               time_limit: float | None = None) -> list[np.ndarray]:
    """An exact cover of the free cells by tetrominoes of the allowed shapes.

    Parameters
    ----------
    occupancy : ndarray of bool, shape (H, W), or Workspace
        ``occ[y, x]``, True for an obstacle.
    shapes : iterable of str, optional
        The allowed morphologies, e.g. ``"TZ"`` or ``["O"]``; all seven when None.
    method : {"auto", "backtracking", "cpsat"}
        The portfolio (default), the paper's backtracking search or CP-SAT (see the module
        docstring). ``auto`` gives the backtracker's tiling wherever the backtracker needs few steps.
    shuffle : bool
        False (default): the fixed pattern order, one tiling per map, ``seed`` unused. True: the
        pattern order (and CP-SAT's random seed) drawn from ``seed``, for another tiling.
    seed : None, int or numpy.random.Generator
        With ``shuffle``: an int or a Generator gives the same tiling every time, None a fresh one.
    time_limit : float, optional
        Seconds the search may take, model building included; :data:`DEFAULT_TIME_LIMIT` (60 s)
        when None.

    Returns
    -------
    list of ndarray of int, shape (4, 2)
        The cells ``(x, y)`` of each tile, the tiles in scan order of their first cell.

    Raises
    ------
    TilingTimeLimitError
        If the time limit runs out first: neither a tiling nor a proof that none exists was found
        (a subclass of TilingError, so catch it first to tell the two apart).
    TilingError
        If a pre-check fails (no free cell; free area, or a 4-connected region's area, not a multiple
        of 4; unequal checkerboard colours without T; a cell no allowed tile fits over) or no tiling
        exists: a proof that the map cannot be tiled.
    UnknownShapeError
        If a shape name is unknown.
    ParameterError
        If ``shapes`` is empty, or ``method``, ``seed`` or ``time_limit`` is invalid.

    Examples
    --------
    >>> tiles = find_tiles(np.zeros((4, 2), dtype=bool), shapes="O")
    >>> [t.tolist() for t in tiles]
    [[[0, 3], [1, 3], [0, 2], [1, 2]], [[0, 1], [1, 1], [0, 0], [1, 0]]]
    """
    occ, _ = _as_occupancy(occupancy, "occupancy")
    patterns = _check_shapes(shapes)
    seed, deadline, time_limit = _check_options(method, shuffle, seed, time_limit)
    try:
        return _tilings(occ, patterns, method, seed, deadline, 1)[0]
    except _TimeLimit as err:
        raise _retime(method, time_limit) from err


def _band_splits(occ: np.ndarray):
    """Candidate splits into two overlapping bands, best first: (shared free cells, axis, k1, k2).

    Axis 0 splits rows (bands ``y < k2`` and ``y >= k1``), axis 1 columns; ``1 <= k1 < k2 <= n - 1``
    so that both bands are proper, and both bands' free areas are multiples of 4.
    """
    free = ~occ
    out = []
    for axis in (0, 1):
        per_line = free.sum(axis=1 - axis)
        before = np.concatenate([[0], np.cumsum(per_line)])  # free cells in lines < k
        n, total = len(per_line), int(before[-1])
        for k1 in range(1, n - 1):
            for k2 in range(k1 + 1, n):
                area_a, area_b = int(before[k2]), total - int(before[k1])
                if area_a % 4 == 0 and area_b % 4 == 0:
                    out.append((int(before[k2] - before[k1]), axis, k1, k2))
    out.sort()
    return out


def _band(occ: np.ndarray, axis: int, lo: int, hi: int) -> np.ndarray:
    """The occupancy of the lines lo <= k < hi alone (every other line an obstacle)."""
    band = np.ones_like(occ)
    if axis == 0:
        band[lo:hi] = occ[lo:hi]
    else:
        band[:, lo:hi] = occ[:, lo:hi]
    return band


def _overlapping_tiles(occ, patterns, method, seed, deadline, cause):
    """The tiles of the best split whose two bands both tile (see :func:`tile_workspace`)."""
    for _shared, axis, k1, k2 in _band_splits(occ):
        if deadline is not None and _time.perf_counter() > deadline:
            raise _TimeLimit("time limit")
        n = occ.shape[axis]
        band_a, band_b = _band(occ, axis, 0, k2), _band(occ, axis, k1, n)
        if _violation(band_a, patterns) is not None or _violation(band_b, patterns) is not None:
            continue
        try:
            tiles_a = _tilings(band_a, patterns, method, seed, deadline, 1)[0]
            tiles_b = _tilings(band_b, patterns, method, seed, deadline, 1)[0]
        except _TimeLimit:
            raise
        except TilingError:
            continue
        return tiles_a + tiles_b
    raise TilingError(
        f"{cause}; nor does any split of the grid into two overlapping bands of rows or of columns "
        "have both bands tileable"
    ) from cause


def tile_workspace(workspace, *, shapes=None, method: str = "auto", shuffle: bool = False, seed=None,
                   time_limit: float | None = None, overlap: bool = False, weights=DEFAULT_BLOCK_WEIGHTS,
                   name: str = "") -> Tileset:
    """Tile a workspace and label the tiles by Algorithm 1: the waypoints of Le et al. 2018.

    Parameters
    ----------
    workspace : Workspace or ndarray of bool, shape (H, W)
        The map (``occ[y, x]`` True for an obstacle).
    shapes, method, shuffle, seed, time_limit
        As in :func:`find_tiles`; the time limit covers the whole call, splits included.
    overlap : bool
        When the free cells do not tile as they are, split the grid into two overlapping bands of
        rows (``y < k2`` and ``y >= k1``) or of columns whose free cells both tile, the split with
        the fewest shared free cells first (ties: rows before columns, then smaller ``k1``), and keep
        the tiles of both: the shared cells are covered twice (Le et al. 2018, §3.1, Fig. 5d–f). A
        map that tiles as it is is tiled normally.
    weights : sequence of 4 float
        α, β, λ, γ of eq. 2, for Algorithm 1's choice among a symmetric tile's options.
    name : str
        The tileset's name.

    Returns
    -------
    Tileset
        Tiles numbered 1, 2, … in scan order, each labelled by a robot footprint.

    Raises
    ------
    TilingError
        As :func:`find_tiles`; with ``overlap``, when no split tiles either.
    UnknownShapeError, ParameterError
        On invalid options.

    Examples
    --------
    >>> ts = tile_workspace(np.zeros((7, 6), dtype=bool), overlap=True)
    >>> len(ts), int(ts.coverage().sum()), ts.complete
    (12, 48, True)
    """
    occ, cell_size = _as_occupancy(workspace, "workspace")
    patterns = _check_shapes(shapes)
    seed, deadline, time_limit = _check_options(method, shuffle, seed, time_limit)
    check_weights(weights)
    overlap = check_bool(overlap, "overlap")
    if not isinstance(name, str):
        raise ParameterError(f"name must be a string, got {type(name).__name__} {reprlib.repr(name)}")
    try:
        try:
            tiles = _tilings(occ, patterns, method, seed, deadline, 1)[0]
        except _TimeLimit:
            raise
        except TilingError as err:
            if not overlap:
                raise
            tiles = _overlapping_tiles(occ, patterns, method, seed, deadline, err)
    except _TimeLimit as err:
        raise _retime(method, time_limit) from err
    return block_locations(occ, tiles, weights=weights, cell_size=cell_size, name=name)


def enumerate_tilings(workspace, *, shapes=None, limit: int = 10, method: str = "auto",
                      time_limit: float | None = None, weights=DEFAULT_BLOCK_WEIGHTS) -> list[Tileset]:
    """Up to ``limit`` distinct tilings of a workspace (distinct as sets of tiles), labelled.

    The backtracker continues its depth-first search after each tiling (so the tilings come in its
    search order); CP-SAT enumerates solutions on one worker. Both are deterministic. When the time
    limit runs out after some tilings were found, those are returned.

    Parameters
    ----------
    workspace : Workspace or ndarray of bool, shape (H, W)
        The map.
    shapes, method, time_limit
        As in :func:`find_tiles`.
    limit : int
        Most tilings to return (at least 1).
    weights : sequence of 4 float
        The eq.-2 weights of Algorithm 1.

    Returns
    -------
    list of Tileset
        Between 1 and ``limit`` tilings, each numbered and labelled as by :func:`tile_workspace`.

    Raises
    ------
    TilingTimeLimitError
        If the time limit runs out before the first tiling (and before a proof that there is none).
    TilingError
        If the map has no tiling.
    UnknownShapeError, ParameterError
        On invalid options (``limit`` not a positive integer, among others).

    Examples
    --------
    >>> len(enumerate_tilings(np.zeros((4, 4), dtype=bool), shapes="O", limit=5))
    1
    """
    occ, cell_size = _as_occupancy(workspace, "workspace")
    patterns = _check_shapes(shapes)
    limit = check_int(limit, "limit", minimum=1)
    _, deadline, time_limit = _check_options(method, False, None, time_limit)
    check_weights(weights)
    try:
        found = _tilings(occ, patterns, method, None, deadline, limit)
    except _TimeLimit as err:
        raise _retime(method, time_limit) from err
    return [block_locations(occ, tiles, weights=weights, cell_size=cell_size) for tiles in found]
