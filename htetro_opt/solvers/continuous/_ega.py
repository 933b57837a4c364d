"""Nazarahari et al. 2019's enhanced GA as a planning method: APF initial paths, the EGA (or pymoo's
multi-objective algorithms) over path bases, one :class:`ContinuousPlan`.

One ``seed`` drives a whole run (None: fresh entropy; an int or a numpy Generator: reproducible): it
breaks the APF's ties and seeds pymoo, whose ``random_state`` every operator draws from.
"""

from __future__ import annotations

import dataclasses
import time

import numpy as np

from htetro_opt._validation import as_rng, check_bool, check_int, derive_seed
from htetro_opt.errors import ParameterError
from htetro_opt.model._lattice import check_grid
from htetro_opt.problems.names import DEFAULT_PATH_WEIGHTS
from htetro_opt.problems.path_bases import PathBasesProblem, check_path_weights
from htetro_opt.solvers.continuous._result import ContinuousPlan, check_scenario, finish_plan
from htetro_opt.solvers.continuous._spec import SPEC

__all__ = ["plan_ega", "plan_ega_paper", "plan_moea", "plan_nsga2", "MOEA_ALGORITHMS"]

_EGA, _MOEA = SPEC.defaults("ega"), SPEC.defaults("nsga2")  # the task's defaults, declared once in its spec
_PAPER = SPEC.defaults("ega-paper")

MOEA_ALGORITHMS = ("nsga2", "nsga3", "smsemoa", "agemoea")
"""pymoo's algorithms :func:`plan_moea` runs over path bases."""


def _initial(scenario, *, grid: float, pop_size: int, finer: bool, rng, refine: bool = True) -> list:
    """Each robot's APF paths (an empty list for a robot whose goal is unreachable)."""
    from htetro_opt.operators.path_bases.sampling import initial_paths

    return [initial_paths(scenario.geometry, s, g, pop_size, grid=grid, finer=finer, seed=rng, refine=refine)
            for s, g in zip(scenario.starts, scenario.goals)]


def _reachable(scenario, initial: list):
    """The scenario of the robots whose goals the APF reaches, and their indices."""
    rows = [i for i, paths in enumerate(initial) if paths]
    if len(rows) == scenario.n_robots:
        return scenario, rows
    return dataclasses.replace(scenario, starts=scenario.starts[rows], goals=scenario.goals[rows]), rows


def _as_path(line: np.ndarray) -> np.ndarray:
    return line[:1].copy() if (line == line[0]).all() else line


def _best(problem: PathBasesProblem, xs: list):
    """The member to report: obstacle-free paths first, then fewest conflicts, then the cost."""
    terms = problem.measure(xs)
    F, _ = problem.objectives_of(terms)
    order = np.lexsort((F[:, 0], terms["conflicts"], terms["bad"].sum(axis=1)))
    return xs[int(order[0])]


def _run_ga(scenario, *, variant: str, additions: tuple, path: str, weights, safety: str, grid: float,
            pop_size: int, max_gen: int, rng) -> tuple[list, list, dict]:
    """One EGA run: (per-robot polylines or None, per-robot PBs or None, info)."""
    from pymoo.optimize import minimize

    from htetro_opt.algorithms.enhanced_ga import EnhancedGA
    from htetro_opt.operators.path_bases import PathBasesSampling

    initial = _initial(scenario, grid=grid, pop_size=pop_size, finer="finer-apf" in additions, rng=rng,
                       refine="apf-refinement" in additions)
    sub, rows = _reachable(scenario, initial)
    lines, pbs = [None] * scenario.n_robots, [None] * scenario.n_robots
    info = {"algorithm": variant, "weights": list(weights), "path": path, "safety": safety, "grid": grid,
            "pop_size": pop_size, "max_gen": max_gen}
    if not rows:
        return lines, pbs, {**info, "history": [], "terms": None}
    problem = PathBasesProblem(sub, path=path, weights=weights, safety=safety, grid=grid)
    sampling = PathBasesSampling([initial[i] for i in rows])
    algorithm = EnhancedGA(pop_size, sampling=sampling, additions=additions)
    res = minimize(problem, algorithm, ("n_gen", max_gen + 1), seed=derive_seed(rng))
    best = _best(problem, [ind.X[0] for ind in res.algorithm.pop])
    for k, row in enumerate(rows):
        part = problem.robots(best)[k]
        lines[row] = _as_path(problem.polyline(part, k))
        pbs[row] = part
    return lines, pbs, {**info, "history": list(res.algorithm.history), "terms": problem.measure([best])}


