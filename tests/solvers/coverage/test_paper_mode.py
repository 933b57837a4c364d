"""Cheng et al. 2019's Alg. 5 as published (``stripes-paper``) and our additions to it (``STRIPES_ADDITIONS``).

Oracles: spies on our mop-up and greedy walk (never called in the paper's mode), the simulator's replay of
every plan, and the covered cells recomputed here from the replayed poses' footprints, independently of the
planner's bookkeeping.
"""

import json

import numpy as np
import pytest

from htetro_opt.cli import main
from htetro_opt.errors import ParameterError
from htetro_opt.model import FOOTPRINTS, SEED004_COMMANDS, Simulator, Workspace
from htetro_opt.scenarios import load_scenario
from htetro_opt.solvers import plan_coverage
from htetro_opt.solvers.coverage import SPEC, STRIPES_ADDITIONS
from htetro_opt.solvers.coverage import _dispatch, _rbt, _stripes

# a pocket above a lane: small enough that the paper's search ends well within its budget
POCKET = Workspace(np.array([[c == "#" for c in row] for row in ("##..####", "##..####", "........",
                                                                  "........")][::-1]))


def covered_by_replay(ws, plan):
    """The cells under the robot's blocks at every pose of the simulator's own replay of the commands."""
    run = Simulator(ws, commands=SEED004_COMMANDS).run([plan.commands], plan.start)
    assert run.valid[0] and run.time[0] == plan.time
    poses = run.poses(0)
    assert (poses == plan.poses).all()
    covered = np.zeros(ws.occupancy.shape, dtype=bool)
    for x, y, state, heading in poses.tolist():
        for dx, dy in FOOTPRINTS[state, heading].tolist():
            covered[y + dy, x + dx] = True
    return covered


def check(ws, plan):
    """The plan re-validates, and what it says it covered and missed is what its replay covers."""
    covered = covered_by_replay(ws, plan)
    assert (covered == plan.covered).all()
    missed = {(int(x), int(y)) for y, x in np.argwhere(plan.coverable & ~covered)}
    assert set(plan.missed) == missed
    assert plan.success == (not missed and not plan.failed_regions)
    record = plan.as_dict()
    assert {(c["x"], c["y"]) for c in record["missed"]} == missed
    assert record["failed_regions"] == [dict(r) for r in plan.failed_regions]
    assert record["success"] is plan.success and record["additions"] == list(plan.additions)


@pytest.fixture
def spies(monkeypatch):
    """Make our mop-up and greedy walk fail loudly wherever they are called from."""
    def never(name):
        def call(*args, **kwargs):
            raise AssertionError(f"{name} was called")
        return call

    for module in (_dispatch, _stripes):
        monkeypatch.setattr(module, "mop_up", never("mop_up"))
    for module in (_stripes, _rbt):
        monkeypatch.setattr(module, "greedy_walk", never("greedy_walk"))
    monkeypatch.setattr(_rbt, "search_region", never("search_region (best-first)"))


@pytest.mark.parametrize("scenario, layers, stripes, budget", [
    ("coverage_16x7", "O,hI", [2, 3, 2], 20_000),  # Figs. 8b-11: budgets run out, the result says so
    ("coverage_16x16", "vI", 3, 20_000),  # N_str,1 with the I: two cells left, as the paper's Table 2 says
    ("coverage_16x16", "vI", 4, 20_000),
    ("coverage_16x16", "O", 4, 20_000),
])
def test_the_paper_mode_calls_no_mop_up_and_no_greedy_walk(spies, scenario, layers, stripes, budget):
    sc = load_scenario(scenario)
    ends = {"start": sc.start, "goal": sc.goal} if sc.roadmap else {}
    plan = plan_coverage(sc.workspace, layers, method="stripes-paper", stripes=stripes, budget=budget, **ends)
    assert plan.additions == () and plan.as_dict()["additions"] == []
    assert plan.mopup_commands == 0
    check(sc.workspace, plan)


