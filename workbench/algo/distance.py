"""Exact float64 point-to-triangle distances and certified bounds of a triangle's farthest point.

The building blocks of the Hausdorff metric (:mod:`workbench.algo.hausdorff`) and of the
Hausdorff-bounded decimator (:mod:`workbench.algo.simplify`), compiled with numba:

* :func:`closest_point_on_triangle` -- the closest point of a triangle to a point, by the
  Voronoi-region walk of Ericson (*Real-Time Collision Detection*, §5.1.5). A degenerate
  triangle (repeated vertices, collinear vertices, zero area to rounding) is the union of its
  three edges and is treated as such, so the result is never NaN.
* :func:`triangle_bounds` -- lower and upper bounds of ``max_{p ∈ T} d(p, F)``, the farthest a
  point of triangle T gets from a set F of triangles. The distance to one triangle is a convex
  function of p, so on T it peaks at a corner: ``max_{p∈T} d(p, f) = max_i d(t_i, f)`` and
  ``min_f max_i d(t_i, f)`` is an upper bound for the union. Where no single f certifies it
  tightly, T is split into four at its edge midpoints (to a depth limit) and the bound is the
  largest over the pieces. The lower bound is the largest distance seen at any corner.

All inputs are float64 in model units; translate far-away geometry near the origin first
(:func:`workbench.algo.hausdorff.hausdorff` does) so differences keep their digits.
"""

from __future__ import annotations

import numba
import numpy as np

__all__ = ["closest_point_on_triangle", "point_triangle_distance", "points_triangles_distance",
           "triangle_bounds"]

# a triangle whose doubled area squared is below this share of |ab|²·|ac|² is degenerate
_DEGENERATE_REL = 1e-24


@numba.njit(cache=True, inline="always")
def _dot(a0, a1, a2, b0, b1, b2):
    return a0 * b0 + a1 * b1 + a2 * b2


@numba.njit(cache=True)
def _closest_on_segment(p, a, b, out):
    """Closest point of segment ab to p into out; returns the squared distance."""
    e0, e1, e2 = b[0] - a[0], b[1] - a[1], b[2] - a[2]
    length_sq = _dot(e0, e1, e2, e0, e1, e2)
    t = 0.0
    if length_sq > 0.0:
        t = _dot(p[0] - a[0], p[1] - a[1], p[2] - a[2], e0, e1, e2) / length_sq
        t = min(max(t, 0.0), 1.0)
    out[0], out[1], out[2] = a[0] + t * e0, a[1] + t * e1, a[2] + t * e2
    d0, d1, d2 = p[0] - out[0], p[1] - out[1], p[2] - out[2]
    return _dot(d0, d1, d2, d0, d1, d2)


@numba.njit(cache=True)
def closest_point_on_triangle(p, a, b, c, out):
    """The point of triangle abc closest to p, written into ``out`` (3,); returns the squared
    distance. p, a, b, c are float64 (3,) arrays."""
    ab0, ab1, ab2 = b[0] - a[0], b[1] - a[1], b[2] - a[2]
    ac0, ac1, ac2 = c[0] - a[0], c[1] - a[1], c[2] - a[2]
    n0 = ab1 * ac2 - ab2 * ac1
    n1 = ab2 * ac0 - ab0 * ac2
    n2 = ab0 * ac1 - ab1 * ac0
    area_sq = _dot(n0, n1, n2, n0, n1, n2)
    scale = _dot(ab0, ab1, ab2, ab0, ab1, ab2) * _dot(ac0, ac1, ac2, ac0, ac1, ac2)
    if not area_sq > _DEGENERATE_REL * scale:  # also catches scale == 0 (repeated vertices)
        tmp = np.empty(3)
        best = _closest_on_segment(p, a, b, out)
        for s, e in ((b, c), (c, a)):
            d = _closest_on_segment(p, s, e, tmp)
            if d < best:
                best = d
                out[0], out[1], out[2] = tmp[0], tmp[1], tmp[2]
        return best
    ap0, ap1, ap2 = p[0] - a[0], p[1] - a[1], p[2] - a[2]
    d1 = _dot(ab0, ab1, ab2, ap0, ap1, ap2)
    d2 = _dot(ac0, ac1, ac2, ap0, ap1, ap2)
    if d1 <= 0.0 and d2 <= 0.0:
        v = w = 0.0
    else:
        bp0, bp1, bp2 = p[0] - b[0], p[1] - b[1], p[2] - b[2]
        d3 = _dot(ab0, ab1, ab2, bp0, bp1, bp2)
        d4 = _dot(ac0, ac1, ac2, bp0, bp1, bp2)
        cp0, cp1, cp2 = p[0] - c[0], p[1] - c[1], p[2] - c[2]
        d5 = _dot(ab0, ab1, ab2, cp0, cp1, cp2)
        d6 = _dot(ac0, ac1, ac2, cp0, cp1, cp2)
        vc = d1 * d4 - d3 * d2
        vb = d5 * d2 - d1 * d6
        va = d3 * d6 - d5 * d4
        if d3 >= 0.0 and d4 <= d3:  # vertex b
            v, w = 1.0, 0.0
        elif vc <= 0.0 and d1 >= 0.0 and d3 <= 0.0:  # edge ab
            v, w = d1 / (d1 - d3), 0.0
        elif d6 >= 0.0 and d5 <= d6:  # vertex c
            v, w = 0.0, 1.0
        elif vb <= 0.0 and d2 >= 0.0 and d6 <= 0.0:  # edge ac
            v, w = 0.0, d2 / (d2 - d6)
        elif va <= 0.0 and (d4 - d3) >= 0.0 and (d5 - d6) >= 0.0:  # edge bc
            w = (d4 - d3) / ((d4 - d3) + (d5 - d6))
            v = 1.0 - w
        else:  # inside the face
            denom = 1.0 / (va + vb + vc)
            v, w = vb * denom, vc * denom
    out[0] = a[0] + v * ab0 + w * ac0
    out[1] = a[1] + v * ab1 + w * ac1
    out[2] = a[2] + v * ab2 + w * ac2
    e0, e1, e2 = p[0] - out[0], p[1] - out[1], p[2] - out[2]
    return _dot(e0, e1, e2, e0, e1, e2)


