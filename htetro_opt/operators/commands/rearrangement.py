"""Rearrangement: swap commands pairwise within a chromosome (conservative)."""

from __future__ import annotations

import numpy as np
from pymoo.core.mutation import Mutation

from htetro_opt._validation import check_probability, check_real
from htetro_opt.operators.commands._chromosome import Flat, as_column, sequences

__all__ = ["CommandRearrangement", "rearrange_commands"]


def rearrange_commands(rng: np.random.Generator, seqs: list[np.ndarray], *, rate: float | None = None) -> list[np.ndarray]:
    """Each command, with ``rate`` (r_ra, default 1 / l_p), swaps places with another of its
    chromosome drawn at random, on a batch of chromosomes.

    The multiset of each chromosome's commands, and so B2's total displacement, never changes.
    Returns new arrays.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> [s] = rearrange_commands(rng, [np.array([0, 1, 2, 3])], rate=1.0)
    >>> sorted(s.tolist())
    [0, 1, 2, 3]
    """
    flat = Flat(seqs)
    genes = flat.genes
    size = flat.length[flat.owner]
    picked = np.flatnonzero((rng.random(len(genes)) < flat.rate(rate)) & (size > 1))
    if len(picked):
        first = flat.start[flat.owner[picked]]
        partner = first + flat.other(rng, picked - first, size[picked])
        for i, j in zip(picked.tolist(), partner.tolist()):
            genes[i], genes[j] = genes[j], genes[i]
    return flat.split(genes)


class CommandRearrangement(Mutation):
    """The paper's rearrangement as a pymoo (conservative) mutation.

    Parameters
    ----------
    rate : float, optional
        r_ra per command; default 1 / l_p of each chromosome.
    prob : float, keyword-only
        pymoo's per-individual probability that the operator is applied at all (the paper: 1).

    Raises
    ------
    ParameterError
        If ``rate`` or ``prob`` is not a probability.
    """

    def __init__(self, rate: float | None = None, *, prob: float = 1.0) -> None:
        super().__init__(prob=check_probability(prob, "rearrangement prob"))
        self.rate = check_real(rate, "rearrangement rate", minimum=0.0, maximum=1.0, allow_none=True)

    def _do(self, problem, X, *args, random_state=None, **kwargs):
        return as_column(rearrange_commands(random_state, sequences(X), rate=self.rate))
