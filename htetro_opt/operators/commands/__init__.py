"""pymoo operators over variable-length motion-command chromosomes (Cheng et al. 2020).

One operator per module, each a pure function over ``numpy`` arrays beside a thin pymoo class that
takes the ``random_state`` pymoo passes:

- :mod:`.sampling`: Algorithm 1 (:class:`CommandSampling`);
- :mod:`.mutation`: per-command mutation (:class:`CommandMutation`);
- :mod:`.crossover`: single-point crossover of variable-length parents (:class:`CommandCrossover`);
- :mod:`.removal` and :mod:`.rearrangement`: the conservative operators, which never change B2's
  total displacement (:class:`CommandRemoval`, :class:`CommandRearrangement`);
- :mod:`.repair`: ours, optional: invalid commands replaced by valid ones (:class:`CommandRepair`);
- :mod:`.shortcut`: ours, optional: cut the longest loop of a path (:class:`CommandShortcut`);
- :mod:`.replan`: ours, optional: replace a window of a path by the minimum-time path between its
  ends (:class:`CommandReplan`), or the tail of a path that misses the goal by the fastest way to
  it (:class:`CommandReachRepair`);
- :mod:`.polish`: ours, optional: windows of a goal-reaching path re-planned for the largest fitness
  sum (:func:`polish_sum`, the hTetro-GA's balanced polish when a run ends);
- :mod:`.duplicates`: :class:`CommandDuplicateElimination`;
- :mod:`.selection`: the size-4 deterministic tournament on rank and crowding;
- :mod:`.survival`: the goal-reachability sort (:class:`GoalReachabilitySurvival`).
"""

from htetro_opt.operators.commands._chromosome import as_column, as_row, displacement, sequences
from htetro_opt.operators.commands.crossover import CommandCrossover, single_point_crossover
from htetro_opt.operators.commands.duplicates import CommandDuplicateElimination, chromosome_key
from htetro_opt.operators.commands.mutation import CommandMutation, mutate_commands
from htetro_opt.operators.commands.rearrangement import CommandRearrangement, rearrange_commands
from htetro_opt.operators.commands.repair import CommandRepair
from htetro_opt.operators.commands.polish import fitness_sum, polish_sum
from htetro_opt.operators.commands.removal import CommandRemoval, remove_commands
from htetro_opt.operators.commands.replan import (
    CommandReachRepair,
    CommandReplan,
    TransitionGraph,
    reach_repair,
    replan_rows,
    replan_windows,
)
from htetro_opt.operators.commands.shortcut import (
    CommandShortcut,
    cut_longest_loop,
    longest_loops,
    repair_and_shortcut,
    shortcut_sequences,
)
from htetro_opt.operators.commands.sampling import DEFAULT_SAMPLING_WEIGHTS, CommandSampling, sample_commands
from htetro_opt.operators.commands.selection import RankAndCrowdingTournament, rank_and_crowding_tournament
from htetro_opt.operators.commands.survival import GoalReachabilitySurvival, reaches_goal

__all__ = [
    "as_column", "as_row", "displacement", "sequences",
    "CommandCrossover", "single_point_crossover",
    "CommandDuplicateElimination", "chromosome_key",
    "CommandMutation", "mutate_commands",
    "CommandRearrangement", "rearrange_commands",
    "CommandRemoval", "remove_commands",
    "polish_sum", "fitness_sum",
    "CommandRepair",
    "CommandShortcut", "cut_longest_loop", "longest_loops", "shortcut_sequences", "repair_and_shortcut",
    "CommandReplan", "TransitionGraph", "replan_rows", "replan_windows", "CommandReachRepair", "reach_repair",
    "DEFAULT_SAMPLING_WEIGHTS", "CommandSampling", "sample_commands",
    "RankAndCrowdingTournament", "rank_and_crowding_tournament",
    "GoalReachabilitySurvival", "reaches_goal",
]
