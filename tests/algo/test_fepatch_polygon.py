"""Polygon-with-holes retriangulation (fe2003 section 3.4): tiling, orientation, counts, shape."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from matplotlib.path import Path

from workbench.algo.fepatch.polygon import polygon_area, triangulate_polygon


# ----------------------------------------------------------------- brute-force references
def signed_areas(pts, tris):
    a, b, c = pts[tris[:, 0]], pts[tris[:, 1]], pts[tris[:, 2]]
    return 0.5 * ((b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1])
                  - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0]))


def interiors_overlap(pts, tris, rel_tol=1e-12):
    """Pairs of CCW triangles whose open interiors intersect (separating-axis test).

    Two convex sets have disjoint interiors iff some edge line of one of them has all vertices
    of the other on its closed outer side; the tolerance absorbs rounding at shared vertices.
    """
    scale = np.ptp(pts[np.unique(tris)], axis=0).max() ** 2
    T = pts[tris]  # (K, 3, 2)
    K = len(T)
    i, j = np.triu_indices(K, 1)

    def separated(A, B):
        sep = np.zeros(len(A), dtype=bool)
        for s in range(3):
            p, q = A[:, s], A[:, (s + 1) % 3]
            e = q - p
            d = (e[:, None, 0] * (B[:, :, 1] - p[:, None, 1])
                 - e[:, None, 1] * (B[:, :, 0] - p[:, None, 0]))
            sep |= (d <= rel_tol * scale).all(axis=1)
        return sep

    bad = ~(separated(T[i], T[j]) | separated(T[j], T[i]))
    return list(zip(i[bad].tolist(), j[bad].tolist()))


def inside(pts, loop, p):
    """Point in polygon by matplotlib's Path (independent of the module's crossing test)."""
    return bool(Path(pts[loop]).contains_point(p))


def angles_deg(pts, tris):
    T = pts[tris]
    out = []
    for s in range(3):
        u = T[:, (s + 1) % 3] - T[:, s]
        v = T[:, (s + 2) % 3] - T[:, s]
        out.append(np.degrees(np.arctan2(np.abs(u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0]),
                                         (u * v).sum(1))))
    return np.stack(out, axis=1)


def check_triangulation(pts, outer, holes, tris):
    """Every property a triangulation of the polygon must have."""
    n_total = len(outer) + sum(len(h) for h in holes)
    assert tris.shape == (n_total + 2 * len(holes) - 2, 3)
    assert np.issubdtype(tris.dtype, np.integer)
    loop_idx = set(np.concatenate([np.asarray(outer)] + [np.asarray(h) for h in holes]).tolist())
    assert set(tris.ravel().tolist()) == loop_idx  # only loop points, and all of them
    assert (np.sort(tris, axis=1)[:, :-1] != np.sort(tris, axis=1)[:, 1:]).all()
    areas = signed_areas(pts, tris)
    assert (areas > 0).all(), "every triangle counter-clockwise and non-degenerate"
    expected = abs(polygon_area(pts, outer)) - sum(abs(polygon_area(pts, h)) for h in holes)
    assert math.isclose(areas.sum(), expected, rel_tol=1e-9)
    assert interiors_overlap(pts, tris) == []
    centroids = pts[tris].mean(axis=1)
    for c in centroids:
        assert inside(pts, np.asarray(outer), c)
        assert not any(inside(pts, np.asarray(h), c) for h in holes)


# ----------------------------------------------------------------- random polygons with holes
HOLE_CENTRES = [(0.0, 0.0), (0.5, 0.0), (-0.5, 0.0), (0.0, 0.5), (0.0, -0.5), (0.5, 0.5),
                (-0.5, -0.5)]


@st.composite
def polygons_with_holes(draw):
    """Star-shaped outer loop around the origin with radii in [2, 4] and at least 6 points
    whose angular gaps stay below 2*pi/3 (so the disk of radius 1 is inside), plus up to
    seven small convex holes of radius <= 0.2 on centres 0.5 apart inside that disk."""
    n = draw(st.integers(6, 30))
    jitter = draw(st.lists(st.floats(0.0, 0.8), min_size=n, max_size=n))
    radii = draw(st.lists(st.floats(2.0, 4.0), min_size=n, max_size=n))
    ang = 2 * np.pi * (np.arange(n) + np.asarray(jitter)) / n
    outer_xy = np.stack([np.asarray(radii) * np.cos(ang), np.asarray(radii) * np.sin(ang)], axis=1)
    centres = draw(st.lists(st.sampled_from(HOLE_CENTRES), unique=True, max_size=len(HOLE_CENTRES)))
    hole_xy = []
    for cx, cy in centres:
        m = draw(st.integers(3, 7))
        r = draw(st.floats(0.05, 0.2))
        phase = draw(st.floats(0.0, 2 * np.pi))
        jit = draw(st.lists(st.floats(0.0, 0.5), min_size=m, max_size=m))
        a = phase + 2 * np.pi * (np.arange(m) + np.asarray(jit)) / m
        hole_xy.append(np.stack([cx + r * np.cos(a), cy + r * np.sin(a)], axis=1))
    all_xy = np.concatenate([outer_xy] + hole_xy) if hole_xy else outer_xy
    # Shuffle the point order and add unused points, so indices carry no hidden order.
    extra = draw(st.integers(0, 3))
    perm = np.asarray(draw(st.permutations(range(len(all_xy) + extra))))
    pts = np.full((len(all_xy) + extra, 2), 99.0)
    pts[perm[: len(all_xy)]] = all_xy
    pts[perm[len(all_xy):], 0] += np.arange(extra)
    where = perm[: len(all_xy)]
    outer = where[:n]
    if draw(st.booleans()):
        outer = outer[::-1]
    holes, start = [], n
    for h in hole_xy:
        loop = where[start : start + len(h)]
        start += len(h)
        holes.append(loop[::-1] if draw(st.booleans()) else loop)
    return pts, outer, holes


@settings(max_examples=60, deadline=None)
@given(polygons_with_holes())
def test_random_polygons_with_holes_are_tiled(case):
    pts, outer, holes = case
    tris = triangulate_polygon(pts, outer, holes)
    check_triangulation(pts, outer, holes, tris)


def _segments_meet(p, q, r, s):
    """Exact closed-segment intersection on integer coordinates."""
    def orient(a, b, c):
        return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])

    def on(a, b, c):  # c on segment ab, given collinear
        return (min(a[0], b[0]) <= c[0] <= max(a[0], b[0])
                and min(a[1], b[1]) <= c[1] <= max(a[1], b[1]))

    d1, d2, d3, d4 = orient(r, s, p), orient(r, s, q), orient(p, q, r), orient(p, q, s)
    if ((d1 > 0) != (d2 > 0)) and d1 and d2 and ((d3 > 0) != (d4 > 0)) and d3 and d4:
        return True
    return (
        (d1 == 0 and on(r, s, p)) or (d2 == 0 and on(r, s, q))
        or (d3 == 0 and on(p, q, r)) or (d4 == 0 and on(p, q, s))
    )


def brute_force_simple(xy):
    """Whether a loop of distinct integer points is simple: no two non-neighbouring edges meet
    and no neighbouring pair overlaps beyond its common point."""
    n = len(xy)
    edges = [(xy[k], xy[(k + 1) % n]) for k in range(n)]
    for i in range(n):
        for j in range(i + 1, n):
            (p, q), (r, s) = edges[i], edges[j]
            if j == i + 1 or (i == 0 and j == n - 1):
                a, m, c = (p, q, s) if j == i + 1 else (r, s, q)  # m is the shared point
                u, v = (m[0] - a[0], m[1] - a[1]), (c[0] - m[0], c[1] - m[1])
                if u[0] * v[1] - u[1] * v[0] == 0 and u[0] * v[0] + u[1] * v[1] < 0:
                    return False
                if n == 3:
                    continue
            elif _segments_meet(p, q, r, s):
                return False
    return True


@settings(max_examples=300, deadline=None)
@given(st.lists(st.tuples(st.integers(0, 4), st.integers(0, 4)), min_size=3, max_size=9,
                unique=True))
def test_random_grid_loops_are_refused_exactly_when_not_simple(xy):
    # A 5 x 5 grid makes collinear points, touching edges and flat corners common.
    pts = np.asarray(xy, dtype=float)
    loop = np.arange(len(xy))
    if brute_force_simple(xy):
        if polygon_area(pts, loop) == 0.0:
            return  # only a triangle of collinear points is simple with zero area
        tris = triangulate_polygon(pts, loop)
        check_triangulation(pts, loop, [], tris)
    else:
        with pytest.raises(ValueError, match="cross or touch|folds back|zero area"):
            triangulate_polygon(pts, loop)


# ----------------------------------------------------------------- fixed shapes
def test_square_with_square_hole():
    pts = np.array(
        [[0, 0], [4, 0], [4, 4], [0, 4], [1, 1], [3, 1], [3, 3], [1, 3]], dtype=float
    )
    tris = triangulate_polygon(pts, [0, 1, 2, 3], [[4, 5, 6, 7]])
    check_triangulation(pts, [0, 1, 2, 3], [[4, 5, 6, 7]], tris)
    assert len(tris) == 8
    assert math.isclose(signed_areas(pts, tris).sum(), 12.0, rel_tol=1e-12)


def test_comb_shaped_concave_polygon():
    teeth, width, gap, depth = 6, 1.0, 0.5, 5.0
    top = []
    x = 0.0
    for _ in range(teeth):
        top += [(x, 1.0), (x, 1.0 + depth), (x + width, 1.0 + depth), (x + width, 1.0)]
        x += width + gap
    x_end = x - gap
    xy = [(0.0, 0.0), (x_end, 0.0)] + top[::-1]
    pts = np.asarray(xy, dtype=float)
    outer = np.arange(len(pts))
    assert polygon_area(pts, outer) > 0
    tris = triangulate_polygon(pts, outer)
    check_triangulation(pts, outer, [], tris)
    expected = x_end * 1.0 + teeth * width * depth
    assert math.isclose(signed_areas(pts, tris).sum(), expected, rel_tol=1e-12)


def test_comb_with_holes_in_every_tooth_and_offset_far_from_origin():
    # Holes share their rightmost x with each other (a column) and sit in concave pockets;
    # coordinates near 1e6 mm like a car body.
    pts = [(0, 0), (9, 0), (9, 6), (7, 6), (7, 2), (5, 2), (5, 6), (3, 6), (3, 2), (2, 2), (2, 6),
           (0, 6)]
    holes = []
    for cx in (1.0, 4.0, 8.0):
        for cy in (1.0, 4.0):
            base = len(pts)
            pts += [(cx - 0.3, cy - 0.3), (cx + 0.3, cy - 0.3), (cx + 0.3, cy + 0.3),
                    (cx - 0.3, cy + 0.3)]
            holes.append(list(range(base, base + 4)))
    pts = np.asarray(pts, dtype=float) + 1.0e6
    outer = list(range(12))
    tris = triangulate_polygon(pts, outer, holes)
    check_triangulation(pts, outer, holes, tris)


def test_holes_in_a_row_bridge_through_each_other():
    # Each hole's ray to the right meets the next hole, already merged.
    pts = [(0, 0), (20, 0), (20, 2), (0, 2)]
    holes = []
    for k in range(6):
        base = len(pts)
        cx = 2.0 + 3.0 * k
        pts += [(cx - 0.5, 0.8), (cx + 0.5, 1.0), (cx - 0.5, 1.2)]
        holes.append([base, base + 1, base + 2])
    pts = np.asarray(pts, dtype=float)
    tris = triangulate_polygon(pts, [0, 1, 2, 3], holes)
    check_triangulation(pts, [0, 1, 2, 3], holes, tris)


def test_regular_hexagon_has_no_angle_below_30_degrees():
    # Every angle of a triangle on the vertices of a regular hexagon is an inscribed angle
    # over k sides, i.e. a multiple of 30 degrees; so 30 is the bound, and a triangle that is
    # degenerate or built from wrong indices would show a smaller angle.
    a = np.radians(60.0 * np.arange(6))
    pts = np.stack([np.cos(a), np.sin(a)], axis=1)
    tris = triangulate_polygon(pts, range(6))
    check_triangulation(pts, np.arange(6), [], tris)
    assert angles_deg(pts, tris).min() >= 30.0 - 1e-9


def test_ladder_prefers_right_isosceles_over_slivers():
    # A 12 x 1 strip with points every unit along both long sides: only the four corners are
    # ears at first (45 degrees each). Taking the best-shaped ear every time builds the zig-zag
    # of 45-45-90 triangles; any other choice makes a triangle spanning two or more units of
    # one side, whose smallest angle is at most atan(1/2) = 26.6 degrees.
    k = 12
    bottom = [(x, 0.0) for x in range(k + 1)]
    top = [(x, 1.0) for x in range(k, -1, -1)]
    pts = np.asarray(bottom + top, dtype=float)
    outer = np.arange(len(pts))
    tris = triangulate_polygon(pts, outer)
    check_triangulation(pts, outer, [], tris)
    assert angles_deg(pts, tris).min() >= 45.0 - 1e-9


def test_polygon_area_sign_and_offset():
    pts = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=float) + 1e7
    assert polygon_area(pts, [0, 1, 2, 3]) == pytest.approx(1.0, rel=1e-12)
    assert polygon_area(pts, [3, 2, 1, 0]) == pytest.approx(-1.0, rel=1e-12)


def test_triangle_input_returns_itself_counter_clockwise():
    pts = np.array([[0, 0], [0, 1], [1, 0]], dtype=float)  # clockwise
    tris = triangulate_polygon(pts, [0, 1, 2])
    assert tris.shape == (1, 3)
    assert signed_areas(pts, tris)[0] == pytest.approx(0.5)


# ----------------------------------------------------------------- refused input
SQUARE = np.array([[0, 0], [4, 0], [4, 4], [0, 4], [1, 1], [2, 1], [2, 2], [5, 5], [1, 2]],
                  dtype=float)


@pytest.mark.parametrize(
    "outer, holes, message",
    [
        ([0, 1], [], "at least 3"),
        ([0, 1, 2, 3], [[4, 5]], "at least 3"),
        ([0, 1, 1, 2, 3], [], "consecutive"),
        ([0, 1, 2, 3, 0], [], "consecutive"),
        ([0, 1, 2, 99], [], "outside"),
        ([0, 1, 2, 3], [[4, 5, 0]], "more than once"),
        ([0, 2, 1, 8], [], "cross or touch"),  # bow tie
        ([0, 1, 2, 3], [[4, 5, 7]], "cross or touch"),  # hole pokes out of the outer loop
        ([0, 1, 2], [[4, 5, 6], [4, 6, 8]], "more than once"),
        ([0, 1, 2, 4, 6], [], "folds back"),
    ],
)
def test_refuses_bad_loops(outer, holes, message):
    with pytest.raises(ValueError, match=message):
        triangulate_polygon(SQUARE, outer, holes)


def test_refuses_hole_crossing_a_pocket_of_a_comb():
    # A long thin hole spans the comb's pockets: its long edges cross the tooth walls that
    # lie between their ends in x, which the x-range candidate pairs must not miss.
    comb = [(0, 0), (9, 0), (9, 6), (7, 6), (7, 2), (5, 2), (5, 6), (3, 6), (3, 2), (2, 2), (2, 6),
            (0, 6)]
    pts = np.asarray(comb + [(0.5, 4.0), (8.5, 4.0), (8.5, 4.2)], dtype=float)
    with pytest.raises(ValueError, match="cross or touch"):
        triangulate_polygon(pts, list(range(12)), [[12, 13, 14]])
    # The same hole kept inside the base of the comb is fine.
    pts[12:, 1] -= 3.0
    tris = triangulate_polygon(pts, list(range(12)), [[12, 13, 14]])
    check_triangulation(pts, list(range(12)), [[12, 13, 14]], tris)


def test_refuses_hole_outside_and_nested_hole_and_degenerate_points():
    pts = np.array(
        [[0, 0], [4, 0], [4, 4], [0, 4], [5, 5], [6, 5], [6, 6], [1, 1], [3, 1], [3, 3], [2.0, 1.5],
         [2.8, 1.5], [2.8, 2.3]],
        dtype=float,
    )
    with pytest.raises(ValueError, match="not inside the outer"):
        triangulate_polygon(pts, [0, 1, 2, 3], [[4, 5, 6]])
    with pytest.raises(ValueError, match="inside holes"):
        triangulate_polygon(pts, [0, 1, 2, 3], [[7, 8, 9], [10, 11, 12]])
    line = np.array([[0, 0], [1, 1], [2, 2]], dtype=float)
    with pytest.raises(ValueError, match="zero area"):
        triangulate_polygon(line, [0, 1, 2])
    twin = np.array([[0, 0], [1, 0], [1, 1], [0, 0]], dtype=float)
    with pytest.raises(ValueError, match="coordinates"):
        triangulate_polygon(twin, [0, 1, 2, 3])
    with pytest.raises(ValueError, match="NaN"):
        triangulate_polygon(np.array([[0, 0], [1, 0], [np.nan, 1]]), [0, 1, 2])
    with pytest.raises(ValueError, match=r"\(N, 2\)"):
        triangulate_polygon(np.zeros((4, 3)), [0, 1, 2])
    with pytest.raises(ValueError, match="integer"):
        triangulate_polygon(line, [0.0, 1.0, 2.0])
