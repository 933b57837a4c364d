"""Plain matrices, closed tours, fixed ends and the outside solvers (fast-tsp, LKH-3 via elkai).

Both packages are in the ``test`` extra, so these tests import them directly: a CI without them
fails here rather than skipping. Every order is re-priced by a loop of this file's own, and no
method may beat the exact solver's proved optimum (Held–Karp on the closed-tour reduction built by
hand as a second oracle).
"""

import sys

import elkai  # noqa: F401  (the test extra installs it: fail loudly if it is missing)
import fast_tsp  # noqa: F401
import numpy as np
import pytest

from htetro_opt.errors import ParameterError, PlanningError
from htetro_opt.problems.waypoint_sequencing import SequencingInstance, cost_matrix, reduce_to_open_path
from htetro_opt.scenarios import load_tileset, tileset_path
from htetro_opt.solvers.sequencing import (
    ASYMMETRIC_METHODS,
    SPEC,
    auto_method,
    held_karp,
    sequence_waypoints,
    solve_fast_tsp,
    solve_lkh,
    solve_zigzag,
)

# Methods that take a plain matrix, with options that keep each well under a second here.
MATRIX_METHODS = {"exact": {}, "ortools": {"solution_limit": 100}, "local": {"restarts": 5}, "ga": {"patience": 5},
                  "ga-plain": {"max_gen": 30}, "greedy": {"iterations": 30}, "fast-tsp": {"time_limit": 0.2},
                  "lkh": {}}


def options_of(method, seed=0):
    """A call's options: this file's budget, and the seed where the method takes one (the spec says which)."""
    return {**MATRIX_METHODS[method], **({"seed": seed} if SPEC.method(method).takes("seed") else {})}


def priced(cost, order, closed):
    """An order's cost by a plain loop over the matrix (the oracle of every test here)."""
    order = list(order)
    total = 0.0
    for a, b in zip(order, order[1:]):
        total += float(cost[a][b])
    if closed and len(order) > 1:
        total += float(cost[order[-1]][order[0]])
    return total


def euclidean(n, seed):
    xy = np.random.default_rng(seed).random((n, 2)) * 100
    return np.hypot(*(xy[:, None, :] - xy[None, :, :]).transpose(2, 0, 1))


def asymmetric(n, seed):
    rng = np.random.default_rng(seed)
    return euclidean(n, seed) + rng.random((n, n)) * 30


def assert_valid(instance, result):
    order = result.order.tolist()
    assert sorted(order) == list(range(instance.n))
    if instance.start is not None:
        assert order[0] == instance.start
    if instance.end is not None:
        assert order[-1] == instance.end
    assert result.cost == pytest.approx(priced(instance.cost, order, instance.closed), rel=1e-12, abs=1e-9)


# ------------------------------------------------------------------------------------ from_matrix
@pytest.mark.parametrize("method", list(MATRIX_METHODS))
@pytest.mark.parametrize("closed, start, end", [(True, None, None), (True, 3, None), (False, None, None),
                                                (False, 2, None), (False, None, 5), (False, 1, 7)])
def test_no_method_beats_the_proved_optimum_and_every_order_is_valid(method, closed, start, end):
    cost = euclidean(11, seed=3)
    inst = SequencingInstance.from_matrix(cost, closed=closed, start=start, end=end)
    optimum = sequence_waypoints(inst, method="exact")
    assert optimum.info["optimal"]
    assert optimum.info["bound"] <= optimum.cost + 1e-9
    result = sequence_waypoints(inst, method=method, **options_of(method))
    assert_valid(inst, result)
    assert result.cost >= optimum.cost - 1e-6


@pytest.mark.parametrize("closed, start, end", [(True, None, None), (False, None, None), (False, 0, None),
                                                (False, 0, 4), (False, None, 4)])
def test_the_exact_optimum_equals_held_karp_on_the_hand_built_reduction(closed, start, end):
    cost = euclidean(9, seed=5)
    inst = SequencingInstance.from_matrix(cost, closed=closed, start=start, end=end)
    exact = sequence_waypoints(inst, method="exact")
    if closed:  # tour = path from 0 to a copy of 0
        padded = np.zeros((10, 10))
        padded[:9, :9] = cost
        padded[:9, 9] = cost[:, 0]
        padded[9, :9] = cost[0, :]
        padded[9, :] += 1e4  # the copy can only be last
        _, best = held_karp(padded, start=0)  # never leaves the copy: no 1e4 in the optimum
    else:  # enumerate the end by Held–Karp on each fixed last waypoint (leaving it costs 1e4)
        ends = [end] if end is not None else range(9)
        best = np.inf
        for e in ends:
            if e == start:
                continue
            c = cost.copy()
            c[e, :] += 1e4
            best = min(best, held_karp(c, start=start)[1])
    assert exact.cost == pytest.approx(best, rel=1e-9)


