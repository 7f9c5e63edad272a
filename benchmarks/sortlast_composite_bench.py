"""Sort-last compositing on a Dask LocalCluster: whole frames against drawn pixels only.

The es2008 scene (1 M triangles, ``--n``² quads per sheet) is split into ``--domains`` spatial
domains (default 8), rendered at ``--size`` (default 1000×1000) by the software rasterizer on
``--workers`` worker processes (default 2, one thread each), and composited on the workers by
every schedule of :func:`workbench.distributed.sortlast.render_sortlast`: ``tree`` and
``swap`` (whole frames, as before), ``active-tree``, ``active-swap``, ``radix`` (direct
send, and 2×4) and ``local`` (each worker's domains composited there, one piece sent per
other worker). The client fetches the final colour (``color_only``, what a display needs) or
the whole frame (colour, depth, triangle indices: the fetched column). The schedules are
interleaved over ``--repeat`` rounds (default 5); per schedule the median composite time with
its range, the bytes that moved between workers and the bytes the schedule sends, and whether
the image equals the one-process frame. Then the same domains drawn by GL (each worker's own
EGL context) and composited by ``local`` and ``active-swap``, against the image one context
draws.

Run alone (it times): ``.venv/bin/python benchmarks/sortlast_composite_bench.py``.
"""

from __future__ import annotations

import argparse
import logging
import statistics

import numpy as np

SCHEDULES = (("tree", None, False), ("swap", None, False), ("tree", None, True),
             ("swap", None, True), ("active-tree", None, True), ("active-swap", None, True),
             ("radix", None, True), ("radix", (2, 4), True), ("local", None, True),
             ("local", None, False))


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=250)
    parser.add_argument("--domains", type=int, default=8)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--size", type=int, default=1000)
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args(argv)

    import dask
    from distributed import Client, LocalCluster

    from workbench.distributed.domains import split_domains
    from workbench.distributed.sortlast import GLDomains, SoftwareDomains, render_sortlast
    from workbench.measurement.rows import default_camera
    from workbench.paths import Style
    from workbench.scene.builtin import fresh_scene

    scene = f"semicylinders:{args.n}"
    size = (args.size, args.size)
    style = Style(field="distance", bands=10)
    mesh = fresh_scene(scene, False)
    camera = default_camera(mesh, size, view=(0.0, 0.0), up="y")
    software = SoftwareDomains(scene, "pixel_color", style, camera, size)
    domains = split_domains(mesh, args.domains)
    reference = software(np.arange(len(mesh.triangles)))
    with dask.config.set({"distributed.worker.profile.enabled": False}):
        cluster = LocalCluster(n_workers=args.workers, threads_per_worker=1, processes=True,
                               dashboard_address=None, silence_logs=logging.ERROR)
    results: dict[str, list] = {}
    with cluster, Client(cluster) as client:
        client.wait_for_workers(args.workers, timeout=120)
        for method, factors, color_only in SCHEDULES:  # load the scene, compile the kernels
            render_sortlast(client, software, domains, method=method, factors=factors,
                            color_only=color_only)
        for _ in range(args.repeat):
            for method, factors, color_only in SCHEDULES:
                out, stats = render_sortlast(client, software, domains, method=method,
                                             factors=factors, color_only=color_only)
                name = (method + ("" if factors is None else " " + "x".join(map(str, factors)))
                        + (" | colour" if color_only else " | frame"))
                color = out if color_only else out.color
                equal = np.array_equal(color, reference.color) and (
                    color_only or (np.array_equal(out.triangle, reference.triangle)
                                   and np.array_equal(out.depth, reference.depth)))
                results.setdefault(name, []).append((stats.composite_s, stats.bytes_moved,
                                                     stats.schedule_bytes, equal))
        base = statistics.median(r[1] for r in results["swap | frame"])
        print("| schedule | fetched | composite s, median [min, max] | moved MiB | of swap's | "
              "schedule MiB | equal |\n|---|---|---|---:|---:|---:|---|")
        for name, rows in results.items():
            times = [r[0] for r in rows]
            moved = statistics.median(r[1] for r in rows)
            print(f"| {name} | {statistics.median(times):.3f} [{min(times):.3f}, "
                  f"{max(times):.3f}] | {moved / 2**20:.1f} | {moved / base:.0%} | "
                  f"{statistics.median(r[2] for r in rows) / 2**20:.1f} | "
                  f"{all(r[3] for r in rows)} |")
        gl = GLDomains(scene, "pixel_color", style, camera, size)
        _, path, target, _ = gl.prepared()
        target.use()
        target.clear()
        path.draw()
        one_context = target.read()
        render_sortlast(client, gl, domains, method="local")  # every worker opens its context
        for method in ("local", "active-swap", "local", "active-swap"):
            color, stats = render_sortlast(client, gl, domains, method=method, color_only=True)
            print(f"GL domains, {method}: {stats.composite_s:.3f} s, "
                  f"{stats.bytes_moved / 2**20:.1f} MiB moved, image equal to one context: "
                  f"{np.array_equal(color, one_context)}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
