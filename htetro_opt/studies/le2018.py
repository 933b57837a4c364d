"""The experiments of Le et al. 2018 (Electronics) re-run: its Tables 1–5, with the exact optimum.

The paper tiles four workspaces (6 × 6, 8 × 7, 10 × 10, and 11 × 11 with obstacles), orders the
tiles' waypoints by its GA and by zigzag, spiral and greedy baselines, and reports:

- **Table 1**: cost (eq. 2, weights 0.25) and path-generating time of every method on the 11 × 11
  tileset (28 waypoints);
- **Table 2**: on the 10 × 10 tileset, the optimal path under seven weight settings, priced with the
  setting's own weights and with all four blocks at 0.25;
- **Table 3**: the cost of two alternative tilesets per workspace;
- **Tables 4–5**: a coverage simulation on 11 × 11: distance travelled by the blocks, average grid
  coverage time and the share of re-covered cells at heat-map thresholds 150 and 100.

:func:`run_le2018` (with :func:`report`) re-runs all of it on the paper's own labelled tilesets (bundled, transcribed from
its figures) and on tilings of ours, with every method of :mod:`htetro_opt.solvers.sequencing`, and
adds what the paper could not report: each method's gap to the proven optimum (the exact method).
The paper's numbers sit beside ours (``PAPER_*``). Its tables do not say from which tile its paths
start; ours start from tile 1, as its figures' paths do.

On the study runner (:mod:`htetro_opt.studies.runner`), Tables 1 and 2 are the bundled study
``le2018`` (``studies/data/le2018.toml``, or :func:`le2018_study`), run by the runner's own
``sequence`` trial; :func:`report` lays its records out as today's tables, deriving Table 2's
equal-weight prices and Tables 4–5's coverage simulation from the recorded orders (both are
deterministic given an order). Table 3 tiles with a shuffle drawn from a seed, which the runner's
``sequence`` task does not do: it stays :func:`run_table3`, passed to :func:`report`::

    from htetro_opt.studies import le2018

    run = le2018.run_le2018(seeds=5, out="results")        # or run_study(load_study("le2018"))
    print(le2018.report(run, table3=le2018.run_table3(seeds=range(2))))

The command line still runs the in-process path::

    htetro-opt study le2018 --seeds 5 --out DIR

which prints the markdown tables and, with ``--out``, writes ``DIR/le2018.md`` and
``DIR/le2018.csv`` (one line per method run).
"""

from __future__ import annotations

import numbers
import os
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

from htetro_opt._files import write_text
from htetro_opt._validation import check_int, check_time_limit
from htetro_opt.errors import ParameterError, TilingError
from htetro_opt.model.coverage import simulate_coverage
from htetro_opt.problems.waypoint_sequencing import SequencingInstance, path_cost
from htetro_opt.scenarios import Tileset, load_scenario, load_tileset, tileset_path
from htetro_opt.solvers.sequencing import sequence_waypoints
from htetro_opt.solvers.sequencing._spec import SPEC as SEQUENCING
from htetro_opt.solvers.sequencing._spec import is_tileset
from htetro_opt.solvers.tiling import tile_workspace
from htetro_opt.studies.metrics import format_mean_std, mean_std
from htetro_opt.studies.runner import Study, StudyRun, rows_csv
from htetro_opt.studies.runner import run_study as run_runner_study

__all__ = [
    "PAPER_TABLE1",
    "PAPER_TABLE2",
    "PAPER_TABLE3",
    "PAPER_TABLE4",
    "PAPER_TABLE5",
    "PAPER_TILESETS",
    "paper_tileset",
    "TABLE1_METHODS",
    "TABLE1_SCENARIOS",
    "TABLE2_SCENARIOS",
    "le2018_study",
    "run_le2018",
    "report",
    "run_table1",
    "run_table2",
    "run_table3",
    "run_table45",
    "markdown_report",
    "write_csv",
]

