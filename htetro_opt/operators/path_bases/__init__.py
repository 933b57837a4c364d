"""Operators over Nazarahari et al. 2019's path-base chromosomes (float PBs, one robot or K), each a
pure function beside a thin pymoo class, randomness from pymoo's ``random_state``:

- :class:`PathBasesSampling`: the APF's initial paths;
- :class:`PathBasesCrossover`: eq. 1 (:func:`mean_crossover`) and eq. 2 (:func:`blend_crossover`);
- :class:`PathBasesMutation`: :func:`random_move`, :func:`smooth_move` (eq. 3), :func:`goal_move`;
- :class:`PathBasesDeletion` (a ``Repair``): :func:`delete_path_bases`;
- :class:`TautRefinement` (ours, a ``Repair``): :func:`taut_path`;
- :class:`CollisionRemoval` (a ``Repair``): :func:`remove_collisions`;
- :class:`PathBasesDuplicateElimination`, :func:`path_key`, :func:`as_column`: float-aware chromosome
  helpers (the command family's cast genes to int64).
"""

from htetro_opt._lazy import attach

__getattr__, __dir__, __all__ = attach(__name__, {
    **{name: ".chromosome" for name in ("as_column", "chromosomes", "path_key", "PathBasesDuplicateElimination")},
    **{name: ".crossover" for name in
       ("pair_path_bases", "mean_crossover", "blend_crossover", "clip_to_box", "PathBasesCrossover")},
    **{name: ".mutation" for name in ("n_mutated", "random_move", "smooth_move", "goal_move", "PathBasesMutation")},
    **{name: ".deletion" for name in ("delete_path_bases", "delete_chromosome", "PathBasesDeletion")},
    **{name: ".refine" for name in ("near_corners", "taut_path", "TautRefinement")},
    **{name: ".collision" for name in ("conflicts", "remove_collisions", "CollisionRemoval")},
    "PathBasesSampling": ".sampling", "initial_paths": ".sampling",
})
