"""Nazarahari et al. 2019's experiments beside the paper's figures: Table 2 (12 maps × A* 1, A* 0.25,
PRM, B-RRT, PSO, the paper's EGA as published (``ega-paper``) with linear and spline paths beside the
paper's "EGA linear" and "EGA spline" rows, and the project's ``ega`` with both path types beside them,
× seeds), §5.1's five (IS, PS) pairs (``ega-paper``), §5.3's normalised weights on map 4 (the EGA as
published and ours), and the four robots of ``ega_cross4`` (our Fig. 11; both EGAs), every length
beside the exact optimum (the visibility graph: r = 0 on these maps). Every record lists the additions
of ours its method ran with (``additions``: none for ``ega-paper``). The report adds why A* 0.25 equals A* 1 on our maps and each A* path after the deletion
operator (an any-angle post-smoothing, not in the paper), and how far the PSO shortened its APF start.

Not on the study runner: the runner's tasks plan grid scenarios, and each trial here needs its map's
exact optimum, computed once per map (0.01–0.1 s) before the trials and shared by every method and
seed. The trials run on a pool of worker processes (``jobs``, default the local cores; ``jobs=1``:
one after the other in the calling process). A seed costs a few minutes of trials on one core (the
spline EGAs most of it, 0.5–15 s a map each; every other Table 2 row 0.01–1.5 s); §5.1's five pairs
cost about a minute a seed, so by default they run on the first seed only (``pair_seeds``).

``htetro-opt study nazarahari2019 [--seeds N] [--workers N] [--out DIR]`` runs it with the defaults
(:func:`run_nazarahari2019` takes the rest: the maps, methods, pairs, B-RRT's time limit) and prints the
report; ``--out`` writes DIR/nazarahari2019.md and DIR/nazarahari2019.csv.
"""

from __future__ import annotations

import io
import os
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from htetro_opt._validation import check_int, check_time_limit
from htetro_opt.model.continuous import path_length
from htetro_opt.operators.path_bases import delete_path_bases
from htetro_opt.scenarios import load_scenario
from htetro_opt.solvers.continuous import plan_continuous
from htetro_opt.studies.runner import write_report as write_study_report

__all__ = ["MAPS", "METHODS", "PAPER_TABLE2", "PAPER_PAIRS", "PAPER_TABLE3", "PAIRS", "PAIRS_METHOD", "NORMALISED",
           "CROSS4", "run_nazarahari2019", "report", "write_report"]

MAPS = ("ega01_random1", "ega02_maze1", "ega03_home", "ega04_corridor1", "ega05_boxpile", "ega06_corridor2",
        "ega07_slits1", "ega08_slits2", "ega09_maze2", "ega10_maze3", "ega11_random2", "ega12_plankpile")
"""Table 1's maps 1–12, as bundled (layouts reconstructed: Fig. 6 is not in our copy)."""

METHODS = {
    "A* 1": ("astar", {"grid": 1.0}),
    "A* 0.25": ("astar", {"grid": 0.25}),
    "PRM": ("prm", {}),  # the paper's (n, radius) per map
    "B-RRT": ("rrt", {}),  # 120 s, the paper's terminal condition
    "PSO": ("pso", {}),
    "EGA linear": ("ega-paper", {}),
    "EGA spline": ("ega-paper", {"path": "spline"}),
    "ega linear (ours)": ("ega", {}),
    "ega spline (ours)": ("ega", {"path": "spline"}),
}
"""Table 2's rows: label → (plan_continuous method, options). The paper's labels run the paper's
algorithms (its EGA as published: ``ega-paper``) and stand beside its numbers; "(ours)" rows are the
project's ``ega``, with every addition of ours (htetro_opt.algorithms.EGA_ADDITIONS), beside them."""

PAIRS_METHOD = "ega-paper"
"""The EGA §5.1's (IS, PS) pairs run with: the paper's, as published."""

DETERMINISTIC = frozenset({"A* 1", "A* 0.25"})
"""Rows run once (the paper's A* has standard deviation 0)."""