PAPER_TABLE1 = {  # method: (cost weight, path generating time s), 11 x 11, 28 waypoints
    "zigzag": (71.642, 0.012),
    "zigzag2": (70.124, 0.155),
    "spiral": (68.175, 0.158),
    "spiral2": (67.124, 0.522),
    "greedy": (65.216, 30.240),
    "ga-plain": (62.368, 1.150),
}
TABLE1_METHODS = ("zigzag", "zigzag2", "spiral", "spiral2", "greedy", "ga-plain", "ga", "ortools", "local", "exact")
TABLE1_SCENARIOS = ("paper_11x11_fig13d", "tiling_11x11")
"""Table 1's maps: the paper's 11 × 11 tileset and our tiling of its map (tiled first, by the tile task's default method)."""
TABLE2_SCENARIOS = ("paper_10x10_fig13c",)
"""Table 2's map: the paper's 10 × 10 tileset."""
METHOD_NAMES = {
    "zigzag": "Zigzag 1 row", "zigzag2": "Zigzag 2 rows", "spiral": "Spiral 1 row", "spiral2": "Spiral 2 rows",
    "greedy": "Greedy search", "ga-plain": "GA as published (ga-plain)",
    "ga": "GA with our additions (ga)",
    "ortools": "OR-Tools GLS", "local": "NN + 2-opt/Or-opt", "exact": "Exact (CP-SAT)",
}

PAPER_TABLE2 = (  # weights (α, β, λ, γ), meaning, cost of considered blocks, cost of 4 blocks; 10 x 10
    ((1.0, 0.0, 0.0, 0.0), "only block a", 50.124, 55.435),
    ((0.0, 1.0, 0.0, 0.0), "only block b", 50.365, 56.321),
    ((0.0, 0.0, 1.0, 0.0), "only block c", 51.321, 56.891),
    ((0.0, 0.0, 0.0, 1.0), "only block d", 52.013, 58.432),
    ((0.5, 0.5, 0.0, 0.0), "only blocks a, b", 51.864, 53.224),
    ((0.0, 0.0, 0.5, 0.5), "only blocks c, d", 51.315, 54.863),
    ((0.25, 0.25, 0.25, 0.25), "all four blocks", 51.417, 51.417),
)

PAPER_TABLE3 = {  # workspace scenario: ((allowed shapes as the paper lists them, cost weight), ...)
    "tiling_6x6": (("LSJOZ", 10.901), ("OIJL", 10.152)),
    "tiling_8x7": (("JLI", 30.761), ("OTLI", 31.434)),
    "tiling_10x10": (("TZ", 51.417), ("ZTJI", 52.325)),
    "tiling_11x11": (("JLTS", 63.122), ("OJLI", 61.1368)),
}

PAPER_TILESETS = {  # bundled tileset: (workspace scenario, the figure's printed cost weight or None)
    "paper_6x6_fig13a": ("tiling_6x6", 10.156),
    "paper_6x6_fig16a": ("tiling_6x6", 10.901),
    "paper_6x6_fig16c": ("tiling_6x6", 9.583),
    "paper_8x7_fig13b": ("tiling_8x7", 30.759),
    "paper_10x10_fig13c": ("tiling_10x10", 51.417),
    "paper_11x11_fig13d": ("tiling_11x11", None),  # the figure's number is garbled in our copy
}

PAPER_TABLE4 = {  # method: (average grid time s, distance travelled cm), 11 x 11
    "zigzag": (5.1439, 2976), "zigzag2": (3.9856, 2272), "spiral": (5.3063, 3050),
    "spiral2": (3.3869, 1994), "greedy": (3.2904, 1922), "ga-plain": (3.2290, 1890),
}
PAPER_TABLE5 = {  # method: (% re-covered at threshold 150, at threshold 100), 11 x 11
    "zigzag": (34.71, 38.01), "zigzag2": (25.61, 28.92), "spiral": (30.57, 32.23),
    "spiral2": (27.27, 29.75), "greedy": (20.66, 23.96), "ga-plain": (15.70, 18.18),
}


def paper_tileset(name: str) -> Tileset:
    """A bundled paper tileset (a key of :data:`PAPER_TILESETS`), named so and with its map's cell size."""
    scenario = load_scenario(PAPER_TILESETS[name][0])
    ts = load_tileset(tileset_path(name), cell_size=scenario.workspace.cell_size)
    return Tileset(ts.occupancy, ts.blocks, ts.ids, ts.cell_size, name)


def _check_seeds(seeds) -> list[int]:
    seeds = list(seeds)
    if not seeds:
        raise ParameterError("seeds must be a non-empty list of non-negative integers, got []")
    return [check_int(s, f"seeds[{i}]", minimum=0) for i, s in enumerate(seeds)]


