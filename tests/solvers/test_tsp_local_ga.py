"""Local search and the DEAP GA for the waypoint order: invariants, local optimality by brute force,
exact optima on small instances, determinism and untouched global random states."""

import itertools
import random

import numpy as np
import pytest
from deap import creator
from hypothesis import given, settings
from hypothesis import strategies as st

from htetro_opt.errors import ParameterError
from htetro_opt.problems.waypoint_sequencing import SequencingInstance, path_cost
from htetro_opt.scenarios import parse_tileset
from htetro_opt.solvers.sequencing import sequence_waypoints
from htetro_opt.solvers.tsp_ga import (
    Tour,
    make_toolbox,
    order_crossover,
    select_tournament,
    solve_ga,
    swap_mutation,
)
from htetro_opt.solvers.tsp_local import (
    double_bridge,
    improve,
    improve_batch,
    nearest_neighbour,
    or_opt,
    solve_local,
    two_opt,
)

TOL = 1e-9


# ------------------------------------------------------------------------------------ helpers
def euclidean(n, seed, scale=10.0):
    x = np.random.default_rng(seed).random((n, 2)) * scale
    return np.sqrt(((x[:, None] - x[None]) ** 2).sum(-1))


def random_symmetric(n, seed):
    """Non-metric symmetric costs: the gains must not rely on the triangle inequality."""
    a = np.random.default_rng(seed).random((n, n)) * 10
    c = a + a.T
    np.fill_diagonal(c, 0.0)
    return c


def instance(cost, start=0):
    return SequencingInstance(cost, np.zeros((len(cost), 4, 2)), start=start)


def is_permutation(order, n):
    return sorted(np.asarray(order).tolist()) == list(range(n))


def brute_optimum(cost, start):
    """The cheapest open path by enumeration (n ≤ 9)."""
    n = len(cost)
    rest = [i for i in range(n) if i != start]
    perms = np.array(list(itertools.permutations(rest)), dtype=np.int64)
    if start is not None:
        perms = np.hstack([np.full((len(perms), 1), start), perms])
    return float(path_cost(cost, perms).min())


def improving_reversal(cost, order, fixed):
    """Some reversal of order[i..j] (i < j; i ≥ 1 with a fixed start) that is cheaper, or None."""
    order = np.asarray(order)
    base = path_cost(cost, order)
    for i in range(1 if fixed else 0, len(order)):
        for j in range(i + 1, len(order)):
            p = order.copy()
            p[i:j + 1] = p[i:j + 1][::-1]
            if path_cost(cost, p) < base - TOL:
                return i, j
    return None


def improving_segment_move(cost, order, fixed, lengths=(1, 2, 3)):
    """Some move of a segment (as is or reversed) elsewhere that is cheaper, or None."""
    order = list(np.asarray(order).tolist())
    base = path_cost(cost, order)
    lo = 1 if fixed else 0
    for L in lengths:
        for i in range(lo, len(order) - L + 1):
            seg, rest = order[i:i + L], order[:i] + order[i + L:]
            for k in range(lo, len(rest) + 1):
                for s in (seg, seg[::-1]):
                    if path_cost(cost, rest[:k] + s + rest[k:]) < base - TOL:
                        return i, L, k
    return None


CASES = [(gen, n, seed, fixed) for gen in (euclidean, random_symmetric) for n in (2, 3, 5, 8, 11)
         for seed in (0, 1) for fixed in (True, False)]


# ----------------------------------------------------------------------- GA operators (hypothesis)
@st.composite
def permutations(draw, min_size=0, max_size=12):
    n = draw(st.integers(min_size, max_size))
    return draw(st.permutations(list(range(n))))


@settings(max_examples=150, deadline=None)
@given(permutations(), st.integers(0, 2**32 - 1))
def test_swap_mutation_swaps_two_genes(genes, seed):
    child = list(genes)
    assert swap_mutation(child, random.Random(seed)) == (child,)
    assert sorted(child) == sorted(genes)
    changed = [i for i, (a, b) in enumerate(zip(genes, child)) if a != b]
    assert len(changed) == (2 if len(genes) >= 2 else 0)
    if changed:
        i, j = changed
        assert child[i] == genes[j] and child[j] == genes[i]


