"""Sort-last compositing on a Dask LocalCluster: whole frames against drawn pixels only.

Case ``software``: the es2008 scene (``n``² quads per sheet; full 250: 1 M triangles, at
1000 × 1000; quick 16 at 200 × 200) is split into 8 spatial domains, rendered by the software
rasterizer on 2 worker processes (one thread each), and composited on the workers by every
schedule of :func:`workbench.distributed.sortlast.render_sortlast`: ``tree`` and ``swap``
(whole frames), ``active-tree``, ``active-swap``, ``radix`` (direct send, and 2×4) and
``local`` (each worker's domains composited there, one piece sent per other worker). The
client fetches the final colour (``| colour``, what a display needs) or the whole frame
(``| frame``). One warm-up round loads the scene and compiles the kernels; the schedules are
then interleaved, the reported time being each run's ``composite_s``; every schedule carries
``over_swap_frame`` (its time over whole-frame binary swap's) and the columns ``moved_bytes``
(between workers), ``schedule_bytes`` (what the schedule sends) and ``equal`` (the image
equals the one-process frame in every round).

Case ``gl``: the same domains drawn by OpenGL (each worker's own EGL context), composited by
``local`` and ``active-swap`` (colour only), ``equal`` against the image one context draws.

Run: ``workbench bench sortlast_composite_bench [--quick]`` (needs dask's distributed; the gl
case an OpenGL context).
"""

from __future__ import annotations

from workbench.measurement.bench import Case, benchmark, needs_gl, needs_module

SCHEDULES = (("tree", None, False), ("swap", None, False), ("tree", None, True),
             ("swap", None, True), ("active-tree", None, True), ("active-swap", None, True),
             ("radix", None, True), ("radix", (2, 4), True), ("local", None, True),
             ("local", None, False))
SIZES = {"full": {"n": 250, "size": 1000}, "quick": {"n": 16, "size": 200}}
DOMAINS, WORKERS = 8, 2


def label(method: str, factors, color_only: bool) -> str:
    """``swap | frame``, ``radix 2x4 | colour`` …"""
    return (method + ("" if factors is None else " " + "x".join(map(str, factors)))
            + (" | colour" if color_only else " | frame"))


@benchmark("sortlast_composite_bench", "sort-last compositing schedules on a Dask LocalCluster",
           cases=[Case("software", SIZES["full"], SIZES["quick"]),
                  Case("gl", SIZES["full"], SIZES["quick"])],
           requires=[needs_module("dask", "distributed")])
def sortlast_composite(bench, n: int, size: int) -> None:
    import logging

    import dask
    import numpy as np
    from distributed import Client, LocalCluster

    from workbench.distributed.domains import split_domains
    from workbench.distributed.sortlast import GLDomains, SoftwareDomains, render_sortlast
    from workbench.measurement.rows import default_camera
    from workbench.paths import Style
    from workbench.scene.builtin import fresh_scene

    gl = bench.case.name == "gl"
    bench.require(gl and needs_gl())
    scene = f"semicylinders:{n}"
    shape = (size, size)
    style = Style(field="distance", bands=10)
    mesh = fresh_scene(scene, False)
    camera = default_camera(mesh, shape, view=(0.0, 0.0), up="y")
    domains = split_domains(mesh, DOMAINS)
    if gl:
        render = GLDomains(scene, "pixel_color", style, camera, shape)
        _, path, target, _ = render.prepared()
        target.use()
        target.clear()
        path.draw()
        reference = target.read()
        schedules = (("local", None, True), ("active-swap", None, True))
    else:
        render = SoftwareDomains(scene, "pixel_color", style, camera, shape)
        reference = render(np.arange(len(mesh.triangles)))
        schedules = SCHEDULES
    with dask.config.set({"distributed.worker.profile.enabled": False}):
        cluster = LocalCluster(n_workers=WORKERS, threads_per_worker=1, processes=True,
                               dashboard_address=None, silence_logs=logging.ERROR)
    seen: dict[str, dict] = {}
    with cluster, Client(cluster) as client:
        client.wait_for_workers(WORKERS, timeout=120)

        def clock(method, factors, color_only):
            def run() -> float:
                out, stats = render_sortlast(client, render, domains, method=method,
                                             factors=factors, color_only=color_only)
                if gl:
                    equal = bool(np.array_equal(out, reference))
                else:
                    color = out if color_only else out.color
                    equal = np.array_equal(color, reference.color) and (
                        color_only or (np.array_equal(out.triangle, reference.triangle)
                                       and np.array_equal(out.depth, reference.depth)))
                row = seen.setdefault(label(method, factors, color_only), {"equal": True})
                row.update(moved_bytes=stats.bytes_moved, schedule_bytes=stats.schedule_bytes,
                           equal=row["equal"] and bool(equal))
                return stats.composite_s
            return run

        clocks = {label(*s): clock(*s) for s in schedules}
        base = "swap | frame" if not gl else "local | colour"
        bench.interleave(clocks, [(name, base) for name in clocks if name != base],
                         reported=True, columns_of=seen, domains=DOMAINS, workers=WORKERS,
                         triangles=int(len(mesh.triangles)))
