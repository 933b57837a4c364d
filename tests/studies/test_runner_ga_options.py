"""The study runner's hTetro-GA options (re-planning, exact seeding, pick, convergence, reaching share)
and its ``fastest_gap`` metric."""

import pytest

from htetro_opt.errors import ParameterError
from htetro_opt.scenarios import load_scenario
from htetro_opt.solvers.grid_paths import plan_path
from htetro_opt.studies.runner import Study, StudyError, load_study, run_study, run_trial

TINY = {"pop_size": 16, "max_gen": 100, "patience": 10}  # reaches the goal of h_shape and random with seeds 0 and 2
OPTIONS = {"replan_window": 12, "replan_members": 1, "seed_exact": False, "pick": "fastest",
           "convergence": "hypervolume", "reach_share": 0.75, "polish_window": 0}


def _study(**entry):
    return Study(name="x", task="plan", scenarios=["three_slit"], methods=[entry])


def test_ga_options_are_taken_and_reach_the_planner():
    study = Study(name="x", task="plan", scenarios=["h_shape"], methods=[{"method": "htetro-ga", **TINY, **OPTIONS}])
    assert study.methods[0].options == {**TINY, **OPTIONS}
    record = run_trial("plan", "h_shape", "htetro-ga", study.methods[0].parameters(study.scenarios[0]), 0)
    grid = load_scenario("h_shape")
    plan = plan_path(grid.workspace, grid.roadmap, method="htetro-ga", seed=0, **TINY, **OPTIONS)
    assert record["reached"] and record["commands"] == ",".join(plan.tokens)
    assert record["pick"] == "fastest" and record["replan_window"] == 12
    # the options change the run: without them the same seed gives another plan here
    other = run_trial("plan", "h_shape", "htetro-ga", TINY, 0)
    assert other["reached"] and other["commands"] != record["commands"]


@pytest.mark.parametrize("method", ["nsga2", "smsemoa"])
def test_pymoo_algorithms_take_every_ga_option_but_the_reaching_share(method):
    _study(method=method, pick="safest", convergence="best", seed_exact=True, replan_window=40, replan_members=2)
    with pytest.raises(StudyError, match=rf"methods\[0\]: reach_share applies to htetro-ga only, not to {method}"):
        _study(method=method, reach_share=1.0)


def test_pymoo_algorithm_records_the_replanning_run():
    options = {"pop_size": 12, "max_gen": 8, "replan_window": 20, "replan_members": 1}
    record = run_trial("plan", "random", "nsga2", options, 0)
    grid = load_scenario("random")
    plan = plan_path(grid.workspace, grid.roadmap, method="nsga2", seed=0, **options)
    assert record["commands"] == ",".join(plan.tokens) and record["replan_window"] == 20


@pytest.mark.parametrize("method", ["htetro-ga", "htetro-ga-paper"])
def test_the_conservative_option_is_pymoos_algorithms_only(method):
    assert _study(method="nsga3", conservative=True).methods[0].options == {"conservative": True}
    with pytest.raises(StudyError, match=r"methods\[0\]: conservative applies to pymoo's algorithms "
                                         rf"\(nsga2, nsga3, smsemoa, agemoea\) only, not to {method}"):
        _study(method=method, conservative=True)
    with pytest.raises(StudyError, match=r"methods\[0\]: conservative"):
        _study(method="nsga2", conservative="yes")


def test_pymoo_algorithm_records_the_conservative_run():
    options = {"pop_size": 12, "max_gen": 8, "conservative": True, "replan_window": 20}
    record = run_trial("plan", "random", "smsemoa", options, 0)
    grid = load_scenario("random")
    plan = plan_path(grid.workspace, grid.roadmap, method="smsemoa", seed=0, **options)
    plain = plan_path(grid.workspace, grid.roadmap, method="smsemoa", seed=0, **{**options, "conservative": False})
    assert record["commands"] == ",".join(plan.tokens) and record["conservative"] is True
    assert str(plan.legs[0].front) != str(plain.legs[0].front)  # the option reaches the algorithm


@pytest.mark.parametrize("method", ["dijkstra", "exact", "astar", "heat"])
@pytest.mark.parametrize("key, value", sorted(OPTIONS.items()))
def test_exact_and_heat_methods_refuse_every_ga_option_by_name(method, key, value):
    with pytest.raises(StudyError, match=rf"methods\[0\]: {key} applies to .* only, not to "):
        _study(method=method, **{key: value})


@pytest.mark.parametrize("key, value, match", [
    ("pick", "quickest", "pick must be one of balanced, fastest, smoothest, safest"),
    ("pick", 1, "pick must be one of"),
    ("convergence", "front", "convergence must be one of best, hypervolume"),
    ("seed_exact", "yes", "seed_exact"),
    ("replan_window", -1, "replan_window"),
    ("replan_window", 2.5, "replan_window"),
    ("replan_members", -3, "replan_members"),
    ("reach_share", 0.0, "reach_share"),
    ("reach_share", 1.5, "reach_share"),
])
def test_bad_ga_option_values_name_the_entry_and_key(tmp_path, key, value, match):
    with pytest.raises(StudyError, match=rf"methods\[0\]: {match}"):
        _study(method="htetro-ga-paper", **{key: value})
    text = f'task = "plan"\nscenarios = ["random"]\n[[methods]]\nmethod = "htetro-ga"\n' \
           f'[methods.per_scenario.random]\n{key} = {value!r}\n'.replace("'", '"')
    path = tmp_path / "bad.toml"
    path.write_text(text.replace("= True", "= true").replace("= False", "= false"))
    with pytest.raises(StudyError, match=r"methods\[0\], per_scenario.random: "):
        load_study(path)


