"""Single-point crossover of two variable-length command chromosomes (non-conservative)."""

from __future__ import annotations

import numpy as np
from pymoo.core.crossover import Crossover

from htetro_opt._validation import check_int, check_probability
from htetro_opt.operators.commands._chromosome import sequences

__all__ = ["CommandCrossover", "cap_genes", "single_point_crossover"]


def single_point_crossover(
    rng: np.random.Generator, a: np.ndarray, b: np.ndarray, *, max_genes: int | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Cut each parent at its own random point and swap the tails: ``a[:i] + b[j:]``, ``b[:j] + a[i:]``.

    ``i`` and ``j`` are drawn independently and uniformly (0 … len), so the offspring's lengths vary
    (the paper's crossover, Fig. 8b: a cut point in each parent, no bound on the children's length);
    with ``max_genes`` each offspring is cut to at most that many genes (:func:`cap_genes`, ours:
    nothing else stops chromosomes from growing, and genes after a child's goal or first invalid
    command are never scored).

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> c, d = single_point_crossover(rng, np.array([1, 1, 1]), np.array([2, 2]))
    >>> sorted(c.tolist() + d.tolist())
    [1, 1, 1, 2, 2]
    """
    i = int(rng.integers(0, len(a) + 1))
    j = int(rng.integers(0, len(b) + 1))
    first, second = np.concatenate([a[:i], b[j:]]), np.concatenate([b[:j], a[i:]])
    if max_genes is not None:
        first, second = cap_genes(first, max_genes), cap_genes(second, max_genes)
    return first, second


def cap_genes(child: np.ndarray, max_genes: int) -> np.ndarray:
    """The gene cap (ours, the hTetro-GA's ``gene-cap`` addition): ``child`` cut to its first ``max_genes`` genes."""
    return child[:max_genes]


class CommandCrossover(Crossover):
    """The paper's single-point crossover as a pymoo operator: two parents, two offspring.

    Parameters
    ----------
    prob : float
        Probability that a mating crosses over (pymoo's parameter; the hTetro-GA applies its own
        r_cr when choosing whom to mate, and passes 1.0).
    max_genes : int, optional
        Longest offspring, a fixed number of genes (ours).
    length_cap : int, optional, keyword-only
        Longest offspring as a multiple of the problem's l_p,max (ours: the hTetro-GA's ``gene-cap``
        addition and pymoo's algorithms use 2), when ``max_genes`` is not given. Neither given: no
        cap, the paper's.

    Raises
    ------
    ParameterError
        If ``prob`` is not a probability or ``max_genes`` or ``length_cap`` not a positive integer.
    """

    def __init__(self, prob: float = 1.0, *, max_genes: int | None = None, length_cap: int | None = None) -> None:
        super().__init__(n_parents=2, n_offsprings=2, prob=check_probability(prob, "crossover prob"))
        self.max_genes = check_int(max_genes, "max_genes", minimum=1, allow_none=True)
        self.length_cap = check_int(length_cap, "length_cap", minimum=1, allow_none=True)

    def limit(self, problem) -> int | None:
        """The longest offspring on ``problem``, None for no cap."""
        if self.max_genes is not None:
            return self.max_genes
        return None if self.length_cap is None else self.length_cap * problem.max_length

    def _do(self, problem, X, *args, random_state=None, **kwargs):
        _, n_matings, _ = X.shape
        limit = self.limit(problem)
        Y = np.empty((2, n_matings, 1), dtype=object)
        parents_a, parents_b = sequences(X[0]), sequences(X[1])
        for k in range(n_matings):
            Y[0, k, 0], Y[1, k, 0] = single_point_crossover(random_state, parents_a[k], parents_b[k], max_genes=limit)
        return Y
