"""Any mesh render path drawn by the es2008 software rasterizer instead of GL.

:class:`SoftwarePath` takes the name of a mesh path (``position``, ``flat``, ``gouraud``,
``vertex_color``, ``pixel_color``, ``element_color``) and its :class:`~.style.Style`, and draws
the same image on the CPU with :func:`workbench.algo.softraster.render`: it rasterizes the
path's own :class:`~.drawdata.MeshDrawData` (the same triangles and quad diagonals, the same
deformation plot, normals, colour texture, transfer-function alpha test and clip planes), with
the same pixel rule as llvmpipe and the no-result rule of :mod:`~.colormap` (a triangle with a
non-finite value drawn whole in :data:`~.colormap.NO_RESULT_COLOR`). It follows the path
protocol (prepare, set_camera, set_step, draw, release) so that
:func:`workbench.measurement.rows` times it like any path through the
:class:`~workbench.paths.backends.SoftwareRasterizer` backend; it draws into a
:class:`SoftwareTarget` instead of a GL framebuffer, and needs no GL context.

Refused with ValueError: a path that is not a mesh path, a wire frame (a GL line pass),
strips (a GL index layout; the triangles are the same without), a perspective camera (the
rasterizer is orthographic, as es2008's), MSAA samples. Beams and SPH particles are not
drawn: a :class:`~workbench.paths.kinds.KindWarning` names them with their counts.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from ..algo.softraster import Frame, RasterOptions, Shading, render
from . import colormap
from .base import RenderPath
from .kinds import warn_not_drawn
from .registry import path_class

if TYPE_CHECKING:
    import moderngl
    from numpy.typing import ArrayLike

    from ..gl.camera import Camera
    from ..scene.protocol import Scene
    from .style import Style

DEFAULT_OPTIONS = RasterOptions()  # frozen: one instance serves as every path's default

SHADING_OF = {"position": "constant", "flat": "flat", "gouraud": "gouraud",
              "vertex_color": "vertex_color", "pixel_color": "pixel_color",
              "element_color": "element_color"}


@dataclass(eq=False)
class RasterInputs:
    """The arrays a software path rasterizes (see :meth:`SoftwarePath.raster_inputs`):
    ``coordinates`` (V, 3) float64 drawn vertex positions (model units), ``normals`` (V, 3)
    float32 or None, ``values`` (V,) normalised field (NaN: no value) or None,
    ``triangle_values`` (K,) (NaN: no value) or None,
    ``triangles`` (K, 3) int64 into the vertices, the ``shading`` and the model-space
    ``clip_planes`` (P, 4)."""

    coordinates: np.ndarray
    normals: np.ndarray | None
    values: np.ndarray | None
    triangle_values: np.ndarray | None
    triangles: np.ndarray
    shading: Shading
    clip_planes: np.ndarray


class SoftwareTarget:
    """The software path's framebuffer: a :class:`Frame` with the GL framebuffer's
    ``use`` / ``clear`` / ``read`` / ``release`` calls (colours in [0, 1] as GL clears)."""

    def __init__(self, size: tuple[int, int]) -> None:
        width, height = (int(v) for v in size)
        if width <= 0 or height <= 0:
            raise ValueError(f"framebuffer size must be positive, got {size}")
        self.size = (width, height)
        self.frame = Frame.empty(width, height)

    def use(self) -> None:
        """Nothing to bind: the path draws into ``frame``."""

    def clear(self, color: tuple[float, float, float, float] = (1.0, 1.0, 1.0, 1.0),
              depth: float = 1.0) -> None:
        rgba = np.rint(np.clip(np.asarray(color, np.float64), 0, 1) * 255).astype(np.uint8)
        self.frame.color[...] = rgba
        self.frame.depth[...] = depth
        self.frame.triangle[...] = -1

    def read(self) -> np.ndarray:
        """(H, W, 4) uint8 RGBA copy, row 0 at the top."""
        return self.frame.color.copy()

    def release(self) -> None:
        """Nothing to free."""


class SoftwarePath(RenderPath):
    """The image of mesh path ``name`` with ``style``, rasterized on the CPU with ``options``."""

    rasterizer = "software"
    needs = frozenset({"triangles"})  # replaced by the drawn path's
    style: Style

    def __init__(self, name: str = "pixel_color", style: Style | None = None,
                 options: RasterOptions = DEFAULT_OPTIONS) -> None:
        cls = path_class(name)
        if name not in SHADING_OF:
            raise ValueError(f"the software rasterizer draws the mesh paths "
                             f"{', '.join(SHADING_OF)}; not {name!r}")
        if style is not None and getattr(style, "wireframe", False):
            raise ValueError("the software rasterizer draws no wire frame (a GL line pass); "
                             "drop the wire frame")
        if style is not None and getattr(style, "strips", "none") != "none":
            raise ValueError("strips are a GL index layout; the software rasterizer draws the "
                             "same triangles from the list: use strips='none'")
        self.name, self.style_class = name, cls.style_class
        super().__init__(style)
        self.needs = cls.needs
        self.options = options
        self._drawn = cls(self.style)  # builds the draw data; never prepared on GL
        self.target: SoftwareTarget | None = None
        self.stats = None
        self.mesh = self.data = self.scale = None
        self._workspace: dict = {}
        self.deleted = 0  # elements hidden at the drawn step (erosion)

    @classmethod
    def default_camera(cls, scene: Scene, size: tuple[int, int], **kwargs: Any) -> Camera:
        """The camera of the mesh paths."""
        return path_class("position").default_camera(scene, size, **kwargs)

    @property
    def renderer(self) -> str:
        """The renderer named in measurement rows."""
        o = self.options
        generator = f"span table S={o.table_size}" if o.generator == "table" else "half-space"
        threads = self.stats.threads if self.stats is not None else (o.threads or "all")
        return (f"software rasterizer ({generator}, {o.subpixel_bits} sub-pixel bits, "
                f"{threads} threads)")

    def make_target(self, size: tuple[int, int], samples: int = 0) -> SoftwareTarget:
        """A framebuffer of ``size`` (W, H) that this path draws into from now on."""
        if samples:
            raise ValueError("the software rasterizer draws without MSAA: samples must be 0")
        self.target = SoftwareTarget(size)
        return self.target

    # ------------------------------------------------------------------ prepare
    def prepare(self, ctx: moderngl.Context | None, mesh: Scene, camera: Camera) -> None:
        """Build the drawn path's draw data for ``mesh`` (``ctx`` is not used: no GL)."""
        style = self.style
        if camera.projection != "orthographic":
            raise ValueError("the software rasterizer draws orthographic views only")
        data = self._drawn.draw_data(mesh)
        warn_not_drawn(mesh, "the software rasterizer")  # beams and SPH particles: GL only
        if style.deleted == "ghost" and mesh.erodes:
            raise ValueError("the software rasterizer hides deleted elements; "
                             "deleted='ghost' (translucent) is drawn on GL only")
        self.data, self.scale = data, data.scale
        self._triangles = np.ascontiguousarray(data.triangle_list(), np.int64)
        self.triangles, self.vertices = len(self._triangles), data.n_vertices
        self.vertices_sent = self._triangles.size
        self.mesh, self.origin = mesh, np.array(camera.origin, np.float64)
        scale = data.scale
        self._shading = Shading(
            kind=SHADING_OF[self.name], base_color=style.base_color,
            missing_color=colormap.NO_RESULT_COLOR,
            texels=None if scale is None else scale.texture_data(),
            linear=False if scale is None else scale.linear,
            coord=(1.0, 0.0) if scale is None else scale.coord_transform,
            alpha_test=scale is not None and style.hide_range is not None)
        planes = np.array(style.clip_planes, np.float64).reshape(-1, 4)
        planes[:, 3] += planes[:, :3] @ self.origin  # moved to the upload origin in float64
        self._planes = planes
        self.set_camera(camera)
        self.set_step(style.step)

    def set_camera(self, camera: Camera) -> None:
        if self.mesh is None:
            raise RuntimeError(f"software path {self.name!r} is not prepared")
        if not np.array_equal(np.asarray(camera.origin, np.float64), self.origin):
            raise ValueError(f"camera origin {camera.origin} differs from the prepared origin "
                             f"{self.origin}: prepare the path again for a new origin")
        if camera.projection != "orthographic":
            raise ValueError("the software rasterizer draws orthographic views only")
        self._view, self._projection = camera.view_matrix(), camera.projection_matrix()

    def shown_coordinates(self, step: int) -> np.ndarray:
        """(N, 3) float64 node positions drawn for ``step`` (deformation plot applied)."""
        return self.data.shown_coordinates(step)

    def set_step(self, step: int) -> int:
        mesh, data = self.mesh, self.data
        if mesh is None:
            raise RuntimeError(f"software path {self.name!r} is not prepared")
        step = mesh.step_index(step)
        shown = data.shown_coordinates(step)
        # what GL uploads per step: float32 relative to the origin (subtracted in float64)
        self._positions = data.positions(shown, self.origin)
        self._normals = data.normals(shown)
        self._values = self._triangle_values = None
        if data.field_per is not None:
            # the values GL uploads, NaN where GL uploads a missing flag: the rasterizer flags
            # the triangles of a non-finite value
            t, missing = colormap.mark_missing(data.normalised(step))
            self.missing_values = int(missing.sum())
            t = np.where(missing, np.nan, t)
            if data.field_per == "node":
                self._values = data.vertex_values(t)
            else:
                self._triangle_values = t[data.triangle_element]
        # erosion: only the triangles of elements in use at the step are rasterized
        live = data.live_triangles(step)
        self._live_triangles, self._live_values = self._triangles, self._triangle_values
        if live is not None:
            self._live_triangles = self._triangles[live]
            if self._triangle_values is not None:
                self._live_values = self._triangle_values[live]
        self.deleted = 0 if live is None else mesh.n_deleted(step)
        self.step = step
        return sum(a.nbytes for a in (self._positions, self._normals, self._values,
                                      self._triangle_values) if a is not None)

    def draw(self, vectorized: bool = True) -> None:
        """Rasterize into the target made by :meth:`make_target` (on top of what it holds);
        ``vectorized=False`` runs every step as plain Python (small scenes only). ``stats``
        then holds the draw's :class:`~workbench.algo.softraster.RenderStats`."""
        if self.mesh is None or self.target is None:
            raise RuntimeError(f"software path {self.name!r} needs prepare and make_target")
        _, self.stats = render(
            self._positions, self._live_triangles, self._view, self._projection,
            self.target.size, self._shading, self.options, normals=self._normals,
            values=self._values, triangle_values=self._live_values, clip_planes=self._planes,
            frame=self.target.frame, vectorized=vectorized, workspace=self._workspace)

    def render_triangles(self, ids: ArrayLike,
                         background: tuple[int, int, int, int] = (255, 255, 255, 255)) -> Frame:
        """A new frame of :attr:`target`'s size (``make_target`` first) with only the triangles
        ``ids`` of the path's triangle list drawn, keeping their indices in that list as the
        frame's triangle indices: the frame of one domain for sort-last compositing. A triangle of
        an element deleted at the drawn step (erosion) is not drawn."""
        if self.mesh is None or self.target is None:
            raise RuntimeError(f"software path {self.name!r} needs prepare and make_target")
        ids = np.asarray(ids, np.int64)
        if ids.ndim != 1 or (len(ids) and (ids.min() < 0 or ids.max() >= self.triangles)):
            raise ValueError(f"triangle ids must be a 1-D array of indices below "
                             f"{self.triangles}")
        live = self.data.live_triangles(self.step)
        if live is not None:  # erosion: a deleted element's triangles are not drawn
            ids = ids[live[ids]]
        tv = None if self._triangle_values is None else self._triangle_values[ids]
        frame, _ = render(self._positions, self._triangles[ids], self._view, self._projection,
                          self.target.size, self._shading, self.options, ids=ids,
                          normals=self._normals, values=self._values, triangle_values=tv,
                          clip_planes=self._planes, background=background)
        return frame

    def raster_inputs(self) -> RasterInputs:
        """What :meth:`draw` rasterizes at the current step, for writing it elsewhere
        (:func:`workbench.distributed.chunked.write_chunked`): float64 drawn vertex coordinates,
        normals, values, triangles, shading and model-space clip planes. Refused (ValueError)
        at a step where elements are deleted: the triangle list keeps every element."""
        if self.mesh is None:
            raise ValueError(f"software path {self.name!r} is not prepared")
        if self.deleted:
            raise ValueError(f"{self.mesh.name} has {self.deleted} elements deleted at step "
                             f"{self.step}: its raster inputs keep every element; write the "
                             f"live elements (FEMesh.subset(mesh.alive(step))) instead")
        shown = self.data.shown_coordinates(self.step)
        coordinates = shown if self.data.vertex_node is None else shown[self.data.vertex_node]
        return RasterInputs(np.ascontiguousarray(coordinates, np.float64), self._normals,
                            self._values, self._triangle_values, self._triangles,
                            self._shading, np.array(self.style.clip_planes,
                                                    np.float64).reshape(-1, 4))

    def release(self) -> None:
        self.mesh = None
        self.target = None
        self._workspace = {}

