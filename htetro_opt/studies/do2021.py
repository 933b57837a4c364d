"""The experiments of Do et al. 2021 (IEEE Access) re-run: Tables 6–8 and Fig. 13 of its heat-conduction planner.

The paper plans for hTetro by climbing a steady heat field (goal = source, start = sink) and reports:

- **Table 6**: the costs f_t, f_sm, f_sf and f (eqs. 9–12) of the plan under four weightings
  (w_t, w_sm, w_sf) of eq. 12 (time (1, 0, 0), smoothness (0, 1, 0), safety (0, 0, 1) and
  multi-objective (1, 1, 1)) on six 24 × 24 maps (random, H-shape, spiral, 3-slit, zigzag, maze);
- **Table 7**: the same beside "the Genetic Algorithm" (n_pop = 100, 50 runs; Cheng et al. 2020's
  hTetro-GA, by our reading) on the first four maps, with runtimes;
- **Fig. 13**: online replanning in a maze with two obstacle cells unknown to the planner
  (sensor range D_S = 6 cells);
- **Table 8**: on a real 128 × 128 room, the heat planner's multi-objective plan against A* and
  Dijkstra (with diagonals) restricted to the O-shape: −18.03 % travel time and −15.69 % energy.

Our copy of the paper keeps only the tables' captions; the text keeps some Table-6 values
(:data:`PAPER_TABLE6`, where it contradicts itself both readings are kept) and Table 8's two
percentages (:data:`PAPER_TABLE8`). Ours sit beside them, with what the paper could not report: each
heat plan's gap to the exact minimum-time plan over the same 17 commands.

**On the study runner.** Tables 6 and 7 are the bundled study ``do2021``
(``studies/data/do2021.toml``, or :func:`do2021_study`): the heat planner once per weighting as
published (``heat-paper``: the paper's mesh, tentative cost and stop rule; the paper's numbers stand
beside it) and ours (``heat``, with our additions), heat trials taking no seed, the exact
minimum-time plan with the diagonals, and the two GAs — ``htetro-ga-paper`` (Cheng et al. 2020's GA as
published, the paper's comparison) and ``htetro-ga`` (ours) — with n_pop 100, 5 seeds by default, on
the first four maps only (the GA entries' own ``scenarios``), with the runner's metrics
``objectives``, ``gap`` and ``heat_fitness``: every plan, whatever its method, is scored by Do et al.
2021's eqs. 9–12 (:func:`~htetro_opt.problems.heat_costs.heat_fitness`, t_max the map's default).
The Table-6 report says, per map and planner, whether the paper's property holds (each criterion's
best value lies in that criterion's row). Table 7 scores the
GA's and the exact plan (one plan per run, optimising no such weighting) under each row's weights:
f = Σ w·(f_t, f_sm, f_sf) / Σ w of its recorded costs. Table 8 (:func:`run_table8`) and Fig. 13
(:func:`run_fig13`) are single deterministic runs, made in this process. :func:`report` lays it all
out as Markdown, :func:`report_rows` as CSV rows::

    from htetro_opt.studies import do2021

    run = do2021.run_do2021(seeds=5, out="results")   # or run_study(load_study("do2021"), out=...)
    print(do2021.report(run, table8=do2021.run_table8(), fig13=do2021.run_fig13()))

From the shell, ``htetro-opt study do2021 [--seeds N] [--workers N] [--out DIR]``, which writes ``DIR/do2021.md`` and ``DIR/do2021.csv`` (the paper's tables: they replace
the runner's generic summary of the same names, which ``summarise(read_records(DIR/do2021.jsonl))``
gives back), beside the runner's ``DIR/do2021.jsonl`` (every trial).
"""

from __future__ import annotations

import math
import numbers
import os
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from htetro_opt._validation import check_real
from htetro_opt.errors import ParameterError
from htetro_opt.studies.metrics import format_mean_std, mean_std, values_of
from htetro_opt.studies.runner import Study, StudyRun
from htetro_opt.studies.runner import write_report as write_study_report
from htetro_opt.studies.runner import run_study as run_runner_study

__all__ = [
    "GA_METHODS",
    "GA_POP_SIZE",
    "HEAT_METHODS",
    "PAPER_FIG13",
    "PAPER_TABLE6",
    "PAPER_TABLE8",
    "ROWS",
    "TABLE6_SCENARIOS",
    "TABLE7_SCENARIOS",
    "TABLES",
    "ablation_report",
    "ablation_rows",
    "report",
    "report_rows",
    "run_fig13",
    "run_do2021",
    "run_table8",
    "do2021_study",
    "write_report",
]

ROWS = (("time", (1.0, 0.0, 0.0)), ("smoothness", (0.0, 1.0, 0.0)), ("safety", (0.0, 0.0, 1.0)),
        ("multi", (1.0, 1.0, 1.0)))
"""Table 6's rows: the name and the weights (w_t, w_sm, w_sf) of eq. 12 the plan is optimised for."""
TABLES = (6, 7, 8, 13)
"""What :func:`main` runs: Tables 6, 7, 8 and Fig. 13."""
TABLE6_SCENARIOS = ("random", "h_shape", "spiral", "three_slit", "zigzag", "maze")
TABLE7_SCENARIOS = TABLE6_SCENARIOS[:4]
"""Table 7 compares on the first four maps of Table 6."""
GA_POP_SIZE = 100
"""Table 7's hTetro-GA population (the paper: "a population size of 100 ... executed 50 times")."""
HEAT_METHODS = ("heat-paper", "heat")
"""Table 6's and 7's heat planners: the paper's algorithm as published, and ours (with our additions)."""
GA_METHODS = {"htetro-ga-paper": "Cheng et al. 2020's GA as published: the paper's comparison",
              "htetro-ga": "ours: that GA with our additions"}
"""Table 7's GAs, each with what it is."""

