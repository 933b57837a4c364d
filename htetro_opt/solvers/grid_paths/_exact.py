"""Exact minimum-time planning over (x, y, state, heading) — the reference for every heuristic.

The search graph is the :class:`~htetro_opt.model.Simulator`'s own transition table: one node per
pose, one edge per valid command weighted by its duration, so every plan re-validates in the
simulator by construction. With moving obstacles the graph is time-expanded over their period
(node = pose × time modulo the period; the obstacles' time is the number of commands executed, as in
the simulator), and a command that leaves the pose unchanged (``stop``, a shapeshift to the current
shape) is a way to wait. A roadmap is planned leg by leg, each leg starting where and when the previous one
ended (Cheng et al. 2020's configuration loop); each leg is time-optimal.

Two algorithms give the same optimum: ``"dijkstra"`` (scipy.sparse.csgraph over the whole graph, the
fastest here) and ``"astar"`` (a heapq A* that expands only what it needs, with the admissible
heuristic "grid distance of B2's cell to the goal × the cheapest translation time per cell"). When
moving obstacles have a long common period the whole time-expanded graph would not fit in memory
(more than :data:`MAX_EXPANDED_NODES` nodes): "dijkstra" then hands over to A*, and the plan's
``method`` says so. A leg that is unreachable even without the moving obstacles is reported at once.
"""

from __future__ import annotations

import heapq
import math
import time as _time
from typing import Sequence

import numpy as np
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import dijkstra

from htetro_opt._validation import check_int
from htetro_opt.errors import ParameterError, PlanningError
from htetro_opt.model.commands import COMMANDS, Timing
from htetro_opt.model.robot import Pose
from htetro_opt.model.simulate import Simulator
from htetro_opt.model.workspace import Workspace, grid_distance
from htetro_opt.solvers.grid_paths._result import Plan, finish_plan, prepare

__all__ = ["plan_exact", "EXACT_METHODS"]

EXACT_METHODS = ("dijkstra", "astar")
MAX_EXPANDED_NODES = 8_000_000
"""Above this many time-expanded nodes (poses × obstacle period), "dijkstra" hands over to the lazy A*."""


