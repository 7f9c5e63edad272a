"""Sweep benchmarks: what a cached point costs, what a second worker gives, kill and resume.

1. **skip**: a 1 000-point grid of cheap untimed points is run once, then again; the second
   run computes nothing, and the median time per point to compute its key and read its
   stored row (``SweepResult.skip_ms``) is reported (target: < 5 ms).
2. **scaling**: a grid of error-only points (``timed = false``: drawn once, compared with the
   reference path's image) on a LocalCluster of 1 and of 2 workers; points per second of the
   compute phase (``SweepResult.compute_s``: submitting to storing the last, cluster start-up
   excluded) and their ratio (target on 2 cores: >= 1.6).
3. **resume**: ``workbench sweep sweeps/bands_vertex_pixel.toml --quick`` killed with SIGKILL at
   random moments ``--kills`` times (during start-up, or once 1 to 3 more points are stored,
   plus a random delay of up to 0.5 s), then run to the end; after every run no point file
   written before it may have been rewritten (same inode and mtime), and the final table must
   equal a clean run's in every column but times and run ids.

Run: ``.venv/bin/python benchmarks/sweep_bench.py [--only skip,scaling,resume] [--kills 5]
[--seed 0] [--keep DIR]``.
"""

from __future__ import annotations

import argparse
import random
import shutil
import signal
import statistics
import subprocess
import sys
import tempfile
import textwrap
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SWEEP = [sys.executable, "-m", "workbench.cli.sweep"]

SKIP_GRID = """
    name = "skip_1000"
    timed = false
    [grid]
    scene = "semicylinders:2"
    path = ["position", "flat", "gouraud", "vertex_color"]
    bands = [{bands}]
    field = "distance"
    size = "16x16"
"""

SCALING_GRID = """
    name = "scaling"
    timed = false
    reference = "pixel_color"
    [grid]
    scene = "semicylinders:32"
    path = ["vertex_color", "pixel_color", "gouraud", "flat"]
    bands = [{bands}]
    field = "distance"
    size = "400x400"
"""


def _config(folder: Path, text: str, name: str) -> Path:
    path = folder / f"{name}.toml"
    path.write_text(textwrap.dedent(text))
    return path


def bench_skip(folder: Path) -> dict:
    """Median ms to skip a cached point, over a 1 000-point sweep run twice."""
    from workbench.sweep import load_config, run_sweep

    config = load_config(_config(folder, SKIP_GRID.format(bands=", ".join(map(str, range(250)))),
                                 "skip"))
    out = folder / "skip"
    start = time.perf_counter()
    first = run_sweep(config, out, progress=False)
    first_s = time.perf_counter() - start
    start = time.perf_counter()
    second = run_sweep(config, out, progress=False)
    second_s = time.perf_counter() - start
    assert first.computed == 1000 and second.computed == 0 and second.cached == 1000
    skips = sorted(second.skip_ms)
    return dict(points=len(second.rows), first_run_s=first_s, first_failed=first.failed,
                second_run_s=second_s, skip_median_ms=statistics.median(skips),
                skip_p95_ms=skips[int(0.95 * (len(skips) - 1))], skip_max_ms=skips[-1],
                skip_total_s=sum(skips) / 1e3)


def _spin(_) -> float:
    start = time.perf_counter()
    total = 0
    for i in range(5_000_000):
        total += i
    return time.perf_counter() - start


def machine_scaling() -> float:
    """How much faster 2 processes finish 2 pieces of pure-Python work than 1 process finishes
    one after the other, now: 2.0 on two idle cores, less while other programs run."""
    from concurrent.futures import ProcessPoolExecutor

    with ProcessPoolExecutor(2) as pool:
        list(pool.map(_spin, range(2)))  # start both processes
        start = time.perf_counter()
        for _ in range(2):
            pool.submit(_spin, 0).result()
        one = time.perf_counter() - start
        start = time.perf_counter()
        list(pool.map(_spin, range(2)))
        return one / (time.perf_counter() - start)


def bench_scaling(folder: Path, bands: int = 15, rounds: int = 2) -> dict:
    """Points per second of error-only points on 1 and on 2 workers, the best of ``rounds``
    alternating runs each (other programs on the machine only ever slow a run down)."""
    from workbench.sweep import load_config, run_sweep

    config = load_config(_config(
        folder, SCALING_GRID.format(bands=", ".join(map(str, range(bands)))), "scaling"))
    best = {1: 0.0, 2: 0.0}
    for round_ in range(rounds):
        for workers in (1, 2):
            result = run_sweep(config, folder / f"scaling_{workers}_{round_}", workers=workers,
                               progress=False)
            assert result.computed == len(result.rows) and result.failed == 0
            best[workers] = max(best[workers], result.computed / result.compute_s)
    return dict(points=len(result.rows), points_per_s_1=best[1], points_per_s_2=best[2],
                speedup=best[2] / best[1], machine_scaling=machine_scaling(),
                load=Path("/proc/loadavg").read_text().split()[0])


def _stamps(points: Path) -> dict[str, tuple[int, int]]:
    return {p.name: (p.stat().st_ino, p.stat().st_mtime_ns) for p in points.glob("*.json")}


def _stable(out: Path) -> list[dict]:
    from workbench.output.tables import read_table
    from workbench.sweep import stable_row

    return [stable_row(r) for r in read_table(out / "table.csv")]


