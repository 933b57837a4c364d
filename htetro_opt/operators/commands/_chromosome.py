"""Helpers shared by the command-chromosome operators: the object column pymoo stores them in, and
the flat layout the batch operators work on."""

from __future__ import annotations

from typing import Iterable

import numpy as np

from htetro_opt.model.commands import COMMANDS

__all__ = ["SHIFTS", "MOVES", "as_row", "as_column", "sequences", "displacement", "Flat"]

SHIFTS = np.array([c.shift for c in COMMANDS], dtype=np.int64)
"""(dx, dy) of B2 for every global command id."""

MOVES = (SHIFTS != 0).any(axis=1)
"""Commands that move B2 (translations and diagonals); every other command leaves it in place."""


def _as_genes(s) -> np.ndarray:
    return s if type(s) is np.ndarray and s.dtype == np.int64 and s.ndim == 1 else np.asarray(s, dtype=np.int64).ravel()


def as_row(s) -> np.ndarray:
    """One chromosome as a row of :func:`as_column`: shape (1,), object dtype, holding an int64 array.

    The hTetro-GA stores rows in pymoo ``Individual`` objects one at a time, several times a
    generation: this spares it building a one-row design matrix for each.

    Examples
    --------
    >>> row = as_row([3, 1])
    >>> row.shape, row[0].tolist(), bool((row[0] == as_column([[3, 1]])[0][0]).all())
    ((1,), [3, 1], True)
    """
    row = np.empty(1, dtype=object)
    row[0] = _as_genes(s)
    return row


def as_column(seqs: Iterable[np.ndarray]) -> np.ndarray:
    """Chromosomes as pymoo's design matrix: shape (n, 1), object dtype, one int64 array per row."""
    seqs = list(seqs)
    X = np.empty((len(seqs), 1), dtype=object)
    for i, s in enumerate(seqs):
        X[i, 0] = s if type(s) is np.ndarray and s.dtype == np.int64 and s.ndim == 1 else _as_genes(s)  # the GAs' case inline
    return X


def sequences(X: np.ndarray) -> list[np.ndarray]:
    """The chromosomes of a design matrix (or of a 1-D object array)."""
    X = np.asarray(X, dtype=object)
    return [x if type(x) is np.ndarray and x.dtype == np.int64 else np.asarray(x, dtype=np.int64)
            for x in (X[:, 0] if X.ndim == 2 else X)]


def displacement(seq: np.ndarray) -> tuple[int, int]:
    """The (dx, dy) of B2 after the whole sequence (rotations and shapeshifts turn about B2)."""
    dx, dy = SHIFTS[np.asarray(seq, dtype=np.int64)].sum(axis=0) if len(seq) else (0, 0)
    return int(dx), int(dy)


class Flat:
    """A batch of chromosomes laid end to end: ``genes`` (a copy), each gene's ``owner`` and each
    chromosome's ``start`` and ``length``, so operators can draw for the whole batch at once."""

    def __init__(self, seqs: list[np.ndarray]) -> None:
        self.length = np.fromiter((len(s) for s in seqs), dtype=np.int64, count=len(seqs))
        self.start = np.cumsum(self.length) - self.length
        self.genes = np.concatenate(seqs).astype(np.int64) if len(seqs) else np.empty(0, np.int64)
        self.owner = np.repeat(np.arange(len(seqs)), self.length)

    def rate(self, rate: float | None) -> np.ndarray:
        """Per-gene rate: ``rate``, or 1 / l_p of the gene's chromosome when None."""
        if rate is not None:
            return np.full(len(self.genes), float(rate))
        return 1.0 / self.length[self.owner]

    def other(self, rng: np.random.Generator, local: np.ndarray, size: np.ndarray) -> np.ndarray:
        """For items at positions ``local`` of groups of ``size`` (≥ 2), a uniformly drawn other position."""
        others = np.floor(rng.random(len(local)) * (size - 1)).astype(np.int64)
        return others + (others >= local)

    def split(self, genes: np.ndarray, keep: np.ndarray | None = None) -> list[np.ndarray]:
        """The chromosomes again, keeping only the genes where ``keep``."""
        if keep is None:
            lengths = self.length
        else:
            genes, lengths = genes[keep], np.bincount(self.owner[keep], minlength=len(self.length))
        ends = np.cumsum(lengths)
        return [genes[a:b] for a, b in zip((ends - lengths).tolist(), ends.tolist())]  # np.split's views, faster
