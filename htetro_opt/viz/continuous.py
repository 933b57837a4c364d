"""Plots of continuous planning (Nazarahari et al. 2019): the workspace with its obstacles (and the
C-obstacles' outline for a disc robot), several methods' paths with their path bases (Fig. 9), or one
method under several weights (Fig. 10), the robots where two come closest (Fig. 11), the APF's
potential (Fig. 3) and a multi-objective front.

matplotlib is imported lazily (:mod:`htetro_opt.viz._style`); nothing here plans: the figures draw
:class:`~htetro_opt.solvers.continuous.ContinuousPlan` objects and scenarios as they are.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from htetro_opt.errors import ParameterError
from htetro_opt.viz._style import _colour_bar, _legend, _pyplot

__all__ = ["plot_continuous", "plot_apf_potential", "plot_continuous_front", "PLAN_COLOURS"]

PLAN_COLOURS = ("#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#17becf", "#8c564b", "#e377c2")
"""One colour per plan (methods, weights), or per robot when one plan is drawn."""

_OBSTACLE = "#7f7f7f"
_UNITS = "map units"  # a continuous scenario's coordinates have no unit of their own (from a grid: cells)


def _check_scenario(scenario):
    from htetro_opt.solvers.continuous import check_scenario  # the solvers load only when a plot is drawn

    try:
        return check_scenario(scenario)
    except Exception as err:
        raise ParameterError(str(err)) from err


def _plans(plans) -> list:
    from htetro_opt.solvers.continuous import ContinuousPlan

    if isinstance(plans, ContinuousPlan):
        plans = [plans]
    if isinstance(plans, (str, bytes)) or not isinstance(plans, Sequence):
        raise ParameterError(f"plans must be a ContinuousPlan or a sequence of them, got {type(plans).__name__}")
    for i, plan in enumerate(plans):
        if not isinstance(plan, ContinuousPlan):
            raise ParameterError(f"plans[{i}] must be a ContinuousPlan, got {type(plan).__name__}")
    return list(plans)


def _workspace(ax, scenario, *, outline: bool) -> None:
    from matplotlib.collections import PolyCollection

    ax.add_collection(PolyCollection([np.asarray(o) for o in scenario.obstacles], facecolors=_OBSTACLE,
                                     edgecolors="none", gid="obstacles"))
    if outline and scenario.robot_radius > 0:
        grown = scenario.geometry.polygonised("inner").obstacles
        ax.add_collection(PolyCollection([np.asarray(o) for o in grown], facecolors="none", edgecolors=_OBSTACLE,
                                         linestyles="--", linewidths=0.8, gid="c-obstacles"))
    ax.plot([0, scenario.width, scenario.width, 0, 0], [0, 0, scenario.height, scenario.height, 0], color="black",
            linewidth=1.0)
    ax.set_xlim(-0.02 * scenario.width, 1.02 * scenario.width)
    ax.set_ylim(-0.02 * scenario.height, 1.02 * scenario.height)
    ax.set_aspect("equal")
    ax.set_xlabel(f"x ({_UNITS})")
    ax.set_ylabel(f"y ({_UNITS})")


def _label(plan) -> str:
    """The plan's legend entry: method (and weights), total length over the robots that reached
    their goals, and which did not."""
    weights = plan.info.get("weights")
    label = plan.method
    if weights is not None and list(weights) != [1.0, 0.0, 0.0]:
        label += " W=(" + ", ".join(f"{w:.3g}" for w in weights) + ")"
    missed = [k for k, reached in enumerate(plan.robots_reached) if not reached]
    if not missed:
        return f"{label}: {plan.length:.2f}"
    if len(missed) == len(plan.robots_reached):
        return f"{label}: {'goal not' if len(missed) == 1 else 'no goal'} reached"
    robots = f"robot{'s' if len(missed) > 1 else ''} {', '.join(map(str, missed))}"
    return f"{label}: {plan.length:.2f} ({robots} not reached)"


def _robot_width(k: int, n: int) -> float:
    """Line width of robot k of n in one plan: the first widest, each later one (drawn on top)
    narrower, so that where robots share a stretch (two driving one line in opposite directions)
    every colour still shows, as nested stripes."""
    return 1.5 + min(1.0, 3.0 / max(n - 1, 1)) * (n - 1 - k)


def _ends(ax, scenario, *, per_robot: bool) -> None:
    """Starts as filled dots drawn over the goals, goals as hollow stars: where robots swap places,
    a start and another robot's goal share a point and both stay visible. ``per_robot``: each in its
    robot's colour (a legend entry per robot gives the colours), else black."""
    n = scenario.n_robots
    colours = [PLAN_COLOURS[k % len(PLAN_COLOURS)] if per_robot else "black" for k in range(n)]
    ax.scatter(scenario.goals[:, 0], scenario.goals[:, 1], marker="*", s=190, facecolors="none",
               edgecolors=colours, linewidths=1.4, zorder=4, gid="goals")
    ax.scatter(scenario.starts[:, 0], scenario.starts[:, 1], marker="o", s=30, c=colours, edgecolors="black",
               linewidths=0.6, zorder=5, gid="starts")
    ax.plot([], [], "o", color="black", markersize=5, label="start" + (" (robot's colour)" if per_robot else ""))
    ax.plot([], [], "*", markerfacecolor="none", markeredgecolor="black", markersize=12,
            label="goal (hollow)" + (", robot's colour" if per_robot else ""))


