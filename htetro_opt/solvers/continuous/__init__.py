"""Path planning in continuous workspaces (Nazarahari et al. 2019): :func:`plan_continuous` with
``method=``.

- ``"exact"``: each robot's shortest path over the visibility graph of the free space's corners
  (:func:`visibility_path`): the reference of every heuristic (for r > 0, a lower and a feasible
  upper bound);
- ``"astar"``: A* on an 8-connected lattice of spacing ``grid`` (:func:`lattice_path`), the paper's
  grid baseline;
- ``"prm"``, ``"rrt"`` and ``"pso"``: the paper's other baselines (:func:`prm_path`: a roadmap of
  exactly n free samples; :func:`rrt_path`: OMPL's RRTConnect, an optional dependency;
  :func:`pso_path`: pymoo's PSO from the APF's paths, every move kept feasible), each robot alone;
- ``"ega"``, ``"ega-paper"`` and ``"nsga2"``: Nazarahari et al. 2019's enhanced GA over path bases
  (:func:`plan_ega`, :func:`plan_ega_paper`) and pymoo's multi-objective algorithms over the same
  (:func:`plan_moea`), several robots planned jointly;
- the APF of Nazarahari et al. 2019 (:func:`apf_paths`, :func:`apf_population`): the feasible
  initial paths of its enhanced GA.

Every method returns a :class:`ContinuousPlan`, re-validated against the scenario's geometry.

The geometry the problems and operators share with these planners lives below them and is
re-exported here: the APF, the lattice (:func:`lattice_graph`, :func:`check_grid`),
:func:`visibility_path` and :data:`SAFETY_MARGIN` in :mod:`htetro_opt.model`, :func:`check_scenario`
in :mod:`htetro_opt.scenarios` (as ``check_continuous_scenario``).
"""

from htetro_opt._lazy import attach

__getattr__, __dir__, __all__ = attach(__name__, {
    "plan_continuous": "._dispatch", "SPEC": "._spec",
    "ContinuousPlan": "._result", "SAFETY_MARGIN": "._result", "check_scenario": "._result",
    "check_grid": "htetro_opt.model._lattice",
    "visibility_path": "htetro_opt.model._visibility",
    "lattice_path": "._astar", "lattice_graph": "htetro_opt.model._lattice",
    "plan_ega": "._ega", "plan_ega_paper": "._ega", "plan_moea": "._ega", "plan_nsga2": "._ega",
    "MOEA_ALGORITHMS": "._ega",
    "prm_path": "._prm", "plan_prm": "._prm", "PAPER_PRM": "._prm",
    "rrt_path": "._rrt", "plan_rrt": "._rrt",
    "pso_path": "._pso", "plan_pso": "._pso", "pad_path_bases": "._pso", "keep_feasible_moves": "._pso",
    **{name: "htetro_opt.model._apf" for name in ("apf_depths", "apf_paths", "apf_population", "turning_points")},
})
