"""Waypoint sequencing (Le et al. 2018): tiles become waypoints, and their order is an open-path TSP.

- **Block locations** (Algorithm 1): tiles are visited in scan order (top row first, left to right);
  a tile with one filling pose (L, J, T) takes it, a symmetric tile (I, S, Z: 2 options, O: 4) takes
  the option of least eq.-2 cost to the previous tile's blocks (eq. 3). The first tile, which has no
  previous one, takes its first option (the lowest heading): a choice of ours.
- **Cost** (eqs. 1–2): moving from waypoint i to waypoint j costs
  ``α D_a + β D_b + λ D_c + γ D_d``, ``D_l`` the Euclidean distance between block l's cells at i and
  at j (in cells). The weights default to 0.25 each.
- **Sequencing** (eq. 4): the order visiting every waypoint once, from a start tile (tile 1 by
  default, or free), that minimises the summed cost. The path is open: it does not return.

:class:`SequencingInstance` holds one instance for every sequencing method (cost matrix, block cells, start);
:class:`SequencingProblem` poses it as a pymoo permutation problem.
"""

from __future__ import annotations

import reprlib
from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

from htetro_opt._validation import check_int
from htetro_opt.errors import ConfigurationError, ParameterError, PlanningError
from htetro_opt.model.tiles import scan_key, tile_poses
from htetro_opt.scenarios.tileset import Tileset, check_tileset

__all__ = [
    "DEFAULT_BLOCK_WEIGHTS",
    "check_weights",
    "block_locations",
    "cost_matrix",
    "path_cost",
    "SequencingInstance",
    "check_instance",
]

DEFAULT_BLOCK_WEIGHTS = (0.25, 0.25, 0.25, 0.25)
"""α, β, λ, γ of eq. 2: every block counts the same."""


def check_weights(weights) -> np.ndarray:
    """The eq.-2 weights (α, β, λ, γ) as an array, validated.

    Raises
    ------
    ParameterError
        Unless there are four finite, non-negative weights with a positive sum. (The paper's weights
        sum to 1; others are accepted as given, not rescaled.)

    Examples
    --------
    >>> check_weights([0, 1, 0, 0]).tolist()
    [0.0, 1.0, 0.0, 0.0]
    """
    try:
        w = np.array(weights, dtype=float).reshape(-1)
    except (TypeError, ValueError) as err:
        raise ParameterError(f"weights must be four numbers (α, β, λ, γ), got {weights!r}") from err
    if w.shape != (4,) or not np.isfinite(w).all() or (w < 0).any() or w.sum() <= 0:
        raise ParameterError(
            f"weights must be four finite, non-negative numbers (α, β, λ, γ) with a positive sum, got {w.tolist()}"
        )
    return w


def cost_matrix(blocks, weights=DEFAULT_BLOCK_WEIGHTS) -> np.ndarray:
    """Eq. 2 between every pair of waypoints: ``C[i, j] = Σ_l w_l ‖blocks[i, l] − blocks[j, l]‖``.

    Parameters
    ----------
    blocks : array_like, shape (n, 4, 2)
        Cells of blocks a, b, c, d at each waypoint.
    weights : sequence of 4 float
        α, β, λ, γ.

    Returns
    -------
    ndarray of float, shape (n, n)
        Symmetric, zero on the diagonal.

    Examples
    --------
    >>> blocks = [[(0, 0), (0, 1), (0, 2), (0, 3)], [(3, 0), (3, 1), (3, 2), (3, 3)]]
    >>> cost_matrix(blocks).tolist()
    [[0.0, 3.0], [3.0, 0.0]]
    """
    w = check_weights(weights)
    b = _block_cells(blocks).astype(float)
    distance = np.sqrt(((b[:, None] - b[None, :]) ** 2).sum(-1))
    return distance @ w


def _block_cells(blocks) -> np.ndarray:
    """Block cells as an (n, 4, 2) array of numbers."""
    try:
        b = np.asarray(blocks)
        ok = b.size == 0 or (np.issubdtype(b.dtype, np.number) and b.size % 8 == 0)
    except (TypeError, ValueError):
        ok = False
    if not ok:
        raise ParameterError(f"blocks must be the (n, 4, 2) cells of blocks a–d at each waypoint, got "
                             f"{type(blocks).__name__} {reprlib.repr(blocks)}")
    return b.reshape(-1, 4, 2)


