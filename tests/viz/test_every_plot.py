"""Every plot of htetro_opt.viz, drawn through the library from a plan of each method family, is saved
as a valid image file (a PNG or a GIF that Pillow opens and verifies).

Nothing here checks pixels or what is drawn (the other tests of tests/viz do): this is the net that
catches a plot type or a method family's plan that no longer draws or saves at all. The plans are
tiny (small maps, a handful of generations) so that the whole module stays quick.
"""

from __future__ import annotations

import numpy as np
import pytest
from PIL import Image

from htetro_opt import viz
from htetro_opt.model import Pose, Workspace, simulate_coverage
from htetro_opt.problems.waypoint_sequencing import SequencingInstance
from htetro_opt.scenarios import load_scenario
from htetro_opt.solvers import plan_continuous, plan_coverage, plan_path, sequence_waypoints, tile_workspace
from htetro_opt.solvers.grid_paths import replan_heat

PNG = b"\x89PNG\r\n\x1a\n"
GIF = (b"GIF87a", b"GIF89a")
TINY_GA = {"pop_size": 6, "max_gen": 3, "seed": 0}
TINY_SWARM = {"pop_size": 6, "max_gen": 3, "seed": 0}

# An 8 × 8 room: walls round it, a 2 × 2 block in it.
ROOM = np.zeros((8, 8), dtype=bool)
ROOM[[0, -1], :] = ROOM[:, [0, -1]] = True
ROOM[3:5, 4:6] = True
ROOM_ROADMAP = (Pose(1, 2, "O"), Pose(5, 6, "O"))  # B2 is the O's top-left block
# The same room with the goal walled in: no plan reaches it.
WALLED = ROOM.copy()
WALLED[4:8, 4] = WALLED[4, 4:8] = True
WALLED_ROADMAP = (Pose(1, 2, "O"), Pose(5, 6, "O"))
# An 8 × 8 open map with a 2 × 2 block in its middle: 60 free cells, a multiple of 4 (tiling + TSP covers it).
COVER = np.zeros((8, 8), dtype=bool)
COVER[3:5, 3:5] = True


@pytest.fixture(scope="module")
def grid():
    ws = Workspace(ROOM)
    walled = Workspace(WALLED)
    exact = plan_path(ws, ROOM_ROADMAP, method="dijkstra")
    ga = plan_path(ws, ROOM_ROADMAP, method="htetro-ga", **TINY_GA)
    unreached = plan_path(walled, WALLED_ROADMAP, method="htetro-ga-paper", **TINY_GA)
    assert exact.reached and not unreached.reached
    heat = plan_path(ws, ROOM_ROADMAP, method="heat", keep_fields=True)
    maze = load_scenario("maze_partial")
    replanned = replan_heat(maze, sensor_range=6.0, keep_fields=True).as_plan()
    assert replanned.info["replans"]
    return {"ws": ws, "walled": walled, "exact": exact, "ga": ga, "unreached": unreached, "heat": heat,
            "maze": maze, "replanned": replanned}


@pytest.fixture(scope="module")
def continuous():
    cross = load_scenario("ega_cross4")  # four robots swapping corners
    plans = {"exact": plan_continuous(cross, method="exact"),
             "pso": plan_continuous(cross, method="pso", **TINY_SWARM),
             "ega": plan_continuous(cross, method="ega", **TINY_GA)}
    slits = load_scenario("ega07_slits1")
    front = plan_continuous(slits, method="nsga2", seed=0, pop_size=6, max_gen=3)
    return {"cross": cross, "slits": slits, "front": front, **plans}


@pytest.fixture(scope="module")
def tiles():
    tileset = tile_workspace(load_scenario("tiling_6x6").workspace, name="tiling_6x6").tileset
    result = sequence_waypoints(SequencingInstance.from_tileset(tileset), method="zigzag")
    coverage = simulate_coverage(tileset, [tileset.index(t) for t in result.tiles], pixels_per_cell=4)
    return tileset, result.tiles, coverage


@pytest.fixture(scope="module")
def cover():
    ws = Workspace(COVER)
    return ws, {"stripes": plan_coverage(ws, method="stripes"), "tiling-tsp": plan_coverage(ws, method="tiling-tsp")}


