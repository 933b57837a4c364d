"""The coverage motion model of Le et al. 2018 (§5, part two; Tables 4–5, Figs. 17–19), for any waypoint order.

The paper drives a simulated hTetro through the waypoints of a tileset in a given order and reports,
per strategy, the distance travelled by the blocks, the average time spent on a grid cell, a
coverage heat map "normalized to the range from 0 to 255" and the share of cells whose heat exceeds
100 or 150 (the re-covered area). This module's model of that run:

- **Motion.** The robot starts at the first waypoint. Between consecutive waypoints every block
  moves in a straight line from its cell centre at one waypoint to its cell centre at the next, all
  four blocks leaving and arriving together; the segment lasts ``longest block displacement /
  speed``. The same straight-line motion is how the blocks shapeshift at a waypoint. The motion
  ignores obstacles between waypoints, as the paper's cost does (its §7 leaves obstacle-aware costs
  to future work): a block may sweep across an obstacle cell.
- **Dwelling.** At every waypoint (the first and the last included) the robot stays ``dwell``
  seconds: "each grid in the workspace required at least 1 s to be covered".
- **Coverage time.** The grid is rasterised at ``pixels_per_cell`` pixels per cell side; a pixel is
  covered while its centre lies inside a block's unit square. The time is exact: for a square
  translating linearly, the instants a point is inside it form one interval per axis, and their
  intersection's length is the coverage time. ``cell_time`` is the mean pixel time over a cell, and
  the average grid time is its mean over the free cells.
- **Heat map.** The pixel times scaled to 0…255, by default so that the most covered pixel is 255
  (or by a fixed number of seconds mapped to 255, so that runs can be compared on one scale). A
  cell's heat is the mean of its pixels' heat ("the average pixel values of cells were considered").
- **Re-covered area** (Table 5): the percentage of cells whose heat exceeds a threshold. The paper
  divides by all 121 cells of its 11 × 11 map, obstacles included; that is the default
  (``denominator="all"``), and ``denominator="free"`` divides by, and counts only, the free cells.
- **Distance** (Table 4): the sum over segments of the four blocks' Euclidean displacements, in
  cells, also per block. The paper's "averaging the final values of the trajectories" of the four
  blocks is :attr:`CoverageResult.mean_block_distance` (= the eq.-2 path cost with equal weights).

The paper's own figures (Tables 4 and 5) came from a MATLAB Simulink model with its own robot
dynamics; they are a reference to compare with, not something this model reproduces exactly.

Cheng et al. 2019 (§II-C, §V) measure coverage plans of motion commands the same way:
:func:`simulate_command_coverage` drives the blocks through the commands themselves (no dwelling,
no straight-line shortcuts), and :func:`grid_activity` is its eq. 4.
"""

from __future__ import annotations

import math
import reprlib
from dataclasses import dataclass

import numpy as np

from htetro_opt._validation import check_int, check_real
from htetro_opt.errors import ConfigurationError, ParameterError
from htetro_opt.model.commands import COMMANDS, N_COMMANDS, parse_commands
from htetro_opt.model.robot import FOOTPRINTS, Pose, as_pose, shape_index
from htetro_opt.model.simulate import Simulator
from htetro_opt.model.sweeps import motion_samples
from htetro_opt.model.workspace import check_workspace

__all__ = ["CoverageResult", "simulate_coverage", "simulate_command_coverage", "grid_activity",
           "RECOVERED_DENOMINATORS", "MAX_PIXELS"]

RECOVERED_DENOMINATORS = ("all", "free")
"""What :meth:`CoverageResult.recovered` divides by: every cell of the grid (the paper) or the free cells."""

MAX_PIXELS = 1 << 24
"""Largest pixel grid :func:`simulate_coverage` builds (16.8 M pixels, 134 MB of float64)."""


