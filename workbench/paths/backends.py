"""What draws a path: a headless GL context, or the es2008 software rasterizer on the CPU.

A backend gives the measurement function (:func:`workbench.measurement.rows.measure`) all it
needs to draw and time a path the same way on either renderer:

* :meth:`path` — the drawable for a registry name or a path: the GL path itself, or its
  :class:`~workbench.paths.software.SoftwarePath`;
* :meth:`target` — a framebuffer (``use``, ``clear``, ``read``, ``release``) of a size, with
  MSAA samples where the renderer has them;
* :meth:`prepare` and :meth:`bind` — prepare the path (the uploads finished, so that they count
  as preparation) and make it draw into a target;
* :meth:`finish` and :meth:`gpu_timer` — wait for the draws, and a GPU time query (None where
  the renderer has none);
* :attr:`renderer` and :meth:`renderer_of` — the renderer a row names.

:func:`as_backend` takes a moderngl context (the GL backend) or a backend.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import moderngl

from ..algo.softraster import RasterOptions
from ..gl import Framebuffer, GpuTimer, renderer
from ..gl.context import timer_queries_meaningful
from .base import RenderPath
from .registry import make_path
from .software import SoftwarePath, SoftwareTarget

if TYPE_CHECKING:
    from ..gl.camera import Camera
    from ..scene.protocol import Scene
    from .style import Style


class GLBackend:
    """Draws on the moderngl context ``ctx`` into offscreen framebuffers."""

    kind = "gl"

    def __init__(self, ctx: moderngl.Context) -> None:
        self.ctx = ctx

    @property
    def renderer(self) -> str:
        return renderer(self.ctx)

    def path(self, path: str | RenderPath, style: object | None = None) -> RenderPath:
        """``path`` (a registry name, made with ``style``, or a GL path) ready to prepare;
        ValueError for a software path."""
        if isinstance(path, str):
            return make_path(path, style)
        if style is not None:
            raise ValueError("give a style with a path name, not with a path instance")
        if isinstance(path, SoftwarePath):
            raise ValueError("a software path draws on the software rasterizer backend, not on "
                             "a GL context")
        return path

    def target(self, size: tuple[int, int], samples: int = 0) -> Framebuffer:
        return Framebuffer(self.ctx, size, samples=samples)

    def prepare(self, path: RenderPath, scene: Scene, camera: Camera) -> None:
        path.prepare(self.ctx, scene, camera)
        self.ctx.finish()  # the uploads count as preparation

    def bind(self, path: RenderPath, target: Framebuffer) -> None:
        target.use()

    def renderer_of(self, path: RenderPath) -> str:
        """The renderer a row of ``path`` names: the context's."""
        return self.renderer

    def finish(self) -> None:
        self.ctx.finish()

    def gpu_timer(self) -> GpuTimer | None:
        """A GPU time query, or None on a software renderer (its queries time nothing)."""
        if not timer_queries_meaningful(self.ctx):
            return None
        return GpuTimer(self.ctx)  # moderngl 5.13 queries have no release(); it is collected


@dataclass
class SoftwareRasterizer:
    """Draws the mesh paths with the es2008 software rasterizer (``options``) on the CPU."""

    options: RasterOptions = field(default_factory=RasterOptions)
    kind = "software"

    @property
    def renderer(self) -> str:
        return SoftwarePath("position", options=self.options).renderer

    def path(self, path: str | RenderPath, style: Style | None = None) -> SoftwarePath:
        """The software path of ``path``: a registry name (made with ``style``), a mesh path
        (its name and style) or a software path (as it is)."""
        if isinstance(path, SoftwarePath):
            if style is not None:
                raise ValueError("give a style with a path name, not with a path instance")
            return path
        if not isinstance(path, str):
            if style is not None:
                raise ValueError("give a style with a path name, not with a path instance")
            path, style = path.name, path.style
        return SoftwarePath(path, style, self.options)

    def target(self, size: tuple[int, int], samples: int = 0) -> SoftwareTarget:
        if samples:
            raise ValueError("the software rasterizer draws without MSAA: samples must be 0")
        return SoftwareTarget(size)

    def prepare(self, path: SoftwarePath, scene: Scene, camera: Camera) -> None:
        path.prepare(None, scene, camera)

    def bind(self, path: SoftwarePath, target: SoftwareTarget) -> None:
        path.target = target

    def renderer_of(self, path: SoftwarePath) -> str:
        """The renderer a row of ``path`` names: the rasterizer with the threads it drew on."""
        return path.renderer

    def finish(self) -> None:
        """Nothing to wait for: the draws are done when they return."""

    def gpu_timer(self) -> None:
        return None


Backend = GLBackend | SoftwareRasterizer


def as_backend(backend: moderngl.Context | Backend) -> Backend:
    """``backend`` itself, or the GL backend of a moderngl context; TypeError otherwise."""
    if isinstance(backend, (GLBackend, SoftwareRasterizer)):
        return backend
    if isinstance(backend, moderngl.Context):
        return GLBackend(backend)
    raise TypeError(f"expected a GL context or a backend (GLBackend, SoftwareRasterizer), got "
                    f"{type(backend).__name__}")
