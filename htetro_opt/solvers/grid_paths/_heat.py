"""Do et al. 2021's heat-conduction planner (§V): a reaching search that climbs the temperature field.

Each leg solves the steady heat field of :func:`~htetro_opt.solvers.grid_paths.solve_heat_field` with the
leg's goal B2 cell as source (T = 1) and its start B2 cell as sink (T = 0). The paper's reaching
process (Table 4, step V) extends the reached set to the "equal or higher temperature" neighbours of
each cell; here the search state is the whole pose (x, y, shape, heading), and the rule applies to
the robot's B2 cell: a translation (diagonals included) from pose U to pose V is allowed iff
``T(B2 of V) ≥ T(B2 of U) − ε`` (ε the field's tolerance); rotations and shapeshifts, which stay on
B2's cell, always are. The graph is the exact planner's (the simulator's transition table) with that
mask, searched by scipy's Dijkstra to convergence, so a leg's plan is optimal under the constraint
[ours: the paper keeps the best of the reaching paths it enumerates].

Edge cost, minimised (eq. 12 as a sum over commands) [ours]::

    J_i = [w_t t_i / t_max + w_sf s(pose after i) / L] / (w_t + w_sm + w_sf) + 1e-9 t_i / t_max

with ``s`` Fig. 5's safety penalty of a pose (:func:`~htetro_opt.problems.heat_costs.safety_pattern`)
and ``L`` the number of commands of the leg's time-only constrained plan (the paper's ``1/l_p`` with
the length fixed, so the cost stays a sum over edges); the last term breaks ties towards the faster
plan. Minimising Σ s / L is not minimising the mean safety penalty of eq. 11 exactly (a plan with
fewer commands divides by less). Smoothness (w_sm > 0) would need the last command in the search
state and is not available yet.

When no monotone path exists but an unconstrained one does, the leg takes the unconstrained optimum
and ``info["relaxed"]`` says so; ``monotone=False`` searches unconstrained throughout.
"""

from __future__ import annotations

import reprlib
import time as _time
from collections.abc import Mapping
from dataclasses import replace
from typing import Sequence

import numpy as np

from htetro_opt._validation import check_bool, check_real
from htetro_opt.errors import ParameterError
from htetro_opt.model.commands import COMMANDS, Timing, command_set
from htetro_opt.model.robot import N_HEADINGS, Pose
from htetro_opt.model.simulate import Simulator
from htetro_opt.model.workspace import Workspace
from htetro_opt.problems.heat_costs import default_t_max, heat_fitness, safety_pattern
from htetro_opt.solvers.grid_paths._exact import _check_memory, _dijkstra_leg, _Graph
from htetro_opt.solvers.grid_paths._heat_field import HEAT_ELEMENTS, solve_heat_field
from htetro_opt.solvers.grid_paths._result import Plan, check_map, check_roadmap, finish_plan, prepare

__all__ = ["plan_heat"]

_FIELD_OPTIONS = ("k_obstacle", "split_pinches", "solver", "tol")
_TIE_BREAK = 1e-9
_MOVES = ("translation", "diagonal")


def _check_weights(weights) -> tuple[float, float, float]:
    if isinstance(weights, (str, bytes)) or not hasattr(weights, "__len__") or len(weights) != 3:
        raise ParameterError(f"weights must be three numbers (w_t, w_sm, w_sf), got {reprlib.repr(weights)}")
    w = tuple(check_real(v, f"weights[{i}] ({name})", minimum=0.0)
              for i, (v, name) in enumerate(zip(weights, ("w_t", "w_sm", "w_sf"))))
    if sum(w) <= 0:
        raise ParameterError(f"weights (w_t, w_sm, w_sf) must not all be zero, got {list(w)}")
    if w[1] > 0:
        raise ParameterError(f"weights[1] (w_sm) = {w[1]:g}: the heat planner's smoothness cost needs the last "
                             "command in the search state, which is not available yet; use w_sm = 0")
    return w


def _check_field_options(options) -> dict:
    if options is None:
        return {}
    if not isinstance(options, Mapping):
        raise ParameterError(f"field_options must be a mapping of solve_heat_field options, got {reprlib.repr(options)}")
    unknown = sorted(set(options) - set(_FIELD_OPTIONS))
    if unknown:
        raise ParameterError(f"field_options takes no {', '.join(map(repr, unknown))}: "
                             f"its keys are {', '.join(_FIELD_OPTIONS)}")
    return dict(options)


