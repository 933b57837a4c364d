"""Local search for the open-path waypoint TSP of Le et al. 2018: nearest neighbour, 2-opt, Or-opt, ILS.

Moves are priced with numpy, never one by one: a round computes the gain of every candidate move as
a matrix (rows: a position, columns: its partner positions), takes each row's best, and applies a
greedy set of non-overlapping improving moves (largest gain first). Two kinds of rounds:

- *restricted*: only moves creating an edge from a waypoint to one of its :data:`NEIGHBOURS`
  cheapest waypoints, or touching an end of the path — O(n·k) per round;
- *full*: every move, from the cost matrix gathered in path order ``C[order][:, order]`` — O(n²).

A search runs restricted rounds until none improves, then one full round of each move to certify
the result, and goes back to restricted rounds if the full one still improved. So the result is a
true local optimum of the neighbourhood, and on 1000 random points nearest neighbour + 2-opt +
Or-opt takes about 0.2–0.5 s here (most of it the two certifying O(n²) rounds).

The path is **open**: it does not return to its first waypoint. Both ends are handled with a dummy
waypoint that costs nothing to reach: the path is padded with it at the end (fixed start: the first
waypoint never moves) or at both ends (free start). Reversing a suffix then changes one edge only,
and with a free start so does reversing a prefix; moving a segment to either end is an ordinary
insertion next to the dummy.

- :func:`nearest_neighbour_paths` — the one nearest-neighbour construction, batched: many paths at
  once, each from its own first (and optionally forced second) waypoint, ties to the lowest index
  or to the lowest of a priority table. The exact solver's hint and the greedy baseline are built
  on it too;
- :func:`nearest_neighbour` — the greedy construction (from the fixed start, or the best of many
  starts);
- :func:`two_opt` — reverse ``order[i..j]``;
- :func:`or_opt` — move a segment of 1–3 waypoints elsewhere, optionally reversed;
- :func:`improve` — 2-opt and Or-opt in turn until neither improves;
- :func:`double_bridge` — the classic kick of iterated local search;
- :func:`solve_local` — the ``local`` method of :func:`~htetro_opt.solvers.sequencing.sequence_waypoints`:
  nearest neighbour, then :func:`improve`, then optionally iterated local search.

The gains assume a symmetric cost (eq. 2 is); an asymmetric matrix is refused. Improvements smaller
than ``1e-9 × max |cost|`` are ignored, so rounding noise never cycles.
"""

from __future__ import annotations

import math
import reprlib
import time

import numpy as np

from htetro_opt._progress import check_progress, report
from htetro_opt._validation import as_rng, check_bool, check_int, check_real, check_time_limit
from htetro_opt.errors import ParameterError
from htetro_opt.problems.waypoint_sequencing import check_instance
from htetro_opt.solvers.sequencing._budgets import default_time_limit

__all__ = [
    "NEIGHBOURS",
    "TIE_TOLERANCE",
    "double_bridge",
    "improve",
    "improve_batch",
    "nearest_neighbour",
    "nearest_neighbour_paths",
    "or_opt",
    "solve_local",
    "two_opt",
]

NEIGHBOURS = 10
"""Size of each waypoint's candidate list in the restricted rounds."""

_BATCH_ELEMENTS = 2_000_000
"""The batched local search of :func:`improve_batch` gathers at most this many costs at a time."""


# --------------------------------------------------------------------------------------- checks
def _check_square(cost) -> np.ndarray:
    """A non-empty, finite, square cost matrix as floats (every method's matrix check)."""
    try:
        C = np.asarray(cost, dtype=float)
    except (TypeError, ValueError) as err:
        raise ParameterError(f"cost must be a square matrix of numbers, got {type(cost).__name__}") from err
    if C.ndim != 2 or C.shape[0] != C.shape[1] or C.shape[0] == 0:
        raise ParameterError(f"cost must be a non-empty square matrix, got shape {C.shape}")
    if not np.isfinite(C).all():
        raise ParameterError(f"cost must be finite, got {np.count_nonzero(~np.isfinite(C))} non-finite entries")
    return C


def _check_cost(cost) -> np.ndarray:
    """:func:`_check_square`, and symmetric: the 2-opt and Or-opt gains assume it."""
    C = _check_square(cost)
    if not np.allclose(C, C.T, rtol=1e-9, atol=1e-12):
        raise ParameterError("cost must be symmetric (the 2-opt and Or-opt gains assume it)")
    return C


def _check_order(order, n: int) -> np.ndarray:
    try:
        p = np.array(order, dtype=np.int64).reshape(-1)
    except (TypeError, ValueError) as err:
        raise ParameterError(f"order must be a sequence of waypoint indices, got {order!r}") from err
    if len(p) != n or not np.array_equal(np.sort(p), np.arange(n)):
        raise ParameterError(f"order must be a permutation of 0…{n - 1}")
    return p


def _check_rounds(max_rounds) -> float:
    rounds = check_int(max_rounds, "max_rounds", minimum=0, allow_none=True)
    return math.inf if rounds is None else rounds


