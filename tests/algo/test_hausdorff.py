"""The AABB tree's queries against brute force over every triangle, and the certified
Hausdorff bracket against independent references: libigl's point-mesh distances on dense
samples, exact rational arithmetic at the points the bracket names, closed-form cases and a
sampled reference tool."""

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from meshes import barycentric_grid, quad_grid

from workbench.algo.hausdorff import hausdorff
from workbench.algo.nearest.bvh import TriangleBVH
from workbench.algo.nearest.triangle import point_triangle_distance, points_triangles_distance
from workbench.reliability import exact


# --------------------------------------------------------------------------- meshes
def grid(n: int, m: int | None = None, height=None, size: float = 1.0):
    """An n×m grid over [-size, size]², two triangles per cell, z = height(x, y)."""
    m = n if m is None else m
    return quad_grid(n, m, span=((-size, size), (-size, size)), z=height, ij=True,
                     triangles=True)


def height_field(rng, n, m, amplitude):
    """A grid with random heights: a bumpy open surface."""
    v, f = grid(n, m)
    v[:, 2] = amplitude * rng.normal(size=len(v))
    return v, f


def soup(rng, n_vertices, n_triangles, spread):
    """Random vertices and triangles, repeated indices (degenerate triangles) included."""
    v = rng.normal(size=(n_vertices, 3)) * spread
    return v, rng.integers(0, n_vertices, size=(n_triangles, 3))


def dense_points(v, f, n):
    """A barycentric grid of spacing 1/n on every triangle, and the largest spacing between
    neighbouring grid points (every point of the surface is within it of a grid point)."""
    u, w = barycentric_grid(n)
    c = v[f]
    e1, e2 = c[:, 1] - c[:, 0], c[:, 2] - c[:, 0]
    pts = c[:, None, 0] + u[None, :, None] * e1[:, None] + w[None, :, None] * e2[:, None]
    longest = max(np.linalg.norm(e1, axis=1).max(), np.linalg.norm(e2, axis=1).max(),
                  np.linalg.norm(e2 - e1, axis=1).max())
    return pts.reshape(-1, 3), longest / n


def distance_to_mesh(points, v, f):
    """Distances from ``points`` to the mesh by libigl (an independent float64 kernel)."""
    import igl

    p = np.atleast_2d(np.asarray(points, np.float64))
    return np.sqrt(igl.point_mesh_squared_distance(p, v, np.asarray(f, np.int64))[0])


pair = st.tuples(st.integers(0, 10**6), st.sampled_from(["fields", "soups", "mixed"]))


def make_pair(seed, kind):
    rng = np.random.default_rng(seed)
    if kind == "fields":
        va, fa = height_field(rng, *rng.integers(1, 4, size=2), amplitude=0.3)
        vb, fb = height_field(rng, *rng.integers(1, 4, size=2), amplitude=0.3)
    elif kind == "soups":
        va, fa = soup(rng, 6, rng.integers(1, 6), 1.0)
        vb, fb = soup(rng, 6, rng.integers(1, 6), 1.0)
    else:
        va, fa = height_field(rng, 2, 3, amplitude=0.2)
        vb, fb = soup(rng, 7, rng.integers(2, 8), 0.8)
    return va, fa, vb, fb


# --------------------------------------------------------------------------- the tree
@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 10**6), n_triangles=st.integers(1, 60),
       split_factor=st.sampled_from([0.3, 1.0, 4.0, 1e9]), leaf_size=st.integers(1, 8))
def test_nearest_matches_brute_force(seed, n_triangles, split_factor, leaf_size):
    rng = np.random.default_rng(seed)
    v, f = soup(rng, 2 * n_triangles + 3, n_triangles, 2.0)
    v[: len(v) // 3] *= 10  # long triangles, entered as several references
    tree = TriangleBVH(v, f, leaf_size=leaf_size, split_factor=split_factor)
    points = rng.normal(size=(40, 3)) * 6
    table = points_triangles_distance(points, v[f])
    dist, tri, closest = tree.nearest(points)
    assert np.allclose(dist, table.min(axis=1), rtol=0, atol=1e-12)
    assert np.allclose(table[np.arange(len(points)), tri], dist, rtol=0, atol=1e-12)
    assert np.allclose(np.linalg.norm(points - closest, axis=1), dist, rtol=0, atol=1e-9)
    for c, t in zip(closest, tri):  # the closest point lies on its triangle
        assert point_triangle_distance(c, *v[f[t]]) <= 1e-9
    # any start triangle gives the same answer (up to rounding where triangles tie)
    hinted, _, _ = tree.nearest(points, hint=rng.integers(-1, n_triangles, size=len(points)))
    assert np.allclose(hinted, dist, rtol=0, atol=1e-12)


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 10**6), n_triangles=st.integers(1, 40),
       radius=st.floats(0.0, 8.0))
