"""What a mesh path draws, without OpenGL: vertices, index layout, per-step arrays, colour scale.

:meth:`MeshPath.draw_data <workbench.paths.mesh.MeshPath.draw_data>` builds a
:class:`MeshDrawData` from a mesh and the path's style; the GL path uploads it, and the
software rasterizer (:mod:`workbench.paths.software`) rasterizes the same object. Everything
here is numpy on the CPU, float64 until the float32 arrays a renderer takes.

The pieces a path's preparation produces, in order:

* :class:`Topology` — the drawn vertices (the node of each, or the nodes themselves) and the
  triangles into them; for crease-split paths the split and the split row of each vertex, for
  element paths the vertex that carries each element's value;
* :class:`Layout` — the index buffer for ``Style.strips`` and ``Style.quad_diagonal``: a
  triangle list, or strip indices with :data:`~workbench.algo.strips.RESTART` markers;
* then vertices no triangle uses are dropped and the indices renumbered
  (:func:`compact`), giving :class:`MeshDrawData`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from ..algo.strips import RESTART, unstripify
from . import colormap

if TYPE_CHECKING:
    from ..scene.crease import GouraudSplit
    from ..scene.mesh import FEMesh
    from .colormap import ColorScale
    from .style import Style

PRIMITIVES = ("triangles", "triangle_strip")


@dataclass(eq=False)
class Topology:
    """The drawn vertices of a mesh path and its triangles.

    ``vertex_node`` (V,) node of each vertex, None when the vertices are the nodes themselves;
    ``triangles`` (K, 3) into the vertices; ``split`` the crease split whose normals the
    vertices take (None: no normals) and ``split_rows`` (V,) the row of each vertex in it
    (None: vertex i is split vertex i); ``element_vertex`` (M,) the vertex carrying each
    element's value (−1: none; element paths only); ``attributes`` the extra per-vertex
    float32 arrays uploaded once, as (data, format, name)."""

    vertex_node: np.ndarray | None
    triangles: np.ndarray
    split: GouraudSplit | None = None
    split_rows: np.ndarray | None = None
    element_vertex: np.ndarray | None = None
    attributes: list[tuple[np.ndarray, str, str]] = field(default_factory=list)


@dataclass(eq=False)
class Layout:
    """The index buffer: ``index`` (K, 3) triangles or a 1-D strip index array with restart
    markers, ``primitive`` ("triangles" or "triangle_strip"), and the counts ``triangles``
    (triangles drawn), ``strips`` (primitives restarted, 0 for a list) and ``vertices_sent``
    (vertex indices one draw sends, restart markers excluded). ``triangle_element`` (T,) the
    element of each listed triangle where the list keeps element identity, else None."""

    index: np.ndarray
    primitive: str
    triangles: int
    strips: int
    vertices_sent: int
    triangle_element: np.ndarray | None = None


@dataclass(eq=False)
class MeshDrawData:
    """Everything a mesh path draws of ``mesh`` with ``style``, GL-free.

    ``vertex_node`` (V,) int64 node of each drawn vertex (None: the nodes themselves, all of
    them used); ``index`` int32 (K, 3) triangles or uint32 strip indices (``primitive``);
    ``triangles``, ``strips``, ``vertices_sent`` as :class:`Layout`; ``split`` and
    ``split_rows`` give per-vertex normals (crease-split paths); ``field_per`` ("node",
    "element" or None) and ``scale`` (the :class:`ColorScale`) the colour of the field;
    ``element_vertex`` (M,) the vertex carrying each element's value; ``attributes`` static
    per-vertex float32 arrays (data, format, name); ``edges`` (E, 2) int32 vertex pairs of the
    line-overdraw wire frame (None without); ``triangle_element`` as :class:`Layout`.
    ``erodes``: whether the mesh deletes elements at some step, read once when made.
    """

    mesh: FEMesh
    style: Style
    vertex_node: np.ndarray | None
    n_vertices: int
    index: np.ndarray
    primitive: str
    triangles: int
    strips: int
    vertices_sent: int
    split: GouraudSplit | None = None
    split_rows: np.ndarray | None = None
    field_per: str | None = None
    scale: ColorScale | None = None
    element_vertex: np.ndarray | None = None
    attributes: list[tuple[np.ndarray, str, str]] = field(default_factory=list)
    edges: np.ndarray | None = None
    triangle_element: np.ndarray | None = None

    def __post_init__(self) -> None:
        # whether the mesh deletes elements at some step, decided once (not per step)
        self.erodes = bool(self.mesh.erodes)

    # ------------------------------------------------------------------ per step
    def shown_coordinates(self, step: int) -> np.ndarray:
        """(N, 3) float64 node positions drawn for ``step``: ``reference + magnification·
        (step − reference)`` in float64 per node (the deformation plot)."""
        mesh, style = self.mesh, self.style
        current = mesh.coordinates(step)
        if style.magnification == 1.0 or step == style.reference_step:
            return current
        reference = mesh.coordinates(style.reference_step)
        return reference + style.magnification * (current - reference)

    def positions(self, shown: np.ndarray, origin: np.ndarray) -> np.ndarray:
        """(V, 3) float32 vertex positions relative to ``origin``, from the node positions
        ``shown`` (subtracted in float64, then cast)."""
        points = shown if self.vertex_node is None else shown[self.vertex_node]
        return (points - origin).astype(np.float32)

    def normals(self, shown: np.ndarray) -> np.ndarray | None:
        """(V, 3) float32 crease-split vertex normals for node positions ``shown``; None for a
        path without normals."""
        if self.split is None:
            return None
        normals = self.split.normals(shown)
        if self.split_rows is not None:
            normals = normals[self.split_rows]
        return normals.astype(np.float32)

    @property
    def static_values(self) -> bool:
        """Whether the field is the same at every step (uploaded once)."""
        return self.field_per is not None and self._field().ndim == 1

    @property
    def has_missing(self) -> bool:
        """Whether the field has a non-finite value at any step: the path then draws the
        no-result rule (:mod:`~workbench.paths.colormap`) with a missing flag per vertex."""
        return self.field_per is not None and not bool(np.isfinite(self._field()).all())

    def _field(self) -> np.ndarray:
        fields = self.mesh.node_fields if self.field_per == "node" else self.mesh.element_fields
        return fields[self.style.field]

    def normalised(self, step: int) -> np.ndarray:
        """The field at ``step`` normalised by the scale, per node or per element (float64;
        non-finite values kept as NaN)."""
        mesh, name = self.mesh, self.style.field
        values = mesh.node_field(name, step) if self.field_per == "node" \
            else mesh.element_field(name, step)
        return self.scale.normalise(values)

    def values(self, step: int) -> tuple[np.ndarray, np.ndarray, int]:
        """``(values, missing, count)`` at ``step``: (V,) float32 normalised field values per
        vertex (0 where a node's value is not finite), (V,) float32 missing flags per vertex (1
        where the vertex's node, or the element it carries, has no finite value; else 0) and
        how many node or element values were not finite (:func:`~.colormap.mark_missing`)."""
        t, missing = colormap.mark_missing(self.normalised(step))
        return (self.vertex_values(t).astype(np.float32),
                self.vertex_values(missing.astype(np.float64)).astype(np.float32),
                int(missing.sum()))

    def vertex_values(self, t: np.ndarray) -> np.ndarray:
        """(V,) per-vertex values from per-node values, or from per-element values through
        each element's vertex (the others 0)."""
        if self.field_per == "element":
            has = self.element_vertex >= 0
            out = np.zeros(self.n_vertices, np.float64)
            out[self.element_vertex[has]] = t[has]
            return out
        return t if self.vertex_node is None else t[self.vertex_node]

    def live_triangles(self, step: int) -> np.ndarray | None:
        """(T,) bool over the triangle list, the triangles of elements in use at ``step``;
        None where the mesh deletes no element or the layout is strips (no
        ``triangle_element``): everything is drawn (:class:`~.mesh.ErosionWarning`)."""
        if not self.erodes or self.triangle_element is None:
            return None
        return self.mesh.alive(step)[self.triangle_element]

    def live_edges(self, step: int) -> np.ndarray | None:
        """(E,) bool over ``edges``, the wire-frame edges of elements in use at ``step``; None
        without erosion or without a wire frame."""
        if self.edges is None or not self.erodes:
            return None
        return self.mesh.live_edges(step)

    def triangle_list(self) -> np.ndarray:
        """(T, 3) int64 the drawn triangles as a list (strips unrolled, restarts dropped)."""
        if self.primitive == "triangles":
            return np.asarray(self.index, np.int64).reshape(-1, 3)
        return unstripify(np.asarray(self.index, np.uint32)).astype(np.int64)


def compact(topology: Topology, layout: Layout, n_nodes: int
            ) -> tuple[np.ndarray | None, int, np.ndarray, np.ndarray | None, np.ndarray | None]:
    """Drop the vertices no triangle of ``topology`` uses and renumber: returns
    ``(vertex_node, n_vertices, index, split_rows, remap)`` where ``remap`` (V,) maps old
    vertex numbers to new ones (−1 dropped), None when every vertex is used."""
    vertex_node, triangles = topology.vertex_node, topology.triangles
    n_vertices = n_nodes if vertex_node is None else len(vertex_node)
    index, split_rows = layout.index, topology.split_rows
    used = np.zeros(n_vertices, bool)
    used[triangles.ravel()] = True
    remap = None
    if not used.all():  # unreferenced nodes are not uploaded
        keep = np.flatnonzero(used)
        remap = np.full(n_vertices, -1, np.int64)
        remap[keep] = np.arange(len(keep))
        vertex_node = keep if vertex_node is None else vertex_node[keep]
        if topology.split is not None:
            split_rows = keep if split_rows is None else split_rows[keep]
        if index.ndim == 1:  # strip indices: restart markers stay
            marker = index == RESTART
            index = np.where(marker, RESTART, remap[np.where(marker, 0, index)])
            index = index.astype(np.uint32)
        else:
            index = remap[index]
        n_vertices = len(keep)
    index = np.ascontiguousarray(index, dtype=np.uint32 if index.ndim == 1 else np.int32)
    return vertex_node, n_vertices, index, split_rows, remap


def vertex_of_node(vertex_node: np.ndarray | None, n_nodes: int) -> np.ndarray:
    """(N,) one vertex index per referenced node (the first vertex of each)."""
    if vertex_node is None:
        return np.arange(n_nodes)
    first = np.full(n_nodes, -1, np.int64)
    first[vertex_node[::-1]] = np.arange(len(vertex_node))[::-1]
    return first
