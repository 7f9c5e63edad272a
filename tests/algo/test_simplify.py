"""Hausdorff-bounded decimation: the tolerance holds (by dense sampling and by the certificate),
no coordinate is created, faces stay valid and oriented, boundaries, features, parts and
non-manifold input are handled."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from meshes import barycentric_grid, folded, quad_grid, split_quads

from workbench.algo.nearest.triangle import points_triangles_distance
from workbench.algo.simplify import Decimation, hausdorff_decimate


# --------------------------------------------------------------------------- meshes and checks
def grid(n, height=None, size=1.0, offset=(0.0, 0.0, 0.0), diagonal_flip=False):
    """An n×n grid of squares over [0, size]² (moved by ``offset``), split into triangles wound
    counter-clockwise seen from +z, along the other diagonal with ``diagonal_flip``;
    z = height(x, y)."""
    v, quads = quad_grid(n, n, span=((0, size), (0, size)), z=height, origin=offset)
    if diagonal_flip:
        return v, np.concatenate([quads[:, [0, 1, 3]], quads[:, [1, 2, 3]]])
    return v, split_quads(quads)


def wave(a=0.15, fx=2.0, fy=1.5, phase=0.0):
    return lambda x, y: a * np.sin(fx * x + phase) * np.cos(fy * y)


def samples(corners, n=6):
    """Points of a barycentric grid with n steps on each triangle of (K, 3, 3) corners,
    (K, S, 3)."""
    u, w = barycentric_grid(n)
    weights = np.stack([1 - u - w, u, w], 1)       # (S, 3)
    return np.einsum("sk,tkc->tsc", weights, corners)


def sampled_distances(v, original, simplified, n=6):
    """(K, S) distance from samples of each original triangle to the simplified triangles, by
    libigl (a float64 kernel independent of ours)."""
    import igl

    pts = samples(v[original], n)
    d2, _, _ = igl.point_mesh_squared_distance(pts.reshape(-1, 3), v,
                                               np.asarray(simplified, np.int64))
    return np.sqrt(d2).reshape(pts.shape[:2])


def unit_normals(v, t):
    n = np.cross(v[t[:, 1]] - v[t[:, 0]], v[t[:, 2]] - v[t[:, 0]])
    return n / np.linalg.norm(n, axis=1, keepdims=True)


def check_result(v, t, r: Decimation, tol_abs=None, parts=None):
    """The properties every decimation must have; ``tol_abs`` None takes each part's own."""
    out = r.triangles
    assert out.dtype == np.int32 and out.ndim == 2 and out.shape[1] == 3 and len(out) > 0
    # only vertices the input used: no coordinate is created or moved
    assert np.isin(out, t).all()
    # non-degenerate, no duplicate faces
    assert (out[:, 0] != out[:, 1]).all() and (out[:, 1] != out[:, 2]).all() \
        and (out[:, 2] != out[:, 0]).all()
    cross = np.linalg.norm(np.cross(v[out[:, 1]] - v[out[:, 0]], v[out[:, 2]] - v[out[:, 0]]),
                           axis=1)
    longest = max(np.ptp(v[np.unique(t)], axis=0).max(), 1e-300)
    assert (cross > 1e-9 * longest ** 2).all()
    keyed = np.sort(out, axis=1)
    if parts is not None:
        keyed = np.concatenate([r.parts[:, None], keyed], 1)
    assert len(np.unique(keyed, axis=0)) == len(out)
    # the tolerance: dense sampling of the original surface against the simplified one ...
    labels = np.zeros(len(t), int) if parts is None else parts
    for label in np.unique(labels):
        own = out if parts is None else out[r.parts == label]
        d = sampled_distances(v, t[labels == label], own)
        tol = r.tol_for(label) if tol_abs is None else tol_abs
        assert d.max() <= tol * (1 + 1e-9)
        # ... and the certificate: each triangle's bound covers its own samples
        bound = r.bounds[labels == label]
        assert (bound <= tol * (1 + 1e-12)).all()
        assert (d.max(axis=1) <= bound + 1e-9 * tol).all()
    assert r.certified_max == pytest.approx(np.nanmax(r.bounds))
    assert r.bytes_saved == 24 * len(np.unique(out))


