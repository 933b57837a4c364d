"""The one result type of grid path planning, and the one place a plan is re-validated.

Every method of :func:`~htetro_opt.solvers.grid_paths.plan_path` returns a :class:`Plan`, built by
:func:`finish_plan`, which replays the commands in the simulator from the roadmap's start: a method
cannot report a time, a pose or a validity its commands do not have.
"""

from __future__ import annotations

import math
import reprlib
import time
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from htetro_opt.algorithms.names import PICKS
from htetro_opt.errors import ParameterError, PlanningError
from htetro_opt.model.commands import COMMANDS
from htetro_opt.model.robot import Pose, as_pose
from htetro_opt.model.simulate import Simulator
from htetro_opt.model.workspace import Workspace, check_workspace
from htetro_opt.problems.names import FITNESS_NAMES
from htetro_opt.solvers._result import Result

__all__ = ["Plan", "FrontMember", "LegResult", "finish_plan", "prepare", "check_roadmap", "check_map"]


@dataclass(frozen=True, eq=False)  # holds arrays: identity equality, hashable
class FrontMember:
    """One GA individual: its executed commands (global ids), fitnesses, time and the poses it visits
    ((x, y, state, heading) rows, its leg's start first)."""

    commands: np.ndarray
    fitness: np.ndarray  # (f_gr, f_t, f_sm, f_sf)
    time: float
    reached: bool
    poses: np.ndarray

    @property
    def tokens(self) -> list[str]:
        return [COMMANDS[int(c)].token for c in self.commands]

    def as_dict(self) -> dict:
        return {
            "fitness": {name: float(v) for name, v in zip(FITNESS_NAMES, self.fitness)},
            "time": float(self.time),
            "reached": bool(self.reached),
            "commands": self.tokens,
        }


@dataclass(frozen=True, eq=False)
class LegResult:
    """One leg of a GA's configuration loop: its final leading front, selections and convergence.

    ``reach_generation`` is the first generation (1 = the initial population) holding an individual
    that reaches the leg's goal, None if none ever did; ``history`` holds, per generation, the four
    fitnesses of that generation's multi-objective solution (the paper's Fig. 10).
    """

    start: Pose
    goal: Pose
    t0: int
    reached: bool
    front: tuple[FrontMember, ...]
    selected: Mapping[str, FrontMember]
    reach_generation: int | None
    reach_time_s: float | None
    generations: int
    converged: bool
    runtime_s: float
    history: np.ndarray
    hv_history: np.ndarray | None = None  # per generation, when asked for (plan_ga's hv_reference)


@dataclass(frozen=True, eq=False)  # holds arrays: identity equality, hashable
class Plan(Result):
    """A plan through a roadmap, whatever the method: global command ids from the start, and what
    they achieve (re-validated in the simulator). ``success`` is ``reached``.

    Attributes
    ----------
    method : str
        The method that made it (``"dijkstra"``, ``"astar"``, ``"htetro-ga"``, …; a hand-over from
        Dijkstra to A* shows as ``"dijkstra (astar)"``).
    commands : ndarray of int64
        Global command ids, from the roadmap's start.
    reached : bool
        False when some leg was not solved; ``commands`` then holds the legs before it.
    time : float
        Duration of the commands.
    poses : ndarray, shape (len(commands) + 1, 4)
        (x, y, state, heading) after each command, the start first.
    leg_ends : tuple of int
        Number of commands at the end of each solved leg.
    failed_leg : int
        Index of the leg that was not solved, −1 when reached.
    runtime_s : float
    legs : tuple of LegResult
        The GAs' per-leg records (fronts, selections, convergence); empty for the graph searches.
    info : dict
        Other method-specific extras (JSON-ready); for a callable method whose answer did not solve
        every leg, ``returned`` (the answer's length) and ``first_invalid`` (its first invalid
        command, −1 if none).
    """

    method: str
    commands: np.ndarray
    reached: bool
    time: float
    poses: np.ndarray
    leg_ends: tuple[int, ...]
    failed_leg: int = -1
    runtime_s: float = 0.0
    legs: tuple[LegResult, ...] = ()
    info: Mapping = field(default_factory=dict)

    @property
    def tokens(self) -> list[str]:
        return [COMMANDS[int(c)].token for c in self.commands]

    @property
    def success(self) -> bool:
        return bool(self.reached)

    @property
    def message(self) -> str:
        if self.reached:
            return f"reached the goal: {len(self.commands)} commands, {self.time:g} s"
        why = "the GA's final population holds no member reaching it" if self.legs else "it has no path"
        return f"goal not reached: leg {self.failed_leg + 1} was not solved ({why}); the plan holds the legs before it"

    def _fields(self) -> dict:
        out = {"reached": bool(self.reached), "commands": self.tokens, "time": float(self.time),
               "objectives": self.objectives(), "leg_ends": list(self.leg_ends), "failed_leg": self.failed_leg}
        if self.legs:
            out.update(self._ga_fields())
        return out

    def _ga_fields(self) -> dict:
        """The GAs' fields: every leg's record, the last leg's front, the picked solution's fitnesses
        (averaged over the legs) and, when each leg's exact optimum is known (``seed_exact``), the gaps of
        the plan and of the legs' fastest members to it."""
        pick = self.info.get("pick", "balanced")
        legs = [{"start": leg.start.as_dict(), "goal": leg.goal.as_dict(), "reached": leg.reached,
                 "reach_generation": leg.reach_generation, "generations": leg.generations,
                 "converged": leg.converged, "runtime_s": round(leg.runtime_s, 6),
                 "selected": {name: member.as_dict() for name, member in leg.selected.items()},
                 "front": [member.as_dict() for member in leg.front]} for leg in self.legs]
        fitness = np.mean([leg.selected[PICKS[pick]].fitness for leg in self.legs], axis=0)
        out = {"pick": pick, "reach_generation": self.reach_generation,
               "generations": sum(leg.generations for leg in self.legs),
               "fitness": {name: float(v) for name, v in zip(FITNESS_NAMES, fitness)},
               "front": legs[-1]["front"], "legs": legs}
        exact = self.info.get("exact_times")
        if exact is not None and self.reached and None not in exact and sum(exact) > 0:
            # each leg's optimum from where and when the returned plan starts it
            fastest = sum(leg.selected["time"].time for leg in self.legs)
            out["gap"] = {"exact": float(sum(exact)), "picked": (self.time - sum(exact)) / sum(exact),
                          "fastest": (fastest - sum(exact)) / sum(exact)}
        return out

    @property
    def reach_generation(self) -> int | None:
        """GAs: the largest first-reach generation over the legs (None if some leg never reached, and
        for the graph searches)."""
        gens = [leg.reach_generation for leg in self.legs]
        return None if not gens or None in gens else max(gens)

    def objectives(self) -> dict:
        """Path metrics: time, number of commands by kind, B2's travelled distance.

        Cheng et al. 2019's ``2l/2r`` count as rotations, its other block commands as shapeshifts.
        """
        commands = [COMMANDS[int(c)] for c in self.commands]
        moves = [c for c in commands if c.kind in ("translation", "diagonal")]
        turns = [c for c in commands if c.turn != 0]
        return {
            "time": float(self.time),
            "n_commands": len(commands),
            "translations": len(moves),
            "rotations": len(turns),
            "shapeshifts": sum(c.kind == "shapeshift" or any(c.hinge_delta) for c in commands),
            "path_length": float(sum(math.hypot(*c.shift) for c in moves)),
        }