def test_fastest_gap_is_the_legs_fastest_front_member_against_the_exact_optimum(tmp_path):
    study = Study(name="g", task="plan", scenarios=["h_shape", "random"], seeds=[0, 2], metrics=["gap"],
                  methods=[{"method": "exact"}, {"method": "htetro-ga", **TINY}])
    run = run_study(study, executor="serial")
    exact = {r["scenario"]: r for r in run.references}
    for record in run.records:
        best = exact[record["scenario"]]["time"]
        if record["method"] == "astar":  # "exact"
            assert "fastest_gap" not in record and record["gap"] == 0.0
            continue
        assert record["reached"]
        grid = load_scenario(record["scenario"])
        plan = plan_path(grid.workspace, grid.roadmap, method="htetro-ga", seed=record["seed"], **TINY)
        # the oracle: every leg's front, not the plan's own selection
        fastest = sum(min(m.time for m in leg.front if m.reached) for leg in plan.legs)
        assert record["fastest_time"] == pytest.approx(fastest)
        assert record["fastest_gap"] == pytest.approx((fastest - best) / best)
        assert record["gap"] == pytest.approx((plan.time - best) / best)
        assert 0.0 <= record["fastest_gap"] <= record["gap"]  # static maps: no leg is faster than its optimum
    rows = {(row["scenario"], row["label"]): row for row in run.summary}
    ga = [r for r in run.records if r["scenario"] == study.scenarios[0] and r["method"] != "astar"]
    row = rows[(study.scenarios[0], "htetro-ga")]
    assert row["fastest_gap_mean"] == pytest.approx(sum(r["fastest_gap"] for r in ga) / len(ga))


def test_pick_fastest_makes_the_two_gaps_equal_on_a_one_leg_map():
    study = Study(name="f", task="plan", scenarios=["random"], seeds=[0], metrics=["gap"],
                  methods=[{"method": "htetro-ga", "pick": "fastest", **TINY}])
    assert len(load_scenario("random").roadmap) == 2
    (record,) = run_study(study, executor="serial").records
    assert record["reached"] and record["gap"] == record["fastest_gap"]


def test_fastest_gap_needs_the_gap_metric():
    record = run_trial("plan", "three_slit", "htetro-ga", TINY, 0)
    assert "fastest_time" not in record and "fastest_gap" not in record
    with pytest.raises(ParameterError, match="metric"):
        run_trial("plan", "three_slit", "htetro-ga", TINY, 0, metrics=["fastest_gap"])


def test_bundled_ga_replan_study_is_issue_15s_setting():
    from htetro_opt.scenarios import list_scenarios

    study = load_study("ga_replan")
    names = [s.rsplit("/", 1)[-1] for s in study.scenarios]
    assert names == ["random", "spiral", "h_shape", "three_slit", "perpendicular_dynamic", "parallel_dynamic",
                     "maze", "zigzag"]
    # every bundled Cheng et al. 2020 (seed 000) map, both moving-obstacle maps among them
    cheng2020 = {n for n in list_scenarios() if getattr(load_scenario(n), "source", "").startswith("Cheng et al., "
                                                                                                    "IEEE Access 2020")}
    assert cheng2020 == set(names[:6])
    assert all(load_scenario(s).workspace.moving for s in study.scenarios[4:6])
    assert study.seeds == tuple(range(10)) and "gap" in study.metrics and "generations" in study.metrics
    assert [(m.method, dict(m.options)) for m in study.methods] == [("htetro-ga", {"pop_size": 50}),
                                                                     ("htetro-ga-paper", {"pop_size": 50})]
    assert len(study.trials()) == 160 and len({r.key for r in study.references().values()}) == 8


@pytest.mark.parametrize("method", ["nsga2", "dijkstra"])
def test_reach_patience_is_the_htetro_gas_option(method):
    for ga in ("htetro-ga", "htetro-ga-paper"):
        assert _study(method=ga, reach_patience=0).methods[0].options == {"reach_patience": 0}
    with pytest.raises(StudyError, match=r"methods\[0\]: reach_patience"):
        _study(method="htetro-ga", reach_patience=-1)
    with pytest.raises(StudyError, match=rf"methods\[0\]: reach_patience applies to the .* not to {method}"):
        _study(method=method, reach_patience=5)


def test_reach_patience_reaches_the_planner():
    # a patience of 1 fires the repair in the first generation without a reach; 0 never does
    grid = load_scenario("h_shape")
    options = {**TINY, "max_gen": 3}
    records = {p: run_trial("plan", "h_shape", "htetro-ga", {**options, "reach_patience": p}, 0) for p in (0, 1)}
    plans = {p: plan_path(grid.workspace, grid.roadmap, method="htetro-ga", seed=0, reach_patience=p, **options)
             for p in (0, 1)}
    for p in (0, 1):
        assert records[p]["reach_patience"] == p and records[p]["commands"] == ",".join(plans[p].tokens)
    assert str(plans[0].legs[0].front) != str(plans[1].legs[0].front)
