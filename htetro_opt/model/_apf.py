"""Nazarahari et al. 2019's artificial potential field (§4.2, Algorithm 1): feasible initial paths.

The lattice holds the points k·d of F (d = ``grid``, 1 in the paper); two of them one step apart
(axis or diagonal, i.e. within d√2) are neighbours when the segment between them is feasible. The
start and the goal, which need not lie on the lattice, are linked to the feasible nodes they see
within 1.5·d (the lattice of :func:`~htetro_opt.model.lattice_graph`, which the A* baseline
searches too).

**Potential.** Algorithm 1 hands ξ0 to the goal and ξ_i = ξ_{i−1} − α to the nodes first reached at
the i-th sweep of its OPEN / TEMP / CLOSED lists: a breadth-first search from the goal. We keep its
hop depth (:func:`apf_depths`; potential = −depth, i.e. ξ0 − α·depth in the paper's plots).

**Paths.** From the start, step to a neighbour of highest potential (one hop nearer the goal) until
the goal; where several neighbours tie, the paper splits the path in two. Rather than enumerating
every split (their number grows exponentially), we walk ``10 × n_paths`` times with the ties broken
at random and keep the first ``n_paths`` distinct paths (ours). A path's path bases (PBs) are its
turning points (Fig. 2b): the start and the goal are not genes.

If the start does not reach the goal on the lattice (a passage narrower than d, or off the lattice)
the lattice is refined to d/2, d/4, d/8 (ours: the paper guarantees a path only "if one exists" on
its grid); beyond that the goal counts as unreachable.
"""

from __future__ import annotations

import numpy as np
from scipy.sparse import csr_matrix

from htetro_opt._validation import as_rng, check_int
from htetro_opt.model._lattice import check_grid, lattice_graph
from htetro_opt.model.continuous import ContinuousGeometry

__all__ = ["apf_depths", "apf_paths", "apf_population", "turning_points", "REFINEMENTS", "FILL_RATE"]

REFINEMENTS = 3
"""How many times the lattice is halved when the start does not reach the goal (d/2 … d/8)."""

TRIES = 10
"""Walks per wanted path."""

FILL_RATE = 0.3
"""Probability that a PB of a fill-up copy moves (within d/2); ours, the paper says "some of its PBs"."""


def apf_depths(graph: csr_matrix, source: int) -> np.ndarray:
    """Hop depth of every node from ``source`` (Algorithm 1's sweeps; −1 where unreached), by a
    level-synchronous breadth-first search over the CSR graph.

    Examples
    --------
    >>> g = csr_matrix(([1, 1, 1, 1], ([0, 1, 1, 2], [1, 0, 2, 1])), shape=(4, 4))
    >>> apf_depths(g, 0).tolist()
    [0, 1, 2, -1]
    """
    indptr, indices = graph.indptr, graph.indices
    depth = np.full(graph.shape[0], -1, dtype=np.int64)
    depth[source] = 0
    frontier = np.array([source])
    level = 0
    while len(frontier):
        level += 1
        starts, ends = indptr[frontier], indptr[frontier + 1]
        counts = ends - starts
        # the neighbours of the whole frontier at once: positions starts[i] … ends[i] − 1
        offsets = np.arange(counts.sum()) - np.repeat(np.cumsum(counts) - counts, counts)
        around = np.unique(indices[np.repeat(starts, counts) + offsets])
        frontier = around[depth[around] < 0]
        depth[frontier] = level
    return depth


def turning_points(path: np.ndarray) -> np.ndarray:
    """The interior vertices of a polyline where its direction changes (the PBs of Fig. 2b): repeated
    points and collinear ones dropped, the start and the goal left out.

    Examples
    --------
    >>> turning_points(np.array([[0, 0], [1, 1], [2, 2], [3, 2], [3, 2], [4, 2]], float)).tolist()
    [[2.0, 2.0]]
    """
    path = np.asarray(path, dtype=float)
    if len(path) < 3:
        return np.empty((0, 2))
    keep = np.ones(len(path), dtype=bool)
    keep[1:] = (np.diff(path, axis=0) != 0).any(axis=1)
    path = path[keep]
    if len(path) < 3:
        return np.empty((0, 2))
    u, v = path[1:-1] - path[:-2], path[2:] - path[1:-1]
    cross = u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0]
    dot = (u * v).sum(axis=1)
    turn = (np.abs(cross) > 1e-12 * np.hypot(*u.T) * np.hypot(*v.T)) | (dot < 0)
    return path[1:-1][turn].copy()


def _walks(graph: csr_matrix, depth: np.ndarray, source: int, n_walks: int, rng: np.random.Generator) -> np.ndarray:
    """``n_walks`` greedy ascents from ``source``, each step to a random neighbour one hop nearer the
    goal: the node sequences, shape (n_walks, depth[source] + 1)."""
    coo = graph.tocoo()
    down = depth[coo.col] == depth[coo.row] - 1
    order = np.lexsort((coo.col[down], coo.row[down]))
    rows, cols = coo.row[down][order], coo.col[down][order]
    indptr = np.searchsorted(rows, np.arange(graph.shape[0] + 1))
    steps = int(depth[source])
    out = np.empty((n_walks, steps + 1), dtype=np.int64)
    out[:, 0] = source
    current = out[:, 0]
    for k in range(1, steps + 1):
        lo, hi = indptr[current], indptr[current + 1]
        current = cols[lo + (rng.random(n_walks) * (hi - lo)).astype(np.int64)]
        out[:, k] = current
    return out


