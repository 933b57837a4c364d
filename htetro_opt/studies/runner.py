"""Studies at scale: scenarios × methods × seeds, on one machine or a Dask cluster, resumable.

A **study** (:class:`Study`) names a task (the command-line verb it stands for: ``plan``, ``tile``,
``sequence`` or ``cover``), the scenarios to run it on, the methods with their options, the seeds, and the
optional metrics to record. It is built in Python or read from a TOML file (:func:`load_study`: a
bundled name, ``htetro-opt``'s ``studies/data/*.toml``, or a path), which reads like the command
line it stands for: ``task`` is the verb, each method's keys are that verb's options with
underscores::

    name = "small"
    task = "plan"
    scenarios = ["random", "three_slit", "h_shape"]
    seeds = 3                     # or a list of seeds
    [[methods]]
    method = "dijkstra"
    [[methods]]
    method = "htetro-ga"
    pop_size = 20
    max_gen = 40

Top-level keys: ``name`` (default: the file's stem; it names the results files), ``description``,
``task``, ``scenarios`` (bundled names or files; relative paths start from the study file's folder),
``seeds`` (N for 0 … N−1, or a list), ``metrics`` (optional metrics, :data:`METRICS`) and the
``[[methods]]``. A method entry holds ``method``, an optional ``label`` (the name of its rows), the
verb's options, and ``[methods.per_scenario.<scenario>]`` tables of options for one scenario
(e.g. Table 4's ``max_length = 200`` on the spiral map). An entry's own ``scenarios`` (a list of
some of the study's scenarios) runs the method on those only (Do et al. 2021's Table 7 runs the GA
on the first four maps of its Table 6). The options:

- ``plan``: method ``dijkstra`` (alias ``exact``), ``astar``, ``htetro-ga``, ``htetro-ga-paper``,
  ``nsga2``, ``nsga3``, ``smsemoa``, ``agemoea``, ``heat``; ``clearance``; ``diagonals`` (the exact
  methods); ``pop_size``, ``max_gen``, ``patience``, ``max_length``, ``convergence`` (``"best"`` or
  ``"hypervolume"``), ``pick`` (``"balanced"``, ``"fastest"``, ``"smoothest"``, ``"safest"``),
  ``seed_exact``, ``replan_window``, ``replan_members`` (the GAs; pymoo's algorithms re-plan only
  when given a window), ``reach_share`` (the hTetro-GA's sort), ``reach_patience`` (its reach
  repair) and ``polish_window`` (its balanced polish) (``htetro-ga`` and ``htetro-ga-paper`` only),
  ``conservative`` (pymoo's algorithms only; see
  :func:`~htetro_opt.solvers.grid_paths.plan_ga`); ``weights``
  (``[w_t, w_sm, w_sf]`` or ``"w_t,w_sm,w_sf"``), ``t_max``, ``element`` (``"q1"`` or ``"p0"``),
  ``monotone``, ``band`` (``"auto"``, ``"full"`` or a radius in cells) (the heat planner of
  Do et al. 2021, which always plans with the diagonals);
- ``tile``: method ``auto``, ``backtracking`` or ``cpsat``; ``shapes`` (e.g. ``"TZ"``), ``overlap``,
  ``shuffle`` (then the trials are seeded), ``time_limit`` (default: the library's 60 s);
- ``sequence``: any sequencing method (``auto``, ``exact``, ``ortools``, ``local``, ``ga``, …);
  ``start`` (a tile label or ``"free"``), ``weights`` (``[a, b, c, d]`` or ``"a,b,c,d"``),
  ``time_limit``, ``shapes`` (for scenarios, which are tiled first);
- ``cover`` (complete coverage, Cheng et al. 2019): method ``stripes``, ``stripes-paper``,
  ``boustrophedon`` or ``tiling-tsp``; ``shapes`` (the morphology layers, ``"O,vI,hI"`` or a list
  such as ``["O", "hI"]``; default the paper's O, vI, hI), ``start`` (``"scenario"``: the roadmap's
  first and last poses, as on the command line, or ``"auto"``), ``clearance``; ``stripes`` (a width
  or widths bottom up, ``[2, 3, 2]`` or ``"2,3,2"``, checked against every scenario's height),
  ``region_columns``, ``budget``, ``ends`` (``"sweep"`` or ``"both"``) (the stripes methods);
  ``mopup`` (``"sequenced"`` or ``"nearest"``; the stripes methods and ``boustrophedon``);
  ``time_limit`` (the stripes methods and ``tiling-tsp``). Every coverage method is deterministic: its trials run once.

Seeds come from the study, never from a method entry. The whole study is checked before any trial
runs (:class:`StudyError` names the file, the method entry ``methods[i]``, counted from 0, and the
key).

A **trial** (:func:`run_trial`) is one method on one scenario with one seed: a pure, module-level
function whose record is a flat, JSON-ready dict of its inputs, metrics, runtime, solution (the
commands or order, comma-separated), the package version and ``key``, a hash of its inputs. A method
whose result does not depend on a seed (the exact planners, the heat planner, a tiling without
``shuffle``, the deterministic sequencing methods) runs once per scenario, its record's ``seed`` None.
The gap to the exact optimum (metric ``"gap"``) comes from one **reference** trial per scenario and
run (:func:`run_reference`: Dijkstra for ``plan``, the CP-SAT optimum for ``sequence``), recorded in
the results file like the others. A ``cover`` trial has no optimum to compare with: its record
always holds the lower bound ⌈(coverable − 4) / g⌉ on its action cost (g: the most new cells one
command adds, 2 for {O}, 4 with an I; every plan starts on 4 covered cells), computed from the
trial's own coverable cells, and metric ``"gap"`` sets ``reference`` to that bound and ``gap`` to
the cost over it (no reference trial). A ``plan`` reference takes the trial's ``clearance`` and command
set: the exact methods' ``diagonals``, none for the GAs (their chromosomes have no diagonals), and
always the diagonals for the heat planner, whose 17 commands (Do et al. 2021) include them.

:func:`run_study` runs the trials ``serial``-ly, on local ``processes`` (the default) or on a
``dask`` cluster (a local one, or the scheduler at an address), appends one JSON line per trial to
``DIR/<name>.jsonl`` as each finishes (flushed and synced), skips recorded trials on ``resume``,
and writes the :func:`summarise` table to ``DIR/<name>.csv`` and ``DIR/<name>.md``. The same study
and seeds give the same records (:data:`RUNTIME_FIELDS` aside), whatever the executor and however
often the run was interrupted; a method that stops on a time budget rather than by itself (``ortools``,
``time_limit`` cut-offs) depends on the machine's speed, as it does on the command line.

**Multi-objective metrics** (metric ``"front"``, ``plan`` with the GA methods only). A trial records
the leading front F0 of its last leg's final population (:attr:`LegResult.front`: the goal-reaching
individuals' non-dominated set, or everyone's when none reaches) as its distinct
``[f_gr, f_t, f_sm, f_sf]`` rows, rounded to 6 decimals, and the **hypervolume** ``hv`` of those
rows (:func:`hypervolume`). Both indicators are computed in pymoo's minimisation space,
F = −(f_gr, f_t, f_sm, f_sf), as in the notebook ``01_htetro_ga_pareto``, with the same choices:

- HV's reference point is :data:`HV_REFERENCE`, r = (0, 1, 0, 0), i.e. f_gr = 0, f_t = −1,
  f_sm = 0, f_sf = 0, fixed in advance, the same for every method, seed and scenario, and not taken
  from the runs (a data-derived point would change with the set of runs compared). f_gr, f_sm and
  f_sf lie in [0, 1] and 0 is the worst value each can take, so r is their nadir: every point with
  some goal progress, smoothness and safety counts. f_t has no lower bound (a path slower than
  t_max has f_t < 0); f_t = −1 is a path taking 2 t_max, the time of the longest all-translation
  chromosome the operators keep (offspring are cut at 2 l_p,max genes); slower members add nothing.
  The box between the ideal point (−1, −1, −1, −1) and r has volume 2, so 0 ≤ HV ≤ 2.
- **IGD+** (Ishibuchi et al. 2015, pymoo's ``IGDPlus``; lower is better, 0 when a run found the
  whole reference front) needs every run: :func:`front_metrics`, applied by :func:`summarise`,
  measures each record's front against the reference front of its scenario: the union of the
  fronts of every method and seed, reduced to its leading front (the best approximation of the true
  front these runs found), in the same unnormalised space. Trials whose ``clearance`` or
  ``max_length`` differ optimise different fitnesses (t_max = l_p,max × 1 s scales f_t) and are not
  pooled. The results file keeps the per-trial ``hv``; ``igd_plus`` is recomputed from the records'
  fronts, so :func:`summarise` of a results file gives the run's summary.

Metric ``"hv_curve"`` records the last leg's hypervolume by generation (against
:data:`HV_REFERENCE`): the convergence curve of the whole front. Metric ``"history"`` records the
convergence curve the GA keeps: the last leg's multi-objective
solution's ``[f_gr, f_t, f_sm, f_sf]`` per generation (:attr:`LegResult.history`, the paper's
Fig. 10). The front itself is not kept per generation, so there is no hypervolume-by-generation curve.
"""

from __future__ import annotations

import csv
import functools
import hashlib
import io
import json
import math
import numbers
import os
import re
import statistics
import time
import tomllib
import uuid
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from concurrent.futures.process import BrokenProcessPool
from contextlib import contextmanager
from dataclasses import dataclass, field, replace
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

from htetro_opt import __version__
from htetro_opt._files import write_text
from htetro_opt._progress import check_progress, report
from htetro_opt._validation import check_bool, check_int, check_real, check_time_limit
from htetro_opt.errors import HtetroError, OutputError, ParameterError
from htetro_opt.studies.metrics import (
    format_mean_std,
    group_records,
    mean_std,
    values_of,
)

__all__ = [
    "EXECUTORS",
    "HV_REFERENCE",
    "METRICS",
    "RUNTIME_FIELDS",
    "TASKS",
    "MethodSpec",
    "Study",
    "StudyError",
    "StudyRun",
    "Trial",
    "WorkerLost",
    "coverage_bound",
    "rows_csv",
    "front_metrics",
    "hypervolume",
    "list_studies",
    "load_study",
    "markdown_summary",
    "read_records",
    "reference_trial",
    "run_reference",
    "run_study",
    "run_trial",
    "summarise",
    "write_summary",
]

TASKS = ("plan", "tile", "sequence", "cover")
"""The tasks a study can run: the command-line verbs of the same names."""

EXECUTORS = ("serial", "processes", "dask")
"""Where the trials run: in this process, on a local process pool, on a Dask cluster."""