def _on_paper_map(tileset: Tileset, scenarios: Sequence[str]) -> bool:
    """Whether ``tileset`` tiles the map a paper table is about: one of ``scenarios``, as bundled or as our
    tiling of it (named ``ours <scenario> (…)`` by :func:`_tileset`)."""
    words = tileset.name.split()
    return tileset.name in scenarios or (len(words) > 1 and words[0] == "ours" and words[1] in scenarios)


def run_table1(tileset: Tileset, *, seeds: Iterable[int] = (0,), methods: Sequence[str] = TABLE1_METHODS,
               time_limit: float | None = None) -> list[dict]:
    """Every method on one tileset from tile 1: one record per (method, seed), with the gap to the optimum.

    A method that does not draw from the seed (the sequencing spec says which) runs once, seed 0.
    ``time_limit`` caps each method that takes one.
    """
    seeds = _check_seeds(seeds)
    time_limit = check_time_limit(time_limit)
    instance = SequencingInstance.from_tileset(tileset, start=tileset.ids[0])
    optimum = sequence_waypoints(instance, method="exact")
    records = []
    for method in methods:
        chosen = SEQUENCING.method(method)
        for seed in (seeds if chosen.draws() else [0]):
            options = {"seed": seed} if chosen.takes("seed") else {}
            if time_limit is not None and chosen.takes("time_limit"):
                options["time_limit"] = time_limit
            result = optimum if method == "exact" else sequence_waypoints(instance, method=method, **options)
            records.append({
                "table": 1, "tileset": tileset.name, "paper_map": _on_paper_map(tileset, TABLE1_SCENARIOS),
                "method": method, "seed": seed, "cost": result.cost,
                "runtime_s": result.runtime_s, "optimum": optimum.cost,
                "proven": bool(optimum.info.get("optimal", False)),
                "gap_pct": 100.0 * (result.cost - optimum.cost) / optimum.cost, "order": result.tiles,
            })
    return records


def run_table2(tileset: Tileset) -> list[dict]:
    """Table 2: the optimal order under each weight setting, priced by its own and by equal weights."""
    equal = SequencingInstance.from_tileset(tileset, start=tileset.ids[0])
    paper_map = _on_paper_map(tileset, TABLE2_SCENARIOS)  # the paper's numbers are of its 10 x 10 map only
    records = []
    for weights, meaning, paper_own, paper_four in PAPER_TABLE2:
        if not paper_map:
            paper_own = paper_four = None
        instance = SequencingInstance.from_tileset(tileset, start=tileset.ids[0], weights=weights)
        result = sequence_waypoints(instance, method="exact")
        records.append({
            "table": 2, "tileset": tileset.name, "paper_map": paper_map,
            "weights": ",".join(f"{w:g}" for w in weights), "meaning": meaning,
            "cost_own": result.cost, "cost_four": path_cost(equal.cost, result.order),
            "paper_own": paper_own, "paper_four": paper_four, "proven": bool(result.info.get("optimal", False)),
        })
    return records


def run_table3(*, seeds: Iterable[int] = (0,), method: str = "cpsat") -> list[dict]:
    """Table 3: alternative tilesets per workspace, each at its proven optimum from tile 1.

    For every workspace: the paper's own labelled tilesets, and our tilings (by the tiling
    ``method``) with each allowed-shape set the paper's Table 3 names, one tiling per seed (the
    tiler's order shuffled by the seed); an untileable set is recorded as such.
    """
    seeds = _check_seeds(seeds)
    records = []
    for name, (scenario_name, printed) in PAPER_TILESETS.items():
        ts = paper_tileset(name)
        optimum = sequence_waypoints(SequencingInstance.from_tileset(ts, start=ts.ids[0]), method="exact")
        records.append({"table": 3, "workspace": scenario_name, "tileset": name, "shapes": "".join(sorted(set(ts.shapes))),
                        "tiles": len(ts), "cost": optimum.cost, "paper": printed,
                        "proven": bool(optimum.info.get("optimal", False))})
    for scenario_name, rows in PAPER_TABLE3.items():
        workspace = load_scenario(scenario_name).workspace
        for shapes, printed in rows:
            for seed in seeds:
                label = f"ours {shapes} seed {seed}"
                try:
                    ts = tile_workspace(workspace, shapes=shapes, method=method, shuffle=True, seed=seed,
                                        name=label).tileset
                except TilingError as err:
                    records.append({"table": 3, "workspace": scenario_name, "tileset": label, "shapes": shapes,
                                    "tiles": 0, "cost": None, "paper": printed, "proven": False, "note": str(err)})
                    continue
                optimum = sequence_waypoints(SequencingInstance.from_tileset(ts, start=1), method="exact")
                records.append({"table": 3, "workspace": scenario_name, "tileset": label,
                                "shapes": "".join(sorted(set(ts.shapes))), "tiles": len(ts), "cost": optimum.cost,
                                "paper": printed, "proven": bool(optimum.info.get("optimal", False))})
    return records


