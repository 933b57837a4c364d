"""Waypoints (Algorithm 1 of Le et al. 2018), the eq.-2 cost and the sequencing instance / pymoo problem."""

import itertools
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from htetro_opt.errors import ParameterError, PlanningError, TilesetFormatError
from htetro_opt.model.robot import Pose
from htetro_opt.model.tiles import tile_poses
from htetro_opt.problems import (
    DEFAULT_BLOCK_WEIGHTS,
    SequencingInstance,
    SequencingProblem,
    block_locations,
    check_weights,
    cost_matrix,
    path_cost,
)
from htetro_opt.scenarios import Tileset, parse_tileset

points = st.lists(st.tuples(st.integers(0, 9), st.integers(0, 9)), min_size=2, max_size=6)


@settings(max_examples=30, deadline=None)
@given(st.lists(st.lists(st.tuples(st.integers(0, 9), st.integers(0, 9)), min_size=4, max_size=4), min_size=2, max_size=5),
       st.lists(st.floats(0, 1), min_size=4, max_size=4).filter(lambda w: sum(w) > 0))
def test_cost_is_the_weighted_sum_of_block_displacements(blocks, weights):
    cost = cost_matrix(blocks, weights)
    b = np.array(blocks, float)
    for i, j in itertools.product(range(len(b)), repeat=2):
        expected = sum(w * np.hypot(*(b[i, l] - b[j, l])) for l, w in enumerate(weights))
        assert cost[i, j] == pytest.approx(expected)
    assert np.allclose(cost, cost.T) and np.allclose(np.diag(cost), 0)


def test_default_weights_count_every_block_alike():
    assert DEFAULT_BLOCK_WEIGHTS == (0.25, 0.25, 0.25, 0.25)
    # an I tile lying flat, then stood up around its second block: blocks a–d move √2, 0, √2, 2√2…
    flat = [(0, 1), (1, 1), (2, 1), (3, 1)]
    upright = [(1, 2), (1, 1), (1, 0), (1, -1)]
    moved = [math.dist(a, b) for a, b in zip(flat, upright)]
    # …so the default cost is their mean
    assert cost_matrix([flat, upright])[0, 1] == pytest.approx(sum(moved) / 4)


def test_path_cost_sums_consecutive_legs_for_one_order_and_for_a_batch():
    cost = np.array([[0, 1, 5], [1, 0, 2], [5, 2, 0]], float)
    assert path_cost(cost, [2, 1, 0]) == 3.0
    assert path_cost(cost, [[0, 2, 1], [1, 0, 2]]).tolist() == [7.0, 6.0]


@pytest.mark.parametrize("weights", [[0.25] * 3, [-1, 1, 0, 0], [0, 0, 0, 0], [np.nan, 1, 0, 0], "abc"])
def test_bad_weights_are_parameter_errors(weights):
    with pytest.raises(ParameterError, match="weights"):
        check_weights(weights)


def test_algorithm1_numbers_tiles_in_scan_order_and_labels_them_by_footprints():
    # a 4 x 2 strip: two O tiles, listed in reverse order
    tiles = [[(2, 0), (3, 0), (2, 1), (3, 1)], [(0, 0), (1, 0), (0, 1), (1, 1)]]
    ts = block_locations(np.zeros((2, 4), bool), tiles)
    assert ts.ids == (1, 2)
    assert ts.blocks[0, :, 0].max() == 1  # tile 1 is the left square
    assert all(p is not None for p in ts.poses)


def test_algorithm1_picks_the_option_nearest_the_previous_waypoint():
    # an L (one option) then, right of it, an O (four options): the O takes the option of least eq.-2
    # cost to the L's blocks (eq. 3)
    l_cells = Pose(0, 0, "L", 0).cells()  # (1,0) (0,0) (0,1) (0,2): first in scan order at (0, 2)
    o_cells = [(2, 1), (3, 1), (2, 2), (3, 2)]  # first in scan order at (2, 2): tile 2
    ts = block_locations(np.zeros((3, 4), bool), [o_cells, l_cells])
    assert ts.shapes == ("L", "O")
    options = np.array([p.cells() for p in tile_poses(o_cells)], float)
    costs = np.sqrt(((options - ts.blocks[0]) ** 2).sum(-1)).mean(-1)
    assert len(set(np.round(costs, 9))) > 1  # the choice matters here
    assert np.array_equal(ts.blocks[1], options[np.argmin(costs)])


def test_algorithm1_follows_the_previous_tile_in_scan_order_through_a_chain_of_symmetric_tiles():
    # three horizontal I tiles stacked: each one should copy its predecessor's heading (all blocks move 1 cell)
    tiles = [[(x, y) for x in range(4)] for y in range(3)]
    ts = block_locations(np.zeros((3, 4), bool), tiles)
    assert len({p.heading for p in ts.poses}) == 1
    inst = SequencingInstance.from_tileset(ts)
    assert inst.path_cost([0, 1, 2]) == pytest.approx(2.0)


