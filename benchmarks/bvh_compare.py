"""The two nearest-point hierarchies on the same triangles: TriangleBVH against ElementHierarchy.

:class:`~workbench.algo.nearest.bvh.TriangleBVH` (an AABB tree over triangles, with split
references of long triangles, used by the Hausdorff metric) and
:class:`~workbench.algo.nearest.hierarchy.ElementHierarchy` (the per-part AABB/OBB forest of
crash2000 §4, used for part distances and force-tube section cuts) are built on the same
surface: the shared LS-DYNA car deck refined 4 x 4 (:func:`workbench.scene.generators.refine`;
quick: the plain deck). Both start from the FEMesh: the BVH's build includes triangulating the
elements and translating the nodes by the hierarchy's origin, so that both measure the same
float64 numbers.

Queries: every node's nearest triangle of the whole surface (the near-zero case of the
Hausdorff metric), and the same nodes moved by a fixed random offset of 1 mm, each within
the 1.5 mm cut-off (BVH: ``max_distance``, strictly nearer; hierarchy: ``cutoff``, at most as
far) and without a cut-off. Both must give the same distances to 1e-12 relative (points
exactly at the cut-off excepted); the benchmark stops with an error otherwise.

Timed, interleaved (one warm-up round compiles or loads the numba kernels): the three builds
(``<structure> build``, with the ratio to the BVH's build), then per query set and cut-off the
three queries (``<structure> query``, ratio to the BVH's), columns ``query`` and
``cutoff_mm``; the hierarchy's rows carry its counters per query (``bv_tests``,
``element_tests``, ``slab_skips``).

Run: ``workbench bench bvh_compare [--quick]`` (needs the shared car deck).
"""

from __future__ import annotations

import numpy as np

from workbench.data import CAR_DECK
from workbench.measurement.bench import Case, benchmark, needs_shared_file

REL_TOL = 1e-12
CUTOFF, OFFSET = 1.5, 1.0
BVH_LEAF, LEAF = 2, 1  # as the Hausdorff metric builds it; as crash2000's Table 2, upper half


def check_same(name, reference, got, cutoff) -> None:
    """ValueError unless ``got`` equals ``reference`` to REL_TOL relative (a point at the
    cut-off may be in one and out of the other: the BVH's bound is strict)."""
    both_inf = np.isinf(reference) & np.isinf(got)
    at_cutoff = np.isfinite(cutoff) & ((reference == cutoff) | (got == cutoff))
    scale = np.maximum(np.abs(np.where(np.isinf(reference), 0, reference)),
                       np.abs(np.where(np.isinf(got), 0, got)))
    close = np.abs(np.where(both_inf, 0, got - reference)) <= REL_TOL * scale
    bad = ~(both_inf | at_cutoff | close)
    if bad.any():
        i = np.flatnonzero(bad)[:5]
        raise ValueError(f"{name}: {bad.sum()} distances differ from the BVH's, first at "
                         f"points {i.tolist()}: {got[i].tolist()} vs {reference[i].tolist()}")


@benchmark("bvh_compare", "TriangleBVH against the crash2000 ElementHierarchy: builds and "
                          "nearest-triangle queries on the car deck",
           cases=[Case("car", {"refine": 4}, {"refine": 1})],
           requires=[needs_shared_file(CAR_DECK)])
def bvh_compare(bench, refine: int) -> None:
    from workbench import data
    from workbench.algo.nearest.bvh import TriangleBVH
    from workbench.algo.nearest.hierarchy import ElementHierarchy, local_origin, used_nodes
    from workbench.scene.generators import refine as refined
    from workbench.scene.readers import load

    mesh = load(data.shared_file(CAR_DECK))
    mesh = refined(mesh, refine) if refine > 1 else mesh
    targets = np.flatnonzero(np.bincount(mesh.triangulation.element_of,
                                         minlength=len(mesh.elements)))
    used = used_nodes(np.asarray(mesh.elements)[targets], mesh.n_nodes)
    origin = local_origin(mesh.nodes, used)
    direction = np.random.default_rng(0).normal(size=(len(used), 3))
    direction /= np.linalg.norm(direction, axis=1)[:, None]
    query_sets = {"nodes": mesh.nodes[used], "moved nodes": mesh.nodes[used] + OFFSET * direction}

    def bvh():
        tri = np.asarray(mesh.triangulation.triangles, dtype=np.int64)
        return TriangleBVH(mesh.nodes - origin, tri, leaf_size=BVH_LEAF)

    builders = {"TriangleBVH": bvh,
                "hierarchy aabb": lambda: ElementHierarchy(mesh, kind="aabb", leaf_size=LEAF,
                                                           elements=targets, origin=origin),
                "hierarchy obb": lambda: ElementHierarchy(mesh, kind="obb", leaf_size=LEAF,
                                                          elements=targets, origin=origin)}
    built = {name: build() for name, build in builders.items()}

    def query(name, points, cutoff):
        structure = built[name]
        if name == "TriangleBVH":
            return structure.nearest(points - origin, max_distance=cutoff)[0], None
        r = structure.nearest(points, cutoff)
        return r.distance, dict(bv_tests=r.bv_tests / len(points),
                                element_tests=r.element_tests / len(points),
                                slab_skips=r.plane_skips / len(points))

    ratios = [(name, "TriangleBVH") for name in builders if name != "TriangleBVH"]
    bench.interleave({f"{n} build": b for n, b in builders.items()},
                     [(f"{a} build", f"{b} build") for a, b in ratios],
                     triangles=built["TriangleBVH"].n_triangles, queries=len(used))
    for q, points in query_sets.items():
        for cutoff in (CUTOFF, np.inf):
            reference, _ = query("TriangleBVH", points, cutoff)
            counters = {}
            for name in list(builders)[1:]:
                d, counters[f"{name} query"] = query(name, points, cutoff)
                check_same(f"{name}, {q}, cutoff {cutoff}", reference, d, cutoff)
            bench.interleave(
                {f"{n} query": (lambda n=n, p=points, c=cutoff: query(n, p, c)) for n in builders},
                [(f"{a} query", f"{b} query") for a, b in ratios], columns_of=counters,
                query=q, cutoff_mm=f"{cutoff:g}", queries=len(used))
