"""hTetro robot geometry: hinge kinematics, morphologies and cell footprints (shared/MODEL.md §2).

The robot is a chain B1–H1–B2–H2–B3–H3–B4 of unit squares. In B2's frame (B2's centre at the origin,
θB2 = 0) the I-shape has block centres B1 (0, −1), B2 (0, 0), B3 (0, 1), B4 (0, 2) and hinges
H1 (½, −½), H2 (½, ½), H3 (−½, 3/2). B1 turns about H1 by θB1 − θB2 = θH1 − π/2; B3 (carrying H3 and
B4) turns about H2 by θB3 − θB2 = π/2 − θH2; B4 turns about H3 by θB4 − θB3 = θH3 − π/2. Hinge angles
stay in [π/2, 3π/2], so each relative turn is unambiguous.

A *hinge state* is a triple of hinge angles in units of π/2, each 1, 2 or 3. The 23 triples whose
blocks occupy four distinct cells are the robot's *states*; the first seven are the named
morphologies of Table 1 of Cheng et al. 2020 (I, O, L, J, Z, S, T), the rest are the intermediate states
Cheng et al. 2019's single-block commands pass through, named ``h`` + the triple (e.g. ``h213``).
"""

from __future__ import annotations

import itertools
import math
import reprlib

import numpy as np

from collections.abc import Sequence
from typing import NamedTuple

from htetro_opt._validation import check_int
from htetro_opt.errors import ConfigurationError, ParameterError, UnknownShapeError

__all__ = [
    "Pose",
    "SHAPES",
    "STATE_NAMES",
    "HINGE_STATES",
    "N_NAMED",
    "N_STATES",
    "N_HEADINGS",
    "FOOTPRINTS",
    "shape_index",
    "as_pose",
    "block_poses",
    "rotate_cells",
]

SHAPES: tuple[str, ...] = ("I", "O", "L", "J", "Z", "S", "T")
"""The seven named morphologies, in the order used for every shape index."""

_NAMED_HINGES = {
    "I": (1, 1, 1),
    "O": (1, 3, 1),
    "L": (3, 1, 1),
    "J": (3, 2, 3),
    "Z": (3, 1, 3),
    "S": (3, 2, 1),
    "T": (2, 3, 3),
}
N_HEADINGS = 4

_I_CENTRES = np.array([[0.0, -1.0], [0.0, 0.0], [0.0, 1.0], [0.0, 2.0]])
_H1 = np.array([0.5, -0.5])
_H2 = np.array([0.5, 0.5])
_H3 = np.array([-0.5, 1.5])


def _rotate_about(points: np.ndarray, angle: np.ndarray, pivot: np.ndarray) -> np.ndarray:
    """Rotate ``points[..., 2]`` by ``angle[...]`` (radians, CCW) about ``pivot[..., 2]``."""
    cos, sin = np.cos(angle), np.sin(angle)
    d = points - pivot
    return pivot + np.stack([cos * d[..., 0] - sin * d[..., 1], sin * d[..., 0] + cos * d[..., 1]], -1)


def block_poses(hinges, heading=0.0):
    """Block centres and block angles for hinge angles and a heading, in B2's frame.

    Parameters
    ----------
    hinges : array_like, shape (..., 3)
        Hinge angles θH1, θH2, θH3 in radians (any real values; batch dimensions allowed).
    heading : array_like, shape (...)
        θB2 in radians: the whole robot is turned by it counter-clockwise about B2's centre.

    Returns
    -------
    centres : ndarray, shape (..., 4, 2)
        Centres of B1–B4 relative to B2's centre.
    angles : ndarray, shape (..., 4)
        Block angles θB1–θB4 in radians.

    Examples
    --------
    >>> centres, _ = block_poses(np.array([1, 3, 1]) * np.pi / 2)  # the O-shape
    >>> np.rint(centres).astype(int).tolist()
    [[0, -1], [0, 0], [1, 0], [1, -1]]
    """
    try:
        hinges = np.asarray(hinges, dtype=float)
        if hinges.ndim == 0 or hinges.shape[-1] != 3:
            raise ValueError
    except (TypeError, ValueError) as err:
        raise ParameterError(f"hinges must be an array of hinge-angle triples, shape (..., 3), "
                             f"got {reprlib.repr(hinges)}") from err
    try:
        heading = np.broadcast_to(np.asarray(heading, dtype=float), hinges.shape[:-1])
    except (TypeError, ValueError) as err:
        raise ParameterError(f"heading must be a number or an array of shape {hinges.shape[:-1]}, "
                             f"got {reprlib.repr(heading)}") from err
    turn1 = hinges[..., 0] - math.pi / 2
    turn3 = math.pi / 2 - hinges[..., 1]
    turn4 = hinges[..., 2] - math.pi / 2
    shape = hinges.shape[:-1]
    b1 = _rotate_about(np.broadcast_to(_I_CENTRES[0], shape + (2,)), turn1, _H1)
    b3 = _rotate_about(np.broadcast_to(_I_CENTRES[2], shape + (2,)), turn3, _H2)
    h3 = _rotate_about(np.broadcast_to(_H3, shape + (2,)), turn3, _H2)
    b4 = _rotate_about(np.broadcast_to(_I_CENTRES[3], shape + (2,)), turn3, _H2)
    b4 = _rotate_about(b4, turn4, h3)
    b2 = np.zeros(shape + (2,))
    centres = np.stack([b1, b2, b3, b4], axis=-2)
    centres = _rotate_about(centres, heading[..., None], np.zeros(2))
    angles = np.stack([turn1, np.zeros(shape), turn3, turn3 + turn4], axis=-1) + heading[..., None]
    return centres, angles


