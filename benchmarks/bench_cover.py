"""Coverage planning (Cheng et al. 2019): the stripes method beside the paper's variant and the baselines.

Per case: action cost (commands), the lower bound ⌈(coverable − 4) / g⌉ (g = most new cells one
command adds), completeness, region searches (run / proven optimal / memo hits / nodes expanded), the
DAG's size, CPU and wall seconds (one process; the sweep tables are warmed first and timed apart).
Every plan is re-validated by an independent Simulator replay, and the baseline is asserted to cover
the same cells. A second table runs every method (stripes, stripes-paper, boustrophedon, tiling-tsp)
on the 16 x 16 map with the command-driven coverage metrics.

    python benchmarks/bench_cover.py            # the issue's targets
    python benchmarks/bench_cover.py --quick    # the 16 x 16 rows only
"""

from __future__ import annotations

import argparse
import math
import time

from htetro_opt.errors import TilingError
from htetro_opt.model import SEED004_COMMANDS, Simulator, sweep_tables
from htetro_opt.scenarios import load_scenario
from htetro_opt.solvers import plan_coverage
from htetro_opt.solvers.coverage import LayerGraph

CASES = [
    ("coverage_16x16", "O", 4),
    ("coverage_16x16", "O,vI", 4),
    ("coverage_16x16", "O,hI", 4),
    ("coverage_16x16", "vI,hI", 4),
    ("coverage_16x16", "O,vI,hI", 4),
    ("coverage_16x16", "O", 3),
    ("coverage_16x16", "O,vI,hI", 3),
    ("coverage_16x7", "O,hI", "2,3,2"),
    ("tiling_64x64", "O", 4),
    ("tiling_64x64", "O,vI,hI", 4),
]


def run(name: str, layers: str, stripes, method: str = "stripes") -> dict:
    sc = load_scenario(name)
    start = goal = None
    if sc.roadmap:
        start, goal = sc.start, sc.goal
    cpu, wall = time.process_time(), time.perf_counter()
    plan = plan_coverage(sc.workspace, layers, method=method, stripes=stripes, start=start, goal=goal)
    cpu, wall = time.process_time() - cpu, time.perf_counter() - wall
    sim = Simulator(sc.workspace, commands=SEED004_COMMANDS)
    replay = sim.run([plan.commands], plan.start)
    assert replay.valid[0] and replay.time[0] == plan.time
    lg = LayerGraph(sc.workspace, plan.layers)
    bound = math.ceil((int(plan.coverable.sum()) - 4) / lg.gain)
    return {"plan": plan, "cpu": cpu, "wall": wall, "bound": bound, "nodes_graph": int(lg.valid.sum()),
            "edges_graph": len(lg.edges[0])}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="the 16 x 16 and 16 x 7 rows only")
    args = parser.parse_args()
    began = time.perf_counter()
    sweep_tables()
    print(f"sweep tables: {time.perf_counter() - began:.2f} s (once per process)\n")
    print("| map | S | stripes | complete | cost | bound | boustrophedon-O | regions (opt / memo) | nodes "
          "| DAG nodes / edges | graph vertices / edges | CPU s | wall s |")
    print("|---|---|---|---|---:|---:|---:|---|---:|---|---|---:|---:|")
    baselines: dict = {}
    for name, layers, stripes in CASES:
        if args.quick and name == "tiling_64x64":
            continue
        r = run(name, layers, stripes)
        p = r["plan"]
        if name not in baselines:
            baselines[name] = run(name, "O", 4, method="boustrophedon")
        b = baselines[name]["plan"]
        if p.layers == ("O",):  # the same morphology set covers the same cells
            assert (b.coverable == p.coverable).all() and not (b.coverable & ~b.covered).any()
        print(f"| {name} | {{{layers}}} | {stripes} | {'yes' if p.complete else 'no'} | {p.action_cost} | {r['bound']} "
              f"| {b.action_cost} | {p.regions} ({p.regions_optimal} / {p.memo_hits}) | {p.nodes} "
              f"| {p.info.get('dag_nodes')} / {p.info.get('dag_edges')} | {r['nodes_graph']} / {r['edges_graph']} "
              f"| {r['cpu']:.2f} | {r['wall']:.2f} |")
    print("\n| map | S | method | complete | cost | avg coverage time | re-covered % | switches | turns | wall s |")
    print("|---|---|---|---|---:|---:|---:|---:|---:|---:|")
    for name, layers in (("coverage_16x16", "O"), ("coverage_16x16", "O,vI,hI"), ("coverage_16x7", "O,hI")):
        for method in ("stripes", "stripes-paper", "boustrophedon", "tiling-tsp"):
            try:
                r = run(name, layers, "2,3,2" if name == "coverage_16x7" else 4, method=method)
            except TilingError as err:
                print(f"| {name} | {{{layers}}} | {method} | untileable: {str(err).split(':')[0]} | | | | | | |")
                continue
            p = r["plan"]
            print(f"| {name} | {{{layers}}} | {method} | {'yes' if p.complete else 'no'} | {p.action_cost} "
                  f"| {p.average_coverage_time:.3f} | {p.recovered_pct:.1f} | {p.switches} | {p.turns} "
                  f"| {r['wall']:.2f} |")
    print("\nbaseline boustrophedon-O CPU s: "
          + ", ".join(f"{k} {v['cpu']:.2f}" for k, v in baselines.items()))
    print(f"total {time.perf_counter() - began:.1f} s")


if __name__ == "__main__":
    main()
