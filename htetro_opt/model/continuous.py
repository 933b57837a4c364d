"""Continuous workspaces (Nazarahari et al. 2019): a disc robot among polygon obstacles.

A W × H rectangle holds polygon obstacles; a robot is a disc of radius r (a point when r = 0), and
its radius is added to the obstacles (shared/MODEL.md §1). This is the only module of htetro_opt
that imports shapely; :class:`ContinuousGeometry` builds its shapely objects once per workspace and
answers, vectorised, whether points, segments and whole paths are feasible, how far they stay from
the obstacles, and at which corners a shortest path can bend.

**Feasibility** (where the paper is silent, our definition): the robot's centre must stay in the
closure of F = [r, W − r] × [r, H − r] minus the open C-obstacles.

- r = 0: a point or segment is feasible iff the closed region ``box − ∪ obstacles`` covers it
  (shapely's regularised difference). Touching an obstacle, or running along its edge, is allowed;
  a zero-width gap (a wall touching the map edge, two obstacles sharing an edge) is closed.
- r > 0: feasible iff inside the shrunk box and at distance ≥ r from every obstacle (touching at
  exactly r is allowed).

No obstacle is shrunk or grown by a tolerance: a shrink by 1e-9 lets a path slide along a wall
that touches the map edge and come out shorter than the true optimum.

**Clearance** of a point: its distance to the nearest obstacle or map edge, minus r (negative in
collision).

**Polygonised C-obstacles** (:meth:`ContinuousGeometry.polygonised`) for r > 0: each obstacle
grown by r as a polygon with 8 segments a quarter circle (``quad_segs=8``). Grown by r itself
("inner") the polygon lies inside the true C-obstacle, so a shortest path around it is a lower
bound; grown by r / cos(π/32) ("outer") it contains the true C-obstacle, so its corners are
feasible points whose paths give an upper bound.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import shapely
from shapely import STRtree

from htetro_opt._validation import check_real
from htetro_opt.errors import ParameterError, UnknownShapeError

__all__ = [
    "ContinuousGeometry",
    "Corners",
    "SAFETY_MARGIN",
    "as_polygon",
    "as_robot_radius",
    "closest_approach",
    "enclosing_radius",
    "path_length",
    "path_smoothness",
    "polyline_segments",
    "robot_distance",
]

QUAD_SEGS = 8
"""Segments per quarter circle of a polygonised C-obstacle (shapely's ``quad_segs``)."""

OUTER_FACTOR = 1.0 / math.cos(math.pi / (4 * QUAD_SEGS)) * (1.0 + 1e-9)
"""Radius factor of the outer polygonisation: its chords stay at distance ≥ r from the obstacle (the
1e-9 keeps a chord's midpoint from landing a rounding error inside)."""

SAFETY_MARGIN = 0.5
"""Robots closer than 2 r + this conflict (the safety distance d_s; a choice of ours: the paper's
§4.5 leaves it open), as :func:`robot_distance` measures how close they come."""


def as_polygon(value, name: str = "obstacle") -> np.ndarray:
    """An obstacle as an (n, 2) float array of vertices: a rectangle ``[xmin, ymin, xmax, ymax]``
    or a simple polygon ``[[x, y], ...]`` of at least 3 points, with positive area.

    Raises
    ------
    ParameterError
        Naming ``name``: not numbers, not finite, a rectangle with xmin ≥ xmax or ymin ≥ ymax, fewer
        than 3 points, or an invalid polygon (with shapely's reason, e.g. a self-intersection).

    Examples
    --------
    >>> as_polygon([0, 0, 2, 1]).tolist()
    [[0.0, 0.0], [2.0, 0.0], [2.0, 1.0], [0.0, 1.0]]
    >>> as_polygon([[0, 0], [2, 2], [2, 0], [0, 2]], "obstacles[3]")
    Traceback (most recent call last):
    ...
    htetro_opt.errors.ParameterError: obstacles[3]: invalid polygon: Self-intersection at (1, 1)
    """
    try:
        arr = np.array(value, dtype=float)
    except (TypeError, ValueError) as err:
        raise ParameterError(f"{name}: expected [xmin, ymin, xmax, ymax] or a list of [x, y] points, "
                             f"got {value!r}") from err
    if arr.shape == (4,):
        if not np.isfinite(arr).all():
            raise ParameterError(f"{name}: coordinates must be finite numbers, got {arr.tolist()}")
        x0, y0, x1, y1 = arr
        if not (x0 < x1 and y0 < y1):
            raise ParameterError(f"{name}: a rectangle needs xmin < xmax and ymin < ymax, got {arr.tolist()}")
        return np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]])
    if arr.ndim != 2 or arr.shape[1] != 2 or len(arr) < 3:
        raise ParameterError(f"{name}: expected [xmin, ymin, xmax, ymax] or at least 3 [x, y] points, "
                             f"got shape {arr.shape}")
    if not np.isfinite(arr).all():
        raise ParameterError(f"{name}: coordinates must be finite numbers")
    if len(arr) > 3 and np.array_equal(arr[0], arr[-1]):
        arr = arr[:-1]  # a closed ring written out
    polygon = shapely.polygons(arr)
    reason = shapely.is_valid_reason(polygon)
    if reason != "Valid Geometry":
        kind, _, where = reason.partition("[")
        at = f" at ({', '.join(f'{float(v):g}' for v in where.rstrip(']').split())})" if where else ""
        raise ParameterError(f"{name}: invalid polygon: {kind}{at}")
    if not polygon.area > 0:
        raise ParameterError(f"{name}: the polygon has no area")
    return arr


