"""Certified Hausdorff distance between triangle meshes, exact in float64 (crash2000 §3.2).

The one-sided distance from surface A to surface B is ``H = sup_{p ∈ A} d(p, B)``. Sampling
only ever gives a lower bound, and sampled tools do not say how far below H they are;
:func:`hausdorff` returns a bracket ``lower <= H <= upper`` instead, narrowed to a tolerance:

1. Both meshes are translated by one float64 origin (the centre of A's bounding box), so
   coordinates far from the origin keep their digits in the differences.
2. **Lower bound**: exact distances (through :class:`~workbench.algo.bvh.TriangleBVH`) of A's
   vertices, edge midpoints and face centroids; each is the distance of a point of A, so their
   largest is <= H.
3. **Upper bound** per triangle T of A: the distance to one face f of B is convex in p, so over
   T it peaks at a corner, and ``min_f max_i d(t_i, f)`` bounds ``max_{p∈T} d(p, B)`` from above
   for any set of faces f; the first set is the nearest faces of T's samples.
4. **Refinement** of the triangles whose bound exceeds the lower bound + ``tol``. With
   ``split="planes"`` (default) a triangle is cut into convex pieces by planes chosen where the
   nearest face changes (the bisector of an edge of B, or where the distances to two faces
   cross), so that each piece has one face nearest to all its vertices and its bound equals its
   largest vertex distance: first against the samples' faces and their neighbours only, then,
   for the triangles still above, against every face near each piece, whose exact vertex
   distances raise the lower bound. With ``split="midpoint"`` the triangles are subdivided
   4 ways by :func:`~workbench.algo.distance.triangle_bounds` against the faces near them
   (slower: where two faces meet, a piece's bound only shrinks with its size). Either way the
   refinement stops when ``upper - lower <= tol`` or at the depth limit (``tol_reached``).

Any face set gives a valid upper bound; a lower bound needs the nearest face of each point it
measures, which the candidate sets hold by construction (see :func:`_gather`). Distances are in
model units; the bracket is exact up to float64 rounding of the distances themselves (relative
1e-16 of the coordinates after the translation).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numba
import numpy as np

from .bvh import PARALLEL_MIN, TriangleBVH, check_triangles, nearest_one, within
from .distance import closest_point_on_triangle, triangle_bounds

__all__ = ["HausdorffResult", "hausdorff"]

DEFAULT_REL_TOL = 1e-4  # of A's bounding-box diagonal
DEFAULT_MAX_DEPTH = 16
MAX_DEPTH_LIMIT = 30
SPLITS = ("planes", "midpoint")
# distances closer than this share of the coordinates are equal to rounding
_ROUNDING = 1e-13
# the candidate ball is widened by this share so that rounding never drops a nearest face
_BALL_SLACK = 1e-9
# degree-3 quadrature on a triangle: weights of each corner, each edge midpoint, the centroid
_W_CORNER, _W_EDGE, _W_CENTROID = 1.0 / 20.0, 2.0 / 15.0, 9.0 / 20.0


@dataclass(frozen=True, eq=False)
class HausdorffResult:
    """The Hausdorff distance from surface A to surface B as a certified bracket (model units).

    ``lower <= H <= upper``; ``max`` is the best estimate, the lower bound (a distance actually
    attained at ``location[0]``). ``mean`` and ``rms`` are area-weighted **sample estimates** of
    the distance over A (a degree-3 rule on each triangle: corners, edge midpoints, centroid),
    not bounds. ``location`` (2, 3): the point of A where ``lower`` is attained and the point of
    B nearest to it, in the input coordinates. ``samples``: points whose exact distance was
    queried through the tree (vertices, edge midpoints, centroids; the corners visited by the
    subdivision are not counted). ``refined``: triangles of A bounded against every face near
    them (the last refinement step). ``area``: A's area. ``tol_reached``:
    ``upper - lower <= tol``.

    For the symmetric distance (``one_sided=False``) the bracket is the larger of both
    directions', ``mean``/``rms`` are taken over both surfaces by area, ``location[0]`` lies on
    the surface whose direction attains ``lower``, and ``forward`` (A to B) and ``backward``
    (B to A) hold the one-sided results.
    """

    max: float
    lower: float
    upper: float
    mean: float
    rms: float
    location: np.ndarray
    samples: int
    seconds: float
    tol: float
    tol_reached: bool
    refined: int
    area: float
    forward: HausdorffResult | None = None
    backward: HausdorffResult | None = None

    @property
    def width(self) -> float:
        """``upper - lower``: how far the estimate may be below the true distance."""
        return self.upper - self.lower


def hausdorff(va, fa, vb, fb, *, one_sided: bool = True, tol: float | None = None,
              max_depth: int = DEFAULT_MAX_DEPTH, split: str = "planes") -> HausdorffResult:
    """Certified Hausdorff distance from mesh A (``va`` (N, 3) float, ``fa`` (K, 3) int) to
    mesh B (``vb``, ``fb``), or the symmetric distance (the larger of both directions) when
    ``one_sided`` is False.

    ``tol`` (model units, default 1e-4 of A's bounding-box diagonal) is the bracket width to
    reach. ``split`` picks the refinement ("planes" or "midpoint", see the module notes);
    ``max_depth`` limits it: levels of 4-way subdivision, or three plane cuts per level
    (``tol_reached`` in the result says whether the width was reached). Unreferenced vertices
    are ignored, also when their coordinates are not finite; degenerate triangles are allowed
    (measured as their edges). Refused with ValueError naming the input: bad shapes, no
    triangles, non-integer or out-of-range indices, non-finite coordinates of used vertices;
    and a negative or non-finite ``tol``, a ``max_depth`` outside [0, 30], an unknown
    ``split``; a ``one_sided`` that is not a bool with TypeError.
    """
    start = time.perf_counter()
    va, fa = check_triangles(va, fa, "A (va, fa)")
    vb, fb = check_triangles(vb, fb, "B (vb, fb)")
    if not isinstance(one_sided, (bool, np.bool_)):
        raise TypeError(f"one_sided must be True or False, got {one_sided!r}")
    if int(max_depth) != max_depth or not 0 <= max_depth <= MAX_DEPTH_LIMIT:
        raise ValueError(f"max_depth must be an integer in [0, {MAX_DEPTH_LIMIT}], "
                         f"got {max_depth!r}")
    max_depth = int(max_depth)
    if split not in SPLITS:
        raise ValueError(f"split must be one of {SPLITS}, got {split!r}")
    used_a = np.unique(fa)
    lo, hi = va[used_a].min(axis=0), va[used_a].max(axis=0)
    origin = 0.5 * (lo + hi)
    if tol is None:
        tol = DEFAULT_REL_TOL * float(np.linalg.norm(hi - lo))
    elif not (np.isfinite(tol) and tol >= 0):
        raise ValueError(f"tol must be finite and >= 0 (model units), got {tol!r}")
    tol = float(tol)

    a = _Surface(va - origin, fa)
    b = _Surface(vb - origin, fb)
    forward = _one_sided(a, b, tol, max_depth, split, origin, start)
    if one_sided:
        return forward
    backward = _one_sided(b, a, tol, max_depth, split, origin, time.perf_counter())
    top = forward if forward.lower >= backward.lower else backward
    area = forward.area + backward.area
    if area > 0:
        mean = (forward.mean * forward.area + backward.mean * backward.area) / area
        rms = np.sqrt((forward.rms ** 2 * forward.area + backward.rms ** 2 * backward.area) / area)
    else:
        mean, rms = max(forward.mean, backward.mean), max(forward.rms, backward.rms)
    lower = max(forward.lower, backward.lower)
    upper = max(forward.upper, backward.upper)
    return HausdorffResult(
        max=lower, lower=lower, upper=upper, mean=float(mean), rms=float(rms),
        location=top.location, samples=forward.samples + backward.samples,
        seconds=time.perf_counter() - start, tol=tol,
        tol_reached=forward.tol_reached and backward.tol_reached,
        refined=forward.refined + backward.refined, area=area,
        forward=forward, backward=backward)


class _Surface:
    """A mesh near the origin with its used vertices compacted, and its tree built on demand."""

    def __init__(self, vertices: np.ndarray, triangles: np.ndarray):
        used, inverse = np.unique(triangles, return_inverse=True)
        self.vertices = np.ascontiguousarray(vertices[used])
        self.triangles = inverse.reshape(triangles.shape).astype(np.int64)
        self._bvh = None
        self._neighbours = None

    @property
    def neighbours(self) -> np.ndarray:
        if self._neighbours is None:
            self._neighbours = _face_neighbours(self.vertices, self.triangles)
        return self._neighbours

    @property
    def bvh(self) -> TriangleBVH:
        if self._bvh is None:
            self._bvh = TriangleBVH(self.vertices, self.triangles, leaf_size=2)
        return self._bvh


def _one_sided(a: _Surface, b: _Surface, tol: float, max_depth: int, split: str,
               origin: np.ndarray, start: float) -> HausdorffResult:
    bvh = b.bvh
    v, f = a.vertices, a.triangles
    nv = len(v)
    corners = np.ascontiguousarray(v[f])  # (K, 3, 3)

    # unique edges and, per triangle, its edges (01, 12, 20)
    pairs = np.sort(f[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1)
    keys, tri_edge = np.unique(pairs[:, 0] * nv + pairs[:, 1], return_inverse=True)
    tri_edge = tri_edge.reshape(-1, 3)
    edges = np.stack([keys // nv, keys % nv], axis=1)

    # exact distances of the samples; each search starts from a neighbour's nearest face
    dv, fv, pv = bvh.nearest(v)
    midpoints = 0.5 * (v[edges[:, 0]] + v[edges[:, 1]])
    dm, fm, pm = bvh.nearest(midpoints, hint=fv[edges[:, 0]])
    centroids = (corners[:, 0] + corners[:, 1] + corners[:, 2]) / 3.0
    dc, fc, pc = bvh.nearest(centroids, hint=fm[tri_edge[:, 0]])

    samples = [(dv, v, pv), (dm, midpoints, pm), (dc, centroids, pc)]
    lower, point_a, point_b = -1.0, None, None
    for d, pts, near in samples:
        i = int(np.argmax(d))
        if d[i] > lower:
            lower, point_a, point_b = float(d[i]), pts[i], near[i]

    # first upper bound per triangle from its samples' nearest faces
    candidates = np.concatenate([fv[f], fm[tri_edge], fc[:, None]], axis=1)
    candidates = np.sort(candidates, axis=1)
    upper = np.empty(len(f))
    _sample_upper(corners, candidates, bvh.corners, upper)

    # refine the triangles that can hold a larger distance, largest first
    if split == "planes":
        eps = _ROUNDING * max(np.abs(v).max(), np.abs(bvh.corners).max())
        _tighten(corners, np.flatnonzero(upper > lower + tol), candidates, b.neighbours, upper,
                 lower + tol, 3 * max_depth, eps, bvh.arrays())
    order = np.argsort(-upper, kind="stable")
    order = order[upper[order] > lower + tol]
    if split == "planes":
        new_lower, point, refined = _refine_planes(corners, order, upper, lower, tol,
                                                   3 * max_depth, eps, bvh.arrays())
        if point is not None and new_lower > lower:
            lower = new_lower
            _, _, near = bvh.nearest(point[None])
            point_a, point_b = point, near[0]
    else:
        new_lower, best_t, best_target, best_radius, refined = _refine(
            corners, order, upper, lower, tol, max_depth, *bvh.arrays())
        if best_t >= 0:
            # the subdivision raised the lower bound: find the point where it is attained
            found, point = _locate_in(corners[best_t], best_radius, best_target, max_depth,
                                      *bvh.arrays())
            if found >= lower:
                _, _, near = bvh.nearest(point[None])
                point_a, point_b = point, near[0]
            lower = max(found, new_lower)

    global_upper = max(float(upper.max()), lower)
    area2 = np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]),
                           axis=1)
    area = 0.5 * float(area2.sum())
    weights = area2 if area > 0 else np.ones(len(f))
    mean = float(_quadrature(dv[f], dm[tri_edge], dc, weights, 1))
    rms = float(np.sqrt(_quadrature(dv[f], dm[tri_edge], dc, weights, 2)))
    return HausdorffResult(
        max=lower, lower=lower, upper=global_upper, mean=mean, rms=rms,
        location=np.stack([point_a + origin, point_b + origin]),
        samples=len(v) + len(edges) + len(f), seconds=time.perf_counter() - start, tol=tol,
        tol_reached=global_upper - lower <= tol, refined=int(refined), area=area)


def _quadrature(d_corner, d_edge, d_centroid, weights, power):
    per_triangle = (_W_CORNER * (d_corner ** power).sum(axis=1)
                    + _W_EDGE * (d_edge ** power).sum(axis=1) + _W_CENTROID * d_centroid ** power)
    return (weights * per_triangle).sum() / weights.sum()


# --------------------------------------------------------------------------- numba kernels
@numba.njit(cache=True)
def _sample_upper_range(begin, end, tri, candidates, faces, out):
    """out[t] = min over the candidate slots c of max over t's corners of d(corner, faces[c])."""
    tmp = np.empty(3)
    for t in range(begin, end):
        best = np.inf
        previous = -1
        for j in range(candidates.shape[1]):
            c = candidates[t, j]
            if c == previous:  # candidates are sorted: skip repeats
                continue
            previous = c
            worst = 0.0
            for i in range(3):
                d = closest_point_on_triangle(tri[t, i], faces[c, 0], faces[c, 1], faces[c, 2],
                                              tmp)
                if d > worst:
                    worst = d
                    if worst >= best:
                        break
            best = min(best, worst)
        out[t] = np.sqrt(best)


@numba.njit(cache=True, parallel=True)
def _sample_upper_parallel(tri, candidates, faces, out):
    n = len(tri)
    for chunk in numba.prange((n + 255) // 256):
        _sample_upper_range(chunk * 256, min(n, (chunk + 1) * 256), tri, candidates, faces, out)


def _sample_upper(tri, candidates, faces, out):
    if len(tri) >= PARALLEL_MIN:
        _sample_upper_parallel(tri, candidates, faces, out)
    else:
        _sample_upper_range(0, len(tri), tri, candidates, faces, out)


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


@numba.njit(cache=True)
def _refine(tri, order, upper, lower, tol, max_depth, box_lo, box_hi, child, first, count,
            ref_tri, corners, depth):
    """Bound the triangles ``order`` (largest upper bound first) by subdivision against the
    faces near them; updates ``upper`` in place and returns (lower, triangle that set it, its
    subdivision target, its candidate radius, triangles refined)."""
    buffer = np.empty(len(ref_tri), np.int64)
    best_t, best_target, best_radius = -1, 0.0, 0.0
    refined = 0
    for t in order:
        target = lower + tol
        if upper[t] <= target:
            continue
        c, radius = _ball_radius(tri[t], upper[t])
        n = within(c, radius * radius, box_lo, box_hi, child, first, count, ref_tri, corners,
                   depth, buffer)
        if n == 0:  # cannot happen when upper[t] is a true bound; keep it as it is
            continue
        lo, up = triangle_bounds(tri[t], corners[buffer[:n]], target, max_depth)
        refined += 1
        upper[t] = min(upper[t], up)
        if lo > lower:
            lower, best_t, best_target, best_radius = lo, t, target, radius
    return lower, best_t, best_target, best_radius, refined


_MAX_POLY = 16  # vertices of a piece in the plane-split refinement
# a vertex this close to a cut plane, relative to the piece's radius, lies on it
_PLANE_ROUNDING = 1e-10
# a piece near more faces than this is halved before its conflicts are resolved
_MANY_FACES = 48
# a piece near more faces than this is halved without measuring it
_HUGE_FACES = 1024
# the triangles with the largest upper bounds refined one by one before the rest in parallel
_SERIAL_HEAD = 16


@numba.njit(cache=True)
def _shared_edge_plane(f, g, normal):
    """The plane through the edge that faces f and g (3, 3) share (equal corner coordinates),
    bisecting the angle between them: writes its unit normal (pointing into f's side) and
    returns the index of a corner of f on it, or -1 when they share no edge or fold onto
    each other."""
    shared = np.empty(2, np.int64)
    n_shared = 0
    f_only = -1
    for i in range(3):
        hit = False
        for j in range(3):
            if f[i, 0] == g[j, 0] and f[i, 1] == g[j, 1] and f[i, 2] == g[j, 2]:
                hit = True
        if hit and n_shared < 2:
            shared[n_shared] = i
            n_shared += 1
        elif not hit:
            f_only = i
    if n_shared != 2 or f_only < 0:
        return -1
    g_only = -1
    for j in range(3):
        if not ((g[j, 0] == f[shared[0], 0] and g[j, 1] == f[shared[0], 1]
                 and g[j, 2] == f[shared[0], 2])
                or (g[j, 0] == f[shared[1], 0] and g[j, 1] == f[shared[1], 1]
                    and g[j, 2] == f[shared[1], 2])):
            g_only = j
    if g_only < 0:
        return -1
    p = f[shared[0]]
    e = f[shared[1]] - p
    ee = e[0] * e[0] + e[1] * e[1] + e[2] * e[2]
    if ee == 0.0:
        return -1
    u = f[f_only] - p
    u = u - (u[0] * e[0] + u[1] * e[1] + u[2] * e[2]) / ee * e
    w = g[g_only] - p
    w = w - (w[0] * e[0] + w[1] * e[1] + w[2] * e[2]) / ee * e
    nu = np.sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2])
    nw = np.sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2])
    if nu == 0.0 or nw == 0.0:
        return -1
    m = u / nu - w / nw
    nm = np.sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2])
    if not nm > 1e-9:
        return -1
    normal[:] = m / nm
    return shared[0]


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


