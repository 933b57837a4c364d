"""Waypoint sequencing (Le et al. 2018): order a tileset's waypoints as an open path of least eq.-2 cost.

:func:`sequence_waypoints` runs one method (``method=``, a method of :data:`SPEC` or a callable) and returns a :class:`SequenceResult` re-priced on the instance. The methods, each also a
function of its own:

- ``exact`` (:func:`solve_exact`): the CP-SAT optimum with a proof, up to 40 waypoints;
  :func:`held_karp` is the independent dynamic-programming reference (≤ 16);
- ``ortools`` (:func:`solve_ortools`): OR-Tools routing with guided local search, the paper's baseline;
- ``ils`` (:func:`solve_ils`): the compiled (numba), seeded iterated local search — 2-opt and Or-opt
  with neighbour lists and don't-look bits, local double-bridge kicks — ``auto``'s engine beyond the
  exact range. Its local search is the package's one 2-opt/Or-opt local search: ``local``, the
  memetic GA and :func:`improve` (with :func:`two_opt`, :func:`or_opt`, :func:`improve_batch`, for a
  plain cost matrix) run it too;
- ``local`` (:func:`solve_local`): nearest neighbour, then that local search to a local optimum of the
  whole 2-opt/Or-opt neighbourhood, optionally iterated with :func:`double_bridge` kicks;
  :func:`nearest_neighbour_paths` is the one nearest-neighbour construction (the exact solver's
  hint and the greedy baseline use it too);
- ``ga``, ``ga-plain`` (:func:`solve_ga`): the paper's GA on DEAP, with or without a memetic step;
- ``zigzag``, ``zigzag2``, ``spiral``, ``spiral2``, ``greedy``: the paper's baselines;
- ``fast-tsp`` (:func:`solve_fast_tsp`) and ``lkh`` (:func:`solve_lkh`): outside solvers, optional
  packages (fast-tsp, MIT; elkai running LKH-3, non-commercial use only).

Instances may be closed tours or open paths with a fixed end, from any cost matrix
(:meth:`~htetro_opt.problems.SequencingInstance.from_matrix`) or a TSPLIB file
(:func:`htetro_opt.scenarios.tsplib.load_tsplib`; its coordinate types keep their costs implicit at any
size, and the methods that need a matrix get it built within the memory budget). A tileset of more than
:data:`~htetro_opt.problems.waypoint_sequencing.DENSE_LIMIT` waypoints keeps its eq.-2 costs
implicit (no n × n matrix, memory linear in n); ``ils`` (and so ``auto``) sequences it, the other
methods ask for ``from_tileset(..., dense=True)``.
"""

from htetro_opt._lazy import attach

__getattr__, __dir__, __all__ = attach(__name__, {
    "sequence_waypoints": "._dispatch", "SequenceResult": "._dispatch", "SPEC": "._spec",
    "EXACT_AUTO_LIMIT": "._spec", "ASYMMETRIC_METHODS": "._dispatch",
    "auto_method": "._dispatch", "MATRIX_BYTES_PER_ENTRY": "._dispatch", "MATRIX_BYTES_DEFAULT": "._dispatch",
    "default_time_limit": "._budgets", "TIME_LIMIT_TEXT": "._budgets",
    "solve_exact": "._exact", "held_karp": "._exact", "EXACT_MAX_SIZE": "._spec",
    "solve_ortools": "._ortools", "ortools_time_limit": "._ortools", "FIRST_SOLUTIONS": "._spec",
    "solve_local": "._local", "nearest_neighbour": "._local", "nearest_neighbour_paths": "._local",
    "two_opt": "._local", "or_opt": "._local", "improve": "._local", "improve_batch": "._local",
    "double_bridge": "._local",
    "solve_ga": "._ga", "make_toolbox": "._ga",
    "solve_zigzag": "._baselines", "solve_spiral": "._baselines", "solve_greedy": "._baselines",
    "PATTERN_VARIANTS": "._baselines",
    "solve_ils": "._ils", "ils_kicks": "._ils", "ILS_NEIGHBOURS": "._spec", "ILS_KICK_SPAN": "._ils",
    "solve_fast_tsp": "._backends", "solve_lkh": "._backends", "CANDIDATE_LISTS": "._spec",
})
