"""The hTetro-GA, its termination and the leg-by-leg planner: reproducible, optimal on easy maps, consistent plans."""

from types import SimpleNamespace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from pymoo.core.population import Population
from pymoo.optimize import minimize

from htetro_opt.errors import ParameterError, PlanningError
from htetro_opt.model import Pose, Simulator, Workspace, format_commands, parse_commands
from htetro_opt.operators import as_column, sequences
from htetro_opt.problems import CommandPathProblem
from htetro_opt.solvers import (
    GA_ALGORITHMS,
    SELECTIONS,
    FrontConvergence,
    GAPlan,
    HTetroGA,
    leading_front,
    make_algorithm,
    plan_exact,
    plan_ga,
    select_solutions,
    trim_reached,
)


def bordered(width=12, height=12):
    occ = np.zeros((height, width), dtype=bool)
    occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = True
    return occ


OPEN = Workspace(bordered())
START, GOAL = Pose(3, 3, "O", 0), Pose(7, 6, "O", 0)


@pytest.fixture(scope="module")
def problem():
    return CommandPathProblem(OPEN, START, GOAL, max_length=20)


@pytest.fixture(scope="module")
def small_problem():
    return CommandPathProblem(Workspace(bordered(10, 10)), Pose(3, 3, "O", 0), Pose(6, 5, "O", 0), max_length=12)


def population_arrays(res):
    return res.pop.get("F"), [s.tolist() for s in sequences(res.pop.get("X"))]


# --- HTetroGA ---------------------------------------------------------------------------------
def test_htetro_ga_is_reproducible(problem):
    runs = [minimize(problem, HTetroGA(pop_size=20), ("n_gen", 10), seed=seed) for seed in (4, 4, 5)]
    (F0, X0), (F1, X1), (F2, X2) = (population_arrays(r) for r in runs)
    assert np.array_equal(F0, F1) and X0 == X1
    assert np.array_equal(runs[0].F, runs[1].F)
    assert not (X0 == X2 and np.array_equal(F0, F2))  # the seed matters


def test_htetro_ga_finds_the_exact_optimum_on_an_open_map(problem):
    exact = plan_exact(OPEN, [START, GOAL])
    assert exact.reached and exact.time == 7.0
    best = 1 - exact.time / problem.t_max
    res = minimize(problem, HTetroGA(pop_size=20), ("n_gen", 40), seed=1)
    F = res.pop.get("F")
    reached = F[:, 0] == -1.0
    assert reached.any()
    assert -F[reached, 1].min() == pytest.approx(best)  # the fastest goal-reaching member is optimal
    assert (-F[:, 1][reached] <= best + 1e-12).all()  # and nobody beats the exact planner
    assert (res.F[:, 0] == -1.0).all()  # the optimum (rank 0) reaches the goal


def test_reaching_members_are_trimmed_and_their_fitness_is_current(problem):
    res = minimize(problem, HTetroGA(pop_size=20), ("n_gen", 8), seed=2)
    X, F = sequences(res.pop.get("X")), res.pop.get("F")
    reached, executed = res.pop.get("reached").astype(bool), res.pop.get("executed").astype(int)
    assert reached.any()
    again = problem.simulate(X)
    assert np.array_equal(again.reached, reached) and np.array_equal(again.executed, executed)
    assert np.array_equal(-problem.fitness(again), F)
    for x, r, n in zip(X, reached, executed):
        if r:
            assert len(x) == n  # no genes after the goal


def test_trim_reached_flag():
    problem = CommandPathProblem(OPEN, START, Pose(4, 3, "O", 0), max_length=20)  # one step away: random walks reach it
    kept = minimize(problem, HTetroGA(pop_size=20, trim_reached=False), ("n_gen", 1), seed=0)
    X, reached, executed = sequences(kept.pop.get("X")), kept.pop.get("reached"), kept.pop.get("executed")
    assert any(r and len(x) > n for x, r, n in zip(X, reached, executed))  # the initial genes run past the goal
    trimmed = minimize(problem, HTetroGA(pop_size=20), ("n_gen", 1), seed=0)
    X, reached, executed = sequences(trimmed.pop.get("X")), trimmed.pop.get("reached"), trimmed.pop.get("executed")
    assert reached.any() and all(len(x) == n for x, r, n in zip(X, reached, executed) if r)


def test_trim_reached_function():
    seqs = [parse_commands("x+,x+,y+,y-"), parse_commands("x+,x+,y+"), parse_commands("y+,y+")]
    pop = Population.new("X", as_column(seqs))
    pop.set("reached", np.array([True, False, True]), "executed", np.array([2, 1, 2]))
    assert trim_reached(pop) is pop
    assert [format_commands(s) for s in sequences(pop.get("X"))] == [["x+", "x+"], ["x+", "x+", "y+"], ["y+", "y+"]]
    assert len(trim_reached(Population.empty())) == 0


