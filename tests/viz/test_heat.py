"""plot_heat_field and plot_heat_plan: the drawn image is the field, arrows are bounded and point
uphill, the drawn path is the poses, obstacles take plot_path's grey, files are written atomically."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
import pytest
from matplotlib.colors import to_rgba

from htetro_opt.errors import OutputError, ParameterError
from htetro_opt.model import Pose, Workspace
from htetro_opt.scenarios import load_scenario
from htetro_opt.solvers.grid_paths import plan_heat, solve_heat_field
from htetro_opt.viz import HEAT_COLORMAP, plot_heat_field, plot_heat_plan

OBSTACLE_RGBA = plt.get_cmap("Greys")(1 / 1.4)  # plot_path's obstacle colour (Greys, vmax 1.4)


@pytest.fixture(scope="module")
def h_shape():
    """The H-shape map, its heat plan and the plan's field (goal cell the source, start cell the sink)."""
    scenario = load_scenario("h_shape")
    plan = plan_heat(scenario.workspace, scenario.roadmap)
    start, goal = plan.poses[0], plan.poses[-1]
    field = solve_heat_field(scenario.workspace, (goal[0], goal[1]), (start[0], start[1]))
    return scenario, plan, field


@pytest.fixture(scope="module")
def cut_off():
    """A 12 × 8 map with a walled-in room (x 8..10, y 4..6) the field cannot reach."""
    occ = np.zeros((8, 12), dtype=bool)
    occ[3, 7:12] = True
    occ[3:8, 7] = True
    ws = Workspace(occ)
    return ws, solve_heat_field(ws, (10, 1), (1, 1))


def by_gid(ax, gid):
    found = [a for a in ax.get_children() if a.get_gid() == gid]
    assert len(found) == 1, gid
    return found[0]


def gids(ax) -> set[str]:
    return {a.get_gid() for a in ax.get_children() if a.get_gid()}


def pixel(ax, x: float, y: float) -> np.ndarray:
    """The RGBA (0..1) drawn at data point (x, y)."""
    ax.figure.canvas.draw()
    buffer = np.asarray(ax.figure.canvas.buffer_rgba())
    px, py = ax.transData.transform((x, y))
    return buffer[buffer.shape[0] - 1 - int(np.rint(py)), int(np.rint(px))] / 255.0


def legend_labels(ax) -> list[str]:
    return [t.get_text() for t in ax.get_legend().get_texts()]


def test_the_image_is_the_field_where_it_has_a_temperature(h_shape):
    scenario, plan, field = h_shape
    ax = plot_heat_field(field, workspace=scenario.workspace, poses=plan.poses)
    data = by_gid(ax, "temperature").get_array()
    finite = np.isfinite(field.cells)
    assert data.shape == field.cells.shape and finite.sum() > 200
    assert np.array_equal(np.asarray(data)[finite], field.cells[finite])
    assert np.array_equal(np.ma.getmaskarray(data), ~finite)
    assert (~finite == scenario.workspace.occupancy).all()  # H-shape: every free cell is connected
    assert by_gid(ax, "temperature").get_cmap().name == HEAT_COLORMAP


def test_obstacles_take_plot_path_s_grey_and_cells_their_temperature_s_colour(h_shape):
    scenario, _, field = h_shape
    ax = plot_heat_field(field, workspace=scenario.workspace, arrows=0)
    y, x = np.argwhere(scenario.workspace.occupancy)[0]
    assert np.allclose(pixel(ax, x, y), OBSTACLE_RGBA, atol=2 / 255)
    for cell in [(scenario.goal.x, scenario.goal.y), (scenario.start.x, scenario.start.y), (3, 12)]:
        expected = plt.get_cmap(HEAT_COLORMAP)(field.cells[cell[1], cell[0]])
        assert np.allclose(pixel(ax, *cell), expected, atol=2 / 255), cell


