"""Batch simulation of motion-command sequences by table lookup (the hot path of every GA).

A :class:`Simulator` compiles, once per workspace, command set, timing and clearance, a transition
table ``next[pose, command]``: poses are the flat ids ``((state * 4 + heading) * H + y) * W + x``,
``next`` holds the pose after the command or ``dead`` where the command's swept cells are not all
inside the map and free, and an extra ``pad`` command leaves every pose unchanged. Simulating a batch
is then one add and one gather per sequence and step, in a loop compiled by numba (:func:`_walk`; as
numpy calls on the whole batch, a step cost a few microseconds of call overhead whatever the batch,
and a repairing step several times that): the table is kept premultiplied by its column count, so a
gathered value plus the next command is the next index. Moving obstacles add, per time step, a
sorted array of blocked ``pose * n_columns + command`` keys (the swept-cell table turned inside out),
searched once per sequence and step. :func:`transitions_at` gives the table's rows
at some cells only, from the same sweep check, for maps whose whole table would not fit in memory.

Time for moving obstacles is the number of commands executed (MODEL.md §5): command number t (from 0,
counted from ``t0``) must keep its swept cells clear of every cell a moving obstacle covers between
times t and t + 1.
"""

from __future__ import annotations

import contextlib
import contextvars
import math
import os
import reprlib
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from htetro_opt._jit import lazy_jit
from htetro_opt._validation import check_bool, check_int
from htetro_opt.errors import ConfigurationError, ParameterError, PlanningError, UnknownCommandError
from htetro_opt.model.commands import (
    COMMANDS,
    N_COMMANDS,
    TOKENS,
    Timing,
    _token_list,
    command_id,
    command_set,
)
from htetro_opt.model.robot import N_HEADINGS, N_NAMED, N_STATES, STATE_NAMES, Pose, as_pose, shape_index
from htetro_opt.model.sweeps import SweepTables, sweep_tables
from htetro_opt.model.workspace import Workspace, check_workspace, describe_cells

__all__ = ["Simulator", "SimulationResult", "simulate", "MEMORY_BUDGET", "memory_budget", "table_shape",
           "compile_bytes", "cells_within", "map_text", "size_text", "check_memory", "transitions_at", "budget_of",
           "replay", "Replay"]

_STOP = command_id("stop")

MEMORY_BUDGET = 4 * 2**30
"""Most bytes the simulator's tables (and the exact planner's graph over them) may take, 4 GiB: the
budget is this or half the machine's physical memory, whichever is smaller (:func:`memory_budget`).
A map that would need more is refused before anything is allocated, with what would fit."""

_ROWS_PER_SORT = 1 << 16
"""Poses whose valid commands the repair sorts at a time (bounds the sort's temporary arrays)."""

@lazy_jit
def _summary(keys, lengths, goal_keys, stop_at_goal, dead_key, n_columns, progress, first_invalid, executed,
             final_ids):
    """The integer outcome of a run, per sequence (column ``b`` of the (L + 1, B) ``keys``), into the
    arrays given: the roadmap progress (the first step at or after the previous hit where the next
    pose is met), the first invalid command (-1 if none) before the run's end (the goal's step with
    ``stop_at_goal``), the commands executed and the final pose id. :meth:`Simulator._summarise`
    compiled (:func:`htetro_opt._jit.lazy_jit`): as numpy calls on the whole (L + 1, B) array it cost a
    dozen passes over it."""
    width = keys.shape[0] - 1
    n_goals = len(goal_keys)
    for b in range(keys.shape[1]):
        k, when = 0, 0
        while k < n_goals:
            t = when
            while t <= width and keys[t, b] != goal_keys[k]:
                t += 1
            if t > width:
                break
            k, when = k + 1, t
        progress[b] = k + 1
        run_length = lengths[b]
        if stop_at_goal and n_goals and k == n_goals:
            run_length = min(run_length, when)
        first_invalid[b] = -1
        for t in range(1, min(run_length, width) + 1):
            if keys[t, b] == dead_key:
                first_invalid[b] = t - 1
                break
        executed[b] = first_invalid[b] if first_invalid[b] >= 0 else run_length
        final_ids[b] = keys[executed[b], b] // n_columns


def _blocked_at(blocked, lo, hi, key):
    """Whether ``key`` is among the sorted ``blocked[lo:hi]``."""
    i = lo + np.searchsorted(blocked[lo:hi], key)
    return i < hi and blocked[i] == key


@lazy_jit(calls=("_blocked_at",))  # compiled on first use: importing the model does not import numba
def _walk(keys, steps, lengths, flat, table, n_commands, dead_key, blocked, offsets, t0, repair, u, used, t):
    """The hot loop of :meth:`Simulator._step_all`, compiled: steps ``t``, ``t + 1``, … of the batch;
    returns the next step to run (``len(steps)`` when done) and the draws of ``u`` used.

    A step is, for each sequence in row order, ``key' = flat[key + command]``, dead where a moving
    obstacle blocks ``key + command`` (``blocked[offsets[p]:offsets[p + 1]]``, sorted, at the phase
    p = (t0 + t) mod the period, ``len(offsets) − 1``). With
    ``repair``, a command that kills a live sequence is replaced as :meth:`Simulator.run` documents:
    where no obstacle moves at that step, by the ⌊u·n⌋-th of the pose's n valid columns (``table``,
    see :attr:`Simulator._valid_columns`; one draw, none when n = 0); where one does, by the valid
    command of largest draw among one draw per command (n_commands draws, whether or not any is
    valid). The draws are taken from ``u`` in order, so in step order, then row order: the order in
    which the numpy loop this replaced drew them from the generator. The loop stops early, before a
    step, when ``u`` might not hold that step's draws; the caller refills it and calls again.
    """
    width, batch = steps.shape
    period = len(offsets) - 1
    while t < width:
        if t % 8 == 0 and t:
            live = False
            for r in range(batch):
                if keys[t, r] != dead_key and lengths[r] > t:
                    live = True
                    break
            if not live:  # every sequence has died or ended: nothing changes any more
                for s in range(t + 1, width + 1):
                    keys[s] = keys[t]
                return width, used
        phase = (t0 + t) % period
        lo, hi = offsets[phase], offsets[phase + 1]
        if repair and len(u) - used < batch * (n_commands if hi > lo else 1):
            return t, used
        for r in range(batch):
            here = keys[t, r]
            index = here + steps[t, r]
            after = flat[index]
            if hi > lo and _blocked_at(blocked, lo, hi, index):
                after = dead_key
            if repair and after == dead_key and here != dead_key:
                if hi > lo:  # the static table does not know the moving obstacles: test every command
                    best, best_u = 0, -2.0
                    for c in range(n_commands):
                        key = here + c
                        value = u[used + c] if flat[key] != dead_key and not _blocked_at(blocked, lo, hi, key) else -1.0
                        if value > best_u:  # the first of equals, as argmax
                            best, best_u = c, value
                    used += n_commands
                    if best_u >= 0.0:
                        steps[t, r] = best
                        after = flat[here + best]
                else:
                    n_valid = table[here + n_commands]
                    if n_valid > 0:
                        pick = table[here + int(u[used] * n_valid)]
                        used += 1
                        steps[t, r] = pick
                        after = flat[here + pick]
            keys[t + 1, r] = after
        t += 1
    return t, used


