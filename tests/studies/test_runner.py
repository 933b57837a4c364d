"""The study runner: study files, trials, executors (serial, processes, Dask), resume, errors, summaries."""

import csv
import json
import math
import os
import signal
import statistics
import subprocess
import sys
import time
from pathlib import Path

import pytest

from htetro_opt.errors import OutputError, ParameterError
from htetro_opt.scenarios import (
    format_tileset,
    list_tilesets,
    load_scenario,
    load_tileset,
    tileset_path,
)
from htetro_opt.solvers.grid_paths import plan_path
from htetro_opt.solvers.tiling import tile_workspace
from htetro_opt.studies import table4
from htetro_opt.studies.runner import (
    RUNTIME_FIELDS,
    Study,
    StudyError,
    WorkerLost,
    load_study,
    read_records,
    run_study,
    run_trial,
    summarise,
    write_summary,
)

# The example, as written.
EXAMPLE = '''\
name = "small"
task = "plan"
scenarios = ["random", "three_slit", "h_shape"]
seeds = 3                     # or a list of seeds
[[methods]]
method = "dijkstra"
[[methods]]
method = "htetro-ga"
pop_size = 20
max_gen = 40
'''

# Two maps, the exact plan and a quick GA (some seeds reach, some do not), gaps to the optimum.
AGREE = '''\
name = "agree"
task = "plan"
scenarios = ["random", "h_shape"]
seeds = 2
metrics = ["gap", "generations"]
[[methods]]
method = "exact"
[[methods]]
method = "htetro-ga"
pop_size = 16
max_gen = 30
patience = 5
'''


def _file(folder: Path, text: str, name: str = "study.toml") -> Path:
    path = folder / name
    path.write_text(text, encoding="utf-8")
    return path


def _content(records):
    """Records without their wall-clock fields, in key order."""
    return sorted(({k: v for k, v in r.items() if k not in RUNTIME_FIELDS} for r in records), key=lambda r: r["key"])


def _lines(path: Path) -> list[dict]:
    return [json.loads(line) for line in path.read_text(encoding="utf-8").splitlines()]


@pytest.fixture(scope="module")
def agree_baseline(tmp_path_factory):
    """The AGREE study run serially: records and references."""
    path = _file(tmp_path_factory.mktemp("agree"), AGREE)
    run = run_study(path, executor="serial")
    return path, _content(run.records + run.references)


# --- study files -----------------------------------------------------------------------------------
def test_example_study_works_as_written(tmp_path):
    study = load_study(_file(tmp_path, EXAMPLE))
    assert study == load_study("small")  # the bundled small.toml is the example
    assert [t.seed for t in study.trials() if t.scenario == "random"] == [None, 0, 1, 2]

    tiny = EXAMPLE.replace("seeds = 3", "seeds = 1").replace("max_gen = 40", "max_gen = 3")
    run = run_study(_file(tmp_path, tiny), out=tmp_path / "out", executor="serial")
    assert run.path == tmp_path / "out" / "small.jsonl"
    assert [(r["scenario"], r["method"], r["seed"]) for r in run.records] == [
        (s, m, seed) for s in ("random", "three_slit", "h_shape") for m, seed in (("dijkstra", None), ("htetro-ga", 0))]
    lines = _lines(run.path)  # the trials, and the exact reference of each scenario, which a gap needs
    assert _content(r for r in lines if r["kind"] == "trial") == _content(run.records)
    assert sorted(r["scenario"] for r in lines if r["kind"] == "reference") == ["h_shape", "random", "three_slit"]
    for record in run.records:  # gaps by default; no plan beats the proven optimum
        assert record["gap"] is None if not record["reached"] else record["gap"] >= 0
        assert record["gap"] == 0 or record["method"] != "dijkstra"
    for record in run.records:  # the planner itself, called directly, is the oracle
        scenario = load_scenario(record["scenario"])
        options = {} if record["method"] == "dijkstra" else {"pop_size": 20, "max_gen": 3, "seed": 0}
        plan = plan_path(scenario.workspace, scenario.roadmap, method=record["method"], **options)
        assert record["reached"] is plan.reached
        assert record["commands"] == ",".join(plan.tokens)
        assert record["time"] == (plan.time if plan.reached else None)
        assert record["error"] is None and len(record["key"]) == 64
    assert {p.name for p in (tmp_path / "out").iterdir()} == {"small.jsonl", "small.csv", "small.md"}


