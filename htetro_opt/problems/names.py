"""The problems' names and plain constants, importable without pymoo (the task specs and the command
line offer them as choices and defaults)."""

from __future__ import annotations

__all__ = ["DEFAULT_PATH_WEIGHTS", "FITNESS_NAMES", "OBJECTIVE_KINDS", "PATH_KINDS", "SAFETY_KINDS"]

FITNESS_NAMES = ("f_gr", "f_t", "f_sm", "f_sf")
"""Cheng et al. 2020's four fitnesses f_gr, f_t, f_sm, f_sf, in objective order."""

PATH_KINDS = ("linear", "spline")
"""How Nazarahari et al. 2019's path bases are joined: straight segments, or a cubic spline."""

SAFETY_KINDS = ("paper", "min")
"""The path-base problem's safety term: eq. 5's sum of the path bases' clearances, or the smallest
clearance along the path."""

OBJECTIVE_KINDS = ("weighted", "separate")
"""The path-base problem's objectives: eq. 6's weighted sum, or length, smoothness and −safety apart."""

DEFAULT_PATH_WEIGHTS = (1.0, 0.0, 0.0)
"""(W_L, W_S, W_R) of eq. 6: length only, the paper's single-objective comparison (§5.2)."""
