"""One trial of a study: a method of a task's spec on one scenario with one seed, and its record.

A trial is ``spec.solve(scenario, method=…, **options)`` (:meth:`~htetro_opt._spec.TaskSpec.solve`), then
the result as a flat, JSON-ready record: the trial's inputs, ``result.as_dict()``'s fields (lists of
tokens or labels joined by commas), the metrics asked for, the package version and the method's
``fingerprint`` (:meth:`~htetro_opt._spec.TaskSpec.fingerprint`), by which a resumed study tells a record
of today's code from a stale one.
"""

from __future__ import annotations

import hashlib
import json
import math
import numbers
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from htetro_opt import __version__
from htetro_opt._spec import TaskSpec
from htetro_opt.errors import ParameterError, StudyError

__all__ = ["HV_REFERENCE", "RUNTIME_FIELDS", "Trial", "coverage_bound", "reference_trial", "run_reference",
           "run_trial", "spec_of", "trial_record"]

HV_REFERENCE = (0.0, 1.0, 0.0, 0.0)
"""The hypervolume's reference point in pymoo's minimisation space F = −(f_gr, f_t, f_sm, f_sf):
f_gr = 0, f_t = −1 (a path taking twice t_max), f_sm = 0, f_sf = 0; fixed for every study, and the
notebook ``01_htetro_ga_pareto``'s (the runner's docstring gives the reasons)."""

RUNTIME_FIELDS = ("runtime_s", "reach_time_s")
"""Wall-clock fields of a record: the only ones that differ between two runs of the same trial."""

_FRONT_DIGITS = 6
_TILING_GAIN = 4  # tiling-tsp's legs pass through any state: no command adds more than 4 new cells
_EQUAL_WEIGHTS = (1.0, 1.0, 1.0)  # heat_f of the plans that optimise no (w_t, w_sm, w_sf)


def spec_of(task: str, scenario) -> TaskSpec:
    """The spec a study task runs on ``scenario``: ``plan`` is the grid-path task on a grid scenario and
    the continuous one on a continuous scenario."""
    from htetro_opt.solvers._tasks import VERBS

    if task not in VERBS:
        raise ParameterError(f"task must be one of {', '.join(VERBS)}, got {task!r}")
    specs = VERBS[task]
    if len(specs) == 1:
        return specs[0]
    from htetro_opt.scenarios import ContinuousScenario, load_scenario

    loaded = scenario if not isinstance(scenario, str) else load_scenario(scenario)
    return specs[1] if isinstance(loaded, ContinuousScenario) else specs[0]


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

    @property
    def fingerprint(self) -> str:
        """The method's spec and options as they stand in today's code (:meth:`TaskSpec.fingerprint`)."""
        return spec_of(self.task, self.scenario).fingerprint(self.method, self.parameters)

    def head(self) -> dict:
        """The leading fields of this trial's record (its inputs, flattened)."""
        return _head(self.inputs())


def reference_trial(trial: Trial) -> Trial:
    """The exact-optimum trial whose result ``trial``'s gap is measured against: the task's exact method
    on the same scenario with the options that define the problem (the spec's ``reference`` options: a
    plan's clearance and command set, a sequence's start, end, weights and shapes), the trial's method's
    own problem on top (:attr:`~htetro_opt._spec.Method.problem`: a GA has no diagonals, the heat planner
    always has them, so its gap is to the minimum-time plan over the same commands).

    Raises
    ------
    ParameterError
        If the task has no exact method.
    """
    spec = spec_of(trial.task, trial.scenario)
    if spec.exact is None:
        raise ParameterError(f"task {trial.task!r} has no exact reference (a cover trial records its own lower "
                             "bound)")
    exact = spec.method(spec.exact)
    method = spec.method(trial.method) if trial.method in spec.names else None
    parameters = {k: v for k, v in trial.parameters.items() if spec.options[k].reference and exact.takes(k)}
    if method is not None:
        parameters.update({k: v for k, v in method.problem.items() if exact.takes(k)})
    # a value the exact method has by default is left out, so that trials of one problem share one reference
    parameters = {k: _plain(parameters[k]) for k in sorted(parameters)
                  if _plain(parameters[k]) != _plain(spec.default_of(exact, k))}
    return Trial(trial.task, trial.scenario, exact.name, parameters, None, "reference", (), "reference")


