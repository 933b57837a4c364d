"""The labelled tileset text format (seed 003, MODEL.md §6)."""

import numpy as np
import pytest

from htetro_opt.errors import HtetroError, TilesetFormatError
from htetro_opt.model.robot import Pose
from htetro_opt.scenarios import Tileset, format_tileset, load_tileset, parse_tileset, save_tileset

TWO_TILES = """
1c 1d 2c 2b
1b 1a 2d 2a
#  #  -1 .
"""


def test_parse_reads_cells_blocks_obstacles_and_free_cells():
    ts = parse_tileset(TWO_TILES)
    assert (ts.width, ts.height, ts.ids) == (4, 3, (1, 2))
    assert ts.occupancy[0].tolist() == [True, True, True, False]
    assert ts.blocks[0].tolist() == [[1, 1], [0, 1], [0, 2], [1, 2]]  # a, b, c, d
    assert ts.shapes == ("O", "O")
    assert not ts.complete  # (3, 0) is free and uncovered
    assert not ts.overlapping


def test_our_labelling_maps_to_poses_and_foreign_labelling_loads_as_given():
    ts = parse_tileset(TWO_TILES)
    assert ts.poses[0] == Pose(0, 1, "O", 1)
    # tile 2's chain a-b-c-d runs around the square the other way (a mirror image): no footprint of MODEL.md §2
    assert ts.poses[1] is None
    assert ts.blocks[1].tolist() == [[3, 1], [3, 2], [2, 2], [2, 1]]


def test_format_round_trips_and_writes_hash_for_obstacles(tmp_path):
    ts = parse_tileset(TWO_TILES)
    text = format_tileset(ts)
    assert "-1" not in text
    again = parse_tileset(text)
    assert again.ids == ts.ids and np.array_equal(again.blocks, ts.blocks)
    assert np.array_equal(again.occupancy, ts.occupancy)
    path = tmp_path / "t.txt"
    save_tileset(ts, path)
    assert np.array_equal(load_tileset(path).blocks, ts.blocks)
    assert [p.name for p in tmp_path.iterdir()] == ["t.txt"]


def test_overlapping_cells_are_joined_by_a_slash():
    ts = Tileset.from_poses(np.zeros((3, 2), bool), [Pose(0, 0, "O", 1), Pose(0, 1, "O", 1)])
    text = format_tileset(ts)
    assert "/" in text
    again = parse_tileset(text)
    assert again.overlapping and again.complete
    assert again.coverage().tolist() == [[1, 1], [2, 2], [1, 1]]


def test_tiles_are_listed_in_scan_order_whatever_their_labels():
    ts = parse_tileset("7a 7b 7c 7d\n3a 3b 3c 3d")
    assert ts.ids == (7, 3)
    assert ts.index(3) == 1


@pytest.mark.parametrize(
    "text, message",
    [
        ("1a 1b 1c 1d\n2a 2b 2c", "row 2 has 3 tokens"),
        ("1a 1b 1c 1x", r"unknown token '1x' at row 1, column 4"),
        ("1a 1b 1c 0d", r"unknown token '0d'"),
        ("1a 1b 1c", "tile 1 has no block d"),
        ("1a 1b 1c 1d 1a", "label '1a' appears twice"),
        ("1a 1b 1c .\n.  .  .  1d", "not a tetromino"),
        ("", "empty"),
    ],
)
def test_malformed_tilesets_name_what_is_wrong(text, message):
    with pytest.raises(TilesetFormatError, match=message):
        parse_tileset(text)


def test_unknown_tile_and_unreadable_file_are_clear_errors(tmp_path):
    ts = parse_tileset(TWO_TILES)
    with pytest.raises(TilesetFormatError, match="no tile 9"):
        ts.index(9)
    with pytest.raises(HtetroError, match="cannot read tileset"):
        load_tileset(tmp_path / "missing.txt")


def test_blocks_off_the_grid_or_on_obstacles_are_rejected():
    occ = np.zeros((2, 2), bool)
    occ[0, 0] = True
    with pytest.raises(TilesetFormatError, match="on an obstacle"):
        Tileset.from_poses(occ, [Pose(0, 0, "O", 1)])
    with pytest.raises(TilesetFormatError, match="outside"):
        Tileset.from_poses(np.zeros((2, 2), bool), [Pose(1, 1, "O", 1)])
