"""The two nearest-point hierarchies on the same triangles: TriangleBVH against ElementHierarchy.

:class:`~workbench.algo.nearest.bvh.TriangleBVH` (an AABB tree over triangles, with split
references of
long triangles, used by the Hausdorff metric) and
:class:`~workbench.algo.nearest.hierarchy.ElementHierarchy` (the per-part AABB/OBB forest of
crash2000
§4, used for part distances and force-tube section cuts) are built on the same surface: the
shared LS-DYNA car deck refined 4 x 4 (:func:`workbench.scene.generators.refine`; ``--quick``:
the plain deck). Both start from the FEMesh: the BVH's build includes triangulating the elements
(the hierarchy does that inside its own build) and translating the nodes by the hierarchy's
origin, so that both measure the same float64 numbers.

Queries: every node's nearest triangle of the whole surface (no part excluded; a node lies on
the surface, so this is the near-zero case of the Hausdorff metric), and the same nodes moved
by a fixed random offset of length ``--offset`` mm, each within ``--cutoff`` mm (BVH:
``max_distance``, strictly nearer; hierarchy: ``cutoff``, at most as far) and without a
cut-off. Both must give the same distances to 1e-12 relative (points exactly at the cut-off
excepted); the script stops with an error otherwise.

Timing: one warm-up of everything (numba kernels compile or load from their cache), then
``--repeat`` rounds; in each round every structure is built and queried once, the order of the
structures alternating between rounds, so a disturbance of the machine hits all of them alike.
The table gives medians, and the ratio to the BVH (time / BVH time) as the median and the
range over the rounds. The hierarchy's counters (bounding-volume tests, exact element tests,
slab skips, per query) are printed; the BVH counts nothing. Wall-clock times hold for the
machine and the numba thread count printed above the table: run it on a quiet machine.

Run: ``WORKBENCH_DATA=... .venv/bin/python benchmarks/bvh_compare.py [--quick] [--repeat 7]``.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time

import numba
import numpy as np

from workbench import data
from workbench.algo.nearest.bvh import TriangleBVH
from workbench.algo.nearest.hierarchy import ElementHierarchy, local_origin, used_nodes
from workbench.scene.generators import refine
from workbench.scene.readers import load

REL_TOL = 1e-12


def surface(quick: bool):
    """The car deck (refined 4 x 4 unless ``quick``) and the indices of its elements with
    triangles (the others have nothing to measure against)."""
    path = data.shared_file(data.CAR_DECK)
    if path is None:
        sys.exit("the shared car deck (lsopt_car6) is not available: set WORKBENCH_DATA")
    mesh = load(path)
    if not quick:
        mesh = refine(mesh, 4)
    targets = np.flatnonzero(np.bincount(mesh.triangulation.element_of,
                                         minlength=len(mesh.elements)))
    return mesh, targets


def build_bvh(mesh, origin, leaf_size):
    tri = np.asarray(mesh.triangulation.triangles, dtype=np.int64)
    return TriangleBVH(mesh.nodes - origin, tri, leaf_size=leaf_size)


def build_hierarchy(mesh, targets, origin, kind, leaf_size):
    return ElementHierarchy(mesh, kind=kind, leaf_size=leaf_size, elements=targets,
                            origin=origin)


def query(structure, points, origin, cutoff):
    """(distances, counters or None) of the nearest triangle of every point."""
    if isinstance(structure, TriangleBVH):
        d, _, _ = structure.nearest(points - origin, max_distance=cutoff)
        return d, None
    r = structure.nearest(points, cutoff)
    return r.distance, (r.bv_tests, r.element_tests, r.plane_skips)


def check_same(name, reference, got, cutoff):
    """Exit with an error unless ``got`` equals ``reference`` to REL_TOL relative (a point at
    the cut-off may be in one and out of the other: the BVH's bound is strict)."""
    both_inf = np.isinf(reference) & np.isinf(got)
    at_cutoff = np.isfinite(cutoff) & ((reference == cutoff) | (got == cutoff))
    scale = np.maximum(np.abs(np.where(np.isinf(reference), 0, reference)),
                       np.abs(np.where(np.isinf(got), 0, got)))
    close = np.abs(np.where(both_inf, 0, got - reference)) <= REL_TOL * scale
    bad = ~(both_inf | at_cutoff | close)
    if bad.any():
        i = np.flatnonzero(bad)[:5]
        sys.exit(f"{name}: {bad.sum()} distances differ from the BVH's, first at points "
                 f"{i.tolist()}: {got[i].tolist()} vs {reference[i].tolist()}")


def spread(values) -> str:
    return f"{statistics.median(values):.2f} [{min(values):.2f}, {max(values):.2f}]"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="the plain car deck, not refined 4 x 4")
    ap.add_argument("--repeat", type=int, default=7, help="timed rounds (default 7)")
    ap.add_argument("--cutoff", type=float, default=1.5, help="cut-off distance in mm")
    ap.add_argument("--offset", type=float, default=1.0,
                    help="length of the offset of the moved nodes in mm")
    ap.add_argument("--bvh-leaf", type=int, default=2,
                    help="triangles per BVH leaf (2 as the Hausdorff metric builds it)")
    ap.add_argument("--leaf", type=int, default=1,
                    help="elements per hierarchy leaf (1 as crash2000's Table 2, upper half)")
    args = ap.parse_args()
    if args.repeat < 1:
        ap.error("--repeat must be >= 1")

    mesh, targets = surface(args.quick)
    used = used_nodes(np.asarray(mesh.elements)[targets], mesh.n_nodes)
    origin = local_origin(mesh.nodes, used)
    rng = np.random.default_rng(0)
    direction = rng.normal(size=(len(used), 3))
    direction /= np.linalg.norm(direction, axis=1)[:, None]
    query_sets = {"nodes": mesh.nodes[used],
                  "moved nodes": mesh.nodes[used] + args.offset * direction}
    cutoffs = [args.cutoff, np.inf]

    builders = {
        "TriangleBVH": lambda: build_bvh(mesh, origin, args.bvh_leaf),
        "hierarchy aabb": lambda: build_hierarchy(mesh, targets, origin, "aabb", args.leaf),
        "hierarchy obb": lambda: build_hierarchy(mesh, targets, origin, "obb", args.leaf),
    }
    names = list(builders)
    cases = [(q, c) for q in query_sets for c in cutoffs]

    # warm-up and the equality check
    built = {name: build() for name, build in builders.items()}
    counters = {}
    for q, c in cases:
        reference, _ = query(built["TriangleBVH"], query_sets[q], origin, c)
        for name in names[1:]:
            d, counts = query(built[name], query_sets[q], origin, c)
            check_same(f"{name}, {q}, cutoff {c}", reference, d, c)
            counters[name, q, c] = counts

    build_s = {name: [] for name in names}
    query_s = {(name, q, c): [] for name in names for q, c in cases}
    for r in range(args.repeat):
        order = names if r % 2 == 0 else names[::-1]
        for name in order:
            t0 = time.perf_counter()
            structure = builders[name]()
            build_s[name].append(time.perf_counter() - t0)
            for q, c in cases:
                t0 = time.perf_counter()
                query(structure, query_sets[q], origin, c)
                query_s[name, q, c].append(time.perf_counter() - t0)

    bvh, h = built["TriangleBVH"], built["hierarchy aabb"]
    print(f"car deck{'' if args.quick else ' refined 4 x 4'}: {mesh.n_nodes:,} nodes, "
          f"{len(targets):,} elements with triangles, {bvh.n_triangles:,} triangles; "
          f"BVH {bvh.n_references:,} references, {bvh.n_nodes:,} nodes (leaf {args.bvh_leaf}); "
          f"hierarchy {h.n_bvs:,} + {h.n_top_bvs} top BVs (leaf {args.leaf}); "
          f"{len(used):,} queries per set; {args.repeat} rounds, "
          f"{numba.get_num_threads()} numba threads")
    print()
    print("| structure | query | cutoff (mm) | build (ms) | build ÷ BVH | queries/s | "
          "query time ÷ BVH | BV tests/query | element tests/query | slab skips/query |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    n = len(used)
    for q, c in cases:
        for name in names:
            times = query_s[name, q, c]
            ratio_b = [a / b for a, b in zip(build_s[name], build_s["TriangleBVH"])]
            ratio_q = [a / b for a, b in zip(times, query_s["TriangleBVH", q, c])]
            counts = counters.get((name, q, c))
            tests = ("n/a",) * 3 if counts is None else tuple(f"{x / n:.1f}" for x in counts)
            print(f"| {name} | {q} | {c:g} | {1e3 * statistics.median(build_s[name]):.1f} | "
                  f"{spread(ratio_b)} | {n / statistics.median(times):,.0f} | {spread(ratio_q)} | "
                  f"{' | '.join(tests)} |")


if __name__ == "__main__":
    main()
