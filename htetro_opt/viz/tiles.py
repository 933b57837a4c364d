"""Plots of Le et al. 2018's tilesets, waypoint orders (Figs. 13–14) and coverage heat maps (Fig. 18).

matplotlib is imported only inside the functions; nothing here computes a plan or a simulation.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from htetro_opt.errors import HtetroError, ParameterError
from htetro_opt.scenarios.tileset import BLOCK_LETTERS, Tileset
from htetro_opt.viz._style import SHAPE_COLOURS, _cell_grid, _colour_bar, _legend, _pyplot
from htetro_opt.viz.plot import DENSE_CELL_PT, _cell_points, _mixed_image, _outline_segments, _shape_counts, _squares

__all__ = ["plot_tileset", "plot_coverage"]

_OBSTACLE_COLOUR = "#333333"
_UNKNOWN_COLOUR = "#bbbbbb"
_ORDER_COLOUR = "#c0392b"
_ORDER_ALPHA = 0.7  # the order is not a driven path: lighter than what is on the map
_CHAR_WIDTH = 0.6  # a digit's width in DejaVu Sans, as a share of the font size
_MIN_FONT = 5.0  # pt: smaller labels are noise, not information
_MOST_VISIT_NUMBERS = 40


def _figure(ax, width: int, height: int, extra: float = 1.6):
    plt = _pyplot()
    if ax is not None:
        return ax.figure, ax
    side = min(9.0, max(4.0, 0.55 * max(width, height)))
    aspect = height / width
    fig, ax = plt.subplots(figsize=(side + extra, max(2.5, side * aspect) + 0.7), layout="compressed")
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


def _label_font(cell_pt: float, chars: int) -> float:
    """The font size (pt) at which ``chars`` characters fill 90 % of a cell's width, at most 9."""
    return min(9.0, 0.9 * cell_pt / (_CHAR_WIDTH * max(chars, 1)))


def _visit_step(n: int, most: int = _MOST_VISIT_NUMBERS) -> int:
    """The smallest of 1, 2, 5, 10, 20, 50, … that numbers at most ``most`` of ``n`` visits."""
    step, scale = 1, 1
    while n / step > most:
        for factor in (2, 5, 10):
            step = factor * scale
            if n / step <= most:
                break
        scale *= 10
    return step


