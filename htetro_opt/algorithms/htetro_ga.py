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

Eight additions of ours are on by default, each switchable (:meth:`HTetroGA.with_additions`, the
names of :data:`~htetro_opt.algorithms.GA_ADDITIONS`), and :meth:`HTetroGA.as_published` turns them
all off:

- **repair** (:class:`~htetro_opt.operators.CommandRepair`): every new chromosome has its invalid
  commands replaced by valid ones, so children run their whole genes;
- **shortcut** (:class:`~htetro_opt.operators.CommandShortcut`): the conservative set also cuts the
  longest loop out of each path;
- **reach levels** of the goal-reachability sort (``reach_levels``): the members that do not reach
  are sorted in one section per f_gr value, highest first, where the paper (§IV-C step 3) has two
  sections, reached and not reached (:class:`~htetro_opt.operators.GoalReachabilitySurvival`);
- **end-pose niching** of the goal-reachability sort (``niche_size``);
- **gene cap** (``gene_cap``): crossover cuts each child to at most 2 l_p,max genes; the paper's
  single-point crossover has no bound (:func:`~htetro_opt.operators.commands.crossover.cap_genes`);
- **windowed exact re-planning** (:class:`~htetro_opt.operators.commands.CommandReplan`,
  ``replan_window`` and ``replan_members``): each generation, a window of up to W executed commands of
  the fastest goal-reaching member and of a few random reaching members is replaced by the minimum-time
  path between the window's end poses; the re-planned chromosomes join the offspring. It generalises
  the shortcut and is the only operator that makes the 2–4-gene changes a route needs (``sS … sO``
  where ``y+ … y−`` would do), so the fastest member no longer stays above the exact optimum;
- **reach repair** (:class:`~htetro_opt.operators.commands.CommandReachRepair`, ``reach_patience``):
  re-planning touches only goal-reaching members, so a run whose population gets stuck without
  reaching stays stuck (measured: parallel_dynamic, seed 9, the whole population on the goal cell in
  the wrong morphology for 1000 generations). When no member reaches and the population's best
  goal reachability f_gr has not risen for ``reach_patience`` generations, the member nearest to the
  goal has its tail after the pose nearest to the goal replaced by the minimum-time path from there
  to the goal (time-expanded on moving maps), and joins the offspring. A run that reaches before
  stalling that long is untouched (the step draws no random numbers before it fires).
