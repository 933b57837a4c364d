"""The hTetro-GA: reproducible, optimal on an easy map, trimmed chromosomes, and pymoo's operator contract."""

import numpy as np
import pytest
from pymoo.core.population import Population
from pymoo.optimize import minimize

from htetro_opt.algorithms import ConvergenceRecorder, FrontConvergence, HTetroGA, make_algorithm, trim_reached
from htetro_opt.errors import ParameterError
from htetro_opt.model import Pose, Workspace, format_commands, parse_commands
from htetro_opt.operators import (
    CommandMutation,
    CommandRearrangement,
    CommandRemoval,
    CommandRepair,
    as_column,
    sequences,
)
from htetro_opt.problems import CommandPathProblem
from htetro_opt.solvers.grid_paths import plan_exact


def bordered(width=12, height=12):
    occ = np.zeros((height, width), dtype=bool)
    occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = True
    return occ


OPEN = Workspace(bordered())
START, GOAL = Pose(3, 3, "O", 0), Pose(7, 6, "O", 0)


@pytest.fixture(scope="module")
def problem():
    return CommandPathProblem(OPEN, START, GOAL, max_length=20)


def population_arrays(res):
    return res.pop.get("F"), [s.tolist() for s in sequences(res.pop.get("X"))]


def frozen(**options):
    """An hTetro-GA whose variation operators are never applied (pymoo ``prob`` 0) although each would
    change every gene it is applied to (rate 1), and with neither repair nor shortcut (nor re-planning
    nor the balanced polish, unless ``replan_window`` or ``polish_window`` says)."""
    options = {"replan_window": 0, "polish_window": 0, **options}
    return HTetroGA(pop_size=10, removal=CommandRemoval(1.0, 1.0, prob=0.0),
                    rearrangement=CommandRearrangement(1.0, prob=0.0), mutation=CommandMutation(1.0, prob=0.0),
                    crossover_rate=0.0, repair=False, shortcut=False, **options)


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
    again = problem.simulate(X)  # the stored values are those of the chromosomes as they now are
    assert np.array_equal(again.reached, reached) and np.array_equal(again.executed, executed)
    assert np.array_equal(problem.evaluate(as_column(X)), F)
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


@pytest.mark.parametrize("options", [dict(pop_size=1), dict(pop_size=2.5), dict(pop_size=True),
                                     dict(crossover_rate=1.5), dict(crossover_rate=-0.1), dict(niche_size=-1),
                                     dict(repair=1), dict(shortcut="no"), dict(trim_reached=None),
                                     dict(reach_share=0), dict(reach_share=1.2)])
def test_htetro_ga_parameters(options):
    with pytest.raises(ParameterError):
        HTetroGA(**options)


def test_as_published_switches_every_addition_off():
    ours, paper = HTetroGA(10), make_algorithm("htetro-ga-paper", 10)
    assert isinstance(ours.repair, CommandRepair) and ours.shortcut and ours.survival.niche_size == 3
    assert not isinstance(paper.repair, CommandRepair) and not paper.shortcut and paper.survival.niche_size == 0


# --- pymoo's operator contract ----------------------------------------------------------------
def test_operators_run_through_do_so_their_prob_is_honoured(problem):
    # Applied through ``_do``, removal, rearrangement and mutation at rate 1 would change every
    # chromosome; through ``do`` with prob 0 they change none, so no generation has anything new.
    algorithm = frozen()
    algorithm.setup(problem, termination=("n_gen", 10), seed=0)
    algorithm.next()  # the initial population
    assert algorithm._infill() is None
    # the same operators with pymoo's default prob do produce offspring
    lively = HTetroGA(pop_size=10, removal=CommandRemoval(1.0, 1.0), rearrangement=CommandRearrangement(1.0),
                      mutation=CommandMutation(1.0), crossover_rate=0.0, repair=False, shortcut=False)
    lively.setup(problem, termination=("n_gen", 10), seed=0)
    lively.next()
    off = lively._infill()
    assert off is not None and len(off) > 0


def test_a_mutation_applied_to_some_individuals_only(problem):
    # prob 0.5: about half the non-conservative children are mutated, the others are the parents
    algorithm = HTetroGA(pop_size=40, removal=CommandRemoval(0.0, 0.0, prob=0.0),
                         rearrangement=CommandRearrangement(0.0, prob=0.0), mutation=CommandMutation(1.0, prob=0.5),
                         crossover_rate=0.0, repair=False, shortcut=False)
    algorithm.setup(problem, termination=("n_gen", 10), seed=3)
    algorithm.next()
    parents = {tuple(x.tolist()) for x in sequences(algorithm.pop.get("X"))}
    off = sequences(algorithm._infill().get("X"))
    assert all(tuple(x.tolist()) not in parents for x in off)  # offspring are new chromosomes only
    assert 0.2 * len(parents) < len(off) < 0.8 * len(parents)


