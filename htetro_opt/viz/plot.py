"""Plots of maps and plans (matplotlib is imported lazily; nothing here computes a plan)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from htetro_opt._files import atomic_path
from htetro_opt.errors import HtetroError
from htetro_opt.model.robot import FOOTPRINTS, SHAPES, STATE_NAMES, Pose, shape_index
from htetro_opt.model.workspace import Workspace

__all__ = ["SHAPE_COLOURS", "SELECTION_STYLES", "plot_path", "plot_ga_plan", "save_figure"]

SHAPE_COLOURS = {
    "I": "#1f77b4", "O": "#ff7f0e", "L": "#2ca02c", "J": "#d62728",
    "Z": "#9467bd", "S": "#8c564b", "T": "#e377c2",
}
_INTERMEDIATE_COLOUR = "#7f7f7f"


def _pyplot():
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    return plt


def _colour(state: int) -> str:
    return SHAPE_COLOURS.get(STATE_NAMES[state], _INTERMEDIATE_COLOUR)


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

    Parameters
    ----------
    workspace : Workspace
    poses : ndarray of int, shape (n, 4)
        (x, y, state, heading) of the poses visited, in order.
    roadmap : tuple of Pose, keyword-only
        Configurations to outline (start green, intermediate blue, goal red).
    hidden : ndarray, shape (m, 2), optional, keyword-only
        Obstacles unknown to the planner, drawn hatched.
    title : str, keyword-only
    ax : matplotlib Axes, optional, keyword-only

    Returns
    -------
    matplotlib Figure
    """
    plt = _pyplot()
    from matplotlib.patches import Patch, Rectangle

    poses = np.asarray(poses, dtype=int).reshape(-1, 4)
    if ax is None:
        side = 6.0
        aspect = workspace.height / workspace.width
        fig, ax = plt.subplots(figsize=(side + 1.6, max(2.5, side * aspect) + 0.7), constrained_layout=True)
    else:
        fig = ax.figure
    w, h = workspace.width, workspace.height
    ax.imshow(workspace.occupancy, cmap="Greys", vmin=0, vmax=1.4, origin="lower",
              extent=(-0.5, w - 0.5, -0.5, h - 0.5), interpolation="nearest")
    if w <= 64 and h <= 64:
        ax.set_xticks(np.arange(-0.5, w, 1), minor=True)
        ax.set_yticks(np.arange(-0.5, h, 1), minor=True)
        ax.grid(which="minor", color="#dddddd", linewidth=0.4)
        ax.tick_params(which="minor", length=0)
    for obstacle in workspace.moving:
        start_cells = obstacle.cells_at(0)
        track = np.concatenate([obstacle.cells_at(t) for t in range(obstacle.period)])
        for x, y in np.unique(track, axis=0):
            ax.add_patch(Rectangle((x - 0.5, y - 0.5), 1, 1, facecolor="none", edgecolor="#555555", hatch="..", linewidth=0))
        for x, y in start_cells:
            ax.add_patch(Rectangle((x - 0.5, y - 0.5), 1, 1, facecolor="#555555", alpha=0.8))
    if hidden is not None:
        for x, y in np.asarray(hidden).reshape(-1, 2):
            ax.add_patch(Rectangle((x - 0.5, y - 0.5), 1, 1, facecolor="none", edgecolor="black", hatch="xx"))
    used = []
    change = np.ones(len(poses), dtype=bool)
    if len(poses) > 1:
        change[1:] = (poses[1:, 2] != poses[:-1, 2]) | (poses[1:, 3] != poses[:-1, 3])
    change[-1:] = True
    for i, (x, y, s, hd) in enumerate(poses):
        colour = _colour(s)
        if STATE_NAMES[s] not in used:
            used.append(STATE_NAMES[s])
        for bx, by in FOOTPRINTS[s, hd] + (x, y):
            ax.add_patch(Rectangle((bx - 0.5, by - 0.5), 1, 1, facecolor=colour, alpha=0.12, linewidth=0))
            if change[i]:
                ax.add_patch(Rectangle((bx - 0.45, by - 0.45), 0.9, 0.9, facecolor="none", edgecolor=colour, linewidth=1.2))
    if len(poses):
        ax.plot(poses[:, 0], poses[:, 1], color="black", linewidth=1.2, marker=".", markersize=3, label="B2 path")
    for i, pose in enumerate(roadmap):
        edge = "green" if i == 0 else "red" if i == len(roadmap) - 1 else "blue"
        for bx, by in pose.cells():
            ax.add_patch(Rectangle((bx - 0.5, by - 0.5), 1, 1, facecolor="none", edgecolor=edge, linewidth=2.2, linestyle="--"))
    handles = [Patch(facecolor=_colour(shape_index(n)), alpha=0.6, label=f"{n}-shape" if n in SHAPES else n) for n in used]
    if roadmap:
        handles.append(Patch(facecolor="none", edgecolor="green", linestyle="--", label="start"))
        handles.append(Patch(facecolor="none", edgecolor="red", linestyle="--", label="goal"))
    if handles:
        ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8, frameon=False)
    ax.set_xlim(-0.5, w - 0.5)
    ax.set_ylim(-0.5, h - 0.5)
    ax.set_aspect("equal")
    ax.set_xlabel("x (cells)")
    ax.set_ylabel("y (cells)")
    if title:
        ax.set_title(title, fontsize=10)
    return fig