class _Graph:
    """The simulator's transition table as a (time-expanded) CSR graph, cheapest command per edge.

    With ``static``, moving obstacles are ignored (the table itself only knows the static map).
    """

    def __init__(self, sim: Simulator, *, static: bool = False) -> None:
        self.sim = sim
        self.moving = bool(sim.workspace.moving) and not static
        self.period = sim.workspace.period if self.moving else 1
        n, c = sim.n_poses, sim.n_commands
        self.target = sim.next[:n, :c]
        usable = self.target != sim.dead
        if not self.moving:
            # A command that leaves the pose unchanged is useless on a static map; with moving
            # obstacles it is a wait, which advances their clock.
            usable &= self.target != np.arange(n, dtype=self.target.dtype)[:, None]
        for cheap, costly in self._colliding_columns():
            usable[:, costly] &= ~(usable[:, cheap] & (self.target[:, cheap] == self.target[:, costly]))
        self.usable = usable
        if (sim.durations[:c] <= 0).any() and usable[:, sim.durations[:c] <= 0].any():
            raise PlanningError("exact planning needs every command that moves the robot to take a positive time")
        self._matrix: csr_matrix | None = None

    def _colliding_columns(self) -> list[tuple[int, int]]:
        """Pairs (cheaper, costlier) of local commands that lead some pose to the same next pose."""
        sim, t = self.sim, self.sim.tables
        ids, states = sim.command_ids, slice(0, sim.n_states)
        pairs = []
        for i in range(len(ids)):
            for j in range(i + 1, len(ids)):
                a, b = ids[i], ids[j]
                if (t.shift[a] != t.shift[b]).any() or (t.next_heading[states, :, a] != t.next_heading[states, :, b]).any():
                    continue
                both = t.legal[states, a] & t.legal[states, b]
                if (t.next_state[states, a][both] == t.next_state[states, b][both]).any():
                    cheap, costly = (i, j) if sim.durations[i] <= sim.durations[j] else (j, i)
                    pairs.append((cheap, costly))
        return pairs

    def _usable_at(self, phase: int) -> np.ndarray:
        if not self.moving:
            return self.usable
        keys = self.sim.blocked_keys(phase)
        usable = self.usable.copy()
        columns = self.sim.n_columns
        usable[keys // columns, keys % columns] = False
        return usable

    def matrix(self) -> csr_matrix:
        """The whole graph: node = phase * n_poses + pose, one edge per usable (pose, command)."""
        if self._matrix is None:
            sim = self.sim
            period, n = self.period, sim.n_poses
            weights = np.broadcast_to(sim.durations[: sim.n_commands], self.target.shape)
            indptr, indices, data = [np.zeros(1, dtype=np.int64)], [], []
            for phase in range(period):
                usable = self._usable_at(phase)
                indptr.append(indptr[-1][-1] + np.cumsum(usable.sum(axis=1)))
                indices.append(self.target[usable].astype(np.int64) + ((phase + 1) % period) * n)
                data.append(weights[usable])
            self._matrix = csr_matrix(
                (np.concatenate(data), np.concatenate(indices), np.concatenate(indptr)),
                shape=(n * period, n * period),
            )
        return self._matrix

    def step_command(self, u: int, v: int, phase: int) -> int:
        """Local command of the cheapest usable edge u → v at time ``phase``."""
        candidates = np.flatnonzero((self.target[u] == v) & self.usable_row(u, phase))
        return int(candidates[np.argmin(self.sim.durations[candidates])])

    def usable_row(self, u: int, phase: int) -> np.ndarray:
        """Which commands can be executed from pose u at time ``phase``."""
        if not self.moving:
            return self.usable[u]
        row = self.usable[u].copy()
        keys = self.sim.blocked_keys(phase)
        columns = self.sim.n_columns
        row[keys[(keys // columns) == u] % columns] = False
        return row


def _dijkstra_leg(graph: _Graph, start: int, goal: int, t0: int) -> list[int] | None:
    sim = graph.sim
    period, n = graph.period, sim.n_poses
    source = (t0 % period) * n + start
    dist, pred = dijkstra(graph.matrix(), indices=source, return_predecessors=True)
    goal_nodes = goal + n * np.arange(period)
    best = goal_nodes[np.argmin(dist[goal_nodes])]
    if not np.isfinite(dist[best]):
        return None
    nodes = [int(best)]
    while nodes[-1] != source:
        nodes.append(int(pred[nodes[-1]]))
    nodes.reverse()
    return [graph.step_command(a % n, b % n, (a // n)) for a, b in zip(nodes[:-1], nodes[1:])]


def _astar_leg(graph: _Graph, start: int, goal: int, t0: int, heuristic: np.ndarray) -> list[int] | None:
    sim = graph.sim
    period, n = graph.period, sim.n_poses
    cells = sim.workspace.width * sim.workspace.height  # pose % cells is the pose's cell y * W + x
    flat_h = heuristic.ravel()
    durations = sim.durations[: sim.n_commands].tolist()
    source = (t0 % period) * n + start
    best = {source: 0.0}
    parent: dict[int, tuple[int, int]] = {}
    frontier = [(flat_h[start % cells], 0.0, source)]
    while frontier:
        _, g, node = heapq.heappop(frontier)
        if g > best.get(node, math.inf):
            continue
        pose, phase = node % n, node // n
        if pose == goal:
            commands = []
            while node != source:
                node, column = parent[node]
                commands.append(column)
            return commands[::-1]
        row = graph.target[pose].tolist()
        usable = graph.usable_row(pose, phase).tolist()
        next_phase = (phase + 1) % period
        for column, target in enumerate(row):
            if not usable[column]:
                continue
            cost = g + durations[column]
            child = next_phase * n + target
            if cost < best.get(child, math.inf):
                best[child] = cost
                parent[child] = (node, column)
                heapq.heappush(frontier, (cost + flat_h[target % cells], cost, child))
    return None


def plan_exact(
    workspace: Workspace | Simulator,
    roadmap: Sequence[Pose],
    *,
    diagonals: bool = False,
    commands: Sequence[str] | None = None,
    timing: Timing | None = None,
    clearance: float = 0.0,
    method: str = "dijkstra",
    t0: int = 0,
) -> Plan:
    """Minimum-time plan through a roadmap of configurations.

    Parameters
    ----------
    workspace : Workspace or Simulator
        The map, or an already compiled simulator (then the command options below are ignored).
    roadmap : sequence of Pose
        Start first, goal last, at least two configurations.
    diagonals : bool, keyword-only
        Allow the four diagonal translations (seed 001).
    commands : sequence of str, optional, keyword-only
        Command tokens to plan with (default: Cheng et al. 2020's set, plus diagonals when asked).
    timing : Timing, optional, keyword-only
    clearance : float, keyword-only
        δ in cells (MODEL.md §4).
    method : {"dijkstra", "astar"}, keyword-only
        Both give the optimum; a ``"dijkstra"`` plan whose time-expanded graph would be too large is
        made by A* (its ``method`` then reads ``"dijkstra (astar)"``).
    t0 : int, keyword-only
        Commands already executed at the start (the clock of moving obstacles), e.g. to plan one leg
        of a longer roadmap.

    Returns
    -------
    Plan
        ``reached`` is False (not an exception) when a leg has no path.

    Raises
    ------
    ParameterError
        If the method is unknown or ``t0`` is not a non-negative integer.
    PlanningError
        If the roadmap has fewer than two configurations.
    ConfigurationError
        If the start collides or a configuration is outside the map.

    Examples
    --------
    >>> ws = Workspace(np.zeros((5, 5), dtype=bool))
    >>> plan = plan_exact(ws, [Pose(1, 1, "O", 0), Pose(3, 2, "O", 0)])
    >>> plan.reached, plan.time, len(plan.tokens)
    (True, 3.0, 3)
    """
    if method not in EXACT_METHODS:
        raise ParameterError(f"unknown exact method {method!r}: expected one of {', '.join(EXACT_METHODS)}")
    t0 = check_int(t0, "t0", minimum=0)
    began = _time.perf_counter()
    sim, roadmap, ids = prepare(workspace, roadmap, t0=t0, commands=commands, diagonals=diagonals,
                                timing=timing, clearance=clearance)
    graph = _Graph(sim)
    moving = bool(sim.workspace.moving)
    search = method
    if method == "dijkstra" and moving and sim.n_poses * sim.workspace.period > MAX_EXPANDED_NODES:
        search = "astar"
    static = _Graph(sim, static=True) if moving else graph
    has_diagonals = any(COMMANDS[int(c)].kind == "diagonal" for c in sim.command_ids)
    per_cell = min(
        [sim.timing.translation] + ([sim.timing.diagonal / math.sqrt(2.0)] if has_diagonals else [])
    )
    local: list[int] = []
    leg_ends: list[int] = []
    failed = -1
    for leg, (a, b) in enumerate(zip(ids[:-1], ids[1:])):
        if moving and _dijkstra_leg(static, a, b, 0) is None:  # moving obstacles only remove edges
            steps = None
        elif search == "dijkstra":
            steps = _dijkstra_leg(graph, a, b, t0 + len(local))
        else:
            goal_cell = tuple(int(v) for v in sim.decode(b)[:2])
            h = grid_distance(sim.workspace, goal_cell, diagonals=has_diagonals) * per_cell
            steps = _astar_leg(graph, a, b, t0 + len(local), h)
        if steps is None:
            failed = leg
            break
        local.extend(steps)
        leg_ends.append(len(local))
    global_ids = sim.command_ids[np.array(local, dtype=np.int64)] if local else np.empty(0, dtype=np.int64)
    label = method if search == method else f"{method} ({search})"
    return finish_plan(sim, global_ids, ids[0], t0=t0, method=label, leg_ends=leg_ends, failed_leg=failed,
                       began=began)
