"""One entry point for planning a path through a grid roadmap, whatever the method."""

from __future__ import annotations

import time as _time
from typing import Callable, Sequence

import numpy as np

from htetro_opt.errors import PlanningError
from htetro_opt.model.commands import parse_commands
from htetro_opt.model.robot import Pose
from htetro_opt.model.simulate import Simulator
from htetro_opt.model.workspace import Workspace
from htetro_opt.solvers.grid_paths._result import Plan, finish_plan, prepare
from htetro_opt.solvers.grid_paths._spec import SPEC

__all__ = ["plan_path"]

_COMPILE = ("commands", "diagonals", "timing", "clearance")


def plan_path(workspace: Workspace | Simulator, roadmap: Sequence[Pose], *,
              method: str | Callable = SPEC.default, **options) -> Plan:
    """Plan the robot's commands through a roadmap of configurations, with one method.

    Parameters
    ----------
    workspace : Workspace or Simulator
        The map, or a compiled simulator (then ``commands``, ``diagonals``, ``timing`` and
        ``clearance`` are its own).
    roadmap : sequence of Pose
        Start first, goal last, at least two configurations.
    method : str or callable, keyword-only
        A method of the task's spec (:data:`~htetro_opt.solvers.grid_paths.SPEC`, which lists every
        method with its options and defaults):

        - ``"dijkstra"`` (default; alias ``"exact"``), ``"astar"``: the minimum-time plan
          (:func:`~htetro_opt.solvers.grid_paths.plan_exact`);
        - ``"htetro-ga"``, ``"htetro-ga-paper"``, ``"nsga2"``, ``"nsga3"``, ``"smsemoa"``,
          ``"agemoea"``: a multi-objective GA over command chromosomes, leg by leg
          (:func:`~htetro_opt.solvers.grid_paths.plan_ga`);
        - ``"heat"``, ``"heat-paper"``: Do et al. 2021's heat-conduction planner with our additions,
          or as published, static maps only (:func:`~htetro_opt.solvers.grid_paths.plan_heat`).

        Or a callable ``method(simulator, roadmap, **options)`` returning the plan's commands (tokens
        or global ids) from the roadmap's start; it gets a compiled
        :class:`~htetro_opt.model.Simulator` and the roadmap as poses. Its answer is replayed: the
        legs it solves are kept, and an answer that runs an invalid command, stops short or ends
        off the goal gives ``reached=False``, the first unsolved leg as ``failed_leg`` and
        ``info={"returned": its length, "first_invalid": index of its first invalid command or −1}``.
    **options
        Keyword options of the method (e.g. ``clearance``, ``diagonals``, ``pop_size``, ``seed``), each
        checked and defaulted by the spec before any work; ``commands``, ``diagonals``, ``timing`` and
        ``clearance`` compile a callable's simulator, the others are passed to it.

    Returns
    -------
    Plan
        Re-validated in the simulator, whatever the method. ``reached`` is False (not an exception)
        when some leg was not solved; ``commands`` then holds the legs before it.

    Raises
    ------
    ParameterError
        On an unknown method, an option the named method does not take (naming its options), or a bad
        option value.
    PlanningError
        If the roadmap has fewer than two configurations, or a callable returns something that is
        not a sequence of commands.
    ConfigurationError
        If a configuration collides or lies outside the map.

    Examples
    --------
    >>> ws = Workspace(np.zeros((6, 6), dtype=bool))
    >>> roadmap = [Pose(1, 1, "O", 0), Pose(3, 2, "O", 0)]
    >>> plan_path(ws, roadmap).time, plan_path(ws, roadmap, method="astar").time
    (3.0, 3.0)
    >>> plan_path(ws, roadmap, method=lambda sim, roadmap: ["y+", "x+", "x+"]).reached
    True
    >>> short = plan_path(ws, roadmap, method=lambda sim, roadmap: "y+,x+")
    >>> short.reached, short.failed_leg, short.info
    (False, 0, {'returned': 2, 'first_invalid': -1})
    """
    if callable(method):
        return _plan_with(method, workspace, roadmap, options)
    chosen = SPEC.method(method)
    options = SPEC.check(chosen, options, stage="method")
    return chosen.load(SPEC.package)(workspace, roadmap, **chosen.presets, **options)


def _as_commands(commands, name: str) -> np.ndarray:
    """A method's answer as global command ids: tokens (a comma-separated string or a sequence) or ids."""
    try:
        if isinstance(commands, str):
            return parse_commands(commands)
        commands = list(commands)
        if commands and all(isinstance(c, str) for c in commands):
            return parse_commands(",".join(commands))
        return np.asarray(commands, dtype=np.int64).reshape(-1)
    except (TypeError, ValueError) as err:
        raise PlanningError(f"method {name} returned {commands!r}: expected command tokens or ids") from err


def _plan_with(method: Callable, workspace, roadmap, options: dict) -> Plan:
    """Run a user's method and make its commands a :class:`Plan`, its legs found by replaying them.

    The commands are replayed from the start: they solve leg k when, after solving the legs before
    it, their valid prefix passes through configuration k + 1 (the first time counts), and the last
    leg when that prefix is the whole answer and ends on the goal. An answer that stops short, runs
    an invalid command or wanders off the goal is not an error: the plan keeps the legs it solved,
    ``failed_leg`` names the first one it did not, and ``info`` records ``returned`` (the answer's
    length) and ``first_invalid`` (its first invalid command, −1 if none).
    """
    name = getattr(method, "__name__", type(method).__name__)
    compile_options = {k: options.pop(k) for k in _COMPILE if k in options}
    began = _time.perf_counter()
    sim, roadmap, ids = prepare(workspace, roadmap, **compile_options)
    commands = _as_commands(method(sim, list(roadmap), **options), name)
    result = sim.run([commands], ids[0])
    executed = int(result.executed[0])
    trace = result.trace[0, : executed + 1]
    leg_ends, step = [], 0
    for target in ids[1:-1]:
        hits = np.flatnonzero(trace[step:] == target)
        if not len(hits):
            break
        step += int(hits[0])
        leg_ends.append(step)
    if len(leg_ends) == len(ids) - 2 and executed == len(commands) and trace[-1] == ids[-1]:
        leg_ends.append(executed)
    solved = len(leg_ends) == len(ids) - 1
    info = {} if solved else {"returned": len(commands), "first_invalid": int(result.first_invalid[0])}
    kept = commands[: leg_ends[-1] if leg_ends else 0]
    return finish_plan(sim, kept, ids[0], method=name, leg_ends=leg_ends, failed_leg=-1 if solved else len(leg_ends),
                       began=began, info=info)
