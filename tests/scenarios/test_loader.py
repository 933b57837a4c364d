"""Tests of the scenario loader: TOML grid and continuous scenarios, ROS map_server maps, errors."""

from __future__ import annotations

import textwrap
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from htetro_opt.errors import (
    ConfigurationError,
    HtetroError,
    MapFormatError,
    ScenarioError,
    UnknownShapeError,
)
from htetro_opt.model.robot import Pose
from htetro_opt.model.workspace import Workspace
from htetro_opt.scenarios import (
    ContinuousScenario,
    Scenario,
    format_grid,
    list_scenarios,
    load_ros_map,
    load_scenario,
    load_scenario_file,
    parse_grid,
    parse_scenario,
    read_pgm,
)

# 8 x 8 map: a wall ring around a 6 x 6 free room, plus one obstacle cell at (5, 5).
ROOM = """\
########
#......#
#....#.#
#......#
#......#
#......#
#......#
########"""


def write(path: Path, text: str) -> Path:
    path.write_text(textwrap.dedent(text))
    return path


def grid_toml(grid: str = ROOM, roadmap: str = "", extra: str = "", name: str = "room") -> str:
    """A grid-scenario TOML text; ``extra`` top-level keys go before the tables."""
    return (
        f'name = "{name}"\nsource = "test"\n{extra}\ngrid = """\n{grid}\n"""\n{roadmap}'
    )


def pose_table(x, y, shape, heading=None, table="roadmap") -> str:
    line = f'[[{table}]]\nx = {x}\ny = {y}\nshape = "{shape}"\n'
    if heading is not None:
        line += f"heading = {heading}\n"
    return line


START_GOAL = pose_table(2, 2, "O") + pose_table(3, 4, "I", 1)


def grid_data(**overrides) -> dict:
    data = {"name": "room", "source": "test", "grid": ROOM,
            "roadmap": [{"x": 2, "y": 2, "shape": "O"}, {"x": 3, "y": 4, "shape": "I", "heading": 1}]}
    data.update(overrides)
    return {k: v for k, v in data.items() if v is not None}


# --------------------------------------------------------------------------------------------------
# parse_grid / format_grid


def test_parse_grid_flips_rows_so_occ0_is_the_bottom_row():
    occ = parse_grid("#..\n...\n..#")
    assert occ.shape == (3, 3)
    assert occ.dtype == bool
    # Text row 1 (top) holds '#' at column 1 -> cell (0, 2); text row 3 (bottom) '#' at column 3 -> (2, 0).
    assert occ[2, 0] and occ[0, 2]
    assert occ.sum() == 2
    assert occ[0].tolist() == [False, False, True]


def test_parse_grid_ignores_surrounding_blank_lines_and_indentation():
    occ = parse_grid("\n\n   #.\n   ..\n\n")
    assert occ.tolist() == [[False, False], [True, False]]


def test_format_grid_writes_top_row_first():
    occ = np.zeros((2, 3), dtype=bool)
    occ[0, 0] = True  # bottom-left
    assert format_grid(occ) == "...\n#.."


@settings(max_examples=60, deadline=None)
@given(st.integers(1, 7), st.integers(1, 7), st.data())
def test_parse_and_format_grid_are_inverse(h, w, data):
    cells = data.draw(st.lists(st.booleans(), min_size=h * w, max_size=h * w))
    occ = np.array(cells, dtype=bool).reshape(h, w)
    text = format_grid(occ)
    assert text.count("\n") == h - 1
    assert np.array_equal(parse_grid(text), occ)
    assert format_grid(parse_grid(text)) == text


def test_parse_grid_ragged_rows_names_the_row():
    with pytest.raises(MapFormatError) as info:
        parse_grid("....\n...\n....")
    msg = str(info.value)
    assert "row 2" in msg and "3" in msg and "4" in msg and "ragged" in msg


def test_parse_grid_unknown_character_names_row_and_column():
    with pytest.raises(MapFormatError) as info:
        parse_grid("....\n..x.\n....")
    msg = str(info.value)
    assert "'x'" in msg and "row 2" in msg and "column 3" in msg


@pytest.mark.parametrize("text", ["", "\n\n", "   \n  \n"])
def test_parse_grid_empty_raises(text):
    with pytest.raises(MapFormatError, match="empty"):
        parse_grid(text)


def test_error_hierarchy():
    for cls in (ScenarioError, MapFormatError, ConfigurationError, UnknownShapeError):
        assert issubclass(cls, HtetroError)
    assert issubclass(MapFormatError, ScenarioError)


# --------------------------------------------------------------------------------------------------
# A valid grid scenario


def test_valid_grid_scenario_loads(tmp_path):
    path = write(tmp_path / "room.toml", grid_toml(roadmap=START_GOAL, extra='cell_size_m = 0.25\ndescription = "d"'))
    sc = load_scenario_file(path)
    assert isinstance(sc, Scenario)
    assert sc.name == "room" and sc.source == "test" and sc.description == "d"
    ws = sc.workspace
    assert isinstance(ws, Workspace)
    assert (ws.width, ws.height) == (8, 8)
    assert ws.cell_size == 0.25
    # The '#' on text row 3, column 6 is cell (5, 5): y = 8 - 3 = 5.
    assert ws.occupancy[5, 5] and not ws.occupancy[2, 5] and not ws.occupancy[5, 2]
    assert ws.occupancy[0].all() and ws.occupancy[7].all() and ws.occupancy[:, 0].all()
    assert ws.occupancy.sum() == 28 + 1
    assert format_grid(ws.occupancy) == ROOM
    assert sc.roadmap == (Pose(2, 2, "O", 0), Pose(3, 4, "I", 1))
    assert sc.start == Pose(2, 2, "O", 0)
    assert sc.goal == Pose(3, 4, "I", 1)
    assert sc.hidden.shape == (0, 2)
    assert ws.moving == ()
    assert sc.path == tmp_path


