"""Studies: the papers' experiments re-run on this project's solvers, their published figures beside ours.

- :mod:`htetro_opt.studies.table4`: Cheng et al. 2020's Table 4 (hTetro-GA over six environments
  and three population sizes), plus the gap of every GA plan to the exact minimum-time plan;
- :mod:`htetro_opt.studies.seed003`: Le et al. 2018's Tables 1–5 (tiling + waypoint sequencing),
  with every method's gap to the exact optimum;
- :mod:`htetro_opt.studies.metrics`: mean ± standard deviation aggregation over trial records.

Studies may use the model, problems, solvers and scenarios, never the plotting or the command line.
"""

from htetro_opt.studies.metrics import format_mean_std, group_records, mean_std, values_of

__all__ = ["format_mean_std", "group_records", "mean_std", "values_of"]
