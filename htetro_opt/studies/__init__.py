"""Studies: the papers' experiments re-run on this project's solvers, their published figures beside ours.

- :mod:`htetro_opt.studies.table4`: Cheng et al. 2020's Table 4 (hTetro-GA over six environments
  and three population sizes), plus the gap of every GA plan to the exact minimum-time plan;
- :mod:`htetro_opt.studies.le2018`: Le et al. 2018's Tables 1–5 (tiling + waypoint sequencing),
  with every method's gap to the exact optimum;
- :mod:`htetro_opt.studies.do2021`: Do et al. 2021's Tables 6–8 and Fig. 13 (the heat-conduction
  planner under four weightings, beside the hTetro-GA, the exact optimum and O-shape-only A* and
  Dijkstra; replanning with hidden obstacles), every plan scored by the paper's costs;
- :mod:`htetro_opt.studies.cheng2019`: Cheng et al. 2019's Table 2 (complete coverage over seven
  morphology sets and two stripe widths, by our reading and by the paper's Alg. 5), its 16 × 7 map,
  two baselines and two larger maps, every plan beside its lower bound;
- :mod:`htetro_opt.studies.nazarahari2019`: Nazarahari et al. 2019's Table 2 (12 continuous maps × A*,
  PRM, B-RRT, PSO and the enhanced GA), §5.1's (IS, PS) pairs, §5.3's weights and four robots, every
  length beside the exact optimum;
- :mod:`htetro_opt.studies.metrics`: mean ± standard deviation aggregation over trial records.

Studies may use the model, problems, solvers and scenarios, never the plotting or the command line.
"""

from htetro_opt.studies.metrics import format_mean_std, group_records, mean_std, values_of

__all__ = ["format_mean_std", "group_records", "mean_std", "values_of"]
