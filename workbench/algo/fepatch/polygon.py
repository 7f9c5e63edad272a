"""Retriangulation of planar polygons with holes (fe2003, Rose & Ertl, section 3.4).

A simplified subpatch is bounded by an outer loop and possibly some hole loops of node indices,
its nodes projected on the subpatch plane. The outer loop is oriented counter-clockwise and the
holes clockwise; every hole is joined to the outer boundary by a bridge (a pair of coincident,
opposite edges) so that one weakly simple loop remains, which is then cut into triangles by ear
clipping. The ear clipper takes ears from a priority queue that prefers near-equilateral
triangles: the ear whose triangle has the largest minimum angle goes first.

No point is added and no coordinate changes: triangles are triples of the input point indices,
so the result shares the nodes of the original model.
"""

from __future__ import annotations

import heapq
import math
from collections.abc import Sequence

import numpy as np

__all__ = ["polygon_area", "triangulate_polygon"]

# Edge pairs tested at once by the self-intersection check (bounds its temporary memory).
_PAIR_BLOCK = 1 << 20


def polygon_area(points2d: np.ndarray, loop: Sequence[int] | np.ndarray) -> float:
    """Signed area of the closed loop ``points2d[loop]`` (shoelace formula).

    Positive for a counter-clockwise loop, negative for a clockwise one, in squared units of
    ``points2d``. The loop is not closed explicitly (its last point connects to its first).
    Coordinates are taken relative to the loop's first point, which keeps the sum accurate
    for polygons far from the origin (car coordinates in millimetres).
    """
    pts = np.asarray(points2d, dtype=np.float64)
    idx = np.asarray(loop, dtype=np.int64)
    if pts.ndim != 2 or pts.shape[1] != 2:
        raise ValueError(f"points2d must be (N, 2), got {pts.shape}")
    if idx.ndim != 1 or len(idx) == 0:
        raise ValueError("loop must be a non-empty 1-D sequence of point indices")
    p = pts[idx] - pts[idx[0]]
    x, y = p[:, 0], p[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))


def triangulate_polygon(
    points2d: np.ndarray,
    outer: Sequence[int] | np.ndarray,
    holes: Sequence[Sequence[int] | np.ndarray] = (),
    *,
    validate: bool = True,
) -> np.ndarray:
    """Triangulate the polygon bounded by ``outer`` with the given ``holes``.

    Parameters
    ----------
    points2d:
        (N, 2) float coordinates (any planar length unit, e.g. node positions projected on a
        subpatch plane). Points not named by any loop are ignored.
    outer:
        Point indices of the outer boundary loop, either orientation, not closed (the last
        index connects to the first).
    holes:
        Index loops of the holes, either orientation, each strictly inside ``outer``.
    validate:
        Run the simplicity checks listed below; they test every pair of boundary edges whose
        x-ranges overlap (O(E^2) for E edges at worst, far fewer on typical outlines). Skip
        them only for input known to be simple.

    Returns
    -------
    (K, 3) int64 array of point indices, every triangle counter-clockwise, with
    ``K = n_points + 2 * n_holes - 2`` where ``n_points`` counts the points of all loops.
    The triangles exactly tile the polygon: their areas sum to the outer area minus the hole
    areas and their interiors are disjoint.

    Raises
    ------
    ValueError
        Always detected: ``points2d`` not (N, 2) or not finite; a loop with fewer than 3
        points, an index out of range, the same index twice in a row (including last ==
        first, i.e. an explicitly closed loop); a point index used twice anywhere in the
        loops; two loop points with identical coordinates; a loop of zero area.
        With ``validate`` (default): any two boundary edges that cross, touch or overlap
        (other than neighbours sharing their common point), a spike (an edge folding back
        on its predecessor), a hole not strictly inside the outer loop, and a hole inside
        another hole. The tests are floating-point orientation tests without tolerance, so
        boundaries that come within rounding distance of each other count as touching only
        when the rounded predicates say so.
        Without ``validate``, self-intersecting input may still be refused when no ear can
        be found, but may also yield overlapping triangles.
    """
    pts = np.asarray(points2d, dtype=np.float64)
    if pts.ndim != 2 or pts.shape[1] != 2:
        raise ValueError(f"points2d must be (N, 2), got {pts.shape}")
    if not np.isfinite(pts).all():
        raise ValueError("points2d contains NaN or infinite coordinates")
    n_pts = len(pts)
    loops = [_as_loop(outer, n_pts, "outer")]
    loops += [_as_loop(h, n_pts, f"holes[{k}]") for k, h in enumerate(holes)]
    _check_distinct(pts, loops)

    for k, loop in enumerate(loops):
        area = polygon_area(pts, loop)
        name = "outer" if k == 0 else f"holes[{k - 1}]"
        if area == 0.0:
            raise ValueError(f"{name} has zero area")
        # The outer loop runs counter-clockwise, holes clockwise: the polygon's interior is
        # then on the left of every boundary edge.
        if (area < 0.0) == (k == 0):
            loops[k] = loop[::-1].copy()

    if validate:
        _check_simple(pts, loops)

    chain = loops[0]
    hole_loops = loops[1:]
    # Holes are bridged from right to left, so that a hole's ray to the right meets holes
    # already merged into the outer loop rather than passing between unmerged ones.
    order = sorted(
        range(len(hole_loops)), key=lambda k: -float(pts[hole_loops[k], 0].max())
    )
    for k in order:
        chain = _bridge_hole(pts, chain, hole_loops[k], k)
    return _ear_clip(pts, chain)


