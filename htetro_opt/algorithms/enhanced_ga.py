"""Nazarahari et al. 2019's enhanced GA (EGA, §4.3, Fig. 1) as a pymoo genetic algorithm, and pymoo's
multi-objective algorithms over the same path-base chromosomes.

The paper names its parameters after the Yarpiz MATLAB GA (crossover and mutation "probabilities"
0.35 and 0.15, "mutation rate" 0.2, population size PS, iterations IS), and we read its loop as that
GA's. Each generation, from the PS members (sorted best first):

1. n_c = 2 ⌊0.35 PS / 2 + ½⌋ children: n_c / 2 pairs of parents drawn by roulette wheel with
   P ∝ exp(−8 c / c_worst) (c the member's cost), each pair giving one child of eq. 1 and one of
   eq. 2 (:class:`~htetro_opt.operators.path_bases.PathBasesCrossover`);
2. n_m = ⌊0.15 PS + ½⌋ mutants, each of a uniformly drawn member by one of the three mutations
   (:class:`~htetro_opt.operators.path_bases.PathBasesMutation`);
3. with several robots, collision removal of every conflicted child (§4.5);
4. deletion (§4.3.4) of one member drawn by the roulette (the paper's "an individual is selected from the
   mating pool"), which is then one more child, its PBs assessed once each, left to right;
5. the members and the new children merged, sorted stably feasible first, then by G, then by F (the
   paper's "large penalty" for infeasible paths), and cut to PS.

The roulette's cost is F plus 10 (W + H) per unit of G (infeasible segments and conflicts), so that
infeasible members are rarely parents. That is :meth:`EnhancedGA.as_published` (``additions=()``).

Our additions (:data:`~htetro_opt.algorithms.EGA_ADDITIONS`), all on by default, each
switched singly by ``additions``:

- ``delete-every-child``: deletion of every child and of the initial paths, instead of step 4's one
  roulette pick;
- ``deletion-passes``: the deletion repeats its pass until one drops nothing;
- ``straight-first``: the deletion first tries the straight start → goal segment;
- ``child-dedup``: children equal to a member or to an earlier child are dropped after deletion
  (before refinement, which would only rebuild them) and again after refinement, and duplicate
  initial paths too (pymoo's duplicate elimination);
- ``taut-refinement`` (:class:`~htetro_opt.operators.path_bases.TautRefinement`) of the initial
  paths and of each generation's best child: without it the EGA stalls a few per cent above the
  optimum on mazes, short of the wall corners (refining every child found nothing more on the twelve
  maps, in up to twice the time);
- ``finer-apf``: half the initial population from the APF's lattice at step d / 2: the d = 1
  lattice misses gaps narrower than 1, and with them the shortest way through ``ega12_plankpile``;
- ``apf-refinement``: a lattice that does not join a robot's start to its goal is halved up to three
  times (the paper's APF at d finds no path then: as published the robot is not reached).

:func:`make_path_algorithm` gives pymoo's NSGA-II, NSGA-III, SMS-EMOA or AGE-MOEA with the same
sampling, crossover, mutation and duplicate elimination, deletion as their repair (the command
chromosomes' :func:`~htetro_opt.algorithms.make_algorithm` hard-wires the command operators, hence a
second factory).
"""

from __future__ import annotations

import math

import numpy as np
from pymoo.algorithms.base.genetic import GeneticAlgorithm
from pymoo.core.duplicate import NoDuplicateElimination
from pymoo.core.population import Population

from htetro_opt._spec import additions as additions_check
from htetro_opt._validation import check_int, check_probability, check_real
from htetro_opt.algorithms.factory import _pymoo_algorithm
from htetro_opt.algorithms.names import EGA_ADDITIONS
from htetro_opt.errors import ParameterError
from htetro_opt.operators.path_bases import (
    CollisionRemoval,
    PathBasesCrossover,
    PathBasesDeletion,
    PathBasesDuplicateElimination,
    PathBasesMutation,
    PathBasesSampling,
    TautRefinement,
    as_column,
    path_key,
)

__all__ = ["EnhancedGA", "make_path_algorithm", "PATH_ALGORITHMS", "feasibility_order"]

PATH_ALGORITHMS = ("ega", "ega-paper", "nsga2", "nsga3", "smsemoa", "agemoea")
"""Algorithm names :func:`make_path_algorithm` knows."""


_check_additions = additions_check(EGA_ADDITIONS)


def feasibility_order(F: np.ndarray, G: np.ndarray) -> np.ndarray:
    """Rows sorted stably: feasible (G ≤ 0) first, then by G, then by the first objective.

    Examples
    --------
    >>> feasibility_order(np.array([[3.0], [1.0], [2.0], [0.5]]), np.array([[0.0], [0.0], [0.0], [2.0]])).tolist()
    [1, 2, 0, 3]
    """
    G = np.maximum(np.asarray(G, dtype=float).reshape(len(F), -1).sum(axis=1), 0.0)
    return np.lexsort((np.asarray(F, dtype=float)[:, 0], G, G > 0))


