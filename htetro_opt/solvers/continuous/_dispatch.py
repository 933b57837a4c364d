"""One entry point for planning in a continuous scenario, whatever the method."""

from __future__ import annotations

import time
from typing import Callable

import numpy as np

from htetro_opt.errors import PlanningError
from htetro_opt.solvers.continuous._result import ContinuousPlan, check_scenario, finish_plan
from htetro_opt.solvers.continuous._spec import SPEC

__all__ = ["plan_continuous"]


def plan_continuous(scenario, *, method: str | Callable = SPEC.default, **options) -> ContinuousPlan:
    """Plan every robot's path through a continuous scenario (Nazarahari et al. 2019), with one method.

    Parameters
    ----------
    scenario : ContinuousScenario
        A loaded continuous scenario (``ContinuousScenario.from_grid`` converts a grid one).
    method : str or callable, keyword-only
        A method of the task's spec (:data:`~htetro_opt.solvers.continuous.SPEC`, which lists every
        method with its options and defaults):

        - ``"exact"`` (default): the shortest path of each robot alone, over the visibility graph of
          the free space's corners: the optimum for a point robot; for r > 0 a feasible upper bound,
          with the lower bound in ``info`` (no options);
        - ``"astar"``: A* on the 8-connected lattice of spacing ``grid`` (default 1.0; the paper
          also uses 0.25), each robot alone;
        - ``"prm"``: the shortest path over a roadmap of exactly ``n`` uniform free samples joined
          within ``radius`` (default: the paper's per map), then deletion, each robot alone
          (:func:`~htetro_opt.solvers.continuous.plan_prm`: options ``n``, ``radius``, ``seed``);
        - ``"rrt"``: OMPL's RRTConnect (the paper's B-RRT, step 2), then deletion, each robot alone
          (:func:`~htetro_opt.solvers.continuous.plan_rrt`: options ``time_limit`` (120 s),
          ``seed``; needs the optional OMPL: ``pip install 'htetro-opt[ompl]'``);
        - ``"pso"``: pymoo's particle swarm over the path bases from the APF's paths, each robot
          alone (:func:`~htetro_opt.solvers.continuous.plan_pso`: options ``pop_size``,
          ``max_gen``, ``grid``, ``seed``);
        - ``"ega"``: Nazarahari et al. 2019's enhanced GA over path bases with our additions, all
          robots jointly (:func:`~htetro_opt.solvers.continuous.plan_ega`: options ``path``,
          ``weights`` or ``normalise``, ``safety``, ``grid``, ``pop_size``, ``max_gen``, ``seed``);
        - ``"ega-paper"``: the same GA as published (:func:`~htetro_opt.solvers.continuous.plan_ega_paper`);
        - ``"nsga2"``: pymoo's NSGA-II over the same path bases, minimising (length, smoothness,
          −safety); the front in ``info["front"]`` (:func:`~htetro_opt.solvers.continuous.plan_moea`:
          options ``path``, ``safety``, ``grid``, ``pop_size``, ``max_gen``, ``seed``).

        Or a callable ``method(geometry, start, goal, **options)`` returning one robot's path (an
        (n, 2) array from its start to its goal) or None; it is called once per robot with the
        scenario's :class:`~htetro_opt.model.ContinuousGeometry`.
    **options
        Keyword options of the method (``grid`` for ``"astar"``; see above for the GAs), each checked
        and defaulted by the spec before any work.

    Returns
    -------
    ContinuousPlan
        Re-validated against the obstacles, whatever the method. A robot whose goal cannot be
        reached has an empty path and ``reached`` is False (not an exception). Robots planned alone
        may meet: ``conflicts`` and ``min_robot_distance`` say so.

    Raises
    ------
    ScenarioError
        For a grid scenario (or anything but a continuous one).
    ParameterError
        On an unknown method, an option the method does not take or a bad option value (``grid`` ≤ 0
        or above min(W, H) / 2, bad weights, an unknown ``path`` or ``safety``); ``"rrt"`` without
        OMPL installed.
    PlanningError
        If a callable method returns a path that is not an (n, 2) array from the start to the goal,
        or that collides.

    Examples
    --------
    >>> from htetro_opt.scenarios import load_scenario
    >>> scenario = load_scenario("ega07_slits1")
    >>> exact = plan_continuous(scenario)
    >>> astar = plan_continuous(scenario, method="astar", grid=1.0)
    >>> exact.reached, astar.reached, exact.length < astar.length
    (True, True, True)
    >>> straight = plan_continuous(scenario, method=lambda geometry, start, goal: np.array([start, goal]))
    Traceback (most recent call last):
    ...
    htetro_opt.errors.PlanningError: method <lambda>: the path of robot 0 collides with the obstacles
    """
    scenario = check_scenario(scenario)
    if callable(method):
        return _plan_with(method, scenario, options)
    chosen = SPEC.method(method)
    options = SPEC.check(chosen, options, stage="method")
    return chosen.load(SPEC.package)(scenario, **chosen.presets, **options)


def _plan_with(method: Callable, scenario, options: dict) -> ContinuousPlan:
    name = getattr(method, "__name__", type(method).__name__)
    began = time.perf_counter()
    paths = []
    for i, (start, goal) in enumerate(zip(scenario.starts, scenario.goals)):
        path = method(scenario.geometry, start.copy(), goal.copy(), **options)
        if path is not None:
            try:
                path = np.asarray(path, dtype=float)
            except (TypeError, ValueError) as err:
                raise PlanningError(f"method {name} returned {type(path).__name__} for robot {i}: "
                                    "expected an (n, 2) array or None") from err
            if path.ndim != 2 or path.shape[1] != 2 or not len(path) or not np.isfinite(path).all():
                raise PlanningError(f"method {name} returned an array of shape {path.shape} for robot {i}: "
                                    "expected (n, 2) finite points")
            if not (np.array_equal(path[0], start) and np.array_equal(path[-1], goal)):
                raise PlanningError(f"method {name}: the path of robot {i} does not run from its start "
                                    f"{start.tolist()} to its goal {goal.tolist()}")
            if not scenario.geometry.path_feasible(path):
                raise PlanningError(f"method {name}: the path of robot {i} collides with the obstacles")
        paths.append(path)
    return finish_plan(scenario, paths, method=name, began=began)
