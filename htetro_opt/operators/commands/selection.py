"""Deterministic tournament on rank, then crowding distance (the paper's parent choice, size 4)."""

from __future__ import annotations

import math

import numpy as np
from pymoo.operators.selection.tournament import TournamentSelection
from pymoo.util.misc import random_permutations

__all__ = ["RankAndCrowdingTournament", "rank_and_crowding_tournament", "rank_and_crowding_winners"]


def rank_and_crowding_winners(rank: np.ndarray, crowding: np.ndarray, P: np.ndarray) -> np.ndarray:
    """The winner of each row of competitors ``P`` (indices into ``rank`` and ``crowding``): the
    lowest rank, ties broken by the largest crowding distance (NaN counts as 0).

    Among full ties the first competitor wins; the competitors are drawn at random, so this is not
    biased.

    Examples
    --------
    >>> rank_and_crowding_winners(np.array([1, 0, 0]), np.array([9.0, 1.0, np.inf]), np.array([[0, 1, 2]]))
    array([2])
    """
    P = np.asarray(P)
    rank = np.asarray(rank)[P].astype(float)
    crowding = np.nan_to_num(np.asarray(crowding)[P].astype(float), nan=0.0)
    best = rank == rank.min(axis=1, keepdims=True)
    winner = np.where(best, crowding, -np.inf).argmax(axis=1)
    return P[np.arange(len(P)), winner]


def rank_and_crowding_tournament(pop, P, random_state=None, **kwargs) -> np.ndarray:
    """pymoo's comparison function: :func:`rank_and_crowding_winners` of a population whose
    individuals carry ``rank`` and ``crowding`` (set by the survival)."""
    return rank_and_crowding_winners(pop.get("rank"), pop.get("crowding"), P)


class RankAndCrowdingTournament(TournamentSelection):
    """Deterministic tournament selection of size ``pressure`` (the paper's 4) on rank and crowding."""

    def __init__(self, pressure: int = 4) -> None:
        super().__init__(func_comp=rank_and_crowding_tournament, pressure=pressure)

    def select(self, rank: np.ndarray, crowding: np.ndarray, n_select: int, n_parents: int, *,
               random_state: np.random.Generator) -> np.ndarray:
        """The selection on arrays: row indices of shape ``(n_select, n_parents)``.

        The same draws and winners as pymoo's ``do(problem, pop, n_select, n_parents, to_pop=False)``
        on a population with this ``rank`` and ``crowding`` (pymoo's tournament: competitors from
        consecutive random permutations of the population).
        """
        n_random = n_select * n_parents * self.pressure
        n_perms = math.ceil(n_random / len(rank))
        P = random_permutations(n_perms, len(rank), random_state=random_state)[:n_random]
        winners = rank_and_crowding_winners(rank, crowding, np.reshape(P, (n_select * n_parents, self.pressure)))
        return np.reshape(winners, (n_select, n_parents))
