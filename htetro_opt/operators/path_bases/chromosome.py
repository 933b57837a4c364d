"""Path-base chromosomes in pymoo's design matrix: float arrays, keyed exactly.

The command-chromosome helpers (:mod:`htetro_opt.operators.commands`) cast genes to int64; path
bases are floats, and two paths whose PBs differ in the last bit are different paths. These are the
float-aware equivalents: :func:`as_column` stores chromosomes (an (n, 2) float array, or a tuple of
K of them) one per row without casting, and :func:`path_key` hashes their exact bytes and shapes.
"""

from __future__ import annotations

from typing import Iterable

import numpy as np
from pymoo.core.duplicate import DuplicateElimination

__all__ = ["as_column", "chromosomes", "path_key", "PathBasesDuplicateElimination"]


def as_column(xs: Iterable) -> np.ndarray:
    """Chromosomes as pymoo's design matrix: shape (n, 1), object dtype, each row's chromosome as it
    is (an (n_i, 2) float array, or a tuple of them for several robots).

    Examples
    --------
    >>> X = as_column([np.zeros((1, 2)), (np.zeros((0, 2)), np.ones((2, 2)))])
    >>> X.shape, type(X[1, 0]).__name__
    ((2, 1), 'tuple')
    """
    xs = list(xs)
    X = np.empty((len(xs), 1), dtype=object)
    for i, x in enumerate(xs):
        X[i, 0] = tuple(x) if isinstance(x, list) else x
    return X


def chromosomes(X) -> list:
    """The chromosomes of a design matrix (or of a 1-D object array, or a list)."""
    if isinstance(X, list):
        return X
    X = np.asarray(X, dtype=object)
    return list(X[:, 0] if X.ndim == 2 else X)


def path_key(x) -> int:
    """Hash of a chromosome's exact coordinates, robot by robot (floats are not rounded: distinct
    paths are never merged as duplicates).

    Examples
    --------
    >>> path_key(np.array([[1.0, 2.0]])) == path_key(np.array([[1.0, 2.0]]))
    True
    >>> path_key(np.array([[1.0, 2.0]])) == path_key(np.array([[1.0, 2.0 + 1e-15]]))
    False
    >>> path_key((np.empty((0, 2)), np.ones((1, 2)))) == path_key((np.ones((1, 2)), np.empty((0, 2))))
    False
    """
    if isinstance(x, np.ndarray) and x.dtype == object:
        x = x.ravel()[0]
    parts = x if isinstance(x, (tuple, list)) else (x,)
    arrays = [np.ascontiguousarray(p, dtype=np.float64).reshape(-1, 2) for p in parts]
    return hash((tuple(len(a) for a in arrays), b"".join(a.tobytes() for a in arrays)))


class PathBasesDuplicateElimination(DuplicateElimination):
    """Chromosomes with exactly the same PBs (robot by robot) are duplicates; nothing else is."""

    def _do(self, pop, other, is_duplicate):
        seen = set()
        if other is not None:
            seen.update(path_key(x) for x in other.get("X")[:, 0])
        for i, x in enumerate(pop.get("X")[:, 0]):
            key = path_key(x)
            if key in seen:
                is_duplicate[i] = True
            else:
                seen.add(key)
        return is_duplicate