PAPER_TABLE6: dict[tuple[str, str], dict[str, Any]] = {
    # (scenario, row): {cost: value, (low, high) range over all four rows, or a list of the readings
    # the text gives for the same cell when it contradicts itself}
    ("random", "time"): {"f_t": (0.879, 0.894)},
    ("random", "smoothness"): {"f_t": [(0.879, 0.894), 0.867], "f_sf": 0.615},
    ("random", "safety"): {"f_t": (0.879, 0.894), "f_sf": 0.945},
    ("random", "multi"): {"f_t": (0.879, 0.894), "f": 0.892},
    ("h_shape", "time"): {"f_t": 0.869, "f_sm": 0.875, "f_sf": 0.766},
    ("h_shape", "smoothness"): {"f_t": 0.869, "f_sm": 0.875, "f_sf": 0.766},
    ("h_shape", "safety"): {"f_t": 0.851, "f_sf": 0.926},
    ("h_shape", "multi"): {"f_t": 0.864, "f_sm": 0.813, "f_sf": 0.914},
    ("spiral", "time"): {"f_t": (0.652, 0.667), "f_sm": (0.862, 0.920), "f_sf": 0.702},
    ("spiral", "smoothness"): {"f_t": (0.652, 0.667), "f_sm": (0.862, 0.920), "f_sf": 0.704},
    ("spiral", "safety"): {"f_t": (0.652, 0.667), "f_sm": (0.862, 0.920), "f_sf": 0.862},
    ("spiral", "multi"): {"f_t": (0.652, 0.667), "f_sm": (0.862, 0.920), "f_sf": 0.862},
}
"""The Table-6 cells our copy's text keeps (§VI-A-1 to 3; the table itself is lost). Random: f_t
0.879–0.894 over all four rows, yet the smoothness path's f_t = 0.867 and f_sf = 0.615 (both kept).
The other maps' cells are not in the text."""

PAPER_TABLE8 = {"time_pct": -18.03, "energy_pct": -15.69}
"""Table 8: the heat planner's multi-objective plan against O-shape-only A*, in travel time and
energy (means of 5 real-robot trials). Energy is not modelled here."""

PAPER_FIG13 = {"start": (2, 2), "goal": (22, 21), "hidden": ((5, 11), (6, 11)), "replan_cell": (5, 7),
               "sensor_range": 6.0}
"""Fig. 13's cells (§VI-A-7): start, goal, the two unknown obstacle cells, where the robot replans."""

_COSTS = ("f_t", "f_sm", "f_sf", "f")
_O_MOVES = ("x+", "x-", "y+", "y-")
_DIAGONALS = ("x+y+", "x+y-", "x-y+", "x-y-")


# --- the study --------------------------------------------------------------------------------------
def _check_tables(tables) -> tuple[int, ...]:
    if isinstance(tables, str):  # "6,7,8,13", as on the command line
        try:
            tables = [int(t) for t in tables.split(",") if t.strip()]
        except ValueError:
            raise ParameterError(f"tables must be some of {', '.join(map(str, TABLES))}, got {tables!r}") from None
    if isinstance(tables, (numbers.Integral, bytes)) or not isinstance(tables, Iterable):
        raise ParameterError(f"tables must be a list of some of {', '.join(map(str, TABLES))}, got {tables!r}")
    tables = list(tables)
    bad = [t for t in tables if isinstance(t, bool) or t not in TABLES]
    if not tables or bad:
        raise ParameterError(f"tables must be some of {', '.join(map(str, TABLES))} (13: Fig. 13), got {tables!r}")
    return tuple(t for t in TABLES if t in tables)


def do2021_study(seeds: int | Sequence[int] = 5, *, tables: Iterable[int] = (6, 7),
                  scenarios: Sequence[str] = TABLE6_SCENARIOS, ga_scenarios: Sequence[str] = TABLE7_SCENARIOS,
                  ga_options: Mapping[str, Any] | None = None) -> Study:
    """Tables 6 and 7 as a study of the runner (task ``plan``); with the defaults the bundled study
    ``do2021`` (``load_study("do2021")``).

    Parameters
    ----------
    seeds : int or sequence of int
        The GA's seeds (N: 0 … N−1); the heat and exact trials run once.
    tables : iterable of int, keyword-only
        6 and/or 7 (others are ignored: they are not runner trials). Table 6 alone: the heat rows
        (``heat-paper`` and ``heat``) on ``scenarios``; Table 7 alone: the heat rows, the exact plan and
        the two GAs (``htetro-ga-paper``, ``htetro-ga``) on ``ga_scenarios``.
    scenarios : sequence of str, keyword-only
        Table 6's maps.
    ga_scenarios : sequence of str, keyword-only
        Table 7's maps, some of ``scenarios``: the GA runs on these only.
    ga_options : mapping, optional, keyword-only
        The GA entries' options (default ``{"pop_size": 100}``; e.g. ``max_gen`` for a quick run).

    Returns
    -------
    Study

    Raises
    ------
    StudyError
        If a scenario, option or value is invalid (the runner's checks).

    Examples
    --------
    >>> study = do2021_study(2, ga_scenarios=["random"], scenarios=["random", "maze"])
    >>> [(t.scenario, t.label, t.seed) for t in study.trials()][7:12]  # doctest: +NORMALIZE_WHITESPACE
    [('random', 'heat, multi', None), ('random', 'exact', None), ('random', 'htetro-ga-paper', 0),
     ('random', 'htetro-ga-paper', 1), ('random', 'htetro-ga', 0)]
    """
    tables = _check_tables(tables)
    if 6 not in tables and 7 not in tables:
        raise ParameterError("do2021_study runs Tables 6 and 7; Table 8 and Fig. 13 are run_table8 and run_fig13")
    if isinstance(scenarios, str) or isinstance(ga_scenarios, str):
        raise ParameterError("scenarios and ga_scenarios must be lists of scenario names")
    entries: list[dict[str, Any]] = [{"label": f"{method}, {name}", "method": method, "weights": list(weights)}
                                     for method in HEAT_METHODS for name, weights in ROWS]
    if 7 in tables:
        ga = {"pop_size": GA_POP_SIZE, **dict(ga_options or {})}
        entries.append({"label": "exact", "method": "dijkstra", "diagonals": True})
        for method in GA_METHODS:
            entries.append({"label": method, "method": method, **ga,
                            **({} if 6 not in tables else {"scenarios": list(ga_scenarios)})})
    if not isinstance(seeds, numbers.Integral) and isinstance(seeds, Iterable):
        seeds = list(seeds)
    return Study(name="do2021", task="plan", scenarios=tuple(scenarios) if 6 in tables else tuple(ga_scenarios),
                 methods=entries, seeds=seeds, metrics=("objectives", "gap", "heat_fitness"),
                 description="Do et al. 2021, Tables 6 and 7: the heat-conduction planner as published (heat-paper) "
                             "and ours (heat) under four weightings, beside Cheng et al. 2020's GA as published "
                             "(htetro-ga-paper), ours (htetro-ga) and the exact optimum")