def _is_linear_ox_child(child, keep, fill):
    n = len(child)
    for a in range(n + 1):
        for b in range(a, n + 1):
            if child[a:b] != keep[a:b]:
                continue
            kept = set(keep[a:b])
            if child[:a] + child[b:] == [g for g in fill if g not in kept]:
                return True
    return n == 0


@settings(max_examples=150, deadline=None)
@given(st.integers(0, 10).flatmap(lambda n: st.tuples(st.permutations(list(range(n))),
                                                      st.permutations(list(range(n))))),
       st.integers(0, 2**32 - 1))
def test_order_crossover_makes_permutations_from_a_slice_and_the_other_order(parents, seed):
    p1, p2 = list(parents[0]), list(parents[1])
    c1, c2 = Tour(p1), Tour(p2)
    assert order_crossover(c1, c2, random.Random(seed)) == (c1, c2)
    assert sorted(c1) == sorted(c2) == sorted(p1)
    assert _is_linear_ox_child(list(c1), p1, p2) and _is_linear_ox_child(list(c2), p2, p1)
    assert isinstance(c1, Tour) and hasattr(c1, "fitness")


@settings(max_examples=60, deadline=None)
@given(st.integers(2, 9), st.integers(0, 8), st.integers(0, 2**16))
def test_toolbox_operators_keep_the_fixed_start_first(n, start, seed):
    start = start % n
    tb = make_toolbox(instance(euclidean(n, seed), start), random.Random(seed))
    pop = tb.population(6)
    for a, b in zip(pop[::2], pop[1::2]):
        tb.mate(a, b)
    for t in pop:
        tb.mutate(t)
    assert tb.evaluate(pop) == 6
    orders = tb.orders(pop)
    assert (orders[:, 0] == start).all()
    assert all(is_permutation(o, n) for o in orders)
    assert np.allclose([t.fitness.values[0] for t in pop], path_cost(euclidean(n, seed), orders))
    assert tb.evaluate(pop) == 0  # valid fitnesses are not priced again


def test_tournament_picks_the_cheapest_of_each_draw():
    pop = [Tour([i]) for i in range(5)]
    for t, c in zip(pop, [5.0, 4.0, 3.0, 2.0, 1.0]):
        t.fitness.values = (c,)
    assert [t[0] for t in select_tournament(pop, 20, random.Random(0), 5 * 40)] == [4] * 20
    assert {t[0] for t in select_tournament(pop, 200, random.Random(0), 1)} == set(range(5))


# ------------------------------------------------------------------------- local search
@pytest.mark.parametrize("gen,n,seed,fixed", CASES)
def test_moves_never_worsen_keep_the_start_and_reach_their_local_optimum(gen, n, seed, fixed):
    cost = gen(n, seed)
    start = np.random.default_rng(seed + 7).permutation(n)
    base = path_cost(cost, start)
    for move, check in ((two_opt, [improving_reversal]), (or_opt, [improving_segment_move]),
                        (improve, [improving_reversal, improving_segment_move])):
        out = move(cost, start, fixed_start=fixed)
        assert out.dtype == np.int64 and is_permutation(out, n)
        assert path_cost(cost, out) <= base + TOL
        if fixed:
            assert out[0] == start[0]
        for find in check:
            assert find(cost, out, fixed) is None, (move.__name__, find.__name__)


@pytest.mark.parametrize("fixed", [True, False])
def test_restricted_rounds_are_certified_on_a_larger_instance(fixed):
    # 120 waypoints: the neighbour-list rounds do most of the work, the full rounds certify
    cost = euclidean(120, 3)
    start = nearest_neighbour(cost, start=0 if fixed else None)
    out = two_opt(cost, start, fixed_start=fixed)
    assert improving_reversal(cost, out, fixed) is None
    out = improve(cost, start, fixed_start=fixed)
    assert improving_reversal(cost, out, fixed) is None
    assert path_cost(cost, out) < path_cost(cost, start)


@pytest.mark.parametrize("fixed", [True, False])
def test_iterated_local_search_ends_at_a_certified_local_optimum(fixed):
    cost = euclidean(40, 11)
    inst = instance(cost, 5 if fixed else None)
    order, info = solve_local(inst, restarts=25, seed=2)
    assert inst.check_order(order) is not None
    assert inst.path_cost(order) <= info["local_optimum_cost"] + TOL <= info["initial_cost"] + TOL
    assert improving_reversal(cost, order, fixed) is None
    assert improving_segment_move(cost, order, fixed) is None


