"""Coverage planning (Cheng et al. 2019): the stripes method beside the paper's variant and the baselines.

Per case: action cost (commands), the lower bound ⌈(coverable − 4) / g⌉ (g = most new cells one
command adds), completeness, region searches (run / proven optimal / memo hits / nodes expanded), the
DAG's size, CPU and wall seconds (one process; the sweep tables are warmed first and timed apart).
Every plan is re-validated by an independent Simulator replay, and the baseline is asserted to cover
the same cells. A second table runs every method (stripes, stripes-paper, boustrophedon, tiling-tsp)
on the 16 x 16 map with the command-driven coverage metrics; a third sets ``ends="both"`` beside the
default ``"sweep"`` (asserting it never costs more), and the boustrophedon's mop-up sequenced beside
nearest-first.

    python benchmarks/bench_cover.py            # the issue's targets
    python benchmarks/bench_cover.py --quick    # the 16 x 16 and 16 x 7 rows only

The indoor room's {O} rows start at the roadmap's start (its goal lies behind a doorway the O cannot
pass) or at the bottom-left pose, both with a free end, and their boustrophedon from the same start.
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
    ("indoor_room", "O,vI,hI", 4),  # the roadmap's start and goal, behind the doorway
    ("indoor_room", "O", 4, "start"),  # the roadmap's start, a free end (the O cannot pass the doorway)
    ("indoor_room", "O", 4, "auto"),  # the bottom-left pose, a free end
]
LARGE = ("tiling_64x64", "indoor_room")


def run(name: str, layers: str, stripes, method: str = "stripes", where: str = "roadmap", **options) -> dict:
    """One plan; ``where``: the roadmap's start and goal ("roadmap"), its start and a free end
    ("start"), or the bottom-left pose and a free end ("auto"); ``options`` go to plan_coverage."""
    sc = load_scenario(name)
    start = goal = None
    if sc.roadmap and where != "auto":
        start = sc.start
        goal = sc.goal if where == "roadmap" else None
    cpu, wall = time.process_time(), time.perf_counter()
    plan = plan_coverage(sc.workspace, layers, method=method, stripes=stripes, start=start, goal=goal, **options)
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
    for name, layers, stripes, *ends in CASES:
        if args.quick and name in LARGE:
            continue
        ends = ends[0] if ends else "roadmap"
        r = run(name, layers, stripes, where=ends)
        p = r["plan"]
        key = (name, "start" if ends == "roadmap" and name == "indoor_room" else ends)  # O cannot reach its goal
        if key not in baselines:
            baselines[key] = run(name, "O", 4, method="boustrophedon", where=key[1])
        b = baselines[key]["plan"]
        if p.layers == ("O",):  # the same morphology set from the same start covers the same cells
            assert (b.coverable == p.coverable).all() and not (b.coverable & ~b.covered).any()
        print(f"| {name}{'' if ends == 'roadmap' else f' ({ends})'} | {{{layers}}} | {stripes} | {'yes' if p.complete else 'no'} | {p.action_cost} | {r['bound']} "
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
    print("\n| map | S | stripes | cost, ends sweep | cost, ends both | folded stripes | CPU s sweep / both |")
    print("|---|---|---|---:|---:|---:|---|")
    for name, layers, stripes in (("coverage_16x16", "O", 4), ("coverage_16x16", "O,vI,hI", 4),
                                  ("coverage_16x16", "vI,hI", 4), ("coverage_16x16", "O", 3),
                                  ("coverage_16x7", "O,hI", "2,3,2")):
        sweep, both = run(name, layers, stripes), run(name, layers, stripes, ends="both")
        assert both["plan"].action_cost <= sweep["plan"].action_cost
        folded = sum(d.get("folded", False) for d in both["plan"].stripes_detail)
        print(f"| {name} | {{{layers}}} | {stripes} | {sweep['plan'].action_cost} | {both['plan'].action_cost} "
              f"| {folded} | {sweep['cpu']:.2f} / {both['cpu']:.2f} |")
    print("\n| map (boustrophedon-O) | mop-up nearest-first: commands (mop-up) | sequenced: commands (mop-up) |")
    print("|---|---:|---:|")
    for name, ends in (("coverage_16x7", "roadmap"), ("indoor_room", "auto")):
        if args.quick and name in LARGE:
            continue
        near = run(name, "O", 4, method="boustrophedon", where=ends, mopup="nearest")["plan"]
        seq = run(name, "O", 4, method="boustrophedon", where=ends, mopup="sequenced")["plan"]
        assert seq.action_cost <= near.action_cost
        print(f"| {name} ({ends}) | {near.action_cost} ({near.mopup_commands}) "
              f"| {seq.action_cost} ({seq.mopup_commands}) |")
    print("\nbaseline boustrophedon-O CPU s: "
          + ", ".join(f"{k[0]} ({k[1]}) {v['cpu']:.2f}" for k, v in baselines.items()))
    print(f"total {time.perf_counter() - began:.1f} s")


if __name__ == "__main__":
    main()