def test_default_cell_size_and_heading(tmp_path):
    path = write(tmp_path / "room.toml", grid_toml(roadmap=pose_table(2, 2, "O")))
    sc = load_scenario_file(path)
    assert sc.workspace.cell_size == 1.0
    assert sc.start == Pose(2, 2, "O", 0)
    assert sc.goal is None  # a single configuration is a start without a goal


def test_roadmap_with_intermediate_configuration():
    sc = parse_scenario(grid_data(roadmap=[
        {"x": 2, "y": 2, "shape": "O"},
        {"x": 4, "y": 2, "shape": "O", "heading": 0},
        {"x": 3, "y": 4, "shape": "I", "heading": 1},
    ]))
    assert len(sc.roadmap) == 3
    assert sc.roadmap[1] == Pose(4, 2, "O", 0)
    assert sc.goal == Pose(3, 4, "I", 1)


def test_scenario_without_roadmap_has_no_start():
    sc = parse_scenario(grid_data(roadmap=None))
    assert sc.roadmap == () and sc.start is None and sc.goal is None


def test_hidden_cells_and_true_workspace():
    sc = parse_scenario(grid_data(hidden=[[4, 3], [6, 6]]))
    assert sc.hidden.tolist() == [[4, 3], [6, 6]]
    assert not sc.workspace.occupancy[3, 4] and not sc.workspace.occupancy[6, 6]
    true = sc.true_workspace()
    assert true.occupancy[3, 4] and true.occupancy[6, 6]
    diff = true.occupancy ^ sc.workspace.occupancy
    assert diff.sum() == 2
    assert true.cell_size == sc.workspace.cell_size
    # The planner's workspace is left untouched.
    assert not sc.workspace.occupancy[3, 4]


def test_true_workspace_without_hidden_cells_equals_workspace():
    sc = parse_scenario(grid_data())
    assert np.array_equal(sc.true_workspace().occupancy, sc.workspace.occupancy)


def test_moving_obstacle_pingpong(tmp_path):
    moving = '[[moving]]\ncells = [[1, 6], [2, 6]]\nroute = [[0, 0], [3, 0]]\n'
    path = write(tmp_path / "m.toml", grid_toml(grid=ROOM.replace("#....#.#", "#......#"), roadmap=START_GOAL + moving))
    sc = load_scenario_file(path)
    (ob,) = sc.workspace.moving
    assert ob.mode == "pingpong" and ob.speed == 1
    # Displacements 0, 1, 2, 3, 2, 1, then back to 0.
    xs = [ob.cells_at(t)[:, 0].tolist() for t in range(7)]
    assert xs == [[1, 2], [2, 3], [3, 4], [4, 5], [3, 4], [2, 3], [1, 2]]
    assert all((ob.cells_at(t)[:, 1] == 6).all() for t in range(7))
    assert ob.period == 6
    assert sc.workspace.period == 6
    assert sc.workspace.occupancy_at(3)[6, 4] and sc.workspace.occupancy_at(3)[6, 5]
    assert not sc.workspace.occupancy[6, 4]  # static occupancy excludes the moving obstacle


def test_moving_obstacle_loop_with_diagonal_return():
    sc = parse_scenario(grid_data(grid=ROOM.replace("#....#.#", "#......#"), moving=[
        {"cells": [[1, 4]], "route": [[0, 0], [2, 0], [2, 2]], "mode": "loop"}]))
    (ob,) = sc.workspace.moving
    path = [tuple(ob.cells_at(t)[0]) for t in range(7)]
    # Right 2, up 2, then diagonally back to the start: (3, 6) -> (2, 5) -> (1, 4).
    assert path == [(1, 4), (2, 4), (3, 4), (3, 5), (3, 6), (2, 5), (1, 4)]
    assert ob.period == 6


def test_moving_obstacle_speed_two():
    sc = parse_scenario(grid_data(grid=ROOM.replace("#....#.#", "#......#"), moving=[
        {"cells": [[1, 6]], "route": [[0, 0], [3, 0]], "speed": 2}]))
    (ob,) = sc.workspace.moving
    assert ob.speed == 2
    # Unit steps 0 1 2 3 2 1 (6 of them), two per command: 0, 2, 2 (=step 4), 0, ...
    assert [int(ob.cells_at(t)[0, 0]) for t in range(4)] == [1, 3, 3, 1]
    assert ob.period == 3
    # Between t = 0 and t = 1 the obstacle passes through x = 1, 2 and 3.
    assert sorted(ob.cells_during(0)[:, 0].tolist()) == [1, 2, 3]


def test_start_colliding_with_moving_obstacle_at_time_zero():
    with pytest.raises(ConfigurationError) as info:
        parse_scenario(grid_data(moving=[{"cells": [[3, 2]]}]), where="m.toml")
    msg = str(info.value)
    assert "m.toml" in msg and "roadmap[1]" in msg and "(3, 2)" in msg


