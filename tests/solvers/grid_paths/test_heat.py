"""plan_heat: Do et al. 2021's search up the temperature field, checked against the simulator, an
independently solved field, the exact planner and the paper's cost measure."""

from __future__ import annotations

import numpy as np
import pytest

from htetro_opt.errors import ParameterError, PlanningError
from htetro_opt.model import Pose, Simulator, Workspace
from htetro_opt.model.commands import COMMANDS, command_set
from htetro_opt.problems.heat_costs import heat_fitness
from htetro_opt.scenarios import load_scenario
from htetro_opt.solvers.grid_paths import HEAT_ADDITIONS, plan_exact, plan_heat, plan_path, solve_heat_field

MAPS = ("random", "h_shape", "three_slit", "maze")


def _replay(workspace, plan, start):
    sim = Simulator(workspace, diagonals=True)
    result = sim.run([plan.commands], start)
    assert result.valid[0] and int(result.executed[0]) == len(plan.commands)
    return result.final_pose(0)


@pytest.mark.parametrize("name", MAPS)
@pytest.mark.parametrize("weights", [(1.0, 0.0, 0.0), (0.0, 0.0, 1.0), (1.0, 0.0, 1.0)])
def test_plans_revalidate_reach_the_goal_and_climb_the_field(name, weights):
    scenario = load_scenario(name)
    plan = plan_heat(scenario.workspace, scenario.roadmap, weights=weights)
    assert plan.method == "heat" and plan.reached and plan.failed_leg == -1
    assert _replay(scenario.workspace, plan, scenario.start) == scenario.goal
    assert plan.info["relaxed"] == [False]
    # the temperature of B2's cell, from a field solved here, never drops on a translation
    start, goal = scenario.start, scenario.goal
    field = solve_heat_field(scenario.workspace, (goal.x, goal.y), (start.x, start.y), element="q1")
    temperature = field.cells[plan.poses[:, 1], plan.poses[:, 0]]
    assert temperature[0] == 0.0 and temperature[-1] == 1.0
    moves = np.array([COMMANDS[int(c)].kind in ("translation", "diagonal") for c in plan.commands])
    drops = temperature[:-1] - temperature[1:]
    assert moves.any() and (drops[moves] <= field.epsilon).all()
    fitness = heat_fitness(scenario.workspace, plan.poses, plan.commands, weights=weights)
    assert plan.info["fitness"] == pytest.approx(fitness)
    assert plan.info["weights"] == list(weights) and plan.info["t_max"] > 0
    assert plan.info["field"][0]["element"] == "q1" and plan.info["field"][0]["dofs"] > 0


@pytest.mark.parametrize("name", MAPS)
def test_unconstrained_time_plan_is_the_exact_optimum_and_the_monotone_one_no_faster(name):
    scenario = load_scenario(name)
    exact = plan_exact(scenario.workspace, scenario.roadmap, diagonals=True)
    free = plan_heat(scenario.workspace, scenario.roadmap, monotone=False)
    monotone = plan_heat(scenario.workspace, scenario.roadmap)
    assert free.time == pytest.approx(exact.time, abs=1e-9)
    assert monotone.time >= exact.time - 1e-9
    assert free.info["relaxed"] == [False]


@pytest.mark.parametrize("name", MAPS)
@pytest.mark.parametrize("monotone", [True, False])
def test_safety_weight_buys_safety_and_time_weight_buys_time(name, monotone):
    scenario = load_scenario(name)
    fast = plan_heat(scenario.workspace, scenario.roadmap, weights=(1, 0, 0), monotone=monotone)
    safe = plan_heat(scenario.workspace, scenario.roadmap, weights=(0, 0, 1), monotone=monotone)
    assert safe.info["fitness"]["f_sf"] >= fast.info["fitness"]["f_sf"] - 1e-12
    assert fast.time <= safe.time + 1e-9


def test_a_safety_plan_differs_from_the_time_plan_somewhere():
    scenario = load_scenario("h_shape")  # a case where the weights matter: else the test above is vacuous
    fast = plan_heat(scenario.workspace, scenario.roadmap, weights=(1, 0, 0))
    safe = plan_heat(scenario.workspace, scenario.roadmap, weights=(0, 0, 1))
    assert safe.info["fitness"]["f_sf"] > fast.info["fitness"]["f_sf"] + 0.1
    assert safe.time > fast.time


