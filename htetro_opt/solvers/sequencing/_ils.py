"""The ``ils`` method: a compiled, seeded iterated local search (2-opt + Or-opt) on closed tours.

Every instance is solved as a **closed, symmetric tour** on ``n`` nodes, or ``n + 1`` with a dummy
node ``d`` for an open path: legs to ``d`` cost 0, except that a fixed start ``s`` (and a fixed end
``e``) is pinned next to ``d`` by giving ``d``'s legs to the other nodes a penalty
``K = 3 · max|C| + 1``, which an improving move always removes (the dummy-node reduction of
:mod:`~htetro_opt.solvers.sequencing._backends`, in floats). The tour is cut at ``d`` and re-priced by
the dispatcher.

The search (a choice of ours, after the classic 2-opt + Or-opt local search with neighbour lists
and don't-look bits, and iterated local search with double-bridge kicks of Lourenço, Martin and
Stützle 2003):

- **Neighbour lists**: each node's :data:`ILS_NEIGHBOURS` cheapest other nodes.
- **Local search**: a queue of active nodes (the don't-look bits: a node whose moves all failed
  leaves the queue until an edge at it changes). For an active node ``a``, every 2-opt move that
  creates an edge from ``a`` (either tour direction) to a neighbour cheaper than the edge it
  replaces, and every Or-opt move of a segment of 1–3 nodes beginning or ending at ``a`` to an edge
  next to one of its ends' neighbours, as it is or reversed; the first improving move is applied.
  Every move is a sequence of 2-opt moves (an Or-opt is two or three), each reversing the shorter
  side of the tour array, and logged, so that a rejected kick is undone exactly.
- **Kicks**: a double bridge ``A B C D → A C B D`` whose three segments are 1–:data:`ILS_KICK_SPAN`
  nodes long (a *local* double bridge: it changes the tour near one random node), the local search
  restarted from the 8 nodes it touched, the result kept if it is no costlier, undone otherwise.
- **Budget**: :func:`ils_kicks` kicks, a function of ``n`` only, from a generator seeded by
  ``seed`` (a splitmix64 stream inside the compiled code), so the same seed gives the same order on
  every machine. ``time_limit`` is only a safety cap: when it stops the search first, the result
  says so (``info["timed_out"]``) and is no longer reproducible.

The kernel is compiled by numba (≥ 0.59, a core dependency, so that ``auto`` gives the same order on
every install). Should it be missing,
``ils`` runs the pure-numpy ``local`` method with restarts under the same time cap instead, and says
so in ``info["engine"]``: its results are worse (benchmarks/README.md) and depend on the clock.
"""

from __future__ import annotations

import time

import numpy as np

from htetro_opt._validation import as_rng, check_int, check_time_limit
from htetro_opt.errors import ParameterError
from htetro_opt.problems.waypoint_sequencing import SequencingInstance, check_instance
from htetro_opt.solvers.sequencing._budgets import default_time_limit

__all__ = ["HAVE_NUMBA", "ILS_KICK_SPAN", "ILS_NEIGHBOURS", "ils_kicks", "solve_ils"]

ILS_NEIGHBOURS = 8
"""Size of each node's neighbour (candidate) list."""

ILS_KICK_SPAN = 100
"""Longest segment of a kick's double bridge (each of its three segments has 1…this many nodes)."""

try:  # pragma: no cover - depends on the environment
    import numba

    _jit = numba.njit(cache=True, nogil=True)
    HAVE_NUMBA = True
except ImportError:  # pragma: no cover
    numba = None

    def _jit(function):
        return function

    HAVE_NUMBA = False
"""Whether numba is installed: ``ils`` runs its compiled kernel, else the ``local`` fallback."""


def ils_kicks(n: int) -> int:
    """The number of kicks ``ils`` makes on ``n`` nodes: ``400 · n`` + 1000, at most 2 000 000.

    Examples
    --------
    >>> ils_kicks(100), ils_kicks(1000), ils_kicks(100_000)
    (41000, 401000, 2000000)
    """
    return int(min(2_000_000, 400 * n + 1000))