def run_table45(tileset: Tileset, table1: Iterable[dict]) -> list[dict]:
    """Tables 4–5: the coverage simulation of every order of Table 1 (the first seed of each method).

    The distance is the mean over the four blocks of the distance each travels (the paper: "averaging
    the final values of the trajectories"), which equals the path's eq.-2 cost at equal weights. The
    re-covered shares are read on one heat-map scale for all methods: the longest mean coverage time
    of any cell under any of them is 255. (Each method scaled to its own maximum, the better paths
    look worse, since their hottest cell is cooler; the paper does not say which scale it used.)
    """
    runs, seen = [], set()
    for row in table1:
        if row["tileset"] != tileset.name or row["method"] in seen:
            continue
        seen.add(row["method"])
        order = [tileset.index(t) for t in row["order"]]
        runs.append((row, simulate_coverage(tileset, order)))
    scale = max(float(coverage.cell_time.max()) for _, coverage in runs)
    paper_map = _on_paper_map(tileset, TABLE1_SCENARIOS)  # the paper's Tables 4-5 are of its 11 x 11 map
    return [{
        "table": 4, "tileset": tileset.name, "paper_map": paper_map, "method": row["method"], "cost": row["cost"],
        "distance_cells": float(coverage.mean_block_distance),
        "distance_cm": 100.0 * tileset.cell_size * float(coverage.mean_block_distance),
        "average_grid_time_s": float(coverage.average_grid_time),
        "recovered_150": float(coverage.recovered(150, scale=scale)),
        "recovered_100": float(coverage.recovered(100, scale=scale)),
    } for row, coverage in runs]


def _fmt(value, digits: int = 3) -> str:
    return "–" if value is None else f"{value:.{digits}f}"


