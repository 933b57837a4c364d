"""The graph-free search run in the interpreter, compiled, or begun in one and resumed in the other gives the
same plan, pose for pose and expansion for expansion; the small maps' distances, without scipy, are scipy's."""

import numpy as np
import pytest

from htetro_opt.errors import ConfigurationError
from htetro_opt.model import Pose, Simulator, Workspace
from htetro_opt.model.robot import STATE_NAMES
from htetro_opt.solvers.grid_paths import _exact, _lazy, plan_exact


def random_case(seed):
    """A random map of 8 to 14 cells a side and two random collision-free poses on it."""
    rng = np.random.default_rng(seed)
    w, h = (int(v) for v in rng.integers(8, 15, size=2))
    occ = rng.random((h, w)) < rng.uniform(0.05, 0.25)
    occ[:5, :5] = occ[-5:, -5:] = False
    ws = Workspace(occ)
    sim = Simulator(ws)
    poses = []
    while len(poses) < 2:
        pose = Pose(int(rng.integers(w)), int(rng.integers(h)), STATE_NAMES[int(rng.integers(7))], int(rng.integers(4)))
        try:
            sim.check_pose(pose)
        except ConfigurationError:
            continue
        poses.append(pose)
    return ws, poses


def revalidates(plan, ws, roadmap, **compile_options):
    result = Simulator(ws, **compile_options).run([plan.commands], roadmap[0], roadmap=roadmap[1:])
    assert result.valid[0] and bool(result.reached[0]) == plan.reached
    assert result.time[0] == pytest.approx(plan.time) and (result.poses(0) == plan.poses).all()


def run(monkeypatch, ws, roadmap, *, interpreted, method="astar", diagonals=False):
    """A plan with ``interpreted`` expansions in the interpreter first (0: compiled only; None: all)."""
    for kernel in (_lazy._bucket_kernel, _lazy._heap_kernel):
        monkeypatch.setattr(kernel, "loaded", lambda: False)  # as in a process that has not loaded numba yet
    monkeypatch.setattr(_lazy, "_interpreted_left", 10**9 if interpreted is None else interpreted)
    plan = plan_exact(ws, roadmap, method=method, diagonals=diagonals)
    left = _lazy._interpreted_left
    return plan, left


def same(a, b):
    assert a.reached == b.reached and a.time == b.time and a.info == b.info
    assert np.array_equal(a.commands, b.commands) and np.array_equal(a.poses, b.poses)


