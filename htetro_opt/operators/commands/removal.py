"""Removal: drop non-translational commands singly and translations in opposite pairs (conservative)."""

from __future__ import annotations

import numpy as np
from pymoo.core.mutation import Mutation

from htetro_opt._validation import check_probability, check_real
from htetro_opt.operators.commands._chromosome import MOVES, SHIFTS, Flat, as_column, sequences

__all__ = ["CommandRemoval", "remove_commands"]


def remove_commands(
    rng: np.random.Generator,
    seqs: list[np.ndarray],
    *,
    translation_rate: float | None = None,
    other_rate: float | None = None,
) -> list[np.ndarray]:
    """The paper's removal operator on a batch of chromosomes; B2's total displacement never changes.

    Each command that does not move B2 (rotation, shapeshift, …) is removed with ``other_rate``
    (r_rm,nt). Each translation is picked with ``translation_rate`` (r_rm,t) and paired with another
    translation of the same chromosome drawn at random; when the two cancel out (x+ with x−, y+ with
    y−, a diagonal with its opposite) both are removed. Both rates default to 1 / l_p of each
    chromosome. Returns new arrays.

    Examples
    --------
    >>> from htetro_opt.model import parse_commands
    >>> rng = np.random.default_rng(0)
    >>> [s] = remove_commands(rng, [parse_commands("x+,sI,x-")], translation_rate=1, other_rate=1)
    >>> s.tolist()
    []
    """
    flat = Flat(seqs)
    genes = flat.genes
    draws = rng.random(len(genes))
    moves = MOVES[genes]
    keep = moves | (draws >= flat.rate(other_rate))
    translations = np.flatnonzero(moves)
    owner = flat.owner[translations]
    count = np.bincount(owner, minlength=len(flat.length))
    first = np.cumsum(count) - count
    picked = np.flatnonzero((draws[translations] < flat.rate(translation_rate)[translations]) & (count[owner] > 1))
    if len(picked):
        group = owner[picked]
        partner = first[group] + flat.other(rng, picked - first[group], count[group])
        p, q = translations[picked], translations[partner]
        cancel = ~(SHIFTS[genes[p]] + SHIFTS[genes[q]]).any(axis=1)
        for a, b in zip(p[cancel].tolist(), q[cancel].tolist()):
            if keep[a] and keep[b]:
                keep[a] = keep[b] = False
    return flat.split(genes, keep)


class CommandRemoval(Mutation):
    """The paper's removal as a pymoo (conservative) mutation.

    Parameters
    ----------
    translation_rate, other_rate : float, optional
        r_rm,t and r_rm,nt; default 1 / l_p of each chromosome.
    prob : float, keyword-only
        pymoo's per-individual probability that the operator is applied at all (the paper: 1).

    Raises
    ------
    ParameterError
        If a rate or ``prob`` is not a probability.
    """

    def __init__(self, translation_rate: float | None = None, other_rate: float | None = None, *,
                 prob: float = 1.0) -> None:
        super().__init__(prob=check_probability(prob, "removal prob"))
        self.translation_rate, self.other_rate = (
            check_real(rate, f"removal {name}", minimum=0.0, maximum=1.0, allow_none=True)
            for name, rate in (("translation_rate", translation_rate), ("other_rate", other_rate)))

    def _do(self, problem, X, *args, random_state=None, **kwargs):
        return as_column(remove_commands(random_state, sequences(X), translation_rate=self.translation_rate,
                                         other_rate=self.other_rate))
