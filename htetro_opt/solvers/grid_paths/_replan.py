"""Do et al. 2021's reactive navigation in a partially known map (§VI-A-7): plan, move, sense, replan.

The robot plans with :func:`~htetro_opt.solvers.grid_paths.plan_heat` on what it knows, executes the
plan one command at a time in the true world, senses after every command (the paper's "sampling
interval of one motion command") and, when the rest of its plan has become invalid in what it now
knows, plans again from where it stands: a new temperature field whose sink is its current B2 cell.
Moving obstacles are out of scope (the paper's §VII leaves them to future work).
"""

from __future__ import annotations

import reprlib
import time as _time
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from htetro_opt._validation import check_real
from htetro_opt.errors import ParameterError, PlanningError
from htetro_opt.model.commands import COMMANDS, command_set
from htetro_opt.model.robot import FOOTPRINTS, STATE_NAMES, Pose
from htetro_opt.model.simulate import Simulator
from htetro_opt.model.workspace import Workspace
from htetro_opt.problems.heat_costs import heat_fitness
from htetro_opt.scenarios.loader import ContinuousScenario, Scenario
from htetro_opt.solvers.grid_paths._heat import plan_heat
from htetro_opt.solvers.grid_paths._result import Plan, check_roadmap

__all__ = ["HeatRun", "replan_heat"]

_COMPILE_OPTIONS = ("commands", "timing", "clearance")


@dataclass(frozen=True, eq=False)  # holds arrays: identity equality, hashable
class HeatRun:
    """What the robot did in the true world while replanning (:func:`replan_heat`).

    Attributes
    ----------
    executed : ndarray of int64
        Global command ids executed, from the roadmap's start.
    poses : ndarray, shape (len(executed) + 1, 4)
        (x, y, state, heading) after each command, the start first.
    time : float
        Duration of the executed commands.
    reached : bool
        The executed commands pass through the roadmap's configurations in order and end on the goal.
    replans : tuple of dict
        One record per plan made after the initial one: ``step`` (commands executed before it),
        ``pose`` (the :class:`~htetro_opt.model.Pose` it starts from) and ``revealed`` (the obstacle
        cells, (x, y), that became known since the previous plan was made).
    fitness : dict
        :func:`~htetro_opt.problems.heat_costs.heat_fitness` of the executed commands on the true map,
        with the plans' ``t_max`` and ``weights``: ``f_t``, ``f_sm``, ``f_sf``, ``f``.
    plans : int
        Number of :func:`~htetro_opt.solvers.grid_paths.plan_heat` calls (1 + ``len(replans)``).
    runtime_s : float
    fields : tuple of HeatField
        The last plan's fields, when ``keep_fields=True`` was passed (for plots; not in ``as_dict``).
    info : dict
        ``sensor_range``, ``reach`` (the command reach: the farthest, in cells, that a command of the
        set sweeps from the block centres of the pose it starts from), ``t_max``, ``weights`` and ``revealed``
        (the number of obstacle cells sensed that the scenario's map lacked).
    """

    executed: np.ndarray
    poses: np.ndarray
    time: float
    reached: bool
    replans: tuple[dict, ...]
    fitness: Mapping[str, float]
    plans: int
    runtime_s: float = 0.0
    info: Mapping = field(default_factory=dict)
    fields: tuple = ()

    @property
    def tokens(self) -> list[str]:
        return [COMMANDS[int(c)].token for c in self.executed]

    def as_dict(self) -> dict:
        """The run as JSON-ready values (command tokens, poses as dicts, cells as [x, y] pairs)."""
        return {
            "commands": self.tokens,
            "time": float(self.time),
            "reached": bool(self.reached),
            "replans": [{"step": r["step"], "pose": r["pose"].as_dict(), "revealed": [list(c) for c in r["revealed"]]}
                        for r in self.replans],
            "fitness": {k: float(v) for k, v in self.fitness.items()},
            "plans": int(self.plans),
            "runtime_s": round(self.runtime_s, 6),
            **self.info,
        }

    def as_plan(self) -> Plan:
        """The run as a :class:`~htetro_opt.solvers.grid_paths.Plan` of its executed commands (method
        ``"heat (replanning)"``, or ``"heat-paper (replanning)"``), its ``info`` holding the additions, the run's fitness, weights, t_max, sensor range,
        plans and replans (and the last plan's fields, when kept)."""
        info = {"additions": list(self.info.get("additions", ())), "fitness": dict(self.fitness),
                "weights": self.info["weights"], "t_max": self.info["t_max"],
                "sensor_range": self.info["sensor_range"], "plans": int(self.plans),
                "replans": self.as_dict()["replans"], "fields": self.fields}
        return Plan(method=f"{self.info.get('method', 'heat')} (replanning)", commands=self.executed, reached=self.reached, time=self.time,
                    poses=self.poses, leg_ends=(len(self.executed),) if self.reached else (),
                    failed_leg=-1 if self.reached else 0, runtime_s=self.runtime_s, info=info)


