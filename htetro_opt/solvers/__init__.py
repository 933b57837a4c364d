"""Solvers assembled on the shared model: the exact planner, the hTetro-GA (seed 000) and the
command-chromosome planner that runs it, or pymoo's own algorithms, leg by leg."""

from htetro_opt.solvers.exact import ALGORITHMS, Plan, plan_exact
from htetro_opt.solvers.ga import (
    GA_ALGORITHMS,
    SELECTIONS,
    ConvergenceRecorder,
    FrontMember,
    GAPlan,
    LegResult,
    make_algorithm,
    plan_ga,
    select_solutions,
)
from htetro_opt.solvers.htetro_ga import HTetroGA, trim_reached
from htetro_opt.solvers.termination import FrontConvergence, leading_front

__all__ = [
    "ALGORITHMS", "Plan", "plan_exact",
    "GA_ALGORITHMS", "SELECTIONS", "ConvergenceRecorder", "FrontMember", "GAPlan", "LegResult",
    "make_algorithm", "plan_ga", "select_solutions",
    "HTetroGA", "trim_reached",
    "FrontConvergence", "leading_front",
]