def path_cost(cost: np.ndarray, order) -> np.ndarray | float:
    """Summed cost of an open path (one order) or of a batch of orders (rows).

    Examples
    --------
    >>> path_cost(np.array([[0, 1, 5], [1, 0, 2], [5, 2, 0]]), [0, 1, 2])
    3.0

    Raises
    ------
    ParameterError
        If ``cost`` is not a square matrix of numbers, or ``order`` not waypoint indices into it.
    """
    try:
        cost = np.asarray(cost)
        ok = cost.ndim == 2 and cost.shape[0] == cost.shape[1] and np.issubdtype(cost.dtype, np.number)
    except (TypeError, ValueError):
        ok = False
    if not ok:
        raise ParameterError(f"cost must be a square matrix of numbers, got {type(cost).__name__} {reprlib.repr(cost)}")
    try:
        order = np.asarray(order)
        ok = order.ndim >= 1 and (order.size == 0 or np.issubdtype(order.dtype, np.integer))
        ok = ok and (order.size == 0 or (order.min() >= 0 and order.max() < len(cost)))
    except (TypeError, ValueError):
        ok = False
    if not ok:
        raise ParameterError(f"order must be waypoint indices in 0…{len(cost) - 1}, got {reprlib.repr(order)}")
    order = order.astype(np.int64, copy=False)
    legs = cost[order[..., :-1], order[..., 1:]].sum(-1)
    return float(legs) if order.ndim == 1 else legs


def block_locations(occupancy, tiles, *, weights=DEFAULT_BLOCK_WEIGHTS, cell_size: float = 1.0,
                    name: str = "") -> Tileset:
    """Algorithm 1: label the blocks of every tile and number the tiles in scan order.

    Parameters
    ----------
    occupancy : ndarray of bool, shape (H, W)
        The workspace's obstacles.
    tiles : iterable of array_like, shape (4, 2)
        The cells of each tile, in any order.
    weights : sequence of 4 float
        The eq.-2 weights used to pick among a symmetric tile's options (eq. 3).

    Returns
    -------
    Tileset
        Tiles numbered 1, 2, … in scan order of their first cell, each labelled by a robot footprint.

    Raises
    ------
    ConfigurationError
        If a tile's cells are not four integer cells of a tetromino.
    ParameterError
        If ``tiles`` is not a sequence, or the weights are invalid.

    Examples
    --------
    >>> ts = block_locations(np.zeros((2, 4), bool), [[(0, 0), (1, 0), (2, 0), (3, 0)], [(0, 1), (1, 1), (2, 1), (3, 1)]])
    >>> [p.heading for p in ts.poses]  # the second I takes the option whose blocks lie beside the first's
    [1, 1]
    """
    w = check_weights(weights)
    if isinstance(tiles, (str, bytes)) or not isinstance(tiles, Iterable):
        raise ParameterError(f"tiles must be a sequence of tiles, each four (x, y) cells, got "
                             f"{type(tiles).__name__} {reprlib.repr(tiles)}")
    cells_of = []
    for i, tile in enumerate(tiles):
        cells = _block_cells(tile) if not isinstance(tile, str) else None
        if cells is None or cells.shape != (1, 4, 2) or not np.issubdtype(cells.dtype, np.integer):
            raise ConfigurationError(f"tiles[{i}] must be four (x, y) integer cells, got {reprlib.repr(tile)}")
        cells_of.append(cells[0].astype(np.int64))
    ordered = sorted(cells_of, key=lambda cells: scan_key(min(map(tuple, cells.tolist()), key=scan_key)))
    poses = []
    previous = None
    for cells in ordered:
        options = tile_poses(cells)
        if previous is None or len(options) == 1:
            chosen = options[0]
        else:
            footprints = np.array([p.cells() for p in options], dtype=float)
            costs = np.sqrt(((footprints - previous) ** 2).sum(-1)) @ w
            chosen = options[int(np.argmin(costs))]
        poses.append(chosen)
        previous = chosen.cells().astype(float)
    return Tileset.from_poses(occupancy, poses, cell_size=cell_size, name=name)


