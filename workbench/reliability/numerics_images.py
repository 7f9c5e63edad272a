"""The image checks of the numerical stress suite (:mod:`workbench.reliability.numerics`):

e. **rasterizer coverage** (:func:`workbench.algo.softraster.render`, fused and by steps):
   closed fans of about 1 000 thin triangles and the front faces of a closed convex mesh,
   whose model coordinates its float32 transform maps exactly, against the exact rule of
   :mod:`workbench.algo.softraster.rule` (:mod:`~workbench.reliability.exact_planar`: exact
   window coordinates, snapping with halves to even, top-left ties). Two promises: every
   pixel centre strictly inside a fan's outline, or covered by any face of the closed mesh, is
   covered by exactly one of its (front) triangles ("exactly once", a property of the rule);
   and the rasterizer covers exactly the pixels the rule says, with the triangle it says (its
   triangle index image, and its fragment count against the exact total, back faces too).
f. **GL against software images** (:func:`workbench.measurement.rows` on the EGL context and
   on :class:`~workbench.paths.SoftwareRasterizer`) of the fan, the closed mesh, a sliver sheet
   and a sliver sheet 1e7 away, from two views: the share of differing pixels at most the
   tolerances of tests/paths/test_software_path.py (0 for ``position`` on llvmpipe, 0.5 % for the
   shaded paths, here counting the pixels off by more than 1/255: the sliver sheets' sloped
   faces put up to 2.3 % of the pixels one level apart in one channel, the rounding of the
   interpolated light; the note gives that share).

h. **fields through the colour paths** (``vertex_color``, ``pixel_color``, ``element_color``,
   GL and software, the sheet facing the camera so that the headlight is 1): constant fields
   (0, ±1e-30, 3.7, 2^60, −1e30) take the scale's first colour; values exactly on band
   boundaries (dyadic, and float64 boundaries of non-dyadic ranges with their neighbours) take
   the colour of the band the documented rule gives (:meth:`ColorScale.evaluate`, the CPU
   twin of the texture; for dyadic boundaries also the exact band ``min(⌊t·n⌋, n − 1)``);
   values spanning ±1e-30…1e30 take ``evaluate``'s colour; the twin itself gives a finite
   colour for every finite value; every pixel of every image (NaN fields too) is the
   background, a lit scale colour or the lit no-result colour (no garbage from a NaN). And
   the no-result check (:func:`check_no_result`): 0 pixels of a scale colour in the regions
   whose value is missing (triangles with a non-finite node value, elements with a non-finite
   value) or within 2 px of the triangles whose values are all missing, GL and software,
   counted by :func:`workbench.paths.colormap.scale_colour_pixels`.
"""

from __future__ import annotations

import math

import numpy as np

from .exact_planar import coverage, snap_exact, strictly_inside, window_exact
from .numerics_cases import case_rng
from .numerics_scenes import (
    RASTER_KINDS,
    RASTER_SIZE,
    RASTER_VIEW,
    SCENE_KINDS,
    field_sheet,
    nan_sheet,
    raster_projection,
    raster_scene,
    scene_mesh,
)

IMAGE_SIZE = (96, 72)
SHADED_LIMIT = 0.005  # tests/paths/test_software_path.py: shaded paths within 0.5 % of the pixels
SHADED_STEP = 1  # … counting pixels off by more than this (1/255: the rounding of the light)
COLOUR_TOLERANCE = 3  # in 1/255: texture filtering and interpolation (colormap notes)
RIM_K = 2  # pixels around a missing region where no scale colour may be
NODE_PATHS = ("vertex_color", "pixel_color")


def deliver(image: np.ndarray, region: np.ndarray, scale) -> np.ndarray:
    """The image the no-result check counts (the image itself; a fault test replaces this
    to paint into it, :func:`workbench.reliability.faults.painted_nan_rim`)."""
    return image


