"""The Table-4 study: the paper's numbers, one trial's record, the aggregation, the files and the CLI."""

import math
import os
import re
from pathlib import Path

import pytest

from htetro_opt.errors import ParameterError
from htetro_opt.scenarios import load_scenario
from htetro_opt.solvers import plan_exact
from htetro_opt.studies import format_mean_std, mean_std, table4, values_of
from htetro_opt.studies.table4 import (
    ENVIRONMENTS,
    MAX_LENGTH,
    PAPER_TABLE4,
    RECORD_FIELDS,
    TABLE4_COLUMNS,
    TIME_FIELDS,
    main,
    markdown_table,
    read_csv,
    run_study,
    run_trial,
    summarise,
    write_csv,
)

PAPER = Path("/work/shared/seeds/000_51d82c02672dadf4.txt")


# --- the paper's table ---------------------------------------------------------------------------
def test_paper_table_shape():
    assert tuple(PAPER_TABLE4) == ENVIRONMENTS
    for env in ENVIRONMENTS:
        assert sorted(PAPER_TABLE4[env]) == [25, 50, 100]
        for n in (25, 50, 100):
            cell = PAPER_TABLE4[env][n]
            assert tuple(cell) == TABLE4_COLUMNS and len(cell) == 8
            assert all(len(pair) == 2 and all(isinstance(v, float) for v in pair) for pair in cell.values())
            assert cell["f_gr"] == (1.0, 0.0)


def test_paper_table_spot_checks():
    assert PAPER_TABLE4["three_slit"][50]["reach_generation"] == (210.60, 27.56)
    assert PAPER_TABLE4["random"][100]["f_t"] == (0.633, 0.014)
    assert PAPER_TABLE4["perpendicular_dynamic"][50]["reach_generation"] == (1.12, 0.324)
    assert PAPER_TABLE4["random"][25]["f_t"] == (0.556, 0.992)  # as printed