@dataclass(frozen=True, eq=False)  # holds arrays: identity equality, hashable
class SequencingInstance:
    """One waypoint-sequencing instance, shared by every sequencing method.

    Parameters
    ----------
    cost : ndarray of float, shape (n, n)
        Eq.-2 cost between waypoints (symmetric, zero diagonal).
    blocks : ndarray of int, shape (n, 4, 2)
        Cells of blocks a–d at each waypoint (the pattern baselines scan block b's cell).
    start : int or None
        Index (0…n−1) of the waypoint every path starts from, or None for a free start.
    ids : tuple of int
        Tile labels, for reporting orders.
    shape : (int, int)
        The grid's (H, W).

    Raises
    ------
    PlanningError
        If the cost matrix is not square, non-empty and finite.
    ParameterError
        If ``start`` is not None or a waypoint index, or an argument has the wrong type or size.
    """

    cost: np.ndarray
    blocks: np.ndarray
    start: int | None = 0
    ids: tuple[int, ...] = ()
    shape: tuple[int, int] = (0, 0)

    def __post_init__(self) -> None:
        try:
            cost = np.array(self.cost, dtype=float)
        except (TypeError, ValueError) as err:
            raise ParameterError(f"cost must be a square matrix of numbers, got {type(self.cost).__name__} "
                                 f"{reprlib.repr(self.cost)}") from err
        n = len(cost) if cost.ndim else 0
        if cost.shape != (n, n) or n == 0 or not np.isfinite(cost).all():
            raise PlanningError(f"the cost matrix must be square, non-empty and finite, got shape {cost.shape}")
        start = check_int(self.start, "start", minimum=0, maximum=n - 1, allow_none=True)
        blocks = _block_cells(self.blocks)
        if len(blocks) != n:
            raise ParameterError(f"blocks must hold the cells of the {n} waypoints of the cost matrix, got {len(blocks)}")
        blocks = blocks.astype(np.int64)
        try:
            ids = tuple(check_int(i, "tile id") for i in self.ids) or tuple(range(1, n + 1))
            shape = tuple(check_int(v, "grid shape (H, W)", minimum=0) for v in self.shape)
        except TypeError as err:
            raise ParameterError(f"ids and shape must be sequences of integers, got {reprlib.repr(self.ids)} "
                                 f"and {reprlib.repr(self.shape)}") from err
        if len(ids) != n or len(shape) != 2:
            raise ParameterError(f"need one tile id per waypoint ({n}) and a grid shape (H, W), got {len(ids)} ids "
                                 f"and shape {shape}")
        for array in (cost, blocks):
            array.setflags(write=False)
        object.__setattr__(self, "cost", cost)
        object.__setattr__(self, "blocks", blocks)
        object.__setattr__(self, "ids", ids)
        object.__setattr__(self, "start", start)
        object.__setattr__(self, "shape", shape)

    @classmethod
    def from_tileset(cls, tileset: Tileset, *, start: int | None = 1,
                     weights=DEFAULT_BLOCK_WEIGHTS) -> "SequencingInstance":
        """The instance of a labelled tileset.

        Parameters
        ----------
        start : int or None
            The label of the start tile (tile 1 by default), or None for a free start.

        Raises
        ------
        TilesetFormatError
            If no tile has the start label.
        PlanningError
            If the tileset has no tiles.
        ParameterError
            If ``tileset`` is not a Tileset.

        Examples
        --------
        >>> from htetro_opt.scenarios import parse_tileset
        >>> inst = SequencingInstance.from_tileset(parse_tileset("1a 1b 1c 1d\\n2a 2b 2c 2d"))
        >>> inst.cost.tolist(), inst.start
        ([[0.0, 1.0], [1.0, 0.0]], 0)
        """
        check_tileset(tileset)
        if len(tileset) == 0:
            raise PlanningError(f"{tileset.name or 'tileset'} has no tiles to sequence")
        index = None if start is None else tileset.index(start)
        return cls(cost_matrix(tileset.blocks, weights), tileset.blocks, index, tileset.ids,
                   tileset.occupancy.shape)

    @property
    def n(self) -> int:
        return len(self.cost)

    def path_cost(self, order) -> float:
        """Summed cost of an order (waypoint indices)."""
        return path_cost(self.cost, order)

    def check_order(self, order) -> np.ndarray:
        """The order as an int array, checked to visit every waypoint once from the start.

        Raises
        ------
        PlanningError
            If it is not a permutation of 0…n−1 or does not begin at the start waypoint.
        """
        try:
            array = np.asarray(order)
            ok = array.size == 0 or np.issubdtype(array.dtype, np.integer)
        except (TypeError, ValueError):
            ok = False
        if not ok:
            raise PlanningError(f"an order must be waypoint indices, got {reprlib.repr(order)}")
        order = array.astype(np.int64).reshape(-1)
        if len(order) != self.n or not np.array_equal(np.sort(order), np.arange(self.n)):
            raise PlanningError(f"an order must visit each of the {self.n} waypoints exactly once")
        if self.start is not None and order[0] != self.start:
            raise PlanningError(f"an order must begin at tile {self.ids[self.start]}, not tile {self.ids[order[0]]}")
        return order

    def tile_order(self, order) -> list[int]:
        """Tile labels of an order of waypoint indices."""
        return [self.ids[i] for i in np.asarray(order, dtype=np.int64).tolist()]


def check_instance(instance, name: str = "instance") -> SequencingInstance:
    """``instance`` itself if it is a :class:`SequencingInstance`: the one check of every
    sequencing entry point.

    Raises
    ------
    ParameterError
        Naming ``name`` and what it got (with how to make an instance).

    Examples
    --------
    >>> check_instance("fig13b.txt")
    Traceback (most recent call last):
    ...
    htetro_opt.errors.ParameterError: instance must be a SequencingInstance (e.g. SequencingInstance.from_tileset(load_tileset(path))), got str 'fig13b.txt'
    """
    if not isinstance(instance, SequencingInstance):
        raise ParameterError(f"{name} must be a SequencingInstance (e.g. SequencingInstance.from_tileset("
                             f"load_tileset(path))), got {type(instance).__name__} {reprlib.repr(instance)}")
    return instance


def __getattr__(name: str):
    # SequencingProblem subclasses pymoo's Problem; it lives apart so that tiling and sequencing,
    # which import this module, do not import pymoo.
    if name == "SequencingProblem":
        from htetro_opt.problems._sequencing_problem import SequencingProblem

        return SequencingProblem
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
