"""Seed 000's planner: a command-chromosome GA per roadmap leg (the paper's configuration loop).

:func:`plan_ga` runs one optimisation per leg of the roadmap, each starting where (and when, for
moving obstacles) the previous leg's selected solution ended. The algorithm is the paper's
hTetro-GA by default, or one of pymoo's own (NSGA-II, NSGA-III, SMS-EMOA, AGE-MOEA) with the same
problem and operators. From each leg's final population it selects, as the paper does, the
leading-front individual with the largest sum of the four fitnesses (the "multi-objective based
solution", which the next leg continues from) and the best-f_t, best-f_sm and best-f_sf ones.
"""

from __future__ import annotations

import time as _time
from dataclasses import dataclass, field
from typing import Mapping, Sequence

import numpy as np
from pymoo.core.callback import Callback
from pymoo.optimize import minimize

from htetro_opt.errors import ParameterError, PlanningError
from htetro_opt.model.commands import COMMANDS, SEED000_COMMANDS, Timing
from htetro_opt.model.robot import Pose
from htetro_opt.model.simulate import Simulator
from htetro_opt.model.workspace import Workspace
from htetro_opt.operators import (
    CommandCrossover,
    CommandDuplicateElimination,
    CommandMutation,
    CommandRepair,
    CommandSampling,
)
from htetro_opt.problems.command_path import FITNESS_NAMES, CommandPathProblem
from htetro_opt.solvers.exact import Plan
from htetro_opt.solvers.htetro_ga import HTetroGA
from htetro_opt.solvers.termination import FrontConvergence, leading_front

__all__ = [
    "GA_ALGORITHMS",
    "SELECTIONS",
    "FrontMember",
    "GAPlan",
    "LegResult",
    "ConvergenceRecorder",
    "make_algorithm",
    "plan_ga",
    "select_solutions",
]

GA_ALGORITHMS = ("htetro", "htetro-paper", "nsga2", "nsga3", "smsemoa", "agemoea")
"""Algorithm names :func:`make_algorithm` knows: the hTetro-GA with our additions, as published, and
four of pymoo's."""

SELECTIONS = ("multi_objective", "time", "smoothness", "safety")
"""The paper's four output solutions: largest fitness sum in F0, then best f_t, f_sm, f_sf."""


def select_solutions(F: np.ndarray) -> dict[str, int]:
    """Indices of the paper's four output solutions among a population's objective values.

    Parameters
    ----------
    F : ndarray, shape (n, 4)
        Objectives ``(−f_gr, −f_t, −f_sm, −f_sf)``.

    Returns
    -------
    dict
        ``{"multi_objective", "time", "smoothness", "safety"}`` → row index, all taken from the
        leading front (the goal-reaching individuals' non-dominated set, or everyone's when none
        reaches). Ties go to the shorter time, then the lower index.

    Examples
    --------
    >>> F = -np.array([[1.0, 0.6, 0.5, 0.2], [1.0, 0.5, 0.9, 0.3], [0.5, 0.9, 0.9, 0.9]])
    >>> select_solutions(F)
    {'multi_objective': 1, 'time': 0, 'smoothness': 1, 'safety': 1}
    """
    F = np.asarray(F, dtype=float)
    front = leading_front(F)
    if len(front) == 0:
        raise PlanningError("cannot select solutions from an empty population")
    fitness = -F[front]

    def best(score: np.ndarray) -> int:
        order = np.lexsort((front, -fitness[:, 1], -score))  # score desc, f_t desc, index asc
        return int(front[order[0]])

    return {
        "multi_objective": best(fitness.sum(axis=1)),
        "time": best(fitness[:, 1]),
        "smoothness": best(fitness[:, 2]),
        "safety": best(fitness[:, 3]),
    }


