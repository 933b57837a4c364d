"""Studies: the papers' experiments re-run on this project's solvers, with their published figures beside ours.

- :mod:`htetro_opt.studies.table4`: seed 000's Table 4 (hTetro-GA over six environments and three
  population sizes), plus the gap of every GA plan to the exact minimum-time plan.
- :mod:`htetro_opt.studies.seed003`: seed 003's Tables 1–5 (tiling + waypoint sequencing), with every
  method's gap to the exact optimum.
- :mod:`htetro_opt.studies.coverage`: seed 003's coverage simulation (distance, heat map, re-covered area).
- :mod:`htetro_opt.studies.metrics`: mean ± standard deviation aggregation over trial records.

Studies may use the model, problems, solvers and scenarios, never the plotting or the command line.
"""

from htetro_opt.studies.coverage import CoverageResult, simulate_coverage
from htetro_opt.studies.metrics import (
    format_mean_std,
    group_records,
    mean_std,
    values_of,
)

__all__ = ["CoverageResult", "simulate_coverage", "format_mean_std", "group_records", "mean_std", "values_of"]
