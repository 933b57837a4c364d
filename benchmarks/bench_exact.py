"""The graph-free exact planner at real-map scale, side by side with scipy's point-robot Dijkstra.

``python benchmarks/bench_exact.py [--sizes 1.7M,4M] [--map FILE.yaml ...] [--upsample K] [--old-vs-new]``
builds building-like maps (see :func:`building_map`) and loads real ROS ``map_server`` maps given with
``--map`` (read by the project's loader; ``--upsample K`` also plans each at K x K finer cells), plans one long leg on each with the new planner (``dijkstra`` and ``astar``, each in
its own process so that ``resource.getrusage``'s peak resident memory is that run's), times
scipy.sparse.csgraph.dijkstra for a point robot over the same free cells (4-connected, unit steps) in
another process, and prints a Markdown table with the ratios and the machine's load (``uptime``).
``--old-vs-new`` adds the explicit-graph planner (the simulator's whole table as a CSR graph and scipy's
Dijkstra over it, kept for moving obstacles) against the new one on a 300 x 600 map.

Kernels are compiled (or loaded from numba's cache) on a small map in each process before the clock
starts.
"""

from __future__ import annotations

import argparse
import json
import resource
import subprocess
import sys
import time

import numpy as np

FACTOR = 6
"""Fine cells per coarse cell of the generated maps (at 3 cm cells, a coarse cell is 18 cm)."""


