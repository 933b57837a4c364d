"""Continuous scenarios (Nazarahari et al. 2019): the loader's geometric checks, from_grid, radii."""

import textwrap

import numpy as np
import pytest

from htetro_opt.errors import ConfigurationError, ParameterError, ScenarioError
from htetro_opt.scenarios import ContinuousScenario, load_scenario, load_scenario_file

BASE = """\
width = 10
height = 8
robot_radius = 0.5
obstacles = [[1, 1, 3, 2], [[5, 5], [7, 5], [6, 7]]]

[[robots]]
start = [0.5, 3]
goal = [9, 7.5]

[[robots]]
start = [4, 4]
goal = [8, 1]
"""


def load(tmp_path, text):
    path = tmp_path / "field.toml"
    path.write_text(textwrap.dedent(text))
    return load_scenario_file(path)


@pytest.mark.parametrize("change, error, words", [
    (("[[5, 5], [7, 5], [6, 7]]", "[[5, 5], [7, 7], [7, 5], [5, 7]]"), ScenarioError,
     "field.toml: obstacles[2]: invalid polygon: Self-intersection at (6, 6)"),
    (("[[5, 5], [7, 5], [6, 7]]", "[[5, 5], [6, 6], [7, 7]]"), ScenarioError, "obstacles[2]: invalid polygon"),
    (("start = [4, 4]", "start = [1.2, 3]"), ConfigurationError,
     "robots[1] and robots[2] overlap: their starts [0.5, 3.0] and [1.2, 3.0] are 0.7 apart, less than 2 r = 1"),
    (("goal = [8, 1]", "goal = [8.5, 7]"), ConfigurationError, "robots[1] and robots[2] overlap: their goals"),
    (("start = [4, 4]", "start = [2, 2.3]"), ConfigurationError, "robots[2]: start [2.0, 2.3] collides with obstacles[1]"),
    (("goal = [8, 1]", "goal = [6, 5.5]"), ConfigurationError, "robots[2]: goal [6.0, 5.5] collides with obstacles[2]"),
    (("robot_radius = 0.5", "robot_radius = 4"), ScenarioError, "leaves no room"),
])
def test_the_loader_checks_polygons_collisions_and_overlapping_robots(tmp_path, change, error, words):
    text = BASE.replace(*change)
    assert text != BASE
    with pytest.raises(error) as info:
        load(tmp_path, text)
    assert words in str(info.value)


def test_touching_an_obstacle_or_another_robot_is_allowed(tmp_path):
    text = BASE.replace("start = [4, 4]", "start = [1.5, 3]").replace("goal = [8, 1]", "goal = [3.5, 1.5]")
    sc = load(tmp_path, text)  # the starts exactly 2 r apart; the goal exactly r from obstacles[1]
    assert sc.geometry.points_feasible(sc.goals).all()
    assert sc.geometry.clearance([[3.5, 1.5]])[0] == 0.0


def test_a_point_robot_may_stand_on_an_obstacle_edge_but_not_inside(tmp_path):
    text = BASE.replace("robot_radius = 0.5", "robot_radius = 0").replace("start = [4, 4]", "start = [3, 1.5]")
    assert load(tmp_path, text).starts[1].tolist() == [3, 1.5]
    with pytest.raises(ConfigurationError, match="obstacles\\[1\\]"):
        load(tmp_path, text.replace("start = [3, 1.5]", "start = [2.9, 1.5]"))


def test_with_robot_radius_takes_numbers_and_shape_letters_and_rechecks():
    sc = load_scenario("ega_cross4")
    assert sc.with_robot_radius(0.25).robot_radius == 0.25
    bigger = sc.with_robot_radius("O")
    assert bigger.robot_radius == pytest.approx(np.sqrt(2)) and bigger.geometry.robot_radius == bigger.robot_radius
    with pytest.raises(ConfigurationError, match="collides|outside"):
        sc.with_robot_radius(3.5)
    with pytest.raises(ParameterError, match="robot_radius"):
        sc.with_robot_radius("Q")


def test_from_grid_turns_cells_into_unit_squares_and_the_roadmap_ends_into_start_and_goal():
    grid = load_scenario("three_slit")
    sc = ContinuousScenario.from_grid(grid)
    assert (sc.width, sc.height) == (grid.workspace.width, grid.workspace.height)
    assert sc.starts.tolist() == [[grid.start.x + 0.5, grid.start.y + 0.5]]
    assert sc.goals.tolist() == [[grid.goal.x + 0.5, grid.goal.y + 0.5]]
    occ = grid.workspace.occupancy
    centres = np.argwhere(np.ones_like(occ))[:, ::-1] + 0.5
    assert np.array_equal(~sc.geometry.points_feasible(centres), occ[centres[:, 1].astype(int), centres[:, 0].astype(int)])
    assert sum(np.ptp(o[:, 0]) * np.ptp(o[:, 1]) for o in sc.obstacles) == occ.sum()  # runs do not overlap
    assert ContinuousScenario.from_grid(grid, robot_radius="O").robot_radius == pytest.approx(np.sqrt(2))


@pytest.mark.parametrize("scenario, error", [("tiling_6x6", ScenarioError), ("ega01_random1", ScenarioError)])
def test_from_grid_needs_a_grid_scenario_with_a_roadmap(scenario, error):
    with pytest.raises(error):
        ContinuousScenario.from_grid(load_scenario(scenario))


def test_from_grid_refuses_a_radius_that_makes_the_start_collide():
    grid = load_scenario("three_slit")
    room = ContinuousScenario.from_grid(grid).geometry.clearance(np.array([[grid.start.x + 0.5, grid.start.y + 0.5]]))[0]
    assert ContinuousScenario.from_grid(grid, robot_radius=room).robot_radius == room  # touching
    with pytest.raises(ConfigurationError, match="robots\\[1\\]: start"):
        ContinuousScenario.from_grid(grid, robot_radius=room + 0.01)
