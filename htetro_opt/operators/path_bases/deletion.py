"""Nazarahari et al. 2019's deletion operator (§4.2.4): redundant path bases dropped.

The PBs are assessed left to right: one is dropped when that is beneficial, i.e. the path stays
feasible and its cost does not rise, or, for an infeasible path, its infeasible segments become
fewer. Ours, where the paper is silent: passes repeat until one drops nothing (so the operator is
idempotent), and a feasible straight start → goal segment whose cost does not rise replaces the
path first (left-to-right deletion alone can stall on two PBs that each hide the other's
neighbour).

By default the path is the polyline through its PBs and its cost is its length, which a deletion
never raises (the triangle inequality): only feasibility decides, and each step checks one segment.
With another cost (weights, a spline, several robots) a ``judge`` scores each candidate whole.
"""

from __future__ import annotations

from typing import Callable

import numpy as np
from pymoo.core.repair import Repair

from htetro_opt.model.continuous import ContinuousGeometry

__all__ = ["delete_path_bases", "delete_chromosome", "PathBasesDeletion", "TOLERANCE"]

TOLERANCE = 1e-9
"""Relative slack of "the cost does not rise" (a dropped collinear PB changes a length by rounding)."""


def _not_worse(new, old) -> bool:
    new, old = np.atleast_1d(new), np.atleast_1d(old)
    return bool(np.all(new <= old + TOLERANCE * np.maximum(1.0, np.abs(old))))


def delete_path_bases(pbs, start, goal, geometry: ContinuousGeometry | None = None, *,
                      judge: Callable | None = None) -> np.ndarray:
    """The PBs left after deletion (see the module docstring).

    Parameters
    ----------
    pbs : array_like, shape (n, 2)
    start, goal : array_like, shape (2,)
    geometry : ContinuousGeometry, optional
        Checks the segments of the polyline start → PBs → goal (the default criterion).
    judge : callable, keyword-only, optional
        ``judge(pbs) -> (bad, cost)``: the number of infeasible segments (or any violation count) and
        the cost (a number, or an array: then no entry may rise) of a candidate. Replaces the default.

    Returns
    -------
    ndarray, shape (m, 2), m ≤ n

    Examples
    --------
    >>> geo = ContinuousGeometry(10, 10, [[4, 0, 6, 8]])
    >>> pbs = np.array([[2.0, 8.0], [4.0, 8.0], [5.0, 9.0], [6.0, 8.0], [8.0, 5.0]])
    >>> delete_path_bases(pbs, [1, 1], [9, 1], geo).tolist()
    [[4.0, 8.0], [6.0, 8.0]]
    """
    start, goal = np.asarray(start, dtype=float), np.asarray(goal, dtype=float)
    pbs = np.array(pbs, dtype=float).reshape(-1, 2)
    if not len(pbs):
        return pbs
    if judge is None:
        if geometry is None:
            raise TypeError("delete_path_bases needs a geometry or a judge")
        return _delete_polyline(pbs, start, goal, geometry)
    bad, cost = judge(pbs)
    if bad == 0:
        empty = np.empty((0, 2))
        b, c = judge(empty)
        if b == 0 and _not_worse(c, cost):
            return empty
    changed = True
    while changed and len(pbs):
        changed, i = False, 0
        while i < len(pbs):
            candidate = np.delete(pbs, i, axis=0)
            b, c = judge(candidate)
            if (b == 0 and _not_worse(c, cost)) if bad == 0 else b < bad:
                if bad > 0 and b == 0:  # feasible now: start again under the feasible rule
                    return delete_path_bases(candidate, start, goal, judge=judge)
                pbs, bad, cost, changed = candidate, b, c, True
            else:
                i += 1
    return pbs


