"""One entry point for every waypoint-sequencing method (Le et al. 2018), and the result they share.

Every method is a function ``solve_<name>(instance, *, seed=0, time_limit=None, **options)`` that
returns ``(order, info)``: the waypoint indices in visiting order and a dict of JSON-ready extras
(``{"optimal": True}``, generation counts, …). :func:`sequence_waypoints` runs one, re-checks that the
order visits every waypoint once from the start (to the end), and prices it with the instance's own
cost matrix, so a method cannot report a cost its order does not have. A user's callable with the
same signature is a method too.

Each method solves the paper's problem, an open path with a fixed or free start. A closed tour or a
fixed end is handed to a method that does not take it natively (all but ``fast-tsp`` and ``lkh``)
as that problem, by :func:`~htetro_opt.problems.waypoint_sequencing.reduce_to_open_path`; its order
is decoded and re-priced on the instance as given. A method that assumes symmetric costs, or needs
tile geometry, refuses an instance without them before it runs.
"""

from __future__ import annotations

import inspect
import time
from dataclasses import dataclass, field
from importlib import import_module

import numpy as np

from htetro_opt._progress import check_progress
from htetro_opt._validation import check_seed, check_time_limit
from htetro_opt.errors import ParameterError
from htetro_opt.problems.waypoint_sequencing import (
    SequencingInstance,
    check_instance,
    reduce_to_open_path,
)

__all__ = [
    "ASYMMETRIC_METHODS",
    "EXACT_AUTO_LIMIT",
    "SEQUENCE_METHODS",
    "SequenceResult",
    "auto_method",
    "sequence_waypoints",
]

# name → (module, function, preset options, capabilities): "asymmetric" (asymmetric costs allowed),
# "tours" (closed tours and fixed ends taken natively), "geometry" (needs the tiles' block cells),
# "implicit" (sequences an instance without a cost matrix, SequencingInstance.implicit)
_METHODS = {
    "exact": ("._exact", "solve_exact", {}, {"asymmetric"}),
    "ortools": ("._ortools", "solve_ortools", {}, {"asymmetric"}),
    "local": ("._local", "solve_local", {}, set()),
    "ils": ("._ils", "solve_ils", {}, {"tours", "implicit"}),
    # the memetic GA finds its best within a few generations; 50 more without improvement suffice
    "ga": ("._ga", "solve_ga", {"memetic": True, "patience": 50}, set()),
    "ga-plain": ("._ga", "solve_ga", {"memetic": False}, set()),
    "zigzag": ("._baselines", "solve_zigzag", {"rows": 1}, {"asymmetric", "geometry"}),
    "zigzag2": ("._baselines", "solve_zigzag", {"rows": 2}, {"asymmetric", "geometry"}),
    "spiral": ("._baselines", "solve_spiral", {"rows": 1}, {"asymmetric", "geometry"}),
    "spiral2": ("._baselines", "solve_spiral", {"rows": 2}, {"asymmetric", "geometry"}),
    "greedy": ("._baselines", "solve_greedy", {}, {"asymmetric"}),
    "fast-tsp": ("._backends", "solve_fast_tsp", {}, {"tours"}),
    "lkh": ("._backends", "solve_lkh", {}, {"asymmetric", "tours"}),
}

SEQUENCE_METHODS: tuple[str, ...] = ("auto",) + tuple(_METHODS)
"""Method names: ``auto`` (the default), then every method."""

ASYMMETRIC_METHODS: tuple[str, ...] = tuple(name for name, entry in _METHODS.items() if "asymmetric" in entry[3])
"""The methods that accept an asymmetric cost matrix (the others assume ``cost[i, j] == cost[j, i]``)."""

EXACT_AUTO_LIMIT = 40
"""``auto`` proves the optimum with the exact solver up to this many waypoints (a closed tour counts
one more, the copy of its first waypoint); beyond, see :func:`auto_method`."""


