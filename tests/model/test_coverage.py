"""Seed 003's coverage simulation (Tables 4–5, Fig. 18) and the tileset / heat-map plots."""

import json

import matplotlib
import numpy as np
import pytest

from htetro_opt.errors import ParameterError
from htetro_opt.model import CoverageResult, simulate_coverage
from htetro_opt.problems import SequencingInstance, cost_matrix
from htetro_opt.scenarios import load_tileset, parse_tileset, tileset_path
from htetro_opt.solvers.sequencing import solve_greedy, solve_zigzag
from htetro_opt.viz import plot_coverage, plot_tileset, save_figure

matplotlib.use("Agg")  # before pyplot is first imported (htetro_opt.viz imports it lazily)

FIG14 = tileset_path("paper_11x11_fig13d")  # the paper's Figs. 13d and 14


@pytest.fixture(scope="module")
def fig14():
    return load_tileset(FIG14, cell_size=0.25)


@pytest.fixture(scope="module")
def fig14_run(fig14):
    inst = SequencingInstance.from_tileset(fig14, start=1)
    order, _ = solve_zigzag(inst, rows=2)
    return inst, order, simulate_coverage(fig14, order, pixels_per_cell=6)


def brute_force_pixel_time(blocks, order, shape, p, speed, dwell, steps=1500):
    """Time-sampled coverage: block squares at many instants, pixel centres tested one by one."""
    h, w = shape
    xs = (np.arange(w * p) + 0.5) / p - 0.5
    ys = (np.arange(h * p) + 0.5) / p - 0.5
    out = np.zeros((h * p, w * p))

    def add(centres, dt):
        for cx, cy in centres:
            inside = (np.abs(ys[:, None] - cy) < 0.5) & (np.abs(xs[None, :] - cx) < 0.5)
            out[inside] += dt

    for k, i in enumerate(order):
        add(blocks[i], dwell)
        if k + 1 < len(order):
            a, b = blocks[i].astype(float), blocks[order[k + 1]].astype(float)
            duration = np.sqrt(((b - a) ** 2).sum(-1)).max() / speed
            for s in (np.arange(steps) + 0.5) / steps:
                add(a + (b - a) * s, duration / steps)
    return out


def test_total_distance_is_the_sum_of_the_four_blocks_displacements(fig14, fig14_run):
    inst, order, result = fig14_run
    b = fig14.blocks[order].astype(float)
    per_block = np.sqrt(((b[1:] - b[:-1]) ** 2).sum(-1)).sum(axis=0)
    assert result.block_distance == pytest.approx(per_block)
    assert result.distance == pytest.approx(per_block.sum())
    assert result.mean_block_distance == pytest.approx(inst.path_cost(order))  # eq. 2 with α = β = λ = γ = ¼
    assert result.distance_m == pytest.approx(result.distance * 0.25)  # the tileset's cell size
    assert simulate_coverage(fig14, order, pixels_per_cell=2, cell_size=0.5).distance_m == pytest.approx(result.distance / 2)
    assert simulate_coverage(SequencingInstance.from_tileset(fig14), order, pixels_per_cell=2).distance_m is None


def test_one_waypoint_covers_exactly_its_four_cells_for_the_dwell_time(fig14):
    result = simulate_coverage(fig14, [6], pixels_per_cell=5, dwell=2.5)
    expected = np.zeros(fig14.occupancy.shape)
    for x, y in fig14.blocks[6]:
        expected[y, x] = 2.5
    assert np.array_equal(result.cell_time, expected)
    assert set(np.unique(result.pixel_time).tolist()) == {0.0, 2.5}
    assert result.distance == 0 and result.duration == 2.5


