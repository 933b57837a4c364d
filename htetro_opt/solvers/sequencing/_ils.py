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

- **Costs**: the dense matrix, or, for an implicit instance (no n × n matrix, above
  :data:`~htetro_opt.problems.waypoint_sequencing.DENSE_LIMIT` waypoints), eq. 2 computed from the
  block cells at each look-up, so that memory stays linear in n (benchmarks/README.md, "TSPLIB,
  a map with obstacles, memory linear in n"); or, for a TSPLIB coordinate instance (``EUC_2D``,
  ``CEIL_2D``, ``ATT``, ``GEO``, at any size), TSPLIB's integer metric of the coordinates at each look-up
  (:func:`_tsplib`, the formulas of :mod:`htetro_opt.scenarios.tsplib`). The kernel is compiled once per
  kind (:func:`_d`), so the dense case pays nothing for the others.
- **Neighbour lists**: each node's :data:`ILS_NEIGHBOURS` cheapest other nodes: from the matrix, or
  (implicit) the cheapest by eq. 2 among the ``4k`` nearest by the weighted centre of the blocks, a
  k-d tree query (eq. 2 is at least Σw times the centres' distance), or by the TSPLIB metric among the
  ``4k`` nearest coordinates (GEO: points on the unit sphere); ties go to the lowest index, with the
  matrix and without, so both give the same lists. Each node's legs to its neighbours are priced once
  per run. With ``candidates="alpha"`` (a choice of ours, the default up to :data:`ILS_ALPHA_AUTO`
  waypoints): each node's alpha-nearest instead (Helsgaun 2000, LKH's candidate sets, section
  "alpha-nearness candidates" below), still ordered by cost.
- **Start**: the nearest-neighbour tour from node 0 (dense; a TSPLIB coordinate instance builds the same
  tour with a k-d tree, from its start on an open path), or the waypoints along a Hilbert curve through
  their block centres (implicit eq. 2: nearest neighbour needs every row of the matrix).
- **Local search**: a queue of active nodes (the don't-look bits: a node whose moves all failed
  leaves the queue until an edge at it changes). For an active node ``a``, every 2-opt move that
  creates an edge from ``a`` (either tour direction) to a neighbour cheaper than the edge it
  replaces (with ``lk_depth`` above 0, in ``ils`` only: the LK-style move of :func:`_lk_move`
  instead, 2-opt and sequential 3-opt moves along the neighbour lists, Lin and Kernighan 1973), and
  every Or-opt move of a segment of 1–3 nodes beginning or ending at ``a`` to an edge
  next to one of its ends' neighbours, as it is or reversed; the first improving move is applied.
  Every move is a sequence of 2-opt moves (an Or-opt is two or three), each reversing the shorter
  side of the tour array, and logged, so that a rejected kick is undone exactly. A *full* pass
  (:meth:`LocalCore.descend`, not the ILS) takes every other node as a candidate and prunes
  nothing, so that one from every node that finds no move proves a local optimum of the whole
  neighbourhood.
- **Kicks**: a double bridge ``A B C D → A C B D`` whose three segments are 1–:data:`ILS_KICK_SPAN`
  nodes long (a *local* double bridge: it changes the tour near one random node), the local search
  restarted from the 8 nodes it touched, the result kept if it is no costlier, undone otherwise.
- **Budget**: :func:`ils_kicks` kicks, a function of ``n`` only, from a generator seeded by
  ``seed`` (a splitmix64 stream inside the compiled code), so the same seed gives the same order on
  every machine. ``time_limit`` is only a safety cap: when it stops the search first, the result
  says so (``info["timed_out"]``) and is no longer reproducible.

