"""Plots of the heat planner's temperature field (Do et al. 2021, panels (b) of Figs. 7–12): the
temperature as an image, its gradient as arrows, the path of B2 on top.

matplotlib is imported lazily, as in :mod:`htetro_opt.viz.plot`, whose map drawing (obstacles in its
grey, y up, cell grid on small maps) this module reuses; nothing here computes a field or a plan.
The number of artists does not grow with the map: one image, one quiver (at most ``arrows`` arrows a
side), one line and a few marker sets.
"""

from __future__ import annotations

import math
import reprlib
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from htetro_opt._files import check_output_path
from htetro_opt._validation import check_bool, check_int
from htetro_opt.errors import HtetroError, ParameterError
from htetro_opt.model.robot import STATE_NAMES, Pose, as_pose
from htetro_opt.model.workspace import Workspace, check_workspace
from htetro_opt.viz._style import _ROADMAP_COLOURS, _colour_bar, _legend, _marker_handle, _obstacle_colour, _pyplot
from htetro_opt.viz.plot import (
    DENSE_CELL_PT,
    _cell_keys,
    _cell_points,
    _draw_map,
    _frame,
    _hidden_cells,
    _squares,
    _map_figure,
    figure_format,
    plot_path,
    save_figure,
)

__all__ = ["HEAT_COLORMAP", "plot_heat_field", "plot_heat_plan"]

HEAT_COLORMAP = "viridis"
"""The temperature's colormap: perceptually uniform, and free of the obstacles' grey and of the
path's and markers' colours."""

_REPLAN_COLOUR = "#ff00ff"
_NO_FIELD_TEXT = "start and goal are not connected: no temperature field"


def _heat_field_type():
    # Imported when a plot is drawn: importing htetro_opt.viz must not import the solvers.
    from htetro_opt.solvers.grid_paths import HeatField

    return HeatField


def _check_field(field, name: str = "field"):
    heat_field = _heat_field_type()
    if not isinstance(field, heat_field):
        raise ParameterError(f"{name} must be a HeatField (from solve_heat_field), "
                             f"got {type(field).__name__} {reprlib.repr(field)}")
    cells = np.asarray(field.cells, dtype=float)
    if cells.ndim != 2 or not cells.size:
        raise ParameterError(f"{name}.cells must be a non-empty (H, W) array, got shape {cells.shape}")
    return field


def _is_several(field) -> bool:
    """Whether ``field`` is a sequence of more than one field (one per leg or per replan)."""
    return isinstance(field, Sequence) and not isinstance(field, (str, bytes)) and len(field) > 1


def _last_field(field):
    """``field`` itself, or the last of a non-empty sequence of fields (one per leg or per replan)."""
    if isinstance(field, Sequence) and not isinstance(field, (str, bytes)):
        if not len(field):
            raise ParameterError("field must be a HeatField or a non-empty sequence of them, got an empty sequence")
        return _check_field(field[-1], f"field[{len(field) - 1}]")
    return _check_field(field)


def _check_map(workspace, cells: np.ndarray) -> Workspace:
    """The workspace to draw obstacles from: the given one (its size the field's), or, without one, a
    map whose obstacles are the cells that have no temperature."""
    if workspace is None:
        return Workspace(np.isnan(cells))
    workspace = check_workspace(workspace)
    if (workspace.height, workspace.width) != cells.shape:
        raise ParameterError(f"the workspace is {workspace.width} × {workspace.height} cells but the field is "
                             f"{cells.shape[1]} × {cells.shape[0]}: the field must be solved on this workspace")
    return workspace


def _check_poses(poses, workspace: Workspace, name: str = "poses") -> np.ndarray | None:
    if poses is None:
        return None
    try:
        array = np.asarray(poses)
        ok = array.ndim == 2 and array.shape[1] == 4 and len(array) > 0 and np.issubdtype(array.dtype, np.integer)
    except (TypeError, ValueError):
        ok = False
    if not ok:
        raise ParameterError(f"{name} must be a non-empty (n, 4) integer array of (x, y, state, heading) rows "
                             f"(a plan's poses), got {reprlib.repr(poses)}")
    array = array.astype(np.int64)
    outside = ~((array[:, 0] >= 0) & (array[:, 0] < workspace.width)
                & (array[:, 1] >= 0) & (array[:, 1] < workspace.height))
    if outside.any():
        i = int(np.flatnonzero(outside)[0])
        raise ParameterError(f"{name}[{i}]: B2 cell ({array[i, 0]}, {array[i, 1]}) lies outside the "
                             f"{workspace.width} × {workspace.height} map")
    return array