def test_bundled_table4_is_the_paper_setting():
    study = load_study("table4")
    trials = study.trials()
    assert study.scenarios == table4.ENVIRONMENTS and study.seeds == tuple(range(50))
    assert {t.parameters["pop_size"] for t in trials} == set(table4.POP_SIZES)
    assert all(t.parameters["max_length"] == table4.MAX_LENGTH[t.scenario] for t in trials)
    assert all(t.parameters["max_gen"] == 1000 for t in trials)
    # the paper's GA stops at our reading of its "convergence of the solution", ours at its own patience
    assert {t.parameters["patience"] for t in trials if t.method == "htetro-ga-paper"} == {10}
    assert {t.parameters["patience"] for t in trials if t.method == "htetro-ga"} == {100}
    assert len(trials) == 2 * 6 * 3 * 50 and "gap" in study.metrics  # the paper's GA and ours
    assert len({r.key for r in study.references().values()}) == 6  # one exact reference per map


def test_bundled_sequencing_study():
    study = load_study("sequencing")
    assert study.task == "sequence" and set(study.scenarios) <= set(list_tilesets())
    assert [m.method for m in study.methods] == ["exact", "ortools", "local", "ga", "greedy", "zigzag2"]
    seeded = {t.method for t in study.trials() if t.seed is not None}
    assert seeded == {"ga", "greedy"}  # the others do not depend on a seed: one run each