def test_cut_off_free_cells_are_white_with_a_workspace_and_grey_without(cut_off):
    ws, field = cut_off
    assert np.isnan(field.cells[5, 9]) and not ws.occupancy[5, 9]
    with_map = plot_heat_field(field, workspace=ws, arrows=0)
    assert np.allclose(pixel(with_map, 9, 5), to_rgba("white"), atol=2 / 255)
    assert "free, cut off from start and goal (no temperature)" in legend_labels(with_map)
    without = plot_heat_field(field, arrows=0)
    assert np.allclose(pixel(without, 9, 5), OBSTACLE_RGBA, atol=2 / 255)


@pytest.mark.parametrize("arrows", [3, 5, 7, 23, 40])
def test_at_most_arrows_a_side(h_shape, arrows):
    scenario, _, field = h_shape
    quiver = by_gid(plot_heat_field(field, workspace=scenario.workspace, arrows=arrows, colorbar=False), "gradient")
    assert 0 < quiver.N <= arrows**2
    assert len(np.unique(quiver.X)) <= arrows and len(np.unique(quiver.Y)) <= arrows
    # arrows sit on cells with a temperature, never on an obstacle
    assert not scenario.workspace.occupancy[quiver.Y.astype(int), quiver.X.astype(int)].any()


def test_every_cell_gets_an_arrow_when_there_is_room_and_each_points_uphill():
    ws = Workspace(np.zeros((9, 12), dtype=bool))
    field = solve_heat_field(ws, (11, 8), (0, 0))
    quiver = by_gid(plot_heat_field(field, workspace=ws, arrows=12), "gradient")
    x, y = quiver.X.astype(int), quiver.Y.astype(int)
    # all but the source's and the sink's cells, whose four nodes are held at one temperature (∇T = 0)
    assert quiver.N == 12 * 9 - 2
    assert {(i, j) for i in range(12) for j in range(9)} - set(zip(x.tolist(), y.tolist())) == {(11, 8), (0, 0)}
    # the oracle: a short step along the arrow warms up, measured on the nodes' bilinear interpolant
    step = 0.05 * np.stack([quiver.U, quiver.V], axis=1) / np.hypot(quiver.U, quiver.V)[:, None]

    def bilinear(px, py):
        i, j = np.floor(px + 0.5).astype(int), np.floor(py + 0.5).astype(int)  # lower-left node
        fx, fy = px + 0.5 - i, py + 0.5 - j
        n = field.nodes
        return (n[j, i] * (1 - fx) * (1 - fy) + n[j, i + 1] * fx * (1 - fy)
                + n[j + 1, i] * (1 - fx) * fy + n[j + 1, i + 1] * fx * fy)

    assert (bilinear(x + step[:, 0], y + step[:, 1]) > bilinear(x - step[:, 0], y - step[:, 1])).all()


def test_no_arrows_when_asked_for_none(h_shape):
    scenario, _, field = h_shape
    assert "gradient" not in gids(plot_heat_field(field, workspace=scenario.workspace, arrows=0))


def test_the_path_line_is_b2_s_track_with_start_and_end_markers(h_shape):
    scenario, plan, field = h_shape
    ax = plot_heat_field(field, workspace=scenario.workspace, poses=plan.poses)
    assert np.array_equal(by_gid(ax, "path").get_xydata(), plan.poses[:, :2])
    assert by_gid(ax, "start").get_offsets().tolist() == [plan.poses[0, :2].tolist()]
    assert by_gid(ax, "end").get_offsets().tolist() == [plan.poses[-1, :2].tolist()]
    assert {"path of block B2", "start", "end of the path"} <= set(legend_labels(ax))


def test_the_axes_are_the_map_s_with_y_up(h_shape):
    scenario, _, field = h_shape
    ax = plot_heat_field(field, workspace=scenario.workspace, colorbar=False, title="")
    assert ax.get_xlim() == (-0.5, 23.5) and ax.get_ylim() == (-0.5, 23.5)  # y grows upwards
    assert len(ax.figure.axes) == 1 and ax.get_title() == ""
    with_bar = plot_heat_field(field, workspace=scenario.workspace)
    assert len(with_bar.figure.axes) == 2 and with_bar.get_title() == "temperature field T and ∇T"


