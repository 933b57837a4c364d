"""Variation and selection operators, one family per kind of chromosome.

- :mod:`htetro_opt.operators.commands` (Cheng et al. 2020): pymoo operators over variable-length
  motion-command chromosomes, each a pure batch function beside a thin pymoo class;
- :mod:`htetro_opt.operators.permutation` (Le et al. 2018): DEAP operators over waypoint orders,
  drawing from a private ``random.Random``;
- :mod:`htetro_opt.operators.path_bases` (Nazarahari et al. 2019): pymoo operators over float
  path-base chromosomes, each a pure function beside a thin pymoo class.

Every public name of the three is available here too (but path_bases' own as_column and chromosomes).
"""

from htetro_opt._lazy import attach

_COMMANDS = [
    "as_column", "displacement", "sequences",
    "CommandCrossover", "single_point_crossover",
    "CommandDuplicateElimination", "chromosome_key",
    "CommandMutation", "mutate_commands",
    "CommandRearrangement", "rearrange_commands",
    "CommandRemoval", "remove_commands",
    "CommandRepair",
    "CommandShortcut", "cut_longest_loop", "longest_loops", "shortcut_sequences", "repair_and_shortcut",
    "DEFAULT_SAMPLING_WEIGHTS", "CommandSampling", "sample_commands",
    "RankAndCrowdingTournament", "rank_and_crowding_tournament",
    "GoalReachabilitySurvival", "reaches_goal",
]
_PERMUTATION = ["Tour", "TourFitness", "order_crossover", "select_tournament", "swap_mutation"]
_PATH_BASES = [  # as_column and chromosomes stay in operators.path_bases: the command family has its own
    "PathBasesSampling", "PathBasesCrossover", "mean_crossover", "blend_crossover", "PathBasesMutation", "random_move",
    "smooth_move", "goal_move", "PathBasesDeletion", "delete_path_bases", "TautRefinement", "taut_path",
    "CollisionRemoval", "remove_collisions", "PathBasesDuplicateElimination", "path_key",
]

__getattr__, __dir__, __all__ = attach(__name__, {**{name: ".commands" for name in _COMMANDS},
                                                  **{name: ".permutation" for name in _PERMUTATION},
                                                  **{name: ".path_bases" for name in _PATH_BASES}})