def _legal_hinge_states() -> list[tuple[int, int, int]]:
    named = [_NAMED_HINGES[s] for s in SHAPES]
    rest = []
    for triple in itertools.product((1, 2, 3), repeat=3):
        if triple in named:
            continue
        centres, _ = block_poses(np.array(triple) * math.pi / 2)
        if len({tuple(c) for c in np.rint(centres).astype(int).tolist()}) == 4:
            rest.append(triple)
    return named + rest


HINGE_STATES: tuple[tuple[int, int, int], ...] = tuple(_legal_hinge_states())
"""Hinge triples (units of π/2) of every legal state: the 7 named shapes, then the intermediates."""
STATE_NAMES: tuple[str, ...] = SHAPES + tuple("h" + "".join(map(str, t)) for t in HINGE_STATES[len(SHAPES):])
N_NAMED = len(SHAPES)
N_STATES = len(HINGE_STATES)
_STATE_INDEX = {name: i for i, name in enumerate(STATE_NAMES)}
_STATE_BY_HINGES = {triple: i for i, triple in enumerate(HINGE_STATES)}


def rotate_cells(cells: np.ndarray, heading: int) -> np.ndarray:
    """Turn integer cell offsets ``(..., 2)`` by ``heading`` quarter turns counter-clockwise."""
    cells = np.asarray(cells)
    x, y = cells[..., 0], cells[..., 1]
    for _ in range(heading % 4):
        x, y = -y, x
    return np.stack([x, y], axis=-1)


def _footprints() -> np.ndarray:
    centres, _ = block_poses(np.array(HINGE_STATES, dtype=float) * math.pi / 2)
    base = np.rint(centres).astype(np.int64)
    table = np.stack([rotate_cells(base, h) for h in range(N_HEADINGS)], axis=1)
    table.setflags(write=False)
    return table


FOOTPRINTS: np.ndarray = _footprints()
"""Cell offsets of (B1, B2, B3, B4) from B2, indexed ``[state, heading, block, (x, y)]``."""


def shape_index(name: str) -> int:
    """Index of a state name (``"I"`` … ``"T"`` or an intermediate such as ``"h213"``).

    Raises
    ------
    UnknownShapeError
        If ``name`` is not a state of the robot.

    Examples
    --------
    >>> shape_index("O")
    1
    >>> shape_index("Q")
    Traceback (most recent call last):
    ...
    htetro_opt.errors.UnknownShapeError: unknown shape 'Q': expected one of I, O, L, J, Z, S, T (or an intermediate state such as h112 with Cheng et al. 2019's block commands)
    """
    try:
        return _STATE_INDEX[name]
    except (KeyError, TypeError) as err:
        raise UnknownShapeError(
            f"unknown shape {name!r}: expected one of {', '.join(SHAPES)} (or an intermediate state such as "
            f"{STATE_NAMES[N_NAMED]} with Cheng et al. 2019's block commands)"
        ) from err


def _pose_int(value, name: str) -> int:
    """A pose's integer field (x, y or heading): a ConfigurationError naming it otherwise."""
    if type(value) is int:  # the common case, checked without the option machinery
        return value
    try:
        return check_int(value, f"pose {name}")
    except ParameterError as err:  # a pose is a configuration: keep the error its callers catch
        raise ConfigurationError(str(err)) from err


class _PoseFields(NamedTuple):
    x: int
    y: int
    shape: str
    heading: int


