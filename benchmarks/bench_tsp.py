"""Quality and speed of the tiling and waypoint sequencing of Le et al. 2018, every method side by side.

1. Agreement (≤ 40 waypoints): OR-Tools (its default time limit, 1 s up to 20 waypoints rising to 30 s at 40) against the exact CP-SAT optimum on
   the paper's six labelled tilesets, our tilings of its four workspaces, and random Euclidean
   instances of 20, 30 and 40 waypoints, fixed start (tile 1) and free start.
2. GA: the paper's GA on DEAP (``ga-plain``) and the memetic GA (``ga``, 2-opt/Or-opt on offspring),
   several seeds each, gap to the exact optimum and time, on the paper-sized instances.
3. Scale: the 64 × 64 ``tiling_64x64`` map (~1000 waypoints): tiling time by both tiling methods,
   then every sequencing method's cost and time side by side (gap to the best), and the default
   (``auto``) tile + sequence time against the one-minute target.
4. Tiling without tails (issue 16, item 6) moved to benchmarks/bench_tiling.py.
5. Backends: the outside solvers ``fast-tsp`` and ``lkh`` (LKH-3 through elkai), where installed,
   beside the project's ``local`` (plain and iterated) and ``ils`` (the compiled iterated local search, its
   kick budget; auto's engine beyond 40 waypoints): on two small TSPLIB instances with their
   published optima (burma14, ulysses16, data inline), TSPLIB-like random uniform instances (integer
   coordinates in [0, 10⁴), EUC_2D rounding, closed tours; LKH with one run is their reference; the
   TSPLIB files themselves are part 6) and the eq.-2 instance of tiling_64x64 (open path from
   tile 1). Every cost is re-priced here from the matrix, independently of the solvers.

6. TSPLIB (issue 16): eight classic instances (benchmarks/data/tsplib, 51–1002 cities) against their
   published optima: ``auto`` (ils), fast-tsp, LKH and OR-Tools (``tsplib``), the memetic and plain GA
   (``tsplib-ga``); the eq.-2 instance of a 128 × 128 map with furniture against LKH (``obstacles``);
   free maps of 4096–16 384 waypoints tiled and sequenced, time and peak memory (``memory``).

Run:  python benchmarks/bench_tsp.py [--quick] [--seeds N] [--budget S]
      [--parts agreement,ga,scale,backends,tsplib,tsplib-ga,obstacles,memory,versus,implicit]
      [--tsplib-dir DIR] [--names a,b] [--methods auto,fast-tsp]
      [--implicit-n N] [--implicit-file F.tsp] [--variants "ils:neighbours=10|…"] [--no-lkh] [--lkh-params P]

7. Versus (issue 25, item 4): auto against fast-tsp at ``--budget`` seconds on TSPLIB instances of 400-2103
   cities (pcb442, pr1002 and those of VERSUS_OPTIMA found in ``--tsplib-dir``), gap to the optimum.
8. Implicit (issue 25, item 4): a seeded 16 384-city EUC_2D instance (uniform in [0, 10⁴)², written as a
   TSPLIB file to a temporary folder, or ``--implicit-file``), loaded by ``load_tsplib`` and sequenced by
   ``auto`` with ``time_limit=60`` in a fresh process (load time, peak RSS, cost), against LKH-3 (elkai, one
   run) given the same file's coordinates in its own process (its time, peak RSS). ``--variants`` adds
   ``ils`` runs with other options (``"ils:neighbours=10|ils:lk_depth=2"``), each in its own process.
"""

from __future__ import annotations

import argparse
import ast
import platform
import statistics
import time
from pathlib import Path

import numpy as np

from htetro_opt.problems import SequencingInstance, cost_matrix
from htetro_opt.scenarios import (
    list_tilesets,
    load_scenario,
    load_tileset,
    tileset_path,
)
from htetro_opt.scenarios.tsplib import load_tsplib, parse_tsplib, tsplib_distances
from htetro_opt.solvers.sequencing import sequence_waypoints
from htetro_opt.solvers.tiling import TILING_METHODS, tile_workspace

# the maps' one definition is the tiling benchmark's (this script runs from benchmarks/)
from bench_tiling import map_furniture  # noqa: E402

WORKSPACES = ("tiling_6x6", "tiling_8x7", "tiling_10x10", "tiling_11x11")


def _paper_sized() -> list[tuple[str, object]]:
    out = [(name, load_tileset(tileset_path(name))) for name in list_tilesets()]
    for name in WORKSPACES:
        out.append((f"ours {name}", tile_workspace(load_scenario(name).workspace, name=name)))
    return out


