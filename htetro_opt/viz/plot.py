"""Plots of maps and plans (matplotlib is imported lazily; nothing here computes a plan).

Everything that grows with the path or the map is drawn as a fixed number of artists: the cells
the robot occupies are one RGBA image (a per-cell count of footprints, coloured by shape), outlines
are one :class:`~matplotlib.collections.LineCollection` per kind, obstacle cells one
:class:`~matplotlib.collections.PolyCollection` per kind and the path one line. A 10,000-command
plan draws and saves in about a second.

Detail follows the size of a cell on the figure: below :data:`DENSE_CELL_PT` points (12 pixels at
100 dpi), a footprint is a few pixels, so outlines would be noise; the plot then marks poses
(B2, shape changes, roadmap poses) with markers instead, and drops the per-pose dots of the path.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from htetro_opt._files import atomic_path, check_output_path
from htetro_opt.errors import ParameterError
from htetro_opt.model.robot import FOOTPRINTS, N_NAMED, SHAPES, Pose
from htetro_opt.model.workspace import Workspace
from htetro_opt.viz._style import (
    _INTERMEDIATE_COLOUR,
    _MOVING_COLOUR,
    _ROADMAP_COLOURS,
    SHAPE_COLOURS,
    _cell_grid,
    _colour,
    _draw_occupancy,
    _legend,
    _marker_handle,
    _obstacle_colour,
    _pyplot,
)
from htetro_opt.viz.fronts import _draw_convergence

__all__ = ["SHAPE_COLOURS", "SELECTION_STYLES", "DENSE_CELL_PT", "plot_path", "plot_ga_plan", "save_figure",
           "figure_format"]

_HIDDEN_HIT_COLOUR = "#d00000"

DENSE_CELL_PT = 9.0
"""Side of a cell on the figure, in points (1/72 in), below which plots switch from outlines and
labels to markers (9 pt is 12.5 pixels at 100 dpi)."""


def _footprint_cells(poses) -> np.ndarray:
    """The cells of B1–B4 at each (x, y, state, heading) pose, shape (n, 4, 2)."""
    poses = np.asarray(poses, dtype=np.int64).reshape(-1, 4)
    return FOOTPRINTS[poses[:, 2], poses[:, 3]] + poses[:, None, :2]


def _cell_points(ax, width: int, height: int) -> float:
    """Side of one cell on the figure in points, from the axes' current box (before layout, so a
    little generous when a legend later takes room)."""
    box = ax.get_position()
    w_in, h_in = ax.figure.get_size_inches()
    return 72.0 * min(box.width * w_in / width, box.height * h_in / height)


def _squares(cells, inset: float = 0.0) -> np.ndarray:
    """Corners of the unit squares of some (x, y) cells, shape (n, 4, 2), for a PolyCollection."""
    cells = np.asarray(cells, dtype=float).reshape(-1, 1, 2)
    half = 0.5 - inset
    return cells + np.array([[-half, -half], [half, -half], [half, half], [-half, half]])


def _outline_segments(groups: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The boundary of each group of four cells: unit edges between a group's cell and a cell outside it.

    Parameters
    ----------
    groups : ndarray of int, shape (n, 4, 2)

    Returns
    -------
    segments : ndarray, shape (m, 2, 2)
    owner : ndarray of int, shape (m,)
        The group each segment outlines.
    """
    groups = np.asarray(groups, dtype=np.int64).reshape(-1, 4, 2)
    steps = np.array([[1, 0], [-1, 0], [0, 1], [0, -1]])
    neighbours = groups[:, :, None, :] + steps[None, None, :, :]  # (n, 4 cells, 4 steps, 2)
    inside = (neighbours[:, :, :, None, :] == groups[:, None, None, :, :]).all(-1).any(-1)
    g, c, s = np.nonzero(~inside)
    mid = groups[g, c] + steps[s] / 2.0  # centre of the shared edge
    along = np.abs(steps[s][:, ::-1]) / 2.0  # half an edge, perpendicular to the step
    return np.stack([mid - along, mid + along], axis=1), g


