"""Continuous planning (Nazarahari et al. 2019): the exact reference and lattice A* against
independent oracles (networkx over every obstacle vertex, scipy's Dijkstra over a lattice built here),
the lower-bound invariant on every bundled map, re-validation and typed errors."""

import itertools

import networkx as nx
import numpy as np
import pytest
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import dijkstra

from htetro_opt.errors import ParameterError, PlanningError, ScenarioError
from htetro_opt.model import ContinuousGeometry, path_length
from htetro_opt.scenarios import list_scenarios, load_scenario, parse_scenario
from htetro_opt.solvers import plan_continuous

EGA_MAPS = [n for n in list_scenarios() if n.startswith("ega")]


def scenario(obstacles, start, goal, *, width=10.0, height=10.0, r=0.0, more=()):
    robots = [{"start": list(start), "goal": list(goal)}] + [{"start": list(s), "goal": list(g)} for s, g in more]
    return parse_scenario({"name": "t", "width": width, "height": height, "robot_radius": r,
                           "obstacles": obstacles, "robots": robots})


def random_boxes(rng, n, size=10.0):
    boxes = []
    for _ in range(n):
        x, y = rng.uniform(0.5, size - 2.5, 2)
        w, h = rng.uniform(0.3, 2.0, 2)
        boxes.append([x, y, x + w, y + h])
    return boxes


def revalidated(plan, sc):
    for i, path in enumerate(plan.paths):
        if plan.robots_reached[i]:
            assert path[0].tolist() == sc.starts[i].tolist() and path[-1].tolist() == sc.goals[i].tolist()
            assert sc.geometry.path_feasible(path)
            assert plan.lengths[i] == pytest.approx(path_length(path))
    assert all(plan.feasible)
    return plan


def test_exact_equals_the_shortest_path_over_every_obstacle_vertex():
    # the oracle: all vertices (no corner selection, no tangent pruning), networkx's Dijkstra
    rng = np.random.default_rng(0)
    checked = 0
    for trial in range(12):
        boxes = random_boxes(rng, 7)
        geo = ContinuousGeometry(10, 10, boxes)
        free = rng.uniform(0, 10, (200, 2))
        free = free[geo.points_feasible(free)]
        start, goal = free[0], free[1]
        sc = scenario(boxes, start, goal)
        plan = revalidated(plan_continuous(sc), sc)
        points = [tuple(start), tuple(goal)] + [tuple(v) for o in geo.obstacles for v in o]
        graph = nx.Graph()
        graph.add_nodes_from(range(len(points)))
        pairs = list(itertools.combinations(range(len(points)), 2))
        a = np.array([points[i] for i, _ in pairs])
        b = np.array([points[j] for _, j in pairs])
        for (i, j), ok in zip(pairs, geo.segments_feasible(a, b)):
            if ok:
                graph.add_edge(i, j, weight=float(np.hypot(*np.subtract(points[i], points[j]))))
        try:
            want = nx.dijkstra_path_length(graph, 0, 1)
        except nx.NetworkXNoPath:
            assert not plan.reached
            continue
        assert plan.reached and plan.lengths[0] == pytest.approx(want, abs=1e-9)
        checked += 1
    assert checked >= 8


def test_exact_bounds_for_a_disc_robot():
    rng = np.random.default_rng(1)
    reached = 0
    for _ in range(8):
        boxes = [b for b in random_boxes(rng, 6) if b[0] > 1.2 and b[1] > 1.2 and b[2] < 8.8 and b[3] < 8.8]
        sc = scenario(boxes, [0.6, 0.6], [9.4, 9.4], r=0.4)
        plan = revalidated(plan_continuous(sc), sc)
        lower, upper = plan.info["lower_bound"][0], plan.info["upper_bound"][0]
        assert plan.reached == np.isfinite(upper)
        assert lower <= upper <= lower * 1.01
        assert plan.lengths[0] == pytest.approx(upper)
        astar = revalidated(plan_continuous(sc, method="astar", grid=0.5), sc)
        assert astar.reached and astar.lengths[0] >= lower - 1e-9
        reached += plan.reached
    assert reached == 8


@pytest.mark.parametrize("name", EGA_MAPS)
def test_no_method_returns_a_feasible_path_shorter_than_the_exact_lower_bound(name):
    sc = load_scenario(name)
    exact = revalidated(plan_continuous(sc), sc)
    assert exact.reached
    lower = np.array(exact.info["lower_bound"])
    assert np.all(lower <= exact.lengths + 1e-9)
    for grid in (1.0, 0.25):
        astar = revalidated(plan_continuous(sc, method="astar", grid=grid), sc)
        assert astar.reached
        assert np.all(astar.lengths >= lower - 1e-9), (grid, astar.lengths, lower)


def lattice_distance(geo, start, goal, grid):
    """Shortest 8-connected lattice distance by scipy's Dijkstra, the lattice built here."""
    x0, y0, x1, y1 = geo.bounds
    xs = np.arange(np.ceil(x0 / grid), np.floor(x1 / grid) + 1) * grid
    ys = np.arange(np.ceil(y0 / grid), np.floor(y1 / grid) + 1) * grid
    points = np.array([(x, y) for y in ys for x in xs])
    key = {tuple(p): k for k, p in enumerate(points.tolist())}
    edges = []
    for k, (x, y) in enumerate(points.tolist()):
        for dx, dy in ((1, 0), (0, 1), (1, 1), (-1, 1)):
            other = key.get((x + dx * grid, y + dy * grid))
            if other is not None:
                edges.append((k, other))
    edges = np.array(edges)
    ok = geo.points_feasible(points)
    edges = edges[ok[edges[:, 0]] & ok[edges[:, 1]]]
    edges = edges[geo.segments_feasible(points[edges[:, 0]], points[edges[:, 1]])]
    w = np.hypot(*(points[edges[:, 0]] - points[edges[:, 1]]).T)
    graph = coo_matrix((w, (edges[:, 0], edges[:, 1])), shape=(len(points), len(points))).tocsr()
    return dijkstra(graph, directed=False, indices=key[tuple(start)])[key[tuple(goal)]]


