"""Windowed exact re-planning: keeps the start and the end pose, never slower, re-validates, and a
window holding a detour becomes the exact optimum between its ends (oracle: plan_exact). The static
search (an A*) finds scipy's Dijkstra time within any limit, by a path that replays in the simulator,
the same path for the same question. The reach repair: the repaired path reaches at its times, its
tail is the exact optimum from the pose kept."""

from __future__ import annotations

import random

import numpy as np
import pytest
from pymoo.core.population import Population
from scipy.sparse.csgraph import dijkstra

from htetro_opt.errors import ParameterError
from htetro_opt.model import (
    SEED000_COMMANDS,
    MovingObstacle,
    Pose,
    Simulator,
    Timing,
    Workspace,
    format_commands,
    parse_commands,
)
from htetro_opt.model.robot import STATE_NAMES
from htetro_opt.operators.commands import (
    CommandReachRepair,
    CommandReplan,
    TransitionGraph,
    as_column,
    reach_repair,
    replan_windows,
    sequences,
)
from htetro_opt.operators.commands.replan import _astar, _pop, _sift_up
from htetro_opt.problems import CommandPathProblem
from htetro_opt.scenarios import load_scenario
from htetro_opt.solvers.grid_paths import plan_exact

SEED_IDS = parse_commands(",".join(SEED000_COMMANDS))


def bordered(width=12, height=12):
    occ = np.zeros((height, width), dtype=bool)
    occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = True
    return occ


def cluttered(seed: int, size: int = 14) -> Workspace:
    rng = np.random.default_rng(seed)
    occ = rng.random((size, size)) < 0.12
    occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = True
    occ[1:4, 1:4] = False
    occ[size - 4 : size - 1, size - 4 : size - 1] = False
    return Workspace(occ)


def walk(problem, rng, n=12, length=60):
    """Random chromosomes, repaired so that they run their whole genes."""
    seqs = [rng.choice(SEED_IDS, size=length) for _ in range(n)]
    result = problem.simulator.run(seqs, problem.start_id, t0=problem.t0, repair=rng)
    return [result.sequence(i) for i in range(n)]


@pytest.mark.parametrize("map_seed", [0, 1, 2, 3])
@pytest.mark.parametrize("window", [1, 7, 40])
def test_keeps_start_and_end_pose_never_slower_and_revalidates(map_seed, window):
    ws = cluttered(map_seed)
    problem = CommandPathProblem(ws, Pose(2, 2, "O", 0), Pose(11, 11, "O", 0), max_length=30)
    seqs = walk(problem, np.random.default_rng(map_seed))
    before = problem.simulate(seqs)
    out = replan_windows(problem, seqs, window=window, random_state=np.random.default_rng(7))
    after = problem.simulate(out)
    changed = 0
    for k, (old, new) in enumerate(zip(seqs, out)):
        done, now = int(before.executed[k]), int(after.executed[k])
        assert after.valid[k] or not before.valid[k]
        assert np.array_equal(after.poses(k)[0], before.poses(k)[0])  # the start
        assert np.array_equal(after.poses(k)[-1], before.poses(k)[-1])  # the end pose
        assert after.time[k] <= before.time[k] + 1e-9
        assert np.array_equal(new[now:], old[done:])  # the genes after the executed part are kept
        changed += not np.array_equal(old, new)
    assert changed  # random walks hold detours: the test would pass vacuously otherwise


def test_a_window_holding_a_detour_becomes_the_exact_optimum():
    occ = bordered(14, 10)
    occ[1:6, 7] = True  # a wall from the bottom: the straight way is blocked, the way round is over it
    ws = Workspace(occ)
    start, goal = Pose(2, 2, "O", 0), Pose(11, 2, "O", 0)
    # up to the top, across, and down again: a detour of 4 extra cells up and 4 down
    detour = parse_commands(",".join(["y+"] * 6 + ["x+"] * 9 + ["y-"] * 6))
    problem = CommandPathProblem(ws, start, goal, max_length=30)
    assert problem.simulate([detour]).reached[0]
    [out] = replan_windows(problem, [detour], window=len(detour), random_state=np.random.default_rng(0))
    oracle = plan_exact(ws, [start, goal])
    result = problem.simulate([out])
    assert result.reached[0] and result.time[0] == oracle.time < problem.simulate([detour]).time[0]


