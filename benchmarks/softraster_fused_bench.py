"""The fused, tile-parallel software rasterizer against the paper's per-step pipeline.

The es2008 benchmark (:func:`~workbench.scene.generators.semicylinders`: 8 sheets of
``--quads`` × ``--quads`` quads, 1 M triangles at 250, at ``--size`` pixels, seen from the
front as in the reproduction ``table_software_raster``), drawn by the software path with per-
pixel bands (``pixel_color``, 10 bands of ``distance``) and flat shading, by the steps
(``RasterOptions(fused=False)``) and fused, with 1 and 2 threads; with ``--gl``, llvmpipe's
position-only draw (the floor) on the EGL context as well. One draw of every configuration in
turn, ``--repeat`` rounds after ``--warmup``, so that a slow change of the machine reaches all
alike. Printed per configuration: the median wall ms, its spread (min, max, interquartile
range), and the median of the per-round ratios: the steps over fused (same threads), 1 thread
over 2 (same renderer), llvmpipe's floor over the draw; and whether the fused images equal the
steps' (colour, depth, triangle index).

Run: ``.venv/bin/python benchmarks/softraster_fused_bench.py [--repeat 15] [--quads 250]
[--size 1000] [--paths pixel_color,flat] [--gl]``.
"""

from __future__ import annotations

import argparse
import statistics
import time
from contextlib import ExitStack

from workbench.algo.softraster import RasterOptions
from workbench.measurement.rows import default_camera, prepared
from workbench.paths import SoftwareRasterizer, Style
from workbench.scene.generators import semicylinders

WHITE = (1.0, 1.0, 1.0, 1.0)
STYLES = {"pixel_color": Style(field="distance", bands=10), "flat": Style()}


def parse(argv=None) -> argparse.Namespace:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--repeat", type=int, default=15, help="timed rounds (default 15)")
    p.add_argument("--warmup", type=int, default=2, help="untimed rounds first (default 2)")
    p.add_argument("--quads", type=int, default=250, help="quads a side per sheet (250: 1 M "
                   "triangles)")
    p.add_argument("--size", type=int, default=1000, help="image width and height in pixels")
    p.add_argument("--paths", default="pixel_color,flat",
                   help=f"comma-separated, of {', '.join(STYLES)}")
    p.add_argument("--gl", action="store_true", help="time llvmpipe's position-only draw too")
    args = p.parse_args(argv)
    paths = args.paths.split(",")
    if any(name not in STYLES for name in paths) or args.repeat < 1 or args.warmup < 0 \
            or args.quads < 1 or args.size < 1:
        p.error(f"--paths from {', '.join(STYLES)}; --repeat, --quads and --size positive, "
                f"--warmup not negative")
    args.paths = paths
    return args


def configurations(paths):
    """(label, path name, renderer, threads): the steps and fused, 1 and 2 threads."""
    for name in paths:
        for renderer in ("steps", "fused"):
            for threads in (1, 2):
                yield f"{name} {renderer} {threads}t", name, renderer, threads


def spread(ms: list[float]) -> str:
    q1, _, q3 = statistics.quantiles(ms, n=4) if len(ms) > 1 else (ms[0], 0, ms[0])
    return (f"{statistics.median(ms):8.1f} ms  (min {min(ms):6.1f}, max {max(ms):6.1f}, "
            f"IQR {q3 - q1:5.1f})")


def ratio(times: dict, a: str, b: str) -> str:
    """Median of a_i / b_i over the rounds, with its range."""
    r = [x / y for x, y in zip(times[a], times[b])]
    return f"{statistics.median(r):5.2f}x  [{min(r):.2f}, {max(r):.2f}]"


def main(argv=None) -> int:
    args = parse(argv)
    mesh = semicylinders(8, args.quads)
    size = (args.size, args.size)
    camera = default_camera(mesh, size, view=(0.0, 0.0), up="y")
    print(f"{len(mesh.triangles)} triangles at {size[0]}x{size[1]}, {args.repeat} rounds "
          f"after {args.warmup}")
    with ExitStack() as stack:
        ready = {}
        for label, name, renderer, threads in configurations(args.paths):
            options = RasterOptions(threads=threads, fused=renderer == "fused")
            ready[label] = stack.enter_context(prepared(
                SoftwareRasterizer(options), mesh, name, STYLES[name], camera, size))
        if args.gl:
            from workbench.gl import create_context, renderer

            ctx = create_context()
            ready["llvmpipe position"] = stack.enter_context(
                prepared(ctx, mesh, "position", Style(), camera, size))
            print(f"GL: {renderer(ctx)}")
        times = {label: [] for label in ready}
        for round_ in range(args.warmup + args.repeat):
            for label, r in ready.items():
                r.bind()
                r.target.clear(WHITE)
                r.backend.finish()
                start = time.perf_counter()
                r.path.draw()
                r.backend.finish()
                if round_ >= args.warmup:
                    times[label].append((time.perf_counter() - start) * 1e3)
        print("\nmedian wall time per draw")
        for label, ms in times.items():
            print(f"  {label:24s} {spread(ms)}")
        print("\nsteps / fused (same threads), 1 thread / 2 threads (same renderer)")
        for name in args.paths:
            for threads in (1, 2):
                print(f"  {name} {threads}t   steps / fused  "
                      f"{ratio(times, f'{name} steps {threads}t', f'{name} fused {threads}t')}")
            for renderer in ("steps", "fused"):
                print(f"  {name} {renderer:5s} 1t / 2t       "
                      f"{ratio(times, f'{name} {renderer} 1t', f'{name} {renderer} 2t')}")
        if args.gl:
            print("\nllvmpipe's position-only floor / software draw")
            for label in times:
                if label != "llvmpipe position":
                    print(f"  {label:24s} {ratio(times, 'llvmpipe position', label)}")
        print("\nfused images against the steps' (colour, depth, triangle index)")
        for name in args.paths:
            ref = ready[f"{name} steps 1t"].target.frame
            for threads in (1, 2):
                frame = ready[f"{name} fused {threads}t"].target.frame
                diff = [int((getattr(frame, a) != getattr(ref, a)).any(axis=-1).sum()
                            if a == "color" else (getattr(frame, a) != getattr(ref, a)).sum())
                        for a in ("color", "depth", "triangle")]
                print(f"  {name} fused {threads}t: differing pixels {diff}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