METRICS = {
    "plan": ("objectives", "generations", "fitness", "gap", "heat_fitness", "front", "history", "hv_curve"),
    "tile": (),
    "sequence": ("gap",),
    "cover": ("gap",),
}
"""Optional metrics per task, beyond those every record holds (plan: ``reached``, ``time``,
``n_commands``; tile: ``tiles``, ``overlapping``, ``n_I`` … ``n_T``; sequence: ``cost``,
``waypoints``; cover: ``action_cost``, ``time``, ``complete``, ``free``, ``coverable``,
``covered``, ``uncoverable``, ``lower_bound``, ``average_coverage_time``, ``recovered_pct``,
``coverage_pct``, ``coverable_pct``, ``path_length``, ``switches``, ``turns``, ``regions``,
``regions_optimal``, ``memo_hits``, ``nodes``, ``mopup_commands``, ``transit_commands``,
``dag_cost``, ``time_limited`` and ``layers``, the morphology set the plan used):

- ``objectives``: ``translations``, ``rotations``, ``shapeshifts``, ``path_length`` (:meth:`Plan.objectives`);
- ``generations``: the GAs' ``generations`` (summed over the legs), ``reach_generation`` and
  ``reach_time_s``;
- ``fitness``: the GAs' ``f_gr``, ``f_t``, ``f_sm``, ``f_sf`` of the multi-objective solution,
  averaged over the legs (Cheng et al. 2020's Table 4);
- ``gap``: ``reference`` (the exact optimum's time or cost) and ``gap`` = (value − reference) /
  reference; for the GA methods also ``fastest_time``, the summed time of each leg's fastest
  goal-reaching front member (the plan's legs chain the picked member, ``pick``; with moving
  obstacles a leg's fastest member is timed from the picked chain's clock, and a leg started later
  can be quicker than Dijkstra's leg-by-leg optimal plan, so the sum may fall below the reference),
  and ``fastest_gap``, its gap to the same reference; for ``sequence`` only where the optimum is
  proven (≤ 40 waypoints); for ``cover`` the reference is the trial's ``lower_bound`` (a bound, not an optimum: its gap is an upper bound
  on the gap to the optimum);
- ``heat_fitness`` (every plan method): Do et al. 2021's costs of the plan
  (:func:`~htetro_opt.problems.heat_costs.heat_fitness`, eqs. 9–12 with Fig. 5's safety), so that
  a GA's, an exact and a heat plan are scored alike: ``heat_f_t``, ``heat_f_sm``, ``heat_f_sf``,
  with the map's default t_max (a heat trial's own ``t_max`` where it sets one), and ``heat_f``, eq.
  12 with the heat trial's weights, and equal weights (1, 1, 1) for every other method (a choice of
  ours: they optimise no such weighting); plus ``shapes_used``, the morphologies the plan's poses
  take, as letters in order of first use (``"OI"``). None where the goal was not reached;
- ``front`` (the GA methods only): ``front``, the last leg's leading front as distinct
  ``[f_gr, f_t, f_sm, f_sf]`` rows rounded to 6 decimals, and ``hv``, its hypervolume
  (:func:`hypervolume`); the summary adds ``igd_plus`` (:func:`front_metrics`);
- ``history`` (the GA methods only): ``history``, the last leg's multi-objective solution's
  ``[f_gr, f_t, f_sm, f_sf]`` per generation, rounded to 6 decimals (the convergence curve)."""

HV_REFERENCE = (0.0, 1.0, 0.0, 0.0)
"""The hypervolume's reference point in pymoo's minimisation space F = −(f_gr, f_t, f_sm, f_sf):
f_gr = 0, f_t = −1 (a path taking twice t_max), f_sm = 0, f_sf = 0; fixed for every study, and the
notebook ``01_htetro_ga_pareto``'s (the module docstring gives the reasons)."""

_GA_METRICS = ("front", "history", "hv_curve")  # the exact planners have no population, hence no front
_FRONT_DIGITS = 6

RUNTIME_FIELDS = ("runtime_s", "reach_time_s")
"""Wall-clock fields of a record: the only ones that differ between two runs of the same trial."""

_METRIC_FIELDS = {
    "plan": ("reached", "time", "n_commands", "translations", "rotations", "shapeshifts", "path_length",
             "generations", "reach_generation", "reach_time_s", "f_gr", "f_t", "f_sm", "f_sf", "reference", "gap",
             "heat_f_t", "heat_f_sm", "heat_f_sf", "heat_f", "shapes_used", "hv", "igd_plus", "fastest_time",
             "fastest_gap"),
    "tile": ("tiles", "overlapping", "n_I", "n_O", "n_L", "n_J", "n_Z", "n_S", "n_T"),
    "sequence": ("cost", "waypoints", "optimal", "reference", "gap"),
    # the summary's columns; the records hold more (path_length, turns, memo_hits, nodes, …)
    "cover": ("action_cost", "time", "coverable", "covered", "lower_bound", "reference", "gap",
              "average_coverage_time", "recovered_pct", "coverage_pct", "switches", "regions", "regions_optimal",
              "mopup_commands"),
}
_PLAN_ALIASES = {"exact": "dijkstra"}  # the study files call the minimum-time plan "exact"
_HEAT_METHODS = ("heat",)  # Do et al. 2021's planner: weights and field options, no seed
_STRIPE_METHODS = ("stripes", "stripes-paper")  # Cheng et al. 2019's planners: stripes, regions, budgets
_TILING_GAIN = 4  # tiling-tsp's legs pass through any state: no command adds more than 4 new cells
_EQUAL_WEIGHTS = (1.0, 1.0, 1.0)  # heat_f of the plans that optimise no (w_t, w_sm, w_sf)
_TOP_KEYS = ("name", "description", "task", "scenarios", "seeds", "metrics", "methods")
_ENTRY_KEYS = ("method", "label", "scenarios", "per_scenario")
_NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.-]*")


class StudyError(ParameterError):
    """A study (a TOML file or a :class:`Study` built in Python) is invalid: the message names the
    file, the method entry (``methods[i]``, counted from 0) and the key."""


class WorkerLost(HtetroError, RuntimeError):
    """A worker process of the ``processes`` executor died (killed, out of memory): the trials
    recorded so far are kept, and ``resume=True`` continues the study."""


# --- options of each task --------------------------------------------------------------------------
def _plan_methods() -> tuple[tuple[str, ...], tuple[str, ...]]:
    from htetro_opt.solvers.grid_paths import EXACT_METHODS, PLAN_METHODS

    return tuple(PLAN_METHODS) + tuple(_PLAN_ALIASES), tuple(EXACT_METHODS)


def _plan_kind(method: str) -> str:
    """Which option set a plan method takes: ``"exact"`` (the graph searches), ``"heat"`` or ``"ga"``."""
    if method in _plan_methods()[1]:
        return "exact"
    return "heat" if method in _HEAT_METHODS else "ga"


def _kind(task: str, method: str) -> str:
    """Which option set a method takes: plan's :func:`_plan_kind`; cover: ``"stripes"`` (both stripe
    planners) or the method's name; the other tasks: the method's name."""
    if task == "plan":
        return _plan_kind(method)
    if task == "cover" and method in _STRIPE_METHODS:
        return "stripes"
    return method


def _methods_of(task: str) -> tuple[str, ...]:
    if task == "plan":
        return _plan_methods()[0]
    if task == "cover":
        from htetro_opt.solvers.coverage import COVERAGE_METHODS

        return tuple(COVERAGE_METHODS)
    if task == "tile":
        from htetro_opt.solvers.tiling import TILING_METHODS

        return tuple(TILING_METHODS)
    from htetro_opt.solvers.sequencing import SEQUENCE_METHODS

    return tuple(SEQUENCE_METHODS)


def _canonical_method(task: str, method: str) -> str:
    return _PLAN_ALIASES.get(method, method) if task == "plan" else method


def _check_clearance(value, name: str) -> float:
    return check_real(value, name, minimum=0.0, maximum=10.0, include_maximum=False)


def _check_shapes(value, name: str) -> str:
    from htetro_opt.model.robot import SHAPES

    if isinstance(value, (list, tuple)) and all(isinstance(v, str) for v in value):
        value = "".join(value)
    if not isinstance(value, str) or not value or any(letter not in SHAPES for letter in value):
        raise ParameterError(f"{name} must be morphology letters of {''.join(SHAPES)} such as 'TZ', got {value!r}")
    return value


def _check_start(value, name: str) -> int | str:
    if value == "free":
        return "free"
    if isinstance(value, str) and value.strip().isdigit():  # the command line's "--start 1"
        value = int(value)
    try:
        return check_int(value, name, minimum=1)
    except ParameterError:
        raise ParameterError(f"{name} must be a tile label (a positive integer) or 'free', got {value!r}") from None


def _check_heat_weights(value, name: str) -> list[float]:
    from htetro_opt.problems.heat_costs import check_heat_weights  # the one check; heavy imports stay lazy

    return list(check_heat_weights(value, name))


def _check_element(value, name: str) -> str:
    from htetro_opt.solvers.grid_paths import HEAT_ELEMENTS

    if not isinstance(value, str) or value not in HEAT_ELEMENTS:
        raise ParameterError(f"{name} must be one of {', '.join(HEAT_ELEMENTS)} (the heat field's element), "
                             f"got {value!r}")
    return value


def _check_band(value, name: str) -> str | int:
    if value in ("auto", "full"):
        return value
    try:
        return check_int(value, name, minimum=1)
    except ParameterError:
        raise ParameterError(f"{name} must be 'auto', 'full' or a radius in cells (an integer ≥ 1), "
                             f"got {value!r}") from None


def _check_layers(value, name: str) -> str:
    """A coverage morphology set: ``"O,vI"`` or ``["O", "vI"]`` (any form of
    :func:`~htetro_opt.solvers.coverage.parse_layers`), as its layers' names joined by commas."""
    from htetro_opt.errors import UnknownShapeError
    from htetro_opt.solvers.coverage import parse_layers

    if not isinstance(value, (str, list, tuple)):
        raise ParameterError(f"{name} must be morphology layers such as 'O,vI,hI' or ['O', 'hI'], got {value!r}")
    try:
        return ",".join(layer.name for layer in parse_layers(value))
    except UnknownShapeError as err:
        raise ParameterError(f"{name}: {err.args[0]}") from None


def _check_stripes(value, name: str) -> int | list[int]:
    """Stripe widths: a width (an int, or ``"4"``) or widths bottom up (``[2, 3, 2]`` or ``"2,3,2"``),
    each a positive integer; whether they fit a map is checked against each scenario's height."""
    if isinstance(value, str):  # the command line's "--stripes 2,3,2"
        parts = [p.strip() for p in value.split(",")]
        if not all(p.isdigit() for p in parts):
            raise ParameterError(f"{name} must be a width or comma-separated widths such as '2,3,2', got {value!r}")
        value = int(parts[0]) if len(parts) == 1 else [int(p) for p in parts]
    if isinstance(value, (list, tuple)):
        if not value:
            raise ParameterError(f"{name} must name at least one width, got {value!r}")
        return [check_int(v, f"{name}[{i}]", minimum=1) for i, v in enumerate(value)]
    try:
        return check_int(value, name, minimum=1)
    except ParameterError:
        raise ParameterError(f"{name} must be a width (an integer ≥ 1) or a list of widths bottom up, "
                             f"got {value!r}") from None


def _check_choice(choices: Callable[[], Sequence[str]], what: str) -> Callable:
    """A check of an option that names one of ``choices()`` (loaded when checked: pymoo stays lazy)."""
    def check(value, name: str) -> str:
        known = tuple(choices())
        if not isinstance(value, str) or value not in known:
            raise ParameterError(f"{name} must be one of {', '.join(known)} ({what}), got {value!r}")
        return value
    return check


def _picks() -> tuple[str, ...]:
    from htetro_opt.algorithms import PICKS

    return tuple(PICKS)


def _convergence_measures() -> tuple[str, ...]:
    from htetro_opt.algorithms import CONVERGENCE_MEASURES

    return tuple(CONVERGENCE_MEASURES)


def _coverage_ends() -> tuple[str, ...]:
    from htetro_opt.solvers.coverage import ENDS

    return tuple(ENDS)


def _mopup_orders() -> tuple[str, ...]:
    from htetro_opt.solvers.coverage import MOPUP_ORDERS

    return tuple(MOPUP_ORDERS)


