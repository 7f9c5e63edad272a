"""The one measurement function: any registered path on any scene, timed the same way everywhere.

:func:`measure` is :func:`~workbench.paths.drawing.prepared` (the path's ``needs`` derived on
the scene, the path prepared and bound to a target) plus timing plus a row: it warms up,
times the draw (GPU and wall, median and spread, read-back apart; see
:func:`workbench.measurement.timing.time_draw`), reads the image and releases the path's GL
objects in all cases, also when a draw raises. It returns a :class:`Measurement`: the image and
one table row. Experiments, ``workbench render``, sweeps and tests all call it, so a time means
the same in every table. It draws on a backend (:mod:`workbench.paths.backends`): a GL context,
or the software rasterizer.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from contextlib import ExitStack
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from ..gl import Camera
from ..paths.backends import as_backend
from ..paths.base import RenderPath
from ..paths.drawing import WHITE, Prepared, prepared
from ..paths.registry import DEFAULT_PATHS, path_class
from ..paths.style import style_summary
from .timing import MIN_REPEATS, TIMING_COLUMNS, Timing, time_draw, time_readback, timed_draw

if TYPE_CHECKING:
    import moderngl

    from ..paths.backends import Backend
    from ..scene.protocol import Scene
    from .stats import StoppingRule

UNTIMED = TIMING_COLUMNS


@dataclass
class Measurement:
    """What :func:`measure` returns: ``row`` (flat table columns, see :func:`measure`),
    ``image`` ((H, W, 4) uint8 RGBA, row 0 at the top), ``timing`` (the
    :class:`~workbench.measurement.timing.Timing`, None untimed) and ``path`` (released; its
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
            probe: Callable[[RenderPath], dict[str, Any]] | None = None,
            stop: StoppingRule | None = None) -> Measurement:
    """Measure ``path`` (a registry name, made with ``style``, or an unprepared
    :class:`RenderPath`) drawing ``scene`` (an FE mesh, a spacetime scene or a textured
    surface) on ``backend`` (a GL context, or a backend of :mod:`workbench.paths.backends`:
    :class:`~workbench.paths.backends.SoftwareRasterizer` draws the mesh paths on the CPU,
    timed by the wall clock alone, ``gpu_ms`` None) with ``camera`` (default the path family's
    :meth:`~RenderPath.default_camera`) into a ``size`` (W, H) framebuffer with ``samples``
    MSAA samples cleared to ``background``, prepared as
    :func:`~workbench.paths.drawing.prepared` does; its image is the one
    :func:`~workbench.paths.drawing.render` draws for the same arguments.

    With ``timed`` it warms up ``warmup`` times and times ``repeats`` (≥ 5) draws, and more
    until ``stop`` (a :class:`~workbench.measurement.stats.StoppingRule`) is satisfied where one
    is given; otherwise it draws once. ``probe``, if given, is called with the still prepared
    path after the image is read (the framebuffer bound again, still holding that image) and
    before the release; the columns of the dict it returns are added to the row (say, the
    vertex-shader invocations of one more draw, or the time of ``set_step``). The image is not
    read again after it.

    The row: ``scene``, ``path``, ``style`` (fields off their defaults), ``renderer``,
    ``size`` ("WxH"), ``samples`` (MSAA), ``triangles``, ``vertices``, ``vertices_sent``,
    ``strips``, ``edges``, ``bytes_uploaded``, ``bytes_per_step``, ``derive_ms`` and
    ``derive_bytes`` (what the scene derived for this path now: 0 when cached), ``prepare_ms``,
    then the timing columns of :data:`~workbench.measurement.timing.TIMING_COLUMNS` (``gpu_ms``
    … ``repeats``, the wall median's 95 % interval ``wall_ms_lo``/``wall_ms_hi`` and the raw
    ``wall_samples_ms``; None untimed, ``gpu_ms`` None on a software renderer), and
    ``covered_px`` (pixels that differ from the background). Times in ms, on the renderer
    named.

    Takes more than 12 arguments because it is the one public measurement call: the drawing
    arguments of :func:`~workbench.paths.drawing.render` plus the timing options, all but the
    first seven keyword-only; grouping them into an options object would only move the names.
    """
    if timed and (int(repeats) != repeats or repeats < MIN_REPEATS):
        raise ValueError(f"repeats must be an integer >= {MIN_REPEATS}, got {repeats}")
    backend = as_backend(backend)
    timing = None
    with prepared(backend, scene, path, style, camera, size, samples=samples,
                  step=step) as ready:
        path, fb = ready.path, ready.target
        if timed:
            timing = time_draw(backend, fb, path.draw, warmup=warmup, repeat=repeats,
                               background=background, stop=stop)
        else:
            fb.clear(background)
            path.draw()
        image = fb.read()
        probed = {}
        if probe is not None:
            fb.use()
            probed = probe(path)
    row = measurement_row(backend, scene, ready, image, timing, background, probed)
    return Measurement(row=row, image=image, timing=timing, path=path)


