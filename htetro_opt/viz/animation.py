"""Animated GIFs of a plan: the robot's blocks moving, turning and shapeshifting, command by command.

matplotlib (and Pillow, which comes with it) is imported only inside the functions. The plan is
replayed in the :class:`~htetro_opt.model.Simulator` (so an animation never shows a pose the model
does not reach), and the frames between two poses are the command's continuous motion as the model
samples it to find the swept cells (:func:`~htetro_opt.model.sweeps.motion_samples`): a rotation or a
shapeshift is seen turning about its hinges, not jumping.

Rendering is blitted: the map, the roadmap and the title are drawn once into a background, and each
frame restores it and draws only the robot, the moving obstacles and the status line, then maps the
pixels onto one fixed palette. A 200-command plan at 4 frames a step (801 frames) takes a few
seconds; matplotlib's ``FuncAnimation`` with ``PillowWriter`` redraws the whole figure (and its
layout) for every frame, about fifteen times as long a frame.
"""

from __future__ import annotations

import math
import reprlib
from collections.abc import Iterable
from pathlib import Path

import numpy as np

from htetro_opt._files import atomic_path, check_output_path
from htetro_opt._validation import check_int, check_real
from htetro_opt.errors import ParameterError, PlanningError
from htetro_opt.model.commands import COMMANDS, command_set, format_commands, parse_commands
from htetro_opt.model.robot import HINGE_STATES, as_pose, block_poses, rotate_cells
from htetro_opt.model.simulate import Simulator
from htetro_opt.model.sweeps import motion_samples
from htetro_opt.model.workspace import MovingObstacle, Workspace, check_workspace
from htetro_opt.viz._style import (
    _INTERMEDIATE_COLOUR,
    _MOVING_COLOUR,
    SHAPE_COLOURS,
    _cell_grid,
    _colour,
    _draw_occupancy,
    _obstacle_colour,
)
from htetro_opt.viz.plot import DENSE_CELL_PT, _cell_points, _draw_roadmap, _hidden_cells, _squares

__all__ = ["MAX_FPS", "PathAnimation", "animate_path", "save_gif"]

MAX_FPS = 50.0
"""Most frames a second a GIF may ask for: browsers show delays under 20 ms as 100 ms."""

_MAP_INCHES = 5.0  # the map's longer side on the figure
_MARGINS = {"left": 0.65, "right": 0.25, "bottom": 0.5, "status": 0.32, "title_line": 0.2, "top": 0.08}
_EDGE_COLOUR = "#222222"
_TRAIL_COLOUR = "black"  # B2's path so far (one of the palette's colours: no blend to quantise)
_UNIT_SQUARE = np.array([[-0.5, -0.5], [0.5, -0.5], [0.5, 0.5], [-0.5, 0.5]])


