"""Constant-time slices of tetrahedral spacetime meshes (st2005 §4.1) and their quadrisection.

Slices are checked on conforming tent-pitched meshes and on non-conforming front-refined ones:
the polygons tile the domain exactly once (areas add up to the domain, and random points fall in
exactly one polygon), every corner lies in its tetrahedron, times exactly at vertex times and
on flat band fronts give no NaN, and the incremental `TimeSlicer` agrees bit for bit with the
brute-force `slice_at` whatever the order of the times.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from workbench.algo.spacetime.mesh import (
    SpacetimeMesh,
    front_refined,
    interval_mesh,
    rect_triangulation,
    tent_pitch,
)
from workbench.algo.spacetime.slicing import Slice, TimeSlicer, polygon_areas, quadrisect, slice_at

PROPERTY = settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
T_END = 0.3
BANDS = 3


def ring_front(x, t):
    return np.abs(np.linalg.norm(x - 0.5, axis=1) - (0.1 + t))


def conforming(seed: int) -> SpacetimeMesh:
    p, t = rect_triangulation(4, 3, jitter=0.25, seed=seed)
    return tent_pitch(p, t, 0.0, T_END, 1.0, rng_seed=seed)


def non_conforming(seed: int) -> SpacetimeMesh:
    p, t = rect_triangulation(4, 4, jitter=0.25, seed=seed)
    return front_refined(p, t, T_END, 1.0, front_distance=ring_front, bands=BANDS, width=0.05,
                         levels=2, rng_seed=seed)


MESHES = {"conforming": conforming(0), "non-conforming": non_conforming(0)}
mesh_kind = st.sampled_from(sorted(MESHES))
slice_time = st.floats(0.0, T_END, exclude_min=True)


def check_slice(m: SpacetimeMesh, s: Slice):
    """Area exact, no NaN, CCW, triangle convention, corners inside their tetrahedra."""
    assert s.corners.shape == (s.n_polygons, 4, 2) and s.element.dtype == np.int64
    assert not np.isnan(s.corners).any()
    area = polygon_areas(s)
    assert np.all(area >= -1e-15)
    assert np.isclose(area.sum(), 1.0, rtol=1e-9)
    tri = ~s.is_quad
    assert np.array_equal(s.corners[tri, 3], s.corners[tri, 2])
    # barycentric coordinates of each corner, lifted to (x, y, t), in its tetrahedron
    p = m.points[m.simplices[s.element]]  # (P, 4, 3)
    lifted = np.concatenate([s.corners, np.full(s.corners.shape[:2] + (1,), s.t)], axis=2)
    edges = np.transpose(p[:, 1:] - p[:, :1], (0, 2, 1))  # columns are edge vectors
    rhs = np.transpose(lifted - p[:, :1], (0, 2, 1))
    lam = np.linalg.solve(edges, rhs)  # (P, 3, 4)
    bary = np.concatenate([1 - lam.sum(axis=1, keepdims=True), lam], axis=1)
    assert bary.min() >= -1e-9


def covering_counts(s: Slice, pts: np.ndarray, margin: float = 1e-7):
    """For each point: polygons strictly containing it, and whether it is near an edge."""
    c = s.corners[:, None]  # (P, 1, 4, 2)
    nxt = np.roll(s.corners, -1, axis=1)[:, None]
    e = nxt - c
    length = np.linalg.norm(e, axis=-1)
    rel = pts[None, :, None, :] - c
    cross = e[..., 0] * rel[..., 1] - e[..., 1] * rel[..., 0]
    with np.errstate(invalid="ignore", divide="ignore"):
        dist = np.where(length > 0, cross / length, np.inf)  # (P, N, 4)
    inside = np.all(dist > margin, axis=2) & (polygon_areas(s) > 0)[:, None]
    # near the boundary of a polygon: within margin of an edge while not outside another edge
    near = np.any(np.all(dist > -margin, axis=2) & ~inside, axis=0)
    return inside.sum(axis=0), near


# --------------------------------------------------------------------------- slices
def test_hand_checked_tetrahedra():
    pts = np.array([[0, 0, 0], [1, 0, 1], [0, 1, 1], [0, 0, 1],      # one vertex below 0.5
                    [0, 0, 0], [2, 0, 0], [0, 2, 1], [2, 3, 1],      # two below
                    [0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=float)  # three below
    m = SpacetimeMesh(pts, np.array([[0, 1, 2, 3], [4, 5, 6, 7], [8, 9, 10, 11]]))
    s = slice_at(m, 0.5)
    assert s.n_polygons == 3 and s.is_quad.tolist() == [False, True, False]
    assert {tuple(c) for c in s.corners[0]} == {(0.0, 0.0), (0.5, 0.0), (0.0, 0.5)}
    assert {tuple(c) for c in s.corners[1]} == {(0.0, 1.0), (1.0, 1.5), (2.0, 1.5), (1.0, 1.0)}
    assert {tuple(c) for c in s.corners[2]} == {(0.0, 0.0), (0.5, 0.0), (0.0, 0.5)}
    assert np.allclose(polygon_areas(s), [0.125, 0.5, 0.125])  # CCW: positive
    # the quad's corners go round its boundary (no bow tie): consecutive corners share a face
    assert np.array_equal(s.corners[1], np.roll(s.corners[1], 0, axis=0))
    assert np.isclose(np.linalg.norm(np.diff(np.r_[s.corners[1], s.corners[1][:1]], axis=0),
                                     axis=1).sum(), 2 + 2 * np.hypot(1, 0.5))


@PROPERTY
@given(kind=mesh_kind, t=slice_time)
def test_slice_tiles_the_domain(kind, t):
    m = MESHES[kind]
    s = slice_at(m, t)
    check_slice(m, s)
    assert np.array_equal(np.sort(s.element), np.flatnonzero((m.tmin < t) & (m.tmax >= t)))


@PROPERTY
@given(seed=st.integers(0, 30), t=slice_time, kind=mesh_kind)
def test_random_points_fall_in_exactly_one_polygon(seed, t, kind):
    m = conforming(seed) if kind == "conforming" else non_conforming(seed)
    s = slice_at(m, t)
    pts = np.random.default_rng(seed).uniform(0.0, 1.0, (60, 2))
    count, near = covering_counts(s, pts)
    assert np.all(count[~near] == 1)
    assert np.all(count <= 1)


def test_slicing_counts_would_see_a_missing_or_doubled_polygon():
    m = MESHES["non-conforming"]
    s = slice_at(m, 0.17)
    pts = np.random.default_rng(1).uniform(0.0, 1.0, (200, 2))
    count, near = covering_counts(s, pts)
    assert np.all(count[~near] == 1)
    doubled = Slice(s.t, np.concatenate([s.corners, s.corners[:50]]),
                    np.concatenate([s.element, s.element[:50]]),
                    np.concatenate([s.is_quad, s.is_quad[:50]]))
    assert covering_counts(doubled, pts)[0].max() == 2


@pytest.mark.parametrize("kind", sorted(MESHES))
def test_exact_vertex_and_band_times(kind):
    m = MESHES[kind]
    times = np.unique(m.points[:, -1])
    rng = np.random.default_rng(0)
    special = list(rng.choice(times[1:], 10)) + list(np.linspace(0.0, T_END, BANDS + 1)[1:])
    for t in special:
        check_slice(m, slice_at(m, t))
    assert slice_at(m, 0.0).n_polygons == 0  # half-open rule: nothing is below t_start
    assert slice_at(m, T_END * 1.01).n_polygons == 0


def test_flat_front_gives_the_top_faces():
    m = MESHES["non-conforming"]
    tk = np.linspace(0.0, T_END, BANDS + 1)[1]
    s = slice_at(m, tk)
    check_slice(m, s)
    area = polygon_areas(s)
    # positive-area polygons are the band's top faces: triangles with all corners at vertices
    top = area > 1e-14
    assert not s.is_quad[top].any()
    at_tk = m.points[m.points[:, -1] == tk, :2]
    keys = {tuple(r) for r in at_tk.tolist()}
    assert all(tuple(c) in keys for c in s.corners[top].reshape(-1, 2).tolist())


@PROPERTY
@given(kind=mesh_kind, times=st.lists(slice_time, min_size=1, max_size=12))
def test_time_slicer_matches_brute_force(kind, times):
    m = MESHES[kind]
    slicer = TimeSlicer(m, outer=True)
    sequence = sorted(times) + sorted(times, reverse=True) + times
    for t in sequence:
        s, ref = slicer.slice(t), slice_at(m, t, outer=True)
        order = np.argsort(s.element)
        assert np.array_equal(s.element[order], ref.element)
        assert np.array_equal(s.corners[order], ref.corners)
        assert np.array_equal(s.is_quad[order], ref.is_quad)
        assert np.array_equal(s.outer[order], ref.outer)
        assert np.array_equal(np.sort(slicer.active), ref.element)
    assert TimeSlicer(m).slice(times[0]).outer is None  # derived only when asked for


# --------------------------------------------------------------------------- outer edges
def edge_lengths(s: Slice) -> np.ndarray:
    return np.linalg.norm(np.roll(s.corners, -1, axis=1) - s.corners, axis=2)


def on_square_boundary(s: Slice) -> np.ndarray:
    """(P, 4) bool: polygon edges of non-zero length with both ends on one side of the unit
    square — the reference for ``outer``, from geometry alone."""
    a, b = s.corners, np.roll(s.corners, -1, axis=1)
    on = np.zeros(a.shape[:2], bool)
    for axis in (0, 1):
        for side in (0.0, 1.0):
            on |= (np.abs(a[..., axis] - side) < 1e-12) & (np.abs(b[..., axis] - side) < 1e-12)
    return on & (edge_lengths(s) > 0)


@PROPERTY
@given(kind=mesh_kind, t=st.floats(1e-6, T_END - 1e-6),
       max_area=st.one_of(st.none(), st.floats(2e-4, 0.05)))
def test_outer_edges_are_the_domain_boundary(kind, t, max_area):
    m = MESHES[kind]
    # through a vertex an edge may run along a tetrahedron edge shared by a boundary face and
    # an inner one; those times are tested below
    assume(np.abs(m.points[:, -1] - t).min() > 1e-9)
    s = slice_at(m, t, outer=True)
    if max_area is not None:
        s = quadrisect(s, max_area)
    assert s.outer.shape == (s.n_polygons, 4) and s.outer.dtype == bool
    assert not s.outer[~s.is_quad, 2].any()
    assert np.array_equal(s.outer, on_square_boundary(s))
    assert s.outer.any() and not s.outer.all()


@pytest.mark.parametrize("kind", sorted(MESHES))
def test_outer_edges_at_vertex_and_band_times_are_never_inner(kind):
    m = MESHES[kind]
    times = np.unique(m.points[:, -1])
    rng = np.random.default_rng(1)
    for t in list(rng.choice(times[1:], 15)) + list(np.linspace(0.0, T_END, BANDS + 1)[1:]):
        s = slice_at(m, t, outer=True)
        boundary = on_square_boundary(s)
        real = s.outer & (edge_lengths(s) > 0)
        # an inner edge is never taken for a boundary one (it would lose its overdraw); a
        # boundary edge along a tetrahedron edge whose faces through it are inner is missed
        assert not (real & ~boundary).any()


def test_outer_edges_follow_the_flips_and_the_children():
    """Hand-checked: a lone tetrahedron, all of whose faces are outer, cut clockwise and
    counter-clockwise, and quadrisected: outer edges are the polygon's whole perimeter, the
    children's inner edges are not outer."""
    for pts in ([[0, 0, 0], [1, 0, 1], [0, 1, 1], [0, 0, 1]],    # one vertex below t = 0.5
                [[0, 0, 0], [0, 1, 1], [1, 0, 1], [0, 0, 1]],    # the same, other orientation
                [[0, 0, 0], [2, 0, 0], [0, 2, 1], [2, 3, 1]]):   # a quad
        m = SpacetimeMesh(np.array(pts, float), np.array([[0, 1, 2, 3]]))
        s = slice_at(m, 0.5, outer=True)
        assert polygon_areas(s)[0] > 0
        assert np.array_equal(s.outer, edge_lengths(s) > 0)
        q = quadrisect(s, 0.2 * polygon_areas(s)[0])
        assert q.n_polygons == 16
        perimeter = (edge_lengths(s) * s.outer).sum()
        assert np.isclose((edge_lengths(q) * q.outer).sum(), perimeter)
        # an outer child edge lies on the parent's boundary (its midpoint on a parent edge
        # line), an inner one does not
        mid = 0.5 * (q.corners + np.roll(q.corners, -1, axis=1))
        length = edge_lengths(q) > 0
        assert np.all(distance_to_edge_lines(mid[q.outer], s.corners[0]) < 1e-12)
        assert np.all(distance_to_edge_lines(mid[~q.outer & length], s.corners[0]) > 1e-6)