_BUDGET_TEXT = "the smaller of htetro_opt.model.simulate.MEMORY_BUDGET and half the physical memory"
_GIVEN = contextvars.ContextVar("memory_budget", default=None)  # (bytes, where it was set) within budget_of


@contextlib.contextmanager
def budget_of(nbytes: int | None, source: str = "the memory_budget given"):
    """Within the block, :func:`memory_budget` is ``nbytes`` (None: the default), and refusals say it
    was set by ``source`` (e.g. a method's ``memory_budget`` option, the command line's ``--memory-budget``).

    Examples
    --------
    >>> with budget_of(2**30):
    ...     memory_budget()
    1073741824
    """
    token = _GIVEN.set(None if nbytes is None else (int(nbytes), source))
    try:
        yield
    finally:
        _GIVEN.reset(token)


def memory_budget() -> int:
    """Bytes the tables of one simulator (and a search over them) may take: :data:`MEMORY_BUDGET`,
    or half the physical memory where that is less (``os.sysconf``; where it is unknown, the
    constant alone); within :func:`budget_of`, the budget given there.

    Examples
    --------
    >>> 0 < memory_budget() <= MEMORY_BUDGET
    True
    """
    given = _GIVEN.get()
    if given is not None:
        return given[0]
    try:
        physical = os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (AttributeError, ValueError, OSError):  # not a POSIX system, or the names are unknown
        return MEMORY_BUDGET
    return min(MEMORY_BUDGET, physical // 2) if physical > 0 else MEMORY_BUDGET


def _resolve_commands(commands, diagonals: bool) -> tuple[int, ...]:
    """Global ids of a simulator's command set: the default (with ``diagonals``), tokens or ids."""
    diagonals = check_bool(diagonals, "diagonals")
    if commands is None:
        return command_set(diagonals=diagonals)
    if isinstance(commands, str):
        return command_set(tokens=commands)
    listed = _token_list(commands, "commands")
    if all(isinstance(c, str) for c in listed):
        return command_set(tokens=listed)
    try:
        listed = [check_int(c, "command id", minimum=0, maximum=N_COMMANDS - 1) for c in listed]
    except ParameterError as err:
        raise UnknownCommandError(f"a command set is all tokens or all command ids: {err}") from err
    return command_set(tokens=[TOKENS[c] for c in listed])


def _states_of(ids) -> int:
    """Number of robot states a command set reaches: the intermediate ones only with block commands."""
    uses_blocks = any(COMMANDS[c].kind == "block" and any(COMMANDS[c].hinge_delta) for c in ids)
    return N_STATES if uses_blocks else N_NAMED


def _sweep_validity(tables: SweepTables, command_ids: np.ndarray, n_states: int, free_at) -> np.ndarray:
    """``valid[state, heading, command, *cells]``: MODEL.md §4's check of a command set at some B2 cells.

    The one implementation of the sweep check, for the :class:`Simulator`'s whole map and for
    :func:`transitions_at`'s cells: ``free_at(offsets)`` takes the ``(D, 2)`` distinct swept-cell
    offsets ``(ox, oy)`` and returns, shape ``(D, *cells)``, whether the cell at each offset from each
    B2 cell is inside the map and free. A command is valid where it is legal in the state and all its
    swept cells are free.
    """
    offsets = tables.offsets[:n_states, :, command_ids]  # (S, 4, C, K, 2)
    # One integer key per offset: np.unique(axis=0) sorts the rows as structured values, far slower.
    span = int(np.abs(offsets).max())
    base = 2 * span + 1
    keys, inverse = np.unique((offsets[..., 0] + span) * base + offsets[..., 1] + span, return_inverse=True)
    distinct = np.column_stack([keys // base - span, keys % base - span])  # (D, 2) of (ox, oy)
    shifted = free_at(distinct)
    which = inverse.reshape(offsets.shape[:-1])
    valid = shifted[which[..., 0]]
    for k in range(1, which.shape[-1]):
        valid &= shifted[which[..., k]]
    legal = tables.legal[:n_states, command_ids]
    valid &= legal.reshape(legal.shape[0], 1, legal.shape[1], *(1,) * (shifted.ndim - 1))
    return valid


def _target_entries(tables: SweepTables, command_ids: np.ndarray, n_states: int, height: int,
                    width: int) -> np.ndarray:
    """``(S, 4, C)`` target pose id minus the start cell's ``y * W + x``: with the pose ids
    ``((state' * 4 + heading') * H + y + dy) * W + x + dx`` split into a per-(state, heading, command)
    part and a per-cell part. Meaningless where the command is illegal or invalid: callers mask those."""
    target_state = tables.next_state[:n_states][:, command_ids].clip(0)  # (S, C)
    target_heading = tables.next_heading[:n_states][:, :, command_ids]  # (S, 4, C)
    dx, dy = tables.shift[command_ids, 0], tables.shift[command_ids, 1]
    return ((target_state[:, None, :] * N_HEADINGS + target_heading) * height + dy) * width + dx


def table_shape(workspace: Workspace, *, commands=None, diagonals: bool = False) -> tuple[int, int]:
    """``(n_poses, n_commands)`` of the :class:`Simulator` these options compile, without compiling it.

    Examples
    --------
    >>> table_shape(Workspace(np.zeros((10, 10), dtype=bool)))  # 7 shapes x 4 headings x 100 cells
    (2800, 13)
    """
    check_workspace(workspace)
    ids = _resolve_commands(commands, diagonals)
    return _states_of(ids) * N_HEADINGS * workspace.height * workspace.width, len(ids)


def _table_dtype(n_poses: int, n_commands: int):
    return np.int32 if (n_poses + 1) * (n_commands + 1) < 2**31 else np.int64


def compile_bytes(n_poses: int, n_commands: int, *, repair: bool = True) -> int:
    """Peak bytes of compiling a :class:`Simulator` (and of running it) for ``n_poses`` poses and
    ``n_commands`` commands.

    The peak is the transition table (``(n_poses + 1) x (n_commands + 1)`` int32, int64 past 2³¹
    entries) and, from the first run, the table premultiplied by its column count, one more table of
    the same size; plus, per pose and command, one byte of the bool validity table the table is built
    from or, with ``repair`` (runs that repair, as the GAs' do), the two bytes of every pose's valid
    commands and of their count (int16), sorted a slice of poses at a time
    (tests/model/test_simulate.py compares this with tracemalloc's peak).

    Examples
    --------
    >>> round(compile_bytes(28_000_000, 13) / 10**6)  # bytes a cell of a 1000 x 1000 map, 28 poses a cell
    4237
    """
    entries = (n_poses + 1) * (n_commands + 1)
    tables = 2 * entries * np.dtype(_table_dtype(n_poses, n_commands)).itemsize
    if not repair:
        return tables + n_poses * n_commands
    sorting = 10 * min(n_poses, _ROWS_PER_SORT) * n_commands  # argsort's int64 result and its bool input
    return tables + 3 * n_poses * n_commands + sorting


def cells_within(bytes_for_cells, budget: int | None = None) -> int:
    """The most cells ``c`` with ``bytes_for_cells(c) <= budget`` (default :func:`memory_budget`);
    ``bytes_for_cells`` must grow with ``c``.

    Examples
    --------
    >>> cells_within(lambda c: 1000 * c, budget=10**6)
    1000
    """
    budget = memory_budget() if budget is None else budget
    lo, hi = 0, 1
    while bytes_for_cells(hi) <= budget:
        lo, hi = hi, hi * 2
    while hi - lo > 1:
        mid = (lo + hi) // 2
        lo, hi = (mid, hi) if bytes_for_cells(mid) <= budget else (lo, mid)
    return lo


def map_text(cells: int) -> str:
    """"a map of at most N cells (e.g. s x s)", for the messages of :func:`check_memory`'s callers."""
    side = math.isqrt(cells)
    return f"a map of at most {cells:,} cells (e.g. {side} x {side})"


def check_memory(needed: int, what: str, advice: str) -> None:
    """Refuse, before allocating, tables that would take more than :func:`memory_budget`.

    Raises
    ------
    PlanningError
        Saying what would need how much memory, the budget, and ``advice`` (what would fit).
    """
    budget = memory_budget()
    if needed > budget:
        given = _GIVEN.get()
        raise PlanningError(f"{what} would need about {size_text(needed)} of memory, more than the budget of "
                            f"{size_text(budget)} ({_BUDGET_TEXT if given is None else given[1]}): {advice}")


def size_text(n: int) -> str:
    """A number of bytes for a message, in GiB from 1 GiB up, in MiB from 1 MiB up, in KiB or bytes below
    (a budget of a few KiB is not "0.0 MiB").

    Examples
    --------
    >>> size_text(3 * 2**29), size_text(2**40)
    ('1.5 GiB', '1024.0 GiB')
    >>> size_text(2**20), size_text(1024), size_text(100)
    ('1.0 MiB', '1.0 KiB', '100 bytes')
    """
    if n >= 2**30:
        return f"{n / 2**30:.1f} GiB"
    if n >= 2**20:
        return f"{n / 2**20:.1f} MiB"
    return f"{n / 2**10:.1f} KiB" if n >= 2**10 else f"{int(n)} bytes"


@dataclass(frozen=True, eq=False)
class SimulationResult:
    """Outcome of simulating a batch of command sequences.

    Attributes
    ----------
    valid : ndarray of bool, shape (B,)
        No command of the run part was invalid.
    first_invalid : ndarray of int, shape (B,)
        Index of the first invalid command, −1 if none.
    executed : ndarray of int, shape (B,)
        Commands executed: those before the first invalid one (and, with ``stop_at_goal``, up to
        reaching the goal).
    reached : ndarray of bool, shape (B,)
        The executed prefix passes through the roadmap's configurations in order and ends on the last.
    progress : ndarray of int, shape (B,)
        Number of roadmap configurations passed (the start counts as the first).
    time : ndarray of float, shape (B,)
        Total duration of the executed commands.
    final : ndarray of int, shape (B, 4)
        Final (x, y, state, heading).
    trace : ndarray of int, shape (B, L + 1)
        Pose ids after each command (``simulator.dead`` once invalid); entries past ``executed`` are
        meaningless. Computed on first use.
    """

    valid: np.ndarray
    first_invalid: np.ndarray
    executed: np.ndarray
    reached: np.ndarray
    progress: np.ndarray
    time: np.ndarray
    final: np.ndarray
    simulator: "Simulator"
    keys: np.ndarray  # (L + 1, B) of pose * n_columns, as the simulation loop leaves them
    local: np.ndarray  # (B, L) of the simulator's command columns, padded with its `pad`

    def __len__(self) -> int:
        return len(self.valid)

    @cached_property
    def trace(self) -> np.ndarray:
        return (self.keys // self.simulator.n_columns).T.astype(np.int64)

    def prefix(self, i: int) -> np.ndarray:
        """The executed prefix of sequence i, as global command ids."""
        return self.simulator.command_ids[self.local[i, : self.executed[i]]]

    def sequence(self, i: int) -> np.ndarray:
        """The whole of sequence i as run (with ``repair``, the repaired commands), as global command ids."""
        row = self.local[i]
        return self.simulator.command_ids[row[row != self.simulator.pad]]

    def poses(self, i: int) -> np.ndarray:
        """Poses visited by sequence i, start included: shape (executed + 1, 4) of (x, y, state, heading)."""
        return self.simulator.decode(self.trace[i, : self.executed[i] + 1])

    def final_pose(self, i: int) -> Pose:
        x, y, s, h = (int(v) for v in self.final[i])
        return Pose(x, y, STATE_NAMES[s], h)


def _pose_id(ws, n_states: int, pose) -> int:
    """The id of ``pose`` on ``ws``'s pose grid, ((state · 4 + heading) · height + y) · width + x, as
    :meth:`Simulator.encode` numbers poses (and the graph-free exact planner's pose space), with the
    checks both make: a state the command set reaches, a cell on the map."""
    pose = as_pose(pose)
    s = shape_index(pose.shape)
    if s >= n_states:
        raise ConfigurationError(f"state {pose.shape!r} is an intermediate state: it needs Cheng et al. 2019's "
                                 "block commands (1l, 1r, 3l, 3r, 4l, 4r) in the simulator's command set")
    if not ws.contains(pose.x, pose.y):
        raise ConfigurationError(f"pose ({pose.x}, {pose.y}) lies outside the {ws.width} x {ws.height} map")
    return int(((s * N_HEADINGS + pose.heading) * ws.height + pose.y) * ws.width + pose.x)


def _check_pose(ws: Workspace, tables: SweepTables, n_states: int, pose, what: str, t: int | None) -> int:
    """:meth:`Simulator.check_pose` without a simulator (:func:`replay` and the coverage layer graph use it
    too): the pose's id, or a ConfigurationError naming ``what`` and the offending cells."""
    pose = as_pose(pose, what)
    try:
        pid = _pose_id(ws, n_states, pose)
    except ConfigurationError as err:
        raise ConfigurationError(f"{what} {tuple(pose)}: {err}") from err
    outside, occupied = ws.conflicts(tables.cells(shape_index(pose.shape), pose.heading, _STOP) + (pose.x, pose.y), t)
    conflicts = outside + occupied
    if conflicts:
        margin = f" (with clearance {tables.clearance:g})" if tables.clearance else ""
        when = "" if t is None else f" at time {t}"
        raise ConfigurationError(
            f"{what} {tuple(pose)}{margin} collides with obstacles or the map edge{when} "
            f"at {describe_cells(conflicts)}"
        )
    return pid


class Simulator:
    """Compiled transition tables of one workspace for one command set.

    Parameters
    ----------
    workspace : Workspace
    commands : iterable of str or int, optional, keyword-only
        Command tokens or ids the sequences may use; Cheng et al. 2020's set by default (plus the
        diagonals when ``diagonals``). Cheng et al. 2019's block commands bring in the 16 intermediate states.
    diagonals : bool, keyword-only
        Add the four diagonal translations to the default set.
    timing : Timing, keyword-only
    clearance : float, keyword-only
        δ in cells (MODEL.md §4).

    Examples
    --------
    >>> from htetro_opt.model import parse_commands
    >>> sim = Simulator(Workspace(np.zeros((6, 6), dtype=bool)))
    >>> result = sim.run([parse_commands("x+,x+,y+")], Pose(1, 2, "O", 0))
    >>> result.final_pose(0), float(result.time[0])
    (Pose(x=3, y=3, shape='O', heading=0), 3.0)
    """

    def __init__(
        self,
        workspace: Workspace,
        *,
        commands: Iterable[str | int] | None = None,
        diagonals: bool = False,
        timing: Timing | None = None,
        clearance: float = 0.0,
    ) -> None:
        check_workspace(workspace)
        ids = _resolve_commands(commands, diagonals)
        if timing is not None and not isinstance(timing, Timing):
            raise ParameterError(f"timing must be a Timing or None, got {type(timing).__name__} {reprlib.repr(timing)}")
        self.workspace = workspace
        self.timing = timing if timing is not None else Timing()
        self.tables: SweepTables = sweep_tables(clearance)
        self.command_ids = np.array(ids, dtype=np.int64)
        self.n_commands = len(ids)
        self.pad = self.n_commands
        self.n_columns = self.n_commands + 1
        self.n_states = _states_of(ids)
        self.n_poses = self.n_states * N_HEADINGS * workspace.height * workspace.width
        per_cell = self.n_states * N_HEADINGS
        check_memory(
            compile_bytes(self.n_poses, self.n_commands),
            f"the simulator's tables for this {workspace.width} x {workspace.height} map ({per_cell} poses a cell, "
            f"{self.n_commands} commands)",
            f"they fit {map_text(cells_within(lambda c: compile_bytes(c * per_cell, self.n_commands)))} with these "
            "commands; use a smaller map or coarser cells",
        )
        self.dead = self.n_poses
        self.local = np.full(N_COMMANDS, -1, dtype=np.int64)
        self.local[self.command_ids] = np.arange(self.n_commands)
        self.durations = np.append(self.timing.durations()[self.command_ids], 0.0)
        self.next = self._transition_table()
        self._blocked: dict[int, np.ndarray] = {}

    # --- compilation -------------------------------------------------------------------------
    def _valid_table(self, free: np.ndarray) -> np.ndarray:
        """valid[state, heading, command, y, x] for a free-cell map (True = free)."""
        h, w = free.shape

        def free_at(offsets: np.ndarray) -> np.ndarray:
            # Whole-map shifts are slices of the map framed by blocked cells: no index arrays of map size.
            margin = int(np.abs(offsets).max()) + 1
            framed = np.zeros((h + 2 * margin, w + 2 * margin), dtype=bool)  # outside the map is blocked
            framed[margin : margin + h, margin : margin + w] = free
            return np.stack([framed[margin + oy : margin + oy + h, margin + ox : margin + ox + w]
                             for ox, oy in offsets])

        return _sweep_validity(self.tables, self.command_ids, self.n_states, free_at)

    def _transition_table(self) -> np.ndarray:
        ws = self.workspace
        h, w, S, C = ws.height, ws.width, self.n_states, self.n_commands
        dtype = _table_dtype(self.n_poses, self.n_commands)
        blocked = self._valid_table(~ws.occupancy).transpose(0, 1, 3, 4, 2)  # (S, 4, H, W, C)
        np.logical_not(blocked, out=blocked)
        entry = _target_entries(self.tables, self.command_ids, S, h, w)
        cell = np.arange(h * w, dtype=dtype).reshape(h, w)
        table = np.empty((self.n_poses + 1, self.n_columns), dtype=dtype)
        view = table[:-1, :C].reshape(S, N_HEADINGS, h, w, C)
        np.add(entry.astype(dtype)[:, :, None, None, :], cell[None, None, :, :, None], out=view)
        np.copyto(view, self.dead, where=blocked)  # putmask would copy the strided view whole
        table[:-1, C] = np.arange(self.n_poses, dtype=dtype)
        table[-1] = self.dead
        return table

    @cached_property
    def _flat_next(self) -> np.ndarray:
        """``next * n_columns`` flattened: a step is ``key' = flat[key + command]`` with key = pose * n_columns."""
        return (self.next * self.n_columns).ravel()

    @cached_property
    def _sweep_entries(self) -> np.ndarray:
        """Rows (state, heading, local command, ox, oy) of every swept cell of every legal entry."""
        t = self.tables
        rows = []
        for s in range(self.n_states):
            for h in range(N_HEADINGS):
                for ci, g in enumerate(self.command_ids):
                    if t.legal[s, g]:
                        cells = t.cells(s, h, g)
                        rows.append(np.column_stack([np.tile([s, h, ci], (len(cells), 1)), cells]))
        return np.concatenate(rows)

    def blocked_keys(self, t: int) -> np.ndarray:
        """Sorted keys ``pose * n_columns + command`` that a moving obstacle blocks at step t → t + 1."""
        ws = self.workspace
        phase = t % ws.period
        if phase not in self._blocked:
            cells = np.argwhere(ws.moving_during(phase))[:, ::-1]  # (x, y)
            e = self._sweep_entries
            px = cells[:, None, 0] - e[None, :, 3]
            py = cells[:, None, 1] - e[None, :, 4]
            inside = (px >= 0) & (px < ws.width) & (py >= 0) & (py < ws.height)
            pose = ((e[None, :, 0] * N_HEADINGS + e[None, :, 1]) * ws.height + py) * ws.width + px
            keys = pose * self.n_columns + e[None, :, 2]
            self._blocked[phase] = np.unique(keys[inside])
        return self._blocked[phase]

    # --- poses -------------------------------------------------------------------------------
    def encode(self, pose: Pose) -> int:
        """Flat pose id of a pose.

        Raises
        ------
        ConfigurationError
            If the pose is outside the map or its state is not used by this simulator.
        """
        return _pose_id(self.workspace, self.n_states, pose)

    def decode(self, ids) -> np.ndarray:
        """(x, y, state, heading) of flat pose ids, shape (..., 4)."""
        ids = np.asarray(ids, dtype=np.int64)
        ws = self.workspace
        x = ids % ws.width
        y = (ids // ws.width) % ws.height
        sh = ids // (ws.width * ws.height)
        return np.stack([x, y, sh // N_HEADINGS, sh % N_HEADINGS], axis=-1)

    def pose_conflicts(self, pose_id: int, t: int | None = None) -> list[tuple[int, int]]:
        """Cells of a pose's footprint (with clearance) that lie outside the map or on an obstacle.

        With ``t``, moving obstacles at time t count too.
        """
        x, y, s, h = (int(v) for v in self.decode(pose_id))
        outside, occupied = self.workspace.conflicts(self.tables.cells(s, h, _STOP) + (x, y), t)
        return outside + occupied

    def check_pose(self, pose: Pose, *, what: str = "pose", t: int | None = None) -> int:
        """Encode a pose and check it is collision-free; its flat id.

        Raises
        ------
        ConfigurationError
            Naming ``what`` (e.g. "start") and the offending cells if the pose lies outside the map or
            collides.
        """
        return _check_pose(self.workspace, self.tables, self.n_states, pose, what, t)

    # --- simulation --------------------------------------------------------------------------
    def _local_commands(self, sequences) -> tuple[np.ndarray, np.ndarray]:
        """Sequences of global ids as one (B, L) array of local columns, padded with ``pad``."""
        if isinstance(sequences, np.ndarray) and sequences.ndim == 2:
            if sequences.size and not np.issubdtype(sequences.dtype, np.integer):
                raise ParameterError(f"sequences must hold integer command ids, got an array of {sequences.dtype}")
            ids = sequences.astype(np.int64, copy=False)
            lengths = np.full(len(ids), ids.shape[1], dtype=np.int64)
            present = None
        else:
            if isinstance(sequences, (str, bytes)) or not isinstance(sequences, Iterable):
                raise ParameterError(
                    "sequences must be a batch of command-id sequences (e.g. [parse_commands('x+,y+')]), "
                    f"got {type(sequences).__name__} {reprlib.repr(sequences)}")
            arrays = sequences if type(sequences) is list and all(
                type(s) is np.ndarray and s.dtype == np.int64 and s.ndim == 1 for s in sequences
            ) else [_command_ids(s, i) for i, s in enumerate(sequences)]  # the GAs' batches pass as they are
            lengths = np.fromiter((len(a) for a in arrays), dtype=np.int64, count=len(arrays))
            width = int(lengths.max()) if len(lengths) else 0
            present = np.arange(width)[None, :] < lengths[:, None]
            ids = np.concatenate(arrays).astype(np.int64, copy=False) if width else np.empty(0, np.int64)
        bad = (ids < 0) | (ids >= N_COMMANDS)
        if bad.any():
            raise UnknownCommandError(f"command id {int(ids[bad][0])} is not a command")
        mapped = self.local[ids]
        if (mapped < 0).any():
            token = TOKENS[int(ids[mapped < 0][0])]
            raise UnknownCommandError(f"command {token!r} is not in this simulator's command set")
        if present is None:
            return mapped, lengths
        local = np.full(present.shape, self.pad, dtype=np.int64)
        local[present] = mapped
        return local, lengths

    def run(
        self,
        sequences: Sequence[Sequence[int]] | np.ndarray,
        start: Pose | int,
        *,
        roadmap: Sequence[Pose] | None = None,
        t0: int = 0,
        stop_at_goal: bool = False,
        repair: np.random.Generator | None = None,
    ) -> SimulationResult:
        """Simulate a batch of command sequences from one start pose.

        Parameters
        ----------
        sequences : sequence of int arrays
            Global command ids (see :func:`parse_commands`), of any lengths; a 2-D array is a batch of
            equal-length sequences.
        start : Pose or int
            Start pose (or its flat id).
        roadmap : sequence of Pose, optional, keyword-only
            Configurations to pass through in order after the start; the last is the goal.
        t0 : int, keyword-only
            Time index (commands already executed) at the start, for moving obstacles.
        stop_at_goal : bool, keyword-only
            End each sequence when it reaches the goal (Cheng et al. 2020's child termination).
        repair : numpy.random.Generator, optional, keyword-only
            Replace every command that would be invalid where it is executed by one drawn uniformly
            from the commands valid there (a sequence dies only where none is); the result's
            ``local`` (and :meth:`SimulationResult.sequence`) hold the repaired commands.

        Returns
        -------
        SimulationResult

        Raises
        ------
        ConfigurationError
            If the start pose collides or a roadmap pose lies outside the map.
        UnknownCommandError
            If a sequence uses a command outside this simulator's set.
        """
        t0 = check_int(t0, "t0", minimum=0)
        stop_at_goal = check_bool(stop_at_goal, "stop_at_goal")
        if repair is not None and not isinstance(repair, np.random.Generator):
            raise ParameterError(f"repair must be a numpy.random.Generator or None, got {reprlib.repr(repair)}")
        if isinstance(start, (int, np.integer)) and not isinstance(start, (bool, np.bool_)):
            if not 0 <= start < self.n_poses:
                raise ConfigurationError(f"start pose id {start} is not a pose id of this simulator "
                                         f"(0…{self.n_poses - 1})")
            start_id = int(start)
        else:
            start_id = self.check_pose(start, what="start", t=t0)
        if roadmap is None:
            roadmap = ()
        elif isinstance(roadmap, (str, bytes, Pose)) or not isinstance(roadmap, Iterable):
            raise ParameterError(f"roadmap must be a sequence of poses or None, got {type(roadmap).__name__} "
                                 f"{reprlib.repr(roadmap)}")
        goals = np.array([self.encode(as_pose(p, f"roadmap[{i}]")) for i, p in enumerate(roadmap)], dtype=np.int64)
        local, lengths = self._local_commands(sequences)
        keys, local = self._step_all(local, lengths, start_id * self.n_columns, t0, repair)
        return self._summarise(keys, local, lengths, goals * self.n_columns, stop_at_goal)

    def _step_all(self, local: np.ndarray, lengths: np.ndarray, start_key: int, t0: int,
                  repair: np.random.Generator | None = None) -> tuple[np.ndarray, np.ndarray]:
        """The hot loop: keys ``pose * n_columns`` after each step, shape (L + 1, B), and the (B, L)
        local commands as run (``local`` itself unless ``repair`` changed some).

        Each step is one gather per sequence, compiled (:func:`_walk`); moving obstacles add a
        binary search among the keys they block at that step. With ``repair``, a command that kills
        a live sequence is replaced by a valid one; padding never dies, so it is never repaired.
        The repair's draws come from ``repair`` in step order, then row order: :func:`_walk` takes
        them from a buffer drawn ahead, and the generator is then moved on by exactly the draws
        used (its state restored, the used draws drawn again), so it ends where drawing them one
        step at a time would leave it.
        """
        batch, width = local.shape
        flat = self._flat_next
        dead_key = self.dead * self.n_columns
        steps = np.array(local.T, dtype=flat.dtype, order="C")  # (L, B): a contiguous row per step, a copy repair may change
        keys = np.empty((width + 1, batch), dtype=flat.dtype)
        keys[0] = start_key
        offsets, blocked = self._blocked_by_phase
        table = self._valid_columns if repair is not None else np.zeros(1, dtype=np.int16)
        lengths = np.asarray(lengths, dtype=np.int64)
        per_row = self.n_commands if len(blocked) else 1  # the most draws a sequence takes at a step
        t, u = 0, np.zeros(0)
        while t < width:
            if repair is not None:
                state = repair.bit_generator.state
                u = repair.random(max(4096, 4 * batch * per_row))
                repair.bit_generator.state = state
            t, used = _walk(keys, steps, lengths, flat, table, self.n_commands, dead_key, blocked, offsets,
                            t0, repair is not None, u, 0, t)
            if used:
                repair.random(used)  # the generator moves on by the draws the steps took
        if repair is None:
            return keys, local
        return keys, steps.T.astype(np.int64)

    @cached_property
    def _blocked_by_phase(self) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`blocked_keys` of every phase of the obstacles' period, end to end, and where each
        phase's begin (``offsets[phase]:offsets[phase + 1]``); one empty phase on a static map."""
        period = self.workspace.period if self.workspace.moving else 1
        per_phase = [self.blocked_keys(p) for p in range(period)] if self.workspace.moving else []
        offsets = np.zeros(period + 1, dtype=np.int64)
        offsets[1:] = np.cumsum([len(b) for b in per_phase]) if per_phase else 0
        blocked = np.concatenate(per_phase).astype(np.int64) if per_phase else np.zeros(0, dtype=np.int64)
        return offsets, blocked

    @cached_property
    def _valid_columns(self) -> np.ndarray:
        """The repair's table, laid out like the keys: row ``pose`` (``(n_poses + 1, n_columns)``, the
        last row the dead pose's) holds the pose's valid command columns first and, in its last
        column, how many there are; so with key = pose * n_columns, ``table.take(key + n_commands)``
        is the count and ``table.take(key + j)`` the j-th valid column, without a division."""
        n, c = self.n_poses, self.n_commands
        table = np.zeros((n + 1, self.n_columns), dtype=np.int16)  # the dead pose: no valid command
        rows, nxt, step = table[:n], self.next[:n, :c], _ROWS_PER_SORT
        for lo in range(0, n, step):  # in slices: argsort's int64 result is 4 times the int16 kept
            invalid = nxt[lo : lo + step] == self.dead
            rows[lo : lo + step, :c] = np.argsort(invalid, axis=1, kind="stable")
            rows[lo : lo + step, c] = c - invalid.sum(axis=1)
        return table.ravel()

    def _summarise(self, keys, local, lengths, goal_keys, stop_at_goal) -> SimulationResult:
        """Per-sequence outcome from the (L + 1, B) keys of a run."""
        width, batch = keys.shape[0] - 1, keys.shape[1]
        progress, first_invalid, executed, final_ids = (np.empty(batch, dtype=np.int64) for _ in range(4))
        _summary(keys, np.asarray(lengths, dtype=np.int64), np.asarray(goal_keys, dtype=np.int64),
                            bool(stop_at_goal), self.dead * self.n_columns, self.n_columns, progress, first_invalid,
                            executed, final_ids)
        done = progress == len(goal_keys) + 1
        reached = done & (final_ids * self.n_columns == goal_keys[-1]) if len(goal_keys) else np.zeros(batch, dtype=bool)
        durations = self.durations[local]
        durations[np.arange(width)[None, :] >= executed[:, None]] = 0.0
        return SimulationResult(
            valid=first_invalid < 0,
            first_invalid=first_invalid,
            executed=executed,
            reached=reached,
            progress=progress,
            time=durations.sum(axis=1),
            final=self.decode(final_ids),
            simulator=self,
            keys=keys,
            local=local,
        )


def _command_ids(sequence, i: int) -> np.ndarray:
    """One sequence of a batch as a flat integer array of command ids."""
    if isinstance(sequence, np.ndarray) and sequence.dtype.kind in "iu":  # the GAs' case, checked first
        return sequence.ravel()
    try:
        array = np.asarray(sequence)
    except (TypeError, ValueError):
        array = None
    if array is None or (array.size and not np.issubdtype(array.dtype, np.integer)) or isinstance(sequence, str):
        raise ParameterError(f"sequences[{i}] must be a sequence of integer command ids (parse_commands turns tokens "
                             f"into ids), got {reprlib.repr(sequence)}")
    return array.astype(np.int64, copy=False).ravel()


def simulate(workspace: Workspace, sequences, start: Pose, **options) -> SimulationResult:
    """Compile a :class:`Simulator` for ``workspace`` and run ``sequences`` from ``start``.

    Keyword options are split between :class:`Simulator` (commands, diagonals, timing, clearance)
    and :meth:`Simulator.run` (roadmap, t0, stop_at_goal).
    """
    compile_keys = {"commands", "diagonals", "timing", "clearance"}
    sim = Simulator(workspace, **{k: v for k, v in options.items() if k in compile_keys})
    return sim.run(sequences, start, **{k: v for k, v in options.items() if k not in compile_keys})


def transitions_at(
    workspace: Workspace,
    cells,
    *,
    commands: Iterable[str | int] | None = None,
    diagonals: bool = False,
    clearance: float = 0.0,
) -> np.ndarray:
    """Next pose of every (state, heading, command) at some B2 cells: rows of the :class:`Simulator`'s
    table without compiling it for the whole map.

    ``transitions_at(workspace, cells)[i, state, heading, j]`` is the :class:`Simulator`'s
    ``next[pose, j]`` for the pose ``(x, y, state, heading)`` of ``cells[i] = (x, y)``, with −1 for
    its ``dead``: the flat pose id ``((state' * 4 + heading') * H + y') * W + x'`` of the whole map
    (:meth:`Simulator.encode`'s numbering) after command j, or −1 where the command is not legal in
    the state or its swept cells (with clearance δ, MODEL.md §4) are not all inside the map and
    free. The Simulator's table is the all-cells case and comes from the same sweep check; this
    function takes memory in proportion to ``len(cells)`` only (beyond the workspace itself), for
    searches on maps whose full table would not fit (1.6 GB for the table alone at 1000 x 1000 with the
    default commands, :func:`compile_bytes`).

    Only the static occupancy counts: moving obstacles are ignored, as in the Simulator's ``next``
    table (its runs check them apart, per time step).

    Parameters
    ----------
    workspace : Workspace
    cells : array_like of int, shape (n, 2)
        B2 cells ``(x, y)`` inside the map; repeats are allowed.
    commands : iterable of str or int, optional, keyword-only
        Command tokens or ids, resolved as :class:`Simulator` resolves them: Cheng et al. 2020's set
        by default (plus the diagonals when ``diagonals``); Cheng et al. 2019's block commands bring
        in the 16 intermediate states.
    diagonals : bool, keyword-only
        Add the four diagonal translations to the default set.
    clearance : float, keyword-only
        δ in cells (MODEL.md §4).

    Returns
    -------
    ndarray of int64, shape (n, n_states, 4, n_commands)
        Target pose ids, −1 where invalid. ``n_states`` is 7, or 23 with block commands; the
        commands are in the order of the command set (a :class:`Simulator`'s ``command_ids``,
        :func:`command_set` for the default sets).

    Raises
    ------
    ParameterError
        If ``cells`` is not an (n, 2) array of integers, a cell lies outside the map, ``workspace``
        is not a Workspace, or an option is invalid.
    UnknownCommandError
        If a command is not in the vocabulary.

    Examples
    --------
    >>> from htetro_opt.model import shape_index
    >>> ws = Workspace(np.zeros((5, 5), dtype=bool))
    >>> ids = transitions_at(ws, [(1, 2), (3, 2)], commands="x+,x-")
    >>> ids.shape  # 2 cells, 7 shapes, 4 headings, 2 commands
    (2, 7, 4, 2)
    >>> ids[:, shape_index("O"), 0]  # the O is two cells wide: x+ from x = 3 would leave the map
    array([[112, 110],
           [ -1, 112]])
    >>> sim = Simulator(ws, commands="x+,x-")
    >>> sim.next[sim.encode(Pose(1, 2, "O", 0)), :2].tolist()
    [112, 110]
    """
    check_workspace(workspace)
    ids = np.array(_resolve_commands(commands, diagonals), dtype=np.int64)
    tables = sweep_tables(clearance)
    xy = _check_cells(cells, workspace)
    h, w = workspace.height, workspace.width
    n_states = _states_of(ids.tolist())
    occupied = workspace.occupancy
    x, y = xy[:, 0], xy[:, 1]

    def free_at(offsets: np.ndarray) -> np.ndarray:
        px, py = x[None, :] + offsets[:, :1], y[None, :] + offsets[:, 1:]  # (D, n)
        free = (px >= 0) & (px < w) & (py >= 0) & (py < h)
        free &= ~occupied[py.clip(0, h - 1), px.clip(0, w - 1)]
        return free

    valid = _sweep_validity(tables, ids, n_states, free_at)  # (S, 4, C, n)
    out = _target_entries(tables, ids, n_states, h, w)[None] + (y * w + x)[:, None, None, None]
    np.copyto(out, -1, where=~valid.transpose(3, 0, 1, 2))
    return out


@dataclass(frozen=True, eq=False)
class Replay:
    """Outcome of :func:`replay`: one command sequence run from one pose, as :meth:`Simulator.run` runs it.

    Attributes
    ----------
    valid : bool
        No command was invalid.
    first_invalid : int
        Index of the first invalid command, −1 if none.
    executed : int
        Commands executed (those before the first invalid one).
    poses : ndarray of int, shape (executed + 1, 4)
        (x, y, state, heading) before the first command and after each executed one.
    final_id : int
        The last pose's id (:meth:`Simulator.encode`'s numbering).
    time : float
        Total duration of the executed commands.
    """

    valid: bool
    first_invalid: int
    executed: int
    poses: np.ndarray
    final_id: int
    time: float


_REPLAY_CHUNK = 1 << 16
"""Commands whose swept cells :func:`replay` checks at a time (bounds its temporary arrays)."""


def replay(workspace: Workspace, sequence, start, *, commands: Iterable[str | int] | None = None,
           diagonals: bool = False, timing: Timing | None = None, clearance: float = 0.0) -> Replay:
    """Run one command sequence from one pose without compiling the :class:`Simulator`'s table.

    The same outcome as ``Simulator(workspace, ...).run([sequence], start)`` on a map without moving
    obstacles, in memory proportional to the sequence rather than to the map (the table is ~760 MB at
    384 x 384 with Cheng et al. 2019's commands, and a run doubles it): the robot's (state, heading) and
    B2's cell are followed through the sequence from the per-(state, heading, command) tables (the next
    state and heading, B2's shift), then every step's swept cells (with clearance δ) are checked at once
    against the map, MODEL.md §4's check, as the table is built from it. A command is invalid where it is
    illegal in its state or a swept cell is off the map or blocked; the run stops there.

    Parameters
    ----------
    workspace : Workspace
        Its static occupancy only (the :class:`Simulator` checks moving obstacles per step).
    sequence : sequence of int
        Global command ids (:func:`~htetro_opt.model.parse_commands` turns tokens into ids).
    start : Pose or int
        The start pose (checked collision-free), or its id (:meth:`Simulator.encode`), as
        :meth:`Simulator.run` takes it.
    commands, diagonals, timing, clearance : keyword-only
        As :class:`Simulator`'s.

    Raises
    ------
    ConfigurationError
        If the start pose collides, lies off the map or is in a state the command set does not reach.
    UnknownCommandError
        If a command is not in the command set.

    Examples
    --------
    >>> from htetro_opt.model import parse_commands
    >>> ws = Workspace(np.zeros((6, 6), dtype=bool))
    >>> r = replay(ws, parse_commands("x+,x+,y+"), Pose(1, 2, "O", 0))
    >>> r.valid, r.poses[-1].tolist(), r.time
    (True, [3, 3, 1, 0], 3.0)
    >>> replay(ws, parse_commands("x+,x+,x+,x+"), Pose(1, 2, "O", 0)).first_invalid  # the O is two cells wide
    3
    """
    check_workspace(workspace)
    ids = np.array(_resolve_commands(commands, diagonals), dtype=np.int64)
    if timing is not None and not isinstance(timing, Timing):
        raise ParameterError(f"timing must be a Timing or None, got {type(timing).__name__} {reprlib.repr(timing)}")
    timing = timing if timing is not None else Timing()
    tables = sweep_tables(clearance)
    n_states = _states_of(ids.tolist())
    if isinstance(start, (int, np.integer)) and not isinstance(start, (bool, np.bool_)):
        n_poses = n_states * N_HEADINGS * workspace.height * workspace.width
        if not 0 <= start < n_poses:
            raise ConfigurationError(f"start pose id {start} is not a pose id of this map (0…{n_poses - 1})")
        start_id = int(start)  # as Simulator.run takes an id: unchecked
    else:
        start_id = _check_pose(workspace, tables, n_states, start, "start", None)
    seq = _command_ids(sequence, 0).astype(np.int64, copy=False)
    allowed = np.zeros(N_COMMANDS, dtype=bool)
    allowed[ids] = True
    bad = (seq < 0) | (seq >= N_COMMANDS)
    if bad.any():
        raise UnknownCommandError(f"command id {int(seq[bad][0])} is not a command")
    if not allowed[seq].all():
        raise UnknownCommandError(f"command {TOKENS[int(seq[~allowed[seq]][0])]!r} is not in this command set")
    h, w = workspace.height, workspace.width
    n = len(seq)
    x0, y0 = start_id % w, (start_id // w) % h
    sh0 = start_id // (w * h)
    # the (state, heading) after each command, followed through the tables; B2's cell is the shifts' sum
    states, headings = np.empty(n + 1, dtype=np.int64), np.empty(n + 1, dtype=np.int64)
    st, hd = sh0 // N_HEADINGS, sh0 % N_HEADINGS
    states[0], headings[0] = st, hd
    next_state, next_heading, legal = tables.next_state.tolist(), tables.next_heading.tolist(), tables.legal
    first_illegal = n
    for t, c in enumerate(seq.tolist()):
        if not legal[st, c]:
            first_illegal = t
            states[t + 1:], headings[t + 1:] = st, hd
            break
        st, hd = next_state[st][c], next_heading[st][hd][c]
        states[t + 1], headings[t + 1] = st, hd
    xs = x0 + np.concatenate([[0], np.cumsum(tables.shift[seq, 0])])
    ys = y0 + np.concatenate([[0], np.cumsum(tables.shift[seq, 1])])
    first_invalid = first_illegal
    occupied = workspace.occupancy
    for lo in range(0, first_illegal, _REPLAY_CHUNK):  # the swept cells of each step, from its start pose
        hi = min(first_illegal, lo + _REPLAY_CHUNK)
        offsets = tables.offsets[states[lo:hi], headings[lo:hi], seq[lo:hi]]  # (m, K, 2)
        px, py = xs[lo:hi, None] + offsets[..., 0], ys[lo:hi, None] + offsets[..., 1]
        free = (px >= 0) & (px < w) & (py >= 0) & (py < h)
        free &= ~occupied[py.clip(0, h - 1), px.clip(0, w - 1)]
        ok = free.all(axis=1)
        if not ok.all():
            first_invalid = lo + int(np.argmin(ok))
            break
    executed = first_invalid
    poses = np.stack([xs, ys, states, headings], axis=1)[: executed + 1]
    durations = timing.durations()[seq][None, :]  # summed as Simulator.run sums its (1, L) row
    durations[:, executed:] = 0.0
    x, y, s_, hd_ = (int(v) for v in poses[-1])
    return Replay(valid=executed == n, first_invalid=-1 if executed == n else executed, executed=executed,
                  poses=poses, final_id=((s_ * N_HEADINGS + hd_) * h + y) * w + x,
                  time=float(durations.sum(axis=1)[0]))


def _check_cells(cells, workspace: Workspace) -> np.ndarray:
    """``cells`` as an (n, 2) int64 array of (x, y) cells inside the workspace."""
    try:
        array = np.asarray(cells)
    except (TypeError, ValueError) as err:  # ragged rows
        raise ParameterError(f"cells must be an (n, 2) array of (x, y) cells, got {reprlib.repr(cells)}") from err
    if array.shape == (0,):
        return np.empty((0, 2), dtype=np.int64)
    if array.ndim != 2 or array.shape[1] != 2:
        one = " (one cell is [(x, y)])" if array.shape == (2,) else ""
        raise ParameterError(f"cells must be an (n, 2) array of (x, y) cells{one}, got shape {array.shape}: "
                             f"{reprlib.repr(cells)}")
    if array.size and array.dtype.kind not in "iu":
        raise ParameterError(f"cells must hold integer (x, y) cells, got an array of {array.dtype}: "
                             f"{reprlib.repr(cells)}")
    x, y = array[:, 0], array[:, 1]
    outside = (x < 0) | (x >= workspace.width) | (y < 0) | (y >= workspace.height)
    if outside.any():
        first = int(np.flatnonzero(outside)[0])
        raise ParameterError(f"cells must lie inside the {workspace.width} x {workspace.height} map; outside it: "
                             f"{describe_cells(array[outside])} (the first at cells[{first}])")
    return array.astype(np.int64, copy=False)
