"""pyvista/VTK as a reference renderer: the same triangles, camera and size, drawn offscreen on EGL.

VTK draws through its own EGL render window class (``vtkEGLRenderWindow``, chosen explicitly, so
nothing tries X first), offscreen, in an EGL context made here and handed to the window as one
it does not own: on the EGL display of the caller's current context (the same device), or of
EGL device ``device`` where one is asked for or none is current. A window that owns its
context terminates its EGL display when it is destroyed, and the display is shared with
moderngl's context on the same device: terminating it would break that one. Every call puts
back the EGL context that was current before, so moderngl keeps working in between; every VTK
object is freed with VTK's context current, so that VTK never deletes GL names in the caller's
context.

Lighting. The workbench paths shade ``colour · (0.25 + 0.75 |n·l|)`` with a headlight and no
specular term, evaluated per vertex and interpolated. VTK is given one headlight of intensity 1
(no light kit, no automatic light), ambient 0.25, diffuse 0.75, specular 0, the base colour as
ambient and diffuse colour, and its own two-sided lighting: so its colour is
``colour · (0.25 + 0.75 max(0, n·l))``, where VTK flips the interpolated, renormalised normal
of a fragment on a back-facing triangle (by winding) and evaluates per pixel. It differs from
ours where a vertex normal points away from the viewer on a triangle facing it (on silhouettes;
VTK: ambient only, ours: ``|n·l|``) and, slightly, wherever lighting per pixel differs from
lighting interpolated from the vertices. With an orthographic camera the light is directional
along the view (as ours); with a perspective one it is a point light at the eye (VTK's
positional headlight with a 180° cone and no attenuation), as ours. No face culling; no gamma.
The window draws with ``samples`` × multisampling (default 4, as pyrender, so that it compares
with our 4× MSAA Gouraud image); 0 turns it off.
"""

from __future__ import annotations

import ctypes
from typing import TYPE_CHECKING

import numpy as np

from ..gl.context import egl, keeping_current, raw_gl
from ..measurement.timing import Timing, check_counts
from .pyrender import (
    AMBIENT,
    DIFFUSE,
    ReleasedReference,
    checked_size,
    checked_triangles,
    rgba_colours,
    time_frames,
)

if TYPE_CHECKING:
    from numpy.typing import ArrayLike

    from ..gl import Camera

LIGHTING = ("VTK headlight, ambient 0.25, diffuse 0.75, no specular, VTK's own two-sided "
            "lighting: max(0, n.l) per pixel, the normal flipped on back-facing triangles "
            "(ours: |n.l| per vertex, interpolated)")
EGL_PLATFORM_DEVICE_EXT = 0x313F
PBUFFER_SIZE = 16  # the context's own surface: VTK draws into framebuffer objects of its own


def versions() -> str:
    """"VTK <version>, pyvista <version>": the libraries this reference draws with."""
    import pyvista
    from vtkmodules.vtkCommonCore import vtkVersion

    return f"VTK {vtkVersion.GetVTKVersion()}, pyvista {pyvista.__version__}"


def _device_display(EGL, device: int | None):
    """The initialised EGL display of EGL device ``device`` (None: ``WORKBENCH_EGL_DEVICE`` or
    0). The display is never terminated: other contexts on the device share it."""
    from ..gl.devices import device_handle, device_index

    index = device_index(device)  # refuses an index outside EGL's devices
    address = ctypes.cast(EGL.eglGetProcAddress("eglGetPlatformDisplayEXT"),
                          ctypes.c_void_p).value
    if not address:
        raise RuntimeError("EGL has no eglGetPlatformDisplayEXT: devices cannot be chosen")
    platform_display = ctypes.CFUNCTYPE(EGL.EGLDisplay, ctypes.c_uint, ctypes.c_void_p,
                                        ctypes.c_void_p)(address)
    display = platform_display(EGL_PLATFORM_DEVICE_EXT, device_handle(index), None)
    if not EGL.eglInitialize(display, None, None):
        raise RuntimeError(f"could not initialise the EGL display of device {index}")
    return display


