"""plan_ga: the leg-by-leg GA planner gives reproducible, re-validated plans and reports failures."""

import numpy as np
import pytest

from htetro_opt.algorithms import SELECTIONS
from htetro_opt.errors import ParameterError, PlanningError
from htetro_opt.model import Pose, Simulator, Workspace
from htetro_opt.solvers.grid_paths import LegResult, Plan, plan_exact, plan_ga


def bordered(width=12, height=12):
    occ = np.zeros((height, width), dtype=bool)
    occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = True
    return occ


OPEN = Workspace(bordered())
START, GOAL = Pose(3, 3, "O", 0), Pose(7, 6, "O", 0)


def pocket():
    """The bordered map with a closed 2 × 2 pocket holding the goal (7, 8)."""
    occ = bordered()
    occ[6:10, 6:10] = True
    occ[7:9, 7:9] = False
    return Workspace(occ)


def test_plan_ga_revalidates_and_is_reproducible():
    roadmap = [START, GOAL]
    plan = plan_ga(OPEN, roadmap, pop_size=16, max_gen=60, patience=10, max_length=20, seed=3)
    assert isinstance(plan, Plan) and plan.reached and plan.failed_leg == -1
    assert plan.method == "htetro-ga"
    assert len(plan.legs) == 1 and isinstance(plan.legs[0], LegResult)
    check = Simulator(OPEN).run([plan.commands], START, roadmap=[GOAL])
    assert check.valid[0] and check.reached[0]
    assert check.time[0] == plan.time
    assert np.array_equal(check.poses(0), plan.poses)
    assert plan.time >= plan_exact(OPEN, roadmap).time
    assert plan.leg_ends == (len(plan.commands),)
    again = plan_ga(OPEN, roadmap, pop_size=16, max_gen=60, patience=10, max_length=20, seed=3)
    assert again.commands.tolist() == plan.commands.tolist()


def test_plan_ga_multi_leg_roadmap():
    roadmap = [Pose(3, 3, "O", 0), Pose(7, 4, "O", 0), Pose(7, 8, "I", 0)]
    plan = plan_ga(OPEN, roadmap, pop_size=16, max_gen=60, patience=10, max_length=20, seed=5)
    assert plan.reached and plan.failed_leg == -1
    assert len(plan.legs) == 2 and len(plan.leg_ends) == 2
    assert plan.leg_ends[-1] == len(plan.commands)
    sim = Simulator(OPEN)
    check = sim.run([plan.commands], roadmap[0], roadmap=roadmap[1:])
    assert check.valid[0] and check.reached[0] and check.time[0] == plan.time
    begin, total = 0, 0.0
    for k, (leg, end) in enumerate(zip(plan.legs, plan.leg_ends)):
        assert leg.start == roadmap[k] and leg.goal == roadmap[k + 1]
        assert leg.t0 == begin  # each leg starts where (and when) the previous one ended
        assert leg.reached and 1 <= leg.reach_generation <= leg.generations
        chosen = leg.selected["multi_objective"]
        assert chosen.commands.tolist() == plan.commands[begin:end].tolist()
        assert chosen.reached and chosen.fitness[0] == 1.0
        assert tuple(chosen.poses[0]) == tuple(plan.poses[begin]) and tuple(chosen.poses[-1]) == tuple(plan.poses[end])
        part = sim.run([plan.commands[:end]], roadmap[0])
        assert part.final_pose(0) == roadmap[k + 1]
        assert set(leg.selected) == set(SELECTIONS)
        assert any(m is chosen or m.commands.tolist() == chosen.commands.tolist() for m in leg.front)
        total += chosen.time
        begin = end
    assert total == pytest.approx(plan.time)
    assert plan.reach_generation == max(leg.reach_generation for leg in plan.legs)


def test_plan_ga_unreachable_goal_is_reported_not_raised():
    plan = plan_ga(pocket(), [Pose(3, 3, "O", 0), Pose(7, 8, "O", 0)], pop_size=10, max_gen=4, max_length=15, seed=0)
    assert plan.reached is False and plan.failed_leg == 0
    assert len(plan.commands) == 0 and plan.leg_ends == () and plan.time == 0.0
    assert len(plan.legs) == 1
    leg = plan.legs[0]
    assert not leg.reached and leg.reach_generation is None and not leg.converged
    assert plan.reach_generation is None
    assert len(leg.history) == 4  # one row per generation: the cap was honoured
    assert leg.generations == len(leg.history) == 4


def test_plan_ga_reports_convergence_per_leg():
    plan = plan_ga(OPEN, [START, GOAL], pop_size=16, max_gen=300, patience=5, max_length=20, seed=3)
    leg = plan.legs[0]
    assert leg.converged is True and leg.generations < 300  # stopped by patience, not by the cap


def test_plan_ga_errors():
    roadmap = [START, GOAL]
    with pytest.raises(ParameterError):
        plan_ga(OPEN, roadmap, algorithm="simulated-annealing")
    with pytest.raises(ParameterError):
        plan_ga(OPEN, roadmap, algorithm="htetro")  # the old name
    with pytest.raises(ParameterError):
        plan_ga(OPEN, roadmap, pop_size=1)
    with pytest.raises(ParameterError):
        plan_ga(OPEN, roadmap, seed=-1)
    with pytest.raises(ParameterError):
        plan_ga(OPEN, roadmap, verbose="yes")
    with pytest.raises(PlanningError):
        plan_ga(OPEN, [START])


def test_plan_ga_with_pymoo_algorithm():
    plan = plan_ga(OPEN, [START, GOAL], algorithm="nsga2", pop_size=12, max_gen=25, patience=5, max_length=20, seed=0)
    assert plan.method == "nsga2"
    check = Simulator(OPEN).run([plan.commands], START, roadmap=[GOAL])
    assert check.valid[0] and bool(check.reached[0]) == plan.reached