def test_a_window_in_the_middle_is_replaced_by_the_exact_optimum_between_its_ends():
    ws = Workspace(bordered(14, 14))
    start, goal = Pose(3, 5, "O", 0), Pose(11, 5, "O", 0)
    # x+ x+, then a loop of rotations and shapeshifts, then on: any 6-command window inside it shortens it
    middle = "r+,sI,r-,sO,r+,r-"
    path = parse_commands("x+,x+," + middle + ",x+,x+,x+,x+,x+,x+")
    problem = CommandPathProblem(ws, start, goal, max_length=30)
    before = problem.simulate([path])
    assert before.reached[0] and before.executed[0] == len(path)
    shorter = 0
    for seed in range(5):
        rng = np.random.default_rng(seed)
        i = int(np.random.default_rng(seed).integers(0, len(path) - 6 + 1))  # the window replan draws
        [out] = replan_windows(problem, [path], window=6, random_state=rng)
        a, b = before.poses(0)[i], before.poses(0)[i + 6]
        pose_a, pose_b = (Pose(int(p[0]), int(p[1]), STATE_NAMES[int(p[2])], int(p[3])) for p in (a, b))
        oracle = plan_exact(ws, [pose_a, pose_b]).time
        window_time = float(Timing().durations()[path[i : i + 6]].sum())
        expected = before.time[0] - window_time + min(oracle, window_time)
        assert problem.simulate([out]).time[0] == pytest.approx(expected)
        shorter += expected < before.time[0]
    assert shorter


@pytest.mark.parametrize("map_seed", [0, 5])
def test_the_graph_gives_the_exact_planners_optimum_between_any_two_poses(map_seed):
    ws = cluttered(map_seed)
    sim = Simulator(ws)
    graph = TransitionGraph(sim)
    rng = np.random.default_rng(map_seed)
    free = [p for p in (Pose(int(x), int(y), s, int(h)) for x, y, s, h in
                        zip(rng.integers(1, 13, 60), rng.integers(1, 13, 60), rng.choice(list("IOLT"), 60),
                            rng.integers(0, 4, 60)))
            if not sim.pose_conflicts(sim.encode(p))]
    for a, b in zip(free[0::2], free[1::2]):
        oracle = plan_exact(ws, [a, b])
        found = graph.fastest(sim.encode(a), 0, sim.encode(b), 0, limit=1e9)
        if not oracle.reached:
            assert found == []
            continue
        [(commands, time)] = found
        check = sim.run([commands], a, roadmap=[b])
        assert check.valid[0] and check.reached[0] and time == check.time[0] == oracle.time


def moving_map():
    """A corridor crossed by a block that sweeps it up and down: the static optimum runs into it."""
    occ = bordered(14, 10)
    occ[8:, :] = True
    up, down = tuple((0, k) for k in range(6)), tuple((0, k) for k in range(4, 0, -1))
    return Workspace(occ, moving=(MovingObstacle(cells=((7, 1),), route=up + down, speed=1),))


def test_with_moving_obstacles_the_result_revalidates_and_timed_is_the_exact_optimum():
    ws = moving_map()
    start, goal = Pose(5, 2, "O", 0), Pose(11, 2, "O", 0)
    problem = CommandPathProblem(ws, start, goal, max_length=30)
    oracle = plan_exact(ws, [start, goal])
    static = plan_exact(Workspace(ws.occupancy), [start, goal])
    assert oracle.reached and static.time < oracle.time  # the obstacles make the static optimum wait
    # the oracle's plan after ten waits (do-nothing shapeshifts) at the start
    slow = np.concatenate([parse_commands(",".join(["sO"] * 10)), oracle.commands])
    slow_result = problem.simulate([slow])
    assert slow_result.reached[0]
    [plain] = replan_windows(problem, [slow], window=len(slow), random_state=np.random.default_rng(0))
    [timed] = replan_windows(problem, [slow], window=len(slow), random_state=np.random.default_rng(0), timed=True)
    for out in (plain, timed):
        result = problem.simulate([out])
        assert result.valid[0] and result.reached[0] and result.time[0] <= slow_result.time[0]
    assert problem.simulate([timed]).time[0] == oracle.time