def _command_reach(simulator: Simulator) -> float:
    """The farthest, in cells, that a command of ``simulator`` sweeps from the robot's block centres.

    The largest, over every named state, heading and command of the simulator's set (with its
    clearance), of the distance from a swept cell's centre to the nearest block centre of the pose the
    command starts from. A sensor that sees at least this far around every block sees every cell the
    next command can touch.

    Examples
    --------
    >>> sim = Simulator(Workspace(np.zeros((4, 4), dtype=bool)), diagonals=True)
    >>> round(_command_reach(sim), 4)  # the O → J shapeshift's far corner: √10
    3.1623
    """
    tables, ids, states = simulator.tables, simulator.command_ids, simulator.n_states
    offsets = tables.offsets[:states, :, ids]  # (S, 4, C, K, 2), padded by repeating a swept cell
    blocks = FOOTPRINTS[:states]  # (S, 4, 4 blocks, 2)
    squared = ((offsets[..., None, :] - blocks[:, :, None, None, :, :]) ** 2).sum(axis=-1)  # (S, 4, C, K, 4)
    farthest = squared.min(axis=-1).max(axis=-1)  # (S, 4, C)
    legal = tables.legal[:states, ids][:, None, :]
    return float(np.sqrt(np.where(legal, farthest, 0).max()))


def _check_scenario(scenario) -> Scenario:
    if isinstance(scenario, ContinuousScenario):
        raise ParameterError(f"replan_heat plans on grid scenarios; {scenario.name!r} is a continuous one "
                             "(Nazarahari et al. 2019's planners take those)")
    if not isinstance(scenario, Scenario):
        raise ParameterError(f"scenario must be a grid Scenario (e.g. load_scenario('maze_partial')), "
                             f"got {type(scenario).__name__} {reprlib.repr(scenario)}")
    if scenario.workspace.moving:
        raise ParameterError(f"scenario {scenario.name!r} has moving obstacles: replanning handles static maps only "
                             "(Do et al. 2021 leave moving obstacles to future work); use plan_exact (dijkstra), "
                             "which plans around known moving obstacles")
    return scenario


def _sense(pose: np.ndarray, radius: float, shape: tuple[int, int]) -> tuple[slice, slice, np.ndarray]:
    """The cells whose centre lies within ``radius`` of a block centre of ``pose`` (x, y, state, heading),
    as a window of the map (rows, columns) and the mask of the sensed cells in it."""
    centres = FOOTPRINTS[pose[2], pose[3]] + pose[:2]  # (4, 2) cells = block centres
    h, w = shape
    reach = int(np.floor(radius))
    x0, y0 = (np.maximum(centres.min(axis=0) - reach, 0)).tolist()
    x1, y1 = (np.minimum(centres.max(axis=0) + reach, (w - 1, h - 1)) + 1).tolist()
    ys, xs = np.mgrid[y0:y1, x0:x1]
    squared = (xs[None] - centres[:, 0, None, None]) ** 2 + (ys[None] - centres[:, 1, None, None]) ** 2
    return slice(y0, y1), slice(x0, x1), squared.min(axis=0) <= radius * radius


def _as_pose(sim: Simulator, pose_id: int) -> Pose:
    x, y, s, h = (int(v) for v in sim.decode(pose_id))
    return Pose(x, y, STATE_NAMES[s], h)


