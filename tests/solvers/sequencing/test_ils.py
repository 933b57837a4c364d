"""The compiled iterated local search (``ils``): valid orders, reproducible by seed, never below a proven
optimum, at the optimum on small instances, and better than plain ``local`` (nearest neighbour and the
same local search, without kicks) on larger ones."""

import itertools

import numpy as np
import pytest

from htetro_opt.errors import ParameterError
from htetro_opt.problems import SequencingInstance
from htetro_opt.solvers.sequencing import (
    auto_method,
    held_karp,
    ils_kicks,
    sequence_waypoints,
)


def euclidean(n, seed):
    xy = np.random.default_rng(seed).random((n, 2)) * 100
    return np.sqrt(((xy[:, None] - xy[None]) ** 2).sum(-1))


def brute_force(C, closed, start, end):
    """Independent oracle for ≤ 8 waypoints: every permutation."""
    from itertools import permutations

    n = len(C)
    best = np.inf
    for p in permutations(range(n)):
        if (start is not None and p[0] != start) or (end is not None and p[-1] != end):
            continue
        cost = sum(C[a, b] for a, b in itertools.pairwise(p)) + (C[p[-1], p[0]] if closed else 0.0)
        best = min(best, cost)
    return best


@pytest.mark.parametrize("closed, start, end", [(False, 0, None), (False, None, None), (False, 2, 5),
                                                (False, None, 4), (True, 0, None), (True, None, None)])
def test_small_instances_reach_the_optimum(closed, start, end):
    for seed in range(6):
        C = euclidean(8, seed)
        inst = SequencingInstance.from_matrix(C, closed=closed, start=start, end=end)
        result = sequence_waypoints(inst, method="ils", seed=seed)
        order = result.order.tolist()
        assert sorted(order) == list(range(8))
        priced = sum(C[a, b] for a, b in itertools.pairwise(order)) + (C[order[-1], order[0]] if closed else 0.0)
        assert result.cost == pytest.approx(priced)
        assert result.cost == pytest.approx(brute_force(C, closed, start, end), rel=1e-9)


def test_never_below_the_held_karp_optimum_over_seeds():
    for seed in range(10):
        C = euclidean(14, 100 + seed)
        inst = SequencingInstance.from_matrix(C, start=0)
        optimum = held_karp(C, start=0)[1]
        result = sequence_waypoints(inst, method="ils", seed=seed)
        assert result.cost >= optimum - 1e-9
        assert result.cost == pytest.approx(optimum, rel=1e-9)


def test_same_seed_same_order_and_the_budget_is_kicks():
    C = euclidean(300, 3)
    inst = SequencingInstance.from_matrix(C, closed=True)
    a = sequence_waypoints(inst, method="ils", seed=5, kicks=20_000)
    b = sequence_waypoints(inst, method="ils", seed=5, kicks=20_000)
    c = sequence_waypoints(inst, method="ils", seed=6, kicks=20_000)
    assert np.array_equal(a.order, b.order) and a.info["kicks"] == 20_000 and not a.info["timed_out"]
    # another seed, another walk (with the alpha lists both walks end at the same tour here)
    assert (a.info["improving_kicks"], a.order.tolist()) != (c.info["improving_kicks"], c.order.tolist())
    assert ils_kicks(300) > 20_000


def test_better_than_plain_local_search():
    C = euclidean(400, 9)
    inst = SequencingInstance.from_matrix(C, start=0)
    ils = sequence_waypoints(inst, method="ils", seed=0, kicks=40_000)
    local = sequence_waypoints(inst, method="local", seed=0)
    assert ils.cost < 0.98 * local.cost


def test_time_cap_is_reported():
    inst = SequencingInstance.from_matrix(euclidean(2000, 1), closed=True)
    result = sequence_waypoints(inst, method="ils", time_limit=0.05)
    assert result.info["timed_out"] and result.info["kicks"] < ils_kicks(2001)
    assert sorted(result.order.tolist()) == list(range(2000))