def _shape_counts(cells: np.ndarray, colour_index: np.ndarray, n_colours: int, height: int, width: int):
    """How many of the groups of cells of each colour cover each cell, ``counts[k, y, x]``; cells
    outside the grid are left out."""
    x, y = cells[..., 0].ravel(), cells[..., 1].ravel()
    k = np.repeat(colour_index, cells.shape[1])
    keep = (x >= 0) & (x < width) & (y >= 0) & (y < height)
    flat = (k[keep] * height + y[keep]) * width + x[keep]
    return np.bincount(flat, minlength=n_colours * height * width).reshape(n_colours, height, width)


def _mixed_image(counts: np.ndarray, colours, alpha: float, *, cap: float = 0.9) -> np.ndarray:
    """An RGBA image of stacked translucent layers: per cell the colours mixed by their counts, and the
    opacity of ``count`` layers of opacity ``alpha`` (at most ``cap``)."""
    from matplotlib.colors import to_rgb

    rgb = np.array([to_rgb(c) for c in colours])
    total = counts.sum(axis=0)
    image = np.zeros(total.shape + (4,))
    covered = total > 0
    image[..., :3] = np.tensordot(counts, rgb, axes=(0, 0)) / np.maximum(total, 1)[..., None]
    image[..., 3] = np.where(covered, np.minimum(cap, 1.0 - (1.0 - alpha) ** total), 0.0)
    return image


def _draw_map(ax, workspace: Workspace, hidden, *, dense: bool) -> list:
    """Static obstacles, moving obstacles and their tracks, hidden obstacles; their legend handles."""
    from matplotlib.collections import PolyCollection
    from matplotlib.patches import Patch

    w, h = workspace.width, workspace.height
    _draw_occupancy(ax, workspace.occupancy)
    handles = []
    if workspace.occupancy.any():
        handles.append(Patch(facecolor=_obstacle_colour(), label="obstacle"))
    if not dense:
        _cell_grid(ax, w, h, colour="#dddddd", linewidth=0.4)
    if workspace.moving:
        tracks = np.unique(np.concatenate([m.cells_at(t) for m in workspace.moving for t in range(m.period)]), axis=0)
        starts = np.concatenate([m.cells_at(0) for m in workspace.moving])
        ax.add_collection(PolyCollection(_squares(tracks), facecolors="none", edgecolors=_MOVING_COLOUR, hatch="..",
                                         linewidths=0, zorder=2))
        ax.add_collection(PolyCollection(_squares(starts), facecolors=_MOVING_COLOUR, edgecolors="white", hatch="//",
                                         linewidths=0, alpha=0.85, zorder=2))
        handles.append(Patch(facecolor=_MOVING_COLOUR, edgecolor="white", hatch="//", linewidth=0, alpha=0.85,
                             label="moving obstacle at t = 0"))
        handles.append(Patch(facecolor="none", edgecolor=_MOVING_COLOUR, hatch="..", linewidth=0,
                             label="moving obstacle's track"))
    hidden = _hidden_cells(hidden)
    if len(hidden):
        ax.add_collection(PolyCollection(_squares(hidden), facecolors="none", edgecolors="black", hatch="xx",
                                         linewidths=0.8, zorder=2))
        handles.append(Patch(facecolor="none", edgecolor="black", hatch="xx", label="hidden obstacle (unknown to planner)"))
    return handles


def _hidden_cells(hidden) -> np.ndarray:
    return np.empty((0, 2), dtype=np.int64) if hidden is None else np.asarray(hidden, dtype=np.int64).reshape(-1, 2)


