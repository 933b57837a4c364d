"""The exact reference: shortest paths over a visibility graph of the free space's corners.

A shortest path among polygons bends only at reflex corners of the free region, and leaves each
corner along a tangent: :func:`~htetro_opt.model.visibility_path` searches the visibility graph of
the start, the goal and the corners (the model's code, which the enhanced GA's taut refinement runs
too).

- r = 0 (every bundled map of Nazarahari et al. 2019): the optimum itself.
- r > 0: the C-obstacles are not polygons. Polygonised inside the true ones (grown by r, 8
  segments a quarter circle) the optimum is a **lower bound**; over the corners of polygons grown by
  r / cos(π/32), which contain the true ones, with every segment checked against the true geometry,
  it is a feasible **upper bound** (0.1–0.4 % above the lower one at these radii). Both are
  reported; the plan's path is the upper one. A passage between 2 r and 2 r / cos(π/32) wide is
  open to the robot but closed to the upper bound's corners: there the upper bound may not exist.
"""

from __future__ import annotations

import time

from htetro_opt.model._visibility import visibility_path
from htetro_opt.solvers.continuous._result import ContinuousPlan, finish_plan

__all__ = ["plan_exact"]


def plan_exact(scenario) -> ContinuousPlan:
    """Each robot's shortest path, alone, with its lower and upper bounds (see the module docstring).

    ``info`` holds ``lower_bound`` and ``upper_bound`` per robot (equal when r = 0; inf when not
    reached) and ``corners`` (the visibility graph's corner count, per bound).
    """
    began = time.perf_counter()
    geometry = scenario.geometry
    exact = geometry.robot_radius == 0
    inner = geometry.polygonised("inner")
    inner_corners = inner.corners()
    outer_corners = inner_corners if exact else geometry.polygonised("outer").corners()
    paths, lower, upper = [], [], []
    for start, goal in zip(scenario.starts, scenario.goals):
        path, length = visibility_path(geometry, start, goal, corners=outer_corners)
        bound = length if exact else visibility_path(inner, start, goal, corners=inner_corners)[1]
        paths.append(path)
        lower.append(bound)
        upper.append(length)
    info = {"lower_bound": lower, "upper_bound": upper, "corners": [len(inner_corners), len(outer_corners)]}
    return finish_plan(scenario, paths, method="exact", began=began, info=info)
