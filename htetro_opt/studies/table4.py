"""Cheng et al. 2020's Table 4 re-run: hTetro-GA over six environments and three population sizes.

The paper (Cheng et al., IEEE Access 2020, §V–VI) runs hTetro-GA 50 times in each of six environments
with n_pop = 25, 50 and 100, l_p,max = 200 on the spiral map and 100 elsewhere, at most 1000
generations, and reports per cell of its Table 4 the mean ± standard deviation of the generation at
which some individual first reaches the goal ("reach population"), the generation at which the run
stops ("terminate population"), the wall-clock times of both, and the four fitnesses of the output
("multi-objective based") solution. :data:`PAPER_TABLE4` holds those numbers; :func:`run_study`
re-runs the experiment with :func:`~htetro_opt.solvers.grid_paths.plan_ga` on the bundled scenarios of the same
names, and also measures what the paper could not: how far each GA plan is from the exact
minimum-time plan (:func:`~htetro_opt.solvers.grid_paths.plan_exact`, same start, goal and obstacle clock).

Our environments are reconstructions (the paper's figures are not in our copy, see each scenario's
``source``), so the generations and times need not match the paper's; the exact optimum is the
reference that does not depend on the reconstruction.

Run from Python::

    from htetro_opt.studies import table4
    records = table4.run_study(["three_slit", "random"], [25, 50], range(3), max_gen=300, jobs=2)
    print(table4.markdown_table(table4.summarise(records)))

(``htetro-opt study table4`` runs the same grid on the study runner, :mod:`htetro_opt.studies.runner`,
with its generic summary.)
"""

from __future__ import annotations

import csv
import io
import math
import os
from collections.abc import Callable, Iterable, Mapping, Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path
from typing import Any

import numpy as np

from htetro_opt._files import atomic_path
from htetro_opt._validation import check_int
from htetro_opt.algorithms import GA_ALGORITHMS
from htetro_opt.errors import ConfigurationError, ParameterError
from htetro_opt.model.commands import SEED000_COMMANDS
from htetro_opt.model.robot import Pose
from htetro_opt.model.simulate import Simulator
from htetro_opt.scenarios import Scenario, load_scenario
from htetro_opt.solvers.grid_paths import Plan, plan_exact, plan_ga
from htetro_opt.studies.metrics import (
    format_mean_std,
    group_records,
    mean_std,
    values_of,
)

__all__ = [
    "ENVIRONMENTS",
    "MAX_LENGTH",
    "PAPER_TABLE4",
    "POP_SIZES",
    "RECORD_FIELDS",
    "TABLE4_COLUMNS",
    "TIME_FIELDS",
    "markdown_table",
    "read_csv",
    "run_study",
    "run_trial",
    "summarise",
    "write_csv",
]

ENVIRONMENTS = ("random", "spiral", "h_shape", "three_slit", "perpendicular_dynamic", "parallel_dynamic")
"""The six environments of Cheng et al. 2020's Table 4, by the names of our bundled scenarios (its row order)."""

MAX_LENGTH = {name: (200 if name == "spiral" else 100) for name in ENVIRONMENTS}
"""l_p,max per environment (paper §V-B3): 200 for the spiral map, 100 for the others."""

POP_SIZES = (25, 50, 100)
"""The population sizes n_pop of Table 4."""

TABLE4_COLUMNS = (
    "reach_generation",
    "terminate_generation",
    "reach_time_s",
    "terminate_time_s",
    "f_gr",
    "f_t",
    "f_sm",
    "f_sf",
)
"""Table 4's eight columns: reach and terminate "population" (generation), reach and terminate time
(seconds), and the output solution's f_gr, f_t, f_sm and f_sf."""


def _row(*pairs: tuple[float, float]) -> dict[str, tuple[float, float]]:
    assert len(pairs) == len(TABLE4_COLUMNS)
    return dict(zip(TABLE4_COLUMNS, pairs))


