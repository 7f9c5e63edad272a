"""The st2005 render paths against the exact float64 image of the same solution."""

import numpy as np
import pytest
from meshes import random_tiling
from scipy.ndimage import binary_dilation

from workbench.algo.spacetime.exact import colour_error, element_boundary, exact_image
from workbench.algo.spacetime.fields import BAR, STEEL
from workbench.algo.spacetime.poly import evaluate
from workbench.algo.spacetime.raster import PixelGrid
from workbench.gl import Camera
from workbench.measurement.images import crack_pixels
from workbench.measurement.rows import measure
from workbench.paths import PATHS, make_path
from workbench.paths.colormap import colormap_lut
from workbench.paths.spacetime import SpacetimeScene, SpacetimeStyle, spacetime_path, top_camera

U_MAX = 300.0
SIZE = 96
CELL = 5.0  # mm


def _polygons(n, offset, seed):
    """n×n cells of CELL mm, each a quad or two triangles, jittered: a tiling of a square."""
    return random_tiling(n, 0.25, seed) * CELL + offset


def _scene(n=4, offset=(0.0, 0.0), seed=0, t=3.0, moving=True, scale=1.0):
    """One element per polygon with random cubic coefficients: strains ~1e-3, U up to ~U_MAX."""
    corners = _polygons(n, np.asarray(offset, np.float64), seed)
    P = len(corners)
    rng = np.random.default_rng(seed + 1)
    centre = np.c_[corners.mean(axis=1), np.full(P, t + 0.4)]
    extent = np.c_[np.ptp(corners, axis=1) * 1.1, np.full(P, 2.0)]
    coeffs = rng.normal(scale=3e-3 * scale, size=(P, 20, 2))
    if not moving:  # no monomial with t: zero velocity, a flat height field
        from workbench.algo.spacetime.poly import EXPONENTS
        coeffs[:, EXPONENTS[:, 2] > 0] = 0.0
    return SpacetimeScene(corners, np.arange(P), coeffs, centre, extent, STEEL.lam, STEEL.mu, t=t)


def _render(ctx, scene, style, camera, size, background=(1.0, 1.0, 1.0, 1.0)):
    """(H, W, 4) uint8 image of one untimed draw of the path for ``style.shading``."""
    return measure(ctx, scene, spacetime_path(style), camera=camera, size=size,
                   background=background, timed=False).image


def _exact(scene, grid, lighting=True, height_scale=20.0):
    return exact_image(scene.corners, scene.element, scene.coeffs, scene.centre, scene.extent,
                       STEEL if scene.t is not None else BAR, grid, t=scene.t, U_max=U_MAX,
                       table=colormap_lut("inferno"), height_scale=height_scale, lighting=lighting)


def _top(ctx, scene, shading, *, origin=None, lighting=True, height_scale=20.0, overdraw="none"):
    grid = PixelGrid.fit(*scene.bounds(), SIZE)
    o = None if origin is None else np.asarray(origin, np.float64)
    camera = top_camera(grid, (-1.0, 50.0), origin=o)
    style = SpacetimeStyle(shading=shading, U_max=U_MAX, height_scale=height_scale,
                           lighting=lighting, edge_overdraw=overdraw)
    return _render(ctx, scene, style, camera, (grid.width, grid.height)), grid


def _inner_error(image, exact):
    """colour_error away from element boundaries (where either element may be shown)."""
    labels = np.where(exact.polygon >= 0, exact.polygon, -1)
    keep = exact.covered & ~element_boundary(labels)
    err = np.abs(image[..., :3].astype(float) - 255 * exact.rgb).max(axis=2)
    return err[keep]


@pytest.mark.parametrize("lighting", [True, False])
def test_per_pixel_matches_the_exact_image(ctx, lighting):
    scene = _scene()
    image, grid = _top(ctx, scene, "per_pixel", lighting=lighting)
    exact = _exact(scene, grid, lighting=lighting)
    inner = _inner_error(image, exact)
    assert inner.max() <= 1.0 + 1e-9  # within 1/255 everywhere off element boundaries
    stats = colour_error(image, exact)
    assert stats["uncovered"] == 0
    assert stats["share_over_1"] <= 0.05  # only boundary pixels may pick the neighbour


