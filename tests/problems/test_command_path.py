"""Seed 000's path problem: the four fitnesses of eqs. 3–6 on hand-made sequences, child termination, errors."""

import math

import networkx as nx
import numpy as np
import pytest

from htetro_opt.errors import ConfigurationError, HtetroError, ParameterError, PlanningError
from htetro_opt.model import (
    SEED000_COMMANDS,
    STATE_NAMES,
    MovingObstacle,
    Pose,
    Simulator,
    Timing,
    Workspace,
    parse_commands,
    shape_index,
)
from htetro_opt.operators import as_column
from htetro_opt.problems import (
    FITNESS_NAMES,
    SAFETY_COEFFICIENT,
    SAFETY_PATTERN,
    CommandPathProblem,
    safety_field,
)
from htetro_opt.scenarios import load_scenario

SQRT2 = math.sqrt(2.0)


def bordered(width=12, height=12):
    occ = np.zeros((height, width), dtype=bool)
    occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = True
    return occ


def ids(tokens):
    return parse_commands(tokens) if tokens else np.empty(0, dtype=np.int64)


def fitness(problem, *token_lists):
    """(f_gr, f_t, f_sm, f_sf) of each sequence, through pymoo's evaluate."""
    return -problem.evaluate(as_column([ids(t) for t in token_lists]))


def grid_steps(occ, source, target):
    """W_A*: 4-connected steps between two free cells over free cells (networkx), None if disconnected."""
    h, w = occ.shape
    graph = nx.grid_2d_graph(w, h)  # nodes (x, y)
    graph.remove_nodes_from([(x, y) for y in range(h) for x in range(w) if occ[y, x]])
    try:
        return nx.shortest_path_length(graph, source, target)
    except nx.NetworkXNoPath:
        return None


def danger(occ, cells):
    """Eq. 6's inner sum for one pose: 1 / ‖offset‖ over the obstacle or out-of-map cells within 2 of a block."""
    h, w = occ.shape
    total = 0.0
    for bx, by in cells:
        for dx in range(-2, 3):
            for dy in range(-2, 3):
                cx, cy = bx + dx, by + dy
                if 0 < dx * dx + dy * dy <= 4 and (not (0 <= cx < w and 0 <= cy < h) or occ[cy, cx]):
                    total += 1 / math.hypot(dx, dy)
    return total


DURATION = {"translation": 1.0, "rotation": 2.0, "shapeshift": 3.0}


def kind(token):
    return "rotation" if token.startswith("r") else "shapeshift" if token.startswith("s") else "translation"


def oracle_fitness(ws, start, goal, tokens, max_length, successors):
    """(f_gr, f_t, f_sm, f_sf) of one sequence by eqs. 3–6 as the paper states them, executed command by
    command by the test suite's own validity model, stopping at the first invalid command or the goal."""
    pose = (start.x, start.y, shape_index(start.shape), start.heading)
    target = (goal.x, goal.y, shape_index(goal.shape), goal.heading)
    executed, poses = [], []
    for t, token in enumerate(tokens):
        if pose == target:
            break
        moves = {tok: nxt for tok, nxt, _ in successors(ws, pose, t, SEED000_COMMANDS)}
        if token not in moves:
            break
        pose = moves[token]
        executed.append(token)
        poses.append(pose)
    n = len(executed)
    steps = grid_steps(ws.occupancy, pose[:2], target[:2])
    if pose == target:
        f_gr = 1.0
    elif steps is None:
        f_gr = 0.0
    else:
        f_gr = 1 / (1 + (steps if steps else 0.5))  # the goal cell in another shape or heading: half a cell
    f_t = 1 - sum(DURATION[kind(t)] for t in executed) / max_length
    changes = sum(a != b for a, b in zip(executed, executed[1:]))
    f_sm = 1 - changes / (n - 1) if n > 1 else 1.0
    penalty = sum(danger(ws.occupancy, Pose(x, y, STATE_NAMES[s], h).cells().tolist()) for x, y, s, h in poses)
    f_sf = 1 - penalty / (n * (6 + 2 * SQRT2)) if n else 1.0
    return [f_gr, f_t, f_sm, f_sf], n, pose == target