def test_draws_on_a_given_axes_and_the_last_of_a_sequence_of_fields(h_shape):
    scenario, _, field = h_shape
    start, goal = scenario.start, scenario.goal
    other = solve_heat_field(scenario.workspace, (start.x, start.y), (goal.x, goal.y))  # source and sink swapped
    _, ax = plt.subplots()
    assert plot_heat_field([field, other], workspace=scenario.workspace, ax=ax) is ax
    drawn = np.asarray(by_gid(ax, "temperature").get_array())
    finite = np.isfinite(other.cells)
    assert np.array_equal(drawn[finite], other.cells[finite])


def test_a_field_that_was_not_solved_says_so(cut_off):
    ws, _ = cut_off
    field = solve_heat_field(ws, (9, 5), (1, 1))  # the source inside the walled-in room
    assert not field.connected
    ax = plot_heat_field(field, workspace=ws)
    assert "no field" in gids(ax) and "gradient" not in gids(ax)
    assert np.ma.getmaskarray(by_gid(ax, "temperature").get_array()).all()


def test_heat_plan_draws_footprints_left_the_field_right_and_replans_on_both(h_shape):
    scenario, plan, field = h_shape
    replans = [{"step": 5, "pose": Pose(*plan.poses[5, :2].tolist(), "O", 0)},
               {"pose": {"x": int(plan.poses[9, 0]), "y": int(plan.poses[9, 1]), "shape": "O", "heading": 0}},
               {"pose": plan.poses[12]}]
    fig = plot_heat_plan(scenario.workspace, plan, field, replans=replans, roadmap=scenario.roadmap, title="h_shape")
    ax_path, ax_heat = fig.axes[:2]
    assert len(fig.axes) == 3  # the two panels and the colour bar
    assert "footprints" in gids(ax_path) and "temperature" not in gids(ax_path)
    assert "temperature" in gids(ax_heat) and "footprints" not in gids(ax_heat)
    assert np.array_equal(by_gid(ax_heat, "path").get_xydata(), plan.poses[:, :2])
    expected = plan.poses[[5, 9, 12], :2].tolist()
    for ax in (ax_path, ax_heat):
        assert by_gid(ax, "replans").get_offsets().tolist() == expected
        assert "replanned here (3)" in legend_labels(ax)
    assert "obstacle" in legend_labels(ax_path) and "goal" in legend_labels(ax_path)  # plot_path's legend kept
    assert fig.get_suptitle() == "h_shape"


def test_heat_plan_saves_a_png_atomically(h_shape, tmp_path):
    scenario, plan, field = h_shape
    target = tmp_path / "heat.png"
    fig = plot_heat_plan(scenario.workspace, plan, field, path=target)
    assert target.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and target.stat().st_size > 10_000
    assert [p.name for p in tmp_path.iterdir()] == ["heat.png"]  # no temporary file left behind
    assert not plt.fignum_exists(fig.number)  # saved and closed


def test_a_bad_output_path_fails_before_drawing(h_shape, tmp_path):
    scenario, plan, field = h_shape
    with pytest.raises(ParameterError, match="not 'nope'"):
        plot_heat_plan(scenario.workspace, plan, field, path=tmp_path / "heat.nope")
    with pytest.raises(OutputError, match="does not exist"):
        plot_heat_plan(scenario.workspace, plan, field, path=tmp_path / "missing" / "heat.png")
    assert plt.get_fignums() == []