PAPER_TABLE4: dict[str, dict[int, dict[str, tuple[float, float]]]] = {
    "random": {
        25: _row((2.88, 0.49), (36.84, 8.16), (1.78, 0.19), (10.79, 4.47),
                 (1.000, 0.000), (0.556, 0.992), (0.368, 0.106), (0.283, 0.043)),
        50: _row((2.36, 0.39), (22.48, 11.04), (3.98, 0.65), (23.85, 6.92),
                 (1.000, 0.000), (0.580, 0.113), (0.389, 0.084), (0.291, 0.059)),
        100: _row((1.84, 0.27), (21.84, 5.79), (6.47, 0.87), (45.18, 16.56),
                  (1.000, 0.000), (0.633, 0.014), (0.451, 0.079), (0.305, 0.034)),
    },
    "spiral": {
        25: _row((104.52, 20.05), (119.32, 19.09), (84.68, 33.53), (94.56, 32.78),
                 (1.000, 0.000), (0.546, 0.073), (0.601, 0.111), (0.208, 0.020)),
        50: _row((54.68, 14.82), (67.68, 14.77), (91.67, 22.29), (120.32, 18.72),
                 (1.000, 0.000), (0.593, 0.083), (0.574, 0.116), (0.194, 0.015)),
        100: _row((43.24, 8.10), (57.68, 12.02), (141.15, 13.10), (154.23, 16.18),
                  (1.000, 0.000), (0.588, 0.092), (0.587, 0.111), (0.223, 0.023)),
    },
    "h_shape": {
        25: _row((12.65, 4.67), (34.80, 7.35), (6.13, 1.75), (14.36, 3.28),
                 (1.000, 0.000), (0.496, 0.046), (0.463, 0.093), (0.326, 0.089)),
        50: _row((6.05, 1.17), (33.45, 10.74), (6.62, 1.18), (23.20, 6.25),
                 (1.000, 0.000), (0.493, 0.075), (0.481, 0.106), (0.328, 0.068)),
        100: _row((5.61, 0.84), (26.05, 5.91), (9.73, 1.89), (34.92, 7.65),
                  (1.000, 0.000), (0.513, 0.061), (0.498, 0.067), (0.331, 0.092)),
    },
    "three_slit": {
        25: _row((374.02, 35.17), (393.80, 34.10), (55.57, 11.14), (58.49, 1.07),
                 (1.000, 0.000), (0.444, 0.027), (0.450, 0.056), (0.234, 0.020)),
        50: _row((210.60, 27.56), (252.42, 35.43), (56.44, 6.32), (66.14, 8.52),
                 (1.000, 0.000), (0.442, 0.031), (0.462, 0.070), (0.242, 0.012)),
        100: _row((181.20, 20.73), (201.6, 18.73), (90.67, 23.77), (100.30, 24.74),
                  (1.000, 0.000), (0.480, 0.024), (0.472, 0.057), (0.247, 0.010)),
    },
    "perpendicular_dynamic": {
        25: _row((1.42, 0.49), (24.6, 4.85), (23.08, 3.59), (28.75, 3.50),
                 (1.000, 0.000), (0.704, 0.034), (0.441, 0.096), (0.387, 0.100)),
        50: _row((1.12, 0.324), (19.20, 3.09), (26.93, 4.64), (33.05, 5.45),
                 (1.000, 0.000), (0.726, 0.110), (0.459, 0.150), (0.604, 0.266)),
        100: _row((1.04, 0.20), (19.04, 2.95), (51.50, 12.52), (64.32, 11.72),
                  (1.000, 0.000), (0.710, 0.131), (0.460, 0.153), (0.610, 0.246)),
    },
    "parallel_dynamic": {
        25: _row((10.24, 4.08), (26.6, 4.72), (6.59, 2.14), (14.58, 2.41),
                 (1.000, 0.000), (0.495, 0.090), (0.464, 0.101), (0.167, 0.016)),
        50: _row((6.66, 3.74), (23.56, 3.48), (6.92, 1.36), (19.88, 2.99),
                 (1.000, 0.000), (0.531, 0.037), (0.494, 0.068), (0.167, 0.018)),
        100: _row((4.82, 0.96), (24.00, 4.96), (9.92, 1.49), (34.82, 7.40),
                  (1.000, 0.000), (0.537, 0.078), (0.491, 0.081), (0.171, 0.016)),
    },
}
"""Cheng et al. 2020's Table 4: environment → n_pop → column → (mean, std), copied as printed (50 trials each).

Printed oddities kept as they are: random n_pop = 25 has f_t = 0.556 ± 0.992 (the spread is probably
0.092), and 3-slit n_pop = 25 a terminate time spread (1.07 s) far below its reach time spread.
"""