def _check_cover_start(value, name: str) -> str:
    if value not in ("scenario", "auto"):
        raise ParameterError(f"{name} must be 'scenario' (the roadmap's first and last poses) or 'auto' (the "
                             f"bottom-left pose of the first layer, a free end), got {value!r}")
    return value


def _check_weights(value, name: str) -> list[float]:
    from htetro_opt.problems import check_weights

    if isinstance(value, str):  # the command line's "--weights 0.4,0.2,0.2,0.2"
        try:
            value = [float(v) for v in value.split(",")]
        except ValueError:
            raise ParameterError(f"{name} must be four numbers a,b,c,d, got {value!r}") from None
    if not isinstance(value, (list, tuple)):
        raise ParameterError(f"{name} must be four numbers (a list, or 'a,b,c,d'), got {value!r}")
    values = [check_real(v, f"{name}[{i}]", minimum=0.0) for i, v in enumerate(value)]
    try:
        return [float(v) for v in check_weights(values)]
    except ParameterError as err:
        raise ParameterError(f"{name}: {err}") from None


_ALL = None  # an option every method of the task takes
_HTETRO_GA = ("htetro-ga", "htetro-ga-paper")  # the hTetro-GA's own sort: pymoo's algorithms have none
_PYMOO_GA = ("nsga2", "nsga3", "smsemoa", "agemoea")  # the conservative set is the hTetro-GA's own
_OPTIONS: dict[str, dict[str, tuple[Callable, str | None]]] = {
    # option: (check, which methods take it: None all, "exact" the graph searches, "heat" Do et al.
    # 2021's planner, "ga" the others, or a tuple of kinds and method names)
    "plan": {
        "clearance": (_check_clearance, _ALL),
        "diagonals": (check_bool, "exact"),
        "pop_size": (lambda v, n: check_int(v, n, minimum=2), "ga"),
        "max_gen": (lambda v, n: check_int(v, n, minimum=1), "ga"),
        "patience": (lambda v, n: check_int(v, n, minimum=1), "ga"),
        "max_length": (lambda v, n: check_int(v, n, minimum=1), "ga"),
        "convergence": (_check_choice(_convergence_measures, "the termination's measure of improvement"), "ga"),
        "pick": (_check_choice(_picks, "the front member each leg returns"), "ga"),
        "seed_exact": (check_bool, "ga"),
        "replan_window": (lambda v, n: check_int(v, n, minimum=0), "ga"),
        "replan_members": (lambda v, n: check_int(v, n, minimum=0), "ga"),
        "reach_share": (lambda v, n: check_real(v, n, minimum=0.0, maximum=1.0, include_minimum=False), _HTETRO_GA),
        "reach_patience": (lambda v, n: check_int(v, n, minimum=0), _HTETRO_GA),
        "polish_window": (lambda v, n: check_int(v, n, minimum=0), _HTETRO_GA),
        "conservative": (check_bool, _PYMOO_GA),
        "weights": (_check_heat_weights, "heat"),
        "t_max": (lambda v, n: check_real(v, n, minimum=0.0, include_minimum=False), "heat"),
        "element": (_check_element, "heat"),
        "monotone": (check_bool, "heat"),
        "band": (_check_band, "heat"),
    },
    "tile": {
        "shapes": (_check_shapes, _ALL),
        "overlap": (check_bool, _ALL),
        "shuffle": (check_bool, _ALL),
        "time_limit": (check_time_limit, _ALL),
    },
    "sequence": {
        "start": (_check_start, _ALL),
        "weights": (_check_weights, _ALL),
        "time_limit": (check_time_limit, _ALL),
        "shapes": (_check_shapes, _ALL),
    },
    "cover": {
        "shapes": (_check_layers, _ALL),
        "start": (_check_cover_start, _ALL),
        "clearance": (_check_clearance, _ALL),
        "stripes": (_check_stripes, "stripes"),
        "region_columns": (lambda v, n: check_int(v, n, minimum=1), "stripes"),
        "budget": (lambda v, n: check_int(v, n, minimum=1), "stripes"),
        "ends": (_check_choice(_coverage_ends, "where a stripe may be left"), "stripes"),
        "mopup": (_check_choice(_mopup_orders, "the order of the mop-up's targets"), ("stripes", "boustrophedon")),
        "time_limit": (check_time_limit, ("stripes", "tiling-tsp")),
    },
}
_REFERENCE_OPTIONS = {"plan": ("clearance", "diagonals"), "sequence": ("start", "weights", "shapes")}


_SCOPE_NAMES = {"exact": "the exact methods (dijkstra, astar)", "heat": "the heat planner (Do et al. 2021)",
                "ga": "the GA methods", _HTETRO_GA: "the hTetro-GA methods (htetro-ga, htetro-ga-paper)",
                _PYMOO_GA: "pymoo's algorithms (nsga2, nsga3, smsemoa, agemoea)",
                "stripes": "the stripes methods (stripes, stripes-paper)",
                ("stripes", "tiling-tsp"): "the stripes methods (stripes, stripes-paper) and tiling-tsp",
                ("stripes", "boustrophedon"): "the stripes methods (stripes, stripes-paper) and boustrophedon"}


def _takes(task: str, method: str, scope: str | tuple[str, ...] | None) -> bool:
    scopes = (scope,) if isinstance(scope, str) else scope
    return scope is None or _kind(task, method) in scopes or method in scopes


def _seeded(task: str, method: str, parameters: Mapping[str, Any]) -> bool:
    """Whether the method's result depends on a seed (else the trial runs once, seed None)."""
    if task == "plan":
        return _plan_kind(method) == "ga"
    if task == "tile":
        return bool(parameters.get("shuffle", False))
    if task == "cover":
        return False
    from htetro_opt.studies.le2018 import (
        STOCHASTIC,  # the sequencing methods that draw random numbers
    )

    return method in STOCHASTIC


# --- scenarios -------------------------------------------------------------------------------------
def _is_tileset(name: str) -> bool:
    """``sequence``'s rule, as on the command line: a ``.toml`` file or a bundled scenario is a
    scenario to tile first; a bundled tileset name or any other file a labelled tileset."""
    from htetro_opt.scenarios import list_scenarios, list_tilesets

    if name.endswith(".toml"):
        return False
    if name in list_tilesets():
        return True
    return name not in list_scenarios()


def _grid_scenario(name: str):
    from htetro_opt.errors import ScenarioError
    from htetro_opt.scenarios import Scenario, load_scenario

    scenario = load_scenario(name)
    if not isinstance(scenario, Scenario):
        raise ScenarioError(f"scenario {scenario.name!r} is continuous; this task needs a grid scenario")
    return scenario


def _resolve_scenario(task: str, name, base: Path | None, where: str) -> str:
    """The scenario's name if bundled, else its path (relative paths from the study file's folder),
    checked by loading it."""
    from htetro_opt.scenarios import (
        list_scenarios,
        list_tilesets,
        load_tileset,
        tileset_path,
    )

    if not isinstance(name, str) or not name:
        raise StudyError(f"{where} must be a scenario name or file path, got {name!r}")
    bundled = list_scenarios() + (list_tilesets() if task == "sequence" else [])
    resolved = name
    if "/" in name or name not in bundled:
        path = Path(name)
        if base is not None and not path.is_absolute():
            path = base / path
        if not path.is_file():
            kinds = "scenario or tileset" if task == "sequence" else "scenario"
            raise StudyError(f"{where}: unknown {kinds} {name!r}: not a bundled name ({', '.join(bundled)}) "
                             "nor a file")
        resolved = str(path.resolve())
    try:
        if task == "sequence" and _is_tileset(resolved):
            load_tileset(tileset_path(resolved))
        else:
            scenario = _grid_scenario(resolved)
            if task == "plan" and scenario.goal is None:
                raise StudyError(f"scenario {scenario.name!r} has no roadmap with a start and a goal to plan for")
    except HtetroError as err:
        raise StudyError(f"{where} {name!r}: {' '.join(str(err).split())}") from err
    return resolved


# --- the study -------------------------------------------------------------------------------------
@dataclass(frozen=True)
class MethodSpec:
    """One method of a study: its canonical name, the label its rows carry, its options (for every
    scenario, and per scenario on top of them), and the scenarios it runs on (None: all the study's)."""

    method: str
    label: str
    options: Mapping[str, Any] = field(default_factory=dict)
    per_scenario: Mapping[str, Mapping[str, Any]] = field(default_factory=dict)
    scenarios: tuple[str, ...] | None = None

    def runs_on(self, scenario: str) -> bool:
        """Whether the method runs on ``scenario`` (a study's resolved scenario)."""
        return self.scenarios is None or scenario in self.scenarios

    def parameters(self, scenario: str) -> dict:
        """The options of a trial on ``scenario``, its own overrides applied, sorted by name."""
        merged = {**self.options, **self.per_scenario.get(scenario, {})}
        return {k: merged[k] for k in sorted(merged)}

    def as_entry(self) -> dict:
        """The study-file entry of this method."""
        entry = {"method": self.method, "label": self.label, **self.options}
        if self.scenarios is not None:
            entry["scenarios"] = list(self.scenarios)
        if self.per_scenario:
            entry["per_scenario"] = {k: dict(v) for k, v in self.per_scenario.items()}
        return entry


@dataclass(frozen=True)
class Trial:
    """One run: a method with its parameters on a scenario with a seed (None: not seeded).

    ``kind`` is ``"trial"``, or ``"reference"`` for the exact optimum a study's gaps are measured
    against. :attr:`key` hashes every input, so that a trial is recognised in a results file.
    """

    task: str
    scenario: str
    method: str
    parameters: Mapping[str, Any]
    seed: int | None
    label: str
    metrics: tuple[str, ...] = ()
    kind: str = "trial"

    def inputs(self) -> dict:
        return _inputs(self.kind, self.task, self.scenario, self.method, self.label, self.seed, self.parameters,
                       self.metrics)

    @property
    def key(self) -> str:
        return _key(self.inputs())

    def head(self) -> dict:
        """The leading fields of this trial's record (its inputs, flattened)."""
        return _head(self.inputs())