class PathAnimation:
    """The frames of an animated plan, drawn on one matplotlib figure (made by :func:`animate_path`).

    A frame is a moment ``(step, fraction)``: ``fraction`` of the way through command number ``step``
    (from 0), so ``(i, 0.0)`` shows pose i, the start when i = 0, and the last frame shows the final
    pose. :meth:`draw_frame` moves the artists to a frame; :meth:`render` returns its pixels; saving
    is :func:`save_gif`.

    Attributes
    ----------
    figure : matplotlib Figure
        Drawn with the Agg canvas, outside pyplot (nothing to close).
    poses : ndarray of int, shape (n + 1, 4)
        (x, y, state, heading) after each command, the start first, as the simulator replays them.
    steps : ndarray of int, shape (F,)
        The pose each frame starts from (the command being executed, or the pose shown).
    fractions : ndarray of float, shape (F,)
        How far through that command each frame is, in [0, 1).
    robot : matplotlib PolyCollection
        The four block squares B1–B4, in the state's colour.
    obstacles : matplotlib PolyCollection or None
        One square per moving-obstacle cell (None without moving obstacles).
    status : matplotlib Text
        The step counter and the time, above the map.
    trail : matplotlib Line2D
        B2's path so far: its cell at each pose up to the frame's, then where B2 is at the frame.
    """

    def __init__(self, figure, poses, steps, fractions, *, commands, times, motions, moving, artists):
        self.figure = figure
        self.poses = poses
        self.steps = steps
        self.fractions = fractions
        self._commands = commands
        self._times = times
        self._motions = motions
        self._moving = moving
        self.robot = artists["robot"]
        self.obstacles = artists.get("obstacles")
        self.status = artists["status"]
        self._labels = artists.get("labels", ())
        self._marker = artists.get("marker")
        self._hidden = artists.get("hidden")
        self.trail = artists["trail"]
        figure.canvas.draw()  # everything but the animated artists: the background of every frame
        self._background = figure.canvas.copy_from_bbox(figure.bbox)
        self._palette = _palette(np.asarray(figure.canvas.buffer_rgba())[..., :3], _dynamic_colours())

    def __len__(self) -> int:
        return len(self.steps)

    def _check_frame(self, i) -> int:
        return check_int(i, "frame", minimum=0, maximum=len(self) - 1)

    def _blocks(self, i: int) -> tuple[np.ndarray, np.ndarray, int]:
        """Block centres (4, 2) and angles (4,) in the workspace at frame i, and the state shown."""
        i = self._check_frame(i)
        step, u = int(self.steps[i]), float(self.fractions[i])
        if step == len(self._commands):  # the final pose (or the start of an empty plan)
            if step:
                return self._at(step - 1, 1.0) + (int(self.poses[step, 2]),)
            x, y, s, h = (int(v) for v in self.poses[0])
            centres, angles = block_poses(np.array(HINGE_STATES[s], dtype=float) * math.pi / 2, h * math.pi / 2)
            return centres + (x, y), angles, s
        return self._at(step, u) + (int(self.poses[step, 2]),)

    def _at(self, step: int, u: float) -> tuple[np.ndarray, np.ndarray]:
        """Blocks ``u`` of the way through command ``step``: its motion samples, interpolated."""
        centres, angles = self._motions[step]
        where = u * (len(centres) - 1)
        lo = min(int(where), len(centres) - 2)
        w = where - lo
        x, y = self.poses[step, :2]
        return (1 - w) * centres[lo] + w * centres[lo + 1] + (x, y), (1 - w) * angles[lo] + w * angles[lo + 1]

    def _obstacle_cells(self, i: int) -> np.ndarray:
        """Centres (m, 2) of the moving obstacles' cells at frame i (between cells while they move)."""
        i = self._check_frame(i)
        time = self.steps[i] + self.fractions[i]  # commands executed: the obstacles' clock
        if not self._moving:
            return np.empty((0, 2))
        return np.concatenate([_obstacle_at(obstacle, unit, time) for obstacle, unit in self._moving])

    def draw_frame(self, i: int) -> tuple:
        """Move the animated artists to frame i; the artists drawn over the background, in drawing
        order (the status line last)."""
        centres, angles, state = self._blocks(i)
        cos, sin = np.cos(angles)[:, None], np.sin(angles)[:, None]
        corners = centres[:, None, :] + np.stack(
            [cos * _UNIT_SQUARE[:, 0] - sin * _UNIT_SQUARE[:, 1], sin * _UNIT_SQUARE[:, 0] + cos * _UNIT_SQUARE[:, 1]],
            axis=-1)
        self.robot.set_verts(corners)
        self.robot.set_facecolor(_colour(state))
        done = self.poses[: int(self.steps[i]) + 1, :2].astype(float)
        track = np.vstack([done, centres[1:2]])  # B2 is block 2: where it is now, mid-command
        self.trail.set_data(track[:, 0], track[:, 1])
        for label, (x, y) in zip(self._labels, centres):
            label.set_data([x], [y])
        if self._marker is not None:
            self._marker.set_data([centres[1, 0]], [centres[1, 1]])
        if self.obstacles is not None:
            self.obstacles.set_verts(_squares(self._obstacle_cells(i)))
        self.status.set_text(self._status_text(i))
        drawn = (self.obstacles, self.trail, self.robot, *self._labels, self._marker, self._hidden, self.status)
        return tuple(a for a in drawn if a is not None)

    def _status_text(self, i: int) -> str:
        step, u, n = int(self.steps[i]), float(self.fractions[i]), len(self._commands)
        if u == 0.0:
            return f"step {step}/{n}, t = {self._times[step]:.2f} s"
        token = COMMANDS[int(self._commands[step])].token
        t = self._times[step] + u * (self._times[step + 1] - self._times[step])
        return f"step {step}/{n} \u2192 {step + 1}: {token}, t = {t:.2f} s"

    def render(self, i: int) -> np.ndarray:
        """The pixels of frame i, an (H, W, 3) uint8 array (a copy)."""
        return np.ascontiguousarray(np.asarray(self._draw(i))[..., :3])

    def _draw(self, i: int):
        """Draw frame i on the canvas; the canvas's RGBA buffer (a view, overwritten by the next frame)."""
        canvas = self.figure.canvas
        canvas.restore_region(self._background)
        for artist in self.draw_frame(i):
            self.figure.draw_artist(artist)
        return canvas.buffer_rgba()

    def frame_image(self, i: int):
        """Frame i as a Pillow image in the animation's one palette (mode ``"P"``), as a GIF holds it."""
        from PIL import Image

        buffer = self._draw(i)
        rgba = Image.frombuffer("RGBA", (buffer.shape[1], buffer.shape[0]), buffer, "raw", "RGBA", 0, 1)
        return rgba.convert("RGB").quantize(palette=self._palette, dither=Image.Dither.NONE)


