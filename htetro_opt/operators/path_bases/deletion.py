"""Nazarahari et al. 2019's deletion operator (§4.3.4): redundant path bases dropped.

The paper: "the deletion operator assesses each PB sequentially. If the deletion of any chosen PB is
beneficial (turns an infeasible path to a feasible one, reduces the path length, increases the path
smoothness), the deletion operator deletes it." Our reading: the PBs are assessed once each, left to
right, each against the path as the earlier deletions left it; a deletion is beneficial when the
path stays feasible and its cost does not rise, or, for an infeasible path, when its infeasible
segments become fewer (the cost's "large penalty" falls; once none is left the feasible rule
applies to the PBs still to come). That is ``passes=False, straight=False``.

Two additions of ours, on by default (:data:`~htetro_opt.solvers.continuous._spec.EGA_ADDITIONS`):
``passes`` (``deletion-passes``) repeats the pass until one drops nothing, so the operator is
idempotent; ``straight`` (``straight-first``) first replaces a feasible path by the straight
start → goal segment when that is no costlier (left-to-right deletion alone can stall on two PBs
that each hide the other's neighbour).

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
                      judge: Callable | None = None, passes: bool = True, straight: bool = True) -> np.ndarray:
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
    passes : bool, keyword-only
        Ours: repeat the left-to-right pass until one drops nothing; False: one pass (the paper).
    straight : bool, keyword-only
        Ours: first try the straight start → goal segment; False: PBs are only deleted one at a time.

    Returns
    -------
    ndarray, shape (m, 2), m ≤ n

    Examples
    --------
    >>> geo = ContinuousGeometry(10, 10, [[4, 0, 6, 8]])
    >>> pbs = np.array([[2.0, 8.0], [4.0, 8.0], [5.0, 9.0], [6.0, 8.0], [8.0, 5.0]])
    >>> delete_path_bases(pbs, [1, 1], [9, 1], geo).tolist()
    [[4.0, 8.0], [6.0, 8.0]]
    >>> zigzag = np.array([[2.0, 7.0], [7.0, 10.0], [2.0, 10.0], [8.0, 9.0]])
    >>> delete_path_bases(zigzag, [1, 1], [9, 1], geo, passes=False, straight=False).tolist()  # the paper's pass
    [[2.0, 7.0], [2.0, 10.0], [8.0, 9.0]]
    >>> delete_path_bases(zigzag, [1, 1], [9, 1], geo).tolist()  # passes until none drops a PB
    [[2.0, 10.0], [8.0, 9.0]]
    """
    start, goal = np.asarray(start, dtype=float), np.asarray(goal, dtype=float)
    pbs = np.array(pbs, dtype=float).reshape(-1, 2)
    if not len(pbs):
        return pbs
    if judge is None:
        if geometry is None:
            raise TypeError("delete_path_bases needs a geometry or a judge")
        if not passes:
            return _one_pass(pbs, start, goal, geometry, straight=straight)
        return _delete_polyline(pbs, start, goal, geometry, straight=straight)
    bad, cost = judge(pbs)
    if bad == 0 and straight:
        empty = np.empty((0, 2))
        b, c = judge(empty)
        if b == 0 and _not_worse(c, cost):
            return empty
    changed = True
    while changed and len(pbs):
        changed, i = False, 0
        while i < len(pbs):  # a PB dropped: the next one moves into place i, so each is assessed once
            candidate = np.delete(pbs, i, axis=0)
            b, c = judge(candidate)
            if (b == 0 and _not_worse(c, cost)) if bad == 0 else b < bad:
                if bad > 0 and b == 0 and passes:  # feasible now: start again under the feasible rule
                    return delete_path_bases(candidate, start, goal, judge=judge, straight=straight)
                pbs, bad, cost, changed = candidate, b, c, True
            else:
                i += 1
        if not passes:
            break
    return pbs


def _one_pass(pbs: np.ndarray, start: np.ndarray, goal: np.ndarray, geometry: ContinuousGeometry, *,
              straight: bool) -> np.ndarray:
    """The paper's deletion on the polyline start → PBs → goal under its length: each PB assessed once, left to
    right, against the last PB kept (one segment test per PB)."""
    points = np.vstack([start, pbs, goal])
    ok = geometry.path_segments_feasible(points)
    if straight and ok.all() and geometry.segments_feasible(start[None], goal[None])[0]:
        return np.empty((0, 2))
    bad = int((~ok).sum())
    kept, left_ok = [0], bool(ok[0])  # left_ok: the segment from the last kept point to point k
    for k in range(1, len(points) - 1):
        link = bool(geometry.segments_feasible(points[kept[-1]][None], points[k + 1][None])[0])
        after = bad - int(not left_ok) - int(not ok[k]) + int(not link)
        if link if bad == 0 else after < bad:  # feasible: the length never rises (triangle inequality)
            bad, left_ok = after, link
        else:
            kept.append(k)
            left_ok = bool(ok[k])
    return points[kept[1:]].copy()


def _delete_polyline(pbs: np.ndarray, start: np.ndarray, goal: np.ndarray, geometry: ContinuousGeometry, *,
                     straight: bool = True) -> np.ndarray:
    points = np.vstack([start, pbs, goal])
    ok = geometry.path_segments_feasible(points)
    if straight and ok.all() and geometry.segments_feasible(start[None], goal[None])[0]:
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
                    return _delete_polyline(points[1:-1], start, goal, geometry, straight=straight)
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

    Parameters
    ----------
    passes, straight : bool
        Our two additions (see :func:`delete_path_bases`); both False: the paper's single pass.
    """

    def __init__(self, *, passes: bool = True, straight: bool = True) -> None:
        super().__init__()
        self.passes, self.straight = bool(passes), bool(straight)

    def _do(self, problem, X, **kwargs):
        Y = np.empty((len(X), 1), dtype=object)
        for i in range(len(X)):
            Y[i, 0] = delete_chromosome(problem, X[i, 0], passes=self.passes, straight=self.straight)
        return Y


def delete_chromosome(problem, x, *, passes: bool = True, straight: bool = True):
    """One chromosome of ``problem`` after deletion, robot by robot (see :class:`PathBasesDeletion`)."""
    parts = problem.robots(x)
    plain = problem.n_robots == 1 and problem.path == "linear" and (
        problem.objectives == "weighted" and problem.weights[1:] == (0.0, 0.0))
    for k in range(len(parts)):
        if plain:
            parts[k] = delete_path_bases(parts[k], problem.starts[k], problem.goals[k], problem.geometry,
                                         passes=passes, straight=straight)
            continue

        def judge(candidate, k=k):
            trial = list(parts)
            trial[k] = candidate
            G, F = problem.score([problem.join(trial)])
            return G[0], (F[0] if problem.objectives == "separate" else F[0, 0])

        parts[k] = delete_path_bases(parts[k], problem.starts[k], problem.goals[k], judge=judge, passes=passes,
                                     straight=straight)
    return problem.join(parts)
