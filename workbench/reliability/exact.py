"""Exact rational references for the numerical stress suite and the tests.

Everything here computes with :class:`fractions.Fraction` from the float64 inputs, which are
converted exactly, and shares no code with the production kernels (:mod:`workbench.algo`): it
is the independent answer they are checked against, slow and plain on purpose.

* :func:`point_triangle_sq` -- the exact squared distance from a point to a (possibly
  degenerate) triangle. The closest point of a triangle with rational corners to a rational
  point is rational (a projection onto a plane or a segment), so the squared distance is an
  exact rational number.
* :func:`point_triangle_distance` -- its square root rounded to float64 (correctly rounded to
  within one unit in the last place).
* :func:`points_mesh_distance` -- the exact distance of each point to the union of triangles.
* :func:`polygon_area2` -- twice the signed area of a planar polygon, exactly.
"""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np

__all__ = ["point_triangle_distance", "point_triangle_sq", "points_mesh_distance",
           "polygon_area2", "sqrt_fraction"]


def _vec(x) -> tuple[Fraction, Fraction, Fraction]:
    a, b, c = (float(v) for v in x)
    return Fraction(a), Fraction(b), Fraction(c)


def _sub(u, v):
    return u[0] - v[0], u[1] - v[1], u[2] - v[2]


def _dot(u, v):
    return u[0] * v[0] + u[1] * v[1] + u[2] * v[2]


def _cross(u, v):
    return (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])


def _segment_sq(p, a, b) -> Fraction:
    e = _sub(b, a)
    ee = _dot(e, e)
    ap = _sub(p, a)
    if ee == 0:
        return _dot(ap, ap)
    t = min(max(_dot(ap, e) / ee, Fraction(0)), Fraction(1))
    d = (ap[0] - t * e[0], ap[1] - t * e[1], ap[2] - t * e[2])
    return _dot(d, d)


def point_triangle_sq(p, a, b, c) -> Fraction:
    """Exact squared distance from point ``p`` to triangle ``abc`` (float coordinates, each a
    length-3 sequence), as a Fraction. A triangle with zero area (collinear or repeated
    corners) is the union of its edges. Non-finite coordinates are refused with ValueError."""
    for x in (p, a, b, c):
        if not all(math.isfinite(float(v)) for v in x):
            raise ValueError("exact distances need finite coordinates")
    P, A, B, C = _vec(p), _vec(a), _vec(b), _vec(c)
    best = min(_segment_sq(P, A, B), _segment_sq(P, B, C), _segment_sq(P, C, A))
    n = _cross(_sub(B, A), _sub(C, A))
    nn = _dot(n, n)
    if nn == 0:
        return best
    t = _dot(n, _sub(P, A)) / nn
    q = (P[0] - t * n[0], P[1] - t * n[1], P[2] - t * n[2])
    # q lies in the plane; it is in the triangle when it is on the inner side of all three edges
    inside = all(_dot(_cross(_sub(v1, v0), _sub(q, v0)), n) >= 0
                 for v0, v1 in ((A, B), (B, C), (C, A)))
    if inside:
        best = min(best, t * t * nn)
    return best


def sqrt_fraction(x: Fraction) -> float:
    """The square root of a non-negative Fraction, as the float64 nearest to it (to within one
    unit in the last place: the integer square root is taken at 120 bits, then rounded)."""
    if x < 0:
        raise ValueError("square root of a negative number")
    if x == 0:
        return 0.0
    # scale by an even power of two so that the integer square root carries >= 120 bits
    num, den = x.numerator, x.denominator
    shift = max(0, 240 - (num.bit_length() - den.bit_length()))
    shift += shift & 1
    root = math.isqrt((num << shift) // den)
    return math.ldexp(float(root), -(shift // 2))


def point_triangle_distance(p, a, b, c) -> float:
    """The exact distance from ``p`` to triangle ``abc``, rounded to float64."""
    return sqrt_fraction(point_triangle_sq(p, a, b, c))


def points_mesh_distance(points, corners) -> np.ndarray:
    """(P,) exact distances (rounded to float64) from each of ``points`` (P, 3) to the union of
    the triangles ``corners`` (T, 3, 3). Quadratic in P·T with rational arithmetic: for small
    inputs only."""
    points = np.asarray(points, np.float64).reshape(-1, 3)
    corners = np.asarray(corners, np.float64).reshape(-1, 3, 3)
    out = np.empty(len(points))
    for i, p in enumerate(points):
        out[i] = sqrt_fraction(min(point_triangle_sq(p, *t) for t in corners))
    return out


def polygon_area2(points) -> Fraction:
    """Twice the signed area of the planar polygon ``points`` (N, 2), exactly (shoelace)."""
    pts = [(Fraction(float(x)), Fraction(float(y))) for x, y in np.asarray(points, np.float64)]
    total = Fraction(0)
    for (x0, y0), (x1, y1) in zip(pts, pts[1:] + pts[:1]):
        total += x0 * y1 - x1 * y0
    return total
