"""TSPLIB files: every edge-weight type against hand-computed distances, TSPLIB's published optima
of two small public instances (data inline), bad files, and ``htetro-opt sequence FILE.tsp``."""

import itertools
import json
import math
import re
from pathlib import Path

import numpy as np
import pytest

from htetro_opt.cli import main
from htetro_opt.errors import ScenarioError
from htetro_opt.problems import SequencingInstance
from htetro_opt.scenarios.tsplib import EDGE_WEIGHT_FORMATS, load_tsplib, parse_tsplib, tsplib_distances
from htetro_opt.solvers.sequencing import sequence_waypoints

# TSPLIB's burma14 (GEO, optimum 3323) and ulysses16 (GEO, optimum 6859), as published.
BURMA14 = """NAME: burma14
TYPE: TSP
COMMENT: 14-Staedte in Burma (Zaw Win)
DIMENSION: 14
EDGE_WEIGHT_TYPE: GEO
EDGE_WEIGHT_FORMAT: FUNCTION
DISPLAY_DATA_TYPE: COORD_DISPLAY
NODE_COORD_SECTION
   1  16.47       96.10
   2  16.47       94.44
   3  20.09       92.54
   4  22.39       93.37
   5  25.23       97.24
   6  22.00       96.05
   7  20.47       97.02
   8  17.20       96.29
   9  16.30       97.38
  10  14.05       98.12
  11  16.53       97.38
  12  21.52       95.59
  13  19.41       97.13
  14  20.09       94.55
EOF
"""
ULYSSES16 = """NAME: ulysses16.tsp
TYPE: TSP
COMMENT: Odyssey of Ulysses (Groetschel/Padberg)
DIMENSION: 16
EDGE_WEIGHT_TYPE: GEO
DISPLAY_DATA_TYPE: COORD_DISPLAY
NODE_COORD_SECTION
 1 38.24 20.42
 2 39.57 26.15
 3 40.56 25.32
 4 36.26 23.12
 5 33.48 10.54
 6 37.56 12.19
 7 38.42 13.11
 8 37.52 20.44
 9 41.23 9.10
 10 41.17 13.05
 11 36.08 -5.21
 12 38.47 15.13
 13 38.15 15.35
 14 37.51 15.17
 15 35.49 14.32
 16 39.36 19.56
EOF
"""
# burma14's first row as TSPLIB's explicit version of the instance lists it
BURMA14_ROW1 = [0, 153, 510, 706, 966, 581, 455, 70, 160, 372, 157, 567, 342, 398]


def coords_text(kind, points, name="t"):
    lines = [f"NAME : {name}", "TYPE : TSP", f"DIMENSION : {len(points)}", f"EDGE_WEIGHT_TYPE : {kind}",
             "NODE_COORD_SECTION"]
    lines += [f"{i} " + " ".join(str(v) for v in p) for i, p in enumerate(points, 1)]
    return "\n".join(lines + ["EOF"])


def explicit_text(fmt, numbers, n=4, kind="TSP"):
    return (f"NAME: m\nTYPE: {kind}\nDIMENSION: {n}\nEDGE_WEIGHT_TYPE: EXPLICIT\nEDGE_WEIGHT_FORMAT: {fmt}\n"
            f"EDGE_WEIGHT_SECTION\n{numbers}\nEOF\n")


def priced(cost, order, closed=True):
    total = sum(float(cost[a][b]) for a, b in zip(order, order[1:]))
    return total + (float(cost[order[-1]][order[0]]) if closed else 0.0)


# ------------------------------------------------------------------------------------ distances
@pytest.mark.parametrize("kind, points, expected", [
    # nint is ⌊x + 0.5⌋: 2.5 → 3 (Python's round would give 2), √2 → 1
    ("EUC_2D", [(0, 0), (3, 4), (2.5, 0), (1, 1)], [0, 5, 3, 1]),
    ("CEIL_2D", [(0, 0), (3, 4), (2.5, 0), (1, 1)], [0, 5, 3, 2]),
    ("MAN_2D", [(0, 0), (3, 4), (2.5, 0), (1, 1)], [0, 7, 3, 2]),
    ("MAX_2D", [(0, 0), (3, 4), (2.5, 0), (1, 1)], [0, 4, 3, 1]),
    # r = √((Δx² + Δy²)/10): √2.5 = 1.58 → 2; √10 = 3.16 → 3 < r → 4; √100 = 10 exactly → 10
    ("ATT", [(0, 0), (3, 4), (10, 0), (10, 30)], [0, 2, 4, 10]),
    ("EUC_3D", [(0, 0, 0), (1, 2, 2), (0, 0, 2.5), (1, 1, 1)], [0, 3, 3, 2]),
])
def test_coordinate_types_by_hand(kind, points, expected):
    tsp = parse_tsplib(coords_text(kind, points))
    assert tsp.cost[0].tolist() == expected
    assert np.array_equal(tsp.cost, tsp.cost.T)
    assert tsp.edge_weight_type == kind and tsp.dimension == 4