def plot_tileset(tileset: Tileset, order=None, *, title: str = "", ax=None):
    """Draw a labelled tileset and, optionally, a visiting order (Le et al. 2018, Figs. 13–14).

    Tiles are filled with their morphology's colour (:data:`SHAPE_COLOURS`; one image, darker where
    tiles overlap), tile borders are drawn thick and obstacles dark. With an order, dashed straight
    segments join consecutive tiles' block-b cells (B2, the robot's reference) and carry visit numbers
    (the start in green). A segment is the order between two tiles as the sequencing cost (eq. 2)
    prices it, a straight displacement: not the path the robot drives, which a sequence does not
    plan, so it is drawn dashed and lighter, and the legend says so (it may cross an obstacle).

    How much is written depends on how large a cell is on the figure, so that a large tileset stays
    readable: each cell carries its labels (``12b``: block b of tile 12) only when the longest label
    fits in a cell at 5 pt or more (on a 9-inch figure, up to about 40 × 40 cells); each visit gets
    a circled number and a dashed arrow to the next one when its number fits likewise, otherwise the
    order is a dashed line through the block-b cells with a number at visits 1, k, 2k, … and the last, k being the
    smallest of 1, 2, 5, 10, 20, 50, … that writes at most 40 numbers. The 64 × 64 tiling (1004
    tiles) thus gets tile colours, borders, the path and 22 numbers, and draws and saves in about half a second.

    Parameters
    ----------
    tileset : Tileset
    order : sequence of int, optional
        Tile labels (ids, not indices) in visiting order.
    title : str, keyword-only
        Drawn as given; by default the tileset's name without its folder.
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
    >>> sorted(t.get_text() for t in fig.axes[0].texts)
    ['1', '1a', '1b', '1c', '1d', '2', '2a', '2b', '2c', '2d']
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
    from matplotlib.collections import LineCollection
    from matplotlib.colors import ListedColormap
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    w, h = tileset.width, tileset.height
    fig, ax = _figure(ax, w, h, extra=3.2)
    cell_pt = _cell_points(ax, w, h)
    shapes = tileset.shapes
    used = list(dict.fromkeys(shapes))
    colours = [SHAPE_COLOURS.get(s, _UNKNOWN_COLOUR) for s in used]
    if len(tileset):
        counts = _shape_counts(tileset.blocks, np.array([used.index(s) for s in shapes]), len(used), h, w)
        ax.imshow(_mixed_image(counts, colours, 0.35, cap=1.0), origin="lower", interpolation="nearest",
                  extent=(-0.5, w - 0.5, -0.5, h - 0.5), zorder=1, gid="tiles")
    obstacles = np.ma.masked_where(~tileset.occupancy, tileset.occupancy.astype(float))
    ax.imshow(obstacles, cmap=ListedColormap([_OBSTACLE_COLOUR]), origin="lower", interpolation="nearest",
              extent=(-0.5, w - 0.5, -0.5, h - 0.5), zorder=1, gid="obstacles")
    thin = [[(x - 0.5, -0.5), (x - 0.5, h - 0.5)] for x in range(w + 1)]
    thin += [[(-0.5, y - 0.5), (w - 0.5, y - 0.5)] for y in range(h + 1)]
    ax.add_collection(LineCollection(thin, colors="#cccccc", linewidths=0.5, zorder=1.5))
    border = 1.8 if cell_pt >= DENSE_CELL_PT else 0.9
    if len(tileset):
        segments, _ = _outline_segments(tileset.blocks)
        ax.add_collection(LineCollection(segments, colors="black", linewidths=border, zorder=2))

    handles = [Patch(facecolor=c, alpha=0.5, label=f"{s}-shape tile") for s, c in zip(used, colours)]
    handles.append(Line2D([], [], color="black", linewidth=border, label="tile border"))
    if tileset.occupancy.any():
        handles.append(Patch(facecolor=_OBSTACLE_COLOUR, label="obstacle"))
    longest = max((len(str(i)) + 1 for i in tileset.ids), default=2)
    font = _label_font(cell_pt, longest)
    labelled = len(tileset) > 0 and font >= _MIN_FONT
    if labelled:
        _draw_cell_labels(ax, tileset, font, shifted=visits is not None)
        handles.append(Patch(facecolor="none", edgecolor="none",
                             label=f"{tileset.ids[0]}b: block b of tile {tileset.ids[0]}"))
    if visits:
        handles += _draw_order(ax, tileset.blocks[visits, 1], cell_pt)
    if labelled or visits:
        handles.append(Patch(facecolor="none", edgecolor="none", label="a–d: blocks B1–B4 (b = B2, the reference)"))
    _legend(ax, handles)
    _frame(ax, w, h, title or Path(tileset.name).name)
    return fig


def _draw_cell_labels(ax, tileset: Tileset, font: float, *, shifted: bool) -> None:
    labels: dict[tuple[int, int], list[str]] = {}
    for tile, cells in zip(tileset.ids, tileset.blocks.tolist()):
        for letter, (x, y) in zip(BLOCK_LETTERS, cells):
            labels.setdefault((x, y), []).append(f"{tile}{letter}")
    for (x, y), names in labels.items():
        ax.text(x, y + (0.22 if shifted else 0.0), "/".join(names), ha="center", va="center",
                fontsize=font * (0.8 if len(names) > 1 else 1.0), color="#222222", in_layout=False, zorder=3)


def _draw_order(ax, refs: np.ndarray, cell_pt: float) -> list:
    """The visiting order through block-b cells ``refs`` (n, 2): dashed arrows and every number when
    they fit in a cell, else a dashed line and every k-th number. Returns the legend handles.

    A segment is the order from one tile to the next as the eq.-2 cost prices it, a straight line
    between block-b cells: not the path the robot drives (which a sequence does not plan), so it is
    drawn dashed and lighter, and may cross an obstacle."""
    from matplotlib.collections import LineCollection, PolyCollection
    from matplotlib.lines import Line2D

    refs = refs.astype(float)
    n = len(refs)
    font = _label_font(cell_pt, len(str(n)) + 1)
    every = font >= _MIN_FONT
    step = 1 if every else _visit_step(n)
    dashes = (0, (4, 2.5))
    if every:
        tail, head = refs[:-1], refs[1:]
        gap = head - tail
        length = np.hypot(gap[:, 0], gap[:, 1])
        keep = length > 0.6
        unit = gap[keep] / length[keep, None]
        normal = unit[:, ::-1] * (-1, 1)
        tip = head[keep] - 0.3 * unit
        base = tip - 0.28 * unit
        segments = np.stack([tail[keep] + 0.3 * unit, base], axis=1)
        ax.add_collection(LineCollection(segments, colors=_ORDER_COLOUR, linewidths=1.2, linestyles=[dashes],
                                         alpha=_ORDER_ALPHA, zorder=4, gid="order"))
        heads = np.stack([tip, base + 0.12 * normal, base - 0.12 * normal], axis=1)
        ax.add_collection(PolyCollection(heads, facecolors=_ORDER_COLOUR, edgecolors="none", alpha=_ORDER_ALPHA,
                                         zorder=4, gid="order heads"))
        numbered = np.arange(n)
    else:
        ax.plot(refs[:, 0], refs[:, 1], color=_ORDER_COLOUR, linewidth=0.9, linestyle=dashes, alpha=_ORDER_ALPHA,
                marker=".", markersize=2, zorder=4, gid="order")
        numbered = np.unique(np.r_[0, np.arange(step - 1, n, step), n - 1])
        font = max(_MIN_FONT, min(8.0, font * 1.6))
    label = ("visiting order, block b to block b" + ("" if every else " (dots)")
             + ":\n  the order between tiles (straight, as the cost\n  prices it), not the driven path")
    for k in numbered.tolist():
        x, y = refs[k]
        ax.text(x, y - (0.18 if every else 0.0), str(k + 1), ha="center", va="center", fontsize=font * 0.9,
                color="white", fontweight="bold", in_layout=False, zorder=5,
                bbox={"boxstyle": "circle,pad=0.15", "facecolor": "green" if k == 0 else _ORDER_COLOUR,
                      "edgecolor": "none"})
    handles = [Line2D([], [], color=_ORDER_COLOUR, linewidth=1.3, linestyle=dashes, alpha=_ORDER_ALPHA,
                      marker=">" if every else ".", label=label),
               Line2D([], [], linestyle="none", marker="o", markersize=8, color=_ORDER_COLOUR,
                      label="visit number" if every else f"visit number (1, {step}, {2 * step}, …, {n})")]
    handles.append(Line2D([], [], linestyle="none", marker="o", markersize=8, color="green", label="start (visit 1)"))
    return handles


def plot_coverage(result, *, title: str = "", ax=None, time_unit: str = "s"):
    """Draw a coverage heat map (Le et al. 2018, Fig. 18): pixel time scaled to 0…255, green to red.

    Parameters
    ----------
    result : CoverageResult
        From :func:`~htetro_opt.model.coverage.simulate_coverage`.
    title : str, keyword-only
        Above the map; a line with the average grid time and the distance is added below it.
    ax : matplotlib Axes, optional, keyword-only
    time_unit : str, keyword-only
        The unit of the result's times, written after the average grid time: seconds for
        :func:`~htetro_opt.model.coverage.simulate_coverage`'s runs, ``"command units"`` for a
        coverage plan's (:func:`~htetro_opt.model.coverage.simulate_command_coverage`).

    Returns
    -------
    matplotlib Figure
        Pixels never covered are left white; cells that are not free are hatched dark.

    Examples
    --------
    >>> from htetro_opt.scenarios import parse_tileset
    >>> from htetro_opt.model.coverage import simulate_coverage
    >>> fig = plot_coverage(simulate_coverage(parse_tileset("1a 1b 1c 1d\\n2a 2b 2c 2d"), [0, 1]))
    >>> len(fig.axes)  # the map and its colour bar
    2
    >>> import matplotlib.pyplot as plt; plt.close(fig)
    """
    for attribute in ("heat", "free", "cell_time", "average_grid_time", "distance", "mean_block_distance"):
        if not hasattr(result, attribute):
            raise ParameterError(f"result must be a CoverageResult, got {type(result).__name__}")
    if not isinstance(time_unit, str) or not time_unit:
        raise ParameterError(f"time_unit must be a non-empty string, got {time_unit!r}")
    plt = _pyplot()
    from matplotlib.collections import PolyCollection
    from matplotlib.patches import Patch

    h, w = result.cell_time.shape
    fig, ax = _figure(ax, w, h, extra=1.2)
    heat = np.ma.masked_where(result.pixel_time <= 0, result.heat)
    cmap = plt.get_cmap("RdYlGn_r").with_extremes(bad="white")
    image = ax.imshow(heat, cmap=cmap, vmin=0, vmax=255, origin="lower", interpolation="nearest",
                      extent=(-0.5, w - 0.5, -0.5, h - 0.5))
    _colour_bar(ax, image, "coverage time, normalised (0–255)", shrink=0.85, fontsize=8)
    blocked = np.argwhere(~result.free)[:, ::-1]
    handles = [Patch(facecolor="white", edgecolor="#888888", label="never covered")]
    if len(blocked):
        ax.add_collection(PolyCollection(_squares(blocked), facecolors=_OBSTACLE_COLOUR, alpha=0.55,
                                         edgecolors="black", hatch="xx", linewidths=0.5))
        handles.append(Patch(facecolor=_OBSTACLE_COLOUR, alpha=0.55, edgecolor="black", hatch="xx",
                             label="not free (obstacle)"))
    ax.legend(handles=handles, loc="upper center", bbox_to_anchor=(0.5, -0.09), ncols=len(handles), fontsize=8,
              frameon=False)
    if w <= 64 and h <= 64:
        _cell_grid(ax, w, h, colour="#888888", linewidth=0.3)
    per_block = f"{result.mean_block_distance:.1f} cells"
    if result.distance_m is not None:
        per_block += f" = {result.distance_m / 4:.2f} m"
    summary = (f"avg grid time {result.average_grid_time:.3f} {time_unit}; travel: 4 blocks {result.distance:.1f} cells, "
               f"per block {per_block}")
    _frame(ax, w, h, f"{title}\n{summary}" if title else summary)
    return fig