@numba.njit(cache=True)
def _gather(poly, n, bound, parent, full, corners, tree, scratch, pool, start):
    """The faces a piece (``poly``, n vertices, valid upper bound ``bound``) needs, written to
    ``pool`` from ``start`` (grown when short); returns (pool, how many), how many -1 when more
    than ``_HUGE_FACES`` are near (from the tree; not written).

    The nearest face f* of a point p of the piece lies within ``bound`` of p, and within
    d(c, B) + |p - c| of p (c the piece's centre, ρ its radius), so within
    ``min(bound + ρ, d(c, B) + 2ρ)`` of c; the second radius keeps the set small for pieces
    far from B. The faces are taken from ``parent`` (the parent piece's faces, which hold the
    nearest face of every point of the parent) by exact distance, or, for a long parent list
    and ``full``, from the tree (``tree``: box_lo, box_hi, child, first, count, ref_tri,
    depth; ``scratch``: room for every reference).
    """
    box_lo, box_hi, child, first, count, ref_tri, depth = tree
    c, rho = _piece_ball(poly, n)
    tmp = np.empty(3)
    if full and (len(parent) == 0 or len(parent) > _MANY_FACES):
        stack = np.empty(depth + 2, np.int64)
        stack_d = np.empty(depth + 2)
        near = np.empty(3)
        d_sq, _ = nearest_one(c, -1, np.inf, box_lo, box_hi, child, first, count, ref_tri,
                              corners, depth, stack, stack_d, tmp, near)
        radius = min(bound + rho, np.sqrt(d_sq) + 2.0 * rho) * (1.0 + _BALL_SLACK)
        m = within(c, radius * radius, box_lo, box_hi, child, first, count, ref_tri, corners,
                   depth, scratch, _HUGE_FACES)
        if m < 0:
            return pool, -1
    else:
        d = np.empty(len(parent))
        d_min = np.inf
        for k in range(len(parent)):
            face = corners[parent[k]]
            d[k] = closest_point_on_triangle(c, face[0], face[1], face[2], tmp)
            d_min = min(d_min, d[k])
        radius = min(bound + rho, np.sqrt(d_min) + 2.0 * rho) * (1.0 + _BALL_SLACK)
        m = 0
        for k in range(len(parent)):
            if d[k] <= radius * radius:
                scratch[m] = parent[k]
                m += 1
    if start + m > len(pool):
        grown = np.empty(2 * (start + m), np.int64)
        grown[:start] = pool[:start]
        pool = grown
    pool[start:start + m] = scratch[:m]
    return pool, m


