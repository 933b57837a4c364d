"""The names the GAs over command chromosomes and the enhanced GA over path bases take, as plain data:
importing them loads no pymoo, so that the grid-path and continuous tasks' specs
(``htetro_opt.solvers.grid_paths._spec``, ``htetro_opt.solvers.continuous._spec``) and the command
line can offer them as choices."""

from __future__ import annotations

__all__ = ["CONVERGENCE_MEASURES", "EGA_ADDITIONS", "GA_ADDITIONS", "GA_ALGORITHMS", "PICKS", "SELECTIONS"]

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
    "reach-levels": "the goal-reachability sort splits the members that do not reach into one section per f_gr value, "
                    "highest first (the paper: two sections, reached and not reached)",
    "niching": "end-pose niching of the goal-reachability sort (niche_size 3)",
    "gene-cap": "crossover cuts each child to at most twice l_p,max genes (the paper: no cap)",
    "replanning": "each generation, windows of the fastest and of a few random goal-reaching members are replaced by "
                  "the minimum-time path between their ends (replan_window, replan_members)",
    "reach-repair": "when no member reaches and the best goal reachability stalls (reach_patience generations), the "
                    "member nearest to the goal gets the minimum-time path to it",
    "polish": "when the run ends, the largest-sum leading-front member is re-planned exactly for the largest fitness "
              "sum (polish_window)",
}
"""The hTetro-GA's additions of ours to Cheng et al. 2020's algorithm, by name, each switchable
(:meth:`~htetro_opt.algorithms.HTetroGA.with_additions`): ``htetro-ga`` has them all, ``htetro-ga-paper``
none (docs/papers/cheng2020.md measures what each changes)."""

EGA_ADDITIONS = {
    "delete-every-child": "deletion runs on every child and on the initial paths; the paper deletes the PBs of one "
                          "roulette pick per generation, which is then one more child",
    "deletion-passes": "deletion repeats its left-to-right pass until a pass drops nothing; the paper assesses each "
                       "PB of the path once, in order (§4.3.4)",
    "straight-first": "deletion first tries the straight start-goal segment, kept when it is feasible and no "
                      "costlier; the paper only deletes PBs one at a time",
    "child-dedup": "children equal to a member or to an earlier child are dropped (and duplicate initial paths); "
                   "the paper keeps every child",
    "taut-refinement": "the initial paths and each generation's best child are pulled taut by an exact "
                       "visibility-graph search over their own PBs and the wall corners within 2 d of them",
    "finer-apf": "half the initial paths come from the APF lattice at half the step, d / 2; the paper's APF runs "
                 "at d only",
    "apf-refinement": "when the APF lattice does not join a robot's start to its goal it is halved up to three "
                      "times (d / 2 ... d / 8); the paper's APF at d then finds no path, and the robot is not reached",
}
"""Our additions to Nazarahari et al. 2019's enhanced GA (§4.3), by name (:class:`~htetro_opt.algorithms.EnhancedGA`):
the continuous task's ``ega`` runs them all, ``ega-paper`` (the paper's) none; each is switched on or off singly by
the ``additions`` option (docs/papers/nazarahari2019.md)."""