def animate_path(
    workspace: Workspace,
    commands,
    start,
    *,
    roadmap=(),
    hidden=None,
    title: str = "",
    timing=None,
    frames_per_step: int = 4,
    max_frames: int = 1000,
    dpi: float = 80,
) -> PathAnimation:
    """Animate a plan: the robot executing ``commands`` from ``start``, with the moving obstacles.

    The commands are replayed in a :class:`~htetro_opt.model.Simulator` of ``workspace`` (moving
    obstacles included), so the poses drawn are the model's. Each command gets ``frames_per_step``
    frames: its start pose, then the blocks ``1/k, 2/k, …`` of the way through its continuous motion
    (the samples the swept cells come from), so a rotation, a shapeshift or a block command is seen
    turning about B2 or the hinges; the last frame shows the final pose. With ``frames_per_step=1``
    there are exactly ``len(commands) + 1`` frames, one per pose.

    Moving obstacles keep the model's clock, the number of commands executed: at pose i they cover
    ``cells_at(i)``, and during command i they slide, one unit step after another, to
    ``cells_at(i + 1)``. The status line gives the step and the time (the sum of the commands'
    durations, in seconds under the default timing).

    Long plans are capped at ``max_frames`` frames: a plan with more than ``max_frames - 1``
    commands' worth of frames first gets fewer frames a step (at least one), and one with more than
    ``max_frames - 1`` commands shows only every few poses (evenly spaced, the start and the final pose
    always), without the motion in between.

    Drawn once: the map (obstacles grey, as :func:`~htetro_opt.viz.plot_path` draws it), the moving
    obstacles' tracks (dotted), the roadmap poses' outlines (dashed: start green, intermediate blue,
    goal red) and the title. Drawn each frame: B2's path so far (a black line through its cell at
    each pose up to the frame's, then to where B2 is mid-command; a dot a pose where cells are
    large enough), the four blocks, filled in their state's colour
    (:data:`~htetro_opt.viz.SHAPE_COLOURS`, grey for an intermediate state) and numbered 1–4 where a
    cell is large enough (on a dense map a ring marks B2 instead), the moving obstacles (hatched) and
    the hidden obstacles (cross-hatched, over the robot so a path through them shows).

    Parameters
    ----------
    workspace : Workspace
        The map the plan was made for (the one the simulator checks it against).
    commands : str, sequence of str or of int
        Command tokens (``"x+,r+"`` or ``["x+", "r+"]``) or global command ids (a plan's ``commands``).
    start : Pose or (x, y, shape[, heading])
    roadmap : sequence of Pose, keyword-only
        Configurations to outline (the first is the start, the last the goal).
    hidden : ndarray, shape (m, 2), optional, keyword-only
        Obstacles unknown to the planner.
    title : str, keyword-only
        Drawn as given above the status line.
    timing : Timing, optional, keyword-only
        Durations for the time shown (the default :class:`~htetro_opt.model.Timing` otherwise).
    frames_per_step : int, keyword-only
        Frames per command, at least 1.
    max_frames : int, keyword-only
        Most frames, at least 2 (see above). The GIF encoder holds every frame until it writes the
        file, a byte a pixel (0.23 MB for a square map at the default dpi), so 1000 frames take about
        230 MB.
    dpi : float, keyword-only
        Pixels per inch; the map's longer side is 5 inches (400 pixels at the default 80).

    Returns
    -------
    PathAnimation

    Raises
    ------
    PlanningError
        If a command is invalid where it is executed (animate the executed prefix instead,
        :meth:`~htetro_opt.model.SimulationResult.prefix`).
    ConfigurationError
        If the start pose collides or lies outside the map.
    UnknownCommandError
        If a command is not a token or command id.
    ParameterError
        If an option is out of range.

    Examples
    --------
    >>> from htetro_opt.model import Pose, Workspace
    >>> anim = animate_path(Workspace(np.zeros((6, 6), dtype=bool)), "3r,3r,x+", Pose(2, 2, "I"),
    ...                     frames_per_step=2)
    >>> len(anim), anim.poses[-1].tolist()      # 3 commands x 2 frames + the final pose; (x, y, O, 0)
    (7, [3, 2, 1, 0])
    >>> anim.draw_frame(1)[-1].get_text()       # half way through the first 3r
    'step 0/3 → 1: 3r, t = 0.50 s'
    """
    check_workspace(workspace)
    ids = _command_ids(commands)
    start = as_pose(start, "start")
    frames_per_step = check_int(frames_per_step, "frames_per_step", minimum=1)
    max_frames = check_int(max_frames, "max_frames", minimum=2)
    dpi = check_real(dpi, "dpi", minimum=10.0, maximum=600.0)
    if not isinstance(title, str):
        raise ParameterError(f"title must be a string, got {type(title).__name__} {reprlib.repr(title)}")
    if isinstance(roadmap, (str, bytes)) or not isinstance(roadmap, Iterable):
        raise ParameterError(f"roadmap must be a sequence of poses, got {type(roadmap).__name__} {reprlib.repr(roadmap)}")
    roadmap = tuple(as_pose(p, f"roadmap[{i}]") for i, p in enumerate(roadmap))
    hidden = _hidden_cells(hidden)

    sim = Simulator(workspace, commands=sorted(set(command_set()) | set(ids.tolist())), timing=timing)
    result = sim.run([ids], start)
    if not result.valid[0]:
        bad = int(result.first_invalid[0])
        raise PlanningError(f"command {bad + 1} of {len(ids)} ({COMMANDS[int(ids[bad])].token!r}) is invalid where it "
                            "is executed (its swept cells leave the map or meet an obstacle): animate the executed "
                            "prefix")
    poses = result.poses(0)
    times = np.concatenate([[0.0], np.cumsum(sim.timing.durations()[ids])])
    steps, fractions = _frame_times(len(ids), frames_per_step, max_frames)
    motions = _motions(poses, ids, set(steps[steps < len(ids)].tolist()) | ({len(ids) - 1} if len(ids) else set()))
    moving = [(obstacle, MovingObstacle(obstacle.cells, obstacle.route, speed=1, mode=obstacle.mode))
              for obstacle in workspace.moving]
    figure, artists = _figure(workspace, roadmap, hidden, title, dpi)
    return PathAnimation(figure, poses, steps, fractions, commands=ids, times=times, motions=motions,
                         moving=moving, artists=artists)


