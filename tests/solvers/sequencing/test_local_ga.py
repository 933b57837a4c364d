"""Local search and the DEAP GA for the waypoint order: invariants, local optimality by brute force,
exact optima on small instances, determinism and untouched global random states."""

import itertools
import random
from itertools import pairwise

import numpy as np
import pytest
from deap import creator
from hypothesis import given, settings
from hypothesis import strategies as st

from htetro_opt.errors import ParameterError
from htetro_opt.problems.waypoint_sequencing import SequencingInstance
from htetro_opt.scenarios import parse_tileset
from htetro_opt.solvers.sequencing import (
    double_bridge,
    improve,
    improve_batch,
    make_toolbox,
    nearest_neighbour,
    or_opt,
    sequence_waypoints,
    solve_ga,
    solve_local,
    two_opt,
)

TOL = 1e-9
PAPER = {"additions": (), "mutation_rate": 1.0}  # ga-plain's defaults: Le et al. 2018's Algorithm 2 as published


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


def path_cost(cost, order):
    """Summed legs of an open path, one by one (independent of the library's vectorised sum)."""
    return sum(float(cost[a][b]) for a, b in pairwise(np.asarray(order).tolist()))


def naive_nearest_neighbour(cost, start):
    """Always on to the cheapest unvisited waypoint, ties to the lowest index (a plain loop)."""
    order, left = [start], set(range(len(cost))) - {start}
    while left:
        order.append(min(left, key=lambda j: (cost[order[-1]][j], j)))
        left.remove(order[-1])
    return order


def eq2_cost(tileset, tiles):
    """Eq. 2 at equal weights summed along an order of tile labels, block by block (by hand)."""
    blocks = {t: np.asarray(b, dtype=float) for t, b in zip(tileset.ids, tileset.blocks)}
    return sum(0.25 * float(np.hypot(*(blocks[a][k] - blocks[b][k]))) for a, b in pairwise(tiles) for k in range(4))


def brute_optimum(cost, start):
    """The cheapest open path by enumeration (n ≤ 9)."""
    n = len(cost)
    rest = [i for i in range(n) if i != start]
    perms = np.array(list(itertools.permutations(rest)), dtype=np.int64)
    if start is not None:
        perms = np.hstack([np.full((len(perms), 1), start), perms])
    C = np.asarray(cost)
    return float(C[perms[:, :-1], perms[:, 1:]].sum(1).min())


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


def improving_segment_move(cost, order, fixed, lengths=(1, 2, 3), elsewhere=False):
    """Some move of a segment (as is or reversed) elsewhere that is cheaper, or None. ``elsewhere``:
    not back where it was (reversed in place it is a 2-opt move, which Or-opt of other lengths than
    1–3 does not make)."""
    order = list(np.asarray(order).tolist())
    base = path_cost(cost, order)
    lo = 1 if fixed else 0
    for L in lengths:
        for i in range(lo, len(order) - L + 1):
            seg, rest = order[i:i + L], order[:i] + order[i + L:]
            for k in range(lo, len(rest) + 1):
                if elsewhere and k == i:
                    continue
                for s in (seg, seg[::-1]):
                    if path_cost(cost, rest[:k] + s + rest[k:]) < base - TOL:
                        return i, L, k
    return None


CASES = [(gen, n, seed, fixed) for gen in (euclidean, random_symmetric) for n in (2, 3, 5, 8, 11)
         for seed in (0, 1) for fixed in (True, False)]


# --------------------------------------------------------- the GA's toolbox (operators: tests/operators)
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
    assert np.allclose([t.fitness.values[0] for t in pop], [path_cost(euclidean(n, seed), o) for o in orders])
    assert tb.evaluate(pop) == 0  # valid fitnesses are not priced again


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


@pytest.mark.parametrize("lengths", [(3,), (2, 4)])
@pytest.mark.parametrize("n", [3, 4, 5, 7, 9, 11])
def test_or_opt_of_other_segment_lengths_reaches_its_local_optimum(n, lengths):
    # without lengths 1 and 2 no other move stands in for a segment moved just before its
    # neighbour's neighbour, or (in a path of the segment and two more waypoints) to the far end
    for gen, seed, fixed in itertools.product((euclidean, random_symmetric), range(4), (True, False)):
        cost = gen(n, seed)
        start = np.random.default_rng(seed + 7).permutation(n)
        out = or_opt(cost, start, fixed_start=fixed, segment_lengths=lengths)
        assert is_permutation(out, n) and path_cost(cost, out) <= path_cost(cost, start) + TOL
        assert not fixed or out[0] == start[0]
        assert improving_segment_move(cost, out, fixed, lengths, elsewhere=True) is None, (gen.__name__, seed, fixed)