# --------------------------------------------------------------------------------------------------
# Error paths of grid scenarios


def test_malformed_toml_names_file_and_line(tmp_path):
    path = write(tmp_path / "bad.toml", 'name = "x"\nsource = \ngrid = "."\n')
    with pytest.raises(ScenarioError) as info:
        load_scenario_file(path)
    msg = str(info.value)
    assert "bad.toml" in msg and "malformed TOML" in msg and "line 2" in msg


def test_missing_file_names_the_path(tmp_path):
    path = tmp_path / "nowhere.toml"
    with pytest.raises(ScenarioError) as info:
        load_scenario_file(path)
    assert "nowhere.toml" in str(info.value)


def test_non_utf8_file_raises_scenario_error(tmp_path):
    path = tmp_path / "binary.toml"
    path.write_bytes(b"name = \"\xff\xfe\"\n")
    with pytest.raises(ScenarioError, match="binary.toml"):
        load_scenario_file(path)


def test_a_table_without_a_name_and_no_file_to_name_it_after_is_refused():
    with pytest.raises(ScenarioError) as info:
        parse_scenario(grid_data(name=None), where="s.toml")
    msg = str(info.value)
    assert "s.toml" in msg and "missing key 'name'" in msg


def test_a_users_file_needs_neither_name_nor_source(tmp_path):
    path = write(tmp_path / "my_room.toml", 'grid = """\n#....#\n#....#\n"""\n')
    scenario = load_scenario_file(path)
    assert scenario.name == "my_room" and scenario.source == "" and scenario.description == ""


def test_a_byte_order_mark_is_accepted(tmp_path):
    path = tmp_path / "bom.toml"
    path.write_bytes("\ufeffname = \"bom\"\ngrid = \"\"\"\n....\n....\n\"\"\"\n".encode("utf-8"))
    assert load_scenario_file(path).name == "bom"


@pytest.mark.parametrize("key", ["source", "description"])
def test_source_and_description_must_be_text(key):
    with pytest.raises(ScenarioError, match=f"'{key}' must be a string"):
        parse_scenario(grid_data(**{key: 3}), where="s.toml")


def test_mistyped_name():
    with pytest.raises(ScenarioError, match="'name' must be str, got int"):
        parse_scenario(grid_data(name=3))


def test_unknown_top_level_key_is_named(tmp_path):
    path = write(tmp_path / "u.toml", grid_toml(roadmap=START_GOAL, extra="colour = 3"))
    with pytest.raises(ScenarioError) as info:
        load_scenario_file(path)
    msg = str(info.value)
    assert "u.toml" in msg and "unknown key" in msg and "colour" in msg


def test_stray_width_key_in_grid_scenario_is_named():
    with pytest.raises(ScenarioError) as info:
        parse_scenario(grid_data(width=8))
    msg = str(info.value)
    assert "width" in msg and "grid" not in msg.split("unknown key")[-1]


def test_both_grid_and_map():
    with pytest.raises(ScenarioError) as info:
        parse_scenario(grid_data(map="room.yaml"), where="s.toml")
    msg = str(info.value)
    assert "s.toml" in msg and "'grid'" in msg and "'map'" in msg and "exactly one" in msg


def test_neither_grid_nor_map():
    with pytest.raises(ScenarioError) as info:
        parse_scenario(grid_data(grid=None, roadmap=None), where="s.toml")
    assert "exactly one" in str(info.value) and "'grid'" in str(info.value)


def test_ragged_grid_in_file_names_file_and_row(tmp_path):
    grid = ROOM.replace("#......#\n#......#\n#......#\n#......#\n########", "#......#\n#.....#\n#......#\n#......#\n########")
    path = write(tmp_path / "r.toml", grid_toml(grid=grid))
    with pytest.raises(MapFormatError) as info:
        load_scenario_file(path)
    msg = str(info.value)
    assert "r.toml" in msg and "row 5" in msg and "ragged" in msg


def test_unknown_grid_character_in_file(tmp_path):
    grid = ROOM.replace("#......#\n########", "#..o...#\n########")
    path = write(tmp_path / "c.toml", grid_toml(grid=grid))
    with pytest.raises(MapFormatError) as info:
        load_scenario_file(path)
    msg = str(info.value)
    assert "c.toml" in msg and "'o'" in msg and "row 7" in msg and "column 4" in msg


def test_empty_grid_in_scenario():
    with pytest.raises(MapFormatError, match="empty"):
        parse_scenario(grid_data(grid="\n\n", roadmap=None))


def test_start_colliding_with_obstacle_names_cell_and_roadmap_index():
    with pytest.raises(ConfigurationError) as info:
        parse_scenario(grid_data(roadmap=[{"x": 4, "y": 5, "shape": "O"}, {"x": 3, "y": 2, "shape": "O"}]),
                       where="s.toml")
    msg = str(info.value)
    # O at (4, 5): blocks (4, 4), (4, 5), (5, 5), (5, 4); (5, 5) is the obstacle.
    assert "s.toml" in msg and "roadmap[1]" in msg and "start" in msg and "(5, 5)" in msg and "collides" in msg


