"""The continuous geometry (Nazarahari et al. 2019) against a dense-sampling oracle in plain numpy."""

import numpy as np
import pytest

from htetro_opt.errors import HtetroError, ParameterError, UnknownShapeError
from htetro_opt.model import (
    ContinuousGeometry,
    as_polygon,
    as_robot_radius,
    enclosing_radius,
    path_length,
    path_smoothness,
    robot_distance,
)

W = H = 10.0


def random_rectangles(rng, n=8):
    """Rotated rectangles (centre, half sizes, angle), some axis-aligned."""
    centre = rng.uniform(1.0, 9.0, (n, 2))
    half = rng.uniform(0.2, 1.5, (n, 2))
    angle = np.where(rng.random(n) < 0.5, 0.0, rng.uniform(0, np.pi, n))
    return centre, half, angle


def corners_of(centre, half, angle):
    signs = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]], dtype=float)
    c, s = np.cos(angle), np.sin(angle)
    local = signs[None] * half[:, None]
    return np.stack([centre[:, None, 0] + c[:, None] * local[..., 0] - s[:, None] * local[..., 1],
                     centre[:, None, 1] + s[:, None] * local[..., 0] + c[:, None] * local[..., 1]], axis=-1)


def local_frame(points, centre, half, angle):
    """|coordinates| of each point in each rectangle's frame, shape (n_points, n_rects, 2)."""
    d = points[:, None] - centre[None]
    c, s = np.cos(angle), np.sin(angle)
    return np.abs(np.stack([c * d[..., 0] + s * d[..., 1], -s * d[..., 0] + c * d[..., 1]], axis=-1))


def oracle(a, b, rects, r, spacing):
    """+1 feasible, −1 infeasible, 0 too close to call at this sampling: a segment's samples, with
    1-Lipschitz depth / distance functions, bound the true extreme within spacing / 2."""
    centre, half, angle = rects
    verdict = np.zeros(len(a), dtype=int)
    for k in range(len(a)):
        n = max(2, int(np.ceil(np.hypot(*(b[k] - a[k])) / spacing)) + 1)
        t = np.linspace(0.0, 1.0, n)[:, None]
        pts = a[k] + t * (b[k] - a[k])
        step = np.hypot(*(b[k] - a[k])) / (n - 1)
        q = local_frame(pts, centre, half, angle)
        if r == 0:
            depth = np.min(half[None] - q, axis=2).max()   # > 0 strictly inside some rectangle
            verdict[k] = -1 if depth > 0 else (1 if depth < -step / 2 else 0)
        else:
            dist = np.hypot(*np.maximum(q - half[None], 0.0).transpose(2, 0, 1)).min()
            inside = all(r <= p[i] <= (W, H)[i] - r for p in (a[k], b[k]) for i in (0, 1))
            if not inside or dist < r:
                verdict[k] = -1
            elif dist - step / 2 >= r:
                verdict[k] = 1
    return verdict


@pytest.mark.parametrize("r", [0.0, 0.3])
def test_segments_agree_with_dense_sampling(r):
    rng = np.random.default_rng(2019)
    agreed = 0
    for trial in range(5):
        rects = random_rectangles(rng)
        geo = ContinuousGeometry(W, H, list(corners_of(*rects)), robot_radius=r)
        a = rng.uniform(0, W, (2000, 2))
        b = np.clip(a + rng.normal(0, 1.5, a.shape), 0, W)
        got = geo.segments_feasible(a, b)
        want = oracle(a, b, rects, r, spacing=0.02)
        sure = want != 0
        assert np.array_equal(got[sure], want[sure] > 0), (trial, np.flatnonzero(got[sure] != (want[sure] > 0)))
        assert sure.mean() > 0.95
        assert 0.1 < got.mean() < 0.9  # both kinds are tested
        agreed += sure.sum()
    assert agreed > 9500


