"""Plots of GA fronts and convergence (matplotlib is imported lazily; nothing here computes a front).

A front is an array of fitnesses, one row per member and the columns (f_gr, f_t, f_sm, f_sf), all
to be maximised (f_t = 1 − t/t_max is negative for a path slower than t_max, f_sf beside many
obstacles: the axes say what the values mean), or the GA record it comes from: a :class:`~htetro_opt.solvers.grid_paths.Plan`
(its last leg's front) or a :class:`~htetro_opt.solvers.grid_paths.LegResult`. pymoo's ``F`` is
the negation (pymoo minimises): pass ``-F``.

- :func:`plot_fronts`: a matrix of pairwise scatter plots, each front its own colour and marker;
- :func:`plot_parallel`: parallel coordinates, every axis scaled to the range of all fronts shown;
- :func:`plot_convergence`: a GA's multi-objective solution's four fitnesses per generation.
"""

from __future__ import annotations

import numbers
from collections.abc import Mapping, Sequence

import numpy as np

from htetro_opt.errors import ParameterError
from htetro_opt.viz._style import _FITNESS_STYLES, _legend, _marker_handle, _pyplot

__all__ = ["DEFAULT_OBJECTIVES", "FITNESS_OBJECTIVES", "plot_convergence", "plot_fronts", "plot_parallel"]

FITNESS_OBJECTIVES = tuple(name for name, _ in _FITNESS_STYLES)
"""The columns of a front, in order: ``("f_gr", "f_t", "f_sm", "f_sf")`` (the problem's
``FITNESS_NAMES``, named here without importing pymoo)."""

DEFAULT_OBJECTIVES = ("f_t", "f_sm", "f_sf")
"""The objectives drawn unless chosen: f_gr is 1 on every member of a goal-reaching front."""

_MARKERS = ("o", "s", "^", "D", "v", "P", "X", "*", "<", ">")
_BETTER = "(higher is better)"
_SCALES = {
    "f_gr": "1: goal reached, 0: unreachable",
    "f_t": "1 − t/t_max: 0 at t_max, < 0 slower",
    "f_sm": "1: no change of command",
    "f_sf": "1: no obstacle near, < 0 near many",
}
"""What a fitness's values mean: none is bounded to [0, 1] but f_gr and f_sm (f_t = 1 − t/t_max is
negative for a path slower than t_max; f_sf = 1 − Σ D/(l_p λ_sp) is negative beside many obstacles)."""


def _axis_label(name: str) -> str:
    """An objective's axis label: its name, that higher is better, and what its values mean."""
    return f"{name} {_BETTER}\n{_SCALES[name]}"


# --------------------------------------------------------------------------------------------- checks


def _ga_types():
    # Imported when an argument is neither an array nor a list: the solvers pull in pymoo, which a
    # caller plotting plain arrays does not need.
    from htetro_opt.solvers.grid_paths import FrontMember, LegResult, Plan

    return Plan, LegResult, FrontMember


def _is_plain(value) -> bool:
    return isinstance(value, (np.ndarray, list, tuple, numbers.Number))


def _fitness_array(value, name: str, what: str) -> np.ndarray:
    """``value`` as a float array of shape (n, 4), finite."""
    try:
        array = np.asarray(value, dtype=float)
    except (TypeError, ValueError) as err:
        raise ParameterError(f"{name} must be {what}, got {type(value).__name__}") from err
    if array.ndim != 2 or array.shape[1] != len(FITNESS_OBJECTIVES):
        raise ParameterError(f"{name} must be {what}, got an array of shape {array.shape}")
    bad = np.flatnonzero(~np.isfinite(array).all(axis=1))
    if len(bad):
        raise ParameterError(f"{name} holds non-finite fitnesses (row {int(bad[0])})")
    return array


_FRONT = "an array of shape (n, 4) of fitnesses (f_gr, f_t, f_sm, f_sf), a Plan or a LegResult"


def _as_front(value, name: str) -> tuple[np.ndarray, str | None]:
    """One front as an (n, 4) array, and its default label (a Plan's method) or None."""
    if not _is_plain(value):
        Plan, LegResult, _ = _ga_types()
        if isinstance(value, Plan):
            if not value.legs:
                raise ParameterError(f"{name} is a {value.method!r} plan without GA legs: it has no front")
            return _member_fitness(value.legs[-1].front, name), value.method
        if isinstance(value, LegResult):
            return _member_fitness(value.front, name), None
    elif isinstance(value, (list, tuple)) and value and not any(_is_plain(v) for v in value):
        return _member_fitness(value, name), None  # a leg's front: a tuple of FrontMember
    return _fitness_array(value, name, _FRONT), None