def test_goal_colliding_with_obstacle():
    with pytest.raises(ConfigurationError) as info:
        parse_scenario(grid_data(roadmap=[{"x": 2, "y": 2, "shape": "O"}, {"x": 5, "y": 3, "shape": "I"}]))
    msg = str(info.value)
    # I at (5, 3): blocks (5, 2)..(5, 5).
    assert "roadmap[2]" in msg and "goal" in msg and "(5, 5)" in msg


def test_goal_on_wall_of_file(tmp_path):
    path = write(tmp_path / "g.toml", grid_toml(roadmap=pose_table(2, 2, "O") + pose_table(6, 3, "O")))
    with pytest.raises(ConfigurationError) as info:
        load_scenario_file(path)
    msg = str(info.value)
    # O at (6, 3) has B3/B4 on the right wall x = 7.
    assert "g.toml" in msg and "roadmap[2]" in msg and "(7, 3)" in msg and "(7, 2)" in msg


@pytest.mark.parametrize("index,pose,outside", [
    (1, {"x": 1, "y": 0, "shape": "I"}, "(1, -1)"),                # B1 below the map
    (2, {"x": 1, "y": 2, "shape": "I", "heading": 1}, "(-1, 2)"),  # lying along x, B4 left of the map
    (2, {"x": 5, "y": 2, "shape": "L"}, "(6, 2)"),                 # B1 right of the map
    (2, {"x": 2, "y": 3, "shape": "I"}, "(2, 5)"),                 # B4 above the map
])
def test_pose_with_a_block_outside_the_map(index, pose, outside):
    grid = "......\n......\n......\n......\n......"  # 6 x 5, no walls
    roadmap = [{"x": 2, "y": 2, "shape": "O"}, {"x": 3, "y": 2, "shape": "O"}]
    roadmap[index - 1] = pose
    with pytest.raises(ConfigurationError) as info:
        parse_scenario(grid_data(grid=grid, roadmap=roadmap), where="s.toml")
    msg = str(info.value)
    assert "s.toml" in msg and f"roadmap[{index}]" in msg and "outside the 6 x 5 map" in msg and outside in msg


def test_unknown_shape_is_named_with_roadmap_index():
    with pytest.raises(UnknownShapeError) as info:
        parse_scenario(grid_data(roadmap=[{"x": 2, "y": 2, "shape": "O"}, {"x": 3, "y": 4, "shape": "Q"}]),
                       where="s.toml")
    msg = str(info.value)
    assert "s.toml" in msg and "roadmap[2]" in msg and "'Q'" in msg
    assert isinstance(info.value, HtetroError)


@pytest.mark.parametrize("heading,words", [(1.5, "integer"), (4, "0, 1, 2 or 3"), (-1, "0, 1, 2 or 3"),
                                           (True, "integer"), ("1", "integer")])
def test_bad_heading(heading, words):
    with pytest.raises(ConfigurationError) as info:
        parse_scenario(grid_data(roadmap=[{"x": 2, "y": 2, "shape": "O", "heading": heading}]), where="s.toml")
    msg = str(info.value)
    assert "s.toml" in msg and "roadmap[1]" in msg and "heading" in msg and words in msg


def test_bad_heading_in_file(tmp_path):
    path = write(tmp_path / "h.toml", grid_toml(roadmap=pose_table(2, 2, "O") + pose_table(3, 4, "I", 2.0)))
    with pytest.raises(ConfigurationError) as info:
        load_scenario_file(path)
    msg = str(info.value)
    assert "h.toml" in msg and "roadmap[2]" in msg and "heading" in msg and "2.0" in msg


@pytest.mark.parametrize("entry,words", [
    ({"x": 2.0, "y": 2, "shape": "O"}, "'x' must be int"),
    ({"x": 2, "shape": "O"}, "missing key 'y'"),
    ({"x": 2, "y": 2}, "missing key 'shape'"),
    ({"x": 2, "y": 2, "shape": "O", "colour": 1}, "unknown key(s) colour"),
])
def test_malformed_roadmap_entry(entry, words):
    with pytest.raises(ScenarioError) as info:
        parse_scenario(grid_data(roadmap=[{"x": 2, "y": 2, "shape": "O"}, entry]))
    msg = str(info.value)
    assert "roadmap[2]" in msg and words in msg


def test_roadmap_must_be_an_array_of_tables(tmp_path):
    path = write(tmp_path / "t.toml", grid_toml(roadmap='[roadmap]\nx = 2\ny = 2\nshape = "O"\n'))
    with pytest.raises(ScenarioError, match="'roadmap' must be an array of tables"):
        load_scenario_file(path)


def test_moving_obstacle_running_into_a_wall():
    # Starts at (2, 5) and patrols 4 cells to the right: it runs into the obstacle cell (5, 5).
    with pytest.raises(ScenarioError) as info:
        parse_scenario(grid_data(moving=[{"cells": [[2, 5]], "route": [[0, 0], [4, 0]]}]), where="s.toml")
    msg = str(info.value)
    assert "s.toml" in msg and "moving[1]" in msg and "static obstacle cell (5, 5)" in msg
    assert not isinstance(info.value, ConfigurationError)


def test_second_moving_obstacle_running_into_a_wall_is_indexed():
    with pytest.raises(ScenarioError) as info:
        parse_scenario(grid_data(moving=[{"cells": [[6, 1]]}, {"cells": [[1, 6]], "route": [[0, 0], [0, 1]]}]))
    msg = str(info.value)
    assert "moving[2]" in msg and "(1, 7)" in msg