def check_disk(out):
    """A triangulated disk stays one: edges with at most two faces, one boundary loop, every
    vertex on one fan, Euler characteristic 1."""
    e = np.sort(np.concatenate([out[:, [0, 1]], out[:, [1, 2]], out[:, [2, 0]]]), axis=1)
    edges, counts = np.unique(e, axis=0, return_counts=True)
    assert counts.max() <= 2
    n_vertices = len(np.unique(out))
    assert n_vertices - len(edges) + len(out) == 1
    boundary = edges[counts == 1]
    # one loop: every boundary vertex on exactly two boundary edges, and connected
    assert (np.bincount(boundary.ravel())[np.unique(boundary)] == 2).all()
    loop = {int(boundary[0, 0])}
    for _ in range(len(boundary)):
        loop |= {int(x) for a, b in boundary if a in loop or b in loop for x in (a, b)}
    assert len(loop) == len(np.unique(boundary))


def check_orientation(v, t, out):
    """Each output face agrees with the original triangle nearest its centroid."""
    centroids = v[out].mean(axis=1)
    nearest = points_triangles_distance(centroids, v[t]).argmin(axis=1)
    dots = np.einsum("ij,ij->i", unit_normals(v, out), unit_normals(v, t)[nearest])
    assert (dots > 0).all()


# --------------------------------------------------------------------------- the tolerance
@settings(max_examples=25, deadline=None)
@given(n=st.integers(3, 9), a=st.floats(0.0, 0.3), fx=st.floats(0.5, 4.0), fy=st.floats(0.5, 4.0),
       phase=st.floats(0, 3), tol=st.floats(0.002, 0.08), flip=st.booleans())
def test_tolerance_holds_on_smooth_surfaces(n, a, fx, fy, phase, tol, flip):
    v, t = grid(n, wave(a, fx, fy, phase), diagonal_flip=flip)
    r = hausdorff_decimate(v, t, tol)
    diameter = np.linalg.norm(np.ptp(v, axis=0))
    assert r.part_labels.tolist() == [0]
    assert r.tol_abs == pytest.approx([tol * diameter])
    check_result(v, t, r, tol * diameter)
    check_disk(r.triangles)
    check_orientation(v, t, r.triangles)
    removed = len(t) - len(r.triangles)    # a collapse removes one or two faces
    assert (removed + 1) // 2 <= r.collapses <= removed


@settings(max_examples=15, deadline=None)
@given(seed=st.integers(0, 2**16), tol=st.floats(0.01, 0.2))
def test_tolerance_holds_on_rough_surfaces_in_model_units(seed, tol):
    rng = np.random.default_rng(seed)
    v, t = grid(6)
    v[:, 2] = rng.uniform(-0.2, 0.2, len(v))
    r = hausdorff_decimate(v, t, tol, relative=False)
    assert r.tol_abs.tolist() == [tol]
    check_result(v, t, r, tol)
    check_disk(r.triangles)


@settings(max_examples=30, deadline=None)
@given(n=st.integers(3, 8), a=st.floats(0.0, 0.5), seed=st.integers(0, 2**16),
       tol=st.floats(0.01, 0.6), normal_deg=st.floats(20.0, 180.0), keep=st.booleans(),
       feature=st.floats(0.0, 180.0))
