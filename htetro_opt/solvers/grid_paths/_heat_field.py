"""Steady heat conduction on the grid (Do et al. 2021, §IV, eqs. 3–8): the field of the heat planner.

The workspace is the heat domain, one square element per cell: free cells conduct (k = 1), obstacles
insulate (eq. 3; ``k_obstacle = 0`` removes them, a small positive ``k_obstacle`` keeps them as poor
conductors). The goal's B2 cell is the heat source (u = 1 on its dofs), the start's B2 cell the sink
(u = 0, eq. 6); every other boundary, the map's edge and the obstacles' sides, is insulated
(zero flux, eq. 7 with q̄ = 0), and there is no internal heat (Q = 0 in eq. 5). The discrete system
K U = F (eq. 8) is solved for the temperatures, which fall monotonically from the goal to the start
(the maximum principle), so following the temperature upwards leads from the start to the goal.

Two elements:

- ``"q1"`` (the paper's bilinear quadrilateral): one dof per grid node; a cell's temperature is the
  value at its centre, the mean of its four nodes.
- ``"p0"`` [ours]: one constant per cell, coupled across the shared sides only by the interior
  penalty form (1/h)∫[u][v] ds: the 5-point cell-centred finite-volume scheme, with no coupling
  through corners.

Departures from the paper, each with a switch back (STYLE 7):

- *Corner leak* [ours]: Q1 couples two free cells that touch only at a corner, where no robot passes.
  ``split_pinches=True`` (default) gives such a node one copy per element, so the field's connectivity
  is the 4-connectivity of the free cells; ``split_pinches=False`` is the paper's mesh.
- A node shared by the start's and the goal's cells (adjacent cells) would be both 0 and 1: it stays
  free [ours], and the two cells keep their prescribed values.
- Free regions holding no Dirichlet dof have no defined temperature (the system would be singular):
  they are dropped (NaN). A start and goal in different regions give ``connected=False`` and no solve.

Assembly uses the element matrix that scikit-fem computes once on a one-element mesh (STYLE 6:
compute once, the hot path is array arithmetic): on the structured grid each node's row is a 9-point
stencil, summed by 16 shifted array additions and laid out as CSR directly (no COO of 16 entries an
element, no sort); the few elements at a split pinch node are scattered and added. Here, not
scikit-fem's ``asm``: on the 1000 x 1000 grid ``asm(laplace, Basis(MeshQuad, ElementQuad1()))`` alone
takes 3.6 CPU s against 0.09 s for this assembly (dofs and matrix, median of 3, load 4, 2026-12-04),
and the field's whole solve is ~2.5 s. The test suite checks the field against scikit-fem's own
``asm`` / ``condense`` / ``solve`` on small maps, with the pinch copies as mesh nodes of their own.
"""

from __future__ import annotations

import time as _time
from dataclasses import dataclass, field
from functools import cache

import numpy as np
from scipy.sparse import coo_matrix, csr_matrix
from scipy.sparse.csgraph import connected_components
from scipy.sparse.linalg import spsolve

from htetro_opt._validation import check_bool, check_real
from htetro_opt.errors import ConfigurationError, ParameterError
from htetro_opt.model.workspace import check_workspace
from htetro_opt.solvers.grid_paths._spec import HEAT_ELEMENTS

__all__ = ["DIRECT_MAX_DOFS", "HEAT_SOLVERS", "HeatField", "q1_element_matrix", "solve_heat_field"]

HEAT_SOLVERS = ("auto", "direct", "amg")
"""Linear solvers: SuperLU, pyamg's Ruge–Stüben as a CG preconditioner, or the choice by size."""

DIRECT_MAX_DOFS = 10_000
"""``solver="auto"`` factorises systems below this many unknowns, and runs AMG-preconditioned CG above."""

_DIRECT_EPSILON = 1e-12


