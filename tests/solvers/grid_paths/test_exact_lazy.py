"""The graph-free exact planner against the explicit-graph one it replaced, on many small random maps.

The reference is ``_exact._plan_graph``: the simulator's whole transition table as a CSR graph and
scipy.sparse.csgraph's Dijkstra over it (the planner of static maps before, kept for moving obstacles).
Every plan is re-validated by running its commands in a compiled :class:`~htetro_opt.model.Simulator`.
"""

import math

import numpy as np
import pytest

from htetro_opt.errors import ConfigurationError, ParameterError, PlanningError
from htetro_opt.model import Pose, Simulator, Timing, Workspace
from htetro_opt.model.commands import command_set
from htetro_opt.model.robot import STATE_NAMES
from htetro_opt.solvers.grid_paths import EXACT_METHODS, plan_exact, plan_path
from htetro_opt.solvers.grid_paths import _exact, _lazy
from htetro_opt.solvers.grid_paths._spec import check_bytes

BLOCKS = ["stop", "x+", "x-", "y+", "y-", "1l", "1r", "2l", "2r", "3l", "3r", "4l", "4r"]


def random_case(seed, *, states=7, clearance=0.0):
    """A random map of 8 to 14 cells a side, two corners kept free, and two random collision-free poses on it."""
    rng = np.random.default_rng(seed)
    w, h = (int(v) for v in rng.integers(8, 15, size=2))
    occ = rng.random((h, w)) < rng.uniform(0.05, 0.25)
    occ[:5, :5] = occ[-5:, -5:] = False  # room for collision-free poses, with a clearance too
    ws = Workspace(occ)
    sim = Simulator(ws, commands=BLOCKS if states > 7 else None, clearance=clearance)
    poses = []
    while len(poses) < 2:
        pose = Pose(int(rng.integers(w)), int(rng.integers(h)), STATE_NAMES[int(rng.integers(7))], int(rng.integers(4)))
        try:
            sim.check_pose(pose)
        except ConfigurationError:
            continue
        poses.append(pose)
    return ws, poses


def reference(ws, roadmap, method="dijkstra", **options):
    options = {"diagonals": False, "commands": None, "timing": None, "clearance": 0.0, **options}
    return _exact._plan_graph(ws, roadmap, method=method, t0=0, **options)


def revalidates(plan, ws, roadmap, **compile_options):
    result = Simulator(ws, **compile_options).run([plan.commands], roadmap[0], roadmap=roadmap[1:])
    assert result.valid[0]
    assert result.time[0] == pytest.approx(plan.time)
    assert (result.poses(0) == plan.poses).all()
    assert bool(result.reached[0]) == plan.reached


@pytest.mark.parametrize("diagonals", [False, True])
def test_same_optimum_as_the_explicit_graph_on_random_maps(diagonals):
    reached = 0
    for seed in range(30):
        ws, roadmap = random_case(seed)
        expected = reference(ws, roadmap, diagonals=diagonals)
        for method in EXACT_METHODS:
            plan = plan_exact(ws, roadmap, method=method, diagonals=diagonals)
            assert plan.method == method
            assert plan.reached == expected.reached, seed
            assert plan.time == pytest.approx(expected.time), seed
            revalidates(plan, ws, roadmap, diagonals=diagonals)
        reached += expected.reached
    assert 5 <= reached <= 29  # both outcomes are exercised


@pytest.mark.parametrize("timing", [Timing(rotation=2.5, shapeshift=0.7), Timing(rotation=math.pi, translation=1.3)],
                         ids=["quanta", "irrational"])
def test_other_timings_bucket_and_heap(timing):
    # 0.1 s quanta go through the bucket queue; pi has no quantum and goes through the float heap
    durations = timing.durations()[list(command_set())]  # the default commands: no diagonal
    assert (_lazy.quantum(durations) is None) == (timing.rotation == math.pi)
    for seed in range(15):
        ws, roadmap = random_case(100 + seed)
        expected = reference(ws, roadmap, timing=timing)
        for method in EXACT_METHODS:
            plan = plan_exact(ws, roadmap, method=method, timing=timing)
            assert plan.reached == expected.reached and plan.time == pytest.approx(expected.time), seed
            revalidates(plan, ws, roadmap, timing=timing)