def test_geo_reproduces_burma14s_published_distances():
    tsp = parse_tsplib(BURMA14)
    assert tsp.cost[0].tolist() == BURMA14_ROW1
    assert tsp.name == "burma14" and tsp.comment == "14-Staedte in Burma (Zaw Win)"


def test_geo_by_hand_on_one_pair():
    # 16.47 is 16° 47′: lat = π (16 + 5·0.47/3) / 180 with π = 3.141592; both at longitude 96° 10′
    # and 94° 44′: q1 = cos(Δlon), q2 = 1, q3 = cos(2 lat); d = ⌊6378.388 acos(½((1+q1) − (1−q1) q3)) + 1⌋
    import math

    lat = 3.141592 * (16 + 5 * 0.47 / 3) / 180
    dlon = 3.141592 * ((96 + 5 * 0.10 / 3) - (94 + 5 * 0.44 / 3)) / 180
    q1, q3 = math.cos(dlon), math.cos(2 * lat)
    by_hand = int(6378.388 * math.acos(0.5 * ((1 + q1) * 1 - (1 - q1) * q3)) + 1)
    assert by_hand == 153
    assert tsplib_distances([[16.47, 96.10], [16.47, 94.44]], "GEO")[0, 1] == 153


M = [[0, 1, 2, 3], [1, 0, 4, 5], [2, 4, 0, 6], [3, 5, 6, 0]]
LAYOUTS = {"FULL_MATRIX": "0 1 2 3 1 0 4 5 2 4 0 6 3 5 6 0", "UPPER_ROW": "1 2 3\n4 5\n6",
           "LOWER_ROW": "1\n2 4\n3 5 6", "UPPER_DIAG_ROW": "0 1 2 3\n0 4 5\n0 6\n0",
           "LOWER_DIAG_ROW": "0\n1 0\n2 4 0\n3 5 6 0", "UPPER_COL": "1\n2 4\n3 5 6", "LOWER_COL": "1 2 3\n4 5\n6",
           "UPPER_DIAG_COL": "0\n1 0\n2 4 0\n3 5 6 0", "LOWER_DIAG_COL": "0 1 2 3\n0 4 5\n0 6\n0"}


@pytest.mark.parametrize("fmt", EDGE_WEIGHT_FORMATS)
def test_every_explicit_format_gives_the_same_matrix(fmt):
    tsp = parse_tsplib(explicit_text(fmt, LAYOUTS[fmt]))
    assert tsp.cost.tolist() == M and tsp.coords is None


def test_an_atsp_full_matrix_keeps_its_direction():
    tsp = parse_tsplib(explicit_text("FULL_MATRIX", "0 1 9\n5 0 2\n3 8 0", n=3, kind="ATSP"))
    assert tsp.type == "ATSP" and tsp.cost.tolist() == [[0, 1, 9], [5, 0, 2], [3, 8, 0]]
    inst = SequencingInstance.from_matrix(tsp.cost, closed=True, start=0)
    assert not inst.symmetric
    for method in ("exact", "lkh"):
        result = sequence_waypoints(inst, method=method)
        assert result.order.tolist() == [0, 1, 2] and result.cost == 6  # 1 + 2 + 3, not 9 + 8 + 5


# ------------------------------------------------------------------------------------- optima
@pytest.mark.parametrize("text, optimum", [(BURMA14, 3323), (ULYSSES16, 6859)])
def test_the_published_optima_of_small_tsplib_instances(text, optimum):
    tsp = parse_tsplib(text)
    inst = SequencingInstance.from_matrix(tsp.cost, closed=True)
    exact = sequence_waypoints(inst, method="exact")
    assert exact.info["optimal"] and exact.cost == optimum
    assert priced(tsp.cost, exact.order.tolist()) == optimum
    for method, options in (("lkh", {}), ("fast-tsp", {"time_limit": 0.2}), ("local", {"restarts": 20})):
        seed = {"seed": 0} if method == "local" else {}  # lkh and fast-tsp draw from no seed of ours
        result = sequence_waypoints(inst, method=method, **seed, **options)
        assert priced(tsp.cost, result.order.tolist()) == result.cost >= optimum
    assert sequence_waypoints(inst, method="lkh").cost == optimum