def test_instance_from_tileset_knows_its_start_and_checks_orders():
    ts = parse_tileset("1a 1b 1c 1d\n2a 2b 2c 2d\n3a 3b 3c 3d")
    inst = SequencingInstance.from_tileset(ts, start=2)
    assert inst.start == 1 and inst.n == 3 and inst.ids == (1, 2, 3)
    assert inst.check_order([1, 0, 2]).tolist() == [1, 0, 2]
    assert inst.tile_order([1, 0, 2]) == [2, 1, 3]
    with pytest.raises(PlanningError, match="begin at tile 2"):
        inst.check_order([0, 1, 2])
    with pytest.raises(PlanningError, match="exactly once"):
        inst.check_order([1, 1, 2])
    with pytest.raises(TilesetFormatError, match="no tile 7"):
        SequencingInstance.from_tileset(ts, start=7)
    assert SequencingInstance.from_tileset(ts, start=None).start is None
    with pytest.raises(PlanningError, match="no tiles"):
        SequencingInstance.from_tileset(Tileset(np.zeros((2, 2), bool), np.empty((0, 4, 2)), ()))


@pytest.mark.parametrize("start", [3, -1, 1.0, True, "0"])
def test_instance_refuses_a_start_that_is_no_waypoint_index(start):
    with pytest.raises(ParameterError, match=f"start must be an integer in \\[0, 2\\] or None, got {start!r}"):
        SequencingInstance(np.zeros((3, 3)), np.zeros((3, 4, 2)), start)
    assert SequencingInstance(np.zeros((3, 3)), np.zeros((3, 4, 2)), np.int64(2)).start == 2


@pytest.mark.parametrize("options,words", [
    ({"blocks": np.zeros((2, 4, 2))}, "blocks must hold the cells of the 3 waypoints"),
    ({"blocks": np.zeros((3, 4, 2)), "ids": (1, 2)}, "need one tile id per waypoint (3)"),
    ({"blocks": np.zeros((3, 4, 2)), "shape": (4,)}, "grid shape (H, W)"),
    ({"blocks": np.zeros((3, 4, 2)), "ids": ("a", "b", "c")}, "tile id must be an integer, got 'a'"),
])
def test_instance_refuses_parts_that_do_not_match_its_cost_matrix(options, words):
    with pytest.raises(ParameterError) as info:
        SequencingInstance(np.zeros((3, 3)), **options)
    assert words in str(info.value)


@pytest.mark.parametrize("order", ["abc", [0.0, 1.0, 2.0], None, [[0, 1], [2]]])
def test_an_order_that_is_not_indices_is_a_planning_error(order):
    inst = SequencingInstance(np.zeros((3, 3)), np.zeros((3, 4, 2)), 0)
    with pytest.raises(PlanningError, match="an order must be waypoint indices"):
        inst.check_order(order)


def walk(points, order):
    """Length of the walk through the points in this order (by hand: every block sits on the point)."""
    return sum(math.dist(points[a], points[b]) for a, b in itertools.pairwise(order))


def test_pymoo_problem_evaluates_path_costs_from_the_fixed_start():
    rng = np.random.default_rng(1)
    pts = rng.integers(0, 20, size=(6, 2))
    blocks = np.repeat(pts[:, None, :], 4, axis=1)
    inst = SequencingInstance(cost_matrix(blocks), blocks, start=3)
    problem = SequencingProblem(inst)
    assert problem.n_var == 5
    perms = np.array([rng.permutation(5) for _ in range(8)])
    orders = problem.order(perms)
    others = [0, 1, 2, 4, 5]  # the variables index the waypoints other than the start
    assert orders.tolist() == [[3] + [others[i] for i in p] for p in perms.tolist()]
    assert np.allclose(problem.evaluate(perms)[:, 0], [walk(pts.tolist(), o) for o in orders.tolist()])


def test_pymoo_problem_prices_a_closed_tour_and_an_implicit_instance_by_hand():
    rng = np.random.default_rng(4)
    pts = rng.integers(0, 20, size=(6, 2))
    blocks = np.repeat(pts[:, None, :], 4, axis=1)
    perms = np.array([rng.permutation(5) for _ in range(8)])
    closed = SequencingInstance(cost_matrix(blocks), blocks, start=0, closed=True)
    problem = SequencingProblem(closed)
    tours = [o + [o[0]] for o in problem.order(perms).tolist()]  # back to the first waypoint
    assert np.allclose(problem.evaluate(perms)[:, 0], [walk(pts.tolist(), t) for t in tours])
    implicit = SequencingInstance(None, blocks, start=0)
    assert implicit.implicit
    problem = SequencingProblem(implicit)
    assert np.allclose(problem.evaluate(perms)[:, 0],
                       [walk(pts.tolist(), o) for o in problem.order(perms).tolist()])