def test_no_monotone_path_relaxes_the_leg_to_the_unconstrained_optimum():
    # a 10 x 10 map found by a random search: the O-shape must cool down to reach the goal
    occ = np.zeros(100, dtype=bool)
    occ[[12, 16, 18, 21, 26, 36, 38, 46, 47, 51, 60, 64, 72, 78, 80, 82, 88, 89, 91, 92]] = True
    ws = Workspace(occ.reshape(10, 10))
    roadmap = [Pose(4, 5, "O", 0), Pose(6, 7, "O", 0)]
    plan = plan_heat(ws, roadmap)
    assert plan.reached and plan.info["relaxed"] == [True]
    assert _replay(ws, plan, roadmap[0]) == roadmap[-1]
    free = plan_heat(ws, roadmap, monotone=False)
    assert plan.time == pytest.approx(free.time) and free.info["relaxed"] == [False]
    field = solve_heat_field(ws, (6, 7), (4, 5))
    temperature = field.cells[plan.poses[:, 1], plan.poses[:, 0]]
    moves = np.array([COMMANDS[int(c)].kind in ("translation", "diagonal") for c in plan.commands])
    assert ((temperature[:-1] - temperature[1:])[moves] > field.epsilon).any()  # it really had to cool down


def test_multi_leg_roadmaps_plan_leg_by_leg():
    ws = Workspace(np.zeros((10, 10), dtype=bool))
    roadmap = [Pose(1, 1, "O", 0), Pose(7, 2, "O", 0), Pose(2, 7, "I", 1)]
    plan = plan_heat(ws, roadmap, weights=(1, 0, 1))
    assert plan.reached and len(plan.leg_ends) == 2 and len(plan.info["field"]) == 2
    assert _replay(ws, plan, roadmap[0]) == roadmap[-1]
    assert tuple(plan.poses[plan.leg_ends[0], :2]) == (7, 2)


def test_unreachable_goal_and_start_equal_to_goal():
    occ = np.zeros((6, 12), dtype=bool)
    occ[:, 5:7] = True  # a full wall
    ws = Workspace(occ)
    plan = plan_heat(ws, [Pose(1, 1, "O", 0), Pose(9, 1, "O", 0)])
    assert not plan.reached and plan.failed_leg == 0 and len(plan.commands) == 0
    same = plan_heat(ws, [Pose(1, 1, "O", 0), Pose(1, 1, "O", 0)])
    assert same.reached and len(same.commands) == 0 and same.time == 0.0
    assert same.info["fitness"] == {"f_t": 1.0, "f_sm": 1.0, "f_sf": 1.0, "f": 1.0}


def test_plan_path_routes_heat():
    scenario = load_scenario("three_slit")
    plan = plan_path(scenario.workspace, scenario.roadmap, method="heat", weights=(1, 0, 1), element="p0")
    assert plan.method == "heat" and plan.reached and plan.info["field"][0]["element"] == "p0"
    with pytest.raises(ParameterError, match="no option 'pop_size'"):
        plan_path(scenario.workspace, scenario.roadmap, method="heat", pop_size=10)


def test_default_commands_are_do_et_al_s_seventeen():
    scenario = load_scenario("random")
    plan = plan_heat(scenario.workspace, scenario.roadmap)
    assert set(plan.commands.tolist()) <= set(command_set(diagonals=True))
    assert any(COMMANDS[int(c)].kind == "diagonal" for c in plan.commands)


@pytest.mark.parametrize("kwargs, match", [
    ({"weights": (1, 0)}, "three numbers"),
    ({"weights": (0, 0, 0)}, "not all be zero"),
    ({"weights": (1, -1, 0)}, "w_sm"),
    ({"weights": (1, float("nan"), 0)}, "w_sm"),
    ({"band": 0}, "band"),
    ({"band": "narrow"}, "unknown band"),
    ({"band_seed": "line"}, "unknown band_seed"),
    ({"engine": "bfs"}, "unknown engine"),
    ({"keep_fields": 1}, "keep_fields"),
    ({"t_max": 0}, "t_max"),
    ({"t_max": float("inf")}, "t_max"),
    ({"element": "p2"}, "unknown element"),
    ({"monotone": "yes"}, "monotone"),
    ({"field_options": {"nope": 1}}, "nope"),
    ({"commands": ["x+", "x-", "y+", "y-", "1l"]}, "block commands"),
])
def test_bad_inputs_raise_typed_errors(kwargs, match):
    ws = Workspace(np.zeros((6, 6), dtype=bool))
    with pytest.raises(ParameterError, match=match):
        plan_heat(ws, [Pose(1, 1, "O", 0), Pose(3, 3, "O", 0)], **kwargs)


def test_moving_obstacles_and_short_roadmaps_are_refused():
    dynamic = load_scenario("perpendicular_dynamic")
    with pytest.raises(ParameterError, match="static maps only: use dijkstra"):
        plan_heat(dynamic.workspace, dynamic.roadmap)
    with pytest.raises(PlanningError):
        plan_heat(Workspace(np.zeros((6, 6), dtype=bool)), [Pose(1, 1, "O", 0)])


