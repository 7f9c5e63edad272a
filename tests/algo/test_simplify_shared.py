"""Collapses along the common boundary of two parts: no crack opens, corners stay, both parts
stay within their tolerances (checked by the independent exact metric) and drawable."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from meshes import quad_grid

from workbench.algo.hausdorff import hausdorff
from workbench.algo.simplify import (
    MAX_AUTO_DEPTH,
    MIN_DEPTH,
    certification_depths,
    hausdorff_decimate,
)


# --------------------------------------------------------------------------- meshes and checks
def two_part_grid(n, walk, amplitude, phase):
    """An n×n grid over [0, 1]² with z = amplitude·sin(3x + phase)·cos(2y), split into part 0
    (below) and part 1 (above) along the grid polyline that runs at row ``walk[i]`` in column i
    (a staircase from the left side to the right side). Triangles wound counter-clockwise."""
    v, t = quad_grid(n, n, span=((0, 1), (0, 1)), triangles=True,
                     z=lambda x, y: amplitude * np.sin(3 * x + phase) * np.cos(2 * y))
    # row and column of each triangle's square
    row, col = np.tile(np.repeat(np.arange(n), n), 2), np.tile(np.arange(n), 2 * n)
    parts = (row >= np.asarray(walk)[col]).astype(np.int32)
    return v, t, parts


def edges_of(t):
    """(3K, 2) sorted vertex pairs of the triangles' edges."""
    return np.sort(np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]]), axis=1)


def edge_counts(t):
    """Distinct sorted edges of t and the number of triangles on each."""
    if not len(t):
        return np.zeros((0, 2), np.int64), np.zeros(0, np.int64)
    return np.unique(edges_of(t), axis=0, return_counts=True)


def boundary_edges(t):
    e, c = edge_counts(t)
    return e[c == 1]


def as_set(edges):
    return {tuple(e) for e in np.asarray(edges).tolist()}


def cracks(t_in, p_in, t_out, p_out):
    """Common-boundary edges that one part has and its neighbour lacks: for every pair of parts
    P, Q, every boundary edge of P's result whose two vertices both lie on the input's common
    boundary of P and Q (vertices used by both) must be an edge of Q's result, unless both ends
    lie on the input's open boundary (the two parts only touch there). Returns the offenders as
    (P, Q, a, b) tuples; empty when watertight."""
    open_vertices = set(np.unique(boundary_edges(t_in)).tolist())
    labels = np.unique(p_in)
    used = {p: set(np.unique(t_in[p_in == p]).tolist()) for p in labels}
    out_edges = {p: as_set(edges_of(t_out[p_out == p])) for p in labels}
    bad = []
    for p in labels:
        for a, b in as_set(boundary_edges(t_out[p_out == p])):
            if a in open_vertices and b in open_vertices:
                continue
            for q in labels:
                if q != p and a in used[q] and b in used[q] and (a, b) not in out_edges[q]:
                    bad.append((int(p), int(q), a, b))
    return bad


def open_edges_stay_on_the_open_boundary(t_in, t_out):
    """Every edge with a single face in the whole result joins two vertices of the input's open
    boundary: a crack would open a new hole inside."""
    open_vertices = np.unique(boundary_edges(t_in))
    return np.isin(boundary_edges(t_out), open_vertices).all()


def each_part_drawable(v, t_in, p_in, r):
    """Every part keeps triangles of non-zero area, with no edge of more faces within the part
    than it had in the input (no new non-manifold edge)."""
    for p in np.unique(p_in):
        own = r.triangles[r.parts == p]
        if not len(own):
            return False
        area = np.linalg.norm(np.cross(v[own[:, 1]] - v[own[:, 0]], v[own[:, 2]] - v[own[:, 0]]),
                              axis=1)
        if not (area > 0).all():
            return False
        _, c_in = edge_counts(t_in[p_in == p])
        _, c_out = edge_counts(own)
        if c_out.max() > max(c_in.max(), 2):
            return False
    return True


