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
* :func:`points_mesh_distance` -- the exact distance of each point to the union of triangles;
  :func:`nearest_distance` the same for one point among many triangles, the rational work
  spent only on the triangles whose bounding box is not farther than a distance found.
* :func:`polygon_area2` -- twice the signed area of a planar polygon, exactly.
* :func:`exact_point_triangle_sq` -- :func:`point_triangle_sq` for any exact coordinates
  (floats, ints, Fractions), computed on integers over one common denominator: the same
  value, about ten times as fast (the numerical stress suite asks for tens of thousands).
* :func:`exact_sq_error` -- how far a computed distance lies from the square root of an exact
  squared distance.
"""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np

__all__ = ["common_integers", "exact_point_triangle_sq", "exact_sq_error",
           "point_triangle_distance", "point_triangle_sq", "points_mesh_distance",
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


def nearest_distance(point, corners) -> float:
    """The exact distance (rounded to float64) from ``point`` (3,) to the union of the triangles
    ``corners`` (T, 3, 3), T >= 1. Triangles are visited in order of the distance to their
    bounding boxes (a lower bound of the distance to the triangle, computed in float64 and
    lowered by a relative 1e-12 for its rounding); the visit stops at the first box farther
    than the least exact distance found (raised likewise), so only the triangles that may be
    nearest are measured exactly."""
    p = np.asarray(point, np.float64).reshape(3)
    c = np.asarray(corners, np.float64).reshape(-1, 3, 3)
    gap = np.maximum(np.maximum(c.min(axis=1) - p, p - c.max(axis=1)), 0.0)
    box = np.sqrt((gap ** 2).sum(axis=1)) * (1.0 - 1e-12)
    best, reach = None, np.inf
    for t in np.argsort(box, kind="stable"):
        if box[t] > reach:
            break
        d = point_triangle_sq(p, *c[t])
        if best is None or d < best:
            best = d
            reach = sqrt_fraction(best) * (1.0 + 1e-12)
    return sqrt_fraction(best)


def polygon_area2(points) -> Fraction:
    """Twice the signed area of the planar polygon ``points`` (N, 2), exactly (shoelace)."""
    pts = [(Fraction(float(x)), Fraction(float(y))) for x, y in np.asarray(points, np.float64)]
    total = Fraction(0)
    for (x0, y0), (x1, y1) in zip(pts, pts[1:] + pts[:1]):
        total += x0 * y1 - x1 * y0
    return total


# --------------------------------------------------------------------------- on integers
def common_integers(values) -> tuple[list[int], int]:
    """``(integers, denominator)``: every exact number of ``values`` (floats, ints, Fractions;
    floats converted exactly) as ``integers[i] / denominator`` over one common denominator
    (a power of two for floats). Non-finite values are refused with ValueError."""
    pairs = []
    for v in values:
        if isinstance(v, Fraction):
            pairs.append((v.numerator, v.denominator))
            continue
        v = float(v)
        if not math.isfinite(v):
            raise ValueError("exact arithmetic needs finite coordinates")
        pairs.append(v.as_integer_ratio())
    den = math.lcm(*(d for _, d in pairs))
    return [n * (den // d) for n, d in pairs], den


def _less(n1, d1, n2, d2) -> bool:
    return n1 * d2 < n2 * d1


def _int_segment_sq(p, a, b) -> tuple[int, int]:
    """(numerator, denominator) of the squared distance from integer point p to segment ab."""
    e = (b[0] - a[0], b[1] - a[1], b[2] - a[2])
    ap = (p[0] - a[0], p[1] - a[1], p[2] - a[2])
    ee = e[0] * e[0] + e[1] * e[1] + e[2] * e[2]
    aa = ap[0] * ap[0] + ap[1] * ap[1] + ap[2] * ap[2]
    if ee == 0:
        return aa, 1
    num = ap[0] * e[0] + ap[1] * e[1] + ap[2] * e[2]
    if num <= 0:
        return aa, 1
    if num >= ee:
        bp = (p[0] - b[0], p[1] - b[1], p[2] - b[2])
        return bp[0] * bp[0] + bp[1] * bp[1] + bp[2] * bp[2], 1
    return aa * ee - num * num, ee


def exact_point_triangle_sq(p, a, b, c) -> Fraction:
    """The exact squared distance from point ``p`` to triangle ``abc`` (each three exact
    numbers: floats, ints or Fractions), as a Fraction; equal to :func:`point_triangle_sq`.

    All twelve coordinates are put over one common denominator and the rest is integer
    arithmetic: the nearest of the three edges (a projection clamped to the segment), and the
    plane distance ``(n·(p − a))² / (n·n)`` where the projection of p lies inside, which holds
    when ``((v1 − v0) × (p − v0)) · n ≥ 0`` on every edge (the projection differs from p by a
    multiple of n, which drops out). A triangle with ``n = 0`` is its three edges. Non-finite
    coordinates are refused with ValueError."""
    ints, den = common_integers([*p, *a, *b, *c])
    P, A, B, C = (tuple(ints[3 * i:3 * i + 3]) for i in range(4))
    best_n, best_d = _int_segment_sq(P, A, B)
    for u, v in ((B, C), (C, A)):
        n_, d_ = _int_segment_sq(P, u, v)
        if _less(n_, d_, best_n, best_d):
            best_n, best_d = n_, d_
    ab = (B[0] - A[0], B[1] - A[1], B[2] - A[2])
    ac = (C[0] - A[0], C[1] - A[1], C[2] - A[2])
    n = (ab[1] * ac[2] - ab[2] * ac[1], ab[2] * ac[0] - ab[0] * ac[2],
         ab[0] * ac[1] - ab[1] * ac[0])
    nn = n[0] * n[0] + n[1] * n[1] + n[2] * n[2]
    if nn:
        inside = True
        for v0, v1 in ((A, B), (B, C), (C, A)):
            e = (v1[0] - v0[0], v1[1] - v0[1], v1[2] - v0[2])
            q = (P[0] - v0[0], P[1] - v0[1], P[2] - v0[2])
            cr = (e[1] * q[2] - e[2] * q[1], e[2] * q[0] - e[0] * q[2], e[0] * q[1] - e[1] * q[0])
            if cr[0] * n[0] + cr[1] * n[1] + cr[2] * n[2] < 0:
                inside = False
                break
        if inside:
            s = n[0] * (P[0] - A[0]) + n[1] * (P[1] - A[1]) + n[2] * (P[2] - A[2])
            if _less(s * s, nn, best_n, best_d):
                best_n, best_d = s * s, nn
    return Fraction(best_n, best_d * den * den)


def exact_sq_error(computed: float, exact_sq: Fraction) -> float:
    """``|computed − sqrt(exact_sq)|`` for a computed distance (float) and an exact squared
    distance (Fraction), to a few digits: ``|computed² − exact_sq| / (computed + sqrt(exact_sq))``
    with the numerator exact. NaN for a NaN ``computed``, inf for an infinite one."""
    computed = float(computed)
    if not math.isfinite(computed):
        return computed if math.isnan(computed) else math.inf
    root = sqrt_fraction(exact_sq)
    den = abs(computed) + root
    if den == 0.0:
        return 0.0
    if computed < 0:  # not a distance: as far from the exact value as it is
        return root - computed
    return float(abs(Fraction(computed) ** 2 - exact_sq)) / den
