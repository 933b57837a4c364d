"""The baselines of Le et al. 2018: zigzag and spiral patterns, and the randomised greedy search."""

from itertools import pairwise

import numpy as np
import pytest

from htetro_opt.errors import ParameterError
from htetro_opt.problems.waypoint_sequencing import SequencingInstance, cost_matrix
from htetro_opt.scenarios import load_tileset, parse_tileset, tileset_path
from htetro_opt.solvers.sequencing import (
    PATTERN_VARIANTS,
    sequence_waypoints,
    solve_greedy,
    solve_spiral,
    solve_zigzag,
)

# The canonical patterns and the grid's symmetries have no public name: the tests below check that
# the solvers pick the cheapest of the eight variants these generate.
from htetro_opt.solvers.sequencing._baselines import (
    _SYMMETRIES,
    _spiral_canonical,
    _transform,
    _zigzag_canonical,
)

# Le et al. 2018, Fig. 14: the 11 x 11 map with obstacles, 28 tiles (labels as printed, some tiles by another
# chain convention than ours)
FIG14 = tileset_path("paper_11x11_fig13d")  # the paper's Figs. 13d and 14

PATTERNS = [(solve_zigzag, 1), (solve_zigzag, 2), (solve_spiral, 1), (solve_spiral, 2)]


@pytest.fixture(scope="module")
def fig14():
    return load_tileset(FIG14)


def point_instance(cells, shape, start=0):
    """An instance whose four blocks sit on one cell per waypoint: the patterns see block b only."""
    cells = np.asarray(cells, dtype=np.int64)
    blocks = np.repeat(cells[:, None, :], 4, axis=1)
    return SequencingInstance(cost_matrix(blocks), blocks, start, shape=shape)


def ring_of(cells, shape, rows):
    h, w = shape
    x, y = cells[:, 0], cells[:, 1]
    return np.minimum.reduce([x, y, w - 1 - x, h - 1 - y]) // rows


def test_variant_names_are_the_eight_corner_direction_pairs():
    assert len(set(PATTERN_VARIANTS)) == 8
    assert PATTERN_VARIANTS[0] == "top-left, right"
    corners = {name.split(",")[0] for name in PATTERN_VARIANTS}
    assert corners == {"top-left", "top-right", "bottom-left", "bottom-right"}


@pytest.mark.parametrize("canonical", [_zigzag_canonical, _spiral_canonical])
@pytest.mark.parametrize("rows", [1, 2, 3])
def test_every_variant_is_a_permutation(fig14, canonical, rows):
    cells = fig14.blocks[:, 1]
    for symmetry in _SYMMETRIES:
        seen, shape = _transform(cells, fig14.occupancy.shape, *symmetry)
        assert seen.min() >= 0 and (seen.max(axis=0) < shape[::-1]).all()
        order = canonical(seen, shape, rows)
        assert sorted(order.tolist()) == list(range(len(fig14)))


@pytest.mark.parametrize("solver, rows", PATTERNS)
def test_pattern_orders_begin_at_every_start_and_are_permutations(fig14, solver, rows):
    for start in (None,) + fig14.ids:
        inst = SequencingInstance.from_tileset(fig14, start=start)
        order, info = solver(inst, rows=rows)
        inst.check_order(order)  # a permutation, from the start when fixed
        assert order.dtype == np.int64
        assert info["rows"] == rows and info["variant"] in PATTERN_VARIANTS
        assert ("start_moved" in info) == (start is not None)


@pytest.mark.parametrize("canonical, solver", [(_zigzag_canonical, solve_zigzag), (_spiral_canonical, solve_spiral)])
@pytest.mark.parametrize("rows", [1, 2])
def test_the_cheapest_fitting_variant_is_chosen(fig14, canonical, solver, rows):
    cells = fig14.blocks[:, 1]
    variants = [canonical(*_transform(cells, fig14.occupancy.shape, *s), rows) for s in _SYMMETRIES]
    free = SequencingInstance.from_tileset(fig14, start=None)
    order, info = solver(free, rows=rows)
    assert free.path_cost(order) == pytest.approx(min(free.path_cost(v) for v in variants))
    assert order.tolist() == variants[PATTERN_VARIANTS.index(info["variant"])].tolist()
    for start in fig14.ids:
        inst = SequencingInstance.from_tileset(fig14, start=start)
        order, info = solver(inst, rows=rows)
        fitting = [v for v in variants if v[0] == inst.start]
        if fitting:
            assert not info["start_moved"]
            assert inst.path_cost(order) == pytest.approx(min(inst.path_cost(v) for v in fitting))
        else:  # the start moved to the front of the chosen variant, the rest in its order
            assert info["start_moved"]
            chosen = variants[PATTERN_VARIANTS.index(info["variant"])]
            assert order[1:].tolist() == [i for i in chosen.tolist() if i != inst.start]