def plot_continuous(scenario, plans=(), *, ax=None, title: str = "", path_bases: bool = True,
                    closest: bool = True, outline: bool = True):
    """The workspace, its obstacles and the plans' paths.

    Parameters
    ----------
    scenario : ContinuousScenario
    plans : ContinuousPlan or sequence of them
        Drawn in :data:`PLAN_COLOURS` order, one colour a plan (a single plan: one colour a robot).
    ax : matplotlib Axes, keyword-only, optional
        Draw there (default: a new figure).
    title : str, keyword-only
    path_bases : bool, keyword-only
        Mark each path's PBs (``info["path_bases"]`` where it gives their points, as the GAs' plans do;
        else the path's interior vertices, as for the PSO's and the graph searches' plans).
    closest : bool, keyword-only
        For a plan of several robots, draw the two that come closest as discs of radius r at that
        moment, joined by a dotted line (Fig. 11).
    outline : bool, keyword-only
        For r > 0, outline the C-obstacles (the obstacles grown by r).

    Returns
    -------
    matplotlib Figure
        The map in its own coordinates (axes labelled "x (map units)", "y (map units)") and the
        legend right of it: start, goal, and per plan its method, its total length over the robots
        that reached their goals and those that did not (which have no line). One plan of several
        robots draws each robot in its own colour with a legend entry of its own ("robot k: its
        length" or "robot k: not reached"), robot 0's line widest and each later one narrower, so
        that paths along one line stay visible. Starts are filled dots drawn over the goals' hollow
        stars (in the robot's colour for one plan of several robots), so that where the robots swap
        places both stay visible.

    Raises
    ------
    ParameterError
        If ``scenario`` is not a continuous scenario or a plan is not a ContinuousPlan.
    """
    from htetro_opt.model.continuous import closest_approach

    scenario = _check_scenario(scenario)
    plans = _plans(plans)
    plt = _pyplot()
    if ax is None:
        fig, ax = plt.subplots(figsize=(6.4, 6.4 * scenario.height / scenario.width))
    else:
        fig = ax.figure
    _workspace(ax, scenario, outline=outline)
    per_robot = len(plans) == 1 and scenario.n_robots > 1  # one plan of several robots: a colour a robot
    _ends(ax, scenario, per_robot=per_robot)
    for p, plan in enumerate(plans):
        label = _label(plan)  # on the plan's first line drawn (one plan of several robots: a line of its own)
        if per_robot:
            if any(plan.robots_reached):
                label = label.replace(": ", ": total ", 1)
            ax.plot([], [], linestyle="none", label=label)
            label = None
        for k, path in enumerate(plan.paths):
            colour = PLAN_COLOURS[(k if len(plans) == 1 else p) % len(PLAN_COLOURS)]
            width = _robot_width(k, len(plan.paths)) if per_robot else 1.5
            if per_robot:
                reached = plan.robots_reached[k] and len(path)
                robot = f"robot {k}: " + (f"{float(plan.lengths[k]):.2f}" if reached else "not reached")
                if not len(path):
                    ax.plot([], [], "-", color=colour, linewidth=width, label=robot)
                    continue
                label = robot
            if not len(path):
                continue
            ax.plot(path[:, 0], path[:, 1], "-", color=colour, linewidth=width, label=label, gid=f"path-{p}-{k}")
            label = None
            if path_bases:
                pbs = _path_bases(plan, k, path)
                if len(pbs):
                    ax.plot(pbs[:, 0], pbs[:, 1], "o", color=colour, markersize=3.5, markerfacecolor="white",
                            gid=f"pbs-{p}-{k}")
        if label is not None:  # no robot reached its goal: the legend still names the plan
            ax.plot([], [], "-", color=PLAN_COLOURS[p % len(PLAN_COLOURS)], linewidth=1.5, label=label)
        reached = [k for k in range(len(plan.paths)) if plan.robots_reached[k] and len(plan.paths[k])]
        if closest and len(reached) > 1:
            best = min(((closest_approach(plan.paths[a], plan.paths[b]), a, b) for i, a in enumerate(reached)
                        for b in reached[i + 1:]), key=lambda item: item[0][0])
            (distance, t), a, b = best
            spots = [_at(plan.paths[a], t), _at(plan.paths[b], t)]
            radius = max(scenario.robot_radius, 0.15)
            for spot, k in zip(spots, (a, b)):
                colour = PLAN_COLOURS[(k if len(plans) == 1 else p) % len(PLAN_COLOURS)]
                ax.add_patch(plt.Circle(tuple(spot), radius, facecolor=colour, alpha=0.5, edgecolor="black", zorder=3,
                                        gid=f"closest-{p}"))
            ax.plot(*np.transpose(spots), ":", color="black", linewidth=1.0,
                    label=f"closest approach {distance:.2f} (t = {t:.1f})" if p == 0 else None)
    _legend(ax, ax.get_legend_handles_labels()[0], x=1.02)
    ax.set_title(title or scenario.name)
    return fig