def _replan_pose(value, name: str) -> Pose:
    """A replan's pose: a Pose, a ``{x, y, shape, heading}`` mapping (a run's JSON), or a sequence
    (x, y, state, heading) with the state a name or an index (a row of a plan's poses)."""
    if isinstance(value, Mapping):
        missing = sorted({"x", "y", "shape"} - set(value))
        if missing:
            raise ParameterError(f"{name} must have keys x, y, shape (and heading), missing {', '.join(missing)}")
        value = (value["x"], value["y"], value["shape"], value.get("heading", 0))
    elif (isinstance(value, (Sequence, np.ndarray)) and not isinstance(value, (str, bytes, Pose))
          and len(value) == 4 and isinstance(value[2], (int, np.integer)) and not isinstance(value[2], bool)):
        if not 0 <= int(value[2]) < len(STATE_NAMES):
            raise ParameterError(f"{name}: state {int(value[2])} is not a state index 0…{len(STATE_NAMES) - 1}")
        value = (value[0], value[1], STATE_NAMES[int(value[2])], value[3])
    try:
        return as_pose(value, name)
    except HtetroError as err:
        raise ParameterError(str(err)) from err


def _check_replans(replans) -> list[Pose]:
    if replans is None:
        return []
    if isinstance(replans, (str, bytes, Mapping)) or not isinstance(replans, Sequence):
        raise ParameterError(f"replans must be a list of records with a 'pose' (as a HeatRun's replans), "
                             f"got {reprlib.repr(replans)}")
    poses = []
    for i, record in enumerate(replans):
        if not isinstance(record, Mapping) or "pose" not in record:
            raise ParameterError(f"replans[{i}] must be a mapping with a 'pose' entry, got {reprlib.repr(record)}")
        poses.append(_replan_pose(record["pose"], f"replans[{i}]['pose']"))
    return poses


def _revealed_cells(replans, hidden, cells: np.ndarray, workspace: Workspace) -> np.ndarray:
    """The obstacle cells the drawn field knows that the map lacks: those the replans' records list as
    ``revealed`` (hidden, then sensed), and the hidden cells without a temperature. Shape (m, 2), (x, y).

    Raises
    ------
    ParameterError
        If a replan's ``revealed`` is not a list of (x, y) cells.
    """
    listed = []
    for i, record in enumerate(replans or ()):
        given = record.get("revealed", ()) if isinstance(record, Mapping) else ()
        try:
            listed.append(np.asarray(given, dtype=np.int64).reshape(-1, 2))
        except (TypeError, ValueError) as err:
            raise ParameterError(f"replans[{i}]['revealed'] must be a list of (x, y) cells, "
                                 f"got {reprlib.repr(given)}") from err
    hidden = _hidden_cells(hidden)
    h, w = cells.shape
    on_map = (hidden[:, 0] >= 0) & (hidden[:, 0] < w) & (hidden[:, 1] >= 0) & (hidden[:, 1] < h)
    hidden = hidden[on_map]
    listed.append(hidden[np.isnan(cells[hidden[:, 1], hidden[:, 0]])])  # an obstacle of the field's map
    found = np.unique(np.concatenate(listed), axis=0)
    found = found[(found[:, 0] >= 0) & (found[:, 0] < w) & (found[:, 1] >= 0) & (found[:, 1] < h)]
    return found[~workspace.occupancy[found[:, 1], found[:, 0]]]


def _draw_revealed(ax, cells: np.ndarray) -> list:
    """Obstacles revealed while replanning: the obstacles' grey, hatched in the replans' magenta."""
    if not len(cells):
        return []
    from matplotlib.collections import PolyCollection
    from matplotlib.patches import Patch

    style = {"facecolor": _obstacle_colour(), "edgecolor": _REPLAN_COLOUR, "hatch": "xx"}
    ax.add_collection(PolyCollection(_squares(cells), facecolors=style["facecolor"], edgecolors=_REPLAN_COLOUR,
                                     hatch="xx", linewidths=0.8, zorder=2.2, gid="revealed obstacles"))
    return [Patch(**style, linewidth=0.8, label=f"revealed obstacle: hidden, then sensed ({len(cells)})")]


