"""Scalar-field paths: colour per vertex, colour per pixel, and colour per element.

All three normalise the field in float64 on the CPU and look colours up in the 1-D colormap
texture of :mod:`workbench.paths.colormap` (smooth or bands, transfer-function α):

* ``vertex_color`` looks the colour up in the vertex shader at each crease-split vertex and
  interpolates the lit RGB (and the transfer α) across the triangle: contours inside an
  element are lost where the colormap bends between the vertex values, and a hidden range
  cuts where the interpolated α crosses ½.
* ``pixel_color`` interpolates the normalised scalar and looks it up per fragment: the colour
  reference path (smooth or band contours crossing elements, exact hidden-range cuts).
* ``element_color`` draws an element field with one colour per element: each triangle reads
  its element's value from a float texture indexed by ``gl_PrimitiveID`` and is lit flat (as
  the ``flat`` path), so vertices are the mesh nodes and no value is duplicated per vertex.

Node fields are drawn by the per-vertex paths and element fields by ``element_color``; the
other pairing is refused with ValueError naming the path that draws it (averaging an element
field to the nodes, or a node field to the elements, would be a different field).
"""

from __future__ import annotations

from .base import MeshPath


class VertexColorPath(MeshPath):
    """Gouraud normals, colormap evaluated at the vertices, RGB interpolated."""

    name = "vertex_color"
    needs = frozenset({"gouraud", "node_field"})
    vertex_shader, fragment_shader = "vertex_color.vert.glsl", "vertex_color.frag.glsl"
    split = True
    field_per = "node"


class PixelColorPath(MeshPath):
    """Gouraud normals, scalar interpolated, colour looked up per fragment (the reference)."""

    name = "pixel_color"
    needs = frozenset({"gouraud", "node_field"})
    vertex_shader, fragment_shader = "pixel_color.vert.glsl", "pixel_color.frag.glsl"
    split = True
    field_per = "node"


class ElementColorPath(MeshPath):
    """One colour per element from an element field, flat lit."""

    name = "element_color"
    needs = frozenset({"triangles", "element_field"})
    vertex_shader, fragment_shader = "flat.vert.glsl", "element_color.frag.glsl"
    field_per = "element"
