"""Simplification of feature lines and subpatch borders (fe2003 §3.3).

The surfaces of planar subpatches are not simplified; the lines between them are. A line node
is removed while the resulting chord stays within the line's error bound ``l`` of every original
node it replaces (the "maximum allowed accumulated deviation"), never leaves the adjacent
subpatch planes by more than ``d``, and never removes a fixed node (where three or more feature
edges meet, so that the topology of the line network cannot change). The bound depends on how
much the two subpatches beside the line differ (eq. 1):

    l = l_inner · cos²Δ + l_outer · (1 − cos²Δ),    cos Δ = n1 · n2,

so lines between nearly coplanar subpatches (Δ ≈ 0) may be simplified coarsely (l_inner) and
silhouette lines, outer boundaries and sharp edges finely (l_outer). Removal order: smallest
deviation first (a priority queue of node removals, as an edge collapse on the line).
"""

from __future__ import annotations

import heapq

import numpy as np

__all__ = ["line_tolerance", "simplify_polyline"]


def line_tolerance(n1, n2, l_inner: float, l_outer: float) -> float:
    """Eq. 1 of fe2003: the error bound of a line between subpatches with unit plane normals
    ``n1`` and ``n2`` (for an outer boundary pass the same normal twice and use l_outer as
    l_inner). Model units."""
    c = float(np.dot(np.asarray(n1, np.float64), np.asarray(n2, np.float64)))
    c2 = min(c * c, 1.0)
    return l_inner * c2 + l_outer * (1.0 - c2)


def _segment_distances(points: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distances of ``points`` (k, 3) to the segment ab."""
    ab = b - a
    length_sq = float(ab @ ab)
    if length_sq == 0.0:
        return np.linalg.norm(points - a, axis=1)
    t = np.clip((points - a) @ ab / length_sq, 0.0, 1.0)
    return np.linalg.norm(points - (a + t[:, None] * ab), axis=1)


def simplify_polyline(points, tol: float, *, fixed=None, planes=(), d: float | None = None,
                      closed: bool = False) -> np.ndarray:
    """Indices of the nodes of polyline ``points`` (n, 3) kept after simplification.

    A node is removed when the chord between its kept neighbours stays within ``tol`` of every
    original node between them and, if ``planes`` ((normal, offset) pairs, points p with
    n·p + offset = 0) and ``d`` are given, the chord's end points lie within ``d`` of every plane
    (the chord then does too: distance to a plane is linear along it). End points of an open
    line and ``fixed`` nodes are never removed; a closed line keeps at least three nodes.
    Refuses fewer than two points, non-finite coordinates, a negative tolerance.
    """
    p = np.asarray(points, np.float64)
    if p.ndim != 2 or p.shape[1] != 3 or len(p) < 2:
        raise ValueError(f"points must be (n >= 2, 3), got {p.shape}")
    if not np.isfinite(p).all():
        raise ValueError("points must be finite")
    if not tol >= 0:
        raise ValueError(f"tol must be >= 0, got {tol}")
    n = len(p)
    keep_always = np.zeros(n, bool) if fixed is None else np.asarray(fixed, bool).copy()
    if not closed:
        keep_always[[0, -1]] = True
    plane_list = [(np.asarray(nrm, np.float64), float(off)) for nrm, off in planes]

    def off_planes(i: int) -> bool:
        return d is not None and any(abs(nrm @ p[i] + off) > d for nrm, off in plane_list)

    prev = np.arange(n) - 1
    nxt = np.arange(n) + 1
    if closed:
        prev[0], nxt[-1] = n - 1, 0
    alive = np.ones(n, bool)
    version = np.zeros(n, np.int64)

    def between(a: int, b: int) -> np.ndarray:
        """Original node indices strictly between a and b along the line."""
        if a < b:
            return np.arange(a + 1, b)
        return np.r_[np.arange(a + 1, n), np.arange(0, b)]

    def cost(i: int) -> float:
        a, b = prev[i], nxt[i]
        if keep_always[i] or a < 0 or b >= n or off_planes(a) or off_planes(b):
            return np.inf
        return float(_segment_distances(p[between(a, b)], p[a], p[b]).max())

    heap = [(cost(i), i, 0) for i in range(n)]
    heap = [h for h in heap if np.isfinite(h[0])]
    heapq.heapify(heap)
    count = n
    while heap:
        c, i, v = heapq.heappop(heap)
        if not alive[i] or v != version[i]:
            continue
        if c > tol or (closed and count <= 3):
            break
        a, b = prev[i], nxt[i]
        alive[i] = False
        count -= 1
        nxt[a], prev[b] = b, a
        for j in (a, b):
            if alive[j]:
                version[j] += 1
                cj = cost(j)
                if np.isfinite(cj):
                    heapq.heappush(heap, (cj, j, version[j]))
    return np.flatnonzero(alive)
