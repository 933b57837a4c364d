"""Plots of seed 003's tilesets, waypoint orders (Figs. 13–14) and coverage heat maps (Fig. 18).

matplotlib is imported only inside the functions; nothing here computes a plan or a simulation.
"""

from __future__ import annotations

import numpy as np

from htetro_opt.errors import HtetroError, ParameterError
from htetro_opt.scenarios.tileset import BLOCK_LETTERS, Tileset
from htetro_opt.viz.plot import SHAPE_COLOURS, _pyplot

__all__ = ["plot_tileset", "plot_coverage"]

_OBSTACLE_COLOUR = "#333333"
_UNKNOWN_COLOUR = "#bbbbbb"


def _figure(ax, width: int, height: int, extra: float = 1.6):
    plt = _pyplot()
    if ax is not None:
        return ax.figure, ax
    side = min(9.0, max(4.0, 0.55 * max(width, height)))
    aspect = height / width
    fig, ax = plt.subplots(figsize=(side + extra, max(2.5, side * aspect) + 0.7), constrained_layout=True)
    return fig, ax


def _frame(ax, width: int, height: int, title: str) -> None:
    ax.set_xlim(-0.5, width - 0.5)
    ax.set_ylim(-0.5, height - 0.5)
    ax.set_aspect("equal")
    if width <= 40:
        ax.set_xticks(range(width))
    if height <= 40:
        ax.set_yticks(range(height))
    ax.tick_params(labelsize=7)
    ax.set_xlabel("x (cells)")
    ax.set_ylabel("y (cells)")
    if title:
        ax.set_title(title, fontsize=10)


def plot_tileset(tileset: Tileset, order=None, *, title: str = "", ax=None):
    """Draw a labelled tileset and, optionally, a visiting order (seed 003's Figs. 13–14).

    Tiles are filled with their morphology's colour (:data:`SHAPE_COLOURS`), each cell shows its
    labels (``12b``), tile borders are drawn thick and obstacles dark. With an order, arrows join
    consecutive tiles' block-b cells and each block b carries its visit number (the start circled in
    green).

    Parameters
    ----------
    tileset : Tileset
    order : sequence of int, optional
        Tile labels (ids, not indices) in visiting order.
    title : str, keyword-only
    ax : matplotlib Axes, optional, keyword-only

    Returns
    -------
    matplotlib Figure

    Raises
    ------
    ParameterError
        If ``order`` names a tile the tileset does not have.

    Examples
    --------
    >>> from htetro_opt.scenarios import parse_tileset
    >>> fig = plot_tileset(parse_tileset("1a 1b 1c 1d\\n2a 2b 2c 2d"), [1, 2])
    >>> len(fig.axes)
    1
    >>> import matplotlib.pyplot as plt; plt.close(fig)
    """
    if not isinstance(tileset, Tileset):
        raise ParameterError(f"tileset must be a Tileset, got {type(tileset).__name__}")
    visits = None
    if order is not None:
        try:
            visits = [tileset.index(t) for t in order]
        except (HtetroError, TypeError, ValueError) as err:
            raise ParameterError(f"order: {err}") from err
    from matplotlib.collections import LineCollection, PatchCollection
    from matplotlib.colors import to_rgba
    from matplotlib.patches import Patch, Rectangle

    w, h = tileset.width, tileset.height
    fig, ax = _figure(ax, w, h, extra=2.1)
    font = max(4.0, min(9.0, 70.0 / max(w, h)))
    squares, colours = [], []
    for y, x in zip(*np.nonzero(tileset.occupancy)):
        squares.append(Rectangle((x - 0.5, y - 0.5), 1, 1))
        colours.append(to_rgba(_OBSTACLE_COLOUR))
    labels: dict[tuple[int, int], list[str]] = {}
    shapes = tileset.shapes
    used = []
    for i, (tile, cells) in enumerate(zip(tileset.ids, tileset.blocks)):
        colour = to_rgba(SHAPE_COLOURS.get(shapes[i], _UNKNOWN_COLOUR), 0.35)
        if shapes[i] not in used:
            used.append(shapes[i])
        for letter, (x, y) in zip(BLOCK_LETTERS, cells.tolist()):
            squares.append(Rectangle((x - 0.5, y - 0.5), 1, 1))
            colours.append(colour)
            labels.setdefault((x, y), []).append(f"{tile}{letter}")
    if squares:
        ax.add_collection(PatchCollection(squares, facecolors=colours, linewidths=0))
    # thin grid, then thick borders wherever a tile's cell meets a cell of another tile (or none)
    thin = [[(x - 0.5, -0.5), (x - 0.5, h - 0.5)] for x in range(w + 1)]
    thin += [[(-0.5, y - 0.5), (w - 0.5, y - 0.5)] for y in range(h + 1)]
    ax.add_collection(LineCollection(thin, colors="#cccccc", linewidths=0.5))
    thick = []
    for i, cells in enumerate(tileset.blocks):
        mine = {tuple(c) for c in cells.tolist()}
        for x, y in mine:
            for dx, dy in ((1, 0), (-1, 0), (0, 1), (0, -1)):
                if (x + dx, y + dy) in mine:
                    continue
                if dx:
                    ex = x + dx / 2
                    thick.append([(ex, y - 0.5), (ex, y + 0.5)])
                else:
                    ey = y + dy / 2
                    thick.append([(x - 0.5, ey), (x + 0.5, ey)])
    if thick:
        ax.add_collection(LineCollection(thick, colors="black", linewidths=1.8))
    for (x, y), names in labels.items():
        text = "/".join(names)
        ax.text(x, y + (0.22 if visits is not None else 0.0), text, ha="center", va="center",
                fontsize=font * (0.8 if len(names) > 1 else 1.0), color="#222222", in_layout=False)
    if visits:
        refs = tileset.blocks[visits, 1].astype(float)
        for k in range(len(refs) - 1):
            ax.annotate("", xy=refs[k + 1], xytext=refs[k], annotation_clip=False, in_layout=False,
                        arrowprops={"arrowstyle": "-|>", "color": "#c0392b", "linewidth": 1.3,
                                    "shrinkA": 5, "shrinkB": 5, "mutation_scale": 9})
        for k, (x, y) in enumerate(refs):
            edge = "green" if k == 0 else "#c0392b"
            ax.text(x, y - 0.18, str(k + 1), ha="center", va="center", fontsize=font * 0.9, color="white", in_layout=False,
                    fontweight="bold", bbox={"boxstyle": "circle,pad=0.15", "facecolor": edge, "edgecolor": "none"})
    handles = [Patch(facecolor=SHAPE_COLOURS.get(s, _UNKNOWN_COLOUR), alpha=0.5, label=f"{s}-shape") for s in used]
    if tileset.occupancy.any():
        handles.append(Patch(facecolor=_OBSTACLE_COLOUR, label="obstacle"))
    if visits:
        handles.append(Patch(facecolor="green", label="start (visit 1)"))
    if handles:
        ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8, frameon=False)
    _frame(ax, w, h, title or tileset.name)
    return fig