SELECTION_STYLES = {
    "multi_objective": ("black", "multi-objective (max Σ f)"),
    "time": ("#1f77b4", "best f_t"),
    "smoothness": ("#2ca02c", "best f_sm"),
    "safety": ("#9467bd", "best f_sf"),
}
"""Colour and legend label of each of the paper's four output solutions (Fig. 9)."""

_FITNESS_STYLES = (("f_gr", "black"), ("f_t", "#1f77b4"), ("f_sm", "#2ca02c"), ("f_sf", "#9467bd"))


def plot_ga_plan(workspace: Workspace, plan, *, roadmap: tuple[Pose, ...] = (), hidden=None, title: str = ""):
    """The paper's Figs. 9 and 10 for a GA plan: the four selected paths, and convergence.

    Parameters
    ----------
    workspace : Workspace
    plan : GAPlan
        From :func:`~htetro_opt.solvers.plan_ga`: the chained multi-objective solution's ``poses``
        and, per leg, ``selected`` members (with ``poses``) and ``history``.
    roadmap, hidden, title : keyword-only
        As for :func:`plot_path`.

    Returns
    -------
    matplotlib Figure
        Left: the map, the multi-objective path's footprints, and the B2 tracks of the four
        selections (offset slightly so overlapping tracks stay visible). Right: the multi-objective
        solution's four fitnesses per generation, legs one after another.
    """
    plt = _pyplot()
    aspect = workspace.height / workspace.width
    fig, (ax_map, ax_fit) = plt.subplots(
        1, 2, figsize=(13.5, max(3.5, 6.0 * aspect) + 0.8), constrained_layout=True,
        gridspec_kw={"width_ratios": [1.35, 1.0]},
    )
    plot_path(workspace, plan.poses, roadmap=roadmap, hidden=hidden, ax=ax_map)
    for line in list(ax_map.lines):  # the generic B2 path is replaced by the four coloured tracks
        line.remove()
    for k, (name, (colour, label)) in enumerate(SELECTION_STYLES.items()):
        offset = (k - 1.5) * 0.08
        for j, leg in enumerate(plan.legs):
            member = leg.selected.get(name)
            if member is None or not len(member.poses):
                continue
            ax_map.plot(member.poses[:, 0] + offset, member.poses[:, 1] + offset, color=colour,
                        linewidth=2.2 if name == "multi_objective" else 1.3, label=label if j == 0 else None,
                        zorder=4 if name == "multi_objective" else 3)
    handles, labels = ax_map.get_legend_handles_labels()
    old = ax_map.get_legend()
    extra = list(old.legend_handles) if old is not None else []
    ax_map.legend(handles=extra + handles, loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8, frameon=False)
    if title:
        ax_map.set_title(title, fontsize=10)

    start = 1
    for j, leg in enumerate(plan.legs):
        history = np.asarray(leg.history).reshape(-1, 4)
        gens = np.arange(start, start + len(history))
        for i, (name, colour) in enumerate(_FITNESS_STYLES):
            ax_fit.plot(gens, history[:, i], color=colour, linewidth=1.4, label=name if j == 0 else None)
        if leg.reach_generation is not None:
            ax_fit.axvline(start + leg.reach_generation - 1, color="red", linestyle=":", linewidth=1.0,
                           label="goal first reached" if j == 0 else None)
        if j:
            ax_fit.axvline(start - 0.5, color="#888888", linestyle="--", linewidth=0.8)
        start += len(history)
    ax_fit.set_xlabel("generation" + (" (legs one after another)" if len(plan.legs) > 1 else ""))
    ax_fit.set_ylabel("fitness of the multi-objective solution")
    ax_fit.set_title("convergence (Fig. 10)", fontsize=10)
    ax_fit.grid(alpha=0.3)
    ax_fit.legend(fontsize=8, loc="lower right")
    return fig


def save_figure(fig, path: str | Path, *, dpi: int = 120) -> Path:
    """Save a figure as PNG atomically (a temporary file renamed into place), then close it.

    Raises
    ------
    HtetroError
        If the directory does not exist or the file cannot be written.
    """
    plt = _pyplot()
    path = Path(path)
    directory = path.parent if str(path.parent) else Path(".")
    if not directory.is_dir():
        plt.close(fig)
        raise HtetroError(f"cannot write plot {str(path)!r}: directory {str(directory)!r} does not exist")
    try:
        with atomic_path(path) as tmp:
            fig.savefig(tmp, dpi=dpi, format="png")
    except OSError as err:
        raise HtetroError(f"cannot write plot {str(path)!r}: {err.strerror or err}") from err
    finally:
        plt.close(fig)
    return path