def enclosing_radius(shape: str) -> float:
    """Radius of the smallest disc enclosing the hTetro footprint of a morphology (shared/MODEL.md
    §2), in cells: how a continuous planner can stand in for the robot in one shape.

    Raises
    ------
    UnknownShapeError
        If ``shape`` is not one of the seven morphologies.

    Examples
    --------
    >>> [round(enclosing_radius(s), 4) for s in "OTLI"]
    [1.4142, 1.5811, 1.8028, 2.0616]
    """
    from htetro_opt.model.robot import FOOTPRINTS, SHAPES, shape_index

    if shape not in SHAPES:
        raise UnknownShapeError(f"unknown shape {shape!r}: expected one of {', '.join(SHAPES)}")
    cells = FOOTPRINTS[shape_index(shape), 0]
    squares = shapely.union_all([shapely.box(x - 0.5, y - 0.5, x + 0.5, y + 0.5) for x, y in cells.tolist()])
    return float(shapely.minimum_bounding_radius(squares))


def as_robot_radius(value, name: str = "robot_radius") -> float:
    """A robot radius: a finite number ≥ 0, or a morphology letter (its :func:`enclosing_radius`).

    Raises
    ------
    ParameterError
        If it is neither.

    Examples
    --------
    >>> as_robot_radius(0.5), round(as_robot_radius("O"), 4)
    (0.5, 1.4142)
    """
    if isinstance(value, str):
        try:
            return enclosing_radius(value)
        except UnknownShapeError as err:
            raise ParameterError(f"{name} must be a number >= 0 or a shape letter (I O L J Z S T), "
                                 f"got {value!r}") from err
    return check_real(value, name, minimum=0.0)


def _as_points(points, name: str) -> np.ndarray:
    try:
        arr = np.asarray(points, dtype=float)
    except (TypeError, ValueError) as err:
        raise ParameterError(f"{name} must be [x, y] points, got {type(points).__name__}") from err
    if arr.ndim == 1 and arr.shape == (2,):
        arr = arr[None]
    if arr.ndim != 2 or arr.shape[1] != 2:
        raise ParameterError(f"{name} must be an (n, 2) array of [x, y] points, got shape {arr.shape}")
    if not np.isfinite(arr).all():
        raise ParameterError(f"{name} must hold finite coordinates")
    return arr


def path_length(path) -> float:
    """Length of a polyline (an (n, 2) array; 0 for fewer than two points).

    Examples
    --------
    >>> path_length([[0, 0], [3, 4], [3, 5]])
    6.0
    """
    path = _as_points(path, "path")
    return float(np.hypot(*np.diff(path, axis=0).T).sum()) if len(path) > 1 else 0.0


def path_smoothness(path) -> float:
    """Sum of the turning angles at a polyline's interior vertices, in degrees (Nazarahari et al.
    2019, eq. 4, counted at every interior vertex; zero-length segments are skipped).

    Examples
    --------
    >>> path_smoothness([[0, 0], [1, 0], [1, 1]]), path_smoothness([[0, 0], [1, 0], [2, 0]])
    (90.0, 0.0)
    """
    path = _as_points(path, "path")
    steps = np.diff(path, axis=0)
    steps = steps[np.hypot(*steps.T) > 0]
    if len(steps) < 2:
        return 0.0
    a, b = steps[:-1], steps[1:]
    angles = np.arctan2(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0], (a * b).sum(axis=1))
    return float(np.degrees(np.abs(angles)).sum())


