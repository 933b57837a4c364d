"""The command-chromosome operators: invariants on random chromosomes, determinism, and the pymoo wrappers."""

from collections import Counter

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from pymoo.core.population import Population
from pymoo.core.problem import Problem

from htetro_opt.errors import ParameterError, UnknownCommandError
from htetro_opt.model import (
    COMMANDS,
    DIAGONAL_COMMANDS,
    SEED000_COMMANDS,
    Pose,
    Timing,
    Workspace,
    command_id,
    parse_commands,
)
from htetro_opt.operators import (
    DEFAULT_SAMPLING_WEIGHTS,
    CommandCrossover,
    CommandDuplicateElimination,
    CommandMutation,
    CommandRearrangement,
    CommandRemoval,
    CommandSampling,
    GoalReachabilitySurvival,
    RankAndCrowdingTournament,
    as_column,
    displacement,
    mutate_commands,
    rank_and_crowding_tournament,
    reaches_goal,
    rearrange_commands,
    remove_commands,
    repair_and_shortcut,
    sample_commands,
    sequences,
    single_point_crossover,
)
from htetro_opt.problems import CommandPathProblem

SEED_IDS = [command_id(t) for t in SEED000_COMMANDS]
REMOVAL_IDS = SEED_IDS + [command_id(t) for t in DIAGONAL_COMMANDS]
TRANSLATION_IDS = {command_id(t) for t in ("x+", "x-", "y+", "y-")}
MOVE_IDS = {i for i, c in enumerate(COMMANDS) if c.shift != (0, 0)}
OPPOSITE = {}
for _token, _other in [("x+", "x-"), ("y+", "y-"), ("x+y+", "x-y-"), ("x+y-", "x-y+")]:
    OPPOSITE[command_id(_token)] = command_id(_other)
    OPPOSITE[command_id(_other)] = command_id(_token)

seeds = st.integers(0, 2**32 - 1)
rates = st.one_of(st.none(), st.floats(0.0, 1.0))


def chromosomes(ids, max_size=25):
    return st.lists(st.sampled_from(ids), max_size=max_size).map(lambda genes: np.array(genes, dtype=np.int64))


def batches(ids=SEED_IDS, max_chromosomes=6, max_size=25):
    return st.lists(chromosomes(ids, max_size), max_size=max_chromosomes)


def copies(seqs):
    return [s.copy() for s in seqs]


def same_lists(a, b):
    return len(a) == len(b) and all(np.array_equal(x, y) for x, y in zip(a, b))


def is_subsequence(small, big):
    it = iter(big.tolist())
    return all(any(g == h for h in it) for g in small.tolist())


@pytest.fixture(scope="module")
def problem():
    """A small open-map problem with seed 000's 13 commands, l_p,max = 10."""
    return CommandPathProblem(Workspace(np.zeros((12, 12), dtype=bool)), Pose(4, 4, "O", 0), Pose(6, 4, "O", 0),
                              max_length=10)


# --- helpers ----------------------------------------------------------------------------------
def test_displacement_as_column_and_sequences():
    assert displacement(parse_commands("x+,x+,y-,sI,r+,x-y+")) == (1, 0)
    assert displacement(np.empty(0, dtype=np.int64)) == (0, 0)
    X = as_column([[1, 2], np.array([3], dtype=np.int32), np.empty(0, dtype=np.int64)])
    assert X.shape == (3, 1) and X.dtype == object
    assert all(x[0].dtype == np.int64 and x[0].ndim == 1 for x in X)
    assert [s.tolist() for s in sequences(X)] == [[1, 2], [3], []]
    assert [s.tolist() for s in sequences(X[:, 0])] == [[1, 2], [3], []]


# --- removal ----------------------------------------------------------------------------------
@settings(max_examples=150, deadline=None)
@given(seqs=batches(REMOVAL_IDS), seed=seeds, translation_rate=rates, other_rate=rates)
def test_removal_is_conservative(seqs, seed, translation_rate, other_rate):
    before = copies(seqs)
    out = remove_commands(np.random.default_rng(seed), seqs, translation_rate=translation_rate, other_rate=other_rate)
    assert same_lists(seqs, before)  # inputs untouched
    assert len(out) == len(seqs)
    for original, child in zip(seqs, out):
        assert child.dtype == np.int64
        assert displacement(child) == displacement(original)
        assert is_subsequence(child, original)
        removed = Counter(original.tolist()) - Counter(child.tolist())
        # translations (and diagonals) leave only in cancelling pairs: x+ with x-, x+y+ with x-y-, ...
        for gene, n in removed.items():
            if gene in MOVE_IDS:
                assert removed[OPPOSITE[gene]] == n
    again = remove_commands(np.random.default_rng(seed), seqs, translation_rate=translation_rate, other_rate=other_rate)
    assert same_lists(out, again)


