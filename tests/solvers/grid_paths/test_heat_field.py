"""The heat-conduction field (Do et al. 2021, §IV): invariants over random maps and independent oracles
(scikit-fem's own assembly for Q1, a numpy 5-point finite-difference solve for P0)."""

from __future__ import annotations

import numpy as np
import pytest
import skfem as fem
from skfem.helpers import dot, grad

from htetro_opt.errors import ConfigurationError, ParameterError
from htetro_opt.model.workspace import Workspace
from htetro_opt.solvers.grid_paths import HeatField, solve_heat_field


def random_case(seed: int, density: float = 0.3):
    """A random map and two distinct free cells (source, sink)."""
    rng = np.random.default_rng(seed)
    h, w = rng.integers(5, 12, size=2)
    occ = rng.random((h, w)) < density
    free = np.argwhere(~occ)
    a, b = rng.choice(len(free), size=2, replace=False)
    (sy, sx), (zy, zx) = free[a], free[b]
    return occ, (int(sx), int(sy)), (int(zx), int(zy))


def diagonal_map() -> np.ndarray:
    occ = np.ones((3, 3), dtype=bool)
    occ[[0, 1, 2], [0, 1, 2]] = False
    return occ


@pytest.mark.parametrize("element", ["q1", "p0"])
@pytest.mark.parametrize("split", [True, False])
def test_values_bounded_and_prescribed(element, split):
    connected = 0
    for seed in range(40):
        occ, source, sink = random_case(seed)
        field = solve_heat_field(Workspace(occ), source, sink, element=element, split_pinches=split)
        assert isinstance(field, HeatField) and field.cells.shape == occ.shape
        assert np.isnan(field.cells[occ]).all()
        if not field.connected:
            continue
        connected += 1
        values = field.cells[~np.isnan(field.cells)]
        assert values.min() >= -1e-9 and values.max() <= 1 + 1e-9
        assert field.cells[source[1], source[0]] == 1.0 and field.cells[sink[1], sink[0]] == 0.0
        if element == "q1":
            nodes = field.corners[~np.isnan(field.corners)]
            assert nodes.min() >= -1e-9 and nodes.max() <= 1 + 1e-9
    assert connected >= 10


def _touches(cell, node_xy) -> bool:
    (x, y), (nx, ny) = cell, node_xy
    return x <= nx <= x + 1 and y <= ny <= y + 1


@pytest.mark.parametrize("split", [True, False])
def test_q1_nodes_have_no_strict_interior_extremum(split):
    checked = 0
    for seed in range(30):
        occ, source, sink = random_case(seed)
        field = solve_heat_field(Workspace(occ), source, sink, split_pinches=split)
        if not field.connected:
            continue
        h, w = occ.shape
        c = field.corners
        for ny in range(h + 1):
            for nx in range(w + 1):
                if _touches(source, (nx, ny)) or _touches(sink, (nx, ny)):
                    continue  # Dirichlet dofs (and the rare shared ones beside them)
                around = [(x, y) for x in (nx - 1, nx) for y in (ny - 1, ny)
                          if 0 <= x < w and 0 <= y < h and not np.isnan(c[y, x]).any()]
                if not around:
                    continue
                # An unsplit node is one dof of all its cells; a split one, one dof per cell.
                groups = [around] if not np.isnan(field.nodes[ny, nx]) else [[cell] for cell in around]
                for group in groups:
                    x0, y0 = group[0]
                    value = c[y0, x0, ny - y0, nx - x0]
                    neighbours = [c[y, x, j, i] for x, y in group for j in (0, 1) for i in (0, 1)
                                  if (x + i, y + j) != (nx, ny)]
                    assert max(neighbours) >= value - field.epsilon
                    assert min(neighbours) <= value + field.epsilon
                    checked += 1
    assert checked > 500


def test_p0_cells_have_no_strict_interior_extremum():
    checked = 0
    for seed in range(30):
        occ, source, sink = random_case(seed)
        field = solve_heat_field(Workspace(occ), source, sink, element="p0")
        if not field.connected:
            continue
        t = field.cells
        h, w = occ.shape
        for y, x in np.argwhere(~np.isnan(t)):
            if (x, y) in (source, sink):
                continue
            neighbours = [t[y + dy, x + dx] for dx, dy in ((1, 0), (-1, 0), (0, 1), (0, -1))
                          if 0 <= x + dx < w and 0 <= y + dy < h and not np.isnan(t[y + dy, x + dx])]
            assert max(neighbours) >= t[y, x] - field.epsilon
            assert min(neighbours) <= t[y, x] + field.epsilon
            checked += 1
    assert checked > 200