def test_auto_runs_ils_beyond_the_exact_range_and_refuses_nothing_it_should_not():
    inst = SequencingInstance.from_matrix(euclidean(60, 2), start=0)
    assert auto_method(inst) == "ils"
    assert sequence_waypoints(inst, kicks=1000).method == "auto (ils)"
    asymmetric = euclidean(10, 1) + np.triu(np.ones((10, 10)))
    with pytest.raises(ParameterError, match="symmetric"):
        sequence_waypoints(SequencingInstance.from_matrix(asymmetric), method="ils")
    for bad in (-1, 1.5):
        with pytest.raises(ParameterError, match="kicks"):
            sequence_waypoints(inst, method="ils", kicks=bad)


@pytest.mark.parametrize("n", [1, 2, 3, 4, 5])
def test_tiny_instances(n):
    C = euclidean(n, 0)
    for closed, start in ((False, 0), (False, None), (True, None)):
        result = sequence_waypoints(SequencingInstance.from_matrix(C, closed=closed, start=start), method="ils")
        assert sorted(result.order.tolist()) == list(range(n))


# ------------------------------------------------------- implicit eq.-2 costs (memory linear in n)
def _blocks(n, seed):
    """Random tiles' block cells: four cells near one random centre each."""
    rng = np.random.default_rng(seed)
    return rng.integers(0, 120, size=(n, 1, 2)) + rng.integers(0, 3, size=(n, 4, 2))


def _eq2_price(blocks, order, closed):
    """The order's eq.-2 cost by a loop of our own (weights 0.25)."""
    legs = list(itertools.pairwise(order)) + ([(order[-1], order[0])] if closed else [])
    return sum(0.25 * sum(float(np.hypot(*(blocks[a, k] - blocks[b, k]))) for k in range(4)) for a, b in legs)


@pytest.mark.parametrize("closed, start, end", [(False, 0, None), (False, None, None), (False, 3, 7), (True, 5, None)])
def test_implicit_instances_give_valid_orders_priced_like_a_loop(closed, start, end):
    blocks = _blocks(150, 1)
    inst = SequencingInstance(None, blocks, start, closed=closed, end=end)
    assert auto_method(inst) == "ils"
    result = sequence_waypoints(inst, seed=2, kicks=5000)
    order = result.order.tolist()
    assert result.method == "auto (ils)" and result.info["costs"].startswith("implicit")
    assert sorted(order) == list(range(150))
    assert start is None or order[0] == start
    assert end is None or order[-1] == end
    assert result.cost == pytest.approx(_eq2_price(blocks, order, closed))


def test_implicit_search_is_as_good_as_the_dense_one():
    from htetro_opt.problems import cost_matrix

    gaps = []
    for seed in range(3):
        blocks = _blocks(200, 10 + seed)
        dense = sequence_waypoints(SequencingInstance(cost_matrix(blocks), blocks, 0), method="ils", seed=seed,
                                   kicks=8000)
        implicit = sequence_waypoints(SequencingInstance(None, blocks, 0), method="ils", seed=seed, kicks=8000)
        gaps.append(implicit.cost / dense.cost - 1)
    assert np.mean(gaps) < 0.01 and max(gaps) < 0.02  # the same search; a different start and list ties


def test_methods_needing_the_matrix_refuse_an_implicit_instance():
    inst = SequencingInstance(None, _blocks(50, 0), 0)
    for method in ("exact", "ortools", "local", "ga", "greedy", "zigzag"):
        with pytest.raises(ParameterError, match="implicit"):
            sequence_waypoints(inst, method=method)


