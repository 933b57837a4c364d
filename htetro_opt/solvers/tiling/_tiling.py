"""Tiling a grid workspace with tetrominoes: the first phase of Le et al. 2018 (§3.1, Fig. 5).

The free cells of a workspace are covered exactly once by tetrominoes of the allowed morphologies
(all seven by default; the paper's Fig. 12c uses only Z and T, its Fig. 16c only O). Each tile then
becomes a waypoint: :func:`tile_workspace` hands the tiles to Algorithm 1
(:func:`~htetro_opt.problems.waypoint_sequencing.block_locations`), which numbers them in scan order
and labels their blocks a–d with a robot footprint.

This module holds the entry points (:func:`tile_workspace`, :func:`find_tiles`,
:func:`enumerate_tilings`) and their option checks; each part of the work has its own private
module of the package, whose docstring describes it in full:

Pre-checks (``_prechecks``)
    Before any search every method tests the same necessary conditions (a free cell; areas, of the
    map and of each 4-connected region, multiples of 4; the colourings of tiling theory and an
    integer-lattice test of the cell counts by ``(x mod 4, y mod 4)``; a placement over every free
    cell), each failing with a :class:`~htetro_opt.errors.TilingError` that names what is wrong and
    where. They are sound (never reject a tileable map) and catch most untileable maps at once.

``"backtracking"`` (``_backtracking``), the paper's algorithm (its ref. 38)
    The classic polyomino tiling backtracker in scan order, complete, pruned by the enclosed
    regions each placement leaves, by colourings and by a memo of the states that held no tiling.

``"cpsat"`` (``_cpsat``), OR-Tools CP-SAT on the exact-cover model
    One Boolean per placement, one exactly-one constraint per free cell, the backtracker's order
    as a decision strategy, on one worker with a seed. ortools is imported only when it runs.

``"auto"`` (``_portfolio``, the default), a portfolio of fixed, machine-independent budgets
    The backtracker for a budget of steps; on large maps a compiled sweep (``_sweep``) repaired by
    small exact covers; CP-SAT band by band; then CP-SAT region by region. Every budget is counted
    in steps or CP-SAT's deterministic time, so a map gets the same tiling on every machine.

Overlapping sub-workspaces (``_overlap``, §3.1, Fig. 5d–f)
    With ``overlap=True``, a map that does not tile as it is is split into two overlapping bands
    of rows or of columns that both tile, and both bands' tiles are kept.

``_common`` holds what they share (the grid's padding, the placements, the pattern order and the
two ways a search stops early). The entry points import the algorithm modules; those import only
``_common``, ``_prechecks`` and each other (``_portfolio`` uses ``_backtracking`` and ``_cpsat``),
never this module.

Time limit
    Every method is exact, and a map can pass every pre-check, have no tiling, and take a search
    hours to prove it (a 64 × 62 rectangle with T alone, which has none since 4 does not divide 62).
    So a call is bounded: by ``time_limit``, or by :data:`DEFAULT_TIME_LIMIT` (60 s) when it is None.
    A search cut short raises :class:`TilingTimeLimitError`, a subclass of
    :class:`~htetro_opt.errors.TilingError` that says the map may still be tileable; a plain
    TilingError is a proof that it is not.

Work budgets
    The time limit depends on the machine and its load. A budget of work does not: ``max_steps``
    (the backtracker's search steps) or ``max_deterministic_time`` (CP-SAT's deterministic time, for
    ``cpsat`` and for the last stage of ``auto``, whose other stages have fixed budgets). With one
    and a time limit that does not run out, a call tiles, proves, or gives up at the same point on
    every machine; running out raises :class:`TilingWorkLimitError`, a TilingTimeLimitError (no proof).

Examples
--------
>>> tile_workspace(np.zeros((2, 4), dtype=bool)).tileset.shapes
('I', 'I')
>>> ts = tile_workspace(np.zeros((2, 4), dtype=bool), shapes="O").tileset
>>> ts.ids, ts.shapes, ts.complete
((1, 2), ('O', 'O'), True)
"""

from __future__ import annotations

