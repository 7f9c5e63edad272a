"""The es2008 scene at 100 M triangles, rendered sort-last on a LocalCluster of this machine's
workers, each loading only its own domains from a chunked scene on disk.

Steps (untimed): write 8 sheets of ``n``×``n`` quads (full 2500: 100 M triangles; quick 64) as
a chunked scene, one domain per sheet (:func:`workbench.distributed.bigscene.
write_semicylinders_chunked`; the writer holds one sheet at a time); start a LocalCluster of 2
worker processes (one thread each); render a small scene of as many domains first, so that
the workers' kernels are compiled; render once with the one-process reference and check the
images are equal (the benchmark stops otherwise). Timed: ``run_chunked_sortlast`` at
1000 × 1000 with ``local`` compositing (the reference left out), the run's own clocks giving
two rows, ``sortlast render`` and ``sortlast composite``. Columns: ``triangles``,
``scene_gib`` on disk, ``domain_mib`` (the largest domain in memory), ``idle_mib`` (an idle
worker, the fixed overhead), ``peak_mib`` (the largest worker's high-water mark in the
checked run), ``bytes_moved`` and ``reference_s``.

The full size is skipped on a machine with less than 16 GiB of memory: scaled from the quick
size, a domain (one sheet) takes some 650 MiB in memory, each worker holds four beside its
fixed 300 MiB, and the reference holds one more; the scene takes some 2 GiB on disk.

Run: ``workbench bench sortlast_100m [--quick]`` (needs dask's distributed).
"""

from __future__ import annotations

from workbench.measurement.bench import Case, benchmark, needs_memory_gib, needs_module

SHEETS, WORKERS, SIZE, METHOD, PATH = 8, 2, (1000, 1000), "local", "pixel_color"
FULL_MEMORY_GIB = 16  # an estimate (see above), not a measurement


@benchmark("sortlast_100m", "the es2008 scene at 100 M triangles rendered sort-last from a "
                            "chunked scene on disk",
           cases=[Case("chunked", {"n": 2500}, {"n": 64})],
           requires=[needs_module("dask", "distributed")])
def sortlast_100m(bench, n: int) -> None:
    import logging
    import shutil
    import tempfile
    from pathlib import Path

    import dask
    from distributed import Client, LocalCluster

    from workbench.distributed.bigscene import run_chunked_sortlast, write_semicylinders_chunked
    from workbench.distributed.sortlast import reset_peak_memory

    bench.require(not bench.quick and needs_memory_gib(FULL_MEMORY_GIB))
    root = Path(tempfile.mkdtemp(prefix="sortlast-100m-"))
    try:
        folder = write_semicylinders_chunked(root / "scene", SHEETS, n, path=PATH)
        disk = sum(f.stat().st_size for f in folder.rglob("*") if f.is_file())
        with dask.config.set({"distributed.worker.profile.enabled": False}):
            cluster = LocalCluster(n_workers=WORKERS, threads_per_worker=1, processes=True,
                                   dashboard_address=None, silence_logs=logging.ERROR,
                                   memory_limit=0)
        with cluster, Client(cluster) as client:
            client.wait_for_workers(WORKERS, timeout=120)
            write_semicylinders_chunked(root / "warm-up", SHEETS, 8, path=PATH, replace=True)
            run_chunked_sortlast(client, root / "warm-up", SIZE, method=METHOD, reference=False)
            idle = reset_peak_memory(client)
            _, checked = run_chunked_sortlast(client, folder, SIZE, method=METHOD)
            if not checked.equal:
                raise ValueError("the sort-last image differs from the one-process reference")

            def run() -> dict[str, float]:
                _, r = run_chunked_sortlast(client, folder, SIZE, method=METHOD,
                                            reference=False)
                return {"render": r.render_s, "composite": r.composite_s}

            bench.time_reported("sortlast", run, warmup=0, triangles=checked.triangles,
                                scene_gib=disk / 2**30, domain_mib=checked.domain_mib,
                                idle_mib=max(idle.values()),
                                peak_mib=max(checked.peak_mib.values()),
                                bytes_moved=checked.bytes_moved,
                                reference_s=checked.reference_s, method=METHOD)
    finally:
        shutil.rmtree(root, ignore_errors=True)