def test_the_paper_mode_reports_what_it_leaves_and_which_searches_ran_out(spies):
    sc = load_scenario("coverage_16x16")
    plan = plan_coverage(sc.workspace, "vI", method="stripes-paper", stripes=3)
    # 3-row stripes are too narrow for the vertical I's sweep: Table 2 says N_str,1 with an I is not complete
    assert not plan.success and plan.missed and "left uncovered" in plan.message
    tight = plan_coverage(sc.workspace, "O", method="stripes-paper", stripes=4, budget=2_000)
    assert tight.failed_regions and not tight.success and "spent their budget" in tight.message
    for region in tight.failed_regions:
        assert region["reason"] == "node budget" and region["nodes"] > 2_000
        c0, c1 = region["columns"]
        assert 0 <= c0 < c1 <= sc.workspace.width and region["entry"]["shape"] == "O"


def test_the_paper_mode_succeeds_where_its_search_ends(spies):
    plan = plan_coverage(POCKET, "O", method="stripes-paper")
    assert plan.success and plan.complete and not plan.failed_regions and plan.regions == plan.regions_optimal
    check(POCKET, plan)


def test_a_time_limit_fails_the_paper_modes_regions_instead_of_a_greedy_walk(spies):
    ws = load_scenario("coverage_16x16").workspace
    plan = plan_coverage(ws, "O,vI,hI", method="stripes-paper", time_limit=1e-6)
    assert plan.time_limited and not plan.success and plan.failed_regions
    assert {r["reason"] for r in plan.failed_regions} == {"time limit"}
    check(ws, plan)



def test_past_the_time_limit_the_paper_mode_builds_no_region_problem(spies, monkeypatch):
    # a region past the limit fails as it is: its problem (window, distances) is not built first
    monkeypatch.setattr(_stripes._Planner, "_build", lambda *a, **k: pytest.fail("a region problem was built"))
    ws = load_scenario("coverage_16x16").workspace
    plan = plan_coverage(ws, "O,vI,hI", method="stripes-paper", time_limit=1e-6)
    assert plan.time_limited and plan.failed_regions and plan.info["time_limit_cut"]["failed_regions"] > 0
    check(ws, plan)


def _cut_at_once(self):
    """_Planner._past_cutoff past its cutoff from the start, the deadline itself far away (no clock read)."""
    self.time_limited = True
    return True


def test_past_the_time_limit_ours_walks_one_chain_greedily_and_says_what_was_cut(monkeypatch):
    # past the cutoff (the deadline not yet passed): no search and no full problem, light problems, one
    # greedy walk per region of one chain; the plan still covers every coverable cell (the mop-up) and re-validates
    built = []
    build = _stripes._Planner._build
    monkeypatch.setattr(_stripes._Planner, "_build", lambda self, *a: built.append(a[-1]) or build(self, *a))
    monkeypatch.setattr(_stripes, "search_region", lambda *a, **k: pytest.fail("a region was searched"))
    monkeypatch.setattr(_stripes._Planner, "_past_cutoff", _cut_at_once)
    ws = load_scenario("coverage_16x16").workspace
    plan = plan_coverage(ws, "O,vI,hI", time_limit=10**6)
    cut = plan.info["time_limit_cut"]
    assert plan.time_limited and plan.success and built and all(built) and plan.regions_optimal == 0
    assert cut["greedy_regions"] > 0 and cut["unpriced_edges"] > 0 and cut["candidates_skipped"]
    assert cut["dag_stopped"] is None and "mopup_stopped" not in cut and cut["cells_left"] == 0
    check(ws, plan)


def test_past_the_deadline_ours_stops_the_dag_and_the_mopup_and_says_so():
    # a deadline already passed: the DAG's search stops after its first few nodes, its path ends at the
    # furthest node it settled, and the mop-up covers nothing more; the plan re-validates (check) and what
    # it leaves uncovered is what time_limit_cut says
    ws = load_scenario("coverage_16x16").workspace
    plan = plan_coverage(ws, "O,vI,hI", time_limit=1e-9)
    cut = plan.info["time_limit_cut"]
    stopped = cut["dag_stopped"]
    assert plan.time_limited and stopped["sweeps"] == plan.info["sweeps"] and stopped["sweeps_entered"] <= stopped["sweeps"]
    left = int((plan.coverable & ~plan.covered).sum())
    assert left > 0 and cut["cells_left"] == left and cut["mopup_stopped"] and not plan.success
    check(ws, plan)

