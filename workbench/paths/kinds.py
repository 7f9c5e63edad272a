"""Beams and SPH particles drawn over a mesh path's surface, in the same frame (GL).

A mesh's :attr:`~workbench.scene.mesh.FEMesh.beams` and
:attr:`~workbench.scene.mesh.FEMesh.particles` (:mod:`workbench.scene.kinds`) have no faces;
:class:`KindsOverlay` draws them after the surface, depth-tested against it, with one small
program each (``kinds.vert.glsl`` / ``kinds.frag.glsl``), through the path's camera, clip
planes and deformation plot:

* **beams** as ``GL_LINES`` one pixel wide, unlit;
* **SPH particles** as ``GL_POINTS`` whose size is twice the radius projected to pixels (the
  point one radius away along the eye's up axis), drawn as round discs shaded as spheres seen
  along the view (``0.25 + 0.75·n_z``), at the depth of their centre: sphere impostors without
  per-pixel depth. llvmpipe draws points up to 255 pixels across; a larger one is clamped.

**Colour.** Where the path draws a node field, a beam's ends and a particle take the values of
their nodes; where it draws an element field that the beams (particles) also carry under the
same name, their own values; both through the path's colour scale and texture, a non-finite
value in the no-result colour. Otherwise each is drawn in its part's colour
(:data:`PART_COLORS`, by part id modulo 10).

**Erosion.** Per state (:meth:`KindsOverlay.set_step`) only the beams and particles in use
(their ``"alive"`` field) are written to the front of the vertex buffers and drawn; a deleted
one gives no pixel, also with ``Style.deleted = "ghost"`` (the ghost pass is the surface's).

A path that draws otherwise than :meth:`MeshPath.draw <workbench.paths.mesh.MeshPath.draw>`
(the exploded view), the sort-last domain draws and the software rasterizer leave beams and
particles out, with a :class:`KindWarning` naming the kind and the count
(:func:`warn_not_drawn`).
"""

from __future__ import annotations

import warnings
from typing import TYPE_CHECKING

import moderngl
import numpy as np

from ..gl import load_program
from .colormap import NO_RESULT_COLOR

if TYPE_CHECKING:
    from ..scene.mesh import FEMesh

# part colours (tab10 without its grey, which the surface's default colour resembles)
PART_COLORS = np.array([
    (0.122, 0.467, 0.706), (1.000, 0.498, 0.055), (0.173, 0.627, 0.173),
    (0.839, 0.153, 0.157), (0.580, 0.404, 0.741), (0.549, 0.337, 0.294),
    (0.890, 0.467, 0.761), (0.000, 0.000, 0.502), (0.737, 0.741, 0.133),
    (0.090, 0.745, 0.812)], np.float64)
PAINT_COLOR, PAINT_FIELD, PAINT_MISSING = 0.0, 1.0, 2.0


class KindWarning(UserWarning):
    """A path leaves out element kinds of the mesh it cannot draw (beams, SPH particles):
    said with the kind and the count, not hidden."""


def not_drawn(mesh: FEMesh) -> list[str]:
    """'N beams', 'N SPH particles': what ``mesh`` holds beside its surface."""
    return [f"{kind.count} {kind.label}s" for kind in (mesh.beams, mesh.particles)
            if kind is not None]


def warn_not_drawn(mesh: FEMesh, who: str, stacklevel: int = 3) -> None:
    """A :class:`KindWarning` that ``who`` leaves out the beams and particles of ``mesh``
    (nothing where it has none)."""
    left = not_drawn(mesh)
    if left:
        warnings.warn(f"{mesh.name}: {who} draws shells and faces only: "
                      f"{' and '.join(left)} not drawn", KindWarning, stacklevel=stacklevel)


def part_colors(parts: np.ndarray) -> np.ndarray:
    """(K, 3) float64 colour of each part id."""
    return PART_COLORS[np.asarray(parts, np.int64) % len(PART_COLORS)]