def assert_image(path, kind: str) -> None:
    """``path`` is a non-empty ``kind`` ("PNG" or "GIF") file that Pillow opens and verifies."""
    data = path.read_bytes()
    assert data.startswith(PNG) if kind == "PNG" else data[:6] in GIF, path
    with Image.open(path) as image:
        assert image.format == kind and image.size[0] > 0 and image.size[1] > 0
        image.verify()


DRAWINGS = {
    # grid paths
    "path dijkstra": lambda g, c, t, v: viz.plot_path(g["ws"], g["exact"].poses, roadmap=ROOM_ROADMAP),
    "ga plan": lambda g, c, t, v: viz.plot_ga_plan(g["ws"], g["ga"], roadmap=ROOM_ROADMAP),
    "ga plan unreached": lambda g, c, t, v: viz.plot_ga_plan(g["walled"], g["unreached"], roadmap=WALLED_ROADMAP),
    "heat plan": lambda g, c, t, v: viz.plot_heat_plan(g["ws"], g["heat"], g["heat"].info["fields"],
                                                       roadmap=ROOM_ROADMAP, arrows=4),
    "heat field": lambda g, c, t, v: viz.plot_heat_field(g["heat"].info["fields"], workspace=g["ws"],
                                                         poses=g["heat"].poses, arrows=4).figure,
    "heat replanning": lambda g, c, t, v: viz.plot_heat_plan(
        g["maze"].workspace, g["replanned"], g["replanned"].info["fields"], replans=g["replanned"].info["replans"],
        roadmap=g["maze"].roadmap, hidden=g["maze"].hidden, arrows=6),
    # the GA's front and convergence
    "fronts": lambda g, c, t, v: viz.plot_fronts([g["ga"], g["unreached"]], labels=["reached", "unreached"],
                                                 objectives=("f_t", "f_sf")),
    "parallel": lambda g, c, t, v: viz.plot_parallel(g["ga"]),
    "convergence": lambda g, c, t, v: viz.plot_convergence(g["unreached"]),
    # continuous paths
    "continuous exact": lambda g, c, t, v: viz.plot_continuous(c["cross"], c["exact"]),
    "continuous pso": lambda g, c, t, v: viz.plot_continuous(c["cross"], c["pso"]),
    "continuous ega": lambda g, c, t, v: viz.plot_continuous(c["cross"], c["ega"]),
    "continuous methods": lambda g, c, t, v: viz.plot_continuous(c["cross"], [c["exact"], c["pso"], c["ega"]]),
    "apf potential": lambda g, c, t, v: viz.plot_apf_potential(c["slits"], grid=2.0, n_paths=1),
    "continuous front": lambda g, c, t, v: viz.plot_continuous_front(c["front"]),
    # tiling and sequencing
    "tileset": lambda g, c, t, v: viz.plot_tileset(t[0]),
    "tileset order": lambda g, c, t, v: viz.plot_tileset(t[0], order=t[1]),
    "tileset coverage": lambda g, c, t, v: viz.plot_coverage(t[2]),
    # complete coverage
    "cover stripes": lambda g, c, t, v: viz.plot_cover(v[0], v[1]["stripes"]),
    "cover tiling-tsp": lambda g, c, t, v: viz.plot_cover(v[0], v[1]["tiling-tsp"]),
    "cover tiling-tsp line": lambda g, c, t, v: viz.plot_cover(v[0], v[1]["tiling-tsp"], arrows=10),
    "cover heat stripes": lambda g, c, t, v: viz.plot_cover_heat(v[1]["stripes"]),
    "cover heat tiling-tsp": lambda g, c, t, v: viz.plot_cover_heat(v[1]["tiling-tsp"]),
}


@pytest.mark.parametrize("name", list(DRAWINGS))
def test_every_plot_is_saved_as_a_valid_png(name, grid, continuous, tiles, cover, tmp_path):
    figure = DRAWINGS[name](grid, continuous, tiles, cover)
    path = viz.save_figure(figure, tmp_path / f"{name.replace(' ', '_')}.png", dpi=40)
    assert_image(path, "PNG")


def test_an_animation_is_saved_as_a_valid_gif(grid, tmp_path):
    plan = grid["exact"]
    animation = viz.animate_path(grid["ws"], plan.commands, ROOM_ROADMAP[0], roadmap=ROOM_ROADMAP,
                                 frames_per_step=1, dpi=30)
    path = viz.save_gif(animation, tmp_path / "plan.gif", fps=10)
    assert_image(path, "GIF")
    with Image.open(path) as gif:
        assert gif.n_frames > 1
