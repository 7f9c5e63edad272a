"""pyrender as a reference renderer: the same triangles, camera and size, drawn offscreen on EGL.

pyrender is imported lazily (with ``PYOPENGL_PLATFORM=egl`` set first) and creates its own EGL
context; every call here puts back whatever EGL context was current before (the caller's
moderngl context), so moderngl keeps working in between. Two things differ from pyrender's
own clean-up: the EGL display is never terminated (it is shared with moderngl's context on the
same device, and terminating it would break that one), and GL resources are freed only by
:meth:`PyrenderReference.release` (or when the object is collected).

Lighting. The workbench paths shade ``colour · (0.25 + 0.75 |n·l|)`` with a headlight along the
view direction and no specular term. pyrender shades physically based and gamma-encodes its
output (``linear^(1/2.2)``), so the approximation is: a white, fully rough, non-metallic,
double-sided material; vertex colours passed linearised (``c^2.2``) so that gamma returns
them unchanged; normals turned towards the light (two-sided ``|n·l|``); an ambient light of
``0.25^2.2`` so that grazing faces get 0.25 · colour as ours; and a directional light at the
camera pose, bright enough that a face turned to the camera gets exactly its colour. In
between, gamma makes pyrender brighter than ours (at n·l = 0.5: 0.745 instead of 0.625 of the
colour). With a perspective camera the paths' light sits at the eye (its direction varies
across the image), pyrender's stays parallel to the viewing axis. pyrender also draws with
4× multisampling (edges are anti-aliased).
"""

from __future__ import annotations

import ctypes
import math
import time
from typing import TYPE_CHECKING

import numpy as np

from ..gl.context import is_software_renderer, keeping_current, raw_gl
from ..measurement.timing import Timing, check_counts

if TYPE_CHECKING:
    from collections.abc import Callable

    import pyrender
    from numpy.typing import ArrayLike

    from ..gl import Camera

AMBIENT, DIFFUSE = 0.25, 0.75  # the workbench paths' lighting model
GAMMA = 2.2  # pyrender's output encoding
_F0 = 0.04  # pyrender's dielectric reflectance (also its minimum roughness)


def _headlight_intensity() -> float:
    """Directional intensity giving linear radiance 1 (with the ambient term) at n = l = v."""
    diffuse = (1.0 - _F0) * (1.0 - _F0) / math.pi  # (1 − F)·c_diff/π with a white base colour
    specular = _F0 * (1.0 / math.pi) / (4.0 + 0.001)  # F·G·D/(4 nl nv + 0.001), G = 1, D = 1/π
    return (1.0 - AMBIENT ** GAMMA) / (diffuse + specular)


def _load():
    """Import pyrender and PyOpenGL on EGL (never another platform)."""
    GL = raw_gl()
    import pyrender
    from OpenGL import EGL

    return pyrender, EGL, GL


class ReleasedReference:
    """A reference renderer holding GL resources of its own: ``with ref:`` releases them on the
    way out, and so does garbage collection (errors then ignored); subclasses define
    ``release``, harmless when done already."""

    def release(self) -> None:
        raise NotImplementedError

    def __enter__(self):
        return self

    def __exit__(self, *exc: object) -> None:
        self.release()

    def __del__(self) -> None:
        try:
            self.release()
        except Exception:  # an interpreter shutting down may have torn down EGL already
            pass


