"""Time limits honoured: every method that takes ``time_limit`` stops within it, compile excluded.

Issue 25, item 5: ``runtime_s`` ≤ limit + 10 % for every method that takes a time limit, the first
compile of the kernels excluded (the kernels are compiled, or loaded from numba's disk cache, by a
short warm-up run of the same method before the timed one, on a small instance and then briefly on the
timed one). The methods come from the task specs
(:data:`htetro_opt.solvers._tasks.TASKS`, every method whose spec says it takes ``time_limit``), so a
method added later is measured without editing this file; each task has one instance here, large
enough that its methods would run well past the limit without one.

For each method the table gives the result's own ``runtime_s``, the wall time of the call measured
outside it (``spec.solve``: posing the problem included), both as a ratio to the limit, and whether the
run was cut (``time_limited`` in the result's info, or it finished early: then the limit was not the
binding constraint and the ratio says little).

Run:  python benchmarks/bench_time_limits.py [--limit 2] [--only TASK[:METHOD]] [--out FILE.md]
"""

from __future__ import annotations

import argparse
import importlib.util
import os
import platform
import time
from pathlib import Path

from htetro_opt.errors import HtetroError
from htetro_opt.solvers._tasks import TASKS

DATA = Path(__file__).parent / "data" / "tsplib"

# One instance per task, sized so that every method taking a time limit would run past a few seconds
# without one; ``warm`` is the warm-up instance (small: it only compiles or loads the kernels).
INSTANCES = {
    "grid_paths": {"scenario": "three_slit", "warm": "three_slit",
                   "options": {"max_gen": 1_000_000, "patience": 1_000_000, "pop_size": 60},
                   "warm_options": {"max_gen": 2, "pop_size": 8}},
    "continuous": {"scenario": "ega10_maze3", "warm": "ega07_slits1", "options": {}, "warm_options": {}},
    "tiling": {"scenario": "tiling_64x64", "warm": "tiling_6x6", "options": {}, "warm_options": {}},
    "sequencing": {"scenario": str(DATA / "pr1002.tsp"), "warm": str(DATA / "eil51.tsp"),
                   "options": {"closed": True}, "warm_options": {"closed": True}},
    "coverage": {"scenario": "tiling_64x64", "warm": "coverage_16x7", "options": {}, "warm_options": {}},
}

# A method's own instance where the task's does not suit it: the exact sequencer proves optima of at most
# 40 waypoints (it refuses larger instances before any work).
OWN_INSTANCES = {
    ("coverage", "tiling-tsp"): {"scenario": "coverage_16x16", "warm": "coverage_16x16", "options": {},
                                 "warm_options": {}},
    ("sequencing", "exact"): {"scenario": "tiling_11x11", "warm": "paper_6x6_fig13a", "options": {"closed": True},
                              "warm_options": {}},
}

# Methods whose time limit bounds only a part of the run, said beside their row.
NOTES = {
    ("sequencing", "greedy"): "the limit bounds its optional improvement step",
}


def _applicable(spec, method: str, options: dict) -> dict:
    return {key: value for key, value in options.items() if spec.method(method).takes(key)}


def measure(task: str, method: str, limit: float) -> dict:
    spec = TASKS[task]
    instance = OWN_INSTANCES.get((task, method), INSTANCES[task])
    warm = _applicable(spec, method, instance["warm_options"])
    spec.solve(instance["warm"], method=method, time_limit=min(limit, 1.0), **warm)
    options = _applicable(spec, method, instance["options"])
    # and the timed instance itself, briefly: some kernels (pymoo's AGE-MOEA survival, by numba) compile
    # only for the sizes the timed run meets
    try:
        spec.solve(instance["scenario"], method=method, time_limit=min(limit, 1.0) / 2, **options)
    except HtetroError:
        pass  # nothing found in so short a time (OR-Tools, CP-SAT): the kernels are loaded all the same
    started = time.perf_counter()
    _, result = spec.solve(instance["scenario"], method=method, time_limit=limit, **options)
    wall = time.perf_counter() - started
    info = getattr(result, "info", {}) or {}
    return {"task": task, "method": method, "runtime_s": float(result.runtime_s), "wall_s": wall,
            "cut": bool(info.get("time_limited", False) or getattr(result, "time_limited", False)),
            "success": bool(getattr(result, "success", True))}


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--limit", type=float, default=2.0, help="the time limit given to each method, s")
    parser.add_argument("--only", action="append", default=[], help="TASK or TASK:METHOD (repeatable)")
    parser.add_argument("--out", type=Path, help="also write the table to this Markdown file")
    args = parser.parse_args(argv)

    rows = []
    for task, spec in TASKS.items():
        for name in spec.names:
            if not spec.method(name).takes_time_limit:
                continue
            if args.only and task not in args.only and f"{task}:{name}" not in args.only:
                continue
            requires = spec.method(name).requires
            if requires and importlib.util.find_spec(requires.replace("-", "_")) is None:  # an optional package: said, not measured
                rows.append({"task": task, "method": name, "skipped": f"needs the optional package {requires}"})
                continue
            try:
                row = measure(task, name, args.limit)
            except Exception as error:  # said in the table: this instance does not suit the method
                rows.append({"task": task, "method": name, "skipped": f"{type(error).__name__}: {error}"})
                print(f"{task:11} {name:16} failed: {error}", flush=True)
                continue
            rows.append(row)
            print(f"{task:11} {name:16} runtime_s {row['runtime_s']:7.2f}  wall {row['wall_s']:7.2f}  "
                  f"{row['runtime_s'] / args.limit:5.2f}x  cut={row['cut']}", flush=True)

    load = os.getloadavg()
    lines = [f"time limit {args.limit:g} s; {platform.node()}, {os.cpu_count()} cores, load "
             f"{load[0]:.1f} / {load[1]:.1f} / {load[2]:.1f} (1 / 5 / 15 min) at the end; "
             f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}", "",
             "| task | method | runtime_s | / limit | wall (posing included) | / limit | cut by the limit | note |",
             "|---|---|---:|---:|---:|---:|---|---|"]
    worst = 0.0
    for row in rows:
        if "skipped" in row:
            lines.append(f"| {row['task']} | `{row['method']}` | – | – | – | – | – | not measured: {row['skipped']} |")
            continue
        ratio = row["runtime_s"] / args.limit
        worst = max(worst, ratio) if row["cut"] else worst
        note = NOTES.get((row["task"], row["method"]), "" if row["cut"] else "finished before the limit")
        lines.append(f"| {row['task']} | `{row['method']}` | {row['runtime_s']:.2f} | {ratio:.2f} | "
                     f"{row['wall_s']:.2f} | {row['wall_s'] / args.limit:.2f} | {'yes' if row['cut'] else 'no'} "
                     f"| {note} |")
    lines += ["", f"worst runtime_s / limit among the runs the limit cut: {worst:.2f} (target ≤ 1.10)"]
    text = "\n".join(lines)
    print("\n" + text)
    if args.out:
        args.out.write_text(text + "\n", encoding="utf-8")


if __name__ == "__main__":
    main()
