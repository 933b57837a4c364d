"""Grid workspaces, moving obstacles and grid distances (shared/MODEL.md §1, §5).

Cell ``(x, y)`` has x growing to the right and y upwards; occupancy is ``occ[y, x]`` with True for an
obstacle, and every cell outside the map counts as an obstacle. Moving obstacles advance along their
route by ``speed`` cells per command executed (time index t = number of commands executed so far).
"""

from __future__ import annotations

import math
import reprlib
from dataclasses import dataclass, field

import numpy as np

from htetro_opt._validation import check_bool, check_int, check_real
from htetro_opt.errors import ConfigurationError, ParameterError, ScenarioError

__all__ = ["Workspace", "MovingObstacle", "grid_distance", "check_workspace", "describe_cells"]


@dataclass(frozen=True, eq=False)  # holds arrays: identity equality, hashable
class MovingObstacle:
    """A rigid group of cells patrolling a route.

    Parameters
    ----------
    cells : ndarray of int, shape (n, 2)
        (x, y) cells the obstacle covers at t = 0.
    route : ndarray of int, shape (m, 2)
        Waypoints of the obstacle's displacement from ``cells``; the first is (0, 0). Between two
        waypoints the obstacle moves one cell per unit step along each axis that still differs (so
        diagonal segments are allowed).
    speed : int
        Unit steps taken per command executed.
    mode : {"pingpong", "loop"}
        Patrol back and forth along the route, or return from its last waypoint to its first.
    """

    cells: np.ndarray
    route: np.ndarray
    speed: int = 1
    mode: str = "pingpong"
    _steps: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        cells, route = _cell_pairs(self.cells, "cells"), _cell_pairs(self.route, "route")
        if len(cells) == 0:
            raise ScenarioError("a moving obstacle needs at least one cell")
        if len(route) == 0 or route[0].any():
            route = np.vstack([np.zeros((1, 2), dtype=np.int64), route])
        try:
            speed = check_int(self.speed, "moving obstacle speed", minimum=1)
        except ParameterError as err:  # obstacles come from scenario files: the loader's error
            raise ScenarioError(str(err)) from err
        if self.mode not in ("pingpong", "loop"):
            raise ScenarioError(f"moving obstacle mode must be 'pingpong' or 'loop', got {self.mode!r}")
        path = [route[0]]
        waypoints = list(route[1:]) + ([route[0]] if self.mode == "loop" else [])
        for target in waypoints:
            while (path[-1] != target).any():
                path.append(path[-1] + np.sign(target - path[-1]))
        unit = np.array(path)
        if self.mode == "pingpong" and len(unit) > 1:
            unit = np.vstack([unit, unit[-2:0:-1]])
        elif self.mode == "loop" and len(unit) > 1:
            unit = unit[:-1]
        object.__setattr__(self, "cells", cells)
        object.__setattr__(self, "route", route)
        object.__setattr__(self, "speed", speed)
        object.__setattr__(self, "_steps", unit)

    @property
    def period(self) -> int:
        """Number of commands after which the obstacle is back where it started."""
        n = len(self._steps)
        return n // math.gcd(n, self.speed)

    def displacement(self, t: int) -> np.ndarray:
        """Displacement (dx, dy) at time t."""
        return self._steps[(t * self.speed) % len(self._steps)]

    def cells_at(self, t: int) -> np.ndarray:
        """Cells covered at time t, shape (n, 2)."""
        return self.cells + self.displacement(t)

    def cells_during(self, t: int) -> np.ndarray:
        """Cells covered at any instant between time t and t + 1 (every unit step in between)."""
        start = t * self.speed
        shifts = self._steps[np.arange(start, start + self.speed + 1) % len(self._steps)]
        return (self.cells[None, :, :] + shifts[:, None, :]).reshape(-1, 2)


