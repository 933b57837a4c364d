"""The study of Le et al. 2018 (Tables 1–5): records, gaps to the optimum, the report and the command line."""

import csv
from itertools import pairwise

import numpy as np
import pytest

from htetro_opt.cli import main as cli_main
from htetro_opt.errors import ParameterError
from htetro_opt.problems import SequencingInstance
from htetro_opt.solvers.sequencing import held_karp
from htetro_opt.studies import le2018
from htetro_opt.solvers.sequencing import SPEC as SEQUENCING
from htetro_opt.studies.runner import StudyRun, load_study, run_study


def eq2_cost(tileset, tiles, weights=(0.25,) * 4):
    """Eq. 2 summed along an order of tile labels, block by block (by hand)."""
    blocks = {t: np.asarray(b, dtype=float) for t, b in zip(tileset.ids, tileset.blocks)}
    return sum(w * float(np.hypot(*(blocks[a][k] - blocks[b][k])))
               for a, b in pairwise(tiles) for k, w in enumerate(weights))


@pytest.fixture(scope="module")
def fig13b():
    return le2018.paper_tileset("paper_8x7_fig13b")


@pytest.fixture(scope="module")
def table1(fig13b):
    return le2018.run_table1(fig13b, seeds=[0, 1], methods=("zigzag", "greedy", "ga-plain", "ga", "exact"))


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
    rows = le2018.run_table2(fig13b)
    assert [r["weights"] for r in rows] == [",".join(f"{w:g}" for w in ws) for ws, *_ in le2018.PAPER_TABLE2]
    equal = rows[-1]
    for r, (weights, *_) in zip(rows, le2018.PAPER_TABLE2):
        assert r["proven"]
        # each setting's optimum, against Held–Karp on that setting's costs
        own = SequencingInstance.from_tileset(fig13b, start=1, weights=weights)
        assert r["cost_own"] == pytest.approx(held_karp(own.cost, start=0)[1], rel=1e-9)
        # the equal-weight optimum is the cheapest path at equal weights
        assert r["cost_four"] >= equal["cost_four"] - 1e-9


def test_table45_covers_every_method_on_one_scale(fig13b, table1):
    rows = le2018.run_table45(fig13b, table1)
    assert [r["method"] for r in rows] == ["zigzag", "greedy", "ga-plain", "ga", "exact"]
    for r in rows:
        # the mean block distance is the eq.-2 cost at equal weights
        assert r["distance_cells"] == pytest.approx(r["cost"])
        assert r["distance_cm"] == pytest.approx(25.0 * r["cost"])
        assert 0 <= r["recovered_150"] <= r["recovered_100"] <= 100
    exact = rows[-1]
    assert all(exact["distance_cells"] <= r["distance_cells"] + 1e-9 for r in rows)


def test_report_puts_the_papers_numbers_beside_ours_and_csv_round_trips(tmp_path, fig13b, table1):
    records = table1 + le2018.run_table45(fig13b, table1)
    report = le2018.markdown_report(records)  # the paper's Tables 1, 4, 5 are of its 11 x 11 map, not this 8 x 7
    assert "### Table 1 on paper_8x7_fig13b" in report and "62.368" not in report and "1890" not in report
    as_if = le2018.markdown_report([{**r, "paper_map": True} for r in records])  # laid out as on the 11 x 11
    assert "62.368" in as_if and "Tables 4–5" in as_if and "1890" in as_if  # the paper's GA
    path = le2018.write_csv(records, tmp_path / "s.csv")
    rows = list(csv.DictReader(path.open()))
    assert len(rows) == len(records) and rows[0]["method"] == "zigzag"


def test_bad_seeds_and_command_line_errors(capsys):
    with pytest.raises(ParameterError, match="seeds"):
        le2018.run_table1(None, seeds=[])
    for bad in (-1, 1.5, True):
        with pytest.raises(ParameterError, match=r"seeds\[1\] must be a non-negative integer"):
            le2018.run_table1(None, seeds=[0, bad])
    assert cli_main(["study", "le2018", "--seeds", "0"]) == 2
    assert cli_main(["study", "le2018", "--time-limit", "-1"]) == 2
    assert cli_main(["study", "le2018", "--time-limit", "inf"]) == 2
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 3 and all(line.startswith("error: ") for line in err)
    assert "--seeds" in err[0] and all("--time-limit" in line for line in err[1:])