# ------------------------------------------------------------------------------------ the kernel
# Tours are int64 arrays ``tour`` with ``pos[tour[i]] == i``. All moves go through _two_opt.

@_jit
def _next(state):
    """splitmix64: the next 64-bit draw of the one-element uint64 ``state``."""
    state[0] += np.uint64(0x9E3779B97F4A7C15)
    z = state[0]
    z = (z ^ (z >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
    z = (z ^ (z >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
    return z ^ (z >> np.uint64(31))


@_jit
def _below(state, k):
    """A draw in 0…k−1."""
    return np.int64(_next(state) % np.uint64(k))


@_jit
def _reverse(tour, pos, i, j):
    """Reverse tour positions i…j (cyclic, i to j going forward), or the complement when shorter."""
    n = tour.shape[0]
    inner = (j - i) % n + 1
    if 2 * inner > n:  # the complement j+1 … i−1: the same cycle
        i, j = (j + 1) % n, (i - 1) % n
        inner = n - inner
    for _ in range(inner // 2):
        a, b = tour[i], tour[j]
        tour[i], tour[j] = b, a
        pos[b], pos[a] = i, j
        i = (i + 1) % n
        j = (j - 1) % n


@_jit
def _two_opt(tour, pos, a, b, c, d):
    """Replace the edges (a, b) and (c, d) by (a, c) and (b, d); b next to a and d next to c in the
    same direction of the tour."""
    n = tour.shape[0]
    if tour[(pos[a] + 1) % n] == b:
        _reverse(tour, pos, pos[b], pos[c])
    else:
        _reverse(tour, pos, pos[a], pos[d])


@_jit
def _push(queue, queued, head, size, node):
    """Append ``node`` to the circular queue unless it is in it; the new size."""
    n = queue.shape[0]
    if queued[node]:
        return size
    queued[node] = True
    queue[(head + size) % n] = node
    return size + 1


@_jit
def _log(log, count, a, b, c, d):
    if count < log.shape[0]:
        log[count, 0], log[count, 1], log[count, 2], log[count, 3] = a, b, c, d
    return count + 1


@_jit
def _or_move(tour, pos, log, count, p, s1, s2, nx, x, y, forward):
    """Move the segment s1…s2 (between p and nx) between x and y, reversed or not, by 2-opt moves."""
    _two_opt(tour, pos, p, s1, x, y)
    count = _log(log, count, p, s1, x, y)
    _two_opt(tour, pos, p, x, nx, s2)
    count = _log(log, count, p, x, nx, s2)
    if forward:
        _two_opt(tour, pos, x, s2, s1, y)
        count = _log(log, count, x, s2, s1, y)
    return count


@_jit
def _local_search(D, nbr, tour, pos, queue, queued, head, size, log, count, eps):
    """Improve the tour from the queued nodes until the queue is empty; (gain, moves logged)."""
    n = tour.shape[0]
    k = nbr.shape[1]
    gain_total = 0.0
    while size > 0:
        a = queue[head]
        head = (head + 1) % n
        size -= 1
        queued[a] = False
        improved = False
        # 2-opt: a new edge (a, c), c a neighbour, in both directions of the tour
        for direction in range(2):
            if improved:
                break
            if direction == 0:
                b = tour[(pos[a] + 1) % n]
            else:
                b = tour[(pos[a] - 1) % n]
            d_ab = D[a, b]
            for t in range(k):
                c = nbr[a, t]
                g1 = d_ab - D[a, c]
                if g1 <= eps:
                    break
                if direction == 0:
                    d = tour[(pos[c] + 1) % n]
                else:
                    d = tour[(pos[c] - 1) % n]
                if c == b or d == a:
                    continue
                gain = g1 + D[c, d] - D[b, d]
                if gain > eps:
                    if direction == 0:
                        _two_opt(tour, pos, a, b, c, d)
                        count = _log(log, count, a, b, c, d)
                    else:
                        _two_opt(tour, pos, b, a, d, c)
                        count = _log(log, count, b, a, d, c)
                    gain_total += gain
                    size = _push(queue, queued, head, size, a)
                    size = _push(queue, queued, head, size, b)
                    size = _push(queue, queued, head, size, c)
                    size = _push(queue, queued, head, size, d)
                    improved = True
                    break
        if improved or n < 8:
            continue
        # Or-opt: a segment of 1-3 nodes with a at one end, next to a neighbour of a
        for length in range(1, 4):
            if improved:
                break
            for direction in range(2):
                if improved:
                    break
                # the segment s1 … s2 in tour order, a = s1 (direction 0) or a = s2 (direction 1)
                if direction == 0:
                    i = pos[a]
                else:
                    i = (pos[a] - length + 1) % n
                s1 = tour[i]
                s2 = tour[(i + length - 1) % n]
                p = tour[(i - 1) % n]
                nx = tour[(i + length) % n]
                removal = D[p, s1] + D[s2, nx] - D[p, nx]
                if removal <= eps:
                    continue
                for t in range(k):
                    c = nbr[a, t]
                    if removal - D[a, c] <= eps:
                        break
                    # c must lie outside the segment
                    off = (pos[c] - i) % n
                    if off < length:
                        continue
                    # the two edges at c: (c, succ c) and (pred c, c)
                    for side in range(2):
                        if side == 0:
                            x, y = c, tour[(pos[c] + 1) % n]
                        else:
                            x, y = tour[(pos[c] - 1) % n], c
                        if x == s2 or y == s1 or y == p:  # (s2, nx), (p, s1), or no move at all
                            continue
                        if (pos[x] - i) % n < length or (pos[y] - i) % n < length:
                            continue
                        base = removal + D[x, y]
                        fwd = base - D[x, s1] - D[s2, y]
                        rev = base - D[x, s2] - D[s1, y]
                        if fwd >= rev and fwd > eps:
                            count = _or_move(tour, pos, log, count, p, s1, s2, nx, x, y, True)
                            gain_total += fwd
                            improved = True
                        elif rev > fwd and rev > eps:
                            count = _or_move(tour, pos, log, count, p, s1, s2, nx, x, y, False)
                            gain_total += rev
                            improved = True
                        if improved:
                            for node in (a, p, nx, s1, s2, x, y):
                                size = _push(queue, queued, head, size, node)
                            break
                    if improved:
                        break
    return gain_total, head, count


@_jit
def _tour_cost(D, tour):
    n = tour.shape[0]
    total = 0.0
    for i in range(n):
        total += D[tour[i], tour[(i + 1) % n]]
    return total


@_jit
def _ils(D, nbr, tour, kicks, span, seed, eps):
    """Local search, then ``kicks`` kicks (double bridges); the tour in place. Returns (kicks done,
    kicks that lowered the cost)."""
    n = tour.shape[0]
    pos = np.empty(n, dtype=np.int64)
    for i in range(n):
        pos[tour[i]] = i
    queue = np.empty(n, dtype=np.int64)
    queued = np.zeros(n, dtype=np.bool_)
    log = np.empty((4 * n + 64, 4), dtype=np.int64)
    state = np.empty(1, dtype=np.uint64)
    state[0] = np.uint64(seed)
    head = 0
    size = 0
    for i in range(n):
        size = _push(queue, queued, head, size, tour[i])
    _, head, _ = _local_search(D, nbr, tour, pos, queue, queued, head, size, log, 0, eps)
    size = 0
    kept = 0
    done = 0
    if n < 8:
        return done, kept
    span = min(span, (n - 2) // 3)
    for _ in range(kicks):
        done += 1
        # A B C D → A C B D with |B|, |C|, |D-gap| in 1…span: cut after p1, p2, p3 (positions)
        start = _below(state, n)
        l1 = 1 + _below(state, span)
        l2 = 1 + _below(state, span)
        a1 = tour[start]
        b1 = tour[(start + 1) % n]
        b2 = tour[(start + l1) % n]
        c1 = tour[(start + l1 + 1) % n]
        c2 = tour[(start + l1 + l2) % n]
        d1 = tour[(start + l1 + l2 + 1) % n]
        delta = (D[a1, c1] + D[c2, b1] + D[b2, d1]) - (D[a1, b1] + D[b2, c1] + D[c2, d1])
        count = 0
        _two_opt(tour, pos, a1, b1, c2, d1)
        count = _log(log, count, a1, b1, c2, d1)
        _two_opt(tour, pos, a1, c2, c1, b2)
        count = _log(log, count, a1, c2, c1, b2)
        _two_opt(tour, pos, c2, b2, b1, d1)
        count = _log(log, count, c2, b2, b1, d1)
        for node in (a1, b1, b2, c1, c2, d1):
            size = _push(queue, queued, head, size, node)
        gain, head, count = _local_search(D, nbr, tour, pos, queue, queued, head, size, log, count, eps)
        size = 0
        if delta - gain <= eps and count <= log.shape[0]:
            if delta - gain < -eps:
                kept += 1
            continue
        # undo: the inverse of replacing (a, b), (c, d) by (a, c), (b, d), in reverse order
        if count > log.shape[0]:  # too many moves to undo (never seen): recompute the positions only
            continue
        for m in range(count - 1, -1, -1):
            a, b, c, d = log[m, 0], log[m, 1], log[m, 2], log[m, 3]
            _two_opt(tour, pos, a, c, b, d)
    return done, kept


# ------------------------------------------------------------------------------------- the method
def _closed_matrix(instance: SequencingInstance) -> tuple[np.ndarray, int | None]:
    """The symmetric closed-tour matrix (module docstring) and the dummy's index (None: closed)."""
    C = (instance.cost + instance.cost.T) / 2
    n = instance.n
    if instance.closed:
        return np.ascontiguousarray(C), None
    penalty = 3.0 * float(np.abs(C).max()) + 1.0
    D = np.zeros((n + 1, n + 1))
    D[:n, :n] = C
    pinned = [i for i in (instance.start, instance.end) if i is not None]
    if pinned:
        D[n, :n] = penalty
        D[n, pinned] = 0.0
        D[:n, n] = D[n, :n]
    return D, n


def _neighbour_lists(D: np.ndarray, k: int) -> np.ndarray:
    n = len(D)
    k = min(k, n - 1)
    masked = D + np.diag(np.full(n, np.inf))
    part = np.argpartition(masked, k - 1, axis=1)[:, :k] if k < n - 1 else np.argsort(masked, axis=1)[:, :k]
    costs = np.take_along_axis(masked, part, axis=1)
    order = np.lexsort((part, costs), axis=1)  # cheapest first, ties by index: the same on every machine
    return np.ascontiguousarray(np.take_along_axis(part, order, axis=1), dtype=np.int64)


def _decode(tour: np.ndarray, dummy: int | None, instance: SequencingInstance) -> np.ndarray:
    """The order of the instance's waypoints: the tour cut at the dummy (oriented to the fixed start,
    or away from the fixed end), or a closed tour rotated to its start."""
    tour = np.asarray(tour, dtype=np.int64)
    if dummy is None:
        first = 0 if instance.start is None else instance.start
        i = int(np.flatnonzero(tour == first)[0])
        return np.roll(tour, -i)
    i = int(np.flatnonzero(tour == dummy)[0])
    order = np.roll(tour, -i)[1:]
    if instance.start is not None and order[0] != instance.start or instance.start is None and instance.end is not None and order[0] == instance.end:
        order = order[::-1]
    return order.copy()


def _greedy_tour(D: np.ndarray) -> np.ndarray:
    """The nearest-neighbour tour from node 0 (the package's one construction)."""
    from htetro_opt.solvers.sequencing._local import nearest_neighbour_paths

    return nearest_neighbour_paths(D, [0])[0]


def solve_ils(instance, *, seed=0, time_limit: float | None = None, kicks: int | None = None,
              neighbours: int = ILS_NEIGHBOURS) -> tuple[np.ndarray, dict]:
    """Iterated local search (2-opt + Or-opt, local double-bridge kicks), compiled and seeded.

    Parameters
    ----------
    instance : SequencingInstance
        Symmetric costs; an open path (fixed or free start and end) or a closed tour.
    seed : None, int or numpy.random.Generator
        Seed of the kicks: an int or a Generator gives the same order on every machine (unless the
        time cap stops the search first), None fresh entropy.
    time_limit : float, optional
        A safety cap in seconds (None: 60 s + 1 s per 20 waypoints, at most 600 s): the search
        stops at the first chunk of kicks that ends after it, and ``info["timed_out"]`` says so.
    kicks : int, optional
        Kicks of the iterated local search (None: :func:`ils_kicks` of the node count; 0: local
        search only).
    neighbours : int
        Size of the neighbour lists.

    Returns
    -------
    order : ndarray of int64
    info : dict
        ``engine`` (``"numba"``, or the fallback), ``kicks`` (done), ``improving_kicks``,
        ``timed_out``, ``initial_cost`` (nearest neighbour, on the closed-tour matrix).

    Raises
    ------
    ParameterError
        On an asymmetric instance, a negative ``kicks``, ``neighbours < 1`` or an invalid seed or
        time limit.

    Examples
    --------
    >>> from htetro_opt.problems.waypoint_sequencing import SequencingInstance
    >>> x = np.array([0.0, 5, 1, 4, 2, 3])
    >>> inst = SequencingInstance.from_matrix(np.abs(np.subtract.outer(x, x)), start=0)
    >>> order, info = solve_ils(inst, kicks=50)
    >>> order.tolist(), inst.path_cost(order)
    ([0, 2, 4, 5, 3, 1], 5.0)
    """
    instance = check_instance(instance)
    if not instance.symmetric:
        raise ParameterError("method 'ils' assumes a symmetric cost matrix: use one of lkh, ortools, exact, greedy")
    time_limit = check_time_limit(time_limit)
    if time_limit is None:
        time_limit = default_time_limit("ils", instance.n)
    kicks = check_int(kicks, "kicks", minimum=0, allow_none=True)
    neighbours = check_int(neighbours, "neighbours", minimum=1)
    rng = as_rng(seed)
    stream = int(rng.integers(0, 2**63))
    began = time.perf_counter()
    if not HAVE_NUMBA:
        return _fallback(instance, rng, time_limit)
    D, dummy = _closed_matrix(instance)
    m = len(D)
    if kicks is None:
        kicks = ils_kicks(m)
    if m < 8:  # every tour through node 0, no kick can help
        from itertools import permutations

        tours = np.array([(0, *p) for p in permutations(range(1, m))], dtype=np.int64).reshape(-1, m)
        costs = D[tours, np.roll(tours, -1, axis=1)].sum(axis=1)
        best = tours[int(np.argmin(costs))]
        cost = float(costs.min())
        return _decode(best, dummy, instance), {"engine": "enumeration", "initial_cost": cost, "kicks": 0,
                                                "improving_kicks": 0, "timed_out": False, "tour_cost": cost}
    nbr = _neighbour_lists(D, neighbours)
    tour = _greedy_tour(D).astype(np.int64)
    info = {"engine": "numba", "initial_cost": float(_tour_cost(D, tour))}
    eps = 1e-9 * max(1.0, float(np.abs(D).max()))
    done = kept = 0
    timed_out = False
    # chunks of kicks, each with its own stream draw, so that the cap can stop between them
    chunk = max(1000, kicks // 64)
    first = True
    while first or done < kicks:
        step = min(chunk, kicks - done)
        d, k = _ils(D, nbr, tour, step, ILS_KICK_SPAN, np.uint64((stream + 0x9E37 * done) % 2**64), eps)
        first = False
        done += d
        kept += k
        if step == 0:
            break
        if time_limit is not None and time.perf_counter() - began > time_limit and done < kicks:
            timed_out = True
            break
    info.update(kicks=done, improving_kicks=kept, timed_out=timed_out, tour_cost=float(_tour_cost(D, tour)))
    return _decode(tour, dummy, instance), info


def _fallback(instance, rng, time_limit):
    """Without numba: ``local`` with restarts under the cap (its default time budget when None)."""
    from htetro_opt.solvers.sequencing._dispatch import sequence_waypoints

    result = sequence_waypoints(instance, method="local", seed=rng, time_limit=time_limit, restarts=10**9)
    return result.order, {**result.info, "engine": "local (numba is not installed)"}
