"""Convex pieces of a triangle and the planes that cut them (the geometry of the plane-split
refinement of :mod:`workbench.algo.hausdorff`).

A piece is a planar convex polygon of at most ``_MAX_POLY`` vertices, stored as rows of a
(``_MAX_POLY``, 3) array with its vertex count beside it. The helpers here find its centre and
radius, the planes that separate the regions where one face of B or another is nearest (the
bisector of an edge two faces share, the zero line of the difference of two distances), the
signed sides of its vertices to a plane, and cut it in two. Lengths are in model units, after
the translation :func:`~workbench.algo.hausdorff.hausdorff` applies.
"""

from __future__ import annotations

import numba
import numpy as np

_MAX_POLY = 16  # vertices of a piece in the plane-split refinement
# a vertex this close to a cut plane, relative to the piece's radius, lies on it
_PLANE_ROUNDING = 1e-10
# the candidate ball is widened by this share so that rounding never drops a nearest face
_BALL_SLACK = 1e-9


@numba.njit(cache=True)
def _ball_radius(t, upper):
    """Radius around t's centroid that holds the nearest face of every point of t, given an
    upper bound of their distances."""
    c = (t[0] + t[1] + t[2]) / 3.0
    rho = 0.0
    for i in range(3):
        e = t[i] - c
        rho = max(rho, np.sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]))
    return c, (upper + rho) * (1.0 + _BALL_SLACK)


@numba.njit(cache=True, inline="always")
def _same_point(f, i, g, j):
    return f[i, 0] == g[j, 0] and f[i, 1] == g[j, 1] and f[i, 2] == g[j, 2]


@numba.njit(cache=True)
def _shared_edge_plane(f, g, normal):
    """The plane through the edge that faces f and g (3, 3) share (equal corner coordinates),
    bisecting the angle between them: writes its unit normal (pointing into f's side) and
    returns the index of a corner of f on it, or -1 when they share no edge or fold onto
    each other. Scalars only: no array is allocated."""
    s0 = s1 = -1
    n_shared = 0
    f_only = -1
    for i in range(3):
        hit = _same_point(f, i, g, 0) or _same_point(f, i, g, 1) or _same_point(f, i, g, 2)
        if hit and n_shared < 2:
            if n_shared == 0:
                s0 = i
            else:
                s1 = i
            n_shared += 1
        elif not hit:
            f_only = i
    if n_shared != 2 or f_only < 0:
        return -1
    g_only = -1
    for j in range(3):
        if not (_same_point(g, j, f, s0) or _same_point(g, j, f, s1)):
            g_only = j
    if g_only < 0:
        return -1
    p0, p1, p2 = f[s0, 0], f[s0, 1], f[s0, 2]
    e0, e1, e2 = f[s1, 0] - p0, f[s1, 1] - p1, f[s1, 2] - p2
    ee = e0 * e0 + e1 * e1 + e2 * e2
    if ee == 0.0:
        return -1
    u0, u1, u2 = f[f_only, 0] - p0, f[f_only, 1] - p1, f[f_only, 2] - p2
    k = (u0 * e0 + u1 * e1 + u2 * e2) / ee
    u0, u1, u2 = u0 - k * e0, u1 - k * e1, u2 - k * e2
    w0, w1, w2 = g[g_only, 0] - p0, g[g_only, 1] - p1, g[g_only, 2] - p2
    k = (w0 * e0 + w1 * e1 + w2 * e2) / ee
    w0, w1, w2 = w0 - k * e0, w1 - k * e1, w2 - k * e2
    nu = np.sqrt(u0 * u0 + u1 * u1 + u2 * u2)
    nw = np.sqrt(w0 * w0 + w1 * w1 + w2 * w2)
    if nu == 0.0 or nw == 0.0:
        return -1
    m0, m1, m2 = u0 / nu - w0 / nw, u1 / nu - w1 / nw, u2 / nu - w2 / nw
    nm = np.sqrt(m0 * m0 + m1 * m1 + m2 * m2)
    if not nm > 1e-9:
        return -1
    normal[0], normal[1], normal[2] = m0 / nm, m1 / nm, m2 / nm
    return s0


@numba.njit(cache=True)
def _sides(poly, n, point, normal, rho, side):
    """Signed distances (scaled by |normal|) of the n vertices of a piece of radius ``rho`` to
    the plane through ``point``, into ``side``; those within rounding of the plane count as on
    it. Returns (vertices strictly above, strictly below)."""
    scale = np.sqrt(normal[0] * normal[0] + normal[1] * normal[1] + normal[2] * normal[2])
    zero = _PLANE_ROUNDING * rho * scale
    n_pos = n_neg = 0
    for i in range(n):
        e = poly[i] - point
        s = e[0] * normal[0] + e[1] * normal[1] + e[2] * normal[2]
        if abs(s) <= zero:
            s = 0.0
        side[i] = s
        n_pos += s > 0.0
        n_neg += s < 0.0
    return n_pos, n_neg


