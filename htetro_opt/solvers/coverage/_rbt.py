"""The region search of Cheng et al. 2019 (Alg. 5's RBT), as a best-first branch and bound.

A *region* is a small piece of a stripe: a window of the workspace graph (its vertices, local
numbers 0 … V−1), the target cells it must cover (bit t of an integer mask), an entry vertex and
an exit vertex (or a free end). A search state is (vertex, covered targets); revisiting vertices is
allowed, and the table of states already reached at lower cost is Alg. 5's missing loop check (the
transposition table on (vertex, covered cells) of our reading).

Departure from the paper, stated here: Alg. 5 is a depth-first search with pruning; this is the same
search ordered best-first (A*), with the same kind of bound: a state costs at least
``max(distance to the exit, ⌈uncovered / g⌉, max over uncovered targets t of the cheapest way to
cover t and then reach the exit)``, g being the most new cells one command adds. The bound is
consistent, so the first state popped at the exit with every target covered is optimal: a search
that ends within its node budget is a proof (the ``best-first`` addition).

The best-first loop runs compiled (numba, :func:`_astar`: the same states, heap order and expansions as
the Python loop, which runs where a state's key would not fit 63 bits), and its tables toward an exit
(:func:`_tables`) are built once per region and exit and shared by the searches from every entry: on a
64 × 64 map of {O, vI, hI} the DAG prices ~46,000 (entry, exit) pairs of ~1,100 regions, each search
expanding ~17 states, so the set-up, not the search, was the cost (issue 25).

The paper variant (:func:`search_simple`, :func:`search_inserting`) is Alg. 5 as written: a
depth-first branch and bound over *simple* paths (no vertex twice: §IV-D's "each vertex is visited
once", a check Algs. 5–6 lack), moves ordered by new cells, then progress along the sweep; when no
simple path covers the targets, a pose covering the first uncovered target is inserted (Alg. 5
l. 12–13) and the two halves are searched apart, each simple. The paper gives no bound on the
insertions; ours, :data:`MAX_INSERTIONS`, only turns an insertion that repeats itself forever into a
region without a walk.

**The node budget.** The paper's search has none: it runs to its end. Ours stops a search after
``budget`` expansions. With ``fallback`` (the ``greedy-fallback`` addition) the region then takes the
search's best walk so far, or the greedy walk (nearest vertex covering an uncovered target, then the
exit), reported as not proven optimal; without it the search returns an *exhausted* result
(:attr:`RegionResult.exhausted`): the region has no walk and the plan reports it as failed, since
the paper's algorithm was not run to its end there.
"""

from __future__ import annotations

import heapq
import math
from dataclasses import dataclass, field

import numpy as np

from htetro_opt._jit import lazy_jit

__all__ = ["Region", "RegionResult", "search_region", "greedy_walk", "LazyDistances", "search_simple", "search_inserting",
           "MAX_INSERTIONS"]

MAX_INSERTIONS = 8
"""Poses the paper variant inserts into one region (Alg. 5 l. 12–13), nested, before the region has no walk
(then the greedy walk with ``fallback``)."""


@dataclass(frozen=True, eq=False)
class Region:
    """One region's search problem, in local vertex numbers.

    ``adjacency[v]`` lists ``(w, cost)``; ``bits[v]`` the targets v's footprint covers; ``full``
    all targets; ``dist`` / ``pred`` all-pairs shortest paths in the window (inf / −9999 where none).
    """

    adjacency: tuple
    bits: tuple
    full: int
    dist: np.ndarray
    pred: np.ndarray
    progress: tuple = ()  # per vertex: how far along the sweep its B2 is (the paper variant's move order)
    target_progress: tuple = ()  # per target bit, likewise
    tables: dict = field(default_factory=dict, repr=False)  # the best-first search's per-exit tables (_tables)