@settings(max_examples=60, deadline=None)
@given(seqs=batches(REMOVAL_IDS), seed=seeds)
def test_removal_rates_select_what_is_removed(seqs, seed):
    rng = np.random.default_rng(seed)
    assert same_lists(remove_commands(rng, seqs, translation_rate=0.0, other_rate=0.0), seqs)
    only_moves = remove_commands(rng, seqs, translation_rate=0.0, other_rate=1.0)
    assert same_lists(only_moves, [s[np.isin(s, list(MOVE_IDS))] for s in seqs])
    no_others_removed = remove_commands(rng, seqs, translation_rate=1.0, other_rate=0.0)
    for original, child in zip(seqs, no_others_removed):
        keep = ~np.isin(original, list(MOVE_IDS))
        assert Counter(child[~np.isin(child, list(MOVE_IDS))].tolist()) == Counter(original[keep].tolist())


def test_removal_pairs_examples():
    rng = np.random.default_rng(0)
    assert remove_commands(rng, [parse_commands("x+,sI,x-")], translation_rate=1, other_rate=1)[0].tolist() == []
    assert remove_commands(rng, [parse_commands("x+y+,x-y-")], translation_rate=1, other_rate=1)[0].tolist() == []
    for tokens in ("x+,x+", "x+y+,x-,y-", "y+,x-", "x+y-,x-y-"):  # nothing here cancels pairwise
        seq = parse_commands(tokens)
        for seed in range(20):
            out = remove_commands(np.random.default_rng(seed), [seq], translation_rate=1, other_rate=1)
            assert out[0].tolist() == seq.tolist()


def test_removal_default_rate_removes_sometimes():
    seqs = [parse_commands("x+,x-,sI,y+,y-")] * 200
    out = remove_commands(np.random.default_rng(3), seqs)  # rates 1 / l_p = 0.2
    lengths = Counter(len(s) for s in out)
    assert lengths[5] > 0 and sum(n for k, n in lengths.items() if k < 5) > 0


# --- rearrangement ----------------------------------------------------------------------------
@settings(max_examples=150, deadline=None)
@given(seqs=batches(REMOVAL_IDS), seed=seeds, rate=rates)
def test_rearrangement_keeps_the_multiset(seqs, seed, rate):
    before = copies(seqs)
    out = rearrange_commands(np.random.default_rng(seed), seqs, rate=rate)
    assert same_lists(seqs, before)
    assert len(out) == len(seqs)
    for original, child in zip(seqs, out):
        assert len(child) == len(original)
        assert sorted(child.tolist()) == sorted(original.tolist())
        assert displacement(child) == displacement(original)
    assert same_lists(out, rearrange_commands(np.random.default_rng(seed), seqs, rate=rate))
    assert same_lists(rearrange_commands(np.random.default_rng(seed), seqs, rate=0.0), seqs)


def test_rearrangement_does_permute():
    seq = np.arange(6, dtype=np.int64)
    out = rearrange_commands(np.random.default_rng(0), [seq] * 50, rate=1.0)
    assert sum(not np.array_equal(s, seq) for s in out) > 40


# --- mutation ---------------------------------------------------------------------------------
@settings(max_examples=150, deadline=None)
@given(seqs=batches(), seed=seeds, rate=st.floats(0.0, 1.0),
       alphabet=st.lists(st.sampled_from(DIAGONAL_COMMANDS), min_size=1, unique=True))
def test_mutation_keeps_lengths_and_draws_from_the_alphabet(seqs, seed, rate, alphabet):
    ids = parse_commands(alphabet)  # disjoint from the chromosomes' seed-000 genes: mutated genes show
    before = copies(seqs)
    out = mutate_commands(np.random.default_rng(seed), seqs, rate=rate, commands=ids)
    assert same_lists(seqs, before)
    assert [len(s) for s in out] == [len(s) for s in seqs]
    for original, child in zip(seqs, out):
        changed = child != original
        assert np.isin(child[changed], ids).all()
    assert same_lists(out, mutate_commands(np.random.default_rng(seed), seqs, rate=rate, commands=ids))
    assert same_lists(mutate_commands(np.random.default_rng(seed), seqs, rate=0.0, commands=ids), seqs)
    full = mutate_commands(np.random.default_rng(seed), seqs, rate=1.0, commands=ids)
    assert all(np.isin(s, ids).all() for s in full)