@dataclass(frozen=True)
class Study:
    """Scenarios × methods × seeds of one task, checked as a whole when made.

    Parameters
    ----------
    name : str
        Names the results files (``<name>.jsonl``, ``.csv``, ``.md``): letters, digits, ``_.-``.
    task : {"plan", "tile", "sequence", "cover"}
    scenarios : sequence of str
        Bundled names or files (``sequence``: labelled tilesets too, or scenarios to tile first).
    methods : sequence of mapping or MethodSpec
        Each a study-file entry: ``method``, an optional ``label`` (default: the method's name, with
        its options when several entries share it), the verb's options, ``scenarios`` (optional: run
        it on these of the study's scenarios only) and ``per_scenario`` (scenario → options
        overriding them there).
    seeds : int or sequence of int
        N for seeds 0 … N−1, or the seeds themselves (default 1). Methods that take no seed run once.
    metrics : sequence of str
        Optional metrics of the task (:data:`METRICS`).
    description : str
    source : str, optional
        The study file, named in error messages; relative scenario paths start from its folder.

    Raises
    ------
    StudyError
        Naming the file (or study), the entry and the key of the first mistake.

    Examples
    --------
    >>> study = Study(name="demo", task="plan", scenarios=["three_slit"], seeds=2,
    ...               methods=[{"method": "exact"}, {"method": "htetro-ga", "pop_size": 10}])
    >>> [(t.label, t.seed) for t in study.trials()]
    [('exact', None), ('htetro-ga', 0), ('htetro-ga', 1)]
    >>> Study(name="d", task="plan", scenarios=["three_slit"], methods=[{"method": "astar", "pop_size": 10}])
    Traceback (most recent call last):
    ...
    htetro_opt.studies.runner.StudyError: study 'd', methods[0]: pop_size applies to the GA methods only, not to astar
    """

    name: str
    task: str
    scenarios: tuple[str, ...]
    methods: tuple[MethodSpec, ...]
    seeds: tuple[int, ...] = (0,)
    metrics: tuple[str, ...] = ()
    description: str = ""
    source: str | None = field(default=None, compare=False)

    def __post_init__(self) -> None:
        where = f"study file {self.source!r}" if self.source else f"study {self.name!r}"
        if not isinstance(self.name, str) or not _NAME.fullmatch(self.name):
            raise StudyError(f"{where}: name must be letters, digits, '_', '.' or '-' (it names the results "
                             f"files), got {self.name!r}")
        if self.task not in TASKS:
            raise StudyError(f"{where}: task must be one of {', '.join(TASKS)} (a command-line verb), "
                             f"got {self.task!r}")
        if not isinstance(self.description, str):
            raise StudyError(f"{where}: description must be a string, got {self.description!r}")
        base = Path(self.source).parent if self.source else None
        scenarios, written = _check_scenarios(self.task, self.scenarios, base, where)
        seeds = _check_seeds(self.seeds, f"{where}: seeds")
        metrics = _check_metrics(self.task, self.metrics, where)
        methods = _check_methods(self.task, self.methods, scenarios, written, where)
        for i, spec in enumerate(methods):
            _check_ga_metrics(self.task, spec.method, metrics, f"{where}, methods[{i}]")
        object.__setattr__(self, "scenarios", scenarios)
        object.__setattr__(self, "seeds", seeds)
        object.__setattr__(self, "metrics", metrics)
        object.__setattr__(self, "methods", methods)

    def with_seeds(self, seeds: int | Sequence[int]) -> Study:
        """The same study with other seeds (an int N: 0 … N−1)."""
        return replace(self, seeds=seeds)

    def trials(self) -> list[Trial]:
        """Every trial, scenario by scenario, method by method, seed by seed."""
        out = []
        for scenario in self.scenarios:
            for spec in self.methods:
                if not spec.runs_on(scenario):
                    continue
                parameters = spec.parameters(scenario)
                seeds = self.seeds if _seeded(self.task, spec.method, parameters) else (None,)
                out.extend(Trial(self.task, scenario, spec.method, parameters, seed, spec.label, self.metrics)
                           for seed in seeds)
        return out

    def references(self) -> dict[str, Trial]:
        """The reference trial (the exact optimum) of each trial that asks for a gap, by trial key (none
        for ``cover``, whose trials measure their gap to their own lower bound)."""
        if "gap" not in self.metrics or self.task not in _REFERENCE_OPTIONS:
            return {}
        return {trial.key: reference_trial(trial) for trial in self.trials()}


def reference_trial(trial: Trial) -> Trial:
    """The exact-optimum trial whose result ``trial``'s gap is measured against: the same scenario
    with the options that change the optimum (plan: clearance and the command set; sequence: start,
    weights, shapes).

    A plan's command set: an exact trial's ``diagonals``, none for a GA (its chromosomes have no
    diagonals), and the diagonals for the heat planner (``diagonals=True``), whose 17 commands
    (Do et al. 2021, Cheng et al. 2020's 11 plus the four diagonals) include them: its gap is then
    to the minimum-time plan over the same commands, 0 for a time-only plan on the optimal route.
    """
    method = "dijkstra" if trial.task == "plan" else "exact"
    parameters = {k: v for k, v in trial.parameters.items() if k in _REFERENCE_OPTIONS.get(trial.task, ())}
    if trial.task == "plan":
        kind = _plan_kind(trial.method)
        if kind == "heat":
            parameters["diagonals"] = True
        elif kind == "ga":
            parameters.pop("diagonals", None)
        parameters = {k: parameters[k] for k in sorted(parameters)}
    return Trial(trial.task, trial.scenario, method, parameters, None, "reference", (), "reference")


def _check_scenarios(task, scenarios, base, where) -> tuple[tuple[str, ...], dict[str, str]]:
    if isinstance(scenarios, str) or not isinstance(scenarios, Sequence) or not scenarios:
        raise StudyError(f"{where}: scenarios must be a non-empty list of scenario names or files, got {scenarios!r}")
    resolved, written = [], {}
    for i, name in enumerate(scenarios):
        path = _resolve_scenario(task, name, base, f"{where}: scenarios[{i}]")
        if path in resolved:
            raise StudyError(f"{where}: scenarios[{i}] {name!r} is listed twice")
        resolved.append(path)
        written[name] = written[path] = path
    return tuple(resolved), written


def _check_seeds(seeds, where: str) -> tuple[int, ...]:
    if isinstance(seeds, (str, bytes)) or not isinstance(seeds, (numbers.Integral, Sequence)) or \
            isinstance(seeds, bool) or (isinstance(seeds, Sequence) and not seeds):
        raise StudyError(f"{where} must be a positive integer N (seeds 0 … N−1) or a non-empty list of seeds, "
                         f"got {seeds!r}")
    try:
        if isinstance(seeds, numbers.Integral):
            return tuple(range(check_int(seeds, where, minimum=1)))
        out = tuple(check_int(s, f"{where}[{i}]", minimum=0) for i, s in enumerate(seeds))
    except ParameterError as err:
        raise StudyError(str(err)) from err
    if len(set(out)) < len(out):
        raise StudyError(f"{where} lists a seed twice: {list(out)}")
    return out


def _check_metrics(task, metrics, where) -> tuple[str, ...]:
    known = METRICS[task]
    if isinstance(metrics, str) or not isinstance(metrics, Sequence):
        raise StudyError(f"{where}: metrics must be a list of names ({', '.join(known) or 'none for ' + task}), "
                         f"got {metrics!r}")
    for i, metric in enumerate(metrics):
        if metric not in known:
            raise StudyError(f"{where}: metrics[{i}]: unknown metric {metric!r} for task {task}: expected "
                             f"{', '.join(known) if known else 'none (its records hold every metric)'}")
    return tuple(m for m in known if m in metrics)


def _check_ga_metrics(task, method, metrics, where) -> None:
    """Refuse a metric of the GAs' populations (:data:`_GA_METRICS`) for a method that has none."""
    for metric in metrics:
        if metric in _GA_METRICS and not _takes(task, method, "ga"):
            planner = "the heat planner" if _plan_kind(method) == "heat" else "an exact planner"
            raise StudyError(f"{where}: metric {metric!r} applies to the GA methods only, not to {method}: {planner} "
                             "has no population, hence no front (metric 'gap' compares a plan with the optimum)")


def _check_options(task, method, options, scenarios, where) -> dict:
    """A method's options, each checked; ``scenarios`` the study's scenarios the options apply to."""
    if not isinstance(options, Mapping):
        raise StudyError(f"{where} must be a table of options, got {options!r}")
    known = _OPTIONS[task]
    out = {}
    for key, value in options.items():
        if key == "seed":
            raise StudyError(f"{where}: seed: the study's `seeds` give every trial its seed; "
                             "a method entry takes none")
        if key not in known:
            raise StudyError(f"{where}: unknown option {key!r} for task {task}: its options are "
                             f"{', '.join(list(_ENTRY_KEYS) + list(known))}")
        check, scope = known[key]
        if not _takes(task, method, scope):
            implied = " (it always plans with the diagonals)" if key == "diagonals" and method in _HEAT_METHODS else ""
            raise StudyError(f"{where}: {key} applies to {_SCOPE_NAMES[scope]} only, not to {method}{implied}")
        if task == "cover" and key == "stripes":
            _check_stripes_fit(value, scenarios, where)
        if task == "sequence" and key == "shapes":
            tilesets = [s for s in scenarios if _is_tileset(s)]
            if tilesets:
                raise StudyError(f"{where}: shapes applies only to scenarios to tile, not to the tileset "
                                 f"{tilesets[0]!r} (give it under per_scenario)")
        try:
            out[key] = check(value, key)
        except ParameterError as err:
            raise StudyError(f"{where}: {err}") from err
    return out


def _check_stripes_fit(value, scenarios, where) -> None:
    """Stripe widths that fit every one of ``scenarios``: a width at most its height, widths summing to it."""
    from htetro_opt.solvers.coverage import stripe_widths

    try:
        value = _check_stripes(value, "stripes")
    except ParameterError as err:
        raise StudyError(f"{where}: {err}") from err
    for scenario in scenarios:
        grid = _grid_scenario(scenario)
        try:
            stripe_widths(value, grid.workspace.height)
        except ParameterError as err:
            raise StudyError(f"{where}: {err} (scenario {grid.name!r}, {grid.workspace.height} rows; give its "
                             "widths under per_scenario)") from err


def _check_methods(task, methods, scenarios, written, where) -> tuple[MethodSpec, ...]:
    if isinstance(methods, (str, Mapping)) or not isinstance(methods, Sequence) or not methods:
        raise StudyError(f"{where}: methods must be a non-empty list of method entries ([[methods]] tables), "
                         f"got {methods!r}")
    entries = [m.as_entry() if isinstance(m, MethodSpec) else m for m in methods]
    specs = []
    for i, entry in enumerate(entries):
        here = f"{where}, methods[{i}]"
        if not isinstance(entry, Mapping):
            raise StudyError(f"{here} must be a table with a method and its options, got {entry!r}")
        if "method" not in entry:
            raise StudyError(f"{here}: method is missing (one of {', '.join(_methods_of(task))})")
        name = entry["method"]
        if not isinstance(name, str) or name not in _methods_of(task):
            raise StudyError(f"{here}: unknown {task} method {name!r}: expected one of {', '.join(_methods_of(task))}")
        method = _canonical_method(task, name)
        label = entry.get("label")
        if label is not None and (not isinstance(label, str) or not label.strip()):
            raise StudyError(f"{here}: label must be a non-empty string, got {label!r}")
        own = _check_entry_scenarios(entry.get("scenarios"), scenarios, written, here)
        options = _check_options(task, method, {k: v for k, v in entry.items() if k not in _ENTRY_KEYS},
                                 scenarios if own is None else own, here)
        per_scenario = entry.get("per_scenario", {})
        if not isinstance(per_scenario, Mapping):
            raise StudyError(f"{here}: per_scenario must be a table of scenario → options, got {per_scenario!r}")
        overrides = {}
        for scenario, scenario_options in per_scenario.items():
            if scenario not in written:
                raise StudyError(f"{here}: per_scenario.{scenario}: {scenario!r} is not one of the study's "
                                 f"scenarios ({', '.join(map(repr, scenarios))})")
            if own is not None and written[scenario] not in own:
                raise StudyError(f"{here}: per_scenario.{scenario}: {scenario!r} is not one of the entry's "
                                 "scenarios, on which alone it runs")
            overrides[written[scenario]] = _check_options(task, method, scenario_options, [written[scenario]],
                                                          f"{here}, per_scenario.{scenario}")
        specs.append((name, label, method, options, overrides, own))
    names = [name for name, *_ in specs]
    out, labels = [], {}
    for i, (name, label, method, options, overrides, own) in enumerate(specs):
        if label is None:
            label = name
            if names.count(name) > 1 and options:
                label += " (" + ", ".join(f"{k}={_text(options[k])}" for k in sorted(options)) + ")"
        if label in labels:
            raise StudyError(f"{where}, methods[{i}]: label {label!r} is also methods[{labels[label]}]'s: "
                             "give each entry its own label")
        labels[label] = i
        out.append(MethodSpec(method, label, options, overrides, own))
    return tuple(out)


