"""Labelled tilesets (Le et al. 2018, shared/MODEL.md §6): tiles, their block cells a–d, and the text format.

The text lists the grid's rows top first, one whitespace-separated token per cell:

- ``#`` (or the paper's ``-1``): an obstacle;
- ``.``: a free cell no tile covers;
- ``<tile><block>``, e.g. ``12b``: a cell of tile 12 holding block b, with a, b, c, d = B1, B2, B3, B4;
- several labels joined by ``/``, e.g. ``3c/7a``: a cell two tiles of an overlapping tiling share.

Each tile must have exactly one cell for each of a, b, c and d, and its four cells must be a
tetromino. Tilesets htetro-opt writes label every tile with a robot footprint (a :class:`Pose`);
tilesets read from elsewhere are taken as given, whatever chain convention labelled them.

Examples
--------
>>> ts = parse_tileset('''
... 1c 1d #
... 1b 1a #
... ''')
>>> ts.ids, ts.shapes, ts.poses[0]
((1,), ('O',), Pose(x=0, y=0, shape='O', heading=1))
"""

from __future__ import annotations

import re
import reprlib
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from htetro_opt._files import write_text
from htetro_opt._validation import check_int, check_real
from htetro_opt.errors import OutputError, ParameterError, ScenarioError, TilesetFormatError
from htetro_opt.model.robot import Pose, as_pose
from htetro_opt.model.tiles import identify_tile, scan_key, tile_poses
from htetro_opt.model.workspace import Workspace
from htetro_opt.scenarios._paths import as_path

__all__ = ["Tileset", "BLOCK_LETTERS", "parse_tileset", "format_tileset", "load_tileset", "save_tileset",
           "check_tileset"]

BLOCK_LETTERS = "abcd"
"""Le et al. 2018's block names, in chain order: a, b, c, d = B1, B2, B3, B4 (b is the reference)."""

_LABEL = re.compile(r"^([1-9][0-9]*)([abcd])$")
_OBSTACLE_TOKENS = ("#", "-1")


