"""animate_path and save_gif: frame counts, the drawn blocks against the simulator's poses, the
continuous motion between poses, moving obstacles on the model's clock, atomic saving."""

import math
import subprocess
import sys

import numpy as np
import pytest
from matplotlib.colors import to_rgb
from PIL import Image

from htetro_opt.errors import ConfigurationError, OutputError, ParameterError, PlanningError
from htetro_opt.model import FOOTPRINTS, MovingObstacle, Pose, Simulator, Timing, Workspace, command_set
from htetro_opt.viz import SHAPE_COLOURS, animate_path, save_gif

OPEN = Workspace(np.zeros((12, 12), dtype=bool))


def random_plan(workspace, start, n, *, commands=None, seed=0):
    """n commands valid from start (random, each invalid one repaired), and the simulator's poses."""
    sim = Simulator(workspace, commands=commands)
    rng = np.random.default_rng(seed)
    result = sim.run([sim.command_ids[rng.integers(0, sim.n_commands, n)]], start, repair=rng)
    assert result.executed[0] == n
    return result.sequence(0), result.poses(0)


def drawn_squares(anim, i) -> np.ndarray:
    """The corners of the robot's four squares as drawn at frame i, shape (4, 4, 2)."""
    anim.draw_frame(i)
    return np.array([path.vertices[:4] for path in anim.robot.get_paths()])


def drawn_obstacle_cells(anim, i) -> np.ndarray:
    """The centres of the moving obstacles' squares as drawn at frame i, shape (m, 2)."""
    anim.draw_frame(i)
    return np.array([path.vertices[:4].mean(axis=0) for path in anim.obstacles.get_paths()])


def edge_angles(squares) -> np.ndarray:
    """Direction of each square's first edge, in degrees modulo 90."""
    edge = squares[:, 1] - squares[:, 0]
    return np.degrees(np.arctan2(edge[:, 1], edge[:, 0])) % 90.0


def is_axis_aligned(squares) -> bool:
    a = edge_angles(squares)
    return bool(np.all(np.minimum(a, 90.0 - a) < 1e-6))


def as_set(cells) -> set[tuple[int, int]]:
    return {(int(x), int(y)) for x, y in np.rint(cells).astype(int).tolist()}


def test_gif_has_one_frame_per_pose(tmp_path):
    commands, _ = random_plan(OPEN, Pose(5, 5, "O"), 15)
    anim = animate_path(OPEN, commands, Pose(5, 5, "O"), frames_per_step=1)
    path = save_gif(anim, tmp_path / "plan.gif")
    assert path.read_bytes()[:6] == b"GIF89a"
    with Image.open(path) as gif:
        assert gif.n_frames == len(anim) == len(commands) + 1
        assert gif.info["loop"] == 0


@pytest.mark.parametrize("k", [2, 4])
def test_gif_has_k_frames_per_step(tmp_path, k):
    commands, _ = random_plan(OPEN, Pose(5, 5, "O"), 12, seed=k)
    anim = animate_path(OPEN, commands, Pose(5, 5, "O"), frames_per_step=k)
    with Image.open(save_gif(anim, tmp_path / "plan.gif", fps=25)) as gif:
        assert gif.n_frames == len(commands) * k + 1
        assert gif.info["duration"] == 40


def test_an_empty_plan_is_one_frame(tmp_path):
    anim = animate_path(OPEN, [], Pose(5, 5, "T", 2))
    with Image.open(save_gif(anim, tmp_path / "still.gif")) as gif:
        assert gif.n_frames == 1
    expected = Pose(5, 5, "T", 2).cells()
    assert np.allclose(drawn_squares(anim, 0).mean(axis=1), expected)


def test_long_plans_are_capped():
    commands, poses = random_plan(OPEN, Pose(5, 5, "O"), 40)
    fewer = animate_path(OPEN, commands, Pose(5, 5, "O"), frames_per_step=4, max_frames=100)
    assert len(fewer) == 40 * 2 + 1  # two frames a step fit, four do not
    sparse = animate_path(OPEN, commands, Pose(5, 5, "O"), max_frames=11)
    assert len(sparse) == 11 and sparse.steps[0] == 0 and sparse.steps[-1] == 40
    assert not sparse.fractions.any()  # poses only: no motion between them
    for i, step in enumerate(sparse.steps.tolist()):
        x, y, s, h = poses[step]
        assert as_set(drawn_squares(sparse, i).mean(axis=1)) == as_set(FOOTPRINTS[s, h] + (x, y))


@pytest.mark.parametrize("commands", [None, command_set(diagonals=True), command_set(seed004=True)],
                         ids=["cheng2020", "diagonals", "cheng2019-blocks"])
