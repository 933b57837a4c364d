"""Nearest neighbour and 2-opt / Or-opt for the open-path waypoint TSP of Le et al. 2018: the ``local`` method.

- :func:`nearest_neighbour_paths` — the one nearest-neighbour construction, batched: many paths at
  once, each from its own first (and optionally forced second) waypoint, ties to the lowest index
  or to the lowest of a priority table. The exact solver's hint and the greedy baseline are built
  on it too;
- :func:`nearest_neighbour` — the greedy construction (from the fixed start, or the best of many
  starts);
- :func:`two_opt`, :func:`or_opt`, :func:`improve`, :func:`improve_batch` — the package's one
  2-opt / Or-opt local search, the compiled one of ``ils``
  (:meth:`~htetro_opt.solvers.sequencing._ils.LocalCore.descend`), on a plain cost matrix: they
  check their arguments, hand the open path to it and return its local optimum;
- :func:`double_bridge` — the classic kick of iterated local search;
- :func:`solve_local` — the ``local`` method of :func:`~htetro_opt.solvers.sequencing.sequence_waypoints`:
  nearest neighbour, then the local search, then optionally iterated local search.

The search makes first-improvement moves from each waypoint's :data:`NEIGHBOURS` cheapest waypoints
(neighbour lists and don't-look bits, as in ``ils``), then full passes in which every waypoint is a
candidate and no move is pruned, until one makes no move: so the result is a true local optimum of
the neighbourhood (no reversal of a sub-path, and no move of a segment of 1–3 waypoints elsewhere,
as it is or reversed, makes the path cheaper). Each full pass costs O(n²) cost look-ups, in compiled
code: on 1000 random points nearest neighbour and the search take about 0.2–0.3 s here (2 s on
3000), most of it the two or three certifying passes; a restart of the iterated search, which
certifies nothing, takes about 1 ms on 1000 points (15 ms with the earlier numpy search).

The path is **open**: it does not return to its first waypoint. The compiled search works on closed
tours, so the path is closed through a dummy waypoint: its legs cost nothing with a free start, and
with a fixed start a penalty on its legs to every other waypoint pins the start next to it (the
dummy-node reduction of :mod:`~htetro_opt.solvers.sequencing._ils`). Reversing a suffix then changes
one edge of the path, and with a free start so does reversing a prefix; moving a segment to either
end is an ordinary insertion next to the dummy.

The gains assume a symmetric cost (eq. 2 is); an asymmetric matrix is refused. Improvements smaller
than ``1e-9`` times the largest leg of the closed tour (the penalty included, and at least 1) are
ignored, so rounding noise never cycles. The compiled search is imported when a search first runs,
so that importing this module (as the exact solver and the greedy baseline do, for the
construction) does not import numba.
"""

from __future__ import annotations

import math
import reprlib
import time

import numpy as np

from htetro_opt._progress import check_progress, report
from htetro_opt._validation import as_rng, check_bool, check_int, check_real, check_time_limit
from htetro_opt.errors import ParameterError
from htetro_opt.problems.waypoint_sequencing import SequencingInstance, check_instance
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
"""Size of each waypoint's neighbour list in the local search's first phase (``ils`` uses
:data:`~htetro_opt.solvers.sequencing.ILS_NEIGHBOURS`)."""


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


def _check_rounds(max_rounds) -> int | None:
    return check_int(max_rounds, "max_rounds", minimum=0, allow_none=True)


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


# ------------------------------------------------------------------------------- the local search
def _core(C: np.ndarray, first: int | None, neighbours: int = NEIGHBOURS):
    """The compiled local search prepared on the open path of ``C`` from ``first`` (None: a free start)."""
    from htetro_opt.solvers.sequencing._ils import LocalCore  # imports numba: only when a search runs

    return LocalCore(SequencingInstance(C, None, first), neighbours=neighbours)


def _search(C: np.ndarray, p: np.ndarray, fixed_start: bool, *, two_opt: bool = True, lengths=(1, 2, 3),
            max_rounds: int | None = None) -> np.ndarray:
    """The checked order ``p`` improved by :meth:`LocalCore.descend` (paths of one or two waypoints
    have no move: unchanged)."""
    if len(p) < 3:
        return p.copy()
    core = _core(C, int(p[0]) if fixed_start else None)
    return core.descend(p, two_opt=two_opt, lengths=lengths, max_moves=max_rounds)


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

    The compiled local search (module docstring) with 2-opt moves only: first-improvement moves
    from the neighbour lists, then full passes over every reversal until one finds none. Reversing
    a suffix changes one edge only; with ``fixed_start=False`` reversing a prefix too.

    Parameters
    ----------
    cost : array_like, shape (n, n)
        Symmetric, finite costs.
    order : array_like of int
        A permutation of 0…n−1.
    fixed_start : bool
        Keep ``order[0]`` first (True) or let any waypoint begin the path.
    max_rounds : int, optional
        Make at most this many improving moves (None: to the 2-opt local optimum). The name is the
        earlier search's, each of whose rounds applied a set of moves; a round is now one move.

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
    return _search(C, p, fixed_start, lengths=(), max_rounds=_check_rounds(max_rounds))


