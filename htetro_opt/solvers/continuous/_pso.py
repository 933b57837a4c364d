"""Nazarahari et al. 2019's PSO baseline (§5.2): pymoo's particle swarm over the path bases, started
from the APF's feasible paths.

A particle is one robot's PBs flattened, ``(x1, y1, …, xm, ym)``, inside F's box; its cost is the
polyline's length, and the number of infeasible segments is its constraint (pymoo's personal and
social bests prefer feasible particles, so the APF's feasible start is never lost). The APF's
paths have different PB counts: each is padded to the largest by splitting its longest segment at
the midpoint, which changes neither its shape nor its feasibility (§5.2: "a feasible initial
population obtained from the proposed APF was used to initiate the PSO").

Parameters as §5.2 gives them, read as the Yarpiz MATLAB PSO whose names the paper uses (inertia
weight 0.5 damped ×0.99 per iteration, personal and global learning coefficients 2; velocities
start at zero): pymoo's ``PSO`` with its adaptive parameters and its best-particle perturbation off
(neither is in that PSO). PS 10, IS 20 as for the EGA. No deletion (the paper applies it to PRM and
B-RRT only).

Two choices of ours, where the paper is silent, make the swarm search at all (measured on the 12
maps × 3 seeds: without them it shortened its best APF start by more than 0.1 % only on
ega04_corridor1 and ega08_slits2, by 0.31 % on average and 6.3 % at most; with them by
1.9–12.3 %, 6.7 % on average):

- **Feasible moves** (:func:`keep_feasible_moves`): a PB whose move would make one of its two
  segments infeasible stays where it was (with the segment's other end), its velocity zeroed, as
  against a wall. The APF's paths run along the walls, their PBs on obstacle edges, so a move of
  all 2m coordinates at once nearly always pushes some PB into an obstacle; with the
  infeasible-segment count as a constraint (the paper's "large penalty") such a particle never
  again improves on its personal best, and the global best, whose velocity starts at zero with its
  personal and social bests at its own position, never moves. Every particle now stays feasible.
- **Velocity cap d/2 per coordinate** (:data:`VELOCITY_STEP` × d) instead of Yarpiz's 0.1 × the
  box (3 on a 30 × 30 map, 5 on 50 × 50, across corridors 1–2 wide), where most moves were put
  back: with feasible moves and the box cap the swarm shortened its start by 0 % on ega02_maze1
  and 0–3 % on ega07_slits1 (3 seeds), with d/2 by 2.6–5.0 % and 9.9–12.6 %.
"""

from __future__ import annotations

import time

import numpy as np

from htetro_opt._validation import as_rng, check_int, derive_seed
from htetro_opt.model._lattice import check_grid
from htetro_opt.solvers.continuous._result import ContinuousPlan, check_scenario, finish_plan
from htetro_opt.solvers.continuous._spec import SPEC

_PSO = SPEC.defaults("pso")  # the task's defaults, declared once in its spec

__all__ = ["pad_path_bases", "keep_feasible_moves", "pso_path", "plan_pso", "INERTIA", "DAMPING", "LEARNING",
           "VELOCITY_STEP"]

INERTIA = 0.5
DAMPING = 0.99
LEARNING = 2.0
VELOCITY_STEP = 0.5
"""A particle's velocity is capped at VELOCITY_STEP × d per coordinate (ours; see the module docstring)."""


def pad_path_bases(pbs, start, goal, m: int) -> np.ndarray:
    """``pbs`` with PBs added until there are ``m``, each at the midpoint of the polyline's longest
    segment (the first of equal ones).

    Examples
    --------
    >>> pad_path_bases([[0, 4]], [0, 0], [2, 4], 3).tolist()
    [[0.0, 1.0], [0.0, 2.0], [0.0, 4.0]]
    """
    start, goal = np.asarray(start, dtype=float), np.asarray(goal, dtype=float)
    points = np.vstack([start, np.asarray(pbs, dtype=float).reshape(-1, 2), goal])
    while len(points) - 2 < m:
        k = int(np.argmax(np.hypot(*np.diff(points, axis=0).T)))
        points = np.insert(points, k + 1, (points[k] + points[k + 1]) / 2, axis=0)
    return points[1:-1]