def _tables(region: Region, exit: int | None) -> tuple:
    """The best-first search's tables toward one exit: (the target bits as a list and an array, the
    distance to the exit per vertex, ``via`` (T, V), per vertex the targets by decreasing ``via``, and the
    Python loop's per-vertex bound lists, filled lazily, and per vertex whether every target can be covered
    from it). They depend on the region and the
    exit only, not on the entry, so they are built once per exit and shared by every entry's search
    (the DAG prices a region from each of its entry ports to each exit: 8 × 8 searches of one region
    on a 4-row band of {O, vI, hI})."""
    found = region.tables.get(exit)
    if found is not None:
        return found
    dist, bits, full = region.dist, region.bits, region.full
    n = len(bits)
    dexit = dist[:, exit] if exit is not None else np.zeros(n)
    positions = [t for t in range(full.bit_length()) if full >> t & 1]
    targets = [1 << t for t in positions]
    covers = region.tables.get("covers")
    if covers is None:  # the vertices covering each target, concatenated, and where each target's start
        lists = [[v for v, b in enumerate(bits) if b >> t & 1] for t in positions]
        covers = region.tables["covers"] = (np.array([v for c in lists for v in c], dtype=np.int64),
                                            np.cumsum([0] + [len(c) for c in lists[:-1]], dtype=np.int64),
                                            all(lists))
    flat, starts, every = covers
    # via[t][v]: the cheapest way from v to cover target t and then reach the exit (min over its covers c
    # of dist[v, c] + dexit[c]; inf when no vertex covers t): one reduceat over the covers' columns
    if not targets:
        via = np.zeros((0, n))
    elif every:
        via = np.minimum.reduceat((dist[:, flat] + dexit[flat][None, :]), starts, axis=1).T
    else:  # some target has no cover (reduceat cannot take an empty group)
        mask = np.zeros((len(positions), n), dtype=bool)
        for t, p in enumerate(positions):
            mask[t] = [b >> p & 1 for b in bits]
        via = np.where(mask[:, None, :], (dist + dexit[None, :])[None, :, :], np.inf).min(axis=2)
    order = np.ascontiguousarray(np.argsort(-via, axis=0, kind="stable").T)  # (V, T): targets by via, decreasing
    wide = full.bit_length() > 62  # the compiled search's keys would not fit: the Python loop alone runs
    found = region.tables[exit] = (targets, None if wide else np.array(targets, dtype=np.int64),
                                   np.ascontiguousarray(dexit, dtype=float),
                                   np.ascontiguousarray(via, dtype=float), order.astype(np.int64), {},
                                   np.isfinite(via).all(axis=0).tolist())
    return found


@dataclass(frozen=True)
class RegionResult:
    cost: int
    path: tuple[int, ...]  # local vertices, entry first
    optimal: bool
    nodes: int
    exhausted: bool = False  # the node budget ran out: no walk (path empty) unless the search had one so far
    missing: int = 0  # targets (bits) the walk leaves uncovered: the paper's search keeps its maximum coverage


def _segment(region: Region, a: int, b: int) -> list[int]:
    """The shortest path a → b in the window, a first."""
    path, pred = [b], region.pred[a]
    while path[-1] != a:
        path.append(int(pred[path[-1]]))
    return path[::-1]


def greedy_walk(region: Region, entry: int, exit: int | None) -> RegionResult | None:
    """From the entry, go to the nearest vertex covering an uncovered target (ties: more new targets,
    then the lower number), until all are covered; then to the exit. None if the exit is unreachable.

    The covering part does not depend on the exit: it is walked once per entry and kept on the region
    (a time limit prices every remaining (entry, exit) pair of a region by this walk)."""
    dist = region.dist
    if exit is not None and not math.isfinite(dist[entry][exit]):
        return None
    cover = region.tables.get(("greedy", entry), False)
    if cover is False:
        cover = region.tables[("greedy", entry)] = _greedy_cover(region, entry)
    if cover is None:
        return None
    cur, path, cost = cover
    if exit is not None and exit != cur:
        path = path + tuple(_segment(region, cur, exit)[1:])
        cost += dist[cur][exit]
    return RegionResult(int(round(cost)), path, False, 0)


