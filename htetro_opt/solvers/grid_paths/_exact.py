"""Exact minimum-time planning over (x, y, state, heading) — the reference for every heuristic.

Two engines, the same optimum:

- **Static maps** (:mod:`~htetro_opt.solvers.grid_paths._lazy`): no graph is built. A pose's successors
  are computed when it is expanded, from the simulator's per-(state, heading, command) tables and the
  map, in a numba loop; costs and back pointers take 4 bytes a pose (10 with non-integer command times),
  and the queue is a bucket queue (a binary heap when the times are not multiples of one quantum).
  ``"dijkstra"`` searches with h = 0, ``"astar"`` with the point-robot distance field as an admissible,
  consistent heuristic (its proof is in :func:`~htetro_opt.solvers.grid_paths._lazy.heuristic_field`).
  Given a Workspace, the plan is re-validated by replaying it through the simulator's own sweep check
  at the cells it visits (:func:`~htetro_opt.model.simulate.transitions_at`), so no map-sized table is
  compiled; given a compiled Simulator, by running it there.
- **Moving obstacles** (the explicit graph, kept as it was): the search graph is the
  :class:`~htetro_opt.model.Simulator`'s own transition table, time-expanded over the obstacles' period
  (node = pose × time modulo the period; the obstacles' time is the number of commands executed, as in
  the simulator), and a command that leaves the pose unchanged (``stop``, a shapeshift to the current
  shape) is a way to wait. ``"dijkstra"`` is scipy.sparse.csgraph over the whole graph, ``"astar"`` a
  heapq A* with the heuristic "grid distance of B2's cell to the goal × the cheapest translation time per
  cell". When the whole time-expanded graph would not fit in memory (more than :data:`MAX_EXPANDED_NODES`
  nodes, or more than the memory budget) "dijkstra" hands over to A*, and the plan's ``method`` says so.
  A leg that is unreachable even without the moving obstacles is reported at once.

A roadmap is planned leg by leg, each leg starting where and when the previous one ended (Cheng et
al. 2020's configuration loop); each leg is time-optimal.

Before anything map-sized is allocated, the memory the search would need is estimated for the engine
that runs; a map that would not fit the budget (``memory_budget``, the command line's
``--memory-budget``; by default :func:`~htetro_opt.model.simulate.memory_budget`) is refused with a
:class:`~htetro_opt.errors.PlanningError` that says how much it would need, what fits, and the flag.
"""

from __future__ import annotations

import heapq
import math
import time as _time
from typing import Sequence

import numpy as np

from htetro_opt._validation import check_int
from htetro_opt.errors import ParameterError, PlanningError
from htetro_opt.model.commands import COMMANDS, Timing
from htetro_opt.model.robot import Pose
from htetro_opt.model.simulate import (
    Simulator,
    budget_of,
    cells_within,
    check_memory,
    compile_bytes,
    map_text,
    memory_budget,
    size_text,
    table_shape,
    transitions_at,
)
from htetro_opt.model.workspace import Workspace, grid_distance
from htetro_opt.solvers.grid_paths._lazy import PoseSpace, lazy_bytes, quantum, search_leg
from htetro_opt.solvers.grid_paths._spec import check_bytes as parse_bytes
from htetro_opt.solvers.grid_paths._result import Plan, check_map, check_roadmap, finish_plan, prepare

__all__ = ["plan_exact", "EXACT_METHODS"]

EXACT_METHODS = ("dijkstra", "astar")
MAX_EXPANDED_NODES = 8_000_000
"""Above this many time-expanded nodes (poses × obstacle period), "dijkstra" hands over to the lazy A*."""

_GRAPH_BYTES = 40
"""Peak bytes per (pose, command) entry of building the CSR search graph and running scipy's Dijkstra
over it, beyond the simulator's tables (measured: 34 to 37 on maps of 50 x 50 to 350 x 350 cells;
tests/solvers/grid_paths/test_exact.py compares the estimate with tracemalloc's peak)."""
_MASK_BYTES = 3
"""Peak bytes per (pose, command) entry of A*'s usable-command mask and its temporaries."""
_ASTAR_BYTES = 200
"""Bytes per pose of A*'s heap and dictionaries when it reaches every pose, as it does when the goal
cannot be reached (measured: 183)."""


