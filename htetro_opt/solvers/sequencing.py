"""One entry point for every waypoint-sequencing solver of seed 003, and the result they share.

Every solver is a function ``solve_<name>(instance, *, seed=0, time_limit=None, **options)`` that
returns ``(order, info)``: the waypoint indices in visiting order and a dict of JSON-ready extras
(``{"optimal": True}``, generation counts, …). :func:`sequence_waypoints` runs one, re-checks that the
order visits every waypoint once from the start, and prices it with the instance's own cost matrix,
so a solver cannot report a cost its order does not have.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from importlib import import_module

import numpy as np

from htetro_opt.errors import ParameterError
from htetro_opt.problems.waypoint_sequencing import SequencingInstance

__all__ = ["SEQUENCE_SOLVERS", "EXACT_AUTO_LIMIT", "SequenceResult", "sequence_waypoints"]

_SOLVERS = {
    "exact": ("htetro_opt.solvers.tsp_exact", "solve_exact", {}),
    "ortools": ("htetro_opt.solvers.tsp_ortools", "solve_ortools", {}),
    "local": ("htetro_opt.solvers.tsp_local", "solve_local", {}),
    # the memetic GA finds its best within a few generations; 50 more without improvement suffice
    "ga": ("htetro_opt.solvers.tsp_ga", "solve_ga", {"memetic": True, "patience": 50}),
    "ga-plain": ("htetro_opt.solvers.tsp_ga", "solve_ga", {"memetic": False}),
    "zigzag": ("htetro_opt.solvers.tsp_baselines", "solve_zigzag", {"rows": 1}),
    "zigzag2": ("htetro_opt.solvers.tsp_baselines", "solve_zigzag", {"rows": 2}),
    "spiral": ("htetro_opt.solvers.tsp_baselines", "solve_spiral", {"rows": 1}),
    "spiral2": ("htetro_opt.solvers.tsp_baselines", "solve_spiral", {"rows": 2}),
    "greedy": ("htetro_opt.solvers.tsp_baselines", "solve_greedy", {}),
}

SEQUENCE_SOLVERS: tuple[str, ...] = ("auto",) + tuple(_SOLVERS)
"""Solver names: ``auto`` (the default), then every solver."""

EXACT_AUTO_LIMIT = 40
"""``auto`` proves the optimum with the exact solver up to this many waypoints, and runs the local
search beyond (the winner on the 1000-waypoint benchmark, benchmarks/README.md)."""


@dataclass(frozen=True, eq=False)
class SequenceResult:
    """A solver's order, re-priced on the instance.

    ``order`` holds waypoint indices; ``tiles`` the same order as tile labels.
    """

    solver: str
    order: np.ndarray
    tiles: list[int]
    cost: float
    runtime_s: float
    info: dict = field(default_factory=dict)

    def as_dict(self) -> dict:
        return {"solver": self.solver, "order": self.tiles, "cost": self.cost,
                "runtime_s": round(self.runtime_s, 6), **self.info}


def _resolve(name: str, n: int) -> tuple[str, object, dict]:
    if name == "auto":
        name = "exact" if n <= EXACT_AUTO_LIMIT else "local"
    if name not in _SOLVERS:
        raise ParameterError(f"unknown sequencing solver {name!r}: expected one of {', '.join(SEQUENCE_SOLVERS)}")
    module, function, preset = _SOLVERS[name]
    return name, getattr(import_module(module), function), preset


def sequence_waypoints(instance: SequencingInstance, solver: str = "auto", *, seed: int = 0,
                       time_limit: float | None = None, **options) -> SequenceResult:
    """Order the waypoints of an instance with one solver.

    Parameters
    ----------
    instance : SequencingInstance
        Costs, block cells and start.
    solver : str
        One of :data:`SEQUENCE_SOLVERS`. ``auto`` is the exact solver up to
        :data:`EXACT_AUTO_LIMIT` waypoints and the local search beyond.
    seed : int
        Seed of the stochastic solvers (the deterministic ones ignore it).
    time_limit : float, optional
        Wall-clock budget in seconds for the solvers that take one (exact, ortools, ga, local).
    **options
        Passed to the solver function (e.g. ``pop_size`` for ``ga``, ``iterations`` for ``greedy``).

    Returns
    -------
    SequenceResult

    Raises
    ------
    ParameterError
        On an unknown solver or option value.

    Examples
    --------
    >>> from htetro_opt.scenarios import parse_tileset
    >>> inst = SequencingInstance.from_tileset(parse_tileset("1a 1b 1c 1d\\n2a 2b 2c 2d\\n3a 3b 3c 3d"), start=3)
    >>> result = sequence_waypoints(inst, "exact")
    >>> result.tiles, result.cost
    ([3, 2, 1], 2.0)
    """
    if time_limit is not None and not time_limit > 0:
        raise ParameterError(f"time limit must be positive, got {time_limit!r}")
    name, function, preset = _resolve(solver, instance.n)
    began = time.perf_counter()
    order, info = function(instance, seed=seed, time_limit=time_limit, **{**preset, **options})
    runtime = time.perf_counter() - began
    order = instance.check_order(order)
    label = solver if solver == name else f"{solver} ({name})"
    return SequenceResult(label, order, instance.tile_order(order), instance.path_cost(order), runtime, dict(info))
