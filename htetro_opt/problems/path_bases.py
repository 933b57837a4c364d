"""Nazarahari et al. 2019's path planning in a continuous workspace as a pymoo problem: path bases.

An individual is one object variable: a float (n, 2) array of the path's interior **path bases**
(PBs; the start and the goal are not genes), n varying from individual to individual; with K robots,
a tuple of K such arrays (a joint chromosome, §4.5). The robot's path runs start → PBs → goal,
either straight between them (``path="linear"``) or along a cubic spline through them
(``path="spline"``: scipy's ``CubicSpline`` over the chord length, natural ends, sampled at least 10
times a piece and at most 0.1 apart; the samples form the polyline that is measured and checked).

Terms of one robot's path (§4.4):

- **L**, its length;
- **S**, the sum of its turning angles at every interior vertex, in **degrees** (eq. 4 as Table 2
  counts it: its A* smoothness values are multiples of 45, and eq. 4's printed range drops a vertex);
- **safety**: ``"paper"`` = eq. 5's R = Σ_PB D_i, D_i the clearance of PB i; ``"min"`` (ours) = the
  smallest clearance along the whole path (eq. 5 looks at the PBs only, ignores the segments, and
  rewards keeping PBs: a path without PBs has R = 0).

**F.** ``objectives="weighted"``: eq. 6's C = W_L·L + W_S·S + W_R / safety (the last term only when
W_R > 0; a safety ≤ 0 counts as :data:`TINY_SAFETY`), summed over the robots. ``"separate"`` (for
NSGA-II and the like): (ΣL, ΣS, −safety), safety summed over the robots for ``"paper"`` and the
smallest over them for ``"min"``; −safety rather than 1/safety (ours) keeps the third objective
finite on paths that touch an obstacle. With K > 1 robots, the penalty of §4.5 is added to C (to ΣL
in ``"separate"``): 10 (W + H) (d_s − d) / d_s for each pair of robots whose closest approach d is
below d_s (:data:`~htetro_opt.model.continuous.SAFETY_MARGIN`; robots move at unit speed and wait
at their goals, as :func:`~htetro_opt.model.robot_distance` measures).

**G** (one inequality constraint, feasible at 0): the number of infeasible segments of all the
robots' polylines plus the number of conflicting pairs. The paper's "large penalty" for infeasible
paths is the algorithms' feasibility-first sort on G.
"""

from __future__ import annotations

from functools import cached_property

import numpy as np
from pymoo.core.problem import Problem
from scipy.interpolate import CubicSpline

from htetro_opt._validation import check_real
from htetro_opt.errors import ParameterError
from htetro_opt.model._lattice import check_grid
from htetro_opt.model.continuous import SAFETY_MARGIN, path_smoothness, polyline_segments, robot_distance
from htetro_opt.problems.names import DEFAULT_PATH_WEIGHTS, OBJECTIVE_KINDS, PATH_KINDS, SAFETY_KINDS
from htetro_opt.scenarios.loader import check_continuous_scenario

__all__ = [
    "PathBasesProblem",
    "TINY_SAFETY",
    "check_path_weights",
    "spline_path",
    "render_path",
]

TINY_SAFETY = 1e-9
"""The safety a path without clearance counts as in W_R / safety (eq. 6 divides by it)."""

SPLINE_SAMPLES = 10
"""Least samples a spline piece is cut into."""

SPLINE_SPACING = 0.1
"""Largest distance (in chord length) between two samples of a spline."""

PENALTY_FACTOR = 10.0
"""The §4.5 penalty per conflicting pair is PENALTY_FACTOR (W + H) (d_s − d) / d_s (ours: the paper's
penalty is "linear", its scale unstated; this one outweighs any path's length)."""


def _choice(value, name: str, options: tuple) -> str:
    if not isinstance(value, str) or value not in options:
        raise ParameterError(f"{name} must be one of {', '.join(map(repr, options))}, got {value!r}")
    return value


