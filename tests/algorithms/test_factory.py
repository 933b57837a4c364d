"""make_algorithm: every name runs the same problem and operators under its pymoo algorithm."""

import sys

import numpy as np
import pytest
from pymoo.optimize import minimize

from htetro_opt.algorithms import GA_ALGORITHMS, HTetroGA, make_algorithm
from htetro_opt.errors import ParameterError
from htetro_opt.model import Pose, Workspace
from htetro_opt.operators import CommandRepair, as_column, sequences
from htetro_opt.problems import CommandPathProblem


@pytest.fixture(scope="module")
def small_problem():
    occ = np.zeros((10, 10), dtype=bool)
    occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = True
    return CommandPathProblem(Workspace(occ), Pose(3, 3, "O", 0), Pose(6, 5, "O", 0), max_length=12)


@pytest.mark.parametrize("name", GA_ALGORITHMS)
def test_every_algorithm_runs(small_problem, name):
    pop_size = 6 if name == "agemoea" else 12
    res = minimize(small_problem, make_algorithm(name, pop_size), ("n_gen", 3), seed=1)
    assert res.F.ndim == 2 and res.F.shape[1] == 4 and len(res.F) >= 1
    F = res.pop.get("F")
    assert len(res.pop) == pop_size
    X = sequences(res.pop.get("X"))
    assert all(np.isin(x, small_problem.command_ids).all() for x in X)
    assert np.array_equal(small_problem.evaluate(as_column(X)), F)  # the stored objectives are current


def test_names_give_their_algorithms():
    from pymoo.algorithms.moo.nsga2 import NSGA2
    from pymoo.algorithms.moo.nsga3 import NSGA3
    from pymoo.algorithms.moo.sms import SMSEMOA

    assert type(make_algorithm("htetro-ga", 10)) is HTetroGA
    assert make_algorithm("htetro-ga-paper", 10).shortcut is False
    assert type(make_algorithm("nsga2", 10)) is NSGA2
    assert type(make_algorithm("nsga3", 10)) is NSGA3
    assert type(make_algorithm("smsemoa", 10)) is SMSEMOA


def test_pymoo_algorithms_get_the_repair():
    for name in ("nsga2", "nsga3", "smsemoa", "agemoea"):
        assert isinstance(make_algorithm(name, 12).repair, CommandRepair)


@pytest.mark.parametrize("name, pop_size, options, word", [
    ("nsga4", 10, {}, "'nsga4'"),
    ("htetro", 10, {}, "'htetro'"),  # the old name is refused, not mapped
    ("nsga2", 1, {}, "pop_size"),
    ("nsga2", 10, {"sampling_weights": {"x+": -1.0}}, "sampling weight of 'x\\+'"),
    ("nsga2", 10, {"crossover_rate": 1.5}, "crossover_rate"),  # named as the caller knows it
    ("htetro-ga", 10, {"crossover_rate": -0.5}, "crossover_rate"),
])
def test_make_algorithm_parameters(name, pop_size, options, word):
    with pytest.raises(ParameterError, match=word):
        make_algorithm(name, pop_size, **options)


def test_agemoea_without_numba_is_a_clear_error(monkeypatch):
    monkeypatch.delitem(sys.modules, "pymoo.algorithms.moo.age", raising=False)
    monkeypatch.setitem(sys.modules, "numba", None)  # makes `import numba` fail
    with pytest.raises(ParameterError, match="numba"):
        make_algorithm("agemoea", 12)


def test_reach_share_reaches_the_htetro_ga_sort_and_the_paper_mode_refuses_it():
    assert make_algorithm("htetro-ga", 20).survival.reach_share == 1.0
    assert make_algorithm("htetro-ga", 20, reach_share=0.6).survival.reach_share == 0.6
    assert make_algorithm("htetro-ga-paper", 20, reach_share=1.0).survival.reach_share == 1.0  # no cap: the paper's
    with pytest.raises(ParameterError, match="htetro-ga-paper refuses it"):
        make_algorithm("htetro-ga-paper", 20, reach_share=0.6)  # ours, not an addition


