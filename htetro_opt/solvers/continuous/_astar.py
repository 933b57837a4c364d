"""A* on an 8-connected lattice, Nazarahari et al. 2019's grid baseline (§5.2: grid 1 and 0.25).

The lattice (:func:`~htetro_opt.model.lattice_graph`) holds the points (i·grid, j·grid) that are
feasible; an edge joins two of them one step apart (axis or diagonal) when the segment between them
is feasible (the geometry's bounding-box prefilter leaves the exact test to the edges near an
obstacle). Weights are Euclidean, the heuristic is the Euclidean distance to the goal (admissible,
consistent). The start and the goal need not lie on the lattice: each is linked to the feasible nodes
it sees within 1.5·grid (and to each other, within that reach). The path is the lattice path as
found: no vertex is deleted (the paper applies its deletion operator to PRM and B-RRT, not to A*).
"""

from __future__ import annotations

import heapq
import math
import time

import numpy as np
from scipy.sparse import csr_matrix

from htetro_opt.model._lattice import check_grid, lattice_graph
from htetro_opt.model.continuous import ContinuousGeometry
from htetro_opt.solvers.continuous._result import ContinuousPlan, finish_plan

__all__ = ["lattice_path", "plan_astar"]


def _astar(graph: csr_matrix, points: np.ndarray, source: int, target: int) -> list[int] | None:
    indptr, indices, data = graph.indptr, graph.indices, graph.data
    goal = points[target]
    h = np.hypot(*(points - goal).T).tolist()
    best = {source: 0.0}
    parent = {source: -1}
    frontier = [(h[source], 0.0, source)]
    closed = set()
    while frontier:
        _, g, node = heapq.heappop(frontier)
        if node in closed:
            continue
        if node == target:
            order = [node]
            while parent[order[-1]] >= 0:
                order.append(parent[order[-1]])
            return order[::-1]
        closed.add(node)
        for k in range(indptr[node], indptr[node + 1]):
            child = int(indices[k])
            cost = g + float(data[k])
            if child not in closed and cost < best.get(child, math.inf):
                best[child] = cost
                parent[child] = node
                heapq.heappush(frontier, (cost + h[child], cost, child))
    return None


def lattice_path(geometry: ContinuousGeometry, start, goal, *, grid: float = 1.0) -> tuple[np.ndarray | None, dict]:
    """A* from ``start`` to ``goal`` over the 8-connected lattice of spacing ``grid``.

    Returns
    -------
    path : ndarray, shape (n, 2), or None
        Start first, goal last (a single point when they coincide); None when not reached.
    info : dict
        ``grid``, ``nodes``, ``edges`` (undirected).

    Examples
    --------
    >>> path, info = lattice_path(ContinuousGeometry(10, 10), [1, 1], [4, 3])
    >>> path.tolist(), info["nodes"]
    ([[1.0, 1.0], [2.0, 2.0], [3.0, 2.0], [4.0, 3.0]], 123)
    """
    grid = check_grid(grid, geometry)
    start, goal = np.asarray(start, dtype=float), np.asarray(goal, dtype=float)
    nodes, graph = lattice_graph(geometry, grid, ends=[start, goal])
    info = {"grid": grid, "nodes": len(nodes), "edges": graph.nnz // 2}
    if np.array_equal(start, goal):
        return start[None].copy(), info
    order = _astar(graph, nodes, len(nodes) - 2, len(nodes) - 1)
    if order is None:
        return None, info
    path = nodes[order]
    keep = np.ones(len(path), dtype=bool)
    keep[1:] = (np.diff(path, axis=0) != 0).any(axis=1)  # an end sitting on a lattice node
    return path[keep], info


def plan_astar(scenario, *, grid: float = 1.0) -> ContinuousPlan:
    """Each robot's A* path on the lattice of spacing ``grid``, alone."""
    began = time.perf_counter()
    geometry = scenario.geometry
    grid = check_grid(grid, geometry)
    paths, infos = [], []
    for start, goal in zip(scenario.starts, scenario.goals):
        path, info = lattice_path(geometry, start, goal, grid=grid)
        paths.append(path)
        infos.append(info)
    info = {"grid": grid, "nodes": infos[0]["nodes"], "edges": infos[0]["edges"]}
    return finish_plan(scenario, paths, method="astar", began=began, info=info)

