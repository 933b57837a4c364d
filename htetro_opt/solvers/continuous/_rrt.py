"""Nazarahari et al. 2019's B-RRT baseline (§5.2): OMPL's ``RRTConnect`` on our geometry.

Two trees grow from the start and the goal with step 2 (``setRange(2.0)``, the paper's) until they
meet or the time limit passes (the paper stopped at 120 s); states and motions are checked by this
package's :class:`~htetro_opt.model.ContinuousGeometry` (an ``ob.MotionValidator`` subclass: a
motion is valid when the whole segment is, no interpolation), and the paper's deletion operator
(§4.3.4) drops the redundant vertices. OMPL's generator is seeded before each planner
(``ou.RNG.setSeed``), and the planner runs on one thread: the same seed gives the same paths.

OMPL is an optional dependency: ``pip install 'htetro-opt[ompl]'`` (the ``ompl`` wheel, BSD-3).
"""

from __future__ import annotations

import time

import numpy as np

from htetro_opt._spec import DEFAULT_SEED
from htetro_opt._validation import as_rng, check_time_limit, derive_seed
from htetro_opt.errors import ParameterError
from htetro_opt.solvers.continuous._result import ContinuousPlan, check_scenario, finish_plan
from htetro_opt.solvers.continuous._spec import RRT_TIME_LIMIT

__all__ = ["rrt_path", "plan_rrt", "STEP"]

STEP = 2.0
"""The trees' step (the paper's "step size of the B-RRT … set to 2 in all environments")."""

INSTALL = "pip install 'htetro-opt[ompl]' (or: pip install ompl)"


def _ompl():
    try:
        from ompl import base as ob
        from ompl import geometric as og
        from ompl import util as ou
    except ImportError as err:
        raise ParameterError(f"method 'rrt' needs OMPL, which is not installed: {INSTALL}") from err
    return ob, og, ou


def rrt_path(geometry, start, goal, *, time_limit: float | None = None, seed=None,
             delete: bool = True) -> tuple[np.ndarray | None, dict]:
    """One robot's path by OMPL's RRTConnect (see the module docstring).

    Parameters
    ----------
    geometry : ContinuousGeometry
    start, goal : array_like, shape (2,)
        Feasible points.
    time_limit : float, keyword-only
        Seconds before giving up (default: the paper's terminal condition, 120 s, the task spec's
        ``RRT_TIME_LIMIT``).
    seed : None, int or numpy Generator, keyword-only
        Seeds OMPL's generator (None: fresh entropy).
    delete : bool, keyword-only
        Apply the deletion operator to the path found (the paper: yes).

    Returns
    -------
    path : ndarray, shape (n, 2), or None
        Start first, goal last; None when the trees did not meet in time.
    info : dict
        ``states`` (the path's before deletion), ``tree_length`` (its length), ``time_limit``.

    Raises
    ------
    ParameterError
        Without OMPL, or on a bad ``time_limit`` or ``seed``.

    Examples
    --------
    >>> from htetro_opt.model import ContinuousGeometry
    >>> geo = ContinuousGeometry(10, 10, [[4, 0, 6, 8]])
    >>> path, info = rrt_path(geo, [1, 1], [9, 1], seed=0)
    >>> geo.path_feasible(path), info["states"] >= len(path) >= 3
    (True, True)
    """
    time_limit = check_time_limit(time_limit, "time_limit")
    time_limit = RRT_TIME_LIMIT if time_limit is None else time_limit
    rng_seed = derive_seed(seed)
    ob, og, ou = _ompl()
    start, goal = np.asarray(start, dtype=float), np.asarray(goal, dtype=float)
    info = {"states": 0, "tree_length": None, "time_limit": time_limit}
    if np.array_equal(start, goal):
        return start[None].copy(), info
    ou.setLogLevel(ou.LogLevel.LOG_NONE)

    space = ob.RealVectorStateSpace(2)
    bounds = ob.RealVectorBounds(2)
    x0, y0, x1, y1 = geometry.bounds
    bounds.setLow(0, x0), bounds.setHigh(0, x1), bounds.setLow(1, y0), bounds.setHigh(1, y1)
    space.setBounds(bounds)
    si = ob.SpaceInformation(space)
    si.setStateValidityChecker(lambda s: bool(geometry.points_feasible([s[0], s[1]])[0]))

    class SegmentValidator(ob.MotionValidator):
        def checkMotion(self, s1, s2, *last):
            if last:  # the lastValid form: RRTConnect does not call it
                raise NotImplementedError("checkMotion with lastValid")
            return bool(geometry.segments_feasible([[s1[0], s1[1]]], [[s2[0], s2[1]]])[0])

    validator = SegmentValidator(si)
    si.setMotionValidator(validator)
    si.setup()
    ou.RNG.setSeed(rng_seed)  # before the planner: it draws its sampler's seed from OMPL's generator
    problem = ob.ProblemDefinition(si)
    a, b = space.allocState(), space.allocState()
    a[0], a[1] = start
    b[0], b[1] = goal
    problem.setStartAndGoalStates(a, b)
    planner = og.RRTConnect(si)
    planner.setRange(STEP)
    planner.setProblemDefinition(problem)
    planner.setup()
    planner.solve(time_limit)
    path = None
    if problem.hasExactSolution():
        solution = problem.getSolutionPath()
        path = np.array([[solution.getState(k)[0], solution.getState(k)[1]] for k in range(solution.getStateCount())])
        path[0], path[-1] = start, goal
        info["states"] = len(path)
        info["tree_length"] = float(np.hypot(*np.diff(path, axis=0).T).sum())
        if delete:
            from htetro_opt.operators.path_bases import delete_path_bases

            path = np.vstack([start, delete_path_bases(path[1:-1], start, goal, geometry), goal])
    # break the validator <-> space-information cycle now, not at interpreter exit
    planner.clear()
    problem.clearSolutionPaths()
    del planner, problem, validator, si
    return path, info


def plan_rrt(scenario, *, time_limit: float | None = None, seed=DEFAULT_SEED) -> ContinuousPlan:
    """Each robot's B-RRT path (:func:`rrt_path`), alone, with deletion; one ``seed`` drives every
    robot's run. ``info``: ``time_limit``, and per robot ``states`` and ``tree_length``.

    Raises
    ------
    ParameterError
        Without OMPL (naming the pip command), or on a bad ``time_limit``.
    """
    began = time.perf_counter()
    scenario = check_scenario(scenario)
    time_limit = check_time_limit(time_limit, "time_limit")
    _ompl()
    rng = as_rng(seed)
    paths, infos = [], []
    for start, goal in zip(scenario.starts, scenario.goals):
        path, info = rrt_path(scenario.geometry, start, goal, time_limit=time_limit, seed=rng)
        paths.append(path)
        infos.append(info)
    info = {"time_limit": RRT_TIME_LIMIT if time_limit is None else time_limit,
            "states": [i["states"] for i in infos], "tree_length": [i["tree_length"] for i in infos]}
    return finish_plan(scenario, paths, method="rrt", began=began, info=info)