def checked_triangles(vertices: ArrayLike, triangles: ArrayLike,
                      normals: ArrayLike) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(vertices float64, triangles, normals float64) a reference renderer draws, refused
    (ValueError) where malformed: vertices not a non-empty finite (V, 3) array, triangles not a
    (K, 3) integer array of indices into them, normals not finite and shaped like the vertices,
    or of zero length."""
    vertices = np.asarray(vertices, np.float64)
    triangles = np.asarray(triangles)
    normals = np.asarray(normals, np.float64)
    if vertices.ndim != 2 or vertices.shape[1] != 3 or not len(vertices):
        raise ValueError(f"vertices must be a non-empty (V, 3) array, got {vertices.shape}")
    if not np.isfinite(vertices).all():
        raise ValueError("vertices must be finite")
    if (triangles.ndim != 2 or triangles.shape[1] != 3
            or not np.issubdtype(triangles.dtype, np.integer)):
        raise ValueError(f"triangles must be a (K, 3) integer array, got {triangles.dtype} "
                         f"{triangles.shape}")
    if len(triangles) and (triangles.min() < 0 or triangles.max() >= len(vertices)):
        raise ValueError(f"triangle indices must lie in [0, {len(vertices)})")
    if normals.shape != vertices.shape or not np.isfinite(normals).all():
        raise ValueError(f"normals must be finite and shaped like vertices {vertices.shape}, "
                         f"got {normals.shape}")
    zero = int(np.sum(np.linalg.norm(normals, axis=1) == 0.0))
    if zero:
        raise ValueError(f"{zero} vertex normals have zero length")
    return vertices, triangles, normals


def checked_size(size: tuple[int, int]) -> tuple[int, int]:
    """(width, height) as integers; ValueError where either is not positive."""
    width, height = (int(s) for s in size)
    if width <= 0 or height <= 0:
        raise ValueError(f"size must be positive, got {size}")
    return width, height


def time_frames(GL, renderer_name: str, frame: Callable[[], object],
                read: Callable[[], object], warmup: int, repeat: int) -> Timing:
    """The :class:`Timing` of a reference renderer's ``frame`` (its render with read-back, in
    the GL context current now, ``GL`` PyOpenGL's module): wall ms of ``repeat`` frames after
    ``warmup``, GPU ms from a GL_TIME_ELAPSED query around each (none on a software renderer
    ``renderer_name`` or where timer queries fail), and wall ms of ``read`` (the read-back
    alone) ``repeat`` times."""
    query = None
    if not is_software_renderer(renderer_name):
        try:
            query = int(GL.glGenQueries(1)[0])
        except Exception:  # no timer queries on this driver
            query = None
    wall, gpu, readback = [], [], []
    try:
        for i in range(warmup + repeat):
            if query is not None:
                GL.glBeginQuery(GL.GL_TIME_ELAPSED, query)
            start = time.perf_counter()
            frame()
            elapsed = (time.perf_counter() - start) * 1e3
            if query is not None:
                GL.glEndQuery(GL.GL_TIME_ELAPSED)
                ns = ctypes.c_uint64()
                GL.glGetQueryObjectui64v(query, GL.GL_QUERY_RESULT, ctypes.byref(ns))
            if i >= warmup:
                wall.append(elapsed)
                if query is not None:
                    gpu.append(ns.value / 1e6)
        for _ in range(repeat):
            start = time.perf_counter()
            read()
            readback.append((time.perf_counter() - start) * 1e3)
    finally:
        if query is not None:
            GL.glDeleteQueries(1, [query])
    return Timing.from_samples(wall, gpu if query is not None else None, readback)


def rgba_colours(colors, count: int) -> np.ndarray:
    """(count, 4) float RGBA in [0, 1] from None, one colour or per-vertex colours."""
    c = np.asarray((0.8, 0.8, 0.8) if colors is None else colors)
    if c.ndim == 1:
        c = np.broadcast_to(c, (count, c.shape[0]))
    if c.ndim != 2 or c.shape[0] != count or c.shape[1] not in (3, 4):
        raise ValueError(f"colors must be one colour (3|4,) or per vertex ({count}, 3|4), "
                         f"got shape {np.shape(colors)}")
    if np.issubdtype(c.dtype, np.integer):
        c = c / 255.0
    c = np.asarray(c, np.float64)
    if not np.all((c >= 0.0) & (c <= 1.0)):
        raise ValueError("float colours must lie in [0, 1] (integer colours in [0, 255])")
    if c.shape[1] == 3:
        c = np.c_[c, np.ones(count)]
    return c


class PyrenderReference(ReleasedReference):
    """The triangles ``(vertices, triangles, normals)`` drawn by pyrender through our ``camera``.

    ``vertices``: (V, 3) float64 model coordinates, uploaded relative to ``camera.origin``;
    ``triangles``: (K, 3) vertex indices; ``normals``: (V, 3) smooth vertex normals (any
    length but zero); ``colors``: (V, 3|4) per-vertex colours or one RGB(A) colour, or instead
    ``base_color``: one colour (neither: light grey); floats in [0, 1] or integers in [0, 255];
    ``size`` = (width, height) pixels;
    ``background``: the clear colour, floats in [0, 1]. No face culling. The lighting is an
    approximation of the workbench's (see the module notes). Refuses malformed arrays,
    out-of-range indices, non-finite coordinates, zero normals and a non-positive size.
    """

    name = "pyrender"

    def __init__(self, vertices: ArrayLike, triangles: ArrayLike, normals: ArrayLike,
                 camera: Camera, size: tuple[int, int], *, colors: ArrayLike | None = None,
                 base_color: ArrayLike | None = None,
                 background: tuple[float, float, float, float] = (1.0, 1.0, 1.0, 1.0)) -> None:
        if colors is not None and base_color is not None:
            raise ValueError("give per-vertex colors or one base_color, not both")
        vertices, triangles, normals = checked_triangles(vertices, triangles, normals)
        width, height = checked_size(size)
        bg = np.asarray(background, np.float64)
        if bg.shape != (4,) or not np.all((bg >= 0) & (bg <= 1)):
            raise ValueError(f"background must be 4 floats in [0, 1], got {background!r}")

        pyrender, self._EGL, self._GL = _load()
        self.camera, self.size = camera, (width, height)
        self.triangles, self.vertices = len(triangles), len(vertices)

        # two-sided headlight: turn every normal towards the light (the viewer)
        towards_viewer = np.asarray(camera.eye, np.float64) - np.asarray(camera.target, np.float64)
        towards_viewer /= np.linalg.norm(towards_viewer)
        normals = normals / np.linalg.norm(normals, axis=1)[:, None]
        normals[normals @ towards_viewer < 0.0] *= -1.0
        rgba = rgba_colours(base_color if colors is None else colors, len(vertices))
        linear = np.c_[rgba[:, :3] ** GAMMA, rgba[:, 3]]

        positions = camera.relative(vertices)
        indices = triangles.astype(np.uint32)
        material = pyrender.MetallicRoughnessMaterial(
            baseColorFactor=[1.0, 1.0, 1.0, 1.0], metallicFactor=0.0, roughnessFactor=1.0,
            doubleSided=True)
        primitive = pyrender.Primitive(positions=positions, normals=normals.astype(np.float32),
                                       color_0=linear.astype(np.float32), indices=indices,
                                       material=material, mode=pyrender.GLTF.TRIANGLES)
        self.bytes_uploaded = int(positions.nbytes + 12 * len(normals) + 16 * len(linear)
                                  + indices.nbytes)
        scene = pyrender.Scene(bg_color=bg, ambient_light=np.full(3, AMBIENT ** GAMMA))
        scene.add(pyrender.Mesh(primitives=[primitive]))
        pose = np.linalg.inv(camera.view_matrix())
        scene.add(self.pyrender_camera(camera), pose=pose)
        scene.add(pyrender.DirectionalLight(color=np.ones(3), intensity=_headlight_intensity()),
                  pose=pose)
        self._scene = scene
        self._flags = pyrender.RenderFlags.RGBA
        self._offscreen_flags = pyrender.RenderFlags.RGBA | pyrender.RenderFlags.OFFSCREEN
        with keeping_current() as restore:
            self._offscreen = pyrender.OffscreenRenderer(width, height)
            # pyrender's own delete() terminates the EGL display shared with moderngl
            self._offscreen.delete = lambda: None
            self._platform = self._offscreen._platform
            restore.display = self._restore_display = self._platform._egl_display
            self.renderer_name = self._GL.glGetString(self._GL.GL_RENDERER).decode()

    @staticmethod
    def pyrender_camera(camera: Camera) -> pyrender.Camera:
        """The pyrender camera with ``camera``'s projection (same matrix, see the tests)."""
        pyrender, _, _ = _load()
        if camera.projection == "orthographic":
            return pyrender.OrthographicCamera(xmag=camera.half_height * camera.aspect,
                                               ymag=camera.half_height, znear=camera.near,
                                               zfar=camera.far)
        return pyrender.PerspectiveCamera(yfov=math.radians(camera.fov_deg), znear=camera.near,
                                          zfar=camera.far, aspectRatio=camera.aspect)

    def _check_alive(self) -> None:
        if getattr(self, "_offscreen", None) is None:
            raise RuntimeError("this pyrender reference has been released")

    def render(self) -> np.ndarray:
        """(H, W, 4) uint8 RGBA, row 0 at the top; the caller's EGL context stays current."""
        self._check_alive()
        with keeping_current(self._restore_display):
            color, _depth = self._offscreen.render(self._scene, flags=self._flags)
        return np.array(color, np.uint8)

    def time(self, warmup: int = 2, repeat: int = 7) -> Timing:
        """Time pyrender's ``render`` (ms): wall time including its MSAA resolve and read-back
        (colour and depth), GPU time from a GL_TIME_ELAPSED query around the same call (None
        where timer queries fail), and read-back (resolve + colour and depth read) alone.
        Refuses ``repeat`` < 5 and a negative ``warmup``."""
        check_counts(warmup, repeat)
        self._check_alive()
        renderer = self._offscreen._renderer
        with keeping_current(self._restore_display):
            self._platform.make_current()
            return time_frames(
                self._GL, self.renderer_name,
                lambda: self._offscreen.render(self._scene, flags=self._flags),
                lambda: renderer._read_main_framebuffer(self._scene, self._offscreen_flags),
                warmup, repeat)

    def release(self) -> None:
        """Free pyrender's GL resources and its EGL context (not the shared display)."""
        offscreen = getattr(self, "_offscreen", None)
        if offscreen is None:
            return
        self._offscreen = None
        EGL, platform = self._EGL, self._platform
        renderer = offscreen._renderer
        with keeping_current(self._restore_display):
            platform.make_current()
            renderer.delete()
        EGL.eglDestroyContext(platform._egl_display, platform._egl_context)
        # pyrender's finalizers would delete GL names again in whichever context is current,
        # and terminate the shared display: make them no-ops
        renderer.delete = lambda: None
        platform._egl_context = platform._egl_display = None
        offscreen._renderer = offscreen._platform = None