class EnhancedGA(GeneticAlgorithm):
    """The EGA over a :class:`~htetro_opt.problems.PathBasesProblem` (weighted objective; see the
    module docstring).

    Parameters
    ----------
    pop_size : int
        PS (10 in the paper's Table 2).
    sampling, crossover, mutation : pymoo operators, optional
        Default: the APF's paths, eqs. 1 and 2, the three mutations.
    crossover_share, mutation_share : float
        0.35 and 0.15: n_c = 2 ⌊crossover_share · PS / 2 + ½⌋ children, n_m = ⌊mutation_share · PS + ½⌋ mutants.
    selection_pressure : float
        β of the roulette's P ∝ exp(−β c / c_worst) (8).
    additions : collection of str
        Our additions switched on (names of :data:`~htetro_opt.algorithms.EGA_ADDITIONS`;
        default all; ``()``: the paper's EGA). ``finer-apf`` and ``apf-refinement`` act only when
        ``sampling`` is not given (see :func:`~htetro_opt.operators.path_bases.initial_paths`).
    collision_tries : int
        Moves tried per conflicted child with several robots (§4.5; 20).

    Raises
    ------
    ParameterError
        If ``pop_size`` is below 2, a share is not in [0, 1], the pressure is negative, an addition
        is unknown, or ``collision_tries`` is negative.

    Attributes
    ----------
    additions : tuple of str
        The additions switched on, in :data:`EGA_ADDITIONS`' order.
    history : list of float
        The best member's cost after each generation (the initial population first).

    Examples
    --------
    >>> from pymoo.optimize import minimize
    >>> from htetro_opt.problems import PathBasesProblem
    >>> from htetro_opt.scenarios import load_scenario
    >>> problem = PathBasesProblem(load_scenario("ega07_slits1"))
    >>> res = minimize(problem, EnhancedGA(10), ("n_gen", 21), seed=1)
    >>> best = res.opt[0]
    >>> round(float(best.F[0]), 2), float(best.G[0])  # the exact optimum is 64.43
    (64.43, 0.0)
    """

    def __init__(self, pop_size: int = 10, *, sampling=None, crossover=None, mutation=None,
                 crossover_share: float = 0.35, mutation_share: float = 0.15, selection_pressure: float = 8.0,
                 additions=tuple(EGA_ADDITIONS), collision_tries: int = 20, **kwargs) -> None:
        pop_size = check_int(pop_size, "pop_size", minimum=2)
        self.additions = _check_additions(additions, "additions")
        on = set(self.additions)
        super().__init__(
            pop_size=pop_size,
            sampling=sampling if sampling is not None else PathBasesSampling(finer="finer-apf" in on,
                                                                             refine="apf-refinement" in on),
            crossover=crossover if crossover is not None else PathBasesCrossover(),
            mutation=mutation if mutation is not None else PathBasesMutation(),
            # the paper keeps every path, copies included (child-dedup off: pymoo's no-op elimination)
            eliminate_duplicates=PathBasesDuplicateElimination() if "child-dedup" in on else NoDuplicateElimination(),
            advance_after_initial_infill=True,
            **kwargs,
        )
        self.crossover = self.mating.crossover
        self.mutation = self.mating.mutation
        self.crossover_share = check_probability(crossover_share, "crossover_share")
        self.mutation_share = check_probability(mutation_share, "mutation_share")
        self.selection_pressure = check_real(selection_pressure, "selection_pressure", minimum=0.0)
        self.delete_children = "delete-every-child" in on
        self.refine = "taut-refinement" in on
        self.finer_apf = "finer-apf" in on
        self.dedup = "child-dedup" in on
        self.collision_tries = check_int(collision_tries, "collision_tries", minimum=0)
        self.deletion = PathBasesDeletion(passes="deletion-passes" in on, straight="straight-first" in on)
        self.refinement = TautRefinement()
        self.collision_removal = CollisionRemoval(self.collision_tries)
        self.history: list[float] = []

    @classmethod
    def as_published(cls, pop_size: int = 10, *, additions=(), **kwargs) -> EnhancedGA:
        """The EGA without our additions: deletion of one roulette pick per generation in one pass,
        every child kept, no taut refinement, the APF on the lattice of step d only. ``additions``
        switches some back on (e.g. ``("taut-refinement",)``)."""
        return cls(pop_size, additions=additions, **kwargs)

    @property
    def n_children(self) -> int:
        """n_c, always even."""
        return 2 * int(math.floor(self.crossover_share * self.pop_size / 2 + 0.5))

    @property
    def n_mutants(self) -> int:
        return int(math.floor(self.mutation_share * self.pop_size + 0.5))

    # --- pymoo's loop -----------------------------------------------------------------------------
    def _setup(self, problem, **kwargs):
        if getattr(problem, "n_obj", 1) != 1:
            raise ParameterError("the enhanced GA minimises one objective (eq. 6): build the problem with "
                                 "objectives='weighted', or use make_path_algorithm('nsga2', ...)")
        self.history = []

    def _initialize_infill(self):
        pop = super()._initialize_infill()
        if self.problem.n_robots > 1 and self.collision_tries:
            pop = self.collision_removal.do(self.problem, pop, random_state=self.random_state)
        if self.delete_children:
            pop = self.deletion.do(self.problem, pop)
        if self.refine:
            pop = self.refinement.do(self.problem, pop)
        return pop

    def _initialize_advance(self, infills=None, **kwargs):
        self._survive(infills)

    def _costs(self, pop: Population) -> np.ndarray:
        F, G = pop.get("F", "G")
        return F[:, 0] + self.problem.penalty_scale * np.maximum(G, 0).sum(axis=1)

    def _roulette(self, n: int) -> np.ndarray:
        cost = self._costs(self.pop)
        worst = cost.max()
        if worst > 0 and np.isfinite(worst):
            weights = np.exp(-self.selection_pressure * cost / worst)
        else:  # all equal (or all infinite): uniform
            weights = np.ones(len(cost))
        return self.random_state.choice(len(cost), size=n, p=weights / weights.sum())

    def _infill(self):
        problem, rng, pop = self.problem, self.random_state, self.pop
        X = [ind.X[0] for ind in pop]
        parts = []
        if self.n_children:
            matings = self._roulette(self.n_children).reshape(-1, 2)
            parts.append(self.crossover.do(problem, Population.new("X", as_column(X)), matings, random_state=rng))
        if self.n_mutants:
            picks = rng.integers(len(X), size=self.n_mutants)
            parts.append(self.mutation.do(problem, Population.new("X", as_column([X[i] for i in picks])),
                                          random_state=rng))
        off = Population.merge(*parts) if parts else Population.empty()
        if problem.n_robots > 1 and self.collision_tries and len(off):
            off = self.collision_removal.do(problem, off, random_state=rng)
        if self.delete_children and len(off):
            off = self.deletion.do(problem, off)
        elif not self.delete_children:
            pick = Population.new("X", as_column([X[int(self._roulette(1)[0])]]))
            off = Population.merge(off, self.deletion.do(problem, pick))
        off = self._new(off, {path_key(x) for x in X}) if self.dedup else (off if len(off) else None)
        if self.refine and off is not None:
            G, F = problem.score(list(off.get("X")[:, 0]))
            k = int(feasibility_order(F, G)[0])
            rest = [i for i in range(len(off)) if i != k]
            off = Population.merge(off[rest], self.refinement.do(problem, off[[k]]))
            if self.dedup:
                off = self._new(off, {path_key(x) for x in X})
        return off

    @staticmethod
    def _new(off: Population, seen: set) -> Population | None:
        """The individuals of ``off`` whose chromosomes are neither in ``seen`` (updated) nor earlier."""
        if not len(off):
            return None
        keep = []
        for i, x in enumerate(off.get("X")[:, 0]):
            key = path_key(x)
            if key not in seen:
                seen.add(key)
                keep.append(i)
        return off[keep] if keep else None

    def _advance(self, infills=None, **kwargs):
        self._survive(self.pop if infills is None else Population.merge(self.pop, infills))

    def _survive(self, pop: Population) -> None:
        F, G = pop.get("F", "G")
        self.pop = pop[feasibility_order(F, G)[: self.pop_size]]
        self.history.append(float(self._costs(self.pop[:1])[0]))

    def _set_optimum(self):
        self.opt = self.pop[:1]