def measurement_row(backend: Backend, scene: Scene, ready: Prepared, image: np.ndarray,
                    timing: Timing | None, background: tuple[float, float, float, float],
                    probed: dict[str, Any]) -> dict[str, Any]:
    """The row :func:`measure` documents, of the path ``ready`` drew into ``image``."""
    path = ready.path
    width, height = ready.target.size
    back = np.round(np.asarray(background) * 255).astype(np.uint8)
    row = dict(scene=scene.name, path=path.name, style=style_summary(path.style),
               renderer=backend.renderer_of(path), size=f"{width}x{height}",
               samples=ready.samples, triangles=path.triangles, vertices=path.vertices,
               vertices_sent=path.vertices_sent, strips=path.strips, edges=path.edges,
               bytes_uploaded=path.bytes_uploaded, bytes_per_step=path.bytes_per_step,
               derive_ms=ready.derivation.ms, derive_bytes=ready.derivation.nbytes,
               prepare_ms=ready.prepare_ms)
    row.update(timing.as_row() if timing is not None else dict.fromkeys(UNTIMED))
    row["covered_px"] = int((image != back).any(axis=-1).sum())
    row.update(probed)
    return row


@dataclass(frozen=True)
class Together:
    """One of the paths :func:`measure_together` measures: ``path`` (a registry name made with
    ``style``, or an unprepared path), its MSAA ``samples`` and an optional ``probe`` (as in
    :func:`measure`)."""

    path: str | RenderPath
    style: object | None = None
    samples: int = 0
    probe: Callable[[RenderPath], dict[str, Any]] | None = None


def measure_together(backend: moderngl.Context | Backend, scene: Scene,
                     paths: Sequence[Together], camera: Camera | None = None,
                     size: tuple[int, int] = (800, 600), repeats: int = 7, *, warmup: int = 2,
                     step: int | None = None,
                     background: tuple[float, float, float, float] = WHITE,
                     stop: StoppingRule | None = None) -> list[Measurement]:
    """:func:`measure` of several ``paths`` on one ``scene``, ``camera`` and ``size``, their
    draws interleaved: every path is prepared first, then each round draws every path once,
    in order (each cleared and waited for outside the clock, as :func:`time_draw` does),
    ``warmup`` rounds untimed, then at least ``repeats`` timed rounds and more until ``stop`` is
    satisfied for every path. A slow change of the machine's speed (another process, the
    clock) then reaches every path alike, so their ratios hold, within this run and against
    another run measured the same way. Returns one :class:`Measurement` per path, in order,
    with the rows :func:`measure` gives (``repeats``: the timed rounds)."""
    if int(repeats) != repeats or repeats < MIN_REPEATS:
        raise ValueError(f"repeats must be an integer >= {MIN_REPEATS}, got {repeats}")
    if not paths:
        raise ValueError("measure_together needs at least one path")
    backend = as_backend(backend)
    with ExitStack() as stack:
        ready = [stack.enter_context(prepared(backend, scene, p.path, p.style, camera, size,
                                              samples=p.samples, step=step)) for p in paths]
        timers = [backend.gpu_timer() for _ in ready]
        wall: list[list[float]] = [[] for _ in ready]
        gpu: list[list[float]] = [[] for _ in ready]
        rounds = 0
        while rounds < warmup + repeats or (
                stop is not None and not all(stop.done(samples) for samples in wall)):
            rounds += 1
            for i, (r, timer) in enumerate(zip(ready, timers)):
                r.bind()
                wall_ms, gpu_ms = timed_draw(backend, r.target, r.path.draw, timer, background)
                if rounds > warmup:
                    wall[i].append(wall_ms)
                    gpu[i].append(gpu_ms)
        out = []
        for i, (r, spec) in enumerate(zip(ready, paths)):
            r.bind()
            image = r.target.read()
            readback = time_readback(r.target, len(wall[i]))
            timing = Timing.from_samples(wall[i], gpu[i] if timers[i] is not None else None,
                                         readback)
            probed = spec.probe(r.path) if spec.probe is not None else {}
            row = measurement_row(backend, scene, r, image, timing, background, probed)
            out.append(Measurement(row=row, image=image, timing=timing, path=r.path))
    return out
