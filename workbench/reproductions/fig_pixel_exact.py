"""st2005: pixel-exact rendering of spacetime FE solutions, per vertex against per pixel.

Every image here has an exact answer: the solutions are least-squares cubic fits (20
monomials per element, element-local coordinates, discontinuous across elements like a DG
solution) of closed-form elastodynamic fields, and the exact image is the float64 shading of
those polynomials at the pixel centres of a top view (:mod:`workbench.algo.spacetime.exact`).
Colour is strain energy density U on the log scale s = log(U + 1)/log(U_max + 1), height the
velocity magnitude; lighting is Phong with the height field's exact normal.

Outputs in ``figures/fig_pixel_exact/``:

* ``table.md`` — per slice size (10³ … 10⁶ polygons; 10³ … 10⁵ with ``--quick``):
  tetrahedra, polygons, per-frame slicing time, then for each path (per vertex, per pixel)
  without edge overdraw, with the paper's line overdraw ("over"), with lines behind the fill
  ("behind") and with lines and skirts behind it ("skirts"), element records in a buffer
  texture, and once more without overdraw from the paper's 2-D texture rectangle ("texture"): the
  time to upload the slice (``prepare_ms``, program linking included), GPU and wall ms per frame,
  max and mean colour error against the exact image (1/255), the share of covered pixels over
  1/255 — all of them, and those whose centre is more than 0.01 px from an element edge (closer,
  the rasteriser's sub-pixel precision may pick the neighbouring element) with their max error —
  and crack pixels (background enclosed by the surface) in an oblique perspective view;
* ``slicing.md`` — incremental slicing of a spacetime mesh of ~10⁶ tetrahedra (10⁵ quick) as t
  advances, with and without the domain-boundary edges, against slicing every tetrahedron from
  scratch;
* ``sweep.md``, ``sweep.png`` — error and time against the quadrisection threshold and the mesh
  resolution (run time against error), with crack pixels for lines and for skirts;
* ``stability.md`` — the domain 10⁴ element sizes from the origin (relative against global
  float32 coordinates, on the GPU and in a float32 emulation), zero velocity and zero strain,
  slices through a flat front and through a vertex;
* ``fig3_bar.png`` (the 1-D bar fixed at one end, its whole (x, t) spacetime),
  ``fig5_slice.png`` (a slice: per vertex, per pixel, exact, both error maps),
  ``fig5_crop.png`` (a closer look at a quarter of it), ``fig5_colorbar.png`` (the per-pixel
  slice with its colour bar), ``fig4_cracks.png`` (oblique views of slices of 10³, 10⁴ and 10⁵
  polygons: raw polygons, lines over and behind the fill, lines with quadrisection, skirts) and
  ``fig8_height.png`` (the height field, per vertex against per pixel).

The tiny size (the tests' check of every table's shape) draws slices of 10³ polygons 160 px
wide, with a sweep of two thresholds and two resolutions and a coarser stability mesh.

Run: ``workbench run fig_pixel_exact [--quick]``.
"""

from __future__ import annotations

import time

import numpy as np

from workbench.algo.spacetime.exact import colour_error, edge_distance, exact_image
from workbench.algo.spacetime.fields import BAR, STEEL, RadialPulse
from workbench.algo.spacetime.mesh import front_refined, rect_triangulation
from workbench.algo.spacetime.poly import (
    evaluate_float32_global,
    evaluate_float32_local,
    speed,
)
from workbench.algo.spacetime.raster import PixelGrid
from workbench.algo.spacetime.scene import (
    DOMAIN,
    PULSE,
    T_SLICE,
    Solution,
    SpacetimeScene,
    bar_scene,
    plate_solution,
    slice_scene,
    window,
)
from workbench.algo.spacetime.slicing import TimeSlicer, polygon_areas, quadrisect, slice_at
from workbench.experiment.context import ExperimentContext
from workbench.experiment.registry import experiment
from workbench.gl import Camera
from workbench.measurement.images import crack_pixels
from workbench.measurement.interleave import draw_clock, interleaved_ratios
from workbench.measurement.timing import time_call
from workbench.output.figures import save_field_figure, save_image_grid
from workbench.paths.colormap import colormap_lut
from workbench.paths.drawing import prepared
from workbench.paths.spacetime import OVERDRAWS, SpacetimeStyle, spacetime_path, top_camera
from workbench.reproductions._pixel_exact_figures import plot_sweep

