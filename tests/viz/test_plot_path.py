"""plot_path and plot_ga_plan: bounded artists, drawn cells equal to the footprints, legends, warnings."""

import subprocess
import sys

import numpy as np
import pytest
from matplotlib.colors import to_rgb

from htetro_opt.model import Pose, Simulator, Workspace
from htetro_opt.model.robot import STATE_NAMES
from htetro_opt.scenarios import load_scenario
from htetro_opt.solvers.grid_paths import plan_path
from htetro_opt.viz import SHAPE_COLOURS, plot_ga_plan, plot_path, save_figure

OPEN = Workspace(np.zeros((30, 30), dtype=bool))


def random_walk(workspace, start, n, seed=0):
    """Poses of n valid commands from start: random commands, each invalid one repaired by the simulator."""
    sim = Simulator(workspace)
    rng = np.random.default_rng(seed)
    result = sim.run([sim.command_ids[rng.integers(0, sim.n_commands, n)]], start, repair=rng)
    assert result.executed[0] == n
    return result.poses(0)


def cells_of(poses) -> set[tuple[int, int]]:
    """The oracle: every block cell of every pose, through Pose.cells()."""
    return {(int(x), int(y)) for x, y, s, h in poses.tolist() for x, y in Pose(x, y, STATE_NAMES[s], h).cells().tolist()}


def artist(ax, gid):
    found = [a for a in ax.get_children() if a.get_gid() == gid]
    assert len(found) == 1, gid
    return found[0]


def legend_labels(ax) -> list[str]:
    return [t.get_text() for t in ax.get_legend().get_texts()]


def count_artists(ax) -> int:
    return len(ax.patches) + len(ax.collections) + len(ax.lines) + len(ax.images) + len(ax.texts)


@pytest.fixture(scope="module")
def walk():
    return random_walk(OPEN, Pose(15, 15, "O", 0), 2000)


@pytest.fixture(scope="module")
def maze_partial():
    scenario = load_scenario("maze_partial")
    return scenario, plan_path(scenario.workspace, scenario.roadmap, method="dijkstra")


def test_artists_do_not_grow_with_the_path(walk):
    short = plot_path(OPEN, walk[:20], roadmap=(Pose(15, 15, "O", 0),)).axes[0]
    long = plot_path(OPEN, walk, roadmap=(Pose(15, 15, "O", 0),)).axes[0]
    assert len(walk) == 2001 and len(np.unique(walk[:, 2])) == 7  # every shape, many changes
    assert count_artists(long) <= 10
    assert count_artists(long) == count_artists(short)


def test_drawn_cells_are_the_footprints(walk):
    ax = plot_path(OPEN, walk[:300]).axes[0]
    image = artist(ax, "footprints").get_array()
    drawn = {(int(x), int(y)) for y, x in zip(*np.nonzero(image[..., 3] > 0))}
    assert drawn == cells_of(walk[:300])


def test_one_shape_is_drawn_in_its_colour_and_darker_where_covered_more():
    poses = np.array([[3, 3, 1, 0], [4, 3, 1, 0], [5, 3, 1, 0]])  # the O-shape, one cell right at a time
    image = artist(plot_path(OPEN, poses).axes[0], "footprints").get_array()
    assert np.allclose(image[3, 3, :3], to_rgb(SHAPE_COLOURS["O"]))
    # B2 at x covers cells x and x + 1 of the O-shape (heading 0): x = 3 once, 4 twice, 5 twice, 6 once
    assert 0 < image[3, 3, 3] < image[3, 4, 3]
    assert image[3, 5, 3] == image[3, 4, 3] and image[3, 6, 3] == image[3, 3, 3] and image[3, 7, 3] == 0


def test_legend_names_everything_drawn():
    scenario = load_scenario("perpendicular_dynamic")
    plan = plan_path(scenario.workspace, scenario.roadmap, method="dijkstra")
    hidden = np.array([[1, 1]])
    labels = " | ".join(legend_labels(plot_path(scenario.workspace, plan.poses, roadmap=scenario.roadmap,
                                                hidden=hidden).axes[0]))
    for words in ("obstacle", "moving obstacle at t = 0", "moving obstacle's track", "hidden obstacle",
                  "robot's cells", "O-shape", "path of block B2", "start", "intermediate roadmap pose", "goal",
                  "shape/heading change"):
        assert words in labels, words
    assert "path on a hidden obstacle" not in labels  # (1, 1) is not on the path


