"""Outside TSP solvers behind ``method=``: ``fast-tsp`` (the fast-tsp package, MIT) and ``lkh`` (LKH-3
by Keld Helsgaun through the elkai package, whose licence allows academic, non-commercial use only).

Both are optional (``pip install "htetro-opt[fast-tsp]"``, ``"htetro-opt[lkh]"``), imported only
when their method runs, and both solve **closed tours on integer matrices**. So each instance is
restated, with its result decoded and re-priced by the dispatcher like every other method's:

- **Integer costs.** The off-diagonal costs are shifted to be non-negative (every tour, and every
  path through the dummy node below, has the same number of real legs, so a shift changes every
  order's cost alike) and scaled so that the largest becomes the solver's resolution, then rounded.
  An integer matrix that fits (TSPLIB's) is used as it is, scale 1, so its optimum is exact. After
  scaling, each leg is off by at most half a unit: an order's rounded cost is within
  ``legs / (2 · scale)`` of its true cost, so the solver's best order may be up to
  ``legs / scale`` above the true optimum. fast-tsp stores costs as 16-bit integers: the resolution
  is 65 535 for a closed tour or a free path, 32 767 when a start or end is pinned (the dummy's
  penalty needs the other half) — about 1.5·10⁻⁵·max|C| per leg, e.g. 0.0014 cells per leg on the
  85-cell eq.-2 costs of a 64 × 64 map. LKH's resolution is :data:`LKH_RESOLUTION` (10⁶; LKH
  multiplies costs by its PRECISION of 100 in 32-bit integers).
- **Open paths** (the paper's problem) by the standard dummy-node reduction: one more node ``d``,
  every path a tour cut at ``d``. Legs to ``d`` cost 0, except that a fixed start ``s`` (and a fixed
  end ``e``) is pinned next to ``d``: with a symmetric matrix, ``d``'s legs to every other node cost
  ``K = 2·max + 1`` (in integer units); with an asymmetric one (``lkh`` only), the legs from ``d`` to
  nodes other than ``s`` and from nodes other than ``e`` to ``d`` cost ``K``. Any tour using a ``K``
  leg can be rearranged into one that does not at a cost of at most ``max`` per ``K`` leg saved, so
  an optimal tour never uses one. A heuristic's tour that does is still decoded to a valid order
  (rotated to the start, the end moved last) and re-priced.
- **Closed tours** as they are; the order is rotated to begin at the start (waypoint 0 when free).

Seeds: neither package takes one. fast-tsp (one thread by default) searches until its time budget
runs out, so, like ``ortools``, its result depends on how far it gets (tours of up to 20 nodes are
solved exactly and are reproducible); elkai runs LKH with its fixed internal seed, so the same
instance always gives the same order. Both check ``seed`` and ignore it.
"""

from __future__ import annotations

from importlib import import_module

import numpy as np

from htetro_opt._validation import check_int, check_seed, check_time_limit
from htetro_opt.errors import ParameterError
from htetro_opt.problems.waypoint_sequencing import SequencingInstance, check_instance
from htetro_opt.solvers.sequencing._budgets import default_time_limit
from htetro_opt.solvers.sequencing._spec import check_candidates

__all__ = ["FAST_TSP_RESOLUTION", "LKH_RESOLUTION", "solve_fast_tsp", "solve_lkh"]

FAST_TSP_RESOLUTION = 2**16 - 1
"""fast-tsp's largest integer cost (it stores costs as uint16)."""

LKH_RESOLUTION = 10**6
"""The largest integer cost handed to LKH (it multiplies costs by 100 in 32-bit integers)."""

_INSTALL = {
    "fast-tsp": ("fast_tsp", "the fast-tsp package (MIT licence): pip install \"htetro-opt[fast-tsp]\""),
    "lkh": ("elkai", "the elkai package, which runs LKH-3 by Keld Helsgaun; its licence allows academic, "
                     "non-commercial use only: pip install \"htetro-opt[lkh]\""),
}


def _package(method: str):
    module, text = _INSTALL[method]
    try:
        return import_module(module)
    except ImportError as err:
        raise ParameterError(f"method {method!r} needs {text}") from err