def as_pose(row) -> Pose:
    return Pose(int(row[0]), int(row[1]), STATE_NAMES[int(row[2])], int(row[3]))


@pytest.mark.parametrize("name", ["parallel_dynamic", "perpendicular_dynamic"])
def test_the_timed_search_is_the_exact_planners_optimum_valid_at_its_times(name):
    # oracle: plan_exact's time-expanded Dijkstra from the window's start time; windows between poses
    # of the exact plan of a bundled moving-obstacle map (Cheng et al. 2020), started at their own times
    scenario = load_scenario(name)
    sim = Simulator(scenario.workspace)
    graph = TransitionGraph(sim)
    plan = plan_exact(sim, scenario.roadmap)
    trace = sim.run([plan.commands], scenario.roadmap[0]).poses(0)
    period = scenario.workspace.period
    rng = np.random.default_rng(3)
    waited = 0
    for _ in range(12):
        i = int(rng.integers(0, len(trace) - 2))
        j = int(rng.integers(i + 1, min(len(trace), i + 41)))
        a, b = as_pose(trace[i]), as_pose(trace[j])
        oracle = plan_exact(sim, [a, b], t0=i)
        [(commands, time)] = graph.fastest(sim.encode(a), i, sim.encode(b), j, limit=200.0)
        check = sim.run([commands], a, roadmap=[b], t0=i)  # valid at the times it runs
        assert check.valid[0] and check.reached[0] and time == check.time[0] == oracle.time
        # arriving at another phase than the fastest may need waits: still valid, never faster
        shift = int(rng.integers(1, 6))
        same = graph.fastest(sim.encode(a), i, sim.encode(b), j + shift, limit=200.0, same_phase=True)
        if same:
            [(later, later_time)] = same
            check = sim.run([later], a, roadmap=[b], t0=i)
            assert check.valid[0] and check.reached[0] and check.time[0] == later_time >= time
            assert (i + len(later)) % period == (j + shift) % period
            waited += 1
    assert waited


def pocket_map() -> Workspace:
    """The corridor of ``moving_map`` with its moving block walled off in a pocket it never leaves."""
    occ = bordered(14, 12)
    occ[8, :] = True  # the pocket: rows 9-10, out of the robot's reach
    route = tuple((k, 0) for k in range(5)) + tuple((k, 0) for k in range(3, 0, -1))
    return Workspace(occ, moving=(MovingObstacle(cells=((3, 9),), route=route, speed=1),))


def test_the_timed_search_equals_the_static_search_where_the_obstacles_never_come():
    ws = pocket_map()
    sim, static = Simulator(ws), Simulator(Workspace(ws.occupancy))
    timed_graph, static_graph = TransitionGraph(sim), TransitionGraph(static)
    assert timed_graph.period > 1  # the time-expanded search runs
    rng = np.random.default_rng(0)
    found = 0
    for _ in range(20):
        a = Pose(int(rng.integers(2, 11)), int(rng.integers(2, 6)), str(rng.choice(list("OSZT"))), int(rng.integers(4)))
        b = Pose(int(rng.integers(2, 11)), int(rng.integers(2, 6)), str(rng.choice(list("OSZT"))), int(rng.integers(4)))
        if sim.pose_conflicts(sim.encode(a), 0) or sim.pose_conflicts(sim.encode(b), 0) or a == b:
            continue
        t = int(rng.integers(0, 40))
        timed = timed_graph.fastest(sim.encode(a), t, sim.encode(b), t, limit=60.0)
        plain = static_graph.fastest(static.encode(a), 0, static.encode(b), 0, limit=60.0)
        assert [time for _, time in timed] == [time for _, time in plain]
        found += len(timed)
    assert found


