"""The exact planner: optimal against independent searches, and every plan re-validates."""

import heapq
import re
import sys
import time
import tracemalloc
from functools import partial

import networkx as nx
import numpy as np
import pytest

from htetro_opt.errors import ConfigurationError, ParameterError, PlanningError
from htetro_opt.model import SEED000_COMMANDS, MovingObstacle, Pose, Simulator, Workspace, shape_index
from htetro_opt.scenarios import parse_grid
from htetro_opt.solvers.grid_paths import EXACT_METHODS, plan_exact, plan_path


def as_tuple(pose):
    return (pose.x, pose.y, shape_index(pose.shape), pose.heading)


def networkx_optimum(ws, start, goal, tokens, successors):
    graph = nx.DiGraph()
    seen, stack = {as_tuple(start)}, [as_tuple(start)]
    while stack:
        pose = stack.pop()
        for _, nxt, cost in successors(ws, pose, 0, tokens):
            if nxt != pose and (not graph.has_edge(pose, nxt) or graph[pose][nxt]["weight"] > cost):
                graph.add_edge(pose, nxt, weight=cost)
            if nxt not in seen:
                seen.add(nxt)
                stack.append(nxt)
    try:
        return nx.shortest_path_length(graph, as_tuple(start), as_tuple(goal), weight="weight")
    except (nx.NetworkXNoPath, nx.NodeNotFound):
        return None


def time_expanded_optimum(ws, start, goal, tokens, successors, horizon=200):
    period = ws.period
    best = {(as_tuple(start), 0): 0.0}
    frontier = [(0.0, 0, as_tuple(start))]
    while frontier:
        cost, t, pose = heapq.heappop(frontier)
        if pose == as_tuple(goal):
            return cost
        if t >= horizon or cost > best.get((pose, t % period), np.inf):
            continue
        for _, nxt, d in successors(ws, pose, t, tokens):
            key = (nxt, (t + 1) % period)
            if cost + d < best.get(key, np.inf):
                best[key] = cost + d
                heapq.heappush(frontier, (cost + d, t + 1, nxt))
    return None


def random_workspace(seed, w=12, h=12, density=0.12):
    rng = np.random.default_rng(seed)
    occ = rng.random((h, w)) < density
    occ[0:5, 0:5] = False
    occ[h - 5 :, w - 5 :] = False
    return Workspace(occ)


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("diagonals", [False, True])
def test_optimal_against_networkx_and_revalidates(seed, diagonals, successors):
    ws = random_workspace(seed)
    start, goal = Pose(2, 2, "O", 0), Pose(9, 9, "O", 0)
    tokens = list(SEED000_COMMANDS) + (["x+y+", "x+y-", "x-y+", "x-y-"] if diagonals else [])
    expected = networkx_optimum(ws, start, goal, tokens, successors)
    for method in EXACT_METHODS:
        plan = plan_exact(ws, [start, goal], diagonals=diagonals, method=method)
        assert plan.method == method
        assert expected is not None and plan.reached  # these maps connect start and goal (unreachable: below)
        assert plan.time == pytest.approx(expected)
        result = Simulator(ws, diagonals=diagonals).run([plan.commands], start, roadmap=[goal])
        assert result.valid[0] and result.reached[0]
        assert result.time[0] == pytest.approx(plan.time)
        assert plan.poses[-1].tolist() == list(as_tuple(goal))


def test_seed_004_commands_and_intermediate_states(successors):
    ws = Workspace(np.zeros((9, 9), dtype=bool))
    start, goal = Pose(4, 4, "I", 0), Pose(4, 4, "O", 0)
    plan = plan_exact(ws, [start, goal], commands=["stop", "x+", "x-", "y+", "y-", "1l", "1r", "2l", "2r", "3l", "3r", "4l", "4r"])
    assert plan.tokens == ["3r", "3r"]  # seed 004 §IV: two consecutive 3r take I to O
    assert plan.time == 2.0


