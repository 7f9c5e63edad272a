"""The compiled kernels of :mod:`workbench.scene.solids` for large solid models: node-pattern
kinds, the exact shared-face count (counting sort by smallest node, O(F + N)) and the signed
volume, one loop per solid or face. Imported only when a model is large enough to repay
``import numba`` and loading the kernels (:data:`workbench.scene.solids.COMPILED_FROM`); the
numpy versions in :mod:`~workbench.scene.solids` give the same results and are the reference
they are tested against.
"""

from __future__ import annotations

import numba
import numpy as np

TET, PENTA, HEX = 4, 6, 8  # kind codes = number of distinct nodes (as in solids)


@numba.njit(cache=True, nogil=True)
def _kinds(s):  # pragma: no cover - compiled
    kind = np.zeros(s.shape[0], np.int8)
    for e in range(s.shape[0]):
        distinct = 0
        for i in range(8):
            new = True
            for j in range(i):
                if s[e, j] == s[e, i]:
                    new = False
                    break
            if new:
                distinct += 1
        if distinct == 8:
            kind[e] = HEX
        elif distinct == 6 and s[e, 4] == s[e, 5] and s[e, 6] == s[e, 7]:
            kind[e] = PENTA
        elif (distinct == 4 and s[e, 3] == s[e, 4] and s[e, 3] == s[e, 5]
              and s[e, 3] == s[e, 6] and s[e, 3] == s[e, 7]):
            kind[e] = TET
    return kind


@numba.njit(cache=True, nogil=True, inline="always")
def _face_key(faces, i):  # pragma: no cover - compiled
    """Sorted node ids ``a < b < c < d`` of face ``i``; ``d = -1`` for a triangle."""
    a = faces[i, 0]
    b = faces[i, 1]
    c = faces[i, 2]
    d = faces[i, 3]
    if a > b:
        a, b = b, a
    if d == c:  # triangle a b c c
        if b > c:
            b, c = c, b
        if a > b:
            a, b = b, a
        d = -1
    else:  # sorting network (0,1) (2,3) (0,2) (1,3) (1,2)
        if c > d:
            c, d = d, c
        if a > c:
            a, c = c, a
        if b > d:
            b, d = d, b
        if b > c:
            b, c = c, b
    return a, b, c, d


@numba.njit(cache=True, nogil=True)
def _face_multiplicity(faces, n_nodes):  # pragma: no cover - compiled
    """How many rows of ``faces`` have the same sorted node set as each row, exactly.

    Faces are bucketed by their smallest node (counting sort, O(F + N)) with the rest of their
    key (``b * (N + 1) + c`` and ``d``) stored in bucket order; within a bucket the keys are
    sorted (insertion sort for small buckets, a stable two-key sort for large ones) and equal
    runs counted.
    """
    nf = faces.shape[0]
    m = np.int64(n_nodes) + 1
    start = np.zeros(n_nodes + 1, np.int64)
    for i in range(nf):
        a, b, c, d = _face_key(faces, i)
        start[a + 1] += 1
    for v in range(n_nodes):
        start[v + 1] += start[v]
    fill = start[:-1].copy()
    order = np.empty(nf, np.int64)
    bk1 = np.empty(nf, np.int64)
    bk2 = np.empty(nf, np.int32)
    for i in range(nf):
        a, b, c, d = _face_key(faces, i)
        p = fill[a]
        fill[a] = p + 1
        order[p] = i
        bk1[p] = b * m + c
        bk2[p] = d
    mult = np.ones(nf, np.int32)
    for v in range(n_nodes):
        s = start[v]
        e = start[v + 1]
        size = e - s
        if size < 2:
            continue
        if size <= 64:  # insertion sort of the bucket by (k1, k2), then count the runs
            for p in range(s + 1, e):
                x1 = bk1[p]
                x2 = bk2[p]
                xo = order[p]
                q = p - 1
                while q >= s and (bk1[q] > x1 or (bk1[q] == x1 and bk2[q] > x2)):
                    bk1[q + 1] = bk1[q]
                    bk2[q + 1] = bk2[q]
                    order[q + 1] = order[q]
                    q -= 1
                bk1[q + 1] = x1
                bk2[q + 1] = x2
                order[q + 1] = xo
            r = s
            while r < e:
                t = r + 1
                while t < e and bk1[t] == bk1[r] and bk2[t] == bk2[r]:
                    t += 1
                if t - r > 1:
                    for u in range(r, t):
                        mult[order[u]] = t - r
                r = t
        else:
            a1 = bk1[s:e]
            a2 = bk2[s:e]
            o = np.argsort(a2, kind="mergesort")
            o = o[np.argsort(a1[o], kind="mergesort")]
            r = 0
            while r < size:
                t = r + 1
                while t < size and a1[o[t]] == a1[o[r]] and a2[o[t]] == a2[o[r]]:
                    t += 1
                for u in range(r, t):
                    mult[order[s + o[u]]] = t - r
                r = t
    return mult


@numba.njit(cache=True, nogil=True)
def _signed_volume(s, nodes, table, cols):  # pragma: no cover - compiled
    """Signed volume x 6 of solids ``s`` (k, 8) bounded by the faces ``table`` (nf, 4).

    Divergence theorem about the solid's centroid ``g`` (mean of the distinct nodes ``cols``):
    ``6 V = 2 sum_f (c_f - g) . A_f`` with ``2 A_f = (p2 - p0) x (p3 - p1)`` (the exact vector
    area of a quad, and of a triangle ``p0 p1 p2 p2``) and ``4 c_f = p0 + p1 + p2 + p3``, a point
    of the face's plane when it is planar (exact there); only the sign is used.
    """
    k = s.shape[0]
    vol = np.empty(k)
    nc = cols.shape[0]
    pts = np.empty((8, 3))
    for e in range(k):
        gx = 0.0
        gy = 0.0
        gz = 0.0
        for c in cols:
            v = s[e, c]
            gx += nodes[v, 0]
            gy += nodes[v, 1]
            gz += nodes[v, 2]
        gx /= nc
        gy /= nc
        gz /= nc
        for c in cols:
            v = s[e, c]
            pts[c, 0] = nodes[v, 0] - gx
            pts[c, 1] = nodes[v, 1] - gy
            pts[c, 2] = nodes[v, 2] - gz
        acc = 0.0
        for f in range(table.shape[0]):
            i0 = table[f, 0]
            i1 = table[f, 1]
            i2 = table[f, 2]
            i3 = table[f, 3]
            ux = pts[i2, 0] - pts[i0, 0]
            uy = pts[i2, 1] - pts[i0, 1]
            uz = pts[i2, 2] - pts[i0, 2]
            wx = pts[i3, 0] - pts[i1, 0]
            wy = pts[i3, 1] - pts[i1, 1]
            wz = pts[i3, 2] - pts[i1, 2]
            cx = pts[i0, 0] + pts[i1, 0] + pts[i2, 0] + pts[i3, 0]
            cy = pts[i0, 1] + pts[i1, 1] + pts[i2, 1] + pts[i3, 1]
            cz = pts[i0, 2] + pts[i1, 2] + pts[i2, 2] + pts[i3, 2]
            acc += cx * (uy * wz - uz * wy) + cy * (uz * wx - ux * wz) + cz * (ux * wy - uy * wx)
        vol[e] = acc / 4.0
    return vol