# --------------------------------------------------------------------------- e.
def check_coverage(report, count: int, seed: int) -> None:
    """Check e over ``count`` scenes of every raster generator."""
    from ..algo.softraster import RasterOptions, Shading, render

    size, proj = RASTER_SIZE, raster_projection()
    options = {"fused": RasterOptions(early_depth=False),
               "steps": RasterOptions(fused=False, early_depth=False)}
    for kind in RASTER_KINDS:
        once = report.row("e. exactly once", kind, "px")
        row = report.row("e. coverage", kind, "px wrong")
        pixels = 0
        for i in range(count):
            positions, triangles, ring, label = raster_scene(kind, case_rng(seed, f"raster/{kind}",
                                                                            i))
            fixed = snap_exact(window_exact(positions, proj @ RASTER_VIEW, size), size[1])
            count_all, _, sign = coverage(fixed[triangles], size)
            front = sign < 0 if ring is None else np.ones(len(triangles), bool)
            drawn = triangles[front]
            count_front, first, _ = coverage(fixed[drawn], size)
            if ring is None:
                inside = count_all > 0
            else:
                outline = snap_exact(window_exact(np.c_[ring, np.zeros(len(ring))],
                                                  proj @ RASTER_VIEW, size), size[1])
                inside = strictly_inside(outline, size)
            bad = int((count_front[inside] != 1).sum() + (count_front > 1).sum())
            once.record(bad, bad == 0, f"#{i} ({label}): {bad} pixel centres not covered "
                        f"exactly once")
            for name, option in options.items():
                frame, stats = render(positions, drawn, RASTER_VIEW, proj, size,
                                      Shading("constant"), option)
                wrong = int((frame.triangle != first).sum())
                extra = abs(int(stats.fragments) - int(count_front.sum()))
                pixels += frame.triangle.size
                row.record(wrong + extra, wrong == 0 and extra == 0,
                           f"#{i} {name} ({label}): {wrong} pixels show another triangle, "
                           f"{stats.fragments} fragments for {count_front.sum()} covered")
                if ring is None:  # every face: back faces add their own coverage
                    _, stats = render(positions, triangles, RASTER_VIEW, proj, size,
                                      Shading("constant"), option)
                    extra = abs(int(stats.fragments) - int(count_all.sum()))
                    row.record(extra, extra == 0, f"#{i} {name} all faces ({label}): "
                               f"{stats.fragments} fragments for {count_all.sum()} covered")
        row.note = f"{pixels} pixels compared"
        once.note = "centres inside the outline"


# --------------------------------------------------------------------------- shared
_CONTEXT: dict = {}


def gl_context(gl: bool = True):
    """(context, renderer name) of one EGL context for the suite, or (None, why not)."""
    if not gl:
        return None, "not asked for (--no-gl)"
    if "ctx" not in _CONTEXT:
        from ..gl import GLUnavailable, create_context, renderer

        try:
            ctx = create_context()
            _CONTEXT["ctx"] = (ctx, renderer(ctx))
        except GLUnavailable as exc:
            _CONTEXT["ctx"] = (None, f"no GL context: {exc}")
    return _CONTEXT["ctx"]


def _image(backend, mesh, name, style, camera, size=IMAGE_SIZE) -> np.ndarray:
    from ..measurement.rows import measure

    return measure(backend, mesh, name, style, camera=camera, size=size, timed=False).image


# --------------------------------------------------------------------------- f.
def check_gl_against_software(report, seed: int, gl: bool = True) -> None:
    """Check f: every scene generator once, four paths, two views."""
    from ..measurement.rows import default_camera
    from ..paths import SoftwareRasterizer, Style

    ctx, renderer = gl_context(gl)
    software = SoftwareRasterizer()
    paths = (("position", Style()), ("gouraud", Style()),
             ("pixel_color", Style(field="f", bands=6)), ("vertex_color", Style(field="f")))
    for kind in SCENE_KINDS:
        row = report.row("f. GL vs software", kind, "% px differ")
        raw = 0.0
        if ctx is None:
            row.skip(renderer)
            continue
        mesh, label = scene_mesh(kind, case_rng(seed, f"scene/{kind}", 0))
        for view in ((30.0, 25.0), (0.0, 90.0)):
            camera = default_camera(mesh, IMAGE_SIZE, view=view)
            for name, style in paths:
                a = _image(ctx, mesh, name, style, camera).astype(np.int64)
                b = _image(software, mesh, name, style, camera).astype(np.int64)
                step = np.abs(a - b).max(axis=-1)
                exact = name == "position" and "llvmpipe" in renderer
                share = float((step > (0 if exact else SHADED_STEP)).mean())
                raw = max(raw, float((step > 0).mean()))
                limit = 0.0 if exact else SHADED_LIMIT
                row.record(100 * share, share <= limit, f"{name} view {view} ({label}): "
                           f"{100 * share:.2f} % of the pixels differ (limit {100 * limit:g} %)")
        row.note = (f"limit 0 (position, llvmpipe), 0.5 % > 1/255; any difference: up to "
                    f"{100 * raw:.2f} %")


