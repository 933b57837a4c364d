"""The 8-connected lattice of a continuous workspace (Nazarahari et al. 2019): what the APF
(:func:`~htetro_opt.model.apf_paths`) and the A* baseline
(:func:`~htetro_opt.solvers.continuous.lattice_path`) search.

The lattice holds the points (i·grid, j·grid) that are feasible; an edge joins two of them one step
apart (axis or diagonal) when the segment between them is feasible (the geometry's bounding-box
prefilter leaves the exact test to the edges near an obstacle). Weights are Euclidean. The start and
the goal need not lie on the lattice: each is linked to the feasible nodes it sees within 1.5·grid
(and to each other, within that reach).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.sparse import csr_matrix

from htetro_opt._validation import check_real
from htetro_opt.model.continuous import ContinuousGeometry

__all__ = ["check_grid", "lattice_graph"]

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
    # both directions; a zero weight (an end on a node) stays stored, and the A* baseline walks
    # stored entries, so it remains an edge
    graph = csr_matrix((np.concatenate([w, w]), (np.concatenate([u, v]), np.concatenate([v, u]))), shape=(n, n))
    return nodes, graph