@pytest.mark.parametrize("share, name, word", [(0.0, "htetro-ga", "reach_share"), (1.1, "htetro-ga-paper", "reach_share"),
                                               (0.75, "nsga2", "applies to the hTetro-GA")])
def test_reach_share_is_refused_out_of_range_or_for_pymoo_algorithms(share, name, word):
    with pytest.raises(ParameterError, match=word):
        make_algorithm(name, 20, reach_share=share)


def test_plan_ga_passes_reach_share_on():
    from htetro_opt.solvers.grid_paths import plan_ga

    ws, roadmap = Workspace(np.zeros((10, 10), dtype=bool)), [Pose(2, 2, "O", 0), Pose(6, 5, "O", 0)]
    plans = [plan_ga(ws, roadmap, pop_size=20, max_gen=30, max_length=20, seed=3, reach_share=s) for s in (None, 0.5)]
    assert all(p.reached for p in plans) and plans[0].legs[0].front != plans[1].legs[0].front
    assert make_algorithm("nsga2", 20, reach_share=1.0).pop_size == 20  # 1 is no cap: any algorithm takes it
    with pytest.raises(ParameterError, match="reach_share"):
        plan_ga(ws, roadmap, algorithm="nsga2", reach_share=0.5)


# --- the re-planning step for pymoo's algorithms ---------------------------------------------------
PYMOO = [name for name in GA_ALGORITHMS if not name.startswith("htetro")]


@pytest.mark.parametrize("name", PYMOO)
def test_pymoo_algorithms_take_the_replanning_through_their_mating(name):
    from pymoo.core.mating import Mating

    from htetro_opt.algorithms.factory import ReplanMating

    if name == "agemoea":
        pytest.importorskip("numba")
    plain, replanning = make_algorithm(name, 12), make_algorithm(name, 12, replan_window=9, replan_members=2)
    assert type(plain.mating) is Mating and not isinstance(plain.mating, ReplanMating)
    assert isinstance(replanning.mating, ReplanMating) and replanning.mating.mating.selection is not None
    assert (replanning.mating.replan.window, replanning.mating.members) == (9, 2)
    assert make_algorithm(name, 12, replan_window=5).mating.members == 3
    assert type(make_algorithm(name, 12, replan_window=0).mating) is Mating


def test_replan_mating_adds_the_fastest_members_exact_window_to_the_offspring():
    from pymoo.core.population import Population

    from htetro_opt.model import format_commands, parse_commands
    from htetro_opt.solvers.grid_paths import plan_exact

    ws = Workspace(np.zeros((8, 8), dtype=bool))
    start, goal = Pose(1, 2, "O", 0), Pose(5, 2, "O", 0)
    problem = CommandPathProblem(ws, start, goal, max_length=10)
    detour = parse_commands("y+,x+,x+,y-,x+,x+")  # reaches the goal in 6 s; the optimum takes 4
    wander = parse_commands("y+,y+,x+")  # does not reach it
    X = as_column([detour, wander])
    pop = Population.new(X=X, F=problem.evaluate(X), rank=np.array([0, 1]), crowding=np.array([np.inf, np.inf]))
    algorithm = make_algorithm("nsga2", 2, replan_window=6, replan_members=0)
    algorithm.setup(problem, seed=0)  # pymoo's selection draws from the algorithm's stream, not numpy's global one
    off = algorithm.mating.do(problem, pop, 2, random_state=algorithm.random_state, algorithm=algorithm)
    oracle = plan_exact(ws, [start, goal])
    offspring = [format_commands(x) for x in sequences(off.get("X"))]
    assert format_commands(oracle.commands) in offspring and len(off) <= 3