def test_a_closed_tour_of_a_matrix_equals_the_dummy_node_reduction_of_its_open_path():
    # The open path (free ends) of C is the closed tour of C plus a dummy node at cost 0 from and to every node.
    cost = euclidean(10, seed=8)
    dummy = np.zeros((11, 11))
    dummy[:10, :10] = cost
    tour = sequence_waypoints(SequencingInstance.from_matrix(dummy, closed=True), method="exact")
    path = sequence_waypoints(SequencingInstance.from_matrix(cost), method="exact")
    assert tour.cost == pytest.approx(path.cost, rel=1e-9)
    order = tour.order.tolist()
    at = order.index(10)
    assert priced(cost, order[at + 1:] + order[:at], closed=False) == pytest.approx(path.cost, rel=1e-9)


@pytest.mark.parametrize("method", ASYMMETRIC_METHODS)
def test_asymmetric_costs_are_priced_in_the_travelled_direction(method):
    if method in ("zigzag", "zigzag2", "spiral", "spiral2"):
        pytest.skip("the patterns need tile geometry (tested below)")
    cost = asymmetric(10, seed=1)
    for closed, start, end in ((True, 0, None), (False, 2, 6), (False, None, None)):
        inst = SequencingInstance.from_matrix(cost, closed=closed, start=start, end=end)
        optimum = sequence_waypoints(inst, method="exact").cost
        result = sequence_waypoints(inst, method=method, **options_of(method))
        assert_valid(inst, result)
        assert result.cost >= optimum - 1e-6
        if method in ("exact", "lkh"):
            assert result.cost == pytest.approx(optimum, rel=1e-5)


@pytest.mark.parametrize("method", ["local", "ga", "ga-plain", "fast-tsp"])
def test_the_symmetric_methods_refuse_an_asymmetric_matrix_naming_the_others(method):
    inst = SequencingInstance.from_matrix(asymmetric(6, seed=2))
    with pytest.raises(ParameterError, match=f"method '{method}' assumes a symmetric cost matrix.*lkh"):
        sequence_waypoints(inst, method=method)


@pytest.mark.parametrize("method", ["zigzag", "zigzag2", "spiral", "spiral2"])
def test_the_patterns_refuse_a_plain_matrix(method):
    inst = SequencingInstance.from_matrix(euclidean(6, seed=0))
    with pytest.raises(ParameterError, match="no tile geometry"):
        sequence_waypoints(inst, method=method)
    with pytest.raises(ParameterError, match="no tile geometry"):
        solve_zigzag(inst)


def test_auto_runs_exact_small_local_large_and_ortools_on_large_asymmetric():
    assert auto_method(SequencingInstance.from_matrix(euclidean(40, 0))) == "exact"
    assert auto_method(SequencingInstance.from_matrix(euclidean(40, 0), closed=True)) == "ils"  # 41 with the copy
    assert auto_method(SequencingInstance.from_matrix(euclidean(39, 0), closed=True)) == "exact"
    assert auto_method(SequencingInstance.from_matrix(asymmetric(41, 0))) == "ortools"
    # never fast-tsp (installed here): no seed, stops on the clock; the default must reproduce
    instance = SequencingInstance.from_matrix(euclidean(45, 0), closed=True)
    first, again = sequence_waypoints(instance, seed=3), sequence_waypoints(instance, seed=3)
    assert first.method == "auto (ils)" and first.order.tolist() == again.order.tolist()


def test_a_tileset_instance_can_be_closed_or_end_at_a_tile_with_the_patterns_too():
    ts = load_tileset(tileset_path("paper_8x7_fig13b"))
    base = SequencingInstance.from_tileset(ts, start=1)
    ended = SequencingInstance(base.cost, base.blocks, 0, base.ids, base.shape, end=5)
    for method in ("zigzag", "spiral2", "exact", "local"):
        result = sequence_waypoints(ended, method=method)
        assert_valid(ended, result)
    closed = SequencingInstance(base.cost, base.blocks, 0, base.ids, base.shape, closed=True)
    exact = sequence_waypoints(closed, method="exact")
    assert_valid(closed, exact)
    assert exact.cost > sequence_waypoints(base, method="exact").cost  # the way back costs something


