"""Duplicate elimination of identical command chromosomes, by a hash of their bytes."""

from __future__ import annotations

import numpy as np
from pymoo.core.duplicate import DuplicateElimination

__all__ = ["CommandDuplicateElimination", "chromosome_key", "first_occurrences", "first_keys"]


def chromosome_key(x) -> int:
    """Hash of a chromosome's commands (equal for equal commands whatever the integer dtype).

    Examples
    --------
    >>> chromosome_key(np.array([1, 2])) == chromosome_key(np.array([1, 2], dtype=np.int32))
    True
    """
    if type(x) is np.ndarray and x.dtype == np.int64:
        return hash(x.tobytes())
    x = np.asarray(x)
    if x.dtype == object:
        x = x.ravel()[0]
    return hash(np.asarray(x, dtype=np.int64).tobytes())


def first_occurrences(X: np.ndarray, seen: set | None = None) -> np.ndarray:
    """Rows of a design matrix (or items of a list of chromosomes) whose chromosome is neither in
    ``seen`` (a set of :func:`chromosome_key` values, updated in place) nor in an earlier row.

    Examples
    --------
    >>> from htetro_opt.operators import as_column
    >>> first_occurrences(as_column([[1, 2], [3], [1, 2]])).tolist()
    [0, 1]
    """
    rows = X if isinstance(X, list) else np.asarray(X, dtype=object).reshape(len(X), -1)[:, 0]
    return first_keys([chromosome_key(x) for x in rows], seen)


def first_keys(keys, seen: set | None = None) -> np.ndarray:
    """Positions of the :func:`chromosome_key` values ``keys`` that are neither in ``seen`` (updated in
    place) nor earlier in ``keys``: :func:`first_occurrences` of chromosomes whose keys are known.

    Examples
    --------
    >>> first_keys([5, 3, 5, 7], {7}).tolist()
    [0, 1]
    """
    seen = set() if seen is None else seen
    add = seen.add  # returns None: the comprehension keeps a new key and records it in one test
    return np.array([i for i, key in enumerate(keys) if not (key in seen or add(key))], dtype=np.int64)


class CommandDuplicateElimination(DuplicateElimination):
    """Identical chromosomes (same commands in the same order) are duplicates.

    Keys are computed once per individual per call (pymoo's ``HashDuplicateElimination`` hashes every
    individual twice through a Python-level function, several times slower on large populations).
    """

    def _do(self, pop, other, is_duplicate):
        seen = set()
        if other is not None:
            seen.update(chromosome_key(x) for x in other.get("X")[:, 0])
        for i, x in enumerate(pop.get("X")[:, 0]):
            key = chromosome_key(x)
            if key in seen:
                is_duplicate[i] = True
            else:
                seen.add(key)
        return is_duplicate