import reprlib
import time as _time
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from htetro_opt._validation import (
    check_bool,
    check_int,
    check_seed,
    check_time_limit,
    derive_seed,
)
from htetro_opt.errors import ParameterError, ScenarioError, TilingError, TilingTimeLimitError, TilingWorkLimitError
from htetro_opt.model.tiles import Pattern, patterns_of
from htetro_opt.model.workspace import Workspace
from htetro_opt.problems.waypoint_sequencing import (
    DEFAULT_BLOCK_WEIGHTS,
    block_locations,
    check_weights,
)
from htetro_opt.scenarios.tileset import Tileset
from htetro_opt.solvers._result import Result
from htetro_opt.solvers.tiling._backtracking import _backtracking_tilings
from htetro_opt.solvers.tiling._common import _OutOfWork, _shape_text, _TimeLimit, _WorkLimit
from htetro_opt.solvers.tiling._cpsat import _cpsat_tilings
from htetro_opt.solvers.tiling._overlap import _overlapping_tiles
from htetro_opt.solvers.tiling._portfolio import _auto_tilings
from htetro_opt.solvers.tiling._prechecks import _precheck
from htetro_opt._spec import Method
from htetro_opt.solvers.tiling._spec import DEFAULT_TIME_LIMIT, SPEC

__all__ = [
    "DEFAULT_TIME_LIMIT",
    "TILING_METHODS",
    "TilingResult",
    "TilingTimeLimitError",
    "TilingWorkLimitError",
    "enumerate_tilings",
    "find_tiles",
    "tile_workspace",
]

TILING_METHODS = ("auto", "backtracking", "cpsat")
"""The tiling algorithms :func:`find_tiles` and :func:`enumerate_tilings` run: a portfolio of the
others (the default), the paper's backtracking search and OR-Tools CP-SAT (:func:`tile_workspace` takes
these and any method registered in the spec)."""

# DEFAULT_TIME_LIMIT (60 s, the task spec's) bounds a call whose time_limit is None. Every method is exact, so on
# a map that passes every pre-check but has no tiling the search may have to go through a great many partial
# tilings before it proves so (a 64 x 64 map with T and Z only, say): without a bound it could run for hours.


@dataclass(frozen=True, eq=False)
class TilingResult(Result):
    """A tiling, labelled: the :class:`~htetro_opt.scenarios.Tileset` and how it was made.

    ``tileset`` holds the tiles (numbered 1, 2, … in scan order, each labelled by a robot footprint);
    ``shapes`` counts them by morphology. A map that cannot be tiled raises instead (a
    :class:`~htetro_opt.errors.TilingError` is a proof that no tiling exists), so ``success`` is True.
    """

    tileset: Tileset
    method: str
    runtime_s: float = 0.0
    info: Mapping = field(default_factory=dict)

    @property
    def shapes(self) -> dict[str, int]:
        """Tiles per morphology, the morphologies in alphabetical order."""
        return {shape: self.tileset.shapes.count(shape) for shape in sorted(set(self.tileset.shapes))}

    @property
    def success(self) -> bool:
        return True

    @property
    def message(self) -> str:
        counts = ", ".join(f"{k} {v}" for k, v in self.shapes.items())
        twice = " (two overlapping sub-workspaces)" if self.tileset.overlapping else ""
        return f"{len(self.tileset)} tiles: {counts}{twice}"

    def _fields(self) -> dict:
        return {"tiles": len(self.tileset), "shapes": self.shapes, "overlapping": bool(self.tileset.overlapping),
                "complete": bool(self.tileset.complete)}

# ------------------------------------------------------------------------------------------------
# Validation


def _as_occupancy(workspace, name: str) -> tuple[np.ndarray, float]:
    if isinstance(workspace, Workspace):
        return workspace.occupancy, workspace.cell_size
    try:
        return Workspace(workspace).occupancy, 1.0
    except ScenarioError as err:  # an argument here, not a file's content
        got = (f"an array of shape {workspace.shape}" if isinstance(workspace, np.ndarray)
               else f"{type(workspace).__name__} {reprlib.repr(workspace)}")
        raise ParameterError(f"{name} must be a Workspace or a non-empty 2-D (H, W) array of booleans "
                             f"(True = obstacle) or 0/1, got {got}") from err


def _check_shapes(shapes) -> tuple[Pattern, ...]:
    if shapes is not None:
        try:
            names = list(shapes)  # "TZ" -> ["T", "Z"]
        except TypeError as err:
            raise ParameterError(f"shapes must be morphology names such as 'TZ' or ['O'], got {shapes!r}") from err
        if not names:
            raise ParameterError("shapes is empty: allow at least one morphology (I, O, L, J, Z, S, T)")
        shapes = names
    return patterns_of(shapes)


def _check_method(method) -> str:
    if method not in TILING_METHODS:
        raise ParameterError(f"unknown tiling method {method!r}: expected one of {', '.join(TILING_METHODS)}")
    return method


