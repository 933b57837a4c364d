"""What the plot modules share that is style: the lazy pyplot import, colours, legend entries, the
colour bar and the cell grid.

Every module of :mod:`htetro_opt.viz` takes these from here, and this module imports none of them,
so no two viz modules import each other in a circle. matplotlib is imported only inside the
functions: importing this module (or :mod:`htetro_opt.viz`) does not import it.
"""

from __future__ import annotations

import numpy as np

from htetro_opt.model.robot import N_NAMED, SHAPES

SHAPE_COLOURS = {
    "I": "#1f77b4", "O": "#ff7f0e", "L": "#2ca02c", "J": "#d62728",
    "Z": "#9467bd", "S": "#8c564b", "T": "#e377c2",
}
"""The colour of each of the seven shapes (footprints, outlines, tiles)."""

_INTERMEDIATE_COLOUR = "#7f7f7f"  # every state between two named shapes
_OBSTACLE_CMAP, _OBSTACLE_VMAX = "Greys", 1.4  # an occupancy image: free cells white, obstacles a mid grey
_OBSTACLE_VALUE = 1 / _OBSTACLE_VMAX  # where the occupancy's colormap puts an obstacle
_MOVING_COLOUR = "#1b4f72"
_ROADMAP_COLOURS = {"start": "green", "intermediate roadmap pose": "blue", "goal": "red"}

_FITNESS_STYLES = (("f_gr", "black"), ("f_t", "#1f77b4"), ("f_sm", "#2ca02c"), ("f_sf", "#9467bd"))
"""(name, colour) of the GA's four fitnesses, in the order of a front's columns."""


def _pyplot():
    # The backend is the caller's choice (a notebook's inline one, a desktop's window); the command
    # line picks Agg itself. Forcing Agg here would stop a notebook from showing the figures.
    import matplotlib.pyplot as plt

    return plt


def _colour(state: int) -> str:
    """The colour of a robot state: its shape's, or the intermediate grey."""
    return SHAPE_COLOURS[SHAPES[state]] if state < N_NAMED else _INTERMEDIATE_COLOUR


def _obstacle_colour() -> tuple:
    """The RGBA colour of an obstacle cell in :func:`_draw_occupancy`'s image (for legends)."""
    from matplotlib import colormaps

    return colormaps[_OBSTACLE_CMAP](_OBSTACLE_VALUE)


def _draw_occupancy(ax, occupancy: np.ndarray):
    """A grid map's obstacles as one image under everything else, cell (x, y) centred on (x, y)."""
    h, w = occupancy.shape
    return ax.imshow(occupancy, cmap=_OBSTACLE_CMAP, vmin=0, vmax=_OBSTACLE_VMAX, origin="lower",
                     extent=(-0.5, w - 0.5, -0.5, h - 0.5), interpolation="nearest", zorder=0)


def _marker_handle(label: str, **style):
    """A legend entry: a line (``linestyle="-"``) or, by default, a marker alone."""
    from matplotlib.lines import Line2D

    return Line2D([], [], linestyle=style.pop("linestyle", "none"), label=label, **style)


def _legend(ax, handles, *, x: float = 1.01) -> None:
    """The legend outside the axes, its top-left corner at (``x``, 1) in axes coordinates (just
    right of the top-right corner); none without handles."""
    if handles:
        ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(x, 1.0), fontsize=8, frameon=False)


def _colour_bar(ax, mappable, label: str, *, shrink: float = 1.0, pad: float | None = None,
                fontsize: float | None = None):
    """A colour bar for ``mappable`` beside ``ax`` (taking its room from ``ax``), labelled.

    ``shrink`` is the bar's share of the axes' height; ``pad`` the gap to the axes as a share of
    its width (matplotlib's default when None); ``fontsize`` the label's (the axes labels' when
    None). Returns the :class:`~matplotlib.colorbar.Colorbar`.
    """
    bar = ax.figure.colorbar(mappable, ax=ax, shrink=shrink, **({} if pad is None else {"pad": pad}))
    bar.set_label(label, **({} if fontsize is None else {"fontsize": fontsize}))
    return bar


def _cell_grid(ax, width: int, height: int, *, colour: str, linewidth: float) -> None:
    """Thin lines between the cells of a ``width`` × ``height`` map drawn with cell centres at
    integers (minor ticks at the half-integers, without tick marks)."""
    ax.set_xticks(np.arange(-0.5, width, 1), minor=True)
    ax.set_yticks(np.arange(-0.5, height, 1), minor=True)
    ax.grid(which="minor", color=colour, linewidth=linewidth)
    ax.tick_params(which="minor", length=0)