def test_moving_obstacle_leaving_the_map():
    grid = "......\n......\n......"
    with pytest.raises(ScenarioError) as info:
        parse_scenario(grid_data(grid=grid, roadmap=None, moving=[{"cells": [[4, 1]], "route": [[0, 0], [3, 0]]}]))
    msg = str(info.value)
    assert "moving[1]" in msg and "leaves the 6 x 3 map" in msg and "(6, 1)" in msg


def test_fast_moving_obstacle_jumping_over_a_wall_is_rejected():
    # Speed 2 with a wall one cell ahead: the obstacle sits only on displacements 0 and 2, but it
    # passes through displacement 1 in between, which is a wall.
    grid = "......\n..#...\n......"
    with pytest.raises(ScenarioError) as info:
        parse_scenario(grid_data(grid=grid, roadmap=None,
                                 moving=[{"cells": [[1, 1]], "route": [[0, 0], [2, 0]], "speed": 2}]))
    assert "moving[1]" in str(info.value) and "(2, 1)" in str(info.value)


@pytest.mark.parametrize("entry,words", [
    ({"cells": [[1, 1.5]]}, "cells"),
    ({"cells": [[1, 2, 3]]}, "cells"),
    ({"cells": [[6, 6]], "route": "east"}, "route"),
    ({"cells": [[6, 6]], "colour": 1}, "unknown key(s) colour"),
    ({"route": [[0, 0]]}, "missing key 'cells'"),
])
def test_malformed_moving_obstacle_is_located(entry, words):
    with pytest.raises(ScenarioError) as info:
        parse_scenario(grid_data(moving=[entry]), where="s.toml")
    msg = str(info.value)
    assert "s.toml" in msg and "moving[1]" in msg and words in msg


@pytest.mark.parametrize("entry", [{"cells": [[6, 6]], "speed": 0}, {"cells": [[6, 6]], "mode": "zigzag"},
                                   {"cells": []}])
def test_bad_moving_obstacle_parameters_are_located(entry):
    with pytest.raises(ScenarioError) as info:
        parse_scenario(grid_data(moving=[{"cells": [[6, 1]]}, entry]), where="s.toml")
    msg = str(info.value)
    assert "s.toml" in msg and "moving[2]" in msg


def test_moving_not_an_array_raises_scenario_error():
    with pytest.raises(ScenarioError, match="moving"):
        parse_scenario(grid_data(moving=5))


def test_hidden_cell_outside_the_map(tmp_path):
    path = write(tmp_path / "h.toml", grid_toml(extra="hidden = [[3, 3], [8, 2]]", roadmap=START_GOAL))
    with pytest.raises(ScenarioError) as info:
        load_scenario_file(path)
    msg = str(info.value)
    assert "h.toml" in msg and "hidden" in msg and "(8, 2)" in msg and "8 x 8" in msg


@pytest.mark.parametrize("hidden", [[3, 3], [[3, 3.5]], "x", [[-1, 2]]])
def test_malformed_or_negative_hidden_cells(hidden):
    with pytest.raises(ScenarioError, match="hidden"):
        parse_scenario(grid_data(hidden=hidden))


@pytest.mark.parametrize("value", [0, -1.0, "big", True])
def test_bad_cell_size(value):
    with pytest.raises(ScenarioError, match="cell_size_m"):
        parse_scenario(grid_data(cell_size_m=value))


@pytest.mark.parametrize("key,value,words", [
    ("cell_size_m", "inf", "'cell_size_m' must be a finite number > 0, got inf"),
    ("cell_size_m", "nan", "'cell_size_m' must be a finite number > 0, got nan"),
    ("cell_size_m", "-inf", "'cell_size_m' must be a finite number > 0, got -inf"),
])
def test_a_non_finite_number_in_a_file_names_the_file_and_the_key(tmp_path, key, value, words):
    path = write(tmp_path / "odd.toml", grid_toml(extra=f"{key} = {value}", roadmap=START_GOAL))
    with pytest.raises(ScenarioError) as info:
        load_scenario_file(path)
    message = str(info.value)
    assert message.startswith("odd.toml: ") and words in message and "None" not in message


@pytest.mark.parametrize("speed,words", [("inf", "got inf"), ("1.5", "got 1.5"), ("0", "got 0")])
def test_a_bad_moving_obstacle_speed_names_the_key(tmp_path, speed, words):
    moving = f"[[moving]]\ncells = [[6, 6]]\nroute = [[0, 0], [0, -1]]\nspeed = {speed}\n"
    path = write(tmp_path / "fast.toml", grid_toml(roadmap=START_GOAL + moving))
    with pytest.raises(ScenarioError) as info:
        load_scenario_file(path)
    message = str(info.value)
    assert message.startswith("fast.toml: moving[1]: 'speed'") and words in message


def test_a_ros_map_with_an_infinite_resolution_names_the_yaml_and_the_key(tmp_path):
    write_map(tmp_path, PIXELS, resolution=".inf")
    (tmp_path / "s.toml").write_text('name = "s"\nmap = "m.yaml"\n')
    with pytest.raises(ScenarioError) as info:
        load_scenario_file(tmp_path / "s.toml")
    message = str(info.value)
    assert "m.yaml" in message and "'resolution' must be a finite number > 0, got inf" in message