def make_path_algorithm(name: str = "ega", pop_size: int = 10, *, sampling=None):
    """A pymoo algorithm over path-base chromosomes, by name.

    Parameters
    ----------
    name : {"ega", "ega-paper", "nsga2", "nsga3", "smsemoa", "agemoea"}
        :class:`EnhancedGA`, :meth:`EnhancedGA.as_published`, or pymoo's algorithm with the path-base
        operators and deletion as its repair (NSGA-III with Das–Dennis directions for three
        objectives, about ``pop_size`` of them).
    pop_size : int
    sampling : pymoo Sampling, optional
        Default: the APF's paths (:class:`~htetro_opt.operators.path_bases.PathBasesSampling`; for
        ``"ega"`` half of them from the finer lattice, see :class:`EnhancedGA`).

    Raises
    ------
    ParameterError
        On an unknown name or a ``pop_size`` below 2; ``"agemoea"`` without numba.

    Examples
    --------
    >>> type(make_path_algorithm("smsemoa", 12)).__name__, make_path_algorithm("ega-paper").additions
    ('SMSEMOA', ())
    """
    if name not in PATH_ALGORITHMS:
        raise ParameterError(f"unknown algorithm {name!r}: expected one of {', '.join(PATH_ALGORITHMS)}")
    pop_size = check_int(pop_size, "pop_size", minimum=2)
    if name == "ega":
        return EnhancedGA(pop_size, sampling=sampling)
    if name == "ega-paper":
        return EnhancedGA.as_published(pop_size, sampling=sampling)
    sampling = sampling if sampling is not None else PathBasesSampling()
    operators = dict(sampling=sampling, crossover=PathBasesCrossover(), mutation=PathBasesMutation(),
                     eliminate_duplicates=PathBasesDuplicateElimination(), repair=PathBasesDeletion())
    return _pymoo_algorithm(name, pop_size, operators, n_objectives=3)
