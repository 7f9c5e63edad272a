"""Timing of draws and CPU work: warm-up, at least five repetitions, the median with its
confidence interval, and a stopping rule.

GPU time comes from a GL_TIME_ELAPSED query around the draw where the renderer's timer queries
time the draw (a GPU; not a software renderer such as llvmpipe, whose ``gpu_ms`` stays None);
wall time spans the draw and the backend's ``finish`` (``ctx.finish()`` on GL); read-back
(``Framebuffer.read``) is timed on its own. Clearing the target is excluded from all three.
Times are in milliseconds and hold only for the renderer they were measured on (the backend's
``renderer``), so experiments report ratios from one run, measured interleaved where a table
states them (:mod:`workbench.measurement.interleave`).

The wall time's median comes with a distribution-free 95 % interval (order statistics,
:func:`workbench.measurement.stats.median_interval`): ``wall_ms_lo``/``wall_ms_hi``. With a
:class:`~workbench.measurement.stats.StoppingRule` the draws go on past ``repeat`` until that
interval is narrow enough or the rule's maximum count is reached; ``repeats`` records how many
were timed.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from statistics import median
from typing import TYPE_CHECKING, Any

from ..paths.backends import as_backend
from .stats import StoppingRule, median_interval

if TYPE_CHECKING:
    import moderngl

    from ..gl import Framebuffer
    from ..paths.backends import Backend
    from ..paths.software import SoftwareTarget

MIN_REPEATS = 5


def check_counts(warmup: int, repeat: int) -> None:
    """Refuse fewer than :data:`MIN_REPEATS` repetitions or a negative warm-up count."""
    if int(repeat) != repeat or repeat < MIN_REPEATS:
        raise ValueError(f"repeat must be an integer >= {MIN_REPEATS} (median and spread need "
                         f"several samples), got {repeat}")
    if int(warmup) != warmup or warmup < 0:
        raise ValueError(f"warmup must be a non-negative integer, got {warmup}")


def _spread(samples: list[float] | None) -> tuple[float | None, float | None, float | None]:
    if not samples:
        return None, None, None
    return float(median(samples)), float(min(samples)), float(max(samples))


@dataclass(frozen=True)
class Timing:
    """Median and range of repeated measurements, in milliseconds.

    GPU and read-back times are ``None`` where they were not measured (CPU work, or a renderer
    whose timer queries time nothing). ``wall_ms_lo``/``wall_ms_hi`` bound the wall median with
    95 % confidence (order statistics; 93.75 % with the least count, 5).
    ``wall_samples_ms``/``gpu_samples_ms`` keep the raw repetitions; ``result`` holds what the
    timed function returned last (:func:`time_call` only).
    """

    gpu_ms: float | None
    gpu_ms_min: float | None
    gpu_ms_max: float | None
    wall_ms: float
    wall_ms_min: float
    wall_ms_max: float
    readback_ms: float | None
    repeats: int
    wall_ms_lo: float | None = None
    wall_ms_hi: float | None = None
    wall_samples_ms: tuple[float, ...] = field(default=(), repr=False, compare=False)
    gpu_samples_ms: tuple[float, ...] = field(default=(), repr=False, compare=False)
    result: Any = field(default=None, repr=False, compare=False)

    @classmethod
    def from_samples(cls, wall: list[float], gpu: list[float] | None = None,
                     readback: list[float] | None = None, result: Any = None) -> Timing:
        """Summarise raw samples (ms): medians and ranges; ``gpu``/``readback`` may be None."""
        if len(wall) < MIN_REPEATS:
            raise ValueError(f"need at least {MIN_REPEATS} wall-time samples, got {len(wall)}")
        if gpu is not None and len(gpu) != len(wall):
            raise ValueError(f"{len(gpu)} GPU samples for {len(wall)} wall samples")
        g, g_min, g_max = _spread(gpu)
        w, w_min, w_max = _spread(wall)
        interval = median_interval(wall)
        return cls(gpu_ms=g, gpu_ms_min=g_min, gpu_ms_max=g_max, wall_ms=w, wall_ms_min=w_min,
                   wall_ms_max=w_max, readback_ms=_spread(readback)[0], repeats=len(wall),
                   wall_ms_lo=interval.lo, wall_ms_hi=interval.hi,
                   wall_samples_ms=tuple(wall), gpu_samples_ms=tuple(gpu or ()), result=result)

    def as_row(self, prefix: str = "") -> dict[str, Any]:
        """Flat table columns (:data:`TIMING_COLUMNS`: ``gpu_ms`` … ``repeats``, then the
        wall median's interval ``wall_ms_lo``/``wall_ms_hi`` and the raw
        ``wall_samples_ms``, kept for the results store and left out of CSV and Markdown
        tables), names optionally prefixed."""
        return {prefix + name: getattr(self, name) for name in TIMING_COLUMNS}


#: the columns a timing adds to a row, in milliseconds (``repeats``: how many draws were timed)
TIMING_COLUMNS = ("gpu_ms", "gpu_ms_min", "gpu_ms_max", "wall_ms", "wall_ms_min", "wall_ms_max",
                  "readback_ms", "repeats", "wall_ms_lo", "wall_ms_hi", "wall_samples_ms")


EMPTY_GPU_NOTE = ("{columns} empty: {renderers} rasterizes on the CPU, and its GL timer queries "
                  "do not time the draw (they answer about 3e-05 ms for whole frames); wall_ms "
                  "is the time.")


def empty_gpu_note(rows: list[dict[str, Any]], renderer: str | None = None) -> list[str]:
    """A table's note on its GPU-time columns (names containing ``gpu_ms``) where every value is
    empty because the rows' renderers (their ``renderer`` column, else ``renderer``) are
    software renderers; no note otherwise."""
    from ..gl.context import is_software_renderer

    columns = sorted({k for row in rows for k in row if "gpu_ms" in k})
    if not columns or any(row.get(c) is not None for row in rows for c in columns):
        return []
    renderers = sorted({str(r.get("renderer") or renderer) for r in rows
                        if r.get("renderer") or renderer})
    if not renderers or not all(is_software_renderer(r) for r in renderers):
        return []
    return [EMPTY_GPU_NOTE.format(columns=", ".join(columns), renderers=" and ".join(renderers))]


def time_draw(backend: moderngl.Context | Backend, fb: Framebuffer | SoftwareTarget,
              draw: Callable[[], Any], warmup: int = 2, repeat: int = 7,
              readback_repeat: int | None = None,
              background: tuple[float, float, float, float] = (1.0, 1.0, 1.0, 1.0),
              stop: StoppingRule | None = None) -> Timing:
    """Time ``draw()`` into framebuffer ``fb`` on ``backend`` (a GL context, or a backend of
    :mod:`workbench.paths.backends`): GPU, wall and read-back milliseconds.

    Each repetition clears ``fb`` to ``background`` RGBA (and waits for the clear) outside the
    clock, then measures wall time around ``draw()`` plus the backend's ``finish``, inside a
    GPU timer query where the renderer has one (``gpu_ms`` None otherwise, as on the software
    rasterizer). ``draw`` must draw into the bound framebuffer and must not open a time query of
    its own (queries of one kind do not nest). Read-back is then timed separately: ``fb.read()``
    of the finished last draw, repeated ``readback_repeat`` times (default ``repeat``) after
    one untimed read. Afterwards ``fb`` holds the last drawn image. With ``stop`` the draws go
    on after ``repeat`` until ``stop.done`` says the wall median's interval is narrow enough.
    Refuses ``repeat`` < 5 and a negative ``warmup``.
    """
    backend = as_backend(backend)
    check_counts(warmup, repeat)
    readback_repeat = repeat if readback_repeat is None else readback_repeat
    check_counts(0, readback_repeat)
    timer = backend.gpu_timer()
    wall: list[float] = []
    gpu: list[float] = []
    i = 0
    while i < warmup + repeat or (stop is not None and not stop.done(wall)):
        i += 1
        wall_ms, gpu_ms = timed_draw(backend, fb, draw, timer, background)
        if i > warmup:
            wall.append(wall_ms)
            gpu.append(gpu_ms)
    fb.read()
    return Timing.from_samples(wall, gpu if timer is not None else None,
                               time_readback(fb, readback_repeat))


def timed_draw(backend: Backend, fb: Framebuffer | SoftwareTarget, draw: Callable[[], Any],
               timer: Any, background: tuple[float, float, float, float]
               ) -> tuple[float, float | None]:
    """One timed draw, as :func:`time_draw` times each: ``fb`` cleared to ``background`` and
    waited for outside the clock, then the wall ms of ``draw()`` and the backend's ``finish``,
    inside ``timer`` (the backend's GPU timer, or None) whose ms come second (None without)."""
    fb.clear(background)
    backend.finish()
    start = time.perf_counter()
    if timer is None:
        draw()
    else:
        with timer:
            draw()
    backend.finish()
    wall_ms = (time.perf_counter() - start) * 1e3
    return wall_ms, None if timer is None else timer.elapsed_ms


def time_readback(fb: Framebuffer | SoftwareTarget, repeat: int) -> list[float]:
    """Wall ms of ``repeat`` reads of ``fb``'s finished image."""
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        fb.read()
        times.append((time.perf_counter() - start) * 1e3)
    return times


def time_call(fn: Callable[[], Any], warmup: int = 1, repeat: int = 5,
              stop: StoppingRule | None = None,
              setup: Callable[[], Any] | None = None) -> Timing:
    """Wall time (ms) of the CPU work ``fn()``; GPU and read-back times are None.

    The value returned by the last call is kept in ``Timing.result``. With ``stop`` the calls
    go on after ``repeat`` as in :func:`time_draw`. ``setup``, where given, is called untimed
    before every call (warm-up calls too). Refuses ``repeat`` < 5 and a negative ``warmup``.
    """
    check_counts(warmup, repeat)
    wall: list[float] = []
    result = None
    i = 0
    while i < warmup + repeat or (stop is not None and not stop.done(wall)):
        i += 1
        if setup is not None:
            setup()
        start = time.perf_counter()
        result = fn()
        elapsed = (time.perf_counter() - start) * 1e3
        if i > warmup:
            wall.append(elapsed)
    return Timing.from_samples(wall, result=result)