def test_per_vertex_is_visibly_wrong_on_the_same_solution(ctx):
    scene = _scene()
    image, grid = _top(ctx, scene, "per_vertex")
    exact = _exact(scene, grid)
    inner = _inner_error(image, exact)
    assert inner.max() > 8.0  # cubic fields are not linear: interpolation misses them
    assert (inner > 1.0).mean() > 0.2


def test_far_from_origin_relative_upload_keeps_the_bound_global_does_not(ctx):
    offset = np.array([5.0e4, -5.0e4])  # 10^4 element sizes away
    scene = _scene(offset=offset)
    near_image, _ = _top(ctx, _scene(), "per_pixel")
    image, grid = _top(ctx, scene, "per_pixel")
    exact = _exact(scene, grid)
    assert _inner_error(image, exact).max() <= 1.0 + 1e-9
    assert np.array_equal(image, near_image)  # relative upload: the same float32 numbers
    global_image, _ = _top(ctx, scene, "per_pixel", origin=(0.0, 0.0, 0.0))
    # global float32 coordinates round positions to 4 µm here (local coordinates to ~1e-3):
    # the bound breaks
    assert _inner_error(global_image, exact).max() > 1.2


def test_zero_velocity_and_zero_strain_give_finite_exact_colours(ctx):
    for scene in (_scene(moving=False), _scene(scale=0.0)):
        image, grid = _top(ctx, scene, "per_pixel")
        exact = _exact(scene, grid)
        assert np.isfinite(exact.rgb).all()
        assert _inner_error(image, exact).max() <= 1.0 + 1e-9
        vertex, _ = _top(ctx, scene, "per_vertex")
        assert colour_error(vertex, exact)["uncovered"] == 0


def test_bar_spacetime_triangles(ctx):
    scene = _scene(t=3.0)
    # reuse the polygons as (x, t) triangles of a bar: centre/extent in (x, 0, t)
    corners = scene.corners
    centre = np.c_[scene.centre[:, 0], np.zeros(len(corners)), scene.centre[:, 1]]
    extent = np.c_[scene.extent[:, 0], np.ones(len(corners)), scene.extent[:, 1]]
    bar = SpacetimeScene(corners, scene.element, scene.coeffs, centre, extent, BAR.lam, BAR.mu,
                         t=None)
    for shading in ("per_pixel", "per_vertex"):
        image, grid = _top(ctx, bar, shading)
        exact = _exact(bar, grid, lighting=False)
        inner = _inner_error(image, exact)
        if shading == "per_pixel":
            assert inner.max() <= 1.0 + 1e-9
        else:
            assert inner.max() > 4.0


def test_edge_overdraw_closes_the_cracks_between_discontinuous_elements(ctx):
    scene = _scene(n=6, seed=3)
    lo, hi = scene.bounds()
    speed = evaluate(scene.coeffs, scene.centre, scene.extent, np.repeat(scene.element, 4),
                     scene.corners[..., 0].ravel(), scene.corners[..., 1].ravel(), scene.t)["speed"]
    top = 40.0 * speed.max()
    camera = Camera.fit_box(np.r_[lo, 0.0], np.r_[hi, top], azimuth=20, elevation=35,
                            projection="perspective", up="z")
    size = (160, 120)
    background = (0.0, 1.0, 0.0, 1.0)
    counts = {}
    for overdraw in ("none", "over", "behind"):
        style = SpacetimeStyle(shading="per_pixel", U_max=U_MAX, height_scale=40.0,
                               edge_overdraw=overdraw)
        image = _render(ctx, scene, style, camera, size, background)
        counts[overdraw] = int(crack_pixels(image, background).sum())
    assert counts["none"] > 20  # independent per-element heights tear the surface apart
    assert counts["over"] == 0
    assert counts["behind"] == 0


def test_overdraw_behind_the_fill_leaves_the_polygons_pixels_exact(ctx):
    scene = _scene(n=6, seed=3)
    images = {mode: _top(ctx, scene, "per_pixel", overdraw=mode)[0]
              for mode in ("none", "over", "behind")}
    grid = PixelGrid.fit(*scene.bounds(), SIZE)
    exact = _exact(scene, grid)
    share = {mode: colour_error(image, exact)["share_over_1"] for mode, image in images.items()}
    # lines on top paint half a pixel of the neighbour with their own element's colour
    assert share["over"] > share["none"] + 0.01
    # lines behind the fill show only where no polygon covers the pixel: in the top view the
    # polygons tile the square, so inside it the image is the one without lines; outside,
    # the boundary lines reach at most a pixel beyond the outline
    covered = exact.covered
    assert np.array_equal(images["behind"][covered], images["none"][covered])
    outside = (images["behind"] != images["none"]).any(axis=2) & ~covered
    assert not (outside & ~binary_dilation(covered, iterations=1)).any()