@dataclass(frozen=True, eq=False)  # holds arrays: identity equality, hashable
class CoverageResult:
    """The outcome of one simulated coverage run (see the module docstring for the model).

    Attributes
    ----------
    distance : float
        Summed Euclidean displacement of the four blocks over every segment, in cells.
    block_distance : ndarray of float, shape (4,)
        The same per block a, b, c, d.
    distance_m : float or None
        ``distance`` in metres (times the cell size), None when no cell size is known.
    pixel_time : ndarray of float, shape (H·p, W·p)
        Seconds each pixel was covered by some block; row 0 is the bottom row (``[y, x]`` as the
        occupancy).
    cell_time : ndarray of float, shape (H, W)
        Mean pixel time of each cell.
    free : ndarray of bool, shape (H, W)
        The cells counted as free.
    duration : float
        Length of the run in seconds (dwelling and moving).
    pixels_per_cell : int
    cell_size : float or None
    """

    distance: float
    block_distance: np.ndarray
    distance_m: float | None
    pixel_time: np.ndarray
    cell_time: np.ndarray
    free: np.ndarray
    duration: float
    pixels_per_cell: int
    cell_size: float | None = None

    @property
    def mean_block_distance(self) -> float:
        """Distance travelled averaged over the four blocks, in cells (the paper's Table 4 measure)."""
        return self.distance / 4.0

    @property
    def average_grid_time(self) -> float:
        """Mean of :attr:`cell_time` over the free cells, in seconds (Table 4's "Avg. Grid Time")."""
        return float(self.cell_time[self.free].mean()) if self.free.any() else 0.0

    def heat_map(self, scale: float | None = None) -> np.ndarray:
        """Pixel times scaled to 0…255.

        Parameters
        ----------
        scale : float, optional
            Seconds mapped to 255 (higher times are clipped). By default the largest pixel time.

        Raises
        ------
        ParameterError
            If ``scale`` is not a positive number.
        """
        if scale is None:
            top = float(self.pixel_time.max())
        else:
            top = check_real(scale, "scale", minimum=0.0, include_minimum=False)
        if top <= 0:
            return np.zeros_like(self.pixel_time)
        return np.clip(self.pixel_time * (255.0 / top), 0.0, 255.0)

    @property
    def heat(self) -> np.ndarray:
        """The heat map normalised so that the most covered pixel is 255, shape (H·p, W·p)."""
        return self.heat_map()

    def cell_heat(self, scale: float | None = None) -> np.ndarray:
        """Mean heat of each cell's pixels, shape (H, W) (see :meth:`heat_map` for ``scale``)."""
        p = self.pixels_per_cell
        h, w = self.cell_time.shape
        return self.heat_map(scale).reshape(h, p, w, p).mean(axis=(1, 3))

    def recovered(self, threshold: float, *, denominator: str = "all", scale: float | None = None) -> float:
        """Percentage of cells whose mean heat exceeds ``threshold`` (Table 5's re-covered area).

        Parameters
        ----------
        threshold : float
            On the 0…255 scale (the paper: 150 and 100).
        denominator : {"all", "free"}, keyword-only
            ``"all"``: cells above the threshold among all H·W cells, obstacles included (the
            paper's 121 cells of the 11 × 11 map). ``"free"``: free cells above the threshold among
            the free cells.
        scale : float, optional, keyword-only
            Passed to :meth:`heat_map`.

        Returns
        -------
        float
            A percentage, 0…100.

        Raises
        ------
        ParameterError
            If ``threshold`` is not a number or ``denominator`` is unknown.

        Notes
        -----
        With the default per-run normalisation the measure is relative to the run's own most covered
        pixel: an evenly re-covered run can score higher than one that re-covers a few cells many
        times. To compare runs on absolute time, give all of them one ``scale`` (e.g. the largest
        ``pixel_time.max()`` among them).
        """
        threshold = check_real(threshold, "threshold (on the 0…255 scale)")
        if denominator not in RECOVERED_DENOMINATORS:
            raise ParameterError(f"denominator must be one of {', '.join(RECOVERED_DENOMINATORS)}, got {denominator!r}")
        above = self.cell_heat(scale) > threshold
        if denominator == "free":
            cells = int(self.free.sum())
            return 100.0 * int((above & self.free).sum()) / cells if cells else 0.0
        return 100.0 * int(above.sum()) / above.size

    def as_dict(self, thresholds=(150, 100)) -> dict:
        """JSON-ready summary: distances, average grid time, duration and re-covered percentages."""
        out = {
            "distance_cells": self.distance,
            "mean_block_distance_cells": self.mean_block_distance,
            "block_distance_cells": [float(d) for d in self.block_distance],
            "average_grid_time_s": self.average_grid_time,
            "duration_s": self.duration,
        }
        if self.distance_m is not None:
            out["distance_m"] = self.distance_m
            out["mean_block_distance_m"] = self.distance_m / 4.0
        for t in thresholds:
            out[f"recovered_{t:g}_pct"] = self.recovered(t)
        return out