def _check_options(shuffle, seed, time_limit) -> tuple[int | None, float, float]:
    """The search's order seed (None: the fixed order), its deadline and its time limit (None:
    :data:`DEFAULT_TIME_LIMIT`), all options checked (the seed too when ``shuffle`` is off and it
    goes unused: a bad value is a mistake either way)."""
    seed = check_seed(seed)
    order_seed = derive_seed(seed) if check_bool(shuffle, "shuffle") else None
    time_limit = check_time_limit(time_limit)
    if time_limit is None:
        time_limit = DEFAULT_TIME_LIMIT
    return order_seed, _time.perf_counter() + time_limit, time_limit


# ------------------------------------------------------------------------------------------------
# Drivers


_BUDGET_NAMES = ("max_steps", "max_deterministic_time")


def _work_message(method, budget, limit) -> str:
    if budget == "max_steps":
        return (f"the backtracking search found no tiling and proved none impossible within max_steps={limit} "
                "search steps; try the auto or cpsat method or a larger max_steps")
    return (f"{'CP-SAT' if method == 'cpsat' else 'the auto portfolio'} found no tiling and proved none impossible "
            f"within max_deterministic_time={limit:g} (CP-SAT's deterministic time); try a larger one")


def _budgets(options) -> dict:
    """The work budgets given among ``options`` (checked by the spec, which refuses one a method does
    not take): ``{name: [left]}``, shared by every search of the call (the bands of ``overlap`` too)."""
    return {name: [options[name]] for name in _BUDGET_NAMES if options.get(name) is not None}


def _time_message(method, time_limit) -> str:
    if method == "backtracking":
        return (f"the backtracking search found no tiling and proved none impossible within the time limit of "
                f"{time_limit:g} s; try the auto or cpsat method or a longer time limit")
    if method == "auto":
        return (f"no tiling found and none proven impossible within the time limit of {time_limit:g} s "
                "(backtracking, bands, then CP-SAT); try a longer time limit")
    return (f"CP-SAT found no tiling and proved none impossible within the time limit of {time_limit:g} s "
            "(building its model included); try a longer time limit")


def _tilings(occ, patterns, method, seed, deadline, limit, budgets=None):
    """Pre-checks, then up to ``limit`` tilings (non-empty list) or TilingError / _TimeLimit
    (_WorkLimit when one of ``budgets``, from :func:`_budgets`, runs out)."""
    _precheck(occ, patterns)
    budgets = budgets or {}
    if method == "backtracking":
        found = []
        generator = _backtracking_tilings(occ, patterns, seed, deadline, budgets.get("max_steps"))
        try:
            for tiles in generator:
                found.append(tiles)
                if len(found) >= limit:
                    break
        except _OutOfWork:
            if not found:
                raise _WorkLimit("max_steps") from None
        except _TimeLimit:
            if not found:
                raise
        finally:
            generator.close()
    elif method == "auto":
        found = _auto_tilings(occ, patterns, seed, deadline, limit, budgets.get("max_deterministic_time"))
    else:
        found = _cpsat_tilings(occ, patterns, seed, deadline, limit, budgets.get("max_deterministic_time"))
    if not found:
        raise TilingError(
            f"no tiling of the {int((~occ).sum())} free cells by {_shape_text(patterns)} tetrominoes exists "
            f"(the {method} search is exhaustive)"
        )
    return found


def _retime(method, time_limit, err=None, options=None) -> TilingTimeLimitError:
    """The error the caller sees when the time limit ran out, or (``err`` a _WorkLimit) the work budget
    of ``options`` it names."""
    if isinstance(err, _WorkLimit):
        limit = options[err.budget]
        return TilingWorkLimitError(_work_message(method, err.budget, limit), budget=err.budget, limit=limit,
                                    time_limit=time_limit, method=method)
    return TilingTimeLimitError(_time_message(method, time_limit), time_limit=time_limit, method=method)


