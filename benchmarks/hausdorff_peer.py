"""Our certified Hausdorff bracket against cascading-upper-bounds (Sacht & Jacobson, SGP 2024),
timed interleaved: the ``hausdorff_peer`` table of the simplify_tradeoff experiment on its own.

The table and its method are the experiment's
(:func:`workbench.reproductions.simplify_tradeoff.peer_rows`): the bunny (pymeshlab's sample,
56 172 triangles) and the shared car deck (8 732 triangles), each against pymeshlab's quadric
edge collapse (whole mesh, vertices moved) to 1 000 and 4 000 triangles, one-sided original →
decimated, both tools at our default bracket width (1e-4 of the original's bounding-box
diagonal, handed to the peer as the same absolute width). One untimed round of both, then 9
rounds (``--size quick``: 5, 1 000 only; tiny: 3, the smallest panels) of ours then the peer,
each timed around its own call; medians and [min, max] over the rounds, and the per-round ratio
peer ÷ ours the same way. Ours runs on every core (numba), the peer on one thread: the times
hold for the machine and thread count printed above the table; run it on a quiet machine.

Writes ``hausdorff_peer.csv`` and ``.md`` into ``--out`` (default ``figures/hausdorff_peer``)
and prints the Markdown table.

Run: ``nice -n 10 .venv/bin/python benchmarks/hausdorff_peer.py [--size full|quick|tiny]
[--out DIR]`` (the whole experiment, ``workbench run simplify_tradeoff``, writes the same table
beside its others).
"""

from __future__ import annotations

import argparse
import os
import platform
from pathlib import Path

import numba

from workbench.experiment.context import ExperimentContext
from workbench.reproductions.simplify_tradeoff import peer_rows


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--size", choices=("full", "quick", "tiny"), default="full")
    parser.add_argument("--out", type=Path, default=Path("figures/hausdorff_peer"))
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    exp = ExperimentContext("hausdorff_peer", args.out, args.size, progress=print)
    print(f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores, numba threads "
          f"{numba.get_num_threads()}, load {os.getloadavg()[0]:.2f}")
    rows = peer_rows(exp, exp.builtin("car"))
    exp.table(rows, "hausdorff_peer", "Ours against cascading-upper-bounds, interleaved")
    print((args.out / "hausdorff_peer.md").read_text(encoding="utf-8"))
    print(f"load {os.getloadavg()[0]:.2f} at the end")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
