"""Windowed exact re-planning (ours, optional): a window of a path replaced by the fastest way between its ends.

A memetic step that generalises the shortcut (:mod:`.shortcut` cuts a window whose two end poses are
equal; here they may differ): a window of up to W executed commands is replaced by the minimum-time
command sequence between the poses before and after it, found on the simulator's transition table
by an A* towards the window's end, bounded by the window's own time so that it stays local. With
moving obstacles the search is time-expanded (the obstacles' clock is the number of commands
executed, as in the simulator), so the new window is valid at the times it runs.

The *reach repair* (:func:`reach_repair`) is the same search with the goal as the window's end: a
chromosome that does not reach keeps its executed commands up to the pose from which the goal is
nearest in time, and the minimum-time path from there (at its time) to the goal replaces the rest.
"""

from __future__ import annotations

import weakref

import numpy as np
from pymoo.core.mutation import Mutation
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import dijkstra

from htetro_opt._jit import lazy_jit
from htetro_opt._validation import check_bool, check_int, check_probability
from htetro_opt.errors import PlanningError
from htetro_opt.model.simulate import Simulator
from htetro_opt.operators.commands._chromosome import as_column, sequences

__all__ = ["CommandReachRepair", "CommandReplan", "TransitionGraph", "reach_repair", "replan_rows", "replan_windows"]

_TOLERANCE = 1e-9  # times are sums of float durations: an equal time is not an improvement
_ANSWERS = 1 << 14  # searches :meth:`TransitionGraph.fastest` remembers (a few hundred bytes each)


def _before(key_a, changes_a, time_a, a, key_b, changes_b, time_b, b):
    """Whether pose ``a`` (time + heuristic ``key_a``, ``changes_a`` command changes, time ``time_a``)
    leaves the heap before pose ``b``: the smaller time + heuristic first, then the fewer command
    changes, then the larger time (of equally promising poses the one nearer the goal, which ends
    the search sooner), then the smaller id. A total order, so the search is deterministic (and
    any correct heap pops the poses in the same order)."""
    if key_a != key_b:
        return key_a < key_b
    if changes_a != changes_b:
        return changes_a < changes_b
    if time_a != time_b:
        return time_a > time_b
    return a < b


def _sift_up(heap, heap_key, heap_changes, heap_time, position, i, node, key, changes, time):
    """Put pose ``node`` with its key (``key``, ``changes``, ``time``) in heap slot ``i`` or above: a
    new entry (``i`` the slot after the last) or one whose key has just been lowered (``i`` its slot)."""
    while i > 0:
        up = (i - 1) >> 1
        if not _before(key, changes, time, node, heap_key[up], heap_changes[up], heap_time[up], heap[up]):
            break
        heap[i], heap_key[i], heap_changes[i], heap_time[i] = heap[up], heap_key[up], heap_changes[up], heap_time[up]
        position[heap[i]] = i
        i = up
    heap[i], heap_key[i], heap_changes[i], heap_time[i] = node, key, changes, time
    position[node] = i


def _pop(heap, heap_key, heap_changes, heap_time, position, size):
    """Remove the heap's first entry (read before the call); the new size.

    Bottom-up (Floyd): the hole left at the top goes down to a leaf, filled at each level by the
    child that comes first, and the last entry then goes up from that leaf; the last entry usually
    belongs near the leaves, so this takes about one comparison a level where sifting it down from
    the top takes two."""
    position[heap[0]] = -1
    size -= 1
    if size == 0:
        return 0
    i = 0
    while True:
        child = 2 * i + 1
        if child >= size:
            break
        right = child + 1
        if right < size and _before(heap_key[right], heap_changes[right], heap_time[right], heap[right],
                                    heap_key[child], heap_changes[child], heap_time[child], heap[child]):
            child = right
        heap[i], heap_key[i], heap_changes[i], heap_time[i] = (heap[child], heap_key[child], heap_changes[child],
                                                               heap_time[child])
        position[heap[i]] = i
        i = child
    _sift_up(heap, heap_key, heap_changes, heap_time, position, i, heap[size], heap_key[size], heap_changes[size],
             heap_time[size])
    return size


