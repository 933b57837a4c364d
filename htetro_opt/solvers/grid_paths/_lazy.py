r"""Exact minimum-time search over the hTetro's poses without building their graph (static maps).

:func:`~htetro_opt.solvers.grid_paths.plan_exact`'s engine on a map without moving obstacles. The
explicit graph of every pose and command (the simulator's ``next`` table and a CSR matrix over it, about
70 bytes a pose with the default commands) is what cost the memory and most of the time on maps of
10^6 cells and more; here a pose's successors are computed when the pose is expanded, from the
simulator's per-(state, heading, command) tables (:class:`~htetro_opt.model.sweeps.SweepTables`: the
swept cells, the next state and heading, B2's shift) and the map, in a loop compiled by numba:

- **Pose space.** Pose ids are the :class:`~htetro_opt.model.Simulator`'s,
  ``((state * 4 + heading) * H + y) * W + x`` (:class:`PoseSpace`), cell-major inside the search
  (``cell * 28 + state * 4 + heading``: a cell's poses share cache lines). The map is framed by blocked cells
  as wide as the largest sweep, so a command's swept cells are one flat offset each from the pose's cell
  and need no bounds test; a per-cell Chebyshev distance to the nearest blocked cell (one byte, from
  scipy.ndimage, or numpy's erosions on a small map) proves a command valid at once where its whole
  sweep lies within that distance, so most commands away from walls are never checked cell by cell.
- **A few bytes a pose.** One unsigned 32-bit word a pose holds both the best known cost and the
  back pointer: the cost in time quanta in the high bits, the parent's (state, heading) and the command
  in the low ones (the parent's cell is the pose's minus the command's shift). A cost too large for the
  high bits makes the search restart with 64-bit words (8 bytes a pose).
- **Bucket queue.** When every command's duration is a whole multiple of one quantum (the default
  timing: 1, 2, 3 s), costs are integers and the queue is Dial's: a ring of ``2 * longest + 2`` buckets
  over f = g + h, each a stack of 4,096-entry blocks from one pool (4 bytes an entry). Otherwise (the
  diagonals' √2) a binary heap on arrays over float64 costs (10 bytes a pose: cost and parent apart).
- **A\*** (``"astar"``) adds the heuristic of :func:`heuristic_field`: the point-robot distance of B2's
  cell to the goal cell over free cells times the least time a cell of B2's travel takes; ``"dijkstra"``
  searches with h = 0. Both stop when the goal is taken from the queue, so both return the optimum.

The queue's pool is grown from Python when the compiled loop runs short (it returns and is called
again), so every array of the search is numpy's and ``tracemalloc`` sees it. A process's first
:data:`_INTERPRETED` expansions on a small pose space run the same kernels in the interpreter
(:func:`_run`), since importing numba and loading them costs more than a small map's whole search.
"""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np

from htetro_opt._jit import lazy_jit
from htetro_opt.errors import ConfigurationError, PlanningError
from htetro_opt.model.commands import command_id
from htetro_opt.model.robot import N_HEADINGS, Pose, as_pose
from htetro_opt.model.simulate import _pose_id, _resolve_commands, _states_of, memory_budget
from htetro_opt.model.sweeps import SweepTables, sweep_tables
from htetro_opt.model.workspace import Workspace, describe_cells, grid_distance

__all__ = ["PoseSpace", "heuristic_field", "search_leg", "lazy_bytes", "quantum"]