def save_gif(animation: PathAnimation, path, *, fps: float = 20.0) -> Path:
    """Write an animation as a looping GIF, atomically (a temporary file renamed into place).

    Frames are rendered one at a time as the encoder asks for them. The encoder merges consecutive
    frames that are identical into one longer frame (a command of zero duration with nothing else
    moving); otherwise the GIF has one frame per frame of the animation.

    Parameters
    ----------
    animation : PathAnimation
    path : str or Path
        The GIF to write; a name with another extension than ``.gif`` is refused.
    fps : float, keyword-only
        Frames a second, in (0, :data:`MAX_FPS`]; GIF delays are whole hundredths of a second, so
        the delay is rounded to one.

    Returns
    -------
    Path

    Raises
    ------
    OutputError
        If the folder does not exist or the file cannot be written (nothing is left behind).
    ParameterError
        If ``fps`` is out of range or the extension is not ``.gif``.

    Examples
    --------
    >>> import tempfile
    >>> from htetro_opt.model import Pose, Workspace
    >>> anim = animate_path(Workspace(np.zeros((5, 5), dtype=bool)), "x+,y+", Pose(1, 1, "O"))
    >>> path = save_gif(anim, Path(tempfile.mkdtemp()) / "plan.gif")
    >>> path.read_bytes()[:6]
    b'GIF89a'
    """
    if not isinstance(animation, PathAnimation):
        raise ParameterError(f"animation must be a PathAnimation (from animate_path), got "
                             f"{type(animation).__name__} {reprlib.repr(animation)}")
    fps = check_real(fps, "fps", minimum=0.0, maximum=MAX_FPS, include_minimum=False)
    path = Path(path)
    if path.suffix.lower() not in ("", ".gif"):
        raise ParameterError(f"cannot write animation {str(path)!r}: it is written as a GIF, so its name must end "
                             f"in .gif, not {path.suffix!r}")
    check_output_path(path, what="animation")
    delay = 10 * round(100.0 / fps)  # ms, whole hundredths of a second
    with atomic_path(path, what="animation") as tmp:
        rest = (animation.frame_image(i) for i in range(1, len(animation)))
        animation.frame_image(0).save(tmp, format="GIF", save_all=True, append_images=rest, duration=delay, loop=0)
    return path


