"""Certified Hausdorff distance between triangle meshes, exact in float64 (crash2000 §3.2).

The one-sided distance from surface A to surface B is ``H = sup_{p ∈ A} d(p, B)``. Sampling
only ever gives a lower bound, and sampled tools do not say how far below H they are;
:func:`hausdorff` returns a bracket ``lower <= H <= upper`` instead, narrowed to a tolerance:

1. Both meshes are translated by one float64 origin (the centre of A's bounding box), so
   coordinates far from the origin keep their digits in the differences.
2. **Lower bound**: exact distances (through :class:`~workbench.algo.nearest.bvh.TriangleBVH`) of
   A's
   vertices, edge midpoints and face centroids; each is the distance of a point of A, so their
   largest is <= H.
3. **Upper bound** per triangle T of A: the distance to one face f of B is convex in p, so over
   T it peaks at a corner, and ``min_f max_i d(t_i, f)`` bounds ``max_{p∈T} d(p, B)`` from above
   for any set of faces f; the first set is the nearest faces of T's samples.
4. **Refinement** of the triangles whose bound exceeds the lower bound + ``tol``. With
   ``split="planes"`` (default) a triangle is cut into convex pieces by planes chosen where the
   nearest face changes (the bisector of an edge of B, or where the distances to two faces
   cross), so that each piece has one face nearest to all its vertices and its bound equals its
   largest vertex distance: first against the samples' faces and their neighbours only, then,
   for the triangles still above, against every face near each piece, whose exact vertex
   distances raise the lower bound. With ``split="midpoint"`` the triangles are subdivided
   4 ways by :func:`~workbench.algo.nearest.triangle.triangle_bounds` against the faces near them
   (slower: where two faces meet, a piece's bound only shrinks with its size). Either way the
   refinement stops when ``upper - lower <= tol`` or at the depth limit (``tol_reached``).

Any face set gives a valid upper bound; a lower bound needs the nearest face of each point it
measures, which the candidate sets hold by construction (see :func:`~.polygon._gather`).
Distances are in model units. The bracket is certified: its ends are rounded outward by the
bound of their own rounding (:func:`~.metric.bracket_rounding`, the error model of
:mod:`workbench.algo.nearest.triangle`: the backward-stable distance kernel's error, and how far the
measured points, built by interpolation, may lie from A), so it holds the exact value, also 0
for a surface against any refinement of itself, slivers included.

Bracket only (``estimates=False``): steps 2 and 3 run on the few triangles that a cascade of
cheap bounds from A's vertex distances leaves above the lower bound + ``tol``
(:mod:`.cascade`); the other triangles are never sampled, and there are no mean and RMS
estimates.

The package: :mod:`.metric` the public :func:`hausdorff`, :class:`HausdorffResult` and the
one-sided driver; :mod:`.cascade` the cheap bounds of the bracket-only mode; :mod:`.refine` the
sampled upper bounds and their refinement; :mod:`.polygon` the bounds of a triangle cut into
convex pieces; :mod:`.pieces` the geometry of those pieces and of the planes that cut them.
"""

from .metric import (
    DEFAULT_MAX_DEPTH,
    DEFAULT_REL_TOL,
    MAX_DEPTH_LIMIT,
    SPLITS,
    HausdorffResult,
    hausdorff,
)

__all__ = ["DEFAULT_MAX_DEPTH", "DEFAULT_REL_TOL", "MAX_DEPTH_LIMIT", "SPLITS", "HausdorffResult",
           "hausdorff"]