@pytest.mark.slow
def test_a_free_256_map_tiles_and_sequences_in_linear_memory():
    """Issue 16, item 3: 16 384 waypoints in a fresh process, peak memory well under the 4 GB target
    (the dense matrix alone would take 2.1 GB, its construction 17 GB)."""
    import subprocess
    import sys

    code = (
        "import resource, numpy as np\n"
        "from htetro_opt.model.workspace import Workspace\n"
        "from htetro_opt.problems import SequencingInstance\n"
        "from htetro_opt.solvers.sequencing import sequence_waypoints\n"
        "from htetro_opt.solvers.tiling import tile_workspace\n"
        "ts = tile_workspace(Workspace(np.zeros((256, 256), dtype=bool))).tileset\n"
        "inst = SequencingInstance.from_tileset(ts, start=1)\n"
        "r = sequence_waypoints(inst, seed=0)\n"
        "b = ts.blocks.astype(float)\n"
        "o = r.order\n"
        "cost = float((np.sqrt(((b[o[:-1]] - b[o[1:]]) ** 2).sum(-1)) * 0.25).sum())\n"
        "print(inst.implicit, sorted(o.tolist()) == list(range(inst.n)), abs(cost - r.cost) < 1e-6 * cost,\n"
        "      resource.getrusage(resource.RUSAGE_SELF).ru_maxrss // 1024)\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.split()
    assert out[:3] == ["True", "True", "True"]
    assert int(out[3]) < 1500  # MB; 317 MB measured (benchmarks/README.md)


def _move_case(n, instance_seed, tour_seed, tours):
    """A Euclidean instance for the compiled moves' tests: its matrix, neighbour lists and their costs, a
    plain re-pricing loop (the oracle), and ``tours`` random tours, each with its positions and an empty log,
    drawn one at a time (a test changes each tour before the next is drawn)."""
    from htetro_opt.solvers.sequencing import _ils

    C = euclidean(n, instance_seed)
    nbr = _ils._neighbour_lists(C, 8)
    rng = np.random.default_rng(tour_seed)

    def loop_cost(tour):
        return sum(C[tour[i], tour[(i + 1) % n]] for i in range(n))

    def random_tours():
        for _ in range(tours):
            tour = rng.permutation(n).astype(np.int64)
            pos = np.empty(n, dtype=np.int64)
            pos[tour] = np.arange(n)
            yield tour, pos, np.empty((4 * n + 64, 4), dtype=np.int64)

    return C, nbr, _ils._neighbour_costs(C, nbr), loop_cost, random_tours()


def test_the_lk_move_gains_what_a_repricing_loop_says_and_keeps_a_tour():
    """The LK-style move (2-opt and sequential 3-opt priced without flips, deeper chains flipped and
    undone): on random tours of a Euclidean instance, the gain it reports is the fall of the tour's cost
    re-priced by a plain loop, the tour stays a permutation with consistent positions, and it makes
    3-opt moves (two flips) and deeper ones, not only 2-opt."""
    from htetro_opt.solvers.sequencing import _ils

    n = 80
    C, nbr, nc, loop_cost, tours = _move_case(n, 21, 0, 20)
    flips = set()
    for tour, pos, log in tours:
        touched = np.empty(14, dtype=np.int64)
        added = np.empty((6, 2), dtype=np.int64)
        for t1 in range(n):
            for back in (0, 1):
                before = loop_cost(tour)
                gain, count, _ = _ils._lk_move(C, nbr, nc, tour, pos, log, 0, t1, back, 6, 1e-9, touched, added)
                assert sorted(tour.tolist()) == list(range(n)) and np.array_equal(pos[tour], np.arange(n))
                assert before - loop_cost(tour) == pytest.approx(gain, abs=1e-9)
                if gain > 0:
                    flips.add(int(count))
    assert {1, 2} <= flips and max(flips) >= 3


def test_the_lk_move_reaches_the_optimum_and_repeats_by_seed():
    """``ils`` with ``lk_depth=2`` (off by default): on 10-node closed tours it ends at the optimum of every
    tour through node 0 (enumerated; never below it), the same seed gives the same tour, and the option is
    the one that reaches the kernel (a deeper move takes another walk than the 2-opt one on 300 nodes)."""
    n = 10
    for seed in range(3):
        C = euclidean(n, 300 + seed)
        optimum = min(sum(C[a, b] for a, b in itertools.pairwise((0, *p, 0)))
                      for p in itertools.permutations(range(1, n)) if p[0] < p[-1])
        inst = SequencingInstance.from_matrix(C, closed=True)
        a, b = (sequence_waypoints(inst, method="ils", seed=seed, kicks=300, lk_depth=2) for _ in range(2))
        assert np.array_equal(a.order, b.order) and sorted(a.order.tolist()) == list(range(n))
        cost = sum(C[a.order[i], a.order[(i + 1) % n]] for i in range(n))
        assert cost == pytest.approx(optimum, rel=1e-9)
    inst = SequencingInstance.from_matrix(euclidean(300, 3), closed=True)
    plain, deep = (sequence_waypoints(inst, method="ils", seed=5, kicks=2_000, lk_depth=d) for d in (0, 2))
    assert not np.array_equal(plain.order, deep.order)


def test_the_segment_exchange_gains_what_a_repricing_loop_says_and_undoes_exactly():
    """The or-3opt move (:func:`_or3_move`, ``or3opt``): on random tours of a Euclidean instance its gain is
    the fall of the tour's cost re-priced by a plain loop, the tour stays a permutation with consistent
    positions, both closings occur (the halves swapped, three flips; reversed in place, two), and the
    logged flips undone in reverse order give back the tour's cost before the move."""
    from htetro_opt.solvers.sequencing import _ils

    n = 90
    C, nbr, nc, loop_cost, tours = _move_case(n, 22, 1, 12)
    flips = set()
    for tour, pos, log in tours:
        touched = np.empty(8, dtype=np.int64)
        for t1 in range(n):
            for back in (0, 1):
                before = loop_cost(tour)
                gain, count, nt = _ils._or3_move(C, nbr, nc, tour, pos, log, 0, t1, back, 1e-9, touched)
                assert sorted(tour.tolist()) == list(range(n)) and np.array_equal(pos[tour], np.arange(n))
                after = loop_cost(tour)
                assert before - after == pytest.approx(gain, abs=1e-9) and gain >= 0
                if gain > 0:
                    flips.add(int(count))
                    assert nt == 6 and t1 in touched[:nt]
                    undone = tour.copy()
                    back_pos = pos.copy()
                    for m in range(count - 1, -1, -1):
                        a, b, c, d = log[m]
                        _ils._two_opt(undone, back_pos, a, c, b, d)
                    assert loop_cost(undone) == pytest.approx(before, abs=1e-9)
    assert flips == {2, 3}


@pytest.mark.parametrize("options", [{"or3opt": True}, {"accept_worse": 0.2}, {"kick_span": 10},
                                     {"or3opt": True, "lk_depth": 2, "kick_span": 7}, {"candidates": "nearest"}])
def test_the_search_options_keep_a_valid_tour_priced_right_and_repeat_by_seed(options):
    """``or3opt``, ``accept_worse``, ``kick_span`` and ``candidates`` (off or at their defaults in ``ILS_*``):
    the same seed gives the same tour when the kicks complete, the reported cost is the re-priced tour's, no tour is
    below the proven optimum of berlin52 (7542, TSPLIB) and each option reaches the kernel (another walk
    than the default's on 300 nodes)."""
    from pathlib import Path

    from htetro_opt.scenarios.tsplib import load_tsplib

    tsp = load_tsplib(Path(__file__).resolve().parents[3] / "benchmarks" / "data" / "tsplib" / "berlin52.tsp")
    inst = SequencingInstance.from_matrix(tsp.cost, closed=True, start=0)
    # (a generous cap: the first call may compile the kernel, which counts against the limit)
    a, b = (sequence_waypoints(inst, method="ils", seed=3, kicks=3_000, time_limit=600, **options) for _ in range(2))
    assert np.array_equal(a.order, b.order) and not a.info["timed_out"] and a.info["kicks"] == 3_000
    order = a.order.tolist()
    assert sorted(order) == list(range(52))
    priced = sum(tsp.cost[order[i], order[(i + 1) % 52]] for i in range(52))
    assert a.cost == pytest.approx(priced, rel=1e-12) and priced >= 7542 - 1e-9
    assert priced <= 1.03 * 7542
    big = SequencingInstance.from_matrix(euclidean(300, 3), closed=True)
    plain, other = (sequence_waypoints(big, method="ils", seed=5, kicks=2_000, **o) for o in ({}, options))
    assert not np.array_equal(plain.order, other.order)


def test_an_explicit_time_limit_sets_a_kick_budget_that_repeats_when_it_completes():
    """``kick_rate``: with an explicit ``time_limit`` and no ``kicks`` the budget is max(ils_kicks(n),
    kick_rate · time_limit), a number, so the same seed gives the same tour when it completes; without a
    limit (or at rate 0) it stays ils_kicks(n)."""
    inst = SequencingInstance.from_matrix(euclidean(60, 4), closed=True)
    runs = [sequence_waypoints(inst, method="ils", seed=2, time_limit=600, kick_rate=100) for _ in range(2)]
    assert all(r.info["kicks"] == 60_000 and not r.info["timed_out"] for r in runs)
    assert np.array_equal(runs[0].order, runs[1].order)
    assert sequence_waypoints(inst, method="ils", seed=2, kick_rate=100).info["kicks"] == ils_kicks(60)
    assert sequence_waypoints(inst, method="ils", seed=2, time_limit=600, kick_rate=0).info["kicks"] == ils_kicks(60)
    assert sequence_waypoints(inst, method="ils", seed=2, time_limit=1, kick_rate=10).info["kicks"] == ils_kicks(60)


@pytest.mark.parametrize("bad", [{"kick_rate": -1.0}, {"accept_worse": -0.5}, {"kick_span": 0}, {"or3opt": "yes"},
                                 {"candidates": "quadrant"}])
def test_bad_search_options_are_refused_before_work(bad):
    inst = SequencingInstance.from_matrix(euclidean(30, 1), closed=True)
    with pytest.raises(ParameterError, match=next(iter(bad))):
        sequence_waypoints(inst, method="ils", **bad)


def test_alpha_lists_match_a_spanning_tree_oracle():
    """``candidates="alpha"``'s lists (Helsgaun 2000, section 4.2), for any penalties: each node's k others
    of least alpha (the leg under the penalties less the dearest leg on the minimum spanning tree's path
    between its ends), ordered by cost. The oracle: scipy's minimum spanning tree of the penalised matrix
    and each tree path walked in Python."""
    from scipy.sparse.csgraph import minimum_spanning_tree

    from htetro_opt.solvers.sequencing._ils import _alpha_lists, _dense_tree

    m, k = 40, 6
    C = euclidean(m, 11)
    pi = np.random.default_rng(12).normal(0.0, 3.0, m)
    P = C + pi[:, None] + pi[None, :]
    parent = _dense_tree(C, m, np.full(m, -1), pi)
    tree = minimum_spanning_tree(P - P.min() + 1.0).toarray()  # (a constant shift keeps every leg positive)
    ours = {frozenset((v, int(parent[v]))) for v in range(m) if parent[v] >= 0}
    assert ours == {frozenset(e) for e in zip(*np.nonzero(tree))}
    adjacent = {v: set() for v in range(m)}
    for a, b in ours:
        adjacent[a].add(b)
        adjacent[b].add(a)
    lists = _alpha_lists(C, pi, parent, k)
    for i in range(m):
        dearest = {i: -np.inf}  # the dearest penalised leg on the tree path from i, by a walk from i
        stack = [i]
        while stack:
            v = stack.pop()
            for u in adjacent[v] - dearest.keys():
                dearest[u] = max(dearest[v], P[v, u])
                stack.append(u)
        alpha = {j: P[i, j] - dearest[j] for j in range(m) if j != i}
        assert all(alpha[j] == pytest.approx(0.0, abs=1e-9) for j in adjacent[i])
        assert min(alpha.values()) >= -1e-9
        chosen = sorted(alpha, key=lambda j: (alpha[j], P[i, j]))[:k]
        assert lists[i].tolist() == sorted(chosen, key=lambda j: (C[i, j], j))


def test_the_ascent_raises_the_one_tree_bound_and_never_past_the_optimum():
    """The subgradient ascent behind the alpha lists, on the complete graph of 13 nodes: its penalised
    1-tree length is a Held-Karp lower bound, so it never exceeds the proven optimum (``held_karp``), and
    it rises above the plain 1-tree's."""
    from htetro_opt.solvers.sequencing._ils import _ascent

    m = 13
    C = euclidean(m, 21)
    # the closed tour's optimum: the best open path from 0 to a copy of 0 that nothing leaves cheaply
    open_path = np.full((m + 1, m + 1), 1e6)
    open_path[:m, :m], open_path[:m, m] = C, C[:, 0]
    optimum = held_karp(open_path, start=0)[1]
    rows, cols = np.nonzero(~np.eye(m, dtype=bool))
    ptr = np.arange(0, m * (m - 1) + 1, m - 1)
    upper = C[np.arange(m), np.roll(np.arange(m), -1)].sum()  # a tour's length, for the step
    plain = _ascent(ptr, cols, C[rows, cols], upper, 1)[1]
    pi, bound, trees = _ascent(ptr, cols, C[rows, cols], upper, 500)
    assert 1 < trees <= 500 and pi.shape == (m,)
    assert plain < bound <= optimum + 1e-9


def test_the_default_lists_are_alpha_up_to_their_limit_and_nearest_beyond(monkeypatch):
    """``candidates="auto"``: alpha-nearness lists up to ``ILS_ALPHA_AUTO`` waypoints and within a tenth of the
    time limit, the nearest otherwise; ``"alpha"`` beyond ``ILS_ALPHA_LIMIT`` is refused before any work (both
    limits lowered to 59 here, so that 60 waypoints pass them)."""
    from htetro_opt.solvers.sequencing import _ils

    inst = SequencingInstance.from_matrix(euclidean(60, 7), closed=True)
    assert sequence_waypoints(inst, method="ils", kicks=10).info["candidates"] == "alpha"
    assert sequence_waypoints(inst, method="ils", kicks=10, candidates="nearest").info["candidates"] == "nearest"
    # a time limit whose tenth the estimate (60² pairs at ILS_ALPHA_PAIR_SECONDS) passes: the nearest lists
    tight = 60 ** 2 * _ils.ILS_ALPHA_PAIR_SECONDS * 10
    assert sequence_waypoints(inst, method="ils", kicks=10, time_limit=0.9 * tight).info["candidates"] == "nearest"
    assert sequence_waypoints(inst, method="ils", kicks=10, time_limit=1.1 * tight).info["candidates"] == "alpha"
    monkeypatch.setattr(_ils, "ILS_ALPHA_AUTO", 59)
    assert sequence_waypoints(inst, method="ils", kicks=10).info["candidates"] == "nearest"
    assert sequence_waypoints(inst, method="ils", kicks=10, candidates="alpha").info["candidates"] == "alpha"
    monkeypatch.setattr(_ils, "ILS_ALPHA_LIMIT", 59)
    with pytest.raises(ParameterError, match="candidates='alpha'.*at most 59 waypoints, got 60"):
        sequence_waypoints(inst, method="ils", candidates="alpha")


_BUILDS = """
import json
import numpy as np
from numba import types
from numba.core.registry import CPUDispatcher
from htetro_opt.problems import SequencingInstance
from htetro_opt.solvers.sequencing import _ils, sequence_waypoints
xy = np.random.default_rng(7).random((24, 2)) * 100
inst = SequencingInstance.from_matrix(np.sqrt(((xy[:, None] - xy[None]) ** 2).sum(-1)), closed=True, start=0)
for options in ({"candidates": "nearest"}, {"candidates": "alpha"}):
    sequence_waypoints(inst, method="ils", seed=0, kicks=50, **options)
sequence_waypoints(inst, method="local", seed=0)
print(json.dumps({name: [[str(t) for t in signature] for signature in k.signatures]
                  for name, k in vars(_ils).items() if isinstance(k, CPUDispatcher)}))
"""


def test_the_kernels_are_compiled_for_typed_arguments_only_one_build_a_cost_kind(tmp_path):
    """numba compiles a kernel once more for every literal constant it is passed (a bare ``0`` or ``True``
    from another kernel): the ILS, its moves, the alpha lists and ``local``'s descent all pass typed values,
    so that on dense matrix costs every kernel is built once and none for a literal. In a fresh process and
    a fresh numba cache: a kernel loaded from the cache lists only what its callers were loaded with."""
    import json
    import os
    import subprocess
    import sys

    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path)}
    run = subprocess.run([sys.executable, "-c", _BUILDS], capture_output=True, text=True, check=True, env=env,
                         timeout=600)
    builds = json.loads(run.stdout.strip().splitlines()[-1])
    assert {"_ils", "_local_search", "_lk_move", "_or3_move", "_or_move", "_descend", "_alpha_lists"} <= set(builds)
    for name, signatures in builds.items():
        assert not any("Literal" in t for signature in signatures for t in signature), (name, signatures)
        assert len(signatures) <= 1, (name, signatures)  # one cost kind here: one build each
    assert all(len(builds[name]) == 1 for name in ("_ils", "_local_search", "_lk_move", "_descend", "_alpha_lists"))