def _draw_footprints(ax, workspace: Workspace, poses: np.ndarray, *, dense: bool) -> list:
    """The cells the robot occupies along the path (one image), and where its shape or heading changes."""
    from matplotlib.collections import LineCollection
    from matplotlib.patches import Patch

    if not len(poses):
        return []
    w, h = workspace.width, workspace.height
    cells = _footprint_cells(poses)
    colour_index = np.minimum(poses[:, 2], N_NAMED)  # every intermediate state shares one grey
    colours = [SHAPE_COLOURS[s] for s in SHAPES] + [_INTERMEDIATE_COLOUR]
    counts = _shape_counts(cells, colour_index, len(colours), h, w)
    ax.imshow(_mixed_image(counts, colours, 0.4 if dense else 0.15), origin="lower", interpolation="nearest",
              extent=(-0.5, w - 0.5, -0.5, h - 0.5), zorder=1, gid="footprints")
    handles = [Patch(facecolor="#888888", alpha=0.45, label="robot's cells (darker: more poses):")]
    for k in np.unique(colour_index).tolist():
        name = f"{SHAPES[k]}-shape" if k < N_NAMED else "intermediate states"
        handles.append(Patch(facecolor=colours[k], alpha=0.6, label=f"    {name}"))

    change = np.zeros(len(poses), dtype=bool)
    change[1:] = (poses[1:, 2] != poses[:-1, 2]) | (poses[1:, 3] != poses[:-1, 3])
    edge = np.array([_colour(s) for s in range(int(poses[:, 2].max()) + 1)])
    if dense:
        if change.any():
            ax.scatter(poses[change, 0], poses[change, 1], c=edge[poses[change, 2]], marker="D", s=14,
                       edgecolors="black", linewidths=0.4, zorder=3.5, gid="shape changes")
            handles.append(_marker_handle("shape/heading change (at B2, new shape's colour)", marker="D",
                                          markerfacecolor="white", markeredgecolor="black", markersize=5))
    else:
        change[0] = change[-1] = True
        segments, owner = _outline_segments(cells[change])
        ax.add_collection(LineCollection(segments, colors=edge[poses[change, 2]][owner], linewidths=1.3, zorder=2.5))
        handles.append(_marker_handle("footprint at start, end, shape/heading change",
                                      linestyle="-", color="#555555", linewidth=1.3))
    return handles


def _draw_roadmap(ax, roadmap, *, dense: bool) -> list:
    """Roadmap poses: footprints outlined dashed (start green, intermediate blue, goal red)."""
    from matplotlib.collections import LineCollection

    handles = []
    kinds = ["intermediate roadmap pose"] * len(roadmap)
    if roadmap:
        kinds[0] = "start"
    if len(roadmap) > 1:
        kinds[-1] = "goal"
    markers = {"start": "o", "intermediate roadmap pose": "s", "goal": "*"}
    for kind, colour in _ROADMAP_COLOURS.items():
        chosen = [pose for pose, k in zip(roadmap, kinds) if k == kind]
        if not chosen:
            continue
        segments, _ = _outline_segments(np.array([pose.cells() for pose in chosen]))
        ax.add_collection(LineCollection(segments, colors=colour, linewidths=2.2, linestyles="--", zorder=4))
        style = {"linestyle": "--", "color": colour, "linewidth": 2.0}
        if dense:  # a dashed outline of a few pixels is lost: mark B2 as well
            ax.scatter([p.x for p in chosen], [p.y for p in chosen], marker=markers[kind], s=60,
                       facecolors="none", edgecolors=colour, linewidths=1.5, zorder=4)
            style.update(marker=markers[kind], markerfacecolor="none", markeredgecolor=colour)
        count = f" ({len(chosen)})" if kind == "intermediate roadmap pose" and len(chosen) > 1 else ""
        handles.append(_marker_handle(f"{kind}{count}", **style))
    return handles


