"""The study of Cheng et al. 2019 (Table 2 and beyond): the runner's cover task, the report and the command line."""

import csv
import json
import math

import numpy as np
import pytest

from htetro_opt.cli import main as cli_main
from htetro_opt.errors import ParameterError
from htetro_opt.model import (
    FOOTPRINTS,
    SEED004_COMMANDS,
    Simulator,
    parse_commands,
    shape_index,
)
from htetro_opt.scenarios import load_scenario
from htetro_opt.solvers.coverage import plan_coverage
from htetro_opt.studies import cheng2019
from htetro_opt.studies.runner import (
    METRICS,
    TASKS,
    Study,
    StudyError,
    load_study,
    run_reference,
    run_trial,
)

COVER = 'task = "cover"\nscenarios = ["coverage_16x7", "coverage_16x16"]\n[[methods]]\nmethod = "stripes"\n'


def _file(tmp_path, text, name="study.toml"):
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


# A tiny cheng2019-shaped study: a few Table-2 rows by both planners, the 16 x 7 map and the baselines.
SMALL = """name = "cheng2019"
task = "cover"
scenarios = ["coverage_16x16", "coverage_16x7"]
metrics = ["gap"]
[[methods]]
label = "stripes {O} N_str,1"
method = "stripes"
shapes = "O"
stripes = 3
scenarios = ["coverage_16x16"]
[[methods]]
label = "stripes {O} N_str,2"
method = "stripes"
shapes = "O"
stripes = 4
scenarios = ["coverage_16x16"]
[[methods]]
label = "stripes {vI} N_str,2"
method = "stripes"
shapes = "vI"
stripes = 4
scenarios = ["coverage_16x16"]
[[methods]]
label = "stripes {O,hI} N_str,1"
method = "stripes"
shapes = "O,hI"
stripes = 3
scenarios = ["coverage_16x16"]
[[methods]]
label = "stripes {O,vI,hI} N_str,2"
method = "stripes"
shapes = ["O", "vI", "hI"]
stripes = 4
scenarios = ["coverage_16x16"]
[[methods]]
label = "stripes-paper {O} N_str,2"
method = "stripes-paper"
shapes = "O"
stripes = 4
scenarios = ["coverage_16x16"]
[[methods]]
label = "stripes-paper {vI} N_str,2"
method = "stripes-paper"
shapes = "vI"
stripes = 4
scenarios = ["coverage_16x16"]
[[methods]]
label = "stripes-paper {vI} N_str,1"
method = "stripes-paper"
shapes = "vI"
stripes = 3
scenarios = ["coverage_16x16"]
[[methods]]
label = "stripes {vI,hI} N_str,2"
method = "stripes"
shapes = "vI,hI"
stripes = 4
scenarios = ["coverage_16x16"]
[[methods]]
label = "stripes {vI,hI} N_str,2 without sweep-order"
method = "stripes"
shapes = "vI,hI"
stripes = 4
additions = ["fixed-regions", "best-first", "greedy-fallback", "split-sweeps", "shortest-joins", "mopup"]
scenarios = ["coverage_16x16"]
[[methods]]
label = "stripes {O,hI} 2,3,2"
method = "stripes"
shapes = "O,hI"
stripes = "2,3,2"
scenarios = ["coverage_16x7"]
[[methods]]
label = "boustrophedon {O}"
method = "boustrophedon"
shapes = "O"
[[methods]]
label = "tiling-tsp {O}"
method = "tiling-tsp"
shapes = "O"
scenarios = ["coverage_16x16"]
"""

