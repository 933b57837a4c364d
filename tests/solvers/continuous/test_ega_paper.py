"""``ega-paper`` is Nazarahari et al. 2019's EGA and nothing of ours (issue 24): spies prove that it never
calls the duplicate filter, the taut refinement, the repeated deletion passes, the straight start-goal
segment, the finer APF or a refined APF lattice, that its deletion assesses each PB once, left to right, on one roulette pick a
generation; each of our additions switched on alone runs (and only it); the plans list what ran."""

import json

import numpy as np
import pytest

import htetro_opt.model._apf as apf
import htetro_opt.operators.path_bases.deletion as deletion
from htetro_opt.algorithms import EGA_ADDITIONS, EnhancedGA
from htetro_opt.cli import main
from htetro_opt.errors import ParameterError
from htetro_opt.model.continuous import ContinuousGeometry
from htetro_opt.operators.path_bases import (PathBasesDeletion, PathBasesDuplicateElimination, TautRefinement,
                                             delete_path_bases)
from htetro_opt.scenarios import load_scenario
from htetro_opt.scenarios.loader import parse_scenario
from htetro_opt.solvers.continuous import plan_continuous

MAP, GENERATIONS = "ega08_slits2", 4


class Spy:
    """Records the calls of a function (their keywords, and the size of a repair's population), then calls it."""

    def __init__(self, monkeypatch, owner, name, *, method=False):
        self.calls, function = [], owner.__dict__[name] if method else getattr(owner, name)
        function = getattr(function, "__func__", function)  # a staticmethod's function

        def spy(*args, **kwargs):
            self.calls.append({**kwargs, "_args": args})
            return function(*args, **kwargs)

        static = method and isinstance(owner.__dict__[name], staticmethod)
        monkeypatch.setattr(owner, name, staticmethod(spy) if static else spy)


@pytest.fixture
def spies(monkeypatch):
    """Spies on every place one of our additions acts."""
    return {
        "delete": Spy(monkeypatch, deletion, "delete_path_bases"),  # delete_chromosome's call, per robot
        "one_pass": Spy(monkeypatch, deletion, "_one_pass"),
        "passes": Spy(monkeypatch, deletion, "_delete_polyline"),
        "repair": Spy(monkeypatch, PathBasesDeletion, "_do", method=True),  # (self, problem, X): X the individuals
        "apf": Spy(monkeypatch, apf, "apf_population"),
        "dedup": Spy(monkeypatch, EnhancedGA, "_new", method=True),
        "eliminate": Spy(monkeypatch, PathBasesDuplicateElimination, "_do", method=True),
        "taut": Spy(monkeypatch, TautRefinement, "_do", method=True),
    }


def _deleted(spies):
    """How many individuals each call of the deletion repair held."""
    return [len(c["_args"][2]) for c in spies["repair"].calls]


def _plan(method, **options):
    return plan_continuous(load_scenario(MAP), method=method, max_gen=GENERATIONS, seed=3, **options)


def test_ega_paper_runs_none_of_our_additions(spies):
    plan = _plan("ega-paper")
    assert plan.reached and plan.additions == ()
    assert spies["dedup"].calls == [] and spies["eliminate"].calls == []  # every child kept, copies included
    assert spies["taut"].calls == []
    assert spies["passes"].calls == []  # never the repeated passes
    # the deletion: one roulette pick a generation (one robot), each a single pass without the straight segment
    assert _deleted(spies) == [1] * GENERATIONS and len(spies["delete"].calls) == GENERATIONS
    assert all(c["passes"] is False and c["straight"] is False for c in spies["delete"].calls)
    assert len(spies["one_pass"].calls) == GENERATIONS
    assert {c["grid"] for c in spies["apf"].calls} == {1.0}  # the APF at step d only
    assert {c["refinements"] for c in spies["apf"].calls} == {0}  # and never a finer lattice to rescue it


@pytest.mark.parametrize("path", ["linear", "spline"])
def test_ega_paper_plans_both_of_the_papers_path_types(spies, path):
    plan = _plan("ega-paper", path=path)
    geometry = load_scenario(MAP).geometry
    assert plan.reached and plan.info["path"] == path and plan.additions == ()
    assert geometry.path_feasible(plan.paths[0]) == plan.feasible[0]
    if path == "spline":  # a spline's cost is judged whole: the deletion's judge, still one pass, no straight segment
        assert len(plan.paths[0]) > len(plan.info["path_bases"][0]) + 2
        assert spies["one_pass"].calls == [] and spies["delete"].calls
    assert all(c["passes"] is False and c["straight"] is False for c in spies["delete"].calls)
    assert spies["dedup"].calls == [] and spies["taut"].calls == []


def test_ours_runs_every_addition(spies):
    plan = _plan("ega")
    assert plan.additions == tuple(EGA_ADDITIONS)
    assert spies["dedup"].calls and spies["taut"].calls and spies["passes"].calls
    assert all(c["passes"] and c["straight"] for c in spies["delete"].calls)
    assert max(_deleted(spies)) > 1  # every child and the initial paths
    assert {c["grid"] for c in spies["apf"].calls} == {1.0, 0.5}