class _TourProblem:
    """An instance as a closed tour on an integer matrix (module docstring), and the way back."""

    def __init__(self, instance: SequencingInstance, resolution: int):
        n = instance.n
        C = instance.cost
        self.symmetric = instance.symmetric
        if self.symmetric:
            C = (C + C.T) / 2  # equal within 1e-9 already; exactly equal, so rounding keeps it symmetric
        off = ~np.eye(n, dtype=bool)
        C = C - (min(0.0, float(C[off].min())) if n > 1 else 0.0)
        self.n, self.start, self.end, self.closed = n, instance.start, instance.end, instance.closed
        self.pinned = [p for p in (self.start, self.end) if p is not None] if not self.closed else []
        budget = (resolution - 1) // 2 if self.pinned else resolution
        top = float(C[off].max()) if n > 1 else 0.0
        integral = bool(np.all(C[off] == np.rint(C[off])))
        self.scale = 1.0 if (integral and top <= budget) or top == 0 else budget / top
        T = np.rint(C * self.scale).astype(np.int64)
        np.fill_diagonal(T, 0)
        if self.closed:
            self.matrix, self.dummy = T, None
            return
        d = self.dummy = n
        big = 2 * int(T.max()) + 1
        M = np.zeros((n + 1, n + 1), dtype=np.int64)
        M[:n, :n] = T
        if self.symmetric:
            if self.pinned:
                M[d, :n] = M[:n, d] = big
                for p in self.pinned:
                    M[d, p] = M[p, d] = 0
        else:
            if self.start is not None:
                M[d, :n] = big
                M[d, self.start] = 0
            if self.end is not None:
                M[:n, d] = big
                M[self.end, d] = 0
        self.matrix = M

    def decode(self, tour) -> np.ndarray:
        tour = [int(v) for v in tour]
        if len(tour) > len(self.matrix):  # a tour listing its first node again at the end
            tour = tour[:len(self.matrix)]
        if self.dummy is None:
            path = tour
        else:
            at = tour.index(self.dummy)
            path = tour[at + 1:] + tour[:at]
            if self.symmetric:  # a tour may run either way round
                if self.start is not None and path[0] != self.start and path[-1] == self.start:
                    path = path[::-1]
                elif self.start is None and self.end is not None and path[-1] != self.end and path[0] == self.end:
                    path = path[::-1]
        begin = self.start if self.start is not None else (0 if self.closed else None)
        if begin is not None and path[0] != begin:  # a closed tour's rotation, or a heuristic's miss
            at = path.index(begin)
            path = path[at:] + path[:at]
        if self.end is not None and path[-1] != self.end:
            path = [v for v in path if v != self.end] + [self.end]
        return np.array(path, dtype=np.int64)