from ._declared.fig_pixel_exact import DECLARED

U_MAX = 100.0  # kJ/m³, top of the log colour scale
HEIGHT_SCALE = 800.0  # mm of height per mm/µs (peak speeds ~1e-2 mm/µs)
COLORMAP = "plasma"  # its dark end is blue, not black, so lighting shows everywhere
BACKGROUND = (1.0, 1.0, 1.0, 1.0)
CRACK_BACKGROUND = (0.0, 1.0, 0.0, 1.0)  # a colour the ramp never produces
EDGE_PX = 0.01  # pixel centres this close to an element edge may go to either element
# space-mesh cells per side for each target slice size (polygons per slice ≈ 6.6 n² plus the
# refinement along the front, which dominates on coarse meshes)
RESOLUTIONS = {1_000: 7, 10_000: 28, 100_000: 115, 1_000_000: 390}


def spacetime_style(shading, overdraw="none", lighting=True, store="buffer") -> SpacetimeStyle:
    """The experiment's style: its colour scale and height scale, with ``shading``
    ("per_vertex", "per_pixel"), edge ``overdraw``, ``lighting`` and element ``store``."""
    return SpacetimeStyle(shading=shading, edge_overdraw=overdraw, lighting=lighting,
                          height_scale=HEIGHT_SCALE, U_max=U_MAX, colormap=COLORMAP,
                          element_store=store)


def top_height(scene: SpacetimeScene) -> float:
    """The largest vertex height of the scene (mm)."""
    if scene.is_bar:
        return 1.0
    c = scene.corners.reshape(-1, 2)
    fastest = speed(scene.coeffs, scene.centre, scene.extent, np.repeat(scene.element, 4),
                    c[:, 0], c[:, 1], scene.t).max()
    return float(HEIGHT_SCALE * fastest) + 1e-3


