"""The names the GAs over command chromosomes take, as plain data: importing them loads no pymoo, so
that the grid-path task's spec (``htetro_opt.solvers.grid_paths._spec``) and the command line can
offer them as choices."""

from __future__ import annotations

__all__ = ["CONVERGENCE_MEASURES", "GA_ADDITIONS", "GA_ALGORITHMS", "PICKS", "SELECTIONS"]

GA_ALGORITHMS = ("htetro-ga", "htetro-ga-paper", "nsga2", "nsga3", "smsemoa", "agemoea")
"""Algorithm names :func:`~htetro_opt.algorithms.make_algorithm` knows: the hTetro-GA with our
additions, as published, and four of pymoo's."""

CONVERGENCE_MEASURES = ("best", "hypervolume")
"""What :class:`~htetro_opt.algorithms.FrontConvergence` watches: the best of each fitness, or the best
time and the hypervolume of the goal-reaching individuals."""

SELECTIONS = ("multi_objective", "time", "smoothness", "safety")
"""The paper's four output solutions: largest fitness sum in F0, then best f_t, f_sm, f_sf."""

PICKS = {"balanced": "multi_objective", "fastest": "time", "smoothest": "smoothness", "safest": "safety"}
"""Which of the four solutions a planner returns, by the name the planner and the CLI take (``pick``).

Cheng et al. 2020 contradicts itself here: §VI, presenting Table 4, says the output solution is
"the individual with the smallest crowding distance" in F0; §VI-B (Figs. 9 and 10) that the
multi-objective based solutions are the individuals "with the maximum sum of the four fitness values"
within F0. ``"balanced"`` is the latter;
the former is not offered (the extremes of a front have infinite crowding distance, so the
"smallest" is an arbitrary interior member)."""

GA_ADDITIONS = {
    "repair": "every new chromosome has its invalid commands replaced by valid ones, so children run their whole genes",
    "shortcut": "the conservative set also cuts the longest loop out of each path",
    "niching": "end-pose niching of the goal-reachability sort (niche_size 3)",
    "replanning": "each generation, windows of the fastest and of a few random goal-reaching members are replaced by "
                  "the minimum-time path between their ends (replan_window, replan_members)",
    "reach-repair": "when no member reaches and the best goal reachability stalls (reach_patience generations), the "
                    "member nearest to the goal gets the minimum-time path to it",
    "polish": "when the run ends, the largest-sum leading-front member is re-planned exactly for the largest fitness "
              "sum (polish_window)",
}
"""The hTetro-GA's additions of ours to Cheng et al. 2020's algorithm, by name, each switchable
(:meth:`~htetro_opt.algorithms.HTetroGA.with_additions`): ``htetro-ga`` has them all, ``htetro-ga-paper``
none."""
