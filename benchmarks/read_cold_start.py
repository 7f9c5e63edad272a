"""Read time of a keyword deck in a fresh process: cold (no compiled kernels on disk), cached
(kernels compiled by an earlier process) and, for reference, the import alone; each with the
solid steps chosen by model size (numpy below ``COMPILED_FROM`` solids, "by size") and with the
compiled kernels for every size ("compiled always", as before that threshold).

Cases (decks): ``import only``; ``solid block``, a generated block of n x n x n hexahedra
(full n = 20: 8 000 solids; quick n = 8, without the cold compiled-always process, which
compiles for some 16 s) written as ``*ELEMENT_SOLID``; ``car deck`` (the
shared deck, shells only; full size only). Each call is a new Python process that imports the
reader and reads the deck, measuring itself (``time.perf_counter`` from before the import to
after the read; the reported seconds); "cold" points ``NUMBA_CACHE_DIR`` at a new empty
folder, "cached" at one a previous process filled. The four clocks (cold/cached × by size /
compiled always) are interleaved; the "compiled always" rows carry ``over_cold_by_size`` /
``over_cached_by_size``, and every row ``numba`` (whether the process imported numba).

Run: ``workbench bench read_cold_start [--quick]``.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

from workbench.measurement.bench import Case, benchmark

STEPS = ("by size", "compiled always")
_PROBE = """
import json, sys, time
t0 = time.perf_counter()
from workbench.scene.readers import load
if sys.argv[2] == "compiled always":
    import workbench.scene.solids as solids
    solids.COMPILED_FROM = 0
t1 = time.perf_counter()
mesh = load(sys.argv[1]) if sys.argv[1] != "-" else None
t2 = time.perf_counter()
print(json.dumps({"import_s": t1 - t0, "read_s": t2 - t1, "total_s": t2 - t0,
                  "numba": "numba" in sys.modules,
                  "elements": 0 if mesh is None else mesh.n_elements}))
"""


def solid_deck(n: int, folder: Path) -> Path:
    """An n x n x n block of unit hexahedra (10 mm) with one *PART, as a keyword deck."""
    lines = ["*KEYWORD", "*PART", "block", f"{1:10d}{1:10d}{1:10d}", "*NODE"]
    m = n + 1
    for k in range(m):
        for j in range(m):
            for i in range(m):
                lines.append(f"{1 + i + m * (j + m * k):8d}{10.0 * i:16.1f}{10.0 * j:16.1f}"
                             f"{10.0 * k:16.1f}")
    lines.append("*ELEMENT_SOLID")
    eid = 0
    for k in range(n):
        for j in range(n):
            for i in range(n):
                a = 1 + i + m * (j + m * k)
                b, c, d = a + 1, a + 1 + m, a + m
                up = m * m
                eid += 1
                lines.append("".join(f"{v:8d}" for v in (eid, 1, a, b, c, d, a + up, b + up,
                                                          c + up, d + up)))
    lines.append("*END")
    path = folder / f"block{n}.k"
    path.write_text("\n".join(lines) + "\n")
    return path


def probe(deck: str, cache: Path, steps: str) -> dict:
    """What one fresh process reading ``deck`` with numba's cache at ``cache`` reports."""
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache))
    out = subprocess.run([sys.executable, "-c", _PROBE, deck, steps], env=env, check=True,
                         capture_output=True, text=True).stdout
    return json.loads(out.strip().splitlines()[-1])


@benchmark("read_cold_start", "reading a deck in a fresh process, cold and with numba's cache",
           cases=[Case("import only"),
                  Case("solid block", {"n": 20}, {"n": 8, "cold_compiled": False}),
                  Case("car deck")])
def read_cold_start(bench, n: int = 0, cold_compiled: bool = True) -> None:
    from workbench.data import CAR_DECK, shared_file

    with tempfile.TemporaryDirectory(prefix="cold-start-") as name:
        folder = Path(name)
        if bench.case.name == "import only":
            deck = "-"
        elif bench.case.name == "solid block":
            deck = str(solid_deck(n, folder))
        else:
            bench.require(bench.quick and "the car deck is read at full size only")
            car = shared_file(CAR_DECK)
            bench.require(car is None and f"needs the shared data file {CAR_DECK}")
            deck = str(car)
        warm = folder / "warm-cache"
        probe(deck, warm, STEPS[1])  # fills the cache the "cached" runs use
        used: dict[str, bool] = {}
        fresh = iter(range(10**6))

        def clock(case: str, steps: str):
            def run() -> float:
                cache = folder / f"cold-{next(fresh)}" if case == "cold" else warm
                result = probe(deck, cache, steps)
                used[f"{case} {steps}"] = result["numba"]
                return result["total_s"]
            return run

        clocks = {f"{case} {steps}": clock(case, steps)
                  for case in ("cold", "cached") for steps in STEPS}
        if not cold_compiled:  # some 16 s a process: left out of the quick size
            del clocks[f"cold {STEPS[1]}"]
        timings = bench.interleave(
            clocks, [(f"{case} {STEPS[1]}", f"{case} {STEPS[0]}") for case in ("cold", "cached")
                     if f"{case} {STEPS[1]}" in clocks], warmup=0, reported=True)
        for row in bench.rows[-len(timings):]:
            row["numba"] = used[row["function"]]
