"""Cheap certified upper bounds for every triangle of A, so that only the triangles that may
hold the largest distance go through the exact refinement (the bracket-only mode of
:func:`~workbench.algo.hausdorff.hausdorff`, ``estimates=False``).

The distance to B is 1-Lipschitz and, to one face, convex. :func:`cascade` first bounds every
vertex v of A by its distance to one face of B, ``face[v]`` (:func:`_vertex_distances`, in
Morton order): every ``STRIDE``-th vertex is measured through B's tree, every other one takes
the face of the vertex before it (or one of that face's neighbours), and is measured through
the tree only where that bound exceeds the largest distance measured so far. The largest
measured distance is then the largest of all vertices', the first lower bound, and each bound
``dist[v] = d(v, face[v])`` is at least the vertex's distance. Each triangle T of A is then
bounded by the cheapest rule that brings it to the lower bound + tol:

1. **Lipschitz**: every point of T is within its cover radius r (:func:`_cover_radius`) of a
   corner, so ``max_{p ∈ T} d(p, B) <= max_i dist[t_i] + r``.
2. **Convexity**: ``max_{p ∈ T} d(p, B) <= max_i d(t_i, g)`` for any face g of B; here the
   corners' faces (a corner's distance to its own face is ``dist``: three corners on one face
   need no further distance).
3. **Cut along B's edges** (:func:`_straddle_range`): a T whose corners have different faces
   straddles their common edges; cut along the planes that bisect those edges
   (the corners' faces and the faces between them, up to ``_MAX_PIECES`` pieces), each piece
   is bounded by rule 2 against its own face, and the pieces cover T.

What stays above is for the exact refinement (:mod:`.refine`). Distances are in model units,
coordinates after the translation of :func:`hausdorff`; the bounds are computed values, to be
rounded outward with the rest of the bracket.
"""

from __future__ import annotations

from typing import NamedTuple

import numba
import numpy as np

from ..nearest.bvh import PARALLEL_MIN, bounding_box, nearest_one
from ..nearest.state import new_search
from ..nearest.triangle import closest_point_on_triangle
from .pieces import _shared_edge_plane


class Cascade(NamedTuple):
    """What the cascade found: ``upper`` (K,) a certified upper bound of the distance over each
    triangle of A; ``lower`` the largest exact distance measured at a point of A, attained at
    ``point_a`` with nearest point ``point_b`` of B; ``queries`` the points measured through
    the tree."""

    upper: np.ndarray
    lower: float
    point_a: np.ndarray
    point_b: np.ndarray
    queries: int


def _morton_order(points: np.ndarray) -> np.ndarray:
    """Indices that sort ``points`` (N, 3) along a Morton (Z-order) curve of 21 bits a axis."""
    lo, hi = bounding_box(points)
    span = float((hi - lo).max())
    return np.argsort(_morton_codes(points, lo, (2 ** 21 - 1) / span if span > 0 else 0.0))


@numba.njit(cache=True, inline="always")
def _spread(x):
    """The 21 low bits of x spread to every third bit."""
    x &= 0x1FFFFF
    x = (x | (x << 32)) & 0x1F00000000FFFF
    x = (x | (x << 16)) & 0x1F0000FF0000FF
    x = (x | (x << 8)) & 0x100F00F00F00F00F
    x = (x | (x << 4)) & 0x10C30C30C30C30C3
    return (x | (x << 2)) & 0x1249249249249249


@numba.njit(cache=True)
def _morton_codes(points, lo, scale):
    """(N,) int64 Morton codes of ``points`` on a grid of ``scale`` cells a unit from ``lo``."""
    out = np.empty(len(points), np.int64)
    top = 2 ** 21 - 1
    for i in range(len(points)):
        code = 0
        for k in range(3):
            q = min(max(int((points[i, k] - lo[k]) * scale), 0), top)
            code |= _spread(q) << k
        out[i] = code
    return out


@numba.njit(cache=True, inline="always")
def _cover_radius(t):
    """The least r such that every point of triangle t (3, 3) is within r of a corner: the
    circumradius ``L / (2 sin Θ)`` (L the longest edge, Θ the angle opposite it, from the law of
    cosines; Θ in [60°, 90°) is well conditioned) for an acute triangle, else L / 2."""
    ea = 0.0
    eb = 0.0
    ec = 0.0
    for k in range(3):
        ea += (t[1, k] - t[0, k]) ** 2
        eb += (t[2, k] - t[1, k]) ** 2
        ec += (t[0, k] - t[2, k]) ** 2
    longest = max(ea, max(eb, ec))
    rest = ea + eb + ec - longest
    if longest >= rest:  # right or obtuse (degenerate included)
        return 0.5 * np.sqrt(longest)
    x, y = (eb, ec) if longest == ea else ((ea, ec) if longest == eb else (ea, eb))
    cos = (x + y - longest) / (2.0 * np.sqrt(x * y))
    return 0.5 * np.sqrt(longest) / np.sqrt(max(1.0 - cos * cos, 0.75))