TABLE6 = [(1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0), (1.0, 1.0, 1.0)]


def _surrogate(workspace, plan, weights, length):
    """J of a one-leg plan from heat_fitness's exact eqs. 9-12 (an independent path to the same
    number): Σ [w_t t/t_max + w_sm d/L + w_sf s/L] / Σw + 1e-9 Σt/t_max, the first command counted as a change."""
    f = heat_fitness(workspace, plan.poses, plan.commands, t_max=plan.info["t_max"])
    n = len(plan.commands)
    time_part = 1.0 - f["f_t"]
    changes = (1.0 - f["f_sm"]) * n + (1 if n else 0)
    hazard = (1.0 - f["f_sf"]) * n
    w_t, w_sm, w_sf = weights
    return (w_t * time_part + (w_sm * changes + w_sf * hazard) / length) / sum(weights) + 1e-9 * time_part


def _clutter(seed, size=16):
    """A size x size map with 1-2-cell blocks, and O-shaped start and goal far apart on free cells."""
    rng = np.random.default_rng(seed)
    occ = np.zeros((size, size), dtype=bool)
    while occ.mean() < 0.15:
        w, h = rng.integers(1, 3, size=2)
        x, y = rng.integers(0, size - w + 1), rng.integers(0, size - h + 1)
        occ[y:y + h, x:x + w] = True
    occ[:4, :4] = occ[size - 5:, size - 5:] = False  # room for the O-shapes (B2 at a corner of the square)
    return Workspace(occ), [Pose(1, 1, "O", 0), Pose(size - 3, size - 3, "O", 0)]


SURROGATE_ONLY = [a for a in HEAT_ADDITIONS if a != "exact-pick"]  # each row's own surrogate optimum, unpicked


@pytest.mark.parametrize("name", ["random", "h_shape", "three_slit"])
def test_each_weighting_minimises_its_own_surrogate_among_the_table6_plans(name):
    scenario = load_scenario(name)
    plans = {w: plan_heat(scenario.workspace, scenario.roadmap, weights=w, additions=SURROGATE_ONLY) for w in TABLE6}
    length = len(plans[(1.0, 0.0, 0.0)].commands)  # L: the time-only constrained plan's length
    assert all(p.info["length"] == [length] for p in plans.values())
    assert all(p.reached and p.info["relaxed"] == [False] for p in plans.values())
    for w, plan in plans.items():
        own = _surrogate(scenario.workspace, plan, w, length)
        assert own == pytest.approx(plan.info["surrogate"][0], rel=1e-9, abs=1e-12)
        for other in plans.values():
            assert own <= _surrogate(scenario.workspace, other, w, length) + 1e-12
    if name == "h_shape":  # where the weights matter, so that the comparisons above are not all ties
        f = {w: p.info["fitness"] for w, p in plans.items()}
        assert f[(0.0, 1.0, 0.0)]["f_sm"] > f[(1.0, 0.0, 0.0)]["f_sm"] + 0.05
        assert f[(0.0, 0.0, 1.0)]["f_sf"] > f[(1.0, 0.0, 0.0)]["f_sf"] + 0.1


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("weights", TABLE6)
def test_the_paper_s_waves_and_dijkstra_reach_the_same_optimum(seed, weights):
    ws, roadmap = _clutter(seed)
    waves = plan_heat(ws, roadmap, weights=weights, engine="wavefront")
    heap = plan_heat(ws, roadmap, weights=weights)
    assert waves.reached == heap.reached
    if heap.reached:
        assert waves.info["surrogate"] == pytest.approx(heap.info["surrogate"], rel=1e-12)
        assert waves.info["relaxed"] == heap.info["relaxed"]
        assert _replay(ws, waves, roadmap[0]) == roadmap[-1]


@pytest.mark.parametrize("weights", TABLE6)
def test_scaling_the_weights_keeps_the_plan(weights):
    scenario = load_scenario("h_shape")
    plan = plan_heat(scenario.workspace, scenario.roadmap, weights=weights)
    scaled = plan_heat(scenario.workspace, scenario.roadmap, weights=tuple(3.5 * w for w in weights))
    assert scaled.commands.tolist() == plan.commands.tolist()
    again = plan_heat(scenario.workspace, scenario.roadmap, weights=weights)
    assert again.commands.tolist() == plan.commands.tolist()  # deterministic