TILE = 'task = "tile"\nscenarios = ["tiling_6x6"]\n[[methods]]\nmethod = "cpsat"\n'
SEQUENCE = 'task = "sequence"\nscenarios = ["paper_6x6_fig13a"]\n[[methods]]\nmethod = "local"\n'
BAD = {
    "unknown top-level key": ("seed = 3\n" + EXAMPLE, ["unknown key 'seed'"]),
    "unknown task": (EXAMPLE.replace('task = "plan"', 'task = "drive"'), ["task", "'drive'"]),
    "unknown scenario": (EXAMPLE.replace('"h_shape"]', '"atlantis"]'), ["scenarios[2]", "'atlantis'"]),
    "scenario without a roadmap": (EXAMPLE.replace('"h_shape"]', '"tiling_6x6"]'), ["scenarios[2]", "no roadmap"]),
    "unknown method": (EXAMPLE.replace('"htetro-ga"', '"htetro-gaa"'), ["methods[1]", "'htetro-gaa'"]),
    "option the method does not take": (EXAMPLE.replace('method = "dijkstra"', 'method = "dijkstra"\npop_size = 5'),
                                        ["methods[0]", "pop_size", "GA methods ("]),
    "option the verb does not take": (EXAMPLE + 'shapes = "TZ"\n', ["methods[1]", "takes no option 'shapes'"]),
    "wrong type": (EXAMPLE.replace("pop_size = 20", 'pop_size = "20"'), ["methods[1]", "pop_size", "'20'"]),
    "bool for an integer": (EXAMPLE.replace("max_gen = 40", "max_gen = true"), ["methods[1]", "max_gen", "True"]),
    "out of range": (EXAMPLE.replace("pop_size = 20", "pop_size = 1"), ["methods[1]", "pop_size", "at least 2"]),
    "seed in a method entry": (EXAMPLE + "seed = 4\n", ["methods[1]", "seed", "seeds"]),
    "no seeds": (EXAMPLE.replace("seeds = 3", "seeds = 0"), ["seeds", "0"]),
    "a seed twice": (EXAMPLE.replace("seeds = 3", "seeds = [1, 1]"), ["seeds", "twice"]),
    "method missing": (EXAMPLE + "[[methods]]\npop_size = 3\n", ["methods[2]", "method is missing"]),
    "override for another scenario": (EXAMPLE + "[methods.per_scenario.spiral]\nmax_length = 200\n",
                                      ["methods[1]", "per_scenario.spiral", "not one of the study's scenarios"]),
    "bad override": (EXAMPLE + "[methods.per_scenario.random]\nmax_length = 0\n",
                     ["methods[1], per_scenario.random", "max_length"]),
    "unknown metric": ('metrics = ["gapp"]\n' + EXAMPLE, ["metrics[0]", "'gapp'"]),
    "same label twice": (EXAMPLE + '[[methods]]\nmethod = "dijkstra"\n', ["methods[2]", "label 'dijkstra'"]),
    "not TOML": (EXAMPLE.replace("seeds = 3", "seeds = "), ["not valid TOML"]),
    "no methods": (EXAMPLE.split("[[methods]]")[0], ["methods is missing"]),
    "infinite time limit": (TILE + "time_limit = inf\n", ["methods[0]", "time_limit", "inf"]),
    "three weights": (SEQUENCE + "weights = [0.5, 0.25, 0.25]\n", ["methods[0]", "weights"]),
    "shapes for a tileset": (SEQUENCE + 'shapes = "TZ"\n', ["methods[0]", "shapes", "'paper_6x6_fig13a'"]),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_study_file_is_refused_before_anything_runs(tmp_path, case):
    text, expected = BAD[case]
    path = _file(tmp_path, text, "bad.toml")
    with pytest.raises(StudyError) as info:
        load_study(path)
    message = str(info.value)
    assert isinstance(info.value, ParameterError)
    assert str(path) in message, message
    for part in expected:
        assert part in message, message
    with pytest.raises(ParameterError):
        run_study(path, out=tmp_path / "out", executor="serial")
    assert not (tmp_path / "out").exists()


def test_python_study_names_the_study():
    with pytest.raises(StudyError, match=r"study 'x', methods\[0\]: diagonals applies to the exact methods"):
        Study(name="x", task="plan", scenarios=["random"], methods=[{"method": "nsga2", "diagonals": True}])
    with pytest.raises(StudyError, match="name must be"):
        Study(name="../x", task="plan", scenarios=["random"], methods=[{"method": "astar"}])


def test_bad_run_options(tmp_path):
    study = Study(name="x", task="plan", scenarios=["three_slit"], methods=[{"method": "dijkstra"}])
    for options, match in [({"executor": "threads"}, "executor"), ({"executor": "serial", "workers": 2}, "workers"),
                           ({"scheduler": "tcp://127.0.0.1:1"}, "scheduler"), ({"resume": True}, "resume needs out"),
                           ({"retries": -1}, "retries"), ({"progress": 3}, "progress"), ({"seeds": 0}, "seeds")]:
        with pytest.raises(ParameterError, match=match):
            run_study(study, **options)


# --- trials and their records ----------------------------------------------------------------------
def test_sequence_and_tile_records_match_the_solvers(tmp_path):
    from htetro_opt.problems import SequencingInstance
    from htetro_opt.solvers.sequencing import held_karp, sequence_waypoints

    study = Study(name="seq", task="sequence", scenarios=["paper_6x6_fig13a", "tiling_8x7"], seeds=[3, 7],
                  metrics=["gap"], methods=[{"method": "greedy"}, {"method": "zigzag2", "start": "free"}])
    run = run_study(study, executor="serial")
    assert [(r["method"], r["seed"]) for r in run.records] == [("greedy", 3), ("greedy", 7), ("zigzag2", None)] * 2
    for record in run.records:
        scenario = record["scenario"]
        tileset = (load_tileset(tileset_path(scenario)) if scenario in list_tilesets()
                   else tile_workspace(load_scenario(scenario).workspace).tileset)
        start = None if record.get("start") == "free" else 1
        instance = SequencingInstance.from_tileset(tileset, start=start)
        options = {} if record["seed"] is None else {"seed": record["seed"]}
        result = sequence_waypoints(instance, method=record["method"], **options)
        assert record["order"] == ",".join(map(str, result.tiles))
        assert record["cost"] == result.cost and record["waypoints"] == instance.n
        # the gap is to the proven optimum of the same start: Held-Karp as the independent oracle
        optimum = held_karp(instance.cost, start=instance.start)[1]
        assert record["reference"] == pytest.approx(optimum, rel=1e-9)
        assert record["gap"] == pytest.approx((record["cost"] - optimum) / optimum, rel=1e-6, abs=1e-9)

    tiles = Study(name="tiles", task="tile", scenarios=["tiling_6x6"], seeds=2,
                  methods=[{"method": "backtracking"},
                           {"method": "backtracking", "shuffle": True, "label": "shuffled"}])
    records = run_study(tiles, executor="serial").records
    assert [(r["label"], r["seed"]) for r in records] == [("backtracking", None), ("shuffled", 0), ("shuffled", 1)]
    workspace = load_scenario("tiling_6x6").workspace
    for record in records:
        tileset = tile_workspace(workspace, shuffle=record.get("shuffle", False), seed=record["seed"]).tileset
        assert record["tileset"].split(";") == [" ".join(r.split()) for r in format_tileset(tileset).split("\n")]
        assert record["tiles"] == len(tileset) == 9
        assert sum(record[f"n_{s}"] for s in "IOLJZST") == 9


def test_trial_key_hashes_the_inputs():
    a = run_trial("plan", "three_slit", "astar", {"clearance": 0.0}, None)
    b = run_trial("plan", "three_slit", "exact", {"clearance": 0.0}, None, label="astar")
    c = run_trial("plan", "three_slit", "astar", {}, None)
    assert a["key"] == b["key"] and a["key"] != c["key"]  # "exact" is astar; an option given is an input
    study = Study(name="k", task="plan", scenarios=["three_slit"], methods=[{"method": "astar", "clearance": 0.0}],
                  metrics=())  # a metric asked for is an input of the key too
    assert study.trials()[0].key == a["key"]


# --- executors -------------------------------------------------------------------------------------
def test_processes_give_the_serial_records(agree_baseline, tmp_path):
    path, baseline = agree_baseline
    run = run_study(path, executor="processes", workers=2, out=tmp_path)
    assert _content(run.records + run.references) == baseline
    assert _content(_lines(run.path)) == baseline  # the file holds the same, one line per trial
    # the gaps against the planner's own exact optimum
    for record in run.records:
        scenario = load_scenario(record["scenario"])
        exact = plan_path(scenario.workspace, scenario.roadmap, method="dijkstra").time
        assert record["reference"] == exact
        assert record["gap"] == (None if not record["reached"] else (record["time"] - exact) / exact)
    assert any(r["gap"] is None for r in run.records) and any(r["gap"] and r["gap"] > 0 for r in run.records)


def test_dask_local_cluster_gives_the_serial_records(agree_baseline):
    distributed = pytest.importorskip("distributed")
    path, baseline = agree_baseline
    cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=False, dashboard_address=":0")
    client = distributed.Client(cluster)
    try:
        notes = []
        run = run_study(path, executor="dask", scheduler=client, progress=lambda d, t, note: notes.append(note))
    finally:
        client.close()
        cluster.close()
    assert _content(run.records + run.references) == baseline
    assert run.dashboard and any(n.startswith("Dask dashboard: ") for n in notes)


