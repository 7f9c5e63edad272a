"""The fused, tile-parallel software rasterizer draws what the paper's steps draw, bit for bit:
colour, depth and triangle index, for every shading, clip planes, the alpha test, the colour
texture, depth ties and bad triangles; and the same for any thread count."""

import numba
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from test_softraster import pixel_projection

from workbench.algo.softraster import SHADINGS, Frame, RasterOptions, Shading, render
from workbench.algo.softraster import fused as fused_module
from workbench.measurement.rows import default_camera
from workbench.paths import SoftwareRasterizer, Style, prepared
from workbench.scene.generators import crash_sequence, stamped_panels

SIZES = [(64, 48), (97, 61), (160, 120)]


def random_scene(seed: int, size, count: int) -> dict:
    """``count`` triangles of their own vertices over an image of ``size``: mostly small, some
    large, some off the image, some with vertices on pixel centres, some degenerate, some
    through the near or far plane, some repeated later (coplanar, equal depths) and some of one
    depth overlapping; normals, vertex and triangle values (a few not numbers)."""
    rng = np.random.default_rng(seed)
    width, height = size
    centre = rng.uniform([-15, -15], [width + 15, height + 15], (count, 2))
    scale = rng.choice([0.6, 2.5, 8.0, 40.0], count, p=[0.3, 0.4, 0.2, 0.1])
    xy = centre[:, None, :] + rng.normal(0.0, 1.0, (count, 3, 2)) * scale[:, None, None]
    on_centres = rng.random(count) < 0.2
    xy[on_centres] = np.floor(xy[on_centres]) + 0.5
    z = rng.uniform(0.05, 0.95, (count, 1)) + rng.normal(0.0, 0.05, (count, 3))
    through = rng.random(count) < 0.08  # through the near or the far plane
    z[through] = rng.uniform(-0.4, 1.4, (through.sum(), 3))
    flat = rng.random(count) < 0.15  # one depth, overlapping one another
    z[flat] = np.round(rng.uniform(0.2, 0.8, (flat.sum(), 1)), 1)
    line = rng.random(count) < 0.05
    xy[line, 2] = 0.5 * (xy[line, 0] + xy[line, 1])
    point = rng.random(count) < 0.03
    xy[point, 1] = xy[point, 0]
    pts = np.concatenate([xy, z[:, :, None]], axis=2)
    repeats = rng.random(count) < 0.15  # an earlier triangle again: equal depths everywhere
    pts[repeats] = pts[rng.integers(0, count, repeats.sum())]
    pts = pts.reshape(-1, 3)
    values = rng.uniform(-0.1, 1.1, len(pts))
    values[rng.random(len(pts)) < 0.03] = np.nan
    triangle_values = rng.uniform(-0.1, 1.1, count)
    triangle_values[rng.random(count) < 0.05] = np.nan
    return dict(points=pts, triangles=np.arange(len(pts)).reshape(-1, 3),
                normals=rng.normal(0.0, 1.0, (len(pts), 3)), values=values,
                triangle_values=triangle_values)


def shading_of(kind: str, seed: int, alpha_test: bool, linear: bool) -> Shading:
    """``kind`` with a random 1-D colour texture of 2 to 9 texels (some nearly transparent)."""
    rng = np.random.default_rng(seed + 1)
    texels = rng.integers(0, 256, (int(rng.integers(2, 10)), 4)).astype(np.uint8)
    texels[rng.random(len(texels)) < 0.4, 3] = 60
    return Shading(kind, base_color=(0.8, 0.6, 0.4), missing_color=(0.1, 0.9, 0.3),
                   texels=texels, linear=linear, coord=(0.9, 0.05), alpha_test=alpha_test)


def draw(scene: dict, size, shading: Shading, options: RasterOptions, frame=None, **kw):
    return render(scene["points"], scene["triangles"], np.eye(4), pixel_projection(*size), size,
                  shading, options, normals=scene["normals"], values=scene["values"],
                  triangle_values=scene["triangle_values"], frame=frame, **kw)


def assert_same(a: Frame, b: Frame) -> None:
    assert np.array_equal(a.triangle, b.triangle), \
        f"{int((a.triangle != b.triangle).sum())} pixels differ in triangle index"
    assert np.array_equal(a.depth, b.depth), \
        f"{int((a.depth != b.depth).sum())} pixels differ in depth"
    assert np.array_equal(a.color, b.color), \
        f"{int((a.color != b.color).any(axis=-1).sum())} pixels differ in colour"


scenes = dict(
    seed=st.integers(0, 2 ** 32 - 1), size=st.sampled_from(SIZES),
    count=st.integers(1, 400), tile=st.sampled_from([8, 16, 64]),
    bits=st.sampled_from([8, 4, 0]), n_planes=st.integers(0, 2), alpha_test=st.booleans(),
    linear=st.booleans(), permuted=st.booleans(), early=st.booleans())


@pytest.mark.parametrize("kind", SHADINGS)
@settings(max_examples=25, deadline=None)
@given(**scenes)
def test_fused_draws_what_the_steps_draw(kind, seed, size, count, tile, bits, n_planes,
                                         alpha_test, linear, permuted, early):
    scene = random_scene(seed, size, count)
    rng = np.random.default_rng(seed + 2)
    planes = rng.normal(0.0, 1.0, (n_planes, 4)) * [1.0, 1.0, 0.0, 0.0]
    planes[:, 3] = -(planes[:, :2] * rng.uniform(0, size, (n_planes, 2))).sum(axis=1)
    ids = rng.permutation(count) if permuted else None  # depth ties go to the lower id
    shading = shading_of(kind, seed, alpha_test, linear)
    kw = dict(clip_planes=planes, ids=ids)
    steps, steps_stats = draw(scene, size, shading, RasterOptions(
        fused=False, tile=tile, subpixel_bits=bits, session=97, early_depth=early), **kw)
    fused, fused_stats = draw(scene, size, shading, RasterOptions(
        tile=tile, subpixel_bits=bits, early_depth=early), **kw)
    assert_same(fused, steps)
    assert fused_stats.kept == steps_stats.kept


