"""Faults injected on purpose, so that a check shows it can fail: a render path whose draw is
slower by a known share (for ``workbench results compare`` and its detection benchmark), and
the numeric faults the numerical stress suite (:mod:`workbench.reliability.numerics`) must
catch, each a context manager that undoes itself:

* :func:`region_walk_kernel` -- the old point–triangle kernel (:func:`region_walk_closest_point`,
  Ericson's region walk) where Python callers look the kernel up;
* :func:`unrounded_bounds` -- the Hausdorff bracket and the simplifier's certificates without
  their outward rounding;
* :func:`painted_nan_rim` -- a rim of scale colour painted around the missing regions of every
  image the no-result check receives; :func:`legacy_nan_sentinel` -- the old interpolated
  sentinel in place of the no-result rule.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any

import numba
import numpy as np


def slowed(path: Any, finish: Callable[[], Any], share: float) -> Any:
    """``path`` with its ``draw`` made ``1 + share`` times as long: after drawing and waiting
    for the draw (``finish``), it spins for ``share`` of the time that took (a spin, not a
    sleep, so that the clock sees busy time). Returns ``path``; refuses a negative share."""
    if not share >= 0:
        raise ValueError(f"share must be >= 0, got {share}")
    draw = path.draw

    def slow_draw() -> None:
        start = time.perf_counter()
        draw()
        finish()
        end = time.perf_counter() + share * (time.perf_counter() - start)
        while time.perf_counter() < end:
            pass

    path.draw = slow_draw
    return path


# --------------------------------------------------------------------------- numeric faults
# (workbench stress numerics must fail under each of these, naming the case)
_FLAT_REL_OLD = 1e-24  # the old kernel's degenerate-triangle threshold


@numba.njit(cache=True)
def _old_segment(p, a, b, out):
    e0, e1, e2 = b[0] - a[0], b[1] - a[1], b[2] - a[2]
    length_sq = e0 * e0 + e1 * e1 + e2 * e2
    t = 0.0
    if length_sq > 0.0:
        t = ((p[0] - a[0]) * e0 + (p[1] - a[1]) * e1 + (p[2] - a[2]) * e2) / length_sq
        t = min(max(t, 0.0), 1.0)
    out[0], out[1], out[2] = a[0] + t * e0, a[1] + t * e1, a[2] + t * e2
    d0, d1, d2 = p[0] - out[0], p[1] - out[1], p[2] - out[2]
    return d0 * d0 + d1 * d1 + d2 * d2


@numba.njit(cache=True)
def region_walk_closest_point(p, a, b, c, out):
    """The point–triangle kernel before the backward-stable one: Ericson's Voronoi-region walk
    (*Real-Time Collision Detection* §5.1.5) on barycentric dot products, which overstates the
    distance to slivers by up to tens of percent of their size. Same signature as
    :func:`workbench.algo.nearest.triangle.closest_point_on_triangle` (writes the point into
    ``out``,
    returns the squared distance)."""
    ab0, ab1, ab2 = b[0] - a[0], b[1] - a[1], b[2] - a[2]
    ac0, ac1, ac2 = c[0] - a[0], c[1] - a[1], c[2] - a[2]
    n0 = ab1 * ac2 - ab2 * ac1
    n1 = ab2 * ac0 - ab0 * ac2
    n2 = ab0 * ac1 - ab1 * ac0
    area_sq = n0 * n0 + n1 * n1 + n2 * n2
    scale = (ab0 * ab0 + ab1 * ab1 + ab2 * ab2) * (ac0 * ac0 + ac1 * ac1 + ac2 * ac2)
    if not area_sq > _FLAT_REL_OLD * scale:
        tmp = np.empty(3)
        best = _old_segment(p, a, b, out)
        for s, e in ((b, c), (c, a)):
            d = _old_segment(p, s, e, tmp)
            if d < best:
                best = d
                out[0], out[1], out[2] = tmp[0], tmp[1], tmp[2]
        return best
    ap0, ap1, ap2 = p[0] - a[0], p[1] - a[1], p[2] - a[2]
    d1 = ab0 * ap0 + ab1 * ap1 + ab2 * ap2
    d2 = ac0 * ap0 + ac1 * ap1 + ac2 * ap2
    if d1 <= 0.0 and d2 <= 0.0:
        v = w = 0.0
    else:
        bp0, bp1, bp2 = p[0] - b[0], p[1] - b[1], p[2] - b[2]
        d3 = ab0 * bp0 + ab1 * bp1 + ab2 * bp2
        d4 = ac0 * bp0 + ac1 * bp1 + ac2 * bp2
        cp0, cp1, cp2 = p[0] - c[0], p[1] - c[1], p[2] - c[2]
        d5 = ab0 * cp0 + ab1 * cp1 + ab2 * cp2
        d6 = ac0 * cp0 + ac1 * cp1 + ac2 * cp2
        vc = d1 * d4 - d3 * d2
        vb = d5 * d2 - d1 * d6
        va = d3 * d6 - d5 * d4
        if d3 >= 0.0 and d4 <= d3:
            v, w = 1.0, 0.0
        elif vc <= 0.0 and d1 >= 0.0 and d3 <= 0.0:
            v, w = d1 / (d1 - d3), 0.0
        elif d6 >= 0.0 and d5 <= d6:
            v, w = 0.0, 1.0
        elif vb <= 0.0 and d2 >= 0.0 and d6 <= 0.0:
            v, w = 0.0, d2 / (d2 - d6)
        elif va <= 0.0 and (d4 - d3) >= 0.0 and (d5 - d6) >= 0.0:
            w = (d4 - d3) / ((d4 - d3) + (d5 - d6))
            v = 1.0 - w
        else:
            denom = 1.0 / (va + vb + vc)
            v, w = vb * denom, vc * denom
    out[0] = a[0] + v * ab0 + w * ac0
    out[1] = a[1] + v * ab1 + w * ac1
    out[2] = a[2] + v * ab2 + w * ac2
    e0, e1, e2 = p[0] - out[0], p[1] - out[1], p[2] - out[2]
    return e0 * e0 + e1 * e1 + e2 * e2


@contextmanager
def replaced(module: Any, name: str, value: Any) -> Iterator[Any]:
    """``module.name`` set to ``value`` for the block, restored after it (also on error)."""
    before = getattr(module, name)
    setattr(module, name, value)
    try:
        yield value
    finally:
        setattr(module, name, before)


@contextmanager
def region_walk_kernel() -> Iterator[None]:
    """Fault 1: :func:`region_walk_closest_point` as the point–triangle kernel that Python
    callers look up (``workbench.algo.nearest.triangle.closest_point_on_triangle``; compiled callers
    keep the kernel they were compiled with). The suite's distance check must fail."""
    from ..algo.nearest import triangle as distance

    with replaced(distance, "closest_point_on_triangle", region_walk_closest_point):
        yield