def run_do2021(seeds: int | Sequence[int] | None = None, *, tables: Iterable[int] = (6, 7), study: Study | None = None,
                executor: str = "processes", workers: int | None = None, scheduler=None,
                out: str | os.PathLike | None = None, resume: bool = False, retries: int = 0,
                progress=None) -> StudyRun:
    """Run Tables 6 and 7 on the study runner: :func:`do2021_study` (or ``study``, e.g. a smaller
    file of the same shape); ``report(run)`` lays the records out as the paper's tables.

    ``seeds``: the GA's (N: 0 … N−1), default 5, or ``study``'s own when it is given.
    ``executor``, ``workers``, ``scheduler``, ``out``, ``resume``, ``retries`` and ``progress`` are
    :func:`~htetro_opt.studies.runner.run_study`'s.
    """
    if study is None:
        study = do2021_study(5 if seeds is None else seeds, tables=tables)
    elif not isinstance(study, Study):
        raise ParameterError(f"study must be a Study (load_study's), got {study!r}")
    elif seeds is not None:
        study = study.with_seeds(seeds)
    return run_runner_study(study, out=out, executor=executor, workers=workers, scheduler=scheduler,
                            resume=resume, retries=retries, progress=progress)


# --- Table 8 and Fig. 13: single runs in this process -----------------------------------------------
def _shapes(plan) -> str:
    from htetro_opt.model.robot import STATE_NAMES

    return "".join(dict.fromkeys(STATE_NAMES[int(s)] for s in plan.poses[:, 2]))


def run_table8(scenario: str = "indoor_room_doorway") -> list[dict]:
    """Table 8's analog: the O-shape-only A* and Dijkstra against the heat planner, one plan each.

    ``indoor_room_doorway`` (128 × 128) is our reconstruction of the paper's room with a doorway an
    O-shape passes. Rows: O-only A* (:func:`~htetro_opt.solvers.grid_paths.plan_exact`, method
    ``astar``, commands x±, y±: no turn, no shapeshift, so the robot keeps its O-shape), O-only
    Dijkstra with the four diagonals, the heat planner's multi-objective plan (weights (1, 1, 1),
    the paper's row) as published (``heat-paper``, the paper's numbers beside it) and ours (``heat``)
    and, beyond the paper, our time-only plan (1, 0, 0). Each row: travel time, B2's
    distance (``path_length``), shapeshifts, rotations, the shapes used, the change against A* in %,
    and the planner's runtime. Energy, the paper's other measure, is not modelled.

    Returns
    -------
    list of dict
        One per row, ``table`` 8.
    """
    from htetro_opt.scenarios import load_scenario
    from htetro_opt.solvers.grid_paths import plan_exact, plan_heat

    grid = load_scenario(scenario)
    ws, roadmap = grid.workspace, grid.roadmap
    plans = [
        ("O-only A*", "astar", plan_exact(ws, roadmap, method="astar", commands=list(_O_MOVES))),
        ("O-only Dijkstra (diagonals)", "dijkstra",
         plan_exact(ws, roadmap, method="dijkstra", commands=list(_O_MOVES + _DIAGONALS))),
        ("heat-paper, multi (1, 1, 1)", "heat-paper",
         plan_heat(ws, roadmap, weights=(1.0, 1.0, 1.0), method="heat-paper")),
        ("heat, multi (1, 1, 1)", "heat", plan_heat(ws, roadmap, weights=(1.0, 1.0, 1.0))),
        ("heat, time (1, 0, 0)", "heat", plan_heat(ws, roadmap, weights=(1.0, 0.0, 0.0))),
    ]
    base = plans[0][2]
    rows = []
    for label, method, plan in plans:
        objectives = plan.objectives()
        paper = label.startswith("heat-paper, multi")  # the paper's numbers beside its own algorithm
        rows.append({
            "table": "8", "scenario": grid.name, "label": label, "method": method, "reached": bool(plan.reached),
            "time": plan.time, "time_pct": 100.0 * (plan.time - base.time) / base.time,
            "path_length": objectives["path_length"],
            "distance_pct": 100.0 * (objectives["path_length"] - base.objectives()["path_length"])
            / base.objectives()["path_length"],
            "n_commands": objectives["n_commands"], "shapeshifts": objectives["shapeshifts"],
            "rotations": objectives["rotations"], "shapes_used": _shapes(plan), "runtime_s": plan.runtime_s,
            "paper_time_pct": PAPER_TABLE8["time_pct"] if paper else None,
            "paper_energy_pct": PAPER_TABLE8["energy_pct"] if paper else None,
        })
    return rows


