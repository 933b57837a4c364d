"""Solvers, one subpackage per planning task, each with one entry point taking ``method=``.

- :mod:`~htetro_opt.solvers.grid_paths`: :func:`plan_path` (exact Dijkstra / A*, the hTetro-GA of
  Cheng et al. 2020 and pymoo's algorithms over command chromosomes);
- :mod:`~htetro_opt.solvers.tiling`: :func:`tile_workspace` (Le et al. 2018: backtracking, CP-SAT);
- :mod:`~htetro_opt.solvers.sequencing`: :func:`sequence_waypoints` (Le et al. 2018: exact,
  OR-Tools, local search, the paper's GA, baselines);
- :mod:`~htetro_opt.solvers.coverage`: :func:`plan_coverage` (Cheng et al. 2019: stripes, regions and
  an auxiliary DAG; a boustrophedon baseline);
- :mod:`~htetro_opt.solvers.continuous`: :func:`plan_continuous` (Nazarahari et al. 2019: the exact
  visibility-graph reference, lattice A*).

The subpackages load lazily: importing one does not import the others' dependencies.
"""

from htetro_opt._lazy import attach

__getattr__, __dir__, __all__ = attach(__name__, {
    "plan_path": ".grid_paths", "plan_exact": ".grid_paths", "plan_ga": ".grid_paths", "Plan": ".grid_paths",
    "PLAN_METHODS": ".grid_paths",
    "tile_workspace": ".tiling", "enumerate_tilings": ".tiling", "find_tiles": ".tiling", "TILING_METHODS": ".tiling",
    "sequence_waypoints": ".sequencing", "SequenceResult": ".sequencing", "SEQUENCE_METHODS": ".sequencing",
    "plan_coverage": ".coverage", "CoveragePlan": ".coverage", "COVERAGE_METHODS": ".coverage",
    "plan_continuous": ".continuous", "ContinuousPlan": ".continuous", "CONTINUOUS_METHODS": ".continuous",
})
