"""One contract per task: every entry point, the command line and the study runner read the task's spec.

The oracles here are outside the spec: the entry points' own results (what a method returned), the
command line's parser and output, a study's records, and the modules a fresh interpreter loads.
"""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest

from htetro_opt._spec import Method
from htetro_opt.algorithms import GA_ADDITIONS
from htetro_opt.errors import ParameterError
from htetro_opt.problems import SequencingInstance
from htetro_opt.scenarios import load_scenario, load_tileset, tileset_path
from htetro_opt.solvers import plan_continuous, plan_coverage, plan_path, sequence_waypoints, tile_workspace
from htetro_opt.solvers._tasks import TASKS, VERBS


@pytest.fixture(scope="module")
def grid():
    return load_scenario("three_slit")


@pytest.fixture(scope="module")
def instance():
    return SequencingInstance.from_tileset(load_tileset(tileset_path("paper_6x6_fig13a")), start=1)


def _calls(grid, instance):
    """Each entry point, called with the task's data and options."""
    continuous = load_scenario("ega07_slits1")
    return {
        "grid_paths": lambda **o: plan_path(grid.workspace, grid.roadmap, **o),
        "continuous": lambda **o: plan_continuous(continuous, **o),
        "tiling": lambda **o: tile_workspace(np.zeros((4, 4), dtype=bool), **o),
        "sequencing": lambda **o: sequence_waypoints(instance, **o),
        "coverage": lambda **o: plan_coverage(load_scenario("coverage_16x7").workspace, "O", **o),
    }


@pytest.mark.parametrize("task", list(TASKS))
def test_every_entry_point_refuses_an_unknown_option_naming_the_methods_options(grid, instance, task):
    call = _calls(grid, instance)[task]
    spec = TASKS[task]
    with pytest.raises(ParameterError) as err:
        call(method=spec.default, no_such_option=1)
    message = str(err.value)
    assert "no_such_option" in message and "its options are" in message
    own = [o for o in spec.methods[spec.default].options if spec.options[o].stage == "method"]
    assert all(option in message for option in own)


@pytest.mark.parametrize("task", list(TASKS))
def test_every_result_says_its_method_success_and_runtime_in_json(grid, instance, task):
    result = _calls(grid, instance)[task]()
    record = json.loads(json.dumps(result.as_dict(), allow_nan=False))
    assert record["method"].startswith(TASKS[task].default)
    assert record["success"] is True and isinstance(record["message"], str) and record["runtime_s"] >= 0
    assert isinstance(record["info"], dict)