@dataclass(frozen=True, eq=False)  # holds arrays: identity equality, hashable
class HeatField:
    """A steady temperature field on a grid workspace.

    Attributes
    ----------
    cells : ndarray of float, shape (H, W)
        ``cells[y, x]``, the temperature of cell (x, y) in [0, 1]: 1 on the source (goal) cell, 0 on
        the sink (start) cell, NaN on obstacles and on free regions that hold neither.
    nodes : ndarray of float, shape (H + 1, W + 1), or None
        ``nodes[y, x]``, the temperature at grid node (x, y) (the lower-left corner of cell (x, y));
        NaN where no conducting cell of the solved region touches the node and at split pinch nodes
        (which have one value per cell: see ``corners``). None for ``"p0"``.
    corners : ndarray of float, shape (H, W, 2, 2), or None
        ``corners[y, x, j, i]``, the temperature at node (x + i, y + j) as cell (x, y)'s element sees
        it. None for ``"p0"``.
    connected : bool
        Whether the source and the sink lie in one conducting region (otherwise nothing was solved).
    epsilon : float
        Tolerance of monotonicity checks on this field: 1e-12 after a direct solve, 10·tol after AMG.
    info : dict
        ``element``, ``dofs`` (unknowns solved for), ``pinches`` (nodes split), ``solver``
        (``"direct"``, ``"amg"`` or None), ``iterations`` (CG iterations, 0 when direct) and
        ``seconds`` (the whole call).
    """

    cells: np.ndarray
    nodes: np.ndarray | None
    connected: bool
    epsilon: float
    info: dict = field(default_factory=dict)
    corners: np.ndarray | None = None

    def gradient(self) -> tuple[np.ndarray, np.ndarray]:
        """The temperature gradient at the cell centres, per cell width: ``(gx, gy)``, each (H, W).

        For ``"q1"`` the exact gradient of the bilinear interpolant at the centre; for ``"p0"`` central
        differences of the neighbouring cells (one-sided where one neighbour has no temperature).
        NaN where undefined (obstacles, dropped regions, a cell with no neighbour along an axis).

        Examples
        --------
        >>> from htetro_opt.model.workspace import Workspace
        >>> field = solve_heat_field(Workspace(np.zeros((1, 3), dtype=bool)), (2, 0), (0, 0), element="p0")
        >>> gx, gy = field.gradient()
        >>> gx.round(3).tolist(), bool(np.isnan(gy).all())
        ([[0.5, 0.5, 0.5]], True)
        """
        if self.corners is not None:
            c = self.corners
            gx = 0.5 * (c[:, :, 0, 1] + c[:, :, 1, 1] - c[:, :, 0, 0] - c[:, :, 1, 0])
            gy = 0.5 * (c[:, :, 1, 0] + c[:, :, 1, 1] - c[:, :, 0, 0] - c[:, :, 0, 1])
            return gx, gy
        return _central_difference(self.cells, axis=1), _central_difference(self.cells, axis=0)


def _central_difference(values: np.ndarray, axis: int) -> np.ndarray:
    t = np.moveaxis(values, axis, -1)
    pad = np.full(t.shape[:-1] + (1,), np.nan)
    before = np.concatenate([pad, t[..., :-1]], axis=-1)
    after = np.concatenate([t[..., 1:], pad], axis=-1)
    both = 0.5 * (after - before)
    forward, backward = after - t, t - before
    out = np.where(np.isnan(both), np.where(np.isnan(forward), backward, forward), both)
    out[np.isnan(t)] = np.nan
    return np.moveaxis(out, -1, axis)


@cache
def q1_element_matrix() -> np.ndarray:
    """The Q1 Laplace element matrix of a unit square, local dofs in the order (0, 0), (1, 0), (1, 1), (0, 1).

    scikit-fem assembles it once on a one-element mesh.

    Examples
    --------
    >>> (q1_element_matrix() * 6).round().astype(int)[0].tolist()
    [4, -1, -2, -1]
    """
    import skfem as fem
    from skfem.models.poisson import laplace

    mesh = fem.MeshQuad1()  # nodes (0, 0), (1, 0), (1, 1), (0, 1)
    matrix = fem.asm(laplace, fem.Basis(mesh, fem.ElementQuad1())).toarray()
    matrix.setflags(write=False)
    return matrix


_Q1_CORNERS = ((0, 0), (0, 1), (1, 1), (1, 0))
"""(j, i) of scikit-fem's local Q1 dofs: node (x + i, y + j) of cell (x, y)."""


def _check_cell(value, name: str, workspace) -> tuple[int, int]:
    try:
        x, y = (int(v) for v in value)
        ok = all(isinstance(v, (int, np.integer)) and not isinstance(v, (bool, np.bool_)) for v in value)
    except (TypeError, ValueError) as err:
        raise ParameterError(f"{name} must be an (x, y) pair of integers, got {value!r}") from err
    if not ok:
        raise ParameterError(f"{name} must be an (x, y) pair of integers, got {value!r}")
    if not workspace.contains(x, y):
        raise ConfigurationError(f"{name} cell ({x}, {y}) is outside the {workspace.width} × "
                                 f"{workspace.height} map")
    if workspace.occupancy[y, x]:
        raise ConfigurationError(f"{name} cell ({x}, {y}) is on an obstacle")
    return x, y


def _check_choice(value, name: str, choices: tuple[str, ...]) -> str:
    if not isinstance(value, str) or value not in choices:
        raise ParameterError(f"{name} must be one of {', '.join(map(repr, choices))}, got {value!r}")
    return value


