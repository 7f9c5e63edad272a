"""The es2008 scene at 100 M triangles, rendered sort-last on a LocalCluster of this machine's
workers, each loading only its own domains from a chunked scene on disk.

Steps: write ``--sheets`` sheets of ``--n``×``--n`` quads (default 8 × 2500²: 100 M triangles)
as a chunked scene, one domain per sheet (:func:`workbench.distributed.bigscene.
write_semicylinders_chunked`; the writer holds one sheet at a time); start a LocalCluster of
``--workers`` worker processes (one thread each); render at ``--size`` with ``--method``
compositing (default ``local``; :func:`~workbench.distributed.bigscene.run_chunked_sortlast`; a
small scene of as many domains first, so that the workers' kernels are compiled), then render
the reference in this process domain by domain and compare. Printed: triangles, write time, render
and composite time, triangles/s, bytes moved, each worker's peak resident memory next to the
largest domain's in-memory size and the memory of an idle worker (the fixed overhead), the
reference time and whether the images are equal. Peak memory is each worker's high-water mark,
reset after the warm-up (the idle memory then is the fixed overhead). The scene folder is removed
at the end unless ``--keep`` (or ``--reuse``: render a scene already written to ``--folder``).

Run alone (it times): ``.venv/bin/python benchmarks/sortlast_100m.py [--n 2500] [--sheets 8]``.
"""

from __future__ import annotations

import argparse
import logging
import shutil
import tempfile
import time
from pathlib import Path


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sheets", type=int, default=8)
    parser.add_argument("--n", type=int, default=2500, help="quads per sheet edge (2500)")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--size", default="1000x1000")
    parser.add_argument("--method", default="local",
                        choices=("local", "tree", "swap", "active-tree", "active-swap", "radix"))
    parser.add_argument("--path", default="pixel_color")
    parser.add_argument("--folder", help="where to write the scene (default: a temporary one)")
    parser.add_argument("--keep", action="store_true", help="keep the scene folder")
    parser.add_argument("--reuse", action="store_true",
                        help="render the scene already in --folder (written when absent); keeps it")
    args = parser.parse_args(argv)
    size = tuple(int(v) for v in args.size.lower().split("x"))

    import dask
    from distributed import Client, LocalCluster

    from workbench.distributed.bigscene import run_chunked_sortlast, write_semicylinders_chunked
    from workbench.distributed.sortlast import reset_peak_memory

    root = Path(args.folder) if args.folder else Path(tempfile.mkdtemp(prefix="sortlast-100m-"))
    folder = root / "scene"
    try:
        start = time.perf_counter()

        def written(k: int) -> None:
            print(f"  sheet {k} written ({time.perf_counter() - start:.0f} s)", flush=True)

        if args.reuse and (folder / "scene.json").is_file():
            print(f"  reusing the scene in {folder}")
        else:
            write_semicylinders_chunked(folder, args.sheets, args.n, path=args.path,
                                        progress=written, replace=args.reuse)
        write_s = time.perf_counter() - start
        disk = sum(f.stat().st_size for f in folder.rglob("*") if f.is_file())
        with dask.config.set({"distributed.worker.profile.enabled": False}):
            cluster = LocalCluster(n_workers=args.workers, threads_per_worker=1, processes=True,
                                   dashboard_address=None, silence_logs=logging.ERROR,
                                   memory_limit=0)
        with cluster, Client(cluster) as client:
            client.wait_for_workers(args.workers, timeout=120)
            # a small scene first: the workers compile their kernels, and their memory after
            # it is the fixed overhead
            write_semicylinders_chunked(root / "warm-up", args.sheets, 8, path=args.path,
                                        replace=True)
            run_chunked_sortlast(client, root / "warm-up", size, method=args.method,
                                 reference=False)
            idle = reset_peak_memory(client)
            image, run = run_chunked_sortlast(client, folder, size, method=args.method)
        overhead = max(idle.values())
        print(f"| triangles | {run.triangles:,} |")
        print(f"| domains / workers | {run.domains} / {run.workers} |")
        print(f"| scene on disk | {disk / 2**30:.2f} GiB, written in {write_s:.1f} s |")
        print(f"| render (cluster) | {run.render_s:.2f} s, {run.triangles_per_s / 1e6:.1f} M "
              f"triangles/s |")
        print(f"| composite ({run.method}) | {run.composite_s:.3f} s, "
              f"{run.bytes_moved / 2**20:.1f} MiB moved |")
        print(f"| largest domain in memory | {run.domain_mib:.0f} MiB |")
        print(f"| idle worker (fixed overhead) | {overhead:.0f} MiB |")
        for address, peak in sorted(run.peak_mib.items()):
            share = run.share_mib[address]
            print(f"| peak of worker {address} | {peak:.0f} MiB = overhead + "
                  f"{(peak - overhead) / share:.2f} x its share of {share:.0f} MiB "
                  f"({(peak - overhead) / run.domain_mib:.2f} x the largest domain) |")
        print(f"| reference (one process, domain by domain) | {run.reference_s:.1f} s |")
        print(f"| images equal | {run.equal} |")
    finally:
        if not (args.keep or args.reuse):
            shutil.rmtree(root if not args.folder else folder, ignore_errors=True)
    return 0 if run.equal else 1


if __name__ == "__main__":
    raise SystemExit(main())