@dataclass(frozen=True, eq=False)  # holds arrays: identity equality, hashable
class Workspace:
    """A W × H grid of cells with static occupancy and optional moving obstacles.

    Parameters
    ----------
    occupancy : array_like of bool, shape (H, W)
        ``occ[y, x]``, True for an obstacle; row 0 is the bottom row.
    cell_size : float
        d_grid in metres (1.0 when the map has no scale).
    moving : tuple of MovingObstacle
        Obstacles that move while the robot executes commands.

    Examples
    --------
    >>> ws = Workspace(np.zeros((3, 4), dtype=bool))
    >>> ws.width, ws.height, ws.is_free(3, 2), ws.is_free(4, 0)
    (4, 3, True, False)
    """

    occupancy: np.ndarray
    cell_size: float = 1.0
    moving: tuple[MovingObstacle, ...] = ()

    def __post_init__(self) -> None:
        occ = _occupancy(self.occupancy)
        moving = self.moving
        if isinstance(moving, MovingObstacle):
            moving = (moving,)
        if not isinstance(moving, (tuple, list)) or not all(isinstance(m, MovingObstacle) for m in moving):
            raise ScenarioError(f"moving must be a sequence of MovingObstacle, got {reprlib.repr(self.moving)}")
        try:
            cell_size = check_real(self.cell_size, "cell_size", minimum=0.0, include_minimum=False)
        except ParameterError as err:  # maps come from scenario files: the loader's error
            raise ScenarioError(str(err)) from err
        object.__setattr__(self, "cell_size", cell_size)
        occ.setflags(write=False)
        object.__setattr__(self, "occupancy", occ)
        object.__setattr__(self, "moving", tuple(moving))

    @property
    def width(self) -> int:
        return int(self.occupancy.shape[1])

    @property
    def height(self) -> int:
        return int(self.occupancy.shape[0])

    @property
    def period(self) -> int:
        """Period of the moving obstacles in commands (1 for a static workspace)."""
        return math.lcm(*(m.period for m in self.moving)) if self.moving else 1

    def contains(self, x: int, y: int) -> bool:
        return 0 <= x < self.width and 0 <= y < self.height

    def is_free(self, x: int, y: int, t: int | None = None) -> bool:
        """Whether a cell is inside the map and free (of moving obstacles too when ``t`` is given)."""
        if not self.contains(x, y):
            return False
        occ = self.occupancy if t is None else self.occupancy_at(t)
        return not occ[y, x]

    def conflicts(self, cells, t: int | None = None) -> tuple[list[tuple[int, int]], list[tuple[int, int]]]:
        """Which of some (x, y) cells lie outside the map, and which on an obstacle.

        With ``t``, moving obstacles at time t count too.

        Returns
        -------
        outside, occupied : list of (int, int)
        """
        occ = self.occupancy if t is None else self.occupancy_at(t)
        outside, occupied = [], []
        for x, y in np.asarray(cells).reshape(-1, 2).tolist():
            if not self.contains(x, y):
                outside.append((x, y))
            elif occ[y, x]:
                occupied.append((x, y))
        return outside, occupied

    def _mark(self, cells_of) -> np.ndarray:
        occ = np.zeros_like(self.occupancy)
        for obstacle in self.moving:
            cells = cells_of(obstacle)
            inside = (cells[:, 0] >= 0) & (cells[:, 0] < self.width) & (cells[:, 1] >= 0) & (cells[:, 1] < self.height)
            occ[cells[inside, 1], cells[inside, 0]] = True
        return occ

    def moving_at(self, t: int) -> np.ndarray:
        """Cells covered by moving obstacles at time t, as an (H, W) bool array."""
        return self._mark(lambda m: m.cells_at(t))

    def moving_during(self, t: int) -> np.ndarray:
        """Cells covered by moving obstacles at any instant of step t → t + 1, (H, W) bool."""
        return self._mark(lambda m: m.cells_during(t))

    def occupancy_at(self, t: int) -> np.ndarray:
        """Static and moving occupancy at time t, (H, W) bool."""
        return self.occupancy | self.moving_at(t) if self.moving else self.occupancy

    def without_moving(self) -> "Workspace":
        """The same map with its moving obstacles removed."""
        return Workspace(self.occupancy, self.cell_size)


