"""Do et al. 2021's path costs (eqs. 9–12 and Fig. 5): time, smoothness, safety and their weighted sum.

The heat-conduction planner of Do et al. 2021 scores a path ``p = (p_1, …, p_lp)`` of motion commands
with three costs to be *maximised*, each 1 for an empty path:

- **Time** (eq. 9): ``f_t = 1 − Σ t_{p_i} / t_max``. The paper sets ``t_max`` to the time the O-shape
  takes for half a complete-coverage path of the obstacle-free map (39.6 s on 24 × 24 cells) without
  saying how that path runs. Ours (:func:`default_t_max`): a boustrophedon of ⌈H/2⌉ two-cell lanes of
  W − 2 translations each, halved, ``t_max = t_translation · ⌈H/2⌉ · (W − 2) / 2``; that is
  132 · t_translation on 24 × 24, the paper's 39.6 s iff t_translation = 0.3 s. ``f_t`` may be
  negative for a path longer than ``t_max`` (the paper does not clip it, nor do we).
- **Smoothness** (eq. 10): ``f_sm = 1 − #{i < l_p : p_i ≠ p_{i+1}} / l_p``. The printed sum runs to
  i = l_p, past the last command; ours counts the l_p − 1 changes between consecutive commands and
  keeps the paper's denominator l_p (so a path of k alternating commands scores 1 − (k − 1)/k, never 0).
  Commands are compared by token (global command id).
- **Safety** (Fig. 5): eq. 11 weights each obstacle cell by ``1/‖(x, y)‖``, but Fig. 5's worked numbers
  (1 − 10/20 = 0.5 for the O-shape, 1 − 14/24 for the I-shape) follow another rule, which we implement:
  the search pattern U of a pose is every cell whose centre lies within 2 d_grid (inclusive) of some
  block centre, the robot's own four cells excluded; cell c weighs n_c, the number of the four block
  disks (radius 2 d_grid) holding it (:func:`safety_pattern`: the O-shape's U has 20 cells, 8 of weight
  3 and 12 of weight 1; the I-shape's 24). A pose's penalty is ``s = Σ_{c ∈ U} n_c W_obs(c) / |U|``
  with ``W_obs = 1`` on an obstacle or off-map cell, and ``f_sf = 1 − mean s`` over the poses after
  each command (eq. 11's ``1/l_p Σ_i``). Ours: a pose fully walled in has ``s = Σ n_c / |U| > 1``
  (36/20 for the O-shape), so ``f_sf`` may be negative; the paper does not say. Only static obstacles
  count (the paper's maps have no moving ones); the start pose is not scored, as in eq. 11.
- **Weighted sum** (eq. 12): ``f = (w_t f_t + w_sm f_sm + w_sf f_sf) / (w_t + w_sm + w_sf)``.

Everything is a gather on integer tables computed once at import (:data:`FOOTPRINTS`' idea); no
simulator is needed: the poses are given (as :attr:`Plan.poses <htetro_opt.solvers.Plan>` holds them).
"""

from __future__ import annotations

import math
import reprlib

import numpy as np

from htetro_opt._validation import check_int, check_real
from htetro_opt.errors import ParameterError
from htetro_opt.model.commands import N_COMMANDS, Timing
from htetro_opt.model.robot import FOOTPRINTS, N_HEADINGS, N_STATES, shape_index
from htetro_opt.model.workspace import Workspace, check_workspace

__all__ = ["HEAT_COST_NAMES", "SAFETY_RADIUS", "check_heat_weights", "default_t_max", "safety_pattern", "heat_fitness"]

HEAT_COST_NAMES = ("f_t", "f_sm", "f_sf", "f")
"""The keys of :func:`heat_fitness`'s answer: eq. 9, eq. 10, Fig. 5's safety, eq. 12."""

SAFETY_RADIUS = 2
"""Radius of Do et al. 2021's obstacle-searching circles, in cells (r = 2 d_grid)."""