# -------------------------------------------------------------------------------------- reduction
def test_the_reduction_prices_every_decoded_order_at_its_cost_plus_the_offset():
    rng = np.random.default_rng(4)
    for cost, closed, start, end in ((euclidean(7, 1), True, None, None), (euclidean(7, 1), False, 1, 3),
                                     (asymmetric(7, 1), False, None, 3), (asymmetric(7, 1), True, 2, None)):
        inst = SequencingInstance.from_matrix(cost, closed=closed, start=start, end=end)
        red = reduce_to_open_path(inst)
        assert red.instance.end is None and not red.instance.closed
        for _ in range(20):
            order = inst.check_order(_random_valid(inst, rng))
            lifted = order.tolist() + ([inst.n] if closed else [])
            assert red.decode(lifted).tolist() == order.tolist()
            assert red.instance.path_cost(lifted) - red.offset == pytest.approx(priced(cost, order, closed))


def _random_valid(inst, rng):
    """A random valid order; a closed tour's from its start, or from 0 (where the reduction begins it)."""
    first = inst.start if inst.start is not None or not inst.closed else 0
    rest = [i for i in rng.permutation(inst.n).tolist() if i not in (first, inst.end)]
    return ([first] if first is not None else []) + rest + ([inst.end] if inst.end is not None else [])


def test_a_heuristic_order_that_misses_the_end_is_still_decoded_to_a_valid_order():
    inst = SequencingInstance.from_matrix(euclidean(6, 2), start=0, end=2)
    red = reduce_to_open_path(inst)
    assert red.decode([0, 2, 1, 3, 4, 5]).tolist() == [0, 1, 3, 4, 5, 2]


# ------------------------------------------------------------------------------------ bad inputs
@pytest.mark.parametrize("matrix, words", [
    ([[0, 1, 2], [1, 0]], "row 1 has 2 entries"),
    ([[0, 1], [1, np.nan]], "must be finite"),
    ([[0, 1], [np.inf, 0]], "must be finite"),
    (np.zeros((2, 3)), "square"),
    ([], "non-empty"),
    ("abc", "matrix"),
    ([["a", "b"], ["c", "d"]], "numbers"),
])
def test_bad_matrices_are_parameter_errors(matrix, words):
    with pytest.raises(ParameterError, match=words):
        SequencingInstance.from_matrix(matrix)


@pytest.mark.parametrize("options, words", [
    ({"start": 2, "end": 2}, "cannot begin and end at one waypoint"),
    ({"closed": True, "end": 1}, "open paths only"),
    ({"start": 3}, "start must be an integer"),
    ({"end": -1}, "end must be an integer"),
    ({"closed": 1}, "closed must be True or False"),
])
def test_bad_ends_are_parameter_errors(options, words):
    with pytest.raises(ParameterError, match=words):
        SequencingInstance.from_matrix(euclidean(3, 0), **options)


def test_one_waypoint_may_begin_and_end_an_open_path_and_every_method_handles_it():
    inst = SequencingInstance.from_matrix([[0.0]], start=0, end=0)
    for method in MATRIX_METHODS:
        assert sequence_waypoints(inst, method=method, **MATRIX_METHODS[method]).order.tolist() == [0]
    tour = SequencingInstance.from_matrix([[7.0]], closed=True)
    assert sequence_waypoints(tour, method="lkh").cost == 0.0  # no leg, the diagonal is never used


def test_an_order_that_does_not_end_at_the_end_is_refused():
    inst = SequencingInstance.from_matrix(euclidean(4, 0), start=0, end=3)
    assert inst.check_order([0, 2, 1, 3]).tolist() == [0, 2, 1, 3]
    with pytest.raises(PlanningError, match="end at tile 4, not tile 2"):
        inst.check_order([0, 3, 2, 1])


def test_a_callable_method_gets_the_open_path_and_its_order_is_decoded():
    inst = SequencingInstance.from_matrix(euclidean(5, 0), closed=True, start=2)
    seen = []

    def identity(instance, **_):
        seen.append((instance.n, instance.start, instance.end, instance.closed))
        return [instance.start] + [i for i in range(instance.n) if i != instance.start], {}

    result = sequence_waypoints(inst, method=identity)
    assert seen == [(6, 2, None, False)]  # a copy of waypoint 2 closes the tour
    assert result.order.tolist() == [2, 0, 1, 3, 4]
    assert result.cost == pytest.approx(priced(inst.cost, [2, 0, 1, 3, 4], closed=True))