def or_opt(cost, order, *, fixed_start: bool = True, segment_lengths=(1, 2, 3),
           max_rounds: int | None = None) -> np.ndarray:
    """Or-opt: move a segment of consecutive waypoints, as is or reversed, to a cheaper place.

    The compiled local search (module docstring) with Or-opt moves only: first-improvement moves
    from the neighbour lists, then full passes over every segment move until one finds none.

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
        Make at most this many improving moves (None: at the Or-opt local optimum); see
        :func:`two_opt`.

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
    return _search(C, p, fixed_start, two_opt=False, lengths=lengths, max_rounds=_check_rounds(max_rounds))


def improve(cost, order, *, fixed_start: bool = True, segment_lengths=(1, 2, 3),
            max_rounds: int | None = None) -> np.ndarray:
    """2-opt and Or-opt together until neither improves: the package's local search on a cost matrix.

    A thin wrapper of the compiled search of ``ils``
    (:meth:`~htetro_opt.solvers.sequencing._ils.LocalCore.descend`; module docstring).

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
        Make at most this many improving moves of either kind (None: to the joint local optimum);
        see :func:`two_opt`.

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
    return _search(C, p, fixed_start, lengths=lengths, max_rounds=_check_rounds(max_rounds))


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
    """:func:`improve` for many orders of one cost matrix, the search prepared once per first waypoint.

    Parameters
    ----------
    cost : array_like, shape (n, n)
    orders : array_like of int, shape (B, n)
        Permutations of 0…n−1.
    fixed_start, segment_lengths
        As :func:`improve`.
    max_rounds : int, optional
        The budget of improving moves of each order (None: to its local optimum).
    deadline : float
        A ``time.perf_counter()`` instant after which no pass of the search starts: the orders not
        reached by then come back as they were.

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
    out = P.copy()
    if n < 3:
        return out
    cores = {}  # one prepared search per fixed start (its penalty pins that waypoint)
    for r, p in enumerate(P):
        first = int(p[0]) if fixed_start else None
        if first not in cores:
            cores[first] = _core(C, first)
        out[r] = cores[first].descend(p, lengths=lengths, max_moves=rounds, deadline=deadline)
    return out


def solve_local(instance, *, seed=0, time_limit: float | None = None, restarts: int = 0,
                max_starts: int = 32, progress=None) -> tuple[np.ndarray, dict]:
    """Nearest neighbour, then the compiled 2-opt/Or-opt search to a local optimum; optionally iterated.

    With ``restarts > 0``, each restart kicks the best order so far with a :func:`double_bridge`
    drawn from the ``seed``'s generator, repairs it by the neighbour-list search (no full passes),
    and keeps it if it is cheaper; the best order is then certified by the full passes.

    Parameters
    ----------
    instance : SequencingInstance
        Costs and start (``instance.start`` None: free start).
    seed : None, int or numpy.random.Generator
        Seed of the kicks (unused without restarts): an int or a Generator reproduces a run (unless
        ``time_limit`` cuts it short), None draws fresh entropy.
    time_limit : float, optional
        Wall-clock budget in seconds: no pass of the search and no restart starts after it (the
        nearest-neighbour construction, and a pass once begun, always complete). None: 10 s + 1 s
        per 100 waypoints, at most 120 s.
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
        ``initial_cost`` (nearest neighbour), ``local_optimum_cost`` (after the first descent),
        ``restarts`` (kicks done), ``improving_restarts``, ``timed_out`` and ``time_limit_s``.

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
    fixed = instance.start is not None
    tol = _tolerance(C)
    order = nearest_neighbour(C, start=instance.start, max_starts=max_starts)
    info = {"initial_cost": float(_path_cost(C, order))}
    # the open path from the instance's start (a closed tour or a fixed end reaches this method as
    # the dispatcher's open-path reduction)
    core = _core(C, instance.start) if len(C) >= 3 else None
    best = order if core is None else core.descend(order, deadline=deadline)
    best_cost = _path_cost(C, best)
    info["local_optimum_cost"] = float(best_cost)
    done = improving = 0
    report(progress, 0, restarts, f"local optimum {best_cost:.4g}")
    while done < restarts and time.perf_counter() < deadline:
        done += 1
        kicked = double_bridge(best, rng, fixed_start=fixed)
        # a kick changes three edges: the neighbour-list search repairs it; the best order is certified below
        candidate = kicked if core is None else core.descend(kicked, certify=False, deadline=deadline)
        cost = _path_cost(C, candidate)
        if cost < best_cost - tol:
            best, best_cost, improving = candidate, cost, improving + 1
        report(progress, done, restarts, f"best cost {best_cost:.4g}")
    if improving:
        best = core.descend(best, deadline=deadline)
    info.update(restarts=done, improving_restarts=improving, timed_out=time.perf_counter() >= deadline,
                time_limit_s=time_limit)
    return best, info


def _path_cost(C: np.ndarray, order: np.ndarray) -> float:
    return float(C[order[:-1], order[1:]].sum())


def _path_costs(C: np.ndarray, orders: np.ndarray) -> np.ndarray:
    return C[orders[:, :-1], orders[:, 1:]].sum(1)