def _inputs(kind, task, scenario, method, label, seed, parameters, metrics) -> dict:
    return {"kind": kind, "task": task, "scenario": scenario, "method": method, "label": label, "seed": seed,
            "parameters": {k: _plain(parameters[k]) for k in sorted(parameters)}, "metrics": list(metrics)}


def _plain(value):
    """A parameter as JSON holds it (a tuple of weights as a list)."""
    if isinstance(value, tuple):
        return [_plain(v) for v in value]
    return value


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


def trial_record(head: Mapping[str, Any], metrics: Mapping[str, Any], solution: Mapping[str, Any],
                 runtime_s: float | None, error: str | None = None, *, fingerprint: str | None = None) -> dict:
    """A record: the trial's head, its metrics, its solution, runtime, error, the package version and
    the method's fingerprint."""
    record = dict(head)
    record.update({k: _finite(v) for k, v in metrics.items()})
    record.update(solution)
    record["runtime_s"] = _finite(runtime_s)
    record["error"] = error
    record["version"] = __version__
    record["fingerprint"] = fingerprint
    return record


# --- a result as a record, per task -----------------------------------------------------------------
def _plan_record(problem, plan, method, parameters, metrics) -> tuple[dict, dict]:
    from htetro_opt.problems.names import FITNESS_NAMES

    reached = bool(plan.reached)
    out = {"reached": reached, "time": float(plan.time) if reached else None,
           "n_commands": len(plan.commands) if reached else None}
    if "objectives" in metrics:
        objectives = plan.objectives()
        out.update({k: objectives[k] if reached else None
                    for k in ("translations", "rotations", "shapeshifts", "path_length")})
    legs = plan.legs
    if "gap" in metrics and legs:  # fastest_gap, beside the picked plan's gap
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
        from htetro_opt.studies._summary import hypervolume

        front = _fitness_rows([member.fitness for member in legs[-1].front], unique=True)
        out["front"], out["hv"] = front, hypervolume(front)
    if "history" in metrics:
        out["history"] = _fitness_rows(legs[-1].history, unique=False)
    if "hv_curve" in metrics:
        out["hv_curve"] = [round(float(v), 6) for v in legs[-1].hv_history]
    if "heat_fitness" in metrics:
        out.update(_heat_metrics(problem.scenario.workspace, plan, method, parameters))
    return out, {"commands": ",".join(plan.tokens)}


def _heat_metrics(workspace, plan, method, parameters: Mapping[str, Any]) -> dict:
    """Metric ``heat_fitness``: Do et al. 2021's costs of any plan (the heat planner's by its own weights and
    t_max), and the morphologies it uses."""
    from htetro_opt.model.robot import STATE_NAMES
    from htetro_opt.problems import heat_fitness

    names = ("heat_f_t", "heat_f_sm", "heat_f_sf", "heat_f", "shapes_used")
    if not plan.reached:
        return dict.fromkeys(names)
    heat = "heat" in method.family
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


def _continuous_record(problem, plan, method, parameters, metrics) -> tuple[dict, dict]:
    objectives = plan.objectives()
    out = {"reached": bool(plan.reached), "length": objectives["length"] if plan.reached else None,
           "smoothness_deg": objectives["smoothness_deg"] if plan.reached else None,
           "safety": objectives["safety"] if plan.reached else None, "min_clearance": objectives["min_clearance"],
           "min_robot_distance": plan.min_robot_distance, "conflicts": len(plan.conflicts)}
    return out, {"paths": [p.tolist() for p in plan.paths]}


def _tile_record(problem, result, method, parameters, metrics) -> tuple[dict, dict]:
    from htetro_opt.model.robot import SHAPES
    from htetro_opt.scenarios import format_tileset

    tileset = result.tileset
    kinds = tileset.shapes
    out = {"tiles": len(tileset), "overlapping": tileset.overlapping, **{f"n_{s}": kinds.count(s) for s in SHAPES}}
    rows = (" ".join(row.split()) for row in format_tileset(tileset).split("\n"))
    return out, {"tileset": ";".join(rows)}


