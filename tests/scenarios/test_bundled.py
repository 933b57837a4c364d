"""The bundled scenario library reconstructs the papers' environments with their stated features."""

import re

import numpy as np
import pytest

from htetro_opt.model import Simulator
from htetro_opt.scenarios import Scenario, list_scenarios, load_scenario
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