def _draw_hidden_hits(ax, poses: np.ndarray, hidden) -> list:
    """Mark the hidden-obstacle cells the path's footprints cover, with a note under the map."""
    from matplotlib.collections import PolyCollection

    hidden = _hidden_cells(hidden)
    if not len(hidden) or not len(poses):
        return []
    cells = _footprint_cells(poses)
    on_hidden = np.isin(_cell_keys(cells), _cell_keys(hidden))  # (poses, blocks)
    if not on_hidden.any():
        return []
    hit_cells = np.unique(cells[on_hidden], axis=0)
    first = int(np.flatnonzero(on_hidden.any(axis=1))[0])
    ax.add_collection(PolyCollection(_squares(hit_cells), facecolors=_HIDDEN_HIT_COLOUR, alpha=0.35,
                                     edgecolors=_HIDDEN_HIT_COLOUR, linewidths=2.0, zorder=5))
    ax.scatter(hit_cells[:, 0], hit_cells[:, 1], marker="x", s=40, color=_HIDDEN_HIT_COLOUR, linewidths=2, zorder=5)
    where = "at the start" if first == 0 else f"first after command {first}"
    shown = ", ".join(f"({x}, {y})" for x, y in hit_cells[:6].tolist()) + (", …" if len(hit_cells) > 6 else "")
    ax.annotate(f"Warning: the path drives through {len(hit_cells)} hidden obstacle cell"
                f"{'s' if len(hit_cells) > 1 else ''}\n{shown}, {where}",
                xy=(0.0, 0.0), xycoords="axes fraction", xytext=(0, -38), textcoords="offset points",
                ha="left", va="top", fontsize=8.5, color=_HIDDEN_HIT_COLOUR, fontweight="bold",
                annotation_clip=False, gid="hidden-obstacle warning")
    return [_marker_handle("path on a hidden obstacle", marker="x", color=_HIDDEN_HIT_COLOUR,
                           markersize=7, markeredgewidth=2)]


def _cell_keys(cells: np.ndarray) -> np.ndarray:
    """One integer per (x, y) cell (|x|, |y| < 2**20), to compare sets of cells with ``np.isin``."""
    cells = np.asarray(cells, dtype=np.int64)
    return (cells[..., 0] + 2**20) * 2**21 + (cells[..., 1] + 2**20)


def _frame(ax, workspace: Workspace, title: str) -> None:
    ax.set_xlim(-0.5, workspace.width - 0.5)
    ax.set_ylim(-0.5, workspace.height - 0.5)
    ax.set_aspect("equal")
    ax.set_xlabel("x (cells)")
    ax.set_ylabel("y (cells)")
    if title:
        ax.set_title(title, fontsize=10)


def _map_figure(workspace: Workspace, ax):
    if ax is not None:
        return ax.figure, ax
    side = 6.0
    aspect = workspace.height / workspace.width
    return _pyplot().subplots(figsize=(side + 3.3, max(2.5, side * aspect) + 1.0), layout="compressed")


def _draw_plan(ax, workspace: Workspace, poses: np.ndarray, roadmap, hidden, *, path_line: bool) -> list:
    """Everything :func:`plot_path` draws but the legend; returns the legend handles."""
    dense = _cell_points(ax, workspace.width, workspace.height) < DENSE_CELL_PT
    handles = _draw_map(ax, workspace, hidden, dense=dense)
    handles += _draw_footprints(ax, workspace, poses, dense=dense)
    if path_line and len(poses):
        style = {"linewidth": 0.8} if dense else {"linewidth": 1.2, "marker": ".", "markersize": 3}
        ax.plot(poses[:, 0], poses[:, 1], color="black", zorder=3, **style)
        label = "path of block B2" + ("" if dense else " (dot: each pose)")
        handles.append(_marker_handle(label, linestyle="-", color="black", **style))
    handles += _draw_roadmap(ax, roadmap, dense=dense)
    return handles + _draw_hidden_hits(ax, poses, hidden)