def _check_lengths(segment_lengths) -> tuple[int, ...]:
    try:
        lengths = tuple(segment_lengths)
    except TypeError:
        lengths = (segment_lengths,)
    if not lengths:
        raise ParameterError("segment_lengths must hold at least one positive integer, got an empty sequence")
    return tuple(sorted({check_int(L, f"segment_lengths[{i}]", minimum=1) for i, L in enumerate(lengths)}))


def _tolerance(C: np.ndarray) -> float:
    return 1e-9 * float(np.abs(C).max())


# ------------------------------------------------------------------------------ padded paths
def _padded_cost(C: np.ndarray) -> np.ndarray:
    """C with one more row and column of zeros: the dummy waypoint ``n`` at the open end(s)."""
    n = len(C)
    D = np.zeros((n + 1, n + 1))
    D[:n, :n] = C
    return D


def _pad(order: np.ndarray, n: int, fixed_start: bool) -> np.ndarray:
    tail = np.array([n], dtype=np.int64)
    return np.concatenate([order, tail] if fixed_start else [tail, order, tail])


def _unpad(q: np.ndarray, fixed_start: bool) -> np.ndarray:
    return q[:-1].copy() if fixed_start else q[1:-1].copy()


def _neighbours(C: np.ndarray, k: int) -> np.ndarray:
    """The k cheapest other waypoints of every waypoint, plus a row for the dummy (any k waypoints:
    the end moves are priced separately)."""
    n = len(C)
    k = min(k, n - 1)
    if k <= 0:
        return np.zeros((n + 1, 0), dtype=np.int64)
    masked = C + np.diag(np.full(n, np.inf))
    table = np.argpartition(masked, k - 1, axis=1)[:, :k] if k < n - 1 else np.argsort(masked, axis=1)[:, :k]
    return np.vstack([table, np.arange(k)[None, :]]).astype(np.int64)


def _gather(D: np.ndarray, q: np.ndarray) -> np.ndarray:
    """``D[q][:, q]``: the costs in path order (two takes beat ``np.ix_``)."""
    return D.take(q, axis=0).take(q, axis=1)


def _greedy_disjoint(gain: np.ndarray, lo: np.ndarray, hi: np.ndarray, m: int) -> list[int]:
    """Indices of a greedy (largest gain first) set of moves whose edge spans [lo, hi] are disjoint."""
    used = np.zeros(m, dtype=bool)
    chosen = []
    for k in np.argsort(-gain, kind="stable").tolist():
        a, b = lo[k], hi[k]
        if not used[a:b + 1].any():
            used[a:b + 1] = True
            chosen.append(k)
    return chosen


def _row_best(gain: np.ndarray, *columns: np.ndarray):
    """Per row, the largest gain and the matching entries of ``columns`` (same shape as ``gain``)."""
    rows = np.arange(len(gain))
    best = gain.argmax(1)
    return (gain[rows, best],) + tuple(c[rows, best] for c in columns)


