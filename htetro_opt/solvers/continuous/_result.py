"""The one result type of continuous path planning, and the one place a plan is re-validated.

Every method of :func:`~htetro_opt.solvers.continuous.plan_continuous` returns a
:class:`ContinuousPlan`, built by :func:`finish_plan`, which checks each path against the scenario's
geometry and measures it: a method cannot report a length or a feasibility its paths do not have.
"""

from __future__ import annotations

import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from htetro_opt.errors import PlanningError
from htetro_opt.model.continuous import SAFETY_MARGIN, path_length, path_smoothness, robot_distance
from htetro_opt.scenarios.loader import ContinuousScenario
from htetro_opt.scenarios.loader import check_continuous_scenario as check_scenario
from htetro_opt.solvers._result import Result

__all__ = ["ContinuousPlan", "finish_plan", "check_scenario", "SAFETY_MARGIN"]


@dataclass(frozen=True, eq=False)  # holds arrays: identity equality, hashable
class ContinuousPlan(Result):
    """Paths through a continuous scenario, whatever the method, measured and re-validated.

    ``success``: every robot reached its goal on an obstacle-free path (robots planned alone may still
    meet: ``conflicts``).

    Attributes
    ----------
    method : str
    scenario : str
        The scenario's name.
    paths : tuple of ndarray
        One (n_i, 2) polyline per robot, its start first and its goal last (a single point when the
        start is the goal); an empty (0, 2) array for a robot whose goal was not reached.
    robots_reached : tuple of bool
    feasible : tuple of bool
        Per robot: the path is obstacle-free (an unreached robot's empty path counts as feasible).
    lengths, smoothness_deg, safety, min_clearance : ndarray, shape (n_robots,)
        Per robot: length; the sum of turning angles in degrees (eq. 4); eq. 5's R, the sum of the
        interior vertices' clearances; the smallest clearance along the whole path (NaN when not
        reached).
    min_robot_distance : float or None
        Smallest distance between two robots that leave together at unit speed and wait at their
        goals (None with fewer than two reached robots).
    conflicts : tuple of (int, int)
        Pairs of robots closer than ``safety_distance`` at some time.
    safety_distance : float
        2 r + :data:`SAFETY_MARGIN`.
    runtime_s : float
    history : ndarray
        Per generation, a method's best cost (empty for the graph searches).
    info : dict
        Method-specific extras, JSON-ready (``"exact"``: ``lower_bound`` and ``upper_bound`` per
        robot; ``"astar"``: ``grid``, ``nodes``, ``edges``).
    """

    method: str
    scenario: str
    paths: tuple[np.ndarray, ...]
    robots_reached: tuple[bool, ...]
    feasible: tuple[bool, ...]
    lengths: np.ndarray
    smoothness_deg: np.ndarray
    safety: np.ndarray
    min_clearance: np.ndarray
    min_robot_distance: float | None
    conflicts: tuple[tuple[int, int], ...]
    safety_distance: float
    runtime_s: float = 0.0
    history: np.ndarray = field(default_factory=lambda: np.zeros(0))
    info: Mapping = field(default_factory=dict)

    @property
    def reached(self) -> bool:
        """Every robot reached its goal."""
        return all(self.robots_reached)

    @property
    def length(self) -> float:
        """Total length over the robots that reached their goals."""
        return float(np.nansum(np.where(self.robots_reached, self.lengths, np.nan))) if self.paths else 0.0

    def objectives(self) -> dict:
        """Totals over the robots: ``length``, ``smoothness_deg``, ``safety`` (eq. 5's R) and
        ``min_clearance`` (the smallest over the robots; None when none reached)."""
        reached = np.array(self.robots_reached)
        clear = self.min_clearance[reached]
        return {
            "length": float(self.lengths[reached].sum()),
            "smoothness_deg": float(self.smoothness_deg[reached].sum()),
            "safety": float(self.safety[reached].sum()),
            "min_clearance": float(clear.min()) if len(clear) else None,
        }

    @property
    def success(self) -> bool:
        return self.reached and all(self.feasible)

    @property
    def message(self) -> str:
        missed = [k for k, ok in enumerate(self.robots_reached) if not ok]
        if missed:
            return f"robot{'s' if len(missed) > 1 else ''} {', '.join(map(str, missed))} did not reach the goal"
        clash = f"; {len(self.conflicts)} pair(s) of robots closer than {self.safety_distance:g}" if self.conflicts else ""
        return f"every robot reached its goal, total length {self.length:.3f}{clash}"

    def _fields(self) -> dict:
        """``scenario, reached, paths, objectives, min_robot_distance, conflicts``."""
        return {
            "scenario": self.scenario,
            "reached": self.reached,
            "paths": [p.tolist() for p in self.paths],
            "objectives": self.objectives(),
            "min_robot_distance": self.min_robot_distance,
            "conflicts": [list(c) for c in self.conflicts],
        }