def _axis_interval(offset: np.ndarray, delta: float):
    """Fractions s of a segment during which ``|offset − delta·s| < ½`` (one axis of the square)."""
    if delta == 0:
        inside = np.abs(offset) < 0.5
        return np.where(inside, -np.inf, np.inf), np.where(inside, np.inf, -np.inf)
    a, b = (offset - 0.5) / delta, (offset + 0.5) / delta
    return np.minimum(a, b), np.maximum(a, b)


def _sweep(pixel_time: np.ndarray, a: np.ndarray, b: np.ndarray, duration: float, p: int) -> None:
    """Add the time a unit square moving from centre ``a`` to ``b`` in ``duration`` s covers each pixel."""
    rows, cols = pixel_time.shape
    lo = np.minimum(a, b) - 0.5
    hi = np.maximum(a, b) + 0.5
    c0, c1 = max(0, math.floor((lo[0] + 0.5) * p)), min(cols, math.ceil((hi[0] + 0.5) * p))
    r0, r1 = max(0, math.floor((lo[1] + 0.5) * p)), min(rows, math.ceil((hi[1] + 0.5) * p))
    if c0 >= c1 or r0 >= r1:
        return
    xs = (np.arange(c0, c1) + 0.5) / p - 0.5
    ys = (np.arange(r0, r1) + 0.5) / p - 0.5
    x_lo, x_hi = _axis_interval(xs - a[0], float(b[0] - a[0]))
    y_lo, y_hi = _axis_interval(ys - a[1], float(b[1] - a[1]))
    start = np.maximum(np.maximum(y_lo[:, None], x_lo[None, :]), 0.0)
    end = np.minimum(np.minimum(y_hi[:, None], x_hi[None, :]), 1.0)
    pixel_time[r0:r1, c0:c1] += duration * np.clip(end - start, 0.0, None)


