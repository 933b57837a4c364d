"""Termination of the command-chromosome GAs: a generation cap or a converged leading front."""

from __future__ import annotations

import numpy as np
from pymoo.core.termination import Termination
from pymoo.util.nds.non_dominated_sorting import NonDominatedSorting

from htetro_opt.errors import ParameterError
from htetro_opt.operators.survival import reaches_goal

__all__ = ["FrontConvergence", "leading_front"]


def leading_front(F: np.ndarray) -> np.ndarray:
    """Indices of the leading front F0: the non-dominated individuals among those reaching the goal
    (f_gr = 1), or among all when none does."""
    F = np.asarray(F, dtype=float)
    reached = np.flatnonzero(reaches_goal(F))
    pool = reached if len(reached) else np.arange(len(F))
    if len(pool) == 0:
        return pool
    front = NonDominatedSorting().do(F[pool], only_non_dominated_front=True)
    return pool[np.sort(front)]


class FrontConvergence(Termination):
    """Stop after ``max_gen`` generations, or once the leading front has stopped improving.

    The front counts as converged when some individual reaches the goal and for ``patience``
    generations in a row neither the best f_t, f_sm or f_sf among the goal-reaching individuals
    nor their best sum of the four fitnesses (the paper's multi-objective solution) has improved.
    (The front's membership itself keeps changing as crowding distance trades equivalent points.)

    Parameters
    ----------
    max_gen : int
        n_pop,max of the paper (1000).
    patience : int
        Generations without improvement that count as convergence.
    tolerance : float
        Smallest increase that counts as an improvement.

    Attributes
    ----------
    converged : bool
        Whether the run stopped by convergence (rather than by ``max_gen``).

    Raises
    ------
    ParameterError
        If ``max_gen`` or ``patience`` is not a positive integer.
    """

    def __init__(self, max_gen: int = 1000, patience: int = 100, tolerance: float = 1e-9) -> None:
        super().__init__()
        for name, value in (("max_gen", max_gen), ("patience", patience)):
            if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
                raise ParameterError(f"{name} must be a positive integer, got {value!r}")
        self.max_gen, self.patience, self.tolerance = int(max_gen), int(patience), tolerance
        self.stall = 0
        self.best: np.ndarray | None = None
        self.converged = False

    def _update(self, algorithm) -> float:
        F = algorithm.pop.get("F")
        progress = algorithm.n_gen / self.max_gen
        reached = reaches_goal(F)
        if reached.any():
            fitness = -F[reached]
            best = np.append(fitness[:, 1:].max(axis=0), fitness.sum(axis=1).max())
            improved = self.best is None or (best > self.best + self.tolerance).any()
            self.best = best if self.best is None else np.maximum(best, self.best)
            self.stall = 0 if improved else self.stall + 1
            self.converged = self.stall >= self.patience
            progress = max(progress, self.stall / self.patience)
        return min(progress, 1.0)
