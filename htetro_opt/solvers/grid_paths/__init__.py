"""Grid path planning through a roadmap of configurations: :func:`plan_path` with ``method=``.

- ``"dijkstra"``, ``"astar"`` (:func:`plan_exact`): the minimum-time plan over (x, y, shape,
  heading), time-expanded for moving obstacles: the exact reference of every heuristic;
- ``"htetro-ga"``, ``"htetro-ga-paper"``, ``"nsga2"``, ``"nsga3"``, ``"smsemoa"``, ``"agemoea"``
  (:func:`plan_ga`): Cheng et al. 2020's multi-objective GA over motion-command chromosomes, or one
  of pymoo's algorithms over the same problem, leg by leg.
- :func:`plan_max_fitness_sum` (not a ``plan_path`` method: one leg, start to goal): the exact
  maximum of the GA's fitness sum f_gr + f_t + f_sm + f_sf under its own objective, the reference of
  its balanced pick.

- ``"heat"``, ``"heat-paper"`` (:func:`plan_heat`): Do et al. 2021's heat-conduction planner (with our
  additions, :data:`HEAT_ADDITIONS`, or as published), a search that climbs each leg's temperature
  field (:func:`solve_heat_field`, scikit-fem's bilinear element or cell-centred), static maps only; :func:`replan_heat` runs it online on a scenario with hidden
  obstacles (§VI-A-7), sensing and replanning as the robot moves, and returns a :class:`HeatRun`.

Every method returns a :class:`Plan`, re-validated in the simulator.
"""

from htetro_opt._lazy import attach

__getattr__, __dir__, __all__ = attach(__name__, {
    "plan_path": "._dispatch", "SPEC": "._spec",
    "Plan": "._result", "FrontMember": "._result", "LegResult": "._result",
    "plan_exact": "._exact", "EXACT_METHODS": "._exact",
    "plan_ga": "._ga",
    "plan_max_fitness_sum": "._fitness_sum",
    "plan_heat": "._heat", "HEAT_ADDITIONS": "._spec", "HEAT_ENGINES": "._spec", "BAND_SEEDS": "._spec",
    "replan_heat": "._replan", "HeatRun": "._replan",
    "solve_heat_field": "._heat_field", "HeatField": "._heat_field", "HEAT_ELEMENTS": "._spec",
})
