"""Cheng et al. 2019's stripe coverage (§III–IV): stripes, their pieces, regions and one auxiliary DAG.

The paper's Alg. 5 (``stripes-paper``, no addition) and ours (``stripes``) are one planner: each of our
departures is an addition of :data:`~htetro_opt.solvers.coverage._spec.STRIPES_ADDITIONS`, switched on
singly. With none, a stripe is cut at its forced poses and each region searched in the whole stripe
(``fixed-regions`` off) by the paper's depth-first search over simple paths with insertions
(``best-first`` off); a split stripe is widened (``split-sweeps`` off); the sweeps keep their greedy
order (``sweep-order`` off) and consecutive stripes are joined by cut-edges (``shortest-joins`` off); a
search past its node budget or the time limit fails and is listed (``greedy-fallback`` off); and nothing
visits what the stripes leave (``mopup`` off, the caller's). The paragraphs below are our readings of the
paper with every addition on, each naming the addition a reading belongs to.

Our reading of the paper, where it is ambiguous or contradicts itself:

- **Stripes** (Def. 6–7) are bands of rows stacked from y = 0. A vertex belongs to stripe k when its
  whole footprint lies in k's rows (Def. 6 uses B2's cell; with footprints, a stripe's cost does not
  depend on its neighbours).
- **Pieces.** A wall or a piece of furniture splits a stripe's vertices into connected pieces (and
  at the map's top edge the vertical I cannot switch to the O). Pieces covering the same targets are
  alternatives of one *sweep* (each entered by its own ports); a piece covering targets no larger
  piece covers is a sweep of its own. Each sweep is one vertex chain of the DAG (ports, regions,
  ports), consecutive sweeps joined by transit legs: shortest paths in the workspace graph (the
  paper's variant joins consecutive stripes by its cut-edges, one layer through both bands, Def. 9,
  where they exist). The sweeps are taken greedily, each the one whose entry is nearest the last
  one's exit, in either direction (ties: the lower stripe, the direction opposite to the last): on a
  map without splits this is the paper's boustrophedon of stripes (+x, −x, …); a room behind a
  doorway is covered whole before the robot goes back through it. Up to :data:`ORDER_SWEEPS`
  sweeps, the default variant (``sweep-order``) then improves that order by moving or reversing one sweep at a time
  while the whole DAG's cost drops (coverage_16x16 {vI, hI}: 190 → 173 commands).
- **Widening** (Alg. 5 l. 14): when some of a stripe's targets lie under no vertex of its band, rows
  are borrowed one at a time, the previous stripe's first, at most as many as the stripe has (the
  band that leaves fewest out wins, then the narrowest). The paper also widens a stripe whose exit
  is unreachable (a split stripe) until one piece covers it; our default variant plans both ways,
  split stripes swept piece by piece or widened, and keeps the cheaper plan (:func:`plan_stripes`).
  A sweep's targets stay its own rows' cells.
- **Ports and joins** (Def. 8–9): per piece and layer, the vertices at the sweep's x end with the
  lowest and the highest y are its ports (entry at the start end, exit at the far end). With
  ``ends="both"`` every sweep may be left at either end: the DAG holds it in both directions and,
  in the default variant, folded (out for the lower half of its rows, back for the upper half), so
  an O in a 4-row band may finish where it began.
- **Regions** (§IV-B): each sweep is cut every ``region_columns`` columns along its direction, on
  two staggered grids (:data:`CUT_OFFSETS`), each a chain of the DAG between the sweep's ports; the
  ports at a cut are the sweep's vertices with B2 in the cut column (a cut without any is dropped).
  A region may use the sweep's vertices with B2 up to 3 columns outside it and must cover the targets
  in its columns reachable from its entry in that window; the rest is left to the mop-up.
- **One DAG** (eq. 8, typos fixed): start, ports, cuts, joins and goal are the nodes of one
  directed graph (:class:`_Dag`: networkx's DiGraph and Dijkstra, step for step, without their
  overhead); a region edge costs its search's cost (``_rbt``), computed lazily by the Dijkstra's
  weight callable and memoised by the region's content (its window
  of vertices and edges relative to the window, targets, entry and exit), not by a cell (Alg. 1's
  ``WT`` keys by the vertex's cell only, which mixes different costs).
- **Start, goal, mop-up** (``mopup``): the first sweep is in the lowest stripe (the one holding the start, else
  the nearest); a start outside it reaches its entry ports (a goal outside the last sweep is reached
  from its exit ports) by shortest paths; without a goal the plan ends where the last region does.
  Cells the sweeps leave uncovered are visited afterwards (mop-up: nearest-first, then re-ordered by
  2-opt and Or-opt over exact leg costs when that is cheaper), and the plan then returns to the goal
  if there is one. If the DAG has no path at all, the whole map is covered by the
  mop-up walk from the start.
"""

from __future__ import annotations

import hashlib
import heapq
import itertools
import math
import time
from dataclasses import dataclass, field

import numpy as np
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import connected_components, dijkstra

from htetro_opt._validation import check_int
from htetro_opt.errors import ParameterError
from htetro_opt.solvers.coverage._layers import LayerGraph
from htetro_opt.solvers.coverage._rbt import (LazyDistances, Region, RegionResult, greedy_walk, search_inserting,
                                              search_region)
from htetro_opt.solvers.coverage._result import Coverability
from htetro_opt.solvers.coverage._spec import STRIPES_ADDITIONS

__all__ = ["stripe_widths", "plan_stripes", "StripeOutcome", "shortest_path", "mop_up", "WINDOW_MARGIN", "CUT_OFFSETS"]

WINDOW_MARGIN = 3
"""Columns a region may use beyond its own on either side (B2's column)."""

CUT_OFFSETS = (0.0, 0.5)
"""The default variant's cut grids, as fractions of ``region_columns``: cuts every
``region_columns`` columns from the sweep's start, and that grid shifted by half a region. Both are
chains of the DAG between the sweep's ports, so each sweep takes the cheaper (a superset of one grid:
the DAG's path never costs more); a cut that happens to fall across a sweep's cheapest turn costs
commands (coverage_16x7, {O, hI}: 90 with one grid, 88 with both; indoor_room, {O, vI, hI}: 4,832
and 4,810), for about twice the region searches."""

ORDER_SWEEPS = 12
"""Up to this many sweeps, the greedy order of the sweeps is improved by moves checked on the whole
DAG (:meth:`_Planner._improve_order`); beyond, each try's DAG solve costs too much and the greedy
order stands (on a map without splits it is the boustrophedon of stripes)."""

WINDOWS_KEPT = 192
"""Region windows whose problems (each with its all-pairs distances and per-exit tables, ~450 KB for 130
vertices) are kept at
once, the oldest dropped first: the DAG's Dijkstra prices the sweeps roughly in chain order, so a dropped
window is seldom asked for again (it is then rebuilt: the same problem). Without the bound a 256 x 256
map of {O, vI, hI} held 4.7 GB."""

ORDER_TRIES = 300
"""DAG solves the order's improvement may spend."""

DROP_PENALTY = 1_000_000
"""DAG weight of a target a region leaves to the mop-up (it cannot reach it in its window from its
entry): more than any plan's commands, so the DAG's path leaves as few as it can and only then
costs least. Without it, a chain that skips targets looks cheaper than it is (coverage_16x7 in one
7-row stripe, {O, hI}: 71 commands of DAG path, then 15 of mop-up, against 78 covering all)."""

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
class _Sweep:
    """One chain of the DAG: a stripe's piece (or its alternative pieces), swept along one direction."""

    stripe: int  # the stripe's index, bottom up
    own: tuple[int, int]  # the stripe's own rows [low, high)
    band: tuple[int, int]  # rows with the borrowed ones
    pieces: list  # alternative connected pieces covering the same targets, each its vertices
    nodes: np.ndarray  # their union
    targets: np.ndarray  # flat coverable cells of the stripe's own rows this sweep must cover
    direction: int = 1  # +1: sweep +x, −1: −x
    blocks: list = field(default_factory=list)  # region columns [c0, c1) in sweep order (the plan's layout)
    cuts: list = field(default_factory=list)  # ports (vertices) at each cut between blocks
    layouts: dict = field(default_factory=dict)  # (direction, offset, fold) -> (blocks, cuts, passes): the DAG's chains
    cost: int = 0
    folded: bool = False  # the DAG's path takes the folded chain (out and back, ``ends="both"``)
    key: int = 0  # unique per sweep: region searches are cached by it


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
    failed: dict = field(default_factory=dict)  # region key -> the failed search (JSON-ready), greedy-fallback off