def _command_ids(workspace, commands) -> tuple[int, ...]:
    """The command set to plan with (Do et al. 2021's 17 by default), refusing Cheng et al. 2019's blocks."""
    if isinstance(workspace, Simulator):
        ids = tuple(int(c) for c in workspace.command_ids)
    elif commands is None:
        ids = command_set(diagonals=True)
    elif isinstance(commands, str) or all(isinstance(c, str) for c in commands):
        ids = command_set(tokens=commands)
    else:
        listed = list(commands)
        if not all(isinstance(c, (int, np.integer)) and 0 <= c < len(COMMANDS) for c in listed):
            raise ParameterError(f"commands must be tokens or command ids 0…{len(COMMANDS) - 1}, "
                                 f"got {reprlib.repr(commands)}")
        ids = command_set(tokens=[COMMANDS[int(c)].token for c in listed])
    blocks = [COMMANDS[c].token for c in ids if COMMANDS[c].kind == "block"]
    if blocks:
        raise ParameterError(f"the heat planner does not take Cheng et al. 2019's block commands ({', '.join(blocks)})")
    return ids


def _safety_penalties(sim: Simulator) -> np.ndarray:
    """Fig. 5's penalty s of every pose id (and 0 for the dead pose): Σ n_c W_obs(c) / |U|, off-map cells
    counting as obstacles, as :func:`~htetro_opt.problems.heat_costs.heat_fitness` scores them."""
    ws = sim.workspace
    h, w = ws.height, ws.width
    patterns = [[safety_pattern(s, k) for k in range(N_HEADINGS)] for s in range(sim.n_states)]
    pad = max(int(np.abs(offsets).max()) for row in patterns for offsets, _ in row)
    blocked = np.pad(np.asarray(ws.occupancy, dtype=np.float64), pad, constant_values=1.0)
    s = np.zeros(sim.n_poses + 1)
    for state, row in enumerate(patterns):
        for heading, (offsets, weights) in enumerate(row):
            total = np.zeros((h, w))
            for (dx, dy), n_c in zip(offsets.tolist(), weights.tolist()):
                total += n_c * blocked[pad + dy: pad + dy + h, pad + dx: pad + dx + w]
            base = (state * N_HEADINGS + heading) * h * w
            s[base: base + h * w] = (total / len(offsets)).ravel()
    return s


