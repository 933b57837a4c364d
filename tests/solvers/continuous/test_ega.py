"""Nazarahari et al. 2019's enhanced GA through plan_continuous: never below the exact lower bound,
one seed ⇒ one plan, the four robots of ega_cross4 kept apart, §5.3's normalisation, the NSGA-II
front, and typed errors."""

import json

import numpy as np
import pytest

from htetro_opt.errors import ParameterError
from htetro_opt.model import path_length, robot_distance
from htetro_opt.scenarios import list_scenarios, load_scenario, parse_scenario
from htetro_opt.solvers.continuous import plan_continuous, plan_moea

EGA_MAPS = [n for n in list_scenarios() if n.startswith("ega") and n != "ega_cross4"]


def scenario(obstacles, robots, *, r=0.0, size=10.0):
    return parse_scenario({"name": "t", "width": size, "height": size, "robot_radius": r, "obstacles": obstacles,
                           "robots": [{"start": list(s), "goal": list(g)} for s, g in robots]})


def revalidated(plan, sc):
    for i, path in enumerate(plan.paths):
        if plan.robots_reached[i]:
            assert path[0].tolist() == sc.starts[i].tolist() and path[-1].tolist() == sc.goals[i].tolist()
            assert sc.geometry.path_feasible(path)
            assert plan.lengths[i] == pytest.approx(path_length(path))
    return plan


# Five of the maps whose default runs take longest (2-5 s each) run with `pytest -m slow`, which keeps
# the default suite within its 5 minutes; the other seven cover each kind of map (random, home,
# corridor, box pile, slits, maze) in the default run.
_SLOW_EGA_MAPS = {"ega02_maze1", "ega06_corridor2", "ega07_slits1", "ega09_maze2", "ega12_plankpile"}


@pytest.mark.parametrize("name", [pytest.param(name, marks=pytest.mark.slow) if name in _SLOW_EGA_MAPS else name
                                  for name in EGA_MAPS])
def test_no_ga_returns_a_feasible_path_shorter_than_the_exact_lower_bound(name):
    sc = load_scenario(name)
    lower = np.array(plan_continuous(sc).info["lower_bound"])
    runs = [("ega", {}), ("ega-paper", {"max_gen": 3}), ("nsga2", {"max_gen": 3})]
    if sc.width <= 30:
        runs.append(("ega", {"path": "spline", "max_gen": 3}))
    for method, options in runs:
        plan = plan_continuous(sc, method=method, seed=0, **options)
        assert plan.reached, (method, options)
        if "path" not in options:
            revalidated(plan, sc)
        assert np.all(plan.lengths[list(plan.feasible)] >= lower[list(plan.feasible)] - 1e-9), (method, options)
        for member in plan.info.get("front", []):
            assert member["objectives"]["length"] >= lower.sum() - 1e-9


@pytest.mark.parametrize("method", ["ega", "ega-paper", "nsga2"])
def test_the_same_seed_gives_the_same_paths(method):
    sc = load_scenario("ega01_random1")
    first = plan_continuous(sc, method=method, seed=11, max_gen=6)
    again = plan_continuous(sc, method=method, seed=np.random.default_rng(11), max_gen=6)
    same = plan_continuous(sc, method=method, seed=11, max_gen=6)
    assert all(np.array_equal(a, b) for a, b in zip(first.paths, same.paths))
    assert np.array_equal(first.history, same.history) and len(first.history) == 7
    assert again.reached  # a Generator is a seed too (its own stream: not the int's)


def test_the_ga_keeps_the_robots_of_cross4_apart():
    sc = load_scenario("ega_cross4")
    alone = plan_continuous(sc)
    assert alone.conflicts  # each robot's own optimum crosses the centre at the same time
    for seed in range(2):
        plan = revalidated(plan_continuous(sc, method="ega", seed=seed), sc)
        assert plan.reached and all(plan.feasible) and plan.conflicts == ()
        assert plan.min_robot_distance >= plan.safety_distance
        closest = min(robot_distance(plan.paths[a], plan.paths[b]) for a in range(4) for b in range(a + 1, 4))
        assert closest == pytest.approx(plan.min_robot_distance)
        assert plan.lengths.sum() <= 1.10 * alone.lengths.sum()


def test_normalise_runs_each_term_alone_then_weighs_them():
    sc = load_scenario("ega04_corridor1")
    plan = revalidated(plan_continuous(sc, method="ega", normalise=True, seed=2, max_gen=8), sc)
    optima = plan.info["normalised_from"]
    assert optima["length"] == pytest.approx(plan_continuous(sc).lengths[0], rel=1e-3)
    assert plan.info["weights"] == pytest.approx([1.0, optima["length"] / optima["smoothness_deg"],
                                                  optima["length"] / optima["safety_cost"]])
    # the weighted path trades length for smoothness and safety
    assert plan.lengths[0] >= optima["length"] - 1e-9
    # why §5.3's terms do not balance with eq. 5: its R sums over PBs, and the safety-only run keeps
    # many more of them than the length-only run (the weighted run's path bases are reported too)
    length_only, smoothness_only, safety_only = optima["path_bases"]
    assert safety_only > 2 * length_only and len(plan.info["path_bases"][0]) < safety_only