def _command_ids(commands) -> np.ndarray:
    """A plan's commands as global ids: tokens are parsed, ids checked (naming the first bad one)."""
    if isinstance(commands, str):
        return parse_commands(commands)
    if isinstance(commands, bytes) or not isinstance(commands, Iterable):
        raise ParameterError(f"commands must be command tokens or ids, got {type(commands).__name__} "
                             f"{reprlib.repr(commands)}")
    listed = np.asarray(commands).reshape(-1).tolist() if isinstance(commands, np.ndarray) else list(commands)
    if all(isinstance(c, str) for c in listed):
        return parse_commands(listed)
    return parse_commands(format_commands(listed))


def _frame_times(n: int, per_step: int, max_frames: int) -> tuple[np.ndarray, np.ndarray]:
    """(step, fraction) of every frame, at most ``max_frames`` of them (see :func:`animate_path`)."""
    per_step = min(per_step, (max_frames - 1) // n) if n else 1
    if per_step >= 1:
        steps = np.append(np.repeat(np.arange(n), per_step), n)
        fractions = np.append(np.tile(np.arange(per_step) / per_step, n), 0.0)
        return steps, fractions
    steps = np.unique(np.rint(np.linspace(0, n, max_frames)).astype(np.int64))
    return steps, np.zeros(len(steps))


def _motions(poses: np.ndarray, ids: np.ndarray, needed) -> dict[int, tuple[np.ndarray, np.ndarray]]:
    """Per command needed, its sampled block motion relative to B2's start cell, in the workspace frame.

    The model samples a motion at heading 0 (:func:`motion_samples`); at heading h it is that motion
    turned by h quarter turns, a translation's shift counter-turned first (as the sweep tables do).
    """
    cache: dict[tuple[int, int, int], tuple[np.ndarray, np.ndarray]] = {}
    motions = {}
    for step in needed:
        state, heading, command = int(poses[step, 2]), int(poses[step, 3]), int(ids[step])
        key = (state, heading, command)
        if key not in cache:
            shift = tuple(rotate_cells(np.array(COMMANDS[command].shift), -heading).tolist())
            centres, angles = motion_samples(state, COMMANDS[command], shift=shift)
            cache[key] = rotate_cells(centres, heading), angles + heading * math.pi / 2
        motions[int(step)] = cache[key]
    return motions


def _obstacle_at(obstacle: MovingObstacle, unit: MovingObstacle, time: float) -> np.ndarray:
    """Cells of ``obstacle`` at a fractional time: between two unit steps it slides in a straight line.

    ``unit`` is the obstacle at speed 1, whose displacement at time k is the obstacle's k-th unit step.
    """
    where = time * obstacle.speed
    k = math.floor(where)
    w = where - k
    shift = unit.displacement(k) if w == 0 else (1 - w) * unit.displacement(k) + w * unit.displacement(k + 1)
    return obstacle.cells + shift


def _figure(workspace: Workspace, roadmap, hidden: np.ndarray, title: str, dpi: float):
    """The figure with its static content drawn, and the animated artists (unset until a frame)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.collections import PolyCollection
    from matplotlib.figure import Figure

    w, h = workspace.width, workspace.height
    scale = _MAP_INCHES / max(w, h)
    map_w, map_h = w * scale, h * scale
    m = _MARGINS
    top = m["top"] + m["status"] + m["title_line"] * (len(title.splitlines()) if title else 0)
    fig_w, fig_h = m["left"] + map_w + m["right"], m["bottom"] + map_h + top
    fig = Figure(figsize=(fig_w, fig_h), dpi=dpi)
    FigureCanvasAgg(fig)
    ax = fig.add_axes((m["left"] / fig_w, m["bottom"] / fig_h, map_w / fig_w, map_h / fig_h))
    _draw_occupancy(ax, workspace.occupancy)
    ax.set_xlim(-0.5, w - 0.5)
    ax.set_ylim(-0.5, h - 0.5)
    ax.set_xlabel("x (cells)", fontsize=8)
    ax.set_ylabel("y (cells)", fontsize=8)
    ax.tick_params(labelsize=7)
    cell_pt = _cell_points(ax, w, h)
    dense = cell_pt < DENSE_CELL_PT
    if not dense:
        _cell_grid(ax, w, h, colour="#dddddd", linewidth=0.4)
    if title:
        fig.text(0.5, 1 - m["top"] / fig_h, title, ha="center", va="top", fontsize=9)
    artists = {}
    if workspace.moving:
        tracks = np.unique(np.concatenate([o.cells_at(t) for o in workspace.moving for t in range(o.period)]), axis=0)
        ax.add_collection(PolyCollection(_squares(tracks), facecolors="none", edgecolors=_MOVING_COLOUR, hatch="..",
                                         linewidths=0, zorder=2))
        artists["obstacles"] = ax.add_collection(PolyCollection(
            [], facecolors=_MOVING_COLOUR, edgecolors="white", hatch="//", linewidths=0, zorder=3, animated=True))
    _draw_roadmap(ax, roadmap, dense=dense)
    artists["trail"], = ax.plot([], [], color=_TRAIL_COLOUR, linewidth=1.3 if dense else 1.6, marker=None if dense
                                else ".", markersize=4, zorder=4.5, animated=True)
    if map_w >= 4.0:  # room beside the status line for a key
        fig.text(1 - m["right"] / fig_w, (m["bottom"] + map_h + 0.08) / fig_h,
                 f"{_TRAIL_COLOUR} line: B2's path so far", ha="right", va="bottom", fontsize=7, color="#444444")
    artists["robot"] = ax.add_collection(PolyCollection(
        [], edgecolors=_EDGE_COLOUR, linewidths=0 if dense else 1.0, zorder=5, animated=True))
    if dense:  # a block is a few pixels: a ring marks where B2 is
        artists["marker"], = ax.plot([], [], marker="o", markersize=14, markerfacecolor="none", markeredgecolor="black",
                                     markeredgewidth=1.2, linestyle="none", zorder=6, animated=True)
    elif cell_pt >= 12.0:
        # Mathtext markers: the digits' outlines are made once, so a frame draws paths, not text.
        artists["labels"] = tuple(ax.plot([], [], marker=f"$\\mathbf{{{b}}}$", markersize=min(9.0, 0.45 * cell_pt),
                                          color="white", linestyle="none", zorder=6, animated=True)[0]
                                  for b in range(1, 5))
    if len(hidden):
        artists["hidden"] = ax.add_collection(PolyCollection(
            _squares(hidden), facecolors="none", edgecolors="black", hatch="xx", linewidths=0.8, zorder=7,
            animated=True))
    artists["status"] = fig.text(m["left"] / fig_w, (m["bottom"] + map_h + 0.08) / fig_h, "", ha="left",
                                 va="bottom", fontsize=9, family="monospace", animated=True)
    return fig, artists


def _dynamic_colours() -> tuple[list[str], list[str]]:
    """The colours the animated artists fill with, and those around them (edges, text, the map)."""
    from matplotlib.colors import to_hex

    fills = [*SHAPE_COLOURS.values(), _INTERMEDIATE_COLOUR, _MOVING_COLOUR]
    return fills, ["white", "black", _EDGE_COLOUR, "#dddddd", to_hex(_obstacle_colour())]


def _palette(background: np.ndarray, colours: tuple[list[str], list[str]]):
    """One 256-colour palette for every frame: the animated fills, their blends with what surrounds
    them (their anti-aliased edges), and the rest from the background's own colours.

    One palette keeps colours from flickering between frames; mapping onto it is a lookup per pixel.
    """
    from matplotlib.colors import to_rgb
    from PIL import Image

    fills, around = (np.array([to_rgb(c) for c in group]) for group in colours)
    blends = [fills, around]
    for other in around:
        for t in (0.25, 0.5, 0.75):
            blends.append((1 - t) * fills + t * other)
    swatch = np.unique(np.rint(np.concatenate(blends) * 255).astype(np.uint8), axis=0)
    rest = 256 - len(swatch)
    quantized = Image.fromarray(np.ascontiguousarray(background)).quantize(rest, method=Image.Quantize.MEDIANCUT)
    colours_of_background = np.array(quantized.getpalette()[: 3 * rest], dtype=np.uint8).reshape(-1, 3)
    table = np.concatenate([swatch, colours_of_background])
    holder = Image.new("P", (1, 1))
    holder.putpalette(table.ravel().tolist() + [0] * (768 - table.size))
    return holder