def _pattern_of(footprint: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """U and n_c of one footprint (4 block offsets): cells sorted by (y, x)."""
    r = SAFETY_RADIUS
    lo, hi = footprint.min(axis=0) - r, footprint.max(axis=0) + r
    xs, ys = np.meshgrid(np.arange(lo[0], hi[0] + 1), np.arange(lo[1], hi[1] + 1))
    cells = np.column_stack([xs.ravel(), ys.ravel()])  # row-major in y: sorted by (y, x)
    squared = ((cells[:, None, :] - footprint[None, :, :]) ** 2).sum(axis=-1)  # (cells, 4), exact integers
    counts = (squared <= r * r).sum(axis=1)
    own = (squared == 0).any(axis=1)
    keep = (counts > 0) & ~own
    return cells[keep].astype(np.int64), counts[keep].astype(np.int64)


def _pattern_tables() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Offsets ``[state, heading, k, 2]`` and weights ``[state, heading, k]`` padded with weight 0, and |U|."""
    patterns = [[_pattern_of(FOOTPRINTS[s, h]) for h in range(N_HEADINGS)] for s in range(N_STATES)]
    width = max(len(w) for row in patterns for _, w in row)
    offsets = np.zeros((N_STATES, N_HEADINGS, width, 2), dtype=np.int64)
    weights = np.zeros((N_STATES, N_HEADINGS, width), dtype=np.int64)
    sizes = np.zeros((N_STATES, N_HEADINGS), dtype=np.int64)
    for s, row in enumerate(patterns):
        for h, (cells, counts) in enumerate(row):
            offsets[s, h, : len(cells)] = cells
            weights[s, h, : len(cells)] = counts
            sizes[s, h] = len(cells)
    for table in (offsets, weights, sizes):
        table.setflags(write=False)
    return offsets, weights, sizes


# Padding entries point at B2's own cell with weight 0: always a valid gather, never a penalty.
_PATTERN_OFFSETS, _PATTERN_WEIGHTS, _PATTERN_SIZES = _pattern_tables()


def _check_timing(timing) -> Timing:
    if timing is None:
        return Timing()
    if not isinstance(timing, Timing):
        raise ParameterError(f"timing must be a Timing or None, got {type(timing).__name__} {reprlib.repr(timing)}")
    return timing


def _check_state(state, name: str = "state") -> int:
    """A state given by name (``"O"``, ``"h213"``) or index, as its index."""
    if isinstance(state, str):
        return shape_index(state)
    try:
        return check_int(state, name, minimum=0, maximum=N_STATES - 1)
    except ParameterError as err:
        raise ParameterError(f"{err} (or a state name such as 'O')") from err


def default_t_max(workspace: Workspace, timing: Timing | None = None) -> float:
    """Do et al. 2021's t_max (eq. 9): half an O-shape coverage path of the obstacle-free map.

    ``t_max = t_translation · ⌈H/2⌉ · (W − 2) / 2`` [ours: the paper gives only the 24 × 24 value,
    39.6 s; a boustrophedon of ⌈H/2⌉ two-cell lanes of W − 2 translations, halved, gives 132
    translations there, the paper's figure iff t_translation = 0.3 s]. Lane changes are not counted.

    Parameters
    ----------
    workspace : Workspace
        Only its width W and height H are used.
    timing : Timing, optional
        Command durations (default :class:`~htetro_opt.model.Timing`).

    Returns
    -------
    float

    Raises
    ------
    ParameterError
        If ``workspace`` or ``timing`` has the wrong type, or the formula gives no positive time (a map
        narrower than 3 cells, or a zero translation time): pass ``t_max`` explicitly then.

    Examples
    --------
    >>> default_t_max(Workspace(np.zeros((24, 24), dtype=bool)), Timing(translation=0.3))
    39.6
    """
    workspace = check_workspace(workspace)
    timing = _check_timing(timing)
    t_max = timing.translation * math.ceil(workspace.height / 2) * (workspace.width - 2) / 2
    t_max = round(t_max, 12)  # 0.3 · 132 prints as 39.6, not 39.599999999999994
    if not t_max > 0:
        raise ParameterError(f"the default t_max is not positive ({t_max:g}) for a {workspace.width} x "
                             f"{workspace.height} map with t_translation = {timing.translation:g}: give t_max")
    return t_max


def safety_pattern(state, heading: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Do et al. 2021's obstacle-searching pattern of one footprint (Fig. 5).

    The cells whose centre lies within 2 cells (inclusive) of some block centre, the robot's own four
    cells excluded, each weighted by the number of the four radius-2 block disks holding it. Eq. 11's
    ``1/‖(x, y)‖`` weights disagree with Fig. 5's worked numbers; these reproduce the figure.

    Parameters
    ----------
    state : str or int
        A state name (``"I"`` … ``"T"``, or an intermediate state such as ``"h213"``) or its index.
    heading : int
        Quarter turns, 0…3.

    Returns
    -------
    offsets : ndarray of int64, shape (k, 2)
        Cells of the pattern relative to B2's cell, sorted by (y, x).
    weights : ndarray of int64, shape (k,)
        n_c, in 1…4.

    Raises
    ------
    UnknownShapeError
        If ``state`` is a name that is not a state of the robot.
    ParameterError
        If ``state`` is not a name or an index, or ``heading`` is not in 0…3.

    Examples
    --------
    >>> offsets, weights = safety_pattern("O")
    >>> len(offsets), np.bincount(weights).tolist()
    (20, [0, 12, 0, 8])
    >>> len(safety_pattern("I", 1)[0])
    24
    """
    s = _check_state(state)
    h = check_int(heading, "heading", minimum=0, maximum=N_HEADINGS - 1)
    k = _PATTERN_SIZES[s, h]
    return _PATTERN_OFFSETS[s, h, :k].copy(), _PATTERN_WEIGHTS[s, h, :k].copy()


def _check_poses(poses) -> np.ndarray:
    try:
        array = np.asarray(poses)
        if array.dtype == object or not (np.issubdtype(array.dtype, np.integer) or array.size == 0):
            raise TypeError
        array = array.astype(np.int64).reshape(array.shape)
    except (TypeError, ValueError) as err:
        raise ParameterError(f"poses must be an integer array of (x, y, state, heading) rows, "
                             f"got {reprlib.repr(poses)}") from err
    if array.ndim != 2 or array.shape[1] != 4 or len(array) == 0:
        raise ParameterError(f"poses must have shape (n + 1, 4), the start first, got shape {array.shape}")
    bad_state = (array[:, 2] < 0) | (array[:, 2] >= N_STATES)
    bad_heading = (array[:, 3] < 0) | (array[:, 3] >= N_HEADINGS)
    if bad_state.any() or bad_heading.any():
        row = int(np.flatnonzero(bad_state | bad_heading)[0])
        raise ParameterError(f"poses row {row} {array[row].tolist()} needs a state in 0…{N_STATES - 1} "
                             f"and a heading in 0…{N_HEADINGS - 1}")
    return array


def _check_commands(commands, n: int) -> np.ndarray:
    try:
        array = np.asarray(commands)
        if array.dtype == object or not (np.issubdtype(array.dtype, np.integer) or array.size == 0):
            raise TypeError
        array = array.astype(np.int64).reshape(-1) if array.ndim <= 1 else None
    except (TypeError, ValueError) as err:
        raise ParameterError(f"commands must be a 1-D integer array of global command ids, "
                             f"got {reprlib.repr(commands)}") from err
    if array is None:
        raise ParameterError(f"commands must be 1-D, got shape {np.shape(commands)}")
    if len(array) != n:
        raise ParameterError(f"commands must hold one command per pose after the start: {n} for "
                             f"{n + 1} poses, got {len(array)}")
    bad = (array < 0) | (array >= N_COMMANDS)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise ParameterError(f"commands[{i}] = {int(array[i])} is not a command id (ids are 0…{N_COMMANDS - 1})")
    return array


def check_heat_weights(weights, name: str = "weights") -> tuple[float, float, float]:
    """Eq. 12's weights (w_t, w_sm, w_sf), checked once for every caller: three finite numbers ≥ 0,
    not all zero; a string "w_t,w_sm,w_sf" (as on the command line or in a study file) is read too.

    Raises
    ------
    ParameterError
        Naming ``name`` (e.g. ``"--weights"``) and what is wrong.

    Examples
    --------
    >>> check_heat_weights("1,0,1"), check_heat_weights([2, 0, 0])
    ((1.0, 0.0, 1.0), (2.0, 0.0, 0.0))
    """
    if isinstance(weights, str):
        try:
            weights = [float(v) for v in weights.split(",")]
        except ValueError:
            raise ParameterError(f"{name} must be three numbers w_t,w_sm,w_sf, got {weights!r}") from None
    if isinstance(weights, bytes) or not hasattr(weights, "__len__") or len(weights) != 3:
        raise ParameterError(f"{name} must be three numbers (w_t, w_sm, w_sf), got {reprlib.repr(weights)}")
    w = tuple(check_real(v, f"{name}[{i}] ({part})", minimum=0.0)
              for i, (v, part) in enumerate(zip(weights, ("w_t", "w_sm", "w_sf"))))
    if sum(w) <= 0:
        raise ParameterError(f"{name} (w_t, w_sm, w_sf) must not all be zero, got {list(w)}")
    return w


def heat_fitness(workspace: Workspace, poses, commands, *, t_max: float | None = None,
                 timing: Timing | None = None, weights=(1.0, 0.0, 0.0)) -> dict[str, float]:
    """Do et al. 2021's costs f_t (eq. 9), f_sm (eq. 10), f_sf (Fig. 5) and f (eq. 12) of one path.

    Parameters
    ----------
    workspace : Workspace
        The map; its static occupancy (off-map cells are obstacles) is what the safety cost sees.
    poses : array_like of int, shape (n + 1, 4)
        (x, y, state index, heading) of the start and after each command, as ``Plan.poses`` holds them.
        They are taken as given (not re-simulated).
    commands : array_like of int, shape (n,)
        Global command ids, as ``Plan.commands`` holds them.
    t_max : float, optional, keyword-only
        Eq. 9's time budget; default :func:`default_t_max` ``(workspace, timing)``.
    timing : Timing, optional, keyword-only
        Command durations t_{p_i} (default :class:`~htetro_opt.model.Timing`).
    weights : sequence of 3 float, keyword-only
        (w_t, w_sm, w_sf) of eq. 12: finite, ≥ 0, not all zero. The default scores time alone.

    Returns
    -------
    dict
        ``{"f_t", "f_sm", "f_sf", "f"}`` (:data:`HEAT_COST_NAMES`), floats, higher is better; all 1.0
        for an empty path (l_p = 0).

    Raises
    ------
    ParameterError
        Naming the argument: a workspace or timing of the wrong type, poses not of shape (n + 1, 4) or
        with a state or heading out of range, commands not n command ids, a t_max that is not a
        positive finite number, or weights that are not three finite non-negative numbers with a
        positive sum.

    Examples
    --------
    >>> from htetro_opt.model import parse_commands, shape_index
    >>> ws = Workspace(np.zeros((24, 24), dtype=bool))
    >>> O = shape_index("O")
    >>> poses = [(5, 5, O, 0), (6, 5, O, 0), (7, 5, O, 0), (7, 6, O, 0)]
    >>> costs = heat_fitness(ws, poses, parse_commands("x+ x+ y+"), weights=(1, 1, 1))
    >>> {k: round(v, 4) for k, v in costs.items()}
    {'f_t': 0.9773, 'f_sm': 0.6667, 'f_sf': 1.0, 'f': 0.8813}
    """
    workspace = check_workspace(workspace)
    timing = _check_timing(timing)
    poses = _check_poses(poses)
    commands = _check_commands(commands, len(poses) - 1)
    w = np.array(check_heat_weights(weights))
    t_max = (default_t_max(workspace, timing) if t_max is None
             else check_real(t_max, "t_max", minimum=0.0, include_minimum=False))
    l_p = len(commands)
    if l_p == 0:
        return dict.fromkeys(HEAT_COST_NAMES, 1.0)

    f_t = 1.0 - float(timing.durations()[commands].sum()) / t_max
    f_sm = 1.0 - int((commands[1:] != commands[:-1]).sum()) / l_p

    after = poses[1:]  # eq. 11 scores the pose after each command, not the start
    s, h = after[:, 2], after[:, 3]
    cells = _PATTERN_OFFSETS[s, h] + after[:, None, :2]  # (l_p, k, 2)
    cx, cy = cells[..., 0], cells[..., 1]
    inside = (cx >= 0) & (cx < workspace.width) & (cy >= 0) & (cy < workspace.height)
    occupied = workspace.occupancy[cy.clip(0, workspace.height - 1), cx.clip(0, workspace.width - 1)]
    obstacle = ~inside | occupied
    penalty = (_PATTERN_WEIGHTS[s, h] * obstacle).sum(axis=1) / _PATTERN_SIZES[s, h]
    f_sf = 1.0 - float(penalty.mean())

    costs = np.array([f_t, f_sm, f_sf])
    f = float(w @ costs / w.sum())
    return {"f_t": float(f_t), "f_sm": float(f_sm), "f_sf": float(f_sf), "f": f}

