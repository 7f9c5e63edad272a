"""Results-store benchmark: write N synthetic measurement rows, then time three queries.

The rows (columns experiment, table, scene, path, style, renderer, size, wall_ms, wall_ms_lo,
wall_ms_hi, ssim, error, max_diff_255, triangles and a 9-sample ``wall_samples_ms`` list) go
through ``ResultsStore.append_rows`` into ``--files`` files spread over 10 runs on 2 machines,
in a temporary folder. Each query then runs ``--repeat`` times, each time through a new
``ResultsStore`` (no cached footers) and a new DuckDB connection; the time covers connecting,
creating the views, running the query and fetching the result as a pyarrow Table.

1. **median**: ``SELECT path, median(wall_ms) FROM rows WHERE renderer = 'x' GROUP BY path``
   (target: < 1 s for 1 000 000 rows in 100 files).
2. **join**: rows × runs × machines, filtered by ``error < e``, counted per machine and path.
3. **count**: ``SELECT count(*) FROM rows``.

Prints the write time and, per query, the median and min–max in ms.

Run: ``.venv/bin/python benchmarks/results_query_bench.py [--rows 1000000] [--files 100]
[--repeat 7] [--seed 0] [--keep DIR]``.
"""

from __future__ import annotations

import argparse
import random
import shutil
import statistics
import tempfile
import time
from pathlib import Path

from workbench.results.store import ResultsStore

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


def write_store(root: Path, rows: int, files: int, seed: int) -> float:
    """Fill a store at ``root``; returns the seconds spent in ``append_rows`` (generation
    excluded)."""
    rng = random.Random(seed)
    store = ResultsStore(root)
    runs = [f"bench-{i:02d}" for i in range(10)]
    for i in range(2):
        store.record_machine({"machine_id": f"m{i}", "cpu": f"cpu {i}", "renderer": "x"})
    for i, run_id in enumerate(runs):
        store.record_run({"run_id": run_id, "machine_id": f"m{i % 2}", "started": float(i)})
    spent = 0.0
    for f in range(files):
        batch = synthetic_rows(rows // files + (f < rows % files), rng)
        start = time.perf_counter()
        store.append_rows(runs[f % len(runs)], batch, experiment="render_paths", table="table")
        spent += time.perf_counter() - start
    return spent


def time_query(root: Path, sql: str, repeat: int) -> list[float]:
    """Milliseconds for each of ``repeat`` runs of ``sql`` through a fresh store and
    connection."""
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        ResultsStore(root).query(sql)
        times.append((time.perf_counter() - start) * 1e3)
    return times


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--rows", type=int, default=1_000_000)
    parser.add_argument("--files", type=int, default=100)
    parser.add_argument("--repeat", type=int, default=7)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--keep", type=Path, help="write the store here and keep it")
    args = parser.parse_args(argv)
    root = args.keep or Path(tempfile.mkdtemp(prefix="results_bench_"))
    try:
        write_s = write_store(root, args.rows, args.files, args.seed)
        print(f"write: {args.rows} rows in {args.files} files: {write_s:.2f} s "
              f"({write_s / args.files * 1e3:.0f} ms per append_rows)")
        for name, sql in QUERIES.items():
            times = time_query(root, sql, args.repeat)
            print(f"{name:7s} median {statistics.median(times):7.1f} ms   "
                  f"min–max {min(times):7.1f}–{max(times):7.1f} ms   ({args.repeat} runs)")
    finally:
        if args.keep is None:
            shutil.rmtree(root, ignore_errors=True)


if __name__ == "__main__":
    main()
