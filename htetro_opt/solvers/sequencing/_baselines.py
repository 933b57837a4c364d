"""The baselines of Le et al. 2018 for waypoint sequencing (§5, Table 1, Fig. 14): zigzag, spiral, greedy search.

The paper compares its GA with "zigzag scanning", "spiral scanning" (each "one-row" and "two-rows")
and a "greedy search with 10,000 iterations". It describes them in one sentence each; the readings
implemented here are:

- **Zigzag** (boustrophedon, "one-row or two-rows-wise nearest searching"): the waypoints are
  grouped by block b's cell into horizontal bands ``rows`` rows high, counted from the top row. The
  bands that hold waypoints are visited from the top down, the first left to right, the next right
  to left, and so on (the direction alternates between non-empty bands: empty rows, e.g. between the
  reference cells of vertical tiles, are skipped, not swept).
  Within a band the waypoints are ordered by x (in the band's direction); waypoints with the same x
  (only possible with ``rows`` ≥ 2) are taken nearest-first: the one whose y is closest to the
  previous waypoint's y comes first (ties: the upper one). So a two-row band is swept column by
  column, each column entered from the side the robot is already on.
- **Spiral** ("from out-to-in by one-row (or column) and two-rows (or columns) based nearest
  searching"): block b's cell lies in ring ``k = min(x, y, W − 1 − x, H − 1 − y) // rows`` (its
  distance to the grid border, in bands ``rows`` wide). Rings are visited from the outside in, each
  walked clockwise from its top-left corner: along its top side left to right, down its right side,
  along its bottom side right to left, up its left side. A cell belongs to the side of the ring it is
  nearest to (ties: top, right, bottom, left, in that order), and waypoints at the same position
  along the ring are again taken nearest-first to the previous waypoint (ties: the outer one).
- **Variants** (both patterns): the pattern can start in any corner and run first along either
  axis, the eight symmetries of the grid. The variant is named by where it starts and its first
  direction, e.g. ``"top-left, right"`` (the canonical zigzag and spiral) or ``"bottom-right, up"``.
  With a fixed start tile, the cheapest variant that begins at the start tile is taken; when no
  variant does, the start tile is moved to the front of each variant and the cheapest such order is
  taken (``info["start_moved"]`` is then True). With a free start, the cheapest variant.
- **Greedy search**: every iteration builds a nearest-neighbour path with one random element, and
  the cheapest path is kept. With a fixed start, iteration 0 is the plain nearest-neighbour path from
  the start and every later iteration goes first to a random second waypoint (the paper: "random
  trajectories from the initial waypoint"), then nearest-neighbour; with a free start, every
  iteration starts at a random waypoint. Ties between equally near waypoints are broken at random.
  All iterations are built together as numpy batches by the package's one nearest-neighbour
  construction (:func:`~htetro_opt.solvers.sequencing.nearest_neighbour_paths`, random
  priorities breaking its ties); the random draws of each batch do not depend on the total number of
  iterations, so with the same seed more iterations never give a worse path.

"Nearest" is always by the instance's own cost (eq. 2), "position" by block b's cell (the paper's
reference block), both as in the paper.
"""

from __future__ import annotations

import math
import time

import numpy as np

from htetro_opt._progress import check_progress, report
from htetro_opt._validation import as_rng, check_int, check_seed, check_time_limit
from htetro_opt.errors import ParameterError
from htetro_opt.problems.waypoint_sequencing import SequencingInstance, check_instance, path_cost
from htetro_opt.solvers.sequencing._budgets import default_time_limit
from htetro_opt.solvers.sequencing._local import nearest_neighbour_paths

__all__ = ["PATTERN_VARIANTS", "solve_zigzag", "solve_spiral", "solve_greedy"]

# The eight symmetries of the grid as (swap x and y, then mirror x, then mirror y), the canonical
# pattern first: a variant runs the canonical pattern on the grid seen through the symmetry.
_SYMMETRIES = tuple((swap, fx, fy) for swap in (False, True) for fy in (False, True) for fx in (False, True))
_DIRECTIONS = {(1, 0): "right", (-1, 0): "left", (0, 1): "up", (0, -1): "down"}


def _variant_name(swap: bool, fx: bool, fy: bool) -> str:
    """Where the canonical pattern (top-left corner, going right) starts and goes in the original grid."""
    # canonical start: (x' = 0, y' = top); direction (+1, 0). Undo the mirrors, then the swap.
    low_x, low_y = not fx, fy  # after undoing mirrors: is the start at x' = 0? at y' = 0?
    dx, dy = (-1 if fx else 1), 0
    if swap:
        low_x, low_y = low_y, low_x
        dx, dy = dy, dx
    corner = f"{'bottom' if low_y else 'top'}-{'left' if low_x else 'right'}"
    return f"{corner}, {_DIRECTIONS[(dx, dy)]}"


