"""Operators over Nazarahari et al. 2019's path bases: invariants with hypothesis (children in the
box, eq. 1 and eq. 2 geometry, mutations' reach, deletion's properties), taut refinement against the
exact reference, collision removal, float duplicates, and pymoo's random_state as the only randomness."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from pymoo.core.population import Population

from htetro_opt.model import path_length, robot_distance
from htetro_opt.model.continuous import closest_approach
from htetro_opt.operators.path_bases import (
    CollisionRemoval,
    PathBasesCrossover,
    PathBasesDeletion,
    PathBasesDuplicateElimination,
    PathBasesMutation,
    PathBasesSampling,
    TautRefinement,
    as_column,
    blend_crossover,
    conflicts,
    delete_path_bases,
    goal_move,
    mean_crossover,
    n_mutated,
    random_move,
    smooth_move,
    taut_path,
)
from htetro_opt.problems import PathBasesProblem
from htetro_opt.scenarios import load_scenario
from htetro_opt.solvers.continuous import apf_paths, plan_continuous

points = st.lists(st.tuples(st.floats(0, 30), st.floats(0, 30)), min_size=0, max_size=12).map(
    lambda xs: np.array(xs, dtype=float).reshape(-1, 2))
seeds = st.integers(0, 2**32 - 1)

MAP = load_scenario("ega11_random2")


def polyline(start, pbs, goal):
    return np.vstack([start, pbs, goal])


# --- crossovers -------------------------------------------------------------------------------
@settings(max_examples=150, deadline=None)
@given(points)
def test_eq1_of_a_path_with_itself_is_the_path(a):
    assert np.array_equal(mean_crossover(a, a), a)


def expected_pairs(a, b):
    """The pairs eqs. 1 and 2 combine, computed here: by index, or each PB of the shorter parent
    with its nearest in the other (a loop)."""
    if len(a) == len(b):
        return list(zip(a, b))
    short, other = (a, b) if len(a) < len(b) else (b, a)
    return [(p, min(other, key=lambda q: np.hypot(*(q - p)))) for p in short]


@settings(max_examples=150, deadline=None)
@given(points, points, seeds)
def test_eq2_children_lie_on_the_line_of_each_pb_pair(a, b, seed):
    child = blend_crossover(a, b, random_state=np.random.default_rng(seed))
    pairs = expected_pairs(a, b)
    assert len(child) == len(pairs) == min(len(a), len(b))
    for c, (p, q) in zip(child, pairs):
        u, v = q - p, c - p
        assert abs(u[0] * v[1] - u[1] * v[0]) <= 1e-9 * max(1.0, np.hypot(*u) * np.hypot(*v))
        assert np.hypot(*v) <= 2 * np.hypot(*u) + 1e-9  # α in [−1, 1]: c = q + α (p − q)


@settings(max_examples=100, deadline=None)
@given(points, points)
def test_eq1_is_the_mean_of_each_pair(a, b):
    child = mean_crossover(a, b)
    pairs = expected_pairs(a, b)
    assert len(child) == len(pairs)
    for c, (p, q) in zip(child, pairs):
        assert np.allclose(c, (p + q) / 2, atol=1e-12)


# --- mutations --------------------------------------------------------------------------------
@settings(max_examples=150, deadline=None)
@given(points, seeds, st.floats(0.1, 3.0))
def test_mutations_move_k_pbs_within_their_reach(pbs, seed, step):
    rng = np.random.default_rng(seed)
    start, goal = np.array([1.0, 1.0]), np.array([29.0, 29.0])
    k = n_mutated(len(pbs))
    moved = random_move(pbs, step=step, random_state=rng)
    gap = np.hypot(*(moved - pbs).T)
    assert (gap > 0).sum() <= k and gap.max(initial=0) <= step + 1e-9
    towards = goal_move(pbs, goal, step=step, random_state=rng)
    before, after = np.hypot(*(goal - pbs).T), np.hypot(*(goal - towards).T)
    assert np.all(after <= before + 1e-9) and ((before - after) > 1e-12).sum() <= k
    assert np.allclose(before - after, np.hypot(*(towards - pbs).T))  # straight towards the goal, never past
    smooth = smooth_move(pbs, start, goal, random_state=rng)
    assert (np.hypot(*(smooth - pbs).T) > 0).sum() <= k
    if len(pbs):  # eq. 3 with α, β ≥ 0, α + β ≤ ½: a convex combination of the path's points
        hull = polyline(start, pbs, goal)
        assert np.all(smooth >= hull.min(axis=0) - 1e-9) and np.all(smooth <= hull.max(axis=0) + 1e-9)


@settings(max_examples=40, deadline=None)
@given(st.lists(points, min_size=2, max_size=6), seeds)
def test_pymoo_classes_keep_children_in_the_box(members, seed):
    problem = PathBasesProblem(MAP.with_robot_radius(0.5))
    pop = Population.new("X", as_column(members))
    matings = np.array([[i, (i + 1) % len(members)] for i in range(len(members))])
    off = PathBasesCrossover().do(problem, pop, matings, random_state=np.random.default_rng(seed))
    off = PathBasesMutation().do(problem, off, random_state=np.random.default_rng(seed))
    x0, y0, x1, y1 = problem.box
    assert len(off) == 2 * len(members)
    for x in off.get("X")[:, 0]:
        assert np.all((x[:, 0] >= x0) & (x[:, 0] <= x1) & (x[:, 1] >= y0) & (x[:, 1] <= y1))
        line = problem.polyline(x)
        assert np.array_equal(line[0], problem.starts[0]) and np.array_equal(line[-1], problem.goals[0])


# --- deletion ---------------------------------------------------------------------------------
def random_paths(sc, rng, n):
    start, goal = sc.starts[0], sc.goals[0]
    paths, _ = apf_paths(sc.geometry, start, goal, n_paths=n, seed=rng)
    return [p + rng.normal(0, 0.3, p.shape) * (rng.random(len(p)) < 0.3)[:, None] for p in paths]


@settings(max_examples=30, deadline=None)
@given(seeds, st.sampled_from(["ega01_random1", "ega07_slits1", "ega12_plankpile"]))
def test_deletion_keeps_feasibility_never_lengthens_and_is_idempotent(seed, name):
    sc = load_scenario(name)
    geo, start, goal = sc.geometry, sc.starts[0], sc.goals[0]
    for pbs in random_paths(sc, np.random.default_rng(seed), 3):
        before = polyline(start, pbs, goal)
        out = delete_path_bases(pbs, start, goal, geo)
        after = polyline(start, out, goal)
        bad_before = int((~geo.path_segments_feasible(before)).sum())
        bad_after = int((~geo.path_segments_feasible(after)).sum())
        if bad_before == 0:
            assert bad_after == 0 and path_length(after) <= path_length(before) + 1e-9
        else:
            assert bad_after <= bad_before
        assert len(out) <= len(pbs) and all(any(np.array_equal(o, p) for p in pbs) for o in out)
        assert np.array_equal(delete_path_bases(out, start, goal, geo), out)

        # the judged form, scoring every candidate whole, agrees with the segment-by-segment default
        def judge(candidate):
            line = polyline(start, candidate, goal)
            return int((~geo.path_segments_feasible(line)).sum()), path_length(line)

        assert np.array_equal(delete_path_bases(pbs, start, goal, judge=judge), out)


@settings(max_examples=60, deadline=None)
@given(points, st.sampled_from([0.0, 0.4]))
def test_deletion_empties_a_path_whose_straight_segment_is_free(pbs, r):
    sc = load_scenario("ega_cross4").with_robot_radius(r)
    start, goal = np.array([2.0, 10.0]), np.array([28.0, 10.0])  # below the side boxes' reach
    assert sc.geometry.segments_feasible(start[None], goal[None])[0]
    pbs = np.clip(pbs, 1, 29)
    if sc.geometry.path_feasible(polyline(start, pbs, goal)):
        assert delete_path_bases(pbs, start, goal, sc.geometry).shape == (0, 2)


def test_deletion_repair_on_weights_and_several_robots():
    sc = load_scenario("ega04_corridor1")
    paths, _ = apf_paths(sc.geometry, sc.starts[0], sc.goals[0], n_paths=4, seed=0)
    for weights in [(1, 0, 0), (1, 0.2, 0), (1, 0, 5)]:
        problem = PathBasesProblem(sc, weights=weights)
        G, F = problem.score(paths)
        pop = PathBasesDeletion().do(problem, Population.new("X", as_column(paths)))
        G2, F2 = problem.score(list(pop.get("X")[:, 0]))
        assert np.all(G2 == 0) and np.all(F2[:, 0] <= F[:, 0] + 1e-9)
        assert all(len(a) <= len(b) for a, b in zip(pop.get("X")[:, 0], paths))


# --- taut refinement --------------------------------------------------------------------------
@pytest.mark.parametrize("name", ["ega02_maze1", "ega07_slits1", "ega12_plankpile", "ega_cross4"])
def test_taut_refinement_is_feasible_never_longer_and_not_below_the_exact_optimum(name):
    sc = load_scenario(name)
    problem = PathBasesProblem(sc)
    exact = plan_continuous(sc)
    start, goal = sc.starts[0], sc.goals[0]
    paths, _ = apf_paths(sc.geometry, start, goal, n_paths=3, seed=1)
    for pbs in paths:
        pbs = delete_path_bases(pbs, start, goal, sc.geometry)
        for _ in range(3):
            taut = taut_path(pbs, start, goal, sc.geometry, problem.corners, reach=2.0)
            line = polyline(start, taut, goal)
            assert sc.geometry.path_feasible(line)
            assert path_length(line) <= path_length(polyline(start, pbs, goal)) + 1e-9
            assert path_length(line) >= exact.info["lower_bound"][0] - 1e-9
            pbs = taut


def test_the_taut_refinement_repair_keeps_only_improvements():
    sc = load_scenario("ega07_slits1")
    problem = PathBasesProblem(sc, weights=(1, 0, 0))
    paths, _ = apf_paths(sc.geometry, sc.starts[0], sc.goals[0], n_paths=3, seed=2)
    G, F = problem.score(paths)
    pop = TautRefinement().do(problem, Population.new("X", as_column(paths)))
    G2, F2 = problem.score(list(pop.get("X")[:, 0]))
    assert np.all(G2 <= G) and np.all(F2 < F)


# --- collision removal ------------------------------------------------------------------------
def position(path, t):
    s = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(path, axis=0).T))])
    return np.array([np.interp(t, s, path[:, 0]), np.interp(t, s, path[:, 1])])


@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(st.floats(0, 10), st.floats(0, 10)), min_size=2, max_size=5),
       st.lists(st.tuples(st.floats(0, 10), st.floats(0, 10)), min_size=2, max_size=5))
def test_closest_approach_is_where_the_robots_come_closest(a, b):
    a, b = np.array(a), np.array(b)
    d, t = closest_approach(a, b)
    assert d == pytest.approx(robot_distance(a, b), abs=1e-12)
    assert np.hypot(*(position(a, t) - position(b, t))) == pytest.approx(d, abs=1e-9)
    times = np.linspace(0, max(path_length(a), path_length(b)), 2001)
    sampled = np.hypot(*(position(a, times) - position(b, times))).min()
    assert d <= sampled + 1e-9


def test_collision_removal_on_cross4_lessens_or_removes_the_conflicts():
    sc = load_scenario("ega_cross4")
    problem = PathBasesProblem(sc)
    straight = tuple(np.empty((0, 2)) for _ in range(4))
    before = problem.measure([straight])["penalty"][0]
    assert len(conflicts(problem.polylines(straight), problem.safety_distance)) == 6 and before > 0
    resolved = 0
    for seed in range(8):
        pop = CollisionRemoval(tries=200).do(problem, Population.new("X", as_column([straight])),
                                             random_state=np.random.default_rng(seed))
        x = pop.get("X")[0, 0]
        lines = problem.polylines(x)
        assert sc.geometry.paths_feasible(lines).all()
        assert x is straight or problem.measure([x])["penalty"][0] < before
        resolved += conflicts(lines, problem.safety_distance) == []
    assert resolved >= 1


# --- duplicates and randomness ----------------------------------------------------------------
def test_float_duplicates_are_not_merged():
    a = np.array([[1.0, 2.0], [3.0, 4.0]])
    pop = Population.new("X", as_column([a, a + 1e-12, a.copy(), a[:1]]))
    is_dup = PathBasesDuplicateElimination()._do(pop, None, np.zeros(4, dtype=bool))
    assert is_dup.tolist() == [False, False, True, False]


def test_operators_draw_only_from_random_state():
    sc = load_scenario("ega05_boxpile")
    problem = PathBasesProblem(sc)
    np.random.seed(0)
    reference = np.random.random(3)
    np.random.seed(0)

    def run(seed):
        rng = np.random.default_rng(seed)
        pop = PathBasesSampling().do(problem, 6, random_state=rng)
        off = PathBasesCrossover().do(problem, pop, np.array([[0, 1], [2, 3], [4, 5]]), random_state=rng)
        off = PathBasesMutation().do(problem, off, random_state=rng)
        return [x.copy() for x in off.get("X")[:, 0]]

    first, second = run(5), run(5)
    assert all(np.array_equal(p, q) for p, q in zip(first, second))
    assert not all(np.array_equal(p, q) for p, q in zip(first, run(6)))
    assert np.array_equal(np.random.random(3), reference)