@contextmanager
def unrounded_bounds() -> Iterator[None]:
    """Fault 2: certified bounds not rounded outward by their rounding error — the Hausdorff
    bracket's margin (``workbench.algo.hausdorff.metric.bracket_rounding``) and the
    simplifier's certificate margin (``certificate_rounding`` where
    ``workbench.algo.simplify.decimate`` looks it up) set to 0. The suite's Hausdorff check
    must fail (a bracket that misses the exact value)."""
    from ..algo.hausdorff import metric
    from ..algo.simplify import decimate

    def no_margin(*args, **kwargs):
        return 0.0

    def no_margins(vertices, triangles, tol, depths):
        return np.zeros(len(np.atleast_1d(tol)))

    with replaced(metric, "bracket_rounding", no_margin), \
            replaced(decimate, "certificate_rounding", no_margins):
        yield


@contextmanager
def painted_nan_rim(width: int = 1) -> Iterator[None]:
    """Fault 3a: every image the suite's no-result check receives gets a rim of the scale's
    first colour, ``width`` pixels wide, painted just inside each missing region (as the old
    interpolated sentinel drew one). The check must fail."""
    from scipy import ndimage

    from . import numerics_images

    def deliver(image, region, scale):
        inner = ndimage.binary_erosion(region, np.ones((3, 3), bool), iterations=width)
        rim = region & ~inner
        out = image.copy()
        out[rim, :3] = scale.texture_data()[0, :3]
        return out

    with replaced(numerics_images, "deliver", deliver):
        yield


@contextmanager
def legacy_nan_sentinel() -> Iterator[None]:
    """Fault 3b: the old NaN handling — non-finite values uploaded as the sentinel −1e30 and
    interpolated — in place of ``workbench.paths.colormap.mark_missing`` (where the paths
    look it up there; a no-op where they do not)."""
    from ..paths import colormap

    if not hasattr(colormap, "legacy_mark_missing"):
        yield
        return
    with replaced(colormap, "mark_missing", colormap.legacy_mark_missing):
        yield