def run_fig13(scenario: str = "maze_partial", *, sensor_range: float = 6.0) -> dict:
    """Fig. 13's analog: :func:`~htetro_opt.solvers.grid_paths.replan_heat` on a map with hidden obstacles.

    The robot plans time-only heat plans (the paper's Fig. 13: "best path results based on time
    consumption") on what it knows and replans as its sensors (range ``sensor_range`` cells) reveal
    the hidden cells. Measured against the true world's exact minimum-time plan (Dijkstra with the
    diagonals on ``scenario.true_workspace()``) and the plan made on the known map (what the robot
    would do with no hidden obstacle).

    Returns
    -------
    dict
        ``table`` "13", ``reached``, ``plans``, ``replans`` (``step``, ``pose`` (x, y, shape,
        heading), ``revealed`` cells), ``time`` (executed), ``true_optimum``, ``ratio`` (time /
        true_optimum), ``known_plan`` (the heat plan's time on the known map), ``f_t`` … ``f`` of the
        executed path, ``runtime_s``, and the paper's cells.
    """
    from htetro_opt.scenarios import load_scenario
    from htetro_opt.solvers.grid_paths import plan_exact, plan_heat, replan_heat

    sensor_range = check_real(sensor_range, "sensor_range", minimum=0.0, include_minimum=False)
    grid = load_scenario(scenario)
    run = replan_heat(grid, sensor_range=sensor_range)
    truth = plan_exact(grid.true_workspace(), grid.roadmap, diagonals=True)
    known = plan_heat(grid.workspace, grid.roadmap)
    best = truth.time if truth.reached else None
    return {
        "table": "13", "scenario": grid.name, "sensor_range": sensor_range, "reached": bool(run.reached),
        "plans": int(run.plans),
        "replans": [{"step": r["step"], "pose": [r["pose"].x, r["pose"].y, r["pose"].shape, r["pose"].heading],
                     "revealed": [list(c) for c in r["revealed"]]} for r in run.replans],
        "time": float(run.time), "true_optimum": best,
        "ratio": None if best is None or not run.reached else float(run.time) / best,
        "known_plan": float(known.time) if known.reached else None,
        **{k: float(run.fitness[k]) for k in _COSTS}, "runtime_s": float(run.runtime_s),
        "paper_start": list(PAPER_FIG13["start"]), "paper_goal": list(PAPER_FIG13["goal"]),
        "paper_hidden": [list(c) for c in PAPER_FIG13["hidden"]], "paper_replan_cell": list(PAPER_FIG13["replan_cell"]),
    }


# --- from records to tables -------------------------------------------------------------------------
def _row_of(weights) -> str:
    """Table 6's row name of a heat trial's weights (scaling them keeps the plan), else the weights."""
    if weights is None:
        weights = ROWS[0][1]  # plan_heat's default
    w = np.asarray(weights, dtype=float)
    for name, row in ROWS:
        r = np.asarray(row)
        if np.allclose(w / w.sum(), r / r.sum()):
            return name
    return "weights " + ",".join(f"{v:g}" for v in w)


def _weights_of(row: str) -> tuple[float, ...]:
    named = dict(ROWS)
    if row in named:
        return named[row]
    return tuple(float(v) for v in row.split(" ", 1)[1].split(","))


def _kind(record: Mapping[str, Any]) -> str:
    """A record's method as its family in the grid-path spec: ``heat``, ``exact`` or ``ga``."""
    from htetro_opt.solvers.grid_paths._spec import SPEC

    family = SPEC.method(record.get("method")).family
    return next(kind for kind in ("heat", "exact", "ga") if kind in family)


def _scored(record: Mapping[str, Any], weights) -> float | None:
    """Eq. 12 of a record's recorded costs under other weights (None if it did not reach)."""
    costs = [record.get(f"heat_{k}") for k in ("f_t", "f_sm", "f_sf")]
    if any(c is None for c in costs):
        return None
    w = np.asarray(weights, dtype=float)
    return float(w @ np.asarray(costs) / w.sum())


def _ok(record: Mapping[str, Any]) -> bool:
    return record.get("error") is None


def _check_run(run) -> StudyRun | None:
    if run is None:
        return None
    if not isinstance(run, StudyRun):
        raise ParameterError(f"run must be the StudyRun of run_do2021 or run_study, got {run!r}")
    if run.study.task != "plan":
        raise ParameterError(f"the do2021 report lays out plan studies, not task {run.study.task!r}")
    if any(r.get("error") is None and "heat_f" not in r for r in run.records):
        raise ParameterError("the do2021 report needs the study's metric 'heat_fitness' (every plan scored by "
                             "Do et al. 2021's costs)")
    return run


def _scenarios(records) -> list[str]:
    return list(dict.fromkeys(r["scenario"] for r in records))


def _name(scenario: str) -> str:
    return Path(scenario).stem if scenario.endswith(".toml") else scenario


def _table6_rows(run: StudyRun) -> list[dict]:
    rows = []
    for scenario in _scenarios(run.records):
        for r in run.records:
            if r["scenario"] != scenario or _kind(r) != "heat" or not _ok(r):
                continue
            row = _row_of(r.get("weights"))
            # the paper's numbers stand beside its own algorithm's run only
            paper = PAPER_TABLE6.get((_name(scenario), row), {}) if r["method"] == "heat-paper" else {}
            rows.append({
                "table": "6", "scenario": _name(scenario), "row": row, "label": r["label"], "method": r["method"],
                "weights": ",".join(f"{w:g}" for w in _weights_of(row)), "runs": 1, "reached": r.get("reached"),
                **{k: r.get(f"heat_{k}") for k in _COSTS}, "time": r.get("time"), "reference": r.get("reference"),
                "gap": r.get("gap"), "shapes_used": r.get("shapes_used"), "shapeshifts": r.get("shapeshifts"),
                "runtime_s": r.get("runtime_s"), "additions": ",".join(r.get("additions") or ()),
                **{f"paper_{k}": _paper_text(paper.get(k)) or None for k in _COSTS},
            })
    return rows


def _table7_rows(run: StudyRun) -> list[dict]:
    """Per Table-7 map (one with GA records) and row: heat, GA (mean ± std over seeds), exact."""
    rows = []
    for scenario in _scenarios(run.records):
        mine = [r for r in run.records if r["scenario"] == scenario and _ok(r)]
        gas = [r for r in mine if _kind(r) == "ga"]
        if not gas:
            continue
        heats = {(r["method"], _row_of(r.get("weights"))): r for r in mine if _kind(r) == "heat"}
        exact = next((r for r in mine if _kind(r) == "exact"), None)
        for row, weights in ROWS:
            for method in dict.fromkeys(m for m, _ in heats):
                heat = heats.get((method, row))
                if heat is not None:
                    rows.append(_t7(scenario, row, method, [heat], weights))
            for label in dict.fromkeys(r["label"] for r in gas):
                rows.append(_t7(scenario, row, label, [r for r in gas if r["label"] == label], weights))
            if exact is not None:
                rows.append(_t7(scenario, row, exact["label"], [exact], weights))
    return rows