def _random_instance(n: int, seed: int, start) -> SequencingInstance:
    rng = np.random.default_rng(seed)
    blocks = np.repeat(rng.integers(0, 100, size=(n, 2))[:, None, :], 4, axis=1)
    return SequencingInstance(cost_matrix(blocks), blocks, start)


def agreement(quick: bool) -> None:
    print("## Agreement: OR-Tools (default time limit) against the exact optimum\n")
    print("| instance | n | start | exact cost | exact s | proven | OR-Tools cost | OR-Tools s | equal |")
    print("|---|---:|---|---:|---:|---|---:|---:|---|")
    cases = [(name, SequencingInstance.from_tileset(ts, start=start), label)
             for name, ts in _paper_sized() for start, label in ((ts.ids[0], "tile 1"), (None, "free"))]
    for n in (20, 30, 40):
        for seed in range(1 if quick else 3):
            for start, label in ((0, "fixed"), (None, "free")):
                cases.append((f"random {n} pts, seed {seed}", _random_instance(n, seed, start), label))
    agree = 0
    for name, inst, label in cases:
        exact = sequence_waypoints(inst, method="exact")
        routing = sequence_waypoints(inst, method="ortools")
        same = abs(routing.cost - exact.cost) <= 1e-6 * max(1.0, exact.cost)
        agree += same
        print(f"| {name} | {inst.n} | {label} | {exact.cost:.4f} | {exact.runtime_s:.2f} | {exact.info.get('optimal')} | "
              f"{routing.cost:.4f} | {routing.runtime_s:.2f} | {'yes' if same else 'NO'} |")
    print(f"\nOR-Tools equals the exact optimum on {agree} of {len(cases)} instances.\n")


def ga(quick: bool, seeds: int) -> None:
    print(f"## GA: plain (the paper's) and memetic, {seeds} seeds, gap to the exact optimum\n")
    print("| instance | n | optimum | plain gap % mean (max) | plain s | memetic gap % mean (max) | memetic s |")
    print("|---|---:|---:|---:|---:|---:|---:|")
    cases = _paper_sized()
    if quick:
        cases = cases[-3:]
    all_gaps = {"ga-plain": [], "ga": []}
    for name, ts in cases:
        inst = SequencingInstance.from_tileset(ts, start=ts.ids[0])
        optimum = sequence_waypoints(inst, method="exact").cost
        cells = []
        for method in ("ga-plain", "ga"):
            runs = [sequence_waypoints(inst, method=method, seed=s) for s in range(seeds)]
            gaps = [100 * (r.cost - optimum) / optimum for r in runs]
            all_gaps[method] += gaps
            cells.append(f"{statistics.mean(gaps):.2f} ({max(gaps):.2f}) | {statistics.mean(r.runtime_s for r in runs):.2f}")
        print(f"| {name} | {inst.n} | {optimum:.3f} | {cells[0]} | {cells[1]} |")
    for method, gaps in all_gaps.items():
        within = sum(g <= 1.0 for g in gaps)
        print(f"\n{method}: within 1 % of the optimum in {within} of {len(gaps)} runs; mean gap {statistics.mean(gaps):.2f} %.")
    print()


def scale(quick: bool) -> None:
    scenario = load_scenario("tiling_64x64")
    print("## Scale: tiling_64x64\n")
    tilings = {}
    for method in TILING_METHODS:
        began = time.perf_counter()
        tilings[method] = tile_workspace(scenario.workspace, method=method, name=scenario.name)
        print(f"- tiling by {method}: {len(tilings[method])} tiles in {time.perf_counter() - began:.2f} s")
    ts = tilings["backtracking"]
    inst = SequencingInstance.from_tileset(ts, start=1)
    print(f"\n{inst.n} waypoints, start tile 1.\n")
    runs = [("local", {}), ("ortools", {}), ("ortools", {"time_limit": 10.0}),
            ("ga", {"time_limit": 30.0}), ("ga-plain", {"time_limit": 30.0}),
            ("greedy", {"iterations": 200 if quick else 1000}),
            ("zigzag", {}), ("zigzag2", {}), ("spiral", {}), ("spiral2", {})]
    if not quick:
        runs.insert(1, ("local", {"time_limit": 10.0, "restarts": 10**6}))
    results = []
    for method, options in runs:
        r = sequence_waypoints(inst, method=method, **options)
        label = method + "".join(f", {k}={v:g}" for k, v in options.items())
        results.append((label, r))
    best = min(r.cost for _, r in results)
    print("| method | cost | gap to best % | time s |")
    print("|---|---:|---:|---:|")
    for label, r in sorted(results, key=lambda item: item[1].cost):
        print(f"| {label} | {r.cost:.2f} | {100 * (r.cost - best) / best:.2f} | {r.runtime_s:.2f} |")
    began = time.perf_counter()
    default = sequence_waypoints(SequencingInstance.from_tileset(
        tile_workspace(scenario.workspace, name=scenario.name), start=1))
    total = time.perf_counter() - began
    print(f"\nDefault tile + sequence (backtracking + {default.method}): {total:.2f} s "
          f"(target < 60 s), cost {default.cost:.2f}.\n")


