"""The bundled scenario library reconstructs the papers' environments with their stated features."""

import re

import numpy as np
import pytest

from htetro_opt.model import Simulator
from htetro_opt.scenarios import ContinuousScenario, Scenario, list_scenarios, load_scenario
from htetro_opt.solvers.grid_paths import plan_exact

SEED_000 = ["random", "h_shape", "spiral", "three_slit", "perpendicular_dynamic", "parallel_dynamic"]
SIZES = {
    **{name: (24, 24) for name in SEED_000},
    "zigzag": (24, 24), "maze": (24, 24), "maze_partial": (24, 24), "indoor_room": (128, 128),
    "indoor_room_doorway": (128, 128),
    "tiling_6x6": (6, 6), "tiling_8x7": (8, 7), "tiling_10x10": (10, 10), "tiling_11x11": (11, 11),
    "coverage_16x7": (16, 7), "coverage_16x16": (16, 16),
}
TRANSLATIONS = ["x+", "x-", "y+", "y-"]


@pytest.fixture(scope="module")
def scenarios():
    return {name: load_scenario(name) for name in list_scenarios()}


def test_the_library_holds_every_environment_of_the_issue(scenarios):
    assert set(SIZES) <= set(scenarios)


@pytest.mark.parametrize("name", sorted(SIZES))
def test_size_and_source(scenarios, name):
    sc = scenarios[name]
    assert isinstance(sc, Scenario) and sc.name == name
    assert (sc.workspace.width, sc.workspace.height) == SIZES[name]
    assert PAPER.match(sc.source) and "Fig" in sc.source, sc.source


PAPER = re.compile(r"^(Cheng|Do|Le|Nazarahari) et al\., [A-Za-z ]+ (2018|2019|2020|2021), ")
"""A bundled source names its paper by authors, venue and year: "Cheng et al., IEEE Access 2020, Fig. 9d"."""


def test_no_bundled_text_names_a_paper_by_its_seed_number(scenarios):
    for name, sc in scenarios.items():
        for text in (sc.source, sc.description):
            assert not re.search(r"seed[ -]?00\d", text, re.I), (name, text)


@pytest.mark.parametrize("name", SEED_000)
def test_seed_000_roadmaps_begin_and_end_with_the_o_shape(scenarios, name):
    roadmap = scenarios[name].roadmap
    assert roadmap[0].shape == "O" and roadmap[-1].shape == "O"
    assert len(roadmap) == (4 if name == "perpendicular_dynamic" else 2)
    assert bool(scenarios[name].workspace.moving) == name.endswith("dynamic")


@pytest.mark.parametrize("name", ["three_slit", "parallel_dynamic"])
def test_impassable_for_the_o_shape_passable_after_shapeshifting(scenarios, name):
    sc = scenarios[name]
    static = sc.workspace.without_moving()
    assert not plan_exact(static, sc.roadmap, commands=TRANSLATIONS).reached
    assert not plan_exact(static, sc.roadmap, commands=TRANSLATIONS + ["r+", "r-"]).reached
    plan = plan_exact(sc.workspace, sc.roadmap)
    assert plan.reached
    assert any(t.startswith("s") for t in plan.tokens)


@pytest.mark.parametrize("name", ["perpendicular_dynamic", "parallel_dynamic"])
def test_moving_obstacles_are_in_the_way(scenarios, name):
    sc = scenarios[name]
    static = plan_exact(sc.workspace.without_moving(), sc.roadmap)
    dynamic = plan_exact(sc.workspace, sc.roadmap)
    assert dynamic.reached and dynamic.time > static.time
    assert not Simulator(sc.workspace).run([static.commands], sc.start).valid[0]


WITHOUT_ROADMAP = {n for n in SIZES if n.startswith("tiling")} | {"coverage_16x16"}  # tiling maps only


def test_only_the_tiling_maps_have_no_roadmap(scenarios):
    assert {n for n in SIZES if not scenarios[n].roadmap} == WITHOUT_ROADMAP
    assert all(scenarios[n].goal is None for n in WITHOUT_ROADMAP)


@pytest.mark.parametrize("name", sorted(set(SIZES) - WITHOUT_ROADMAP))
def test_every_roadmap_is_solvable_and_the_plan_revalidates(scenarios, name):
    sc = scenarios[name]
    diagonals = name in ("zigzag", "maze", "maze_partial", "indoor_room",
                         "indoor_room_doorway")  # seed 001 moves diagonally
    plan = plan_exact(sc.workspace, sc.roadmap, diagonals=diagonals)
    assert plan.reached
    result = Simulator(sc.workspace, diagonals=diagonals).run([plan.commands], sc.start, roadmap=sc.roadmap[1:])
    assert result.valid[0] and result.reached[0]
    assert result.time[0] == pytest.approx(plan.time)


def test_seed_000_spiral_is_the_longest(scenarios):
    times = {n: plan_exact(scenarios[n].workspace.without_moving(), scenarios[n].roadmap).time for n in SEED_000}
    assert max(times, key=times.get) == "spiral"


def test_maze_partial_unknown_obstacles_start_and_goal(scenarios):
    sc = scenarios["maze_partial"]
    assert sorted(map(tuple, sc.hidden.tolist())) == [(5, 11), (6, 11)]
    assert (sc.start.x, sc.start.y) == (2, 2) and (sc.goal.x, sc.goal.y) == (22, 21)
    known = plan_exact(sc.workspace, sc.roadmap, diagonals=True)
    true = plan_exact(sc.true_workspace(), sc.roadmap, diagonals=True)
    assert true.reached and true.time > known.time  # the unknown cells lengthen the best path
    assert not Simulator(sc.true_workspace(), diagonals=True).run([known.commands], sc.start).valid[0]