@pytest.mark.parametrize("name", MAPS)
@pytest.mark.parametrize("element", ["q1", "p0"])
def test_a_band_search_revalidates_and_is_never_better_than_the_whole_graph(name, element):
    scenario = load_scenario(name)
    whole = plan_heat(scenario.workspace, scenario.roadmap, element=element, band="full")
    assert whole.info["band"][0]["radius"] is None
    for radius in (1, 3):
        banded = plan_heat(scenario.workspace, scenario.roadmap, element=element, band=radius)
        record = banded.info["band"][0]
        assert banded.reached and record["seed"] == "ascent" and record["radius"] >= radius
        assert _replay(scenario.workspace, banded, scenario.start) == scenario.goal
        assert Simulator(scenario.workspace, diagonals=True).run([banded.commands], scenario.start).poses(0).tolist() \
            == banded.poses.tolist()
        assert banded.info["surrogate"][0] >= whole.info["surrogate"][0] - 1e-12
        assert banded.info["relaxed"] == whole.info["relaxed"]


def test_a_band_wide_enough_is_the_whole_search():
    scenario = load_scenario("maze")
    whole = plan_heat(scenario.workspace, scenario.roadmap, weights=(1, 1, 1))
    banded = plan_heat(scenario.workspace, scenario.roadmap, weights=(1, 1, 1), band=48)
    assert banded.info["band"][0]["cells"] == int((~scenario.workspace.occupancy).sum())
    assert banded.commands.tolist() == whole.commands.tolist()
    assert banded.info["fitness"] == pytest.approx(whole.info["fitness"])


@pytest.mark.parametrize("seed", range(12))
def test_widening_reaches_whenever_the_whole_search_does(seed):
    ws, roadmap = _clutter(seed, size=20)
    whole = plan_heat(ws, roadmap)
    banded = plan_heat(ws, roadmap, band=1)
    ablation = plan_heat(ws, roadmap, band=1, band_seed="grid_distance")
    assert banded.reached == whole.reached == ablation.reached
    if whole.reached:
        assert banded.info["relaxed"] == whole.info["relaxed"]
        assert banded.time >= whole.time - 1e-9 or banded.info["relaxed"] != [False]
        assert _replay(ws, banded, roadmap[0]) == roadmap[-1]
        assert ablation.info["band"][0]["seed"] in ("grid_distance", None)


def test_a_band_with_no_path_in_the_map_reports_the_failed_leg():
    occ = np.zeros((6, 12), dtype=bool)
    occ[:, 5:7] = True
    plan = plan_heat(Workspace(occ), [Pose(1, 1, "O", 0), Pose(9, 1, "O", 0)], band=2)
    assert not plan.reached and plan.failed_leg == 0 and len(plan.commands) == 0
    # no monotone path: the band widens to the whole map before the leg is relaxed
    occ = np.zeros(100, dtype=bool)
    occ[[12, 16, 18, 21, 26, 36, 38, 46, 47, 51, 60, 64, 72, 78, 80, 82, 88, 89, 91, 92]] = True
    ws = Workspace(occ.reshape(10, 10))
    roadmap = [Pose(4, 5, "O", 0), Pose(6, 7, "O", 0)]
    banded, whole = plan_heat(ws, roadmap, band=1), plan_heat(ws, roadmap)
    assert banded.info["relaxed"] == whole.info["relaxed"] == [True]
    assert banded.info["band"][0]["cells"] == int((~ws.occupancy).sum())
    assert banded.time == pytest.approx(whole.time)


def test_kept_fields_are_the_legs_fields():
    scenario = load_scenario("three_slit")
    plan = plan_heat(scenario.workspace, scenario.roadmap, keep_fields=True)
    (field,) = plan.info["fields"]
    start, goal = scenario.start, scenario.goal
    reference = solve_heat_field(scenario.workspace, (goal.x, goal.y), (start.x, start.y))
    np.testing.assert_allclose(field.cells, reference.cells, atol=1e-10)


@pytest.mark.parametrize("band", ["full", 3])
def test_the_search_graph_is_the_exact_planner_s_graph_of_the_same_table(band):
    """_LegSearch builds its one-layer CSR itself: it is the exact planner's ``_Graph.matrix()`` of the
    same (masked, weighted) table, edge for edge, on the whole simulator and on a band."""
    from htetro_opt.solvers.grid_paths import _heat
    from htetro_opt.solvers.grid_paths._exact import _Graph

    built = []
    original = _heat._LegSearch._matrix

    def spy(self):
        matrix = original(self)
        if self.layers == 1:
            g = self.graph
            built.append((matrix, _Graph(g.sim, mask=g.usable, weights=g.weights).matrix()))
        return matrix

    scenario = load_scenario("h_shape")
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(_heat._LegSearch, "_matrix", spy)
        plan = plan_heat(scenario.workspace, scenario.roadmap, band=band)
    assert plan.reached and built
    for ours, reference in built:
        assert ours.shape == reference.shape and ours.nnz == reference.nnz > 0
        assert (ours != reference).nnz == 0
        np.testing.assert_array_equal(ours.indptr, reference.indptr)
        np.testing.assert_array_equal(ours.indices, reference.indices)
