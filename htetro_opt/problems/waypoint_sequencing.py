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
a TSPLIB coordinate instance (:meth:`SequencingInstance.from_tsplib`) holds its coordinates and metric instead
of a matrix, at any size;
:class:`SequencingProblem` poses it as a pymoo permutation problem.

Beyond the paper (a choice of ours, for inputs users have): an instance may come from any square
finite matrix (:meth:`SequencingInstance.from_matrix`, no tile geometry, asymmetric allowed), be a
closed tour (``closed=True``: the order returns to its first waypoint) or an open path with a fixed
last waypoint (``end``). :func:`reduce_to_open_path` turns such an instance into the paper's open
path with a fixed or free start, so that every method built for the paper's problem solves it too.
"""

from __future__ import annotations

import reprlib
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from htetro_opt._validation import check_bool, check_int
from htetro_opt.errors import ConfigurationError, ParameterError, PlanningError
from htetro_opt.model.tiles import scan_key, tile_poses
from htetro_opt.scenarios.tileset import Tileset, check_tileset
from htetro_opt.scenarios.tsplib import IMPLICIT_TYPES, TsplibInstance, tsplib_distances, tsplib_legs

__all__ = [
    "DEFAULT_BLOCK_WEIGHTS",
    "check_weights",
    "block_locations",
    "cost_matrix",
    "eq2_legs",
    "DENSE_LIMIT",
    "path_cost",
    "SequencingInstance",
    "OpenPathReduction",
    "check_instance",
    "check_matrix",
    "reduce_to_open_path",
]

DEFAULT_BLOCK_WEIGHTS = (0.25, 0.25, 0.25, 0.25)
"""α, β, λ, γ of eq. 2: every block counts the same."""

DENSE_LIMIT = 5000
"""Above this many waypoints :meth:`SequencingInstance.from_tileset` keeps the eq.-2 costs implicit
(computed from the block cells when needed) instead of an n × n matrix: 8·n² bytes, 2.1 GB at 16 384
waypoints, which the ``ils`` method does not need (benchmarks/README.md, "TSPLIB, a map with
obstacles, memory linear in n": 317 MB to tile and sequence 16 384 waypoints)."""


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
    n = len(b)
    out = np.empty((n, n))
    # rows in blocks: the (rows, n, 4, 2) differences of one block stay near 64 MB, not 64 B·n²
    step = max(1, (1 << 23) // max(1, 8 * n))
    for r in range(0, n, step):
        out[r:r + step] = np.sqrt(((b[r:r + step, None] - b[None, :]) ** 2).sum(-1)) @ w
    return out


def eq2_legs(blocks, weights, a, b) -> np.ndarray:
    """Eq. 2 between waypoints ``a[k]`` and ``b[k]`` (arrays of indices), without a matrix.

    Examples
    --------
    >>> blocks = np.array([[(0, 0), (0, 1), (0, 2), (0, 3)], [(3, 0), (3, 1), (3, 2), (3, 3)]])
    >>> eq2_legs(blocks, DEFAULT_BLOCK_WEIGHTS, [0, 1], [1, 1]).tolist()
    [3.0, 0.0]
    """
    w = check_weights(weights)
    cells = _block_cells(blocks).astype(float)
    a, b = np.asarray(a, dtype=np.int64), np.asarray(b, dtype=np.int64)
    return np.sqrt(((cells[a] - cells[b]) ** 2).sum(-1)) @ w


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


def check_matrix(matrix, name: str = "matrix") -> np.ndarray:
    """A square, non-empty, finite matrix of numbers as a float array (a copy), validated.

    Raises
    ------
    ParameterError
        Naming ``name`` and what is wrong: not numbers, ragged rows (which row), not square, empty,
        or non-finite entries (how many, and the first).

    Examples
    --------
    >>> check_matrix([[0, 1], [2, 0]]).tolist()
    [[0.0, 1.0], [2.0, 0.0]]
    >>> check_matrix([[0, 1, 2], [1, 0]])
    Traceback (most recent call last):
    ...
    htetro_opt.errors.ParameterError: matrix must be square: row 1 has 2 entries, row 0 has 3
    """
    if isinstance(matrix, (list, tuple)):
        lengths = [len(row) if isinstance(row, (list, tuple, np.ndarray)) else None for row in matrix]
        for i, length in enumerate(lengths):
            if length is not None and lengths[0] is not None and length != lengths[0]:
                raise ParameterError(f"{name} must be square: row {i} has {length} entries, row 0 has {lengths[0]}")
    try:
        m = np.array(matrix, dtype=float)
    except (TypeError, ValueError) as err:
        raise ParameterError(f"{name} must be a square matrix of numbers, got {type(matrix).__name__} "
                             f"{reprlib.repr(matrix)}") from err
    if m.ndim != 2 or m.shape[0] != m.shape[1] or m.shape[0] == 0:
        raise ParameterError(f"{name} must be a non-empty square matrix, got shape {m.shape}")
    bad = ~np.isfinite(m)
    if bad.any():
        i, j = (int(v) for v in np.argwhere(bad)[0])
        raise ParameterError(f"{name} must be finite: {int(bad.sum())} entries are not, the first at "
                             f"[{i}, {j}] = {m[i, j]}")
    return m


@dataclass(frozen=True, eq=False)  # holds arrays: identity equality, hashable
class SequencingInstance:
    """One waypoint-sequencing instance, shared by every sequencing method.

    Parameters
    ----------
    cost : ndarray of float, shape (n, n), or None
        Cost of moving from waypoint i to waypoint j: eq. 2 for a tileset (symmetric, zero diagonal),
        any finite numbers for :meth:`from_matrix` (the diagonal is never used). None: the eq.-2
        costs of ``blocks`` under ``weights``, computed when needed (an *implicit* instance, memory
        linear in n; only ``ils`` sequences it, see :data:`DENSE_LIMIT`).
    blocks : ndarray of int, shape (n, 4, 2), or None
        Cells of blocks a–d at each waypoint (the pattern baselines scan block b's cell); None for an
        instance without tile geometry (:meth:`from_matrix`), which the pattern baselines refuse.
    start : int or None
        Index (0…n−1) of the waypoint every order begins at, or None for a free start (for a closed
        tour: where the listed order begins; its cost does not depend on it).
    ids : tuple of int
        Tile labels, for reporting orders (default 1…n).
    shape : (int, int)
        The grid's (H, W).
    closed : bool
        True: a closed tour, priced with the leg from the last waypoint back to the first. False
        (the paper's problem): an open path.
    end : int or None
        Open paths only: the index of the waypoint every order ends at, or None for a free end.
    weights : sequence of 4 float, or None
        The eq.-2 weights of an implicit instance (None: :data:`DEFAULT_BLOCK_WEIGHTS`); ignored
        when ``cost`` is given.
    coords : ndarray of float, shape (n, 2), or None
        With ``cost`` None and no ``blocks``: the node coordinates of a TSPLIB coordinate instance, as
        the file gives them, priced by ``metric`` when needed (an implicit instance whose matrix the
        methods that need one build on demand, within the memory budget:
        :func:`~htetro_opt.solvers.sequencing.sequence_waypoints`).
    metric : str or None
        The TSPLIB ``EDGE_WEIGHT_TYPE`` of ``coords``, one of
        :data:`~htetro_opt.scenarios.tsplib.IMPLICIT_TYPES` (TSPLIB's integer rounding of each).

    Raises
    ------
    PlanningError
        If the cost matrix is not square, non-empty and finite, or an implicit instance has neither
        blocks nor coordinates.
    ParameterError
        If ``start`` or ``end`` is not None or a waypoint index, ``end`` is given for a closed tour or
        equals ``start`` on an open path of more than one waypoint, or an argument has the wrong type
        or size.
    """

    cost: np.ndarray
    blocks: np.ndarray | None = None
    start: int | None = 0
    ids: tuple[int, ...] = ()
    shape: tuple[int, int] = (0, 0)
    closed: bool = False
    end: int | None = None
    weights: tuple[float, ...] | None = None
    coords: np.ndarray | None = None
    metric: str | None = None

    def __post_init__(self) -> None:
        weights = None
        coords, metric = _check_coordinates(self.coords, self.metric) if self.cost is None else (None, None)
        if coords is not None:  # implicit TSPLIB costs
            if self.blocks is not None:
                raise ParameterError("an instance is priced by its blocks (eq. 2) or by its coordinates, not both: "
                                     "give blocks=None with coords")
            cost = None
            n = len(coords)
        elif self.cost is None:  # implicit eq.-2 costs
            if self.blocks is None or len(_block_cells(self.blocks)) == 0:
                raise PlanningError("an instance without a cost matrix needs the block cells of its waypoints "
                                    "(or the coordinates and metric of a TSPLIB instance)")
            weights = tuple(check_weights(DEFAULT_BLOCK_WEIGHTS if self.weights is None else self.weights).tolist())
            cost = None
            n = len(_block_cells(self.blocks))
        else:
            try:
                cost = np.array(self.cost, dtype=float)
            except (TypeError, ValueError) as err:
                raise ParameterError(f"cost must be a square matrix of numbers, got {type(self.cost).__name__} "
                                     f"{reprlib.repr(self.cost)}") from err
            n = len(cost) if cost.ndim else 0
            if cost.shape != (n, n) or n == 0 or not np.isfinite(cost).all():
                raise PlanningError(f"the cost matrix must be square, non-empty and finite, got shape {cost.shape}")
        start = check_int(self.start, "start", minimum=0, maximum=n - 1, allow_none=True)
        closed = check_bool(self.closed, "closed")
        end = check_int(self.end, "end", minimum=0, maximum=n - 1, allow_none=True)
        if closed and end is not None:
            raise ParameterError(f"end={end} applies to open paths only: a closed tour returns to its first waypoint")
        if end is not None and end == start and n > 1:
            raise ParameterError(f"start and end are both waypoint {end}: an open path of {n} waypoints "
                                 "cannot begin and end at one waypoint (use closed=True for a tour)")
        blocks = None
        if self.blocks is not None:
            blocks = _block_cells(self.blocks)
            if len(blocks) != n:
                raise ParameterError(f"blocks must hold the cells of the {n} waypoints of the cost matrix, "
                                     f"got {len(blocks)}")
            blocks = blocks.astype(np.int64)
            blocks.setflags(write=False)
        try:
            ids = tuple(check_int(i, "tile id") for i in self.ids) or tuple(range(1, n + 1))
            shape = tuple(check_int(v, "grid shape (H, W)", minimum=0) for v in self.shape)
        except TypeError as err:
            raise ParameterError(f"ids and shape must be sequences of integers, got {reprlib.repr(self.ids)} "
                                 f"and {reprlib.repr(self.shape)}") from err
        if len(ids) != n or len(shape) != 2:
            raise ParameterError(f"need one tile id per waypoint ({n}) and a grid shape (H, W), got {len(ids)} ids "
                                 f"and shape {shape}")
        if cost is not None:
            cost.setflags(write=False)
        object.__setattr__(self, "cost", cost)
        object.__setattr__(self, "weights", weights)
        object.__setattr__(self, "blocks", blocks)
        object.__setattr__(self, "ids", ids)
        object.__setattr__(self, "start", start)
        object.__setattr__(self, "shape", shape)
        object.__setattr__(self, "closed", closed)
        object.__setattr__(self, "end", end)
        object.__setattr__(self, "coords", coords)
        object.__setattr__(self, "metric", metric)

    @classmethod
    def from_tileset(cls, tileset: Tileset, *, start: int | None = 1,
                     weights=DEFAULT_BLOCK_WEIGHTS, dense: bool | None = None) -> "SequencingInstance":
        """The instance of a labelled tileset.

        Parameters
        ----------
        start : int or None
            The label of the start tile (tile 1 by default), or None for a free start.
        weights : sequence of 4 float
            α, β, λ, γ of eq. 2.
        dense : bool or None
            True: hold the n × n eq.-2 matrix (every method can run); False: keep the costs implicit
            (memory linear in n; ``ils`` and ``auto`` only); None (default): dense up to
            :data:`DENSE_LIMIT` waypoints.

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
        w = check_weights(weights)
        dense = None if dense is None else check_bool(dense, "dense")
        if len(tileset) == 0:
            raise PlanningError(f"{tileset.name or 'tileset'} has no tiles to sequence")
        index = None if start is None else tileset.index(start)
        if dense is None:
            dense = len(tileset) <= DENSE_LIMIT
        cost = cost_matrix(tileset.blocks, w) if dense else None
        return cls(cost, tileset.blocks, index, tileset.ids, tileset.occupancy.shape, weights=tuple(w.tolist()))

    @classmethod
    def from_matrix(cls, matrix, *, closed: bool = False, start: int | None = None, end: int | None = None,
                    ids=None) -> "SequencingInstance":
        """The instance of a plain cost matrix: no tile geometry, any square finite matrix.

        ``matrix[i][j]`` is the cost of moving from waypoint i to waypoint j; the diagonal is never
        used. An asymmetric matrix is accepted here; the methods that assume symmetric costs
        (``local``, ``ga``, ``fast-tsp``) refuse it, and the pattern baselines (``zigzag``,
        ``spiral``), which scan tile positions, refuse any instance without geometry.

        Parameters
        ----------
        matrix : array_like, shape (n, n)
            Finite numbers (a list of lists or an array).
        closed : bool, keyword-only
            A closed tour (True) or an open path (False, the default).
        start, end : int or None, keyword-only
            Waypoint indices (0…n−1) the order begins / ends at; None (the default): free. ``end``
            applies to open paths only.
        ids : sequence of int, optional, keyword-only
            Labels of the waypoints in reports (default 1…n).

        Raises
        ------
        ParameterError
            On a ragged, non-square, empty or non-finite matrix, a bad ``start`` or ``end``, ``end``
            with ``closed=True``, or ``start == end`` on an open path of more than one waypoint.

        Examples
        --------
        >>> inst = SequencingInstance.from_matrix([[0, 1, 9], [1, 0, 2], [9, 2, 0]], closed=True)
        >>> inst.path_cost([0, 1, 2]), inst.blocks is None, inst.symmetric
        (12.0, True, True)
        >>> SequencingInstance.from_matrix([[0, 1], [5, 0]], start=0, end=1).path_cost([0, 1])
        1.0
        """
        m = check_matrix(matrix)
        return cls(m, None, start, () if ids is None else ids, (0, 0), closed, end)

    @classmethod
    def from_coordinates(cls, coords, metric: str, *, closed: bool = False, start: int | None = None,
                         end: int | None = None, ids=None) -> "SequencingInstance":
        """The instance of node coordinates under a TSPLIB metric, its costs implicit: memory linear in n.

        Parameters
        ----------
        coords : array_like, shape (n, 2)
            Finite coordinates, as a TSPLIB file gives them (``DDD.MM`` latitude and longitude for ``GEO``).
        metric : str
            One of :data:`~htetro_opt.scenarios.tsplib.IMPLICIT_TYPES`: ``EUC_2D`` (``nint`` of the
            Euclidean distance), ``CEIL_2D``, ``ATT`` (pseudo-Euclidean) or ``GEO`` (TSPLIB's sphere of
            6378.388 km), with TSPLIB's integer rounding (:mod:`htetro_opt.scenarios.tsplib`).
        closed, start, end, ids : keyword-only
            As :meth:`from_matrix`.

        Raises
        ------
        ParameterError
            On an unknown metric, coordinates that are not an (n, 2) array of finite numbers, or a bad
            ``start`` or ``end``.

        Examples
        --------
        >>> inst = SequencingInstance.from_coordinates([[0, 0], [3, 4], [3, 0]], "EUC_2D", closed=True)
        >>> inst.implicit, inst.cost is None, inst.path_cost([0, 1, 2])   # 5 + 4 + 3
        (True, True, 12.0)
        """
        if coords is None or metric is None:
            raise ParameterError("from_coordinates needs the coordinates and their metric")
        return cls(None, None, start, () if ids is None else ids, (0, 0), closed, end, coords=coords, metric=metric)

    @classmethod
    def from_tsplib(cls, tsp: TsplibInstance, *, closed: bool = True, start: int | None = None,
                    end: int | None = None) -> "SequencingInstance":
        """The instance of a TSPLIB file (:func:`~htetro_opt.scenarios.tsplib.load_tsplib`): its coordinates
        and metric for the types of :data:`~htetro_opt.scenarios.tsplib.IMPLICIT_TYPES` (no n × n matrix,
        at any size), its cost matrix otherwise (``EXPLICIT``, the 3-D, Manhattan and maximum types).

        ``start`` / ``end`` are node indices (0…n−1) or None; a TSPLIB instance is a closed tour unless
        ``closed=False``.

        Raises
        ------
        ParameterError
            If ``tsp`` is not a :class:`~htetro_opt.scenarios.tsplib.TsplibInstance`, or on a bad
            ``start`` or ``end``.

        Examples
        --------
        >>> from htetro_opt.scenarios.tsplib import parse_tsplib
        >>> tsp = parse_tsplib("TYPE: TSP\\nDIMENSION: 3\\nEDGE_WEIGHT_TYPE: ATT\\nNODE_COORD_SECTION\\n"
        ...                    "1 0 0\\n2 3 4\\n3 1 1\\nEOF")
        >>> inst = SequencingInstance.from_tsplib(tsp)
        >>> inst.implicit, inst.metric, inst.path_cost([0, 1, 2])   # 2 + 2 + 1
        (True, 'ATT', 5.0)
        """
        if not isinstance(tsp, TsplibInstance):
            raise ParameterError(f"from_tsplib needs a TsplibInstance (load_tsplib(path)), got {type(tsp).__name__}")
        if tsp.coords is not None and tsp.edge_weight_type in IMPLICIT_TYPES:
            return cls.from_coordinates(tsp.coords, tsp.edge_weight_type, closed=closed, start=start, end=end)
        return cls.from_matrix(tsp.cost, closed=closed, start=start, end=end)

    @property
    def n(self) -> int:
        if self.cost is not None:
            return len(self.cost)
        return len(self.blocks) if self.coords is None else len(self.coords)

    @property
    def implicit(self) -> bool:
        """Whether the costs are computed when needed (eq. 2 of the blocks, or a TSPLIB metric of the
        coordinates), with no n × n matrix."""
        return self.cost is None

    @property
    def matrix_bytes(self) -> int:
        """Bytes of the n × n float matrix of the costs: 8·n²."""
        return 8 * self.n * self.n

    def with_matrix(self) -> "SequencingInstance":
        """This instance with its n × n cost matrix (itself if it has one): for the methods that need a
        matrix. An implicit instance's matrix takes :attr:`matrix_bytes`; its callers check the memory
        budget first (:func:`~htetro_opt.solvers.sequencing.sequence_waypoints`).

        Examples
        --------
        >>> inst = SequencingInstance.from_coordinates([[0, 0], [3, 4], [3, 0]], "EUC_2D")
        >>> inst.with_matrix().cost.tolist()
        [[0.0, 5.0, 3.0], [5.0, 0.0, 4.0], [3.0, 4.0, 0.0]]
        """
        if self.cost is not None:
            return self
        if self.coords is not None:
            matrix = tsplib_distances(self.coords, self.metric)
        else:
            matrix = cost_matrix(self.blocks, self.weights)
        return SequencingInstance(matrix, self.blocks, self.start, self.ids, self.shape, self.closed, self.end)

    @cached_property
    def symmetric(self) -> bool:
        """Whether ``cost`` is symmetric (to 1e-9 relative): the methods that assume it check this."""
        if self.cost is None:
            return True  # eq. 2 and the TSPLIB metrics are
        return bool(np.allclose(self.cost, self.cost.T, rtol=1e-9, atol=1e-12))

    def legs(self, a, b) -> np.ndarray:
        """The costs of the moves ``a[k] → b[k]`` (waypoint indices), from the matrix, eq. 2 or the metric.

        Examples
        --------
        >>> inst = SequencingInstance.from_matrix([[0, 1, 9], [1, 0, 2], [9, 2, 0]])
        >>> inst.legs([0, 2], [1, 0]).tolist()
        [1.0, 9.0]
        """
        a, b = np.asarray(a, dtype=np.int64), np.asarray(b, dtype=np.int64)
        if self.coords is not None:
            return tsplib_legs(self.coords, self.metric, a, b)
        if self.cost is None:
            return eq2_legs(self.blocks, self.weights, a, b)
        return self.cost[a, b]

    @property
    def has_geometry(self) -> bool:
        """Whether the waypoints have block cells (a tileset's instance) for the pattern baselines."""
        return self.blocks is not None

    def path_cost(self, order) -> float:
        """Summed cost of an order (waypoint indices); a closed tour adds the leg back to its first."""
        if self.cost is None:
            order = np.asarray(order)
            if order.ndim != 1 or order.size and (not np.issubdtype(order.dtype, np.integer) or order.min() < 0
                                                  or order.max() >= self.n):
                raise ParameterError(f"order must be waypoint indices in 0…{self.n - 1}, got {reprlib.repr(order)}")
            total = float(self.legs(order[:-1], order[1:]).sum())
        else:
            total = path_cost(self.cost, order)
        if self.closed and np.size(order) > 1:
            order = np.asarray(order, dtype=np.int64)
            total += float(self.legs(order[-1:], order[:1])[0])
        return total

    def check_order(self, order) -> np.ndarray:
        """The order as an int array, checked to visit every waypoint once from the start (to the end).

        Raises
        ------
        PlanningError
            If it is not a permutation of 0…n−1, does not begin at the start waypoint or does not
            end at the end waypoint.
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
        if self.end is not None and order[-1] != self.end:
            raise PlanningError(f"an order must end at tile {self.ids[self.end]}, not tile {self.ids[order[-1]]}")
        return order

    def tile_order(self, order) -> list[int]:
        """Tile labels of an order of waypoint indices."""
        return [self.ids[i] for i in np.asarray(order, dtype=np.int64).tolist()]


@dataclass(frozen=True, eq=False)
class OpenPathReduction:
    """An instance restated as the paper's open path (free end), and the way back.

    ``instance`` is an open path with a free end and the original's start (a closed tour: its
    start, or waypoint 0); ``decode(order)`` turns an order of it into a valid order of the original
    (dropping the closing copy, moving the end waypoint last); every order of the original that
    ``decode`` returns unchanged costs ``offset`` more in ``instance`` than in the original.
    """

    instance: SequencingInstance
    decode: Callable[[np.ndarray], np.ndarray]
    offset: float


def reduce_to_open_path(instance: SequencingInstance) -> OpenPathReduction:
    """Restate a closed tour or a fixed-end path as an open path with a free end (a choice of ours).

    - **Closed tour** of ``n`` waypoints: an open path over ``n + 1``, the last a copy of the first
      waypoint ``s`` (the start, or 0 when free) with ``s``'s costs, from ``s`` to the copy. Its
      cost is the tour's.
    - **Fixed end** ``e`` (also the copy of a closed tour): a penalty ``K = 5·max|C|`` (1 when every
      cost is 0) makes any other last waypoint dearer than any path ending at ``e``. A symmetric
      matrix gets ``K`` on every leg touching ``e`` (so it stays symmetric, for the methods that
      need it; an optimal path then touches ``e`` once, at an end, and the offset is ``K``; with a
      free start a path beginning at ``e`` is reversed); an asymmetric one gets ``K`` on the legs
      leaving ``e`` (offset 0). Moving ``e`` to the end of a path changes its other legs by at most
      ``4·max|C|`` and saves at least ``K``, so an optimal order of the reduction is one of the
      original, and a lower bound on it, less the offset, bounds the original's optimum.

    A heuristic's order that misses the end is still decoded to a valid order (the end waypoint
    moved last); its cost is then the original's, re-priced, not the reduction's.

    Examples
    --------
    >>> inst = SequencingInstance.from_matrix([[0, 1, 4], [1, 0, 2], [4, 2, 0]], closed=True, start=1)
    >>> red = reduce_to_open_path(inst)
    >>> red.instance.n, red.instance.start, red.instance.end, red.decode([1, 0, 2, 3]).tolist()
    (4, 1, None, [1, 0, 2])
    >>> inst.path_cost([1, 0, 2]), red.instance.path_cost([1, 0, 2, 3]) - red.offset
    (7.0, 7.0)
    """
    instance = check_instance(instance)
    if instance.implicit:
        raise ParameterError(f"this instance of {instance.n} waypoints keeps its costs implicit (no n × n "
                             "matrix), which the open-path reduction needs: build it with "
                             "SequencingInstance.from_tileset(..., dense=True) or instance.with_matrix(), or use "
                             "method 'ils' (or auto)")
    n, C, blocks = instance.n, instance.cost, instance.blocks
    start, end, ids = instance.start, instance.end, instance.ids
    copied = instance.closed and n > 1
    if copied:
        s = 0 if start is None else start
        D = np.zeros((n + 1, n + 1))
        D[:n, :n] = C
        D[:n, n] = C[:, s]
        D[n, :n] = C[s, :]
        D[s, n] = D[n, s] = 0.0
        C, start, end, ids = D, s, n, ids + (max(ids) + 1,)
        if blocks is not None:
            blocks = np.concatenate([blocks, blocks[s:s + 1]])
    offset = 0.0
    if end is not None and len(C) > 1:
        top = float(np.abs(C[~np.eye(len(C), dtype=bool)]).max())
        penalty = 5.0 * top if top > 0 else 1.0
        symmetric = bool(np.allclose(C, C.T, rtol=1e-9, atol=1e-12))
        C = np.array(C, dtype=float)
        C[end, :] += penalty
        if symmetric:
            C[:, end] += penalty
            offset = penalty
    reduced = SequencingInstance(C, blocks, start, ids, instance.shape)
    fixed_end = end

    def decode(order) -> np.ndarray:
        order = np.asarray(order, dtype=np.int64).reshape(-1)
        if fixed_end is not None and len(order) > 1 and order[-1] != fixed_end:
            if order[0] == fixed_end and start is None and offset:
                order = order[::-1]  # symmetric: the reversed path costs the same
            else:
                order = np.concatenate([order[order != fixed_end], [fixed_end]])
        if copied:
            order = order[order != n]
        return order.copy()

    return OpenPathReduction(reduced, decode, offset)


def _check_coordinates(coords, metric) -> tuple[np.ndarray | None, str | None]:
    """(coords as a read-only (n, 2) float array, metric) of a coordinate instance; (None, None) without."""
    if coords is None and metric is None:
        return None, None
    if metric is None or str(metric).upper() not in IMPLICIT_TYPES:
        raise ParameterError(f"metric must be one of {', '.join(IMPLICIT_TYPES)} with coords, got {metric!r}")
    try:
        x = np.array(coords, dtype=float)
    except (TypeError, ValueError) as err:
        raise ParameterError(f"coords must be an (n, 2) array of numbers, got {type(coords).__name__} "
                             f"{reprlib.repr(coords)}") from err
    if x.ndim != 2 or x.shape[1] != 2 or len(x) == 0 or not np.isfinite(x).all():
        raise ParameterError(f"coords must be a non-empty (n, 2) array of finite numbers, got shape {x.shape}")
    x.setflags(write=False)
    return x, str(metric).upper()


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
