"""Exact planar references for the numerical stress suite: slices of tetrahedra and pixel
coverage, in rational or exact integer arithmetic, sharing no code with :mod:`workbench.algo`.

* :func:`tet_slice_area` -- the area of the plane t = const through a spacetime tetrahedron
  (x, y, t corners), exactly: the convex hull of the points where its edges meet the plane.
* :func:`hull_area` -- the area of the convex hull of rational points (Andrew's monotone chain).
* :func:`window_exact` and :func:`snap_exact` -- GL window coordinates of model points through
  a 4 × 4 matrix, as Fractions, and their fixed-point image coordinates by the rasterization
  rule's snapping (``round((w − ½)·2^b)``, halves to even, y turned over).
* :func:`coverage` -- which pixel centres each triangle of fixed-point corners covers under
  the top-left tie rule (covered where every edge function is > 0, or = 0 on a *left* edge
  (dy < 0) or a *bottom* edge (dy = 0, dx < 0) of the triangle turned to positive area in
  image coordinates, y down), counted per pixel, with the lowest covering triangle index.
* :func:`strictly_inside` -- pixel centres strictly inside a closed polygon (winding number ≠ 0,
  no centre on an edge), exactly.

Integer arrays are int64 after a check that no product can overflow (``|coordinates| < 2^30``).
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np

__all__ = ["coverage", "hull_area", "snap_exact", "strictly_inside", "tet_slice_area",
           "window_exact"]

_LIMIT = 1 << 30


def hull_area(points) -> Fraction:
    """The area of the convex hull of ``points`` (pairs of exact numbers), as a Fraction: 0 for
    fewer than three points or collinear ones."""
    pts = sorted({(Fraction(x), Fraction(y)) for x, y in points})
    if len(pts) < 3:
        return Fraction(0)

    def cross(o, a, b):
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    lower, upper = [], []
    for p in pts:
        while len(lower) >= 2 and cross(lower[-2], lower[-1], p) <= 0:
            lower.pop()
        lower.append(p)
    for p in reversed(pts):
        while len(upper) >= 2 and cross(upper[-2], upper[-1], p) <= 0:
            upper.pop()
        upper.append(p)
    hull = lower[:-1] + upper[:-1]
    twice = sum((hull[i][0] * hull[(i + 1) % len(hull)][1]
                 - hull[(i + 1) % len(hull)][0] * hull[i][1] for i in range(len(hull))),
                Fraction(0))
    return abs(twice) / 2


def tet_slice_area(corners, t) -> Fraction:
    """The exact area of the slice t = const of the tetrahedron ``corners`` (4 rows of x, y, t;
    floats, converted exactly), as a Fraction: 0 unless some corner has t_v < t and some
    t_v ≥ t (the half-open rule of the slicer), else the hull of the points
    ``x_b + (t − t_b)/(t_a − t_b)·(x_a − x_b)`` on the edges from a corner below to one above
    (these include every corner lying in the plane, so the hull is the whole section)."""
    c = [tuple(Fraction(float(v)) for v in row) for row in corners]
    t = Fraction(float(t))
    below = [p for p in c if p[2] < t]
    above = [p for p in c if p[2] >= t]
    if not below or not above:
        return Fraction(0)
    points = []
    for b in below:
        for a in above:
            w = (t - b[2]) / (a[2] - b[2])
            points.append((b[0] + w * (a[0] - b[0]), b[1] + w * (a[1] - b[1])))
    return hull_area(points)


def window_exact(points, matrix, size) -> list[tuple[Fraction, Fraction, Fraction]]:
    """GL window coordinates (x right, y up, in pixels; depth in [0, 1]) of model ``points``
    (N, 3) through the clip matrix ``matrix`` (4, 4) into an image ``size`` (W, H), exactly:
    ``ndc = (M·p)_xyz / (M·p)_w``, ``x = ndc_x·W/2 + W/2``, ``y = ndc_y·H/2 + H/2``,
    ``z = ndc_z/2 + 1/2``."""
    m = [[Fraction(float(v)) for v in row] for row in np.asarray(matrix, np.float64)]
    half_w, half_h = Fraction(int(size[0]), 2), Fraction(int(size[1]), 2)
    out = []
    for p in np.asarray(points, np.float64):
        q = [Fraction(float(v)) for v in p] + [Fraction(1)]
        clip = [sum((m[r][k] * q[k] for k in range(4)), Fraction(0)) for r in range(4)]
        nx, ny, nz = (clip[r] / clip[3] for r in range(3))
        out.append((nx * half_w + half_w, ny * half_h + half_h, nz / 2 + Fraction(1, 2)))
    return out


def snap_exact(window, height: int, bits: int = 8) -> np.ndarray:
    """(N, 2) int64 fixed-point image coordinates of exact window coordinates ``window``
    (pairs, y up): ``round((w − ½)·2^bits)`` with halves to even, y turned over
    (``(H − 1)·2^bits − round((w_y − ½)·2^bits)``). Refuses coordinates beyond 2^30."""
    scale = 1 << int(bits)
    out = []
    for wx, wy, *_ in window:
        x = round((Fraction(wx) - Fraction(1, 2)) * scale)  # Fraction.__round__: half to even
        y = ((int(height) - 1) << int(bits)) - round((Fraction(wy) - Fraction(1, 2)) * scale)
        if abs(x) >= _LIMIT or abs(y) >= _LIMIT:
            raise ValueError("fixed-point coordinates beyond 2^30")
        out.append((x, y))
    return np.array(out, np.int64).reshape(-1, 2)


def coverage(fixed, size, bits: int = 8) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(count, first, area_sign)`` of triangles ``fixed`` (T, 3, 2) fixed-point image
    coordinates in an image ``size`` (W, H): ``count`` (H, W) how many triangles cover each
    pixel centre (at (i·2^bits, j·2^bits)) under the top-left rule, ``first`` (H, W) the lowest
    index of a covering triangle (−1: none), ``area_sign`` (T,) the sign of each triangle's
    area in image coordinates (y down) as given (negative: counter-clockwise in GL's window
    coordinates, a front face by default; 0 covers nothing)."""
    fixed = np.asarray(fixed, np.int64).reshape(-1, 3, 2)
    if len(fixed) and np.abs(fixed).max() >= _LIMIT:
        raise ValueError("fixed-point coordinates beyond 2^30")
    width, height = (int(v) for v in size)
    count = np.zeros((height, width), np.int64)
    first = np.full((height, width), -1, np.int64)
    sign = np.zeros(len(fixed), np.int64)
    for k, tri in enumerate(fixed):
        (x0, y0), (x1, y1), (x2, y2) = (tuple(int(v) for v in row) for row in tri)
        area = (x1 - x0) * (y2 - y0) - (y1 - y0) * (x2 - x0)
        sign[k] = (area > 0) - (area < 0)
        if area == 0:
            continue
        if area < 0:
            (x1, y1), (x2, y2) = (x2, y2), (x1, y1)
        i0 = max(0, -((-min(x0, x1, x2)) >> bits))
        i1 = min(width - 1, max(x0, x1, x2) >> bits)
        j0 = max(0, -((-min(y0, y1, y2)) >> bits))
        j1 = min(height - 1, max(y0, y1, y2) >> bits)
        if i0 > i1 or j0 > j1:
            continue
        jj, ii = np.mgrid[j0:j1 + 1, i0:i1 + 1].astype(np.int64)
        px, py = ii << bits, jj << bits
        inside = np.ones(px.shape, bool)
        for (ax, ay), (bx, by) in (((x0, y0), (x1, y1)), ((x1, y1), (x2, y2)),
                                   ((x2, y2), (x0, y0))):
            dx, dy = bx - ax, by - ay
            e = dx * (py - ay) - dy * (px - ax)
            tie = dy < 0 or (dy == 0 and dx < 0)
            inside &= (e > 0) | ((e == 0) & tie)
        count[j0:j1 + 1, i0:i1 + 1] += inside
        block = first[j0:j1 + 1, i0:i1 + 1]
        block[inside & (block < 0)] = k
    return count, first, sign