@pytest.mark.parametrize("method", EXACT_METHODS)
def test_moving_obstacles_time_expanded(method, successors):
    occ = np.zeros((9, 9), dtype=bool)
    occ[4, :] = True
    occ[4, 3:7] = False  # a 4-wide door
    moving = (MovingObstacle(np.array([[3, 4]]), np.array([[3, 0]])),)  # patrols the door
    ws = Workspace(occ, moving=moving)
    start, goal = Pose(4, 1, "O", 0), Pose(4, 7, "O", 0)
    static = plan_exact(ws.without_moving(), [start, goal], method=method)
    plan = plan_exact(ws, [start, goal], method=method)
    expected = time_expanded_optimum(ws, start, goal, list(SEED000_COMMANDS), successors)
    assert plan.reached and plan.time == pytest.approx(expected)
    assert plan.time > static.time  # the patrol forces a detour or a wait
    result = Simulator(ws).run([plan.commands], start, roadmap=[goal])
    assert result.valid[0] and result.reached[0]
    assert not Simulator(ws).run([static.commands], start).valid[0]


def test_waiting_in_place_is_used_when_it_is_the_only_way(successors):
    # The robot starts in a pocket exactly its size (no room to move or turn); a patrol blocks the
    # pocket's mouth during the first two steps, so the only plan idles twice (sO while O) first.
    grid = [
        "############",
        "####..######",
        "####..######",
        "............",
        "............",
        "############",
    ]
    occ = np.array([[c == "#" for c in row] for row in grid[::-1]])
    moving = (MovingObstacle(np.array([[4, 2], [5, 2]]), np.array([[-4, 0]])),)
    ws = Workspace(occ, moving=moving)
    start, goal = Pose(4, 4, "O", 0), Pose(9, 2, "O", 0)
    plan = plan_exact(ws, [start, goal])
    assert plan.reached
    assert plan.tokens[:2] == ["sO", "sO"]
    assert plan.time == pytest.approx(time_expanded_optimum(ws, start, goal, list(SEED000_COMMANDS), successors))
    assert Simulator(ws).run([plan.commands], start, roadmap=[goal]).reached[0]
    assert plan_exact(ws, [start, goal], method="astar").time == plan.time


def test_roadmap_is_planned_leg_by_leg():
    ws = Workspace(np.zeros((10, 10), dtype=bool))
    roadmap = [Pose(1, 2, "O", 0), Pose(7, 2, "I", 1), Pose(7, 7, "O", 0)]
    plan = plan_exact(ws, roadmap)
    legs = [plan_exact(ws, roadmap[i : i + 2]) for i in range(2)]
    assert plan.time == pytest.approx(sum(leg.time for leg in legs))
    assert len(plan.leg_ends) == 2
    mid = plan.poses[plan.leg_ends[0]]
    assert mid.tolist() == [7, 2, shape_index("I"), 1]
    assert Simulator(ws).run([plan.commands], roadmap[0], roadmap=roadmap[1:]).reached[0]


@pytest.mark.parametrize("method", EXACT_METHODS)
def test_unreachable_goal_is_reported_not_raised(method, successors):
    occ = np.zeros((10, 10), dtype=bool)
    occ[5, :] = True
    ws, start, goal = Workspace(occ), Pose(2, 2, "O", 0), Pose(2, 8, "O", 0)
    assert networkx_optimum(ws, start, goal, list(SEED000_COMMANDS), successors) is None
    plan = plan_exact(ws, [start, goal], method=method)
    assert not plan.reached and plan.failed_leg == 0 and len(plan.commands) == 0 and plan.time == 0.0
    assert plan.poses.tolist() == [[2, 2, shape_index("O"), 0]]  # the plan stays at the start


