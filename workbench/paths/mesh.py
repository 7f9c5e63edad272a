"""The shared implementation of the FE mesh paths: draw data built on the CPU, uploaded once.

:class:`MeshPath` builds a :class:`~workbench.paths.drawdata.MeshDrawData` for a mesh
(:meth:`MeshPath.draw_data`, GL-free: the software rasterizer draws the same object) and
uploads it: one indexed triangle VAO, optionally a wire-frame VAO of lines. Per time step it
uploads positions (and normals, and time-dependent field values), never topology.

Subclasses choose shaders and two switches: ``split`` (vertices are the crease-split Gouraud
vertices with per-vertex normals; otherwise the mesh's referenced nodes without normals) and
``field_per`` (None, ``"node"`` or ``"element"``: the field's normalised values go up as a
per-vertex float attribute ``value``). :meth:`MeshPath.topology` and :meth:`MeshPath.layout`
may be overridden to number the vertices or lay out the index buffer differently.

A field with a non-finite value at any step is drawn by the no-result rule of
:mod:`~workbench.paths.colormap`: the shaders are compiled with ``MISSING``, a per-vertex float
attribute ``missing`` (0 or 1) goes up beside ``value``, and the path's
``missing_geometry_shader`` (the per-vertex field paths: ``no_result.geom.glsl``) turns it into
one flag per triangle; an element path's flag rides on the element's provoking vertex.
"""

from __future__ import annotations

import warnings
from typing import TYPE_CHECKING, ClassVar

import moderngl
import numpy as np

from ..algo.strips import RESTART, quad_strips, tri_strips
from ..gl import Camera, load_program
from .base import GLPath
from .colormap import NO_RESULT_COLOR, ColorScale, scale_for
from .drawdata import Layout, MeshDrawData, Topology, compact, vertex_of_node
from .kinds import build_overlay, warn_not_drawn
from .style import GHOST_ALPHA, Style

if TYPE_CHECKING:
    from ..scene.mesh import FEMesh
    from ..scene.protocol import Scene

PRIMITIVE_MODES = {"triangles": moderngl.TRIANGLES, "triangle_strip": moderngl.TRIANGLE_STRIP}


def field_kind(mesh: FEMesh, name: str) -> str:
    """'node' or 'element' for a field of ``mesh``; KeyError listing the mesh's fields otherwise."""
    if name in mesh.node_fields:
        return "node"
    if name in mesh.element_fields:
        return "element"
    raise KeyError(f"{mesh.name} has no field {name!r}; node fields: {sorted(mesh.node_fields)}, "
                   f"element fields: {sorted(mesh.element_fields)}")


class ErosionWarning(UserWarning):
    """A path draws elements the mesh deletes at the drawn state (erosion): said, not hidden."""