@pytest.fixture(scope="module")
def open_problem():
    """12 × 12 map whose border is the only obstacle; O-shape from (3, 3) to (7, 6), l_p,max = 20."""
    return CommandPathProblem(Workspace(bordered()), Pose(3, 3, "O", 0), Pose(7, 6, "O", 0), max_length=20)


def test_safety_pattern_and_field():
    assert FITNESS_NAMES == ("f_gr", "f_t", "f_sm", "f_sf")
    assert SAFETY_PATTERN.shape == (12, 2)
    assert len({tuple(o) for o in SAFETY_PATTERN.tolist()}) == 12
    assert all(0 < dx * dx + dy * dy <= 4 for dx, dy in SAFETY_PATTERN.tolist())
    assert SAFETY_COEFFICIENT == pytest.approx(6 + 2 * SQRT2)
    assert SAFETY_COEFFICIENT == pytest.approx(sum(1 / math.hypot(dx, dy) for dx, dy in SAFETY_PATTERN.tolist()))
    field = safety_field(np.zeros((6, 7), dtype=bool))
    assert field[2:4, 2:5].tolist() == [[0.0] * 3] * 2  # two cells from every edge
    # a corner: (-1, 0), (0, -1) at 1, (-1, -1), (-1, 1), (1, -1) at √2, (-2, 0), (0, -2) at 2 lie outside
    assert field[0, 0] == pytest.approx(2 + 3 / SQRT2 + 1)
    assert field[0, 3] == pytest.approx(1 + 2 / SQRT2 + 0.5)  # bottom edge, away from the corners
    walled = np.ones((5, 5), dtype=bool)
    walled[2, 2] = False
    assert safety_field(walled)[2, 2] == pytest.approx(SAFETY_COEFFICIENT)
    occ = np.zeros((7, 7), dtype=bool)
    occ[3, 5] = True  # two cells to the right of the centre
    assert safety_field(occ)[3, 3] == pytest.approx(0.5)
    assert safety_field(occ)[4, 4] == pytest.approx(1 / SQRT2)


# --- goal reachability (eq. 3) ----------------------------------------------------------------
def test_goal_reachability(open_problem):
    f = fitness(open_problem, "y+,y+,y+,x+,x+,x+,x+", "sI,x+,x+,x+,x+,y+,y+,y+", "x+,x+", "", "r+,x+,x+,x+,x+,y+,y+,y+",
                "x+,x+,x+,x+,y+,y+,y+,sI")
    assert f[0, 0] == 1.0  # exactly the goal configuration
    assert f[1, 0] < 1.0 and f[1, 0] == pytest.approx(2 / 3)  # goal cell, I-shape: counts half a cell away
    assert f[4, 0] < 1.0 and f[4, 0] == pytest.approx(2 / 3)  # goal cell and shape, another heading
    assert f[2, 0] == pytest.approx(1 / (1 + 2 + 3))  # B2 on (5, 3): 5 cells from (7, 6)
    assert f[3, 0] == pytest.approx(1 / (1 + 7))  # nothing executed: the start's distance
    assert f[5, 0] == 1.0  # passes through the goal configuration: stops there, the sI is never executed
    out = open_problem.evaluate(as_column([ids("y+,y+,y+,x+,x+,x+,x+"), ids("x+,x+")]),
                                return_values_of=["reached", "executed", "time"])
    assert out[0].astype(bool).tolist() == [True, False]
    assert out[1].tolist() == [7, 2] and out[2].tolist() == [7.0, 2.0]


