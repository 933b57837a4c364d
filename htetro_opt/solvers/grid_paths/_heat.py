"""Do et al. 2021's heat-conduction planner (§V): a reaching search that climbs the temperature field.

Each leg solves the steady heat field of :func:`~htetro_opt.solvers.grid_paths.solve_heat_field` with the
leg's goal B2 cell as source (T = 1) and its start B2 cell as sink (T = 0). The paper's reaching
process (§V-B, steps 1–5) extends the reached set, wave by wave, to the "equal or higher
temperature" neighbours of each cell; here the search state is the whole pose (x, y, shape, heading),
and the rule applies to the robot's B2 cell: a translation (diagonals included) from pose U to pose V
is allowed iff ``T(B2 of V) ≥ T(B2 of U) − ε`` (ε the field's tolerance, so that isothermal dead-end
pockets stay enterable); rotations and shapeshifts, which stay on B2's cell, always are. The graph is
the exact planner's (the simulator's transition table) with that mask.

**As published** (``method="heat-paper"``, ``additions=()``): the paper's bilinear mesh (pinch nodes
shared), the tentative cost ``f(U) + f(U, V)`` with f(U, V) eq. 12's cost of the one command U → V
(:class:`_TentativeSearch`, which names our readings), and the stop rule of step 4: the waves end
when the goal pose enters the list, so the plan is the cheapest the waves found up to the first wave
that reaches the goal (the fewest commands' wave). A leg with no climbing path fails (``reached``
False), as "G cannot be reached".

**Ours** (``method="heat"``: every addition of :data:`~htetro_opt.solvers.grid_paths.HEAT_ADDITIONS`,
each switched singly by ``additions``):

- ``pinch-split``: the field's mesh gives each pinch node one copy per element (no corner leak);
- ``converge``: the search runs to convergence (scipy's Dijkstra, or the waves relaxed until nothing
  improves with ``engine="wavefront"``; same optimum), so a leg's plan is optimal under the rule;
- ``surrogate-cost``: the edge cost, minimised, is (eq. 12 as a sum over commands)::

      J_i = [w_t t_i / t_max + w_sm d_i / L + w_sf s(pose after i) / L] / (w_t + w_sm + w_sf) + 1e-9 t_i / t_max

  with ``s`` Fig. 5's safety penalty of a pose (:func:`~htetro_opt.problems.heat_costs.safety_pattern`),
  ``d_i`` = 1 when command i differs from command i − 1 (eq. 10; the first command is free), and ``L``
  the number of commands of the leg's time-only constrained plan (the paper's ``1/l_p`` with the length
  fixed, so the cost stays a sum over edges); the last term breaks ties towards the faster plan. With
  w_sm > 0 the last command becomes part of the search state: one layer of poses per repeatable
  command (translations and rotations; a shapeshift cannot repeat) and a hub layer, entered at no
  cost from every layer, whose commands pay the change ``w_sm / L`` — a repeat inside a layer does not.
  Minimising Σ s / L is not minimising eq. 11's mean exactly (a plan with fewer commands divides by
  less); the plan's ``info["fitness"]`` reports the exact eqs. 9–12. Eqs. 10 and 11 are ratios over
  the plan's own length, so padding a path with repeated commands or safe detours raises them without
  end; with L fixed the search cannot pad;
- ``exact-pick``: the leg's plan is the best by the exact eqs. 9–12 under the asked weights among the
  searches for those weights and for Table 6's four weightings. Table 6's property (each criterion's
  best value lies in that criterion's row) then holds by construction, which the surrogate alone
  breaks on ``random`` (smoothness row f_sm 0.679, multi-objective row 0.690);
- ``relax-fallback``: when no monotone path exists but an unconstrained one does, the leg takes the
  unconstrained optimum and ``info["relaxed"]`` says so; ``monotone=False`` searches unconstrained
  throughout (an ablation);
- ``band`` (for large maps): the whole pose graph of a 1000 x 1000 map has 28 million poses;
  ``band`` restricts a leg's search to the poses whose B2 cell lies within Chebyshev distance r of the
  field's steepest-ascent line from the start's cell to the goal's (over the grid nodes for ``"q1"``,
  over the cells without cutting an obstacle corner for ``"p0"``; by the discrete maximum principle the
  line never stalls, and on a numerical stall the band follows the ``grid_distance`` shortest path
  instead). No path in the band doubles r, until the band holds every free cell, where the band search
  is the full search. Transitions are computed for the band's cells only
  (:func:`~htetro_opt.model.simulate.transitions_at`), and the plan is replayed through them.
"""

from __future__ import annotations

import reprlib
import time as _time
from collections.abc import Mapping
from dataclasses import replace
from types import SimpleNamespace
from typing import NamedTuple, Sequence

import numpy as np
from scipy.ndimage import maximum_filter
from scipy.sparse import coo_matrix, csr_matrix
from scipy.sparse.csgraph import dijkstra

from htetro_opt._validation import check_bool, check_int, check_real
from htetro_opt.errors import ConfigurationError, ParameterError, PlanningError
from htetro_opt.model.commands import COMMANDS, Timing, command_set
from htetro_opt.model.robot import N_HEADINGS, Pose
from htetro_opt.model.commands import command_id
from htetro_opt.model.robot import as_pose, shape_index
from htetro_opt.model.simulate import Simulator, check_memory, table_shape, transitions_at
from htetro_opt.model.sweeps import sweep_tables
from htetro_opt.model.workspace import Workspace, describe_cells, grid_distance
from htetro_opt.problems.heat_costs import check_heat_weights, default_t_max, heat_fitness, safety_pattern
from htetro_opt.solvers.grid_paths._exact import _GRAPH_BYTES, _check_memory, _Graph
from htetro_opt.solvers.grid_paths._heat_field import solve_heat_field
from htetro_opt.solvers.grid_paths._result import Plan, check_map, check_roadmap, finish_plan, prepare
from htetro_opt._spec import additions as additions_check
from htetro_opt.solvers.grid_paths._spec import (BAND_SEEDS, HEAT_ADDITIONS, HEAT_ELEMENTS, HEAT_ENGINES, SPEC,
                                                 TABLE6_WEIGHTS)

