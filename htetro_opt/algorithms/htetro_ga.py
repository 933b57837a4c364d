"""The paper's hTetro-GA (Cheng et al. 2020, Fig. 7) as a pymoo genetic algorithm.

Each generation makes two offspring sets from the parents P: a conservative one (removal, then
rearrangement, of every parent) and a non-conservative one (for each parent slot, with rate
r_cr = 0.5 a child of single-point crossover between two winners of size-4 deterministic
tournaments, otherwise the parent itself; then mutation of all). Parents and both sets are merged,
duplicates removed, and the goal-reachability sort keeps ``pop_size`` survivors.

A chromosome that reaches the goal is trimmed to its executed prefix (the genes after the goal are
never executed), so that the conservative operators keep its end cell: without the trim, removing an
``x+`` before the goal with an ``x−`` after it would move where the child stops. ``trim_reached=False``
keeps the genes whole.

Three additions of ours are on by default, each switchable, and :meth:`HTetroGA.as_published` turns
them all off:

- **repair** (:class:`~htetro_opt.operators.CommandRepair`): every new chromosome has its invalid
  commands replaced by valid ones, so children run their whole genes;
- **shortcut** (:class:`~htetro_opt.operators.CommandShortcut`): the conservative set also cuts the
  longest loop out of each path;
- **end-pose niching** of the goal-reachability sort (``niche_size``).

Measured on the paper's six maps (benchmarks/README.md), the published algorithm under MODEL.md's
child termination rarely gets through the spiral's corridor or our random map in 1000 generations,
and its best time stays well above the exact optimum; the additions fix both.
"""

from __future__ import annotations

import numpy as np
from pymoo.algorithms.base.genetic import GeneticAlgorithm
from pymoo.core.population import Population

from htetro_opt._validation import check_bool, check_int, check_probability
from htetro_opt.operators.commands import (
    CommandCrossover,
    CommandDuplicateElimination,
    CommandMutation,
    CommandRearrangement,
    CommandRemoval,
    CommandRepair,
    CommandSampling,
    GoalReachabilitySurvival,
    RankAndCrowdingTournament,
)
from htetro_opt.operators.commands import as_column, sequences
from htetro_opt.operators.commands.duplicates import chromosome_key, first_occurrences
from htetro_opt.operators.commands.shortcut import repair_and_shortcut

__all__ = ["HTetroGA", "trim_reached"]


def trim_reached(pop: Population) -> Population:
    """Cut every goal-reaching chromosome of ``pop`` to its executed prefix, in place."""
    if len(pop) == 0:
        return pop
    reached, executed, X = pop.get("reached").astype(bool), pop.get("executed").astype(np.int64), pop.get("X")
    for i in np.flatnonzero(reached):
        if len(X[i, 0]) > executed[i]:
            pop[i].set("X", as_column([X[i, 0][: executed[i]]])[0])
    return pop