def _t7(scenario: str, row: str, label: str, records: list[dict], weights) -> dict:
    f = [_scored(r, weights) for r in records]
    mean, std = mean_std(f)
    runtime, runtime_std = mean_std(values_of(records, "runtime_s"))
    time, time_std = mean_std(values_of(records, "time"))
    gap, _ = mean_std(values_of(records, "gap"))
    return {"table": "7", "scenario": _name(scenario), "row": row, "label": label, "method": records[0]["method"],
            "weights": ",".join(f"{w:g}" for w in weights), "runs": len(records),
            "reached": sum(bool(r.get("reached")) for r in records), "f": mean, "f_std": std,
            "f_min": min((v for v in f if v is not None), default=None),
            "f_max": max((v for v in f if v is not None), default=None), "time": time, "time_std": time_std,
            "gap": gap, "runtime_s": runtime, "runtime_s_std": runtime_std}


def report_rows(run: StudyRun | None = None, *, table8: Iterable[Mapping] | None = None,
                fig13: Mapping | None = None) -> list[dict]:
    """The report's figures as flat rows (one per table cell group), for ``do2021.csv``.

    Table 6: one row per heat trial (``table`` "6"); Table 7: per map, row and method the mean
    ``f`` (under the row's weights) with ``f_std``, the worst and best run's ``f_min`` and
    ``f_max``, time, gap and runtime over the seeds (``table`` "7"); Table 8's rows as
    :func:`run_table8` gives them; Fig. 13's run flattened (``table`` "13"; replans as text).
    """
    run = _check_run(run)
    rows: list[dict] = []
    if run is not None:
        rows += _table6_rows(run) + _table7_rows(run)
    rows += [dict(r) for r in (table8 or ())]
    if fig13 is not None:
        flat = {k: v for k, v in fig13.items() if k != "replans"}
        flat["replans"] = "; ".join(f"step {r['step']} at {tuple(r['pose'])}: revealed "
                                    + " ".join(f"({x}, {y})" for x, y in r["revealed"]) for r in fig13["replans"])
        rows.append(flat)
    return rows


# --- Markdown ---------------------------------------------------------------------------------------
def _fmt(value, digits: int = 3) -> str:
    return "–" if value is None else f"{value:.{digits}f}"


def _paper_text(cell) -> str:
    """A paper cell: a value, a range over the rows ("0.879–0.894"), or contradicting readings ("a / b")."""
    if cell is None:
        return ""
    if isinstance(cell, list):
        return " / ".join(_paper_text(c) for c in cell)
    if isinstance(cell, tuple):  # (low, high): the text's range over the rows
        return f"{cell[0]:.3f}–{cell[1]:.3f}"
    return f"{cell:.3f}"


def _pct(value) -> str:
    return "–" if value is None else f"{100.0 * value:+.1f} %"


def _property_breaks(rows: list[dict]) -> list[str]:
    """Where one planner's four Table-6 rows on one map break the paper's property ("the maximum cost
    value in a column of a criterion is the value of the element in the row having the same name"): a
    criterion whose best value is in another row's plan. f is compared under the multi row's weights."""
    by_row = {r["row"]: r for r in rows}
    if any(row not in by_row for row, _ in ROWS):
        return []
    breaks = []
    for (row, weights), key in zip(ROWS, ("f_t", "f_sm", "f_sf", "f")):
        def value(r):
            return _weighted(r, weights) if key == "f" else r[key]
        own = value(by_row[row])
        best = max(by_row, key=lambda other: value(by_row[other]) if value(by_row[other]) is not None else -math.inf)
        if own is not None and value(by_row[best]) is not None and value(by_row[best]) > own + 1e-12:
            breaks.append(f"{key} {own:.3f} in the {row} row < {value(by_row[best]):.3f} in the {best} row")
    return breaks


def _weighted(row: Mapping[str, Any], weights) -> float | None:
    costs = [row.get(k) for k in ("f_t", "f_sm", "f_sf")]
    if any(c is None for c in costs):
        return None
    w = np.asarray(weights, dtype=float)
    return float(w @ np.asarray(costs, dtype=float) / w.sum())


def _table6_md(rows: list[dict]) -> list[str]:
    out = ["## Table 6: the heat planner's costs under four weightings", "",
           "Each row's plan minimises its weighting of eq. 12; all four costs of that plan are listed "
           "(higher is better). `heat-paper` is the paper's algorithm as published (its mesh, its tentative cost, "
           "its stop rule: docs/papers/do2021.md); the paper's numbers stand beside it. `heat` is ours (our "
           "additions: the pinch split, the converged search, the surrogate cost, the exact pick among Table 6's "
           "weightings). t_max = t_translation·⌈H/2⌉·(W−2)/2 = 132 s on 24 × 24, the paper's 39.6 s at "
           "t_translation = 0.3 s: only the normalisation compares, not the values — our maps are "
           "reconstructions from the paper's figures, so f_t itself differs (random: the paper's 0.879–0.894 "
           "against ours below). Gap: the plan's time against the exact minimum-time plan over the same 17 "
           "commands (Dijkstra with the diagonals). Paper: the cells the text of our copy keeps (the table is "
           "lost); a range is the text's range over all four rows, 'a / b' two readings of one cell that "
           "contradict each other.", ""]
    for scenario in dict.fromkeys(r["scenario"] for r in rows):
        mine = [r for r in rows if r["scenario"] == scenario]
        reference = next((r["reference"] for r in mine if r["reference"] is not None), None)
        out += [f"### {scenario} (exact minimum time {_fmt(reference)} s)", "",
                "| row (w_t, w_sm, w_sf) | method | f_t | f_sm | f_sf | f | time s | gap to exact | shapes "
                "| runtime s | paper f_t | paper f_sm | paper f_sf | paper f |",
                "|---|---|---:|---:|---:|---:|---:|---:|---|---:|---:|---:|---:|---:|"]
        order = {name: i for i, (name, _) in enumerate(ROWS)}
        methods = list(dict.fromkeys(r["method"] for r in mine))
        for r in sorted(mine, key=lambda r: (order.get(r["row"], len(order)), methods.index(r["method"]))):
            paper = [r[f"paper_{k}"] or "" for k in _COSTS]
            out.append(f"| {r['row']} ({r['weights']}) | {r['method']} | " + " | ".join(_fmt(r[k]) for k in _COSTS)
                       + f" | {_fmt(r['time'], 2)} | {_pct(r['gap'])} | {r['shapes_used'] or '–'} | "
                       f"{_fmt(r['runtime_s'])} | " + " | ".join(paper) + " |")
        out.append("")
        for method in methods:
            breaks = _property_breaks([r for r in mine if r["method"] == method])
            out.append(f"- Table 6's property (each criterion's best value in its own row), {method}: "
                       + ("holds." if not breaks else "**broken**: " + "; ".join(breaks) + "."))
        out.append("")
    return out