def strictly_inside(polygon, size, bits: int = 8) -> np.ndarray:
    """(H, W) bool: pixel centres strictly inside the closed polygon ``polygon`` (P, 2)
    fixed-point image coordinates (non-zero winding number, and on none of its edges)."""
    poly = np.asarray(polygon, np.int64).reshape(-1, 2)
    width, height = (int(v) for v in size)
    jj, ii = np.mgrid[0:height, 0:width].astype(np.int64)
    px, py = ii << bits, jj << bits
    winding = np.zeros((height, width), np.int64)
    on_edge = np.zeros((height, width), bool)
    for (ax, ay), (bx, by) in zip(poly, np.roll(poly, -1, axis=0)):
        ax, ay, bx, by = int(ax), int(ay), int(bx), int(by)
        cross = (bx - ax) * (py - ay) - (by - ay) * (px - ax)
        on_edge |= (cross == 0) & (np.minimum(ax, bx) <= px) & (px <= np.maximum(ax, bx)) \
            & (np.minimum(ay, by) <= py) & (py <= np.maximum(ay, by))
        up = (ay <= py) & (by > py) & (cross > 0)
        down = (ay > py) & (by <= py) & (cross < 0)
        winding += up.astype(np.int64) - down.astype(np.int64)
    return (winding != 0) & ~on_edge
