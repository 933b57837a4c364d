"""Tetromino tiles and the robot poses that fill them (Le et al. 2018, §3.1; shared/MODEL.md §2).

A *tile* is a set of four free cells covered by the robot in one of its seven morphologies. The
robot's footprints (:data:`~htetro_opt.model.robot.FOOTPRINTS`) give each morphology 1 (O), 2 (I, S, Z)
or 4 (L, J, T) distinct cell patterns, 19 in all: the fixed tetrominoes. A pattern is filled by the
poses whose footprint covers exactly its cells: one pose for L, J and T, two for I, S and Z, four for
O. Le et al. 2018 call these the block-location *options* of a tiling pattern (its Figs. 7 and 8).

Scan order is the order the paper's Algorithm 1 numbers tiles in: the top row first, each row from
left to right, i.e. by ``(-y, x)``.
"""

from __future__ import annotations

import reprlib
from collections.abc import Iterable
from typing import NamedTuple

import numpy as np

from htetro_opt.errors import ConfigurationError, ParameterError
from htetro_opt.model.robot import FOOTPRINTS, N_HEADINGS, SHAPES, Pose, shape_index

__all__ = ["Pattern", "PATTERNS", "patterns_of", "identify_tile", "tile_poses", "scan_key"]


class Pattern(NamedTuple):
    """One fixed tetromino: a shape, its cells relative to its first cell in scan order, and the
    headings of the robot poses that fill it.

    ``cells[0]`` is ``(0, 0)`` and the cells are in scan order, so a pattern anchored at the first
    free cell of a grid in scan order covers that cell and nothing before it.
    ``anchors[k]`` is B2's offset from ``cells[0]`` for ``headings[k]``.
    """

    shape: str
    cells: np.ndarray
    headings: tuple[int, ...]
    anchors: np.ndarray


def scan_key(cell) -> tuple[int, int]:
    """Sort key of a cell ``(x, y)`` in scan order: top row first, then left to right."""
    return (-int(cell[1]), int(cell[0]))


def _patterns() -> tuple[Pattern, ...]:
    found: dict[tuple, dict] = {}
    for shape in SHAPES:
        s = shape_index(shape)
        for heading in range(N_HEADINGS):
            cells = sorted(map(tuple, FOOTPRINTS[s, heading].tolist()), key=scan_key)
            first = np.array(cells[0])
            key = (shape, tuple(tuple(c) for c in (np.array(cells) - first).tolist()))
            entry = found.setdefault(key, {"headings": [], "anchors": []})
            entry["headings"].append(heading)
            entry["anchors"].append(-first)
    out = []
    for (shape, cells), entry in found.items():
        rel = np.array(cells, dtype=np.int64)
        anchors = np.array(entry["anchors"], dtype=np.int64)
        rel.setflags(write=False)
        anchors.setflags(write=False)
        out.append(Pattern(shape, rel, tuple(entry["headings"]), anchors))
    return tuple(out)


PATTERNS: tuple[Pattern, ...] = _patterns()
"""The 19 fixed tetrominoes the robot can fill, in the order of :data:`SHAPES` then heading."""

_BY_CELLS = {tuple(map(tuple, p.cells.tolist())): p for p in PATTERNS}


def patterns_of(shapes=None) -> tuple[Pattern, ...]:
    """The patterns of the given morphologies (all seven when ``shapes`` is None).

    Parameters
    ----------
    shapes : iterable of str, optional
        Morphology names, e.g. ``"TZ"`` or ``["O"]``.

    Raises
    ------
    UnknownShapeError
        If a name is not a state of the robot.
    ConfigurationError
        If a name is one of the intermediate states (of Cheng et al. 2019's block commands), which
        tile nothing.
    ParameterError
        If ``shapes`` is not a string or a sequence of names.

    Examples
    --------
    >>> [p.shape for p in patterns_of("OI")]
    ['I', 'I', 'O']
    """
    if shapes is None:
        return PATTERNS
    if isinstance(shapes, bytes) or not isinstance(shapes, Iterable):
        raise ParameterError(f"shapes must be morphology names such as 'TZ' or ['O'], "
                             f"got {type(shapes).__name__} {reprlib.repr(shapes)}")
    wanted = set()
    for name in shapes:
        if shape_index(name) >= len(SHAPES):
            raise ConfigurationError(f"{name!r} is an intermediate state (of Cheng et al. 2019's block commands), "
                                 f"not a tile shape ({', '.join(SHAPES)})")
        wanted.add(name)
    return tuple(p for p in PATTERNS if p.shape in wanted)


def _cell_array(cells) -> np.ndarray:
    """(x, y) integer pairs as an (n, 2) int64 array."""
    try:
        array = np.asarray(cells)
        ok = array.size == 0 or (np.issubdtype(array.dtype, np.integer) and array.ndim >= 1 and array.shape[-1] == 2)
    except (TypeError, ValueError):
        ok = False
    if not ok:
        raise ConfigurationError(f"cells must be (x, y) integer pairs, got {reprlib.repr(cells)}")
    return array.astype(np.int64, copy=False).reshape(-1, 2)


def identify_tile(cells) -> Pattern | None:
    """The pattern of four cells ``(x, y)``, or None if they are not a tetromino.

    Examples
    --------
    >>> identify_tile([(2, 2), (3, 2), (2, 1), (3, 1)]).shape
    'O'
    >>> identify_tile([(0, 0), (2, 0), (3, 0), (4, 0)]) is None
    True

    Raises
    ------
    ConfigurationError
        If ``cells`` are not (x, y) integer pairs.
    """
    cells = sorted(map(tuple, _cell_array(cells).tolist()), key=scan_key)
    if len(cells) != 4:
        return None
    first = np.array(cells[0])
    return _BY_CELLS.get(tuple(map(tuple, (np.array(cells) - first).tolist())))


def tile_poses(cells) -> tuple[Pose, ...]:
    """The robot poses whose footprint covers exactly these four cells (1, 2 or 4 of them).

    Raises
    ------
    ConfigurationError
        If the cells are not a tetromino.

    Examples
    --------
    >>> [p.heading for p in tile_poses([(0, 0), (1, 0), (0, 1), (1, 1)])]
    [0, 1, 2, 3]
    """
    pattern = identify_tile(cells)
    if pattern is None:
        raise ConfigurationError(f"cells {np.asarray(cells).tolist()} are not a tetromino")
    first = min(map(tuple, _cell_array(cells).tolist()), key=scan_key)
    return tuple(
        Pose(int(first[0] + a[0]), int(first[1] + a[1]), pattern.shape, h)
        for h, a in zip(pattern.headings, pattern.anchors)
    )