def test_goal_reachability_uses_the_grid_distance_around_obstacles():
    occ = bordered()
    occ[1:9, 6] = True  # a wall between start and goal, open at the top
    ws = Workspace(occ)
    problem = CommandPathProblem(ws, Pose(3, 3, "O", 0), Pose(9, 3, "O", 0), max_length=20)
    f = fitness(problem, "x+", "y+,y+")
    # from (4, 3): up to row 9 (6), across to column 9 (5), down to row 3 (6) — not the 5 cells straight across
    assert f[0, 0] == pytest.approx(1 / (1 + 17))
    assert grid_steps(occ, (4, 3), (9, 3)) == 17
    # from (3, 5): up 4, across 6, down 6
    assert grid_steps(occ, (3, 5), (9, 3)) == 16
    assert f[1, 0] == pytest.approx(1 / (1 + 16))


def test_unreachable_goal_cell_scores_zero():
    occ = bordered()
    occ[6:10, 6:10] = True
    occ[7:9, 7:9] = False  # a closed 2 × 2 pocket holding the goal
    problem = CommandPathProblem(Workspace(occ), Pose(3, 3, "O", 0), Pose(7, 8, "O", 0), max_length=10)
    f = fitness(problem, "x+,y+", "")
    assert f[:, 0].tolist() == [0.0, 0.0]


# --- child termination ------------------------------------------------------------------------
def test_genes_after_the_goal_do_not_count(open_problem):
    reach = "y+,y+,y+,x+,x+,x+,x+"
    f = fitness(open_problem, reach, reach + ",y+,y+,sI", reach + ",x-,r+,r+,r+,sZ,y-")
    assert f[0, 0] == 1.0
    assert np.array_equal(f[1], f[0]) and np.array_equal(f[2], f[0])
    out = open_problem.evaluate(as_column([ids(reach + ",y+,y+,sI")]), return_values_of=["executed", "time"])
    assert out[0].tolist() == [7] and out[1].tolist() == [7.0]


def test_genes_after_the_first_invalid_command_do_not_count(open_problem):
    # from (3, 3) the O-shape (columns 3 and 4) can step left twice; a third x- hits the border at x = 0
    f = fitness(open_problem, "x-,x-", "x-,x-,x-", "x-,x-,x-,y+,y+,y+,x+", "x-,x-,x-,sI,r+")
    assert np.array_equal(f[1], f[0]) and np.array_equal(f[2], f[0]) and np.array_equal(f[3], f[0])
    executed = open_problem.evaluate(as_column([ids("x-,x-,x-,y+,y+,y+,x+")]), return_values_of=["executed"])
    assert executed.tolist() == [2]
    assert not np.array_equal(f[0], fitness(open_problem, "x-,x-,y+")[0])  # a valid third command would count


def test_invalid_first_command_scores_the_start():
    problem = CommandPathProblem(Workspace(bordered()), Pose(1, 2, "O", 0), Pose(7, 6, "O", 0), max_length=20)
    f = fitness(problem, "x-,y+,y+,x+", "")  # x- at once puts the left column on the border
    assert np.array_equal(f[0], f[1])
    assert f[0, 1:].tolist() == [1.0, 1.0, 1.0]
    assert f[0, 0] == pytest.approx(1 / (1 + 6 + 4))


# --- time (eq. 4) -----------------------------------------------------------------------------
def test_time_fitness(open_problem):
    assert open_problem.t_max == 20.0
    seqs = ["x+,x+", "x+,y+,sI,x+", "x+,y+,r+,x+", ""]
    f = fitness(open_problem, *seqs)
    executed = open_problem.evaluate(as_column([ids(t) for t in seqs]), return_values_of=["executed"])
    assert executed.tolist() == [2, 4, 4, 0]
    assert f[0, 1] == pytest.approx(1 - 2 / 20)
    assert f[1, 1] == pytest.approx(1 - (1 + 1 + 3 + 1) / 20)  # a shapeshift takes 3
    assert f[2, 1] == pytest.approx(1 - (1 + 1 + 2 + 1) / 20)  # a rotation takes 2
    assert f[3, 1] == 1.0


