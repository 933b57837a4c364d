"""Waypoint sequencing (Le et al. 2018, eq. 4) with OR-Tools' vehicle-routing local search.

One vehicle visits every waypoint; a dummy node turns the routing model's tour into the open path:

- fixed start: the vehicle starts at the start waypoint and ends at the dummy, which every waypoint
  reaches at zero cost (``RoutingIndexManager(n + 1, 1, [start], [dummy])``);
- free start: the dummy is the depot, with zero-cost arcs to and from every waypoint.

A first solution (``PATH_CHEAPEST_ARC`` by default) is improved by guided local search until the
time limit. Guided local search does not stop by itself, so the method always runs for its whole
time limit, and its result depends on how far the search gets in that time, not on a seed: the same
instance can give different orders on a loaded machine. Routing needs integer costs: they are
scaled (see ``scale``) and rounded, and the costs are handed to OR-Tools as a matrix
(``RegisterTransitMatrix``), so that the search never calls back into Python: on 1000 waypoints a
Python transit callback made the search about ten times slower (10 s reached 7 % above what the
matrix reaches).

Measured on a loaded 2-core machine: the search reaches the proved optimum (of
:func:`~htetro_opt.solvers.sequencing.solve_exact`) on 20 waypoints within 0.4 s, on 28–30 within
2 s, on 40 after a median 1.8 s but up to 17 s (hence :func:`ortools_time_limit`). On 1000 uniform
random points (fixed start) its path was 7 % longer after 10 s, and 5 % after 30 s, than the one
the ``local`` method's iterated local search found in 10 s.
"""

from __future__ import annotations

import time

import numpy as np

from htetro_opt._interrupt import on_signal
from htetro_opt._progress import check_progress, report
from htetro_opt._validation import check_int, check_real, check_seed, check_time_limit
from htetro_opt.errors import ParameterError, PlanningError
from htetro_opt.problems.waypoint_sequencing import SequencingInstance, check_instance
from htetro_opt.solvers.sequencing._spec import FIRST_SOLUTIONS

__all__ = ["ORTOOLS_COST_RESOLUTION", "ortools_time_limit", "solve_ortools"]

ORTOOLS_COST_RESOLUTION = 1e9
"""Default cost scale: the largest absolute cost becomes this integer (as in the exact solver)."""

_MAX_PATH_UNITS = 2**53
"""Scaled path costs must stay exact in a double (guided local search prices its penalties in
floating point) and far inside int64."""

def ortools_time_limit(n: int) -> float:
    """The default time limit for ``n`` waypoints, in seconds.

    1 s up to 20 waypoints, rising linearly to 30 s at 40 waypoints, 30 s beyond. The small sizes
    get this much because guided local search's time to reach the proved optimum has a long tail.
    Measured with ``PATH_CHEAPEST_ARC`` on a loaded 2-core machine: at most 0.4 s for 20 random
    waypoints, 2 s for 28–30, and for 40 (24 instances: uniform points, tilings, random cells;
    fixed and free start) a median of 1.8 s but a worst case of 17 s (one run at 20 s ended above
    the optimum). With these defaults, 24 further instances (8 each of 20, 30 and 40 waypoints)
    all ended at the proved optimum. It is no guarantee: the time to the optimum has a long tail.

    Examples
    --------
    >>> ortools_time_limit(10), ortools_time_limit(30), ortools_time_limit(40), ortools_time_limit(1000)
    (1.0, 15.5, 30.0, 30.0)
    """
    return float(min(max(1.0 + 29.0 * (n - 20) / 20, 1.0), 30.0))