def simulate_coverage(waypoints, order, *, pixels_per_cell: int = 10, speed: float = 1.0, dwell: float = 1.0,
                      cell_size: float | None = None, occupancy=None) -> CoverageResult:
    """Drive the robot through waypoints in order and record how long every part of the grid is covered.

    Parameters
    ----------
    waypoints : Tileset, SequencingInstance or array_like of shape (n, 4, 2)
        The waypoints' block cells ``(x, y)``, as an array or as the ``blocks`` of a
        :class:`~htetro_opt.scenarios.Tileset` (which also gives the obstacles and, when
        ``cell_size`` is not given, the cell size in metres) or of a
        :class:`~htetro_opt.problems.SequencingInstance` (which gives the grid's ``shape``).
    order : sequence of int
        Waypoint indices (positions in ``instance.blocks``) in visiting order; at least one. It need
        not visit every waypoint, and may repeat one.
    pixels_per_cell : int, keyword-only
        Raster resolution p: the pixel grid is (H·p, W·p).
    speed : float, keyword-only
        Speed of the fastest block, in cells per second.
    dwell : float, keyword-only
        Seconds spent at each waypoint (the paper: at least 1 s per grid cell).
    cell_size : float, optional, keyword-only
        Cell side in metres, for :attr:`CoverageResult.distance_m`.
    occupancy : array_like of bool, shape (H, W), optional, keyword-only
        Obstacles (``occ[y, x]``), for the free cells of the averages. By default a tileset's own;
        otherwise, the cells that no waypoint's blocks cover are obstacles.

    Returns
    -------
    CoverageResult

    Raises
    ------
    ParameterError
        If an option is out of range, the order is empty or names a waypoint the instance lacks,
        ``occupancy`` does not match the grid, or the pixel grid would exceed :data:`MAX_PIXELS`.

    Notes
    -----
    Blocks move in straight lines between waypoints and ignore obstacles, as the paper's cost does.

    Examples
    --------
    >>> from htetro_opt.scenarios import parse_tileset
    >>> ts = parse_tileset("1a 1b 1c 1d\\n2a 2b 2c 2d")
    >>> result = simulate_coverage(ts, [0, 1], pixels_per_cell=4)
    >>> result.distance, result.duration, result.average_grid_time
    (4.0, 3.0, 1.5)
    """
    p = check_int(pixels_per_cell, "pixels_per_cell", minimum=1)
    speed = check_real(speed, "speed", minimum=0.0, include_minimum=False)
    dwell = check_real(dwell, "dwell", minimum=0.0)
    cell_size = check_real(cell_size, "cell_size", minimum=0.0, include_minimum=False, allow_none=True)
    # Duck-typed, so that the model need not import the scenario and problem layers above it.
    blocks = getattr(waypoints, "blocks", waypoints)
    try:
        blocks = np.asarray(blocks)
    except (TypeError, ValueError) as err:
        raise ParameterError(f"waypoints must be a tileset, an instance or an (n, 4, 2) array, got {waypoints!r}") from err
    if blocks.ndim != 3 or blocks.shape[1:] != (4, 2) or not np.issubdtype(blocks.dtype, np.integer) \
            or (blocks.size and blocks.min() < 0):
        got = (f"an array of shape {blocks.shape}" if blocks.ndim else f"{type(waypoints).__name__} "
               f"{reprlib.repr(waypoints)}")
        raise ParameterError(f"waypoints must hold (n, 4, 2) non-negative integer block cells, got {got}")
    own_map = getattr(waypoints, "occupancy", None)
    if own_map is not None:
        shape = np.shape(own_map)
        if occupancy is None:
            occupancy = own_map
        if cell_size is None and getattr(waypoints, "cell_size", None) is not None:
            cell_size = float(waypoints.cell_size)
    else:
        shape = tuple(getattr(waypoints, "shape", (0, 0)))
        if min(shape) <= 0 and len(blocks):
            shape = (int(blocks[..., 1].max()) + 1, int(blocks[..., 0].max()) + 1)
    h, w = int(shape[0]), int(shape[1])
    n = len(blocks)
    try:
        raw = np.asarray(order)
    except (TypeError, ValueError) as err:
        raise ParameterError(f"order must be a sequence of waypoint indices, got {order!r}") from err
    if raw.size and not (np.issubdtype(raw.dtype, np.integer) and raw.ndim == 1):
        raise ParameterError(f"order must be a flat sequence of integer waypoint indices, got {order!r}")
    order = raw.astype(np.int64).reshape(-1)
    if len(order) == 0:
        raise ParameterError("order must name at least one waypoint")
    if order.min() < 0 or order.max() >= n:
        raise ParameterError(f"order names waypoint {int(order.max() if order.max() >= n else order.min())}, "
                             f"outside 0…{n - 1}")
    if occupancy is None:
        covered = np.zeros((h, w), dtype=bool)
        covered[blocks[..., 1].ravel(), blocks[..., 0].ravel()] = True
        free = covered
    else:
        free = ~np.asarray(occupancy, dtype=bool)
        if free.shape != (h, w):
            raise ParameterError(f"occupancy must have the grid's shape {(h, w)}, got {free.shape}")
    if h * w * p * p > MAX_PIXELS:
        raise ParameterError(f"pixels_per_cell={p} makes a {h * p} x {w * p} pixel grid, more than {MAX_PIXELS} pixels")

    centres = blocks[order].astype(float)  # (m, 4, 2) cell centres = cell coordinates
    pixel_time = np.zeros((h * p, w * p))
    # dwelling: each block's own cell, all its pixels, ``dwell`` seconds per visit
    if dwell > 0:
        visits = np.zeros((h, w))
        np.add.at(visits, (blocks[order][..., 1].ravel(), blocks[order][..., 0].ravel()), dwell)
        pixel_time += np.kron(visits, np.ones((p, p)))
    steps = np.sqrt(((centres[1:] - centres[:-1]) ** 2).sum(-1))  # (m − 1, 4)
    durations = steps.max(axis=1) / speed if len(steps) else np.zeros(0)
    for k in range(len(steps)):
        if durations[k] <= 0:
            continue
        for block in range(4):
            _sweep(pixel_time, centres[k, block], centres[k + 1, block], float(durations[k]), p)
    block_distance = steps.sum(axis=0) if len(steps) else np.zeros(4)
    distance = float(block_distance.sum())
    cell_time = pixel_time.reshape(h, p, w, p).mean(axis=(1, 3))
    for array in (pixel_time, cell_time, free, block_distance):
        array.setflags(write=False)
    return CoverageResult(
        distance=distance,
        block_distance=block_distance,
        distance_m=None if cell_size is None else distance * cell_size,
        pixel_time=pixel_time,
        cell_time=cell_time,
        free=free,
        duration=float(durations.sum() + dwell * len(order)),
        pixels_per_cell=p,
        cell_size=cell_size,
    )


