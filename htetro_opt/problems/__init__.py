"""Formal problem definitions, one module per paper, on the shared model.

- :mod:`~htetro_opt.problems.command_path` (seed 000): variable-length motion-command chromosomes
  with the four fitnesses of eqs. 3–6, as a pymoo problem.
- :mod:`~htetro_opt.problems.waypoint_sequencing` (seed 003): tile waypoints (Algorithm 1), the
  eq.-2 block-displacement cost and the open-path TSP over them, for every sequencing solver.
"""

from htetro_opt.problems.command_path import (
    FITNESS_NAMES,
    SAFETY_COEFFICIENT,
    SAFETY_PATTERN,
    CommandPathProblem,
    safety_field,
)
from htetro_opt.problems.waypoint_sequencing import (
    DEFAULT_WEIGHTS,
    SequencingInstance,
    SequencingProblem,
    block_locations,
    check_weights,
    cost_matrix,
    path_cost,
)

__all__ = [
    "CommandPathProblem", "FITNESS_NAMES", "SAFETY_COEFFICIENT", "SAFETY_PATTERN", "safety_field",
    "DEFAULT_WEIGHTS", "SequencingInstance", "SequencingProblem", "block_locations", "check_weights",
    "cost_matrix", "path_cost",
]