# Table 2 of the paper: (length, ±, smoothness, ±, runtime s, ±, success %). "—" is None. Garbles of
# our copy, kept as read: after maps 1–10 a row "— — — 0" with no method name follows EGA Spline (not
# data: left out); map 4's EGA Spline length is printed "33.57 ± 0.2" (two decimals short); map 10's
# PSO row is named "PSO Linear" (the other maps: "PSO Piecewise Linear").
_T2 = """
1 A* 1|35.79 0.00 360.00 0.00 0.10 0.00 100
1 A* 0.25|35.30 0.00 360.00 0.00 6.50 0.00 100
1 PRM|36.83 0.74 238.64 50.31 2.20 0.13 96
1 B-RRT|36.88 1.37 316.53 75.65 0.76 0.36 100
1 PSO|34.84 0.04 239.55 5.49 1.68 0.02 100
1 EGA linear|34.06 0.10 232.39 7.16 1.37 0.01 100
1 EGA spline|34.31 0.17 275.00 18.24 1.41 0.02 100
2 A* 1|251.52 0.00 1665.00 0.00 0.66 0.00 100
2 A* 0.25|245.51 0.00 1575.00 0.00 66.10 0.00 100
2 PRM|259.45 1.14 1526.88 20.11 74.61 2.63 60
2 B-RRT|- - - - - - 0
2 PSO|254.22 0.00 1502.65 8.43 2.95 0.05 100
2 EGA linear|250.71 0.26 1505.97 21.87 2.57 0.01 100
2 EGA spline|253.41 0.46 1528.52 9.61 2.59 0.01 100
3 A* 1|132.22 0.00 1800.00 0.00 0.44 0.00 100
3 A* 0.25|127.77 0.00 2070.00 0.00 41.24 0.00 100
3 PRM|134.43 1.37 1436.76 73.81 63.65 0.80 66
3 B-RRT|- - - - - - 0
3 PSO|127.43 0.12 1359.60 9.53 3.13 0.04 100
3 EGA linear|126.38 0.32 1324.45 24.57 2.68 0.01 100
3 EGA spline|128.12 0.32 1482.05 37.95 2.75 0.00 100
4 A* 1|33.96 0.00 360.00 0.00 0.04 0.00 100
4 A* 0.25|33.17 0.00 405.01 0.00 0.87 0.00 100
4 PRM|36.15 1.31 463.30 88.62 7.15 0.39 100
4 B-RRT|36.37 0.98 538.48 82.55 0.83 0.47 100
4 PSO|34.15 0.02 360.00 7.82 1.47 0.01 100
4 EGA linear|33.34 0.12 303.65 25.31 1.30 0.00 100
4 EGA spline|33.57 0.2 367.98 34.78 1.35 0.01 100
5 A* 1|48.20 0.00 855.00 0.00 0.06 0.00 100
5 A* 0.25|46.48 0.00 1035.00 0.00 4.07 0.00 100
5 PRM|48.75 0.48 478.28 84.49 14.13 0.58 98
5 B-RRT|50.13 0.93 504.73 93.90 4.42 1.91 100
5 PSO|46.93 0.06 572.67 10.11 1.84 0.01 100
5 EGA linear|46.07 0.20 536.43 28.54 1.55 0.01 100
5 EGA spline|46.67 0.29 600.97 31.00 1.59 0.00 100
6 A* 1|68.24 0.00 855.00 0.00 0.13 0.00 100
6 A* 0.25|66.25 0.00 855.01 0.00 8.91 0.00 100
6 PRM|70.88 0.99 900.82 29.64 14.11 0.15 82
6 B-RRT|86.55 1.62 656.33 95.01 5.04 1.87 100
6 PSO|67.12 0.04 642.34 7.95 1.48 0.01 100
6 EGA linear|66.09 0.19 619.11 33.06 1.29 0.00 100
6 EGA spline|66.94 0.31 768.58 41.16 1.34 0.01 100
7 A* 1|68.35 0.00 1350.00 0.00 0.05 0.00 100
7 A* 0.25|64.50 0.00 1440.00 0.00 2.01 0.00 100
7 PRM|68.03 0.74 1140.57 32.96 4.05 0.14 92
7 B-RRT|77.76 2.67 1291.86 102.96 4.09 1.32 100
7 PSO|65.13 0.20 1058.76 21.34 1.32 0.00 100
7 EGA linear|64.16 0.22 1086.76 16.77 1.02 0.00 100
7 EGA spline|65.93 0.56 1214.93 30.34 1.04 0.00 100
8 A* 1|41.45 0.00 945.00 0.00 0.04 0.00 100
8 A* 0.25|39.33 0.00 990.01 0.00 1.32 0.00 100
8 PRM|40.97 0.69 714.70 81.70 11.87 0.47 70
8 B-RRT|46.18 1.76 881.95 80.97 3.97 3.16 100
8 PSO|39.91 0.11 719.42 12.28 1.34 0.01 100
8 EGA linear|39.30 0.23 678.92 34.28 1.01 0.00 100
8 EGA spline|39.82 0.38 756.21 39.50 1.04 0.01 100
9 A* 1|197.20 0.00 1710.00 0.00 0.60 0.00 100
9 A* 0.25|192.40 0.00 2025.00 0.00 61.20 0.00 100
9 PRM|199.79 1.25 1443.66 26.75 46.71 0.77 32
9 B-RRT|- - - - - - 0
9 PSO|195.88 0.02 1441.48 6.86 2.80 0.01 100
9 EGA linear|194.28 0.52 1487.62 20.31 2.68 0.01 100
9 EGA spline|197.09 0.38 1578.16 37.65 2.54 0.01 100
10 A* 1|157.09 0.00 1575.00 0.00 0.17 0.00 100
10 A* 0.25|152.58 0.00 1530.00 0.00 8.10 0.00 100
10 PRM|160.26 1.78 1407.34 80.44 53.25 1.19 18
10 B-RRT|- - - - - - 0
10 PSO|157.71 0.11 1367.00 4.69 1.91 0.01 100
10 EGA linear|155.05 0.29 1350.41 17.14 1.70 0.01 100
10 EGA spline|156.42 0.65 1508.47 41.41 1.63 0.01 100
11 A* 1|43.86 0.00 855.00 0.00 0.10 0.00 100
11 A* 0.25|42.67 0.00 1035.00 0.00 5.22 0.00 100
11 PRM|43.39 0.37 262.49 104.87 26.12 1.10 100
11 B-RRT|47.56 1.82 565.36 166.22 2.65 2.39 100
11 PSO|42.78 0.16 601.22 15.06 1.83 0.01 100
11 EGA linear|42.23 0.16 534.97 59.55 1.53 0.01 100
11 EGA spline|42.97 0.43 682.08 87.53 1.57 0.02 100
12 A* 1|51.76 0.00 1620.00 0.00 0.08 0.00 100
12 A* 0.25|49.47 0.00 1845.00 0.00 6.00 0.00 100
12 PRM|59.49 3.19 1326.63 125.19 27.78 0.71 92
12 B-RRT|57.51 3.08 1519.08 92.40 10.17 9.23 100
12 PSO|51.54 0.01 1620.02 13.91 1.92 0.01 100
12 EGA linear|49.72 0.20 1302.49 92.38 1.59 0.01 100
12 EGA spline|51.98 0.38 1530.81 73.83 1.60 0.01 100
"""