PATTERN_VARIANTS: tuple[str, ...] = tuple(_variant_name(*s) for s in _SYMMETRIES)
"""Names of the eight variants of the zigzag and spiral patterns: start corner, first direction."""


def _transform(cells: np.ndarray, shape: tuple[int, int], swap: bool, fx: bool, fy: bool):
    """Cells (n, 2) seen through a grid symmetry, and the transformed grid's (H, W)."""
    h, w = shape
    x, y = cells[:, 0].copy(), cells[:, 1].copy()
    if swap:
        x, y, h, w = y, x, w, h
    if fx:
        x = w - 1 - x
    if fy:
        y = h - 1 - y
    return np.stack([x, y], axis=1), (h, w)


def _join_groups(groups, position: np.ndarray, outer: np.ndarray) -> list[int]:
    """Concatenate groups of waypoints, each group ordered nearest-first to the previous waypoint.

    ``position`` is each waypoint's coordinate across the pattern's direction (its y in a zigzag band,
    its depth in a spiral ring), ``outer`` its tie-break key (smaller first).
    """
    order: list[int] = []
    for group in groups:
        if len(group) == 1 or not order:
            if len(group) > 1:
                group = sorted(group, key=lambda i: (outer[i], i))
            order.extend(group)
            continue
        previous = position[order[-1]]
        order.extend(sorted(group, key=lambda i: (abs(position[i] - previous), outer[i], i)))
    return order


def _grouped(keys: np.ndarray) -> list[list[int]]:
    """Waypoint indices sorted by integer keys (rows: lexicographic), equal keys grouped."""
    idx = np.lexsort(keys.T[::-1]) if keys.ndim == 2 else np.argsort(keys, kind="stable")
    groups: list[list[int]] = []
    last = None
    for i in idx.tolist():
        key = tuple(keys[i].tolist()) if keys.ndim == 2 else int(keys[i])
        if key != last:
            groups.append([])
            last = key
        groups[-1].append(i)
    return groups