def test_triangles_within_matches_brute_force(seed, n_triangles, radius):
    rng = np.random.default_rng(seed)
    v, f = soup(rng, 2 * n_triangles, n_triangles, 3.0)
    tree = TriangleBVH(v, f, split_factor=0.5)
    p = rng.normal(size=3) * 3
    found = tree.triangles_within(p, radius)
    d = points_triangles_distance(p[None], v[f])[0]
    assert np.array_equal(found, np.unique(found))  # sorted, each triangle once
    assert set(np.flatnonzero(d < radius * (1 - 1e-9))) <= set(found.tolist())
    assert set(found.tolist()) <= set(np.flatnonzero(d <= radius * (1 + 1e-9)))


def test_nearest_beyond_max_distance_finds_nothing():
    v, f = grid(2)
    tree = TriangleBVH(v, f)
    dist, tri, closest = tree.nearest([[0, 0, 0.5], [0, 0, 3.0]], max_distance=1.0)
    assert dist[0] == pytest.approx(0.5) and tri[0] >= 0
    assert dist[1] == np.inf and tri[1] == -1 and np.isnan(closest[1]).all()


def test_tree_refuses_bad_input():
    v, f = grid(1)
    with pytest.raises(ValueError, match="no triangles"):
        TriangleBVH(v, np.zeros((0, 3), int))
    with pytest.raises(ValueError, match="non-finite"):
        TriangleBVH(np.where(np.arange(len(v))[:, None] == 1, np.inf, v), f)
    with pytest.raises(ValueError, match="leaf_size"):
        TriangleBVH(v, f, leaf_size=0)
    tree = TriangleBVH(v, f)
    with pytest.raises(ValueError, match="points"):
        tree.nearest([[0, 0, np.nan]])
    with pytest.raises(ValueError, match="hint"):
        tree.nearest([[0, 0, 0]], hint=[len(f)])
    with pytest.raises(ValueError, match="radius"):
        tree.triangles_within([0, 0, 0], -1.0)


# --------------------------------------------------------------------------- the bracket
@settings(max_examples=60, deadline=None)
@given(pair=pair, split=st.sampled_from(["planes", "midpoint"]),
       tol=st.sampled_from([0.0, 1e-6, 1e-3, 0.05]), estimates=st.booleans())
def test_bracket_holds_the_dense_maximum(pair, split, tol, estimates):
    va, fa, vb, fb = make_pair(*pair)
    r = hausdorff(va, fa, vb, fb, tol=tol, split=split, estimates=estimates)
    points, spacing = dense_points(va, fa, 24)
    dense = distance_to_mesh(points, vb, fb)
    scale = 1e-12 * (1 + np.abs(va).max() + np.abs(vb).max())
    # every dense sample is a point of A: none is farther than the upper bound
    assert dense.max() <= r.upper + scale
    # the true maximum is within one spacing of a sample (distance is 1-Lipschitz)
    assert r.lower <= dense.max() + spacing + scale
    # the estimate is a distance actually attained, at location[0] on A, to location[1] on B
    # (exact rational distances), and the bracket holds it
    a, b = r.location
    assert exact.points_mesh_distance(a, vb[fb])[0] == pytest.approx(r.max, abs=scale)
    assert exact.points_mesh_distance(a, va[fa])[0] <= scale
    assert exact.points_mesh_distance(b, vb[fb])[0] <= scale
    assert np.linalg.norm(a - b) == pytest.approx(r.max, abs=scale)
    assert r.lower <= r.max <= r.upper
    if r.tol_reached:
        assert r.upper - r.lower <= tol
    if estimates:
        assert 0 <= r.mean <= r.rms + scale and r.rms <= r.upper + scale
    else:
        assert np.isnan(r.mean) and np.isnan(r.rms)


@settings(max_examples=30, deadline=None)
@given(pair=pair)
def test_both_refinements_agree(pair):
    va, fa, vb, fb = make_pair(*pair)
    planes = hausdorff(va, fa, vb, fb, tol=1e-6)
    midpoint = hausdorff(va, fa, vb, fb, tol=1e-6, split="midpoint")
    cascade = hausdorff(va, fa, vb, fb, tol=1e-6, estimates=False)
    # certified brackets of one value overlap
    runs = (planes, midpoint, cascade)
    assert max(r.lower for r in runs) <= min(r.upper for r in runs)


