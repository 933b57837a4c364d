"""Speed of the continuous geometry and planners (Nazarahari et al. 2019), each against a baseline
run side by side, answers asserted equal.

1. Population check: 100 paths x 20 segments on ega11_random2 (30 boxes), r = 0 and r = 0.25, a
   GA-like population (a wider robot's exact path resampled, 4 of its points jittered by up to 0.3).
   ``ContinuousGeometry.paths_feasible`` against a per-segment shapely loop (one predicate call per
   segment against the same prepared region / obstacles) and dense numpy sampling (every 0.01).
   Target: <= 2 ms.
2. Exact reference on every bundled map: the visibility graph over the corners with tangent pruning
   (``plan_continuous(method="exact")``) against the same over every obstacle vertex, no pruning,
   networkx's Dijkstra. Target: <= 1 s per map.
3. A* grid 0.25 on the 50 x 50 maps: the heapq A* over the lattice (graph build included) against
   scipy's csgraph Dijkstra on the same lattice graph. Target: <= 2 s.
4. The enhanced GA (PS 10, IS 20, APF included) on every map x ``--seeds`` seeds, side by side with
   the exact optimum and A* at grid 1 and 0.25 run in the same process; EGA as published beside it.
   Targets: EGA mean length <= 1.005 x exact on every map, shorter than A* 0.25 on 12/12; per run
   <= 0.5 s on 20 x 20 / 30 x 30 and <= 2 s on 50 x 50. Every plan re-validates, and no length is
   below the exact lower bound (asserted).
5. ega_cross4 x ``--seeds`` seeds, the four robots planned jointly by the EGA: every run's closest
   approach >= d_s, obstacle-free, sum of lengths <= 1.10 x the sum of the robots' own optima.

6. Our additions to the EGA switched off one at a time (``EnhancedGA(10, additions=...)`` without one of
   ``EGA_ADDITIONS``), mean length / exact over ``--ablation-seeds`` seeds per map (the study
   ``nazarahari2019_ablation`` switches them on one at a time instead).

Run:  python benchmarks/bench_continuous.py [--repeat N] [--seeds S] [--ablation-seeds S] [--only 1,2,3,4,5,6]
"""

from __future__ import annotations

import argparse
import itertools
import statistics
import time

import networkx as nx
import numpy as np
import shapely
from scipy.sparse.csgraph import dijkstra

from htetro_opt.scenarios import list_scenarios, load_scenario
from htetro_opt.solvers.continuous import lattice_graph, plan_continuous


def timed(fn, repeat):
    times = []
    for _ in range(repeat):
        began = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - began)
    return statistics.median(times), out


def population(scenario, rng, n_paths=100, n_segments=20, jitter=0.3, moved=4):
    """A GA-like population: the exact path of a robot 0.25 wider, its longest segments split into
    ``n_segments``, ``moved`` of its interior points jittered by up to ``jitter``."""
    base = plan_continuous(scenario.with_robot_radius(scenario.robot_radius + 0.25)).paths[0]
    while len(base) < n_segments + 1:  # split the longest segment: the same polyline, more points
        k = int(np.argmax(np.hypot(*np.diff(base, axis=0).T)))
        base = np.insert(base, k + 1, (base[k] + base[k + 1]) / 2, axis=0)
    paths = []
    for _ in range(n_paths):
        path = base.copy()
        k = rng.choice(np.arange(1, n_segments), moved, replace=False)
        path[k] += rng.uniform(-jitter, jitter, (moved, 2))
        paths.append(path)
    return paths


def per_segment_loop(geometry, polygons, free, paths):
    """One shapely call per segment, every segment checked (a GA counts the infeasible ones)."""
    r = geometry.robot_radius
    x0, y0, x1, y1 = geometry.bounds
    out = []
    for path in paths:
        bad = 0
        for a, b in zip(path[:-1], path[1:]):
            segment = shapely.LineString([a, b])
            inside = x0 <= min(a[0], b[0]) and max(a[0], b[0]) <= x1 and y0 <= min(a[1], b[1]) and max(a[1], b[1]) <= y1
            ok = inside and (shapely.covered_by(segment, free) if r == 0
                             else all(segment.distance(p) >= r for p in polygons))
            bad += not ok
        out.append(bad == 0)
    return np.array(out)