# --------------------------------------------------------------------------- h.
def _top_camera(lo, hi, size=IMAGE_SIZE):
    """An orthographic camera looking down −z at the box lo–hi (x right, y up)."""
    from ..gl.camera import Camera

    lo, hi = np.asarray(lo, np.float64), np.asarray(hi, np.float64)
    centre, extent = (lo + hi) / 2, float(np.max(hi - lo))
    aspect = size[0] / size[1]
    half = 0.55 * max(hi[1] - lo[1], (hi[0] - lo[0]) / aspect)
    return Camera(origin=centre, eye=np.array([0.0, 0.0, 4.0 * extent]), target=np.zeros(3),
                  up=np.array([0.0, 1.0, 0.0]), half_height=half, aspect=aspect,
                  near=2.0 * extent, far=6.0 * extent)


def _scale(mesh, style):
    from ..paths.colormap import scale_for

    return scale_for(mesh, style.field, style.colormap, style.value_range, style.bands,
                     style.hide_range)


def _colour_mask(image, scale) -> np.ndarray:
    """Pixels holding a lit colour of ``scale`` (the colormap module's checker where it has
    one, else the same test here)."""
    from ..paths import colormap

    if hasattr(colormap, "scale_colour_mask"):
        return colormap.scale_colour_mask(image, scale, tolerance=COLOUR_TOLERANCE)
    return _lit_match(image, scale.texture_data()[:, :3])


def _lit_match(image, colours) -> np.ndarray:
    px = image[..., :3].reshape(-1, 3).astype(np.float64)
    found = np.zeros(len(px), bool)
    for c in np.unique(np.asarray(colours, np.float64).reshape(-1, 3), axis=0):
        cc = float(c @ c)
        f = np.clip(px @ c / cc, 0.25, 1.0) if cc > 0 else np.full(len(px), 0.25)
        found |= np.abs(px - np.rint(f[:, None] * c)).max(axis=1) <= COLOUR_TOLERANCE
    return found.reshape(image.shape[:2])


def _no_result_colours() -> np.ndarray:
    from ..paths import colormap

    colours = [np.asarray(getattr(colormap, "NO_RESULT_COLOR", (0.75, 0.75, 0.78))) * 255]
    return np.array(colours)


def _garbage(image, scale) -> int:
    """Pixels that are neither background, nor a lit scale colour, nor the lit no-result
    colour."""
    background = (image[..., :3] == 255).all(axis=-1)
    known = background | _colour_mask(image, scale) | _lit_match(image, _no_result_colours())
    return int((~known).sum())


def _patch_pixels(camera, corners, size=IMAGE_SIZE):
    """Per patch (Q, 4, 3 corners), the (rows, columns) of the pixel centres at least 1 px
    inside its projection."""
    out = []
    for quad in corners:
        w = camera.project(quad, size)
        x0, x1 = w[:, 0].min() + 1.0, w[:, 0].max() - 1.0
        y0, y1 = w[:, 1].min() + 1.0, w[:, 1].max() - 1.0
        cols = np.arange(math.ceil(x0 - 0.5), math.floor(x1 - 0.5) + 1)
        rows = np.arange(math.ceil(y0 - 0.5), math.floor(y1 - 0.5) + 1)
        out.append(np.ix_(rows, cols))
    return out


def _field_cases(rng):
    """(case, values, Style keywords, exact band per value or None) of the colour checks."""
    from ..paths.colormap import ColorScale

    cases = []
    for k, v in enumerate((0.0, 1e-30, -1e-30, 3.7, 2.0 ** 60, -1e30)):
        cases.append(("constant", np.full(4, v), {"bands": 5 * (k % 2)}, None))
    for n in (4, 8):
        values = np.arange(n + 1) / n
        cases.append(("band boundary", values, {"bands": n, "value_range": (0.0, 1.0)},
                      np.minimum(np.arange(n + 1), n - 1)))
    for lo, hi, n in ((0.1, 0.7, 6), (-3.3, 1.9, 7), (1e-7, 3e-7, 5)):
        edges = lo + np.arange(n + 1) * ((hi - lo) / n)
        values = np.concatenate([edges, np.nextafter(edges, np.inf),
                                 np.nextafter(edges, -np.inf)])
        cases.append(("band boundary", values, {"bands": n, "value_range": (lo, hi)}, None))
    for bands in (0, 7):
        mags = 10.0 ** rng.uniform(-30, 30, 14)
        values = np.concatenate([mags * rng.choice((-1, 1), 14), [0.0, 1e-30, 1e30, -1e30]])
        cases.append(("1e-30..1e30", values, {"bands": bands}, None))
    ColorScale()  # the module is importable: the colormap exists
    return cases


