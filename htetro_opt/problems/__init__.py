"""Formal problem definitions, one module per paper, on the shared model.

- :mod:`~htetro_opt.problems.command_path` (seed 000): variable-length motion-command chromosomes
  with the four fitnesses of eqs. 3–6, as a pymoo problem.
"""

from htetro_opt.problems.command_path import (
    FITNESS_NAMES,
    SAFETY_COEFFICIENT,
    SAFETY_PATTERN,
    CommandPathProblem,
    safety_field,
)

__all__ = ["CommandPathProblem", "FITNESS_NAMES", "SAFETY_COEFFICIENT", "SAFETY_PATTERN", "safety_field"]
