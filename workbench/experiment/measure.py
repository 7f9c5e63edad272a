"""The one measurement function: any registered path on any scene, timed the same way everywhere.

:func:`measure` derives what the path declares (``needs``) on the scene, prepares the path,
warms up, times the draw (GPU and wall, median and spread, read-back apart; see
:func:`workbench.experiment.timing.time_draw`), reads the image and releases the path's GL
objects in all cases, also when a draw raises. It returns a :class:`Measurement`: the image and
one table row. Experiments, ``workbench render``, sweeps and tests all call it, so a time means
the same in every table. It draws on a backend (:mod:`workbench.paths.backends`): a GL context,
or the software rasterizer.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from ..gl import Camera
from ..paths.backends import as_backend
from ..paths.base import RenderPath
from ..paths.registry import DEFAULT_PATHS, path_class
from ..paths.style import style_summary
from ..scene.needs import Derivation, derive, derived_items, needed_items
from .timing import MIN_REPEATS, Timing, time_draw

if TYPE_CHECKING:
    import moderngl

    from ..paths.backends import Backend
    from ..scene.protocol import Scene

WHITE = (1.0, 1.0, 1.0, 1.0)
UNTIMED = ("gpu_ms", "gpu_ms_min", "gpu_ms_max", "wall_ms", "wall_ms_min", "wall_ms_max",
           "readback_ms", "repeats")


@dataclass
class Measurement:
    """What :func:`measure` returns: ``row`` (flat table columns, see :func:`measure`),
    ``image`` ((H, W, 4) uint8 RGBA, row 0 at the top), ``timing`` (the
    :class:`~workbench.experiment.timing.Timing`, None untimed) and ``path`` (released; its
    counters — triangles, bytes, ``scale`` — stay readable)."""

    row: dict[str, Any]
    image: np.ndarray
    timing: Timing | None
    path: RenderPath


def default_camera(scene: Scene, size: tuple[int, int],
                   view: tuple[float, float] = (30.0, 25.0), projection: str = "orthographic",
                   up: str = "z", style: object | None = None) -> Camera:
    """A camera showing all of ``scene`` at ``size`` (W, H): the default camera of the family
    of paths that draws scenes of its kind (:meth:`RenderPath.default_camera`) — for an FE mesh
    or a textured surface :meth:`Camera.fit_box` at azimuth/elevation ``view`` (degrees) over
    the bounds of every step; for a spacetime scene the top view whose pixel centres are those
    of the exact image, its depth range enclosing the heights drawn with
    ``style.height_scale``."""
    family = path_class(DEFAULT_PATHS[scene.kind])
    return family.default_camera(scene, size, view=view, projection=projection, up=up,
                                 style=style)


def measure(backend: moderngl.Context | Backend, scene: Scene, path: str | RenderPath,
            style: object | None = None, camera: Camera | None = None,
            size: tuple[int, int] = (800, 600), repeats: int = 7, *, warmup: int = 2,
            samples: int = 0, step: int | None = None,
            background: tuple[float, float, float, float] = WHITE, timed: bool = True,
            probe: Callable[[RenderPath], dict[str, Any]] | None = None) -> Measurement:
    """Measure ``path`` (a registry name, made with ``style``, or an unprepared
    :class:`RenderPath`) drawing ``scene`` (an FE mesh, a spacetime scene or a textured
    surface) on ``backend`` (a GL context, or a backend of :mod:`workbench.paths.backends`:
    :class:`~workbench.paths.backends.SoftwareRasterizer` draws the mesh paths on the CPU,
    timed by the wall clock alone, ``gpu_ms`` None) with ``camera`` (default the path family's
    :meth:`~RenderPath.default_camera`) into a ``size`` (W, H) framebuffer with ``samples``
    MSAA samples cleared to ``background``.

    Derives the path's ``needs`` on an FE mesh first (cached there) and refuses, with
    RuntimeError, a path whose ``prepare`` derived anything it did not declare. With ``timed``
    it warms up ``warmup`` times and times ``repeats`` (≥ 5) draws; otherwise it draws once.
    ``step`` (default the style's) is uploaded with ``set_step`` after ``prepare``.
    ``probe``, if given, is called with the still prepared path after the image is read (the
    framebuffer bound again, still holding that image) and before the release; the columns of
    the dict it returns are added to the row (say, the vertex-shader invocations of one more
    draw, or the time of ``set_step``). The image is not read again after it.

    The row: ``scene``, ``path``, ``style`` (fields off their defaults), ``renderer``,
    ``size`` ("WxH"), ``samples`` (MSAA), ``triangles``, ``vertices``, ``vertices_sent``,
    ``strips``, ``edges``, ``bytes_uploaded``, ``bytes_per_step``, ``derive_ms`` and
    ``derive_bytes`` (what the scene derived for this path now: 0 when cached), ``prepare_ms``,
    then ``gpu_ms``, ``gpu_ms_min``, ``gpu_ms_max``, ``wall_ms``, ``wall_ms_min``,
    ``wall_ms_max``, ``readback_ms`` and ``repeats`` (None untimed), and ``covered_px`` (pixels
    that differ from the background). Times in ms, on the renderer named.
    """
    if timed and (int(repeats) != repeats or repeats < MIN_REPEATS):
        raise ValueError(f"repeats must be an integer >= {MIN_REPEATS}, got {repeats}")
    backend = as_backend(backend)
    path = backend.path(path, style)
    width, height = (int(v) for v in size)
    if camera is None:
        camera = path.default_camera(scene, (width, height), style=path.style)
    derivation, mesh = Derivation({}), scene.kind == "mesh"
    if mesh:
        derivation = derive(scene, path.needs, path.style)
        held = derived_items(scene)
    fb = backend.target((width, height), samples)
    timing = None
    try:
        with path:
            start = time.perf_counter()
            backend.prepare(path, scene, camera)
            prepare_ms = (time.perf_counter() - start) * 1e3
            if mesh:
                undeclared = derived_items(scene) - held - needed_items(path.needs, path.style)
                if undeclared:
                    raise RuntimeError(f"path {path.name!r} derived {sorted(undeclared)} without "
                                       f"declaring it in needs {sorted(path.needs)}")
            if step is not None:
                path.set_step(step)
            backend.bind(path, fb)
            if timed:
                timing = time_draw(backend, fb, path.draw, warmup=warmup, repeat=repeats,
                                   background=background)
            else:
                fb.clear(background)
                path.draw()
            image = fb.read()
            probed = {}
            if probe is not None:
                fb.use()
                probed = probe(path)
    finally:
        fb.release()
    back = np.round(np.asarray(background) * 255).astype(np.uint8)
    row = dict(scene=scene.name, path=path.name, style=style_summary(path.style),
               renderer=backend.renderer_of(path), size=f"{width}x{height}", samples=samples,
               triangles=path.triangles, vertices=path.vertices,
               vertices_sent=path.vertices_sent, strips=path.strips, edges=path.edges,
               bytes_uploaded=path.bytes_uploaded, bytes_per_step=path.bytes_per_step,
               derive_ms=derivation.ms, derive_bytes=derivation.nbytes, prepare_ms=prepare_ms)
    row.update(timing.as_row() if timing is not None else dict.fromkeys(UNTIMED))
    row["covered_px"] = int((image != back).any(axis=-1).sum())
    row.update(probed)
    return Measurement(row=row, image=image, timing=timing, path=path)