class _VTKContext:
    """An OpenGL 3.3 core EGL context with a small pbuffer surface, for VTK to draw in."""

    def __init__(self, device: int | None) -> None:
        EGL = self._EGL = egl()
        display = EGL.eglGetCurrentDisplay() if device is None else None
        if not display:
            display = _device_display(EGL, device)
        self.display = display
        config, found = EGL.EGLConfig(), EGL.EGLint()
        attributes = [EGL.EGL_SURFACE_TYPE, EGL.EGL_PBUFFER_BIT,
                      EGL.EGL_RENDERABLE_TYPE, EGL.EGL_OPENGL_BIT,
                      EGL.EGL_RED_SIZE, 8, EGL.EGL_GREEN_SIZE, 8, EGL.EGL_BLUE_SIZE, 8,
                      EGL.EGL_ALPHA_SIZE, 8, EGL.EGL_DEPTH_SIZE, 24, EGL.EGL_NONE]
        if (not EGL.eglChooseConfig(display, (EGL.EGLint * len(attributes))(*attributes),
                                    ctypes.pointer(config), 1, ctypes.pointer(found))
                or found.value < 1):
            raise RuntimeError("no EGL configuration with an RGBA8 pbuffer and a depth buffer")
        EGL.eglBindAPI(EGL.EGL_OPENGL_API)
        version = [EGL.EGL_CONTEXT_MAJOR_VERSION, 3, EGL.EGL_CONTEXT_MINOR_VERSION, 3,
                   EGL.EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL.EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                   EGL.EGL_NONE]
        self.context = EGL.eglCreateContext(display, config, EGL.EGL_NO_CONTEXT,
                                            (EGL.EGLint * len(version))(*version))
        if not self.context:
            raise RuntimeError("could not create an OpenGL 3.3 core EGL context for VTK")
        size = [EGL.EGL_WIDTH, PBUFFER_SIZE, EGL.EGL_HEIGHT, PBUFFER_SIZE, EGL.EGL_NONE]
        self.surface = EGL.eglCreatePbufferSurface(display, config,
                                                   (EGL.EGLint * len(size))(*size))
        if not self.surface:
            EGL.eglDestroyContext(display, self.context)
            raise RuntimeError("could not create an EGL pbuffer surface for VTK")

    def make_current(self) -> None:
        if not self._EGL.eglMakeCurrent(self.display, self.surface, self.surface, self.context):
            raise RuntimeError("could not make VTK's EGL context current")

    def destroy(self) -> None:
        """Destroy the surface and the context (not the display); call with it not current."""
        self._EGL.eglDestroySurface(self.display, self.surface)
        self._EGL.eglDestroyContext(self.display, self.context)