def test_step_frames_draw_the_simulators_poses(commands):
    sequence, poses = random_plan(OPEN, Pose(5, 5, "I"), 60, commands=commands, seed=3)
    k = 3
    anim = animate_path(OPEN, sequence, Pose(5, 5, "I"), frames_per_step=k)
    assert np.array_equal(anim.poses, poses)
    for step, (x, y, s, h) in enumerate(poses.tolist()):
        squares = drawn_squares(anim, step * k)
        assert anim.steps[step * k] == step and anim.fractions[step * k] == 0.0
        assert np.allclose(squares.mean(axis=1), FOOTPRINTS[s, h] + (x, y), atol=1e-9), step
        assert is_axis_aligned(squares), step
        assert np.allclose(np.linalg.norm(squares[:, 1] - squares[:, 0], axis=1), 1.0)


def test_the_robot_is_coloured_by_its_state_in_the_gif(tmp_path):
    workspace = Workspace(np.zeros((6, 6), dtype=bool))
    anim = animate_path(workspace, "sL,x+", Pose(2, 2, "O"), frames_per_step=1)
    with Image.open(save_gif(anim, tmp_path / "plan.gif")) as gif:
        frames = []
        for i in range(gif.n_frames):
            gif.seek(i)
            frames.append(np.asarray(gif.convert("RGB"), dtype=float) / 255)
    ax = anim.figure.axes[0]
    height = frames[0].shape[0]

    def pixel(frame, cell):  # a point inside the cell, clear of the block's number
        px, py = ax.transData.transform(np.asarray(cell, dtype=float) + 0.3)
        return frames[frame][int(height - py), int(px)]

    for frame, pose in enumerate([Pose(2, 2, "O"), Pose(2, 2, "L"), Pose(3, 2, "L")]):
        for cell in pose.cells():
            assert np.allclose(pixel(frame, cell), to_rgb(SHAPE_COLOURS[pose.shape]), atol=0.02), (frame, cell)
    assert np.allclose(pixel(2, (2, 2)), 1.0, atol=0.1)  # the cell B2 left is white again


def test_a_rotation_is_seen_turning_about_b2():
    anim = animate_path(OPEN, "r+", Pose(5, 5, "L", 0), frames_per_step=4)
    assert is_axis_aligned(drawn_squares(anim, 0)) and is_axis_aligned(drawn_squares(anim, 4))
    start = Pose(5, 5, "L", 0).cells()
    for i, turn in zip((1, 2, 3), (22.5, 45.0, 67.5)):
        squares = drawn_squares(anim, i)
        assert not is_axis_aligned(squares)
        assert np.allclose(edge_angles(squares), turn, atol=0.5)  # whole squares turn, not only their centres
        centres = squares.mean(axis=1)
        assert np.allclose(centres[1], (5, 5))  # B2's centre is the pivot
        angle = math.radians(turn)
        turned = (start - (5, 5)) @ np.array([[math.cos(angle), math.sin(angle)],
                                              [-math.sin(angle), math.cos(angle)]]) + (5, 5)
        assert np.allclose(centres, turned, atol=0.02)


def test_a_shapeshift_turns_blocks_about_the_hinges_and_keeps_b2():
    anim = animate_path(OPEN, "sL", Pose(5, 5, "I", 1), frames_per_step=4)
    for i in (1, 3):
        squares = drawn_squares(anim, i)
        assert not is_axis_aligned(squares)
        assert np.allclose(squares[1].mean(axis=0), (5, 5)) and is_axis_aligned(squares[1:2])
        assert np.allclose(squares[2:].mean(axis=1), Pose(5, 5, "I", 1).cells()[2:])  # only B1 turns (I to L)
    assert np.allclose(drawn_squares(anim, 4).mean(axis=1), Pose(5, 5, "L", 1).cells())


def test_translations_move_in_the_workspace_frame_whatever_the_heading():
    for heading in range(4):
        anim = animate_path(OPEN, "x+,y-", Pose(5, 5, "J", heading), frames_per_step=2)
        cells = Pose(5, 5, "J", heading).cells()
        assert np.allclose(drawn_squares(anim, 1).mean(axis=1), cells + (0.5, 0.0))
        assert np.allclose(drawn_squares(anim, 3).mean(axis=1), cells + (1.0, -0.5))
        assert is_axis_aligned(drawn_squares(anim, 1))


