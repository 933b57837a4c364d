"""plot_tileset and plot_coverage: labels that follow the density, borders, bounded artists."""

import re

import numpy as np
import pytest
from matplotlib.colors import to_rgb

from htetro_opt.model import simulate_coverage
from htetro_opt.scenarios import (
    load_scenario,
    load_tileset,
    parse_tileset,
    tileset_path,
)
from htetro_opt.solvers import tile_workspace
from htetro_opt.viz import SHAPE_COLOURS, plot_coverage, plot_tileset

CELL_LABEL = re.compile(r"^\d+[abcd](/\d+[abcd])*$")


@pytest.fixture(scope="module")
def large():
    tileset = tile_workspace(load_scenario("tiling_64x64").workspace, name="tiling_64x64").tileset
    assert len(tileset) == 1004
    return tileset


@pytest.fixture(scope="module")
def small():
    return load_tileset(tileset_path("paper_11x11_fig13d"))


def texts(ax) -> list[str]:
    return [t.get_text() for t in ax.texts]


def legend_labels(ax) -> list[str]:
    return [t.get_text() for t in ax.get_legend().get_texts()]


def gid(ax, name):
    found = [a for a in ax.get_children() if a.get_gid() == name]
    assert len(found) == 1, name
    return found[0]


def test_a_small_tileset_has_every_label_and_visit_number(small):
    ax = plot_tileset(small, list(small.ids)).axes[0]
    labels = [t for t in texts(ax) if CELL_LABEL.match(t)]
    assert len(labels) == 4 * len(small) and "12b" in labels
    assert sorted(int(t) for t in texts(ax) if t.isdigit()) == list(range(1, len(small) + 1))
    assert "1b: block b of tile 1" in legend_labels(ax)


def test_a_large_tileset_drops_cell_labels_and_thins_visit_numbers(large):
    fig = plot_tileset(large, list(large.ids))
    ax = fig.axes[0]
    assert not [t for t in texts(ax) if CELL_LABEL.match(t)]
    numbers = sorted(int(t) for t in texts(ax) if t.isdigit())
    assert numbers[0] == 1 and numbers[-1] == 1004 and len(numbers) <= 45
    assert set(numbers[1:-1]) <= set(range(50, 1004, 50))
    assert len(ax.patches) + len(ax.collections) + len(ax.lines) + len(ax.images) <= 8
    labels = " | ".join(legend_labels(ax))
    assert "block b" in labels and "B2, the reference" in labels and "visit number (1, 50, 100, …, 1004)" in labels


def test_tile_colours_and_obstacles_are_per_cell(small):
    ax = plot_tileset(small).axes[0]
    tiles = gid(ax, "tiles").get_array()
    for shape, cells in zip(small.shapes, small.blocks):
        rgb = to_rgb(SHAPE_COLOURS[shape])
        for x, y in cells.tolist():
            assert np.allclose(tiles[y, x, :3], rgb) and tiles[y, x, 3] > 0
    assert (tiles[..., 3] > 0).sum() == 4 * len(small)  # a tiling without overlaps: one tile per cell
    obstacles = gid(ax, "obstacles").get_array()
    assert np.array_equal(~np.ma.getmaskarray(obstacles), small.occupancy)


def test_borders_match_a_naive_count(small):
    ax = plot_tileset(small).axes[0]
    expected = 0
    for cells in small.blocks.tolist():
        mine = {tuple(c) for c in cells}
        expected += sum((x + dx, y + dy) not in mine for x, y in mine for dx, dy in ((1, 0), (-1, 0), (0, 1), (0, -1)))
    thick = [c for c in ax.collections if c.get_linewidths()[0] > 1.0]
    assert len(thick) == 1 and len(thick[0].get_segments()) == expected


def test_overlapping_cells_are_darker_and_show_both_labels():
    tileset = parse_tileset("1a 1b/2a 2b\n1d 1c/2d 2c")  # two O tiles sharing a column
    ax = plot_tileset(tileset).axes[0]
    tiles = gid(ax, "tiles").get_array()
    assert tiles[0, 1, 3] > tiles[0, 0, 3]
    assert "1b/2a" in texts(ax)


def test_default_title_has_no_folder(small):
    title = plot_tileset(small).axes[0].get_title()
    assert title == "paper_11x11_fig13d.txt" and "/" not in title
    assert plot_tileset(small, title="mine").axes[0].get_title() == "mine"


def test_coverage_obstacles_are_one_collection(small):
    result = simulate_coverage(small, list(range(len(small))), pixels_per_cell=4)
    fig = plot_coverage(result, title="in order")
    ax = fig.axes[0]
    assert not ax.patches
    (blocked,) = [c for c in ax.collections if len(c.get_paths()) == int((~result.free).sum())]
    assert blocked.get_hatch() == "xx"
    assert " s;" in ax.get_title()  # the average grid time, with its unit
    assert "not free (obstacle)" in legend_labels(ax)


@pytest.mark.parametrize("which", ["small", "large"])
def test_the_order_is_drawn_dashed_and_said_not_to_be_the_driven_path(which, request):
    tileset = request.getfixturevalue(which)
    ax = plot_tileset(tileset, list(tileset.ids)).axes[0]
    order = gid(ax, "order")
    styles = order.get_linestyles() if hasattr(order, "get_linestyles") else [order.get_linestyle()]
    assert all(style not in ("-", "solid", (0, None)) for style in styles)  # dashed: the order, not a path
    assert order.get_alpha() < 1
    assert any("not the driven path" in label for label in legend_labels(ax))