def finish_plan(sim: Simulator, commands: np.ndarray, start: int, *, t0: int = 0, method: str,
                leg_ends, failed_leg: int, began: float, legs=(), info=None) -> Plan:
    """Replay ``commands`` from pose id ``start`` (at time ``t0``) and wrap them as a :class:`Plan`.

    Raises
    ------
    PlanningError
        If the commands do not re-validate: a method's bug, never the user's input.
    """
    commands = np.asarray(commands, dtype=np.int64)
    result = sim.run([commands], start, t0=t0)
    if not result.valid[0]:
        raise PlanningError(f"internal error: the {method} plan does not re-validate in the simulator "
                            f"(command {int(result.first_invalid[0]) + 1} of {len(commands)} is invalid)")
    return Plan(
        method=method,
        commands=commands,
        reached=failed_leg < 0,
        time=float(result.time[0]),
        poses=result.poses(0),
        leg_ends=tuple(int(e) for e in leg_ends),
        failed_leg=int(failed_leg),
        runtime_s=time.perf_counter() - began,
        legs=tuple(legs),
        info=dict(info or {}),
    )


def check_roadmap(roadmap) -> list[Pose]:
    """A roadmap as a list of at least two poses (start first, goal last), checked before any work.

    Raises
    ------
    ParameterError
        If ``roadmap`` is not a sequence.
    PlanningError
        If it has fewer than two configurations.
    ConfigurationError, UnknownShapeError
        If an entry is not a pose, naming it (``roadmap[i]``).
    """
    if isinstance(roadmap, (str, bytes, Pose)) or not isinstance(roadmap, Iterable):
        raise ParameterError(f"roadmap must be a sequence of poses (start first, goal last), "
                             f"got {type(roadmap).__name__} {reprlib.repr(roadmap)}")
    roadmap = [as_pose(p, f"roadmap[{i}]") for i, p in enumerate(roadmap)]
    if len(roadmap) < 2:
        raise PlanningError("a roadmap needs a start and a goal (at least two configurations)")
    return roadmap


def check_map(workspace) -> Workspace | Simulator:
    """``workspace`` itself if it is a Workspace or a compiled Simulator.

    Raises
    ------
    ParameterError
        Naming what it got.
    """
    return workspace if isinstance(workspace, Simulator) else check_workspace(workspace, what="a Workspace or a Simulator")


def prepare(workspace: Workspace | Simulator, roadmap: Sequence[Pose], *, t0: int = 0,
            **compile_options) -> tuple[Simulator, list[Pose], list[int]]:
    """The simulator (compiled unless given), the roadmap as poses and their pose ids, all checked
    before any planning starts (the workspace and roadmap before the simulator is compiled).

    Raises
    ------
    ParameterError
        If ``workspace`` is neither a Workspace nor a Simulator, or ``roadmap`` is not a sequence.
    PlanningError
        If the roadmap has fewer than two configurations, or the simulator's tables would not fit
        the memory budget.
    ConfigurationError
        If the start collides (at time ``t0``) or a configuration lies outside the map.
    """
    check_map(workspace)
    roadmap = check_roadmap(roadmap)
    sim = workspace if isinstance(workspace, Simulator) else Simulator(workspace, **compile_options)
    ids = [sim.check_pose(roadmap[0], what="start", t=t0)]
    for i, pose in enumerate(roadmap[1:], start=1):
        ids.append(sim.check_pose(pose, what="goal" if i == len(roadmap) - 1 else f"roadmap configuration {i + 1}"))
    return sim, roadmap, ids