def _occupancy(value) -> np.ndarray:
    """An occupancy grid as a fresh bool array: booleans, or numbers that are all 0 or 1."""
    try:
        occ = np.array(value)
    except (TypeError, ValueError):
        occ = None
    if occ is not None and occ.dtype != bool:
        if occ.ndim != 2 or not np.issubdtype(occ.dtype, np.number) or not np.isin(occ, (0, 1)).all():
            occ = None
        else:
            occ = occ.astype(bool)
    if occ is None or occ.ndim != 2 or occ.shape[0] == 0 or occ.shape[1] == 0:
        got = (f"shape {occ.shape}" if occ is not None and occ.dtype == bool
               else f"{type(value).__name__} {reprlib.repr(value)}")
        raise ScenarioError(f"occupancy must be a non-empty 2-D array of booleans (True = obstacle) or 0/1, got {got}")
    return occ


def _cell_pairs(value, name: str) -> np.ndarray:
    """(x, y) integer pairs as an (n, 2) int64 array."""
    try:
        array = np.asarray(value)
        ok = array.size == 0 or (np.issubdtype(array.dtype, np.integer) and array.ndim <= 2 and array.size % 2 == 0
                                 and (array.ndim < 2 or array.shape[-1] == 2))
    except (TypeError, ValueError):
        ok = False
    if not ok:
        raise ScenarioError(f"moving obstacle {name} must be (x, y) integer pairs, got {reprlib.repr(value)}")
    return array.astype(np.int64).reshape(-1, 2)


def describe_cells(cells, limit: int = 5) -> str:
    """A short text of some (x, y) cells for a message: how many, and at most ``limit`` of them.

    Examples
    --------
    >>> describe_cells([(0, 0)]), describe_cells([(0, 0), (1, 0)])
    ('cell (0, 0)', '2 cells (0, 0), (1, 0)')
    >>> describe_cells([(x, 0) for x in range(40)], limit=3)
    '40 cells (0, 0), (1, 0), (2, 0) and 37 more'
    """
    pairs = [(int(x), int(y)) for x, y in np.asarray(cells).reshape(-1, 2).tolist()]
    if len(pairs) == 1:
        return f"cell {pairs[0]}"
    shown = ", ".join(map(str, pairs[:limit]))
    more = f" and {len(pairs) - limit} more" if len(pairs) > limit else ""
    return f"{len(pairs)} cells {shown}{more}"


def check_workspace(workspace, name: str = "workspace", *, what: str = "a Workspace") -> "Workspace":
    """``workspace`` itself if it is a :class:`Workspace`: the one check of every argument that takes one
    (``what`` says what the argument may be, for one that also takes a compiled simulator).

    Raises
    ------
    ParameterError
        Naming ``name`` and what it got.

    Examples
    --------
    >>> check_workspace("map.toml")
    Traceback (most recent call last):
    ...
    htetro_opt.errors.ParameterError: workspace must be a Workspace (e.g. Workspace(occupancy), or a scenario's .workspace), got str 'map.toml'
    """
    if not isinstance(workspace, Workspace):
        raise ParameterError(f"{name} must be {what} (e.g. Workspace(occupancy), or a scenario's .workspace), "
                             f"got {type(workspace).__name__} {reprlib.repr(workspace)}")
    return workspace


_BFS_CELLS = 10_000
"""Maps of at most this many cells get their 4-connected distances by a breadth-first search in the interpreter
(about 1 us a cell: 10 ms at most) rather than by scipy's Dijkstra, which costs 0.08 s to import; the distances
are whole numbers of steps, so both give the same floats."""