def test_errors():
    ws = Workspace(np.zeros((6, 6), dtype=bool))
    with pytest.raises(PlanningError, match="start and a goal"):
        plan_exact(ws, [Pose(1, 1, "O", 0)])
    with pytest.raises(ParameterError, match="'bfs'"):
        plan_exact(ws, [Pose(1, 1, "O", 0), Pose(3, 3, "O", 0)], method="bfs")
    with pytest.raises(ParameterError, match="t0"):
        plan_exact(ws, [Pose(1, 1, "O", 0), Pose(3, 3, "O", 0)], t0=-1)
    with pytest.raises(ConfigurationError, match="goal"):
        plan_exact(ws, [Pose(1, 1, "O", 0), Pose(5, 5, "O", 0)])  # goal's B3 leaves the map
    with pytest.raises(ConfigurationError, match="start"):
        plan_exact(Workspace(np.ones((6, 6), dtype=bool)), [Pose(1, 1, "O", 0), Pose(3, 3, "O", 0)])


# A wall across the map with a 2-cell gap above the start and a 4-cell gap to the right. The O-shape
# (2 cells wide) fits the narrow gap; with a clearance every block needs a free cell on each side, so
# only the wide gap lets it (or any other shape) through.
TWO_GAPS = parse_grid("""
................
................
................
................
................
###..######....#
................
................
................
................
................
................
""".strip())


@pytest.mark.parametrize("method", EXACT_METHODS)
def test_clearance_forces_the_detour_and_is_optimal(method, successors):
    ws = Workspace(TWO_GAPS)
    start, goal = Pose(3, 2, "O", 0), Pose(3, 10, "O", 0)
    plain = plan_exact(ws, [start, goal], method=method)
    padded = plan_exact(ws, [start, goal], clearance=0.2, method=method)
    assert plain.reached and plain.time == 8.0  # straight up through the narrow gap
    assert padded.reached
    expected = networkx_optimum(ws, start, goal, list(SEED000_COMMANDS), partial(successors, clearance=0.2))
    assert padded.time == pytest.approx(expected)
    assert padded.time > plain.time
    assert (padded.poses[:, 0] >= 10).any()  # B2 passes through the wide gap's columns
    padded_sim = Simulator(ws, clearance=0.2)
    assert padded_sim.run([padded.commands], start, roadmap=[goal]).reached[0]
    assert not padded_sim.run([plain.commands], start).valid[0]  # the narrow gap is too narrow with clearance


def test_long_obstacle_periods_hand_over_to_astar(monkeypatch):
    from htetro_opt.solvers.grid_paths import _exact  # its module constant is patched

    occ = np.zeros((10, 10), dtype=bool)
    moving = (
        MovingObstacle(np.array([[0, 9]]), np.array([[8, 0]])),  # period 16
        MovingObstacle(np.array([[9, 0]]), np.array([[0, 6]]), mode="loop"),  # period 12
    )
    ws = Workspace(occ, moving=moving)
    roadmap = [Pose(2, 2, "O", 0), Pose(6, 5, "O", 0)]
    full = plan_exact(ws, roadmap)
    monkeypatch.setattr(_exact, "MAX_EXPANDED_NODES", 10)
    handed = plan_exact(ws, roadmap)
    assert full.method == "dijkstra" and handed.method == "dijkstra (astar)"
    assert handed.time == pytest.approx(full.time)
    assert plan_exact(ws, roadmap, method="astar").method == "astar"  # asked for: no hand-over to report


def test_statically_unreachable_leg_is_reported_without_a_time_expanded_search():
    occ = np.zeros((10, 10), dtype=bool)
    occ[5, :] = True
    moving = (MovingObstacle(np.array([[0, 8]]), np.array([[8, 0]])),)
    for method in EXACT_METHODS:
        plan = plan_exact(Workspace(occ, moving=moving), [Pose(2, 2, "O", 0), Pose(2, 8, "O", 0)], method=method)
        assert not plan.reached and plan.failed_leg == 0


# --- the memory budget ---------------------------------------------------------------------------------

SIMULATE = sys.modules["htetro_opt.model.simulate"]  # the module (htetro_opt.model.simulate is the function)