def _zigzag_canonical(cells: np.ndarray, shape: tuple[int, int], rows: int) -> np.ndarray:
    """Boustrophedon from the top-left corner, first band left to right."""
    h, _ = shape
    x, y = cells[:, 0], cells[:, 1]
    band = np.unique((h - 1 - y) // rows, return_inverse=True)[1].reshape(-1)  # non-empty bands, from the top
    along = np.where(band % 2 == 0, x, -x)  # every other band runs right to left
    groups = _grouped(np.stack([band, along], axis=1))
    return np.array(_join_groups(groups, y, -y), dtype=np.int64)  # ties: the upper one


def _spiral_canonical(cells: np.ndarray, shape: tuple[int, int], rows: int) -> np.ndarray:
    """Rings from the outside in, each clockwise from its top-left corner."""
    h, w = shape
    x, y = cells[:, 0], cells[:, 1]
    to_border = np.stack([h - 1 - y, w - 1 - x, y, x], axis=1)  # top, right, bottom, left
    depth = to_border.min(axis=1)
    ring = depth // rows
    lo = ring * rows
    top, right, bottom, left = h - 1 - lo, w - 1 - lo, lo, lo
    side = to_border.argmin(axis=1)  # first minimum: ties go to top, right, bottom, left
    width, height = right - left + 1, top - bottom + 1
    along = np.select(
        [side == 0, side == 1, side == 2],
        [x - left, width + (top - y), width + height + (right - x)],
        2 * width + height + (y - bottom),
    )
    groups = _grouped(np.stack([ring, along], axis=1))
    return np.array(_join_groups(groups, depth, depth), dtype=np.int64)  # ties: the outer one


def _check_pattern_options(rows, seed, time_limit) -> int:
    """``rows`` checked; ``seed`` and ``time_limit`` checked although a pattern uses neither, so that a
    bad value is refused by every method alike."""
    check_seed(seed)
    check_time_limit(time_limit)
    return check_int(rows, "rows", minimum=1)


def _best_variant(instance: SequencingInstance, canonical, rows: int) -> tuple[np.ndarray, dict]:
    if not instance.has_geometry:
        raise ParameterError("the zigzag and spiral patterns scan the tiles' positions, and this instance has no "
                             "tile geometry (a plain cost matrix): use another method")
    cells = np.asarray(instance.blocks[:, 1], dtype=np.int64)
    h, w = instance.shape
    if h <= 0 or w <= 0:  # an instance built without its grid's shape: use the cells' extent
        h, w = int(cells[:, 1].max()) + 1, int(cells[:, 0].max()) + 1
    variants = []
    for symmetry in _SYMMETRIES:
        seen, seen_shape = _transform(cells, (h, w), *symmetry)
        variants.append(canonical(seen, seen_shape, rows))
    variants = np.array(variants, dtype=np.int64)
    start = instance.start
    moved = False
    if start is not None:
        fitting = np.flatnonzero(variants[:, 0] == start)
        if len(fitting):
            candidates = fitting
        else:
            moved = True
            rest = variants[variants != start].reshape(len(variants), -1)
            variants = np.concatenate([np.full((len(variants), 1), start, dtype=np.int64), rest], axis=1)
            candidates = np.arange(len(variants))
    else:
        candidates = np.arange(len(variants))
    costs = np.atleast_1d(path_cost(instance.cost, variants[candidates]))
    k = int(candidates[int(np.argmin(costs))])
    info = {"rows": rows, "variant": PATTERN_VARIANTS[k]}
    if start is not None:
        info["start_moved"] = moved
    return variants[k].copy(), info


def solve_zigzag(instance: SequencingInstance, *, rows: int = 1, seed=0,
                 time_limit: float | None = None) -> tuple[np.ndarray, dict]:
    """The zigzag scanning (boustrophedon) of Le et al. 2018 over block b's cells.

    Parameters
    ----------
    instance : SequencingInstance
        Costs, block cells, start and grid shape.
    rows : int, keyword-only
        Height of the bands swept back and forth: 1 ("one-row") or 2 ("two-rows"); larger values
        are accepted.
    seed, time_limit : keyword-only
        Accepted for the method contract (and checked) but unused: the pattern is deterministic.

    Returns
    -------
    order : ndarray of int64
        Waypoint indices, beginning at ``instance.start`` when it is set.
    info : dict
        ``rows``, ``variant`` (one of :data:`PATTERN_VARIANTS`) and, with a fixed start,
        ``start_moved`` (True when no variant began at the start tile, see the module docstring).

    Raises
    ------
    ParameterError
        If ``rows`` is not a positive integer, ``seed`` or ``time_limit`` is invalid, or the
        instance has no tile geometry (:meth:`SequencingInstance.from_matrix`).

    Examples
    --------
    >>> from htetro_opt.scenarios import parse_tileset
    >>> ts = parse_tileset("1a 1b 1c 1d 2a 2b 2c 2d\\n3a 3b 3c 3d 4a 4b 4c 4d")
    >>> order, info = solve_zigzag(SequencingInstance.from_tileset(ts))
    >>> order.tolist(), info["variant"]  # tile 1's column down, then tile 2's column up
    ([0, 2, 3, 1], 'top-left, down')
    """
    instance = check_instance(instance)
    return _best_variant(instance, _zigzag_canonical, _check_pattern_options(rows, seed, time_limit))


def solve_spiral(instance: SequencingInstance, *, rows: int = 1, seed=0,
                 time_limit: float | None = None) -> tuple[np.ndarray, dict]:
    """The spiral scanning of Le et al. 2018: rings of block b's cells from the outside in, each walked clockwise.

    Parameters
    ----------
    instance : SequencingInstance
        Costs, block cells, start and grid shape.
    rows : int, keyword-only
        Width of a ring: 1 ("one-row (or column)") or 2 ("two-rows (or columns)"); larger values
        are accepted.
    seed, time_limit : keyword-only
        Accepted for the method contract (and checked) but unused: the pattern is deterministic.

    Returns
    -------
    order : ndarray of int64
        Waypoint indices, beginning at ``instance.start`` when it is set.
    info : dict
        ``rows``, ``variant`` (one of :data:`PATTERN_VARIANTS`) and, with a fixed start,
        ``start_moved``.

    Raises
    ------
    ParameterError
        If ``rows`` is not a positive integer, ``seed`` or ``time_limit`` is invalid, or the
        instance has no tile geometry (:meth:`SequencingInstance.from_matrix`).

    Examples
    --------
    >>> from htetro_opt.scenarios import parse_tileset
    >>> ts = parse_tileset("1a 2a 2b 2c 2d\\n1b . . . 3a\\n1c . . . 3b\\n1d 4d 4c 4b 3c\\n. . 4a . 3d")
    >>> order, info = solve_spiral(SequencingInstance.from_tileset(ts, start=2))
    >>> [ts.ids[i] for i in order], info["variant"]  # the outer ring anticlockwise, then tile 4 inside
    ([2, 1, 3, 4], 'top-right, left')
    """
    instance = check_instance(instance)
    return _best_variant(instance, _spiral_canonical, _check_pattern_options(rows, seed, time_limit))


_GREEDY_CELLS = 1 << 21
"""At most this many paths × waypoints are built at once by the greedy search (a few tens of MB)."""
_GREEDY_WORK = 10_000_000
"""At most about this many paths × waypoints² per batch, so that a time limit is checked every ~0.1–0.3 s."""


def solve_greedy(instance: SequencingInstance, *, iterations: int = 10000, seed=0,
                 time_limit: float | None = None, progress=None) -> tuple[np.ndarray, dict]:
    """The greedy search of Le et al. 2018: the cheapest of many randomised nearest-neighbour paths.

    With a fixed start, iteration 0 is the plain nearest-neighbour path from the start (its ties, like
    every iteration's, broken at random); see the module docstring for the other iterations.

    Parameters
    ----------
    instance : SequencingInstance
        Costs and start.
    iterations : int, keyword-only
        Number of paths built (the paper: 10,000).
    seed : None, int or numpy.random.Generator, keyword-only
        Source of the random draws: an int or a Generator reproduces a run (unless ``time_limit``
        stops it), None draws fresh entropy.
    time_limit : float, optional, keyword-only
        Wall-clock budget in seconds: no new batch of paths is started once it is spent (at least
        one batch always runs). None: 10 s + 1 s per 100 waypoints, at most 30 s.
    progress : callable, optional, keyword-only
        ``progress(paths built, iterations, note)`` after each batch.

    Returns
    -------
    order : ndarray of int64
        The cheapest path found (the earliest among equally cheap ones).
    info : dict
        ``iterations`` (requested), ``iterations_run``, ``best_iteration``, ``timed_out`` (the time limit
        stopped it before its iterations) and ``time_limit_s``.

    Raises
    ------
    ParameterError
        If ``iterations`` is not a positive integer, or ``seed`` or ``time_limit`` is invalid.

    Examples
    --------
    >>> from htetro_opt.scenarios import parse_tileset
    >>> ts = parse_tileset("1a 1b 1c 1d\\n2a 2b 2c 2d\\n3a 3b 3c 3d\\n4a 4b 4c 4d")
    >>> order, info = solve_greedy(SequencingInstance.from_tileset(ts, start=2), iterations=50)
    >>> order.tolist(), info["iterations_run"]
    ([1, 0, 2, 3], 50)
    """
    instance = check_instance(instance)
    iterations = check_int(iterations, "iterations", minimum=1)
    rng = as_rng(seed)
    time_limit = check_time_limit(time_limit)
    if time_limit is None:
        time_limit = default_time_limit("greedy", instance.n)
    progress = check_progress(progress)
    began = time.perf_counter()
    n, start, cost = instance.n, instance.start, instance.cost
    if n == 1 or (n == 2 and start is not None):
        order = np.arange(n, dtype=np.int64) if start in (None, 0) else np.array([1, 0], dtype=np.int64)
        return order, {"iterations": iterations, "iterations_run": 1, "best_iteration": 0, "timed_out": False,
                       "time_limit_s": time_limit}
    chunk = max(1, min(_GREEDY_CELLS // n, _GREEDY_WORK // (n * n)))  # depends on n only
    best_order, best_cost, best_at, done = None, math.inf, 0, 0
    while done < iterations:
        # draws of full-size chunks, so the first k paths do not depend on ``iterations``
        priority = rng.random((chunk, n))
        if start is None:
            first = rng.integers(0, n, chunk)
            second = None
        else:
            first = np.full(chunk, start, dtype=np.int64)
            second = rng.integers(0, n - 1, chunk)
            second = second + (second >= start)
            if done == 0:
                second[0] = -1  # iteration 0: the plain nearest-neighbour path
        take = min(chunk, iterations - done)
        orders = nearest_neighbour_paths(cost, first[:take], seconds=None if second is None else second[:take],
                                         priority=priority[:take])
        costs = path_cost(cost, orders)
        k = int(np.argmin(costs))
        if costs[k] < best_cost:
            best_order, best_cost, best_at = orders[k].copy(), float(costs[k]), done + k
        done += take
        report(progress, done, iterations, f"best cost {best_cost:.4g}")
        if time.perf_counter() - began >= time_limit:
            break
    return best_order, {"iterations": iterations, "iterations_run": done, "best_iteration": best_at,
                        "timed_out": done < iterations, "time_limit_s": time_limit}