def _delete_polyline(pbs: np.ndarray, start: np.ndarray, goal: np.ndarray, geometry: ContinuousGeometry) -> np.ndarray:
    points = np.vstack([start, pbs, goal])
    ok = geometry.path_segments_feasible(points)
    if ok.all() and geometry.segments_feasible(start[None], goal[None])[0]:
        return np.empty((0, 2))
    while len(points) > 2:
        # every candidate's joining segment at once: a pass that would drop nothing is not run
        joined = geometry.segments_feasible(points[:-2], points[2:])
        bad = int((~ok).sum())
        after = bad - (~ok[:-1]).astype(int) - (~ok[1:]).astype(int) + (~joined).astype(int)
        if not (joined if bad == 0 else after < bad).any():
            break
        if bad == 0:
            points = _feasible_pass(points, joined, geometry)
            ok = np.ones(len(points) - 1, dtype=bool)
            continue
        i = 1
        while i < len(points) - 1:
            link = bool(joined[i - 1]) if joined is not None else bool(
                geometry.segments_feasible(points[i - 1:i], points[i + 1:i + 2])[0])
            bad = int((~ok).sum())
            after = bad - int(not ok[i - 1]) - int(not ok[i]) + int(not link)
            if after < bad:
                points = np.delete(points, i, axis=0)
                ok = np.concatenate([ok[:i - 1], [link], ok[i + 1:]])
                joined = None  # the next candidate's left neighbour moved
                if ok.all():  # feasible now: start again under the feasible rule
                    return _delete_polyline(points[1:-1], start, goal, geometry)
            else:
                i += 1
                if joined is None:
                    joined = np.concatenate([np.zeros(i - 1, dtype=bool),
                                             geometry.segments_feasible(points[i - 1:-2], points[i + 1:])])
    return points[1:-1].copy()


def _feasible_pass(points: np.ndarray, joined: np.ndarray, geometry: ContinuousGeometry) -> np.ndarray:
    """One left-to-right pass over a feasible polyline: from the last kept point a, candidate k goes
    iff a → k + 1 is feasible. ``joined[k − 1]`` already says so when a = k − 1; after a deletion the
    segments from a to the next points are tested a few at a time (doubling) and read in order."""
    kept, a, k, ahead = [0], 0, 1, {}
    while k < len(points) - 1:
        if a == k - 1:
            link = bool(joined[k - 1])
        else:
            if k + 1 not in ahead:
                width = max(4, 2 * len(ahead))
                ends = points[k + 1:k + 1 + width]
                tested = geometry.segments_feasible(np.repeat(points[a:a + 1], len(ends), axis=0), ends)
                ahead.update(zip(range(k + 1, k + 1 + len(ends)), tested.tolist()))
            link = ahead[k + 1]
        if not link:
            kept.append(k)
            a, ahead = k, {}
        k += 1
    kept.append(len(points) - 1)
    return points[kept]


class PathBasesDeletion(Repair):
    """Deletion as a pymoo ``Repair`` over a :class:`~htetro_opt.problems.PathBasesProblem`: every
    robot of every individual, in turn.

    A single robot on a polyline whose cost is its length (weights (W_L, 0, 0), or the
    ``"separate"`` objectives' first) takes the segment-by-segment default; otherwise each candidate
    is judged by the problem: G (infeasible segments and robot conflicts) and the cost (eq. 6 with
    the robots' penalty; in ``"separate"`` mode all three objectives, none of which may rise).
    """

    def _do(self, problem, X, **kwargs):
        Y = np.empty((len(X), 1), dtype=object)
        for i in range(len(X)):
            Y[i, 0] = delete_chromosome(problem, X[i, 0])
        return Y


def delete_chromosome(problem, x):
    """One chromosome of ``problem`` after deletion, robot by robot (see :class:`PathBasesDeletion`)."""
    parts = problem.robots(x)
    plain = problem.n_robots == 1 and problem.path == "linear" and (
        problem.objectives == "weighted" and problem.weights[1:] == (0.0, 0.0))
    for k in range(len(parts)):
        if plain:
            parts[k] = delete_path_bases(parts[k], problem.starts[k], problem.goals[k], problem.geometry)
            continue

        def judge(candidate, k=k):
            trial = list(parts)
            trial[k] = candidate
            G, F = problem.score([problem.join(trial)])
            return G[0], (F[0] if problem.objectives == "separate" else F[0, 0])

        parts[k] = delete_path_bases(parts[k], problem.starts[k], problem.goals[k], judge=judge)
    return problem.join(parts)
