"""Point-to-triangle distances against exact rational arithmetic (slivers, needles, collinear
and repeated corners, far offsets) and dense sampling, and certified triangle bounds."""

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
from meshes import barycentric_grid

from workbench.algo.nearest.triangle import (
    DISTANCE_ERROR,
    UNIT_ROUNDOFF,
    closest_point_on_triangle,
    point_triangle_distance,
    points_triangles_distance,
    triangle_bounds,
)
from workbench.reliability import exact

coords = st.floats(-10, 10, allow_nan=False, width=64)
vec3 = arrays(np.float64, 3, elements=coords)


def dense_min(p, a, b, c, n=120):
    """Smallest distance from p to a dense barycentric grid on abc, and the grid's spacing."""
    u, v = barycentric_grid(n)
    pts = a + u[:, None] * (b - a) + v[:, None] * (c - a)
    spacing = max(np.linalg.norm(b - a), np.linalg.norm(c - a), np.linalg.norm(c - b)) / n
    return np.sqrt(((pts - p) ** 2).sum(axis=1)).min(), spacing


TINY = 2.11943693e-119  # a triangle this small once divided by a squared normal that underflowed


@settings(max_examples=300, deadline=None)
@given(p=vec3, a=vec3, b=vec3, c=vec3)
@example(p=np.zeros(3), a=np.zeros(3), b=np.full(3, TINY), c=np.array([0.0, TINY, TINY]))
@example(p=np.ones(3), a=np.zeros(3), b=np.zeros(3), c=np.full(3, 6.9278465e-300))  # a point
def test_distance_matches_dense_sampling(p, a, b, c):
    d = point_triangle_distance(p, a, b, c)
    brute, spacing = dense_min(p, a, b, c)
    # the exact minimum is at most any sample, and a sample lies within one spacing of it
    assert d <= brute + 1e-9
    assert d >= brute - spacing - 1e-9


@settings(max_examples=200, deadline=None)
@given(p=vec3, a=vec3, b=vec3, c=vec3)
@example(p=np.zeros(3), a=np.zeros(3), b=np.full(3, TINY), c=np.array([0.0, TINY, TINY]))
def test_closest_point_lies_on_the_triangle(p, a, b, c):
    out = np.empty(3)
    d2 = closest_point_on_triangle(p, a, b, c, out)
    assert np.isfinite(out).all() and d2 >= 0
    assert abs(np.sqrt(d2) - np.linalg.norm(p - out)) <= 1e-9 * (1 + np.sqrt(d2))
    # out is in the triangle: the distance from out to the triangle is ~0
    assert point_triangle_distance(out, a, b, c) <= 1e-7 * (1 + np.abs([a, b, c]).max())


def kernel_bound(p, a, b, c):
    """The documented error bound of the kernel: DISTANCE_ERROR · u · max_i |p − corner_i|."""
    r = max(np.linalg.norm(p - a), np.linalg.norm(p - b), np.linalg.norm(p - c))
    return DISTANCE_ERROR * UNIT_ROUNDOFF * r


def thin_triangle(rng, kind, eps, size, offset):
    """A triangle of ``size`` whose third corner is ``eps·size`` from the segment of the first
    two (``cap``), from the first corner (``needle``), on that segment up to rounding
    (``collinear``), equal to a corner (``repeated``), or anywhere (``plain``); all moved by
    ``offset``."""
    a, b = rng.normal(size=3) * size, rng.normal(size=3) * size
    if kind == "cap":
        c = a + rng.uniform(-0.2, 1.2) * (b - a) + rng.normal(size=3) * eps * size
    elif kind == "needle":
        c = a + rng.normal(size=3) * eps * size
    elif kind == "collinear":
        c = a + rng.uniform(0, 1) * (b - a)
    elif kind == "repeated":
        c = b.copy()
    else:
        c = rng.normal(size=3) * size
    return a + offset, b + offset, c + offset


@settings(max_examples=400, deadline=None)
@given(seed=st.integers(0, 2**32 - 1),
       kind=st.sampled_from(["cap", "needle", "collinear", "repeated", "plain"]),
       log_eps=st.floats(-15, -2), log_size=st.floats(-3, 3), log_offset=st.floats(0, 7),
       far=st.booleans(), log_reach=st.floats(-4, 1))
def test_distance_is_within_the_error_bound_of_the_exact_one(seed, kind, log_eps, log_size,
                                                             log_offset, far, log_reach):
    """The kernel's distance is within its documented bound (64 u max_i |p − corner_i|) of the
    exact rational distance, on thin, flat and far-away triangles, points near and far."""
    rng = np.random.default_rng(seed)
    size = 10.0 ** log_size
    offset = rng.normal(size=3) * 10.0 ** log_offset if far else np.zeros(3)
    a, b, c = thin_triangle(rng, kind, 10.0 ** log_eps, size, offset)
    p = rng.dirichlet([1, 1, 1]) @ np.array([a, b, c]) + rng.normal(size=3) * size * \
        10.0 ** log_reach
    out = np.empty(3)
    d = np.sqrt(closest_point_on_triangle(p, a, b, c, out))
    assert abs(d - exact.point_triangle_distance(p, a, b, c)) <= kernel_bound(p, a, b, c)
    # the point returned lies on the triangle, to the rounding of its coordinates
    scale = np.abs([a, b, c, p]).max()
    assert exact.point_triangle_distance(out, a, b, c) <= 8 * UNIT_ROUNDOFF * scale