def solve_fast_tsp(instance: SequencingInstance, *, seed=0, time_limit: float | None = None, threads: int = 1,
                   candidates: str = "auto") -> tuple[np.ndarray, dict]:
    """An order by fast-tsp's local search (Or-opt, 2-opt and Or-3opt moves with neighbour lists in an
    iterated local search, compiled), the ``fast-tsp`` method.

    Needs the optional fast-tsp package (MIT licence, ``pip install "htetro-opt[fast-tsp]"``). Open
    paths go through the dummy-node reduction, costs through 16-bit integers (module docstring:
    about 1.5·10⁻⁵·max|C| per leg). Symmetric costs only.

    Parameters
    ----------
    instance : SequencingInstance
        Costs (symmetric), start, end, closed or open.
    seed : None, int or numpy.random.Generator
        Checked and ignored: fast-tsp takes no seed. Its search runs until ``time_limit``, so the
        result depends on how far it gets on the machine (tours of up to 20 nodes, including the
        dummy, are solved exactly).
    time_limit : float, optional
        Wall-clock budget in seconds, all of which is used (None: 0.5 s + 1 s per 400 waypoints, at
        most 30 s).
    threads : int
        fast-tsp's ``max_threads`` (default 1; it never uses more than the machine's cores).
    candidates : str
        fast-tsp's neighbour lists, one of :data:`CANDIDATE_LISTS`: ``"auto"`` (its default)
        runs LKH-style α-nearness preprocessing when it fits the budget.

    Returns
    -------
    order : ndarray of int64
    info : dict
        ``time_limit_s``, ``scale`` (integer units per cost unit) and ``threads``.

    Raises
    ------
    ParameterError
        If fast-tsp is not installed, the matrix is asymmetric, or on a bad option.

    Examples
    --------
    >>> inst = SequencingInstance.from_matrix(np.abs(np.subtract.outer([0, 5, 1, 4, 2, 3], [0, 5, 1, 4, 2, 3])))
    >>> order, info = solve_fast_tsp(inst, time_limit=0.1)
    >>> inst.path_cost(order), info["scale"]
    (5.0, 1.0)
    """
    instance = check_instance(instance)
    check_seed(seed)
    limit = check_time_limit(time_limit)
    limit = default_time_limit("fast-tsp", instance.n) if limit is None else limit
    threads = check_int(threads, "threads", minimum=1)
    candidates = check_candidates(candidates, "candidates")
    if not instance.symmetric:
        raise ParameterError("method 'fast-tsp' assumes a symmetric cost matrix, and this one is not: use lkh, "
                             "exact or ortools")
    fast_tsp = _package("fast-tsp")
    problem = _TourProblem(instance, FAST_TSP_RESOLUTION)
    info = {"time_limit_s": limit, "scale": problem.scale, "threads": threads}
    m = len(problem.matrix)
    if m <= 3:  # every tour of three nodes or fewer is the same tour, either way round
        return problem.decode(range(m)), info
    tour = fast_tsp.find_tour(problem.matrix, duration_seconds=limit, max_threads=threads, candidates=candidates)
    return problem.decode(tour), info


def solve_lkh(instance: SequencingInstance, *, seed=0, time_limit: float | None = None,
              runs: int = 1) -> tuple[np.ndarray, dict]:
    """An order by LKH-3 (Helsgaun's Lin–Kernighan heuristic) through elkai, the ``lkh`` method.

    Needs the optional elkai package (``pip install "htetro-opt[lkh]"``), whose licence allows
    academic, non-commercial use only. Symmetric and asymmetric costs; open paths through the
    dummy-node reduction (module docstring).

    Parameters
    ----------
    instance : SequencingInstance
        Costs, start, end, closed or open.
    seed : None, int or numpy.random.Generator
        Checked and ignored: elkai runs LKH with its fixed internal seed, so the same instance always
        gives the same order.
    time_limit : None
        Not supported: elkai exposes no time limit, only ``runs``. A number is refused.
    runs : int
        LKH's RUNS: independent runs from new initial tours, the best kept (default 1; each run takes
        about 6 s on 1000 random points here).

    Returns
    -------
    order : ndarray of int64
    info : dict
        ``runs`` and ``scale`` (integer units per cost unit).

    Raises
    ------
    ParameterError
        If elkai is not installed, or on a ``time_limit`` or a bad option.

    Examples
    --------
    >>> inst = SequencingInstance.from_matrix([[0, 1, 9, 9], [9, 0, 1, 9], [9, 9, 0, 1], [1, 9, 9, 0]], closed=True)
    >>> order, info = solve_lkh(inst)
    >>> order.tolist(), inst.path_cost(order)
    ([0, 1, 2, 3], 4.0)
    """
    instance = check_instance(instance)
    check_seed(seed)
    if check_time_limit(time_limit) is not None:
        raise ParameterError(f"method 'lkh' takes no time limit (elkai runs LKH for a number of runs): got "
                             f"time_limit={time_limit!r}; set runs instead")
    runs = check_int(runs, "runs", minimum=1)
    elkai = _package("lkh")
    problem = _TourProblem(instance, LKH_RESOLUTION)
    info = {"runs": runs, "scale": problem.scale}
    m = len(problem.matrix)
    if m < 3:  # elkai needs three nodes; one or two make one tour
        return problem.decode(range(m)), info
    tour = elkai.DistanceMatrix(problem.matrix.tolist()).solve_tsp(runs=runs)
    return problem.decode(tour), info
