"""Overlapping sub-workspaces (Le et al. 2018, §3.1, Fig. 5d–f): ``tile_workspace(..., overlap=True)``.

"If the size of the coverage area is not a multiple of hTetro blocks, we can segment this workspace
into two partially overlapping sub-workspaces and both can be tiled." The paper gives no rule for
the segmentation; ours: with ``overlap=True``, a map that does not tile as it is (a pre-check fails
or no tiling exists) is split into two bands of rows, ``y < k2`` and ``y >= k1`` with
``1 <= k1 < k2 <= H - 1`` (so that both are proper sub-grids, sharing rows ``k1 … k2 − 1``), or two
bands of columns likewise, whose free cells both tile; the split with the fewest shared free cells
wins, ties going to rows before columns, then to the smaller ``k1`` (then ``k2``). Both bands' tiles
are kept, so the shared cells are covered twice (:meth:`~htetro_opt.scenarios.tileset.Tileset.coverage`
is 2 there): a free grid 6 wide and 7 high (area 42) splits into rows 0–1 and rows 1–6, 12 tiles
covering its 42 cells with the 6 cells of row 1 covered twice.

Each band is tiled by the caller's method (a function passed in, so that this module needs none of
the methods' modules): the pre-checks first, then the search.
"""

from __future__ import annotations

import time as _time

import numpy as np

from htetro_opt.errors import TilingError
from htetro_opt.solvers.tiling._common import _TimeLimit
from htetro_opt.solvers.tiling._prechecks import _violation


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

def _overlapping_tiles(occ, patterns, deadline, cause, tile):
    """The tiles of the best split whose two bands both tile (see
    :func:`~htetro_opt.solvers.tiling.tile_workspace`). ``tile(band)`` tiles a band's occupancy
    by the call's method (pre-checks included): its tiles, or TilingError, or _TimeLimit."""
    for _shared, axis, k1, k2 in _band_splits(occ):
        if deadline is not None and _time.perf_counter() > deadline:
            raise _TimeLimit("time limit")
        n = occ.shape[axis]
        band_a, band_b = _band(occ, axis, 0, k2), _band(occ, axis, k1, n)
        if _violation(band_a, patterns) is not None or _violation(band_b, patterns) is not None:
            continue
        try:
            tiles_a = tile(band_a)
            tiles_b = tile(band_b)
        except _TimeLimit:
            raise
        except TilingError:
            continue
        return tiles_a + tiles_b
    raise TilingError(
        f"{cause}; nor does any split of the grid into two overlapping bands of rows or of columns "
        "have both bands tileable"
    ) from cause