BAD = {
    "unknown layer": ('shapes = "O,Q"\n', ["shapes", "unknown layer 'Q'", "SHAPE@H"]),
    "layers not a string": ("shapes = 3\n", ["shapes", "'O,vI,hI'", "3"]),
    "stripes not summing to the height": ("stripes = [4, 4]\n", ["stripes", "[4, 4]", "sum to", "coverage_16x7"]),
    "stripe wider than the map": ("stripes = 12\n", ["stripes", "12", "coverage_16x7"]),
    "stripe width zero": ("stripes = 0\n", ["stripes", "0"]),
    "stripe widths not numbers": ('stripes = "2,x"\n', ["stripes", "'2,x'"]),
    "region columns zero": ("region_columns = 0\n", ["region_columns", "positive integer", "0"]),
    "budget zero": ("budget = 0\n", ["budget", "positive integer", "0"]),
    "time limit zero": ("time_limit = 0\n", ["time_limit"]),
    "time limit infinite": ("time_limit = inf\n", ["time_limit", "inf"]),
    "unknown start": ('start = "middle"\n', ["start", "'scenario'", "'auto'", "'middle'"]),
    "negative clearance": ("clearance = -1\n", ["clearance", "-1"]),
    "another task's option": ("pop_size = 10\n", ["takes no option 'pop_size'", "its options are shapes, start"]),
    "stripes for the boustrophedon": ('[[methods]]\nmethod = "boustrophedon"\nstripes = 4\n',
                                      ["methods[1]", "stripes applies to the stripes methods", "not to boustrophedon"]),
    "budget for tiling-tsp": ('[[methods]]\nmethod = "tiling-tsp"\nbudget = 100\n',
                              ["methods[1]", "budget", "not to tiling-tsp"]),
    "time limit for the boustrophedon": ('[[methods]]\nmethod = "boustrophedon"\ntime_limit = 5\n',
                                         ["methods[1]", "time_limit", "and tiling-tsp", "not to boustrophedon"]),
    "unknown ends": ('ends = "middle"\n', ["ends", "sweep, both", "'middle'"]),
    "unknown mop-up order": ('mopup = "random"\n', ["mopup", "sequenced, nearest", "'random'"]),
    "ends for the boustrophedon": ('[[methods]]\nmethod = "boustrophedon"\nends = "both"\n',
                                   ["methods[1]", "ends", "not to boustrophedon"]),
    "mop-up order for tiling-tsp": ('[[methods]]\nmethod = "tiling-tsp"\nmopup = "nearest"\n',
                                    ["methods[1]", "mopup", "not to tiling-tsp"]),
    "unknown method": ('[[methods]]\nmethod = "spiral"\n', ["methods[1]", "unknown cover method 'spiral'",
                                                           "boustrophedon"]),
    "seed in an entry": ("seed = 1\n", ["seed", "seeds"]),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_cover_options_are_checked_and_bad_ones_named(tmp_path, case):
    extra, expected = BAD[case]
    path = _file(tmp_path, COVER + extra)
    with pytest.raises(StudyError) as info:
        load_study(path)
    message = str(info.value)
    assert isinstance(info.value, ParameterError) and str(path) in message, message
    for part in expected:
        assert part in message, message


def test_cover_task_refuses_continuous_scenarios_and_other_metrics(tmp_path):
    assert "cover" in TASKS and METRICS["cover"] == ("gap",)
    with pytest.raises(StudyError, match=r"scenarios\[0\] 'ega01_random1'.*continuous"):
        load_study(_file(tmp_path, COVER.replace('"coverage_16x7", "coverage_16x16"', '"ega01_random1"')))
    with pytest.raises(StudyError, match="metrics.0.: unknown metric 'front' for task cover"):
        load_study(_file(tmp_path, 'metrics = ["front"]\n' + COVER))
    # widths per map: a list that fits one map only is given under per_scenario
    study = load_study(_file(tmp_path, COVER + "[methods.per_scenario.coverage_16x7]\nstripes = [2, 3, 2]\n"))
    assert [t.parameters for t in study.trials()] == [{"stripes": [2, 3, 2]}, {}]
    assert all(t.seed is None for t in study.with_seeds(3).trials())  # deterministic: one run each


def _replay(record):
    """The record's commands replayed from its start in a simulator of Cheng et al. 2019's commands."""
    scenario = load_scenario(record["scenario"])
    ws = scenario.workspace
    x, y, shape, heading = record["start_pose"]
    ids = parse_commands(record["commands"].split(",")) if record["commands"] else np.zeros(0, dtype=np.int64)
    result = Simulator(ws, commands=SEED004_COMMANDS).run([ids], (x, y, shape, heading))
    assert result.valid[0], record["label"]
    poses = result.poses(0)
    cells = FOOTPRINTS[poses[:, 2], poses[:, 3]] + poses[:, None, :2]
    covered = np.zeros(ws.occupancy.shape, dtype=bool)
    covered[cells[..., 1].ravel(), cells[..., 0].ravel()] = True
    return ws, ids, result, poses, covered


@pytest.fixture(scope="module")
def small_run(tmp_path_factory):
    folder = tmp_path_factory.mktemp("cheng2019")
    study = load_study(_file(folder, SMALL, "small.toml"))
    return cheng2019.run_cheng2019(study=study, executor="serial", out=folder), folder


def test_records_revalidate_in_the_simulator_and_hold_the_bound(small_run):
    run, _ = small_run
    assert run.failed == 1  # the O-tiling of the 16 x 16 map does not exist
    for record in run.records:
        if record["error"] is not None:
            assert record["method"] == "tiling-tsp" and record["error"].startswith("TilingError:")
            continue
        ws, ids, result, poses, covered = _replay(record)
        assert record["action_cost"] == len(ids) and record["time"] == pytest.approx(float(result.time[0]))
        free = ~ws.occupancy
        assert record["covered"] == int((covered & free).sum()) and not (covered & ~free).any()
        assert record["free"] == int(free.sum())
        assert record["complete"] == bool((covered | ~free).all())
        if record["method"] != "stripes-paper":  # ours cover every coverable cell; the paper's may leave some
            assert record["covered"] >= record["coverable"]
        layers = record["layers"].split(",")
        # every pose of the replay in S's shapes, or an intermediate state of a switch
        assert record["layers"] == ("O" if record["method"] == "boustrophedon" else record["layers"])
        gain = 2 if layers == ["O"] else 4  # the most new cells one O translation adds; an I adds 4
        bound = max(0, math.ceil((record["coverable"] - 4) / gain))
        assert record["lower_bound"] == bound == record["reference"]
        # the replay covers only coverable cells (a cell under a reachable pose is coverable): what it leaves of them
        left = record["coverable"] - int((covered & free).sum())
        assert record["missed"] == left  # recomputed from the replay, not the planner's
        if record["method"] == "stripes-paper":  # the paper's algorithm: no mop-up, no greedy walk, nothing rescued
            assert record["additions"] == [] and record["mopup_commands"] == 0
            assert record["failed_regions"] >= 0 and (record["gap"] is None) == (left > 0)
        else:
            assert left == 0 and record["coverable_pct"] == 100.0 and record["failed_regions"] == 0
        if left:
            assert record["gap"] is None  # the bound is on plans covering every coverable cell
        else:
            assert record["action_cost"] >= bound
            assert record["gap"] == pytest.approx((record["action_cost"] - bound) / bound)
        assert record["seed"] is None
        if layers == ["O"]:
            assert set(poses[:, 2].tolist()) == {shape_index("O")}


def test_options_reach_the_planner():
    scenario = load_scenario("coverage_16x7")
    record = run_trial("cover", "coverage_16x7", "stripes",
                       {"shapes": "O,hI", "stripes": [2, 3, 2], "region_columns": 3, "budget": 500}, None)
    plan = plan_coverage(scenario.workspace, "O,hI", stripes=(2, 3, 2), region_columns=3, budget=500,
                         start=scenario.start, goal=scenario.goal)
    assert record["commands"] == ",".join(plan.tokens) and record["regions"] == plan.regions
    assert record["start_pose"] == [scenario.start.x, scenario.start.y, "O", 0]
    auto = run_trial("cover", "coverage_16x7", "stripes", {"shapes": "O,hI", "stripes": "2,3,2", "start": "auto"},
                     None)
    free_end = plan_coverage(scenario.workspace, "O,hI", stripes=(2, 3, 2))
    assert auto["commands"] == ",".join(free_end.tokens) and auto["commands"] != record["commands"]
    assert "gap" not in auto and auto["lower_bound"] == 25  # (102 - 4) / 4, rounded up
    # the stripes and regions of the first trial, where both ends pay (92 against 100): seconds, not the
    # default stripes' ten
    both = run_trial("cover", "coverage_16x7", "stripes", {"shapes": "O,hI", "stripes": [2, 3, 2], "region_columns": 3,
                                                            "budget": 500, "ends": "both", "mopup": "nearest"}, None)
    folded = plan_coverage(scenario.workspace, "O,hI", stripes=(2, 3, 2), region_columns=3, budget=500, ends="both",
                           mopup="nearest", start=scenario.start, goal=scenario.goal)
    assert both["commands"] == ",".join(folded.tokens) and both["action_cost"] == folded.action_cost
    assert folded.info["ends"] == "both" and both["action_cost"] < record["action_cost"]
    nearest = run_trial("cover", "coverage_16x7", "boustrophedon", {"shapes": "O", "mopup": "nearest"}, None)
    assert nearest["commands"] == ",".join(plan_coverage(scenario.workspace, "O", method="boustrophedon",
                                                         mopup="nearest", start=scenario.start,
                                                         goal=scenario.goal).tokens)
    with pytest.raises(ParameterError, match="cover"):
        run_reference("cover", "coverage_16x7", {})
    gapped = Study(name="g", task="cover", scenarios=["coverage_16x7"], metrics=["gap"], methods=[{"method": "stripes"}])
    assert gapped.references() == {}  # the bound is the trial's own


def test_report_sets_the_paper_beside_ours(small_run):
    run, _ = small_run
    text = cheng2019.report(run)
    for part in ("## Table 2", "| {O} | N_str,1 (3,3,3,3,4) | yes | 137 | 2.104 |", "| yes | 120 | 1.994 |",
                 "| {vI} | N_str,2 (4,4,4,4) | no | – | – |", "no (?)", "## The 16 × 7 map", "| 73 |",
                 "## Every method on the 16 × 16 map", "untileable", "never fitted", "4 × 120 / 1.994 = 241",
                 "112 / 120 = 0.93", "**Stripes against the boustrophedon**"):
        assert part in text, part
    assert "## Failed trials" not in text and "## Larger maps" not in text
    rows = cheng2019.report_rows(run)
    by = {r["label"]: r for r in rows if r["scenario"] == "coverage_16x16"}
    assert by["stripes {O} N_str,2"]["paper_action_cost"] == 120 and by["stripes {O} N_str,2"]["part"] == "table2"
    assert by["stripes {O,hI} N_str,1"]["paper_config"] == "Any config with vI, hI (?)"
    assert by["stripes {O,hI} N_str,1"]["paper_complete"] is False
    assert by["stripes {O,vI,hI} N_str,2"]["paper_average_coverage_time"] == 1.77
    assert by["boustrophedon {O}"]["paper_action_cost"] is None and by["boustrophedon {O}"]["part"] == "maps"
    assert by["tiling-tsp {O}"]["error"] == "untileable"
    records = {(r["scenario"], r["label"]): r for r in run.records}
    for row in rows:  # ours are the records'
        record = records[(load_scenario(row["scenario"]).name, row["label"])]
        assert row["action_cost"] == record.get("action_cost") and row["gap"] == record.get("gap")
    small = next(r for r in rows if r["part"] == "16x7" and r["method"] == "stripes")
    assert small["paper_action_cost"] == 73 and small["complete"] is False  # (0, 0) fits no pose of {O, hI}
    # Table 2's golden facts: {vI} alone cannot cover the map, {O, vI, hI} is cheaper than {O}
    assert by["stripes {vI} N_str,2"]["complete"] is False
    assert by["stripes {O,vI,hI} N_str,2"]["action_cost"] < by["stripes {O} N_str,2"]["action_cost"]
    with pytest.raises(ParameterError, match="StudyRun"):
        cheng2019.report([])


def test_report_shows_the_published_algorithm_as_it_reaches_it(small_run):
    run, _ = small_run
    text = cheng2019.report(run)
    rows = {r["label"]: r for r in cheng2019.report_rows(run)}
    records = {r["label"]: r for r in run.records}
    for label in ("stripes-paper {O} N_str,2", "stripes-paper {vI} N_str,2", "stripes-paper {vI} N_str,1"):
        row, record = rows[label], records[label]
        assert row["part"] == "table2" and row["additions"] == "" and row["mopup_commands"] == 0
        assert row["missed"] == record["missed"] and row["failed_regions"] == record["failed_regions"]
        assert row["complete"] == record["complete"]
    # N_str,1 with the I: the paper's Table 2 says not complete, and its algorithm as published leaves cells
    assert rows["stripes-paper {vI} N_str,1"]["missed"] > 0 and rows["stripes-paper {vI} N_str,1"]["gap"] is None
    line = next(l for l in text.splitlines() if l.startswith("| {vI} | N_str,1"))
    cells = [c.strip() for c in line.strip("|").split("|")]
    assert cells[5] == "no" and cells[6] == str(records["stripes-paper {vI} N_str,1"]["missed"])
    assert "as published (`stripes-paper`) covers every coverable cell on" in text
    # the sweeps' order figure comes from the run: the row without sweep-order beside the one with every addition
    unordered, ordered = records["stripes {vI,hI} N_str,2 without sweep-order"], records["stripes {vI,hI} N_str,2"]
    assert f"took it from {unordered['action_cost']} (this run, without it) to {ordered['action_cost']}" in text
    assert rows["stripes {vI,hI} N_str,2 without sweep-order"]["part"] == "order"
    assert "sweep-order" not in unordered["additions"] and ordered["additions"][-1] == "mopup"


def test_csv_round_trips(small_run):
    run, folder = small_run
    md, table = cheng2019.write_report(folder, run, figures={"fig8b": "cheng2019_fig8b.png"})
    assert "[cheng2019_fig8b.png](cheng2019_fig8b.png)" in md.read_text(encoding="utf-8")
    with open(table, newline="", encoding="utf-8") as handle:
        read = list(csv.DictReader(handle))
    rows = cheng2019.report_rows(run)
    assert len(read) == len(rows) and set(read[0]) == set(rows[0])
    for got, want in zip(read, rows):
        for key, value in want.items():
            if value is None:
                assert got[key] == "", key
            elif isinstance(value, bool):
                assert got[key] == str(value), key
            elif isinstance(value, (int, float)):
                assert float(got[key]) == value, key  # repr: floats come back exactly
            else:
                assert got[key] == value, key


def test_figure_plans_are_the_studys_plans(small_run):
    run, _ = small_run
    plans = cheng2019.figure_plans(["fig8b"])
    _, plan, title = plans["fig8b"]
    record = next(r for r in run.records if r["label"] == "stripes {O,hI} 2,3,2")
    assert ",".join(plan.tokens) == record["commands"] and "Fig. 8b" in title
    with pytest.raises(ParameterError, match="unknown figure 'fig9'"):
        cheng2019.figure_plans(["fig9"])


def test_bundled_study_is_the_builders():
    study = load_study("cheng2019")
    assert study == cheng2019.cheng2019_study()
    trials = study.trials()
    table2 = [t for t in trials if t.scenario == "coverage_16x16" and t.method in ("stripes", "stripes-paper")
              and t.label != cheng2019.ORDER_CHECK["label"]]
    assert len(table2) == 2 * 14
    assert {(t.parameters["shapes"], t.parameters["stripes"]) for t in table2} == {
        (layers, width) for layers in cheng2019.TABLE2_LAYERS for width in (3, 4)}
    assert {t.scenario for t in trials} == {"coverage_16x16", "coverage_16x7", "tiling_64x64", "indoor_room"}
    assert all(t.seed is None for t in trials) and study.metrics == ("gap",)
    assert len(cheng2019.cheng2019_study(large=False).trials()) == len(trials) - 6
    assert len(cheng2019.PAPER_TABLE2) == 9 and cheng2019.PAPER_16X7["action_cost"] == 73


def test_command_line_runs_a_cheng2019_study_file(tmp_path, capsys):
    path = _file(tmp_path, SMALL.replace('["coverage_16x16", "coverage_16x7"]', '["coverage_16x7"]')
                 .replace('scenarios = ["coverage_16x16"]\n', 'scenarios = ["coverage_16x7"]\n')
                 .replace("stripes = 3\n", "stripes = 7\n").replace("stripes = 4\n", "stripes = 7\n"), "mine.toml")
    out = tmp_path / "out"
    assert cli_main(["study", str(path), "--executor", "serial", "--out", str(out), "--json", "--quiet",
                     "--figures"]) == 0
    result = json.loads(capsys.readouterr().out)
    errors = {r["label"]: r["error"].split(":")[0] for r in result["records"] if r["error"]}
    # 103 free cells tile with no O; the roadmap's start (an O) is not in {vI} nor {vI, hI}: all recorded, the
    # study goes on
    no_o = ("stripes {vI} N_str,2", "stripes-paper {vI} N_str,2", "stripes-paper {vI} N_str,1",
            "stripes {vI,hI} N_str,2", "stripes {vI,hI} N_str,2 without sweep-order")
    assert result["study"] == "cheng2019" and errors == {"tiling-tsp {O}": "TilingError",
                                                         **dict.fromkeys(no_o, "ConfigurationError")}
    assert set(result["figures"]) == {"fig8b", "fig14a", "fig14bc", "fig15a", "fig15bc"}
    for name in result["figures"].values():
        assert (out / name).read_bytes()[:4] == b"\x89PNG"
    text = (out / "cheng2019.md").read_text(encoding="utf-8")
    assert "## The 16 × 7 map" in text and "## Figures" in text and "## Table 2" not in text
    assert (out / "cheng2019.jsonl").exists() and (out / "cheng2019.csv").exists()
    for args, message in ((["--seeds", "2"], "deterministic"), (["--figures"], "--figures needs --out")):
        assert cli_main(["study", str(path), "--executor", "serial", *args]) == 2
        assert message in capsys.readouterr().err
    assert cli_main(["study", "small", "--figures", "--out", str(tmp_path / "x")]) == 2
    assert "--figures applies to cheng2019 only" in capsys.readouterr().err


def test_the_one_command_line_refuses_bad_options(capsys):
    from htetro_opt.cli import main

    assert main(["study", "cheng2019", "--resume"]) == 2
    assert "error: --resume needs --out DIR" in capsys.readouterr().err
    assert main(["study", "cheng2019", "--workers", "0"]) == 2
    assert "--workers" in capsys.readouterr().err
    assert not hasattr(cheng2019, "main")  # one command line: htetro-opt study


def test_the_ablation_study_runs_the_paper_each_addition_alone_and_ours():
    from htetro_opt.solvers.coverage import SPEC, STRIPES_ADDITIONS

    study = load_study("cheng2019_ablation")
    assert study.task == "cover" and study.metrics == ("gap",)
    trials = study.trials()
    configs = {(t.scenario, t.parameters["shapes"], str(t.parameters["stripes"])) for t in trials}
    assert configs == {("coverage_16x16", "O", "4"), ("coverage_16x16", "O,vI,hI", "4"),
                       ("coverage_16x7", "O,hI", "[2, 3, 2]")}
    for config in configs:
        mine = [t for t in trials if (t.scenario, t.parameters["shapes"], str(t.parameters["stripes"])) == config]
        switched = [SPEC.check(t.method, {"additions": t.parameters.get("additions",
                                                                         SPEC.default_of(t.method, "additions"))},
                               fill=False)["additions"] for t in mine]
        # the paper's algorithm, then each addition alone in STRIPES_ADDITIONS' order, then ours with all
        assert [t.method for t in mine] == ["stripes-paper"] * (len(STRIPES_ADDITIONS) + 1) + ["stripes"]
        assert switched == [()] + [(a,) for a in STRIPES_ADDITIONS] + [tuple(STRIPES_ADDITIONS)]
