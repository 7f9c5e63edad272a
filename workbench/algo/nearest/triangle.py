"""Backward-stable float64 point-to-triangle distances, their error model, and bounds of a
triangle's farthest point.

The building blocks of the Hausdorff metric (:mod:`workbench.algo.hausdorff`) and of the
Hausdorff-bounded decimator (:mod:`workbench.algo.simplify`), compiled with numba:

* :func:`closest_point_on_triangle` -- the closest point of a triangle to a point, in a frame
  set on the triangle's longest edge and orthogonalised twice, so that slivers, needles and
  collinear corners keep their accuracy (the Voronoi-region walk of Ericson, *Real-Time
  Collision Detection* §5.1.5, loses it to cancellation: up to a third of the triangle's size
  for a corner 1e-7…1e-11 of it from an edge or another corner). A triangle whose height is
  at most 2⁻⁵³ of its longest edge is the union of its three edges, so the result is never
  NaN.
* :func:`triangle_bounds` -- lower and upper bounds of ``max_{p ∈ T} d(p, F)``, the farthest a
  point of triangle T gets from a set F of triangles. The distance to one triangle is a convex
  function of p, so on T it peaks at a corner: ``max_{p∈T} d(p, f) = max_i d(t_i, f)`` and
  ``min_f max_i d(t_i, f)`` is an upper bound for the union. Where no single f certifies it
  tightly, T is split into four at its edge midpoints (to a depth limit) and the bound is the
  largest over the pieces. The lower bound is the largest distance seen at any corner.

All inputs are float64 in model units; translate far-away geometry near the origin first
(:func:`workbench.algo.hausdorff.hausdorff` does) so differences keep their digits.

**Error model** (u = 2⁻⁵³, the unit roundoff; first order in u). Let ``R = max_i |p − corner_i|``.

* The distance of :func:`closest_point_on_triangle` is within ``DISTANCE_ERROR · u · R``
  (64 u R, about 7e-15 R) of the exact one. Derivation: the differences p − o and the edges
  carry a relative u, which moves p and the corners by at most u R and 2 u R; the frame on the
  longest edge e (``|e| <= 2R``) is orthogonal to within 3 u after two Gram–Schmidt passes, and
  the orthogonalised third corner moves by at most ``4 u |e|``; the projection coordinates and the
  plane distance ``(q·n)/|n|`` carry at most ``8 u |q|``; a wrong inside/outside decision happens
  only within 10 u R of an edge line, where face and edge distances agree to that; a segment
  distance carries at most 10 u R. Summed, 32 u R; the constant doubles it. The worst seen
  against exact rational arithmetic on adversarial inputs (``workbench stress numerics``) is
  under 3 u R. It holds for triangles of any size whose squared distances are in float64's
  range (distances between about 1e-154 and 1e154; a triangle far below or above unit size is
  measured scaled by a power of two, exactly). Because R <= d + (the triangle's longest
  edge), the error of a distance d to a triangle of longest edge D is at most
  :func:`distance_rounding` (d, D); that also bounds the error of a minimum over triangles of
  longest edge <= D.
* A point built from others by one interpolation (``a + t(b − a)``, a midpoint, a centroid, a
  translation of the model) lies within ``CONSTRUCTION_ERROR · u · M`` of the exact point, M the
  largest coordinate norm; L nested constructions within L times that
  (:func:`construction_rounding`). The distance to a surface moves by at most as much as the
  point (it is 1-Lipschitz), and a convex piece whose corners were built so still covers its
  exact counterpart to within that distance.

Certificates built on these kernels (the Hausdorff bracket, the simplifier's bounds) widen their
lower and upper bounds by both terms (:func:`outward`); :func:`triangle_bounds` itself returns
the computed values.
"""

from __future__ import annotations

import math

import numba
import numpy as np

__all__ = ["CONSTRUCTION_ERROR", "DISTANCE_ERROR", "UNIT_ROUNDOFF", "closest_point_on_triangle",
           "construction_rounding", "distance_rounding", "outward", "point_triangle_distance",
           "points_triangles_distance", "triangle_bounds"]

