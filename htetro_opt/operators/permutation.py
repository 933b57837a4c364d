"""Permutation operators for DEAP over waypoint orders (the GA of Le et al. 2018).

DEAP's own operators (``tools.cxOrdered``, ``tools.mutShuffleIndexes``, ``tools.selTournament``) draw
from the global ``random`` module; these take a private ``random.Random`` instead, so that a run is
reproducible for a seed and leaves the global state alone. Individuals are :class:`Tour` lists with
a :class:`TourFitness` (DEAP's convention, without ``deap.creator``).
"""

from __future__ import annotations

import random
from operator import attrgetter

from deap import base

__all__ = ["Tour", "TourFitness", "order_crossover", "select_tournament", "swap_mutation"]


class TourFitness(base.Fitness):
    """A DEAP fitness minimising the path cost (one objective)."""

    weights = (-1.0,)


class Tour(list):
    """An individual: a list of waypoint indices with a :class:`TourFitness` (DEAP's convention,
    without ``deap.creator``).

    Examples
    --------
    >>> t = Tour([2, 0, 1])
    >>> t.fitness.valid, t.fitness.weights
    (False, (-1.0,))
    """

    def __init__(self, genes=()):
        super().__init__(genes)
        self.fitness = TourFitness()

    def copy(self) -> Tour:
        """A copy with a copy of the fitness (what the toolbox's ``clone`` does)."""
        twin = Tour(self)
        if self.fitness.valid:
            twin.fitness.values = self.fitness.values
        return twin


def swap_mutation(individual, rng: random.Random):
    """The paper's mutation: swap two distinct random genes, in place.

    Parameters
    ----------
    individual : mutable sequence
        A permutation (shorter than two genes: left as is).
    rng : random.Random
        The source of randomness.

    Returns
    -------
    tuple
        ``(individual,)``, as DEAP's mutations do. The fitness is not touched: invalidate it.

    Examples
    --------
    >>> swap_mutation([0, 1, 2, 3], random.Random(5))
    ([0, 1, 3, 2],)
    """
    if len(individual) >= 2:
        i, j = rng.sample(range(len(individual)), 2)
        individual[i], individual[j] = individual[j], individual[i]
    return (individual,)


def order_crossover(ind1, ind2, rng: random.Random):
    """Linear order crossover (OX for open paths), in place on both parents.

    A random slice ``[a, b)`` is kept in place from one parent; the other positions take the
    remaining genes *left to right* in the other parent's order (classic OX fills cyclically from
    ``b``, which suits closed tours; a path has a beginning, so this variant keeps the other
    parent's genes near their positions). The genes exclude a fixed start, which thus stays first.

    Parameters
    ----------
    ind1, ind2 : mutable sequence
        Permutations of the same genes.
    rng : random.Random

    Returns
    -------
    tuple
        ``(ind1, ind2)``, now the two children. Fitnesses are not touched.

    Examples
    --------
    >>> order_crossover([0, 1, 2, 3, 4, 5], [5, 4, 3, 2, 1, 0], random.Random(5))  # keeps slice [2, 4)
    ([5, 4, 2, 3, 1, 0], [0, 1, 3, 2, 4, 5])
    """
    n = len(ind1)
    if n >= 2:
        a, b = sorted(rng.sample(range(n + 1), 2))
        p1, p2 = list(ind1), list(ind2)
        ind1[:] = _linear_ox(p1, p2, a, b)
        ind2[:] = _linear_ox(p2, p1, a, b)
    return ind1, ind2


def _linear_ox(keep: list, fill: list, a: int, b: int) -> list:
    kept = set(keep[a:b])
    rest = [g for g in fill if g not in kept]
    return rest[:a] + keep[a:b] + rest[a:]


def select_tournament(individuals, k: int, rng: random.Random, tournsize: int) -> list:
    """``k`` winners of tournaments among ``tournsize`` individuals drawn with replacement.

    Like ``deap.tools.selTournament`` (the best fitness wins, the first drawn on ties) but drawing
    from ``rng``. Returns references, not copies.

    Examples
    --------
    >>> pop = [Tour([i]) for i in range(4)]
    >>> for t, c in zip(pop, [3.0, 1.0, 2.0, 4.0]):
    ...     t.fitness.values = (c,)
    >>> [t[0] for t in select_tournament(pop, 4, random.Random(1), 3)]  # tour 1 is the cheapest
    [1, 0, 1, 0]
    """
    fitness = attrgetter("fitness")
    return [max((rng.choice(individuals) for _ in range(tournsize)), key=fitness) for _ in range(k)]
