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

A TSPLIB coordinate instance keeps its costs implicit (coordinates and the metric, memory linear in n):
``ils`` (and so ``auto`` beyond the exact range) prices it as it is; a method that needs the matrix gets
it built for its run when the matrix and the method's copies of it (:data:`MATRIX_BYTES_PER_ENTRY`, about
48 bytes an entry) fit the memory budget (:func:`~htetro_opt.model.simulate.memory_budget`), and is refused with a
:class:`~htetro_opt.errors.PlanningError` naming the method, n and the memory before any work otherwise.
An implicit eq.-2 instance (a tileset above ``DENSE_LIMIT``) is refused by those methods, as before.
"""

from __future__ import annotations

import inspect
import time
from dataclasses import dataclass, field

import numpy as np

from htetro_opt._progress import check_progress
from htetro_opt._spec import DEFAULT_SEED
from htetro_opt._validation import check_seed, check_time_limit
from htetro_opt.errors import ParameterError
from htetro_opt.problems.waypoint_sequencing import (
    SequencingInstance,
    check_instance,
    reduce_to_open_path,
)
from htetro_opt.solvers._result import Result
from htetro_opt.solvers.sequencing._spec import EXACT_AUTO_LIMIT, SPEC

__all__ = [
    "ASYMMETRIC_METHODS",
    "MATRIX_BYTES_DEFAULT",
    "MATRIX_BYTES_PER_ENTRY",
    "SequenceResult",
    "auto_method",
    "sequence_waypoints",
]


def _asymmetric() -> tuple[str, ...]:
    return tuple(name for name, m in SPEC.methods.items() if "asymmetric" in m.capabilities and name != "auto")


def __getattr__(name: str):
    if name == "ASYMMETRIC_METHODS":  # read from the spec when asked: a registered method counts too
        return _asymmetric()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


@dataclass(frozen=True, eq=False)
class SequenceResult(Result):
    """A method's order, re-priced on the instance.

    ``method`` names the method (``"auto (exact)"`` when ``auto`` chose it); ``order`` holds
    waypoint indices, ``tiles`` the same order as tile labels; ``info`` the method's extras
    (``optimal`` when the order is proven optimal); ``time_limited`` whether the clock, not the method's
    own end, stopped it. Every order visits every waypoint once, so ``success`` is always True;
    ``message`` says whether the order is proven optimal.
    """

    method: str
    order: np.ndarray
    tiles: list[int]
    cost: float
    runtime_s: float
    info: dict = field(default_factory=dict)
    time_limited: bool = False

    @property
    def success(self) -> bool:
        return True

    @property
    def message(self) -> str:
        proof = "proven optimal" if self.info.get("optimal") else "not proven optimal"
        return f"{len(self.tiles)} waypoints, cost {self.cost:.6g} ({proof})"

    def _fields(self) -> dict:
        return {"order": [int(t) for t in self.tiles], "cost": float(self.cost)}


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
    waypoint too; a TSPLIB coordinate instance gets its small matrix built for it). Beyond, and for an
    implicit eq.-2 instance (no cost matrix), for symmetric costs, ``ils`` (the compiled iterated local search, whose
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
    if instance.implicit and instance.coords is None:  # eq. 2 without a matrix: only ils sequences it
        return "ils"
    size = instance.n + (1 if instance.closed and instance.n > 1 else 0)
    if size <= EXACT_AUTO_LIMIT:
        return "exact"
    if not instance.symmetric:
        return "ortools"
    return "ils"


def _resolve(method, instance: SequencingInstance):
    """(the name the result carries, the Method run, the name it runs as) of ``method`` on ``instance``,
    its capabilities checked against the instance before it runs."""
    chosen = SPEC.method(method)
    run = SPEC.method(auto_method(instance)) if chosen.name == "auto" else chosen
    capabilities = run.capabilities
    if instance.implicit and instance.coords is not None and "implicit" not in capabilities:
        _check_matrix_memory(run.name, instance)
    elif instance.implicit and "implicit" not in capabilities:
        raise ParameterError(f"method {run.name!r} needs the cost matrix, and this instance of {instance.n} waypoints "
                             "keeps its eq.-2 costs implicit (above DENSE_LIMIT waypoints): use ils or auto, or "
                             "SequencingInstance.from_tileset(..., dense=True)")
    if "geometry" in capabilities and not instance.has_geometry:
        raise ParameterError(f"method {run.name!r} scans the tiles' positions, and this instance has no tile geometry "
                             "(a plain cost matrix): use another method, e.g. auto")
    if "asymmetric" not in capabilities and not instance.symmetric:
        raise ParameterError(f"method {run.name!r} assumes a symmetric cost matrix, and this one is not: use one of "
                             f"{', '.join(_asymmetric())} (or auto)")
    label = run.name if chosen is run else f"{chosen.name} ({run.name})"
    return label, chosen, run


MATRIX_BYTES_PER_ENTRY = {"lkh": 80}
"""Peak bytes per entry of the n × n matrix a method needs on a coordinate instance (default
:data:`MATRIX_BYTES_DEFAULT`): the float matrix and the method's own copies (the open-path reduction, the
symmetrised and integer ones, elkai's lists and text). Measured on 2026-12-07 as peak RSS above the
process's start at 1500-3000 cities: fast-tsp 44, local 50, lkh 74 (benchmarks/README.md, "Implicit TSPLIB
coordinates at 16 384 cities")."""

