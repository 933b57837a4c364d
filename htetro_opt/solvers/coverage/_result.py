"""The one result type of coverage planning, and the one place a coverage plan is re-validated.

Every method of :func:`~htetro_opt.solvers.coverage.plan_coverage` returns a :class:`CoveragePlan`
built by :func:`finish_coverage`, which replays the commands from the start as the layer graph's
:class:`~htetro_opt.model.Simulator` runs them (:func:`~htetro_opt.model.simulate.replay`, the same
transitions and sweep check without compiling the map's whole table; the simulator itself where
obstacles move): the covered cells, the poses and the time are
those of the replay (every pose the robot passes through, the intermediate states of a switch
included), never the planner's own bookkeeping.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from functools import cached_property
from typing import Mapping

import numpy as np
from scipy.sparse.csgraph import breadth_first_order

from htetro_opt.errors import ConfigurationError, PlanningError
from htetro_opt.model.commands import COMMANDS, SEED004_COMMANDS, parse_commands
from htetro_opt.model.coverage import (
    CoverageResult,
    grid_activity,
    simulate_command_coverage,
)
from htetro_opt.model.robot import FOOTPRINTS, Pose, as_pose
from htetro_opt.model.simulate import replay
from htetro_opt.model.workspace import Workspace
from htetro_opt.solvers._result import Result
from htetro_opt.solvers.coverage._layers import LayerGraph

__all__ = ["CoveragePlan", "Coverability", "coverability", "finish_coverage", "check_end", "UNCOVERABLE_REASONS",
           "RECOVERED_TIME"]

RECOVERED_TIME = 1.5
"""Cell time (in command units) from which a coverable cell counts as re-covered (:attr:`CoveragePlan.recovered_pct`)."""

UNCOVERABLE_REASONS = ("no-fit", "unreachable")
"""Why a free cell is not coverable: no valid pose of S covers it anywhere, or none that the start
can reach (a pocket walled off from it)."""


@dataclass(frozen=True, eq=False)  # holds arrays: identity equality, hashable
class CoveragePlan(Result):
    """A complete-coverage plan, whatever the method: commands from the start and what they cover
    (re-validated in the simulator). ``success``: every coverable cell is covered (``complete`` asks for
    every free cell, which a cell no pose of S covers prevents).

    Attributes
    ----------
    method : str
    layers : tuple of str
        The morphology set S the plan used.
    stripes : tuple of int
        Stripe widths, bottom up (empty for methods without stripes).
    start, goal : Pose, Pose or None
        None for a free end.
    commands : ndarray of int64
        Global command ids (Cheng et al. 2019's commands; ``stop`` never appears).
    poses : ndarray, shape (len(commands) + 1, 4)
        (x, y, state, heading) after each command, the start first.
    time : float
        Duration under the simulator's timing (one unit a command by default: the action cost).
    free, coverable, covered : ndarray of bool, shape (H, W)
        Free cells; free cells under some valid pose of S that the start can reach; cells under the
        robot's blocks at some pose of the replay.
    uncoverable : tuple of (x, y, reason)
        The free cells that are not coverable, with a reason of :data:`UNCOVERABLE_REASONS`.
    stripes_detail : tuple of dict
        Per stripe: ``rows`` (its own, [low, high)), ``band`` (with the rows borrowed by widening,
        [low, high)), ``borrowed`` (their number), ``cost`` (commands of the plan's part in it),
        ``regions``, ``direction`` (+1: swept +x), ``folded`` (swept out and back, ``ends="both"``)
        and ``cuts`` (x of the cell edges between its regions, each at x − ½).
    regions, regions_optimal, memo_hits, nodes : int
        Region searches run (memo hits excluded), those proven optimal, memo hits, search nodes expanded.
    dag_cost : int or None
        Cost of the auxiliary DAG's shortest path (None when the method has none).
    switches : int
        Layer changes along the plan (a switch's intermediate states do not count).
    transit_commands, mopup_commands : int
        Commands of the legs outside the DAG: start/goal transits, and the mop-up of what the
        stripes left uncovered.
    time_limited : bool
        The time limit cut the search short (the plan is still valid; without ``greedy-fallback`` the
        regions searched past it fail).
    failed_regions : tuple of dict
        Stripe methods without the ``greedy-fallback`` addition: every region search that spent its
        node budget (or ran past the time limit) and so has no walk, each with its ``stripe``, ``rows``,
        ``columns`` ([c0, c1)), ``direction``, ``entry`` and ``exit`` poses (``exit`` None: a free
        end), ``reason`` (``"node budget"`` or ``"time limit"``) and ``nodes``. Any makes ``success``
        false: the paper's algorithm was not run to its end there.
    ends : str or None
        The stripe methods' ``ends`` option (``"sweep"`` or ``"both"``); None for the other methods.
    runtime_s : float
    info : dict
        Method-specific extras (JSON-ready).

    Notes
    -----
    The measures of Cheng et al. 2019 §V are properties: :attr:`action_cost`, :attr:`coverage_pct`
    (of the free cells), :attr:`coverable_pct`, :attr:`average_coverage_time` and
    :attr:`recovered_pct` (from the pixel simulation :attr:`coverage`, computed on first use),
    :attr:`switches`, :attr:`turns`, :attr:`path_length` (B2's) and :attr:`activity` (eq. 4).
    """

    method: str
    layers: tuple[str, ...]
    stripes: tuple[int, ...]
    start: Pose
    goal: Pose | None
    commands: np.ndarray
    poses: np.ndarray
    time: float
    free: np.ndarray
    coverable: np.ndarray
    covered: np.ndarray
    uncoverable: tuple[tuple[int, int, str], ...]
    stripes_detail: tuple = ()
    regions: int = 0
    regions_optimal: int = 0
    memo_hits: int = 0
    nodes: int = 0
    dag_cost: int | None = None
    transit_commands: int = 0
    mopup_commands: int = 0
    switches: int = 0
    time_limited: bool = False
    ends: str | None = None
    failed_regions: tuple = ()
    runtime_s: float = 0.0
    info: Mapping = field(default_factory=dict)

    @property
    def tokens(self) -> list[str]:
        return [COMMANDS[int(c)].token for c in self.commands]

    @property
    def action_cost(self) -> int:
        """Number of commands (the paper's action cost)."""
        return len(self.commands)

    @property
    def complete(self) -> bool:
        """Every free cell is covered."""
        return bool((self.covered | ~self.free).all())

    @property
    def coverage_pct(self) -> float:
        """Covered free cells, percent of the free cells."""
        free = int(self.free.sum())
        return 100.0 * int((self.covered & self.free).sum()) / free if free else 100.0

    @property
    def coverable_pct(self) -> float:
        """Covered coverable cells, percent of the coverable cells (100 for every method's plan)."""
        n = int(self.coverable.sum())
        return 100.0 * int((self.covered & self.coverable).sum()) / n if n else 100.0

    @property
    def path_length(self) -> float:
        """Length of B2's path in cells (B2 stays on its cell in a switch)."""
        return float(sum(math.hypot(*COMMANDS[int(c)].shift) for c in self.commands))

    @cached_property
    def coverage(self) -> CoverageResult:
        """Pixel coverage times of the run (Cheng et al. 2019 §V: 10 × 10 pixels a cell, time step 0.1),
        from :func:`~htetro_opt.model.coverage.simulate_command_coverage`; computed on first use."""
        return simulate_command_coverage(Workspace(~self.free), self.start, self.commands)

    @property
    def average_coverage_time(self) -> float:
        """The paper's average coverage time: mean time a free cell's pixels are under a block
        (:attr:`CoverageResult.average_grid_time`), in command units."""
        return self.coverage.average_grid_time

    @property
    def recovered_pct(self) -> float:
        """Coverable cells covered for :data:`RECOVERED_TIME` (1.5) or more, percent of the coverable cells."""
        n = int(self.coverable.sum())
        return 100.0 * int((self.coverage.cell_time[self.coverable] >= RECOVERED_TIME).sum()) / n if n else 0.0

    @property
    def activity(self) -> np.ndarray:
        """Grid activity at the end of the plan (Cheng et al. 2019 eq. 4): −1 obstacle, 1 covered, 0 not."""
        return grid_activity(Workspace(~self.free), self.poses)

    @property
    def turns(self) -> int:
        """Changes of direction between consecutive translations."""
        moves = [COMMANDS[int(c)].shift for c in self.commands if COMMANDS[int(c)].kind == "translation"]
        return sum(a != b for a, b in zip(moves[:-1], moves[1:]))

    @property
    def missed(self) -> tuple[tuple[int, int], ...]:
        """The coverable cells the plan leaves uncovered, (x, y) bottom row first (none with a mop-up)."""
        ys, xs = np.nonzero(self.coverable & ~self.covered)
        return tuple((int(x), int(y)) for y, x in zip(ys, xs))

    @property
    def success(self) -> bool:
        """Every coverable cell covered, and no region search failed (:attr:`failed_regions`)."""
        return bool((self.covered | ~self.coverable).all()) and not self.failed_regions

    @property
    def message(self) -> str:
        missed = len(self.missed)
        failed = len(self.failed_regions)
        searches = f"; {failed} region searches spent their budget without a walk" if failed else ""
        if missed:
            return f"{missed} coverable cells left uncovered ({self.action_cost} commands){searches}"
        if failed:
            return f"covered every coverable cell in {self.action_cost} commands{searches}"
        unreachable = f"; {len(self.uncoverable)} free cells no pose of the set covers" if self.uncoverable else ""
        return f"covered every coverable cell in {self.action_cost} commands{unreachable}"

    def _fields(self) -> dict:
        """The CLI's ``cover --json`` keys."""
        return {
            "shapes": list(self.layers),
            "stripes": list(self.stripes),
            "start": self.start.as_dict(),
            "goal": None if self.goal is None else self.goal.as_dict(),
            "complete": self.complete,
            "free": int(self.free.sum()),
            "coverable": int(self.coverable.sum()),
            "covered": int((self.covered & self.free).sum()),
            "uncoverable": [{"x": x, "y": y, "reason": r} for x, y, r in self.uncoverable],
            "action_cost": self.action_cost,
            "time": self.time,
            "commands": self.tokens,
            "coverage_pct": self.coverage_pct,
            "coverable_pct": self.coverable_pct,
            "recovered_pct": self.recovered_pct,
            "average_coverage_time": self.average_coverage_time,
            "path_length": self.path_length,
            "switches": self.switches,
            "turns": self.turns,
            "regions": self.regions,
            "regions_optimal": self.regions_optimal,
            "memo_hits": self.memo_hits,
            "nodes": self.nodes,
            "dag_cost": self.dag_cost,
            "transit_commands": self.transit_commands,
            "mopup_commands": self.mopup_commands,
            "stripes_detail": [dict(d) for d in self.stripes_detail],
            "ends": self.ends,
            "missed": [{"x": x, "y": y} for x, y in self.missed],
            "failed_regions": [dict(r) for r in self.failed_regions],
        }


@dataclass(frozen=True, eq=False)
class Coverability:
    """What the start can cover: its reachable vertices and cells, and why the other free cells cannot be."""

    reachable: np.ndarray  # (N,) bool over the layer graph's vertices
    coverable: np.ndarray  # (H, W) bool
    uncoverable: tuple[tuple[int, int, str], ...]


def coverability(lg: LayerGraph, start_node: int) -> Coverability:
    """Vertices reachable from ``start_node`` and the cells their footprints cover (the coverable
    cells); every other free cell with its reason (``no-fit`` or ``unreachable``)."""
    order = breadth_first_order(lg.matrix, start_node, directed=True, return_predecessors=False)
    reachable = np.zeros(lg.n_nodes, dtype=bool)
    reachable[order] = True
    hw = lg.width * lg.height
    coverable = np.zeros(hw, dtype=bool)
    coverable[lg.footprint[reachable].ravel()] = True
    fits = np.zeros(hw, dtype=bool)
    fits[lg.footprint[lg.node_valid].ravel()] = True
    free = ~lg.workspace.occupancy.reshape(-1)
    coverable &= free
    rest = np.flatnonzero(free & ~coverable)
    uncoverable = tuple((int(c % lg.width), int(c // lg.width), "unreachable" if fits[c] else "no-fit") for c in rest)
    return Coverability(reachable, coverable.reshape(lg.height, lg.width), uncoverable)


def check_end(lg: LayerGraph, pose, what: str) -> int:
    """The vertex of a start or goal pose, checked: inside the map, collision-free, a layer of S.

    Raises
    ------
    ConfigurationError
        Naming ``what``: off the map, colliding, or in a layer outside S.
    """
    pose = as_pose(pose, what)
    lg.check_pose(pose, what=what)
    v = lg.node_of(pose)
    if v is None:
        names = ", ".join(layer.name for layer in lg.layers)
        raise ConfigurationError(f"{what} {tuple(pose)} is not in a layer of the morphology set ({names}): "
                                 "add it to --shapes or use --start auto")
    return v


def finish_coverage(lg: LayerGraph, tokens, start_node: int, *, method: str, stripes=(), goal_node: int | None,
                    coverable: Coverability, began: float, **extras) -> CoveragePlan:
    """Replay the commands from the start and wrap them as a :class:`CoveragePlan`.

    Raises
    ------
    PlanningError
        If the commands do not re-validate, or do not end on the goal: a method's bug, never the
        user's input.
    """
    commands = parse_commands(list(tokens)) if not isinstance(tokens, np.ndarray) else tokens.astype(np.int64)
    if lg.workspace.moving:  # the simulator checks moving obstacles step by step
        run = lg.sim.run([commands], lg.pose_id(start_node))
        valid, first_invalid, poses = bool(run.valid[0]), int(run.first_invalid[0]), run.poses(0)
        end, duration = int(run.trace[0, len(commands)]) if valid else -1, float(run.time[0])
    else:  # the same replay without the simulator's table (~760 MB at 384 x 384, twice that once run)
        run = replay(lg.workspace, commands, lg.pose_id(start_node), commands=SEED004_COMMANDS,
                     clearance=lg.clearance)
        valid, first_invalid, poses, end, duration = run.valid, run.first_invalid, run.poses, run.final_id, run.time
    if not valid:
        raise PlanningError(f"internal error: the {method} coverage plan does not re-validate in the simulator "
                            f"(command {first_invalid + 1} of {len(commands)} is invalid)")
    if goal_node is not None and end != lg.pose_id(goal_node):
        raise PlanningError(f"internal error: the {method} coverage plan does not end on the goal")
    cells = FOOTPRINTS[poses[:, 2], poses[:, 3]] + poses[:, None, :2]  # (n, 4, 2)
    covered = np.zeros((lg.height, lg.width), dtype=bool)
    covered[cells[..., 1].ravel(), cells[..., 0].ravel()] = True
    free = ~lg.workspace.occupancy
    keys = {(layer.state, layer.heading) for layer in lg.layers}
    visited = [(int(s), int(h)) for s, h in poses[:, 2:] if (int(s), int(h)) in keys]
    switches = sum(a != b for a, b in zip(visited[:-1], visited[1:]))
    for array in (commands, poses, covered, free):
        array.setflags(write=False)
    return CoveragePlan(
        method=method,
        layers=tuple(layer.name for layer in lg.layers),
        stripes=tuple(int(s) for s in stripes),
        start=lg.pose(start_node),
        goal=None if goal_node is None else lg.pose(goal_node),
        commands=commands,
        poses=poses,
        time=duration,
        free=free,
        coverable=coverable.coverable,
        covered=covered,
        uncoverable=coverable.uncoverable,
        switches=switches,
        runtime_s=time.perf_counter() - began,
        **extras,
    )
