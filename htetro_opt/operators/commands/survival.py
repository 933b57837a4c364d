"""The hTetro-GA's goal-reachability sort: individuals that reach the goal survive first."""

from __future__ import annotations

import numpy as np
from pymoo.core.survival import Survival
from pymoo.operators.survival.rank_and_crowding import RankAndCrowding
from pymoo.util.randomized_argsort import randomized_argsort

from htetro_opt._validation import check_bool, check_int, check_real

__all__ = ["GoalReachabilitySurvival", "niche_excess", "reaches_goal", "reachability_levels", "rank_and_crowding"]


def reaches_goal(F: np.ndarray) -> np.ndarray:
    """Which rows of ``F = (−f_gr, …)`` reach the goal (f_gr = 1 exactly)."""
    return np.asarray(F)[:, 0] == -1.0


class GoalReachabilitySurvival(Survival):
    """Survival by the paper's §IV-C (steps 3–5): goal reachability first, then fast non-dominated sorting.

    The paper's sort (``levels=False``, ``niche_size=0``): "goal reachability sort, which sorts the
    entire population into two sections" (step 3), the individuals that reach the goal (f_gr = 1)
    first, then all the others; "fast non-dominated sorting independently in both sections" (step
    4), on the four objectives F = (−f_gr, −f_t, −f_sm, −f_sf) of §IV-C (in the first section f_gr is
    1 throughout, in the second it is one objective among four); the fronts are concatenated in that
    order and pushed to the next population, the last front that does not fit cut by crowding
    distance (step 5).

    **Reach levels** (ours, ``levels=True``): the individuals that do not reach are split further
    into one section per value of f_gr, highest first, each sorted on its own, so that a member
    nearer the goal always survives before one farther from it (a lexicographic reading of step 4's
    "individuals with smaller f_gr values are strictly Pareto-dominated by those with higher
    values"). With two sections only, f_t, f_sm and f_sf of the unreached section reward children
    that stop early as much as f_gr rewards those that get near the goal.

    **End-pose niching** (ours, ``niche_size``): among the individuals that do not reach the goal, at
    most ``niche_size`` ending on the same pose keep their section (those with the largest
    f_t + f_sm + f_sf); the others are placed after every section. Without it the whole population
    soon ends on one pose in front of an obstacle that the grid distance W_A* cannot see (it ignores
    the robot's footprint), and the detour needed to get round it is never kept. Individuals must
    carry ``end`` (the final pose id, set by :class:`~htetro_opt.problems.CommandPathProblem`);
    ``niche_size=0`` switches niching off (the paper's).

    **Reaching share** (ours, ``reach_share``): the goal-reaching section keeps at most this share of
    the survivors (rounded down, at least one) while individuals that do not reach the goal are left
    to fill the rest, so that explorers survive once a first route has reached the goal. 1 (the
    default) is the paper's sort.

    NSGA-II's crowding distance keeps the *least* crowded individuals of the last front; the paper's
    text says "small crowding distances", which contradicts the NSGA-II it cites, and we follow
    NSGA-II. Every survivor gets ``rank`` (0 = leading front) and ``crowding``.
    """

    def __init__(self, niche_size: int = 0, nds=None, crowding_func: str = "cd", *, reach_share: float = 1.0,
                 levels: bool = False) -> None:
        super().__init__(filter_infeasible=True)
        self.niche_size = check_int(niche_size, "niche_size", minimum=0)
        self.reach_share = check_real(reach_share, "reach_share", minimum=0.0, maximum=1.0, include_minimum=False)
        self.levels = check_bool(levels, "levels")
        self.ranking = RankAndCrowding(nds=nds, crowding_func=crowding_func)

    def sections(self, F: np.ndarray, end: np.ndarray) -> np.ndarray:
        """Each row's section key, the sections sorted in ascending key: −1 for the rows that reach the
        goal; with reach levels −f_gr for the others, else 0; the niching's excess after every section."""
        if self.levels:
            return reachability_levels(F, end, self.niche_size)
        sections = np.where(reaches_goal(F), -1.0, 0.0)
        if self.niche_size:
            sections[niche_excess(F, end, self.niche_size)] = 1.0
        return sections

    def sort(self, F: np.ndarray, end: np.ndarray, n_survive: int, *,
             random_state: np.random.Generator) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The sort on arrays: the survivors' rows, in order, with their ``rank`` and ``crowding``.

        ``F`` is the (n, 4) objectives and ``end`` each row's final pose id (read only with niching).
        """
        levels = self.sections(F, end)
        rows, ranks, crowdings, n_kept, n_ranks = [], [], [], 0, 0
        n_reaching = n_survive
        if self.reach_share < 1.0:  # leave room for the others, as far as there are others
            n_others = int((levels != -1.0).sum())
            n_reaching = max(int(self.reach_share * n_survive), n_survive - n_others, 1)
        for level in np.unique(levels):  # ascending: the goal-reaching section first
            if n_kept >= n_survive:
                break
            section = np.flatnonzero(levels == level)
            room = min(n_survive, n_reaching) if level == -1.0 else n_survive
            kept, rank, crowding = rank_and_crowding(F[section], min(room - n_kept, len(section)),
                                                     nds=self.ranking.nds, crowding=self.ranking.crowding_func,
                                                     random_state=random_state)
            rows.append(section[kept])
            ranks.append(rank + n_ranks)
            crowdings.append(crowding)
            n_ranks = int(ranks[-1].max()) + 1
            n_kept += len(kept)
        if not rows:
            return np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros(0)
        return np.concatenate(rows), np.concatenate(ranks), np.concatenate(crowdings)

    def _do(self, problem, pop, *args, n_survive=None, random_state=None, **kwargs):
        n_survive = len(pop) if n_survive is None else n_survive
        F = pop.get("F")
        end = pop.get("end") if self.niche_size else np.zeros(len(pop), dtype=np.int64)
        rows, rank, crowding = self.sort(F, end, n_survive, random_state=random_state)
        survivors = pop[rows]
        survivors.set("rank", rank, "crowding", crowding)
        return survivors


def niche_excess(F: np.ndarray, end: np.ndarray, niche_size: int) -> np.ndarray:
    """The rows that do not reach the goal and lie beyond the ``niche_size`` best (largest
    f_t + f_sm + f_sf) of those ending on the same pose (see :class:`GoalReachabilitySurvival`).

    Examples
    --------
    >>> F = np.array([[-1.0, -0.5, 0, 0], [-0.5, -0.2, 0, 0], [-0.5, -0.3, 0, 0], [-0.5, -0.1, 0, 0]])
    >>> niche_excess(F, np.array([7, 3, 3, 3]), 2).tolist()  # row 3 is its niche's worst
    [3]
    """
    F = np.asarray(F)
    unreached = np.flatnonzero(~reaches_goal(F))
    ends = np.asarray(end)[unreached].astype(np.int64)
    by_end = np.lexsort((F[unreached, 1:].sum(axis=1), ends))  # best (lowest −sum) first per end
    order, sorted_ends = unreached[by_end], ends[by_end]
    starts = np.r_[True, sorted_ends[1:] != sorted_ends[:-1]]
    group_start = np.maximum.accumulate(np.where(starts, np.arange(len(order)), 0))
    return np.sort(order[np.arange(len(order)) - group_start >= niche_size])


def reachability_levels(F: np.ndarray, end: np.ndarray, niche_size: int) -> np.ndarray:
    """The reach levels (ours): −f_gr of each row of ``F``, with the rows beyond their end-pose niche
    pushed after every level (see :class:`GoalReachabilitySurvival`).

    Examples
    --------
    >>> F = np.array([[-1.0, -0.5, 0, 0], [-0.5, -0.2, 0, 0], [-0.5, -0.3, 0, 0], [-0.5, -0.1, 0, 0]])
    >>> reachability_levels(F, np.array([7, 3, 3, 3]), 2).tolist()  # row 3 is its niche's worst
    [-1.0, -0.5, -0.5, 1.5]
    """
    F = np.asarray(F)
    levels = F[:, 0].copy()
    if niche_size:
        levels[niche_excess(F, end, niche_size)] += 2.0  # −f_gr lies in [−1, 0]: +2 puts them after every level
    return levels


def rank_and_crowding(F: np.ndarray, n_survive: int, *, nds, crowding,
                      random_state: np.random.Generator) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """NSGA-II's survival on arrays: the surviving rows of ``F``, their rank and crowding distance.

    pymoo's ``RankAndCrowding`` survival without its population: ``nds`` (pymoo's compiled
    non-dominated sorting) ranks until ``n_survive`` are ranked, ``crowding`` (pymoo's crowding
    function) measures each front, and the front that does not fit keeps its least crowded rows,
    ties broken at random; the same draws and the same survivors, in the same order.

    Examples
    --------
    >>> from pymoo.operators.survival.rank_and_crowding import RankAndCrowding
    >>> ranking = RankAndCrowding()
    >>> F = np.array([[0.0, 1.0], [1.0, 0.0], [0.5, 0.5], [1.0, 1.0]])
    >>> rows, rank, _ = rank_and_crowding(F, 3, nds=ranking.nds, crowding=ranking.crowding_func,
    ...                                   random_state=np.random.default_rng(0))
    >>> sorted(rows.tolist()), rank.tolist()
    ([0, 1, 2], [0, 0, 0])
    """
    F = np.asarray(F).astype(float, copy=False)
    n_survive = min(n_survive, len(F))
    rows, ranks, crowdings = [], [], []
    n_kept = 0
    for k, front in enumerate(nds.do(F, n_stop_if_ranked=n_survive)):
        front = np.asarray(front)
        if n_kept + len(front) > n_survive:
            n_remove = n_kept + len(front) - n_survive
            distance = crowding.do(F[front, :], n_remove=n_remove)
            keep = randomized_argsort(distance, order="descending", method="numpy", random_state=random_state)
            keep = keep[:-n_remove]
        else:
            distance = crowding.do(F[front, :], n_remove=0)
            keep = np.arange(len(front))
        rows.append(front[keep])
        ranks.append(np.full(len(keep), k, dtype=np.int64))
        crowdings.append(np.asarray(distance, dtype=float)[keep])
        n_kept += len(keep)
    if not rows:
        return np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros(0)
    return np.concatenate(rows).astype(np.int64), np.concatenate(ranks), np.concatenate(crowdings)