def test_plane_cuts_close_the_bracket_where_nearest_faces_change():
    # a bumpy surface against a coarse one: the nearest face changes inside A's triangles
    va, fa = grid(7, height=lambda x, y: 0.2 * np.sin(3 * x) * np.cos(2 * y))
    vb, fb = grid(2, height=lambda x, y: 0.1 * x * y)
    r = hausdorff(va, fa, vb, fb, tol=1e-9)
    assert r.tol_reached and r.upper - r.lower <= 1e-9
    coarse = hausdorff(va, fa, vb, fb, tol=1e-9, max_depth=0)
    assert not coarse.tol_reached and coarse.upper - coarse.lower > 1e-9
    # the deeper search finds at least the distance the shallow one did and bounds it tighter
    # (each bracket is rounded outward by a margin that grows with its depth)
    assert coarse.lower <= coarse.max <= r.max <= r.upper <= coarse.upper


def test_identical_meshes_are_at_distance_zero():
    v, f = grid(6, height=lambda x, y: 0.2 * np.sin(3 * x) * y)
    for one_sided in (True, False):
        r = hausdorff(v, f, v, f, tol=0.0, one_sided=one_sided)
        assert 0.0 <= r.lower <= r.upper <= 1e-12
        assert r.mean <= 1e-12


@pytest.mark.parametrize("h", [1e-9, 0.37, 250.0])
def test_a_plate_and_its_copy_lifted_by_h(h):
    v, f = grid(5)
    r = hausdorff(v, f, v + [0, 0, h], f, tol=0.0)
    assert r.lower == pytest.approx(h, rel=1e-12) and r.upper == pytest.approx(h, rel=1e-12)
    assert r.mean == pytest.approx(h, rel=1e-12) and r.rms == pytest.approx(h, rel=1e-12)


def pyramid(height):
    """The square [-1, 1]² with its centre lifted to ``height``: four triangles."""
    v = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0], [0, 0, height]], float)
    return v, np.array([[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]])


@pytest.mark.parametrize("height", [0.05, 0.6, 3.0])
def test_lifted_centre_against_the_flat_square(height):
    lifted, fl = pyramid(height)
    # the flat square, its centre vertex moved off the centre so that the farthest point of the
    # flat square from the pyramid (the centre) is no sample and must be found by refinement
    flat = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0], [0.31, -0.17, 0]], float)
    ff = fl
    up = hausdorff(lifted, fl, flat, ff, tol=1e-10)
    assert up.lower == pytest.approx(height, rel=1e-12) and up.upper == pytest.approx(height,
                                                                                    rel=1e-12)
    # from the flat square, the centre is nearest to a slanted face: h / sqrt(1 + h²)
    expected = height / np.sqrt(1 + height ** 2)
    down = hausdorff(flat, ff, lifted, fl, tol=1e-10)
    assert down.tol_reached
    assert down.lower <= expected * (1 + 1e-12) and expected <= down.upper * (1 + 1e-12)
    assert down.upper - down.lower <= 1e-10
    assert np.allclose(down.location[0], 0, atol=1e-6)
    # one-sided distances differ; the symmetric one is the larger, both reported
    both = hausdorff(lifted, fl, flat, ff, tol=1e-10, one_sided=False)
    assert both.lower == max(up.lower, down.lower) and both.upper == max(up.upper, down.upper)
    assert both.forward.lower == up.lower and both.backward.lower == down.lower
    assert np.allclose(both.location, up.location)


@settings(max_examples=20, deadline=None)
@given(pair=pair)
def test_symmetric_is_the_larger_one_sided(pair):
    va, fa, vb, fb = make_pair(*pair)
    ab = hausdorff(va, fa, vb, fb, tol=1e-6)
    ba = hausdorff(vb, fb, va, fa, tol=ab.tol)
    sym = hausdorff(va, fa, vb, fb, tol=1e-6, one_sided=False)
    assert (sym.forward.lower, sym.forward.upper) == (ab.lower, ab.upper)
    assert sym.lower == max(sym.forward.lower, sym.backward.lower)
    assert sym.upper == max(sym.forward.upper, sym.backward.upper)
    assert sym.samples == ab.samples + ba.samples
    # B to A on its own is translated by B's origin, not A's: its bracket differs by rounding
    # and refinement, and must still overlap
    slack = 1e-12 * (1 + np.abs(va).max() + np.abs(vb).max())
    assert max(sym.backward.lower, ba.lower) <= min(sym.backward.upper, ba.upper) + slack
    assert max(sym.lower, ab.lower, ba.lower) <= min(sym.upper, max(ab.upper, ba.upper)) + slack


