"""Bounding volumes of the element hierarchy: each element's slab, and the boxes of the tree
nodes, axis-aligned (AABB) or oriented after Gottschalk, Lin & Manocha (OBB; the frame from the
area-weighted covariance of a node's triangles, see :mod:`workbench.algo.nearest.hierarchy`).

Everything is in coordinates relative to the hierarchy's origin and widened by ``pad`` so that
rounding never excludes a point a volume should contain. The boxes are packed per node: an
AABB as (lo, hi), an OBB as (centre, three axes as rows, half extents).
"""

from __future__ import annotations

import numba
import numpy as np


def bounding_volumes(kind: str, verts, corners, n_tri, left, right, start, end,
                     pad: float) -> np.ndarray:
    """(nodes, 6) AABBs or (nodes, 15) OBBs (``kind`` "aabb" or "obb") of the tree ``left``,
    ``right``, ``start``, ``end`` over elements in tree order with nodes ``verts`` (E, 4, 3)
    and triangles ``corners`` (E, 2, 3, 3), ``n_tri`` (E,) of them each."""
    if kind == "aabb":
        return _aabb_boxes(verts, left, right, start, end, pad)
    cov, ref = _covariances(corners, n_tri, verts, start, end)
    val, vec = np.linalg.eigh(cov)  # ascending eigenvalues, vectors in columns
    axes = np.ascontiguousarray(vec[:, :, ::-1].transpose(0, 2, 1))  # rows, major first
    # a node whose elements span no plane (a segment, a point) has no normal of its own: it
    # takes its parent's frame, which on a planar part is the part's plane
    flat = ~(val[:, 1] > 1e-12 * val[:, 2])
    _inherit_frames(axes, flat, left, right)
    return _obb_boxes(verts, start, end, axes, ref, pad)


def _slabs(corners, n_tri, verts, pad) -> np.ndarray:
    """(E, 5): unit normal and [lo, hi] of normal·x over each element's nodes, widened by pad.
    The normal is the sum of the triangles' cross products; an element without area takes a
    direction across its longest edge (any unit vector bounds the distance)."""
    a, b, c = corners[:, :, 0], corners[:, :, 1], corners[:, :, 2]
    cross = np.cross(b - a, c - a) * (np.arange(2)[None, :] < n_tri[:, None])[:, :, None]
    n = cross.sum(axis=1)
    length = np.sqrt((n * n).sum(axis=1))
    ok = length > 0
    normal = np.zeros_like(n)
    normal[ok] = n[ok] / length[ok, None]
    if not ok.all():
        v = verts[~ok]
        edges = v[:, [1, 2, 3, 0]] - v
        longest = edges[np.arange(len(v)), np.argmax((edges * edges).sum(axis=2), axis=1)]
        helper = np.eye(3)[np.argmin(np.abs(longest), axis=1)]
        alt = np.cross(longest, helper)
        alt_len = np.sqrt((alt * alt).sum(axis=1))
        alt = np.where(alt_len[:, None] > 0, alt / np.where(alt_len > 0, alt_len, 1)[:, None],
                       np.array([1.0, 0.0, 0.0]))
        normal[~ok] = alt
    s = np.einsum("eij,ej->ei", verts, normal)
    return np.concatenate([normal, (s.min(axis=1) - pad)[:, None],
                           (s.max(axis=1) + pad)[:, None]], axis=1)


@numba.njit(cache=True)
def _aabb_boxes(verts, left, right, start, end, pad):
    """(nodes, 6) boxes lo, hi: leaves from their elements' nodes (widened by pad), inner
    nodes from their children (children have larger indices than their parents)."""
    n = len(start)
    bv = np.empty((n, 6))
    for i in range(n - 1, -1, -1):
        if left[i] >= 0:
            c0, c1 = left[i], right[i]
            for k in range(3):
                bv[i, k] = min(bv[c0, k], bv[c1, k])
                bv[i, 3 + k] = max(bv[c0, 3 + k], bv[c1, 3 + k])
            continue
        for k in range(3):
            lo = np.inf
            hi = -np.inf
            for j in range(start[i], end[i]):
                for c in range(4):
                    x = verts[j, c, k]
                    lo = min(lo, x)
                    hi = max(hi, x)
            bv[i, k] = lo - pad
            bv[i, 3 + k] = hi + pad
    return bv