def distance_to_edge_lines(points: np.ndarray, polygon: np.ndarray) -> np.ndarray:
    """(K,) distance from each point to the nearest line through an edge of ``polygon``."""
    a, b = polygon, np.roll(polygon, -1, axis=0)
    keep = np.linalg.norm(b - a, axis=1) > 0
    a, e = a[keep], (b - a)[keep]
    rel = points[:, None, :] - a[None]
    cross = e[None, :, 0] * rel[..., 1] - e[None, :, 1] * rel[..., 0]
    return (np.abs(cross) / np.linalg.norm(e, axis=1)[None]).min(axis=1)


def test_slice_at_elements_subset():
    m = MESHES["conforming"]
    full = slice_at(m, 0.1)
    sub = slice_at(m, 0.1, elements=np.arange(0, m.n_simplices, 3))
    keep = full.element % 3 == 0
    assert np.array_equal(sub.element, full.element[keep])
    assert np.array_equal(sub.corners, full.corners[keep])


def test_refuses_bad_input():
    p, s = interval_mesh(4)
    bar = tent_pitch(p, s, 0.0, 1.0, 1.0)
    with pytest.raises(ValueError, match="1-D"):
        slice_at(bar, 0.5)
    with pytest.raises(ValueError, match="1-D"):
        TimeSlicer(bar)
    m = MESHES["conforming"]
    with pytest.raises(ValueError):
        slice_at(m, np.nan)
    with pytest.raises(ValueError):
        slice_at(m, 0.1, elements=[m.n_simplices])
    with pytest.raises(ValueError):
        quadrisect(slice_at(m, 0.1), 0.0)