# ----------------------------------------------------------------------------------- bad input
@pytest.mark.parametrize("text, words", [
    (coords_text("XRAY1", [(0, 0), (1, 1)]), ["line 4", "unknown EDGE_WEIGHT_TYPE XRAY1"]),
    ("TYPE: CVRP\nDIMENSION: 2\nEDGE_WEIGHT_TYPE: EUC_2D\nNODE_COORD_SECTION\n1 0 0\n2 1 1\nEOF",
     ["line 1", "TYPE CVRP is not supported"]),
    ("TYPE: TSP\nEDGE_WEIGHT_TYPE: EUC_2D\nNODE_COORD_SECTION\n1 0 0\nEOF", ["DIMENSION is missing"]),
    ("TYPE: TSP\nDIMENSION: two\nEDGE_WEIGHT_TYPE: EUC_2D\nEOF", ["line 2", "DIMENSION must be a positive integer"]),
    (coords_text("EUC_2D", [(0, 0), (1, 1)]).replace("DIMENSION : 2", "DIMENSION : 3"), ["needs 3 lines", "got 6"]),
    (coords_text("EUC_2D", [(0, 0), (1, 1)]).replace("2 1 1", "1 1 1"), ["number the nodes 1…2"]),
    (coords_text("EUC_2D", [(0, 0), (1, 1)]).replace("2 1 1", "2 1 x"), ["line 6", "coordinates must be numbers", "'x'"]),
    (coords_text("EUC_2D", [(0, 0), (1, 1)]).replace("EOF", "FIXED_EDGES_SECTION\n1 2\n-1\nEOF"),
     ["FIXED_EDGES_SECTION is not supported"]),
    (explicit_text("UPPER_ROW", "1 2 3 4 5"), ["needs 6 numbers, got 5"]),
    (explicit_text("UPPER_ROW", "1 2 3 4 5 6 7"), ["needs 6 numbers, got 7"]),
    (explicit_text("TRIANGLE", "1 2 3 4 5 6"), ["EDGE_WEIGHT_FORMAT TRIANGLE is not supported"]),
    (explicit_text("UPPER_ROW", "1 2 3 4 5 6", kind="ATSP"), ["an ATSP needs EDGE_WEIGHT_FORMAT FULL_MATRIX"]),
    (explicit_text("UPPER_ROW", "1 2 3 4 5 nan"), ["edge weights must be finite"]),
    ("TYPE: TSP\nDIMENSION: 2\nEDGE_WEIGHT_TYPE: EXPLICIT\nEDGE_WEIGHT_FORMAT: FULL_MATRIX\nEOF",
     ["needs an EDGE_WEIGHT_SECTION"]),
    ("TYPE: TSP\nthis is not a header\n", ["line 2", "expected 'KEY : VALUE'"]),
])
def test_bad_files_are_scenario_errors_naming_the_line(text, words):
    with pytest.raises(ScenarioError) as info:
        parse_tsplib(text, where="bad.tsp")
    message = str(info.value)
    assert message.startswith("bad.tsp")
    for word in words:
        assert word in message, (word, message)


def test_a_missing_file_and_a_non_path_are_scenario_errors(tmp_path):
    with pytest.raises(ScenarioError, match="none.tsp"):
        load_tsplib(tmp_path / "none.tsp")
    with pytest.raises(ScenarioError, match="path must be a file path"):
        load_tsplib(14)


def test_the_file_name_is_the_default_name(tmp_path):
    path = tmp_path / "square.tsp"
    path.write_text(coords_text("EUC_2D", [(0, 0), (0, 3), (4, 3), (4, 0)]).replace("NAME : t\n", ""))
    assert load_tsplib(path).name == "square"


# ------------------------------------------------------------------------------------------ CLI
def run(capsys, argv):
    code = main(argv)
    out, err = capsys.readouterr()
    return code, out, err


def test_cli_sequences_a_tsplib_file_as_a_closed_tour_priced_by_tsplib(capsys, tmp_path):
    path = tmp_path / "burma14.tsp"
    path.write_text(BURMA14)
    code, out, err = run(capsys, ["sequence", str(path), "--json"])
    assert code == 0 and err == ""
    record = json.loads(out)
    assert record["tsplib"] == "burma14" and record["closed"] is True and record["method"] == "auto (exact)"
    assert record["cost"] == 3323 and isinstance(record["cost"], int)
    order = [node - 1 for node in record["order"]]
    assert sorted(order) == list(range(14)) and order[0] == 0
    assert priced(parse_tsplib(BURMA14).cost, order) == 3323


