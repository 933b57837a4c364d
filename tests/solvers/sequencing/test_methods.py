"""What every sequencing method shares: one seed meaning (None, int or Generator), one time-limit
rule, ``method=`` as a name or a callable, and one result type."""

from itertools import pairwise

import numpy as np
import pytest

from htetro_opt.errors import ParameterError, PlanningError
from htetro_opt.problems.waypoint_sequencing import SequencingInstance, cost_matrix
from htetro_opt.scenarios import load_tileset, tileset_path
from htetro_opt.solvers.sequencing import (
    SPEC,
    SequenceResult,
    sequence_waypoints,
    solve_exact,
    solve_ga,
    solve_greedy,
    solve_local,
    solve_ortools,
    solve_spiral,
    solve_zigzag,
    solve_fast_tsp,
    solve_lkh,
)

# Options that keep each method fast here; with them every method runs in well under a second.
FAST = {"exact": {}, "ortools": {"solution_limit": 50}, "local": {"restarts": 5}, "ils": {"kicks": 200}, "ga": {"patience": 5},
        "ga-plain": {"max_gen": 20}, "zigzag": {}, "zigzag2": {}, "spiral": {}, "spiral2": {},
        "greedy": {"iterations": 20}, "fast-tsp": {"time_limit": 0.1}, "lkh": {}}
FUNCTIONS = [solve_exact, solve_ortools, solve_local, solve_ga, solve_greedy, solve_zigzag, solve_spiral,
             solve_fast_tsp, solve_lkh]


@pytest.fixture(scope="module")
def fig13b():
    return load_tileset(tileset_path("paper_8x7_fig13b"))  # 14 tiles


@pytest.fixture(scope="module")
def inst(fig13b):
    return SequencingInstance.from_tileset(fig13b, start=1)


def eq2_cost(tileset, tiles):
    """Eq. 2 at equal weights summed along an order of tile labels, block by block (by hand)."""
    blocks = {t: np.asarray(b, dtype=float) for t, b in zip(tileset.ids, tileset.blocks)}
    return sum(0.25 * float(np.hypot(*(blocks[a][k] - blocks[b][k]))) for a, b in pairwise(tiles) for k in range(4))


def test_the_methods_are_the_documented_names():
    assert tuple(SPEC.methods) == ("auto",) + tuple(FAST)


# ------------------------------------------------------------------------------------------ seeds
# The stochastic methods and an option making their result depend on the seed.
STOCHASTIC = {"local": {"restarts": 3, "max_starts": 1}, "ga": {"max_gen": 2}, "ga-plain": {"max_gen": 0},
              "greedy": {"iterations": 3}}


@pytest.mark.parametrize("method", list(STOCHASTIC))
def test_same_int_seed_same_order_and_an_equal_generator_the_same_again(inst, method):
    def run(seed):
        return sequence_waypoints(inst, method=method, seed=seed, **STOCHASTIC[method]).order.tolist()

    assert run(11) == run(11)
    assert run(np.random.default_rng(5)) == run(np.random.default_rng(5))
    inst.check_order(run(None))  # fresh entropy: some valid order


@pytest.mark.parametrize("method", ["ga-plain", "greedy"])
def test_the_seed_is_used(inst, method):
    # no generation (ga-plain) or three paths (greedy): the best of a few random draws depends on them
    orders = {tuple(sequence_waypoints(inst, method=method, seed=s, **STOCHASTIC[method]).order.tolist())
              for s in range(6)}
    assert len(orders) > 1


def test_a_generator_advances_so_two_runs_from_one_generator_differ(inst):
    rng = np.random.default_rng(0)
    first = solve_ga(inst, seed=rng, max_gen=0)[0].tolist()
    second = solve_ga(inst, seed=rng, max_gen=0)[0].tolist()
    assert first != second


@pytest.mark.parametrize("function", FUNCTIONS, ids=lambda f: f.__name__)
@pytest.mark.parametrize("seed", [-1, 1.5, True, "0", np.random.RandomState(0)])
def test_every_method_refuses_a_bad_seed_naming_it(inst, function, seed):
    with pytest.raises(ParameterError, match=r"seed must be None, a non-negative integer"):
        function(inst, seed=seed)


