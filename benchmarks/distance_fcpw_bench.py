"""Exact float64 part distances against fcpw (float32) on the car deck refined 8 x 8.

The query of crash2000 §4.1 (``workbench run table_bvh_distance``): for every node, the
distance to the nearest triangle of another part within ``--cutoff`` mm (1.5). Timed, on the
same model (the shared LS-DYNA car deck refined k x k by
:func:`workbench.scene.generators.refine`, as the experiment builds it):

* ``ours`` -- :func:`workbench.algo.nearest.parts.batched_part_distances`: one 4-wide tree
  searched by groups of nearby nodes, exact float64, numba threads. Query time: each node's
  own parts, the grouping, the search and the results (the tree's build apart).
* ``fcpw`` -- :mod:`workbench.references.distances` tool "fcpw": one vectorized fcpw scene
  per excluded part set (17 on the car), ``find_closest_points`` with the cut-off as search
  radius, float32, all cores. Query time: the ``find_closest_points`` calls only (not the
  builds, not reading the distances out of fcpw's interaction list).
* ``hierarchy`` (``--hierarchy``) -- :func:`~workbench.algo.nearest.parts.part_distances`,
  the crash2000 AABB hierarchy with one element per leaf (the experiment's Table 2 row).

Checks before timing: our distances equal the hierarchy's to the last bit and those of every
node against every triangle on a sample of nodes (the script stops otherwise); fcpw's are
compared with ours (nodes off by more than 1e-6 mm, largest error).

Timing: one warm-up of everything (numba kernels compile or load from their cache), then
``--rounds`` rounds, each running every tool once, in alternating order so that a disturbance
of the machine hits all alike. Printed: medians with [min, max] over the rounds, queries per
second of the median, and ours ÷ fcpw query time per round (median [min, max]; below 1: ours
faster). Wall-clock times hold for the machine and thread counts printed: run it alone.

Run: ``.venv/bin/python benchmarks/distance_fcpw_bench.py [--refine 8] [--rounds 7]
[--hierarchy] [--quick]`` (the car deck from ``$WORKBENCH_DATA`` or ``shared/data`` beside the
checkout; about 1.5 minutes at the defaults on 2 cores, most of it fcpw's 17 builds a round
and the brute-force check).
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys

import numba
import numpy as np

from workbench import data
from workbench.algo.nearest.hierarchy import local_origin
from workbench.algo.nearest.parts import batched_part_distances, node_parts, part_distances
from workbench.algo.nearest.triangle import points_triangles_distance
from workbench.references.distances import compare_with_exact, reference_part_distances
from workbench.scene.generators import refine
from workbench.scene.readers import load

SAMPLE = 400  # nodes checked against every triangle (half of them within the cut-off)


def model(k: int):
    path = data.shared_file(data.CAR_DECK)
    if path is None:
        sys.exit("the shared car deck (lsopt_car6) is not available: set WORKBENCH_DATA")
    mesh = load(path)
    return refine(mesh, k) if k > 1 else mesh


def brute_force_sample(mesh, cutoff: float, nodes: np.ndarray) -> np.ndarray:
    """Distances of ``nodes`` to the triangles of the parts not their own, every triangle
    tried, in the same local coordinates as ours; inf beyond the cut-off."""
    coords = mesh.coordinates(0)
    local = coords - local_origin(coords, mesh.used_nodes())
    tr = mesh.triangulation
    corners = local[np.asarray(tr.triangles, np.int64)]
    tri_part = mesh.parts[tr.element_of]
    ptr, own = node_parts(mesh)
    out = np.full(len(nodes), np.inf)
    for i, node in enumerate(nodes):
        others = ~np.isin(tri_part, own[ptr[node]:ptr[node + 1]])
        if others.any():
            d = points_triangles_distance(local[node][None], corners[others]).min()
            out[i] = d if d <= cutoff else np.inf
    return out


def check(mesh, cutoff: float, ours, hierarchy, fcpw) -> str:
    """Stop unless ours equals the hierarchy and a brute-force sample bit for bit; fcpw's
    errors against ours as one line."""
    if not np.array_equal(ours.distance, hierarchy.distance):
        bad = np.flatnonzero(ours.distance != hierarchy.distance)
        sys.exit(f"ours differs from the hierarchy at {len(bad)} nodes, first {bad[:5].tolist()}")
    rng = np.random.default_rng(0)
    near = np.flatnonzero(np.isfinite(ours.distance))
    nodes = np.unique(np.r_[rng.choice(mesh.used_nodes(), SAMPLE // 2, replace=False),
                            rng.choice(near, min(SAMPLE // 2, len(near)), replace=False)])
    exact = brute_force_sample(mesh, cutoff, nodes)
    if not np.array_equal(exact, ours.distance[nodes]):
        sys.exit("ours differs from every node against every triangle on the sample")
    c = compare_with_exact(ours.distance, fcpw)
    return (f"ours = hierarchy on all {mesh.n_nodes:,} nodes and = brute force on {len(nodes)} "
            f"sampled nodes, to the last bit; fcpw: {c['off']} of {c['both_within']} nodes "
            f"within the cut-off off by more than 1e-6 mm, largest error "
            f"{c['max_abs_error']:.3g} mm, {c['cutoff_disagreements']} disagree about the "
            f"cut-off")


def spread(values, scale: float = 1.0, fmt: str = ".2f") -> str:
    v = [scale * x for x in values]
    return f"{statistics.median(v):{fmt}} [{min(v):{fmt}}, {max(v):{fmt}}]"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--refine", type=int, default=8, help="k of the k x k refinement (8)")
    ap.add_argument("--rounds", type=int, default=7, help="timed rounds (7)")
    ap.add_argument("--cutoff", type=float, default=1.5, help="cut-off in mm (1.5)")
    ap.add_argument("--hierarchy", action="store_true",
                    help="also time the crash2000 AABB hierarchy")
    ap.add_argument("--quick", action="store_true", help="refined 2 x 2, 3 rounds")
    args = ap.parse_args()
    if args.quick:
        args.refine, args.rounds = 2, 3
    if args.rounds < 1 or args.refine < 1 or not args.cutoff > 0:
        ap.error("--rounds and --refine must be >= 1, --cutoff > 0")

    mesh = model(args.refine)
    tools = {
        "ours": lambda: batched_part_distances(mesh, args.cutoff),
        "fcpw": lambda: reference_part_distances("fcpw", mesh, args.cutoff),
    }
    if args.hierarchy:
        tools["hierarchy"] = lambda: part_distances(mesh, args.cutoff)

    ours = tools["ours"]()  # warm-up, and the checks
    fcpw = tools["fcpw"]()
    if not fcpw.available:
        sys.exit(f"fcpw: {fcpw.reason}")
    summary = check(mesh, args.cutoff, ours, part_distances(mesh, args.cutoff), fcpw)

    names = list(tools)
    seconds = {name: [] for name in names}
    for r in range(args.rounds):
        for name in (names if r % 2 == 0 else names[::-1]):
            result = tools[name]()
            seconds[name].append(result.seconds_query if name == "fcpw" else result.query_s)

    n = ours.nodes_queried
    print(f"car deck refined {args.refine} x {args.refine}: {mesh.n_nodes:,} nodes, "
          f"{mesh.n_elements:,} elements, {len(np.unique(mesh.parts))} parts, "
          f"{mesh.triangulation.n_triangles:,} triangles; {n:,} queries, cut-off "
          f"{args.cutoff:g} mm; {args.rounds} rounds; {numba.get_num_threads()} numba threads, "
          f"{os.cpu_count()} cores (fcpw: one thread per core)")
    print(summary)
    print()
    print("| tool | precision | query s, median [min, max] | queries/s (median) | "
          "query time ÷ fcpw, median [min, max] |")
    print("|---|---|---|---|---|")
    precision = {"ours": "float64, exact", "fcpw": "float32",
                 "hierarchy": "float64, exact"}
    for name in names:
        ratio = [a / b for a, b in zip(seconds[name], seconds["fcpw"])]
        print(f"| {name} | {precision[name]} | {spread(seconds[name], fmt='.4f')} | "
              f"{n / statistics.median(seconds[name]):,.0f} | {spread(ratio, fmt='.3f')} |")


if __name__ == "__main__":
    main()
