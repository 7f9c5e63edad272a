"""Nearest points on triangles, exact in float64: the kernel, the trees and the queries over them.

=================  ================================================================
``triangle``       the backward-stable point–triangle kernel and its error model
``bvh``            a bounding-box hierarchy over triangles, nearest-point queries
``batch``          many points at once, each ignoring some parts
``hierarchy``      crash2000's per-part hierarchies (AABB or OBB) in one forest of arrays
``parts``          per-node distance to the other parts, part connectivity, flange
                   distances
``penetrations``   initial penetrations: nodes nearer another part than half the sum of
                   the two shell thicknesses (crash2000 §4.1), optionally self-contact
``state``          the trees and search scratch as the kernels take them (NamedTuples)
=================  ================================================================

Every distance here is within the kernel's stated error of the exact value; the Hausdorff
brackets (:mod:`workbench.algo.hausdorff`) and the simplifier's bounds build on it."""