@pytest.mark.parametrize("method", ["exact", "zigzag", "zigzag2", "spiral", "spiral2"])
def test_the_deterministic_methods_take_no_seed(inst, method):
    a = sequence_waypoints(inst, method=method, **FAST[method])
    b = sequence_waypoints(inst, method=method, **FAST[method])
    assert a.order.tolist() == b.order.tolist()
    with pytest.raises(ParameterError, match=f"method '{method}' takes no option 'seed' \\(seed applies to "):
        sequence_waypoints(inst, method=method, seed=0, **FAST[method])


def test_ortools_accepts_every_kind_of_seed(inst):
    for seed in (None, 3, np.random.default_rng(1)):
        order, info = solve_ortools(inst, seed=seed, time_limit=60.0, solution_limit=10)
        inst.check_order(order)
        assert info["time_limit_s"] == 60.0


# ------------------------------------------------------------------------------------ time limits
@pytest.mark.parametrize("function", FUNCTIONS, ids=lambda f: f.__name__)
@pytest.mark.parametrize("bad", [float("inf"), 0, -1, float("nan"), True, "1"])
def test_every_method_refuses_a_bad_time_limit(inst, function, bad):
    with pytest.raises(ParameterError, match="time_limit must be a positive, finite number"):
        function(inst, time_limit=bad)


def test_the_dispatcher_refuses_an_infinite_time_limit(inst):
    with pytest.raises(ParameterError, match=r"time_limit .* got inf"):
        sequence_waypoints(inst, method="local", time_limit=float("inf"))


# --------------------------------------------------------------------------- method= and results
@pytest.mark.parametrize("method", list(FAST))
def test_every_named_method_gives_a_result_priced_by_eq2(fig13b, inst, method):
    seed = {"seed": 1} if SPEC.method(method).takes("seed") else {}
    result = sequence_waypoints(inst, method=method, **seed, **FAST[method])
    assert isinstance(result, SequenceResult) and result.method == method
    assert result.tiles[0] == 1 and sorted(result.tiles) == sorted(fig13b.ids)
    assert result.cost == pytest.approx(eq2_cost(fig13b, result.tiles))
    record = result.as_dict()
    assert record["method"] == method and record["order"] == result.tiles and record["cost"] == result.cost


def test_a_callable_method_is_run_with_the_seed_time_limit_and_options(fig13b, inst):
    calls = []

    def scan(instance, *, seed, time_limit, reverse=False):
        calls.append((seed, time_limit, reverse))
        rest = [i for i in range(instance.n) if i != instance.start]
        return [instance.start] + (rest[::-1] if reverse else rest), {"reversed": reverse}

    result = sequence_waypoints(inst, method=scan, seed=4, time_limit=2, reverse=True)
    assert calls == [(4, 2.0, True)]
    assert result.method == "scan" and result.info == {"reversed": True}
    assert result.tiles == [1] + list(range(14, 1, -1))
    assert result.cost == pytest.approx(eq2_cost(fig13b, result.tiles))


def test_a_callable_method_cannot_report_an_invalid_order(inst):
    with pytest.raises(PlanningError, match="exactly once"):
        sequence_waypoints(inst, method=lambda instance, **_: ([0, 0], {}))
    with pytest.raises(PlanningError, match="begin at tile 1"):
        sequence_waypoints(inst, method=lambda instance, **_: (list(range(instance.n))[::-1], {}))


def test_method_is_keyword_only_and_must_be_known(inst):
    with pytest.raises(TypeError):
        sequence_waypoints(inst, "exact")
    with pytest.raises(ParameterError, match="unknown sequencing method 'nsga2'"):
        sequence_waypoints(inst, method="nsga2")


def test_auto_chooses_by_size():
    rng = np.random.default_rng(2)
    small = rng.integers(0, 50, (12, 4, 2))
    assert sequence_waypoints(SequencingInstance(cost_matrix(small), small, 0)).method == "auto (exact)"
    large = rng.integers(0, 50, (41, 4, 2))
    # never fast-tsp, although installed by the test extra: it is not reproducible (no seed, stops on the clock)
    assert sequence_waypoints(SequencingInstance(cost_matrix(large), large, 0)).method == "auto (ils)"