def _q1_dofs(free: np.ndarray, split: bool) -> tuple[np.ndarray, int]:
    """Global dof of each corner of each cell, (H, W, 2, 2) (the grid nodes, then 4 copies a split
    pinch); and the number of pinches split."""
    h, w = free.shape
    node = np.arange((h + 1) * (w + 1)).reshape(h + 1, w + 1)
    dofs = np.empty((h, w, 2, 2), dtype=np.int64)
    for j in (0, 1):
        for i in (0, 1):
            dofs[:, :, j, i] = node[j:j + h, i:i + w]
    if not split or h < 2 or w < 2:
        return dofs, 0
    # Interior node (x, y) with cells a = (x-1, y-1), b = (x, y-1), c = (x-1, y), d = (x, y) around it.
    a, b, c, d = free[:-1, :-1], free[:-1, 1:], free[1:, :-1], free[1:, 1:]
    ny, nx = np.nonzero((a & d & ~b & ~c) | (b & c & ~a & ~d))
    ny, nx = ny + 1, nx + 1
    fresh = node.size + 4 * np.arange(len(ny))
    # One copy per element around the node: cells (x-1+i, y-1+j) see it as their corner (1-j, 1-i).
    for k, (j, i) in enumerate(((0, 0), (0, 1), (1, 0), (1, 1))):
        dofs[ny - 1 + j, nx - 1 + i, 1 - j, 1 - i] = fresh + k
    return dofs, len(ny)


def _q1_matrix(conductivity: np.ndarray, dofs: np.ndarray, size: int) -> csr_matrix:
    """The Q1 stiffness matrix K over ``size`` dofs (rows of no conducting element empty), in canonical CSR.

    An element whose four corners are grid nodes adds to the 9-point stencil of each corner: the
    stencil's nine coefficients per node are summed on the node grid by 16 shifted array additions, and
    row by row they are the CSR in column order already (no sort, no duplicates). The few elements
    around a split pinch node (whose copies are no grid nodes) are scattered as COO and added.
    """
    h, w = conductivity.shape
    ke = q1_element_matrix()
    corner_dofs = dofs[:, :, [j for j, _ in _Q1_CORNERS], [i for _, i in _Q1_CORNERS]]  # (H, W, 4)
    grid = (h + 1) * (w + 1)
    special = (corner_dofs >= grid).any(axis=2) & (conductivity > 0)  # an element with a pinch copy
    k = np.where(special, 0.0, conductivity)
    stencil = np.zeros((9, h + 1, w + 1))  # slot (dj + 1) * 3 + (di + 1): the neighbour (x + di, y + dj)
    for a, (ja, ia) in enumerate(_Q1_CORNERS):
        for b, (jb, ib) in enumerate(_Q1_CORNERS):
            stencil[(jb - ja + 1) * 3 + (ib - ia + 1), ja:ja + h, ia:ia + w] += ke[a, b] * k
    stencil = stencil.reshape(9, grid).T  # (node, slot): row by row, columns ascending
    on = stencil != 0  # obstacle-only neighbours (k = 0) store nothing; Q1's entries never cancel
    # int32 indices (pyamg's and SuperLU's own type) unless the entries could overflow them
    index = np.int32 if 9 * size < 2**31 else np.int64
    offsets = np.array([dj * (w + 1) + di for dj in (-1, 0, 1) for di in (-1, 0, 1)], dtype=index)
    indptr = np.zeros(size + 1, dtype=index)
    np.cumsum(on.sum(axis=1, dtype=index), out=indptr[1:grid + 1])
    indptr[grid + 1:] = indptr[grid]
    indices = (np.arange(grid, dtype=index)[:, None] + offsets)[on]
    matrix = csr_matrix((stencil[on], indices, indptr), shape=(size, size))
    if special.any():
        ey, ex = np.nonzero(special)
        local = corner_dofs[ey, ex]
        rows = np.broadcast_to(local[:, :, None], (len(ey), 4, 4)).ravel()
        cols = np.broadcast_to(local[:, None, :], (len(ey), 4, 4)).ravel()
        data = (conductivity[ey, ex][:, None, None] * ke[None]).ravel()
        matrix = (matrix + coo_matrix((data, (rows, cols)), shape=(size, size)).tocsr()).tocsr()
    return matrix