def _member_fitness(members, name: str) -> np.ndarray:
    _, _, FrontMember = _ga_types()
    for k, member in enumerate(members):
        if not isinstance(member, FrontMember):
            raise ParameterError(f"{name}[{k}] must be a FrontMember, got {type(member).__name__}")
    fitness = [np.asarray(m.fitness, dtype=float).reshape(-1) for m in members]
    return _fitness_array(np.array(fitness).reshape(-1, len(FITNESS_OBJECTIVES)), name, _FRONT)


def _is_one_front(fronts) -> bool:
    """Whether a list/tuple is one front (rows of numbers, or FrontMembers) rather than several."""
    if not fronts:
        return False
    if all(isinstance(v, numbers.Number) or (isinstance(v, (list, tuple, np.ndarray)) and np.ndim(v) == 1)
           for v in fronts):
        return True
    if any(_is_plain(v) for v in fronts):
        return False
    return all(isinstance(v, _ga_types()[2]) for v in fronts)


def _check_fronts(fronts, labels) -> list[tuple[str, np.ndarray]]:
    """``(label, fitness array)`` per front, in order, checked."""
    if isinstance(fronts, Mapping):
        names = [f"fronts[{key!r}]" for key in fronts]
        given, defaults = list(fronts.values()), [str(key) for key in fronts]
    elif isinstance(fronts, (list, tuple)) and not _is_one_front(fronts):
        names = [f"fronts[{k}]" for k in range(len(fronts))]
        given, defaults = list(fronts), [None] * len(fronts)
    elif isinstance(fronts, (str, bytes)):
        raise ParameterError(f"fronts must be {_FRONT}, or a sequence or mapping of them, "
                             f"got {type(fronts).__name__}")
    else:
        names, given, defaults = ["fronts"], [fronts], [None]
    if not given:
        raise ParameterError("fronts is empty: give at least one front")
    arrays, own = [], []
    for name, value, default in zip(names, given, defaults):
        array, method = _as_front(value, name)
        arrays.append(array)
        own.append(default if default is not None else method)
    if labels is None:
        labels = [label if label is not None else f"front {k + 1}" for k, label in enumerate(own)]
    else:
        if isinstance(labels, (str, bytes)) or not isinstance(labels, Sequence):
            raise ParameterError(f"labels must be a sequence of one label per front ({len(arrays)}), "
                                 f"got {type(labels).__name__}")
        if len(labels) != len(arrays):
            raise ParameterError(f"labels must give one label per front: got {len(labels)} for {len(arrays)}")
        labels = [str(label) for label in labels]
    if not sum(len(a) for a in arrays):
        raise ParameterError("fronts have no members: there is nothing to draw")
    return list(zip(labels, arrays))


def _check_objectives(objectives, name: str = "objectives") -> list[int]:
    """Column indices of at least two distinct objective names."""
    if isinstance(objectives, (str, bytes)) or not isinstance(objectives, Sequence):
        raise ParameterError(f"{name} must be a sequence of objective names from {FITNESS_OBJECTIVES}, "
                             f"got {objectives!r}")
    unknown = [o for o in objectives if o not in FITNESS_OBJECTIVES]
    if unknown:
        raise ParameterError(f"{name} holds unknown objective {unknown[0]!r}: the objectives are "
                             f"{', '.join(FITNESS_OBJECTIVES)}")
    if len(set(objectives)) != len(objectives):
        raise ParameterError(f"{name} names an objective twice: {tuple(objectives)!r}")
    if len(objectives) < 2:
        raise ParameterError(f"{name} must name at least two objectives, got {tuple(objectives)!r}")
    return [FITNESS_OBJECTIVES.index(o) for o in objectives]


def _styles(n: int) -> list[tuple[str, str]]:
    """A colour (matplotlib's colour cycle) and a marker per front."""
    colours = _pyplot().rcParams["axes.prop_cycle"].by_key()["color"]
    return [(colours[k % len(colours)], _MARKERS[k % len(_MARKERS)]) for k in range(n)]


# --------------------------------------------------------------------------------------------- plots