@dataclass(frozen=True, eq=False)  # holds arrays: identity equality, hashable
class FrontMember:
    """One individual: its executed commands (global ids), fitnesses, time and the poses it visits
    ((x, y, state, heading) rows, its leg's start first)."""

    commands: np.ndarray
    fitness: np.ndarray  # (f_gr, f_t, f_sm, f_sf)
    time: float
    reached: bool
    poses: np.ndarray

    @property
    def tokens(self) -> list[str]:
        return [COMMANDS[int(c)].token for c in self.commands]

    def as_dict(self) -> dict:
        return {
            "fitness": {name: float(v) for name, v in zip(FITNESS_NAMES, self.fitness)},
            "time": float(self.time),
            "reached": bool(self.reached),
            "commands": self.tokens,
        }


@dataclass(frozen=True, eq=False)
class LegResult:
    """One leg of the configuration loop: its final leading front, selections and convergence record.

    ``reach_generation`` is the first generation (1 = the initial population) holding an individual
    that reaches the leg's goal, None if none ever did; ``history`` holds, per generation, the four
    fitnesses of that generation's multi-objective solution (the paper's Fig. 10).
    """

    start: Pose
    goal: Pose
    t0: int
    reached: bool
    front: tuple[FrontMember, ...]
    selected: Mapping[str, FrontMember]
    reach_generation: int | None
    reach_time_s: float | None
    generations: int
    converged: bool
    runtime_s: float
    history: np.ndarray


@dataclass(frozen=True, eq=False)
class GAPlan(Plan):
    """A :class:`~htetro_opt.solvers.Plan` (the chain of each leg's multi-objective solution) plus
    every leg's :class:`LegResult`."""

    legs: tuple[LegResult, ...] = field(default=())

    @property
    def reach_generation(self) -> int | None:
        """The largest first-reach generation over the legs (None if some leg never reached)."""
        gens = [leg.reach_generation for leg in self.legs]
        return None if not gens or None in gens else max(gens)


class ConvergenceRecorder(Callback):
    """Records, per generation, whether the goal has been reached and the multi-objective solution's
    fitnesses. Works under any pymoo algorithm."""

    def __init__(self, began: float | None = None) -> None:
        super().__init__()
        self.began = _time.perf_counter() if began is None else began
        self.reach_generation: int | None = None
        self.reach_time_s: float | None = None
        self.history: list[np.ndarray] = []

    def notify(self, algorithm) -> None:
        F = algorithm.pop.get("F")
        if self.reach_generation is None and (F[:, 0] == -1.0).any():
            self.reach_generation = int(algorithm.n_gen)
            self.reach_time_s = _time.perf_counter() - self.began
        self.history.append(-F[select_solutions(F)["multi_objective"]])