def finish_plan(scenario: ContinuousScenario, paths: Sequence, *, method: str, began: float,
                history=None, info=None, require_feasible: bool = True) -> ContinuousPlan:
    """Measure and re-validate one path per robot (None for a robot not planned to its goal).

    Raises
    ------
    PlanningError
        If a path does not run from its robot's start to its goal, or (with ``require_feasible``,
        as for the graph searches) is not feasible: a method's bug, never the user's input.
    """
    geometry = scenario.geometry
    if len(paths) != scenario.n_robots:
        raise PlanningError(f"internal error: the {method} plan has {len(paths)} paths for {scenario.n_robots} robots")
    kept, reached = [], []
    for i, path in enumerate(paths):
        if path is None:
            kept.append(np.empty((0, 2)))
            reached.append(False)
            continue
        path = np.array(path, dtype=float).reshape(-1, 2)
        if not len(path) or not (np.array_equal(path[0], scenario.starts[i])
                                 and np.array_equal(path[-1], scenario.goals[i])):
            raise PlanningError(f"internal error: the {method} path of robot {i} does not run from its start "
                                f"{scenario.starts[i].tolist()} to its goal {scenario.goals[i].tolist()}")
        kept.append(path)
        reached.append(True)
    n = len(kept)
    feasible = np.ones(n, dtype=bool)
    live = [i for i in range(n) if reached[i]]
    if live:
        feasible[live] = geometry.paths_feasible([kept[i] for i in live])
    if require_feasible and not feasible.all():
        raise PlanningError(f"internal error: the {method} path of robot {int(np.argmin(feasible))} does not "
                            "re-validate against the obstacles")
    nan = np.full(n, np.nan)
    lengths, smooth, safety, clearance = nan.copy(), nan.copy(), nan.copy(), nan.copy()
    for i in live:
        lengths[i] = path_length(kept[i])
        smooth[i] = path_smoothness(kept[i])
        safety[i] = float(geometry.clearance(kept[i][1:-1]).sum()) if len(kept[i]) > 2 else 0.0
        clearance[i] = geometry.path_clearance(kept[i])
    d_s = 2 * scenario.robot_radius + SAFETY_MARGIN
    closest, conflicts = None, []
    for a in range(len(live)):
        for b in range(a + 1, len(live)):
            d = robot_distance(kept[live[a]], kept[live[b]])
            closest = d if closest is None else min(closest, d)
            if d < d_s:
                conflicts.append((live[a], live[b]))
    return ContinuousPlan(
        method=method,
        scenario=scenario.name,
        paths=tuple(kept),
        robots_reached=tuple(reached),
        feasible=tuple(bool(f) for f in feasible),
        lengths=lengths,
        smoothness_deg=smooth,
        safety=safety,
        min_clearance=clearance,
        min_robot_distance=closest,
        conflicts=tuple(conflicts),
        safety_distance=d_s,
        runtime_s=time.perf_counter() - began,
        history=np.zeros(0) if history is None else np.asarray(history, dtype=float),
        info=dict(info or {}),
    )
