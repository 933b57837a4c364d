"""A study's summary: one row per scenario × method of its records, the fronts' hypervolume and IGD+,
as CSV and Markdown.

**Multi-objective metrics** (metric ``"front"``, the GA methods). A trial records the leading front F0
of its last leg's final population as its distinct ``[f_gr, f_t, f_sm, f_sf]`` rows, rounded to 6
decimals, and the **hypervolume** ``hv`` of those rows (:func:`hypervolume`). Both indicators are computed
in pymoo's minimisation space, F = −(f_gr, f_t, f_sm, f_sf), as in the notebook ``01_htetro_ga_pareto``:

- HV's reference point is :data:`~htetro_opt.studies.runner.HV_REFERENCE`, r = (0, 1, 0, 0), i.e.
  f_gr = 0, f_t = −1, f_sm = 0, f_sf = 0, fixed in advance, the same for every method, seed and
  scenario, and not taken from the runs (a data-derived point would change with the set of runs
  compared). f_gr, f_sm and f_sf lie in [0, 1] and 0 is the worst value each can take, so r is their
  nadir. f_t has no lower bound (a path slower than t_max has f_t < 0); f_t = −1 is a path taking
  2 t_max, the time of the longest all-translation chromosome the operators keep (offspring are cut at
  2 l_p,max genes); slower members add nothing. The box between the ideal point (−1, −1, −1, −1) and r
  has volume 2, so 0 ≤ HV ≤ 2.
- **IGD+** (Ishibuchi et al. 2015, pymoo's ``IGDPlus``; lower is better, 0 when a run found the whole
  reference front) needs every run: :func:`front_metrics`, applied by :func:`summarise`, measures each
  record's front against the reference front of its scenario: the union of the fronts of every method
  and seed, reduced to its leading front, in the same unnormalised space. Trials whose ``clearance`` or
  ``max_length`` differ optimise different fitnesses and are not pooled.
"""

from __future__ import annotations

import csv
import io
import numbers
import os
import statistics
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from htetro_opt._files import write_text
from htetro_opt.errors import OutputError, ParameterError
from htetro_opt.studies._study import _NAME
from htetro_opt.studies._trial import HV_REFERENCE
from htetro_opt.studies.metrics import format_mean_std, group_records, mean_std, values_of

__all__ = ["front_metrics", "hypervolume", "markdown_summary", "rows_csv", "summarise", "write_report",
           "write_summary"]

_METRIC_FIELDS = {
    "plan": ("reached", "time", "n_commands", "translations", "rotations", "shapeshifts", "path_length",
             "generations", "reach_generation", "reach_time_s", "f_gr", "f_t", "f_sm", "f_sf", "reference", "gap",
             "heat_f_t", "heat_f_sm", "heat_f_sf", "heat_f", "shapes_used", "hv", "igd_plus", "fastest_time",
             "fastest_gap", "length", "smoothness_deg", "safety", "min_clearance", "min_robot_distance", "conflicts"),
    "tile": ("tiles", "overlapping", "n_I", "n_O", "n_L", "n_J", "n_Z", "n_S", "n_T"),
    "sequence": ("cost", "waypoints", "optimal", "reference", "gap"),
    "cover": ("action_cost", "time", "coverable", "covered", "lower_bound", "reference", "gap",
              "average_coverage_time", "recovered_pct", "coverage_pct", "switches", "regions", "regions_optimal",
              "mopup_commands"),
}
"""The summary's columns per task (the records hold more)."""


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
    fields = [k for task, names in _METRIC_FIELDS.items() if any(r.get("task") == task for r in records)
              for k in names]
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
    if isinstance(value, (list, tuple)):  # an order, a set of weights: one cell, space-separated
        return " ".join(_cell(v) for v in value)
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
    markdown, table = write_report(folder, name, markdown_summary(summary), summary, what="study summary")
    return table, markdown


def write_report(folder: str | os.PathLike, name: str, markdown: str, rows: Sequence[Mapping[str, Any]], *,
                 what: str = "study report") -> tuple[Path, Path]:
    """Write a study's report: ``folder/<name>.md`` (``markdown``) and ``folder/<name>.csv`` (``rows``, by
    :func:`rows_csv`), each atomically (no half-written file is left). Every study writes its report so.

    Returns
    -------
    (Path, Path)
        The Markdown and CSV files.

    Raises
    ------
    OutputError
        If the folder cannot be made or a file cannot be written.
    """
    folder = Path(folder)
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as err:
        raise OutputError(f"cannot create the folder {str(folder)!r} for the {what}: {err.strerror or err}") from err
    return (write_text(folder / f"{name}.md", markdown, what=what),
            write_text(folder / f"{name}.csv", rows_csv(rows), what=what))
