"""Cheng et al. 2020's Table 4 re-run: hTetro-GA over six environments and three population sizes.

The paper (Cheng et al., IEEE Access 2020, §V–VI) runs hTetro-GA 50 times in each of six environments
with n_pop = 25, 50 and 100, l_p,max = 200 on the spiral map and 100 elsewhere, at most 1000
generations, and reports per cell of its Table 4 the mean ± standard deviation of the generation at
which some individual first reaches the goal ("reach population"), the generation at which the run
stops ("terminate population"), the wall-clock times of both, and the four fitnesses of the output
("multi-objective based") solution. :data:`PAPER_TABLE4` holds those numbers. :func:`run_trial` is one
run, measured as Table 4 does with :func:`~htetro_opt.solvers.grid_paths.plan_ga` on the bundled
scenario of the same name, plus what the paper could not measure: how far the GA's best plan is from
the exact minimum-time plan (:func:`~htetro_opt.solvers.grid_paths.plan_exact`, same start, goal and
obstacle clock). :func:`trial` is the same run as a trial of the study runner
(:mod:`htetro_opt.studies.runner`), which runs the grid (the bundled study ``table4``,
``studies/data/table4.toml``, or :func:`table4_study`), records it and resumes it; :func:`summarise`,
:func:`markdown_table` and :func:`report` lay its records out as Table 4, ours beside the paper's.

Our environments are reconstructions (the paper's figures are not in our copy, see each scenario's
``source``), so the generations and times need not match the paper's; the exact optimum is the
reference that does not depend on the reconstruction.

The study runs two methods beside the paper's numbers: ``htetro-ga-paper``, the paper's algorithm as
published (its l_p,max, and the paper mode's patience of 10 generations, our reading of "the
convergence of the solution"), and ``htetro-ga``, ours (our eight additions, patience 100). The
report gives, for each environment and n_pop, the paper's row, the as-published run's and ours.

Run from Python::

    from htetro_opt.studies import table4
    from htetro_opt.studies.runner import load_study, run_study

    run = run_study(load_study("table4"), trial=table4.trial, seeds=3, out="results", workers=2)
    print(table4.report(run))

or a smaller grid with :func:`run_table4` (``run_table4(["three_slit", "random"], [25, 50], 3,
max_gen=300)``), the same study with other settings.
"""

from __future__ import annotations

import itertools
import math
import numbers
import os
import statistics
from collections.abc import Iterable, Mapping, Sequence
from typing import Any

import numpy as np

from htetro_opt import __version__
from htetro_opt._validation import check_int
from htetro_opt.algorithms import GA_ALGORITHMS
from htetro_opt.errors import ConfigurationError, ParameterError
from htetro_opt.model.commands import SEED000_COMMANDS
from htetro_opt.model.robot import Pose
from htetro_opt.model.simulate import Simulator
from htetro_opt.scenarios import Scenario, load_scenario
from htetro_opt.solvers.grid_paths import Plan, plan_exact, plan_ga
from htetro_opt.solvers.grid_paths._spec import GA_PATIENCE
from htetro_opt.solvers.grid_paths._spec import SPEC as PLAN_SPEC
from htetro_opt.studies.metrics import (
    format_mean_std,
    group_records,
    mean_std,
    values_of,
)
from htetro_opt.studies.runner import Study, StudyRun, Trial, run_study

