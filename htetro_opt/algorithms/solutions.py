"""The leading front of a command-chromosome population and the paper's four output solutions.

:func:`leading_front` is F0 (the goal-reaching individuals' non-dominated set, or everyone's when none
reaches), :func:`select_solutions` picks Cheng et al. 2020's four solutions from it, and
:class:`ConvergenceRecorder` logs them per generation under any pymoo algorithm (the paper's Fig. 10).
"""

from __future__ import annotations

import time as _time

import numpy as np
from pymoo.core.callback import Callback
from pymoo.util.nds.non_dominated_sorting import NonDominatedSorting

from htetro_opt.errors import PlanningError
from htetro_opt.operators.commands.survival import reaches_goal

__all__ = ["leading_front", "select_solutions", "ConvergenceRecorder"]


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


def select_solutions(F: np.ndarray) -> dict[str, int]:
    """Indices of the paper's four output solutions among a population's objective values.

    Parameters
    ----------
    F : ndarray, shape (n, 4)
        Objectives ``(−f_gr, −f_t, −f_sm, −f_sf)``.

    Returns
    -------
    dict
        ``{"multi_objective", "time", "smoothness", "safety"}`` → row index, all taken from the
        leading front (the goal-reaching individuals' non-dominated set, or everyone's when none
        reaches). Ties go to the shorter time, then the lower index.

    Examples
    --------
    >>> F = -np.array([[1.0, 0.6, 0.5, 0.2], [1.0, 0.5, 0.9, 0.3], [0.5, 0.9, 0.9, 0.9]])
    >>> select_solutions(F)
    {'multi_objective': 1, 'time': 0, 'smoothness': 1, 'safety': 1}
    """
    F = np.asarray(F, dtype=float)
    front = leading_front(F)
    if len(front) == 0:
        raise PlanningError("cannot select solutions from an empty population")
    fitness = -F[front]

    def best(score: np.ndarray) -> int:
        order = np.lexsort((front, -fitness[:, 1], -score))  # score desc, f_t desc, index asc
        return int(front[order[0]])

    return {
        "multi_objective": best(fitness.sum(axis=1)),
        "time": best(fitness[:, 1]),
        "smoothness": best(fitness[:, 2]),
        "safety": best(fitness[:, 3]),
    }


class ConvergenceRecorder(Callback):
    """Records, per generation, whether the goal has been reached and the multi-objective solution's
    fitnesses. Works under any pymoo algorithm.

    Parameters
    ----------
    began : float, optional
        ``time.perf_counter()`` at the start of the run (default: now).
    on_generation : callable, optional
        Called after each generation as ``on_generation(generation, best_f_t, reached)``: the best
        f_t among goal-reaching individuals (None while none reaches).
    hv_reference : sequence of 4 float, optional
        With it, ``hv_history`` records per generation the hypervolume (pymoo's ``HV``) of the leading
        front against this reference point, in pymoo's minimisation space F = −(f_gr, f_t, f_sm, f_sf):
        the convergence curve of the whole front, not only of one solution. Off by default (it costs
        an HV computation a generation).
    """

    def __init__(self, began: float | None = None, on_generation=None, hv_reference=None) -> None:
        super().__init__()
        self.began = _time.perf_counter() if began is None else began
        self.on_generation = on_generation
        self.hv_reference = None if hv_reference is None else np.asarray(hv_reference, dtype=float)
        self.hv_history: list[float] = []
        self.reach_generation: int | None = None
        self.reach_time_s: float | None = None
        self.history: list[np.ndarray] = []

    def notify(self, algorithm) -> None:
        F = algorithm.pop.get("F")
        reached = F[:, 0] == -1.0
        if self.reach_generation is None and reached.any():
            self.reach_generation = int(algorithm.n_gen)
            self.reach_time_s = _time.perf_counter() - self.began
        self.history.append(-F[select_solutions(F)["multi_objective"]])
        if self.hv_reference is not None:
            from pymoo.indicators.hv import HV

            self.hv_history.append(float(HV(ref_point=self.hv_reference)(F[leading_front(F)])))
        if self.on_generation is not None:
            best_f_t = float(-F[reached, 1].min()) if reached.any() else None
            self.on_generation(int(algorithm.n_gen), best_f_t, bool(reached.any()))
