"""The robot geometry against shared/MODEL.md §2."""

import math

import numpy as np
import pytest

from htetro_opt.errors import ConfigurationError, UnknownShapeError
from htetro_opt.model.robot import (
    FOOTPRINTS,
    HINGE_STATES,
    N_STATES,
    SHAPES,
    STATE_NAMES,
    Pose,
    block_poses,
    rotate_cells,
    shape_index,
)

# MODEL.md §2, footprint table: offsets of (B1, B2, B3, B4) from B2 at heading 0.
MODEL_FOOTPRINTS = {
    "I": [(0, -1), (0, 0), (0, 1), (0, 2)],
    "O": [(0, -1), (0, 0), (1, 0), (1, -1)],
    "L": [(1, 0), (0, 0), (0, 1), (0, 2)],
    "J": [(1, 0), (0, 0), (1, 1), (1, 2)],
    "Z": [(1, 0), (0, 0), (0, 1), (-1, 1)],
    "S": [(1, 0), (0, 0), (1, 1), (2, 1)],
    "T": [(1, -1), (0, 0), (1, 0), (2, 0)],
}
# seed 000 Table 1 hinge-angle triples, in units of π/2.
TABLE_1 = {"I": (1, 1, 1), "O": (1, 3, 1), "L": (3, 1, 1), "J": (3, 2, 3), "Z": (3, 1, 3), "S": (3, 2, 1), "T": (2, 3, 3)}


@pytest.mark.parametrize("shape", SHAPES)
def test_footprint_table_of_model_md(shape):
    assert FOOTPRINTS[shape_index(shape), 0].tolist() == [list(c) for c in MODEL_FOOTPRINTS[shape]]


@pytest.mark.parametrize("shape", SHAPES)
def test_named_states_use_the_hinge_triples_of_table_1(shape):
    assert HINGE_STATES[shape_index(shape)] == TABLE_1[shape]


def test_hinge_kinematics_yield_the_footprints_with_no_overlap():
    centres, angles = block_poses(np.array(HINGE_STATES, dtype=float) * math.pi / 2)
    assert np.allclose(centres, np.rint(centres))  # blocks sit on cells
    assert np.allclose(np.sin(2 * angles), 0)  # and are axis-aligned
    for s in range(N_STATES):
        cells = {tuple(c) for c in np.rint(centres[s]).astype(int).tolist()}
        assert len(cells) == 4


def test_seed_004_angle_notation_agrees():
    # vertical I = (0, 0, 0, 0), O = (0, 0, −π, −π), horizontal I = (−π/2, …): block angles.
    _, angles = block_poses(np.array(TABLE_1["O"]) * math.pi / 2)
    assert np.allclose(angles, [0, 0, -math.pi, -math.pi])
    _, angles = block_poses(np.array(TABLE_1["I"]) * math.pi / 2, -math.pi / 2)
    assert np.allclose(angles, [-math.pi / 2] * 4)


def test_23_legal_states_and_every_hinge_within_limits():
    assert N_STATES == 23 and len(set(HINGE_STATES)) == 23
    assert all(1 <= v <= 3 for triple in HINGE_STATES for v in triple)
    assert STATE_NAMES[:7] == SHAPES


def test_headings_turn_the_footprint_counter_clockwise():
    i = shape_index("L")
    for h in range(4):
        assert FOOTPRINTS[i, h].tolist() == rotate_cells(FOOTPRINTS[i, 0], h).tolist()
    assert FOOTPRINTS[shape_index("I"), 1].tolist() == [[1, 0], [0, 0], [-1, 0], [-2, 0]]


def test_footprints_are_the_seven_one_sided_tetrominoes():
    def canonical(cells):
        variants = []
        for h in range(4):
            c = rotate_cells(np.array(cells), h)
            c = c - c.min(axis=0)
            variants.append(tuple(sorted(map(tuple, c.tolist()))))
        return min(variants)

    names = {canonical(MODEL_FOOTPRINTS[s]) for s in SHAPES}
    assert len(names) == 7  # no two named shapes are rotations of each other


def test_unknown_shape_and_bad_poses_raise_typed_errors():
    with pytest.raises(UnknownShapeError, match="'Q'"):
        shape_index("Q")
    with pytest.raises(ConfigurationError, match="heading"):
        Pose.of(0, 0, "O", 4)
    with pytest.raises(ConfigurationError, match="x"):
        Pose.of(0.5, 0, "O", 0)


@pytest.mark.parametrize("q,expected", [
    ((0, 0, 0, 0, 0, 0), ("I", 0)),  # seed 004's vertical I
    ((0, 0, 0, 0, -math.pi, -math.pi), ("O", 0)),  # seed 004's O
    ((0, 0, -math.pi / 2, -math.pi / 2, -math.pi / 2, -math.pi / 2), ("I", 3)),  # horizontal I
])
def test_pose_from_seed_004_configurations(q, expected):
    pose = Pose.from_q(q)
    assert (pose.shape, pose.heading) == expected


@pytest.mark.parametrize("state", range(N_STATES))
@pytest.mark.parametrize("heading", range(4))
def test_q_round_trips_and_gives_the_footprint(state, heading):
    pose = Pose(2, 3, STATE_NAMES[state], heading)
    assert Pose.from_q(pose.q) == pose
    x, y, *angles = pose.q
    hinges = (math.pi / 2 + angles[0] - angles[1], math.pi / 2 + angles[1] - angles[2], math.pi / 2 + angles[3] - angles[2])
    centres, _ = block_poses(np.array(hinges), angles[1])
    assert np.rint(centres).astype(int).tolist() == (pose.cells() - (x, y)).tolist()


@pytest.mark.parametrize("q,words", [
    ((0, 0, 0.1, 0, 0, 0), "multiples of π/2"),
    ((0, 0, -math.pi / 2, 0, 0, 0), "outside"),  # θH1 = 0: B1 would fold past B2
    ((0, 0, math.pi, 0, -math.pi, -math.pi), "overlapping"),  # hinges (3π/2, 3π/2, π/2): B1 on B3
    ((0, 0, 0, 0, 0), "θB4"),
])
def test_bad_configurations_are_rejected(q, words):
    with pytest.raises(ConfigurationError, match=words):
        Pose.from_q(q)
