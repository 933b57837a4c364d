"""The study runner's multi-objective metrics: the front and its hypervolume per trial, IGD+ over a
study's runs, the GA's convergence history, and the metrics' validation."""

import itertools
import random

import numpy as np
import pytest

from htetro_opt.errors import ParameterError
from htetro_opt.scenarios import load_scenario
from htetro_opt.solvers.grid_paths import plan_path
from htetro_opt.studies.runner import (
    HV_REFERENCE,
    RUNTIME_FIELDS,
    Study,
    StudyError,
    front_metrics,
    hypervolume,
    load_study,
    markdown_summary,
    read_records,
    run_study,
    run_trial,
    summarise,
)


# --- independent oracles ---------------------------------------------------------------------------
def box_union_volume(fitness, reference=HV_REFERENCE):
    """Exact volume of the union of the boxes [−f, r] (minimisation space) by inclusion–exclusion:
    the boxes of a subset intersect in the box from their componentwise worst corner to r."""
    points = [tuple(-v for v in row) for row in fitness]
    total = 0.0
    for size in range(1, len(points) + 1):
        for subset in itertools.combinations(points, size):
            corner = [max(p[j] for p in subset) for j in range(4)]
            volume = 1.0
            for j in range(4):
                volume *= max(reference[j] - corner[j], 0.0)
            total += (-1) ** (size + 1) * volume
    return total


def dominates(a, b):
    """a dominates b, fitnesses maximised."""
    return all(x >= y for x, y in zip(a, b)) and any(x > y for x, y in zip(a, b))


def reference_front(fronts):
    """The union's leading front, naively: goal-reaching points (f_gr = 1) if any, then those no other
    point of that pool dominates."""
    union = {tuple(row) for front in fronts for row in front}
    pool = [p for p in union if p[0] == 1.0] or list(union)
    return [p for p in pool if not any(dominates(q, p) for q in pool)]


def igd_plus(front, reference):
    """Mean over reference points z of min over front points a of ‖max(a − z, 0)‖, in F = −f."""
    total = 0.0
    for z in reference:
        total += min(sum(max(-a_j + z_j, 0.0) ** 2 for a_j, z_j in zip(a, z)) ** 0.5 for a in front)
    return total / len(reference)


def content(records):
    """Records without their wall-clock fields, in key order."""
    return sorted(({k: v for k, v in r.items() if k not in RUNTIME_FIELDS} for r in records), key=lambda r: r["key"])


# --- hypervolume -----------------------------------------------------------------------------------
def test_hypervolume_hand_computed():
    assert HV_REFERENCE == (0.0, 1.0, 0.0, 0.0)
    # one point: its box to r = (0, 1, 0, 0) in F = −f is 1 × (0.5 + 1) × 0.5 × 0.5
    assert hypervolume([[1.0, 0.5, 0.5, 0.5]]) == pytest.approx(0.375)
    # two points: 0.375 + 1 × 1 × 1 × 1 − the overlap 1 × 1 × 0.5 × 0.5
    assert hypervolume([[1.0, 0.5, 0.5, 0.5], [1.0, 0.0, 1.0, 1.0]]) == pytest.approx(1.125)
    # the ideal point spans the whole box; a dominated point or a duplicate adds nothing
    assert hypervolume([[1.0, 1.0, 1.0, 1.0]]) == pytest.approx(2.0)
    assert hypervolume([[1.0, 0.5, 0.5, 0.5], [0.5, 0.2, 0.5, 0.1], [1.0, 0.5, 0.5, 0.5]]) == pytest.approx(0.375)
    # slower than 2 t_max (f_t < −1), or no goal progress: outside the reference box
    assert hypervolume([[1.0, -1.5, 1.0, 1.0], [0.0, 1.0, 1.0, 1.0]]) == 0.0
    assert hypervolume([]) == 0.0


def test_hypervolume_matches_an_exact_box_union_on_random_fronts():
    rng = np.random.default_rng(7)
    for _ in range(40):
        n = int(rng.integers(1, 7))
        fitness = np.column_stack([rng.choice([1.0, rng.uniform()], size=n), rng.uniform(-1.3, 1.0, n),
                                   rng.uniform(0, 1, n), rng.uniform(0, 1, n)]).round(3)
        assert hypervolume(fitness.tolist()) == pytest.approx(box_union_volume(fitness.tolist()), abs=1e-12)


@pytest.mark.parametrize("front", [[[1.0, 0.5, 0.5]], "front", [[1.0, 0.5, 0.5, float("nan")]], [[1.0, [0.5]]]])
def test_hypervolume_refuses_what_is_not_a_front(front):
    with pytest.raises(ParameterError, match="four finite fitnesses"):
        hypervolume(front)


# --- IGD+ ------------------------------------------------------------------------------------------
def _record(scenario, label, seed, front, **extra):
    return {"kind": "trial", "task": "plan", "scenario": scenario, "label": label, "method": "htetro-ga",
            "seed": seed, "reached": True, "front": front, "hv": hypervolume(front), **extra}