@pytest.fixture
def dask_processes(tmp_path):
    """A Dask scheduler and two workers, each a process of its own on 127.0.0.1; the address."""
    pytest.importorskip("distributed")
    started = []
    scheduler_file = tmp_path / "scheduler.json"

    def start(module, *args):
        with open(tmp_path / f"{module.rsplit('.', 1)[-1]}-{len(started)}.log", "w") as log:
            started.append(subprocess.Popen([sys.executable, "-m", module, *args], stdout=log,
                                            stderr=subprocess.STDOUT))

    try:
        start("distributed.cli.dask_scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
              "--scheduler-file", str(scheduler_file))
        deadline = time.monotonic() + 300  # hang guards, wide enough for a busy machine, not measures
        while not scheduler_file.exists() or not scheduler_file.read_text():
            assert time.monotonic() < deadline, "the Dask scheduler did not start"
            time.sleep(0.05)
        time.sleep(0.05)  # the file is written in one go, but let it be complete
        address = json.loads(scheduler_file.read_text())["address"]
        for _ in range(2):
            start("distributed.cli.dask_worker", address, "--nthreads", "1", "--no-nanny", "--no-dashboard",
                  "--host", "127.0.0.1")
        from distributed import Client

        with Client(address, timeout="300s") as client:
            client.wait_for_workers(2, timeout=300)
        yield address
    finally:
        for process in reversed(started):
            process.terminate()
        for process in started:
            try:  # a worker keeps trying to reach a scheduler that is gone: do not wait for it long
                process.wait(timeout=2)
            except subprocess.TimeoutExpired:
                process.kill()
                process.wait()


