"""Nazarahari et al. 2019's collision removal (§4.5) for joint chromosomes of several robots.

Robots leave together at unit speed and wait at their goals; two conflict when their closest
approach (:func:`~htetro_opt.model.closest_approach`) is below the problem's safety distance d_s.
For a conflicted chromosome, up to ``tries`` times: a random conflicting pair, a random robot of
it, a random PB of that robot before the time of their closest approach, moved to a uniform point of
the disc of radius d (the step) around it, clipped to F's box. The chromosome is replaced once a
move leaves it free of conflicts and every path obstacle-free.

Ours, where the paper is silent: a move that keeps the robot's path obstacle-free and does not raise
the chromosome's total §4.5 penalty is kept for the next try (the paper "repeats the process"
without saying from where), and when the tries run out the chromosome with the lowest penalty so far
is returned if that is lower than the original's (the GA's penalty then ranks it); a robot without a PB
before the closest approach gets a new one at a
uniformly drawn point of its path before it (the straight paths of ``ega_cross4`` have none); a
spline path's PBs are placed in time by the polyline through them.
"""

from __future__ import annotations

import numpy as np
from pymoo.core.repair import Repair

from htetro_opt._validation import check_int
from htetro_opt.model.continuous import closest_approach
from htetro_opt.operators.path_bases.crossover import clip_to_box

__all__ = ["conflicts", "remove_collisions", "CollisionRemoval", "TRIES"]

TRIES = 20
"""Moves tried per conflicted chromosome."""


def conflicts(lines, safety_distance: float) -> list[tuple[int, int, float, float]]:
    """The conflicting pairs of robots following ``lines``: (p, q, closest distance, its time).

    Examples
    --------
    >>> conflicts([np.array([[0.0, 0.0], [4.0, 0.0]]), np.array([[4.0, 0.5], [0.0, 0.5]])], 1.0)
    [(0, 1, 0.5, 2.0)]
    """
    out = []
    for p in range(len(lines)):
        for q in range(p + 1, len(lines)):
            d, t = closest_approach(lines[p], lines[q])
            if d < safety_distance:
                out.append((p, q, d, t))
    return out


def _penalty(pairs, safety_distance: float) -> float:
    return sum((safety_distance - d) / safety_distance for _, _, d, _ in pairs)


def _move_before(pbs: np.ndarray, start: np.ndarray, goal: np.ndarray, t: float, step: float,
                 rng: np.random.Generator) -> np.ndarray:
    points = np.vstack([start, pbs, goal])
    s = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(points, axis=0).T))])
    before = np.flatnonzero(s[1:-1] < t)
    out = pbs.copy()
    if len(before):
        j = int(before[rng.integers(len(before))])
    else:  # a new PB on the path before the closest approach
        u = rng.uniform(0.0, min(t, s[-1]))
        seg = int(min(np.searchsorted(s, u, side="right") - 1, len(points) - 2))
        frac = (u - s[seg]) / (s[seg + 1] - s[seg]) if s[seg + 1] > s[seg] else 0.0
        out = np.insert(out, seg, points[seg] + frac * (points[seg + 1] - points[seg]), axis=0)
        j = seg
    angle = rng.uniform(0.0, 2 * np.pi)
    radius = step * np.sqrt(rng.random())
    out[j] += radius * np.array([np.cos(angle), np.sin(angle)])
    return out


def remove_collisions(x, problem, *, tries: int = TRIES, random_state: np.random.Generator):
    """``x`` (a joint chromosome of ``problem``, a :class:`~htetro_opt.problems.PathBasesProblem`)
    with its robot conflicts removed, or lessened when ``tries`` moves do not remove them all (``x``
    itself when no move lessened them).

    Examples
    --------
    >>> from htetro_opt.problems import PathBasesProblem
    >>> from htetro_opt.scenarios import parse_scenario
    >>> sc = parse_scenario({"name": "t", "width": 10, "height": 10, "robot_radius": 0.2, "obstacles": [],
    ...                      "robots": [{"start": [1, 5], "goal": [9, 5]}, {"start": [5, 1], "goal": [5, 9]}]})
    >>> problem = PathBasesProblem(sc)
    >>> x = (np.empty((0, 2)), np.empty((0, 2)))       # both reach (5, 5) at time 4
    >>> y = remove_collisions(x, problem, tries=50, random_state=np.random.default_rng(0))
    >>> conflicts(problem.polylines(x), 0.9) != [], conflicts(problem.polylines(y), 0.9)
    (True, [])
    """
    tries = check_int(tries, "tries", minimum=0)
    d_s = problem.safety_distance
    parts = problem.robots(x)
    lines = [problem.polyline(p, k) for k, p in enumerate(parts)]
    pairs = conflicts(lines, d_s)
    if not pairs:
        return x
    penalty = start = _penalty(pairs, d_s)
    for _ in range(tries):
        p, q, _, t = pairs[int(random_state.integers(len(pairs)))]
        k = (p, q)[int(random_state.integers(2))]
        moved = clip_to_box(_move_before(parts[k], problem.starts[k], problem.goals[k], t, problem.step,
                                         random_state), problem.box)
        line = problem.polyline(moved, k)
        if not problem.geometry.path_feasible(line):
            continue
        trial_lines = lines[:k] + [line] + lines[k + 1:]
        trial_pairs = conflicts(trial_lines, d_s)
        trial_penalty = _penalty(trial_pairs, d_s)
        if trial_penalty <= penalty:
            parts, lines, pairs, penalty = parts[:k] + [moved] + parts[k + 1:], trial_lines, trial_pairs, trial_penalty
            if not pairs:
                break
    return problem.join(parts) if penalty < start else x


class CollisionRemoval(Repair):
    """Collision removal as a pymoo ``Repair``: every conflicted individual, ``tries`` moves each.

    The generator is pymoo's ``random_state`` (passed by the algorithm); without one the operator
    draws fresh entropy.
    """

    def __init__(self, tries: int = TRIES) -> None:
        super().__init__()
        self.tries = check_int(tries, "tries", minimum=0)

    def _do(self, problem, X, random_state=None, **kwargs):
        rng = random_state if random_state is not None else np.random.default_rng()
        Y = np.empty((len(X), 1), dtype=object)
        for i in range(len(X)):
            Y[i, 0] = X[i, 0] if problem.n_robots < 2 else remove_collisions(X[i, 0], problem, tries=self.tries,
                                                                             random_state=rng)
        return Y