BURMA14 = """NAME: burma14
TYPE: TSP
DIMENSION: 14
EDGE_WEIGHT_TYPE: GEO
NODE_COORD_SECTION
1 16.47 96.10
2 16.47 94.44
3 20.09 92.54
4 22.39 93.37
5 25.23 97.24
6 22.00 96.05
7 20.47 97.02
8 17.20 96.29
9 16.30 97.38
10 14.05 98.12
11 16.53 97.38
12 21.52 95.59
13 19.41 97.13
14 20.09 94.55
EOF
"""
ULYSSES16 = """NAME: ulysses16
TYPE: TSP
DIMENSION: 16
EDGE_WEIGHT_TYPE: GEO
NODE_COORD_SECTION
1 38.24 20.42
2 39.57 26.15
3 40.56 25.32
4 36.26 23.12
5 33.48 10.54
6 37.56 12.19
7 38.42 13.11
8 37.52 20.44
9 41.23 9.10
10 41.17 13.05
11 36.08 -5.21
12 38.47 15.13
13 38.15 15.35
14 37.51 15.17
15 35.49 14.32
16 39.36 19.56
EOF
"""
OPTIMA = {"burma14": 3323, "ulysses16": 6859}  # TSPLIB's published optima


def _installed(module: str) -> bool:
    try:
        __import__(module)
    except ImportError:
        return False
    return True


def _tour_cost(cost: np.ndarray, order, closed: bool) -> float:
    """The order's cost by a loop of our own, independent of every solver and of the instance's pricing."""
    total = sum(float(cost[a, b]) for a, b in zip(order[:-1], order[1:]))
    return total + (float(cost[order[-1], order[0]]) if closed else 0.0)


def backends(quick: bool, budget: float) -> None:
    have_fast, have_lkh = _installed("fast_tsp"), _installed("elkai")
    print(f"## Backends: fast-tsp ({'installed' if have_fast else 'not installed'}) and LKH-3 via elkai "
          f"({'installed' if have_lkh else 'not installed'}) beside the project's methods\n")
    cases = [(t.name, SequencingInstance.from_matrix(t.cost, closed=True, start=0), OPTIMA[t.name])
             for t in (parse_tsplib(BURMA14), parse_tsplib(ULYSSES16))]
    for n, seed in ((200, 0), (1000, 1)) if quick else ((200, 0), (500, 1), (1000, 2), (2000, 3)):
        xy = np.random.default_rng(seed).integers(0, 10_000, size=(n, 2))
        cases.append((f"uniform {n} (EUC_2D, seed {seed})",
                      SequencingInstance.from_matrix(tsplib_distances(xy, "EUC_2D"), closed=True, start=0), None))
    scenario = load_scenario("tiling_64x64")
    ts = tile_workspace(scenario.workspace, name=scenario.name)
    cases.append(("tiling_64x64 eq. 2 (open, tile 1)", SequencingInstance.from_tileset(ts, start=1), None))
    runs = [("local", {}), ("local", {"restarts": 10**6, "time_limit": budget}), ("ils", {})]
    if have_fast:
        runs += [("fast-tsp", {"time_limit": 1.0}), ("fast-tsp", {"time_limit": budget})]
    if have_lkh:
        runs.append(("lkh", {"runs": 1}))
    reference = "LKH with one run" if have_lkh else "the row's best cost"
    print(f"Gap in % to the published optimum (burma14, ulysses16), else to {reference}; seconds in brackets. "
          "Closed tours except tiling_64x64.\n")
    labels = [m + "".join(f", {k}={'∞' if v == 10**6 else f'{v:g}'}" for k, v in o.items()) for m, o in runs]
    print("| instance | n | reference cost | " + " | ".join(labels) + " |")
    print("|---|---:|---:|" + "---:|" * len(runs))
    for name, inst, optimum in cases:
        results = []
        for method, options in runs:
            r = sequence_waypoints(inst, method=method, seed=0, **options)
            cost = _tour_cost(inst.cost, r.order.tolist(), inst.closed)
            assert sorted(r.order.tolist()) == list(range(inst.n)) and abs(cost - r.cost) <= 1e-6 * max(1.0, cost)
            if optimum is not None:
                assert cost >= optimum - 1e-9, (name, method, cost)
            results.append((cost, r.runtime_s))
        best = optimum if optimum is not None else (results[-1][0] if have_lkh else min(c for c, _ in results))
        cells = [f"{100 * (c - best) / best:.2f} ({t:.2f})" for c, t in results]
        print(f"| {name} | {inst.n} | {best:.2f} | " + " | ".join(cells) + " |", flush=True)
    print()