# --------------------------------------------------------------------------- quadrisection
def inside_parent(child: np.ndarray, parent: np.ndarray, tol: float = 1e-12) -> np.ndarray:
    """Whether every corner of child (C, 4, 2) lies in its convex CCW parent (C, 4, 2)."""
    nxt = np.roll(parent, -1, axis=1)
    e = (nxt - parent)[:, None]  # (C, 1, 4, 2)
    rel = child[:, :, None] - parent[:, None]  # (C, 4, 4, 2)
    cross = e[..., 0] * rel[..., 1] - e[..., 1] * rel[..., 0]
    return np.all(cross >= -tol, axis=(1, 2))


@PROPERTY
@given(kind=mesh_kind, t=slice_time, max_area=st.floats(2e-4, 0.05))
def test_quadrisect(kind, t, max_area):
    m = MESHES[kind]
    s = slice_at(m, t)
    q = quadrisect(s, max_area)
    area = polygon_areas(q)
    assert np.isclose(area.sum(), polygon_areas(s).sum(), rtol=1e-12)
    assert np.all(area <= max_area) and np.all(area >= -1e-15)
    assert not np.isnan(q.corners).any()
    tri = ~q.is_quad
    assert np.array_equal(q.corners[tri, 3], q.corners[tri, 2])
    parent = {e: i for i, e in enumerate(s.element.tolist())}
    idx = np.array([parent[e] for e in q.element.tolist()])
    assert np.array_equal(q.is_quad, s.is_quad[idx])  # triangles stay triangles, quads quads
    assert np.all(inside_parent(q.corners, s.corners[idx]))
    split = polygon_areas(s) > max_area
    assert q.n_polygons >= s.n_polygons + 3 * split.sum()


def test_quadrisect_one_level():
    s = Slice(0.0, np.array([[[0, 0], [2, 0], [0, 2], [0, 2]],
                             [[0, 0], [2, 0], [2, 2], [0, 2]]], dtype=float),
              np.array([7, 9]), np.array([False, True]))
    q = quadrisect(s, 1.5)
    area = polygon_areas(q)
    assert np.allclose(area[q.element == 7], 0.5) and np.allclose(area[q.element == 9], 1.0)
    assert (q.element == 7).sum() == 4 and (q.element == 9).sum() == 4