def test_mutation_rate_is_per_gene():
    seqs = [np.zeros(100, dtype=np.int64)] * 50
    out = mutate_commands(np.random.default_rng(5), seqs, rate=0.1, commands=np.array([7]))
    hits = sum(int((s == 7).sum()) for s in out)
    assert 350 < hits < 650  # binomial(5000, 0.1): mean 500, sd 21


# --- crossover --------------------------------------------------------------------------------
@settings(max_examples=200, deadline=None)
@given(a=chromosomes(SEED_IDS, 30), b=chromosomes(SEED_IDS, 30), seed=seeds)
def test_crossover_swaps_tails(a, b, seed):
    a0, b0 = a.copy(), b.copy()
    c, d = single_point_crossover(np.random.default_rng(seed), a, b)
    assert np.array_equal(a, a0) and np.array_equal(b, b0)
    assert len(c) + len(d) == len(a) + len(b)
    assert Counter(c.tolist() + d.tolist()) == Counter(a.tolist() + b.tolist())
    # c = a[:i] + b[j:] and d = b[:j] + a[i:] for some cut points i, j
    cuts = [(i, j) for i in range(len(a) + 1) for j in range(len(b) + 1)]
    assert any(np.array_equal(c, np.concatenate([a[:i], b[j:]])) and np.array_equal(d, np.concatenate([b[:j], a[i:]]))
               for i, j in cuts)
    c2, d2 = single_point_crossover(np.random.default_rng(seed), a, b)
    assert np.array_equal(c, c2) and np.array_equal(d, d2)


@settings(max_examples=100, deadline=None)
@given(a=chromosomes(SEED_IDS, 30), b=chromosomes(SEED_IDS, 30), seed=seeds, limit=st.integers(1, 40))
def test_crossover_max_genes_caps_the_offspring(a, b, seed, limit):
    c, d = single_point_crossover(np.random.default_rng(seed), a, b, max_genes=limit)
    full_c, full_d = single_point_crossover(np.random.default_rng(seed), a, b)
    assert np.array_equal(c, full_c[:limit]) and np.array_equal(d, full_d[:limit])


def test_crossover_cut_points_are_independent_and_uniform():
    rng = np.random.default_rng(0)
    a, b = np.zeros(4, dtype=np.int64), np.ones(8, dtype=np.int64)
    pairs = Counter()
    for _ in range(4500):
        c, _ = single_point_crossover(rng, a, b)
        i = int((c == 0).sum())
        pairs[(i, len(c) - i)] += 1  # (i, 8 − j)
    assert len(pairs) == 5 * 9  # every (i, j) with i in 0 … 4 and j in 0 … 8
    assert all(50 < n < 150 for n in pairs.values())


def test_crossover_operator_caps_only_when_asked():
    class Stub:
        n_var, max_length = 1, 3

    pop = Population.new("X", as_column([np.zeros(6, dtype=np.int64)] * 50 + [np.ones(6, dtype=np.int64)] * 50))
    matings = np.column_stack([np.arange(50), np.arange(50, 100)])
    off = CommandCrossover().do(Stub(), pop, matings, random_state=np.random.default_rng(3))
    lengths = [len(x) for x in sequences(off.get("X"))]
    assert len(lengths) == 100 and max(lengths) > 6 and sum(lengths) == 600  # the paper's: no cap, genes kept
    off = CommandCrossover(length_cap=2).do(Stub(), pop, matings, random_state=np.random.default_rng(3))
    lengths = [len(x) for x in sequences(off.get("X"))]
    assert len(lengths) == 100 and max(lengths) == 6 and min(lengths) < 6  # twice l_p,max (the gene-cap addition)
    assert max(len(x) for x in sequences(CommandCrossover(max_genes=4).do(
        Stub(), pop, matings, random_state=np.random.default_rng(3)).get("X"))) == 4


def test_crossover_with_empty_parents():
    rng = np.random.default_rng(1)
    a, b = np.empty(0, dtype=np.int64), parse_commands("x+,y+,sI")
    for _ in range(20):
        c, d = single_point_crossover(rng, a, b)
        assert sorted(c.tolist() + d.tolist()) == sorted(b.tolist())
        c, d = single_point_crossover(rng, b, a)
        assert sorted(c.tolist() + d.tolist()) == sorted(b.tolist())