def test_coarse_decimation_keeps_a_valid_disk(n, a, seed, tol, normal_deg, keep, feature):
    # loose tolerances and rules: topology alone has to keep the disk a disk
    rng = np.random.default_rng(seed)
    v, t = grid(n, wave(a, *rng.uniform(0.5, 3.0, 2)), diagonal_flip=bool(seed % 2))
    v[:, :2] += rng.uniform(-0.3, 0.3, (len(v), 2)) / n
    r = hausdorff_decimate(v, t, tol, max_normal_deg=normal_deg, keep_boundary=keep,
                           feature_deg=feature)
    check_result(v, t, r, r.tol_for(0))
    check_disk(r.triangles)


def test_a_closed_surface_stays_closed():
    # an octahedron with every rule relaxed: collapses stop before faces would double up
    v = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], float)
    t = np.array([[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4],
                  [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]])
    r = hausdorff_decimate(v, t, 10.0, relative=False, max_normal_deg=180.0, feature_deg=180.0)
    out = r.triangles
    e = np.sort(np.concatenate([out[:, [0, 1]], out[:, [1, 2]], out[:, [2, 0]]]), axis=1)
    _, counts = np.unique(e, axis=0, return_counts=True)
    assert (counts == 2).all() and len(out) >= 4
    assert len(np.unique(np.sort(out, axis=1), axis=0)) == len(out)
    assert r.collapses == 6 - len(np.unique(out))


def test_flat_plate_collapses_to_its_corners_and_keeps_the_boundary():
    v, t = grid(12, size=10.0)
    r = hausdorff_decimate(v, t, 0.2)
    check_result(v, t, r, r.tol_for(0))
    assert len(r.triangles) == 2
    assert r.collapses == len(np.unique(t)) - 4
    corners = [0, 12, 13 * 12, 13 * 13 - 1]
    assert set(np.unique(r.triangles)) == set(corners)
    assert (unit_normals(v, r.triangles)[:, 2] > 0.999).all()
    # the boundary polyline of the result is the square's perimeter
    e = np.sort(np.concatenate([r.triangles[:, [0, 1]], r.triangles[:, [1, 2]],
                                r.triangles[:, [2, 0]]]), axis=1)
    edges, counts = np.unique(e, axis=0, return_counts=True)
    boundary = edges[counts == 1]
    perimeter = np.linalg.norm(v[boundary[:, 0]] - v[boundary[:, 1]], axis=1).sum()
    assert perimeter == pytest.approx(40.0)


def test_a_boundary_may_slide_only_along_itself():
    # a plate with a wavy outline: keep_boundary holds boundary vertices on the boundary
    v, t = grid(10, wave(0.1, 3.0, 3.0))
    on_boundary = (np.isclose(v[:, 0], 0) | np.isclose(v[:, 0], 1) | np.isclose(v[:, 1], 0)
                   | np.isclose(v[:, 1], 1))
    kept = hausdorff_decimate(v, t, 0.15)
    free = hausdorff_decimate(v, t, 0.15, keep_boundary=False)
    for r in (kept, free):
        check_result(v, t, r, r.tol_for(0))
    e = np.sort(np.concatenate([kept.triangles[:, [0, 1]], kept.triangles[:, [1, 2]],
                                kept.triangles[:, [2, 0]]]), axis=1)
    edges, counts = np.unique(e, axis=0, return_counts=True)
    assert on_boundary[edges[counts == 1]].all()
    assert len(free.triangles) <= len(kept.triangles)


def test_smaller_tolerance_never_gives_fewer_triangles():
    v, t = grid(16, wave(0.2, 3.0, 2.0))
    counts = []
    for tol in (0.05, 0.02, 0.01, 0.005, 0.002):
        r = hausdorff_decimate(v, t, tol)
        check_result(v, t, r, r.tol_for(0))
        check_disk(r.triangles)
        counts.append(len(r.triangles))
    assert counts == sorted(counts)
    assert counts[0] < counts[-1] < len(t)


def folded_plate(angle_deg: float = 35.0):
    """(vertices, triangles): the 8×8 grid over [0, 2]² folded up by ``angle_deg`` along x = 1
    (the ridge, two units long, on z = 0)."""
    v, t = grid(8, size=2.0)
    return folded(v, 1.0, angle_deg), t