def _check_entry_scenarios(own, scenarios, written, where) -> tuple[str, ...] | None:
    """A method entry's ``scenarios``: some of the study's (resolved), in the study's order; None if not given."""
    if own is None:
        return None
    if isinstance(own, str) or not isinstance(own, Sequence) or not own:
        raise StudyError(f"{where}: scenarios must be a non-empty list of the study's scenarios, got {own!r}")
    chosen = set()
    for i, name in enumerate(own):
        if not isinstance(name, str) or name not in written:
            raise StudyError(f"{where}: scenarios[{i}] {name!r} is not one of the study's scenarios "
                             f"({', '.join(map(repr, scenarios))})")
        if written[name] in chosen:
            raise StudyError(f"{where}: scenarios[{i}] {name!r} is listed twice")
        chosen.add(written[name])
    return tuple(s for s in scenarios if s in chosen)


def _text(value) -> str:
    if isinstance(value, (list, tuple)):
        return ",".join(f"{v:g}" if isinstance(v, float) else str(v) for v in value)
    if isinstance(value, float):
        return f"{value:g}"
    return str(value)


# --- study files -----------------------------------------------------------------------------------
def _data_dir() -> Path:
    return Path(str(resources.files("htetro_opt.studies") / "data"))


def list_studies() -> list[str]:
    """Names of the bundled study files, sorted.

    Examples
    --------
    >>> {"small", "table4", "sequencing"} <= set(list_studies())
    True
    """
    return sorted(p.stem for p in _data_dir().glob("*.toml"))


def load_study(name_or_path: str | os.PathLike) -> Study:
    """Read a study: a bundled name (:func:`list_studies`) or a TOML file.

    Top-level keys: ``name`` (default: the file's stem), ``description``, ``task``, ``scenarios``,
    ``seeds``, ``metrics`` and the ``[[methods]]`` entries, see :class:`Study`.

    Raises
    ------
    StudyError
        If there is no such study, the file is not TOML, or anything in it is invalid (naming the
        file, the entry and the key).

    Examples
    --------
    >>> study = load_study("small")
    >>> study.task, study.scenarios, [m.label for m in study.methods], len(study.trials())
    ('plan', ('random', 'three_slit', 'h_shape'), ['dijkstra', 'htetro-ga'], 12)
    """
    if not isinstance(name_or_path, (str, os.PathLike)):
        raise StudyError(f"a study must be a bundled name or a file path, got {name_or_path!r}")
    bundled = _data_dir() / f"{name_or_path}.toml"
    if isinstance(name_or_path, str) and "/" not in name_or_path and bundled.is_file():
        path = bundled
    else:
        path = Path(name_or_path)
        if not path.is_file():
            raise StudyError(f"no study {str(name_or_path)!r}: not a bundled study ({', '.join(list_studies())}) "
                             "nor a file")
    where = f"study file {str(path)!r}"
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError) as err:
        raise StudyError(f"{where}: cannot read it: {getattr(err, 'strerror', None) or err}") from err
    except tomllib.TOMLDecodeError as err:
        raise StudyError(f"{where}: not valid TOML: {err}") from err
    for key in data:
        if key not in _TOP_KEYS:
            raise StudyError(f"{where}: unknown key {key!r}: a study file has {', '.join(_TOP_KEYS)}")
    for key in ("task", "scenarios", "methods"):
        if key not in data:
            raise StudyError(f"{where}: {key} is missing")
    return Study(name=data.get("name", path.stem), task=data["task"], scenarios=data["scenarios"],
                 methods=data["methods"], seeds=data.get("seeds", 1), metrics=data.get("metrics", ()),
                 description=data.get("description", ""), source=str(path))


# --- one trial -------------------------------------------------------------------------------------
def _inputs(kind, task, scenario, method, label, seed, parameters, metrics) -> dict:
    return {"kind": kind, "task": task, "scenario": scenario, "method": method, "label": label, "seed": seed,
            "parameters": {k: parameters[k] for k in sorted(parameters)}, "metrics": list(metrics)}


def _key(inputs: Mapping[str, Any]) -> str:
    text = json.dumps(inputs, sort_keys=True, separators=(",", ":"), ensure_ascii=True, allow_nan=False)
    return hashlib.sha256(text.encode("ascii")).hexdigest()


def _head(inputs: Mapping[str, Any]) -> dict:
    head = {"key": _key(inputs)}
    head.update({k: inputs[k] for k in ("kind", "task", "scenario", "method", "label", "seed")})
    head.update(inputs["parameters"])
    return head


def _finite(value):
    """A JSON-ready scalar, or list of them: numpy's as Python's, NaN and infinities as None."""
    if value is None or isinstance(value, (bool, str)):
        return value
    if isinstance(value, (list, tuple)):
        return [_finite(v) for v in value]
    if isinstance(value, numbers.Integral):
        return int(value)
    value = float(value)
    return value if math.isfinite(value) else None


def _tileset_of(scenario: str, shapes: str | None):
    from htetro_opt.scenarios import load_tileset, tileset_path
    from htetro_opt.solvers.tiling import tile_workspace

    if _is_tileset(scenario):
        return load_tileset(tileset_path(scenario))
    grid = _grid_scenario(scenario)
    return tile_workspace(grid.workspace, shapes=list(shapes) if shapes else None, name=grid.name)


def _plan(scenario, method, parameters, seed, metrics) -> tuple[dict, dict, float]:
    from htetro_opt.problems import FITNESS_NAMES
    from htetro_opt.solvers.grid_paths import plan_path

    grid = _grid_scenario(scenario)
    options = dict(parameters)
    if _seeded("plan", method, parameters):
        options["seed"] = seed
    if "hv_curve" in metrics:
        options["hv_reference"] = HV_REFERENCE
    plan = plan_path(grid.workspace, grid.roadmap, method=method, **options)
    reached = bool(plan.reached)
    out = {"reached": reached, "time": float(plan.time) if reached else None,
           "n_commands": len(plan.commands) if reached else None}
    if "objectives" in metrics:
        objectives = plan.objectives()
        out.update({k: objectives[k] if reached else None
                    for k in ("translations", "rotations", "shapeshifts", "path_length")})
    legs = plan.legs
    if "gap" in metrics and _plan_kind(method) == "ga":  # fastest_gap, beside the picked plan's gap
        out["fastest_time"] = sum(float(leg.selected["time"].time) for leg in legs) if reached else None
    if "generations" in metrics:
        out["generations"] = sum(leg.generations for leg in legs) if legs else None
        out["reach_generation"] = plan.reach_generation
        out["reach_time_s"] = sum(leg.reach_time_s for leg in legs) if legs and reached else None
    if "fitness" in metrics:
        fitness = [leg.selected["multi_objective"].fitness for leg in legs]
        out.update({name: sum(float(f[i]) for f in fitness) / len(fitness) if fitness else None
                    for i, name in enumerate(FITNESS_NAMES)})
    if "front" in metrics:  # a GA's plan has a leg, the failed one's included
        front = _fitness_rows([member.fitness for member in legs[-1].front], unique=True)
        out["front"], out["hv"] = front, hypervolume(front)
    if "history" in metrics:
        out["history"] = _fitness_rows(legs[-1].history, unique=False)
    if "hv_curve" in metrics:
        out["hv_curve"] = [round(float(v), 6) for v in legs[-1].hv_history]
    if "heat_fitness" in metrics:
        out.update(_heat_metrics(grid.workspace, plan, method, parameters))
    return out, {"commands": ",".join(plan.tokens)}, plan.runtime_s


def _heat_metrics(workspace, plan, method: str, parameters: Mapping[str, Any]) -> dict:
    """Metric ``heat_fitness``: Do et al. 2021's costs of any plan, and the morphologies it uses."""
    from htetro_opt.model.robot import STATE_NAMES
    from htetro_opt.problems import heat_fitness

    names = ("heat_f_t", "heat_f_sm", "heat_f_sf", "heat_f", "shapes_used")
    if not plan.reached:
        return dict.fromkeys(names)
    heat = _plan_kind(method) == "heat"
    weights = plan.info["weights"] if heat else _EQUAL_WEIGHTS
    costs = heat_fitness(workspace, plan.poses, plan.commands, t_max=parameters.get("t_max") if heat else None,
                         weights=weights)
    shapes = "".join(dict.fromkeys(STATE_NAMES[int(s)] for s in plan.poses[:, 2]))
    return {"heat_f_t": costs["f_t"], "heat_f_sm": costs["f_sm"], "heat_f_sf": costs["f_sf"], "heat_f": costs["f"],
            "shapes_used": shapes}


def _fitness_rows(fitness, *, unique: bool) -> list[list[float]]:
    """(f_gr, f_t, f_sm, f_sf) rows, rounded to 6 decimals, as lists (distinct and sorted if ``unique``)."""
    rows = np.round(np.asarray(fitness, dtype=float).reshape(-1, 4), _FRONT_DIGITS) + 0.0  # + 0.0: no -0.0
    if unique:
        rows = np.unique(rows, axis=0)
    return rows.tolist()


def _tile(scenario, method, parameters, seed) -> tuple[dict, dict, float]:
    from htetro_opt.model.robot import SHAPES
    from htetro_opt.scenarios import format_tileset
    from htetro_opt.solvers.tiling import tile_workspace

    grid = _grid_scenario(scenario)
    shapes = parameters.get("shapes")
    began = time.perf_counter()
    tileset = tile_workspace(grid.workspace, method=method, shapes=list(shapes) if shapes else None,
                             shuffle=parameters.get("shuffle", False), seed=seed,
                             time_limit=parameters.get("time_limit"), overlap=parameters.get("overlap", False),
                             name=grid.name)
    runtime = time.perf_counter() - began
    kinds = tileset.shapes
    out = {"tiles": len(tileset), "overlapping": tileset.overlapping, **{f"n_{s}": kinds.count(s) for s in SHAPES}}
    rows = (" ".join(row.split()) for row in format_tileset(tileset).split("\n"))
    return out, {"tileset": ";".join(rows)}, runtime


def _instance(scenario, parameters):
    from htetro_opt.problems import DEFAULT_BLOCK_WEIGHTS, SequencingInstance

    tileset = _tileset_of(scenario, parameters.get("shapes"))
    start = parameters.get("start", 1)
    return SequencingInstance.from_tileset(tileset, start=None if start == "free" else start,
                                           weights=parameters.get("weights", DEFAULT_BLOCK_WEIGHTS))


def _sequence(scenario, method, parameters, seed) -> tuple[dict, dict, float]:
    from htetro_opt.solvers.sequencing import sequence_waypoints

    instance = _instance(scenario, parameters)
    options = {} if seed is None else {"seed": seed}
    result = sequence_waypoints(instance, method=method, time_limit=parameters.get("time_limit"), **options)
    out = {"cost": float(result.cost), "waypoints": instance.n}
    return out, {"order": ",".join(str(t) for t in result.tiles)}, result.runtime_s


def coverage_bound(coverable: int, gain: int) -> int:
    """The lower bound on a coverage plan's action cost: ⌈(coverable − 4) / gain⌉, at least 0.

    The robot starts on 4 covered cells and no command adds more than ``gain`` new ones.

    Examples
    --------
    >>> coverage_bound(216, 2), coverage_bound(216, 4), coverage_bound(3, 4)
    (106, 53, 0)
    """
    return max(0, math.ceil((int(coverable) - 4) / int(gain)))


