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


def test_hypervolume_convergence_ends_legs_sooner_with_the_same_best_time():
    # patience 20 by default with the hypervolume measure, 100 with the best-fitness one
    runs = {measure: plan_ga(OPEN, [START, GOAL], pop_size=16, max_gen=400, max_length=20, seed=3,
                             convergence=measure) for measure in ("best", "hypervolume")}
    best, volume = runs["best"].legs[0], runs["hypervolume"].legs[0]
    assert volume.converged and best.converged
    assert volume.generations < best.generations
    assert volume.selected["time"].time == best.selected["time"].time == 7.0  # the exact optimum
    again = plan_ga(OPEN, [START, GOAL], pop_size=16, max_gen=400, max_length=20, seed=3, convergence="hypervolume",
                    patience=volume.generations)  # a patience of its own overrides the measure's default
    assert again.legs[0].generations > volume.generations
    with pytest.raises(ParameterError, match="convergence"):
        plan_ga(OPEN, [START, GOAL], convergence="volume")


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


# --- seed_exact, pick, the re-planning options ------------------------------------------------
def test_exact_seeding_puts_the_exact_plan_into_the_initial_population():
    from htetro_opt.operators import CommandSampling
    from htetro_opt.problems import CommandPathProblem

    exact = plan_exact(OPEN, [START, GOAL])
    problem = CommandPathProblem(OPEN, START, GOAL, max_length=20)
    X = CommandSampling(include=[exact.commands]).do(problem, 8, random_state=np.random.default_rng(0)).get("X")
    assert len(X) == 8 and X[0, 0].tolist() == exact.commands.tolist()
    plain = CommandSampling().do(problem, 7, random_state=np.random.default_rng(0)).get("X")
    assert [x.tolist() for x in X[1:, 0]] == [x.tolist() for x in plain[:, 0]]  # the rest drawn as before


def test_seed_exact_gives_the_exact_optimum_as_the_best_time():
    from htetro_opt.scenarios import load_scenario

    slits = load_scenario("three_slit")  # the GA alone does not get through a slit in 3 generations
    roadmap = slits.roadmap
    exact = plan_exact(slits.workspace, roadmap)
    plan = plan_ga(slits.workspace, roadmap, pop_size=10, max_gen=3, seed=0, seed_exact=True, replan_window=0,
                   pick="fastest")
    assert plan.info["exact_times"] == [exact.time]
    assert plan.legs[0].selected["time"].time == exact.time == plan.time
    unseeded = plan_ga(slits.workspace, roadmap, pop_size=10, max_gen=3, seed=0, replan_window=0)
    assert not unseeded.reached and "exact_times" not in unseeded.info


@pytest.mark.parametrize("pick, column", [("balanced", None), ("fastest", 1), ("smoothest", 2), ("safest", 3)])
def test_pick_returns_the_member_with_the_largest_fitness(pick, column):
    from htetro_opt.algorithms import PICKS

    plan = plan_ga(OPEN, [START, Pose(8, 8, "O", 0)], pop_size=16, max_gen=40, patience=10, max_length=20, seed=2,
                   pick=pick)
    leg = plan.legs[0]
    front = np.array([member.fitness for member in leg.front])
    score = front.sum(axis=1) if column is None else front[:, column]
    chosen = leg.selected[PICKS[pick]]
    assert plan.commands.tolist() == chosen.commands.tolist() and plan.info["pick"] == pick
    assert (chosen.fitness.sum() if column is None else chosen.fitness[column]) == score.max()


def test_pick_seed_exact_and_replan_errors():
    roadmap = [START, GOAL]
    for options in (dict(pick="best"), dict(pick=None), dict(seed_exact="yes"), dict(replan_window=-1),
                    dict(replan_members=-1), dict(algorithm="nsga2", replan_window=-4),
                    dict(algorithm="smsemoa", reach_share=0.5)):
        with pytest.raises(ParameterError):
            plan_ga(OPEN, roadmap, max_gen=2, **options)


