"""Sort-last compositing with whole frames against active pixels, in one process.

The es2008 benchmark (8 semi-cylindrical sheets of 250 × 250 quads, 1 M triangles, seen from
the front at 1000 × 1000 with per-pixel distance bands, as the compositing table of
``table_software_raster`` draws it) is split into 8 domains by space
(:func:`workbench.distributed.domains.split_domains`) and each domain drawn by the software
rasterizer. The 8 frames are then composited, in this process, by:

* full-frame binary tree and binary swap (:mod:`workbench.algo.composite.merge`: whole
  frames or halves sent, 16 bytes a pixel);
* active-pixel binary tree, binary swap and radix-k with factors 2x2x2, 2x4, 4x2 and 8 (direct
  send) (:mod:`workbench.algo.composite.active`: bounding box + run lengths of the drawn
  pixels sent).

Per schedule: bytes sent between ranks (as the schedule counts them), their share of the
full-frame tree's and swap's, and the composite wall time (the whole in-process schedule,
domain frames in, final frame out; median and minimum of ``--repeat`` runs, the schedules run
in turn so that load drifts hit them alike). Every result is checked against
``functools.reduce(composite, frames)`` and the one-process image of all triangles.
Targets for the active schedules: bytes <= 25 % of the full-frame schedules', composite
<= 0.1 s.

Run: ``.venv/bin/python benchmarks/composite_active_bench.py [--quads 250] [--size 1000]
[--domains 8] [--repeat 7]``.
"""

from __future__ import annotations

import argparse
import functools
import statistics
import time

import numpy as np

from workbench.algo.composite.merge import binary_swap, binary_tree, composite
from workbench.algo.composite.schedules import active_radix, active_swap, active_tree
from workbench.distributed.domains import split_domains
from workbench.distributed.sortlast import SoftwareDomains
from workbench.measurement.rows import default_camera
from workbench.paths import Style
from workbench.scene.generators import semicylinders

BANDS = dict(field="distance", bands=10)  # the compositing table's shading
TARGET_SHARE, TARGET_S = 0.25, 0.1


def frames_of(quads: int, size: int, domains: int):
    """(domain frames, one-process frame, seconds to draw the domains)."""
    camera = default_camera(semicylinders(8, quads), (size, size), view=(0.0, 0.0), up="y")
    render = SoftwareDomains(f"semicylinders:{quads}", "pixel_color", Style(**BANDS), camera,
                             (size, size))
    parts = split_domains(render.prepared().mesh, domains, by="space")
    start = time.perf_counter()
    frames = [render(ids) for ids in parts]
    drawn = time.perf_counter() - start
    whole = render(np.arange(render.prepared().triangles))
    return frames, whole, drawn


def schedules(domains: int):
    yield "full-frame tree", binary_tree
    yield "full-frame swap", binary_swap
    yield "active tree", active_tree
    yield "active swap", active_swap
    for factors in radix_factors(domains):
        name = "active radix-k " + "x".join(map(str, factors))
        yield name, functools.partial(active_radix, factors=factors)


def radix_factors(domains: int) -> list[tuple[int, ...]]:
    """All ordered factorisations of ``domains`` into factors >= 2 (2x2x2, 2x4, 4x2, 8 for 8)."""
    if domains == 1:
        return [()]
    return [(k,) + rest for k in range(2, domains + 1) if domains % k == 0
            for rest in radix_factors(domains // k)]


def same(a, b) -> bool:
    return all(x.dtype == y.dtype and x.tobytes() == y.tobytes()
               for x, y in ((a.color, b.color), (a.depth, b.depth), (a.triangle, b.triangle)))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quads", type=int, default=250, help="quads per sheet side")
    parser.add_argument("--size", type=int, default=1000, help="image side in pixels")
    parser.add_argument("--domains", type=int, default=8)
    parser.add_argument("--repeat", type=int, default=7, help="timed runs per schedule")
    args = parser.parse_args()

    frames, whole, drawn = frames_of(args.quads, args.size, args.domains)
    covered = [float((f.triangle >= 0).mean()) for f in frames]
    print(f"semicylinders:{args.quads} at {args.size}x{args.size}, {args.domains} domains by "
          f"space, drawn in {drawn:.2f} s; drawn share per frame "
          f"{min(covered):.1%}..{max(covered):.1%}")
    expected = functools.reduce(composite, frames)
    assert same(expected, whole), "the composite of the domains is not the one-process image"

    runs = dict(schedules(args.domains))
    seconds = {name: [] for name in runs}
    stats = {}
    for name, schedule in runs.items():  # warm-up and check
        out, stats[name] = schedule(frames)
        assert same(out, expected), f"{name}: not functools.reduce(composite, frames)"
    for _ in range(args.repeat):
        for name, schedule in runs.items():
            seconds[name].append(schedule(frames)[1].seconds)

    full = {"tree": stats["full-frame tree"].bytes_moved,
            "swap": stats["full-frame swap"].bytes_moved}
    print(f"\n{'schedule':24s} {'rounds':>6s} {'MB sent':>8s} {'/ tree':>7s} {'/ swap':>7s} "
          f"{'median s':>9s} {'min s':>7s}  per round MB")
    failed = []
    for name in runs:
        s, t = stats[name], seconds[name]
        median = statistics.median(t)
        per_round = getattr(s, "round_bytes", ())
        print(f"{name:24s} {s.rounds:6d} {s.bytes_moved / 1e6:8.1f} "
              f"{s.bytes_moved / full['tree']:7.1%} {s.bytes_moved / full['swap']:7.1%} "
              f"{median:9.3f} {min(t):7.3f}  " + " ".join(f"{b / 1e6:.1f}" for b in per_round))
        if name.startswith("active"):
            if s.bytes_moved > TARGET_SHARE * min(full.values()):
                failed.append(f"{name}: {s.bytes_moved / 1e6:.1f} MB")
            if median > TARGET_S:
                failed.append(f"{name}: {median:.3f} s")
    print(f"\ntargets (active): bytes <= {TARGET_SHARE:.0%} of the smaller full-frame schedule's "
          f"({TARGET_SHARE * min(full.values()) / 1e6:.1f} MB), median composite <= "
          f"{TARGET_S} s: " + ("met" if not failed else "missed by " + "; ".join(failed)))


if __name__ == "__main__":
    main()