def test_scene_and_style_refusals():
    scene = _scene()
    with pytest.raises(ValueError):
        SpacetimeStyle(shading="per_face")
    with pytest.raises(ValueError):
        SpacetimeStyle(edge_overdraw=True)
    with pytest.raises(ValueError):
        SpacetimeStyle(U_max=0.0)
    with pytest.raises(ValueError, match="element_store"):
        SpacetimeStyle(element_store="ssbo")
    with pytest.raises(ValueError, match="outer"):
        SpacetimeScene(scene.corners, scene.element, scene.coeffs, scene.centre, scene.extent,
                       STEEL.lam, STEEL.mu, t=1.0, outer=np.zeros((3, 4), bool)).check()
    bad = SpacetimeScene(scene.corners[:0], scene.element[:0], scene.coeffs, scene.centre,
                         scene.extent, STEEL.lam, STEEL.mu, t=1.0)
    with pytest.raises(ValueError, match="no polygons"):
        bad.check()
    bad = SpacetimeScene(scene.corners, scene.element + 1000, scene.coeffs, scene.centre,
                         scene.extent, STEEL.lam, STEEL.mu, t=1.0)
    with pytest.raises(ValueError):
        bad.check()
    coeffs = scene.coeffs.copy()
    coeffs[3, 5, 1] = np.nan
    bad = SpacetimeScene(scene.corners, scene.element, coeffs, scene.centre, scene.extent,
                         STEEL.lam, STEEL.mu, t=1.0)
    with pytest.raises(ValueError, match="finite"):
        bad.check()


def test_spacetime_path_is_the_registered_path_of_the_shading():
    for shading, name in (("per_vertex", "spacetime_vertex"), ("per_pixel", "spacetime_pixel")):
        path = spacetime_path(SpacetimeStyle(shading=shading, U_max=U_MAX))
        assert type(path) is PATHS[name] and path.style.shading == shading
        assert path.style.U_max == U_MAX
    # a registered path fixes its shading whatever the style says
    assert make_path("spacetime_vertex", SpacetimeStyle()).style.shading == "per_vertex"
    assert spacetime_path().name == "spacetime_pixel"


def test_overdraw_behind_keeps_the_near_and_far_planes(ctx):
    """The squeezed depth of 'behind' must not let geometry outside near/far through."""
    scene = _scene(n=6, seed=3)
    lo, hi = scene.bounds()
    mid = (lo + hi) / 2
    camera = Camera.fit_box(np.r_[mid - 4.0, 0.0], np.r_[mid + 4.0, 1.0], azimuth=20,
                            elevation=35, projection="perspective", up="z", margin=0.9)
    background = (0.0, 1.0, 0.0, 1.0)
    covered = {}
    for overdraw in ("none", "over", "behind"):
        style = SpacetimeStyle(shading="per_pixel", U_max=U_MAX, height_scale=40.0,
                               edge_overdraw=overdraw)
        image = _render(ctx, scene, style, camera, (120, 90), background)
        covered[overdraw] = (image[..., :3] != (0, 255, 0)).any(axis=2)
    assert 0.05 < covered["none"].mean() < 0.95  # near/far planes cut the plate
    assert np.array_equal(covered["behind"], covered["over"])


def _square_outer(scene):
    """(P, 4) bool: the polygon edges on the boundary of the tiled square, from geometry."""
    lo, hi = scene.bounds()
    a, b = scene.corners, np.roll(scene.corners, -1, axis=1)
    on = np.zeros(a.shape[:2], bool)
    for axis in (0, 1):
        for side in (lo[axis], hi[axis]):
            on |= (a[..., axis] == side) & (b[..., axis] == side)
    return on & ~np.all(a == b, axis=2)