TSPLIB_DIR = Path(__file__).parent / "data" / "tsplib"
TSPLIB_OPTIMA = {"eil51": 426, "berlin52": 7542, "kroA100": 21282, "ch130": 6110, "a280": 2579, "lin318": 42029,
                 "pcb442": 50778, "pr1002": 259045}  # TSPLIB's published optima (Reinelt)


def tsplib(quick: bool, budget: float) -> None:
    """Issue 16, item 1: TSPLIB's classic instances (benchmarks/data/tsplib), closed tours, every method's
    tour re-priced here and held against the published optimum."""
    runs = [("auto", {"time_limit": budget}), ("fast-tsp", {"time_limit": 1.0}), ("lkh", {"runs": 1}),
            ("ortools", {"time_limit": budget})]
    modules = {"fast-tsp": "fast_tsp", "lkh": "elkai"}
    runs = [(m, o) for m, o in runs if m not in modules or _installed(modules[m])]
    labels = [m + "".join(f", {k}={v:g}" for k, v in o.items()) for m, o in runs]
    print("## TSPLIB: gap to the published optimum in % (seconds), closed tours, seed 0\n")
    print("| instance | n | optimum | " + " | ".join(labels) + " |")
    print("|---|---:|---:|" + "---:|" * len(runs))
    names = list(TSPLIB_OPTIMA)[:3] + ["pr1002"] if quick else list(TSPLIB_OPTIMA)
    gaps = {label: [] for label in labels}
    for name in names:
        tsp = load_tsplib(TSPLIB_DIR / f"{name}.tsp")
        inst = SequencingInstance.from_matrix(tsp.cost, closed=True, start=0)
        optimum = TSPLIB_OPTIMA[name]
        cells = []
        for label, (method, options) in zip(labels, runs):
            r = sequence_waypoints(inst, method=method, seed=0, **options)
            cost = _tour_cost(inst.cost, r.order.tolist(), True)
            assert sorted(r.order.tolist()) == list(range(inst.n)) and abs(cost - r.cost) <= 1e-6 * cost
            assert cost >= optimum, (name, method, cost)  # nothing beats a proven optimum
            gap = 100 * (cost - optimum) / optimum
            gaps[label].append(gap)
            cells.append(f"{gap:.2f} ({r.runtime_s:.2f})" + (f" [{r.method}]" if method == "auto" else ""))
        print(f"| {name} | {inst.n} | {optimum} | " + " | ".join(cells) + " |", flush=True)
    print("| mean gap % | | | " + " | ".join(f"{statistics.mean(g):.2f}" for g in gaps.values()) + " |\n")


# TSPLIB's published optima (Reinelt) of the instances of 400-2103 cities the ``versus`` part reads from
# --tsplib-dir (the files are not in the repository: TSPLIB's, fetched by whoever runs the part)
VERSUS_OPTIMA = {"rd400": 15281, "pcb442": 50778, "d493": 35002, "att532": 27686, "rat575": 6773, "u724": 41910,
                 "rat783": 8806, "pr1002": 259045, "u1060": 224094, "vm1084": 239297, "pcb1173": 56892,
                 "d1291": 50801, "rl1304": 252948, "fl1400": 20127, "fl1577": 22249, "d1655": 62128,
                 "u1817": 57201, "d2103": 80450}


