"""Scalar-field paths: colour per vertex, colour per pixel, and colour per element.

All three normalise the field in float64 on the CPU and look colours up in the 1-D colormap
texture of :mod:`workbench.paths.colormap` (smooth or bands, transfer-function α):

* ``vertex_color`` looks the colour up in the vertex shader at each crease-split vertex and
  interpolates the lit RGB (and the transfer α) across the triangle: contours inside an
  element are lost where the colormap bends between the vertex values, and a hidden range
  cuts where the interpolated α crosses ½.
* ``pixel_color`` interpolates the normalised scalar and looks it up per fragment: the colour
  reference path (smooth or band contours crossing elements, exact hidden-range cuts).
* ``element_color`` draws an element field with one colour per element, lit flat (as the
  ``flat`` path). The value travels as a ``flat`` varying from a provoking vertex of its own
  per element (:func:`provoking_vertices`): the vertices are the mesh nodes plus the few
  duplicates the assignment needs, and no per-fragment fetch is made (a value texture read by
  ``gl_PrimitiveID`` drew the 1 M-triangle es2008 scene about 30 % slower on llvmpipe).

A non-finite value draws the triangles that use it in the no-result colour (the rule of
:mod:`workbench.paths.colormap`): the per-vertex paths flag them in the geometry shader
``no_result.geom.glsl``, ``element_color`` by a flat flag of the element's provoking vertex.

Node fields are drawn by the per-vertex paths and element fields by ``element_color``; the
other pairing is refused with ValueError naming the path that draws it (averaging an element
field to the nodes, or a node field to the elements, would be a different field).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import maximum_bipartite_matching

from .drawdata import Topology
from .mesh import MeshPath

if TYPE_CHECKING:
    from numpy.typing import ArrayLike

    from ..scene.mesh import FEMesh


class VertexColorPath(MeshPath):
    """Gouraud normals, colormap evaluated at the vertices, RGB interpolated."""

    name = "vertex_color"
    needs = frozenset({"gouraud"})
    vertex_shader, fragment_shader = "vertex_color.vert.glsl", "vertex_color.frag.glsl"
    missing_geometry_shader = "no_result.geom.glsl"
    missing_defines = {"VERTEX_COLOR": 1}
    split = True
    field_per = "node"


class PixelColorPath(MeshPath):
    """Gouraud normals, scalar interpolated, colour looked up per fragment (the reference)."""

    name = "pixel_color"
    needs = frozenset({"gouraud"})
    vertex_shader, fragment_shader = "pixel_color.vert.glsl", "pixel_color.frag.glsl"
    missing_geometry_shader = "no_result.geom.glsl"
    split = True
    field_per = "node"


class ElementColorPath(MeshPath):
    """One colour per element from an element field, flat lit; the value rides on a provoking
    vertex per element (``flat`` varying, last-vertex convention)."""

    name = "element_color"
    needs = frozenset({"triangles"})
    vertex_shader, fragment_shader = "element_color.vert.glsl", "element_color.frag.glsl"
    field_per = "element"

    def topology(self, mesh: FEMesh) -> Topology:
        """The mesh nodes plus the duplicates :func:`provoking_vertices` needs, each element's
        triangles rotated so that its own vertex comes last."""
        vertex_node, triangles, provoking = provoking_vertices(
            mesh.triangles, mesh.triangulation.element_of, mesh.n_nodes, mesh.n_elements)
        return Topology(vertex_node, triangles, element_vertex=provoking)


def provoking_vertices(triangles: ArrayLike, element_of: ArrayLike, n_nodes: int,
                       n_elements: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Give every element its own provoking vertex, for ``flat`` per-element attributes.

    ``triangles`` (K, 3) node indices and ``element_of`` (K,) their elements, non-decreasing
    (as ``mesh.triangulation``). Each element needs a vertex shared by all its triangles that
    no other element uses as provoking vertex; its triangles are then rotated (winding kept) so
    that this vertex comes last (``GL_LAST_VERTEX_CONVENTION``). Candidates are the nodes
    common to the element's triangles (a quad's split diagonal, a triangle's three nodes);
    elements and candidates are paired by a maximum bipartite matching (Hopcroft–Karp, scipy),
    and an element left unmatched gets a duplicate of its lowest-numbered candidate as a new
    vertex: none on a regular quad grid, 156 for the 4 366 quads of the car6 deck, 0.3 % of the
    nodes on generated stamped panels.

    Returns ``(vertex_node, triangles, provoking)``: (V,) int64 node of each vertex (the nodes
    0..N−1 themselves, then the duplicates), (K, 3) int32 rotated triangles into vertices, and
    (M,) int64 provoking vertex of each element (−1 for an element without triangles).
    Refuses a decreasing ``element_of`` or an element whose triangles share no node.
    """
    tri = np.asarray(triangles, np.int64)
    el = np.asarray(element_of, np.int64)
    k = len(tri)
    if (np.diff(el) < 0).any():
        raise ValueError("element_of must be non-decreasing (an element's triangles together)")
    start = np.flatnonzero(np.r_[True, el[1:] != el[:-1]]) if k else np.zeros(0, np.int64)
    rank = np.arange(k) - np.repeat(start, np.diff(np.r_[start, k]))
    slot = np.repeat(np.arange(len(start)), np.diff(np.r_[start, k]))  # element slot per triangle
    cand = tri[start].copy()  # candidates: the first triangle's nodes that later ones hold too
    for r in range(1, int(rank.max(initial=0)) + 1):
        sel = rank == r
        inside = (cand[slot[sel]][:, :, None] == tri[sel][:, None, :]).any(axis=2)
        cand[slot[sel]] = np.where(inside, cand[slot[sel]], -1)
    if (cand < 0).all(axis=1).any():
        raise ValueError("an element's triangles share no node")
    ok = cand >= 0
    rows = np.repeat(np.arange(len(start)), 3)[ok.ravel()]
    pairs = csr_matrix((np.ones(len(rows), np.int8), (rows, cand[ok])),
                       shape=(len(start), n_nodes))
    chosen = maximum_bipartite_matching(pairs, perm_type="column").astype(np.int64)
    left = np.flatnonzero(chosen < 0)
    base = np.where(ok[left], cand[left], n_nodes).min(axis=1)
    chosen[left] = n_nodes + np.arange(len(left))
    vertex_node = np.r_[np.arange(n_nodes), base]
    out = tri.copy()
    dup = np.flatnonzero(chosen[slot] >= n_nodes)
    if len(dup):  # the duplicated node of those elements' triangles becomes the new vertex
        new = chosen[slot[dup]]
        out[dup] = np.where(out[dup] == vertex_node[new][:, None], new[:, None], out[dup])
    # rotate so that the provoking vertex comes last: (a, b, p) keeps the cyclic order
    j = np.argmax(out == chosen[slot][:, None], axis=1)
    out = np.take_along_axis(out, (j[:, None] + np.array([1, 2, 3])) % 3, axis=1)
    provoking = np.full(n_elements, -1, np.int64)
    provoking[el[start]] = chosen
    return vertex_node, out.astype(np.int32), provoking