def test_a_start_on_obstacles_says_how_many_cells_collide():
    data = grid_data(grid="\n".join(["#" * 8] * 8), roadmap=[{"x": 3, "y": 3, "shape": "I"}])
    with pytest.raises(ConfigurationError) as info:
        parse_scenario(data, where="walls.toml")
    assert "collides with obstacles at 4 cells (3, 2), (3, 3), (3, 4), (3, 5)" in str(info.value)


# --------------------------------------------------------------------------------------------------
# ROS map_server maps


def write_map(directory: Path, pixels, *, kind="P5", maxval=255, name="m", yaml_extra="", resolution=0.05):
    """Write ``name.yaml`` and ``name.pgm``; ``pixels`` lists image rows top first."""
    pixels = np.asarray(pixels, dtype=np.int64)
    h, w = pixels.shape
    if kind == "P5":
        body = bytes(pixels.astype(np.uint8).ravel().tolist())
        data = f"P5\n# a comment\n{w} {h}\n{maxval}\n".encode() + body
    else:
        rows = "\n".join(" ".join(str(v) for v in row) for row in pixels.tolist())
        data = f"P2\n{w} {h}\n{maxval}\n{rows}\n".encode()
    (directory / f"{name}.pgm").write_bytes(data)
    (directory / f"{name}.yaml").write_text(
        f"image: {name}.pgm\nresolution: {resolution}\norigin: [0.0, 0.0, 0.0]\n{yaml_extra}"
    )
    return directory / f"{name}.yaml"


# Default thresholds: occupied 0.65, free 0.196; p = (255 - v) / 255.
# 255 -> p 0 free; 210 -> p 0.176 free; 150 -> p 0.41 unknown; 60 -> p 0.76 occupied; 0 occupied.
PIXELS = [[255, 210, 150],
          [60, 0, 255]]


@pytest.mark.parametrize("kind", ["P5", "P2"])
def test_ros_map_thresholds_and_flip(tmp_path, kind):
    occ, cell = load_ros_map(write_map(tmp_path, PIXELS, kind=kind))
    assert cell == 0.05
    assert occ.dtype == bool and occ.shape == (2, 3)
    # The top image row becomes the highest y.
    assert occ[1].tolist() == [False, False, True]   # unknown (150) -> obstacle
    assert occ[0].tolist() == [True, True, False]


def test_read_pgm_p5_and_p2_agree(tmp_path):
    write_map(tmp_path, PIXELS, kind="P5", name="a")
    write_map(tmp_path, PIXELS, kind="P2", name="b")
    a, ma = read_pgm(tmp_path / "a.pgm")
    b, mb = read_pgm(tmp_path / "b.pgm")
    assert ma == mb == 255
    assert a.tolist() == b.tolist() == PIXELS


def test_read_pgm_sixteen_bit(tmp_path):
    (tmp_path / "w.pgm").write_bytes(b"P5 2 1 1000\n" + (0).to_bytes(2, "big") + (1000).to_bytes(2, "big"))
    image, maxval = read_pgm(tmp_path / "w.pgm")
    assert maxval == 1000 and image.tolist() == [[0, 1000]]


def test_ros_map_custom_thresholds(tmp_path):
    # free_thresh 0.5, occupied_thresh 0.8: 150 (p 0.41) becomes free, 60 (p 0.76) is now unknown -> obstacle.
    occ, _ = load_ros_map(write_map(tmp_path, PIXELS, yaml_extra="free_thresh: 0.5\noccupied_thresh: 0.8\n"))
    assert occ[1].tolist() == [False, False, False]
    assert occ[0].tolist() == [True, True, False]


def test_ros_map_negate(tmp_path):
    # negate: p = v / 255: 255 occupied, 210 (p 0.82) occupied, 150 (0.59) unknown, 60 (0.235) unknown, 0 free.
    occ, _ = load_ros_map(write_map(tmp_path, PIXELS, yaml_extra="negate: 1\n"))
    assert occ[1].tolist() == [True, True, True]
    assert occ[0].tolist() == [True, False, True]


def test_ros_map_cell_size_aggregates_pixel_blocks(tmp_path):
    # 4 x 4 image, 2 x 2 cells: each cell is free only if its four pixels are.
    pixels = [[255, 255, 255, 0],
              [255, 255, 255, 255],
              [150, 255, 255, 255],
              [255, 255, 255, 255]]
    occ, cell = load_ros_map(write_map(tmp_path, pixels, resolution=0.05), cell_size=0.1)
    assert cell == pytest.approx(0.1)
    # Top image half -> y = 1: right cell holds the 0 pixel. Bottom half -> y = 0: left cell holds 150.
    assert occ.tolist() == [[True, False], [False, True]]


def test_ros_map_cell_size_equal_to_resolution_is_identity(tmp_path):
    path = write_map(tmp_path, PIXELS)
    a, _ = load_ros_map(path)
    b, cell = load_ros_map(path, cell_size=0.05)
    assert cell == 0.05 and np.array_equal(a, b)


@pytest.mark.parametrize("cell_size", [0.075, 0.025, 0.11])
def test_ros_map_cell_size_not_a_multiple(tmp_path, cell_size):
    path = write_map(tmp_path, [[255] * 4] * 4)
    with pytest.raises(ScenarioError) as info:
        load_ros_map(path, cell_size=cell_size)
    msg = str(info.value)
    assert "m.yaml" in msg and "multiple" in msg and str(cell_size) in msg
    assert not isinstance(info.value, MapFormatError)