RECORD_FIELDS = (
    "environment",
    "pop_size",
    "seed",
    "method",
    "max_gen",
    "patience",
    "max_length",
    "legs",
    "legs_run",
    "reached",
    "reach_generation",
    "terminate_generation",
    "reach_time_s",
    "terminate_time_s",
    "f_gr",
    "f_t",
    "f_sm",
    "f_sf",
    "plan_time",
    "best_time",
    "exact_time",
    "gap",
    "f_t_gap",
)
"""The keys of a :func:`run_trial` record, in CSV column order."""

_INT_FIELDS = {"pop_size", "seed", "max_gen", "patience", "max_length", "legs", "legs_run",
               "reach_generation", "terminate_generation"}
_BOOL_FIELDS = {"reached"}
_STR_FIELDS = {"environment", "method"}
TIME_FIELDS = ("reach_time_s", "terminate_time_s")
"""The wall-clock fields of a record: the only ones that differ between two runs of the same trial."""


# --- validation ----------------------------------------------------------------------------------
def _check_environment(environment: Any) -> str:
    if not isinstance(environment, str) or environment not in ENVIRONMENTS:
        raise ParameterError(
            f"unknown environment {environment!r}: expected one of {', '.join(ENVIRONMENTS)}"
        )
    return environment


def _check_method(method: Any) -> str:
    if method not in GA_ALGORITHMS:
        raise ParameterError(f"unknown method {method!r}: expected one of {', '.join(GA_ALGORITHMS)}")
    return str(method)


# --- one trial -----------------------------------------------------------------------------------
def _environment(environment: str) -> tuple[Scenario, Simulator]:
    """The bundled scenario and its compiled simulator (Cheng et al. 2020's commands)."""
    scenario = load_scenario(environment)
    return scenario, Simulator(scenario.workspace, commands=SEED000_COMMANDS)


def _exact_leg(sim: Simulator, start: Pose, goal: Pose, t0: int) -> tuple[float, int] | None:
    """(time, number of commands) of the minimum-time plan of one leg from ``start`` at clock ``t0``,
    None if the goal cannot be reached."""
    try:
        plan = plan_exact(sim, [start, goal], t0=int(t0))
    except ConfigurationError:  # the start collides with a moving obstacle at that clock
        return None
    return (float(plan.time), len(plan.commands)) if plan.reached else None


def _sum_or_none(values: Iterable[float | None]) -> float | None:
    values = list(values)
    return None if not values or any(v is None for v in values) else float(sum(values))


def _trial_record(environment: str, pop_size: int, seed: int, method: str, max_gen: int,
                  patience: int, plan: Plan, sim: Simulator, roadmap: Sequence[Pose], t_max: float) -> dict:
    legs = plan.legs
    reached = bool(plan.reached)
    generations = [len(leg.history) for leg in legs]  # generations run: one history row each
    mo = [leg.selected["multi_objective"].fitness for leg in legs]
    fitness = np.mean(np.asarray(mo, dtype=float), axis=0) if mo else np.full(4, np.nan)

    # The exact optimum of every roadmap leg: from the GA leg's start and clock where the GA ran the
    # leg; legs never attempted (after a failed one) continue the exact plan's own clock.
    exact_legs: list[float | None] = []
    clock = 0
    for i, (start, goal) in enumerate(zip(roadmap[:-1], roadmap[1:])):
        if i < len(legs):
            start, goal, clock = legs[i].start, legs[i].goal, legs[i].t0
        leg = _exact_leg(sim, start, goal, clock)
        exact_legs.append(None if leg is None else leg[0])
        if leg is None:
            break
        clock += leg[1]
    exact_time = _sum_or_none(exact_legs) if len(exact_legs) == len(roadmap) - 1 else None

    best_time = gap = f_t_gap = None
    if reached:
        best_legs = [float(leg.selected["time"].time) for leg in legs]
        best_time = float(sum(best_legs))
        if exact_time is not None and exact_time > 0:
            gap = (best_time - exact_time) / exact_time
            leg_gaps = []
            for best, exact in zip(best_legs, exact_legs):
                f_t_exact = 1.0 - exact / t_max
                f_t_best = 1.0 - best / t_max
                leg_gaps.append((f_t_exact - f_t_best) / f_t_exact if f_t_exact > 0 else math.nan)
            f_t_gap = None if any(math.isnan(g) for g in leg_gaps) else float(max(leg_gaps))

    return {
        "environment": environment,
        "pop_size": pop_size,
        "seed": seed,
        "method": method,
        "max_gen": max_gen,
        "patience": patience,
        "max_length": MAX_LENGTH[environment],
        "legs": len(roadmap) - 1,
        "legs_run": len(legs),
        "reached": reached,
        "reach_generation": plan.reach_generation if reached else None,
        "terminate_generation": int(sum(generations)),
        "reach_time_s": _sum_or_none(leg.reach_time_s for leg in legs) if reached else None,
        "terminate_time_s": float(plan.runtime_s),
        "f_gr": float(fitness[0]),
        "f_t": float(fitness[1]),
        "f_sm": float(fitness[2]),
        "f_sf": float(fitness[3]),
        "plan_time": float(plan.time) if reached else None,
        "best_time": best_time,
        "exact_time": exact_time,
        "gap": gap,
        "f_t_gap": f_t_gap,
    }


