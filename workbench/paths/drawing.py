"""How a path is drawn: the one place a render path is prepared, drawn and released.

* :func:`prepared` — a context manager: the path made (from a registry name and a style, or
  given unprepared), what it declares it needs derived on the scene, prepared on a backend
  (:mod:`workbench.paths.backends`: a GL context or the software rasterizer) with a camera,
  bound to a new target of a size; the path and the target released on exit, also when the
  body raises. It yields a :class:`Prepared`, which a frame loop keeps across frames
  (:mod:`workbench.animation.frames`) and the measurement function times
  (:func:`workbench.measurement.rows.measure`).
* :func:`render` — one image, untimed: :func:`prepared`, clear, draw, read back.
* :func:`prepared_path` — a path prepared and left prepared, for a caller that keeps it for
  the life of a process (a sort-last worker's cache, a chunked scene's writer); the caller
  releases it.

Nothing here times anything but the preparation (``Prepared.prepare_ms``); timing a draw is the
measurement layer's job.
"""

from __future__ import annotations

import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..scene.needs import Derivation, derive, derived_items, needed_items
from .backends import as_backend
from .base import RenderPath

if TYPE_CHECKING:
    import moderngl

    from ..gl import Camera, Framebuffer
    from ..scene.protocol import Scene
    from .backends import Backend
    from .software import SoftwareTarget

WHITE = (1.0, 1.0, 1.0, 1.0)


@dataclass
class Prepared:
    """A path prepared on a backend, bound to its own target: what :func:`prepared` yields.
    ``draw()`` draws into ``target`` (bind it first with :meth:`bind` when another target was
    used since); ``prepare_ms`` (wall ms, the uploads waited for) and ``derivation`` say what
    preparing cost; ``samples`` is the target's MSAA sample count."""

    backend: Backend
    path: RenderPath
    target: Framebuffer | SoftwareTarget
    camera: Camera
    prepare_ms: float
    derivation: Derivation
    samples: int = 0

    def bind(self) -> None:
        """Make ``target`` the one ``path`` draws into."""
        self.backend.bind(self.path, self.target)

    def image(self, background: tuple[float, float, float, float] = WHITE) -> np.ndarray:
        """The target bound, cleared to ``background`` (RGBA in [0, 1]), drawn and read back:
        (H, W, 4) uint8 RGBA, row 0 at the top. Untimed."""
        self.bind()
        self.target.clear(background)
        self.path.draw()
        return self.target.read()

    def resize(self, size: tuple[int, int]) -> None:
        """Draw into a new ``size`` (W, H) target from now on (same MSAA samples), bound; the
        old target is released once the new one exists. The camera is the caller's to change
        (``path.set_camera``). ValueError for a size that is not positive."""
        target = self.backend.target(tuple(int(v) for v in size), self.samples)
        self.target.release()
        self.target = target
        self.bind()


def _prepare(backend: Backend, scene: Scene, path: RenderPath,
             camera: Camera) -> tuple[float, Derivation]:
    """Derive ``path``'s needs on an FE mesh ``scene``, prepare it on ``backend`` and refuse
    (RuntimeError) what it derived without declaring it; (prepare wall ms, derivation)."""
    derivation, mesh = Derivation({}), scene.kind == "mesh"
    if mesh:
        derivation = derive(scene, path.needs, path.style)
        held = derived_items(scene)
    start = time.perf_counter()
    backend.prepare(path, scene, camera)
    prepare_ms = (time.perf_counter() - start) * 1e3
    if mesh:
        undeclared = derived_items(scene) - held - needed_items(path.needs, path.style)
        if undeclared:
            raise RuntimeError(f"path {path.name!r} derived {sorted(undeclared)} without "
                               f"declaring it in needs {sorted(path.needs)}")
    return prepare_ms, derivation


@contextmanager
def prepared(backend: moderngl.Context | Backend, scene: Scene, path: str | RenderPath,
             style: object | None = None, camera: Camera | None = None,
             size: tuple[int, int] = (800, 600), *, samples: int = 0,
             step: int | None = None) -> Iterator[Prepared]:
    """``path`` (a registry name made with ``style``, or an unprepared :class:`RenderPath`)
    prepared to draw ``scene`` with ``camera`` (default the path family's) into a new
    ``size`` (W, H) target with ``samples`` MSAA samples on ``backend``, bound; the path and the
    target are released on exit, also when the body raises.

    Derives the path's ``needs`` on an FE mesh first (cached there) and refuses, with
    RuntimeError, a path whose ``prepare`` derived anything it did not declare. ``step``
    (default the style's) is uploaded with ``set_step`` after ``prepare``. Refused as the
    backend refuses the path (ValueError: a software path on GL, MSAA on the software
    rasterizer; TypeError for a backend that is none) and as the path refuses the scene.
    """
    backend = as_backend(backend)
    path = backend.path(path, style)
    width, height = (int(v) for v in size)
    if camera is None:
        camera = path.default_camera(scene, (width, height), style=path.style)
    ready = Prepared(backend, path, backend.target((width, height), samples), camera, 0.0,
                     Derivation({}), samples)
    try:
        with path:
            ready.prepare_ms, ready.derivation = _prepare(backend, scene, path, camera)
            if step is not None:
                path.set_step(step)
            ready.bind()
            yield ready
    finally:
        ready.target.release()  # the one drawn into last (Prepared.resize replaces it)


def render(backend: moderngl.Context | Backend, scene: Scene, path: str | RenderPath,
           style: object | None = None, camera: Camera | None = None,
           size: tuple[int, int] = (800, 600), step: int | None = None, *, samples: int = 0,
           background: tuple[float, float, float, float] = WHITE) -> np.ndarray:
    """The image of ``path`` (a registry name made with ``style``, or an unprepared path)
    drawing ``scene`` at state ``step`` (default the style's) on ``backend`` with ``camera``
    (default the path family's) into a ``size`` (W, H) target with ``samples`` MSAA samples
    cleared to ``background``: (H, W, 4) uint8 RGBA, row 0 at the top. Untimed; the path and
    the target are released before it returns. The same image :func:`measure
    <workbench.measurement.rows.measure>` reads for the same arguments. Refused as
    :func:`prepared` refuses."""
    with prepared(backend, scene, path, style, camera, size, samples=samples,
                  step=step) as ready:
        return ready.image(background)


def prepared_path(backend: moderngl.Context | Backend, scene: Scene, path: str | RenderPath,
                  style: object | None = None, camera: Camera | None = None, *,
                  size: tuple[int, int] | None = None) -> RenderPath:
    """``path`` (a registry name made with ``style``, or an unprepared path) prepared to draw
    ``scene`` with ``camera`` (default the path family's at ``size``, else 64 × 64) on
    ``backend``, its needs derived as :func:`prepared` derives them, and left prepared: for a
    caller that keeps the path for the life of a process and releases it itself
    (``path.release()``). A software path gets its own ``size`` (W, H) target where ``size``
    is given. Refused as :func:`prepared` refuses; the path is released when preparing
    raises."""
    backend = as_backend(backend)
    path = backend.path(path, style)
    if camera is None:
        camera = path.default_camera(scene, size or (64, 64), style=path.style)
    try:
        _prepare(backend, scene, path, camera)
        if size is not None and hasattr(path, "make_target"):
            path.make_target(tuple(int(v) for v in size))
    except BaseException:
        path.release()
        raise
    return path
