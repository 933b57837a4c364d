"""Exact waypoint sequencing (Le et al. 2018, eq. 4): the proved optimum of the open-path TSP.

Two exact methods, used as references for every heuristic sequencer:

- :func:`solve_exact` (the ``"exact"`` sequencing method, up to :data:`EXACT_MAX_SIZE` waypoints):
  CP-SAT's circuit constraint over the waypoints plus one dummy node that closes the open path. Every
  waypoint has an arc to the dummy (the path may end anywhere); the dummy has an arc to the start
  waypoint only when the start is fixed, to every waypoint when it is free. The cost of a
  Hamiltonian circuit is then the cost of the open path it contains.
- :func:`held_karp`: the Held–Karp dynamic programme in vectorised numpy, up to
  :data:`HELD_KARP_MAX_SIZE` waypoints: an independent reference for tests.

CP-SAT runs with one worker and ``linearization_level=2`` (the circuit's LP relaxation with
subtour cuts), from a hint: the cheapest nearest-neighbour path on the integer costs CP-SAT sees,
from the start or from every waypoint (built by
:func:`~htetro_opt.solvers.sequencing.nearest_neighbour_paths`). Measured on this project's loaded
2-core machine, that proves 40 waypoints optimal in 0.15–1 s (median 0.33 s over 38 instances:
uniform points, tilings, random cells; fixed and free start) and 28 waypoints in 0.1–0.4 s, while
the default 8-worker portfolio needed 10–60 s on the same instances (2 workers: 8–20 s). One worker
also makes the search reproducible: the same seed gives the same order, also among tied optima.
"""

from __future__ import annotations

import numpy as np

from htetro_opt._interrupt import on_signal
from htetro_opt._validation import check_int, check_time_limit, derive_seed
from htetro_opt.errors import ParameterError, PlanningError
from htetro_opt.problems.waypoint_sequencing import SequencingInstance, check_instance, path_cost
from htetro_opt.solvers.sequencing._local import _check_square, nearest_neighbour_paths
from htetro_opt.solvers.sequencing._spec import EXACT_MAX_SIZE, EXACT_TIME_LIMIT

__all__ = [
    "COST_RESOLUTION",
    "HELD_KARP_MAX_SIZE",
    "held_karp",
    "solve_exact",
]

COST_RESOLUTION = 1e9
"""CP-SAT needs integer costs: the largest absolute cost becomes this integer, every other cost is
scaled alike and rounded (see :func:`solve_exact` for what this guarantees)."""

HELD_KARP_MAX_SIZE = 16
"""Largest instance :func:`held_karp` accepts (its table has ``2**n · n`` entries)."""


def _greedy_hint(cost: np.ndarray, start: int | None) -> list[int]:
    """The nearest-neighbour path (ties: the lowest index) from ``start`` or, for a free start, the
    cheapest of those from every waypoint (ties: the lowest first waypoint)."""
    firsts = np.arange(len(cost)) if start is None else np.array([start])
    paths = nearest_neighbour_paths(cost, firsts)
    return paths[int(np.argmin(path_cost(cost, paths)))].tolist()


