"""Do et al. 2021's heat planner: speed and quality against the exact planner, run side by side.

1. Field routes: ``solve_heat_field`` with the direct solver (SuperLU) and with pyamg's Ruge–Stüben
   hierarchy preconditioning CG, q1 and p0, on synthetic N x N maps (N = 24, 128, 512, 1000);
   the two routes' fields must agree to 10·tol.
2. Plans: time-only heat (``band="auto"``: the whole pose graph up to 4 million poses, a band of
   radius 8 around the field's ascent line above) against the exact minimum-time plan with the same
   17 commands (Dijkstra where its graph fits the memory budget, A* above), each in a fresh process:
   CPU seconds, wall seconds, peak RSS, and the gap of heat's time to the optimum. The ablation runs
   the band around a ``grid_distance`` shortest cell path instead of the ascent line: what the field buys.
3. Quality: time-only heat on the seven bundled 24 x 24 maps (= exact optimum?), and on 100 random
   32 x 32 maps of 1-2-cell blocks (strict success: a monotone path exists; after the fallback every
   plan reaches; mean gap to the optimum).
4. Weighted plans (w_sm > 0 puts the last command in the search state): 24 x 24 maps and the
   128 x 128 indoor room.
5. End to end on 1000 x 1000 (issue 25: <= 5 s): time-only heat (band auto) and a side-by-side
   baseline alternate in fresh processes, heat, baseline, heat, ...: scipy's Dijkstra for a point
   robot over the same free cells (8-connected, no corner cutting, graph build included). Per run the
   plan call's CPU and wall seconds, the field's CPU share, the process's CPU seconds (imports and map
   included) and peak RSS; the medians, the median of the pairwise CPU ratios heat / baseline, and
   the load average before and after.

Synthetic N x N maps: axis-aligned rectangles with sides drawn in [2, N/33) placed uniformly (fixed
seeds) until at least 20 % of the cells are blocked; O-shaped start (10, 10) and goal (N - 10, N - 10)
on cleared 9 x 9 squares.

Part 5 also runs on real ROS ``map_server`` maps given with ``--map`` (read by the project's loader;
one leg between the open cells nearest two opposite corners of the largest piece of open space, as
bench_exact.py picks them).

Run:  python benchmarks/bench_heat.py [--sizes 24,128,512,1000] [--clutter 100] [--skip-plans]
                                      [--pairs 3] [--only-e2e] [--map FILE.yaml ...]
"""

from __future__ import annotations

import argparse
import math
import multiprocessing as mp
import os
import resource
import statistics
import time

import numpy as np

BUNDLED = ("random", "h_shape", "spiral", "three_slit", "zigzag", "maze", "maze_partial")