# A map the graph-free planner fits in the default budget (1000 x 1000: about 0.3 GiB) is refused under a
# budget given as the option; 5000 x 5000 (about 7 GiB) under the default one.
@pytest.mark.parametrize(("side", "budget"), [(1000, "128MiB"), (5000, None)])
@pytest.mark.parametrize("method", ["dijkstra", "astar"])
def test_a_huge_map_is_refused_at_once_saying_how_much_memory_and_what_fits(monkeypatch, side, budget, method):
    monkeypatch.setattr(Simulator, "_transition_table", lambda self: pytest.fail("allocated before the check"))
    monkeypatch.setattr(np, "full", lambda *a, **k: pytest.fail("allocated before the check"))
    huge = Workspace(np.zeros((side, side), dtype=bool))
    began = time.process_time()  # "at once" in CPU time, which a busy machine does not stretch
    with pytest.raises(PlanningError) as info:
        plan_path(huge, [Pose(1, 1, "O", 0), Pose(side - 3, side - 3, "O", 0)], method=method, memory_budget=budget)
    assert time.process_time() - began < 2.0
    message = str(info.value)
    needed = _needed_bytes(message)
    limit = float(re.search(r"more than the budget of ([\d.]+) (MiB|GiB)", message)[1])
    assert needed > limit > 0 and f"{side} x {side} map" in message
    assert re.search(rf"'{method}' fits a map of at most [\d,]+ cells \(e\.g\. \d+ x \d+\)", message), message
    assert "--memory-budget" in message
    if budget is not None:
        assert "set by memory_budget (--memory-budget)" in message and "128.0 MiB" in message


def _needed_bytes(message):
    number, unit = re.search(r"would need about ([\d.]+) (MiB|GiB) of memory", message).groups()
    return float(number) * (2**20 if unit == "MiB" else 2**30)


@pytest.mark.parametrize("method", EXACT_METHODS)
def test_the_estimate_bounds_the_memory_planning_takes(monkeypatch, method):
    """tracemalloc's peak of a real plan (numpy reports its arrays to it) against the refusal's figure,
    on A*'s worst case: the goal is walled in, so the search reaches every other pose. The room's door is a
    bent corridor one cell wide: B2's point-robot distance (A*'s heuristic) reaches the goal, no shape does."""
    side = 90 if method == "dijkstra" else 50  # A* under tracemalloc is slow; Dijkstra's fixed costs need room
    occ = np.zeros((side, side), dtype=bool)
    occ[33:47, 33:47] = True
    occ[37:43, 37:43] = False  # a room no robot's door leads to
    occ[40, 33:36] = occ[41, 35:37] = False  # (33..35, 40) then (35..36, 41): a point passes the bend, no shape
    ws = Workspace(occ)
    roadmap = [Pose(2, 2, "O", 0), Pose(39, 40, "O", 0)]
    plan_exact(Workspace(np.zeros((8, 8), dtype=bool)), [Pose(2, 2, "O", 0), Pose(4, 4, "O", 0)], method=method)
    tracemalloc.start()
    try:
        assert not plan_exact(ws, roadmap, method=method).reached
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    monkeypatch.setattr(SIMULATE, "MEMORY_BUDGET", 2**20)
    with pytest.raises(PlanningError) as info:
        plan_exact(ws, roadmap, method=method)
    needed = _needed_bytes(str(info.value))
    assert peak <= needed <= 1.6 * peak


def test_a_time_expanded_graph_beyond_the_budget_hands_over_to_astar(monkeypatch):
    occ = np.zeros((10, 10), dtype=bool)
    moving = (MovingObstacle(np.array([[0, 9]]), np.array([[8, 0]])),)
    ws = Workspace(occ, moving=moving)
    roadmap = [Pose(2, 2, "O", 0), Pose(6, 5, "O", 0)]
    full = plan_exact(ws, roadmap)
    monkeypatch.setattr(SIMULATE, "MEMORY_BUDGET", 1)
    with pytest.raises(PlanningError) as info:
        plan_exact(ws, roadmap, method="astar")
    monkeypatch.setattr(SIMULATE, "MEMORY_BUDGET", int(_needed_bytes(str(info.value))) + 2**20)
    handed = plan_exact(ws, roadmap)
    assert full.method == "dijkstra" and handed.method == "dijkstra (astar)"
    assert handed.time == pytest.approx(full.time)