@pytest.mark.parametrize("scale", [1e-150, 1e-100, 1e-76, 1e-40, 1.0, 1e40, 1e76, 1e100, 1e150])
def test_tiny_and_huge_triangles_keep_their_accuracy(scale):
    """Far below or above unit size (where the squared normal, the fourth power of the size,
    under- or overflows) the kernel measures a scaled copy: within its bound of exact."""
    rng = np.random.default_rng(5)
    for _ in range(20):
        a, b, c, p = rng.normal(size=(4, 3)) * scale
        d = point_triangle_distance(p, a, b, c)
        assert abs(d - exact.point_triangle_distance(p, a, b, c)) <= kernel_bound(p, a, b, c)
        # a point at unit distance from the triangle, however small or large it is
        q = a + rng.normal(size=3)
        d = point_triangle_distance(q, a, b, c)
        assert abs(d - exact.point_triangle_distance(q, a, b, c)) <= kernel_bound(q, a, b, c)


def test_the_sliver_example_is_exact():
    """A corner 2⁻²³ from another: the closest point the old region walk returned was 0.0077
    off the triangle."""
    a, b, c = np.array([2.078125, 0, 2.078125]), np.zeros(3), 2.0 ** -23 * np.ones(3)
    p = np.array([0, 3.625, 3.625])
    out = np.empty(3)
    d = np.sqrt(closest_point_on_triangle(p, a, b, c, out))
    assert abs(d - exact.point_triangle_distance(p, a, b, c)) <= kernel_bound(p, a, b, c)
    assert exact.point_triangle_distance(out, a, b, c) <= 1e-15


@pytest.mark.parametrize("tri", [
    [[0, 0, 0], [0, 0, 0], [0, 0, 0]],            # a point
    [[0, 0, 0], [1, 0, 0], [1, 0, 0]],            # repeated vertex: a segment
    [[0, 0, 0], [1, 0, 0], [3, 0, 0]],            # collinear
    [[0, 0, 0], [1, 1e-13, 0], [2, 0, 0]],        # zero area to rounding
])
def test_degenerate_triangles_are_their_edges(tri):
    a, b, c = (np.array(v, np.float64) for v in tri)
    rng = np.random.default_rng(3)
    for p in rng.normal(size=(50, 3)) * 3:
        d = point_triangle_distance(p, a, b, c)
        assert abs(d - exact.point_triangle_distance(p, a, b, c)) <= kernel_bound(p, a, b, c)


def test_points_far_away_keep_their_distance():
    a, b, c = np.eye(3)
    p = np.array([1e8, 0.0, 0.0])
    assert point_triangle_distance(p, a, b, c) == pytest.approx(1e8 - 1.0, rel=1e-15)
    # a point above the face centroid: distance along the normal
    centroid = (a + b + c) / 3
    normal = np.ones(3) / np.sqrt(3)
    assert (point_triangle_distance(centroid + 0.25 * normal, a, b, c)
            == pytest.approx(0.25, abs=1e-15))


def test_brute_force_table_agrees_with_single_calls():
    rng = np.random.default_rng(0)
    pts, tris = rng.normal(size=(7, 3)), rng.normal(size=(5, 3, 3))
    table = points_triangles_distance(pts, tris)
    for i, p in enumerate(pts):
        for j, t in enumerate(tris):
            assert table[i, j] == point_triangle_distance(p, *t)


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 10**6), n_faces=st.integers(1, 4))
def test_triangle_bounds_bracket_the_farthest_point(seed, n_faces):
    rng = np.random.default_rng(seed)
    t = rng.normal(size=(3, 3))
    faces = t[None] + 0.4 * rng.normal(size=(n_faces, 3, 3))
    lower, upper = triangle_bounds(t, faces, 0.0, 6)
    # the 2^6 barycentric grid holds every corner the bounds looked at, and more: its largest
    # distance to the union lies inside the bracket
    n = 64
    u, v = barycentric_grid(n)
    pts = t[0] + u[:, None] * (t[1] - t[0]) + v[:, None] * (t[2] - t[0])
    sampled = points_triangles_distance(pts, faces).min(axis=1).max()
    assert lower <= sampled + 1e-9
    assert sampled <= upper + 1e-12
    # refining deeper never widens the bracket
    lower2, upper2 = triangle_bounds(t, faces, 0.0, 8)
    assert lower2 >= lower - 1e-12 and upper2 <= upper + 1e-12


def test_a_triangle_on_its_own_face_is_at_distance_zero():
    t = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], np.float64)
    assert triangle_bounds(t, t[None], 0.0, 4) == (0.0, 0.0)
    # split in two faces along the diagonal: the union covers t exactly
    halves = np.array([[[0, 0, 0], [1, 0, 0], [0.5, 0.5, 0]],
                       [[0, 0, 0], [0.5, 0.5, 0], [0, 1, 0]]])
    lower, upper = triangle_bounds(t, halves, 1e-3, 12)
    assert lower == 0.0 and upper <= 1e-3