def _command_ids(commands) -> np.ndarray:
    """Global command ids of tokens (a string or a sequence) or of an integer array."""
    if isinstance(commands, np.ndarray) and commands.dtype != object and commands.ndim == 1 and \
            (commands.size == 0 or np.issubdtype(commands.dtype, np.integer)):
        ids = commands.astype(np.int64)
        if ids.size and (ids.min() < 0 or ids.max() >= N_COMMANDS):
            raise ParameterError(f"commands: id {int(ids[(ids < 0) | (ids >= N_COMMANDS)][0])} is not a command id")
        return ids
    return parse_commands(commands)


def _turn(points: np.ndarray, heading: int) -> np.ndarray:
    """Points (..., 2) turned by ``heading`` quarter turns counter-clockwise about the origin."""
    x, y = points[..., 0], points[..., 1]
    for _ in range(heading % 4):
        x, y = -y, x
    return np.stack([x, y], axis=-1)


def _stamp(pixel_time: np.ndarray, centres: np.ndarray, angles: np.ndarray, weight: float, p: int) -> None:
    """Add ``weight`` seconds to every pixel whose centre lies inside one of the turned unit squares
    ``centres (K, 2)``, ``angles (K,)`` (a pixel under two squares of one instant counts once per square)."""
    rows, cols = pixel_time.shape
    reach = 0.5 * math.sqrt(2.0)
    c0 = max(0, math.floor((centres[:, 0].min() - reach + 0.5) * p))
    c1 = min(cols, math.ceil((centres[:, 0].max() + reach + 0.5) * p))
    r0 = max(0, math.floor((centres[:, 1].min() - reach + 0.5) * p))
    r1 = min(rows, math.ceil((centres[:, 1].max() + reach + 0.5) * p))
    if c0 >= c1 or r0 >= r1:
        return
    xs = (np.arange(c0, c1) + 0.5) / p - 0.5
    ys = (np.arange(r0, r1) + 0.5) / p - 0.5
    dx = xs[None, None, :] - centres[:, 0, None, None]
    dy = ys[None, :, None] - centres[:, 1, None, None]
    cos, sin = np.cos(angles)[:, None, None], np.sin(angles)[:, None, None]
    inside = (np.abs(dx * cos + dy * sin) < 0.5) & (np.abs(-dx * sin + dy * cos) < 0.5)
    pixel_time[r0:r1, c0:c1] += weight * inside.sum(axis=0)


