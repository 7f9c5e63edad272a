"""Read time of a keyword deck in a fresh process: cold (no compiled kernels on disk), cached
(kernels compiled by an earlier process) and, for reference, the import alone; each with the
solid steps chosen by model size (numpy below ``COMPILED_FROM`` solids, "by size") and with the
compiled kernels for every size ("compiled always", as before that threshold).

Decks: the shared car deck (shells only) when present, and a generated block of n x n x n
hexahedra (``--n``, default 20: 8 000 solids) written as ``*ELEMENT_SOLID``. Each run is a new
Python process that imports the reader and reads the deck; the process measures itself
(``time.perf_counter`` from before the import to after the read) and reports whether numba was
imported. "cold" points ``NUMBA_CACHE_DIR`` at a new empty folder; "cached" at one a previous
process filled. The cases are interleaved, ``--repeat`` rounds (default 7); medians and the
range are printed, one process at a time, with the ratio of medians compiled always / by size.

Run: ``.venv/bin/python benchmarks/read_cold_start.py [--n 20] [--repeat 7]``.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

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


def run(deck: str, cache: Path, steps: str) -> dict:
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache))
    out = subprocess.run([sys.executable, "-c", _PROBE, deck, steps], env=env, check=True,
                         capture_output=True, text=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=20, help="hexahedra per block edge (20)")
    parser.add_argument("--repeat", type=int, default=7, help="interleaved rounds (7)")
    args = parser.parse_args(argv)
    from workbench.data import CAR_DECK, shared_file

    with tempfile.TemporaryDirectory(prefix="cold-start-") as folder:
        folder = Path(folder)
        decks = {"import only": "-", f"solid block ({args.n ** 3} hexahedra)":
                 str(solid_deck(args.n, folder))}
        car = shared_file(CAR_DECK)
        if car is not None:
            decks["car deck (shells)"] = str(car)
        warm = folder / "warm-cache"
        for deck in decks.values():
            run(deck, warm, STEPS[1])  # fills the cache the "cached" runs use
        times: dict[tuple[str, str, str], list[float]] = {}
        numba_used = {}
        for r in range(args.repeat):
            for name, deck in decks.items():
                for case in ("cold", "cached"):
                    for steps in STEPS:
                        cache = folder / f"cold-{r}-{len(times)}-{steps[0]}" \
                            if case == "cold" else warm
                        result = run(deck, cache, steps)
                        times.setdefault((name, case, steps), []).append(result["total_s"])
                        numba_used[(name, steps)] = result["numba"]
        print(f"{'deck':<34}{'case':<8}{'solid steps':<17}{'median s':>9}{'min s':>8}"
              f"{'max s':>8}  numba  ratio")
        for (name, case, steps), values in times.items():
            ratio = statistics.median(times[(name, case, STEPS[1])]) / statistics.median(values)
            print(f"{name:<34}{case:<8}{steps:<17}{statistics.median(values):>9.3f}"
                  f"{min(values):>8.3f}{max(values):>8.3f}  "
                  f"{'yes' if numba_used[(name, steps)] else 'no':<5}  {ratio:.2f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