def test_a_cell_passed_once_is_covered_less_than_a_cell_dwelt_in():
    # two horizontal I tiles with an empty row between them: the blocks cross row 1 once
    ts = parse_tileset("1a 1b 1c 1d\n. . . .\n2a 2b 2c 2d")
    fast = simulate_coverage(ts, [0, 1], speed=2.0, pixels_per_cell=8)
    assert np.allclose(fast.cell_time[1], 0.5)  # a unit square crossing a point at 2 cells/s covers it 0.5 s
    assert (fast.cell_time[1] < 1.0).all() and (fast.cell_time[[0, 2]] >= 1.0).all()
    assert (fast.pixel_time[8:16] < 1.0).all()
    # at 1 cell/s a crossing covers every point of the crossed cell exactly as long as a 1 s dwell
    slow = simulate_coverage(ts, [0, 1], speed=1.0, pixels_per_cell=8)
    assert np.allclose(slow.pixel_time[8:16], 1.0)
    assert slow.free[1].all()  # '.' cells are free, only passed over
    assert slow.average_grid_time == pytest.approx((1.5 + 1.0 + 1.5) / 3)


def test_exact_coverage_matches_a_time_sampled_simulation():
    # arbitrary block positions (not tetrominoes): diagonal moves of different lengths
    blocks = np.array([
        [(0, 0), (1, 0), (2, 1), (3, 3)],
        [(3, 2), (2, 2), (2, 0), (0, 3)],
        [(1, 3), (0, 1), (3, 0), (1, 1)],
    ])
    inst = SequencingInstance(cost_matrix(blocks), blocks, 0, shape=(4, 4))
    order = [0, 1, 2, 0]
    result = simulate_coverage(inst, order, pixels_per_cell=4, speed=1.7, dwell=0.3)
    expected = brute_force_pixel_time(blocks, order, (4, 4), 4, 1.7, 0.3)
    assert np.abs(result.pixel_time - expected).max() < 0.02


def test_covered_area_times_seconds_is_four_blocks_times_the_duration(fig14_run):
    _, order, result = fig14_run
    p = result.pixels_per_cell
    assert result.pixel_time.sum() / p**2 == pytest.approx(4 * result.duration)
    assert result.cell_time.sum() == pytest.approx(4 * result.duration)
    assert result.average_grid_time == pytest.approx(result.cell_time[result.free].mean())
    assert result.duration == pytest.approx(len(order) * 1.0 + sum(
        np.sqrt(((result_blocks[1:] - result_blocks[:-1]) ** 2).sum(-1)).max(axis=1).sum()
        for result_blocks in [load_tileset(FIG14).blocks[order].astype(float)]))


def test_a_path_that_revisits_a_region_recovers_more_cells_than_a_direct_one():
    strip = parse_tileset(" ".join(f"{t}{letter}" for t in range(1, 5) for letter in "abcd"))  # 16 x 1, I tiles
    direct = simulate_coverage(strip, [0, 1, 2, 3], pixels_per_cell=4)
    revisit = simulate_coverage(strip, [0, 2, 1, 3], pixels_per_cell=4)  # back over tiles 2 and 3
    assert (revisit.cell_time >= direct.cell_time - 1e-12).all()
    scale = max(direct.pixel_time.max(), revisit.pixel_time.max())  # one scale for both runs
    for threshold in (100, 150):
        assert revisit.recovered(threshold, scale=scale) > direct.recovered(threshold, scale=scale)
    assert revisit.average_grid_time > direct.average_grid_time


def test_recovered_counts_cells_above_a_threshold_over_all_or_free_cells(fig14, fig14_run):
    _, _, result = fig14_run
    heat = result.cell_heat()
    assert heat.shape == (11, 11) and heat.max() <= 255
    assert result.heat.max() == pytest.approx(255)
    assert heat == pytest.approx(result.cell_time * 255 / result.pixel_time.max())
    for threshold in (100, 150, 50):
        above = heat > threshold
        assert result.recovered(threshold) == pytest.approx(100 * above.sum() / 121)  # the paper's 121 cells
        assert result.recovered(threshold, denominator="free") == pytest.approx(
            100 * (above & ~fig14.occupancy).sum() / 112)
    assert result.recovered(-1) == 100.0 and result.recovered(255) == 0.0
    scaled = result.cell_heat(scale=2.0)
    assert scaled.max() <= 255 and scaled == pytest.approx(np.clip(result.pixel_time * 127.5, 0, 255).reshape(
        11, 6, 11, 6).mean(axis=(1, 3)))
    json.dumps(result.as_dict())
    assert result.as_dict()["recovered_150_pct"] == result.recovered(150)