def versus(budget: float, tsplib_dir: Path | None, names: list[str] | None, methods: list[str]) -> None:
    """Issue 25, item 4: ``auto`` against fast-tsp at the same time budget on TSPLIB instances of 400-2103
    cities, closed tours, run alternately (which one goes first swaps every instance) on the loaded
    machine: gap to the published optimum, every tour re-priced here. The instances are pcb442 and pr1002
    (benchmarks/data/tsplib) and those of :data:`VERSUS_OPTIMA` found in ``tsplib_dir``."""
    found = {}
    for name in VERSUS_OPTIMA:
        for folder in (TSPLIB_DIR, tsplib_dir):
            if folder is not None and (folder / f"{name}.tsp").exists():
                found[name] = folder / f"{name}.tsp"
    if names:
        found = {name: found[name] for name in names}
    runs = {"auto": ("auto", {"time_limit": budget, "seed": 0}), "fast-tsp": ("fast-tsp", {"time_limit": budget})}
    runs.update({f"ils-kicks={k}": ("ils", {"kicks": int(k), "seed": 0, "time_limit": 10 * budget})
                 for k in (m.split("=")[1] for m in methods if m.startswith("ils-kicks="))})
    for m in methods:  # a lever against the default: auto[or3opt=True;kick_rate=1e5] (options as Python literals)
        if m.endswith("]") and "[" in m:
            base, _, args = m[:-1].partition("[")
            options = {k: ast.literal_eval(v) for k, v in (kv.split("=") for kv in args.split(";") if kv)}
            runs[m] = (base, {**runs[base][1], **options})
    labels = [m for m in methods if m in runs]
    print(f"## auto against fast-tsp, {budget:g} s each, closed tours: gap to the published optimum in % (seconds)\n")
    print("| instance | n | optimum | " + " | ".join(labels) + " |")
    print("|---|---:|---:|" + "---:|" * len(labels))
    gaps = {label: [] for label in labels}
    for row, (name, path) in enumerate(found.items()):
        inst = SequencingInstance.from_matrix(load_tsplib(path).cost, closed=True, start=0)
        optimum = VERSUS_OPTIMA[name]
        cells = {}
        for label in (labels if row % 2 == 0 else labels[::-1]):
            method, options = runs[label]
            r = sequence_waypoints(inst, method=method, **options)
            cost = _tour_cost(inst.cost, r.order.tolist(), True)
            assert sorted(r.order.tolist()) == list(range(inst.n)) and abs(cost - r.cost) <= 1e-6 * cost
            assert cost >= optimum, (name, method, cost)  # nothing beats a proven optimum
            gap = 100 * (cost - optimum) / optimum
            gaps[label].append(gap)
            extra = f", {r.info['kicks']} kicks" if "kicks" in r.info else ""
            cells[label] = f"{gap:.2f} ({r.runtime_s:.1f}{extra})"
        print(f"| {name} | {inst.n} | {optimum} | " + " | ".join(cells[label] for label in labels) + " |", flush=True)
    print("| mean gap % | | | " + " | ".join(f"{statistics.mean(g):.3f}" for g in gaps.values()) + " |")
    if len(labels) >= 2:
        a, b = gaps[labels[0]], gaps[labels[1]]
        print(f"\n{labels[0]} below {labels[1]} on {sum(x < y - 1e-9 for x, y in zip(a, b))}, equal on "
              f"{sum(abs(x - y) <= 1e-9 for x, y in zip(a, b))}, above on {sum(x > y + 1e-9 for x, y in zip(a, b))} "
              f"of {len(a)} instances.")
    print()


def tsplib_ga(budget: float) -> None:
    """Issue 16, item 5: the memetic GA (its local step the compiled local search of ils) and the paper's
    plain GA on the TSPLIB instances of 130+ cities, closed tours, seed 0, under ``budget`` seconds."""
    print(f"## The GA on TSPLIB, time_limit={budget:g}: gap to the published optimum\n")
    print("| instance | n | method | gap % | seconds | generations | stopped |")
    print("|---|---:|---|---:|---:|---:|---|")
    for name in ("ch130", "a280", "lin318", "pcb442", "pr1002"):
        inst = SequencingInstance.from_matrix(load_tsplib(TSPLIB_DIR / f"{name}.tsp").cost, closed=True, start=0)
        optimum = TSPLIB_OPTIMA[name]
        for method in ("ga", "ga-plain"):
            r = sequence_waypoints(inst, method=method, seed=0, time_limit=budget)
            cost = _tour_cost(inst.cost, r.order.tolist(), True)
            assert sorted(r.order.tolist()) == list(range(inst.n)) and cost >= optimum
            print(f"| {name} | {inst.n} | {method} | {100 * (cost - optimum) / optimum:.2f} | {r.runtime_s:.2f} | "
                  f"{r.info['generations']} | {r.info['stopped']} |", flush=True)
    print()