@numba.njit(cache=True, parallel=True)
def _covariances(corners, n_tri, verts, start, end):
    """(nodes, 3, 3) covariance of each node's surface (area-weighted over its triangles,
    Gottschalk's continuous formula; the vertex covariance where the area is zero) and the
    reference point (nodes, 3) it was taken about."""
    n = len(start)
    cov = np.zeros((n, 3, 3))
    ref = np.empty((n, 3))
    for i in numba.prange(n):
        r0, r1, r2 = verts[start[i], 0, 0], verts[start[i], 0, 1], verts[start[i], 0, 2]
        ref[i, 0], ref[i, 1], ref[i, 2] = r0, r1, r2
        area = 0.0
        s0 = s1 = s2 = 0.0
        q00 = q01 = q02 = q11 = q12 = q22 = 0.0
        for j in range(start[i], end[i]):
            for t in range(n_tri[j]):
                ax, ay, az = corners[j, t, 0, 0] - r0, corners[j, t, 0, 1] - r1, \
                    corners[j, t, 0, 2] - r2
                bx, by, bz = corners[j, t, 1, 0] - r0, corners[j, t, 1, 1] - r1, \
                    corners[j, t, 1, 2] - r2
                cx, cy, cz = corners[j, t, 2, 0] - r0, corners[j, t, 2, 1] - r1, \
                    corners[j, t, 2, 2] - r2
                ux, uy, uz = bx - ax, by - ay, bz - az
                wx, wy, wz = cx - ax, cy - ay, cz - az
                x0 = uy * wz - uz * wy
                x1 = uz * wx - ux * wz
                x2 = ux * wy - uy * wx
                ar = 0.5 * np.sqrt(x0 * x0 + x1 * x1 + x2 * x2)
                if ar == 0.0:
                    continue
                mx, my, mz = (ax + bx + cx) / 3.0, (ay + by + cy) / 3.0, (az + bz + cz) / 3.0
                area += ar
                s0 += ar * mx
                s1 += ar * my
                s2 += ar * mz
                f = ar / 12.0
                q00 += f * (9.0 * mx * mx + ax * ax + bx * bx + cx * cx)
                q01 += f * (9.0 * mx * my + ax * ay + bx * by + cx * cy)
                q02 += f * (9.0 * mx * mz + ax * az + bx * bz + cx * cz)
                q11 += f * (9.0 * my * my + ay * ay + by * by + cy * cy)
                q12 += f * (9.0 * my * mz + ay * az + by * bz + cy * cz)
                q22 += f * (9.0 * mz * mz + az * az + bz * bz + cz * cz)
        if not area > 0.0:  # no area: the covariance of the corner nodes
            area = 0.0
            s0 = s1 = s2 = 0.0
            q00 = q01 = q02 = q11 = q12 = q22 = 0.0
            for j in range(start[i], end[i]):
                for c in range(4):
                    x, y, z = verts[j, c, 0] - r0, verts[j, c, 1] - r1, verts[j, c, 2] - r2
                    area += 1.0
                    s0 += x
                    s1 += y
                    s2 += z
                    q00 += x * x
                    q01 += x * y
                    q02 += x * z
                    q11 += y * y
                    q12 += y * z
                    q22 += z * z
        m0, m1, m2 = s0 / area, s1 / area, s2 / area
        cov[i, 0, 0] = q00 / area - m0 * m0
        cov[i, 0, 1] = cov[i, 1, 0] = q01 / area - m0 * m1
        cov[i, 0, 2] = cov[i, 2, 0] = q02 / area - m0 * m2
        cov[i, 1, 1] = q11 / area - m1 * m1
        cov[i, 1, 2] = cov[i, 2, 1] = q12 / area - m1 * m2
        cov[i, 2, 2] = q22 / area - m2 * m2
    return cov, ref