def find_tiles(occupancy, *, shapes=None, method: str = "auto", shuffle: bool = False, seed=None,
               time_limit: float | None = None, max_steps: int | None = None,
               max_deterministic_time: float | None = None) -> list[np.ndarray]:
    """An exact cover of the free cells by tetrominoes of the allowed shapes.

    Parameters
    ----------
    occupancy : ndarray of bool, shape (H, W), or Workspace
        ``occ[y, x]``, True for an obstacle.
    shapes : iterable of str, optional
        The allowed morphologies, e.g. ``"TZ"`` or ``["O"]``; all seven when None.
    method : {"auto", "backtracking", "cpsat"}
        The portfolio (default), the paper's backtracking search or CP-SAT (see the module
        docstring). ``auto`` gives the backtracker's tiling wherever the backtracker needs few steps.
    shuffle : bool
        False (default): the fixed pattern order, one tiling per map, ``seed`` unused. True: the
        pattern order (and CP-SAT's random seed) drawn from ``seed``, for another tiling.
    seed : None, int or numpy.random.Generator
        With ``shuffle``: an int or a Generator gives the same tiling every time, None a fresh one.
    time_limit : float, optional
        Seconds the search may take, model building included; :data:`DEFAULT_TIME_LIMIT` (60 s)
        when None.
    max_steps : int, optional
        ``backtracking`` only: search steps (placements tried) before it gives up, the same on every
        machine. None: only the time limit.
    max_deterministic_time : float, optional
        ``cpsat``, and ``auto``'s last stage: CP-SAT's deterministic time (its own unit, about a
        second, the same on every machine) before it gives up. None: only the time limit.

    Returns
    -------
    list of ndarray of int, shape (4, 2)
        The cells ``(x, y)`` of each tile, the tiles in scan order of their first cell.

    Raises
    ------
    TilingTimeLimitError
        If the time limit runs out first: neither a tiling nor a proof that none exists was found
        (a subclass of TilingError, so catch it first to tell the two apart); its subclass
        :class:`TilingWorkLimitError` if a work budget runs out first.
    TilingError
        If a pre-check fails (no free cell; free area, or a 4-connected region's area, not a multiple
        of 4; unequal checkerboard colours without T; a cell no allowed tile fits over) or no tiling
        exists: a proof that the map cannot be tiled.
    UnknownShapeError
        If a shape name is unknown.
    ParameterError
        If ``shapes`` is empty, or ``method``, ``seed``, ``time_limit`` or a budget is invalid (or a
        budget the method does not take is given).

    Examples
    --------
    >>> tiles = find_tiles(np.zeros((4, 2), dtype=bool), shapes="O")
    >>> [t.tolist() for t in tiles]
    [[[0, 3], [1, 3], [0, 2], [1, 2]], [[0, 1], [1, 1], [0, 0], [1, 0]]]
    """
    occ, _ = _as_occupancy(occupancy, "occupancy")
    patterns = _check_shapes(shapes)
    method = _check_method(method)
    given = {"max_steps": max_steps, "max_deterministic_time": max_deterministic_time}
    given = SPEC.check(method, {k: v for k, v in given.items() if v is not None}, fill=False)
    seed, deadline, time_limit = _check_options(shuffle, seed, time_limit)
    try:
        return _tilings(occ, patterns, method, seed, deadline, 1, _budgets(given))[0]
    except _TimeLimit as err:
        raise _retime(method, time_limit, err, given) from err