def test_feature_edges_are_kept():
    # a plate folded by 35 degrees along x = 1, with a tolerance loose enough that faces across
    # the fold pass: the feature rule alone keeps every face on one side
    angle = np.radians(35.0)
    v, t = folded_plate(35.0)

    def sides(r):
        corners = v[r.triangles]
        flat = np.isclose(corners[:, :, 2], 0).all(axis=1)
        slope = np.isclose(corners[:, :, 2], (corners[:, :, 0] - 1.0) * np.tan(angle)).all(axis=1)
        return flat | slope

    r = hausdorff_decimate(v, t, 0.15)
    check_result(v, t, r, r.tol_for(0))
    check_disk(r.triangles)
    assert sides(r).all()
    assert len(r.triangles) <= 8
    # a fold below the feature angle is not kept, and the tolerance still holds
    r_soft = hausdorff_decimate(v, t, 0.15, feature_deg=40.0)
    check_result(v, t, r_soft, r_soft.tol_for(0))
    assert not sides(r_soft).all()


def test_creases_shorter_than_the_tolerance_allows_are_not_feature_lines():
    # a plate of noise: many edges bend by more than 30 degrees, but every crease line is short
    # against ten tolerances, so none is kept and the plate goes down to a few triangles
    for seed in range(3):
        rng = np.random.default_rng(seed)
        v, t = grid(12, size=2.0)
        inner = ((v[:, :2] > 0.01) & (v[:, :2] < 1.99)).all(axis=1)
        v[inner, 2] = rng.uniform(-0.04, 0.04, inner.sum())
        r = hausdorff_decimate(v, t, 0.1, relative=False)
        every = hausdorff_decimate(v, t, 0.1, relative=False, feature_min_length=None)
        check_result(v, t, r, 0.1)
        check_result(v, t, every, 0.1)
        assert 2 * len(r.triangles) <= len(every.triangles)
    # a long crease is kept whole: the fold of 35 degrees, two units long, at a tolerance
    # whose ten times are shorter
    v, t = folded_plate(35.0)
    r = hausdorff_decimate(v, t, 0.01)
    assert 10 * r.tol_for(0) < 2.0
    check_result(v, t, r, r.tol_for(0))
    e = np.sort(np.concatenate([r.triangles[:, [0, 1]], r.triangles[:, [1, 2]],
                                r.triangles[:, [2, 0]]]), axis=1)
    e = np.unique(e, axis=0)
    on_ridge = np.isclose(v[e, 0], 1.0).all(axis=1) & np.isclose(v[e, 2], 0.0).all(axis=1)
    assert np.linalg.norm(v[e[on_ridge, 0]] - v[e[on_ridge, 1]], axis=1).sum() == \
        pytest.approx(2.0)
    with pytest.raises(ValueError, match="feature_min_length"):
        hausdorff_decimate(v, t, 0.01, feature_min_length=-1.0)


def test_relative_tolerance_ignores_translation():
    v, t = grid(12, wave(0.2, 2.5, 2.0))
    r = hausdorff_decimate(v, t, 0.01)
    far = v + 1e6
    r_far = hausdorff_decimate(far, t, 0.01)
    assert len(r_far.triangles) == len(r.triangles)
    assert r_far.tol_for(0) == pytest.approx(r.tol_for(0), rel=1e-9)
    assert r_far.certified_max <= r_far.tol_for(0)
    # the sampled check in coordinates near the origin, on the far result's faces
    d = sampled_distances(v, t, r_far.triangles)
    assert d.max() <= r_far.tol_for(0) * (1 + 1e-6)


@settings(max_examples=20, deadline=None)
@given(seed=st.integers(0, 2 ** 32 - 1), log_offset=st.integers(0, 20), n=st.integers(3, 6),
       tol=st.floats(0.005, 0.1), sliver=st.booleans())