@numba.njit(cache=True)
def point_triangle_distance(p, a, b, c):
    """Euclidean distance from p to triangle abc (float64, model units)."""
    out = np.empty(3)
    return np.sqrt(closest_point_on_triangle(p, a, b, c, out))


@numba.njit(cache=True)
def _points_triangles(points, tri):
    out = np.empty((len(points), len(tri)))
    tmp = np.empty(3)
    for i in range(len(points)):
        for j in range(len(tri)):
            out[i, j] = np.sqrt(closest_point_on_triangle(points[i], tri[j, 0], tri[j, 1],
                                                          tri[j, 2], tmp))
    return out


def points_triangles_distance(points, triangles) -> np.ndarray:
    """(P, T) distances from each of ``points`` (P, 3) to each triangle of ``triangles``
    (T, 3, 3) corner coordinates: brute force, for checks and small inputs."""
    p = np.ascontiguousarray(points, np.float64).reshape(-1, 3)
    t = np.ascontiguousarray(triangles, np.float64).reshape(-1, 3, 3)
    return _points_triangles(p, t)


@numba.njit(cache=True)
def _corner_distances(t, faces, out):
    """out[i, f] = d(t[i], faces[f]) for the three corners of t."""
    tmp = np.empty(3)
    for i in range(3):
        for f in range(len(faces)):
            out[i, f] = np.sqrt(closest_point_on_triangle(t[i], faces[f, 0], faces[f, 1],
                                                          faces[f, 2], tmp))


@numba.njit(cache=True)
def triangle_bounds(t, faces, target, max_depth):
    """(lower, upper) bounds of max over the points p of triangle ``t`` (3, 3) of the distance
    from p to the union of ``faces`` (F, 3, 3).

    Pieces are split (four ways, at edge midpoints) while their upper bound exceeds ``target``
    and their depth is below ``max_depth``; with ``target`` at or above the true value the upper
    bound comes out ≤ ``target`` as soon as the depth allows. F must be ≥ 1.
    """
    n_faces = len(faces)
    # an explicit stack of pieces (corner coordinates, depth)
    stack = np.empty((4 * max_depth + 4, 3, 3))
    depth = np.empty(4 * max_depth + 4, np.int64)
    stack[0] = t
    depth[0] = 0
    top = 1
    dist = np.empty((3, n_faces))
    lower = 0.0
    upper = 0.0
    while top > 0:
        top -= 1
        piece = stack[top].copy()
        level = depth[top]
        _corner_distances(piece, faces, dist)
        piece_upper = np.inf
        for f in range(n_faces):
            worst = max(dist[0, f], max(dist[1, f], dist[2, f]))
            if worst < piece_upper:
                piece_upper = worst
        for i in range(3):
            nearest = dist[i, 0]
            for f in range(1, n_faces):
                nearest = min(nearest, dist[i, f])
            lower = max(lower, nearest)
        if piece_upper <= target or level >= max_depth or piece_upper <= lower:
            upper = max(upper, piece_upper)
            continue
        m01 = 0.5 * (piece[0] + piece[1])
        m12 = 0.5 * (piece[1] + piece[2])
        m20 = 0.5 * (piece[2] + piece[0])
        for k in range(4):
            if k == 0:
                stack[top, 0], stack[top, 1], stack[top, 2] = piece[0], m01, m20
            elif k == 1:
                stack[top, 0], stack[top, 1], stack[top, 2] = m01, piece[1], m12
            elif k == 2:
                stack[top, 0], stack[top, 1], stack[top, 2] = m20, m12, piece[2]
            else:
                stack[top, 0], stack[top, 1], stack[top, 2] = m12, m20, m01
            depth[top] = level + 1
            top += 1
    return lower, max(upper, lower)