def tile_workspace(workspace, *, method: str = SPEC.default, **options) -> TilingResult:
    """Tile a workspace and label the tiles by Algorithm 1: the waypoints of Le et al. 2018.

    Parameters
    ----------
    workspace : Workspace or ndarray of bool, shape (H, W)
        The map (``occ[y, x]`` True for an obstacle).
    method : str or callable, keyword-only
        A method of the task's spec (:data:`~htetro_opt.solvers.tiling.SPEC`): ``"auto"`` (default),
        ``"backtracking"`` or ``"cpsat"``, see :func:`find_tiles`. Or a callable
        ``method(occupancy, *, shapes, shuffle, seed, time_limit)`` returning the tiles as
        :func:`find_tiles` does (so is a method registered in the spec); its tiles are checked to cover
        every free cell once (with ``overlap``, the callable is given the whole map only).
    **options
        Checked and defaulted by the spec before any work:

        shapes, shuffle, seed, time_limit
            As in :func:`find_tiles` (the seed only with ``shuffle``); the time limit covers the whole
            call, splits included (default :data:`DEFAULT_TIME_LIMIT`, 60 s).
        max_steps, max_deterministic_time
            As in :func:`find_tiles`, for the methods that take them; a budget covers the whole call,
            splits included.
        overlap : bool
            When the free cells do not tile as they are, split the grid into two overlapping bands of
            rows (``y < k2`` and ``y >= k1``) or of columns whose free cells both tile, the split with
            the fewest shared free cells first (ties: rows before columns, then smaller ``k1``), and
            keep the tiles of both: the shared cells are covered twice (Le et al. 2018, §3.1,
            Fig. 5d–f). A map that tiles as it is is tiled normally.
        weights : sequence of 4 float
            α, β, λ, γ of eq. 2, for Algorithm 1's choice among a symmetric tile's options.
        name : str
            The tileset's name.

    Returns
    -------
    TilingResult
        Its ``tileset``: tiles numbered 1, 2, … in scan order, each labelled by a robot footprint.

    Raises
    ------
    TilingError
        As :func:`find_tiles`; with ``overlap``, when no split tiles either.
    UnknownShapeError, ParameterError
        On invalid options (an unknown one among them, naming the method's options).

    Examples
    --------
    >>> result = tile_workspace(np.zeros((7, 6), dtype=bool), overlap=True)
    >>> ts = result.tileset
    >>> len(ts), int(ts.coverage().sum()), ts.complete, result.method
    (12, 48, True, 'auto')
    """
    began = _time.perf_counter()
    occ, cell_size = _as_occupancy(workspace, "workspace")
    if callable(method):
        chosen = Method(getattr(method, "__name__", type(method).__name__), method, "a user's tiler",
                        tuple(o for o in SPEC.options if o not in _BUDGET_NAMES), seeded=True)
    else:
        chosen = SPEC.method(method)
    options = SPEC.check(chosen, options)
    patterns = _check_shapes(options["shapes"])
    seed, deadline, time_limit = _check_options(options["shuffle"], options["seed"], options["time_limit"])
    weights, name = check_weights(options["weights"]), options["name"]
    if not isinstance(name, str):
        raise ParameterError(f"name must be a string, got {type(name).__name__} {reprlib.repr(name)}")
    if chosen.function is not None:  # a user's tiler: its tiles checked by Algorithm 1's labelling
        tiles = chosen.load(SPEC.package)(occ, shapes=options["shapes"], shuffle=options["shuffle"],
                                          seed=options["seed"], time_limit=time_limit)
        tileset = block_locations(occ, tiles, weights=weights, cell_size=cell_size, name=name)
        return _result(tileset, chosen.name, began)
    budgets = _budgets(options)
    try:
        try:
            tiles = _tilings(occ, patterns, chosen.name, seed, deadline, 1, budgets)[0]
        except _TimeLimit:
            raise
        except TilingError as err:
            if not options["overlap"]:
                raise

            def tile(band):  # each band by the same method, pre-checks included
                return _tilings(band, patterns, chosen.name, seed, deadline, 1, budgets)[0]

            tiles = _overlapping_tiles(occ, patterns, deadline, err, tile)
    except _TimeLimit as err:
        raise _retime(chosen.name, time_limit, err, options) from err
    return _result(block_locations(occ, tiles, weights=weights, cell_size=cell_size, name=name), chosen.name, began)


def _result(tileset: Tileset, method: str, began: float) -> TilingResult:
    return TilingResult(tileset, method, _time.perf_counter() - began)


def enumerate_tilings(workspace, *, shapes=None, limit: int = 10, method: str = "auto",
                      time_limit: float | None = None, weights=DEFAULT_BLOCK_WEIGHTS) -> list[Tileset]:
    """Up to ``limit`` distinct tilings of a workspace (distinct as sets of tiles), labelled.

    The backtracker continues its depth-first search after each tiling (so the tilings come in its
    search order); CP-SAT enumerates solutions on one worker. Both are deterministic. When the time
    limit runs out after some tilings were found, those are returned.

    Parameters
    ----------
    workspace : Workspace or ndarray of bool, shape (H, W)
        The map.
    shapes, method, time_limit
        As in :func:`find_tiles`.
    limit : int
        Most tilings to return (at least 1).
    weights : sequence of 4 float
        The eq.-2 weights of Algorithm 1.

    Returns
    -------
    list of Tileset
        Between 1 and ``limit`` tilings, each numbered and labelled as by :func:`tile_workspace`.

    Raises
    ------
    TilingTimeLimitError
        If the time limit runs out before the first tiling (and before a proof that there is none).
    TilingError
        If the map has no tiling.
    UnknownShapeError, ParameterError
        On invalid options (``limit`` not a positive integer, among others).

    Examples
    --------
    >>> len(enumerate_tilings(np.zeros((4, 4), dtype=bool), shapes="O", limit=5))
    1
    """
    occ, cell_size = _as_occupancy(workspace, "workspace")
    patterns = _check_shapes(shapes)
    limit = check_int(limit, "limit", minimum=1)
    method = _check_method(method)
    _, deadline, time_limit = _check_options(False, None, time_limit)
    check_weights(weights)
    try:
        found = _tilings(occ, patterns, method, None, deadline, limit)
    except _TimeLimit as err:
        raise _retime(method, time_limit) from err
    return [block_locations(occ, tiles, weights=weights, cell_size=cell_size) for tiles in found]
