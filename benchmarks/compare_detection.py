"""How often ``workbench results compare`` flags a change that is not there, and finds one that
is: runs of the same measurement (paths of the es2008 scene measured together) recorded back
to back into a temporary store, plain and with one path's draw (Gouraud) slowed by 20 % of its
own time, compared pairwise at several thresholds.

Per threshold (cases ``0``, ``0.05``, ``0.1``, ``0.25``) one row ``detection`` with
``false_positive_share`` (plain-against-plain lines flagged), ``others_flagged_share``
(unslowed paths flagged in plain-against-slowed comparisons) and ``detected_share`` (plain-
against-slowed comparisons that flag the slowed path), and the timed ``compare_runs`` call.
Full: 4 plain and 4 slowed runs of 64² quads a sheet at 400 × 400; quick: 2 and 2 of 16² at
120 × 120. The runs are drawn once and shared by the cases.

Run: ``workbench bench compare_detection [--quick]`` (needs an OpenGL context).
"""

from __future__ import annotations

import itertools
from functools import cache

from workbench.measurement.bench import Case, benchmark, needs_gl

PATHS = (("position", {}), ("flat", {}), ("gouraud", {}),
         ("pixel_color", {"field": "distance"}), ("vertex_color", {"field": "distance"}),
         ("pixel_color", {"field": "distance", "bands": 10}))
SLOWED, SHARE = 2, 0.2  # gouraud, by 20 %
SIZES = {"full": {"runs": 4, "n": 64, "pixels": 400}, "quick": {"runs": 2, "n": 16, "pixels": 120}}


@cache
def recorded(runs: int, n: int, pixels: int):
    """(store, plain run ids, slowed run ids): ``runs`` of each, alternating, in a temporary
    store (kept for the process, shared by the cases)."""
    import tempfile
    from pathlib import Path

    from workbench.gl import create_context
    from workbench.gl.context import describe
    from workbench.measurement.rows import Together, measure_together
    from workbench.measurement.stats import StoppingRule
    from workbench.paths import Style, make_path
    from workbench.reliability.faults import slowed
    from workbench.results.provenance import machine_fingerprint, run_record
    from workbench.results.store import ResultsStore
    from workbench.scene import generators

    ctx = create_context()
    machine = machine_fingerprint(renderer=describe(ctx))
    mesh = generators.semicylinders(n=n)
    store = ResultsStore(Path(tempfile.mkdtemp(prefix="compare_detection_")))
    store.record_machine(machine)

    def record(share: float) -> str:
        paths = [make_path(name, Style(**options)) for name, options in PATHS]
        if share:
            paths[SLOWED] = slowed(paths[SLOWED], ctx.finish, share)
        measured = measure_together(ctx, mesh, [Together(p) for p in paths],
                                    size=(pixels, pixels), repeats=9,
                                    stop=StoppingRule(0.02, 9, 41))
        run = run_record(machine, f"compare_detection share={share}", size="bench")
        store.record_run(run)
        store.append_rows(run["run_id"], [{**m.row, "case": f"{i}"}
                                          for i, m in enumerate(measured)],
                          experiment="compare_detection", table="table",
                          experiment_size="bench")
        return run["run_id"]

    plain, slow = [], []
    for _ in range(runs):  # alternate, so that drift reaches both kinds alike
        plain.append(record(0.0))
        slow.append(record(SHARE))
    return store, tuple(plain), tuple(slow)


@benchmark("compare_detection", "false positives and detection of `results compare` on runs "
                                "with one path slowed by 20 %",
           cases=[Case(t, SIZES["full"], SIZES["quick"]) for t in ("0", "0.05", "0.1", "0.25")],
           requires=[needs_gl])
def compare_detection(bench, runs: int, n: int, pixels: int) -> None:
    from workbench.results.compare import compare_runs

    threshold = float(bench.case.name)
    store, plain, slow = recorded(runs, n, pixels)
    false = lines = 0
    for a, b in itertools.combinations(plain, 2):
        found = compare_runs(store, a, b, threshold=threshold)
        false += sum(line["flagged"] for line in found)
        lines += len(found)
    found_slow = others = other_lines = 0
    for a, b in itertools.product(plain, slow):
        found = compare_runs(store, a, b, threshold=threshold)
        mine = [line["measurement"].startswith(f"case={SLOWED},") for line in found]
        found_slow += any(line["flagged"] and m for line, m in zip(found, mine))
        others += sum(line["flagged"] for line, m in zip(found, mine) if not m)
        other_lines += sum(not m for m in mine)
    bench.record("detection", false_positive_share=false / max(lines, 1),
                 others_flagged_share=others / max(other_lines, 1),
                 detected_share=found_slow / (len(plain) * len(slow)), pairs=len(plain) * len(slow),
                 slowed_share=SHARE)
    bench.time("compare_runs", lambda: compare_runs(store, plain[0], slow[0],
                                                    threshold=threshold))
