"""Queries of the element hierarchy (numba): the nearest element of points, with parts excluded
per point (crash2000 §4.1), each part's nearest element, and the elements a plane cuts
(§4.2).

The kernels take the flat forest of :class:`~workbench.algo.nearest.hierarchy.ElementHierarchy`
(packed bounding volumes, children, element ranges, each node's part) and its elements as the
NamedTuples of :mod:`.state`, and count the tests of crash2000's Table 2. Distances are
squared, exact float64, in the hierarchy's local coordinates.
"""

from __future__ import annotations

import numba
import numpy as np

from ..triangle import closest_point_on_triangle
from .state import LeafSearch

_CHUNK = 64  # points per parallel work item
# a box or slab is pruned only when its squared distance exceeds the bound by this share
_SLACK = 1.0 + 1e-12
_SLACK_DIV = 1.0 / _SLACK  # pruned when d2 * _SLACK_DIV >= best


@numba.njit(cache=True, inline="always")
def _bv_distance_sq(bv, node, p0, p1, p2, obb):
    """Squared distance from (p0, p1, p2) to bounding volume ``node`` (0 inside)."""
    d = 0.0
    if obb:
        x0 = p0 - bv[node, 0]
        x1 = p1 - bv[node, 1]
        x2 = p2 - bv[node, 2]
        for k in range(3):
            t = abs(bv[node, 3 + 3 * k] * x0 + bv[node, 4 + 3 * k] * x1
                    + bv[node, 5 + 3 * k] * x2) - bv[node, 12 + k]
            if t > 0.0:
                d += t * t
    else:
        e = bv[node, 0] - p0
        if e > 0.0:
            d += e * e
        else:
            e = p0 - bv[node, 3]
            if e > 0.0:
                d += e * e
        e = bv[node, 1] - p1
        if e > 0.0:
            d += e * e
        else:
            e = p1 - bv[node, 4]
            if e > 0.0:
                d += e * e
        e = bv[node, 2] - p2
        if e > 0.0:
            d += e * e
        else:
            e = p2 - bv[node, 5]
            if e > 0.0:
                d += e * e
    return d


# the squared point/bounding-volume distance under its public name, for searches of other
# criteria over the same forest (:mod:`workbench.algo.nearest.penetrations`)
bv_distance_sq = _bv_distance_sq


@numba.njit(cache=True, inline="always")
def _is_excluded(node, node_part, own, o0, o1):
    q = node_part[node]
    for k in range(o0, o1):
        if own[k] == q:
            return True
    return False