def test_time_budget_follows_the_translation_time():
    timing = Timing(translation=2.0, shapeshift=5.0)
    problem = CommandPathProblem(Workspace(bordered()), Pose(3, 3, "O", 0), Pose(7, 6, "O", 0), max_length=15,
                                 timing=timing)
    assert problem.t_max == 30.0
    assert np.array_equal(problem.durations, timing.durations())
    f = fitness(problem, "sI,x+")
    assert f[0, 1] == pytest.approx(1 - 7 / 30)


# --- smoothness (eq. 5) -----------------------------------------------------------------------
def test_smoothness_fitness(open_problem):
    f = fitness(open_problem, "x+,x+,y+,y+,y+,sI,x+", "x+,x+,x+", "x+,y+,x+,y+", "x+", "", "x+,x-,x+,x-,x+")
    assert f[0, 2] == pytest.approx(1 - 3 / 6)  # x+→y+, y+→sI, sI→x+ over 6 neighbouring pairs
    assert f[1, 2] == 1.0
    assert f[2, 2] == pytest.approx(0.0)
    assert f[3, 2] == 1.0 and f[4, 2] == 1.0  # l_p = 1 and l_p = 0
    assert f[5, 2] == pytest.approx(0.0)


def test_smoothness_counts_only_the_executed_prefix(open_problem):
    # x-, x-, then an invalid x-: no change in the executed prefix, whatever follows
    assert fitness(open_problem, "x-,x-,x-,y+,x+,y+,x+")[0, 2] == 1.0
    # y+, x+ executed... then the goal stops the child before the changes that follow
    f = fitness(open_problem, "y+,y+,y+,x+,x+,x+,x+,sI,r+,y-")
    assert f[0, 2] == pytest.approx(1 - 1 / 6)


# --- safety (eq. 6) ---------------------------------------------------------------------------
def test_safety_far_from_obstacles_is_one():
    problem = CommandPathProblem(Workspace(np.zeros((14, 14), dtype=bool)), Pose(6, 6, "O", 0), Pose(9, 9, "O", 0),
                                 max_length=20)
    f = fitness(problem, "x+,y+,sI,r+,x-", "")
    assert f[0, 3] == 1.0 and f[1, 3] == 1.0


def test_safety_near_a_wall_is_lower(open_problem):
    f = fitness(open_problem, "y+,x+", "x-,y-", "x-")
    # via (3, 4) to (4, 4): every block stays 3 or more cells from the border, out of the pattern's reach
    assert f[0, 3] == 1.0
    assert f[1, 3] < 1.0 and f[2, 3] < 1.0
    assert f[2, 3] < f[0, 3]


def test_safety_hand_computed():
    # a free 12 × 12 map (only its outside counts as obstacle); the horizontal I-shape on the bottom row
    ws = Workspace(np.zeros((12, 12), dtype=bool))
    problem = CommandPathProblem(ws, Pose(5, 0, "I", 1), Pose(6, 8, "I", 1), max_length=10)
    f = fitness(problem, "x+", "x+,y+")
    # after x+ the blocks are (4..7, 0): each has (0, -1) at 1, (±1, -1) at √2 and (0, -2) at 2 outside the map
    first = 4 * (1 + 2 / SQRT2 + 0.5)
    assert f[0, 3] == pytest.approx(1 - first / SAFETY_COEFFICIENT)
    # after y+ they are (4..7, 1): only (0, -2) lies outside
    assert f[1, 3] == pytest.approx(1 - (first + 4 * 0.5) / (2 * SAFETY_COEFFICIENT))
    assert f[0, 3] == pytest.approx(1 - (6 + 4 * SQRT2) / (6 + 2 * SQRT2))