# --- sampling ---------------------------------------------------------------------------------
@settings(max_examples=100, deadline=None)
@given(
    weights=st.dictionaries(st.sampled_from(SEED000_COMMANDS), st.floats(0.01, 10.0), min_size=1),
    t_max=st.floats(0.5, 60.0),
    n=st.integers(0, 8),
    seed=seeds,
    rotation=st.floats(0.5, 4.0),
)
def test_sampling_fills_the_time_budget(weights, t_max, n, seed, rotation):
    durations = Timing(rotation=rotation).durations()
    commands = np.array(SEED_IDS)
    w = np.array([weights.get(t, 0.0) for t in SEED000_COMMANDS])
    out = sample_commands(np.random.default_rng(seed), n, commands=commands, weights=w, durations=durations,
                          t_max=t_max)
    assert len(out) == n
    allowed = parse_commands(list(weights))
    for s in out:
        assert s.dtype == np.int64 and len(s) >= 1
        assert np.isin(s, allowed).all()
        total = durations[s].sum()
        assert total >= t_max
        assert total - durations[s[-1]] < t_max
    again = sample_commands(np.random.default_rng(seed), n, commands=commands, weights=w, durations=durations,
                            t_max=t_max)
    assert same_lists(out, again)


def test_sampling_follows_the_weights():
    commands = parse_commands("x+,y+")
    out = sample_commands(np.random.default_rng(2), 100, commands=commands, weights=np.array([3.0, 1.0]),
                          durations=Timing().durations(), t_max=20.0)
    genes = np.concatenate(out)
    share = (genes == command_id("x+")).mean()
    assert 0.7 < share < 0.8  # 2000 draws at p = 0.75


def test_command_sampling_defaults_to_translations(problem):
    assert set(DEFAULT_SAMPLING_WEIGHTS) == {"x+", "x-", "y+", "y-"}
    pop = CommandSampling().do(problem, 30, random_state=np.random.default_rng(0))
    assert len(pop) == 30
    for s in sequences(pop.get("X")):
        assert set(s.tolist()) <= TRANSLATION_IDS
        assert len(s) == problem.max_length  # translations take t_translation, t_max = l_p,max × t_translation
    genes = np.concatenate(sequences(pop.get("X")))
    assert set(genes.tolist()) == TRANSLATION_IDS


def test_command_sampling_validates_weights(problem):
    with pytest.raises(ParameterError):
        CommandSampling({"x+": -1.0})
    with pytest.raises(ParameterError):
        CommandSampling({"x+": 0.0, "y+": 0.0})
    with pytest.raises(ParameterError):
        CommandSampling({"x+": float("nan")})
    with pytest.raises(UnknownCommandError):
        CommandSampling({"forward": 1.0})
    with pytest.raises(ParameterError):  # a diagonal is not in seed 000's command set
        CommandSampling({"x+": 1.0, "x+y+": 1.0}).do(problem, 3, random_state=np.random.default_rng(0))
    pop = CommandSampling({"sI": 1.0, "r+": 1.0}).do(problem, 10, random_state=np.random.default_rng(0))
    assert set(np.concatenate(sequences(pop.get("X"))).tolist()) == {command_id("sI"), command_id("r+")}


# --- the pymoo classes: random_state only, deterministic, no global state -------------------
def _population(seed=0, n=8):
    rng = np.random.default_rng(seed)
    seqs = [rng.choice(SEED_IDS, size=rng.integers(2, 15)).astype(np.int64) for _ in range(n)]
    return Population.new("X", as_column(seqs))


def _ranked_population(n=10, seed=0):
    rng = np.random.default_rng(seed)
    pop = _population(seed, n)
    pop.set("F", rng.random((n, 4)), "rank", rng.integers(0, 3, n), "crowding", rng.random(n))
    return pop


def _run_operator(name, problem, rng):
    if name == "sampling":
        return sequences(CommandSampling().do(problem, 6, random_state=rng).get("X"))
    if name == "mutation":
        return sequences(CommandMutation(rate=0.3).do(problem, _population(), random_state=rng).get("X"))
    if name == "removal":
        return sequences(CommandRemoval(0.5, 0.5).do(problem, _population(), random_state=rng).get("X"))
    if name == "rearrangement":
        return sequences(CommandRearrangement(0.5).do(problem, _population(), random_state=rng).get("X"))
    if name == "crossover":
        parents = np.array([[0, 1], [2, 3], [4, 5]])
        return sequences(CommandCrossover().do(problem, _population(), parents, random_state=rng).get("X"))
    if name == "tournament":
        return [RankAndCrowdingTournament().do(problem, _ranked_population(), 5, n_parents=2, to_pop=False,
                                               random_state=rng).ravel()]
    if name == "survival":
        pop = _ranked_population()
        pop.set("idx", np.arange(len(pop)), "end", np.arange(len(pop)) % 2)
        return [GoalReachabilitySurvival().do(problem, pop, n_survive=4, random_state=rng).get("idx")]
    raise AssertionError(name)


