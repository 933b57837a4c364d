"""The array forms the hTetro-GA runs on, each against pymoo's Population-based original or a fresh
simulation: operators (batch.py), tournament, survival, the shortcut's derived simulation, the
re-planning graph's remembered answers."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from pymoo.core.mutation import Mutation
from pymoo.core.population import Population
from pymoo.core.problem import Problem
from pymoo.operators.survival.rank_and_crowding import RankAndCrowding

from htetro_opt.model import SEED000_COMMANDS, Pose, Simulator, Workspace, parse_commands
from htetro_opt.operators.commands import (
    CommandCrossover,
    CommandMutation,
    CommandRearrangement,
    CommandRemoval,
    CommandReplan,
    RankAndCrowdingTournament,
    TransitionGraph,
    as_column,
    sequences,
)
from htetro_opt.operators.commands.batch import apply_crossover, apply_mutation
from htetro_opt.operators.commands.shortcut import cut_result, cut_sequences, loop_cuts
from htetro_opt.operators.commands.survival import rank_and_crowding
from htetro_opt.problems import CommandPathProblem

SEED_IDS = parse_commands(",".join(SEED000_COMMANDS))


def cluttered(seed: int = 0, size: int = 12) -> Workspace:
    rng = np.random.default_rng(seed)
    occ = rng.random((size, size)) < 0.15
    occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = True
    occ[1:4, 1:4] = False
    occ[8:11, 8:11] = False
    return Workspace(occ)


@pytest.fixture(scope="module")
def problem():
    return CommandPathProblem(cluttered(3), Pose(2, 2, "O", 0), Pose(9, 9, "O", 0), max_length=20)


def random_seqs(rng, n, longest=30):
    return [rng.choice(SEED_IDS, size=int(rng.integers(0, longest))) for _ in range(n)]


def as_lists(seqs):
    return [np.asarray(s).tolist() for s in seqs]


class Reverse(Mutation):
    """A user's operator that overrides pymoo's ``do()`` (it must be run through it)."""

    def do(self, problem, pop, *args, random_state=None, **kwargs):
        return Population.new("X", as_column([s[::-1] for s in sequences(pop.get("X"))]))


@pytest.mark.parametrize("operator", [CommandMutation(prob=0.5), CommandMutation(0.3), CommandRemoval(0.5, 0.5, prob=0.7),
                                      CommandRearrangement(0.4, prob=0.3), Reverse()],
                         ids=["mutation", "mutation-prob1", "removal", "rearrangement", "user-do"])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_apply_mutation_is_pymoos_do(problem, operator, seed):
    seqs = random_seqs(np.random.default_rng(seed), 25)
    ours = apply_mutation(operator, problem, seqs, random_state=np.random.default_rng(seed + 10))
    rng = np.random.default_rng(seed + 10)
    theirs = operator.do(problem, Population.new("X", as_column(seqs)), random_state=rng)
    assert as_lists(ours) == as_lists(sequences(theirs.get("X")))
    after = np.random.default_rng(seed + 10)
    apply_mutation(operator, problem, seqs, random_state=after)
    assert after.random() == rng.random()  # the same draws, so the rest of a run is the same too


def test_apply_mutation_runs_the_replanning_as_its_do_does(problem):
    seqs = [parse_commands("y+,x+,x+,y-,x+,x+,y+,y+,y+"), parse_commands("x+,x-,x+,y+")]
    operator = CommandReplan(6, prob=0.5)
    ours = apply_mutation(operator, problem, seqs, random_state=np.random.default_rng(4))
    theirs = operator.do(problem, Population.new("X", as_column(seqs)), random_state=np.random.default_rng(4))
    assert as_lists(ours) == as_lists(sequences(theirs.get("X")))


@pytest.mark.parametrize("prob", [1.0, 0.5, 0.0])
@pytest.mark.parametrize("seed", [0, 1])
def test_apply_crossover_is_pymoos_do(problem, prob, seed):
    rng = np.random.default_rng(seed)
    seqs = random_seqs(rng, 12)
    matings = rng.integers(0, len(seqs), size=(7, 2))
    operator = CommandCrossover(prob)
    ours = apply_crossover(operator, problem, seqs, matings, random_state=np.random.default_rng(seed + 5))
    theirs = operator.do(problem, Population.new("X", as_column(seqs)), matings, random_state=np.random.default_rng(seed + 5))
    assert len(ours) == 14
    assert as_lists(ours) == as_lists(sequences(theirs.get("X")))


def test_apply_crossover_of_equal_length_parents(problem):
    # numpy would stack equal-length chromosomes into a 2-D array if they were assigned at once
    seqs = [np.arange(4), np.arange(4, 8)]
    off = apply_crossover(CommandCrossover(), problem, seqs, np.array([[0, 1]]), random_state=np.random.default_rng(0))
    assert sorted(sum(as_lists(off), [])) == list(range(8))


@pytest.mark.parametrize("seed", range(5))
def test_tournament_select_is_pymoos_tournament(seed):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(5, 40))
    rank = rng.integers(0, 4, size=n)
    crowding = np.where(rng.random(n) < 0.2, np.inf, rng.random(n))
    pop = Population.new("X", as_column([np.array([i]) for i in range(n)]))
    pop.set("rank", rank, "crowding", crowding)
    selection = RankAndCrowdingTournament(4)
    theirs = selection.do(None, pop, 9, n_parents=2, to_pop=False, random_state=np.random.default_rng(seed))
    ours = selection.select(rank, crowding, 9, 2, random_state=np.random.default_rng(seed))
    assert ours.shape == (9, 2) and np.array_equal(ours, theirs)


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(1, 60), n_survive=st.integers(1, 70),
       levels=st.integers(1, 5))
def test_rank_and_crowding_is_pymoos_survival(seed, n, n_survive, levels):
    # an independent oracle: pymoo's RankAndCrowding on a Population, with the same generator
    rng = np.random.default_rng(seed)
    F = rng.integers(0, levels + 1, size=(n, 4)) / levels  # coarse values: many ties and duplicates
    ranking = RankAndCrowding()
    pop = Population.new("F", F)
    theirs = ranking.do(Problem(n_var=1, n_obj=4), pop, n_survive=n_survive, random_state=np.random.default_rng(seed))
    rows, rank, crowding = rank_and_crowding(F, n_survive, nds=ranking.nds, crowding=ranking.crowding_func,
                                             random_state=np.random.default_rng(seed))
    index = {id(ind): i for i, ind in enumerate(pop)}
    assert rows.tolist() == [index[id(ind)] for ind in theirs]
    assert np.array_equal(rank, theirs.get("rank"))
    assert np.array_equal(crowding, theirs.get("crowding").astype(float))


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), map_seed=st.integers(0, 10))
def test_the_cut_paths_simulation_is_that_of_running_them(seed, map_seed):
    # oracle: a fresh simulation of the shortened sequences (with the goal and child termination)
    ws = cluttered(map_seed)
    problem = CommandPathProblem(ws, Pose(2, 2, "O", 0), Pose(9, 9, "O", 0), max_length=20)
    rng = np.random.default_rng(seed)
    seqs = random_seqs(rng, 16, longest=40) + [parse_commands("x+,y+,x-,y-,x+,x+")]
    result = problem.simulate(seqs, repair=np.random.default_rng(seed))
    seqs = [result.sequence(i) for i in range(len(seqs))]
    cuts = loop_cuts(result, 12)  # only the first 12 are cut, as the hTetro-GA cuts its conservative set
    derived = problem.outcomes(cut_result(result, *cuts))
    fresh = problem.outcomes(problem.simulate(cut_sequences(seqs, *cuts)))
    assert (cuts[0] != cuts[1]).any()
    for key in fresh:
        assert np.array_equal(derived[key], fresh[key]), key


def test_f_sf_does_not_depend_on_the_batch():
    # numpy sums a batch of one pairwise: f_sf is summed in command order whatever the batch
    problem = CommandPathProblem(cluttered(1), Pose(2, 2, "O", 0), Pose(9, 9, "O", 0), max_length=60)
    seqs = random_seqs(np.random.default_rng(7), 30, longest=60)
    batch = problem.evaluate(as_column(seqs))
    alone = np.vstack([problem.evaluate(as_column([s])) for s in seqs])
    assert np.array_equal(batch, alone)


def test_the_graph_remembers_answers_without_changing_them():
    # oracle: a new graph for every question, so nothing is remembered
    sim = Simulator(cluttered(2))
    remembering = TransitionGraph(sim)
    rng = np.random.default_rng(0)
    free = [pid for pid in (sim.encode(Pose(x, y, "O", 0)) for x, y in [(2, 2), (9, 9), (2, 9), (9, 2), (3, 8)])
            if not sim.pose_conflicts(pid)]
    questions = [(int(rng.choice(free)), int(rng.choice(free)), float(rng.integers(3, 40))) for _ in range(12)]
    found = 0
    for source, target, limit in questions + questions:  # each asked twice
        fresh = TransitionGraph(sim).fastest(source, 0, target, 0, limit=limit)
        answer = remembering.fastest(source, 0, target, 0, limit=limit)
        assert [(p.tolist(), t) for p, t in answer] == [(p.tolist(), t) for p, t in fresh]
        found += len(answer)
    assert found and len(free) >= 3
    path = next(p for s, t, lim in questions for p, _ in remembering.fastest(s, 0, t, 0, limit=lim) if len(p))
    with pytest.raises(ValueError):  # an answer is shared: no caller can change it
        path[0] = 0