def _is_heat(row: Mapping[str, Any]) -> bool:
    return row["method"] in HEAT_METHODS


def _speedups(rows: list[dict]) -> list[tuple[str, str, str, float, float, float]]:
    """Per map, heat planner and GA: (map, heat, GA, heat runtime per plan (mean over the rows), GA runtime
    per plan, ratio)."""
    out = []
    for scenario in dict.fromkeys(r["scenario"] for r in rows):
        mine = [r for r in rows if r["scenario"] == scenario]
        gas = [r for r in mine if not _is_heat(r) and r["method"] not in ("dijkstra", "astar")]
        for method in dict.fromkeys(r["method"] for r in mine if _is_heat(r)):
            heat = [r["runtime_s"] for r in mine if r["method"] == method and r["runtime_s"] is not None]
            for label in dict.fromkeys(r["label"] for r in gas):
                ga = next(r for r in gas if r["label"] == label)
                if heat and ga["runtime_s"] is not None:
                    h, g = sum(heat) / len(heat), ga["runtime_s"]
                    out.append((scenario, method, label, h, g, g / h if h > 0 else math.inf))
    return out


def _ga_name(label: str) -> str:
    return f"{label} ({GA_METHODS[label]})" if label in GA_METHODS else label


def _table7_md(rows: list[dict]) -> list[str]:
    exact_methods = ("dijkstra", "astar")
    out = ["## Table 7: the heat planner against the hTetro-GA and the exact optimum", "",
           "Every path scored by Do et al. 2021's costs (eqs. 9–12). The heat plans of each row minimise that "
           "row's weighting: `heat-paper` as published, `heat` ours. The GAs and the exact minimum-time plan make "
           "one plan per run, scored under each row's weights: "
           + "; ".join(f"`{m}`, {what}" for m, what in GA_METHODS.items())
           + " (each its balanced solution). GA: mean ± std over its seeds (the paper's 50 runs: `--seeds 50`). "
           "The paper's Table 7 is lost in our copy; its text says the heat planner \"outperforms the genetic "
           "algorithm in all the categories and all the environments\" and \"performs much faster\".", ""]
    tallies: dict[tuple[str, str], list] = {}
    for scenario in dict.fromkeys(r["scenario"] for r in rows):
        mine = [r for r in rows if r["scenario"] == scenario]
        heats = list(dict.fromkeys(r["label"] for r in mine if _is_heat(r)))
        ga_labels = list(dict.fromkeys(r["label"] for r in mine if not _is_heat(r)
                                       and r["method"] not in exact_methods))
        exact_label = next((r["label"] for r in mine if r["method"] in exact_methods), None)
        header = ["row"] + [f"{h} f" for h in heats] + [f"{g} f (n)" for g in ga_labels]
        header += ([f"{exact_label} f"] if exact_label else [])
        pairs = [(h, g) for h in heats for g in ga_labels]
        header += [f"{h} ≥ {g} mean" for h, g in pairs]
        out += [f"### {scenario}", "", "| " + " | ".join(header) + " |", "|---|" + "---:|" * (len(header) - 1)]
        for row, _ in ROWS:
            cells = {r["label"]: r for r in mine if r["row"] == row}
            line = [row] + [_fmt(cells[h]["f"]) if h in cells else "–" for h in heats]
            for g in ga_labels:
                c = cells.get(g)
                line.append("–" if c is None else f"{format_mean_std(c['f'], c['f_std'], digits=3)} ({c['runs']})"
                            if c["f"] is not None else f"– ({c['reached']}/{c['runs']} reached)")
            if exact_label:
                c = cells.get(exact_label)
                line.append(_fmt(c["f"]) if c else "–")
            for h, g in pairs:
                heat, c = cells.get(h), cells.get(g)
                if heat is not None and heat["f"] is not None and c is not None and not c["reached"]:
                    # no run of the GA reached the goal: the heat plan, which did, outperforms it
                    tallies.setdefault((h, g), []).append((True, True, ""))
                    line.append("yes (GA unreached)")
                    continue
                if heat is None or c is None or heat["f"] is None or c["f"] is None:
                    line.append("–")
                    continue
                win = heat["f"] >= c["f"] - 1e-12
                beats_all = c["f_max"] is not None and heat["f"] >= c["f_max"] - 1e-12
                tallies.setdefault((h, g), []).append((win, beats_all, f"{scenario} {row} ({heat['f']:.3f} < "
                                                       f"{c['f']:.3f})"))
                line.append("yes" if win else "**no**")
            out.append("| " + " | ".join(line) + " |")
        runtimes = []
        for label in heats + ga_labels + ([exact_label] if exact_label else []):
            c = [r for r in mine if r["label"] == label]
            if not c:
                continue
            first = c[0]
            if label in heats:
                rt = mean_std([r["runtime_s"] for r in c])
                runtimes.append(f"{label} {format_mean_std(*rt, digits=3)} s per plan (over the four rows)")
            else:
                runtimes.append(f"{label} {format_mean_std(first['runtime_s'], first['runtime_s_std'], digits=3)} s, "
                                f"time {format_mean_std(first['time'], first['time_std'], digits=2)} s "
                                f"(gap {_pct(first['gap'])}, {first['reached']}/{first['runs']} reached)")
        out += ["", "Runtime per plan: " + "; ".join(runtimes) + ".", ""]
    speed = _speedups(rows)
    out += ["**Targets.**", ""]
    for (h, g), cells in tallies.items():
        wins = sum(c[0] for c in cells)
        every = sum(c[1] for c in cells)
        losses = [c[2] for c in cells if not c[0]]
        out.append(f"- {h} f ≥ {_ga_name(g)} mean f on {wins} of {len(cells)} (map, row) cells"
                   + (f"; not on {', '.join(losses)}" if losses else "") + f"; ≥ every run's f on {every} of "
                   f"{len(cells)}.")
    if any(not c[0] for cells in tallies.values() for c in cells):
        out.append("- why a GA can win a row: eqs. 10 and 11 divide by the path's own length, so a longer path "
                   "with as many changes of command (or more safe poses) scores higher; the heat planners sum over "
                   "commands and never pad, the GA's chromosomes do (its paths are slower: see the time row).")
    for h in dict.fromkeys(s[1] for s in speed):
        for g in dict.fromkeys(s[2] for s in speed if s[1] == h):
            mine = [s for s in speed if s[1] == h and s[2] == g]
            low, high = min(s[5] for s in mine), max(s[5] for s in mine)
            out.append(f"- speed: {g} takes {low:.0f}–{high:.0f}× {h}'s time per plan ("
                       + ", ".join(f"{s[0]} {s[5]:.0f}×" for s in mine) + "); target ≥ 20×: "
                       + ("met." if low >= 20 else "not met on every map."))
    out.append("")
    return out