OPERATOR_NAMES = ["sampling", "mutation", "removal", "rearrangement", "crossover", "tournament", "survival"]


@pytest.mark.parametrize("name", OPERATOR_NAMES)
def test_pymoo_operators_use_only_their_random_state(problem, name):
    np.random.seed(1234)
    reference = np.random.random(3)
    np.random.seed(1234)
    first = _run_operator(name, problem, np.random.default_rng(99))
    assert np.array_equal(np.random.random(3), reference)  # global state untouched
    second = _run_operator(name, problem, np.random.default_rng(99))
    assert same_lists(first, second)


@pytest.mark.parametrize("name", ["sampling", "mutation", "removal", "rearrangement", "crossover"])
def test_pymoo_operators_depend_on_the_seed(problem, name):
    outputs = [_run_operator(name, problem, np.random.default_rng(s)) for s in range(6)]
    assert any(not same_lists(outputs[0], o) for o in outputs[1:])


def test_pymoo_operators_keep_their_invariants(problem):
    pop = _population(3, 12)
    parents = sequences(pop.get("X"))
    rng = np.random.default_rng(4)
    def apply(operator):
        return sequences(operator.do(problem, Population.new("X", pop.get("X")), random_state=rng).get("X"))

    removed = apply(CommandRemoval(1.0, 0.5))
    assert [displacement(s) for s in removed] == [displacement(s) for s in parents]
    shuffled = apply(CommandRearrangement(1.0))
    assert [sorted(s.tolist()) for s in shuffled] == [sorted(s.tolist()) for s in parents]
    mutated = apply(CommandMutation(1.0))
    assert [len(s) for s in mutated] == [len(s) for s in parents]
    assert all(np.isin(s, problem.command_ids).all() for s in mutated)
    matings = np.array([[0, 1], [2, 3], [4, 5]])
    off = sequences(CommandCrossover().do(problem, pop, matings, random_state=rng).get("X"))
    assert len(off) == 6
    for k, (i, j) in enumerate(matings):  # pymoo lays out offspring as (first of every mating, second of every mating)
        pair = off[k].tolist() + off[k + len(matings)].tolist()
        assert Counter(pair) == Counter(parents[i].tolist() + parents[j].tolist())


@pytest.mark.parametrize("make, words", [
    (lambda: CommandMutation(rate=1.5), "mutation rate"),
    (lambda: CommandMutation(rate=-0.1), "mutation rate"),
    (lambda: CommandMutation(rate="0.1"), "mutation rate"),
    (lambda: CommandMutation(prob=2.0), "mutation prob"),
    (lambda: CommandRemoval(translation_rate=2.0), "removal translation_rate"),
    (lambda: CommandRemoval(other_rate=-1.0), "removal other_rate"),
    (lambda: CommandRemoval(prob=-1.0), "removal prob"),
    (lambda: CommandRearrangement(rate=1.01), "rearrangement rate"),
    (lambda: CommandRearrangement(prob=float("nan")), "rearrangement prob"),
    (lambda: CommandCrossover(prob=1.2), "crossover prob"),
    (lambda: CommandCrossover(max_genes=0), "max_genes"),
    (lambda: CommandCrossover(max_genes=2.0), "max_genes"),
    (lambda: CommandCrossover(max_genes=True), "max_genes"),
])
def test_operator_options_are_validated(make, words):
    with pytest.raises(ParameterError, match=words):
        make()


@pytest.mark.parametrize("operator", [CommandMutation(1.0, prob=0.0), CommandRemoval(1.0, 1.0, prob=0.0),
                                      CommandRearrangement(1.0, prob=0.0)])
def test_prob_zero_applies_an_operator_to_nobody(problem, operator):
    pop = _population(4, 12)
    before = sequences(pop.get("X"))
    after = sequences(operator.do(problem, Population.new("X", pop.get("X")),
                                  random_state=np.random.default_rng(0)).get("X"))
    assert same_lists(before, after)