def shortest_path(lg: LayerGraph, source: int, target: int, matrix=None) -> tuple[float, list[int]]:
    """Cost and vertices of the cheapest path source → target in the workspace graph (or ``matrix``)."""
    dist, pred = dijkstra(lg.matrix if matrix is None else matrix, indices=source, return_predecessors=True)
    if not math.isfinite(dist[target]):
        return math.inf, []
    return float(dist[target]), _walk_back(pred, source, target)


def _walk_back(pred, source: int, target: int) -> list[int]:
    path = [target]
    while path[-1] != source:
        path.append(int(pred[path[-1]]))
    return path[::-1]


def _nearest_first(lg: LayerGraph, path: list[int], target: np.ndarray, reachable: np.ndarray,
                   covered: np.ndarray, deadline: float | None = None) -> tuple[list[int], list[int]]:
    """Extend from ``path[-1]``: each time to the nearest vertex covering an uncovered target cell
    (ties: the lower vertex number), stopping early past ``deadline``. Returns (the added vertices, the
    vertices gone to). Updates ``covered``."""
    added: list[int] = []
    goals: list[int] = []
    cur = path[-1]
    while (target & ~covered).any():
        if deadline is not None and time.perf_counter() > deadline:
            break
        useful = reachable & (target & ~covered)[lg.footprint].any(axis=1)
        dist, pred = dijkstra(lg.matrix, indices=cur, return_predecessors=True)
        cost = np.where(useful, dist, np.inf)
        goal = int(np.argmin(cost))
        if not math.isfinite(cost[goal]):
            break  # cannot happen for coverable cells: they are under reachable vertices
        leg = _walk_back(pred, cur, goal)[1:]
        covered[lg.footprint[leg].ravel()] = True
        added += leg
        goals.append(goal)
        cur = goal
    return added, goals


def mop_up(lg: LayerGraph, path: list[int], coverable: np.ndarray, reachable: np.ndarray, *,
           order: str = "sequenced", goal: int | None = None, deadline: float | None = None,
           cut: dict | None = None) -> list[int]:
    """Extend a vertex path until every coverable cell is under a visited footprint.

    ``"nearest"``: each time to the nearest vertex covering an uncovered cell (ties: the lower
    vertex number). ``"sequenced"`` (the default): the vertices that walk goes to, re-ordered as an
    open path from ``path[-1]`` by 2-opt and Or-opt over the exact leg costs between them
    (:func:`~htetro_opt.solvers.sequencing.improve`, deterministic, from the nearest-first order),
    driven by shortest legs, skipping a vertex whose cells are covered by then and finishing
    nearest-first if the new legs left a cell; the cheaper of the two walks is kept, counting the
    return to ``goal`` if there is one (ties: the nearest-first one), so the sequenced mop-up never
    costs more.

    ``deadline`` (``time.perf_counter()`` seconds): the nearest-first walk stops there, leaving cells
    uncovered, and the sequencing is skipped (the nearest-first walk kept) when it would not end by
    then (about twice the nearest-first walk's time: its legs' searches, then the walk along the new
    order); ``cut`` then records what was cut (``mopup_stopped``, ``mopup_sequencing_skipped``)."""
    target = coverable.reshape(-1)
    base = np.zeros(lg.width * lg.height, dtype=bool)
    base[lg.footprint[path].ravel()] = True
    began = time.perf_counter()
    covered = base.copy()
    added, goals = _nearest_first(lg, path, target, reachable, covered, deadline)
    left = int((target & ~covered).sum())
    if left and cut is not None:
        cut["mopup_stopped"] = True
    if order == "nearest" or len(goals) < 3:  # two waypoints have one order from a fixed start
        return added
    if deadline is not None and (left or time.perf_counter() + 2 * (time.perf_counter() - began) > deadline):
        if cut is not None:
            cut["mopup_sequencing_skipped"] = True
        return added
    nodes = [path[-1]] + goals
    # the legs between them, 64 sources at a time: all at once held len(nodes) rows of the whole graph
    legs = np.vstack([dijkstra(lg.matrix, indices=nodes[i:i + 64])[:, nodes] for i in range(0, len(nodes), 64)])
    from htetro_opt.solvers.sequencing import improve

    better = improve(np.maximum(legs, legs.T), np.arange(len(nodes)), fixed_start=True)
    if better.tolist() == list(range(len(nodes))):
        return added
    covered, cur, walk = base.copy(), path[-1], []
    for i in better.tolist()[1:]:
        if deadline is not None and time.perf_counter() > deadline:  # the nearest-first walk covers them all
            if cut is not None:
                cut["mopup_sequencing_skipped"] = True
            return added
        goal_i = nodes[i]
        if not (target & ~covered)[lg.footprint[goal_i]].any():
            continue
        _, leg = shortest_path(lg, cur, goal_i)
        covered[lg.footprint[leg].ravel()] = True
        walk += leg[1:]
        cur = goal_i
    rest, _ = _nearest_first(lg, [cur], target, reachable, covered)
    walk += rest
    def cost(w: list[int]) -> float:
        end = ([path[-1]] + w)[-1]
        back = 0.0 if goal is None else shortest_path(lg, end, goal)[0]
        return len(lg.commands_of([path[-1]] + w)) + back

    return walk if cost(walk) < cost(added) else added


class _RegionEdge(tuple):
    """A region edge's data, (sweep, chain, block, exits) read by name as the fixed edges' dicts are: a tuple
    of four is ~100 bytes against a dict's ~230, and a 128 x 128 map's DAG has ~210,000 of them."""

    __slots__ = ()
    _AT = {"sweep": 0, "layout": 1, "block": 2, "exits": 3}

    def __getitem__(self, key):
        if key == "kind":
            return "region"
        return tuple.__getitem__(self, self._AT[key] if isinstance(key, str) else key)


class _Dag:
    """The auxiliary DAG: successors in insertion order, each edge's data a dict (networkx's DiGraph
    interface, as far as the planner uses it).

    Hand-written because the DAG is rebuilt for every order the sweeps' improvement tries (159 DAGs on
    a random 16 x 16 map of {O, vI, hI}) and ``networkx.DiGraph.add_edge`` and ``single_source_dijkstra``
    were then half the planner's time; :meth:`shortest_path` is networkx's Dijkstra step for step (the
    same heap of (distance, insertion count, node), the same relaxation order and first-found
    predecessor), so the path it picks among equal ones is networkx's."""

    __slots__ = ("adj", "edge_count", "stopped", "expand", "built")

    def __init__(self) -> None:
        self.adj: dict = {}
        self.edge_count = 0
        self.stopped = False  # the last shortest_path was stopped (``stop``) before reaching its target
        self.expand = None  # expand(self, s): add sweep s's part, called when an entry port ("in", s, v) is settled
        self.built: set = set()

    def _successors(self, u, v) -> dict:
        """``u``'s successors, both nodes added first if new (in insertion order, as networkx)."""
        adj = self.adj
        succ = adj.get(u)
        if succ is None:
            succ = adj[u] = {}
        if v not in adj:
            adj[v] = {}
        return succ

    def add_edge(self, u, v, **data) -> None:
        succ = self._successors(u, v)
        old = succ.get(v)
        if old is None:
            succ[v] = data
            self.edge_count += 1
        else:  # networkx updates an existing edge's data
            old.update(data)

    def add_region(self, u, v, data: _RegionEdge) -> None:
        """A region edge (never added twice: its tail names its chain and block)."""
        succ = self._successors(u, v)
        if v not in succ:
            self.edge_count += 1
        succ[v] = data

    def has_node(self, n) -> bool:
        return n in self.adj

    __contains__ = has_node

    def number_of_nodes(self) -> int:
        return len(self.adj)

    def number_of_edges(self) -> int:
        return self.edge_count

    def shortest_path(self, source, target, weight, stop=None, progress=None) -> tuple[float, list] | None:
        """(distance, nodes) of the cheapest source → target path, ``weight(u, v, data)`` giving each
        edge's cost (None: hidden); None when there is none.

        ``stop()`` (checked every 32 nodes settled) ends the search early: the path returned is then the
        cheapest to the settled node of greatest ``progress(node)`` (ties: the nearer, then the first
        settled), and :attr:`stopped` is set. Without a stop the search is networkx's, step for step."""
        adj = self.adj
        dist: dict = {}
        seen = {source: 0}
        pred: dict = {}
        c = itertools.count()
        fringe = [(0, next(c), source)]
        self.stopped = False
        settled = 0
        while fringe:
            d, _, v = heapq.heappop(fringe)
            if v in dist:
                continue
            dist[v] = d
            if v == target:
                break
            if self.expand is not None and type(v) is tuple and v[0] == "in" and v[1] not in self.built:
                self.expand(self, v[1])
            settled += 1
            if stop is not None and settled % 32 == 0 and stop():
                self.stopped = True
                break
            for u, e in adj[v].items():
                cost = weight(v, u, e)
                if cost is None:
                    continue
                du = d + cost
                if u in dist:
                    if du < dist[u]:
                        raise ValueError("Contradictory paths found:", "negative weights?")
                elif u not in seen or du < seen[u]:
                    seen[u] = du
                    heapq.heappush(fringe, (du, next(c), u))
                    pred[u] = v
        if self.stopped:  # dicts keep insertion order: max() keeps the first settled of equal keys
            target = max(dist, key=lambda n: (progress(n), -dist[n]))
        elif target not in dist:
            return None
        path = [target]
        while path[-1] in pred:
            path.append(pred[path[-1]])
        return dist[target], path[::-1]