def check_path_weights(weights, name: str = "weights") -> tuple[float, float, float]:
    """Eq. 6's (W_L, W_S, W_R): three finite non-negative numbers, not all zero.

    Examples
    --------
    >>> check_path_weights([1, 0.187, 0.201])
    (1.0, 0.187, 0.201)
    >>> check_path_weights((0, 0, 0))
    Traceback (most recent call last):
    ...
    htetro_opt.errors.ParameterError: weights must not all be zero, got (0, 0, 0)
    """
    if isinstance(weights, (str, bytes)) or not hasattr(weights, "__len__") or len(weights) != 3:
        raise ParameterError(f"{name} must be three numbers (W_L, W_S, W_R), got {weights!r}")
    out = tuple(check_real(w, f"{name}[{i}]", minimum=0.0) for i, w in enumerate(weights))
    if not any(out):
        raise ParameterError(f"{name} must not all be zero, got {weights!r}")
    return out


def spline_path(points) -> np.ndarray:
    """The natural cubic spline through ``points`` (start, PBs, goal), parametrised by chord length,
    as a polyline: each piece cut into max(10, ⌈chord / 0.1⌉) equal steps of the parameter. Repeated
    (or all but coincident) points are merged; two points give the straight segment.

    Examples
    --------
    >>> curve = spline_path([[0, 0], [1, 1], [2, 0]])
    >>> len(curve), curve[[0, 15, -1]].round(6).tolist()
    (31, [[0.0, 0.0], [1.0, 1.0], [2.0, 0.0]])
    """
    points = np.asarray(points, dtype=float)
    chords = np.hypot(*np.diff(points, axis=0).T)
    # a point (all but the goal) too near the one before it to advance the parameter is merged
    keep = np.concatenate([[True], chords > 1e-12 * max(1.0, float(chords.sum()))])
    if not keep[-1]:
        keep[np.flatnonzero(keep)[-1]] = False
        keep[-1] = True
    points = points[keep] if len(points) else points
    if len(points) < 3:
        return points.copy()
    chords = np.hypot(*np.diff(points, axis=0).T)
    t = np.concatenate([[0.0], np.cumsum(chords)])
    steps = np.maximum(SPLINE_SAMPLES, np.ceil(chords / SPLINE_SPACING)).astype(np.int64)
    # the samples of piece i: t_i + k (t_{i+1} − t_i) / steps_i, k = 0 … steps_i − 1; then the end
    piece = np.repeat(np.arange(len(chords)), steps)
    k = np.arange(steps.sum()) - np.repeat(np.cumsum(steps) - steps, steps)
    ts = np.append(t[piece] + k * chords[piece] / steps[piece], t[-1])
    curve = CubicSpline(t, points, bc_type="natural")(ts)
    at_pb = np.append(np.cumsum(steps) - steps, len(ts) - 1)
    curve[at_pb] = points  # exactly through the PBs (the spline meets them up to rounding)
    return curve


def render_path(start, pbs, goal, *, path: str = "linear") -> np.ndarray:
    """The polyline a robot follows: start → PBs → goal, straight or along :func:`spline_path`.

    Examples
    --------
    >>> render_path([0, 0], np.array([[1, 1]]), [2, 0]).tolist()
    [[0.0, 0.0], [1.0, 1.0], [2.0, 0.0]]
    """
    points = np.vstack([np.asarray(start, dtype=float), np.asarray(pbs, dtype=float).reshape(-1, 2),
                        np.asarray(goal, dtype=float)])
    return spline_path(points) if path == "spline" else points