def test_diagonal_corner_leak_and_split():
    ws = Workspace(diagonal_map())
    leaky = solve_heat_field(ws, (2, 2), (0, 0), split_pinches=False)
    assert leaky.connected and 0 < leaky.cells[1, 1] < 1
    split = solve_heat_field(ws, (2, 2), (0, 0))
    assert not split.connected and split.info["pinches"] == 2 and np.isnan(split.cells).all()
    assert not solve_heat_field(ws, (2, 2), (0, 0), element="p0").connected


def test_corner_only_contact_of_regions_is_disconnected():
    occ = np.ones((4, 4), dtype=bool)
    occ[:2, :2] = False  # start region, bottom left
    occ[2:, 2:] = False  # goal region, top right: touches the start region at node (2, 2) only
    ws = Workspace(occ)
    for element in ("q1", "p0"):
        assert not solve_heat_field(ws, (3, 3), (0, 0), element=element).connected
    assert solve_heat_field(ws, (3, 3), (0, 0), split_pinches=False).connected
    # An isolated free region is dropped, the rest is solved.
    occ[3, 0] = False
    occ[2, 2] = True
    occ[1, 2] = False
    occ[1, 3] = False
    field = solve_heat_field(Workspace(occ), (3, 3), (0, 0))
    assert field.connected and np.isnan(field.cells[3, 0])


@pytest.mark.parametrize("element", ["q1", "p0"])
def test_transpose_and_mirror(element):
    for seed in range(10):
        occ, (sx, sy), (zx, zy) = random_case(seed)
        h, w = occ.shape
        base = solve_heat_field(Workspace(occ), (sx, sy), (zx, zy), element=element)
        transposed = solve_heat_field(Workspace(occ.T), (sy, sx), (zy, zx), element=element)
        mirrored = solve_heat_field(Workspace(occ[:, ::-1]), (w - 1 - sx, sy), (w - 1 - zx, zy), element=element)
        flipped = solve_heat_field(Workspace(occ[::-1]), (sx, h - 1 - sy), (zx, h - 1 - zy), element=element)
        assert base.connected == transposed.connected == mirrored.connected == flipped.connected
        np.testing.assert_allclose(transposed.cells, base.cells.T, atol=1e-10)
        np.testing.assert_allclose(mirrored.cells, base.cells[:, ::-1], atol=1e-10)
        np.testing.assert_allclose(flipped.cells, base.cells[::-1], atol=1e-10)


def test_p0_is_the_five_point_scheme():
    occ = np.zeros((6, 7), dtype=bool)
    occ[3, :5] = True  # a wall with a gap on the right
    occ[0, 3] = occ[5, 3] = True
    source, sink = (1, 5), (0, 0)
    free = [tuple(c) for c in np.argwhere(~occ)]  # (y, x), all 4-connected on this map
    index = {cell: k for k, cell in enumerate(free)}
    n = len(free)
    laplacian = np.zeros((n, n))
    for (y, x), k in index.items():
        for dy, dx in ((1, 0), (-1, 0), (0, 1), (0, -1)):
            other = index.get((y + dy, x + dx))
            if other is not None:
                laplacian[k, k] += 1
                laplacian[k, other] -= 1
    hot, cold = index[source[::-1]], index[sink[::-1]]
    rhs = np.zeros(n)
    for k, value in ((hot, 1.0), (cold, 0.0)):
        laplacian[k] = 0
        laplacian[k, k] = 1
        rhs[k] = value
    expected = np.full(occ.shape, np.nan)
    expected[tuple(np.array(free).T)] = np.linalg.solve(laplacian, rhs)
    field = solve_heat_field(Workspace(occ), source, sink, element="p0")
    assert field.nodes is None and field.corners is None
    np.testing.assert_allclose(field.cells, expected, atol=1e-12)


def pinch_nodes(occ) -> set[tuple[int, int]]:
    """Interior nodes (x, y) where two free cells touch only at that corner (two diagonal patterns)."""
    free = ~occ
    h, w = occ.shape
    return {(x, y) for y in range(1, h) for x in range(1, w)
            if (free[y - 1, x - 1] and free[y, x] and not free[y - 1, x] and not free[y, x - 1])
            or (free[y - 1, x] and free[y, x - 1] and not free[y - 1, x - 1] and not free[y, x])}