def test_zigzag_one_row_sweeps_left_to_right_then_right_to_left():
    # two rows of vertical I tiles (b second from the bottom): the row-wise zigzag is the cheapest
    ts = parse_tileset("""
        1d 2d 3d 4d
        1c 2c 3c 4c
        1b 2b 3b 4b
        1a 2a 3a 4a
        5d 6d 7d 8d
        5c 6c 7c 8c
        5b 6b 7b 8b
        5a 6a 7a 8a
    """)
    order, info = solve_zigzag(SequencingInstance.from_tileset(ts, start=1), rows=1)
    assert [ts.ids[i] for i in order] == [1, 2, 3, 4, 8, 7, 6, 5]
    assert info == {"rows": 1, "variant": "top-left, right", "start_moved": False}
    # from the other end of the top row the mirrored variant is taken
    order, info = solve_zigzag(SequencingInstance.from_tileset(ts, start=4), rows=1)
    assert [ts.ids[i] for i in order] == [4, 3, 2, 1, 5, 6, 7, 8]
    assert info["variant"] == "top-right, left"


def test_zigzag_skips_empty_rows_when_alternating():
    # reference cells on rows 5 and 1 only: the second non-empty band still runs right to left
    ts = parse_tileset("""
        1d 2d 3d
        1c 2c 3c
        1b 2b 3b
        1a 2a 3a
        4d 5d 6d
        4c 5c 6c
        4b 5b 6b
        4a 5a 6a
    """)
    order, _ = solve_zigzag(SequencingInstance.from_tileset(ts, start=1), rows=1)
    assert [ts.ids[i] for i in order] == [1, 2, 3, 6, 5, 4]


def test_zigzag_two_rows_sweeps_each_band_column_by_column_nearest_first():
    w, h = 6, 4
    cells = [(x, y) for y in range(h) for x in range(w)]
    inst = point_instance(cells, (h, w), start=cells.index((0, 3)))
    order, info = solve_zigzag(inst, rows=2)
    visited = [cells[i] for i in order]
    expected = [(0, 3), (0, 2), (1, 2), (1, 3), (2, 3), (2, 2), (3, 2), (3, 3), (4, 3), (4, 2), (5, 2), (5, 3),
                (5, 1), (5, 0), (4, 0), (4, 1), (3, 1), (3, 0), (2, 0), (2, 1), (1, 1), (1, 0), (0, 0), (0, 1)]
    assert visited == expected
    assert info["variant"] == "top-left, right"


def test_spiral_walks_each_ring_clockwise_from_its_top_left():
    w, h = 5, 4
    cells = np.array([(x, y) for y in range(h) for x in range(w)])
    order = _spiral_canonical(cells, (h, w), 1)
    visited = [tuple(cells[i]) for i in order]
    assert visited == [(0, 3), (1, 3), (2, 3), (3, 3), (4, 3), (4, 2), (4, 1), (4, 0), (3, 0), (2, 0), (1, 0),
                       (0, 0), (0, 1), (0, 2), (1, 2), (2, 2), (3, 2), (3, 1), (2, 1), (1, 1)]


@pytest.mark.parametrize("rows", [1, 2])
def test_spiral_visits_outer_rings_before_inner_ones(fig14, rows):
    rings = ring_of(fig14.blocks[:, 1], fig14.occupancy.shape, rows)
    assert len(set(rings.tolist())) > 1
    for start in (None,) + fig14.ids:
        inst = SequencingInstance.from_tileset(fig14, start=start)
        order, info = solve_spiral(inst, rows=rows)
        tail = order[1:] if info.get("start_moved") else order
        assert np.all(np.diff(rings[tail]) >= 0), (start, rings[order].tolist())


def test_spiral_on_a_full_grid_is_a_unit_step_walk_except_between_rings():
    w, h = 6, 6
    cells = [(x, y) for y in range(h) for x in range(w)]
    inst = point_instance(cells, (h, w), start=None)
    order, _ = solve_spiral(inst, rows=1)
    steps = np.abs(np.diff(np.array(cells)[order], axis=0)).sum(axis=1)
    assert (steps == 1).sum() >= len(cells) - 3  # 3 ring changes at most cost more than one cell


@pytest.mark.parametrize("solver", [solve_zigzag, solve_spiral])
@pytest.mark.parametrize("rows", [0, -1, 1.5, True, "2"])
def test_bad_rows_raise(fig14, solver, rows):
    with pytest.raises(ParameterError, match="rows"):
        solver(SequencingInstance.from_tileset(fig14), rows=rows)


def naive_nearest_neighbour(cost, start):
    """Always on to the cheapest unvisited waypoint, ties to the lowest index (a plain loop)."""
    order, left = [start], set(range(len(cost))) - {start}
    while left:
        nxt = min(left, key=lambda j: (cost[order[-1], j], j))
        order.append(nxt)
        left.remove(nxt)
    return order


def random_instance(n, seed, start=0):
    rng = np.random.default_rng(seed)
    blocks = rng.integers(0, 40, size=(n, 4, 2))
    return SequencingInstance(cost_matrix(blocks), blocks, start, shape=(40, 40))


