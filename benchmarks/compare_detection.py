"""How often ``workbench results compare`` flags a change that is not there, and finds one that
is: runs of the same measurement (paths of the es2008 scene measured together) recorded
back to back, plain and with one path's draw slowed by a share of its own time, compared
pairwise at several thresholds.

    python benchmarks/compare_detection.py [--runs 4] [--slow 0.2] [--n 64] [--size 400]

Prints, per threshold, the share of plain-against-plain lines flagged (false positives) and the
share of plain-against-slowed comparisons that flag the slowed path (detection), with the
renderer it ran on. Never run beside another timing.
"""

from __future__ import annotations

import argparse
import itertools
import tempfile
from pathlib import Path

from workbench.gl import create_context
from workbench.gl.context import describe
from workbench.measurement.rows import Together, measure_together
from workbench.measurement.stats import StoppingRule
from workbench.paths import Style, make_path
from workbench.reliability.faults import slowed
from workbench.results.compare import compare_runs
from workbench.results.provenance import machine_fingerprint, run_record
from workbench.results.store import ResultsStore
from workbench.scene import generators

PATHS = (("position", {}), ("flat", {}), ("gouraud", {}),
         ("pixel_color", {"field": "distance"}), ("vertex_color", {"field": "distance"}),
         ("pixel_color", {"field": "distance", "bands": 10}))
SLOWED = 2  # gouraud


def record(store, machine, ctx, mesh, size, share: float) -> str:
    """One run of :data:`PATHS` measured together (path :data:`SLOWED` slowed by ``share``)."""
    paths = [make_path(name, Style(**options)) for name, options in PATHS]
    if share:
        paths[SLOWED] = slowed(paths[SLOWED], ctx.finish, share)
    measured = measure_together(ctx, mesh, [Together(p) for p in paths], size=(size, size),
                                repeats=9, stop=StoppingRule(0.02, 9, 41))
    run = run_record(machine, f"compare_detection share={share}", size="bench")
    store.record_run(run)
    store.append_rows(run["run_id"], [{**m.row, "case": f"{i}"} for i, m in enumerate(measured)],
                      experiment="compare_detection", table="table", experiment_size="bench")
    return run["run_id"]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=4, help="plain runs and slowed runs each")
    parser.add_argument("--slow", type=float, default=0.2, help="added share of the draw time")
    parser.add_argument("--n", type=int, default=64, help="quads per sheet side")
    parser.add_argument("--size", type=int, default=400, help="image side in pixels")
    parser.add_argument("--thresholds", default="0,0.05,0.1,0.25")
    args = parser.parse_args()
    ctx = create_context()
    machine = machine_fingerprint(renderer=describe(ctx))
    mesh = generators.semicylinders(n=args.n)
    with tempfile.TemporaryDirectory() as folder:
        store = ResultsStore(Path(folder))
        store.record_machine(machine)
        plain, slow = [], []
        for _ in range(args.runs):  # alternate, so that drift reaches both kinds alike
            plain.append(record(store, machine, ctx, mesh, args.size, 0.0))
            slow.append(record(store, machine, ctx, mesh, args.size, args.slow))
        print(f"{machine['renderer']}, {machine['cpu']}, {machine['logical_cores']} cores; "
              f"{len(mesh.triangles)} triangles at {args.size}x{args.size}, {len(PATHS)} paths, "
              f"{args.runs} plain and {args.runs} runs with path {SLOWED} slowed by "
              f"{args.slow:.0%}")
        for threshold in (float(t) for t in args.thresholds.split(",")):
            false = lines = 0
            for a, b in itertools.combinations(plain, 2):
                found = compare_runs(store, a, b, threshold=threshold)
                false += sum(line["flagged"] for line in found)
                lines += len(found)
            found_slow = others = other_lines = 0
            for a, b in itertools.product(plain, slow):
                found = compare_runs(store, a, b, threshold=threshold)
                found_slow += any(line["flagged"] and line["measurement"].startswith(
                    f"case={SLOWED},") for line in found)
                rest = [line for line in found
                        if not line["measurement"].startswith(f"case={SLOWED},")]
                others += sum(line["flagged"] for line in rest)
                other_lines += len(rest)
            pairs = len(plain) * len(slow)
            print(f"threshold {threshold:.0%}: false positives {false}/{lines} "
                  f"({false / max(lines, 1):.1%}) plain vs plain, {others}/{other_lines} "
                  f"({others / max(other_lines, 1):.1%}) unslowed paths vs slowed runs; "
                  f"slowed path found {found_slow}/{pairs} ({found_slow / pairs:.0%})")


if __name__ == "__main__":
    main()
