"""Path planning in continuous workspaces (Nazarahari et al. 2019): :func:`plan_continuous` with
``method=``.

- ``"exact"``: each robot's shortest path over the visibility graph of the free space's corners
  (:func:`visibility_path`): the reference of every heuristic (for r > 0, a lower and a feasible
  upper bound);
- ``"astar"``: A* on an 8-connected lattice of spacing ``grid`` (:func:`lattice_path`), the paper's
  grid baseline.

Every method returns a :class:`ContinuousPlan`, re-validated against the scenario's geometry.
"""

from htetro_opt._lazy import attach

__getattr__, __dir__, __all__ = attach(__name__, {
    "plan_continuous": "._dispatch", "CONTINUOUS_METHODS": "._dispatch",
    "ContinuousPlan": "._result",
    "visibility_path": "._exact",
    "lattice_path": "._astar", "lattice_graph": "._astar",
})