def markdown_report(records: Iterable[dict]) -> str:
    """The tables as markdown, the paper's numbers beside ours."""
    records = list(records)
    out = []
    for name in dict.fromkeys(r["tileset"] for r in records if r["table"] == 1):
        rows = [r for r in records if r["table"] == 1 and r["tileset"] == name]
        optimum = rows[0]["optimum"]
        best = "no optimum" if optimum is None else f"optimum {optimum:.3f}{'' if rows[0]['proven'] else ' (not proven)'}"
        elsewhere = "" if rows[0].get("paper_map", True) else "; the paper's Table 1 is on its 11 × 11 map, not this one"
        out += [f"### Table 1 on {name} ({len(rows[0]['order'])} waypoints, start tile {rows[0]['order'][0]}; "
                f"{best}{elsewhere})", "",
                "| method | cost (ours) | gap to optimum | time s (ours) | cost (paper) | time s (paper) |",
                "|---|---|---|---|---|---|"]
        for method in dict.fromkeys(r["method"] for r in rows):
            mine = [r for r in rows if r["method"] == method]
            cost, gap, runtime = (mean_std([r[k] for r in mine if r[k] is not None])
                                  for k in ("cost", "gap_pct", "runtime_s"))
            paper = PAPER_TABLE1.get(method, (None, None)) if rows[0].get("paper_map", True) else (None, None)
            runs = f" ({len(mine)} seeds)" if len(mine) > 1 else ""
            out.append(f"| {METHOD_NAMES.get(method, method)}{runs} | {format_mean_std(*cost, digits=3)} | "
                       f"{format_mean_std(*gap, digits=2)} % | {format_mean_std(*runtime, digits=3)} | "
                       f"{_fmt(paper[0])} | {_fmt(paper[1])} |")
        out.append("")
    for name in dict.fromkeys(r["tileset"] for r in records if r["table"] == 2):
        rows = [r for r in records if r["table"] == 2 and r["tileset"] == name]
        elsewhere = "" if rows[0].get("paper_map", True) else " (the paper's Table 2 is on its 10 × 10 map, not this one)"
        out += [f"### Table 2 on {name}: optimal order under each weight setting{elsewhere}", "",
                "| weights α,β,λ,γ | meaning | cost, own weights (ours) | cost, 4 blocks (ours) | own (paper) | 4 blocks (paper) |",
                "|---|---|---|---|---|---|"]
        out += [f"| {r['weights']} | {r['meaning']} | {r['cost_own']:.3f} | {r['cost_four']:.3f} | "
                f"{_fmt(r['paper_own'])} | {_fmt(r['paper_four'])} |" for r in rows]
        out.append("")
    rows = [r for r in records if r["table"] == 3]
    if rows:
        out += ["### Table 3: alternative tilesets, each at its proven optimum from tile 1", "",
                "| workspace | tileset | shapes | tiles | optimum (ours) | paper |", "|---|---|---|---|---|---|"]
        out += [f"| {r['workspace']} | {r['tileset']} | {r['shapes']} | {r['tiles']} | "
                f"{_fmt(r['cost']) if r['cost'] is not None else 'untileable'} | {_fmt(r['paper'])} |" for r in rows]
        out.append("")
    for name in dict.fromkeys(r["tileset"] for r in records if r["table"] == 4):
        rows = [r for r in records if r["table"] == 4 and r["tileset"] == name]
        out += [f"### Tables 4–5 on {name}: coverage simulation (first seed of each method)", "",
                "| method | distance cm (ours) | (paper) | avg grid time s (ours) | (paper) | "
                "re-covered >150 (ours) | (paper) | >100 (ours) | (paper) |", "|---|---|---|---|---|---|---|---|---|"]
        for r in rows:
            paper = r.get("paper_map", True)  # the paper's Tables 4-5 are on its 11 x 11 map
            t4 = PAPER_TABLE4.get(r["method"], (None, None)) if paper else (None, None)
            t5 = PAPER_TABLE5.get(r["method"], (None, None)) if paper else (None, None)
            out.append(f"| {METHOD_NAMES.get(r['method'], r['method'])} | {r['distance_cm']:.0f} | {_fmt(t4[1], 0)} | "
                       f"{r['average_grid_time_s']:.3f} | {_fmt(t4[0], 4)} | {r['recovered_150']:.2f} % | "
                       f"{_fmt(t5[0], 2)} | {r['recovered_100']:.2f} % | {_fmt(t5[1], 2)} |")
        out.append("")
    return "\n".join(out)


def write_csv(records: Iterable[dict], path) -> Path:
    """One CSV line per record (the union of their keys as columns; a list, an order, space-separated),
    written atomically."""
    return write_text(Path(path), rows_csv(list(records)), what="study report")


# --- on the study runner ---------------------------------------------------------------------------
def _weights_label(weights: Sequence[float]) -> str:
    return ",".join(f"{float(w):g}" for w in weights)


