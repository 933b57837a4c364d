"""Scenario files (shared/MODEL.md §6): one TOML file per environment.

A grid scenario::

    name = "three_slit"
    source = "Cheng et al. 2020, Fig. 9d (reconstructed)"
    licence = "BSD-3-Clause"       # optional: the terms of a map taken from elsewhere
    description = "..."            # optional
    cell_size_m = 0.25             # optional, d_grid in metres
    grid = '''
    ######
    #....#
    ######
    '''                            # rows top first, '#' obstacle, '.' free
    # or, instead of grid: map = "room.yaml"  (a ROS map_server map beside the file)
    hidden = [[5, 11], [6, 11]]    # optional: obstacles the planner does not know of
    [[roadmap]]                    # first = start, last = goal
    x = 1
    y = 1
    shape = "O"
    heading = 0                    # quarter turns, optional (0)
    [[moving]]                     # optional moving obstacles
    cells = [[3, 4], [4, 4]]       # cells at t = 0
    route = [[0, 0], [0, 6]]       # displacement waypoints
    speed = 1                      # cells per command, optional
    mode = "pingpong"              # or "loop", optional

A continuous scenario (Nazarahari et al. 2019) has ``width``, ``height``, ``obstacles`` (rectangles
``[xmin, ymin, xmax, ymax]`` or polygons ``[[x, y], ...]``), ``robot_radius`` and ``[[robots]]`` with
``start`` and ``goal`` points. Obstacles must be simple polygons; starts and goals must be
feasible (:mod:`htetro_opt.model.continuous`), and no two robots' starts (nor goals) closer than 2 r.
"""

from __future__ import annotations

import reprlib
import tomllib
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from typing import Any

import numpy as np

from htetro_opt._validation import check_int, check_real
from htetro_opt.errors import ConfigurationError, MapFormatError, ParameterError, ScenarioError, UnknownShapeError
from htetro_opt.model.robot import Pose, shape_index
from htetro_opt.model.workspace import MovingObstacle, Workspace, describe_cells
from htetro_opt.scenarios._paths import as_path
from htetro_opt.scenarios.rosmap import load_ros_map

__all__ = ["Scenario", "ContinuousScenario", "check_continuous_scenario", "load_scenario_file", "parse_scenario",
           "parse_grid", "format_grid"]

_GRID_KEYS = {"name", "source", "licence", "description", "cell_size_m", "grid", "map", "roadmap", "moving", "hidden"}
_CONTINUOUS_KEYS = {"name", "source", "licence", "description", "width", "height", "obstacles", "robot_radius", "robots"}


@dataclass(frozen=True, eq=False)  # holds arrays: identity equality, hashable
class Scenario:
    """A grid environment with its roadmap (first configuration = start, last = goal).

    ``source`` says where the layout comes from and ``licence`` under which terms it may be used and
    shared (empty for our own reconstructions, which the package's licence covers).
    """

    name: str
    source: str
    workspace: Workspace
    roadmap: tuple[Pose, ...] = ()
    description: str = ""
    hidden: np.ndarray = field(default_factory=lambda: np.empty((0, 2), dtype=np.int64))
    path: Path | None = None
    licence: str = ""

    @property
    def start(self) -> Pose | None:
        return self.roadmap[0] if self.roadmap else None

    @property
    def goal(self) -> Pose | None:
        return self.roadmap[-1] if len(self.roadmap) > 1 else None

    def true_workspace(self) -> Workspace:
        """The workspace with its hidden obstacles revealed."""
        occ = self.workspace.occupancy.copy()
        occ[self.hidden[:, 1], self.hidden[:, 0]] = True
        return Workspace(occ, self.workspace.cell_size, self.workspace.moving)