def solve_exact(instance: SequencingInstance, *, seed=0, time_limit: float | None = None,
                max_size: int = EXACT_MAX_SIZE) -> tuple[np.ndarray, dict]:
    """The optimal order of an instance's waypoints (open path), proved by CP-SAT.

    Costs are scaled so that the largest absolute cost ``M`` becomes :data:`COST_RESOLUTION`
    (10⁹) and rounded to integers. The order returned with ``optimal`` True is optimal for the
    rounded costs, so its true cost exceeds the true optimum by at most
    ``(n − 1) · M / 10⁹`` (each of the ``n − 1`` legs is off by at most half a unit, on both sides
    of the comparison) — below 4·10⁻⁸·M for 40 waypoints, far below any difference that matters.
    ``info["bound"]`` accounts for the rounding, so it bounds the true optimum, not the rounded one.

    Parameters
    ----------
    instance : SequencingInstance
        Costs and start (an index, or None for a free start).
    seed : None, int or numpy.random.Generator
        Source of CP-SAT's random seed (:func:`~htetro_opt._validation.derive_seed`: an int is used
        as it is, modulo 2³¹ − 1). The search runs on one worker, so the same seed gives the same
        order, also among tied optimal orders (which of them may depend on the seed) — unless the
        time limit interrupts the search, whose wall-clock cut-off is not reproducible. None: a
        fresh seed.
    time_limit : float, optional
        Wall-clock budget in seconds (default :data:`EXACT_TIME_LIMIT`, 60 s). When it runs out, the
        best order found so far is returned with ``optimal`` False.
    max_size : int
        Largest number of waypoints accepted (default 40; 40 random waypoints are proved in about
        a second, larger instances may take much longer).

    Returns
    -------
    order : ndarray of int64, shape (n,)
        Waypoint indices, beginning at ``instance.start`` when it is fixed.
    info : dict
        ``optimal`` (bool: proved optimal), ``bound`` (float: a valid lower bound on the true
        optimum, in cost units, rounding accounted for) and ``status`` (CP-SAT's status name).

    Raises
    ------
    ParameterError
        If the instance has more than ``max_size`` waypoints, or on a bad ``time_limit``, ``seed``
        or ``max_size``.
    PlanningError
        If the time limit runs out before any order is found.

    Examples
    --------
    >>> from htetro_opt.scenarios import parse_tileset
    >>> inst = SequencingInstance.from_tileset(parse_tileset("1a 1b 1c 1d\\n2a 2b 2c 2d\\n3a 3b 3c 3d"), start=2)
    >>> order, info = solve_exact(inst)
    >>> order.tolist(), info["optimal"], inst.path_cost(order)
    ([1, 0, 2], True, 3.0)
    """
    instance = check_instance(instance)
    limit = check_time_limit(time_limit)
    limit = EXACT_TIME_LIMIT if limit is None else limit
    random_seed = derive_seed(seed)
    max_size = check_int(max_size, "max_size", minimum=1)
    n = instance.n
    if n > max_size:
        raise ParameterError(
            f"the exact method proves optima of at most {max_size} waypoints, this instance has {n}: "
            "use the ils, ortools or local method for large instances"
        )
    start = instance.start
    if n == 1:
        return np.zeros(1, dtype=np.int64), {"optimal": True, "bound": 0.0, "status": "OPTIMAL"}

    from ortools.sat.python import cp_model  # deferred: importing OR-Tools costs ~0.3 s

    top = float(np.abs(instance.cost).max())
    scale = COST_RESOLUTION / top if top > 0 else 1.0
    scaled = instance.cost * scale
    icost = np.rint(scaled).astype(np.int64)
    rounding = float(np.abs(icost - scaled).max())  # at most 0.5

    model = cp_model.CpModel()
    dummy = n
    arcs: list[tuple[int, int, object]] = []
    terms = []
    for i in range(n):
        for j in range(n):
            if i != j:
                literal = model.new_bool_var(f"x{i}_{j}")
                arcs.append((i, j, literal))
                if icost[i, j]:
                    terms.append((int(icost[i, j]), literal))
        arcs.append((i, dummy, model.new_bool_var(f"x{i}_end")))
        if start is None or i == start:
            arcs.append((dummy, i, model.new_bool_var(f"x_begin_{i}")))
    model.add_circuit(arcs)
    model.minimize(sum(c * x for c, x in terms))
    # Hint the greedy path: a first solution and upper bound at once (the timings above are with
    # it); CP-SAT may still end at another optimum when several tie.
    greedy = _greedy_hint(icost, start)
    hinted = set(zip([dummy] + greedy, greedy + [dummy]))
    for tail, head, literal in arcs:
        model.add_hint(literal, (tail, head) in hinted)

    solver = cp_model.CpSolver()
    solver.parameters.num_workers = 1
    solver.parameters.catch_sigint_signal = False  # Ctrl-C goes to Python (htetro_opt._interrupt)
    solver.parameters.linearization_level = 2
    solver.parameters.random_seed = random_seed
    solver.parameters.max_time_in_seconds = limit
    with on_signal(solver.stop_search):  # Ctrl-C stops CP-SAT now, not at its time limit
        status = solver.solve(model)
    if status not in (cp_model.OPTIMAL, cp_model.FEASIBLE):
        raise PlanningError(
            f"CP-SAT found no order of the {n} waypoints within {limit:g} s (status {solver.status_name(status)}): "
            "raise time_limit or use the 'ortools' method"
        )
    successor = {tail: head for tail, head, literal in arcs if solver.boolean_value(literal)}
    order = []
    node = successor[dummy]
    while node != dummy:
        order.append(node)
        node = successor[node]
    # Every path's rounded cost is within (n − 1)·rounding of its scaled true cost; the last term
    # covers the float arithmetic of a cost summed over n legs.
    bound = (solver.best_objective_bound - (n - 1) * rounding) / scale
    bound -= 1e-12 * abs(bound)
    info = {"optimal": status == cp_model.OPTIMAL, "bound": float(bound), "status": solver.status_name(status)}
    return np.array(order, dtype=np.int64), info