def le2018_study(seeds: int | Sequence[int] = 5, *, methods: Sequence[str] = TABLE1_METHODS,
                  weights: bool = True, scenarios: Sequence[str] = TABLE1_SCENARIOS + TABLE2_SCENARIOS,
                  time_limit: float | None = None) -> Study:
    """Tables 1 and 2 as a study of the runner (task ``sequence``, metric ``"gap"``); with the
    defaults the bundled study ``le2018`` (``load_study("le2018")``).

    Parameters
    ----------
    seeds : int or sequence of int
        N for seeds 0 … N−1, or the seeds (the methods that draw from the seed run once per seed).
    methods : sequence of str, keyword-only
        Table 1's methods, one entry each, labelled by the method's name.
    weights : bool, keyword-only
        Add Table 2's entries: the exact method under each weight setting of :data:`PAPER_TABLE2`,
        labelled ``"exact, weights a,b,c,d"``.
    scenarios : sequence of str, keyword-only
        Labelled tilesets, or maps tiled first (every entry runs on every scenario).
    time_limit : float, optional, keyword-only
        A cap in seconds on each method but the exact one (whose results are the optimum).

    Returns
    -------
    Study

    Raises
    ------
    StudyError
        If a method or scenario is unknown, or a value out of range.

    Examples
    --------
    >>> study = le2018_study(2, methods=("zigzag", "greedy"), weights=False, scenarios=["paper_6x6_fig13a"])
    >>> [(t.label, t.seed) for t in study.trials()]
    [('zigzag', None), ('greedy', 0), ('greedy', 1)]
    """
    if isinstance(methods, str) or not isinstance(methods, Sequence):
        raise ParameterError(f"methods must be a list of sequencing methods, got {methods!r}")
    time_limit = check_time_limit(time_limit)
    cap = {} if time_limit is None else {"time_limit": time_limit}
    # the cap on each heuristic that takes one (the exact solver keeps its own: it proves the optimum)
    entries: list[dict[str, Any]] = [{"method": m, **(cap if m != "exact" and SEQUENCING.method(m).takes("time_limit")
                                                       else {})} for m in methods]
    if weights:
        entries += [{"label": f"exact, weights {_weights_label(w)}", "method": "exact", "weights": list(w)}
                    for w, *_ in PAPER_TABLE2]
    if not isinstance(seeds, numbers.Integral) and isinstance(seeds, Iterable):
        seeds = list(seeds)
    return Study(name="le2018", task="sequence", scenarios=tuple(scenarios) if isinstance(scenarios, Sequence)
                 and not isinstance(scenarios, str) else scenarios, methods=entries, seeds=seeds, metrics=("gap",),
                 description="Le et al. 2018, Tables 1, 2, 4 and 5: waypoint sequencing on the paper's tilesets, "
                             "with the gap to the optimum")


def run_le2018(seeds: int | Sequence[int] = 5, *, methods: Sequence[str] = TABLE1_METHODS, weights: bool = True,
                scenarios: Sequence[str] = TABLE1_SCENARIOS + TABLE2_SCENARIOS, time_limit: float | None = None,
                executor: str = "processes", workers: int | None = None, out: str | os.PathLike | None = None,
                resume: bool = False, progress=None) -> StudyRun:
    """Run :func:`le2018_study` on the study runner (its own ``sequence`` trial); ``report(run)``
    lays the result out as the paper's tables.

    ``executor``, ``workers``, ``out``, ``resume`` and ``progress`` are
    :func:`~htetro_opt.studies.runner.run_study`'s (``progress(done, total, note)``), the other
    arguments :func:`le2018_study`'s.
    """
    study = le2018_study(seeds, methods=methods, weights=weights, scenarios=scenarios, time_limit=time_limit)
    return run_runner_study(study, out=out, executor=executor, workers=workers, resume=resume, progress=progress)


def _tileset(scenario: str, shapes: str | None) -> Tileset:
    """The tileset a ``sequence`` trial on ``scenario`` ordered, named as the report names it (the
    tiling without shuffle is deterministic, so this is the trial's)."""
    if scenario in PAPER_TILESETS:
        return paper_tileset(scenario)
    if is_tileset(scenario):
        return load_tileset(tileset_path(scenario))
    workspace = load_scenario(scenario).workspace
    result = tile_workspace(workspace, shapes=list(shapes) if shapes else None)  # the sequence task's tiler
    ts = result.tileset
    name = f"ours {Path(scenario).stem if scenario.endswith('.toml') else scenario} "
    name += f"({shapes}, {result.method})" if shapes else f"({result.method})"
    return Tileset(ts.occupancy, ts.blocks, ts.ids, workspace.cell_size, name)


def _order(record: Mapping[str, Any], tileset: Tileset) -> list[int]:
    order = [int(t) for t in str(record["order"]).split(",")]
    if sorted(order) != sorted(tileset.ids):
        raise ParameterError(f"the order of {record['scenario']} {record['label']} does not visit the tiles of "
                             f"{tileset.name} (was the scenario changed since the run?)")
    return order


def _reference(record: Mapping[str, Any], references: Sequence[Mapping[str, Any]]) -> Mapping[str, Any] | None:
    for ref in references:
        if ref.get("scenario") == record["scenario"] and all(
                ref.get(k) == record.get(k) for k in ("start", "weights", "shapes")):
            return ref
    return None