class _Search:
    """2-opt and Or-opt rounds on padded paths of one cost matrix.

    A round is either *restricted* — only moves that create an edge to one of a waypoint's
    ``neighbours`` cheapest waypoints, or touch an end of the path: O(n·k) — or *full*: every move,
    O(n²). The search runs restricted rounds to their local optimum, then full rounds to certify it
    (and resumes if a full round still finds moves), so the result is a true local optimum.
    """

    def __init__(self, C: np.ndarray, fixed_start: bool, lengths=(1, 2, 3), neighbours: int = NEIGHBOURS,
                 max_rounds: float = math.inf, deadline: float = math.inf) -> None:
        self.n = len(C)
        self.D = _padded_cost(C)
        self._flat = self.D.ravel()
        self.tol = _tolerance(C)
        self.fixed = fixed_start
        self.lengths = lengths
        self.nbr = _neighbours(C, neighbours)
        self.budget = max_rounds
        self.deadline = deadline

    # -- helpers
    def _cost(self, a, b) -> np.ndarray:
        """``D[a, b]`` (broadcast) by a flat take, faster than 2-D fancy indexing."""
        return np.take(self._flat, a * len(self.D) + b)

    def _positions(self, q: np.ndarray) -> np.ndarray:
        pos = np.zeros(len(self.D), dtype=np.int64)
        pos[q] = np.arange(len(q))  # the dummy's entry is never read: no neighbour list holds it
        return pos

    def _ends(self, rows: int, m: int) -> list[np.ndarray]:
        """Columns of partner edges at the ends: the last edge (to the dummy), and with a free
        start the first one (from the dummy)."""
        cols = [np.full((rows, 1), m - 2, dtype=np.int64)]
        if not self.fixed:
            cols.append(np.zeros((rows, 1), dtype=np.int64))
        return cols

    # -- 2-opt
    def two_opt_moves(self, q: np.ndarray, full: bool):
        """Best 2-opt partner edge of every edge: (gain, lo, hi) with edges lo + 2 ≤ hi."""
        D, m = self.D, len(q)
        e1 = np.arange(m - 1)
        if full:
            Q = _gather(D, q)
            E = np.diagonal(Q, 1)
            G = E[:, None] - Q[:-1, :-1]
            G += E
            G -= Q[1:, 1:]
            G[e1, e1] = 0.0
            G[e1[:-1], e1[1:]] = 0.0
            G[e1[1:], e1[:-1]] = 0.0
            e2 = np.broadcast_to(e1, G.shape)
        else:
            pos = self._positions(q)
            a, b = q[:-1], q[1:]
            E = self._cost(a, b)
            e2 = np.hstack([pos[self.nbr[a]], pos[self.nbr[b]] - 1, *self._ends(m - 1, m)])
            valid = (e2 >= 0) & (e2 <= m - 2) & (np.abs(e2 - e1[:, None]) >= 2)
            e2 = np.where(valid, e2, 0)
            G = E[:, None] + E[e2]
            G -= self._cost(a[:, None], q[e2])
            G -= self._cost(b[:, None], q[e2 + 1])
            G[~valid] = 0.0
        gain, partner = _row_best(G, e2)
        return gain, np.minimum(e1, partner), np.maximum(e1, partner)

    def two_opt_round(self, q: np.ndarray, full: bool) -> float:
        """One round (in place); the total gain applied."""
        if len(q) < 4:
            return 0.0
        gain, lo, hi = self.two_opt_moves(q, full)
        keep = gain > self.tol
        if not keep.any():
            return 0.0
        lo, hi, gain = lo[keep], hi[keep], gain[keep]
        _, first = np.unique(lo * len(q) + hi, return_index=True)  # (e1, e2) and (e2, e1) are one move
        lo, hi, gain = lo[first], hi[first], gain[first]
        total = 0.0
        for c in _greedy_disjoint(gain, lo, hi, len(q)):
            a, b = lo[c] + 1, hi[c] + 1
            q[a:b] = q[a:b][::-1].copy()
            total += gain[c]
        return total

    # -- Or-opt
    def or_opt_moves(self, q: np.ndarray, L: int, full: bool, Q=None):
        """Best move of every segment q[i:i+L]: (i, gain, k, reversed), k the edge it goes into."""
        m = len(q)
        S = m - 1 - L  # segments start at i = 1..m-1-L
        if S <= 0:
            return None
        i = np.arange(1, m - L)
        prev, s0, se, nxt = q[i - 1], q[i], q[i + L - 1], q[i + L]
        removal = self._cost(prev, s0) + self._cost(se, nxt) - self._cost(prev, nxt)
        if full:
            E = np.diagonal(Q, 1)
            k = np.broadcast_to(np.arange(m - 1), (S, m - 1))
            forward = Q[1:m - L, :m - 1] + Q[L:m - 1, 1:m]
            forward -= E
            if L > 1:
                reverse = Q[L:m - 1, :m - 1] + Q[1:m - L, 1:m]
                reverse -= E
            rows = np.arange(S)
            invalid = np.zeros((S, m - 1), dtype=bool)
            for t in range(L + 1):  # edges i−1 … i+L−1 touch the segment: row r = i − 1, edge r + t
                ok = rows + t < m - 1
                invalid[rows[ok], rows[ok] + t] = True
        else:
            pos = self._positions(q)
            k = np.hstack([pos[self.nbr[s0]], pos[self.nbr[s0]] - 1, pos[self.nbr[se]],
                           pos[self.nbr[se]] - 1, *self._ends(S, m)])
            valid = (k >= 0) & (k <= m - 2) & ((k < i[:, None] - 1) | (k > i[:, None] + L - 1))
            k = np.where(valid, k, 0)
            qa, qb = q[k], q[k + 1]
            E = self._cost(qa, qb)
            forward = self._cost(qa, s0[:, None]) + self._cost(se[:, None], qb) - E
            reverse = self._cost(qa, se[:, None]) + self._cost(s0[:, None], qb) - E
            invalid = ~valid
        if L > 1:
            flipped = reverse < forward
            np.minimum(forward, reverse, out=forward)
        else:
            flipped = np.zeros(forward.shape, dtype=bool)
        forward[invalid] = np.inf
        gain, k, flipped = _row_best(removal[:, None] - forward, k, flipped)
        return i, gain, k, flipped

    def or_opt_round(self, q: np.ndarray, full: bool) -> float:
        """One round (in place); the total gain applied."""
        Q = _gather(self.D, q) if full else None
        parts = [(L, g) for L in self.lengths if (g := self.or_opt_moves(q, L, full, Q)) is not None]
        if not parts:
            return 0.0
        i, gain, k, rev = (np.concatenate([g[c] for _, g in parts]) for c in range(4))
        L = np.concatenate([np.full(len(g[0]), L) for L, g in parts])
        keep = gain > self.tol
        if not keep.any():
            return 0.0
        i, gain, k, rev, L = i[keep], gain[keep], k[keep], rev[keep], L[keep]
        lo, hi = np.minimum(i - 1, k), np.maximum(i + L - 1, k)
        total = 0.0
        for c in _greedy_disjoint(gain, lo, hi, len(q)):
            _move_segment(q, int(i[c]), int(L[c]), int(k[c]), bool(rev[c]))
            total += gain[c]
        return total

    # -- drivers
    def _live(self) -> bool:
        return self.budget > 0 and time.perf_counter() < self.deadline

    def _round(self, round_fn, q: np.ndarray, full: bool) -> bool:
        if not self._live():
            return False
        self.budget -= 1
        return round_fn(q, full) > 0.0

    def _rounds(self, round_fn, q: np.ndarray, full: bool) -> bool:
        """Rounds until none improves or the budget/deadline runs out; True if any did."""
        improved = False
        while self._round(round_fn, q, full):
            improved = True
        return improved

    def descend(self, q: np.ndarray, round_fns, certify: bool = True) -> np.ndarray:
        """Restricted rounds of each move in turn until none improves, then (``certify``) one full
        round of each; back to restricted rounds if a full one still improved."""
        while True:
            improved = True
            while improved:
                improved = self._each(round_fns, q, self._rounds, full=False)
            if not certify or not self._each(round_fns, q, self._round, full=True):
                return q

    @staticmethod
    def _each(round_fns, q, runner, *, full: bool) -> bool:
        """Run ``runner`` for every move in turn (no short cut); True if any improved."""
        improved = False
        for fn in round_fns:
            improved |= runner(fn, q, full)
        return improved


