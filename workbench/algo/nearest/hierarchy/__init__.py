"""Bounding-volume hierarchies over FE shell elements, one tree per part under one top level.

:class:`ElementHierarchy` is the per-part hierarchy of crash2000 (Sommer & Ertl, §4): for a set
of elements of an :class:`~workbench.scene.mesh.FEMesh` it builds one tree per part and a top
level over the parts, all in one forest of flat arrays that numba traverses.

* **Geometry.** An element is the triangles :attr:`FEMesh.triangulation` gives it (a quad split
  along its shorter diagonal, a triangle as itself, nothing for a topologically degenerate
  element); its bounding volume encloses its corner nodes, which for every element with
  triangles are exactly the triangles' vertices.
* **Bounding volumes** (``kind``): ``"aabb"`` axis-aligned boxes, or ``"obb"`` oriented boxes
  after Gottschalk, Lin & Manocha (*OBBTree*, 1996): the frame is the eigenvector basis of the
  area-weighted covariance of the node's triangles (the vertex covariance where they have no
  area), made exactly right-handed and orthonormal (a node whose elements span no plane, a
  segment or a point, takes its parent's frame); the extents come from projecting every
  corner node onto that frame. Any orthonormal frame encloses the nodes, so degenerate and
  planar parts only change how tight the box is: a planar part gets one axis along its normal
  with (nearly) zero extent. Every box is widened by a few units in the last place of the
  coordinates so that rounding never excludes a point it should contain.
* **Trees.** Top down, a node's elements (its parts, at the top level) are split at the median
  of their centres along the longest axis of the centres' box (``"aabb"``) or the principal
  axis of the centres (``"obb"``, as Gottschalk splits), until a node holds at most
  ``leaf_size`` elements. A tree over n elements therefore has the same number of nodes for both
  kinds (2n − 1 with one element per leaf). The top level is a tree of the same kind over the
  parts whose leaves *are* the parts' roots: each top node encloses whole parts, each part's
  subtree only that part, so a query can skip a part (its own, say) at its root.
* **Layout.** Nodes are numbered top level first (``P − 1`` nodes for P parts, breadth first),
  then each part's tree, breadth first with siblings adjacent. Every node covers a contiguous
  range ``start[i]:end[i]`` of the elements in tree order (:attr:`element_order` gives their
  mesh indices), so a leaf's elements are read in one sweep.

Queries (exact in float64; lengths in the mesh's units, millimetres for crash decks):

* :meth:`ElementHierarchy.nearest` -- for each point the nearest element within a cut-off,
  optionally skipping some parts per point (crash2000 §4.1, also the counters of its Table 2).
  Branch and bound, iterative with a small stack, the nearer child first; inside a leaf an
  element whose *slab* (the element between two parallel planes along its normal, see
  :attr:`slab`) is already farther than the best distance so far is skipped without computing
  its exact distance (the paper's point-to-plane test).
* :meth:`ElementHierarchy.cut_by_plane` -- the elements a plane cuts (crash2000 §4.2, section
  planes of force tubes), visiting only the bounding volumes the plane meets.

The hierarchy is built in coordinates relative to a float64 origin near the model (the centre
of the bounding box of its nodes unless given), so that models far from the origin keep their
digits; queries take and return the mesh's own coordinates.

The package: :mod:`.element_hierarchy` the class and its queries' result, :mod:`.trees` the
median-split trees and the forest layout, :mod:`.volumes` the slabs and the AABB/OBB boxes,
:mod:`.queries` the numba searches, :mod:`.state` the forest and its elements as those
searches take them (NamedTuples), :mod:`.inputs` the checks and small conversions shared with
:mod:`workbench.algo.nearest.parts`.

Why a second hierarchy beside :class:`~workbench.algo.nearest.bvh.TriangleBVH`: this one is the
subject
of crash2000 §4, so it holds what that tree cannot: FE elements with parts (a quad is one
element of two triangles, a degenerate element is kept for plane cuts), one tree per part under
a top level so that a query skips its own parts at their roots, oriented boxes beside
axis-aligned ones, the slab (point-to-plane) test, the counters of the paper's Table 2 (which
depend on the tree's shape, one element per reference), per-part nearest elements and plane
cuts. It has no hints, no split references of long triangles and no candidate lists within a
radius; those serve the certified bounds of the Hausdorff metric. Measured by
``benchmarks/bvh_compare.py`` (7 interleaved rounds, run twice, 2 cores) on the car deck refined
4 x 4 (139 712 triangles, 70 002 nearest-point queries per set, no part excluded): the AABB
element hierarchy builds in 0.36-0.37x the BVH's time and answers queries within a 1.5 mm
cut-off in 0.94-0.99x its time (medians; single rounds 0.49-1.60x), unbounded ones in
1.07-1.28x; the OBB hierarchy in 1.2-1.5x. Neither is faster at what both do, so each stays for
what only it does.
"""

from .element_hierarchy import KINDS, ElementHierarchy, NearestElements
from .inputs import check_finite, distinct, local_origin, squared_bound, used_nodes

__all__ = ["KINDS", "ElementHierarchy", "NearestElements", "check_finite",
           "distinct", "local_origin", "squared_bound", "used_nodes"]