class LazyDistances:
    """A window's shortest paths computed one source at a time, on demand: ``dist[a]`` / ``pred[a]`` (rows)
    and ``dist[a, b]`` as the all-pairs arrays give them (the same rows: scipy's Dijkstra per source).
    For a region only walked greedily (a time limit): the walk needs a few sources, not all of them."""

    __slots__ = ("graph", "rows", "dist", "pred")

    def __init__(self, graph) -> None:
        self.graph, self.rows = graph, {}
        self.dist, self.pred = _Rows(self, 0), _Rows(self, 1)

    def row(self, a: int) -> tuple:
        found = self.rows.get(a)
        if found is None:
            from scipy.sparse.csgraph import dijkstra

            found = self.rows[a] = dijkstra(self.graph, indices=int(a), return_predecessors=True)
        return found


class _Rows:
    __slots__ = ("of", "which")

    def __init__(self, of: LazyDistances, which: int) -> None:
        self.of, self.which = of, which

    def __getitem__(self, key):
        if isinstance(key, tuple):
            a, b = key
            return self.of.row(a)[self.which][b]
        return self.of.row(key)[self.which]


def _greedy_cover(region: Region, entry: int) -> tuple | None:
    """:func:`greedy_walk`'s covering part: (where it ends, its vertices, its cost), None if a target is
    out of reach."""
    dist, bits = region.dist, region.bits
    cur, mask, path, cost = entry, bits[entry], [entry], 0.0
    while mask != region.full:
        unc = region.full & ~mask
        best = None
        row = dist[cur].tolist()
        for u, b in enumerate(bits):
            if b & unc and math.isfinite(row[u]):
                key = (row[u], -(b & unc).bit_count(), u)
                if best is None or key < best:
                    best = key
        if best is None:
            return None
        u = best[2]
        for w in _segment(region, cur, u)[1:]:
            mask |= bits[w]
            path.append(w)
        cost += row[u]
        cur = u
    return cur, tuple(path), cost


def _popcount(x):
    count = 0
    while x:
        x &= x - 1
        count += 1
    return count


