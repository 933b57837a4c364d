"""TSPLIB coordinate instances kept implicit (issue 25, item 4): each metric against a pure-Python oracle
of TSPLIB's formula, entry by entry against the matrix, TSPLIB's published tour lengths re-priced, the
same ILS run with and without the matrix, no n × n array at 16 384 cities, and the matrix methods'
on-demand matrix and their refusal past the memory budget."""

import math
from pathlib import Path

import numpy as np
import pytest

from htetro_opt.errors import ParameterError, PlanningError
from htetro_opt.model.simulate import budget_of, size_text
from htetro_opt.problems import SequencingInstance
from htetro_opt.scenarios.tsplib import load_tsplib, parse_tsplib
from htetro_opt.solvers.sequencing import MATRIX_BYTES_DEFAULT, MATRIX_BYTES_PER_ENTRY, auto_method, sequence_waypoints

DATA = Path(__file__).parents[3] / "benchmarks" / "data" / "tsplib"
METRICS = ("EUC_2D", "CEIL_2D", "ATT", "GEO")


# ------------------------------------------------------------------ the oracle: TSPLIB's C, in Python
def _nint(x):
    return int(x + 0.5)


def _geo_radians(x):
    deg = int(x)  # C's (int): towards zero
    return 3.141592 * (deg + 5.0 * (x - deg) / 3.0) / 180.0


def oracle(metric, p, q):
    """TSPLIB95's distance functions as its document and reference code state them (one pair)."""
    if metric == "GEO":
        lat_i, lon_i = _geo_radians(p[0]), _geo_radians(p[1])
        lat_j, lon_j = _geo_radians(q[0]), _geo_radians(q[1])
        q1, q2, q3 = math.cos(lon_i - lon_j), math.cos(lat_i - lat_j), math.cos(lat_i + lat_j)
        return int(6378.388 * math.acos(0.5 * ((1.0 + q1) * q2 - (1.0 - q1) * q3)) + 1.0)
    xd, yd = p[0] - q[0], p[1] - q[1]
    if metric == "ATT":
        r = math.sqrt((xd * xd + yd * yd) / 10.0)
        t = _nint(r)
        return t + 1 if t < r else t
    if metric == "CEIL_2D":
        return math.ceil(math.sqrt(xd * xd + yd * yd))
    return _nint(math.sqrt(xd * xd + yd * yd))


def coordinates(metric, n, seed):
    rng = np.random.default_rng(seed)
    if metric == "GEO":  # DDD.MM: degrees and minutes below 60, both hemispheres
        deg = np.column_stack([rng.integers(-60, 61, n), rng.integers(-170, 171, n)])
        return np.round(deg + np.sign(deg + 0.5) * rng.integers(0, 60, (n, 2)) / 100, 2)
    if metric == "ATT":
        return rng.integers(0, 8000, (n, 2)).astype(float)
    return np.round(rng.uniform(0, 1000, (n, 2)), 3)


def tour_file(path):
    """The node order of a TSPLIB .tour file (0-based)."""
    lines = path.read_text().split("TOUR_SECTION")[1].split()
    return [int(v) - 1 for v in lines if v not in ("-1", "EOF")]


def priced(metric, xy, order, closed=True):
    legs = list(zip(order, order[1:])) + ([(order[-1], order[0])] if closed else [])
    return sum(oracle(metric, xy[a], xy[b]) for a, b in legs)


# ---------------------------------------------------------------------------------------- costs
@pytest.mark.parametrize("metric", METRICS)
def test_each_metric_equals_the_oracle_and_the_matrix_entry_by_entry(metric):
    xy = coordinates(metric, 40, 1)
    inst = SequencingInstance.from_coordinates(xy, metric, closed=True)
    assert inst.implicit and inst.cost is None and inst.n == 40
    a, b = np.divmod(np.arange(40 * 40), 40)
    implicit = inst.legs(a, b).reshape(40, 40)
    expected = [[0 if i == j else oracle(metric, xy[i].tolist(), xy[j].tolist()) for j in range(40)] for i in range(40)]
    assert implicit.tolist() == expected
    assert inst.with_matrix().cost.tolist() == expected
    assert len({v for row in expected for v in row}) > 100  # the instance exercises the rounding, not a few values