class _Planner:
    def __init__(self, lg: LayerGraph, cov: Coverability, start: int, goal: int | None, widths, *,
                 region_columns: int, budget: int, deadline: float | None, memo: bool,
                 additions=tuple(STRIPES_ADDITIONS), widening: str = "split", ends: str = "sweep",
                 shared_memo: dict | None = None, mopup: str = "sequenced") -> None:
        self.lg, self.cov, self.start, self.goal, self.ends = lg, cov, start, goal, ends
        on = set(additions)
        # each addition of ours, on or off (STRIPES_ADDITIONS); all off: the paper's Alg. 5
        self.fixed, self.best_first = "fixed-regions" in on, "best-first" in on
        self.fallback, self.split_sweeps = "greedy-fallback" in on, "split-sweeps" in on
        self.reorder, self.shortest = "sweep-order" in on, "shortest-joins" in on
        self.mopup = mopup if "mopup" in on else None
        self.failed: dict = {}  # region searches that spent their budget without greedy-fallback, by region
        self.region_columns, self.budget, self.deadline, self.use_memo = region_columns, budget, deadline, memo
        n = lg.n_nodes
        ids = np.arange(n)
        self.bx = ids % lg.width
        self.by = (ids // lg.width) % lg.height
        self.ylo, self.yhi = lg.rows
        self.reach = cov.reachable
        self.coverable = cov.coverable.reshape(-1)
        self.memo: dict = {} if shared_memo is None else shared_memo  # keyed by content: safe to share
        self._from: dict | None = None  # shortest paths from a port, (dist, pred), kept while the order is improved
        self.problems: dict = {}  # (sweep, chain, block, entry) -> its region problem
        self.windows: dict = {}  # (sweep, chain, block, window) -> its vertices, pieces, graph and problems
        self._sweep_edges: dict = {}  # sweep -> the workspace graph's edges among its vertices
        self.results: dict = {}
        self.stats = {"regions": 0, "optimal": 0, "memo_hits": 0, "nodes": 0}
        self.time_limited = False
        # the time limit (see _past_cutoff): region problems built and their seconds, the DAG's blocks not built yet
        self.began = time.perf_counter()
        self._build_times: list = []
        self._per_build, self._built, self._blocks, self._unbuilt = 0.001, set(), {}, 0
        self._unpriced = 0  # region edges of the sweeps' first chains in blocks not built yet
        self.cut = {"greedy_regions": 0, "hidden_edges": 0, "failed_regions": 0}  # what the time limit cut
        self._keys = 0
        lows = np.cumsum((0,) + tuple(widths))
        self.bands: list[tuple[tuple[int, int], tuple[int, int]]] = []  # (own rows, band) per stripe kept
        self.widening, self.choices = widening, 0  # stripes where splitting and widening both apply
        sweeps: list[_Sweep] = []
        for lo, hi in zip(lows[:-1], lows[1:]):
            own = (int(lo), int(hi))
            options = self._widen(*own)
            self.choices += len(options) > 1
            band, found = options[0] if widening == "split" else options[-1]
            mine = self._sweeps(len(self.bands), own, band, found)
            if mine:
                sweeps += mine
                self.bands.append((own, band))
        self.sweeps = self._order(sweeps)
        for sweep in self.sweeps:
            self._regions(sweep)

    # --- stripes and their pieces ---------------------------------------------------------------
    def _split(self, band: tuple[int, int], targets: np.ndarray) -> tuple[int, list]:
        """The band's sweeps: (targets no piece covers, [(alternative pieces, their targets)]).

        The band's vertices fall into connected pieces (a wall or a piece of furniture splits a stripe;
        at the map's top edge the vertical I cannot switch to the O). Pieces covering the same targets
        are alternatives of one sweep (each entered by its own layer's port); a piece covering targets
        no larger piece covers is a sweep of its own, for its new targets; the rest are dropped.
        """
        lo, hi = band
        idx = np.flatnonzero(self.reach & (self.ylo >= lo) & (self.yhi < hi))
        if not len(idx) or not len(targets):
            return len(targets), []
        n, labels = connected_components(self.lg.matrix[idx][:, idx], directed=False)
        where = np.full(self.lg.width * self.lg.height, -1)
        where[targets] = np.arange(len(targets))
        hit = where[self.lg.footprint[idx]]  # (V, 4) target index or −1
        masks = np.zeros((n, len(targets)), dtype=bool)
        rows = np.repeat(labels, 4)
        keep = hit.ravel() >= 0
        masks[rows[keep], hit.ravel()[keep]] = True
        counts = masks.sum(axis=1)
        groups: list[tuple[list[int], np.ndarray, np.ndarray]] = []  # (labels, mask, new targets)
        claimed = np.zeros(len(targets), dtype=bool)
        for c in np.lexsort((np.arange(n), -counts)).tolist():
            if counts[c] == 0:
                break
            same = next((g for g in groups if (g[1] == masks[c]).all()), None)
            if same is not None:
                same[0].append(c)
            elif (masks[c] & ~claimed).any():
                groups.append(([c], masks[c], masks[c] & ~claimed))
                claimed |= masks[c]
        found = [([idx[labels == c] for c in labs], targets[new]) for labs, _, new in groups]
        return int((~claimed).sum()), found

    def _sweeps(self, stripe: int, own, band, found) -> list[_Sweep]:
        made = []
        for pieces, targets in found:
            self._keys += 1
            made.append(_Sweep(stripe, own, band, pieces, np.unique(np.concatenate(pieces)), targets, key=self._keys))
        return made

    def _widen(self, lo: int, hi: int) -> list:
        """The stripe's candidate (band, sweeps), cheapest first to try.

        Widening (Alg. 5 l. 14): rows are borrowed one at a time (the previous stripe's first), at
        most as many as the stripe has. Two reasons to borrow: targets under no vertex of the band
        (the band leaving fewest out wins, then the narrowest), and the stripe split into pieces (the
        first band with one piece covering all its targets). The first always applies; the second is
        the paper's ("the exit is unreachable"); our default variant also sweeps the split stripe's
        pieces apart, joined by transit legs, and keeps the cheaper plan (:func:`plan_stripes`).
        Returns [split, joined] when they differ, else the one candidate.
        """
        cells = np.arange(lo * self.lg.width, hi * self.lg.width)
        targets = cells[self.coverable[cells]]
        bands, low, high = [(lo, hi)], lo, hi
        for _ in range(hi - lo):
            if low > 0:
                low -= 1
            elif high < self.lg.height:
                high += 1
            else:
                break
            bands.append((low, high))
        best, joined = None, None
        for band in bands:
            missing, found = self._split(band, targets)
            if best is None or missing < best[0]:
                best = (missing, band, found)
            if len(found) == 1 and missing == 0:
                joined = (band, found)
                break
        if joined is None:
            return [best[1:]]
        if not self.split_sweeps or joined[0] == best[1]:
            return [joined]
        return [best[1:], joined]

    def _forced(self, sweep: _Sweep) -> np.ndarray:
        """The sweep's forced poses: the only vertex of the sweep covering some target."""
        hw = self.lg.width * self.lg.height
        fp = self.lg.footprint[sweep.nodes]  # (V, 4)
        hits = np.zeros((len(sweep.nodes), hw), dtype=bool)
        hits[np.repeat(np.arange(len(sweep.nodes)), 4), fp.ravel()] = True
        hits = hits[:, sweep.targets]
        lonely = hits.sum(axis=0) == 1
        return sweep.nodes[np.flatnonzero(hits[:, lonely].any(axis=1))]

    def _offsets(self) -> tuple[int, ...]:
        """Offsets of the default variant's cut grids: every ``region_columns`` columns from the
        sweep's start, and the same grid shifted by half a region (:data:`CUT_OFFSETS`)."""
        rc = self.region_columns
        return tuple(dict.fromkeys(min(rc - 1, int(f * rc)) for f in CUT_OFFSETS))

    def _regions(self, sweep: _Sweep) -> None:
        """The sweep's chains for the DAG (``sweep.layouts``), keyed ``(direction, offset, fold)``.

        Per direction (the sweep's own; both with ``ends="both"``) and cut grid (the paper's: forced
        poses; ours: every ``region_columns`` columns, at each offset of :meth:`_offsets`), a
        straight chain (fold 0) runs from the start end to the far end. With ``ends="both"`` the
        default variant adds a folded chain (fold 1) that ends where it began: out along the
        direction for the lower half of the stripe's own rows, back for the upper half, turning at
        the far end's vertices (the O in a 4-row band, one lane out and one back). Each value is
        (region columns in chain order, ports at each cut, per region (direction, own rows it must
        cover)). ``sweep.blocks``/``cuts`` start as the first chain's and become the DAG path's."""
        directions = (sweep.direction,) if self.ends == "sweep" else (sweep.direction, -sweep.direction)
        lo, hi = sweep.own
        mid = lo + (hi - lo + 1) // 2
        sweep.layouts = {}
        for d in directions:
            for offset in (self._offsets() if self.fixed else (0,)):
                blocks, cuts = self._layout(sweep, d, offset)
                chain = (blocks, cuts, [(d, (lo, hi))] * len(blocks))
                if not any(_same_chain(chain, other) for other in sweep.layouts.values()):
                    sweep.layouts[(d, offset, 0)] = chain  # a narrow sweep may give one chain twice
                if self.ends == "sweep" or not self.fixed or mid >= hi:
                    continue
                turn = np.array(self._ports(sweep, d, every=True), dtype=np.int64)
                back, back_cuts = self._layout(sweep, -d, offset)
                sweep.layouts[(d, offset, 1)] = (blocks + back, cuts + [turn] + back_cuts,
                                                  [(d, (lo, mid))] * len(blocks) + [(-d, (mid, hi))] * len(back))
        sweep.blocks, sweep.cuts = next(iter(sweep.layouts.values()))[:2]

    def _layout(self, sweep: _Sweep, direction: int, offset: int) -> tuple[list, list]:
        """Region columns [c0, c1) in sweep order and the ports at each cut, for one direction and
        (default variant) one cut grid: cuts at ``offset``, ``offset + region_columns``, … columns
        from the sweep's start."""
        w, rc = self.lg.width, self.region_columns
        forced = None if self.fixed else self._forced(sweep)
        if not self.fixed:  # the paper's: cut only at forced poses, blocks starting at their columns, along the sweep
            edges = [c for c in sorted(set(self.bx[forced].tolist())) if 0 < c < w]
            if direction < 0:
                edges = [c + 1 for c in edges if c + 1 < w]
            bounds = [0] + sorted(set(edges)) + [w]
            blocks = [(a, b) for a, b in zip(bounds[:-1], bounds[1:]) if b > a]
        else:
            bounds = sorted({0, w} | set(range(offset, w, rc)))
            blocks = [(a, b) for a, b in zip(bounds[:-1], bounds[1:])]
        if direction < 0:
            blocks = [(w - c1, w - c0) for c0, c1 in blocks] if self.fixed else blocks[::-1]
        bx = self.bx[sweep.nodes]
        merged, cuts = [blocks[0]], []
        for block in blocks[1:]:
            column = block[0] if direction > 0 else block[1] - 1
            ports = sweep.nodes[bx == column]
            if not self.fixed:
                ports = ports[np.isin(ports, forced)]
            if len(ports):
                cuts.append(ports)
                merged.append(block)
            else:  # no vertex to cut at: this block joins the previous one
                c0, c1 = merged[-1]
                merged[-1] = (min(c0, block[0]), max(c1, block[1]))
        return merged, cuts

    def _ports(self, sweep: _Sweep, end: int, toward: tuple[int, ...] = (-1, 1), every: bool = False) -> list[int]:
        """Per piece and layer, the vertices at the x end ``end`` (+1: max x) with the y extremes
        ``toward`` (+1: max y): the ports a sweep is entered or left by (``every``: all the
        vertices at that x, a folded chain's turn)."""
        hw = self.lg.width * self.lg.height
        ports = []
        for piece in sweep.pieces:
            for layer in range(self.lg.n_layers):
                nodes = piece[piece // hw == layer]
                if every and len(nodes):
                    far = (end * self.bx[nodes]).max()
                    ports += sorted(nodes[end * self.bx[nodes] == far].tolist())
                    continue
                for t in toward:
                    if len(nodes):
                        key = np.lexsort((-t * self.by[nodes], -end * self.bx[nodes]))
                        ports.append(int(nodes[key[0]]))
        return list(dict.fromkeys(ports))

    def _order(self, sweeps: list[_Sweep]) -> list[_Sweep]:
        """The sweeps in the order the DAG chains them, each with its direction.

        The first is in the lowest stripe: the one holding the start (swept +x), else the one whose
        entry is nearest the start. Then, greedily, the sweep (and direction) whose entry is nearest
        the last one's exit (ties: the lower stripe, the direction opposite to the last, the piece
        listed first): on a map without splits that is the boustrophedon of stripes, and pieces
        split by a wall are swept where the robot is, not in stripe order (a room behind a doorway is
        covered whole before the robot goes back through it)."""
        if not sweeps:
            return []
        matrix = self.lg.matrix
        ports = {(i, d): (self._ports(s, -d), self._ports(s, d)) for i, s in enumerate(sweeps) for d in (1, -1)}
        lowest = min(s.stripe for s in sweeps)
        holding = [i for i, s in enumerate(sweeps) if s.stripe == lowest and self.start in set(s.nodes.tolist())]
        if holding:
            here = (holding[0], 1)
        else:
            dist = dijkstra(matrix, indices=self.start)
            here = min(((i, d) for i, s in enumerate(sweeps) if s.stripe == lowest for d in (1, -1)),
                       key=lambda k: (dist[ports[k][0]].min(), -k[1], k[0]))
        order, left = [], set(range(len(sweeps)))
        while True:
            i, d = here
            sweeps[i].direction = d
            order.append(sweeps[i])
            left.discard(i)
            if not left:
                return order
            dist = self._nearest(ports[here][1], [ports[(j, e)][0] for j in left for e in (1, -1)])
            here = min(((j, e) for j in left for e in (1, -1)),
                       key=lambda k: (dist[ports[k][0]].min(), sweeps[k[0]].stripe, k[1] == d, k[0]))

    def _nearest(self, sources: list[int], targets: list[list[int]]) -> np.ndarray:
        """Distances from the nearest of ``sources``, exact up to the nearest of ``targets`` at least: the
        search bounded at 64, 256, 1,024 commands, then the whole map, stopping at the first bound within
        which a target lies (the distances within a bound are the whole search's; beyond it they are
        infinite, and no target there can be the nearest). A search over the whole map per sweep was
        quadratic in the map's size: most of the set-up's time on malaga_building."""
        ids = np.unique(np.concatenate([np.asarray(t, dtype=np.int64) for t in targets])) if targets else []
        for limit in (64, 256, 1024, np.inf):
            dist = dijkstra(self.lg.matrix, indices=sources, min_only=True, limit=limit)
            if not len(ids) or np.isfinite(dist[ids]).any():
                return dist
        return dist

    def _translations(self, layer: int, rows: tuple[int, int]):
        hw = self.lg.width * self.lg.height
        ids = np.arange(layer * hw, (layer + 1) * hw)
        keep = ids[self.reach[ids] & (self.ylo[ids] >= rows[0]) & (self.yhi[ids] < rows[1])]
        return keep, self.lg.matrix[keep][:, keep]

    # --- regions ------------------------------------------------------------------------------
    def _problem(self, stripe: _Sweep, layout: tuple[int, int], b: int, entry: int, exits: list[int],
                 light: bool = False):
        """The region problem of block b of a sweep's chain ``layout`` from ``entry``: (nodes, Region,
        memo key, targets outside the window, local number of each node). ``light`` (past a time limit):
        a problem for the greedy walk only, its shortest paths computed per source on demand, no memo key.

        The problem depends on the entry only through its window (its x widens the window where it lies
        outside the block's) and the connected piece of the window it is in, so it is built once per
        (block, window, piece) and shared by the block's entries: every entry port at a cut has the
        cut's x, and the DAG prices each block from each of them (on tiling_64x64 {O, vI, hI} this was
        the planner's second cost after the searches)."""
        key = (stripe.key, layout, b, entry)
        found = self.problems.get(key)
        if found is not None:
            return found
        lg = self.lg
        c0, c1 = stripe.layouts[layout][0][b]
        xs = [self.bx[entry]] + [self.bx[e] for e in exits if e >= 0]
        margin = WINDOW_MARGIN if self.fixed else lg.width  # the paper's regions: the whole stripe
        x0 = int(min(c0, *xs) - margin)
        x1 = int(max(c1 - 1, *xs) + margin)
        window_key = (stripe.key, layout, b, x0, x1)
        window = self.windows.get(window_key)
        began = time.perf_counter()
        if window is None:
            nodes = stripe.nodes[(self.bx[stripe.nodes] >= x0) & (self.bx[stripe.nodes] <= x1)]
            sub = self._submatrix(stripe, nodes, x0, x1)
            _, labels = connected_components(sub, directed=False)
            window = self.windows[window_key] = (nodes, labels, {}, sub)
            while len(self.windows) > WINDOWS_KEPT:  # the oldest window's problems: rebuilt if asked again
                del self.windows[next(iter(self.windows))]
        nodes, labels, pieces, sub = window
        at = int(np.searchsorted(nodes, entry))
        if at < len(nodes) and nodes[at] == entry:
            piece = int(labels[at])
        else:  # an entry outside the sweep's vertices (cannot happen for a port): its own window
            nodes = np.union1d(nodes, [entry])
            sub = lg.matrix[nodes][:, nodes].tocsr()
            sub.sort_indices()
            _, labels = connected_components(sub, directed=False)
            pieces, piece = {}, int(labels[int(np.searchsorted(nodes, entry))])
        found = pieces.get(piece)
        if found is None:
            mine = labels == piece
            if not mine.all():
                sub = sub[mine][:, mine].tocsr()
                sub.sort_indices()
            found = pieces[piece] = self._build(stripe, layout, b, nodes[mine], sub, x0, x1, light)
            self._build_times.append(time.perf_counter() - began)
            if len(self._build_times) % 16 == 0:  # the median of 16 or more: a build caught by a pause (132 ms against
                self._per_build = float(np.median(self._build_times))  # 0.6) is not the rule, nor is the first
            block = (stripe.key, layout, b)
            if block not in self._built:
                self._built.add(block)
                if block in self._blocks:
                    self._unbuilt -= 1
                    self._unpriced -= self._blocks[block]
        if len(self.problems) > WINDOWS_KEPT * 8:  # entry -> problem: a shortcut, dropped wholesale when large
            self.problems.clear()
        self.problems[key] = found
        return found

    def _submatrix(self, stripe: _Sweep, nodes: np.ndarray, x0: int, x1: int):
        """The workspace graph on a window's vertices (``nodes``, sorted: the sweep's with B2 in columns
        x0 … x1), as a CSR matrix with sorted indices: what ``lg.matrix[nodes][:, nodes]`` gives, from
        the sweep's own edges (kept per sweep) rather than by fancy-indexing the map's whole matrix,
        which cost more than the region search itself."""
        edges = self._sweep_edges.get(stripe.key)
        if edges is None:
            src, dst, cost = self.lg.edges
            inside = np.zeros(self.lg.n_nodes, dtype=bool)
            inside[stripe.nodes] = True
            keep = inside[src] & inside[dst]
            edges = self._sweep_edges[stripe.key] = (src[keep], dst[keep], cost[keep].astype(float),
                                                     self.bx[src[keep]], self.bx[dst[keep]])
        src, dst, cost, xs, xd = edges
        keep = (xs >= x0) & (xs <= x1) & (xd >= x0) & (xd <= x1)
        rows, cols = np.searchsorted(nodes, src[keep]), np.searchsorted(nodes, dst[keep])
        order = np.lexsort((cols, rows))
        n = len(nodes)
        indptr = np.zeros(n + 1, dtype=np.int32)
        np.cumsum(np.bincount(rows, minlength=n), out=indptr[1:])
        return csr_matrix((cost[keep][order], cols[order].astype(np.int32), indptr), shape=(n, n))

    def _build(self, stripe: _Sweep, layout, b: int, nodes: np.ndarray, sub, x0: int, x1: int, light: bool = False):
        """The region problem on a window's connected piece ``nodes``, ``sub`` the graph on them (see
        :meth:`_problem`)."""
        lg = self.lg
        direction, (r0, r1) = stripe.layouts[layout][2][b]
        c0, c1 = stripe.layouts[layout][0][b]
        tx, ty = stripe.targets % lg.width, stripe.targets // lg.width
        targets = stripe.targets[(tx >= c0) & (tx < c1) & (ty >= r0) & (ty < r1)]
        fp = lg.footprint[nodes]  # (V, 4)
        reachable_targets = targets[np.isin(targets, fp)]  # sorted by (y, x): bit t is the t-th
        if len(reachable_targets) <= 62:  # a vertex's bits: OR over its footprint's cells that are targets
            where = np.searchsorted(reachable_targets, fp)
            hit = reachable_targets[np.minimum(where, max(len(reachable_targets) - 1, 0))] == fp if len(
                reachable_targets) else np.zeros(fp.shape, dtype=bool)
            bits = tuple(np.bitwise_or.reduce(np.where(hit, np.left_shift(1, where, dtype=np.int64), 0),
                                              axis=1).tolist())
        else:
            bit_of = {int(c): t for t, c in enumerate(reachable_targets.tolist())}
            bits = tuple(sum(1 << bit_of[c] for c in set(row) if c in bit_of) for row in fp.tolist())
        full = (1 << len(reachable_targets)) - 1
        local = {int(v): i for i, v in enumerate(nodes.tolist())}
        if light:  # the greedy walk needs neither the adjacency nor all the pairs' distances
            paths = LazyDistances(sub)
            region = Region((), bits, full, paths.dist, paths.pred)
            return nodes, region, None, len(targets) - len(reachable_targets), local
        width = x1 - x0 + 1
        band_lo = stripe.band[0]
        rel = (nodes // (lg.width * lg.height)) * 10**6 + (self.by[nodes] - band_lo) * width + (self.bx[nodes] - x0)
        # the region's content, as a 256-bit digest: the arrays themselves (~8 KB a region) were held for every
        # region of the run, most of a large map's memory
        content = hashlib.blake2b(digest_size=32)
        for part in (np.int64(width).tobytes(), rel.tobytes(), sub.indptr.tobytes(), sub.indices.tobytes(),
                     sub.data.tobytes(), np.array(bits, dtype=np.int64).tobytes() if full >> 62 == 0 else repr(bits).encode()):
            content.update(np.int64(len(part)).tobytes())
            content.update(part)
        memo_key = (content.digest(), 0 if self.best_first else direction)  # the paper's orders its moves by the sweep
        dist, pred = dijkstra(sub, return_predecessors=True)
        indptr, indices, costs = sub.indptr.tolist(), sub.indices.tolist(), sub.data.astype(int).tolist()
        adjacency = tuple(tuple(zip(indices[indptr[v]:indptr[v + 1]], costs[indptr[v]:indptr[v + 1]]))
                          for v in range(len(nodes)))
        progress = tuple((direction * self.bx[nodes]).tolist())
        target_progress = tuple((direction * (reachable_targets % lg.width)).tolist())
        region = Region(adjacency, bits, full, dist, pred, progress, target_progress)
        return nodes, region, memo_key, len(targets) - len(reachable_targets), local

    def _past_cutoff(self) -> bool:
        """Whether the time limit has come for the region searches: the deadline less what pricing the
        DAG's blocks not built yet will take without searching, less a twentieth of the time allowed for
        what follows the DAG (the mop-up, the commands, the replay). That pricing is a light problem and
        a greedy walk per entry of each block of one chain, and a leg per edge (:meth:`_kept_late`):
        measured at about 0.7 of a full problem's build per block not built yet (both cut grids
        counted) and a fortieth of one per edge of that chain, at the seconds a build has taken so far (their median). Past it, every region edge not yet priced takes its greedy walk or is left unpriced
        (``greedy-fallback``), or fails without being built (the paper's variant), so that the plan ends
        within the limit: a region problem built past the deadline for each of ~29,000 lazily priced
        edges made a 2 s limit on tiling_64x64 {O, vI, hI} last 5.3 s."""
        if self.deadline is None:
            return False
        if self.time_limited:
            return True
        now = time.perf_counter()
        reserve = self._per_build * (0.7 * self._unbuilt + self._unpriced / 40) + 0.05 * (self.deadline - self.began)
        if now + reserve > self.deadline:
            self.time_limited = True
        return self.time_limited

    def region_cost(self, sweep: _Sweep, layout: tuple[int, int], b: int, entry: int, exit: int,
                    exits: list[int]) -> float | None:
        """DAG weight of block b of a sweep's chain ``layout`` from entry to exit (−1: a free end):
        its search's cost plus :data:`DROP_PENALTY` per target of its columns it cannot reach in its
        window from that entry (left to the mop-up); None if impossible."""
        key = (sweep.key, layout, b, entry, exit)
        if key not in self.results:
            late = self._past_cutoff()
            if late and not self.fallback:  # the paper's: a region past the time limit fails, nothing built
                self.failed[key] = self._failure(sweep, layout, b, entry, exit, RegionResult(0, (), False, 0), True)
                self.cut["failed_regions"] += 1
                self.results[key] = None
                return None
            if late and not self._kept_late(sweep, layout):
                self.cut["hidden_edges"] += 1
                self.results[key] = None
                return None
            nodes, region, memo_key, dropped, local = self._problem(sweep, layout, b, entry, exits, light=late)
            if exit >= 0 and exit not in local:
                self.results[key] = None
                return None
            e_local, x_local = local[entry], (local[exit] if exit >= 0 else None)
            full_key = (memo_key, e_local, x_local)
            # the fallback is in the key: a failed search is a result, not a walk another planner may take
            full_key = full_key + (self.fallback,)
            if memo_key is not None and self.use_memo and full_key in self.memo:
                self.stats["memo_hits"] += 1
                result, late = self.memo[full_key]
            else:
                if late:  # with greedy-fallback (above): its greedy walk, no search
                    result = greedy_walk(region, e_local, x_local)
                    self.cut["greedy_regions"] += 1
                else:
                    search = search_region if self.best_first else search_inserting
                    result = search(region, e_local, x_local, gain=self.lg.gain, budget=self.budget,
                                    fallback=self.fallback)
                self.stats["regions"] += 1
                if result is not None:
                    self.stats["optimal"] += bool(result.optimal)
                    self.stats["nodes"] += result.nodes
                if memo_key is not None:  # a light problem (past the time limit) has no content key
                    self.memo[full_key] = (result, late)
            if result is not None and result.exhausted:  # the paper's search not run to its end: the region fails
                self.failed[key] = self._failure(sweep, layout, b, entry, exit, result, late)
                result = None
            # the walk in the window's numbers, beside the window's vertices: mapped to the map's only on the
            # DAG's path (a list of the map's ints per edge held ~800 bytes an edge, 740,000 edges at 256 x 256)
            self.results[key] = None if result is None else (result.cost, (nodes, result.path),
                                                             dropped + result.missing.bit_count())
        found = self.results[key]
        return None if found is None else found[0] + DROP_PENALTY * found[2]

    def _kept_late(self, sweep: _Sweep, layout) -> bool:
        """Past the time limit (``greedy-fallback``): whether a region edge is priced by its greedy walk or
        left unpriced. Only the sweep's first chain is kept (every entry and exit of it: the walk's
        covering part is walked once per entry and shared by its exits, so an exit costs a leg), so that
        the DAG's remaining part is one chain of greedy regions rather than both cut grids' (~29,000
        edges on tiling_64x64 {O, vI, hI}, each built and walked: longer than a 2 s limit). Keeping only
        the exit nearest each walk's end was cheaper, but could leave a chain with no way through (on
        malaga_building the whole map then went to the mop-up: 217 s for a 3 s limit)."""
        return layout == next(iter(sweep.layouts))

    def _failure(self, sweep: _Sweep, layout, b: int, entry: int, exit: int, result, late: bool) -> dict:
        """A failed region search as the result lists it (JSON-ready)."""
        c0, c1 = sweep.layouts[layout][0][b]
        return {"stripe": sweep.stripe, "rows": list(sweep.own), "columns": [int(c0), int(c1)],
                "direction": int(layout[0]), "entry": self.lg.pose(entry).as_dict(),
                "exit": None if exit < 0 else self.lg.pose(exit).as_dict(),
                "reason": "time limit" if late else "node budget", "nodes": int(result.nodes)}

    # --- the DAG ------------------------------------------------------------------------------
    def _legs(self, g: _Dag, outs: list[int], intos: list[int], tail, head, a=None, b=None) -> list[int]:
        """Fixed edges from the ports ``outs`` (DAG nodes ``tail(v)``) to the ports ``intos`` (``head(v)``):
        shortest paths in the workspace graph. The paper's variant joins consecutive stripes by its
        cut-edges (translations in one layer through both bands, Def. 9) and falls back on those paths
        only where a stripe's pieces have none. Returns the ports reached."""
        reached = []
        if not self.shortest and a is not None and b.stripe == a.stripe + 1:
            rows = (min(a.band[0], b.band[0]), max(a.band[1], b.band[1]))
            hw = self.lg.width * self.lg.height
            for layer in range(self.lg.n_layers):
                ins = [v for v in intos if v // hw == layer]
                if not ins:
                    continue
                keep, matrix = self._translations(layer, rows)
                for out in (v for v in outs if v // hw == layer):
                    dist, pred = dijkstra(matrix, indices=int(np.searchsorted(keep, out)), return_predecessors=True)
                    for into in ins:
                        k = int(np.searchsorted(keep, into))
                        if math.isfinite(dist[k]):
                            path = [int(keep[v]) for v in _walk_back(pred, int(np.searchsorted(keep, out)), k)]
                            g.add_edge(tail(out), head(into), kind="fixed", cost=dist[k], path=path)
                            reached.append(into)
            if reached:
                return list(dict.fromkeys(reached))
        for out in outs:
            if self._from is None:
                # bounded first (legs join nearby ports; a search over the whole map per port was quadratic in
                # its size), the whole map only if some port lies beyond the bound
                far = max((abs(self.bx[out] - self.bx[v]) + abs(self.by[out] - self.by[v]) for v in intos), default=0)
                dist, pred = dijkstra(self.lg.matrix, indices=out, return_predecessors=True, limit=2 * far + 16)
                if not all(math.isfinite(dist[v]) for v in intos):
                    dist, pred = dijkstra(self.lg.matrix, indices=out, return_predecessors=True)
            else:  # the order's improvement builds many DAGs over the same ports
                if out not in self._from:
                    self._from[out] = dijkstra(self.lg.matrix, indices=out, return_predecessors=True)
                dist, pred = self._from[out]
            for into in intos:
                if math.isfinite(dist[into]):  # the leg walked back now: an edge holding the pred array
                    # (one of the map's size per port) made most of a large map's memory
                    g.add_edge(tail(out), head(into), kind="fixed", cost=dist[into], path=_walk_back(pred, out, into))
                    reached.append(into)
        return list(dict.fromkeys(reached))

    @staticmethod
    def _exit_side(layout: tuple[int, int, int]) -> int:
        """The x end a chain leaves its sweep by: the far end (+1: max x), or for a folded chain the one it began at."""
        return -layout[0] if layout[2] else layout[0]

    def _end_ports(self, sweep: _Sweep, side: int) -> list[int]:
        """The entry ports (side −1) or exit ports (side +1) of every chain of a sweep."""
        ends = dict.fromkeys(-k[0] if side < 0 else self._exit_side(k) for k in sweep.layouts)
        return list(dict.fromkeys(v for e in ends for v in self._ports(sweep, e)))

    def dag(self, chain: list[_Sweep], *, start: int | None, goal) -> _Dag:
        """The auxiliary DAG of a chain of sweeps: "S" (the start vertex, or every entry port of the
        first sweep at no cost when None); per sweep s its entry ports ``("in", s, v)``, the ports at
        the cuts of each of its chains ``(s, layout, b, v)`` and its exit ports ``("out", s, v)``
        (v = −1: a free end); then "G" (the goal vertex, or a free end when None). A sweep's chains
        (its cut grids and, with ``ends="both"``, both directions) run in parallel between its ports.

        Built sweep by sweep as the search gets there (:meth:`_build_sweep`, when it first settles one of
        the sweep's entry ports): each node's edges are added in the order a whole build adds them, so the
        search is the same, and a search stopped by the deadline has not built the sweeps it did not reach
        (on malaga_building the whole DAG, 162,000 region edges and a leg search per sweep, took 2 s)."""
        g = _Dag()
        self._chain = chain
        first = chain[0]
        start_inside = start is not None and start in set(first.nodes.tolist())
        if start is None:
            for v in self._end_ports(first, -1):
                g.add_edge("S", ("in", 0, v), kind="fixed", cost=0, path=[v])
        elif start_inside:
            g.add_edge("S", ("in", 0, start), kind="fixed", cost=0, path=[start])
        else:
            self._legs(g, [start], self._end_ports(first, -1), lambda v: "S", lambda v: ("in", 0, v))
        g.adj.setdefault("G", {})
        self._dag_ends = (start, start_inside, goal)
        g.expand, g.built = self._build_sweep, set()
        # the time limit's estimate (_past_cutoff): the region edges of every sweep's first chain, before any is
        # built (its end levels counted as its nearest cut's ports)
        blocks_seen: dict = {}
        for sweep in chain:
            for layout, (blocks, cuts, _) in sweep.layouts.items():
                sizes = [len(c) for c in cuts] or [2]
                sizes = [sizes[0]] + sizes + [sizes[-1]]
                for k in range(len(blocks)):
                    blocks_seen[(sweep.key, layout, k)] = sizes[k] * sizes[k + 1] * (layout == next(iter(sweep.layouts)))
        self._blocks = blocks_seen
        left = [n for block, n in blocks_seen.items() if block not in self._built]
        self._unbuilt, self._unpriced = len(left), sum(left)
        return g

    def _build_sweep(self, g: _Dag, s: int) -> None:
        """Sweep s's part of the DAG: the legs from its exit ports (to the next sweep's entry ports, or to
        "G"), then per chain the edges from its entry ports and its region edges, block by block."""
        if s in g.built:
            return
        g.built.add(s)
        chain, (start, start_inside, goal) = self._chain, self._dag_ends
        last = len(chain) - 1
        sweep = chain[s]
        goal_inside = s == last and goal is not None and goal in set(sweep.nodes.tolist())
        if s < last:
            nxt = chain[s + 1]
            self._legs(g, self._end_ports(sweep, 1), self._end_ports(nxt, -1), lambda v: ("out", s, v),
                       lambda v: ("in", s + 1, v), sweep, nxt)
        elif goal is None:
            g.add_edge(("out", s, -1), "G", kind="fixed", cost=0, path=[])
        elif goal_inside:
            g.add_edge(("out", s, goal), "G", kind="fixed", cost=0, path=[goal])
        else:
            self._legs(g, self._end_ports(sweep, 1), [goal], lambda v: ("out", s, v), lambda v: "G")
        for layout, (blocks, cuts, _) in sweep.layouts.items():
            d = layout[0]
            if s == 0 and start_inside:
                entries = [start]
            else:
                entries = [v for v in self._ports(sweep, -d) if g.has_node(("in", s, v))]
            if s == last and goal is None:
                exits = [-1]
            elif goal_inside:
                exits = [goal]
            else:
                exits = [v for v in self._ports(sweep, self._exit_side(layout)) if g.has_node(("out", s, v))]
            levels = [entries] + [c.tolist() for c in cuts] + [exits]
            end = len(levels) - 1

            def name(i: int, v: int, s=s, layout=layout, end=end):
                return ("out", s, v) if i == end else (s, layout, i, v)

            for p in entries:  # each chain its own first node: one-region chains would share an edge
                g.add_edge(("in", s, p), name(0, p), kind="fixed", cost=0, path=[p])
            for b in range(len(blocks)):
                for p in levels[b]:
                    for q in levels[b + 1]:
                        g.add_region(name(b, p), name(b + 1, q), _RegionEdge((sweep, layout, b, levels[b + 1])))

    def build_all(self, g: _Dag) -> None:
        """Every sweep's part of the DAG (its size for the report, and the tests' whole DAG)."""
        for s in range(len(self._chain)):
            self._build_sweep(g, s)

    def _solve(self, g: _Dag):
        """(cost, node path) of the DAG's shortest S → G path, region costs computed lazily; (None, None)
        if there is none. The cost is in commands: the path's weight without the penalties for
        targets left to the mop-up."""
        def weight(u, v, data):
            if data["kind"] == "fixed":
                return data["cost"]
            return self.region_cost(data["sweep"], data["layout"], data["block"], u[-1], v[-1], data["exits"])

        if "S" not in g or "G" not in g:
            return None, None
        # the greedy walks past the cutoff (_past_cutoff) are priced one by one too: past the deadline, less a
        # twentieth of the time allowed (the commands and the replay), the search stops where it has got to
        stop = progress = None
        if self.deadline is not None and self.fallback:
            end = self.deadline - 0.05 * (self.deadline - self.began)
            lengths = {s: {k: len(v[0]) + 1 for k, v in sweep.layouts.items()} for s, sweep in enumerate(self._chain)}

            def stop() -> bool:
                return time.perf_counter() > end

            def progress(n):  # how far along the chain of sweeps a node is
                if n == "S":
                    return (-1, 0, 0.0)
                if n[0] == "in":
                    return (n[1], 0, 0.0)
                if n[0] == "out":
                    return (n[1], 2, 0.0)
                return (n[0], 1, n[2] / lengths[n[0]][n[1]])

        found = g.shortest_path("S", "G", weight, stop=stop, progress=progress)
        if g.stopped:
            self.time_limited = True
            last = found[1][-1]
            reached = -1 if last == "S" else last[1] if last[0] in ("in", "out") else last[0]
            self.cut["dag_stopped"] = {"sweeps": len(self._chain), "sweeps_entered": reached + 1,
                                       "last_node": list(last) if isinstance(last, tuple) else last}
        if found is None:
            return None, None
        weighted, path = found
        return weighted - DROP_PENALTY * self._dropped(g, path), path

    def _dropped(self, g: _Dag, path: list) -> int:
        """Targets the regions along a DAG path leave to the mop-up."""
        return sum(self.results[(d["sweep"].key, d["layout"], d["block"], u[-1], v[-1])][2]
                   for u, v, d in ((u, v, g.adj[u][v]) for u, v in zip(path[:-1], path[1:])) if d["kind"] == "region")

    def _improve_order(self) -> int:
        """Improve the greedy order of the sweeps (default variant, at most :data:`ORDER_SWEEPS`
        sweeps): move one sweep elsewhere in the chain, as is or reversed, or reverse one in place,
        keeping the first move that lowers the plan's cost (the DAG's path with its mop-up and the
        way to the goal: a cheaper path may leave more to the mop-up), until none does or
        :data:`ORDER_TRIES` orders have been tried. Returns the orders tried."""
        n = len(self.sweeps)
        if not self.reorder or not 2 <= n <= ORDER_SWEEPS:
            return 0

        def cost(order) -> float:  # the plan's: the DAG's path, then the mop-up and the way to the goal
            for sweep, d in order:
                if sweep.direction != d:
                    sweep.direction = d
                    self._regions(sweep)
            g = self.dag([sweep for sweep, _ in order], start=self.start, goal=self.goal)
            found, dag_path = self._solve(g)
            if found is None or g.stopped:  # a path cut short by the deadline is no candidate order
                return math.inf
            return plan_total(self.lg, self.cov, self._vertex_path(g, dag_path), found, self.goal, self.mopup)

        if self._past_cutoff():
            return 0  # no time left: the greedy order stands (each try costs a DAG search and its mop-up)
        self._from = {}
        current = [(sweep, sweep.direction) for sweep in self.sweeps]
        best, tries = cost(current), 1
        last = current  # the order the sweeps' directions and regions were last set for
        improved = True
        while improved and tries < ORDER_TRIES:
            improved = False
            moves = [(i, i, True) for i in range(n)] + [
                (i, j, flip) for i in range(1, n) for j in range(1, n) if i != j for flip in (False, True)]
            for i, j, flip in moves:  # the first sweep holds the start: it may turn, never move
                if tries >= ORDER_TRIES or self._past_cutoff():
                    break
                order = list(current)
                sweep, d = order.pop(i)
                order.insert(j, (sweep, -d if flip else d))
                found, last = cost(order), order
                tries += 1
                if found < best:
                    best, current, improved = found, order, True
                    break
        if last is not current:
            cost(current)  # set the sweeps back to the best order's directions and regions
        self.sweeps = [sweep for sweep, _ in current]
        self._from = None  # a large map's arrays: not kept past the search
        return tries

    def _vertex_path(self, g: _Dag, dag_path: list) -> list[int]:
        """The workspace-graph vertices along a DAG path, from the start."""
        path = [self.start]
        for u, v in zip(dag_path[:-1], dag_path[1:]):
            data = g.adj[u][v]
            if data["kind"] == "fixed":
                leg = data["path"] if "path" in data else _walk_back(*data["pred"])
            else:
                nodes, walk = self.results[(data["sweep"].key, data["layout"], data["block"], u[-1], v[-1])][1]
                leg = nodes[list(walk)].tolist()
            if leg and leg[0] == path[-1]:
                leg = leg[1:]
            path += leg
        return path

    def plan(self) -> StripeOutcome:
        info: dict = {"sweeps": len(self.sweeps)}
        then = "the whole map is covered by the mop-up walk" if self.mopup else "nothing is covered"
        if not self.sweeps:
            info["dag"] = f"no stripe has a piece: {then}"
            return self._outcome([self.start], None, 0, info)
        info["order_tries"] = self._improve_order()
        g = self.dag(self.sweeps, start=self.start, goal=self.goal)
        dag_cost, dag_path = self._solve(g)
        if not g.stopped:  # the whole DAG's size (a search stopped by the deadline: the part it built)
            self.build_all(g)
        info.update({"dag_nodes": g.number_of_nodes(), "dag_edges": g.number_of_edges()})
        if dag_path is None:
            info["dag"] = f"no path: {then}"
            return self._outcome([self.start], None, 0, info)
        path, joins = self._vertex_path(g, dag_path), 0
        for u, v in zip(dag_path[:-1], dag_path[1:]):
            data = g.adj[u][v]
            if data["kind"] == "fixed":
                joins += int(data["cost"])
            else:
                sweep, layout = data["sweep"], data["layout"]
                sweep.cost += self.results[(sweep.key, layout, data["block"], u[-1], v[-1])][0]
                sweep.direction = layout[0]  # the chain the path takes: for the report and the plot
                sweep.blocks, sweep.cuts = sweep.layouts[layout][:2]
                sweep.folded = bool(layout[2])
        info["dag_path"] = [list(n) if isinstance(n, tuple) else n for n in dag_path]
        info["dag_dropped"] = self._dropped(g, dag_path)  # the DAG's first criterion, before its cost
        info["dag_joins"] = joins  # commands of the DAG's fixed edges: start leg, cut-edges, transits, goal leg
        return self._outcome(path, int(dag_cost), 0, info)

    def _outcome(self, path, dag_cost, transit, info) -> StripeOutcome:
        details = []
        for k, (own, band) in enumerate(self.bands):
            mine = [sw for sw in self.sweeps if sw.stripe == k]
            details.append({
                "rows": list(own), "band": list(band), "borrowed": (band[1] - band[0]) - (own[1] - own[0]),
                "cost": sum(sw.cost for sw in mine), "pieces": len(mine), "regions": sum(len(sw.blocks) for sw in mine),
                "direction": mine[0].direction if mine else 1, "folded": any(sw.folded for sw in mine),
                "cuts": sorted({b[0] if sw.direction > 0 else b[1] for sw in mine for b in sw.blocks[1:]})})
        info["order"] = [[sw.stripe, sw.direction] for sw in self.sweeps]
        info["widening"] = self.widening
        return StripeOutcome(path, dag_cost, transit, details, self.stats["regions"], self.stats["optimal"],
                             self.stats["memo_hits"], self.stats["nodes"], self.time_limited, info,
                             dict(self.failed))


def plan_total(lg: LayerGraph, cov: Coverability, path: list[int], dag_cost: float, goal: int | None,
               mopup: str | None) -> float:
    """Commands of a plan whose DAG path (costing ``dag_cost``) is ``path``: that, the mop-up, and the
    way back to the goal if there is one. Without a mop-up (None) a coverable cell left uncovered costs
    :data:`DROP_PENALTY`, so that a plan covering more wins first."""
    if mopup is None:
        covered = np.zeros(lg.width * lg.height, dtype=bool)
        covered[lg.footprint[path].ravel()] = True
        left = int((cov.coverable.reshape(-1) & ~covered).sum())
        back = 0.0 if goal is None or path[-1] == goal else shortest_path(lg, path[-1], goal)[0]
        return DROP_PENALTY * left + dag_cost + back
    walk = [path[-1]] + mop_up(lg, path, cov.coverable, cov.reachable, order=mopup, goal=goal)
    back = 0.0 if goal is None or walk[-1] == goal else shortest_path(lg, walk[-1], goal)[0]
    return dag_cost + len(lg.commands_of(walk)) + back


def _same_chain(a: tuple, b: tuple) -> bool:
    """Two chains with the same regions, cuts and passes (a narrow sweep's cut grids may coincide)."""
    return a[0] == b[0] and a[2] == b[2] and len(a[1]) == len(b[1]) and all(
        np.array_equal(x, y) for x, y in zip(a[1], b[1]))


def plan_stripes(lg: LayerGraph, cov: Coverability, start: int, goal: int | None, widths, *, region_columns: int,
                 budget: int, deadline: float | None, memo: bool = True, additions=tuple(STRIPES_ADDITIONS),
                 ends: str = "sweep", mopup: str = "sequenced") -> StripeOutcome:
    """The stripes' vertex path from ``start`` (to ``goal``, or a free end) along the auxiliary DAG's
    shortest path; the mop-up and the return to the goal are the caller's.

    ``additions``: the names of :data:`~htetro_opt.solvers.coverage._spec.STRIPES_ADDITIONS` switched
    on (all by default; none: the paper's Alg. 5). Without ``mopup`` the candidates below are compared
    by the coverable cells their DAG paths leave, then by cost; without ``greedy-fallback`` a region
    search that spends its budget fails and is listed in the outcome's ``failed``.

    Widening is cost-aware in the default variant: when a stripe split into pieces could also be
    joined by borrowing rows, the plan is made both ways (every split stripe swept piece by piece,
    and every such stripe widened as the paper does) and the one costing fewer commands with its
    mop-up wins (ties: the split one). With ``ends="both"`` the ``"sweep"`` plans are candidates
    too (ties: ``"both"``): the both-ends DAG is a superset, so its path never costs more, but its
    mop-up may, and the plan must never cost more than ``"sweep"``'s. Every candidate shares one
    memo of region searches (keyed by content)."""
    additions = tuple(additions)
    mopup = mopup if "mopup" in additions else None
    split = "split-sweeps" in additions
    options = dict(region_columns=region_columns, budget=budget, deadline=deadline, memo=memo, additions=additions,
                   shared_memo={}, mopup=mopup or "sequenced")
    first = "split" if split else "joined"
    began = time.perf_counter()
    planner = _Planner(lg, cov, start, goal, widths, **options, widening=first, ends=ends)
    runs = {(first, ends): planner.plan()}
    reorder, sweeps, choices = planner.reorder, len(planner.sweeps), planner.choices
    cuts = [(planner.cut, planner.time_limited)]  # what each candidate's time limit cut (not the planners: their memory)
    took = time.perf_counter() - began  # a further candidate: up to twice that (tiling_64x64's joined one, fewer memo hits)
    widenings = [first] + (["joined"] if split and choices else [])
    time_limited = planner.time_limited
    del planner  # its windows, problems and DAG: not held while the next candidate is planned
    skipped = []
    for widening, e in [(w, e) for e in dict.fromkeys((ends, "sweep")) for w in widenings]:
        if (widening, e) in runs:
            continue
        if deadline is not None and (time_limited or time.perf_counter() + 2 * took > deadline):
            skipped.append(f"{widening}/{e}")  # a time limit: the candidates planned so far (the first always)
            continue
        # "both" keeps "sweep"'s plan as a candidate: never costlier with its mop-up
        other = _Planner(lg, cov, start, goal, widths, **options, widening=widening, ends=e)
        runs[(widening, e)] = other.plan()
        cuts.append((other.cut, other.time_limited))
        del other

    def said(best: StripeOutcome) -> StripeOutcome:  # what the time limit cut, in the result's info
        if best.time_limited:
            best.info["time_limit_cut"] = {
                "greedy_regions": sum(c["greedy_regions"] for c, _ in cuts),
                "unpriced_edges": sum(c["hidden_edges"] for c, _ in cuts),
                "failed_regions": sum(c["failed_regions"] for c, _ in cuts),
                "candidates_skipped": skipped, "order_search_cut": any(late for _, late in cuts)
                and reorder and 2 <= sweeps <= ORDER_SWEEPS,
                "dag_stopped": next((c["dag_stopped"] for c, _ in cuts if "dag_stopped" in c), None)}
        return best

    if len(runs) == 1:
        runs[(first, ends)].time_limited |= bool(skipped)
        return said(runs[(first, ends)])

    costs = {key: math.inf if o.dag_cost is None else plan_total(lg, cov, o.path, o.dag_cost, goal, mopup)
             for key, o in runs.items()}
    key = min(costs, key=lambda k: (costs[k], k[1] != ends, k[0] != first))  # ties: the asked ends, split
    best = runs[key]
    if len(widenings) > 1:
        best.info["widening_costs"] = {w: min(c for (w2, _), c in costs.items() if w2 == w) for w in widenings}
    if ends != "sweep":
        best.info["ends_costs"] = {e: min(c for (_, e2), c in costs.items() if e2 == e) for e in (ends, "sweep")}
        best.info["ends_dag_costs"] = {  # the DAG's criteria: targets left to the mop-up, then commands
            e: min(([o.info["dag_dropped"], o.dag_cost] for (_, e2), o in runs.items()
                    if e2 == e and o.dag_cost is not None), default=None) for e in (ends, "sweep")}
    best.info["ends"] = key[1]
    for name in ("regions", "regions_optimal", "memo_hits", "nodes"):  # every plan's searches count
        setattr(best, name, sum(getattr(o, name) for o in runs.values()))
    best.time_limited = bool(skipped) or any(o.time_limited for o in runs.values())
    best.failed = {k: v for o in runs.values() for k, v in o.failed.items()}  # every search of the run counts
    return said(best)
