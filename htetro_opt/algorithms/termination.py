"""Termination of the command-chromosome GAs: a generation cap or a converged leading front."""

from __future__ import annotations

import numpy as np
from pymoo.core.termination import Termination

from htetro_opt._validation import check_int, check_real
from htetro_opt.operators.commands.survival import reaches_goal

__all__ = ["FrontConvergence"]


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
        Whether the run stopped by convergence (rather than by ``max_gen``). pymoo's ``minimize``
        works on a copy of the termination, so the run also reports it on its result:
        ``res.data["converged"]``.

    Raises
    ------
    ParameterError
        If ``max_gen`` or ``patience`` is not a positive integer, or ``tolerance`` is negative.

    Examples
    --------
    >>> from pymoo.optimize import minimize
    >>> from htetro_opt.algorithms import HTetroGA
    >>> from htetro_opt.model import Pose, Workspace
    >>> from htetro_opt.problems import CommandPathProblem
    >>> problem = CommandPathProblem(Workspace(np.zeros((8, 8), dtype=bool)), Pose(2, 2, "O", 0),
    ...                              Pose(4, 4, "O", 0), max_length=10)
    >>> res = minimize(problem, HTetroGA(pop_size=20), FrontConvergence(max_gen=500, patience=10), seed=1)
    >>> res.data["converged"], res.algorithm.n_gen < 500
    (True, True)
    """

    def __init__(self, max_gen: int = 1000, patience: int = 100, tolerance: float = 1e-9) -> None:
        super().__init__()
        self.max_gen = check_int(max_gen, "max_gen", minimum=1)
        self.patience = check_int(patience, "patience", minimum=1)
        self.tolerance = check_real(tolerance, "tolerance", minimum=0.0)
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
        algorithm.data["converged"] = self.converged
        return min(progress, 1.0)