@pytest.mark.parametrize("seed", range(3))
def test_on_a_moving_map_windows_stay_valid_at_their_times_and_never_get_longer(seed):
    ws = moving_map()
    problem = CommandPathProblem(ws, Pose(5, 2, "O", 0), Pose(11, 2, "O", 0), max_length=40)
    rng = np.random.default_rng(seed)
    seqs = walk(problem, rng, n=10, length=40)
    before = problem.simulate(seqs)
    out = replan_windows(problem, seqs, window=12, random_state=np.random.default_rng(seed))
    # The executed part is what is re-planned; the genes after it are kept, and on a moving map they
    # may run differently at the new times, so the executed part is checked alone.
    executed = [out[k][: len(out[k]) - (len(seqs[k]) - int(before.executed[k]))] for k in range(len(seqs))]
    after = problem.simulator.run(executed, problem.start_id, t0=problem.t0)
    shorter = 0
    for k in range(len(seqs)):
        assert np.array_equal(out[k][len(executed[k]):], seqs[k][int(before.executed[k]):])
        assert after.valid[k]  # valid at the times it runs
        assert np.array_equal(after.poses(k)[-1], before.poses(k)[-1])
        assert after.time[k] <= before.time[k] + 1e-9
        shorter += after.time[k] < before.time[k] - 1e-9
    assert shorter  # random walks hold detours: not vacuous


def test_random_state_reproducibility_and_global_rng_untouched():
    ws = cluttered(3)
    problem = CommandPathProblem(ws, Pose(2, 2, "O", 0), Pose(11, 11, "O", 0), max_length=30)
    seqs = walk(problem, np.random.default_rng(3))
    np.random.seed(123)
    random.seed(123)
    numpy_state, python_state = np.random.get_state(), random.getstate()
    a = replan_windows(problem, seqs, window=10, random_state=np.random.default_rng(5))
    b = replan_windows(problem, seqs, window=10, random_state=np.random.default_rng(5))
    c = replan_windows(problem, seqs, window=10, random_state=np.random.default_rng(6))
    assert all(np.array_equal(x, y) for x, y in zip(a, b))
    assert not all(np.array_equal(x, y) for x, y in zip(a, c))  # the seed draws the windows
    after = np.random.get_state()
    assert after[0] == numpy_state[0] and np.array_equal(after[1], numpy_state[1]) and after[2:] == numpy_state[2:]
    assert random.getstate() == python_state


def test_operator_uses_the_problem_and_the_given_random_state_and_builds_its_graph_once():
    ws = cluttered(1)
    problem = CommandPathProblem(ws, Pose(2, 2, "O", 0), Pose(11, 11, "O", 0), max_length=30)
    seqs = walk(problem, np.random.default_rng(1), n=6)
    operator = CommandReplan(12)
    pop = operator.do(problem, Population.new("X", np.array(seqs + [None], dtype=object)[:-1, None]),
                      random_state=np.random.default_rng(2))
    expected = replan_windows(problem, seqs, window=12, random_state=np.random.default_rng(2))
    assert all(np.array_equal(x, y) for x, y in zip(sequences(pop.get("X")), expected))
    assert operator.graph(problem.simulator) is operator.graph(problem.simulator)


@pytest.mark.parametrize("window", [0, -3, 2.5, True, None])
def test_bad_windows(window):
    with pytest.raises(ParameterError, match="replan window"):
        CommandReplan(window)
    problem = CommandPathProblem(Workspace(bordered()), Pose(2, 2, "O", 0), Pose(6, 2, "O", 0), max_length=10)
    with pytest.raises(ParameterError, match="replan window"):
        replan_windows(problem, [parse_commands("x+")], window=window, random_state=np.random.default_rng(0))


# --- the reach repair (ours) ------------------------------------------------------------------------
def check_reach_repair(problem, seqs, out):
    """Each output reaches the goal (re-simulated from the start at its times), keeps a prefix of its
    input's executed commands and, after it, is the exact planner's optimum from that pose at that
    time; none beats the exact optimum from the start. Returns how many were repaired."""
    sim = problem.simulator
    before, after = problem.simulate(seqs), problem.simulate(out)
    optimum = plan_exact(sim, [problem.start, problem.goal], t0=problem.t0).time
    repaired = 0
    for k, (old, new) in enumerate(zip(seqs, out)):
        if before.reached[k]:
            assert new is old
            continue
        if new is old:
            continue
        repaired += 1
        run = sim.run([new], problem.start_id, roadmap=[problem.goal], t0=problem.t0)  # no stop: all of it runs
        assert run.valid[0] and run.reached[0] and after.executed[k] == len(new)
        assert problem.t_max + 1e-9 >= after.time[k] >= optimum - 1e-9
        trace = before.poses(k)
        common = next((i for i in range(min(len(old), len(new))) if old[i] != new[i]), min(len(old), len(new)))
        common = min(common, int(before.executed[k]))
        tail = float(problem.durations[new].sum())

        def exact_from(i, trace=trace):  # this member's poses, bound now
            return plan_exact(sim, [as_pose(trace[i]), problem.goal], t0=problem.t0 + i).time

        assert any(abs(tail - float(problem.durations[new[:i]].sum()) - exact_from(i)) < 1e-9
                   for i in range(common, -1, -1))
    return repaired