@numba.njit(cache=True)
def _nearest_one(p, best, root, own, o0, o1, forest, elements, plane_test, search, counts):
    """Squared distance and tree-order index of the nearest element to p strictly nearer than
    ``best`` (-1 when none), searching ``forest`` (a :class:`~.state.Forest` over ``elements``,
    an :class:`~.state.Elements`) from ``root`` and skipping the part trees whose index is in
    own[o0:o1]. Adds to counts: bv tests, element tests, plane skips, leaf elements.
    ``search`` (a :class:`~.state.LeafSearch`): ``stack``/``stack_d`` scratch of depth + 2
    entries, ``tmp`` (3,), ``leaf_g``/``leaf_j`` scratch of the largest leaf's size."""
    bv = forest.bv
    obb = forest.obb
    left = forest.left
    right = forest.right
    start = forest.start
    end = forest.end
    node_part = forest.node_part
    corners = elements.corners
    n_tri = elements.n_tri
    slab = elements.slab
    stack = search.stack
    stack_d = search.stack_d
    tmp = search.tmp
    leaf_g = search.leaf_g
    leaf_j = search.leaf_j
    best_e = -1
    p0, p1, p2 = p[0], p[1], p[2]
    if node_part[root] >= 0 and _is_excluded(root, node_part, own, o0, o1):
        return best, best_e
    d = _bv_distance_sq(bv, root, p0, p1, p2, obb)
    counts[0] += 1
    if d * _SLACK_DIV >= best:
        return best, best_e
    stack[0] = root
    stack_d[0] = d
    top = 1
    while top > 0:
        top -= 1
        node = stack[top]
        if stack_d[top] * _SLACK_DIV >= best:
            continue
        c = left[node]
        if c < 0:
            s0 = start[node]
            m = end[node] - s0
            counts[3] += m
            if not plane_test:
                for j in range(s0, s0 + m):
                    counts[1] += 1
                    for t in range(n_tri[j]):
                        dt = closest_point_on_triangle(p, corners[j, t, 0], corners[j, t, 1],
                                                       corners[j, t, 2], tmp)
                        if dt < best:
                            best = dt
                            best_e = j
                continue
            # the leaf's elements by increasing slab distance (insertion sort, stable): the
            # nearest candidates first, and all the rest skipped once a slab is too far
            for k in range(m):
                j = s0 + k
                s = slab[j, 0] * p0 + slab[j, 1] * p1 + slab[j, 2] * p2
                g = slab[j, 3] - s
                g = max(g, s - slab[j, 4])
                g2 = g * g if g > 0.0 else 0.0
                pos = k
                while pos > 0 and leaf_g[pos - 1] > g2:
                    leaf_g[pos] = leaf_g[pos - 1]
                    leaf_j[pos] = leaf_j[pos - 1]
                    pos -= 1
                leaf_g[pos] = g2
                leaf_j[pos] = j
            for k in range(m):
                if leaf_g[k] * _SLACK_DIV >= best:
                    counts[2] += m - k
                    break
                j = leaf_j[k]
                counts[1] += 1
                for t in range(n_tri[j]):
                    dt = closest_point_on_triangle(p, corners[j, t, 0], corners[j, t, 1],
                                                   corners[j, t, 2], tmp)
                    if dt < best:
                        best = dt
                        best_e = j
            continue
        c1 = right[node]
        check = node_part[node] < 0  # children of a top node may be (excluded) part roots
        use0 = not (check and node_part[c] >= 0 and _is_excluded(c, node_part, own, o0, o1))
        use1 = not (check and node_part[c1] >= 0 and _is_excluded(c1, node_part, own, o0, o1))
        d0 = np.inf
        d1 = np.inf
        if use0:
            d0 = _bv_distance_sq(bv, c, p0, p1, p2, obb)
            counts[0] += 1
        if use1:
            d1 = _bv_distance_sq(bv, c1, p0, p1, p2, obb)
            counts[0] += 1
        if d0 <= d1:
            near, far, dn, df = c, c1, d0, d1
        else:
            near, far, dn, df = c1, c, d1, d0
        if df * _SLACK_DIV < best:
            stack[top] = far
            stack_d[top] = df
            top += 1
        if dn * _SLACK_DIV < best:
            stack[top] = near
            stack_d[top] = dn
            top += 1
    return best, best_e


@numba.njit(cache=True, parallel=True)
def _nearest_many(points, active, exclusion, best0, forest, elements, plane_test, out_d2,
                  out_elem, counts):
    """For each active point, the nearest element of ``elements`` in ``forest`` strictly
    nearer than ``best0`` and not of a part ``exclusion`` (an :class:`~.state.Exclusion`)
    lists for it: squared distance into ``out_d2``, tree-order index into ``out_elem`` (inf,
    -1 where none or inactive), its tests into ``counts[i]``."""
    ptr = exclusion.ptr
    own = exclusion.own
    root = forest.root
    depth = forest.depth
    max_leaf = forest.max_leaf
    n = len(points)
    n_chunks = (n + _CHUNK - 1) // _CHUNK
    for chunk in numba.prange(n_chunks):
        search = LeafSearch(np.empty(2 * depth + 4, np.int64), np.empty(2 * depth + 4),
                            np.empty(3), np.empty(max_leaf), np.empty(max_leaf, np.int64))
        for i in range(chunk * _CHUNK, min(n, (chunk + 1) * _CHUNK)):
            if not active[i]:
                out_d2[i] = np.inf
                out_elem[i] = -1
                continue
            d, e = _nearest_one(points[i], best0, root, own, ptr[i], ptr[i + 1], forest,
                                elements, plane_test, search, counts[i])
            out_d2[i] = d
            out_elem[i] = e


