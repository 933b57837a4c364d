"""Taut refinement of path bases (ours, optional in the enhanced GA).

The paper's EGA moves PBs by small random steps; on a maze it stalls a few per cent short of the
wall corners a shortest path wraps around (as its own EGA loses to A* 0.25 on its mazes). Taut
refinement pulls a path tight in its own corridor: the shortest path from the start to the goal over
the visibility graph (:func:`~htetro_opt.model.visibility_path`, the exact reference's code with
its tangent pruning) of the path's own PBs and of the free space's corners within ``reach``
(2 d) of the path. The path itself is in that graph, so the result is never longer; it is kept if its
cost is lower (for a spline or other weights the taut polyline need not be better).

Two prunings keep the graph cheap (each segment costs a feasibility test): two PBs are joined only
where the path joins them (a shortcut past PBs bends at corners, which are in the graph), and two
points only when the path between their nearest points on it is at most :data:`DETOUR` times their
distance plus 4 d (the other segments cross a wall). Measured: half the run time on the mazes and
the plank pile, the same lengths.
"""

from __future__ import annotations

import numpy as np
from pymoo.core.repair import Repair

from htetro_opt._validation import check_int, check_real
from htetro_opt.model._visibility import visibility_path
from htetro_opt.model.continuous import ContinuousGeometry, Corners
from htetro_opt.operators.path_bases.deletion import TOLERANCE

__all__ = ["near_corners", "taut_path", "TautRefinement", "REACH"]

REACH = 2.0
"""Corners within REACH × d of a path take part in its refinement."""

DETOUR = 2.0
"""A segment between two points is tested only if the path runs at most DETOUR × their distance
+ 2 REACH × d between their nearest points on it: the others cross a wall (a segment homotopic to a
piece of the path is not much shorter than it, for the near-taut paths a GA holds)."""


def _project(points: np.ndarray, path: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each point's distance to the polyline ``path`` and the arc length of its nearest point on it."""
    if len(path) == 1 or not len(points):
        return np.hypot(*(points - path[0]).T), np.zeros(len(points))
    a, d = path[:-1], np.diff(path, axis=0)
    rel = points[:, None, :] - a[None]
    dd = (d * d).sum(axis=1)
    u = np.clip((rel * d[None]).sum(axis=2) / np.where(dd > 0, dd, 1.0), 0.0, 1.0)
    gap = np.hypot(*(rel - u[..., None] * d[None]).transpose(2, 0, 1))
    seg = np.argmin(gap, axis=1)
    s = np.concatenate([[0.0], np.cumsum(np.sqrt(dd))])
    rows = np.arange(len(points))
    return gap[rows, seg], s[seg] + u[rows, seg] * np.sqrt(dd[seg])


def near_corners(corners: Corners, path: np.ndarray, reach: float) -> np.ndarray:
    """Which corners lie within ``reach`` of the polyline ``path`` (a boolean mask)."""
    if not len(corners):
        return np.zeros(0, dtype=bool)
    return _project(corners.points, np.asarray(path, dtype=float))[0] <= reach


def taut_path(pbs, start, goal, geometry: ContinuousGeometry, corners: Corners, *, reach: float) -> np.ndarray:
    """The PBs of the shortest path from ``start`` to ``goal`` over ``pbs`` and the ``corners``
    within ``reach`` of the polyline start → PBs → goal, every segment feasible in ``geometry``
    (``pbs`` unchanged when no such path exists, e.g. the path is infeasible).

    Examples
    --------
    >>> geo = ContinuousGeometry(10, 10, [[4, 0, 6, 8]])
    >>> taut_path(np.array([[3.0, 9.0], [7.0, 9.5]]), [1, 1], [9, 1], geo, geo.corners(), reach=2.0).tolist()
    [[4.0, 8.0], [6.0, 8.0]]
    """
    start, goal = np.asarray(start, dtype=float), np.asarray(goal, dtype=float)
    pbs = np.asarray(pbs, dtype=float).reshape(-1, 2)
    line = np.vstack([start, pbs, goal])
    near = near_corners(corners, line, reach)
    # a PB is no corner: with itself as both neighbours every segment counts as tangent there
    graph = Corners(np.vstack([corners.points[near], pbs]), np.vstack([corners.before[near], pbs]),
                    np.vstack([corners.after[near], pbs]))

    n_pbs = int((~((pbs == start).all(axis=1) | (pbs == goal).all(axis=1))).sum())

    def along_the_path(points, i, j):
        s = _project(points, line)[1]
        keep = np.abs(s[i] - s[j]) <= DETOUR * np.hypot(*(points[i] - points[j]).T) + 2 * reach
        # two PBs join only where the path already does: a shortcut past PBs bends at corners
        first = len(points) - n_pbs
        return keep & ((i < first) | (j < first) | (np.abs(i - j) == 1))

    path, _ = visibility_path(geometry, start, goal, corners=graph, prune=along_the_path)
    return pbs.copy() if path is None else path[1:-1].copy()


class TautRefinement(Repair):
    """Taut refinement as a pymoo ``Repair`` over a :class:`~htetro_opt.problems.PathBasesProblem`:
    each robot of each individual in turn, its taut PBs kept when G does not rise and the first
    objective (eq. 6's cost, or the length) falls while no other rises.

    A path with a few infeasible segments is refined too: the corners near it often join into a
    feasible path (a child pushed across a wall is pulled back into a corridor, sometimes a shorter
    one than its parents'); one with more than ``max_bad`` is left alone (its graph seldom connects,
    and costs the most to build).

    Parameters
    ----------
    reach : float
        In units of the problem's step d.
    max_bad : int
        The most infeasible segments of a robot's path that is still refined.

    Raises
    ------
    ParameterError
        On a non-positive ``reach`` or a negative ``max_bad``.
    """

    def __init__(self, reach: float = REACH, max_bad: int = 2) -> None:
        super().__init__()
        self.reach = check_real(reach, "reach", minimum=0.0, include_minimum=False)
        self.max_bad = check_int(max_bad, "max_bad", minimum=0)

    def _do(self, problem, X, **kwargs):
        xs = [X[i, 0] for i in range(len(X))]
        parts = [problem.robots(x) for x in xs]
        G, F = problem.score(xs)
        for k in range(problem.n_robots):
            bad = problem.measure([problem.join(p) for p in parts])["bad"][:, k]
            reach = self.reach * problem.step
            taut = [taut_path(p[k], problem.starts[k], problem.goals[k], problem.geometry, problem.corners, reach=reach)
                    if b <= self.max_bad else p[k] for p, b in zip(parts, bad)]
            trials = [problem.join(p[:k] + [t] + p[k + 1:]) for p, t in zip(parts, taut)]
            G2, F2 = problem.score(trials)
            scale = TOLERANCE * np.maximum(1.0, np.abs(F))
            others = np.all(F2[:, 1:] <= F[:, 1:] + scale[:, 1:], axis=1)
            better = (G2 <= G) & (F2[:, 0] < F[:, 0] - scale[:, 0]) & others
            for i in np.flatnonzero(better):
                parts[i][k] = taut[i]
            G, F = np.where(better, G2, G), np.where(better[:, None], F2, F)
        Y = np.empty((len(X), 1), dtype=object)
        for i, p in enumerate(parts):
            Y[i, 0] = problem.join(p)
        return Y