@pytest.mark.parametrize("seed", range(3))
def test_reach_repair_on_a_moving_map_reaches_at_its_times_and_never_beats_the_optimum(seed):
    # oracle: plan_exact's time-expanded search from the pose kept, at its time, and from the start
    scenario = load_scenario("parallel_dynamic")
    sim = Simulator(scenario.workspace)
    start, goal = scenario.roadmap[0], scenario.roadmap[1]
    problem = CommandPathProblem(sim, start, goal, max_length=100)
    seqs = walk(problem, np.random.default_rng(seed), n=6, length=30)
    assert not problem.simulate(seqs).reached.any()
    out = reach_repair(problem, seqs)
    assert check_reach_repair(problem, seqs, out) == len(seqs)
    assert [s.tolist() for s in reach_repair(problem, seqs)] == [s.tolist() for s in out]  # deterministic


def test_reach_repair_on_a_static_map_and_members_that_reach_are_left_alone():
    ws = cluttered(1)
    problem = CommandPathProblem(ws, Pose(2, 2, "O", 0), Pose(11, 11, "O", 0), max_length=40)
    optimum = plan_exact(ws, [problem.start, problem.goal])
    seqs = walk(problem, np.random.default_rng(5), n=8, length=25) + [optimum.commands]
    out = reach_repair(problem, seqs)
    assert check_reach_repair(problem, seqs, out) == 8
    assert out[-1] is seqs[-1]


def test_reach_repair_keeps_what_it_cannot_repair_within_t_max():
    # t_max = 4 s: the goal 9 cells away cannot be reached within it, whatever the pose kept
    problem = CommandPathProblem(Workspace(bordered(14, 6)), Pose(2, 2, "O", 0), Pose(11, 2, "O", 0), max_length=4)
    seqs = [parse_commands("x+,x+,x+"), parse_commands("y+")]
    out = reach_repair(problem, seqs)
    assert all(new is old for new, old in zip(out, seqs))
    # with a budget that allows it, the path is repaired from its last pose
    roomy = CommandPathProblem(problem.simulator, problem.start, problem.goal, max_length=12)
    [first, _] = reach_repair(roomy, seqs)
    assert format_commands(first) == ["x+"] * 9


def test_reach_repair_operator_draws_nothing_but_pymoos_prob_and_builds_its_graph_once():
    problem = CommandPathProblem(cluttered(2), Pose(2, 2, "O", 0), Pose(11, 11, "O", 0), max_length=40)
    seqs = walk(problem, np.random.default_rng(1), n=4, length=20)
    op = CommandReachRepair()
    state = random.getstate()
    pop = op.do(problem, Population.new("X", as_column(seqs)), random_state=np.random.default_rng(0))
    assert random.getstate() == state
    assert [s.tolist() for s in sequences(pop.get("X"))] == [s.tolist() for s in reach_repair(problem, seqs)]
    graph = op.graph(problem.simulator)
    op.do(problem, Population.new("X", as_column(seqs)), random_state=np.random.default_rng(1))
    assert op.graph(problem.simulator) is graph
    with pytest.raises(ParameterError, match="tries"):
        CommandReachRepair(tries=0)