class Views:
    """Spacetime scenes ``width`` pixels wide in the top view (against the exact image) and in
    an oblique perspective view (cracks), each measured through the run's context."""

    def __init__(self, exp: ExperimentContext, width: int) -> None:
        self.exp, self.width = exp, width
        self.table = colormap_lut(COLORMAP)
        self._tops: dict[int, tuple[SpacetimeScene, float]] = {}

    def top_height(self, scene: SpacetimeScene) -> float:
        """:func:`top_height` of ``scene``, once per scene (kept, so that its id stays its own)."""
        if self._tops.get(id(scene), (None,))[0] is not scene:
            self._tops[id(scene)] = (scene, top_height(scene))
        return self._tops[id(scene)][1]

    def grid(self, scene: SpacetimeScene) -> PixelGrid:
        return PixelGrid.fit(*scene.bounds(), self.width)

    def top(self, scene, style, *, time_it=False, origin=None):
        """(measurement, grid) of the top view, timed with ``time_it``; ``origin`` (3,) is the
        float64 upload origin (default the grid centre)."""
        grid = self.grid(scene)
        camera = top_camera(grid, (-1.0, self.top_height(scene) + 1.0), origin=origin)
        return self._measure(scene, style, camera, (grid.width, grid.height), BACKGROUND,
                             time_it), grid

    def oblique(self, scene, style, *, size=None):
        """(H, W, 4) uint8 image of a perspective view from 35° above the plate, on
        CRACK_BACKGROUND."""
        lo, hi = scene.bounds()
        top = self.top_height(scene)
        camera = Camera.fit_box(np.r_[lo, 0.0], np.r_[hi, top], azimuth=25, elevation=35,
                                projection="perspective", up="z", margin=0.9,
                                aspect=4 / 3, origin=np.r_[(lo + hi) / 2, 0.0])
        size = size or (self.width, self.width * 3 // 4)
        return self._measure(scene, style, camera, size, CRACK_BACKGROUND, False).image

    def _measure(self, scene, style, camera, size, background, time_it):
        return self.exp.measure(scene, spacetime_path(style), camera=camera, size=size,
                                background=background, timed=time_it)

    def exact(self, scene: SpacetimeScene, material, grid: PixelGrid, lighting=True):
        return exact_image(scene.corners, scene.element, scene.coeffs, scene.centre, scene.extent,
                           material, grid, t=scene.t, U_max=U_MAX, table=self.table,
                           height_scale=HEIGHT_SCALE, lighting=lighting and not scene.is_bar)


def error_columns(image, exact, corners, grid: PixelGrid) -> dict:
    """Colour error against the exact image (1/255): max, mean and the share of covered pixels
    over 1/255, then the same share and the max error once pixels whose centre lies within
    EDGE_PX of its element's edge are set aside — there the rasteriser's finite sub-pixel
    precision may hand the pixel to the neighbouring element, whose discontinuous solution
    differs (DG). ``uncovered``: pixels the exact image covers and the render left white."""
    stats = colour_error(image, exact)
    err = np.abs(image[..., :3].astype(np.float64) - 255.0 * exact.rgb).max(axis=2)
    bad = np.argwhere(exact.covered & (err > 1.0))
    xs, ys = grid.centres()
    d = edge_distance(corners, exact.polygon[bad[:, 0], bad[:, 1]], xs[bad[:, 1]], ys[bad[:, 0]])
    off = bad[d >= EDGE_PX * grid.dx]
    good = exact.covered & (err <= 1.0)
    worst = max(float(err[good].max()) if good.any() else 0.0,
                float(err[off[:, 0], off[:, 1]].max()) if len(off) else 0.0)
    return {"max_diff_255": stats["max"], "mean_diff_255": stats["mean"],
            "share_over_1": stats["share_over_1"],
            "share_over_1_off_edges": len(off) / stats["covered"],
            "max_diff_255_off_edges": worst,
            "uncovered": stats["uncovered"]}


def error_map(image, exact) -> np.ndarray:
    err = np.abs(image[..., :3].astype(np.float64) - 255.0 * exact.rgb).max(axis=2)
    return np.where(exact.covered, err, 0.0)


def detail_target(exp: ExperimentContext) -> int:
    """The slice size of the sweep and of ``fig5``: 10⁴ polygons (tiny 10³)."""
    return exp.pick(10_000, 10_000, 1_000)


# ---------------------------------------------------------------------------- the main table
def timed_slices(slicer: TimeSlicer, frames) -> tuple[object, list[float]]:
    """(the last slice, ms per frame) of slicing ``frames`` (µs) one after the other."""
    slice_ms = []
    for t in frames:
        start = time.perf_counter()
        s = slicer.slice(float(t))
        slice_ms.append(1e3 * (time.perf_counter() - start))
    return s, slice_ms


def size_rows(exp: ExperimentContext, views: Views) -> tuple[list[dict], dict]:
    """The main table: per slice size (10³ … 10⁶ polygons; quick up to 10⁵, tiny 10³) every
    path, overdraw and store; and per size up to 10⁵ (solution, scene, slice) for the rest."""
    rows, keep = [], {}
    targets = [t for t in RESOLUTIONS if t <= exp.pick(1_000_000, 100_000, 1_000)]
    for target in targets:
        n = RESOLUTIONS[target]
        t_lo, t_hi = window(n)
        sol = plate_solution(n, t_lo, t_hi)
        frames = np.linspace(t_lo + 0.05 * (t_hi - t_lo), T_SLICE, 9)
        s, slice_ms = timed_slices(TimeSlicer(sol.mesh, outer=True), frames)
        scene = slice_scene(sol, s)
        exp.say(f"  {target:>9} target: {sol.mesh.n_simplices} tets, {s.n_polygons} polygons, "
                f"mesh {sol.mesh_s:.1f} s, fit {sol.fit_s:.1f} s, slice "
                f"{np.median(slice_ms[1:]):.1f} ms")
        common = dict(target_polygons=target, cells=f"{n}x{n}", tets=sol.mesh.n_simplices,
                      polygons=s.n_polygons, quads=int(s.is_quad.sum()),
                      slice_ms=float(np.median(slice_ms[1:])))
        rows += path_rows(exp, views, sol, scene, common)
        if target <= 100_000:
            keep[target] = (sol, scene, s)
    # cost against the per-vertex path with the same overdraw and store (wall time)
    by = {(row["target_polygons"], row["path"], row["edge_overdraw"], row["element_store"]): row
          for row in rows}
    for row in rows:
        base = by[(row["target_polygons"], "per_vertex", row["edge_overdraw"],
                   row["element_store"])]
        row["wall_vs_per_vertex"] = row["wall_ms"] / base["wall_ms"]
    return rows, keep


def path_rows(exp: ExperimentContext, views: Views, sol: Solution, scene, common: dict):
    """The rows of one slice: both shadings with every overdraw, element records in a buffer
    texture, and once without overdraw from the paper's 2-D texture rectangle; ``common`` the
    slice's columns."""
    rows, exact = [], None
    variants = [(overdraw, "buffer") for overdraw in OVERDRAWS] + [("none", "texture")]
    for shading in ("per_vertex", "per_pixel"):
        for overdraw, store in variants:
            style = spacetime_style(shading, overdraw, store=store)
            m, grid = views.top(scene, style, time_it=True)
            if exact is None:
                exact = views.exact(scene, sol.material, grid)
            oblique = views.oblique(scene, style)
            row = dict(**common, path=shading, edge_overdraw=overdraw, element_store=store,
                       **m.timing.as_row(), prepare_ms=m.row["prepare_ms"],
                       bytes_uploaded=m.row["bytes_uploaded"],
                       **error_columns(m.image, exact, scene.corners, grid),
                       crack_pixels=int(crack_pixels(oblique, CRACK_BACKGROUND).sum()),
                       renderer=exp.renderer, size=f"{grid.width}x{grid.height}")
            rows.append(row)
            exp.say(f"    {shading:10} overdraw {overdraw:6} {store:7} wall "
                    f"{row['wall_ms']:.1f} ms, err max {row['max_diff_255']:.1f} mean "
                    f"{row['mean_diff_255']:.2f}, >1/255 {100 * row['share_over_1']:.4f} % (off "
                    f"edges {100 * row['share_over_1_off_edges']:.4f} %, max "
                    f"{row['max_diff_255_off_edges']:.2f}), cracks {row['crack_pixels']}")
    return rows


# ---------------------------------------------------------------------------------- slicing
def slicing_rows(exp: ExperimentContext) -> list[dict]:
    """Incremental slicing while t advances through a mesh of ~10⁶ (quick 10⁵, tiny ~10⁴)
    tetrahedra, with and without the domain-boundary edges, against slicing from scratch."""
    n, t_end = exp.pick((35, 10.0), (25, 6.0), (8, 3.0))
    field = RadialPulse(**PULSE)
    start = time.perf_counter()
    pts, tris = rect_triangulation(n, n, size=(DOMAIN, DOMAIN), jitter=0.25, seed=2)
    mesh = front_refined(pts, tris, t_end, STEEL.p_wave_speed, bands=4,
                         front_distance=field.front_distance, width=1.5 * DOMAIN / n)
    build_s = time.perf_counter() - start
    exp.say(f"slicing: {mesh.n_simplices} tets built in {build_s:.1f} s")
    start = time.perf_counter()
    slicer = TimeSlicer(mesh)
    sort_s = time.perf_counter() - start
    times = np.linspace(0.05 * t_end, 0.95 * t_end, exp.pick(40, 10, 5))
    inc, polys = [], []
    for t in times:
        start = time.perf_counter()
        s = slicer.slice(float(t))
        inc.append(1e3 * (time.perf_counter() - start))
        polys.append(s.n_polygons)
    # the same frames with the domain-boundary edges the edge overdraw leaves out
    start = time.perf_counter()
    _ = mesh.shared_facets  # derived once per mesh
    facets_s = time.perf_counter() - start
    _, inc_outer = timed_slices(TimeSlicer(mesh, outer=True), times)
    brute = [time_call(lambda t=t: slice_at(mesh, float(t)), warmup=0, repeat=5).wall_ms
             for t in times[:: max(1, len(times) // 5)]]
    area = float(polygon_areas(s).sum())
    row = {"tets": mesh.n_simplices, "build_s": build_s, "sort_s": sort_s, "frames": len(times),
           "polygons_median": int(np.median(polys)), "polygons_max": int(max(polys)),
           "incremental_ms_median": float(np.median(inc[1:])),
           "incremental_ms_max": float(max(inc[1:])),
           "first_frame_ms": inc[0], "shared_facets_s": facets_s,
           "with_outer_ms_median": float(np.median(inc_outer[1:])),
           "brute_force_ms_median": float(np.median(brute)),
           "speedup": float(np.median(brute) / np.median(inc[1:])),
           "last_slice_area_error": abs(area - DOMAIN * DOMAIN) / (DOMAIN * DOMAIN)}
    exp.say(f"  incremental {row['incremental_ms_median']:.1f} ms/frame (max "
            f"{row['incremental_ms_max']:.1f}, {row['with_outer_ms_median']:.1f} with boundary "
            f"edges), brute force {row['brute_force_ms_median']:.1f} ms, "
            f"{row['polygons_median']} polygons")
    return [row]


# ------------------------------------------------------------------------------------ sweep
def quadrisection_rows(exp: ExperimentContext, views: Views, keep: dict) -> list[dict]:
    """Error, time and cracks of the detail slice quadrisected down to a share of its mean
    polygon area (none, 2 … 1/8; quick 1 … 1/4, tiny 1)."""
    rows = []
    sol, _, s = keep[detail_target(exp)]
    mean_area = float(polygon_areas(s).mean())
    factors = exp.pick((None, 2.0, 1.0, 0.5, 0.25, 0.125), (None, 1.0, 0.5, 0.25), (None, 1.0))
    exact = None
    for factor in factors:
        threshold = np.inf if factor is None else factor * mean_area
        q = s if factor is None else quadrisect(s, threshold)
        qs = slice_scene(sol, q)
        for shading in ("per_vertex", "per_pixel"):
            m, grid = views.top(qs, spacetime_style(shading, "behind"), time_it=True)
            if exact is None:  # children show their parent's element: one exact image for all
                exact = views.exact(slice_scene(sol, s), sol.material, grid)
            oblique = views.oblique(qs, spacetime_style(shading, "behind"))
            skirted = views.oblique(qs, spacetime_style(shading, "skirts"))
            rows.append(dict(sweep="quadrisection", cells=sol.label,
                             threshold_mm2=None if factor is None else threshold,
                             threshold_vs_mean_area=factor, polygons=q.n_polygons, path=shading,
                             wall_ms=m.timing.wall_ms, gpu_ms=m.timing.gpu_ms,
                             **error_columns(m.image, exact, s.corners, grid),
                             crack_pixels=int(crack_pixels(oblique, CRACK_BACKGROUND).sum()),
                             crack_pixels_skirts=int(crack_pixels(skirted, CRACK_BACKGROUND).sum()),
                             renderer=exp.renderer))
        exp.say(f"  quadrisection {factor}: {q.n_polygons} polygons, {rows[-1]['crack_pixels']} "
                f"crack pixels with lines behind, {rows[-1]['crack_pixels_skirts']} with skirts")
    return rows


def resolution_rows(exp: ExperimentContext, views: Views) -> list[dict]:
    """Error and time against the space-mesh resolution (12² … 192² cells; quick up to 48²,
    tiny 6² and 8²), with the fitted solution's own error against the closed form."""
    rows = []
    for n in exp.pick((12, 24, 48, 96, 192), (12, 24, 48), (6, 8)):
        t_lo, t_hi = window(n)
        sol_n = plate_solution(n, t_lo, t_hi)
        sn = slice_at(sol_n.mesh, T_SLICE)
        scene_n = slice_scene(sol_n, sn)
        ex = None
        for shading in ("per_vertex", "per_pixel"):
            m, grid = views.top(scene_n, spacetime_style(shading, "behind"), time_it=True)
            if ex is None:
                ex = views.exact(scene_n, sol_n.material, grid)
                closed = closed_form_error(sol_n, grid, ex)
            rows.append(dict(sweep="resolution", cells=f"{n}x{n}", polygons=sn.n_polygons,
                             path=shading, wall_ms=m.timing.wall_ms, gpu_ms=m.timing.gpu_ms,
                             **error_columns(m.image, ex, scene_n.corners, grid),
                             fit_U_err_max=closed,
                             renderer=exp.renderer))
        exp.say(f"  resolution {n}x{n}: {sn.n_polygons} polygons, fitted U off the closed form "
                f"by {closed:.3g} kJ/m³")
    return rows


def closed_form_error(sol: Solution, grid: PixelGrid, exact) -> float:
    """Max ``|U_fitted − U_closed form|`` (kJ/m³) over the covered pixel centres: how far the
    stored solution itself is from the field it approximates."""
    xs, ys = grid.centres()
    X, Y = np.meshgrid(xs, ys)
    cov = exact.covered
    U = sol.field.strain_energy(X[cov], Y[cov], np.full(cov.sum(), T_SLICE))
    return float(np.abs(exact.U[cov] - U).max())


# ------------------------------------------------------------------------------- stability
def stability_rows(exp: ExperimentContext, views: Views) -> list[dict]:
    """Far from the origin, degenerate slices and zero fields, per pixel, against the exact
    image (on a space mesh of 24² cells; tiny 8²)."""
    n = exp.pick(24, 24, 8)
    t_lo, t_hi = window(n)
    near = plate_solution(n, t_lo, t_hi)
    rows = (far_rows(exp, views, near, n, t_lo, t_hi)
            + degenerate_rows(exp, views, near, t_lo, t_hi) + zero_field_rows(exp, views, n))
    for row in rows:
        exp.say(f"  {row['case']}: err max {row['max_diff_255']:.2f}, >1/255 off edges "
                f"{100 * row['share_over_1_off_edges']:.4f} %, max off edges "
                f"{row['max_diff_255_off_edges']:.2f}")
    return rows


def nan_pixels(exact) -> int:
    return int((~np.isfinite(exact.rgb)).any(axis=2).sum())


def far_rows(exp, views: Views, near: Solution, n: int, t_lo: float, t_hi: float) -> list[dict]:
    """The domain at the origin and 10⁴ element sizes away (relative upload, and global float32
    coordinates), on the GPU and in a float32 emulation of the evaluation."""
    h = DOMAIN / n
    far = plate_solution(n, t_lo, t_hi, offset=(1e4 * h, -1e4 * h))
    rows = []
    for label, sol, origin in (("at the origin", near, None),
                               ("10^4 element sizes away, relative upload", far, None),
                               ("10^4 element sizes away, global float32", far, np.zeros(3))):
        s = slice_at(sol.mesh, T_SLICE)
        scene = slice_scene(sol, s)
        m, grid = views.top(scene, spacetime_style("per_pixel"), origin=origin)
        exact = views.exact(scene, sol.material, grid)
        # float32 emulation of the same evaluation at the pixel centres
        xs, ys = grid.centres()
        X, Y = np.meshgrid(xs, ys)
        cov = exact.covered
        elem = scene.element[exact.polygon[cov]]
        args = (sol.coeffs, sol.centre, sol.extent, elem, X[cov], Y[cov], T_SLICE, sol.material)
        ref = exact.U[cov]
        glob = evaluate_float32_global(*args)["U"].astype(np.float64)
        loc = evaluate_float32_local(*args)["U"].astype(np.float64)
        scale = max(float(np.abs(ref).max()), 1e-30)
        rows.append(dict(case=label, offset_mm=float(np.hypot(*np.asarray(sol.field.origin))),
                         polygons=s.n_polygons,
                         **error_columns(m.image, exact, scene.corners, grid),
                         f32_global_U_err_rel=float(np.abs(glob - ref).max() / scale),
                         f32_local_U_err_rel=float(np.abs(loc - ref).max() / scale),
                         nan_pixels=nan_pixels(exact), renderer=exp.renderer))
    return rows


def degenerate_rows(exp, views: Views, near: Solution, t_lo: float, t_hi: float) -> list[dict]:
    """Slices through the flat front between the two bands and through a vertex's time."""
    mid = 0.5 * (t_lo + t_hi)
    vertex_t = float(near.mesh.points[near.mesh.simplices[len(near.mesh.simplices) // 2], 2].max())
    rows = []
    for label, t in (("slice through the flat front between bands", mid),
                     ("slice through a vertex", vertex_t)):
        s = slice_at(near.mesh, t)
        scene = slice_scene(near, s)
        m, grid = views.top(scene, spacetime_style("per_pixel"))
        exact = views.exact(scene, near.material, grid)
        areas = polygon_areas(s)
        rows.append(dict(case=label, t_us=t, polygons=s.n_polygons,
                         zero_area_polygons=int((areas <= 1e-12 * DOMAIN ** 2).sum()),
                         nan_corners=int((~np.isfinite(s.corners)).sum()),
                         area_error=abs(float(areas.sum()) - DOMAIN ** 2) / DOMAIN ** 2,
                         **error_columns(m.image, exact, scene.corners, grid),
                         nan_pixels=nan_pixels(exact), renderer=exp.renderer))
    return rows


def zero_field_rows(exp, views: Views, n: int) -> list[dict]:
    """Zero strain and zero velocity: before the pulse reaches the far corner, U and ``|v|``
    vanish."""
    early = plate_solution(n, 0.0, 1.0, bands=1)
    s = slice_at(early.mesh, 0.5)
    scene = slice_scene(early, s)
    rows = []
    for shading in ("per_vertex", "per_pixel"):
        m, grid = views.top(scene, spacetime_style(shading))
        exact = views.exact(scene, early.material, grid)
        zero = exact.covered & (exact.U < 1e-9)
        rows.append(dict(case=f"U ≈ 0 and |v| ≈ 0 regions ({shading})", polygons=s.n_polygons,
                         zero_U_pixels=int(zero.sum()),
                         **error_columns(m.image, exact, scene.corners, grid),
                         nan_pixels=nan_pixels(exact), renderer=exp.renderer))
    return rows


# --------------------------------------------------------------------------------- figures
def save_bar_figure(exp: ExperimentContext, views: Views) -> None:
    """``fig3_bar.png``: the 1-D bar's whole (x, t) spacetime, per vertex, per pixel, exact."""
    bar, _ = bar_scene()
    images = {}
    for shading in ("per_vertex", "per_pixel"):
        m, grid = views.top(bar, spacetime_style(shading, lighting=False))
        images[shading] = m.image
    exact = views.exact(bar, BAR, grid, lighting=False)
    errors = {shading: error_map(image, exact) for shading, image in images.items()}
    save_image_grid(exp.file("fig3_bar.png"),
                    [images["per_vertex"], images["per_pixel"], exact.rgba8(),
                     errors["per_vertex"], errors["per_pixel"]],
                    ["(a) per vertex", "(b) per pixel", "(c) exact", "|a − c|", "|b − c|"],
                    columns=3)
    exp.say(f"  fig3: bar, {len(bar.corners)} spacetime triangles, per-vertex error max "
            f"{errors['per_vertex'].max():.0f}, per-pixel {errors['per_pixel'].max():.1f} (1/255)")


def save_slice_figures(exp: ExperimentContext, views: Views, keep: dict) -> None:
    """``fig5_slice.png``, ``fig5_crop.png`` and ``fig5_colorbar.png`` of the detail slice."""
    sol, scene, _ = keep[detail_target(exp)]
    images = {}
    for shading in ("per_vertex", "per_pixel"):
        m, grid = views.top(scene, spacetime_style(shading))
        images[shading] = m.image
    exact = views.exact(scene, sol.material, grid)
    panels = [images["per_vertex"], images["per_pixel"], exact.rgba8(),
              error_map(images["per_vertex"], exact), error_map(images["per_pixel"], exact)]
    titles = ["(a) per vertex", "(b) per pixel", "(c) exact", "|a − c|", "|b − c|"]
    save_image_grid(exp.file("fig5_slice.png"), panels, titles, columns=3)
    # a quarter of the image around the ring's upper right part, for a closer look
    h, w = grid.height, grid.width
    box = (slice(h // 4, h // 2), slice(w // 2, w // 2 + w // 4))
    save_image_grid(exp.file("fig5_crop.png"), [p[box] for p in panels], titles, columns=5)
    unlit = views.top(scene, spacetime_style("per_pixel", lighting=False))[0].image
    save_field_figure(exp.file("fig5_colorbar.png"), unlit,
                      value_range=(0.0, float(np.log1p(U_MAX))), colormap=COLORMAP,
                      label="ln(1 + U / (1 kJ/m³)), clamped at U_max", units="",
                      title=f"strain energy density at t = {scene.t:.2f} µs, per pixel, unlit")
    panels = [views.oblique(scene, spacetime_style(sh, "skirts"))
              for sh in ("per_vertex", "per_pixel")]
    save_image_grid(exp.file("fig8_height.png"), panels,
                    ["(a) per-vertex colour", "(b) per-pixel colour"])


def save_crack_figure(exp: ExperimentContext, views: Views, keep: dict) -> None:
    """``fig4_cracks.png``: oblique views of every kept slice size (10³, 10⁴, 10⁵ polygons;
    tiny 10³) raw, with lines over and behind, with quadrisection, and with skirts."""
    panels, titles = [], []
    for target in sorted(keep):
        sol_k, scene_k, s_k = keep[target]
        quads = slice_scene(sol_k, quadrisect(s_k, 0.25 * float(polygon_areas(s_k).mean())))
        row = []
        for label, sc, overdraw in (("raw", scene_k, "none"), ("lines over", scene_k, "over"),
                                    ("lines behind", scene_k, "behind"),
                                    ("behind + quadrisection", quads, "behind"),
                                    ("skirts", scene_k, "skirts")):
            image = views.oblique(sc, spacetime_style("per_pixel", overdraw))
            row.append(image)
            titles.append(f"{s_k.n_polygons} polygons, {label}: "
                          f"{int(crack_pixels(image, CRACK_BACKGROUND).sum())} crack px")
        panels += crop_to_cracks(row)
    save_image_grid(exp.file("fig4_cracks.png"), panels, titles, columns=5)


def crop_to_cracks(images: list) -> list:
    """The same half-size window of every image, centred on the first image's cracks."""
    h, w = images[0].shape[:2]
    cracks = np.argwhere(crack_pixels(images[0], CRACK_BACKGROUND))
    ci, cj = cracks.mean(axis=0).astype(int) if len(cracks) else (h // 2, w // 2)
    i0 = int(np.clip(ci - h // 4, 0, h - h // 2))
    j0 = int(np.clip(cj - w // 4, 0, w - w // 2))
    return [im[i0:i0 + h // 2, j0:j0 + w // 2] for im in images]


def interleaved_rows(exp: ExperimentContext, views: Views, keep: dict) -> list[dict]:
    """Per pixel against per vertex (no edge overdraw, element records in a buffer texture) in
    the top view of the largest slice kept, measured interleaved: the ratio of their wall times
    with its 95 % interval, and the pairs' median times (ms)."""
    target = max(keep)
    _, scene, s = keep[target]
    grid = views.grid(scene)
    camera = top_camera(grid, (-1.0, views.top_height(scene) + 1.0))
    size = (grid.width, grid.height)
    with prepared(exp.gl, scene, spacetime_path(spacetime_style("per_pixel")), camera=camera,
                  size=size) as pixel, \
            prepared(exp.gl, scene, spacetime_path(spacetime_style("per_vertex")),
                     camera=camera, size=size) as vertex:
        ratio = interleaved_ratios(
            {"per_pixel": draw_clock(pixel, BACKGROUND),
             "per_vertex": draw_clock(vertex, BACKGROUND)},
            [("per_pixel", "per_vertex")], exp.ratio_stop())[("per_pixel", "per_vertex")]
    exp.say(f"  interleaved: {ratio}")
    return [dict(target_polygons=target, polygons=s.n_polygons, size=f"{size[0]}x{size[1]}",
                 renderer=exp.renderer, per_pixel_ms=float(np.median(ratio.numerator_ms)),
                 per_vertex_ms=float(np.median(ratio.denominator_ms)),
                 **ratio.as_row("per_pixel_over_per_vertex"))]


@experiment("fig_pixel_exact", "st2005: pixel-exact rendering of spacetime FE solutions, "
                               "per vertex against per pixel, with exact images",
            declared=DECLARED)
def run(exp: ExperimentContext) -> list[dict]:
    views = Views(exp, width=exp.pick(1000, 400, 160))
    exp.say(f"slice sizes on {exp.renderer}")
    rows, keep = size_rows(exp, views)
    exp.table(interleaved_rows(exp, views, keep), "interleaved",
              "st2005 per pixel against per vertex, measured interleaved")
    exp.table(slicing_rows(exp), "slicing", "st2005 time slicing as t advances (ms per frame)")
    exp.say("sweep")
    sweep = quadrisection_rows(exp, views, keep) + resolution_rows(exp, views)
    exp.table(sweep, "sweep", "st2005 error and time against quadrisection and mesh resolution")
    plot_sweep(sweep, exp.file("sweep.png"))
    exp.say("stability")
    exp.table(stability_rows(exp, views), "stability",
              "st2005 numerical stability: far from the origin, zero fields, degenerate slices")
    exp.say("figures")
    save_bar_figure(exp, views)
    save_slice_figures(exp, views, keep)
    save_crack_figure(exp, views, keep)
    return rows