def test_default_mutation_rate_is_one_over_max_length(problem):
    seqs = [np.full(50, command_id("sO"), dtype=np.int64)] * 40
    pop = Population.new("X", as_column(seqs))
    out = sequences(CommandMutation().do(problem, pop, random_state=np.random.default_rng(0)).get("X"))
    hits = sum(int((s != command_id("sO")).sum()) for s in out)
    # 2000 genes at rate 1/10, each redrawn among 13 commands (12/13 differ): mean ~185
    assert 130 < hits < 240


# --- repair -----------------------------------------------------------------------------------
def scalar_repair(sim, start_id, seqs, rng):
    """The repair one command at a time, from the simulator's pose table: at each step, for each live
    sequence in row order, a command leading to the dead pose is replaced by the ⌊u·n⌋-th of the n
    valid commands of the pose, in column order, u drawn from ``rng`` there and then."""
    column = {int(g): j for j, g in enumerate(sim.command_ids)}
    out = [[column[int(g)] for g in s] for s in seqs]
    poses = [start_id] * len(seqs)
    for t in range(max(map(len, out), default=0)):
        for r, genes in enumerate(out):
            if t >= len(genes) or poses[r] == sim.dead:
                continue
            after = int(sim.next[poses[r], genes[t]])
            if after == sim.dead:
                valid = [j for j in range(sim.n_commands) if sim.next[poses[r], j] != sim.dead]
                if valid:
                    genes[t] = valid[int(rng.random() * len(valid))]
                    after = int(sim.next[poses[r], genes[t]])
            poses[r] = after
    return [sim.command_ids[np.array(genes, dtype=np.int64)] for genes in out]


@pytest.mark.parametrize("seed", range(5))
def test_repair_matches_a_scalar_oracle(seed):
    # The batch repair (all sequences in lockstep, its draws taken from a buffer drawn ahead) draws
    # exactly what the scalar one draws and leaves the generator where it does: the recorded GA runs
    # depend on both bit for bit.
    rng = np.random.default_rng(seed)
    occupancy = rng.random((14, 14)) < 0.25
    occupancy[3:7, 3:7] = False
    problem = CommandPathProblem(Workspace(occupancy), Pose(4, 4, "O", 0), Pose(5, 4, "O", 0), max_length=30)
    seqs = [rng.choice(SEED_IDS, size=int(n)) for n in rng.integers(0, 60, size=40)]
    ours_rng, oracle_rng = np.random.default_rng(seed), np.random.default_rng(seed)
    ours = repair_and_shortcut(problem, copies(seqs), repair=ours_rng)
    oracle = scalar_repair(problem.simulator, problem.start_id, seqs, oracle_rng)
    assert same_lists(ours, oracle)
    assert ours_rng.random() == oracle_rng.random()
    assert sum(not np.array_equal(a, b) for a, b in zip(ours, seqs)) > 10  # the repair had work to do


# --- duplicate elimination --------------------------------------------------------------------
def test_duplicate_elimination():
    seqs = [parse_commands("x+,y+"), parse_commands("x+,y+"), parse_commands("y+,x+"), parse_commands("x+"),
            np.array([command_id("x+"), command_id("y+")], dtype=np.int32), np.empty(0, dtype=np.int64),
            np.empty(0, dtype=np.int64), parse_commands("x+,y+,x+")]
    pop = Population.new("X", as_column(seqs))
    kept = CommandDuplicateElimination().do(pop)
    assert [s.tolist() for s in sequences(kept.get("X"))] == [
        parse_commands("x+,y+").tolist(), parse_commands("y+,x+").tolist(), parse_commands("x+").tolist(), [],
        parse_commands("x+,y+,x+").tolist(),
    ]
    other = Population.new("X", as_column([parse_commands("y+,x+"), np.empty(0, dtype=np.int64)]))
    kept = CommandDuplicateElimination().do(pop, other)
    assert [s.tolist() for s in sequences(kept.get("X"))] == [
        parse_commands("x+,y+").tolist(), parse_commands("x+").tolist(), parse_commands("x+,y+,x+").tolist(),
    ]


@settings(max_examples=60, deadline=None)
@given(seqs=batches(SEED_IDS[:3], max_chromosomes=12, max_size=3))
def test_duplicate_elimination_keeps_one_of_each(seqs):
    pop = Population.new("X", as_column(seqs))
    kept = [tuple(s.tolist()) for s in sequences(CommandDuplicateElimination().do(pop).get("X"))]
    assert len(kept) == len(set(kept))
    assert set(kept) == {tuple(s.tolist()) for s in seqs}