def plot_fronts(fronts, *, labels=None, objectives=DEFAULT_OBJECTIVES, title: str = ""):
    """Pairwise scatter plots of one or several fronts, each in its own colour and marker.

    Parameters
    ----------
    fronts : front, sequence of fronts, or mapping of label to front
        A front is an array of shape (n, 4) of fitnesses (f_gr, f_t, f_sm, f_sf), higher is better
        (pymoo's ``-F``); a :class:`~htetro_opt.solvers.grid_paths.Plan` (its last leg's front), a
        :class:`~htetro_opt.solvers.grid_paths.LegResult` or a tuple of its ``FrontMember`` s.
    labels : sequence of str, optional, keyword-only
        One per front, for the legend. Default: a mapping's keys, a Plan's method, else
        ``"front 1"``, ``"front 2"``, …
    objectives : sequence of str, keyword-only
        At least two of ``"f_gr"``, ``"f_t"``, ``"f_sm"``, ``"f_sf"``, in the order of the panels.
    title : str, keyword-only
        Drawn as given above the panels.

    Returns
    -------
    matplotlib Figure
        A k × k matrix of panels for k objectives (``fig.axes[i * k + j]`` is row i, column j):
        panel (i, j) below the diagonal plots objective ``objectives[j]`` (x) against
        ``objectives[i]`` (y), one scatter per front in the order given; the diagonal holds each
        front's histogram of that objective; the panels above the diagonal are blank, the top-right
        one holding the legend.

    Raises
    ------
    ParameterError
        Naming the argument: a front of the wrong shape or with non-finite values, a Plan without GA
        legs, no member in any front, an unknown or repeated objective, fewer than two objectives,
        labels of the wrong length.

    Examples
    --------
    >>> fig = plot_fronts({"a": [[1, 0.5, 0.9, 0.2], [1, 0.6, 0.4, 0.3]], "b": [[1, 0.2, 0.5, 0.8]]})
    >>> len(fig.axes), fig.axes[3].collections[0].get_offsets().tolist()  # row 1 (f_sm), column 0 (f_t), "a"
    (9, [[0.5, 0.9], [0.6, 0.4]])
    >>> import matplotlib.pyplot as plt; plt.close(fig)
    """
    named = _check_fronts(fronts, labels)
    columns = _check_objectives(objectives)
    plt = _pyplot()
    k = len(columns)
    side = 2.5
    fig, axes = plt.subplots(k, k, figsize=(side * k + 1.0, side * k), layout="constrained", squeeze=False)
    styles = _styles(len(named))
    everything = np.vstack([front for _, front in named])
    for i, row in enumerate(columns):
        for j, col in enumerate(columns):
            ax = axes[i, j]
            if j > i:
                ax.set_axis_off()
                continue
            if j < i:
                for (label, front), (colour, marker) in zip(named, styles):
                    ax.scatter(front[:, col], front[:, row], s=18, alpha=0.7, color=colour, marker=marker,
                               linewidths=0, label=label)
                ax.grid(alpha=0.3)
            else:
                _histograms(ax, named, styles, col, everything[:, col])
            if 0 < j < i:  # a row's scatters share the objective on y
                ax.sharey(axes[i, 0])
                ax.tick_params(labelleft=False)
            if i < k - 1:
                ax.tick_params(labelbottom=False)
            if i == k - 1:
                ax.set_xlabel(_axis_label(FITNESS_OBJECTIVES[col]), fontsize=8)
            if j == 0:
                ax.set_ylabel("members" if i == 0 else _axis_label(FITNESS_OBJECTIVES[row]), fontsize=8)
    for j in range(k - 1):  # a column's panels share the objective on x
        for i in range(j + 1, k):
            axes[i, j].sharex(axes[j, j])
    handles = [_marker_handle(label, marker=marker, color=colour, markersize=6)
               for (label, _), (colour, marker) in zip(named, styles)]
    legend_ax = axes[0, k - 1]
    legend_ax.legend(handles=handles, loc="upper right", fontsize=8, frameon=False,
                     title="front" if len(named) == 1 else "fronts", title_fontsize=8)
    if title:
        fig.suptitle(title, fontsize=10)
    return fig


def _histograms(ax, named, styles, col: int, values: np.ndarray) -> None:
    """Each front's distribution of one objective, on bins shared by all fronts."""
    low, high = float(values.min()), float(values.max())
    bins = np.linspace(low, high, 16) if high > low else np.array([low - 0.5, low + 0.5])
    for (label, front), (colour, _) in zip(named, styles):
        if len(front):
            ax.hist(front[:, col], bins=bins, histtype="step", color=colour, linewidth=1.3, label=label)
    ax.set_yticks([])
    ax.set_title(FITNESS_OBJECTIVES[col], fontsize=9)