def simulate_command_coverage(workspace, start, commands, *, timing=None, dt: float = 0.1,
                              pixels_per_cell: int = 10) -> CoverageResult:
    """How long every part of the grid is covered while the robot executes motion commands (Cheng et
    al. 2019 §V: "decomposes a single grid into 10×10 pixels … the time step is … 0.1").

    The commands are replayed in a :class:`~htetro_opt.model.Simulator` from ``start`` (so they must be
    valid there). Each command lasts its :class:`~htetro_opt.model.Timing` duration. In a translation
    (or a diagonal, or ``stop``) every block moves in a straight line, and its pixel times are exact
    (as in :func:`simulate_coverage`). Every other command (rotations, shapeshifts, Cheng et al.
    2019's block commands) moves the blocks along the model's own motion
    (:func:`~htetro_opt.model.sweeps.motion_samples`, turned by the heading), sampled at the midpoints
    of ``dt``-long steps: at each, a pixel whose centre lies inside a block's turned square gains the
    step's duration. The robot does not dwell: the run lasts the commands' total duration.

    Parameters
    ----------
    workspace : Workspace
    start : Pose or (x, y, shape, heading)
    commands : str, sequence of str or ndarray of int
        Command tokens (``"x+, 3r"``) or global command ids.
    timing : Timing, optional, keyword-only
        Durations; one unit a command for Cheng et al. 2019's commands by default.
    dt : float, keyword-only
        Sampling step of the turning motions, in seconds (the paper's 0.1).
    pixels_per_cell : int, keyword-only
        Raster resolution p (the paper's 10).

    Returns
    -------
    CoverageResult
        ``distance`` and ``block_distance`` are the blocks' path lengths (arcs for turning blocks),
        ``duration`` the commands' total time, ``free`` the map's free cells.

    Raises
    ------
    ParameterError
        If ``dt`` or ``pixels_per_cell`` is out of range, or the pixel grid would exceed :data:`MAX_PIXELS`.
    ConfigurationError
        If the start collides or a command is invalid where it is executed.
    UnknownCommandError
        On an unknown token.

    Examples
    --------
    >>> from htetro_opt.model import Pose, Workspace
    >>> ws = Workspace(np.zeros((4, 6), dtype=bool))
    >>> result = simulate_command_coverage(ws, Pose(1, 1, "O", 0), "x+, x+", pixels_per_cell=4)
    >>> result.duration, float(result.pixel_time.sum() / 16)  # 4 blocks x 2 s
    (2.0, 8.0)
    >>> [float(t) for t in result.cell_time[1, 1:5]]  # left at once, passed over (twice), reached last
    [0.5, 1.5, 1.5, 0.5]
    """
    check_workspace(workspace)
    p = check_int(pixels_per_cell, "pixels_per_cell", minimum=1)
    dt = check_real(dt, "dt (seconds)", minimum=0.0, include_minimum=False)
    start = as_pose(start, "start")
    ids = _command_ids(commands)
    h, w = workspace.height, workspace.width
    if h * w * p * p > MAX_PIXELS:
        raise ParameterError(f"pixels_per_cell={p} makes a {h * p} x {w * p} pixel grid, more than {MAX_PIXELS} pixels")
    sim = Simulator(workspace, commands=sorted(set(ids.tolist())) or ["stop"], timing=timing)
    run = sim.run([ids], start)
    if not run.valid[0]:
        k = int(run.first_invalid[0])
        x, y, s, hd = (int(v) for v in run.poses(0)[-1])
        raise ConfigurationError(f"command {k + 1} of {len(ids)} ({COMMANDS[int(ids[k])].token}) is invalid from "
                                 f"({x}, {y}) in state {s} heading {hd}: it sweeps an obstacle or leaves the map")
    poses = run.poses(0)
    durations = sim.timing.durations()[ids]
    pixel_time = np.zeros((h * p, w * p))
    block_distance = np.zeros(4)
    for k, c in enumerate(ids.tolist()):
        x, y, s, hd = (int(v) for v in poses[k])
        command, duration = COMMANDS[c], float(durations[k])
        if command.kind in ("translation", "diagonal", "stop"):
            a = (FOOTPRINTS[s, hd] + (x, y)).astype(float)
            b = a + np.asarray(command.shift, dtype=float)
            if duration > 0:
                for block in range(4):
                    _sweep(pixel_time, a[block], b[block], duration, p)
            block_distance += math.hypot(*command.shift)
            continue
        centres, angles = motion_samples(s, command)
        centres = _turn(centres, hd) + (x, y)
        angles = angles + hd * math.pi / 2
        block_distance += np.sqrt((np.diff(centres, axis=0) ** 2).sum(-1)).sum(axis=0)
        if duration <= 0:
            continue
        n = max(1, math.ceil(duration / dt - 1e-9))
        u = (np.arange(n) + 0.5) / n * (len(centres) - 1)
        i0 = np.minimum(u.astype(int), len(centres) - 2)
        f = (u - i0)[:, None, None]
        mid = centres[i0] * (1 - f) + centres[i0 + 1] * f  # (n, 4, 2), dense samples: chords ≈ arcs
        mid_angles = angles[i0] * (1 - f[..., 0]) + angles[i0 + 1] * f[..., 0]
        _stamp(pixel_time, mid.reshape(-1, 2), mid_angles.reshape(-1), duration / n, p)
    cell_time = pixel_time.reshape(h, p, w, p).mean(axis=(1, 3))
    free = ~workspace.occupancy
    for array in (pixel_time, cell_time, block_distance):
        array.setflags(write=False)
    return CoverageResult(
        distance=float(block_distance.sum()),
        block_distance=block_distance,
        distance_m=float(block_distance.sum()) * workspace.cell_size if workspace.cell_size != 1.0 else None,
        pixel_time=pixel_time,
        cell_time=cell_time,
        free=free,
        duration=float(durations.sum()),
        pixels_per_cell=p,
        cell_size=workspace.cell_size if workspace.cell_size != 1.0 else None,
    )


