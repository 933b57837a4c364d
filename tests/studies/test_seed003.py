"""The study of Le et al. 2018 (Tables 1–5): records, gaps to the optimum, the report and the command line."""

import csv
from itertools import pairwise

import numpy as np
import pytest

from htetro_opt.cli import main as cli_main
from htetro_opt.errors import ParameterError
from htetro_opt.problems import SequencingInstance
from htetro_opt.solvers.sequencing import held_karp
from htetro_opt.studies import seed003


def eq2_cost(tileset, tiles, weights=(0.25,) * 4):
    """Eq. 2 summed along an order of tile labels, block by block (by hand)."""
    blocks = {t: np.asarray(b, dtype=float) for t, b in zip(tileset.ids, tileset.blocks)}
    return sum(w * float(np.hypot(*(blocks[a][k] - blocks[b][k])))
               for a, b in pairwise(tiles) for k, w in enumerate(weights))


@pytest.fixture(scope="module")
def fig13b():
    return seed003.paper_tileset("paper_8x7_fig13b")


@pytest.fixture(scope="module")
def table1(fig13b):
    return seed003.run_table1(fig13b, seeds=[0, 1], methods=("zigzag", "greedy", "ga-plain", "ga", "exact"))


def test_table1_gaps_are_measured_against_the_proven_optimum(fig13b, table1):
    # 14 waypoints: Held–Karp gives the optimum independently of CP-SAT
    _, truth = held_karp(SequencingInstance.from_tileset(fig13b, start=1).cost, start=0)
    optimum = [r for r in table1 if r["method"] == "exact"][0]
    assert optimum["proven"] and optimum["gap_pct"] == 0
    assert optimum["cost"] == pytest.approx(truth, rel=1e-9)
    for r in table1:
        assert r["order"][0] == 1 and sorted(r["order"]) == list(range(1, 15))
        cost = eq2_cost(fig13b, r["order"])
        assert r["cost"] == pytest.approx(cost) and r["optimum"] == pytest.approx(truth, rel=1e-9)
        assert r["gap_pct"] == pytest.approx(100 * (cost - truth) / truth, abs=1e-6)
    assert [r["seed"] for r in table1 if r["method"] == "greedy"] == [0, 1]  # stochastic: one run per seed
    assert [r["seed"] for r in table1 if r["method"] == "zigzag"] == [0]


def test_table2_prices_each_weight_settings_optimum_with_equal_weights(fig13b):
    rows = seed003.run_table2(fig13b)
    assert [r["weights"] for r in rows] == [",".join(f"{w:g}" for w in ws) for ws, *_ in seed003.PAPER_TABLE2]
    equal = rows[-1]
    for r, (weights, *_) in zip(rows, seed003.PAPER_TABLE2):
        assert r["proven"]
        # each setting's optimum, against Held–Karp on that setting's costs
        own = SequencingInstance.from_tileset(fig13b, start=1, weights=weights)
        assert r["cost_own"] == pytest.approx(held_karp(own.cost, start=0)[1], rel=1e-9)
        # the equal-weight optimum is the cheapest path at equal weights
        assert r["cost_four"] >= equal["cost_four"] - 1e-9


def test_table45_covers_every_method_on_one_scale(fig13b, table1):
    rows = seed003.run_table45(fig13b, table1)
    assert [r["method"] for r in rows] == ["zigzag", "greedy", "ga-plain", "ga", "exact"]
    for r in rows:
        # the mean block distance is the eq.-2 cost at equal weights
        assert r["distance_cells"] == pytest.approx(r["cost"])
        assert r["distance_cm"] == pytest.approx(25.0 * r["cost"])
        assert 0 <= r["recovered_150"] <= r["recovered_100"] <= 100
    exact = rows[-1]
    assert all(exact["distance_cells"] <= r["distance_cells"] + 1e-9 for r in rows)


def test_report_puts_the_papers_numbers_beside_ours_and_csv_round_trips(tmp_path, fig13b, table1):
    records = table1 + seed003.run_table45(fig13b, table1)
    report = seed003.markdown_report(records)
    assert "### Table 1 on paper_8x7_fig13b" in report and "62.368" in report  # the paper's GA
    assert "Tables 4–5" in report and "1890" in report
    path = seed003.write_csv(records, tmp_path / "s.csv")
    rows = list(csv.DictReader(path.open()))
    assert len(rows) == len(records) and rows[0]["method"] == "zigzag"


def test_bad_seeds_and_command_line_errors(capsys):
    with pytest.raises(ParameterError, match="seeds"):
        seed003.run_table1(None, seeds=[])
    for bad in (-1, 1.5, True):
        with pytest.raises(ParameterError, match=r"seeds\[1\] must be a non-negative integer"):
            seed003.run_table1(None, seeds=[0, bad])
    assert cli_main(["study", "seed003", "--seeds", "0"]) == 2
    assert cli_main(["study", "seed003", "--time-limit", "-1"]) == 2
    assert cli_main(["study", "seed003", "--time-limit", "inf"]) == 2
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 3 and all(line.startswith("error: ") for line in err)
    assert "--seeds" in err[0] and all("--time-limit" in line for line in err[1:])


@pytest.mark.slow
def test_the_whole_study_runs_and_writes_its_files(tmp_path):
    assert cli_main(["study", "seed003", "--seeds", "1", "--out", str(tmp_path)]) == 0
    assert (tmp_path / "seed003.md").read_text().count("### Table") >= 4