def building_map(width: int, height: int, seed: int = 0) -> np.ndarray:
    """A building-like floor plan, ``occ[y, x]`` True on walls and furniture, ``height x width`` cells.

    Made at a coarse scale (``FACTOR`` fine cells a coarse cell) and upscaled by repeating each coarse
    cell ``FACTOR x FACTOR`` times: an outer wall; corridors 4 coarse cells wide (about 70 cm at 3 cm
    cells) every 40 coarse rows and 56 coarse columns; between them blocks of rooms, each block split
    into 2 to 4 rooms by walls one coarse cell thick, every room with a door 3 coarse cells wide to a
    corridor or to its neighbour; and 0 to 3 pieces of furniture (1 to 4 coarse cells a side) a room.
    Seeded, so every run plans on the same map.
    """
    rng = np.random.default_rng(seed)
    cw, ch = -(-width // FACTOR), -(-height // FACTOR)
    occ = np.zeros((ch, cw), dtype=bool)
    occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = True
    corridor, row_step, col_step = 4, 40, 56
    rows = list(range(row_step, ch - 10, row_step))  # corridor bands' first rows
    cols = list(range(col_step, cw - 10, col_step))
    ybands = [1] + [r + corridor for r in rows]
    yends = rows + [ch - 1]
    xbands = [1] + [c + corridor for c in cols]
    xends = cols + [cw - 1]
    for y0, y1 in zip(ybands, yends):
        for x0, x1 in zip(xbands, xends):
            # a block of rooms [x0, x1) x [y0, y1), walled where it meets a corridor
            if y0 > 1:
                occ[y0, x0:x1] = True
            if y1 < ch - 1:
                occ[y1 - 1, x0:x1] = True
            if x0 > 1:
                occ[y0:y1, x0] = True
            if x1 < cw - 1:
                occ[y0:y1, x1 - 1] = True
            n_rooms = int(rng.integers(2, 5))
            cuts = np.sort(rng.choice(np.arange(x0 + 8, x1 - 8), size=n_rooms - 1, replace=False))
            edges = [x0] + cuts.tolist() + [x1 - 1]
            for cut in cuts:
                occ[y0:y1, cut] = True
            for a, b in zip(edges[:-1], edges[1:]):
                # a door to the corridor above or below, and one to the next room
                door = int(rng.integers(a + 2, max(a + 3, b - 4)))
                side = y0 if (y0 > 1 and (rng.random() < 0.5 or y1 >= ch - 1)) else y1 - 1
                occ[side, door : door + 3] = False
                if b < x1 - 1:
                    d = int(rng.integers(y0 + 2, y1 - 5))
                    occ[d : d + 3, b] = False
                for _ in range(int(rng.integers(0, 4))):
                    fw, fh = (int(v) for v in rng.integers(1, 5, size=2))
                    fx = int(rng.integers(a + 3, max(a + 4, b - fw - 2)))
                    fy = int(rng.integers(y0 + 3, max(y0 + 4, y1 - fh - 3)))
                    occ[fy : fy + fh, fx : fx + fw] = True
    fine = np.repeat(np.repeat(occ, FACTOR, axis=0), FACTOR, axis=1)
    return fine[:height, :width]


SIZES = {"1.7M": (1006, 1674), "4M": (1600, 2500), "300x600": (300, 600)}


def _endpoints(occ: np.ndarray):
    """Start near the lower-left corner, goal near the upper-right one, both in free open space.

    Both lie in the largest 4-connected piece of the open space (at least 6 cells from any obstacle),
    so that on a real map, whose free cells fall into separate rooms and scanned fragments, the leg
    has a way through.
    """
    from scipy.ndimage import distance_transform_cdt, label

    clear = distance_transform_cdt(~occ, metric="chessboard")
    pieces, count = label(clear >= 6)
    largest = np.argmax(np.bincount(pieces.ravel())[1:]) + 1 if count else 0
    ys, xs = np.nonzero(pieces == largest)
    start = np.argmin(xs + ys)
    goal = np.argmax(xs + ys)
    return (int(xs[start]), int(ys[start])), (int(xs[goal]), int(ys[goal]))


def _peak_bytes() -> int:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024  # kB on Linux


def _map(size: str) -> np.ndarray:
    """A generated map by its size name, or ``PATH.yaml[@K]``: a ROS map, its cells split K x K."""
    if size in SIZES:
        return building_map(*SIZES[size])
    from htetro_opt.scenarios.rosmap import load_ros_map

    path, _, k = size.partition("@")
    occ, _ = load_ros_map(path)
    k = int(k or 1)
    return np.repeat(np.repeat(occ, k, axis=0), k, axis=1)


def _name(size: str, occ_shape) -> str:
    if size in SIZES:
        return f"{size} ({SIZES[size][0]} x {SIZES[size][1]})"
    path, _, k = size.partition("@")
    stem = path.rsplit("/", 1)[-1].removesuffix(".yaml")
    return f"{stem}{f' split {k} x {k}' if k else ''} ({occ_shape[1]} x {occ_shape[0]})"


def run_one(kind: str, size: str) -> dict:
    """One measurement in this process: ``new-dijkstra``, ``new-astar``, ``old-dijkstra`` or ``scipy``."""
    occ = _map(size)
    height, width = occ.shape
    (sx, sy), (gx, gy) = _endpoints(occ)
    base = _peak_bytes()
    if kind == "scipy":
        from scipy.sparse import coo_matrix
        from scipy.sparse.csgraph import dijkstra

        began = time.perf_counter()
        free = ~occ
        index = np.arange(height * width).reshape(height, width)
        right = free[:, :-1] & free[:, 1:]
        up = free[:-1, :] & free[1:, :]
        rows = np.concatenate([index[:, :-1][right], index[:-1, :][up]])
        cols = np.concatenate([index[:, 1:][right], index[1:, :][up]])
        graph = coo_matrix((np.ones(len(rows)), (rows, cols)), shape=(height * width,) * 2).tocsr()
        built = time.perf_counter()
        dist = dijkstra(graph, directed=False, indices=int(index[sy, sx]))
        done = time.perf_counter()
        return {"kind": kind, "size": size, "name": _name(size, occ.shape), "cells": width * height,
                "free": int(free.sum()),
                "graph_s": built - began, "search_s": done - built, "distance": float(dist[gy * width + gx]),
                "peak": _peak_bytes(), "base": base}
    from htetro_opt.model import Pose, Workspace
    from htetro_opt.solvers.grid_paths import plan_exact
    from htetro_opt.solvers.grid_paths._exact import _plan_graph

    # compile or load the kernels before the clock starts: 40 x 40 is past the interpreter's 2**15 poses
    warm = Workspace(np.zeros((40, 40), dtype=bool))
    plan_exact(warm, [Pose(2, 2, "O", 0), Pose(30, 30, "O", 0)], method="dijkstra")
    plan_exact(warm, [Pose(2, 2, "O", 0), Pose(30, 30, "O", 0)], method="astar")
    ws = Workspace(occ)
    roadmap = [Pose(sx, sy, "O", 0), Pose(gx, gy, "O", 0)]
    method = kind.split("-", 1)[1]
    began = time.perf_counter()
    if kind.startswith("new"):
        plan = plan_exact(ws, roadmap, method=method, memory_budget="6GiB")
    else:
        plan = _plan_graph(ws, roadmap, method=method, diagonals=False, commands=None, timing=None, clearance=0.0,
                           t0=0)
    elapsed = time.perf_counter() - began
    return {"kind": kind, "size": size, "cells": width * height, "free": int((~occ).sum()), "seconds": elapsed,
            "time": plan.time, "reached": plan.reached, "commands": len(plan.commands),
            "expanded": plan.info.get("expanded"), "peak": _peak_bytes(), "base": base}


def _child(kind: str, size: str) -> dict:
    out = subprocess.run([sys.executable, __file__, "--one", kind, "--size", size], capture_output=True, text=True,
                         check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="1.7M,4M")
    parser.add_argument("--map", action="append", default=[], help="a ROS map_server YAML (repeatable)")
    parser.add_argument("--upsample", type=int, default=1, help="also plan each --map at K x K finer cells")
    parser.add_argument("--old-vs-new", action="store_true")
    parser.add_argument("--one")
    parser.add_argument("--size")
    args = parser.parse_args()
    if args.one:
        print(json.dumps(run_one(args.one, args.size)))
        return
    load = subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip()
    print(f"`uptime` before: {load}\n")
    gib = 2**30
    print("| map | cells (free) | scipy point robot: graph + Dijkstra | method | plan time | expanded | wall | "
          "peak RSS | target (2 s + 25x scipy) | ratio to scipy |")
    print("|---|---|---:|---|---:|---:|---:|---:|---:|---:|")
    sizes = [s for s in args.sizes.split(",") if s]
    for path in args.map:
        sizes += [path] + ([f"{path}@{args.upsample}"] if args.upsample > 1 else [])
    for size in sizes:
        scipy = _child("scipy", size)
        for kind in ("new-astar", "new-dijkstra"):
            r = _child(kind, size)
            assert r["reached"], r  # the endpoints share one piece of open space: a plan exists
            target = 2 + 25 * scipy["search_s"]
            print(f"| {scipy['name']} | {r['cells']:,} ({r['free']:,}) | "
                  f"{scipy['graph_s']:.2f} + {scipy['search_s']:.2f} s | {kind[4:]} | {r['time']:g} s | "
                  f"{r['expanded']:,} | {r['seconds']:.1f} s | {r['peak'] / gib:.2f} GiB | {target:.1f} s | "
                  f"{r['seconds'] / scipy['search_s']:.0f}x |", flush=True)
    if args.old_vs_new:
        print("\n| map | method | old: explicit graph | new: graph-free | speed-up | old peak RSS | new peak RSS |")
        print("|---|---|---:|---:|---:|---:|---:|")
        for method in ("dijkstra", "astar"):
            old, new = _child(f"old-{method}", "300x600"), _child(f"new-{method}", "300x600")
            assert abs(old["time"] - new["time"]) < 1e-9, (old, new)
            print(f"| 300 x 600 | {method} | {old['seconds']:.2f} s | {new['seconds']:.2f} s | "
                  f"{old['seconds'] / new['seconds']:.1f}x | {old['peak'] / gib:.2f} GiB | {new['peak'] / gib:.2f} GiB |",
                  flush=True)
    load = subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip()
    print(f"\n`uptime` after: {load}")


if __name__ == "__main__":
    main()