def test_bounds_hold_for_exact_distances(seed, log_offset, n, tol, sliver):
    """Each reported bound is at least the exact distance (rational arithmetic, no slack) from
    the corners, the exact edge midpoints and the exact centroid of its triangle to the
    simplified surface, and at most the tolerance; grids with dyadic heights (optionally with a
    row of sliver triangles) far from the origin."""
    from fractions import Fraction

    from workbench.reliability.exact import exact_point_triangle_sq

    rng = np.random.default_rng(seed)
    v, t = grid(n, lambda x, y: rng.integers(-8, 8, size=np.shape(x)) / 256.0)
    if sliver:  # squeeze the first column of cells to a 2^-30 width: sliver triangles
        second = np.unique(v[:, 0])[1]
        v[v[:, 0] == second, 0] = 2.0 ** -30
    v = v + 2.0 ** log_offset * rng.integers(-1000, 1000, size=3)
    r = hausdorff_decimate(v, t, tol, relative=True)
    faces = v[r.triangles]
    for k in rng.choice(len(t), min(len(t), 12), replace=False):
        a, b, c = (tuple(Fraction(float(x)) for x in v[i]) for i in t[k])
        points = [a, b, c] + [tuple((p + q) / 2 for p, q in zip(p1, p2))
                              for p1, p2 in ((a, b), (b, c), (c, a))]
        points.append(tuple((p + q + w) / 3 for p, q, w in zip(a, b, c)))
        worst = max(min(exact_point_triangle_sq(p, *f) for f in faces) for p in points)
        assert worst <= Fraction(float(r.bounds[k])) ** 2
        assert r.bounds[k] <= r.tol_for(0)


# --------------------------------------------------------------------------- parts
def test_parts_keep_their_shared_border():
    v, t = grid(12, wave(0.05, 2.0, 1.0))
    centroid_x = v[t].mean(axis=1)[:, 0]
    parts = np.where(centroid_x < 0.5, 3, 7).astype(np.int32)
    r = hausdorff_decimate(v, t, 0.02, parts=parts)
    check_result(v, t, r, parts=parts)
    assert r.part_labels.tolist() == [3, 7]
    with pytest.raises(KeyError):
        r.tol_for(5)
    shared = np.intersect1d(t[parts == 3], t[parts == 7])
    assert len(shared) == 13
    # shared vertices slide along the common border in both parts at once: those left are
    # used by both parts, and the border's two ends (on the open boundary) never move
    kept = np.intersect1d(shared, r.triangles)
    assert len(kept) < len(shared) and np.isin(shared[[0, -1]], kept).all()
    for label in (3, 7):
        assert np.isin(kept, r.triangles[r.parts == label]).all()
        assert np.isin(r.triangles[r.parts == label], t[parts == label]).all()
    # with sliding off, every shared vertex stays in both parts
    locked = hausdorff_decimate(v, t, 0.02, parts=parts, slide_shared=False)
    check_result(v, t, locked, parts=parts)
    for label in (3, 7):
        assert np.isin(shared, locked.triangles[locked.parts == label]).all()
    # each part's tolerance is relative to its own box
    for label in (3, 7):
        own = np.unique(t[parts == label])
        assert r.tol_for(label) == pytest.approx(0.02 * np.linalg.norm(np.ptp(v[own], axis=0)))
    assert len(r.triangles) < len(t) / 3