def polyline_segments(points: np.ndarray, sizes: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Every segment of many polylines stored end to end: ``points`` (N, 2) holds polyline i's
    ``sizes[i]`` ≥ 1 points after polyline i − 1's. Returns the segments' ends ``a`` and ``b`` and
    the polyline each belongs to (``owner``); a one-point polyline gives one zero-length segment, so
    that it is checked too.

    Examples
    --------
    >>> a, b, owner = polyline_segments(np.array([[0, 0], [1, 0], [2, 0], [5, 5]]), np.array([3, 1]))
    >>> a.tolist(), b.tolist(), owner.tolist()
    ([[0, 0], [1, 0], [5, 5]], [[1, 0], [2, 0], [5, 5]], [0, 0, 1])
    """
    ends = np.cumsum(sizes)
    head = np.ones(len(points), dtype=bool)  # point k starts a segment unless it ends its polyline
    head[ends - 1] = False
    heads = np.flatnonzero(head)
    singles = ends[sizes == 1] - 1
    a = np.concatenate([points[heads], points[singles]])
    b = np.concatenate([points[heads + 1], points[singles]])
    owner = np.concatenate([np.searchsorted(ends, heads, side="right"), np.flatnonzero(sizes == 1)])
    return a, b, owner


def robot_distance(path_a, path_b) -> float:
    """Smallest distance between two robots that leave their starts together at unit speed along
    their paths and wait at their goals: exact, as the relative motion is linear between the merged
    breakpoints of the two paths.

    Examples
    --------
    >>> robot_distance([[0, 0], [4, 0]], [[4, 1], [0, 1]])       # they pass each other at x = 2
    1.0
    >>> robot_distance([[0, 0], [2, 0]], [[2, 0], [2, 0]])       # b waits where a ends
    0.0
    """
    return closest_approach(path_a, path_b)[0]


def closest_approach(path_a, path_b) -> tuple[float, float]:
    """Where two robots come closest, as :func:`robot_distance` defines their motion: the distance
    and the time (= the arc length each has travelled, at unit speed) when it first occurs.

    Examples
    --------
    >>> closest_approach([[0, 0], [4, 0]], [[4, 1], [0, 1]])
    (1.0, 2.0)
    """
    a, b = _as_points(path_a, "path_a"), _as_points(path_b, "path_b")
    if not len(a) or not len(b):
        raise ParameterError("the distance between two robots needs two non-empty paths")
    (a, sa), (b, sb) = _arclength(a), _arclength(b)
    times = np.union1d(sa, sb)
    rel = np.column_stack([np.interp(times, sa, a[:, 0]) if len(a) > 1 else np.full(len(times), a[0, 0]),
                           np.interp(times, sa, a[:, 1]) if len(a) > 1 else np.full(len(times), a[0, 1])])
    rel -= np.column_stack([np.interp(times, sb, b[:, 0]) if len(b) > 1 else np.full(len(times), b[0, 0]),
                            np.interp(times, sb, b[:, 1]) if len(b) > 1 else np.full(len(times), b[0, 1])])
    if len(rel) == 1:
        return float(np.hypot(*rel[0])), 0.0
    p, d = rel[:-1], np.diff(rel, axis=0)
    dd = (d * d).sum(axis=1)
    u = np.clip(-(p * d).sum(axis=1) / np.where(dd > 0, dd, 1.0), 0.0, 1.0)
    gaps = np.hypot(*(p + u[:, None] * d).T)
    k = int(np.argmin(gaps))
    return float(gaps[k]), float(times[k] + u[k] * (times[k + 1] - times[k]))


def _arclength(path: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``path`` without repeated points, and the cumulative length along it (strictly increasing)."""
    keep = np.ones(len(path), dtype=bool)
    keep[1:] = np.hypot(*np.diff(path, axis=0).T) > 0
    path = path[keep]
    return path, np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(path, axis=0).T))])


@dataclass(frozen=True, eq=False)
class Corners:
    """The reflex corners of a free region (where a shortest path may bend): ``points``, and for each
    the vertices before and after it along the region's boundary (for tangent pruning)."""

    points: np.ndarray
    before: np.ndarray
    after: np.ndarray

    def __len__(self) -> int:
        return len(self.points)