def skfem_reference(occ, source, sink, k_obstacle, scale, split=False):
    """Q1 with scikit-fem's own assembly on the conducting cells, k scaled by ``scale``; with ``split``
    every pinch node is one mesh node per element around it."""
    cells = np.argwhere(np.ones_like(occ) if k_obstacle > 0 else ~occ)  # (y, x)
    corner = [(0, 0), (1, 0), (1, 1), (0, 1)]  # counter-clockwise (i, j)
    pinches = pinch_nodes(occ) if split else set()
    keys = {}  # a mesh node per grid node, or per (grid node, element) at a pinch
    t, p = [], []
    for y, x in cells:
        column = []
        for i, j in corner:
            node = (int(x + i), int(y + j))
            key = (node, (int(x), int(y))) if node in pinches else (node, None)
            if key not in keys:
                keys[key] = len(keys)
                p.append(node)
            column.append(keys[key])
        t.append(column)
    t = np.array(t).T
    mesh = fem.MeshQuad1(np.array(p, dtype=float).T, t)
    basis = fem.Basis(mesh, fem.ElementQuad1())
    basis0 = basis.with_element(fem.ElementQuad0())
    k = scale * np.where(occ[cells[:, 0], cells[:, 1]], k_obstacle, 1.0)

    @fem.BilinearForm
    def conduction(u, v, w_):
        return w_.k * dot(grad(u), grad(v))

    a = fem.asm(conduction, basis, k=basis0.interpolate(k))
    element_of = {(int(x), int(y)): e for e, (y, x) in enumerate(cells)}
    hot, cold = t[:, element_of[source]], t[:, element_of[sink]]
    x = np.zeros(basis.N)
    x[hot] = 1.0
    u = fem.solve(*fem.condense(a, np.zeros(basis.N), x=x, D=np.concatenate([hot, cold])))
    temperature = np.full(occ.shape, np.nan)
    for e, (y, xx) in enumerate(cells):
        if not occ[y, xx]:
            temperature[y, xx] = u[t[:, e]].mean()
    return temperature


@pytest.mark.parametrize("scale", [1.0, 7.5])
def test_q1_matches_scikit_fem_and_ignores_the_conductivity_scale(scale):
    compared = 0
    for seed in range(8):
        occ, source, sink = random_case(seed)
        if abs(source[0] - sink[0]) <= 1 and abs(source[1] - sink[1]) <= 1:
            continue  # touching cells: shared nodes left free, which the plain reference cannot do
        expected = skfem_reference(occ, source, sink, 0.05, scale)
        field = solve_heat_field(Workspace(occ), source, sink, k_obstacle=0.05, split_pinches=False)
        assert field.connected
        np.testing.assert_allclose(field.cells, expected, atol=1e-10)
        compared += 1
    assert compared >= 5


def test_split_pinches_match_scikit_fem_on_a_mesh_with_the_copies():
    """The split mesh assembled by scikit-fem (a node per element at each pinch) gives our field, with
    obstacles conducting (all four elements at a pinch carry a copy) and removed (two do)."""
    compared = 0
    for seed in range(40):
        occ, source, sink = random_case(seed)
        if abs(source[0] - sink[0]) <= 1 and abs(source[1] - sink[1]) <= 1 or not pinch_nodes(occ):
            continue
        for k_obstacle in (0.05, 0.0):
            field = solve_heat_field(Workspace(occ), source, sink, k_obstacle=k_obstacle)
            assert field.info["pinches"] == len(pinch_nodes(occ))
            if not field.connected or np.isnan(field.cells[~occ]).any():
                continue  # free regions without a prescribed cell: singular for the plain reference
            expected = skfem_reference(occ, source, sink, k_obstacle, 1.0, split=True)
            np.testing.assert_allclose(field.cells, expected, atol=1e-10)
            compared += 1
    assert compared >= 8