_RAISE = ("; raise the budget with --memory-budget (library: memory_budget=, e.g. '8GiB'), or use a smaller map or "
          "coarser cells")


def _check_lazy(space: PoseSpace, method: str) -> None:
    """Refuse, before anything map-sized is allocated, a static map whose search would not fit the budget."""
    per_cell, q = space.n_sh, quantum(space.durations)

    def need(cells: int) -> int:
        return lazy_bytes(cells * per_cell, cells, space.durations, q)

    ws = space.workspace
    check_memory(need(space.n_cells), f"exact planning ({method}) on this {ws.width} x {ws.height} map ({per_cell} "
                                      f"poses a cell, {space.n_commands} commands)",
                 f"{method!r} fits {map_text(cells_within(need))} with these commands" + _RAISE)


def _search(method: str, n_poses: int, n_commands: int, period: int, tables: int) -> str:
    """The search that runs: "dijkstra" hands a time-expanded graph too large for memory (more than
    :data:`MAX_EXPANDED_NODES` nodes, or beyond the memory budget with the ``tables`` of the simulator)
    to A*."""
    if method != "dijkstra" or period == 1:
        return method
    expanded = tables + _search_bytes(n_poses, n_commands, "dijkstra", period)
    return "astar" if n_poses * period > MAX_EXPANDED_NODES or expanded > memory_budget() else method


def _search_bytes(n_poses: int, n_commands: int, search: str, period: int) -> int:
    """Peak bytes of the search beyond the simulator: the CSR graph (time-expanded over the moving
    obstacles' period) for Dijkstra; for A*, the usable mask and its search state with every pose
    reached once; plus the static graph that tells an unreachable leg at once when obstacles move."""
    entries = n_poses * n_commands
    static = entries * _GRAPH_BYTES if period > 1 else 0
    if search == "dijkstra":
        return static + entries * _GRAPH_BYTES * period
    return static + entries * _MASK_BYTES + n_poses * _ASTAR_BYTES


def _check_memory(workspace: Workspace | Simulator, method: str, commands, diagonals) -> str:
    """The search to run; refuse, before compiling anything, a plan whose tables and graph would not
    fit the memory budget."""
    compiled = isinstance(workspace, Simulator)
    ws = workspace.workspace if compiled else workspace
    if compiled:
        n_poses, n_commands = workspace.n_poses, workspace.n_commands
    else:
        n_poses, n_commands = table_shape(workspace, commands=commands, diagonals=diagonals)
    cells = ws.width * ws.height
    per_cell, period = n_poses // cells, ws.period if ws.moving else 1

    def tables(c: int) -> int:  # a given simulator's tables exist already; the plan never repairs
        return 0 if compiled else compile_bytes(c * per_cell, n_commands, repair=False)

    def need(c: int, search: str) -> int:
        return tables(c) + _search_bytes(c * per_cell, n_commands, search, period)

    search = _search(method, n_poses, n_commands, period, tables(cells))
    needed = need(cells, search)
    advice = f"{search!r} fits {map_text(cells_within(lambda c: need(c, search)))} with these commands"
    if search == "dijkstra":
        astar = need(cells, "astar")
        advice += (f"; method='astar' fits this map (about {size_text(astar)})" if astar <= memory_budget()
                   else f"; method='astar' fits {map_text(cells_within(lambda c: need(c, 'astar')))}")
    check_memory(needed, f"exact planning ({search}) on this {ws.width} x {ws.height} map ({per_cell} poses a cell, "
                         f"{n_commands} commands, moving obstacles)", advice + _RAISE)
    return search