def plot_parallel(fronts, *, labels=None, objectives=DEFAULT_OBJECTIVES, title: str = ""):
    """Parallel coordinates of one or several fronts: a polyline per member, a colour per front.

    Every axis is scaled to [0, 1] from the lowest to the highest value of its objective over all
    the fronts shown, ``(value - min) / (max - min)``, and the real minimum and maximum are written
    under and above it. An objective with a single value over all fronts is drawn at 0.5.

    Parameters
    ----------
    fronts, labels, objectives, title
        As for :func:`plot_fronts`; ``objectives`` are the axes, left to right.

    Returns
    -------
    matplotlib Figure
        One axes: one :class:`~matplotlib.collections.LineCollection` per front (in the order
        given, labelled with the front's label; a segment list per member, x the objective's
        position 0, 1, …), a vertical line per objective from 0 to 1, and the texts with gid ``"min f_t"``,
        ``"max f_t"``, … giving the real range of each axis.

    Raises
    ------
    ParameterError
        As :func:`plot_fronts`.

    Examples
    --------
    >>> fig = plot_parallel([[[1, 0.5, 0.9, 0.2], [1, 0.6, 0.4, 0.3]]], objectives=("f_t", "f_sf"))
    >>> fig.axes[0].collections[0].get_segments()[1].tolist()  # the second member is highest on both
    [[0.0, 1.0], [1.0, 1.0]]
    >>> import matplotlib.pyplot as plt; plt.close(fig)
    """
    named = _check_fronts(fronts, labels)
    columns = _check_objectives(objectives)
    from matplotlib.collections import LineCollection

    plt = _pyplot()
    k = len(columns)
    everything = np.vstack([front[:, columns] for _, front in named])
    low, high = everything.min(axis=0), everything.max(axis=0)
    span = high - low
    fig, ax = plt.subplots(figsize=(1.8 * k + 4.0, 4.6), layout="constrained")
    positions = np.arange(k, dtype=float)
    styles = _styles(len(named))
    handles = []
    for (label, front), (colour, _) in zip(named, styles):
        values = front[:, columns]
        scaled = np.divide(values - low, span, out=np.full_like(values, 0.5), where=span > 0)
        segments = np.stack([np.broadcast_to(positions, scaled.shape), scaled], axis=-1)
        ax.add_collection(LineCollection(segments, colors=colour, alpha=0.45, linewidths=1.0, label=label))
        handles.append(_marker_handle(label, linestyle="-", color=colour, linewidth=1.5))
    for x, col, lo, hi in zip(positions, columns, low, high):
        name = FITNESS_OBJECTIVES[col]
        ax.plot([x, x], [0.0, 1.0], color="black", linewidth=0.8, zorder=0)
        ax.text(x, -0.03, f"{lo:.3g}", ha="center", va="top", fontsize=8, gid=f"min {name}")
        ax.text(x, 1.03, f"{hi:.3g}", ha="center", va="bottom", fontsize=8, gid=f"max {name}")
    ax.set_xlim(-0.25, k - 0.75)
    ax.set_ylim(-0.12, 1.12)
    ax.set_xticks(positions, [FITNESS_OBJECTIVES[c] for c in columns])
    ax.tick_params(axis="x", length=0)
    ax.set_yticks([])
    ax.set_ylabel(f"each axis from its minimum to its maximum\n{_BETTER}")
    for spine in ax.spines.values():
        spine.set_visible(False)
    _legend(ax, handles)
    if title:
        ax.set_title(title, fontsize=10)
    return fig


def _check_histories(history_or_plan) -> list[tuple[np.ndarray, int | None]]:
    """(history, first-reach generation or None) per leg."""
    name = "history_or_plan"
    what = "a Plan or LegResult of a GA, a sequence of LegResults, or an array of shape (generations, 4)"
    if not _is_plain(history_or_plan) or (isinstance(history_or_plan, (list, tuple)) and history_or_plan
                                          and not any(_is_plain(v) for v in history_or_plan)):
        Plan, LegResult, _ = _ga_types()
        if isinstance(history_or_plan, Plan):
            if not history_or_plan.legs:
                raise ParameterError(f"{name} is a {history_or_plan.method!r} plan without GA legs: "
                                     f"it has no convergence history")
            legs = history_or_plan.legs
        elif isinstance(history_or_plan, LegResult):
            legs = [history_or_plan]
        elif isinstance(history_or_plan, (list, tuple)):
            legs = history_or_plan
            for k, leg in enumerate(legs):
                if not isinstance(leg, LegResult):
                    raise ParameterError(f"{name}[{k}] must be a LegResult, got {type(leg).__name__}")
        else:
            raise ParameterError(f"{name} must be {what}, got {type(history_or_plan).__name__}")
        out = [(_fitness_array(np.asarray(leg.history).reshape(-1, 4), f"{name}'s leg {k} history", what),
                leg.reach_generation) for k, leg in enumerate(legs)]
    else:
        out = [(_fitness_array(history_or_plan, name, what), None)]
    if not sum(len(h) for h, _ in out):
        raise ParameterError(f"{name} has no generation: there is nothing to draw")
    return out