@pytest.mark.parametrize("map_seed", [11, 12])
def test_objectives_match_an_independent_oracle_on_a_cluttered_map(map_seed, successors):
    rng = np.random.default_rng(map_seed)
    occ = rng.random((10, 12)) < 0.12
    occ[2:9, 2:8] = False  # room to turn the I-shape round at the start
    occ[5, 8] = True  # an obstacle near the goal
    ws = Workspace(occ)
    start, goal = Pose(4, 5, "O", 0), Pose(5, 4, "I", 2)
    problem = CommandPathProblem(ws, start, goal, max_length=12)
    tokens = ["x+", "x-", "y+", "y-", "r+", "r-", "sI", "sO", "sL", "sT"]
    runs = [list(rng.choice(tokens, size=rng.integers(0, 14))) for _ in range(80)]
    runs += [["sI", "r+", "r+", "y-", "x+"], ["sI", "r+", "r+", "x+", "y-", "sO"]]  # reaching the goal, then more
    F, executed, reached = problem.evaluate(as_column([ids(t) for t in runs]),
                                            return_values_of=["F", "executed", "reached"])
    seen = set()
    for i, tokens_i in enumerate(runs):
        expected, n, hit = oracle_fitness(ws, start, goal, tokens_i, 12, successors)
        assert int(executed[i]) == n and bool(reached[i]) == hit
        assert (-F[i]).tolist() == pytest.approx(expected)
        seen.add((hit, n > 1, n < len(tokens_i)))
    assert {(True, True, True), (False, True, False), (False, True, True)} <= seen  # the sample covers the cases


def test_objectives_of_a_hand_computed_run():
    # A 6 × 5 open map (only the outside counts as obstacle); the O-shape from (1, 1) towards (3, 2).
    ws = Workspace(np.zeros((5, 6), dtype=bool))
    problem = CommandPathProblem(ws, Pose(1, 1, "O", 0), Pose(3, 2, "O", 0), max_length=4)
    f = fitness(problem, "x+,sI", "x+,x+,y+,y-")
    # x+, then sI: 2 commands, 1 change, 1 + 3 = 4 s of t_max = 4 s; B2 ends on (2, 1), 2 steps from (3, 2).
    # After x+ the O covers (2, 0), (3, 0) on the bottom row, whose (0, −1), (±1, −1), (0, −2) lie outside
    # the map, and (2, 1), (3, 1), whose (0, −2) does; after sI the I covers (2, 0) (as before), (2, 1)
    # (as before), (2, 2) (nothing outside within 2) and (2, 3), whose (0, +2) lies outside.
    bottom, second = 1 + 2 / SQRT2 + 0.5, 0.5
    after_x = 2 * bottom + 2 * second
    after_i = bottom + second + 0 + 0.5
    assert f[0].tolist() == pytest.approx([1 / 3, 1 - 4 / 4, 1 - 1 / 1, 1 - (after_x + after_i) / (2 * (6 + 2 * SQRT2))])
    # x+, x+, y+ reaches (3, 2): the child stops there, y- is never executed
    assert f[1, :3].tolist() == pytest.approx([1.0, 1 - 3 / 4, 1 - 1 / 2])


# --- parameters and configurations -------------------------------------------------------------
@pytest.mark.parametrize("options", [
    dict(max_length=0), dict(max_length=-3), dict(max_length=2.5), dict(max_length=True), dict(max_length="10"),
    dict(t0=-1), dict(t0=1.0), dict(t0=True),
])
def test_bad_parameters(options):
    with pytest.raises(ParameterError):
        CommandPathProblem(Workspace(bordered()), Pose(3, 3, "O", 0), Pose(7, 6, "O", 0), **options)


@pytest.mark.parametrize("start,goal", [
    (Pose(1, 1, "O", 0), Pose(7, 6, "O", 0)),  # the start's B1 lies on the border
    (Pose(3, 3, "O", 0), Pose(10, 6, "O", 0)),  # the goal's right column lies on the border
    (Pose(3, 3, "O", 0), Pose(12, 6, "O", 0)),  # outside the map
    (Pose(3, 3, "O", 0), Pose(6, 10, "I", 0)),  # the I-shape pokes into the top border
])
def test_colliding_configurations(start, goal):
    with pytest.raises(ConfigurationError):
        CommandPathProblem(Workspace(bordered()), start, goal)


