"""The exploded-view path (ghost2013): an object of interest revealed inside its assembly.

The focus part (``ExplodeStyle.focus``) stays in place and is drawn once, in ``focus_color``.
Every other part is drawn twice, cut by a split plane through the focus: once keeping the
+normal side translated by ``+offset·n`` and once keeping the −normal side translated by
``−offset·n``. The cut is a clip distance against the plane in the vertex shader (after the
style's own clip planes), on the untranslated position, with the plane moved to the upload
origin in float64 as every path does; shading is the flat path's derivative face normal.

The half in front of the focus (:func:`workbench.algo.explode.front_sign`) is drawn last. With
an opacity ``alpha < 1`` it is blended over the rest (``SRC_ALPHA, ONE_MINUS_SRC_ALPHA``) and
its back faces are culled where :func:`~workbench.algo.explode.cull_back_faces` allows it (not
when the eye lies between the original and the translated plane).

Beyond ``draw`` the path offers what the paper's interaction needs:

* :meth:`ExplodedPath.measure_occlusion` — two ``GL_SAMPLES_PASSED`` queries in an internal
  framebuffer of the bound viewport's size: the focus alone into a cleared depth buffer
  (``p_unocc``) and the focus after both halves (``p_occ``). Each query draws the focus a second
  time with ``depth ≤`` over a depth-only pre-pass of the same geometry, so a count is the number
  of pixels where the focus is the nearest surface (no overdraw of its own back faces). The
  focus never moves, so ``p_unocc`` is counted once per camera, step and image size and kept.
  Returns ``(p_unocc, p_occ, gpu_ms)``; ``last_occlusion`` holds the counts, the GPU (None
  on a software renderer) and wall times, whether ``p_unocc`` was counted anew and whether
  ``p_occ`` came from the frame.
* **Counting in the frame** (the thesis's "during the actual rendering"). With
  ``count_in_draw`` on (the default), :meth:`ExplodedPath.draw` ends with the same ``depth ≤``
  count of the focus over the frame it has just drawn, colour and depth writes off: that is
  ``p_occ`` for the frame's offset at the cost of one more draw of the focus alone. A blended
  front half writes depth like an opaque one, so a ghosted frame counts the same; where its
  back faces were culled they are first drawn into the depth buffer alone (the frame's depth
  buffer then holds the halves as the separate pass sees them). The result is read only by the
  next :meth:`step_animation`. A multisampled framebuffer (samples, not pixels) is counted by
  the separate pass instead.
* :meth:`ExplodedPath.step_animation` — ``r = (p_unocc − p_occ)/p_unocc`` (0 when the focus is
  off screen) from the last frame's count when that frame was drawn at the current state (the
  separate pass otherwise), then :func:`~workbench.algo.explode.next_state`; the offset and the
  ghosting opacity (:func:`~workbench.algo.explode.ghost_alpha`) follow the new state. A new
  camera or offset releases a held explosion (:func:`~workbench.algo.explode.release`).
* :meth:`ExplodedPath.pick` — colour picking: every part drawn with a second program writing
  its code (index in the sorted part ids + 1, 24 bits in RGB) with the geometry, offsets,
  clipping and culling of the drawn image, blending off, into the internal framebuffer; one
  pixel is read back. A pixel where a translated half now lies returns that half's part.

Triangles are uploaded once, sorted by part with the focus first, so the focus, the other parts
and each single part (for picking) are contiguous ranges of one index buffer.

Refused with ValueError (one line): a plane spec other than "auto", "x", "y", "z" or three
finite numbers "a,b,c" with a non-zero normal, a negative or non-finite offset, an opacity
outside (0, 1], speed / dt / o_max not positive, strips or a wire frame (not drawn by this
path); at prepare, an unset (empty) focus, a focus part the mesh does not have (listing its
part ids), a focus without a drawable triangle, and a focus that is the whole mesh.
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import moderngl
import numpy as np

from ..gl import Framebuffer, GpuTimer, SamplesPassed, load_program, write_masks
from .drawdata import Layout, Topology
from .mesh import MeshPath
from .style import Style

if TYPE_CHECKING:
    from ..algo.explode import ExplodeSettings
    from ..gl.camera import Camera
    from ..scene.mesh import FEMesh
    from .colormap import ColorScale

AXES = ("x", "y", "z")
NO_PART = np.iinfo(np.int64).min  # what id_image() holds where no part was drawn


def _explode():
    """The GL-free dynamics (imported on use, so the registry loads without it)."""
    from ..algo import explode

    return explode


def parse_plane(spec: str | Sequence[float] | np.ndarray) -> str | tuple[float, float, float]:
    """``"auto"``, an axis name, or a (a, b, c) normal from ``"a,b,c"`` or a 3-sequence;
    ValueError for anything else."""
    if isinstance(spec, str):
        text = spec.strip().lower()
        if text == "auto" or text in AXES:
            return text
        parts = text.split(",")
    else:
        parts = list(spec) if isinstance(spec, (tuple, list, np.ndarray)) else [spec]
    try:
        normal = tuple(float(v) for v in parts)
    except (TypeError, ValueError):
        normal = ()
    if len(normal) != 3 or not all(math.isfinite(v) for v in normal) or \
            not any(v != 0.0 for v in normal):
        raise ValueError(f"plane must be 'auto', 'x', 'y', 'z' or a normal 'a,b,c' of three "
                         f"finite numbers, not all zero; got {spec!r}")
    return normal


@dataclass
class ExplodeStyle(Style):
    """:class:`Style` plus the exploded view: ``focus`` (the part id kept in place), ``plane``
    ("auto", "x", "y", "z" or a normal "a,b,c" through the focus), ``offset`` (model units, each
    half's distance from the plane), ``alpha`` (opacity of the front half), ``focus_color``,
    and the animation settings ``o_max`` (model units; None: the mesh's diameter by
    ``o_max_of``), ``speed`` (s_u), ``dt``, ``ghost_start`` (share of o_max where ghosting
    starts), ``ratio_exponent`` (p in the growth speed s_u·Δoffset·r^p; 1 is the thesis,
    default 0.5) and ``reject_deg`` (the automatic plane's limit on normal·view)."""

    focus: int | None = None
    plane: str = "auto"
    offset: float = 0.0
    alpha: float = 1.0
    focus_color: tuple = (0.95, 0.5, 0.1)
    o_max: float | None = None
    speed: float = 1.0
    dt: float = 0.1
    ghost_start: float = 0.7
    ratio_exponent: float = 0.5
    reject_deg: float = 20.0

    def __post_init__(self) -> None:
        plane = parse_plane(self.plane)
        self.plane = plane if isinstance(plane, str) else ",".join(f"{v:g}" for v in plane)
        if self.focus is not None:
            if isinstance(self.focus, bool) or int(self.focus) != self.focus:
                raise ValueError(f"focus must be a part id (an integer), got {self.focus!r}")
            self.focus = int(self.focus)
        self.offset = float(self.offset)
        if not (math.isfinite(self.offset) and self.offset >= 0.0):
            raise ValueError(f"offset must be a finite distance >= 0, got {self.offset}")
        self.alpha = float(self.alpha)
        if not 0.0 < self.alpha <= 1.0:
            raise ValueError(f"alpha must be in (0, 1], got {self.alpha}")
        for name in ("speed", "dt") + (("o_max",) if self.o_max is not None else ()):
            value = float(getattr(self, name))
            if not (math.isfinite(value) and value > 0):
                raise ValueError(f"{name} must be positive and finite, got {getattr(self, name)}")
            setattr(self, name, value)
        self.animation_settings(1.0 if self.o_max is None else self.o_max)  # checks the rest
        if self.strips != "none" or self.quad_diagonal == "strip":
            raise ValueError("the exploded path draws a triangle list: strips='none' and "
                             "quad_diagonal 'auto' or 'shorter'")
        if self.wireframe:
            raise ValueError("the exploded path draws no wire frame")
        color = tuple(float(c) for c in self.focus_color)
        if len(color) != 3 or not all(0.0 <= c <= 1.0 for c in color):
            raise ValueError(f"focus_color must be 3 numbers in [0, 1], got {self.focus_color}")
        self.focus_color = color
        super().__post_init__()

    def animation_settings(self, o_max: float) -> ExplodeSettings:
        """The dynamics' :class:`~workbench.algo.explode.ExplodeSettings` for ``o_max`` (model
        units): ``speed``, ``dt``, ``ghost_start`` and ``ratio_exponent``, checked there."""
        return _explode().ExplodeSettings(o_max=o_max, speed=self.speed, dt=self.dt,
                                          ghost_start=self.ghost_start,
                                          ratio_exponent=self.ratio_exponent)


class ExplodedPath(MeshPath):
    """The focus in place, the other parts split by a plane and moved apart (flat shading)."""

    name = "exploded"
    needs = frozenset({"triangles"})
    style_class = ExplodeStyle
    vertex_shader, fragment_shader = "exploded.vert.glsl", "exploded.frag.glsl"
    pick_shader = "exploded_pick.frag.glsl"
    style: ExplodeStyle

    def __init__(self, style: ExplodeStyle | None = None) -> None:
        super().__init__(style)
        self._pick_program = self._pick_vao = None
        self._scratch: Framebuffer | None = None
        self.offset, self.alpha = self.style.offset, self.style.alpha
        self.last_r: float | None = None
        self.last_occlusion: dict = {}
        self.count_in_draw = True
        self._frame_count: dict | None = None
        self.state = None  # the animation state, from prepare on

    # ------------------------------------------------------------------ prepare
    def check_mesh(self, mesh: FEMesh) -> ColorScale | None:
        """Refuse as :class:`MeshPath` does, and a focus the mesh cannot show (see the module
        docstring)."""
        scale = super().check_mesh(mesh)
        focus = self.style.focus
        ids = sorted(int(p) for p in np.unique(mesh.parts))
        if focus is None:
            raise ValueError(f"the exploded path needs a focus part (empty focus); "
                             f"{mesh.name} has part ids {ids}")
        if focus not in ids:
            raise ValueError(f"{mesh.name} has no part {focus}; part ids: {ids}")
        if len(ids) == 1:
            raise ValueError(f"focus part {focus} is the whole of {mesh.name}: nothing is left "
                             f"to split around it")
        element_of = mesh.triangulation.element_of
        if not (mesh.parts[element_of] == focus).any():
            raise ValueError(f"focus part {focus} of {mesh.name} is empty: it has no "
                             f"drawable triangle")
        return scale

    def layout(self, mesh: FEMesh, topology: Topology) -> Layout:
        """The triangle list sorted by part, the focus first; records each part's range."""
        layout = super().layout(mesh, topology)  # a triangle list (style checked)
        part = mesh.parts[mesh.triangulation.element_of].astype(np.int64)
        focus = self.style.focus
        order = np.lexsort((part, part != focus))
        part = part[order]
        self.part_ids = np.unique(part)  # sorted; code of part_ids[i] is i + 1
        ids, first, count = np.unique(part, return_index=True, return_counts=True)
        self._part_ranges = {int(p): (int(f), int(c)) for p, f, c in zip(ids, first, count)}
        n_focus = int((part == focus).sum())
        self._focus_range = (0, n_focus)
        self._rest_range = (n_focus, len(part) - n_focus)
        element = None if layout.triangle_element is None else layout.triangle_element[order]
        return Layout(layout.index[order], layout.primitive, layout.triangles, layout.strips,
                      layout.vertices_sent, triangle_element=element)

    def _build(self, ctx, mesh, camera) -> None:
        algo = _explode()
        style = self.style
        if style.deleted == "ghost" and mesh.erodes:
            raise ValueError("the exploded path hides deleted elements; deleted='ghost' is "
                             "drawn by the mesh paths (flat, gouraud, ...)")
        points = mesh.coordinates(style.step)
        in_focus = mesh.parts == style.focus
        self._focus_points = points[np.unique(mesh.elements[in_focus])]
        self._rest_points = points[np.unique(mesh.elements[~in_focus])]
        self._plane_spec = parse_plane(style.plane)
        self._choose_plane(camera)
        o_max = style.o_max if style.o_max is not None else float(algo.o_max_of(mesh))
        self.settings = style.animation_settings(o_max)
        self.state = algo.ExplodeState(offset=style.offset)
        self.offset, self.alpha = style.offset, style.alpha
        super()._build(ctx, mesh, camera)
        self._pick_program = self._keep(load_program(
            ctx, self.vertex_shader, self.pick_shader,
            defines={"NUM_CLIP": len(style.clip_planes)}))
        self._pick_vao = self._keep(ctx.vertex_array(
            self._pick_program, [(self._positions, "3f", "position")], self._index,
            index_element_size=4))
        self._set_clip_planes()
        self._alone, self._behind, self._in_frame = (SamplesPassed(ctx), SamplesPassed(ctx),
                                                     SamplesPassed(ctx))
        self._timer = GpuTimer(ctx)
        self.set_camera(camera)

    def _choose_plane(self, camera) -> None:
        """The split plane: the style's manual one, or the automatic one for ``camera``'s view
        direction (chosen again whenever the camera changes, as the view decides it)."""
        algo = _explode()
        if self._plane_spec == "auto":
            view_dir = np.asarray(camera.target, np.float64) - np.asarray(camera.eye, np.float64)
            self.plane = algo.auto_plane(self._focus_points, self._rest_points, view_dir,
                                         reject_deg=self.style.reject_deg)
        else:
            self.plane = algo.manual_plane(self._plane_spec, self._focus_points)
        normal = np.asarray(self.plane.normal, np.float64)
        self.normal = normal / np.linalg.norm(normal)
        self.plane_point = np.asarray(self.plane.point, np.float64)

    def _upload_plane(self) -> None:
        # the plane through the upload origin, in float64 before the float32 cast
        d = -float(self.normal @ self.plane_point) + float(self.normal @ self.origin)
        for program in self._programs():
            program["split_plane"].value = (*(float(v) for v in self.normal), d)

    def _programs(self) -> list:
        return [p for p in (self._program, self._pick_program) if p is not None]

    def set_camera(self, camera: Camera) -> None:
        super().set_camera(camera)
        if self._plane_spec == "auto":
            self._choose_plane(camera)
        self._upload_plane()
        # p_unocc per image size, for this camera and step
        self._unoccluded: dict[tuple[tuple[int, ...], int | None], int] = {}
        self._frame_count = None
        if self.state is not None:  # a new view: a held explosion may shrink again
            self.state = _explode().release(self.state)
        eye = self.origin + np.asarray(camera.eye, np.float64)  # world space, float64
        if camera.projection == "orthographic":  # parallel rays: an eye far back along them
            view = np.asarray(camera.target, np.float64) - np.asarray(camera.eye, np.float64)
            view /= np.linalg.norm(view)
            eye = self.plane_point - 1e6 * self.settings.o_max * view
        self.eye = eye

    # ------------------------------------------------------------------ state
    def set_offset(self, offset: float, alpha: float = 1.0) -> None:
        """Draw with each half ``offset`` model units from the plane, the front one at ``alpha``."""
        offset, alpha = float(offset), float(alpha)
        if not (math.isfinite(offset) and offset >= 0.0):
            raise ValueError(f"offset must be a finite distance >= 0, got {offset}")
        if not 0.0 < alpha <= 1.0:
            raise ValueError(f"alpha must be in (0, 1], got {alpha}")
        self.offset, self.alpha = offset, alpha
        self._frame_count = None
        if self.state is not None:
            self.state = _explode().release(
                _explode().ExplodeState(offset=offset, frame=self.state.frame))

    def front_side(self) -> int:
        """+1 if the half moved along +normal is in front of the focus, else −1."""
        sign = _explode().front_sign(self.plane, self.offset, self.eye)
        return 1 if sign >= 0 else -1

    # ------------------------------------------------------------------ drawing
    def _range(self, vao, start_count) -> None:
        start, count = start_count
        if count:
            vao.render(moderngl.TRIANGLES, vertices=3 * count, first=3 * start)

    def _half(self, program, side: int) -> None:
        """Uniforms of one half (side ±1) or of the focus (side 0)."""
        program["translate"].value = tuple(float(v) for v in side * self.offset * self.normal)
        program["split_side"].value = float(side)

    def _cull(self, side: int) -> bool:
        return bool(_explode().cull_back_faces(self.plane, self.offset, self.eye, side))

    def _pass(self, program, vao, focus: bool = True, halves: bool = True,
              per_part: bool = False) -> None:
        """The focus, then the back half, then the front half (blended at ``alpha`` < 1, back
        faces culled where allowed); ``per_part`` sets the pick code of each part's range."""
        ctx = self.ctx
        ctx.provoking_vertex = moderngl.LAST_VERTEX_CONVENTION
        ctx.enable_only(moderngl.DEPTH_TEST)
        front = self.front_side() if halves else 1
        with self._clip_distances(len(self.style.clip_planes) + 1):
            if focus:
                self._half(program, 0)
                if per_part:
                    self._draw_parts(program, vao, [self.style.focus])
                else:
                    program["base_color"].value = self.style.focus_color
                    program["alpha"].value = 1.0
                    self._range(vao, self._focus_range)
            if not halves:
                return
            for side in (-front, front):
                ghost = side == front and self.alpha < 1.0
                flags = moderngl.DEPTH_TEST
                if ghost and not per_part:
                    flags |= moderngl.BLEND
                    ctx.blend_func = moderngl.SRC_ALPHA, moderngl.ONE_MINUS_SRC_ALPHA
                if ghost and self._cull(side):
                    flags |= moderngl.CULL_FACE
                    ctx.front_face, ctx.cull_face = "ccw", "back"
                ctx.enable_only(flags)
                self._half(program, side)
                if per_part:
                    self._draw_parts(program, vao, [p for p in self._part_ranges
                                                    if p != self.style.focus])
                else:
                    program["base_color"].value = self.style.base_color
                    program["alpha"].value = self.alpha if ghost else 1.0
                    self._range(vao, self._rest_range)
        ctx.enable_only(moderngl.DEPTH_TEST)

    def _draw_parts(self, program, vao, parts) -> None:
        for part in parts:
            code = int(np.searchsorted(self.part_ids, part)) + 1
            program["pick_color"].value = tuple(((code >> s) & 255) / 255.0 for s in (0, 8, 16))
            self._range(vao, self._part_ranges[part])

    def draw(self) -> None:
        self._require_prepared()
        self._pass(self._program, self._vao)
        self._frame_count = self._count_in_frame() if self.count_in_draw else None

    def _count_in_frame(self) -> dict | None:
        """Issue the in-frame ``p_occ`` query over what :meth:`draw` just drew (see the module
        docstring); None in a multisampled framebuffer."""
        ctx = self.ctx
        fbo = ctx.fbo
        attachments = list(fbo.color_attachments) + [fbo.depth_attachment]
        if any(getattr(a, "samples", 0) for a in attachments if a):
            return None
        program, vao = self._program, self._vao
        front = self.front_side()
        with write_masks(ctx, color=False, depth=True):
            if self.alpha < 1.0 and self._cull(front):  # depth of the culled back faces
                ctx.provoking_vertex = moderngl.LAST_VERTEX_CONVENTION
                with self._clip_distances(len(self.style.clip_planes) + 1):
                    ctx.enable_only(moderngl.DEPTH_TEST | moderngl.CULL_FACE)
                    ctx.front_face, ctx.cull_face = "ccw", "front"
                    self._half(program, front)
                    self._range(vao, self._rest_range)
                ctx.enable_only(moderngl.DEPTH_TEST)
                ctx.cull_face = "back"
            with write_masks(ctx, color=False, depth=False):
                ctx.depth_func = "<="
                try:
                    with self._in_frame:
                        self._pass(program, vao, halves=False)
                finally:
                    ctx.depth_func = "<"
        size = tuple(int(v) for v in ctx.viewport[2:])
        return dict(key=(size, getattr(self, "step", None)), offset=self.offset)

    def draw_focus(self) -> None:
        """The focus part alone, as :meth:`draw` shows it."""
        self._require_prepared()
        self._pass(self._program, self._vao, halves=False)

    def draw_halves(self) -> None:
        """The two halves without the focus, as :meth:`draw` shows them."""
        self._require_prepared()
        self._pass(self._program, self._vao, focus=False)

    # ------------------------------------------------------------------ offscreen work
    def _target(self, size=None) -> Framebuffer:
        """The internal framebuffer, of ``size`` or of the bound viewport's size."""
        if size is None:
            size = tuple(self.ctx.viewport[2:]) or tuple(self.ctx.fbo.size)
        size = tuple(int(v) for v in size)
        if self._scratch is None or self._scratch.size != size:
            if self._scratch is not None:
                self._scratch.release()
            self._scratch = Framebuffer(self.ctx, size)
        return self._scratch

    def _restore(self, fbo, viewport) -> None:
        fbo.use()
        self.ctx.viewport = viewport

    def _count(self, fb: Framebuffer, query, halves: bool) -> None:
        """One counting pass into ``fb`` (bound, colour writes off): the focus's
        nearest-surface pixels, after both halves (opaque: ghosting does not count as
        revealing) when ``halves``."""
        ctx, program, vao = self.ctx, self._program, self._vao
        fb.fbo.clear(depth=1.0)
        ctx.depth_func = "<"
        if halves:
            alpha, self.alpha = self.alpha, 1.0
            try:
                self._pass(program, vao, focus=False)
            finally:
                self.alpha = alpha
        self._pass(program, vao, halves=False)  # depth of the focus
        with write_masks(ctx, color=False, depth=False):
            ctx.depth_func = "<="
            try:
                with query:
                    self._pass(program, vao, halves=False)
            finally:
                ctx.depth_func = "<"

    def _counted(self, size, behind: bool) -> tuple[int | None, int | None, dict]:
        """(p_unocc, p_occ, times): p_unocc from the cache or counted, p_occ counted when
        ``behind`` (else None), in the internal framebuffer of ``size``."""
        ctx = self.ctx
        previous, viewport = ctx.fbo, ctx.viewport
        fb = self._target(size)
        key = (fb.size, getattr(self, "step", None))
        counted = key not in self._unoccluded
        start = time.perf_counter()
        try:
            fb.use()
            with write_masks(ctx, color=False, depth=True), self._timer:
                if counted:
                    self._count(fb, self._alone, halves=False)
                if behind:
                    self._count(fb, self._behind, halves=True)
            if counted:
                self._unoccluded[key] = self._alone.samples
            p_occ = self._behind.samples if behind else None
            gpu_ms = self._timer.elapsed_ms
        finally:
            self._restore(previous, viewport)
        wall_ms = (time.perf_counter() - start) * 1e3
        return self._unoccluded[key], p_occ, dict(gpu_ms=gpu_ms, wall_ms=wall_ms,
                                                  unoccluded_counted=counted)

    def measure_occlusion(self, size: tuple[int, int] | None = None) -> tuple[int, int, float]:
        """(p_unocc, p_occ, gpu_ms): the focus's visible pixels drawn alone and drawn after both
        halves, counted by occlusion queries in the internal framebuffer (``size``, default the
        bound viewport's); the previously bound framebuffer and viewport are restored."""
        self._require_prepared()
        p_unocc, p_occ, times = self._counted(size, behind=True)
        self.last_occlusion = dict(p_unocc=p_unocc, p_occ=p_occ, in_frame=False, **times)
        return p_unocc, p_occ, times["gpu_ms"]

    def _frame_occlusion(self, size) -> tuple[int, int] | None:
        """(p_unocc, p_occ) from the last frame's own count, None where there is none for the
        current state and ``size``."""
        frame, self._frame_count = self._frame_count, None
        if frame is None or frame["offset"] != self.offset:
            return None
        frame_size, step = frame["key"]
        if step != getattr(self, "step", None) or (size is not None and
                                                    tuple(int(v) for v in size) != frame_size):
            return None
        start = time.perf_counter()
        p_occ = self._in_frame.samples
        counted = frame["key"] not in self._unoccluded
        gpu_ms = (self._counted(frame_size, behind=False)[2]["gpu_ms"] if counted
                  else 0.0 if self._timer.meaningful else None)
        p_unocc = self._unoccluded[frame["key"]]
        wall_ms = (time.perf_counter() - start) * 1e3
        self.last_occlusion = dict(p_unocc=p_unocc, p_occ=p_occ, in_frame=True, gpu_ms=gpu_ms,
                                   wall_ms=wall_ms, unoccluded_counted=counted)
        return p_unocc, p_occ

    def occlusion_ratio(self, size: tuple[int, int] | None = None) -> float:
        """r = (p_unocc − p_occ)/p_unocc: 1 hidden, 0 revealed (0 as well when off screen)."""
        return _explode().occlusion_ratio(*self.measure_occlusion(size)[:2])

    def step_animation(self, settings: ExplodeSettings | None = None,
                       size: tuple[int, int] | None = None) -> float:
        """One frame of the dynamics: r at the current offset (from the last frame's own count
        when :meth:`draw` drew the current state, else measured by :meth:`measure_occlusion`),
        advance the state with ``next_state`` (``settings`` default the style's), take its
        offset and the ghosting opacity ``ghost_alpha``; returns r."""
        self._require_prepared()
        algo = _explode()
        settings = self.settings if settings is None else settings
        counts = self._frame_occlusion(size)
        if counts is None:
            counts = self.measure_occlusion(size)[:2]
        r = algo.occlusion_ratio(*counts)
        self.state = algo.next_state(self.state, r, settings)
        self.offset = float(self.state.offset)
        self.alpha = float(algo.ghost_alpha(self.offset, settings, r))
        self.last_r = r
        return r

    def id_image(self, size: tuple[int, int] | None = None) -> np.ndarray:
        """(H, W) int64 part ids as picking sees them (row 0 at the top), ``NO_PART`` where
        nothing is drawn."""
        fb = self._draw_ids(size)
        codes = fb.read()[..., :3].astype(np.int64)
        code = codes[..., 0] | codes[..., 1] << 8 | codes[..., 2] << 16
        ids = np.full(code.shape, NO_PART, np.int64)
        hit = (code > 0) & (code <= len(self.part_ids))
        ids[hit] = self.part_ids[code[hit] - 1]
        return ids

    def _draw_ids(self, size=None) -> Framebuffer:
        ctx = self.ctx
        previous, viewport = ctx.fbo, ctx.viewport
        fb = self._target(size)
        try:
            fb.use()
            fb.fbo.clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
            self._pass(self._pick_program, self._pick_vao, per_part=True)
        finally:
            self._restore(previous, viewport)
        return fb

    def pick(self, x: int, y: int, size: tuple[int, int] | None = None) -> int | None:
        """The part id drawn at pixel column ``x``, row ``y`` (row 0 at the top) of the current
        image (``size`` default the bound viewport's), None where nothing is drawn."""
        self._require_prepared()
        fb = self._draw_ids(size)
        width, height = fb.size
        if not (0 <= x < width and 0 <= y < height):
            raise ValueError(f"pixel ({x}, {y}) lies outside the {width}x{height} image")
        data = fb.fbo.read(viewport=(int(x), height - 1 - int(y), 1, 1), components=4,
                           alignment=1)
        r, g, b = data[0], data[1], data[2]
        code = r | g << 8 | b << 16
        if code == 0 or code > len(self.part_ids):
            return None
        return int(self.part_ids[code - 1])

    def release(self) -> None:
        if self._scratch is not None:
            self._scratch.release()
            self._scratch = None
        super().release()
        self._pick_program = self._pick_vao = None


def exploded_camera(camera: Camera, mesh: FEMesh, o_max: float | None = None) -> Camera:
    """``camera`` with its depth range widened by 2·``o_max`` (default the assembly's
    :func:`~workbench.algo.explode.o_max_of`) on both sides. A camera fitted to the assembly
    encloses the unexploded parts only: a half moved toward or away from the viewer would be
    cut by the near or far plane, and a half clipped away would count as revealing the object.
    A perspective camera's near plane moves toward the eye but stays in front of it."""
    from dataclasses import replace

    extra = 2.0 * (float(o_max) if o_max is not None else _explode().o_max_of(mesh))
    near = camera.near - extra
    if camera.projection == "perspective":
        near = max(near, 1e-3 * camera.near)
    return replace(camera, near=near, far=camera.far + extra)