class ContinuousGeometry:
    """Feasibility and clearance in a continuous W × H workspace with polygon obstacles, for a disc
    robot of radius ``robot_radius`` (see the module docstring for the definitions).

    Parameters
    ----------
    width, height : float
        The workspace is [0, width] × [0, height].
    obstacles : sequence
        Rectangles ``[xmin, ymin, xmax, ymax]`` or polygons ``[[x, y], ...]`` (:func:`as_polygon`).
    robot_radius : float or str, keyword-only
        r ≥ 0, or a morphology letter (:func:`as_robot_radius`).

    Raises
    ------
    ParameterError
        On a non-positive size, a bad radius (or one that leaves no room: 2r ≥ width or height), or
        an invalid obstacle (naming ``obstacles[i]``, 0-based).

    Examples
    --------
    >>> geo = ContinuousGeometry(10, 10, [[4, 0, 6, 8]])
    >>> geo.segments_feasible([[1, 1], [3, 0], [4, 0]], [[9, 1], [7, 0], [4, 9]]).tolist()
    [False, False, True]
    >>> geo.clearance([[2, 5], [5, 9]]).tolist()
    [2.0, 1.0]
    >>> ContinuousGeometry(10, 10, [[4, 0, 6, 8]], robot_radius=0.5).points_feasible([[3.5, 1], [3.6, 1]]).tolist()
    [True, False]
    """

    def __init__(self, width, height, obstacles=(), *, robot_radius=0.0):
        width = check_real(width, "width", minimum=0.0, include_minimum=False)
        height = check_real(height, "height", minimum=0.0, include_minimum=False)
        r = as_robot_radius(robot_radius)
        if not 2 * r < min(width, height):
            raise ParameterError(f"robot_radius {r:g} leaves no room in the {width:g} x {height:g} workspace "
                                 f"(2 r must be < {min(width, height):g})")
        if isinstance(obstacles, (str, bytes)) or not hasattr(obstacles, "__iter__"):
            raise ParameterError(f"obstacles must be a sequence of rectangles or polygons, got {type(obstacles).__name__}")
        polygons = tuple(as_polygon(o, f"obstacles[{i}]") for i, o in enumerate(obstacles))
        self._setup(width, height, r, (r, r, width - r, height - r), polygons)

    @classmethod
    def _from_parts(cls, width, height, r, bounds, polygons) -> ContinuousGeometry:
        self = cls.__new__(cls)
        self._setup(width, height, r, bounds, polygons)
        return self

    def _setup(self, width, height, r, bounds, polygons) -> None:
        self.width, self.height, self.robot_radius = float(width), float(height), float(r)
        self.bounds = tuple(float(v) for v in bounds)
        """The box [xmin, ymin, xmax, ymax] the robot's centre must stay in."""
        self.obstacles = tuple(polygons)
        self._polys = np.array([shapely.Polygon(p) for p in self.obstacles] + [None], dtype=object)[:-1]
        self._tree = STRtree(self._polys)
        self._boxes = shapely.bounds(self._polys).reshape(-1, 4)
        self._free = None
        if self.robot_radius == 0:
            free = shapely.box(*self.bounds)
            if len(self._polys):
                free = shapely.difference(free, shapely.union_all(self._polys))
            shapely.prepare(free)
            self._free = free

    def __repr__(self) -> str:
        return (f"ContinuousGeometry({self.width:g} x {self.height:g}, {len(self.obstacles)} obstacles, "
                f"robot_radius={self.robot_radius:g})")

    # ---------------------------------------------------------------------------------------------
    # feasibility

    def _in_box(self, pts: np.ndarray) -> np.ndarray:
        x0, y0, x1, y1 = self.bounds
        return (pts[:, 0] >= x0) & (pts[:, 0] <= x1) & (pts[:, 1] >= y0) & (pts[:, 1] <= y1)

    def _near_pairs(self, lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(item, obstacle) pairs whose bounding boxes, the obstacle's grown by r, meet (touching
        counts): the only ones that need an exact test. Numpy, in chunks, before any shapely object."""
        grown = self._boxes + np.array([-1, -1, 1, 1]) * self.robot_radius
        rows = max(1, (1 << 22) // max(1, len(grown)))
        items, obstacles = [], []
        for s in range(0, len(lo), rows):
            l, h = lo[s:s + rows, None], hi[s:s + rows, None]
            meet = ((l[..., 0] <= grown[:, 2]) & (h[..., 0] >= grown[:, 0])
                    & (l[..., 1] <= grown[:, 3]) & (h[..., 1] >= grown[:, 1]))
            i, j = np.nonzero(meet)
            items.append(i + s)
            obstacles.append(j)
        return np.concatenate(items), np.concatenate(obstacles)

    def _check(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """Feasibility of the segments a → b (points where a == b), vectorised."""
        ok = self._in_box(a) & self._in_box(b)  # the box is convex: a segment's ends decide
        if not len(self._polys) or not ok.any():
            return ok
        idx = np.flatnonzero(ok)
        pair_item, pair_obstacle = self._near_pairs(np.minimum(a[idx], b[idx]), np.maximum(a[idx], b[idx]))
        near = np.unique(pair_item)
        if not len(near):
            return ok
        sa, sb = a[idx[near]], b[idx[near]]
        point = (sa == sb).all(axis=1)
        geoms = np.empty(len(near), dtype=object)
        if point.any():
            geoms[point] = shapely.points(sa[point])
        if (~point).any():
            geoms[~point] = shapely.linestrings(np.stack([sa[~point], sb[~point]], axis=1))
        if self.robot_radius == 0:
            ok[idx[near]] = shapely.covered_by(geoms, self._free)
        else:
            slot = np.searchsorted(near, pair_item)
            bad = shapely.distance(geoms[slot], self._polys[pair_obstacle]) < self.robot_radius
            ok[idx[near[slot[bad]]]] = False
        return ok

    def points_feasible(self, points) -> np.ndarray:
        """Whether each point is a feasible position of the robot's centre.

        Parameters
        ----------
        points : array_like, shape (n, 2) or (2,)

        Returns
        -------
        ndarray of bool, shape (n,)
        """
        pts = _as_points(points, "points")
        return self._check(pts, pts)

    def segments_feasible(self, starts, ends) -> np.ndarray:
        """Whether the robot's centre can move straight from each start to its end.

        Parameters
        ----------
        starts, ends : array_like, shape (n, 2)

        Returns
        -------
        ndarray of bool, shape (n,)
        """
        a, b = _as_points(starts, "starts"), _as_points(ends, "ends")
        if a.shape != b.shape:
            raise ParameterError(f"starts and ends must have the same shape, got {a.shape} and {b.shape}")
        return self._check(a, b)

    def path_segments_feasible(self, path) -> np.ndarray:
        """Feasibility of each segment of a polyline (an (n, 2) array): shape (n − 1,); for a single
        point, shape (1,), the point's own feasibility."""
        path = _as_points(path, "path")
        if len(path) == 1:
            return self.points_feasible(path)
        return self.segments_feasible(path[:-1], path[1:])

    def path_feasible(self, path) -> bool:
        """Whether a whole polyline (start first) is feasible.

        Examples
        --------
        >>> geo = ContinuousGeometry(10, 10, [[4, 0, 6, 8]])
        >>> geo.path_feasible([[1, 1], [4, 8], [6, 8], [9, 1]]), geo.path_feasible([[1, 1], [9, 1]])
        (True, False)
        """
        return bool(self.path_segments_feasible(path).all())

    def paths_feasible(self, paths) -> np.ndarray:
        """Whether each of many polylines is feasible, in one vectorised check of all their segments.

        Parameters
        ----------
        paths : sequence of array_like, each shape (n_i, 2), n_i ≥ 1

        Returns
        -------
        ndarray of bool, shape (len(paths),)
        """
        paths = list(paths)
        if not paths:
            return np.zeros(0, dtype=bool)
        try:  # the hot path (a GA's population): one concatenation, checked as a whole
            sizes = np.array([len(p) for p in paths])
            points = np.concatenate(paths).astype(float, copy=False)
            if points.ndim != 2 or points.shape[1] != 2 or not np.isfinite(points).all():
                raise ValueError
        except (TypeError, ValueError):
            for i, p in enumerate(paths):
                _as_points(p, f"paths[{i}]")  # names the first bad one
            raise
        if (sizes == 0).any():
            raise ParameterError(f"paths[{int(np.argmin(sizes))}] is empty")
        a, b, owner = polyline_segments(points, sizes)
        ok = self._check(a, b)
        bad = np.zeros(len(paths), dtype=bool)
        np.logical_or.at(bad, owner[~ok], True)
        return ~bad

    # ---------------------------------------------------------------------------------------------
    # clearance

    def _edge_distance(self, pts: np.ndarray) -> np.ndarray:
        return np.minimum.reduce([pts[:, 0], self.width - pts[:, 0], pts[:, 1], self.height - pts[:, 1]])

    def _nearest(self, geoms: np.ndarray) -> np.ndarray:
        if not len(self._polys):
            return np.full(len(geoms), np.inf)
        (i, _), dist = self._tree.query_nearest(geoms, return_distance=True, all_matches=False)
        out = np.full(len(geoms), np.inf)
        out[i] = dist
        return out

    def clearance(self, points) -> np.ndarray:
        """Distance of each point to the nearest obstacle or map edge, minus the robot's radius
        (negative in collision).

        Returns
        -------
        ndarray of float, shape (n,)
        """
        pts = _as_points(points, "points")
        return np.minimum(self._nearest(shapely.points(pts)), self._edge_distance(pts)) - self.robot_radius

    def path_clearance(self, path) -> float:
        """The smallest clearance along a whole polyline (its segments, not only its vertices).

        Examples
        --------
        >>> ContinuousGeometry(10, 10, [[4, 4, 6, 6]]).path_clearance([[1, 5], [5, 2], [9, 5]])
        1.0
        """
        path = _as_points(path, "path")
        geom = shapely.points(path[:1]) if len(path) == 1 else np.array([shapely.linestrings(path)])
        # the distance to the map edge is concave along a segment: smallest at a vertex
        return float(min(self._nearest(geom)[0], self._edge_distance(path).min()) - self.robot_radius)

    def colliding_obstacle(self, point) -> int | None:
        """0-based index of an obstacle that a feasible-looking point is too close to (None if none):
        what an error message names."""
        pts = _as_points(point, "point")
        if not len(self._polys):
            return None
        geom = shapely.points(pts)
        if self.robot_radius == 0:
            hit = np.flatnonzero(shapely.contains_properly(self._polys, geom[0]))
        else:
            hit = np.flatnonzero(shapely.distance(self._polys, geom[0]) < self.robot_radius)
        return int(hit[0]) if len(hit) else None

    # ---------------------------------------------------------------------------------------------
    # corners

    def polygonised(self, kind: str = "inner") -> ContinuousGeometry:
        """For r > 0, the point-robot geometry (r = 0) of the C-obstacles polygonised with
        ``quad_segs=8`` inside F's box: ``"inner"`` (grown by r, inside the true C-obstacles: a
        relaxation, whose shortest paths are lower bounds) or ``"outer"`` (grown by r / cos(π/32),
        containing them: its corners are feasible). For r = 0, the geometry itself.

        Raises
        ------
        ParameterError
            If ``kind`` is neither.
        """
        if kind not in ("inner", "outer"):
            raise ParameterError(f"kind must be 'inner' or 'outer', got {kind!r}")
        if self.robot_radius == 0:
            return self
        grow = self.robot_radius * (1.0 if kind == "inner" else OUTER_FACTOR)
        grown = shapely.buffer(self._polys, grow, quad_segs=QUAD_SEGS)
        parts = [np.asarray(p.exterior.coords)[:-1] for p in grown]
        return ContinuousGeometry._from_parts(self.width, self.height, 0.0, self.bounds, parts)

    def corners(self) -> Corners:
        """The reflex corners of the free region (r = 0 geometries, e.g. :meth:`polygonised`): the
        convex obstacle vertices inside the box, where a shortest path may bend.

        Raises
        ------
        ParameterError
            For r > 0 (polygonise first).

        Examples
        --------
        >>> ContinuousGeometry(10, 10, [[4, 0, 6, 8]]).corners().points.tolist()
        [[4.0, 8.0], [6.0, 8.0]]
        """
        if self._free is None:
            raise ParameterError("corners() needs a point robot: use polygonised() first for r > 0")
        points, before, after = [], [], []
        for part in shapely.get_parts(shapely.orient_polygons(self._free)):
            for ring in [part.exterior, *part.interiors]:
                xy = np.asarray(ring.coords)[:-1]
                prev, nxt = np.roll(xy, 1, axis=0), np.roll(xy, -1, axis=0)
                u, v = xy - prev, nxt - xy
                cross = u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0]
                scale = np.hypot(*u.T) * np.hypot(*v.T)
                reflex = cross < -1e-12 * scale  # free region on the left: a right turn is reflex
                points.append(xy[reflex])
                before.append(prev[reflex])
                after.append(nxt[reflex])
        cat = (lambda xs: np.concatenate(xs) if xs else np.empty((0, 2)))
        return Corners(cat(points), cat(before), cat(after))