def test_pymoo_ga_runs_on_the_problem_and_its_best_order_is_valid():
    from pymoo.algorithms.soo.nonconvex.ga import GA
    from pymoo.operators.crossover.ox import OrderCrossover
    from pymoo.operators.mutation.inversion import InversionMutation
    from pymoo.operators.sampling.rnd import PermutationRandomSampling
    from pymoo.optimize import minimize

    rng = np.random.default_rng(3)
    blocks = np.repeat(rng.integers(0, 10, size=(7, 2))[:, None, :], 4, axis=1)
    inst = SequencingInstance(cost_matrix(blocks), blocks, start=0)
    problem = SequencingProblem(inst)
    algorithm = GA(pop_size=20, sampling=PermutationRandomSampling(), crossover=OrderCrossover(),
                   mutation=InversionMutation(), eliminate_duplicates=True)
    res = minimize(problem, algorithm, ("n_gen", 40), seed=1)
    order = inst.check_order(problem.order(res.X)).tolist()
    points = blocks[:, 0].tolist()
    brute = min(walk(points, (0,) + p) for p in itertools.permutations(range(1, 7)))
    # 40 generations of 20 on 6! = 720 orders: the GA finds the optimum, and reports its cost
    assert walk(points, order) == pytest.approx(brute)
    assert res.F[0] == pytest.approx(brute)


# ---------------------------------------------------------------- implicit (matrix-free) instances
def _random_tileset_blocks(n, seed):
    rng = np.random.default_rng(seed)
    return rng.integers(0, 60, size=(n, 4, 2))


def test_cost_matrix_in_row_blocks_equals_the_formula_entry_by_entry(monkeypatch):
    import htetro_opt.problems.waypoint_sequencing as ws

    blocks = _random_tileset_blocks(23, 0)
    w = (0.1, 0.2, 0.3, 0.4)
    C = cost_matrix(blocks, w)
    for i, j in [(0, 1), (5, 17), (22, 3), (9, 9)]:
        expected = sum(w[l] * math.dist(blocks[i, l], blocks[j, l]) for l in range(4))
        assert C[i, j] == pytest.approx(expected)
    assert np.allclose(ws.eq2_legs(blocks, w, [0, 5, 22], [1, 17, 3]), C[[0, 5, 22], [1, 17, 3]])


def test_implicit_instance_prices_like_the_dense_one():
    from htetro_opt.problems.waypoint_sequencing import DENSE_LIMIT

    ts = parse_tileset("1a 1b 1c 1d\n2a 2b 2c 2d\n3a 3b 3c 3d\n4d 4c 4b 4a")
    dense = SequencingInstance.from_tileset(ts, start=2)
    implicit = SequencingInstance.from_tileset(ts, start=2, dense=False)
    assert dense.cost is not None and not dense.implicit and implicit.cost is None and implicit.implicit
    assert len(ts) <= DENSE_LIMIT and implicit.n == dense.n == 4 and implicit.symmetric
    rng = np.random.default_rng(1)
    for _ in range(5):
        order = np.concatenate([[1], rng.permutation([0, 2, 3])])
        priced = sum(dense.cost[a, b] for a, b in itertools.pairwise(order))
        assert implicit.path_cost(order) == pytest.approx(priced) == pytest.approx(dense.path_cost(order))
    closed = SequencingInstance(None, ts.blocks, 0, closed=True, weights=(0, 1, 0, 0))
    b = ts.blocks[:, 1]  # weights (0, 1, 0, 0): block b's walk, back to the first
    assert closed.path_cost([0, 1, 2, 3]) == pytest.approx(sum(math.dist(b[i], b[(i + 1) % 4]) for i in range(4)))


def test_from_tileset_keeps_the_costs_implicit_above_the_dense_limit(monkeypatch):
    import htetro_opt.problems.waypoint_sequencing as ws

    ts = parse_tileset("1a 1b 1c 1d\n2a 2b 2c 2d\n3a 3b 3c 3d")
    monkeypatch.setattr(ws, "DENSE_LIMIT", 2)
    assert SequencingInstance.from_tileset(ts).implicit
    assert not SequencingInstance.from_tileset(ts, dense=True).implicit
    monkeypatch.setattr(ws, "DENSE_LIMIT", 3)
    assert not SequencingInstance.from_tileset(ts).implicit


def test_implicit_instances_refuse_what_needs_a_matrix():
    from htetro_opt.problems.waypoint_sequencing import reduce_to_open_path

    ts = parse_tileset("1a 1b 1c 1d\n2a 2b 2c 2d\n3a 3b 3c 3d")
    implicit = SequencingInstance.from_tileset(ts, dense=False)
    with pytest.raises(ParameterError, match="implicit"):
        reduce_to_open_path(implicit)
    with pytest.raises(PlanningError, match="block cells"):
        SequencingInstance(None)
    with pytest.raises(ParameterError, match="dense"):
        SequencingInstance.from_tileset(ts, dense="yes")
    with pytest.raises(ParameterError, match="weights"):
        SequencingInstance(None, ts.blocks, weights=(1, 2))
    with pytest.raises(ParameterError, match="order"):
        implicit.path_cost([0, 1, 7])