@settings(max_examples=30, deadline=None)
@given(kind=st.sampled_from(SHADINGS), **scenes)
def test_fused_image_does_not_depend_on_the_thread_count(kind, seed, size, count, tile, bits,
                                                         n_planes, alpha_test, linear,
                                                         permuted, early):
    if numba.config.NUMBA_NUM_THREADS < 2:
        pytest.skip("needs 2 numba threads")
    scene = random_scene(seed, size, count)
    shading = shading_of(kind, seed, alpha_test, linear)
    frames = []
    before = numba.get_num_threads()
    try:
        for threads in (1, 2):
            numba.set_num_threads(threads)
            frame, stats = draw(scene, size, shading, RasterOptions(
                threads=threads, tile=tile, subpixel_bits=bits, early_depth=early))
            assert stats.threads == threads
            frames.append(frame)
    finally:
        numba.set_num_threads(before)
    assert_same(frames[0], frames[1])


@settings(max_examples=20, deadline=None)
@given(seed=st.integers(0, 2 ** 32 - 1), size=st.sampled_from(SIZES),
       kind=st.sampled_from(SHADINGS))
def test_fused_draws_on_top_of_a_frame_as_the_steps_do(seed, size, kind):
    # the depth already in the frame starts the hierarchical rejection of hidden triangles
    first, second = random_scene(seed, size, 150), random_scene(seed + 7, size, 150)
    shading = shading_of(kind, seed, True, False)
    under, _ = draw(first, size, shading, RasterOptions(fused=False))
    frames = []
    for fused in (False, True):
        frame = Frame(under.color.copy(), under.depth.copy(), under.triangle.copy())
        draw(second, size, shading, RasterOptions(fused=fused), frame=frame,
             ids=np.arange(150, 300))
        frames.append(frame)
    assert_same(frames[1], frames[0])


@pytest.mark.parametrize("kind", ["flat", "pixel_color", "element_color"])
def test_fused_sessions_draw_what_one_session_draws(monkeypatch, kind):
    size = (97, 61)
    scene = random_scene(11, size, 400)
    shading = shading_of(kind, 11, True, True)
    ids = np.random.default_rng(5).permutation(400)
    whole, stats = draw(scene, size, shading, RasterOptions(), ids=ids)
    assert stats.sessions == 1
    monkeypatch.setattr(fused_module, "SESSION", 53)
    parts, stats = draw(scene, size, shading, RasterOptions(), ids=ids)
    assert stats.sessions == 8
    assert_same(parts, whole)


def test_hidden_triangles_are_rejected_before_their_coverage():
    size = (128, 96)
    rng = np.random.default_rng(3)
    front = [[-1.0, -1.0, 0.2], [400.0, -1.0, 0.2], [-1.0, 400.0, 0.2]]
    behind = np.c_[rng.uniform(0, 128, (600, 2)), rng.uniform(0.25, 0.9, 600)]
    pts = np.r_[front, behind]
    tris = np.r_[[[0, 1, 2]], 3 + np.arange(600).reshape(-1, 3)]
    kw = dict(shading=Shading("flat"))
    fused, stats = render(pts, tris, np.eye(4), pixel_projection(*size), size,
                          options=RasterOptions(tile=32), **kw)
    steps, _ = render(pts, tris, np.eye(4), pixel_projection(*size), size,
                      options=RasterOptions(fused=False, tile=32), **kw)
    assert_same(fused, steps)
    assert (fused.triangle == 0).all()
    # only the front triangle's fragments are generated: those behind it never reach coverage
    assert stats.fragments == size[0] * size[1]


@pytest.fixture(scope="module")
def panels():
    return crash_sequence(stamped_panels(600, seed=1), steps=4)


PATH_CASES = [
    ("position", {}),
    ("flat", {}),
    ("gouraud", {}),
    ("vertex_color", dict(field="displacement", bands=7, step=3)),
    ("pixel_color", dict(field="displacement", step=2)),
    ("pixel_color", dict(field="displacement", bands=5, step=3, hide_range=(100.0, 200.0))),
    ("element_color", dict(field="plastic_strain", bands=6, step=3)),
    ("flat", dict(step=3, magnification=2.5, clip_planes=((0.0, 1.0, 0.2, -50.0),))),
    ("pixel_color", dict(field="thickness", step=1, magnification=4.0,
                         clip_planes=((1.0, 0.0, 0.0, -300.0), (0.2, -1.0, 0.3, 300.0)))),
]


@pytest.mark.parametrize("name,style", PATH_CASES)
@pytest.mark.parametrize("view", [(30.0, 25.0), (0.0, 90.0)])
def test_software_paths_draw_the_same_image_fused(panels, name, style, view):
    size = (160, 120)
    camera = default_camera(panels, size, view=view)
    frames = []
    for fused in (False, True):
        backend = SoftwareRasterizer(RasterOptions(fused=fused, tile=16))
        with prepared(backend, panels, name, Style(**style), camera, size) as ready:
            ready.path.draw()
            frames.append(ready.path.target.frame)
    assert (frames[0].triangle >= 0).sum() > 0.05 * size[0] * size[1]
    assert_same(frames[1], frames[0])


def test_fused_is_the_default_of_the_half_space_generator():
    assert RasterOptions().fused and RasterOptions().generator == "halfspace"
