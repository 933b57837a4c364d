"""The seed-003 paper's own labelled tilesets, transcribed into htetro_opt/scenarios/data/tilesets/.

Le et al., Electronics 2018 (shared/seeds/003): Figs. 13(a)-(d), 14(a)-(f), 15(a)/(b), 16(a)-(c) and the
tile-number grids of Fig. 12. The labels are kept as the paper prints them (not relabelled to
shared/MODEL.md's chain convention), so some tiles are "foreign": they load, but Tileset.poses gives
None for them.

Files and the figures they come from:

- paper_6x6_fig13a   Fig. 13(a) = Fig. 16(b) (cost weight 10.156 / 10.152), tile numbers of Fig. 12(a)
- paper_6x6_fig16a   Fig. 16(a) (cost weight 10.901), "L, S, J, O, Z"
- paper_6x6_fig16c   Fig. 16(c) (cost weight 9.583), only O
- paper_8x7_fig13b   Fig. 13(b) (cost weight 30.759), tile numbers of Fig. 12(b)
- paper_10x10_fig13c Fig. 13(c) = Fig. 15(a) = Fig. 15(b) (cost weight 51.417), tile numbers of Fig. 12(c)
- paper_11x11_fig13d Fig. 13(d) = Fig. 14(a)-(f); Fig. 12(d) tiles rows 6-9, columns 1-2 differently
"""

from collections import Counter
from pathlib import Path

import numpy as np
import pytest

import htetro_opt.scenarios
from htetro_opt.model.tiles import scan_key
from htetro_opt.scenarios import format_tileset, load_scenario, load_tileset, parse_tileset

TILESETS = Path(htetro_opt.scenarios.__file__).parent / "data" / "tilesets"

# file stem -> (bundled scenario, number of tiles)
FILES = {
    "paper_6x6_fig13a": ("tiling_6x6", 9),
    "paper_6x6_fig16a": ("tiling_6x6", 9),
    "paper_6x6_fig16c": ("tiling_6x6", 9),
    "paper_8x7_fig13b": ("tiling_8x7", 14),
    "paper_10x10_fig13c": ("tiling_10x10", 25),
    "paper_11x11_fig13d": ("tiling_11x11", 28),
}

# Tiles whose labels follow shared/MODEL.md's chain convention (Tileset.poses not None) vs the
# foreign ones, as the paper labels them.
FOREIGN = {
    "paper_6x6_fig13a": (6, 9),
    "paper_6x6_fig16a": (1, 3, 4, 6),
    "paper_6x6_fig16c": (),
    "paper_8x7_fig13b": (1, 13),
    "paper_10x10_fig13c": (18,),
    "paper_11x11_fig13d": (1, 2, 3, 6, 8, 9, 12, 14, 17, 18, 20, 24, 25, 26),
}

# One-sided morphologies (shared/MODEL.md §2) of the transcribed tiles.
SHAPES = {
    "paper_6x6_fig13a": Counter(O=3, I=2, J=2, L=2),
    "paper_6x6_fig16a": Counter(L=3, S=3, O=1, Z=1, J=1),
    "paper_6x6_fig16c": Counter(O=9),
    "paper_8x7_fig13b": Counter(O=4, T=4, I=2, L=1, J=1, S=1, Z=1),
    "paper_10x10_fig13c": Counter(T=10, S=9, Z=6),
    "paper_11x11_fig13d": Counter(L=14, J=9, O=3, I=2),
}

# Fig. 12's tile-number grids (rows top first), read from the text: they give tile membership only.
FIG12 = {
    "paper_6x6_fig13a": """
        1 1 2 3 3 4
        1 1 2 3 3 4
        5 2 2 6 7 4
        5 6 6 6 7 4
        5 8 8 7 7 9
        5 8 8 9 9 9
    """,
    "paper_8x7_fig13b": """
        1  1  1  2  3  3  3  3
        1  4  4  2  2  2  5  6
        7  4  4  8  8  5  5  6
        7  7  9  8  8  10 5  6
        7  9  9  9  10 10 11 6
        12 12 13 13 10 14 11 11
        12 12 13 13 14 14 14 11
    """,
    "paper_10x10_fig13c": """
        1  1  1  2  2  2  3  3  3  4
        5  1  6  6  2  7  7  3  4  4
        5  5  8  6  6  9  7  7  10 4
        5  11 8  8  9  9  12 12 10 10
        11 11 13 8  9  14 14 12 12 10
        11 15 13 13 14 14 16 16 16 17
        18 15 15 13 19 20 20 16 17 17
        18 18 15 19 19 19 20 20 21 17
        18 22 22 23 23 24 24 25 21 21
        22 22 23 23 24 24 25 25 25 21
    """,
}