__all__ = [
    "ENVIRONMENTS",
    "MAX_LENGTH",
    "METHODS",
    "PAPER_TABLE4",
    "POP_SIZES",
    "RECORD_FIELDS",
    "STUDY_METRICS",
    "TABLE4_COLUMNS",
    "TIME_FIELDS",
    "markdown_table",
    "report",
    "run_table4",
    "run_trial",
    "summarise",
    "table4_study",
    "trial",
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
"""The keys of a :func:`run_trial` record, in order."""

TIME_FIELDS = ("reach_time_s", "terminate_time_s", "runtime_s")
"""The wall-clock fields of a record (``runtime_s`` only in :func:`trial`'s): the only ones that
differ between two runs of the same trial."""

STUDY_METRICS = ("generations", "fitness", "gap")
"""The runner metrics the Table-4 study asks for (``studies/data/table4.toml``), the only ones
:func:`trial` takes: its record holds Table 4's generations and fitnesses, and ``"gap"`` makes the
runner record each map's exact reference (Dijkstra over the whole roadmap) and the output plan's gap."""

_PAPER_MAX_GEN = 1000  # n_pop,max (§V-B3)
METHODS = ("htetro-ga-paper", "htetro-ga")
"""The methods the Table-4 study runs: the paper's algorithm as published, and ours."""
_TRIAL_OPTIONS = ("pop_size", "max_gen", "patience", "max_length")
_IN_HEAD = ("environment", "pop_size", "seed", "method", "max_gen", "patience", "max_length")
# In a runner record "gap" and "reference" are the runner's (the output plan against the study's
# reference, written by run_study): Table 4's gap of the best plan there is "best_gap"; "time" is the
# output plan's time under the runner's name.
_RENAMED = {"plan_time": "time", "gap": "best_gap"}


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


def _patience(method: str) -> int:
    """The method's own patience (the grid-path spec's: 10 for htetro-ga-paper), else the GAs' default."""
    own = PLAN_SPEC.default_of(method, "patience")
    return GA_PATIENCE["best"] if own is None else own


def _check_list(values: Any, name: str) -> list:
    """A non-empty list of ``values`` (a single str or int is a list of one)."""
    if isinstance(values, (str, numbers.Integral)):
        values = [values]
    if isinstance(values, Mapping) or not isinstance(values, Iterable):
        raise ParameterError(f"{name} must be a list, got {values!r}")
    values = list(values)
    if not values:
        raise ParameterError(f"{name} must not be empty")
    return values


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


def _trial_record(environment: str, pop_size: int, seed: int, method: str, max_gen: int, patience: int,
                  max_length: int, plan: Plan, sim: Simulator, roadmap: Sequence[Pose], t_max: float) -> dict:
    legs = plan.legs
    reached = bool(plan.reached)
    generations = [len(leg.history) for leg in legs]  # generations run: one history row each
    mo = [leg.selected["multi_objective"].fitness for leg in legs]
    fitness = np.mean(np.asarray(mo, dtype=float), axis=0) if mo else np.full(4, np.nan)

    # The exact optimum of every roadmap leg: from the GA leg's start and clock where the GA ran the
    # leg; legs never attempted (after a failed one) continue the exact plan's own clock.
    exact_legs: list[float | None] = []
    clock = 0
    for i, (start, goal) in enumerate(itertools.pairwise(roadmap)):
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
        "max_length": max_length,
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


def _measure(environment, pop_size, seed, *, max_gen, patience, method, max_length) -> tuple[dict, Plan]:
    """:func:`run_trial`'s record and the plan it measures."""
    environment = _check_environment(environment)
    pop_size = check_int(pop_size, "pop_size", minimum=2)
    seed = check_int(seed, "seed", minimum=0)
    max_gen = check_int(max_gen, "max_gen", minimum=1)
    method = _check_method(method)
    patience = check_int(_patience(method) if patience is None else patience, "patience", minimum=1)
    max_length = MAX_LENGTH[environment] if max_length is None else check_int(max_length, "max_length", minimum=1)
    scenario, sim = _environment(environment)
    roadmap = list(scenario.roadmap)
    plan = plan_ga(sim, roadmap, algorithm=method, pop_size=pop_size, max_gen=max_gen,
                   patience=patience, max_length=max_length, seed=seed)
    t_max = max_length * sim.timing.translation
    record = _trial_record(environment, pop_size, seed, method, max_gen, patience, max_length, plan, sim, roadmap,
                           t_max)
    return record, plan


def run_trial(
    environment: str,
    pop_size: int,
    seed: int,
    *,
    max_gen: int = _PAPER_MAX_GEN,
    patience: int | None = None,
    method: str = "htetro-ga",
    max_length: int | None = None,
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
        wall-clock fields (:data:`TIME_FIELDS`) aside.
    max_gen, patience : int, keyword-only
        Termination per leg: at most ``max_gen`` generations, or ``patience`` generations without
        improvement once the goal is reached (default the method's: 10 for ``"htetro-ga-paper"``,
        100 for the others, see :func:`~htetro_opt.solvers.grid_paths.plan_ga`).
    method : str, keyword-only
        One of :data:`~htetro_opt.algorithms.GA_ALGORITHMS` (default the paper's hTetro-GA with our
        additions; ``"htetro-ga-paper"`` runs it as published).
    max_length : int, optional, keyword-only
        l_p,max, the longest chromosome (default the paper's, :data:`MAX_LENGTH`).

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

    Examples
    --------
    >>> record = run_trial("three_slit", 12, 0, max_gen=5)
    >>> record["exact_time"], record["terminate_generation"], record["max_length"]
    (33.0, 5, 100)
    """
    return _measure(environment, pop_size, seed, max_gen=max_gen, patience=patience, method=method,
                    max_length=max_length)[0]


def _plain(value):
    """A JSON-ready scalar (the runner's results file refuses NaN): numpy's as Python's, NaN as None."""
    if value is None or isinstance(value, (bool, str)):
        return value
    if isinstance(value, numbers.Integral):
        return int(value)
    value = float(value)
    return value if math.isfinite(value) else None


def _check_trial_parameters(parameters: Any) -> dict:
    if not isinstance(parameters, Mapping):
        raise ParameterError(f"parameters must be a mapping of option names to values, got {parameters!r}")
    unknown = [k for k in parameters if k not in _TRIAL_OPTIONS]
    if unknown:
        raise ParameterError(f"the Table-4 trial takes the options {', '.join(_TRIAL_OPTIONS)}, "
                             f"not {', '.join(map(repr, unknown))}")
    if "pop_size" not in parameters:
        raise ParameterError("the Table-4 trial needs pop_size (n_pop) among its parameters")
    return dict(parameters)


def trial(task: str, scenario: str, method: str, parameters: Mapping[str, Any], seed: int, *,
          label: str | None = None, metrics: Sequence[str] = ()) -> dict:
    """:func:`run_trial` as a trial of the study runner: ``run_study(study, trial=table4.trial)``.

    The signature is :func:`htetro_opt.studies.runner.run_trial`'s, the record the runner's (its
    ``key`` that of the study's trial, so that the runner recognises and resumes it).

    Parameters
    ----------
    task : {"plan"}
    scenario : str
        One of :data:`ENVIRONMENTS`.
    method : str
        One of :data:`~htetro_opt.algorithms.GA_ALGORITHMS`.
    parameters : mapping
        ``pop_size`` and optionally ``max_gen``, ``patience``, ``max_length`` (defaults as for
        :func:`run_trial`).
    seed : int
    label : str, optional, keyword-only
        The name of the trial's rows (default: ``method``).
    metrics : sequence of str, keyword-only
        The study's metrics, some of :data:`STUDY_METRICS` (the others of
        :data:`~htetro_opt.studies.runner.METRICS`, such as ``"front"``, are the runner's own trial's):
        they enter the trial's key; the record holds every Table-4 measure whatever they are.

    Returns
    -------
    dict
        The runner's head (``key``, ``kind``, ``task``, ``scenario``, ``method``, ``label``,
        ``seed``, the parameters), then :func:`run_trial`'s measures (those not in the head) with
        ``plan_time`` as ``time`` and ``gap`` as ``best_gap``, ``n_commands`` and ``commands``
        (the output plan, as the runner's plan records), ``runtime_s`` (= ``terminate_time_s``),
        ``error`` (None) and ``version``. With the metric ``"gap"``, :func:`~htetro_opt.studies.runner.run_study`
        adds ``reference`` (Dijkstra's time over the whole roadmap) and ``gap`` (the output plan's,
        ``(time − reference) / reference``).

    Raises
    ------
    ParameterError
        If the task is not ``plan``, an option or metric is not one of the trial's, or
        :func:`run_trial` refuses a value.

    Examples
    --------
    >>> record = trial("plan", "three_slit", "htetro-ga", {"pop_size": 12, "max_gen": 5}, 0)
    >>> record["scenario"], record["label"], record["exact_time"], record["error"], len(record["key"])
    ('three_slit', 'htetro-ga', 33.0, None, 64)
    """
    if task != "plan":
        raise ParameterError(f"the Table-4 trial plans paths: task must be 'plan', got {task!r}")
    if label is not None and not isinstance(label, str):
        raise ParameterError(f"label must be a string or None, got {label!r}")
    if isinstance(metrics, str) or not isinstance(metrics, Sequence) or \
            any(m not in STUDY_METRICS for m in metrics):
        raise ParameterError(f"the Table-4 trial records the metrics {', '.join(STUDY_METRICS)} (its record holds "
                             f"them whatever the study asks), not others: got {metrics!r}")
    parameters = _check_trial_parameters(parameters)
    measured, plan = _measure(scenario, parameters["pop_size"], seed, method=method,
                              max_gen=parameters.get("max_gen", _PAPER_MAX_GEN),
                              patience=parameters.get("patience"),
                              max_length=parameters.get("max_length"))
    record = Trial(task, scenario, method, parameters, seed, method if label is None else label,
                   tuple(metrics)).head()
    for name, value in measured.items():
        if name in _IN_HEAD:
            continue
        record[_RENAMED.get(name, name)] = _plain(value)
        if name == "plan_time":
            record["n_commands"] = len(plan.commands) if plan.reached else None
    record["commands"] = ",".join(plan.tokens)
    record["runtime_s"] = _plain(plan.runtime_s)
    record["error"] = None
    record["version"] = __version__
    return record


# --- the study -----------------------------------------------------------------------------------
def table4_study(
    environments: Sequence[str] = ENVIRONMENTS,
    pop_sizes: Sequence[int] = POP_SIZES,
    seeds: int | Sequence[int] = 50,
    *,
    max_gen: int = _PAPER_MAX_GEN,
    patience: int | None = None,
    method: str | Sequence[str] = METHODS,
) -> Study:
    """The Table-4 study for the runner: each method × population size, each environment × seed,
    l_p,max per :data:`MAX_LENGTH`. With the defaults it is the bundled study ``table4``
    (``load_study("table4")``); run it with ``run_study(study, trial=trial)``.

    Parameters
    ----------
    environments : sequence of str
        Names from :data:`ENVIRONMENTS` (a str: one).
    pop_sizes : sequence of int
        One method entry each, labelled ``"<method>, n_pop <n>"`` (an int: one).
    seeds : int or sequence of int
        N for seeds 0 … N−1, or the seeds (the paper ran 50).
    max_gen, patience : keyword-only
        As for :func:`run_trial` (patience: each method's own by default, written into its entries).
    method : str or sequence of str, keyword-only
        The methods, each one of :data:`~htetro_opt.algorithms.GA_ALGORITHMS` (default :data:`METHODS`:
        the paper's as published, then ours).

    Returns
    -------
    Study

    Raises
    ------
    ParameterError
        If an environment is unknown (the message names it), a list is empty, or a number is out of
        range.

    Examples
    --------
    >>> study = table4_study(["three_slit"], [12, 25], 2, max_gen=5, method="htetro-ga")
    >>> [(t.label, t.seed, t.parameters["max_gen"]) for t in study.trials()][:3]
    [('htetro-ga, n_pop 12', 0, 5), ('htetro-ga, n_pop 12', 1, 5), ('htetro-ga, n_pop 25', 0, 5)]
    """
    environments = [_check_environment(e) for e in _check_list(environments, "environments")]
    pop_sizes = [check_int(n, "pop_size", minimum=2) for n in _check_list(pop_sizes, "pop_sizes")]
    methods = [_check_method(m) for m in _check_list(method, "method")]
    max_gen = check_int(max_gen, "max_gen", minimum=1)
    patience = check_int(patience, "patience", minimum=1, allow_none=True)
    common = statistics.mode(MAX_LENGTH.values())  # 100 for the method entry; the spiral's 200 per map
    per_scenario = {e: {"max_length": MAX_LENGTH[e]} for e in environments if MAX_LENGTH[e] != common}
    entries = [{"label": f"{m}, n_pop {n}", "method": m, "pop_size": n, "max_gen": max_gen,
                "patience": _patience(m) if patience is None else patience, "max_length": common,
                **({"per_scenario": per_scenario} if per_scenario else {})}
               for m in methods for n in pop_sizes]
    return Study(name="table4", task="plan", scenarios=environments, methods=entries,
                 seeds=seeds if isinstance(seeds, numbers.Integral) else list(_check_list(seeds, "seeds")),
                 metrics=STUDY_METRICS,
                 description="Cheng et al. 2020, Table 4: hTetro-GA as published and ours over six maps and three "
                             "population sizes")


def run_table4(
    environments: Sequence[str] = ENVIRONMENTS,
    pop_sizes: Sequence[int] = POP_SIZES,
    seeds: int | Sequence[int] = 50,
    *,
    max_gen: int = _PAPER_MAX_GEN,
    patience: int | None = None,
    method: str | Sequence[str] = METHODS,
    executor: str = "processes",
    workers: int | None = None,
    out: str | os.PathLike | None = None,
    progress=None,
) -> StudyRun:
    """Run :func:`table4_study` on the study runner with :func:`trial`.

    ``executor``, ``workers``, ``out`` and ``progress`` are
    :func:`~htetro_opt.studies.runner.run_study`'s (``progress(done, total, note)``); the other
    arguments :func:`table4_study`'s. ``report(run)`` lays the result out as Table 4.

    Returns
    -------
    StudyRun
        Its ``records`` are :func:`trial` records, in the order environment, population size, seed.

    Raises
    ------
    ParameterError
        On an invalid argument, before any trial runs.
    """
    study = table4_study(environments, pop_sizes, seeds, max_gen=max_gen, patience=patience, method=method)
    return run_study(study, out=out, executor=executor, workers=workers, progress=progress, trial=trial)


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
        :func:`trial` records (a :class:`~htetro_opt.studies.runner.StudyRun`'s ``records``, or
        :func:`~htetro_opt.studies.runner.read_records` of its results file: references are left out).

    Returns
    -------
    list of dict
        Rows in :data:`ENVIRONMENTS` order (others after, by name), then by population size and
        method, with:

        - ``environment`` (the records' ``scenario``), ``pop_size``, ``method``, ``runs``,
          ``errors`` (trials that raised, recorded with their ``error``), ``reached`` (runs whose
          output solution has f_gr = 1) and ``reach_rate`` (their fraction of the runs);
        - for each of :data:`TABLE4_COLUMNS` ``<column>_mean`` and ``<column>_std`` (sample standard
          deviation) and the paper's ``paper_<column>_mean`` and ``paper_<column>_std`` (None where
          the paper has no such row). The reach columns are defined only for runs that reached; f_gr,
          the terminate generation and the terminate time are over all runs; f_t, f_sm and f_sf over
          the runs that reached (a failed run's output solution is not a path to the goal);
        - ``best_time_mean``, ``best_time_std``, ``exact_time_mean``, ``exact_time_min``,
          ``exact_time_max``, ``best_gap_mean``, ``best_gap_max``, ``f_t_gap_mean``, ``f_t_gap_max``
          and ``time_mean`` (the output plan's; each over the runs where it is defined).

    Examples
    --------
    >>> rows = summarise([
    ...     {"scenario": "random", "pop_size": 25, "f_gr": 1.0, "f_t": 0.6, "terminate_generation": 10},
    ...     {"scenario": "random", "pop_size": 25, "f_gr": 0.5, "f_t": 0.9, "terminate_generation": 30},
    ... ])
    >>> rows[0]["reach_rate"], rows[0]["f_t_mean"], rows[0]["terminate_generation_mean"]
    (0.5, 0.6, 20.0)
    """
    if isinstance(records, (str, Mapping)) or not isinstance(records, Iterable):
        raise ParameterError(f"records must be an iterable of trial records (dicts), got {records!r}")
    records = [r for r in records if r.get("kind", "trial") != "reference"]
    groups = group_records(records, ["scenario", "pop_size", "method"])
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
            "errors": sum(r.get("error") is not None for r in group),
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
        for name in ("best_gap", "f_t_gap"):
            values = values_of(group, name)
            row[f"{name}_mean"] = mean_std(values)[0]
            row[f"{name}_max"] = max(values) if values else None
        row["time_mean"] = mean_std(values_of(group, "time"))[0]
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


_SOURCES = {"htetro-ga-paper": "as published (htetro-ga-paper)", "htetro-ga": "ours (htetro-ga)"}
_PAPER_SOURCE = "Cheng et al. 2020, Table 4"
_PAPER_RUNS = 50  # Table 4's trials per row; its f_gr = 1.000 ± 0.000 everywhere: every output reached


def _source_order(method) -> tuple:
    return (list(_SOURCES).index(method) if method in _SOURCES else len(_SOURCES), str(method or ""))


def markdown_table(summary: Iterable[Mapping[str, Any]]) -> str:
    """A markdown table of :func:`summarise` rows: for each environment and n_pop, the paper's row
    (Cheng et al. 2020's Table 4, where it has that n_pop), then the as-published run
    (``htetro-ga-paper``), ours (``htetro-ga``) and any other method, each as "mean ± std".

    Columns: environment, n_pop, source, runs, errors (only when some trial raised), reached (of
    runs), reach and terminate generation, reach and terminate time, f_t, f_sm, f_sf, the exact
    optimum time, the best GA time (mean ± std over the runs that reached) and the gap of the best
    GA time to the optimum (mean, and the largest in brackets); the paper measured no optimum.

    Examples
    --------
    >>> text = markdown_table(summarise([{"scenario": "three_slit", "pop_size": 50, "f_gr": 1.0,
    ...     "method": "htetro-ga-paper", "reach_generation": 200, "best_time": 36.0, "exact_time": 33.0,
    ...     "best_gap": 3 / 33}]))
    >>> for line in text.splitlines()[2:]:
    ...     print(" | ".join(line.split(" | ")[:6]))
    | three_slit | 50 | Cheng et al. 2020, Table 4 | 50 | 50/50 | 210.60 ± 27.56
    | three_slit | 50 | as published (htetro-ga-paper) | 1 | 1/1 | 200.00
    """
    summary = sorted(summary, key=lambda row: (_order((row["environment"], row["pop_size"], None))[:3],
                                               _source_order(row.get("method"))))
    errors = any(row.get("errors") for row in summary)
    header = ["environment", "n_pop", "source", "runs"] + (["errors"] if errors else []) + ["reached"]
    lead = len(header)
    header += [label for _, label, _ in _MD_COLUMNS]
    header += ["exact optimum", "best GA time", "gap to optimum"]
    aligns = ["---", "---:", "---"] + ["---:"] * (len(header) - 3)
    lines = ["| " + " | ".join(header) + " |", "|" + "|".join(aligns) + "|"]
    done = set()
    for row in summary:
        group = (row["environment"], row["pop_size"])
        if group not in done and row.get(f"paper_{_MD_COLUMNS[0][0]}_mean") is not None:
            cells = [str(row["environment"]), str(row["pop_size"]), _PAPER_SOURCE, str(_PAPER_RUNS)]
            cells += ["–"] if errors else []
            cells += [f"{_PAPER_RUNS}/{_PAPER_RUNS}"]
            cells += [format_mean_std(row.get(f"paper_{column}_mean"), row.get(f"paper_{column}_std"), digits=digits)
                      for column, _, digits in _MD_COLUMNS]
            cells += ["–", "–", "–"]
            lines.append("| " + " | ".join(cells) + " |")
        done.add(group)
        method = row.get("method")
        cells = [str(row["environment"]), str(row["pop_size"]), _SOURCES.get(method, str(method))]
        cells += [str(row["runs"])] + ([str(row.get("errors", 0))] if errors else [])
        cells += [f"{row['reached']}/{row['runs']}"]
        assert len(cells) == lead
        cells += [format_mean_std(row.get(f"{column}_mean"), row.get(f"{column}_std"), digits=digits)
                  for column, _, digits in _MD_COLUMNS]
        lo, hi = row.get("exact_time_min"), row.get("exact_time_max")
        cells.append(_number(lo) if lo == hi else f"{_number(lo)}–{_number(hi)}")
        cells.append(format_mean_std(row.get("best_time_mean"), row.get("best_time_std"), digits=1))
        gap_mean, gap_max = row.get("best_gap_mean"), row.get("best_gap_max")
        cells.append("–" if gap_mean is None else f"{100 * gap_mean:.1f} % (max {100 * gap_max:.1f} %)")
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def report(run: StudyRun) -> str:
    """The Markdown Table 4 of a run of the Table-4 study: the paper's numbers, the as-published run and
    ours, the exact optimum and the gap (:func:`markdown_table` of :func:`summarise`).

    Raises
    ------
    ParameterError
        If ``run`` is not a :class:`~htetro_opt.studies.runner.StudyRun`, or its records are not
        :func:`trial`'s (the study was run without ``trial=table4.trial``).
    """
    if not isinstance(run, StudyRun):
        raise ParameterError(f"run must be the StudyRun of run_study, got {run!r}")
    foreign = [r for r in run.records if r.get("error") is None and "terminate_generation" not in r]
    if foreign:
        raise ParameterError(f"the records of study {run.study.name!r} are not Table-4 trials (e.g. "
                             f"{foreign[0].get('scenario')} {foreign[0].get('label')}): run it with "
                             "run_study(..., trial=htetro_opt.studies.table4.trial)")
    return markdown_table(summarise(run.records))
