"""Nazarahari et al. 2019's two crossovers of path bases (§4.3.2, eqs. 1 and 2).

Parents with equally many PBs are combined PB by PB; otherwise each PB of the parent with fewer is
paired with the nearest PB of the other (the paper), and the child has as many PBs as that parent.
Eq. 1 takes each pair's mean; eq. 2 a random affine combination α p + (1 − α) q, one α ~ U[−1, 1]
per pair shared by x and y (so the child PB lies on the line through the pair). A mating gives one
child of each (:class:`PathBasesCrossover`); several robots are crossed robot by robot, and the
children are clipped to F's box.
"""

from __future__ import annotations

import numpy as np
from pymoo.core.crossover import Crossover

from htetro_opt._validation import check_probability

__all__ = ["pair_path_bases", "mean_crossover", "blend_crossover", "clip_to_box", "PathBasesCrossover"]


def clip_to_box(pbs: np.ndarray, box) -> np.ndarray:
    """PBs moved into the box [xmin, ymin, xmax, ymax] (each coordinate clipped)."""
    return np.clip(pbs, [box[0], box[1]], [box[2], box[3]])


def pair_path_bases(a, b) -> tuple[np.ndarray, np.ndarray]:
    """The PB pairs two parents are combined by: PB by PB for equal counts, else each PB of the
    parent with fewer beside the nearest PB of the other (that parent's PBs first).

    Examples
    --------
    >>> p, q = pair_path_bases(np.array([[0.0, 0.0], [5.0, 5.0], [9.0, 9.0]]), np.array([[8.0, 8.0]]))
    >>> p.tolist(), q.tolist()
    ([[8.0, 8.0]], [[9.0, 9.0]])
    """
    a, b = np.asarray(a, dtype=float).reshape(-1, 2), np.asarray(b, dtype=float).reshape(-1, 2)
    if len(a) == len(b):
        return a, b
    short, other = (a, b) if len(a) < len(b) else (b, a)
    if not len(short):
        return short, short.copy()
    gaps = np.hypot(short[:, None, 0] - other[None, :, 0], short[:, None, 1] - other[None, :, 1])
    return short, other[np.argmin(gaps, axis=1)]


def mean_crossover(a, b) -> np.ndarray:
    """Eq. 1: each pair's mean.

    Examples
    --------
    >>> mean_crossover(np.array([[0.0, 0.0], [2.0, 2.0]]), np.array([[2.0, 0.0], [2.0, 4.0]])).tolist()
    [[1.0, 0.0], [2.0, 3.0]]
    """
    p, q = pair_path_bases(a, b)
    return (p + q) / 2


def blend_crossover(a, b, *, random_state: np.random.Generator) -> np.ndarray:
    """Eq. 2: α p + (1 − α) q for each pair (p from the parent with fewer PBs, or from ``a``), one α
    ~ U[−1, 1] per pair for both coordinates.

    Examples
    --------
    >>> child = blend_crossover(np.array([[0.0, 0.0]]), np.array([[2.0, 2.0]]), random_state=np.random.default_rng(0))
    >>> bool(child[0, 0] == child[0, 1])  # on the line through the pair
    True
    """
    p, q = pair_path_bases(a, b)
    alpha = random_state.uniform(-1.0, 1.0, (len(p), 1))
    return alpha * p + (1 - alpha) * q


class PathBasesCrossover(Crossover):
    """Both crossovers as a pymoo operator: two parents, two offspring (eq. 1's, then eq. 2's),
    robot by robot, clipped to the problem's box (a :class:`~htetro_opt.problems.PathBasesProblem`).

    Parameters
    ----------
    prob : float
        pymoo's probability that a mating crosses over (else the parents are copied).
    """

    def __init__(self, prob: float = 1.0) -> None:
        super().__init__(n_parents=2, n_offsprings=2, prob=check_probability(prob, "crossover prob"))

    def _do(self, problem, X, *args, random_state=None, **kwargs):
        _, n_matings, _ = X.shape
        Y = np.empty((2, n_matings, 1), dtype=object)
        for k in range(n_matings):
            first, second = [], []
            for a, b in zip(problem.robots(X[0, k, 0]), problem.robots(X[1, k, 0])):
                first.append(clip_to_box(mean_crossover(a, b), problem.box))
                second.append(clip_to_box(blend_crossover(a, b, random_state=random_state), problem.box))
            Y[0, k, 0], Y[1, k, 0] = problem.join(first), problem.join(second)
        return Y
