"""Tiles: the 19 fixed tetrominoes and the poses that fill them (seed 003 Figs. 7–8)."""

import itertools

import numpy as np
import pytest

from htetro_opt.errors import ConfigurationError, UnknownShapeError
from htetro_opt.model.robot import SHAPES
from htetro_opt.model.tiles import PATTERNS, identify_tile, patterns_of, scan_key, tile_poses

OPTIONS = {"I": 2, "O": 4, "L": 1, "J": 1, "Z": 2, "S": 2, "T": 1}


def _connected_quads():
    """Every 4-cell edge-connected set containing (0, 0) as its first cell in scan order."""
    found = set()
    frontier = {((0, 0),)}
    for _ in range(3):
        grown = set()
        for cells in frontier:
            for (x, y) in cells:
                for dx, dy in ((1, 0), (-1, 0), (0, 1), (0, -1)):
                    c = (x + dx, y + dy)
                    if c not in cells:
                        grown.add(tuple(sorted(cells + (c,))))
        frontier = grown
    for cells in frontier:
        first = min(cells, key=scan_key)
        found.add(tuple(sorted((x - first[0], y - first[1]) for x, y in cells)))
    return found


def test_the_patterns_are_exactly_the_nineteen_fixed_tetrominoes():
    assert len(PATTERNS) == 19
    ours = {tuple(sorted(map(tuple, p.cells.tolist()))) for p in PATTERNS}
    assert ours == _connected_quads()


def test_pattern_cells_start_at_their_first_cell_in_scan_order():
    for p in PATTERNS:
        cells = list(map(tuple, p.cells.tolist()))
        assert cells[0] == (0, 0)
        assert cells == sorted(cells, key=scan_key)


@pytest.mark.parametrize("shape", SHAPES)
def test_every_pattern_has_the_papers_number_of_block_options(shape):
    for p in patterns_of(shape):
        poses = tile_poses(p.cells + (5, 5))
        assert len(poses) == OPTIONS[shape]
        for pose in poses:
            assert pose.shape == shape
            assert {tuple(c) for c in pose.cells().tolist()} == {tuple(c) for c in (p.cells + (5, 5)).tolist()}
        labellings = {tuple(map(tuple, pose.cells().tolist())) for pose in poses}
        assert len(labellings) == len(poses)  # each option labels the blocks differently


def test_identify_tile_rejects_what_is_not_a_tetromino():
    assert identify_tile([(0, 0), (1, 1), (2, 2), (3, 3)]) is None
    assert identify_tile([(0, 0), (1, 0), (2, 0)]) is None
    with pytest.raises(ConfigurationError, match="not a tetromino"):
        tile_poses([(0, 0), (0, 1), (0, 2), (0, 4)])


def test_identify_tile_ignores_the_order_of_cells():
    cells = [(3, 3), (4, 3), (5, 3), (4, 2)]
    for perm in itertools.permutations(cells):
        assert identify_tile(perm).shape == "T"


def test_patterns_of_validates_names():
    assert {p.shape for p in patterns_of("TZ")} == {"T", "Z"}
    with pytest.raises(UnknownShapeError):
        patterns_of("Q")
    with pytest.raises(ConfigurationError, match="intermediate"):
        patterns_of(["h213"])
    assert np.array_equal(np.sort([len(patterns_of(s)) for s in SHAPES]), [1, 2, 2, 2, 4, 4, 4])