def worst_over_tolerance(v, t, parts, r):
    """Largest ratio over parts of the exact one-sided distance (part's original → part's
    result, :func:`workbench.algo.hausdorff.hausdorff` upper bound) to that part's tol."""
    worst = 0.0
    for p in np.unique(parts):
        tol = r.tol_for(p)
        h = hausdorff(v, t[parts == p], v, r.triangles[r.parts == p], tol=1e-6 * tol)
        worst = max(worst, h.upper / tol)
    return worst


def shared_vertices(t, parts):
    """Vertices used by two or more parts."""
    pairs = np.unique(np.stack([t.ravel(), np.repeat(parts, 3)], 1), axis=0)
    ids, counts = np.unique(pairs[:, 0], return_counts=True)
    return ids[counts > 1]


# --------------------------------------------------------------------------- random two parts
walks = st.integers(6, 12).flatmap(
    lambda n: st.tuples(st.just(n),
                        st.lists(st.sampled_from([-1, 0, 0, 0, 1]), min_size=n - 1,
                                 max_size=n - 1),
                        st.integers(2, n - 2)))


def walk_rows(n, steps, start):
    rows = [start]
    for s in steps:
        rows.append(int(np.clip(rows[-1] + s, 2, n - 2)))
    return rows


@settings(max_examples=25, deadline=None)
@given(walks, st.floats(0.0, 0.2), st.floats(0.0, 3.0), st.sampled_from([0.01, 0.03, 0.08]),
       st.sampled_from([30.0, 60.0]))
def test_shared_boundary_collapse_opens_no_crack(walk, amplitude, phase, tol, feature_deg):
    n, steps, start = walk
    v, t, parts = two_part_grid(n, walk_rows(n, steps, start), amplitude, phase)
    r = hausdorff_decimate(v, t, tol, parts=parts, feature_deg=feature_deg)
    assert cracks(t, parts, r.triangles, r.parts) == []
    assert open_edges_stay_on_the_open_boundary(t, r.triangles)
    assert each_part_drawable(v, t, parts, r)
    assert worst_over_tolerance(v, t, parts, r) <= 1.0 + 1e-9
    assert np.isin(r.triangles, t).all()
    # the shared vertices still used are used by both parts: the buffer stays shared
    kept = np.intersect1d(shared_vertices(t, parts), r.triangles)
    for p in (0, 1):
        assert np.isin(kept, r.triangles[r.parts == p]).all()


def test_a_straight_common_boundary_slides_down_to_its_ends():
    # a flat plate split along y = 0.5: the shared line may shrink to its two end points
    v, t, parts = two_part_grid(10, [5] * 10, 0.0, 0.0)
    shared = shared_vertices(t, parts)
    assert len(shared) == 11
    r = hausdorff_decimate(v, t, 0.01, parts=parts)
    kept = np.intersect1d(shared, r.triangles)
    ends = shared[np.isin(v[shared, 0], (0.0, 1.0))]
    assert sorted(kept.tolist()) == sorted(ends.tolist())
    assert cracks(t, parts, r.triangles, r.parts) == []
    locked = hausdorff_decimate(v, t, 0.01, parts=parts, slide_shared=False)
    assert np.isin(shared, locked.triangles).all()
    assert len(r.triangles) < len(locked.triangles)


def test_corners_of_the_common_boundary_never_move():
    # a staircase with right-angle turns: with feature_deg = 30 every turn is a corner
    n = 10
    rows = [3, 3, 3, 3, 6, 6, 6, 6, 6, 6]
    v, t, parts = two_part_grid(n, rows, 0.0, 0.0)
    r = hausdorff_decimate(v, t, 0.05, parts=parts, feature_deg=30.0)
    # the turns: vertices of the shared line at x = 4/n, rows 3 and 6
    turn = [4 + (n + 1) * 3, 4 + (n + 1) * 6]
    for p in (0, 1):
        assert np.isin(turn, r.triangles[r.parts == p]).all()
    assert cracks(t, parts, r.triangles, r.parts) == []


def test_a_vertex_of_three_parts_never_moves():
    v, t, parts = two_part_grid(8, [4] * 8, 0.0, 0.0)
    centre_x = v[t].mean(axis=1)[:, 0]
    parts = np.where((parts == 1) & (centre_x > 0.5), 2, parts).astype(np.int32)
    meeting = 4 + 9 * 4                                   # (0.5, 0.5): parts 0, 1 and 2
    r = hausdorff_decimate(v, t, 0.05, parts=parts)
    for p in (0, 1, 2):
        assert meeting in r.triangles[r.parts == p]
    assert cracks(t, parts, r.triangles, r.parts) == []
    assert worst_over_tolerance(v, t, parts, r) <= 1.0 + 1e-9


