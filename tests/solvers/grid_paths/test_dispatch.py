"""plan_path: one entry point for every method, one result type, every plan re-validated."""

import numpy as np
import pytest

from htetro_opt.errors import ParameterError, PlanningError, UnknownCommandError
from htetro_opt.model import Pose, Simulator, Workspace, parse_commands
from htetro_opt.solvers.grid_paths import EXACT_METHODS, SPEC, Plan, plan_path

OPEN = Workspace(np.zeros((8, 8), dtype=bool))
START, MID, GOAL = Pose(1, 1, "O", 0), Pose(3, 1, "O", 0), Pose(3, 3, "O", 0)


def test_method_names():
    assert set(EXACT_METHODS) < set(SPEC.methods)
    assert tuple(SPEC.methods)[2:] == ("htetro-ga", "htetro-ga-paper", "nsga2", "nsga3", "smsemoa", "agemoea", "heat",
                                     "heat-paper")


@pytest.mark.parametrize("method", EXACT_METHODS)
def test_exact_methods(method):
    plan = plan_path(OPEN, [START, MID, GOAL], method=method)
    assert isinstance(plan, Plan) and plan.method == method
    assert plan.reached and plan.time == 4.0 and plan.leg_ends == (2, 4)
    assert plan.legs == ()  # the graph searches keep no GA records
    assert plan.objectives() == {"time": 4.0, "n_commands": 4, "translations": 4, "rotations": 0, "shapeshifts": 0,
                                 "path_length": 4.0}


def test_a_ga_method_with_tiny_settings():
    plan = plan_path(OPEN, [START, GOAL], method="htetro-ga", pop_size=10, max_gen=30, max_length=8, seed=1)
    assert plan.method == "htetro-ga" and len(plan.legs) == 1
    assert plan.reached and plan.time >= 4.0  # the optimum is 4
    assert Simulator(OPEN).run([plan.commands], START, roadmap=[GOAL]).reached[0]
    again = plan_path(OPEN, [START, GOAL], method="htetro-ga", pop_size=10, max_gen=30, max_length=8, seed=1)
    assert again.tokens == plan.tokens


def test_a_callable_returning_tokens_or_ids():
    seen = {}

    def planner(sim, roadmap, *, detour=False):
        seen.update(sim=sim, roadmap=roadmap)
        return ["x+", "x+"] + (["y+", "y-"] if detour else []) + ["y+", "y+"]

    plan = plan_path(OPEN, [START, MID, GOAL], method=planner, clearance=0.0, detour=True)
    assert isinstance(seen["sim"], Simulator) and seen["roadmap"] == [START, MID, GOAL]
    assert plan.method == "planner" and plan.reached and plan.failed_leg == -1
    assert plan.tokens == ["x+", "x+", "y+", "y-", "y+", "y+"] and plan.leg_ends == (2, 6)
    assert plan.time == 6.0 and plan.poses[-1].tolist() == [3, 3, 1, 0]
    assert plan.info == {}
    by_ids = plan_path(OPEN, [START, GOAL], method=lambda sim, roadmap: parse_commands("y+,y+,x+,x+"))
    assert by_ids.reached and by_ids.tokens == ["y+", "y+", "x+", "x+"]
    as_text = plan_path(OPEN, [START, GOAL], method=lambda sim, roadmap: "y+, y+, x+, x+")
    assert as_text.tokens == by_ids.tokens


@pytest.mark.parametrize("answer, failed_leg, leg_ends, first_invalid", [
    ("y-,x+,x+,y+,y+", 0, (), 0),  # the first command leaves the map: nothing solved
    ("x+,x+,y+,x+,x+,x+,x+,x+,y+", 1, (2,), 6),  # leg 1 solved, then into the map's edge
    ("x+,x+,y+", 1, (2,), -1),  # stops short of the goal
    ("x+,x+,y+,y+,x+", 1, (2,), -1),  # passes the goal and ends elsewhere
    ("y+,y+,x+,x+", 0, (), -1),  # ends on the goal but skips the roadmap's middle configuration
])
def test_a_callable_answer_that_fails_is_a_plan_not_a_crash(answer, failed_leg, leg_ends, first_invalid):
    plan = plan_path(OPEN, [START, MID, GOAL], method=lambda sim, roadmap: answer)
    assert not plan.reached and plan.failed_leg == failed_leg and plan.leg_ends == leg_ends
    assert len(plan.commands) == (leg_ends[-1] if leg_ends else 0)  # the solved legs only
    assert plan.info == {"returned": len(answer.split(",")), "first_invalid": first_invalid}
    assert Simulator(OPEN).run([plan.commands], START).valid[0]


def test_a_callable_answer_that_is_not_commands():
    with pytest.raises(PlanningError, match="returned"):
        plan_path(OPEN, [START, GOAL], method=lambda sim, roadmap: None)
    with pytest.raises(UnknownCommandError):
        plan_path(OPEN, [START, GOAL], method=lambda sim, roadmap: ["x+", "jump"])
    with pytest.raises(UnknownCommandError):  # a diagonal outside the simulator's command set
        plan_path(OPEN, [START, GOAL], method=lambda sim, roadmap: ["x+y+", "x+y+"])
    diagonal = plan_path(OPEN, [START, GOAL], method=lambda sim, roadmap: ["x+y+", "x+y+"], diagonals=True)
    assert diagonal.reached


def test_unknown_methods_and_options():
    with pytest.raises(ParameterError, match="'bfs'"):
        plan_path(OPEN, [START, GOAL], method="bfs")
    with pytest.raises(ParameterError, match="'htetro'"):
        plan_path(OPEN, [START, GOAL], method="htetro")  # the old GA name
    with pytest.raises(ParameterError, match="pop_size"):
        plan_path(OPEN, [START, GOAL], method="dijkstra", pop_size=10)  # a GA option given to a graph search
    with pytest.raises(ParameterError, match="t0"):
        plan_path(OPEN, [START, GOAL], method="nsga2", t0=3)


def test_a_method_whose_plan_does_not_revalidate_is_an_internal_error(monkeypatch):
    from htetro_opt.solvers.grid_paths import _exact  # its leg search is replaced by a broken one

    x_minus = int(parse_commands("x-")[0])
    # the static map's graph-free search, replayed through the simulator's sweep check (given a map) or
    # run in the simulator (given one)
    monkeypatch.setattr(_exact, "search_leg", lambda space, a, b, astar: ([space.command_ids.tolist().index(x_minus)] * 3, 0))
    with pytest.raises(PlanningError, match="internal error.*dijkstra.*command 2 of 3"):
        plan_path(OPEN, [START, GOAL], method="dijkstra")
    with pytest.raises(PlanningError, match="internal error.*astar.*command 2 of 3"):
        plan_path(OPEN, [START, GOAL])  # the default
    with pytest.raises(PlanningError, match="internal error.*astar.*command 2 of 3"):
        plan_path(Simulator(OPEN), [START, GOAL], method="astar")