def held_karp(cost, *, start: int | None = None) -> tuple[np.ndarray, float]:
    """The optimal open path by the Held–Karp dynamic programme (vectorised numpy, n ≤ 16).

    ``best[S, j]`` is the cheapest path that visits the waypoint set ``S`` (a bit mask) and ends at
    ``j``; the sets are filled by increasing size, all sets of one size at once. Time
    ``O(2ⁿ · n²)``, memory ``O(2ⁿ · n)``.

    Parameters
    ----------
    cost : array_like, shape (n, n)
        Cost of moving from waypoint i to waypoint j (need not be symmetric).
    start : int, optional
        Index of the first waypoint, or None for a free start.

    Returns
    -------
    order : ndarray of int64, shape (n,)
        An optimal order (the first in index order among ties).
    cost : float
        Its summed cost.

    Raises
    ------
    ParameterError
        If the matrix is not square, empty, not finite, larger than :data:`HELD_KARP_MAX_SIZE`, or
        ``start`` is not one of its indices.

    Examples
    --------
    >>> order, total = held_karp([[0, 1, 5], [1, 0, 2], [5, 2, 0]], start=1)
    >>> order.tolist(), total
    ([1, 0, 2], 6.0)
    """
    c = _check_square(cost)
    n = len(c)
    if n > HELD_KARP_MAX_SIZE:
        raise ParameterError(f"held_karp accepts at most {HELD_KARP_MAX_SIZE} waypoints, got {n}")
    start = check_int(start, "start", minimum=0, maximum=n - 1, allow_none=True)

    full = (1 << n) - 1
    bits = 1 << np.arange(n, dtype=np.int64)
    masks = np.arange(1 << n, dtype=np.int64)
    member = (masks[:, None] & bits) != 0  # member[S, j]: j in S
    size = member.sum(1)
    best = np.full((1 << n, n), np.inf)
    firsts = [start] if start is not None else range(n)
    for j in firsts:
        best[1 << j, j] = 0.0
    for k in range(2, n + 1):
        layer = masks[size == k]
        if start is not None:
            layer = layer[(layer & (1 << start)) != 0]
        # previous[m, j, i] = best[S_m without j, i] + c[i, j]: reach j last, from i.
        previous = best[layer[:, None] ^ bits[None, :]]  # (m, j, i)
        candidates = previous + c.T[None, :, :]
        value = candidates.min(axis=2)
        best[layer] = np.where(member[layer], value, np.inf)

    last = int(np.argmin(best[full]))
    order = [last]
    mask = full
    while len(order) < n:
        mask ^= 1 << last
        last = int(np.argmin(best[mask] + c[:, last]))
        order.append(last)
    order = np.array(order[::-1], dtype=np.int64)
    return order, path_cost(c, order)