def _signed(value: float) -> str:
    """A signed percentage to 2 decimals, without the "−0.00" of rounding noise below zero."""
    return f"{round(float(value), 2) + 0.0:+.2f}"


def _parse_table2(text: str) -> dict:
    table = {}
    for line in text.strip().splitlines():
        head, values = line.split("|")
        number, label = head.split(" ", 1)
        cells = [None if v == "-" else float(v) for v in values.split()]
        table.setdefault(MAPS[int(number) - 1], {})[label] = tuple(cells)
    return table


PAPER_TABLE2 = _parse_table2(_T2)
"""map → row label → (length, std, smoothness °, std, runtime s, std, success %), None for "—"."""

PAIRS = ((20, 10), (20, 20), (50, 20), (20, 50), (100, 20))
"""§5.1's five (IS, PS) pairs (Figs. 7–8)."""

PAPER_PAIRS = {"best_length_100_20": (33.80, 249.78, 124.74, 32.96, 45.40, 65.32, 63.20, 38.27, 193.13, 153.04,
                                      41.40, 48.68),
               "worst_ratio_20_10": {"linear": 1.026, "spline": 1.031}}
"""§5.1's figures: the (IS 100, PS 20) mean lengths per map, and (IS 20, PS 10)'s worst ratio to them."""

