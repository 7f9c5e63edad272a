"""Force tubes (crash2000, §4.2 and Fig. 7): how much force a structure carries along a trace
line, per section plane and time step, drawn as a tube whose rings grow and colour with it.

The engineer picks two or more **control points** (the trace line, model units). Each segment
carries section planes equally spaced along it and orthogonal to it; near each joint the
normals are blended between the two segments' directions (:func:`section_planes`). For every
plane the shell elements it cuts are found (by default with a vectorised test of the nodes'
signed distances; a bounding-volume hierarchy can be plugged in as ``cut``) and the **section
force** through the plane is integrated (:func:`section_force`). :func:`force_tube` does this
for every plane and step, with the control points following the deformation;
:func:`tube_mesh` turns one step (or all) into an :class:`~workbench.scene.mesh.FEMesh` tube
with a node field ``"section_force"`` for the colour map, and :func:`with_tube` appends it to
the model.

**The section force.** For a shell element with mid-surface stress tensor σ (3 × 3, global
coordinates, stress units) and thickness t (model units), the force transmitted across a cut
line of the mid-surface is ``t · ∫ σ·m dl``, with m the unit normal of the cut line inside the
element's surface, pointing to the side the plane normal points to. The stress is uniform per
element (one value per shell, as a d3plot stores it), so the integral is ``t · σ · (m L)`` with
L the cut length, and ``m L = c × ν`` for the cut segment c (oriented counter-clockwise about
the triangle normal ν as part of the boundary of the triangle's negative part). Quads are
split into the triangles (0, 1, 2) and (0, 2, 3); a triangle element (third node repeated)
is its first triangle. The cut is exact in float64 (no sampling): the crossing points of the
edges are the linear interpolation of the nodes by their signed distances. The result is the
force that the material on the positive side of the plane exerts on the material on the
negative side: a structure in tension along the normal gives a positive **axial force**
(the force's component along the unit normal); the axial force does not depend on which way
the normal points, the force vector flips with it.

**Nodes on the plane (the tie rule).** Every node is classified once per plane by its signed
distance s = (x − p)·n: negative (s < 0) or not (s ≥ 0; a node exactly on the plane counts
as positive). An element contributes the cut of its negative part; hence

* an element whose nodes are all negative, or all non-negative, contributes nothing;
* an element touching the plane only at a node contributes nothing (either side);
* an edge lying in the plane is counted exactly once, by the element on the negative side
  (the element on the positive side touches the plane along that edge and contributes
  nothing); an element lying in the plane contributes nothing.

Because the classification is per node, neighbouring elements always agree, so a closed
cross-section is cut along one closed line whatever nodes happen to lie on the plane.

**How this differs from the paper.** crash2000 accumulates the *nodal* forces of the vertices
on the normal side of the plane that belong to elements with vertices on the other side.
A d3plot holds element stresses, not nodal internal forces, so here the traction of each cut
element's membrane stress is integrated across the cut instead. For a uniform stress the
two agree; on a coarse mesh with varying stress the paper's sum depends on how the elements
straddle the plane, this integral on the stress per element.

Refused with ValueError (one clear message each): fewer than two control points, non-finite
control points or coordinates, a zero-length segment, a trace line that turns straight back
on itself, a zero plane normal, missing stress or thickness fields, bad shapes.

Modules: :mod:`.planes` (the section planes of a trace line), :mod:`.section` (the force
through one plane, the stress tensor of the element fields), :mod:`.tube` (every plane and
step), :mod:`.geometry` (the tube as a mesh) and :mod:`.prismatic` (a load case with a
closed-form answer).
"""

from .geometry import TUBE_FIELD, tube_mesh, with_tube
from .planes import section_planes
from .prismatic import prismatic_tube
from .section import STRESS_FIELDS, THICKNESS_FIELD, crossing_elements, section_force, stress_tensor
from .tube import BRUTE_FORCE, ForceTube, force_tube

__all__ = ["BRUTE_FORCE", "STRESS_FIELDS", "THICKNESS_FIELD", "TUBE_FIELD", "ForceTube",
           "crossing_elements", "force_tube", "prismatic_tube", "section_force",
           "section_planes", "stress_tensor", "tube_mesh", "with_tube"]