def test_htetro_ga_parameters():
    for options in (dict(pop_size=1), dict(pop_size=2.5), dict(pop_size=True), dict(crossover_rate=1.5),
                    dict(crossover_rate=-0.1), dict(niche_size=-1)):
        with pytest.raises(ParameterError):
            HTetroGA(**options)


# --- termination ------------------------------------------------------------------------------
def fake_algorithm(F, n_gen):
    return SimpleNamespace(pop=Population.new("F", np.asarray(F, dtype=float)), n_gen=n_gen)


def test_front_convergence_counts_generations_without_improvement():
    term = FrontConvergence(max_gen=100, patience=3)
    reached = -np.array([[1.0, 0.5, 0.5, 0.5], [0.5, 0.9, 0.9, 0.9]])
    assert term.update(fake_algorithm(reached, 1)) == pytest.approx(0.01)
    assert term.update(fake_algorithm(reached, 2)) == pytest.approx(1 / 3)
    assert term.update(fake_algorithm(reached, 3)) == pytest.approx(2 / 3)
    better_safety = -np.array([[1.0, 0.5, 0.5, 0.6]])
    assert term.update(fake_algorithm(better_safety, 4)) == pytest.approx(0.04)  # improved: the count restarts
    assert not term.has_terminated()
    worse = -np.array([[1.0, 0.4, 0.4, 0.4]])
    for gen, expected in ((5, 1 / 3), (6, 2 / 3)):
        assert term.update(fake_algorithm(worse, gen)) == pytest.approx(expected)
        assert not term.converged
    assert term.update(fake_algorithm(better_safety, 7)) == 1.0  # matching the best is no improvement
    assert term.converged and term.has_terminated()


def test_front_convergence_waits_for_the_goal_and_stops_at_max_gen():
    term = FrontConvergence(max_gen=5, patience=1)
    unreached = -np.array([[0.5, 1.0, 1.0, 1.0]])
    for gen in range(1, 5):
        assert term.update(fake_algorithm(unreached, gen)) == pytest.approx(gen / 5)
    assert not term.has_terminated()
    assert term.update(fake_algorithm(unreached, 5)) == 1.0
    assert term.has_terminated() and not term.converged


@pytest.mark.parametrize("options", [dict(max_gen=0), dict(max_gen=-5), dict(max_gen=2.5), dict(max_gen=True),
                                     dict(patience=0), dict(patience=1.0), dict(patience=None)])
def test_front_convergence_parameters(options):
    with pytest.raises(ParameterError):
        FrontConvergence(**options)


def test_front_convergence_stops_a_run_early(small_problem):
    term = FrontConvergence(max_gen=300, patience=5)
    res = minimize(small_problem, HTetroGA(pop_size=12), term, seed=0, copy_termination=False)
    assert term.converged
    assert res.algorithm.n_gen < 100
    assert (res.pop.get("F")[:, 0] == -1.0).any()


def test_leading_front():
    F = -np.array([
        [1.0, 0.5, 0.5, 0.5],  # 0: reaches, dominated by 1
        [1.0, 0.6, 0.5, 0.5],  # 1
        [1.0, 0.4, 0.9, 0.5],  # 2
        [0.5, 0.9, 0.9, 0.9],  # 3: dominates everyone on the last three, but does not reach
    ])
    assert leading_front(F).tolist() == [1, 2]
    unreached = -np.array([[0.5, 0.5, 0.5, 0.5], [0.5, 0.9, 0.9, 0.9], [0.2, 1.0, 0.1, 0.1], [0.2, 0.1, 0.1, 0.1]])
    assert leading_front(unreached).tolist() == [1, 2]  # nobody reaches: the plain non-dominated front
    assert len(leading_front(np.empty((0, 4)))) == 0


# --- selections -------------------------------------------------------------------------------
def test_select_solutions_examples():
    F = -np.array([
        [1.0, 0.5, 0.5, 0.5],  # 0: dominated by 1, ties it on f_t and comes first
        [1.0, 0.5, 0.6, 0.6],  # 1
        [1.0, 0.7, 0.1, 0.2],  # 2: fastest
        [1.0, 0.3, 0.9, 0.3],  # 3: smoothest
        [1.0, 0.2, 0.2, 0.95],  # 4: safest
        [0.5, 1.0, 1.0, 1.0],  # 5: best at everything but f_gr
    ])
    chosen = select_solutions(F)
    assert set(chosen) == set(SELECTIONS)
    assert chosen == {"multi_objective": 1, "time": 2, "smoothness": 3, "safety": 4}
    # ties: the shorter time wins, then the lower index
    F = -np.array([[1.0, 0.5, 0.9, 0.3], [1.0, 0.6, 0.9, 0.1], [1.0, 0.6, 0.9, 0.1]])
    assert select_solutions(F) == {"multi_objective": 0, "time": 1, "smoothness": 1, "safety": 0}
    with pytest.raises(PlanningError):
        select_solutions(np.empty((0, 4)))


def dominates(a, b):
    return (a <= b).all() and (a < b).any()