def test_far_from_the_origin_the_bracket_keeps_its_digits():
    va, fa = grid(6, height=lambda x, y: 0.2 * np.sin(3 * x) * y)
    vb, fb = grid(3, height=lambda x, y: 0.1 * x + 0.05)
    near = hausdorff(va, fa, vb, fb, tol=0.0)
    shift = np.array([1e6, -1e6, 1e6])
    far = hausdorff(va + shift, fa, vb + shift, fb, tol=0.0)
    assert far.lower == pytest.approx(near.lower, rel=1e-9)
    assert far.upper == pytest.approx(near.upper, rel=1e-9)
    assert np.allclose(far.location - shift, near.location, atol=1e-8)


def test_unreferenced_vertices_are_ignored():
    va, fa = grid(3, height=lambda x, y: 0.3 * x * y)
    vb, fb = grid(2)
    base = hausdorff(va, fa, vb, fb, tol=0.0)
    junk = np.array([[1e9, 0, 0], [np.nan, 0, 0], [0, np.inf, 0]])
    more = hausdorff(np.vstack([junk, va]), fa + 3, np.vstack([vb, junk]), fb, tol=0.0)
    assert (more.lower, more.upper, more.mean) == (base.lower, base.upper, base.mean)


def test_degenerate_triangles_are_measured_as_their_edges():
    vb, fb = grid(2)
    # a segment 0.5 above the plate, given as a triangle with a repeated vertex
    va = np.array([[-0.5, 0, 0.5], [0.5, 0, 0.5], [0.0, 0, 0.5]])
    r = hausdorff(va, np.array([[0, 1, 1]]), vb, fb, tol=0.0)
    assert r.lower == pytest.approx(0.5, rel=1e-12) and r.upper == pytest.approx(0.5, rel=1e-12)
    # and as the target: the distance to a segment
    r = hausdorff(vb, fb, np.array([[0, 0, 0], [1, 0, 0]]), np.array([[0, 1, 1]]), tol=1e-9)
    assert r.lower == pytest.approx(np.sqrt(2.0), rel=1e-9)  # corner (-1, ±1) to (0, 0)


def test_bad_input_is_refused_naming_the_input():
    v, f = grid(2)
    with pytest.raises(ValueError, match=r"A \(va, fa\): no triangles"):
        hausdorff(v, np.zeros((0, 3), int), v, f)
    with pytest.raises(ValueError, match=r"B \(vb, fb\): no triangles"):
        hausdorff(v, f, v, np.zeros((0, 3), int))
    bad = v.copy()
    bad[f[0, 0], 2] = np.nan
    with pytest.raises(ValueError, match=r"A \(va, fa\): non-finite"):
        hausdorff(bad, f, v, f)
    with pytest.raises(ValueError, match=r"B \(vb, fb\): non-finite"):
        hausdorff(v, f, bad, f)
    with pytest.raises(ValueError, match=r"B \(vb, fb\): triangles must be \(K, 3\)"):
        hausdorff(v, f, v, f[:, :2])
    with pytest.raises(ValueError, match=r"A \(va, fa\): vertices must be \(N, 3\)"):
        hausdorff(v[:, :2], f, v, f)
    with pytest.raises(ValueError, match="integers"):
        hausdorff(v, f.astype(float), v, f)
    with pytest.raises(ValueError, match="missing vertices"):
        hausdorff(v, f + len(v), v, f)
    with pytest.raises(ValueError, match="tol"):
        hausdorff(v, f, v, f, tol=-1.0)
    with pytest.raises(ValueError, match="tol"):
        hausdorff(v, f, v, f, tol=np.nan)
    with pytest.raises(ValueError, match="max_depth"):
        hausdorff(v, f, v, f, max_depth=31)
    with pytest.raises(ValueError, match="split"):
        hausdorff(v, f, v, f, split="random")
    with pytest.raises(TypeError, match="one_sided"):
        hausdorff(v, f, v, f, one_sided="yes")
    with pytest.raises(TypeError, match="estimates"):
        hausdorff(v, f, v, f, estimates=None)


