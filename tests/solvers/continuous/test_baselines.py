"""Nazarahari et al. 2019's remaining baselines: PRM (a roadmap of exactly n samples), B-RRT (OMPL's
RRTConnect) and PSO (pymoo's, from the APF paths): never below the exact lower bound, re-validated,
the same seed giving the same paths, and their own invariants against independent oracles."""

import sys
import time

import networkx as nx
import numpy as np
import pytest

from htetro_opt.errors import ParameterError
from htetro_opt.model import ContinuousGeometry, path_length
from htetro_opt.scenarios import list_scenarios, load_scenario, parse_scenario
from htetro_opt.solvers import plan_continuous
from htetro_opt.solvers.continuous import (PAPER_PRM, keep_feasible_moves, pad_path_bases, prm_path, pso_path,
                                          rrt_path)

EGA_MAPS = [n for n in list_scenarios() if n.startswith("ega")]
WALL = ContinuousGeometry(10, 10, [[4, 0, 6, 8]])


def on_polyline(points, line):
    """Whether every point lies on the polyline (distance to its nearest segment below 1e-9)."""
    a, b = line[:-1], line[1:]
    for p in points:
        t = np.clip(((p - a) * (b - a)).sum(axis=1) / np.maximum(((b - a) ** 2).sum(axis=1), 1e-300), 0, 1)
        if np.hypot(*(a + t[:, None] * (b - a) - p).T).min() > 1e-9:
            return False
    return True


# Two of the three mazes (2.4-3.1 s each, most of this test's time) run with `pytest -m slow`, which keeps
# the default suite within its 5 minutes; ega10_maze3 keeps a maze in the default run.
@pytest.mark.parametrize("name", [pytest.param(name, marks=pytest.mark.slow)
                                  if name in ("ega02_maze1", "ega09_maze2") else name for name in EGA_MAPS])
def test_no_baseline_is_below_the_exact_lower_bound_and_all_revalidate(name):
    sc = load_scenario(name)
    lower = np.array(plan_continuous(sc).info["lower_bound"])
    for method in ("prm", "pso", "rrt"):
        plan = plan_continuous(sc, method=method, seed=0)
        assert plan.method == method and all(plan.feasible)
        for i, path in enumerate(plan.paths):
            if plan.robots_reached[i]:
                assert path[0].tolist() == sc.starts[i].tolist() and path[-1].tolist() == sc.goals[i].tolist()
                assert sc.geometry.path_feasible(path)
                assert plan.lengths[i] >= lower[i] - 1e-9, (method, plan.lengths[i], lower[i])
        assert plan.reached or method == "prm", method  # PRM may miss (the paper: 18-100 %)


@pytest.mark.parametrize("method", ["prm", "pso", "rrt"])
def test_the_same_seed_gives_the_same_paths(method):
    sc = load_scenario("ega08_slits2")
    a, b, c = (plan_continuous(sc, method=method, seed=s) for s in (5, 5, 6))
    assert all(np.array_equal(p, q) for p, q in zip(a.paths, b.paths))
    assert not all(np.array_equal(p, q) for p, q in zip(a.paths, c.paths))


def test_prm_takes_exactly_n_samples_and_its_roadmap_path_is_dijkstras():
    rng = np.random.default_rng(3)
    start, goal = np.array([1.0, 1.0]), np.array([9.0, 1.0])
    path, info = prm_path(WALL, start, goal, n=150, radius=2.5, seed=rng, delete=False)
    assert info["samples"] == 150
    assert WALL.path_feasible(path) and path_length(path) == pytest.approx(info["roadmap_length"])
    again, _ = prm_path(WALL, start, goal, n=150, radius=2.5, seed=np.random.default_rng(3), delete=False)
    assert np.array_equal(path, again)
    kept, _ = prm_path(WALL, start, goal, n=150, radius=2.5, seed=np.random.default_rng(3))
    assert WALL.path_feasible(kept) and path_length(kept) <= info["roadmap_length"] + 1e-9
    assert on_polyline(kept[1:-1], path)  # deletion only drops vertices


def test_prm_on_a_graph_built_by_networkx():
    # an empty map, radius 3: the roadmap path equals networkx's shortest path over the same points
    geo = ContinuousGeometry(10, 10)
    start, goal = np.array([0.5, 0.5]), np.array([9.5, 9.5])
    path, info = prm_path(geo, start, goal, n=80, radius=3.0, seed=11, delete=False)
    rng = np.random.default_rng(11)
    # the samples as the PRM draws them (one batch of 2 n, all free on an empty map)
    points = rng.uniform((0, 0), (10, 10), size=(160, 2))[:80]
    graph = nx.Graph()
    nodes = [tuple(start), tuple(goal)] + [tuple(p) for p in points]
    for i, p in enumerate(nodes):
        for q in nodes[i + 1:]:
            d = float(np.hypot(p[0] - q[0], p[1] - q[1]))
            if d <= 3.0:
                graph.add_edge(p, q, weight=d)
    assert path_length(path) == pytest.approx(nx.shortest_path_length(graph, nodes[0], nodes[1], weight="weight"))
    straight, _ = prm_path(geo, start, goal, n=80, radius=3.0, seed=11)
    assert straight.tolist() == [start.tolist(), goal.tolist()]  # deletion empties a free S -> D