def _arrow_grid(cells: np.ndarray, arrows: int) -> tuple[np.ndarray, np.ndarray]:
    """Rows and columns at which to draw arrows: one cell in every ``step`` each way (the same step
    both ways, so arrows sit on a square lattice), at most ``arrows`` a side, centred on the map."""
    h, w = cells.shape
    step = max(math.ceil(w / arrows), math.ceil(h / arrows))
    return np.arange((h - 1) % step // 2, h, step), np.arange((w - 1) % step // 2, w, step)


def _draw_gradient(ax, field, arrows: int) -> list:
    """∇T as unit arrows at a subsample of the cells: the direction to climb (the magnitude, which
    spans orders of magnitude between the source, the sink and the far rooms, is not drawn)."""
    if arrows == 0 or not field.connected:
        return []
    cells = np.asarray(field.cells, dtype=float)
    gx, gy = (np.asarray(g, dtype=float) for g in field.gradient())
    # A cell-centred field has no gradient along an axis without neighbours (a 1-cell corridor): 0 there.
    has = ~np.isnan(cells) & ~(np.isnan(gx) & np.isnan(gy))
    gx, gy = np.where(has, np.nan_to_num(gx), 0.0), np.where(has, np.nan_to_num(gy), 0.0)
    rows, cols = _arrow_grid(cells, arrows)
    y, x = (a.ravel() for a in np.meshgrid(rows, cols, indexing="ij"))
    u, v = gx[y, x], gy[y, x]
    norm = np.hypot(u, v)
    keep = has[y, x] & (norm > 0)
    if not keep.any():
        return []
    spacing = rows[1] - rows[0] if len(rows) > 1 else (cols[1] - cols[0] if len(cols) > 1 else 1)
    length = 0.75 * spacing
    x, y, u, v, norm = x[keep], y[keep], u[keep], v[keep], norm[keep]
    ax.quiver(x, y, length * u / norm, length * v / norm, angles="xy", scale_units="xy", scale=1,
              pivot="middle", color="white", edgecolor="black", linewidth=0.4, width=0.004,
              headwidth=4, headlength=4.5, headaxislength=4, zorder=2, gid="gradient")
    return [_marker_handle("∇T: direction of rising temperature", marker=r"$\rightarrow$", color="black",
                           markersize=10)]


def _draw_track(ax, poses: np.ndarray, *, dense: bool) -> list:
    """B2's path: a white line outlined in black (seen on every colour), start and end markers."""
    from matplotlib import patheffects

    outline = [patheffects.Stroke(linewidth=3.2, foreground="black"), patheffects.Normal()]
    ax.plot(poses[:, 0], poses[:, 1], color="white", linewidth=1.6, zorder=3, path_effects=outline, gid="path")
    size = 90 if dense else 110
    ax.scatter(poses[:1, 0], poses[:1, 1], marker="o", s=size * 0.7, color=_ROADMAP_COLOURS["start"],
               edgecolors="white", linewidths=1.2, zorder=4, gid="start")
    ax.scatter(poses[-1:, 0], poses[-1:, 1], marker="*", s=size * 1.6, color=_ROADMAP_COLOURS["goal"],
               edgecolors="white", linewidths=1.0, zorder=4, gid="end")
    return [_marker_handle("path of block B2", linestyle="-", color="white", linewidth=1.6, path_effects=outline),
            _marker_handle("start", marker="o", color=_ROADMAP_COLOURS["start"], markeredgecolor="white", markersize=8),
            _marker_handle("end of the path", marker="*", color=_ROADMAP_COLOURS["goal"], markeredgecolor="white",
                           markersize=12)]


def _draw_replans(ax, replans: list[Pose]) -> list:
    """Where the robot replanned: a cross at B2."""
    if not replans:
        return []
    ax.scatter([p.x for p in replans], [p.y for p in replans], marker="X", s=110, color=_REPLAN_COLOUR,
               edgecolors="black", linewidths=0.8, zorder=5, gid="replans")
    return [_marker_handle(f"replanned here ({len(replans)})", marker="X", color=_REPLAN_COLOUR,
                           markeredgecolor="black", markersize=9)]


def _draw_heat(ax, field, workspace: Workspace, poses, replans: list[Pose], *, arrows: int, colorbar: bool,
               title: str | None, revealed: np.ndarray, hidden=None, later: bool = False) -> None:
    plt = _pyplot()
    cells = np.asarray(field.cells, dtype=float)
    dense = _cell_points(ax, workspace.width, workspace.height) < DENSE_CELL_PT
    # obstacles in plot_path's grey, under the image; hidden ones the field still has a temperature on
    # (not yet sensed when it was solved) cross-hatched over it
    unknown = _hidden_cells(hidden)
    h, w = cells.shape
    unknown = unknown[(unknown[:, 0] >= 0) & (unknown[:, 0] < w) & (unknown[:, 1] >= 0) & (unknown[:, 1] < h)]
    unknown = unknown[~np.isnan(cells[unknown[:, 1], unknown[:, 0]])]  # the field has a temperature there
    handles = _draw_map(ax, workspace, None, dense=dense)
    cmap = plt.get_cmap(HEAT_COLORMAP).with_extremes(bad=(0.0, 0.0, 0.0, 0.0))  # no temperature: the map shows
    image = ax.imshow(np.ma.masked_invalid(cells), cmap=cmap, vmin=0.0, vmax=1.0, origin="lower",
                      interpolation="nearest", extent=(-0.5, workspace.width - 0.5, -0.5, workspace.height - 0.5),
                      zorder=1, gid="temperature")
    handles += _draw_revealed(ax, revealed)
    if len(unknown):
        from matplotlib.collections import PolyCollection
        from matplotlib.patches import Patch

        ax.add_collection(PolyCollection(_squares(unknown), facecolors="none", edgecolors="black", hatch="xx",
                                         linewidths=0.8, zorder=2.2, gid="hidden obstacles"))
        handles.append(Patch(facecolor="none", edgecolor="black", hatch="xx",
                             label="hidden obstacle, not sensed when this field was solved"))
    dropped = np.isnan(cells) & ~workspace.occupancy
    if len(revealed):
        dropped[revealed[:, 1], revealed[:, 0]] = False
    if dropped.any():
        from matplotlib.patches import Patch

        handles.append(Patch(facecolor="white", edgecolor="#999999", linewidth=0.6,
                             label="free, cut off from start and goal (no temperature)"))
    if not field.connected:
        ax.text(0.5, 0.5, _NO_FIELD_TEXT, transform=ax.transAxes, ha="center", va="center", fontsize=9,
                bbox={"facecolor": "white", "edgecolor": "black"}, zorder=6, gid="no field")
    handles += _draw_gradient(ax, field, arrows)
    if poses is not None:
        handles += _draw_track(ax, poses, dense=dense)
    handles += _draw_replans(ax, replans)
    if colorbar:
        # after a replan (or of several legs' fields) the field drawn is the last plan's: its sink is
        # where that plan started, not the start marked on the path
        ends = "0 at the last plan's start, 1 at its goal" if later else "sink: start 0, source: goal 1"
        _colour_bar(ax, image, f"temperature T ({ends})", shrink=0.85, pad=0.02)
    _frame(ax, workspace, "temperature field T and ∇T" if title is None else title)
    if handles:
        ax.legend(handles=handles, loc="upper center", bbox_to_anchor=(0.5, -0.1), ncol=2, fontsize=8,
                  frameon=False)


def plot_heat_field(field, *, workspace: Workspace | None = None, poses=None, replans=None, arrows: int = 40,
                    ax=None, colorbar: bool = True, title: str | None = None, hidden=None):
    """Draw a temperature field, its gradient and a path: panel (b) of Do et al. 2021's Figs. 7–12.

    Drawn, with a legend under the map: the cell temperatures as an image (the :data:`HEAT_COLORMAP`
    from 0 at the sink, the start's B2 cell, to 1 at the source, the goal's; of several fields or with
    replans, the last plan's start and goal, which the colour bar's label then says); obstacles in
    :func:`~htetro_opt.viz.plot_path`'s grey; free cells without a temperature (regions cut off from
    the start and the goal) white; ∇T as unit arrows (the direction in which the temperature rises,
    which a heat plan climbs) at a square lattice of cells, at most ``arrows`` a side; B2's path as a
    white line outlined in black, with a green dot at its start and a red star at its end; replanning
    poses as magenta crosses; obstacles revealed while replanning (hidden obstacles that the field's map
    has, as the replans' ``revealed`` cells and the ``hidden`` cells without a temperature) in the
    obstacles' grey hatched magenta, and hidden obstacles the field does not know cross-hatched black.
    y grows upwards (MODEL.md §1).

    Parameters
    ----------
    field : HeatField or sequence of HeatField
        From :func:`~htetro_opt.solvers.grid_paths.solve_heat_field`; of a sequence (one field per leg
        or per replan) the last is drawn.
    workspace : Workspace, optional, keyword-only
        The map the field was solved on (its size must be the field's). Without it, every cell without
        a temperature is drawn as an obstacle.
    poses : array of int, shape (n, 4), optional, keyword-only
        (x, y, state, heading) of the poses visited, as a plan's ``poses``.
    replans : sequence of mapping, optional, keyword-only
        Records with a ``"pose"`` entry, as a :class:`~htetro_opt.solvers.grid_paths.HeatRun`'s
        ``replans``: a Pose, a ``{x, y, shape, heading}`` mapping or an (x, y, state, heading) row,
        and optionally ``"revealed"``, the obstacle cells (x, y) sensed before that replan.
    arrows : int ≥ 0, keyword-only
        Most arrows along each side of the map (0: none).
    ax : matplotlib Axes, optional, keyword-only
        Drawn on (a new figure when None).
    colorbar : bool, keyword-only
        Add a colour bar beside ``ax``.
    title : str, optional, keyword-only
        Drawn as given; None gives "temperature field T and ∇T", "" no title.
    hidden : ndarray, shape (m, 2), optional, keyword-only
        The scenario's hidden obstacles (x, y): those without a temperature were sensed before the
        field was solved (drawn as revealed), the others are drawn cross-hatched.

    Returns
    -------
    matplotlib Axes
        The image has gid ``"temperature"``, the arrows ``"gradient"``, the path ``"path"``.

    Raises
    ------
    ParameterError
        If ``field`` is not a HeatField, the workspace is not a Workspace of the field's size,
        ``poses`` is not an (n, 4) integer array of cells on the map, a replan has no valid pose,
        ``arrows`` is not a non-negative integer or ``colorbar`` not a bool.

    Examples
    --------
    >>> from htetro_opt.solvers.grid_paths import solve_heat_field
    >>> ws = Workspace(np.zeros((4, 6), dtype=bool))
    >>> field = solve_heat_field(ws, (5, 1), (0, 1))
    >>> ax = plot_heat_field(field, workspace=ws, poses=[[0, 1, 1, 0], [1, 1, 1, 0], [2, 1, 1, 0]], arrows=3)
    >>> [a.get_gid() for a in ax.get_children() if a.get_gid() in ("temperature", "gradient", "path")]
    ['temperature', 'gradient', 'path']
    >>> import matplotlib.pyplot as plt; plt.close(ax.figure)
    """
    several = _is_several(field)
    field = _last_field(field)
    cells = np.asarray(field.cells, dtype=float)
    workspace = _check_map(workspace, cells)
    poses = _check_poses(poses, workspace)
    replan_poses = _check_replans(replans)
    arrows = check_int(arrows, "arrows", minimum=0)
    colorbar = check_bool(colorbar, "colorbar")
    if title is not None and not isinstance(title, str):
        raise ParameterError(f"title must be a string or None, got {reprlib.repr(title)}")
    revealed = _revealed_cells(replans, hidden, cells, workspace)
    _, ax = _map_figure(workspace, ax)
    _draw_heat(ax, field, workspace, poses, replan_poses, arrows=arrows, colorbar=colorbar, title=title,
               revealed=revealed, hidden=hidden, later=several or bool(replan_poses))
    return ax


def plot_heat_plan(workspace: Workspace, plan, field, *, replans=None, roadmap=(), hidden=None, arrows: int = 40,
                   title: str = "", path: str | Path | None = None):
    """A heat plan in two panels: the robot's footprints, and the temperature field it climbed.

    Left, :func:`~htetro_opt.viz.plot_path` of the plan (footprints by shape, B2's path, the roadmap's
    poses, hidden obstacles); right, :func:`plot_heat_field` of the (last) field with B2's path; the
    poses the robot replanned from and the obstacles revealed while replanning are marked on both. Do et al. 2021's Figs. 7–12, panels (a) and (b)
    (for one plan), and Fig. 13 with ``replans``.

    Parameters
    ----------
    workspace : Workspace
    plan : Plan
        Anything with ``poses``, an (n, 4) array of (x, y, state, heading) (a
        :class:`~htetro_opt.solvers.grid_paths.Plan`, or a ``HeatRun`` of replanning).
    field : HeatField or sequence of HeatField
        The field drawn on the right (the last of a sequence), solved on ``workspace``.
    replans : sequence of mapping, optional, keyword-only
        Records with a ``"pose"`` entry (see :func:`plot_heat_field`).
    roadmap, hidden : keyword-only
        As for :func:`~htetro_opt.viz.plot_path` (left panel).
    arrows : int ≥ 0, keyword-only
        As for :func:`plot_heat_field`.
    title : str, keyword-only
        The figure's title, drawn as given ("" none).
    path : str or Path, optional, keyword-only
        Save the figure there (:func:`~htetro_opt.viz.save_figure`: atomically, format by extension),
        which also closes it.

    Returns
    -------
    matplotlib Figure

    Raises
    ------
    ParameterError
        On the arguments :func:`plot_heat_field` refuses, a ``plan`` without (n, 4) ``poses``, or a
        ``path`` whose extension matplotlib cannot write (checked before drawing).
    OutputError
        If ``path``'s folder does not exist or cannot be written (checked before drawing).
    """
    workspace = check_workspace(workspace)
    several = _is_several(field)
    field = _last_field(field)
    _check_map(workspace, np.asarray(field.cells, dtype=float))
    if not hasattr(plan, "poses"):
        raise ParameterError(f"plan must have poses (a Plan, or a HeatRun), got {type(plan).__name__} "
                             f"{reprlib.repr(plan)}")
    poses = _check_poses(plan.poses, workspace, "plan.poses")
    replan_poses = _check_replans(replans)
    revealed = _revealed_cells(replans, hidden, np.asarray(field.cells, dtype=float), workspace)
    arrows = check_int(arrows, "arrows", minimum=0)
    if not isinstance(title, str):
        raise ParameterError(f"title must be a string, got {reprlib.repr(title)}")
    if path is not None:
        figure_format(path)
        check_output_path(path, what="plot")

    plt = _pyplot()
    aspect = workspace.height / workspace.width
    fig, (ax_path, ax_heat) = plt.subplots(1, 2, figsize=(15.0, max(3.5, 6.0 * aspect) + 2.0), layout="compressed")
    plot_path(workspace, poses, roadmap=roadmap, hidden=hidden, title="footprints along the plan", ax=ax_path)
    if replan_poses or len(revealed):  # plot_path's legend is made: redo it with the replans' entries
        handles = ax_path.get_legend().legend_handles
        handles = [h for h in handles if h is not None]
        unknown = _hidden_cells(hidden)
        if len(revealed) and np.isin(_cell_keys(unknown), _cell_keys(revealed)).all():  # none left unknown
            handles = [h for h in handles if not h.get_label().startswith("hidden obstacle")]
        handles += _draw_revealed(ax_path, revealed) + _draw_replans(ax_path, replan_poses)
        ax_path.get_legend().remove()
        _legend(ax_path, handles)
    _draw_heat(ax_heat, field, workspace, poses, replan_poses, arrows=arrows, colorbar=True, title=None,
               revealed=revealed, hidden=hidden, later=several or bool(replan_poses))
    if title:
        fig.suptitle(title, fontsize=11)
    if path is not None:
        save_figure(fig, path)
    return fig