def test_dask_scheduler_and_worker_processes_give_the_serial_records(agree_baseline, dask_processes):
    path, baseline = agree_baseline
    run = run_study(path, executor="dask", scheduler=dask_processes)
    assert _content(run.records + run.references) == baseline


# --- interruption and resume -----------------------------------------------------------------------
SLOW = '''\
name = "slow"
task = "plan"
scenarios = ["three_slit"]
seeds = 14
metrics = []                  # trials only: no exact reference among the lines counted
[[methods]]
method = "htetro-ga"
pop_size = 16
max_gen = 40
'''


def test_killed_run_resumes_to_the_uninterrupted_records(tmp_path):
    path = _file(tmp_path, SLOW)
    out = tmp_path / "out"
    results = out / "slow.jsonl"
    code = ("from htetro_opt.studies.runner import run_study; "
            f"run_study({str(path)!r}, out={str(out)!r}, executor='serial')")
    child = subprocess.Popen([sys.executable, "-c", code])
    try:
        deadline = time.monotonic() + 600  # a hang guard, not a measure
        while not results.exists() or results.read_text().count("\n") < 3:
            assert child.poll() is None, "the study ended before it could be killed"
            assert time.monotonic() < deadline
            time.sleep(0.01)
        assert child.poll() is None
        os.kill(child.pid, signal.SIGKILL)
    finally:
        child.wait()
    before = read_records(results)
    assert 3 <= len(before) < 14

    resumed = run_study(path, out=out, executor="processes", workers=2, resume=True)
    assert resumed.resumed == len(before)
    uninterrupted = run_study(path, executor="serial")
    assert _content(resumed.records) == _content(uninterrupted.records)
    lines = _lines(results)
    assert len(lines) == 14 and len({r["key"] for r in lines}) == 14  # none lost, none twice
    assert _content(lines) == _content(uninterrupted.records)


def dying_trial(task, scenario, method, parameters, seed, *, label=None, metrics=()):
    if seed == 1:
        os._exit(3)  # a worker process killed mid-trial (out of memory, say)
    return run_trial(task, scenario, method, parameters, seed, label=label, metrics=metrics)


def test_lost_worker_process_stops_the_run_and_keeps_the_records(tmp_path):
    study = Study(name="lost", task="plan", scenarios=["three_slit"], seeds=[0, 1], metrics=(),
                  methods=[{"method": "htetro-ga", "pop_size": 4, "max_gen": 2}])
    with pytest.raises(WorkerLost, match="resume continues the study"):
        run_study(study, out=tmp_path, executor="processes", workers=1, trial=dying_trial)
    kept = read_records(tmp_path / "lost.jsonl")
    assert [r["seed"] for r in kept] in ([], [0])  # seed 0 may or may not have finished first
    resumed = run_study(study, out=tmp_path, executor="serial", resume=True)
    assert [r["seed"] for r in resumed.records] == [0, 1] and resumed.failed == 0


