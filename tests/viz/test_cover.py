"""Plots of coverage plans (Cheng et al. 2019 Figs. 8b, 14, 15): what is drawn matches the plan."""

import matplotlib
import numpy as np
import pytest

from htetro_opt.errors import ParameterError
from htetro_opt.model import Workspace
from htetro_opt.scenarios import load_scenario
from htetro_opt.solvers.coverage import plan_coverage
from htetro_opt.viz import LAYER_COLOURS, plot_cover, plot_cover_heat, save_figure

matplotlib.use("Agg")  # before pyplot is first imported (htetro_opt.viz imports it lazily)
import matplotlib.pyplot as plt
from matplotlib.colors import to_rgba

# (state, heading) of the paper's layers: I is state 0, O state 1
KEYS = {"O": (1, 0), "vI": (0, 0), "hI": (0, 3)}


@pytest.fixture(scope="module")
def case_16x7():
    sc = load_scenario("coverage_16x7")
    plan = plan_coverage(sc.workspace, "O,hI", stripes=[2, 3, 2], start=sc.start, goal=sc.goal)
    return sc.workspace, plan


def by_gid(ax, gid):
    return [a for a in ax.get_children() if a.get_gid() == gid]


def test_arrows_switches_and_markers_match_the_plan(case_16x7, tmp_path):
    ws, plan = case_16x7
    fig = plot_cover(ws, plan, title="16 x 7")
    ax = fig.axes[0]
    poses = plan.poses
    for name in plan.layers:
        (quiver,) = by_gid(ax, f"arrows {name}")
        state, heading = KEYS[name]
        moved = [(int(a[0]), int(a[1]), int(b[0] - a[0]), int(b[1] - a[1])) for a, b in zip(poses[:-1], poses[1:])
                 if (a[2], a[3]) == (state, heading) and (a[0], a[1]) != (b[0], b[1])]
        drawn = [(int(x), int(y), int(u), int(v)) for (x, y), u, v in zip(quiver.get_offsets(), quiver.U, quiver.V)]
        assert sorted(drawn) == sorted(moved) and drawn
        assert to_rgba(quiver.get_facecolor()[0]) == to_rgba(LAYER_COLOURS[name])
    # one footprint outline per arrival in another layer (unit edges: 8 for an O, 10 for an I)
    keys = {KEYS[name] for name in plan.layers}
    layer_poses = [tuple(p) for p in poses.tolist() if tuple(p[2:]) in keys]
    arrivals = [b for a, b in zip(layer_poses[:-1], layer_poses[1:]) if a[2:] != b[2:]]
    (switches,) = by_gid(ax, "switch footprints")
    assert len(arrivals) == plan.switches > 0
    assert len(switches.get_segments()) == sum(8 if state == 1 else 10 for _, _, state, _ in arrivals)
    corners = {tuple(c) for seg in switches.get_segments() for c in np.asarray(seg).tolist()}
    assert all((x + 0.5, y + 0.5) in corners for x, y, _, _ in arrivals)  # outlines around B2's cell
    (crosses,) = by_gid(ax, "uncoverable")
    assert crosses.get_offsets().tolist() == [[x, y] for x, y, _ in plan.uncoverable] == [[0, 0]]
    assert by_gid(ax, "start")[0].get_offsets().tolist() == [[plan.start.x, plan.start.y]]
    assert by_gid(ax, "goal")[0].get_offsets().tolist() == [[plan.goal.x, plan.goal.y]]
    assert len([a for a in ax.patches if a.get_gid() == "borrowed rows"]) == plan.stripes_detail[-1]["borrowed"]
    # each stripe's region cuts, dashed across its band at the cell edge before the cut column (the
    # default variant picks one of two cut grids per stripe, so the columns differ between stripes)
    cuts = by_gid(ax, "region cuts")[0].get_segments()
    drawn = sorted((float(seg[0][0]), float(seg[0][1]), float(seg[1][1])) for seg in cuts)
    expected = sorted((c - 0.5, s["band"][0] - 0.5, s["band"][1] - 0.5) for s in plan.stripes_detail for c in s["cuts"])
    assert drawn == expected and drawn
    assert all(0 < c < ws.occupancy.shape[1] for s in plan.stripes_detail for c in s["cuts"])
    path = save_figure(fig, tmp_path / "cover.png")
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    plt.close(fig)