# --- tournament -------------------------------------------------------------------------------
@settings(max_examples=100, deadline=None)
@given(data=st.data(), n=st.integers(1, 12), rows=st.integers(1, 10))
def test_tournament_picks_lowest_rank_then_largest_crowding(data, n, rows):
    ranks = np.array(data.draw(st.lists(st.integers(0, 3), min_size=n, max_size=n)))
    crowd = np.array(data.draw(st.lists(st.one_of(st.floats(0, 5), st.just(np.inf)), min_size=n, max_size=n)))
    P = np.array(data.draw(st.lists(st.lists(st.integers(0, n - 1), min_size=4, max_size=4), min_size=rows,
                                    max_size=rows)))
    pop = Population.new("X", as_column([[i] for i in range(n)]))
    pop.set("rank", ranks, "crowding", crowd)
    winners = rank_and_crowding_tournament(pop, P)
    assert winners.shape == (rows,)
    for row, w in zip(P, winners):
        assert w in row
        assert ranks[w] == ranks[row].min()
        assert crowd[w] == crowd[row][ranks[row] == ranks[row].min()].max()


def test_tournament_examples():
    pop = Population.new("X", as_column([[i] for i in range(4)]))
    pop.set("rank", np.array([1, 0, 0, 2]), "crowding", np.array([9.0, 0.5, 2.0, np.inf]))
    assert rank_and_crowding_tournament(pop, np.array([[0, 1, 2, 3], [3, 0, 0, 3], [2, 1, 3, 0]])).tolist() == [2, 0, 2]
    pop.set("crowding", np.array([9.0, np.inf, np.nan, 1.0]))  # nan crowding counts as 0
    assert rank_and_crowding_tournament(pop, np.array([[2, 1, 0, 3], [2, 3, 0, 2]])).tolist() == [1, 2]
    picks = RankAndCrowdingTournament(pressure=4).do(None, pop, 7, n_parents=2, to_pop=False,
                                                     random_state=np.random.default_rng(0))
    assert picks.shape == (7, 2) and set(picks.ravel().tolist()) <= {0, 1, 2, 3}


# --- survival ---------------------------------------------------------------------------------
LEVELS = [1.0, 0.5, 1 / 3, 0.25, 0.0]


def effective_levels(F, end, niche_size, levels=True):
    """The sections in order: with ``levels`` −f_gr (the reach levels, ours), else the paper's two (−1 for the goal-
    reaching individuals, 0 for the others); the unreached individuals beyond the ``niche_size`` best of their end
    pose after every section."""
    sections = F[:, 0].copy() if levels else np.where(F[:, 0] == -1.0, -1.0, 0.0)
    if niche_size:
        for e in np.unique(end):
            group = np.flatnonzero((end == e) & (F[:, 0] != -1.0))
            order = group[np.argsort(F[group, 1:].sum(axis=1), kind="stable")]
            sections[order[niche_size:]] += 2.0
    return sections


@pytest.mark.parametrize("levels", [False, True])
@pytest.mark.parametrize("niche_size", [0, 1, 3])
@settings(max_examples=60, deadline=None)
@given(data=st.data(), n=st.integers(1, 25), seed=seeds)
def test_goal_reachability_survival(niche_size, levels, data, n, seed):
    f_gr = np.array(data.draw(st.lists(st.sampled_from(LEVELS), min_size=n, max_size=n)))
    n_survive = data.draw(st.integers(1, n + 3))
    rng = np.random.default_rng(seed)
    # coarse values so that ties and dominance both occur, plus a tiny distinct jitter so that niches have no ties
    F = np.column_stack([-f_gr, -rng.integers(0, 4, (n, 3)) / 4 - np.arange(n)[:, None] * 1e-9])
    end = rng.integers(0, 3, n)
    pop = Population.new("X", as_column([[i] for i in range(n)]), "F", F)
    pop.set("idx", np.arange(n), "end", end)
    problem = Problem(n_var=1, n_obj=4)
    survivors = GoalReachabilitySurvival(niche_size=niche_size, levels=levels).do(problem, pop, n_survive=n_survive,
                                                                                 random_state=rng)
    assert len(survivors) == min(n, n_survive)
    idx = survivors.get("idx").astype(int)
    assert len(set(idx.tolist())) == len(idx)
    assert np.array_equal(survivors.get("F"), F[idx])
    rank, crowding = survivors.get("rank"), survivors.get("crowding")
    assert all(r is not None and int(r) >= 0 for r in rank)
    assert all(c is not None and not np.isnan(float(c)) for c in crowding)
    level = effective_levels(F, end, niche_size, levels)
    lost = np.setdiff1d(np.arange(n), idx)
    n_goal = int((f_gr == 1).sum())
    assert (f_gr[idx] == 1).sum() == min(n_goal, n_survive)  # individuals reaching the goal survive first
    if len(lost):  # then the higher f_gr levels (of individuals within their niche) before the lower
        assert level[idx].max() <= level[lost].min()
    rank = rank.astype(int)
    for a in range(len(idx)):
        for b in range(len(idx)):
            fa, fb = F[idx[a]], F[idx[b]]
            if level[idx[a]] < level[idx[b]]:
                assert rank[a] < rank[b]  # the sections' fronts are ranked in level order
            elif level[idx[a]] == level[idx[b]] and (fa <= fb).all() and (fa < fb).any():
                assert rank[a] < rank[b]  # within a section, a dominating individual ranks better
    assert rank.min() == 0


