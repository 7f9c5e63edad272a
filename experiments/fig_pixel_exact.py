"""st2005: pixel-exact rendering of spacetime FE solutions, per vertex against per pixel.

Every image here has an exact answer: the solutions are least-squares cubic fits (20
monomials per element, element-local coordinates, discontinuous across elements like a DG
solution) of closed-form elastodynamic fields, and the exact image is the float64 shading of
those polynomials at the pixel centres of a top view (:mod:`workbench.algo.spacetime.exact`).
Colour is strain energy density U on the log scale s = log(U + 1)/log(U_max + 1), height the
velocity magnitude; lighting is Phong with the height field's exact normal.

Outputs in ``figures/fig_pixel_exact/``:

* ``table.md`` — per slice size (10³ … 10⁶ polygons; 10³ … 10⁵ with ``--quick``): tetrahedra,
  polygons, per-frame slicing time, then for each path (per vertex, per pixel) without edge
  overdraw, with the paper's line overdraw ("over"), with lines behind the fill ("behind") and
  with lines and skirts behind it ("skirts"), element records in a buffer texture, and once
  more without overdraw from the paper's 2-D texture rectangle ("texture"): the time to upload
  the slice (``prepare_ms``, program linking included), GPU and wall ms per frame, max and
  mean colour error against the exact image (1/255), the share of covered pixels over 1/255 —
  all of them, and those whose centre is more than 0.01 px from an element edge (closer, the
  rasteriser's sub-pixel precision may pick the neighbouring element) with their max error —
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

Run: ``workbench run fig_pixel_exact [--quick]``.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from workbench.algo.spacetime.exact import colour_error, edge_distance, exact_image
from workbench.algo.spacetime.fields import BAR, STEEL, RadialPulse
from workbench.algo.spacetime.mesh import front_refined, rect_triangulation
from workbench.algo.spacetime.poly import evaluate, evaluate_float32_global, evaluate_float32_local
from workbench.algo.spacetime.raster import PixelGrid
from workbench.algo.spacetime.slicing import TimeSlicer, polygon_areas, quadrisect, slice_at
from workbench.experiment.compare import crack_pixels
from workbench.experiment.figures import save_field_figure, save_image_grid
from workbench.experiment.measure import measure
from workbench.experiment.context import ExperimentContext
from workbench.experiment.registry import experiment
from workbench.experiment.tables import atomic_open, write_table
from workbench.experiment.timing import time_call
from workbench.gl import Camera, create_context, renderer
from workbench.paths.colormap import colormap_lut
from workbench.paths.spacetime import OVERDRAWS, SpacetimeStyle, spacetime_path, top_camera
from workbench.algo.spacetime.scene import (DOMAIN, PULSE, T_SLICE, Solution, SpacetimeScene, bar_scene,
                                       plate_solution, slice_scene, window)

U_MAX = 100.0  # kJ/m³, top of the log colour scale
HEIGHT_SCALE = 800.0  # mm of height per mm/µs (peak speeds ~1e-2 mm/µs)
COLORMAP = "plasma"  # its dark end is blue, not black, so lighting shows everywhere
BACKGROUND = (1.0, 1.0, 1.0, 1.0)
CRACK_BACKGROUND = (0.0, 1.0, 0.0, 1.0)  # a colour the ramp never produces
EDGE_PX = 0.01  # pixel centres this close to an element edge may go to either element
# space-mesh cells per side for each target slice size (polygons per slice ≈ 6.6 n² plus the
# refinement along the front, which dominates on coarse meshes)
RESOLUTIONS = {1_000: 7, 10_000: 28, 100_000: 115, 1_000_000: 390}


class Renderer:
    """One GL context; measures spacetime scenes in the top view (against the exact image) and
    in an oblique perspective view (cracks), each through
    :func:`~workbench.experiment.measure.measure`."""

    def __init__(self, width: int, repeat: int) -> None:
        self.ctx = create_context()
        self.name = renderer(self.ctx)
        self.width, self.repeat = width, repeat
        self.table = colormap_lut(COLORMAP)

    def style(self, shading, overdraw="none", lighting=True, store="buffer") -> SpacetimeStyle:
        return SpacetimeStyle(shading=shading, edge_overdraw=overdraw, lighting=lighting,
                              height_scale=HEIGHT_SCALE, U_max=U_MAX, colormap=COLORMAP,
                              element_store=store)

    def grid(self, scene: SpacetimeScene) -> PixelGrid:
        return PixelGrid.fit(*scene.bounds(), self.width)

    def heights(self, scene: SpacetimeScene) -> float:
        """The largest vertex height of the scene (mm)."""
        if scene.is_bar:
            return 1.0
        c = scene.corners.reshape(-1, 2)
        speed = evaluate(scene.coeffs, scene.centre, scene.extent, np.repeat(scene.element, 4),
                         c[:, 0], c[:, 1], scene.t)["speed"]
        return float(HEIGHT_SCALE * speed.max()) + 1e-3

    def top(self, scene, style, *, time_it=False, origin=None):
        """(measurement, grid) of the top view, timed with ``time_it``; ``origin`` (3,) is the
        float64 upload origin (default the grid centre)."""
        grid = self.grid(scene)
        camera = top_camera(grid, (-1.0, self.heights(scene) + 1.0), origin=origin)
        return self._measure(scene, style, camera, (grid.width, grid.height), BACKGROUND,
                             time_it), grid

    def oblique(self, scene, style, *, size=None):
        """(H, W, 4) uint8 image of a perspective view from 35° above the plate, on
        CRACK_BACKGROUND."""
        lo, hi = scene.bounds()
        top = self.heights(scene)
        camera = Camera.fit_box(np.r_[lo, 0.0], np.r_[hi, top], azimuth=25, elevation=35,
                                projection="perspective", up="z", margin=0.9,
                                aspect=4 / 3, origin=np.r_[(lo + hi) / 2, 0.0])
        size = size or (self.width, self.width * 3 // 4)
        return self._measure(scene, style, camera, size, CRACK_BACKGROUND, False).image

    def _measure(self, scene, style, camera, size, background, time_it):
        return measure(self.ctx, scene, spacetime_path(style), camera=camera, size=size,
                       repeats=self.repeat, background=background, timed=time_it)

    def exact(self, scene: SpacetimeScene, material, grid: PixelGrid, lighting=True):
        return exact_image(scene.corners, scene.element, scene.coeffs, scene.centre, scene.extent,
                           material, grid, t=scene.t, U_max=U_MAX, table=self.table,
                           height_scale=HEIGHT_SCALE, lighting=lighting and not scene.is_bar)

    def release(self) -> None:
        self.ctx.release()


def error_columns(image, exact, corners, grid: PixelGrid, prefix="") -> dict:
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
    return {prefix + "err_max": stats["max"], prefix + "err_mean": stats["mean"],
            prefix + "share_over_1": stats["share_over_1"],
            prefix + "share_over_1_off_edges": len(off) / stats["covered"],
            prefix + "err_max_off_edges": worst,
            prefix + "uncovered": stats["uncovered"]}


def error_map(image, exact) -> np.ndarray:
    err = np.abs(image[..., :3].astype(np.float64) - 255.0 * exact.rgb).max(axis=2)
    return np.where(exact.covered, err, 0.0)


# ---------------------------------------------------------------------------- the main table
def size_rows(r: Renderer, quick: bool, say) -> tuple[list[dict], dict]:
    rows, keep = [], {}
    targets = [t for t in RESOLUTIONS if not quick or t <= 100_000]
    for target in targets:
        n = RESOLUTIONS[target]
        t_lo, t_hi = window(n)
        sol = plate_solution(n, t_lo, t_hi)
        slicer = TimeSlicer(sol.mesh, outer=True)
        frames = np.linspace(t_lo + 0.05 * (t_hi - t_lo), T_SLICE, 9)
        slice_ms = []
        for t in frames:
            start = time.perf_counter()
            s = slicer.slice(float(t))
            slice_ms.append(1e3 * (time.perf_counter() - start))
        scene = slice_scene(sol, s)
        say(f"  {target:>9} target: {sol.mesh.n_simplices} tets, {s.n_polygons} polygons, "
            f"mesh {sol.mesh_s:.1f} s, fit {sol.fit_s:.1f} s, slice {np.median(slice_ms[1:]):.1f} ms")
        exact = None
        # every overdraw with the element records in a buffer texture, and the paper's 2-D
        # texture rectangle for comparison
        variants = [(overdraw, "buffer") for overdraw in OVERDRAWS] + [("none", "texture")]
        for shading in ("per_vertex", "per_pixel"):
            for overdraw, store in variants:
                style = r.style(shading, overdraw, store=store)
                m, grid = r.top(scene, style, time_it=True)
                if exact is None:
                    exact = r.exact(scene, sol.material, grid)
                oblique = r.oblique(scene, style)
                row = dict(target_polygons=target, cells=f"{n}x{n}", tets=sol.mesh.n_simplices,
                           polygons=s.n_polygons, quads=int(s.is_quad.sum()),
                           slice_ms=float(np.median(slice_ms[1:])), path=shading,
                           edge_overdraw=overdraw, element_store=store, **m.timing.as_row(),
                           prepare_ms=m.row["prepare_ms"], upload_bytes=m.row["bytes_uploaded"],
                           **error_columns(m.image, exact, scene.corners, grid),
                           crack_pixels=int(crack_pixels(oblique, CRACK_BACKGROUND).sum()),
                           renderer=r.name, image=f"{grid.width}x{grid.height}")
                rows.append(row)
                say(f"    {shading:10} overdraw {overdraw:6} {store:7} wall {row['wall_ms']:.1f} ms, "
                    f"err max {row['err_max']:.1f} mean {row['err_mean']:.2f}, "
                    f">1/255 {100 * row['share_over_1']:.4f} % (off edges "
                    f"{100 * row['share_over_1_off_edges']:.4f} %, max "
                    f"{row['err_max_off_edges']:.2f}), cracks {row['crack_pixels']}")
        if target <= 100_000:
            keep[target] = (sol, scene, s)
    # cost against the per-vertex path with the same overdraw and store (wall time)
    by = {(row["target_polygons"], row["path"], row["edge_overdraw"], row["element_store"]): row
          for row in rows}
    for row in rows:
        base = by[(row["target_polygons"], "per_vertex", row["edge_overdraw"], row["element_store"])]
        row["wall_vs_per_vertex"] = row["wall_ms"] / base["wall_ms"]
    return rows, keep


# ---------------------------------------------------------------------------------- slicing
def slicing_rows(quick: bool, say) -> list[dict]:
    """Incremental slicing while t advances through a mesh of ~10⁶ (10⁵ quick) tetrahedra."""
    n, t_end = (25, 6.0) if quick else (35, 10.0)
    field = RadialPulse(**PULSE)
    start = time.perf_counter()
    pts, tris = rect_triangulation(n, n, size=(DOMAIN, DOMAIN), jitter=0.25, seed=2)
    mesh = front_refined(pts, tris, t_end, STEEL.p_wave_speed, bands=4,
                         front_distance=field.front_distance, width=1.5 * DOMAIN / n)
    build_s = time.perf_counter() - start
    say(f"slicing: {mesh.n_simplices} tets built in {build_s:.1f} s")
    start = time.perf_counter()
    slicer = TimeSlicer(mesh)
    sort_s = time.perf_counter() - start
    times = np.linspace(0.05 * t_end, 0.95 * t_end, 10 if quick else 40)
    inc, polys = [], []
    for t in times:
        start = time.perf_counter()
        s = slicer.slice(float(t))
        inc.append(1e3 * (time.perf_counter() - start))
        polys.append(s.n_polygons)
    # the same frames with the domain-boundary edges the edge overdraw leaves out
    start = time.perf_counter()
    mesh.shared_facets  # derived once per mesh
    facets_s = time.perf_counter() - start
    outer_slicer = TimeSlicer(mesh, outer=True)
    inc_outer = []
    for t in times:
        start = time.perf_counter()
        outer_slicer.slice(float(t))
        inc_outer.append(1e3 * (time.perf_counter() - start))
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
    say(f"  incremental {row['incremental_ms_median']:.1f} ms/frame (max {row['incremental_ms_max']:.1f}, "
        f"{row['with_outer_ms_median']:.1f} with boundary edges), "
        f"brute force {row['brute_force_ms_median']:.1f} ms, {row['polygons_median']} polygons")
    return [row]


# ------------------------------------------------------------------------------------ sweep
def sweep_rows(r: Renderer, quick: bool, keep: dict, say) -> list[dict]:
    rows = []
    sol, _, s = keep[10_000]
    area = polygon_areas(s)
    mean_area = float(area.mean())
    factors = (None, 1.0, 0.5, 0.25) if quick else (None, 2.0, 1.0, 0.5, 0.25, 0.125)
    exact = None
    for factor in factors:
        threshold = np.inf if factor is None else factor * mean_area
        q = s if factor is None else quadrisect(s, threshold)
        qs = slice_scene(sol, q)
        for shading in ("per_vertex", "per_pixel"):
            m, grid = r.top(qs, r.style(shading, "behind"), time_it=True)
            if exact is None:  # children show their parent's element: one exact image for all
                exact = r.exact(slice_scene(sol, s), sol.material, grid)
            oblique = r.oblique(qs, r.style(shading, "behind"))
            skirted = r.oblique(qs, r.style(shading, "skirts"))
            rows.append(dict(sweep="quadrisection", cells=sol.label,
                             threshold_mm2=None if factor is None else threshold,
                             threshold_vs_mean_area=factor, polygons=q.n_polygons, path=shading,
                             wall_ms=m.timing.wall_ms, gpu_ms=m.timing.gpu_ms,
                             **error_columns(m.image, exact, s.corners, grid),
                             crack_pixels=int(crack_pixels(oblique, CRACK_BACKGROUND).sum()),
                             crack_pixels_skirts=int(crack_pixels(skirted, CRACK_BACKGROUND).sum()),
                             renderer=r.name))
        say(f"  quadrisection {factor}: {q.n_polygons} polygons, {rows[-1]['crack_pixels']} crack "
            f"pixels with lines behind, {rows[-1]['crack_pixels_skirts']} with skirts")
    for n in ((12, 24, 48) if quick else (12, 24, 48, 96, 192)):
        t_lo, t_hi = window(n)
        sol_n = plate_solution(n, t_lo, t_hi)
        sn = slice_at(sol_n.mesh, T_SLICE)
        scene_n = slice_scene(sol_n, sn)
        ex = None
        for shading in ("per_vertex", "per_pixel"):
            m, grid = r.top(scene_n, r.style(shading, "behind"), time_it=True)
            if ex is None:
                ex = r.exact(scene_n, sol_n.material, grid)
                closed = closed_form_error(sol_n, grid, ex)
            rows.append(dict(sweep="resolution", cells=f"{n}x{n}", polygons=sn.n_polygons,
                             path=shading, wall_ms=m.timing.wall_ms, gpu_ms=m.timing.gpu_ms,
                             **error_columns(m.image, ex, scene_n.corners, grid),
                             fit_U_err_max=closed,
                             renderer=r.name))
        say(f"  resolution {n}x{n}: {sn.n_polygons} polygons, fitted U off the closed form by "
            f"{closed:.3g} kJ/m³")
    return rows


def closed_form_error(sol: Solution, grid: PixelGrid, exact) -> float:
    """Max |U_fitted − U_closed form| (kJ/m³) over the covered pixel centres: how far the
    stored solution itself is from the field it approximates."""
    xs, ys = grid.centres()
    X, Y = np.meshgrid(xs, ys)
    cov = exact.covered
    U = sol.field.strain_energy(X[cov], Y[cov], np.full(cov.sum(), T_SLICE))
    return float(np.abs(exact.U[cov] - U).max())


def plot_sweep(rows: list[dict], path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(10, 4), dpi=100)
    for ax, sweep, label in zip(axes, ("quadrisection", "resolution"),
                                ("quadrisection threshold", "mesh resolution")):
        for shading, marker in (("per_vertex", "o"), ("per_pixel", "s")):
            pts = [(row["wall_ms"], row["err_mean"]) for row in rows
                   if row["sweep"] == sweep and row["path"] == shading]
            if pts:
                x, y = zip(*pts)
                ax.plot(x, y, marker=marker, label=shading.replace("_", " "))
        ax.axhline(1.0, color="grey", lw=0.8, ls="--")
        ax.set_xlabel("wall time per frame [ms]")
        ax.set_ylabel("mean colour error [1/255]")
        ax.set_yscale("log")
        ax.set_title(f"run time against error: {label}")
        ax.legend()
    fig.tight_layout()
    with atomic_open(path, "wb") as fh:
        fig.savefig(fh, format="png")
    plt.close(fig)


# ------------------------------------------------------------------------------- stability
def stability_rows(r: Renderer, quick: bool, say) -> list[dict]:
    rows = []
    n = 24
    t_lo, t_hi = window(n)
    h = DOMAIN / n
    near = plate_solution(n, t_lo, t_hi)
    far_offset = (1e4 * h, -1e4 * h)
    far = plate_solution(n, t_lo, t_hi, offset=far_offset)
    for label, sol, origin in (("at the origin", near, None),
                               ("10^4 element sizes away, relative upload", far, None),
                               ("10^4 element sizes away, global float32", far, np.zeros(3))):
        s = slice_at(sol.mesh, T_SLICE)
        scene = slice_scene(sol, s)
        m, grid = r.top(scene, r.style("per_pixel"), origin=origin)
        image = m.image
        exact = r.exact(scene, sol.material, grid)
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
                         polygons=s.n_polygons, **error_columns(image, exact, scene.corners, grid),
                         f32_global_U_err_rel=float(np.abs(glob - ref).max() / scale),
                         f32_local_U_err_rel=float(np.abs(loc - ref).max() / scale),
                         nan_pixels=int((~np.isfinite(exact.rgb)).any(axis=2).sum()),
                         renderer=r.name))
    # degenerate slices: the flat front between the two bands, and a vertex's time
    mid = 0.5 * (t_lo + t_hi)
    vertex_t = float(near.mesh.points[near.mesh.simplices[len(near.mesh.simplices) // 2], 2].max())
    for label, t in (("slice through the flat front between bands", mid),
                     ("slice through a vertex", vertex_t)):
        s = slice_at(near.mesh, t)
        scene = slice_scene(near, s)
        m, grid = r.top(scene, r.style("per_pixel"))
        image = m.image
        exact = r.exact(scene, near.material, grid)
        areas = polygon_areas(s)
        rows.append(dict(case=label, t_us=t, polygons=s.n_polygons,
                         zero_area_polygons=int((areas <= 1e-12 * DOMAIN ** 2).sum()),
                         nan_corners=int((~np.isfinite(s.corners)).sum()),
                         area_error=abs(float(areas.sum()) - DOMAIN ** 2) / DOMAIN ** 2,
                         **error_columns(image, exact, scene.corners, grid),
                         nan_pixels=int((~np.isfinite(exact.rgb)).any(axis=2).sum()),
                         renderer=r.name))
    # zero strain and zero velocity: before the pulse reaches the far corner, U and |v| vanish
    early = plate_solution(n, 0.0, 1.0, bands=1)
    s = slice_at(early.mesh, 0.5)
    scene = slice_scene(early, s)
    for shading in ("per_vertex", "per_pixel"):
        m, grid = r.top(scene, r.style(shading))
        image = m.image
        exact = r.exact(scene, early.material, grid)
        zero = exact.covered & (exact.U < 1e-9)
        rows.append(dict(case=f"U ≈ 0 and |v| ≈ 0 regions ({shading})", polygons=s.n_polygons,
                         zero_U_pixels=int(zero.sum()), **error_columns(image, exact, scene.corners, grid),
                         nan_pixels=int((~np.isfinite(exact.rgb)).any(axis=2).sum()),
                         renderer=r.name))
    for row in rows:
        say(f"  {row['case']}: err max {row['err_max']:.2f}, >1/255 off edges "
            f"{100 * row['share_over_1_off_edges']:.4f} %, max off edges "
            f"{row['err_max_off_edges']:.2f}")
    return rows


# --------------------------------------------------------------------------------- figures
def figures(r: Renderer, out_dir: Path, keep: dict, say) -> None:
    bar, _ = bar_scene()
    images, errors = {}, {}
    for shading in ("per_vertex", "per_pixel"):
        m, grid = r.top(bar, r.style(shading, lighting=False))
        images[shading] = m.image
    exact = r.exact(bar, BAR, grid, lighting=False)
    for shading in images:
        errors[shading] = error_map(images[shading], exact)
    save_image_grid(out_dir / "fig3_bar.png",
                    [images["per_vertex"], images["per_pixel"], exact.rgba8(),
                     errors["per_vertex"], errors["per_pixel"]],
                    ["(a) per vertex", "(b) per pixel", "(c) exact", "|a − c|", "|b − c|"],
                    columns=3)
    say(f"  fig3: bar, {len(bar.corners)} spacetime triangles, per-vertex error max "
        f"{errors['per_vertex'].max():.0f}, per-pixel {errors['per_pixel'].max():.1f} (1/255)")

    sol, scene, _ = keep[10_000]
    images = {}
    for shading in ("per_vertex", "per_pixel"):
        m, grid = r.top(scene, r.style(shading))
        images[shading] = m.image
    exact = r.exact(scene, sol.material, grid)
    panels = [images["per_vertex"], images["per_pixel"], exact.rgba8(),
              error_map(images["per_vertex"], exact), error_map(images["per_pixel"], exact)]
    titles = ["(a) per vertex", "(b) per pixel", "(c) exact", "|a − c|", "|b − c|"]
    save_image_grid(out_dir / "fig5_slice.png", panels, titles, columns=3)
    # a quarter of the image around the ring's upper right part, for a closer look
    h, w = grid.height, grid.width
    box = (slice(h // 4, h // 2), slice(w // 2, w // 2 + w // 4))
    save_image_grid(out_dir / "fig5_crop.png", [p[box] for p in panels], titles, columns=5)
    unlit = r.top(scene, r.style("per_pixel", lighting=False))[0].image
    save_field_figure(out_dir / "fig5_colorbar.png", unlit,
                      value_range=(0.0, float(np.log1p(U_MAX))), colormap=COLORMAP,
                      label="ln(1 + U / (1 kJ/m³)), clamped at U_max", units="",
                      title=f"strain energy density at t = {scene.t:.2f} µs, per pixel, unlit")

    panels, titles = [], []
    for target in (1_000, 10_000, 100_000):
        sol_k, scene_k, s_k = keep[target]
        quads = slice_scene(sol_k, quadrisect(s_k, 0.25 * float(polygon_areas(s_k).mean())))
        row = []
        for label, sc, overdraw in (("raw", scene_k, "none"), ("lines over", scene_k, "over"),
                                    ("lines behind", scene_k, "behind"),
                                    ("behind + quadrisection", quads, "behind"),
                                    ("skirts", scene_k, "skirts")):
            image = r.oblique(sc, r.style("per_pixel", overdraw))
            row.append(image)
            titles.append(f"{s_k.n_polygons} polygons, {label}: "
                          f"{int(crack_pixels(image, CRACK_BACKGROUND).sum())} crack px")
        panels += crop_to_cracks(row)
    save_image_grid(out_dir / "fig4_cracks.png", panels, titles, columns=5)
    panels = [r.oblique(scene, r.style(sh, "skirts")) for sh in ("per_vertex", "per_pixel")]
    save_image_grid(out_dir / "fig8_height.png", panels, ["(a) per-vertex colour", "(b) per-pixel colour"])


def crop_to_cracks(images: list) -> list:
    """The same half-size window of every image, centred on the first image's cracks."""
    h, w = images[0].shape[:2]
    cracks = np.argwhere(crack_pixels(images[0], CRACK_BACKGROUND))
    ci, cj = cracks.mean(axis=0).astype(int) if len(cracks) else (h // 2, w // 2)
    i0 = int(np.clip(ci - h // 4, 0, h - h // 2))
    j0 = int(np.clip(cj - w // 4, 0, w - w // 2))
    return [im[i0:i0 + h // 2, j0:j0 + w // 2] for im in images]


@experiment("fig_pixel_exact", "st2005: pixel-exact rendering of spacetime FE solutions, "
                               "per vertex against per pixel, with exact images")
def run(exp: ExperimentContext) -> list[dict]:
    out_dir, quick, say = exp.out_dir, exp.quick, exp.say
    r = Renderer(width=400 if quick else 1000, repeat=5 if quick else 9)
    try:
        say(f"slice sizes on {r.name}")
        rows, keep = size_rows(r, quick, say)
        write_table(slicing_rows(quick, say), out_dir, "slicing",
                    title="st2005 time slicing as t advances (ms per frame)")
        say("sweep")
        sweep = sweep_rows(r, quick, keep, say)
        write_table(sweep, out_dir, "sweep", title="st2005 error and time against quadrisection "
                                                   "and mesh resolution")
        plot_sweep(sweep, out_dir / "sweep.png")
        say("stability")
        write_table(stability_rows(r, quick, say), out_dir, "stability",
                    title="st2005 numerical stability: far from the origin, zero fields, "
                          "degenerate slices")
        say("figures")
        figures(r, out_dir, keep, say)
    finally:
        r.release()
    return rows