def _sequence_record(problem, result, method, parameters, metrics) -> tuple[dict, dict]:
    out = {"cost": float(result.cost), "waypoints": problem.extras["instance"].n,
           "optimal": bool(result.info.get("optimal", False))}
    return out, {"order": ",".join(str(t) for t in result.tiles)}


def coverage_bound(coverable: int, gain: int) -> int:
    """The lower bound on a coverage plan's action cost: ⌈(coverable − 4) / gain⌉, at least 0.

    The robot starts on 4 covered cells and no command adds more than ``gain`` new ones.

    Examples
    --------
    >>> coverage_bound(216, 2), coverage_bound(216, 4), coverage_bound(3, 4)
    (106, 53, 0)
    """
    return max(0, math.ceil((int(coverable) - 4) / int(gain)))


def _cover_record(problem, plan, method, parameters, metrics) -> tuple[dict, dict]:
    from htetro_opt.solvers.coverage import LayerGraph

    coverable = int(plan.coverable.sum())
    # g of the layers the plan used (boustrophedon: the first); tiling-tsp's legs leave the layers
    gain = _TILING_GAIN if method.name == "tiling-tsp" else \
        LayerGraph(problem.scenario.workspace, plan.layers, clearance=parameters.get("clearance", 0.0)).gain
    bound = coverage_bound(coverable, gain)
    fields = plan.as_dict()
    cost = plan.action_cost
    out = {"action_cost": cost, "time": plan.time, "complete": plan.complete, "free": fields["free"],
           "coverable": coverable, "covered": fields["covered"], "uncoverable": len(plan.uncoverable),
           "lower_bound": bound, "missed": len(plan.missed), "failed_regions": len(plan.failed_regions)}
    if "gap" in metrics:  # the bound is on plans covering every coverable cell: none for a plan that leaves some
        out["reference"] = bound
        out["gap"] = None if plan.missed else (cost - bound) / bound if bound > 0 else (0.0 if cost == 0 else None)
    out.update({k: fields[k] for k in ("average_coverage_time", "recovered_pct", "coverage_pct", "coverable_pct",
                                       "path_length", "switches", "turns", "regions", "regions_optimal",
                                       "memo_hits", "nodes", "mopup_commands", "transit_commands", "dag_cost",
                                       "time_limited")})
    out["layers"] = ",".join(plan.layers)
    s = plan.start
    solution = {"commands": ",".join(plan.tokens), "start_pose": [int(s.x), int(s.y), s.shape, int(s.heading)]}
    return out, solution


_RECORDS = {"grid-path planning": _plan_record, "continuous planning": _continuous_record, "tiling": _tile_record,
            "sequencing": _sequence_record, "coverage": _cover_record}


# --- running one ------------------------------------------------------------------------------------
def _check_trial_inputs(task, scenario, parameters) -> None:
    if not isinstance(scenario, str):
        raise ParameterError(f"scenario must be a bundled name or a file path (str), got {scenario!r}")
    if not isinstance(parameters, Mapping):
        raise ParameterError(f"parameters must be a mapping of option names to values, got {parameters!r}")
    spec_of(task, scenario)


