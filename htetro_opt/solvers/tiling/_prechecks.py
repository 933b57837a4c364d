"""The pre-checks of the tiling methods: necessary conditions that prove a map untileable at once.

Before any search every method (``"backtracking"``, ``"cpsat"``, ``"auto"``, and each band of an
overlapping split) tests the same necessary conditions, each failing with a
:class:`~htetro_opt.errors.TilingError` that names what is wrong and where: a free cell exists; the
free area is a multiple of 4; so is the area of every 4-connected region of free cells (a region of
fewer than four cells is isolated); the colourings of tiling theory hold in every region — without
T each tetromino covers 2 black and 2 white cells of a checkerboard (so the counts must be equal),
T alone covers 3 + 1, L and J cover an odd number of cells of the even columns (and rows), I, O, S
and Z an even one, and more generally the region's cell counts by ``(x mod 4, y mod 4)`` must be an
integer combination of the allowed placements' counts (an integer-lattice test); and every free
cell lies under some placement of an allowed shape. They are sound (never reject a tileable map)
and catch most untileable maps at once.

The backtracker (``_backtracking``) applies the lattice test (:func:`_class_lattice`,
:func:`_class_counts`, :func:`_in_lattice`) to the regions its placements enclose as well.
"""

from __future__ import annotations

import functools

import numpy as np
from scipy import ndimage

from htetro_opt.errors import TilingError
from htetro_opt.model.tiles import patterns_of
from htetro_opt.solvers.tiling._common import _placements, _shape_text


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