def run_trial(
    environment: str,
    pop_size: int,
    seed: int,
    *,
    max_gen: int = 1000,
    patience: int = 100,
    method: str = "htetro-ga",
) -> dict:
    """One run of the GA through an environment's roadmap, measured as Table 4 does, plus its gap to
    the exact optimum.

    Parameters
    ----------
    environment : str
        One of :data:`ENVIRONMENTS`.
    pop_size : int
        n_pop.
    seed : int
        The run's seed (:func:`~htetro_opt.solvers.grid_paths.plan_ga`): the same seed gives the same record,
        wall-clock fields aside.
    max_gen, patience : int, keyword-only
        Termination per leg: at most ``max_gen`` generations, or ``patience`` generations without
        improvement once the goal is reached.
    method : str, keyword-only
        One of :data:`~htetro_opt.algorithms.GA_ALGORITHMS` (default the paper's hTetro-GA with our
        additions; ``"htetro-ga-paper"`` runs it as published).

    Returns
    -------
    dict
        A flat record with the keys of :data:`RECORD_FIELDS`:

        - ``reached``: every leg's output solution reaches its goal.
        - ``reach_generation``: the largest, over the legs, first generation holding a goal-reaching
          individual (1 = the initial population); ``reach_time_s``: the sum over the legs of the
          wall-clock time to that generation. None unless ``reached``.
        - ``terminate_generation``: generations run, summed over the legs; ``terminate_time_s``:
          the whole run's wall-clock time.
        - ``f_gr`` … ``f_sf``: the fitnesses of the output (multi-objective) solution, averaged over
          the legs run. They are kept for failed runs (then ``f_gr`` < 1).
        - ``plan_time``: the output plan's time; ``best_time``: the sum over the legs of the time of
          each leg's best-f_t member of the leading front. None unless ``reached``.
        - ``exact_time``: the sum over the legs of the minimum-time plan from the same start and
          obstacle clock as the GA's leg (legs after a failed one continue the exact plan's clock);
          None if some leg is unreachable.
        - ``gap``: ``(best_time − exact_time) / exact_time``; ``f_t_gap``: the largest over the legs
          of ``(f_t,exact − f_t,best) / f_t,exact`` with ``f_t = 1 − time / t_max`` and
          ``t_max = l_p,max × t_translation``. None unless ``reached``.

    Raises
    ------
    ParameterError
        If the environment or method is unknown, or a number is out of range.
    """
    environment = _check_environment(environment)
    pop_size = check_int(pop_size, "pop_size", minimum=2)
    seed = check_int(seed, "seed", minimum=0)
    max_gen = check_int(max_gen, "max_gen", minimum=1)
    patience = check_int(patience, "patience", minimum=1)
    method = _check_method(method)
    scenario, sim = _environment(environment)
    roadmap = list(scenario.roadmap)
    max_length = MAX_LENGTH[environment]
    plan = plan_ga(sim, roadmap, algorithm=method, pop_size=pop_size, max_gen=max_gen,
                   patience=patience, max_length=max_length, seed=seed)
    t_max = max_length * sim.timing.translation
    return _trial_record(environment, pop_size, seed, method, max_gen, patience, plan, sim, roadmap, t_max)