UNIT_ROUNDOFF = 2.0 ** -53  # u: float64 rounds every operation to within a relative u
# |computed − exact| point–triangle distance <= DISTANCE_ERROR · u · R (see the error model)
DISTANCE_ERROR = 64.0
# a point built by one interpolation (a midpoint, a centroid, a cut point, a translation) lies
# within CONSTRUCTION_ERROR · u · M of the exact point (M the largest coordinate norm)
CONSTRUCTION_ERROR = 8.0

# a triangle whose height over its longest edge is at most this share of that edge (float64's
# unit roundoff) is within that height of its edges, and is measured as its three edges
_FLAT_REL = 2.0 ** -53
# the squared longest edge the kernel computes with directly: beyond, the squared normal
# (its fourth power) would underflow or overflow, and the triangle is measured scaled
_EDGE_SQ_MIN = 2.0 ** -500
_EDGE_SQ_MAX = 2.0 ** 500
# a triangle smaller than 2^-400 of a point's distance is that far a point (scaling it to unit
# size would overflow the point's offset)
_POINT_LIKE = 2.0 ** 400


@numba.njit(cache=True, inline="always")
def _dot(a0, a1, a2, b0, b1, b2):
    return a0 * b0 + a1 * b1 + a2 * b2


@numba.njit(cache=True, inline="always")
def _segment_sq(p0, p1, p2, a0, a1, a2, e0, e1, e2):
    """(squared distance, t) from point p to the segment a + t·e, t in [0, 1]."""
    ee = _dot(e0, e1, e2, e0, e1, e2)
    q0, q1, q2 = p0 - a0, p1 - a1, p2 - a2
    t = 0.0
    if ee > 0.0:
        t = min(max(_dot(q0, q1, q2, e0, e1, e2) / ee, 0.0), 1.0)
    d0, d1, d2 = q0 - t * e0, q1 - t * e1, q2 - t * e2
    return _dot(d0, d1, d2, d0, d1, d2), t