@pytest.mark.parametrize("element", ["q1", "p0"])
def test_small_k_obstacle_converges_to_removal(element):
    compared = 0
    for seed in range(8):
        occ, source, sink = random_case(seed, density=0.25)
        removed = solve_heat_field(Workspace(occ), source, sink, element=element)
        if not removed.connected:
            continue
        finite = ~np.isnan(removed.cells)
        errors = [np.abs(solve_heat_field(Workspace(occ), source, sink, element=element, k_obstacle=k).cells
                         - removed.cells)[finite].max() for k in (1e-2, 1e-4, 1e-6)]
        assert errors[0] > errors[1] > errors[2] and errors[2] < 1e-4
        compared += 1
    assert compared >= 3


@pytest.mark.parametrize("element", ["q1", "p0"])
def test_amg_agrees_with_direct(element):
    rng = np.random.default_rng(3)
    occ = rng.random((64, 64)) < 0.2
    occ[20, 5:60] = occ[45, 4:64] = True
    occ[0, 0] = occ[63, 63] = False
    ws = Workspace(occ)
    direct = solve_heat_field(ws, (63, 63), (0, 0), element=element, solver="direct")
    amg = solve_heat_field(ws, (63, 63), (0, 0), element=element, solver="amg", tol=1e-8)
    assert direct.connected and amg.info["solver"] == "amg" and amg.info["iterations"] > 0
    assert amg.epsilon == pytest.approx(1e-7) and direct.epsilon == 1e-12
    np.testing.assert_allclose(amg.cells, direct.cells, atol=10 * 1e-8)
    assert solve_heat_field(ws, (63, 63), (0, 0), element=element).info["solver"] == "direct"  # auto, small


def test_same_cell_and_gradient():
    ws = Workspace(np.zeros((4, 5), dtype=bool))
    zero = solve_heat_field(ws, (2, 1), (2, 1))
    assert zero.connected and np.all(zero.cells == 0)
    field = solve_heat_field(ws, (4, 2), (0, 2))
    gx, gy = field.gradient()
    # Heat flows from the goal at the right to the start at the left (flat inside the prescribed cells).
    assert (gx >= 0).all() and (gx[:, 1:4] > 0).all()
    p0 = solve_heat_field(ws, (4, 2), (0, 2), element="p0")
    assert (p0.gradient()[0] > 0).all()
    holes = np.zeros((3, 3), dtype=bool)
    holes[1, 1] = True
    gx, gy = solve_heat_field(Workspace(holes), (2, 2), (0, 0)).gradient()
    assert np.isnan(gx[1, 1]) and np.isnan(gy[1, 1]) and not np.isnan(gx[0, 0])


def test_adjacent_source_and_sink_keep_their_values():
    ws = Workspace(np.zeros((3, 3), dtype=bool))
    field = solve_heat_field(ws, (1, 1), (2, 1))
    assert field.cells[1, 1] == 1.0 and field.cells[1, 2] == 0.0
    assert np.all((field.cells > 0) & (field.cells < 1) | np.isin(field.cells, (0.0, 1.0)))
    shared = field.nodes[1:3, 2]  # nodes (2, 1) and (2, 2), corners of both cells: left free
    assert np.all((shared > 0) & (shared < 1))
    np.testing.assert_array_equal(field.corners[1, 1, :, 0], 1.0)
    np.testing.assert_array_equal(field.corners[1, 2, :, 1], 0.0)


@pytest.mark.parametrize("kwargs, error, match", [
    ({"element": "q2"}, ParameterError, "element"),
    ({"solver": "cg"}, ParameterError, "solver"),
    ({"k_obstacle": 1.0}, ParameterError, "k_obstacle"),
    ({"k_obstacle": -0.1}, ParameterError, "k_obstacle"),
    ({"tol": 0.0}, ParameterError, "tol"),
    ({"split_pinches": 1}, ParameterError, "split_pinches"),
    ({"source": (5, 0)}, ConfigurationError, "source"),
    ({"sink": (1, 1)}, ConfigurationError, "sink"),
    ({"sink": (0, -1)}, ConfigurationError, "sink"),
    ({"source": (0.5, 1)}, ParameterError, "source"),
    ({"source": 3}, ParameterError, "source"),
])
def test_bad_inputs(kwargs, error, match):
    occ = np.zeros((3, 4), dtype=bool)
    occ[1, 1] = True
    args = {"source": (3, 2), "sink": (0, 0), **kwargs}
    with pytest.raises(error, match=match):
        solve_heat_field(Workspace(occ), args.pop("source"), args.pop("sink"), **args)
    with pytest.raises(ParameterError, match="workspace"):
        solve_heat_field(occ, (3, 2), (0, 0))