def replan_heat(scenario: Scenario, *, sensor_range: float = 6.0, **plan_options) -> HeatRun:
    """Do et al. 2021's online navigation (§VI-A-7): heat plans on the known map, replanned as the robot senses.

    The known map is ``scenario.workspace``; the truth is ``scenario.true_workspace()`` (the known map
    plus the scenario's hidden obstacles). The loop:

    1. **Sense** [ours: the paper gives only the range, D_S = 6 d_grid]: a cell is sensed iff its
       centre lies within ``sensor_range`` (Euclidean, in cells, inclusive) of one of the four block
       centres of the robot's current footprint, with no occlusion. A sensed cell takes its true
       state in the known map: obstacles are added and, in general, a cell believed blocked but
       sensed free is freed (a scenario's known map never holds an obstacle the truth lacks, so with a
       :class:`~htetro_opt.scenarios.Scenario` nothing is ever freed). The robot senses at the start,
       before the first plan, and after every command.
    2. **Plan** with :func:`~htetro_opt.solvers.grid_paths.plan_heat` on the known map from the
       current pose through the roadmap's configurations not yet passed (a leg counts as passed once
       the commands of its plan have been executed) [ours: the paper's example has one leg]; each
       leg's field has its start's B2 cell as sink, so a replan's field has the current B2 cell as
       sink, as in the paper's Fig. 13c.
    3. **Execute** the plan command by command in the true world; after each, sense. When the sensing
       changed the known map and the rest of the plan is invalid in it, plan again (step 2) from the
       current pose. A plan still valid in the changed map is kept [ours: the paper replans when "new
       obstacles occupy the path"].

    Why every executed command is valid in the truth: the known map agrees with the truth on every
    cell sensed from the current pose (sensing wrote them, and the map is static). A command sweeps
    only cells within its *reach* of the block centres of the pose it starts from; the command reach,
    the largest over the set's commands, states and headings, is √10 ≈ 3.16 cells for Do et al.
    2021's 17 commands without clearance (the O → J shapeshift), 4 cells with a clearance of 0.2. With ``sensor_range`` at least that reach, every cell the next command sweeps was
    just sensed, so the command is valid in the truth iff it is valid in the known map, and the plan
    made on the known map only holds valid ones there. A shorter range is refused (ParameterError)
    rather than letting the robot drive into unsensed cells. Each command is nonetheless executed
    through the true world's transition table, and the whole run is replayed there at the end.

    The loop ends: a replan happens only after sensing revealed a new obstacle cell (the plan was
    valid in the map before), so there are at most as many replans as hidden cells. When a plan on
    the known map cannot reach the goal, the robot stops where it is and the run has ``reached =
    False`` [ours]: the known map never holds an obstacle the truth lacks, so no path exists in the
    truth either. The start is checked against the truth (the robot stands there); the other
    configurations against the known map, so a goal on a hidden obstacle is found unreachable as the
    robot senses it.

    Parameters
    ----------
    scenario : Scenario
        A grid scenario with a roadmap (start first, goal last) and a static map; its ``hidden`` cells
        are the obstacles the robot does not know of.
    sensor_range : float, keyword-only
        D_S in cells (Do et al. 2021: 6): finite and at least the command reach of the command set.
    **plan_options
        Passed to :func:`~htetro_opt.solvers.grid_paths.plan_heat` at every (re)plan: ``weights``,
        ``t_max``, ``element``, ``monotone``, ``commands`` (default Do et al. 2021's 17), ``timing``,
        ``clearance``, ``field_options``, and any option it gains. ``commands``, ``timing`` and
        ``clearance`` also compile the simulators of the truth and of each version of the known map;
        plan_heat is handed the known map's simulator (compiled once per version), or the map itself
        when a ``band`` is given (a compiled simulator is searched whole).

    Returns
    -------
    HeatRun
        ``reached`` is False (not an exception) when the goal cannot be reached; a start equal to the
        goal gives an empty run with every cost 1.

    Raises
    ------
    ParameterError
        If ``sensor_range`` is not a finite number of at least the command reach, ``scenario`` is not
        a grid :class:`~htetro_opt.scenarios.Scenario` (a continuous one included) or has moving
        obstacles, or a plan option is bad (as :func:`plan_heat` raises it).
    PlanningError
        If the roadmap has fewer than two configurations.
    ConfigurationError
        If the start collides (in the truth) or lies outside the map, or another configuration does
        in the known map (the simulator's messages).

    Examples
    --------
    >>> from htetro_opt.scenarios import load_scenario
    >>> run = replan_heat(load_scenario("maze_partial"))
    >>> run.reached, run.plans, [r["revealed"] for r in run.replans]
    (True, 2, [((5, 11), (6, 11))])
    """
    began = _time.perf_counter()
    sensor_range = check_real(sensor_range, "sensor_range", minimum=0.0, include_minimum=False)
    scenario = _check_scenario(scenario)
    roadmap = check_roadmap(scenario.roadmap)
    compile_options = {k: plan_options.pop(k) for k in _COMPILE_OPTIONS if k in plan_options}
    if compile_options.get("commands") is None:
        compile_options["commands"] = command_set(diagonals=True)  # plan_heat's default set
    truth = scenario.true_workspace()
    true_sim = Simulator(truth, **compile_options)
    reach = _command_reach(true_sim)
    if sensor_range < reach:
        clearance = true_sim.tables.clearance
        raise ParameterError(
            f"sensor_range must be at least {reach:.4g} cells, got {sensor_range:g}: a command of this set"
            f"{f' with clearance {clearance:g}' if clearance else ''} sweeps cells up to {reach:.4g} cells from "
            "the robot's block centres, which a shorter range would leave unsensed")
    pose = true_sim.check_pose(roadmap[0], what="start")

    shape = truth.occupancy.shape
    known = scenario.workspace.occupancy.copy()
    new_cells: list[tuple[int, int]] = []  # obstacle cells learnt since the last plan

    def sense(pose_id: int) -> bool:
        """Write the truth of the sensed cells into ``known``; whether that changed it."""
        rows, cols, mask = _sense(true_sim.decode(pose_id), sensor_range, shape)
        seen, held = truth.occupancy[rows, cols], known[rows, cols]
        changed = mask & (seen != held)
        if not changed.any():
            return False
        ys, xs = np.nonzero(changed & seen)
        new_cells.extend(zip((xs + cols.start).tolist(), (ys + rows.start).tolist()))
        held[mask] = seen[mask]
        return True

    def compile_known() -> Simulator:
        # Once everything hidden is known, the truth's own simulator serves; else one per map version.
        if np.array_equal(known, truth.occupancy):
            return true_sim
        return Simulator(Workspace(known.copy(), truth.cell_size), **compile_options)

    def plan_from(pose_id: int, targets: list[Pose]):
        # A compiled simulator makes plan_heat search the whole graph: hand it the map when a band is asked for.
        where = known_sim.workspace if "band" in plan_options else known_sim
        return plan_heat(where, [_as_pose(true_sim, pose_id), *targets], **plan_options)

    sense(pose)
    known_sim = compile_known()
    targets = roadmap[1:]
    plan = plan_from(pose, targets)
    first_info = plan.info
    new_cells.clear()
    replans: list[dict] = []
    executed: list[int] = []
    k = 0  # commands of the current plan executed
    while plan.reached and k < len(plan.commands):
        command = int(plan.commands[k])
        after = int(true_sim.next[pose, true_sim.local[command]])
        if after == true_sim.dead:  # excluded by the reach check above: a bug, not the user's input
            raise PlanningError(f"internal error: command {COMMANDS[command].token} (number {len(executed) + 1}) "
                                "is invalid in the true world")
        pose = after
        executed.append(command)
        k += 1
        if not sense(pose):
            continue
        known_sim = compile_known()
        rest = plan.commands[k:]
        if not len(rest) or known_sim.run([rest], pose).valid[0]:
            continue
        targets = targets[sum(end <= k for end in plan.leg_ends):]
        replans.append({"step": len(executed), "pose": _as_pose(true_sim, pose),
                        "revealed": tuple(sorted(set(new_cells)))})
        new_cells.clear()
        plan, k = plan_from(pose, targets), 0

    commands = np.array(executed, dtype=np.int64)
    replay = true_sim.run([commands], roadmap[0], roadmap=roadmap[1:])
    if not replay.valid[0]:
        raise PlanningError("internal error: the executed commands do not re-validate in the true world")
    poses = replay.poses(0)
    weights, t_max = first_info["weights"], first_info["t_max"]
    fitness = heat_fitness(truth, poses, commands, t_max=t_max, timing=true_sim.timing, weights=weights)
    info = {"method": plan_options.get("method", "heat"), "additions": list(first_info.get("additions", ())),
            "sensor_range": sensor_range, "reach": reach, "t_max": t_max, "weights": list(weights),
            "revealed": int((known & ~scenario.workspace.occupancy).sum())}
    return HeatRun(executed=commands, poses=poses, time=float(replay.time[0]), reached=bool(replay.reached[0]),
                   replans=tuple(replans), fitness=fitness, plans=1 + len(replans),
                   runtime_s=_time.perf_counter() - began, info=info, fields=tuple(plan.info.get("fields", ())))