def test_legend_leaves_out_what_is_not_drawn(walk):
    labels = " | ".join(legend_labels(plot_path(OPEN, walk[:5], roadmap=(Pose(15, 15, "O", 0),)).axes[0]))
    for words in ("moving obstacle", "hidden obstacle", "intermediate roadmap pose", "goal"):
        assert words not in labels, words


def test_a_path_through_hidden_obstacles_says_so(maze_partial):
    scenario, plan = maze_partial
    expected = cells_of(plan.poses) & {tuple(c) for c in scenario.hidden.tolist()}
    assert expected == {(5, 11), (6, 11)}  # the scenario's point: the planner does not know them
    ax = plot_path(scenario.workspace, plan.poses, roadmap=scenario.roadmap, hidden=scenario.hidden).axes[0]
    warnings = [t.get_text() for t in ax.texts if "Warning" in t.get_text()]
    assert len(warnings) == 1 and "2 hidden obstacle cells" in warnings[0]
    assert all(f"({x}, {y})" in warnings[0] for x, y in expected)
    assert "path on a hidden obstacle" in legend_labels(ax)
    quiet = plot_path(scenario.workspace, plan.poses, roadmap=scenario.roadmap, hidden=[[0, 23]]).axes[0]
    assert not [t for t in quiet.texts if "Warning" in t.get_text()]


def test_dense_maps_mark_shape_changes_instead_of_outlining():
    scenario = load_scenario("indoor_room")  # 128 x 128: a footprint is a few pixels
    plan = plan_path(scenario.workspace, scenario.roadmap, method="dijkstra")
    ax = plot_path(scenario.workspace, plan.poses, roadmap=scenario.roadmap).axes[0]
    changes = [(x, y) for (x, y, s, h), (_, _, s0, h0) in zip(plan.poses[1:].tolist(), plan.poses[:-1].tolist())
               if (s, h) != (s0, h0)]
    assert changes  # the plan changes shape to pass the door
    marked = artist(ax, "shape changes").get_offsets()
    assert sorted(map(tuple, np.asarray(marked).astype(int).tolist())) == sorted(changes)
    assert any("shape/heading change" in label for label in legend_labels(ax))
    assert not [line for line in ax.lines if line.get_marker() not in ("None", None, "")]  # no per-pose dots
    sparse = plot_path(OPEN, np.array([[3, 3, 1, 0], [3, 3, 0, 0]])).axes[0]
    assert not [a for a in sparse.get_children() if a.get_gid() == "shape changes"]
    assert any("footprint at start, end, shape/heading change" in label for label in legend_labels(sparse))


def test_title_is_drawn_as_given_and_axes_have_units(walk):
    ax = plot_path(OPEN, walk[:10], title="my run: 9 commands").axes[0]
    assert ax.get_title() == "my run: 9 commands"
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("x (cells)", "y (cells)")


def test_ga_plan_panels_and_times():
    start, goal = Pose(1, 1, "O", 0), Pose(3, 3, "O", 0)
    plan = plan_path(Workspace(np.zeros((8, 8), dtype=bool)), [start, goal], method="htetro-ga", pop_size=10,
                     max_gen=30, max_length=8, seed=1)
    fig = plot_ga_plan(Workspace(np.zeros((8, 8), dtype=bool)), plan, roadmap=(start, goal), title="ga run")
    ax_map, ax_fit = fig.axes
    assert ax_map.get_title() == "ga run"
    assert "convergence" in ax_fit.get_title()
    assert not [ax.get_title() for ax in fig.axes if "Fig" in ax.get_title()]
    assert ax_fit.get_xlabel() == "generation" and ax_map.get_xlabel() == "x (cells)"
    labels = legend_labels(ax_map)
    best_time = plan.legs[0].selected["time"].time
    assert f"best f_t, {best_time:g} s" in labels
    assert len([line for line in ax_map.lines]) == 4  # one track per selection, legs joined


def test_save_figure_without_an_extension_writes_png_and_closes(tmp_path):
    import matplotlib.pyplot as plt

    fig = plot_path(OPEN, np.array([[3, 3, 1, 0]]))
    saved = save_figure(fig, tmp_path / "plan", dpi=40)
    assert saved.read_bytes().startswith(b"\x89PNG")
    assert not plt.fignum_exists(fig.number)


def test_importing_viz_does_not_import_matplotlib():
    code = "import sys, htetro_opt.viz; print('matplotlib' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "False"