# S and Z, and L and J, are one free tetromino each: the paper's text names shapes that way
# ("Z and T" for a tiling with both S and Z).
FREE = {"S": "Z", "J": "L"}


def _path(stem):
    return TILESETS / f"{stem}.txt"


@pytest.fixture(scope="module", params=sorted(FILES))
def loaded(request):
    stem = request.param
    return stem, load_tileset(_path(stem))


def test_every_file_is_bundled():
    assert sorted(p.stem for p in TILESETS.glob("paper_*.txt")) == sorted(FILES)


def test_loads_the_same_with_parse_and_load(loaded):
    stem, ts = loaded
    again = parse_tileset(_path(stem).read_text(encoding="utf-8"))
    assert again.ids == ts.ids
    assert np.array_equal(again.blocks, ts.blocks)
    assert np.array_equal(again.occupancy, ts.occupancy)


def test_the_file_is_in_canonical_form(loaded):
    """'#' for obstacles (not the paper's '-1'), rectangular, and unchanged by a format round trip."""
    stem, ts = loaded
    rows = [line.split() for line in _path(stem).read_text(encoding="utf-8").splitlines() if line.strip()]
    assert all("-1" not in row and "." not in row for row in rows)
    assert [r.split() for r in format_tileset(ts).splitlines()] == rows


def test_paper_obstacle_token_reads_the_same(loaded):
    stem, ts = loaded
    text = _path(stem).read_text(encoding="utf-8").replace("#", "-1")
    again = parse_tileset(text)
    assert np.array_equal(again.occupancy, ts.occupancy)
    assert np.array_equal(again.blocks, ts.blocks)


def test_obstacles_are_the_bundled_workspace(loaded):
    stem, ts = loaded
    scenario, _ = FILES[stem]
    occ = load_scenario(scenario).workspace.occupancy
    assert ts.occupancy.shape == occ.shape
    assert np.array_equal(ts.occupancy, occ)


def test_covers_every_free_cell_once(loaded):
    stem, ts = loaded
    assert ts.complete and not ts.overlapping
    cover = ts.coverage()
    assert (cover[~ts.occupancy] == 1).all() and (cover[ts.occupancy] == 0).all()


def test_tile_count(loaded):
    stem, ts = loaded
    assert len(ts) == FILES[stem][1]
    assert 4 * len(ts) == int((~ts.occupancy).sum())


def test_tiles_are_numbered_1_to_n_in_scan_order_of_their_first_cell(loaded):
    """The paper numbers tiles row-wise (Algorithm 1): by first cell, top row first, left to right."""
    stem, ts = loaded
    first = {tile: min(map(tuple, cells.tolist()), key=scan_key) for tile, cells in zip(ts.ids, ts.blocks)}
    assert sorted(first, key=lambda t: scan_key(first[t])) == list(range(1, len(ts) + 1))


def test_consecutive_blocks_share_a_hinge(loaded):
    """a-b, b-c and c-d touch along an edge or at a corner in every tile: the chain a robot can form."""
    stem, ts = loaded
    for tile, cells in zip(ts.ids, ts.blocks):
        steps = np.abs(np.diff(cells, axis=0)).max(axis=1)
        assert (steps == 1).all(), f"{stem}: tile {tile}"


def test_morphologies(loaded):
    stem, ts = loaded
    assert Counter(ts.shapes) == SHAPES[stem]