def _cover(scenario, method, parameters, metrics) -> tuple[dict, dict, float]:
    from htetro_opt.solvers.coverage import DEFAULT_LAYERS, LayerGraph, plan_coverage

    grid = _grid_scenario(scenario)
    options = {k: v for k, v in parameters.items() if k not in ("shapes", "start")}
    start = goal = None
    if parameters.get("start", "scenario") == "scenario" and grid.roadmap:  # as the command line's --start
        start, goal = grid.start, grid.goal
    plan = plan_coverage(grid.workspace, parameters.get("shapes", ",".join(DEFAULT_LAYERS)), method=method,
                         start=start, goal=goal, **options)
    coverable = int(plan.coverable.sum())
    # g of the layers the plan used (boustrophedon: the first); tiling-tsp's legs leave the layers
    gain = _TILING_GAIN if method == "tiling-tsp" else \
        LayerGraph(grid.workspace, plan.layers, clearance=parameters.get("clearance", 0.0)).gain
    bound = coverage_bound(coverable, gain)
    cost = plan.action_cost
    out = {"action_cost": cost, "time": plan.time, "complete": plan.complete, "free": int(plan.free.sum()),
           "coverable": coverable, "covered": int((plan.covered & plan.free).sum()),
           "uncoverable": len(plan.uncoverable), "lower_bound": bound}
    if "gap" in metrics:
        out["reference"] = bound
        out["gap"] = (cost - bound) / bound if bound > 0 else (0.0 if cost == 0 else None)
    out.update({"average_coverage_time": plan.average_coverage_time, "recovered_pct": plan.recovered_pct,
                "coverage_pct": plan.coverage_pct, "coverable_pct": plan.coverable_pct,
                "path_length": plan.path_length, "switches": plan.switches, "turns": plan.turns,
                "regions": plan.regions, "regions_optimal": plan.regions_optimal, "memo_hits": plan.memo_hits,
                "nodes": plan.nodes, "mopup_commands": plan.mopup_commands, "transit_commands": plan.transit_commands,
                "dag_cost": plan.dag_cost, "time_limited": plan.time_limited, "layers": ",".join(plan.layers)})
    s = plan.start
    solution = {"commands": ",".join(plan.tokens), "start_pose": [int(s.x), int(s.y), s.shape, int(s.heading)]}
    return out, solution, plan.runtime_s


def _record(head: dict, metrics: Mapping[str, Any], solution: Mapping[str, Any], runtime_s: float | None,
            error: str | None = None) -> dict:
    record = dict(head)
    record.update({k: _finite(v) for k, v in metrics.items()})
    record.update(solution)
    record["runtime_s"] = _finite(runtime_s)
    record["error"] = error
    record["version"] = __version__
    return record


def _check_trial_inputs(task, scenario, parameters) -> None:
    if task not in TASKS:
        raise ParameterError(f"task must be one of {', '.join(TASKS)}, got {task!r}")
    if not isinstance(scenario, str):
        raise ParameterError(f"scenario must be a bundled name or a file path (str), got {scenario!r}")
    if not isinstance(parameters, Mapping):
        raise ParameterError(f"parameters must be a mapping of option names to values, got {parameters!r}")


def run_trial(task: str, scenario: str, method: str, parameters: Mapping[str, Any], seed: int | None, *,
              label: str | None = None, metrics: Sequence[str] = ()) -> dict:
    """Run one trial and return its record: a flat, JSON-ready dict.

    Parameters
    ----------
    task : {"plan", "tile", "sequence", "cover"}
    scenario : str
        A bundled name or a file (``sequence``: a labelled tileset, or a scenario tiled first).
    method : str
        A method of the task's command-line verb (``plan`` also takes ``exact`` for ``dijkstra``).
    parameters : mapping
        The verb's options, as a study's method entry gives them (``plan``: clearance, diagonals,
        pop_size, max_gen, patience, max_length, convergence, pick, seed_exact, replan_window,
        replan_members, reach_share, reach_patience, polish_window, conservative, and the heat planner's weights,
        t_max, element, monotone, band; ``tile``: shapes, overlap, shuffle, time_limit; ``sequence``: start,
        weights, time_limit, shapes; ``cover``: shapes, start, clearance, stripes, region_columns,
        budget, time_limit).
    seed : int or None
        The seed of a seeded method (None for the others, which run with their default).
    label : str, keyword-only
        The name the trial's rows carry (default: ``method``).
    metrics : sequence of str, keyword-only
        Optional metrics (:data:`METRICS`); ``"gap"`` is added by :func:`run_study` from the
        reference trial (:func:`run_reference`), not here.

    Returns
    -------
    dict
        ``key`` (sha256 of the inputs), ``kind``, ``task``, ``scenario``, ``method``, ``label``,
        ``seed``, the parameters, the metrics, the solution (plan: ``commands``; tile: ``tileset``,
        the labelled rows top-down joined by ``;``; sequence: ``order``, tile labels; cover:
        ``commands`` from ``start_pose``, ``[x, y, shape, heading]``), ``runtime_s``
        (the solver's), ``error`` (None) and ``version``.

    Raises
    ------
    HtetroError
        Whatever the solver raises on this scenario (:func:`run_study` records it as the trial's error).

    Examples
    --------
    >>> record = run_trial("plan", "three_slit", "dijkstra", {}, None)
    >>> record["reached"], record["time"], record["commands"].split(",")[:3]
    (True, 33.0, ['x+', 'x+', 'x+'])
    """
    _check_trial_inputs(task, scenario, parameters)
    if not isinstance(method, str):
        raise ParameterError(f"method must be a method name, got {method!r}")
    if label is not None and not isinstance(label, str):
        raise ParameterError(f"label must be a string or None, got {label!r}")
    method = _canonical_method(task, method)
    try:
        metrics = _check_metrics(task, metrics, "run_trial")
        _check_ga_metrics(task, method, metrics, "run_trial")
    except StudyError as err:
        raise ParameterError(str(err)) from None
    head = _head(_inputs("trial", task, scenario, method, method if label is None else label, seed, parameters,
                         metrics))
    if task == "plan":
        values, solution, runtime = _plan(scenario, method, parameters, seed, metrics)
    elif task == "tile":
        values, solution, runtime = _tile(scenario, method, parameters, seed)
    elif task == "cover":
        values, solution, runtime = _cover(scenario, method, parameters, metrics)
    else:
        values, solution, runtime = _sequence(scenario, method, parameters, seed)
    return _record(head, values, solution, runtime)


def run_reference(task: str, scenario: str, parameters: Mapping[str, Any]) -> dict:
    """The exact optimum a study's gaps are measured against, as a record (``kind`` "reference").

    ``plan``: Dijkstra's minimum-time plan (``reached``, ``time``, ``n_commands``, ``commands``);
    ``sequence``: the CP-SAT optimum (``cost``, ``waypoints``, ``optimal``, ``order``), ``cost``
    None beyond :data:`~htetro_opt.solvers.sequencing.EXACT_AUTO_LIMIT` waypoints, where no optimum
    is proven.

    Examples
    --------
    >>> record = run_reference("sequence", "paper_6x6_fig13a", {})
    >>> round(record["cost"], 6), record["optimal"], record["order"]
    (17.190762, True, '1,2,3,4,9,7,6,8,5')
    """
    _check_trial_inputs(task, scenario, parameters)
    if task not in _REFERENCE_OPTIONS:
        raise ParameterError(f"task {task!r} has no exact reference (plan and sequence have; a cover trial "
                             "records its own lower bound)")
    trial = reference_trial(Trial(task, scenario, "dijkstra" if task == "plan" else "exact", parameters, None,
                                  "reference"))
    if task == "plan":
        values, solution, runtime = _plan(scenario, trial.method, trial.parameters, None, ())
        return _record(trial.head(), values, solution, runtime)
    from htetro_opt.solvers.sequencing import EXACT_AUTO_LIMIT, sequence_waypoints

    instance = _instance(scenario, trial.parameters)
    if instance.n > EXACT_AUTO_LIMIT:
        return _record(trial.head(), {"cost": None, "waypoints": instance.n, "optimal": False}, {"order": None}, None)
    result = sequence_waypoints(instance, method="exact")
    values = {"cost": float(result.cost), "waypoints": instance.n, "optimal": bool(result.info.get("optimal"))}
    return _record(trial.head(), values, {"order": ",".join(str(t) for t in result.tiles)}, result.runtime_s)


def _with_gap(record: dict, reference: Mapping[str, Any] | None) -> dict:
    """``record`` with ``reference`` and ``gap`` (relative, to the exact optimum) after its metrics."""
    if record.get("error") is not None:
        return record
    if record["task"] == "plan":
        value = record.get("time")
        best = reference.get("time") if reference and reference.get("reached") else None
    else:
        value = record.get("cost")
        best = reference.get("cost") if reference and reference.get("optimal") else None
    gaps = {"gap": _relative_gap(value, best)}
    if "fastest_time" in record:
        gaps["fastest_gap"] = _relative_gap(record["fastest_time"], best)
    out = {}
    for k, v in record.items():
        if k == "runtime_s":
            out["reference"] = best
            out.update(gaps)
        out[k] = v
    return out


def _relative_gap(value, best) -> float | None:
    """(value − best) / best; None where either is missing (or best is 0 and value is not)."""
    if value is None or best is None:
        return None
    return _finite((value - best) / best if best > 0 else (0.0 if value == best else None))


# --- executors -------------------------------------------------------------------------------------
def _attempts(function: Callable, args: tuple, retries: int) -> tuple[str, Any]:
    """Run ``function(*args)`` up to ``retries + 1`` times: ("ok", record) or ("error", "Type: message").

    Errors travel as text: an exception of a user's trial function need not pickle."""
    for _ in range(retries + 1):
        try:
            return "ok", function(*args)
        except Exception as err:  # noqa: BLE001 -- any failure of a trial is its result, recorded
            error = _error_text(err)
    return "error", error


def _error_text(err: BaseException) -> str:
    return f"{type(err).__name__}: {' '.join(str(err).split())}"


Call = tuple[Trial, Callable]


def _serial(calls: Sequence[Call], retries: int) -> Iterator[tuple[Trial, tuple[str, Any]]]:
    for trial, function in calls:
        yield trial, _attempts(function, (), retries)


def _processes(calls: Sequence[Call], retries: int, workers: int | None) -> Iterator[tuple[Trial, tuple[str, Any]]]:
    pool = ProcessPoolExecutor(max_workers=min(workers or os.cpu_count() or 1, len(calls)))
    finished = False
    try:
        futures = {pool.submit(_attempts, function, (), retries): trial for trial, function in calls}
        for future in as_completed(futures):
            trial = futures.pop(future)
            try:
                outcome = future.result()
            except BrokenProcessPool as err:
                raise WorkerLost(f"a worker process died while running {trial.scenario} {trial.label} "
                                 f"seed {trial.seed} ({err}); the trials recorded so far are kept: "
                                 "resume continues the study") from err
            yield trial, outcome
        finished = True
    finally:
        pool.shutdown(wait=finished, cancel_futures=True)