def uploaded(scale, values) -> np.ndarray:
    """The normalised values the paths upload for ``values``: ``scale.normalise`` in float64,
    rounded to float32 (colormap notes), as float64."""
    return scale.normalise(values).astype(np.float32).astype(np.float64)


def drawn_colours(scale, values) -> np.ndarray:
    """(..., 4) RGBA in [0, 1] that the texture returns for ``values`` by the documented
    arithmetic of the paths (colormap notes): t normalised in float64 and uploaded as float32,
    ``s = t·scale + offset`` and, for bands, the nearest texel ``⌊s·n⌋`` (clamped), both
    products in float32 as the shader and the texture unit compute them; smooth scales as
    :meth:`ColorScale.lookup` of the uploaded t."""
    t32 = scale.normalise(values).astype(np.float32)
    if not scale.bands:
        return scale.lookup(t32.astype(np.float64))
    a, b = (np.float32(v) for v in scale.coord_transform)
    s = t32 * a + b
    k = np.clip(np.floor(s * np.float32(scale.bands)), 0, scale.bands - 1).astype(np.int64)
    return scale.texture_data()[k].astype(np.float64) / 255.0


def _check_twin(row, values, scale, twin, expected, keywords) -> None:
    """The CPU twin (:meth:`ColorScale.evaluate`) against the band the paths draw
    (:func:`drawn_colours`)."""
    texels = scale.texture_data()[:, :3].astype(np.float64)

    def band(rgb):
        return int(np.abs(texels - np.rint(rgb[:3] * 255)).max(axis=1).argmin())

    for v, a, b in zip(values, twin, expected):
        off = abs(band(a) - band(b))
        row.record(off, off == 0, f"{keywords}: value {float(v)!r} (t = "
                   f"{float(scale.normalise(v))!r}, uploaded {float(uploaded(scale, [v])[0])!r}"
                   f"): ColorScale.evaluate gives band "
                   f"{band(a)}, the paths draw band {band(b)}")


def check_fields(report, seed: int, gl: bool = True) -> None:
    """Check h: the colour cases on GL and in software, and the no-result regions."""
    from ..paths import SoftwareRasterizer, Style

    ctx, renderer = gl_context(gl)
    backends = {"software": SoftwareRasterizer()}
    if ctx is not None:
        backends["GL"] = ctx
    rng = case_rng(seed, "fields", 0)
    rows = {}
    twins = report.row("h. CPU twin", "band boundary", "bands off")
    for case, values, keywords, exact_band in _field_cases(rng):
        row = rows.get(case) or rows.setdefault(case, report.row("h. field colour", case,
                                                                 "/255 off"))
        mesh, corners = field_sheet(values)
        camera = _top_camera(corners.reshape(-1, 3).min(0), corners.reshape(-1, 3).max(0))
        patches = _patch_pixels(camera, corners)
        for name in (*NODE_PATHS, "element_color"):
            style = Style(field="e" if name == "element_color" else "v", **keywords)
            scale = _scale(mesh, style)
            twin = scale.evaluate(values)
            expected = drawn_colours(scale, values)
            if not np.isfinite(twin).all():
                row.record(math.inf, False, f"{name} {keywords}: ColorScale.evaluate gives "
                           f"a non-finite colour for finite values")
                continue
            if name == "element_color" and scale.bands:
                _check_twin(twins, values, scale, twin, expected, keywords)
            if exact_band is not None:
                rule = scale.texture_data()[exact_band, :3].astype(np.float64)
                twin = np.rint(expected[:, :3] * 255)
                off = np.abs(rule - twin).max(axis=1)
                for q in np.flatnonzero(off > 0):
                    row.record(off[q], False, f"{keywords}: value {float(values[q])!r} in band "
                               f"{exact_band[q]} by the exact rule, ColorScale.evaluate gives "
                               f"another colour")
            for backend_name, backend in backends.items():
                image = _image(backend, mesh, name, style, camera)
                junk = _garbage(image, scale)
                if junk:
                    row.record(math.inf, False, f"{backend_name} {name} {keywords}: {junk} "
                               f"pixels of no scale colour")
                for q, where in enumerate(patches):
                    got = image[where][..., :3].reshape(-1, 3).astype(np.float64)
                    want = np.rint(expected[q, :3] * 255)
                    off = float(np.abs(got - want).max()) if len(got) else 0.0
                    row.record(off, off <= COLOUR_TOLERANCE,
                               f"{backend_name} {name} {keywords}: value "
                               f"{float(values[q])!r} drawn "
                               f"{got[np.abs(got - want).max(axis=1).argmax()].astype(int)}, "
                               f"the rule says {want.astype(int)}")
    for row in rows.values():
        row.note = ", ".join(backends) + ("" if ctx is not None else f" ({renderer})")
    check_no_result(report, seed, gl)