def dense_numpy(scenario, paths, spacing=0.01):
    """Every path sampled every ``spacing``; boxes only (ega11_random2's obstacles)."""
    boxes = np.array([[o[:, 0].min(), o[:, 1].min(), o[:, 0].max(), o[:, 1].max()] for o in scenario.obstacles])
    r = scenario.robot_radius
    out = []
    for path in paths:
        pts = []
        for a, b in zip(path[:-1], path[1:]):
            n = max(2, int(np.ceil(np.hypot(*(b - a)) / spacing)) + 1)
            pts.append(a + np.linspace(0, 1, n)[:, None] * (b - a))
        p = np.concatenate(pts)[:, None]
        dx = np.maximum(np.maximum(boxes[:, 0] - p[..., 0], p[..., 0] - boxes[:, 2]), 0)
        dy = np.maximum(np.maximum(boxes[:, 1] - p[..., 1], p[..., 1] - boxes[:, 3]), 0)
        if r == 0:
            inside = (p[..., 0] > boxes[:, 0]) & (p[..., 0] < boxes[:, 2]) & (p[..., 1] > boxes[:, 1]) & (p[..., 1] < boxes[:, 3])
            out.append(not inside.any())
        else:
            out.append(bool((np.hypot(dx, dy) >= r).all()))
    return np.array(out)