def test_an_instance_and_its_tileset_give_the_same_run(fig14):
    inst = SequencingInstance.from_tileset(fig14, start=1)
    order, _ = solve_greedy(inst, iterations=50)
    a = simulate_coverage(inst, order, pixels_per_cell=3)
    b = simulate_coverage(fig14, order, pixels_per_cell=3)
    assert np.array_equal(a.pixel_time, b.pixel_time)
    assert np.array_equal(a.free, ~fig14.occupancy)  # a complete tiling covers exactly the free cells
    c = simulate_coverage(inst, order, pixels_per_cell=3, occupancy=np.zeros((11, 11), bool))
    assert c.free.all() and c.average_grid_time < a.average_grid_time


def test_results_are_read_only(fig14_run):
    _, _, result = fig14_run
    assert isinstance(result, CoverageResult)
    with pytest.raises(ValueError):
        result.pixel_time[0, 0] = 1.0


@pytest.mark.parametrize("options, word", [
    ({"pixels_per_cell": 0}, "pixels_per_cell"),
    ({"pixels_per_cell": 2.5}, "pixels_per_cell"),
    ({"pixels_per_cell": 10_000}, "pixel"),
    ({"speed": 0}, "speed"),
    ({"speed": float("nan")}, "speed"),
    ({"dwell": -1}, "dwell"),
    ({"cell_size": 0}, "cell_size"),
    ({"occupancy": np.zeros((3, 3), bool)}, "occupancy"),
])
def test_bad_options_raise(fig14, options, word):
    with pytest.raises(ParameterError, match=word):
        simulate_coverage(fig14, [0, 1], **options)


@pytest.mark.parametrize("order", [[], [0, 28], [-1], [[0, "x"]], [0.0, 1.5], [[0, 1], [2, 3]], [[0], [1, 2]]])
def test_bad_orders_raise(fig14, order):
    with pytest.raises(ParameterError, match="order"):
        simulate_coverage(fig14, order)


def test_bad_recovered_arguments_raise(fig14_run):
    _, _, result = fig14_run
    with pytest.raises(ParameterError, match="denominator"):
        result.recovered(100, denominator="cells")
    with pytest.raises(ParameterError, match="threshold"):
        result.recovered("100")
    with pytest.raises(ParameterError, match="scale"):
        result.heat_map(scale=0)
    with pytest.raises(ParameterError, match="waypoints"):
        simulate_coverage("map", [0])


def test_plots_draw_and_save(fig14, fig14_run, tmp_path):
    inst, order, result = fig14_run
    fig = plot_tileset(fig14, inst.tile_order(order), title="zigzag, 2 rows")
    assert type(fig).__name__ == "Figure"
    axis = fig.axes[0]
    assert len([t for t in axis.texts if t.get_text() == "28"]) == 1  # visit numbers
    assert any(t.get_text() == "12b" for t in axis.texts)
    assert save_figure(fig, tmp_path / "tiles.png", dpi=50).stat().st_size > 0
    fig = plot_coverage(result, title="zigzag, 2 rows")
    assert len(fig.axes) == 2  # heat map and colour bar
    assert save_figure(fig, tmp_path / "heat.png", dpi=50).stat().st_size > 0


def test_plots_draw_on_a_given_axes_and_reject_bad_input(fig14, fig14_run):
    import matplotlib.pyplot as plt

    _, _, result = fig14_run
    fig, (left, right) = plt.subplots(1, 2)
    assert plot_tileset(fig14, [3, 1], ax=left) is fig
    assert plot_coverage(result, ax=right) is fig
    with pytest.raises(ParameterError, match="order"):
        plot_tileset(fig14, [1, 99], ax=left)
    with pytest.raises(ParameterError, match="tileset"):
        plot_tileset("1a 1b 1c 1d", ax=left)
    with pytest.raises(ParameterError, match="CoverageResult"):
        plot_coverage(fig14, ax=right)
    plt.close(fig)
