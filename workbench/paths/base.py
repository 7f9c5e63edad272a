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
  that is not finite (the stress of a rigid shell in a d3plot, a thickness nobody gave) has no
  colour of the scale: every triangle that has such a value at a vertex (node fields) or as
  its element's (element fields) is drawn whole in the no-result colour
  (:data:`~workbench.paths.colormap.NO_RESULT_COLOR`, pure green), lit, never hidden — the
  rule and its mechanism are in :mod:`workbench.paths.colormap`. ``missing_values`` counts the
  node or element values without one at the step drawn.
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
* **Erosion** (a mesh whose element field ``"alive"`` holds a 0,
  :attr:`~workbench.scene.mesh.FEMesh.erodes`): at each step the mesh paths of a triangle list
  write the triangles and wire-frame edges of the live elements to the front of their index
  buffers and draw only those (``set_step`` sends the whole index, the same bytes every step);
  the deleted ones behind them are drawn translucent with ``Style.deleted = "ghost"``. The
  colour range comes from live elements only. ``deleted`` counts the elements hidden at the
  step drawn. A strip layout keeps every element: it draws them with an
  :class:`~workbench.paths.mesh.ErosionWarning`.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from contextlib import contextmanager
from typing import TYPE_CHECKING, Any, ClassVar, Self

import moderngl
import numpy as np

from ..gl import Camera, load_program
from ..gl.camera import check_resolvable
from ..scene.needs import known_items
from .registry import register
from .style import Style

if TYPE_CHECKING:
    from numpy.typing import ArrayLike

    from ..scene.protocol import Scene

GL_CLIP_DISTANCE0 = 0x3000
POLYGON_OFFSET = (1.0, 1.0)  # fill pass under a wire frame: (factor, units)


class RenderPath(ABC):
    """One way of drawing a scene, built once (``prepare``) and drawn many times (``draw``).

    The protocol every registered path meets: ``prepare(ctx, scene, camera)`` once, then any
    number of ``set_camera``, ``set_step`` and ``draw``, then ``release``. A prepared path is a
    context manager: ``with path:`` releases its GL objects on the way out, also when a draw
    raises.

    ``style_class`` is the dataclass of options the path takes (:class:`Style` for the mesh
    paths); ``scene_kinds`` names the kinds of scene ``prepare`` accepts (``scene.kind``:
    "mesh" for an :class:`~workbench.scene.mesh.FEMesh`, "spacetime" for a
    :class:`~workbench.algo.spacetime.scene.SpacetimeScene`, "surface" for a
    :class:`~workbench.algo.fepatch.surface.TexturedSurface`). ``needs`` names the items the
    path asks the scene to derive and cache (registered in :mod:`workbench.scene.needs`, derived
    by :func:`~workbench.scene.needs.derive` before ``prepare``); an instance drawing a wire
    frame adds ``"edges"`` to its own ``needs``. :meth:`default_camera` is the camera a path
    family shows a scene with when none is given. After ``prepare``: ``triangles``,
    ``vertices`` and ``edges`` (wire-frame lines, 0 without) drawn, ``bytes_uploaded``
    (everything uploaded by prepare, textures included), ``bytes_per_step`` (what one
    ``set_step`` uploads), ``vertices_sent`` (vertex indices one draw sends down the pipeline,
    restart markers excluded: 3 per listed triangle) and ``strips`` (primitives restarted, 0
    for a triangle list).
    """

    name: ClassVar[str]
    needs: ClassVar[frozenset[str]]
    style_class: ClassVar[type] = Style
    scene_kinds: ClassVar[frozenset[str]] = frozenset({"mesh"})
    fixed_options: ClassVar[frozenset[str]] = frozenset()
    style: Any  # an instance of style_class; each path family names its own

    def __init__(self, style: object | None = None) -> None:
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

    @classmethod
    def default_camera(cls, scene: Scene, size: tuple[int, int], *,
                       view: tuple[float, float] = (30.0, 25.0),
                       projection: str = "orthographic", up: str = "z",
                       style: object | None = None) -> Camera:
        """A camera showing all of ``scene`` at ``size`` (W, H): :meth:`Camera.fit_box` over
        ``scene.bounds()`` at azimuth and elevation ``view`` (degrees). Path families whose
        scenes change over time or live in a plane override it."""
        return cls.fit_camera(*scene.bounds(), size, view=view, projection=projection, up=up)

    @staticmethod
    def fit_camera(lo: ArrayLike, hi: ArrayLike, size: tuple[int, int], *,
                   view: tuple[float, float] = (30.0, 25.0), projection: str = "orthographic",
                   up: str = "z") -> Camera:
        """:meth:`Camera.fit_box` over ``lo``–``hi`` for an image of ``size`` (W, H), after
        :func:`~workbench.gl.camera.check_resolvable` refused a box that cannot be drawn."""
        check_resolvable(lo, hi)
        return Camera.fit_box(lo, hi, azimuth=view[0], elevation=view[1], projection=projection,
                              aspect=size[0] / size[1], up=up)

    @abstractmethod
    def prepare(self, ctx: moderngl.Context, scene: Scene, camera: Camera) -> None:
        """Upload what the scene gives (derived data already cached by the scene), with
        ``style.step`` drawn, for ``camera``."""

    @abstractmethod
    def set_camera(self, camera: Camera) -> None:
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

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *exc: object) -> None:
        self.release()

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        if "name" in cls.__dict__:
            unknown = cls.needs - known_items()
            if unknown:
                raise TypeError(f"{cls.__name__}.needs names unknown data {sorted(unknown)}; "
                                f"registered: {sorted(known_items())}")
            register(cls)


class GLPath(RenderPath):
    """The GL bookkeeping every path shares, once: objects kept for ``release``, the prepared
    guard, the camera-origin check, clip-distance enabling, the fill program ``_program`` and
    VAO ``_vao``, an optional pass of lines (``_line_program``/``_line_vao``, drawn after the
    fill, which gets polygon offset), clip planes and camera uniforms for every program.

    ``prepare`` releases a previous preparation, calls ``_check_scene`` (refusals before any GL
    object exists), records the context and the float64 upload origin, then ``_build``; if
    ``_build`` raises, every object made so far is released.
    """

    def __init__(self, style: object | None = None) -> None:
        super().__init__(style)
        self.ctx: moderngl.Context | None = None
        self.origin: np.ndarray | None = None
        self._objects: list = []
        self._program = self._line_program = self._line_vao = None
        self._textures: list = []  # (texture, unit) bound before each draw
        # indices the fill and line passes draw (-1: the whole buffer); fewer where a path
        # hides deleted elements (erosion) at the step
        self._fill_vertices = self._line_vertices = -1
        self.deleted = 0  # elements hidden at the drawn step

    def prepare(self, ctx: moderngl.Context, scene: Scene, camera: Camera) -> None:
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
        index = self._line_index = self._keep(ctx.buffer(edges.tobytes()))
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

    def set_camera(self, camera: Camera) -> None:
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
                self._vao.render(mode, vertices=self._fill_vertices)
                ctx.polygon_offset = (0.0, 0.0)
                self._line_vao.render(moderngl.LINES, vertices=self._line_vertices)
            else:
                self._vao.render(mode, vertices=self._fill_vertices)

    def release(self) -> None:
        for obj in reversed(self._objects):
            obj.release()
        self._objects.clear()
        self._textures = []
        self._fill_vertices = self._line_vertices = -1
        self.ctx = None
