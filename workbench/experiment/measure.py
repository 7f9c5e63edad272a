"""The one measurement function: any registered path on any scene, timed the same way everywhere.

:func:`measure` derives what the path declares (``needs``) on the scene, prepares the path,
warms up, times the draw (GPU and wall, median and spread, read-back apart; see
:func:`workbench.experiment.timing.time_draw`), reads the image and releases the path's GL
objects in all cases, also when a draw raises. It returns a :class:`Measurement`: the image and
one table row. Experiments, ``workbench render``, sweeps and tests all call it, so a time means
the same in every table.
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..gl import Camera, Framebuffer, renderer
from ..paths.base import RenderPath, make_path
from ..scene.derive import Derivation, derive, derived_items, needed_items
from ..scene.mesh import FEMesh
from .timing import MIN_REPEATS, time_cpu_draw, time_draw

WHITE = (1.0, 1.0, 1.0, 1.0)


@dataclass
class Measurement:
    """What :func:`measure` returns: ``row`` (flat table columns, see :func:`measure`),
    ``image`` ((H, W, 4) uint8 RGBA, row 0 at the top), ``timing`` (the
    :class:`~workbench.experiment.timing.Timing`, None untimed) and ``path`` (released; its
    counters — triangles, bytes, ``scale`` — stay readable)."""

    row: dict
    image: np.ndarray
    timing: object
    path: RenderPath


def style_summary(style) -> str:
    """The fields of ``style`` that differ from its class's defaults, as ``name=value`` words."""
    if hasattr(style, "summary"):
        return style.summary()
    default = type(style)()
    return " ".join(f"{f.name}={getattr(style, f.name)}" for f in dataclasses.fields(style)
                    if getattr(style, f.name) != getattr(default, f.name))


def scene_name(scene) -> str:
    """A short name for ``scene``: its ``name``, else its kind and size."""
    name = getattr(scene, "name", None)
    if isinstance(name, str):
        return name
    if hasattr(scene, "corners"):
        kind = "bar" if scene.is_bar else f"slice t={scene.t:g}"
        return f"spacetime {kind}, {len(scene.corners)} polygons"
    return type(scene).__name__


def check_resolvable(lo, hi) -> None:
    """Refuse (ValueError) a bounding box ``lo``–``hi`` (float64, model units) that cannot be
    drawn: not finite, of zero extent, or so far from the origin that float64 coordinates
    cannot tell its points apart to 1/10 000 of its extent (they would draw as one point)."""
    lo, hi = np.asarray(lo, np.float64), np.asarray(hi, np.float64)
    if not (np.isfinite(lo).all() and np.isfinite(hi).all()):
        raise ValueError("the scene's coordinates are not finite")
    extent = float(np.max(hi - lo))
    magnitude = float(np.max(np.abs(np.concatenate([lo, hi]))))
    if extent <= 0:
        raise ValueError("the scene has zero extent: every point lies at one place")
    if np.spacing(magnitude) > 1e-4 * extent:
        raise ValueError(f"coordinates of magnitude {magnitude:.3g} are resolved to "
                         f"{np.spacing(magnitude):.3g} in float64, too coarse for a scene "
                         f"{extent:.3g} wide: translate it nearer the origin")


def default_camera(scene, size: tuple[int, int], view: tuple[float, float] = (30.0, 25.0),
                   projection: str = "orthographic", up: str = "z", style=None) -> Camera:
    """A camera showing all of ``scene`` at ``size`` (W, H): for an FE mesh or a textured
    surface, :meth:`Camera.fit_box` at azimuth/elevation ``view`` (degrees) over the bounds of
    every step; for a spacetime scene, the top view of its drawing plane whose pixel centres
    are those of :meth:`PixelGrid.fit` (so the exact image matches), its depth range enclosing
    the heights drawn with ``style.height_scale``."""
    aspect = size[0] / size[1]
    if hasattr(scene, "corners"):  # a spacetime scene: (x, y) or (x, t) plane, heights up z
        from ..algo.spacetime.raster import PixelGrid
        from ..paths.spacetime import top_camera

        grid = PixelGrid.fit(*scene.bounds(), size[0], size[1])
        top = float(getattr(style, "height_scale", 1.0)) * scene.max_speed()
        return top_camera(grid, (-1.0, top + 1.0))
    if isinstance(scene, FEMesh):
        lo, hi = scene.bounds(all_steps=True)
    else:  # a TexturedSurface
        lo, hi = scene.positions.min(axis=0), scene.positions.max(axis=0)
    check_resolvable(lo, hi)
    return Camera.fit_box(lo, hi, azimuth=view[0], elevation=view[1], projection=projection,
                          aspect=aspect, up=up)


