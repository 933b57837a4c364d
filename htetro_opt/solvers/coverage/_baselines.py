"""Baselines for coverage: a boustrophedon in one layer (BA*-like), and tiling + TSP.

The map is cut into lanes as tall as the layer's footprint (2 rows for the O-shape), bottom up; the
lanes are swept alternately +x and −x; in each lane the robot goes, by exact shortest legs of the
workspace graph, to every lane vertex (footprint inside the lane) that covers a cell not yet covered,
in sweep order. What the lanes leave is covered by the mop-up (nearest first), then the robot returns
to the goal if there is one.

The tiling + TSP baseline (Le et al. 2018's pipeline driven on Cheng et al. 2019's commands) tiles the
free cells with the morphology set's shapes (headings ignored: a tile may take any heading;
:func:`~htetro_opt.solvers.tiling.tile_workspace`), orders the tiles
(:func:`~htetro_opt.solvers.sequencing.sequence_waypoints`, free start, the start tile then the one
nearest the robot's start) and drives the robot from its start through every tile's pose by
minimum-command legs (:func:`~htetro_opt.solvers.grid_paths.plan_exact` on the 13 commands). A map
the shapes cannot tile is a :class:`~htetro_opt.errors.TilingError`.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.sparse.csgraph import dijkstra

from htetro_opt.solvers.coverage._layers import LayerGraph

__all__ = ["boustrophedon_path", "tiling_tsp_tokens"]


def boustrophedon_path(lg: LayerGraph, start: int, reachable: np.ndarray, *, layer: int = 0) -> list[int]:
    """The lane walk's vertex path from ``start`` (the mop-up and the goal are the caller's)."""
    hw = lg.width * lg.height
    low, high = lg.rows
    ids = np.arange(layer * hw, (layer + 1) * hw)
    ids = ids[reachable[ids]]
    if not len(ids):
        return [start]
    lane = int(high[ids[0]] - low[ids[0]] + 1)
    covered = np.zeros(hw, dtype=bool)
    covered[lg.footprint[start]] = True
    path, cur = [start], start
    xs = ids % lg.width
    for k, lo in enumerate(range(0, lg.height, lane)):
        inside = ids[(low[ids] >= lo) & (high[ids] < lo + lane)]
        order = inside[np.lexsort((inside // lg.width, xs[np.searchsorted(ids, inside)] * (1 if k % 2 == 0 else -1)))]
        for v in order.tolist():
            if covered[lg.footprint[v]].all():
                continue
            dist, pred = dijkstra(lg.matrix, indices=cur, return_predecessors=True, limit=np.inf)
            if not math.isfinite(dist[v]):
                continue
            leg = [v]
            while leg[-1] != cur:
                leg.append(int(pred[leg[-1]]))
            leg = leg[::-1][1:]
            covered[lg.footprint[leg].ravel()] = True
            path += leg
            cur = v
    return path


def tiling_tsp_tokens(lg: LayerGraph, start: int, goal: int | None, *, time_limit: float | None = None) -> tuple[
        list[str], dict]:
    """Tokens of the tiling + TSP baseline from ``start`` (through ``goal`` last, if given), and its info.

    Raises
    ------
    TilingError
        If the layers' shapes cannot tile the free cells.
    PlanningError
        If a tile's pose cannot be reached on the 13 commands.
    """
    from htetro_opt.errors import PlanningError
    from htetro_opt.problems import SequencingInstance
    from htetro_opt.solvers.grid_paths import plan_exact
    from htetro_opt.solvers.sequencing import sequence_waypoints
    from htetro_opt.solvers.tiling import tile_workspace

    shapes = list(dict.fromkeys(layer.shape for layer in lg.layers))
    tiles = tile_workspace(lg.workspace, shapes=shapes, time_limit=time_limit).tileset
    poses = tiles.poses
    here = lg.pose(start)
    first = min(range(len(tiles)), key=lambda i: (abs(poses[i].x - here.x) + abs(poses[i].y - here.y), i))
    instance = SequencingInstance.from_tileset(tiles, start=tiles.ids[first])
    order = sequence_waypoints(instance, seed=0, time_limit=time_limit)
    roadmap = [here] + [poses[tiles.index(label)] for label in order.tiles]
    if goal is not None:
        roadmap.append(lg.pose(goal))
    roadmap = [p for k, p in enumerate(roadmap) if k == 0 or p != roadmap[k - 1]]
    info = {"tiles": len(tiles), "sequencing": order.method, "sequence_cost": float(order.cost)}
    if len(roadmap) < 2:  # one tile, and the robot starts on it
        return [], info
    plan = plan_exact(lg.sim, roadmap)
    if not plan.reached:
        raise PlanningError("the tiling + TSP baseline cannot reach every tile's pose on Cheng et al. 2019's commands")
    return list(plan.tokens), info
