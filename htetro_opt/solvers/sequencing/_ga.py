"""The genetic algorithm of Le et al. 2018 for the waypoint order (§4, Algorithm 2) on DEAP, as published
or with our additions.

Algorithm 2 starts from random orders (population 60), selects parents, produces children, mutates
them by swapping two random waypoints, *extends* the population with the best children and
*reduces* it back; "crossover is not included ... due to a similar waypoint re-visiting issue".
Here, as published (``ga-plain``, ``additions=()``):

- **individuals** (:class:`~htetro_opt.operators.permutation.Tour`) are permutations of the
  waypoints other than the start when the start is fixed (so every operator keeps it first), of all
  waypoints otherwise; the order is ``[start] + genes``;
- **selection**: tournaments of ``tournament_size`` (:func:`~htetro_opt.operators.permutation.select_tournament`;
  the paper says only that cheaper orders have more chances to reproduce);
- **children**: copies of the winners, each mutated with probability ``mutation_rate`` (1 for
  ``ga-plain``: without crossover an unmutated child is its parent) by the paper's swap
  (:func:`~htetro_opt.operators.permutation.swap_mutation`);
- **extend and reduce** (elitist, our reading of "adding the best children ... reduce"): parents and
  new children compete for the ``pop_size`` places. ``elite=e`` instead keeps the ``e`` best parents
  and fills the other places with the best children (a comma strategy with elitism);
- **stop** after ``max_gen`` generations, after ``patience`` generations without a better best
  order (the paper's "improvement of the current best solution"), or at ``time_limit``.

Our additions (:data:`~htetro_opt.solvers.sequencing._spec.GA_ADDITIONS`, all on in ``ga``), each
switched singly by ``additions``:

- ``crossover``: pairs of winners are crossed with probability ``crossover_rate`` by a linear order
  crossover (:func:`~htetro_opt.operators.permutation.order_crossover`), which keeps every waypoint once;
- ``distinct``: in the reduction an order already in the population takes no second place (unless
  there are too few distinct ones), so the population does not fill with copies of its best;
- ``memetic``: the cheapest ``local_search_rate`` of each generation's new children are improved by the
  compiled 2-opt/Or-opt local search of ``ils`` (:class:`~htetro_opt.solvers.sequencing._ils.LocalCore`:
  neighbour lists and don't-look bits, milliseconds per child where the earlier vectorised best-move
  search took seconds at 280+ waypoints and left the GA in its first generation) before they
  compete, the time budget checked between children.

Neither mode seeds the population from a heuristic: both start from random orders.

All randomness comes from a private ``random.Random(derive_seed(seed))``: DEAP's own operators
(``tools.cxOrdered``, ``tools.mutShuffleIndexes``, ``tools.selTournament``) draw from the global
``random`` module, so this module registers the operators of :mod:`htetro_opt.operators.permutation`,
which take that generator, on a :class:`deap.base.Toolbox` built per run, and never calls
``deap.creator``. A run leaves the global ``random`` and ``numpy.random`` states untouched and is
deterministic for an int seed or a Generator in a given state (unless ``time_limit`` stops it).
"""

from __future__ import annotations

import math
import random
import time

import numpy as np
from deap import base

from htetro_opt._progress import check_progress, report
from htetro_opt._validation import check_int, check_probability, check_time_limit, derive_seed
from htetro_opt.operators.permutation import Tour, order_crossover, select_tournament, swap_mutation
from htetro_opt.problems.waypoint_sequencing import check_instance, path_cost
from htetro_opt.solvers.sequencing._budgets import default_time_limit
from htetro_opt.solvers.sequencing._ils import LocalCore
from htetro_opt.solvers.sequencing._local import _check_cost, _tolerance
from htetro_opt.solvers.sequencing._spec import SPEC

__all__ = ["make_toolbox", "solve_ga"]