def synthetic(n: int, seed: int = 0, density: float = 0.2):
    from htetro_opt.model import Pose, Workspace

    rng = np.random.default_rng(seed)
    occupancy = np.zeros((n, n), dtype=bool)
    longest = max(3, n // 33)
    while occupancy.mean() < density:
        w, h = rng.integers(2, longest, size=2)
        x, y = rng.integers(0, n - w), rng.integers(0, n - h)
        occupancy[y:y + h, x:x + w] = True
    for cx, cy in ((10, 10), (n - 10, n - 10)):
        occupancy[cy - 4:cy + 5, cx - 4:cx + 5] = False
    return Workspace(occupancy), [Pose(10, 10, "O", 0), Pose(n - 10, n - 10, "O", 0)]


def clutter(seed: int, n: int = 32):
    """A 32 x 32 map of 1-2-cell blocks at density U(0.15, 0.3), start and goal >= 16 apart, reachable."""
    from htetro_opt.model import Pose, Workspace
    from htetro_opt.solvers.grid_paths import plan_exact

    rng = np.random.default_rng(10_000 + seed)
    while True:
        occupancy = np.zeros((n, n), dtype=bool)
        density = rng.uniform(0.15, 0.3)
        while occupancy.mean() < density:
            w, h = rng.integers(1, 3, size=2)
            x, y = rng.integers(0, n - w + 1), rng.integers(0, n - h + 1)
            occupancy[y:y + h, x:x + w] = True
        a, b = rng.integers(1, n - 2, size=2), rng.integers(1, n - 2, size=2)
        if np.abs(a - b).max() < 16:
            continue
        for x, y in (a, b):
            occupancy[y - 1:y + 3, x - 1:x + 3] = False
        ws = Workspace(occupancy)
        roadmap = [Pose(int(a[0]), int(a[1]), "O", 0), Pose(int(b[0]), int(b[1]), "O", 0)]
        exact = plan_exact(ws, roadmap, diagonals=True)
        if exact.reached:
            return ws, roadmap, exact


def real_map(yaml_path: str):
    """A ROS map and one long O-shape leg across its largest piece of open space."""
    from bench_exact import _endpoints  # the same endpoints as the exact planner's benchmark

    from htetro_opt.model import Pose, Workspace
    from htetro_opt.scenarios.rosmap import load_ros_map

    occ, _ = load_ros_map(yaml_path)
    (sx, sy), (gx, gy) = _endpoints(occ)
    return Workspace(occ), [Pose(sx, sy, "O", 0), Pose(gx, gy, "O", 0)]


def _child(job, queue):
    """One measured case in a fresh process (peak RSS is per process)."""
    from htetro_opt.solvers.grid_paths import plan_exact, plan_heat

    kind, n, options = job
    ws, roadmap = synthetic(n) if isinstance(n, int) else real_map(n)
    field_cpu = []
    if kind == "heat":  # the field's CPU seconds (its info holds wall seconds only)
        import htetro_opt.solvers.grid_paths._heat as heat_module

        solve = heat_module.solve_heat_field

        def timed(*args, **kwargs):
            began = time.process_time()
            try:
                return solve(*args, **kwargs)
            finally:
                field_cpu.append(time.process_time() - began)

        heat_module.solve_heat_field = timed
    cpu, wall = time.process_time(), time.perf_counter()
    if kind == "point":
        reached, plan_time = _point_dijkstra(ws, (roadmap[0].x, roadmap[0].y), (roadmap[1].x, roadmap[1].y))
        queue.put({"kind": kind, "n": n, "reached": reached, "time": plan_time,
                   "cpu_s": time.process_time() - cpu, "wall_s": time.perf_counter() - wall,
                   "process_cpu_s": _process_cpu(), "rss_gb": _peak_rss_gb()})
        return
    if kind == "heat":
        plan = plan_heat(ws, roadmap, **options)
        extra = {"band": plan.info["band"][0], "field_s": plan.info["field"][0]["seconds"],
                 "field_cpu_s": sum(field_cpu), "relaxed": plan.info["relaxed"]}
    else:
        from htetro_opt.errors import PlanningError

        if options.get("budget_gib"):  # the reference Dijkstra beyond the default budget, as asked
            import htetro_opt.model.simulate as simulate

            simulate.MEMORY_BUDGET = options["budget_gib"] * 2**30
        try:  # Dijkstra where its graph fits the memory budget, else A* (the same optimum)
            plan = plan_exact(ws, roadmap, diagonals=True, method="dijkstra")
        except PlanningError:
            plan = plan_exact(ws, roadmap, diagonals=True, method="astar")
        extra = {"method": plan.method}
    queue.put({"kind": kind, "n": n, "options": options, "reached": plan.reached, "time": plan.time,
               "cpu_s": time.process_time() - cpu, "wall_s": time.perf_counter() - wall,
               "process_cpu_s": _process_cpu(), "rss_gb": _peak_rss_gb(), **extra})


def _point_dijkstra(ws, start, goal) -> tuple[bool, float]:
    """The baseline: scipy's Dijkstra for a point robot on the free cells, 8-connected (steps 1 and
    sqrt 2, a diagonal only between two free orthogonal cells), the graph built here."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import dijkstra

    free = ~ws.occupancy
    h, w = free.shape
    index = np.arange(h * w).reshape(h, w)
    rows, cols, data = [], [], []
    for dy, dx in ((0, 1), (1, 0), (1, 1), (1, -1)):
        ys, xs = slice(0, h - dy), slice(max(0, -dx), w - max(0, dx))
        yt, xt = slice(dy, h), slice(max(0, dx), w - max(0, -dx))
        ok = free[ys, xs] & free[yt, xt]
        if dy and dx:  # no corner cutting: both orthogonal cells free
            ok &= free[yt, xs] & free[ys, xt]
        rows.append(index[ys, xs][ok])
        cols.append(index[yt, xt][ok])
        data.append(np.full(int(ok.sum()), math.sqrt(2.0) if dy and dx else 1.0))
    graph = coo_matrix((np.concatenate(data), (np.concatenate(rows), np.concatenate(cols))), shape=(h * w,) * 2).tocsr()
    distance = dijkstra(graph, directed=False, indices=start[1] * w + start[0])
    d = float(distance[goal[1] * w + goal[0]])
    return bool(np.isfinite(d)), d


def _process_cpu() -> float:
    """This process's CPU seconds so far (user + system), imports and map generation included."""
    usage = resource.getrusage(resource.RUSAGE_SELF)
    return usage.ru_utime + usage.ru_stime


def _peak_rss_gb() -> float:
    """This process's peak resident set (VmHWM: getrusage's ru_maxrss would carry the parent's over exec)."""
    with open("/proc/self/status") as status:
        for line in status:
            if line.startswith("VmHWM:"):
                return int(line.split()[1]) / 2**20
    return float("nan")


def measured(job):
    context = mp.get_context("spawn")
    queue = context.Queue()
    process = context.Process(target=_child, args=(job, queue))
    process.start()
    result = queue.get()
    process.join()
    return result


def fields(sizes):
    from threadpoolctl import threadpool_limits

    from htetro_opt.solvers.grid_paths import solve_heat_field

    print("## Field routes (CPU s, one BLAS thread)\n")
    print("| map | element | unknowns | direct | AMG (iterations) | max difference |")
    print("|---|---|---:|---:|---:|---:|")
    for n in sizes:
        ws, roadmap = synthetic(n)
        source, sink = (roadmap[1].x, roadmap[1].y), (roadmap[0].x, roadmap[0].y)
        for element in ("q1", "p0"):
            runs = {}
            for solver in ("direct", "amg"):
                if solver == "direct" and n > 512:  # SuperLU's fill-in: 36 CPU s at 1000² (measured)
                    continue
                with threadpool_limits(1):
                    began = time.process_time()
                    runs[solver] = solve_heat_field(ws, source, sink, element=element, solver=solver)
                    runs[solver + "_s"] = time.process_time() - began
            amg = runs["amg"]
            direct = f"{runs['direct_s']:.2f}" if "direct" in runs else "–"
            diff = (f"{np.nanmax(np.abs(runs['direct'].cells - amg.cells)):.1e}" if "direct" in runs else "–")
            if "direct" in runs:
                assert np.nanmax(np.abs(runs["direct"].cells - amg.cells)) <= 10 * amg.epsilon + 1e-12
            print(f"| {n}² | {element} | {amg.info['dofs']:,} | {direct} | {runs['amg_s']:.2f} "
                  f"({amg.info['iterations']}) | {diff} |")
    print()


def plans(sizes):
    print("## Plans, each in a fresh process (time-only; exact = the optimum with the same 17 commands)\n")
    print("| map | planner | CPU s | wall s | peak RSS GB | time | gap | notes |")
    print("|---|---|---:|---:|---:|---:|---:|---|")
    for n in sizes:
        # the exact planner's tables exceed the memory budget above ~610² even for A*
        exact = measured(("exact", n, {})) if n <= 610 else None
        rows = [("exact (" + exact["method"] + ")", exact)] if exact else []
        if exact and exact["method"] != "dijkstra" and n <= 512:  # Dijkstra with a raised budget (5.7 GiB at 512²)
            rows.append(("exact (dijkstra, 8 GiB budget)", measured(("exact", n, {"budget_gib": 8}))))
        rows.append(("heat, band auto", measured(("heat", n, {}))))
        if n >= 128:
            rows.append(("heat, band 8 (ascent line)", measured(("heat", n, {"band": 8}))))
            rows.append(("heat, band 8 (grid_distance path)", measured(("heat", n, {"band": 8,
                                                                                    "band_seed": "grid_distance"}))))
        for label, r in rows:
            gap = f"{(r['time'] - exact['time']) / exact['time']:+.1%}" if r["reached"] and exact else "–"
            note = ""
            if "band" in r:
                b = r["band"]
                note = (f"whole graph; field {r['field_s']:.2f} s" if b["radius"] is None else
                        f"band r {b['radius']}, {b['cells']:,} cells; field {r['field_s']:.2f} s")
                if r["relaxed"] != [False]:
                    note += "; relaxed"
            ratio = f" ({exact['cpu_s'] / r['cpu_s']:.1f}× less)" if exact else ""
            print(f"| {n}² | {label} | {r['cpu_s']:.2f}{ratio} | {r['wall_s']:.2f} | "
                  f"{r['rss_gb']:.2f} | {r['time']:.1f} | {gap} | {note} |")
    print()


def quality(n_clutter: int):
    from htetro_opt.scenarios import load_scenario
    from htetro_opt.solvers.grid_paths import plan_exact, plan_heat

    print("## Quality\n")
    equal = 0
    rows = []
    for name in BUNDLED:
        scenario = load_scenario(name)
        exact = plan_exact(scenario.workspace, scenario.roadmap, diagonals=True)
        heat = plan_heat(scenario.workspace, scenario.roadmap)
        equal += abs(heat.time - exact.time) < 1e-9
        rows.append(f"{name} {heat.time:.2f}/{exact.time:.2f}")
    print(f"- Time-only heat = exact optimum on {equal} of {len(BUNDLED)} bundled maps ({'; '.join(rows)}).")
    strict = reached = 0
    gaps, cpu = [], []
    for seed in range(n_clutter):
        ws, roadmap, exact = clutter(seed)
        began = time.process_time()
        heat = plan_heat(ws, roadmap)
        cpu.append(time.process_time() - began)
        reached += heat.reached
        strict += heat.reached and heat.info["relaxed"] == [False]
        if heat.reached:
            gaps.append((heat.time - exact.time) / exact.time)
    print(f"- {n_clutter} random 32 × 32 maps of 1–2-cell blocks: strict success (a monotone path) "
          f"{strict / n_clutter:.0%}, reached after the fallback {reached / n_clutter:.0%}, mean gap "
          f"{statistics.mean(gaps):.2%} (max {max(gaps):.1%}), median CPU {statistics.median(cpu) * 1e3:.0f} ms a plan.\n")


def weighted():
    from htetro_opt.scenarios import load_scenario
    from htetro_opt.solvers.grid_paths import plan_heat

    print("## Weighted plans (CPU s, warm; the field included)\n")
    print("| map | (1,0,0) | (0,1,0) | (0,0,1) | (1,1,1) |")
    print("|---|---:|---:|---:|---:|")
    for name in ("random", "h_shape", "spiral", "maze", "indoor_room"):
        scenario = load_scenario(name)
        plan_heat(scenario.workspace, scenario.roadmap)  # warm: sweep tables, imports
        cells = []
        for weights in ((1, 0, 0), (0, 1, 0), (0, 0, 1), (1, 1, 1)):
            began = time.process_time()
            plan_heat(scenario.workspace, scenario.roadmap, weights=weights)
            cells.append(f"{time.process_time() - began:.3f}")
        print(f"| {name} | {' | '.join(cells)} |")
    print()


def end_to_end(n: int | str = 1000, pairs: int = 3):
    """Heat and the point-robot baseline alternated in fresh processes; medians and pairwise ratios."""
    load_before = os.getloadavg()
    runs = {"heat": [], "point": []}
    for _ in range(pairs):
        for kind in ("heat", "point"):
            runs[kind].append(measured((kind, n, {})))
    load_after = os.getloadavg()
    heat, point = runs["heat"], runs["point"]
    assert all(r["reached"] for r in heat + point)

    def med(rows, key):
        return statistics.median(r[key] for r in rows)

    ratio = statistics.median(h["cpu_s"] / p["cpu_s"] for h, p in zip(heat, point))
    wall_ratio = statistics.median(h["wall_s"] / p["wall_s"] for h, p in zip(heat, point))
    share = statistics.median(h["field_cpu_s"] / h["cpu_s"] for h in heat)
    name = f"{n} x {n}" if isinstance(n, int) else n
    print(f"## End to end, {name} (median of {pairs} fresh-process runs each, heat and baseline in turn; "
          f"load average {load_before[0]:.1f} before, {load_after[0]:.1f} after)\n")
    print("| run | plan CPU s (min-max) | plan wall s | field CPU s (share) | process CPU s | peak RSS GB | result |")
    print("|---|---:|---:|---:|---:|---:|---|")
    def spread(rows):
        return f"{med(rows, 'cpu_s'):.2f} ({min(r['cpu_s'] for r in rows):.2f}-{max(r['cpu_s'] for r in rows):.2f})"

    print(f"| heat, band auto | {spread(heat)} | {med(heat, 'wall_s'):.2f} | {med(heat, 'field_cpu_s'):.2f} "
          f"({share:.0%}) | {med(heat, 'process_cpu_s'):.2f} | {med(heat, 'rss_gb'):.2f} | "
          f"time {heat[0]['time']:.1f} s |")
    print(f"| point-robot Dijkstra (scipy, free cells) | {spread(point)} | {med(point, 'wall_s'):.2f} | – | "
          f"{med(point, 'process_cpu_s'):.2f} | {med(point, 'rss_gb'):.2f} | length {point[0]['time']:.1f} cells |")
    print(f"\nheat / baseline, median of the pairwise ratios: CPU {ratio:.2f}, wall {wall_ratio:.2f}.\n")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="24,128,512,1000")
    parser.add_argument("--clutter", type=int, default=100)
    parser.add_argument("--skip-plans", action="store_true")
    parser.add_argument("--pairs", type=int, default=3, help="end-to-end runs of heat and of the baseline")
    parser.add_argument("--only-e2e", action="store_true", help="run part 5 only")
    parser.add_argument("--map", action="append", default=[], help="part 5 also on this ROS map YAML (repeatable)")
    args = parser.parse_args()
    sizes = [int(v) for v in args.sizes.split(",")]
    if args.only_e2e:
        end_to_end(pairs=args.pairs)
        for path in args.map:
            end_to_end(path, pairs=args.pairs)
        return
    fields(sizes)
    if not args.skip_plans:
        plans(sizes)
    quality(args.clutter)
    weighted()
    end_to_end(pairs=args.pairs)
    for path in args.map:
        end_to_end(path, pairs=args.pairs)


if __name__ == "__main__":
    main()