ACTS = {  # addition -> whether its spies saw it act
    "delete-every-child": lambda s: max(_deleted(s)) > 1,
    "deletion-passes": lambda s: bool(s["passes"].calls) and all(c["passes"] for c in s["delete"].calls),
    "straight-first": lambda s: all(c["straight"] for c in s["delete"].calls),
    "child-dedup": lambda s: bool(s["dedup"].calls),
    "taut-refinement": lambda s: bool(s["taut"].calls),
    "finer-apf": lambda s: 0.5 in {c["grid"] for c in s["apf"].calls},
    "apf-refinement": lambda s: {c["refinements"] for c in s["apf"].calls} == {3},
}


@pytest.mark.parametrize("addition", list(EGA_ADDITIONS))
def test_each_addition_alone_runs_and_only_it(spies, addition):
    assert set(ACTS) == set(EGA_ADDITIONS)
    plan = _plan("ega-paper", additions=[addition])
    assert plan.reached and plan.additions == (addition,) and plan.as_dict()["additions"] == [addition]
    assert {name for name, acts in ACTS.items() if acts(spies)} == {addition}


def test_where_the_papers_apf_finds_no_path_the_plan_says_so_unless_refined():
    # a corridor 0.6 wide between y = 1.2 and 1.8: no node of the d = 1 lattice is free
    narrow = parse_scenario({"name": "narrow_gap", "width": 10, "height": 4, "robot_radius": 0.0,
                             "obstacles": [[0, 0, 10, 1.2], [0, 1.8, 10, 4]],
                             "robots": [{"start": [1, 1.5], "goal": [9, 1.5]}]})
    paper = plan_continuous(narrow, method="ega-paper", max_gen=2)
    assert not paper.success and not paper.reached and "did not reach" in paper.message
    assert paper.as_dict()["additions"] == []
    for method, options in (("ega-paper", {"additions": ["apf-refinement"]}), ("ega", {})):
        plan = plan_continuous(narrow, method=method, max_gen=2, **options)
        assert plan.success and narrow.geometry.path_feasible(plan.paths[0])
        assert plan.length >= plan_continuous(narrow).length - 1e-9  # never below the exact optimum


def test_an_unknown_addition_is_refused_by_name():
    with pytest.raises(ParameterError, match="unknown addition 'speedup'"):
        _plan("ega", additions=["speedup"])
    with pytest.raises(ParameterError, match="additions"):
        _plan("ega-paper", additions="taut-refinement;finer-apf")


# --- the deletion itself -----------------------------------------------------------------------------------
GEO = ContinuousGeometry(10, 10, [[4, 0, 6, 8]])
START, GOAL = np.array([1.0, 1.0]), np.array([9.0, 1.0])


def _judge(calls):
    def judge(pbs):
        calls.append(len(pbs))
        points = np.vstack([START, pbs, GOAL])
        return int((~GEO.path_segments_feasible(points)).sum()), float(np.hypot(*np.diff(points, axis=0).T).sum())
    return judge


def test_the_papers_deletion_assesses_each_pb_once_in_order():
    zigzag = np.array([[2.0, 7.0], [7.0, 10.0], [2.0, 10.0], [8.0, 9.0]])
    calls = []
    once = delete_path_bases(zigzag, START, GOAL, judge=_judge(calls), passes=False, straight=False)
    assert len(calls) == 1 + len(zigzag)  # the path itself, then each PB once
    assert once.tolist() == [[2.0, 7.0], [2.0, 10.0], [8.0, 9.0]]
    # a second pass would drop another PB: the paper's single pass is not idempotent, ours is
    again = delete_path_bases(once, START, GOAL, GEO, passes=False, straight=False)
    assert len(again) < len(once)
    ours = delete_path_bases(zigzag, START, GOAL, GEO)
    assert delete_path_bases(ours, START, GOAL, GEO).tolist() == ours.tolist() and len(ours) <= len(again)


def test_the_single_pass_on_the_polyline_equals_the_single_pass_judged_whole():
    rng = np.random.default_rng(0)
    checked = 0
    for _ in range(300):
        pbs = rng.uniform(0, 10, (int(rng.integers(1, 8)), 2))
        fast = delete_path_bases(pbs, START, GOAL, GEO, passes=False, straight=False)
        judged = delete_path_bases(pbs, START, GOAL, judge=_judge([]), passes=False, straight=False)
        assert fast.tolist() == judged.tolist()
        checked += not GEO.path_feasible(np.vstack([START, pbs, GOAL]))
    assert checked > 50  # infeasible paths (the "fewer infeasible segments" rule) were among them


def test_the_straight_segment_is_tried_only_with_its_addition():
    pbs = np.array([[1.0, 9.0], [9.0, 9.0]])  # a detour over an open map
    open_map = ContinuousGeometry(10, 10, [])
    assert len(delete_path_bases(pbs, START, GOAL, open_map)) == 0
    for straight, first in ((False, 1), (True, 0)):
        calls = []
        delete_path_bases(pbs, START, GOAL, judge=_judge(calls), passes=False, straight=straight)
        assert calls[:2] == [2, first]  # after the path itself: one PB fewer, or the straight segment


# --- the command line ------------------------------------------------------------------------------------
def test_the_json_lists_the_additions(capsys):
    for method, expected in (("ega-paper", []), ("ega", list(EGA_ADDITIONS))):
        assert main(["plan", "ega07_slits1", "--method", method, "--json"]) == 0
        assert json.loads(capsys.readouterr().out)["additions"] == expected
    assert main(["plan", "ega07_slits1", "--method", "ega-paper", "--additions", "finer-apf,child-dedup", "--json",
                 "--max-gen", "2"]) == 0
    assert json.loads(capsys.readouterr().out)["additions"] == ["child-dedup", "finer-apf"]