def make_toolbox(instance, rng: random.Random, *, tournament_size: int = 3) -> base.Toolbox:
    """A DEAP toolbox for one instance, every operator drawing from ``rng``.

    Registers ``individual`` (a random :class:`~htetro_opt.operators.permutation.Tour` of the
    genes), ``population(n)``, ``clone``, ``mate``
    (:func:`~htetro_opt.operators.permutation.order_crossover`), ``mutate``
    (:func:`~htetro_opt.operators.permutation.swap_mutation`), ``select(pop, k)``
    (:func:`~htetro_opt.operators.permutation.select_tournament`), ``orders(tours)`` (full waypoint
    orders, the start prepended) and ``evaluate(tours)``, which prices every tour of the list with an
    invalid fitness in one vectorised :func:`~htetro_opt.problems.waypoint_sequencing.path_cost` call
    and returns how many.

    Examples
    --------
    >>> from htetro_opt.problems.waypoint_sequencing import SequencingInstance
    >>> inst = SequencingInstance(np.abs(np.subtract.outer([0.0, 1, 2], [0.0, 1, 2])), np.zeros((3, 4, 2)), start=1)
    >>> tb = make_toolbox(inst, random.Random(0))
    >>> pop = tb.population(2)
    >>> tb.evaluate(pop), tb.orders(pop).tolist(), [t.fitness.values[0] for t in pop]
    (2, [[1, 2, 0], [1, 0, 2]], [3.0, 3.0])
    """
    instance = check_instance(instance)
    cost = np.asarray(instance.cost, dtype=float)
    start = instance.start
    genes = [i for i in range(instance.n) if i != start]

    def individual() -> Tour:
        return Tour(rng.sample(genes, len(genes)))

    def orders(tours) -> np.ndarray:
        body = np.array([list(t) for t in tours], dtype=np.int64).reshape(len(tours), len(genes))
        if start is None:
            return body
        return np.hstack([np.full((len(body), 1), start, dtype=np.int64), body])

    def evaluate(tours) -> int:
        fresh = [t for t in tours if not t.fitness.valid]
        if fresh:
            for t, c in zip(fresh, np.atleast_1d(path_cost(cost, orders(fresh))).tolist()):
                t.fitness.values = (c,)
        return len(fresh)

    toolbox = base.Toolbox()
    toolbox.register("individual", individual)
    toolbox.register("population", lambda n: [individual() for _ in range(n)])
    toolbox.register("clone", Tour.copy)
    toolbox.register("mate", order_crossover, rng=rng)
    toolbox.register("mutate", swap_mutation, rng=rng)
    toolbox.register("select", select_tournament, rng=rng, tournsize=tournament_size)
    toolbox.register("orders", orders)
    toolbox.register("evaluate", evaluate)
    return toolbox


# ---------------------------------------------------------------------------------- the solver
def _cost_of(tour: Tour) -> float:
    return tour.fitness.values[0]


def _distinct(tours) -> tuple[list, list]:
    """Tours by cost (stable), first occurrences of each order apart from the repeats."""
    seen, firsts, repeats = set(), [], []
    for t in sorted(tours, key=_cost_of):
        key = tuple(t)
        (repeats if key in seen else firsts).append(t)
        seen.add(key)
    return firsts, repeats


def _reduce(parents: list, children: list, size: int, elite: int | None, distinct: bool) -> list:
    """Extend the population with the children and reduce it to ``size`` (see the module doc)."""
    if not distinct:  # the paper's: the cheapest, copies included (sorted is stable: parents first on ties)
        if elite is None:
            return sorted(parents + children, key=_cost_of)[:size]
        keep = sorted(parents, key=_cost_of)[:elite]
        return (keep + sorted(children, key=_cost_of))[:size]
    if elite is None:
        firsts, repeats = _distinct(parents + children)
        return (firsts + repeats)[:size]
    keep = sorted(parents, key=_cost_of)[:elite]
    kept = {tuple(t) for t in keep}
    firsts, repeats = _distinct([c for c in children if tuple(c) not in kept])
    rest = sorted(parents, key=_cost_of)[elite:]
    return (keep + firsts + rest + repeats)[:size]