def _legacy_records(run: StudyRun) -> list[dict]:
    """The runner's records in :func:`run_table1`'s and :func:`run_table2`'s form (Tables 1, 2 and 4),
    for :func:`markdown_report`."""
    records: list[dict] = []
    table1: dict[str, list[dict]] = {}
    table2: list[dict] = []
    tilesets: dict[tuple, Tileset] = {}
    for r in run.records:
        if r.get("error") is not None:
            continue
        where = (r["scenario"], r.get("shapes"))
        if where not in tilesets:
            tilesets[where] = _tileset(*where)
        ts = tilesets[where]
        order = _order(r, ts)
        ref = _reference(r, run.references)
        optimum = None if ref is None else ref.get("cost")
        if r.get("weights") is None:
            gap = None if optimum is None else 100.0 * (r["cost"] - optimum) / optimum
            table1.setdefault(ts.name, []).append({
                "table": 1, "tileset": ts.name, "paper_map": _on_paper_map(ts, TABLE1_SCENARIOS),
                "method": r["label"], "seed": r["seed"], "cost": r["cost"],
                "runtime_s": r["runtime_s"], "optimum": optimum, "proven": bool(ref and ref.get("optimal")),
                "gap_pct": gap, "order": order})
        else:
            weights = tuple(float(w) for w in r["weights"])
            paper = {tuple(w): (meaning, own, four) for w, meaning, own, four in PAPER_TABLE2}.get(weights)
            if not _on_paper_map(ts, TABLE2_SCENARIOS):  # the paper's Table 2 is on its 10 x 10 map only
                paper = None if paper is None else (paper[0], None, None)
            equal = SequencingInstance.from_tileset(ts, start=order[0])
            table2.append({
                "table": 2, "tileset": ts.name, "paper_map": _on_paper_map(ts, TABLE2_SCENARIOS),
                "weights": _weights_label(weights),
                "meaning": paper[0] if paper else "", "cost_own": r["cost"],
                "cost_four": path_cost(equal.cost, [ts.index(t) for t in order]),
                "paper_own": paper[1] if paper else None, "paper_four": paper[2] if paper else None,
                "proven": r["method"] == "exact" and bool(ref and ref.get("optimal"))})
    for rows in table1.values():
        records += rows
    records += table2
    for name, rows in table1.items():
        ts = next(t for t in tilesets.values() if t.name == name)
        records += run_table45(ts, rows)
    return records


def report(run: StudyRun, *, table3: Iterable[dict] | None = None) -> str:
    """The Markdown tables of a run of the ``le2018`` study, the paper's numbers beside ours: the
    same layout as :func:`markdown_report`'s.

    Table 1 on each scenario from the records without ``weights`` (each method's gap to the proven
    optimum, the study's reference), Table 2 from those with ``weights`` (each order priced also at
    equal weights), Tables 4–5 from the coverage simulation of each Table-1 method's first recorded
    order. Table 3 is not a runner task: pass :func:`run_table3`'s records as ``table3``. Failed
    trials are listed at the end.

    Raises
    ------
    ParameterError
        If ``run`` is not a :class:`~htetro_opt.studies.runner.StudyRun` of the ``sequence`` task,
        or a recorded order does not fit its scenario's tileset.
    """
    if not isinstance(run, StudyRun):
        raise ParameterError(f"run must be the StudyRun of run_study, got {run!r}")
    if run.study.task != "sequence":
        raise ParameterError(f"the le2018 report lays out sequencing studies, not task {run.study.task!r}")
    records = _legacy_records(run)
    if table3 is not None:
        rows = list(table3)
        if any(not isinstance(r, Mapping) or r.get("table") != 3 for r in rows):
            raise ParameterError("table3 must be run_table3's records")
        first4 = next((i for i, r in enumerate(records) if r["table"] == 4), len(records))
        records[first4:first4] = rows
    text = markdown_report(records)
    failed = [r for r in run.records if r.get("error") is not None]
    if failed:
        text += "\n".join(["### Failed trials", ""] + [
            f"- {r['scenario']} {r['label']}" + ("" if r["seed"] is None else f" seed {r['seed']}") + f": {r['error']}"
            for r in failed]) + "\n"
    return text