NORMALISED = (("EGA (ega-paper)", "ega-paper"), ("ega (ours)", "ega"))
"""The EGAs §5.3's normalisation runs with (label, plan_continuous method)."""

CROSS4 = (("EGA (ega-paper)", "ega-paper"), ("ega (ours)", "ega"))
"""The EGAs the four robots of ``ega_cross4`` are planned jointly with (label, plan_continuous method)."""

PAPER_TABLE3 = {"weights": (1.000, 0.187, 0.201), "weighted_terms": (33.49, 32.40, 34.17),
                "single_best": {"length": 32.71, "smoothness": 174.81, "safety": 154.76}}
"""§5.3 (Table 3, on Fig. 10's unnamed map; L* = 32.71 fits map 4, Corridor 1)."""


@dataclass
class Run:
    """The records of one run of the study."""

    seeds: list
    exact: dict = field(default_factory=dict)  # map -> exact optimum
    table2: list = field(default_factory=list)  # one dict per (map, method, seed)
    pairs: list = field(default_factory=list)
    normalised: list = field(default_factory=list)
    cross4: list = field(default_factory=list)
    seconds: float = 0.0


def _record(plan, **keys) -> dict:
    return {**keys, "reached": bool(plan.reached and all(plan.feasible)), "length": float(plan.length),
            "smoothness": float(np.nansum(plan.smoothness_deg)), "runtime": float(plan.runtime_s),
            "additions": list(plan.additions)}


def _trial(part: str, name: str, label: str, method: str, options: dict, seed, seeded: bool = True) -> dict:
    """One trial, a pure function of its arguments (run in a worker process or in this one)."""
    scenario = load_scenario(name)
    plan = plan_continuous(scenario, method=method, **options, **({"seed": seed} if seeded else {}))
    if part == "table2":
        record = _record(plan, map=name, method=label, seed=seed)
        if method == "pso" and len(plan.history):
            record["start"] = float(plan.history[0])  # the best APF path the swarm starts from
        if method == "astar" and plan.reached:
            # any-angle post-smoothing (not in the paper): the deletion operator on the lattice path
            path = plan.paths[0]
            pbs = delete_path_bases(path[1:-1], path[0], path[-1], scenario.geometry)
            record["smoothed"] = float(path_length(np.vstack([path[0], pbs, path[-1]])))
        return record
    if part == "pairs":
        return _record(plan, map=name, pair=label, seed=seed)
    if part == "normalised":
        w = plan.info["weights"]
        terms = (float(plan.lengths[0]), w[1] * float(plan.smoothness_deg[0]),
                 w[2] / max(float(plan.safety[0]), 1e-12))
        return {"seed": seed, "method": label, "additions": list(plan.additions), "weights": list(w),
                "terms": list(terms),
                "single": plan.info["normalised_from"], "path_bases": len(plan.info["path_bases"][0]),
                "safety": float(plan.safety[0]), "runtime": float(plan.runtime_s)}
    return {**_record(plan, map=name, method=label, seed=seed), "min_robot_distance": plan.min_robot_distance,
            "safety_distance": plan.safety_distance, "conflicts": len(plan.conflicts)}