def test_importing_the_command_line_loads_no_solver_library():
    heavy = ("pymoo", "numba", "ortools", "skfem", "deap", "matplotlib", "dask", "pyamg", "shapely")
    code = ("import sys, htetro_opt.cli as cli; cli.build_parser().parse_args(['plan', 'three_slit']); "
            f"print(sorted(m for m in {heavy!r} if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "[]"


def test_plan_method_exact_on_a_grid_is_the_astar_optimum(capsys):
    from htetro_opt.cli import main

    assert main(["plan", "three_slit", "--method", "exact", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["method"] == "astar" and out["time"] == 33.0


def test_a_sequence_study_runs_each_method_once_or_once_per_seed():
    from htetro_opt.studies.runner import Study, run_study

    study = Study(name="seeded", task="sequence", scenarios=["paper_6x6_fig13a"], seeds=3,
                  methods=[{"method": "exact"}, {"method": "ils"}, {"method": "ga", "max_gen": 3}])
    run = run_study(study, executor="serial")
    counts = {m: sum(r["method"] == m for r in run.records) for m in ("exact", "ils", "ga")}
    assert counts == {"exact": 1, "ils": 3, "ga": 3}
    assert all(r["fingerprint"] for r in run.records)


# --- the seed: "seeded" in the spec is "the result can change with the seed" --------------------------
def _draw(task, method):
    """(options, run(seed) -> a hashable result) for a method whose results vary across a few seeds, on
    data small enough for a test; None when the task's data would take too long."""
    grid = load_scenario("three_slit")
    if task == "grid_paths":
        options = {"pop_size": 6, "max_gen": 3, "max_length": 40}
        return options, lambda seed: tuple(plan_path(grid.workspace, grid.roadmap, method=method, seed=seed,
                                                     **options).legs[0].front[0].commands)
    if task == "continuous":
        scenario = load_scenario("ega05_boxpile")
        options = {"time_limit": 2.0} if method == "rrt" else {"pop_size": 4, "max_gen": 2} \
            if TASKS[task].method(method).takes("pop_size") else {}
        def run(seed):  # the whole result: the EGA's taut refinement reaches the same optimal path from many seeds
            record = plan_continuous(scenario, method=method, seed=seed, **options).as_dict()
            return json.dumps({k: v for k, v in record.items() if k != "runtime_s"}, sort_keys=True)
        return options, run
    if task == "tiling":
        options = {"shuffle": True}
        return options, lambda seed: tile_workspace(np.zeros((8, 8), dtype=bool), method=method, seed=seed,
                                                    **options).tileset.blocks.tobytes()
    if task == "sequencing":
        rng = np.random.default_rng(7)
        points = rng.random((60, 2)) * 100  # beyond auto's exact range
        inst = SequencingInstance.from_matrix(np.hypot(*(points[:, None] - points[None]).transpose(2, 0, 1)))
        extra = {"local": {"restarts": 3}, "ga": {"max_gen": 3}, "ga-plain": {"max_gen": 3},
                 "greedy": {"iterations": 3}, "ils": {"kicks": 30}, "auto": {}}[method]
        return extra, lambda seed: tuple(sequence_waypoints(inst, method=method, seed=seed, **extra).order)
    raise AssertionError(f"no data for {task}")


_SEEDED = [(task, name) for task, spec in TASKS.items() for name, m in spec.methods.items() if m.takes("seed")]


@pytest.mark.parametrize("task, method", _SEEDED, ids=lambda v: v if isinstance(v, str) else "")
def test_a_method_that_takes_a_seed_draws_from_it_exactly_when_its_spec_says(task, method):
    spec = TASKS[task]
    options, run = _draw(task, method)
    assert spec.method(method).draws(options)
    assert run(3) == run(3), "the same seed must give the same result"
    assert len({run(seed) for seed in range(4)}) > 1, "the spec says it draws from the seed"
    if task == "tiling":  # without shuffle the tiling is the fixed order's, whatever the seed
        assert not spec.method(method).draws({})
        once = {tile_workspace(np.zeros((8, 8), dtype=bool), method=method, seed=s).tileset.blocks.tobytes()
                for s in range(3)}
        assert len(once) == 1


def test_a_method_that_does_not_draw_takes_no_seed():
    for task, spec in TASKS.items():
        for name, method in spec.methods.items():
            if not method.takes("seed"):
                assert not method.draws({}), (task, name)
            if method.exact and task != "tiling":
                assert not method.draws({}), (task, name)


def test_the_seed_has_one_default_everywhere():
    defaults = {spec.default_of(name, "seed") for spec in TASKS.values() for name, m in spec.methods.items()
                if m.takes("seed")}
    assert defaults == {0}


# --- one place: a method registered in its task's spec is offered everywhere ---------------------------
def _toy(instance, *, seed, time_limit):
    """The tiles in scan order from the start (a toy sequencing method)."""
    rest = [i for i in range(instance.n) if i != instance.start]
    return ([] if instance.start is None else [instance.start]) + rest, {"toy": True}


def test_a_method_registered_in_one_place_is_in_the_cli_its_help_and_a_study(capsys, tmp_path):
    from htetro_opt.cli import build_parser, main
    from htetro_opt.solvers.sequencing import SPEC
    from htetro_opt.studies.runner import Study, run_study

    SPEC.register(Method("toy", _toy, "tiles in scan order (a test's toy)", ("seed", "time_limit"), seeded=False))
    try:
        parser = build_parser()
        sequence = parser._subparsers._group_actions[0].choices["sequence"]
        method = next(a for a in sequence._actions if a.dest == "method")
        assert "toy" in method.choices
        assert main(["sequence", "--help"]) == 0
        assert "tiles in scan order (a test's toy)" in " ".join(capsys.readouterr().out.split())
        assert main(["sequence", "paper_6x6_fig13a", "--method", "toy", "--json"]) == 0
        out = json.loads(capsys.readouterr().out)
        assert out["method"] == "toy" and out["order"] == list(range(1, 10)) and out["info"] == {"toy": True}
        study = Study(name="toy", task="sequence", scenarios=["paper_6x6_fig13a"], seeds=2,
                      methods=[{"method": "toy"}])
        run = run_study(study, out=tmp_path, executor="serial")
        assert [(r["method"], r["seed"], r["order"]) for r in run.records] == [("toy", None, "1,2,3,4,5,6,7,8,9")]
    finally:
        SPEC.unregister("toy")
    assert "toy" not in SPEC.methods


def test_every_verb_offers_every_method_of_its_specs():
    from htetro_opt.cli import build_parser

    commands = build_parser()._subparsers._group_actions[0].choices
    for verb, specs in VERBS.items():
        method = next(a for a in commands[verb]._actions if a.dest == "method")
        assert set(method.choices) == {name for spec in specs for name in spec.names}, verb


# --- the code a record stands for -------------------------------------------------------------------
def test_resume_re_runs_the_records_whose_method_changed_and_says_how_many(tmp_path):
    from dataclasses import replace

    from htetro_opt.solvers.sequencing import SPEC
    from htetro_opt.studies.runner import Study, read_records, run_study

    study = Study(name="stale", task="sequence", scenarios=["paper_6x6_fig13a"], metrics=(),
                  methods=[{"method": "exact"}, {"method": "zigzag"}])
    first = run_study(study, out=tmp_path, executor="serial")
    assert first.stale == 0
    zigzag = SPEC.methods["zigzag"]
    SPEC.register(replace(zigzag, revision=zigzag.revision + 1))  # a behaviour change of zigzag
    try:
        second = run_study(study, out=tmp_path, executor="serial", resume=True)
    finally:
        SPEC.register(zigzag)
    assert second.stale == 1 and second.resumed == 1
    lines = read_records(tmp_path / "stale.jsonl")
    assert [r["method"] for r in lines] == ["exact", "zigzag", "zigzag"]  # the re-run appended, the last kept
    assert second.records[1]["fingerprint"] != first.records[1]["fingerprint"]
    assert second.records[0] == first.records[0]
    third = run_study(study, out=tmp_path, executor="serial", resume=True)
    assert third.stale == 1 and third.resumed == 1  # back to the first revision: the latest record is stale again


# --- additions of ours: none in a method as published, each switchable singly ----------------------------
def test_a_method_as_published_has_none_of_our_additions_and_ours_has_them_all():
    for task, spec in TASKS.items():
        if "additions" not in spec.options:
            continue
        for name, method in spec.methods.items():
            if not method.takes("additions"):
                continue
            # "all" is the method's own additions (the grid-path task has two planners' sets)
            names = spec.check(method, {"additions": "all"}, fill=False)["additions"]
            assert names and all(isinstance(n, str) for n in names), (task, name)
            expected = () if method.origin == "paper" else names
            assert spec.default_of(method, "additions") == expected, (task, name)


@pytest.mark.parametrize("addition", list(GA_ADDITIONS))
def test_each_ga_addition_switches_on_alone_and_the_plan_says_so(grid, addition):
    options = {"pop_size": 6, "max_gen": 2, "max_length": 40}
    paper = plan_path(grid.workspace, grid.roadmap, method="htetro-ga-paper", **options)
    ours = plan_path(grid.workspace, grid.roadmap, method="htetro-ga", **options)
    alone = plan_path(grid.workspace, grid.roadmap, method="htetro-ga-paper", additions=[addition], **options)
    assert paper.as_dict()["additions"] == [] and ours.as_dict()["additions"] == list(GA_ADDITIONS)
    assert alone.as_dict()["additions"] == [addition]
    with pytest.raises(ParameterError, match="unknown addition 'speedup'"):
        plan_path(grid.workspace, grid.roadmap, method="htetro-ga", additions=["speedup"], **options)
