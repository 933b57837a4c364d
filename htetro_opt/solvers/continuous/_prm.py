"""Nazarahari et al. 2019's PRM baseline (§5.2): a roadmap of exactly ``n`` uniform free samples.

The roadmap holds ``n`` points drawn uniformly from F's box and kept when feasible (batches drawn
until ``n`` are kept), plus the start and the goal; an edge joins two of them within ``radius`` of
each other when the segment between them is feasible. Dijkstra (scipy's) finds the shortest path
over the roadmap, and the paper's deletion operator (§4.3.4, as for B-RRT) drops its redundant
vertices. OMPL's PRM is not used: it grows its roadmap for a time budget on several threads, so
neither its sample count nor its results follow a seed, whereas the paper gives (n, radius) per map.
"""

from __future__ import annotations

import time

import numpy as np
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import dijkstra
from scipy.spatial import cKDTree

from htetro_opt._spec import DEFAULT_SEED
from htetro_opt._validation import as_rng, check_int, check_real
from htetro_opt.model.continuous import ContinuousGeometry
from htetro_opt.solvers.continuous._result import ContinuousPlan, check_scenario, finish_plan

__all__ = ["prm_path", "plan_prm", "PAPER_PRM"]

PAPER_PRM = {
    "ega01_random1": (100, 9.0), "ega02_maze1": (900, 7.5), "ega03_home": (1100, 5.0),
    "ega04_corridor1": (300, 6.0), "ega05_boxpile": (300, 6.0), "ega06_corridor2": (300, 9.0),
    "ega07_slits1": (300, 4.0), "ega08_slits2": (350, 6.0), "ega09_maze2": (1100, 5.0),
    "ega10_maze3": (1100, 5.0), "ega11_random2": (300, 9.0), "ega12_plankpile": (300, 9.0),
}
"""The paper's (samples, radius) per map (§5.2), by our bundled scenarios' names."""

DEFAULT_SAMPLES = 300
"""Samples on a map the paper does not list (ours: its most common choice)."""

DEFAULT_RADIUS_SHARE = 0.2
"""Radius on such a map, as a share of min(W, H) (ours: 6 of 30 as on the paper's maps 4 and 5)."""


def _free_samples(geometry: ContinuousGeometry, n: int, rng: np.random.Generator) -> np.ndarray:
    x0, y0, x1, y1 = geometry.bounds
    kept, have = [], 0
    for _ in range(1000):
        if have >= n:
            break
        batch = rng.uniform((x0, y0), (x1, y1), size=(max(2 * (n - have), 16), 2))
        batch = batch[geometry.points_feasible(batch)]
        kept.append(batch)
        have += len(batch)
    points = np.vstack(kept) if kept else np.empty((0, 2))
    return points[:n]


def prm_path(geometry: ContinuousGeometry, start, goal, *, n: int, radius: float, seed=None,
             delete: bool = True) -> tuple[np.ndarray | None, dict]:
    """The shortest path over a probabilistic roadmap of ``n`` free samples (see the module docstring).

    Parameters
    ----------
    geometry : ContinuousGeometry
    start, goal : array_like, shape (2,)
        Feasible points.
    n : int, keyword-only
        Samples, at least 1.
    radius : float, keyword-only
        Samples (and the ends) closer than this are joined when the segment is feasible.
    seed : None, int or numpy Generator, keyword-only
    delete : bool, keyword-only
        Apply the deletion operator to the path found (the paper: yes).

    Returns
    -------
    path : ndarray, shape (m, 2), or None
        Start first, goal last; None when the roadmap does not join them.
    info : dict
        ``samples``, ``radius``, ``edges`` (undirected) and ``roadmap_length`` (before deletion).

    Raises
    ------
    ParameterError
        On a bad ``n``, ``radius`` or ``seed``.

    Examples
    --------
    >>> geo = ContinuousGeometry(10, 10, [[4, 0, 6, 8]])
    >>> path, info = prm_path(geo, [1, 1], [9, 1], n=200, radius=3, seed=0)
    >>> geo.path_feasible(path), info["samples"], round(info["roadmap_length"], 2), len(path)
    (True, 200, 17.79, 6)
    """
    n = check_int(n, "n", minimum=1)
    radius = check_real(radius, "radius", minimum=0.0, include_minimum=False)
    rng = as_rng(seed)
    start, goal = np.asarray(start, dtype=float), np.asarray(goal, dtype=float)
    points = np.vstack([start, goal, _free_samples(geometry, n, rng)])
    info = {"samples": len(points) - 2, "radius": radius, "edges": 0, "roadmap_length": None}
    if np.array_equal(start, goal):
        return start[None].copy(), info
    pairs = cKDTree(points).query_pairs(radius, output_type="ndarray")
    i, j = pairs[:, 0], pairs[:, 1]
    ok = geometry.segments_feasible(points[i], points[j])
    i, j = i[ok], j[ok]
    info["edges"] = len(i)
    w = np.hypot(*(points[i] - points[j]).T)
    w[w == 0] = 1e-300  # a sample on an end: keep the edge (csgraph drops explicit zeros)
    graph = csr_matrix((w, (i, j)), shape=(len(points), len(points)))
    dist, pred = dijkstra(graph, directed=False, indices=0, return_predecessors=True)
    if not np.isfinite(dist[1]):
        return None, info
    order = [1]
    while order[-1] != 0:
        order.append(int(pred[order[-1]]))
    path = points[order[::-1]]
    info["roadmap_length"] = float(np.hypot(*np.diff(path, axis=0).T).sum())
    if delete:
        from htetro_opt.operators.path_bases import delete_path_bases

        path = np.vstack([start, delete_path_bases(path[1:-1], start, goal, geometry), goal])
    return path, info


def plan_prm(scenario, *, n: int | None = None, radius: float | None = None, seed=DEFAULT_SEED) -> ContinuousPlan:
    """Each robot's PRM path (:func:`prm_path`), alone, with deletion.

    ``n`` and ``radius`` default to the paper's for its maps (:data:`PAPER_PRM`), else to
    :data:`DEFAULT_SAMPLES` and :data:`DEFAULT_RADIUS_SHARE` × min(W, H). One ``seed`` drives every
    robot's roadmap (the same seed, the same paths). ``info``: ``samples``, ``radius``, ``edges``
    and ``roadmap_length`` per robot.
    """
    began = time.perf_counter()
    scenario = check_scenario(scenario)
    geometry = scenario.geometry
    paper = PAPER_PRM.get(scenario.name, (DEFAULT_SAMPLES, DEFAULT_RADIUS_SHARE * min(geometry.width, geometry.height)))
    n = paper[0] if n is None else check_int(n, "n", minimum=1)
    radius = paper[1] if radius is None else check_real(radius, "radius", minimum=0.0, include_minimum=False)
    rng = as_rng(seed)
    paths, infos = [], []
    for start, goal in zip(scenario.starts, scenario.goals):
        path, info = prm_path(geometry, start, goal, n=n, radius=radius, seed=rng)
        paths.append(path)
        infos.append(info)
    info = {"samples": n, "radius": radius, "edges": [i["edges"] for i in infos],
            "roadmap_length": [i["roadmap_length"] for i in infos]}
    return finish_plan(scenario, paths, method="prm", began=began, info=info)