def test_cli_open_path_with_an_end_and_restarts(capsys, tmp_path):
    path = tmp_path / "burma14.tsp"
    path.write_text(BURMA14)
    code, out, err = run(capsys, ["sequence", str(path), "--open", "--start", "3", "--end", "7", "--method", "local",
                                  "--restarts", "10", "--json"])
    assert code == 0, err
    record = json.loads(out)
    assert record["closed"] is False and record["order"][0] == 3 and record["order"][-1] == 7
    assert record["info"]["restarts"] == 10
    cost = parse_tsplib(BURMA14).cost
    assert priced(cost, [v - 1 for v in record["order"]], closed=False) == record["cost"]


@pytest.mark.parametrize("argv, words", [
    (["--end", "3"], ["--end applies to open paths", "--open"]),
    (["--weights", "1,0,0,0"], ["--weights does not apply to a TSPLIB file"]),
    (["--start", "99"], ["--start 99", "no node 99"]),
    (["--restarts", "5"], ["--restarts applies to local only", "not to auto"]),
    (["--method", "zigzag"], ["no tile geometry"]),
    (["--method", "lkh", "--time-limit", "2"], ["--time-limit applies to", "not to lkh"]),
])
def test_cli_bad_options_for_a_tsplib_file_are_one_error_line(capsys, tmp_path, argv, words):
    path = tmp_path / "burma14.tsp"
    path.write_text(BURMA14)
    code, out, err = run(capsys, ["sequence", str(path), *argv])
    assert code == 2 and out == ""
    lines = err.splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ")
    for word in words:
        assert word in lines[0], (word, lines[0])


def test_cli_bad_tsplib_files_are_one_error_line(capsys, tmp_path):
    bad = tmp_path / "bad.tsp"
    bad.write_text(coords_text("XRAY1", [(0, 0), (1, 1)]))
    for path, word in ((bad, "XRAY1"), (tmp_path / "none.tsp", "none.tsp")):
        code, out, err = run(capsys, ["sequence", str(path), "--json"])
        assert code == 2 and out == ""
        assert len(err.splitlines()) == 1 and err.startswith("error: ") and word in err


# The eight classic instances the benchmarks measure against (benchmarks/data/tsplib, README there),
# with TSPLIB's published optima, and the optimal tours stored beside seven of them.
STORED = Path(__file__).resolve().parents[2] / "benchmarks" / "data" / "tsplib"
STORED_OPTIMA = {"eil51": 426, "berlin52": 7542, "kroA100": 21282, "ch130": 6110, "a280": 2579, "lin318": 42029,
                 "pcb442": 50778, "pr1002": 259045}


@pytest.mark.parametrize("name", sorted(STORED_OPTIMA))
def test_stored_instances_are_complete(name):
    text = (STORED / f"{name}.tsp").read_text()
    dimension = int(re.search(r"DIMENSION\s*:\s*(\d+)", text).group(1))
    rows = [line.split() for line in text.split("NODE_COORD_SECTION")[1].split("EOF")[0].splitlines() if line.strip()]
    assert [int(r[0]) for r in rows] == list(range(1, dimension + 1)) and all(len(r) == 3 for r in rows)
    tsp = load_tsplib(STORED / f"{name}.tsp")
    assert tsp.name == name and tsp.dimension == dimension and tsp.coords.shape == (dimension, 2)


@pytest.mark.parametrize("name", sorted(n for n in STORED_OPTIMA if (STORED / f"{n}.opt.tour").exists()))
def test_stored_optimal_tours_cost_the_published_optima(name):
    tsp = load_tsplib(STORED / f"{name}.tsp")
    numbers = (STORED / f"{name}.opt.tour").read_text().split("TOUR_SECTION")[1].split()
    tour = [int(v) - 1 for v in itertools.takewhile(lambda v: v not in ("-1", "EOF"), numbers)]
    assert sorted(tour) == list(range(tsp.dimension))
    # priced by the reader's matrix and, independently, by EUC_2D's rule on the coordinates
    xy = tsp.coords
    by_hand = sum(math.floor(math.dist(xy[a], xy[b]) + 0.5) for a, b in zip(tour, tour[1:] + tour[:1]))
    by_matrix = sum(tsp.cost[a, b] for a, b in zip(tour, tour[1:] + tour[:1]))
    assert by_hand == by_matrix == STORED_OPTIMA[name]