@dataclass(frozen=True, eq=False)  # holds arrays: identity equality, hashable
class Tileset:
    """Tiles on a grid, each with the cells of its blocks a, b, c, d.

    Parameters
    ----------
    occupancy : ndarray of bool, shape (H, W)
        ``occ[y, x]``, True for an obstacle (row 0 is the bottom row).
    blocks : ndarray of int, shape (n, 4, 2)
        ``blocks[i, l]`` is the cell (x, y) of block l (0…3 = a…d) of tile ``ids[i]``.
    ids : tuple of int
        Tile labels, in the order of ``blocks``.
    cell_size : float
        d_grid in metres.
    name : str
        Where it came from (a scenario name or a file), for messages and plots.
    """

    occupancy: np.ndarray
    blocks: np.ndarray
    ids: tuple[int, ...]
    cell_size: float = 1.0
    name: str = ""

    def __post_init__(self) -> None:
        where = self.name or "tileset"
        if not isinstance(self.name, str):
            raise TilesetFormatError(f"a tileset's name must be a string, got {reprlib.repr(self.name)}")
        try:
            occ = Workspace(self.occupancy).occupancy.copy()
        except ScenarioError as err:
            raise TilesetFormatError(f"{where}: {err}") from err
        try:
            blocks = np.asarray(self.blocks)
            if (blocks.size and not np.issubdtype(blocks.dtype, np.integer)) or blocks.size % 8:
                raise ValueError
            blocks = blocks.astype(np.int64).reshape(-1, 4, 2)
            ids = tuple(check_int(i, "tile id") for i in self.ids)
        except (TypeError, ValueError) as err:  # ParameterError among them
            raise TilesetFormatError(f"{where}: blocks must be (n, 4, 2) integer cells and ids n integers, got blocks "
                                     f"{reprlib.repr(self.blocks)} and ids {reprlib.repr(self.ids)}") from err
        if len(ids) != len(blocks) or len(set(ids)) != len(ids):
            raise TilesetFormatError(f"{where}: need one distinct id per tile, got {len(ids)} ids for {len(blocks)} tiles")
        try:
            cell_size = check_real(self.cell_size, "cell size", minimum=0.0, include_minimum=False)
        except ParameterError as err:  # tilesets come from files: the loader's error
            raise TilesetFormatError(f"{where}: {err}") from err
        h, w = occ.shape
        for tile, cells in zip(ids, blocks):
            for letter, (x, y) in zip(BLOCK_LETTERS, cells.tolist()):
                if not (0 <= x < w and 0 <= y < h):
                    raise TilesetFormatError(f"{where}: block {tile}{letter} at ({x}, {y}) is outside the {w} x {h} grid")
                if occ[y, x]:
                    raise TilesetFormatError(f"{where}: block {tile}{letter} at ({x}, {y}) is on an obstacle")
            if identify_tile(cells) is None:
                raise TilesetFormatError(
                    f"{where}: the cells of tile {tile} ({', '.join(f'{tile}{b} at {tuple(c)}' for b, c in zip(BLOCK_LETTERS, cells.tolist()))}) "
                    "are not a tetromino"
                )
        for array in (occ, blocks):
            array.setflags(write=False)
        object.__setattr__(self, "occupancy", occ)
        object.__setattr__(self, "blocks", blocks)
        object.__setattr__(self, "ids", ids)
        object.__setattr__(self, "cell_size", cell_size)

    @classmethod
    def from_poses(cls, occupancy, poses, *, ids=None, cell_size: float = 1.0, name: str = "") -> "Tileset":
        """The tileset of robot poses: each pose's footprint is a tile, labelled B1–B4 = a–d.

        ``ids`` default to 1, 2, … in the order of ``poses``.

        Raises
        ------
        ConfigurationError, UnknownShapeError
            If an item of ``poses`` is not a pose (naming it, ``poses[i]``).
        """
        if isinstance(poses, (str, bytes, Pose)) or not isinstance(poses, Iterable):
            raise ParameterError(f"poses must be a sequence of poses, got {type(poses).__name__} {reprlib.repr(poses)}")
        poses = [as_pose(p, f"poses[{i}]") for i, p in enumerate(poses)]
        blocks = np.array([p.cells() for p in poses], dtype=np.int64).reshape(-1, 4, 2)
        ids = tuple(range(1, len(poses) + 1)) if ids is None else ids
        return cls(occupancy, blocks, ids, cell_size, name)

    @property
    def width(self) -> int:
        return self.occupancy.shape[1]

    @property
    def height(self) -> int:
        return self.occupancy.shape[0]

    def __len__(self) -> int:
        return len(self.ids)

    @property
    def shapes(self) -> tuple[str, ...]:
        """The morphology of each tile, from its cells (whatever their labels)."""
        return tuple(identify_tile(cells).shape for cells in self.blocks)

    @property
    def poses(self) -> tuple[Pose | None, ...]:
        """The robot pose whose footprint labels each tile as given, or None for a tile labelled by
        another chain convention than shared/MODEL.md's."""
        out = []
        for cells in self.blocks:
            match = [p for p in tile_poses(cells) if np.array_equal(p.cells(), cells)]
            out.append(match[0] if match else None)
        return tuple(out)

    @property
    def references(self) -> np.ndarray:
        """The cell of block b (the reference) of every tile, shape (n, 2)."""
        return self.blocks[:, 1]

    def coverage(self) -> np.ndarray:
        """How many tiles cover each cell, ``count[y, x]``."""
        count = np.zeros(self.occupancy.shape, dtype=np.int64)
        np.add.at(count, (self.blocks[..., 1].ravel(), self.blocks[..., 0].ravel()), 1)
        return count

    @property
    def complete(self) -> bool:
        """Whether every free cell is covered."""
        return bool((self.coverage()[~self.occupancy] > 0).all())

    @property
    def overlapping(self) -> bool:
        """Whether some cell is covered by more than one tile."""
        return bool((self.coverage() > 1).any())

    def index(self, tile_id: int) -> int:
        """Position in ``ids`` of a tile label.

        Raises
        ------
        TilesetFormatError
            If no tile has that label.
        """
        try:
            return self.ids.index(check_int(tile_id, "tile id"))
        except ValueError as err:  # ParameterError among them
            raise TilesetFormatError(
                f"{self.name or 'tileset'} has no tile {tile_id!r} (tiles {self.ids[0]}…{self.ids[-1]})"
                if self.ids else f"{self.name or 'tileset'} has no tiles"
            ) from err


