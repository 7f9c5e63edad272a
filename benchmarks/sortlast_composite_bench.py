"""Sort-last compositing on a Dask LocalCluster: whole frames against drawn pixels only.

The es2008 scene (1 M triangles, ``--n``² quads per sheet) is split into ``--domains`` spatial
domains (default 8), rendered at ``--size`` (default 1000×1000) by the software rasterizer on
``--workers`` worker processes (default 2, one thread each), and composited on the workers by
every schedule of :func:`workbench.experiment.sortlast.render_sortlast`: ``tree`` and
``swap`` (whole frames, as before), ``active-tree``, ``active-swap`` and ``radix`` (direct
send, and 2×4). The schedules are interleaved over ``--repeat`` rounds (default 5); per
schedule the median composite time with its range, the bytes that moved between workers and
the bytes the schedule sends, and whether the image equals the one-process frame. Then the same
domains drawn by GL (each worker's own EGL context) and composited by ``active-swap``, against
the image one context draws.

Run alone (it times): ``.venv/bin/python benchmarks/sortlast_composite_bench.py``.
"""

from __future__ import annotations

import argparse
import logging
import statistics

import numpy as np

SCHEDULES = (("tree", None), ("swap", None), ("active-tree", None), ("active-swap", None),
             ("radix", None), ("radix", (2, 4)))


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

    from workbench.experiment.measure import default_camera
    from workbench.experiment.sortlast import GLDomains, SoftwareDomains, render_sortlast
    from workbench.paths import Style
    from workbench.scene.builtin import fresh_scene
    from workbench.scene.domains import split_domains

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
        render_sortlast(client, software, domains, method="tree")  # workers load the scene
        for _ in range(args.repeat):
            for method, factors in SCHEDULES:
                frame, stats = render_sortlast(client, software, domains, method=method,
                                               factors=factors)
                name = method + ("" if factors is None else " " + "x".join(map(str, factors)))
                equal = (np.array_equal(frame.color, reference.color)
                         and np.array_equal(frame.triangle, reference.triangle))
                results.setdefault(name, []).append((stats.composite_s, stats.bytes_moved,
                                                     stats.schedule_bytes, equal))
        base = statistics.median(r[1] for r in results["swap"])
        print("| schedule | composite s, median [min, max] | moved MiB | of swap's | "
              "schedule MiB | equal |\n|---|---|---:|---:|---:|---|")
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
        frame, stats = render_sortlast(client, gl, domains, method="active-swap")
        print(f"GL domains, active-swap: {stats.composite_s:.3f} s, "
              f"{stats.bytes_moved / 2**20:.1f} MiB moved, image equal to one context: "
              f"{np.array_equal(frame.color, one_context)}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