def run_nazarahari2019(seeds=5, *, maps=MAPS, methods=tuple(METHODS), pairs=PAIRS, pair_seeds=1,
                       rrt_time_limit=None, normalised=True, cross4=True, jobs=None, progress=None) -> Run:
    """Run the study (see the module docstring).

    Parameters
    ----------
    seeds : int or list of int
        N → seeds 0 … N−1 (the paper: 50).
    maps, methods : keyword-only
        Subsets of :data:`MAPS` and :data:`METHODS`' labels.
    pairs : keyword-only
        §5.1's (IS, PS) pairs to run with the EGA as published, linear (:data:`PAIRS_METHOD`; empty: skip).
    pair_seeds : int, keyword-only
        How many of the seeds (the first) run the pairs: 1 by default, since the pairs cost a third
        of a seed's trials and the EGA's spread between seeds is small; ``None``: every seed.
    rrt_time_limit : float, keyword-only
        B-RRT's seconds per run (default 120, the paper's).
    normalised, cross4 : bool, keyword-only
        Run §5.3's normalised weights (when map 4 is among ``maps``) and the four robots (default: both).
    jobs : int, keyword-only
        Worker processes of the pool (default: the local cores; 1: no pool, the trials one after the
        other in the calling process). Every trial is a pure function
        of its map, method, options and seed, so the records are the same whatever ``jobs`` is, but
        for the runtimes.
    progress : callable, optional
        Called with the number of trials done after each.
    """
    seeds = list(range(check_int(seeds, "seeds", minimum=1))) if not isinstance(seeds, (list, tuple)) else list(seeds)
    pair_seeds = seeds if pair_seeds is None else seeds[:check_int(pair_seeds, "pair_seeds", minimum=0)]
    rrt_time_limit = check_time_limit(rrt_time_limit, "rrt_time_limit")
    jobs = check_int(os.cpu_count() or 1 if jobs is None else jobs, "jobs", minimum=1)
    began = time.perf_counter()
    run = Run(seeds=seeds)
    tasks = []  # _trial's arguments
    for name in maps:
        run.exact[name] = float(plan_continuous(load_scenario(name)).length)
        for label in methods:
            method, options = METHODS[label]
            if method == "rrt" and rrt_time_limit is not None:
                options = {**options, "time_limit": rrt_time_limit}
            for seed in seeds[:1] if label in DETERMINISTIC else seeds:
                tasks.append(("table2", name, label, method, options, seed, label not in DETERMINISTIC))
        for max_gen, pop_size in pairs:
            for seed in pair_seeds:
                tasks.append(("pairs", name, f"({max_gen}, {pop_size})", PAIRS_METHOD,
                              {"pop_size": pop_size, "max_gen": max_gen}, seed))
    if normalised and "ega04_corridor1" in maps:
        tasks += [("normalised", "ega04_corridor1", label, method, {"normalise": True}, seed)
                  for label, method in NORMALISED for seed in seeds]
    if cross4:
        run.exact["ega_cross4"] = float(plan_continuous(load_scenario("ega_cross4")).length)
        tasks += [("cross4", "ega_cross4", label, method, {}, seed) for label, method in CROSS4 for seed in seeds]
    records = [None] * len(tasks)
    if jobs == 1 or len(tasks) <= 1:
        for k, task in enumerate(tasks):
            records[k] = _trial(*task)
            if progress is not None:
                progress(k + 1)
    else:
        with ProcessPoolExecutor(max_workers=min(jobs, len(tasks))) as pool:
            futures = {pool.submit(_trial, *task): k for k, task in enumerate(tasks)}
            for done, future in enumerate(as_completed(futures), 1):
                records[futures[future]] = future.result()
                if progress is not None:
                    progress(done)
    for task, record in zip(tasks, records):
        getattr(run, task[0]).append(record)
    run.seconds = time.perf_counter() - began
    return run


def _ms(values, digits=2) -> str:
    values = np.asarray(values, dtype=float)
    if not len(values):
        return "—"
    return f"{values.mean():.{digits}f} ± {values.std():.{digits}f}"


def _paper_cell(row, k, digits=2) -> str:
    if row is None or row[k] is None:
        return "—"
    return f"{row[k]:.{digits}f} ± {row[k + 1]:.{digits}f}"