def test_survival_niching_example():
    # five unreached individuals on one end pose and one elsewhere, two goal-reaching ones: with niches of 2, the
    # three worst of the crowded pose fall behind the lone (and lower-f_gr) individual
    f = np.array([[1, 0.1, 0.1, 0.1], [1, 0.2, 0.2, 0.2], [0.5, 0.9, 0.9, 0.9], [0.5, 0.8, 0.8, 0.8],
                  [0.5, 0.7, 0.7, 0.7], [0.5, 0.6, 0.6, 0.6], [0.5, 0.5, 0.5, 0.5], [0.25, 0.1, 0.1, 0.1]])
    pop = Population.new("X", as_column([[i] for i in range(len(f))]), "F", -f)
    pop.set("idx", np.arange(len(f)), "end", np.array([9, 9, 4, 4, 4, 4, 4, 7]))
    problem = Problem(n_var=1, n_obj=4)
    kept = GoalReachabilitySurvival(niche_size=2).do(problem, pop, n_survive=5, random_state=np.random.default_rng(0))
    assert sorted(kept.get("idx").tolist()) == [0, 1, 2, 3, 7]
    kept = GoalReachabilitySurvival(niche_size=0).do(problem, pop, n_survive=5, random_state=np.random.default_rng(0))
    assert sorted(kept.get("idx").tolist()) == [0, 1, 2, 3, 4]


def test_survival_validates_niche_size():
    for bad in (-1, 1.5, True):
        with pytest.raises(ParameterError):
            GoalReachabilitySurvival(niche_size=bad)


def test_reaches_goal():
    F = -np.array([[1.0, 0.1, 0.1, 0.1], [0.999, 1, 1, 1], [0.5, 0, 0, 0]])
    assert reaches_goal(F).tolist() == [True, False, False]


@settings(max_examples=60, deadline=None)
@given(data=st.data(), n=st.integers(1, 30), seed=seeds, share=st.sampled_from([0.25, 0.5, 0.75, 1.0]))
def test_the_reaching_share_leaves_room_for_the_others(data, n, seed, share):
    f_gr = np.array(data.draw(st.lists(st.sampled_from(LEVELS), min_size=n, max_size=n)))
    n_survive = data.draw(st.integers(1, n + 3))
    rng = np.random.default_rng(seed)
    F = np.column_stack([-f_gr, -rng.integers(0, 4, (n, 3)) / 4 - np.arange(n)[:, None] * 1e-9])
    end = rng.integers(0, 3, n)
    survival = GoalReachabilitySurvival(reach_share=share)
    rows, rank, crowding = survival.sort(F, end, n_survive, random_state=rng)
    assert len(rows) == min(n, n_survive) and len(set(rows.tolist())) == len(rows)  # the population stays full
    n_goal, n_others = int((f_gr == 1).sum()), int((f_gr != 1).sum())
    kept_goal = int((f_gr[rows] == 1).sum())
    quota = max(int(share * n_survive), n_survive - n_others, 1)
    assert kept_goal == min(n_goal, quota, n_survive)  # at most the share while others can fill the rest
    reaching_first = f_gr[rows] == 1
    assert not (np.diff(reaching_first.astype(int)) > 0).any()  # the reaching section still ranks first
    assert (np.diff(rank) >= 0).all()


@pytest.mark.parametrize("share", [0, -0.5, 1.5, float("nan"), "all"])
def test_the_reaching_share_is_validated(share):
    with pytest.raises(ParameterError, match="reach_share"):
        GoalReachabilitySurvival(reach_share=share)
