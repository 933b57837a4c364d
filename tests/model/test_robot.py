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


@pytest.mark.parametrize("make", [Pose, Pose.of], ids=["Pose", "Pose.of"])
@pytest.mark.parametrize("fields,error,words", [
    ((1, 2, "Q", 0), UnknownShapeError, "unknown shape 'Q'"),
    ((1, 2, None, 0), UnknownShapeError, "unknown shape None"),
    ((1, 2, "O", 4), ConfigurationError, "heading must be 0, 1, 2 or 3 (quarter turns), got 4"),
    ((1, 2, "O", -1), ConfigurationError, "got -1"),
    ((1, 2, "O", 1.0), ConfigurationError, "pose heading must be an integer, got 1.0"),
    ((1.5, 2, "O", 0), ConfigurationError, "pose x must be an integer, got 1.5"),
    (("1", 2, "O", 0), ConfigurationError, "pose x must be an integer, got '1'"),
    ((1, True, "O", 0), ConfigurationError, "pose y must be an integer, got True"),
])
def test_every_way_of_making_a_pose_validates_it(make, fields, error, words):
    with pytest.raises(error) as info:
        make(*fields)
    assert words in str(info.value)


def test_a_made_pose_is_canonical_and_survives_copies():
    pose = Pose(np.int64(3), np.int32(4), np.str_("L"), np.int8(1))
    assert pose == (3, 4, "L", 1) and all(type(v) is t for v, t in zip(pose, (int, int, str, int)))
    assert Pose(3, 4, "O") == Pose.of(3, 4, "O") == Pose(3, 4, "O", 0)
    assert pose._replace(heading=2) == Pose(3, 4, "L", 2)
    with pytest.raises(ConfigurationError, match="got 7"):
        pose._replace(heading=7)
    with pytest.raises(UnknownShapeError):
        Pose._make((0, 0, "Q", 0))
    import copy
    import pickle

    for twin in (pickle.loads(pickle.dumps(pose)), copy.deepcopy(pose), copy.copy(pose)):
        assert twin == pose and type(twin) is Pose
    assert repr(pose) == "Pose(x=3, y=4, shape='L', heading=1)"


def test_the_unknown_shape_error_names_the_intermediate_states():
    with pytest.raises(UnknownShapeError) as info:
        shape_index("X")
    message = str(info.value)
    assert "I, O, L, J, Z, S, T" in message and "intermediate state such as h112" in message
    assert "Cheng et al. 2019" in message and "seed" not in message
    assert Pose(0, 0, "h112", 0).shape == "h112"  # the intermediates themselves are poses


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
