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
    python benchmarks/bench_cover.py --speed    # issue 25's ratios only (below)

``--speed`` (also the last part of a full run; issue 25, item 3): the default method (``stripes``, S = {O,
vI, hI}) beside the boustrophedon baseline (``--method boustrophedon``: the first layer, O) on maps of
scattered obstacles (:func:`scattered`: n² / 40 blocks of 1-3 x 1-3 cells at seeded random places) of
16 x 16 and 64 x 64, several seeds, and coverage_16x16: each plan in its own process, the two methods
alternated, CPU seconds of the whole process (what ``htetro-opt cover`` costs: imports and tables
included) and of the planning call alone; the plan-length ratio; whether every coverable cell is
covered (and the plan re-validates in the simulator); then the wall time, CPU and peak RSS of the
default method and the baseline on a 256 x 256 scattered map and on the bundled real map malaga_building
(177 x 214), with ``--large`` a 384 x 384 scattered map, and with ``--map FILE.yaml`` any ROS map_server map
(read by :func:`~htetro_opt.scenarios.rosmap.load_ros_map`; e.g. the TurtleBot3 world map, 384 x 384 at
5 cm, kept outside the repository) (``--small``: the ratio table only). Peak RSS is given for the planning
(read in the child right after ``plan_coverage``) and for the whole process (the benchmark's own oracle
replay compiles the full Simulator, ~1.5 GB at 384 x 384).

The indoor room's {O} rows start at the roadmap's start (its goal lies behind a doorway the O cannot
pass) or at the bottom-left pose, both with a free end, and their boustrophedon from the same start.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import resource
import subprocess
import sys
import time

import numpy as np

from htetro_opt.errors import TilingError
from htetro_opt.model import SEED004_COMMANDS, Simulator, Workspace, sweep_tables
from htetro_opt.scenarios import load_scenario
from htetro_opt.scenarios.rosmap import load_ros_map
from htetro_opt.solvers import plan_coverage
from htetro_opt.solvers.coverage import LayerGraph
from htetro_opt.solvers.coverage._spec import SPEC as COVERAGE_SPEC

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
    if COVERAGE_SPEC.method(method).takes("stripes"):  # the baselines take no stripe layout
        options["stripes"] = stripes
    plan = plan_coverage(sc.workspace, layers, method=method, start=start, goal=goal, **options)
    cpu, wall = time.process_time() - cpu, time.perf_counter() - wall
    sim = Simulator(sc.workspace, commands=SEED004_COMMANDS)
    replay = sim.run([plan.commands], plan.start)
    assert replay.valid[0] and replay.time[0] == plan.time
    lg = LayerGraph(sc.workspace, plan.layers)
    bound = math.ceil((int(plan.coverable.sum()) - 4) / lg.gain)
    return {"plan": plan, "cpu": cpu, "wall": wall, "bound": bound, "nodes_graph": int(lg.valid.sum()),
            "edges_graph": len(lg.edges[0])}


