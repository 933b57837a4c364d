"""Solvers assembled on the shared model.

- Seed 000: the exact planner, the hTetro-GA and the command-chromosome planner that runs it (or
  pymoo's own algorithms) leg by leg.
- Seed 003: tetromino tiling (backtracking, CP-SAT), and waypoint sequencing by the exact CP-SAT
  optimum, OR-Tools routing, local search, the paper's GA on DEAP (plain or memetic) and the
  zigzag / spiral / greedy baselines, all behind :func:`sequence_waypoints`.
"""

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
from htetro_opt.solvers.sequencing import EXACT_AUTO_LIMIT, SEQUENCE_SOLVERS, SequenceResult, sequence_waypoints
from htetro_opt.solvers.termination import FrontConvergence, leading_front
from htetro_opt.solvers.tiling import TILING_SOLVERS, enumerate_tilings, find_tiles, tile_workspace
from htetro_opt.solvers.tsp_baselines import solve_greedy, solve_spiral, solve_zigzag
from htetro_opt.solvers.tsp_exact import held_karp, solve_exact
from htetro_opt.solvers.tsp_ga import solve_ga
from htetro_opt.solvers.tsp_local import improve, nearest_neighbour, solve_local
from htetro_opt.solvers.tsp_ortools import solve_ortools

__all__ = [
    "ALGORITHMS", "Plan", "plan_exact",
    "GA_ALGORITHMS", "SELECTIONS", "ConvergenceRecorder", "FrontMember", "GAPlan", "LegResult",
    "make_algorithm", "plan_ga", "select_solutions",
    "HTetroGA", "trim_reached",
    "FrontConvergence", "leading_front",
    "TILING_SOLVERS", "enumerate_tilings", "find_tiles", "tile_workspace",
    "EXACT_AUTO_LIMIT", "SEQUENCE_SOLVERS", "SequenceResult", "sequence_waypoints",
    "solve_exact", "held_karp", "solve_ortools", "solve_local", "nearest_neighbour", "improve",
    "solve_ga", "solve_zigzag", "solve_spiral", "solve_greedy",
]