def _kill_at_random(proc, points: Path, stored: int, rng: random.Random) -> int:
    """SIGKILL ``proc`` at a random moment: during start-up (before any new point is stored)
    or after 1 to 3 new point files, plus up to 0.5 s; returns the new points waited for."""
    wait_for = rng.randint(0, 3)
    deadline = time.monotonic() + (rng.uniform(0.5, 3.0) if wait_for == 0 else 600)
    while proc.poll() is None and time.monotonic() < deadline:
        if wait_for and points.exists() and len(list(points.glob("*.json"))) >= stored + wait_for:
            break
        time.sleep(0.01)
    time.sleep(rng.uniform(0.0, 0.5) if wait_for else 0.0)
    if proc.poll() is None:
        proc.send_signal(signal.SIGKILL)
    proc.wait()
    return wait_for


def bench_resume(folder: Path, kills: int = 5, seed: int = 0) -> dict:
    """SIGKILL the quick example sweep ``kills`` times at random moments, then finish it."""
    config = ROOT / "sweeps" / "bands_vertex_pixel.toml"
    clean = folder / "resume_clean"
    start = time.perf_counter()
    done = subprocess.run([*SWEEP, str(config), "--quick", "--out", str(clean)],
                          capture_output=True, text=True)
    clean_s = time.perf_counter() - start
    assert done.returncode == 0, done.stderr
    out = folder / "resume_killed"
    points = out / "points"
    rng = random.Random(seed)
    runs, rewritten = [], 0
    for _ in range(kills + 1):
        before = _stamps(points) if points.exists() else {}
        start = time.perf_counter()
        proc = subprocess.Popen([*SWEEP, str(config), "--quick", "--out", str(out)],
                                stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
        if len(runs) == kills:
            proc.wait()
            wait_for = None
        else:
            wait_for = _kill_at_random(proc, points, len(before), rng)
        after = _stamps(points) if points.exists() else {}
        changed = sum(1 for name, stamp in before.items() if after.get(name) != stamp)
        rewritten += changed
        runs.append(dict(kill_after_s=None if wait_for is None else time.perf_counter() - start,
                         waited_for_points=wait_for, killed=proc.returncode == -signal.SIGKILL,
                         finished_before=len(before), finished_after=len(after),
                         recomputed_finished=changed))
    summary = proc.stdout.read().splitlines()[-1] if proc.returncode == 0 else None
    return dict(clean_run_s=clean_s, runs=runs, recomputed_finished_total=rewritten,
                final_summary=summary, table_matches_clean=_stable(out) == _stable(clean))


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", default="skip,scaling,resume",
                        help="comma-separated benchmarks to run (default all)")
    parser.add_argument("--kills", type=int, default=5)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--keep", metavar="DIR", help="work in DIR and keep it")
    args = parser.parse_args(argv)
    folder = Path(args.keep) if args.keep else Path(tempfile.mkdtemp(prefix="sweep_bench_"))
    folder.mkdir(parents=True, exist_ok=True)
    chosen = args.only.split(",")
    ok = True
    try:
        if "skip" in chosen:
            r = bench_skip(folder)
            ok &= r["skip_median_ms"] < 5
            print(f"skip: {r['points']} cached points, median {r['skip_median_ms']:.3f} ms per "
                  f"point (p95 {r['skip_p95_ms']:.3f}, max {r['skip_max_ms']:.3f}, "
                  f"{r['skip_total_s']:.2f} s in all); whole rerun {r['second_run_s']:.1f} s "
                  f"(first run {r['first_run_s']:.1f} s, {r['first_failed']} failed)", flush=True)
        if "scaling" in chosen:
            r = bench_scaling(folder)
            ok &= r["speedup"] >= 1.6
            print(f"scaling: {r['points']} error-only points, 1 worker "
                  f"{r['points_per_s_1']:.2f} points/s, 2 workers {r['points_per_s_2']:.2f} "
                  f"points/s: {r['speedup']:.2f}x (the machine gives {r['machine_scaling']:.2f}x "
                  f"to pure-Python work right now; load average {r['load']})", flush=True)
        if "resume" in chosen:
            r = bench_resume(folder, args.kills, args.seed)
            ok &= r["recomputed_finished_total"] == 0 and r["table_matches_clean"]
            for i, run in enumerate(r["runs"]):
                when = "to the end" if run["kill_after_s"] is None else (
                    f"SIGKILL after {run['kill_after_s']:.1f} s "
                    + (f"({run['waited_for_points']} new points, then up to 0.5 s)"
                       if run["waited_for_points"] else "(during start-up)")
                    + ("" if run["killed"] else ", but it had already ended"))
                print(f"resume run {i + 1}: {when}: {run['finished_before']} -> "
                      f"{run['finished_after']} points stored, {run['recomputed_finished']} "
                      f"finished points recomputed", flush=True)
            print(f"resume: clean run {r['clean_run_s']:.1f} s; recomputed finished points "
                  f"{r['recomputed_finished_total']}; final table matches the clean run: "
                  f"{r['table_matches_clean']}; {r['final_summary']}", flush=True)
    finally:
        if not args.keep:
            shutil.rmtree(folder, ignore_errors=True)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