def test_moving_obstacles_keep_the_models_clock():
    slow = MovingObstacle(cells=[[10, 10], [10, 9]], route=[[0, 0], [-4, 0]], speed=1, mode="pingpong")
    fast = MovingObstacle(cells=[[1, 10]], route=[[0, 0], [0, -3]], speed=2, mode="loop")
    workspace = Workspace(np.zeros((12, 12), dtype=bool), moving=(slow, fast))
    k, n = 2, 12
    anim = animate_path(workspace, ["y-", "y+"] * (n // 2), Pose(6, 2, "O"), frames_per_step=k)
    seen = set()
    for t in range(n + 1):
        drawn = drawn_obstacle_cells(anim, t * k)
        expected = np.concatenate([slow.cells_at(t), fast.cells_at(t)])
        assert as_set(drawn) == as_set(expected) and np.allclose(drawn, np.rint(drawn)), t
        seen.add(frozenset(as_set(drawn)))
        if t < n:  # half-way through command t: the slow block between its two cells, the fast one on its way
            middle = drawn_obstacle_cells(anim, t * k + 1)
            assert np.allclose(middle[:2], (slow.cells_at(t) + slow.cells_at(t + 1)) / 2), t
            assert as_set(middle[2:]) <= as_set(fast.cells_during(t)), t
    assert len(seen) > 4  # they move


def test_status_shows_step_and_time():
    anim = animate_path(OPEN, "r+,x+,sL", Pose(5, 5, "O"), frames_per_step=2, timing=Timing(rotation=1.5))
    texts = [anim.draw_frame(i)[-1].get_text() for i in range(len(anim))]
    assert texts[0] == "step 0/3, t = 0.00 s"
    assert texts[1] == "step 0/3 \u2192 1: r+, t = 0.75 s"
    assert texts[2] == "step 1/3, t = 1.50 s"
    assert texts[-1] == "step 3/3, t = 5.50 s"
    assert anim.status is anim.draw_frame(0)[-1]


def test_invalid_plans_and_options_are_refused(tmp_path):
    walled = Workspace(np.pad(np.zeros((4, 4), dtype=bool), 1, constant_values=True))
    with pytest.raises(PlanningError, match=r"command 3 of 3 \('x\+'\) is invalid"):
        animate_path(walled, "y+,x+,x+", Pose(2, 2, "O"))  # the O-shape covers x = 2, 3: then 3, 4, then the wall
    with pytest.raises(ConfigurationError, match="start"):
        animate_path(walled, "x+", Pose(0, 2, "O"))
    with pytest.raises(ParameterError, match="frames_per_step"):
        animate_path(OPEN, "x+", Pose(5, 5, "O"), frames_per_step=0)
    anim = animate_path(OPEN, "x+", Pose(5, 5, "O"))
    with pytest.raises(ParameterError, match="fps"):
        save_gif(anim, tmp_path / "a.gif", fps=60)
    with pytest.raises(ParameterError, match=r"\.gif"):
        save_gif(anim, tmp_path / "a.mp4")
    assert not any(tmp_path.iterdir())


def test_saving_into_a_missing_folder_leaves_nothing(tmp_path):
    anim = animate_path(OPEN, "x+,y+", Pose(5, 5, "O"))
    with pytest.raises(OutputError, match="missing"):
        save_gif(anim, tmp_path / "missing" / "plan.gif")
    assert not any(tmp_path.iterdir())


def test_a_failure_while_writing_leaves_the_old_file(tmp_path, monkeypatch):
    target = tmp_path / "plan.gif"
    target.write_bytes(b"old")
    anim = animate_path(OPEN, "x+,y+,x+", Pose(5, 5, "O"))
    frame_image = anim.frame_image

    def failing(i):
        if i == 5:
            raise RuntimeError("interrupted")
        return frame_image(i)

    monkeypatch.setattr(anim, "frame_image", failing)
    with pytest.raises(RuntimeError, match="interrupted"):
        save_gif(anim, target)
    assert target.read_bytes() == b"old" and [p.name for p in tmp_path.iterdir()] == ["plan.gif"]


def test_importing_viz_does_not_import_matplotlib_or_pillow():
    code = "import sys, htetro_opt.viz; print('matplotlib' in sys.modules, 'PIL' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.split() == ["False", "False"]


def test_the_trail_is_b2_s_path_up_to_the_frame():
    sequence, poses = random_plan(OPEN, Pose(5, 5, "I"), 12, seed=5)
    k = 2
    anim = animate_path(OPEN, sequence, Pose(5, 5, "I"), frames_per_step=k)
    for i in range(len(anim)):
        drawn = anim.draw_frame(i)
        assert anim.trail in drawn and drawn.index(anim.trail) < drawn.index(anim.robot)  # under the robot
        track = np.column_stack(anim.trail.get_data())
        step = int(anim.steps[i])
        assert np.array_equal(track[:-1], poses[: step + 1, :2])
        b2 = np.array([path.vertices[:4].mean(axis=0) for path in anim.robot.get_paths()])[1]
        assert np.allclose(track[-1], b2)  # then to where B2 is, mid-command
    assert np.array_equal(np.column_stack(anim.trail.get_data())[:-1], poses[:, :2])  # the last frame: the whole path