@dataclass(frozen=True, eq=False)  # holds arrays: identity equality, hashable
class ContinuousScenario:
    """A continuous W × H rectangle with polygon obstacles and disc robots (Nazarahari et al. 2019).

    ``obstacles`` are (n, 2) vertex arrays, ``starts`` and ``goals`` (k, 2) arrays, one row per
    robot. :attr:`geometry` answers feasibility and clearance questions
    (:class:`~htetro_opt.model.continuous.ContinuousGeometry`, built on first use).

    Examples
    --------
    >>> from htetro_opt.scenarios import load_scenario
    >>> sc = ContinuousScenario.from_grid(load_scenario("three_slit"), robot_radius="O")
    >>> sc.width, sc.n_robots, round(sc.robot_radius, 4), sc.geometry.points_feasible(sc.starts).tolist()
    (24.0, 1, 1.4142, [True])
    """

    name: str
    source: str
    width: float
    height: float
    obstacles: tuple[np.ndarray, ...]
    robot_radius: float
    starts: np.ndarray
    goals: np.ndarray
    description: str = ""
    path: Path | None = None
    licence: str = ""

    @property
    def n_robots(self) -> int:
        return len(self.starts)

    @cached_property
    def geometry(self):
        """The workspace's :class:`~htetro_opt.model.continuous.ContinuousGeometry` (shapely objects
        built once per scenario)."""
        from htetro_opt.model.continuous import ContinuousGeometry  # shapely loads for continuous work only

        return ContinuousGeometry(self.width, self.height, self.obstacles, robot_radius=self.robot_radius)

    def with_robot_radius(self, robot_radius) -> ContinuousScenario:
        """The same scenario for robots of another radius (a number ≥ 0 or a morphology letter: the
        disc enclosing that hTetro footprint), checked as a file is.

        Raises
        ------
        ParameterError
            If the radius is neither a number ≥ 0 nor a shape letter.
        ConfigurationError
            If a start or goal then collides, leaves the workspace, or two robots overlap.
        """
        from htetro_opt.model.continuous import as_robot_radius

        radius = as_robot_radius(robot_radius)
        geometry = _continuous_geometry(self.width, self.height, self.obstacles, radius, self.name)
        _check_robots(geometry, self.starts, self.goals, self.name)
        return ContinuousScenario(self.name, self.source, self.width, self.height, self.obstacles, radius,
                                  self.starts, self.goals, self.description, self.path, self.licence)

    @classmethod
    def from_grid(cls, scenario: Scenario, *, robot_radius=0.0) -> ContinuousScenario:
        """A grid scenario as a continuous one, so that its maps can be compared: each obstacle cell
        (x, y) is the unit square [x, x + 1] × [y, y + 1] (a row's runs of cells merged into
        rectangles), the roadmap's first and last configurations give the start and goal, at their
        B2 cell's centre. Units are cells.

        Parameters
        ----------
        scenario : Scenario
            A grid scenario with a roadmap.
        robot_radius : float or str, keyword-only
            A number ≥ 0 or a morphology letter (the disc enclosing that footprint, e.g. ``"O"``).

        Raises
        ------
        ScenarioError
            If ``scenario`` is not a grid scenario or has no start and goal.
        ParameterError
            On a bad radius.
        ConfigurationError
            If the start or goal collides at that radius.
        """
        from htetro_opt.model.continuous import as_robot_radius

        if not isinstance(scenario, Scenario):
            raise ScenarioError(f"scenario must be a grid Scenario, got {type(scenario).__name__}")
        if scenario.goal is None:
            raise ScenarioError(f"scenario {scenario.name!r} has no start and goal (its roadmap has "
                                f"{len(scenario.roadmap)} configuration(s))")
        radius = as_robot_radius(robot_radius)
        occ = scenario.workspace.occupancy
        obstacles = []
        for y, row in enumerate(occ):
            padded = np.concatenate([[False], row, [False]]).astype(np.int8)
            edges = np.flatnonzero(np.diff(padded))
            for x0, x1 in zip(edges[::2].tolist(), edges[1::2].tolist()):
                obstacles.append(np.array([[x0, y], [x1, y], [x1, y + 1], [x0, y + 1]], dtype=float))
        starts = np.array([[scenario.start.x + 0.5, scenario.start.y + 0.5]])
        goals = np.array([[scenario.goal.x + 0.5, scenario.goal.y + 0.5]])
        width, height = float(occ.shape[1]), float(occ.shape[0])
        geometry = _continuous_geometry(width, height, obstacles, radius, scenario.name)
        _check_robots(geometry, starts, goals, scenario.name)
        source = f"{scenario.source} (as a continuous workspace)" if scenario.source else "a grid scenario"
        return cls(scenario.name, source, width, height, tuple(obstacles), radius, starts, goals,
                   scenario.description, scenario.path, scenario.licence)