@numba.njit(cache=True)
def _polygon_bounds(tri, start_upper, target, max_splits, eps, best_point, corners, tree,
                    fixed):
    """(lower, upper) of max over the points p of triangle ``tri`` (3, 3) of d(p, B), B the
    faces ``corners`` (F, 3, 3) in the tree ``tree`` (box_lo, box_hi, child, first, count,
    ref_tri, depth), given a valid upper bound ``start_upper``.

    A convex piece Q is bounded by ``min_f max_{v ∈ Q} d(v, f)`` over a set of faces f
    (distance to one face is convex, so its max over Q is at a vertex); the bound is exact when
    one face is the nearest of every vertex. First the faces are the vertices' nearest faces
    (from the tree), which settles most pieces; then every face near the piece
    (:func:`_gather`). Where no face serves, Q is cut by a plane into two convex pieces, each
    bounded alone; any plane keeps the bound valid. The plane is chosen so that on each side
    one face tends to be nearest: the bisector of the edge shared by the best single face f and
    the nearest face g of the vertex that spoils f; else the line where ``d(·, f) - d(·, g)``,
    interpolated along Q's edges, vanishes (exact for two face planes; never twice in a row);
    else the plane halfway across the piece from the spoiling vertex. A piece near many faces
    is halved first. A piece stops when its bound is <= ``target`` or within ``eps`` of its
    largest vertex distance, or after ``max_splits`` cuts.

    The vertex distances are exact (nearest faces from the tree; the faces near a piece hold
    the nearest face of each of its points), so their largest is a lower bound, attained at
    ``best_point``. With a non-empty ``fixed`` list of faces, the pieces use those faces (and
    subsets of them) only: the upper bound stays valid, the lower bound does not (a face set
    without the nearest faces overstates distances) and must be ignored.
    """
    full = len(fixed) == 0
    box_lo, box_hi, child, first, count, ref_tri, depth = tree
    size = max_splits + 4
    poly = np.empty((size, _MAX_POLY, 3))
    count_v = np.empty(size, np.int64)
    depth_v = np.empty(size, np.int64)
    kind = np.zeros(size, np.int64)  # how a piece was cut from its parent (2: secant)
    bound = np.empty(size)  # a valid upper bound over the piece: its parent's
    # the parent's faces, pool[parent_start[k]:parent_start[k] + parent_n[k]], from which a
    # piece takes its own (written after them) when it needs them
    parent_start = np.zeros(size, np.int64)
    parent_n = np.zeros(size, np.int64)
    tmp = np.empty(3)
    normal = np.empty(3)
    point = np.empty(3)
    side = np.empty(_MAX_POLY)
    quick = np.empty(_MAX_POLY, np.int64)
    stack = np.empty(depth + 2, np.int64)
    stack_d = np.empty(depth + 2)
    near = np.empty(3)
    scratch = np.empty(len(ref_tri) if full else len(fixed), np.int64)
    dist = np.empty((_MAX_POLY, 64))
    pool = np.empty(max(1024, 4 * len(fixed)), np.int64)
    pool[:len(fixed)] = fixed
    poly[0, :3] = tri
    count_v[0], depth_v[0], bound[0] = 3, 0, start_upper
    parent_n[0] = len(fixed)
    top = 1
    lower_sq = -1.0
    upper_sq = 0.0
    target_sq = target * target
    hint = -1
    while top > 0:
        top -= 1
        n = count_v[top]
        rho = _piece_ball(poly[top], n)[1]
        best_max = bound[top] * bound[top]
        piece_lower = 0.0
        if full:
            # the vertices' nearest faces: exact distances, and a bound that often settles
            # the piece without gathering the faces near it
            n_quick = 0
            for i in range(n):
                d, f = nearest_one(poly[top, i], hint, np.inf, box_lo, box_hi, child, first,
                                   count, ref_tri, corners, depth, stack, stack_d, tmp, near)
                hint = f
                piece_lower = max(piece_lower, d)
                if d > lower_sq:
                    lower_sq = d
                    best_point[:] = poly[top, i]
                new = True
                for j in range(n_quick):
                    new = new and quick[j] != f
                if new:
                    quick[n_quick] = f
                    n_quick += 1
            for j in range(n_quick):
                face = corners[quick[j]]
                worst = 0.0
                for i in range(n):
                    worst = max(worst, closest_point_on_triangle(poly[top, i], face[0], face[1],
                                                                 face[2], tmp))
                    if worst >= best_max:
                        break
                best_max = min(best_max, worst)
            if (best_max <= target_sq or np.sqrt(best_max) <= np.sqrt(piece_lower) + eps
                    or depth_v[top] >= max_splits or n + 2 > _MAX_POLY):
                upper_sq = max(upper_sq, best_max)
                continue
        free = parent_start[top] + parent_n[top]
        pool, n_faces = _gather(poly[top], n, np.sqrt(best_max),
                                pool[parent_start[top]:free], full, corners, tree, scratch, pool,
                                free)
        if n_faces == 0:  # only with fixed faces, none near this piece: keep the bound
            upper_sq = max(upper_sq, best_max)
            continue
        cut = 0
        n_pos = n_neg = 0
        if n_faces < 0 or n_faces > _HUGE_FACES:
            # near this many faces the piece cannot come out tight: halve it unmeasured; its
            # pieces take their faces from the tree
            if depth_v[top] >= max_splits or n + 2 > _MAX_POLY:
                upper_sq = max(upper_sq, best_max)
                continue
            n_faces = 0
            worst_v = _diameter_end(poly[top], n)
            done = False
        else:
            faces = pool[free:free + n_faces]
            if n_faces > dist.shape[1]:
                dist = np.empty((_MAX_POLY, 2 * n_faces))
            for i in range(n):
                for k in range(n_faces):
                    face = corners[faces[k]]
                    dist[i, k] = closest_point_on_triangle(poly[top, i], face[0], face[1],
                                                           face[2], tmp)
            # best single face, the vertex that spoils it most, the exact vertex distances
            best_f, piece_max = 0, np.inf
            for k in range(n_faces):
                worst = 0.0
                for i in range(n):
                    worst = max(worst, dist[i, k])
                if worst < piece_max:
                    best_f, piece_max = k, worst
            best_max = min(best_max, piece_max)
            worst_v, worst_d = 0, -1.0
            for i in range(n):
                if dist[i, best_f] > worst_d:
                    worst_v, worst_d = i, dist[i, best_f]
                nearest = np.inf
                for k in range(n_faces):
                    nearest = min(nearest, dist[i, k])
                piece_lower = max(piece_lower, nearest)
                if full and nearest > lower_sq:
                    lower_sq = nearest
                    best_point[:] = poly[top, i]
            done = (best_max <= target_sq or np.sqrt(best_max) <= np.sqrt(piece_lower) + eps
                    or depth_v[top] >= max_splits or n + 2 > _MAX_POLY)
            if not done:
                g, g_d = 0, np.inf
                for k in range(n_faces):
                    if dist[worst_v, k] < g_d:
                        g, g_d = k, dist[worst_v, k]
                if n_faces > _MANY_FACES:
                    # among many faces: halve the piece first (cheaper than resolving the
                    # conflicts of many faces in one piece, whose cost grows with their square)
                    worst_v = _diameter_end(poly[top], n)
                else:
                    on = _shared_edge_plane(corners[faces[best_f]], corners[faces[g]], normal)
                    if on >= 0:
                        cut = 1
                        n_pos, n_neg = _sides(poly[top], n, corners[faces[best_f], on], normal,
                                              rho, side)
                    if (n_pos == 0 or n_neg == 0) and kind[top] != 2:
                        cut = 2
                        n_pos, n_neg = _secant_plane(poly[top], dist, n, best_f, g, point,
                                                     normal)
                        if n_pos > 0:
                            n_pos, n_neg = _sides(poly[top], n, point, normal, rho, side)
        if not done and (n_pos == 0 or n_neg == 0):
            cut = 3
            far = _farthest(poly[top], n, worst_v)
            normal[:] = poly[top, far] - poly[top, worst_v]
            point[:] = 0.5 * (poly[top, far] + poly[top, worst_v])
            n_pos, n_neg = _sides(poly[top], n, point, normal, rho, side)
            done = n_pos == 0 or n_neg == 0
        if done:
            upper_sq = max(upper_sq, best_max)
            continue
        _split_piece(poly, count_v, depth_v, kind, bound, top, side, cut, np.sqrt(best_max))
        parent_start[top], parent_start[top + 1] = free, free
        parent_n[top], parent_n[top + 1] = n_faces, n_faces
        top += 2
    return np.sqrt(max(lower_sq, 0.0)), np.sqrt(max(upper_sq, lower_sq))


