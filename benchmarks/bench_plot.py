"""Speed and memory of the plots, against the per-patch drawing they replaced, side by side.

1. ``plot_path`` on a random walk of 1,000 and 10,000 commands on the 128 × 128 indoor room (every
   command valid: random commands, each invalid one replaced by the simulator), drawn and saved as
   PNG at ``save_figure``'s 120 dpi.
2. ``plot_tileset`` on the 64 × 64 tiling (1004 tiles), alone and with a visiting order (the tiles
   in scan order).

The baseline is the drawing as it was (one ``Rectangle`` patch per block per pose, one text per
cell and one arrow per visit), copied below. Every case runs in a fresh process, so its peak memory
(max RSS after its first draw and save, imports included: ~140 MB) is its own; times are medians over ``--repeat`` runs (the baseline runs
once with ``--quick``). The drawn footprint cells of both are checked to be the same.

Run:  python benchmarks/bench_plot.py [--repeat N] [--quick]
"""

from __future__ import annotations

import argparse
import multiprocessing
import platform
import resource
import statistics
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

from htetro_opt.model import Simulator
from htetro_opt.model.robot import FOOTPRINTS, SHAPES, STATE_NAMES, shape_index
from htetro_opt.scenarios import BLOCK_LETTERS, load_scenario
from htetro_opt.solvers import tile_workspace


def walk(n: int, seed: int = 0):
    scenario = load_scenario("indoor_room")
    sim = Simulator(scenario.workspace)
    rng = np.random.default_rng(seed)
    result = sim.run([sim.command_ids[rng.integers(0, sim.n_commands, n)]], scenario.roadmap[0], repair=rng)
    assert result.executed[0] == n
    return scenario, result.poses(0)


# --- the baseline: the per-patch drawing as it was --------------------------------------------------

def baseline_plot_path(workspace, poses, *, roadmap=(), title=""):
    import matplotlib.pyplot as plt
    from matplotlib.patches import Patch, Rectangle

    from htetro_opt.viz import SHAPE_COLOURS

    def colour(state):
        return SHAPE_COLOURS.get(STATE_NAMES[state], "#7f7f7f")

    side, aspect = 6.0, workspace.height / workspace.width
    fig, ax = plt.subplots(figsize=(side + 1.6, max(2.5, side * aspect) + 0.7), constrained_layout=True)
    w, h = workspace.width, workspace.height
    ax.imshow(workspace.occupancy, cmap="Greys", vmin=0, vmax=1.4, origin="lower",
              extent=(-0.5, w - 0.5, -0.5, h - 0.5), interpolation="nearest")
    used = []
    change = np.ones(len(poses), dtype=bool)
    change[1:] = (poses[1:, 2] != poses[:-1, 2]) | (poses[1:, 3] != poses[:-1, 3])
    for i, (x, y, s, hd) in enumerate(poses):
        if STATE_NAMES[s] not in used:
            used.append(STATE_NAMES[s])
        for bx, by in FOOTPRINTS[s, hd] + (x, y):
            ax.add_patch(Rectangle((bx - 0.5, by - 0.5), 1, 1, facecolor=colour(s), alpha=0.12, linewidth=0))
            if change[i]:
                ax.add_patch(Rectangle((bx - 0.45, by - 0.45), 0.9, 0.9, facecolor="none", edgecolor=colour(s),
                                       linewidth=1.2))
    ax.plot(poses[:, 0], poses[:, 1], color="black", linewidth=1.2, marker=".", markersize=3)
    for i, pose in enumerate(roadmap):
        edge = "green" if i == 0 else "red" if i == len(roadmap) - 1 else "blue"
        for bx, by in pose.cells():
            ax.add_patch(Rectangle((bx - 0.5, by - 0.5), 1, 1, facecolor="none", edgecolor=edge, linewidth=2.2,
                                   linestyle="--"))
    handles = [Patch(facecolor=colour(shape_index(n)), alpha=0.6, label=f"{n}-shape" if n in SHAPES else n) for n in used]
    ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8, frameon=False)
    ax.set_xlim(-0.5, w - 0.5)
    ax.set_ylim(-0.5, h - 0.5)
    ax.set_aspect("equal")
    ax.set_title(title, fontsize=10)
    return fig