def _move_segment(q: np.ndarray, i: int, L: int, k: int, rev: bool) -> None:
    """Move q[i:i+L] (reversed if ``rev``) between q[k] and q[k+1], in place."""
    seg = q[i:i + L][::-1] if rev else q[i:i + L]
    if k < i:
        q[k + 1:i + L] = np.concatenate([seg, q[k + 1:i]])
    else:
        q[i:k + 1] = np.concatenate([q[i + L:k + 1], seg])


# ----------------------------------------------------------------------------- public API
TIE_TOLERANCE = 1e-9
"""With a ``priority``, :func:`nearest_neighbour_paths` treats costs within
``TIE_TOLERANCE · (1 + |c|)`` of the cheapest ``c`` as tied: eq.-2 costs are sums of square roots,
so equal distances on the grid can differ in their last bits."""


def nearest_neighbour_paths(cost, firsts, *, seconds=None, priority=None) -> np.ndarray:
    """Nearest-neighbour paths, one per first waypoint, all built together (one numpy step per position).

    Each path starts at its first waypoint, goes to its forced second waypoint if it has one, and
    then always on to the cheapest waypoint it has not visited. This is the one construction of the
    package: :func:`nearest_neighbour` (and so the ``local`` method), the exact solver's hint and the
    ``greedy`` baseline are built on it.

    Parameters
    ----------
    cost : array_like, shape (n, n)
        Finite costs (need not be symmetric: a path is built in its own direction).
    firsts : array_like of int, shape (k,)
        The first waypoint of each path.
    seconds : array_like of int, shape (k,), optional, keyword-only
        A forced second waypoint per path, or -1 for none (the greedy baseline's random second step).
    priority : array_like of float, shape (k, n), optional, keyword-only
        Tie-break: of the waypoints within :data:`TIE_TOLERANCE` of the cheapest, path ``r`` takes
        the one of lowest ``priority[r, j]`` (random priorities break ties at random). Without it,
        ties go to the lowest index.

    Returns
    -------
    ndarray of int64, shape (k, n)
        One order per row.

    Raises
    ------
    ParameterError
        On a malformed cost matrix, a waypoint index outside 0…n−1, a forced second waypoint equal to
        its path's first, or a ``priority`` of the wrong shape.

    Examples
    --------
    >>> C = np.abs(np.subtract.outer([0.0, 3, 1, 7], [0.0, 3, 1, 7]))  # points on a line
    >>> nearest_neighbour_paths(C, [1, 3]).tolist()
    [[1, 2, 0, 3], [3, 1, 2, 0]]
    >>> nearest_neighbour_paths(C, [0], seconds=[3]).tolist()  # forced to 3 first, then greedy
    [[0, 3, 1, 2]]
    >>> T = np.ones((3, 3)) - np.eye(3)  # every leg ties: the lowest index, or the lowest priority
    >>> nearest_neighbour_paths(T, [0, 0]).tolist()
    [[0, 1, 2], [0, 1, 2]]
    >>> nearest_neighbour_paths(T, [0, 0], priority=[[0, 1, 0], [0, 0, 1]]).tolist()
    [[0, 2, 1], [0, 1, 2]]
    """
    C = _check_square(cost)
    n = len(C)
    firsts = _check_indices(firsts, "firsts", n)
    k = len(firsts)
    if seconds is not None:
        seconds = _check_indices(seconds, "seconds", n, allow=-1)
        if seconds.shape != firsts.shape or (seconds == firsts).any():
            raise ParameterError(f"seconds must hold one waypoint per path ({k}), -1 or other than its first, "
                                 f"got {seconds.tolist()}")
    if priority is not None:
        try:
            priority = np.asarray(priority, dtype=float)
        except (TypeError, ValueError) as err:
            raise ParameterError(f"priority must be a ({k}, {n}) array of numbers, got {reprlib.repr(priority)}") from err
        if priority.shape != (k, n):
            raise ParameterError(f"priority must have shape ({k}, {n}), one row per path, got {priority.shape}")
    rows = np.arange(k)
    orders = np.empty((k, n), dtype=np.int64)
    visited = np.zeros((k, n), dtype=bool)
    orders[:, 0] = firsts
    visited[rows, firsts] = True
    for step in range(1, n):
        options = np.where(visited, np.inf, C[orders[:, step - 1]])
        if priority is None:
            chosen = options.argmin(1)  # the first minimum: the lowest index among ties
        else:
            nearest = options.min(axis=1, keepdims=True)
            tied = options <= nearest + TIE_TOLERANCE * (1.0 + np.abs(nearest))
            chosen = np.where(tied, priority, np.inf).argmin(1)
        if step == 1 and seconds is not None:
            chosen = np.where(seconds >= 0, seconds, chosen)
        orders[:, step] = chosen
        visited[rows, chosen] = True
    return orders