def _oblique_cracks(ctx, scene, overdraw, shading="per_pixel", height_scale=40.0):
    lo, hi = scene.bounds()
    speed = evaluate(scene.coeffs, scene.centre, scene.extent, np.repeat(scene.element, 4),
                     scene.corners[..., 0].ravel(), scene.corners[..., 1].ravel(), scene.t)["speed"]
    camera = Camera.fit_box(np.r_[lo, 0.0], np.r_[hi, height_scale * speed.max()], azimuth=20,
                            elevation=35, projection="perspective", up="z")
    background = (0.0, 1.0, 0.0, 1.0)
    style = SpacetimeStyle(shading=shading, U_max=U_MAX, height_scale=height_scale,
                           edge_overdraw=overdraw)
    image = _render(ctx, scene, style, camera, (160, 120), background)
    return int(crack_pixels(image, background).sum())


@pytest.mark.parametrize("shading", ["per_pixel", "per_vertex"])
def test_skirts_close_gaps_wider_than_a_line(ctx, shading):
    """Heights that jump by many pixels between elements: one-pixel lines leave most of each
    gap open, skirts close every one of them."""
    scene = _scene(n=6, seed=3)
    scene.outer = _square_outer(scene)
    counts = {mode: _oblique_cracks(ctx, scene, mode, shading, height_scale=400.0)
              for mode in ("none", "behind", "skirts")}
    assert counts["none"] > 200
    assert counts["behind"] > 50  # the paper's lines are not enough here
    assert counts["skirts"] == 0


def test_skirts_leave_the_top_view_to_the_polygons(ctx):
    scene = _scene(n=6, seed=3)
    scene.outer = _square_outer(scene)
    behind, grid = _top(ctx, scene, "per_pixel", overdraw="behind")
    skirts, _ = _top(ctx, scene, "per_pixel", overdraw="skirts")
    assert np.array_equal(skirts, behind)  # vertical quads cover no pixel from straight above
    exact = _exact(scene, grid)
    assert _inner_error(skirts, exact).max() <= 1.0 + 1e-9


def test_edges_on_the_domain_boundary_are_not_overdrawn(ctx):
    scene = _scene(n=6, seed=3)
    none, grid = _top(ctx, scene, "per_pixel")
    covered = _exact(scene, grid).covered
    # every edge treated as shared: boundary lines reach beyond the outline
    spill = (_top(ctx, scene, "per_pixel", overdraw="over")[0] != none).any(axis=2) & ~covered
    assert spill.sum() > 10
    scene.outer = _square_outer(scene)
    assert scene.outer.sum() == 4 * 6
    # the points where inner edges meet the boundary: the 4 × 5 grid nodes on the sides
    lo, hi = scene.bounds()
    a = scene.corners
    inner_ends = {tuple(p) for p in a[~scene.outer].reshape(-1, 2).tolist()
                  if p[0] in (lo[0], hi[0]) or p[1] in (lo[1], hi[1])}
    assert len(inner_ends) >= 4 * 5
    for mode in ("over", "behind", "skirts"):
        image, _ = _top(ctx, scene, "per_pixel", overdraw=mode)
        changed = (image != none).any(axis=2) & ~covered
        # only the last pixel of an inner edge that ends on the boundary may lie beyond it
        assert changed.sum() <= len(inner_ends) < spill.sum() / 10


@pytest.mark.parametrize("shading", ["per_pixel", "per_vertex"])
def test_buffer_and_texture_stores_draw_the_same_image(ctx, shading):
    scene = _scene(n=5, seed=4)
    grid = PixelGrid.fit(*scene.bounds(), SIZE)
    camera = top_camera(grid, (-1.0, 50.0))
    images = []
    for store in ("buffer", "texture"):
        style = SpacetimeStyle(shading=shading, U_max=U_MAX, height_scale=20.0, element_store=store)
        images.append(_render(ctx, scene, style, camera, (grid.width, grid.height)))
    assert np.array_equal(images[0], images[1])  # the same float32 records, fetched two ways
    assert colour_error(images[0], _exact(scene, grid))["uncovered"] == 0


def test_texture_buffer_refusals(ctx):
    from workbench.gl.texbuffer import TextureBuffer

    with pytest.raises(ValueError, match="float32"):
        TextureBuffer(ctx, np.zeros((4, 4)))
    with pytest.raises(ValueError, match="float32"):
        TextureBuffer(ctx, np.zeros((4, 3), np.float32))
    tb = TextureBuffer(ctx, np.zeros((4, 4), np.float32))
    assert tb.nbytes == 64
    tb.release()
    tb.release()  # twice is harmless
