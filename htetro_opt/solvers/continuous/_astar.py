"""A* on an 8-connected lattice, Nazarahari et al. 2019's grid baseline (§5.2: grid 1 and 0.25).

The lattice holds the points (i·grid, j·grid) that are feasible; an edge joins two of them one step
apart (axis or diagonal) when the segment between them is feasible (the geometry's bounding-box
prefilter leaves the exact test to the edges near an obstacle). Weights are Euclidean, the heuristic
is the Euclidean distance to the goal (admissible, consistent). The start and the goal need not lie
on the lattice: each is linked to the feasible nodes it sees within 1.5·grid (and to each other,
within that reach). The path is the lattice path as found: no vertex is deleted (the paper applies its
deletion operator to PRM and B-RRT, not to A*).
"""

from __future__ import annotations

import heapq
import math
import time

import numpy as np
from scipy.sparse import csr_matrix

from htetro_opt._validation import check_real
from htetro_opt.model.continuous import ContinuousGeometry
from htetro_opt.solvers.continuous._result import ContinuousPlan, finish_plan

__all__ = ["lattice_graph", "lattice_path", "plan_astar"]

_STEPS = ((1, 0), (0, 1), (1, 1), (1, -1))


def check_grid(grid, geometry: ContinuousGeometry) -> float:
    """A lattice spacing in (0, min(W, H) / 2].

    Raises
    ------
    ParameterError
        Otherwise.
    """
    return check_real(grid, "grid", minimum=0.0, include_minimum=False,
                      maximum=min(geometry.width, geometry.height) / 2)


def lattice_graph(geometry: ContinuousGeometry, grid: float, ends=()) -> tuple[np.ndarray, csr_matrix]:
    """The lattice's feasible nodes (their points) and its symmetric CSR graph of feasible edges.

    ``ends`` (points off or on the lattice) are appended as the last nodes, each linked to the
    feasible nodes (and other ends) it sees within 1.5·grid.
    """
    x0, y0, x1, y1 = geometry.bounds
    kx = np.arange(math.ceil(x0 / grid - 1e-9), math.floor(x1 / grid + 1e-9) + 1)
    ky = np.arange(math.ceil(y0 / grid - 1e-9), math.floor(y1 / grid + 1e-9) + 1)
    gx, gy = np.meshgrid(kx, ky, indexing="xy")  # gx[j, i] = kx[i]
    lattice = np.column_stack([gx.ravel() * grid, gy.ravel() * grid])
    free = geometry.points_feasible(lattice)
    index = np.full(len(lattice), -1)
    index[free] = np.arange(free.sum())
    nodes = lattice[free]
    nx, ny = len(kx), len(ky)
    us, vs = [], []
    for dx, dy in _STEPS:
        i, j = np.meshgrid(np.arange(max(0, -dx), nx - max(0, dx)), np.arange(max(0, -dy), ny - max(0, dy)))
        a = (j * nx + i).ravel()
        b = ((j + dy) * nx + (i + dx)).ravel()
        both = free[a] & free[b]
        us.append(index[a[both]])
        vs.append(index[b[both]])
    u, v = np.concatenate(us), np.concatenate(vs)
    ends = np.asarray(ends, dtype=float).reshape(-1, 2)
    if len(ends):
        reach = 1.5 * grid
        for k, p in enumerate(ends):
            near = np.flatnonzero(np.hypot(*(nodes - p).T) <= reach + 1e-12)
            u = np.concatenate([u, near])
            v = np.concatenate([v, np.full(len(near), len(nodes) + k)])
            for m in range(k):
                if np.hypot(*(ends[m] - p)) <= reach + 1e-12:
                    u = np.append(u, len(nodes) + m)
                    v = np.append(v, len(nodes) + k)
        nodes = np.vstack([nodes, ends])
    ok = geometry.segments_feasible(nodes[u], nodes[v])
    u, v = u[ok], v[ok]
    w = np.hypot(*(nodes[u] - nodes[v]).T)
    n = len(nodes)
    # both directions; a zero weight (an end on a node) stays stored, and the A* below walks stored
    # entries, so it remains an edge
    graph = csr_matrix((np.concatenate([w, w]), (np.concatenate([u, v]), np.concatenate([v, u]))), shape=(n, n))
    return nodes, graph


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