def _check_indices(values, name: str, n: int, allow: int | None = None) -> np.ndarray:
    """A 1-D int64 array of waypoint indices in 0…n−1 (or equal to ``allow``)."""
    try:
        array = np.asarray(values)
    except (TypeError, ValueError) as err:
        raise ParameterError(f"{name} must be waypoint indices, got {values!r}") from err
    ok = array.ndim == 1 and (array.size == 0 or np.issubdtype(array.dtype, np.integer))
    if ok:
        array = array.astype(np.int64)
        inside = (array >= 0) & (array < n)
        ok = bool((inside if allow is None else inside | (array == allow)).all())
    if not ok:
        raise ParameterError(f"{name} must be a 1-D sequence of waypoint indices in 0…{n - 1}, got {values!r}")
    return array


def nearest_neighbour(cost, *, start: int | None = None, max_starts: int = 32) -> np.ndarray:
    """The nearest-neighbour path: from the start, always on to the cheapest unvisited waypoint.

    Parameters
    ----------
    cost : array_like, shape (n, n)
        Symmetric, finite costs.
    start : int, optional
        The first waypoint. None (free start) runs the construction from several starts at once
        (:func:`nearest_neighbour_paths`) and returns the cheapest path: from every waypoint when
        ``n ≤ max_starts``, otherwise from the ``max_starts`` waypoints of largest total cost to
        the others — the periphery, where a good open path tends to begin (a choice of ours).
    max_starts : int
        See ``start``.

    Returns
    -------
    ndarray of int64, shape (n,)
        The order; ties go to the lowest index (between starts too).

    Raises
    ------
    ParameterError
        On a malformed cost matrix, a start outside 0…n−1 or ``max_starts < 1``.

    Examples
    --------
    >>> C = np.abs(np.subtract.outer([0.0, 3, 1, 7], [0.0, 3, 1, 7]))  # points on a line
    >>> nearest_neighbour(C, start=1).tolist()
    [1, 2, 0, 3]
    >>> nearest_neighbour(C).tolist()  # free start: begin at an end of the line
    [0, 2, 1, 3]
    """
    C = _check_cost(cost)
    n = len(C)
    max_starts = check_int(max_starts, "max_starts", minimum=1)
    start = check_int(start, "start", minimum=0, maximum=n - 1, allow_none=True)
    if start is not None:
        starts = np.array([start], dtype=np.int64)
    elif n <= max_starts:
        starts = np.arange(n, dtype=np.int64)
    else:
        starts = np.sort(np.argsort(-C.sum(1), kind="stable")[:max_starts])
    orders = nearest_neighbour_paths(C, starts)
    return orders[int(np.argmin(_path_costs(C, orders)))].copy()


def two_opt(cost, order, *, fixed_start: bool = True, max_rounds: int | None = None) -> np.ndarray:
    """Open-path 2-opt: reverse sub-paths ``order[i..j]`` while that shortens the path.

    Each round prices the candidate reversals at once and applies a greedy set of non-overlapping
    improving ones (largest gain first); see the module docstring for the restricted and full
    rounds. Reversing a suffix changes one edge only; with ``fixed_start=False`` reversing a prefix
    too.

    Parameters
    ----------
    cost : array_like, shape (n, n)
        Symmetric, finite costs.
    order : array_like of int
        A permutation of 0…n−1.
    fixed_start : bool
        Keep ``order[0]`` first (True) or let any waypoint begin the path.
    max_rounds : int, optional
        Stop after this many rounds (None: at the 2-opt local optimum).

    Returns
    -------
    ndarray of int64
        The improved order: never costlier than ``order``, and with no improving reversal left
        unless ``max_rounds`` cut the search short.

    Raises
    ------
    ParameterError
        On a malformed cost matrix or order, or a negative ``max_rounds``.

    Examples
    --------
    >>> C = np.abs(np.subtract.outer([0.0, 1, 2, 3, 4], [0.0, 1, 2, 3, 4]))
    >>> two_opt(C, [0, 3, 2, 1, 4]).tolist()
    [0, 1, 2, 3, 4]
    >>> two_opt(C, [2, 1, 0, 3, 4]).tolist()  # the start stays: nothing beats 2 1 0 3 4
    [2, 1, 0, 3, 4]
    >>> two_opt(C, [2, 1, 0, 3, 4], fixed_start=False).tolist()
    [0, 1, 2, 3, 4]
    """
    C = _check_cost(cost)
    p = _check_order(order, len(C))
    fixed_start = check_bool(fixed_start, "fixed_start")
    search = _Search(C, fixed_start, max_rounds=_check_rounds(max_rounds))
    return _unpad(search.descend(_pad(p, len(C), fixed_start), [search.two_opt_round]), fixed_start)