def make_algorithm(
    name: str = "htetro",
    pop_size: int = 50,
    *,
    sampling_weights: Mapping[str, float] | None = None,
    crossover_rate: float = 0.5,
):
    """A pymoo algorithm over command chromosomes.

    Parameters
    ----------
    name : {"htetro", "htetro-paper", "nsga2", "nsga3", "smsemoa", "agemoea"}
        ``"htetro"`` is :class:`HTetroGA` with our repair, shortcut and niching, ``"htetro-paper"``
        :meth:`HTetroGA.as_published`; the others are pymoo's algorithms with the command sampling,
        single-point crossover (rate ``crossover_rate``), mutation, duplicate elimination and the
        repair (NSGA-III with Das–Dennis reference directions, about ``pop_size`` of them).
    pop_size : int
    sampling_weights : mapping of token to float, optional
        λ_mc of Algorithm 1.
    crossover_rate : float

    Raises
    ------
    ParameterError
        If the name is unknown, ``pop_size`` is below 2, or ``"agemoea"`` is asked for without numba
        installed (pymoo's AGE-MOEA needs it: the ``agemoea`` extra).
    """
    if name not in GA_ALGORITHMS:
        raise ParameterError(f"unknown algorithm {name!r}: expected one of {', '.join(GA_ALGORITHMS)}")
    if isinstance(pop_size, bool) or not isinstance(pop_size, (int, np.integer)) or pop_size < 2:
        raise ParameterError(f"pop_size must be an integer of at least 2, got {pop_size!r}")
    sampling = CommandSampling(sampling_weights)
    if name == "htetro":
        return HTetroGA(pop_size=pop_size, sampling=sampling, crossover_rate=crossover_rate)
    if name == "htetro-paper":
        return HTetroGA.as_published(pop_size=pop_size, sampling=sampling, crossover_rate=crossover_rate)
    operators = dict(
        sampling=sampling,
        crossover=CommandCrossover(prob=crossover_rate),
        mutation=CommandMutation(),
        eliminate_duplicates=CommandDuplicateElimination(),
        repair=CommandRepair(),
    )
    if name == "nsga2":
        from pymoo.algorithms.moo.nsga2 import NSGA2

        return NSGA2(pop_size=pop_size, **operators)
    if name == "nsga3":
        from pymoo.algorithms.moo.nsga3 import NSGA3
        from pymoo.util.ref_dirs import get_reference_directions

        partitions = 1
        while _n_directions(4, partitions + 1) <= pop_size:
            partitions += 1
        ref_dirs = get_reference_directions("das-dennis", 4, n_partitions=partitions)
        return NSGA3(ref_dirs=ref_dirs, pop_size=pop_size, **operators)
    if name == "smsemoa":
        from pymoo.algorithms.moo.sms import SMSEMOA

        return SMSEMOA(pop_size=pop_size, **operators)
    try:
        from pymoo.algorithms.moo.age import AGEMOEA
    except Exception as err:  # pymoo's AGE-MOEA module turns a missing numba into a bare Exception
        raise ParameterError(
            f"algorithm 'agemoea' needs numba, which pymoo's AGE-MOEA imports: pip install 'htetro-opt[agemoea]' ({err})"
        ) from err
    return AGEMOEA(pop_size=pop_size, **operators)


def _n_directions(n_obj: int, partitions: int) -> int:
    from math import comb

    return comb(partitions + n_obj - 1, n_obj - 1)


def _members(problem: CommandPathProblem, X: np.ndarray, F: np.ndarray) -> list[FrontMember]:
    """Front members of the rows of ``X`` (objectives ``F``), from one batch simulation."""
    result = problem.simulate([x[0] for x in X])
    return [FrontMember(commands=result.prefix(i), fitness=-np.asarray(F[i], dtype=float),
                        time=float(result.time[i]), reached=bool(result.reached[i]), poses=result.poses(i))
            for i in range(len(X))]


