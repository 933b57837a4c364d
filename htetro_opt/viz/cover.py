"""Plots of complete-coverage plans (Cheng et al. 2019, Figs. 8b, 10, 11, 14, 15).

matplotlib is imported only inside the functions; nothing here plans. Every kind of mark is one
artist with a ``gid`` (``"arrows <layer>"`` (``"arrows other"``: moves in no layer), ``"path <layer>"`` (a
long plan's line), ``"switch footprints"``, ``"uncoverable"``, ``"region cuts"``, ``"stripe <k>"``,
``"borrowed rows"``, ``"start"``, ``"goal"`` or ``"end"``), so that a test or a notebook
can find what was drawn.
"""

from __future__ import annotations

import math

import numpy as np

from htetro_opt.errors import ParameterError
from htetro_opt._validation import check_int
from htetro_opt.model.robot import STATE_NAMES, shape_index
from htetro_opt.model.workspace import Workspace, check_workspace
from htetro_opt.viz._style import SHAPE_COLOURS, _legend, _marker_handle, _pyplot
from htetro_opt.viz.plot import (
    DENSE_CELL_PT,
    _cell_points,
    _draw_map,
    _footprint_cells,
    _frame,
    _map_figure,
    _outline_segments,
)

__all__ = ["plot_cover", "plot_cover_heat", "LAYER_COLOURS"]

LAYER_COLOURS = {"vI": "red", "hI": "green", "O": "blue"}
"""B2's arrows in the paper's three layers (Fig. 15: red vertical I, green horizontal I, blue O);
any other layer ``SHAPE@H`` takes its shape's :data:`~htetro_opt.viz.SHAPE_COLOURS`."""

_STRIPE_SHADES = ("#fff2cc", "#d6e6f5")
_UNCOVERABLE_COLOUR = "#b00000"
_OTHER_COLOUR = "#7f7f7f"  # a move made in no layer of the plan
_LANE = 0.12  # cells: how far right of B2's cell centres a long plan's line runs


def _check_plan(plan, workspace=None):
    for attribute in ("poses", "layers", "stripes_detail", "uncoverable", "free", "start", "goal"):
        if not hasattr(plan, attribute):
            raise ParameterError(f"plan must be a CoveragePlan (from plan_coverage), got {type(plan).__name__}")
    if workspace is not None and workspace.occupancy.shape != plan.free.shape:
        raise ParameterError(f"the plan is for a {plan.free.shape[1]} x {plan.free.shape[0]} map, the workspace is "
                             f"{workspace.width} x {workspace.height}")


def _layer_keys(names) -> list[tuple[str, int, int, str]]:
    """(name, state, heading, colour) of each layer name of a plan (``O``, ``vI``, ``hI``, ``SHAPE@H``)."""
    from htetro_opt.solvers.coverage import (
        parse_layers,  # the one reading of layer names
    )

    return [(layer.name, shape_index(layer.shape), layer.heading,
             LAYER_COLOURS.get(layer.name, SHAPE_COLOURS[layer.shape])) for layer in parse_layers(list(names))]


def _draw_stripes(ax, plan, width: int) -> list:
    """Stripe bands (alternating shades), borrowed rows hatched, region cuts dashed."""
    from matplotlib.collections import LineCollection
    from matplotlib.patches import Patch

    handles, cuts, borrowed = [], [], False
    for k, stripe in enumerate(plan.stripes_detail):
        lo, hi = stripe["rows"]
        ax.axhspan(lo - 0.5, hi - 0.5, facecolor=_STRIPE_SHADES[k % 2], alpha=0.45, edgecolor="#7a7a7a",
                   linewidth=1.0, zorder=0.4, gid=f"stripe {k}")  # over the map's image, under the path
        band = stripe.get("band", stripe["rows"])
        for a, b in ((band[0], lo), (hi, band[1])):
            if b > a:
                borrowed = True
                ax.axhspan(a - 0.5, b - 0.5, xmin=0.0, xmax=1.0, facecolor="none", edgecolor="#6a51a3",
                           hatch="//" if k % 2 else "\\\\", linewidth=0, zorder=0.5, gid="borrowed rows")
        bottom, top = band[0] - 0.5, band[1] - 0.5
        cuts += [[(c - 0.5, bottom), (c - 0.5, top)] for c in stripe.get("cuts", ())]
    if plan.stripes_detail:
        handles.append(Patch(facecolor=_STRIPE_SHADES[1], edgecolor="#9a9a9a", label="stripe (own rows)"))
    if borrowed:
        handles.append(Patch(facecolor="none", edgecolor="#6a51a3", hatch="//", label="rows borrowed by widening"))
    if cuts:
        ax.add_collection(LineCollection(cuts, colors="#444444", linestyles="--", linewidths=1.0, zorder=2.6,
                                         gid="region cuts"))
        handles.append(_marker_handle("region cut", linestyle="--", color="#444444", linewidth=1.0))
    return handles


