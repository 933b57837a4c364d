"""The one nearest-neighbour construction and its three users: ``nearest_neighbour`` (the ``local``
method's start), the exact solver's CP-SAT hint and the ``greedy`` baseline — each checked against a
plain-loop nearest neighbour written here."""

import re
from itertools import pairwise

import numpy as np
import pytest

from htetro_opt.errors import ParameterError
from htetro_opt.problems.waypoint_sequencing import SequencingInstance, cost_matrix
from htetro_opt.scenarios import load_tileset, tileset_path
from htetro_opt.solvers.sequencing import (
    nearest_neighbour,
    nearest_neighbour_paths,
    solve_exact,
    solve_greedy,
    solve_local,
)


def naive_nearest_neighbour(cost, start, priority=None, second=None, tol=0.0):
    """Always on to the cheapest unvisited waypoint: ties (within ``tol`` of the cheapest) to the
    lowest priority, then to the lowest index; ``second`` forced as the second waypoint."""
    n = len(cost)
    priority = np.zeros(n) if priority is None else priority
    order, left = [start], set(range(n)) - {start}
    while left:
        here = order[-1]
        if len(order) == 1 and second is not None:
            nxt = second
        else:
            cheapest = min(cost[here][j] for j in left)
            tied = [j for j in left if cost[here][j] <= cheapest + tol * (1 + abs(cheapest))]
            nxt = min(tied, key=lambda j: (priority[j], j))
        order.append(nxt)
        left.remove(nxt)
    return order


def leg_sum(cost, order):
    return sum(float(cost[a][b]) for a, b in pairwise(order))


def point_instance(points, start):
    """Waypoints whose four blocks share one cell: eq. 2 is the Euclidean distance between points."""
    blocks = np.repeat(np.asarray(points, dtype=np.int64)[:, None, :], 4, axis=1)
    return SequencingInstance(cost_matrix(blocks), blocks, start)


@pytest.fixture(scope="module")
def fig14():
    return load_tileset(tileset_path("paper_11x11_fig13d"))


# ------------------------------------------------------------------------------------- the core
def test_core_builds_one_nearest_neighbour_path_per_first_waypoint():
    rng = np.random.default_rng(0)
    cells = rng.integers(0, 5, size=(15, 4, 2))  # many exact ties
    cost = cost_matrix(cells)
    paths = nearest_neighbour_paths(cost, np.arange(15))
    assert paths.shape == (15, 15) and paths.dtype == np.int64
    for first, path in enumerate(paths.tolist()):
        assert path == naive_nearest_neighbour(cost, first)


def test_core_breaks_ties_by_priority_within_the_tolerance_and_forces_second_waypoints():
    rng = np.random.default_rng(1)
    cells = rng.integers(0, 4, size=(12, 4, 2))
    cost = cost_matrix(cells)
    firsts = rng.integers(0, 12, 40)
    priority = rng.random((40, 12))
    seconds = np.where(rng.random(40) < 0.5, (firsts + rng.integers(1, 12, 40)) % 12, -1)
    paths = nearest_neighbour_paths(cost, firsts, seconds=seconds, priority=priority)
    for r in range(40):
        expected = naive_nearest_neighbour(cost, int(firsts[r]), priority[r],
                                           None if seconds[r] < 0 else int(seconds[r]), tol=1e-9)
        assert paths[r].tolist() == expected


def test_core_on_the_documented_line():
    line = np.abs(np.subtract.outer([0.0, 3, 1, 7], [0.0, 3, 1, 7]))
    assert nearest_neighbour_paths(line, [1, 3]).tolist() == [[1, 2, 0, 3], [3, 1, 2, 0]]
    assert nearest_neighbour_paths(line, [0], seconds=[3]).tolist() == [[0, 3, 1, 2]]
    assert nearest_neighbour_paths(line, []).shape == (0, 4)


@pytest.mark.parametrize("kwargs, word", [
    ({"firsts": [4]}, "firsts"), ({"firsts": [0.5]}, "firsts"), ({"firsts": [[0]]}, "firsts"),
    ({"firsts": [0], "seconds": [0]}, "seconds"), ({"firsts": [0], "seconds": [1, 2]}, "seconds"),
    ({"firsts": [0], "seconds": [7]}, "seconds"), ({"firsts": [0, 1], "priority": np.zeros((1, 4))}, "priority"),
])
def test_core_refuses_bad_arguments_naming_them(kwargs, word):
    line = np.abs(np.subtract.outer([0.0, 3, 1, 7], [0.0, 3, 1, 7]))
    with pytest.raises(ParameterError, match=word):
        nearest_neighbour_paths(line, **kwargs)