@pytest.mark.skipif(not PAPER.is_file(), reason="the paper's text is not available")
def test_paper_table_matches_the_text_everywhere():
    lines = PAPER.read_text(encoding="utf-8").splitlines()
    first = next(i for i, line in enumerate(lines) if line.startswith("Random\t"))
    rows = lines[first : first + 18]
    for k, line in enumerate(rows):
        env, n = ENVIRONMENTS[k // 3], (25, 50, 100)[k % 3]
        fields = line.split("\t")
        assert re.findall(r"\d+", fields[1])[-1] == str(n)
        numbers = [tuple(float(v) for v in re.findall(r"\d+(?:\.\d+)?", f)) for f in fields[2:10]]
        assert [PAPER_TABLE4[env][n][c] for c in TABLE4_COLUMNS] == numbers, (env, n)


def test_max_length_follows_the_paper():
    assert set(TIME_FIELDS) <= set(RECORD_FIELDS)
    assert MAX_LENGTH == {e: 200 if e == "spiral" else 100 for e in ENVIRONMENTS}


# --- one trial -----------------------------------------------------------------------------------
@pytest.mark.parametrize("environment, optimum", [("three_slit", 33.0), ("random", 36.0)])
def test_run_trial_record(environment, optimum):
    record = run_trial(environment, 25, 0, max_gen=40)
    assert tuple(record) == RECORD_FIELDS
    assert (record["environment"], record["pop_size"], record["seed"], record["algorithm"]) == (
        environment, 25, 0, "htetro")
    scenario = load_scenario(environment)
    exact = plan_exact(scenario.workspace, scenario.roadmap)
    assert exact.time == optimum
    assert record["exact_time"] == optimum
    assert 1 <= record["terminate_generation"] <= 40
    assert record["terminate_time_s"] > 0
    assert 0.0 <= record["f_gr"] <= 1.0
    if record["reached"]:
        assert record["f_gr"] == 1.0
        assert record["best_time"] >= optimum  # nothing beats the exact optimum
        assert math.isclose(record["gap"], (record["best_time"] - optimum) / optimum)
        assert record["f_t_gap"] >= 0
        assert 1 <= record["reach_generation"] <= record["terminate_generation"]
    else:
        assert record["f_gr"] < 1.0
        for key in ("reach_generation", "reach_time_s", "best_time", "gap", "f_t_gap", "plan_time"):
            assert record[key] is None


def test_failed_multi_leg_trial_still_has_the_exact_reference():
    # One short leg-1 attempt fails; legs never attempted are planned exactly on the exact plan's own
    # clock, so the reference is the whole roadmap's optimum.
    record = run_trial("perpendicular_dynamic", 4, 0, max_gen=2, algorithm="htetro-paper")
    assert (record["legs"], record["legs_run"], record["reached"]) == (3, 1, False)
    assert record["exact_time"] == 36.0  # plan_exact over the whole roadmap (benchmarks/README.md)
    assert record["gap"] is None and record["best_time"] is None


def test_run_trial_is_deterministic_and_validates():
    a = run_trial("three_slit", 12, 3, max_gen=5)
    b = run_trial("three_slit", 12, 3, max_gen=5)
    assert {k: v for k, v in a.items() if k not in TIME_FIELDS} == {
        k: v for k, v in b.items() if k not in TIME_FIELDS}
    with pytest.raises(ParameterError, match="maze"):
        run_trial("maze", 25, 0)
    with pytest.raises(ParameterError, match="pop_size"):
        run_trial("random", 1, 0)
    with pytest.raises(ParameterError, match="algorithm"):
        run_trial("random", 25, 0, algorithm="pso")


def test_run_study_validates_before_running():
    with pytest.raises(ParameterError, match="'nowhere'"):
        run_study(["three_slit", "nowhere"], [12], range(1))
    with pytest.raises(ParameterError, match="seeds"):
        run_study(["three_slit"], [12], [])
    with pytest.raises(ParameterError, match="jobs"):
        run_study(["three_slit"], [12], range(1), jobs=0)


def test_parallel_study_gives_the_same_records():
    calls = []
    serial = run_study(["three_slit"], [12], range(2), max_gen=5)
    parallel = run_study(["three_slit"], [12], range(2), max_gen=5, jobs=2,
                         progress=lambda done, total, record: calls.append((done, total)))
    assert [r["seed"] for r in parallel] == [0, 1]
    strip = lambda rs: [{k: v for k, v in r.items() if k not in TIME_FIELDS} for r in rs]
    assert strip(serial) == strip(parallel)
    assert sorted(calls) == [(1, 2), (2, 2)]


# --- aggregation ---------------------------------------------------------------------------------
def _synthetic():
    base = dict(algorithm="htetro", max_gen=1000, patience=100, max_length=100, legs=1, legs_run=1,
                exact_time=33.0, f_gr=1.0, reached=True, f_sm=0.5, f_sf=0.25)
    rows = [
        dict(base, environment="three_slit", pop_size=50, seed=0, reach_generation=100,
             terminate_generation=200, reach_time_s=1.0, terminate_time_s=2.0, f_t=0.6,
             best_time=36.0, gap=3 / 33, plan_time=40.0),
        dict(base, environment="three_slit", pop_size=50, seed=1, reach_generation=300,
             terminate_generation=400, reach_time_s=3.0, terminate_time_s=4.0, f_t=0.7,
             best_time=33.0, gap=0.0, plan_time=33.0),
        dict(base, environment="three_slit", pop_size=50, seed=2, reached=False, f_gr=0.5, f_t=0.9,
             reach_generation=None, reach_time_s=None, terminate_generation=1000, terminate_time_s=9.0,
             best_time=None, gap=None, plan_time=None),
        dict(base, environment="random", pop_size=25, seed=0, reach_generation=3, terminate_generation=30,
             reach_time_s=0.5, terminate_time_s=1.5, f_t=0.64, best_time=36.0, exact_time=36.0, gap=0.0,
             plan_time=36.0),
    ]
    return rows


def test_metrics_helpers():
    assert mean_std([1.0, 2.0, 3.0, None]) == (2.0, 1.0)
    assert mean_std([1.0, 3.0], ddof=0) == (2.0, 1.0)
    assert mean_std([5.0]) == (5.0, None) and mean_std([None]) == (None, None)
    assert values_of([{"a": 1}, {"a": None}, {"a": float("nan")}, {}], "a") == [1.0]
    assert format_mean_std(210.6, 27.56) == "210.60 ± 27.56"
    assert format_mean_std(None) == "–"
    with pytest.raises(ParameterError):
        mean_std([1.0], ddof=2)


def test_summarise_synthetic():
    rows = summarise(_synthetic())
    assert [(r["environment"], r["pop_size"]) for r in rows] == [("random", 25), ("three_slit", 50)]
    slit = rows[1]
    assert (slit["runs"], slit["reached"]) == (3, 2)
    assert math.isclose(slit["reach_rate"], 2 / 3)
    assert (slit["reach_generation_mean"], slit["reach_generation_std"]) == (200.0, pytest.approx(math.sqrt(2) * 100))
    assert slit["terminate_generation_mean"] == pytest.approx(1600 / 3)  # failed runs count for the cost
    assert slit["terminate_generation_std"] == pytest.approx(mean_std([200, 400, 1000])[1])
    assert slit["f_gr_mean"] == pytest.approx(2.5 / 3)
    assert slit["f_t_mean"] == pytest.approx(0.65)  # quality over the runs that reached
    assert slit["f_t_std"] == pytest.approx(math.sqrt(0.005))
    assert slit["best_time_mean"] == 34.5 and slit["exact_time_mean"] == 33.0
    assert slit["gap_mean"] == pytest.approx(1.5 / 33) and slit["gap_max"] == pytest.approx(3 / 33)
    assert (slit["paper_reach_generation_mean"], slit["paper_reach_generation_std"]) == (210.60, 27.56)
    assert rows[0]["reach_generation_std"] is None  # one run: no spread
    assert slit["algorithm"] == "htetro"
    unknown = summarise([dict(_synthetic()[0], environment="maze")])
    assert unknown[0]["paper_f_t_mean"] is None
    mixed = summarise(_synthetic() + [dict(_synthetic()[0], algorithm="nsga2")])
    assert [(r["environment"], r["algorithm"], r["runs"]) for r in mixed] == [
        ("random", "htetro", 1), ("three_slit", "htetro", 3), ("three_slit", "nsga2", 1)]


def test_markdown_table_synthetic():
    text = markdown_table(summarise(_synthetic()))
    lines = text.strip().splitlines()
    assert len(lines) == 4
    assert lines[0].startswith("| environment | n_pop | runs | reached | reach gen, ours (paper) |")
    assert lines[0].count("|") == lines[1].count("|") == lines[3].count("|")
    slit = lines[3]
    assert slit.startswith("| three_slit | 50 | 3 | 2/3 | 200.00 ± 141.42 (210.60 ± 27.56) |")
    assert "| 0.650 ± 0.071 (0.442 ± 0.031) |" in slit
    assert slit.endswith("| 33 | 34.5 ± 2.1 | 4.5 % (max 9.1 %) |")
    assert "| random | 25 | 1 | 1/1 | 3.00 (2.88 ± 0.49) |" in lines[2]
    mixed = markdown_table(summarise(_synthetic() + [dict(_synthetic()[0], algorithm="nsga2")])).splitlines()
    assert mixed[0].startswith("| environment | n_pop | algorithm | runs | reached |")
    assert mixed[4].startswith("| three_slit | 50 | nsga2 | 1 | 1/1 |")
    assert len({line.count("|") for line in mixed}) == 1


def test_write_and_read_csv(tmp_path):
    records = _synthetic()
    path = write_csv(records, tmp_path / "t.csv")
    lines = path.read_text().splitlines()
    assert lines[0].split(",") == list(RECORD_FIELDS)
    assert len(lines) == 1 + len(records)
    back = read_csv(path)
    assert [{k: r.get(k) for k in RECORD_FIELDS} for r in records] == back
    assert os.listdir(tmp_path) == ["t.csv"]


def test_writes_are_atomic(tmp_path, monkeypatch):
    path = tmp_path / "t.csv"
    path.write_text("old\n")

    def broken(src, dst):
        raise OSError("disk full")

    monkeypatch.setattr(table4.os, "replace", broken)
    with pytest.raises(OSError, match="disk full"):
        write_csv(_synthetic(), path)
    assert path.read_text() == "old\n"
    assert os.listdir(tmp_path) == ["t.csv"]  # no temporary file left behind


# --- command line --------------------------------------------------------------------------------
def test_main_bad_environment(capsys):
    assert main(["--envs", "three_slit,atlantis", "--seeds", "1"]) == 2
    out, err = capsys.readouterr()
    assert out == ""
    assert len(err.strip().splitlines()) == 1
    assert err.startswith("error: ") and "atlantis" in err


@pytest.mark.parametrize("argv", [["--pop-sizes", "25,x"], ["--seeds", "0"], ["--jobs", "0"], ["--bogus"]])
def test_main_usage_errors(argv, capsys):
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and err.startswith("error: ")


def test_main_writes_files(tmp_path, capsys):
    out_dir = tmp_path / "out"
    assert main(["--envs", "three_slit", "--pop-sizes", "12", "--seeds", "1", "--max-gen", "5",
                 "--out", str(out_dir)]) == 0
    printed = capsys.readouterr().out
    assert sorted(os.listdir(out_dir)) == ["table4.csv", "table4.md"]
    assert (out_dir / "table4.md").read_text() == printed
    assert "| three_slit | 12 | 1 |" in printed
    assert read_csv(out_dir / "table4.csv")[0]["exact_time"] == 33.0


@pytest.mark.slow
@pytest.mark.parametrize("environment, optimum", [("three_slit", 33.0), ("perpendicular_dynamic", 36.0)])
def test_reaches_with_the_paper_budget(environment, optimum):
    record = run_trial(environment, 50, 0, max_gen=300)
    assert record["reached"] and record["f_gr"] == 1.0
    assert record["best_time"] >= record["exact_time"] == optimum
    assert record["gap"] >= 0.0 and record["f_t_gap"] >= 0.0
    assert record["reach_generation"] <= record["terminate_generation"]