def baseline_plot_tileset(tileset, order=None, *, title=""):
    import matplotlib.pyplot as plt
    from matplotlib.collections import LineCollection, PatchCollection
    from matplotlib.colors import to_rgba
    from matplotlib.patches import Rectangle

    from htetro_opt.viz import SHAPE_COLOURS

    visits = None if order is None else [tileset.index(t) for t in order]
    w, h = tileset.width, tileset.height
    side = min(9.0, max(4.0, 0.55 * max(w, h)))
    fig, ax = plt.subplots(figsize=(side + 2.1, max(2.5, side * h / w) + 0.7), constrained_layout=True)
    font = max(4.0, min(9.0, 70.0 / max(w, h)))
    squares, colours = [], []
    for y, x in zip(*np.nonzero(tileset.occupancy)):
        squares.append(Rectangle((x - 0.5, y - 0.5), 1, 1))
        colours.append(to_rgba("#333333"))
    labels = {}
    shapes = tileset.shapes
    for i, (tile, cells) in enumerate(zip(tileset.ids, tileset.blocks)):
        colour = to_rgba(SHAPE_COLOURS.get(shapes[i], "#bbbbbb"), 0.35)
        for letter, (x, y) in zip(BLOCK_LETTERS, cells.tolist()):
            squares.append(Rectangle((x - 0.5, y - 0.5), 1, 1))
            colours.append(colour)
            labels.setdefault((x, y), []).append(f"{tile}{letter}")
    ax.add_collection(PatchCollection(squares, facecolors=colours, linewidths=0))
    thin = [[(x - 0.5, -0.5), (x - 0.5, h - 0.5)] for x in range(w + 1)]
    thin += [[(-0.5, y - 0.5), (w - 0.5, y - 0.5)] for y in range(h + 1)]
    ax.add_collection(LineCollection(thin, colors="#cccccc", linewidths=0.5))
    thick = []
    for cells in tileset.blocks:
        mine = {tuple(c) for c in cells.tolist()}
        for x, y in mine:
            for dx, dy in ((1, 0), (-1, 0), (0, 1), (0, -1)):
                if (x + dx, y + dy) not in mine:
                    thick.append([(x + dx / 2, y - 0.5), (x + dx / 2, y + 0.5)] if dx else
                                 [(x - 0.5, y + dy / 2), (x + 0.5, y + dy / 2)])
    ax.add_collection(LineCollection(thick, colors="black", linewidths=1.8))
    for (x, y), names in labels.items():
        ax.text(x, y + (0.22 if visits is not None else 0.0), "/".join(names), ha="center", va="center",
                fontsize=font, color="#222222", in_layout=False)
    if visits:
        refs = tileset.blocks[visits, 1].astype(float)
        for k in range(len(refs) - 1):
            ax.annotate("", xy=refs[k + 1], xytext=refs[k], annotation_clip=False, in_layout=False,
                        arrowprops={"arrowstyle": "-|>", "color": "#c0392b", "linewidth": 1.3,
                                    "shrinkA": 5, "shrinkB": 5, "mutation_scale": 9})
        for k, (x, y) in enumerate(refs):
            ax.text(x, y - 0.18, str(k + 1), ha="center", va="center", fontsize=font * 0.9, color="white",
                    in_layout=False, fontweight="bold",
                    bbox={"boxstyle": "circle,pad=0.15", "facecolor": "#c0392b", "edgecolor": "none"})
    ax.set_xlim(-0.5, w - 0.5)
    ax.set_ylim(-0.5, h - 0.5)
    ax.set_aspect("equal")
    ax.set_title(title, fontsize=10)
    return fig


def footprint_cells_drawn(fig, baseline: bool) -> set:
    """The cells the figure fills with footprints: the baseline's unit squares, or the image's opaque cells."""
    ax = fig.axes[0]
    if baseline:
        return {(round(p.get_x() + 0.5), round(p.get_y() + 0.5)) for p in ax.patches
                if p.get_width() == 1 and p.get_facecolor()[3] > 0 and p.get_linestyle() != "--"}
    (image,) = [a for a in ax.images if a.get_gid() == "footprints"]
    return {(int(x), int(y)) for y, x in zip(*np.nonzero(image.get_array()[..., 3] > 0))}


