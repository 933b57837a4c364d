"""Swept-cell tables (shared/MODEL.md §4), computed once per clearance.

A command is valid when every cell that any block's square overlaps with positive area at any instant
of its continuous motion is inside the map and free. The motion of each command is sampled densely
(at most 2° of block turn between samples, 16 samples per cell of translation) and, at each sample,
the cells a block square overlaps are found exactly by the separating-axis test. The result, for every
(state, heading, command), is an integer array of cell offsets from B2's start cell: the model's AAT /
VAT tables (Cheng et al. 2019), so that the hot path checks validity by table lookup only.

Motions are computed at heading 0 and turned for the other headings: a turned robot's sweep is the
turned sweep, and a translation at heading k is the turned sweep of the translation by the
counter-turned shift at heading 0. Cheng et al. 2019's single-block commands are legal only when the end hinge
state is one of the robot's 23 states (hinges within [π/2, 3π/2], no two blocks on one cell) and no
two non-neighbouring blocks overlap during the motion; shapeshifts, translations and rotations are
always legal.

Built once per clearance and kept on disk (:mod:`htetro_opt._cache`): a later process loads them in
milliseconds rather than building them again (about 0.2 s).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from htetro_opt._cache import load_arrays, source_key, store_arrays
from htetro_opt._validation import check_real
from htetro_opt.model import commands as _commands
from htetro_opt.model import robot as _robot
from htetro_opt.model.commands import COMMANDS, N_COMMANDS, Command
from htetro_opt.model.robot import HINGE_STATES, N_HEADINGS, N_STATES, block_poses, rotate_cells

__all__ = ["SweepTables", "sweep_tables", "motion_samples", "swept_cells"]

_EPS = 1e-9
_MAX_TURN_PER_SAMPLE = math.radians(2.0)
_SAMPLES_PER_CELL = 16


@dataclass(frozen=True, eq=False)  # holds arrays: identity equality, hashable
class SweepTables:
    """Per-(state, heading, command) transition and swept-cell tables of the robot.

    Attributes
    ----------
    clearance : float
        δ, in cells, by which every block square was inflated on each side.
    legal : ndarray of bool, shape (N_STATES, N_COMMANDS)
        Whether the command can be executed from the state at all (hinge limits, self-collision).
    next_state : ndarray of int, shape (N_STATES, N_COMMANDS)
        State after the command (−1 where illegal).
    next_heading : ndarray of int, shape (N_STATES, 4, N_COMMANDS)
    shift : ndarray of int, shape (N_COMMANDS, 2)
        Displacement (dx, dy) of B2's cell in the workspace frame.
    offsets : ndarray of int, shape (N_STATES, 4, N_COMMANDS, K, 2)
        Swept cell offsets from B2's start cell, padded to K by repeating the first offset.
    counts : ndarray of int, shape (N_STATES, 4, N_COMMANDS)
        Number of distinct swept cells of each entry (0 where illegal).
    """

    clearance: float
    legal: np.ndarray
    next_state: np.ndarray
    next_heading: np.ndarray
    shift: np.ndarray
    offsets: np.ndarray
    counts: np.ndarray

    def cells(self, state: int, heading: int, command: int) -> np.ndarray:
        """Distinct swept cell offsets of one entry, shape (n, 2), sorted by (y, x)."""
        return self.offsets[state, heading, command, : self.counts[state, heading, command]]


def motion_samples(state: int, command: Command, *, shift: tuple[int, int] | None = None):
    """Sampled block poses of a command executed from ``state`` at heading 0.

    Parameters
    ----------
    state : int
        Start state index.
    command : Command
        The command; its ``shift`` is replaced by ``shift`` when given (used to turn translations).

    Returns
    -------
    centres : ndarray, shape (T, 4, 2)
        Block centres relative to B2's start centre, T samples including both ends.
    angles : ndarray, shape (T, 4)
    """
    start = np.array(HINGE_STATES[state], dtype=float)
    if command.kind == "shapeshift":
        end = np.array(HINGE_STATES[command.target], dtype=float)
    else:
        end = start + np.array(command.hinge_delta, dtype=float)
    hinge_turn = np.abs(end - start).max() * math.pi / 2
    body_turn = abs(command.turn) * math.pi / 2
    # A hinge turn of the middle hinge swings B4 about a moving pivot: budget for both turns.
    largest_turn = hinge_turn * (2 if command.kind == "shapeshift" else 1) + body_turn
    move = shift if shift is not None else command.shift
    n = 2 + max(int(math.ceil(largest_turn / _MAX_TURN_PER_SAMPLE)), _SAMPLES_PER_CELL * max(map(abs, move)))
    u = np.linspace(0.0, 1.0, n)
    hinges = (start + u[:, None] * (end - start)) * math.pi / 2
    centres, angles = block_poses(hinges, u * command.turn * math.pi / 2)
    centres = centres + u[:, None, None] * np.asarray(move, dtype=float)
    return centres, angles


def swept_cells(centres: np.ndarray, angles: np.ndarray, *, clearance: float = 0.0) -> np.ndarray:
    """Cells overlapped with positive area by squares of side 1 + 2·clearance.

    Parameters
    ----------
    centres : ndarray, shape (..., 2)
        Square centres, in cell units (cell (i, j) spans [i − ½, i + ½] × [j − ½, j + ½]).
    angles : ndarray, shape (...)
        Square angles in radians.
    clearance : float, keyword-only
        δ added on each side of every square.

    Returns
    -------
    ndarray of int, shape (n, 2)
        Distinct (x, y) cells, sorted by y then x.
    """
    half = 0.5 + clearance
    c = np.asarray(centres, dtype=float).reshape(-1, 2)
    a = np.asarray(angles, dtype=float).reshape(-1)
    cos, sin = np.abs(np.cos(a)), np.abs(np.sin(a))
    # Axis-aligned extent of each (turned) square, then the candidate cells of the bounding box.
    extent = half * (cos + sin)
    lo = np.floor(np.min(c - extent[:, None], axis=0) + 0.5).astype(int)
    hi = np.ceil(np.max(c + extent[:, None], axis=0) - 0.5).astype(int)
    gx, gy = np.meshgrid(np.arange(lo[0], hi[0] + 1), np.arange(lo[1], hi[1] + 1))
    cells = np.stack([gx.ravel(), gy.ravel()], axis=-1)
    cx, cy = cells[:, 0:1].astype(float), cells[:, 1:2].astype(float)
    # Separating axes 1–2: the cell's own axes.
    hit = (np.minimum(c[:, 0] + extent, cx + 0.5) - np.maximum(c[:, 0] - extent, cx - 0.5) > _EPS)
    hit &= (np.minimum(c[:, 1] + extent, cy + 0.5) - np.maximum(c[:, 1] - extent, cy - 0.5) > _EPS)
    # Axes 3–4: the square's own axes u = (cos a, sin a) and v = (−sin a, cos a).
    for ux, uy in ((np.cos(a), np.sin(a)), (-np.sin(a), np.cos(a))):
        centre_gap = (cx - c[:, 0]) * ux + (cy - c[:, 1]) * uy
        cell_half = 0.5 * (np.abs(ux) + np.abs(uy))
        hit &= np.abs(centre_gap) < half + cell_half - _EPS
    found = cells[hit.any(axis=1)]
    return found[np.lexsort((found[:, 0], found[:, 1]))]


def _self_overlap(centres: np.ndarray, angles: np.ndarray) -> bool:
    """Whether two non-neighbouring blocks (B1–B3, B1–B4, B2–B4) overlap during a sampled motion."""
    for i, j in ((0, 2), (0, 3), (1, 3)):
        gap = centres[:, i] - centres[:, j]
        # Two unit squares overlap iff no axis of either separates them (4 axes).
        separated = np.zeros(len(gap), dtype=bool)
        for k in (i, j):
            for ux, uy in ((np.cos(angles[:, k]), np.sin(angles[:, k])), (-np.sin(angles[:, k]), np.cos(angles[:, k]))):
                proj = np.abs(gap[:, 0] * ux + gap[:, 1] * uy)
                reach = sum(
                    0.5 * (np.abs(np.cos(angles[:, m]) * ux + np.sin(angles[:, m]) * uy)
                           + np.abs(-np.sin(angles[:, m]) * ux + np.cos(angles[:, m]) * uy))
                    for m in (i, j)
                )
                separated |= proj >= reach - _EPS
        if not separated.all():
            return True
    return False


def sweep_tables(clearance: float = 0.0) -> SweepTables:
    """The robot's swept-cell and transition tables for a clearance δ (cached per δ).

    Parameters
    ----------
    clearance : float
        δ ≥ 0 in cells (e.g. 0.4 for a 35 cm sweep radius on 25 cm blocks: (0.35 − 0.25) / 0.25).

    Returns
    -------
    SweepTables

    Raises
    ------
    ParameterError
        If the clearance is negative or not a finite number.

    Examples
    --------
    >>> tables = sweep_tables()
    >>> int(tables.counts[0, 0, 8])  # the I-shape turning by +90°
    16
    """
    return _sweep_tables(check_real(clearance, "clearance (cells)", minimum=0.0))


_FIELDS = ("legal", "next_state", "next_heading", "shift", "offsets", "counts")
_SOURCES = (__file__, _robot.__file__, _commands.__file__)
"""The files the tables are computed from: an edit of any of them (or a new version) makes a new cache entry."""


@lru_cache(maxsize=8)
def _sweep_tables(clearance: float) -> SweepTables:
    """The tables from the on-disk cache (:mod:`htetro_opt._cache`: milliseconds), or built (about 0.2 s) and
    stored there for the next processes."""
    key = source_key(*_SOURCES)
    name = f"sweeps-{float(clearance).hex()}"
    stored = load_arrays(name, key)
    if stored is not None:
        tables = _from_arrays(clearance, stored)
        if tables is not None:
            return tables
    tables = _build_sweep_tables(clearance)
    store_arrays(name, key, {field: getattr(tables, field) for field in _FIELDS})
    return tables


def _from_arrays(clearance: float, stored: dict) -> SweepTables | None:
    """Tables from stored arrays, or None unless they have the layout :func:`_build_sweep_tables` gives."""
    layout = {"legal": (np.bool_, (N_STATES, N_COMMANDS)), "next_state": (np.int64, (N_STATES, N_COMMANDS)),
              "next_heading": (np.int64, (N_STATES, N_HEADINGS, N_COMMANDS)), "shift": (np.int64, (N_COMMANDS, 2)),
              "counts": (np.int64, (N_STATES, N_HEADINGS, N_COMMANDS))}
    if set(stored) != set(_FIELDS):
        return None
    for field, (dtype, shape) in layout.items():
        if stored[field].dtype != dtype or stored[field].shape != shape:
            return None
    offsets = stored["offsets"]
    if (offsets.dtype != np.int64 or offsets.ndim != 5 or offsets.shape[:3] != (N_STATES, N_HEADINGS, N_COMMANDS)
            or offsets.shape[4] != 2 or int(stored["counts"].max()) > offsets.shape[3]):
        return None
    for field in _FIELDS:
        stored[field].setflags(write=False)
    return SweepTables(clearance, *(stored[field] for field in _FIELDS))


def _build_sweep_tables(clearance: float) -> SweepTables:
    state_index = {triple: i for i, triple in enumerate(HINGE_STATES)}
    legal = np.zeros((N_STATES, N_COMMANDS), dtype=bool)
    next_state = np.full((N_STATES, N_COMMANDS), -1, dtype=np.int64)
    next_heading = np.zeros((N_STATES, N_HEADINGS, N_COMMANDS), dtype=np.int64)
    shift = np.array([cmd.shift for cmd in COMMANDS], dtype=np.int64)
    swept: dict[tuple[int, int, int], np.ndarray] = {}
    body_frame: dict[tuple, np.ndarray] = {}
    for s in range(N_STATES):
        for ci, cmd in enumerate(COMMANDS):
            if cmd.kind == "shapeshift":
                target = cmd.target
            else:
                end = tuple(np.add(HINGE_STATES[s], cmd.hinge_delta).tolist())
                target = state_index.get(end, -1)
            if target < 0:
                continue
            if cmd.kind == "block" and any(cmd.hinge_delta) and _self_overlap(*motion_samples(s, cmd)):
                continue
            legal[s, ci] = True
            next_state[s, ci] = target
            next_heading[s, :, ci] = (np.arange(N_HEADINGS) + cmd.turn) % N_HEADINGS
            for h in range(N_HEADINGS):
                body_shift = tuple(rotate_cells(np.array(cmd.shift), -h).tolist())
                key = (s, target, cmd.hinge_delta, cmd.turn, body_shift)
                if key not in body_frame:
                    samples = motion_samples(s, cmd, shift=body_shift)
                    body_frame[key] = swept_cells(*samples, clearance=clearance)
                cells = rotate_cells(body_frame[key], h)
                swept[s, h, ci] = cells[np.lexsort((cells[:, 0], cells[:, 1]))]
    width = max(len(v) for v in swept.values())
    offsets = np.zeros((N_STATES, N_HEADINGS, N_COMMANDS, width, 2), dtype=np.int64)
    counts = np.zeros((N_STATES, N_HEADINGS, N_COMMANDS), dtype=np.int64)
    for (s, h, ci), cells in swept.items():
        offsets[s, h, ci, : len(cells)] = cells
        offsets[s, h, ci, len(cells):] = cells[0]
        counts[s, h, ci] = len(cells)
    for array in (legal, next_state, next_heading, shift, offsets, counts):
        array.setflags(write=False)
    return SweepTables(clearance, legal, next_state, next_heading, shift, offsets, counts)
