"""The fused, tile-parallel software rasterizer against the paper's per-step pipeline.

The es2008 benchmark (:func:`~workbench.scene.generators.semicylinders`: 8 sheets of 250 ×
250 quads, 1 M triangles, at 1000 × 1000; quick: 32 × 32 quads at 200 × 200), seen from the
front as in the reproduction ``table_software_raster``, drawn by the software path with per-
pixel bands (case ``pixel_color``: 10 bands of ``distance``) and flat shading (case
``flat``), by the steps (``RasterOptions(fused=False)``) and fused, with 1 and 2 threads, and,
where an OpenGL context can be made, the GL position-only draw (the floor: ``gl position``).

Timed interleaved, one draw of every configuration per round (target cleared untimed), two
warm-up rounds: each configuration's wall ms, with the per-round ratios steps over fused
(same threads: ``over_fused_1t``/``over_fused_2t`` on the steps' rows), 1 thread over 2 (same
renderer) and the GL floor over each software draw. Column ``differing_pixels``: pixels of
the fused images that differ from the steps' (colour, depth or triangle index; 0 expected).

Run: ``workbench bench softraster_fused_bench [--quick]``.
"""

from __future__ import annotations

from workbench.measurement.bench import Case, benchmark, needs_gl

SIZES = {"full": {"quads": 250, "size": 1000}, "quick": {"quads": 32, "size": 200}}


@benchmark("softraster_fused_bench", "the fused software rasterizer against the per-step "
                                     "pipeline, 1 and 2 threads",
           cases=[Case("pixel_color", SIZES["full"], SIZES["quick"]),
                  Case("flat", SIZES["full"], SIZES["quick"])])
def softraster_fused(bench, quads: int, size: int) -> None:
    from contextlib import ExitStack

    from workbench.algo.softraster import RasterOptions
    from workbench.measurement.interleave import draw_clock
    from workbench.measurement.rows import default_camera
    from workbench.paths import SoftwareRasterizer, Style, prepared
    from workbench.scene.generators import semicylinders

    name = bench.case.name
    style = Style(field="distance", bands=10) if name == "pixel_color" else Style()
    mesh = semicylinders(8, quads)
    shape = (size, size)
    camera = default_camera(mesh, shape, view=(0.0, 0.0), up="y")
    with ExitStack() as stack:
        ready = {}
        for renderer in ("steps", "fused"):
            for threads in (1, 2):
                options = RasterOptions(threads=threads, fused=renderer == "fused")
                ready[f"{renderer} {threads}t"] = stack.enter_context(prepared(
                    SoftwareRasterizer(options), mesh, name, style, camera, shape))
        software = list(ready)
        if needs_gl() is None:
            from workbench.gl import create_context

            ctx = create_context()
            stack.callback(ctx.release)
            ready["gl position"] = stack.enter_context(
                prepared(ctx, mesh, "position", Style(), camera, shape))
        ratios = [(f"steps {t}t", f"fused {t}t") for t in (1, 2)]
        ratios += [(f"{r} 1t", f"{r} 2t") for r in ("steps", "fused")]
        ratios += [("gl position", label) for label in software if "gl position" in ready]
        differing = {}
        for label in software:  # one draw each, then the fused images against the steps'
            ready[label].bind()
            ready[label].path.draw()
        ref = ready["steps 1t"].target.frame
        for label in software:
            frame = ready[label].target.frame
            differing[label] = {"differing_pixels": int(
                ((frame.color != ref.color).any(axis=-1) | (frame.depth != ref.depth)
                 | (frame.triangle != ref.triangle)).sum())}
        bench.interleave({label: draw_clock(r) for label, r in ready.items()}, ratios,
                         warmup=2, columns_of=differing, triangles=int(len(mesh.triangles)))
