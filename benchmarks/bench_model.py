"""Speed of the shared model's hot paths, each against a baseline run side by side.

1. Simulator: a GA-sized batch (100 sequences x 100 commands) on a 24 x 24 map, of two populations:
   random valid walks (every command executes, like an evolved population) and uniformly random
   commands (most die within a few commands). Baselines, run side by side on the same sequences: the
   plain per-command Python loop over the swept-cell tables (check every swept cell of every command
   against the map, as the papers do), and per-command loops over the simulator's own compiled
   transition table (numpy scalar indexing, and Python lists: the strongest pure-Python baseline).
   Commands per second count submitted commands; the loops stop a sequence at its first invalid one.
2. Exact planner: one leg on a 24 x 24 map and on the 128 x 128 indoor room, scipy csgraph Dijkstra
   and heapq A* against networkx's Dijkstra over the same graph, including every method's graph build
   (the simulator's table compile is timed apart: every method needs it).

Run:  python benchmarks/bench_model.py [--repeat N]
"""

from __future__ import annotations

import argparse
import statistics
import time

import networkx as nx
import numpy as np

from htetro_opt.model import Simulator
from htetro_opt.scenarios import load_scenario
from htetro_opt.solvers.grid_paths import plan_exact


def timed(fn, repeat):
    times = []
    for _ in range(repeat):
        began = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - began)
    return statistics.median(times), out


def loop_numpy(table, dead, durations, sequences, start_id):
    finals, totals = [], []
    for seq in sequences:
        pose, total = start_id, 0.0
        for c in seq:
            nxt = table[pose, c]
            if nxt == dead:
                break
            pose, total = nxt, total + durations[c]
        finals.append(int(pose))
        totals.append(total)
    return finals, totals


def loop_lists(table, dead, durations, sequences, start_id):
    finals, totals = [], []
    for seq in sequences:
        pose, total = start_id, 0.0
        for c in seq:
            nxt = table[pose][c]
            if nxt == dead:
                break
            pose, total = nxt, total + durations[c]
        finals.append(pose)
        totals.append(total)
    return finals, totals


def loop_swept_cells(sweeps, free, shift, next_state, next_heading, durations, sequences, start):
    """The plain algorithm: per command, check each swept cell of the swept-cell table against the map."""
    finals, totals = [], []
    for seq in sequences:
        x, y, s, h = start
        total = 0.0
        for c in seq:
            cells = sweeps[s][h][c]
            if cells is None or not all(free.get((x + ox, y + oy), False) for ox, oy in cells):
                break
            x, y = x + shift[c][0], y + shift[c][1]
            s, h = next_state[s][c], next_heading[s][h][c]
            total += durations[c]
        finals.append((x, y, s, h))
        totals.append(total)
    return finals, totals


def swept_cell_inputs(sim):
    """The swept-cell tables of the simulator's commands as Python lists, and the free cells as a dict."""
    t, ids = sim.tables, sim.command_ids
    sweeps = [[[t.cells(s, h, g).tolist() if t.legal[s, g] else None for g in ids] for h in range(4)]
              for s in range(sim.n_states)]
    ws = sim.workspace
    free = {(x, y): not ws.occupancy[y, x] for y in range(ws.height) for x in range(ws.width)}
    shift = t.shift[ids].tolist()
    next_state = t.next_state[: sim.n_states][:, ids].tolist()
    next_heading = t.next_heading[: sim.n_states][:, :, ids].tolist()
    return sweeps, free, shift, next_state, next_heading, sim.durations.tolist()


def valid_walks(sim, start_id, rng, batch=100, length=100):
    """Random walks choosing uniformly among the valid commands at every step (all commands execute)."""
    out = np.empty((batch, length), dtype=np.int64)
    for i in range(batch):
        pose = start_id
        for t in range(length):
            options = np.flatnonzero(sim.next[pose, : sim.n_commands] != sim.dead)
            out[i, t] = options[rng.integers(len(options))]
            pose = sim.next[pose, out[i, t]]
    return out