def _as_loop(loop, n_pts: int, name: str) -> np.ndarray:
    arr = np.asarray(loop)
    if arr.ndim != 1:
        raise ValueError(f"{name} must be a 1-D sequence of point indices, got shape {arr.shape}")
    if len(arr) < 3:
        raise ValueError(f"{name} has {len(arr)} points; a loop needs at least 3")
    if not np.issubdtype(arr.dtype, np.integer):
        raise ValueError(f"{name} must hold integer point indices, got dtype {arr.dtype}")
    arr = arr.astype(np.int64)
    if arr.min() < 0 or arr.max() >= n_pts:
        raise ValueError(f"{name} names a point outside 0..{n_pts - 1}")
    rep = np.flatnonzero(arr == np.roll(arr, -1))
    if len(rep):
        raise ValueError(
            f"{name} repeats index {int(arr[rep[0]])} at consecutive positions "
            f"{int(rep[0])} and {int((rep[0] + 1) % len(arr))} (loops are closed implicitly)"
        )
    return arr


def _check_distinct(pts: np.ndarray, loops: list[np.ndarray]) -> None:
    allidx = np.concatenate(loops)
    uniq, counts = np.unique(allidx, return_counts=True)
    if (counts > 1).any():
        raise ValueError(
            f"point index {int(uniq[counts > 1][0])} appears more than once in the loops; "
            "a boundary that touches itself is refused"
        )
    _, first, counts = np.unique(pts[allidx], axis=0, return_index=True, return_counts=True)
    if (counts > 1).any():
        p = allidx[first[counts > 1][0]]
        raise ValueError(f"point {int(p)} shares its coordinates with another loop point")


def _orient(ax, ay, bx, by, cx, cy):
    """Twice the signed area of (a, b, c): > 0 for a left turn."""
    return (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)


def _check_simple(pts: np.ndarray, loops: list[np.ndarray]) -> None:
    a_idx = np.concatenate(loops)
    b_idx = np.concatenate([np.roll(lp, -1) for lp in loops])
    c_idx = np.concatenate([np.roll(lp, -2) for lp in loops])
    a, b, c = pts[a_idx], pts[b_idx], pts[c_idx]

    # Spike: edge b->c folds back along a->b.
    u, v = b - a, c - b
    spike = (u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0] == 0.0) & ((u * v).sum(axis=1) < 0.0)
    if spike.any():
        raise ValueError(f"the boundary folds back on itself at point {int(b_idx[spike][0])}")

    # Candidate pairs: edges whose x-ranges overlap (sorted by left end, each edge paired with
    # the later ones that start before it ends), generated in blocks of bounded size.
    n_e = len(a_idx)
    left = np.minimum(a[:, 0], b[:, 0])
    right = np.maximum(a[:, 0], b[:, 0])
    order = np.argsort(left, kind="stable")
    end = np.searchsorted(left[order], right[order], side="right")
    counts = np.maximum(end - np.arange(1, n_e + 1), 0)
    cum = np.concatenate([[0], np.cumsum(counts)])
    start = 0
    while start < n_e:
        stop = max(start + 1, int(np.searchsorted(cum, cum[start] + _PAIR_BLOCK, side="right")) - 1)
        stop = min(stop, n_e)
        rows = np.arange(start, stop)
        c = counts[start:stop]
        first = np.repeat(rows, c)
        step = np.arange(len(first)) - np.repeat(cum[start:stop] - cum[start], c)
        i, j = order[first], order[first + 1 + step]
        start = stop
        if len(i) == 0:
            continue
        share = (
            (a_idx[i] == a_idx[j]) | (a_idx[i] == b_idx[j])
            | (b_idx[i] == a_idx[j]) | (b_idx[i] == b_idx[j])
        )
        i, j = i[~share], j[~share]
        if len(i) == 0:
            continue
        p, q, r, s = a[i], b[i], a[j], b[j]
        d1 = np.sign(_orient(r[:, 0], r[:, 1], s[:, 0], s[:, 1], p[:, 0], p[:, 1]))
        d2 = np.sign(_orient(r[:, 0], r[:, 1], s[:, 0], s[:, 1], q[:, 0], q[:, 1]))
        d3 = np.sign(_orient(p[:, 0], p[:, 1], q[:, 0], q[:, 1], r[:, 0], r[:, 1]))
        d4 = np.sign(_orient(p[:, 0], p[:, 1], q[:, 0], q[:, 1], s[:, 0], s[:, 1]))
        collinear = (d1 == 0) & (d2 == 0) & (d3 == 0) & (d4 == 0)
        lo1, hi1 = np.minimum(p, q), np.maximum(p, q)
        lo2, hi2 = np.minimum(r, s), np.maximum(r, s)
        boxes = ((lo1 <= hi2) & (lo2 <= hi1)).all(axis=1)
        hit = (d1 * d2 <= 0) & (d3 * d4 <= 0) & (~collinear | boxes)
        if hit.any():
            k = int(np.flatnonzero(hit)[0])
            raise ValueError(
                "boundary edges cross or touch: "
                f"({int(a_idx[i[k]])}, {int(b_idx[i[k]])}) and "
                f"({int(a_idx[j[k]])}, {int(b_idx[j[k]])})"
            )

    # With no edges crossing, one point per hole decides containment.
    outer = loops[0]
    for k, hole in enumerate(loops[1:]):
        if not _inside(pts, outer, pts[hole[0]]):
            raise ValueError(f"holes[{k}] is not inside the outer loop")
        for m, other in enumerate(loops[1:]):
            if m != k and _inside(pts, other, pts[hole[0]]):
                raise ValueError(f"holes[{k}] lies inside holes[{m}]")