@dataclass(frozen=True, eq=False)
class SequenceResult:
    """A method's order, re-priced on the instance.

    ``method`` names the method (``"auto (exact)"`` when ``auto`` chose it); ``order`` holds
    waypoint indices, ``tiles`` the same order as tile labels; ``info`` the method's extras.
    """

    method: str
    order: np.ndarray
    tiles: list[int]
    cost: float
    runtime_s: float
    info: dict = field(default_factory=dict)

    def as_dict(self) -> dict:
        return {"method": self.method, "order": self.tiles, "cost": self.cost,
                "runtime_s": round(self.runtime_s, 6), **self.info}


def _takes(function, keyword: str) -> bool:
    """Whether ``function`` accepts ``keyword`` (by name or through ``**kwargs``)."""
    try:
        parameters = inspect.signature(function).parameters.values()
    except (TypeError, ValueError):  # some builtins have no signature
        return False
    return any(p.name == keyword or p.kind is p.VAR_KEYWORD for p in parameters)


def auto_method(instance: SequencingInstance) -> str:
    """The method ``method="auto"`` runs on ``instance``.

    ``exact`` up to :data:`EXACT_AUTO_LIMIT` waypoints (a closed tour counts its copied first
    waypoint too). Beyond, and for an implicit instance (no cost matrix), for symmetric costs, ``ils`` (the compiled iterated local search, whose
    budget is counted in kicks: the same seed gives the same order on every machine; numba, which
    compiles it, is a core dependency); ``ortools`` for asymmetric costs.

    Not ``fast-tsp``, although it is as good or better where measured (benchmarks/README.md,
    "Sequencing backends"): it takes no seed and stops on the clock, so its result depends on the
    machine's load, and the default must give the same result for the same seed on every machine.
    Ask for it with ``method="fast-tsp"``; ``lkh`` is deterministic but its licence is non-commercial.

    Examples
    --------
    >>> asymmetric = np.triu(np.ones((41, 41)))
    >>> auto_method(SequencingInstance.from_matrix(np.eye(5))), auto_method(SequencingInstance.from_matrix(asymmetric))
    ('exact', 'ortools')
    """
    instance = check_instance(instance)
    if instance.implicit:
        return "ils"
    size = instance.n + (1 if instance.closed and instance.n > 1 else 0)
    if size <= EXACT_AUTO_LIMIT:
        return "exact"
    if not instance.symmetric:
        return "ortools"
    return "ils"


def _resolve(method, instance: SequencingInstance) -> tuple[str, object, dict, set]:
    if callable(method):
        return getattr(method, "__name__", type(method).__name__), method, {}, {"asymmetric", "geometry"}
    if method == "auto":
        method = auto_method(instance)
    if not isinstance(method, str) or method not in _METHODS:
        raise ParameterError(f"unknown sequencing method {method!r}: expected one of {', '.join(SEQUENCE_METHODS)} "
                             "or a callable")
    module, function, preset, capabilities = _METHODS[method]
    if instance.implicit and "implicit" not in capabilities:
        raise ParameterError(f"method {method!r} needs the cost matrix, and this instance of {instance.n} waypoints "
                             "keeps its eq.-2 costs implicit (above DENSE_LIMIT waypoints): use ils or auto, or "
                             "SequencingInstance.from_tileset(..., dense=True)")
    if "geometry" in capabilities and not instance.has_geometry:
        raise ParameterError(f"method {method!r} scans the tiles' positions, and this instance has no tile geometry "
                             "(a plain cost matrix): use another method, e.g. auto")
    if "asymmetric" not in capabilities and not instance.symmetric:
        raise ParameterError(f"method {method!r} assumes a symmetric cost matrix, and this one is not: use one of "
                             f"{', '.join(ASYMMETRIC_METHODS)} (or auto)")
    return method, getattr(import_module(module, __package__), function), preset, capabilities