def plot_coverage(result, *, title: str = "", ax=None):
    """Draw a coverage heat map (seed 003's Fig. 18): pixel time scaled to 0…255, green to red.

    Parameters
    ----------
    result : CoverageResult
        From :func:`~htetro_opt.studies.coverage.simulate_coverage`.
    title : str, keyword-only
        Above the map; a line with the average grid time and the distance is added below it.
    ax : matplotlib Axes, optional, keyword-only

    Returns
    -------
    matplotlib Figure
        Pixels never covered are left white; cells that are not free are hatched dark.

    Examples
    --------
    >>> from htetro_opt.scenarios import parse_tileset
    >>> from htetro_opt.studies.coverage import simulate_coverage
    >>> fig = plot_coverage(simulate_coverage(parse_tileset("1a 1b 1c 1d\\n2a 2b 2c 2d"), [0, 1]))
    >>> len(fig.axes)  # the map and its colour bar
    2
    >>> import matplotlib.pyplot as plt; plt.close(fig)
    """
    for attribute in ("heat", "free", "cell_time", "average_grid_time", "distance", "mean_block_distance"):
        if not hasattr(result, attribute):
            raise ParameterError(f"result must be a CoverageResult, got {type(result).__name__}")
    plt = _pyplot()
    from matplotlib.patches import Rectangle

    h, w = result.cell_time.shape
    fig, ax = _figure(ax, w, h, extra=1.2)
    heat = np.ma.masked_where(result.pixel_time <= 0, result.heat)
    cmap = plt.get_cmap("RdYlGn_r").with_extremes(bad="white")
    image = ax.imshow(heat, cmap=cmap, vmin=0, vmax=255, origin="lower", interpolation="nearest",
                      extent=(-0.5, w - 0.5, -0.5, h - 0.5))
    bar = fig.colorbar(image, ax=ax, shrink=0.85)
    bar.set_label("coverage time, normalised (0–255)", fontsize=8)
    for y, x in zip(*np.nonzero(~result.free)):
        ax.add_patch(Rectangle((x - 0.5, y - 0.5), 1, 1, facecolor=_OBSTACLE_COLOUR, alpha=0.55,
                               edgecolor="black", hatch="xx", linewidth=0.5))
    if w <= 64 and h <= 64:
        ax.set_xticks(np.arange(-0.5, w, 1), minor=True)
        ax.set_yticks(np.arange(-0.5, h, 1), minor=True)
        ax.grid(which="minor", color="#888888", linewidth=0.3)
        ax.tick_params(which="minor", length=0)
    per_block = f"{result.mean_block_distance:.1f} cells"
    if result.distance_m is not None:
        per_block += f" = {result.distance_m / 4:.2f} m"
    summary = (f"avg grid time {result.average_grid_time:.3f} s; travel: 4 blocks {result.distance:.1f} cells, "
               f"per block {per_block}")
    _frame(ax, w, h, f"{title}\n{summary}" if title else summary)
    return fig