def solve_heat_field(workspace, source, sink, *, element: str = "q1", k_obstacle: float = 0.0,
                     split_pinches: bool = True, solver: str = "auto", tol: float = 1e-8) -> HeatField:
    """The steady temperature field with the goal's cell as heat source and the start's as sink.

    Parameters
    ----------
    workspace : Workspace
        The map (its static occupancy; moving obstacles are ignored).
    source, sink : (int, int)
        The (x, y) cells held at 1 (the goal's B2 cell) and at 0 (the start's B2 cell). The same cell
        for both gives T ≡ 0.
    element : {"q1", "p0"}, keyword-only
        Bilinear quadrilaterals (the paper's), or cell constants coupled across sides (ours, the
        5-point scheme).
    k_obstacle : float in [0, 1), keyword-only
        Conductivity of obstacle cells relative to free cells; 0 removes them from the domain.
        With ``"p0"`` a side between cells conducts with the harmonic mean of their conductivities.
    split_pinches : bool, keyword-only
        Give a ``"q1"`` node where two free cells touch only at a corner one copy per element, so no
        heat passes where no robot can (ours; False is the paper's mesh).
    solver : {"auto", "direct", "amg"}, keyword-only
        SuperLU, or pyamg's Ruge–Stüben hierarchy preconditioning CG (run on one thread);
        ``"auto"`` picks SuperLU below :data:`DIRECT_MAX_DOFS` unknowns.
    tol : float > 0, keyword-only
        Relative residual at which AMG-preconditioned CG stops.

    Returns
    -------
    HeatField

    Raises
    ------
    ParameterError
        An unknown ``element`` or ``solver``, ``k_obstacle`` outside [0, 1), ``tol`` ≤ 0, a cell that
        is not an (x, y) pair of integers, a ``workspace`` that is not a Workspace.
    ConfigurationError
        ``source`` or ``sink`` outside the map or on an obstacle.

    Examples
    --------
    >>> from htetro_opt.model.workspace import Workspace
    >>> field = solve_heat_field(Workspace(np.zeros((1, 5), dtype=bool)), (4, 0), (0, 0))
    >>> field.cells.round(3).tolist(), field.connected
    ([[0.0, 0.167, 0.5, 0.833, 1.0]], True)
    """
    started = _time.perf_counter()
    workspace = check_workspace(workspace)
    element = _check_choice(element, "element", HEAT_ELEMENTS)
    solver = _check_choice(solver, "solver", HEAT_SOLVERS)
    k_obstacle = check_real(k_obstacle, "k_obstacle", minimum=0.0, maximum=1.0, include_maximum=False)
    split_pinches = check_bool(split_pinches, "split_pinches")
    tol = check_real(tol, "tol", minimum=0.0, include_minimum=False)
    sx, sy = _check_cell(source, "source", workspace)
    zx, zy = _check_cell(sink, "sink", workspace)

    free = ~workspace.occupancy
    h, w = free.shape
    conductivity = np.where(free, 1.0, k_obstacle)
    used = conductivity > 0
    pinches = 0
    if element == "q1":
        dofs, pinches = _q1_dofs(free, split_pinches)
        size = (h + 1) * (w + 1) + 4 * pinches
        matrix = _q1_matrix(conductivity, dofs, size)
        source_dofs, sink_dofs = dofs[sy, sx].ravel(), dofs[zy, zx].ravel()
    else:
        dofs = np.arange(h * w).reshape(h, w)
        size = h * w
        pairs = [(dofs[:, :-1], dofs[:, 1:], conductivity[:, :-1], conductivity[:, 1:]),
                 (dofs[:-1, :], dofs[1:, :], conductivity[:-1, :], conductivity[1:, :])]
        rows, cols, data = [], [], []
        for left, right, k_left, k_right in pairs:
            k_side = np.divide(2 * k_left * k_right, k_left + k_right, out=np.zeros_like(k_left),
                               where=(k_left > 0) & (k_right > 0))
            on = k_side > 0
            p, q, k = left[on], right[on], k_side[on]
            rows += [p, q, p, q]
            cols += [p, q, q, p]
            data += [k, k, -k, -k]
        # Explicit diagonal entries (zero for an isolated cell) mark every conducting cell as a dof.
        cells = dofs[used]
        rows, cols = np.concatenate(rows + [cells]), np.concatenate(cols + [cells])
        data = np.concatenate(data + [np.zeros(len(cells))])
        matrix = coo_matrix((data, (rows, cols)), shape=(size, size)).tocsr()
        del rows, cols, data
        source_dofs, sink_dofs = dofs[sy, sx].reshape(1), dofs[zy, zx].reshape(1)
    # Dofs of no conducting element (nodes of obstacles only, pinch nodes replaced by their copies)
    # have empty rows: isolated in the graph, they lie in no solved region and stay NaN.
    _, label = connected_components(matrix, directed=False)
    connected = bool(label[source_dofs[0]] == label[sink_dofs[0]])
    values = np.full(size, np.nan)
    info = {"element": element, "dofs": 0, "pinches": pinches, "solver": None, "iterations": 0}
    epsilon = _DIRECT_EPSILON
    if connected:
        region = label == label[sink_dofs[0]]
        fixed = np.zeros(size, dtype=bool)
        if (sx, sy) == (zx, zy):
            fixed[sink_dofs] = True
            prescribed = np.zeros(size)
        else:
            shared = np.intersect1d(source_dofs, sink_dofs)  # adjacent start and goal: left free
            hot, cold = np.setdiff1d(source_dofs, shared), np.setdiff1d(sink_dofs, shared)
            fixed[hot] = fixed[cold] = True
            prescribed = np.zeros(size)
            prescribed[hot] = 1.0
        interior = np.flatnonzero(region & ~fixed)
        boundary = np.flatnonzero(fixed)
        values[boundary] = prescribed[boundary]
        if len(interior):
            a, b = _interior_system(matrix, interior, prescribed)
            used_solver = solver if solver != "auto" else ("direct" if len(interior) < DIRECT_MAX_DOFS else "amg")
            values[interior], info["iterations"] = _solve(a, b, used_solver, tol)
            info.update(dofs=len(interior), solver=used_solver)
            if used_solver == "amg":
                epsilon = 10 * tol

    cells = np.full((h, w), np.nan)
    nodes = corners = None
    if element == "q1":
        corners = np.where(used[:, :, None, None], values[dofs], np.nan)
        corners[~free] = np.nan
        cells = corners.mean(axis=(2, 3))
        nodes = np.full((h + 1, w + 1), np.nan)
        flat = nodes.reshape(-1)
        original = dofs < (h + 1) * (w + 1)  # not a pinch copy
        hit = original & ~np.isnan(corners)
        flat[dofs[hit]] = corners[hit]
    else:
        cells[used] = values[dofs[used]]
        cells[~free] = np.nan
    if connected:  # the prescribed cells keep their values, even with shared nodes left free
        cells[sy, sx] = 1.0
        cells[zy, zx] = 0.0
    info["seconds"] = _time.perf_counter() - started
    return HeatField(cells=cells, nodes=nodes, connected=connected, epsilon=epsilon, info=info, corners=corners)


