"""Nazarahari et al. 2019's study: the paper's Table 2 as read (garbles kept), the paper's rows run by
the paper's algorithms (the EGA as published, linear and spline) with ours beside them, a small run's
report with every section, and its command-line entry."""

import pytest

from htetro_opt.algorithms import EGA_ADDITIONS
from htetro_opt.solvers.continuous import SPEC
from htetro_opt.studies import nazarahari2019 as study

OURS = {label for label in study.METHODS if label.endswith("(ours)")}


def test_paper_table2_has_every_map_and_row_and_the_brrt_failures():
    assert set(study.PAPER_TABLE2) == set(study.MAPS)
    for name, rows in study.PAPER_TABLE2.items():
        assert set(rows) == set(study.METHODS) - OURS, name
        assert all(len(r) == 7 for r in rows.values())
    failed = {n for n, rows in study.PAPER_TABLE2.items() if rows["B-RRT"][6] == 0}
    assert failed == {"ega02_maze1", "ega03_home", "ega09_maze2", "ega10_maze3"}
    assert study.PAPER_TABLE2["ega01_random1"]["A* 1"][0] == 35.79
    assert study.PAPER_TABLE2["ega04_corridor1"]["EGA spline"][:2] == (33.57, 0.2)  # printed so


def test_the_papers_rows_run_the_papers_algorithms_and_ours_stand_beside_them():
    for label, (method, options) in study.METHODS.items():
        origin = SPEC.methods[method].origin
        assert origin == "ours" if label in OURS else origin in ("paper", "baseline"), label
    assert study.METHODS["EGA linear"] == ("ega-paper", {}) and study.METHODS["EGA spline"] == (
        "ega-paper", {"path": "spline"})
    assert [study.METHODS[label] for label in sorted(OURS)] == [("ega", {}), ("ega", {"path": "spline"})]
    assert SPEC.methods[study.PAIRS_METHOD].origin == "paper"
    assert {m for _, m in study.NORMALISED} == {m for _, m in study.CROSS4} == {"ega-paper", "ega"}


def test_a_small_run_reports_every_section(tmp_path):
    run = study.run_nazarahari2019(1, maps=("ega07_slits1",), methods=("A* 1", "PRM", "EGA linear",
                                                                       "ega linear (ours)"), pairs=((20, 10),))
    text = study.report(run)
    for words in ("## Table 2", "ega07_slits1 (exact optimum 64.43)", "| EGA linear | 64.43 ± 0.00 | +0.00",
                  "| ega linear (ours) | 64.43 ± 0.00 | +0.00", "## §5.1", "## Four robots",
                  "- EGA (ega-paper): ", "- ega (ours): "):
        assert words in text, words
    additions = {r["method"]: r["additions"] for r in run.table2 + run.cross4}
    assert additions == {"A* 1": [], "PRM": [], "EGA linear": [], "EGA (ega-paper)": [],
                         "ega linear (ours)": list(EGA_ADDITIONS), "ega (ours)": list(EGA_ADDITIONS)}
    assert all(r["additions"] == [] for r in run.pairs)
    assert "§5.3" not in text  # map 4 not in this run
    ok = [r for r in run.table2 if r["reached"]]
    assert all(r["length"] >= run.exact["ega07_slits1"] - 1e-9 for r in ok)
    md, table = study.write_report(tmp_path, run)
    assert md.read_text() == text and table.read_text().count("\n") == 1 + len(run.table2) + len(run.pairs)


def test_the_normalised_section_and_the_a_star_note():
    run = study.run_nazarahari2019(1, maps=("ega04_corridor1",), methods=("A* 1", "A* 0.25"), pairs=(),
                                   cross4=False, jobs=1)
    text = study.report(run)
    assert "Our A* 0.25 equals our A* 1 on 1 of 1 maps" in text and "| EGA (ega-paper) | 1 |" in text
    assert {r["method"]: r["additions"] for r in run.normalised} == {"EGA (ega-paper)": [],
                                                                      "ega (ours)": list(EGA_ADDITIONS)}
    exact = run.exact["ega04_corridor1"]
    for r in run.table2:  # deletion never lengthens a path nor cuts below the optimum
        assert exact - 1e-9 <= r["smoothed"] <= r["length"] + 1e-9
    for r in run.normalised:  # the reported terms are the weights times the plan's own measures
        assert r["terms"][2] == pytest.approx(r["weights"][2] / r["safety"])
        assert r["single"]["length"] == pytest.approx(exact, rel=1e-6)


def test_the_command_line_names_bad_seeds(capsys):
    from htetro_opt.cli import main

    assert main(["study", "nazarahari2019", "--seeds", "0"]) == 2
    assert "--seeds" in capsys.readouterr().err


@pytest.mark.slow
def test_the_papers_fifty_seeds():
    run = study.run_nazarahari2019(50)
    ega = [r for r in run.table2 if r["method"] == "ega linear (ours)"]
    assert all(r["reached"] for r in ega)
    assert all(r["length"] <= 1.005 * run.exact[r["map"]] for r in ega)


def test_worker_processes_give_the_same_records_and_the_pairs_run_on_the_first_seeds():
    options = {"maps": ("ega04_corridor1",), "methods": ("A* 1", "EGA linear"), "pairs": ((20, 10),),
               "pair_seeds": 1, "normalised": False, "cross4": False}
    here = study.run_nazarahari2019(2, jobs=1, **options)
    pool = study.run_nazarahari2019(2, jobs=2, **options)

    def strip(records):
        return [{k: v for k, v in r.items() if k != "runtime"} for r in records]

    assert strip(here.table2) == strip(pool.table2) and strip(here.pairs) == strip(pool.pairs)
    assert [(r["method"], r["seed"]) for r in here.table2] == [("A* 1", 0), ("EGA linear", 0), ("EGA linear", 1)]
    assert [r["seed"] for r in here.pairs] == [0]
    assert not here.normalised and not here.cross4 and "ega_cross4" not in here.exact
    assert "§5.1: (IS, PS) pairs, EGA linear as published (ega-paper), 1 seed " in study.report(here)


def test_the_ablation_study_runs_the_paper_each_addition_alone_and_ours():
    from htetro_opt.studies.runner import Study, load_study, run_study

    ablation = load_study("nazarahari2019_ablation")
    entries = [(m.method, m.options.get("additions")) for m in ablation.methods]
    assert entries[0] == ("ega-paper", None) and entries[-1] == ("ega", None)
    assert [(m, list(a)) for m, a in entries[1:-1]] == [("ega-paper", [name]) for name in EGA_ADDITIONS]
    assert set(ablation.scenarios) <= set(study.MAPS) and "gap" in ablation.metrics
    # the same entries on one map, one seed, two generations: every record says what ran, none beats the optimum
    small = Study(name="ablation_small", task="plan", scenarios=["ega08_slits2"], seeds=1, metrics=["gap"],
                  methods=[{**m.as_entry(), "max_gen": 2} for m in ablation.methods])
    records = [r for r in run_study(small, executor="serial").records if r["kind"] == "trial"]
    assert [r["additions"] for r in records] == [[], *([name] for name in EGA_ADDITIONS), list(EGA_ADDITIONS)]
    assert all(r["reached"] and r["gap"] >= -1e-9 for r in records)