def _check_common(scenario, path, safety, grid, pop_size, max_gen):
    scenario = check_scenario(scenario)
    grid = check_grid(grid, scenario.geometry)
    pop_size = check_int(pop_size, "pop_size", minimum=2)
    max_gen = check_int(max_gen, "max_gen", minimum=0)
    PathBasesProblem(scenario, path=path, safety=safety, grid=grid)  # validates path and safety
    return scenario, grid, pop_size, max_gen


def _plan_weighted(scenario, *, variant, additions, path, weights, normalise, safety, grid, pop_size, max_gen, seed):
    began = time.perf_counter()
    scenario, grid, pop_size, max_gen = _check_common(scenario, path, safety, grid, pop_size, max_gen)
    additions = SPEC.options["additions"].check(additions, "additions")
    normalise = check_bool(normalise, "normalise")
    if normalise and weights is not None:
        raise ParameterError("give weights or normalise=True, not both")
    weights = check_path_weights(DEFAULT_PATH_WEIGHTS if weights is None else weights)
    rng = as_rng(seed)
    extra = {}
    if normalise:
        # §5.3: one run per term, then W_S = L*/S*, W_R = L*/c_R* (c_R = 1 / safety)
        optima, counts = [], []
        for term, name in enumerate(("length", "smoothness", "safety")):
            single = tuple(float(term == k) for k in range(3))
            _, single_pbs, single_info = _run_ga(scenario, variant=variant, additions=additions, path=path,
                                                 weights=single, safety=safety, grid=grid, pop_size=pop_size,
                                                 max_gen=max_gen, rng=rng)
            terms = single_info["terms"]
            counts.append(sum(len(p) for p in single_pbs if p is not None))
            if terms is None:
                optima.append(float("nan"))
            elif term < 2:
                optima.append(float(terms[name].sum()))
            else:
                # a best path without clearance has no finite c_R*: its term cannot be normalised
                clear = terms["safety"]
                optima.append(float((1.0 / clear).sum()) if (clear > 0).all() else float("inf"))
        best_length, best_smoothness, best_safety_cost = optima
        weights = (1.0, best_length / best_smoothness if best_smoothness > 0 else 0.0,
                   best_length / best_safety_cost if np.isfinite(best_safety_cost) and best_safety_cost > 0 else 0.0)
        extra["normalised_from"] = {"length": best_length, "smoothness_deg": best_smoothness,
                                    "safety_cost": best_safety_cost, "path_bases": counts}
    lines, pbs, info = _run_ga(scenario, variant=variant, additions=additions, path=path, weights=weights,
                               safety=safety, grid=grid, pop_size=pop_size, max_gen=max_gen, rng=rng)
    history = info.pop("history")
    info.pop("terms")
    info.update(extra, path_bases=[None if p is None else p.tolist() for p in pbs], additions=list(additions))
    # a spline through the PBs may cut a corner in every member: reported as infeasible, not raised
    return finish_plan(scenario, lines, method=variant, began=began, history=history, info=info,
                       require_feasible=path == "linear")