def apf_paths(geometry: ContinuousGeometry, start, goal, *, n_paths: int = 10, grid: float = 1.0,
              seed=None, refinements: int = REFINEMENTS) -> tuple[list[np.ndarray], dict]:
    """Up to ``n_paths`` distinct feasible paths from ``start`` to ``goal`` by the APF (see the module
    docstring), each as its PBs.

    Parameters
    ----------
    geometry : ContinuousGeometry
    start, goal : array_like, shape (2,)
        Feasible points.
    n_paths : int, keyword-only
        How many distinct paths are wanted (the GA's population size).
    grid : float, keyword-only
        d, the lattice spacing (halved up to three times when the start does not reach the goal).
    seed : None, int or numpy Generator, keyword-only
        Breaks the ties (None: fresh entropy).
    refinements : int, keyword-only
        How many times the lattice may be halved (:data:`REFINEMENTS`; 0: the paper's lattice only).

    Returns
    -------
    paths : list of ndarray, each shape (n_i, 2)
        The PBs of each distinct path, in the order found (empty list: the goal is unreachable; one
        empty array when the start sees the goal, or is the goal).
    info : dict
        ``grid`` (the spacing that reached the start, or the last one tried), ``depth`` (the start's
        hop depth, -1 if unreached), ``nodes`` (the lattice's size).

    Raises
    ------
    ParameterError
        On a bad ``n_paths``, ``grid`` or ``seed``.

    Examples
    --------
    >>> geo = ContinuousGeometry(10, 10, [[4, 0, 6, 8]])
    >>> paths, info = apf_paths(geo, [1, 1], [9, 1], n_paths=3, seed=0)
    >>> len(paths), info["depth"], all(geo.path_feasible(np.vstack([[1, 1], p, [9, 1]])) for p in paths)
    (3, 16, True)
    """
    n_paths = check_int(n_paths, "n_paths", minimum=1)
    refinements = check_int(refinements, "refinements", minimum=0)
    grid = check_grid(grid, geometry)
    rng = as_rng(seed)
    start, goal = np.asarray(start, dtype=float), np.asarray(goal, dtype=float)
    if np.array_equal(start, goal):
        return [np.empty((0, 2))], {"grid": grid, "depth": 0, "nodes": 0}
    for refinement in range(refinements + 1):
        d = grid / 2 ** refinement
        nodes, graph = lattice_graph(geometry, d, ends=[start, goal])
        source, target = len(nodes) - 2, len(nodes) - 1
        depth = apf_depths(graph, target)
        if depth[source] >= 0:
            break
    info = {"grid": d, "depth": int(depth[source]), "nodes": len(nodes)}
    if depth[source] < 0:
        return [], info
    walks = _walks(graph, depth, source, TRIES * n_paths, rng)
    _, first = np.unique(walks, axis=0, return_index=True)
    paths, seen = [], set()
    for row in np.sort(first):
        pbs = turning_points(nodes[walks[row]])
        key = pbs.tobytes()
        if key not in seen:
            seen.add(key)
            paths.append(pbs)
            if len(paths) == n_paths:
                break
    return paths, info


def apf_population(geometry: ContinuousGeometry, start, goal, n: int, *, grid: float = 1.0,
                   seed=None, refinements: int = REFINEMENTS) -> tuple[list[np.ndarray], dict]:
    """Exactly ``n`` initial paths (as PBs): the APF's distinct paths (:func:`apf_paths`), filled up
    as §4.2 says with copies of random ones whose PBs each move, with probability :data:`FILL_RATE`,
    to a uniform point of the disc of radius d/2 around them, a copy kept only if it is feasible and
    new. After ``10 n`` tries the rest are plain copies (a path without PBs has no other form).
    ``refinements`` as in :func:`apf_paths`.

    Returns
    -------
    paths : list of ndarray
        ``n`` arrays of PBs, or an empty list when the goal is unreachable.
    info : dict
        :func:`apf_paths`'s, plus ``distinct`` (how many the APF found).

    Examples
    --------
    >>> geo = ContinuousGeometry(10, 3, [[0, 0, 10, 1.2], [0, 1.8, 10, 3]])  # one lattice row free
    >>> paths, info = apf_population(geo, [1, 1.5], [9, 1.5], 4, grid=0.5, seed=1)
    >>> len(paths), info["distinct"]
    (4, 1)
    """
    n = check_int(n, "n", minimum=1)
    rng = as_rng(seed)
    paths, info = apf_paths(geometry, start, goal, n_paths=n, grid=grid, seed=rng, refinements=refinements)
    info["distinct"] = len(paths)
    if not paths or len(paths) == n:
        return paths, info
    start, goal = np.asarray(start, dtype=float), np.asarray(goal, dtype=float)
    seen = {p.tobytes() for p in paths}
    radius = info["grid"] / 2
    found = list(paths)
    for _ in range(TRIES * n):
        if len(found) == n:
            break
        base = paths[int(rng.integers(len(paths)))]
        if not len(base):
            continue
        moved = rng.random(len(base)) < FILL_RATE
        angle = rng.uniform(0, 2 * np.pi, len(base))
        rho = radius * np.sqrt(rng.random(len(base)))
        copy = base + moved[:, None] * rho[:, None] * np.column_stack([np.cos(angle), np.sin(angle)])
        if copy.tobytes() in seen or not geometry.path_feasible(np.vstack([start, copy, goal])):
            continue
        seen.add(copy.tobytes())
        found.append(copy)
    while len(found) < n:
        found.append(paths[len(found) % len(paths)].copy())
    return found, info