# --- the static search (an A*) against scipy's Dijkstra ------------------------------------------------
def static_questions(sim, rng, n):
    """``n`` (source, target, limit) questions between collision-free poses: half of the targets drawn
    among the poses scipy's Dijkstra reaches within the limit (so most have an answer), half anywhere
    (so many have none)."""
    matrix = TransitionGraph(sim)._graph()[0]
    free = np.array([p for p in rng.choice(sim.n_poses, 4 * n, replace=False) if not sim.pose_conflicts(int(p))])
    questions = []
    for k in range(n):
        source, limit = int(free[k % len(free)]), float(rng.integers(1, 61))
        reached = np.flatnonzero(np.isfinite(dijkstra(matrix, indices=source, limit=limit)))
        target = int(rng.choice(reached)) if k % 2 else int(rng.choice(free))
        questions.append((source, target, limit))
    return questions


@pytest.mark.parametrize("name", ["three_slit", "random", "h_shape"])
def test_the_static_search_finds_scipys_dijkstra_time_and_a_path_that_replays_in_it(name):
    # oracle: scipy's Dijkstra bounded by the same limit (inf: no path within it); the path found is
    # replayed in the simulator from the source, and must end on the target in exactly that time
    sim = Simulator(load_scenario(name).workspace, commands=SEED000_COMMANDS)
    graph, matrix = TransitionGraph(sim), TransitionGraph(sim)._graph()[0]
    rng = np.random.default_rng(len(name))
    answered = unanswered = 0
    for source, target, limit in static_questions(sim, rng, 80):
        oracle = dijkstra(matrix, indices=source, limit=limit)[target]
        found = graph.fastest(source, 0, target, 0, limit=limit)
        if not np.isfinite(oracle):
            assert found == []
            unanswered += 1
            continue
        [(commands, time)] = found
        run = sim.run([commands], source)
        assert time == oracle  # integer durations: exact
        assert run.valid[0] and run.executed[0] == len(commands)
        assert run.trace[0, len(commands)] == target and run.time[0] == time
        answered += 1
    assert answered >= 30 and unanswered >= 5  # both kinds of question were asked


def test_the_static_search_is_exact_with_diagonals_and_with_the_block_commands():
    # the heuristic is derived from the commands: diagonals move two cells of grid distance in √2 s
    # (0.707 s a cell), Cheng et al. 2019's block commands turn through intermediate states
    ws = load_scenario("spiral").workspace
    blocks = list(SEED000_COMMANDS) + ["1l", "1r", "3l", "3r"]
    for sim in (Simulator(ws, diagonals=True), Simulator(ws, commands=blocks)):
        graph, matrix = TransitionGraph(sim), TransitionGraph(sim)._graph()[0]
        answered = 0
        for source, target, limit in static_questions(sim, np.random.default_rng(4), 40):
            oracle = dijkstra(matrix, indices=source, limit=limit)[target]
            found = graph.fastest(source, 0, target, 0, limit=limit)
            assert bool(found) == bool(np.isfinite(oracle))
            if found:
                [(commands, time)] = found
                run = sim.run([commands], source)
                # √2 sums in another order, or over another path as fast: equal up to rounding
                assert time == pytest.approx(oracle, rel=1e-12, abs=1e-12)
                assert run.valid[0] and run.trace[0, len(commands)] == target and run.time[0] == pytest.approx(time)
                answered += 1
        assert answered >= 10