@numba.njit(cache=True)
def _tighten_range(begin, end, tri, order, sample_faces, neighbours, upper, target, max_splits,
                   eps, box_lo, box_hi, child, first, count, ref_tri, corners, depth):
    width = sample_faces.shape[1] * (1 + neighbours.shape[1])
    candidates = np.empty(width, np.int64)
    point = np.empty(3)
    tree = (box_lo, box_hi, child, first, count, ref_tri, depth)
    for k in range(begin, end):
        t = order[k]
        n = 0
        for j in range(sample_faces.shape[1]):
            f = sample_faces[t, j]
            for q in range(-1, neighbours.shape[1]):
                g = f if q < 0 else neighbours[f, q]
                if g < 0:
                    continue
                new = True
                for m in range(n):
                    if candidates[m] == g:
                        new = False
                        break
                if new:
                    candidates[n] = g
                    n += 1
        _, up = _polygon_bounds(tri[t], upper[t], target, max_splits, eps, point, corners, tree,
                                candidates[:n])
        upper[t] = min(upper[t], up)


@numba.njit(cache=True, parallel=True)
def _tighten_parallel(tri, order, sample_faces, neighbours, upper, target, max_splits, eps,
                      box_lo, box_hi, child, first, count, ref_tri, corners, depth):
    n = len(order)
    for chunk in numba.prange((n + 63) // 64):
        _tighten_range(chunk * 64, min(n, (chunk + 1) * 64), tri, order, sample_faces,
                       neighbours, upper, target, max_splits, eps, box_lo, box_hi, child, first,
                       count, ref_tri, corners, depth)


def _tighten(tri, order, sample_faces, neighbours, upper, target, max_splits, eps, bvh_arrays):
    """Upper bounds of the triangles ``order`` by plane cuts against the nearest faces of their
    samples and those faces' neighbours only (no tree queries): cheap, valid, and exact
    wherever those faces cover the triangle, which leaves few triangles for the full
    refinement."""
    args = (tri, order, sample_faces, neighbours, upper, target, max_splits, eps) + \
        tuple(bvh_arrays)
    if len(order) >= PARALLEL_MIN // 16:
        _tighten_parallel(*args)
    else:
        _tighten_range(0, len(order), *args)


def _face_neighbours(vertices: np.ndarray, triangles: np.ndarray, width: int = 6) -> np.ndarray:
    """(K, width) faces sharing an edge with each face (vertices welded by coordinates),
    padded with -1; on an edge of more than two faces, the faces next to it in index order."""
    _, weld = np.unique(vertices, axis=0, return_inverse=True)
    t = weld.reshape(-1)[triangles]
    k = len(t)
    pairs = np.sort(t[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1)
    keys = pairs[:, 0] * (int(weld.max()) + 1) + pairs[:, 1]
    order = np.argsort(keys, kind="stable")
    face = order // 3
    same = np.flatnonzero(keys[order][1:] == keys[order][:-1])
    same = same[face[same] != face[same + 1]]
    src = np.concatenate([face[same], face[same + 1]])
    dst = np.concatenate([face[same + 1], face[same]])
    out = np.full((k, width), -1, np.int64)
    if len(src):
        o = np.lexsort((dst, src))
        src, dst = src[o], dst[o]
        start = np.searchsorted(src, src, side="left")
        rank = np.arange(len(src)) - start
        keep = rank < width
        out[src[keep], rank[keep]] = dst[keep]
    return out


@numba.njit(cache=True)
def _refine_range(begin, end, tri, order, upper, target, max_splits, eps, box_lo, box_hi, child,
                  first, count, ref_tri, corners, depth, out_lower, out_point):
    """Bound the triangles ``order[begin:end]`` by plane cuts against every face near them
    (:func:`_polygon_bounds`), those whose upper bound exceeds ``target``: updates ``upper``,
    writes each one's lower bound and the point attaining it (-1 where skipped)."""
    tree = (box_lo, box_hi, child, first, count, ref_tri, depth)
    none = np.empty(0, np.int64)
    for k in range(begin, end):
        t = order[k]
        out_lower[k] = -1.0
        if upper[t] <= target:
            continue
        lo, up = _polygon_bounds(tri[t], upper[t], target, max_splits, eps, out_point[k],
                                 corners, tree, none)
        upper[t] = min(upper[t], up)
        out_lower[k] = lo


@numba.njit(cache=True, parallel=True)
def _refine_parallel(tri, order, upper, target, max_splits, eps, box_lo, box_hi, child, first,
                     count, ref_tri, corners, depth, out_lower, out_point):
    n = len(order)
    for chunk in numba.prange((n + 7) // 8):
        _refine_range(chunk * 8, min(n, (chunk + 1) * 8), tri, order, upper, target, max_splits,
                      eps, box_lo, box_hi, child, first, count, ref_tri, corners, depth,
                      out_lower, out_point)


def _refine_planes(tri, order, upper, lower, tol, max_splits, eps, bvh_arrays):
    """Bound the triangles ``order`` (largest upper bound first) by plane cuts against every
    face near them; updates ``upper``; returns (lower, the point attaining it or None, how
    many triangles were refined). The largest few go one by one, each raising the target for
    the next; the rest in parallel against the target reached."""
    out_lower = np.full(len(order), -1.0)
    out_point = np.zeros((len(order), 3))
    point = None
    head = min(len(order), _SERIAL_HEAD)
    for k in range(head):
        _refine_range(k, k + 1, tri, order, upper, lower + tol, max_splits, eps,
                      *bvh_arrays, out_lower, out_point)
        if out_lower[k] > lower:
            lower, point = float(out_lower[k]), out_point[k]
    if len(order) > head:
        rest = order[head:]
        tail_lower = np.full(len(rest), -1.0)
        tail_point = np.zeros((len(rest), 3))
        args = (tri, rest, upper, lower + tol, max_splits, eps) + tuple(bvh_arrays) + \
            (tail_lower, tail_point)
        if len(rest) >= 16:
            _refine_parallel(*args)
        else:
            _refine_range(0, len(rest), *args)
        best = int(np.argmax(tail_lower))
        if tail_lower[best] > lower:
            lower, point = float(tail_lower[best]), tail_point[best]
        out_lower[head:] = tail_lower
    return lower, point, int((out_lower >= 0).sum())


@numba.njit(cache=True)
def _locate_in(t, radius, target, max_depth, box_lo, box_hi, child, first, count, ref_tri,
               corners, depth):
    """A point of triangle t whose exact distance is at least the lower bound that
    ``triangle_bounds(t, faces, target, max_depth)`` reports, found by descending into the
    subdivision piece with the largest lower bound (a piece bounded on its own is subdivided at
    least as far as inside the whole, so its lower bound is never smaller)."""
    c, _ = _ball_radius(t, 0.0)
    buffer = np.empty(len(ref_tri), np.int64)
    n = within(c, radius * radius, box_lo, box_hi, child, first, count, ref_tri, corners, depth,
               buffer)
    faces = corners[buffer[:n]]
    piece = t.copy()
    tmp = np.empty(3)
    best = -1.0
    best_point = piece[0].copy()
    children = np.empty((4, 3, 3))
    for level in range(max_depth + 1):
        for i in range(3):
            d = np.inf
            for k in range(n):
                d = min(d, closest_point_on_triangle(piece[i], faces[k, 0], faces[k, 1],
                                                     faces[k, 2], tmp))
            d = np.sqrt(d)
            if d > best:
                best = d
                best_point[:] = piece[i]
        if level == max_depth:
            break
        m01 = 0.5 * (piece[0] + piece[1])
        m12 = 0.5 * (piece[1] + piece[2])
        m20 = 0.5 * (piece[2] + piece[0])
        children[0, 0], children[0, 1], children[0, 2] = piece[0], m01, m20
        children[1, 0], children[1, 1], children[1, 2] = m01, piece[1], m12
        children[2, 0], children[2, 1], children[2, 2] = m20, m12, piece[2]
        children[3, 0], children[3, 1], children[3, 2] = m12, m20, m01
        best_child, best_child_lower = 0, -1.0
        for k in range(4):
            lo, _ = triangle_bounds(children[k].copy(), faces, target, max_depth - level - 1)
            if lo > best_child_lower:
                best_child, best_child_lower = k, lo
        if best_child_lower <= best:
            break
        piece = children[best_child].copy()
    return best, best_point