@pytest.mark.parametrize("r", [0.0, 0.3])
def test_points_agree_with_the_oracle_and_paths_with_their_segments(r):
    rng = np.random.default_rng(7)
    rects = random_rectangles(rng)
    geo = ContinuousGeometry(W, H, list(corners_of(*rects)), robot_radius=r)
    pts = rng.uniform(0, W, (3000, 2))
    want = oracle(pts, pts, rects, r, spacing=1.0)  # a point is its one sample: never ambiguous
    assert (want != 0).all()
    assert np.array_equal(geo.points_feasible(pts), want > 0)
    paths = [rng.uniform(0, W, (n, 2)) if n > 1 else pts[:1] for n in rng.integers(1, 6, 300)]
    paths += [np.cumsum(rng.normal(0, 0.3, (6, 2)), axis=0) + 5 for _ in range(300)]
    expected = [bool(geo.segments_feasible(p[:-1], p[1:]).all()) if len(p) > 1 else bool(geo.points_feasible(p)[0])
                for p in paths]
    assert geo.paths_feasible(paths).tolist() == expected
    assert [geo.path_feasible(p) for p in paths] == expected
    assert 0 < sum(expected) < len(paths)


def test_touching_is_allowed_and_zero_width_gaps_are_closed():
    # a wall touching the bottom edge, a box in the middle, two boxes sharing an edge
    geo = ContinuousGeometry(10, 10, [[4, 0, 6, 3], [2, 5, 3, 6], [7, 5, 8, 6], [8, 5, 9, 6]])
    a = [[4, 1], [1, 0], [2, 5], [2, 6], [7, 5], [8, 5], [8, 4], [3, 0], [0, 0]]
    b = [[4, 4], [3, 0], [3, 5], [3, 5], [9, 5], [8, 6], [8, 7], [7, 0], [0, 10]]
    # along the wall; map edge; box edge; diagonal through the box; along the pair; along the shared
    # edge; across it; under the wall along the edge; along the left edge
    assert geo.segments_feasible(a, b).tolist() == [True, True, True, False, True, False, False, False, True]


def test_a_gap_of_exactly_two_radii_is_passable_and_narrower_is_not():
    geo = ContinuousGeometry(10, 10, [[0, 4, 4, 6], [5, 4, 10, 6]], robot_radius=0.5)
    assert geo.segments_feasible([[4.5, 1]], [[4.5, 9]]).tolist() == [True]
    narrow = ContinuousGeometry(10, 10, [[0, 4, 4, 6], [4.99, 4, 10, 6]], robot_radius=0.5)
    assert narrow.segments_feasible([[4.495, 1]], [[4.495, 9]]).tolist() == [False]
    assert geo.points_feasible([[0.5, 0.5], [0.49, 1], [9.5, 9.5], [9.51, 1]]).tolist() == [True, False, True, False]


def test_clearance_is_the_distance_to_obstacles_or_edges_minus_the_radius():
    rng = np.random.default_rng(3)
    rects = random_rectangles(rng, 5)
    for r in (0.0, 0.25):
        geo = ContinuousGeometry(W, H, list(corners_of(*rects)), robot_radius=r)
        pts = rng.uniform(0, W, (500, 2))
        q = local_frame(pts, *rects)
        dist = np.hypot(*np.maximum(q - rects[1][None], 0.0).transpose(2, 0, 1)).min(axis=1)
        edge = np.minimum.reduce([pts[:, 0], W - pts[:, 0], pts[:, 1], H - pts[:, 1]])
        np.testing.assert_allclose(geo.clearance(pts), np.minimum(dist, edge) - r, atol=1e-9)
    geo = ContinuousGeometry(10, 10, [[4, 4, 6, 6]], robot_radius=0.5)
    # the segment passes the corner (4, 4) closer than either vertex does
    path = [[2.0, 5.0], [5.0, 2.0]]
    assert geo.clearance(path).tolist() == [1.5, 1.5]
    assert geo.path_clearance(path) == pytest.approx(np.sqrt(0.5) - 0.5)


def test_corners_are_the_convex_obstacle_vertices_inside_the_box():
    geo = ContinuousGeometry(10, 10, [[2, 2, 4, 4], [6, 0, 7, 5], [[6, 7], [9, 7], [7.5, 11]]])
    got = sorted(map(tuple, geo.corners().points.tolist()))
    # the wall's foot and the triangle's apex (outside the map) are no corners
    assert got == [(2, 2), (2, 4), (4, 2), (4, 4), (6, 5), (6, 7), (7, 5), (9, 7)]
    with pytest.raises(ParameterError, match="polygonised"):
        ContinuousGeometry(10, 10, [[2, 2, 4, 4]], robot_radius=0.5).corners()