def keep_feasible_moves(geometry, start, goal, old, new) -> tuple[np.ndarray, np.ndarray]:
    """The particles ``new`` with the moved PBs at either end of each infeasible segment put back
    where they were in ``old``, round after round, until no segment is infeasible (which segment
    end broke it is not told apart: both go back).

    Parameters
    ----------
    geometry : ContinuousGeometry
    start, goal : array_like, shape (2,)
    old, new : array_like, shape (n, 2m)
        The particles before and after a move, flattened PBs ``(x1, y1, …, xm, ym)``.

    Returns
    -------
    X : ndarray, shape (n, 2m)
        Each PB either at its new or at its old position; every path feasible whose old path was.
    kept : ndarray of bool, shape (n, m)
        The PBs put back.

    Examples
    --------
    >>> from htetro_opt.model import ContinuousGeometry
    >>> geo = ContinuousGeometry(10, 10, [[4, 0, 6, 8]])
    >>> old, new = [[4, 8.5, 6, 8.5, 8, 6]], [[4, 9, 6, 9, 5, 5]]  # the third PB moves into the wall
    >>> X, kept = keep_feasible_moves(geo, [1, 1], [9, 1], old, new)
    >>> X.tolist(), kept.tolist()
    ([[4.0, 9.0, 6.0, 8.5, 8.0, 6.0]], [[False, True, True]])
    """
    start, goal = np.asarray(start, dtype=float), np.asarray(goal, dtype=float)
    old = np.asarray(old, dtype=float)
    X = np.array(new, dtype=float)
    n, m = len(X), X.shape[1] // 2
    before, after = old.reshape(n, m, 2), X.reshape(n, m, 2)  # views: writing `after` writes X
    kept = np.zeros((n, m), dtype=bool)
    rows = np.arange(n)
    # each round puts back at least one moved PB of every path still infeasible, so at most m rounds
    while len(rows):
        points = np.concatenate([np.broadcast_to(start, (len(rows), 1, 2)), after[rows],
                                 np.broadcast_to(goal, (len(rows), 1, 2))], axis=1)
        bad = ~geometry.segments_feasible(points[:, :-1].reshape(-1, 2),
                                          points[:, 1:].reshape(-1, 2)).reshape(len(rows), m + 1)
        undo = (bad[:, :-1] | bad[:, 1:]) & (after[rows] != before[rows]).any(axis=2)
        busy = undo.any(axis=1)
        rows, undo = rows[busy], undo[busy]
        r, k = np.nonzero(undo)
        after[rows[r], k] = before[rows[r], k]
        kept[rows[r], k] = True
    return X, kept


def _problem(geometry, start, goal, m: int):
    from pymoo.core.problem import Problem

    class FlatPathBases(Problem):
        def __init__(self):
            x0, y0, x1, y1 = geometry.bounds
            super().__init__(n_var=2 * m, n_obj=1, n_ieq_constr=1, xl=np.tile([x0, y0], m), xu=np.tile([x1, y1], m))

        def _evaluate(self, X, out, *args, **kwargs):
            pop = len(X)
            points = np.concatenate([np.broadcast_to(start, (pop, 1, 2)), X.reshape(pop, m, 2),
                                     np.broadcast_to(goal, (pop, 1, 2))], axis=1)
            a, b = points[:, :-1].reshape(-1, 2), points[:, 1:].reshape(-1, 2)
            bad = (~geometry.segments_feasible(a, b)).reshape(pop, m + 1).sum(axis=1)
            out["F"] = np.hypot(*(b - a).T).reshape(pop, m + 1).sum(axis=1)[:, None]
            out["G"] = bad[:, None].astype(float)

    return FlatPathBases()