def _pipeline(positions: np.ndarray, triangles: np.ndarray, normals: np.ndarray,
              colour: np.ndarray, background: np.ndarray, camera: Camera,
              size: tuple[int, int], samples: int) -> tuple:
    """(window, renderer, light, actor, mapper, mesh): the VTK objects drawing the pyvista mesh
    of ``positions`` (float32, relative to the origin), ``triangles`` and ``normals``, lit as
    the module notes say, into an offscreen ``vtkEGLRenderWindow`` that adopts the current
    EGL context."""
    import pyvista
    from vtkmodules.vtkRenderingCore import vtkActor, vtkLight, vtkPolyDataMapper, vtkRenderer
    from vtkmodules.vtkRenderingOpenGL2 import vtkEGLRenderWindow

    mesh = pyvista.PolyData.from_regular_faces(positions, triangles.astype(np.int64))
    mesh.point_data["Normals"] = normals.astype(np.float32)
    mesh.point_data.active_normals_name = "Normals"
    mapper = vtkPolyDataMapper()
    mapper.SetInputData(mesh)
    mapper.ScalarVisibilityOff()
    actor = vtkActor()
    actor.SetMapper(mapper)
    prop = actor.GetProperty()
    prop.SetColor(*colour)  # ambient and diffuse colour
    prop.SetAmbient(AMBIENT)
    prop.SetDiffuse(DIFFUSE)
    prop.SetSpecular(0.0)
    prop.SetInterpolationToGouraud()
    prop.BackfaceCullingOff()
    renderer = vtkRenderer()
    renderer.SetBackground(*background)
    renderer.AddActor(actor)
    renderer.SetAutomaticLightCreation(False)
    renderer.RemoveAllLights()
    renderer.SetTwoSidedLighting(True)
    light = vtkLight()
    light.SetLightTypeToHeadlight()
    light.SetColor(1.0, 1.0, 1.0)
    light.SetIntensity(1.0)
    if camera.projection == "perspective":  # a point light at the eye, as ours
        light.SetPositional(True)
        light.SetConeAngle(180.0)
        light.SetAttenuationValues(1.0, 0.0, 0.0)
    renderer.AddLight(light)
    PyvistaReference.set_vtk_camera(renderer.GetActiveCamera(), camera)
    window = vtkEGLRenderWindow()
    window.SetWindowInfo("")  # adopt the current context: never own (terminate) a display
    window.SetOffScreenRendering(True)
    window.SetSwapBuffers(False)  # read back from VTK's own framebuffer: no swap needed
    window.SetMultiSamples(samples)
    window.SetSize(*size)
    window.AddRenderer(renderer)
    return window, renderer, light, actor, mapper, mesh


def _pixel_array():
    from vtkmodules.vtkCommonCore import vtkUnsignedCharArray

    return vtkUnsignedCharArray()


