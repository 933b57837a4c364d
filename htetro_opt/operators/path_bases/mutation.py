"""Nazarahari et al. 2019's three mutations of path bases (§4.3.3).

Each moves k = max(1, ⌊0.2 n + ½⌋) of a path's n PBs (the paper's mutation rate 0.2; a path without
PBs is left as it is), drawn without replacement:

- :func:`random_move`: each a random direction, a distance ~ U(0, step);
- :func:`smooth_move`: eq. 3, p_i + α (p_{i−1} − p_i) + β (p_{i+1} − p_i) with α, β ~ U(0, 0.25)
  ("small positive coefficients": the bound is ours), the chosen PBs taken in path order, each seeing
  its neighbours as already moved (the start and the goal stand beside the first and last PB);
- :func:`goal_move`: each towards the goal by a distance ~ U(0, step), never past it.

step = d, the APF's lattice spacing. Moved PBs are clipped to F's box.
"""

from __future__ import annotations

import numpy as np
from pymoo.core.mutation import Mutation

from htetro_opt._validation import check_probability
from htetro_opt.operators.path_bases.crossover import clip_to_box

__all__ = ["MUTATION_RATE", "SMOOTH_COEFFICIENT", "n_mutated", "random_move", "smooth_move", "goal_move",
           "PathBasesMutation"]

MUTATION_RATE = 0.2
"""Share of a path's PBs a mutation moves (§5.1)."""

SMOOTH_COEFFICIENT = 0.25
"""Upper bound of eq. 3's α and β."""


def n_mutated(n: int) -> int:
    """k = max(1, ⌊0.2 n + ½⌋) PBs of n (0 for a path without PBs).

    Examples
    --------
    >>> [n_mutated(n) for n in (0, 1, 7, 8, 20)]
    [0, 1, 1, 2, 4]
    """
    return 0 if n == 0 else max(1, int(np.floor(MUTATION_RATE * n + 0.5)))


def _chosen(n: int, rng: np.random.Generator) -> np.ndarray:
    return np.sort(rng.choice(n, size=n_mutated(n), replace=False)) if n else np.zeros(0, dtype=np.int64)


def random_move(pbs, *, step: float, random_state: np.random.Generator) -> np.ndarray:
    """k PBs each moved a distance ~ U(0, step) in a uniformly random direction.

    Examples
    --------
    >>> pbs = np.array([[1.0, 1.0], [5.0, 5.0]])
    >>> moved = random_move(pbs, step=1.0, random_state=np.random.default_rng(0))
    >>> int((moved != pbs).any(axis=1).sum()), bool(np.hypot(*(moved - pbs).T).max() <= 1.0)
    (1, True)
    """
    out = np.array(pbs, dtype=float).reshape(-1, 2)
    rows = _chosen(len(out), random_state)
    angle = random_state.uniform(0.0, 2 * np.pi, len(rows))
    radius = random_state.uniform(0.0, step, len(rows))
    out[rows] += radius[:, None] * np.column_stack([np.cos(angle), np.sin(angle)])
    return out


def smooth_move(pbs, start, goal, *, random_state: np.random.Generator) -> np.ndarray:
    """Eq. 3 on k PBs, in path order.

    Examples
    --------
    >>> moved = smooth_move(np.array([[5.0, 5.0]]), [0, 0], [10, 0], random_state=np.random.default_rng(0))
    >>> bool(moved[0, 1] < 5.0)  # pulled towards the line between its neighbours
    True
    """
    out = np.array(pbs, dtype=float).reshape(-1, 2)
    points = np.vstack([np.asarray(start, dtype=float), out, np.asarray(goal, dtype=float)])
    for i in _chosen(len(out), random_state) + 1:
        alpha, beta = random_state.uniform(0.0, SMOOTH_COEFFICIENT, 2)
        points[i] = points[i] + alpha * (points[i - 1] - points[i]) + beta * (points[i + 1] - points[i])
    return points[1:-1].copy()


def goal_move(pbs, goal, *, step: float, random_state: np.random.Generator) -> np.ndarray:
    """k PBs each moved towards the goal by a distance ~ U(0, step), stopping at the goal.

    Examples
    --------
    >>> goal_move(np.array([[9.5, 0.0]]), [10, 0], step=100.0, random_state=np.random.default_rng(3)).tolist()
    [[10.0, 0.0]]
    """
    out = np.array(pbs, dtype=float).reshape(-1, 2)
    rows = _chosen(len(out), random_state)
    towards = np.asarray(goal, dtype=float) - out[rows]
    gap = np.hypot(*towards.T)
    move = np.minimum(random_state.uniform(0.0, step, len(rows)), gap)
    out[rows] += towards * (move / np.where(gap > 0, gap, 1.0))[:, None]
    return out


class PathBasesMutation(Mutation):
    """The three mutations as a pymoo operator: each robot of each individual gets one of them,
    drawn uniformly, with the problem's step; results clipped to its box.

    Parameters
    ----------
    prob : float
        pymoo's probability that an individual is mutated.
    """

    def __init__(self, prob: float = 1.0) -> None:
        super().__init__(prob=check_probability(prob, "mutation prob"))

    def _do(self, problem, X, *args, random_state=None, **kwargs):
        Y = np.empty((len(X), 1), dtype=object)
        for i in range(len(X)):
            parts = []
            for k, pbs in enumerate(problem.robots(X[i, 0])):
                kind = int(random_state.integers(3))
                if kind == 0:
                    moved = random_move(pbs, step=problem.step, random_state=random_state)
                elif kind == 1:
                    moved = smooth_move(pbs, problem.starts[k], problem.goals[k], random_state=random_state)
                else:
                    moved = goal_move(pbs, problem.goals[k], step=problem.step, random_state=random_state)
                parts.append(clip_to_box(moved, problem.box))
            Y[i, 0] = problem.join(parts)
        return Y