def sequence_waypoints(instance: SequencingInstance, *, method="auto", seed=0, time_limit: float | None = None,
                       progress=None, **options) -> SequenceResult:
    """Order the waypoints of an instance with one method.

    Parameters
    ----------
    instance : SequencingInstance
        Costs, block cells and start.
    method : str or callable, keyword-only
        One of :data:`SEQUENCE_METHODS`. ``auto`` is the exact solver up to
        :data:`EXACT_AUTO_LIMIT` waypoints and, beyond, the compiled iterated local search ``ils``
        (ortools for asymmetric costs): :func:`auto_method`. A callable
        ``method(instance, *, seed, time_limit, **options)`` returning ``(order, info)`` is run the
        same way (given the open-path reduction of a closed tour or a fixed end).
    seed : None, int or numpy.random.Generator, keyword-only
        Seed of the stochastic methods (the deterministic ones and ortools, which has no seed,
        check it and ignore it): an int or a Generator reproduces a run, None draws fresh entropy.
    time_limit : float, optional, keyword-only
        Wall-clock budget in seconds for the methods that take one (exact, ortools, ga, ga-plain,
        local, greedy, fast-tsp; lkh refuses one): a positive, finite number; None: the method's
        default, sized to the instance (:func:`default_time_limit`: exact 60 s; ortools 1 s up to 20
        waypoints, rising to 30 s at 40; ga, ga-plain 10 s + 1 s per 50 waypoints, at most 60 s;
        greedy 10 s + 1 s per 100 waypoints, at most 30 s; local 10 s + 1 s per 100 waypoints, at
        most 120 s; fast-tsp 0.5 s + 1 s per 400 waypoints, at most 30 s; ils, whose budget is
        its kicks, a safety cap of 60 s + 1 s per 20 waypoints, at most 600 s).
    progress : callable, optional, keyword-only
        ``progress(done, total, note)`` from the methods that report (ga, ga-plain, greedy, local,
        ortools; a callable method that takes a ``progress`` keyword), see :mod:`htetro_opt._progress`.
    **options
        Passed to the method (e.g. ``pop_size`` for ``ga``, ``iterations`` for ``greedy``).

    Returns
    -------
    SequenceResult

    Raises
    ------
    ParameterError
        On an unknown method or option value (an infinite ``time_limit`` among them), an
        ``instance`` that is not a :class:`SequencingInstance`, an asymmetric matrix for a method
        that assumes symmetric costs (see :data:`ASYMMETRIC_METHODS`), a plain matrix for a pattern
        baseline, or a method whose optional package is missing.

    Examples
    --------
    >>> from htetro_opt.scenarios import parse_tileset
    >>> inst = SequencingInstance.from_tileset(parse_tileset("1a 1b 1c 1d\\n2a 2b 2c 2d\\n3a 3b 3c 3d"), start=3)
    >>> result = sequence_waypoints(inst, method="exact")
    >>> result.tiles, result.cost
    ([3, 2, 1], 2.0)
    """
    check_instance(instance)
    time_limit = check_time_limit(time_limit)
    seed = check_seed(seed)
    progress = check_progress(progress)
    name, function, preset, capabilities = _resolve(method, instance)
    if progress is not None and _takes(function, "progress"):
        options = {**options, "progress": progress}
    reduction = None
    solved = instance
    if (instance.closed or instance.end is not None) and "tours" not in capabilities:
        reduction = reduce_to_open_path(instance)
        solved = reduction.instance
    began = time.perf_counter()
    order, info = function(solved, seed=seed, time_limit=time_limit, **{**preset, **options})
    runtime = time.perf_counter() - began
    info = dict(info)
    if reduction is not None:
        order = reduction.decode(solved.check_order(order))
        if "bound" in info:  # a bound on the reduction's optimum, which exceeds the instance's by the offset
            info["bound"] = float(info["bound"] - reduction.offset)
    order = instance.check_order(order)
    label = name if method == name or callable(method) else f"{method} ({name})"
    return SequenceResult(label, order, instance.tile_order(order), instance.path_cost(order), runtime, info)