@numba.njit(cache=True)
def _inherit_frames(axes, flat, left, right):
    """axes[c] = axes[parent] for every child c marked ``flat`` (parents precede children)."""
    for i in range(len(left)):
        if left[i] >= 0:
            for c in (left[i], right[i]):
                if flat[c]:
                    axes[c] = axes[i]


@numba.njit(cache=True, parallel=True)
def _obb_boxes(verts, start, end, axes_in, ref, pad):
    """(nodes, 15) OBBs: centre, three orthonormal axes (rows, right-handed) and half extents
    from projecting every node of the node's elements onto the frame ``axes_in``."""
    n = len(start)
    bv = np.empty((n, 15))
    for i in numba.prange(n):
        # re-orthonormalise: a0 unit, a1 unit and orthogonal to a0, a2 = a0 x a1
        a0 = axes_in[i, 0].copy()
        a1 = axes_in[i, 1].copy()
        l0 = np.sqrt(a0[0] * a0[0] + a0[1] * a0[1] + a0[2] * a0[2])
        if not l0 > 0.5:
            a0[:] = 0.0
            a0[0] = 1.0
        else:
            a0 /= l0
        a1 -= (a1[0] * a0[0] + a1[1] * a0[1] + a1[2] * a0[2]) * a0
        l1 = np.sqrt(a1[0] * a1[0] + a1[1] * a1[1] + a1[2] * a1[2])
        if not l1 > 0.5:
            # any unit vector across a0
            k = 0
            if abs(a0[1]) < abs(a0[k]):
                k = 1
            if abs(a0[2]) < abs(a0[k]):
                k = 2
            a1[:] = 0.0
            a1[k] = 1.0
            a1 -= a0[k] * a0
            a1 /= np.sqrt(a1[0] * a1[0] + a1[1] * a1[1] + a1[2] * a1[2])
        else:
            a1 /= l1
        a2 = np.empty(3)
        a2[0] = a0[1] * a1[2] - a0[2] * a1[1]
        a2[1] = a0[2] * a1[0] - a0[0] * a1[2]
        a2[2] = a0[0] * a1[1] - a0[1] * a1[0]
        a2 /= np.sqrt(a2[0] * a2[0] + a2[1] * a2[1] + a2[2] * a2[2])
        lo = np.full(3, np.inf)
        hi = np.full(3, -np.inf)
        r = ref[i]
        for j in range(start[i], end[i]):
            for c in range(4):
                d0 = verts[j, c, 0] - r[0]
                d1 = verts[j, c, 1] - r[1]
                d2 = verts[j, c, 2] - r[2]
                t0 = a0[0] * d0 + a0[1] * d1 + a0[2] * d2
                t1 = a1[0] * d0 + a1[1] * d1 + a1[2] * d2
                t2 = a2[0] * d0 + a2[1] * d1 + a2[2] * d2
                lo[0] = min(lo[0], t0)
                hi[0] = max(hi[0], t0)
                lo[1] = min(lo[1], t1)
                hi[1] = max(hi[1], t1)
                lo[2] = min(lo[2], t2)
                hi[2] = max(hi[2], t2)
        m0, m1, m2 = 0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), 0.5 * (lo[2] + hi[2])
        for k in range(3):
            bv[i, k] = r[k] + m0 * a0[k] + m1 * a1[k] + m2 * a2[k]
            bv[i, 3 + k] = a0[k]
            bv[i, 6 + k] = a1[k]
            bv[i, 9 + k] = a2[k]
        for k in range(3):
            bv[i, 12 + k] = 0.5 * (hi[k] - lo[k]) + pad
    return bv