# --------------------------------------------------------------------------- the car
@pytest.fixture(scope="module")
def car_pair(car_deck):
    pymeshlab = pytest.importorskip("pymeshlab")
    from workbench.scene.builtin import fresh_scene

    car = fresh_scene("car")
    used, inverse = np.unique(car.triangles, return_inverse=True)
    v, f = car.nodes[used], inverse.reshape(-1, 3).astype(np.int64)
    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=v, face_matrix=f.astype(np.int32)))
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=v, face_matrix=f.astype(np.int32)))
    ms.meshing_decimation_quadric_edge_collapse(targetfacenum=len(f) // 8)
    simplified = ms.current_mesh()
    return ms, v, f, simplified.vertex_matrix().copy(), simplified.face_matrix().astype(np.int64)


@pytest.mark.parametrize("estimates", [True, False])
def test_car_bracket_is_above_pymeshlab_sampled_distance(car_pair, estimates):
    ms, v, f, u, g = car_pair
    diag = float(np.linalg.norm(v.max(axis=0) - v.min(axis=0)))
    r = hausdorff(v, f, u, g, tol=1e-4 * diag, estimates=estimates)
    assert r.tol_reached and r.upper - r.lower <= 1e-4 * diag
    # mesh 0 is the original, mesh 1 the simplified one
    sampled = ms.get_hausdorff_distance(sampledmesh=0, targetmesh=1, samplevert=True,
                                        sampleedge=True, sampleface=True, samplenum=20_000)
    assert sampled["max"] <= r.upper * (1 + 1e-7) + 1e-9 * diag
    # the estimate is attained where reported
    a = r.location[0]
    assert distance_to_mesh(a, u, g)[0] == pytest.approx(r.max, rel=1e-9, abs=1e-12 * diag)


@pytest.mark.parametrize("offset", [0.0, 1e3, 1e6])
def test_a_surface_against_itself_has_a_bracket_holding_zero(offset):
    """The exact distance of a surface to itself is 0: rounding of the computed distances must
    not lift the certified lower bound above it, wherever the surface lies."""
    rng = np.random.default_rng(7)
    v, f = pyramid(0.6)
    v = v * rng.uniform(0.5, 40.0) + offset
    for one_sided in (True, False):
        r = hausdorff(v, f, v.copy(), f.copy(), one_sided=one_sided)
        assert r.lower == 0.0 <= r.upper
        assert r.upper <= 1e-9 * max(1.0, offset)


def sliver_refinement(rng, k):
    """A planar parallelogram of two triangles with dyadic corners, and the same surface with
    its first triangle split at a point 2^-k of the way from its edge 01 towards corner 2 (three
    children, two of them slivers): every coordinate exact, so both surfaces are the same set
    and each is at distance exactly 0 from the other."""
    v = rng.integers(-1024, 1024, size=(4, 3)).astype(np.float64)
    v[3] = v[0] + v[2] - v[1]
    f = np.array([[0, 1, 2], [0, 2, 3]])
    t = rng.integers(1, 2 ** 8) / 2 ** 8
    w = np.array([1 - t, t - 2.0 ** -k, 2.0 ** -k])
    p = w[0] * v[0] + w[1] * v[1] + w[2] * v[2]
    vb = np.vstack([v, p])
    fb = np.array([[0, 1, 4], [1, 2, 4], [2, 0, 4], [0, 2, 3]])
    return v, f, vb, fb


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2 ** 32 - 1), k=st.integers(3, 30), log_offset=st.integers(0, 14),
       estimates=st.booleans(), split=st.sampled_from(["planes", "midpoint"]))
def test_a_surface_against_a_sliver_refinement_of_itself_holds_zero(seed, k, log_offset,
                                                                   estimates, split):
    """Refinement with slivers, far from the origin: both one-sided brackets hold 0 (the old
    region walk gave 0.053 ≤ H ≤ 0.053 for an exact 5.5e-24 on such a pair)."""
    rng = np.random.default_rng(seed)
    v, f, vb, fb = sliver_refinement(rng, k)
    offset = 2.0 ** log_offset * rng.integers(-1000, 1000, size=3)
    assume(np.array_equal((vb + offset) - offset, vb))  # moved exactly: still the same set
    for a, b in (((v + offset, f), (vb + offset, fb)), ((vb + offset, fb), (v + offset, f))):
        r = hausdorff(*a, *b, estimates=estimates, split=split)
        assert r.lower <= 0.0 <= r.upper