def test_normalise_without_clearance_gives_no_safety_weight():
    # every APF path touches a wall, so the smallest clearance of the safety-only run's best is 0
    sc = load_scenario("ega04_corridor1")
    plan = plan_continuous(sc, method="ega", normalise=True, safety="min", seed=0, max_gen=2)
    assert plan.info["normalised_from"]["safety_cost"] == float("inf") and plan.info["weights"][2] == 0.0
    out = json.loads(json.dumps(plan.as_dict(), allow_nan=False))  # strict JSON: no Infinity
    assert out["info"]["normalised_from"]["safety_cost"] is None


def test_weights_change_the_path():
    sc = load_scenario("ega04_corridor1")
    short = plan_continuous(sc, method="ega", seed=0, max_gen=8)
    safe = plan_continuous(sc, method="ega", weights=(1, 0, 5), safety="paper", seed=0, max_gen=8)
    assert short.safety[0] == pytest.approx(0.0, abs=1e-9)  # the shortest path bends at the corners
    assert safe.safety[0] > 1.0 and safe.lengths[0] > short.lengths[0]
    assert short.info["weights"] == [1.0, 0.0, 0.0] and len(short.info["path_bases"][0]) >= 1


def test_nsga2_returns_a_front_whose_shortest_is_the_weighted_best():
    sc = load_scenario("ega04_corridor1")
    plan = revalidated(plan_continuous(sc, method="nsga2", seed=1), sc)
    front = plan.info["front"]
    assert len(front) >= 5 and plan.method == "nsga2"
    F = np.array([[m["objectives"]["length"], m["objectives"]["smoothness_deg"], -m["objectives"]["safety"]]
                  for m in front])
    for i in range(len(F)):  # mutually non-dominated
        assert not np.any(np.all(F <= F[i], axis=1) & np.any(F < F[i], axis=1))
    weighted = plan_continuous(sc, method="ega", seed=1)
    assert F[0, 0] <= weighted.lengths[0] * 1.01 and plan.lengths[0] == pytest.approx(F[0, 0])
    for name in ("nsga3", "smsemoa"):
        other = revalidated(plan_moea(sc, algorithm=name, seed=1, max_gen=6), sc)
        assert other.method == name and other.info["front"]


def test_an_enclosed_goal_is_not_reached_and_start_on_goal_is_zero_length():
    walls = [[6, 6, 9, 7], [6, 9, 9, 10], [6, 6, 7, 10], [8, 6, 9, 10]]
    sc = scenario(walls, [([1, 1], [7.5, 8]), ([1, 9], [4, 9])], r=0.1)
    for method in ("ega", "ega-paper", "nsga2"):
        plan = revalidated(plan_continuous(sc, method=method, seed=0, max_gen=3), sc)
        assert plan.robots_reached == (False, True) and plan.paths[0].shape == (0, 2)
    same = scenario(walls, [([2, 2], [2, 2])])
    plan = plan_continuous(same, method="ega", seed=0, max_gen=2)
    assert plan.reached and plan.lengths[0] == 0 and plan.paths[0].tolist() == [[2, 2]]


@pytest.mark.parametrize("options, words", [
    (dict(method="ega", weights=(1, 0, 0), normalise=True), "not both"),
    (dict(method="ega", weights=(0, 0, 0)), "must not all be zero"),
    (dict(method="ega", weights=(1, -1, 0)), "weights[1]"),
    (dict(method="ega", path="bezier"), "path must be one of"),
    (dict(method="ega", safety="max"), "safety must be one of"),
    (dict(method="ega", pop_size=1), "pop_size"),
    (dict(method="ega", grid=0), "grid must be"),
    (dict(method="ega-paper", grid=7), "grid must be"),
    (dict(method="nsga2", weights=(1, 0, 0)), "takes no option 'weights'"),
    (dict(method="exact", path="spline"), "takes no option 'path'"),
    (dict(method="ega", normalise="yes"), "normalise"),
])
def test_bad_options_raise_typed_errors(options, words):
    sc = scenario([[4, 0, 6, 8]], [([1, 1], [9, 1])])
    with pytest.raises(ParameterError) as info:
        plan_continuous(sc, **options)
    assert words in str(info.value)
    with pytest.raises(ParameterError, match="unknown algorithm"):
        plan_moea(sc, algorithm="ega")
