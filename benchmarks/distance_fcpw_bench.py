"""Exact float64 part distances against fcpw (float32) on the car deck refined 8 x 8.

The query of crash2000 §4.1 (``workbench run table_bvh_distance``): for every node, the
distance to the nearest triangle of another part within 1.5 mm. Timed, on the shared LS-DYNA
car deck refined k x k (:func:`workbench.scene.generators.refine`; full 8, quick 2):

* ``ours`` -- :func:`workbench.algo.nearest.parts.batched_part_distances`: one 4-wide tree
  searched by groups of nearby nodes, exact float64, numba threads. Its own query clock: each
  node's own parts, the grouping, the search and the results (the tree's build apart).
* ``fcpw`` -- :mod:`workbench.references.distances` tool "fcpw": one vectorized fcpw scene
  per excluded part set, ``find_closest_points`` with the cut-off as search radius, float32,
  all cores. Its own query clock: the ``find_closest_points`` calls only.
* ``hierarchy`` (only with ``--set hierarchy=true``) --
  :func:`~workbench.algo.nearest.parts.part_distances`, the crash2000 AABB hierarchy with one
  element per leaf (the experiment's Table 2 row), exact float64. Its own query clock.

Checks before timing: our distances equal the crash2000 hierarchy's
(:func:`~workbench.algo.nearest.parts.part_distances`) to the last bit (the benchmark stops
otherwise); fcpw's are compared with ours (``fcpw_off``: nodes off by more than 1e-6 mm,
``fcpw_max_error_mm``). Timed interleaved with the reported query seconds, ``ours`` carrying
``over_fcpw`` (below 1: ours faster), and with the hierarchy ``over_hierarchy``.

Run: ``workbench bench distance_fcpw_bench [--quick] [--set hierarchy=true]`` (needs the car
deck and fcpw).
"""

from __future__ import annotations

import numpy as np

from workbench.data import CAR_DECK
from workbench.measurement.bench import Case, benchmark, needs_module, needs_shared_file

CUTOFF = 1.5


@benchmark("distance_fcpw_bench", "exact float64 part distances against fcpw (float32) on the "
                                  "refined car deck",
           cases=[Case("car", {"refine": 8}, {"refine": 2})],
           requires=[needs_shared_file(CAR_DECK), needs_module("fcpw")])
def distance_fcpw(bench, refine: int, hierarchy: bool = False) -> None:
    from workbench import data
    from workbench.algo.nearest.parts import batched_part_distances, part_distances
    from workbench.references.distances import compare_with_exact, reference_part_distances
    from workbench.scene.generators import refine as refined
    from workbench.scene.readers import load

    mesh = load(data.shared_file(CAR_DECK))
    mesh = refined(mesh, refine) if refine > 1 else mesh
    ours = batched_part_distances(mesh, CUTOFF)
    fcpw = reference_part_distances("fcpw", mesh, CUTOFF)
    if not fcpw.available:
        bench.require(f"fcpw: {fcpw.reason}")
    exact = part_distances(mesh, CUTOFF)
    if not np.array_equal(ours.distance, exact.distance):
        bad = np.flatnonzero(ours.distance != exact.distance)
        raise ValueError(f"ours differs from the hierarchy at {len(bad)} nodes, first "
                         f"{bad[:5].tolist()}")
    c = compare_with_exact(ours.distance, fcpw)
    clocks = {"ours": lambda: batched_part_distances(mesh, CUTOFF).query_s,
              "fcpw": lambda: reference_part_distances("fcpw", mesh, CUTOFF).seconds_query}
    ratios = [("ours", "fcpw")]
    if hierarchy:
        clocks["hierarchy"] = lambda: part_distances(mesh, CUTOFF).query_s
        ratios.append(("ours", "hierarchy"))
    bench.interleave(
        clocks, ratios, reported=True,
        columns_of={"ours": {"precision": "float64, exact"},
                    "hierarchy": {"precision": "float64, exact"},
                    "fcpw": {"precision": "float32", "fcpw_off": c["off"],
                             "fcpw_max_error_mm": c["max_abs_error"],
                             "cutoff_disagreements": c["cutoff_disagreements"]}},
        nodes=mesh.n_nodes, queries=ours.nodes_queried, cutoff_mm=CUTOFF)
