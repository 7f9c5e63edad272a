"""fe2003 (Rose & Ertl §4) render paths: normal maps and the wire-frame texture, in one pass.

Three paths draw a :class:`~workbench.algo.fepatch.surface.TexturedSurface`:

* ``fe_wire_texture`` — the original mesh (every element) with the per-vertex Gouraud headlight
  from ``surface.normals`` and the element outlines restored from the wire-frame distance
  texture;
* ``fe_normal_map`` — the simplified surface with a per-pixel headlight whose normal is decoded
  from the two-component normal map (the vertex's ``normal_axis`` names the dropped component,
  restored as ``+sqrt(max(0, 1 − a² − b²))``; the headlight is two-sided, so the lost sign is
  harmless);
* ``fe_normal_wire`` — the simplified surface with both textures.

The outline test is the one of :mod:`workbench.algo.fepatch.surface`: each channel pair says
"on the outline" where one distance is within half a pixel of zero and the other not below
minus half a pixel, a pixel measured as the distance's change per pixel along the minor axis of
its iso-line (max(|∂/∂x|, |∂/∂y|)), like an aliased one-pixel ``GL_LINES`` line. Outline pixels
take ``Style.wire_color`` exactly; the rest ``Style.base_color`` times the headlight. The
surface's ``line_edges`` (element edges the texture cannot show) are drawn afterwards as
``GL_LINES`` in ``Style.wire_color``, the fill under polygon offset (1, 1) as in
:mod:`workbench.paths.base`.

The surface comes from ``path.surface`` when set before :meth:`~FETexturePath.prepare`,
otherwise from :func:`workbench.algo.fepatch.pipeline.build_model` on the mesh's step 0 with
``Style.fepatch`` (cached per mesh and parameter string). The surface is built for one
configuration, so only step 0 is drawn: ``Style.step`` other than 0, a deformation plot
(magnification ≠ 1 with a reference step other than 0), ``set_step`` with another step,
``Style.wireframe`` (a second, line-overdraw wire frame) and ``Style.strips`` other than
"none" (the paths draw the surface's own triangle list) are refused with ValueError.
``Style.field`` and ``Style.quad_diagonal`` are ignored. Positions are uploaded as float32
relative to ``camera.origin`` (float64 subtraction first); clip planes and the camera work as in
:class:`~workbench.paths.base.MeshPath`.
"""

from __future__ import annotations

import weakref

import moderngl
import numpy as np

from ..gl import load_program
from .base import GLPath

__all__ = ["FETexturePath", "FEWireTexturePath", "FENormalMapPath", "FENormalWirePath",
           "fepatch_model"]

# mesh -> {fepatch parameter string -> model}; a model lives as long as its mesh
_MODELS: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()


def fepatch_model(mesh, fepatch: str):
    """The fe2003 model (``.original`` and ``.simplified`` surfaces) of ``mesh`` at step 0 for
    the parameter string ``fepatch`` (see ``Style.fepatch``), built once per mesh and string."""
    by_parameters = _MODELS.setdefault(mesh, {})
    if fepatch not in by_parameters:
        from ..algo.fepatch.pipeline import build_model

        by_parameters[fepatch] = build_model(mesh.elements, mesh.coordinates(0), fepatch)
    return by_parameters[fepatch]