@pytest.mark.parametrize("metric", METRICS)
def test_the_kernel_prices_a_tour_as_the_oracle(metric):
    xy = coordinates(metric, 120, 2)
    inst = SequencingInstance.from_coordinates(xy, metric, closed=True)
    result = sequence_waypoints(inst, method="ils", seed=0, kicks=2000)
    order = result.order.tolist()
    assert result.info["costs"] == f"implicit ({metric} on demand)"
    assert result.cost == result.info["tour_cost"] == priced(metric, xy.tolist(), order)  # kernel = numpy = oracle


@pytest.mark.parametrize("name, optimum", [("eil51", 426), ("berlin52", 7542), ("kroA100", 21282), ("ch130", 6110),
                                           ("a280", 2579), ("pcb442", 50778), ("pr1002", 259045)])
def test_tsplibs_optimal_tours_reprice_to_the_published_optima(name, optimum):
    tsp = load_tsplib(DATA / f"{name}.tsp")
    inst = SequencingInstance.from_tsplib(tsp)
    assert inst.implicit and inst.metric == "EUC_2D" and "cost" not in vars(tsp)  # no matrix built
    order = tour_file(DATA / f"{name}.opt.tour")
    assert inst.path_cost(order) == optimum == priced("EUC_2D", tsp.coords.tolist(), order)


@pytest.mark.parametrize("text, optimum", [
    # ulysses16 (GEO) as published, and a 4-city ATT square whose every tour is priced by hand
    ("NAME: ulysses16\nTYPE: TSP\nDIMENSION: 16\nEDGE_WEIGHT_TYPE: GEO\nNODE_COORD_SECTION\n"
     "1 38.24 20.42\n2 39.57 26.15\n3 40.56 25.32\n4 36.26 23.12\n5 33.48 10.54\n6 37.56 12.19\n7 38.42 13.11\n"
     "8 37.52 20.44\n9 41.23 9.10\n10 41.17 13.05\n11 36.08 -5.21\n12 38.47 15.13\n13 38.15 15.35\n"
     "14 37.51 15.17\n15 35.49 14.32\n16 39.36 19.56\nEOF", 6859),
    ("TYPE: TSP\nDIMENSION: 4\nEDGE_WEIGHT_TYPE: ATT\nNODE_COORD_SECTION\n1 0 0\n2 0 30\n3 40 30\n4 40 0\nEOF",
     # sides √90 = 9.49 → 9 < r → 10 and √160 = 12.6 → 13; diagonals √250 = 15.8 → 16
     2 * 10 + 2 * 13),
])
def test_the_implicit_search_reaches_published_optima_priced_without_a_matrix(text, optimum):
    inst = SequencingInstance.from_tsplib(parse_tsplib(text))
    assert inst.implicit
    assert sequence_waypoints(inst, method="exact").cost == optimum  # its matrix, built on demand
    result = sequence_waypoints(inst, method="ils", seed=0, kicks=500)
    assert result.cost == result.info["tour_cost"] == optimum


# ------------------------------------------------------------------------------------- the search
@pytest.mark.parametrize("name, closed", [("pr1002", True), ("a280", True), ("kroA100", False)])
def test_the_ils_gives_the_same_tour_with_the_matrix_and_without(name, closed):
    """Same costs, same start tour (nearest neighbour from node 0, built from a k-d tree without the matrix),
    same neighbour lists (ties by index both ways): the same kernel path, so the same order and kicks."""
    tsp = load_tsplib(DATA / f"{name}.tsp")
    implicit = SequencingInstance.from_tsplib(tsp, closed=closed, start=0)
    dense = SequencingInstance.from_matrix(tsp.cost, closed=closed, start=0)
    runs = [sequence_waypoints(inst, method="ils", seed=5, kicks=3000) for inst in (implicit, dense)]
    assert runs[0].info["costs"].startswith("implicit") and runs[1].info["costs"] == "matrix"
    if closed:  # an open path's dummy node starts the dense tour elsewhere: only the closed tours share it
        assert runs[0].info["initial_cost"] == runs[1].info["initial_cost"]
        assert runs[0].order.tolist() == runs[1].order.tolist()
    assert runs[0].cost == implicit.path_cost(runs[0].order) == dense.path_cost(runs[0].order)
    assert sorted(runs[0].order.tolist()) == list(range(tsp.dimension)) and runs[0].order[0] == 0