def scattered(n: int, seed: int) -> np.ndarray:
    """An n x n map of n² / 40 obstacle blocks of 1-3 x 1-3 cells at random places (numpy's default_rng(seed);
    they may touch or overlap)."""
    rng = np.random.default_rng(seed)
    occ = np.zeros((n, n), dtype=bool)
    for _ in range(n * n // 40):
        x, y = rng.integers(0, n), rng.integers(0, n)
        occ[y:y + rng.integers(1, 4), x:x + rng.integers(1, 4)] = True
    return occ


def child(spec: str, method: str) -> None:
    """One plan in this process (``--child``): prints its figures as JSON."""
    if spec.startswith("scattered:"):
        n, seed = (int(v) for v in spec.split(":")[1:])
        ws = Workspace(scattered(n, seed))
    elif spec.endswith(".yaml"):  # a ROS map_server map given with --map, through the project's loader
        ws = Workspace(load_ros_map(spec)[0])
    else:
        ws = load_scenario(spec).workspace
    cpu, wall = time.process_time(), time.perf_counter()
    plan = plan_coverage(ws, method=method)
    cpu, wall = time.process_time() - cpu, time.perf_counter() - wall
    plan_rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024  # before the oracle's own tables
    replay = Simulator(ws, commands=SEED004_COMMANDS).run([plan.commands], plan.start)
    print(json.dumps({"cost": plan.action_cost, "plan_cpu": cpu, "plan_wall": wall, "success": plan.success,
                      "plan_rss": plan_rss, "size": f"{ws.width} x {ws.height}", "free": int((~ws.occupancy).sum()),
                      "valid": bool(replay.valid[0] and replay.time[0] == plan.time),
                      "coverable": int(plan.coverable.sum()), "left": int((plan.coverable & ~plan.covered).sum())}))


def in_process(spec: str, method: str) -> dict:
    """``child`` in a fresh process: its JSON, with the process's CPU seconds, wall seconds and peak RSS (MB)."""
    wall = time.perf_counter()
    proc = subprocess.Popen([sys.executable, __file__, "--child", spec, method], stdout=subprocess.PIPE, text=True)
    out = proc.stdout.read()
    _, status, usage = os.wait4(proc.pid, 0)
    proc.returncode = os.waitstatus_to_exitcode(status)
    assert proc.returncode == 0, f"{spec} {method}: exit {proc.returncode}"
    row = json.loads(out)
    row.update(cpu=usage.ru_utime + usage.ru_stime, wall=time.perf_counter() - wall, rss=usage.ru_maxrss / 1024)
    return row


def speed(repeats: int = 2, large=("scattered:256:0", "malaga_building")) -> None:
    """Issue 25's coverage ratios (see the module docstring); ``large``: the maps of the wall-time and memory
    table (``--large`` adds the 384 x 384 one)."""
    maps = ["coverage_16x16"] + [f"scattered:16:{s}" for s in range(5)] + [f"scattered:64:{s}" for s in range(3)]
    print("| map | stripes CPU s: process / planning | boustrophedon CPU s: process / planning | CPU ratio: "
          "process / planning | plan length: stripes / boustrophedon (ratio) | coverable cells left: stripes / "
          "boustrophedon | stripes peak RSS MB |")
    print("|---|---|---|---|---|---|---:|")
    ratios, planning, lengths = [], [], []
    for spec in maps:
        runs = {"stripes": [], "boustrophedon": []}
        for _ in range(repeats):  # alternated, so that a change in the machine's load hits both
            for method in runs:
                runs[method].append(in_process(spec, method))
        a, b = ({k: float(np.median([r[k] for r in runs[m]])) for k in ("cpu", "plan_cpu", "rss")}
                for m in ("stripes", "boustrophedon"))
        pa, pb = runs["stripes"][0], runs["boustrophedon"][0]
        assert all(r["valid"] for rs in runs.values() for r in rs)
        ratios.append(a["cpu"] / b["cpu"])
        planning.append(a["plan_cpu"] / b["plan_cpu"])
        lengths.append(pa["cost"] / pb["cost"])
        print(f"| {spec} | {a['cpu']:.2f} / {a['plan_cpu']:.2f} | {b['cpu']:.2f} / {b['plan_cpu']:.2f} "
              f"| {ratios[-1]:.2f} / {planning[-1]:.1f} | {pa['cost']} / {pb['cost']} ({lengths[-1]:.2f}) "
              f"| {pa['left']} of {pa['coverable']} / {pb['left']} of {pb['coverable']} | {a['rss']:.0f} |", flush=True)
    print(f"\nprocess CPU ratio stripes / boustrophedon: max {max(ratios):.2f} (target <= 4); planning alone: "
          f"{min(planning):.0f}-{max(planning):.0f}x; plan length ratio max {max(lengths):.2f} (target <= 1)\n")
    print("| map | size, free cells | method | wall s | CPU s (process) | peak RSS MB: planning / process | commands "
          "| every coverable cell covered |")
    print("|---|---|---|---:|---:|---:|---:|---|")
    for spec in large:
        for method in ("stripes", "boustrophedon"):
            if method == "boustrophedon" and spec == "scattered:384:0":
                continue  # the baseline's whole-map Dijkstra per lane vertex: far longer than the planner there
            r = in_process(spec, method)
            print(f"| {os.path.basename(spec)} | {r['size']}, {r['free']} | {method} | {r['wall']:.1f} | {r['cpu']:.1f} "
                  f"| {r['plan_rss']:.0f} / {r['rss']:.0f} | {r['cost']} | "
                  f"{'yes' if r['left'] == 0 else 'no: ' + str(r['left']) + ' left'} |", flush=True)
    load = os.getloadavg()
    print(f"\nload {load[0]:.1f} / {load[1]:.1f} / {load[2]:.1f} (1 / 5 / 15 min) at the end; "
          f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="the 16 x 16 and 16 x 7 rows only")
    parser.add_argument("--speed", action="store_true", help="issue 25's speed ratios only")
    parser.add_argument("--large", action="store_true", help="with --speed: also a 384 x 384 map (minutes)")
    parser.add_argument("--small", action="store_true", help="with --speed: the ratio table only")
    parser.add_argument("--map", action="append", default=[], metavar="FILE.yaml",
                        help="with --speed: also a ROS map_server map (its YAML; e.g. a 384 x 384 building map kept "
                             "outside the repository), in the wall-time and memory table")
    parser.add_argument("--child", nargs=2, metavar=("MAP", "METHOD"), help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        return child(*args.child)
    if args.speed:
        large = () if args.small else ("scattered:256:0", "malaga_building") + (("scattered:384:0",) if args.large else ())
        large += tuple(os.path.abspath(m) for m in args.map)
        return speed(large=large)
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
    print(f"total {time.perf_counter() - began:.1f} s\n")
    if not args.quick:
        speed()


if __name__ == "__main__":
    main()
