"""Solvers assembled on the shared model: the exact planner (and, in later issues, the GAs and baselines)."""

from htetro_opt.solvers.exact import ALGORITHMS, Plan, plan_exact

__all__ = ["ALGORITHMS", "Plan", "plan_exact"]