@pytest.mark.parametrize("method", ["astar", "dijkstra"])
@pytest.mark.parametrize("diagonals", [False, True])  # the bucket queue, the float heap
def test_interpreted_compiled_and_handed_over_searches_agree(monkeypatch, method, diagonals):
    for seed in range(4):
        ws, roadmap = random_case(seed)
        compiled, left = run(monkeypatch, ws, roadmap, interpreted=0, method=method, diagonals=diagonals)
        assert left == 0
        revalidates(compiled, ws, roadmap, diagonals=diagonals)
        best = _exact._plan_graph(ws, roadmap, method="dijkstra", diagonals=diagonals, commands=None, timing=None,
                                  clearance=0.0, t0=0)
        assert compiled.reached == best.reached and compiled.time == pytest.approx(best.time)
        expanded = compiled.info["expanded"]
        plan, left = run(monkeypatch, ws, roadmap, interpreted=None, method=method, diagonals=diagonals)
        same(plan, compiled)
        assert left == 10**9 - expanded  # every expansion in the interpreter
        for k in (1, 7, expanded // 2):  # handed over to the compiled kernel after k expansions
            plan, left = run(monkeypatch, ws, roadmap, interpreted=k, method=method, diagonals=diagonals)
            same(plan, compiled)
            assert left == (0 if expanded > k else k - expanded)


def test_the_queue_grows_in_the_interpreter_too(monkeypatch):
    ws = Workspace(np.zeros((12, 12), dtype=bool))
    roadmap = [Pose(1, 1, "O", 0), Pose(9, 8, "L", 2)]
    monkeypatch.setattr(_lazy, "BLOCK", 2)  # a pool of 64 blocks of 2 entries: the frontier outgrows it
    grown = []
    original = _lazy._run

    def spy(kernel, args, *rest):
        original(kernel, args, *rest)
        grown.append(int(args[0][0]))

    monkeypatch.setattr(_lazy, "_run", spy)
    compiled, _ = run(monkeypatch, ws, roadmap, interpreted=0, method="dijkstra")
    assert grown.count(_lazy._GROW) >= 1
    for k in (None, 50):
        grown.clear()
        plan, _ = run(monkeypatch, ws, roadmap, interpreted=k, method="dijkstra")
        same(plan, compiled)
        assert grown.count(_lazy._GROW) >= 1


def test_the_small_maps_distances_are_scipys():
    from scipy.ndimage import distance_transform_cdt
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import dijkstra

    from htetro_opt.model.workspace import _breadth_first, grid_distance

    rng = np.random.default_rng(5)
    for trial in range(40):
        h, w = (int(v) for v in rng.integers(1, 30, size=2))
        free = rng.random((h, w)) > rng.uniform(0.0, 0.6)
        m = int(rng.integers(1, 4))
        framed = np.zeros((h + 2 * m, w + 2 * m), dtype=np.uint8)
        framed[m : m + h, m : m + w] = free
        want = np.minimum(distance_transform_cdt(framed, metric="chessboard"), 255)
        assert np.array_equal(_lazy._chessboard_by_erosion(framed), want), trial
        if not free.any():
            continue
        gy, gx = (int(v[0]) for v in np.nonzero(free))
        index = np.arange(h * w).reshape(h, w)  # the 4-connected graph, as scipy's Dijkstra sees it
        right, up = free[:, :-1] & free[:, 1:], free[:-1] & free[1:]
        rows = np.concatenate([index[:, :-1][right], index[:-1][up]])
        cols = np.concatenate([index[:, 1:][right], index[1:][up]])
        graph = coo_matrix((np.ones(len(rows)), (rows, cols)), shape=(h * w, h * w)).tocsr()
        want = dijkstra(graph, directed=False, indices=int(index[gy, gx])).reshape(h, w)
        assert np.array_equal(_breadth_first(free, gx, gy), want), trial
        assert np.array_equal(grid_distance(Workspace(~free), (gx, gy)), want), trial
    open_map = np.zeros((600, 600), dtype=np.uint8)  # beyond 255: saturated as the planner saturates scipy's
    open_map[1:-1, 1:-1] = 1
    assert int(_lazy._chessboard_by_erosion(open_map).max()) == 255


def walled_in(side=28):
    """A map whose goal room no shape can enter: Dijkstra's search reaches every other pose (its worst case),
    with 21,952 poses, within _INTERPRETED_POSES (the figure of _INTERPRETED_BYTES is the 34 x 34 map's)."""
    occ = np.zeros((side, side), dtype=bool)
    occ[side - 14 : side - 4, side - 14 : side - 4] = True
    occ[side - 11 : side - 7, side - 11 : side - 7] = False
    return Workspace(occ), [Pose(2, 2, "O", 0), Pose(side - 10, side - 10, "O", 0)]


def test_the_interpreters_lists_stay_within_the_estimate_and_the_budget(monkeypatch):
    import tracemalloc

    ws, roadmap = walled_in()
    space = _lazy.PoseSpace.build(ws)
    assert space.n_poses <= _lazy._INTERPRETED_POSES
    run(monkeypatch, Workspace(np.zeros((8, 8), dtype=bool)), [Pose(2, 2, "O", 0), Pose(4, 4, "O", 0)],
        interpreted=None, method="dijkstra")  # the first call's imports and tables, outside the trace
    monkeypatch.setattr(_lazy, "_interpreted_left", 10**9)
    tracemalloc.start()
    try:
        plan = plan_exact(ws, roadmap, method="dijkstra")
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert not plan.reached and _lazy._interpreted_left == 10**9 - plan.info["expanded"]  # all interpreted
    assert peak <= _lazy.lazy_bytes(space.n_poses, space.n_cells, space.durations) + _lazy._INTERPRETED_BYTES
    # a budget with no room for the lists: compiled from the start, the same search
    tight = _lazy.lazy_bytes(space.n_poses, space.n_cells, space.durations) + _lazy._INTERPRETED_BYTES // 2
    monkeypatch.setattr(_lazy, "_interpreted_left", 10**9)
    compiled = plan_exact(ws, roadmap, method="dijkstra", memory_budget=tight)
    assert _lazy._interpreted_left == 10**9
    same(compiled, plan)


def test_a_larger_pose_space_is_searched_compiled_from_the_start(monkeypatch):
    ws = Workspace(np.zeros((40, 40), dtype=bool))  # 44,800 poses
    roadmap = [Pose(2, 2, "O", 0), Pose(30, 30, "O", 0)]
    plan, left = run(monkeypatch, ws, roadmap, interpreted=None)
    assert plan.reached and left == 10**9
