"""Certificates that an original triangle lies within tol of a few simplified faces.

How the distance is certified rather than sampled: every original triangle T keeps a small
*support* S(T) of current faces such that the subdivision bound of
:func:`workbench.algo.nearest.triangle.triangle_bounds` certifies ``max_{p ∈ T} d(p, S(T)) <= tol``
(the distance to a triangle is convex, so its maximum over a piece of T is at a corner; pieces
are split four ways at edge midpoints where one face does not cover them). S(T) only holds
faces of the current mesh, so every point of T is within tol of the simplified surface. A
collapse u → v changes or removes the faces around u; every original triangle supported by one
of them is re-certified against its remaining support plus the new faces around v, and the
collapse is undone unless all pass. The new support is the set of faces that certified at least
one leaf piece, so supports stay small. A piece that straddles the edge between two faces is
covered only once it is about tol wide, so the subdivision depth is chosen per original
triangle from its longest edge over its tolerance (:func:`certification_depths`): a fixed
shallow depth refuses even exact collapses on a flat plate of large elements.

Candidate faces are held as records of ``_REC`` float64 (:func:`_set_record`), so that the
bounding-sphere and plane tests that reject most of them need no look-up of vertices.
"""

from __future__ import annotations

import numba
import numpy as np

from ..nearest.triangle import (
    closest_point_on_triangle,
    construction_rounding,
    distance_rounding,
    triangle_bounds,
)

# bounds of the automatic certification depth (see certification_depths)
MIN_DEPTH = 5
MAX_AUTO_DEPTH = 10

# a candidate face record: corners a, b, c (0:9), bounding-sphere centre (9:12) and radius
# (12), unit normal (13:16) and plane offset (16); a degenerate face has a zero plane
_REC = 17


def certification_depths(corners: np.ndarray, tol: np.ndarray, max_depth=None) -> np.ndarray:
    """(K,) int64 subdivision depth of the certification of each original triangle.

    ``corners`` (K, 3, 3), ``tol`` (K,) in the same units. A piece of a triangle that straddles
    the edge between two simplified faces is certified only once it is narrow enough for one
    face to reach all of its corners, about ``tol`` across: the depth that takes the longest
    edge L of the triangle down to that, ``ceil(log2(L / tol)) + 1``, at least
    ``MIN_DEPTH`` and at most ``MAX_AUTO_DEPTH``. An integer ``max_depth`` fixes every depth
    to it instead.
    """
    if max_depth is not None:
        return np.full(len(corners), int(max_depth), np.int64)
    edges = corners[:, [1, 2, 0]] - corners
    longest = np.sqrt((edges ** 2).sum(axis=2).max(axis=1))
    ratio = np.maximum(longest / tol, 1.0)
    return np.clip(np.ceil(np.log2(ratio)) + 1, MIN_DEPTH, MAX_AUTO_DEPTH).astype(np.int64)


def certificate_rounding(vertices, triangles, tol, depths) -> np.ndarray:
    """(len(tol),) the bound (model units) of the rounding error of a certificate
    ``max_{p ∈ T} d(p, S(T)) <= tol`` for each tolerance ``tol`` (one per part), following the
    error model of :mod:`workbench.algo.nearest.triangle`: a corner distance up to tol to a face no
    longer than the bounding-box diagonal of the used ``vertices`` ((N, 3) near the origin, or
    (S, N, 3): the largest over the S states), plus
    how far a piece's corners may lie from T after ``depths.max()`` levels of midpoints and the
    translation of the model (which moves T and the faces alike: twice). The certification
    compares against ``tol`` less this, and the reported bounds are rounded up by it."""
    states = vertices if vertices.ndim == 3 else vertices[None]
    used = states[:, np.unique(triangles)]
    diagonal = float(np.linalg.norm(used.max(axis=1) - used.min(axis=1), axis=1).max())
    magnitude = float(np.sqrt((used ** 2).sum(axis=2)).max())
    levels = int(np.max(depths, initial=0)) + 2
    return np.array([distance_rounding(t, diagonal) + construction_rounding(magnitude, levels)
                     for t in np.asarray(tol, np.float64)])


@numba.njit(cache=True)
def _set_record(rec, j, a, b, c):
    """Fill candidate record j from the corner rows a, b, c."""
    for k in range(3):
        rec[j, k], rec[j, 3 + k], rec[j, 6 + k] = a[k], b[k], c[k]
        rec[j, 9 + k] = (a[k] + b[k] + c[k]) / 3.0
    r2 = 0.0
    for corner in (a, b, c):
        d = 0.0
        for k in range(3):
            d += (corner[k] - rec[j, 9 + k]) ** 2
        r2 = max(r2, d)
    rec[j, 12] = np.sqrt(r2)
    n0 = (b[1] - a[1]) * (c[2] - a[2]) - (b[2] - a[2]) * (c[1] - a[1])
    n1 = (b[2] - a[2]) * (c[0] - a[0]) - (b[0] - a[0]) * (c[2] - a[2])
    n2 = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
    length = np.sqrt(n0 * n0 + n1 * n1 + n2 * n2)
    if length > 0.0:
        n0, n1, n2 = n0 / length, n1 / length, n2 / length
    else:
        n0 = n1 = n2 = 0.0
    rec[j, 13], rec[j, 14], rec[j, 15] = n0, n1, n2
    rec[j, 16] = -(n0 * a[0] + n1 * a[1] + n2 * a[2])