def test_seeds_override_and_unseeded_methods(tmp_path):
    study = load_study(_file(tmp_path, EXAMPLE.replace("max_gen = 40", "max_gen = 2")))
    trials = study.with_seeds([5]).trials()
    assert [(t.method, t.seed) for t in trials] == [("dijkstra", None), ("htetro-ga", 5)] * 3
    run = run_study(study, seeds=[5], executor="serial")
    assert [r["seed"] for r in run.records] == [None, 5] * 3


def test_torn_last_line_is_dropped_on_resume(tmp_path):
    study = Study(name="torn", task="plan", scenarios=["three_slit", "h_shape"], methods=[{"method": "dijkstra"}],
                  metrics=())
    first = run_study(study, out=tmp_path, executor="serial")
    text = first.path.read_text()
    lines = text.splitlines(keepends=True)
    torn = lines[0] + lines[1][: len(lines[1]) // 2]  # killed while writing the second line
    first.path.write_text(torn)

    assert read_records(first.path) == [json.loads(lines[0])] and first.path.read_text() == torn  # left as it is
    with pytest.raises(OutputError, match="already holds 1 records"):
        run_study(study, out=tmp_path, executor="serial")
    again = run_study(study, out=tmp_path, executor="serial", resume=True)
    assert again.resumed == 1
    assert _content(again.records) == _content(first.records)
    assert _content(_lines(again.path)) == _content(first.records)

    again.path.write_text(lines[0] + "{not json\n" + lines[1])  # damage that is not a torn write
    with pytest.raises(StudyError, match=r"line 2: not a trial record"):
        run_study(study, out=tmp_path, executor="serial", resume=True)


# --- failures and retries --------------------------------------------------------------------------
def flaky_trial(task, scenario, method, parameters, seed, *, label=None, metrics=()):
    """Fails the first time it runs each trial (a marker file remembers), then runs it."""
    marker = Path(os.environ["HTETRO_TEST_MARKERS"]) / f"{scenario}-{label}-{seed}"
    with open(marker, "a") as handle:
        handle.write("x")
    if marker.read_text() == "x":
        raise RuntimeError(f"transient failure of seed {seed}")
    return run_trial(task, scenario, method, parameters, seed, label=label, metrics=metrics)


def failing_trial(task, scenario, method, parameters, seed, *, label=None, metrics=()):
    marker = Path(os.environ["HTETRO_TEST_MARKERS"]) / f"{scenario}-{label}-{seed}"
    with open(marker, "a") as handle:
        handle.write("x")
    raise KeyError("always")


def test_failing_trial_is_recorded_and_the_study_goes_on(tmp_path):
    # tiling_8x7 tiles into 14 tiles: there is no tile 50 to start from, which only the trial finds out
    study = Study(name="fail", task="sequence", scenarios=["tiling_8x7"], metrics=(),
                  methods=[{"method": "zigzag", "start": 50}, {"method": "zigzag2"}])
    notes = []
    run = run_study(study, out=tmp_path, executor="processes", workers=2,
                    progress=lambda done, total, note: notes.append((done, total, note)))
    bad, good = run.records
    assert bad["error"].startswith("ParameterError: ") and "no tile 50" in bad["error"]
    assert bad["start"] == 50 and "cost" not in bad
    assert good["error"] is None and good["cost"] > 0
    assert run.failed == 1 and notes[-1][:2] == (2, 2) and notes[-1][2].endswith("1 failed")
    assert [(r["errors"], r["success_rate"]) for r in run.summary] == [(1, 0.0), (0, 1.0)]
    assert _content(_lines(run.path)) == _content(run.records)


@pytest.mark.parametrize("executor", ["serial", "processes", "dask"])
def test_retries(tmp_path, monkeypatch, executor):
    if executor == "dask":
        distributed = pytest.importorskip("distributed")
        cluster = distributed.LocalCluster(n_workers=1, threads_per_worker=2, processes=False, dashboard_address=":0")
        client = distributed.Client(cluster)
        options = {"scheduler": client}
    else:
        options = {"workers": 2} if executor == "processes" else {}
    study = Study(name="flaky", task="plan", scenarios=["three_slit"], seeds=2,
                  methods=[{"method": "htetro-ga", "pop_size": 4, "max_gen": 2}])

    def markers(phase):
        (tmp_path / phase).mkdir()
        monkeypatch.setenv("HTETRO_TEST_MARKERS", str(tmp_path / phase))
        return tmp_path / phase

    try:
        markers("once")
        once = run_study(study, executor=executor, trial=flaky_trial, **options)
        assert [r["error"] for r in once.records] == ["RuntimeError: transient failure of seed 0",
                                                      "RuntimeError: transient failure of seed 1"]
        markers("retried")
        retried = run_study(study, executor=executor, trial=flaky_trial, retries=1, **options)
        assert [r["error"] for r in retried.records] == [None, None]
        assert _content(retried.records) == _content(run_study(study, executor="serial").records)

        folder = markers("hopeless")
        hopeless = run_study(study, executor=executor, trial=failing_trial, retries=2, **options)
        assert [r["error"] for r in hopeless.records] == ["KeyError: 'always'"] * 2
        assert sorted(p.read_text() for p in folder.iterdir()) == ["xxx", "xxx"]  # 1 + 2 retries each
    finally:
        if executor == "dask":
            client.close()
            cluster.close()


# --- summaries -------------------------------------------------------------------------------------
def test_summary_against_hand_computed_values(tmp_path):
    def record(label, **values):
        return {"kind": "trial", "task": "plan", "scenario": "map", "label": label, "method": "htetro-ga",
                "error": None, **values}

    records = [
        record("ga", reached=True, time=1.0, n_commands=10, reference=1.0, gap=0.0, runtime_s=0.5),
        record("ga", reached=True, time=2.0, n_commands=20, reference=1.0, gap=1.0, runtime_s=1.5),
        record("ga", reached=True, time=4.0, n_commands=40, reference=1.0, gap=3.0, runtime_s=1.0),
        record("ga", reached=False, time=None, n_commands=None, reference=1.0, gap=None, runtime_s=2.0),
        {**record("ga"), "error": "RuntimeError: boom"},
        record("exact", method="dijkstra", reached=True, time=1.0, n_commands=10, reference=1.0, gap=0.0,
               runtime_s=0.25),
        {**record("exact", method="dijkstra"), "kind": "reference", "reached": True, "time": 1.0},  # left out
    ]
    ga, exact = summarise(records)
    assert (ga["label"], ga["runs"], ga["errors"], ga["successes"], ga["success_rate"]) == ("ga", 5, 1, 3, 0.6)
    assert ga["reference"] == 1.0
    # times 1, 2, 4: mean 7/3, sample variance ((4/3)² + (1/3)² + (5/3)²) / 2 = 7/3, median 2
    assert ga["time_mean"] == pytest.approx(7 / 3)
    assert ga["time_std"] == pytest.approx(math.sqrt(7 / 3))
    assert ga["time_median"] == 2.0
    assert (ga["gap_mean"], ga["gap_median"]) == (pytest.approx(4 / 3), 1.0)
    assert ga["gap_std"] == pytest.approx(math.sqrt(((4 / 3) ** 2 + (1 / 3) ** 2 + (5 / 3) ** 2) / 2))
    # runtimes 0.5, 1.5, 1.0, 2.0 (the failed run measured none): mean 1.25, median 1.25
    assert (ga["runtime_s_mean"], ga["runtime_s_median"]) == (1.25, 1.25)
    assert ga["runtime_s_std"] == pytest.approx(statistics.stdev([0.5, 1.5, 1.0, 2.0]))
    assert (exact["runs"], exact["time_mean"], exact["time_std"], exact["time_median"]) == (1, 1.0, None, 1.0)

    csv_path, md_path = write_summary([ga, exact], tmp_path, name="hand")
    rows = list(csv.DictReader(csv_path.open()))
    assert [r["label"] for r in rows] == ["ga", "exact"]
    assert float(rows[0]["time_mean"]) == pytest.approx(7 / 3) and rows[1]["time_std"] == ""
    text = md_path.read_text()
    assert "| map | ga | 5 | 3/5 | 1 | 2.333 ± 1.528 (2.000) |" in text
