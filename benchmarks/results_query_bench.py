"""Results-store benchmark: write N synthetic measurement rows, then time three queries.

The rows (columns experiment, table, scene, path, style, renderer, size, wall_ms, wall_ms_lo,
wall_ms_hi, ssim, error, max_diff_255, triangles and a 9-sample ``wall_samples_ms`` list) go
through ``ResultsStore.append_rows`` into ``files`` files spread over 10 runs on 2 machines,
in a temporary folder (full: 1 000 000 rows in 100 files; quick: 20 000 in 10). Each query is
then timed, each call through a new ``ResultsStore`` (no cached footers) and a new DuckDB
connection: connecting, creating the views, running the query and fetching the result.

1. **median**: ``SELECT path, median(wall_ms) FROM rows WHERE renderer = 'x' GROUP BY path``
   (target: < 1 s for 1 000 000 rows in 100 files).
2. **join**: rows × runs × machines, filtered by ``error < e``, counted per machine and path.
3. **count**: ``SELECT count(*) FROM rows``.

Rows: one per query, and ``append_rows`` (the write, timed per file).

Run: ``workbench bench results_query_bench [--quick]``.
"""

from __future__ import annotations

import random
import shutil
import tempfile
from pathlib import Path

from workbench.measurement.bench import Case, benchmark

SCENES = ["semicylinders:32", "car", "flange", "membrane", "forcetube"]
PATHS = ["position", "flat", "gouraud", "vertex_color", "pixel_color", "texture", "software"]
STYLES = ["solid", "wireframe", "bands"]
RENDERERS = ["llvmpipe", "nvidia", "x"]
SIZES = ["400x400", "800x800", "1920x1080"]

QUERIES = {
    "median": "SELECT path, median(wall_ms) FROM rows WHERE renderer = 'x' GROUP BY path",
    "join": ("SELECT m.machine_id, r.path, count(*) AS n, avg(r.wall_ms) AS wall_ms "
             "FROM rows r JOIN runs u ON r.run_id = u.run_id "
             "JOIN machines m ON u.machine_id = m.machine_id "
             "WHERE r.error < 0.01 GROUP BY ALL"),
    "count": "SELECT count(*) FROM rows",
}


def synthetic_rows(n: int, rng: random.Random) -> list[dict]:
    """``n`` measurement rows with realistic columns and value ranges."""
    rows = []
    for _ in range(n):
        samples = sorted(rng.lognormvariate(0.5, 0.3) for _ in range(9))
        rows.append({
            "scene": rng.choice(SCENES), "path": rng.choice(PATHS), "style": rng.choice(STYLES),
            "renderer": rng.choice(RENDERERS), "size": rng.choice(SIZES),
            "wall_ms": samples[4], "wall_ms_lo": samples[1], "wall_ms_hi": samples[7],
            "ssim": 1.0 - rng.random() * 0.05, "error": rng.random() * 0.05,
            "max_diff_255": rng.randrange(0, 256), "triangles": rng.randrange(1000, 5_000_000),
            "wall_samples_ms": samples,
        })
    return rows


@benchmark("results_query_bench", "results store: append rows, then three DuckDB queries",
           cases=[Case("store", {"rows": 1_000_000, "files": 100},
                       {"rows": 20_000, "files": 10})])
def results_query(bench, rows: int, files: int) -> None:
    from workbench.results.store import ResultsStore

    rng = random.Random(0)
    root = Path(tempfile.mkdtemp(prefix="results_bench_"))
    try:
        store = ResultsStore(root)
        runs = [f"bench-{i:02d}" for i in range(10)]
        for i in range(2):
            store.record_machine({"machine_id": f"m{i}", "cpu": f"cpu {i}", "renderer": "x"})
        for i, run_id in enumerate(runs):
            store.record_run({"run_id": run_id, "machine_id": f"m{i % 2}", "started": float(i)})
        batches = [synthetic_rows(rows // files + (f < rows % files), rng) for f in range(files)]
        written = iter(range(files))

        def append() -> None:
            f = next(written)
            store.append_rows(runs[f % len(runs)], batches[f], experiment="render_paths",
                              table="table")

        # every file is one timed call (at least 5 files: the median needs them)
        bench.time("append_rows", append, warmup=0, repeat=files, rows_per_file=rows // files)
        for name, sql in QUERIES.items():
            bench.time(name, lambda sql=sql: ResultsStore(root).query(sql), stored_rows=rows,
                       files=files)
    finally:
        shutil.rmtree(root, ignore_errors=True)