def _path_bases(plan, k: int, path: np.ndarray) -> np.ndarray:
    """Robot ``k``'s path bases as an (m, 2) array: the GAs' ``info["path_bases"][k]`` (points),
    else the path's interior vertices (a PSO path runs through its PBs and its ``info`` gives only
    their count; the graph searches' plans give none)."""
    bases = plan.info.get("path_bases")
    listed = isinstance(bases, (Sequence, np.ndarray)) and not isinstance(bases, str)
    entry = bases[k] if listed and k < len(bases) else None
    if entry is not None and not isinstance(entry, (int, float, np.number)):
        points = np.asarray(entry, dtype=float)
        if points.size == 0 or (points.ndim == 2 and points.shape[1] == 2):
            return points.reshape(-1, 2)
    return path[1:-1]


def _at(path: np.ndarray, t: float) -> np.ndarray:
    """Where a robot moving at unit speed along ``path`` (waiting at its end) is at time ``t``."""
    if len(path) == 1:
        return path[0]
    s = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(path, axis=0).T))])
    return np.array([np.interp(t, s, path[:, 0]), np.interp(t, s, path[:, 1])])


def plot_apf_potential(scenario, *, robot: int = 0, grid: float = 1.0, n_paths: int = 3, seed=0, ax=None,
                       title: str = ""):
    """The APF's potential of one robot's goal (Fig. 3a: each lattice node coloured by −hop depth,
    unreached nodes hollow) and a few of its paths (Fig. 3b).

    Raises
    ------
    ParameterError
        On a bad scenario, robot index or grid.
    """
    from htetro_opt._validation import check_int
    from htetro_opt.solvers.continuous import apf_depths, apf_paths, check_grid, lattice_graph

    scenario = _check_scenario(scenario)
    robot = check_int(robot, "robot", minimum=0, maximum=scenario.n_robots - 1)
    grid = check_grid(grid, scenario.geometry)
    start, goal = scenario.starts[robot], scenario.goals[robot]
    nodes, graph = lattice_graph(scenario.geometry, grid, ends=[start, goal])
    depth = apf_depths(graph, len(nodes) - 1)
    plt = _pyplot()
    if ax is None:
        fig, ax = plt.subplots(figsize=(7.2, 6.4 * scenario.height / scenario.width))
    else:
        fig = ax.figure
    _workspace(ax, scenario, outline=True)
    size = max(4.0, 2400.0 / max(len(nodes), 1))
    seen = depth >= 0
    dots = ax.scatter(nodes[seen, 0], nodes[seen, 1], c=-depth[seen], s=size, cmap="viridis", gid="potential")
    ax.scatter(nodes[~seen, 0], nodes[~seen, 1], s=size, facecolors="none", edgecolors="#bbbbbb", gid="unreached")
    _colour_bar(ax, dots, "potential (−hops to the goal)", shrink=0.8)
    paths, _ = apf_paths(scenario.geometry, start, goal, n_paths=n_paths, grid=grid, seed=seed)
    for i, pbs in enumerate(paths):
        line = np.vstack([start, pbs, goal])
        ax.plot(line[:, 0], line[:, 1], "-o", color=PLAN_COLOURS[(i + 1) % len(PLAN_COLOURS)], markersize=3,
                linewidth=1.2, gid=f"apf-{i}")
    ax.plot(*start, "o", color="black")
    ax.plot(*goal, "*", color="black", markersize=10)
    ax.set_title(title or f"{scenario.name}: APF potential, robot {robot}")
    return fig


def plot_continuous_front(plan, *, ax=None, title: str = ""):
    """A multi-objective plan's front (``info["front"]``): length against smoothness, coloured by safety.

    Raises
    ------
    ParameterError
        If ``plan`` has no front (only ``"nsga2"`` and :func:`~htetro_opt.solvers.continuous.plan_moea`
        plans do).
    """
    plan = _plans(plan)[0]
    front = plan.info.get("front")
    if not front:
        raise ParameterError(f"the {plan.method} plan has no front: plan with method='nsga2' (or plan_moea)")
    values = np.array([[m["objectives"]["length"], m["objectives"]["smoothness_deg"], m["objectives"]["safety"]]
                       for m in front])
    plt = _pyplot()
    if ax is None:
        fig, ax = plt.subplots(figsize=(6.0, 4.5))
    else:
        fig = ax.figure
    dots = ax.scatter(values[:, 0], values[:, 1], c=values[:, 2], cmap="viridis", gid="front")
    _colour_bar(ax, dots, "safety")
    ax.set_xlabel("length")
    ax.set_ylabel("smoothness (degrees)")
    ax.set_title(title or f"{plan.scenario}: {plan.method} front ({len(front)} members)")
    return fig