def run_trial(task: str, scenario: str, method: str, parameters: Mapping[str, Any], seed: int | None, *,
              label: str | None = None, metrics: Sequence[str] = ()) -> dict:
    """Run one trial and return its record: a flat, JSON-ready dict.

    Parameters
    ----------
    task : {"plan", "tile", "sequence", "cover"}
    scenario : str
        A bundled name or a file (``sequence``: a labelled tileset, a TSPLIB file, or a scenario tiled first).
    method : str
        A method of the task's spec (an alias such as ``exact`` for ``dijkstra`` resolved).
    parameters : mapping
        The method's options as a study's method entry gives them (the spec's names).
    seed : int or None
        The seed of a method that draws from it (None for the others, which take no seed).
    label : str, keyword-only
        The name the trial's rows carry (default: ``method``).
    metrics : sequence of str, keyword-only
        Optional metrics (:data:`~htetro_opt.studies.runner.METRICS`); ``"gap"`` is added by
        :func:`~htetro_opt.studies.runner.run_study` from the reference trial (:func:`run_reference`).

    Returns
    -------
    dict
        ``key`` (sha256 of the inputs), ``kind``, ``task``, ``scenario``, ``method``, ``label``,
        ``seed``, the parameters, the metrics, the solution (plan: ``commands``; tile: ``tileset``,
        the labelled rows top-down joined by ``;``; sequence: ``order``, tile labels; cover:
        ``commands`` from ``start_pose``, ``[x, y, shape, heading]``; a continuous plan: ``paths``),
        ``runtime_s`` (the solver's), ``error`` (None), ``version`` and ``fingerprint``.

    Raises
    ------
    HtetroError
        Whatever the solver raises on this scenario (:func:`~htetro_opt.studies.runner.run_study`
        records it as the trial's error).

    Examples
    --------
    >>> record = run_trial("plan", "three_slit", "dijkstra", {}, None)
    >>> record["reached"], record["time"], record["commands"].split(",")[:3]
    (True, 33.0, ['x+', 'x+', 'x+'])
    """
    from htetro_opt.studies._study import _check_ga_metrics, _check_metrics

    _check_trial_inputs(task, scenario, parameters)
    if not isinstance(method, str):
        raise ParameterError(f"method must be a method name, got {method!r}")
    if label is not None and not isinstance(label, str):
        raise ParameterError(f"label must be a string or None, got {label!r}")
    spec = spec_of(task, scenario)
    chosen = spec.method(method)
    try:
        metrics = _check_metrics(task, metrics, "run_trial")
        _check_ga_metrics(spec, chosen.name, metrics, "run_trial")
    except StudyError as err:
        raise ParameterError(str(err)) from None
    options = dict(parameters)
    if chosen.draws(options):
        options["seed"] = seed
    if "hv_curve" in metrics:
        options["hv_reference"] = HV_REFERENCE
    head = _head(_inputs("trial", task, scenario, chosen.name, chosen.name if label is None else label, seed,
                         parameters, metrics))
    problem, result = spec.solve(scenario, method=chosen.name, naming="key", **options)
    values, solution = _RECORDS[spec.name](problem, result, chosen, parameters, metrics)
    values["additions"] = list(result.additions)  # of ours, switched on: none for a method as published
    return trial_record(head, values, solution, result.runtime_s,
                        fingerprint=spec.fingerprint(chosen, parameters))


def run_reference(task: str, scenario: str, parameters: Mapping[str, Any]) -> dict:
    """The exact optimum a study's gaps are measured against, as a record (``kind`` "reference").

    ``plan``: Dijkstra's minimum-time plan (``reached``, ``time``, ``n_commands``, ``commands``), or on a
    continuous scenario the visibility-graph optimum (``length``); ``sequence``: the CP-SAT optimum
    (``cost``, ``waypoints``, ``optimal``, ``order``), ``cost`` None beyond
    :data:`~htetro_opt.solvers.sequencing.EXACT_AUTO_LIMIT` waypoints, where no optimum is proven.

    Examples
    --------
    >>> record = run_reference("sequence", "paper_6x6_fig13a", {})
    >>> round(record["cost"], 6), record["optimal"], record["order"]
    (17.190762, True, '1,2,3,4,9,7,6,8,5')
    """
    _check_trial_inputs(task, scenario, parameters)
    spec = spec_of(task, scenario)
    if spec.exact is None:
        raise ParameterError(f"task {task!r} has no exact reference (plan and sequence have; a cover trial "
                             "records its own lower bound)")
    trial = reference_trial(Trial(task, scenario, spec.exact, parameters, None, "reference"))
    fingerprint = spec.fingerprint(trial.method, trial.parameters)
    problem = spec.pose(scenario, naming="key", **{k: v for k, v in trial.parameters.items()
                                                  if spec.options[k].stage == "problem"})
    if spec.name == "sequencing":
        from htetro_opt.solvers.sequencing import EXACT_AUTO_LIMIT

        instance = problem.extras["instance"]
        if instance.n > EXACT_AUTO_LIMIT:
            return trial_record(trial.head(), {"cost": None, "waypoints": instance.n, "optimal": False},
                                {"order": None}, None, fingerprint=fingerprint)
    result = spec.run(problem, method=trial.method, **{k: v for k, v in trial.parameters.items()
                                                       if spec.options[k].stage == "method"})
    values, solution = _RECORDS[spec.name](problem, result, spec.method(trial.method), trial.parameters, ())
    return trial_record(trial.head(), values, solution, result.runtime_s, fingerprint=fingerprint)
