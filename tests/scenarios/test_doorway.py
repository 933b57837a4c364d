"""indoor_room_doorway: indoor_room with a doorway in its dividing wall, the analog of Do et al. 2021's
Table 8 map (O-shape-only A* and Dijkstra), checked against indoor_room and an independent search."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import dijkstra

from htetro_opt.scenarios import load_scenario, read_pgm, scenario_path
from htetro_opt.solvers.grid_paths import plan_exact

AXES = ["x+", "x-", "y+", "y-"]
DIAGONALS = ["x+y+", "x+y-", "x-y+", "x-y-"]
DOORWAY = sorted((x, y) for x in range(62, 66) for y in (10, 11))  # (x, y), y up (MODEL.md §1)


@pytest.fixture(scope="module")
def room():
    return load_scenario("indoor_room")


@pytest.fixture(scope="module")
def doorway():
    return load_scenario("indoor_room_doorway")


def o_shape_time(occupancy: np.ndarray, start, goal, *, diagonals: bool) -> float:
    """The oracle: the fastest O-shape (heading 0) translation path by a search written from MODEL.md §4.

    The O-shape at B2 = (x, y) covers x..x+1 × y−1..y. An axis step sweeps the start and end
    footprints; a diagonal step also the cells beside each block's diagonal, which for the 2 × 2
    square fill the 3 × 3 box around both footprints.
    """
    h, w = occupancy.shape
    free = ~occupancy
    # box_free[y, x]: the a × b box with lower-left cell (x, y) is free (a, b = 2 or 3)
    def box_free(a, b):
        out = np.zeros((h, w), dtype=bool)
        out[: h - b + 1, : w - a + 1] = np.all(
            [free[j: h - b + 1 + j, i: w - a + 1 + i] for i in range(a) for j in range(b)], axis=0)
        return out

    rows, cols, costs = [], [], []
    node = np.arange(h * w).reshape(h, w)
    steps = [(1, 0), (-1, 0), (0, 1), (0, -1)] + ([(1, 1), (1, -1), (-1, 1), (-1, -1)] if diagonals else [])
    for dx, dy in steps:
        # lower-left cell of the swept box of B2 = (x, y): min(x, x + dx), min(y, y + dy) − 1
        a, b = 2 + abs(dx), 2 + abs(dy)
        ok = box_free(a, b)
        ys, xs = np.mgrid[0:h, 0:w]
        lx, ly = xs + min(dx, 0), ys - 1 + min(dy, 0)
        inside = (lx >= 0) & (ly >= 0) & (lx < w) & (ly < h) & (xs + dx >= 0) & (xs + dx < w) \
            & (ys + dy >= 0) & (ys + dy < h)
        valid = np.zeros((h, w), dtype=bool)
        valid[inside] = ok[ly[inside], lx[inside]]
        y, x = np.nonzero(valid)
        rows.append(node[y, x])
        cols.append(node[y + dy, x + dx])
        costs.append(np.full(len(y), math.hypot(dx, dy)))
    graph = coo_matrix((np.concatenate(costs), (np.concatenate(rows), np.concatenate(cols))),
                       shape=(h * w, h * w)).tocsr()
    return float(dijkstra(graph, indices=node[start.y, start.x])[node[goal.y, goal.x]])


def test_it_loads_with_indoor_room_s_size_cells_and_roadmap(room, doorway):
    assert doorway.name == "indoor_room_doorway"
    assert (doorway.workspace.width, doorway.workspace.height) == (128, 128)
    assert doorway.workspace.cell_size == room.workspace.cell_size == 0.25
    assert doorway.roadmap == room.roadmap
    assert "Table 8" in doorway.source and "Table 8" in doorway.description


def test_it_differs_from_indoor_room_exactly_in_the_doorway_cells(room, doorway):
    changed = np.argwhere(room.workspace.occupancy != doorway.workspace.occupancy)[:, ::-1]
    assert sorted(map(tuple, changed.tolist())) == DOORWAY
    assert not doorway.workspace.occupancy[10:12, 62:66].any()


def test_the_doorway_cells_are_the_full_thickness_of_the_dividing_wall(room):
    occ = room.workspace.occupancy
    # the dividing wall: columns 62..65 blocked on every row but the one-cell passage at y = 70
    assert [y for y in range(128) if not occ[y, 62:66].all()] == [70]
    assert not occ[:, 61].all() and not occ[:, 66].all()
    # at y = 10, 11 the wall is exactly x = 62..65, free on both sides: the doorway goes through
    for y in (10, 11):
        assert occ[y, 62:66].all() and not occ[y, 61] and not occ[y, 66]


def test_the_image_is_indoor_room_s_with_the_doorway_pixels_freed():
    # the PGM is what the script in the scenario file writes: no other pixel edited
    before, _ = read_pgm(scenario_path("indoor_room").with_suffix(".pgm"))
    after, maxval = read_pgm(scenario_path("indoor_room_doorway").with_suffix(".pgm"))
    assert maxval == 255 and before.shape == after.shape == (128, 128)
    rows, cols = np.nonzero(before != after)
    assert sorted(zip((127 - rows).tolist(), cols.tolist())) == sorted((y, x) for x, y in DOORWAY)
    assert (after[before != after] == 254).all() and (before[before != after] == 0).all()


def test_only_the_doorway_lets_the_o_shape_through(room, doorway):
    assert not plan_exact(room.workspace, room.roadmap, commands=AXES + DIAGONALS).reached
    assert plan_exact(doorway.workspace, doorway.roadmap, commands=AXES).reached


@pytest.mark.parametrize("method, commands, expected", [
    ("astar", AXES, 144.0),  # the issue's O-only A* (x±, y±)
    ("dijkstra", AXES + DIAGONALS, 128.8),  # the issue's O-only Dijkstra with diagonals
])
def test_o_shape_only_times_are_the_issue_s_and_the_oracle_s(doorway, method, commands, expected):
    plan = plan_exact(doorway.workspace, doorway.roadmap, commands=commands, method=method)
    assert plan.reached and set(plan.tokens) <= set(commands)
    assert plan.time == pytest.approx(expected, abs=0.05)
    oracle = o_shape_time(doorway.workspace.occupancy, doorway.start, doorway.goal,
                          diagonals=len(commands) > 4)
    assert plan.time == pytest.approx(oracle, abs=1e-9)
    assert math.isinf(o_shape_time(load_scenario("indoor_room").workspace.occupancy, doorway.start,
                                   doorway.goal, diagonals=True))


def test_shapeshifting_through_the_narrow_passage_beats_the_o_shape_through_the_doorway(doorway):
    # Table 8's point: with reconfiguration the robot takes the short way, through the 1-cell passage
    full = plan_exact(doorway.workspace, doorway.roadmap, diagonals=True)
    o_only = plan_exact(doorway.workspace, doorway.roadmap, commands=AXES + DIAGONALS)
    assert full.reached and any(t.startswith("s") for t in full.tokens)
    assert full.time < o_only.time - 10
    in_wall = full.poses[(full.poses[:, 0] >= 62) & (full.poses[:, 0] <= 65)]
    assert len(in_wall) and (in_wall[:, 1] == 70).all()  # B2 crosses the wall in the passage, not the doorway