# two goal-reaching trade-offs, a point they dominate, and an unreached point with a better f_t,
# which is not in the reference front (goal reachability first, as in the leading front)
BEST = [[1.0, 0.6, 0.5, 0.9], [1.0, 0.8, 0.4, 0.5]]
WORSE = [[1.0, 0.5, 0.4, 0.8]]
UNREACHED = [[0.4, 0.9, 0.9, 0.9]]


def test_igd_plus_is_zero_for_the_union_and_positive_for_a_dominated_front():
    records = [_record("a", "ga", 0, BEST), _record("a", "ga", 1, WORSE), _record("a", "nsga2", 0, BEST[:1]),
               _record("a", "nsga2", 1, UNREACHED + WORSE)]
    out = front_metrics(records)
    reference = reference_front([r["front"] for r in records])
    assert sorted(reference) == sorted(map(tuple, BEST))
    assert out[0]["igd_plus"] == 0.0
    for record in out[1:]:
        assert record["igd_plus"] == pytest.approx(igd_plus(record["front"], reference))
        assert record["igd_plus"] > 0.0
    # by hand: WORSE's point (0.5, 0.4, 0.8) lags (0.6, 0.5, 0.9) by 0.1 thrice and (0.8, 0.4, 0.5) by 0.3 on f_t
    assert out[1]["igd_plus"] == pytest.approx((0.03 ** 0.5 + 0.3) / 2)
    # new dicts, igd_plus right after hv, the inputs untouched
    assert list(out[0])[-2:] == ["hv", "igd_plus"] and "igd_plus" not in records[0]


def test_igd_plus_pools_per_scenario_and_fitness_definition_and_ignores_order():
    records = [_record("a", "ga", 0, WORSE), _record("a", "ga", 1, BEST),
               _record("b", "ga", 0, WORSE),                              # alone on its map
               _record("a", "ga", 2, WORSE, max_length=200),              # another t_max: another f_t
               {"kind": "trial", "task": "plan", "scenario": "a", "label": "exact", "method": "dijkstra",
                "seed": None, "reached": True, "time": 33.0}]              # no front: unchanged
    out = front_metrics(records)
    assert out[0]["igd_plus"] > 0.0
    assert out[1]["igd_plus"] == out[2]["igd_plus"] == out[3]["igd_plus"] == 0.0
    assert out[4] == records[4]
    for seed in range(5):
        shuffled = list(records)
        random.Random(seed).shuffle(shuffled)
        again = {(r["scenario"], r["seed"], r.get("max_length")): r.get("igd_plus") for r in front_metrics(shuffled)}
        assert again == {(r["scenario"], r["seed"], r.get("max_length")): r.get("igd_plus") for r in out}


def test_summary_reports_hv_and_igd_plus_per_scenario_and_method():
    records = [_record("a", "ga", 0, BEST), _record("a", "ga", 1, WORSE), _record("a", "nsga2", 0, WORSE)]
    rows = {row["label"]: row for row in summarise(records)}
    worse = igd_plus(WORSE, reference_front([BEST, WORSE]))
    assert rows["ga"]["hv_mean"] == pytest.approx((box_union_volume(BEST) + box_union_volume(WORSE)) / 2)
    assert rows["ga"]["igd_plus_mean"] == pytest.approx(worse / 2)
    assert rows["ga"]["igd_plus_std"] == pytest.approx(worse / 2 ** 0.5)
    assert rows["ga"]["igd_plus_median"] == pytest.approx(worse / 2)
    assert rows["nsga2"]["igd_plus_mean"] == pytest.approx(worse) and rows["nsga2"]["igd_plus_std"] is None
    table = markdown_summary(list(rows.values()))
    assert "hv mean ± std (median)" in table and "igd_plus mean ± std (median)" in table


# --- the runner ------------------------------------------------------------------------------------
# On random, three runs reach the goal and one does not; on h_shape, one reaches.
TINY = {"name": "fronts", "task": "plan", "scenarios": ["random", "h_shape"], "seeds": 2,
        "metrics": ["front", "history", "generations"],
        "methods": [{"method": "htetro-ga", "pop_size": 16, "max_gen": 30, "patience": 5},
                    {"method": "nsga2", "pop_size": 16, "max_gen": 30, "patience": 5}]}


@pytest.fixture(scope="module")
def tiny_serial(tmp_path_factory):
    out = tmp_path_factory.mktemp("serial")
    return run_study(Study(**TINY), out=out, executor="serial")