class _Graph:
    """The simulator's transition table as a (time-expanded) CSR graph, cheapest command per edge.

    With ``static``, moving obstacles are ignored (the table itself only knows the static map). A
    ``mask`` (n_poses, n_commands) of allowed edges narrows the graph, and ``weights`` of the same
    shape (positive where usable) replace the commands' durations as edge costs (static maps only);
    the cheapest command per edge is then the one of least weight.
    """

    def __init__(self, sim: Simulator, *, static: bool = False, mask: np.ndarray | None = None,
                 weights: np.ndarray | None = None) -> None:
        self.sim = sim
        self.moving = bool(sim.workspace.moving) and not static
        self.period = sim.workspace.period if self.moving else 1
        n, c = sim.n_poses, sim.n_commands
        if weights is not None and self.moving:
            raise PlanningError("per-edge weights need a static map")
        self.target = sim.next[:n, :c]
        self.weights = weights
        usable = self.target != sim.dead
        if mask is not None:  # before the colliding columns: a masked cheap edge must not hide a costly one
            usable &= mask
        if not self.moving:
            # A command that leaves the pose unchanged is useless on a static map; with moving
            # obstacles it is a wait, which advances their clock.
            usable &= self.target != np.arange(n, dtype=self.target.dtype)[:, None]
        # One edge per (pose, next pose): the CSR graph would otherwise sum the duplicates' costs.
        for cheap, costly in self._colliding_columns():
            same = usable[:, cheap] & usable[:, costly] & (self.target[:, cheap] == self.target[:, costly])
            if weights is None:
                usable[:, costly] &= ~same
            else:
                lighter = weights[:, cheap] <= weights[:, costly]
                usable[:, costly] &= ~(same & lighter)
                usable[:, cheap] &= ~(same & ~lighter)
        self.usable = usable
        if (sim.durations[:c] <= 0).any() and usable[:, sim.durations[:c] <= 0].any():
            raise PlanningError("exact planning needs every command that moves the robot to take a positive time")
        self._matrix = None  # a scipy.sparse.csr_matrix, imported when it is built: a static map's plan needs none

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

    def matrix(self):
        """The whole graph (a scipy.sparse.csr_matrix): node = phase * n_poses + pose, one edge per usable (pose,
        command)."""
        if self._matrix is None:
            from scipy.sparse import csr_matrix

            sim = self.sim
            period, n = self.period, sim.n_poses
            weights = (np.broadcast_to(sim.durations[: sim.n_commands], self.target.shape) if self.weights is None
                       else self.weights)
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
        costs = self.sim.durations[candidates] if self.weights is None else self.weights[u, candidates]
        return int(candidates[np.argmin(costs)])

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
    from scipy.sparse.csgraph import dijkstra

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
    memory_budget: int | str | None = None,
) -> Plan:
    """Minimum-time plan through a roadmap of configurations.

    Parameters
    ----------
    workspace : Workspace or Simulator
        The map, or an already compiled simulator (then the command options below are ignored).
    roadmap : sequence of Pose
        Start first, goal last, at least two configurations.
    diagonals : bool, keyword-only
        Allow the four diagonal translations (Do et al. 2021).
    commands : sequence of str, optional, keyword-only
        Command tokens to plan with (default: Cheng et al. 2020's set, plus diagonals when asked).
    timing : Timing, optional, keyword-only
    clearance : float, keyword-only
        δ in cells (MODEL.md §4).
    method : {"dijkstra", "astar"}, keyword-only
        Both give the optimum; with moving obstacles, a ``"dijkstra"`` plan whose time-expanded graph
        would be too large is made by A* (its ``method`` then reads ``"dijkstra (astar)"``).
    t0 : int, keyword-only
        Commands already executed at the start (the clock of moving obstacles), e.g. to plan one leg
        of a longer roadmap.
    memory_budget : int or str, optional, keyword-only
        Most bytes the search may take (``"8GiB"``, ``"512MiB"``, ``2**33``; the command line's
        ``--memory-budget``); None: :func:`~htetro_opt.model.simulate.memory_budget`.

    Returns
    -------
    Plan
        ``reached`` is False (not an exception) when a leg has no path.

    Raises
    ------
    ParameterError
        If the method is unknown, ``t0`` is not a non-negative integer, or an argument has the
        wrong type.
    PlanningError
        If the roadmap has fewer than two configurations, or the search would need more memory than
        the budget: the message says how much, which map size would fit, and the flag that raises
        the budget. Nothing map-sized is allocated before this check.
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
    budget = parse_bytes(memory_budget, "memory_budget")
    check_map(workspace)
    roadmap = check_roadmap(roadmap)
    source = "set by memory_budget (--memory-budget)"
    with budget_of(budget, source):
        moving = (workspace.workspace if isinstance(workspace, Simulator) else workspace).moving
        options = dict(diagonals=diagonals, commands=commands, timing=timing, clearance=clearance, method=method,
                       t0=t0)
        if moving:
            return _plan_graph(workspace, roadmap, **options)
        return _plan_lazy(workspace, roadmap, **options)


def _plan_lazy(workspace: Workspace | Simulator, roadmap: list[Pose], *, diagonals: bool, commands, timing,
               clearance: float, method: str, t0: int) -> Plan:
    """The graph-free planner of a static map (see the module docstring)."""
    began = _time.perf_counter()
    sim = workspace if isinstance(workspace, Simulator) else None
    if sim is not None:
        space = PoseSpace(sim.workspace, sim.command_ids, sim.durations, sim.tables)
    else:
        space = PoseSpace.build(workspace, commands=commands, diagonals=diagonals, timing=timing, clearance=clearance)
    _check_lazy(space, method)
    check = sim.check_pose if sim is not None else space.check_pose
    ids = [check(roadmap[0], what="start", **({"t": t0} if sim is not None else {}))]
    for i, pose in enumerate(roadmap[1:], start=1):
        ids.append(check(pose, what="goal" if i == len(roadmap) - 1 else f"roadmap configuration {i + 1}"))
    local: list[int] = []
    leg_ends: list[int] = []
    failed, expanded = -1, 0
    for leg, (a, b) in enumerate(zip(ids[:-1], ids[1:])):
        steps, n = search_leg(space, a, b, astar=method == "astar")
        expanded += n
        if steps is None:
            failed = leg
            break
        local.extend(steps)
        leg_ends.append(len(local))
    global_ids = space.command_ids[np.array(local, dtype=np.int64)] if local else np.empty(0, dtype=np.int64)
    info = {"expanded": expanded}
    if sim is not None:
        return finish_plan(sim, global_ids, ids[0], t0=t0, method=method, leg_ends=leg_ends, failed_leg=failed,
                           began=began, info=info)
    return _finish_replayed(space, np.array(local, dtype=np.int64), ids[0], method=method, leg_ends=leg_ends,
                            failed_leg=failed, began=began, info=info)


def _finish_replayed(space: PoseSpace, local: np.ndarray, start: int, *, method: str, leg_ends, failed_leg: int,
                     began: float, info: dict) -> Plan:
    """The :class:`Plan` of local commands from pose id ``start``, re-validated without a map-sized table:
    each command is looked up in the simulator's sweep check at the cell it starts from
    (:func:`~htetro_opt.model.simulate.transitions_at`), which must give the next pose of the trace."""
    trace = [start]
    for c in local.tolist():  # the trace the search claims: the table's target of each command
        pose = trace[-1]
        sh, cell = divmod(pose, space.n_cells)
        e = sh * space.n_commands + c
        trace.append(int(space.target_sh[e]) * space.n_cells + cell + int(space.dy[c]) * space.width + int(space.dx[c]))
    trace = np.array(trace, dtype=np.int64)
    poses = space.decode(trace)
    for lo in range(0, len(local), 20_000):  # the looked-up rows take ~3 kB a cell: a slice at a time
        hi = min(lo + 20_000, len(local))
        rows = transitions_at(space.workspace, poses[lo:hi, :2], commands=space.command_ids.tolist(),
                              clearance=space.tables.clearance)
        k = np.arange(hi - lo)
        after = rows[k, poses[lo:hi, 2], poses[lo:hi, 3], local[lo:hi]]
        bad = np.flatnonzero(after != trace[lo + 1 : hi + 1])
        if len(bad):
            raise PlanningError(f"internal error: the {method} plan does not re-validate in the simulator "
                                f"(command {lo + int(bad[0]) + 1} of {len(local)} is invalid)")
    return Plan(method=method, commands=space.command_ids[local] if len(local) else np.empty(0, dtype=np.int64),
                reached=failed_leg < 0, time=float(space.durations[local].sum()), poses=poses,
                leg_ends=tuple(int(e) for e in leg_ends), failed_leg=int(failed_leg),
                runtime_s=_time.perf_counter() - began, info=info)


def _plan_graph(workspace: Workspace | Simulator, roadmap: list[Pose], *, diagonals: bool, commands, timing,
                clearance: float, method: str, t0: int) -> Plan:
    """The explicit-graph planner (moving obstacles; also the reference of the tests on static maps)."""
    search = _check_memory(workspace, method, commands, diagonals)
    began = _time.perf_counter()
    sim, roadmap, ids = prepare(workspace, roadmap, t0=t0, commands=commands, diagonals=diagonals,
                                timing=timing, clearance=clearance)
    graph = _Graph(sim)
    moving = bool(sim.workspace.moving)
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
