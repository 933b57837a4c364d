"""pymoo's mutation and crossover ``do()`` on a list of chromosomes, without a ``Population``.

A pymoo ``Population`` holds one Python object per individual, and building one costs more than the
command operators themselves: :class:`~htetro_opt.algorithms.HTetroGA` keeps its chromosomes in a
list and applies its operators through these functions. Each does what the operator's pymoo
``do()`` does (the same calls of ``_do``, the same draws for pymoo's ``prob``, the same offspring)
for an operator that keeps pymoo's ``do()``; an operator that overrides ``do()`` is run through it on a
``Population``, so a user's operator behaves as under any pymoo algorithm.
"""

from __future__ import annotations

import numpy as np
from pymoo.core.crossover import Crossover
from pymoo.core.mutation import Mutation
from pymoo.core.population import Population
from pymoo.core.variable import get

from htetro_opt.operators.commands._chromosome import as_column, sequences

__all__ = ["apply_mutation", "apply_crossover"]


def apply_mutation(operator: Mutation, problem, seqs: list[np.ndarray], *,
                   random_state: np.random.Generator) -> list[np.ndarray]:
    """``operator.do(problem, pop, random_state=random_state)`` on the chromosomes ``seqs``.

    Examples
    --------
    >>> from htetro_opt.operators import CommandMutation
    >>> from htetro_opt.problems import CommandPathProblem
    >>> from htetro_opt.model import Pose, Workspace
    >>> problem = CommandPathProblem(Workspace(np.zeros((8, 8), dtype=bool)), Pose(2, 2, "O", 0),
    ...                              Pose(4, 4, "O", 0), max_length=4)
    >>> seqs = [np.zeros(4, dtype=np.int64)] * 3
    >>> ours = apply_mutation(CommandMutation(1.0, prob=0.5), problem, seqs, random_state=np.random.default_rng(1))
    >>> pop = CommandMutation(1.0, prob=0.5).do(problem, Population.new("X", as_column(seqs)),
    ...                                         random_state=np.random.default_rng(1))
    >>> [s.tolist() for s in ours] == [s.tolist() for s in sequences(pop.get("X"))]
    True
    """
    if type(operator).do is not Mutation.do:
        return sequences(operator.do(problem, Population.new("X", as_column(seqs)), random_state=random_state).get("X"))
    n = len(seqs)
    mutated = operator._do(problem, as_column(seqs), random_state=random_state)
    applied = random_state.random(size=n) <= get(operator.prob, size=n)
    return [mutated[i, 0] if applied[i] else seqs[i] for i in range(n)]


def apply_crossover(operator: Crossover, problem, seqs: list[np.ndarray], matings: np.ndarray, *,
                    random_state: np.random.Generator) -> list[np.ndarray]:
    """``operator.do(problem, pop, matings, random_state=random_state).get("X")`` on the chromosomes
    ``seqs``: the offspring of the rows of ``matings`` (indices into ``seqs``, one row of
    ``n_parents`` per mating), every mating's first offspring, then every mating's second, ….

    Examples
    --------
    >>> from htetro_opt.operators import CommandCrossover
    >>> from htetro_opt.problems import CommandPathProblem
    >>> from htetro_opt.model import Pose, Workspace
    >>> problem = CommandPathProblem(Workspace(np.zeros((8, 8), dtype=bool)), Pose(2, 2, "O", 0),
    ...                              Pose(4, 4, "O", 0), max_length=4)
    >>> seqs, matings = [np.arange(4), np.arange(5, 9)], np.array([[0, 1], [1, 0]])
    >>> ours = apply_crossover(CommandCrossover(0.5), problem, seqs, matings, random_state=np.random.default_rng(2))
    >>> off = CommandCrossover(0.5).do(problem, Population.new("X", as_column(seqs)), matings,
    ...                                random_state=np.random.default_rng(2))
    >>> [s.tolist() for s in ours] == [s.tolist() for s in sequences(off.get("X"))]
    True
    """
    matings = np.asarray(matings, dtype=np.int64)
    if type(operator).do is not Crossover.do:
        off = operator.do(problem, Population.new("X", as_column(seqs)), matings, random_state=random_state)
        return sequences(off.get("X"))
    n_matings, n_parents = matings.shape
    n_offsprings = operator.n_offsprings
    X = np.empty((n_parents, n_matings, 1), dtype=object)
    for (m, p), i in np.ndenumerate(matings):  # one by one: numpy would stack equal-length arrays
        X[p, m, 0] = seqs[i]
    if operator.vtype is not None:
        X = X.astype(operator.vtype)
    Xp = np.empty((n_offsprings, n_matings, 1), dtype=X.dtype)
    crossed = random_state.random(n_matings) < get(operator.prob, size=n_matings)
    if crossed.any():
        Q = operator._do(problem, X, random_state=random_state)
        Xp[:, crossed] = Q[:, crossed]
    for k in np.flatnonzero(~crossed):  # pymoo's choice of the parents copied where no crossover happens
        if n_offsprings < n_parents:
            s = random_state.choice(np.arange(n_parents), size=n_offsprings, replace=False)
        elif n_offsprings == n_parents:
            s = np.arange(n_parents)
        else:
            s = []
            while len(s) < n_offsprings:
                s.extend(random_state.permutation(n_parents))
            s = s[:n_offsprings]
        Xp[:, k] = np.copy(X[s, k])
    return sequences(Xp.reshape(-1, 1))