def check_continuous_scenario(scenario) -> ContinuousScenario:
    """``scenario`` itself if it is a :class:`ContinuousScenario` (what the continuous planners and
    :class:`~htetro_opt.problems.PathBasesProblem` accept).

    Raises
    ------
    ScenarioError
        For a grid scenario (naming the way across: ``ContinuousScenario.from_grid``) or anything else.

    Examples
    --------
    >>> from htetro_opt.scenarios import load_scenario
    >>> check_continuous_scenario(load_scenario("three_slit"))
    Traceback (most recent call last):
    ...
    htetro_opt.errors.ScenarioError: scenario 'three_slit' is a grid scenario: plan it with plan_path, or convert it with ContinuousScenario.from_grid(scenario, robot_radius=...)
    """
    if isinstance(scenario, ContinuousScenario):
        return scenario
    if isinstance(scenario, Scenario):
        raise ScenarioError(f"scenario {scenario.name!r} is a grid scenario: plan it with plan_path, or convert it "
                            "with ContinuousScenario.from_grid(scenario, robot_radius=...)")
    raise ScenarioError(f"scenario must be a ContinuousScenario, got {type(scenario).__name__}")


def parse_grid(text: str, *, where: str = "grid") -> np.ndarray:
    """Occupancy ``occ[y, x]`` of a text grid (rows top first, ``#`` obstacle, ``.`` free).

    Raises
    ------
    MapFormatError
        On an empty grid, ragged rows or an unknown character, naming its row and column (1-based,
        counted from the top).

    Examples
    --------
    >>> parse_grid("#..\\n...").astype(int).tolist()
    [[0, 0, 0], [1, 0, 0]]
    """
    if not isinstance(text, str):
        raise MapFormatError(f"{where}: expected a string of rows, got {type(text).__name__}")
    rows = [row.strip() for row in text.strip("\n").splitlines()]
    while rows and not rows[0]:
        rows.pop(0)
    while rows and not rows[-1]:
        rows.pop()
    if not rows:
        raise MapFormatError(f"{where}: the grid is empty")
    width = len(rows[0])
    for r, row in enumerate(rows, start=1):
        if len(row) != width:
            raise MapFormatError(f"{where}: row {r} has {len(row)} cells, row 1 has {width} (ragged grid)")
        for c, char in enumerate(row, start=1):
            if char not in "#.":
                raise MapFormatError(f"{where}: unknown character {char!r} at row {r}, column {c} (use '#' or '.')")
    occ = np.array([[char == "#" for char in row] for row in rows], dtype=bool)
    return occ[::-1].copy()


def format_grid(occupancy: np.ndarray) -> str:
    """Text rows (top first) of an occupancy grid; the inverse of :func:`parse_grid`.

    Raises
    ------
    ScenarioError
        If ``occupancy`` is not a non-empty 2-D array of booleans or 0/1.

    Examples
    --------
    >>> print(format_grid([[0, 0, 0], [1, 0, 0]]))
    #..
    ...
    """
    return "\n".join("".join("#" if v else "." for v in row) for row in Workspace(occupancy).occupancy[::-1])


def _require(table: dict, key: str, kinds, where: str):
    if key not in table:
        raise ScenarioError(f"{where}: missing key {key!r}")
    value = table[key]
    if isinstance(value, bool) or not isinstance(value, kinds):
        names = kinds.__name__ if isinstance(kinds, type) else " or ".join(k.__name__ for k in kinds)
        raise ScenarioError(f"{where}: {key!r} must be {names}, got {type(value).__name__}")
    return value


def _header(data: dict, allowed: set[str], where: str, default_name: str | None) -> tuple[str, str, str, str]:
    """Check a scenario's keys; its name (``default_name``, the file's stem, when absent), source,
    description and licence (all optional: a user's own map needs no bookkeeping)."""
    unknown = set(data) - allowed
    if unknown:
        raise ScenarioError(f"{where}: unknown key(s) {', '.join(sorted(unknown))}")
    if "name" in data or default_name is None:
        name = _require(data, "name", str, where)
    else:
        name = default_name
    texts = []
    for key in ("source", "description", "licence"):
        value = data.get(key, "")
        if not isinstance(value, str):
            raise ScenarioError(f"{where}: {key!r} must be a string, got {type(value).__name__}")
        texts.append(value)
    return name, texts[0], texts[1], texts[2]