@settings(max_examples=80, deadline=None)
@given(st.data(), st.integers(1, 15))
def test_select_solutions_picks_from_the_leading_front(data, n):
    values = st.sampled_from([0.0, 0.25, 0.5, 0.75, 1.0])
    fit = np.array(data.draw(st.lists(st.lists(values, min_size=3, max_size=3), min_size=n, max_size=n)))
    f_gr = np.array(data.draw(st.lists(st.sampled_from([1.0, 0.5, 0.2]), min_size=n, max_size=n)))
    F = -np.column_stack([f_gr, fit])
    pool = np.flatnonzero(f_gr == 1.0) if (f_gr == 1.0).any() else np.arange(n)
    front = [i for i in pool if not any(dominates(F[j], F[i]) for j in pool)]
    assert sorted(leading_front(F).tolist()) == front
    chosen = select_solutions(F)
    for name, score in (("multi_objective", -F.sum(axis=1)), ("time", -F[:, 1]), ("smoothness", -F[:, 2]),
                        ("safety", -F[:, 3])):
        i = chosen[name]
        assert i in front
        assert score[i] == max(score[j] for j in front)


# --- the pymoo algorithms ---------------------------------------------------------------------
@pytest.mark.parametrize("name", GA_ALGORITHMS)
def test_every_algorithm_runs(small_problem, name):
    pop_size = 6 if name == "agemoea" else 12
    res = minimize(small_problem, make_algorithm(name, pop_size), ("n_gen", 3), seed=1)
    assert res.F.ndim == 2 and res.F.shape[1] == 4 and len(res.F) >= 1
    F = res.pop.get("F")
    assert len(res.pop) == pop_size
    X = sequences(res.pop.get("X"))
    assert all(np.isin(x, small_problem.command_ids).all() for x in X)
    assert np.array_equal(-small_problem.fitness(small_problem.simulate(X)), F)


def test_make_algorithm_parameters():
    assert isinstance(make_algorithm("htetro", 10), HTetroGA)
    with pytest.raises(ParameterError):
        make_algorithm("nsga4", 10)
    with pytest.raises(ParameterError):
        make_algorithm("nsga2", 1)
    with pytest.raises(ParameterError):  # sampling weights are validated too
        make_algorithm("nsga2", 10, sampling_weights={"x+": -1.0})


# --- plan_ga ----------------------------------------------------------------------------------
def test_plan_ga_revalidates_and_is_reproducible():
    roadmap = [START, GOAL]
    plan = plan_ga(OPEN, roadmap, pop_size=16, max_gen=60, patience=10, max_length=20, seed=3)
    assert isinstance(plan, GAPlan) and plan.reached and plan.failed_leg == -1
    assert plan.method == "ga-htetro"
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
        assert leg.reached and leg.reach_generation is not None
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
    occ = bordered()
    occ[6:10, 6:10] = True
    occ[7:9, 7:9] = False  # a closed 2 × 2 pocket holding the goal
    plan = plan_ga(Workspace(occ), [Pose(3, 3, "O", 0), Pose(7, 8, "O", 0)], pop_size=10, max_gen=4,
                   max_length=15, seed=0)
    assert plan.reached is False and plan.failed_leg == 0
    assert len(plan.commands) == 0 and plan.leg_ends == () and plan.time == 0.0
    assert len(plan.legs) == 1
    leg = plan.legs[0]
    assert not leg.reached and leg.reach_generation is None and not leg.converged
    assert plan.reach_generation is None


def test_plan_ga_errors():
    roadmap = [START, GOAL]
    with pytest.raises(ParameterError):
        plan_ga(OPEN, roadmap, algorithm="simulated-annealing")
    with pytest.raises(ParameterError):
        plan_ga(OPEN, roadmap, pop_size=1)
    with pytest.raises(PlanningError):
        plan_ga(OPEN, [START])


def test_plan_ga_with_pymoo_algorithm():
    plan = plan_ga(OPEN, [START, GOAL], algorithm="nsga2", pop_size=12, max_gen=25, patience=5, max_length=20, seed=0)
    assert plan.method == "ga-nsga2"
    check = Simulator(OPEN).run([plan.commands], START, roadmap=[GOAL])
    assert check.valid[0] and bool(check.reached[0]) == plan.reached


def test_leg_generations_count_the_generations_run():
    occ = bordered()
    occ[6:10, 6:10] = True
    occ[7:9, 7:9] = False
    plan = plan_ga(Workspace(occ), [Pose(3, 3, "O", 0), Pose(7, 8, "O", 0)], pop_size=10, max_gen=4,
                   max_length=15, seed=0)
    leg = plan.legs[0]
    assert len(leg.history) == 4  # one row per generation: the cap was honoured
    assert leg.generations == len(leg.history) == 4


def test_agemoea_without_numba_is_a_clear_error(monkeypatch):
    import sys

    monkeypatch.delitem(sys.modules, "pymoo.algorithms.moo.age", raising=False)
    monkeypatch.setitem(sys.modules, "numba", None)  # makes `import numba` fail
    with pytest.raises(ParameterError, match="numba"):
        make_algorithm("agemoea", 12)
