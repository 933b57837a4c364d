"""One entry point for every waypoint-sequencing method (Le et al. 2018), and the result they share.

Every method is a function ``solve_<name>(instance, *, seed=0, time_limit=None, **options)`` that
returns ``(order, info)``: the waypoint indices in visiting order and a dict of JSON-ready extras
(``{"optimal": True}``, generation counts, …). :func:`sequence_waypoints` runs one, re-checks that the
order visits every waypoint once from the start, and prices it with the instance's own cost matrix,
so a method cannot report a cost its order does not have. A user's callable with the same signature
is a method too.
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
from htetro_opt.problems.waypoint_sequencing import SequencingInstance, check_instance

__all__ = ["SEQUENCE_METHODS", "EXACT_AUTO_LIMIT", "SequenceResult", "sequence_waypoints"]

_METHODS = {
    "exact": ("._exact", "solve_exact", {}),
    "ortools": ("._ortools", "solve_ortools", {}),
    "local": ("._local", "solve_local", {}),
    # the memetic GA finds its best within a few generations; 50 more without improvement suffice
    "ga": ("._ga", "solve_ga", {"memetic": True, "patience": 50}),
    "ga-plain": ("._ga", "solve_ga", {"memetic": False}),
    "zigzag": ("._baselines", "solve_zigzag", {"rows": 1}),
    "zigzag2": ("._baselines", "solve_zigzag", {"rows": 2}),
    "spiral": ("._baselines", "solve_spiral", {"rows": 1}),
    "spiral2": ("._baselines", "solve_spiral", {"rows": 2}),
    "greedy": ("._baselines", "solve_greedy", {}),
}

SEQUENCE_METHODS: tuple[str, ...] = ("auto",) + tuple(_METHODS)
"""Method names: ``auto`` (the default), then every method."""

EXACT_AUTO_LIMIT = 40
"""``auto`` proves the optimum with the exact solver up to this many waypoints, and runs the local
search beyond (the winner on the 1000-waypoint benchmark, benchmarks/README.md)."""


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


def _resolve(method, n: int) -> tuple[str, object, dict]:
    if callable(method):
        return getattr(method, "__name__", type(method).__name__), method, {}
    if method == "auto":
        method = "exact" if n <= EXACT_AUTO_LIMIT else "local"
    if method not in _METHODS:
        raise ParameterError(f"unknown sequencing method {method!r}: expected one of {', '.join(SEQUENCE_METHODS)} "
                             "or a callable")
    module, function, preset = _METHODS[method]
    return method, getattr(import_module(module, __package__), function), preset


def sequence_waypoints(instance: SequencingInstance, *, method="auto", seed=0, time_limit: float | None = None,
                       progress=None, **options) -> SequenceResult:
    """Order the waypoints of an instance with one method.

    Parameters
    ----------
    instance : SequencingInstance
        Costs, block cells and start.
    method : str or callable, keyword-only
        One of :data:`SEQUENCE_METHODS`. ``auto`` is the exact solver up to
        :data:`EXACT_AUTO_LIMIT` waypoints and the local search beyond. A callable
        ``method(instance, *, seed, time_limit, **options)`` returning ``(order, info)`` is run the same way.
    seed : None, int or numpy.random.Generator, keyword-only
        Seed of the stochastic methods (the deterministic ones and ortools, which has no seed,
        check it and ignore it): an int or a Generator reproduces a run, None draws fresh entropy.
    time_limit : float, optional, keyword-only
        Wall-clock budget in seconds for the methods that take one (exact, ortools, ga, ga-plain,
        local, greedy): a positive, finite number; None: the method's default, sized to the instance
        (:func:`default_time_limit`: exact 60 s; ortools 1 s up to 20 waypoints,
        rising to 30 s at 40; ga, ga-plain 10 s + 1 s per 50 waypoints, at most 60 s; greedy 10 s + 1 s
        per 100 waypoints, at most 30 s; local 10 s + 1 s per 100 waypoints, at most 120 s).
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
        On an unknown method or option value (an infinite ``time_limit`` among them), or an
        ``instance`` that is not a :class:`SequencingInstance`.

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
    name, function, preset = _resolve(method, instance.n)
    if progress is not None and _takes(function, "progress"):
        options = {**options, "progress": progress}
    began = time.perf_counter()
    order, info = function(instance, seed=seed, time_limit=time_limit, **{**preset, **options})
    runtime = time.perf_counter() - began
    order = instance.check_order(order)
    label = name if method == name or callable(method) else f"{method} ({name})"
    return SequenceResult(label, order, instance.tile_order(order), instance.path_cost(order), runtime, dict(info))