def test_start_is_checked_against_moving_obstacles_at_t0():
    # a cell sliding left along row 2: at t = 2 it covers (3, 2), one of the start's cells
    slider = MovingObstacle(np.array([[5, 2]]), np.array([[0, 0], [-3, 0]]))
    ws = Workspace(np.zeros((8, 8), dtype=bool), moving=(slider,))
    start, goal = Pose(2, 2, "O", 0), Pose(2, 5, "O", 0)
    CommandPathProblem(ws, start, goal, t0=0)
    with pytest.raises(ConfigurationError):
        CommandPathProblem(ws, start, goal, t0=2)
    assert issubclass(ConfigurationError, HtetroError) and issubclass(ParameterError, HtetroError)


def test_simulator_can_be_shared():
    sim = Simulator(Workspace(bordered()), commands=["x+", "x-", "y+", "y-"], timing=Timing(translation=0.5))
    problem = CommandPathProblem(sim, Pose(3, 3, "O", 0), Pose(5, 3, "O", 0), max_length=8)
    assert problem.simulator is sim
    assert sorted(problem.command_ids.tolist()) == sorted(parse_commands("x+,x-,y+,y-").tolist())
    assert problem.t_max == 4.0
    assert fitness(problem, "x+,x+")[0, :3].tolist() == pytest.approx([1.0, 1 - 1 / 4, 1.0])


# --- moving obstacles -------------------------------------------------------------------------
def test_moving_obstacles_make_the_start_time_matter():
    scenario = load_scenario("parallel_dynamic")
    ws = scenario.workspace
    start, goal = scenario.roadmap[0], scenario.roadmap[-1]
    seq = ids("y+,y+,y+,y+,y+,y+,y+")
    rows, executed = set(), set()
    static = CommandPathProblem(ws.without_moving(), start, goal, max_length=20)
    for t0 in range(0, 8):
        problem = CommandPathProblem(ws, start, goal, max_length=20, t0=t0)
        F, n = problem.evaluate(as_column([seq]), return_values_of=["F", "executed"])
        rows.add(tuple(F[0].tolist()))
        executed.add(int(n[0]))
        # the moving blocks only cut the run short: it scores as the static map scores the executed prefix
        assert np.array_equal(F, static.evaluate(as_column([seq[: int(n[0])]])))
    assert len(rows) > 1 and len(executed) > 1
    # the pattern repeats with the obstacles' period
    p0 = CommandPathProblem(ws, start, goal, max_length=20, t0=1)
    p1 = CommandPathProblem(ws, start, goal, max_length=20, t0=1 + ws.period)
    assert np.array_equal(p0.evaluate(as_column([seq])), p1.evaluate(as_column([seq])))


def test_the_pose_tables_do_not_depend_on_the_slices_they_are_computed_in(monkeypatch):
    from htetro_opt.problems import command_path  # its module constant is patched

    sim = Simulator(load_scenario("three_slit").workspace.without_moving())
    start, goal = Pose(3, 11, "O", 0), Pose(20, 11, "O", 0)
    whole = CommandPathProblem(sim, start, goal)
    monkeypatch.setattr(command_path, "_POSES_PER_SLICE", 1000)  # 16 slices, the last one short
    sliced = CommandPathProblem(sim, start, goal)
    assert np.array_equal(whole._pose_reachability, sliced._pose_reachability)
    assert np.array_equal(whole._pose_danger, sliced._pose_danger)


def test_pose_tables_beyond_the_memory_budget_are_refused(monkeypatch):
    import sys

    sim = Simulator(Workspace(bordered()))
    monkeypatch.setattr(sys.modules["htetro_opt.model.simulate"], "MEMORY_BUDGET", 2**16)
    with pytest.raises(PlanningError, match=r"the path problem's pose tables .* 12 x 12 map \(28 poses a cell\)"):
        CommandPathProblem(sim, Pose(3, 3, "O", 0), Pose(7, 6, "O", 0))