@pytest.mark.parametrize("fixed", [True, False])
def test_batched_local_search_matches_the_guarantees(fixed):
    n = 9
    cost = random_symmetric(n, 5)
    rng = np.random.default_rng(0)
    if fixed:
        orders = np.array([[0, *rng.permutation(np.arange(1, n))] for _ in range(12)])
    else:
        orders = np.array([rng.permutation(n) for _ in range(12)])
    out = improve_batch(cost, orders, fixed_start=fixed)
    assert out.shape == orders.shape
    for before, after in zip(orders, out):
        assert is_permutation(after, n) and path_cost(cost, after) <= path_cost(cost, before) + TOL
        assert not fixed or after[0] == before[0]
        assert improving_reversal(cost, after, fixed) is None
        assert improving_segment_move(cost, after, fixed) is None


def test_round_budget_and_argument_checks():
    cost = euclidean(10, 0)
    order = np.arange(10)[::-1].copy()
    assert two_opt(cost, order, max_rounds=0).tolist() == order.tolist()
    assert improve(cost, order, max_rounds=0).tolist() == order.tolist()
    assert path_cost(cost, improve(cost, order, max_rounds=1)) <= path_cost(cost, order)
    with pytest.raises(ParameterError, match="permutation"):
        two_opt(cost, [0, 1, 1, 2, 3, 4, 5, 6, 7, 8])
    with pytest.raises(ParameterError, match="symmetric"):
        improve(np.triu(cost), order)
    with pytest.raises(ParameterError, match="segment_lengths"):
        or_opt(cost, order, segment_lengths=(0,))
    with pytest.raises(ParameterError, match="max_rounds"):
        two_opt(cost, order, max_rounds=-1)
    with pytest.raises(ParameterError, match="start"):
        nearest_neighbour(cost, start=10)
    with pytest.raises(ParameterError, match="restarts"):
        solve_local(instance(cost), restarts=-1)


def test_nearest_neighbour_is_greedy_and_the_free_start_is_the_best_of_all_starts():
    cost = euclidean(12, 4)
    order = nearest_neighbour(cost, start=3)
    assert order[0] == 3 and is_permutation(order, 12)
    for step in range(1, 12):
        options = [j for j in range(12) if j not in order[:step]]
        assert cost[order[step - 1], order[step]] == min(cost[order[step - 1], j] for j in options)
    free = nearest_neighbour(cost)
    assert path_cost(cost, free) == min(path_cost(cost, nearest_neighbour(cost, start=s)) for s in range(12))


def test_double_bridge_is_a_permutation_keeping_the_start():
    rng = np.random.default_rng(0)
    for n in (4, 5, 9, 30):
        for fixed in (True, False):
            kicked = double_bridge(np.arange(n), rng, fixed_start=fixed)
            assert is_permutation(kicked, n) and (not fixed or kicked[0] == 0)
    assert double_bridge(np.arange(3), rng).tolist() == [0, 1, 2]


# ------------------------------------------------------------------- solvers reach the optimum
SMALL = [(euclidean, 9, 0, 0), (euclidean, 8, 1, None), (random_symmetric, 9, 2, 4),
         (random_symmetric, 8, 3, None), (euclidean, 7, 4, 6)]


@pytest.mark.parametrize("gen,n,seed,start", SMALL)
def test_solvers_reach_the_exact_optimum_on_small_instances(gen, n, seed, start):
    cost = gen(n, seed)
    inst = instance(cost, start)
    best = brute_optimum(cost, start)
    local, info = solve_local(inst, restarts=30, seed=seed)
    assert inst.check_order(local) is not None
    assert inst.path_cost(local) == pytest.approx(best, abs=1e-9)
    assert info["restarts"] == 30 and info["local_optimum_cost"] >= inst.path_cost(local) - TOL
    memetic, info = solve_ga(inst, seed=seed, patience=30)
    assert inst.path_cost(inst.check_order(memetic)) == pytest.approx(best, abs=1e-9)
    assert info["memetic"] is True and info["generations"] >= 1
    plain, info = solve_ga(inst, seed=seed, memetic=False, patience=30)
    assert inst.path_cost(inst.check_order(plain)) >= best - TOL
    assert info["memetic"] is False
    assert info["evaluations"] >= 60 and 0 <= info["best_generation"] <= info["generations"]