def _run_task(task: tuple[str, int, int, dict]) -> dict:
    environment, pop_size, seed, options = task
    return run_trial(environment, pop_size, seed, **options)


# --- the study -----------------------------------------------------------------------------------
def run_study(
    environments: Sequence[str] = ENVIRONMENTS,
    pop_sizes: Sequence[int] = POP_SIZES,
    seeds: Iterable[int] = range(50),
    *,
    max_gen: int = 1000,
    patience: int = 100,
    method: str = "htetro-ga",
    jobs: int = 1,
    progress: Callable[[int, int, dict], None] | None = None,
) -> list[dict]:
    """Every trial of the study: each environment × population size × seed.

    Parameters
    ----------
    environments : sequence of str
        Names from :data:`ENVIRONMENTS`.
    pop_sizes : sequence of int
    seeds : iterable of int
        One trial per seed (the paper ran 50).
    max_gen, patience, method : keyword-only
        As for :func:`run_trial`.
    jobs : int, keyword-only
        Worker processes; above 1 the trials run in a :class:`~concurrent.futures.ProcessPoolExecutor`.
    progress : callable, optional, keyword-only
        Called as ``progress(done, total, record)`` after each trial, in completion order.

    Returns
    -------
    list of dict
        :func:`run_trial` records in the order environment, then population size, then seed, as
        given, whatever ``jobs`` and the completion order.

    Raises
    ------
    ParameterError
        If an environment is unknown (the message names it), a list is empty, or a number is out of
        range.
    """
    if isinstance(environments, str):
        environments = [environments]
    environments = [_check_environment(e) for e in environments]
    pop_sizes = [check_int(n, "pop_size", minimum=2) for n in ([pop_sizes] if isinstance(pop_sizes, int) else pop_sizes)]
    try:
        seeds = [check_int(s, "seed", minimum=0) for s in seeds]
    except TypeError as err:
        raise ParameterError(f"seeds must be an iterable of integers, got {seeds!r}") from err
    for name, values in (("environments", environments), ("pop_sizes", pop_sizes), ("seeds", seeds)):
        if not values:
            raise ParameterError(f"{name} must not be empty")
    options = dict(
        max_gen=check_int(max_gen, "max_gen", minimum=1),
        patience=check_int(patience, "patience", minimum=1),
        method=_check_method(method),
    )
    jobs = check_int(jobs, "jobs", minimum=1)
    if progress is not None and not callable(progress):
        raise ParameterError(f"progress must be callable, got {progress!r}")

    tasks = [(e, n, s, options) for e in environments for n in pop_sizes for s in seeds]
    results: list[dict | None] = [None] * len(tasks)
    if jobs == 1 or len(tasks) == 1:
        for i, task in enumerate(tasks):
            results[i] = _run_task(task)
            if progress is not None:
                progress(i + 1, len(tasks), results[i])
        return results  # type: ignore[return-value]
    pool = ProcessPoolExecutor(max_workers=min(jobs, len(tasks)))
    try:
        futures = {pool.submit(_run_task, task): i for i, task in enumerate(tasks)}
        for done, future in enumerate(as_completed(futures), start=1):
            i = futures[future]
            results[i] = future.result()
            if progress is not None:
                progress(done, len(tasks), results[i])
    except BaseException:
        pool.shutdown(wait=True, cancel_futures=True)
        raise
    pool.shutdown(wait=True)
    return results  # type: ignore[return-value]


# --- summary -------------------------------------------------------------------------------------
def _is_reached(record: Mapping[str, Any]) -> bool:
    f_gr = record.get("f_gr")
    return f_gr is not None and float(f_gr) >= 1.0 - 1e-9


def _order(key: tuple) -> tuple:
    environment, pop_size, method = key
    rank = ENVIRONMENTS.index(environment) if environment in ENVIRONMENTS else len(ENVIRONMENTS)
    return rank, str(environment), pop_size if pop_size is not None else -1, str(method or "")


