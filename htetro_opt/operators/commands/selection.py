"""Deterministic tournament on rank, then crowding distance (the paper's parent choice, size 4)."""

from __future__ import annotations

import numpy as np
from pymoo.operators.selection.tournament import TournamentSelection

__all__ = ["RankAndCrowdingTournament", "rank_and_crowding_tournament"]


def rank_and_crowding_tournament(pop, P, random_state=None, **kwargs) -> np.ndarray:
    """The winner of each row of ``P``: the lowest rank, ties broken by the largest crowding distance.

    Individuals must carry ``rank`` and ``crowding`` (set by the survival). Among full ties the first
    competitor wins; pymoo draws the competitors at random, so this is not biased.
    """
    P = np.asarray(P)
    rank = pop.get("rank")[P].astype(float)
    crowding = np.nan_to_num(pop.get("crowding")[P].astype(float), nan=0.0)
    best = rank == rank.min(axis=1, keepdims=True)
    winner = np.where(best, crowding, -np.inf).argmax(axis=1)
    return P[np.arange(len(P)), winner]


class RankAndCrowdingTournament(TournamentSelection):
    """Deterministic tournament selection of size ``pressure`` (the paper's 4) on rank and crowding."""

    def __init__(self, pressure: int = 4) -> None:
        super().__init__(func_comp=rank_and_crowding_tournament, pressure=pressure)