- **balanced polish** (:func:`~htetro_opt.operators.commands.polish_sum`, ``polish_window``): when the
  run ends (pymoo's ``_finalize``, which runs before ``result()``), the leading-front member with the
  largest fitness sum (the paper's multi-objective based solution, the one a planner picks) has
  windows of its path re-planned exactly for the largest sum; a path of at most W commands is
  re-planned whole, which gives the leg's largest sum. The polished member joins the population
  through the goal-reachability sort. Its sum is larger than every leading-front member's, so none
  of them dominates it and it is the new pick. The GA's balanced pick otherwise falls short of the
  exact maximum by 0.02–0.06 in some runs, and those picks are 11–17 % slower than the minimum time
  where the maximiser's plan is within 10 % (benchmarks/results/ga_replan/balanced_exact.md). The
  generations before the end are untouched, and the polish draws no random numbers.

**The loop runs on arrays.** A generation keeps the population as a list of chromosomes beside
``F`` and the auxiliary columns (``reached``, ``executed``, ``time``, ``end``, ``rank``, ``crowding``):
the operators run on the list (:mod:`~htetro_opt.operators.commands.batch`: pymoo's ``do()`` without
a ``Population``), each offspring is simulated once (the simulation that repairs it and finds its
loop also scores it; :func:`~htetro_opt.operators.commands.shortcut.repair_shortcut_evaluate`), and
the goal-reachability sort calls pymoo's compiled non-dominated sorting and crowding on ``F``
(:meth:`~htetro_opt.operators.GoalReachabilitySurvival.sort`). pymoo's ``Population`` is kept at the
boundary: ``algorithm.pop`` and ``algorithm.opt`` hold the survivors after every generation (each
survivor's pymoo ``Individual`` made once, when it first survives), so ``minimize``, callbacks,
terminations and pymoo's ask-and-tell interface (``_infill`` returns the offspring, evaluated;
``_advance`` takes them) work as with any pymoo algorithm. The offspring are counted in
``algorithm.evaluator.n_eval`` but do not pass through the evaluator (nor ``algorithm.off``).

Measured on the paper's six maps (docs/papers/cheng2020.md, the ``cheng2020_ablation`` study), the
published algorithm under MODEL.md's child termination often fails to reach the goal in 1000
generations, and its plans stay well above the exact optimum; each addition's share is measured there.
"""

from __future__ import annotations

import time as _time

import numpy as np
from pymoo.algorithms.base.genetic import GeneticAlgorithm
from pymoo.core.individual import Individual
from pymoo.core.population import Population

from htetro_opt._validation import check_bool, check_int, check_probability
from htetro_opt.algorithms.names import GA_ADDITIONS
from htetro_opt.algorithms.solutions import select_solutions
from htetro_opt.errors import ParameterError
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
from htetro_opt.operators.commands import as_column, as_row, sequences
from htetro_opt.operators.commands.batch import apply_crossover, apply_mutation
from htetro_opt.operators.commands.duplicates import chromosome_key, first_keys
from htetro_opt.operators.commands.polish import polish_sum
from htetro_opt.operators.commands.replan import CommandReachRepair, CommandReplan, replan_rows
from htetro_opt.operators.commands.shortcut import repair_shortcut_evaluate

__all__ = ["HTetroGA", "check_additions", "trim_reached"]


def trim_reached(pop: Population) -> Population:
    """Cut every goal-reaching chromosome of ``pop`` to its executed prefix, in place."""
    if len(pop) == 0:
        return pop
    reached, executed, X = pop.get("reached").astype(bool), pop.get("executed").astype(np.int64), pop.get("X")
    for i in np.flatnonzero(reached):
        if len(X[i, 0]) > executed[i]:
            pop[i].set("X", as_column([X[i, 0][: executed[i]]])[0])
    return pop


_COLUMNS = ("reached", "executed", "time", "end")  # what CommandPathProblem.outcomes gives beside F
_EVALUATED = ("F", "G", "H") + _COLUMNS  # what pymoo's evaluator marks evaluated


class _Members:
    """Individuals as arrays: chromosomes, ``F``, the auxiliary columns and, where known, each
    chromosome's :func:`~htetro_opt.operators.commands.duplicates.chromosome_key` and the pymoo
    ``Individual`` that stands for the row at the boundary."""

    def __init__(self, X: list, F: np.ndarray, columns: dict, individuals: list | None = None,
                 keys: list | None = None) -> None:
        self.X = X
        self._keys = keys if keys is not None else [None] * len(X)
        self.F = F
        self.reached = np.asarray(columns["reached"]).astype(bool)
        self.executed = np.asarray(columns["executed"]).astype(np.int64)
        self.time = np.asarray(columns["time"]).astype(float)
        self.end = np.asarray(columns["end"]).astype(np.int64)
        self.individuals = individuals if individuals is not None else [None] * len(X)

    @classmethod
    def of(cls, pop: Population) -> "_Members":
        """The rows of an evaluated population (its individuals kept)."""
        F, *columns = pop.get("F", *_COLUMNS)
        return cls(sequences(pop.get("X")), F.astype(float), dict(zip(_COLUMNS, columns)), list(pop))

    def __len__(self) -> int:
        return len(self.X)

    def take(self, rows: np.ndarray) -> "_Members":
        rows = np.asarray(rows, dtype=np.int64)
        return _Members([self.X[i] for i in rows], self.F[rows],
                        {key: getattr(self, key)[rows] for key in _COLUMNS}, [self.individuals[i] for i in rows],
                        [self._keys[i] for i in rows])

    def __add__(self, other: "_Members") -> "_Members":
        return _Members(self.X + other.X, np.concatenate([self.F, other.F]),
                        {key: np.concatenate([getattr(self, key), getattr(other, key)]) for key in _COLUMNS},
                        self.individuals + other.individuals, self._keys + other._keys)

    def keys(self) -> list[int]:
        """Each chromosome's key, computed once."""
        for i in [i for i, key in enumerate(self._keys) if key is None]:
            self._keys[i] = chromosome_key(self.X[i])
        return self._keys

    def trim_reached(self) -> None:
        """Cut every goal-reaching chromosome to its executed prefix, in place (see :func:`trim_reached`)."""
        for i in np.flatnonzero(self.reached & (np.fromiter(map(len, self.X), np.int64, len(self.X)) > self.executed)):
            self.X[i] = self.X[i][: self.executed[i]]
            self._keys[i] = None
            if self.individuals[i] is not None:
                self.individuals[i].set("X", as_row(self.X[i]))

    def individual(self, i: int, n_iter: int) -> Individual:
        """Row i's pymoo Individual, made as pymoo's evaluator would have left it."""
        if self.individuals[i] is None:
            ind = Individual(X=as_row(self.X[i]), F=self.F[i].copy(), n_gen=n_iter, n_iter=n_iter,
                             **{key: getattr(self, key)[i] for key in _COLUMNS})
            ind.evaluated.update(_EVALUATED)
            self.individuals[i] = ind
        return self.individuals[i]


def check_additions(additions) -> tuple[str, ...]:
    """``additions`` as names of :data:`~htetro_opt.algorithms.GA_ADDITIONS`, in its order.

    Raises
    ------
    ParameterError
        Naming an unknown one and the additions there are.
    """
    if isinstance(additions, str) or not hasattr(additions, "__iter__"):
        raise ParameterError(f"additions must be a collection of names of {', '.join(GA_ADDITIONS)}, "
                             f"got {additions!r}")
    additions = set(additions)
    unknown = sorted(map(str, additions - set(GA_ADDITIONS)))
    if unknown:
        raise ParameterError(f"unknown hTetro-GA addition {', '.join(map(repr, unknown))}: the additions are "
                             f"{', '.join(GA_ADDITIONS)}")
    return tuple(name for name in GA_ADDITIONS if name in additions)


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
    reach_levels : bool
        Sort the members that do not reach in one section per f_gr value (ours; False = the paper's
        two sections, see :class:`~htetro_opt.operators.GoalReachabilitySurvival`).
    niche_size : int
        End-pose niching of the goal-reachability sort (ours; 0 = the paper's sort as written, see
        :class:`~htetro_opt.operators.GoalReachabilitySurvival`).
    gene_cap : bool
        Cut crossover's children to 2 l_p,max genes (ours; False = the paper's unbounded crossover).
        Ignored when ``crossover`` is given (that operator's own cap holds).
    replan_window : int
        W of the windowed exact re-planning (ours; 0 = off, see
        :class:`~htetro_opt.operators.commands.CommandReplan`).
    replan_members : int
        How many random goal-reaching members are re-planned each generation besides the fastest one.
    reach_share : float
        Most share of the population the goal-reaching individuals keep while others can take the
        rest (ours, off by default: 1 = the paper's sort, see
        :class:`~htetro_opt.operators.GoalReachabilitySurvival`; measured in benchmarks/README.md,
        0.75 changes little once the re-planning is on).
    reach_patience : int
        Generations without a reaching member and without a rise of the population's best f_gr after
        which the member nearest to the goal is reach-repaired (ours; 0 = off; see the module
        docstring and :class:`~htetro_opt.operators.commands.CommandReachRepair`). The default, 100,
        is the termination's patience: a search that has stalled as long as a run is allowed to
        stall once it reaches.
    polish_window : int
        W of the balanced polish when the run ends (ours; 0 = off; see the module docstring and
        :func:`~htetro_opt.operators.commands.polish_sum`): the largest-sum leading-front member's
        path re-planned for the largest fitness sum, whole when it has at most W commands.

    Raises
    ------
    ParameterError
        If ``pop_size`` is below 2, ``crossover_rate`` is not a probability, ``niche_size``,
        ``replan_window``, ``replan_members``, ``reach_patience`` or ``polish_window`` is negative or a
        switch is not a bool.

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
        reach_levels: bool = True,
        gene_cap: bool = True,
        replan_window: int = 40,
        replan_members: int = 3,
        reach_share: float = 1.0,
        reach_patience: int = 100,
        polish_window: int = 40,
        **kwargs,
    ) -> None:
        pop_size = check_int(pop_size, "pop_size", minimum=2)
        crossover_rate = check_probability(crossover_rate, "crossover_rate")
        repair = check_bool(repair, "repair")
        self.gene_cap = check_bool(gene_cap, "gene_cap")
        super().__init__(
            pop_size=pop_size,
            sampling=sampling if sampling is not None else CommandSampling(),
            selection=RankAndCrowdingTournament(tournament_size),
            crossover=crossover if crossover is not None else
            CommandCrossover(prob=1.0, length_cap=2 if self.gene_cap else None),
            mutation=mutation if mutation is not None else CommandMutation(),
            survival=GoalReachabilitySurvival(niche_size=niche_size, reach_share=reach_share,
                                              levels=check_bool(reach_levels, "reach_levels")),
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
        self.replan_window = check_int(replan_window, "replan_window", minimum=0)
        self.replan_members = check_int(replan_members, "replan_members", minimum=0)
        self.replan = CommandReplan(self.replan_window) if self.replan_window else None
        self.reach_patience = check_int(reach_patience, "reach_patience", minimum=0)
        self.reach_repair = CommandReachRepair() if self.reach_patience else None
        self._closest, self._stalled = -np.inf, 0  # the best f_gr so far, generations since it last rose
        self.polish_window = check_int(polish_window, "polish_window", minimum=0)
        self._polished = False  # the polish runs once, when the run ends

    @property
    def additions(self) -> tuple[str, ...]:
        """The additions of ours switched on (:data:`~htetro_opt.algorithms.GA_ADDITIONS`' names, in its order)."""
        capped = getattr(self.mating.crossover, "length_cap", None) is not None or \
            getattr(self.mating.crossover, "max_genes", None) is not None
        on = {"repair": isinstance(self.repair, CommandRepair), "shortcut": self.shortcut,
              "reach-levels": self.survival.levels, "niching": self.survival.niche_size > 0, "gene-cap": capped,
              "replanning": self.replan is not None, "reach-repair": self.reach_repair is not None,
              "polish": self.polish_window > 0}
        return tuple(name for name in GA_ADDITIONS if on[name])

    @classmethod
    def with_additions(cls, additions, pop_size: int = 50, **kwargs) -> "HTetroGA":
        """Cheng et al. 2020's hTetro-GA with exactly ``additions`` of ours switched on (names of
        :data:`~htetro_opt.algorithms.GA_ADDITIONS`): each one off is off whatever its parameter in ``kwargs``
        says (``replan_window``, ``reach_patience``, ``polish_window``), each one on takes its parameter from
        ``kwargs`` or the default. ``with_additions(())`` is :meth:`as_published`.

        Raises
        ------
        ParameterError
            If a name is not one of the additions.
        """
        additions = check_additions(additions)
        off = {"repair": {"repair": False}, "shortcut": {"shortcut": False}, "reach-levels": {"reach_levels": False},
               "niching": {"niche_size": 0}, "gene-cap": {"gene_cap": False},
               "replanning": {"replan_window": 0}, "reach-repair": {"reach_patience": 0},
               "polish": {"polish_window": 0}}
        options = dict(kwargs)
        for name, values in off.items():
            if name not in additions:
                options.update(values)
        return cls(pop_size, **options)

    @classmethod
    def as_published(cls, pop_size: int = 50, **kwargs) -> "HTetroGA":
        """The hTetro-GA with none of our additions: no repair, no shortcut, two sections in the sort (no
        reach levels, no niching), no gene cap, no re-planning, no reach repair, no balanced polish.

        A keyword given here switches one back on (e.g. ``replan_window=40``).
        """
        options = dict(repair=False, shortcut=False, reach_levels=False, niche_size=0, gene_cap=False, replan_window=0,
                       reach_patience=0, polish_window=0)
        options.update(kwargs)
        return cls(pop_size, **options)

    # --- pymoo's loop, on arrays ----------------------------------------------------------------
    def next(self) -> None:
        """One generation: offspring, evaluation and survival on arrays, then pymoo's bookkeeping
        (``advance``: the optimum, the termination, the display and the callback)."""
        if not self.is_initialized:
            return super().next()  # the initial population: pymoo's sampling, repair and evaluator
        offspring = self._offspring()
        if offspring is not None:
            self._merge(offspring)
        self.advance()

    def _initialize_advance(self, infills=None, **kwargs):
        members = _Members.of(infills)
        if self.trim_reached:
            members.trim_reached()
        members = members.take(first_keys(members.keys()))
        self._survive(members, len(members))

    def _infill(self):
        """The offspring of a generation as a pymoo ``Population``, already evaluated (pymoo's
        ask-and-tell interface); None when every one duplicates a member or another offspring."""
        offspring = self._offspring()
        if offspring is None:
            return None
        return Population([offspring.individual(i, self.n_iter) for i in range(len(offspring))])

    def _advance(self, infills=None, **kwargs):
        if infills is not None:  # None: nothing new this generation, or ``next`` has already merged it
            self._merge(_Members.of(infills))

    def _offspring(self) -> _Members | None:
        """A generation's new chromosomes, evaluated: both offspring sets and the re-planned members,
        less the duplicates of the members and of each other (None when nothing is left)."""
        # Each operator runs as its pymoo ``do()`` would (batch.py), so that a user's operator (and
        # its ``prob``) behaves here as under any pymoo algorithm.
        problem, rng, mating, parents = self.problem, self.random_state, self.mating, self._members
        X = parents.X
        conservative = apply_mutation(self.removal, problem, X, random_state=rng)
        conservative = apply_mutation(self.rearrangement, problem, conservative, random_state=rng)

        crossing = rng.random(len(X)) < self.crossover_rate
        n_cross = int(crossing.sum())
        non_conservative = [X[i] for i in np.flatnonzero(~crossing)]
        if n_cross:
            matings = mating.selection.select(self._rank, self._crowding, (n_cross + 1) // 2, 2, random_state=rng)
            children = apply_crossover(mating.crossover, problem, X, matings, random_state=rng)
            non_conservative = children[:n_cross] + non_conservative
        non_conservative = apply_mutation(mating.mutation, problem, non_conservative, random_state=rng)

        # One simulation repairs the offspring, finds the loops the shortcut cuts and scores them.
        repair = rng if isinstance(self.repair, CommandRepair) else None
        off, outcomes = repair_shortcut_evaluate(problem, conservative + non_conservative, repair=repair,
                                                 shortcut=len(conservative) if self.shortcut else 0)
        n_varied = len(off)
        if self.replan is not None:
            members = self._replan_members(rng)
            if len(members):
                off = off + apply_mutation(self.replan, problem, [X[i] for i in members], random_state=rng)
        stuck = self._stuck()
        if stuck is not None:
            off = off + apply_mutation(self.reach_repair, problem, [X[stuck]], random_state=rng)
        keys = [chromosome_key(x) for x in off]
        keep = first_keys(keys, set(parents.keys()))
        if not len(keep):
            return None  # nothing new this generation: it counts as one without improvement
        self.evaluator.n_eval += len(keep)
        new = _Members(off[:n_varied], outcomes["F"], outcomes, keys=keys[:n_varied]).take(keep[keep < n_varied])
        replanned = keep[keep >= n_varied]
        if len(replanned):  # a few a generation (most re-planned members are unchanged, and dropped above)
            X_replanned = [off[i] for i in replanned]
            outcomes = problem.outcomes(problem.simulate(X_replanned))
            new = new + _Members(X_replanned, outcomes["F"], outcomes, keys=[keys[i] for i in replanned])
        return new

    def _stuck(self) -> int | None:
        """The row to reach-repair this generation, if the search has stalled without reaching: the
        member nearest to the goal (largest f_gr, then fastest, the first of equals)."""
        members = self._members
        if self.reach_repair is None or members.reached.any():
            return None
        closest = float(-members.F[:, 0].min())  # F = −fitness
        if closest > self._closest + 1e-12:
            self._closest, self._stalled = closest, 0
            return None
        self._stalled += 1
        if self._stalled < self.reach_patience:
            return None
        self._stalled = 0  # if the repair fails, the next try waits another reach_patience generations
        return int(np.lexsort((members.time, members.F[:, 0]))[0])

    def _replan_members(self, rng: np.random.Generator) -> np.ndarray:
        """Rows to re-plan: the fastest goal-reaching member (the first of equals) and
        ``replan_members`` others drawn without replacement among the reaching ones."""
        return replan_rows(self._members.reached, self._members.time, self.replan_members, random_state=rng)

    def _merge(self, offspring: _Members) -> None:
        """The goal-reachability sort of the members and the (trimmed) offspring."""
        if self.trim_reached:
            offspring.trim_reached()
        merged = self._members + offspring
        merged = merged.take(first_keys(merged.keys()))
        self._survive(merged, self.pop_size)

    def _survive(self, members: _Members, n_survive: int) -> None:
        rows, self._rank, self._crowding = self.survival.sort(members.F, members.end, n_survive,
                                                              random_state=self.random_state)
        self._members = members = members.take(rows)
        for i in [i for i, ind in enumerate(members.individuals) if ind is None]:
            members.individual(i, self.n_iter)  # new survivors only: the others keep theirs
        for ind, rank, crowding in zip(members.individuals, self._rank, self._crowding):
            ind.data["rank"], ind.data["crowding"] = rank, crowding  # pymoo's Individual.set, less its lookups
        self.pop = Population(members.individuals)

    def _set_optimum(self):
        self.opt = self.pop[self._rank == 0]

    # --- the end of the run ------------------------------------------------------------------------
    def _finalize(self):
        """pymoo's hook at the end of the run (``advance`` calls it once the termination has
        terminated, before ``result()``): the balanced polish."""
        super()._finalize()
        if self.polish_window and self.is_initialized and not self._polished:
            self._polished = True
            self._polish()

    def _polish(self) -> None:
        """The largest-sum leading-front member (the pick of
        :func:`~htetro_opt.algorithms.select_solutions`) polished, and merged when its sum is larger.

        The polished member sums more than every leading-front member, so none of the population
        dominates it and the sort ranks it in the leading front. Only when that front alone outnumbers
        the population can the crowding cut drop it: then it takes the place of the most crowded
        survivor, and the population is sorted again (no cut: ranks and crowding are its own).
        """
        members = self._members
        if not members.reached.any():
            return
        row = select_solutions(members.F)["multi_objective"]
        deadline = getattr(self.termination, "deadline", None)  # a run's time limit bounds the polish too
        if deadline is not None and _time.perf_counter() >= deadline:
            self.data["time_limited"] = True  # no time left: the run ends unpolished
            return
        polished = polish_sum(self.problem, members.X[row], window=self.polish_window, deadline=deadline)
        if deadline is not None and _time.perf_counter() >= deadline:
            self.data["time_limited"] = True  # cut inside the polish: its result depends on the machine's speed
        if polished is members.X[row]:
            return  # nothing improved
        outcomes = self.problem.outcomes(self.problem.simulate([polished]))
        new = _Members([polished], outcomes["F"], outcomes)
        if first_keys(new.keys(), set(members.keys())).size == 0:
            return  # already a member (cannot happen with a larger sum; the population stays as it is)
        self.evaluator.n_eval += 1
        self._survive(members + new, self.pop_size)
        if not any(x is polished for x in self._members.X):
            survivors = self._members
            most_crowded = int(np.argmin(np.where(self._rank == 0, self._crowding, np.inf)))
            self._survive(survivors.take(np.delete(np.arange(len(survivors)), most_crowded)) + new, self.pop_size)
        self._set_optimum()