# --- one case, in its own process ---------------------------------------------------------------------

def run_case(case: str, n: int, baseline: bool, repeat: int) -> dict:
    import matplotlib

    matplotlib.use("Agg")
    from htetro_opt.viz import plot_path, plot_tileset, save_figure

    if case == "path":
        scenario, poses = walk(n)
        draw = (lambda: baseline_plot_path(scenario.workspace, poses, roadmap=scenario.roadmap, title="walk")) if baseline \
            else (lambda: plot_path(scenario.workspace, poses, roadmap=scenario.roadmap, title="walk"))
    else:
        tileset = tile_workspace(load_scenario("tiling_64x64").workspace, name="tiling_64x64")
        order = list(tileset.ids) if case == "tileset+order" else None
        draw = (lambda: baseline_plot_tileset(tileset, order, title="64")) if baseline \
            else (lambda: plot_tileset(tileset, order, title="64"))
        n = len(tileset)
    draws, saves, cpus, peak, cells = [], [], [], None, None
    with tempfile.TemporaryDirectory() as folder:
        for _ in range(repeat):
            began, cpu = time.perf_counter(), time.process_time()
            fig = draw()
            drawn = time.perf_counter()
            save_figure(fig, Path(folder) / "plot.png")
            draws.append(drawn - began)
            saves.append(time.perf_counter() - drawn)
            cpus.append(time.process_time() - cpu)
            if peak is None:  # the first run's: memory freed by a closed figure is not always returned
                peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
                cells = footprint_cells_drawn(fig, baseline) if case == "path" else None
    return {"case": case, "n": n, "method": "per-patch (before)" if baseline else "collections (now)",
            "draw_s": statistics.median(draws), "save_s": statistics.median(saves), "cpu_s": statistics.median(cpus),
            "max_rss_mb": peak, "cells": cells}


def in_fresh_process(*args) -> dict:
    with ProcessPoolExecutor(max_workers=1, mp_context=multiprocessing.get_context("spawn")) as pool:
        return pool.submit(run_case, *args).result()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--quick", action="store_true", help="the baseline once, and not on 10,000 commands")
    args = parser.parse_args()
    cases = [("path", 1000), ("path", 10000), ("tileset", 0), ("tileset+order", 0)]
    print(f"# bench_plot: Python {platform.python_version()}, {platform.machine()}, repeat {args.repeat}")
    print(f"| {'case':<14} | {'size':>6} | {'method':<18} | {'draw s':>7} | {'save s':>7} | {'total s':>7} | "
          f"{'CPU s':>7} | {'max RSS MB':>10} |")
    print("|" + "|".join("-" * (k + 2) for k in (14, 6, 18, 7, 7, 7, 7, 10)) + "|")
    for case, n in cases:
        rows = [in_fresh_process(case, n, False, args.repeat)]
        if not (args.quick and n > 1000):
            rows.append(in_fresh_process(case, n, True, 1 if args.quick else args.repeat))
        if len(rows) == 2 and rows[0]["cells"] is not None:
            assert rows[0]["cells"] == rows[1]["cells"], "the footprint cells drawn differ"
        for row in rows:
            total = row["draw_s"] + row["save_s"]
            print(f"| {row['case']:<14} | {row['n']:>6} | {row['method']:<18} | {row['draw_s']:>7.2f} | "
                  f"{row['save_s']:>7.2f} | {total:>7.2f} | {row['cpu_s']:>7.2f} | {row['max_rss_mb']:>10.0f} |")
        if len(rows) == 2:
            print(f"|   speed-up     |        |                    |         |         | "
                  f"{(rows[1]['draw_s'] + rows[1]['save_s']) / (rows[0]['draw_s'] + rows[0]['save_s']):>6.0f}× |         |            |")


if __name__ == "__main__":
    main()