@numba.njit(cache=True, inline="always")
def _covers(piece, rec, f, tol, p, a, b, c, tmp):
    """True when the three corners of ``piece`` are within tol of candidate face f.

    The sphere and plane tests only reject (a point farther than tol from the face's bounding
    sphere or plane is farther than tol from the face); acceptance always comes from the
    exact distance of :func:`closest_point_on_triangle`.
    """
    reach = rec[f, 12] + tol
    for i in range(3):
        x, y, z = piece[i, 0], piece[i, 1], piece[i, 2]
        dx, dy, dz = x - rec[f, 9], y - rec[f, 10], z - rec[f, 11]
        if dx * dx + dy * dy + dz * dz > reach * reach:
            return False
        if abs(rec[f, 13] * x + rec[f, 14] * y + rec[f, 15] * z + rec[f, 16]) > tol:
            return False
    for k in range(3):
        a[k], b[k], c[k] = rec[f, k], rec[f, 3 + k], rec[f, 6 + k]
    for i in range(3):
        p[0], p[1], p[2] = piece[i, 0], piece[i, 1], piece[i, 2]
        if np.sqrt(closest_point_on_triangle(p, a, b, c, tmp)) > tol:
            return False
    return True


@numba.njit(cache=True)
def _certify(t, cand, n_cand, tol, max_depth, used, stack, depth, piece, corners):
    """True when every point of triangle t is within tol of the union of the candidate faces
    (records ``cand[:n_cand]``, see ``_REC``); ``corners`` is (5, 3) scratch, ``stack``
    (4 max_depth + 4, 3, 3), ``depth`` (4 max_depth + 4,) and ``piece`` (3, 3) too.

    Walks the same quadtree of pieces as :func:`triangle_bounds` (same midpoints, same order):
    a piece whose three corners are within tol of one face is covered by it (distance to a
    triangle is convex), that face is flagged in ``used`` and the piece is a leaf; otherwise it
    is split, and at ``max_depth`` the certification fails. Faces already flagged are tried
    first, so supports stay small.
    """
    q, qa, qb, qc, tmp = corners[0], corners[1], corners[2], corners[3], corners[4]
    stack[0] = t
    depth[0] = 0
    top = 1
    while top > 0:
        top -= 1
        level = depth[top]
        for i in range(3):
            for c in range(3):
                piece[i, c] = stack[top, i, c]
        covered = False
        for f in range(n_cand):
            if used[f] and _covers(piece, cand, f, tol, q, qa, qb, qc, tmp):
                covered = True
                break
        if not covered:
            for f in range(n_cand):
                if not used[f] and _covers(piece, cand, f, tol, q, qa, qb, qc, tmp):
                    used[f] = True
                    covered = True
                    break
        if covered:
            continue
        if level >= max_depth:
            return False
        for k in range(4):
            for c in range(3):
                m01 = 0.5 * (piece[0, c] + piece[1, c])
                m12 = 0.5 * (piece[1, c] + piece[2, c])
                m20 = 0.5 * (piece[2, c] + piece[0, c])
                if k == 0:
                    stack[top, 0, c], stack[top, 1, c], stack[top, 2, c] = piece[0, c], m01, m20
                elif k == 1:
                    stack[top, 0, c], stack[top, 1, c], stack[top, 2, c] = m01, piece[1, c], m12
                elif k == 2:
                    stack[top, 0, c], stack[top, 1, c], stack[top, 2, c] = m20, m12, piece[2, c]
                else:
                    stack[top, 0, c], stack[top, 1, c], stack[top, 2, c] = m12, m20, m01
            depth[top] = level + 1
            top += 1
    return True


@numba.njit(cache=True)
def _final_bounds(Vs, F, originals, sup, sup_n):
    """Per original triangle, the largest over the certified states at which it is live of the
    upper bound of :func:`triangle_bounds` against its support placed at that state (split
    while above tol); NaN for a triangle live at none. The certificate: each is <= tol by
    construction. A state at which the triangle and its support have bit for bit the
    coordinates of a state already bounded gives the same bound and is skipped."""
    orig, index, live = originals.corners, originals.index, originals.live
    k_orig = orig.shape[0]
    out = np.empty(k_orig)
    tri = np.empty((3, 3))
    checked = np.empty(Vs.shape[0], np.int64)
    for t in range(k_orig):
        n = sup_n[t]
        if n == 0:
            out[t] = np.inf
            continue
        worst = np.nan
        faces = np.empty((n, 3, 3))
        n_checked = 0
        for st in range(Vs.shape[0]):
            if not live[st, t] or _unmoved(t, st, checked, n_checked, Vs, F, index, sup, n):
                continue
            checked[n_checked] = st
            n_checked += 1
            for j in range(n):
                g = sup[t, j]
                for k in range(3):
                    for c in range(3):
                        faces[j, k, c] = Vs[st, F[g, k], c]
            if st == 0:
                tri[:] = orig[t]
            else:
                for k in range(3):
                    for c in range(3):
                        tri[k, c] = Vs[st, index[t, k], c]
            b = triangle_bounds(tri, faces, originals.tol[t], originals.depth[t])[1]
            if not b <= worst:
                worst = b
        out[t] = worst
    return out


@numba.njit(cache=True)
def _unmoved(t, st, checked, n_checked, Vs, F, index, sup, n):
    """Whether original triangle t (corners ``index[t]``) and its support faces ``sup[t, :n]``
    have at state st bit for bit the coordinates they have at one of ``checked[:n_checked]``."""
    for r in range(n_checked):
        other = checked[r]
        same = True
        for k in range(3 * n + 3):
            x = index[t, k] if k < 3 else F[sup[t, (k - 3) // 3], (k - 3) % 3]
            for c in range(3):
                if Vs[st, x, c] != Vs[other, x, c]:
                    same = False
            if not same:
                break
        if same:
            return True
    return False