def parse_tileset(text: str, *, where: str = "tileset", cell_size: float = 1.0) -> Tileset:
    """Read a labelled tileset from its text (see the module docstring for the format).

    Raises
    ------
    TilesetFormatError
        On ragged rows, an unknown token (naming its row and column, 1-based from the top), a label
        used twice, a tile missing one of its blocks a–d, or a tile whose cells are not a tetromino.
    """
    if not isinstance(text, str):
        raise TilesetFormatError(f"{where}: expected text, got {type(text).__name__}")
    rows = [line.split() for line in text.splitlines() if line.strip()]
    if not rows:
        raise TilesetFormatError(f"{where}: the tileset is empty")
    width = len(rows[0])
    for r, row in enumerate(rows, start=1):
        if len(row) != width:
            raise TilesetFormatError(f"{where}: row {r} has {len(row)} tokens, row 1 has {width} (ragged rows)")
    height = len(rows)
    occ = np.zeros((height, width), dtype=bool)
    cells: dict[int, dict[str, tuple[int, int]]] = {}
    for r, row in enumerate(rows, start=1):
        y = height - r
        for c, token in enumerate(row, start=1):
            x = c - 1
            if token in _OBSTACLE_TOKENS:
                occ[y, x] = True
                continue
            if token == ".":
                continue
            for label in token.split("/"):
                match = _LABEL.match(label)
                if match is None:
                    raise TilesetFormatError(
                        f"{where}: unknown token {token!r} at row {r}, column {c} "
                        "(expected '#', '-1', '.', or labels such as '12b' joined by '/')"
                    )
                tile, block = int(match[1]), match[2]
                blocks = cells.setdefault(tile, {})
                if block in blocks:
                    (x0, y0) = blocks[block]
                    raise TilesetFormatError(
                        f"{where}: label {label!r} appears twice, at row {height - y0}, column {x0 + 1} "
                        f"and at row {r}, column {c}"
                    )
                blocks[block] = (x, y)
    for tile, blocks in cells.items():
        missing = [b for b in BLOCK_LETTERS if b not in blocks]
        if missing:
            raise TilesetFormatError(
                f"{where}: tile {tile} has no block {', '.join(missing)} "
                f"(it has {', '.join(f'{tile}{b}' for b in BLOCK_LETTERS if b in blocks)})"
            )
    order = sorted(cells, key=lambda t: scan_key(min((cells[t][b] for b in BLOCK_LETTERS), key=scan_key)))
    blocks = np.array([[cells[t][b] for b in BLOCK_LETTERS] for t in order], dtype=np.int64).reshape(-1, 4, 2)
    return Tileset(occ, blocks, tuple(order), cell_size, where)


def format_tileset(tileset: Tileset) -> str:
    """The text of a tileset, columns aligned; :func:`parse_tileset` reads it back unchanged.

    Examples
    --------
    >>> print(format_tileset(parse_tileset("1a 1b\\n1d 1c\\n# #")))
    1a 1b
    1d 1c
    #  #
    """
    check_tileset(tileset)
    labels: dict[tuple[int, int], list[str]] = {}
    for tile, cells in zip(tileset.ids, tileset.blocks):
        for letter, (x, y) in zip(BLOCK_LETTERS, cells.tolist()):
            labels.setdefault((x, y), []).append(f"{tile}{letter}")
    grid = []
    for y in range(tileset.height - 1, -1, -1):
        row = []
        for x in range(tileset.width):
            if tileset.occupancy[y, x]:
                row.append("#")
            else:
                row.append("/".join(labels.get((x, y), ["."])))
        grid.append(row)
    widths = [max(len(row[c]) for row in grid) for c in range(tileset.width)]
    return "\n".join(" ".join(t.ljust(w) for t, w in zip(row, widths)).rstrip() for row in grid)


def load_tileset(path: str | Path, *, cell_size: float = 1.0) -> Tileset:
    """Read a labelled tileset file.

    Raises
    ------
    ScenarioError
        If the file cannot be read.
    TilesetFormatError
        If its content is malformed (see :func:`parse_tileset`).
    """
    path = as_path(path, "path")
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as err:
        raise ScenarioError(f"cannot read tileset {str(path)!r}: {err}") from err
    return parse_tileset(text, where=str(path), cell_size=cell_size)


def save_tileset(tileset: Tileset, path: str | Path) -> None:
    """Write a tileset's text to a file in one step (nothing half-written is left behind).

    Raises
    ------
    OutputError
        If the file cannot be written (or ``path`` is not a path).
    ParameterError
        If ``tileset`` is not a Tileset.
    """
    check_tileset(tileset)
    write_text(as_path(path, "path", OutputError), format_tileset(tileset) + "\n", what="tileset")


def check_tileset(tileset, name: str = "tileset") -> Tileset:
    """``tileset`` itself if it is a :class:`Tileset`: the one check of every argument that takes one.

    Raises
    ------
    ParameterError
        Naming ``name`` and what it got.
    """
    if not isinstance(tileset, Tileset):
        raise ParameterError(f"{name} must be a Tileset (e.g. from load_tileset or tile_workspace), "
                             f"got {type(tileset).__name__} {reprlib.repr(tileset)}")
    return tileset