def or_opt(cost, order, *, fixed_start: bool = True, segment_lengths=(1, 2, 3),
           max_rounds: int | None = None) -> np.ndarray:
    """Or-opt: move a segment of consecutive waypoints, as is or reversed, to a cheaper place.

    Each round prices the candidate moves of every segment length at once and applies a greedy set
    of non-overlapping improving ones (restricted rounds, then a certifying full one).

    Parameters
    ----------
    cost : array_like, shape (n, n)
        Symmetric, finite costs.
    order : array_like of int
        A permutation of 0…n−1.
    fixed_start : bool
        Keep ``order[0]`` first (True) or let segments move to the front too.
    segment_lengths : sequence of int
        The lengths of the segments that move.
    max_rounds : int, optional
        Stop after this many rounds (None: at the Or-opt local optimum).

    Returns
    -------
    ndarray of int64
        The improved order, never costlier than ``order``.

    Raises
    ------
    ParameterError
        On a malformed cost matrix or order, a non-positive segment length or a negative
        ``max_rounds``.

    Examples
    --------
    >>> C = np.abs(np.subtract.outer([0.0, 1, 2, 3, 4], [0.0, 1, 2, 3, 4]))
    >>> or_opt(C, [0, 1, 4, 2, 3]).tolist()
    [0, 1, 2, 3, 4]
    """
    C = _check_cost(cost)
    p = _check_order(order, len(C))
    fixed_start = check_bool(fixed_start, "fixed_start")
    lengths = _check_lengths(segment_lengths)
    search = _Search(C, fixed_start, lengths, max_rounds=_check_rounds(max_rounds))
    return _unpad(search.descend(_pad(p, len(C), fixed_start), [search.or_opt_round]), fixed_start)


def improve(cost, order, *, fixed_start: bool = True, segment_lengths=(1, 2, 3),
            max_rounds: int | None = None) -> np.ndarray:
    """2-opt to its local optimum, then Or-opt, again and again until neither improves.

    Parameters
    ----------
    cost : array_like, shape (n, n)
        Symmetric, finite costs.
    order : array_like of int
        A permutation of 0…n−1.
    fixed_start : bool
        Keep ``order[0]`` first.
    segment_lengths : sequence of int
        Or-opt's segment lengths.
    max_rounds : int, optional
        Total budget of rounds of both moves (None: to the joint local optimum).

    Returns
    -------
    ndarray of int64
        An order that neither a 2-opt nor an Or-opt move improves (unless ``max_rounds`` stopped
        the search), never costlier than ``order``.

    Raises
    ------
    ParameterError
        As :func:`or_opt`.

    Examples
    --------
    >>> x = [0.0, 5, 1, 4, 2, 3]
    >>> C = np.abs(np.subtract.outer(x, x))
    >>> improve(C, [0, 1, 2, 3, 4, 5]).tolist()
    [0, 2, 4, 5, 3, 1]
    """
    C = _check_cost(cost)
    p = _check_order(order, len(C))
    fixed_start = check_bool(fixed_start, "fixed_start")
    lengths = _check_lengths(segment_lengths)
    search = _Search(C, fixed_start, lengths, max_rounds=_check_rounds(max_rounds))
    q = search.descend(_pad(p, len(C), fixed_start), [search.two_opt_round, search.or_opt_round])
    return _unpad(q, fixed_start)


def double_bridge(order, rng, *, fixed_start: bool = True) -> np.ndarray:
    """The double-bridge kick: cut the path into A B C D and reconnect it as A C B D.

    The cuts are drawn from ``rng`` (a ``numpy.random.Generator``, or a seed as in
    :func:`~htetro_opt._validation.as_rng`); A keeps the first waypoint when ``fixed_start``. Paths
    too short for three inner cuts come back unchanged.

    Examples
    --------
    >>> double_bridge(np.arange(8), np.random.default_rng(1)).tolist()
    [0, 1, 2, 4, 5, 3, 6, 7]
    """
    rng = as_rng(rng, "rng")
    p = _check_order(order, np.size(order))
    lo = 1 if check_bool(fixed_start, "fixed_start") else 0
    if len(p) - lo - 1 < 3:
        return p.copy()
    a, b, c = np.sort(rng.choice(np.arange(lo + 1, len(p)), 3, replace=False))
    return np.concatenate([p[:a], p[b:c], p[a:b], p[c:]])