def test_core_refuses_a_bad_cost_matrix():
    with pytest.raises(ParameterError, match="square"):
        nearest_neighbour_paths(np.zeros((2, 3)), [0])
    with pytest.raises(ParameterError, match="finite"):
        nearest_neighbour_paths([[0, np.nan], [1, 0]], [0])


# ------------------------------------------------------------------- user 1: nearest_neighbour
def test_nearest_neighbour_fixed_and_free_start(fig14):
    inst = SequencingInstance.from_tileset(fig14, start=None)
    cost = inst.cost
    for start in range(inst.n):
        assert nearest_neighbour(cost, start=start).tolist() == naive_nearest_neighbour(cost, start)
    # free start, every waypoint tried (n ≤ max_starts): one of the cheapest of those paths
    paths = [naive_nearest_neighbour(cost, s) for s in range(inst.n)]
    cheapest = min(leg_sum(cost, p) for p in paths)
    free = nearest_neighbour(cost).tolist()
    assert free in [p for p in paths if leg_sum(cost, p) == pytest.approx(cheapest, abs=1e-9)]
    # and the local search starts from it
    _, info = solve_local(inst)
    assert info["initial_cost"] == pytest.approx(cheapest)


def test_nearest_neighbour_free_start_beyond_max_starts_tries_the_periphery():
    points = [(x, 0) for x in (4, 0, 5, 9, 3, 6, 2, 7, 1, 8)]  # a line, its ends (0 and 9) labelled 1 and 3
    inst = point_instance(points, None)
    order = nearest_neighbour(inst.cost, max_starts=2)  # only the two ends are tried; they tie
    assert order.tolist() == naive_nearest_neighbour(inst.cost, 1)  # the lower index wins
    assert order[0] == 1 and leg_sum(inst.cost, order.tolist()) == pytest.approx(9.0)


# ----------------------------------------------------------------- user 2: the exact solver's hint
def test_exact_hint_is_the_cheapest_nearest_neighbour_path_on_the_integer_costs(monkeypatch, fig14):
    from ortools.sat.python import cp_model

    hinted = []
    original = cp_model.CpModel.add_hint

    def spy(self, var, value):
        if value:
            hinted.append(var.name)
        return original(self, var, value)

    monkeypatch.setattr(cp_model.CpModel, "add_hint", spy)
    for start in (5, None):
        hinted.clear()
        inst = SequencingInstance.from_tileset(fig14, start=start)
        order, info = solve_exact(inst)
        assert info["optimal"]
        # the hinted arcs are "x{i}_{j}", "x{i}_end" and "x_begin_{i}": follow them from the begin
        successor = {}
        for name in hinted:
            if m := re.fullmatch(r"x(\d+)_(\d+)", name):
                successor[int(m[1])] = int(m[2])
            elif m := re.fullmatch(r"x_begin_(\d+)", name):
                node = int(m[1])
        path = [node]
        while path[-1] in successor:
            path.append(successor[path[-1]])
        icost = np.rint(inst.cost * (1e9 / inst.cost.max())).astype(np.int64)
        firsts = [inst.start] if start is not None else range(inst.n)
        candidates = [naive_nearest_neighbour(icost, s) for s in firsts]
        assert path == min(candidates, key=lambda p: leg_sum(icost, p))  # min keeps the first of ties
        assert len(path) == inst.n
        # the hint is an upper bound: the optimum is no dearer
        assert leg_sum(inst.cost, order.tolist()) <= leg_sum(inst.cost, path) + 1e-9


# ------------------------------------------------------------------------ user 3: greedy baseline
@pytest.mark.parametrize("seed", range(4))
def test_greedy_iteration_zero_is_the_nearest_neighbour_path(seed):
    rng = np.random.default_rng(seed)
    inst = point_instance(rng.integers(0, 1000, (20, 2)), start=seed)  # distances on a wide grid: no ties
    order, info = solve_greedy(inst, iterations=1, seed=seed)
    assert order.tolist() == naive_nearest_neighbour(inst.cost, seed)
    assert info["best_iteration"] == 0