def report(run: Run) -> str:
    """The study as Markdown: Table 2 beside the paper's, gaps to the exact optimum, §5.1, §5.3, cross4."""
    out = io.StringIO()
    w = out.write
    w(f"# Nazarahari et al. 2019, re-run ({len(run.seeds)} seeds; {run.seconds:.0f} s)\n\n")
    w("Lengths, smoothness (°, sum of turning angles) and runtimes (s) are mean ± std over the successful runs; "
      "success = reached and obstacle-free; gap = mean length / exact optimum − 1. Paper: Table 2 (50 runs, "
      "their machine). Maps are our reconstructions (Fig. 6 is not in our copy). The paper's rows run the paper's "
      "algorithms (EGA linear and EGA spline: `ega-paper`, the EGA as published) beside its numbers; the "
      "\"(ours)\" rows run the project's `ega`, with every addition of ours.\n\n")
    w("## Table 2\n\n")
    summary = []
    for name in [m for m in MAPS if m in run.exact]:
        exact = run.exact[name]
        w(f"### {name} (exact optimum {exact:.2f})\n\n")
        w("| method | length | gap % | smoothness | runtime | success % | paper length | paper smoothness | "
          "paper runtime | paper success % |\n|---|---|---|---|---|---|---|---|---|---|\n")
        for label in METHODS:
            rows = [r for r in run.table2 if r["map"] == name and r["method"] == label]
            if not rows:
                continue
            ok = [r for r in rows if r["reached"]]
            lengths = [r["length"] for r in ok]
            gap = (np.mean(lengths) / exact - 1) * 100 if ok else float("nan")
            success = 100 * len(ok) / len(rows)
            paper = PAPER_TABLE2.get(name, {}).get(label)
            w(f"| {label} | {_ms(lengths)} | {_signed(gap)} | {_ms([r['smoothness'] for r in ok], 1)} | "
              f"{_ms([r['runtime'] for r in rows], 3)} | {success:.0f} | {_paper_cell(paper, 0)} | "
              f"{_paper_cell(paper, 2, 1)} | {_paper_cell(paper, 4)} | "
              f"{'—' if paper is None else f'{paper[6]:.0f}'} |\n")
            summary.append((name, label, np.mean(lengths) if ok else np.nan, gap, success))
        w("\n")
    if summary:
        w("### Summary\n\n")
        for label in METHODS:
            gaps = [g for (_, lab, _, g, _) in summary if lab == label]
            succ = [s for (_, lab, _, _, s) in summary if lab == label]
            if gaps:
                w(f"- {label}: mean gap {_signed(np.nanmean(gaps))} % (max {_signed(np.nanmax(gaps))} %), success "
                  f"{np.mean(succ):.0f} % over {len(gaps)} maps\n")
        astar = {n: length for (n, lab, length, _, _) in summary if lab == "A* 0.25"}
        for label in ("EGA linear", "EGA spline", "ega linear (ours)", "ega spline (ours)", "PSO"):
            wins = [n for (n, lab, length, _, _) in summary if lab == label and n in astar and length < astar[n] - 1e-9]
            if any(lab == label for (_, lab, _, _, _) in summary):
                w(f"- {label} shorter than A* 0.25 on {len(wins)} of {len(astar)} maps (paper, EGA: 7 of 12)\n")
        pso = [r for r in run.table2 if r["method"] == "PSO" and r["reached"] and "start" in r]
        if pso:
            gains = np.array([100 * (1 - r["length"] / r["start"]) for r in pso])
            w(f"- PSO shortened its best APF start by {gains.mean():.2f} % on average ({gains.min():.2f}–"
              f"{gains.max():.2f} % over {len(pso)} runs; feasible moves and a velocity cap of d/2, see "
              "htetro_opt/solvers/continuous/_pso.py)\n")
        w("\n")
        w(_astar_note(run))
    if run.pairs:
        n = len({r["seed"] for r in run.pairs})
        w(f"## §5.1: (IS, PS) pairs, EGA linear as published ({PAIRS_METHOD}), {n} seed{'s' if n > 1 else ''} "
          "(mean length / the pair's best "
          "mean on the map; mean runtime)\n\n")
        labels = [f"({i}, {p})" for i, p in PAIRS]
        w("| map | " + " | ".join(labels) + " | paper (100, 20) |\n|---|" + "---|" * (len(labels) + 1) + "\n")
        for k, name in enumerate(m for m in MAPS if m in run.exact):
            means = {lab: np.mean([r["length"] for r in run.pairs if r["map"] == name and r["pair"] == lab])
                     for lab in labels if any(r["map"] == name and r["pair"] == lab for r in run.pairs)}
            if not means:
                continue
            best = min(means.values())
            times = {lab: np.mean([r["runtime"] for r in run.pairs if r["map"] == name and r["pair"] == lab])
                     for lab in means}
            cells = [f"{means[lab] / best:.4f} ({times[lab]:.2f} s)" if lab in means else "—" for lab in labels]
            w(f"| {name} | " + " | ".join(cells) + f" | {PAPER_PAIRS['best_length_100_20'][MAPS.index(name)]:.2f} |\n")
        w(f"\nPaper: (20, 10) at worst {PAPER_PAIRS['worst_ratio_20_10']['linear']} × (100, 20)'s length "
          "(linear), and the fastest pair.\n\n")
    if run.normalised:
        w(_normalised_section(run.normalised))
    if run.cross4:
        own = run.exact["ega_cross4"]
        w("## Four robots (ega_cross4, our Fig. 11)\n\n")
        for label, _ in CROSS4:
            rows = [r for r in run.cross4 if r.get("method") == label]
            if not rows:
                continue
            ok = [r for r in rows if r["reached"] and r["conflicts"] == 0]
            w(f"- {label}: {len(ok)} of {len(rows)} runs obstacle-free with every pair ≥ d_s = "
              f"{rows[0]['safety_distance']:.2f} apart; closest approach "
              f"{_ms([r['min_robot_distance'] for r in rows], 3)}; Σ lengths {_ms([r['length'] for r in rows])} = "
              f"{np.mean([r['length'] for r in rows]) / own:.4f} × Σ own optima ({own:.2f}); runtime "
              f"{_ms([r['runtime'] for r in rows], 3)} s\n")
    return out.getvalue()