MATRIX_BYTES_DEFAULT = 48
"""Peak bytes per matrix entry of the matrix methods not in :data:`MATRIX_BYTES_PER_ENTRY`."""


def _check_matrix_memory(method: str, instance: SequencingInstance) -> None:
    """Refuse, before any work, to build the matrix of a coordinate instance for ``method`` past the memory
    budget (:func:`~htetro_opt.model.simulate.memory_budget`)."""
    from htetro_opt.model.simulate import check_memory

    per_entry = MATRIX_BYTES_PER_ENTRY.get(method, MATRIX_BYTES_DEFAULT)
    check_memory(per_entry * instance.n ** 2,
                 f"method {method!r} needs the n × n cost matrix, and on this TSPLIB {instance.metric} instance of "
                 f"{instance.n:,} nodes (costs implicit) the matrix and the method's copies of it",
                 "use method ils or auto, which keep the costs implicit at any size, or raise the budget "
                 "(htetro_opt.model.simulate.budget_of)")


def sequence_waypoints(instance: SequencingInstance, *, method="auto", **options) -> SequenceResult:
    """Order the waypoints of an instance with one method.

    Parameters
    ----------
    instance : SequencingInstance
        Costs, block cells and start.
    method : str or callable, keyword-only
        A method of the task's spec (:data:`~htetro_opt.solvers.sequencing.SPEC`, which lists every
        method with its options, defaults and capabilities). ``auto`` is the exact solver up to
        :data:`~htetro_opt.solvers.sequencing.EXACT_AUTO_LIMIT` waypoints and, beyond, the compiled
        iterated local search ``ils`` (ortools for asymmetric costs): :func:`auto_method`; it hands its
        ``seed``, ``time_limit`` and ``progress`` to the method it runs, as far as that one takes them. A
        callable ``method(instance, *, seed, time_limit, **options)`` returning ``(order, info)`` is run
        the same way (given the open-path reduction of a closed tour or a fixed end, and ``progress`` if
        it takes that keyword).
    **options
        The method's options, each checked and defaulted by the spec before any work, among them:

        - ``seed`` (the stochastic methods: auto, ils, local, ga, ga-plain, greedy): None draws fresh
          entropy, an int or a Generator reproduces a run; default 0;
        - ``time_limit`` (the methods that take one; not lkh, nor the instant patterns): seconds, a
          positive finite number; None: the method's default, sized to the instance
          (:func:`~htetro_opt.solvers.sequencing.default_time_limit`);
        - ``progress``: ``progress(done, total, note)`` from the methods that report (ga, ga-plain,
          greedy, local, ortools), see :mod:`htetro_opt._progress`;
        - the methods' own (``pop_size`` for ``ga``, ``iterations`` for ``greedy``, ``runs`` for ``lkh``, …).

    Returns
    -------
    SequenceResult

    Raises
    ------
    ParameterError
        On an unknown method or option (naming the method's options), a bad option value (an infinite
        ``time_limit`` among them), an ``instance`` that is not a :class:`SequencingInstance`, an
        asymmetric matrix for a method that assumes symmetric costs (see :data:`ASYMMETRIC_METHODS`), a
        plain matrix for a pattern baseline, or a method whose optional package is missing.

    Examples
    --------
    >>> from htetro_opt.scenarios import parse_tileset
    >>> inst = SequencingInstance.from_tileset(parse_tileset("1a 1b 1c 1d\\n2a 2b 2c 2d\\n3a 3b 3c 3d"), start=3)
    >>> result = sequence_waypoints(inst, method="exact")
    >>> result.tiles, result.cost
    ([3, 2, 1], 2.0)
    """
    check_instance(instance)
    if callable(method):
        label = getattr(method, "__name__", type(method).__name__)
        call = dict(options)
        call["seed"] = check_seed(call.get("seed", DEFAULT_SEED))
        call["time_limit"] = check_time_limit(call.get("time_limit"))
        progress = check_progress(call.pop("progress", None))
        if progress is not None and _takes(method, "progress"):
            call["progress"] = progress
        function, capabilities = method, {"asymmetric", "geometry"}
    else:
        label, chosen, run = _resolve(method, instance)
        call = SPEC.check(chosen, options, stage="method")
        if run is not chosen:  # auto: its options, to the method it runs as far as that one takes them
            call = SPEC.check(run, {k: v for k, v in call.items() if run.takes(k)}, stage="method")
        function, capabilities, call = run.load(SPEC.package), run.capabilities, {**run.presets, **call}
    reduction = None
    solved = instance
    if not callable(method) and instance.implicit and instance.coords is not None and "implicit" not in capabilities:
        solved = instance.with_matrix()  # within the budget: _resolve checked it
    if (instance.closed or instance.end is not None) and "tours" not in capabilities:
        reduction = reduce_to_open_path(solved)
        solved = reduction.instance
    if reduction is not None and solved.n > call.get("max_size", solved.n):  # the user's count, and why it grew
        raise ParameterError(f"the exact method proves optima of at most {call['max_size']} waypoints, this instance "
                             f"has {instance.n} ({solved.n} as the open path a closed tour or a fixed end is solved "
                             "as): use the ils, ortools or local method for large instances")
    began = time.perf_counter()
    order, info = function(solved, **call)
    runtime = time.perf_counter() - began
    info = dict(info)
    if reduction is not None:
        order = reduction.decode(solved.check_order(order))
        if "bound" in info:  # a bound on the reduction's optimum, which exceeds the instance's by the offset
            info["bound"] = float(info["bound"] - reduction.offset)
    order = instance.check_order(order)
    return SequenceResult(label, order, instance.tile_order(order), instance.path_cost(order), runtime, info,
                          _time_limited(info, capabilities))


def _time_limited(info: dict, capabilities) -> bool:
    """Whether the clock, not the method's own end, stopped it: a search that only ends on its time budget
    (``"timed"``: OR-Tools' guided local search, fast-tsp, unless it says its solution limit ended it),
    generations, kicks or iterations cut short, or an optimality proof not reached in time."""
    if "timed" in capabilities:
        return bool(info.get("time_limited", True))
    return bool(info.get("time_limited") or info.get("timed_out") or info.get("stopped") == "time_limit"
                or info.get("optimal") is False)