def plot_path(
    workspace: Workspace,
    poses: np.ndarray,
    *,
    roadmap: tuple[Pose, ...] = (),
    hidden: np.ndarray | None = None,
    title: str = "",
    ax=None,
):
    """Draw a map and the robot's footprints along a path.

    Drawn, each with a legend entry: obstacles; moving obstacles at t = 0 and the cells their tracks
    pass (dotted); hidden obstacles (cross-hatched); the cells the robot's footprints cover, coloured
    by shape and darker where more poses cover them; the path of block B2; the roadmap poses'
    footprints (dashed: start green, intermediate blue, goal red). Where a cell is at least
    :data:`DENSE_CELL_PT` points wide, the footprint at the start, the end and each change of shape or
    heading is outlined in its shape's colour and the path has a dot per pose; on denser maps (the
    128 × 128 indoor room) a diamond at B2 marks each change of shape or heading and a marker each
    roadmap pose's B2, without per-pose dots. If a footprint covers a hidden obstacle, those cells are
    marked with a red cross and a warning is written under the map. The cost does not grow with the
    number of artists: a 10,000-pose path is one image, one line and one marker set.

    Parameters
    ----------
    workspace : Workspace
    poses : ndarray of int, shape (n, 4)
        (x, y, state, heading) of the poses visited, in order.
    roadmap : tuple of Pose, keyword-only
        Configurations to outline.
    hidden : ndarray, shape (m, 2), optional, keyword-only
        Obstacles unknown to the planner.
    title : str, keyword-only
        Drawn as given (viz adds nothing to it).
    ax : matplotlib Axes, optional, keyword-only

    Returns
    -------
    matplotlib Figure

    Examples
    --------
    >>> from htetro_opt.model import Workspace
    >>> fig = plot_path(Workspace(np.zeros((6, 6), dtype=bool)), [[2, 2, 1, 0], [3, 2, 1, 0]],
    ...                 roadmap=(Pose(2, 2, "O", 0), Pose(3, 2, "O", 0)), hidden=[[4, 1]])
    >>> [t.get_text()[:41] for t in fig.axes[0].texts]  # the O-shape's second pose covers (4, 1)
    ['Warning: the path drives through 1 hidden']
    >>> import matplotlib.pyplot as plt; plt.close(fig)
    """
    poses = np.asarray(poses, dtype=np.int64).reshape(-1, 4)
    fig, ax = _map_figure(workspace, ax)
    handles = _draw_plan(ax, workspace, poses, roadmap, hidden, path_line=True)
    _legend(ax, handles)
    _frame(ax, workspace, title)
    return fig


SELECTION_STYLES = {
    "multi_objective": ("black", "multi-objective (max Σ f)"),
    "time": ("#1f77b4", "best f_t"),
    "smoothness": ("#2ca02c", "best f_sm"),
    "safety": ("#9467bd", "best f_sf"),
}
"""Colour and legend label of each of the paper's four output solutions (Cheng et al. 2020, Fig. 9)."""


def _selection_track(plan, name: str, offset: float):
    """B2's track of one selection over every leg (NaN between legs), its total time and whether it
    reaches every leg's goal, or None."""
    pieces, total, reached = [], 0.0, True
    for leg in plan.legs:
        member = leg.selected.get(name)
        if member is None or not len(member.poses):
            return None
        pieces.append(np.asarray(member.poses, dtype=float)[:, :2] + offset)
        pieces.append(np.full((1, 2), np.nan))
        total += float(member.time)
        reached = reached and bool(getattr(member, "reached", True))
    return (np.concatenate(pieces), total, reached) if pieces else None