def _interior_system(matrix: csr_matrix, interior: np.ndarray, prescribed: np.ndarray):
    """``A = K[interior, interior]`` and ``b = -K[interior, :] @ prescribed`` (prescribed zero off the
    Dirichlet dofs): the rows sliced once, the columns renumbered by a lookup table (scipy's column
    fancy index costs 0.2 s at a million dofs, measured). The interior's rows reach no other region,
    so the only columns dropped are the few Dirichlet dofs'."""
    rows = matrix[interior]
    b = -(rows @ prescribed)
    column = np.full(matrix.shape[1], -1, dtype=np.int32)
    column[interior] = np.arange(len(interior), dtype=np.int32)
    indices = column[rows.indices]
    data, indptr = rows.data, rows.indptr.astype(np.int64)
    drop = np.flatnonzero(indices < 0)
    if len(drop):
        indices, data = np.delete(indices, drop), np.delete(data, drop)
        dropped = np.bincount(np.searchsorted(indptr, drop, side="right") - 1, minlength=len(interior))
        indptr[1:] -= np.cumsum(dropped)
    index_type = np.int32 if indptr[-1] < 2**31 else np.int64
    return csr_matrix((data, indices, indptr.astype(index_type)), shape=(len(interior),) * 2), b


def _solve(a, b: np.ndarray, solver: str, tol: float) -> tuple[np.ndarray, int]:
    if solver == "direct":
        return np.atleast_1d(spsolve(a.tocsc(), b)), 0
    import pyamg
    from threadpoolctl import threadpool_limits

    residuals: list[float] = []
    with threadpool_limits(1):
        # One forward Gauss–Seidel sweep before the coarse correction and one backward after (the
        # V-cycle stays symmetric, as CG needs): 20 iterations of half the smoothing instead of 18 of
        # symmetric sweeps on both sides, 1.18 against 1.42 CPU s at 1000 x 1000 (setup 0.8 s either way)
        hierarchy = pyamg.ruge_stuben_solver(a, presmoother=("gauss_seidel", {"sweep": "forward"}),
                                             postsmoother=("gauss_seidel", {"sweep": "backward"}))
        x = hierarchy.solve(b, tol=tol, accel="cg", maxiter=1000, residuals=residuals)
    return x, max(len(residuals) - 1, 0)
