"""Throughput of the exact distance queries on the car deck refined k x k, for comparing two
versions of the point-triangle kernel interleaved.

Times, after one warm-up of each (numba kernels compile or load from their cache):

* ``part_distance`` -- :func:`workbench.algo.nearest.parts.batched_part_distances`, every
  node against the other parts within ``--cutoff`` mm (crash2000 §4.1); query seconds.
* ``hausdorff_fine_to_coarse`` -- :func:`workbench.algo.hausdorff.hausdorff` from the refined
  car to the car (default tolerance, 1e-4 of the diagonal); seconds.
* ``hausdorff_fine_to_coarse_bracket`` -- the same with ``estimates=False`` (the bracket
  only), where the checkout has that mode.

(The other direction, the car against its refinement, is not a throughput measure: each of
the car's triangles faces dozens of the refinement's, and the refinement resolves them one by
one, some 20 s at 4 x 4 in both versions.)

Each of ``--rounds`` rounds runs each once, in alternating order. One JSON line per round
is printed (seconds per task, the kernel's module file, the numba thread count) so that a
driver can run this script under two checkouts in turn and compare the two in the same
session:

    for i in 1 2 3; do
      PYTHONPATH=OLD python benchmarks/distance_throughput.py --rounds 3
      PYTHONPATH=NEW python benchmarks/distance_throughput.py --rounds 3
    done

``--summary FILE...`` reads such lines back and prints, per task and checkout, the median and
[min, max] of the seconds and the ratio of the medians (new ÷ old, the first checkout named
being old). Run it alone: two processes timing at once disturb each other.
"""

from __future__ import annotations

import argparse
import inspect
import json
import statistics
import sys
import time

import numba
import numpy as np


def _model(k: int):
    from workbench import data
    from workbench.scene.generators import refine
    from workbench.scene.readers import load

    path = data.shared_file(data.CAR_DECK)
    if path is None:
        sys.exit("the shared car deck is not available: set WORKBENCH_DATA")
    car = load(path)
    return car, refine(car, k)


def _tasks(car, fine, cutoff):
    from workbench.algo.hausdorff import hausdorff
    from workbench.algo.nearest.parts import batched_part_distances

    vc, fc = car.coordinates(0), np.asarray(car.triangulation.triangles, np.int64)
    vf, ff = fine.coordinates(0), np.asarray(fine.triangulation.triangles, np.int64)

    def part():
        return batched_part_distances(fine, cutoff).query_s

    def timed(f):
        start = time.perf_counter()
        f()
        return time.perf_counter() - start

    tasks = {
        "part_distance": part,
        "hausdorff_fine_to_coarse": lambda: timed(lambda: hausdorff(vf, ff, vc, fc)),
    }
    if "estimates" in inspect.signature(hausdorff).parameters:  # the bracket-only mode
        tasks["hausdorff_fine_to_coarse_bracket"] = lambda: timed(
            lambda: hausdorff(vf, ff, vc, fc, estimates=False))
    return tasks


def _summary(paths) -> None:
    rows: dict[tuple[str, str], list[float]] = {}
    trees: list[str] = []
    for path in paths:
        with open(path) as fh:
            for line in fh:
                if not line.startswith("{"):
                    continue
                r = json.loads(line)
                if r["tree"] not in trees:
                    trees.append(r["tree"])
                for task, s in r["seconds"].items():
                    rows.setdefault((task, r["tree"]), []).append(s)
    print("| task | " + " | ".join(f"{t} s, median [min, max]" for t in trees)
          + " | ratio of medians (2nd ÷ 1st) |")
    print("|---|" + "---|" * len(trees) + "---|")
    for task in sorted({k[0] for k in rows}):
        cells, medians = [], []
        for t in trees:
            v = rows.get((task, t), [])
            medians.append(statistics.median(v) if v else float("nan"))
            cells.append(f"{statistics.median(v):.3f} [{min(v):.3f}, {max(v):.3f}] (n={len(v)})"
                         if v else "-")
        ratio = medians[1] / medians[0] if len(medians) > 1 else float("nan")
        print(f"| {task} | " + " | ".join(cells) + f" | {ratio:.3f} |")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--refine", type=int, default=8, help="k of the k x k refinement (8)")
    ap.add_argument("--rounds", type=int, default=3, help="timed rounds (3)")
    ap.add_argument("--cutoff", type=float, default=1.5, help="part-distance cut-off, mm (1.5)")
    ap.add_argument("--summary", nargs="+", metavar="FILE",
                    help="summarise the JSON lines of earlier runs instead")
    args = ap.parse_args()
    if args.summary:
        _summary(args.summary)
        return
    if args.rounds < 1 or args.refine < 1 or not args.cutoff > 0:
        ap.error("--rounds and --refine must be >= 1, --cutoff > 0")
    import workbench.algo.nearest.triangle as kernel

    car, fine = _model(args.refine)
    tasks = _tasks(car, fine, args.cutoff)
    for f in tasks.values():  # warm-up
        f()
    names = list(tasks)
    tree = kernel.__file__.rsplit("/workbench/", 1)[0]
    for r in range(args.rounds):
        seconds = {name: tasks[name]() for name in (names if r % 2 == 0 else names[::-1])}
        print(json.dumps({"tree": tree, "refine": args.refine, "round": r,
                          "threads": numba.get_num_threads(), "seconds": seconds}), flush=True)


if __name__ == "__main__":
    main()