def _table8_md(rows: list[Mapping]) -> list[str]:
    out = ["## Table 8: O-shape-only A* and Dijkstra against the heat planner (indoor room with a doorway)", "",
           "Our 128 × 128 reconstruction of the paper's room with a two-cell doorway the O-shape passes. Energy, "
           "the paper's other measure, is not modelled; B2's travelled distance stands beside the time. The "
           "paper's heat row is its multi-objective plan, the paper's numbers beside its algorithm as published "
           "(heat-paper); ours (heat) beside, and our time-only plan in addition.", "",
           "| method | time s | time vs A* | B2 distance | distance vs A* | shapeshifts | rotations | shapes "
           "| runtime s | paper: time vs A* | paper: energy vs A* |",
           "|---|---:|---:|---:|---:|---:|---:|---|---:|---:|---:|"]
    for r in rows:
        out.append(f"| {r['label']} | {_fmt(r['time'], 2)} | {r['time_pct']:+.2f} % | {_fmt(r['path_length'], 2)} | "
                   f"{r['distance_pct']:+.2f} % | {r['shapeshifts']} | {r['rotations']} | {r['shapes_used']} | "
                   f"{_fmt(r['runtime_s'])} | "
                   + ("–" if r.get("paper_time_pct") is None else f"{r['paper_time_pct']:+.2f} %") + " | "
                   + ("–" if r.get("paper_energy_pct") is None else f"{r['paper_energy_pct']:+.2f} %") + " |")
    by = {r["label"]: r for r in rows}
    astar, dijkstra = by.get("O-only A*"), by.get("O-only Dijkstra (diagonals)")
    heats = [r for r in rows if r["method"] in HEAT_METHODS]
    if astar and dijkstra and heats:
        out += ["", "**Targets** (heat ≥ 15 % faster than O-only A*; A* > Dijkstra > heat):", ""]
        for h in heats:
            order = astar["time"] > dijkstra["time"] > h["time"]
            out.append(f"- {h['label']}: {-h['time_pct']:.1f} % faster than A* "
                       f"({'met' if -h['time_pct'] >= 15 else 'not met'}); A* {astar['time']:.1f} > Dijkstra "
                       f"{dijkstra['time']:.1f} > heat {h['time']:.1f}: {'holds' if order else 'does not hold'}.")
    out.append("")
    return out


def _fig13_md(fig: Mapping) -> list[str]:
    replans = "; ".join(f"after {r['step']} commands at ({r['pose'][0]}, {r['pose'][1]}) in the {r['pose'][2]}-shape, "
                        "revealed " + ", ".join(f"({x}, {y})" for x, y in r["revealed"]) for r in fig["replans"])
    ratio = "–" if fig["ratio"] is None else f"{fig['ratio']:.3f}"
    return ["## Fig. 13: replanning with hidden obstacles", "",
            f"`replan_heat({fig['scenario']}, sensor_range={fig['sensor_range']:g})`, time-only plans (the "
            "paper's Fig. 13). The paper: start (2, 2), goal (22, 21), unknown cells (5, 11) and (6, 11), the "
            "robot replans at cell (5, 7).", "",
            f"- reached: {fig['reached']}; plans: {fig['plans']} ({len(fig['replans'])} replan"
            f"{'' if len(fig['replans']) == 1 else 's'}{': ' + replans if replans else ''})",
            f"- executed time {fig['time']:.2f} s; true world's exact optimum (Dijkstra with the diagonals, every "
            f"obstacle known) {_fmt(fig['true_optimum'], 2)} s: ratio {ratio} (target ≤ 1.25); the plan on the known "
            f"map alone {_fmt(fig['known_plan'], 2)} s",
            f"- executed path's costs: f_t {fig['f_t']:.3f}, f_sm {fig['f_sm']:.3f}, f_sf {fig['f_sf']:.3f}; "
            f"runtime {fig['runtime_s']:.3f} s", ""]