def _array(data: dict, key: str, where: str, *, tables: bool = False) -> list:
    value = data.get(key, [])
    if not isinstance(value, list):
        kind = f"an array of tables ([[{key}]])" if tables else "an array"
        raise ScenarioError(f"{where}: {key!r} must be {kind}, got {type(value).__name__}")
    return value


def _number(table: dict, key: str, where: str, default=None, **bounds) -> float:
    """A finite number (within :func:`~htetro_opt._validation.check_real`'s ``bounds``) from a TOML table."""
    value = table.get(key, default)
    if value is None:
        raise ScenarioError(f"{where}: missing key {key!r}")
    try:
        return check_real(value, f"{where}: {key!r}", **bounds)
    except ParameterError as err:  # a file's content: the loader's error
        raise ScenarioError(str(err)) from err


def _cells(value: Any, where: str) -> np.ndarray:
    try:
        cells = np.array(value, dtype=np.int64).reshape(-1, 2)
        if np.array(value).size and np.array(value).ndim != 2:
            raise ValueError
        if not np.array_equal(np.array(value, dtype=float).reshape(-1, 2), cells):
            raise ValueError
    except (TypeError, ValueError) as err:
        raise ScenarioError(f"{where}: expected a list of [x, y] integer pairs") from err
    return cells


def _check_route(obstacle: MovingObstacle, occ: np.ndarray, where: str) -> None:
    h, w = occ.shape
    for t in range(obstacle.period):
        for x, y in obstacle.cells_during(t).tolist():
            if not (0 <= x < w and 0 <= y < h):
                raise ScenarioError(f"{where}: the obstacle leaves the {w} x {h} map at ({x}, {y}) at time {t}")
            if occ[y, x]:
                raise ScenarioError(f"{where}: the obstacle runs into static obstacle cell ({x}, {y}) at time {t}")


def _pose(entry: Any, where: str) -> Pose:
    if not isinstance(entry, dict):
        raise ScenarioError(f"{where}: expected a table with x, y, shape and heading")
    unknown = set(entry) - {"x", "y", "shape", "heading"}
    if unknown:
        raise ScenarioError(f"{where}: unknown key(s) {', '.join(sorted(unknown))}")
    x = _require(entry, "x", int, where)
    y = _require(entry, "y", int, where)
    shape = _require(entry, "shape", str, where)
    heading = entry.get("heading", 0)
    try:
        shape_index(shape)
        return Pose.of(x, y, shape, heading)
    except UnknownShapeError as err:
        raise UnknownShapeError(f"{where}: {err}") from err
    except ConfigurationError as err:
        raise ConfigurationError(f"{where}: {err}") from err


def _check_pose_on_map(pose: Pose, workspace: Workspace, where: str, t: int | None = None) -> None:
    outside, hits = workspace.conflicts(pose.cells(), t)
    if outside:
        raise ConfigurationError(
            f"{where}: {pose.shape}-shape at ({pose.x}, {pose.y}) heading {pose.heading} "
            f"has block(s) outside the {workspace.width} x {workspace.height} map at {describe_cells(outside)}"
        )
    if hits:
        raise ConfigurationError(
            f"{where}: {pose.shape}-shape at ({pose.x}, {pose.y}) heading {pose.heading} collides with obstacles "
            f"at {describe_cells(hits)}"
        )