@numba.njit(cache=True)
def _secant_plane(poly, dist, n, f, g, point, normal):
    """The plane through the zeros of h = d(·, face f) - d(·, face g), linearly interpolated
    along the edges of a planar convex piece of n vertices, perpendicular to the piece: writes
    a point on it and its normal; returns (1, 1), or (0, 0) when h does not change sign twice
    or the piece is degenerate."""
    zeros = np.empty((2, 3))
    n_zeros = 0
    for i in range(n):
        j = (i + 1) % n
        hi = np.sqrt(dist[i, f]) - np.sqrt(dist[i, g])
        hj = np.sqrt(dist[j, f]) - np.sqrt(dist[j, g])
        if (hi > 0.0) != (hj > 0.0) and n_zeros < 2:
            t = hi / (hi - hj)
            zeros[n_zeros] = poly[i] + t * (poly[j] - poly[i])
            n_zeros += 1
    if n_zeros < 2:
        return 0, 0
    # the piece's normal (Newell), then the cut plane's normal within the piece's plane
    pn = np.zeros(3)
    for i in range(n):
        a = poly[i]
        b = poly[(i + 1) % n]
        pn[0] += (a[1] - b[1]) * (a[2] + b[2])
        pn[1] += (a[2] - b[2]) * (a[0] + b[0])
        pn[2] += (a[0] - b[0]) * (a[1] + b[1])
    e = zeros[1] - zeros[0]
    normal[0] = e[1] * pn[2] - e[2] * pn[1]
    normal[1] = e[2] * pn[0] - e[0] * pn[2]
    normal[2] = e[0] * pn[1] - e[1] * pn[0]
    if not (normal[0] * normal[0] + normal[1] * normal[1] + normal[2] * normal[2]) > 0.0:
        return 0, 0
    point[:] = zeros[0]
    return 1, 1


@numba.njit(cache=True)
def _diameter_end(poly, n):
    """A vertex at one end of the longest vertex-to-vertex distance of a piece."""
    best, best_d = 0, -1.0
    for i in range(n):
        for j in range(i + 1, n):
            e = poly[i] - poly[j]
            d = e[0] * e[0] + e[1] * e[1] + e[2] * e[2]
            if d > best_d:
                best, best_d = i, d
    return best


@numba.njit(cache=True)
def _piece_ball(poly, n):
    """Centre (vertex mean) of a convex piece and the largest distance from it to a vertex,
    which is the largest distance to any point of the piece."""
    c = np.zeros(3)
    for i in range(n):
        c += poly[i]
    c /= n
    rho = 0.0
    for i in range(n):
        e = poly[i] - c
        rho = max(rho, np.sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]))
    return c, rho


@numba.njit(cache=True)
def _farthest(poly, n, v):
    """The vertex of a piece farthest from its vertex v."""
    far, far_d = 0, -1.0
    for i in range(n):
        e = poly[i] - poly[v]
        d = e[0] * e[0] + e[1] * e[1] + e[2] * e[2]
        if d > far_d:
            far, far_d = i, d
    return far


@numba.njit(cache=True)
def _split_piece(poly, count_v, depth_v, kind, bound, top, side, cut, piece_upper):
    """Cut the piece at stack position ``top`` by the plane whose signed vertex distances are
    ``side``: the positive side stays at ``top``, the negative side goes to ``top + 1``. The
    cut points are computed once and shared, so the two pieces meet without a gap."""
    n = count_v[top]
    src = poly[top].copy()
    a, b = top, top + 1
    na = nb = 0
    for i in range(n):
        j = (i + 1) % n
        if side[i] >= 0.0:
            poly[a, na] = src[i]
            na += 1
        if side[i] <= 0.0:
            poly[b, nb] = src[i]
            nb += 1
        if (side[i] > 0.0 and side[j] < 0.0) or (side[i] < 0.0 and side[j] > 0.0):
            t = side[i] / (side[i] - side[j])
            poly[a, na] = src[i] + t * (src[j] - src[i])
            poly[b, nb] = poly[a, na]
            na += 1
            nb += 1
    level = depth_v[top] + 1
    count_v[a], count_v[b] = na, nb
    depth_v[a], depth_v[b] = level, level
    kind[a], kind[b] = cut, cut
    bound[a], bound[b] = piece_upper, piece_upper