_STOP = command_id("stop")
BLOCK = 4096
"""Entries of one block of the bucket queue's pool."""
_FOUND, _UNREACHABLE, _OVERFLOW, _GROW, _RANGE, _PAUSE = 0, 1, 2, 3, 4, 5
_WORD_BITS = 32
"""Bits of a pose's word (cost and parent) in the first try; a cost beyond them restarts the leg with 64."""
_HEAP_START = 1 << 16
"""Entries the float heap's arrays start with."""
_INTERPRETED = 15_000
"""Poses a process expands in the interpreter before the compiled kernel takes the search over. Importing numba
and loading a kernel from its on-disk cache costs about 0.3 s CPU, the time of some 35,000 expansions in the
interpreter (8-9 us each; compiled: under 1 us): a search that needs fewer (a 24 x 24 map's A*: 3,000) is done
without numba, and one that needs more is handed over at this count, having lost at most half of numba's
start-up. The kernel is the same code either way, resumed where the interpreter paused: the same plan."""
_interpreted_left = _INTERPRETED
_INTERPRETED_POSES = 2**15
"""The largest pose space searched in the interpreter (a 34 x 34 map with the default commands: the papers'
24 x 24 maps have 16,128 poses); a larger one is searched compiled from the start. The interpreter's lists
take 8 bytes an entry and 32 more for each distinct value (the search's own arrays 4)."""
_INTERPRETED_BYTES = 16 * 2**20
"""Most bytes the interpreter's lists add to :func:`lazy_bytes` within :data:`_INTERPRETED_POSES` (measured
by tracemalloc: at most 3.9 MiB, on a 34 x 34 map whose search reaches every pose, tested in
tests/solvers/grid_paths/test_lazy_interpreted.py); where the memory budget leaves less room, the search is
compiled."""
_MAX_BUCKETS = 4096
"""Most distinct f values ahead of the current one the bucket ring holds (2 * longest command + 2 quanta)."""

# --- memory -------------------------------------------------------------------------------------------
_CELL_BYTES = 120
"""Peak bytes per cell of the map-sized arrays: the framed map and its Chebyshev distances (and
scipy.ndimage's int32 temporaries), and the heuristic's point-robot Dijkstra (scipy's CSR graph over
the free cells and its float64 distances); measured 100 to 110 by tracemalloc on maps of 100 x 100 to
1000 x 1000 cells (tests/solvers/grid_paths/test_exact.py)."""
_QUEUE_SHARE = 0.5
"""Queue entries (4 or 8 bytes each) allowed per pose in the estimate: the frontier and its stale
duplicates; measured at most 0.3 when the search reaches every pose of maps of 50 x 50 cells and more
(a small map's frontier is a large share of it)."""


def lazy_bytes(n_poses: int, n_cells: int, durations, q: float | None | str = "find") -> int:
    """Peak bytes of :func:`search_leg` on a map of ``n_cells`` cells and ``n_poses`` poses with these
    command durations: 4 bytes a pose (cost and parent in one word) with a bucket queue, 10 with the
    float heap (float64 cost and a 16-bit parent), the queue's allowance (4-byte entries, 12 in the
    heap), its initial arrays and the map-sized arrays."""
    q = quantum(durations) if q == "find" else q
    if q is None:
        return int(n_poses * (10 + 12 * _QUEUE_SHARE) + n_cells * _CELL_BYTES + 12 * _HEAP_START)
    n_buckets = 2 * int(np.rint(np.max(durations) / q)) + 2
    return int(n_poses * (4 + 4 * _QUEUE_SHARE) + n_cells * _CELL_BYTES + 4 * BLOCK * max(2 * n_buckets, 64))