def test_ros_map_partial_cells_are_padded_as_blocked(tmp_path):
    # 5 x 5 pixels, walls on the image's top row and right column, cells of 2 x 2 pixels: a 3 x 3
    # grid whose cells that are partly off the image (top row, right column) count as blocked.
    image = [[0] * 5] + [[254, 254, 254, 254, 0] for _ in range(4)]
    occ, _ = load_ros_map(write_map(tmp_path, image), cell_size=0.1)
    assert occ.shape == (3, 3)
    assert occ[2].all() and occ[:, 2].all()
    assert not occ[:2, :2].any()


@pytest.mark.parametrize("data,words", [
    (b"P6\n2 1\n255\n\x00\x00\x00\x00\x00\x00", "magic"),
    (b"BM\x00\x00\x00", "PGM"),
    (b"", "truncated"),
    (b"P5\n3 2\n", "truncated"),
    (b"P5\n3 2\n255\n\x00\x00\x00", "3 bytes, 6 expected"),
    (b"P2\n3 2\n255\n1 2 3 4 5\n", "5 pixels, 6 expected"),
    (b"P2\n3 1\n255\n1 two 3\n", "non-numeric"),
    (b"P2\n2 1\n9\n3 10\n", "max value 9"),
    (b"P5\n3 x\n255\n\x00\x00\x00", "malformed PGM header"),
    (b"P5\n0 2\n255\n", "bad PGM size"),
])
def test_bad_pgm_raises_map_format_error(tmp_path, data, words):
    (tmp_path / "m.pgm").write_bytes(data)
    (tmp_path / "m.yaml").write_text("image: m.pgm\nresolution: 0.05\n")
    with pytest.raises(MapFormatError) as info:
        load_ros_map(tmp_path / "m.yaml")
    msg = str(info.value)
    assert "m.pgm" in msg and words in msg


@pytest.mark.parametrize("text,words", [
    ("resolution: 0.05\n", "missing key 'image'"),
    ("image: m.pgm\n", "missing key 'resolution'"),
    ("image: m.pgm\nresolution: fine\n", "'resolution' must be a finite number > 0, got 'fine'"),
    ("image: m.pgm\nresolution: .inf\n", "'resolution' must be a finite number > 0, got inf"),
    ("image: m.pgm\nresolution: 0.05\noccupied_thresh: .nan\n", "'occupied_thresh' must be a finite number"),
    ("image: m.pgm\nresolution: 0.05\nnegate: maybe\n", "'negate' must be 0 or 1"),
    ("image: m.pgm\nresolution: 0.05\nfree_thresh: 0.9\noccupied_thresh: 0.2\n", "free_thresh"),
    ("image: m.pgm\nresolution: 0.05\nmode: raw\n", "'raw'"),
    ("- a list\n", "mapping"),
    ("image: m.pgm\nresolution: [0.05\n", "malformed YAML"),
])
def test_bad_map_yaml_raises_scenario_error(tmp_path, text, words):
    write_map(tmp_path, PIXELS)
    (tmp_path / "m.yaml").write_text(text)
    with pytest.raises(ScenarioError) as info:
        load_ros_map(tmp_path / "m.yaml")
    msg = str(info.value)
    assert "m.yaml" in msg and words in msg


def test_ros_map_missing_image(tmp_path):
    (tmp_path / "m.yaml").write_text("image: gone.pgm\nresolution: 0.05\n")
    with pytest.raises(ScenarioError, match="gone.pgm"):
        load_ros_map(tmp_path / "m.yaml")


def test_ros_map_missing_yaml(tmp_path):
    with pytest.raises(ScenarioError, match="absent.yaml"):
        load_ros_map(tmp_path / "absent.yaml")


def test_toml_map_resolves_relative_to_the_toml_file(tmp_path, monkeypatch):
    maps = tmp_path / "maps"
    maps.mkdir()
    pixels = np.full((8, 8), 255)
    pixels[0, :] = pixels[-1, :] = pixels[:, 0] = pixels[:, -1] = 0
    pixels[2, 5] = 0  # top-first row 2 -> y = 5
    write_map(maps, pixels, name="room", resolution=0.25)
    (maps / "room.toml").write_text('name = "r"\nsource = "t"\nmap = "room.yaml"\n' + START_GOAL)
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)
    sc = load_scenario_file(Path("..") / "maps" / "room.toml")
    assert sc.workspace.cell_size == 0.25
    assert format_grid(sc.workspace.occupancy) == ROOM
    assert sc.start == Pose(2, 2, "O", 0)


def test_toml_map_with_cell_size(tmp_path):
    pixels = np.full((4, 6), 255)
    pixels[0, 0] = 0  # top-left pixel -> cell (0, 1) of a 3 x 2 grid
    write_map(tmp_path, pixels, name="small", resolution=0.1)
    (tmp_path / "s.toml").write_text('name = "s"\nsource = "t"\nmap = "small.yaml"\ncell_size_m = 0.2\n')
    sc = load_scenario_file(tmp_path / "s.toml")
    assert sc.workspace.cell_size == pytest.approx(0.2)
    assert sc.workspace.occupancy.tolist() == [[False, False, False], [True, False, False]]


