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
start at zero and are capped at 0.1 × the box per coordinate): pymoo's ``PSO`` with its adaptive
parameters and its best-particle perturbation off (neither is in that PSO). PS 10, IS 20 as for the
EGA. No deletion (the paper applies it to PRM and B-RRT only).
"""

from __future__ import annotations

import time

import numpy as np

from htetro_opt._validation import as_rng, check_int, derive_seed
from htetro_opt.solvers.continuous._astar import check_grid
from htetro_opt.solvers.continuous._result import ContinuousPlan, check_scenario, finish_plan

__all__ = ["pad_path_bases", "pso_path", "plan_pso", "INERTIA", "DAMPING", "LEARNING"]

INERTIA = 0.5
DAMPING = 0.99
LEARNING = 2.0
VELOCITY_SHARE = 0.1


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

    from htetro_opt.solvers.continuous._apf import apf_population

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
        def _advance(self, infills=None, **kwargs):
            super()._advance(infills=infills, **kwargs)
            self.w *= DAMPING

    X0 = np.array([pad_path_bases(p, start, goal, m).ravel() for p in initial])
    algorithm = DampedPSO(pop_size=pop_size, sampling=X0, w=INERTIA, c1=LEARNING, c2=LEARNING, adaptive=False,
                          initial_velocity="zero", max_velocity_rate=VELOCITY_SHARE, pertube_best=False)
    history = []
    res = minimize(_problem(geometry, start, goal, m), algorithm, ("n_gen", max_gen + 1), seed=derive_seed(rng),
                   callback=lambda alg: history.append(float(alg.opt[0].F[0])))
    best = res.opt[0].X.reshape(m, 2)
    return np.vstack([start, best, goal]), {"path_bases": m, "history": history}


def plan_pso(scenario, *, pop_size: int = 10, max_gen: int = 20, grid: float = 1.0, seed=None) -> ContinuousPlan:
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