def _pixels_of(mesh, triangles, camera, size=IMAGE_SIZE, shrink: int = 0) -> np.ndarray:
    """(H, W) bool: pixel centres inside the triangles ``triangles`` (a mask over the mesh's
    triangulation) by the fill rule on the camera's projection, shrunk by ``shrink`` px."""
    from scipy import ndimage

    tri = np.asarray(mesh.triangulation.triangles, np.int64)[triangles]
    w = camera.project(mesh.nodes, size)
    fixed = np.rint((w[:, :2] - 0.5) * 256).astype(np.int64)
    inside = coverage(fixed[tri], size)[0] > 0
    if shrink and inside.any():
        inside = ndimage.binary_erosion(inside, np.ones((3, 3), bool), iterations=shrink)
    return inside


def _count_scale(image, where, scale, k) -> int:
    """Pixels of a scale colour within ``k`` px of ``where`` (the colormap module's checker,
    or the same count here where it has none)."""
    from ..paths import colormap

    counter = getattr(colormap, "scale_colour_pixels", None)
    if counter is not None:
        return int(counter(image, where, scale, k, tolerance=COLOUR_TOLERANCE))
    from scipy import ndimage

    near = ndimage.binary_dilation(where, np.ones((2 * k + 1,) * 2, bool)) if k else where
    background = (image[..., :3] == 255).all(axis=-1)
    return int((near & ~background & _lit_match(image, scale.texture_data()[:, :3])).sum())


def check_no_result(report, seed: int, gl: bool = True) -> None:
    """The no-result rows of check h on a sheet with NaN / ±inf node values and NaN element
    values, GL and software: no pixel of a scale colour inside the triangles that have a
    missing value (less a 1 px border, where the float32 projection of the renderers may
    differ from this one's) nor within :data:`RIM_K` px of the triangles whose values are all
    missing (node fields; next to a missing element a neighbour has a value of its own), and
    no pixel of an unknown colour."""
    from ..paths import SoftwareRasterizer, Style

    ctx, _ = gl_context(gl)
    backends = {"software": SoftwareRasterizer()}
    if ctx is not None:
        backends["GL"] = ctx
    mesh, missing_node, missing_element = nan_sheet(case_rng(seed, "nan sheet", 0))
    nodes = mesh.nodes
    camera = _top_camera(nodes.min(0), nodes.max(0))
    tri = np.asarray(mesh.triangulation.triangles, np.int64)
    by_element = missing_element[np.asarray(mesh.triangulation.element_of)]
    for name in (*NODE_PATHS, "element_color"):
        per_element = name == "element_color"
        row = report.row("h. no-result rim", f"{'element' if per_element else 'node'} NaN, "
                         f"{name}", "px")
        region = _pixels_of(mesh, by_element if per_element else missing_node[tri].any(axis=1),
                            camera, shrink=1)
        core = (np.zeros_like(region) if per_element
                else _pixels_of(mesh, missing_node[tri].all(axis=1), camera))
        style = Style(field="e" if per_element else "v")
        scale = _scale(mesh, style)
        for backend_name, backend in backends.items():
            image = deliver(_image(backend, mesh, name, style, camera), region, scale)
            rim = _count_scale(image, region, scale, 0)
            if core.any():
                rim += _count_scale(image, core, scale, RIM_K)
            # vertex colours blend between their corners' colours: only the looked-up paths
            # must show nothing but scale colours, the no-result colour and the background
            junk = 0 if name == "vertex_color" else _garbage(image, scale)
            row.record(rim, rim == 0 and junk == 0,
                       f"{backend_name}: {rim} pixels of a scale colour in the missing region "
                       f"({int(region.sum())} px) or within {RIM_K} px of its wholly missing "
                       f"triangles, {junk} of no known colour")
        row.note = ", ".join(backends)
