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
its iso-line (``max(|∂/∂x|, |∂/∂y|)``), like an aliased one-pixel ``GL_LINES`` line. Outline pixels
take ``Style.wire_color`` exactly; the rest ``Style.base_color`` times the headlight. The
surface's ``line_edges`` (element edges the texture cannot show) are drawn afterwards as
``GL_LINES`` in ``Style.wire_color``, the fill under polygon offset (1, 1) as in
:mod:`workbench.paths.base`.

The path receives its prepared input: ``prepare`` takes either a ``TexturedSurface`` built by
the caller, or an FE mesh whose fe2003 model the scene has derived and cached
(:func:`~workbench.algo.fepatch.mesh_model.fepatch_model` of ``Style.fepatch``, asked for
through ``needs = {"fepatch"}``); the path
draws that model's ``original`` or ``simplified`` surface. The surface is built for one
configuration, so only step 0 is drawn: ``Style.step`` other than 0, a deformation plot
(magnification ≠ 1 with a reference step other than 0), ``set_step`` with another step,
``Style.wireframe`` (a second, line-overdraw wire frame) and ``Style.strips`` other than
"none" (the paths draw the surface's own triangle list) are refused with ValueError.
``Style.field`` and ``Style.quad_diagonal`` are ignored. Positions are uploaded as float32
relative to ``camera.origin`` (float64 subtraction first); clip planes and the camera work as in
:class:`~workbench.paths.mesh.MeshPath`.
"""

from __future__ import annotations

import warnings
from typing import TYPE_CHECKING

import moderngl
import numpy as np

from ..algo.fepatch.mesh_model import fepatch_model
from ..algo.fepatch.surface import CORNER_ROW, corner_rows
from ..gl import Camera, load_program
from .base import GLPath
from .kinds import warn_not_drawn
from .mesh import ErosionWarning

if TYPE_CHECKING:
    from ..scene.protocol import Scene
    from .style import Style

__all__ = ["FETexturePath", "FEWireTexturePath", "FENormalMapPath", "FENormalWirePath"]


def corner_texture(table: np.ndarray) -> np.ndarray:
    """The (rows, CORNER_ROW, 4) uint32 texture of a (M, 4, 2) uint16 corner table: element i
    at row i // CORNER_ROW, column i % CORNER_ROW, corner k in channel k as u + 65536·v; the
    last row is padded with zeros."""
    rows = corner_rows(len(table))
    out = np.zeros((rows * CORNER_ROW, 4), np.uint32)
    out[:len(table)] = table[..., 0].astype(np.uint32) | (table[..., 1].astype(np.uint32) << 16)
    return out.reshape(rows, CORNER_ROW, 4)


class FETexturePath(GLPath):
    """The shared implementation of the fe2003 texture paths (see the module docstring).

    Class switches: ``model_surface`` ("original" or "simplified": which surface of the model
    is drawn from a mesh's model), ``normal_map`` (per-pixel light from the normal map, else
    per-vertex light from ``surface.normals``) and ``wire_texture`` (outlines from the wire
    map).
    """

    needs = frozenset({"fepatch"})
    scene_kinds = frozenset({"mesh", "surface"})
    model_surface: str = "simplified"
    normal_map: bool = True
    wire_texture: bool = False
    style: Style

    # ------------------------------------------------------------------ prepare
    def _check_style(self) -> None:
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

    @classmethod
    def default_camera(cls, scene: Scene, size: tuple[int, int], *,
                       view: tuple[float, float] = (30.0, 25.0),
                       projection: str = "orthographic", up: str = "z",
                       style: object | None = None) -> Camera:
        """:meth:`Camera.fit_box` over the surface, or over every step of the mesh whose model
        is drawn."""
        lo, hi = scene.bounds(all_steps=True) if scene.kind == "mesh" else scene.bounds()
        return cls.fit_camera(lo, hi, size, view=view, projection=projection, up=up)

    def _surface_for(self, scene):
        """The TexturedSurface ``scene`` is, or the one of the mesh's cached fe2003 model."""
        kind = getattr(scene, "kind", None)
        if kind == "surface":
            return scene
        if kind != "mesh":
            raise ValueError(f"path {self.name!r} draws an FE mesh or a TexturedSurface, "
                             f"got {type(scene).__name__}")
        return getattr(fepatch_model(scene, self.style.fepatch), self.model_surface)

    def _check_surface(self, surface) -> None:
        if len(surface.triangles) == 0:
            raise ValueError(f"path {self.name!r}: the surface has no triangles")
        if self.normal_map and surface.normal_map is None:
            raise ValueError(f"path {self.name!r} lights with the normal map: the surface has "
                             f"no normal_map")
        if not self.normal_map and surface.normals is None:
            raise ValueError(f"path {self.name!r} lights per vertex: the surface has no normals")
        if self.wire_texture and surface.wire_map is None and surface.element_map is None:
            raise ValueError(f"path {self.name!r} outlines with the wire texture: the surface "
                             f"has no wire_map or element_map")
        if self.normal_map and len(surface.normal_axis) and \
                (surface.normal_axis.min() < 0 or surface.normal_axis.max() > 2):
            raise ValueError("normal_axis must be 0, 1 or 2")

    def _check_scene(self, scene) -> None:
        """Refuse the styles listed in the module docstring and an unusable surface."""
        self._check_style()
        deleted = scene.n_deleted(self.style.step) if getattr(scene, "erodes", False) else 0
        if deleted:
            warnings.warn(f"{scene.name} deletes {deleted} elements at step {self.style.step} "
                          f"(erosion); path {self.name!r} draws one simplified surface of every "
                          f"element: the deleted ones are drawn", ErosionWarning, stacklevel=2)
        if getattr(scene, "kind", None) == "mesh":
            warn_not_drawn(scene, f"path {self.name!r}")  # beams and SPH particles
        surface = self._surface_for(scene)
        self._check_surface(surface)
        self._surface = surface

    def _texture(self, ctx, data: np.ndarray, unit: int, name: str) -> int:
        """Upload ``data`` (H, W, C) as a texture on ``unit``: bytes filtered linearly, unsigned
        integers (uint16, uint32) as an integer texture read texel by texel."""
        height, width, channels = data.shape
        integer = data.dtype != np.uint8
        dtype = {np.dtype(np.uint8): "f1", np.dtype(np.uint16): "u2",
                 np.dtype(np.uint32): "u4"}[data.dtype]
        tex = self._keep(ctx.texture((width, height), channels,
                                     np.ascontiguousarray(data).tobytes(),
                                     dtype=dtype, alignment=1))
        nearest = (moderngl.NEAREST, moderngl.NEAREST)
        tex.filter = nearest if integer else (moderngl.LINEAR, moderngl.LINEAR)
        tex.repeat_x = tex.repeat_y = False
        self._program[name].value = unit
        self._textures.append((tex, unit))
        return data.nbytes

    def _build(self, ctx: moderngl.Context, scene, camera) -> None:
        surface, style = self._surface, self.style
        corners = self.wire_texture and surface.element_map is not None
        defines = {"NUM_CLIP": len(style.clip_planes), "NORMAL_MAP": int(self.normal_map),
                   "WIRE_TEXTURE": int(self.wire_texture and not corners),
                   "WIRE_CORNERS": int(corners), "CORNER_ROW": CORNER_ROW,
                   "CORNER_SHIFT": CORNER_ROW.bit_length() - 1}
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
        if corners:
            base = np.ascontiguousarray(surface.element_base, np.int32)
            content.append((self._keep(ctx.buffer(base.tobytes())), "1i", "base"))
            uploaded += base.nbytes
        self._vao = self._keep(ctx.vertex_array(self._program, content, self._index,
                                                index_element_size=4))

        if self.normal_map:
            uploaded += self._texture(ctx, surface.normal_map, 0, "normal_map")
        if corners:
            uploaded += self._texture(ctx, surface.element_map[..., None], 1, "element_map")
            uploaded += self._texture(ctx, corner_texture(surface.corner_table), 2,
                                      "corner_table")
            self._program["no_element"].value = surface.no_element
            self._program["corner_step"].value = 1.0 / surface.corner_frac
            self._program["wire_color"].value = style.wire_color
        elif self.wire_texture:
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
        self._require_prepared()
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