def plan_ga(
    workspace: Workspace | Simulator,
    roadmap: Sequence[Pose],
    *,
    algorithm: str = "htetro",
    pop_size: int = 50,
    max_gen: int = 1000,
    patience: int = 100,
    max_length: int = 100,
    seed: int | None = 0,
    sampling_weights: Mapping[str, float] | None = None,
    commands: Sequence[str] | None = None,
    timing: Timing | None = None,
    clearance: float = 0.0,
    verbose: bool = False,
) -> GAPlan:
    """Plan through a roadmap with a command-chromosome GA, one optimisation per leg.

    Parameters
    ----------
    workspace : Workspace or Simulator
    roadmap : sequence of Pose
        Start first, goal last, at least two configurations.
    algorithm : str, keyword-only
        One of :data:`GA_ALGORITHMS`.
    pop_size : int, keyword-only
        n_pop.
    max_gen, patience : int, keyword-only
        Termination (:class:`FrontConvergence`): at most ``max_gen`` generations per leg, or
        ``patience`` generations without improvement once the goal is reached.
    max_length : int, keyword-only
        l_p,max (the paper: 100, 200 for the spiral map).
    seed : int or None, keyword-only
        One seed for the whole run (each leg gets its own stream derived from it); the same seed
        gives the same plan. None draws a fresh one.
    sampling_weights : mapping, optional, keyword-only
        λ_mc of Algorithm 1.
    commands, timing, clearance : keyword-only
        As for :class:`~htetro_opt.model.Simulator` (commands default to seed 000's set).
    verbose : bool, keyword-only
        Print pymoo's per-generation log.

    Returns
    -------
    GAPlan
        ``reached`` is False when a leg's final population holds no individual reaching its goal; the
        plan then holds the legs before it (not the failed leg's best attempt), ``failed_leg`` says
        which leg failed, and ``legs`` ends with that leg's record.

    Raises
    ------
    PlanningError
        If the roadmap has fewer than two configurations.
    ConfigurationError
        If a configuration collides or lies outside the map.
    ParameterError
        If an option is out of range.

    Examples
    --------
    >>> ws = Workspace(np.zeros((10, 10), dtype=bool))
    >>> plan = plan_ga(ws, [Pose(2, 2, "O", 0), Pose(6, 5, "O", 0)], pop_size=20, max_gen=60,
    ...                max_length=20, seed=3)
    >>> plan.reached, plan.time
    (True, 7.0)
    """
    roadmap = [Pose.of(*p) for p in roadmap]
    if len(roadmap) < 2:
        raise PlanningError("a roadmap needs a start and a goal (at least two configurations)")
    make_algorithm(algorithm, pop_size)  # validates the name and size before any work
    began = _time.perf_counter()
    sim = workspace if isinstance(workspace, Simulator) else Simulator(
        workspace, commands=commands if commands is not None else SEED000_COMMANDS, timing=timing,
        clearance=clearance,
    )
    sim.check_pose(roadmap[0], what="start", t=0)
    for i, pose in enumerate(roadmap[1:], start=1):
        sim.check_pose(pose, what="goal" if i == len(roadmap) - 1 else f"roadmap configuration {i + 1}")
    leg_seeds = np.random.SeedSequence(seed).generate_state(len(roadmap) - 1)
    chain: list[np.ndarray] = []
    legs: list[LegResult] = []
    leg_ends: list[int] = []
    failed, start, t0 = -1, roadmap[0], 0
    for leg, goal in enumerate(roadmap[1:]):
        leg_began = _time.perf_counter()
        problem = CommandPathProblem(sim, start, goal, max_length=max_length, t0=t0)
        recorder = ConvergenceRecorder(leg_began)
        termination = FrontConvergence(max_gen=max_gen, patience=patience)
        res = minimize(problem, make_algorithm(algorithm, pop_size, sampling_weights=sampling_weights),
                       termination, seed=int(leg_seeds[leg]), callback=recorder, verbose=verbose,
                       copy_termination=False)
        X, F = res.pop.get("X"), res.pop.get("F")
        chosen = select_solutions(F)
        front_idx = leading_front(F)
        rows = np.array(list(chosen.values()), dtype=np.int64)
        selected = dict(zip(chosen, _members(problem, X[rows], F[rows])))
        reached = bool(selected["multi_objective"].reached)
        legs.append(LegResult(
            start=start, goal=goal, t0=t0, reached=reached,
            front=tuple(_members(problem, X[front_idx], F[front_idx])),
            selected=selected,
            reach_generation=recorder.reach_generation,
            reach_time_s=recorder.reach_time_s,
            generations=len(recorder.history),
            converged=termination.converged,
            runtime_s=_time.perf_counter() - leg_began,
            history=np.array(recorder.history),
        ))
        if not reached:
            failed = leg
            break
        chain.append(selected["multi_objective"].commands)
        t0 += len(chain[-1])
        leg_ends.append(t0)
        start = goal
    commands_all = np.concatenate(chain) if chain else np.empty(0, dtype=np.int64)
    check = sim.run([commands_all], roadmap[0])
    if not check.valid[0]:  # each leg re-validated from where the last ended; this cannot happen
        raise PlanningError("internal error: the GA's plan does not re-validate in the simulator")
    return GAPlan(
        commands=commands_all,
        reached=failed < 0,
        time=float(check.time[0]),
        poses=check.poses(0),
        leg_ends=tuple(leg_ends),
        failed_leg=failed,
        runtime_s=_time.perf_counter() - began,
        method=f"ga-{algorithm}",
        legs=tuple(legs),
    )