class PathBasesProblem(Problem):
    """Nazarahari et al. 2019's path problem over path bases (see the module docstring).

    Parameters
    ----------
    scenario : ContinuousScenario
        The workspace, the robots' radius, starts and goals (K = ``scenario.n_robots``).
    path : {"linear", "spline"}, keyword-only
    weights : three floats, keyword-only
        (W_L, W_S, W_R) of eq. 6 (``objectives="weighted"``): finite, non-negative, not all zero.
    safety : {"paper", "min"}, keyword-only
        Eq. 5's R over the PBs, or the smallest clearance along the path (ours).
    objectives : {"weighted", "separate"}, keyword-only
        One objective (eq. 6) or three (L, S, −safety).
    grid : float, keyword-only
        d: the APF's lattice spacing and the operators' step (1 in the paper).

    Attributes
    ----------
    geometry : ContinuousGeometry
    starts, goals : ndarray, shape (K, 2)
    n_robots : int
    step : float
        d.
    box : tuple of float
        F's box [xmin, ymin, xmax, ymax], where the operators keep the PBs.
    safety_distance : float
        d_s = 2 r + the safety margin.
    penalty_scale : float
        10 (W + H), the penalty of a collision (d = 0).

    Raises
    ------
    ScenarioError
        If ``scenario`` is not a continuous scenario.
    ParameterError
        On an unknown ``path``, ``safety`` or ``objectives``, bad weights or a bad ``grid``.

    Examples
    --------
    >>> from htetro_opt.scenarios import parse_scenario
    >>> sc = parse_scenario({"name": "t", "width": 10, "height": 10, "obstacles": [[4, 0, 6, 8]],
    ...                      "robots": [{"start": [1, 1], "goal": [9, 1]}]})
    >>> problem = PathBasesProblem(sc)
    >>> X = np.empty((2, 1), dtype=object)
    >>> X[0, 0], X[1, 0] = np.array([[4.0, 8.0], [6.0, 8.0]]), np.empty((0, 2))
    >>> F, G = problem.evaluate(X, return_values_of=["F", "G"])
    >>> F.round(4).tolist(), G.tolist()  # over the wall; straight through it (one bad segment)
    ([[17.2315], [8.0]], [[0.0], [1.0]])
    """

    def __init__(self, scenario, *, path: str = "linear", weights=DEFAULT_PATH_WEIGHTS, safety: str = "paper",
                 objectives: str = "weighted", grid: float = 1.0) -> None:
        scenario = check_continuous_scenario(scenario)
        self.scenario = scenario
        self.geometry = scenario.geometry
        self.path = _choice(path, "path", PATH_KINDS)
        self.weights = check_path_weights(weights)
        self.safety = _choice(safety, "safety", SAFETY_KINDS)
        self.objectives = _choice(objectives, "objectives", OBJECTIVE_KINDS)
        self.step = check_grid(grid, self.geometry)
        self.starts = np.asarray(scenario.starts, dtype=float)
        self.goals = np.asarray(scenario.goals, dtype=float)
        self.n_robots = scenario.n_robots
        self.box = self.geometry.bounds
        self.safety_distance = 2 * scenario.robot_radius + SAFETY_MARGIN
        self.penalty_scale = PENALTY_FACTOR * (scenario.width + scenario.height)
        super().__init__(n_var=1, n_obj=1 if self.objectives == "weighted" else 3, n_ieq_constr=1,
                         vtype=object, elementwise=False)

    # --- chromosomes ------------------------------------------------------------------------------
    def robots(self, x) -> list[np.ndarray]:
        """The per-robot PB arrays of one chromosome (a K = 1 chromosome is the array itself).

        Raises
        ------
        ParameterError
            If ``x`` does not hold K arrays of shape (n, 2).
        """
        if isinstance(x, np.ndarray) and x.dtype == object:
            x = x.ravel()[0]
        parts = [x] if self.n_robots == 1 and not isinstance(x, (tuple, list)) else list(x)
        if len(parts) != self.n_robots:
            raise ParameterError(f"a chromosome of this problem holds {self.n_robots} robots' PBs, got {len(parts)}")
        out = []
        for part in parts:
            arr = np.asarray(part, dtype=float)
            if arr.size == 0:
                arr = np.empty((0, 2))
            if arr.ndim != 2 or arr.shape[1] != 2:
                raise ParameterError(f"PBs must be an (n, 2) array, got shape {arr.shape}")
            out.append(arr)
        return out

    def join(self, parts) -> np.ndarray | tuple:
        """A chromosome from per-robot PB arrays (the inverse of :meth:`robots`)."""
        parts = [np.asarray(p, dtype=float).reshape(-1, 2) for p in parts]
        return parts[0] if self.n_robots == 1 else tuple(parts)

    def polyline(self, pbs, robot: int = 0) -> np.ndarray:
        """Robot ``robot``'s path for the PBs ``pbs`` (:func:`render_path`)."""
        return render_path(self.starts[robot], pbs, self.goals[robot], path=self.path)

    def polylines(self, x) -> list[np.ndarray]:
        """Every robot's path of one chromosome."""
        return [self.polyline(p, k) for k, p in enumerate(self.robots(x))]

    # --- measures ---------------------------------------------------------------------------------
    def _needs_safety(self) -> bool:
        return self.objectives == "separate" or self.weights[2] > 0

    def measure(self, xs) -> dict:
        """The terms of many chromosomes at once.

        Returns
        -------
        dict of ndarray
            ``length``, ``smoothness``, ``safety`` (NaN when not needed by F), ``bad`` (infeasible
            segments), each shape (n, K); ``penalty``, ``conflicts`` and ``min_distance`` (inf for one
            robot), shape (n,).
        """
        xs = list(xs)
        n, K = len(xs), self.n_robots
        parts = [self.robots(x) for x in xs]
        lines = [self.polyline(p, k) for ps in parts for k, p in enumerate(ps)]
        sizes = np.fromiter((len(line) for line in lines), np.int64, len(lines))
        points = np.concatenate(lines) if lines else np.empty((0, 2))
        a, b, owner = polyline_segments(points, sizes)  # every segment of every polyline, checked in one call
        ok = self.geometry.segments_feasible(a, b) if len(a) else np.zeros(0, dtype=bool)
        bad = np.bincount(owner[~ok], minlength=len(lines)).reshape(n, K)
        seg = np.hypot(*(b - a).T)
        length = np.bincount(owner, weights=seg, minlength=len(lines)).reshape(n, K)
        smooth = np.array([path_smoothness(line) for line in lines]).reshape(n, K)
        safety = np.full((n, K), np.nan)
        if self._needs_safety():
            if self.safety == "paper":
                pbs = [p for ps in parts for p in ps]
                counts = np.fromiter((len(p) for p in pbs), np.int64, len(pbs))
                if counts.sum():
                    clear = self.geometry.clearance(np.concatenate(pbs))
                    safety = np.bincount(np.repeat(np.arange(len(pbs)), counts), weights=clear,
                                         minlength=len(pbs)).reshape(n, K)
                else:
                    safety = np.zeros((n, K))
            else:
                safety = np.array([self.geometry.path_clearance(line) for line in lines]).reshape(n, K)
        penalty, conflicts, closest = np.zeros(n), np.zeros(n, dtype=np.int64), np.full(n, np.inf)
        if K > 1:
            d_s = self.safety_distance
            for i in range(n):
                mine = lines[i * K:(i + 1) * K]
                for p in range(K):
                    for q in range(p + 1, K):
                        d = robot_distance(mine[p], mine[q])
                        closest[i] = min(closest[i], d)
                        if d < d_s:
                            conflicts[i] += 1
                            penalty[i] += self.penalty_scale * (d_s - d) / d_s
        return {"length": length, "smoothness": smooth, "safety": safety, "bad": bad, "penalty": penalty,
                "conflicts": conflicts, "min_distance": closest}

    def objectives_of(self, terms: dict) -> tuple[np.ndarray, np.ndarray]:
        """``F`` (shape (n, n_obj)) and ``G`` (shape (n, 1)) from :meth:`measure`'s terms."""
        G = (terms["bad"].sum(axis=1) + terms["conflicts"]).astype(float)[:, None]
        W_L, W_S, W_R = self.weights
        if self.objectives == "separate":
            if self.safety == "paper":
                safety = terms["safety"].sum(axis=1)
            else:
                safety = terms["safety"].min(axis=1)
            F = np.column_stack([terms["length"].sum(axis=1) + terms["penalty"], terms["smoothness"].sum(axis=1),
                                 -safety])
            return F, G
        cost = W_L * terms["length"] + W_S * terms["smoothness"]
        if W_R > 0:
            cost = cost + W_R / np.maximum(terms["safety"], TINY_SAFETY)
        return (cost.sum(axis=1) + terms["penalty"])[:, None], G

    def score(self, xs) -> tuple[np.ndarray, np.ndarray]:
        """``G`` as a vector (shape (n,)) and ``F`` (shape (n, n_obj)) of many chromosomes: what
        deletion, refinement and collision removal compare."""
        F, G = self.objectives_of(self.measure(xs))
        return G[:, 0], F

    @cached_property
    def corners(self):
        """The free space's corners where a shortest path may bend (:meth:`ContinuousGeometry.corners`;
        for r > 0 those of the outer polygonisation, which are feasible): what taut refinement uses."""
        geometry = self.geometry
        return geometry.corners() if geometry.robot_radius == 0 else geometry.polygonised("outer").corners()

    def _evaluate(self, X, out, *args, **kwargs):
        F, G = self.objectives_of(self.measure(np.asarray(X, dtype=object).reshape(len(X), -1)[:, 0]))
        out["F"], out["G"] = F, G

    def __repr__(self) -> str:
        return (f"PathBasesProblem({self.scenario.name!r}, {self.n_robots} robot(s), path={self.path!r}, "
                f"weights={self.weights}, safety={self.safety!r}, objectives={self.objectives!r})")