def measure(ctx, scene, path, style=None, camera: Camera | None = None,
            size: tuple[int, int] = (800, 600), repeats: int = 7, *, warmup: int = 2,
            samples: int = 0, step: int | None = None, background=WHITE,
            timed: bool = True, probe: Callable[[RenderPath], dict] | None = None) -> Measurement:
    """Measure ``path`` (a registry name, made with ``style``, or an unprepared
    :class:`RenderPath`) drawing ``scene`` (an FE mesh, a spacetime scene or a textured
    surface) with ``camera`` (default :func:`default_camera`) into a ``size`` (W, H)
    framebuffer with ``samples`` MSAA samples cleared to ``background``.

    A path whose ``rasterizer`` is "software" (:class:`~workbench.paths.software.SoftwarePath`)
    draws on the CPU into its own target: ``ctx`` may be None, the draws are timed by the wall
    clock alone (``gpu_ms`` None) and the row's renderer names the rasterizer.

    Derives the path's ``needs`` on the scene first (cached there) and refuses, with
    RuntimeError, a path whose ``prepare`` derived anything it did not declare. With ``timed``
    it warms up ``warmup`` times and times ``repeats`` (≥ 5) draws; otherwise it draws once.
    ``step`` (default the style's) is uploaded with ``set_step`` after ``prepare``.
    ``probe``, if given, is called with the still prepared path after the image is read (the
    framebuffer bound again, still holding that image) and before the release; the columns of
    the dict it returns are added to the row (say, the vertex-shader invocations of one more
    draw, or the time of ``set_step``). The image is not read again after it.

    The row: ``scene``, ``path``, ``style`` (fields off their defaults), ``renderer``,
    ``width``, ``height``, ``samples``, ``triangles``, ``vertices``, ``vertices_sent``,
    ``strips``, ``edges``, ``bytes_uploaded``, ``bytes_per_step``, ``derive_ms`` and
    ``derive_bytes`` (what the scene derived for this path now: 0 when cached), ``prepare_ms``,
    then ``gpu_ms``, ``gpu_ms_min``, ``gpu_ms_max``, ``wall_ms``, ``wall_ms_min``,
    ``wall_ms_max``, ``readback_ms`` and ``repeats`` (None untimed), and ``covered_px`` (pixels
    that differ from the background). Times in ms, on the renderer named.
    """
    if timed and (int(repeats) != repeats or repeats < MIN_REPEATS):
        raise ValueError(f"repeats must be an integer >= {MIN_REPEATS}, got {repeats}")
    if isinstance(path, str):
        path = make_path(path, style)
    elif style is not None:
        raise ValueError("give a style with a path name, not with a path instance")
    width, height = (int(v) for v in size)
    if camera is None:
        camera = default_camera(scene, (width, height), style=path.style)
    derivation = Derivation({})
    if isinstance(scene, FEMesh):
        derivation = derive(scene, path.needs, path.style)
        held = derived_items(scene)
    software = getattr(path, "rasterizer", "gl") == "software"
    fb = path.make_target((width, height), samples) if software \
        else Framebuffer(ctx, (width, height), samples=samples)
    timing = None
    try:
        with path:
            start = time.perf_counter()
            path.prepare(ctx, scene, camera)
            if not software:
                ctx.finish()  # the uploads count as preparation
            prepare_ms = (time.perf_counter() - start) * 1e3
            if isinstance(scene, FEMesh):
                undeclared = derived_items(scene) - held - needed_items(path.needs, path.style)
                if undeclared:
                    raise RuntimeError(f"path {path.name!r} derived {sorted(undeclared)} without "
                                       f"declaring it in needs {sorted(path.needs)}")
            if step is not None:
                path.set_step(step)
            fb.use()
            if timed and software:
                timing = time_cpu_draw(fb, path.draw, warmup=warmup, repeat=repeats,
                                       background=background)
            elif timed:
                timing = time_draw(ctx, fb, path.draw, warmup=warmup, repeat=repeats,
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
    row = dict(scene=scene_name(scene), path=path.name, style=style_summary(path.style),
               renderer=path.renderer if software else renderer(ctx), width=width, height=height, samples=samples,
               triangles=path.triangles, vertices=path.vertices,
               vertices_sent=path.vertices_sent, strips=path.strips, edges=path.edges,
               bytes_uploaded=path.bytes_uploaded, bytes_per_step=path.bytes_per_step,
               derive_ms=derivation.ms, derive_bytes=derivation.nbytes, prepare_ms=prepare_ms)
    if timing is not None:
        row.update(timing.as_row())
    else:
        row.update(dict.fromkeys(("gpu_ms", "gpu_ms_min", "gpu_ms_max", "wall_ms", "wall_ms_min",
                                  "wall_ms_max", "readback_ms", "repeats")))
    row["covered_px"] = int((image != back).any(axis=-1).sum())
    row.update(probed)
    return Measurement(row=row, image=image, timing=timing, path=path)