def test_morphologies_named_by_the_paper():
    shapes = {stem: set(load_tileset(_path(stem)).shapes) for stem in FILES}
    # Fig. 16(b) (the tileset of Fig. 13a) "consisting of O, I J, L"; Table 3's 6 x 6 tileset 2 "O, I, J, L".
    assert shapes["paper_6x6_fig13a"] == set("OIJL")
    # Fig. 16(a) "consisting of L, S, J, O, Z" (Table 3's 6 x 6 tileset 1 "L, S, J, O, N").
    assert shapes["paper_6x6_fig16a"] == set("LSJOZ")
    # Fig. 16(c) "consisting of only O".
    assert shapes["paper_6x6_fig16c"] == {"O"}
    # Sec. 5: the 10 x 10 tiling uses "Z and T" (free tetrominoes: S counts as Z); Table 3 tileset 1 "T, Z".
    assert {FREE.get(s, s) for s in shapes["paper_10x10_fig13c"]} == {"Z", "T"}
    # Table 3's 11 x 11 tileset 2 "O, J, L, I" (cost 61.1368; Fig. 13d prints about 61.3).
    assert shapes["paper_11x11_fig13d"] == set("OJLI")


def test_section_5_shape_list_for_the_6x6_fits_fig16a_not_fig12a():
    """Sec. 5 says Fig. 12a uses "L, Z, J, O". As free tetrominoes that is Fig. 16(a)'s tileset; the
    tileset of Figs. 12a/13a has I tiles and no Z (it is Fig. 16(b), "O, I, J, L")."""
    free = {stem: {FREE.get(s, s) for s in load_tileset(_path(stem)).shapes} for stem in FILES}
    assert free["paper_6x6_fig16a"] == {"L", "Z", "O"}
    assert "I" in free["paper_6x6_fig13a"] and "Z" not in free["paper_6x6_fig13a"]


@pytest.mark.parametrize("stem", sorted(FIG12))
def test_tiles_match_the_tile_numbers_of_fig12(stem):
    ts = load_tileset(_path(stem))
    numbers = [row.split() for row in FIG12[stem].strip().splitlines()]
    height = len(numbers)
    expected = {}
    for r, row in enumerate(numbers):
        for x, token in enumerate(row):
            expected.setdefault(int(token), set()).add((x, height - 1 - r))
    got = {tile: set(map(tuple, cells.tolist())) for tile, cells in zip(ts.ids, ts.blocks)}
    assert got == expected


def test_conforming_and_foreign_tiles(loaded):
    stem, ts = loaded
    foreign = tuple(tile for tile, pose in zip(ts.ids, ts.poses) if pose is None)
    assert foreign == FOREIGN[stem]
    for tile, pose, cells in zip(ts.ids, ts.poses, ts.blocks):
        if pose is not None:
            assert np.array_equal(pose.cells(), cells), f"{stem}: tile {tile}"


def test_eleven_by_eleven_has_14_of_28_foreign_tiles():
    """shared/MODEL.md §6: in the paper's 11 x 11 figure 14 of 28 tiles use another chain convention."""
    ts = load_tileset(_path("paper_11x11_fig13d"))
    poses = ts.poses
    assert len(ts) == 28
    assert sum(p is None for p in poses) == 14
    assert sum(p is not None for p in poses) == 14


def test_labels_are_kept_as_the_paper_prints_them():
    """Spot checks of tokens every copy of the figure agrees on (rows top first, 1-based)."""
    def token(stem, row, col):
        return _path(stem).read_text(encoding="utf-8").splitlines()[row - 1].split()[col - 1]

    assert [token("paper_11x11_fig13d", 1, c) for c in range(1, 12)] == \
        ["1c", "1b", "1a", "2c", "2b", "2a", "3d", "3c", "#", "#", "4d"]
    assert [token("paper_11x11_fig13d", 11, c) for c in range(1, 12)] == \
        ["25d", "26a", "26b", "26c", "23b", "23a", "27a", "27c", "27d", "28b", "24a"]
    assert [token("paper_10x10_fig13c", 1, c) for c in range(1, 11)] == \
        ["1b", "1c", "1d", "2b", "2c", "2d", "3b", "3c", "3d", "4b"]
    assert [token("paper_6x6_fig13a", 1, c) for c in range(1, 7)] == ["1c", "1d", "2d", "3c", "3d", "4a"]