def plan_heat(
    workspace: Workspace | Simulator,
    roadmap: Sequence[Pose],
    *,
    weights=(1.0, 0.0, 0.0),
    t_max: float | None = None,
    element: str = "q1",
    monotone: bool = True,
    commands: Sequence[str] | None = None,
    timing: Timing | None = None,
    clearance: float = 0.0,
    field_options: Mapping | None = None,
) -> Plan:
    """Do et al. 2021's heat-conduction plan through a roadmap: climb each leg's temperature field.

    Parameters
    ----------
    workspace : Workspace or Simulator
        A static map, or an already compiled simulator (then ``commands``, ``timing`` and
        ``clearance`` are its own).
    roadmap : sequence of Pose
        Start first, goal last, at least two configurations.
    weights : sequence of 3 float, keyword-only
        (w_t, w_sm, w_sf) of eq. 12: finite, ≥ 0, not all zero; w_sm must be 0 (not available yet).
    t_max : float, optional, keyword-only
        Eq. 9's time budget (default :func:`~htetro_opt.problems.heat_costs.default_t_max`).
    element : {"q1", "p0"}, keyword-only
        The field's element (:func:`~htetro_opt.solvers.grid_paths.solve_heat_field`).
    monotone : bool, keyword-only
        Allow only translations to equal or higher temperature (the paper's rule); False searches
        without the field (the same costs, unconstrained).
    commands : sequence of str, optional, keyword-only
        Command tokens (default: Do et al. 2021's 17, Cheng et al. 2020's set plus the diagonals).
    timing : Timing, optional, keyword-only
    clearance : float, keyword-only
        δ in cells (MODEL.md §4).
    field_options : mapping, optional, keyword-only
        More options of ``solve_heat_field``: ``k_obstacle``, ``split_pinches``, ``solver``, ``tol``.

    Returns
    -------
    Plan
        Method ``"heat"``; ``reached`` is False (not an exception) when a leg has no path at all.
        ``info``: ``weights``, ``t_max``, ``relaxed`` (per solved leg: no monotone path, the
        unconstrained one taken), ``field`` (per leg: ``element``, ``dofs``, ``solver``,
        ``seconds``) and ``fitness`` (:func:`~htetro_opt.problems.heat_costs.heat_fitness` of the
        whole plan: ``f_t``, ``f_sm``, ``f_sf``, ``f``).

    Raises
    ------
    ParameterError
        On bad weights, t_max, element, field options or commands (Cheng et al. 2019's block
        commands are refused), or a map with moving obstacles (static maps only).
    PlanningError
        If the roadmap has fewer than two configurations, or the tables would not fit in memory.
    ConfigurationError
        If the start collides or a configuration is outside the map.

    Examples
    --------
    >>> ws = Workspace(np.zeros((6, 6), dtype=bool))
    >>> plan = plan_heat(ws, [Pose(1, 1, "O", 0), Pose(3, 3, "O", 0)])
    >>> plan.reached, round(plan.time, 3), plan.tokens, plan.info["relaxed"]
    (True, 2.828, ['x+y+', 'x+y+'], [False])
    """
    w = _check_weights(weights)
    monotone = check_bool(monotone, "monotone")
    if not isinstance(element, str) or element not in HEAT_ELEMENTS:
        raise ParameterError(f"unknown element {element!r}: expected one of {', '.join(HEAT_ELEMENTS)}")
    options = _check_field_options(field_options)
    check_map(workspace)
    roadmap = check_roadmap(roadmap)
    ws = workspace.workspace if isinstance(workspace, Simulator) else workspace
    if ws.moving:
        raise ParameterError("the heat planner plans on static maps only: use dijkstra with moving obstacles")
    ids_set = _command_ids(workspace, commands)
    if not isinstance(workspace, Simulator) and timing is not None and not isinstance(timing, Timing):
        raise ParameterError(f"timing must be a Timing or None, got {type(timing).__name__} {reprlib.repr(timing)}")
    t_max = (default_t_max(ws, workspace.timing if isinstance(workspace, Simulator) else timing) if t_max is None
             else check_real(t_max, "t_max", minimum=0.0, include_minimum=False))
    _check_memory(workspace, "dijkstra", list(ids_set), False)
    began = _time.perf_counter()
    sim, roadmap, ids = prepare(workspace, roadmap, commands=list(ids_set), timing=timing, clearance=clearance)

    n, c, cells = sim.n_poses, sim.n_commands, ws.width * ws.height
    target = sim.next[:n, :c]
    moves = np.array([COMMANDS[int(g)].kind in _MOVES for g in sim.command_ids])
    time_cost = np.broadcast_to(sim.durations[:c] / t_max, (n, c))
    tie = _TIE_BREAK * time_cost
    safety = _safety_penalties(sim)[target] if w[2] > 0 else None  # s of the pose each edge leads to

    def leg_plan(a: int, b: int, mask) -> list[int] | None:
        """The leg's optimum under ``mask``: time first, then (with w_sf) J with L from the time plan."""
        timed = _dijkstra_leg(_Graph(sim, mask=mask, weights=time_cost + tie), a, b, 0)
        if timed is None or safety is None:
            return timed
        cost = (w[0] * time_cost + w[2] * safety / max(len(timed), 1)) / sum(w) + tie
        return _dijkstra_leg(_Graph(sim, mask=mask, weights=cost), a, b, 0)

    local: list[int] = []
    leg_ends: list[int] = []
    relaxed: list[bool] = []
    fields: list[dict] = []
    failed = -1
    for leg, (a, b) in enumerate(zip(ids[:-1], ids[1:])):
        mask = None
        record = {"element": element, "dofs": 0, "solver": None, "seconds": 0.0}
        if monotone and a != b:
            field = solve_heat_field(ws, tuple(int(v) for v in sim.decode(b)[:2]),
                                     tuple(int(v) for v in sim.decode(a)[:2]), element=element, **options)
            record.update(dofs=int(field.info.get("dofs", 0)), solver=field.info.get("solver"),
                          seconds=float(field.info.get("seconds", 0.0)))
            if field.connected:
                temperature = field.cells.ravel()
                here = temperature[np.arange(n) % cells][:, None]
                there = temperature[target % cells]  # the dead pose's cell: masked by the graph anyway
                mask = ~moves[None, :] | (there >= here - field.epsilon)
        fields.append(record)
        steps = [] if a == b else leg_plan(a, b, mask) if mask is not None else None
        leg_relaxed = False
        if steps is None:  # no monotone path (or no field): the unconstrained optimum, if any
            steps = leg_plan(a, b, None)
            leg_relaxed = monotone and steps is not None
        if steps is None:
            failed = leg
            break
        relaxed.append(leg_relaxed)
        local.extend(steps)
        leg_ends.append(len(local))

    global_ids = sim.command_ids[np.array(local, dtype=np.int64)] if local else np.empty(0, dtype=np.int64)
    info = {"weights": list(w), "t_max": float(t_max), "relaxed": relaxed, "field": fields}
    plan = finish_plan(sim, global_ids, ids[0], method="heat", leg_ends=leg_ends, failed_leg=failed,
                       began=began, info=info)
    fitness = heat_fitness(sim.workspace, plan.poses, plan.commands, t_max=t_max, timing=sim.timing, weights=w)
    return replace(plan, info={**plan.info, "fitness": fitness})