def summarise(records: Iterable[Mapping[str, Any]]) -> list[dict]:
    """One row per (environment, population size, method): our mean ± std beside the paper's.

    Parameters
    ----------
    records : iterable of mapping
        :func:`run_trial` records (or rows read back by :func:`read_csv`).

    Returns
    -------
    list of dict
        Rows in :data:`ENVIRONMENTS` order (others after, by name), then by population size and
        method, with:

        - ``environment``, ``pop_size``, ``method`` (None for records without one), ``runs``,
          ``reached`` (runs whose output solution has f_gr = 1) and ``reach_rate`` (their fraction);
        - for each of :data:`TABLE4_COLUMNS` ``<column>_mean`` and ``<column>_std`` (sample standard
          deviation) and the paper's ``paper_<column>_mean`` and ``paper_<column>_std`` (None where
          the paper has no such row). The reach columns are defined only for runs that reached; f_gr,
          the terminate generation and the terminate time are over all runs; f_t, f_sm and f_sf over
          the runs that reached (a failed run's output solution is not a path to the goal);
        - ``best_time_mean``, ``best_time_std``, ``exact_time_mean``, ``exact_time_min``,
          ``exact_time_max``, ``gap_mean``, ``gap_max``, ``f_t_gap_mean``, ``f_t_gap_max`` and
          ``plan_time_mean`` (each over the runs where it is defined).

    Examples
    --------
    >>> rows = summarise([
    ...     {"environment": "random", "pop_size": 25, "f_gr": 1.0, "f_t": 0.6, "terminate_generation": 10},
    ...     {"environment": "random", "pop_size": 25, "f_gr": 0.5, "f_t": 0.9, "terminate_generation": 30},
    ... ])
    >>> rows[0]["reach_rate"], rows[0]["f_t_mean"], rows[0]["terminate_generation_mean"]
    (0.5, 0.6, 20.0)
    """
    records = list(records)
    groups = group_records(records, ["environment", "pop_size", "method"])
    over_reached = {"f_t", "f_sm", "f_sf"}
    rows = []
    for key in sorted(groups, key=_order):
        group = groups[key]
        environment, pop_size, method = key
        reached = sum(_is_reached(r) for r in group)
        row: dict[str, Any] = {
            "environment": environment,
            "pop_size": pop_size,
            "method": method,
            "runs": len(group),
            "reached": reached,
            "reach_rate": reached / len(group),
        }
        paper = PAPER_TABLE4.get(environment, {}).get(pop_size)
        for column in TABLE4_COLUMNS:
            where = _is_reached if column in over_reached else None
            row[f"{column}_mean"], row[f"{column}_std"] = mean_std(values_of(group, column, where=where))
            row[f"paper_{column}_mean"], row[f"paper_{column}_std"] = paper[column] if paper else (None, None)
        row["best_time_mean"], row["best_time_std"] = mean_std(values_of(group, "best_time"))
        exact = values_of(group, "exact_time")
        row["exact_time_mean"] = mean_std(exact)[0]
        row["exact_time_min"] = min(exact) if exact else None
        row["exact_time_max"] = max(exact) if exact else None
        for name in ("gap", "f_t_gap"):
            values = values_of(group, name)
            row[f"{name}_mean"] = mean_std(values)[0]
            row[f"{name}_max"] = max(values) if values else None
        row["plan_time_mean"] = mean_std(values_of(group, "plan_time"))[0]
        rows.append(row)
    return rows


_MD_COLUMNS = (
    ("reach_generation", "reach gen", 2),
    ("terminate_generation", "terminate gen", 2),
    ("reach_time_s", "reach time (s)", 2),
    ("terminate_time_s", "terminate time (s)", 2),
    ("f_t", "f_t", 3),
    ("f_sm", "f_sm", 3),
    ("f_sf", "f_sf", 3),
)


def _number(value: float | None, digits: int = 1) -> str:
    if value is None:
        return "–"
    return f"{value:g}" if float(value).is_integer() else f"{value:.{digits}f}"


