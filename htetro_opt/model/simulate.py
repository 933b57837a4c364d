"""Batch simulation of motion-command sequences by table lookup (the hot path of every GA).

A :class:`Simulator` compiles, once per workspace, command set, timing and clearance, a transition
table ``next[pose, command]``: poses are the flat ids ``((state * 4 + heading) * H + y) * W + x``,
``next`` holds the pose after the command or ``dead`` where the command's swept cells are not all
inside the map and free, and an extra ``pad`` command leaves every pose unchanged. Simulating a batch
is then one add and one gather per step for the whole batch: the table is kept premultiplied by its
column count, so a gathered value plus the next command is the next index. Moving obstacles add, per
time step, a sorted array of blocked ``pose * n_columns + command`` keys (the swept-cell table turned
inside out), checked with one ``searchsorted`` per step.

Time for moving obstacles is the number of commands executed (MODEL.md §5): command number t (from 0,
counted from ``t0``) must keep its swept cells clear of every cell a moving obstacle covers between
times t and t + 1.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from typing import Iterable, Sequence

import numpy as np

from htetro_opt._validation import check_int
from htetro_opt.errors import ConfigurationError, ParameterError, UnknownCommandError
from htetro_opt.model.commands import (
    COMMANDS,
    N_COMMANDS,
    TOKENS,
    Timing,
    command_id,
    command_set,
)
from htetro_opt.model.robot import N_HEADINGS, N_NAMED, N_STATES, STATE_NAMES, Pose, shape_index
from htetro_opt.model.sweeps import SweepTables, sweep_tables
from htetro_opt.model.workspace import Workspace

__all__ = ["Simulator", "SimulationResult", "simulate"]

_STOP = command_id("stop")


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


class Simulator:
    """Compiled transition tables of one workspace for one command set.

    Parameters
    ----------
    workspace : Workspace
    commands : iterable of str or int, optional, keyword-only
        Command tokens or ids the sequences may use; Cheng et al. 2020's set by default (plus the
        diagonals when ``diagonals``). Seed 004's block commands bring in the 16 intermediate states.
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
        if not isinstance(workspace, Workspace):
            raise TypeError(f"workspace must be a Workspace, got {type(workspace).__name__}")
        if commands is None:
            ids = command_set(diagonals=diagonals)
        else:
            listed = list(commands)
            if all(isinstance(c, str) for c in listed):
                ids = command_set(tokens=listed)
            else:
                try:
                    listed = [check_int(c, "command id", minimum=0, maximum=N_COMMANDS - 1) for c in listed]
                except ParameterError as err:
                    raise UnknownCommandError(f"a command set is all tokens or all command ids: {err}") from err
                ids = command_set(tokens=[TOKENS[c] for c in listed])
        self.workspace = workspace
        self.timing = timing if timing is not None else Timing()
        self.tables: SweepTables = sweep_tables(float(clearance))
        self.command_ids = np.array(ids, dtype=np.int64)
        self.n_commands = len(ids)
        self.pad = self.n_commands
        self.n_columns = self.n_commands + 1
        uses_blocks = any(COMMANDS[c].kind == "block" and any(COMMANDS[c].hinge_delta) for c in ids)
        self.n_states = N_STATES if uses_blocks else N_NAMED
        self.n_poses = self.n_states * N_HEADINGS * workspace.height * workspace.width
        self.dead = self.n_poses
        self.local = np.full(N_COMMANDS, -1, dtype=np.int64)
        self.local[self.command_ids] = np.arange(self.n_commands)
        self.durations = np.append(self.timing.durations()[self.command_ids], 0.0)
        self.next = self._transition_table()
        self._blocked: dict[int, np.ndarray] = {}

    # --- compilation -------------------------------------------------------------------------
    def _valid_table(self, free: np.ndarray) -> np.ndarray:
        """valid[state, heading, command, y, x] for a free-cell map (True = free)."""
        t = self.tables
        offsets = t.offsets[: self.n_states, :, self.command_ids]  # (S, 4, C, K, 2)
        margin = int(np.abs(offsets).max()) + 1
        h, w = free.shape
        framed = np.zeros((h + 2 * margin, w + 2 * margin), dtype=bool)  # outside the map is blocked
        framed[margin : margin + h, margin : margin + w] = free
        distinct, inverse = np.unique(offsets.reshape(-1, 2), axis=0, return_inverse=True)
        shifted = np.stack([
            framed[margin + oy : margin + oy + h, margin + ox : margin + ox + w] for ox, oy in distinct
        ])
        which = inverse.reshape(offsets.shape[:-1])
        valid = shifted[which[..., 0]]
        for k in range(1, which.shape[-1]):
            valid &= shifted[which[..., k]]
        legal = t.legal[: self.n_states, self.command_ids]
        valid &= legal[:, None, :, None, None]
        return valid

    def _transition_table(self) -> np.ndarray:
        t, ws = self.tables, self.workspace
        h, w, S, C = ws.height, ws.width, self.n_states, self.n_commands
        dtype = np.int32 if (self.n_poses + 1) * self.n_columns < 2**31 else np.int64
        ok = self._valid_table(~ws.occupancy).transpose(0, 1, 3, 4, 2)  # (S, 4, H, W, C)
        target_state = t.next_state[:S][:, self.command_ids].clip(0)  # (S, C)
        target_heading = t.next_heading[:S][:, :, self.command_ids]  # (S, 4, C)
        dx, dy = t.shift[self.command_ids, 0], t.shift[self.command_ids, 1]
        # pose id of the target = ((state' * 4 + heading') * H + y + dy) * W + x + dx, split into a
        # per-(state, heading, command) part and a per-cell part; out-of-map targets are masked by `ok`.
        entry = ((target_state[:, None, :] * N_HEADINGS + target_heading) * h + dy) * w + dx
        cell = np.arange(h * w, dtype=dtype).reshape(h, w)
        table = np.empty((self.n_poses + 1, self.n_columns), dtype=dtype)
        view = table[:-1, :C].reshape(S, N_HEADINGS, h, w, C)
        np.add(entry.astype(dtype)[:, :, None, None, :], cell[None, None, :, :, None], out=view)
        np.putmask(view, ~ok, self.dead)
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
        pose, ws = Pose.of(*pose), self.workspace
        s = shape_index(pose.shape)
        if s >= self.n_states:
            raise ConfigurationError(f"state {pose.shape!r} needs seed 004's block commands")
        if not ws.contains(pose.x, pose.y):
            raise ConfigurationError(f"pose ({pose.x}, {pose.y}) lies outside the {ws.width} x {ws.height} map")
        return int(((s * N_HEADINGS + pose.heading) * ws.height + pose.y) * ws.width + pose.x)

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
        try:
            pid = self.encode(pose)
        except ConfigurationError as err:
            raise ConfigurationError(f"{what} {tuple(pose)}: {err}") from err
        conflicts = self.pose_conflicts(pid, t)
        if conflicts:
            margin = f" (with clearance {self.tables.clearance:g})" if self.tables.clearance else ""
            when = "" if t is None else f" at time {t}"
            raise ConfigurationError(
                f"{what} {tuple(pose)}{margin} collides with obstacles or the map edge{when} at cells {conflicts}"
            )
        return pid

    # --- simulation --------------------------------------------------------------------------
    def _local_commands(self, sequences) -> tuple[np.ndarray, np.ndarray]:
        """Sequences of global ids as one (B, L) array of local columns, padded with ``pad``."""
        if isinstance(sequences, np.ndarray) and sequences.ndim == 2:
            ids = sequences.astype(np.int64, copy=False)
            lengths = np.full(len(ids), ids.shape[1], dtype=np.int64)
            present = None
        else:
            sequences = list(sequences)
            lengths = np.fromiter((len(s) for s in sequences), dtype=np.int64, count=len(sequences))
            width = int(lengths.max()) if len(lengths) else 0
            present = np.arange(width)[None, :] < lengths[:, None]
            ids = np.concatenate([np.asarray(s, dtype=np.int64).ravel() for s in sequences]) if width else np.empty(0, np.int64)
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
        start_id = start if isinstance(start, (int, np.integer)) else self.check_pose(start, what="start", t=t0)
        goals = np.array([self.encode(p) for p in roadmap], dtype=np.int64) if roadmap else np.empty(0, np.int64)
        local, lengths = self._local_commands(sequences)
        keys, local = self._step_all(local, lengths, start_id * self.n_columns, t0, repair)
        return self._summarise(keys, local, lengths, goals * self.n_columns, stop_at_goal)

    def _step_all(self, local: np.ndarray, lengths: np.ndarray, start_key: int, t0: int,
                  repair: np.random.Generator | None = None) -> tuple[np.ndarray, np.ndarray]:
        """The hot loop: keys ``pose * n_columns`` after each step, shape (L + 1, B), and the (B, L)
        local commands as run (``local`` itself unless ``repair`` changed some).

        Each step is one add and one gather for the whole batch; moving obstacles add one
        ``searchsorted``. With ``repair``, a command that kills a live sequence is replaced by a valid
        one (:meth:`_repair_step`); padding never dies, so it is never repaired.
        """
        batch, width = local.shape
        flat = self._flat_next
        dead_key = self.dead * self.n_columns
        steps = np.array(local.T, dtype=flat.dtype, order="C")  # (L, B): a contiguous row per step, a copy repair may change
        keys = np.empty((width + 1, batch), dtype=flat.dtype)
        keys[0] = start_key
        index = np.empty(batch, dtype=flat.dtype)
        add, take = np.add, flat.take
        moving = bool(self.workspace.moving)
        blocked = None
        for t in range(width):
            if t % 8 == 0 and t and not ((keys[t] != dead_key) & (lengths > t)).any():
                keys[t + 1 :] = keys[t]  # every sequence has died or ended: nothing changes any more
                break
            add(keys[t], steps[t], out=index)
            take(index, out=keys[t + 1])
            if moving:
                blocked = self.blocked_keys(t0 + t)
                if len(blocked):
                    at = np.searchsorted(blocked, index).clip(max=len(blocked) - 1)
                    keys[t + 1][blocked[at] == index] = dead_key
            if repair is not None:
                self._repair_step(t, steps, keys, blocked, repair)
        if repair is None:
            return keys, local
        return keys, steps.T.astype(np.int64)

    @cached_property
    def _valid_columns(self) -> tuple[np.ndarray, np.ndarray]:
        """Per pose, its valid command columns first (``(n_poses, C)``) and how many there are."""
        valid = self.next[: self.n_poses, : self.n_commands] != self.dead
        order = np.argsort(~valid, axis=1, kind="stable").astype(np.int16)
        return order, valid.sum(axis=1)

    def _repair_step(self, t: int, steps: np.ndarray, keys: np.ndarray, blocked: np.ndarray | None,
                     rng: np.random.Generator) -> None:
        """Replace, in place, step t's commands that killed a live sequence by one drawn uniformly
        from the commands valid there, and redo their step; a sequence dies only where none is."""
        flat = self._flat_next
        dead_key = self.dead * self.n_columns
        bad = np.flatnonzero((keys[t + 1] == dead_key) & (keys[t] != dead_key))
        if not len(bad):
            return
        here = keys[t][bad]
        if blocked is None or not len(blocked):
            n_valid = self._valid_columns[1][here // self.n_columns]
            bad, here, n_valid = bad[n_valid > 0], here[n_valid > 0], n_valid[n_valid > 0]
            draw = (rng.random(len(bad)) * n_valid).astype(np.int64)
            pick = self._valid_columns[0][here // self.n_columns, draw].astype(flat.dtype)
        else:  # the static table does not know the moving obstacles: test every command
            candidates = here[:, None] + np.arange(self.n_commands, dtype=flat.dtype)[None, :]
            ok = flat[candidates] != dead_key
            at = np.searchsorted(blocked, candidates).clip(max=len(blocked) - 1)
            ok &= blocked[at] != candidates
            pick = np.where(ok, rng.random(ok.shape), -1.0).argmax(axis=1).astype(flat.dtype)
            fixable = ok.any(axis=1)
            bad, here, pick = bad[fixable], here[fixable], pick[fixable]
        steps[t, bad] = pick
        keys[t + 1, bad] = flat[here + pick]

    def _summarise(self, keys, local, lengths, goal_keys, stop_at_goal) -> SimulationResult:
        """Per-sequence outcome from the (L + 1, B) keys of a run."""
        width, batch = keys.shape[0] - 1, keys.shape[1]
        steps = np.arange(width + 1)[:, None]
        # Roadmap progress: the first step at or after the previous hit where the next pose is met.
        progress = np.ones(batch, dtype=np.int64)
        when = np.zeros(batch, dtype=np.int64)
        for k, goal in enumerate(goal_keys, start=1):
            hit = (keys == goal) & (steps >= when) & (progress == k)
            found = hit.any(axis=0)
            progress[found] += 1
            when[found] = hit.argmax(axis=0)[found]
        run_length = lengths
        done = progress == len(goal_keys) + 1
        if stop_at_goal and len(goal_keys):
            run_length = np.where(done, np.minimum(lengths, when), lengths)
        died = keys[1:] == self.dead * self.n_columns
        if not (run_length == width).all():
            died &= steps[1:] <= run_length
        first_invalid = np.full(batch, -1, dtype=np.int64)
        if width:
            any_died = died.any(axis=0)
            first_invalid[any_died] = died.argmax(axis=0)[any_died]
        executed = np.where(first_invalid >= 0, first_invalid, run_length)
        final_ids = keys[executed, np.arange(batch)] // self.n_columns
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


def simulate(workspace: Workspace, sequences, start: Pose, **options) -> SimulationResult:
    """Compile a :class:`Simulator` for ``workspace`` and run ``sequences`` from ``start``.

    Keyword options are split between :class:`Simulator` (commands, diagonals, timing, clearance)
    and :meth:`Simulator.run` (roadmap, t0, stop_at_goal).
    """
    compile_keys = {"commands", "diagonals", "timing", "clearance"}
    sim = Simulator(workspace, **{k: v for k, v in options.items() if k in compile_keys})
    return sim.run(sequences, start, **{k: v for k, v in options.items() if k not in compile_keys})
