"""The study of Do et al. 2021 (Tables 6–8, Fig. 13): the runner's heat method and metric, the report and the command line."""

import csv
import json

import numpy as np
import pytest

from htetro_opt.cli import main as cli_main
from htetro_opt.errors import ParameterError
from htetro_opt.model import STATE_NAMES, Simulator, parse_commands
from htetro_opt.problems import heat_fitness
from htetro_opt.scenarios import load_scenario
from htetro_opt.solvers.grid_paths import HEAT_ADDITIONS, plan_exact, plan_heat
from htetro_opt.studies import do2021
from htetro_opt.studies.runner import (
    Study,
    StudyError,
    load_study,
    reference_trial,
    run_study,
)

HEAT = 'task = "plan"\nscenarios = ["three_slit", "random"]\n[[methods]]\nmethod = "heat"\n'


def _file(tmp_path, text, name="study.toml"):
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


# A tiny do2021-shaped study: two maps, the four rows of both heat planners, the exact plan and both
# GAs small, one seed.
SMALL = """name = "do2021"
task = "plan"
scenarios = ["random", "h_shape"]
seeds = 1
metrics = ["objectives", "gap", "heat_fitness"]
""" + "".join(f'[[methods]]\nlabel = "{m}, {row}"\nmethod = "{m}"\nweights = {list(w)}\n'
              for m in do2021.HEAT_METHODS for row, w in do2021.ROWS) + """
[[methods]]
label = "exact"
method = "dijkstra"
diagonals = true
[[methods]]
label = "htetro-ga-paper"
method = "htetro-ga-paper"
pop_size = 16
max_gen = 40
patience = 10
[[methods]]
label = "htetro-ga"
method = "htetro-ga"
pop_size = 16
max_gen = 40
patience = 10
"""