class Pose(_PoseFields):
    """A robot configuration on the grid: B2's cell, the state name and the heading (quarter turns).

    Every pose is validated when it is made, whichever way (``Pose(...)``, :meth:`of`,
    :meth:`from_q`, ``_replace``): integer coordinates, a known state, a heading in 0…3. Integer
    types such as ``numpy.int64`` become plain ints.

    Raises
    ------
    ConfigurationError
        If x, y or heading are not integers or the heading is outside 0…3.
    UnknownShapeError
        If the shape is not a state of the robot.

    Examples
    --------
    >>> Pose(3, 4, "O", 0)
    Pose(x=3, y=4, shape='O', heading=0)
    >>> Pose(3, 4, "O", 4)
    Traceback (most recent call last):
    ...
    htetro_opt.errors.ConfigurationError: pose heading must be 0, 1, 2 or 3 (quarter turns), got 4
    """

    __slots__ = ()

    def __new__(cls, x, y, shape, heading=0):
        if type(shape) is not str or shape not in _STATE_INDEX:
            shape_index(shape)  # raises, naming the shape
            shape = str(shape)  # a str subclass such as numpy.str_
        x, y, heading = _pose_int(x, "x"), _pose_int(y, "y"), _pose_int(heading, "heading")
        if not 0 <= heading < N_HEADINGS:
            raise ConfigurationError(f"pose heading must be 0, 1, 2 or 3 (quarter turns), got {heading}")
        return tuple.__new__(cls, (x, y, shape, heading))

    @classmethod
    def _make(cls, iterable) -> "Pose":  # namedtuple's own skips __new__ (and ``_replace`` uses it)
        return cls(*iterable)

    @classmethod
    def of(cls, x, y, shape, heading=0) -> "Pose":
        """A validated pose, the heading 0 unless given (the same checks as ``Pose(...)``).

        Examples
        --------
        >>> Pose.of(3, 4, "O")
        Pose(x=3, y=4, shape='O', heading=0)
        """
        return cls(x, y, shape, heading)

    @classmethod
    def from_q(cls, q) -> "Pose":
        """The pose of a configuration q = (x, y, θB1, θB2, θB3, θB4) (MODEL.md §2).

        The angles are radians, multiples of π/2; θB2 gives the heading and the hinge angles
        θH1 = π/2 + θB1 − θB2, θH2 = π/2 + θB2 − θB3, θH3 = π/2 + θB4 − θB3 (taken modulo 2π) give the
        state.

        Raises
        ------
        ConfigurationError
            If an angle is not a multiple of π/2, a hinge leaves [π/2, 3π/2], or two blocks overlap.

        Examples
        --------
        >>> Pose.from_q((3, 4, 0, 0, -np.pi, -np.pi))  # Cheng et al. 2019's O-shape
        Pose(x=3, y=4, shape='O', heading=0)
        """
        try:
            x, y, *angles = q
            if len(angles) != 4:
                raise ValueError
            quarters = np.asarray(angles, dtype=float) / (math.pi / 2)
        except (TypeError, ValueError) as err:
            raise ConfigurationError(f"q must be six numbers (x, y, θB1, θB2, θB3, θB4), "
                                     f"got {reprlib.repr(q)}") from err
        if not np.allclose(quarters, np.rint(quarters), atol=1e-9):
            raise ConfigurationError(f"block angles must be multiples of π/2, got {list(angles)}")
        b1, b2, b3, b4 = (int(v) for v in np.rint(quarters))
        hinges = tuple((1 + d) % 4 for d in (b1 - b2, b2 - b3, b4 - b3))
        if hinges not in _STATE_BY_HINGES:
            raise ConfigurationError(
                f"q {tuple(q)} has hinge angles {tuple(h * 90 for h in hinges)}° outside [90°, 270°] "
                "or overlapping blocks"
            )
        return cls(x, y, STATE_NAMES[_STATE_BY_HINGES[hinges]], b2 % N_HEADINGS)

    @property
    def q(self) -> tuple[int, int, float, float, float, float]:
        """The configuration (x, y, θB1, θB2, θB3, θB4), angles in radians with θB2 in [0, 2π)."""
        h1, h2, h3 = HINGE_STATES[shape_index(self.shape)]
        b2 = self.heading
        b1, b3 = b2 + h1 - 1, b2 - h2 + 1
        b4 = b3 + h3 - 1
        return (self.x, self.y, *(float(b * math.pi / 2) for b in (b1, b2, b3, b4)))

    def cells(self) -> np.ndarray:
        """Cells (x, y) of B1, B2, B3, B4, shape (4, 2)."""
        return FOOTPRINTS[shape_index(self.shape), self.heading] + (self.x, self.y)

    def as_dict(self) -> dict:
        return {"x": self.x, "y": self.y, "shape": self.shape, "heading": self.heading}


def as_pose(value, name: str = "pose") -> Pose:
    """``value`` as a :class:`Pose`: a Pose as it is, or a sequence ``(x, y, shape[, heading])``.

    The one check of every argument that takes a pose (a start, a goal, a roadmap's entries).

    Raises
    ------
    ConfigurationError
        Naming ``name``, if ``value`` is not a pose or a sequence of three or four fields, or a
        field is invalid.
    UnknownShapeError
        Naming ``name``, if the shape is not a state of the robot.

    Examples
    --------
    >>> as_pose((1, 2, "O"))
    Pose(x=1, y=2, shape='O', heading=0)
    >>> as_pose("O", "start")
    Traceback (most recent call last):
    ...
    htetro_opt.errors.ConfigurationError: start must be a Pose or (x, y, shape, heading), got 'O'
    """
    if isinstance(value, Pose):
        return value
    if isinstance(value, (str, bytes)) or not isinstance(value, (Sequence, np.ndarray)) or len(value) not in (3, 4):
        raise ConfigurationError(f"{name} must be a Pose or (x, y, shape, heading), got {reprlib.repr(value)}")
    try:
        return Pose(*value) if len(value) == 4 else Pose(*value, 0)
    except UnknownShapeError as err:
        raise UnknownShapeError(f"{name}: {err}") from err
    except ConfigurationError as err:
        raise ConfigurationError(f"{name}: {err}") from err
