"""Shortest paths over a visibility graph of a continuous workspace's corners (Nazarahari et al.
2019's exact reference, and the taut refinement of its enhanced GA).

A shortest path among polygons bends only at reflex corners of the free region, and leaves each
corner along a tangent. :func:`visibility_path` joins the start, the goal and the corners by the
segments that are feasible and tangent at every corner they touch (both neighbours of the corner
on one side of the segment's line), and runs scipy's Dijkstra over them. For r = 0 that is the
optimum itself; for r > 0 the bounds it gives over polygonised C-obstacles are
:func:`~htetro_opt.solvers.continuous.plan_continuous`'s ``"exact"`` method.
"""

from __future__ import annotations

import numpy as np
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import dijkstra

from htetro_opt.model.continuous import ContinuousGeometry, Corners

__all__ = ["visibility_path"]


def _cross(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    return u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0]


def visibility_path(geometry: ContinuousGeometry, start, goal, *,
                    corners: Corners | None = None, prune=None) -> tuple[np.ndarray | None, float]:
    """The shortest path from ``start`` to ``goal`` that bends only at ``corners``, every segment
    feasible in ``geometry``.

    Parameters
    ----------
    geometry : ContinuousGeometry
        Checks every segment.
    start, goal : array_like, shape (2,)
        Feasible points.
    corners : Corners, keyword-only
        Where the path may bend; by default the geometry's own corners (r = 0) or those of its outer
        polygonisation (r > 0).
    prune : callable, keyword-only, optional
        ``prune(points, i, j) -> mask``: which of the candidate segments points[i] – points[j]
        (tangent ones, start and goal at rows 0 and 1, then the corners) are tested at all; a
        caller that knows most of them are blocked (taut refinement: segments between points far
        apart along a path) saves their feasibility tests. The result is then shortest over what
        is kept.

    Returns
    -------
    path : ndarray, shape (n, 2), or None
        Start first, goal last (a single point when they coincide); None if the goal is not reached.
    length : float
        Its length (inf when None).

    Examples
    --------
    >>> geo = ContinuousGeometry(10, 10, [[4, 0, 6, 8]])
    >>> path, length = visibility_path(geo, [1, 1], [9, 1])
    >>> path.tolist(), round(length, 4)
    ([[1.0, 1.0], [4.0, 8.0], [6.0, 8.0], [9.0, 1.0]], 17.2315)
    """
    start, goal = np.asarray(start, dtype=float), np.asarray(goal, dtype=float)
    if np.array_equal(start, goal):
        return start[None].copy(), 0.0
    if corners is None:
        corners = geometry.corners() if geometry.robot_radius == 0 else geometry.polygonised("outer").corners()
    keep = ~((corners.points == start).all(axis=1) | (corners.points == goal).all(axis=1))
    points = np.vstack([start, goal, corners.points[keep]])
    before = np.vstack([start, goal, corners.before[keep]])
    after = np.vstack([start, goal, corners.after[keep]])
    n = len(points)
    i, j = np.triu_indices(n, 1)
    mask = np.ones(len(i), dtype=bool)
    for end, other in ((i, j), (j, i)):  # tangent at every corner end (the start and goal are free)
        line = points[other] - points[end]
        c1 = _cross(line, before[end] - points[end])
        c2 = _cross(line, after[end] - points[end])
        mask &= (end < 2) | (c1 * c2 >= 0)
    i, j = i[mask], j[mask]
    if prune is not None:
        keep = np.asarray(prune(points, i, j), dtype=bool)
        i, j = i[keep], j[keep]
    ok = geometry.segments_feasible(points[i], points[j])
    i, j = i[ok], j[ok]
    weights = np.hypot(*(points[j] - points[i]).T)
    graph = csr_matrix((weights, (i, j)), shape=(n, n))
    dist, pred = dijkstra(graph, directed=False, indices=0, return_predecessors=True)
    if not np.isfinite(dist[1]):
        return None, float("inf")
    order = [1]
    while order[-1] != 0:
        order.append(int(pred[order[-1]]))
    path = points[order[::-1]]
    path[0], path[-1] = start, goal
    return path, float(np.hypot(*np.diff(path, axis=0).T).sum())