def grid_activity(workspace, poses) -> np.ndarray:
    """Cheng et al. 2019's grid activity (eq. 4) after the robot has passed through ``poses``:
    −1 on an obstacle, 1 on a free cell some pose's footprint covered, 0 elsewhere.

    Parameters
    ----------
    workspace : Workspace
    poses : ndarray of int, shape (n, 4), or sequence of Pose
        (x, y, state, heading) rows (a :class:`~htetro_opt.model.SimulationResult`'s ``poses(i)``, a
        coverage plan's ``poses``) or poses; take a prefix for the activity at an earlier time.

    Returns
    -------
    ndarray of int8, shape (H, W)

    Raises
    ------
    ParameterError
        If ``poses`` is not an (n, 4) integer array or a pose lies off the map.

    Examples
    --------
    >>> from htetro_opt.model import Pose, Workspace
    >>> occ = np.zeros((3, 4), dtype=bool); occ[2, 3] = True
    >>> grid_activity(Workspace(occ), [Pose(1, 1, "O", 0)])[::-1].tolist()  # top row first
    [[0, 0, 0, -1], [0, 1, 1, 0], [0, 1, 1, 0]]
    """
    check_workspace(workspace)
    if not isinstance(poses, np.ndarray):
        try:
            poses = np.array([(q.x, q.y, shape_index(q.shape), q.heading) if isinstance(q, Pose) else tuple(q)
                              for q in poses], dtype=np.int64).reshape(-1, 4)
        except (TypeError, ValueError) as err:
            raise ParameterError(f"poses must be (x, y, state, heading) rows or Pose objects, "
                                 f"got {reprlib.repr(poses)}") from err
    if poses.ndim != 2 or poses.shape[1] != 4 or (poses.size and not np.issubdtype(poses.dtype, np.integer)):
        raise ParameterError(f"poses must be an (n, 4) integer array of (x, y, state, heading), got shape {poses.shape}")
    activity = np.where(workspace.occupancy, -1, 0).astype(np.int8)
    if len(poses):
        cells = FOOTPRINTS[poses[:, 2], poses[:, 3]] + poses[:, None, :2]
        x, y = cells[..., 0].ravel(), cells[..., 1].ravel()
        if (x < 0).any() or (x >= workspace.width).any() or (y < 0).any() or (y >= workspace.height).any():
            raise ParameterError("poses: a footprint lies off the map")
        hit = np.zeros(workspace.occupancy.shape, dtype=bool)
        hit[y, x] = True
        activity[hit & ~workspace.occupancy] = 1
    return activity