BAD = {
    "weights all zero": ("weights = [0, 0, 0]\n", ["weights", "all be zero"]),
    "two weights": ("weights = [1, 1]\n", ["weights", "three numbers"]),
    "weights not numbers": ('weights = "a,b,c"\n', ["weights", "'a,b,c'"]),
    "negative weight": ("weights = [1, -1, 0]\n", ["weights[1]", "-1"]),
    "unknown element": ('element = "q2"\n', ["element", "q1, p0", "'q2'"]),
    "band radius 0": ("band = 0\n", ["band", "radius", "0"]),
    "unknown band": ('band = "wide"\n', ["band", "'wide'"]),
    "t_max zero": ("t_max = 0\n", ["t_max", "> 0"]),
    "t_max infinite": ("t_max = inf\n", ["t_max", "inf"]),
    "monotone not a bool": ('monotone = "yes"\n', ["monotone", "True or False"]),
    "diagonals for heat": ("diagonals = true\n", ["diagonals", "exact methods", "not to heat", "always plans"]),
    "GA option for heat": ("pop_size = 10\n", ["pop_size", "GA methods (", "not to heat"]),
    "heat option for dijkstra": ('[[methods]]\nmethod = "dijkstra"\nweights = [1, 0, 0]\n',
                                 ["methods[1]", "weights", "heat planner", "not to dijkstra"]),
    "entry scenario not in the study": ('scenarios = ["spiral"]\n', ["methods[0]", "scenarios[0]", "'spiral'"]),
    "entry scenarios empty": ("scenarios = []\n", ["methods[0]", "scenarios", "non-empty"]),
    "override outside the entry's scenarios": ('scenarios = ["random"]\n[methods.per_scenario.three_slit]\nband = 4\n',
                                               ["per_scenario.three_slit", "not one of the entry's scenarios"]),
    "front of heat": ('metrics = ["front"]\n', ["metric 'front'", "GA methods (", "heat has no population"]),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_heat_options_are_checked_and_bad_ones_named(tmp_path, case):
    extra, expected = BAD[case]
    text = (extra + HEAT) if extra.startswith("metrics") else HEAT + extra
    path = _file(tmp_path, text)
    with pytest.raises(StudyError) as info:
        load_study(path)
    message = str(info.value)
    assert isinstance(info.value, ParameterError) and str(path) in message, message
    for part in expected:
        assert part in message, message


def test_heat_takes_its_options_runs_once_and_its_gap_is_to_the_optimum_with_diagonals(tmp_path):
    options = 'weights = "1,1,1"\nelement = "p0"\nmonotone = true\nband = "full"\nt_max = 100.0\n'
    path = _file(tmp_path, 'seeds = 3\nmetrics = ["gap", "heat_fitness"]\n' + HEAT + options
                 + '[[methods]]\nmethod = "htetro-ga"\npop_size = 8\nmax_gen = 2\nscenarios = ["random"]\n')
    study = load_study(path)
    trials = study.trials()
    assert [(t.scenario, t.method, t.seed) for t in trials] == [
        ("three_slit", "heat", None), ("random", "heat", None), ("random", "htetro-ga", 0),
        ("random", "htetro-ga", 1), ("random", "htetro-ga", 2)]
    assert trials[0].parameters == {"band": "full", "element": "p0", "monotone": True, "t_max": 100.0,
                                    "weights": [1.0, 1.0, 1.0]}
    assert reference_trial(trials[0]).parameters == {"diagonals": True}
    assert reference_trial(trials[2]).parameters == {}  # the GA's chromosomes have no diagonals

    run = run_study(study, executor="serial", seeds=[0])
    for record in run.records:
        scenario = load_scenario(record["scenario"])
        if record["method"] == "heat":  # the options reached the planner: the same plan as a direct call
            plan = plan_heat(scenario.workspace, scenario.roadmap, weights=(1, 1, 1), element="p0", band="full",
                             t_max=100.0)
            assert record["commands"] == ",".join(plan.tokens)
            assert record["heat_f"] == pytest.approx(plan.info["fitness"]["f"], abs=1e-12)
            optimum = plan_exact(scenario.workspace, scenario.roadmap, diagonals=True).time
        else:
            optimum = plan_exact(scenario.workspace, scenario.roadmap).time
        assert record["reference"] == pytest.approx(optimum, abs=1e-9)
    heat = [r for r in run.records if r["method"] == "heat"]
    assert all(r["seed"] is None and r["gap"] >= -1e-12 for r in heat)


def _replayed_costs(scenario, commands, *, diagonals):
    """heat_fitness of a recorded plan, its poses re-simulated from the command tokens (not the runner's)."""
    sim = Simulator(scenario.workspace, diagonals=diagonals)
    ids = parse_commands(commands)
    result = sim.run([ids], scenario.roadmap[0])
    assert result.valid[0]
    poses = result.poses(0)
    costs = heat_fitness(scenario.workspace, poses, ids, weights=(1, 1, 1))
    shapes = "".join(dict.fromkeys(STATE_NAMES[s] for s in poses[:, 2]))
    return costs, shapes


def test_heat_fitness_metric_scores_ga_and_exact_plans_alike():
    study = Study(name="scored", task="plan", scenarios=["h_shape"], seeds=[3], metrics=["heat_fitness"],
                  methods=[{"method": "htetro-ga", "pop_size": 20, "max_gen": 60, "patience": 20},
                           {"method": "dijkstra", "diagonals": True}])
    run = run_study(study, executor="serial")
    scenario = load_scenario("h_shape")
    assert all(r["reached"] for r in run.records), [r["reached"] for r in run.records]
    for record in run.records:
        costs, shapes = _replayed_costs(scenario, record["commands"], diagonals=record["method"] == "dijkstra")
        for name in ("f_t", "f_sm", "f_sf", "f"):  # f at equal weights: neither method optimises a weighting
            assert record[f"heat_{name}"] == pytest.approx(costs[name], abs=1e-12), name
        assert record["shapes_used"] == shapes
    assert set(run.summary[0]) >= {"heat_f_mean", "heat_f_t_mean", "heat_f_sf_std"}


def test_bundled_study_is_the_builders():
    study = load_study("do2021")
    assert study == do2021.do2021_study()
    assert study.scenarios == do2021.TABLE6_SCENARIOS and study.seeds == tuple(range(5))
    trials = study.trials()
    for method in ("heat-paper", "heat"):  # the paper's algorithm and ours, each under the four weightings
        heat = [t for t in trials if t.method == method]
        assert len(heat) == 6 * 4 and all(t.seed is None for t in heat)
        assert {tuple(t.parameters["weights"]) for t in heat} == {w for _, w in do2021.ROWS}
    for method in ("htetro-ga-paper", "htetro-ga"):  # Table 7: the paper's comparison (the GA as published) and ours
        ga = [t for t in trials if t.method == method]
        assert sorted({t.scenario for t in ga}) == sorted(do2021.TABLE7_SCENARIOS)
        assert {t.parameters["pop_size"] for t in ga} == {100} and len(ga) == 4 * 5
        assert {t.label for t in ga} == {method}
    assert len(load_study("do2021").with_seeds(50).trials()) == 6 * (8 + 1) + 2 * 4 * 50
    only7 = do2021.do2021_study(2, tables=[7])
    assert only7.scenarios == do2021.TABLE7_SCENARIOS and len(only7.trials()) == 4 * (8 + 1 + 2 * 2)
    only6 = do2021.do2021_study(tables="6")
    assert {t.method for t in only6.trials()} == {"heat-paper", "heat"}
    for bad in ([8], [5], "6,x", []):
        with pytest.raises(ParameterError, match="(?i)tables"):
            do2021.do2021_study(tables=bad)


@pytest.fixture(scope="module")
def small_run(tmp_path_factory):
    folder = tmp_path_factory.mktemp("do2021")
    study = load_study(_file(folder, SMALL, "small.toml"))
    return do2021.run_do2021(1, study=study, executor="serial", out=folder), folder


def test_smoke_run_reports_tables_6_and_7_beside_the_paper(small_run):
    run, folder = small_run
    assert run.failed == 0
    md, table = do2021.write_report(folder, run)
    text = md.read_text(encoding="utf-8")
    for part in ("## Table 6", "### random", "### h_shape", "## Table 7", "**Targets.**",
                 "0.879–0.894 / 0.867", "0.615", "0.945", "0.892", "0.869", "0.926", "0.914",
                 "only the normalisation compares", "`htetro-ga-paper`, Cheng et al. 2020's GA as published"):
        assert part in text, part
    assert "so f_t compares" not in text
    # heat keeps Table 6's property on both maps (the exact pick); the report says so per planner
    assert text.count("Table 6's property (each criterion's best value in its own row), heat: holds.") == 2
    assert "Table 8" not in text and "Fig. 13" not in text
    with open(table, newline="", encoding="utf-8") as handle:
        rows = list(csv.DictReader(handle))
    t6 = [r for r in rows if r["table"] == "6"]
    assert [(r["scenario"], r["method"], r["row"]) for r in t6] == [
        (s, m, row) for s in ("random", "h_shape") for m in do2021.HEAT_METHODS for row, _ in do2021.ROWS]
    records = {(r["scenario"], r["label"]): r for r in run.records}
    for r in t6:  # our cells are the records', the paper's beside them
        record = records[(r["scenario"], f"{r['method']}, {r['row']}")]
        assert float(r["f"]) == pytest.approx(record["heat_f"]) and float(r["gap"]) == pytest.approx(record["gap"])
        assert float(r["gap"]) >= -1e-12  # no heat plan beats the minimum time over its commands
        assert r["additions"] == ("" if r["method"] == "heat-paper" else ",".join(HEAT_ADDITIONS))
    cells = {(r["scenario"], r["method"], r["row"]): r for r in t6}
    assert cells[("random", "heat-paper", "smoothness")]["paper_f_t"] == "0.879–0.894 / 0.867"
    assert cells[("h_shape", "heat-paper", "multi")]["paper_f_sf"] == "0.914"
    assert cells[("h_shape", "heat", "multi")]["paper_f_sf"] == ""  # the paper's numbers beside its algorithm only
    # Table 7: each row's heat f is the best of the heat plans under that row's weights
    t7 = [r for r in rows if r["table"] == "7"]
    assert {r["label"] for r in t7} == {"heat-paper", "heat", "htetro-ga-paper", "htetro-ga", "exact"}
    # every study record lists the additions switched on: none for the methods as published
    assert all(r["additions"] == [] for r in run.records if r["method"] in ("heat-paper", "htetro-ga-paper"))
    assert all(r["additions"] == list(HEAT_ADDITIONS) for r in run.records if r["method"] == "heat")
    assert all(r["additions"] for r in run.records if r["method"] == "htetro-ga")
    for scenario in ("random", "h_shape"):
        for row, weights in do2021.ROWS:
            for method in do2021.HEAT_METHODS:
                heat = next(r for r in t7 if (r["scenario"], r["row"], r["label"]) == (scenario, row, method))
                record = records[(scenario, f"{method}, {row}")]
                assert float(heat["f"]) == pytest.approx(record["heat_f"])
            exact = records[(scenario, "exact")]
            scored = np.dot(weights, [exact["heat_f_t"], exact["heat_f_sm"], exact["heat_f_sf"]]) / sum(weights)
            assert float(next(r["f"] for r in t7 if (r["scenario"], r["row"], r["label"]) == (scenario, row, "exact"))) \
                == pytest.approx(scored)


def test_report_needs_something_and_the_heat_fitness_metric():
    with pytest.raises(ParameterError, match="needs a run"):
        do2021.report()
    bare = run_study(Study(name="bare", task="plan", scenarios=["three_slit"], methods=[{"method": "heat"}]),
                     executor="serial")
    with pytest.raises(ParameterError, match="heat_fitness"):
        do2021.report(bare)
    with pytest.raises(ParameterError, match="StudyRun"):
        do2021.report([])


@pytest.fixture(scope="module")
def table8():
    return do2021.run_table8()


def test_table8_the_heat_planner_against_o_only_a_star_and_dijkstra(table8):
    rows = {r["label"]: r for r in table8}
    astar, dijkstra = rows["O-only A*"], rows["O-only Dijkstra (diagonals)"]
    multi, timed = rows["heat, multi (1, 1, 1)"], rows["heat, time (1, 0, 0)"]
    assert all(r["reached"] for r in rows.values())
    for r in (astar, dijkstra):  # the O-shape only: no turn, no shapeshift
        assert r["shapes_used"] == "O" and r["shapeshifts"] == r["rotations"] == 0
    assert astar["time"] == pytest.approx(144.0) and dijkstra["time"] == pytest.approx(128.77, abs=0.01)
    assert astar["time"] > dijkstra["time"] > timed["time"]  # the 144.0 / 128.8 / 114.9
    assert timed["time_pct"] <= -15.0 and timed["shapes_used"] == "OI"
    assert multi["time"] < astar["time"]
    paper = rows["heat-paper, multi (1, 1, 1)"]  # the paper's algorithm, its numbers beside it
    assert paper["reached"] and paper["time"] >= timed["time"] - 1e-9  # no faster than the minimum time
    assert paper["paper_time_pct"] == -18.03 and paper["paper_energy_pct"] == -15.69
    assert multi["paper_time_pct"] is None and timed["paper_time_pct"] is None
    scenario = load_scenario("indoor_room_doorway")
    assert timed["time"] == pytest.approx(plan_exact(scenario.workspace, scenario.roadmap, diagonals=True).time)
    text = do2021.report(table8=list(rows.values()))
    assert "energy, the paper's other measure, is not modelled" in text.lower()


def test_fig13_replans_reaches_and_is_no_faster_than_the_true_optimum():
    fig = do2021.run_fig13()
    assert fig["reached"] and fig["plans"] == 1 + len(fig["replans"]) >= 2
    revealed = {tuple(c) for r in fig["replans"] for c in r["revealed"]}
    assert revealed == {(5, 11), (6, 11)}
    assert fig["time"] >= fig["true_optimum"] - 1e-9 and fig["ratio"] <= 1.25
    assert fig["paper_replan_cell"] == [5, 7]


def test_command_line_runs_a_do2021_study_file(tmp_path, capsys, monkeypatch, table8):
    monkeypatch.setattr(do2021, "run_table8", lambda: table8)  # measured once, by the fixture
    path = _file(tmp_path, SMALL.replace('["random", "h_shape"]', '["three_slit"]'), "mine.toml")
    out = tmp_path / "out"
    assert cli_main(["study", str(path), "--seeds", "1", "--executor", "serial", "--out", str(out), "--json",
                     "--quiet"]) == 0
    result = json.loads(capsys.readouterr().out)
    assert result["study"] == "do2021" and result["failed"] == 0
    assert {r["label"] for r in result["table8"]} >= {"O-only A*", "heat, multi (1, 1, 1)"}
    assert result["fig13"]["reached"]
    text = (out / "do2021.md").read_text(encoding="utf-8")
    assert "## Table 6" in text and "## Table 8" in text and "## Fig. 13" in text
    assert (out / "do2021.jsonl").exists() and (out / "do2021.csv").exists()
    assert cli_main(["study", str(path), "--time-limit", "3"]) == 2
    assert "--time-limit applies to le2018 only" in capsys.readouterr().err


def test_fig13_alone_is_reported_and_written(tmp_path):
    do2021.write_report(tmp_path, fig13=do2021.run_fig13())
    assert "## Fig. 13" in (tmp_path / "do2021.md").read_text(encoding="utf-8")
    with open(tmp_path / "do2021.csv", newline="", encoding="utf-8") as handle:
        rows = list(csv.DictReader(handle))
    assert [r["table"] for r in rows] == ["13"] and "(5, 11)" in rows[0]["replans"]
    assert not hasattr(do2021, "main")  # one command line: htetro-opt study


# --- the ablation study: the paper's algorithm, each addition alone, ours ------------------------------
def test_the_ablation_study_runs_the_paper_each_addition_alone_and_ours():
    from dataclasses import replace

    study = load_study("do2021_ablation")
    assert study.scenarios == do2021.TABLE6_SCENARIOS
    variants = list(dict.fromkeys(t.label.rpartition(", ")[0] for t in study.trials()))
    assert variants == ["paper (heat-paper)", *[f"paper + {a}" for a in HEAT_ADDITIONS], "ours (heat)"]
    small = replace(study, scenarios=("random",))  # where the surrogate alone breaks Table 6's property
    run = run_study(small, executor="serial")
    assert run.failed == 0
    for record in run.records:  # each variant's record lists exactly the additions it ran with
        variant = record["label"].rpartition(", ")[0]
        expected = {"paper (heat-paper)": [], "ours (heat)": list(HEAT_ADDITIONS)}.get(
            variant, [variant.removeprefix("paper + ")])
        assert record["additions"] == expected, record["label"]
        assert record["reached"] and record["gap"] >= -1e-12  # none beats Dijkstra's minimum time
    rows = {r["variant"]: r for r in do2021.ablation_rows(run)}
    assert all(r["plans"] == 4 and r["maps"] == 1 for r in rows.values())
    # the exact pick, alone or in ours, keeps Table 6's property on every map
    assert rows["paper + exact-pick"]["property"] == rows["ours (heat)"]["property"] == 1
    # random: heat-paper's multi row is below its time row's f at equal weights, the surrogate's smoothness
    # row below its multi row's f_sm (the property broken)
    assert rows["paper (heat-paper)"]["property"] == rows["paper + surrogate-cost"]["property"] == 0
    text = do2021.ablation_report(run)
    assert text.count("\n") == 2 + len(rows) and "| ours (heat) |" in text