class HTetroGA(GeneticAlgorithm):
    """hTetro-GA: NSGA-II with conservative and non-conservative offspring and the goal-reachability sort.

    Parameters
    ----------
    pop_size : int
        n_pop.
    sampling, crossover, mutation, removal, rearrangement : pymoo operators, optional
        Default to the command-chromosome operators of :mod:`htetro_opt.operators` with the paper's
        rates. Each runs through its pymoo ``do()``, so an operator's own ``prob`` is honoured.
    crossover_rate : float
        r_cr, the share of the non-conservative set made by crossover.
    tournament_size : int
    trim_reached : bool
        Cut chromosomes that reach the goal to their executed prefix (see the module docstring).
    repair : bool
        Repair every new chromosome (ours, see :class:`~htetro_opt.operators.CommandRepair`).
    shortcut : bool
        Cut the longest loop of each conservative offspring's path (ours, see
        :class:`~htetro_opt.operators.CommandShortcut`).
    niche_size : int
        End-pose niching of the goal-reachability sort (ours; 0 = the paper's sort as written, see
        :class:`~htetro_opt.operators.GoalReachabilitySurvival`).

    Raises
    ------
    ParameterError
        If ``pop_size`` is below 2, ``crossover_rate`` is not a probability, ``niche_size`` is
        negative or a switch is not a bool.

    Notes
    -----
    A generation whose offspring are all duplicates of the parents (or of each other) adds nothing:
    ``_infill`` returns None and the generation counts, for the termination, as one without
    improvement; the run still ends by its termination, never abruptly.

    Examples
    --------
    >>> from pymoo.optimize import minimize
    >>> from htetro_opt.model import Pose, Workspace
    >>> from htetro_opt.problems import CommandPathProblem
    >>> problem = CommandPathProblem(Workspace(np.zeros((10, 10), dtype=bool)), Pose(2, 2, "O", 0),
    ...                              Pose(6, 6, "O", 0), max_length=20)
    >>> res = minimize(problem, HTetroGA(pop_size=20), ("n_gen", 30), seed=1)
    >>> bool((res.F[:, 0] == -1).all()), float(res.F[:, 1].min())  # every F0 member reaches; best f_t
    (True, -0.6)
    """

    def __init__(
        self,
        pop_size: int = 50,
        *,
        sampling=None,
        crossover=None,
        mutation=None,
        removal=None,
        rearrangement=None,
        crossover_rate: float = 0.5,
        tournament_size: int = 4,
        trim_reached: bool = True,
        niche_size: int = 3,
        repair: bool = True,
        shortcut: bool = True,
        **kwargs,
    ) -> None:
        pop_size = check_int(pop_size, "pop_size", minimum=2)
        crossover_rate = check_probability(crossover_rate, "crossover_rate")
        repair = check_bool(repair, "repair")
        super().__init__(
            pop_size=pop_size,
            sampling=sampling if sampling is not None else CommandSampling(),
            selection=RankAndCrowdingTournament(tournament_size),
            crossover=crossover if crossover is not None else CommandCrossover(prob=1.0),
            mutation=mutation if mutation is not None else CommandMutation(),
            survival=GoalReachabilitySurvival(niche_size=niche_size),
            eliminate_duplicates=CommandDuplicateElimination(),
            advance_after_initial_infill=True,
            repair=CommandRepair() if repair else None,
            **kwargs,
        )
        self.removal = removal if removal is not None else CommandRemoval()
        self.rearrangement = rearrangement if rearrangement is not None else CommandRearrangement()
        self.crossover_rate = crossover_rate
        self.trim_reached = check_bool(trim_reached, "trim_reached")
        self.shortcut = check_bool(shortcut, "shortcut")

    @classmethod
    def as_published(cls, pop_size: int = 50, **kwargs) -> "HTetroGA":
        """The hTetro-GA with none of our additions: no repair, no shortcut, no niching."""
        return cls(pop_size, repair=False, shortcut=False, niche_size=0, **kwargs)

    def _initialize_advance(self, infills=None, **kwargs):
        if self.trim_reached:
            trim_reached(infills)
        infills = infills[first_occurrences(infills.get("X"))]
        self.pop = self.survival.do(self.problem, infills, n_survive=len(infills), algorithm=self,
                                    random_state=self.random_state)

    def _infill(self):
        # Every operator runs through its pymoo ``do()``, so that a user's operator (and its ``prob``)
        # behaves here as under any pymoo algorithm.
        problem, pop, rng, mating = self.problem, self.pop, self.random_state, self.mating
        X = pop.get("X")
        conservative = self.removal.do(problem, Population.new("X", X), random_state=rng)
        conservative = self.rearrangement.do(problem, conservative, random_state=rng).get("X")

        crossing = rng.random(len(pop)) < self.crossover_rate
        n_cross = int(crossing.sum())
        non_conservative = X[~crossing]
        if n_cross:
            matings = mating.selection.do(problem, pop, (n_cross + 1) // 2, n_parents=2,
                                          to_pop=False, random_state=rng)
            children = mating.crossover.do(problem, pop, matings, random_state=rng).get("X")
            non_conservative = np.concatenate([children[:n_cross], non_conservative])
        non_conservative = mating.mutation.do(problem, Population.new("X", non_conservative),
                                              random_state=rng).get("X")

        off = np.concatenate([conservative, non_conservative])
        # Repair and shortcut share one simulation (their pure function), which costs more than all
        # the other operators together.
        repair = rng if isinstance(self.repair, CommandRepair) else None
        seqs = repair_and_shortcut(problem, sequences(off), repair=repair,
                                   shortcut=len(conservative) if self.shortcut else 0)
        off = as_column(seqs)
        seen = {chromosome_key(x) for x in X[:, 0]}
        off = off[first_occurrences(off, seen)]
        if len(off) == 0:
            return None  # nothing new this generation: it counts as one without improvement
        return Population.new("X", off)

    def _advance(self, infills=None, **kwargs):
        if infills is None:
            return
        if self.trim_reached:
            trim_reached(infills)
        merged = Population.merge(self.pop, infills)
        merged = merged[first_occurrences(merged.get("X"))]
        self.pop = self.survival.do(self.problem, merged, n_survive=self.pop_size, algorithm=self,
                                    random_state=self.random_state)

    def _set_optimum(self):
        self.opt = self.pop[self.pop.get("rank") == 0]