# compiled on first use, with the heap functions it calls: importing the operators does not import numba
@lazy_jit(calls=("_before", "_sift_up", "_pop"))
def _astar(indptr, indices, weights, tails, commands, source, target, bound, pose_x, pose_y, pose_turn, cell_time,
           turn_time, best, changes, parent, position, heap, heap_key, heap_changes, heap_time, touched, path):
    """A* from ``source`` to ``target`` over the CSR graph (``indptr``, ``indices``, ``weights``;
    ``tails`` the row of each edge, ``commands`` its command), poses whose time plus heuristic
    exceeds ``bound`` pruned.

    A pose's label is (time, command changes on the way): the fastest, and of equally fast ways
    the one with the fewest changes between consecutive commands (the hTetro-GA's smoothness
    fitness counts them), compared lexicographically. Labels are per pose, not per (pose, last
    command), so the changes are those of a good path among the fastest, not always the fewest.
    The heuristic of pose p is the grid distance of its cell (``pose_x[p]``, ``pose_y[p]``) to the
    target's × ``cell_time`` plus ``turn_time[target's orientation, orientation]`` (``pose_turn[p]``;
    see :meth:`TransitionGraph._heuristic`): consistent, so a pose is expanded once, with its best
    label (a pose whose label improves after its expansion, which only rounding could cause, goes
    back on the heap, so the search stays exact for a heuristic that is only admissible). The heap
    is binary and indexed (``heap``, ``position``: a pose is on it once, its key lowered in place)
    and keeps each entry's key in the entry's own slot (``heap_key``, ``heap_changes``,
    ``heap_time``) rather than reading it through the pose id: comparing keys is most of the
    search's work (on three_slit's searches a pop and its pushes compared 22 keys through the pose
    ids, 42 % of them tied on time + heuristic, so reading the changes and time as well; now 15,
    with the bottom-up pop of :func:`_pop`). The order is total, so any correct heap pops the poses
    in the same order: the paths are those of the heap that read the keys through the poses.
    ``best`` (all inf) and ``position`` (all -1) are per-pose arrays left as they were found;
    ``changes``, ``parent``, ``touched`` and ``path`` are per-pose scratch, the heap's arrays
    per-slot scratch. Returns the optimum time (inf if none within ``bound``) and the number of
    edges of the path, whose CSR edge indices are in ``path[:count]``, from the target back.
    """
    tx, ty, t_turn = pose_x[target], pose_y[target], pose_turn[target]
    best[source], changes[source], parent[source] = 0.0, 0, -1
    heap[0], heap_changes[0], heap_time[0] = source, 0, 0.0
    heap_key[0] = ((abs(pose_x[source] - tx) + abs(pose_y[source] - ty)) * cell_time
                   + turn_time[t_turn, pose_turn[source]])
    position[source] = 0
    touched[0] = source
    size, n_touched, found = 1, 1, np.inf
    while size:
        node = heap[0]
        size = _pop(heap, heap_key, heap_changes, heap_time, position, size)
        if node == target:
            found = best[node]
            break
        g = best[node]
        incoming = commands[parent[node]] if parent[node] >= 0 else -1
        for edge in range(indptr[node], indptr[node + 1]):
            nxt = indices[edge]
            time = g + weights[edge]
            if time > best[nxt]:
                continue
            turned = changes[node] + (1 if incoming >= 0 and commands[edge] != incoming else 0)
            if time == best[nxt] and turned >= changes[nxt]:
                continue
            f = (time + (abs(pose_x[nxt] - tx) + abs(pose_y[nxt] - ty)) * cell_time
                 + turn_time[t_turn, pose_turn[nxt]])
            if f > bound:
                continue
            if best[nxt] == np.inf:
                touched[n_touched] = nxt
                n_touched += 1
            best[nxt], changes[nxt], parent[nxt] = time, turned, edge
            if position[nxt] < 0:
                size += 1
                _sift_up(heap, heap_key, heap_changes, heap_time, position, size - 1, nxt, f, turned, time)
            else:
                _sift_up(heap, heap_key, heap_changes, heap_time, position, position[nxt], nxt, f, turned, time)
    count = 0
    if found < np.inf:
        node = target
        while node != source:
            path[count] = parent[node]
            node = tails[parent[node]]
            count += 1
    for k in range(size):
        position[heap[k]] = -1
    for k in range(n_touched):
        best[touched[k]] = np.inf
    return found, count