def _move_groups(plan, layers):
    """B2's moves (pose i to i + 1 with another cell), grouped by the layer they are made in:
    ``[(name, colour, label, indices)]``, the layers' in order, then the moves made in no layer (an
    intermediate state, or a shape or heading outside the plan's layers) in grey."""
    poses = np.asarray(plan.poses)
    if len(poses) < 2:
        return []
    a, b = poses[:-1], poses[1:]
    moved = (a[:, :2] != b[:, :2]).any(axis=1)
    groups, claimed = [], np.zeros(len(a), dtype=bool)
    for name, state, heading, colour in layers:
        mine = moved & (a[:, 2] == state) & (a[:, 3] == heading)
        claimed |= mine
        groups.append((name, colour, f"B2 move in {name}", np.flatnonzero(mine)))
    other = np.flatnonzero(moved & ~claimed)
    groups.append(("other", _OTHER_COLOUR, "B2 move in no layer (intermediate state, other shape/heading)", other))
    return [group for group in groups if len(group[3])]


def _draw_arrows(ax, plan, layers, *, dense: bool, arrows: int) -> list:
    """B2's moves, one colour per layer: an arrow each, or, for more moves than ``arrows``, a line (each
    pass kept to its right, so a cell edge driven both ways shows two lanes) with an arrow every k-th move."""
    from matplotlib.collections import LineCollection

    poses = np.asarray(plan.poses)
    groups = _move_groups(plan, layers)
    n_moves = sum(len(group[3]) for group in groups)
    handles = []
    if not n_moves:
        return handles
    long = n_moves > arrows
    every = max(2, math.ceil(n_moves / max(arrows / 3, 1))) if long else 1
    order = np.sort(np.concatenate([group[3] for group in groups]))
    thinned = set(order[every // 2::every].tolist()) if long else None
    for name, colour, label, moves in groups:
        tail = poses[moves, :2].astype(float)
        d = poses[moves + 1, :2] - poses[moves, :2]
        if long:
            unit = d / np.hypot(d[:, 0], d[:, 1])[:, None]
            tail = tail + _LANE * np.column_stack([unit[:, 1], -unit[:, 0]])  # keep right
            ax.add_collection(LineCollection(np.stack([tail, tail + d], axis=1), colors=colour, linewidths=1.4,
                                             capstyle="round", zorder=2.9, gid=f"path {name}"))
            pick = np.array([m in thinned for m in moves.tolist()], dtype=bool)
            if pick.any():  # a short arrow on the middle of the move
                ax.quiver(tail[pick, 0] + 0.5 * d[pick, 0], tail[pick, 1] + 0.5 * d[pick, 1], 0.7 * d[pick, 0],
                          0.7 * d[pick, 1], angles="xy", scale_units="xy", scale=1, color=colour, pivot="mid",
                          width=0.004 if dense else 0.005, headwidth=4.5, headlength=5, headaxislength=4.5, zorder=3,
                          gid=f"arrows {name}")
            handles.append(_marker_handle(label, linestyle="-", marker=">", color=colour, linewidth=1.4,
                                          markersize=6))
        else:
            ax.quiver(tail[:, 0], tail[:, 1], d[:, 0], d[:, 1], angles="xy", scale_units="xy", scale=1, color=colour,
                      width=0.004 if dense else 0.006, headwidth=4, headlength=4, headaxislength=3.5, zorder=3,
                      gid=f"arrows {name}")
            handles.append(_marker_handle(label, marker=r"$\rightarrow$", color=colour, markersize=9))
    if long:
        handles.append(_marker_handle(f"{n_moves} moves: a line (passes keep right), an arrow every {every}",
                                      linestyle="none"))
    return handles


def _switches(plan, layers) -> np.ndarray:
    """Indices of the poses where the plan arrives in another layer (intermediate states skipped)."""
    keys = {(state, heading) for _, state, heading, _ in layers}
    poses = np.asarray(plan.poses)
    index = [i for i, (s, h) in enumerate(poses[:, 2:].tolist()) if (s, h) in keys]
    return np.array([j for i, j in zip(index[:-1], index[1:])
                     if tuple(poses[i, 2:]) != tuple(poses[j, 2:])], dtype=np.int64)


def _draw_switches(ax, plan, layers) -> list:
    from matplotlib.collections import LineCollection

    at = _switches(plan, layers)
    if not len(at):
        return []
    poses = np.asarray(plan.poses)[at]
    colour_of = {(state, heading): colour for _, state, heading, colour in layers}
    segments, owner = _outline_segments(_footprint_cells(poses))
    colours = [colour_of[(int(s), int(h))] for s, h in poses[owner, 2:]]
    ax.add_collection(LineCollection(segments, colors=colours, linewidths=1.6, zorder=3.2, gid="switch footprints"))
    return [_marker_handle(f"footprint after a layer switch ({len(at)})", linestyle="-", color="#555555",
                           linewidth=1.6)]


def _draw_ends(ax, plan, layers) -> list:
    """The start (green, dashed footprint, hollow dot at B2) and the end of the plan (red, dashed
    footprint, star at B2; "goal" when the plan has one, which it ends on), named by their layer."""
    from matplotlib.collections import LineCollection

    names = {(state, heading): name for name, state, heading, _ in layers}

    def layer(state: int, heading: int) -> str:
        return names.get((state, heading), f"{STATE_NAMES[state]}@{heading}")

    poses = np.asarray(plan.poses)
    x, y, state, heading = (int(v) for v in poses[-1])
    end = (f"goal, the end of the plan ({layer(state, heading)})" if plan.goal is not None
           else f"end of the plan ({layer(state, heading)}, after {len(plan.commands)} commands)")
    start = f"start ({layer(shape_index(plan.start.shape), plan.start.heading)})"
    ends = [("start", start, plan.start.cells()[None], (plan.start.x, plan.start.y), "green", "o", 70),
            ("goal" if plan.goal is not None else "end", end, _footprint_cells(poses[-1:]), (x, y), "red", "*", 150)]
    handles = []
    for gid, label, cells, (bx, by), colour, marker, size in ends:
        segments, _ = _outline_segments(cells)
        ax.add_collection(LineCollection(segments, colors=colour, linewidths=2.2, linestyles="--", zorder=4))
        ax.scatter([bx], [by], marker=marker, s=size, facecolors="none", edgecolors=colour, linewidths=1.6,
                   zorder=4.5, gid=gid)
        handles.append(_marker_handle(label, marker=marker, linestyle="--", color=colour, markerfacecolor="none",
                                      markeredgecolor=colour, markersize=7 if marker == "o" else 10))
    return handles


def plot_cover(workspace: Workspace, plan, *, title: str = "", ax=None, arrows: int = 150):
    """Draw a coverage plan on its map, as Cheng et al. 2019's Figs. 8b, 10, 11, 14a and 15a do.

    Stripes are shaded bands (rows borrowed by widening hatched), region cuts dashed lines; B2's
    moves are arrows, one colour per layer (:data:`LAYER_COLOURS`: vI red, hI green, O blue as in the
    paper; grey for a move made in no layer, in an intermediate state or another shape or heading);
    the robot's footprint is outlined where it arrives in another layer; free cells the plan cannot
    cover are marked ✗; the start and the end of the plan (the goal, when it has one) are outlined
    dashed (green with a dot at B2, red with a star), both in the legend.

    A plan of more than ``arrows`` moves would be a thicket of arrows (the tiling + TSP baseline drives
    cells back and forth): it is drawn as a line in the layers' colours, each pass kept a little to its
    right (so an edge driven both ways shows as two lanes), with an arrow on every k-th move, k the
    least that draws at most ``arrows / 3`` of them (at least 2); the legend says so.

    Parameters
    ----------
    workspace : Workspace
        The plan's map.
    plan : CoveragePlan
        From :func:`~htetro_opt.solvers.coverage.plan_coverage`.
    title : str, keyword-only
        Above the map; a line with the action cost, completeness and switches is added.
    ax : matplotlib Axes, optional, keyword-only
    arrows : int ≥ 1, keyword-only
        Most moves drawn as an arrow each; a longer plan is drawn as a line with sparse arrows.

    Returns
    -------
    matplotlib Figure

    Raises
    ------
    ParameterError
        If ``plan`` is not a coverage plan or is for another map's size, or ``arrows`` is not a
        positive integer.

    Examples
    --------
    >>> from htetro_opt.solvers.coverage import plan_coverage
    >>> ws = Workspace(np.zeros((4, 6), dtype=bool))
    >>> fig = plot_cover(ws, plan_coverage(ws, "O"))
    >>> sorted(a.get_gid() for a in fig.axes[0].collections if a.get_gid())
    ['arrows O', 'end', 'region cuts', 'start']
    >>> import matplotlib.pyplot as plt; plt.close(fig)
    """
    check_workspace(workspace)
    _check_plan(plan, workspace)
    arrows = check_int(arrows, "arrows", minimum=1)
    layers = _layer_keys(plan.layers)
    fig, ax = _map_figure(workspace, ax)
    dense = _cell_points(ax, workspace.width, workspace.height) < DENSE_CELL_PT
    handles = _draw_map(ax, workspace, None, dense=dense)
    handles += _draw_stripes(ax, plan, workspace.width)
    handles += _draw_arrows(ax, plan, layers, dense=dense, arrows=arrows)
    handles += _draw_switches(ax, plan, layers)
    if plan.uncoverable:
        cells = np.array([(x, y) for x, y, _ in plan.uncoverable])
        ax.scatter(cells[:, 0], cells[:, 1], marker="x", s=40 if not dense else 12, color=_UNCOVERABLE_COLOUR,
                   linewidths=1.8, zorder=5, gid="uncoverable")
        reasons = sorted({r for _, _, r in plan.uncoverable})
        handles.append(_marker_handle(f"uncoverable ({len(cells)}: {', '.join(reasons)})", marker="x",
                                      color=_UNCOVERABLE_COLOUR, markersize=7, markeredgewidth=1.8))
    handles += _draw_ends(ax, plan, layers)
    state = "complete" if plan.complete else f"{plan.coverage_pct:.1f} % of free cells"
    summary = (f"{plan.method}, {{{', '.join(plan.layers)}}}: {len(plan.commands)} commands, {state}, "
               f"{plan.switches} switches")
    _frame(ax, workspace, f"{title}\n{summary}" if title else summary)
    _legend(ax, handles)
    return fig


def plot_cover_heat(plan, *, title: str = "", bins: int = 30):
    """Coverage time of a plan's run, as Cheng et al. 2019's Figs. 14b–c and 15b–c: the pixel-time map
    (:func:`~htetro_opt.viz.plot_coverage` of ``plan.coverage``) beside a histogram of the time
    spent on each pixel of the free cells.

    Parameters
    ----------
    plan : CoveragePlan
    title : str, keyword-only
    bins : int, keyword-only
        Histogram bins.

    Returns
    -------
    matplotlib Figure
        Two axes and the map's colour bar.

    Raises
    ------
    ParameterError
        If ``plan`` is not a coverage plan or ``bins`` is not a positive integer.

    Examples
    --------
    >>> from htetro_opt.solvers.coverage import plan_coverage
    >>> fig = plot_cover_heat(plan_coverage(Workspace(np.zeros((4, 6), dtype=bool)), "O"))
    >>> len(fig.axes)
    3
    >>> import matplotlib.pyplot as plt; plt.close(fig)
    """
    from htetro_opt.viz.tiles import plot_coverage

    _check_plan(plan)
    bins = check_int(bins, "bins", minimum=1)
    result = plan.coverage
    h, w = result.cell_time.shape
    plt = _pyplot()
    fig, (left, right) = plt.subplots(1, 2, figsize=(12.0, max(3.5, 6.0 * h / w) + 1.0),
                                      gridspec_kw={"width_ratios": [3, 2]}, layout="constrained")
    plot_coverage(result, title=title, ax=left, time_unit="command units")  # a plan's clock: one a command
    p = result.pixels_per_cell
    times = result.pixel_time[np.kron(result.free, np.ones((p, p), dtype=bool))]
    right.hist(times, bins=bins, color="#4c72b0", edgecolor="white", gid="pixel-time histogram")
    right.axvline(result.average_grid_time, color="black", linestyle="--", linewidth=1.2,
                  label=f"average coverage time {result.average_grid_time:.3f} command units")
    right.set_xlabel("time a pixel is covered (command units)")
    right.set_ylabel("pixels of free cells")
    right.set_title(f"{plan.recovered_pct:.1f} % of coverable cells re-covered (≥ 1.5)", fontsize=10)
    right.legend(fontsize=8, frameon=False)
    return fig