@pytest.mark.parametrize("kwargs, match", [
    ({"field": np.zeros((24, 24))}, "must be a HeatField"),
    ({"field": []}, "non-empty sequence"),
    ({"workspace": Workspace(np.zeros((10, 24), dtype=bool))}, "24 × 10 cells but the field is 24 × 24"),
    ({"workspace": "h_shape"}, "workspace must be a Workspace"),
    ({"poses": np.zeros((3, 3), dtype=int)}, r"\(n, 4\) integer array"),
    ({"poses": np.array([[1.5, 2, 1, 0]])}, r"\(n, 4\) integer array"),
    ({"poses": np.array([[1, 2, 1, 0], [30, 2, 1, 0]])}, r"poses\[1\]: B2 cell \(30, 2\) lies outside"),
    ({"arrows": -1}, "arrows must be a non-negative integer"),
    ({"arrows": 2.5}, "arrows must be a non-negative integer"),
    ({"colorbar": "yes"}, "colorbar must be True or False"),
    ({"title": 3}, "title must be a string"),
    ({"replans": [{"step": 1}]}, r"replans\[0\] must be a mapping with a 'pose'"),
    ({"replans": [{"pose": (1, 2, 99, 0)}]}, "state 99 is not a state index"),
    ({"replans": [{"pose": {"x": 1, "y": 2}}]}, "missing shape"),
    ({"replans": [{"pose": (1, 2, "Q", 0)}]}, "Q"),
    ({"replans": {"pose": (1, 2, "O", 0)}}, "replans must be a list"),
])
def test_bad_input_raises_parameter_error(h_shape, kwargs, match):
    scenario, _, field = h_shape
    arguments = {"field": field, "workspace": scenario.workspace, **kwargs}
    with pytest.raises(ParameterError, match=match):
        plot_heat_field(arguments.pop("field"), **arguments)
    assert plt.get_fignums() == []  # checked before a figure is made


@pytest.mark.parametrize("plan, match", [(None, "plan must have poses"), (np.zeros((3, 4)), "plan must have poses")])
def test_heat_plan_refuses_a_plan_without_poses(h_shape, plan, match):
    scenario, _, field = h_shape
    with pytest.raises(ParameterError, match=match):
        plot_heat_plan(scenario.workspace, plan, field)


def test_obstacles_revealed_while_replanning_are_drawn_as_such_not_as_free_cells():
    from htetro_opt.solvers.grid_paths import replan_heat

    scenario = load_scenario("maze_partial")  # its two hidden cells are sensed, and the robot replans
    run = replan_heat(scenario, sensor_range=6.0, keep_fields=True)
    revealed = sorted(tuple(c) for r in run.replans for c in r["revealed"])
    assert revealed == sorted(map(tuple, scenario.hidden.tolist()))
    fig = plot_heat_plan(scenario.workspace, run, run.fields, replans=run.as_dict()["replans"],
                         roadmap=scenario.roadmap, hidden=scenario.hidden)
    ax_path, ax_heat = fig.axes[:2]
    for ax in (ax_path, ax_heat):
        (cells,) = [a for a in ax.collections if a.get_gid() == "revealed obstacles"]
        centres = sorted(tuple(np.asarray(p.vertices[:4]).mean(axis=0).round().astype(int)) for p in cells.get_paths())
        assert centres == revealed
        assert f"revealed obstacle: hidden, then sensed ({len(revealed)})" in legend_labels(ax)
    assert not [label for label in legend_labels(ax_heat) if label.startswith("free")]  # they are not free
    assert not [label for label in legend_labels(ax_path) if label.startswith("hidden obstacle")]  # all sensed
    # the field drawn is the last plan's, solved from where the robot replanned: the colour bar says so
    assert "last plan's start" in fig.axes[2].get_ylabel()
    # without the replans' records, the hidden cells the field has no temperature on are the revealed ones
    ax = plot_heat_field(run.fields, workspace=scenario.workspace, hidden=scenario.hidden, arrows=0)
    assert "revealed obstacles" in gids(ax)
    # a field solved before any sensing has a temperature on the hidden cells: they are hidden, not revealed
    start, goal = scenario.start, scenario.goal
    first = solve_heat_field(scenario.workspace, (goal.x, goal.y), (start.x, start.y))
    ax = plot_heat_field(first, workspace=scenario.workspace, hidden=scenario.hidden, arrows=0)
    assert "revealed obstacles" not in gids(ax) and "hidden obstacles" in gids(ax)
    assert "hidden obstacle, not sensed when this field was solved" in legend_labels(ax)
    # nor is an obstacle of the map (the true map, as notebook 02 passes) drawn as hidden or revealed
    fig = plot_heat_plan(scenario.true_workspace(), run, run.fields, replans=run.replans, roadmap=scenario.roadmap,
                         hidden=scenario.hidden)
    assert not {"revealed obstacles", "hidden obstacles"} & set(gids(fig.axes[1]))