def obstacles(budget: float) -> None:
    """Issue 16, item 1: the eq.-2 instance of a 128 × 128 map with furniture (map_furniture(128, 128, 90,
    seed 0), tiled by auto), open path from tile 1: auto at its default budget and fast-tsp against LKH."""
    from htetro_opt.model.workspace import Workspace

    began = time.perf_counter()
    ts = tile_workspace(Workspace(map_furniture(128, 128, 90, 0)), name="furniture 128")
    inst = SequencingInstance.from_tileset(ts, start=1)
    print(f"## Eq.-2 instance with obstacles: {inst.n} tiles of map_furniture(128, 128, 90, seed 0), open path "
          f"from tile 1 (tiled in {time.perf_counter() - began:.1f} s)\n")
    runs = [("auto", {"time_limit": budget}), ("auto", {}), ("fast-tsp", {"time_limit": budget})]
    if _installed("elkai"):
        runs.append(("lkh", {"runs": 1}))  # minutes: last
    print("| method | cost | seconds | kicks |")
    print("|---|---:|---:|---:|")
    results = []
    for method, options in runs:
        r = sequence_waypoints(inst, method=method, seed=0, **options)
        cost = _tour_cost(inst.cost, r.order.tolist(), False)
        assert sorted(r.order.tolist()) == list(range(inst.n)) and abs(cost - r.cost) <= 1e-6 * cost
        label = method + "".join(f", {k}={v:g}" for k, v in options.items())
        results.append((label, cost))
        print(f"| {label} [{r.method}] | {cost:.2f} | {r.runtime_s:.1f} | {r.info.get('kicks', '')} |", flush=True)
    reference = results[-1][1] if _installed("elkai") else min(c for _, c in results)
    print(f"\nGap to {'LKH' if _installed('elkai') else 'the best'} in %: "
          + ", ".join(f"{label} {100 * (cost - reference) / reference:.2f}" for label, cost in results) + "\n")