def test_plain_ga_finds_the_optimum_of_a_tiny_instance_and_reports_its_stop():
    cost = euclidean(6, 8)
    inst = instance(cost, 2)
    order, info = solve_ga(inst, memetic=False, seed=3, patience=100)
    assert inst.path_cost(order) == pytest.approx(brute_optimum(cost, 2))
    assert info["stopped"] == "patience"
    _, info = solve_ga(inst, memetic=False, max_gen=5, patience=None)
    assert info["generations"] == 5 and info["stopped"] == "max_gen"


def test_trivial_instances():
    assert solve_ga(instance(np.zeros((1, 1)), 0))[0].tolist() == [0]
    assert solve_ga(instance(euclidean(2, 0), 1))[0].tolist() == [1, 0]
    assert solve_local(instance(euclidean(2, 0), None))[0].tolist() in ([0, 1], [1, 0])
    order, _ = solve_ga(instance(euclidean(3, 0), None), patience=5)
    assert is_permutation(order, 3)


def test_ga_options_are_checked_and_named():
    inst = instance(euclidean(6, 0))
    for option, value, word in [("pop_size", 1, "pop_size"), ("crossover_rate", 1.5, "crossover_rate"),
                                ("mutation_rate", -0.1, "mutation_rate"), ("elite", 61, "elite"),
                                ("tournament_size", 0, "tournament_size"), ("patience", 0, "patience"),
                                ("max_gen", -1, "max_gen"), ("local_search_rate", 2, "local_search_rate"),
                                ("seed", 1.5, "seed"), ("time_limit", 0, "time_limit")]:
        with pytest.raises(ParameterError, match=word):
            solve_ga(inst, **{option: value})


def test_elitist_comma_variant_and_time_limit():
    cost = euclidean(12, 6)
    inst = instance(cost, 0)
    order, info = solve_ga(inst, memetic=False, elite=5, seed=1, max_gen=300)
    assert is_permutation(order, 12) and order[0] == 0
    order, info = solve_ga(inst, memetic=False, max_gen=10**9, patience=None, time_limit=0.3)
    assert info["stopped"] == "time_limit" and is_permutation(order, 12)


# ------------------------------------------------------------- determinism and global states
def test_same_seed_same_order_and_global_random_states_untouched():
    cost = euclidean(14, 9)
    inst = instance(cost, None)
    random.seed(12345)
    np.random.seed(54321)
    py_state, np_state = random.getstate(), np.random.get_state()
    creator_names = set(vars(creator))
    runs = {}
    for key, run in [("ga", lambda s: solve_ga(inst, seed=s, patience=20)),
                     ("plain", lambda s: solve_ga(inst, seed=s, memetic=False, patience=40)),
                     ("local", lambda s: solve_local(inst, seed=s, restarts=15))]:
        runs[key] = [run(s)[0].tolist() for s in (7, 7, 8)]
        assert runs[key][0] == runs[key][1]
    assert random.getstate() == py_state
    after = np.random.get_state()
    assert after[0] == np_state[0] and np.array_equal(after[1], np_state[1]) and after[2:] == np_state[2:]
    assert set(vars(creator)) == creator_names  # deap.creator is never used


# ---------------------------------------------------------------------------------- dispatcher
def test_dispatcher_runs_ga_ga_plain_and_local():
    text = "\n".join(f"{i}a {i}b {i}c {i}d" for i in range(1, 8))
    inst = SequencingInstance.from_tileset(parse_tileset(text), start=3)
    results = {name: sequence_waypoints(inst, name, seed=1, patience=20) if name != "local"
               else sequence_waypoints(inst, name, seed=1, restarts=5)
               for name in ("ga", "ga-plain", "local")}
    for result in results.values():
        assert result.tiles[0] == 3 and sorted(result.tiles) == list(range(1, 8))
        assert result.cost == pytest.approx(inst.path_cost(result.order))
    best = brute_optimum(inst.cost, inst.start)
    assert results["ga"].cost == pytest.approx(best) and results["local"].cost == pytest.approx(best)
    assert results["ga"].info["memetic"] is True and results["ga-plain"].info["memetic"] is False
    assert sequence_waypoints(inst, "ga", time_limit=5, patience=5).solver == "ga"