def solve_ortools(instance: SequencingInstance, *, seed=0, time_limit: float | None = None,
                  scale: float | None = None, first_solution: str = "PATH_CHEAPEST_ARC",
                  progress=None, solution_limit: int | None = None) -> tuple[np.ndarray, dict]:
    """A near-optimal order of an instance's waypoints by OR-Tools routing with guided local search.

    Parameters
    ----------
    instance : SequencingInstance
        Costs and start (an index, or None for a free start).
    seed : None, int or numpy.random.Generator
        Accepted for the method contract (and checked) but ignored: OR-Tools routing has no random
        seed. Its result depends on the time limit and on the machine's speed instead.
    time_limit : float, optional
        Wall-clock budget in seconds, all of which is used (default :func:`ortools_time_limit`:
        1 s up to 20 waypoints, rising to 30 s at 40 waypoints and beyond).
    scale : float, optional
        Multiplier turning costs into integers (``round(cost · scale)``). Default: the largest
        absolute cost becomes :data:`ORTOOLS_COST_RESOLUTION` (10⁹); an order's rounded cost is
        then within ``(n − 1) / (2 · scale)`` of its true cost.
    first_solution : str
        One of :data:`FIRST_SOLUTIONS`.
    progress : callable, optional
        ``progress(seconds spent, time limit, note)`` at most five times a second, the note giving the
        cost of the solution the search is at.
    solution_limit : int, optional
        Stop after this many solutions (the first one and each the local search moves to), whichever of
        it and the time limit comes first. The search is deterministic, so a run stopped by it gives the
        same order on every machine. None (default): only the time limit.

    Returns
    -------
    order : ndarray of int64, shape (n,)
        Waypoint indices, beginning at ``instance.start`` when it is fixed.
    info : dict
        ``status`` (OR-Tools' search status), ``time_limit_s`` and ``scale`` used, ``solutions``
        (how many the search went through) and ``time_limited`` (False only when ``solution_limit``
        stopped it: then the order does not depend on the machine's speed).

    Raises
    ------
    ParameterError
        On a bad ``seed``, ``time_limit``, ``scale`` (not positive, or so large that a path's
        scaled cost could reach 2⁵³), ``first_solution`` or ``solution_limit``.
    PlanningError
        If OR-Tools finds no order within the time limit.

    Examples
    --------
    >>> from htetro_opt.scenarios import parse_tileset
    >>> inst = SequencingInstance.from_tileset(parse_tileset("1a 1b 1c 1d\\n2a 2b 2c 2d\\n3a 3b 3c 3d"), start=2)
    >>> order, info = solve_ortools(inst, time_limit=0.1)
    >>> int(order[0]), inst.path_cost(order)  # from tile 2, then tile 1 or tile 3: both cost 3
    (1, 3.0)
    """
    instance = check_instance(instance)
    n = instance.n
    check_seed(seed)
    limit = check_time_limit(time_limit)
    limit = ortools_time_limit(n) if limit is None else limit
    progress = check_progress(progress)
    solution_limit = check_int(solution_limit, "solution_limit", minimum=1, allow_none=True)
    if not isinstance(first_solution, str) or first_solution.upper() not in FIRST_SOLUTIONS:
        raise ParameterError(f"first_solution must be one of {', '.join(FIRST_SOLUTIONS)}; got {first_solution!r}")
    top = float(np.abs(instance.cost).max())
    scale = check_real(scale, "scale", minimum=0, include_minimum=False, allow_none=True)
    if scale is None:
        factor = ORTOOLS_COST_RESOLUTION / top if top > 0 else 1.0
    elif top * scale * n >= _MAX_PATH_UNITS:
        raise ParameterError(
            f"scale={scale!r} makes path costs reach 2**53, beyond exact integers in a double "
            f"(largest cost {top:g}, {n} waypoints): "
            f"use a scale below {_MAX_PATH_UNITS / (top * n):.3g}"
        )
    else:
        factor = scale
    if n == 1:
        return np.zeros(1, dtype=np.int64), {"status": "TRIVIAL", "time_limit_s": limit, "scale": factor,
                                             "solutions": 1, "time_limited": False}

    from ortools.constraint_solver import pywrapcp, routing_enums_pb2  # deferred: a slow import

    # The limit counts building the model too (the user's clock, not only OR-Tools' search), the first
    # import apart, as a compile is; the search keeps a tenth of it at least, to find a first order.
    entered = time.perf_counter()

    dummy = n
    matrix = np.zeros((n + 1, n + 1), dtype=np.int64)
    matrix[:n, :n] = np.rint(instance.cost * factor)
    start = instance.start
    if start is None:
        manager = pywrapcp.RoutingIndexManager(n + 1, 1, dummy)
    else:
        manager = pywrapcp.RoutingIndexManager(n + 1, 1, [int(start)], [dummy])
    routing = pywrapcp.RoutingModel(manager)
    transit = routing.RegisterTransitMatrix(matrix.tolist())  # indexed by node, not routing index
    routing.SetArcCostEvaluatorOfAllVehicles(transit)

    params = pywrapcp.DefaultRoutingSearchParameters()
    params.first_solution_strategy = getattr(routing_enums_pb2.FirstSolutionStrategy, first_solution.upper())
    params.local_search_metaheuristic = routing_enums_pb2.LocalSearchMetaheuristic.GUIDED_LOCAL_SEARCH
    began = time.perf_counter()
    params.time_limit.FromMilliseconds(max(1, round(max(limit - (began - entered), 0.1 * limit) * 1000)))
    if solution_limit is not None:
        params.solution_limit = solution_limit
    last_report = [began]
    solutions = [0]
    with on_signal() as interrupted:
        def at_solution() -> None:
            # Guided local search only stops at its time limit: end it at the next solution it visits
            # (measured at most ~0.2 s apart on 1000 waypoints) once Ctrl-C or SIGTERM has arrived.
            solutions[0] += 1
            if interrupted.is_set():
                routing.solver().FinishCurrentSearch()
            now = time.perf_counter()
            if progress is not None and now - last_report[0] >= 0.2:  # thousands of solutions a second
                last_report[0] = now
                report(progress, round(now - began, 1), limit, f"cost {routing.CostVar().Value() / factor:.4g}")

        routing.AddAtSolutionCallback(at_solution)
        solution = routing.SolveWithParameters(params)
    status = routing_enums_pb2.RoutingSearchStatus.Value.Name(routing.status())
    if solution is None:
        raise PlanningError(
            f"OR-Tools found no order of the {n} waypoints within {limit:g} s (status {status}): raise time_limit"
        )
    order = []
    index = routing.Start(0)
    while not routing.IsEnd(index):
        node = manager.IndexToNode(index)
        if node != dummy:
            order.append(node)
        index = solution.Value(routing.NextVar(index))
    cut = solution_limit is None or solutions[0] < solution_limit  # the clock, not the solution limit, ended it
    return np.array(order, dtype=np.int64), {"status": status, "time_limit_s": limit, "scale": factor,
                                             "solutions": solutions[0], "time_limited": cut}
