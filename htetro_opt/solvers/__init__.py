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

Each task declares itself once in its spec (``SPEC`` of each subpackage, :mod:`htetro_opt._spec`):
its methods, their options, defaults and capabilities; :data:`TASKS` names the five. Every result
extends :class:`Result` (``method``, ``success``, ``message``, ``runtime_s``, ``info``, ``as_dict()``).

The subpackages load lazily: importing one does not import the others' dependencies.
"""

from htetro_opt._lazy import attach

__getattr__, __dir__, __all__ = attach(__name__, {
    "plan_path": ".grid_paths", "plan_exact": ".grid_paths", "plan_ga": ".grid_paths", "Plan": ".grid_paths",
    "tile_workspace": ".tiling", "enumerate_tilings": ".tiling", "find_tiles": ".tiling",
    "TilingResult": ".tiling",
    "sequence_waypoints": ".sequencing", "SequenceResult": ".sequencing",
    "plan_coverage": ".coverage", "CoveragePlan": ".coverage",
    "plan_continuous": ".continuous", "ContinuousPlan": ".continuous",
    "Result": "._result", "TASKS": "._tasks",
})