@numba.njit(cache=True, parallel=True)
def _per_part_many(points, active, exclusion, best0, forest, elements, offsets, counts,
                   out_part, out_d2, fill):
    """For each point, walk the top level of ``forest`` to every part root within ``best0``
    (not excluded by ``exclusion``) and search that part for its nearest element. First pass
    (fill False) counts the parts found per point into ``counts``; the second writes (part
    index, squared distance) at ``offsets``."""
    ptr = exclusion.ptr
    own = exclusion.own
    bv = forest.bv
    obb = forest.obb
    left = forest.left
    right = forest.right
    node_part = forest.node_part
    root = forest.root
    depth = forest.depth
    max_leaf = forest.max_leaf
    n = len(points)
    n_chunks = (n + _CHUNK - 1) // _CHUNK
    for chunk in numba.prange(n_chunks):
        search = LeafSearch(np.empty(2 * depth + 4, np.int64), np.empty(2 * depth + 4),
                            np.empty(3), np.empty(max_leaf), np.empty(max_leaf, np.int64))
        stack2 = np.empty(2 * depth + 4, np.int64)
        scratch = np.zeros(4, np.int64)
        for i in range(chunk * _CHUNK, min(n, (chunk + 1) * _CHUNK)):
            k = 0
            if active[i]:
                p = points[i]
                stack2[0] = root
                top = 1
                while top > 0:
                    top -= 1
                    node = stack2[top]
                    if node_part[node] >= 0:
                        if _is_excluded(node, node_part, own, ptr[i], ptr[i + 1]):
                            continue
                        d, e = _nearest_one(p, best0, node, own, 0, 0, forest, elements, True,
                                            search, scratch)
                        if e >= 0:
                            if fill:
                                out_part[offsets[i] + k] = node_part[node]
                                out_d2[offsets[i] + k] = d
                            k += 1
                        continue
                    if _bv_distance_sq(bv, node, p[0], p[1], p[2], obb) * _SLACK_DIV >= best0:
                        continue
                    stack2[top] = left[node]
                    stack2[top + 1] = right[node]
                    top += 2
            if not fill:
                counts[i] = k


@numba.njit(cache=True)
def _cut(ql, unit, tol, q, nrm, forest, element_nodes, coords, out):
    """Tree-order indices of the elements of ``forest`` (a :class:`~.state.Forest`) cut by the
    plane (see cut_by_plane) into ``out``; returns how many."""
    bv = forest.bv
    obb = forest.obb
    left = forest.left
    right = forest.right
    start = forest.start
    end = forest.end
    stack = np.empty(2 * forest.depth + 4, np.int64)
    stack[0] = forest.root
    top = 1
    k = 0
    while top > 0:
        top -= 1
        node = stack[top]
        if obb:
            s = (unit[0] * (bv[node, 0] - ql[0]) + unit[1] * (bv[node, 1] - ql[1])
                 + unit[2] * (bv[node, 2] - ql[2]))
            r = 0.0
            for a in range(3):
                r += bv[node, 12 + a] * abs(unit[0] * bv[node, 3 + 3 * a]
                                            + unit[1] * bv[node, 4 + 3 * a]
                                            + unit[2] * bv[node, 5 + 3 * a])
        else:
            s = 0.0
            r = 0.0
            for a in range(3):
                c = 0.5 * (bv[node, a] + bv[node, 3 + a])
                h = 0.5 * (bv[node, 3 + a] - bv[node, a])
                s += unit[a] * (c - ql[a])
                r += abs(unit[a]) * h
        if abs(s) > r + tol:
            continue
        c = left[node]
        if c >= 0:
            stack[top] = c
            stack[top + 1] = right[node]
            top += 2
            continue
        for j in range(start[node], end[node]):
            pos = False
            neg = False
            for m in range(4):
                v = element_nodes[j, m]
                sd = ((coords[v, 0] - q[0]) * nrm[0] + (coords[v, 1] - q[1]) * nrm[1]
                      + (coords[v, 2] - q[2]) * nrm[2])
                if sd > 0.0:
                    pos = True
                elif sd < 0.0:
                    neg = True
                else:
                    pos = True
                    neg = True
            if pos and neg:
                out[k] = j
                k += 1
    return k