class PyvistaReference(ReleasedReference):
    """The triangles ``(vertices, triangles, normals)`` drawn by VTK (a pyvista mesh) through
    our ``camera``.

    ``vertices``: (V, 3) float64 model coordinates, uploaded as float32 relative to
    ``camera.origin``; ``triangles``: (K, 3) vertex indices; ``normals``: (V, 3) smooth vertex
    normals (any length but zero; VTK renormalises them); ``base_color``: one RGB(A) colour,
    floats in [0, 1] or integers in [0, 255] (default light grey; the alpha is ignored, the
    mesh is opaque); ``size`` = (width, height) pixels; ``background``: the clear colour, RGB
    floats in [0, 1]; ``samples``: multisampling (0, 1, 2, 4, 8 or 16; default 4);
    ``device``: the EGL device to draw on (None: the current context's, else
    ``WORKBENCH_EGL_DEVICE`` or 0).
    The camera is VTK's own (position, focal point, view up, parallel scale or vertical view
    angle, clipping range, our aspect ratio), giving our matrices (see the tests). The
    lighting approximates the workbench's (see the module notes). Refuses malformed arrays,
    out-of-range indices, non-finite coordinates, zero normals, a non-positive size and a
    sample count VTK does not take.
    """

    name = "pyvista"

    def __init__(self, vertices: ArrayLike, triangles: ArrayLike, normals: ArrayLike,
                 camera: Camera, size: tuple[int, int], *, base_color: ArrayLike | None = None,
                 background: tuple[float, float, float] = (1.0, 1.0, 1.0), samples: int = 4,
                 device: int | None = None) -> None:
        vertices, triangles, normals = checked_triangles(vertices, triangles, normals)
        width, height = checked_size(size)
        bg = np.asarray(background, np.float64)
        if bg.shape != (3,) or not np.all((bg >= 0) & (bg <= 1)):
            raise ValueError(f"background must be 3 floats in [0, 1], got {background!r}")
        if samples not in (0, 1, 2, 4, 8, 16):
            raise ValueError(f"samples must be 0, 1, 2, 4, 8 or 16, got {samples!r}")
        colour = rgba_colours(base_color, 1)[0, :3]

        self.camera, self.size, self.samples = camera, (width, height), int(samples)
        self.triangles, self.vertices = len(triangles), len(vertices)
        positions = camera.relative(vertices)
        self.bytes_uploaded = int(positions.nbytes + 12 * len(normals) + 12 * len(triangles))
        self._GL = raw_gl()
        self._objects = self._window = None
        with keeping_current() as restore:
            self._context = _VTKContext(device)
            restore.display = self._context.display
            self._context.make_current()
            try:
                self._objects = _pipeline(positions, triangles, normals, colour, bg, camera,
                                          self.size, self.samples)
                self._objects[0].Render()
                self.renderer_name = self._GL.glGetString(self._GL.GL_RENDERER).decode()
            except BaseException:
                self._free()
                raise
        self._window = self._objects[0]
        self._pixels = _pixel_array()
        self.version = versions()

    @staticmethod
    def set_vtk_camera(vtk_camera, camera: Camera) -> None:
        """Give the ``vtkCamera`` our ``camera``: eye, target and up (relative to the origin),
        orthographic half height or vertical field of view, near and far, and our aspect
        ratio (so the projection does not follow the window's)."""
        vtk_camera.SetPosition(*np.asarray(camera.eye, np.float64))
        vtk_camera.SetFocalPoint(*np.asarray(camera.target, np.float64))
        vtk_camera.SetViewUp(*np.asarray(camera.up, np.float64))
        if camera.projection == "orthographic":
            vtk_camera.ParallelProjectionOn()
            vtk_camera.SetParallelScale(camera.half_height)
        else:
            vtk_camera.ParallelProjectionOff()
            vtk_camera.UseHorizontalViewAngleOff()
            vtk_camera.SetViewAngle(camera.fov_deg)
        vtk_camera.SetClippingRange(camera.near, camera.far)
        vtk_camera.SetExplicitAspectRatio(camera.aspect)
        vtk_camera.SetUseExplicitAspectRatio(True)

    def _check_alive(self) -> None:
        if getattr(self, "_window", None) is None:
            raise RuntimeError("this pyvista reference has been released")

    def _read(self) -> np.ndarray:
        """(H, W, 3) uint8 RGB of the last render, row 0 at the top (VTK's current)."""
        width, height = self.size
        self._window.GetPixelData(0, 0, width - 1, height - 1, 0, self._pixels, 0)
        rgb = np.frombuffer(memoryview(self._pixels), np.uint8).reshape(height, width, 3)
        return rgb[::-1].copy()

    def render(self) -> np.ndarray:
        """(H, W, 3) uint8 RGB, row 0 at the top; the caller's EGL context stays current."""
        self._check_alive()
        with keeping_current(self._context.display):
            self._context.make_current()
            self._window.Render()
            return self._read()

    def time(self, warmup: int = 2, repeat: int = 7) -> Timing:
        """Time one frame (ms): VTK's ``Render`` and the read-back of its image (the multisample
        resolve and ``glReadPixels``) as wall time; GPU time from a GL_TIME_ELAPSED query
        around the same (None on a software renderer or where timer queries fail); and the
        read-back alone. Refuses ``repeat`` < 5 and a negative ``warmup``."""
        check_counts(warmup, repeat)
        self._check_alive()

        def frame() -> None:
            self._window.Render()
            self._read()

        with keeping_current(self._context.display):
            self._context.make_current()
            return time_frames(self._GL, self.renderer_name, frame, self._read, warmup, repeat)

    def _free(self) -> None:
        """With VTK's context current: free VTK's GL objects, drop every VTK object (destroyed
        here, in this context), make no context current and destroy VTK's context. The
        caller's ``keeping_current`` then restores the previous context."""
        if self._objects is not None:
            self._objects[0].Finalize()  # every renderer's graphics resources, in this context
        self._objects = self._window = None
        EGL, context = egl(), self._context
        EGL.eglMakeCurrent(context.display, EGL.EGL_NO_SURFACE, EGL.EGL_NO_SURFACE,
                           EGL.EGL_NO_CONTEXT)
        context.destroy()

    def release(self) -> None:
        """Free VTK's GL resources and its EGL context (not the shared display)."""
        if getattr(self, "_window", None) is None:
            return
        self._window = None
        with keeping_current(self._context.display):
            self._context.make_current()
            self._free()