def test_prm_defaults_are_the_papers_per_map():
    assert len(PAPER_PRM) == 12 and set(PAPER_PRM) == {n for n in EGA_MAPS if n != "ega_cross4"}
    plan = plan_continuous(load_scenario("ega02_maze1"), method="prm", seed=0)
    assert (plan.info["samples"], plan.info["radius"]) == (900, 7.5)


def test_padding_keeps_the_path_and_pso_never_lengthens_the_best_apf_path():
    start, goal = np.array([1.0, 1.0]), np.array([9.0, 1.0])
    pbs = np.array([[3.0, 8.5], [7.0, 8.5]])
    padded = pad_path_bases(pbs, start, goal, 7)
    line = np.vstack([start, pbs, goal])
    assert len(padded) == 7 and on_polyline(padded, line)
    assert path_length(np.vstack([start, padded, goal])) == pytest.approx(path_length(line))
    path, info = pso_path(WALL, start, goal, seed=2)
    assert WALL.path_feasible(path) and len(path) == info["path_bases"] + 2
    history = np.array(info["history"])
    assert len(history) == 21 and np.all(np.diff(history) <= 1e-12)
    assert path_length(path) == pytest.approx(history[-1])


def test_feasible_moves_put_back_only_pbs_of_broken_segments_and_leave_every_path_feasible():
    # oracle: the geometry's own whole-path check, on random moves of feasible paths over the wall
    rng = np.random.default_rng(3)
    start, goal = np.array([1.0, 1.0]), np.array([9.0, 1.0])
    base = np.array([[2.0, 8.5], [4.0, 8.5], [5.0, 9.0], [6.0, 8.5], [8.0, 5.0]])
    old = (base[None] + rng.uniform(-0.4, 0.4, (300, 5, 2)) * [1, 0]).reshape(300, 10)
    old = old[[WALL.path_feasible(np.vstack([start, x.reshape(5, 2), goal])) for x in old]]
    new = old + rng.normal(0, 1.0, old.shape)
    X, kept = keep_feasible_moves(WALL, start, goal, old, new)
    X3, old3, new3 = X.reshape(-1, 5, 2), old.reshape(-1, 5, 2), new.reshape(-1, 5, 2)
    assert len(old) > 100 and np.array_equal(X3[kept], old3[kept]) and np.array_equal(X3[~kept], new3[~kept])
    feasible_new = np.array([WALL.path_feasible(np.vstack([start, x, goal])) for x in new3])
    assert not kept[feasible_new].any()  # a feasible move is left alone
    assert kept[~feasible_new].any(axis=1).all() and 0 < (~feasible_new).sum() < len(new)
    assert all(WALL.path_feasible(np.vstack([start, x, goal])) for x in X3)


@pytest.mark.parametrize("name", ["ega04_corridor1", "ega07_slits1"])
def test_pso_shortens_its_apf_start(name):
    # before feasible moves and the d/2 velocity cap no particle ever improved on its APF start here
    sc = load_scenario(name)
    exact = plan_continuous(sc).length
    for seed in range(3):
        path, info = pso_path(sc.geometry, sc.starts[0], sc.goals[0], seed=seed)
        history = info["history"]
        assert history[-1] <= 0.95 * history[0] and history[-1] >= exact - 1e-9
        assert sc.geometry.path_feasible(path) and path_length(path) == pytest.approx(history[-1])


def test_rrt_is_seeded_and_honours_its_time_limit():
    start, goal = np.array([1.0, 1.0]), np.array([9.0, 1.0])
    a, info = rrt_path(WALL, start, goal, seed=4, delete=False)
    b, _ = rrt_path(WALL, start, goal, seed=4, delete=False)
    assert np.array_equal(a, b) and info["states"] == len(a) and WALL.path_feasible(a)
    steps = np.hypot(*np.diff(a, axis=0).T)
    assert steps.max() <= 2.0 + 1e-9  # setRange(2.0)
    closed = parse_scenario({"name": "t", "width": 10, "height": 10, "obstacles": [[4, 0, 6, 10]],
                             "robots": [{"start": [1, 1], "goal": [9, 1]}]})
    began = time.process_time()  # the time limit is the feature: measured in CPU time, with a wide margin
    plan = plan_continuous(closed, method="rrt", time_limit=0.2, seed=0)
    assert not plan.reached and time.process_time() - began < 2


def test_rrt_without_ompl_names_the_pip_command(monkeypatch):
    monkeypatch.setitem(sys.modules, "ompl", None)
    with pytest.raises(ParameterError, match=r"pip install 'htetro-opt\[ompl\]'"):
        plan_continuous(load_scenario("ega01_random1"), method="rrt", seed=0)


@pytest.mark.parametrize("method, options, words", [
    ("prm", {"n": 0}, "n must be"),
    ("prm", {"radius": -1}, "radius must be"),
    ("prm", {"grid": 1.0}, "takes no option 'grid'"),
    ("rrt", {"time_limit": 0}, "time_limit must be"),
    ("rrt", {"path": "spline"}, "takes no option 'path'"),
    ("pso", {"pop_size": 1}, "pop_size must be"),
    ("pso", {"grid": 0}, "grid must be"),
    ("pso", {"seed": -1}, "seed must be"),
])
def test_bad_baseline_options_raise_typed_errors(method, options, words):
    with pytest.raises(ParameterError, match=words):
        plan_continuous(load_scenario("ega01_random1"), method=method, **options)