def cli(capsys, argv):
    from htetro_opt.cli import main

    code = main(argv)
    out, err = capsys.readouterr()
    return code, out, err


def test_cli_ga_flags(capsys):
    import json

    code, out, err = cli(capsys, ["plan", "three_slit", "--method", "htetro-ga", "--pop-size", "10", "--max-gen", "3",
                                  "--seed-exact", "--pick", "fastest", "--replan-window", "10",
                                  "--replan-members", "1", "--json", "--quiet"])
    assert code == 0, err
    out = json.loads(out)
    assert out["pick"] == "fastest" and out["gap"] == {"exact": 33.0, "picked": 0.0, "fastest": 0.0}
    code, out, err = cli(capsys, ["plan", "three_slit", "--method", "htetro-ga", "--pop-size", "10", "--max-gen", "3",
                                  "--seed-exact", "--quiet"])
    assert code == 0 and "gap to the exact optimum (33 s): balanced" in out
    runs = {}
    for measure in ("best", "hypervolume"):
        code, out, err = cli(capsys, ["plan", "random", "--method", "htetro-ga", "--pop-size", "16", "--max-gen",
                                      "300", "--patience", "4", "--converge", measure, "--json", "--quiet"])
        assert code == 0, err
        runs[measure] = json.loads(out)["legs"][0]
    assert runs["hypervolume"]["converged"] and runs["best"]["converged"]
    assert runs["hypervolume"]["generations"] != runs["best"]["generations"]  # the flag reaches the termination


@pytest.mark.parametrize("argv, flag", [
    (["--method", "htetro-ga", "--replan-window", "-1"], "--replan-window"),
    (["--method", "htetro-ga", "--replan-members", "-1"], "--replan-members"),
    (["--method", "htetro-ga", "--replan-window", "x"], "--replan-window"),
    (["--method", "htetro-ga", "--pick", "best"], "--pick"),
    (["--method", "nsga2", "--replan-window", "-5"], "--replan-window"),
    (["--method", "dijkstra", "--seed-exact"], "--seed-exact"),
    (["--method", "astar", "--pick", "fastest"], "--pick"),
    (["--method", "heat", "--replan-window", "5"], "--replan-window"),
    (["--method", "htetro-ga", "--converge", "volume"], "--converge"),
    (["--method", "dijkstra", "--converge", "hypervolume"], "--converge"),
    (["--method", "htetro-ga", "--conservative"], "--conservative"),
    (["--method", "htetro-ga-paper", "--conservative"], "--conservative"),
    (["--method", "dijkstra", "--conservative"], "--conservative"),
    (["--method", "nsga2", "--reach-patience", "5"], "--reach-patience"),
])
def test_cli_bad_ga_flags_exit_2(capsys, argv, flag):
    code, out, err = cli(capsys, ["plan", "three_slit", *argv, "--quiet"])
    assert code == 2 and out == "" and err.startswith("error: ") and len(err.splitlines()) == 1
    assert flag in err


def test_cli_conservative_reaches_pymoos_algorithms(capsys, monkeypatch):
    import json

    from htetro_opt.algorithms import ConservativeMating
    from htetro_opt.solvers.grid_paths import _ga

    made, make = [], _ga.make_algorithm

    def spy(*args, **kwargs):  # records the algorithms plan_ga builds
        made.append(make(*args, **kwargs))
        return made[-1]

    monkeypatch.setattr(_ga, "make_algorithm", spy)
    for flags, expected in (([], False), (["--conservative"], True)):
        made.clear()
        code, out, err = cli(capsys, ["plan", "three_slit", "--method", "nsga2", "--pop-size", "8", "--max-gen", "2",
                                      *flags, "--json", "--quiet"])
        assert code == 0, err
        assert json.loads(out)["method"] == "nsga2"
        assert made and all(isinstance(a.mating, ConservativeMating) is expected for a in made)