@pytest.mark.parametrize("fixed", [True, False])
def test_neighbour_list_moves_are_certified_on_a_larger_instance(fixed):
    # 120 waypoints: the neighbour-list search does most of the work, the full passes certify
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
    assert is_permutation(order, 40) and (not fixed or order[0] == 5)
    assert info["initial_cost"] == pytest.approx(path_cost(cost, nearest_neighbour(cost, start=inst.start)))
    assert path_cost(cost, order) <= info["local_optimum_cost"] + TOL <= info["initial_cost"] + TOL
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
    assert path_cost(cost, free) == pytest.approx(min(path_cost(cost, naive_nearest_neighbour(cost, s))
                                                      for s in range(12)))


def test_importing_the_local_search_does_not_import_numba():
    # the exact solver and the greedy baseline import the module for the construction; numba (about
    # half a second) is imported when a search first runs
    import subprocess
    import sys

    code = ("import sys, htetro_opt.solvers.sequencing as s; s.improve, s.solve_local, s.nearest_neighbour; "
            "before = 'numba' in sys.modules; s.improve([[0, 1, 2], [1, 0, 1], [2, 1, 0]], [0, 2, 1]); "
            "print(before, 'numba' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.split() == ["False", "True"]


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
    assert path_cost(cost, inst.check_order(local)) == pytest.approx(best, abs=1e-9)
    assert info["restarts"] == 30 and info["local_optimum_cost"] >= path_cost(cost, local) - TOL
    memetic, info = solve_ga(inst, seed=seed, patience=30)
    assert path_cost(cost, inst.check_order(memetic)) == pytest.approx(best, abs=1e-9)
    assert info["additions"] == ["crossover", "distinct", "memetic"] and info["generations"] >= 1
    # the paper's GA (swaps only, copies kept) may stall above these optima after 30 stale generations
    plain, info = solve_ga(inst, seed=seed, **PAPER, patience=30)
    assert path_cost(cost, inst.check_order(plain)) >= best - TOL
    assert info["additions"] == []
    assert info["evaluations"] >= 60 and 0 <= info["best_generation"] <= info["generations"]


def test_plain_ga_finds_the_optimum_of_a_tiny_instance_and_reports_its_stop():
    cost = euclidean(6, 8)
    inst = instance(cost, 2)
    order, info = solve_ga(inst, **PAPER, seed=3, patience=100)
    assert path_cost(cost, order) == pytest.approx(brute_optimum(cost, 2))
    assert info["stopped"] == "patience"
    _, info = solve_ga(inst, **PAPER, max_gen=5, patience=None)
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
    order, info = solve_ga(inst, **PAPER, elite=5, seed=1, max_gen=300)
    assert is_permutation(order, 12) and order[0] == 0
    order, info = solve_ga(inst, **PAPER, max_gen=10**9, patience=None, time_limit=0.3)
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
                     ("plain", lambda s: solve_ga(inst, seed=s, **PAPER, patience=40)),
                     ("local", lambda s: solve_local(inst, seed=s, restarts=15))]:
        runs[key] = [run(s)[0].tolist() for s in (7, 7, 8)]
        assert runs[key][0] == runs[key][1]
    assert random.getstate() == py_state
    after = np.random.get_state()
    assert after[0] == np_state[0] and np.array_equal(after[1], np_state[1]) and after[2:] == np_state[2:]
    assert set(vars(creator)) == creator_names  # deap.creator is never used


