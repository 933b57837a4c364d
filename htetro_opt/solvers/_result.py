"""What every task's result has, whatever the task (scipy's ``OptimizeResult`` spirit).

:class:`Result` is the base of :class:`~htetro_opt.solvers.grid_paths.Plan`,
:class:`~htetro_opt.solvers.continuous.ContinuousPlan`, :class:`~htetro_opt.solvers.tiling.TilingResult`,
:class:`~htetro_opt.solvers.sequencing.SequenceResult` and
:class:`~htetro_opt.solvers.coverage.CoveragePlan`: each has ``method`` (the method that made it),
``success`` (it did what was asked: reached the goal, covered every coverable cell), ``message`` (in
words, what was missed when it did not), ``runtime_s``, ``time_limited`` (a time limit stopped it, so
it depends on the machine's speed), ``additions`` (the additions of ours to the paper's algorithm it ran
with: none for a method as published) and ``info`` (the method's extras), and
:meth:`Result.as_dict`, the JSON-ready dict that the command line's ``--json`` prints and a study
record holds, the run's own keys beside it.
"""

from __future__ import annotations

import math
import numbers
from abc import ABC, abstractmethod
from collections.abc import Mapping

import numpy as np

__all__ = ["Result", "jsonable"]


class Result(ABC):
    """The base of every task's result (see the module docstring).

    A subclass is a frozen dataclass with the fields ``method``, ``runtime_s`` and ``info``; it says
    what ``success`` and ``message`` are for its task and what its own fields are in JSON
    (:meth:`_fields`).
    """

    __slots__ = ()

    @property
    @abstractmethod
    def success(self) -> bool:
        """The method did what was asked of it."""

    @property
    @abstractmethod
    def message(self) -> str:
        """What the result is, in words; what was missed when not :attr:`success`."""

    @property
    def time_limited(self) -> bool:
        """A time limit, not the method's own end (generations, kicks, a proof), stopped it: the result then
        depends on the machine's speed, not only on the seed."""
        return bool(self.info.get("time_limited", False))

    @property
    def additions(self) -> tuple[str, ...]:
        """The additions of ours to the paper's algorithm the method ran with (none for a method as published,
        and for a method that is not a paper's)."""
        return tuple(self.info.get("additions", ()))

    @abstractmethod
    def _fields(self) -> dict:
        """The task's own fields, JSON-ready, in the order ``as_dict`` lists them."""

    def as_dict(self) -> dict:
        """JSON-ready: ``method``, ``success``, ``message``, ``runtime_s``, ``time_limited``, ``additions``,
        ``info`` (every non-finite number None: strict JSON has no infinity), then the task's own fields."""
        info = {k: v for k, v in self.info.items() if k != "additions"}
        out = {"method": self.method, "success": bool(self.success), "message": self.message,
               "runtime_s": round(float(self.runtime_s), 6), "time_limited": bool(self.time_limited),
               "additions": list(self.additions), "info": jsonable(info)}
        out.update(self._fields())
        return out


def jsonable(value):
    """``value`` as JSON-ready data: numpy scalars and arrays as Python's, tuples as lists, mappings
    with string keys, non-finite floats as None; anything else that is not JSON (a field of arrays kept
    for a plot, a callable) is left out of mappings.

    Examples
    --------
    >>> jsonable({"a": np.float64(1.5), "b": (1, float("inf")), "c": np.arange(2)})
    {'a': 1.5, 'b': [1, None], 'c': [0, 1]}
    """
    if value is None or isinstance(value, (bool, str)):
        return value
    if isinstance(value, np.bool_):
        return bool(value)
    if isinstance(value, numbers.Integral):
        return int(value)
    if isinstance(value, numbers.Real):
        value = float(value)
        return value if math.isfinite(value) else None
    if isinstance(value, np.ndarray):
        return jsonable(value.tolist())
    if isinstance(value, Mapping):
        out = {}
        for k, v in value.items():
            converted = jsonable(v)
            if converted is not _SKIP:
                out[str(k)] = converted
        return out
    if isinstance(value, (list, tuple)):
        return [v for v in (jsonable(v) for v in value) if v is not _SKIP]
    return _SKIP


_SKIP = object()  # a value JSON cannot hold, left out