def pso_path(geometry, start, goal, *, pop_size: int = 10, max_gen: int = 20, grid: float = 1.0,
             seed=None) -> tuple[np.ndarray | None, dict]:
    """One robot's path by the PSO of the module docstring.

    Parameters
    ----------
    geometry : ContinuousGeometry
    start, goal : array_like, shape (2,)
    pop_size, max_gen : int, keyword-only
        Particles and iterations (PS 10, IS 20).
    grid : float, keyword-only
        The APF's lattice spacing d.
    seed : None, int or numpy Generator, keyword-only
        The APF's ties and pymoo's seed.

    Returns
    -------
    path : ndarray, shape (n, 2), or None
        Start first, goal last; None when the APF does not reach the goal.
    info : dict
        ``path_bases`` (m, the particles' PB count), ``history`` (the best length per iteration,
        the initial swarm first).

    Examples
    --------
    >>> from htetro_opt.model import ContinuousGeometry
    >>> geo = ContinuousGeometry(10, 10, [[4, 0, 6, 8]])
    >>> path, info = pso_path(geo, [1, 1], [9, 1], seed=0)
    >>> geo.path_feasible(path), info["history"][-1] <= info["history"][0]
    (True, True)
    """
    from pymoo.algorithms.soo.nonconvex.pso import PSO
    from pymoo.optimize import minimize

    from htetro_opt.model._apf import apf_population

    pop_size = check_int(pop_size, "pop_size", minimum=2)
    max_gen = check_int(max_gen, "max_gen", minimum=0)
    grid = check_grid(grid, geometry)
    rng = as_rng(seed)
    start, goal = np.asarray(start, dtype=float), np.asarray(goal, dtype=float)
    initial, _ = apf_population(geometry, start, goal, pop_size, grid=grid, seed=rng)
    if not initial:
        return None, {"path_bases": 0, "history": []}
    m = max(len(p) for p in initial)
    if m == 0:  # the start sees the goal (or is it)
        path = start[None].copy() if np.array_equal(start, goal) else np.array([start, goal])
        return path, {"path_bases": 0, "history": [float(np.hypot(*(goal - start)))]}

    class DampedPSO(PSO):
        def _infill(self):
            off = super()._infill()
            X, V = off.get("X", "V")
            X, kept = keep_feasible_moves(geometry, start, goal, self.particles.get("X"), X)
            V = V.copy()
            V.reshape(len(V), m, 2)[kept] = 0.0
            off.set("X", X, "V", V)
            return off

        def _advance(self, infills=None, **kwargs):
            super()._advance(infills=infills, **kwargs)
            self.w *= DAMPING

    X0 = np.array([pad_path_bases(p, start, goal, m).ravel() for p in initial])
    x0, y0, x1, y1 = geometry.bounds
    # pymoo caps each coordinate at max_velocity_rate × its range: the rate that makes the cap d/2
    rate = VELOCITY_STEP * grid / np.tile([x1 - x0, y1 - y0], m)
    algorithm = DampedPSO(pop_size=pop_size, sampling=X0, w=INERTIA, c1=LEARNING, c2=LEARNING, adaptive=False,
                          initial_velocity="zero", max_velocity_rate=rate, pertube_best=False)
    history = []
    res = minimize(_problem(geometry, start, goal, m), algorithm, ("n_gen", max_gen + 1), seed=derive_seed(rng),
                   callback=lambda alg: history.append(float(alg.opt[0].F[0])))
    best = res.opt[0].X.reshape(m, 2)
    return np.vstack([start, best, goal]), {"path_bases": m, "history": history}


def plan_pso(scenario, *, pop_size: int = _PSO["pop_size"], max_gen: int = _PSO["max_gen"], grid: float = _PSO["grid"],
             seed=_PSO["seed"]) -> ContinuousPlan:
    """Each robot's PSO path (:func:`pso_path`), alone; one ``seed`` drives every robot's run.

    ``history``: the first robot's best length per iteration; ``info``: ``pop_size``, ``max_gen``,
    ``grid``, ``path_bases`` per robot.
    """
    began = time.perf_counter()
    scenario = check_scenario(scenario)
    pop_size = check_int(pop_size, "pop_size", minimum=2)
    max_gen = check_int(max_gen, "max_gen", minimum=0)
    grid = check_grid(grid, scenario.geometry)
    rng = as_rng(seed)
    paths, infos = [], []
    for start, goal in zip(scenario.starts, scenario.goals):
        path, info = pso_path(scenario.geometry, start, goal, pop_size=pop_size, max_gen=max_gen, grid=grid, seed=rng)
        paths.append(path)
        infos.append(info)
    info = {"pop_size": pop_size, "max_gen": max_gen, "grid": grid, "path_bases": [i["path_bases"] for i in infos]}
    return finish_plan(scenario, paths, method="pso", began=began, history=infos[0]["history"], info=info)