class KindsOverlay:
    """The beams and particles of a prepared mesh path (see the module notes). Its GL
    objects are kept by the path (``keep``) and released with it."""

    def __init__(self, ctx: moderngl.Context, mesh: FEMesh, data, keep) -> None:
        self.ctx, self.mesh, self.data = ctx, mesh, data
        style = data.style
        defines = {"NUM_CLIP": len(style.clip_planes)}
        self.passes = []
        self.beams = self.particles = 0  # drawn at the step
        for kind, points in ((mesh.beams, False), (mesh.particles, True)):
            if kind is None:
                continue
            program = keep(load_program(ctx, "kinds.vert.glsl", "kinds.frag.glsl",
                                        defines=defines | ({"POINTS": 1} if points else {})))
            per = 1 if points else 2
            n = kind.count * per
            buffers = {"position": keep(ctx.buffer(reserve=n * 12)),
                       "paint": keep(ctx.buffer(reserve=n * 16)),
                       "value": keep(ctx.buffer(reserve=n * 4))}
            content = [(buffers["position"], "3f", "position"), (buffers["paint"], "4f", "paint"),
                       (buffers["value"], "1f", "value")]
            if points:
                buffers["radius"] = keep(ctx.buffer(reserve=n * 4))
                content.append((buffers["radius"], "1f", "radius"))
            vao = keep(ctx.vertex_array(program, content))
            scale = data.scale
            if scale is not None:
                program["colormap"].value = 0
                program["colormap_st"].value = scale.coord_transform
            if "missing_color" in {name for name in program}:
                program["missing_color"].value = NO_RESULT_COLOR
            nodes = kind.node[:, None] if points else kind.nodes
            self.passes.append(dict(kind=kind, points=points, program=program, vao=vao,
                                    buffers=buffers, nodes=nodes, count=0))

    @property
    def programs(self) -> list:
        return [p["program"] for p in self.passes]

    # ------------------------------------------------------------------ per step
    def paint(self, kind, nodes: np.ndarray, step: int) -> tuple[np.ndarray, np.ndarray]:
        """((K, per, 4) paint, (K, per) normalised value) of every item of ``kind`` at
        ``step`` (see the module notes for the colour)."""
        data, name = self.data, self.data.style.field
        k, per = nodes.shape
        paint = np.zeros((k, per, 4))
        paint[:, :, :3] = part_colors(kind.parts)[:, None, :]
        value = np.zeros((k, per))
        t = None
        if data.scale is not None and data.field_per == "node":
            t = data.scale.normalise(self.mesh.node_field(name, step))[nodes]
        elif data.scale is not None and data.field_per == "element" and name in kind.fields:
            t = np.repeat(data.scale.normalise(kind.field(name, step))[:, None], per, axis=1)
        if t is not None:
            finite = np.isfinite(t).all(axis=1)
            paint[:, :, 3] = np.where(finite, PAINT_FIELD, PAINT_MISSING)[:, None]
            value = np.where(np.isfinite(t), t, 0.0)
        return paint, value

    def set_step(self, step: int, shown: np.ndarray, origin: np.ndarray) -> int:
        """Write the live beams and particles of ``step`` at node positions ``shown`` (N, 3)
        to the front of their buffers; the bytes sent."""
        sent = 0
        for p in self.passes:
            kind, nodes = p["kind"], p["nodes"]
            live = kind.alive(step)
            paint, value = self.paint(kind, nodes, step)
            arrays = {"position": (shown[nodes[live]] - origin).astype(np.float32),
                      "paint": paint[live].astype(np.float32),
                      "value": value[live].astype(np.float32)}
            if p["points"]:
                arrays["radius"] = kind.radius_at(step)[live].astype(np.float32)
            for key, array in arrays.items():
                if array.size:
                    p["buffers"][key].write(np.ascontiguousarray(array).tobytes())
                    sent += array.nbytes
            p["count"] = int(live.sum()) * nodes.shape[1]
            if p["points"]:
                self.particles = int(live.sum())
            else:
                self.beams = int(live.sum())
        return sent

    def draw(self, clip_distances) -> None:
        """Draw the live beams and particles, depth-tested, after the surface (its colormap
        texture still bound on unit 0); ``clip_distances`` is the path's context manager."""
        ctx = self.ctx
        ctx.enable_only(moderngl.DEPTH_TEST | moderngl.PROGRAM_POINT_SIZE)
        with clip_distances:
            for p in self.passes:
                if not p["count"]:
                    continue
                if p["points"]:
                    p["program"]["viewport"].value = tuple(float(v) for v in ctx.viewport[2:])
                p["vao"].render(moderngl.POINTS if p["points"] else moderngl.LINES,
                                vertices=p["count"])
        ctx.enable_only(moderngl.DEPTH_TEST)


def build_overlay(path, ctx: moderngl.Context, mesh: FEMesh, draws: bool):
    """The :class:`KindsOverlay` of ``path`` for ``mesh`` (None where it has no beams or
    particles); where the path does not draw it (``draws`` False), a :class:`KindWarning`."""
    if mesh.beams is None and mesh.particles is None:
        return None
    if not draws:
        warn_not_drawn(mesh, f"path {path.name!r}", stacklevel=4)
        return None
    return KindsOverlay(ctx, mesh, path.data, path._keep)