# --------------------------------------------------------------------------------- the backends
@pytest.mark.parametrize("n", [1, 2, 3, 4, 25])
@pytest.mark.parametrize("closed", [True, False])
def test_the_backends_on_every_size_against_the_exact_optimum(n, closed):
    inst = SequencingInstance.from_matrix(euclidean(n, n), closed=closed, start=0 if closed else None)
    optimum = sequence_waypoints(inst, method="exact").cost
    for method, options in (("fast-tsp", {"time_limit": 0.3}), ("lkh", {})):
        result = sequence_waypoints(inst, method=method, **options)
        assert_valid(inst, result)
        # integer rounding: each leg off by at most half a unit of the solver's scale
        assert result.cost == pytest.approx(optimum, abs=(n + 1) / result.info["scale"] + 1e-9)


def test_an_integer_matrix_is_handed_over_unscaled():
    cost = np.rint(euclidean(30, 7))
    for method, options in (("fast-tsp", {"time_limit": 0.2}), ("lkh", {})):
        result = sequence_waypoints(SequencingInstance.from_matrix(cost, closed=True), method=method, **options)
        assert result.info["scale"] == 1.0


def test_negative_costs_are_shifted_not_refused():
    cost = euclidean(12, 3) - 50.0
    inst = SequencingInstance.from_matrix(cost, closed=True)
    optimum = sequence_waypoints(inst, method="exact").cost
    assert sequence_waypoints(inst, method="lkh").cost == pytest.approx(optimum, abs=1e-3)


def test_lkh_is_deterministic_and_refuses_a_seed_and_a_time_limit():
    inst = SequencingInstance.from_matrix(euclidean(60, 9), start=4)
    first = sequence_waypoints(inst, method="lkh").order.tolist()
    assert sequence_waypoints(inst, method="lkh").order.tolist() == first  # LKH's own fixed seed
    assert solve_lkh(inst, seed=2)[0].tolist() == first
    for option in ("seed", "time_limit"):  # the spec's lkh draws from no seed and takes no limit
        with pytest.raises(ParameterError, match=f"method 'lkh' takes no option '{option}' \\({option} applies to "):
            sequence_waypoints(inst, method="lkh", **{option: 1})
    with pytest.raises(ParameterError, match="takes no time limit"):
        solve_lkh(inst, time_limit=1.0)
    with pytest.raises(ParameterError, match="runs must be a positive integer"):
        solve_lkh(inst, runs=0)


def test_fast_tsp_reports_its_budget_and_refuses_bad_options():
    inst = SequencingInstance.from_matrix(euclidean(30, 1))
    order, info = solve_fast_tsp(inst, time_limit=0.1, threads=1)
    assert info["time_limit_s"] == 0.1 and info["threads"] == 1
    with pytest.raises(ParameterError, match="candidates must be one of"):
        solve_fast_tsp(inst, candidates="best")
    with pytest.raises(ParameterError, match="threads must be a positive integer"):
        solve_fast_tsp(inst, threads=0)


@pytest.mark.parametrize("method, module, words", [("fast-tsp", "fast_tsp", "MIT"),
                                                   ("lkh", "elkai", "non-commercial use only")])
def test_a_missing_package_is_a_clear_error_naming_the_extra(monkeypatch, method, module, words):
    monkeypatch.setitem(sys.modules, module, None)  # as if not installed: importing it raises ImportError
    inst = SequencingInstance.from_matrix(euclidean(5, 0))
    with pytest.raises(ParameterError) as info:
        sequence_waypoints(inst, method=method)
    assert words in str(info.value) and f"htetro-opt[{method}]" in str(info.value)


def test_the_backends_on_an_eq2_tileset_instance_match_the_exact_optimum():
    ts = load_tileset(tileset_path("paper_10x10_fig13c"))
    inst = SequencingInstance.from_tileset(ts, start=1)
    optimum = sequence_waypoints(inst, method="exact").cost
    blocks = ts.blocks
    assert np.allclose(inst.cost, cost_matrix(blocks))
    for method, options in (("fast-tsp", {"time_limit": 0.3}), ("lkh", {})):
        result = sequence_waypoints(inst, method=method, **options)
        assert_valid(inst, result)
        assert result.cost == pytest.approx(optimum, abs=inst.n / result.info["scale"])