def bench_population(repeat):
    print("## 1. Population check: 100 paths x 20 segments, ega11_random2 (30 boxes)\n")
    print("| r | feasible | paths_feasible ms | per-segment shapely loop ms | ratio | dense numpy (0.01) ms | ratio |")
    print("|---|---:|---:|---:|---:|---:|---:|")
    base = load_scenario("ega11_random2")
    for r in (0.0, 0.25):
        scenario = base.with_robot_radius(r)
        geometry = scenario.geometry
        paths = population(scenario, np.random.default_rng(0))
        polygons = [shapely.Polygon(o) for o in scenario.obstacles]
        for p in polygons:
            shapely.prepare(p)
        free = shapely.difference(shapely.box(*geometry.bounds), shapely.union_all(polygons))
        shapely.prepare(free)
        t_vec, ok = timed(lambda: geometry.paths_feasible(paths), repeat * 10)
        t_loop, ok_loop = timed(lambda: per_segment_loop(geometry, polygons, free, paths), repeat)
        t_dense, ok_dense = timed(lambda: dense_numpy(scenario, paths), max(1, repeat // 2))
        assert np.array_equal(ok, ok_loop), "the per-segment loop disagrees"
        agree = int((ok == ok_dense).sum())
        print(f"| {r:g} | {int(ok.sum())}/100 | {1e3 * t_vec:.2f} | {1e3 * t_loop:.1f} | {t_loop / t_vec:.0f}x "
              f"| {1e3 * t_dense:.0f} ({agree}/100 agree) | {t_dense / t_vec:.0f}x |")
    print()


def all_vertex_networkx(scenario, i):
    geometry = scenario.geometry
    geo = geometry.polygonised("outer")
    points = [tuple(scenario.starts[i]), tuple(scenario.goals[i])] + [tuple(v) for o in geo.obstacles for v in o]
    pairs = np.array(list(itertools.combinations(range(len(points)), 2)))
    pts = np.array(points)
    ok = geometry.segments_feasible(pts[pairs[:, 0]], pts[pairs[:, 1]])
    graph = nx.Graph()
    graph.add_nodes_from(range(len(points)))
    for (a, b) in pairs[ok].tolist():
        graph.add_edge(a, b, weight=float(np.hypot(*(pts[a] - pts[b]))))
    return nx.dijkstra_path_length(graph, 0, 1), len(points)


def bench_exact(repeat):
    print("## 2. Exact reference per map\n")
    print("| map | r | corners | exact (pruned) s | length | all vertices + networkx s | vertices | ratio |")
    print("|---|---|---:|---:|---:|---:|---:|---:|")
    for name in [n for n in list_scenarios() if n.startswith("ega")]:
        scenario = load_scenario(name)
        t_exact, plan = timed(lambda: plan_continuous(scenario), repeat)
        t_base, (length, vertices) = timed(lambda: all_vertex_networkx(scenario, 0), 1)
        assert abs(plan.lengths[0] - length) < 1e-9, (name, plan.lengths[0], length)
        print(f"| {name} | {scenario.robot_radius:g} | {plan.info['corners'][1]} | {t_exact:.3f} | {plan.lengths[0]:.2f} "
              f"| {t_base:.2f} | {vertices} | {t_base / t_exact:.0f}x |")
    print()


def bench_astar(repeat):
    print("## 3. A* grid 0.25 on the 50 x 50 maps\n")
    print("| map | nodes | edges | A* s (graph included) | length | graph build s | csgraph Dijkstra s (on that graph) |")
    print("|---|---:|---:|---:|---:|---:|---:|")
    for name in ("ega02_maze1", "ega03_home", "ega09_maze2", "ega10_maze3"):
        scenario = load_scenario(name)
        start, goal = scenario.starts[0], scenario.goals[0]
        t_astar, plan = timed(lambda: plan_continuous(scenario, method="astar", grid=0.25), repeat)
        t_build, (nodes, graph) = timed(lambda: lattice_graph(scenario.geometry, 0.25, ends=[start, goal]), repeat)
        t_dij, dist = timed(lambda: dijkstra(graph, directed=False, indices=len(nodes) - 2), repeat)
        assert abs(dist[len(nodes) - 1] - plan.lengths[0]) < 1e-9
        print(f"| {name} | {plan.info['nodes']} | {plan.info['edges']} | {t_astar:.3f} | {plan.lengths[0]:.2f} "
              f"| {t_build:.3f} | {t_dij:.3f} |")
    print()


def bench_ega(seeds):
    print(f"## 4. Enhanced GA (PS 10, IS 20) beside exact and A*, {seeds} seeds per map\n")
    print("| map | exact | A* 1 | A* 0.25 | EGA mean ± std | EGA / exact | EGA < A* 0.25 | EGA s mean (max) "
          "| EGA-paper mean | EGA-paper / exact | EGA-paper s mean |")
    print("|---|---:|---:|---:|---:|---:|:---:|---:|---:|---:|---:|")
    within, shorter, paper_shorter, slow = 0, 0, 0, []
    names = [n for n in list_scenarios() if n.startswith("ega") and n != "ega_cross4"]
    for method in ("ega", "ega-paper"):  # the first run imports pymoo, scipy.interpolate and the GA: not timed
        plan_continuous(load_scenario("ega07_slits1"), method=method, seed=0, max_gen=1)
    for name in names:
        scenario = load_scenario(name)
        exact = plan_continuous(scenario)
        lower = exact.info["lower_bound"][0]
        a1 = plan_continuous(scenario, method="astar", grid=1.0).lengths[0]
        a25 = plan_continuous(scenario, method="astar", grid=0.25).lengths[0]
        runs = {}
        for method in ("ega", "ega-paper"):
            lengths, times = [], []
            for seed in range(seeds):
                plan = plan_continuous(scenario, method=method, seed=seed)
                assert plan.reached and all(plan.feasible), (name, method, seed)
                assert plan.lengths[0] >= lower - 1e-9, (name, method, seed, plan.lengths[0], lower)
                lengths.append(plan.lengths[0])
                times.append(plan.runtime_s)
            runs[method] = (np.array(lengths), np.array(times))
        (ega, t_ega), (paper, t_paper) = runs["ega"], runs["ega-paper"]
        ratio = ega.mean() / exact.lengths[0]
        within += ratio <= 1.005
        shorter += ega.mean() < a25
        paper_shorter += paper.mean() < a25
        limit = 2.0 if scenario.width >= 50 else 0.5
        if t_ega.max() > limit:
            slow.append(f"{name} {t_ega.max():.2f} s")
        print(f"| {name} | {exact.lengths[0]:.2f} | {a1:.2f} | {a25:.2f} | {ega.mean():.2f} ± {ega.std():.2f} "
              f"| {ratio:.4f} | {'yes' if ega.mean() < a25 else 'no'} | {t_ega.mean():.2f} ({t_ega.max():.2f}) "
              f"| {paper.mean():.2f} | {paper.mean() / exact.lengths[0]:.4f} | {t_paper.mean():.2f} |")
    print(f"\nEGA within 1.005 x exact on {within}/{len(names)} maps, shorter than A* 0.25 on {shorter}/{len(names)}; "
          f"EGA-paper shorter than A* 0.25 on {paper_shorter}/{len(names)}; runs over the time target: "
          f"{', '.join(slow) or 'none'}\n")


def bench_cross4(seeds):
    print(f"## 5. ega_cross4, four robots planned jointly by the EGA, {seeds} seeds\n")
    scenario = load_scenario("ega_cross4")
    alone = plan_continuous(scenario)
    own = alone.lengths.sum()
    closest, ratios, times = [], [], []
    for seed in range(seeds):
        plan = plan_continuous(scenario, method="ega", seed=seed)
        assert plan.reached and all(plan.feasible)
        closest.append(plan.min_robot_distance)
        ratios.append(plan.lengths.sum() / own)
        times.append(plan.runtime_s)
    closest, ratios, times = map(np.array, (closest, ratios, times))
    print("| planned | closest approach min (mean) | d_s | runs >= d_s | sum of lengths / own optima, max (mean) "
          "| s mean (max) |")
    print("|---|---:|---:|---:|---:|---:|")
    print(f"| each alone (exact) | {alone.min_robot_distance:.3f} | {alone.safety_distance:g} | - | 1.0000 | "
          f"{alone.runtime_s:.2f} |")
    print(f"| jointly (EGA) | {closest.min():.3f} ({closest.mean():.3f}) | {alone.safety_distance:g} "
          f"| {int((closest >= alone.safety_distance).sum())}/{seeds} | {ratios.max():.4f} ({ratios.mean():.4f}) "
          f"| {times.mean():.2f} ({times.max():.2f}) |")
    print()


def bench_ablation(seeds):
    from pymoo.optimize import minimize

    from htetro_opt.algorithms import EGA_ADDITIONS, EnhancedGA
    from htetro_opt.problems import PathBasesProblem

    print(f"## 6. EGA / exact with one addition off, {seeds} seeds per map\n")
    variants = {"all on": {}, **{f"no {name}": {"additions": [a for a in EGA_ADDITIONS if a != name]}
                                 for name in ("taut-refinement", "finer-apf", "delete-every-child")}}
    print("| map | " + " | ".join(variants) + " |")
    print("|---|" + "---:|" * len(variants))
    for name in [n for n in list_scenarios() if n.startswith("ega") and n != "ega_cross4"]:
        scenario = load_scenario(name)
        exact = plan_continuous(scenario).lengths[0]
        row = []
        for options in variants.values():
            best = [minimize(PathBasesProblem(scenario), EnhancedGA(10, **options), ("n_gen", 21),
                             seed=seed).algorithm.history[-1] for seed in range(seeds)]
            row.append(f"{np.mean(best) / exact:.4f}")
        print(f"| {name} | " + " | ".join(row) + " |")
    print()


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--seeds", type=int, default=10)
    parser.add_argument("--ablation-seeds", type=int, default=5)
    parser.add_argument("--only", default="1,2,3,4,5,6", help="sections to run, e.g. 4,5")
    args = parser.parse_args()
    only = {int(k) for k in args.only.split(",")}
    if 1 in only:
        bench_population(args.repeat)
    if 2 in only:
        bench_exact(args.repeat)
    if 3 in only:
        bench_astar(args.repeat)
    if 4 in only:
        bench_ega(args.seeds)
    if 5 in only:
        bench_cross4(args.seeds)
    if 6 in only:
        bench_ablation(args.ablation_seeds)


if __name__ == "__main__":
    main()