def test_a_generation_without_offspring_does_not_end_the_run():
    # Nothing new is ever made: each generation is one without improvement, and the run ends by its
    # termination (the generation cap, or patience once the goal is reached), not at the first one.
    far = CommandPathProblem(OPEN, START, Pose(8, 8, "O", 0), max_length=4)  # 10 cells away, 4 genes
    recorder = ConvergenceRecorder()
    res = minimize(far, frozen(), FrontConvergence(max_gen=7, patience=3), seed=0, callback=recorder)
    assert len(recorder.history) == 7 and res.data["converged"] is False
    assert recorder.reach_generation is None

    near = CommandPathProblem(OPEN, START, Pose(4, 3, "O", 0), max_length=10)  # reached by the initial walks
    recorder = ConvergenceRecorder()
    res = minimize(near, frozen(), FrontConvergence(max_gen=50, patience=3), seed=0, callback=recorder)
    assert recorder.reach_generation == 1
    assert res.data["converged"] is True
    assert len(recorder.history) == 4  # generation 1, then 3 without improvement


# --- windowed exact re-planning (ours) ---------------------------------------------------------
def test_replanning_is_on_by_default_and_off_as_published():
    ours, paper = HTetroGA(10), HTetroGA.as_published(10)
    assert ours.replan_window == 40 and ours.replan_members == 3 and ours.replan.window == 40
    assert paper.replan_window == 0 and paper.replan is None
    assert make_algorithm("htetro-ga-paper", 10).replan is None
    assert HTetroGA.as_published(10, replan_window=12).replan.window == 12  # switched back on by name
    assert HTetroGA(10, replan_window=0).replan is None


@pytest.mark.parametrize("options", [dict(replan_window=-1), dict(replan_members=-2), dict(replan_window=1.5),
                                     dict(replan_window=None)])
def test_replan_parameters(options):
    with pytest.raises(ParameterError, match="replan"):
        HTetroGA(**options)
    with pytest.raises(ParameterError, match="replan"):
        make_algorithm("htetro-ga", 10, **{k: v for k, v in options.items() if v is not None} or dict(replan_window=-1))


def test_pymoos_algorithms_refuse_a_negative_replan_window():
    with pytest.raises(ParameterError, match="replan_window"):
        make_algorithm("nsga2", 10, replan_window=-5)
    assert type(make_algorithm("nsga2", 10, replan_window=0)).__name__ == "NSGA2"


def test_the_replanned_fastest_member_joins_the_population():
    # A wall with the goal behind it; the only initial chromosome that reaches goes the long way round.
    occ = bordered(14, 10)
    occ[1:6, 7] = True
    ws = Workspace(occ)
    start, goal = Pose(2, 2, "O", 0), Pose(11, 2, "O", 0)
    detour = parse_commands(",".join(["y+"] * 6 + ["x+"] * 9 + ["y-"] * 6))
    problem = CommandPathProblem(ws, start, goal, max_length=30)
    optimum = plan_exact(ws, [start, goal]).time
    assert problem.simulate([detour]).time[0] > optimum

    def best_time(**options):
        from htetro_opt.operators import CommandSampling

        algorithm = frozen(sampling=CommandSampling(include=[detour]), **options)
        res = minimize(problem, algorithm, ("n_gen", 2), seed=0)
        reached = res.pop.get("reached").astype(bool)
        return float(res.pop.get("time")[reached].min())

    assert best_time(replan_window=0) == problem.simulate([detour]).time[0]
    assert best_time(replan_window=len(detour)) == optimum  # the whole path is one window


def test_replanning_keeps_the_run_reproducible_and_leaves_the_paper_variant_alone(problem):
    a = minimize(problem, HTetroGA(pop_size=16, replan_window=8), ("n_gen", 8), seed=2)
    b = minimize(problem, HTetroGA(pop_size=16, replan_window=8), ("n_gen", 8), seed=2)
    assert population_arrays(a)[1] == population_arrays(b)[1]
    paper = minimize(problem, HTetroGA.as_published(16), ("n_gen", 8), seed=2)
    off = minimize(problem, HTetroGA(16, repair=False, shortcut=False, reach_levels=False, niche_size=0, gene_cap=False,
                                     replan_window=0, reach_patience=0, polish_window=0), ("n_gen", 8), seed=2)
    assert population_arrays(paper)[1] == population_arrays(off)[1]


