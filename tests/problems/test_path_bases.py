"""Nazarahari et al. 2019's path-base problem: eqs. 4–6 on hand-checkable paths, the spline, G, the
multi-robot penalty, and typed errors."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from htetro_opt.errors import ParameterError, ScenarioError
from htetro_opt.model import robot_distance
from htetro_opt.problems import PathBasesProblem, check_path_weights, spline_path
from htetro_opt.scenarios import load_scenario, parse_scenario


def scenario(obstacles=(), robots=(((1, 1), (9, 1)),), r=0.0, size=10.0):
    return parse_scenario({"name": "t", "width": size, "height": size, "robot_radius": r, "obstacles": list(obstacles),
                           "robots": [{"start": list(s), "goal": list(g)} for s, g in robots]})


def column(*xs):
    X = np.empty((len(xs), 1), dtype=object)
    for i, x in enumerate(xs):
        X[i, 0] = x
    return X


def evaluate(problem, *xs):
    return problem.evaluate(column(*xs), return_values_of=["F", "G"])


def test_length_of_a_straight_path_and_an_l_turn():
    problem = PathBasesProblem(scenario(robots=[((1, 1), (9, 1))]), weights=(1, 1, 0))
    F, G = evaluate(problem, np.empty((0, 2)), np.array([[5.0, 1.0]]), np.array([[5.0, 5.0]]))
    assert F[0, 0] == pytest.approx(8.0) and F[1, 0] == pytest.approx(8.0)  # a collinear PB changes nothing
    assert F[2, 0] == pytest.approx(2 * math.hypot(4, 4) + 90.0)  # two 45° turns at the ends, one 90° at the PB
    turn = PathBasesProblem(scenario(robots=[((1, 1), (9, 5))])).measure([np.array([[9.0, 1.0]])])
    assert turn["length"][0, 0] == pytest.approx(8 + 4) and turn["smoothness"][0, 0] == pytest.approx(90.0)
    assert G.tolist() == [[0.0], [0.0], [0.0]]


@settings(max_examples=60, deadline=None)
@given(st.lists(st.floats(0.5, 9.5), min_size=2, max_size=8), st.integers(0, 6), st.floats(0.05, 0.95))
def test_smoothness_is_unchanged_by_a_collinear_pb(coords, where, t):
    problem = PathBasesProblem(scenario(), weights=(0, 1, 0))
    pbs = np.array(coords[: len(coords) // 2 * 2]).reshape(-1, 2)
    path = np.vstack([problem.starts[0], pbs, problem.goals[0]])
    k = where % (len(path) - 1)
    if np.hypot(*(path[k + 1] - path[k])) < 1e-6:
        return
    inserted = np.insert(pbs, k, path[k] + t * (path[k + 1] - path[k]), axis=0)
    F = evaluate(problem, pbs, inserted)[0]
    assert F[1, 0] == pytest.approx(F[0, 0], abs=1e-6)


def test_safety_is_clearance_minus_the_radius():
    sc = scenario([[4, 4, 6, 6]], robots=[((1, 5), (9, 5))], r=0.25)
    pbs = np.array([[3.0, 7.0], [7.0, 7.0]])
    paper = PathBasesProblem(sc, weights=(0, 0, 1), safety="paper").measure([pbs])["safety"][0, 0]
    assert paper == pytest.approx(2 * (math.hypot(1, 1) - 0.25))
    lowest = PathBasesProblem(sc, weights=(0, 0, 1), safety="min").measure([pbs])["safety"][0, 0]
    assert lowest == pytest.approx(1.0 - 0.25)  # the segment (3, 7)–(7, 7) runs 1 above the box
    F = evaluate(PathBasesProblem(sc, weights=(1, 0, 2), safety="paper"), pbs)[0]
    assert F[0, 0] == pytest.approx(2 * math.hypot(2, 2) + 4 + 2 / paper)


def test_separate_objectives():
    sc = scenario([[4, 4, 6, 6]], robots=[((1, 5), (9, 5))])
    problem = PathBasesProblem(sc, objectives="separate", safety="min")
    F, G = evaluate(problem, np.array([[3.0, 7.0], [7.0, 7.0]]))
    assert F.shape == (1, 3) and problem.n_obj == 3
    assert F[0].tolist() == pytest.approx([2 * math.hypot(2, 2) + 4, 90.0, -1.0])


def test_g_counts_infeasible_segments():
    problem = PathBasesProblem(scenario([[4, 0, 6, 8]]))
    F, G = evaluate(problem, np.empty((0, 2)), np.array([[5.0, 1.0]]), np.array([[4.0, 8.0], [6.0, 8.0]]))
    assert G[:, 0].tolist() == [1.0, 2.0, 0.0]


def test_the_spline_passes_through_its_pbs_with_dense_samples():
    rng = np.random.default_rng(0)
    for _ in range(20):
        points = rng.uniform(0, 10, (rng.integers(3, 7), 2))
        curve = spline_path(points)
        chords = np.hypot(*np.diff(points, axis=0).T)
        at = np.concatenate([[0], np.cumsum(np.maximum(10, np.ceil(chords / 0.1)).astype(int))])
        assert np.array_equal(curve[at], points)
        assert len(curve) >= 10 * (len(points) - 1) + 1
    straight = spline_path([[0, 0], [3, 4]])
    assert straight.tolist() == [[0, 0], [3, 4]]


def test_a_spline_path_is_measured_on_its_samples():
    sc = scenario(robots=[((1, 1), (9, 1))])
    linear = PathBasesProblem(sc, path="linear").measure([np.array([[5.0, 5.0]])])
    spline = PathBasesProblem(sc, path="spline").measure([np.array([[5.0, 5.0]])])
    assert spline["length"][0, 0] > linear["length"][0, 0] * 0.95
    curve = PathBasesProblem(sc, path="spline").polyline(np.array([[5.0, 5.0]]))
    steps = np.diff(curve, axis=0)
    cross = steps[:-1, 0] * steps[1:, 1] - steps[:-1, 1] * steps[1:, 0]
    turns = np.degrees(np.abs(np.arctan2(cross, (steps[:-1] * steps[1:]).sum(axis=1))))
    assert turns.max() < 10 and spline["smoothness"][0, 0] == pytest.approx(turns.sum())  # no sharp turn


def test_robot_conflicts_are_penalised_and_counted_in_g():
    sc = scenario(robots=[((1, 5), (9, 5)), ((9, 5.2), (1, 5.2))], r=0.3)
    problem = PathBasesProblem(sc)
    head_on = (np.empty((0, 2)), np.empty((0, 2)))
    apart = (np.empty((0, 2)), np.array([[5.0, 8.0]]))
    F, G = evaluate(problem, head_on, apart)
    d_s = 2 * 0.3 + 0.5
    assert problem.safety_distance == pytest.approx(d_s)
    d = robot_distance([[1, 5], [9, 5]], [[9, 5.2], [1, 5.2]])
    assert F[0, 0] == pytest.approx(16 + 10 * 20 * (d_s - d) / d_s) and G[0, 0] == 1
    terms = problem.measure([apart])
    assert terms["min_distance"][0] >= d_s and G[1, 0] == 0 and terms["penalty"][0] == 0


def test_ega_cross4_alone_conflicts():
    sc = load_scenario("ega_cross4")
    problem = PathBasesProblem(sc)
    straight = tuple(np.empty((0, 2)) for _ in range(4))
    terms = problem.measure([straight])
    assert terms["conflicts"][0] == 6 and terms["min_distance"][0] == pytest.approx(0.0)


@pytest.mark.parametrize("kwargs, words", [
    (dict(path="bezier"), "path must be one of"),
    (dict(safety="max"), "safety must be one of"),
    (dict(objectives="pareto"), "objectives must be one of"),
    (dict(weights=(1, 0)), "three numbers"),
    (dict(weights=(1, -1, 0)), "weights[1] must be"),
    (dict(weights=(1, float("nan"), 0)), "weights[1] must be"),
    (dict(weights=(0, 0, 0)), "must not all be zero"),
    (dict(grid=0), "grid must be"),
])
def test_bad_options_raise_typed_errors(kwargs, words):
    with pytest.raises(ParameterError) as info:
        PathBasesProblem(scenario(), **kwargs)
    assert words in str(info.value)


def test_a_grid_scenario_is_refused_and_weights_check():
    with pytest.raises(ScenarioError, match="grid scenario"):
        PathBasesProblem(load_scenario("three_slit"))
    assert check_path_weights([1, 0, 0]) == (1.0, 0.0, 0.0)
    problem = PathBasesProblem(scenario(robots=[((1, 1), (9, 1)), ((1, 9), (9, 9))]))
    with pytest.raises(ParameterError, match="holds 2 robots"):
        problem.robots(np.empty((0, 2)))