def solve_ga(instance, *, seed=0, time_limit: float | None = None,
             additions=SPEC.default_of("ga", "additions"), pop_size: int = SPEC.default_of("ga", "pop_size"),
             max_gen: int = SPEC.default_of("ga", "max_gen"), patience: int | None = SPEC.default_of("ga", "patience"),
             crossover_rate: float = SPEC.default_of("ga", "crossover_rate"),
             mutation_rate: float = SPEC.default_of("ga", "mutation_rate"),
             tournament_size: int = SPEC.default_of("ga", "tournament_size"), elite: int | None = None,
             local_search_rate: float = SPEC.default_of("ga", "local_search_rate"),
             progress=None) -> tuple[np.ndarray, dict]:
    """Order the waypoints with the paper's GA (Algorithm 2), with the additions given (default ``ga``'s).

    Parameters
    ----------
    instance : SequencingInstance
        Costs and start (``instance.start`` None: free start).
    seed : None, int or numpy.random.Generator
        Source of the run's private ``random.Random`` (seeded by
        :func:`~htetro_opt._validation.derive_seed`): an int or a Generator reproduces a run, None
        draws fresh entropy.
    time_limit : float, optional
        Wall-clock budget in seconds; checked every generation (and between local-search rounds).
        None: 10 s + 1 s per 50 waypoints, at most 60 s.
    additions : collection of str
        Our additions switched on, of ``"crossover"``, ``"distinct"``, ``"memetic"`` (the module doc);
        ``()`` with ``mutation_rate=1`` is the paper's GA (``ga-plain``).
    pop_size : int
        μ, the population (60 in the paper); also the number of children per generation.
    max_gen : int
        Generation cap.
    patience : int or None
        Stop after this many generations without a cheaper best order (None: never).
    crossover_rate : float
        ``crossover`` only: the probability that a pair of selected parents is crossed.
    mutation_rate : float
        Probability that a child gets a swap mutation.
    tournament_size : int
        Individuals per selection tournament.
    elite : int or None
        None: parents and children compete for every place ((μ+λ) reduction). An integer e: the e
        best parents survive and the other places go to the best children.
    local_search_rate : float
        ``memetic`` only: the share of each generation's new children (the cheapest first) that the
        local search improves (each to its local optimum).
    progress : callable, optional
        ``progress(generation, max_gen, note)`` after every generation, the note giving the best cost.

    Returns
    -------
    order : ndarray of int64
        The best order found, starting at ``instance.start`` when it is set.
    info : dict
        ``generations``, ``evaluations`` (orders priced, initial population included),
        ``additions``, ``best_generation`` (when the best order was found; 0: the initial
        population) and ``stopped`` (``"max_gen"``, ``"patience"`` or ``"time_limit"``).

    Raises
    ------
    ParameterError
        On an invalid option, e.g. ``pop_size`` below 2 or a rate outside [0, 1].

    Examples
    --------
    >>> from htetro_opt.problems.waypoint_sequencing import SequencingInstance
    >>> x = np.array([0.0, 5, 1, 4, 2, 3])
    >>> inst = SequencingInstance(np.abs(np.subtract.outer(x, x)), np.zeros((6, 4, 2)), start=0)
    >>> order, info = solve_ga(inst, seed=1, patience=20)
    >>> order.tolist(), inst.path_cost(order), info["additions"]
    ([0, 2, 4, 5, 3, 1], 5.0, ['crossover', 'distinct', 'memetic'])
    >>> order, info = solve_ga(inst, additions=(), mutation_rate=1.0, seed=1, patience=50)
    >>> inst.path_cost(order)
    5.0
    """
    instance = check_instance(instance)
    rng = random.Random(derive_seed(seed))
    additions = SPEC.options["additions"].check(additions, "additions")
    memetic, crossover, distinct = ("memetic" in additions, "crossover" in additions, "distinct" in additions)
    time_limit = check_time_limit(time_limit)
    if time_limit is None:
        time_limit = default_time_limit("ga" if memetic else "ga-plain", instance.n)
    progress = check_progress(progress)
    pop_size = check_int(pop_size, "pop_size", minimum=2)
    max_gen = check_int(max_gen, "max_gen", minimum=0)
    patience = check_int(patience, "patience", minimum=1, allow_none=True)
    crossover_rate = check_probability(crossover_rate, "crossover_rate")
    mutation_rate = check_probability(mutation_rate, "mutation_rate")
    tournament_size = check_int(tournament_size, "tournament_size", minimum=1)
    elite = check_int(elite, "elite", minimum=0, maximum=pop_size, allow_none=True)
    local_search_rate = check_probability(local_search_rate, "local_search_rate")
    cost = _check_cost(instance.cost)

    began = time.perf_counter()
    deadline = began + time_limit
    toolbox = make_toolbox(instance, rng, tournament_size=tournament_size)
    fixed = instance.start is not None
    info = {"generations": 0, "evaluations": 0, "additions": list(additions), "best_generation": 0,
            "stopped": "max_gen", "time_limit_s": time_limit}
    if instance.n - fixed <= 1:  # nothing to order
        pop = toolbox.population(1)
        info["evaluations"] = toolbox.evaluate(pop)
        return toolbox.orders(pop)[0], info

    tol = _tolerance(cost)
    core = LocalCore(instance) if memetic else None

    def local_search(children: list) -> None:
        chosen = sorted(children, key=_cost_of)[:math.ceil(local_search_rate * len(children))]
        for tour, order in zip(chosen, toolbox.orders(chosen)):
            if time.perf_counter() >= deadline:  # the budget holds inside a generation too
                return
            order = core.improve(order)
            tour[:] = order[1:].tolist() if fixed else order.tolist()
            tour.fitness.values = (float(path_cost(cost, order)),)

    pop = toolbox.population(pop_size)
    evaluations = toolbox.evaluate(pop)
    best = min(pop, key=_cost_of).copy()
    generation = stale = 0
    while generation < max_gen:
        if time.perf_counter() >= deadline:
            info["stopped"] = "time_limit"
            break
        generation += 1
        offspring = [toolbox.clone(t) for t in toolbox.select(pop, pop_size)]
        if crossover:
            for a, b in zip(offspring[::2], offspring[1::2]):
                if rng.random() < crossover_rate:
                    toolbox.mate(a, b)
                    del a.fitness.values, b.fitness.values
        for child in offspring:
            if rng.random() < mutation_rate:
                toolbox.mutate(child)
                del child.fitness.values
        fresh = [c for c in offspring if not c.fitness.valid]
        evaluations += toolbox.evaluate(fresh)
        if memetic:
            local_search(fresh)
        pop = _reduce(pop, offspring, pop_size, elite, distinct)
        leader = min(pop, key=_cost_of)
        report(progress, generation, max_gen, f"best cost {min(_cost_of(leader), _cost_of(best)):.4g}")
        if _cost_of(leader) < _cost_of(best) - tol:
            best, stale = leader.copy(), 0
            info["best_generation"] = generation
        else:
            stale += 1
            if patience is not None and stale >= patience:
                info["stopped"] = "patience"
                break
    info.update(generations=generation, evaluations=evaluations)
    return toolbox.orders([best])[0], info