# --------------------------------------------------------------------------- awkward input
def test_non_manifold_edge_bow_tie_and_duplicates():
    v, t = grid(6, wave(0.05))
    n_plate = len(v)
    # a fin standing on the grid line y = 0.5 (three faces on each of its base edges)
    fv, ft = grid(6)
    fin = np.stack([fv[:, 0], np.full(len(fv), 0.5), 0.5 * fv[:, 1]], 1)
    base = np.flatnonzero(np.isclose(fv[:, 1], 0))
    line = np.flatnonzero(np.isclose(v[:, 1], 0.5))
    remap = np.arange(len(fv)) + n_plate
    remap[base] = line[np.abs(v[line, 0][None, :] - fv[base, 0][:, None]).argmin(axis=1)]
    v2 = np.concatenate([v, fin])
    t2 = np.concatenate([t, remap[ft]])
    # a second plate touching the first at one corner only (a bow-tie vertex)
    bv, bt = grid(4, offset=(1.0, 1.0, 0.0))
    corner = np.flatnonzero(np.isclose(v[:, 0], 1) & np.isclose(v[:, 1], 1))[0]
    bmap = np.arange(len(bv)) + len(v2)
    bmap[0] = corner
    v3 = np.concatenate([v2, bv])
    t3 = np.concatenate([t2, bmap[bt]])
    # duplicate faces, one of them reversed
    t4 = np.concatenate([t3, t3[:5], t3[5:9, ::-1]])
    tol_abs = 0.02 * np.linalg.norm(np.ptp(v3[np.unique(t4)], axis=0))
    r = hausdorff_decimate(v3, t4, 0.02)
    unique_input = np.unique(np.sort(t4, axis=1), axis=0)
    assert len(r.triangles) < len(unique_input)
    check_result(v3, t4, r, tol_abs)
    # base line vertices of the fin (non-manifold edges) and the bow-tie vertex never move
    assert np.isin(line, r.triangles).all()
    assert corner in r.triangles


def test_repeated_index_triangles_are_dropped():
    v, t = grid(4)
    bad = np.array([[0, 0, 1], [2, 3, 2]])
    r = hausdorff_decimate(v, np.concatenate([t, bad]), 0.1)
    assert r.dropped == 2 and np.isnan(r.bounds[-2:]).all()
    assert np.isfinite(r.bounds[:-2]).all()
    assert r.input_triangles == len(t) + 2


@pytest.mark.parametrize("kwargs, message", [
    ({"vertices": np.zeros((4, 2))}, "vertices"),
    ({"vertices": np.full((4, 3), np.nan)}, "finite"),
    ({"triangles": np.array([[0, 1, 9]])}, "missing"),
    ({"triangles": np.zeros((0, 3), int)}, "no triangles"),
    ({"triangles": np.zeros((2, 3))}, "integer"),
    ({"tol": 0.0}, "tol"),
    ({"tol": np.inf}, "tol"),
    ({"parts": np.zeros(5, int)}, "parts"),
    ({"feature_deg": 200}, "feature_deg"),
    ({"max_normal_deg": 0}, "max_normal_deg"),
    ({"max_depth": 20}, "max_depth"),
    ({"passes": 0}, "passes"),
    ({"triangles": np.array([[0, 0, 1]])}, "repeats"),
])
def test_bad_input_is_refused(kwargs, message):
    args = {"vertices": np.eye(4, 3), "triangles": np.array([[0, 1, 2], [0, 2, 3]]),
            "tol": 0.01}
    args.update(kwargs)
    with pytest.raises(ValueError, match=message):
        hausdorff_decimate(args.pop("vertices"), args.pop("triangles"), args.pop("tol"), **args)


# --------------------------------------------------------------------------- the car
def test_car_parts_within_tolerance(car):
    v, t = car.nodes, car.triangles
    parts = car.parts[car.triangulation.element_of]
    r = hausdorff_decimate(v, t, 0.005, parts=parts)
    assert len(r.triangles) < len(t) / 5
    assert r.part_labels.tolist() == np.unique(parts).tolist()
    tol_of = r.tol_abs[np.searchsorted(r.part_labels, parts)]
    assert (r.bounds <= tol_of).all()
    # a sampled check of the two smallest parts (the sampling is brute force)
    for label in sorted(r.part_labels, key=lambda p: (parts == p).sum())[:2]:
        d = sampled_distances(v, t[parts == label], r.triangles[r.parts == label], n=3)
        assert d.max() <= r.tol_for(label)