def test_borrowed_rows_are_hatched():
    # the paper's variant widens 16 x 7's top stripe (Fig. 11); the default sweeps its pieces instead
    sc = load_scenario("coverage_16x7")
    plan = plan_coverage(sc.workspace, "O,hI", method="stripes-paper", stripes=[2, 3, 2], start=sc.start, goal=sc.goal)
    ax = plot_cover(sc.workspace, plan).axes[0]
    assert len([a for a in ax.patches if a.get_gid() == "borrowed rows"]) == plan.stripes_detail[-1]["borrowed"] > 0


def test_heat_figure_has_map_and_histogram(case_16x7, tmp_path):
    _, plan = case_16x7
    fig = plot_cover_heat(plan, title="16 x 7")
    hist = [p for ax in fig.axes for p in ax.patches if p.get_gid() == "pixel-time histogram"]
    p = plan.coverage.pixels_per_cell
    assert sum(bar.get_height() for bar in hist) == plan.free.sum() * p * p
    assert save_figure(fig, tmp_path / "heat.svg").stat().st_size > 1000
    plt.close(fig)


def test_bad_input():
    ws = Workspace(np.zeros((4, 6), dtype=bool))
    with pytest.raises(ParameterError, match="CoveragePlan"):
        plot_cover(ws, "plan")
    with pytest.raises(ParameterError, match="map"):
        plot_cover(Workspace(np.zeros((5, 6), dtype=bool)), plan_coverage(ws, "O"))
    with pytest.raises(ParameterError, match="bins"):
        plot_cover_heat(plan_coverage(ws, "O"), bins=0)


@pytest.fixture(scope="module")
def tiling_tsp_16x16():
    sc = load_scenario("coverage_16x16")
    return sc.workspace, plan_coverage(sc.workspace, method="tiling-tsp")


def legend_labels(ax):
    return [t.get_text() for t in ax.get_legend().get_texts()]


def test_the_start_and_the_end_of_a_plan_are_marked_and_in_the_legend(tiling_tsp_16x16):
    ws, plan = tiling_tsp_16x16
    assert plan.goal is None  # no goal: the end is wherever the plan stops
    ax = plot_cover(ws, plan).axes[0]
    assert by_gid(ax, "start")[0].get_offsets().tolist() == [[plan.start.x, plan.start.y]]
    assert by_gid(ax, "end")[0].get_offsets().tolist() == [plan.poses[-1, :2].tolist()]
    labels = legend_labels(ax)
    assert any(label.startswith("start (") for label in labels)
    assert any(label.startswith("end of the plan (") and f"after {len(plan.commands)} commands" in label
               for label in labels)


def test_a_long_plan_is_a_line_with_sparse_arrows_and_every_move_drawn(tiling_tsp_16x16):
    ws, plan = tiling_tsp_16x16
    poses = plan.poses
    moves = int((poses[1:, :2] != poses[:-1, :2]).any(axis=1).sum())
    assert moves > 150  # more than the default arrows: the line
    ax = plot_cover(ws, plan).axes[0]
    lines = [a for a in ax.collections if str(a.get_gid()).startswith("path ")]
    assert sum(len(line.get_segments()) for line in lines) == moves  # every move, the ones in no layer too
    assert "path other" in {line.get_gid() for line in lines}
    quivers = [a for a in ax.collections if str(a.get_gid()).startswith("arrows ")]
    assert 0 < sum(q.N for q in quivers) <= 150 / 3
    assert any(label.startswith(f"{moves} moves: a line") for label in legend_labels(ax))
    # with room for every arrow, one a move, from B2's cell
    ax = plot_cover(ws, plan, arrows=1000).axes[0]
    quivers = [a for a in ax.collections if str(a.get_gid()).startswith("arrows ")]
    assert sum(q.N for q in quivers) == moves and not [a for a in ax.collections if str(a.get_gid()).startswith("path ")]
    with pytest.raises(ParameterError, match="arrows"):
        plot_cover(ws, plan, arrows=0)


def test_the_heat_figure_gives_one_time_unit_on_both_panels(case_16x7):
    _, plan = case_16x7
    fig = plot_cover_heat(plan)
    left, right = fig.axes[:2]
    assert "command units" in left.get_title() and " s;" not in left.get_title()
    assert "command units" in right.get_xlabel()
    assert all(t.get_text().endswith("command units") for t in right.get_legend().get_texts())
