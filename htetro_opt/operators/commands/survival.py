"""The hTetro-GA's goal-reachability sort: individuals that reach the goal survive first."""

from __future__ import annotations

import numpy as np
from pymoo.core.population import Population
from pymoo.core.survival import Survival
from pymoo.operators.survival.rank_and_crowding import RankAndCrowding

from htetro_opt._validation import check_int

__all__ = ["GoalReachabilitySurvival", "reaches_goal"]


def reaches_goal(F: np.ndarray) -> np.ndarray:
    """Which rows of ``F = (−f_gr, …)`` reach the goal (f_gr = 1 exactly)."""
    return np.asarray(F)[:, 0] == -1.0


class GoalReachabilitySurvival(Survival):
    """Survival by the paper's §IV-C: goal reachability first, then fast non-dominated sorting.

    The merged population is split into sections of equal f_gr, highest first: the individuals
    that reach the goal (f_gr = 1), then the others level by level. This is the paper's rule that
    "robot individuals with smaller f_gr values are strictly Pareto-dominated by those with higher
    values": goal reachability has priority over the three other fitnesses. Each section is sorted by
    fast non-dominated sorting, the fronts are concatenated in that order, and the last front that
    does not fit is cut by crowding distance.

    **End-pose niching** (ours, ``niche_size``): among the individuals that do not reach the goal, at
    most ``niche_size`` ending on the same pose keep their level (those with the largest
    f_t + f_sm + f_sf); the others are placed after every level. Without it the whole population
    soon ends on one pose in front of an obstacle that the grid distance W_A* cannot see (it ignores
    the robot's footprint), and the detour needed to get round it is never kept. Individuals must
    carry ``end`` (the final pose id, set by :class:`~htetro_opt.problems.CommandPathProblem`);
    ``niche_size=0`` switches niching off (the paper's sort as written).

    NSGA-II's crowding distance keeps the *least* crowded individuals of the last front; the paper's
    text says "small crowding distances", which contradicts the NSGA-II it cites, and we follow
    NSGA-II. Every survivor gets ``rank`` (0 = leading front) and ``crowding``.
    """

    def __init__(self, niche_size: int = 3, nds=None, crowding_func: str = "cd") -> None:
        super().__init__(filter_infeasible=True)
        self.niche_size = check_int(niche_size, "niche_size", minimum=0)
        self.ranking = RankAndCrowding(nds=nds, crowding_func=crowding_func)

    def _levels(self, pop) -> np.ndarray:
        """−f_gr of each individual, with individuals beyond their niche pushed after every level."""
        F = pop.get("F")
        levels = F[:, 0].copy()
        if self.niche_size:
            unreached = np.flatnonzero(levels != -1.0)
            ends = pop.get("end")[unreached].astype(np.int64)
            by_end = np.lexsort((F[unreached, 1:].sum(axis=1), ends))  # best (lowest −sum) first per end
            order, sorted_ends = unreached[by_end], ends[by_end]
            starts = np.r_[True, sorted_ends[1:] != sorted_ends[:-1]]
            group_start = np.maximum.accumulate(np.where(starts, np.arange(len(order)), 0))
            excess = order[np.arange(len(order)) - group_start >= self.niche_size]
            levels[excess] += 2.0  # −f_gr lies in [−1, 0]: +2 puts them after every level, in order
        return levels

    def _do(self, problem, pop, *args, n_survive=None, random_state=None, **kwargs):
        n_survive = len(pop) if n_survive is None else n_survive
        levels = self._levels(pop)
        survivors, n_kept, n_ranks = [], 0, 0
        for level in np.unique(levels):  # ascending −f_gr: the highest f_gr first
            if n_kept >= n_survive:
                break
            section = np.flatnonzero(levels == level)
            take = min(n_survive - n_kept, len(section))
            kept = self.ranking.do(problem, pop[section], n_survive=take, random_state=random_state)
            ranks = kept.get("rank") + n_ranks
            kept.set("rank", ranks)
            n_ranks = int(ranks.max()) + 1
            n_kept += len(kept)
            survivors.append(kept)
        return survivors[0] if len(survivors) == 1 else Population.merge(*survivors)
