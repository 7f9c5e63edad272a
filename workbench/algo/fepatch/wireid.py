"""The element-id wire frame: outlines computed per fragment from the corners of the elements
around it, a denser encoding than fe2003 §4.2's distance texture.

Two textures hold it:

* the **element map**, one 16-bit (or, for a subpatch of more than 65 534 elements, 32-bit)
  texel per atlas texel: the index, within its subpatch, of the element whose area holds the
  texel's centre; texels no element holds take the element nearest to them up to ``border``
  texels outside a subpatch (so that lookups just outside a subpatch's border still find its
  elements), and :data:`NO_ELEMENT` beyond;
* the **corner table**: each element's four corners in atlas texels, 16-bit fixed point with
  ``frac`` steps per texel (the largest power of two up to 256 that keeps the atlas within 16
  bits), 16 bytes per element (one RGBA32UI texel when uploaded), elements ordered by subpatch
  so that a vertex's subpatch gives the row of its first element.

A fragment at atlas position t reads the four texels around it (the bilinear footprint), takes
the distinct elements they name, and measures the distance from t to the edges of each (line
segments, so a triangle's repeated corner adds nothing). It is on an outline where the smallest
distance is within half a pixel. Every edge it measures is an edge of the mesh, so the encoding
draws no line that is not there (up to the corners' quantisation, 1/(2·frac) texel); it misses
a line only where none of the four texels belongs to an element of that edge. On a flat run of
edges this cannot happen once the elements are about a texel and a half wide: of the four
texels around a point of an edge, one lies on either side of it within a texel
(:data:`MIN_WIDTH`, checked on random meshes by the tests); narrower elements have their edges
drawn as lines.

:func:`element_map` rasterises and dilates the map, :func:`corner_table` quantises the corners,
:func:`outline_distance` reads them back exactly as the fragment shader does.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from workbench.algo.fepatch.wiretex import _check_corners, _check_size

__all__ = ["MIN_WIDTH", "NO_ELEMENT", "corner_table", "element_map", "on_outline",
           "outline_distance"]

# texels: elements at least this wide (element_widths) have every edge point found among the
# four texels around it
MIN_WIDTH = 1.5
NO_ELEMENT = -1
_INSIDE = 1e-9  # barycentric slack: texel centres on an edge count as inside


@njit(cache=True)
def _seg(px, py, ax, ay, bx, by):  # pragma: no cover - compiled
    dx, dy = bx - ax, by - ay
    den = dx * dx + dy * dy
    t = 0.0
    if den > 0.0:
        t = min(max(((px - ax) * dx + (py - ay) * dy) / den, 0.0), 1.0)
    ex, ey = px - ax - t * dx, py - ay - t * dy
    return np.sqrt(ex * ex + ey * ey)


@njit(cache=True)
def _raster_owner(uv, w, h, eps, reach, owner, near):  # pragma: no cover - compiled
    for m in range(uv.shape[0]):
        x_lo = max(int(np.ceil(uv[m, :, 0].min() - reach - 0.5)), 0)
        x_hi = min(int(np.floor(uv[m, :, 0].max() + reach - 0.5)) + 1, w)
        y_lo = max(int(np.ceil(uv[m, :, 1].min() - reach - 0.5)), 0)
        y_hi = min(int(np.floor(uv[m, :, 1].max() + reach - 0.5)) + 1, h)
        for i in range(y_lo, y_hi):
            py = i + 0.5
            for j in range(x_lo, x_hi):
                px = j + 0.5
                inside = False
                for t in range(2):
                    ax, ay = uv[m, 0, 0], uv[m, 0, 1]
                    bx, by = uv[m, 1 + t, 0], uv[m, 1 + t, 1]
                    cx, cy = uv[m, 2 + t, 0], uv[m, 2 + t, 1]
                    area2 = (bx - ax) * (cy - ay) - (cx - ax) * (by - ay)
                    if abs(area2) <= 1e-12:
                        continue
                    la = ((bx - px) * (cy - py) - (cx - px) * (by - py)) / area2
                    lb = ((cx - px) * (ay - py) - (ax - px) * (cy - py)) / area2
                    if la >= -eps and lb >= -eps and 1.0 - la - lb >= -eps:
                        inside = True
                if inside:
                    owner[i, j] = m
                    near[i, j] = -1.0
                    continue
                if near[i, j] < 0.0:
                    continue
                d = np.inf
                for k in range(4):
                    d = min(d, _seg(px, py, uv[m, k, 0], uv[m, k, 1],
                                    uv[m, (k + 1) % 4, 0], uv[m, (k + 1) % 4, 1]))
                if d <= reach and d < near[i, j]:
                    owner[i, j] = m
                    near[i, j] = d


def element_map(corners_uv, size, border: int = 1) -> np.ndarray:
    """(H, W) int32: per texel the element (row of ``corners_uv``) whose area holds its centre,
    the last in order where several do; a texel no element holds takes the element nearest to
    its centre (distance to the element's edges) up to ``border`` texels away, and
    :data:`NO_ELEMENT` beyond.

    ``corners_uv`` (M, 4, 2) element corners in texel units (texel (row i, column j) has its
    centre at (j + ½, i + ½)); a quad covers its triangles (0, 1, 2) and (0, 2, 3), a triangle
    repeats a corner. ``size`` = (W, H). Refuses bad shapes, non-finite corners, a non-positive
    size and a negative border."""
    uv = _check_corners(corners_uv)
    w, h = _check_size(size)
    if not (np.isfinite(border) and border >= 0):
        raise ValueError(f"border must be non-negative, got {border!r}")
    owner = np.full((h, w), NO_ELEMENT, np.int32)
    near = np.full((h, w), np.inf)
    _raster_owner(uv, w, h, _INSIDE, float(border), owner, near)
    return owner


def corner_table(corners_uv, size) -> tuple[np.ndarray, int]:
    """((M, 4, 2) uint16 corners in steps of 1/``frac`` texel, ``frac``): the largest power of two
    ``frac`` ≤ 256 for which every coordinate of an atlas of ``size`` (W, H) fits 16 bits. Corners
    are rounded to the nearest step and clamped to the atlas. Refuses an atlas wider than
    65 535 texels, bad shapes and non-finite corners."""
    uv = _check_corners(corners_uv)
    w, h = _check_size(size)
    frac = 256
    while frac > 1 and max(w, h) * frac > 65535:
        frac //= 2
    if max(w, h) * frac > 65535:
        raise ValueError(f"an atlas of {w}x{h} texels does not fit 16-bit coordinates")
    q = np.clip(np.rint(uv * frac), 0, np.array([w, h]) * frac)
    return q.astype(np.uint16), frac


def _footprint(points: np.ndarray, w: int, h: int) -> tuple[np.ndarray, np.ndarray]:
    """(rows (P, 4), columns (P, 4)) of the four texels around each point (the bilinear
    footprint: texel centres at half-integers), clamped to the atlas as a texel fetch is."""
    x0 = np.floor(points[:, 0] - 0.5).astype(np.int64)
    y0 = np.floor(points[:, 1] - 0.5).astype(np.int64)
    cols = np.clip(np.stack([x0, x0 + 1, x0, x0 + 1], axis=1), 0, w - 1)
    rows = np.clip(np.stack([y0, y0, y0 + 1, y0 + 1], axis=1), 0, h - 1)
    return rows, cols


def _segment_distance(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    ab = b - a
    den = np.einsum("...j,...j->...", ab, ab)
    t = np.where(den > 0, np.einsum("...j,...j->...", p - a, ab) / np.where(den > 0, den, 1.0),
                 0.0)
    t = np.clip(t, 0.0, 1.0)
    return np.linalg.norm(p - (a + t[..., None] * ab), axis=-1)


def outline_distance(element_ids, corners, frac: int, points, base=0,
                     none: int = NO_ELEMENT) -> np.ndarray:
    """(P,) float64 distance in texels from each of ``points`` (P, 2, texel units) to the nearest
    edge of the elements named by the four texels around it, as the fragment shader measures it
    (inf where none names an element).

    ``element_ids`` (H, W): per texel an element index relative to ``base`` (a scalar or (P,),
    per point: the row of its subpatch's first element) or ``none``; :func:`element_map`'s
    global indices with base 0 and :data:`NO_ELEMENT`, or a surface's ``element_map`` with its
    ``element_base`` and ``no_element``. ``corners`` (M, 4, 2) the quantised corners and
    ``frac`` their steps per texel (:func:`corner_table`)."""
    ids_map = np.asarray(element_ids)
    if ids_map.ndim != 2:
        raise ValueError(f"element_ids must be (H, W), got {ids_map.shape}")
    q = np.asarray(corners)
    if q.ndim != 3 or q.shape[1:] != (4, 2):
        raise ValueError(f"corners must be (M, 4, 2), got {q.shape}")
    pts = np.asarray(points, np.float64)
    if pts.ndim != 2 or pts.shape[1] != 2 or not np.isfinite(pts).all():
        raise ValueError("points must be (P, 2) and finite")
    first = np.broadcast_to(np.asarray(base, np.int64), (len(pts),))
    h, w = ids_map.shape
    c = q.astype(np.float64) / frac
    rows, cols = _footprint(pts, w, h)
    ids = ids_map[rows, cols].astype(np.int64)  # (P, 4)
    best = np.full(len(pts), np.inf)
    for k in range(4):
        ok = ids[:, k] != none
        if not ok.any():
            continue
        corner = c[first[ok] + ids[ok, k]]  # (p, 4, 2)
        p = pts[ok][:, None, :]
        d = _segment_distance(p, corner, np.roll(corner, -1, axis=1)).min(axis=1)
        best[ok] = np.minimum(best[ok], d)
    return best


def on_outline(surface, points, h: float, base=0) -> np.ndarray:
    """(P,) bool: whether ``points`` (P, 2, texel units) lie on an outline of ``surface``'s wire
    frame, either encoding, as the fragment shader decides with ``h`` texels for half a pixel
    (the distance texture: :func:`workbench.algo.fepatch.wiretex.on_outline`; element ids and
    corners: :func:`outline_distance` ≤ h, ``base`` per point the row of its subpatch's first
    element, a vertex's ``element_base``). Refuses a surface without a wire frame."""
    from workbench.algo.fepatch.wiretex import on_outline as on_distance_outline

    if surface.wire_map is not None:
        return on_distance_outline(surface.wire_map, points, h, surface.wire_range)
    if surface.element_map is None:
        raise ValueError("the surface has no wire frame")
    if not h > 0:
        raise ValueError(f"h must be positive, got {h}")
    return outline_distance(surface.element_map, surface.corner_table, surface.corner_frac,
                            points, base, surface.no_element) <= h