def plan_ega(scenario, *, path: str = _EGA["path"], weights=None, normalise: bool = _EGA["normalise"],
             safety: str = _EGA["safety"], grid: float = _EGA["grid"], pop_size: int = _EGA["pop_size"],
             max_gen: int = _EGA["max_gen"], seed=_EGA["seed"], additions=_EGA["additions"]) -> ContinuousPlan:
    """Every robot's path by Nazarahari et al. 2019's enhanced GA with our additions (by default all of
    :data:`~htetro_opt.algorithms.EGA_ADDITIONS`: deletion of every child, repeated deletion passes,
    the straight segment first, duplicate children dropped, taut refinement, a finer APF for half the
    initial paths, the APF's lattice refined where it does not connect; see :class:`~htetro_opt.algorithms.EnhancedGA`), several robots planned jointly
    (§4.5).

    Parameters
    ----------
    scenario : ContinuousScenario
    path : {"linear", "spline"}, keyword-only
    weights : three floats, keyword-only
        (W_L, W_S, W_R) of eq. 6; default (1, 0, 0).
    normalise : bool, keyword-only
        §5.3: three single-term runs give L*, S* and c_R* (c_R = 1 / safety), then a run with
        W = (1, L*/S*, L*/c_R*) (a zero S* gives W_S = 0; a safety-only best path without clearance,
        c_R* = ∞, gives W_R = 0). Not with ``weights``. With ``safety="paper"`` the terms need not
        come out balanced: eq. 5's R grows with the number of PBs, and the safety-only run keeps
        more of them than a run that also weighs length (measured on ``ega04_corridor1``, 2 seeds:
        27.5 PBs against 8.0 on average, largest / smallest weighted term 3.42; as published
        (``ega-paper``) 14.5 against 7.0, and 2.19; benchmarks/results/nazarahari2019).
    safety : {"paper", "min"}, keyword-only
        Eq. 5's R over the PBs, or the smallest clearance along the path.
    grid : float, keyword-only
        d, the APF's lattice and the mutations' step (1).
    pop_size, max_gen : int, keyword-only
        PS and IS (10 and 20, as in Table 2).
    seed : None, int or numpy Generator, keyword-only
    additions : collection of str, keyword-only
        Our additions switched on, exactly (names of :data:`~htetro_opt.algorithms.EGA_ADDITIONS`,
        or ``"all"``, ``"none"``, ``"a,b"``); the plan's ``additions`` lists them.

    Returns
    -------
    ContinuousPlan
        ``history``: the best cost per generation (the initial population first); ``additions``: the
        additions it ran with; ``info``:
        ``algorithm, weights, path, safety, grid, pop_size, max_gen, path_bases`` (per robot), and
        ``normalised_from`` with ``normalise``: ``length``, ``smoothness_deg``, ``safety_cost`` (the
        single-term optima L*, S*, c_R*) and ``path_bases`` (the PBs of the three runs' best
        paths). A robot whose goal the APF cannot reach (at d; with ``apf-refinement`` even at d/8)
        is not reached. With
        ``path="spline"`` a path may come out infeasible (every member's spline cutting a corner):
        ``feasible`` says so.

    Raises
    ------
    ParameterError
        On a bad option (see :class:`~htetro_opt.problems.PathBasesProblem`), an unknown addition, or
        both ``weights`` and ``normalise``.

    Examples
    --------
    >>> from htetro_opt.scenarios import load_scenario
    >>> plan = plan_ega(load_scenario("ega07_slits1"), seed=1)
    >>> plan.reached, round(plan.length, 2), len(plan.additions)  # the exact optimum is 64.43
    (True, 64.43, 7)
    """
    return _plan_weighted(scenario, variant="ega", additions=additions, path=path, weights=weights,
                          normalise=normalise, safety=safety, grid=grid, pop_size=pop_size, max_gen=max_gen, seed=seed)


def plan_ega_paper(scenario, *, path: str = _PAPER["path"], weights=None, normalise: bool = _PAPER["normalise"],
                   safety: str = _PAPER["safety"], grid: float = _PAPER["grid"], pop_size: int = _PAPER["pop_size"],
                   max_gen: int = _PAPER["max_gen"], seed=_PAPER["seed"], additions=_PAPER["additions"]) -> ContinuousPlan:
    """:func:`plan_ega` with the EGA as published (:meth:`~htetro_opt.algorithms.EnhancedGA.as_published`,
    ``additions=()`` by default): the APF at step d only; each generation the deletion of one roulette
    pick, its PBs assessed once each, left to right, as one more child; every child kept, copies too; no
    taut refinement. ``path="spline"`` joins the PBs by a cubic spline (Fig. 5b); its objectives are
    measured on the spline sampled into short segments (§4.4). ``additions`` switches ours on singly.

    Examples
    --------
    >>> from htetro_opt.scenarios import load_scenario
    >>> plan = plan_ega_paper(load_scenario("ega07_slits1"), seed=1)
    >>> plan.reached, plan.additions
    (True, ())
    """
    return _plan_weighted(scenario, variant="ega-paper", additions=additions, path=path, weights=weights,
                          normalise=normalise, safety=safety, grid=grid, pop_size=pop_size, max_gen=max_gen,
                          seed=seed)


