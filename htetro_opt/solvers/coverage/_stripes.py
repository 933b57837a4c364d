"""Cheng et al. 2019's stripe coverage (§III–IV): stripes, regions and one auxiliary DAG.

Our reading of the paper, where it is ambiguous or contradicts itself:

- **Stripes** (Def. 6–7) are bands of rows stacked from y = 0, swept +x in the first, −x in the
  second, … (a boustrophedon of bands). A vertex belongs to stripe k when its whole footprint lies in
  k's rows (Def. 6 uses B2's cell; with footprints, a stripe's cost does not depend on its
  neighbours). **Widening** (Alg. 5 l. 14): when no connected piece of a stripe's vertices covers all
  the coverable cells of its own rows, rows are borrowed one at a time, the previous stripe's first,
  at most as many as the stripe has; the widening that leaves fewest of its cells out wins (ties:
  fewer rows). The stripe then keeps every connected piece that leaves out that fewest (not only
  one: at the map's top edge the vertical I cannot switch to the O, yet each covers the whole
  stripe, and a cut-edge in its own layer enters it); its targets stay its own rows' cells.
- **Ports and cut-edges** (Def. 8–9): per layer and piece, the exit port is the layer's vertex at the
  sweep end (extreme x), y nearest the next stripe; the next stripe's entry port likewise at the same
  end, y nearest the previous stripe; the cut-edge cost is the fewest translations in that layer
  through both bands (no edge if none).
- **Regions** (§IV-B): each stripe is cut every ``region_columns`` columns along its sweep; the ports
  at a cut are the stripe's vertices with B2 in the cut column (a cut without any is dropped). A
  region may use the stripe's vertices with B2 up to 3 columns outside it and must cover the targets
  in its columns reachable from its entry in that window; the rest is left to the mop-up.
- **One DAG** (eq. 8, typos fixed): start, ports, cut-edges and goal are the nodes of one
  ``networkx.DiGraph``; a region edge costs its search's cost (``_rbt``), computed lazily by the
  weight callable of ``nx.single_source_dijkstra`` and memoised by the region's content (its window
  of vertices and edges relative to the window, targets, entry and exit), not by a cell (Alg. 1's
  ``WT`` keys by the vertex's cell only, which mixes different costs).
- **Start, goal, transits, mop-up**: a start outside the first stripe reaches its entry ports (a goal
  outside the last stripe is reached from its exit ports) by shortest paths in the workspace graph;
  without a goal the plan ends where the last region does. Cells the stripes leave uncovered are
  visited nearest-first afterwards (mop-up), and the plan then returns to the goal if there is one.
  If the DAG has no path at all, the whole map is covered by the mop-up walk from the start.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import networkx as nx
import numpy as np
from scipy.sparse.csgraph import connected_components, dijkstra

from htetro_opt._validation import check_int
from htetro_opt.errors import ParameterError
from htetro_opt.solvers.coverage._layers import LayerGraph
from htetro_opt.solvers.coverage._rbt import Region, greedy_walk, search_inserting, search_region
from htetro_opt.solvers.coverage._result import Coverability

__all__ = ["stripe_widths", "plan_stripes", "StripeOutcome", "shortest_path", "mop_up", "WINDOW_MARGIN"]

WINDOW_MARGIN = 3
"""Columns a region may use beyond its own on either side (B2's column)."""


def stripe_widths(stripes, height: int, name: str = "stripes") -> tuple[int, ...]:
    """Stripe widths bottom up: an int w gives ⌊H / w⌋ bands of w rows, the remainder added to the
    last (16 rows, 3 → 3, 3, 3, 3, 4: the paper's N_str,1); a sequence is taken as it is and must sum to H.

    Raises
    ------
    ParameterError
        If a width is not a positive integer, an int is wider than the map, or a sequence does not sum to H.

    Examples
    --------
    >>> stripe_widths(3, 16), stripe_widths([2, 3, 2], 7)
    ((3, 3, 3, 3, 4), (2, 3, 2))
    """
    if isinstance(stripes, str):
        try:
            parts = [int(p) for p in stripes.replace(" ", "").split(",") if p]
        except ValueError:
            raise ParameterError(f"{name} must be a width or comma-separated widths, got {stripes!r}") from None
        stripes = parts[0] if len(parts) == 1 else parts
    if isinstance(stripes, (list, tuple)):
        widths = tuple(check_int(w, f"{name} width", minimum=1) for w in stripes)
        if not widths or sum(widths) != height:
            raise ParameterError(f"{name} widths {list(widths)} must sum to the map's height {height}, "
                                 f"they sum to {sum(widths)}")
        return widths
    w = check_int(stripes, name, minimum=1, maximum=height)
    n = height // w
    return (w,) * (n - 1) + (w + height - n * w,)


@dataclass
class _Stripe:
    own: tuple[int, int]  # own rows [low, high)
    band: tuple[int, int]  # rows with the borrowed ones
    nodes: np.ndarray  # vertices of its connected pieces that leave out fewest targets
    targets: np.ndarray  # flat coverable cells of its own rows
    direction: int = 1  # +1: sweep +x, −1: −x
    blocks: list = field(default_factory=list)  # region columns [c0, c1) in sweep order
    cuts: list = field(default_factory=list)  # ports (vertices) at each cut between blocks
    cost: int = 0
    pieces: list = field(default_factory=list)  # those pieces, each its vertices


@dataclass
class StripeOutcome:
    """What :func:`plan_stripes` found: the vertex path and the search's statistics."""

    path: list[int]
    dag_cost: int | None
    transit: int
    stripes: list
    regions: int = 0
    regions_optimal: int = 0
    memo_hits: int = 0
    nodes: int = 0
    time_limited: bool = False
    info: dict = field(default_factory=dict)


def shortest_path(lg: LayerGraph, source: int, target: int, matrix=None) -> tuple[float, list[int]]:
    """Cost and vertices of the cheapest path source → target in the workspace graph (or ``matrix``)."""
    dist, pred = dijkstra(lg.matrix if matrix is None else matrix, indices=source, return_predecessors=True)
    if not math.isfinite(dist[target]):
        return math.inf, []
    path = [target]
    while path[-1] != source:
        path.append(int(pred[path[-1]]))
    return float(dist[target]), path[::-1]


def mop_up(lg: LayerGraph, path: list[int], coverable: np.ndarray, reachable: np.ndarray) -> list[int]:
    """Extend a vertex path until every coverable cell is under a visited footprint: each time to the
    nearest vertex covering an uncovered cell (ties: the lower vertex number)."""
    hw = lg.width * lg.height
    covered = np.zeros(hw, dtype=bool)
    covered[lg.footprint[path].ravel()] = True
    target = coverable.reshape(-1)
    added: list[int] = []
    cur = path[-1]
    while (target & ~covered).any():
        useful = reachable & (target & ~covered)[lg.footprint].any(axis=1)
        dist, pred = dijkstra(lg.matrix, indices=cur, return_predecessors=True)
        cost = np.where(useful, dist, np.inf)
        goal = int(np.argmin(cost))
        if not math.isfinite(cost[goal]):
            break  # cannot happen for coverable cells: they are under reachable vertices
        leg = [goal]
        while leg[-1] != cur:
            leg.append(int(pred[leg[-1]]))
        leg = leg[::-1][1:]
        covered[lg.footprint[leg].ravel()] = True
        added += leg
        cur = goal
    return added


class _Planner:
    def __init__(self, lg: LayerGraph, cov: Coverability, start: int, goal: int | None, widths, *,
                 region_columns: int, budget: int, deadline: float | None, memo: bool, paper: bool = False) -> None:
        self.lg, self.cov, self.start, self.goal, self.paper = lg, cov, start, goal, paper
        self.region_columns, self.budget, self.deadline, self.use_memo = region_columns, budget, deadline, memo
        n = lg.n_nodes
        ids = np.arange(n)
        self.bx = ids % lg.width
        self.by = (ids // lg.width) % lg.height
        self.ylo, self.yhi = lg.rows
        self.reach = cov.reachable
        self.coverable = cov.coverable.reshape(-1)
        self.memo: dict = {}
        self.problems: dict = {}
        self.results: dict = {}
        self.stats = {"regions": 0, "optimal": 0, "memo_hits": 0, "nodes": 0}
        self.time_limited = False
        lows = np.cumsum((0,) + tuple(widths))
        self.stripes: list[_Stripe] = []
        for lo, hi in zip(lows[:-1], lows[1:]):
            stripe = self._widen(int(lo), int(hi))
            if len(stripe.nodes):
                self.stripes.append(stripe)
        for i, stripe in enumerate(self.stripes):
            stripe.direction = 1 if i % 2 == 0 else -1
            self._regions(stripe)

    # --- stripes ------------------------------------------------------------------------------
    def _piece(self, band: tuple[int, int], targets: np.ndarray) -> tuple[int, np.ndarray, list]:
        """(targets left out, vertices) of the band's connected pieces that leave out fewest: all of
        them, since each can be entered by its own layer's cut-edge (in the top stripe of a free map
        the vertical I cannot switch to the O, yet both cover the whole stripe)."""
        lo, hi = band
        idx = np.flatnonzero(self.reach & (self.ylo >= lo) & (self.yhi < hi))
        if not len(idx):
            return len(targets), idx, []
        _, labels = connected_components(self.lg.matrix[idx][:, idx], directed=False)
        hw = self.lg.width * self.lg.height
        missing = {}
        for label in np.unique(labels).tolist():
            covered = np.zeros(hw, dtype=bool)
            covered[self.lg.footprint[idx[labels == label]].ravel()] = True
            missing[label] = int((~covered[targets]).sum())
        fewest = min(missing.values())
        keep = [label for label, m in missing.items() if m == fewest]
        return fewest, idx[np.isin(labels, keep)], [idx[labels == label] for label in keep]

    def _widen(self, lo: int, hi: int) -> _Stripe:
        cells = np.arange(lo * self.lg.width, hi * self.lg.width)
        targets = cells[self.coverable[cells]]
        bands, low, high = [(lo, hi)], lo, hi
        for _ in range(hi - lo):  # at most as many rows as the stripe has, the previous stripe's first
            if low > 0:
                low -= 1
            elif high < self.lg.height:
                high += 1
            else:
                break
            bands.append((low, high))
        best = None
        for band in bands:
            missing, nodes, pieces = self._piece(band, targets)
            if best is None or missing < best[0]:
                best = (missing, band, nodes, pieces)
            if missing == 0:
                break
        return _Stripe((lo, hi), best[1], best[2], targets, pieces=best[3])

    def _forced(self, stripe: _Stripe) -> np.ndarray:
        """The stripe's forced poses: the only vertex of the stripe covering some target."""
        hw = self.lg.width * self.lg.height
        fp = self.lg.footprint[stripe.nodes]  # (V, 4)
        hits = np.zeros((len(stripe.nodes), hw), dtype=bool)
        hits[np.repeat(np.arange(len(stripe.nodes)), 4), fp.ravel()] = True
        hits = hits[:, stripe.targets]
        lonely = hits.sum(axis=0) == 1
        return stripe.nodes[np.flatnonzero(hits[:, lonely].any(axis=1))]

    def _regions(self, stripe: _Stripe) -> None:
        w, rc = self.lg.width, self.region_columns
        forced = self._forced(stripe) if self.paper else None
        if self.paper:  # cut only at forced poses: blocks start at their columns, along the sweep
            edges = [c for c in sorted(set(self.bx[forced].tolist())) if 0 < c < w]
            if stripe.direction < 0:
                edges = [c + 1 for c in edges if c + 1 < w]
            bounds = [0] + sorted(set(edges)) + [w]
            blocks = [(a, b) for a, b in zip(bounds[:-1], bounds[1:]) if b > a]
        else:
            blocks = [(c, min(c + rc, w)) for c in range(0, w, rc)]
        if stripe.direction < 0:
            blocks = blocks[::-1] if self.paper else [(w - c1, w - c0) for c0, c1 in blocks]
        bx = self.bx[stripe.nodes]
        merged, cuts = [blocks[0]], []
        for block in blocks[1:]:
            column = block[0] if stripe.direction > 0 else block[1] - 1
            ports = stripe.nodes[bx == column]
            if self.paper:
                ports = ports[np.isin(ports, forced)]
            if len(ports):
                cuts.append(ports)
                merged.append(block)
            else:  # no vertex to cut at: this block joins the previous one
                c0, c1 = merged[-1]
                merged[-1] = (min(c0, block[0]), max(c1, block[1]))
        stripe.blocks, stripe.cuts = merged, cuts

    def _ports(self, stripe: _Stripe, layer: int, end: int, toward: int) -> list[int]:
        """Per connected piece of the stripe, the layer's vertex at the x end ``end`` (+1: max x), y
        extreme ``toward`` (+1: max y)."""
        hw = self.lg.width * self.lg.height
        ports = []
        for piece in stripe.pieces:
            nodes = piece[piece // hw == layer]
            if len(nodes):
                key = np.lexsort((-toward * self.by[nodes], -end * self.bx[nodes]))
                ports.append(int(nodes[key[0]]))
        return ports

    def _translations(self, layer: int, rows: tuple[int, int]):
        hw = self.lg.width * self.lg.height
        ids = np.arange(layer * hw, (layer + 1) * hw)
        keep = ids[self.reach[ids] & (self.ylo[ids] >= rows[0]) & (self.yhi[ids] < rows[1])]
        return keep, self.lg.matrix[keep][:, keep]

    # --- regions ------------------------------------------------------------------------------
    def _problem(self, s: int, b: int, entry: int, exits: list[int]):
        """The region problem of block b of stripe s from ``entry``: (nodes, Region, memo key)."""
        key = (s, b, entry)
        if key in self.problems:
            return self.problems[key]
        stripe, lg = self.stripes[s], self.lg
        c0, c1 = stripe.blocks[b]
        xs = [self.bx[entry]] + [self.bx[e] for e in exits if e >= 0]
        margin = lg.width if self.paper else WINDOW_MARGIN  # the paper's regions: the whole stripe
        x0 = min(c0, *xs) - margin
        x1 = max(c1 - 1, *xs) + margin
        nodes = stripe.nodes[(self.bx[stripe.nodes] >= x0) & (self.bx[stripe.nodes] <= x1)]
        if entry not in set(nodes.tolist()):
            nodes = np.union1d(nodes, [entry])
        sub = lg.matrix[nodes][:, nodes]
        _, labels = connected_components(sub, directed=False)
        at = int(np.searchsorted(nodes, entry))
        nodes = nodes[labels == labels[at]]
        sub = lg.matrix[nodes][:, nodes].tocsr()
        sub.sort_indices()
        tx = stripe.targets % lg.width
        targets = stripe.targets[(tx >= c0) & (tx < c1)]
        fp = lg.footprint[nodes]  # (V, 4)
        reachable_targets = targets[np.isin(targets, fp)]
        bit_of = {int(c): t for t, c in enumerate(reachable_targets.tolist())}  # sorted by (y, x)
        bits = tuple(sum(1 << bit_of[c] for c in set(row) if c in bit_of) for row in fp.tolist())
        full = (1 << len(bit_of)) - 1
        width = x1 - x0 + 1
        band_lo = stripe.band[0]
        rel = (nodes // (lg.width * lg.height)) * 10**6 + (self.by[nodes] - band_lo) * width + (self.bx[nodes] - x0)
        memo_key = (width, rel.tobytes(), sub.indptr.tobytes(), sub.indices.tobytes(), sub.data.tobytes(), bits,
                    stripe.direction if self.paper else 0)  # the paper's search orders its moves by the sweep
        dist, pred = dijkstra(sub, return_predecessors=True)
        adjacency = tuple(
            tuple(zip(sub.indices[sub.indptr[v]:sub.indptr[v + 1]].tolist(),
                      sub.data[sub.indptr[v]:sub.indptr[v + 1]].astype(int).tolist()))
            for v in range(len(nodes)))
        progress = tuple((stripe.direction * self.bx[nodes]).tolist())
        target_progress = tuple((stripe.direction * (reachable_targets % lg.width)).tolist())
        region = Region(adjacency, bits, full, dist, pred, progress, target_progress)
        self.problems[key] = (nodes, region, memo_key)
        return self.problems[key]

    def region_cost(self, s: int, b: int, entry: int, exit: int, exits: list[int]) -> float | None:
        """Cost of block b of stripe s from entry to exit (−1: a free end), None if impossible."""
        key = (s, b, entry, exit)
        if key not in self.results:
            nodes, region, memo_key = self._problem(s, b, entry, exits)
            local = {int(v): i for i, v in enumerate(nodes)}
            if exit >= 0 and exit not in local:
                self.results[key] = None
                return None
            e_local, x_local = local[entry], (local[exit] if exit >= 0 else None)
            full_key = (memo_key, e_local, x_local)
            if self.use_memo and full_key in self.memo:
                self.stats["memo_hits"] += 1
                result = self.memo[full_key]
            else:
                if self.deadline is not None and time.perf_counter() > self.deadline:
                    self.time_limited = True
                    result = greedy_walk(region, e_local, x_local)
                else:
                    search = search_inserting if self.paper else search_region
                    result = search(region, e_local, x_local, gain=self.lg.gain, budget=self.budget)
                self.stats["regions"] += 1
                if result is not None:
                    self.stats["optimal"] += bool(result.optimal)
                    self.stats["nodes"] += result.nodes
                self.memo[full_key] = result
            self.results[key] = None if result is None else (result.cost, [int(nodes[v]) for v in result.path])
        found = self.results[key]
        return None if found is None else found[0]

    # --- the DAG ------------------------------------------------------------------------------
    def dag(self) -> nx.DiGraph:
        g = nx.DiGraph()
        lg, last = self.lg, len(self.stripes) - 1
        first = self.stripes[0]
        if self.start in set(first.nodes.tolist()):
            entries = [self.start]
            g.add_edge("S", (0, -1, self.start), kind="fixed", cost=0, path=[self.start])
        else:
            entries = []
            for layer in range(lg.n_layers):
                for port in self._ports(first, layer, -first.direction, -1):
                    cost, path = shortest_path(lg, self.start, port)
                    if math.isfinite(cost):
                        entries.append(port)
                        g.add_edge("S", (0, -1, port), kind="fixed", cost=cost, path=path)
        for s, stripe in enumerate(self.stripes):
            levels = [entries] + [c.tolist() for c in stripe.cuts]
            if s < last:
                nxt = self.stripes[s + 1]
                exits, next_entries = [], []
                rows = (min(stripe.band[0], nxt.band[0]), max(stripe.band[1], nxt.band[1]))
                for layer in range(lg.n_layers):
                    outs = self._ports(stripe, layer, stripe.direction, 1)
                    intos = self._ports(nxt, layer, stripe.direction, -1)
                    if not outs or not intos:
                        continue
                    keep, matrix = self._translations(layer, rows)
                    for out in outs:
                        for into in intos:
                            cost, path = shortest_path(lg, int(np.searchsorted(keep, out)),
                                                       int(np.searchsorted(keep, into)), matrix)
                            if math.isfinite(cost):
                                exits.append(out)
                                next_entries.append(into)
                                g.add_edge((s, len(levels) - 1, out), (s + 1, -1, into), kind="fixed", cost=cost,
                                           path=[int(keep[v]) for v in path])
                exits, entries = list(dict.fromkeys(exits)), list(dict.fromkeys(next_entries))
            elif self.goal is None:
                exits = [-1]
                g.add_edge((s, len(levels) - 1, -1), "G", kind="fixed", cost=0, path=[])
            elif self.goal in set(stripe.nodes.tolist()):
                exits = [self.goal]
                g.add_edge((s, len(levels) - 1, self.goal), "G", kind="fixed", cost=0, path=[self.goal])
            else:
                exits = []
                for layer in range(lg.n_layers):
                    for out in self._ports(stripe, layer, stripe.direction, 1):
                        cost, path = shortest_path(lg, out, self.goal)
                        if math.isfinite(cost):
                            exits.append(out)
                            g.add_edge((s, len(levels) - 1, out), "G", kind="fixed", cost=cost, path=path)
            levels.append(exits)
            for b in range(len(stripe.blocks)):
                for p in levels[b]:
                    for q in levels[b + 1]:
                        g.add_edge((s, b - 1, p), (s, b, q), kind="region", block=(s, b), exits=levels[b + 1])
        return g

    def plan(self) -> StripeOutcome:
        g = self.dag()

        def weight(u, v, data):
            if data["kind"] == "fixed":
                return data["cost"]
            s, b = data["block"]
            return self.region_cost(s, b, u[2], v[2], data["exits"])

        info: dict = {"dag_nodes": g.number_of_nodes(), "dag_edges": g.number_of_edges()}
        try:
            dag_cost, dag_path = nx.single_source_dijkstra(g, "S", "G", weight=weight) if "S" in g and "G" in g \
                else (None, None)
        except nx.NetworkXNoPath:
            dag_cost, dag_path = None, None
        path, transit = [self.start], 0
        if dag_path is None:
            info["dag"] = "no path: the whole map is covered by the mop-up walk"
            return self._outcome(path, None, 0, info)
        for u, v in zip(dag_path[:-1], dag_path[1:]):
            data = g.edges[u, v]
            if data["kind"] == "fixed":
                leg = data["path"]
            else:
                s, _ = data["block"]
                cost, leg = self.results[(s, data["block"][1], u[2], v[2])]
                self.stripes[s].cost += cost
            if leg and leg[0] == path[-1]:
                leg = leg[1:]
            path += leg
        info["dag_path"] = [list(n) if isinstance(n, tuple) else n for n in dag_path]
        return self._outcome(path, int(dag_cost), transit, info)

    def _outcome(self, path, dag_cost, transit, info) -> StripeOutcome:
        details = [{"rows": list(st.own), "band": list(st.band),
                    "borrowed": (st.band[1] - st.band[0]) - (st.own[1] - st.own[0]),
                    "cost": st.cost, "regions": len(st.blocks), "direction": st.direction,
                    "cuts": [b[0] if st.direction > 0 else b[1] for b in st.blocks[1:]]} for st in self.stripes]
        return StripeOutcome(path, dag_cost, transit, details, self.stats["regions"], self.stats["optimal"],
                             self.stats["memo_hits"], self.stats["nodes"], self.time_limited, info)


def plan_stripes(lg: LayerGraph, cov: Coverability, start: int, goal: int | None, widths, *, region_columns: int,
                 budget: int, deadline: float | None, memo: bool = True, paper: bool = False) -> StripeOutcome:
    """The stripes' vertex path from ``start`` (to ``goal``, or a free end) along the auxiliary DAG's
    shortest path; the mop-up and the return to the goal are the caller's."""
    return _Planner(lg, cov, start, goal, widths, region_columns=region_columns, budget=budget, deadline=deadline,
                    memo=memo, paper=paper).plan()