def test_ours_lists_every_addition_and_the_paper_none():
    assert SPEC.default_of("stripes", "additions") == tuple(STRIPES_ADDITIONS)
    assert SPEC.default_of("stripes-paper", "additions") == ()
    assert SPEC.method("stripes-paper").origin == "paper" and SPEC.method("stripes").origin == "ours"
    plan = plan_coverage(POCKET, "O")
    assert plan.additions == tuple(STRIPES_ADDITIONS)


def run_json(capsys, argv):
    assert main(argv) == 0
    return json.loads(capsys.readouterr().out)


def test_cover_json_lists_the_additions(capsys):
    paper = run_json(capsys, ["cover", "coverage_16x7", "--method", "stripes-paper", "--json"])
    ours = run_json(capsys, ["cover", "coverage_16x7", "--method", "stripes", "--json"])
    assert paper["additions"] == [] and ours["additions"] == list(STRIPES_ADDITIONS)
    assert paper["mopup_commands"] == 0 and {"missed", "failed_regions"} <= set(paper)
    assert paper["success"] == (not paper["missed"] and not paper["failed_regions"])
    some = run_json(capsys, ["cover", "coverage_16x7", "--method", "stripes-paper", "--additions",
                             "greedy-fallback,mopup", "--json"])
    assert some["additions"] == ["greedy-fallback", "mopup"] and some["success"] and not some["missed"]


@pytest.mark.parametrize("addition", list(STRIPES_ADDITIONS))
def test_each_addition_alone_runs_and_revalidates(addition, monkeypatch):
    ws = load_scenario("coverage_16x16").workspace
    if addition != "mopup":
        monkeypatch.setattr(_dispatch, "mop_up", lambda *a, **k: (_ for _ in ()).throw(AssertionError("mop-up")))
    if addition != "greedy-fallback":
        for module in (_stripes, _rbt):
            monkeypatch.setattr(module, "greedy_walk",
                                lambda *a, **k: (_ for _ in ()).throw(AssertionError("greedy walk")))
    plan = plan_coverage(ws, "O,vI", method="stripes-paper", stripes=4, budget=3_000, additions=[addition])
    assert plan.additions == (addition,)
    check(ws, plan)


def test_an_addition_alone_does_what_it_says():
    sc = load_scenario("coverage_16x16")
    # with greedy-fallback no region fails; with the mop-up no coverable cell is left
    fallback = plan_coverage(sc.workspace, "O", method="stripes-paper", stripes=4, additions="greedy-fallback")
    assert not fallback.failed_regions and fallback.complete
    mopped = plan_coverage(sc.workspace, "O", method="stripes-paper", stripes=4, additions="mopup")
    assert not mopped.missed and mopped.mopup_commands > 0 and mopped.failed_regions  # the searches still ran out


def test_an_option_of_an_addition_that_is_off_is_refused():
    with pytest.raises(ParameterError, match="mopup addition"):
        plan_coverage(POCKET, "O", method="stripes-paper", mopup="nearest")
    with pytest.raises(ParameterError, match="fixed-regions addition"):
        plan_coverage(POCKET, "O", method="stripes", additions=["mopup"], region_columns=3)
    with pytest.raises(ParameterError, match="unknown addition"):
        plan_coverage(POCKET, "O", method="stripes", additions=["taut"])
    with pytest.raises(ParameterError, match="ends"):
        plan_coverage(POCKET, "O", method="stripes-paper", ends="both")
    # the parameter of an addition that is on is taken
    assert plan_coverage(POCKET, "O", method="stripes-paper", additions="mopup", mopup="nearest").success


def test_memo_is_no_addition_it_gives_the_same_plan():
    ws = load_scenario("coverage_16x16").workspace
    a = plan_coverage(ws, "vI", method="stripes-paper", stripes=4)
    b = plan_coverage(ws, "vI", method="stripes-paper", stripes=4, memo=False)
    assert a.tokens == b.tokens and a.failed_regions == b.failed_regions and a.additions == b.additions == ()