@numba.njit(cache=True)
def _bound_range(begin, end, tri, tri_vertices, dist, face, faces, target, out):
    """out[t] for t in [begin, end): the least of the Lipschitz bound from t's corners (upper
    bounds ``dist`` of the distances of A's vertices, each its distance to the vertex's face
    ``face``; every point of t is within the cover radius of a corner) and, while above
    ``target``, the convexity bound against each of its corners' faces (a corner on that face
    already has its distance: only the others are measured; three corners on one face cost
    nothing)."""
    tmp = np.empty(3)
    for t in range(begin, end):
        v0, v1, v2 = tri_vertices[t, 0], tri_vertices[t, 1], tri_vertices[t, 2]
        far = max(dist[v0], max(dist[v1], dist[v2]))
        f0, f1, f2 = face[v0], face[v1], face[v2]
        if f0 == f1 and f1 == f2:  # convexity against their common face
            out[t] = far
            continue
        best = far + _cover_radius(tri[t])
        if best > target:
            best_sq = best * best
            for j in range(3):
                f = face[tri_vertices[t, j]]
                worst = 0.0
                for i in range(3):
                    v = tri_vertices[t, i]
                    if face[v] == f:
                        d = dist[v] * dist[v]
                    else:
                        d = closest_point_on_triangle(tri[t, i], faces[f, 0], faces[f, 1],
                                                      faces[f, 2], tmp)
                    worst = max(worst, d)
                    if worst >= best_sq:
                        break
                best_sq = min(best_sq, worst)
                if best_sq <= target * target:
                    break
            best = min(best, np.sqrt(best_sq))
        out[t] = best


