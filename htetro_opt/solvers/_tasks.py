"""The five tasks' specs, by name, and the command-line verbs that run them; importing this loads no
solver, only the declarations (:mod:`htetro_opt._spec`)."""

from __future__ import annotations

from htetro_opt.solvers.continuous._spec import SPEC as CONTINUOUS
from htetro_opt.solvers.coverage._spec import SPEC as COVERAGE
from htetro_opt.solvers.grid_paths._spec import SPEC as GRID_PATHS
from htetro_opt.solvers.sequencing._spec import SPEC as SEQUENCING
from htetro_opt.solvers.tiling._spec import SPEC as TILING

__all__ = ["TASKS", "VERBS"]

TASKS = {"grid_paths": GRID_PATHS, "continuous": CONTINUOUS, "tiling": TILING, "sequencing": SEQUENCING,
         "coverage": COVERAGE}
"""Every task's spec, by the name of its solver package."""

VERBS = {"plan": (GRID_PATHS, CONTINUOUS), "tile": (TILING,), "sequence": (SEQUENCING,), "cover": (COVERAGE,)}
"""The command-line verbs (and study tasks) and the specs each runs: ``plan`` runs the grid-path task on
grid scenarios and the continuous one on continuous scenarios."""
