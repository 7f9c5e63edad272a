"""st2005 render paths: time slices of spacetime FE solutions, per vertex or per pixel.

Both paths draw the same polygons (slice polygons of tetrahedra, or the spacetime triangles of
a 1-D bar) with the height ``height_scale·|v|`` evaluated per vertex from the element's cubic
polynomial (the paper's vertex program). They differ in colour and lighting:

* ``per_vertex`` — strain energy density, colour and Phong lighting at the polygon vertices,
  the lit colour interpolated across the polygon (Gouraud);
* ``per_pixel`` — the element's coefficients are fetched per fragment and the strain energy
  density, its colour and the exact normal of the height field are evaluated at every pixel
  (the paper's fragment program).

Element data go to the GPU once per slice, 12 float RGBA texels per element used by the
slice (centre, 1/extent, 20 coefficient vectors), indexed by the element's slot: in a buffer
texture (``element_store="buffer"``, a ``samplerBuffer``) or in a 2-D texture whose rows never
break an element (``"texture"``, the paper's texture rectangle). Positions and element centres
are float32 relative to a float64 origin, so a domain far from the coordinate origin is
evaluated like one at it; ``origin=0`` uploads global coordinates instead, to show what that
costs.

Options: ``edge_overdraw`` draws the edges shared between polygons (every edge but those the
scene marks ``outer``, on the domain boundary) with the same shading after the fill, against the
cracks that open between elements whose heights differ (st2005 §4.3):

* ``"over"`` — one-pixel lines depth-tested like the polygons (the paper's overdraw: a line
  also covers up to half a pixel of the neighbouring polygon, which then shows the line's
  element);
* ``"behind"`` — the polygons in the near half of the depth range and the lines in the far
  half (each keeping its own depth order), so a line shows only where no polygon covers the
  pixel — the gaps — and every pixel a polygon covers keeps that polygon's exact shading;
* ``"skirts"`` — as ``"behind"``, plus a vertical quad hanging from every shared edge down
  below the lowest height (a geometry shader makes it from the edge's line), also in the far
  half: a line fills a gap only up to a pixel wide, a skirt closes a gap of any width. Skirts
  are vertical, so a top view draws none of their pixels.

Quadrisection is done on the polygons before they reach the path
(:func:`workbench.algo.spacetime.slicing.quadrisect`).

The shading model is :mod:`workbench.algo.spacetime.shading`; with a top view its float64
evaluation at pixel centres is the exact image the paths are measured against.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from numbers import Real
from typing import TYPE_CHECKING

import moderngl
import numpy as np

from ..algo.spacetime.raster import PixelGrid
from ..algo.spacetime.scene import SpacetimeScene
from ..algo.spacetime.shading import LIGHT
from ..gl import load_program
from ..gl.camera import Camera
from ..gl.texbuffer import TextureBuffer
from .base import GLPath
from .colormap import colormap_lut

if TYPE_CHECKING:
    from numpy.typing import ArrayLike

    from ..scene.protocol import Scene

SHADINGS = ("per_vertex", "per_pixel")
OVERDRAWS = ("none", "over", "behind", "skirts")
ELEMENT_STORES = ("buffer", "texture")
ELEMENT_TEXELS = 12
ELEMENTS_PER_ROW = 341  # 4092 texels per row


@dataclass
class SpacetimeStyle:
    """How a spacetime path draws.

    shading: "per_vertex" or "per_pixel". edge_overdraw: "none", "over" (shared edges drawn as
    lines over the fill), "behind" (lines that only fill gaps) or "skirts" (lines and vertical
    skirts that only fill gaps). lighting: Phong with the height-field normal (off: the ramp
    colour alone). height_scale: mm of height per mm/µs of speed. U_max: the top of the log
    colour scale in kJ/m³. colormap: a matplotlib colormap name for the ramp. element_store:
    "buffer" (a buffer texture) or "texture" (a 2-D texture of rows).
    Refused with ValueError: an unknown shading, overdraw or store, a U_max that is not
    positive and finite, a height scale that is negative or not finite.
    """

    shading: str = "per_pixel"
    edge_overdraw: str = "none"
    lighting: bool = True
    height_scale: float = 1.0
    U_max: float = 100.0
    colormap: str = "inferno"
    element_store: str = "buffer"

    def __post_init__(self) -> None:
        if self.shading not in SHADINGS:
            raise ValueError(f"shading must be one of {SHADINGS}, got {self.shading!r}")
        if self.edge_overdraw not in OVERDRAWS:
            raise ValueError(f"edge_overdraw must be one of {OVERDRAWS}, "
                             f"got {self.edge_overdraw!r}")
        if self.element_store not in ELEMENT_STORES:
            raise ValueError(f"element_store must be one of {ELEMENT_STORES}, "
                             f"got {self.element_store!r}")
        for name in ("U_max", "height_scale"):
            value = getattr(self, name)
            if isinstance(value, (bool, np.bool_)) or not isinstance(value, Real):
                raise ValueError(f"{name} must be a number, got {value!r}")
        if not (np.isfinite(self.U_max) and self.U_max > 0):
            raise ValueError(f"U_max must be positive and finite, got {self.U_max}")
        if not (np.isfinite(self.height_scale) and self.height_scale >= 0):
            raise ValueError("height_scale must be non-negative and finite, got "
                             f"{self.height_scale}")


def top_camera(grid: PixelGrid, z_range: tuple[float, float] = (-1.0, 1.0),
               origin: ArrayLike | None = None) -> Camera:
    """An orthographic camera looking down −z whose pixels are exactly those of ``grid``
    (a :class:`workbench.algo.spacetime.raster.PixelGrid`): pixel centres of the image read
    back are the grid's centres, so the exact image and the rendered one match pixel for pixel.
    ``z_range`` (mm) must enclose the heights drawn; ``origin`` (3,) defaults to the grid centre
    at z = 0."""
    centre = np.array([grid.left + grid.dx * grid.width / 2,
                       grid.top - grid.dy * grid.height / 2, 0.0])
    origin = centre.copy() if origin is None else np.asarray(origin, np.float64)
    lo, hi = float(z_range[0]), float(z_range[1])
    depth = max(hi - lo, 1e-6)
    eye = centre - origin + np.array([0.0, 0.0, hi + depth])
    return Camera(origin=origin, eye=eye, target=eye - np.array([0.0, 0.0, 1.0]),
                  up=np.array([0.0, 1.0, 0.0]),
                  projection="orthographic", half_height=grid.dy * grid.height / 2,
                  aspect=(grid.dx * grid.width) / (grid.dy * grid.height),
                  near=0.5 * depth, far=2.5 * depth)


class SpacetimePath(GLPath):
    """The shared implementation of the two registered spacetime paths (``spacetime_vertex``,
    ``spacetime_pixel``; :func:`spacetime_path` picks one by ``style.shading``), prepared for one
    scene: a :class:`~workbench.algo.spacetime.scene.SpacetimeScene` (a slice, or the bar's
    spacetime), built by the caller. The scene is one configuration, so ``set_step`` accepts only
    step 0.

    After :meth:`prepare`: ``polygons``, ``triangles``, ``lines`` (shared edges overdrawn) and
    ``skirts`` drawn, ``elements`` (element records uploaded), ``bytes_uploaded``.
    """

    needs = frozenset()
    style_class = SpacetimeStyle
    scene_kinds = frozenset({"spacetime"})
    style: SpacetimeStyle

    def __init__(self, style: SpacetimeStyle | None = None) -> None:
        super().__init__(style)
        self.polygons = self.lines = self.skirts = self.elements = 0

    @property
    def label(self) -> str:
        """The shading and the overdraw, e.g. ``per_pixel+overdraw skirts``."""
        overdraw = self.style.edge_overdraw
        return self.style.shading + ("" if overdraw == "none" else f"+overdraw {overdraw}")

    @property
    def _behind(self) -> bool:
        """Whether the overdraw goes to the far half of the depth range, behind the fill."""
        return self.style.edge_overdraw in ("behind", "skirts")

    @classmethod
    def default_camera(cls, scene: Scene, size: tuple[int, int], *,
                       view: tuple[float, float] = (30.0, 25.0),
                       projection: str = "orthographic", up: str = "z",
                       style: object | None = None) -> Camera:
        """The top view of the scene's drawing plane ((x, y) or (x, t), heights up z) whose
        pixel centres are those of :meth:`PixelGrid.fit`, so that the exact image matches; its
        depth range encloses the heights drawn with ``style.height_scale``. ``view``,
        ``projection`` and ``up`` do not apply."""
        grid = PixelGrid.fit(*scene.bounds(), size[0], size[1])
        top = float(getattr(style, "height_scale", 1.0)) * scene.max_speed()
        return top_camera(grid, (-1.0, top + 1.0))

    def _check_scene(self, scene) -> None:
        if not isinstance(scene, SpacetimeScene):
            raise ValueError(f"path {self.name!r} draws a spacetime scene (e.g. spacetime:radial), "
                             f"got {type(scene).__name__}")
        scene.check()

    def _load(self, ctx, defines: dict, depth_half: int | None, skirt: bool = False):
        defines = dict(defines)
        if depth_half is not None:
            defines["DEPTH_HALF"] = depth_half
        if skirt:
            defines["SKIRT"] = 1
        return self._keep(load_program(ctx, "spacetime.vert.glsl", "spacetime.frag.glsl",
                                       geometry="spacetime_skirt.geom.glsl" if skirt else None,
                                       defines=defines))

    def _build(self, ctx, scene: SpacetimeScene, camera: Camera) -> None:
        self.scene = scene
        style = self.style
        defines = {}
        if style.shading == "per_vertex":
            defines["PER_VERTEX"] = 1
        if scene.is_bar:
            defines["BAR"] = 1
        if style.element_store == "buffer":
            defines["ELEMENT_BUFFER"] = 1
        behind = self._behind
        self._program = self._load(ctx, defines, -1 if behind else None)
        self._line_program = self._skirt_program = None
        if style.edge_overdraw != "none":
            self._line_program = self._load(ctx, defines, 1 if behind else None)
        if style.edge_overdraw == "skirts":
            self._skirt_program = self._load(ctx, defines, 1, skirt=True)

        used, slot = np.unique(scene.element, return_inverse=True)
        self.elements = len(used)
        records = self._element_records(scene, used)
        if style.element_store == "buffer":
            store = self._keep(TextureBuffer(ctx, records.reshape(-1, 4)))
            store_bytes = store.nbytes
        else:
            store = self._element_texture(ctx, records)
            store_bytes = store.width * store.height * 16
        ramp = self._keep(ctx.texture((256, 1), 4, colormap_lut(style.colormap).tobytes()))
        ramp.filter = (moderngl.LINEAR, moderngl.LINEAR)
        ramp.repeat_x = ramp.repeat_y = False
        self._textures = [(store, 0), (ramp, 1)]

        P = len(scene.corners)
        positions = (scene.corners - self.origin[:2]).astype(np.float32).reshape(-1, 2)
        slots = np.repeat(slot.astype(np.int32), 4)
        vbo = self._keep(ctx.buffer(positions.tobytes()))
        sbo = self._keep(ctx.buffer(slots.tobytes()))
        quad = self._is_quad(scene.corners)
        base = (np.arange(P, dtype=np.int64) * 4)[:, None]
        tris = np.concatenate([base + [0, 1, 2], (base + [0, 2, 3])[quad]]).astype(np.int32)
        self.polygons, self.triangles = P, len(tris)
        ibo = self._keep(ctx.buffer(tris.tobytes()))
        layout = [(vbo, "2f", "position"), (sbo, "1i", "slot")]
        self._vao = self._keep(ctx.vertex_array(self._program, layout, ibo, index_element_size=4))
        self._line_vao = self._skirt_vao = None
        nbytes = positions.nbytes + slots.nbytes + tris.nbytes + store_bytes
        if self._line_program is not None:
            edges = self._shared_edges(scene, quad)
            self.lines = len(edges)
            if len(edges):
                lbo = self._keep(ctx.buffer(edges.tobytes()))
                self._line_vao = self._keep(ctx.vertex_array(self._line_program, layout, lbo,
                                                             index_element_size=4))
                if self._skirt_program is not None:
                    self._skirt_vao = self._keep(ctx.vertex_array(self._skirt_program, layout, lbo,
                                                                  index_element_size=4))
                    self.skirts = len(edges)
            nbytes += edges.nbytes
        self.bytes_uploaded = nbytes

        values = self._uniform_values(scene)
        for program in self._programs():
            for name, value in values.items():
                if name in program:
                    program[name].value = value
        self.vertices, self.vertices_sent = len(positions), tris.size
        self.edges = self.lines
        self.set_camera(camera)
        self.bytes_per_step = 0

    @staticmethod
    def _shared_edges(scene: SpacetimeScene, quad: np.ndarray) -> np.ndarray:
        """(E, 2) int32 vertex pairs of the polygon edges to overdraw: all but the zero-length
        edge of a triangle and the edges the scene marks outer."""
        P = len(quad)
        keep = np.ones((P, 4), bool)
        keep[~quad, 2] = False
        if scene.outer is not None:
            keep &= ~np.asarray(scene.outer)
        k = np.arange(4)
        pairs = (np.arange(P, dtype=np.int64) * 4)[:, None, None] + np.stack([k, (k + 1) % 4], -1)
        return pairs[keep].astype(np.int32)

    def _programs(self) -> list:
        return [p for p in (self._program, self._line_program, self._skirt_program)
                if p is not None]

    def _uniform_values(self, scene: SpacetimeScene) -> dict:
        """The scene and style uniforms by name, the same for every program of the path."""
        style = self.style
        lo, hi = scene.bounds()
        return {"elements": 0, "ramp": 1,
                "lam_k": scene.lam * 1e6, "mu_k": scene.mu * 1e6,  # GPa → kJ/m³ per strain²
                "log_denominator": float(np.log1p(style.U_max)),
                "height_scale": 0.0 if scene.is_bar else float(style.height_scale),
                "light": tuple(float(v) for v in LIGHT),
                "lighting": 1.0 if (style.lighting and not scene.is_bar) else 0.0,
                "t_slice": 0.0 if scene.is_bar else float(scene.t),
                # heights are >= 0: a floor a little below 0 keeps every skirt's bottom edge
                # under the lower neighbour instead of on it
                "skirt_floor": -1e-3 * float(max(np.max(hi - lo), 1e-9))}

    def _spacetime_origin(self) -> np.ndarray:
        """The float64 point subtracted from spacetime points (x, y, t) before the float32
        upload: the drawing plane's origin is (x, y) for a slice, (x, t) for the bar."""
        o = self.origin
        return np.array([o[0], 0.0, o[1]]) if self.scene.is_bar else np.array([o[0], o[1], 0.0])

    @staticmethod
    def _is_quad(corners: np.ndarray) -> np.ndarray:
        return ~np.all(corners[:, 3] == corners[:, 2], axis=1)

    def _element_records(self, scene: SpacetimeScene, used: np.ndarray) -> np.ndarray:
        """(n, 12, 4) float32: per used element its centre relative to the upload origin (in
        float64, then cast), 1/extent and the 20 coefficient vectors, two per texel."""
        n = len(used)
        data = np.zeros((n, ELEMENT_TEXELS, 4), np.float32)
        data[:, 0, :3] = scene.centre[used] - self._spacetime_origin()
        data[:, 1, :3] = 1.0 / scene.extent[used]
        data[:, 2:, :] = scene.coeffs[used].reshape(n, 10, 4)
        return data

    def _element_texture(self, ctx, records: np.ndarray):
        """The records in a 2-D RGBA32F texture, rows of 341 elements (4092 texels)."""
        n = len(records)
        rows = -(-n // ELEMENTS_PER_ROW)
        max_size = int(ctx.info.get("GL_MAX_TEXTURE_SIZE", 16384))
        if rows > max_size:
            raise ValueError(f"{n} elements need {rows} texture rows; this renderer allows "
                             f"{max_size}")
        data = np.zeros((rows * ELEMENTS_PER_ROW, ELEMENT_TEXELS, 4), np.float32)
        data[:n] = records
        width = ELEMENTS_PER_ROW * ELEMENT_TEXELS
        texture = self._keep(ctx.texture((width, rows), 4, data.reshape(rows, width, 4).tobytes(),
                                         dtype="f4"))
        texture.filter = (moderngl.NEAREST, moderngl.NEAREST)
        return texture

    def set_step(self, step: int) -> int:
        """The scene is one slice: step 0 is the only one; nothing is uploaded."""
        self._require_prepared()
        if step != 0:
            raise ValueError(f"path {self.name!r} draws one slice (step 0), got step {step}: "
                             f"slice the spacetime mesh at another time for another scene")
        return 0

    def draw(self) -> None:
        """Draw into the bound framebuffer: the fill, then the edge lines and skirts if asked
        for."""
        ctx = self.ctx
        ctx.enable_only(moderngl.DEPTH_TEST)
        ctx.depth_func = "<="
        for texture, unit in self._textures:
            texture.use(unit)
        with self._clip_distances(2 if self._behind else 0):  # the near and far planes
            self._vao.render(moderngl.TRIANGLES)
            if self._line_vao is not None:
                self._line_vao.render(moderngl.LINES)
            if self._skirt_vao is not None:
                self._skirt_vao.render(moderngl.LINES)
        ctx.depth_func = "<"


class SpacetimeVertexPath(SpacetimePath):
    """st2005 per vertex: colour and Phong lighting at the polygon vertices, interpolated."""

    name = "spacetime_vertex"
    fixed_options = frozenset({"shading"})

    def __init__(self, style: SpacetimeStyle | None = None) -> None:
        super().__init__(replace(style or SpacetimeStyle(), shading="per_vertex"))


class SpacetimePixelPath(SpacetimePath):
    """st2005 per pixel: strain energy, colour and the exact height-field normal per fragment."""

    name = "spacetime_pixel"
    fixed_options = frozenset({"shading"})

    def __init__(self, style: SpacetimeStyle | None = None) -> None:
        super().__init__(replace(style or SpacetimeStyle(), shading="per_pixel"))


def spacetime_path(style: SpacetimeStyle | None = None) -> SpacetimePath:
    """The registered spacetime path for ``style.shading`` (default per pixel), with ``style``."""
    style = style or SpacetimeStyle()
    cls = SpacetimeVertexPath if style.shading == "per_vertex" else SpacetimePixelPath
    return cls(style)