def improve_batch(cost, orders, *, fixed_start: bool = True, segment_lengths=(1, 2, 3),
                  max_rounds: int | None = None, deadline: float = math.inf) -> np.ndarray:
    """:func:`improve` for many orders at once, for the memetic GA's offspring.

    Vectorised across the batch: each round applies the single best 2-opt move (then, once 2-opt
    has converged for every order, the single best Or-opt move) of every order that still improves.
    One move per round suits short paths; for long ones :func:`improve`, which applies many
    non-overlapping moves per round, converges in far fewer rounds.

    Parameters
    ----------
    cost : array_like, shape (n, n)
    orders : array_like of int, shape (B, n)
        Permutations of 0…n−1.
    fixed_start, segment_lengths, max_rounds
        As :func:`improve` (``max_rounds``: the budget of rounds of each chunk of the batch).
    deadline : float
        A ``time.perf_counter()`` instant after which no further round starts.

    Returns
    -------
    ndarray of int64, shape (B, n)
        Orders never costlier than their input; at the joint 2-opt/Or-opt local optimum unless the
        budget or deadline stopped the search.

    Examples
    --------
    >>> C = np.abs(np.subtract.outer([0.0, 1, 2, 3, 4], [0.0, 1, 2, 3, 4]))
    >>> improve_batch(C, [[0, 3, 2, 1, 4], [0, 4, 3, 2, 1]]).tolist()
    [[0, 1, 2, 3, 4], [0, 1, 2, 3, 4]]
    """
    C = _check_cost(cost)
    n = len(C)
    try:
        P = np.array(orders)
        if P.size and not np.issubdtype(P.dtype, np.integer):
            raise ValueError
        P = P.astype(np.int64).reshape(-1, n)
    except (TypeError, ValueError) as err:
        raise ParameterError(f"orders must be rows of waypoint indices, each a permutation of 0…{n - 1}, "
                             f"got {reprlib.repr(orders)}") from err
    for p in P:
        _check_order(p, n)
    fixed_start = check_bool(fixed_start, "fixed_start")
    deadline = check_real(deadline, "deadline (a time.perf_counter() instant)", finite=False)
    lengths = _check_lengths(segment_lengths)
    rounds = _check_rounds(max_rounds)
    return _improve_rows(_padded_cost(C), _tolerance(C), P, fixed_start, lengths, rounds, deadline)