@contextmanager
def _dask_client(scheduler, workers: int | None):
    try:
        from distributed import Client, LocalCluster
    except ImportError as err:
        raise ParameterError("executor 'dask' needs dask.distributed: pip install 'htetro-opt[dask]'") from err
    if isinstance(scheduler, Client):  # the caller's: theirs to close
        yield scheduler
        return
    import logging

    cluster = None
    try:
        if scheduler is None:
            cluster = LocalCluster(n_workers=workers, threads_per_worker=1, dashboard_address=":0",
                                   silence_logs=logging.ERROR)
            client = Client(cluster)
        else:
            client = Client(scheduler, timeout="10s")
    except (OSError, TimeoutError) as err:
        if cluster is not None:
            cluster.close()
        where = "a local Dask cluster" if scheduler is None else f"the Dask scheduler {scheduler!r}"
        raise ParameterError(f"cannot connect to {where}: {err}") from err
    try:
        yield client
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def _dask(calls: Sequence[Call], retries: int, client) -> Iterator[tuple[Trial, tuple[str, Any]]]:
    from distributed import as_completed as dask_completed

    futures = {}
    run = uuid.uuid4().hex[:8]  # a key of this run's own: an earlier run's failed task may linger on the cluster
    for trial, function in calls:
        # references first: the gaps of the trials wait for them
        future = client.submit(function, key=f"{trial.kind}-{trial.key[:16]}-{run}", retries=retries,
                               priority=1 if trial.kind == "reference" else 0)
        futures[future] = trial
    try:
        for future in dask_completed(list(futures)):
            trial = futures.pop(future)
            if future.status == "finished":
                outcome = ("ok", future.result())
            else:
                error = future.exception() if future.status == "error" else None
                outcome = ("error", _error_text(error) if error is not None else f"Cancelled: {future.status}")
            future.release()
            yield trial, outcome
    finally:
        for future in futures:
            future.cancel()


def _dashboard(client) -> str | None:
    try:
        return client.dashboard_link
    except (KeyError, AttributeError):  # a scheduler started without its dashboard
        return None


# --- results files ---------------------------------------------------------------------------------
def read_records(path: str | os.PathLike, *, repair: bool = False) -> list[dict]:
    """The records of a results file (JSON Lines), in file order.

    A last line without its newline was torn by a process killed while writing it: it is left out,
    and with ``repair`` cut from the file.

    Raises
    ------
    StudyError
        If a complete line is not a record (naming the file and the line).
    OSError
        If the file cannot be read.
    """
    if not isinstance(path, (str, os.PathLike)):
        raise ParameterError(f"path must be a results file path, got {path!r}")
    path = Path(path)
    data = path.read_bytes()
    lines = data.split(b"\n")
    torn = lines.pop()
    records = []
    for number, line in enumerate(lines, start=1):
        try:
            record = json.loads(line)
        except ValueError:
            record = None
        if not isinstance(record, dict) or not isinstance(record.get("key"), str):
            raise StudyError(f"results file {str(path)!r}, line {number}: not a trial record "
                             f"({line[:60].decode('utf-8', 'replace')!r}…)")
        records.append(record)
    if torn and repair:
        with open(path, "r+b") as handle:
            handle.truncate(len(data) - len(torn))
            handle.flush()
            os.fsync(handle.fileno())
    return records


@contextmanager
def _appender(path: Path | None) -> Iterator[Callable[[Mapping[str, Any]], None]]:
    """A function appending one JSON line per record, flushed and synced, so that a kill loses at
    most the line being written (dropped by the next resume); None: records are not kept."""
    if path is None:
        yield lambda record: None
        return
    try:
        handle = open(path, "a", encoding="utf-8")  # noqa: SIM115 -- open for the whole run
    except OSError as err:
        raise OutputError(f"cannot write results file {str(path)!r}: {err.strerror or err}") from err

    def append(record: Mapping[str, Any]) -> None:
        handle.write(json.dumps(record, ensure_ascii=False, separators=(",", ":"), allow_nan=False) + "\n")
        handle.flush()
        os.fsync(handle.fileno())

    with handle:
        yield append


def _folder(out) -> Path | None:
    if out is None:
        return None
    if not isinstance(out, (str, os.PathLike)):
        raise ParameterError(f"out must be a folder path or None, got {out!r}")
    folder = Path(out)
    if folder.exists() and not folder.is_dir():
        raise OutputError(f"cannot write the study's results in {str(folder)!r}: it is a file, not a folder")
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as err:
        raise OutputError(f"cannot create the results folder {str(folder)!r}: {err.strerror or err}") from err
    return folder


# --- running a study -------------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class StudyRun:
    """What :func:`run_study` did: the study's records (in trial order, resumed ones included), its
    summary, the results file, the Dask dashboard, and counts."""

    study: Study
    records: list[dict]
    references: list[dict]
    summary: list[dict]
    path: Path | None
    dashboard: str | None = None
    resumed: int = 0
    failed: int = 0

    def as_dict(self) -> dict:
        """JSON-ready (for ``--json``)."""
        return {"study": self.study.name, "task": self.study.task,
                "path": None if self.path is None else str(self.path), "dashboard": self.dashboard,
                "trials": len(self.records), "resumed": self.resumed, "failed": self.failed,
                "summary": self.summary, "records": self.records, "references": self.references}


def _is_client(value) -> bool:
    try:
        from distributed import Client
    except ImportError:
        return False
    return isinstance(value, Client)


def _check_run_options(executor, workers, scheduler, retries, resume, out) -> None:
    if executor not in EXECUTORS:
        raise ParameterError(f"executor must be one of {', '.join(EXECUTORS)}, got {executor!r}")
    check_int(workers, "workers", minimum=1, allow_none=True)
    check_int(retries, "retries", minimum=0)
    check_bool(resume, "resume")
    if workers is not None and executor == "serial":
        raise ParameterError("workers applies to the processes and dask executors, not to serial")
    if scheduler is not None:
        if executor != "dask":
            raise ParameterError(f"scheduler applies to the dask executor only, not to {executor}")
        if workers is not None:
            raise ParameterError("workers applies to a local Dask cluster, not to one joined at a scheduler address")
        if not isinstance(scheduler, str) and not _is_client(scheduler):
            raise ParameterError(f"scheduler must be an address such as 'tcp://127.0.0.1:8786' or a "
                                 f"distributed.Client, got {scheduler!r}")
    if resume and out is None:
        raise ParameterError("resume needs out, the folder of the results file to resume")


def run_study(study: Study | str | os.PathLike, *, out: str | os.PathLike | None = None,
              executor: str = "processes", workers: int | None = None, scheduler=None,
              seeds: int | Sequence[int] | None = None, resume: bool = False, retries: int = 0,
              progress=None, trial: Callable | None = None) -> StudyRun:
    """Run every trial of a study, recording each as it finishes.

    Parameters
    ----------
    study : Study, or str or path
        A study, or a bundled study's name or a study file (:func:`load_study`).
    out : str or path, optional, keyword-only
        Folder of the results (created if missing): ``<name>.jsonl``, one line per trial, and the
        summary ``<name>.csv`` and ``<name>.md`` at the end. None: records are only returned.
    executor : {"serial", "processes", "dask"}, keyword-only
        ``processes`` (default): a local process pool; ``dask``: a ``distributed`` cluster.
    workers : int, optional, keyword-only
        Processes of the pool, or workers of a local Dask cluster (default: the machine's cores).
    scheduler : str or distributed.Client, optional, keyword-only
        ``dask`` only: join the cluster of this scheduler address (``"tcp://HOST:PORT"``), or run
        on this client. Default: start a local cluster for the run.
    seeds : int or sequence of int, optional, keyword-only
        Override the study's seeds (N: 0 … N−1).
    resume : bool, keyword-only
        Keep the trials already recorded in ``out``'s results file and run the others. Without it,
        a results file that holds records is an error (rather than overwritten).
    retries : int, keyword-only
        Re-run a trial that raised up to this many times before recording its error.
    progress : callable, optional, keyword-only
        ``progress(done, total, note)`` after each trial (:mod:`htetro_opt._progress`); the note
        names the last trial and counts the failures so far (and the Dask dashboard at the start).
    trial : callable, optional, keyword-only
        A module-level function with :func:`run_trial`'s signature to run instead (benchmarks,
        tests); the references stay :func:`run_reference`.

    Returns
    -------
    StudyRun

    Raises
    ------
    StudyError, ParameterError
        On an invalid study or option, before any trial runs and before any file is written.
    OutputError
        If the results cannot be written, or ``out`` already holds this study's results and
        ``resume`` is off.
    WorkerLost
        If a worker process of the pool died; the records so far are kept.

    Examples
    --------
    >>> study = Study(name="demo", task="plan", scenarios=["three_slit"], methods=[{"method": "dijkstra"}])
    >>> run = run_study(study, executor="serial")
    >>> [(r["label"], r["reached"], r["time"]) for r in run.records]
    [('dijkstra', True, 33.0)]
    >>> run.summary[0]["success_rate"], run.summary[0]["time_mean"]
    (1.0, 33.0)
    """
    study = study if isinstance(study, Study) else load_study(study)
    if seeds is not None:
        study = study.with_seeds(seeds)
    _check_run_options(executor, workers, scheduler, retries, resume, out)
    progress = check_progress(progress)
    if trial is not None and not callable(trial):
        raise ParameterError(f"trial must be a function like run_trial, got {trial!r}")
    function = run_trial if trial is None else trial

    trials = study.trials()
    references_of = study.references()
    references = list({ref.key: ref for ref in references_of.values()}.values())
    folder = _folder(out)
    path = None if folder is None else folder / f"{study.name}.jsonl"
    recorded: dict[str, dict] = {}
    if path is not None and path.exists():
        existing = read_records(path, repair=resume)
        if existing and not resume:
            raise OutputError(f"results file {str(path)!r} already holds {len(existing)} records: resume continues "
                              "the study; remove the file to start it over")
        for record in existing:
            recorded.setdefault(record["key"], record)

    wanted = {t.key for t in trials} | {r.key for r in references}
    resumed = sum(key in recorded for key in wanted)
    todo = [r for r in references if r.key not in recorded] + [t for t in trials if t.key not in recorded]
    calls = [(t, _bind(t, function)) for t in todo]
    total, done = len(wanted), resumed
    failed = sum(recorded[k].get("error") is not None for k in wanted if k in recorded)
    waiting: dict[str, list[dict]] = {}  # reference key -> trial records waiting for it

    def finish(record: dict) -> None:
        nonlocal done, failed
        append(record)
        recorded[record["key"]] = record
        done += 1
        failed += record.get("error") is not None
        note = f"{record['scenario']} {record['label']}" + ("" if record["seed"] is None else f" seed {record['seed']}")
        report(progress, done, total, f"{note}; {failed} failed")

    report(progress, done, total, f"{resumed} recorded before" if resumed else "")
    runner = _outcomes(calls, executor, workers, scheduler, retries)
    with _appender(path) as append, runner as (outcomes, dashboard):
        if dashboard:
            report(progress, done, total, f"Dask dashboard: {dashboard}")
        for item, (status, value) in outcomes:
            record = value if status == "ok" else _record(item.head(), {}, {}, None, value)
            if item.kind == "reference":
                finish(record)
                for pending in waiting.pop(item.key, []):
                    finish(_with_gap(pending, record))
                continue
            if item.key in references_of:
                reference = references_of[item.key].key
                if reference not in recorded:
                    waiting.setdefault(reference, []).append(record)
                    continue
                record = _with_gap(record, recorded[reference])
            finish(record)

    records = [recorded[t.key] for t in trials]
    summary = summarise(records)
    if folder is not None:
        write_summary(summary, folder, name=study.name)
    return StudyRun(study, records, [recorded[r.key] for r in references], summary, path, dashboard,
                    resumed, failed)


def _bind(trial: Trial, function: Callable) -> Callable:
    """The call of one trial, picklable (a partial of a module-level function)."""
    if trial.kind == "reference":
        return functools.partial(run_reference, trial.task, trial.scenario, trial.parameters)
    return functools.partial(function, trial.task, trial.scenario, trial.method, trial.parameters, trial.seed,
                             label=trial.label, metrics=trial.metrics)