__all__ = ["plan_heat", "BAND_AUTO_POSES", "BAND_AUTO_RADIUS"]

_DEFAULTS = SPEC.defaults("heat")  # the task's defaults, declared once in its spec

BAND_AUTO_POSES = 4_000_000
"""``band="auto"`` searches the whole pose graph up to this many poses, and a band above."""

BAND_AUTO_RADIUS = 8
"""``band="auto"``'s first band radius (cells, Chebyshev) on maps above :data:`BAND_AUTO_POSES`."""

_FIELD_OPTIONS = ("k_obstacle", "solver", "tol")
_TIE_BREAK = 1e-9
_MOVES = ("translation", "diagonal")
_TABLE_BYTES = 8 + 1 + 8  # per (pose, command) of a band: targets (int64), usable mask, weights


def _check_band(band) -> str | int:
    if isinstance(band, str):
        if band in ("auto", "full"):
            return band
        raise ParameterError(f"unknown band {band!r}: expected 'auto', 'full' or a radius in cells (an integer ≥ 1)")
    return check_int(band, "band (radius in cells)", minimum=1)


def _check_field_options(options) -> dict:
    if options is None:
        return {}
    if not isinstance(options, Mapping):
        raise ParameterError(f"field_options must be a mapping of solve_heat_field options, got {reprlib.repr(options)}")
    if "split_pinches" in options:
        raise ParameterError("field_options takes no 'split_pinches': the field's pinch split is the pinch-split "
                             "addition (additions=)")
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


def _safety_at(ws: Workspace, cells: np.ndarray, n_states: int) -> np.ndarray:
    """Fig. 5's penalty s of the poses at flat cells ``cells`` (y * W + x), shape (len(cells), states, 4):
    Σ n_c W_obs(c) / |U|, off-map cells counting as obstacles, as
    :func:`~htetro_opt.problems.heat_costs.heat_fitness` scores them."""
    patterns = [[safety_pattern(s, k) for k in range(N_HEADINGS)] for s in range(n_states)]
    pad = max(int(np.abs(offsets).max()) for row in patterns for offsets, _ in row)
    blocked = np.pad(np.asarray(ws.occupancy, dtype=np.float64), pad, constant_values=1.0)
    y, x = np.divmod(cells, ws.width)
    s = np.empty((len(cells), n_states, N_HEADINGS))
    for state, row in enumerate(patterns):
        for heading, (offsets, weights) in enumerate(row):
            around = blocked[pad + y[:, None] + offsets[None, :, 1], pad + x[:, None] + offsets[None, :, 0]]
            s[:, state, heading] = around @ weights / len(offsets)
    return s