def _inside(pts: np.ndarray, loop: np.ndarray, p: np.ndarray) -> bool:
    """Crossing-number test of one point against one loop (point not on the loop)."""
    a = pts[loop]
    b = np.roll(a, -1, axis=0)
    straddle = (a[:, 1] > p[1]) != (b[:, 1] > p[1])
    with np.errstate(divide="ignore", invalid="ignore"):
        x = a[:, 0] + (p[1] - a[:, 1]) * (b[:, 0] - a[:, 0]) / (b[:, 1] - a[:, 1])
    return bool(np.count_nonzero(straddle & (x > p[0])) % 2)


def _bridge_hole(pts: np.ndarray, chain: np.ndarray, hole: np.ndarray, k: int) -> np.ndarray:
    """Splice the clockwise ``hole`` into the counter-clockwise ``chain`` by a bridge.

    The bridge starts at the hole's rightmost point H. A ray from H to the right meets a
    boundary edge first at I; the edge's endpoint M with the larger x is the candidate. If a
    chain point lies in the triangle (H, I, M) it may hide M, and the one seen at the smallest
    angle from the ray (nearest on ties) is taken instead; that point is visible from H.
    Chain points can occur twice (earlier bridges), so a candidate must also see H inside its
    own corner of the polygon.
    """
    hp = pts[hole]
    h_pos = int(np.lexsort((hp[:, 1], -hp[:, 0]))[0])  # max x, then min y
    hx, hy = hp[h_pos]

    P = pts[chain]
    Q = np.roll(P, -1, axis=0)
    # The interior lies left of each edge, so the ray leaving the interior to the right meets
    # edges that run upwards.
    up = (P[:, 1] <= hy) & (hy <= Q[:, 1]) & (P[:, 1] != Q[:, 1])
    with np.errstate(divide="ignore", invalid="ignore"):
        x_hit = P[:, 0] + (hy - P[:, 1]) * (Q[:, 0] - P[:, 0]) / (Q[:, 1] - P[:, 1])
    cand = up & (x_hit >= hx)
    if not cand.any():
        raise ValueError(f"holes[{k}] is not inside the outer loop (no boundary to its right)")
    e = int(np.flatnonzero(cand)[np.argmin(x_hit[cand])])
    qx = float(x_hit[e])
    n = len(chain)
    m = e if P[e, 0] > Q[e, 0] else (e + 1) % n
    if qx != hx:
        mx, my = P[m]
        # Closed triangle (H, I, M), orientation-agnostic.
        t = [(hx, hy), (qx, hy), (mx, my)]
        o = [
            _orient(t[s][0], t[s][1], t[(s + 1) % 3][0], t[(s + 1) % 3][1], P[:, 0], P[:, 1])
            for s in range(3)
        ]
        in_tri = ((o[0] >= 0) & (o[1] >= 0) & (o[2] >= 0)) | (
            (o[0] <= 0) & (o[1] <= 0) & (o[2] <= 0)
        )
        in_tri &= (P[:, 0] > hx) & (P[:, 0] <= mx)
        in_tri &= _locally_inside(P, np.roll(P, 1, axis=0), Q, hx, hy)
        if in_tri.any():
            c = np.flatnonzero(in_tri)
            tan = np.abs(hy - P[c, 1]) / (P[c, 0] - hx)
            m = int(c[np.lexsort((P[c, 0], tan))[0]])
    rotated = np.roll(hole, -h_pos)
    return np.concatenate(
        [chain[: m + 1], rotated, rotated[:1], chain[m : m + 1], chain[m + 1 :]]
    )