@numba.njit(cache=True, parallel=True)
def _bound_parallel(tri, tri_vertices, dist, face, faces, target, out):
    n = len(tri)
    for chunk in numba.prange((n + 255) // 256):
        _bound_range(chunk * 256, min(n, (chunk + 1) * 256), tri, tri_vertices, dist, face,
                     faces, target, out)


def _bound(tri, tri_vertices, dist, face, faces, target, out) -> None:
    args = (tri, tri_vertices, dist, face, faces, float(target), out)
    if len(tri) >= PARALLEL_MIN:
        _bound_parallel(*args)
    else:
        _bound_range(0, len(tri), *args)


@numba.njit(cache=True, inline="always")
def _cut(poly, count, pface, k, m, point, normal, other):
    """Cut piece k (``poly[k, :count[k]]``, bounded by face ``pface[k]``) by the plane through
    ``point`` with ``normal`` (pointing to its face's side): the side of its face stays at k,
    the other side goes to slot m, bounded by face ``other``; the cut points are computed once
    and shared. Returns the number of pieces now used (m + 1, or m when the plane misses)."""
    n = count[k]
    side = np.empty(8)
    n_pos = n_neg = 0
    for i in range(n):
        side[i] = ((poly[k, i, 0] - point[0]) * normal[0] + (poly[k, i, 1] - point[1])
                   * normal[1] + (poly[k, i, 2] - point[2]) * normal[2])
        n_pos += side[i] > 0.0
        n_neg += side[i] < 0.0
    if n_neg == 0:
        return m
    if n_pos == 0:
        pface[k] = other
        return m
    src = poly[k, :n].copy()
    na = nb = 0
    for i in range(n):
        j = (i + 1) % n
        if side[i] >= 0.0:
            poly[k, na] = src[i]
            na += 1
        if side[i] <= 0.0:
            poly[m, nb] = src[i]
            nb += 1
        if (side[i] > 0.0 and side[j] < 0.0) or (side[i] < 0.0 and side[j] > 0.0):
            t = side[i] / (side[i] - side[j])
            for c in range(3):
                poly[k, na, c] = src[i, c] + t * (src[j, c] - src[i, c])
                poly[m, nb, c] = poly[k, na, c]
            na += 1
            nb += 1
    count[k], count[m], pface[m] = na, nb, other
    return m + 1


STRIDE = 16  # every STRIDE-th vertex of A (Morton order) measured first
_MAX_FACES = 8  # faces of B a straddling triangle is cut against
_MAX_PIECES = 8


@numba.njit(cache=True, inline="always")
def _adjacent(f, g, neighbours):
    """Whether faces f and g share an edge (the face neighbour table, -1 padded)."""
    for k in range(neighbours.shape[1]):
        if neighbours[f, k] == g:
            return True
    return False


@numba.njit(cache=True, inline="always")
def _add(faces_list, m, f):
    """Append face f to ``faces_list[:m]`` unless it is there or the list is full; new m."""
    for j in range(m):
        if faces_list[j] == f:
            return m
    if m < len(faces_list):
        faces_list[m] = f
        m += 1
    return m


@numba.njit(cache=True)
def _straddle_range(idx, tri, tri_vertices, face, faces, neighbours, out):
    """out[t] lowered, for the triangles t in ``idx``, to the bound of t cut into pieces by the
    planes that bisect shared edges of B: the faces are its corners' nearest faces and the
    faces next to two of them; starting with the first face's piece, each further face that
    shares an edge with a face already placed cuts every piece of such a face along that
    edge's bisector (the cut points shared, so the pieces cover t). Each piece is bounded by
    its own face's largest vertex distance (convexity). Triangles that would need more than
    ``_MAX_PIECES`` pieces keep their bound."""
    poly = np.empty((_MAX_PIECES, 12, 3))
    count = np.zeros(_MAX_PIECES, np.int64)
    pface = np.zeros(_MAX_PIECES, np.int64)
    normal = np.empty(3)
    tmp = np.empty(3)
    cand = np.empty(_MAX_FACES, np.int64)
    placed = np.zeros(_MAX_FACES, np.bool_)
    for q in range(len(idx)):
        t = idx[q]
        m = 0
        for i in range(3):
            m = _add(cand, m, face[tri_vertices[t, i]])
        if m < 2:
            continue
        n_corner = m
        for i in range(n_corner):
            for j in range(i + 1, n_corner):
                if not _adjacent(cand[i], cand[j], neighbours):
                    for k in range(neighbours.shape[1]):
                        h = neighbours[cand[i], k]
                        if h >= 0 and _adjacent(cand[j], h, neighbours):
                            m = _add(cand, m, h)
        poly[0, :3] = tri[t]
        count[0], pface[0] = 3, cand[0]
        used = 1
        placed[:m] = False
        placed[0] = True
        ok = True
        progress = True
        while progress and ok:
            progress = False
            for j in range(1, m):
                if placed[j]:
                    continue
                g = cand[j]
                touches = False
                for k in range(used):
                    touches = touches or _adjacent(pface[k], g, neighbours)
                if not touches:
                    continue
                placed[j] = True
                progress = True
                for k in range(used):
                    f = pface[k]
                    if f == g or not _adjacent(f, g, neighbours):
                        continue
                    if used >= _MAX_PIECES or count[k] >= 11:
                        ok = False
                        break
                    on = _shared_edge_plane(faces[f], faces[g], normal)
                    if on >= 0:
                        used = _cut(poly, count, pface, k, used, faces[f, on], normal, g)
                if not ok:
                    break
        if not ok:
            continue
        bound_sq = 0.0
        for k in range(used):
            f = pface[k]
            for i in range(count[k]):
                bound_sq = max(bound_sq, closest_point_on_triangle(
                    poly[k, i], faces[f, 0], faces[f, 1], faces[f, 2], tmp))
        out[t] = min(out[t], np.sqrt(bound_sq))


@numba.njit(cache=True, parallel=True)
def _straddle_parallel(idx, tri, tri_vertices, face, faces, neighbours, out):
    n = len(idx)
    for chunk in numba.prange((n + 63) // 64):
        _straddle_range(idx[chunk * 64:min(n, (chunk + 1) * 64)], tri, tri_vertices, face,
                        faces, neighbours, out)


def _straddle(idx, tri, tri_vertices, face, faces, neighbours, out) -> None:
    if len(idx) >= PARALLEL_MIN // 16:
        _straddle_parallel(idx, tri, tri_vertices, face, faces, neighbours, out)
    else:
        _straddle_range(idx, tri, tri_vertices, face, faces, neighbours, out)


@numba.njit(cache=True)
def _vertex_range(begin, end, points, floor_sq, dist_sq, face, exact, neighbours, tree):
    """Squared distance bounds of ``points[begin:end]`` (in Morton order) to B (its ``tree``, a
    :class:`~workbench.algo.nearest.state.Tree`), some measured
    already (``exact``): every other point is bounded by its distance to the face of the point
    before it, or else to one of that face's neighbours, and measured through the tree only
    where the bound exceeds ``floor_sq`` (the largest squared distance measured so far) -- a
    point bounded below it can neither raise the lower bound nor needs more than a valid
    bound."""
    corners = tree.corners
    search = new_search(tree.depth)
    tmp = search.tmp
    previous = -1
    for i in range(begin, end):
        if exact[i]:
            previous = face[i]
            continue
        if previous >= 0:
            t = corners[previous]
            d = closest_point_on_triangle(points[i], t[0], t[1], t[2], tmp)
            g = previous
            k = 0
            while d > floor_sq and k < neighbours.shape[1] and neighbours[previous, k] >= 0:
                h = neighbours[previous, k]
                t = corners[h]
                e = closest_point_on_triangle(points[i], t[0], t[1], t[2], tmp)
                if e < d:
                    d, g = e, h
                k += 1
            if d <= floor_sq:
                dist_sq[i], face[i] = d, g
                previous = g
                continue
        d, f = nearest_one(points[i], previous, np.inf, tree, search)
        dist_sq[i], face[i], exact[i] = d, f, True
        floor_sq = max(floor_sq, d)  # a measured distance: the lower bound is at least it
        previous = f


@numba.njit(cache=True, parallel=True)
def _vertex_parallel(points, floor_sq, dist_sq, face, exact, neighbours, tree):
    n = len(points)
    per = 256
    for chunk in numba.prange((n + per - 1) // per):
        _vertex_range(chunk * per, min(n, (chunk + 1) * per), points, floor_sq, dist_sq, face,
                      exact, neighbours, tree)


def _vertex_distances(points: np.ndarray, bvh,
                      neighbours: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(distance bounds, faces, which are exact) of ``points`` (in Morton order) to B: every
    ``STRIDE``-th point measured first, the others bounded through their neighbour's face (or
    its neighbours, ``neighbours`` (F, w)) and measured only where that bound exceeds the
    largest measured distance (:func:`_vertex_range`). The largest exact distance is the
    largest distance of all."""
    n = len(points)
    dist_sq = np.empty(n)
    face = np.empty(n, np.int64)
    exact = np.zeros(n, np.bool_)
    sampled = np.arange(0, n, STRIDE)
    d, f, _ = bvh.nearest(points[sampled])
    dist_sq[sampled], face[sampled], exact[sampled] = d * d, f, True
    args = (points, float(np.max(d * d)), dist_sq, face, exact, neighbours, bvh.arrays())
    if n >= PARALLEL_MIN:
        _vertex_parallel(*args)
    else:
        _vertex_range(0, n, *args)
    return np.sqrt(dist_sq), face, exact


def cascade(vertices: np.ndarray, tri_vertices: np.ndarray, corners: np.ndarray, bvh,
            neighbours: np.ndarray, tol: float) -> Cascade:
    """Certified upper bounds of the distance to B over every triangle of A (``vertices``
    (N, 3), all used, ``tri_vertices`` (K, 3) int64, their ``corners`` (K, 3, 3)), against B's
    tree ``bvh`` (:class:`~workbench.algo.nearest.bvh.TriangleBVH`) and face neighbours
    ``neighbours``
    (F, w), -1 padded; see the module notes. ``tol``: the bracket width sought (bounds at most
    the lower bound + tol are not tightened further)."""
    order = _morton_order(vertices)
    d_sorted, f_sorted, exact = _vertex_distances(np.ascontiguousarray(vertices[order]), bvh,
                                                  neighbours)
    dist = np.empty(len(vertices))
    face = np.empty(len(vertices), np.int64)
    dist[order], face[order] = d_sorted, f_sorted
    i = order[int(np.argmax(np.where(exact, d_sorted, -1.0)))]
    lower, point_a = float(dist[i]), vertices[i]
    _, _, near = bvh.nearest(point_a[None])
    point_b = near[0]
    upper = np.empty(len(corners))
    _bound(corners, tri_vertices, dist, face, bvh.corners, lower + tol, upper)
    _straddle(np.flatnonzero(upper > lower + tol), corners, tri_vertices, face, bvh.corners,
              neighbours, upper)
    return Cascade(upper, lower, point_a, point_b, int(exact.sum()))
