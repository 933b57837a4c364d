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

:func:`run_study` re-runs all of it on the paper's own labelled tilesets (bundled, transcribed from
its figures) and on tilings of ours, with every method of :mod:`htetro_opt.solvers.sequencing`, and
adds what the paper could not report: each method's gap to the proven optimum (the exact method).
The paper's numbers sit beside ours (``PAPER_*``). Its tables do not say from which tile its paths
start; ours start from tile 1, as its figures' paths do.

Run from the command line::

    htetro-opt study seed003 --seeds 5 --out DIR

which prints the markdown tables and, with ``--out``, writes ``DIR/seed003.md`` and
``DIR/seed003.csv`` (one line per method run).
"""

from __future__ import annotations

import csv
import io
from collections.abc import Iterable, Sequence
from pathlib import Path

from htetro_opt._files import atomic_path
from htetro_opt._validation import check_int, check_time_limit
from htetro_opt.errors import ParameterError, TilingError
from htetro_opt.model.coverage import simulate_coverage
from htetro_opt.problems.waypoint_sequencing import SequencingInstance, path_cost
from htetro_opt.scenarios import Tileset, load_scenario, load_tileset, tileset_path
from htetro_opt.solvers.sequencing import sequence_waypoints
from htetro_opt.solvers.tiling import tile_workspace
from htetro_opt.studies.metrics import format_mean_std, mean_std

__all__ = [
    "PAPER_TABLE1",
    "PAPER_TABLE2",
    "PAPER_TABLE3",
    "PAPER_TABLE4",
    "PAPER_TABLE5",
    "PAPER_TILESETS",
    "paper_tileset",
    "TABLE1_METHODS",
    "STOCHASTIC",
    "run_table1",
    "run_table2",
    "run_table3",
    "run_table45",
    "run_study",
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
STOCHASTIC = ("greedy", "ga-plain", "ga")
METHOD_NAMES = {
    "zigzag": "Zigzag 1 row", "zigzag2": "Zigzag 2 rows", "spiral": "Spiral 1 row", "spiral2": "Spiral 2 rows",
    "greedy": "Greedy search", "ga-plain": "GA (paper's, DEAP)", "ga": "GA + 2-opt/Or-opt (memetic)",
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


def run_table1(tileset: Tileset, *, seeds: Iterable[int] = (0,), methods: Sequence[str] = TABLE1_METHODS,
               time_limit: float | None = None) -> list[dict]:
    """Every method on one tileset from tile 1: one record per (method, seed), with the gap to the optimum.

    Deterministic methods run once (seed 0). ``time_limit`` caps each method that takes one.
    """
    seeds = _check_seeds(seeds)
    time_limit = check_time_limit(time_limit)
    instance = SequencingInstance.from_tileset(tileset, start=tileset.ids[0])
    optimum = sequence_waypoints(instance, method="exact")
    records = []
    for method in methods:
        for seed in (seeds if method in STOCHASTIC else [0]):
            result = optimum if method == "exact" else sequence_waypoints(instance, method=method, seed=seed,
                                                                          time_limit=time_limit)
            records.append({
                "table": 1, "tileset": tileset.name, "method": method, "seed": seed, "cost": result.cost,
                "runtime_s": result.runtime_s, "optimum": optimum.cost,
                "proven": bool(optimum.info.get("optimal", False)),
                "gap_pct": 100.0 * (result.cost - optimum.cost) / optimum.cost, "order": result.tiles,
            })
    return records


def run_table2(tileset: Tileset) -> list[dict]:
    """Table 2: the optimal order under each weight setting, priced by its own and by equal weights."""
    equal = SequencingInstance.from_tileset(tileset, start=tileset.ids[0])
    records = []
    for weights, meaning, paper_own, paper_four in PAPER_TABLE2:
        instance = SequencingInstance.from_tileset(tileset, start=tileset.ids[0], weights=weights)
        result = sequence_waypoints(instance, method="exact")
        records.append({
            "table": 2, "tileset": tileset.name, "weights": ",".join(f"{w:g}" for w in weights), "meaning": meaning,
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
                                        name=label)
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
    return [{
        "table": 4, "tileset": tileset.name, "method": row["method"], "cost": row["cost"],
        "distance_cells": float(coverage.mean_block_distance),
        "distance_cm": 100.0 * tileset.cell_size * float(coverage.mean_block_distance),
        "average_grid_time_s": float(coverage.average_grid_time),
        "recovered_150": float(coverage.recovered(150, scale=scale)),
        "recovered_100": float(coverage.recovered(100, scale=scale)),
    } for row, coverage in runs]


def run_study(*, seeds: Iterable[int] = range(5), time_limit: float | None = None, progress=None) -> list[dict]:
    """Tables 1–5 in one list of records (see the module docstring)."""
    seeds = _check_seeds(seeds)
    say = progress or (lambda message: None)
    records: list[dict] = []
    table1_tilesets = [paper_tileset("paper_11x11_fig13d")]
    ours = tile_workspace(load_scenario("tiling_11x11").workspace, name="ours tiling_11x11 (backtracking)")
    table1_tilesets.append(Tileset(ours.occupancy, ours.blocks, ours.ids, 0.25, ours.name))
    for ts in table1_tilesets:
        say(f"Table 1 on {ts.name}")
        rows = run_table1(ts, seeds=seeds, time_limit=time_limit)
        records += rows
        say(f"Tables 4-5 on {ts.name}")
        records += run_table45(ts, rows)
    say("Table 2 on paper_10x10_fig13c")
    records += run_table2(paper_tileset("paper_10x10_fig13c"))
    say("Table 3")
    records += run_table3(seeds=seeds[:2])
    return records


def _fmt(value, digits: int = 3) -> str:
    return "–" if value is None else f"{value:.{digits}f}"


def markdown_report(records: Iterable[dict]) -> str:
    """The tables as markdown, the paper's numbers beside ours."""
    records = list(records)
    out = []
    for name in dict.fromkeys(r["tileset"] for r in records if r["table"] == 1):
        rows = [r for r in records if r["table"] == 1 and r["tileset"] == name]
        optimum = rows[0]["optimum"]
        out += [f"### Table 1 on {name} ({len(rows[0]['order'])} waypoints, start tile {rows[0]['order'][0]}; "
                f"optimum {optimum:.3f}{'' if rows[0]['proven'] else ' (not proven)'})", "",
                "| method | cost (ours) | gap to optimum | time s (ours) | cost (paper) | time s (paper) |",
                "|---|---|---|---|---|---|"]
        for method in dict.fromkeys(r["method"] for r in rows):
            mine = [r for r in rows if r["method"] == method]
            cost, gap, runtime = (mean_std([r[k] for r in mine]) for k in ("cost", "gap_pct", "runtime_s"))
            paper = PAPER_TABLE1.get(method, (None, None))
            runs = f" ({len(mine)} seeds)" if len(mine) > 1 else ""
            out.append(f"| {METHOD_NAMES.get(method, method)}{runs} | {format_mean_std(*cost, digits=3)} | "
                       f"{format_mean_std(*gap, digits=2)} % | {format_mean_std(*runtime, digits=3)} | "
                       f"{_fmt(paper[0])} | {_fmt(paper[1])} |")
        out.append("")
    rows = [r for r in records if r["table"] == 2]
    if rows:
        out += [f"### Table 2 on {rows[0]['tileset']}: optimal order under each weight setting", "",
                "| weights α,β,λ,γ | meaning | cost, own weights (ours) | cost, 4 blocks (ours) | own (paper) | 4 blocks (paper) |",
                "|---|---|---|---|---|---|"]
        out += [f"| {r['weights']} | {r['meaning']} | {r['cost_own']:.3f} | {r['cost_four']:.3f} | "
                f"{r['paper_own']:.3f} | {r['paper_four']:.3f} |" for r in rows]
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
            t4 = PAPER_TABLE4.get(r["method"], (None, None))
            t5 = PAPER_TABLE5.get(r["method"], (None, None))
            out.append(f"| {METHOD_NAMES.get(r['method'], r['method'])} | {r['distance_cm']:.0f} | {_fmt(t4[1], 0)} | "
                       f"{r['average_grid_time_s']:.3f} | {_fmt(t4[0], 4)} | {r['recovered_150']:.2f} % | "
                       f"{_fmt(t5[0], 2)} | {r['recovered_100']:.2f} % | {_fmt(t5[1], 2)} |")
        out.append("")
    return "\n".join(out)


def write_csv(records: Iterable[dict], path) -> Path:
    """One CSV line per record (the union of their keys as columns), written atomically."""
    records = list(records)
    columns = list(dict.fromkeys(k for r in records for k in r))
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, columns)
    writer.writeheader()
    for r in records:
        writer.writerow({k: " ".join(map(str, v)) if isinstance(v, list) else v for k, v in r.items()})
    with atomic_path(path) as tmp:
        tmp.write_text(buffer.getvalue(), encoding="utf-8")
    return Path(path)