def report(run: StudyRun | None = None, *, table8: Iterable[Mapping] | None = None,
           fig13: Mapping | None = None) -> str:
    """The Markdown tables of Do et al. 2021's study, the paper's numbers beside ours.

    Parameters
    ----------
    run : StudyRun, optional
        A run of the ``do2021`` study (or a study of its shape: ``plan`` trials with the metric
        ``heat_fitness``): Table 6 from its heat trials (rows told apart by their weights), Table 7
        on the maps where a GA ran.
    table8 : list of dict, optional, keyword-only
        :func:`run_table8`'s rows.
    fig13 : dict, optional, keyword-only
        :func:`run_fig13`'s run.

    Returns
    -------
    str

    Raises
    ------
    ParameterError
        If nothing is given, ``run`` is not a plan study's :class:`~htetro_opt.studies.runner.StudyRun`
        or lacks the metric ``heat_fitness``.
    """
    run = _check_run(run)
    table8 = None if table8 is None else list(table8)
    if run is None and table8 is None and fig13 is None:
        raise ParameterError("report needs a run, table8 or fig13")
    out = ["# Do et al. 2021 (IEEE Access): the heat-conduction planner re-run", ""]
    if run is not None:
        seeds = run.study.seeds
        out += [f"Study `{run.study.name}`: {len(run.records)} trials, GA seeds {seeds[0]}–{seeds[-1]} "
                f"({len(seeds)}).", ""]
        t6 = _table6_rows(run)
        if t6:
            out += _table6_md(t6)
        t7 = _table7_rows(run)
        if t7:
            out += _table7_md(t7)
    if table8:
        out += _table8_md(table8)
    if fig13 is not None:
        out += _fig13_md(fig13)
    failed = [] if run is None else [r for r in run.records if r.get("error") is not None]
    if failed:
        out += ["## Failed trials", ""] + [
            f"- {r['scenario']} {r['label']}" + ("" if r["seed"] is None else f" seed {r['seed']}") + f": {r['error']}"
            for r in failed] + [""]
    return "\n".join(out)


def write_report(folder: str | os.PathLike, run: StudyRun | None = None, *, table8=None, fig13=None,
                 name: str = "do2021") -> tuple[Path, Path]:
    """Write :func:`report` as ``folder/<name>.md`` and :func:`report_rows` as ``folder/<name>.csv``,
    each atomically (no half-written file is left).

    Returns
    -------
    (Path, Path)
        The Markdown and CSV files.

    Raises
    ------
    OutputError
        If a file cannot be written (the folder must exist).
    """
    table8 = None if table8 is None else list(table8)
    return write_study_report(folder, name, report(run, table8=table8, fig13=fig13),
                              report_rows(run, table8=table8, fig13=fig13))


# --- the ablation study (do2021_ablation.toml) ------------------------------------------------------
def ablation_rows(run: StudyRun) -> list[dict]:
    """The ``do2021_ablation`` study's figures, one row per variant (a label's part before ", <row>"):
    ``plans``; ``gap_mean`` / ``gap_max`` over its plans and ``time_gap_mean`` / ``time_gap_max``
    over its time-row plans (fractions of the exact minimum time); ``f_<row>``, the mean over the maps
    of that row's own f; ``property``, the maps where its four rows keep Table 6's property (each of
    f_t, f_sm, f_sf and f at equal weights best in its own row), out of ``maps``; ``runtime_median``.

    Raises
    ------
    ParameterError
        As :func:`report`, or if a trial failed or a label does not end in a Table-6 row's name.
    """
    run = _check_run(run)
    trials = [r for r in run.records if r.get("kind", "trial") == "trial"]
    if any(not _ok(r) for r in trials):
        raise ParameterError("the ablation table needs every trial: some failed (see the study's records)")
    rows, names = [], dict(ROWS)
    parts = {}
    for r in trials:
        variant, _, row = r["label"].rpartition(", ")
        if row not in names:
            raise ParameterError(f"label {r['label']!r} does not end in a Table-6 row ({', '.join(names)})")
        parts.setdefault(variant, []).append((row, r))
    for variant, mine in parts.items():
        gaps = [r["gap"] for _, r in mine if r.get("gap") is not None]
        timed = [r["gap"] for row, r in mine if row == "time" and r.get("gap") is not None]
        maps = list(dict.fromkeys(r["scenario"] for _, r in mine))
        held = 0
        for scenario in maps:
            cells = [{"row": row, **{k: r.get(f"heat_{k}") for k in _COSTS}} for row, r in mine
                     if r["scenario"] == scenario]
            held += not _property_breaks(cells) and len(cells) == len(ROWS)
        rows.append({"variant": variant, "plans": len(mine), "reached": sum(bool(r.get("reached")) for _, r in mine),
                     "gap_mean": float(np.mean(gaps)) if gaps else None, "gap_max": max(gaps, default=None),
                     "time_gap_mean": float(np.mean(timed)) if timed else None, "time_gap_max": max(timed, default=None),
                     **{f"f_{row}": _mean([r.get("heat_f") for name, r in mine if name == row]) for row, _ in ROWS},
                     "property": held, "maps": len(maps),
                     "runtime_median": float(np.median([r["runtime_s"] for _, r in mine]))})
    return rows


def _mean(values) -> float | None:
    values = [v for v in values if v is not None]
    return float(np.mean(values)) if values else None


def ablation_report(run: StudyRun) -> str:
    """:func:`ablation_rows` as the Markdown table of docs/papers/do2021.md."""
    out = ["| variant | gap to exact, % (mean / max) | time row gap, % (mean / max) | "
           + " | ".join(f"f {row} row" for row, _ in ROWS) + " | Table-6 property holds | s per plan (median) |",
           "|---|" + "---:|" * (4 + len(ROWS))]
    for r in ablation_rows(run):
        def pair(mean, most):
            return "–" if mean is None else f"{100 * mean:.1f} / {100 * most:.1f}"
        out.append(f"| {r['variant']} | {pair(r['gap_mean'], r['gap_max'])} | {pair(r['time_gap_mean'], r['time_gap_max'])}"
                   " | " + " | ".join(_fmt(r[f"f_{row}"]) for row, _ in ROWS)
                   + f" | {r['property']} of {r['maps']} | {r['runtime_median']:.3f} |")
    return "\n".join(out) + "\n"
