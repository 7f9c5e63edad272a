"""Throughput of the exact distance queries on the car deck refined k x k.

Timed interleaved, after one warm-up round (numba kernels compile or load from their cache),
on the shared car deck refined 8 x 8 (quick: 2 x 2):

* ``part_distance`` -- :func:`workbench.algo.nearest.parts.batched_part_distances`, every
  node against the other parts within 1.5 mm (crash2000 §4.1); its own query seconds;
* ``hausdorff_fine_to_coarse`` -- :func:`workbench.algo.hausdorff.hausdorff` from the refined
  car to the car (default tolerance, 1e-4 of the diagonal); wall seconds;
* ``hausdorff_fine_to_coarse_bracket`` -- the same with ``estimates=False`` (the bracket only).

(The other direction, the car against its refinement, is not a throughput measure: each of
the car's triangles faces dozens of the refinement's.) To compare two versions of the
point-triangle kernel, run this benchmark on each commit and compare the two stored runs with
``workbench results compare``.

Run: ``workbench bench distance_throughput [--quick]`` (needs the shared car deck).
"""

from __future__ import annotations

from workbench.data import CAR_DECK
from workbench.measurement.bench import Case, benchmark, needs_shared_file, seconds_of

CUTOFF = 1.5


@benchmark("distance_throughput", "exact part distances and the Hausdorff metric on the "
                                  "refined car deck",
           cases=[Case("car", {"refine": 8}, {"refine": 2})],
           requires=[needs_shared_file(CAR_DECK)])
def distance_throughput(bench, refine: int) -> None:
    import numba
    import numpy as np

    from workbench import data
    from workbench.algo.hausdorff import hausdorff
    from workbench.algo.nearest.parts import batched_part_distances
    from workbench.scene.generators import refine as refined
    from workbench.scene.readers import load

    car = load(data.shared_file(CAR_DECK))
    fine = refined(car, refine)
    vc, fc = car.coordinates(0), np.asarray(car.triangulation.triangles, np.int64)
    vf, ff = fine.coordinates(0), np.asarray(fine.triangulation.triangles, np.int64)
    bench.interleave(
        {"part_distance": lambda: batched_part_distances(fine, CUTOFF).query_s,
         "hausdorff_fine_to_coarse": lambda: seconds_of(lambda: hausdorff(vf, ff, vc, fc)),
         "hausdorff_fine_to_coarse_bracket": lambda: seconds_of(
             lambda: hausdorff(vf, ff, vc, fc, estimates=False))},
        reported=True, triangles=len(ff), threads=numba.get_num_threads())