def plot_convergence(history_or_plan, *, title: str = ""):
    """The four fitnesses of a GA's multi-objective solution, generation by generation.

    The legs of a multi-leg plan follow one another on the generation axis (the first leg's
    generations are 1, 2, …), with a dashed grey line between legs; where a leg's record says when
    the goal was first reached, a red dotted line marks that generation.

    Parameters
    ----------
    history_or_plan : Plan, LegResult, sequence of LegResult, or array of shape (generations, 4)
        A GA's record (``plan.legs[k].history``: per generation, the multi-objective solution's
        f_gr, f_t, f_sm, f_sf), or such an array.
    title : str, keyword-only
        Drawn as given.

    Returns
    -------
    matplotlib Figure
        One axes with one line per fitness (labelled f_gr, f_t, f_sm, f_sf; between legs its values
        are NaN, so legs are not joined), the lines with gid ``"leg separator"`` and
        ``"goal first reached"``.

    Raises
    ------
    ParameterError
        If ``history_or_plan`` is none of those (or a plan of a graph search, without GA legs), or
        has no generation.

    Examples
    --------
    >>> fig = plot_convergence([[0.0, 0.1, 0.2, 0.3], [1.0, 0.4, 0.5, 0.6]])
    >>> [(line.get_label(), line.get_ydata().tolist()) for line in fig.axes[0].lines][:2]
    [('f_gr', [0.0, 1.0]), ('f_t', [0.1, 0.4])]
    >>> import matplotlib.pyplot as plt; plt.close(fig)
    """
    legs = _check_histories(history_or_plan)
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(7.5, 4.2), layout="constrained")
    _draw_convergence(ax, legs)
    if title:
        ax.set_title(title, fontsize=10)
    return fig


def _draw_convergence(ax, legs) -> None:
    """One line per fitness over all legs (NaN between legs), leg separators and first-reach marks."""
    pieces, gens, start = [], [], 1
    for j, (history, reach) in enumerate(legs):
        if j:
            ax.axvline(start - 0.5, color="#888888", linestyle="--", linewidth=0.8, gid="leg separator",
                       label="next leg" if j == 1 else None)
            pieces.append(np.full((1, 4), np.nan))
            gens.append([start - 0.5])
        if reach is not None:
            ax.axvline(start + reach - 1, color="red", linestyle=":", linewidth=1.0, gid="goal first reached",
                       label="goal first reached" if all(r is None for _, r in legs[:j]) else None)
        pieces.append(history)
        gens.append(np.arange(start, start + len(history)))
        start += len(history)
    values, gens = np.vstack(pieces), np.concatenate(gens)
    for i, (name, colour) in enumerate(_FITNESS_STYLES):
        ax.plot(gens, values[:, i], color=colour, linewidth=1.4, label=name, gid=name, zorder=3)
    if np.nanmin(values) < 0:  # f_t (slower than t_max) or f_sf (beside many obstacles) below 0
        ax.axhline(0.0, color="#555555", linewidth=0.8, zorder=2, gid="zero")
    from matplotlib.ticker import MaxNLocator

    ax.xaxis.set_major_locator(MaxNLocator(integer=True))  # generations are whole
    ax.set_xlabel("generation" + (" (legs one after another)" if len(legs) > 1 else ""))
    ax.set_ylabel(f"fitness {_BETTER}\nf_t = 1 − t/t_max: 0 at t_max, < 0 slower;\n"
                  "f_sf < 0 near many obstacles; f_gr, f_sm in [0, 1]", fontsize=8)
    ax.grid(alpha=0.3)
    handles, labels = ax.get_legend_handles_labels()
    order = sorted(range(len(labels)), key=lambda n: labels[n] not in FITNESS_OBJECTIVES)  # fitnesses first
    ax.legend([handles[n] for n in order], [labels[n] for n in order], fontsize=8, loc="lower right")