@contextmanager
def _outcomes(calls, executor, workers, scheduler, retries):
    """(iterator of (trial, outcome) in completion order, the Dask dashboard or None)."""
    if not calls:
        yield iter(()), None
    elif executor == "serial":
        yield _serial(calls, retries), None
    elif executor == "processes":
        outcomes = _processes(calls, retries, workers)
        try:
            yield outcomes, None
        finally:
            outcomes.close()
    else:
        with _dask_client(scheduler, workers) as client:
            outcomes = _dask(calls, retries, client)
            try:
                yield outcomes, _dashboard(client)
            finally:
                outcomes.close()


# --- multi-objective metrics -----------------------------------------------------------------------
def _objectives(front, what: str) -> np.ndarray:
    """Fitness rows [f_gr, f_t, f_sm, f_sf] as pymoo's minimisation objectives, shape (n, 4)."""
    try:
        fitness = np.asarray(front, dtype=float)
    except (TypeError, ValueError):
        fitness = None
    if fitness is None or not (fitness.ndim == 2 and fitness.shape[1] == 4 or fitness.size == 0) \
            or not np.isfinite(fitness).all():
        raise ParameterError(f"{what} must be rows of four finite fitnesses [f_gr, f_t, f_sm, f_sf], "
                             f"got {front!r:.80}")
    return -fitness.reshape(-1, 4)


def hypervolume(front) -> float:
    """The hypervolume of a front of fitnesses, against the fixed reference point :data:`HV_REFERENCE`.

    Parameters
    ----------
    front : array-like, shape (n, 4)
        [f_gr, f_t, f_sm, f_sf] rows (fitnesses, maximised), as a record's ``front``.

    Returns
    -------
    float
        pymoo's ``HV`` of −front: the volume of the region of the minimisation space dominated by
        the front and dominating :data:`HV_REFERENCE`; 0 for an empty front. At most 2.

    Raises
    ------
    ParameterError
        If ``front`` is not rows of four finite numbers.

    Examples
    --------
    One point spans a box to the reference point: 1 × (0.5 + 1) × 0.5 × 0.5; a second one adds its
    own box (1 × 1 × 1 × 1) less their overlap (1 × 1 × 0.5 × 0.5):

    >>> hypervolume([[1.0, 0.5, 0.5, 0.5]])
    0.375
    >>> hypervolume([[1.0, 0.5, 0.5, 0.5], [1.0, 0.0, 1.0, 1.0]])
    1.125
    """
    from pymoo.indicators.hv import HV

    F = _objectives(front, "front")
    if len(F) == 0:
        return 0.0
    return float(HV(ref_point=np.array(HV_REFERENCE))(F))


def _pool(record: Mapping[str, Any]) -> tuple:
    """The trials whose fronts are compared: one scenario, one fitness definition (clearance changes the
    moves and safety, max_length the f_t scale; clearance 0 is the default)."""
    clearance = record.get("clearance")
    return (record.get("task"), record.get("scenario"), 0.0 if clearance is None else float(clearance),
            record.get("max_length"))


def front_metrics(records: Iterable[Mapping[str, Any]]) -> list[dict]:
    """The records, those with a ``front`` given ``igd_plus``: IGD+ against their scenario's reference front.

    The reference front of a scenario is the union of the fronts of all its records (every method
    and seed; records of another ``clearance`` or ``max_length`` are another problem, pooled apart),
    reduced to its leading front (:func:`~htetro_opt.algorithms.leading_front`: the goal-reaching
    points' non-dominated set, or all points' when none reaches the goal). IGD+ (pymoo's
    ``IGDPlus``) is the mean, over the reference points z, of the distance to the nearest front
    point a counting only where a is worse: min_a ‖max(a − z, 0)‖ in the minimisation space
    F = −(f_gr, f_t, f_sm, f_sf). The result depends on the records only, not on their order.

    Parameters
    ----------
    records : iterable of dict
        Trial records (references and records without a front are returned unchanged).

    Returns
    -------
    list of dict
        New dicts, in order; ``igd_plus`` follows ``hv``.

    Raises
    ------
    ParameterError
        If a record's ``front`` is not rows of four finite fitnesses.

    Examples
    --------
    >>> records = [{"task": "plan", "scenario": "a", "front": [[1.0, 0.5, 0.5, 0.5]], "hv": 0.375},
    ...            {"task": "plan", "scenario": "a", "front": [[1.0, 0.5, 0.9, 0.5]], "hv": 0.675}]
    >>> [round(r["igd_plus"], 6) for r in front_metrics(records)]
    [0.4, 0.0]
    """
    from pymoo.indicators.igd_plus import IGDPlus

    from htetro_opt.algorithms import leading_front

    records = _check_rows(records, "records")
    objectives: list[np.ndarray | None] = []
    pools: dict[tuple, list[np.ndarray]] = {}
    for i, record in enumerate(records):
        front = record.get("front") if record.get("kind", "trial") != "reference" else None
        F = None if front is None else _objectives(front, f"records[{i}]['front']")
        objectives.append(F)
        if F is not None and len(F):
            pools.setdefault(_pool(record), []).append(F)
    references = {}
    for pool, fronts in pools.items():
        union = np.unique(np.vstack(fronts), axis=0)  # sorted: the same for any order of the records
        references[pool] = union[leading_front(union)]
    out = []
    for record, F in zip(records, objectives):
        if F is None:
            out.append(dict(record))
            continue
        value = float(IGDPlus(references[_pool(record)])(F)) if len(F) else None
        row = {}
        for k, v in record.items():
            if k != "igd_plus":
                row[k] = v
            if k == "hv":
                row["igd_plus"] = value
        row.setdefault("igd_plus", value)
        out.append(row)
    return out


# --- summaries -------------------------------------------------------------------------------------
def _success(record: Mapping[str, Any]) -> bool:
    return record.get("error") is None and record.get("reached") is not False


def summarise(records: Iterable[Mapping[str, Any]]) -> list[dict]:
    """One row per scenario × method (label) of trial records (references left out), in order of
    first appearance.

    Each row holds ``task``, ``scenario``, ``label``, ``method``, ``runs``, ``errors``,
    ``successes`` (no error, and the goal reached where the task has one) and ``success_rate``,
    ``reference`` (the exact optimum, where the study measured gaps), and for each numeric metric
    present in the records (``runtime_s`` included) ``<metric>_mean``, ``<metric>_std`` (sample
    standard deviation, None for one value) and ``<metric>_median``, over the runs that measured it.
    Records with a ``front`` (metric ``"front"``) are first given their ``igd_plus`` against all
    the records' fronts (:func:`front_metrics`), so that the rows hold ``hv_*`` and ``igd_plus_*``.

    Examples
    --------
    >>> rows = summarise([
    ...     {"task": "plan", "scenario": "a", "label": "ga", "method": "htetro-ga", "reached": True, "time": 30.0},
    ...     {"task": "plan", "scenario": "a", "label": "ga", "method": "htetro-ga", "reached": False, "time": None},
    ...     {"task": "plan", "scenario": "a", "label": "ga", "method": "htetro-ga", "error": "TilingError: no"},
    ... ])
    >>> rows[0]["runs"], rows[0]["errors"], rows[0]["success_rate"], rows[0]["time_mean"], rows[0]["time_median"]
    (3, 1, 0.3333333333333333, 30.0, 30.0)
    """
    records = _check_rows(records, "records")
    records = front_metrics(r for r in records if r.get("kind", "trial") != "reference")
    fields = [k for task in TASKS if any(r.get("task") == task for r in records) for k in _METRIC_FIELDS[task]]
    numeric = [k for k in dict.fromkeys(fields + ["runtime_s"])
               if k != "reference" and any(_is_number(r.get(k)) for r in records)]
    rows = []
    for (task, scenario, label), group in group_records(records, ["task", "scenario", "label"]).items():
        successes = sum(_success(r) for r in group)
        references = [r["reference"] for r in group if r.get("reference") is not None]
        row: dict[str, Any] = {
            "task": task, "scenario": scenario, "label": label, "method": group[0].get("method"),
            "runs": len(group), "errors": sum(r.get("error") is not None for r in group),
            "successes": successes, "success_rate": successes / len(group),
            "reference": references[0] if references else None,
        }
        for name in numeric:
            values = values_of(group, name)
            row[f"{name}_mean"], row[f"{name}_std"] = mean_std(values)
            row[f"{name}_median"] = float(statistics.median(values)) if values else None
        rows.append(row)
    return rows


def _check_rows(rows, name: str) -> list:
    if isinstance(rows, (str, bytes, Mapping)) or not isinstance(rows, Iterable):
        raise ParameterError(f"{name} must be an iterable of records (dicts), got {rows!r}")
    rows = list(rows)
    for i, row in enumerate(rows):
        if not isinstance(row, Mapping):
            raise ParameterError(f"{name}[{i}] must be a record (a dict), got {row!r}")
    return rows


def _is_number(value) -> bool:
    return isinstance(value, numbers.Real) and not isinstance(value, bool)


def _cell(value) -> str:
    if value is None:
        return ""
    return repr(float(value)) if isinstance(value, float) else str(value)


def rows_csv(summary: Sequence[Mapping[str, Any]]) -> str:
    """Rows of values as CSV text: the union of their keys as columns, in first-seen order; floats
    written exactly (``repr``), None as an empty cell."""
    fields: list[str] = []
    for row in summary:
        fields += [k for k in row if k not in fields]
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(fields)
    for row in summary:
        writer.writerow([_cell(row.get(k)) for k in fields])
    return buffer.getvalue()


def markdown_summary(summary: Sequence[Mapping[str, Any]]) -> str:
    metrics = []
    for row in summary:
        metrics += [k[:-5] for k in row if k.endswith("_mean") and k[:-5] not in metrics]
    metrics = [m for m in metrics if any(row.get(f"{m}_mean") is not None for row in summary)]
    header = ["scenario", "method", "runs", "success", "reference"] + [f"{m} mean ± std (median)" for m in metrics]
    lines = ["| " + " | ".join(header) + " |", "|" + "|".join(["---", "---"] + ["---:"] * (len(header) - 2)) + "|"]
    for row in summary:
        cells = [str(row["scenario"]), str(row["label"]), str(row["runs"]), f"{row['successes']}/{row['runs']}",
                 "–" if row.get("reference") is None else f"{row['reference']:g}"]
        for m in metrics:
            mean, median = row.get(f"{m}_mean"), row.get(f"{m}_median")
            cells.append(format_mean_std(mean, row.get(f"{m}_std"), digits=3)
                         + ("" if median is None else f" ({median:.3f})"))
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def write_summary(summary: Sequence[Mapping[str, Any]], folder: str | os.PathLike, *,
                  name: str = "summary") -> tuple[Path, Path]:
    """Write a :func:`summarise` table as ``folder/<name>.csv`` and ``folder/<name>.md``, atomically.

    Returns
    -------
    (Path, Path)
        The CSV and Markdown files.

    Raises
    ------
    OutputError
        If a file cannot be written (the folder must exist).
    """
    summary = _check_rows(summary, "summary")
    if not isinstance(folder, (str, os.PathLike)):
        raise ParameterError(f"folder must be a folder path, got {folder!r}")
    if not isinstance(name, str) or not _NAME.fullmatch(name):
        raise ParameterError(f"name must be letters, digits, '_', '.' or '-', got {name!r}")
    folder = Path(folder)
    return (write_text(folder / f"{name}.csv", rows_csv(summary), what="study summary"),
            write_text(folder / f"{name}.md", markdown_summary(summary), what="study summary"))