@pytest.mark.parametrize("options", [{"commands": SEED000_COMMANDS}, {"diagonals": True}])
def test_the_static_searchs_heuristic_is_a_consistent_lower_bound(options):
    # oracle: scipy's Dijkstra on the reversed graph, the exact time from every pose to the target
    sim = Simulator(load_scenario("three_slit").workspace, **options)
    graph = TransitionGraph(sim)
    matrix = graph._graph()[0]
    cell_time, turn_time = graph._heuristic()
    width, cells = sim.workspace.width, sim.workspace.width * sim.workspace.height
    poses = np.arange(sim.n_poses)
    tails = np.repeat(poses, np.diff(matrix.indptr))
    for target in np.random.default_rng(1).choice(sim.n_poses, 6, replace=False):
        c, t = poses % cells, int(target) % cells
        h = (np.abs(c % width - t % width) + np.abs(c // width - t // width)) * cell_time \
            + turn_time[int(target) // cells, poses // cells]
        exact = dijkstra(matrix.T.tocsr(), indices=int(target))
        assert h[target] == 0 and (h <= exact + 1e-12).all()
        assert (h[tails] <= matrix.data + h[matrix.indices] + 1e-12).all()  # consistent along every edge


def test_the_static_search_is_deterministic_and_leaves_its_arrays_as_it_found_them():
    sim = Simulator(load_scenario("three_slit").workspace, commands=SEED000_COMMANDS)
    graph = TransitionGraph(sim)
    questions = static_questions(sim, np.random.default_rng(9), 30)
    first = [graph._static_search(s, t, limit) for s, t, limit in questions]  # not remembered: searched
    again = [graph._static_search(s, t, limit) for s, t, limit in reversed(questions)][::-1]
    fresh = [TransitionGraph(sim).fastest(s, 0, t, 0, limit=limit) for s, t, limit in questions]
    for a, b, c in zip(first, again, fresh):
        assert [(p.tolist(), time) for p, time in a] == [(p.tolist(), time) for p, time in b] \
            == [(p.tolist(), time) for p, time in c]
    assert sum(map(len, first)) >= 10
    arrays = graph._search_arrays()
    assert np.isinf(arrays["best"]).all() and (arrays["position"] == -1).all()


def test_the_compiled_static_search_gives_what_its_python_version_gives():
    sim = Simulator(cluttered(3))
    graph = TransitionGraph(sim)
    answered = 0
    for source, target, limit in static_questions(sim, np.random.default_rng(2), 12):
        answers = []
        for search in (_astar, _astar.py_func):
            time, count = search(*graph._astar_arguments(source, target, limit))
            answers.append((time, graph._search_arrays()["path"][:count].tolist()))
        assert answers[0] == answers[1]
        answered += np.isfinite(answers[0][0])
    assert answered


def test_of_equally_fast_paths_the_static_search_takes_one_with_few_command_changes():
    # on an open map every monotone staircase between two O poses is as fast: the one found is an L
    # (one change when both coordinates differ, none when one does), the fewest possible
    sim = Simulator(Workspace(bordered(14, 14)))
    graph = TransitionGraph(sim)
    rng = np.random.default_rng(0)
    for _ in range(100):
        a, b = (Pose(int(rng.integers(2, 12)), int(rng.integers(2, 12)), "O", 0) for _ in range(2))
        [(commands, time)] = graph.fastest(sim.encode(a), 0, sim.encode(b), 0, limit=100.0)
        assert time == abs(a.x - b.x) + abs(a.y - b.y)
        assert int((commands[1:] != commands[:-1]).sum()) == int(a.x != b.x and a.y != b.y)


def test_the_static_searchs_heap_pops_in_the_order_of_its_keys():
    # oracle: Python's sort by (time + heuristic, changes, -time, pose); keys drawn from a few values so
    # that most comparisons tie on the first ones, some keys lowered in place, a few poses popped and
    # pushed again (as the search does when a label improves after its expansion)
    rng = np.random.default_rng(5)
    n = 300
    heap, position = np.empty(n, dtype=np.int64), np.full(n, -1, dtype=np.int64)
    heap_key, heap_changes, heap_time = np.empty(n), np.empty(n, dtype=np.int64), np.empty(n)
    keys, size, popped, again = {}, 0, [], 0

    def push(node, key):
        nonlocal size
        keys[node] = key
        if position[node] < 0:
            size += 1
            _sift_up(heap, heap_key, heap_changes, heap_time, position, size - 1, node, *key)
        else:
            _sift_up(heap, heap_key, heap_changes, heap_time, position, int(position[node]), node, *key)

    def order(node):
        key, changes, time = keys[node]
        return key, changes, -time, node

    for node in rng.permutation(n)[:200]:
        push(int(node), (float(rng.integers(20, 24)), int(rng.integers(0, 4)), float(rng.integers(0, 6))))
    for node in [m for m in keys if rng.random() < 0.3]:  # lowered in place: a smaller time + heuristic
        key, changes, time = keys[node]
        push(node, (key - 1.0, changes, time))
    while size:
        assert heap[0] == min(keys, key=order)
        node = int(heap[0])
        size = _pop(heap, heap_key, heap_changes, heap_time, position, size)
        popped.append(node)
        del keys[node]
        if len(popped) % 40 == 0:
            push(node, (19.0, 0, 0.0))  # back on the heap, now first
            again += 1
    assert (position == -1).all() and len(popped) == 200 + again and again >= 4