@pytest.mark.slow
def test_the_whole_study_runs_and_writes_its_files(tmp_path):
    assert cli_main(["study", "le2018", "--seeds", "1", "--out", str(tmp_path)]) == 0
    assert (tmp_path / "le2018_paper.md").read_text().count("### Table") >= 4


# --- on the study runner ---------------------------------------------------------------------------
RUNNER_METHODS = ("zigzag", "spiral2", "greedy", "ga-plain", "ga", "local", "exact")


@pytest.fixture(scope="module")
def runner_run():
    study = le2018.le2018_study([0, 1], methods=RUNNER_METHODS, scenarios=["paper_8x7_fig13b"])
    return run_study(study, executor="serial")


def _without_runtimes(text):
    """The report's lines, Table 1's runtime column blanked (the only wall-clock numbers)."""
    out = []
    for line in text.splitlines():
        cells = line.split(" | ")
        if len(cells) == 6 and cells[2].endswith("%"):
            cells[3] = "T"
        out.append(" | ".join(cells))
    return out


def test_the_bundled_study_is_the_builders():
    study = load_study("le2018")
    assert study == le2018.le2018_study()
    assert study.task == "sequence" and study.metrics == ("gap",)
    assert study.scenarios == le2018.TABLE1_SCENARIOS + le2018.TABLE2_SCENARIOS
    labels = [m.label for m in study.methods]
    assert labels[:len(le2018.TABLE1_METHODS)] == list(le2018.TABLE1_METHODS)
    assert [m.options["weights"] for m in study.methods[len(le2018.TABLE1_METHODS):]] == \
        [list(w) for w, *_ in le2018.PAPER_TABLE2]


def test_the_runner_path_gives_the_old_paths_numbers(fig13b, runner_run):
    old1 = le2018.run_table1(fig13b, seeds=[0, 1], methods=RUNNER_METHODS)
    seeded = {m for m in RUNNER_METHODS if SEQUENCING.method(m).draws()}  # the spec says which draw from the seed
    old = {(r["method"], r["seed"] if r["method"] in seeded else None): r for r in old1}
    table1 = [r for r in runner_run.records if r.get("weights") is None]
    assert all(r["error"] is None for r in runner_run.records)
    assert {(r["label"], r["seed"]) for r in table1} == set(old)
    for r in table1:
        mine = old[r["label"], r["seed"]]
        assert r["cost"] == pytest.approx(mine["cost"], rel=1e-12)
        assert r["order"] == ",".join(map(str, mine["order"]))
        assert 100 * r["gap"] == pytest.approx(mine["gap_pct"], abs=1e-9)
    weighted = [r for r in runner_run.records if r.get("weights") is not None]
    old2 = le2018.run_table2(fig13b)
    assert [r["cost"] for r in weighted] == pytest.approx([r["cost_own"] for r in old2], rel=1e-9)

    # the report is today's, Tables 2 and 4–5 to the digit, Table 1 but for its runtimes
    text = le2018.report(runner_run)
    expected = le2018.markdown_report(old1 + old2 + le2018.run_table45(fig13b, old1))
    assert _without_runtimes(text) == _without_runtimes(expected)
    assert "### Table 1 on paper_8x7_fig13b" in text
    # the paper's Tables 1, 2 and 4-5 are of its 11 x 11 and 10 x 10 maps: no number of theirs beside the 8 x 7
    assert "62.368" not in text and "1890" not in text and "55.435" not in text and "not this one" in text


def test_the_report_takes_table3_and_lists_failed_trials(runner_run):
    table3 = [{"table": 3, "workspace": "tiling_8x7", "tileset": "x", "shapes": "IJ", "tiles": 14,
               "cost": 17.0, "paper": 30.761, "proven": True}]
    failed = dict(runner_run.records[0], error="TimeoutError: over")
    run = StudyRun(runner_run.study, [failed] + runner_run.records[1:], runner_run.references,
                   runner_run.summary, None)
    text = le2018.report(run, table3=table3)
    assert text.index("### Table 2") < text.index("### Table 3") < text.index("### Tables 4–5")
    assert "| tiling_8x7 | x | IJ | 14 | 17.000 | 30.761 |" in text
    assert text.rstrip().endswith("- paper_8x7_fig13b zigzag: TimeoutError: over")
    assert "Zigzag 1 row" not in text.split("### Table 2")[0]
    with pytest.raises(ParameterError, match="StudyRun"):
        le2018.report(runner_run.records)
    with pytest.raises(ParameterError, match="run_table3"):
        le2018.report(runner_run, table3=[{"table": 1}])