def _improve_rows(D, tol, P, fixed_start, lengths=(1, 2, 3), rounds=math.inf, deadline=math.inf) -> np.ndarray:
    """:func:`improve_batch` without the checks: ``D`` the padded cost, ``P`` (B, n) orders."""
    n = len(D) - 1
    if len(P) == 0 or n < 3:
        return np.array(P, dtype=np.int64)
    tail = np.full((len(P), 1), n, dtype=np.int64)
    Qs = np.hstack([P, tail] if fixed_start else [tail, P, tail])
    chunk = max(1, _BATCH_ELEMENTS // Qs.shape[1] ** 2)
    for lo in range(0, len(Qs), chunk):
        block = Qs[lo:lo + chunk]  # a view: the phases update it in place
        budget = [rounds]
        while True:
            _batch_phase(D, block, tol, _batch_two_opt, budget, deadline)
            if not _batch_phase(D, block, tol, lambda Q: _batch_or_opt(Q, lengths), budget, deadline):
                break
    return Qs[:, :-1] if fixed_start else Qs[:, 1:-1]


def _batch_phase(D, Qs, tol, best_moves, budget: list, deadline) -> bool:
    """Best-move rounds on the padded orders ``Qs`` (in place) until none improves or the shared
    round ``budget`` runs out; True if any did."""
    active = np.arange(len(Qs))
    improved = False
    while active.size and budget[0] > 0 and time.perf_counter() < deadline:
        budget[0] -= 1
        sub = Qs[active]
        gain, source = best_moves(D[sub[:, :, None], sub[:, None, :]])
        better = gain > tol
        if not better.any():
            break
        improved = True
        active = active[better]
        Qs[active] = np.take_along_axis(sub[better], source[better], axis=1)
    return improved


def _batch_two_opt(Q: np.ndarray):
    """Best 2-opt move of each padded order (Q: (B, m, m) costs in path order): gain and the
    gather indices that apply it."""
    B, m, _ = Q.shape
    E = np.diagonal(Q, 1, axis1=1, axis2=2)
    G = E[:, :, None] - Q[:, :-1, :-1]
    G += E[:, None, :]
    G -= Q[:, 1:, 1:]
    G *= np.triu(np.ones((m - 1, m - 1), dtype=bool), 2)
    flat = G.reshape(B, -1).argmax(1)
    gain = G.reshape(B, -1)[np.arange(B), flat]
    e1, e2 = np.divmod(flat, m - 1)
    pos = np.arange(m)[None, :]
    inside = (pos > e1[:, None]) & (pos <= e2[:, None])
    source = np.where(inside, (e1 + 1 + e2)[:, None] - pos, pos)
    return gain, source


def _batch_or_opt(Q: np.ndarray, lengths):
    """Best Or-opt move of each padded order: gain and the gather indices that apply it."""
    B, m, _ = Q.shape
    best = np.full(B, -np.inf)
    move = np.zeros((B, 4), dtype=np.int64)  # i, L, k, reversed
    E = np.diagonal(Q, 1, axis1=1, axis2=2)
    K = m - 1
    for L in lengths:
        S = m - 1 - L
        if S <= 0:
            continue
        i = np.arange(1, m - L)
        removal = Q[:, i - 1, i] + Q[:, i + L - 1, i + L] - Q[:, i - 1, i + L]
        insert = Q[:, 1:m - L, :K] + Q[:, L:m - 1, 1:m]
        insert -= E[:, None, :]
        flipped = np.zeros(insert.shape, dtype=bool)
        if L > 1:
            reverse = Q[:, L:m - 1, :K] + Q[:, 1:m - L, 1:m]
            reverse -= E[:, None, :]
            flipped = reverse < insert
            np.minimum(insert, reverse, out=insert)
        r = np.arange(S)[:, None]
        kk = np.arange(K)[None, :]
        insert[:, (kk >= r) & (kk <= r + L)] = np.inf
        gain = removal[:, :, None] - insert
        flat = gain.reshape(B, -1).argmax(1)
        g = gain.reshape(B, -1)[np.arange(B), flat]
        s, k = np.divmod(flat, K)
        take = g > best
        best = np.where(take, g, best)
        rev = flipped.reshape(B, -1)[np.arange(B), flat]
        move[take] = np.stack([i[s], np.full(B, L), k, rev], axis=1)[take]
    i, L, k, rev = (move[:, c:c + 1] for c in range(4))
    pos = np.arange(m)[None, :]
    seg = np.where(rev == 1, i + L - 1 - (pos - (k + 1)), i + (pos - (k + 1)))  # when k < i
    before = np.where(pos <= k, pos, np.where(pos <= k + L, seg, pos - L))
    before = np.where(pos > i + L - 1, pos, before)
    seg_after = np.where(rev == 1, i + L - 1 - (pos - (k - L + 1)), i + (pos - (k - L + 1)))
    after = np.where(pos < i, pos, np.where(pos <= k - L, pos + L, np.where(pos <= k, seg_after, pos)))
    source = np.where(k < i, before, after)
    return best, source


def solve_local(instance, *, seed=0, time_limit: float | None = None, restarts: int = 0,
                max_starts: int = 32, progress=None) -> tuple[np.ndarray, dict]:
    """Nearest neighbour, then 2-opt/Or-opt to a local optimum; optionally iterated local search.

    With ``restarts > 0``, each restart kicks the best order so far with a :func:`double_bridge`
    drawn from the ``seed``'s generator, improves it again, and keeps it if it is cheaper.

    Parameters
    ----------
    instance : SequencingInstance
        Costs and start (``instance.start`` None: free start).
    seed : None, int or numpy.random.Generator
        Seed of the kicks (unused without restarts): an int or a Generator reproduces a run (unless
        ``time_limit`` cuts it short), None draws fresh entropy.
    time_limit : float, optional
        Wall-clock budget in seconds: no round or restart starts after it (the nearest-neighbour
        construction always completes). None: 10 s + 1 s per 100 waypoints, at most 120 s.
    restarts : int
        Number of kicks of the iterated local search (0: plain local search).
    max_starts : int
        Passed to :func:`nearest_neighbour` for a free start.
    progress : callable, optional
        ``progress(restarts done, restarts, note)`` after the first descent and each restart.

    Returns
    -------
    order : ndarray of int64
    info : dict
        ``initial_cost`` (nearest neighbour), ``local_optimum_cost`` (after the first
        :func:`improve`), ``restarts`` (kicks done), ``improving_restarts`` and ``timed_out``.

    Raises
    ------
    ParameterError
        On a negative ``restarts``, an invalid ``seed`` or ``time_limit``.

    Examples
    --------
    >>> from htetro_opt.problems.waypoint_sequencing import SequencingInstance
    >>> x = np.array([0.0, 5, 1, 4, 2, 3])
    >>> inst = SequencingInstance(np.abs(np.subtract.outer(x, x)), np.zeros((6, 4, 2)), start=None)
    >>> order, info = solve_local(inst)
    >>> order.tolist(), info["initial_cost"], inst.path_cost(order)
    ([0, 2, 4, 5, 3, 1], 5.0, 5.0)
    """
    instance = check_instance(instance)
    restarts = check_int(restarts, "restarts", minimum=0)
    rng = as_rng(seed)
    time_limit = check_time_limit(time_limit)
    if time_limit is None:
        time_limit = default_time_limit("local", instance.n)
    progress = check_progress(progress)
    began = time.perf_counter()
    deadline = began + time_limit
    C = _check_cost(instance.cost)
    n = len(C)
    fixed = instance.start is not None
    order = nearest_neighbour(C, start=instance.start, max_starts=max_starts)
    info = {"initial_cost": float(_path_cost(C, order))}
    search = _Search(C, fixed, deadline=deadline)
    moves = [search.two_opt_round, search.or_opt_round]
    best = _unpad(search.descend(_pad(order, n, fixed), moves), fixed)
    best_cost = _path_cost(C, best)
    info["local_optimum_cost"] = float(best_cost)
    done = improving = 0
    report(progress, 0, restarts, f"local optimum {best_cost:.4g}")
    while done < restarts and time.perf_counter() < deadline:
        done += 1
        kicked = double_bridge(best, rng, fixed_start=fixed)
        # a kick changes four edges: the restricted rounds repair it; the best order is certified below
        candidate = _unpad(search.descend(_pad(kicked, n, fixed), moves, certify=False), fixed)
        cost = _path_cost(C, candidate)
        if cost < best_cost - search.tol:
            best, best_cost, improving = candidate, cost, improving + 1
        report(progress, done, restarts, f"best cost {best_cost:.4g}")
    if improving:
        best = _unpad(search.descend(_pad(best, n, fixed), moves), fixed)
    info.update(restarts=done, improving_restarts=improving, timed_out=time.perf_counter() >= deadline,
                time_limit_s=time_limit)
    return best, info


def _path_cost(C: np.ndarray, order: np.ndarray) -> float:
    return float(C[order[:-1], order[1:]].sum())


def _path_costs(C: np.ndarray, orders: np.ndarray) -> np.ndarray:
    return C[orders[:, :-1], orders[:, 1:]].sum(1)