def markdown_table(summary: Iterable[Mapping[str, Any]]) -> str:
    """A markdown table of :func:`summarise` rows: ours as "mean ± std", the paper's in brackets.

    Columns: environment, n_pop, the method (only when the rows hold more than one), runs, reached
    (of runs), reach and terminate generation, reach and
    terminate time, f_t, f_sm, f_sf (each "ours (paper)"), the exact optimum time, the best GA time
    (mean ± std over the runs that reached) and the gap of the best GA time to the optimum (mean, and
    the largest in brackets).

    Examples
    --------
    >>> text = markdown_table(summarise([{"environment": "three_slit", "pop_size": 50, "f_gr": 1.0,
    ...     "reach_generation": 200, "best_time": 36.0, "exact_time": 33.0, "gap": 3 / 33}]))
    >>> "| three_slit | 50 | 1 | 1/1 | 200.00 (210.60 ± 27.56) |" in text
    True
    """
    summary = list(summary)
    several = len({row.get("method") for row in summary}) > 1
    header = ["environment", "n_pop"] + (["method"] if several else []) + ["runs", "reached"]
    lead = len(header)
    header += [f"{label}, ours (paper)" for _, label, _ in _MD_COLUMNS]
    header += ["exact optimum", "best GA time", "gap to optimum"]
    lines = ["| " + " | ".join(header) + " |",
             "|" + "|".join(["---", "---:"] + (["---"] if several else []) + ["---:"] * (len(header) - 2 - several))
             + "|"]
    for row in summary:
        cells = [str(row["environment"]), str(row["pop_size"])]
        cells += [str(row.get("method"))] if several else []
        cells += [str(row["runs"]), f"{row['reached']}/{row['runs']}"]
        assert len(cells) == lead
        for column, _, digits in _MD_COLUMNS:
            ours = format_mean_std(row.get(f"{column}_mean"), row.get(f"{column}_std"), digits=digits)
            paper = format_mean_std(row.get(f"paper_{column}_mean"), row.get(f"paper_{column}_std"),
                                    digits=digits)
            cells.append(f"{ours} ({paper})")
        lo, hi = row.get("exact_time_min"), row.get("exact_time_max")
        cells.append(_number(lo) if lo == hi else f"{_number(lo)}–{_number(hi)}")
        cells.append(format_mean_std(row.get("best_time_mean"), row.get("best_time_std"), digits=1))
        gap_mean, gap_max = row.get("gap_mean"), row.get("gap_max")
        cells.append("–" if gap_mean is None else f"{100 * gap_mean:.1f} % (max {100 * gap_max:.1f} %)")
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


# --- files ---------------------------------------------------------------------------------------
def _write_atomic(path: str | os.PathLike, text: str) -> Path:
    """Write ``text`` to ``path`` so that the path never holds a half-written file."""
    with atomic_path(path) as tmp:
        with open(tmp, "w", encoding="utf-8", newline="") as handle:
            handle.write(text)
            handle.flush()
            os.fsync(handle.fileno())
    return Path(path)


def _csv_value(value: Any) -> str:
    if value is None:
        return ""
    if isinstance(value, (float, np.floating)):
        return repr(float(value))
    return str(value)


def write_csv(records: Iterable[Mapping[str, Any]], path: str | os.PathLike) -> Path:
    """Write one CSV line per trial record, atomically.

    Columns are :data:`RECORD_FIELDS` then any other keys in order of first appearance; None is
    written as an empty cell, floats at full precision.

    Returns
    -------
    Path
        The path written.

    Raises
    ------
    OSError
        If the file cannot be written (the directory must exist); nothing is left behind.
    """
    records = list(records)
    fields = list(RECORD_FIELDS)
    for record in records:
        fields += [k for k in record if k not in fields]
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(fields)
    for record in records:
        writer.writerow([_csv_value(record.get(k)) for k in fields])
    return _write_atomic(path, buffer.getvalue())


def read_csv(path: str | os.PathLike) -> list[dict]:
    """Read back the records of :func:`write_csv`, with their types (empty cells → None).

    Raises
    ------
    OSError
        If the file cannot be read.
    ParameterError
        If a cell does not parse as its column's type.
    """
    out = []
    with open(path, newline="", encoding="utf-8") as handle:
        for line, raw in enumerate(csv.DictReader(handle), start=2):
            record: dict[str, Any] = {}
            for key, text in raw.items():
                try:
                    if text == "" or text is None:
                        record[key] = None
                    elif key in _STR_FIELDS:
                        record[key] = text
                    elif key in _BOOL_FIELDS:
                        if text not in ("True", "False"):
                            raise ValueError(text)
                        record[key] = text == "True"
                    elif key in _INT_FIELDS:
                        record[key] = int(text)
                    elif key in RECORD_FIELDS:
                        record[key] = float(text)
                    else:
                        record[key] = text
                except ValueError as err:
                    raise ParameterError(f"{path}, line {line}: bad {key} value {text!r}") from err
            out.append(record)
    return out


# --- command line --------------------------------------------------------------------------------
