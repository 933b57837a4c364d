"""Seed 003's study (Tables 1–5): records, gaps to the optimum, the report and the command line."""

import csv

import pytest

from htetro_opt.errors import ParameterError
from htetro_opt.studies import seed003


@pytest.fixture(scope="module")
def fig13b():
    return seed003.paper_tileset("paper_8x7_fig13b")


@pytest.fixture(scope="module")
def table1(fig13b):
    return seed003.run_table1(fig13b, seeds=[0, 1], methods=("zigzag", "greedy", "ga-plain", "ga", "exact"))


def test_table1_gaps_are_measured_against_the_proven_optimum(table1):
    optimum = [r for r in table1 if r["method"] == "exact"][0]
    assert optimum["proven"] and optimum["gap_pct"] == 0
    for r in table1:
        assert r["optimum"] == optimum["cost"]
        assert r["cost"] >= optimum["cost"] - 1e-9  # nothing beats a proven optimum
        assert r["gap_pct"] == pytest.approx(100 * (r["cost"] - optimum["cost"]) / optimum["cost"])
        assert r["order"][0] == 1 and sorted(r["order"]) == list(range(1, 15))
    assert [r["seed"] for r in table1 if r["method"] == "greedy"] == [0, 1]  # stochastic: one run per seed
    assert [r["seed"] for r in table1 if r["method"] == "zigzag"] == [0]


def test_table2_prices_each_weight_settings_optimum_with_equal_weights(fig13b):
    rows = seed003.run_table2(fig13b)
    assert len(rows) == len(seed003.PAPER_TABLE2)
    equal = rows[-1]
    assert equal["cost_own"] == pytest.approx(equal["cost_four"])
    for r in rows:
        assert r["proven"]
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
    assert seed003.main(["--seeds", "0"]) == 2
    assert seed003.main(["--time-limit", "-1"]) == 2
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 2 and all(line.startswith("error: ") for line in err)


@pytest.mark.slow
def test_the_whole_study_runs_and_writes_its_files(tmp_path):
    assert seed003.main(["--seeds", "1", "--out", str(tmp_path)]) == 0
    assert (tmp_path / "seed003.md").read_text().count("### Table") >= 4