def test_outer_polygonisation_has_feasible_corners_and_inner_ones_lie_on_the_c_obstacle():
    rng = np.random.default_rng(5)
    rects = random_rectangles(rng, 6)
    geo = ContinuousGeometry(W, H, list(corners_of(*rects)), robot_radius=0.4)
    outer = geo.polygonised("outer").corners().points
    inner = geo.polygonised("inner").corners().points
    assert len(outer) > 20 and len(inner) > 20
    assert geo.points_feasible(outer).all()
    assert (geo.clearance(inner) <= 1e-9).all()  # on or inside the true C-obstacle


def test_robot_distance_matches_dense_sampling():
    rng = np.random.default_rng(11)

    def position(path, t):
        steps = np.hypot(*np.diff(path, axis=0).T)
        s = np.concatenate([[0], np.cumsum(steps)])
        return np.column_stack([np.interp(t, s, path[:, 0]), np.interp(t, s, path[:, 1])])

    for _ in range(20):
        a = rng.uniform(0, 10, (rng.integers(2, 6), 2))
        b = rng.uniform(0, 10, (rng.integers(2, 6), 2))
        t = np.arange(0, max(path_length(a), path_length(b)) + 1e-6, 1e-6 * 100)
        sampled = np.hypot(*(position(a, t) - position(b, t)).T).min()
        exact = robot_distance(a, b)
        assert exact <= sampled + 1e-12
        assert sampled - exact <= 2e-4  # relative speed ≤ 2, samples 1e-4 apart
    assert robot_distance([[1, 1]], [[4, 5]]) == 5.0


def test_length_and_smoothness():
    assert path_length([[0, 0], [3, 4]]) == 5.0
    assert path_smoothness([[0, 0], [2, 0], [2, 3]]) == pytest.approx(90.0)
    assert path_smoothness([[0, 0], [1, 0], [2, 0], [2, 0], [2, 3]]) == pytest.approx(90.0)  # collinear, repeated
    assert path_smoothness([[0, 0], [1, 1], [2, 0]]) == pytest.approx(90.0)
    assert path_smoothness([[0, 0], [1, 0], [0, 0]]) == pytest.approx(180.0)


def test_enclosing_radii_of_the_morphologies():
    got = {s: round(enclosing_radius(s), 4) for s in "IOLJZST"}
    assert got == {"O": 1.4142, "T": 1.5811, "L": 1.8028, "J": 1.8028, "S": 1.8028, "Z": 1.8028, "I": 2.0616}
    with pytest.raises(UnknownShapeError):
        enclosing_radius("Q")
    assert as_robot_radius("I") == enclosing_radius("I")


@pytest.mark.parametrize("call, words", [
    (lambda: as_polygon([[0, 0], [2, 2], [2, 0], [0, 2]], "obstacles[3]"), "obstacles[3]: invalid polygon: Self-intersection"),
    (lambda: as_polygon([[0, 0], [1, 1], [2, 2]]), "invalid polygon"),
    (lambda: as_polygon([3, 0, 1, 2], "obstacles[0]"), "xmin < xmax"),
    (lambda: as_polygon([[0, 0], [1, 1]]), "at least 3"),
    (lambda: as_polygon("box"), "expected"),
    (lambda: ContinuousGeometry(10, 10, [[0, 0, 1, 1], [[0, 0], [1, np.nan], [1, 0]]]), "obstacles[1]"),
    (lambda: ContinuousGeometry(10, 4, [], robot_radius=2), "leaves no room"),
    (lambda: ContinuousGeometry(0, 4), "width"),
    (lambda: ContinuousGeometry(10, 10, 5), "obstacles must be"),
    (lambda: ContinuousGeometry(10, 10, robot_radius="Q"), "robot_radius"),
    (lambda: ContinuousGeometry(10, 10).segments_feasible([[0, 0]], [[1, 1], [2, 2]]), "same shape"),
    (lambda: ContinuousGeometry(10, 10).points_feasible([[0, 0, 0]]), "points"),
    (lambda: ContinuousGeometry(10, 10).paths_feasible([[[0, 0]], np.empty((0, 2))]), "paths[1]"),
    (lambda: ContinuousGeometry(10, 10).polygonised("middle"), "kind"),
])
def test_bad_inputs_raise_typed_errors(call, words):
    with pytest.raises(ParameterError) as info:
        call()
    assert isinstance(info.value, HtetroError) and words in str(info.value)