def test_toml_map_cell_size_not_a_multiple(tmp_path):
    write_map(tmp_path, np.full((4, 6), 255), name="small", resolution=0.1)
    (tmp_path / "s.toml").write_text('name = "s"\nsource = "t"\nmap = "small.yaml"\ncell_size_m = 0.15\n')
    with pytest.raises(ScenarioError, match="multiple"):
        load_scenario_file(tmp_path / "s.toml")


def test_toml_map_missing_yaml_is_named(tmp_path):
    (tmp_path / "s.toml").write_text('name = "s"\nsource = "t"\nmap = "nothere.yaml"\n')
    with pytest.raises(ScenarioError, match="nothere.yaml"):
        load_scenario_file(tmp_path / "s.toml")


def test_map_pointing_at_binary_image_raises_scenario_error(tmp_path):
    write_map(tmp_path, PIXELS)  # P5 bytes include 0xff
    with pytest.raises(ScenarioError, match="m.pgm"):
        load_ros_map(tmp_path / "m.pgm")


# --------------------------------------------------------------------------------------------------
# Continuous scenarios (seed 002)

CONTINUOUS = """\
name = "field"
source = "seed 002"
width = 10.0
height = 8
robot_radius = 0.5
obstacles = [[1, 1, 3, 2], [[5, 5], [7, 5], [6, 7]]]

[[robots]]
start = [0.5, 0.5]
goal = [9, 7.5]

[[robots]]
start = [4, 4]
goal = [8, 1]
"""


def test_continuous_scenario_loads(tmp_path):
    sc = load_scenario_file(write(tmp_path / "c.toml", CONTINUOUS))
    assert isinstance(sc, ContinuousScenario)
    assert sc.name == "field" and sc.width == 10.0 and sc.height == 8.0 and sc.robot_radius == 0.5
    rect, tri = sc.obstacles
    assert rect.shape == (4, 2)
    assert rect.tolist() == [[1, 1], [3, 1], [3, 2], [1, 2]]
    assert tri.tolist() == [[5, 5], [7, 5], [6, 7]]
    assert sc.starts.tolist() == [[0.5, 0.5], [4, 4]]
    assert sc.goals.tolist() == [[9, 7.5], [8, 1]]


@pytest.mark.parametrize("point,key", [("[10.5, 1]", "start"), ("[-0.1, 1]", "start"), ("[1, 8.01]", "goal")])
def test_continuous_robot_outside_the_rectangle(tmp_path, point, key):
    other = "goal" if key == "start" else "start"
    text = CONTINUOUS.replace("start = [4, 4]\ngoal = [8, 1]", f"{key} = {point}\n{other} = [0.5, 0.5]")
    with pytest.raises(ConfigurationError) as info:
        load_scenario_file(write(tmp_path / "c.toml", text))
    msg = str(info.value)
    assert "c.toml" in msg and "robots[2]" in msg and key in msg and "outside" in msg


@pytest.mark.parametrize("change,words", [
    (("obstacles = [[1, 1, 3, 2], ", "obstacles = [[3, 1, 1, 2], "), "obstacles[1]"),
    (("[[5, 5], [7, 5], [6, 7]]", "[[5, 5], [7, 5]]"), "obstacles[2]"),
    (("robot_radius = 0.5", "robot_radius = -1"), "robot_radius"),
    (("width = 10.0", "width = 0"), "width"),
    (("height = 8\n", "height = 8\ncolour = 1\n"), "colour"),
    (("start = [4, 4]", "start = [4, 4, 1]"), "robots[2]"),
])
def test_continuous_errors(tmp_path, change, words):
    text = CONTINUOUS.replace(*change)
    assert text != CONTINUOUS
    with pytest.raises(ScenarioError) as info:
        load_scenario_file(write(tmp_path / "c.toml", text))
    assert words in str(info.value)


def test_a_continuous_file_without_a_name_is_named_after_the_file(tmp_path):
    text = CONTINUOUS.replace("name = \"field\"\n", "")
    assert load_scenario_file(write(tmp_path / "open_air.toml", text)).name == "open_air"


@pytest.mark.parametrize("change", [
    ("robot_radius = 0.5", 'robot_radius = "big"'),
    ("obstacles = [[1, 1, 3, 2], [[5, 5], [7, 5], [6, 7]]]", "obstacles = 5"),
    ("start = [4, 4]", 'start = ["a", 4]'),
])
def test_continuous_non_numeric_values_raise_scenario_error(tmp_path, change):
    with pytest.raises(ScenarioError):
        load_scenario_file(write(tmp_path / "c.toml", CONTINUOUS.replace(*change)))


# --------------------------------------------------------------------------------------------------
# Bundled scenarios by name


def test_load_unknown_scenario_name():
    with pytest.raises(ScenarioError) as info:
        load_scenario("no_such_name")
    assert "'no_such_name'" in str(info.value)


def test_load_scenario_accepts_a_path(tmp_path):
    path = write(tmp_path / "room.toml", grid_toml(roadmap=START_GOAL))
    assert load_scenario(path).name == "room"
    assert load_scenario(str(path)).start == Pose(2, 2, "O", 0)


def test_list_scenarios_is_sorted_and_loadable():
    names = list_scenarios()
    assert names == sorted(names)
    assert all(isinstance(n, str) and not n.endswith(".toml") for n in names)
    for name in names[:1]:
        assert load_scenario(name).name
