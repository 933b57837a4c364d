"""Tetromino tiling of a grid workspace (Le et al. 2018): :func:`tile_workspace` with ``method=``,
returning a :class:`TilingResult` (its ``tileset``, and how it was made).

``"backtracking"`` is the paper's search (with region, colouring and memo pruning), ``"cpsat"`` an
exact cover by OR-Tools' CP-SAT, ``"auto"`` (the default) a portfolio: the backtracker, a compiled
sweep repaired by small exact covers, CP-SAT band by band and region by region, with budgets counted
in steps, so that no map makes it search for long where another method would not. :func:`enumerate_tilings` lists several tilings and
:func:`find_tiles` returns the bare tiles; a map that cannot be tiled raises a
:class:`~htetro_opt.errors.TilingError` that says why, and one neither tiled nor proven untileable
within the time limit (:data:`DEFAULT_TIME_LIMIT`, 60 s, when none is given) its subclass
:class:`TilingTimeLimitError`.

Importing this package imports neither pymoo nor DEAP, nor OR-Tools or numba (CP-SAT and the
compiled sweep import them when they run). The entry points live in ``_tiling``; each algorithm in
its own private module (``_prechecks``, ``_backtracking``, ``_cpsat``, ``_portfolio`` with
``_sweep``, ``_overlap``, and ``_common`` for what they share), described in its docstring.
"""

from htetro_opt._lazy import attach

__getattr__, __dir__, __all__ = attach(__name__, {
    "tile_workspace": "._tiling", "enumerate_tilings": "._tiling", "find_tiles": "._tiling",
    "TILING_METHODS": "._tiling", "TilingTimeLimitError": "._tiling", "TilingWorkLimitError": "._tiling",
    "DEFAULT_TIME_LIMIT": "._spec",
    "TilingResult": "._tiling", "SPEC": "._spec",
})