The kernel is compiled by numba (≥ 0.59, a core dependency, so that ``auto`` gives the same order on
every install; without it importing this module raises
:class:`~htetro_opt.errors.DependencyError`, :func:`htetro_opt._jit.require_numba`). This module
is imported when a search first runs, never by importing :mod:`htetro_opt.solvers.sequencing`.
:class:`LocalCore` runs the same local search on given orders: it is the package's one 2-opt /
Or-opt local search, the memetic GA's local step (:meth:`LocalCore.improve`) and, with the full
passes (:meth:`LocalCore.descend`), the ``local`` method's and
:func:`~htetro_opt.solvers.sequencing.improve`'s.
"""

from __future__ import annotations

import math
import time

import numpy as np

from htetro_opt._interrupt import kernel_flag
from htetro_opt._jit import require_numba
from htetro_opt._validation import as_rng, check_bool, check_int, check_real, check_time_limit
from htetro_opt.errors import ParameterError
from htetro_opt.problems.waypoint_sequencing import SequencingInstance, check_instance, eq2_legs
from htetro_opt.solvers.sequencing._budgets import default_time_limit
from htetro_opt.solvers.sequencing._spec import (ILS_ACCEPT_WORSE, ILS_ALPHA_AUTO, ILS_ALPHA_LIMIT,
                                                  ILS_ALPHA_PAIR_SECONDS, ILS_ALPHA_TREES, ILS_KICK_RATE,
                                                  ILS_KICK_SPAN, ILS_LK_DEPTH, ILS_NEIGHBOURS, ILS_OR3OPT,
                                                  check_candidates)

__all__ = ["ILS_KICK_SPAN", "LocalCore", "ils_kicks", "solve_ils"]


_UNLIMITED = 1 << 62
"""A move budget that never runs out."""

# The kernels pass each other constants as np.int64(...) / np.bool_(...), never bare: numba types a bare
# constant argument as a literal and compiles the callee once more for it (the local search, the longest
# compile, was built up to six times a cost kind; benchmarks/README.md, "Compiling ahead").

numba = require_numba()  # the kernels below are compiled at their first call
from numba.extending import overload  # noqa: E402 - only once numba is known to import

_jit = numba.njit(cache=True, nogil=True)


def ils_kicks(n: int) -> int:
    """The number of kicks ``ils`` makes on ``n`` nodes: ``400 · n`` + 1000, at most 1 000 000.

    The cap keeps large instances within about a minute (1.5 M kicks on the 3868-waypoint furniture
    map of benchmarks/README.md ended 0.01 % below where 0.6 M did).

    Examples
    --------
    >>> ils_kicks(100), ils_kicks(1000), ils_kicks(100_000)
    (41000, 401000, 1000000)
    """
    return int(min(1_000_000, 400 * n + 1000))


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
    if y == p and x == nx:  # a tour of the segment, p and nx only: the segment reversed in place
        _two_opt(tour, pos, p, s1, s2, nx)
        return _log(log, count, p, s1, s2, nx)
    if y == p:  # the edge just before p (only the full search tries it): reverse p…s2, then s2…s1 back
        _two_opt(tour, pos, x, p, s2, nx)
        count = _log(log, count, x, p, s2, nx)
        if forward:
            _two_opt(tour, pos, x, s2, s1, p)
            count = _log(log, count, x, s2, s1, p)
        return count
    _two_opt(tour, pos, p, s1, x, y)
    count = _log(log, count, p, s1, x, y)
    _two_opt(tour, pos, p, x, nx, s2)
    count = _log(log, count, p, x, nx, s2)
    if forward:
        _two_opt(tour, pos, x, s2, s1, y)
        count = _log(log, count, x, s2, s1, y)
    return count


def _d(cm, a, b):
    """The cost of the leg (a, b). ``cm`` is a dense matrix, the tuple ``(P, w, pen)`` of an implicit
    eq.-2 instance (block cells ``P`` (m, 4, 2) and weights ``w`` of eq. 2), or the tuple
    ``(X, kind, pen)`` of a TSPLIB coordinate instance (:func:`_tsplib`); ``pen[j]`` the leg from the
    dummy node ``m`` to node ``j``. (Plain Python; the kernel's compiled twin is below.)"""
    if isinstance(cm, np.ndarray):
        return cm[a, b]
    return _tsplib(cm, a, b) if isinstance(cm[1], (int, np.integer)) else _eq2(cm, a, b)


def _eq2(cm, a, b):
    """Eq. 2 of an implicit instance's leg (a, b), or the dummy's leg."""
    P, w, pen = cm
    m = P.shape[0]
    if a == m:
        return pen[b]
    if b == m:
        return pen[a]
    total = 0.0
    for block in range(4):
        dx = P[a, block, 0] - P[b, block, 0]
        dy = P[a, block, 1] - P[b, block, 1]
        total += w[block] * math.sqrt(dx * dx + dy * dy)
    return total


_EUC_2D, _CEIL_2D, _ATT, _GEO = range(4)
_METRIC_CODES = {"EUC_2D": _EUC_2D, "CEIL_2D": _CEIL_2D, "ATT": _ATT, "GEO": _GEO}
"""The ``kind`` of a TSPLIB cost model, by EDGE_WEIGHT_TYPE (htetro_opt.scenarios.tsplib.IMPLICIT_TYPES)."""


def _tsplib(cm, a, b):
    """TSPLIB's integer distance of the leg (a, b) of a coordinate instance, or the dummy's leg: ``X`` the
    (m, 2) coordinates (GEO: latitude and longitude in TSPLIB's radians), ``kind`` a :data:`_METRIC_CODES`
    value, the same formulas as :mod:`htetro_opt.scenarios.tsplib` (``nint(v) = ⌊v + 0.5⌋``)."""
    X, kind, pen = cm
    m = X.shape[0]
    if a == m:
        return pen[b]
    if b == m:
        return pen[a]
    if a == b:
        return 0.0
    if kind == _GEO:
        q1 = math.cos(X[a, 1] - X[b, 1])
        q2 = math.cos(X[a, 0] - X[b, 0])
        q3 = math.cos(X[a, 0] + X[b, 0])
        v = min(1.0, max(-1.0, 0.5 * ((1.0 + q1) * q2 - (1.0 - q1) * q3)))
        return math.floor(6378.388 * math.acos(v) + 1.0)
    dx = X[a, 0] - X[b, 0]
    dy = X[a, 1] - X[b, 1]
    if kind == _ATT:
        r = math.sqrt((dx * dx + dy * dy) / 10.0)
        t = math.floor(r + 0.5)
        return t + 1.0 if t < r else t
    e = math.sqrt(dx * dx + dy * dy)
    if kind == _CEIL_2D:
        return math.ceil(e)
    return math.floor(e + 0.5)


# Chosen by type when the kernel compiles, so a dense matrix costs one load, as if written inline:
# a run-time branch between the kinds (or a call LLVM does not inline) made the kernel 8x slower.
# Within a TSPLIB model the metric is a run-time branch on ``kind``, the same for every leg of a run.
@overload(_d, jit_options={"cache": True})
def _d_compiled(cm, a, b):
    if isinstance(cm, numba.types.Array):
        return lambda cm, a, b: cm[a, b]
    if isinstance(cm.types[1], numba.types.Integer):
        return _tsplib
    return _eq2


@_jit
def _lk_move(cm, nbr, nc, tour, pos, log, count, t1, back, depth, eps, touched, added):
    """An LK-style move from ``t1`` (Lin and Kernighan 1973, as a chain of 2-opt flips): (gain, moves
    logged, nodes touched, in ``touched[:returned]``); gain 0 and the tour unchanged when no closed tour
    along the chains gains.

    Break the edge from ``t1`` to its successor (``back`` 0) or predecessor ``t2``; at each level add an
    edge from the chain's free end ``t2`` to a neighbour ``t3`` whose leg leaves a positive partial gain
    and break the edge (t4, t3), t4 the neighbour of t3 on t2's side, which closes the tour again (a
    2-opt flip), then go on from t4, up to ``depth`` flips, never breaking an edge the move added.

    The first two levels are priced on the tour as it is (the positions tell which side of the first
    flip a node lies on), every first-level candidate and every second-level one: the best closing of
    these, a 2-opt or a sequential 3-opt move, is made at once. Only when neither gains does the chain
    go deeper: the two flips are made for real, with the second level's best candidate by
    ``d(t5, t6) - d(t4, t5)``, and so on; the flips up to the best closed tour are kept, the rest undone.
    """
    n = tour.shape[0]
    k = nbr.shape[1]
    s = 1 if back == 0 else -1  # the tour direction from t1 to t2
    t2 = tour[(pos[t1] + s) % n]
    d12 = _d(cm, t1, t2)
    base = count
    for j0 in range(k):
        g1 = d12 - nc[t2, j0]
        if g1 <= eps:  # the list is sorted: no later first edge leaves a gain
            break
        t3 = nbr[t2, j0]
        if t3 == t1:
            continue
        # (an undone deeper chain leaves the same cycle, but perhaps the array the other way round)
        s = 1 if tour[(pos[t1] + 1) % n] == t2 else -1
        t4 = tour[(pos[t3] - s) % n]
        if t4 == t2:
            continue
        g = g1 + _d(cm, t3, t4)
        best = g - _d(cm, t4, t1)  # the 2-opt move
        level = 0
        if best <= eps:  # no gain yet: a 3-opt move must gain more than eps
            best, level = eps, -1
        b5 = b6 = np.int64(-1)
        # level 2 on the tour after the first flip, which reverses S = t2 … t4 (direction s)
        span = ((pos[t4] - pos[t2]) * s) % n
        p5 = p6 = np.int64(-1)
        pv = -np.inf
        for j in range(k):
            g2 = g - nc[t4, j]
            if g2 <= eps:
                break
            t5 = nbr[t4, j]
            if t5 == t1 or t5 == t3:  # t3: t6 would be t2, breaking the edge just added
                continue
            if ((pos[t5] - pos[t2]) * s) % n <= span:  # inside S: its order reversed
                t6 = tour[(pos[t5] + s) % n]
            else:
                t6 = tour[(pos[t5] - s) % n]
            if t6 == t4:
                continue
            v = _d(cm, t5, t6) - nc[t4, j]
            close = g + v - _d(cm, t6, t1)
            if close > best:
                best, level, b5, b6 = close, 1, t5, t6
            if v > pv:
                pv, p5, p6 = v, t5, t6
        if level >= 0:
            _two_opt(tour, pos, t1, t2, t4, t3)  # (t1, t2), (t4, t3) → (t1, t4), (t2, t3)
            count = _log(log, count, t1, t2, t4, t3)
            touched[0], touched[1], touched[2], touched[3] = t1, t2, t3, t4
            if level == 0:
                return best, count, 4
            _two_opt(tour, pos, t1, t4, b6, b5)
            count = _log(log, count, t1, t4, b6, b5)
            touched[4], touched[5] = b5, b6
            return best, count, 6
        if depth <= 2 or p5 < 0 or count + depth >= log.shape[0]:
            continue
        # deeper: the two flips for real, then one candidate a level
        _two_opt(tour, pos, t1, t2, t4, t3)
        count = _log(log, count, t1, t2, t4, t3)
        _two_opt(tour, pos, t1, t4, p6, p5)
        count = _log(log, count, t1, t4, p6, p5)
        touched[0], touched[1], touched[2], touched[3], touched[4], touched[5] = t1, t2, t3, t4, p5, p6
        nt = 6
        added[0, 0], added[0, 1], added[1, 0], added[1, 1] = t2, t3, t4, p5
        g += pv
        best = 0.0
        best_count = base
        e = p6
        for lv in range(2, depth):
            fwd = 1 if tour[(pos[t1] + 1) % n] == e else -1
            pick = pick4 = np.int64(-1)
            pick_val = -np.inf
            for j in range(k):
                if g - nc[e, j] <= eps:
                    break
                c = nbr[e, j]
                if c == t1:
                    continue
                d = tour[(pos[c] - fwd) % n]
                if d == e:
                    continue
                tabu = False
                for q in range(lv):  # (d, c) must not be an edge this move added
                    if (added[q, 0] == c and added[q, 1] == d) or (added[q, 0] == d and added[q, 1] == c):
                        tabu = True
                        break
                if tabu:
                    continue
                v = _d(cm, c, d) - nc[e, j]
                if v > pick_val:
                    pick_val, pick, pick4 = v, c, d
            if pick < 0:
                break
            _two_opt(tour, pos, t1, e, pick4, pick)
            count = _log(log, count, t1, e, pick4, pick)
            added[lv, 0], added[lv, 1] = e, pick
            touched[nt], touched[nt + 1] = pick, pick4
            nt += 2
            g += pick_val
            close = g - _d(cm, pick4, t1)
            if close > best + eps:
                best, best_count = close, count
            e = pick4
        for m in range(count - 1, best_count - 1, -1):  # back to the best closed tour along the chain
            a, b, c, d = log[m, 0], log[m, 1], log[m, 2], log[m, 3]
            _two_opt(tour, pos, a, c, b, d)
        count = best_count
        if best > eps:
            return best, count, nt
    return 0.0, base, 0


@_jit
def _or3_move(cm, nbr, nc, tour, pos, log, count, t1, back, eps, touched):
    """A sequential 3-opt move from ``t1`` that no pair of 2-opt flips along the chain reaches: the
    segment exchange (or-3opt): (gain, moves logged, nodes touched, in ``touched[:returned]``); gain 0 and
    the tour unchanged when none gains.

    Break (t1, t2), t2 the successor (``back`` 0) or predecessor of t1; add (t2, t3), t3 a neighbour of t2
    whose leg leaves a positive partial gain; break (t3, t4), t4 the neighbour of t3 *away* from t2's side
    (the choice a 2-opt flip cannot close), which leaves the segment S = t2 … t3 as a cycle and the rest as
    a path t4 … t1; add (t4, t5), t5 a neighbour of t4 inside S, and break an edge (t5, t6) of S: t6 after
    t5 gives the two halves of S swapped (t1 t6 … t3 t2 … t5 t4), t6 before t5 the two halves reversed in
    place (t1 t6 … t2 t3 … t5 t4). The first closing that gains is made (three or two flips, logged).
    """
    n = tour.shape[0]
    k = nbr.shape[1]
    s = 1 if back == 0 else -1
    t2 = tour[(pos[t1] + s) % n]
    d12 = _d(cm, t1, t2)
    for j0 in range(k):
        g1 = d12 - nc[t2, j0]
        if g1 <= eps:  # sorted lists: no later t3 leaves a gain
            break
        t3 = nbr[t2, j0]
        if t3 == t1:
            continue
        span = ((pos[t3] - pos[t2]) * s) % n  # S = t2 … t3 in direction s: positions 0 … span
        if span < 1 or span >= n - 2:  # S one node, or t4 would be t1
            continue
        t4 = tour[(pos[t3] + s) % n]
        g2 = g1 + _d(cm, t3, t4)
        for j in range(k):
            g3 = g2 - nc[t4, j]
            if g3 <= eps:
                break
            t5 = nbr[t4, j]
            off = ((pos[t5] - pos[t2]) * s) % n
            if off > span:  # not in S
                continue
            if off < span:  # t6 after t5: the halves t2 … t5 and t6 … t3 swapped
                t6 = tour[(pos[t5] + s) % n]
                gain = g3 + _d(cm, t5, t6) - _d(cm, t6, t1)
                if gain > eps:
                    _two_opt(tour, pos, t1, t2, t3, t4)  # t1 [t3 … t6][t5 … t2] t4
                    count = _log(log, count, t1, t2, t3, t4)
                    _two_opt(tour, pos, t1, t3, t6, t5)  # t1 [t6 … t3][t5 … t2] t4
                    count = _log(log, count, t1, t3, t6, t5)
                    _two_opt(tour, pos, t3, t5, t2, t4)  # t1 [t6 … t3][t2 … t5] t4
                    count = _log(log, count, t3, t5, t2, t4)
                    touched[0], touched[1], touched[2], touched[3], touched[4], touched[5] = t1, t2, t3, t4, t5, t6
                    return gain, count, 6
            if off > 0:  # t6 before t5: both halves reversed in place
                t6 = tour[(pos[t5] - s) % n]
                gain = g3 + _d(cm, t5, t6) - _d(cm, t6, t1)
                if gain > eps:
                    _two_opt(tour, pos, t1, t2, t6, t5)  # t1 [t6 … t2][t5 … t3] t4
                    count = _log(log, count, t1, t2, t6, t5)
                    _two_opt(tour, pos, t2, t5, t3, t4)  # t1 [t6 … t2][t3 … t5] t4
                    count = _log(log, count, t2, t5, t3, t4)
                    touched[0], touched[1], touched[2], touched[3], touched[4], touched[5] = t1, t2, t3, t4, t5, t6
                    return gain, count, 6
    return 0.0, count, 0


@_jit
def _local_search(cm, nbr, nc, tour, pos, queue, queued, head, size, log, count, eps, opt2, lengths, full,
                  budget, halt, lk, or3):
    """Improve the tour from the queued nodes until the queue is empty or ``budget`` moves are made:
    (gain, head, moves logged, moves made). Stops early when ``halt[0]`` is set (a signal, see
    :func:`htetro_opt._interrupt.kernel_flag`; the caller's result is then thrown away).

    ``opt2``: try 2-opt moves; ``lengths``: the Or-opt segment lengths, ascending (empty: no Or-opt);
    ``lk``: with ``opt2`` and not ``full``, the LK-style moves of :func:`_lk_move` of at most ``lk``
    flips in place of the 2-opt moves (0: 2-opt); ``or3``: with ``opt2`` and not ``full``, then the segment
    exchanges of :func:`_or3_move` where no 2-opt (LK) or Or-opt move gains.
    Restricted (``full`` False, the ILS): a node's candidates are its neighbour list ``nbr`` (legs
    ``nc``, cheapest first), and the scan of a list stops at the first neighbour whose leg leaves no
    gain. ``full``: every other node is a candidate and nothing is pruned, so that a pass from every
    node that makes no move proves the tour a local optimum of the whole 2-opt / Or-opt neighbourhood.
    """
    n = tour.shape[0]
    k = n - 1 if full else nbr.shape[1]
    gain_total = 0.0
    moves = 0
    touched = np.empty(2 * max(lk, 3) + 2, dtype=np.int64)
    added = np.empty((max(lk, 1), 2), dtype=np.int64)
    while size > 0 and moves < budget:
        if halt[0]:  # one byte read a node: nothing next to the node's scan of its candidates
            break
        a = queue[head]
        head = (head + 1) % n
        size -= 1
        queued[a] = False
        improved = False
        if lk > 0 and opt2 and not full:
            for direction in range(2):
                gain, count, nt = _lk_move(cm, nbr, nc, tour, pos, log, count, a, direction, lk, eps, touched, added)
                if gain > eps:
                    gain_total += gain
                    moves += 1
                    for t in range(nt):
                        size = _push(queue, queued, head, size, touched[t])
                    improved = True
                    break
        # 2-opt: a new edge (a, c), c a candidate, in both directions of the tour (full: one is
        # enough, every pair of edges being (a, succ a) and (c, succ c) for some a)
        for direction in range((1 if full else 2) if opt2 and not (lk > 0 and not full) else 0):
            if improved:
                break
            if direction == 0:
                b = tour[(pos[a] + 1) % n]
            else:
                b = tour[(pos[a] - 1) % n]
            d_ab = _d(cm, a, b)
            for t in range(k):
                if full:
                    c = t if t < a else t + 1
                    g1 = d_ab - _d(cm, a, c)
                else:
                    c = nbr[a, t]
                    g1 = d_ab - nc[a, t]
                    if g1 <= eps:  # the list is sorted: no later neighbour gives a cheaper first edge
                        break
                if direction == 0:
                    d = tour[(pos[c] + 1) % n]
                else:
                    d = tour[(pos[c] - 1) % n]
                if c == b or d == a:
                    continue
                gain = g1 + _d(cm, c, d) - _d(cm, b, d)
                if gain > eps:
                    if direction == 0:
                        _two_opt(tour, pos, a, b, c, d)
                        count = _log(log, count, a, b, c, d)
                    else:
                        _two_opt(tour, pos, b, a, d, c)
                        count = _log(log, count, b, a, d, c)
                    gain_total += gain
                    moves += 1
                    size = _push(queue, queued, head, size, a)
                    size = _push(queue, queued, head, size, b)
                    size = _push(queue, queued, head, size, c)
                    size = _push(queue, queued, head, size, d)
                    improved = True
                    break
        if improved:
            continue
        # Or-opt: a segment with a at one end, next to a candidate (full: into any edge)
        for li in range(lengths.shape[0]):
            if improved:
                break
            length = lengths[li]
            if length > n - 2:  # p and nx would not both lie outside the segment
                break
            for direction in range(1 if full else 2):  # full: every segment begins at some a
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
                removal = _d(cm, p, s1) + _d(cm, s2, nx) - _d(cm, p, nx)
                if removal <= eps and not full:
                    continue
                for t in range(k):
                    if full:
                        c = t if t < a else t + 1
                    else:
                        c = nbr[a, t]
                        if removal - nc[a, t] <= eps:
                            break
                    # c must lie outside the segment
                    off = (pos[c] - i) % n
                    if off < length:
                        continue
                    # the two edges at c: (c, succ c) and (pred c, c); the full search, whose c are
                    # all the nodes, needs only the first
                    for side in range(1 if full else 2):
                        if side == 0:
                            x, y = c, tour[(pos[c] + 1) % n]
                        else:
                            x, y = tour[(pos[c] - 1) % n], c
                        if x == s2 or y == s1:  # (s2, nx) or (p, s1): no move at all
                            continue
                        if y == p and not full:  # the edge before p: only the full search tries it
                            # (so the ILS makes the moves it always made)
                            continue
                        if (pos[x] - i) % n < length or (pos[y] - i) % n < length:
                            continue
                        # the legs to the segment's ends are read from their rows (the costs are
                        # symmetric), which stay in the cache while c runs over the candidates
                        base = removal + _d(cm, x, y)
                        fwd = base - _d(cm, s1, x) - _d(cm, s2, y)
                        rev = base - _d(cm, s2, x) - _d(cm, s1, y)
                        if fwd >= rev and fwd > eps:
                            count = _or_move(tour, pos, log, count, p, s1, s2, nx, x, y, np.bool_(True))
                            gain_total += fwd
                            improved = True
                        elif rev > fwd and rev > eps:
                            count = _or_move(tour, pos, log, count, p, s1, s2, nx, x, y, np.bool_(False))
                            gain_total += rev
                            improved = True
                        if improved:
                            moves += 1
                            for node in (a, p, nx, s1, s2, x, y):
                                size = _push(queue, queued, head, size, node)
                            break
                    if improved:
                        break
        if improved or not or3 or full or not opt2:
            continue
        for direction in range(2):
            gain, count, nt = _or3_move(cm, nbr, nc, tour, pos, log, count, a, direction, eps, touched)
            if gain > eps:
                gain_total += gain
                moves += 1
                for t in range(nt):
                    size = _push(queue, queued, head, size, touched[t])
                break
    return gain_total, head, count, moves


@_jit
def _tour_cost(cm, tour):
    n = tour.shape[0]
    total = 0.0
    for i in range(n):
        total += _d(cm, tour[i], tour[(i + 1) % n])
    return total


@_jit
def _legs(cm, a, b):
    """The kernel's costs of the legs ``a[k] → b[k]``."""
    out = np.empty(a.shape[0])
    for i in range(a.shape[0]):
        out[i] = _d(cm, a[i], b[i])
    return out


@_jit
def _neighbour_costs(cm, nbr):
    """Each node's legs to its neighbours, the search's most frequent look-ups, priced once (eq. 2 has
    four square roots a leg)."""
    nc = np.empty(nbr.shape)
    for a in range(nbr.shape[0]):
        for t in range(nbr.shape[1]):
            nc[a, t] = _d(cm, a, nbr[a, t])
    return nc


@_jit
def _descend(cm, nbr, nc, tour, opt2, lengths, full, eps, budget, halt):
    """One pass of the local search (:func:`_local_search`) from every node of the tour, in place, until
    no queued node has an improving move or ``budget`` moves are made: the moves made."""
    n = tour.shape[0]
    pos = np.empty(n, dtype=np.int64)
    for i in range(n):
        pos[tour[i]] = i
    queue = np.empty(n, dtype=np.int64)
    queued = np.zeros(n, dtype=np.bool_)
    zero = np.int64(0)
    size = zero
    for i in range(n):
        size = _push(queue, queued, zero, size, tour[i])
    log = np.empty((0, 4), dtype=np.int64)  # nothing is undone: no move is logged
    _, _, _, moves = _local_search(cm, nbr, nc, tour, pos, queue, queued, zero, size, log, zero, eps, opt2, lengths,
                                   full, budget, halt, zero, np.bool_(False))
    return moves


@_jit
def _ils(cm, nbr, tour, kicks, span, seed, eps, halt, lk, or3, worse):
    """Local search, then ``kicks`` kicks (double bridges); the tour in place. Returns (kicks done,
    kicks that lowered the cost). Stops early when ``halt[0]`` is set (see :func:`_local_search`).
    ``lk``: the depth of the LK-style moves that replace the 2-opt moves (0: 2-opt, :func:`_lk_move`);
    ``or3``: the segment exchanges of :func:`_or3_move` too; ``worse``: a kick's result is kept when it is
    at most ``worse`` mean legs (of the start tour) above the best tour of the run, which the tour is set
    back to at the end (0: kept when no costlier than the current tour, which is then always the best)."""
    n = tour.shape[0]
    pos = np.empty(n, dtype=np.int64)
    for i in range(n):
        pos[tour[i]] = i
    queue = np.empty(n, dtype=np.int64)
    queued = np.zeros(n, dtype=np.bool_)
    log = np.empty((4 * n + 64, 4), dtype=np.int64)
    state = np.empty(1, dtype=np.uint64)
    state[0] = np.uint64(seed)
    nc = _neighbour_costs(cm, nbr)
    lengths = np.arange(1, 4)
    head = np.int64(0)
    size = np.int64(0)
    yes, no, unlimited = np.bool_(True), np.bool_(False), np.int64(_UNLIMITED)
    for i in range(n):
        size = _push(queue, queued, head, size, tour[i])
    _, head, _, _ = _local_search(cm, nbr, nc, tour, pos, queue, queued, head, size, log, np.int64(0), eps, yes,
                                  lengths, no, unlimited, halt, lk, or3)
    size = np.int64(0)
    kept = 0
    done = 0
    if n < 8:
        return done, kept
    span = min(span, (n - 2) // 3)
    walk = worse > 0.0
    best = np.empty(n if walk else 0, dtype=np.int64)
    cur = best_cost = 0.0
    allowance = 0.0
    if walk:
        best[:] = tour
        cur = best_cost = _tour_cost(cm, tour)
        allowance = worse * cur / n
    for _ in range(kicks):
        if halt[0]:
            break
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
        delta = (_d(cm, a1, c1) + _d(cm, c2, b1) + _d(cm, b2, d1)
                 - _d(cm, a1, b1) - _d(cm, b2, c1) - _d(cm, c2, d1))
        count = np.int64(0)
        _two_opt(tour, pos, a1, b1, c2, d1)
        count = _log(log, count, a1, b1, c2, d1)
        _two_opt(tour, pos, a1, c2, c1, b2)
        count = _log(log, count, a1, c2, c1, b2)
        _two_opt(tour, pos, c2, b2, b1, d1)
        count = _log(log, count, c2, b2, b1, d1)
        for node in (a1, b1, b2, c1, c2, d1):
            size = _push(queue, queued, head, size, node)
        gain, head, count, _ = _local_search(cm, nbr, nc, tour, pos, queue, queued, head, size, log, count, eps,
                                             yes, lengths, no, unlimited, halt, lk, or3)
        size = np.int64(0)
        if walk:
            if cur + delta - gain <= best_cost + allowance + eps and count <= log.shape[0]:
                cur += delta - gain
                if cur < best_cost - eps:
                    best_cost = cur
                    best[:] = tour
                    kept += 1
                continue
        elif delta - gain <= eps and count <= log.shape[0]:
            if delta - gain < -eps:
                kept += 1
            continue
        # undo: the inverse of replacing (a, b), (c, d) by (a, c), (b, d), in reverse order
        if count > log.shape[0]:  # too many moves to undo (never seen): recompute the positions only
            continue
        for m in range(count - 1, -1, -1):
            a, b, c, d = log[m, 0], log[m, 1], log[m, 2], log[m, 3]
            _two_opt(tour, pos, a, c, b, d)
    if walk and best_cost < cur - eps:
        tour[:] = best
    return done, kept


# ---------------------------------------------------------------------- alpha-nearness candidates
# Helsgaun 2000 (LKH), sections 4.1-4.2: a node's candidates are the nodes whose edge to it is nearest to
# being in a minimum 1-tree, with the node penalties pi of a subgradient ascent on the Held-Karp bound.
# None of the field's libraries computes them for a cost function given as a kernel (scipy's
# minimum_spanning_tree takes a matrix or a sparse graph, and the ascent needs hundreds of 1-trees with
# their special leaf), so they are here, compiled beside the costs they read.
_ALPHA_NEAREST = 10
"""Each node's nearest legs in the ascent's sparse graph (with two spanning trees of all the legs)."""


@_jit
def _heap_push(keys, vals, size, key, val):
    """Push (key, val) on the binary min-heap ``keys[:size]``, ``vals[:size]``: the new size."""
    i = size
    keys[i], vals[i] = key, val
    while i > 0:
        up = (i - 1) // 2
        if keys[up] <= keys[i]:
            break
        keys[up], keys[i] = keys[i], keys[up]
        vals[up], vals[i] = vals[i], vals[up]
        i = up
    return size + 1


@_jit
def _heap_pop(keys, vals, size):
    """Pop the least (key, val) of the heap: (key, val, the new size)."""
    key, val = keys[0], vals[0]
    size -= 1
    keys[0], vals[0] = keys[size], vals[size]
    i = 0
    while True:
        low = i
        for child in (2 * i + 1, 2 * i + 2):
            if child < size and keys[child] < keys[low]:
                low = child
        if low == i:
            break
        keys[low], keys[i] = keys[i], keys[low]
        vals[low], vals[i] = vals[i], vals[low]
        i = low
    return key, val, size


@_jit
def _row(cm, v, out):
    """``out[u]``: the leg ``v → u`` for every node ``u`` (the one part of the alpha lists compiled for each
    kind of costs; the rest, :func:`_prim_step` and :func:`_alpha_row`, once for all)."""
    for u in range(out.shape[0]):
        out[u] = _d(cm, v, u)


@_jit
def _prim_step(row, v, pi, avoid, key, parent, done):
    """Prim's step at the node ``v`` just joined (``row``: its legs): the keys of the others lowered, the
    next node to join returned (the legs (u, avoid[u]) left out)."""
    done[v] = True
    nxt, low = -1, np.inf
    for u in range(row.shape[0]):
        if done[u]:
            continue
        c = np.inf if (avoid[u] == v or avoid[v] == u) else row[u] + pi[v] + pi[u]
        if c < key[u]:
            key[u], parent[u] = c, v
        if key[u] < low:
            low, nxt = key[u], u
    return nxt


@_jit
def _dense_tree(cm, m, avoid, pi):
    """The parents of a minimum spanning tree over all ``m`` nodes under the penalties ``pi`` without the
    tree edges (v, avoid[v]) (Prim, O(m²) look-ups, node 0 the root; ``avoid`` all -1: none left out)."""
    key = np.full(m, np.inf)
    parent = np.full(m, -1, dtype=np.int64)
    done = np.zeros(m, dtype=np.bool_)
    row = np.empty(m)
    v = np.int64(0)
    for _ in range(m - 1):
        _row(cm, v, row)
        v = _prim_step(row, v, pi, avoid, key, parent, done)
    return parent


@_jit
def _one_tree(ptr, adj, cost, pi, parent, degree, key, done, hk, hv):
    """A minimum 1-tree of the sparse graph (``ptr``, ``adj``, ``cost``: rows of a symmetric CSR) under the
    penalties ``pi`` (legs ``cost + pi[a] + pi[b]``): a minimum spanning tree (Prim from node 0, a lazy
    heap) and the second cheapest edge of the leaf where that edge is dearest (LKH's choice of the special
    node). Its length, ``parent`` and ``degree`` filled in."""
    m = ptr.shape[0] - 1
    key[:] = np.inf
    done[:] = False
    parent[:] = -1
    degree[:] = 0
    key[0] = 0.0
    size = _heap_push(hk, hv, np.int64(0), 0.0, np.int64(0))
    total = 0.0
    while size > 0:
        kv, v, size = _heap_pop(hk, hv, size)
        if done[v] or kv > key[v]:
            continue
        done[v] = True
        total += kv
        if parent[v] >= 0:
            degree[parent[v]] += 1
            degree[v] += 1
        for e in range(ptr[v], ptr[v + 1]):
            u = adj[e]
            if done[u]:
                continue
            c = cost[e] + pi[v] + pi[u]
            if c < key[u]:
                key[u], parent[u] = c, v
                size = _heap_push(hk, hv, size, c, u)
    root_child = -1
    for u in range(m):
        if parent[u] == 0:
            root_child = u
            break
    best, ba, bb = -np.inf, -1, -1
    for v in range(m):
        if degree[v] != 1:
            continue
        partner = parent[v] if parent[v] >= 0 else root_child
        second, other = np.inf, -1
        for e in range(ptr[v], ptr[v + 1]):
            u = adj[e]
            c = cost[e] + pi[v] + pi[u]
            if u != partner and c < second:
                second, other = c, u
        if other >= 0 and second > best:
            best, ba, bb = second, v, other
    if ba >= 0:
        total += best
        degree[ba] += 1
        degree[bb] += 1
    return total


@_jit
def _ascent(ptr, adj, cost, upper, max_trees):
    """A subgradient ascent on the Held-Karp bound (Held and Karp 1970) over the sparse graph: the node
    penalties ``pi`` of the longest penalised 1-tree (its length less twice the penalties) in at most
    ``max_trees`` 1-trees, that length and the 1-trees computed.

    The step is Held, Wolfe and Crowder's (1974), ``lam · (upper - w) / |g|²`` along ``g``, LKH's blend
    ``0.7 (degree - 2) + 0.3 g_previous`` of the degrees (Helsgaun 2000, section 4.1), ``upper`` a tour's
    length, ``lam`` from 1 halved after 10 trees without a longer one. This step in place of LKH's own
    schedule (a step doubled while it gains, halved each period) is a choice of ours: on the complete graphs
    of rd400 and pcb442 LKH's schedule ended 4.3 % and 4.6 % below the optimum after 300 trees, this one
    0.82 % and 0.58 % (converged: 0.82 % and 0.56-0.61 % after 1000 trees, both)."""
    m = ptr.shape[0] - 1
    nnz = ptr[m]
    pi = np.zeros(m)
    best_pi = np.zeros(m)
    g = np.zeros(m)
    parent = np.empty(m, dtype=np.int64)
    degree = np.empty(m, dtype=np.int64)
    key = np.empty(m)
    done = np.empty(m, dtype=np.bool_)
    hk = np.empty(nnz + 1)
    hv = np.empty(nnz + 1, dtype=np.int64)
    lam, best_w, stalled, trees = 1.0, -np.inf, 0, 0
    while trees < max_trees and lam > 1e-6:
        w = _one_tree(ptr, adj, cost, pi, parent, degree, key, done, hk, hv) - 2.0 * pi.sum()
        trees += 1
        if w > best_w:
            best_w, stalled = w, 0
            best_pi[:] = pi
        else:
            stalled += 1
            if stalled == 10:
                lam, stalled = 0.5 * lam, 0
        off, norm = 0, 0.0
        for i in range(m):
            off += abs(degree[i] - 2)
            g[i] = 0.7 * (degree[i] - 2) + 0.3 * g[i]
            norm += g[i] * g[i]
        if off == 0 or norm == 0.0 or upper <= w:  # a tour (its length the bound, the best there is) or upper met
            break
        t = lam * (upper - w) / norm
        for i in range(m):
            pi[i] += t * g[i]
    return best_pi, best_w, trees


@_jit
def _tree_order(parent):
    """The nodes of the tree ``parent`` (-1 at its root) parents first: a breadth-first order from the root."""
    m = parent.shape[0]
    children = np.zeros(m + 1, dtype=np.int64)
    root = 0
    for v in range(m):
        if parent[v] >= 0:
            children[parent[v] + 1] += 1
        else:
            root = v
    for v in range(m):
        children[v + 1] += children[v]
    fill = children[:m].copy()
    kids = np.empty(max(m - 1, 1), dtype=np.int64)
    for v in range(m):
        if parent[v] >= 0:
            kids[fill[parent[v]]] = v
            fill[parent[v]] += 1
    order = np.empty(m, dtype=np.int64)
    order[0] = root
    tail = 1
    for h in range(m):
        v = order[h]
        for e in range(children[v], children[v + 1]):
            order[tail] = kids[e]
            tail += 1
    return order


@_jit
def _alpha_row(row, i, pi, parent, order, up, beta, mark, out):
    """Node ``i``'s ``len(out)`` alpha-nearest others (``row``: its legs; ``up``: each node's penalised leg to
    its tree parent), written to ``out`` cheapest leg first. alpha(i, j) = c'(i, j) minus the dearest leg
    on the tree path between i and j (Helsgaun 2000, section 4.2), the ``beta`` of j: up the path from i to
    the root, then down from each node's parent in ``order``. The k least by (alpha, c'), then ordered by
    the leg's own cost (ties by index), so that the local search may stop a scan at the first leg that
    leaves no gain."""
    m, k = row.shape[0], out.shape[0]
    beta[i] = -np.inf
    mark[i] = i
    u = i
    while parent[u] >= 0:
        p = parent[u]
        beta[p] = max(beta[u], up[u])
        mark[p] = i
        u = p
    for h in range(1, m):
        v = order[h]
        if mark[v] != i:
            beta[v] = max(beta[parent[v]], up[v])
    ba = np.empty(k)
    bc = np.empty(k)
    bj = np.empty(k, dtype=np.int64)
    size = 0
    for j in range(m):
        if j == i:
            continue
        c = row[j] + pi[i] + pi[j]
        a = c - beta[j]
        if size == k and (a > ba[k - 1] or (a == ba[k - 1] and c >= bc[k - 1])):
            continue
        t = size if size < k else k - 1
        while t > 0 and (a < ba[t - 1] or (a == ba[t - 1] and c < bc[t - 1])):
            ba[t], bc[t], bj[t] = ba[t - 1], bc[t - 1], bj[t - 1]
            t -= 1
        ba[t], bc[t], bj[t] = a, c, j
        if size < k:
            size += 1
    for t in range(size):  # by the leg's own cost (an insertion sort of k), ties by index
        bc[t] = row[bj[t]]
    for t in range(1, size):
        cj, jj = bc[t], bj[t]
        q = t
        while q > 0 and (bc[q - 1] > cj or (bc[q - 1] == cj and bj[q - 1] > jj)):
            bc[q], bj[q] = bc[q - 1], bj[q - 1]
            q -= 1
        bc[q], bj[q] = cj, jj
    out[:] = bj


@_jit
def _alpha_lists(cm, pi, parent, k):
    """Each node's ``k`` alpha-nearest other nodes (:func:`_alpha_row`) for the spanning tree ``parent``
    under the penalties ``pi``: O(m²) look-ups, O(m) memory."""
    m = pi.shape[0]
    order = _tree_order(parent)
    up = np.full(m, -np.inf)  # the leg from each node to its parent, under pi
    for v in range(m):
        if parent[v] >= 0:
            up[v] = _d(cm, v, parent[v]) + pi[v] + pi[parent[v]]
    beta = np.empty(m)
    mark = np.full(m, -1, dtype=np.int64)
    row = np.empty(m)
    out = np.empty((m, k), dtype=np.int64)
    for i in range(m):
        _row(cm, i, row)
        _alpha_row(row, i, pi, parent, order, up, beta, mark, out[i])
    return out


def _alpha_neighbour_lists(cm, m: int, near: np.ndarray, k: int, upper: float,
                           max_trees: int = ILS_ALPHA_TREES) -> tuple[np.ndarray, int]:
    """Each node's ``k`` alpha-nearest other nodes, cheapest first, and the 1-trees the ascent computed
    (``upper``: a tour's length, for the ascent's step).

    The penalties come from :func:`_ascent` on a sparse graph, the lists ``near`` and two edge-disjoint
    minimum spanning trees of all the legs, both ways (connected, and with a second choice at every node,
    on clustered instances too); the alpha values from the minimum spanning tree of *all* the legs under
    those penalties, so that every leg's alpha is at least 0 and the tree's own legs' exactly 0. The
    ascent's bound is not returned: on the sparse graph it is no lower bound of the tour (fl1577: 23142,
    above the optimum 22249)."""
    none, flat = np.full(m, -1, dtype=np.int64), np.zeros(m)
    first = _dense_tree(cm, m, none, flat)
    second = _dense_tree(cm, m, first, flat)
    a = [np.repeat(np.arange(m), near.shape[1])]
    b = [near.ravel()]
    for parent in (first, second):
        child = np.flatnonzero(parent >= 0)
        a.append(child)
        b.append(parent[child])
    a, b = np.concatenate(a), np.concatenate(b)
    pairs = np.unique(np.minimum(a, b) * m + np.maximum(a, b))
    lo, hi = pairs // m, pairs % m
    rows, cols = np.concatenate([lo, hi]), np.concatenate([hi, lo])
    order = np.lexsort((cols, rows))
    rows, cols = rows[order], cols[order]
    ptr = np.zeros(m + 1, dtype=np.int64)
    np.cumsum(np.bincount(rows, minlength=m), out=ptr[1:])
    pi, _, trees = _ascent(ptr, cols, _legs(cm, rows, cols), upper, max_trees)
    return _alpha_lists(cm, pi, _dense_tree(cm, m, none, pi), min(k, m - 1)), int(trees)


# ------------------------------------------------------------------------------------- the method
def _cost_model(instance: SequencingInstance) -> tuple[tuple, int, int | None, float]:
    """The closed, symmetric tour the kernel solves (module docstring): ``(cm, m, dummy, top)``.

    ``cm`` for :func:`_d`: the dense matrix of ``m`` nodes (the instance's symmetrised, plus the
    dummy), or, for an implicit instance, the block cells ``P`` and weights ``w`` (eq. 2) or the
    coordinates ``X`` and the metric's code ``kind`` (TSPLIB), and the dummy's legs ``pen``; ``dummy`` is the
    dummy's index (None: closed); ``top``
    bounds every leg's cost.
    """
    n = instance.n
    pinned = [i for i in (instance.start, instance.end) if i is not None]
    if instance.implicit:
        if instance.coords is not None:
            kind = _METRIC_CODES[instance.metric]
            X = np.array(instance.coords, dtype=float)
            if kind == _GEO:  # TSPLIB's radians, once (scenarios.tsplib's rule: degrees truncated, .MM minutes)
                degrees = np.trunc(X)
                X = 3.141592 * (degrees + 5.0 * (X - degrees) / 3.0) / 180.0
                top = math.floor(6378.388 * math.pi + 1.0)  # half the sphere's circumference
            else:
                diagonal = float(np.hypot(*(X.max(0) - X.min(0))))  # no two nodes lie further apart
                top = math.ceil(diagonal / math.sqrt(10.0) if kind == _ATT else diagonal) + 1.0
            model = [np.ascontiguousarray(X), np.int64(kind)]
        else:
            P = np.ascontiguousarray(instance.blocks, dtype=float)
            w = np.asarray(instance.weights, dtype=float)
            cells = P.reshape(-1, 2)
            top = float(w.sum() * np.hypot(*(cells.max(0) - cells.min(0))))  # no two cells lie further apart
            model = [P, w]
        if instance.closed:
            return (*model, np.zeros(0)), n, None, top
        pen = np.zeros(n)
        if pinned:
            pen[:] = 3.0 * top + 1.0
            pen[pinned] = 0.0
            top = 3.0 * top + 1.0
        return (*model, pen), n + 1, n, top
    C = (instance.cost + instance.cost.T) / 2
    if instance.closed:
        D = np.ascontiguousarray(C)
    else:
        penalty = 3.0 * float(np.abs(C).max()) + 1.0
        D = np.zeros((n + 1, n + 1))
        D[:n, :n] = C
        if pinned:
            D[n, :n] = penalty
            D[n, pinned] = 0.0
            D[:n, n] = D[n, :n]
    return D, len(D), None if instance.closed else n, float(np.abs(D).max())


def _cheapest(candidates: np.ndarray, costs: np.ndarray, k: int) -> np.ndarray:
    """Each row's ``k`` cheapest candidates, cheapest first, ties by index (the same on every machine)."""
    order = np.lexsort((candidates, costs), axis=1)[:, :k]
    return np.ascontiguousarray(np.take_along_axis(candidates, order, axis=1), dtype=np.int64)


def _neighbour_lists(D: np.ndarray, k: int) -> np.ndarray:
    """Each node's ``k`` cheapest other nodes in a dense matrix, a block of rows at a time; ties at the
    k-th cost go to the lowest indices (as :func:`_implicit_neighbour_lists` breaks them, so that an
    instance gives the same lists with its matrix and without; argpartition's own pick among ties
    depends on its algorithm)."""
    n = len(D)
    k = min(k, n - 1)
    out = np.empty((n, k), dtype=np.int64)
    step = max(1, (1 << 22) // n)  # rows per block: about 32 MB of temporaries
    for r in range(0, n, step):
        masked = D[r:r + step].copy()
        rows = np.arange(len(masked))
        masked[rows, np.arange(r, r + len(masked))] = np.inf
        kth = np.partition(masked, k - 1, axis=1)[:, k - 1:k]
        tied = masked == kth
        keep = (masked < kth) | (tied & (np.cumsum(tied, axis=1) <= k - (masked < kth).sum(1, keepdims=True)))
        part = np.nonzero(keep)[1].reshape(len(masked), k)  # k a row, by index
        out[r:r + step] = _cheapest(part, np.take_along_axis(masked, part, axis=1), k)
    return out


def _centres(P: np.ndarray, w: np.ndarray) -> np.ndarray:
    """The weighted centre of each waypoint's blocks: eq. 2 is at least ``Σw`` times their distance."""
    return (P * w[None, :, None]).sum(1) / w.sum()


def _is_tsplib(cm) -> bool:
    return isinstance(cm, tuple) and isinstance(cm[1], (int, np.integer))


def _search_points(cm: tuple) -> np.ndarray:
    """Points whose Euclidean nearest neighbours are a leg's likely cheapest: the blocks' centres (eq. 2),
    the coordinates (the planar TSPLIB metrics grow with their distance), or for GEO the points on the
    unit sphere (the great-circle distance grows with their chord)."""
    if not _is_tsplib(cm):
        return _centres(cm[0], cm[1])
    X, kind = cm[0], int(cm[1])
    if kind != _GEO:
        return X
    lat, lon = X[:, 0], X[:, 1]
    return np.column_stack([np.cos(lat) * np.cos(lon), np.cos(lat) * np.sin(lon), np.sin(lat)])


def _plane_points(cm: tuple) -> np.ndarray:
    """2-D points for the start tour's space-filling curve (GEO: latitude and longitude)."""
    return cm[0] if _is_tsplib(cm) else _centres(cm[0], cm[1])


def _implicit_neighbour_lists(cm: tuple, dummy: int | None, k: int) -> np.ndarray:
    """Neighbour lists without a matrix: each waypoint's nearest ``4k`` by the centre of its blocks (a
    k-d tree; eq. 2 is at least Σw times the centres' distance, so near centres are the likely cheap
    legs), or by its TSPLIB coordinates (:func:`_search_points`), ranked by the costs themselves (ties by
    index); the dummy's legs (``pen``) priced as the dense lists would price them."""
    from scipy.spatial import cKDTree

    pen = cm[2]
    n = len(cm[0])
    m = n + (dummy is not None)
    k = min(k, m - 1)
    q = min(n, 4 * k + 1)
    points = _search_points(cm)
    _, near = cKDTree(points).query(points, k=q)
    near = np.asarray(near, dtype=np.int64).reshape(n, q)
    rows = np.repeat(np.arange(n), q)
    if _is_tsplib(cm):
        costs = _legs(cm, rows, near.ravel()).reshape(n, q)
    else:
        costs = eq2_legs(cm[0], cm[1], rows, near.ravel()).reshape(n, q)
    costs[near == np.arange(n)[:, None]] = np.inf
    if dummy is not None:
        near = np.hstack([near, np.full((n, 1), dummy)])
        costs = np.hstack([costs, pen[:, None]])
    lists = _cheapest(near, costs, k)
    if dummy is None:
        return lists
    mine = np.argsort(pen, kind="stable")[:k][None, :]  # the dummy's own list: its cheapest legs
    return np.vstack([lists, mine.astype(np.int64)])


def _hilbert_tour(cm: tuple, dummy: int | None, first: int) -> np.ndarray:
    """A tour without a matrix: the waypoints along a Hilbert curve through their block centres, from
    ``first``, then the dummy (next to ``first`` round the cycle). Its legs are short wherever the
    waypoints are dense, which is all the local search needs from a start."""
    xy = _plane_points(cm)
    span = np.maximum(xy.max(0) - xy.min(0), 1e-12)
    side = 1 << 16
    x, y = (((xy - xy.min(0)) / span.max()) * (side - 1)).round().astype(np.int64).T
    d = np.zeros(len(xy), dtype=np.int64)
    s = side // 2
    while s > 0:  # the classic xy → Hilbert index, one level at a time
        rx, ry = (x & s) > 0, (y & s) > 0
        d += s * s * ((3 * rx) ^ ry)
        flip = ~ry
        swap_x = np.where(flip & rx, s - 1 - x, x)
        swap_y = np.where(flip & rx, s - 1 - y, y)
        x, y = np.where(flip, swap_y, swap_x), np.where(flip, swap_x, swap_y)
        s //= 2
    order = np.argsort(d, kind="stable")
    order = np.roll(order, -int(np.flatnonzero(order == first)[0]))
    return order if dummy is None else np.append(order, dummy).astype(np.int64)


def _nearest_neighbour_tour(cm: tuple, dummy: int | None, first: int) -> np.ndarray:
    """The nearest-neighbour tour of a TSPLIB coordinate model from ``first`` without a matrix, then the
    dummy: each step goes to the cheapest unvisited node, ties to the lowest index, the tour the dense
    matrix's :func:`_greedy_tour` builds from the same node. A k-d tree over the unvisited nodes (rebuilt
    when half of it is visited) gives the candidates by distance; the metric's rounding never decreases
    with distance, so once the farthest candidate costs more than the cheapest unvisited one, no node
    further away can be cheaper or tie."""
    from scipy.spatial import cKDTree

    points = _search_points(cm)
    n = len(points)
    alive = np.ones(n, dtype=bool)
    tour = np.empty(n, dtype=np.int64)
    tour[0] = here = first
    alive[first] = False
    ids = np.flatnonzero(alive)
    tree = cKDTree(points[ids]) if n > 1 else None
    dead = 0  # visited nodes still in the tree
    for step in range(1, n):
        if 2 * dead >= len(ids):
            ids = np.flatnonzero(alive)
            tree = cKDTree(points[ids])
            dead = 0
        k = 8
        while True:
            k = min(k, len(ids))
            _, at = tree.query(points[here], k=k)
            found = ids[np.atleast_1d(at)]
            live = found[alive[found]]
            if live.size:
                costs = _legs(cm, np.full(live.size, here, dtype=np.int64), live)
                cheapest = costs.min()
                if k == len(ids) or _legs(cm, np.array([here]), found[-1:])[0] > cheapest:
                    here = int(live[costs == cheapest].min())
                    break
            k *= 2
        tour[step] = here
        alive[here] = False
        dead += 1
    return tour if dummy is None else np.append(tour, dummy).astype(np.int64)


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


def _as_directed(order: np.ndarray, before: np.ndarray, instance: SequencingInstance) -> np.ndarray:
    """``order``, or the same path (tour) run the other way where the instance allows it, whichever
    moved the waypoints of ``before`` less: a move may reverse the complement of a segment, so the
    search turns the whole tour round at times, which a free path or a tour does not notice but a
    caller improving an order would."""
    if instance.closed:
        other = np.concatenate([order[:1], order[:0:-1]])
    elif instance.start is None and instance.end is None:
        other = order[::-1].copy()
    else:
        return order
    at = np.empty(len(before), dtype=np.int64)
    at[before] = np.arange(len(before))
    shift = [int(np.abs(at[o] - np.arange(len(o))).sum()) for o in (order, other)]
    return other if shift[1] < shift[0] else order


def _greedy_tour(D: np.ndarray) -> np.ndarray:
    """The nearest-neighbour tour from node 0 (the package's one construction)."""
    from htetro_opt.solvers.sequencing._local import nearest_neighbour_paths

    return nearest_neighbour_paths(D, [0])[0]


def _costs_kind(instance) -> str:
    """How the run reads its costs, for the result's ``costs`` field (docs/formats.md)."""
    if instance.coords is not None:
        return f"implicit ({instance.metric} on demand)"
    return "implicit (eq. 2 on demand)" if instance.implicit else "matrix"


def solve_ils(instance, *, seed=0, time_limit: float | None = None, kicks: int | None = None,
              neighbours: int = ILS_NEIGHBOURS, lk_depth: int = ILS_LK_DEPTH, or3opt: bool = ILS_OR3OPT,
              kick_rate: float = ILS_KICK_RATE, accept_worse: float = ILS_ACCEPT_WORSE,
              kick_span: int = ILS_KICK_SPAN, candidates: str = "auto") -> tuple[np.ndarray, dict]:
    """Iterated local search (2-opt + Or-opt, local double-bridge kicks), compiled and seeded.

    Parameters
    ----------
    instance : SequencingInstance
        Symmetric costs, a matrix or implicit eq.-2 costs (memory linear in n); an open path (fixed or
        free start and end) or a closed tour.
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
    lk_depth : int
        Flips of the LK-style move that replaces the 2-opt moves (0, the default: plain 2-opt; 2: 2-opt
        and sequential 3-opt moves, stronger a kick and about twice as slow, see ``ILS_LK_DEPTH``).
    or3opt : bool
        Add the segment exchanges of :func:`_or3_move` (sequential 3-opt moves no 2-opt flip pair reaches)
        to the local search (``ILS_OR3OPT``).
    kick_rate : float
        With an explicit ``time_limit`` and ``kicks`` None: kicks planned a second of the limit, the
        budget ``max(ils_kicks(n), kick_rate · time_limit)``, a number fixed by the arguments, so the run
        is reproducible when it completes within the limit (0: :func:`ils_kicks` alone; ``ILS_KICK_RATE``).
    accept_worse : float
        Keep a kick's result when it is at most this many mean legs above the run's best tour, which is
        returned (0: only when no costlier, ``ILS_ACCEPT_WORSE``).
    kick_span : int
        Longest segment of a kick's double bridge (:data:`ILS_KICK_SPAN`; ``n // 4`` or more: a global
        double bridge).
    candidates : {"auto", "nearest", "alpha"}
        The neighbour lists: ``"nearest"``, each node's cheapest legs; ``"alpha"``, each node's
        alpha-nearest (Helsgaun 2000, section 4: a leg's alpha is how much longer the cheapest 1-tree
        containing it is, under the penalties of at most :data:`ILS_ALPHA_TREES` steps of a subgradient
        ascent), ordered by cost, O(n²) leg look-ups, at most :data:`ILS_ALPHA_LIMIT` waypoints;
        ``"auto"``: alpha up to :data:`ILS_ALPHA_AUTO` waypoints when their estimated cost
        (:data:`ILS_ALPHA_PAIR_SECONDS`) is at most a tenth of the time limit, nearest otherwise.

    Returns
    -------
    order : ndarray of int64
    info : dict
        ``engine`` (``"numba"``, or ``"enumeration"`` below 8 nodes), ``costs`` (``"matrix"`` or
        implicit), ``candidates`` (``"nearest"``, ``"alpha"``, or ``"none"`` for the enumeration),
        ``ascent_trees`` (the 1-trees of alpha's ascent, 0 without), ``kicks`` (done),
        ``improving_kicks``, ``timed_out``, ``initial_cost`` (the start tour, on the closed tour),
        ``tour_cost``.

    Raises
    ------
    ParameterError
        On an asymmetric instance, a negative ``kicks``, ``neighbours < 1``, an unknown ``candidates``
        (or alpha lists beyond :data:`ILS_ALPHA_LIMIT` waypoints) or an invalid seed or time limit.

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
    explicit = time_limit is not None
    if time_limit is None:
        time_limit = default_time_limit("ils", instance.n)
    kicks = check_int(kicks, "kicks", minimum=0, allow_none=True)
    kick_rate = check_real(kick_rate, "kick_rate", minimum=0.0)
    accept_worse = check_real(accept_worse, "accept_worse", minimum=0.0)
    kick_span = check_int(kick_span, "kick_span", minimum=1)
    or3opt = check_bool(or3opt, "or3opt")
    neighbours = check_int(neighbours, "neighbours", minimum=1)
    candidates = check_candidates(candidates, "candidates")
    # auto: alpha where it pays at no risk to the time limit (a rule of the arguments, so reproducible)
    alpha = candidates == "alpha" or (candidates == "auto" and instance.n <= ILS_ALPHA_AUTO
                                      and instance.n ** 2 * ILS_ALPHA_PAIR_SECONDS <= 0.1 * time_limit)
    if alpha and instance.n > ILS_ALPHA_LIMIT:
        raise ParameterError(f"candidates='alpha' costs O(n²) leg look-ups: at most {ILS_ALPHA_LIMIT} waypoints, "
                             f"got {instance.n}; use candidates='nearest'")
    rng = as_rng(seed)
    stream = int(rng.integers(0, 2**63))
    began = time.perf_counter()
    cm, m, dummy, top = _cost_model(instance)
    if kicks is None:
        kicks = ils_kicks(m)
        if explicit and kick_rate > 0:  # plan to use the limit the caller gave, in a number of kicks
            kicks = max(kicks, int(kick_rate * time_limit))
    if m < 8:  # every tour through node 0, no kick can help
        from itertools import permutations

        D = np.array([[_d(cm, i, j) for j in range(m)] for i in range(m)]).reshape(m, m)
        tours = np.array([(0, *p) for p in permutations(range(1, m))], dtype=np.int64).reshape(-1, m)
        costs = D[tours, np.roll(tours, -1, axis=1)].sum(axis=1)
        best = tours[int(np.argmin(costs))]
        cost = float(costs.min())
        return _decode(best, dummy, instance), {"engine": "enumeration", "costs": _costs_kind(instance),
                                                "candidates": "none", "ascent_trees": 0, "initial_cost": cost,
                                                "kicks": 0, "improving_kicks": 0, "timed_out": False,
                                                "tour_cost": cost}
    # alpha: its lists among the nearest ALPHA_NEAREST and two spanning trees (the ascent's sparse graph)
    near = max(neighbours, _ALPHA_NEAREST) if alpha else neighbours
    if instance.implicit:
        nbr = _implicit_neighbour_lists(cm, dummy, near)
        first = 0 if instance.start is None else instance.start
        if instance.coords is not None:  # (a closed tour: the dense matrix's start tour, from node 0 as it)
            tour = _nearest_neighbour_tour(cm, dummy, 0 if dummy is None else first)
        else:
            tour = _hilbert_tour(cm, dummy, first)
    else:
        nbr = _neighbour_lists(cm, near)
        tour = _greedy_tour(cm).astype(np.int64)
    info = {"engine": "numba", "costs": _costs_kind(instance), "candidates": "alpha" if alpha else "nearest",
            "ascent_trees": 0, "initial_cost": float(_tour_cost(cm, tour))}
    if alpha:
        nbr, info["ascent_trees"] = _alpha_neighbour_lists(cm, m, nbr, neighbours, info["initial_cost"])
    eps = 1e-9 * max(1.0, top)
    done = kept = 0
    timed_out = False
    # chunks of kicks, each with its own stream draw, so that the cap can stop between them
    chunk = max(1000, kicks // 64)
    first = True
    halt = kernel_flag()  # set by SIGINT / SIGTERM under the command line: the kernel returns within moments
    while first or done < kicks:
        step = min(chunk, kicks - done)
        d, k = _ils(cm, nbr, tour, step, kick_span, np.uint64((stream + 0x9E37 * done) % 2**64), eps, halt,
                    lk_depth, or3opt, float(accept_worse))
        first = False
        done += d
        kept += k
        if step == 0:
            break
        if time_limit is not None and time.perf_counter() - began > time_limit and done < kicks:
            timed_out = True
            break
    info.update(kicks=done, improving_kicks=kept, timed_out=timed_out, tour_cost=float(_tour_cost(cm, tour)))
    return _decode(tour, dummy, instance), info


class LocalCore:
    """The compiled local search (2-opt + Or-opt, neighbour lists, don't-look bits) of ``ils`` on one
    instance, prepared once (cost model and neighbour lists) for many orders: the package's one
    2-opt / Or-opt local search.

    :meth:`improve` is the memetic GA's local step (the neighbour-list search, optionally with
    kicks); :meth:`descend` adds the full passes that make its result a local optimum of the whole
    neighbourhood: the ``local`` method and :func:`~htetro_opt.solvers.sequencing.improve` (and its
    :func:`~htetro_opt.solvers.sequencing.two_opt`, :func:`~htetro_opt.solvers.sequencing.or_opt`
    and :func:`~htetro_opt.solvers.sequencing.improve_batch`) run it.

    Parameters
    ----------
    instance : SequencingInstance
        Symmetric costs (a matrix or implicit), an open path or a closed tour.
    neighbours : int
        Size of each node's neighbour list.

    Raises
    ------
    ParameterError
        On an asymmetric instance or ``neighbours < 1``.

    Examples
    --------
    >>> from htetro_opt.problems.waypoint_sequencing import SequencingInstance
    >>> x = np.array([0.0, 5, 1, 4, 2, 3, 7, 6, 9, 8])
    >>> core = LocalCore(SequencingInstance.from_matrix(np.abs(np.subtract.outer(x, x)), start=0))
    >>> core.improve(np.arange(10)).tolist()
    [0, 2, 4, 5, 3, 1, 7, 6, 9, 8]

    Below 8 nodes only :meth:`descend` moves:

    >>> small = LocalCore(SequencingInstance.from_matrix(np.abs(np.subtract.outer(x[:6], x[:6])), start=0))
    >>> small.improve(np.arange(6)).tolist(), small.descend(np.arange(6)).tolist()
    ([0, 1, 2, 3, 4, 5], [0, 2, 4, 5, 3, 1])
    """

    def __init__(self, instance: SequencingInstance, *, neighbours: int = ILS_NEIGHBOURS) -> None:
        self.instance = check_instance(instance)
        if not instance.symmetric:
            raise ParameterError("the compiled local search assumes a symmetric cost matrix")
        k = check_int(neighbours, "neighbours", minimum=1)
        self.cm, self.m, self.dummy, top = _cost_model(instance)
        self.eps = 1e-9 * max(1.0, top)
        self.nbr = self.nc = None
        if self.m >= 4:  # below, every tour costs the same: no move to make
            self.nbr = (_implicit_neighbour_lists(self.cm, self.dummy, k) if instance.implicit
                        else _neighbour_lists(self.cm, k))

    def improve(self, order, *, kicks: int = 0, seed: int = 0) -> np.ndarray:
        """``order`` (a valid order of the instance) improved by the neighbour-list search of ``ils``,
        after ``kicks`` local double-bridge kicks when positive (seeded by ``seed``); unchanged below
        8 nodes (where ``ils`` enumerates instead; the memetic GA's results on tiny instances stay
        those it has always given)."""
        order = self.instance.check_order(order)
        if self.m < 8:
            return order
        tour = order if self.dummy is None else np.append(order, self.dummy)
        tour = np.ascontiguousarray(tour, dtype=np.int64)
        _ils(self.cm, self.nbr, tour, int(kicks), ILS_KICK_SPAN, np.uint64(seed % 2**64), self.eps, kernel_flag(), 0,
             False, 0.0)
        return _decode(tour, self.dummy, self.instance)

    def descend(self, order, *, two_opt: bool = True, lengths=(1, 2, 3), certify: bool = True,
                max_moves: int | None = None, deadline: float = math.inf) -> np.ndarray:
        """``order`` improved to a local optimum of 2-opt and Or-opt (no kicks), at any size.

        The neighbour-list search of ``ils`` from every node, then (``certify``) a full pass from
        every node, every other node a candidate and no move pruned; while the full pass still
        moves, both again. The result is then a local optimum of the whole neighbourhood: no 2-opt
        move (with ``two_opt``) and no move of a segment of one of the ``lengths`` to another edge,
        as it is or reversed, lowers the tour's cost by more than ``2 · eps``.

        Parameters
        ----------
        order : array_like of int
            A valid order of the instance.
        two_opt : bool
            Try 2-opt moves.
        lengths : sequence of int
            Or-opt's segment lengths, positive (empty: no Or-opt).
        certify : bool
            Run the full passes (False: the neighbour-list search only, e.g. to repair a kick).
        max_moves : int, optional
            Make at most this many improving moves (None: to the local optimum).
        deadline : float
            A ``time.perf_counter()`` instant after which no pass starts (a pass is not interrupted).

        Returns
        -------
        ndarray of int64
            The order, never costlier than ``order``.
        """
        order = self.instance.check_order(order)
        budget = _UNLIMITED if max_moves is None else int(max_moves)
        if self.nbr is None or budget <= 0 or time.perf_counter() >= deadline:
            return order
        if self.nc is None:
            self.nc = _neighbour_costs(self.cm, self.nbr)
        tour = order if self.dummy is None else np.append(order, self.dummy)
        tour = np.ascontiguousarray(tour, dtype=np.int64)
        lengths = np.array(sorted({int(L) for L in lengths}), dtype=np.int64)
        two_opt = bool(two_opt)
        halt = kernel_flag()
        while True:
            budget -= _descend(self.cm, self.nbr, self.nc, tour, two_opt, lengths, False, self.eps, budget, halt)
            if not certify or budget <= 0 or time.perf_counter() >= deadline:
                break
            made = _descend(self.cm, self.nbr, self.nc, tour, two_opt, lengths, True, self.eps, budget, halt)
            budget -= made
            if made == 0 or budget <= 0 or time.perf_counter() >= deadline:
                break
        return _as_directed(_decode(tour, self.dummy, self.instance), order, self.instance)
