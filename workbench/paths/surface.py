"""Uncoloured surface paths: the position-only floor, flat shading, and Gouraud shading.

* ``position`` draws the triangles in ``Style.base_color`` without lighting or normals: the
  cheapest draw of the scene, the floor every other path is measured against.
* ``flat`` shades each triangle with its face normal, taken in the fragment shader from the
  screen-space derivatives of the eye-space position, ``n = dFdx(p) × dFdy(p)``. Nothing but
  positions is uploaded per step (no normals, no vertex duplication, no CPU normal pass), at
  the price of a cross product per fragment. For a planar element this is the element normal;
  a warped quad shows the normals of its two triangles.
* ``gouraud`` shades the crease-split vertices (``mesh.gouraud(Style.crease_deg)``) with their
  per-vertex normals: smooth across edges flatter than the crease angle, sharp across creases.
"""

from __future__ import annotations

from .mesh import MeshPath


class PositionPath(MeshPath):
    """Constant colour, positions only: no normals, no lighting."""

    name = "position"
    needs = frozenset({"triangles"})
    vertex_shader, fragment_shader = "position.vert.glsl", "position.frag.glsl"


class FlatPath(MeshPath):
    """Per-face normal from screen-space derivatives, uniform base colour."""

    name = "flat"
    needs = frozenset({"triangles"})
    vertex_shader, fragment_shader = "flat.vert.glsl", "flat.frag.glsl"


class GouraudPath(MeshPath):
    """Per-vertex normals with the crease split, lighting per vertex, uniform base colour."""

    name = "gouraud"
    needs = frozenset({"gouraud"})
    vertex_shader, fragment_shader = "gouraud.vert.glsl", "gouraud.frag.glsl"
    split = True