# --- the pose space -----------------------------------------------------------------------------------
class PoseSpace:
    """The poses of a static map and the compiled tables their successors are computed from.

    Parameters
    ----------
    workspace : Workspace
    command_ids : sequence of int
        Global command ids (a :class:`~htetro_opt.model.Simulator`'s ``command_ids``).
    durations : ndarray of float
        Each command's duration, in the order of ``command_ids``.
    tables : SweepTables

    Notes
    -----
    Entry ``e = (state * 4 + heading) * n_commands + command``: whether it is legal and not a
    self-loop (a command that leaves the pose unchanged is useless on a static map), the (state,
    heading) it leads to, the Chebyshev radius of its swept cells and those cells as flat offsets
    in the framed map.
    """

    def __init__(self, workspace: Workspace, command_ids, durations: np.ndarray, tables: SweepTables) -> None:
        self.workspace, self.tables = workspace, tables
        self.command_ids = np.asarray(command_ids, dtype=np.int64)
        self.durations = np.asarray(durations, dtype=np.float64)[: len(self.command_ids)]
        self.n_commands = len(self.command_ids)
        self.n_states = _states_of(self.command_ids.tolist())
        self.n_sh = self.n_states * N_HEADINGS
        self.width, self.height = workspace.width, workspace.height
        self.n_cells = self.width * self.height
        self.n_poses = self.n_sh * self.n_cells
        t, ids = tables, self.command_ids
        offsets = [[t.cells(s, h, g) if t.legal[s, g] else np.zeros((0, 2), dtype=np.int64) for g in ids]
                   for s in range(self.n_states) for h in range(N_HEADINGS)]
        span = max((int(np.abs(o).max()) for row in offsets for o in row if len(o)), default=0)
        self.margin = span + 1
        self.framed_width = self.width + 2 * self.margin
        n_entries = self.n_sh * self.n_commands
        self.usable = np.zeros(n_entries, dtype=np.uint8)
        self.target_sh = np.zeros(n_entries, dtype=np.int64)
        self.radius = np.zeros(n_entries, dtype=np.int64)
        self.dx = t.shift[ids, 0].astype(np.int64)
        self.dy = t.shift[ids, 1].astype(np.int64)
        pointers, flat = [0], []
        for sh in range(self.n_sh):
            s, h = divmod(sh, N_HEADINGS)
            for c, g in enumerate(ids):
                e = sh * self.n_commands + c
                cells = offsets[sh][c]
                if t.legal[s, g]:
                    self.target_sh[e] = t.next_state[s, g] * N_HEADINGS + t.next_heading[s, h, g]
                    moves = self.target_sh[e] != sh or self.dx[c] or self.dy[c]
                    self.usable[e] = bool(moves)
                    self.radius[e] = int(np.abs(cells).max())
                    flat.append(cells[:, 1] * self.framed_width + cells[:, 0])
                pointers.append(pointers[-1] + (len(cells) if t.legal[s, g] else 0))
        self.sweep_ptr = np.array(pointers, dtype=np.int64)
        self.sweep_off = np.concatenate(flat).astype(np.int64) if flat else np.zeros(0, dtype=np.int64)
        moving = self.usable.reshape(self.n_sh, self.n_commands).any(axis=0)
        if (moving & (self.durations <= 0)).any():
            raise PlanningError("exact planning needs every command that moves the robot to take a positive time")
        self.cbits = max(1, (self.n_commands - 1).bit_length())
        self.pbits = self.cbits + max(1, (self.n_sh - 1).bit_length())
        self._framed = None

    @classmethod
    def build(cls, workspace: Workspace, *, commands=None, diagonals: bool = False, timing=None,
              clearance: float = 0.0) -> "PoseSpace":
        """The pose space a :class:`~htetro_opt.model.Simulator` with these options would compile."""
        import reprlib

        from htetro_opt.errors import ParameterError
        from htetro_opt.model.commands import Timing
        from htetro_opt.model.workspace import check_workspace

        check_workspace(workspace)
        ids = np.array(_resolve_commands(commands, diagonals), dtype=np.int64)
        if timing is not None and not isinstance(timing, Timing):  # as the Simulator says it
            raise ParameterError(f"timing must be a Timing or None, got {type(timing).__name__} {reprlib.repr(timing)}")
        timing = timing if timing is not None else Timing()
        return cls(workspace, ids, timing.durations()[ids], sweep_tables(clearance))

    def framed(self) -> tuple[np.ndarray, np.ndarray]:
        """The framed free map (uint8, 1 free) and its Chebyshev distance to the nearest blocked cell
        (uint8, saturated at 255), both flat over ``(H + 2m) x (W + 2m)``."""
        if self._framed is None:
            m = self.margin
            free = np.zeros((self.height + 2 * m, self.framed_width), dtype=np.uint8)
            free[m : m + self.height, m : m + self.width] = ~self.workspace.occupancy
            if free.size <= _ERODED_CELLS:
                clear = _chessboard_by_erosion(free)
            else:
                from scipy.ndimage import distance_transform_cdt

                clear = distance_transform_cdt(free, metric="chessboard")
                np.minimum(clear, 255, out=clear)
            self._framed = (free.ravel(), clear.astype(np.uint8).ravel())
        return self._framed

    # --- poses, as the Simulator's -------------------------------------------------------------------
    def encode(self, pose: Pose) -> int:
        return _pose_id(self.workspace, self.n_states, pose)

    def internal(self, pose_id: int) -> int:
        """The search's id ``cell * n_sh + sh`` of a Simulator pose id ``sh * n_cells + cell``."""
        sh, cell = divmod(int(pose_id), self.n_cells)
        return cell * self.n_sh + sh

    def decode(self, ids) -> np.ndarray:
        ids = np.asarray(ids, dtype=np.int64)
        x, y = ids % self.width, (ids // self.width) % self.height
        sh = ids // self.n_cells
        return np.stack([x, y, sh // N_HEADINGS, sh % N_HEADINGS], axis=-1)

    def check_pose(self, pose: Pose, *, what: str = "pose") -> int:
        """:meth:`Simulator.check_pose <htetro_opt.model.Simulator.check_pose>` on the static map."""
        pose = as_pose(pose, what)
        try:
            pid = self.encode(pose)
        except ConfigurationError as err:
            raise ConfigurationError(f"{what} {tuple(pose)}: {err}") from err
        x, y, s, h = (int(v) for v in self.decode(pid))
        outside, occupied = self.workspace.conflicts(self.tables.cells(s, h, _STOP) + (x, y))
        if outside or occupied:
            margin = f" (with clearance {self.tables.clearance:g})" if self.tables.clearance else ""
            raise ConfigurationError(f"{what} {tuple(pose)}{margin} collides with obstacles or the map edge "
                                     f"at {describe_cells(outside + occupied)}")
        return pid


_ERODED_CELLS = 40_000
"""Framed maps of at most this many cells get their Chebyshev distances by repeated erosion in numpy (a pass a
unit of distance, at most half the shorter side: about 15 ms at this size) rather than by scipy.ndimage, which
costs 0.05 s to import; both give the same whole numbers."""


def _chessboard_by_erosion(free: np.ndarray) -> np.ndarray:
    """Each cell's Chebyshev distance to the nearest cell of ``free == 0`` (0 there), saturated at 255, where every
    cell of the border is 0: a cell at distance d survives d - 1 erosions by the 3 x 3 square, not d."""
    alive = free.astype(bool)
    clear = np.zeros(free.shape, dtype=np.int32)
    for _ in range(255):
        if not alive.any():
            break
        clear += alive
        rows = alive.copy()  # the 3 x 3 minimum, as a minimum over 3 rows then over 3 columns
        rows[1:] &= alive[:-1]
        rows[:-1] &= alive[1:]
        alive = rows.copy()
        alive[:, 1:] &= rows[:, :-1]
        alive[:, :-1] &= rows[:, 1:]
    return clear


def quantum(durations: np.ndarray) -> float | None:
    """The largest q with every duration a whole multiple of it (within 1e-12), if the longest is at most
    ``(_MAX_BUCKETS - 2) / 2`` quanta; None otherwise (then the search uses the float heap).

    Examples
    --------
    >>> quantum(np.array([1.0, 2.0, 3.0])), quantum(np.array([0.5, 1.5])), quantum(np.array([1.0, 2 ** 0.5]))
    (1.0, 0.5, None)
    """
    fractions = []
    for d in np.asarray(durations, dtype=float):
        f = Fraction(float(d)).limit_denominator(1000)
        if abs(float(f) - d) > 1e-12 * max(1.0, abs(d)):
            return None
        fractions.append(f)
    positive = [f for f in fractions if f > 0]
    if not positive:
        return None
    q = Fraction(math.gcd(*(f.numerator for f in positive)), math.lcm(*(f.denominator for f in positive)))
    return float(q) if max(positive) / q <= (_MAX_BUCKETS - 2) // 2 else None


def heuristic_field(space: PoseSpace, goal_cell: tuple[int, int]) -> np.ndarray:
    """A lower bound on the time from any pose to the goal, per B2 cell: ``rate * D(cell)``, ``inf`` where
    B2 cannot reach the goal cell.

    ``D`` is the point-robot distance over free cells (:func:`~htetro_opt.model.workspace.grid_distance`:
    4-connected steps of 1, plus diagonal steps of √2 not cutting a corner when a command shifts B2
    diagonally), and ``rate`` the least ``duration / step`` over the commands that shift B2.

    Why it is a lower bound (admissible) and consistent: every command moves B2's cell by its ``shift``;
    the command is valid only when all its swept cells are free, and the sweep holds B2's start and end
    cells (and for a diagonal shift both side cells, checked below from the tables). So B2's start cell
    u and end cell v are joined by a free step of length L (1, or √2 for a diagonal) of D's graph, and
    D(u) <= D(v) + L. The command takes at least ``rate * L`` (``rate`` is the least ratio), so
    h(u) = rate D(u) <= rate D(v) + rate L <= h(v) + duration; a command that does not shift B2 keeps
    h and costs >= 0. h(goal pose) = 0, and summing along any plan gives h(start) <= its time. Where a
    command's shift is longer than one cell, or a diagonal's sweep misses a side cell, no such step
    exists: the field is then 0 (Dijkstra's), never an overestimate. ``inf`` where D is infinite is exact:
    B2 cannot reach the goal cell from there through free cells, so no plan can.
    """
    t, ids = space.tables, space.command_ids
    rate, diagonal = math.inf, False
    for c, g in enumerate(ids):
        dx, dy = int(space.dx[c]), int(space.dy[c])
        if not (dx or dy):
            continue
        if abs(dx) > 1 or abs(dy) > 1:
            return np.zeros((space.height, space.width))
        if dx and dy:
            diagonal = True
            for s in range(space.n_states):
                for h in range(N_HEADINGS):
                    if t.legal[s, g]:
                        cells = {tuple(v) for v in t.cells(s, h, g).tolist()}
                        if not {(0, 0), (dx, dy), (dx, 0), (0, dy)} <= cells:
                            return np.zeros((space.height, space.width))
        rate = min(rate, float(space.durations[c]) / math.hypot(dx, dy))
    if not math.isfinite(rate) or rate <= 0:
        return np.zeros((space.height, space.width))
    return grid_distance(space.workspace, goal_cell, diagonals=diagonal) * rate


# --- the compiled searches ----------------------------------------------------------------------------
def _valid(e, fc, usable, radius, clear, free, sweep_ptr, sweep_off):
    """Whether entry e is a usable command at the framed cell fc: its sweep within the cell's clear radius,
    or every swept cell free."""
    if usable[e] == 0:
        return False
    if clear[fc] > radius[e]:
        return True
    for k in range(sweep_ptr[e], sweep_ptr[e + 1]):
        if free[fc + sweep_off[k]] == 0:
            return False
    return True


@lazy_jit(calls=("_valid",))
def _bucket_kernel(state, goal, n_sh, w, wf, m, n_commands, usable, target_sh, radius, dx, dy, sweep_ptr,
                   sweep_off, free, clear, cost, h, g, unset, pbits, cbits, cap, pool, block_next, head, fill,
                   free_blocks, limit):
    """Dial's A* (h = 0: Dijkstra) over integer quanta, resumable.

    ``state`` = [status, current f, entries queued, blocks free, poses expanded]; the queue is a ring of
    ``len(head)`` buckets over f, bucket b a stack of blocks of ``BLOCK`` pose ids in ``pool`` (block
    ``head[b]`` on top holding ``fill[b]`` entries, linked by ``block_next``), free blocks in
    ``free_blocks[:state[3]]``. ``g[pose]`` packs cost << pbits | parent (sh << cbits | command); ``unset``
    is unreached. Returns when the goal is taken (status 0), the queue runs dry (1), a cost exceeds
    ``cap`` (2), fewer free blocks remain than a pose's commands may need (3: grow the pool and call
    again), an f would leave the ring (4, impossible with a consistent h), or ``limit`` poses have been
    expanded (5: call again to go on).
    """
    nb = len(head)
    block = len(pool) // len(block_next)
    cur, queued, n_free, expanded = state[1], state[2], state[3], state[4]
    status = _UNREACHABLE_
    while queued > 0:
        if expanded >= limit:
            status = _PAUSE_
            break
        b = cur % nb
        if head[b] < 0:
            cur += 1
            continue
        if n_free < n_commands:
            status = _GROW_
            break
        top = head[b]
        fill[b] -= 1
        pose = pool[top * block + fill[b]]
        if fill[b] == 0:
            head[b] = block_next[top]
            fill[b] = block if head[b] >= 0 else 0
            free_blocks[n_free] = top
            n_free += 1
        queued -= 1
        word = np.int64(g[pose])
        gq = word >> pbits
        cell = pose // n_sh
        sh = pose - cell * n_sh
        if gq + h[cell] != cur:
            continue  # stale: the pose was reached more cheaply since
        if pose == goal:
            status = _FOUND_
            break
        expanded += 1
        y = cell // w
        x = cell - y * w
        fc = (y + m) * wf + x + m
        base = sh * n_commands
        for c in range(n_commands):
            e = base + c
            if not _valid(e, fc, usable, radius, clear, free, sweep_ptr, sweep_off):
                continue
            ncell = cell + dy[c] * w + dx[c]
            hv = h[ncell]
            if hv < 0:
                continue  # B2 cannot reach the goal from there
            child = ncell * n_sh + target_sh[e]
            ng = gq + cost[c]
            old = np.int64(g[child])
            if old != unset and (old >> pbits) <= ng:
                continue
            if ng > cap:
                state[0] = _OVERFLOW_
                return
            g[child] = (ng << pbits) | (sh << cbits) | c
            f = ng + hv
            if f - cur >= nb or f < cur:
                state[0] = _RANGE_
                return
            fb = f % nb
            if head[fb] < 0 or fill[fb] == block:
                n_free -= 1
                nxt = free_blocks[n_free]
                block_next[nxt] = head[fb]
                head[fb] = nxt
                fill[fb] = 0
            pool[head[fb] * block + fill[fb]] = child
            fill[fb] += 1
            queued += 1
    state[0], state[1], state[2], state[3], state[4] = status, cur, queued, n_free, expanded


def _sift_down(keys, nodes, size, i):
    key, node = keys[i], nodes[i]
    while True:
        child = 2 * i + 1
        if child >= size:
            break
        if child + 1 < size and keys[child + 1] < keys[child]:
            child += 1
        if keys[child] >= key:
            break
        keys[i], nodes[i] = keys[child], nodes[child]
        i = child
    keys[i], nodes[i] = key, node


@lazy_jit(calls=("_valid", "_sift_down"))
def _heap_kernel(state, goal, n_sh, w, wf, m, n_commands, usable, target_sh, radius, dx, dy, sweep_ptr,
                 sweep_off, free, clear, cost, h, g, parent, cbits, keys, nodes, limit):
    """A* (h = 0: Dijkstra) over float64 costs with a binary heap on arrays, resumable.

    ``state`` = [status, heap size, poses expanded]; ``g`` is inf where unreached and ``parent[pose]`` is
    sh << cbits | command. Status 0: the goal was taken; 1: the heap ran dry; 3: the heap's arrays
    may not hold a pose's successors (grow them and call again); 5: ``limit`` poses have been expanded
    (call again to go on).
    """
    size, expanded = state[1], state[2]
    status = _UNREACHABLE_
    while size > 0:
        if expanded >= limit:
            status = _PAUSE_
            break
        if size + n_commands > len(keys):
            status = _GROW_
            break
        f, pose = keys[0], nodes[0]
        size -= 1
        if size > 0:
            keys[0], nodes[0] = keys[size], nodes[size]
            _sift_down(keys, nodes, size, 0)
        cell = pose // n_sh
        sh = pose - cell * n_sh
        gv = g[pose]
        if gv + h[cell] != f:
            continue  # stale
        if pose == goal:
            status = _FOUND_
            break
        expanded += 1
        y = cell // w
        x = cell - y * w
        fc = (y + m) * wf + x + m
        base = sh * n_commands
        for c in range(n_commands):
            e = base + c
            if not _valid(e, fc, usable, radius, clear, free, sweep_ptr, sweep_off):
                continue
            ncell = cell + dy[c] * w + dx[c]
            hv = h[ncell]
            if hv == np.inf:
                continue
            child = ncell * n_sh + target_sh[e]
            ng = gv + cost[c]
            if ng + 1e-9 >= g[child]:
                continue  # equal costs summed in another order differ by rounding: not an improvement
            g[child] = ng
            parent[child] = (sh << cbits) | c
            key = ng + hv
            i = size  # sift up
            size += 1
            while i > 0:
                up = (i - 1) // 2
                if keys[up] <= key:
                    break
                keys[i], nodes[i] = keys[up], nodes[up]
                i = up
            keys[i], nodes[i] = key, child
    state[0], state[1], state[2] = status, size, expanded


_FOUND_, _UNREACHABLE_, _OVERFLOW_, _GROW_, _RANGE_, _PAUSE_ = (  # numba globals
    _FOUND, _UNREACHABLE, _OVERFLOW, _GROW, _RANGE, _PAUSE)


def _bucket_search(*args) -> None:
    """:func:`_bucket_kernel` to its end, by :func:`_run`: its arguments but ``limit``, then whether the
    interpreter may run it; ``args[18]`` is ``g``."""
    _run(_bucket_kernel, args[:-1], 4, (18,), args[-1])


def _heap_search(*args) -> None:
    """:func:`_heap_kernel` to its end, by :func:`_run`: its arguments but ``limit``, then whether the interpreter
    may run it; ``args[18:20]`` are ``g, parent``."""
    _run(_heap_kernel, args[:-1], 2, (18, 19), args[-1])


def _run(kernel, args, expanded_at: int, kept: tuple[int, ...], interpret: bool) -> None:
    """``kernel(*args, limit)`` to its end (any status but 5): if ``interpret`` (a pose space of at most
    :data:`_INTERPRETED_POSES` whose lists fit the memory budget), in the interpreter while the process's
    budget of :data:`_INTERPRETED` expansions lasts and the kernel has not been loaded; then compiled.

    ``args[0]`` is the kernel's state (poses expanded at ``expanded_at``); the interpreter runs on lists
    (3 times faster than on numpy's scalars), copied back into the arrays of ``kept`` (those read after the
    search ends) and, when the search is to go on, into every array.
    """
    global _interpreted_left
    state = args[0]
    if interpret and not kernel.loaded() and _interpreted_left > 0:
        listed = [a.tolist() if isinstance(a, np.ndarray) else a for a in args]
        before = int(state[expanded_at])
        kernel.interpreted(*listed, before + _interpreted_left)
        status = listed[0][0]
        resumed = status in (_GROW, _PAUSE)
        for i, (array, values) in enumerate(zip(args, listed)):
            if isinstance(array, np.ndarray) and (i == 0 or i in kept or (resumed and array.flags.writeable)):
                array[:] = values
        _interpreted_left -= int(state[expanded_at]) - before
        if status != _PAUSE:
            return
    kernel(*args, np.int64(2**62))


def _tables(space: PoseSpace):
    free, clear = space.framed()
    return (space.n_sh, space.width, space.framed_width, space.margin, space.n_commands, space.usable,
            space.target_sh, space.radius, space.dx, space.dy, space.sweep_ptr, space.sweep_off, free, clear)


def search_leg(space: PoseSpace, start: int, goal: int, *, astar: bool) -> tuple[list[int] | None, int]:
    """Local command columns of a minimum-time path from pose id ``start`` to ``goal`` (None if there is
    none), and the poses expanded."""
    if start == goal:
        return [], 0
    gx, gy = (int(v) for v in space.decode(goal)[:2])
    field = heuristic_field(space, (gx, gy)) if astar else np.zeros((space.height, space.width))
    q = quantum(space.durations)
    sx, sy = (int(v) for v in space.decode(start)[:2])
    if not np.isfinite(field[sy, sx]):
        return None, 0
    index = np.int32 if space.n_poses < 2**31 else np.int64
    # Inside the search a pose is cell * n_sh + sh: a cell's poses are neighbours in memory, so a pose's
    # successors (same cell, or the next cell) mostly share its cache lines.
    start, goal = (space.internal(p) for p in (start, goal))
    interpret = space.n_poses <= _INTERPRETED_POSES and (
        memory_budget() >= lazy_bytes(space.n_poses, space.n_cells, space.durations, q) + _INTERPRETED_BYTES)
    if q is not None:
        return _bucket_leg(space, start, goal, field, q, index, interpret)
    return _heap_leg(space, start, goal, field, index, interpret)


def _bucket_leg(space, start, goal, field, q, index, interpret=False):
    cost = np.rint(space.durations / q).astype(np.int64)
    # floor(h / q) of a consistent h is consistent with integer costs: floor(a) <= floor(b + c) = floor(b) + c
    h = np.where(np.isfinite(field), np.floor(field / q * (1 - 1e-12) + 1e-9), -1).astype(np.int64).ravel()
    longest = int(cost.max())
    n_buckets = 2 * longest + 2
    for wide in (False, True):
        if wide:
            g = np.full(space.n_poses, 2**62, dtype=np.int64)
            unset, cap = 2**62, (2**62 >> space.pbits) - 1
        else:
            g = np.full(space.n_poses, 2**32 - 1, dtype=np.uint32)
            unset, cap = 2**32 - 1, (((1 << _WORD_BITS) - 1) >> space.pbits) - 1
        g[start] = 0
        n_blocks = max(2 * n_buckets, 64)
        pool = np.zeros(n_blocks * BLOCK, dtype=index)  # zeros: one shared int in the interpreter's list
        block_next = np.full(n_blocks, -1, dtype=np.int64)
        head = np.full(n_buckets, -1, dtype=np.int64)
        fill = np.zeros(n_buckets, dtype=np.int64)
        free_blocks = np.arange(n_blocks, dtype=np.int64)[::-1].copy()
        f0 = int(h[start // space.n_sh])
        b = f0 % n_buckets
        top = free_blocks[n_blocks - 1]
        head[b], fill[b], pool[top * BLOCK] = top, 1, start
        state = np.array([_UNREACHABLE, f0, 1, n_blocks - 1, 0], dtype=np.int64)
        while True:
            _bucket_search(state, goal, *_tables(space), cost, h, g, unset, space.pbits, space.cbits, cap, pool,
                           block_next, head, fill, free_blocks, interpret)
            if state[0] != _GROW:
                break
            grown = max(n_blocks // 2, 64)  # the pool grows by half: numpy arrays, seen by tracemalloc
            pool = np.concatenate([pool, np.empty(grown * BLOCK, dtype=index)])
            block_next = np.concatenate([block_next, np.full(grown, -1, dtype=np.int64)])
            n_free = int(state[3])
            free_blocks = np.concatenate([free_blocks[:n_free], np.arange(n_blocks, n_blocks + grown),
                                          np.zeros(n_blocks - n_free, dtype=np.int64)])
            state[3] = n_free + grown
            n_blocks += grown
        if state[0] == _RANGE:
            raise PlanningError("internal error: the exact search's heuristic is not consistent")
        if state[0] != _OVERFLOW:
            break
        del g, pool
    if state[0] == _UNREACHABLE:
        return None, int(state[4])
    mask, cmask = (1 << space.pbits) - 1, (1 << space.cbits) - 1
    return _walk_back(space, start, goal, lambda p: int(g[p]) & mask, cmask), int(state[4])


def _heap_leg(space, start, goal, field, index, interpret=False):
    h = (field * (1 - 1e-12)).ravel()
    g = np.full(space.n_poses, np.inf)
    parent = np.zeros(space.n_poses, dtype=np.uint16)
    g[start] = 0.0
    keys = np.empty(_HEAP_START)
    nodes = np.empty(_HEAP_START, dtype=index)
    keys[0], nodes[0] = h[start // space.n_sh], start
    state = np.array([_UNREACHABLE, 1, 0], dtype=np.int64)
    while True:
        _heap_search(state, goal, *_tables(space), space.durations, h, g, parent, space.cbits, keys, nodes, interpret)
        if state[0] != _GROW:
            break
        keys = np.concatenate([keys, np.empty(len(keys) // 2)])
        nodes = np.concatenate([nodes, np.empty(len(nodes) // 2, dtype=index)])
    if state[0] == _UNREACHABLE:
        return None, int(state[2])
    return _walk_back(space, start, goal, lambda p: int(parent[p]), (1 << space.cbits) - 1), int(state[2])


def _walk_back(space: PoseSpace, start: int, goal: int, parent_of, cmask: int) -> list[int]:
    """The commands from ``start`` to ``goal`` by the back pointers: a pose's parent is its cell minus the
    command's shift, at the (state, heading) the pointer holds."""
    steps, pose = [], goal
    while pose != start:
        p = parent_of(pose)
        c, sh = p & cmask, p >> space.cbits
        cell = pose // space.n_sh - int(space.dy[c]) * space.width - int(space.dx[c])
        steps.append(c)
        pose = cell * space.n_sh + sh
        if len(steps) > space.n_poses:
            raise PlanningError("internal error: the exact search's back pointers loop")
    return steps[::-1]