# ---------------------------------------------------------------------------------- dispatcher
def test_dispatcher_runs_ga_ga_plain_and_local():
    # seven horizontal I tiles stacked: tile i to tile j costs |i − j|; from tile 3 an optimum goes
    # up to tile 1 and then down to tile 7 (2 + 6 = 8; 3 1 2 4 … ties with it)
    ts = parse_tileset("\n".join(f"{i}a {i}b {i}c {i}d" for i in range(1, 8)))
    inst = SequencingInstance.from_tileset(ts, start=3)
    results = {name: sequence_waypoints(inst, method=name, seed=1, patience=20) if name != "local"
               else sequence_waypoints(inst, method=name, seed=1, restarts=5)
               for name in ("ga", "ga-plain", "local")}
    for name, result in results.items():
        assert result.method == name and result.as_dict()["method"] == name
        assert result.tiles[0] == 3 and sorted(result.tiles) == list(range(1, 8))
        assert result.cost == pytest.approx(eq2_cost(ts, result.tiles))
    assert results["ga"].cost == pytest.approx(8.0) and results["local"].cost == pytest.approx(8.0)
    assert results["ga"].additions == ("crossover", "distinct", "memetic") and results["ga-plain"].additions == ()
    assert sequence_waypoints(inst, method="ga", time_limit=5, patience=5).method == "ga"


def test_memetic_ga_keeps_its_time_budget_on_300_waypoints():
    # the time limit is the feature: the run's length in CPU time (a busy machine does not stretch it)
    from time import process_time

    warm = instance(euclidean(20, 0), 0)
    solve_ga(warm, seed=0, max_gen=1)  # compiles the local search, once per install (numba's cache)
    inst = instance(euclidean(300, 4), 0)
    began = process_time()
    order, info = solve_ga(inst, seed=0, time_limit=2.0, patience=None, max_gen=10**6)
    spent = process_time() - began
    assert is_permutation(order, 300) and order[0] == 0
    assert info["stopped"] == "time_limit" and spent < 2.0 + 1.5
    assert info["generations"] > 1


# ------------------------------------------------------------------ ga-plain is Algorithm 2 as published
def _spy(monkeypatch, name):
    """Count the calls of the GA module's ``name`` (an operator or helper), still running it."""
    from htetro_opt.solvers.sequencing import _ga

    calls = []
    real = getattr(_ga, name)

    def spy(*args, **kwargs):
        calls.append(1)
        return real(*args, **kwargs)

    monkeypatch.setattr(_ga, name, spy)
    return calls


def test_ga_plain_never_crosses_and_swaps_every_child(monkeypatch):
    inst = SequencingInstance.from_tileset(parse_tileset("\n".join(f"{i}a {i}b {i}c {i}d" for i in range(1, 13))),
                                           start=1)
    crossed, swapped = _spy(monkeypatch, "order_crossover"), _spy(monkeypatch, "swap_mutation")
    distinct = _spy(monkeypatch, "_distinct")
    result = sequence_waypoints(inst, method="ga-plain", seed=2, max_gen=7, patience=None)
    assert result.info["generations"] == 7 and result.additions == ()
    assert not crossed and not distinct  # "crossover is not included"; copies compete like any order
    assert len(swapped) == 7 * 60  # each of the 60 children of each generation gets the paper's swap
    ours = sequence_waypoints(inst, method="ga", seed=2, max_gen=7, patience=None)
    assert crossed and distinct and ours.additions == ("crossover", "distinct", "memetic")


@pytest.mark.parametrize("addition", ["crossover", "distinct", "memetic"])
def test_each_ga_addition_switches_alone(monkeypatch, addition):
    inst = instance(euclidean(15, 4), 0)
    operator = {"crossover": "order_crossover", "distinct": "_distinct", "memetic": "LocalCore"}[addition]
    calls = _spy(monkeypatch, operator)
    result = sequence_waypoints(inst, method="ga-plain", additions=[addition], seed=0, max_gen=3, patience=None)
    assert result.additions == (addition,) and calls
    assert sequence_waypoints(inst, method="ga-plain", additions=[addition], seed=0, max_gen=3,
                              patience=None).order.tolist() == result.order.tolist()  # seeded: the same again


def test_a_rate_for_an_addition_that_is_off_is_refused():
    inst = instance(euclidean(6, 0))
    with pytest.raises(ParameterError, match="crossover_rate sets the crossover addition, which is off in ga-plain"):
        sequence_waypoints(inst, method="ga-plain", crossover_rate=0.5)
    with pytest.raises(ParameterError, match="local_search_rate sets the memetic addition"):
        sequence_waypoints(inst, method="ga", additions=["crossover"], local_search_rate=0.5)