def bench_simulator(repeat: int) -> list[dict]:
    scenario = load_scenario("random")
    sim = Simulator(scenario.workspace)
    rng = np.random.default_rng(0)
    start_id = sim.check_pose(scenario.start, what="start")
    populations = {
        "valid random walks": valid_walks(sim, start_id, rng),
        "uniform random commands": rng.integers(0, sim.n_commands, size=(100, 100)),
    }
    table_np, table_list = sim.next, sim.next.tolist()
    swept_inputs = swept_cell_inputs(sim)
    start_tuple = tuple(int(v) for v in sim.decode(start_id))
    durations_np, durations_list = sim.durations, sim.durations.tolist()
    rows = []
    for name, local in populations.items():
        global_seqs = sim.command_ids[local]
        local_lists = local.tolist()
        n = global_seqs.size
        t_vec, result = timed(lambda: sim.run(global_seqs, start_id), repeat)
        t_np, (finals, totals) = timed(lambda: loop_numpy(table_np, sim.dead, durations_np, local_lists, start_id), repeat)
        t_list, (finals2, totals2) = timed(lambda: loop_lists(table_list, sim.dead, durations_list, local_lists, start_id), repeat)
        t_swept, (finals3, totals3) = timed(lambda: loop_swept_cells(*swept_inputs, local_lists, start_tuple), repeat)
        final_ids = result.trace[np.arange(len(result)), result.executed]
        assert np.allclose(result.time, totals) and np.allclose(totals, totals2) and np.allclose(totals, totals3)
        assert final_ids.tolist() == finals == finals2
        assert [tuple(f) for f in result.final.tolist()] == finals3
        rows.append({
            "population": name,
            "commands": n,
            "executed_share": float(result.executed.sum() / n),
            "vectorised_cmd_per_s": n / t_vec,
            "loop_numpy_cmd_per_s": n / t_np,
            "loop_lists_cmd_per_s": n / t_list,
            "ratio_vs_numpy_loop": t_np / t_vec,
            "ratio_vs_list_loop": t_list / t_vec,
            "loop_swept_cmd_per_s": n / t_swept,
            "ratio_vs_swept_loop": t_swept / t_vec,
        })
    return rows, timed(lambda: Simulator(scenario.workspace), 3)[0]


def networkx_leg(sim, start_id, goal_id):
    graph = nx.DiGraph()
    n, c = sim.n_poses, sim.n_commands
    target = sim.next[:n, :c]
    src = np.broadcast_to(np.arange(n)[:, None], target.shape)
    keep = (target != sim.dead) & (target != src)
    weights = np.broadcast_to(sim.durations[:c][None, :], target.shape)
    edges = {}
    for u, v, w in zip(src[keep].tolist(), target[keep].tolist(), weights[keep].tolist()):
        if w < edges.get((u, v), np.inf):
            edges[u, v] = w
    graph.add_weighted_edges_from((u, v, w) for (u, v), w in edges.items())
    return nx.dijkstra_path_length(graph, start_id, goal_id)