def test_nsga2_with_the_replanning_reaches_and_stays_valid(small_problem):
    res = minimize(small_problem, make_algorithm("nsga2", 12, replan_window=8), ("n_gen", 15), seed=2)
    X = sequences(res.pop.get("X"))
    assert len(res.pop) == 12 and np.array_equal(small_problem.evaluate(as_column(X)), res.pop.get("F"))
    assert (res.pop.get("F")[:, 0] == -1).any()


# --- the conservative offspring set for pymoo's algorithms ----------------------------------------
@pytest.mark.parametrize("name", PYMOO)
def test_pymoo_algorithms_take_the_conservative_set_through_their_mating(name):
    from pymoo.core.mating import Mating

    from htetro_opt.algorithms import ConservativeMating, ReplanMating

    if name == "agemoea":
        pytest.importorskip("numba")
    assert type(make_algorithm(name, 12).mating) is Mating
    conservative = make_algorithm(name, 12, conservative=True)
    assert isinstance(conservative.mating, ConservativeMating) and conservative.mating.mating.selection is not None
    both = make_algorithm(name, 12, conservative=True, replan_window=9)
    assert isinstance(both.mating, ReplanMating) and isinstance(both.mating.mating, ConservativeMating)
    assert type(make_algorithm(name, 12, conservative=False).mating) is Mating


@pytest.mark.parametrize("name", ["htetro-ga", "htetro-ga-paper"])
@pytest.mark.parametrize("value", [True, False])
def test_the_htetro_ga_refuses_the_conservative_option(name, value):
    with pytest.raises(ParameterError, match="conservative"):
        make_algorithm(name, 12, conservative=value)


@pytest.mark.parametrize("value", [1, "yes", 2.5])
def test_conservative_must_be_a_bool(value):
    with pytest.raises(ParameterError, match="conservative"):
        make_algorithm("nsga2", 12, conservative=value)


def test_the_conservative_set_adds_one_new_child_per_member_to_pymoos_own_offspring():
    # control: the same population and seeds without the conservative set
    from pymoo.core.population import Population

    from htetro_opt.model import format_commands, parse_commands

    ws = Workspace(np.zeros((8, 8), dtype=bool))
    problem = CommandPathProblem(ws, Pose(1, 2, "O", 0), Pose(5, 2, "O", 0), max_length=10)
    loopy = parse_commands("x+,x+,r+,r-,x+,x+")  # reaches the goal in 8 s; its loop r+ r- costs 4
    wander = parse_commands("y+,y+,x+")
    X = as_column([loopy, wander])
    outcomes = problem.outcomes(problem.simulate(sequences(X)))
    members = {tuple(format_commands(x)) for x in (loopy, wander)}
    straight = ("x+",) * 4
    hits = {True: 0, False: 0}
    for seed in range(6):
        offspring = {}
        for conservative in (True, False):
            pop = Population.new(X=X, F=outcomes["F"], reached=outcomes["reached"], executed=outcomes["executed"],
                                 rank=np.array([0, 1]), crowding=np.array([np.inf, np.inf]))
            algorithm = make_algorithm("nsga2", 2, conservative=conservative)
            algorithm.setup(problem, seed=seed)  # pymoo's selection draws from the algorithm's stream
            off = algorithm.mating.do(problem, pop, 2, random_state=algorithm.random_state, algorithm=algorithm)
            offspring[conservative] = [tuple(format_commands(x)) for x in sequences(off.get("X"))]
            assert all(np.isin(x, problem.command_ids).all() for x in sequences(off.get("X")))
            hits[conservative] += straight in offspring[conservative]
        own, extra = offspring[True][: len(offspring[False])], offspring[True][len(offspring[False]):]
        assert own == offspring[False]  # pymoo's own offspring are untouched: the set draws after them
        assert 1 <= len(extra) <= 2  # at most one child per member, and here never all duplicates
        assert not (set(extra) & (members | set(own))) and len(set(extra)) == len(extra)
    assert hits[True] and not hits[False]  # the set can cut the loop; pymoo's own operators did not