@lazy_jit(calls=("_popcount",))
def _astar(indptr, indices, costs, bits, full, entry, exit, gain, budget, dexit, via, orders, targets, shift):
    """:func:`search_region`'s A*, compiled: the same states, bound, heap order (numba's heapq is CPython's
    algorithm) and expansion count as the Python loop it replaces, on arrays (a state (v, mask) is the key
    ``v << shift | mask``). Returns (status, cost, expansions, path): status 0 found, 1 no covering walk,
    2 the budget ran out."""
    n_t = targets.shape[0]

    def bound(v, unc):
        best = dexit[v]
        q = -(-_popcount(unc) // gain)
        if q > best:
            best = float(q)
        for k in range(n_t):
            t = orders[v, k]
            if unc & targets[t]:
                value = via[t, v]
                return value if value > best else best
        return best

    m0 = bits[entry]
    k0 = (entry << shift) | m0
    best_g = {k0: 0}
    parent = {k0: -1}
    heap = [(bound(entry, full & ~m0), 0, entry, m0)]
    expanded = 0
    while len(heap):
        f, neg_g, v, mask = heapq.heappop(heap)
        g = -neg_g
        key = (v << shift) | mask
        if best_g[key] < g:
            continue
        if mask == full and (exit < 0 or v == exit):
            path = [v]
            state = parent[key]
            while state >= 0:
                path.append(state >> shift)
                state = parent[state]
            return 0, g, expanded, np.array(path[::-1], dtype=np.int64)
        expanded += 1
        if expanded > budget:
            return 2, 0, expanded, np.zeros(0, dtype=np.int64)
        for i in range(indptr[v], indptr[v + 1]):
            w = indices[i]
            m2 = mask | bits[w]
            g2 = g + costs[i]
            k2 = (w << shift) | m2
            if g2 < best_g.get(k2, 1 << 62):
                h = bound(w, full & ~m2)
                if h == np.inf:
                    continue
                best_g[k2] = g2
                parent[k2] = key
                heapq.heappush(heap, (g2 + h, -g2, w, m2))
    return 1, 0, expanded, np.zeros(0, dtype=np.int64)


def _arrays(region: Region) -> tuple | None:
    """The region as the compiled search's arrays (CSR adjacency in the listed order, bits), or None when
    a state's key would not fit 63 bits (then the Python loop runs)."""
    found = region.tables.get("arrays", False)
    if found is not False:
        return found
    n = len(region.bits)
    shift = max(1, region.full.bit_length())
    if shift + max(1, n).bit_length() > 62:
        region.tables["arrays"] = None
        return None
    indptr = np.zeros(n + 1, dtype=np.int64)
    indptr[1:] = np.cumsum([len(a) for a in region.adjacency])
    flat = [wc for a in region.adjacency for wc in a]
    indices = np.array([w for w, _ in flat], dtype=np.int64)
    costs = np.array([c for _, c in flat], dtype=np.int64)
    found = region.tables["arrays"] = (indptr, indices, costs, np.array(region.bits, dtype=np.int64), shift)
    return found


def search_region(region: Region, entry: int, exit: int | None, *, gain: int, budget: int,
                  fallback: bool = True, compiled: bool = True) -> RegionResult | None:
    """The cheapest walk from ``entry`` covering every target and ending at ``exit`` (anywhere for
    None), by A* over (vertex, covered) with at most ``budget`` expansions; past the budget, the
    greedy walk (``fallback``) or an exhausted result without a walk. None when the exit cannot be
    reached or a target cannot be covered."""
    dist, bits, full = region.dist, region.bits, region.full
    if exit is not None and not math.isfinite(dist[entry, exit]):
        return None
    targets, target_array, dexit, via, orders, lists, coverable = _tables(region, exit)
    if not coverable[entry]:  # some target cannot be covered (and the exit then reached) from the entry
        return None
    arrays = _arrays(region) if compiled else None
    if arrays is not None:
        indptr, indices, costs, bit_array, shift = arrays
        status, g, expanded, path = _astar(indptr, indices, costs, bit_array, full, entry, -1 if exit is None else exit,
                                           gain, budget, dexit, via, orders, target_array, shift)
        if status == 0:
            return RegionResult(int(g), tuple(path.tolist()), True, int(expanded))
        if status == 1:
            return None
        return _cut_short(region, entry, exit, int(expanded), fallback)
    dexit_list = dexit.tolist()

    def bound(v: int, unc: int) -> float:
        best = dexit_list[v]
        q = -(-unc.bit_count() // gain)
        if q > best:
            best = q
        order = lists.get(v)
        if order is None:
            column = via[:, v].tolist()
            order = lists[v] = [(column[t], targets[t]) for t in orders[v].tolist()]
        for value, bit in order:
            if unc & bit:
                return value if value > best else best
        return best

    start = (entry, bits[entry])
    best_g = {start: 0}
    parent: dict = {start: None}
    heap = [(bound(entry, full & ~bits[entry]), 0, entry, bits[entry])]
    expanded, cut_short = 0, False
    adjacency = region.adjacency
    while heap:
        f, neg_g, v, mask = heapq.heappop(heap)
        g = -neg_g
        if best_g[(v, mask)] < g:
            continue
        if mask == full and (exit is None or v == exit):
            path, state = [], (v, mask)
            while state is not None:
                path.append(state[0])
                state = parent[state]
            return RegionResult(int(g), tuple(path[::-1]), True, expanded)
        expanded += 1
        if expanded > budget:
            cut_short = True
            break
        for w, c in adjacency[v]:
            m2 = mask | bits[w]
            g2 = g + c
            key = (w, m2)
            if g2 < best_g.get(key, math.inf):
                h = bound(w, full & ~m2)
                if h == math.inf:
                    continue
                best_g[key] = g2
                parent[key] = (v, mask)
                heapq.heappush(heap, (g2 + h, -g2, w, m2))
    if not cut_short:  # searched to the end: no covering walk
        return None
    return _cut_short(region, entry, exit, expanded, fallback)


def _cut_short(region: Region, entry: int, exit: int | None, expanded: int, fallback: bool) -> RegionResult | None:
    """A best-first search past its budget: the greedy walk (``fallback``), or an exhausted result."""
    if not fallback:
        return RegionResult(0, (), False, expanded, exhausted=True)
    walk = greedy_walk(region, entry, exit)
    if walk is None:
        return None
    return RegionResult(walk.cost, walk.path, False, expanded)


class _Budget(Exception):
    """The region's node budget is spent: the search keeps its best so far."""


def search_simple(region: Region, entry: int, exit: int | None, *, gain: int, budget: int,
                  targets: int | None = None) -> RegionResult | None:
    """The cheapest *simple* walk (no vertex twice) from ``entry`` covering ``targets`` (all by
    default) and ending at ``exit`` (anywhere for None): a depth-first branch and bound with at most
    ``budget`` expansions. Past the budget, an exhausted result holding the best walk found so far
    (its path empty if none); None when there is no simple walk."""
    return _simple(region, entry, exit, gain=gain, budget=budget, targets=targets)[0]


def _simple(region: Region, entry: int, exit: int | None, *, gain: int, budget: int,
            targets: int | None = None) -> tuple[RegionResult | None, int]:
    """The cheapest *simple* walk (no vertex twice) from ``entry`` covering ``targets`` (all by
    default): :func:`search_simple`'s result, and the expansions it took (also when there is no walk).

    As the paper's RBT, the search keeps the walk of *maximum coverage* (then least cost) ending at the
    exit: when no simple walk covers every target, that walk is returned with the targets it leaves
    (:attr:`RegionResult.missing`), for :func:`search_inserting` to insert an intermediate pose."""
    full = region.full if targets is None else targets
    bits = [b & full for b in region.bits]
    dist = region.dist
    n = len(bits)
    if exit is not None and not math.isfinite(dist[entry, exit]):
        return None, 0
    dexit = dist[:, exit].tolist() if exit is not None else [0.0] * n
    progress = region.progress or (0,) * n
    best_cost, best_path = math.inf, None
    part = [(-1, 0), None, 0]  # (covered targets, −cost), walk, mask: the maximum coverage so far
    path, on_path, expanded = [entry], {entry}, 0
    adjacency = region.adjacency

    def dfs(v: int, mask: int, cost: int) -> None:
        nonlocal best_cost, best_path, expanded
        if exit is None or v == exit:
            key = ((mask & full).bit_count(), -cost)
            if key > part[0]:
                part[:] = [key, tuple(path), mask]
        if mask == full and (exit is None or v == exit):
            if cost < best_cost:
                best_cost, best_path = cost, tuple(path)
            return
        expanded += 1
        if expanded > budget:
            raise _Budget
        unc = full & ~mask
        if cost + max(dexit[v], -(-unc.bit_count() // gain)) >= best_cost:
            return
        moves = sorted(((w, c) for w, c in adjacency[v] if w not in on_path),
                       key=lambda wc: (-(bits[wc[0]] & unc).bit_count(), -progress[wc[0]], wc[0]))
        for w, c in moves:
            path.append(w)
            on_path.add(w)
            dfs(w, mask | bits[w], cost + c)
            on_path.discard(w)
            path.pop()

    try:
        dfs(entry, bits[entry], 0)
    except _Budget:
        return RegionResult(0 if best_path is None else int(best_cost), best_path or (), False, expanded,
                            exhausted=True), expanded
    if best_path is None:
        if part[1] is None:
            return None, expanded
        return RegionResult(-part[0][1], part[1], False, expanded, missing=full & ~part[2]), expanded
    return RegionResult(int(best_cost), best_path, True, expanded), expanded


def search_inserting(region: Region, entry: int, exit: int | None, *, gain: int, budget: int,
                     fallback: bool = True) -> RegionResult | None:
    """Alg. 5 with its failure rule (§IV-D, Fig. 10): a simple walk of maximum coverage
    (:func:`search_simple`); when it leaves targets, insert the pose nearest the entry that covers
    the one it leaves earliest along the sweep, search the halves (targets up to that pose, then the
    rest) apart in the same way, and keep the better (more targets covered, then fewer commands), up
    to :data:`MAX_INSERTIONS` nested poses. Targets no insertion covers are left (the paper: "the grids
    will be left unvisited while the algorithm moves on"): :attr:`RegionResult.missing`.

    Past ``budget`` expansions in all, with ``fallback`` (the ``greedy-fallback`` addition) a search
    keeps its best simple walk so far, and a region left without a walk takes the greedy walk; without
    it the result is exhausted (no walk: the paper's search has no budget, it would have gone on).
    None when a target or the exit cannot be reached at all, or (without ``fallback``) when the
    insertions find no walk."""
    if exit is not None and not math.isfinite(region.dist[entry, exit]):
        return None
    order = region.target_progress or (0,) * region.full.bit_length()
    spent = [0]
    cut_short = [False]

    def solve(a: int, b: int | None, targets: int, depth: int):
        left = budget - spent[0]  # one budget for the region, insertions included
        if left <= 0:
            cut_short[0] = True
            return None
        result, expanded = _simple(region, a, b, gain=gain, budget=left, targets=targets)
        spent[0] += expanded
        if result is not None and result.exhausted:
            cut_short[0] = True
            return result if fallback and result.path else None
        if result is None or not result.missing or depth >= MAX_INSERTIONS:
            return result
        unc = result.missing
        first = min((t for t in range(unc.bit_length()) if unc >> t & 1), key=lambda t: (order[t], t))
        covers = [v for v, bv in enumerate(region.bits) if bv >> first & 1 and math.isfinite(region.dist[a, v])]
        if not covers:
            return result
        p = min(covers, key=lambda v: (region.dist[a, v], v))
        before = sum(1 << t for t in range(targets.bit_length()) if targets >> t & 1 and order[t] <= order[first])
        if p == b and before == targets:  # the same region again: no insertion helps
            return result
        head = solve(a, p, before, depth + 1)
        tail = solve(p, b, targets & ~before, depth + 1) if head is not None else None
        if head is None or tail is None:
            return None if cut_short[0] and not fallback else result
        covered = 0
        for v in head.path + tail.path:
            covered |= region.bits[v]
        joined = RegionResult(head.cost + tail.cost, head.path + tail.path[1:], False, 0,
                              missing=targets & ~covered)
        better = (joined.missing.bit_count(), joined.cost) < (result.missing.bit_count(), result.cost)
        return joined if better else result

    found = solve(entry, exit, region.full, 0)
    if found is not None and cut_short[0] and not fallback:  # some half was cut short: not the paper's answer
        found = None
    if found is not None and found.missing and fallback:  # ours: a walk covering all, not one leaving targets
        found = greedy_walk(region, entry, exit) or found
    if found is None:
        if not fallback:
            return RegionResult(0, (), False, spent[0], exhausted=True) if cut_short[0] else None
        found = greedy_walk(region, entry, exit)
        if found is None:
            return None
    optimal = found.optimal and not cut_short[0]
    return RegionResult(found.cost, found.path, optimal, spent[0], missing=found.missing)
