"""The balanced polish: a path of at most W commands polished reaches the exact maximum of the fitness
sum (plan_max_fitness_sum, an independent search); a polished path replays in the simulator, keeps its
start, ends on the goal, never sums less and never more than the maximum; the shared programme's
kernels stay where the exact maximiser finds them; bad input is refused by name."""

import numpy as np
import pytest

from htetro_opt.errors import ParameterError
from htetro_opt.model import (
    SEED000_COMMANDS,
    MovingObstacle,
    Pose,
    Simulator,
    Workspace,
    parse_commands,
)
from htetro_opt.operators.commands import fitness_sum, polish_sum
from htetro_opt.problems import CommandPathProblem
from htetro_opt.scenarios import load_scenario
from htetro_opt.solvers.grid_paths import plan_exact, plan_max_fitness_sum

TOLERANCE = 1e-9


def _static(shape, blocked):
    occupancy = np.zeros(shape, dtype=bool)
    for x, y in blocked:
        occupancy[y, x] = True
    return Workspace(occupancy)


def _crossing():
    """A two-row corridor (y = 3, 4) crossed at x = 4 by an obstacle patrolling the column x = 4 from
    y = 0 to 7 (period 14), as in the exact maximiser's tests."""
    occupancy = np.ones((8, 8), dtype=bool)
    occupancy[3:5, :] = False
    occupancy[:, 4] = False
    return Workspace(occupancy, moving=(MovingObstacle(np.array([[4, 0]]), np.array([[0, 7]])),))


# (workspace, start, goal, max_length, t0)
CASES = {
    "6x6 one obstacle": (_static((6, 6), [(3, 2)]), Pose(1, 1, "O", 0), Pose(3, 4, "O", 0), 6, 0),
    "8x8 two obstacles": (_static((8, 8), [(3, 2), (5, 5)]), Pose(1, 1, "O", 0), Pose(6, 5, "O", 0), 12, 0),
    "moving, waits": (_crossing(), Pose(1, 4, "O", 0), Pose(6, 4, "O", 0), 1, 0),
    "moving, at t0 5": (_crossing(), Pose(1, 4, "O", 0), Pose(6, 4, "O", 0), 12, 5),
}


@pytest.fixture(scope="module")
def legs():
    """Per case: the problem, the leg's exact maximum S* and a few goal-reaching paths of the GA's
    kind (random commands, repaired as the hTetro-GA repairs its offspring, cut at the goal)."""
    made = {}
    rng = np.random.default_rng(7)
    for name, (workspace, start, goal, max_length, t0) in CASES.items():
        sim = Simulator(workspace, commands=SEED000_COMMANDS)
        problem = CommandPathProblem(sim, start, goal, max_length=max_length, t0=t0)
        best = plan_max_fitness_sum(sim, start, goal, max_length=max_length, t0=t0).info["fitness_sum"]
        genes = rng.choice(problem.command_ids, size=(4000, 30))
        result = problem.simulate(list(genes), repair=rng)
        reaching = np.flatnonzero(result.reached)[:6]
        paths = [result.prefix(i) for i in reaching] + [plan_exact(sim, [start, goal], t0=t0).commands]
        made[name] = (problem, best, paths)
    return made


def _check_polished(problem, before, after, best):
    """The polished path replays (every command valid), starts at the leg's start (the problem runs
    it from there), ends on the goal, sums no less than before and no more than the maximum."""
    result = problem.simulate([after])
    assert result.reached[0] and result.executed[0] == len(after)
    assert result.trace[0, 0] == problem.start_id and result.final_pose(0) == problem.goal
    total = float(problem.fitness(result)[0].sum())
    assert total >= fitness_sum(problem, before)[0] - TOLERANCE
    assert total <= best + TOLERANCE
    return total


@pytest.mark.parametrize("case", list(CASES))
def test_a_path_within_the_window_is_polished_to_the_exact_maximum(case, legs):
    problem, best, paths = legs[case]
    assert len(paths) >= 2
    for path in paths:
        assert len(path) <= 40
        total = _check_polished(problem, path, polish_sum(problem, path, window=40), best)
        assert total == pytest.approx(best, abs=TOLERANCE), (case, path.tolist())


@pytest.mark.parametrize("case", list(CASES))
@pytest.mark.parametrize("window", [2, 3, 5])
def test_small_windows_never_lose_and_never_beat_the_maximum(case, window, legs):
    problem, best, paths = legs[case]
    gained = 0
    for path in paths:
        polished = polish_sum(problem, path, window=window)
        total = _check_polished(problem, path, polished, best)
        gained += total > fitness_sum(problem, path)[0] + TOLERANCE
        assert (polished is path) == (total <= fitness_sum(problem, path)[0] + TOLERANCE)  # the input when unchanged
    if case == "6x6 one obstacle" and window == 5:
        assert gained  # random paths have windows to improve


