"""Workspaces: what an occupancy grid may hold, the checks of their arguments, and short cell lists."""

import numpy as np
import pytest

from htetro_opt.errors import ConfigurationError, ParameterError, ScenarioError
from htetro_opt.model import MovingObstacle, Workspace, grid_distance
from htetro_opt.model.workspace import check_workspace, describe_cells


@pytest.mark.parametrize("occupancy", [[[0, 1], [1, 0]], np.array([[0.0, 1.0], [1.0, 0.0]]),
                                       np.array([[False, True], [True, False]])])
def test_an_occupancy_of_booleans_or_0_1_is_accepted(occupancy):
    assert Workspace(occupancy).occupancy.tolist() == [[False, True], [True, False]]


@pytest.mark.parametrize("occupancy,got", [
    ([[0.5, 0.0]], "got list [[0.5, 0.0]]"),  # np.array(..., dtype=bool) would make 0.5 an obstacle
    ([["#", "."]], "got list [['#', '.']]"),  # and "." one as well
    ("#.\n..", "got str '#.\\n..'"),
    (None, "got NoneType None"),
    (np.zeros((2, 2, 2)), "got ndarray"),
    (np.zeros((0, 3), dtype=bool), "got shape (0, 3)"),
])
def test_any_other_occupancy_is_refused_saying_what_it_got(occupancy, got):
    with pytest.raises(ScenarioError) as info:
        Workspace(occupancy)
    assert "occupancy must be a non-empty 2-D array of booleans (True = obstacle) or 0/1" in str(info.value)
    assert got in str(info.value)


def test_moving_obstacles_must_be_moving_obstacles():
    one = MovingObstacle([[0, 0]], [[0, 0], [1, 0]])
    assert Workspace(np.zeros((2, 3), bool), moving=one).moving == (one,)
    assert Workspace(np.zeros((2, 3), bool), moving=[one]).moving == (one,)
    for bad in (5, [5], "x", [one, None]):
        with pytest.raises(ScenarioError, match="moving must be a sequence of MovingObstacle"):
            Workspace(np.zeros((2, 3), bool), moving=bad)


@pytest.mark.parametrize("cells,route", [("ab", [[0, 0]]), ([[0.5, 0]], [[0, 0]]), ([[0, 0]], [[0, 1, 2]])])
def test_a_moving_obstacle_needs_integer_pairs(cells, route):
    with pytest.raises(ScenarioError, match="integer pairs"):
        MovingObstacle(cells, route)


def test_check_workspace_names_the_argument_and_what_it_got():
    ws = Workspace(np.zeros((2, 2), bool))
    assert check_workspace(ws) is ws
    with pytest.raises(ParameterError, match=r"^map must be a Workspace .* got ndarray"):
        check_workspace(np.zeros((2, 2)), "map")


def test_grid_distance_checks_its_arguments():
    ws = Workspace(np.zeros((2, 3), bool))
    assert grid_distance(ws, (np.int64(0), 0)).tolist() == [[0.0, 1.0, 2.0], [1.0, 2.0, 3.0]]
    for goal in ("ab", (0.5, 0), 3, (0, 0, 0)):
        with pytest.raises(ConfigurationError, match="goal must be a cell"):
            grid_distance(ws, goal)
    with pytest.raises(ConfigurationError, match="outside the map"):
        grid_distance(ws, (5, 0))
    with pytest.raises(ParameterError, match="diagonals"):
        grid_distance(ws, (0, 0), diagonals="yes")


def test_describe_cells_counts_and_shows_at_most_the_limit():
    assert describe_cells([(1, 2)]) == "cell (1, 2)"
    assert describe_cells(np.array([[1, 2], [3, 4]])) == "2 cells (1, 2), (3, 4)"
    many = describe_cells([(x, 7) for x in range(700)])
    assert many.startswith("700 cells (0, 7), (1, 7), (2, 7), (3, 7), (4, 7) and 695 more") and len(many) < 80