class MeshPath(GLPath):
    """An FE mesh drawn from its :class:`MeshDrawData` (see the module docstring)."""

    vertex_shader: ClassVar[str]
    fragment_shader: ClassVar[str]
    # the geometry shader of the no-result rule (None: the flag needs none) and its defines
    missing_geometry_shader: ClassVar[str | None] = None
    missing_defines: ClassVar[dict] = {}
    split: ClassVar[bool] = False
    field_per: ClassVar[str | None] = None
    style: Style
    _ghost_vao = None  # the ghost pass of deleted elements (Style.deleted = "ghost"), if any
    _kinds = None  # the beams and SPH particles drawn over the surface (paths.kinds), if any

    @classmethod
    def default_camera(cls, scene: Scene, size: tuple[int, int], *,
                       view: tuple[float, float] = (30.0, 25.0),
                       projection: str = "orthographic", up: str = "z",
                       style: object | None = None) -> Camera:
        """:meth:`Camera.fit_box` over the bounds of every step of the mesh at azimuth and
        elevation ``view`` (degrees)."""
        return cls.fit_camera(*scene.bounds(all_steps=True), size, view=view,
                              projection=projection, up=up)

    # ------------------------------------------------------------------ draw data (GL-free)
    def check_mesh(self, mesh: FEMesh) -> ColorScale | None:
        """Refuse a mesh or style this path cannot draw (ValueError, KeyError for an unknown
        field); the colour scale of the field drawn (None without a field)."""
        if getattr(mesh, "kind", None) != "mesh":
            raise ValueError(f"path {self.name!r} draws an FE mesh, got {type(mesh).__name__}")
        style = self.style
        for label in ("step", "reference_step"):
            if getattr(style, label) >= mesh.n_steps:
                raise ValueError(f"{label} {getattr(style, label)} out of range: "
                                 f"{mesh.name} has {mesh.n_steps} steps")
        if self.field_per is None:
            return None
        self._check_field(mesh)
        return scale_for(mesh, style.field, style.colormap, style.value_range, style.bands,
                         style.hide_range)

    def _check_field(self, mesh) -> None:
        name = self.style.field
        if name in getattr(mesh, "unavailable", {}):
            raise ValueError(f"{name} cannot be drawn: {mesh.unavailable[name]}")
        if name is None:
            raise ValueError(f"path {self.name!r} draws a field: set Style.field to one of "
                             f"node fields {sorted(mesh.node_fields)} or element fields "
                             f"{sorted(mesh.element_fields)}")
        kind = field_kind(mesh, name)
        if kind != self.field_per:
            other = "element_color" if kind == "element" else "pixel_color or vertex_color"
            article = "an" if kind == "element" else "a"
            raise ValueError(f"path {self.name!r} draws {self.field_per} fields, {name!r} is "
                             f"{article} {kind} field: draw it with {other}")

    def topology(self, mesh: FEMesh) -> Topology:
        """The drawn vertices and triangles: the crease-split vertices (``split``) or the mesh
        nodes, triangles in the triangulation's order."""
        if self.split:
            split = mesh.gouraud(self.style.crease_deg)
            return Topology(np.asarray(split.vertex_node, np.int64), split.triangles, split=split)
        return Topology(None, mesh.triangles)

    def layout(self, mesh: FEMesh, topology: Topology) -> Layout:
        """The index buffer for ``Style.strips`` and ``Style.quad_diagonal`` (see
        :class:`Layout`); ValueError for strips of a path whose vertices are not shared."""
        style, triangles = self.style, topology.triangles
        if style.strips == "none" and style.diagonal == "shorter":
            return Layout(triangles, "triangles", len(triangles), 0, triangles.size,
                          triangle_element=mesh.triangulation.element_of)
        if type(self).topology is not MeshPath.topology:
            raise ValueError(f"path {self.name!r} gives every triangle its own provoking vertex; "
                             f"strips and strip diagonals need shared vertices: draw it with "
                             f"strips='none' and quad_diagonal='shorter'")
        if style.diagonal == "strip":
            elements = topology.split.elements if self.split else mesh.elements
            quads = quad_strips(elements, style.strip_cutoff)
            if style.strips == "quad":
                index = quads.restart_indices(RESTART)
                strips = quads.n_strips + len(quads.leftover) + len(quads.triangles)
                return Layout(index, "triangle_strip", len(triangles), strips,
                              len(index) - max(strips - 1, 0))
            triangles = quads.triangle_list()
        if style.strips == "triangle":
            n_vertices = mesh.n_nodes if topology.vertex_node is None \
                else len(topology.vertex_node)
            tri = tri_strips(triangles, n_vertices, RESTART)
            return Layout(tri.indices, "triangle_strip", len(triangles), tri.n_strips,
                          tri.n_vertices)
        return Layout(triangles, "triangles", len(triangles), 0, triangles.size)

    def draw_data(self, mesh: FEMesh) -> MeshDrawData:
        """What this path draws of ``mesh`` with its style, GL-free (refusals as
        :meth:`check_mesh` and :meth:`layout`)."""
        scale = self.check_mesh(mesh)
        topology = self.topology(mesh)
        layout = self.layout(mesh, topology)
        if mesh.erodes and layout.triangle_element is None:
            deleted = int((~np.stack([mesh.alive(t) for t in range(mesh.n_steps)])).any(0).sum())
            warnings.warn(f"{mesh.name} deletes {deleted} elements part-way (erosion); path "
                          f"{self.name!r} draws strips, which keep every element: the deleted "
                          f"ones are drawn (a triangle list hides them: strips='none', "
                          f"quad_diagonal='shorter')", ErosionWarning, stacklevel=2)
        vertex_node, n_vertices, index, split_rows, remap = compact(topology, layout,
                                                                    mesh.n_nodes)
        element_vertex = topology.element_vertex
        attributes = [(np.ascontiguousarray(data, np.float32), fmt, name)
                      for data, fmt, name in topology.attributes]
        if remap is not None:
            keep = np.flatnonzero(remap >= 0)
            attributes = [(data[keep], fmt, name) for data, fmt, name in attributes]
            if element_vertex is not None:
                element_vertex = np.where(element_vertex >= 0,
                                          remap[np.maximum(element_vertex, 0)], -1)
        edges = None
        if getattr(self.style, "wireframe", False):
            edges = np.ascontiguousarray(vertex_of_node(vertex_node, mesh.n_nodes)[mesh.edges],
                                         dtype=np.int32)
        return MeshDrawData(
            mesh=mesh, style=self.style, vertex_node=vertex_node, n_vertices=n_vertices,
            index=index, primitive=layout.primitive, triangles=layout.triangles,
            strips=layout.strips, vertices_sent=layout.vertices_sent, split=topology.split,
            split_rows=split_rows, field_per=self.field_per, scale=scale,
            element_vertex=element_vertex, attributes=attributes, edges=edges,
            triangle_element=layout.triangle_element)

    # ------------------------------------------------------------------ prepare (GL)
    def _check_scene(self, mesh) -> None:
        self.data = self.draw_data(mesh)
        self.scale = self.data.scale

    def _build(self, ctx: moderngl.Context, mesh, camera) -> None:
        data, style = self.data, self.style
        self.mesh = mesh
        self.mode = PRIMITIVE_MODES[data.primitive]
        self.triangles, self.strips = data.triangles, data.strips
        self.vertices_sent, self.vertices = data.vertices_sent, data.n_vertices
        defines = {"NUM_CLIP": len(style.clip_planes)}
        if style.hide_range is not None and self.field_per is not None:
            defines["HIDE"] = 1
        missing = data.has_missing
        geometry = None
        if missing:
            defines |= {"MISSING": 1, **self.missing_defines}
            geometry = self.missing_geometry_shader
        self._program = self._keep(load_program(ctx, self.vertex_shader, self.fragment_shader,
                                                geometry, defines=defines))
        n = data.n_vertices
        self._positions = self._keep(ctx.buffer(reserve=n * 12))
        self._index = self._keep(ctx.buffer(data.index.tobytes()))
        uploaded = data.index.nbytes
        content = [(self._positions, "3f", "position")]
        self._normals = self._values = self._missing = None
        if data.split is not None:
            self._normals = self._keep(ctx.buffer(reserve=n * 12))
            content.append((self._normals, "3f", "normal"))
        if self.field_per is not None:
            self._values = self._keep(ctx.buffer(reserve=n * 4))
            content.append((self._values, "1f", "value"))
        if missing:
            self._missing = self._keep(ctx.buffer(reserve=n * 4))
            content.append((self._missing, "1f", "missing"))
        for array, fmt, name in data.attributes:
            content.append((self._keep(ctx.buffer(array.tobytes())), fmt, name))
            uploaded += array.nbytes
        if data.scale is not None:
            uploaded += self._colormap_texture(ctx, data.scale)
        self._vao = self._keep(ctx.vertex_array(self._program, content, self._index,
                                                index_element_size=4))
        self._content, self._id_program, self._ghost_vao = content, None, None
        if "base_color" in self._uniforms(self._program):
            self._program["base_color"].value = style.base_color
        if data.edges is not None:
            uploaded += self._line_pass(ctx, self._positions, data.edges)
        if data.static_values:
            uploaded += self._upload_values(style.step)
        if style.deleted == "ghost" and data.live_triangles(style.step) is not None:
            self._ghost_vao = self._keep(ctx.vertex_array(
                self._keep(load_program(ctx, "position.vert.glsl", "ghost.frag.glsl",
                                        defines={"NUM_CLIP": len(style.clip_planes)})),
                [(self._positions, "3f", "position")], self._index, index_element_size=4))
            self._ghost_vao.program["ghost_color"].value = (*style.base_color, GHOST_ALPHA)
        self._kinds = build_overlay(self, ctx, mesh, draws=type(self).draw is MeshPath.draw)
        self._set_clip_planes()
        self.set_camera(camera)
        # the triangles in use that the index buffers hold (erosion): every one as prepared;
        # the ghost pass's layout (live first) is written by the first step
        live = data.live_triangles(style.step)
        self._live_shown = None if live is None or self._ghost_vao is not None else \
            np.ones(len(live), bool)
        self.bytes_per_step = self.set_step(style.step)
        self.bytes_uploaded = uploaded + self.bytes_per_step

    def _colormap_texture(self, ctx, scale: ColorScale) -> int:
        """The 1-D colour texture on unit 0 and the scale's uniforms; returns its bytes."""
        texels = scale.texture_data()
        texture = self._keep(ctx.texture((len(texels), 1), 4, texels.tobytes()))
        self._textures = [(texture, 0)]
        filt = moderngl.LINEAR if scale.linear else moderngl.NEAREST
        texture.filter = (filt, filt)
        texture.repeat_x = texture.repeat_y = False
        self._program["colormap"].value = 0
        if "missing_color" in self._uniforms(self._program):  # used with MISSING only
            self._program["missing_color"].value = NO_RESULT_COLOR
        self._program["colormap_st"].value = scale.coord_transform
        return texels.nbytes

    # ------------------------------------------------------------------ per frame / per step
    def shown_coordinates(self, step: int) -> np.ndarray:
        """(N, 3) float64 node positions drawn for ``step`` (deformation plot applied)."""
        return self.data.shown_coordinates(step)

    def set_step(self, step: int) -> int:
        self._require_prepared()
        step = self.mesh.step_index(step)
        shown = self.data.shown_coordinates(step)
        positions = self.data.positions(shown, self.origin)
        self._positions.write(positions)
        sent = positions.nbytes
        normals = self.data.normals(shown)
        if normals is not None:
            self._normals.write(normals)
            sent += normals.nbytes
        if self.field_per is not None and not self.data.static_values:
            sent += self._upload_values(step)
        sent += self._upload_live(step)
        if self._kinds is not None:
            sent += self._kinds.set_step(step, shown, self.origin)
        self.step = step
        return sent

    def _upload_live(self, step: int) -> int:
        """With erosion, show the triangles (and wire-frame edges) of the elements in use at
        ``step`` and no other; the bytes sent. Nothing is sent where the step keeps the
        elements of the step drawn before (the buffers hold them already). The fill index is
        changed in place (:meth:`_write_changed_triangles`: the triangles whose state changed,
        a deleted one made degenerate), or, with the ghost pass, written whole with the live
        triangles first (:meth:`_live_index`); the wire frame's edges are written whole, the
        live ones first."""
        live = self.data.live_triangles(step)
        if live is None:
            return 0
        self.deleted = self.mesh.n_deleted(step)
        before, self._live_shown = self._live_shown, live
        changed = None if before is None else np.flatnonzero(live != before)
        if changed is not None and not len(changed):
            return 0
        if self._ghost_vao is None:
            sent = self._write_changed_triangles(live, changed)
        else:
            index, self._fill_vertices = self._live_index(live)
            self._index.write(index.tobytes())
            sent = index.nbytes
        edges = self.data.live_edges(step)
        if edges is not None:
            pairs = np.ascontiguousarray(np.concatenate([self.data.edges[edges],
                                                         self.data.edges[~edges]]), np.int32)
            self._line_index.write(pairs.tobytes())
            self._line_vertices = int(edges.sum()) * 2
            sent += pairs.nbytes
        return sent

    def _write_changed_triangles(self, live: np.ndarray, changed: np.ndarray) -> int:
        """Write, in place, the triangles ``changed`` (ascending indices into the triangle
        list) of the fill index, whose state in ``live`` (bool over the triangle list) differs
        from what the buffer holds: a triangle now in use gets its three vertices back, one
        deleted becomes degenerate (its first vertex three times: no fragment), each run of
        consecutive changed triangles one write; every triangle keeps its place, so the whole
        buffer is drawn in the order of an uneroded draw. The bytes sent (12 a changed
        triangle)."""
        rows = np.asarray(self.data.index, np.int32).reshape(-1, 3)[changed]
        dead = ~live[changed]
        rows[dead] = rows[dead][:, :1]
        rows = np.ascontiguousarray(rows)
        starts = np.flatnonzero(np.diff(changed, prepend=-2) != 1)
        ends = np.append(starts[1:], len(changed))
        for start, end in zip(starts.tolist(), ends.tolist()):
            self._index.write(rows[start:end].tobytes(), offset=int(changed[start]) * 12)
        self._fill_vertices = -1
        return rows.nbytes

    def _upload_values(self, step: int) -> int:
        """Upload the normalised field values of ``step`` (non-finite ones as 0) and, for a
        field with non-finite values, the missing flags beside them; the bytes sent."""
        values, missing, self.missing_values = self.data.values(step)
        self._values.write(values)
        if self._missing is None:
            return values.nbytes
        self._missing.write(missing)
        return values.nbytes + missing.nbytes

    def _live_index(self, live: np.ndarray) -> tuple[np.ndarray, int]:
        """(the int32 triangle index to upload, the vertices the fill pass draws) with the
        triangles ``live`` (bool over the triangle list) shown, for the ghost pass: the live
        triangles first and the deleted ones behind them (which it draws translucent)."""
        index = np.concatenate([self.data.index[live], self.data.index[~live]])
        return np.ascontiguousarray(index, np.int32), int(live.sum()) * 3

    def draw(self) -> None:
        self.ctx.provoking_vertex = moderngl.LAST_VERTEX_CONVENTION
        self._render(self.mode)
        if self._kinds is not None:
            self._kinds.draw(self._clip_distances(len(self.style.clip_planes)))
        if self._ghost_vao is not None:
            self._draw_ghosts()

    def _programs(self) -> list:
        """The fill and line programs, and the ghost pass's where there is one (its camera and
        clip planes set with theirs)."""
        ghost = [] if self._ghost_vao is None else [self._ghost_vao.program]
        kinds = [] if self._kinds is None else self._kinds.programs
        return [*super()._programs(), *ghost, *kinds]

    def _draw_ghosts(self) -> None:
        """The deleted elements' triangles (behind the live ones in the index buffer) in
        ``base_color`` at opacity GHOST_ALPHA, blended over what is drawn, depth-tested."""
        count = self.data.triangles * 3 - self._fill_vertices
        if count <= 0:
            return
        ctx = self.ctx
        ctx.enable_only(moderngl.DEPTH_TEST | moderngl.BLEND)
        ctx.blend_func = moderngl.SRC_ALPHA, moderngl.ONE_MINUS_SRC_ALPHA
        with self._clip_distances(len(self.style.clip_planes)):
            self._ghost_vao.render(moderngl.TRIANGLES, vertices=count,
                                   first=self._fill_vertices)
        ctx.enable_only(moderngl.DEPTH_TEST)

    # ------------------------------------------------------------------ sort-last domains
    def draw_triangles(self, ids: np.ndarray, triangle_ids: bool = False) -> None:
        """Draw only the triangles ``ids`` (indices into the triangle list, drawn in that
        order) in the style's GL state: one domain of a sort-last run. With ``triangle_ids``
        each fragment writes, instead of its colour, the position in ``ids`` of its triangle
        plus one (an unsigned integer target; 0 where nothing is drawn), through the same
        placement and clip planes, so the same triangle wins each pixel as in the colour pass.

        A triangle of an element deleted at the drawn step (erosion) gives no fragment.
        Refused (ValueError): a strip layout (a triangle is no index range of it) and a line
        pass or an alpha test (their fragments are not the triangles')."""
        self._require_prepared()
        data = self.data
        if data.primitive != "triangles" or self._line_vao is not None or \
                self.style.hide_range is not None:
            raise ValueError(f"path {self.name!r} draws domains of a triangle list without a "
                             f"wire frame or hidden range (strips {self.style.strips!r})")
        if self._kinds is not None:
            warn_not_drawn(self.mesh, "a sort-last domain (draw_triangles)")
        ids = np.asarray(ids, np.int64)
        index = np.ascontiguousarray(data.triangle_list()[ids], np.int32)
        if not len(index):
            return
        live = data.live_triangles(self.step)
        if live is not None:  # a deleted element's triangle made degenerate: no fragment,
            dead = ~live[ids]  # and every other triangle keeps its position in ``ids``
            index[dead] = index[dead][:, :1]
        ctx = self.ctx
        buffer = ctx.buffer(index.tobytes())
        if triangle_ids:
            program = self._triangle_id_program()
            vao = ctx.vertex_array(program, [(self._positions, "3f", "position")], buffer,
                                   index_element_size=4)
        else:
            vao = ctx.vertex_array(self._program, self._content, buffer, index_element_size=4)
        vao_before, line_before, count = self._vao, self._line_vao, self._fill_vertices
        try:
            self._vao, self._fill_vertices = vao, -1
            ctx.provoking_vertex = moderngl.LAST_VERTEX_CONVENTION
            self._render(moderngl.TRIANGLES)
        finally:
            self._vao, self._line_vao, self._fill_vertices = vao_before, line_before, count
            vao.release()
            buffer.release()

    def _triangle_id_program(self) -> moderngl.Program:
        """The program of :meth:`draw_triangles` with ``triangle_ids``, its placement and clip
        uniforms copied from the path's program."""
        if self._id_program is None:
            self._id_program = self._keep(load_program(
                self.ctx, "position.vert.glsl", "triangle_id.frag.glsl",
                defines={"NUM_CLIP": len(self.style.clip_planes)}))
        program = self._id_program
        for name in ("mvp", "view", "clip_planes"):
            if name in self._uniforms(program) and name in self._uniforms(self._program):
                program[name].value = self._program[name].value
        return program