def test_a_reaching_share_keeps_explorers(problem):
    # the goal is reached early on this open map: the paper's sort soon holds reaching members only
    counts = {}
    for share in (1.0, 0.5):
        res = minimize(problem, HTetroGA(pop_size=20, reach_share=share), ("n_gen", 15), seed=0)
        counts[share] = int(res.pop.get("reached").astype(bool).sum())
    assert counts[1.0] == 20 and counts[0.5] == 10


# --- the reach repair (ours) -------------------------------------------------------------------------
def stalled_run(problem, seqs, n_gen, **options):
    """A frozen hTetro-GA (see ``frozen``) from the chromosomes ``seqs``: nothing but the reach repair
    can change its population, so a population that does not reach stays stalled."""
    recorder = ConvergenceRecorder()
    algorithm = frozen(sampling=Population.new("X", as_column(seqs)), **options)
    res = minimize(problem, algorithm, ("n_gen", n_gen), seed=0, callback=recorder)
    return res, recorder


def test_a_stalled_run_on_a_moving_map_is_reach_repaired_after_its_patience():
    # oracle: plan_exact's time-expanded optimum; the repaired member re-validates in the Simulator
    from htetro_opt.model import Simulator
    from htetro_opt.scenarios import load_scenario

    scenario = load_scenario("parallel_dynamic")
    sim = Simulator(scenario.workspace)
    start, goal = scenario.roadmap
    problem = CommandPathProblem(sim, start, goal, max_length=100)
    rng = np.random.default_rng(0)
    walks = sim.run([rng.choice(problem.command_ids, 30) for _ in range(10)], problem.start_id, repair=rng)
    seqs = [walks.sequence(i) for i in range(10)]
    assert not problem.simulate(seqs).reached.any()
    optimum = plan_exact(sim, [start, goal]).time

    res, recorder = stalled_run(problem, seqs, 9, reach_patience=5)
    assert recorder.reach_generation is not None and recorder.reach_generation > 5  # waited its patience
    reached = res.pop.get("reached").astype(bool)
    assert reached.any()
    for x, t in zip(sequences(res.pop.get("X")[reached]), res.pop.get("time")[reached]):
        check = sim.run([x], problem.start_id, roadmap=[goal], t0=problem.t0)  # all of it, at its times
        assert check.valid[0] and check.reached[0] and check.time[0] == t >= optimum
    again, _ = stalled_run(problem, seqs, 9, reach_patience=5)
    assert population_arrays(again)[1] == population_arrays(res)[1]  # same seed, same result
    for options in (dict(reach_patience=0), dict(reach_patience=20)):
        off, recorder = stalled_run(problem, seqs, 9, **options)
        assert recorder.reach_generation is None and not off.pop.get("reached").astype(bool).any()


def test_the_reach_repair_is_on_by_default_off_as_published_and_idle_in_a_run_that_reaches(problem):
    assert HTetroGA(10).reach_patience == 100 and HTetroGA(10).reach_repair is not None
    assert HTetroGA.as_published(10).reach_patience == 0 and HTetroGA.as_published(10).reach_repair is None
    assert make_algorithm("htetro-ga-paper", 10).reach_repair is None
    assert make_algorithm("htetro-ga-paper", 10, reach_patience=7).reach_patience == 7  # switched back on
    # this run reaches in its first generations: at the default patience the repair never fires and
    # draws nothing, so the run is the one without it; at a patience of 1 it fires before the reach
    runs = {}
    for patience in (100, 0, 1):
        recorder = ConvergenceRecorder()
        res = minimize(problem, HTetroGA(16, reach_patience=patience), ("n_gen", 12), seed=4, callback=recorder)
        runs[patience] = population_arrays(res)[1]
        assert recorder.reach_generation is not None and recorder.reach_generation < 12
    assert runs[100] == runs[0] != runs[1]


@pytest.mark.parametrize("value", [-1, 2.5, None, True])
def test_reach_patience_parameters(value):
    with pytest.raises(ParameterError, match="reach_patience"):
        HTetroGA(10, reach_patience=value)
    if value is not None:
        with pytest.raises(ParameterError, match="reach_patience"):
            make_algorithm("htetro-ga", 10, reach_patience=value)
    with pytest.raises(ParameterError, match="reach_patience applies to the hTetro-GA"):
        make_algorithm("nsga2", 10, reach_patience=5)
    assert type(make_algorithm("nsga2", 10, reach_patience=0)).__name__ == "NSGA2"