class FETexturePath(GLPath):
    """The shared implementation of the fe2003 texture paths (see the module docstring).

    Class switches: ``model_surface`` ("original" or "simplified": which surface of the model
    is drawn when ``surface`` is not set), ``normal_map`` (per-pixel light from the normal map,
    else per-vertex light from ``surface.normals``) and ``wire_texture`` (outlines from the wire
    map). Attribute ``surface``: the :class:`TexturedSurface` to draw, None (default) to build
    it from the mesh at ``prepare``.
    """

    needs = frozenset({"triangles"})
    model_surface: str = "simplified"
    normal_map: bool = True
    wire_texture: bool = False

    def __init__(self, style=None) -> None:
        super().__init__(style)
        self.surface = None

    # ------------------------------------------------------------------ prepare
    def _check_style(self, mesh) -> None:
        style = self.style
        if style.step != 0:
            raise ValueError(f"path {self.name!r} draws the configuration its textured surface "
                             f"was built for (step 0), got step {style.step}")
        if style.magnification != 1.0 and style.reference_step != 0:
            raise ValueError(f"path {self.name!r} cannot draw a deformation plot: its textured "
                             f"surface is built for step 0 alone")
        if style.wireframe:
            raise ValueError(f"path {self.name!r} draws its wire frame from a texture: "
                             f"wireframe=True would add a second, line-overdraw wire frame")
        if style.strips != "none":
            raise ValueError(f"path {self.name!r} draws its surface's triangle list: "
                             f"use strips='none'")

    def _surface_for(self, mesh):
        if self.surface is not None:
            return self.surface
        if mesh is None:
            raise ValueError(f"path {self.name!r} needs a mesh, or a surface set beforehand")
        return getattr(fepatch_model(mesh, self.style.fepatch), self.model_surface)

    def _check_surface(self, surface) -> None:
        if len(surface.triangles) == 0:
            raise ValueError(f"path {self.name!r}: the surface has no triangles")
        if self.normal_map and surface.normal_map is None:
            raise ValueError(f"path {self.name!r} lights with the normal map: the surface has "
                             f"no normal_map")
        if not self.normal_map and surface.normals is None:
            raise ValueError(f"path {self.name!r} lights per vertex: the surface has no normals")
        if self.wire_texture and surface.wire_map is None:
            raise ValueError(f"path {self.name!r} outlines with the wire texture: the surface "
                             f"has no wire_map")
        if self.normal_map and len(surface.normal_axis) and \
                (surface.normal_axis.min() < 0 or surface.normal_axis.max() > 2):
            raise ValueError("normal_axis must be 0, 1 or 2")

    def prepare(self, ctx: moderngl.Context, mesh, camera) -> None:
        """Upload the surface (built from ``mesh`` when ``surface`` is None) and its textures
        for ``camera``; refuses the styles listed in the module docstring."""
        if self.ctx is not None:
            self.release()
        self._check_style(mesh)
        surface = self._surface_for(mesh)
        self._check_surface(surface)
        self.mesh, self.ctx, self.origin = mesh, ctx, np.array(camera.origin, np.float64)
        self._surface = surface
        try:
            self._build(ctx, camera)
        except BaseException:
            self.release()
            raise

    def _texture(self, ctx, data: np.ndarray, unit: int, name: str) -> int:
        height, width, channels = data.shape
        tex = self._keep(ctx.texture((width, height), channels, np.ascontiguousarray(data).tobytes(),
                                     dtype="f1", alignment=1))
        tex.filter = (moderngl.LINEAR, moderngl.LINEAR)
        tex.repeat_x = tex.repeat_y = False
        self._program[name].value = unit
        self._textures.append((tex, unit))
        return data.nbytes

    def _build(self, ctx: moderngl.Context, camera) -> None:
        surface, style = self._surface, self.style
        defines = {"NUM_CLIP": len(style.clip_planes), "NORMAL_MAP": int(self.normal_map),
                   "WIRE_TEXTURE": int(self.wire_texture)}
        self._program = self._keep(load_program(ctx, "fe_texture.vert.glsl",
                                                "fe_texture.frag.glsl", defines=defines))
        self._program["base_color"].value = style.base_color
        uploaded = 0
        n = len(surface.positions)
        self._positions = self._keep(ctx.buffer(reserve=n * 12))
        index = np.ascontiguousarray(surface.triangles, np.int32)
        self._index = self._keep(ctx.buffer(index.tobytes()))
        uploaded += index.nbytes
        width, height = surface.size if surface.size is not None else (1, 1)
        texcoord = (surface.uv / np.array([width, height], np.float64)).astype(np.float32)
        content = [(self._positions, "3f", "position"),
                   (self._keep(ctx.buffer(texcoord.tobytes())), "2f", "texcoord")]
        uploaded += texcoord.nbytes
        if self.normal_map:
            extra = surface.normal_axis.astype(np.float32)
            content.append((self._keep(ctx.buffer(extra.tobytes())), "1f", "axis"))
        else:
            extra = surface.normals.astype(np.float32)
            content.append((self._keep(ctx.buffer(extra.tobytes())), "3f", "normal"))
        uploaded += extra.nbytes
        self._vao = self._keep(ctx.vertex_array(self._program, content, self._index,
                                                index_element_size=4))

        if self.normal_map:
            uploaded += self._texture(ctx, surface.normal_map, 0, "normal_map")
        if self.wire_texture:
            uploaded += self._texture(ctx, surface.wire_map, 1, "wire_map")
            self._program["wire_range"].value = float(surface.wire_range)
            self._program["wire_color"].value = style.wire_color

        edges = surface.line_edges
        if len(edges):
            if edges.min() < 0 or edges.max() >= n:
                raise ValueError(f"line_edges index outside 0..{n - 1}")
            uploaded += self._line_pass(ctx, self._positions, edges)

        self.triangles, self.vertices = len(index), n
        self.vertices_sent, self.strips = index.size, 0
        self._set_clip_planes()
        self.set_camera(camera)
        self.bytes_per_step = self.set_step(0)
        self.bytes_uploaded = uploaded + self.bytes_per_step

    # ------------------------------------------------------------------ per frame / per step
    def set_step(self, step: int) -> int:
        """Upload the surface's positions (float32 relative to the origin); only step 0, the
        configuration the surface was built for, is accepted."""
        if self.ctx is None:
            raise RuntimeError(f"path {self.name!r} is not prepared")
        if step != 0:
            raise ValueError(f"path {self.name!r} draws the configuration its textured surface "
                             f"was built for (step 0), got step {step}")
        data = (self._surface.positions - self.origin).astype(np.float32)
        self._positions.write(data.tobytes())
        self.step = 0
        return data.nbytes

    def draw(self) -> None:
        self._render(moderngl.TRIANGLES)


class FEWireTexturePath(FETexturePath):
    """The original mesh, per-vertex headlight from ``surface.normals``, wire texture outlines."""

    name = "fe_wire_texture"
    model_surface, normal_map, wire_texture = "original", False, True


class FENormalMapPath(FETexturePath):
    """The simplified surface, per-pixel headlight from the two-component normal map."""

    name = "fe_normal_map"
    model_surface, normal_map, wire_texture = "simplified", True, False


class FENormalWirePath(FETexturePath):
    """The simplified surface with the normal map and the wire texture outlines."""

    name = "fe_normal_wire"
    model_surface, normal_map, wire_texture = "simplified", True, True
