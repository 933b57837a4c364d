"""Mutation: each command becomes, with rate r_mu, a random command of the full set (non-conservative)."""

from __future__ import annotations

import numpy as np
from pymoo.core.mutation import Mutation

from htetro_opt._validation import check_probability, check_real
from htetro_opt.operators.commands._chromosome import Flat, as_column, sequences

__all__ = ["CommandMutation", "mutate_commands"]


def mutate_commands(rng: np.random.Generator, seqs: list[np.ndarray], *, rate: float, commands: np.ndarray) -> list[np.ndarray]:
    """Replace each command, with probability ``rate``, by one drawn uniformly from ``commands``.

    The draw may return the same command. Returns new arrays; the inputs are not modified.

    Examples
    --------
    >>> rng = np.random.default_rng(1)
    >>> [s] = mutate_commands(rng, [np.zeros(5, dtype=np.int64)], rate=1.0, commands=np.array([7]))
    >>> s.tolist()
    [7, 7, 7, 7, 7]
    """
    flat = Flat(seqs)
    genes = flat.genes
    hit = rng.random(len(genes)) < rate
    genes[hit] = rng.choice(np.asarray(commands, dtype=np.int64), size=int(hit.sum()))
    return flat.split(genes)


class CommandMutation(Mutation):
    """The paper's mutation, rate r_mu = 1 / l_p,max per command by default.

    Parameters
    ----------
    rate : float, optional
        Per-command rate; default ``1 / problem.max_length``.
    prob : float, keyword-only
        pymoo's per-individual probability that the mutation is applied at all (the paper: 1).

    Raises
    ------
    ParameterError
        If ``rate`` or ``prob`` is not a probability.
    """

    def __init__(self, rate: float | None = None, *, prob: float = 1.0) -> None:
        super().__init__(prob=check_probability(prob, "mutation prob"))
        self.rate = check_real(rate, "mutation rate", minimum=0.0, maximum=1.0, allow_none=True)

    def _do(self, problem, X, *args, random_state=None, **kwargs):
        rate = self.rate if self.rate is not None else 1.0 / problem.max_length
        return as_column(mutate_commands(random_state, sequences(X), rate=rate, commands=problem.command_ids))