def bench_exact(name: str, repeat: int) -> dict:
    scenario = load_scenario(name)
    roadmap = scenario.roadmap[:2]
    t_compile, sim = timed(lambda: Simulator(scenario.workspace.without_moving()), repeat)
    start_id, goal_id = sim.check_pose(roadmap[0]), sim.encode(roadmap[1])
    t_dij, plan = timed(lambda: plan_exact(sim, roadmap), repeat)
    t_astar, plan_a = timed(lambda: plan_exact(sim, roadmap, method="astar"), repeat)
    t_nx, nx_time = timed(lambda: networkx_leg(sim, start_id, goal_id), max(1, repeat // 2))
    assert abs(plan.time - plan_a.time) < 1e-9 and abs(plan.time - nx_time) < 1e-9
    return {
        "scenario": name,
        "size": f"{scenario.workspace.width}x{scenario.workspace.height}",
        "states": sim.n_poses,
        "optimum_time": plan.time,
        "compile_s": t_compile,
        "dijkstra_s": t_dij,
        "astar_s": t_astar,
        "networkx_s": t_nx,
        "ratio_networkx_vs_dijkstra": t_nx / t_dij,
    }


def bench_moving(name: str, repeat: int) -> dict:
    """A whole roadmap with its moving obstacles (time-expanded over their period)."""
    scenario = load_scenario(name)
    t_compile, sim = timed(lambda: Simulator(scenario.workspace), repeat)
    t_dij, plan = timed(lambda: plan_exact(sim, scenario.roadmap), repeat)
    t_astar, plan_a = timed(lambda: plan_exact(sim, scenario.roadmap, method="astar"), repeat)
    assert plan.reached and abs(plan.time - plan_a.time) < 1e-9
    return {"scenario": name, "period": scenario.workspace.period, "legs": len(scenario.roadmap) - 1,
            "nodes": sim.n_poses * scenario.workspace.period, "optimum_time": plan.time,
            "compile_s": t_compile, "dijkstra_s": t_dij, "astar_s": t_astar}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=7)
    args = parser.parse_args()
    rows, compile_s = bench_simulator(args.repeat)
    print("## Simulator: 100 sequences x 100 commands, 24 x 24 map ('random'), Cheng et al. 2020's commands\n")
    print("| population | executed | `Simulator.run` | loop over swept cells | loop, compiled numpy table "
          "| loop, compiled list table |")
    print("|---|---:|---:|---:|---:|---:|")
    def versus(ratio):
        return f"{ratio:.1f}x slower" if ratio >= 1 else f"{1 / ratio:.1f}x faster"

    for r in rows:
        print(f"| {r['population']} | {r['executed_share']:.0%} | {r['vectorised_cmd_per_s'] / 1e6:.1f} M/s "
              f"| {r['loop_swept_cmd_per_s'] / 1e6:.2f} M/s ({versus(r['ratio_vs_swept_loop'])}) "
              f"| {r['loop_numpy_cmd_per_s'] / 1e6:.2f} M/s ({versus(r['ratio_vs_numpy_loop'])}) "
              f"| {r['loop_lists_cmd_per_s'] / 1e6:.2f} M/s ({versus(r['ratio_vs_list_loop'])}) |")
    print(f"\nCommands/s count every submitted command (the loops stop a sequence at its first invalid one). "
          f"Compiling the table for this map: {compile_s * 1e3:.1f} ms.\n")
    print("## Exact planner, one leg (graph build + query; the simulator compile listed apart)\n")
    print("| scenario | size | poses | optimum | compile | csgraph Dijkstra | heapq A* | networkx | networkx / Dijkstra |")
    print("|---|---|---:|---:|---:|---:|---:|---:|---:|")
    for name in ("random", "three_slit", "spiral", "indoor_room"):
        r = bench_exact(name, args.repeat)
        print(f"| {r['scenario']} | {r['size']} | {r['states']:,} | {r['optimum_time']:g} | {r['compile_s'] * 1e3:.0f} ms "
              f"| {r['dijkstra_s'] * 1e3:.0f} ms | {r['astar_s'] * 1e3:.0f} ms | {r['networkx_s'] * 1e3:.0f} ms "
              f"| {r['ratio_networkx_vs_dijkstra']:.1f}x |")
    print("\n## Exact planner with moving obstacles, whole roadmap\n")
    print("| scenario | legs | period | time-expanded nodes | optimum | compile | csgraph Dijkstra | heapq A* |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|")
    for name in ("perpendicular_dynamic", "parallel_dynamic"):
        r = bench_moving(name, max(1, args.repeat // 3))
        print(f"| {r['scenario']} | {r['legs']} | {r['period']} | {r['nodes']:,} | {r['optimum_time']:g} "
              f"| {r['compile_s'] * 1e3:.0f} ms | {r['dijkstra_s'] * 1e3:.0f} ms | {r['astar_s'] * 1e3:.0f} ms |")


if __name__ == "__main__":
    main()