def _tile_and_sequence(side: int, dense) -> dict:
    """In a fresh process: tile a free side × side map, sequence it with auto; times and peak memory."""
    import resource

    from htetro_opt.model.workspace import Workspace

    began = time.perf_counter()
    ts = tile_workspace(Workspace(np.zeros((side, side), dtype=bool)), name=f"free {side}")
    tiled = time.perf_counter()
    inst = SequencingInstance.from_tileset(ts, start=1, dense=dense)
    built = time.perf_counter()
    r = sequence_waypoints(inst, seed=0)
    done = time.perf_counter()
    order = r.order
    blocks = ts.blocks.astype(float)  # the cost re-priced here, from the block cells, by a loop of our own
    cost = sum(float(np.sqrt(((blocks[a] - blocks[b]) ** 2).sum(-1)) @ np.full(4, 0.25))
               for a, b in zip(order[:-1].tolist(), order[1:].tolist()))
    assert sorted(order.tolist()) == list(range(inst.n)) and abs(cost - r.cost) <= 1e-6 * cost
    return {"n": inst.n, "implicit": inst.implicit, "method": r.method, "cost": r.cost, "kicks": r.info.get("kicks"),
            "tile_s": tiled - began, "instance_s": built - tiled, "sequence_s": done - built, "total_s": done - began,
            "peak_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}


def memory(quick: bool) -> None:
    """Issue 16, item 3: free maps tiled and sequenced by ``auto``, each in a fresh process (its peak RSS)."""
    from concurrent.futures import ProcessPoolExecutor
    from multiprocessing import get_context

    print("## Memory linear in n: free maps, tile + sequence (auto), one fresh process each\n")
    print("| map | waypoints | costs | tile s | instance s | sequence s | total s | peak RSS MB | cost | kicks |")
    print("|---|---:|---|---:|---:|---:|---:|---:|---:|---:|")
    cases = [(128, None), (180, None), (256, None)] if not quick else [(128, None), (256, None)]
    if not quick:
        cases.insert(2, (180, True))  # 8100 waypoints with the dense matrix, for comparison
    for side, dense in cases:
        with ProcessPoolExecutor(1, mp_context=get_context("spawn")) as pool:
            row = pool.submit(_tile_and_sequence, side, dense).result()
        print(f"| free {side} × {side} | {row['n']} | {'implicit' if row['implicit'] else 'matrix'} | "
              f"{row['tile_s']:.1f} | {row['instance_s']:.1f} | {row['sequence_s']:.1f} | {row['total_s']:.1f} | "
              f"{row['peak_mb']:.0f} | {row['cost']:.1f} | {row['kicks']} |", flush=True)
    print()


def _write_uniform_tsplib(path: Path, n: int, seed: int) -> None:
    """A TSPLIB EUC_2D file of ``n`` cities uniform in [0, 10⁴)², six decimals (read back exactly by both)."""
    xy = np.random.default_rng(seed).uniform(0.0, 1e4, size=(n, 2))
    lines = [f"NAME : rand{n}", f"COMMENT : uniform in [0, 1e4)^2, seed {seed}", "TYPE : TSP", f"DIMENSION : {n}",
             "EDGE_WEIGHT_TYPE : EUC_2D", "NODE_COORD_SECTION"]
    lines += [f"{i} {x:.6f} {y:.6f}" for i, (x, y) in enumerate(xy, 1)]
    path.write_text("\n".join(lines + ["EOF", ""]))


def _euc2d_tour(coords: np.ndarray, order) -> float:
    """A closed tour's EUC_2D length by a loop of our own: nint(√(Δx² + Δy²)) = ⌊d + 0.5⌋ per leg."""
    o = np.asarray(order, dtype=np.int64)
    d = coords[o] - coords[np.roll(o, -1)]
    return float(np.floor(np.sqrt((d * d).sum(1)) + 0.5).sum())


def _implicit_run(path: str, method: str, options: dict) -> dict:
    """In a fresh process: load the TSPLIB file, pose its implicit instance, sequence it; times, peak RSS."""
    import resource

    began = time.perf_counter()
    tsp = load_tsplib(path)
    loaded = time.perf_counter()
    inst = SequencingInstance.from_tsplib(tsp, start=0)
    posed = time.perf_counter()
    r = sequence_waypoints(inst, method=method, seed=0, **options)
    done = time.perf_counter()
    assert sorted(r.order.tolist()) == list(range(inst.n)) and _euc2d_tour(tsp.coords, r.order) == r.cost
    return {"n": inst.n, "implicit": inst.implicit, "method": r.method, "cost": r.cost, "load_s": loaded - began,
            "pose_s": posed - loaded, "sequence_s": done - posed, "kicks": r.info.get("kicks"),
            "timed_out": r.info.get("timed_out"), "initial": r.info.get("initial_cost"),
            "peak_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}


def _lkh_coordinates_run(path: str, params: str = "") -> dict:
    """In a fresh process: LKH-3 (elkai's solver, RUNS = 1) on the file's coordinates as TSPLIB text, so that
    LKH computes EUC_2D itself (no matrix: elkai's DistanceMatrix would hand it n² numbers as text)."""
    import resource

    from elkai import _elkai

    tsp = load_tsplib(path)
    text = Path(path).read_text().replace("EOF", "")
    began = time.perf_counter()
    extra = "".join(f"{item.strip()}\n" for item in params.split(";") if item.strip())
    tour = [int(v) - 1 for v in _elkai.solve_problem(f"RUNS = 1\nPROBLEM_FILE = :stdin:\n{extra}", text)]
    tour = tour[:tsp.dimension]
    done = time.perf_counter()
    assert sorted(tour) == list(range(tsp.dimension))
    return {"cost": _euc2d_tour(tsp.coords, tour), "seconds": done - began,
            "peak_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}


def implicit(n: int, file: Path | None, variants: list[str], lkh: bool, lkh_params: str = "",
             time_limit: float = 60.0) -> None:
    """Issue 25, item 4: a TSPLIB coordinate instance of ``n`` cities kept implicit, auto at 60 s against LKH."""
    import os
    import subprocess
    import sys
    import tempfile
    from concurrent.futures import ProcessPoolExecutor
    from multiprocessing import get_context

    def fresh(function, *args):
        with ProcessPoolExecutor(1, mp_context=get_context("spawn")) as pool:
            return pool.submit(function, *args).result()

    with tempfile.TemporaryDirectory() as folder:
        path = file or Path(folder) / f"rand{n}.tsp"
        if file is None:
            _write_uniform_tsplib(path, n, seed=0)
        print(f"## Implicit TSPLIB coordinates: {path.name}, closed tour, seed 0\n")
        load = subprocess.run([sys.executable, "-c", "import resource, sys; from htetro_opt.scenarios.tsplib import "
                               "load_tsplib; t = load_tsplib(sys.argv[1]); print(t.dimension, resource.getrusage("
                               "resource.RUSAGE_SELF).ru_maxrss // 1024)", str(path)], capture_output=True, text=True,
                              check=True, env={**os.environ})
        print(f"load_tsplib alone, fresh process: {load.stdout.strip().split()[0]} cities, peak RSS "
              f"{load.stdout.strip().split()[1]} MB (interpreter and imports included)\n")
        print("| run | method | costs | load s | pose s | sequence s | kicks | timed out | start cost | cost | "
              "peak RSS MB |")
        print("|---|---|---|---:|---:|---:|---:|---|---:|---:|---:|")
        rows = [("auto", "auto", {"time_limit": time_limit})]
        for variant in variants:
            method, _, text = variant.partition(":")
            options = {k: int(v) for k, v in (item.split("=") for item in text.split(",") if item)}
            rows.append((variant, method, {"time_limit": time_limit, **options}))
        results = {}
        for label, method, options in rows:
            row = fresh(_implicit_run, str(path), method, options)
            results[label] = row
            print(f"| {label}, time_limit={time_limit:g} | {row['method']} | "
                  f"{'implicit' if row['implicit'] else 'matrix'} | {row['load_s']:.2f} | {row['pose_s']:.3f} | "
                  f"{row['sequence_s']:.1f} | {row['kicks']} | {row['timed_out']} | {row['initial']:.0f} | "
                  f"{row['cost']:.0f} | {row['peak_mb']:.0f} |", flush=True)
        print()
        if lkh and _installed("elkai"):
            ref = fresh(_lkh_coordinates_run, str(path), lkh_params)
            given = f"; {lkh_params}" if lkh_params else ""
            print(f"LKH-3 (elkai, RUNS = 1, EUC_2D coordinates{given}): cost {ref['cost']:.0f} in "
                  f"{ref['seconds']:.1f} s, "
                  f"peak RSS {ref['peak_mb']:.0f} MB\n")
            print("Gap to LKH in %: " + ", ".join(f"{label} {100 * (r['cost'] / ref['cost'] - 1):.2f}"
                                                for label, r in results.items()) + "\n")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--parts", default="agreement,ga,scale")
    parser.add_argument("--seeds", type=int, default=5)
    parser.add_argument("--budget", type=float, default=10.0, help="backends: the longer time budget in seconds")
    parser.add_argument("--tsplib-dir", type=Path, default=None,
                        help="versus: a folder holding more TSPLIB files (name.tsp) of VERSUS_OPTIMA")
    parser.add_argument("--names", default="", help="versus: only these instances (comma-separated)")
    parser.add_argument("--methods", default="auto,fast-tsp",
                        help="versus: the columns, among auto, fast-tsp, ils-kicks=K and auto[option=value;...]")
    parser.add_argument("--implicit-n", type=int, default=16384, help="implicit: cities of the generated instance")
    parser.add_argument("--implicit-file", type=Path, default=None,
                        help="implicit: a TSPLIB EUC_2D file (e.g. a public one in /tmp) instead of the generated one")
    parser.add_argument("--variants", default="", help="implicit: more runs, '|'-separated, e.g. ils:neighbours=10")
    parser.add_argument("--no-lkh", action="store_true", help="implicit: skip the LKH reference")
    parser.add_argument("--lkh-params", default="", help="implicit: more LKH parameters, ';'-separated, e.g. "
                        "'CANDIDATE_SET_TYPE = POPMUSIC;TIME_LIMIT = 300' (its default run: over an hour at 16 384)")
    args = parser.parse_args()
    print(f"# Le et al. 2018 benchmark ({platform.python_version()}, {platform.processor() or platform.machine()})\n")
    parts = args.parts.split(",")
    known = {"agreement", "ga", "scale", "backends", "memory", "tsplib", "tsplib-ga", "obstacles", "versus", "implicit"}
    if set(parts) - known:  # "tiling" moved to bench_tiling.py: say so rather than run nothing
        parser.error(f"unknown parts: {', '.join(sorted(set(parts) - known))} (tiling: benchmarks/bench_tiling.py)")
    if "agreement" in parts:
        agreement(args.quick)
    if "ga" in parts:
        ga(args.quick, 2 if args.quick else args.seeds)
    if "scale" in parts:
        scale(args.quick)
    if "backends" in parts:
        backends(args.quick, args.budget)
    if "memory" in parts:
        memory(args.quick)
    if "tsplib" in parts:
        tsplib(args.quick, args.budget)
    if "tsplib-ga" in parts:
        tsplib_ga(args.budget)
    if "obstacles" in parts:
        obstacles(30.0)
    if "implicit" in parts:
        implicit(args.implicit_n, args.implicit_file, [v for v in args.variants.split("|") if v], not args.no_lkh,
                 args.lkh_params)
    if "versus" in parts:
        versus(args.budget, args.tsplib_dir, [n for n in args.names.split(",") if n], args.methods.split(","))


if __name__ == "__main__":
    main()