def test_clearance_block_commands_and_roadmaps():
    for seed in range(12):
        ws, roadmap = random_case(200 + seed, clearance=0.2)
        expected = reference(ws, roadmap, clearance=0.2)
        plan = plan_exact(ws, roadmap, method="astar", clearance=0.2)
        assert plan.reached == expected.reached and plan.time == pytest.approx(expected.time), seed
        revalidates(plan, ws, roadmap, clearance=0.2)
    for seed in range(6):  # Cheng et al. 2019's block commands: 23 states, the intermediate ones too
        ws, roadmap = random_case(300 + seed, states=23)
        expected = reference(ws, roadmap, commands=BLOCKS)
        for method in EXACT_METHODS:
            plan = plan_exact(ws, roadmap, method=method, commands=BLOCKS)
            assert plan.reached == expected.reached and plan.time == pytest.approx(expected.time), seed
            revalidates(plan, ws, roadmap, commands=BLOCKS)
    ws = Workspace(np.zeros((12, 12), dtype=bool))
    roadmap = [Pose(1, 1, "O", 0), Pose(8, 2, "I", 1), Pose(3, 8, "T", 2), Pose(8, 8, "O", 0)]
    plan = plan_exact(ws, roadmap, method="astar", diagonals=True)
    assert plan.time == pytest.approx(reference(ws, roadmap, diagonals=True).time)
    assert len(plan.leg_ends) == 3
    revalidates(plan, ws, roadmap, diagonals=True)


def test_a_compiled_simulator_is_used_as_given():
    ws, roadmap = random_case(7)
    sim = Simulator(ws, diagonals=True)
    plan = plan_exact(sim, roadmap, method="astar")
    assert plan.time == pytest.approx(reference(ws, roadmap, diagonals=True).time)
    revalidates(plan, ws, roadmap, diagonals=True)


def test_no_map_sized_table_is_compiled_on_a_static_map(monkeypatch):
    monkeypatch.setattr(Simulator, "_transition_table", lambda self: pytest.fail("compiled the simulator's table"))
    ws = Workspace(np.zeros((40, 60), dtype=bool))
    plan = plan_exact(ws, [Pose(2, 2, "O", 0), Pose(50, 30, "S", 3)], method="astar")
    assert plan.reached and plan.poses[-1].tolist() == [50, 30, 5, 3]


def test_the_heuristic_is_consistent_and_admissible():
    """h(u) <= h(v) + duration over every valid transition of the simulator's own table, and h of the
    start at most the optimum: the A* proof's two claims, checked edge by edge."""
    for seed, diagonals in [(s, d) for s in range(8) for d in (False, True)]:
        ws, roadmap = random_case(400 + seed)
        sim = Simulator(ws, diagonals=diagonals)
        space = _lazy.PoseSpace(ws, sim.command_ids, sim.durations, sim.tables)
        goal = roadmap[1]
        h = _lazy.heuristic_field(space, (goal.x, goal.y)).ravel()
        n, cells = sim.n_poses, ws.width * ws.height
        target = sim.next[:n, : sim.n_commands]
        valid = target != sim.dead
        source = np.broadcast_to(np.arange(n)[:, None], target.shape)
        hu, hv = h[source[valid] % cells], h[target[valid] % cells]
        cost = np.broadcast_to(sim.durations[: sim.n_commands], target.shape)[valid]
        assert not (np.isinf(hv) & np.isfinite(hu)).any()  # a finite h never leads to an infinite one
        finite = np.isfinite(hu)
        assert (hu[finite] <= hv[finite] + cost[finite] + 1e-9).all(), seed
        best = reference(ws, roadmap, diagonals=diagonals)
        start_h = h[roadmap[0].y * ws.width + roadmap[0].x]
        if best.reached:
            assert start_h <= best.time + 1e-9
        elif np.isinf(start_h):
            assert not best.reached


def test_costs_beyond_the_narrow_word_restart_with_wide_words(monkeypatch):
    ws = Workspace(np.zeros((14, 14), dtype=bool))
    roadmap = [Pose(1, 1, "O", 0), Pose(11, 10, "L", 2)]
    narrow = plan_exact(ws, roadmap)
    calls = []
    original = _lazy._bucket_search
    monkeypatch.setattr(_lazy, "_bucket_search", lambda *args: calls.append(args[18].dtype) or original(*args))
    monkeypatch.setattr(_lazy, "_WORD_BITS", 10 + 3)  # room for costs of 0..6 s only
    wide = plan_exact(ws, roadmap)
    assert wide.time == narrow.time > 6
    assert np.dtype(np.uint32) in calls and np.dtype(np.int64) in calls


def test_the_memory_budget_is_an_option_and_its_refusal_names_the_flag():
    ws = Workspace(np.zeros((60, 60), dtype=bool))
    roadmap = [Pose(2, 2, "O", 0), Pose(50, 50, "O", 0)]
    with pytest.raises(PlanningError, match="would need about") as info:
        plan_path(ws, roadmap, memory_budget="64KiB")
    message = str(info.value)
    assert "--memory-budget" in message and "set by memory_budget" in message
    assert plan_path(ws, roadmap, memory_budget="1GiB").reached
    assert plan_path(ws, roadmap, method="astar", memory_budget=2**30).reached
    assert check_bytes("8GiB", "m") == 8 * 2**30 and check_bytes("2GB", "m") == 2 * 10**9
    assert check_bytes(" 512 mib", "m") == 2**29 and check_bytes(4096, "m") == 4096
    for bad in ("8 parsecs", "", "-1GiB", 0, -5, "GiB"):
        with pytest.raises(ParameterError, match="memory_budget"):
            plan_path(ws, roadmap, memory_budget=bad)