def test_the_crack_check_sees_a_crack():
    # drop a shared vertex from one part only (as an independent collapse per part would)
    v, t, parts = two_part_grid(6, [3] * 6, 0.0, 0.0)
    u, w = 2 + 7 * 3, 3 + 7 * 3                           # neighbours on the shared line
    moved = np.where((t == u) & (parts[:, None] == 0), w, t)
    keep = ((moved[:, 0] != moved[:, 1]) & (moved[:, 1] != moved[:, 2])
            & (moved[:, 2] != moved[:, 0]))
    bad = cracks(t, parts, moved[keep], parts[keep])
    assert bad and {b[0] for b in bad} <= {0, 1}
    assert not open_edges_stay_on_the_open_boundary(t, moved[keep])


# --------------------------------------------------------------------------- the car deck
@pytest.fixture(scope="module")
def car_triangles(car_deck):
    """The car deck's nodes, triangles and the part of each triangle."""
    from workbench.scene.builtin import fresh_scene

    mesh = fresh_scene("car")
    return mesh.nodes, mesh.triangles.astype(np.int64), mesh.parts[mesh.triangulation.element_of]


@pytest.mark.parametrize("tol", [0.001, 0.005])
def test_car_shared_boundaries_stay_watertight_and_within_tolerance(car_triangles, tol):
    v, t, parts = car_triangles
    r = hausdorff_decimate(v, t, tol, parts=parts)
    locked = hausdorff_decimate(v, t, tol, parts=parts, slide_shared=False)
    for result in (r, locked):
        assert cracks(t, parts, result.triangles, result.parts) == []
        assert open_edges_stay_on_the_open_boundary(t, result.triangles)
        assert each_part_drawable(v, t, parts, result)
        assert worst_over_tolerance(v, t, parts, result) <= 1.0 + 1e-9
    shared = shared_vertices(t, parts)
    # sliding removed shared vertices that locking keeps, and the result is smaller
    assert np.isin(shared, locked.triangles).all()
    assert not np.isin(shared, r.triangles).all()
    assert len(r.triangles) < len(locked.triangles)


# --------------------------------------------------------------------------- certification depth
def test_depth_follows_edge_length_over_tolerance():
    corners = np.array([[[0, 0, 0], [100, 0, 0], [0, 1, 0]],
                        [[0, 0, 0], [1, 0, 0], [0, 1, 0]],
                        [[0, 0, 0], [0, 0, 0], [0, 0, 0]]], np.float64)
    tol = np.array([0.5, 0.5, 0.5])
    # log2(100 / 0.5) = 7.6 -> 9; short and zero-length edges keep the minimum depth
    assert certification_depths(corners, tol).tolist() == [9, MIN_DEPTH, MIN_DEPTH]
    assert certification_depths(corners, tol / 1e6).max() == MAX_AUTO_DEPTH
    assert certification_depths(corners, tol, 3).tolist() == [3, 3, 3]


def test_a_flat_plate_of_large_triangles_reaches_its_corners_at_a_small_tolerance():
    # a 4 × 4 grid of 2.5 mm squares, tolerance 0.1 % of its diagonal (0.014 mm): a fixed depth
    # of 5 leaves pieces of 0.1 mm, too coarse to certify those that straddle two coplanar
    # faces, so not one collapse passes; the automatic depth certifies down to the corners
    v, t = quad_grid(4, 4, span=((0, 10), (0, 10)), triangles=True)
    auto = hausdorff_decimate(v, t, 0.001)
    fixed = hausdorff_decimate(v, t, 0.001, max_depth=5)
    assert len(auto.triangles) == 2 and len(fixed.triangles) == len(t)
    for r in (auto, fixed):
        assert (r.bounds <= r.tol_for(0)).all()
        h = hausdorff(v, t, v, r.triangles, tol=1e-6)
        assert h.upper <= r.tol_for(0)