def plot_ga_plan(workspace: Workspace, plan, *, roadmap: tuple[Pose, ...] = (), hidden=None, title: str = ""):
    """A GA plan: the four selected solutions' paths, and the convergence of the chosen one.

    These are the paper's (Cheng et al. 2020) Figs. 9 and 10.

    Parameters
    ----------
    workspace : Workspace
    plan : Plan
        From :func:`~htetro_opt.solvers.grid_paths.plan_path` with a GA method: the chained
        multi-objective solution's ``poses`` and, per leg, ``selected`` members (with ``poses``
        and ``time``) and ``history``.
    roadmap, hidden, title : keyword-only
        As for :func:`plot_path`.

    Returns
    -------
    matplotlib Figure
        Left: the map as :func:`plot_path` draws it, for the multi-objective path, with the B2 tracks
        of the four selections (offset slightly so overlapping tracks stay visible; the legend gives
        each one's total time in s, and says "goal not reached" of a selection short of a leg's goal,
        the GA's best try rather than a part of the plan). Right: the multi-objective solution's four fitnesses per
        generation, legs one after another.
    """
    plt = _pyplot()
    poses = np.asarray(plan.poses, dtype=np.int64).reshape(-1, 4)
    aspect = workspace.height / workspace.width
    fig, (ax_map, ax_fit) = plt.subplots(
        1, 2, figsize=(14.5, max(3.5, 6.0 * aspect) + 1.0), layout="compressed",
        gridspec_kw={"width_ratios": [1.45, 1.0]},
    )
    handles = _draw_plan(ax_map, workspace, poses, roadmap, hidden, path_line=False)
    for k, (name, (colour, label)) in enumerate(SELECTION_STYLES.items()):
        track = _selection_track(plan, name, (k - 1.5) * 0.08)
        if track is None:
            continue
        xy, total, reached = track
        width = 2.2 if name == "multi_objective" else 1.3
        ax_map.plot(xy[:, 0], xy[:, 1], color=colour, linewidth=width, zorder=4 if name == "multi_objective" else 3)
        # a selection short of a goal is the GA's best try, not part of the plan (whose time the title may give)
        shown = f"{label}, {total:g} s" + ("" if reached else ", goal not reached")
        handles.append(_marker_handle(shown, linestyle="-", color=colour, linewidth=width))
    _legend(ax_map, handles)
    _frame(ax_map, workspace, title)

    if plan.legs:
        _draw_convergence(ax_fit, [(np.asarray(leg.history, dtype=float).reshape(-1, 4), leg.reach_generation)
                                   for leg in plan.legs])
    ax_fit.set_title("convergence of the multi-objective solution's fitnesses", fontsize=10)
    return fig


def save_figure(fig, path: str | Path, *, dpi: int = 120) -> Path:
    """Save a figure atomically (a temporary file renamed into place), then close it.

    The format follows the file's extension when matplotlib writes it (``.png``, ``.pdf``,
    ``.svg``, …); a name without an extension gets PNG. The page is trimmed to what is drawn
    (``bbox_inches="tight"``), so a legend or note outside the axes is never cut off.

    Raises
    ------
    OutputError
        If the folder does not exist or the file cannot be written.
    ParameterError
        If the extension names a format matplotlib cannot write.
    """
    plt = _pyplot()
    path = Path(path)
    try:
        fmt = figure_format(path)
        check_output_path(path, what="plot")
        with atomic_path(path, what="plot") as tmp:
            fig.savefig(tmp, dpi=dpi, format=fmt, bbox_inches="tight")  # nothing drawn is cut off
    finally:
        plt.close(fig)
    return path


def figure_format(path: str | Path) -> str:
    """The matplotlib format for a plot file's extension (PNG when it has none).

    Raises
    ------
    ParameterError
        If matplotlib cannot write that format.
    """
    suffix = Path(path).suffix.lower().lstrip(".")
    if not suffix:
        return "png"
    from matplotlib.backend_bases import FigureCanvasBase

    formats = FigureCanvasBase.get_supported_filetypes()
    if suffix not in formats:
        raise ParameterError(f"cannot write plot {str(path)!r}: matplotlib writes {', '.join(sorted(formats))}, "
                             f"not {suffix!r}")
    return suffix
