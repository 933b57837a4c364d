"""Our additions to the hTetro-GA: the repairing simulation, the repair and shortcut operators."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from pymoo.core.population import Population

from htetro_opt.model import SEED000_COMMANDS, MovingObstacle, Pose, Simulator, Workspace, parse_commands
from htetro_opt.operators import (
    CommandRepair,
    CommandShortcut,
    as_column,
    cut_longest_loop,
    displacement,
    longest_loops,
    repair_and_shortcut,
    sequences,
)
from htetro_opt.problems import CommandPathProblem

SEED_IDS = parse_commands(",".join(SEED000_COMMANDS))


def cluttered(seed: int = 0, size: int = 12) -> Workspace:
    rng = np.random.default_rng(seed)
    occ = rng.random((size, size)) < 0.15
    occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = True
    occ[1:4, 1:4] = False
    occ[8:11, 8:11] = False
    return Workspace(occ)


@settings(max_examples=40, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
@given(seed=st.integers(0, 2**32 - 1), map_seed=st.integers(0, 20))
def test_repaired_sequences_are_valid_and_change_only_invalid_commands(seed, map_seed, successors):
    ws = cluttered(map_seed)
    sim = Simulator(ws)
    rng = np.random.default_rng(seed)
    seqs = [rng.choice(SEED_IDS, size=int(rng.integers(0, 40))) for _ in range(12)]
    start = Pose(2, 2, "O", 0)
    result = sim.run(seqs, start, repair=np.random.default_rng(seed))
    plain = sim.run([result.sequence(i) for i in range(len(seqs))], start)
    for i, original in enumerate(seqs):
        repaired = result.sequence(i)
        assert len(repaired) == len(original)
        if result.valid[i]:
            assert plain.valid[i] and plain.executed[i] == len(original)  # the repaired sequence runs whole
        # every changed command was invalid where it stood, and its replacement is valid there
        poses = plain.poses(i)
        tokens = [SEED000_COMMANDS[list(SEED_IDS).index(c)] for c in repaired]
        original_tokens = [SEED000_COMMANDS[list(SEED_IDS).index(c)] for c in original]
        for t in range(plain.executed[i]):
            here = tuple(int(v) for v in poses[t])
            valid_here = {tok for tok, _, _ in successors(ws, here, t, SEED000_COMMANDS)}
            assert tokens[t] in valid_here
            if tokens[t] != original_tokens[t]:
                assert original_tokens[t] not in valid_here


def test_repair_is_reproducible_and_leaves_valid_sequences_alone():
    sim = Simulator(cluttered(3))
    seqs = [np.random.default_rng(k).choice(SEED_IDS, size=30) for k in range(8)]
    a = sim.run(seqs, Pose(2, 2, "O", 0), repair=np.random.default_rng(7))
    b = sim.run(seqs, Pose(2, 2, "O", 0), repair=np.random.default_rng(7))
    assert all(np.array_equal(a.sequence(i), b.sequence(i)) for i in range(8))
    fine = [a.sequence(i)[: a.executed[i]] for i in range(8)]
    c = sim.run(fine, Pose(2, 2, "O", 0), repair=np.random.default_rng(99))
    assert all(np.array_equal(c.sequence(i), fine[i]) for i in range(8))


def test_repair_respects_moving_obstacles():
    occ = np.zeros((9, 9), dtype=bool)
    occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = True
    wall = MovingObstacle(cells=((6, 3),), route=((0, 0), (0, 1), (0, 2), (0, 1)), speed=1)
    ws = Workspace(occ, moving=(wall,))
    sim = Simulator(ws)
    seqs = [np.full(12, SEED_IDS[0])]  # x+ repeatedly into the moving block's lane
    for seed in range(10):
        result = sim.run(seqs, Pose(1, 3, "O", 0), repair=np.random.default_rng(seed))
        replay = sim.run([result.sequence(0)], Pose(1, 3, "O", 0))
        assert replay.executed[0] == result.executed[0]
        assert replay.valid[0] == result.valid[0]


def test_sequence_drops_the_padding():
    sim = Simulator(Workspace(np.zeros((6, 6), dtype=bool)))
    result = sim.run([parse_commands("x+"), parse_commands("x+,y+,x-")], Pose(1, 1, "O", 0))
    assert result.sequence(0).tolist() == parse_commands("x+").tolist()
    assert result.sequence(1).tolist() == parse_commands("x+,y+,x-").tolist()


def test_repair_operator_uses_the_problem_start_and_the_given_random_state():
    ws = cluttered(5)
    problem = CommandPathProblem(ws, Pose(2, 2, "O", 0), Pose(8, 8, "O", 0), max_length=30)
    seqs = [np.random.default_rng(k).choice(SEED_IDS, size=30) for k in range(10)]

    def repaired(seed):
        pop = Population.new("X", as_column(seqs))
        return sequences(CommandRepair().do(problem, pop, random_state=np.random.default_rng(seed)).get("X"))

    np.random.seed(0)
    reference = np.random.random()
    np.random.seed(0)
    first = repaired(1)
    assert np.random.random() == reference  # the global generator is untouched
    assert all(np.array_equal(a, b) for a, b in zip(first, repaired(1)))
    assert not all(np.array_equal(a, b) for a, b in zip(first, repaired(2)))  # the seed matters
    before = problem.simulator.run(seqs, problem.start_id)
    after = problem.simulator.run(first, problem.start_id)
    assert before.valid.sum() < 5 and after.valid.sum() > before.valid.sum() + 3


@pytest.mark.parametrize("trace,executed,expected", [
    ([1, 2, 3, 4], 3, None),
    ([1, 2, 1], 2, (0, 2)),
    ([5, 6, 7, 6, 5, 8], 5, (0, 4)),
    ([5, 6, 7, 6, 9, 8], 5, (1, 3)),
    ([5, 6, 7, 6, 9, 5], 3, (1, 3)),  # steps after `executed` are not part of the path
])
def test_cut_longest_loop(trace, executed, expected):
    assert cut_longest_loop(np.array(trace), executed) == expected


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**32 - 1))
def test_shortcut_keeps_the_end_pose_and_never_lengthens(seed):
    ws = cluttered(seed % 7)
    problem = CommandPathProblem(ws, Pose(2, 2, "O", 0), Pose(9, 9, "O", 0), max_length=40)
    rng = np.random.default_rng(seed)
    # valid walks that wander (repaired), so they hold loops
    walks = problem.simulator.run([rng.choice(SEED_IDS, size=40) for _ in range(10)], problem.start_id, repair=rng)
    X = as_column(walks.sequence(i)[: walks.executed[i]] for i in range(10))
    Y = CommandShortcut().do(problem, Population.new("X", X.copy()), random_state=rng).get("X")
    before = problem.simulate([x[0] for x in X])
    after = problem.simulate([y[0] for y in Y])
    for i in range(10):
        assert len(Y[i, 0]) <= len(X[i, 0])
        assert displacement(Y[i, 0]) == displacement(X[i, 0])
        assert after.valid[i]  # a static map: cutting a loop never breaks a path
        assert tuple(after.final[i]) == tuple(before.final[i])
        assert after.time[i] <= before.time[i]


@settings(max_examples=200, deadline=None)
@given(data=st.data())
def test_batch_loops_match_the_one_row_version(data):
    width = data.draw(st.integers(1, 16))
    rows = data.draw(st.lists(st.lists(st.integers(0, 4), min_size=width, max_size=width), min_size=1, max_size=4))
    trace = np.array(rows)
    executed = np.array([data.draw(st.integers(0, width - 1)) for _ in rows])
    cut_i, cut_j = longest_loops(trace, executed)
    for r in range(len(rows)):
        expected = cut_longest_loop(trace[r], int(executed[r]))
        assert (None if cut_i[r] == cut_j[r] else (int(cut_i[r]), int(cut_j[r]))) == expected


def test_repair_and_shortcut_share_one_simulation():
    problem = CommandPathProblem(cluttered(2), Pose(2, 2, "O", 0), Pose(9, 9, "O", 0), max_length=40)
    seqs = [np.random.default_rng(k).choice(SEED_IDS, size=40) for k in range(8)]
    assert all(a is b for a, b in zip(repair_and_shortcut(problem, seqs), seqs))  # nothing asked: unchanged
    both = repair_and_shortcut(problem, seqs, repair=np.random.default_rng(3), shortcut=4)
    repaired = repair_and_shortcut(problem, seqs, repair=np.random.default_rng(3))
    assert all(np.array_equal(a, b) for a, b in zip(both[4:], repaired[4:]))  # only the first 4 are cut
    cut = repair_and_shortcut(problem, repaired[:4], shortcut=4)
    assert all(np.array_equal(a, b) for a, b in zip(both[:4], cut))  # the loops are those of the repaired paths
    assert sum(len(a) < len(b) for a, b in zip(both[:4], repaired[:4])) > 0