def parse_scenario(data: dict, *, where: str = "scenario", base: Path | None = None,
                   default_name: str | None = None) -> Scenario | ContinuousScenario:
    """Build a scenario from a parsed TOML table (see the module docstring for the format).

    ``name`` may be left out when ``default_name`` is given (a file's stem); ``source`` and
    ``description`` are optional.

    Raises
    ------
    ScenarioError, MapFormatError
        On missing, unknown or mistyped keys and malformed grids or maps.
    ConfigurationError
        If a roadmap configuration leaves the map or collides with an obstacle.
    UnknownShapeError
        If a roadmap configuration names an unknown shape.
    """
    if not isinstance(data, dict):
        raise ScenarioError(f"{where}: data must be a table (a dict, as tomllib reads a file), "
                            f"got {type(data).__name__} {reprlib.repr(data)}")
    if "grid" not in data and "map" not in data and ("width" in data or "robots" in data):
        return _parse_continuous(data, where=where, base=base, default_name=default_name)
    name, source, description, licence = _header(data, _GRID_KEYS, where, default_name)
    if ("grid" in data) == ("map" in data):
        raise ScenarioError(f"{where}: give exactly one of 'grid' (text rows) or 'map' (a ROS map YAML)")
    cell_size = None
    if "cell_size_m" in data:
        cell_size = _number(data, "cell_size_m", where, minimum=0.0, include_minimum=False)
    if "grid" in data:
        occ = parse_grid(_require(data, "grid", str, where), where=f"{where}: grid")
        cell_size = float(cell_size) if cell_size is not None else 1.0
    else:
        map_path = Path(_require(data, "map", str, where))
        if not map_path.is_absolute() and base is not None:
            map_path = base / map_path
        occ, cell_size = load_ros_map(map_path, cell_size=None if cell_size is None else float(cell_size))
    moving = []
    for i, entry in enumerate(_array(data, "moving", where, tables=True), start=1):
        at = f"{where}: moving[{i}]"
        if not isinstance(entry, dict):
            raise ScenarioError(f"{at}: expected a table with cells, route, speed and mode")
        extra = set(entry) - {"cells", "route", "speed", "mode"}
        if extra:
            raise ScenarioError(f"{at}: unknown key(s) {', '.join(sorted(extra))}")
        cells = _cells(_require(entry, "cells", list, at), f"{at}: cells")
        route = _cells(entry.get("route", [[0, 0]]), f"{at}: route")
        try:
            speed = check_int(entry.get("speed", 1), f"{at}: 'speed' (cells per command)", minimum=1)
        except ParameterError as err:  # a file's content: the loader's error
            raise ScenarioError(str(err)) from err
        try:
            obstacle = MovingObstacle(cells, route, speed=speed, mode=entry.get("mode", "pingpong"))
        except ScenarioError as err:
            raise ScenarioError(f"{at}: {err}") from err
        _check_route(obstacle, occ, at)
        moving.append(obstacle)
    hidden = _cells(_array(data, "hidden", where), f"{where}: hidden")
    h, w = occ.shape
    for x, y in hidden.tolist():
        if not (0 <= x < w and 0 <= y < h):
            raise ScenarioError(f"{where}: hidden obstacle ({x}, {y}) lies outside the {w} x {h} map")
    entries = _array(data, "roadmap", where, tables=True)
    try:
        workspace = Workspace(occ, cell_size, tuple(moving))
    except ScenarioError as err:
        raise ScenarioError(f"{where}: {err}") from err
    roadmap = []
    for i, entry in enumerate(entries, start=1):
        at = f"{where}: roadmap[{i}]" + (" (start)" if i == 1 else " (goal)" if i == len(entries) else "")
        pose = _pose(entry, at)
        _check_pose_on_map(pose, workspace, at, t=0 if i == 1 else None)
        if i == 1 and len(hidden):
            revealed = occ.copy()
            revealed[hidden[:, 1], hidden[:, 0]] = True
            _check_pose_on_map(pose, Workspace(revealed), f"{at} (against the hidden obstacles)")
        roadmap.append(pose)
    return Scenario(name, source, workspace, tuple(roadmap), description, hidden, base, licence)


def _continuous_geometry(width, height, obstacles, radius, where):
    from htetro_opt.model.continuous import ContinuousGeometry  # shapely loads for continuous work only

    try:
        return ContinuousGeometry(width, height, obstacles, robot_radius=radius)
    except ParameterError as err:
        raise ScenarioError(f"{where}: {err}") from err