class _Space:
    """The poses one search sees, duck-typed as the simulator :class:`_Graph` reads: the whole
    simulator, or a band of cells with its transitions (pose id = (band cell * states + state) * 4 +
    heading, the band's cells in map order)."""

    def __init__(self, sim, cell_of: np.ndarray, safety: np.ndarray | None, cells: np.ndarray | None = None):
        self.sim = sim
        self.cell_of = cell_of  # flat map cell (y * W + x) of every pose
        self.safety = safety  # s of every pose, or None
        self.cells = cells  # a band's flat cells, sorted; None for the whole simulator

    @classmethod
    def whole(cls, sim: Simulator, with_safety: bool) -> "_Space":
        ws = sim.workspace
        cells = ws.width * ws.height
        safety = None
        if with_safety:  # simulator ids are state-major: ((state * 4 + heading) * H + y) * W + x
            safety = _safety_at(ws, np.arange(cells), sim.n_states).transpose(1, 2, 0).ravel()
        return cls(sim, np.arange(sim.n_poses) % cells, safety)

    @classmethod
    def band(cls, ws: Workspace, cells: np.ndarray, *, ids, n_states: int, tables, durations,
             with_safety: bool) -> "_Space":
        per_cell = n_states * N_HEADINGS
        n, hw = len(cells) * per_cell, ws.width * ws.height
        check_memory(n * len(ids) * (_TABLE_BYTES + _GRAPH_BYTES), f"the heat planner's search band of {len(cells)} "
                     f"cells on this {ws.width} x {ws.height} map", "give a smaller band radius, or a smaller map")
        xy = np.column_stack([cells % ws.width, cells // ws.width])
        target = transitions_at(ws, xy, commands=list(ids), clearance=tables.clearance).reshape(n, len(ids))
        # Global id g = state' * H * W + cell: local = (band index of the cell) * per_cell + state'. In
        # int32 where the ids fit and with few temporaries: this table has 14.7 million entries on a
        # 1000 x 1000 map (band r 8), where each pass over it costs.
        index = np.int32 if per_cell * hw < 2**31 and n < 2**31 else np.int64
        g = target.astype(index)
        del target
        state = g // index(hw)  # -1 for a dead entry
        g -= state * index(hw)  # the target's cell
        first = np.full(hw, n, dtype=index)  # out of the band: n, which the minimum below keeps
        first[cells] = np.arange(0, n, per_cell, dtype=index)
        local = first[g]
        del g
        local += state
        np.minimum(local, n, out=local)
        local[state < 0] = n  # dead
        sim = SimpleNamespace(workspace=ws, tables=tables, command_ids=np.asarray(ids, dtype=np.int64),
                              n_commands=len(ids), n_states=n_states, n_poses=n, dead=n, next=local,
                              durations=np.append(durations, 0.0))
        safety = _safety_at(ws, cells, n_states).ravel() if with_safety else None
        return cls(sim, np.repeat(cells, per_cell), safety, cells)

    def pose_id(self, row) -> int:
        """Id of an (x, y, state, heading) row in this space (-1 if its cell is not in the band)."""
        x, y, s, h = (int(v) for v in row)
        ws = self.sim.workspace
        if self.cells is None:
            return ((s * N_HEADINGS + h) * ws.height + y) * ws.width + x
        i = int(np.searchsorted(self.cells, y * ws.width + x))
        if i == len(self.cells) or self.cells[i] != y * ws.width + x:
            return -1
        return (i * self.sim.n_states + s) * N_HEADINGS + h

    def rows(self, start: int, steps: list[int]) -> np.ndarray:
        """(x, y, state, heading) of the poses after each local command from pose ``start``."""
        nodes = [start]
        for c in steps:
            nodes.append(int(self.sim.next[nodes[-1], c]))
        return self.decode(np.array(nodes[1:], dtype=np.int64))

    def decode(self, nodes: np.ndarray) -> np.ndarray:
        """(x, y, state, heading) rows of pose ids of this space."""
        ws = self.sim.workspace
        flat = self.cell_of[nodes]
        if self.cells is None:  # the simulator's ids: ((state * 4 + heading) * H + y) * W + x
            sh = nodes // (ws.width * ws.height)
        else:
            sh = nodes % (self.sim.n_states * N_HEADINGS)
        return np.stack([flat % ws.width, flat // ws.width, sh // N_HEADINGS, sh % N_HEADINGS], axis=-1)


def _wavefront(matrix, source: int, stop: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, int, int]:
    """Do et al. 2021's reaching waves (Table 4, steps 1–5) over a weighted graph: every node whose
    tentative cost was lowered in one wave (``list``) extends the next (``listNext``). With ``stop`` (the
    goal's nodes) the waves end when one of them enters the list (§V-B step 4, the paper's rule);
    without, when nothing improves (a label-correcting search: Dijkstra's distances). Returns the
    distances, the predecessors, the waves run and the nodes expanded."""
    n = matrix.shape[0]
    dist = np.full(n, np.inf)
    pred = np.full(n, -9999, dtype=np.int64)
    dist[source] = 0.0
    wave = np.array([source])
    indptr, indices, data = matrix.indptr, matrix.indices, matrix.data
    waves = expanded = 0
    while len(wave):
        waves += 1
        expanded += len(wave)
        counts = indptr[wave + 1] - indptr[wave]
        first = np.repeat(indptr[wave] - np.cumsum(counts) + counts, counts)
        edges = first + np.arange(counts.sum())
        u, v = np.repeat(wave, counts), indices[edges]
        reach = dist[u] + data[edges]
        better = reach < dist[v]
        u, v, reach = u[better], v[better], reach[better]
        order = np.lexsort((reach, v))
        keep = order[np.r_[True, v[order][1:] != v[order][:-1]]] if len(order) else order
        dist[v[keep]], pred[v[keep]] = reach[keep], u[keep]
        wave = v[keep]
        if stop is not None and np.isin(stop, wave).any():
            break
    return dist, pred, waves, expanded


class _LegSearch:
    """One leg's search over a space with an additive cost per command, optionally with the last
    command in the state (the surrogate cost). ``engine``: ``"dijkstra"`` or ``"wavefront"`` (to
    convergence), or ``"paper"`` (the waves, stopping when the goal enters the list)."""

    def __init__(self, space: _Space, mask, cost: np.ndarray, change: float, engine: str):
        self.space, self.engine = space, engine
        self.graph = _Graph(space.sim, mask=mask, weights=cost)
        self.change = change
        self.waves = self.expanded = None
        sim = space.sim
        kinds = [COMMANDS[int(g)].kind for g in sim.command_ids]
        self.repeatable = np.array([k != "shapeshift" for k in kinds])
        self.layers = 1 + int(self.repeatable.sum()) if change > 0 else 1
        self.layer_of = np.zeros(sim.n_commands, dtype=np.int64)
        self.layer_of[self.repeatable] = np.arange(1, self.repeatable.sum() + 1)

    def _matrix(self):
        g = self.graph
        if self.layers == 1:
            # _Graph.matrix()'s CSR for a static map, built in place: the table's own index type and no
            # concatenated copies. On the 1000 x 1000 band (12 million edges) that build spends ~1 s
            # in page faults of its int64 temporaries; this one 0.04 s (measured, same matrix).
            n = g.sim.n_poses
            usable = g.usable
            weights = (np.broadcast_to(g.sim.durations[: g.sim.n_commands], usable.shape) if g.weights is None
                       else g.weights)
            counts = usable.sum(axis=1, dtype=np.int64)
            index = np.int32 if counts.sum() < 2**31 and n < 2**31 else np.int64
            indptr = np.zeros(n + 1, dtype=index)
            np.cumsum(counts, out=indptr[1:])
            return csr_matrix((weights[usable], g.target[usable].astype(index, copy=False), indptr), shape=(n, n))
        n = g.sim.n_poses
        u, c = np.nonzero(g.usable)
        v = g.target[u, c].astype(np.int64)
        w = g.weights[u, c]
        layer = self.layer_of[c]
        repeat = layer > 0
        rows = [u, layer[repeat] * n + u[repeat], np.arange(n, n * self.layers)]
        cols = [layer * n + v, layer[repeat] * n + v[repeat], np.tile(np.arange(n), self.layers - 1)]
        data = [w + self.change, w[repeat], np.zeros(n * (self.layers - 1))]
        return coo_matrix((np.concatenate(data), (np.concatenate(rows), np.concatenate(cols))),
                          shape=(n * self.layers, n * self.layers)).tocsr()

    def run(self, start: int, goal: int) -> tuple[list[int], float] | None:
        """Local commands of the optimum start → goal and its cost J, or None."""
        matrix = self._matrix()
        n = self.graph.sim.n_poses
        ends = goal + n * np.arange(self.layers)
        if self.engine == "dijkstra":
            dist, pred = dijkstra(matrix, indices=start, return_predecessors=True)
        else:
            dist, pred, self.waves, self.expanded = _wavefront(matrix, start,
                                                               ends if self.engine == "paper" else None)
        end = int(ends[np.argmin(dist[ends])])
        if not np.isfinite(dist[end]):
            return None
        nodes = [end]
        while nodes[-1] != start:
            nodes.append(int(pred[nodes[-1]]))
        nodes.reverse()
        column_of = np.flatnonzero(self.repeatable)  # layer k's command is column_of[k - 1]
        steps = []
        for a, b in zip(nodes[:-1], nodes[1:]):
            (la, pa), (lb, pb) = divmod(a, n), divmod(b, n)
            if lb == 0 and la > 0:  # a layer into the hub, at the same pose: no command
                continue
            # into layer k the command is k's (a repeat, or a change from the hub); hub to hub, a shapeshift
            steps.append(int(column_of[lb - 1]) if lb > 0 else self.graph.step_command(pa, pb, 0))
        return steps, float(dist[end])


class _TentativeSearch:
    """The paper's reaching process (§V-B, steps 1–5) with its tentative cost: every pose keeps one
    tentative cost f and one ``prev`` link, and the cost of V through U is ``f(U) + f(U, V)``, where
    f(U, V) is eq. 12's cost of the one command U → V: ``[w_t t / t_max + w_sm d + w_sf s(V)] / Σw``
    (eq. 9's time, eq. 10's change d = 1 when the command differs from the last one of U's tentative
    path, eq. 11's safety penalty of the pose it reaches, each as the term of a one-command path).
    Every pose of the current list tries each command allowed under the field's rule; a lower cost is
    assigned (ties keep the first) and the pose enters the next list. With ``stop`` the process ends
    when the goal enters the list (step 4); without, when the list is empty (ours: ``converge``).

    Our readings, where the paper is silent: the state is the pose (x, y, shape, heading), not B2's
    cell, and G is the goal pose; "f(U) + f(U, V)" is a sum over the commands, so eqs. 10 and 11 are
    not divided by the path's length (the search cannot know it); d is taken against the last command
    of U's tentative path (one label per pose, as the paper keeps one cost per cell). The costs are
    never negative and a reassignment is strict, so the ``prev`` links never close a cycle.
    """

    def __init__(self, space: _Space, mask, weights, t_max: float, stop: bool):
        sim = space.sim
        n, c = sim.n_poses, sim.n_commands
        self.space, self.stop = space, stop
        self.target = sim.next[:n, :c].astype(np.int64)
        usable = (self.target != sim.dead) & (self.target != np.arange(n)[:, None])
        self.usable = usable if mask is None else usable & mask
        self.durations = np.asarray(sim.durations[:c], dtype=np.float64) / t_max
        self.weights = np.asarray(weights, dtype=np.float64) / float(np.sum(weights))
        self.waves = self.expanded = 0

    def run(self, start: int, goal: int) -> tuple[list[int], float] | None:
        """Local commands of the path traced back from the goal and the goal's tentative cost, or None."""
        n = self.space.sim.n_poses
        w_t, w_sm, w_sf = self.weights
        safety = self.space.safety if w_sf > 0 else None
        cost = np.full(n, np.inf)
        cost[start] = 0.0
        last = np.full(n, -1, dtype=np.int64)  # the command into the pose on its tentative path (local id)
        pred = np.full(n, -1, dtype=np.int64)
        wave = np.array([start])
        while len(wave):
            self.waves += 1
            self.expanded += len(wave)
            rows, k = np.nonzero(self.usable[wave])
            u = wave[rows]
            v = self.target[u, k]
            step = w_t * self.durations[k] + w_sm * ((last[u] >= 0) & (last[u] != k))
            if safety is not None:
                step = step + w_sf * safety[v]
            tentative = cost[u] + step
            better = tentative < cost[v]
            u, v, k, tentative = u[better], v[better], k[better], tentative[better]
            order = np.lexsort((tentative, v))
            keep = order[np.r_[True, v[order][1:] != v[order][:-1]]] if len(order) else order
            v = v[keep]
            cost[v], last[v], pred[v] = tentative[keep], k[keep], u[keep]
            wave = v
            if self.stop and goal in wave:
                break
        if not np.isfinite(cost[goal]):
            return None
        nodes = [goal]
        while nodes[-1] != start:
            nodes.append(int(pred[nodes[-1]]))
            if len(nodes) > n:
                raise PlanningError("internal error: the heat planner's prev links form a cycle")
        nodes.reverse()
        return [int(last[b]) for b in nodes[1:]], float(cost[goal])


def _ascent_line(field, start: tuple[int, int], goal: tuple[int, int], free: np.ndarray) -> np.ndarray | None:
    """Cells along the field's steepest-ascent line from the start's cell to the goal's: over the grid
    nodes (q1), or over the cells without cutting an obstacle corner (p0). None on a stall (a
    plateau the tolerance cannot order)."""
    h, w = free.shape
    if field.corners is not None:
        # A node's value: the largest of its elements' values (split pinch nodes have one per cell).
        values = np.full((h + 1, w + 1), -np.inf)
        for j in (0, 1):
            for i in (0, 1):
                c = np.where(np.isnan(field.corners[:, :, j, i]), -np.inf, field.corners[:, :, j, i])
                values[j: j + h, i: i + w] = np.maximum(values[j: j + h, i: i + w], c)
        gx, gy = goal
        node = min(((start[0] + i, start[1] + j) for j in (0, 1) for i in (0, 1)), key=lambda p: values[p[1], p[0]])
        path = [node]
        goal_nodes = {(gx + i, gy + j) for j in (0, 1) for i in (0, 1)}
        while path[-1] not in goal_nodes:
            x, y = path[-1]
            best, best_value = None, values[y, x]
            for dx in (-1, 0, 1):
                for dy in (-1, 0, 1):
                    nx, ny = x + dx, y + dy
                    if (dx, dy) == (0, 0) or not (0 <= nx <= w and 0 <= ny <= h):
                        continue
                    # the move runs inside a conducting cell: the diagonal's cell, or one beside the edge
                    cells = ([(min(x, nx), min(y, ny))] if dx and dy else
                             [(min(x, nx), y - 1), (min(x, nx), y)] if dx else [(x - 1, min(y, ny)), (x, min(y, ny))])
                    if not any(0 <= cx < w and 0 <= cy < h and np.isfinite(field.cells[cy, cx]) for cx, cy in cells):
                        continue
                    if values[ny, nx] > best_value:
                        best, best_value = (nx, ny), values[ny, nx]
            if best is None:
                return None
            path.append(best)
        nodes = np.array(path)
        line = np.zeros((h, w), dtype=bool)
        for j in (0, 1):
            for i in (0, 1):
                cx, cy = nodes[:, 0] - i, nodes[:, 1] - j
                inside = (cx >= 0) & (cx < w) & (cy >= 0) & (cy < h)
                line[cy[inside], cx[inside]] = True
        return line & free
    t = np.where(np.isnan(field.cells), -np.inf, field.cells)
    path = [tuple(start)]
    while path[-1] != tuple(goal):
        x, y = path[-1]
        best, best_value = None, t[y, x]
        for dx in (-1, 0, 1):
            for dy in (-1, 0, 1):
                nx, ny = x + dx, y + dy
                if (dx, dy) == (0, 0) or not (0 <= nx < w and 0 <= ny < h) or not free[ny, nx]:
                    continue
                if dx and dy and not (free[y, nx] and free[ny, x]):
                    continue
                if t[ny, nx] > best_value:
                    best, best_value = (nx, ny), t[ny, nx]
        if best is None:
            return None
        path.append(best)
    line = np.zeros((h, w), dtype=bool)
    xy = np.array(path)
    line[xy[:, 1], xy[:, 0]] = True
    return line


def _distance_line(ws: Workspace, start: tuple[int, int], goal: tuple[int, int]) -> np.ndarray | None:
    """Cells of a shortest 8-connected cell path start → goal (``grid_distance``), None if none."""
    distance = grid_distance(ws, goal, diagonals=True)
    if not np.isfinite(distance[start[1], start[0]]):
        return None
    h, w = distance.shape
    padded = np.pad(distance, 1, constant_values=np.inf)
    line = np.zeros((h, w), dtype=bool)
    x, y = start
    line[y, x] = True
    while (x, y) != tuple(goal):
        around = padded[y: y + 3, x: x + 3]
        dy, dx = np.unravel_index(np.argmin(around), (3, 3))
        x, y = x + int(dx) - 1, y + int(dy) - 1
        line[y, x] = True
    return line


def plan_heat(
    workspace: Workspace | Simulator,
    roadmap: Sequence[Pose],
    *,
    method: str = "heat",
    additions=None,
    weights=_DEFAULTS["weights"],
    t_max: float | None = None,
    element: str = _DEFAULTS["element"],
    monotone: bool = _DEFAULTS["monotone"],
    band: str | int = _DEFAULTS["band"],
    band_seed: str = _DEFAULTS["band_seed"],
    engine: str = _DEFAULTS["engine"],
    commands: Sequence[str] | None = None,
    timing: Timing | None = None,
    clearance: float = _DEFAULTS["clearance"],
    field_options: Mapping | None = None,
    keep_fields: bool = _DEFAULTS["keep_fields"],
) -> Plan:
    """Do et al. 2021's heat-conduction plan through a roadmap: climb each leg's temperature field.

    Parameters
    ----------
    workspace : Workspace or Simulator
        A static map, or an already compiled simulator (then ``commands``, ``timing`` and
        ``clearance`` are its own, and the whole graph is searched).
    roadmap : sequence of Pose
        Start first, goal last, at least two configurations.
    method : {"heat", "heat-paper"}, keyword-only
        The plan's method name, and the default of ``additions``: all of
        :data:`~htetro_opt.solvers.grid_paths.HEAT_ADDITIONS` for ``"heat"``, none for ``"heat-paper"``.
    additions : collection of str, optional, keyword-only
        Our additions switched on, exactly (names of ``HEAT_ADDITIONS``; ``()`` is the paper's
        algorithm). Listed in the plan's ``additions``.
    weights : sequence of 3 float, keyword-only
        (w_t, w_sm, w_sf) of eq. 12: finite, ≥ 0, not all zero.
    t_max : float, optional, keyword-only
        Eq. 9's time budget (default :func:`~htetro_opt.problems.heat_costs.default_t_max`).
    element : {"q1", "p0"}, keyword-only
        The field's element (:func:`~htetro_opt.solvers.grid_paths.solve_heat_field`).
    monotone : bool, keyword-only
        Allow only translations to equal or higher temperature (the paper's rule); False searches
        without the field (the same costs, unconstrained: an ablation).
    band : "auto", "full" or int, keyword-only
        With the ``band`` addition: search the whole pose graph (``"full"``), or a band of that
        Chebyshev radius (cells) around the field's ascent line, doubled until a path is found;
        ``"auto"``: full up to :data:`BAND_AUTO_POSES` poses, else radius :data:`BAND_AUTO_RADIUS`.
        Without it the whole graph is searched.
    band_seed : {"ascent", "grid_distance"}, keyword-only
        The line a band follows: the field's steepest ascent (the paper's guidance), or a shortest
        8-connected cell path that ignores the field (an ablation: what the field buys).
    engine : {"dijkstra", "wavefront"}, keyword-only
        With the ``converge`` addition and the surrogate cost: scipy's Dijkstra, or the paper's reaching
        waves relaxed to convergence (slower; same optimum). Without ``converge`` the waves stop when
        the goal enters the list, whatever this says.
    commands : sequence of str, optional, keyword-only
        Command tokens (default: Do et al. 2021's 17, Cheng et al. 2020's set plus the diagonals).
    timing : Timing, optional, keyword-only
    clearance : float, keyword-only
        δ in cells (MODEL.md §4).
    field_options : mapping, optional, keyword-only
        More options of ``solve_heat_field``: ``k_obstacle``, ``solver``, ``tol`` (the mesh's pinch
        split is the ``pinch-split`` addition).
    keep_fields : bool, keyword-only
        Also keep each leg's :class:`~htetro_opt.solvers.grid_paths.HeatField` in ``info["fields"]``
        (for plots; not JSON).

    Returns
    -------
    Plan
        Method ``method``; ``reached`` is False (not an exception) when a leg has no path: with
        ``relax-fallback`` off, also when no path climbs the field (the paper's "G cannot be reached").
        ``info`` (JSON-ready but for ``fields``): ``additions``, ``weights``, ``t_max``, and per solved
        leg ``relaxed`` (no monotone path: the unconstrained one taken), ``surrogate`` (the cost the
        search minimised: J, or the paper's tentative 1 − f), ``length`` (the L of J, None under the
        paper's cost), ``pick`` (the weights whose search gave the leg's plan), ``waves`` and
        ``expanded`` (the reaching waves run and the poses they expanded, None for Dijkstra),
        ``band`` (``radius`` (None = whole graph), ``cells``, ``seed``: ``"ascent"``,
        ``"grid_distance"`` or None); per leg ``field`` (``element``, ``dofs``, ``pinches``,
        ``solver``, ``iterations``, ``seconds``); ``fitness``
        (:func:`~htetro_opt.problems.heat_costs.heat_fitness` of the whole plan: ``f_t``, ``f_sm``,
        ``f_sf``, ``f``).

    Raises
    ------
    ParameterError
        On bad weights, t_max, element, band, engine, additions, field options or commands (Cheng et
        al. 2019's block commands are refused), or a map with moving obstacles (static maps only).
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
    >>> paper = plan_heat(ws, [Pose(1, 1, "O", 0), Pose(3, 3, "O", 0)], method="heat-paper")
    >>> paper.method, paper.additions, paper.tokens, paper.info["waves"]
    ('heat-paper', (), ['x+y+', 'x+y+'], [2])
    """
    if method not in ("heat", "heat-paper"):
        raise ParameterError(f"method must be 'heat' or 'heat-paper', got {method!r}")
    on = set(_check_additions(additions if additions is not None else
                              (tuple(HEAT_ADDITIONS) if method == "heat" else ()), "additions"))
    w = check_heat_weights(weights)
    monotone = check_bool(monotone, "monotone")
    keep_fields = check_bool(keep_fields, "keep_fields")
    band = _check_band(band)
    if not isinstance(band_seed, str) or band_seed not in BAND_SEEDS:
        raise ParameterError(f"unknown band_seed {band_seed!r}: expected one of {', '.join(BAND_SEEDS)}")
    if not isinstance(element, str) or element not in HEAT_ELEMENTS:
        raise ParameterError(f"unknown element {element!r}: expected one of {', '.join(HEAT_ELEMENTS)}")
    if not isinstance(engine, str) or engine not in HEAT_ENGINES:
        raise ParameterError(f"unknown engine {engine!r}: expected one of {', '.join(HEAT_ENGINES)}")
    options = _check_field_options(field_options)
    check_map(workspace)
    roadmap = check_roadmap(roadmap)
    compiled = isinstance(workspace, Simulator)
    ws = workspace.workspace if compiled else workspace
    if ws.moving:
        raise ParameterError("the heat planner plans on static maps only: use dijkstra with moving obstacles")
    ids_set = _command_ids(workspace, commands)
    if not compiled and timing is not None and not isinstance(timing, Timing):
        raise ParameterError(f"timing must be a Timing or None, got {type(timing).__name__} {reprlib.repr(timing)}")
    timing = workspace.timing if compiled else (timing or Timing())
    t_max = (default_t_max(ws, timing) if t_max is None
             else check_real(t_max, "t_max", minimum=0.0, include_minimum=False))
    n_poses, _ = table_shape(ws, commands=list(ids_set))
    whole = (compiled or "band" not in on or band == "full"
             or (band == "auto" and n_poses <= BAND_AUTO_POSES))
    radius = None if whole else (BAND_AUTO_RADIUS if band == "auto" else band)
    surrogate_cost, converge, pick = "surrogate-cost" in on, "converge" in on, "exact-pick" in on
    relax = "relax-fallback" in on
    leg_engine = engine if converge else "paper"
    # a converged time-only surrogate search is the fastest plan under the rule: no other row's plan can
    # have a higher f = f_t, so the pick would only repeat it
    exact_time = surrogate_cost and converge and w[1] == 0 and w[2] == 0
    with_safety = w[2] > 0 or (pick and not exact_time)
    began = _time.perf_counter()
    if whole:
        if not compiled:
            _check_memory(workspace, "dijkstra", list(ids_set), False)
        sim, roadmap, ids = prepare(workspace, roadmap, commands=list(ids_set), timing=timing, clearance=clearance)
        space = _Space.whole(sim, with_safety)
        rows = [sim.decode(i) for i in ids]
    else:
        tables = sweep_tables(check_real(clearance, "clearance", minimum=0.0))
        n_states = n_poses // (N_HEADINGS * ws.width * ws.height)
        rows = [_pose_row(ws, pose, _pose_name(i, len(roadmap)), n_states, tables) for i, pose in enumerate(roadmap)]
        band_options = dict(ids=ids_set, n_states=n_states, tables=tables, with_safety=with_safety,
                            durations=timing.durations()[list(ids_set)])

    def weighted(space: _Space, a: int, b: int, mask, weights) -> _Found | None:
        """The leg's search under one weighting: the surrogate J (ours) or the paper's tentative cost."""
        sim = space.sim
        n, c = sim.n_poses, sim.n_commands
        if not surrogate_cost:
            searcher = _TentativeSearch(space, mask, weights, t_max, stop=not converge)
            found = searcher.run(a, b)
            return None if found is None else _Found(*found, None, searcher.waves, searcher.expanded, weights)
        target = sim.next[:n, :c]
        # Per-command costs stay (c,) rows broadcast over the poses until a per-pose term enters: an
        # (n, c) array is 14.7 million entries on a 1000 x 1000 band
        time_cost = sim.durations[:c] / t_max
        tie = _TIE_BREAK * time_cost
        timer = _LegSearch(space, mask, np.broadcast_to(time_cost + tie, (n, c)), 0.0, leg_engine)
        timed = timer.run(a, b)
        if timed is None or (weights[1] == 0 and weights[2] == 0):
            return None if timed is None else _Found(*timed, len(timed[0]), timer.waves, timer.expanded, weights)
        length = max(len(timed[0]), 1)
        total = sum(weights)
        cost = np.broadcast_to(weights[0] * time_cost / total + tie, (n, c))
        if weights[2] > 0:
            cost = cost + weights[2] * space.safety[np.minimum(target, n - 1)] / (length * total)
        searcher = _LegSearch(space, mask, cost, weights[1] / (length * total), leg_engine)
        steps, value = searcher.run(a, b)
        return _Found(steps, value, length, searcher.waves, searcher.expanded, weights)

    def search(space: _Space, a: int, b: int, field) -> _Found | None:
        """The leg's plan in ``space`` under the field's rule if ``field``: the asked weighting's search,
        or with ``exact-pick`` the best by eqs. 9–12 of it and Table 6's four weightings' searches."""
        sim = space.sim
        mask = None
        if field is not None:
            n, c = sim.n_poses, sim.n_commands
            target = sim.next[:n, :c]
            moves = np.array([COMMANDS[int(g)].kind in _MOVES for g in sim.command_ids])
            here = field.cells.ravel()[space.cell_of]  # the temperature of every pose's B2 cell
            there = here[np.minimum(target, n - 1)]  # dead targets: masked by the graph
            mask = ~moves[None, :] | (there >= here[:, None] - field.epsilon)
        own = weighted(space, a, b, mask, w)
        if not pick or own is None or exact_time:
            return own
        best, best_f = own, None
        for weights in (w, *[t for t in TABLE6_WEIGHTS if not _same_weights(t, w)]):
            found = own if weights is w else weighted(space, a, b, mask, weights)
            if found is None:
                continue
            poses = np.vstack([space.decode(np.array([a])), space.rows(a, found.steps)])
            global_ids = np.asarray([int(sim.command_ids[s]) for s in found.steps], dtype=np.int64)
            f = heat_fitness(ws, poses.reshape(-1, 4), global_ids, t_max=t_max, timing=timing, weights=w)["f"]
            if best_f is None or f > best_f + 1e-12:
                best, best_f = found, f
        return best

    commands_out: list[int] = []
    poses_out = [np.asarray(rows[0], dtype=np.int64)[None]]
    leg_ends: list[int] = []
    per_leg: dict[str, list] = {key: [] for key in ("relaxed", "surrogate", "length", "pick", "waves", "expanded")}
    bands: list[dict] = []
    records: list[dict] = []
    fields = []
    failed = -1
    for leg in range(len(roadmap) - 1):
        a_row, b_row = np.asarray(rows[leg]), np.asarray(rows[leg + 1])
        record = {"element": element, "dofs": 0, "pinches": 0, "solver": None, "iterations": 0, "seconds": 0.0}
        field = None
        if (a_row != b_row).any() and monotone:
            field = solve_heat_field(ws, (int(b_row[0]), int(b_row[1])), (int(a_row[0]), int(a_row[1])),
                                     element=element, split_pinches="pinch-split" in on, **options)
            record.update({key: field.info.get(key) for key in record if key != "element"})
            fields.append(field)
        records.append(record)
        rule = field if monotone and field is not None and field.connected else None
        if (a_row == b_row).all():
            found = _LegPlan([], 0.0, 0, False, np.empty((0, 4), dtype=np.int64), None, 0, 0)
            leg_band = {"radius": radius, "cells": 0, "seed": None}
        elif whole:
            found = _relaxed(search, space, space.pose_id(a_row), space.pose_id(b_row), rule, monotone, relax)
            leg_band = {"radius": None, "cells": ws.width * ws.height, "seed": None}
        else:
            found, leg_band = _band_search(search, ws, a_row, b_row, field, rule, monotone, radius, band_seed,
                                           band_options, relax)
        bands.append(leg_band)
        if found is None:
            failed = leg
            break
        for key in per_leg:
            per_leg[key].append(getattr(found, key))
        commands_out.extend(found.commands)
        poses_out.append(found.rows)
        leg_ends.append(len(commands_out))
    per_leg["pick"] = [None if p is None else [float(v) for v in p] for p in per_leg["pick"]]
    info = {"additions": [a for a in HEAT_ADDITIONS if a in on], "weights": list(w), "t_max": float(t_max),
            **per_leg, "band": bands, "field": records}
    if keep_fields:
        info["fields"] = fields
    global_ids = np.array(commands_out, dtype=np.int64)
    if whole:
        plan = finish_plan(sim, global_ids, ids[0], method=method, leg_ends=leg_ends, failed_leg=failed,
                           began=began, info=info)
    else:
        plan = _finish_band_plan(ws, global_ids, np.concatenate(poses_out), ids_set, tables, timing,
                                 leg_ends=leg_ends, failed=failed, began=began, info=info, method=method)
    fitness = heat_fitness(ws, plan.poses, plan.commands, t_max=t_max, timing=timing, weights=w)
    return replace(plan, info={**plan.info, "fitness": fitness})


_check_additions = additions_check(HEAT_ADDITIONS)


def _same_weights(a, b) -> bool:
    """Two weightings of eq. 12 that give the same cost (one a positive multiple of the other)."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    return bool(np.allclose(a / a.sum(), b / b.sum()))


class _Found(NamedTuple):
    steps: list[int]  # local commands
    surrogate: float  # the cost the search minimised
    length: int | None  # the L of J's smoothness and safety terms; None under the paper's cost
    waves: int | None  # reaching waves run (None for Dijkstra)
    expanded: int | None  # poses expanded by them
    pick: tuple  # the weights of the search that found it


class _LegPlan(NamedTuple):
    commands: list[int]  # global command ids
    surrogate: float  # the cost minimised
    length: int | None  # the L of J's smoothness and safety terms
    relaxed: bool
    rows: np.ndarray  # (x, y, state, heading) after each command
    pick: tuple | None
    waves: int | None
    expanded: int | None


def _leg_plan(space: _Space, a: int, found: _Found, relaxed: bool) -> _LegPlan:
    return _LegPlan([int(space.sim.command_ids[s]) for s in found.steps], found.surrogate, found.length, relaxed,
                    space.rows(a, found.steps), found.pick, found.waves, found.expanded)


def _relaxed(search, space: _Space, a: int, b: int, rule, monotone: bool, relax: bool) -> _LegPlan | None:
    """The leg under the field's rule; with ``relax`` (ours), else unconstrained (flagged relaxed when the
    rule was asked for). Without the rule asked (``monotone`` False), unconstrained."""
    found = search(space, a, b, rule) if rule is not None else None
    leg_relaxed = False
    if found is None and (relax or not monotone):
        found, leg_relaxed = search(space, a, b, None), monotone
    return None if found is None else _leg_plan(space, a, found, leg_relaxed)


def _pose_name(i: int, n: int) -> str:
    return "start" if i == 0 else "goal" if i == n - 1 else f"roadmap configuration {i + 1}"


def _pose_row(ws: Workspace, pose, what: str, n_states: int, tables) -> np.ndarray:
    """(x, y, state, heading) of a roadmap pose, checked as ``Simulator.check_pose`` checks it,
    without the simulator's whole table."""
    pose = as_pose(pose, what)
    s = shape_index(pose.shape)
    if s >= n_states:
        raise ConfigurationError(f"{what} {tuple(pose)}: state {pose.shape!r} is an intermediate state, which the "
                                 "heat planner's commands cannot reach")
    if not ws.contains(pose.x, pose.y):
        raise ConfigurationError(f"{what} {tuple(pose)}: pose ({pose.x}, {pose.y}) lies outside the "
                                 f"{ws.width} x {ws.height} map")
    footprint = tables.cells(s, pose.heading, command_id("stop")) + np.array([pose.x, pose.y])
    inside = ((footprint >= 0) & (footprint < np.array([ws.width, ws.height]))).all(axis=1)
    conflicts = [(int(x), int(y)) for (x, y), ok in zip(footprint, inside) if not ok or ws.occupancy[y, x]]
    if conflicts:
        margin = f" (with clearance {tables.clearance:g})" if tables.clearance else ""
        raise ConfigurationError(f"{what} {tuple(pose)}{margin} collides with obstacles or the map edge at "
                                 f"{describe_cells(conflicts)}")
    return np.array([pose.x, pose.y, s, pose.heading], dtype=np.int64)


def _band_search(search, ws: Workspace, a_row, b_row, field, rule, monotone: bool, radius: int, band_seed: str,
                 options: dict, relax: bool):
    """A leg searched in widening bands around the field's ascent line (or the grid_distance path)."""
    free = ~ws.occupancy
    a_cell, b_cell = (int(a_row[0]), int(a_row[1])), (int(b_row[0]), int(b_row[1]))
    line, seed = None, None
    if rule is not None and band_seed == "ascent":
        line, seed = _ascent_line(field, a_cell, b_cell, free), "ascent"
    if line is None:
        line, seed = _distance_line(ws, a_cell, b_cell), "grid_distance"
    if line is None:  # not even 8-connected: no robot passes
        return None, {"radius": radius, "cells": 0, "seed": None}
    r, n_free = radius, int(free.sum())
    unconstrained = relax or not monotone  # the search without the field's rule is asked for, or a rescue
    while True:
        inside = maximum_filter(line, size=2 * r + 1, mode="constant", cval=False) & free
        cells = np.flatnonzero(inside.ravel())
        space = _Space.band(ws, cells, **options)
        record = {"radius": r, "cells": len(cells), "seed": seed}
        a, b = space.pose_id(a_row), space.pose_id(b_row)
        found = search(space, a, b, rule) if rule is not None else None
        if found is not None:
            return _leg_plan(space, a, found, False), record
        if unconstrained and (len(cells) == n_free or rule is None):  # the whole map, or no rule to widen for
            found = search(space, a, b, None)
            if found is not None or len(cells) == n_free:
                return (None if found is None else _leg_plan(space, a, found, monotone)), record
        if len(cells) == n_free:
            return None, record
        r *= 2


def _finish_band_plan(ws: Workspace, commands: np.ndarray, rows: np.ndarray, ids, tables, timing, *,
                      leg_ends, failed: int, began: float, info: dict, method: str = "heat") -> Plan:
    """Re-validate a band plan step by step through :func:`~htetro_opt.model.simulate.transitions_at`
    (the map is too large for the simulator's whole table) and wrap it as a :class:`Plan`."""
    ids = list(ids)
    if len(commands):
        lookup = np.full(len(COMMANDS), -1, dtype=np.int64)
        lookup[ids] = np.arange(len(ids))
        local = lookup[commands]
        table = transitions_at(ws, rows[:-1, :2], commands=ids, clearance=tables.clearance)
        reached_ids = table[np.arange(len(commands)), rows[:-1, 2], rows[:-1, 3], local]
        claimed = ((rows[1:, 2] * N_HEADINGS + rows[1:, 3]) * ws.height + rows[1:, 1]) * ws.width + rows[1:, 0]
        wrong = np.flatnonzero(reached_ids != claimed)
        if len(wrong):
            raise PlanningError(f"internal error: the heat plan does not re-validate (command {int(wrong[0]) + 1} "
                                f"of {len(commands)} is invalid)")
    return Plan(method=method, commands=commands, reached=failed < 0,
                time=float(timing.durations()[commands].sum()), poses=rows, leg_ends=tuple(leg_ends),
                failed_leg=int(failed), runtime_s=_time.perf_counter() - began, info=dict(info))