def _astar_note(run: Run) -> str:
    """Why A* 0.25 equals A* 1 on the lattice-aligned maps, and A* with any-angle post-smoothing."""
    rows = {(r["map"], r["method"]): r for r in run.table2 if r["method"] in DETERMINISTIC and r["reached"]}
    names = [n for n in MAPS if (n, "A* 1") in rows and (n, "A* 0.25") in rows]
    if not names:
        return ""
    out = io.StringIO()
    w = out.write
    same = [n for n in names if abs(rows[n, "A* 1"]["length"] - rows[n, "A* 0.25"]["length"]) < 1e-9]
    w("### A* 0.25 against A* 1\n\n")
    w(f"Our A* 0.25 equals our A* 1 on {len(same)} of {len(names)} maps. An 8-connected lattice path between "
      "two lattice points is as long as the octile distance between them whatever the spacing, and on maps "
      "whose obstacle vertices, start and goal all lie on the integer lattice the shortest such path bends at "
      "the same integer corners at spacing 0.25 as at spacing 1: the finer lattice adds vertices, not length. "
      "Only rotated obstacles (ega12_plankpile's planks) separate the two. The paper's A* 0.25 is 1.4–5.6 % "
      "shorter than its A* 1 on every map, so its layouts (Fig. 6, not in our copy) are not on a unit lattice, "
      "and the comparison with its A* 0.25 is on other terms than ours. Beside it, not in the paper, each A* "
      "path after the deletion operator (any-angle post-smoothing: a vertex dropped when the shortcut stays "
      "feasible):\n\n")
    w("| map | exact | A* 1 | A* 0.25 | A* 1 + deletion | gap % | A* 0.25 + deletion | gap % |\n"
      "|---|---|---|---|---|---|---|---|\n")
    for n in names:
        exact = run.exact[n]
        a1, a4 = rows[n, "A* 1"], rows[n, "A* 0.25"]
        w(f"| {n} | {exact:.2f} | {a1['length']:.2f} | {a4['length']:.2f} | {a1['smoothed']:.2f} | "
          f"{_signed((a1['smoothed'] / exact - 1) * 100)} | {a4['smoothed']:.2f} | "
          f"{_signed((a4['smoothed'] / exact - 1) * 100)} |\n")
    w("\n")
    return out.getvalue()