def _breadth_first(free: np.ndarray, gx: int, gy: int) -> np.ndarray:
    """4-connected steps from every cell to (gx, gy) over ``free`` cells, ``inf`` where unreachable."""
    h, w = free.shape
    n = h * w
    usable = free.ravel().tolist()
    dist = [-1] * n
    goal = gy * w + gx
    dist[goal] = 0
    queue, i = [goal], 0
    while i < len(queue):
        cell = queue[i]
        i += 1
        step = dist[cell] + 1
        x = cell % w
        for nb, inside in ((cell - 1, x > 0), (cell + 1, x < w - 1), (cell - w, cell >= w), (cell + w, cell < n - w)):
            if inside and usable[nb] and dist[nb] < 0:
                dist[nb] = step
                queue.append(nb)
    out = np.array(dist, dtype=float).reshape(h, w)
    out[out < 0] = np.inf
    return out


def grid_distance(workspace: Workspace, goal: tuple[int, int], *, diagonals: bool = False) -> np.ndarray:
    """Shortest path length from every free cell to ``goal`` over free cells (MODEL.md §5, W_A*).

    Moves are 4-connected with length 1 (plus diagonal moves of length √2 between free cells when
    ``diagonals``, not cutting an obstacle corner); moving obstacles are ignored.

    Parameters
    ----------
    workspace : Workspace
    goal : (int, int)
        The goal cell (x, y).
    diagonals : bool, keyword-only

    Returns
    -------
    ndarray of float, shape (H, W)
        ``inf`` on obstacles and cells that cannot reach the goal.

    Raises
    ------
    ConfigurationError
        If the goal cell is not a pair of integers, outside the map or on an obstacle.
    ParameterError
        If ``workspace`` is not a Workspace or ``diagonals`` not True or False.

    Examples
    --------
    >>> grid_distance(Workspace(np.zeros((1, 3), dtype=bool)), (0, 0)).tolist()
    [[0.0, 1.0, 2.0]]
    """
    check_workspace(workspace)
    diagonals = check_bool(diagonals, "diagonals")
    try:
        gx, gy = goal
        gx, gy = check_int(gx, "goal x"), check_int(gy, "goal y")
    except (TypeError, ValueError) as err:  # ParameterError among them
        raise ConfigurationError(f"goal must be a cell (x, y) of integers, got {reprlib.repr(goal)}") from err
    if not workspace.is_free(gx, gy):
        raise ConfigurationError(f"goal cell ({gx}, {gy}) is outside the map or on an obstacle")
    free = ~workspace.occupancy
    h, w = free.shape
    if not diagonals and h * w <= _BFS_CELLS:
        return _breadth_first(free, gx, gy)
    from scipy.sparse import coo_matrix  # here, not at import: importing scipy.sparse.csgraph costs 0.08 s
    from scipy.sparse.csgraph import dijkstra

    index = np.arange(h * w).reshape(h, w)
    rows, cols, weights = [], [], []
    moves = [(1, 0, 1.0), (0, 1, 1.0)]
    if diagonals:
        moves += [(1, 1, math.sqrt(2.0)), (1, -1, math.sqrt(2.0))]
    for dx, dy, length in moves:
        ys = slice(max(0, -dy), h - max(0, dy))
        xs = slice(0, w - dx)
        ys2 = slice(max(0, dy), h - max(0, -dy))
        xs2 = slice(dx, w)
        ok = free[ys, xs] & free[ys2, xs2]
        if dx and dy:  # no corner cutting
            ok &= free[ys2, xs] & free[ys, xs2]
        rows.append(index[ys, xs][ok])
        cols.append(index[ys2, xs2][ok])
        weights.append(np.full(int(ok.sum()), length))
    r, c, wt = np.concatenate(rows), np.concatenate(cols), np.concatenate(weights)
    graph = coo_matrix((wt, (r, c)), shape=(h * w, h * w)).tocsr()
    dist = dijkstra(graph, directed=False, indices=int(index[gy, gx]))
    return dist.reshape(h, w)