def _check_robots(geometry, starts: np.ndarray, goals: np.ndarray, where: str) -> None:
    """Starts and goals inside F (the shrunk box, clear of the C-obstacles), no two robots' starts
    (nor goals) closer than 2 r (nor equal)."""
    r = geometry.robot_radius
    for key, points in (("start", starts), ("goal", goals)):
        feasible = geometry.points_feasible(points)
        for i in np.flatnonzero(~feasible).tolist():
            at, point = f"{where}: robots[{i + 1}]", points[i].tolist()
            hit = geometry.colliding_obstacle(points[i])
            if hit is None:
                raise ConfigurationError(f"{at}: {key} {point} (radius {r:g}) lies outside the "
                                         f"{geometry.width:g} x {geometry.height:g} workspace")
            raise ConfigurationError(f"{at}: {key} {point} collides with obstacles[{hit + 1}] (radius {r:g})")
    for key, points in (("start", starts), ("goal", goals)):
        if len(points) > 1:
            gaps = np.hypot(*(points[:, None] - points[None]).transpose(2, 0, 1))
            close = np.argwhere(np.triu((gaps < 2 * r) | (gaps == 0), 1))
            if len(close):
                i, j = close[0].tolist()
                raise ConfigurationError(f"{where}: robots[{i + 1}] and robots[{j + 1}] overlap: their {key}s "
                                         f"{points[i].tolist()} and {points[j].tolist()} are {gaps[i, j]:g} "
                                         f"apart, less than 2 r = {2 * r:g}")


def _parse_continuous(data: dict, *, where: str, base: Path | None, default_name: str | None = None) -> ContinuousScenario:
    from htetro_opt.model.continuous import as_polygon

    name, source, description, licence = _header(data, _CONTINUOUS_KEYS, where, default_name)
    width = _number(data, "width", where, minimum=0.0, include_minimum=False)
    height = _number(data, "height", where, minimum=0.0, include_minimum=False)
    radius = _number(data, "robot_radius", where, default=0.0, minimum=0.0)
    obstacles = []
    for i, item in enumerate(_array(data, "obstacles", where), start=1):
        try:
            obstacles.append(as_polygon(item, f"{where}: obstacles[{i}]"))
        except ParameterError as err:  # a file's content: the loader's error
            raise ScenarioError(str(err)) from err
    geometry = _continuous_geometry(width, height, obstacles, radius, where)
    robots = _array(data, "robots", where, tables=True)
    if not robots:
        raise ScenarioError(f"{where}: 'robots' needs at least one robot ([[robots]] with start and goal)")
    points = {"start": [], "goal": []}
    for i, robot in enumerate(robots, start=1):
        at = f"{where}: robots[{i}]"
        if not isinstance(robot, dict) or set(robot) - {"start", "goal"}:
            raise ScenarioError(f"{at}: expected a table with 'start' and 'goal'")
        for key, out in points.items():
            value = _require(robot, key, list, at)
            try:
                point = np.array(value, dtype=float)
            except (TypeError, ValueError) as err:
                raise ScenarioError(f"{at}: {key} must be [x, y] numbers, got {value!r}") from err
            if point.shape != (2,) or not np.isfinite(point).all():
                raise ScenarioError(f"{at}: {key} must be [x, y] numbers, got {value!r}")
            out.append(point)
    starts, goals = np.array(points["start"]), np.array(points["goal"])
    _check_robots(geometry, starts, goals, where)
    scenario = ContinuousScenario(name, source, width, height, tuple(obstacles), radius, starts, goals,
                                  description, base, licence)
    scenario.__dict__["geometry"] = geometry  # built for the checks: the cached property's value
    return scenario


def load_scenario_file(path: str | Path) -> Scenario | ContinuousScenario:
    """Read one scenario TOML file.

    Raises
    ------
    ScenarioError
        If ``path`` is not a path, the file cannot be read or is not valid TOML (with the parser's
        line and column), or a key is missing, unknown or mistyped (naming the file and the key).
    """
    path = as_path(path, "path")
    try:
        text = path.read_text(encoding="utf-8-sig")  # a byte-order mark, as some editors write, is fine
    except OSError as err:
        raise ScenarioError(f"{path}: cannot read scenario: {err.strerror or err}") from err
    except UnicodeDecodeError as err:
        raise ScenarioError(f"{path}: not a UTF-8 text file") from err
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise ScenarioError(f"{path}: malformed TOML: {' '.join(str(err).split())}") from err
    return parse_scenario(data, where=str(path.name), base=path.parent, default_name=path.stem)
