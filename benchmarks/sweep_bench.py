"""Sweep benchmarks: what a cached point costs, what a second worker gives, kill and resume.

Cases:

1. **skip**: a grid of cheap untimed points (full 1 000, quick 40) is run once (every point
   computed, untimed), then again and again; a rerun computes nothing, and the reported
   time is the median per point to compute its key and read its stored row
   (``SweepResult.skip_ms``; target < 5 ms), row ``cached point``.
2. **scaling**: a grid of error-only points (``timed = false``: drawn once, compared with the
   reference path's image; full 60 at 400 × 400, quick 12 at 100 × 100) on a LocalCluster of
   1 and of 2 workers (each run its own cluster), interleaved without a warm-up round; the
   reported time is the compute phase (``SweepResult.compute_s``: submitting to storing the
   last, cluster start-up excluded);
   ``1 worker`` carries ``over_2_workers`` (the speed-up; target on 2 cores >= 1.6) and the
   column ``machine_scaling`` (what 2 processes give pure-Python work at that moment).
3. **resume**: ``workbench sweep sweeps/bands_vertex_pixel.toml --quick`` killed with SIGKILL
   at random moments (full 5 times, quick once; during start-up, or once 1 to 3 more points
   are stored, plus a random delay of up to 0.5 s), then run to the end; after every run no
   point file written before it may have been rewritten (same inode and mtime), and the final
   table must equal a clean run's in every column but times and run ids. Row ``resume``
   (``recomputed_finished``, ``table_matches_clean``, ``kills``) and the timed clean run.

Run: ``workbench bench sweep_bench [--quick]`` (scaling and resume need an OpenGL context).
"""

from __future__ import annotations

import random
import signal
import statistics
import subprocess
import sys
import tempfile
import textwrap
import time
from pathlib import Path

from workbench.measurement.bench import Case, benchmark, needs_gl

ROOT = Path(__file__).resolve().parents[1]
SWEEP = [sys.executable, "-m", "workbench.cli.sweep"]

SKIP_GRID = """
    name = "skip"
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
    size = "{size}"
"""


def _config(folder: Path, text: str, name: str) -> Path:
    path = folder / f"{name}.toml"
    path.write_text(textwrap.dedent(text))
    return path


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


@benchmark("sweep_bench", "sweeps: a cached point's cost, 1 against 2 workers, kill and resume",
           cases=[Case("skip", {"bands": 250}, {"bands": 10}),
                  Case("scaling", {"bands": 15, "size": "400x400"},
                       {"bands": 3, "size": "100x100"}),
                  Case("resume", {"kills": 5}, {"kills": 1})])
def sweep_bench(bench, bands: int = 0, size: str = "", kills: int = 0) -> None:
    from workbench.sweep import load_config, run_sweep

    with tempfile.TemporaryDirectory(prefix="sweep_bench_") as name:
        folder = Path(name)
        if bench.case.name == "skip":
            config = load_config(_config(
                folder, SKIP_GRID.format(bands=", ".join(map(str, range(bands)))), "skip"))
            out = folder / "skip"
            first = run_sweep(config, out, progress=False)  # computes every point, untimed
            bench.time_reported(
                "cached point",
                lambda: statistics.median(run_sweep(config, out, progress=False).skip_ms) / 1e3,
                points=4 * bands, first_run_failed=first.failed)
            return
        bench.require(needs_gl())
        if bench.case.name == "scaling":
            config = load_config(_config(folder, SCALING_GRID.format(
                bands=", ".join(map(str, range(bands))), size=size), "scaling"))
            runs = iter(range(10**6))

            def clock(workers: int):
                def run() -> float:
                    result = run_sweep(config, folder / f"scaling_{next(runs)}",
                                       workers=workers, progress=False)
                    if result.failed or result.computed != len(result.rows):
                        raise ValueError(f"scaling sweep: {result.failed} points failed")
                    return result.compute_s
                return run

            bench.interleave({"1 worker": clock(1), "2 workers": clock(2)},
                             [("1 worker", "2 workers")], warmup=0, reported=True,
                             points=4 * bands, machine_scaling=machine_scaling())
            return
        r = bench_resume(folder, kills, seed=0)
        bench.record("resume", kills=kills, recomputed_finished=r["recomputed_finished_total"],
                     table_matches_clean=r["table_matches_clean"], clean_run_s=r["clean_run_s"],
                     final_summary=r["final_summary"])
        if r["recomputed_finished_total"] or not r["table_matches_clean"]:
            raise ValueError(f"resume: {r['recomputed_finished_total']} finished points "
                             f"recomputed, table matches the clean run: "
                             f"{r['table_matches_clean']}")