@pytest.mark.parametrize("seed", range(5))
def test_greedy_one_iteration_is_the_nearest_neighbour_path(seed):
    inst = random_instance(25, seed, start=seed)  # random real costs: no ties
    order, info = solve_greedy(inst, iterations=1, seed=seed)
    assert order.tolist() == naive_nearest_neighbour(inst.cost, inst.start)
    assert info["iterations_run"] == 1 and info["best_iteration"] == 0


def test_greedy_one_iteration_with_ties_is_a_nearest_neighbour_path_up_to_ties(fig14):
    inst = SequencingInstance.from_tileset(fig14, start=1)
    for seed in range(5):
        order, _ = solve_greedy(inst, iterations=1, seed=seed)
        inst.check_order(order)
        left = set(range(inst.n)) - {int(order[0])}
        for here, nxt in pairwise(order):
            assert inst.cost[here, nxt] == pytest.approx(min(inst.cost[here, j] for j in left))
            left.remove(int(nxt))


@pytest.mark.parametrize("start", [1, None])
def test_greedy_more_iterations_is_never_worse_and_is_reproducible(fig14, start):
    inst = SequencingInstance.from_tileset(fig14, start=start)
    for seed in (0, 1):
        costs = []
        for iterations in (1, 3, 30, 300, 3000):
            order, info = solve_greedy(inst, iterations=iterations, seed=seed)
            inst.check_order(order)
            again, _ = solve_greedy(inst, iterations=iterations, seed=seed)
            assert again.tolist() == order.tolist()
            assert info["iterations_run"] == iterations
            costs.append(inst.path_cost(order))
        assert all(b <= a + 1e-12 for a, b in pairwise(costs)), costs


def test_greedy_free_start_tries_random_starts_and_never_loses_to_its_nearest_neighbour_paths():
    inst = random_instance(12, 7, start=None)
    order, _ = solve_greedy(inst, iterations=400, seed=3)
    inst.check_order(order)
    best_nn = min(inst.path_cost(naive_nearest_neighbour(inst.cost, s)) for s in range(inst.n))
    assert inst.path_cost(order) <= best_nn + 1e-9  # 400 random starts cover all 12 with near certainty


def test_greedy_tiny_instances():
    one = random_instance(1, 0, start=0)
    assert solve_greedy(one)[0].tolist() == [0]
    two = random_instance(2, 0, start=1)
    assert solve_greedy(two)[0].tolist() == [1, 0]
    three = random_instance(3, 0, start=None)
    three.check_order(solve_greedy(three, iterations=5)[0])


def test_greedy_honours_a_time_limit():
    inst = random_instance(300, 1, start=0)
    order, info = solve_greedy(inst, iterations=10**6, time_limit=0.01)
    inst.check_order(order)
    assert 1 <= info["iterations_run"] < 10**6


@pytest.mark.parametrize("iterations", [0, -5, 2.5, True, None])
def test_greedy_bad_iterations_raise(fig14, iterations):
    with pytest.raises(ParameterError, match="iterations"):
        solve_greedy(SequencingInstance.from_tileset(fig14), iterations=iterations)


@pytest.mark.parametrize("bad", [0, -1.0, float("inf"), float("nan"), "1", True])
def test_greedy_bad_time_limit_raises(fig14, bad):
    with pytest.raises(ParameterError, match="time_limit"):
        solve_greedy(SequencingInstance.from_tileset(fig14), time_limit=bad)


def eq2_cost(tileset, tiles):
    """Eq. 2 at equal weights summed along an order of tile labels, block by block (by hand)."""
    blocks = {t: np.asarray(b, dtype=float) for t, b in zip(tileset.ids, tileset.blocks)}
    return sum(0.25 * float(np.hypot(*(blocks[a][k] - blocks[b][k]))) for a, b in pairwise(tiles) for k in range(4))


@pytest.mark.parametrize("name", ["zigzag", "zigzag2", "spiral", "spiral2", "greedy"])
def test_dispatcher_runs_every_baseline(fig14, name):
    inst = SequencingInstance.from_tileset(fig14, start=5)
    options = {"iterations": 200, "seed": 2} if name == "greedy" else {}  # the patterns draw from no seed
    result = sequence_waypoints(inst, method=name, **options)
    assert result.method == name
    assert result.tiles[0] == 5 and sorted(result.tiles) == sorted(fig14.ids)
    assert result.cost == pytest.approx(eq2_cost(fig14, result.tiles))
    if name == "greedy":
        assert result.info["iterations_run"] == 200
    else:
        assert result.info["rows"] == (2 if name.endswith("2") else 1)


def test_greedy_beats_the_patterns_on_the_papers_map(fig14):
    # Table 1's ranking (greedy below zigzag and spiral); the costs themselves differ from the paper's
    inst = SequencingInstance.from_tileset(fig14, start=1)
    greedy = inst.path_cost(solve_greedy(inst, iterations=2000)[0])
    for solver, rows in PATTERNS:
        assert greedy < inst.path_cost(solver(inst, rows=rows)[0])