def test_indoor_room_passage_needs_a_shapeshift(scenarios):
    sc = scenarios["indoor_room"]
    assert not plan_exact(sc.workspace, sc.roadmap, commands=TRANSLATIONS).reached
    plan = plan_exact(sc.workspace, sc.roadmap)
    assert plan.reached and any(t.startswith("s") for t in plan.tokens)


@pytest.mark.parametrize("name", ["tiling_6x6", "tiling_8x7", "tiling_10x10", "tiling_11x11"])
def test_tiling_maps_have_a_free_area_of_whole_tetrominoes(scenarios, name):
    free = int((~scenarios[name].workspace.occupancy).sum())
    assert free % 4 == 0


def test_tiling_11x11_obstacles_of_fig_12d(scenarios):
    occ = scenarios["tiling_11x11"].workspace.occupancy
    cells = sorted(map(tuple, np.argwhere(occ)[:, ::-1].tolist()))
    assert cells == sorted([(8, 10), (9, 10), (8, 9), (9, 9), (4, 4), (5, 4), (8, 4), (4, 3), (5, 3)])


def test_every_bundled_scenario_says_where_it_comes_from_and_what_it_is():
    # A user's file may leave source and description out; the bundled library never does.
    for name in list_scenarios():
        scenario = load_scenario(name)
        assert scenario.source.strip(), name
        assert scenario.description.strip(), name


# --------------------------------------------------------------------------------------------------
# Nazarahari et al. 2019: Table 1's twelve maps and the four-robot field

EGA_TABLE2 = {  # map: (size, A* grid 1 length of the paper's Table 2)
    "ega01_random1": (30, 35.79), "ega02_maze1": (50, 251.52), "ega03_home": (50, 132.22),
    "ega04_corridor1": (30, 33.96), "ega05_boxpile": (30, 48.20), "ega06_corridor2": (30, 68.24),
    "ega07_slits1": (20, 68.35), "ega08_slits2": (20, 41.45), "ega09_maze2": (50, 197.20),
    "ega10_maze3": (50, 157.09), "ega11_random2": (30, 43.86), "ega12_plankpile": (30, 51.76),
}


def test_the_library_holds_the_twelve_maps_and_the_four_robot_field(scenarios):
    assert set(EGA_TABLE2) | {"ega_cross4"} == {n for n in scenarios if n.startswith("ega")}


@pytest.mark.parametrize("name", sorted(EGA_TABLE2))
def test_ega_maps_size_source_and_calibration(scenarios, name):
    from htetro_opt.solvers.continuous import plan_continuous

    sc = scenarios[name]
    size, astar = EGA_TABLE2[name]
    assert isinstance(sc, ContinuousScenario) and (sc.width, sc.height) == (size, size)
    assert sc.robot_radius == 0 and sc.n_robots == 1
    number = int(name[3:5])
    assert PAPER.match(sc.source) and f"Table 1 map {number} " in sc.source and "Fig. 6" in sc.source
    plan = plan_continuous(sc, method="astar", grid=1.0)
    assert plan.reached and abs(plan.length / astar - 1) <= 0.10, plan.length


def _as_polygons(sc):
    import shapely

    return [shapely.Polygon(o) for o in sc.obstacles]


@pytest.mark.parametrize("name", sorted(EGA_TABLE2))
def test_ega_maps_have_passages_of_at_least_one_and_no_corner_contacts(scenarios, name):
    import shapely

    sc = scenarios[name]
    polygons = _as_polygons(sc)
    edge = shapely.box(0, 0, sc.width, sc.height).exterior
    for i, a in enumerate(polygons):
        assert shapely.box(0, 0, sc.width, sc.height).covers(a)
        assert a.distance(edge) == 0 or a.distance(edge) >= 1, (i, a.distance(edge))
        for j in range(i + 1, len(polygons)):
            gap = a.distance(polygons[j])
            assert gap == 0 or gap >= 1 - 1e-9, (i, j, gap)
            if gap == 0:  # pieces that meet share an edge or an area, never a lone corner
                assert a.intersection(polygons[j]).length > 0 or a.intersection(polygons[j]).area > 0, (i, j)
    axis_aligned = all(len(o) == 4 and set(o[:, 0]) | set(o[:, 1]) <= set(range(51))
                       and len(set(o[:, 0])) == 2 and len(set(o[:, 1])) == 2 for o in sc.obstacles)
    assert axis_aligned == (name != "ega12_plankpile")  # the planks are rotated


def test_ega_cross4_robots_planned_alone_meet_at_the_centre(scenarios):
    from htetro_opt.solvers.continuous import plan_continuous

    sc = scenarios["ega_cross4"]
    assert sc.robot_radius == 0.5 and sc.n_robots == 4
    assert sc.starts.tolist() == [[3, 3], [27, 3], [27, 27], [3, 27]]
    assert sc.goals.tolist() == [[27, 27], [3, 27], [3, 3], [27, 3]]
    plan = plan_continuous(sc)
    assert all(len(p) == 2 for p in plan.paths)  # each own optimum is the straight diagonal
    np.testing.assert_allclose(plan.lengths, 24 * np.sqrt(2))
    assert plan.min_robot_distance < 2 * sc.robot_radius  # they collide
    assert len(plan.conflicts) == 6