class TransitionGraph:
    """The simulator's transition table as a CSR graph, built once, and its minimum-time searches.

    The static graph has one node per pose and an edge between two poses when a valid command leads
    from one to the other, weighted by the cheapest such command's duration (a command that leaves
    the pose unchanged only costs time, and is left out). With moving obstacles the search is
    time-expanded: a state is a pose and a phase of their period (the obstacles' clock is the number
    of commands executed, as in the simulator), the commands valid when they start are its edges, and
    a command that leaves the pose unchanged is a wait. These are the graphs the exact planner
    (:func:`~htetro_opt.solvers.grid_paths.plan_exact`) searches, so a window re-planned on them is the
    exact optimum between its ends. The static graph is searched by an A* towards the window's end
    (:meth:`_static_search`), the static times to a pose from everywhere by scipy's Dijkstra
    (:meth:`time_to`). The time-expanded graph is never built whole (on a 24 × 24 map
    with a period of 40 it has 645 120 nodes, and scipy's Dijkstra allocates its arrays over all of
    them at every search): the search runs layer by layer, bounded by the window's own time and by
    the static time to the window's end (see :meth:`_timed`), and visits only the window's
    neighbourhood. Measured on the Cheng et al. 2020 moving-obstacle maps (40 windows of up to 40
    commands of the exact plan, bound 200 s): 1.3–1.5 ms a search (median), 11 ms at most;
    benchmarks/README.md has the cost inside hTetro-GA runs.

    :meth:`fastest` remembers its answers (the last 16384 questions): the graphs never change and
    the search is deterministic, so a question asked again gets the same answer without a search.
    In an hTetro-GA run most windows are asked again (the fastest member keeps its path for many
    generations, and so do its windows): measured over 300 generations on three 24 × 24 maps, 46–91 %.

    Parameters
    ----------
    simulator : Simulator

    Raises
    ------
    PlanningError
        If ``simulator`` is not a Simulator, or a command that changes the pose takes no time
        (Dijkstra and A* need positive weights).

    Examples
    --------
    >>> from htetro_opt.model import Pose, Workspace
    >>> sim = Simulator(Workspace(np.zeros((6, 6), dtype=bool)))
    >>> graph = TransitionGraph(sim)
    >>> a, b = sim.encode(Pose(1, 1, "O", 0)), sim.encode(Pose(3, 2, "O", 0))
    >>> [(commands, time)] = graph.fastest(a, 0, b, 0, limit=5.0)
    >>> len(commands), time
    (3, 3.0)
    """

    def __init__(self, simulator: Simulator) -> None:
        if not isinstance(simulator, Simulator):
            raise PlanningError(f"TransitionGraph needs a Simulator, got {type(simulator).__name__}")
        sim = self.simulator = simulator
        self.n_poses = sim.n_poses
        self.period = sim.workspace.period if sim.workspace.moving else 1
        self._static: tuple[csr_matrix, np.ndarray] | None = None
        self._reverse: csr_matrix | None = None
        self._heuristic_parts: tuple[float, np.ndarray] | None = None  # the A* heuristic (:meth:`_heuristic`)
        self._arrays: dict[str, np.ndarray] | None = None  # the A*'s per-graph arrays (:meth:`_search_arrays`)
        self._labels: np.ndarray | None = None  # the timed search's best time per (phase, pose), reset after use
        self._answers: dict[tuple, list] = {}
        self._graph()

    def _graph(self) -> tuple[csr_matrix, np.ndarray]:
        """The static graph, and the local command of each edge."""
        if self._static is not None:
            return self._static
        sim, n, c = self.simulator, self.n_poses, self.simulator.n_commands
        target = sim.next[:n, :c].astype(np.int64)
        durations = sim.durations[:c]
        usable = target != sim.dead
        if (durations[np.flatnonzero(usable.any(axis=0))] <= 0).any():
            raise PlanningError("exact re-planning needs every command that moves the robot to take a positive time")
        usable &= target != np.arange(n)[:, None]  # a command that leaves the pose unchanged only costs time
        pose, column = np.nonzero(usable)
        # Each pose's entries by (next pose, duration): the first of each (pose, next pose) group is the
        # cheapest edge, and CSR wants each row's columns sorted (scipy would sum duplicates).
        order = np.lexsort((durations[column], target[pose, column], pose))
        pose, column = pose[order], column[order]
        nxt = target[pose, column]
        first = np.r_[True, (pose[1:] != pose[:-1]) | (nxt[1:] != nxt[:-1])]
        pose, column, nxt = pose[first], column[first], nxt[first]
        indptr = np.r_[0, np.cumsum(np.bincount(pose, minlength=n))]
        index_type = np.int32 if max(n, len(nxt)) < 2**31 else np.int64
        matrix = csr_matrix((durations[column], nxt.astype(index_type), indptr.astype(index_type)), shape=(n, n))
        self._static = matrix, column.astype(np.int16)
        return self._static

    def fastest(self, source: int, t: int, target: int, t_end: int, *, limit: float,
                static: bool = False, same_phase: bool = False) -> list[tuple[np.ndarray, float]]:
        """The fastest command sequence from pose ``source`` at time ``t`` to pose ``target`` that takes
        at most ``limit``, as a list of one (empty when there is none).

        On a static map, or with ``static`` (moving obstacles ignored: a lower bound, whose path is
        valid only where they are not), that is the minimum-time sequence. With moving obstacles it
        is the fastest at any arrival time or, with ``same_phase``, the fastest arriving at ``t_end``'s
        phase of the obstacles' period (what follows the window then runs at the same obstacle times
        as before).

        Returns
        -------
        list of (ndarray of int, float)
            Global command ids and their total duration.
        """
        timed = not static and self.period > 1
        period = self.period if timed else 1
        arrival = t_end % period if timed and same_phase else None
        query = (period, (t % period) * self.n_poses + source, int(target), arrival, float(limit))
        if query in self._answers:
            return self._answers[query]
        bound = limit * (1 + _TOLERANCE) + _TOLERANCE
        answer = self._timed(source, t, target, arrival, bound) if timed else self._static_search(source, target, bound)
        for path, _ in answer:
            path.flags.writeable = False  # shared by every caller asking the same
        if len(self._answers) >= _ANSWERS:
            del self._answers[next(iter(self._answers))]  # the oldest
        self._answers[query] = answer
        return answer

    def time_to(self, target: int, *, limit: float = np.inf) -> np.ndarray:
        """The static minimum time from every pose to pose ``target`` (inf beyond ``limit``): a lower
        bound on the time-expanded one, as the moving obstacles only remove edges."""
        if self._reverse is None:
            self._reverse = self._graph()[0].T.tocsr()
            self._labels = np.full(self.period * self.n_poses, np.inf)
        return dijkstra(self._reverse, indices=int(target), limit=limit)

    def _static_search(self, source: int, target: int, bound: float) -> list[tuple[np.ndarray, float]]:
        """The minimum-time path on the static graph by A* (:func:`_astar`), bounded by ``bound``;
        of equally fast paths, one with few command changes.

        Hand-written (compiled by numba on first use) rather than scipy's Dijkstra, which has no
        goal, no heuristic and no second criterion: bounded by a window's time it labels most of
        the map, where the A* labels only poses whose time plus the lower bound to the window's end
        is within the bound. Measured side by side in one process on the 1183 searches of four
        default hTetro-GA runs (n_pop 100, 200 generations, seeds 0-1; bounds of 48-49 s, median):
        on three_slit (16 128 poses; its slits need re-orientations the heuristic only partly sees)
        220 µs a search against scipy's 886 µs (median; 3.6× in the mean), on random 15 µs against
        396 µs (25×). Its optimum time is scipy's (the heuristic is a lower bound,
        :meth:`_heuristic`). Of equally fast paths it keeps, per pose, the one with the fewest
        command changes, which the hTetro-GA's smoothness fitness counts: on those searches 5.29 /
        6.73 changes a path (three_slit / random) where scipy's choice had 5.38 / 7.79 (the fewest
        possible, on a sixth of them: 4.42 / 6.51). The same question always gets the same path.

        Its heap keeps the keys in its own slots (:func:`_astar`): on the 1044 searches recorded
        from four default runs (n_pop 100, 200 generations, seeds 0-1, 2026-11-26), side by side
        with the heap that read them through the pose ids, the same paths in 132 µs against 198 µs
        a search on three_slit (mean; median 63 / 99 µs) and 6 µs against 11 µs on random. Tried
        and left out, measured on the same searches with the former heap: ALT landmarks (Goldberg
        and Harrelson 2005; K landmark poses chosen farthest first, exact static times to and from
        each by scipy's Dijkstra, the heuristic the larger of today's and the landmarks' bound) took
        three_slit's search from 196 to 123 µs with K = 16 (96 µs with 32) but cost 37 ms (91 ms)
        per graph, i.e. per run, where a run's searches saved about 17 ms (23 ms); even the exact
        heuristic, for free, would take it to 52 µs. A cache of reverse Dijkstras per target (54-87 %
        of the searches ask a target asked before) costs 874 µs (three_slit) / 351 µs (random) a new
        target, more than the searches it would shorten.
        """
        commands = self._graph()[1]
        time, count = _astar(*self._astar_arguments(source, target, bound))
        if not np.isfinite(time):
            return []
        edges = self._search_arrays()["path"][:count][::-1]
        return [(self.simulator.command_ids[commands[edges].astype(np.int64)], float(time))]

    def _astar_arguments(self, source: int, target: int, bound: float) -> tuple:
        """:func:`_astar`'s arguments for a search from ``source`` to ``target`` within ``bound``."""
        (matrix, commands), arrays = self._graph(), self._search_arrays()
        cell_time, turn_time = self._heuristic()
        return (matrix.indptr, matrix.indices, matrix.data, arrays["tails"], commands, int(source), int(target),
                float(bound), arrays["x"], arrays["y"], arrays["orientation"], cell_time, turn_time, arrays["best"],
                arrays["changes"], arrays["parent"], arrays["position"], arrays["heap"], arrays["heap_key"],
                arrays["heap_changes"], arrays["heap_time"], arrays["touched"], arrays["path"])

    def _heuristic(self) -> tuple[float, np.ndarray]:
        """The A* heuristic's two parts, derived from the static graph's edges once: ``cell_time``,
        the least time per cell of grid distance any edge moves the reference cell, and
        ``turn_time[b, a]``, the least time from orientation (state, heading) a to b counting of each
        edge only its time beyond its moves' share (``time - cells moved × cell_time``, ≥ 0); indexed
        by the target's orientation first, so that a search reads one row.

        A path's time is the sum of its edges' (cells moved × cell_time) and their remainders: the
        first sum is at least the grid distance between its ends × cell_time, the second at least
        the turn time between their orientations. So grid distance × cell_time + turn_time is a lower
        bound, and consistent (each part obeys the triangle inequality along an edge). With Cheng
        et al. 2020's commands, a translation moves one cell in 1 s and turns nothing, a rotation or
        shapeshift moves nothing: the heuristic is the grid distance plus the fastest re-orientation.
        """
        if self._heuristic_parts is None:
            matrix = self._graph()[0]
            ws = self.simulator.workspace
            width, cells = ws.width, ws.width * ws.height
            tails = self._search_arrays()["tails"].astype(np.int64)
            heads = matrix.indices.astype(np.int64)
            moved = (np.abs(tails % cells % width - heads % cells % width)
                     + np.abs(tails % cells // width - heads % cells // width))
            moving = moved > 0
            cell_time = float((matrix.data[moving] / moved[moving]).min()) if moving.any() else 0.0
            rest = np.maximum(matrix.data - moved * cell_time, 0.0)
            n_turns = self.n_poses // cells
            turns = np.full((n_turns, n_turns), np.inf)
            np.minimum.at(turns, (tails // cells, heads // cells), rest)
            np.fill_diagonal(turns, 0.0)
            for k in range(n_turns):  # Floyd-Warshall: a few dozen orientations
                np.minimum(turns, turns[:, k, None] + turns[None, k, :], out=turns)
            self._heuristic_parts = cell_time, np.ascontiguousarray(turns.T)
        return self._heuristic_parts

    def _search_arrays(self) -> dict[str, np.ndarray]:
        """The A*'s arrays, allocated once per graph: each edge's tail, each pose's cell (x, y) and
        orientation (read where the search would otherwise divide its id), and per-pose labels and
        heap left as the search found them (``best`` all inf, ``position`` all -1)."""
        if self._arrays is None:
            matrix, n = self._graph()[0], self.n_poses
            index_type = matrix.indices.dtype
            ws = self.simulator.workspace
            poses, cells = np.arange(n), ws.width * ws.height  # pose id = orientation * cells + y * width + x
            self._arrays = {
                "tails": np.repeat(np.arange(n, dtype=index_type), np.diff(matrix.indptr)),
                "x": (poses % ws.width).astype(index_type),
                "y": (poses % cells // ws.width).astype(index_type),
                "orientation": (poses // cells).astype(index_type),
                "best": np.full(n, np.inf),
                "changes": np.empty(n, dtype=index_type),
                "parent": np.empty(n, dtype=index_type),
                "position": np.full(n, -1, dtype=index_type),
                "heap": np.empty(n, dtype=index_type),
                "heap_key": np.empty(n),
                "heap_changes": np.empty(n, dtype=index_type),
                "heap_time": np.empty(n),
                "touched": np.empty(n, dtype=index_type),
                "path": np.empty(n, dtype=index_type),
            }
        return self._arrays

    def _timed(self, source: int, t: int, target: int, arrival: int | None,
               limit: float) -> list[tuple[np.ndarray, float]]:
        """The time-expanded search: layered searches (:meth:`_layers`) under a rising bound.

        Every label of a layered search satisfies time + static time to ``target`` ≤ the bound, so
        a search whose bound is at least the optimum finds it. The first bound is the static
        optimum (the moving obstacles only remove edges, so nothing is faster); each next one is
        the smallest pruned label's (time + static time to go) or, if larger, the static optimum
        plus twice the last excess, so that a window whose optimum waits long costs a few searches,
        not one per distinct time. The neighbourhood searched is then that of the optimum, not that
        of the window's own time, which may be far larger.
        """
        to_go = self.time_to(target, limit=limit)
        floor = float(to_go[source])
        if not floor <= limit:
            return []
        bound = min(limit, floor * (1 + _TOLERANCE) + _TOLERANCE)
        while True:
            found, pruned = self._layers(source, t, target, arrival, bound, to_go)
            if found or bound >= limit or not np.isfinite(pruned):
                return found
            bound = min(limit, max(pruned, floor + 2 * (bound - floor)) * (1 + _TOLERANCE) + _TOLERANCE)

    def _layers(self, source: int, t: int, target: int, arrival: int | None, bound: float,
                to_go: np.ndarray) -> tuple[list[tuple[np.ndarray, float]], float]:
        """One layered search under ``bound``: the fastest arrival (at phase ``arrival`` if given) and
        the smallest time + time to go of the labels the bound pruned.

        A label is (pose, time) after k commands; a layer expands every label by every command
        valid at its phase (a command that leaves the pose unchanged is a wait) and keeps, per pose,
        the fastest. A label is pruned when its time plus the static minimum time to ``target`` (a
        lower bound) exceeds ``bound`` (lowered to the best arrival once one is found), or when it
        is no faster than an earlier label of the same pose at the same phase of the period.
        """
        sim, n, period = self.simulator, self.n_poses, self.period
        if source == target and (arrival is None or t % period == arrival):
            return [(sim.command_ids[:0], 0.0)], np.inf  # already there: the window was a wait
        c = sim.n_commands
        columns = np.arange(c)
        durations = sim.durations[:c]
        labels, touched = self._labels, []
        poses, times = np.array([source], dtype=np.int64), np.zeros(1)
        layers = []  # per layer: (row of the label it came from, local command)
        best, pruned = None, np.inf  # best: (time, layer, row)
        try:
            while len(poses):
                k = len(layers)
                after = sim.next[poses, :c].astype(np.int64)
                valid = after != sim.dead
                blocked = sim.blocked_keys(t + k)
                if len(blocked):
                    keys = poses[:, None] * sim.n_columns + columns
                    valid &= blocked[np.searchsorted(blocked, keys).clip(max=len(blocked) - 1)] != keys
                arrive = times[:, None] + durations
                estimate = arrive + to_go[np.where(valid, after, source)]
                over = valid & (estimate > bound)
                if over.any():
                    pruned = min(pruned, float(estimate[over].min()))
                row, column = np.nonzero(valid & ~over)
                if not len(row):
                    break
                nxt, when = after[row, column], arrive[row, column]
                order = np.lexsort((when, nxt))  # per next pose, the fastest first
                first = order[np.r_[True, nxt[order][1:] != nxt[order][:-1]]]
                row, column, nxt, when = row[first], column[first], nxt[first], when[first]
                phase = (t + k + 1) % period
                node = phase * n + nxt
                better = when < labels[node] - _TOLERANCE
                row, column, nxt, when, node = row[better], column[better], nxt[better], when[better], node[better]
                labels[node] = when
                touched.append(node)
                layers.append((row, column))
                hit = np.flatnonzero(nxt == target)
                if len(hit) and (arrival is None or phase == arrival) and (best is None or when[hit[0]] < best[0]):
                    best = (float(when[hit[0]]), len(layers), int(hit[0]))
                    bound = min(bound, best[0] + _TOLERANCE)  # nothing slower is wanted any more
                poses, times = nxt, when  # those beyond a lowered bound have no children
        finally:
            for node in touched:
                labels[node] = np.inf
        if best is None:
            return [], pruned
        time, layer, r = best
        path = []
        for row, column in reversed(layers[:layer]):
            path.append(column[r])
            r = row[r]
        return [(sim.command_ids[np.array(path[::-1], dtype=np.int64)], time)], pruned


def replan_windows(problem, seqs: list[np.ndarray], *, window: int, random_state: np.random.Generator,
                   graph: TransitionGraph | None = None, timed: bool = True) -> list[np.ndarray]:
    """Replace one window of each chromosome's executed commands by the fastest way between its ends.

    Each chromosome is simulated from the problem's start (with its goal and child termination);
    a window of ``min(window, executed)`` consecutive executed commands is drawn uniformly, and the
    minimum-time command sequence from the pose before the window (at its time) to the pose after it
    replaces it when strictly faster. The new executed part is simulated again and kept only if it
    is valid, ends on the same pose and is no slower; the genes after the executed part are kept. So
    the chromosome's start, end pose and validity are kept and its time never grows. Returns new
    arrays (the input ones where nothing changed).

    With moving obstacles the static graph is searched first: its optimum is a lower bound (a
    window that cannot beat it is left alone) and, when it runs clear of the obstacles at the times it
    runs and leaves the rest of the path valid, it is the window's optimum. With ``timed`` (the
    default), a window whose static optimum collides is then re-planned by the time-expanded search
    (see :meth:`TransitionGraph.fastest`), which gives its exact optimum; without it, on
    moving-obstacle maps the step improves a window only where the obstacles leave the static optimum
    free.

    Parameters
    ----------
    problem : CommandPathProblem
        Provides ``simulator``, ``start_id``, ``goal`` and ``t0``.
    seqs : list of ndarray
        Global command ids.
    window : int, keyword-only
        W, the most commands a window holds (at least 1).
    random_state : numpy.random.Generator, keyword-only
        Draws the windows.
    graph : TransitionGraph, optional, keyword-only
        The problem's simulator's graph, if already built (building it costs more than a search).
    timed : bool, default True, keyword-only
        With moving obstacles, fall back on the time-expanded search (see above).

    Raises
    ------
    ParameterError
        If ``window`` is not a positive integer or ``timed`` not a bool.

    Examples
    --------
    >>> from htetro_opt.model import Pose, Workspace, format_commands, parse_commands
    >>> from htetro_opt.problems import CommandPathProblem
    >>> problem = CommandPathProblem(Workspace(np.zeros((8, 8), dtype=bool)), Pose(1, 2, "O", 0),
    ...                              Pose(5, 2, "O", 0), max_length=10)
    >>> [s] = replan_windows(problem, [parse_commands("y+,x+,x+,y-,x+,x+")], window=6,
    ...                      random_state=np.random.default_rng(0))
    >>> format_commands(s)
    ['x+', 'x+', 'x+', 'x+']
    """
    window = check_int(window, "replan window", minimum=1)
    timed = check_bool(timed, "timed")
    out = list(seqs)
    if not seqs:
        return out
    sim = problem.simulator
    graph = graph if graph is not None else TransitionGraph(sim)
    result = sim.run(seqs, problem.start_id, roadmap=[problem.goal], t0=problem.t0, stop_at_goal=True)
    trace, executed = result.trace, result.executed
    durations = sim.durations[result.local]
    windows = []
    for k in np.flatnonzero(executed > 0):
        done = int(executed[k])
        length = min(window, done)
        i = int(random_state.integers(0, done - length + 1))
        windows.append((int(k), i, i + length, float(durations[k, i : i + length].sum())))

    def improve(windows, **question) -> list:
        """Re-plan ``windows`` by one question to the graph; those whose candidates all failed."""
        candidates = []  # (window, new executed part)
        for w in windows:
            k, i, j, spent = w
            for path, time in graph.fastest(int(trace[k, i]), problem.t0 + i, int(trace[k, j]), problem.t0 + j,
                                            limit=spent, **question):
                if time < spent - _TOLERANCE:
                    done = seqs[k][: executed[k]]
                    candidates.append((w, np.concatenate([done[:i], path, done[j:]]).astype(np.int64)))
        if not candidates:
            return []
        check = sim.run([c for _, c in candidates], problem.start_id, t0=problem.t0)
        final = check.trace[np.arange(len(candidates)), check.executed]
        settled = set()
        for m, ((k, *_), new) in enumerate(candidates):
            if k not in settled and check.valid[m] and final[m] == trace[k, executed[k]] \
                    and check.time[m] <= result.time[k] + _TOLERANCE:
                out[k] = np.concatenate([new, seqs[k][executed[k]:]])
                settled.add(k)
        return list(dict.fromkeys(w for w, _ in candidates if w[0] not in settled))

    unsettled = improve(windows, static=True)
    if timed and graph.period > 1:
        # The fastest at any phase first; where it leaves the rest of the path invalid (the obstacles
        # meet it at other times), the fastest arriving at the old phase, which keeps the rest's times.
        for same_phase in (False, True):
            if unsettled:
                unsettled = improve(unsettled, static=False, same_phase=same_phase)
    return out


def reach_repair(problem, seqs: list[np.ndarray], *, graph: TransitionGraph | None = None,
                 tries: int = 3) -> list[np.ndarray]:
    """Make chromosomes that do not reach the goal reach it: the executed commands up to a pose, then
    the minimum-time path from that pose (at its time) to the goal.

    Each chromosome is simulated from the problem's start (with its goal and child termination).
    The poses it passes are ranked by their static minimum time to the goal (a lower bound, on a
    moving map as well), the nearest first and, of equals, the one passed first; for up to ``tries``
    distinct poses in that order, the fastest path from the pose to the goal is searched
    (:meth:`TransitionGraph.fastest`: time-expanded with the obstacles' clock on a moving map, so it
    is valid at the times it runs), bounded so that the whole path takes at most t_max, the
    problem's time budget (f_t ≥ 0). The first candidate the simulator confirms to reach the goal
    replaces the chromosome; a chromosome that already reaches, or for which no candidate does, is
    returned unchanged. The pose kept is the nearest to the goal rather than the start so that the
    chromosome's lineage (its route so far) is kept and only its tail is planned.

    Parameters
    ----------
    problem : CommandPathProblem
        Provides ``simulator``, ``start_id``, ``goal``, ``goal_id``, ``t0`` and ``t_max``.
    seqs : list of ndarray
        Global command ids.
    graph : TransitionGraph, optional, keyword-only
        The problem's simulator's graph, if already built.
    tries : int, default 3, keyword-only
        How many distinct poses a chromosome may be cut at.

    Returns
    -------
    list of ndarray
        New arrays where a chromosome was repaired, the input ones elsewhere.

    Raises
    ------
    ParameterError
        If ``tries`` is not a positive integer.

    Examples
    --------
    >>> from htetro_opt.model import Pose, Workspace, format_commands, parse_commands
    >>> from htetro_opt.problems import CommandPathProblem
    >>> problem = CommandPathProblem(Workspace(np.zeros((8, 8), dtype=bool)), Pose(1, 2, "O", 0),
    ...                              Pose(5, 2, "O", 0), max_length=10)
    >>> [s] = reach_repair(problem, [parse_commands("x+,x+,x+,y+,y+")])
    >>> format_commands(s)
    ['x+', 'x+', 'x+', 'x+']
    """
    tries = check_int(tries, "reach repair tries", minimum=1)
    out = list(seqs)
    if not seqs:
        return out
    sim = problem.simulator
    graph = graph if graph is not None else TransitionGraph(sim)
    result = sim.run(seqs, problem.start_id, roadmap=[problem.goal], t0=problem.t0, stop_at_goal=True)
    to_go = graph.time_to(problem.goal_id, limit=problem.t_max)
    durations = sim.durations[result.local]
    for k in np.flatnonzero(~result.reached.astype(bool)):
        done = int(result.executed[k])
        poses = result.trace[k, : done + 1].astype(np.int64)
        elapsed = np.r_[0.0, np.cumsum(durations[k, :done])]
        budget = problem.t_max - elapsed
        order = np.lexsort((np.arange(done + 1), to_go[poses]))  # nearest first, then the first passed
        order = order[to_go[poses[order]] <= budget[order] * (1 + _TOLERANCE) + _TOLERANCE]
        _, first = np.unique(poses[order], return_index=True)
        for i in order[np.sort(first)][:tries]:
            found = graph.fastest(int(poses[i]), problem.t0 + int(i), problem.goal_id, 0, limit=float(budget[i]))
            if not found:
                continue
            candidate = np.concatenate([seqs[k][:i], found[0][0]]).astype(np.int64)
            check = sim.run([candidate], problem.start_id, roadmap=[problem.goal], t0=problem.t0, stop_at_goal=True)
            if check.reached[0] and check.executed[0] == len(candidate):
                out[k] = candidate
                break
    return out


def replan_rows(reached, time, members: int, *, random_state: np.random.Generator) -> np.ndarray:
    """The rows a generation re-plans: the fastest goal-reaching one (the first of equals) and
    ``members`` others drawn without replacement among the reaching ones, those in row order.

    Parameters
    ----------
    reached : array-like of bool
        Which rows reach the goal.
    time : array-like of float
        A time per row (or any key smaller for faster, e.g. pymoo's F column of −f_t).
    members : int
        K, the reaching rows drawn besides the fastest.
    random_state : numpy.random.Generator, keyword-only

    Examples
    --------
    >>> replan_rows([True, False, True, True], [9.0, 1.0, 5.0, 7.0], 1, random_state=np.random.default_rng(0))
    array([2, 3])
    """
    members = check_int(members, "replan members", minimum=0)
    reached = np.flatnonzero(np.asarray(reached, dtype=bool))
    if not len(reached):
        return reached.astype(np.int64)
    best = reached[np.argmin(np.asarray(time, dtype=float)[reached])]
    others = reached[reached != best]
    drawn = random_state.choice(others, size=min(members, len(others)), replace=False)
    return np.r_[best, np.sort(drawn)].astype(np.int64)


class _GraphPerSimulator:
    """Keeps each simulator's :class:`TransitionGraph` while the simulator lives (a problem's graph is
    built once, not once a generation)."""

    def graph(self, simulator: Simulator) -> TransitionGraph:
        """The simulator's :class:`TransitionGraph`, built on first use."""
        graphs = self.__dict__.setdefault("_graphs", weakref.WeakKeyDictionary())
        if simulator not in graphs:
            graphs[simulator] = TransitionGraph(simulator)
        return graphs[simulator]


class CommandReplan(_GraphPerSimulator, Mutation):
    """Windowed exact re-planning as a pymoo mutation (see :func:`replan_windows`).

    Builds the :class:`TransitionGraph` of a problem's simulator once and keeps it while the
    simulator lives. A memetic local step of ours, not part of the paper's hTetro-GA; the hTetro-GA
    applies it each generation to its fastest goal-reaching member and a few random reaching ones
    (:class:`~htetro_opt.algorithms.HTetroGA`'s ``replan_window`` and ``replan_members``). The problem
    must provide ``simulator``, ``start_id``, ``goal`` and ``t0``.

    Parameters
    ----------
    window : int
        W, the most executed commands a window holds.
    timed : bool, default True, keyword-only
        With moving obstacles, fall back on the time-expanded search (see :func:`replan_windows`).
    prob : float, keyword-only
        pymoo's per-individual probability that the operator is applied.

    Raises
    ------
    ParameterError
        If ``window`` is not a positive integer, ``timed`` not a bool or ``prob`` not a probability.
    """

    def __init__(self, window: int = 40, *, timed: bool = True, prob: float = 1.0) -> None:
        super().__init__(prob=check_probability(prob, "replan prob"))
        self.window = check_int(window, "replan window", minimum=1)
        self.timed = check_bool(timed, "timed")

    def _do(self, problem, X, *args, random_state=None, **kwargs):
        return as_column(replan_windows(problem, sequences(X), window=self.window, random_state=random_state,
                                        graph=self.graph(problem.simulator), timed=self.timed))


class CommandReachRepair(_GraphPerSimulator, Mutation):
    """The reach repair as a pymoo mutation (see :func:`reach_repair`).

    Ours, not part of the paper's hTetro-GA: the hTetro-GA applies it to the member nearest to the
    goal when no member has reached it and the population's best goal reachability has not risen for
    ``reach_patience`` generations (:class:`~htetro_opt.algorithms.HTetroGA`). Builds the
    :class:`TransitionGraph` of a problem's simulator once and keeps it while the simulator lives. The
    problem must provide ``simulator``, ``start_id``, ``goal``, ``goal_id``, ``t0`` and ``t_max``.

    Parameters
    ----------
    tries : int, default 3, keyword-only
        How many distinct poses a chromosome may be cut at.
    prob : float, keyword-only
        pymoo's per-individual probability that the operator is applied.
    """

    def __init__(self, *, tries: int = 3, prob: float = 1.0) -> None:
        super().__init__(prob=check_probability(prob, "reach repair prob"))
        self.tries = check_int(tries, "reach repair tries", minimum=1)

    def _do(self, problem, X, *args, random_state=None, **kwargs):
        return as_column(reach_repair(problem, sequences(X), graph=self.graph(problem.simulator), tries=self.tries))