def plan_moea(scenario, *, algorithm: str = "nsga2", path: str = _MOEA["path"], safety: str = _MOEA["safety"],
              grid: float = _MOEA["grid"], pop_size: int = _MOEA["pop_size"], max_gen: int = _MOEA["max_gen"],
              seed=_MOEA["seed"]) -> ContinuousPlan:
    """A front of paths minimising (L, S, −safety) by one of pymoo's multi-objective algorithms over
    path bases (:func:`~htetro_opt.algorithms.make_path_algorithm`: APF initial paths, the EGA's
    crossovers and mutations, deletion as the repair, where no objective may rise).

    Returns
    -------
    ContinuousPlan
        The paths of the front's shortest member; ``info["front"]``: the feasible members, distinct
        in their objectives, that no other member of any population or offspring of the run
        dominates (sorted by length), ``{"objectives": {"length", "smoothness_deg", "safety"}, "paths"}``.
        A robot whose goal the APF cannot reach is not reached.

    Raises
    ------
    ParameterError
        On an unknown algorithm or a bad option.

    Examples
    --------
    >>> from htetro_opt.scenarios import load_scenario
    >>> plan = plan_moea(load_scenario("ega04_corridor1"), seed=0)
    >>> plan.reached, len(plan.info["front"]) >= 1
    (True, True)
    """
    from pymoo.core.population import Population
    from pymoo.optimize import minimize

    from htetro_opt.algorithms.enhanced_ga import make_path_algorithm
    from htetro_opt.operators.path_bases import PathBasesSampling

    began = time.perf_counter()
    if algorithm not in MOEA_ALGORITHMS:
        raise ParameterError(f"unknown algorithm {algorithm!r}: expected one of {', '.join(MOEA_ALGORITHMS)}")
    scenario, grid, pop_size, max_gen = _check_common(scenario, path, safety, grid, pop_size, max_gen)
    rng = as_rng(seed)
    initial = _initial(scenario, grid=grid, pop_size=pop_size, finer=False, rng=rng)
    sub, rows = _reachable(scenario, initial)
    lines = [None] * scenario.n_robots
    info = {"algorithm": algorithm, "path": path, "safety": safety, "grid": grid, "pop_size": pop_size,
            "max_gen": max_gen, "front": []}
    history = []
    if rows:
        problem = PathBasesProblem(sub, path=path, safety=safety, objectives="separate", grid=grid)
        moea = make_path_algorithm(algorithm, pop_size, sampling=PathBasesSampling([initial[i] for i in rows]))
        held = []  # every population and offspring the run evaluated: a member crowded out of the
        # last population may still be non-dominated among all of them (PS 10 keeps few)

        def record(alg):
            history.append(float(np.min(alg.pop.get("F")[:, 0])))
            held.extend(p for p in (alg.pop, alg.off) if p is not None and len(p))

        res = minimize(problem, moea, ("n_gen", max_gen + 1), seed=derive_seed(rng), callback=record)
        front = _front(problem, Population.merge(*held))
        best = front[0][1] if front else _best(problem, [ind.X[0] for ind in res.algorithm.pop])
        for k, row in enumerate(rows):
            lines[row] = _as_path(problem.polyline(problem.robots(best)[k], k))
        for F, x in front:
            paths = [None] * scenario.n_robots
            for k, row in enumerate(rows):
                paths[row] = _as_path(problem.polyline(problem.robots(x)[k], k)).tolist()
            info["front"].append({"objectives": {"length": float(F[0]), "smoothness_deg": float(F[1]),
                                                 "safety": float(-F[2])}, "paths": paths})
    return finish_plan(scenario, lines, method=algorithm, began=began, history=history, info=info,
                       require_feasible=path == "linear")


def _front(problem: PathBasesProblem, pop) -> list:
    """The feasible non-dominated members, distinct in F, sorted by length."""
    from pymoo.util.nds.non_dominated_sorting import NonDominatedSorting

    F, G = pop.get("F", "G")
    feasible = np.flatnonzero(G[:, 0] <= 0)
    if not len(feasible):
        return []
    first = feasible[NonDominatedSorting().do(F[feasible], only_non_dominated_front=True)]
    _, unique = np.unique(F[first].round(12), axis=0, return_index=True)
    first = first[unique]
    first = first[np.argsort(F[first, 0], kind="stable")]
    return [(F[i], pop[i].X[0]) for i in first]


def plan_nsga2(scenario, *, path: str = _MOEA["path"], safety: str = _MOEA["safety"], grid: float = _MOEA["grid"],
               pop_size: int = _MOEA["pop_size"], max_gen: int = _MOEA["max_gen"], seed=_MOEA["seed"]) -> ContinuousPlan:
    """:func:`plan_moea` with pymoo's NSGA-II."""
    return plan_moea(scenario, algorithm="nsga2", path=path, safety=safety, grid=grid, pop_size=pop_size,
                     max_gen=max_gen, seed=seed)