@pytest.mark.parametrize("name, leg", [("h_shape", 0), ("perpendicular_dynamic", 1)])
def test_bundled_map_windows_replay_and_reach_at_most_the_maximum(name, leg):
    """A detour (the minimum-time plan with a loop x+, x− at its middle) on a bundled map, polished
    with windows shorter than the path: valid, better, at most S*; with W above its length: S*."""
    scenario = load_scenario(name)
    sim = Simulator(scenario.workspace, commands=SEED000_COMMANDS)
    start, goal = scenario.roadmap[leg], scenario.roadmap[leg + 1]
    t0 = sum(len(plan_exact(sim, scenario.roadmap[k: k + 2]).commands) for k in range(leg))
    exact = plan_exact(sim, [start, goal], t0=t0).commands
    middle = len(exact) // 2
    problem = CommandPathProblem(sim, start, goal, max_length=100, t0=t0)
    for loop in ("x+,x-", "y+,y-", "x-,x+", "y-,y+"):
        detour = np.r_[exact[:middle], parse_commands(loop), exact[middle:]]
        if fitness_sum(problem, detour)[1] and problem.simulate([detour]).executed[0] == len(detour):
            break
    else:
        pytest.fail("no loop fits at the middle of the plan")
    best = plan_max_fitness_sum(sim, start, goal, max_length=100, t0=t0).info["fitness_sum"]
    windowed = polish_sum(problem, detour, window=8)
    assert _check_polished(problem, detour, windowed, best) > fitness_sum(problem, detour)[0]
    assert _check_polished(problem, detour, polish_sum(problem, detour, window=60), best) == pytest.approx(
        best, abs=TOLERANCE)


def test_deterministic_and_the_input_back_when_nothing_to_do(legs):
    problem, _, paths = legs["8x8 two obstacles"]
    path = paths[0]
    first, second = polish_sum(problem, path, window=4), polish_sum(problem, path, window=4)
    assert first.tolist() == second.tolist()
    assert polish_sum(problem, path, window=0) is path
    missing = parse_commands("x-")  # does not reach the goal
    assert polish_sum(problem, missing) is missing
    optimum = polish_sum(problem, path)  # S*: polishing again finds nothing
    assert polish_sum(problem, optimum) is optimum


def test_a_deadline_already_passed_stops_the_polish_before_any_window(legs):
    """A run's time limit bounds the polish: with its deadline in the past (0, a ``perf_counter`` value
    no run reaches again) no window length is tried and the input comes back, though the same path
    polishes to a larger sum without one."""
    problem, _, paths = legs["6x6 one obstacle"]
    improvable = [path for path in paths if polish_sum(problem, path, window=40) is not path]
    assert improvable
    for path in improvable:
        assert polish_sum(problem, path, window=40, deadline=0.0) is path
        assert polish_sum(problem, path, window=2, deadline=0.0) is path


@pytest.mark.parametrize("keyword, value, match", [
    ("window", -1, "polish_window"), ("window", 2.5, "polish_window"), ("span", -1, "span"),
    ("max_rounds", 0, "max_rounds"),
])
def test_bad_options_are_refused_by_name(keyword, value, match, legs):
    problem, _, paths = legs["6x6 one obstacle"]
    with pytest.raises(ParameterError, match=match):
        polish_sum(problem, paths[0], **{keyword: value})
    with pytest.raises(ParameterError, match="CommandPathProblem"):
        polish_sum(problem.simulator, paths[0])


def test_the_exact_maximiser_uses_the_shared_programme():
    from htetro_opt.operators.commands import _sum_dp
    from htetro_opt.solvers.grid_paths import _fitness_sum

    assert _fitness_sum.min_bracket is _sum_dp.min_bracket and _fitness_sum.first_arrivals is _sum_dp.first_arrivals


def test_the_programme_leaves_its_tables_as_it_found_them():
    """min_bracket resets only the rows it touched: on shared tables, a sequence of questions gets the
    answers each gets on fresh tables, and the tables end all inf (the contract of both callers)."""
    from htetro_opt.operators.commands._sum_dp import backward_steps, min_bracket, reverse_graph, usable_table

    scenario = load_scenario("h_shape")
    problem = CommandPathProblem(scenario.workspace, scenario.start, scenario.goal, max_length=100)
    sim = problem.simulator
    n, c = sim.n_poses, sim.n_commands
    target = np.ascontiguousarray(sim.next[:n, :c])
    usable = usable_table(sim)
    durations = np.ascontiguousarray(sim.durations[:c], dtype=np.float64)
    danger = np.ascontiguousarray(problem._pose_danger[:n])
    indptr, indices = reverse_graph(target, usable)
    exact = plan_exact(sim, [problem.start, problem.goal])
    run = problem.simulate([exact.commands])
    poses = (run.keys[: len(exact.commands) + 1, 0] // sim.n_columns).tolist()  # pose ids along the optimum

    def tables():
        return (np.full((n, c), np.inf), np.full((n, c), np.inf), np.zeros(n, dtype=np.int64),
                np.zeros(n, dtype=np.int64), np.zeros(n, dtype=np.int64))

    shared = tables()
    rng = np.random.default_rng(3)
    answered = 0
    for _ in range(12):
        i = int(rng.integers(0, len(poses) - 6))
        j = i + int(rng.integers(2, 6))
        steps = np.empty(n, dtype=np.int64)
        backward_steps(indptr, indices, poses[j], problem.goal_id, steps)
        m = j - i + int(rng.integers(0, 3))
        arguments = (target, usable, 0, durations, danger, poses[i], -1, poses[j], -1, problem.goal_id, m,
                     0.01, 1.0 / 40, 1.0 / 400, steps)
        fresh = min_bracket(*arguments, *tables(), np.zeros((1, 1, 1), dtype=np.int32), False)
        assert min_bracket(*arguments, *shared, np.zeros((1, 1, 1), dtype=np.int32), False) == fresh
        assert np.isinf(shared[0]).all() and np.isinf(shared[1]).all()
        answered += bool(np.isfinite(fresh[0]))
    assert answered >= 6  # most windows of the optimum have a way of m commands (m ≥ the window's own)