def _locally_inside(P, Pprev, Pnext, hx, hy):
    """Whether the direction from each chain point towards (hx, hy) enters the polygon's
    interior corner at that point (interior on the left of the counter-clockwise chain)."""
    e0 = Pprev - P
    e1 = Pnext - P
    d = np.stack([hx - P[:, 0], hy - P[:, 1]], axis=1)

    def cross(u, v):
        return u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0]

    convex = cross(e1, e0) >= 0
    in_convex = (cross(e1, d) > 0) & (cross(d, e0) > 0)
    in_reflex = (cross(e0, d) < 0) | (cross(d, e1) < 0)
    return np.where(convex, in_convex, in_reflex)


def _min_angle(ax, ay, bx, by, cx, cy) -> float:
    """Smallest interior angle (radians) of a non-degenerate triangle."""
    def angle(px, py, qx, qy, rx, ry):
        ux, uy, vx, vy = qx - px, qy - py, rx - px, ry - py
        return math.atan2(abs(ux * vy - uy * vx), ux * vx + uy * vy)

    return min(
        angle(ax, ay, bx, by, cx, cy), angle(bx, by, cx, cy, ax, ay), angle(cx, cy, ax, ay, bx, by)
    )


def _ear_clip(pts: np.ndarray, chain: np.ndarray) -> np.ndarray:
    """Ear clipping of a counter-clockwise weakly simple loop, best-shaped ear first.

    An ear at b (neighbours a, c) is strictly convex and its closed triangle holds no loop
    point other than copies of a, b or c (bridges repeat points). Clipping b changes only the
    ears of a and c, whose heap entries are replaced (stale ones carry an old version number).
    """
    n = len(chain)
    X = pts[chain]
    xs, ys = X[:, 0], X[:, 1]
    xl, yl = xs.tolist(), ys.tolist()
    prv = list(range(-1, n - 1))
    prv[0] = n - 1
    nxt = list(range(1, n + 1))
    nxt[-1] = 0
    alive = np.ones(n, dtype=bool)
    version = [0] * n

    def quality(b: int) -> float | None:
        a, c = prv[b], nxt[b]
        ax, ay, bx, by, cx, cy = xl[a], yl[a], xl[b], yl[b], xl[c], yl[c]
        if _orient(ax, ay, bx, by, cx, cy) <= 0.0:
            return None
        sel = alive & (chain != chain[a]) & (chain != chain[b]) & (chain != chain[c])
        sel &= (xs >= min(ax, bx, cx)) & (xs <= max(ax, bx, cx))
        sel &= (ys >= min(ay, by, cy)) & (ys <= max(ay, by, cy))
        if sel.any():
            px, py = xs[sel], ys[sel]
            inside = (
                (_orient(ax, ay, bx, by, px, py) >= 0)
                & (_orient(bx, by, cx, cy, px, py) >= 0)
                & (_orient(cx, cy, ax, ay, px, py) >= 0)
            )
            if inside.any():
                return None
        return _min_angle(ax, ay, bx, by, cx, cy)

    heap: list[tuple[float, int, int]] = []

    def push(b: int) -> None:
        q = quality(b)
        if q is not None:
            heapq.heappush(heap, (-q, b, version[b]))

    for b in range(n):
        push(b)
    tris = []
    remaining = n
    rescanned = False
    while remaining > 3:
        if not heap:
            if rescanned:
                raise ValueError(
                    "no ear left to clip: the boundary is self-intersecting or degenerate"
                )
            # Safety net for nearly degenerate input: look at every corner once more.
            rescanned = True
            for b in np.flatnonzero(alive).tolist():
                version[b] += 1
                push(b)
            continue
        _, b, ver = heapq.heappop(heap)
        if not alive[b] or ver != version[b]:
            continue
        rescanned = False
        a, c = prv[b], nxt[b]
        tris.append((chain[a], chain[b], chain[c]))
        alive[b] = False
        nxt[a], prv[c] = c, a
        remaining -= 1
        for v in (a, c):
            version[v] += 1
            push(v)
    b = int(np.flatnonzero(alive)[0])
    tris.append((chain[prv[b]], chain[b], chain[nxt[b]]))
    return np.asarray(tris, dtype=np.int64).reshape(-1, 3)