@pytest.mark.parametrize("name, grid", [("ega07_slits1", 1.0), ("ega12_plankpile", 1.0), ("ega05_boxpile", 0.5),
                                        ("ega_cross4", 1.0)])
def test_astar_equals_dijkstra_on_its_lattice(name, grid):
    sc = load_scenario(name)
    plan = revalidated(plan_continuous(sc, method="astar", grid=grid), sc)
    for i in range(sc.n_robots):
        assert plan.lengths[i] == pytest.approx(lattice_distance(sc.geometry, sc.starts[i], sc.goals[i], grid))


def test_astar_on_an_empty_map_is_the_octile_distance():
    rng = np.random.default_rng(4)
    for grid in (1.0, 0.25):
        for _ in range(5):
            start, goal = rng.integers(0, 41, (2, 2)) * 0.25 if grid == 0.25 else rng.integers(0, 11, (2, 2))
            sc = scenario([], start, goal)
            plan = revalidated(plan_continuous(sc, method="astar", grid=grid), sc)
            dx, dy = np.abs(np.subtract(goal, start))
            assert plan.lengths[0] == pytest.approx(max(dx, dy) + (np.sqrt(2) - 1) * min(dx, dy))


def test_off_lattice_ends_link_to_the_nodes_they_see():
    sc = scenario([[4, 0, 6, 8]], [1.3, 0.7], [8.6, 2.2])
    plan = revalidated(plan_continuous(sc, method="astar"), sc)
    assert plan.reached and plan.lengths[0] >= plan_continuous(sc).lengths[0]
    assert np.hypot(*(plan.paths[0][1] - plan.paths[0][0])) <= 1.5


def test_an_enclosed_goal_is_not_reached_and_start_equal_goal_has_zero_length():
    walled = scenario([[6, 6, 9, 7], [6, 9, 9, 10], [6, 6, 7, 10], [8, 6, 9, 10]], [1, 1], [7.5, 8])
    for method in ("exact", "astar"):
        plan = revalidated(plan_continuous(walled, method=method), walled)
        assert not plan.reached and plan.paths[0].shape == (0, 2) and plan.objectives()["min_clearance"] is None
    same = scenario([[4, 4, 6, 6]], [2, 2], [2, 2])
    for method in ("exact", "astar"):
        plan = revalidated(plan_continuous(same, method=method), same)
        assert plan.reached and plan.lengths[0] == 0 and plan.paths[0].tolist() == [[2, 2]]


def test_robots_planned_alone_report_their_conflicts():
    sc = scenario([], [1, 5], [9, 5], r=0.3, more=[([9, 5.2], [1, 5.2])])
    plan = revalidated(plan_continuous(sc), sc)
    assert plan.min_robot_distance == pytest.approx(0.2) and plan.conflicts == ((0, 1),)
    assert plan.safety_distance == pytest.approx(1.1)
    data = plan.as_dict()
    assert set(data) == {"scenario", "method", "success", "message", "reached", "paths", "objectives",
                         "min_robot_distance", "conflicts", "runtime_s", "time_limited", "additions", "info"}
    assert set(data["objectives"]) == {"length", "smoothness_deg", "safety", "min_clearance"}


def test_a_callable_method_is_replayed_and_checked():
    sc = scenario([[4, 0, 6, 8]], [1, 1], [9, 1])

    def over_the_wall(geometry, start, goal):
        return np.array([start, [4, 8], [6, 8], goal])

    plan = revalidated(plan_continuous(sc, method=over_the_wall), sc)
    assert plan.method == "over_the_wall" and plan.lengths[0] == pytest.approx(plan_continuous(sc).lengths[0])
    assert not plan_continuous(sc, method=lambda geometry, start, goal: None).reached
    with pytest.raises(PlanningError, match="collides"):
        plan_continuous(sc, method=lambda geometry, start, goal: np.array([start, goal]))
    with pytest.raises(PlanningError, match="start"):
        plan_continuous(sc, method=lambda geometry, start, goal: np.array([goal, start]))
    with pytest.raises(PlanningError, match="shape"):
        plan_continuous(sc, method=lambda geometry, start, goal: [1, 2, 3])


@pytest.mark.parametrize("call, error, words", [
    (lambda sc: plan_continuous(load_scenario("three_slit")), ScenarioError, "grid scenario"),
    (lambda sc: plan_continuous("ega01_random1"), ScenarioError, "ContinuousScenario"),
    (lambda sc: plan_continuous(sc, method="dijkstra"), ParameterError, "unknown continuous planning method"),
    (lambda sc: plan_continuous(sc, method="exact", grid=1.0), ParameterError, "takes no option 'grid'"),
    (lambda sc: plan_continuous(sc, method="astar", path="spline"), ParameterError, "takes no option 'path'"),
    (lambda sc: plan_continuous(sc, method="astar", grid=0), ParameterError, "grid must be"),
    (lambda sc: plan_continuous(sc, method="astar", grid=6), ParameterError, "grid must be"),
    (lambda sc: plan_continuous(sc, method="astar", grid="1"), ParameterError, "grid must be"),
])
def test_bad_inputs_raise_typed_errors(call, error, words):
    sc = scenario([[4, 0, 6, 8]], [1, 1], [9, 1])
    with pytest.raises(error) as info:
        call(sc)
    assert words in str(info.value)