def test_auto_runs_ils_beyond_the_exact_range_and_exact_below_it():
    big = SequencingInstance.from_coordinates(coordinates("EUC_2D", 300, 3), "EUC_2D", closed=True)
    small = SequencingInstance.from_coordinates(coordinates("EUC_2D", 12, 3), "EUC_2D", closed=True)
    assert auto_method(big) == "ils" and auto_method(small) == "exact"
    result = sequence_waypoints(small)
    assert result.method == "auto (exact)" and result.info["optimal"]


# ------------------------------------------------------------------------------------------ memory
def test_a_16384_city_instance_holds_no_n_by_n_array():
    n = 16_384
    xy = np.random.default_rng(0).uniform(0, 1e4, (n, 2))
    text = "TYPE: TSP\nDIMENSION: %d\nEDGE_WEIGHT_TYPE: EUC_2D\nNODE_COORD_SECTION\n" % n
    text += "\n".join(f"{i} {x:.3f} {y:.3f}" for i, (x, y) in enumerate(xy, 1)) + "\nEOF"
    tsp = parse_tsplib(text)
    inst = SequencingInstance.from_tsplib(tsp, start=0)
    assert "cost" not in vars(tsp) and tsp.weights is None  # the file's matrix was never built
    arrays = [v for v in (*vars(tsp).values(), *vars(inst).values()) if isinstance(v, np.ndarray)]
    assert inst.cost is None and arrays and max(a.size for a in arrays) == 2 * n
    assert inst.legs([0], [1])[0] == int(math.dist(tsp.coords[0], tsp.coords[1]) + 0.5)


def test_matrix_methods_get_the_matrix_within_the_budget_and_a_named_refusal_beyond():
    xy = coordinates("ATT", 60, 4)
    inst = SequencingInstance.from_coordinates(xy, "ATT", closed=True, start=0)
    result = sequence_waypoints(inst, method="local", seed=0)  # some 170 KiB: well within the budget
    assert result.cost == priced("ATT", xy.tolist(), result.order.tolist())
    needed = MATRIX_BYTES_PER_ENTRY.get("local", MATRIX_BYTES_DEFAULT) * 60 * 60
    with budget_of(needed, "a test's budget"):  # exactly the need: built
        assert sequence_waypoints(inst, method="local", seed=0).cost == result.cost
    with budget_of(needed - 1, "a test's budget"), pytest.raises(PlanningError) as info:
        sequence_waypoints(inst, method="local", seed=0)
    message = str(info.value)
    for words in ("method 'local'", "60 nodes", size_text(needed), "a test's budget", "ils or auto"):
        assert words in message, (words, message)
    with budget_of(1, "a test's budget"):  # ils keeps the costs implicit: no budget to meet
        assert sequence_waypoints(inst, method="ils", seed=0, kicks=100).cost > 0


def test_the_16384_city_refusal_names_the_method_and_the_memory_before_any_work():
    xy = np.random.default_rng(1).uniform(0, 1e4, (16_384, 2))
    inst = SequencingInstance.from_coordinates(xy, "EUC_2D", closed=True)
    with budget_of(4 * 2**30, "a 4 GiB budget"):
        for method in ("lkh", "fast-tsp", "ortools", "local"):
            with pytest.raises(PlanningError, match=rf"method '{method}' .* 16,384 nodes .* GiB .* ils or auto"):
                sequence_waypoints(inst, method=method)


def test_bad_coordinates_and_metrics_are_refused():
    with pytest.raises(ParameterError, match="metric must be one of"):
        SequencingInstance.from_coordinates([[0, 0], [1, 1]], "MAN_2D")
    with pytest.raises(ParameterError, match=r"\(n, 2\)"):
        SequencingInstance.from_coordinates([[0, 0, 0], [1, 1, 1]], "EUC_2D")
    with pytest.raises(ParameterError, match="finite"):
        SequencingInstance.from_coordinates([[0, np.nan], [1, 1]], "EUC_2D")
    with pytest.raises(ParameterError, match="not both"):
        SequencingInstance(None, np.zeros((2, 4, 2), int), 0, coords=[[0, 0], [1, 1]], metric="EUC_2D")