def test_ga_records_carry_their_front_hv_and_history(tiny_serial):
    assert len(tiny_serial.records) == 8
    assert {r["reached"] for r in tiny_serial.records} == {True, False}
    for record in tiny_serial.records:
        assert record["error"] is None
        # the front is the plan's last leg's leading front, as plan_path gives it with the trial's seed
        scenario = load_scenario(record["scenario"])
        plan = plan_path(scenario.workspace, scenario.roadmap, method=record["method"], pop_size=16, max_gen=30,
                         patience=5, seed=record["seed"])
        leg = plan.legs[-1]
        expected = {tuple(round(float(v), 6) for v in member.fitness) for member in leg.front}
        assert sorted(map(tuple, record["front"])) == sorted(expected)
        assert len(record["front"]) == len(expected)  # distinct rows
        assert record["hv"] == pytest.approx(box_union_volume(record["front"]), abs=1e-12)
        assert 0.0 <= record["hv"] <= 2.0
        assert all(row[0] == 1.0 for row in record["front"]) == record["reached"]
        # the convergence curve: the multi-objective solution's fitnesses, one row per generation
        assert len(record["history"]) == record["generations"] == leg.generations
        assert record["history"] == np.round(leg.history, 6).tolist()


def test_summary_of_a_ga_study_carries_hv_and_igd_plus(tiny_serial):
    records = tiny_serial.records
    for row in tiny_serial.summary:
        group = [r for r in records if (r["scenario"], r["label"]) == (row["scenario"], row["label"])]
        pool = [r["front"] for r in records if r["scenario"] == row["scenario"]]
        values = [igd_plus(r["front"], reference_front(pool)) for r in group]
        assert row["hv_mean"] == pytest.approx(np.mean([r["hv"] for r in group]))
        assert row["igd_plus_mean"] == pytest.approx(np.mean(values))
        assert row["igd_plus_median"] == pytest.approx(np.median(values))
    # the results file holds what the summary needs: summarising it again gives the same table
    assert summarise(read_records(tiny_serial.path)) == tiny_serial.summary
    text = tiny_serial.path.with_suffix(".md").read_text(encoding="utf-8")
    assert "igd_plus mean" in text and "hv mean" in text


def test_processes_give_the_serial_records(tiny_serial, tmp_path):
    run = run_study(Study(**TINY), out=tmp_path, executor="processes", workers=2)
    assert content(run.records) == content(tiny_serial.records)
    def clocked(name):
        return name.startswith(RUNTIME_FIELDS)

    summary = [{k: v for k, v in row.items() if not clocked(k)} for row in run.summary]
    assert summary == [{k: v for k, v in row.items() if not clocked(k)} for row in tiny_serial.summary]
    assert all(row["igd_plus_mean"] is not None for row in summary)


# --- validation ------------------------------------------------------------------------------------
@pytest.mark.parametrize("metric", ["front", "history"])
def test_ga_metrics_on_an_exact_method_name_the_entry(tmp_path, metric):
    study = tmp_path / "mixed.toml"
    study.write_text(f'task = "plan"\nscenarios = ["three_slit"]\nmetrics = ["{metric}"]\n'
                     '[[methods]]\nmethod = "htetro-ga"\n[[methods]]\nmethod = "exact"\n', encoding="utf-8")
    with pytest.raises(StudyError) as err:
        load_study(study)
    for words in (str(study), "methods[1]", repr(metric), "GA methods (", "astar"):
        assert words in str(err.value)
    with pytest.raises(ParameterError, match=rf"'{metric}' applies to the GA methods \(.*\) only, not to astar"):
        run_trial("plan", "three_slit", "astar", {}, None, metrics=[metric])


@pytest.mark.parametrize("task, scenario, method", [("tile", "three_slit", "backtracking"),
                                                    ("sequence", "paper_6x6_fig13a", "exact")])
def test_front_on_another_task_is_refused(task, scenario, method):
    with pytest.raises(StudyError, match=r"metrics\[0\]: unknown metric 'front' for task " + task):
        Study(name="d", task=task, scenarios=[scenario], metrics=["front"], methods=[{"method": method}])


def test_hv_curve_is_the_front_hypervolume_by_generation_and_never_falls_behind_the_final_front():
    from htetro_opt.studies.runner import HV_REFERENCE, hypervolume, run_trial

    record = run_trial("plan", "three_slit", "htetro-ga", {"pop_size": 12, "max_gen": 15, "patience": 5},
                       3, metrics=("front", "hv_curve", "generations"))
    curve = record["hv_curve"]
    assert len(curve) == record["generations"] and all(v >= 0 for v in curve)
    # the last generation's value is the final front's hypervolume (computed independently from the rows)
    assert curve[-1] == pytest.approx(hypervolume(record["front"]), abs=1e-5)
    assert HV_REFERENCE == (0.0, 1.0, 0.0, 0.0)


def test_hv_curve_is_refused_for_an_exact_method():
    from htetro_opt.studies.runner import run_trial

    with pytest.raises(Exception, match="hv_curve"):
        run_trial("plan", "three_slit", "dijkstra", {}, None, metrics=("hv_curve",))
