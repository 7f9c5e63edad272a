"""The render-path interface, its shared implementation, and the registry of paths.

A render path is built once for a scene (:meth:`RenderPath.prepare`) and drawn many times
(:meth:`RenderPath.draw`), so that timing covers drawing only; :meth:`RenderPath.set_step`
uploads one time step's coordinates (and normals, and time-dependent field values) into the
buffers allocated at prepare time, never topology.

Conventions every path follows (a reference renderer can match them exactly):

* **Vertices** are uploaded as float32 relative to ``camera.origin`` (``camera.relative``);
  geometry stays float64 on the CPU. A deformation plot shows
  ``reference + magnification·(step − reference)``, computed in float64 per node.
* **Lighting** (all lit paths): a two-sided headlight without specular,
  ``colour·(0.25 + 0.75·|n·l|)``, ``l`` the unit direction towards the viewer in eye space —
  ``(0, 0, 1)`` for an orthographic camera, ``−p_eye/|p_eye|`` for a perspective one. The
  absolute value lights a back face as its front (shells are two-sided). Flat paths evaluate
  it per fragment with the face normal; Gouraud paths evaluate it per vertex with the
  crease-split vertex normal and interpolate the resulting factor (or lit colour) across the
  triangle. A zero normal gets the ambient 0.25 only.
* **Colour scales**: see :mod:`workbench.paths.colormap` (1-D texture, smooth or bands,
  transfer-function α with an alpha test that discards fragments with α < ½). A field value
  that is not finite (the stress of a rigid shell in a d3plot, a thickness nobody gave) is
  drawn in ``Style.base_color``, never hidden and never given a colour of the scale; per node,
  every fragment interpolated from such a vertex takes that colour. ``missing_values`` counts
  them for the step drawn.
* **Clip planes**: up to four world-space float64 planes ``(a, b, c, d)``; points with
  ``a·x + b·y + c·z + d ≥ 0`` are kept. The plane is moved to the upload origin in float64
  (``d' = d + (a, b, c)·origin``) and applied with ``gl_ClipDistance``.
* **Strips** (``Style.strips``): ``"none"`` draws an indexed triangle list; ``"triangle"``
  draws meshoptimizer's triangle strips of the same triangles and ``"quad"`` the bandified quad
  strips (:mod:`workbench.algo.strips`), both as ``GL_TRIANGLE_STRIP`` with primitive restart at
  index 0xFFFFFFFF (which moderngl enables in every context). Quad strips split each quad along
  its strip's diagonal; ``Style.quad_diagonal = "strip"`` gives the unstripped list and the
  triangle strips those same triangles, so all three draw identical images. Strips are built
  over the drawn vertices (crease-split ones for Gouraud paths), so a crease ends a strip.
* **Wire frame** (``Style.wireframe``): the element edges (quad edges, no diagonals) drawn as a
  second pass of ``GL_LINES``; the fill pass uses polygon offset (factor 1, units 1) so the
  lines win the depth test — the "standard wire frame" line overdraw of fe2003 Table 3.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from contextlib import contextmanager
from dataclasses import dataclass
from typing import ClassVar

import moderngl
import numpy as np

from ..algo.strips import RESTART, quad_strips, tri_strips
from ..gl import load_program
from .colormap import NO_VALUE, ColorScale, scale_for

# what a path may ask the scene to derive and cache (see workbench.scene.derive)
NEEDS = frozenset({"triangles", "edges", "gouraud", "fepatch", "part_distances"})
MAX_CLIP_PLANES = 4
GL_CLIP_DISTANCE0 = 0x3000
POLYGON_OFFSET = (1.0, 1.0)  # fill pass under a wire frame: (factor, units)
STRIPS = ("none", "triangle", "quad")
QUAD_DIAGONALS = ("auto", "shorter", "strip")


@dataclass
class Style:
    """How a path draws; every field is optional.

    field: name of a node field ((N,) or (T, N)) or element field ((M,) or (T, M)) of the mesh.
    step: time step drawn. colormap: a matplotlib colormap name. value_range: (lo, hi) of the
    colour scale, default the field's range over all steps. bands: 0 for smooth contours, n > 0
    for n constant-colour bands. hide_range: field values in [lo, hi] get α = 0 in the 1-D
    texture and are discarded by the alpha test (crash2000 §5). crease_deg: Gouraud crease angle
    in degrees. clip_planes: up to 4 world-space planes (a, b, c, d) keeping a·x+b·y+c·z+d ≥ 0.
    magnification / reference_step: deformation plot, shown = reference + magnification·(step −
    reference). wireframe: line-overdraw element wire frame in ``wire_color``. base_color: RGB in
    [0, 1] of the uncoloured paths. cull_back: cull back faces (default off: shells are two-sided).
    strips: "none" (triangle list), "triangle" (meshoptimizer triangle strips) or "quad" (quad
    strips by bandification, quads shorter than ``strip_cutoff`` drawn one by one).
    quad_diagonal: how quads are split, "shorter" (the shorter diagonal), "strip" (the diagonal
    of the quad's strip) or "auto" ("strip" for quad strips, else "shorter").
    fepatch: the fe2003 parameter set of the texture paths, "A" or "B" (their Table 1), or
    "alpha_g1,d,l_outer,l_inner" in degrees and model units.

    Refused with ValueError: more than 4 clip planes, a plane that is not 4 finite numbers with a
    non-zero normal, a negative step, a non-finite magnification, a crease angle outside
    [0, 180], colours that are not 3 numbers in [0, 1], a negative band count.
    """

    field: str | None = None
    step: int = 0
    colormap: str = "viridis"
    value_range: tuple[float, float] | None = None
    bands: int = 0
    hide_range: tuple[float, float] | None = None
    crease_deg: float = 30.0
    clip_planes: tuple = ()
    magnification: float = 1.0
    reference_step: int = 0
    wireframe: bool = False
    wire_color: tuple = (0.0, 0.0, 0.0)
    base_color: tuple = (0.75, 0.75, 0.78)
    cull_back: bool = False
    strips: str = "none"
    strip_cutoff: int = 1
    quad_diagonal: str = "auto"
    fepatch: str = "A"

    def __post_init__(self) -> None:
        planes = np.asarray(self.clip_planes, np.float64).reshape(-1, 4) if len(self.clip_planes) \
            else np.zeros((0, 4))
        if len(planes) > MAX_CLIP_PLANES:
            raise ValueError(f"at most {MAX_CLIP_PLANES} clip planes, got {len(planes)}")
        if not np.isfinite(planes).all() or (np.abs(planes[:, :3]).sum(axis=1) == 0).any():
            raise ValueError(f"clip planes must be finite (a, b, c, d) with a non-zero normal, "
                             f"got {self.clip_planes}")
        self.clip_planes = tuple(tuple(float(v) for v in p) for p in planes)
        for name in ("step", "reference_step", "bands"):
            value = getattr(self, name)
            if int(value) != value or value < 0:
                raise ValueError(f"{name} must be a non-negative integer, got {value}")
            setattr(self, name, int(value))
        if not math.isfinite(self.magnification):
            raise ValueError(f"magnification must be finite, got {self.magnification}")
        if not 0.0 <= self.crease_deg <= 180.0:
            raise ValueError(f"crease_deg must be in [0, 180], got {self.crease_deg}")
        for name in ("wire_color", "base_color"):
            color = tuple(float(c) for c in getattr(self, name))
            if len(color) != 3 or not all(0.0 <= c <= 1.0 for c in color):
                raise ValueError(f"{name} must be 3 numbers in [0, 1], got {getattr(self, name)}")
            setattr(self, name, color)
        if self.strips not in STRIPS:
            raise ValueError(f"strips must be one of {STRIPS}, got {self.strips!r}")
        if self.quad_diagonal not in QUAD_DIAGONALS:
            raise ValueError(f"quad_diagonal must be one of {QUAD_DIAGONALS}, "
                             f"got {self.quad_diagonal!r}")
        if self.strips == "quad" and self.quad_diagonal == "shorter":
            raise ValueError("quad strips split each quad along the strip's diagonal: "
                             "quad_diagonal='shorter' cannot be drawn with strips='quad'")
        if int(self.strip_cutoff) != self.strip_cutoff or self.strip_cutoff < 1:
            raise ValueError(f"strip_cutoff must be an integer >= 1, got {self.strip_cutoff}")
        self.strip_cutoff = int(self.strip_cutoff)

    @property
    def diagonal(self) -> str:
        """The quad split in use: "strip" or "shorter" (``quad_diagonal`` with "auto" resolved)."""
        if self.quad_diagonal != "auto":
            return self.quad_diagonal
        return "strip" if self.strips == "quad" else "shorter"


    def summary(self) -> str:
        """The fields that differ from the defaults, as ``name=value`` words (for table rows)."""
        default = type(self)()
        return " ".join(f"{name}={_word(getattr(self, name))}" for name in self.__dataclass_fields__
                        if getattr(self, name) != getattr(default, name))


def _word(value) -> str:
    """A value written without spaces: floats to 6 significant digits, tuples as (a,b,...)."""
    if isinstance(value, tuple):
        return "(" + ",".join(_word(v) for v in value) + ")"
    return f"{value:.6g}" if isinstance(value, float) else str(value)


class RenderPath(ABC):
    """One way of drawing a scene, built once (``prepare``) and drawn many times (``draw``).

    The protocol every registered path meets: ``prepare(ctx, scene, camera)`` once, then any
    number of ``set_camera``, ``set_step`` and ``draw``, then ``release``. A prepared path is a
    context manager: ``with path:`` releases its GL objects on the way out, also when a draw
    raises.

    ``style_class`` is the dataclass of options the path takes (:class:`Style` for the mesh
    paths); ``scene_kind`` names what ``prepare`` accepts ("mesh": an
    :class:`~workbench.scene.mesh.FEMesh`; "spacetime": a
    :class:`~workbench.scene.spacetime.SpacetimeScene`). ``needs`` names the data the path asks
    the scene to derive and cache (a subset of :data:`NEEDS`, read by
    :func:`workbench.scene.derive.derive` before ``prepare``); an instance drawing a wire
    frame adds ``"edges"`` to its own ``needs``. After ``prepare``: ``triangles``,
    ``vertices`` and ``edges`` (wire-frame lines, 0 without) drawn, ``bytes_uploaded``
    (everything uploaded by prepare, textures included), ``bytes_per_step`` (what one
    ``set_step`` uploads), ``vertices_sent`` (vertex indices one draw sends down the pipeline,
    restart markers excluded: 3 per listed triangle) and ``strips`` (primitives restarted, 0
    for a triangle list).
    """

    name: ClassVar[str]
    needs: ClassVar[frozenset[str]]
    style_class: ClassVar[type] = Style
    scene_kind: ClassVar[str] = "mesh"
    fixed_options: ClassVar[frozenset[str]] = frozenset()

    def __init__(self, style=None) -> None:
        style = style if style is not None else self.style_class()
        if not isinstance(style, self.style_class):
            raise TypeError(f"path {self.name!r} takes a {self.style_class.__name__}, "
                            f"got {type(style).__name__}")
        self.style = style
        if getattr(self.style, "wireframe", False):
            self.needs = type(self).needs | {"edges"}
        self.triangles = self.vertices = self.edges = 0
        self.vertices_sent = self.strips = 0
        self.bytes_uploaded = self.bytes_per_step = 0
        self.missing_values = 0

    @abstractmethod
    def prepare(self, ctx: moderngl.Context, scene, camera) -> None:
        """Upload what the scene gives (derived data already cached by the scene), with
        ``style.step`` drawn, for ``camera``."""

    @abstractmethod
    def set_camera(self, camera) -> None:
        """Set the camera uniforms; ``camera.origin`` must equal the one given to ``prepare``."""

    @abstractmethod
    def set_step(self, step: int) -> int:
        """Upload the coordinates (and normals, time-dependent values) of ``step``; return bytes."""

    @abstractmethod
    def draw(self) -> None:
        """Draw into the bound framebuffer: no uploads, no allocations; sets its own GL state."""

    @abstractmethod
    def release(self) -> None:
        """Free every GL object the path holds; harmless when nothing is held."""

    def __enter__(self) -> "RenderPath":
        return self

    def __exit__(self, *exc) -> None:
        self.release()

    def __init_subclass__(cls, **kwargs) -> None:
        super().__init_subclass__(**kwargs)
        if "name" in cls.__dict__:
            unknown = cls.needs - NEEDS
            if unknown:
                raise TypeError(f"{cls.__name__}.needs names unknown data {sorted(unknown)}")
            PATHS[cls.name] = cls


PATHS: dict[str, type[RenderPath]] = {}


def path_class(name: str) -> type[RenderPath]:
    """The registered path class ``name``; ValueError listing the registry otherwise."""
    try:
        return PATHS[name]
    except KeyError:
        raise ValueError(f"unknown render path {name!r}; known paths: {sorted(PATHS)}") from None


def make_path(name: str, style=None, **options) -> RenderPath:
    """A new, unprepared path of registry ``name`` with ``style`` (an instance of the path's
    ``style_class``) or, instead, ``options`` naming fields of that class; ValueError for an
    unknown path, or for an option the path does not take (naming it and the known ones)."""
    cls = path_class(name)
    if options:
        if style is not None:
            raise ValueError("give either a style or options, not both")
        style = cls.style_class(**check_options(name, options))
    return cls(style)


def path_options(name: str) -> frozenset[str]:
    """The option names path ``name`` takes: the fields of its ``style_class`` but those the
    path fixes itself (``fixed_options``, e.g. the shading of a spacetime path)."""
    cls = path_class(name)
    return frozenset(cls.style_class.__dataclass_fields__) - cls.fixed_options


def check_options(name: str, options: dict) -> dict:
    """``options`` unchanged when path ``name`` takes every key; ValueError naming the first
    unknown key and the known ones otherwise."""
    known = path_options(name)
    for key in options:
        if key not in known:
            raise ValueError(f"path {name!r} takes no option {key!r}; "
                             f"its options: {', '.join(sorted(known))}")
    return options


def field_kind(mesh, name: str) -> str:
    """'node' or 'element' for a field of ``mesh``; KeyError listing the mesh's fields otherwise."""
    if name in mesh.node_fields:
        return "node"
    if name in mesh.element_fields:
        return "element"
    raise KeyError(f"{mesh.name} has no field {name!r}; node fields: {sorted(mesh.node_fields)}, "
                   f"element fields: {sorted(mesh.element_fields)}")


class GLPath(RenderPath):
    """The GL bookkeeping every path shares, once: objects kept for ``release``, the prepared
    guard, the camera-origin check, clip-distance enabling, the fill program ``_program`` and
    VAO ``_vao``, an optional pass of lines (``_line_program``/``_line_vao``, drawn after the
    fill, which gets polygon offset), clip planes and camera uniforms for every program.

    ``prepare`` releases a previous preparation, calls ``_check_scene`` (refusals before any GL
    object exists), records the context and the float64 upload origin, then ``_build``; if
    ``_build`` raises, every object made so far is released.
    """

    def __init__(self, style=None) -> None:
        super().__init__(style)
        self.ctx = None
        self.origin = None
        self._objects: list = []
        self._program = self._line_program = self._line_vao = None
        self._textures: list = []  # (texture, unit) bound before each draw

    def prepare(self, ctx: moderngl.Context, scene, camera) -> None:
        if self.ctx is not None:
            self.release()
        self._check_scene(scene)
        self.ctx, self.origin = ctx, np.array(camera.origin, np.float64)
        try:
            self._build(ctx, scene, camera)
        except BaseException:
            self.release()
            raise

    def _check_scene(self, scene) -> None:
        """Refuse a scene or style the path cannot draw (ValueError), before any GL object."""

    @abstractmethod
    def _build(self, ctx: moderngl.Context, scene, camera) -> None:
        """Make and upload the GL objects (through ``_keep``), set the camera and the step."""

    def _keep(self, obj):
        self._objects.append(obj)
        return obj

    def _require_prepared(self) -> None:
        if self.ctx is None:
            raise RuntimeError(f"path {self.name!r} is not prepared")

    def _programs(self) -> list:
        return [p for p in (self._program, self._line_program) if p is not None]

    @staticmethod
    def _uniforms(program) -> set[str]:
        return {name for name in program if isinstance(program[name], moderngl.Uniform)}

    def _line_pass(self, ctx: moderngl.Context, positions, edges: np.ndarray) -> int:
        """Build the pass drawing ``edges`` (K, 2) vertex pairs of ``positions`` as GL_LINES in
        ``Style.wire_color``; returns the bytes uploaded."""
        edges = np.ascontiguousarray(edges, dtype=np.int32)
        self._line_program = self._keep(load_program(
            ctx, "position.vert.glsl", "position.frag.glsl",
            defines={"NUM_CLIP": len(self.style.clip_planes)}))
        self._line_program["base_color"].value = self.style.wire_color
        index = self._keep(ctx.buffer(edges.tobytes()))
        self._line_vao = self._keep(ctx.vertex_array(
            self._line_program, [(positions, "3f", "position")], index, index_element_size=4))
        self.edges = len(edges)
        return edges.nbytes

    def _set_clip_planes(self) -> None:
        planes = np.array(self.style.clip_planes, np.float64).reshape(-1, 4)
        if not len(planes):
            return
        shifted = planes.copy()
        shifted[:, 3] += planes[:, :3] @ self.origin  # float64, before the float32 cast
        data = shifted.astype(np.float32).tobytes()
        for program in self._programs():
            program["clip_planes"].write(data)

    @contextmanager
    def _clip_distances(self, count: int):
        """``gl_ClipDistance`` 0 … count − 1 enabled for the draws inside the block."""
        for i in range(count):
            self.ctx.enable_direct(GL_CLIP_DISTANCE0 + i)
        try:
            yield
        finally:
            for i in range(count):
                self.ctx.disable_direct(GL_CLIP_DISTANCE0 + i)

    def set_camera(self, camera) -> None:
        """Camera uniforms for every program: ``mvp``, and where a program has them ``view``,
        ``perspective``, ``eye_position`` and ``eye_axis`` (unit vector from target to eye)."""
        self._require_prepared()
        if not np.array_equal(np.asarray(camera.origin, np.float64), self.origin):
            raise ValueError(f"camera origin {camera.origin} differs from the prepared origin "
                             f"{self.origin}: prepare the path again for a new origin")
        mvp, view = camera.mvp_bytes(), camera.view_bytes()
        perspective = 1.0 if camera.projection == "perspective" else 0.0
        eye = np.asarray(camera.eye, np.float64)
        axis = eye - np.asarray(camera.target, np.float64)
        axis = tuple(float(v) for v in axis / np.linalg.norm(axis))
        for program in self._programs():
            names = self._uniforms(program)
            program["mvp"].write(mvp)
            if "view" in names:
                program["view"].write(view)
            if "perspective" in names:
                program["perspective"].value = perspective
            if "eye_position" in names:
                program["eye_position"].value = tuple(float(v) for v in eye)
            if "eye_axis" in names:
                program["eye_axis"].value = axis

    def _render(self, mode: int) -> None:
        """Draw the fill VAO with ``mode`` and then the line pass, in the style's GL state."""
        ctx, style = self.ctx, self.style
        ctx.enable_only(moderngl.DEPTH_TEST | (moderngl.CULL_FACE if style.cull_back else 0))
        if style.cull_back:
            ctx.front_face, ctx.cull_face = "ccw", "back"
        for texture, unit in self._textures:
            texture.use(unit)
        with self._clip_distances(len(style.clip_planes)):
            if self._line_vao is not None:
                ctx.polygon_offset = POLYGON_OFFSET
                self._vao.render(mode)
                ctx.polygon_offset = (0.0, 0.0)
                self._line_vao.render(moderngl.LINES)
            else:
                self._vao.render(mode)

    def release(self) -> None:
        for obj in reversed(self._objects):
            obj.release()
        self._objects.clear()
        self._textures = []
        self.ctx = None


class MeshPath(GLPath):
    """The shared implementation: one indexed triangle VAO, optionally a wire-frame VAO.

    Subclasses choose shaders and two switches: ``split`` (vertices are the crease-split
    Gouraud vertices with per-vertex normals; otherwise the mesh's referenced nodes without
    normals) and ``field_per`` (None, ``"node"`` or ``"element"``: the field's normalised
    values go up as a per-vertex float attribute ``value``); :meth:`topology` may be overridden
    to number the vertices differently.
    """

    vertex_shader: ClassVar[str]
    fragment_shader: ClassVar[str]
    split: ClassVar[bool] = False
    field_per: ClassVar[str | None] = None

    # ------------------------------------------------------------------ prepare
    def _check_scene(self, mesh) -> None:
        if not hasattr(mesh, "n_steps") or not hasattr(mesh, "elements"):
            raise ValueError(f"path {self.name!r} draws an FE mesh, got {type(mesh).__name__}")
        style = self.style
        for label in ("step", "reference_step"):
            if getattr(style, label) >= mesh.n_steps:
                raise ValueError(f"{label} {getattr(style, label)} out of range: "
                                 f"{mesh.name} has {mesh.n_steps} steps")
        self.scale: ColorScale | None = None
        if self.field_per is not None:
            self._check_field(mesh)
            self.scale = scale_for(mesh, style.field, style.colormap, style.value_range,
                                   style.bands, style.hide_range)

    def topology(self, mesh) -> tuple[np.ndarray | None, np.ndarray]:
        """(vertex_node, triangles): the node of each vertex (None: the nodes themselves) and
        (K, 3) triangles into the vertices; unreferenced vertices are dropped afterwards."""
        if self.split:
            self._gouraud = mesh.gouraud(self.style.crease_deg)
            return np.asarray(self._gouraud.vertex_node, np.int64), self._gouraud.triangles
        return None, mesh.triangles

    def static_attributes(self) -> list[tuple[np.ndarray, str, str]]:
        """Extra per-vertex attributes uploaded once, as (float32 data, format, name)."""
        return []

    def layout(self, mesh, triangles: np.ndarray, n_vertices: int) -> np.ndarray:
        """The index buffer content for ``Style.strips`` and ``Style.quad_diagonal``: (K, 3)
        triangles for a list, a 1-D strip index array with ``RESTART`` markers otherwise. Sets
        ``mode``, ``triangles``, ``strips`` and ``vertices_sent``."""
        style = self.style
        self.mode, self.strips = moderngl.TRIANGLES, 0
        self.triangles = len(triangles)
        if style.strips == "none" and style.diagonal == "shorter":
            self.vertices_sent = triangles.size
            return triangles
        if type(self).topology is not MeshPath.topology:
            raise ValueError(f"path {self.name!r} gives every triangle its own provoking vertex; "
                             f"strips and strip diagonals need shared vertices: draw it with "
                             f"strips='none' and quad_diagonal='shorter'")
        if style.diagonal == "strip":
            elements = self._gouraud.elements if self.split else mesh.elements
            quads = quad_strips(elements, style.strip_cutoff)
            if style.strips == "quad":
                index = quads.restart_indices(RESTART)
                self.mode = moderngl.TRIANGLE_STRIP
                self.strips = quads.n_strips + len(quads.leftover) + len(quads.triangles)
                self.vertices_sent = len(index) - max(self.strips - 1, 0)
                return index
            triangles = quads.triangle_list()
            self.triangles = len(triangles)
        if style.strips == "triangle":
            tri = tri_strips(triangles, n_vertices, RESTART)
            self.mode, self.strips, self.vertices_sent = (moderngl.TRIANGLE_STRIP, tri.n_strips,
                                                          tri.n_vertices)
            return tri.indices
        self.vertices_sent = triangles.size
        return triangles

    def _build(self, ctx: moderngl.Context, mesh, camera) -> None:
        self.mesh = mesh
        style = self.style
        # row in the crease split of each vertex (None: vertex i is split vertex i)
        self._split_rows = None
        vertex_node, triangles = self.topology(mesh)
        n_vertices = mesh.n_nodes if vertex_node is None else len(vertex_node)
        index = self.layout(mesh, triangles, n_vertices)
        used = np.zeros(n_vertices, bool)
        used[triangles.ravel()] = True
        self._remap = None
        if not used.all():  # unreferenced nodes are not uploaded
            keep = np.flatnonzero(used)
            self._remap = np.full(n_vertices, -1, np.int64)
            self._remap[keep] = np.arange(len(keep))
            vertex_node = keep if vertex_node is None else vertex_node[keep]
            if self.split:
                self._split_rows = keep if self._split_rows is None else self._split_rows[keep]
            if index.ndim == 1:  # strip indices: restart markers stay
                marker = index == RESTART
                index = np.where(marker, RESTART, self._remap[np.where(marker, 0, index)])
                index = index.astype(np.uint32)
            else:
                index = self._remap[index]
            n_vertices = len(keep)
        self._vertex_node = vertex_node
        index = np.ascontiguousarray(index, dtype=np.uint32 if index.ndim == 1 else np.int32)
        self.vertices = n_vertices
        uploaded = 0

        defines = {"NUM_CLIP": len(style.clip_planes)}
        if style.hide_range is not None and self.field_per is not None:
            defines["HIDE"] = 1
        self._program = self._keep(load_program(ctx, self.vertex_shader, self.fragment_shader,
                                                defines=defines))
        self._positions = self._keep(ctx.buffer(reserve=n_vertices * 12))
        self._index = self._keep(ctx.buffer(index.tobytes()))
        uploaded += index.nbytes
        content = [(self._positions, "3f", "position")]
        self._normals = self._values = self._colormap = None
        if self.split:
            self._normals = self._keep(ctx.buffer(reserve=n_vertices * 12))
            content.append((self._normals, "3f", "normal"))
        if self.field_per is not None:
            self._values = self._keep(ctx.buffer(reserve=n_vertices * 4))
            content.append((self._values, "1f", "value"))
        for data, fmt, name in self.static_attributes():
            data = np.ascontiguousarray(data, np.float32)
            if self._remap is not None:
                data = data[keep]
            content.append((self._keep(ctx.buffer(data.tobytes())), fmt, name))
            uploaded += data.nbytes
        if self.scale is not None:
            texels = self.scale.texture_data()
            self._colormap = self._keep(ctx.texture((len(texels), 1), 4, texels.tobytes()))
            self._textures = [(self._colormap, 0)]
            filt = moderngl.LINEAR if self.scale.linear else moderngl.NEAREST
            self._colormap.filter = (filt, filt)
            self._colormap.repeat_x = self._colormap.repeat_y = False
            self._program["colormap"].value = 0
            self._program["missing_color"].value = style.base_color
            self._program["colormap_st"].value = self.scale.coord_transform
            uploaded += texels.nbytes
        self._vao = self._keep(ctx.vertex_array(self._program, content, self._index,
                                                index_element_size=4))
        if "base_color" in self._uniforms(self._program):
            self._program["base_color"].value = style.base_color

        self._line_program = self._line_vao = None
        if style.wireframe:
            uploaded += self._line_pass(ctx, self._positions, self._vertex_of_node()[mesh.edges])

        self._static_values = False
        if self.field_per is not None and self._field_values().ndim == 1:
            uploaded += self._upload_values(style.step)
            self._static_values = True
        self._set_clip_planes()
        self.set_camera(camera)
        self.bytes_per_step = self.set_step(style.step)
        self.bytes_uploaded = uploaded + self.bytes_per_step

    def _check_field(self, mesh) -> None:
        name = self.style.field
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

    def _field_values(self) -> np.ndarray:
        by_name = self.mesh.node_fields if self.field_per == "node" else self.mesh.element_fields
        return by_name[self.style.field]

    def _vertex_of_node(self) -> np.ndarray:
        """(N,) one vertex index per referenced node (the first split vertex of each)."""
        if self._vertex_node is None:
            return np.arange(self.mesh.n_nodes)
        first = np.full(self.mesh.n_nodes, -1, np.int64)
        first[self._vertex_node[::-1]] = np.arange(len(self._vertex_node))[::-1]
        return first

    # ------------------------------------------------------------------ per frame / per step
    def shown_coordinates(self, step: int) -> np.ndarray:
        """(N, 3) float64 node positions drawn for ``step`` (deformation plot applied)."""
        mesh, style = self.mesh, self.style
        current = mesh.coordinates(step)
        if style.magnification == 1.0 or step == style.reference_step:
            return current
        reference = mesh.coordinates(style.reference_step)
        return reference + style.magnification * (current - reference)

    def set_step(self, step: int) -> int:
        self._require_prepared()
        if int(step) != step or not 0 <= step < self.mesh.n_steps:
            raise ValueError(f"step {step} out of range: {self.mesh.name} has "
                             f"{self.mesh.n_steps} steps")
        step = int(step)
        shown = self.shown_coordinates(step)
        points = shown if self._vertex_node is None else shown[self._vertex_node]
        data = (points - self.origin).astype(np.float32)
        self._positions.write(data)
        sent = data.nbytes
        if self.split:
            normals = self._gouraud.normals(shown)
            if self._split_rows is not None:
                normals = normals[self._split_rows]
            normals = normals.astype(np.float32)
            self._normals.write(normals)
            sent += normals.nbytes
        if self.field_per is not None and not self._static_values:
            sent += self._upload_values(step)
        self.step = step
        return sent

    def _upload_values(self, step: int) -> int:
        """Upload the normalised field values of ``step``; non-finite ones as ``NO_VALUE``."""
        values = self.mesh.node_field(self.style.field, step) if self.field_per == "node" \
            else self.mesh.element_field(self.style.field, step)
        t = self.scale.normalise(values)
        missing = ~np.isfinite(t)
        self.missing_values = int(missing.sum())
        if self.missing_values:
            t[missing] = NO_VALUE
        data = self.vertex_values(t).astype(np.float32)
        self._values.write(data)
        return data.nbytes

    def vertex_values(self, t: np.ndarray) -> np.ndarray:
        """(V,) per-vertex values from per-node values (element paths override)."""
        return t if self._vertex_node is None else t[self._vertex_node]

    def draw(self) -> None:
        self.ctx.provoking_vertex = moderngl.LAST_VERTEX_CONVENTION
        self._render(self.mode)
