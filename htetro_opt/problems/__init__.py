"""Formal problem definitions, one module per paper, on the shared model.

- :mod:`~htetro_opt.problems.command_path` (Cheng et al. 2020): variable-length motion-command
  chromosomes with the four fitnesses of eqs. 3–6, as a pymoo problem;
- :mod:`~htetro_opt.problems.heat_costs` (Do et al. 2021): the paper's weighted costs (eqs. 9–12, the
  safety of its Fig. 5) of any path, for its heat-conduction planner and for comparing
  every planner on them;
- :mod:`~htetro_opt.problems.waypoint_sequencing` (Le et al. 2018): tile waypoints (Algorithm 1), the
  eq.-2 block-displacement cost and the open-path TSP over them, for every sequencing method, plus
  :class:`SequencingProblem`, the same as a pymoo permutation problem;
- :mod:`~htetro_opt.problems.path_bases` (Nazarahari et al. 2019): a continuous path as its path
  bases (one object variable, K robots jointly), eqs. 4–6 and the multi-robot penalty, as a pymoo
  problem.

Names load lazily, so that importing the sequencing problem does not import pymoo.
"""

from htetro_opt._lazy import attach

__getattr__, __dir__, __all__ = attach(__name__, {
    **{name: ".command_path" for name in
       ("CommandPathProblem", "SAFETY_COEFFICIENT", "SAFETY_PATTERN", "safety_field")},
    **{name: ".names" for name in
       ("FITNESS_NAMES", "PATH_KINDS", "SAFETY_KINDS", "OBJECTIVE_KINDS", "DEFAULT_PATH_WEIGHTS")},
    **{name: ".waypoint_sequencing" for name in
       ("DEFAULT_BLOCK_WEIGHTS", "DENSE_LIMIT", "SequencingInstance", "block_locations", "check_weights",
        "cost_matrix", "eq2_legs", "path_cost", "check_instance")},
    "SequencingProblem": "._sequencing_problem",
    **{name: ".path_bases" for name in
       ("PathBasesProblem", "check_path_weights", "spline_path", "render_path")},
    **{name: ".heat_costs" for name in
       ("HEAT_COST_NAMES", "SAFETY_RADIUS", "check_heat_weights", "default_t_max", "safety_pattern",
        "heat_fitness")},
})