def _normalised_section(records: list) -> str:
    """§5.3 per EGA: the weights, the weighted terms and their balance, and the PB counts behind it."""
    out = io.StringIO()
    w = out.write
    w("## §5.3: normalised weights on ega04_corridor1 (Table 3)\n\n")
    w("Three single-term runs give L*, S* and c_R* = 1 / R* (R = eq. 5's sum of the PBs' clearances), then a "
      "run weighs W = (1, L*/S*, L*/c_R*). Paper: weights "
      f"{PAPER_TABLE3['weights']}, weighted terms {PAPER_TABLE3['weighted_terms']}, single-term optima length "
      f"{PAPER_TABLE3['single_best']['length']}, smoothness {PAPER_TABLE3['single_best']['smoothness']}°.\n\n")
    w("| EGA | runs | W_S | W_R | L | W_S·S | W_R/R | largest / smallest (target ≤ 1.5) | L* | S* | R* | "
      "PBs: length-only, safety-only, weighted | R / R* |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|\n")
    for label, _ in NORMALISED:
        rows = [r for r in records if r.get("method") == label]
        if not rows:
            continue
        weights = np.array([r["weights"] for r in rows])
        terms = np.array([r["terms"] for r in rows])
        ratio = terms.max(axis=1) / terms.min(axis=1)
        single = np.array([[r["single"]["length"], r["single"]["smoothness_deg"], 1 / r["single"]["safety_cost"]]
                           for r in rows])
        counts = np.array([r["single"]["path_bases"] + [r["path_bases"]] for r in rows], dtype=float)
        share = np.array([r["safety"] for r in rows]) / single[:, 2]
        w(f"| {label} | {len(rows)} | {_ms(weights[:, 1], 3)} | {_ms(weights[:, 2], 0)} | {_ms(terms[:, 0])} | "
          f"{_ms(terms[:, 1])} | {_ms(terms[:, 2])} | {_ms(ratio)} | {_ms(single[:, 0])} | {_ms(single[:, 1], 1)} | "
          f"{_ms(single[:, 2], 1)} | {', '.join(_ms(counts[:, k], 1) for k in (0, 2, 3))} | {_ms(share)} |\n")
    w("\nThe safety term is the one out of scale: W_R/R = L*·R*/R, and eq. 5's R grows with the number of "
      "PBs. The safety-only run keeps the APF's many PBs and pushes each away from the walls; a run that also "
      "weighs length and smoothness deletes or straightens the PBs that cost it turning (no operator of the "
      "paper adds one), so it ends with a fraction R / R* of R* and a safety term L*·R*/R of 2–4 L*. Balance "
      "would need a short, smooth path holding about as many PBs as the safety-only one, each about as far "
      "from the walls: the EGA's operators do not reach it, and eq. 5 rewards PB count rather than the "
      "path's shape. `safety=\"min\"` (the smallest clearance along the path, ours) does not grow with the "
      "PBs, but every APF path touches a wall, so its safety-only run finds no clearance (c_R* = ∞, W_R = 0) "
      "and there is no safety term to balance.\n\n")
    return out.getvalue()


def write_report(folder, run: Run) -> tuple[Path, Path]:
    """DIR/nazarahari2019.md (the report) and DIR/nazarahari2019.csv (every Table 2 and §5.1 trial), each
    atomically (the folder must exist)."""
    rows = [{"part": part, "map": r["map"], "method": r.get("method", r.get("pair")), "seed": r["seed"],
             "reached": r["reached"], "length": round(r["length"], 6), "smoothness": round(r["smoothness"], 4),
             "runtime": round(r["runtime"], 4), "additions": ",".join(r.get("additions", ()))}
            for part, records in (("table2", run.table2), ("pairs", run.pairs)) for r in records]
    return write_study_report(folder, "nazarahari2019", report(run), rows)
