"""The software rasterizer against brute force: the pixel rule, both fragment generators, the
depth test, thread counts, sessions, tiles, clipping and bad triangles."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from workbench.algo.softraster import Frame, RasterOptions, Shading, render
from workbench.algo.softraster.rule import coverage_mask, snap
from workbench.scene.generators import semicylinders

W, H = 40, 32
DEFAULT_OPTIONS = RasterOptions()
DEFAULT_SHADING = Shading()


def pixel_projection(width: int, height: int) -> np.ndarray:
    """Orthographic projection putting model (x, y, z) at image (x, y) pixels, depth z."""
    proj = np.zeros((4, 4))
    proj[0, 0], proj[0, 3] = 2.0 / width, -1.0
    proj[1, 1], proj[1, 3] = -2.0 / height, 1.0
    proj[2, 2], proj[2, 3] = 2.0, -1.0
    proj[3, 3] = 1.0
    return proj


def draw(points, triangles, options=DEFAULT_OPTIONS, shading=DEFAULT_SHADING, size=(W, H),
         **kw):
    frame, stats = render(np.asarray(points, np.float64), triangles, np.eye(4),
                          pixel_projection(*size), size, shading, options, **kw)
    return frame, stats


def window(points, size=(W, H)):
    """The GL window coordinates (y up) the rasterizer computes for pixel-space points, in
    float32 as the vertex stage does."""
    p = np.asarray(points, np.float32)
    hw, hh = np.float32(size[0] / 2), np.float32(size[1] / 2)
    x = ((p[:, 0] * np.float32(2.0 / size[0]) + np.float32(-1.0)) * hw + hw)
    y = ((p[:, 1] * np.float32(-2.0 / size[1]) + np.float32(1.0)) * hh + hh)
    return np.c_[x, y].astype(np.float64)


coords = st.floats(-5.0, W + 5.0, allow_nan=False, width=32)
triangle_points = st.lists(st.tuples(coords, coords), min_size=3, max_size=3)


@settings(max_examples=150, deadline=None)
@given(triangle_points, st.sampled_from([0, 2, 8]))
def test_one_triangle_covers_what_brute_force_covers(points, bits):
    pts = np.c_[np.asarray(points, np.float64), np.full(3, 0.5)]
    frame, _ = draw(pts, [[0, 1, 2]], RasterOptions(subpixel_bits=bits))
    fixed = snap(window(pts), H, bits)
    expected = coverage_mask(fixed, W, H, bits)
    assert np.array_equal(frame.triangle == 0, expected)


@settings(max_examples=80, deadline=None)
@given(st.lists(st.tuples(st.integers(-12, 12), st.integers(-12, 12)), min_size=2, max_size=2),
       st.sampled_from([10, 15]))
def test_table_and_half_space_generate_the_same_fragments(offsets, size):
    # triangles just below and above the table size go through both generators identically
    (a, b), (c, d) = offsets
    v0 = np.array([20.5, 15.5, 0.5])
    pts = np.array([v0, v0 + [a, b, 0], v0 + [c, d, 0]])
    table, stats = draw(pts, [[0, 1, 2]], RasterOptions(generator="table", table_size=size,
                                                        subpixel_bits=0))
    half, _ = draw(pts, [[0, 1, 2]], RasterOptions(subpixel_bits=0))
    assert np.array_equal(table.triangle, half.triangle)
    fits = all(-size <= v <= size - 1 for v in (a, b, c, d))
    assert stats.table_fit == (fits and stats.kept == 1)


def lattice_triangles(n: int, seed: int):
    """A jittered (n+1)² lattice over the image, split into 2n² triangles (both diagonals)."""
    rng = np.random.default_rng(seed)
    gx, gy = np.meshgrid(np.linspace(-1, W + 1, n + 1), np.linspace(-1, H + 1, n + 1))
    pts = np.c_[gx.ravel(), gy.ravel(), np.full(gx.size, 0.5)]
    inner = (gx.ravel() > 0) & (gx.ravel() < W) & (gy.ravel() > 0) & (gy.ravel() < H)
    pts[inner, :2] += rng.uniform(-0.3, 0.3, (inner.sum(), 2)) * (W / n)
    # some vertices exactly on pixel centres, so that edges pass through centres
    pts[inner & (np.arange(len(pts)) % 3 == 0), :2] = \
        np.floor(pts[inner & (np.arange(len(pts)) % 3 == 0), :2]) + 0.5
    tris = []
    for j in range(n):
        for i in range(n):
            a, b = j * (n + 1) + i, j * (n + 1) + i + 1
            c, d = a + n + 1, b + n + 1
            tris += [[a, b, d], [a, d, c]] if (i + j) % 2 else [[a, b, c], [b, d, c]]
    return pts, np.array(tris)


@pytest.mark.parametrize("bits", [0, 8])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_triangles_tiling_the_image_cover_every_pixel_once(bits, seed):
    pts, tris = lattice_triangles(7, seed)
    count = np.zeros((H, W), int)
    for k in range(len(tris)):
        frame, _ = draw(pts, tris[k:k + 1], RasterOptions(subpixel_bits=bits))
        count += frame.triangle >= 0
    assert (count == 1).all()
    whole, _ = draw(pts, tris, RasterOptions(subpixel_bits=bits))
    assert (whole.triangle >= 0).all()


def test_a_shared_edge_is_drawn_once():
    # two triangles sharing a diagonal through pixel centres
    pts = np.array([[2.5, 2.5, 0.5], [12.5, 2.5, 0.5], [12.5, 12.5, 0.5], [2.5, 12.5, 0.5]])
    first, _ = draw(pts, [[0, 1, 2]])
    second, _ = draw(pts, [[0, 2, 3]])
    overlap = (first.triangle >= 0) & (second.triangle >= 0)
    assert not overlap.any()
    diagonal = [(j, j) for j in range(3, 12)]
    assert all((first.triangle[j, i] >= 0) != (second.triangle[j, i] >= 0) for j, i in diagonal)


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 2 ** 31), st.booleans())
def test_depth_test_does_not_depend_on_triangle_order(seed, ties):
    rng = np.random.default_rng(seed)
    k = 30
    pts = np.c_[rng.uniform(0, W, (3 * k, 2)), np.repeat(rng.uniform(0.1, 0.9, k), 3)]
    if ties:  # coplanar pairs: equal depths, the lower index must win in any order
        pts[3 * (k // 2):, :] = pts[:3 * (k - k // 2), :]
    tris = np.arange(3 * k).reshape(k, 3)
    shading = Shading("flat")
    a, _ = draw(pts, tris, shading=shading)
    order = rng.permutation(k)
    b, _ = draw(pts, tris[order], shading=shading, ids=order)
    assert np.array_equal(a.triangle, b.triangle)
    assert np.array_equal(a.color, b.color)
    assert np.array_equal(a.depth, b.depth)


def scene():
    mesh = semicylinders(4, 16)
    proj = np.zeros((4, 4))
    proj[0, 0] = proj[1, 1] = 1 / 110
    proj[2, 2], proj[3, 3] = -1 / 150, 1.0
    pos = mesh.coordinates(0) - [0, 0, -15]
    t = mesh.node_fields["distance"] / mesh.node_fields["distance"].max()
    normals = np.tile([0.0, 0.0, 1.0], (len(pos), 1))
    normals[:, 0] = np.sin(pos[:, 0] / 100)
    return pos, mesh.triangles, proj, t, normals


def bands_shading():
    from workbench.paths.colormap import ColorScale

    scale = ColorScale("viridis", (0.0, 1.0), 6)
    return Shading("pixel_color", texels=scale.texture_data(), linear=False,
                   coord=scale.coord_transform)


@pytest.mark.parametrize("options", [
    RasterOptions(threads=1), RasterOptions(threads=2), RasterOptions(tile=8),
    RasterOptions(session=100), RasterOptions(early_depth=False),
    RasterOptions(tile=16, session=37, threads=2, early_depth=False)])
def test_image_is_the_same_for_threads_tiles_sessions_and_early_depth(options):
    pos, tris, proj, t, normals = scene()
    kw = dict(values=t, normals=normals)
    reference, _ = render(pos, tris, np.eye(4), proj, (120, 90), bands_shading(), **kw)
    frame, stats = render(pos, tris, np.eye(4), proj, (120, 90), bands_shading(), options, **kw)
    assert (reference.triangle >= 0).sum() > 5000
    assert np.array_equal(frame.color, reference.color)
    assert np.array_equal(frame.triangle, reference.triangle)
    assert np.array_equal(frame.depth, reference.depth)
    assert stats.kept == len(tris)


@pytest.mark.parametrize("size", [10, 20])
def test_table_and_half_space_draw_the_same_scene(size):
    pos, tris, proj, t, normals = scene()
    kw = dict(values=t, normals=normals)
    half, _ = render(pos, tris, np.eye(4), proj, (120, 90), bands_shading(),
                     RasterOptions(subpixel_bits=0), **kw)
    table, stats = render(pos, tris, np.eye(4), proj, (120, 90), bands_shading(),
                          RasterOptions(generator="table", table_size=size, subpixel_bits=0),
                          **kw)
    assert 0.5 * stats.kept < stats.table_fit  # both generators at work for S = 10
    assert size == 20 or stats.table_fit < stats.kept
    assert np.array_equal(half.color, table.color)
    assert np.array_equal(half.triangle, table.triangle)


def test_interpreted_steps_draw_what_the_compiled_ones_draw():
    mesh = semicylinders(2, 4)
    pos = mesh.coordinates(0) - [0, 0, -5]
    proj = np.diag([1 / 110, 1 / 110, -1 / 50, 1.0])
    t = mesh.node_fields["distance"] / mesh.node_fields["distance"].max()
    normals = np.tile([0.3, 0.0, 1.0], (len(pos), 1))
    for options in (RasterOptions(), RasterOptions(generator="table", subpixel_bits=0)):
        on, s_on = render(pos, mesh.triangles, np.eye(4), proj, (48, 40), bands_shading(),
                          options, values=t, normals=normals)
        off, s_off = render(pos, mesh.triangles, np.eye(4), proj, (48, 40), bands_shading(),
                            options, values=t, normals=normals, vectorized=False)
        assert np.array_equal(on.color, off.color)
        assert np.array_equal(on.triangle, off.triangle)
        assert s_on.fragments == s_off.fragments > 0


def test_bad_and_clipped_triangles_draw_nothing_and_raise_nothing():
    good = [[5.5, 5.5, 0.5], [20.5, 6.5, 0.5], [8.5, 20.5, 0.5]]
    bad = [
        [[1, 1, 0.5], [1, 1, 0.5], [1, 1, 0.5]],  # a point
        [[1, 1, 0.5], [5, 5, 0.5], [9, 9, 0.5]],  # a line
        [[np.nan, 1, 0.5], [5, 5, 0.5], [9, 1, 0.5]],  # not finite
        [[np.inf, 1, 0.5], [5, 5, 0.5], [9, 1, 0.5]],
        [[-50, -50, 0.5], [-40, -50, 0.5], [-45, -40, 0.5]],  # off the image
        [[5, 5, 1.5], [20, 6, 1.5], [8, 20, 1.5]],  # beyond the far plane
        [[5, 5, -0.5], [20, 6, -0.5], [8, 20, -0.5]],  # before the near plane
        [[1e12, 5, 0.5], [-1e12, 6, 0.5], [8, 20, 0.5]],  # beyond the guard band
    ]
    pts = np.array(good + sum(bad, []), np.float64)
    tris = np.arange(len(pts)).reshape(-1, 3)
    frame, stats = draw(pts, tris)
    alone, _ = draw(np.array(good), [[0, 1, 2]])
    assert stats.kept == 1
    assert np.array_equal(frame.triangle, alone.triangle)
    # a clip plane that keeps x <= 3 clips the good triangle wholly
    clipped, stats = draw(np.array(good), [[0, 1, 2]], clip_planes=[[-1.0, 0.0, 0.0, 3.0]])
    assert stats.kept == 0 and (clipped.triangle < 0).all()


def test_a_clip_plane_keeps_the_side_it_names():
    pts = np.array([[0.0, 0.0, 0.5], [W, 0.0, 0.5], [0.0, 2.0 * H, 0.5], [W, 2.0 * H, 0.5]])
    frame, _ = draw(pts, [[0, 1, 2], [1, 3, 2]], clip_planes=[[1.0, 0.0, 0.0, -10.0]])
    drawn = frame.triangle >= 0
    assert drawn[:, 10:].all() and not drawn[:, :10].any()


def test_refusals():
    pts = np.zeros((3, 3))
    with pytest.raises(ValueError, match="subpixel_bits=0"):
        RasterOptions(generator="table")
    with pytest.raises(ValueError, match="orthographic"):
        persp = np.zeros((4, 4))
        persp[3, 2] = -1
        render(pts, [[0, 1, 2]], np.eye(4), persp, (8, 8))
    with pytest.raises(ValueError, match="triangle indices"):
        draw(pts, [[0, 1, 3]])
    with pytest.raises(ValueError, match="needs normals"):
        draw(pts, [[0, 1, 2]], shading=bands_shading())
    with pytest.raises(ValueError, match="shading must be"):
        Shading("phong")
    with pytest.raises(ValueError, match="frame is"):
        draw(pts, [[0, 1, 2]], frame=Frame.empty(4, 4))