@numba.njit(cache=True)
def _closest_sq(p0, p1, p2, a0, a1, a2, b0, b1, b2, c0, c1, c2):
    """(squared distance, closest point x, y, z) from p to triangle abc, from scalars: the
    kernel of :func:`closest_point_on_triangle` (scalar arguments: no array passing per call).

    A triangle whose longest edge lies outside [2⁻²⁵⁰, 2²⁵⁰] (where the squared normal, the
    fourth power of its size, would underflow or overflow) is measured with every difference to
    its first corner scaled by a power of two that brings that edge near 1 (exact), and the
    result scaled back; one smaller than 2⁻⁴⁰⁰ of the point's offset is measured as its nearest
    corner. A squared distance outside float64's range (a distance below about
    1e-154 or above about 1e154) underflows to 0 or overflows to inf."""
    d, o0, o1, o2, fits = _closest_core(p0, p1, p2, a0, a1, a2, b0, b1, b2, c0, c1, c2)
    if fits:
        return d, o0, o1, o2
    longest = max(abs(b0 - a0), abs(b1 - a1), abs(b2 - a2), abs(c0 - a0), abs(c1 - a1),
                  abs(c2 - a2), abs(c0 - b0), abs(c1 - b1), abs(c2 - b2))
    reach = max(abs(p0 - a0), abs(p1 - a1), abs(p2 - a2))
    if reach > _POINT_LIKE * longest:
        # the triangle is a point at the distance's resolution (its size below 2^-400 of the
        # distance): the nearest corner, off by at most that size
        best, o0, o1, o2 = _dot(p0 - a0, p1 - a1, p2 - a2, p0 - a0, p1 - a1, p2 - a2), a0, a1, a2
        d = _dot(p0 - b0, p1 - b1, p2 - b2, p0 - b0, p1 - b1, p2 - b2)
        if d < best:
            best, o0, o1, o2 = d, b0, b1, b2
        d = _dot(p0 - c0, p1 - c1, p2 - c2, p0 - c0, p1 - c1, p2 - c2)
        if d < best:
            best, o0, o1, o2 = d, c0, c1, c2
        return best, o0, o1, o2
    k = math.frexp(longest)[1]
    # 2^-k in two factors: one would overflow for a subnormal edge (k below -1023)
    f1, f2 = math.ldexp(1.0, -(k // 2)), math.ldexp(1.0, -(k - k // 2))
    d, o0, o1, o2, _ = _closest_core((p0 - a0) * f1 * f2, (p1 - a1) * f1 * f2,
                                     (p2 - a2) * f1 * f2, 0.0, 0.0, 0.0, (b0 - a0) * f1 * f2,
                                     (b1 - a1) * f1 * f2, (b2 - a2) * f1 * f2,
                                     (c0 - a0) * f1 * f2, (c1 - a1) * f1 * f2,
                                     (c2 - a2) * f1 * f2)
    return (math.ldexp(d, 2 * k), a0 + math.ldexp(o0, k), a1 + math.ldexp(o1, k),
            a2 + math.ldexp(o2, k))


@numba.njit(cache=True)
def _closest_core(p0, p1, p2, a0, a1, a2, b0, b1, b2, c0, c1, c2):
    """:func:`_closest_sq` for a triangle whose longest edge lies in [2⁻²⁵⁰, 2²⁵⁰], or whose
    corners are equal: (squared distance, closest point, True); (0, 0, 0, 0, False) for any
    other."""
    ab0, ab1, ab2 = b0 - a0, b1 - a1, b2 - a2
    bc0, bc1, bc2 = c0 - b0, c1 - b1, c2 - b2
    ca0, ca1, ca2 = a0 - c0, a1 - c1, a2 - c2
    lab = _dot(ab0, ab1, ab2, ab0, ab1, ab2)
    lbc = _dot(bc0, bc1, bc2, bc0, bc1, bc2)
    lca = _dot(ca0, ca1, ca2, ca0, ca1, ca2)
    # o the start of the longest edge e, w from o to the third corner
    if lab >= lbc and lab >= lca:
        o0, o1, o2, e0, e1, e2, w0, w1, w2, ee = a0, a1, a2, ab0, ab1, ab2, -ca0, -ca1, \
            -ca2, lab
    elif lbc >= lca:
        o0, o1, o2, e0, e1, e2, w0, w1, w2, ee = b0, b1, b2, bc0, bc1, bc2, -ab0, -ab1, \
            -ab2, lbc
    else:
        o0, o1, o2, e0, e1, e2, w0, w1, w2, ee = c0, c1, c2, ca0, ca1, ca2, -bc0, -bc1, \
            -bc2, lca
    if ee > _EDGE_SQ_MAX or (ee < _EDGE_SQ_MIN and (ab0 != 0.0 or ab1 != 0.0 or ab2 != 0.0
                                                     or ca0 != 0.0 or ca1 != 0.0
                                                     or ca2 != 0.0)):
        return 0.0, 0.0, 0.0, 0.0, False
    q0, q1, q2 = p0 - o0, p1 - o1, p2 - o2
    if ee > 0.0:
        # h: the third corner's offset orthogonal to e, twice orthogonalised
        s = _dot(w0, w1, w2, e0, e1, e2) / ee
        h0, h1, h2 = w0 - s * e0, w1 - s * e1, w2 - s * e2
        s2 = _dot(h0, h1, h2, e0, e1, e2) / ee
        h0, h1, h2 = h0 - s2 * e0, h1 - s2 * e1, h2 - s2 * e2
        s += s2
        hh = _dot(h0, h1, h2, h0, h1, h2)
        if hh > _FLAT_REL * _FLAT_REL * ee:
            # p = o + x·e + y·h + z·n; the triangle is (0, 0), (1, 0), (s, 1) in (x, y)
            x = _dot(q0, q1, q2, e0, e1, e2) / ee
            y = _dot(q0, q1, q2, h0, h1, h2) / hh
            if y >= 0.0 and x >= s * y and x <= 1.0 + (s - 1.0) * y:
                n0 = e1 * h2 - e2 * h1
                n1 = e2 * h0 - e0 * h2
                n2 = e0 * h1 - e1 * h0
                nn = _dot(n0, n1, n2, n0, n1, n2)
                qn = _dot(q0, q1, q2, n0, n1, n2)
                t = qn / nn
                return qn * t, p0 - t * n0, p1 - t * n1, p2 - t * n2, True
    else:  # three equal corners
        return _dot(q0, q1, q2, q0, q1, q2), a0, a1, a2, True
    # outside the face (or a flat triangle): the nearest of the three edges
    best, t = _segment_sq(p0, p1, p2, a0, a1, a2, ab0, ab1, ab2)
    s0, s1, s2_, f0, f1, f2 = a0, a1, a2, ab0, ab1, ab2
    d, u = _segment_sq(p0, p1, p2, b0, b1, b2, bc0, bc1, bc2)
    if d < best:
        best, t, s0, s1, s2_, f0, f1, f2 = d, u, b0, b1, b2, bc0, bc1, bc2
    d, u = _segment_sq(p0, p1, p2, c0, c1, c2, ca0, ca1, ca2)
    if d < best:
        best, t, s0, s1, s2_, f0, f1, f2 = d, u, c0, c1, c2, ca0, ca1, ca2
    return best, s0 + t * f0, s1 + t * f1, s2_ + t * f2, True


@numba.njit(cache=True, inline="always")
def closest_point_on_triangle(p, a, b, c, out):
    """The point of triangle abc closest to p, written into ``out`` (3,); returns the squared
    distance. p, a, b, c are float64 (3,) arrays.

    Backward stable: the result is the exact answer for inputs moved by a few units in the last
    place of ``|p − corner|`` and of the triangle's size, for every triangle (slivers, needles,
    collinear and repeated corners), so the distance is within a few 1e-16 of
    ``max_i |p − corner_i|`` of the exact one (the distance moves by at most as much as a corner
    does). How: the frame is set on the longest edge e (from corner o), the third corner's
    offset from it is orthogonalised against e twice (Gram–Schmidt, so the frame is orthogonal
    to rounding however thin the triangle), and p's coordinates in that frame decide whether
    its projection falls inside; an error in that decision only happens within rounding of an
    edge, where the face and the edge give the same distance to rounding. Outside, the nearest
    of the three edges (projections on segments are backward stable) gives the point. A triangle
    whose height is at most 2⁻⁵³ of its longest edge is its three edges.
    """
    d, out[0], out[1], out[2] = _closest_sq(p[0], p[1], p[2], a[0], a[1], a[2], b[0], b[1],
                                            b[2], c[0], c[1], c[2])
    return d


def distance_rounding(distance, diameter) -> float:
    """Bound (model units) of the rounding error of a computed distance ``distance`` to a
    triangle (or the least over triangles) whose longest edge is at most ``diameter``:
    ``DISTANCE_ERROR · u · (distance + diameter)``, rounded up (see the error model)."""
    bound = DISTANCE_ERROR * UNIT_ROUNDOFF * (float(distance) + float(diameter))
    return float(np.nextafter(bound * (1.0 + 4.0 * UNIT_ROUNDOFF), np.inf))


def construction_rounding(magnitude, levels) -> float:
    """Bound (model units) of how far a point built by ``levels`` nested interpolations of
    points of norm at most ``magnitude`` lies from the exact point (see the error model)."""
    bound = CONSTRUCTION_ERROR * UNIT_ROUNDOFF * float(magnitude) * float(levels)
    return float(np.nextafter(bound * (1.0 + 4.0 * UNIT_ROUNDOFF), np.inf))


def outward(lower, upper, margin) -> tuple[float, float]:
    """``(lower − margin, upper + margin)`` rounded down and up (lower at least 0): a computed
    bracket widened by the bound of its rounding error so that it holds the exact value."""
    lo = max(0.0, float(np.nextafter(float(lower) - float(margin), -np.inf)))
    hi = float(np.nextafter(float(upper) + float(margin), np.inf))
    return lo, hi


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
