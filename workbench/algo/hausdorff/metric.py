"""The public entry of the certified Hausdorff distance: :func:`hausdorff`, its result
:class:`HausdorffResult` and the one-sided driver (see :mod:`workbench.algo.hausdorff` for the
method).

:func:`_one_sided` measures A's samples through B's tree, takes the first upper bound per
triangle (:func:`~.refine._sample_upper`) and refines the triangles that may hold a larger
distance (:mod:`.refine`); :class:`_Surface` holds a mesh translated near the origin with its
tree and face neighbours built on demand. Distances are in model units.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numba
import numpy as np

from ..nearest.bvh import TriangleBVH, bounding_box, check_triangles, compacted, used_vertices
from ..nearest.triangle import construction_rounding, distance_rounding, outward
from .cascade import cascade
from .refine import _locate_in, _refine, _refine_planes, _sample_upper, _tighten

__all__ = ["HausdorffResult", "hausdorff"]

DEFAULT_REL_TOL = 1e-4  # of A's bounding-box diagonal
DEFAULT_MAX_DEPTH = 16
MAX_DEPTH_LIMIT = 30
SPLITS = ("planes", "midpoint")
# a piece's bound within this share of the coordinates of its largest vertex distance is final
_ROUNDING = 1e-13
# degree-3 quadrature on a triangle: weights of each corner, each edge midpoint, the centroid
_W_CORNER, _W_EDGE, _W_CENTROID = 1.0 / 20.0, 2.0 / 15.0, 9.0 / 20.0


@dataclass(frozen=True, eq=False)
class HausdorffResult:
    """The Hausdorff distance from surface A to surface B as a certified bracket (model units).

    ``lower <= H <= upper``, each rounded outward by the bound of its own rounding error;
    ``max`` is the best estimate, the largest distance computed at a point of A
    (``location[0]``), of which ``lower`` is the rounded-down value. ``mean`` and ``rms`` are
    area-weighted **sample estimates** of the distance over A (a degree-3 rule on each
    triangle: corners, edge midpoints, centroid), not bounds. ``location`` (2, 3): the point
    of A where ``max`` is attained and the point of B nearest to it, in the input coordinates.
    ``samples``: points whose exact distance was queried through the tree (vertices, edge
    midpoints, centroids, and the cascade's points without ``estimates``; the corners visited
    by the subdivision are not counted).
    ``refined``: triangles of A bounded against every face near them (the last refinement
    step). ``area``: A's area. ``tol_reached``: ``upper - lower <= tol``.

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
              max_depth: int = DEFAULT_MAX_DEPTH, split: str = "planes",
              estimates: bool = True) -> HausdorffResult:
    """Certified Hausdorff distance from mesh A (``va`` (N, 3) float, ``fa`` (K, 3) int) to
    mesh B (``vb``, ``fb``), or the symmetric distance (the larger of both directions) when
    ``one_sided`` is False.

    ``tol`` (model units, default 1e-4 of A's bounding-box diagonal) is the bracket width to
    reach. ``split`` picks the refinement ("planes" or "midpoint", see the module notes);
    ``max_depth`` limits it: levels of 4-way subdivision, or three plane cuts per level
    (``tol_reached`` in the result says whether the width was reached). ``estimates`` (default
    True) also gives the sample estimates ``mean`` and ``rms``, which measure every vertex,
    edge midpoint and centroid of A; with False only the bracket is computed, through a cascade
    of cheap bounds that leaves most of A unmeasured (:mod:`.cascade`; much faster where A is
    fine), and ``mean``/``rms`` are NaN. Unreferenced vertices
    are ignored, also when their coordinates are not finite; degenerate triangles are allowed
    (measured as their edges). Refused with ValueError naming the input: bad shapes, no
    triangles, non-integer or out-of-range indices, non-finite coordinates of used vertices;
    and a negative or non-finite ``tol``, a ``max_depth`` outside [0, 30], an unknown
    ``split``; a ``one_sided`` or ``estimates`` that is not a bool with TypeError.
    """
    start = time.perf_counter()
    va, fa = check_triangles(va, fa, "A (va, fa)")
    vb, fb = check_triangles(vb, fb, "B (vb, fb)")
    if not isinstance(one_sided, (bool, np.bool_)):
        raise TypeError(f"one_sided must be True or False, got {one_sided!r}")
    if not isinstance(estimates, (bool, np.bool_)):
        raise TypeError(f"estimates must be True or False, got {estimates!r}")
    if int(max_depth) != max_depth or not 0 <= max_depth <= MAX_DEPTH_LIMIT:
        raise ValueError(f"max_depth must be an integer in [0, {MAX_DEPTH_LIMIT}], "
                         f"got {max_depth!r}")
    max_depth = int(max_depth)
    if split not in SPLITS:
        raise ValueError(f"split must be one of {SPLITS}, got {split!r}")
    used_a = used_vertices(fa, len(va))
    lo, hi = bounding_box(va[used_a])
    origin = 0.5 * (lo + hi)
    if tol is None:
        tol = DEFAULT_REL_TOL * float(np.linalg.norm(hi - lo))
    elif not (np.isfinite(tol) and tol >= 0):
        raise ValueError(f"tol must be finite and >= 0 (model units), got {tol!r}")
    tol = float(tol)

    a = _Surface(va - origin, fa)
    b = _Surface(vb - origin, fb)
    forward = _one_sided(a, b, tol, max_depth, split, origin, start, bool(estimates))
    if one_sided:
        return forward
    backward = _one_sided(b, a, tol, max_depth, split, origin, time.perf_counter(),
                          bool(estimates))
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
        max=max(forward.max, backward.max), lower=lower, upper=upper, mean=float(mean),
        rms=float(rms),
        location=top.location, samples=forward.samples + backward.samples,
        seconds=time.perf_counter() - start, tol=tol,
        tol_reached=forward.tol_reached and backward.tol_reached,
        refined=forward.refined + backward.refined, area=area,
        forward=forward, backward=backward)


class _Surface:
    """A mesh near the origin with its used vertices compacted, and its tree built on demand."""

    def __init__(self, vertices: np.ndarray, triangles: np.ndarray):
        used, self.triangles = compacted(triangles, len(vertices))
        self.vertices = np.ascontiguousarray(vertices[used])
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
            self._bvh = TriangleBVH(self.vertices, self.triangles, leaf_size=1)
        return self._bvh


def _one_sided(a: _Surface, b: _Surface, tol: float, max_depth: int, split: str,
               origin: np.ndarray, start: float, estimates: bool) -> HausdorffResult:
    bvh = b.bvh
    all_corners = _corners(a.vertices, a.triangles)  # (K, 3, 3)
    lower, point_a, point_b = -1.0, None, None
    pruned_upper, queries = -1.0, 0
    if estimates:
        v, f = a.vertices, a.triangles
    else:
        # bracket only: bound every triangle cheaply, refine those that may hold the maximum
        first = cascade(a.vertices, a.triangles, all_corners, bvh, b.neighbours, tol)
        lower, point_a, point_b, queries = first.lower, first.point_a, first.point_b, \
            first.queries
        keep = first.upper > lower + tol
        if (~keep).any():
            pruned_upper = float(first.upper[~keep].max())
        used, f = compacted(a.triangles[keep], len(a.vertices))
        v = np.ascontiguousarray(a.vertices[used])
    corners = np.ascontiguousarray(v[f])
    upper = np.full(len(f), -1.0)
    refined = 0
    if len(f):
        (lower, point_a, point_b, samples, refined,
         (dv, dm, dc, tri_edge)) = _bound_triangles(v, f, corners, b, upper, lower, point_a,
                                                    point_b, tol, max_depth, split)
        queries += samples

    # round the bracket outward by the bound of its own rounding (the error model of
    # workbench.algo.nearest.triangle): distances to B's faces, and the points they were measured
    # at,
    # built by up to `levels` interpolations (samples, cuts or midpoints, the translation)
    estimate = lower
    top = max(float(upper.max(initial=-1.0)), pruned_upper, lower)
    lower, global_upper = outward(lower, top, bracket_rounding(a.vertices, bvh.corners, top,
                                                               split, max_depth))
    area2 = _doubled_areas(all_corners)
    area = 0.5 * float(area2.sum())
    if estimates:
        weights = area2 if area > 0 else np.ones(len(f))
        mean = float(_quadrature(dv[f], dm[tri_edge], dc, weights, 1))
        rms = float(np.sqrt(_quadrature(dv[f], dm[tri_edge], dc, weights, 2)))
    else:
        mean = rms = float("nan")
    return HausdorffResult(
        max=estimate, lower=lower, upper=global_upper, mean=mean, rms=rms,
        location=np.stack([point_a + origin, point_b + origin]),
        samples=queries, seconds=time.perf_counter() - start, tol=tol,
        tol_reached=global_upper - lower <= tol, refined=int(refined), area=area)


def _bound_triangles(v, f, corners, b, upper, lower, point_a, point_b, tol, max_depth, split):
    """Exact samples of the triangles ``f`` of A (vertices ``v``, corners ``corners``), their
    first upper bounds and the refinement (steps 2–4 of the method), starting from a lower
    bound ``lower`` attained at ``point_a`` (-1 and None for none). Writes each triangle's upper
    bound into ``upper``; returns (lower, point_a, point_b, samples queried, triangles refined,
    (vertex, edge-midpoint and centroid distances, each triangle's edges))."""
    bvh = b.bvh
    nv = len(v)
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

    for d, pts, near in ((dv, v, pv), (dm, midpoints, pm), (dc, centroids, pc)):
        i = int(np.argmax(d))
        if d[i] > lower:
            lower, point_a, point_b = float(d[i]), pts[i], near[i]

    # first upper bound per triangle from its samples' nearest faces
    candidates = np.concatenate([fv[f], fm[tri_edge], fc[:, None]], axis=1)
    candidates = np.sort(candidates, axis=1)
    _sample_upper(corners, candidates, bvh.corners, upper)

    # refine the triangles that can hold a larger distance, largest first
    refined = 0
    if split == "planes":
        eps = _rounding_eps(v, bvh.corners)
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
            corners, order, upper, lower, tol, max_depth, bvh.arrays())
        if best_t >= 0:
            # the subdivision raised the lower bound: find the point where it is attained
            found, point = _locate_in(corners[best_t], best_radius, best_target, max_depth,
                                      bvh.arrays())
            if found >= lower:
                _, _, near = bvh.nearest(point[None])
                point_a, point_b = point, near[0]
            lower = max(found, new_lower)
    samples = len(v) + len(edges) + len(f)
    return lower, point_a, point_b, samples, refined, (dv, dm, dc, tri_edge)


def _rounding_eps(vertices, faces) -> float:
    """How close (model units) a piece's bound may come to its largest vertex distance to be
    final in the plane cuts: ``_ROUNDING`` of the largest coordinate."""
    return _ROUNDING * max(np.abs(vertices).max(), np.abs(faces).max())


def bracket_rounding(vertices, faces, distance, split, max_depth) -> float:
    """The margin (model units) by which a computed bracket of distances up to ``distance``
    from points built on A (``vertices`` (N, 3), translated) to the faces ``faces`` (F, 3, 3)
    of B is widened: the rounding of a distance to a face of B's longest edge, plus how far the
    measured points may lie from A (``3 · max_depth`` plane cuts or ``max_depth`` midpoint
    levels after a sample's own construction, and the translation of A and of B). Coordinates
    are bounded by the diagonal of the box around both (the origin lies in it), so the margin
    does not depend on the origin or on which surface came first."""
    edges = faces[:, [1, 2, 0]] - faces
    longest = float(np.sqrt((edges ** 2).sum(axis=2).max())) if len(faces) else 0.0
    corners = faces.reshape(-1, 3)
    (lo_a, hi_a), (lo_b, hi_b) = bounding_box(vertices), bounding_box(corners)
    lo, hi = np.minimum(lo_a, lo_b), np.maximum(hi_a, hi_b)
    magnitude = float(np.linalg.norm(hi - lo))
    levels = (3 * max_depth if split == "planes" else max_depth) + 3
    return distance_rounding(distance, longest) + construction_rounding(magnitude, levels)


@numba.njit(cache=True)
def _corners(vertices: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """(K, 3, 3) ``vertices[triangles]``, gathered in one compiled pass (numpy's fancy index
    of rows takes several times as long)."""
    out = np.empty((len(triangles), 3, 3))
    for t in range(len(triangles)):
        for i in range(3):
            v = triangles[t, i]
            out[t, i, 0], out[t, i, 1], out[t, i, 2] = (vertices[v, 0], vertices[v, 1],
                                                        vertices[v, 2])
    return out


@numba.njit(cache=True)
def _doubled_areas(corners: np.ndarray) -> np.ndarray:
    """(K,) twice the area of each triangle of ``corners`` (K, 3, 3): |(b − a) × (c − a)|."""
    out = np.empty(len(corners))
    for t in range(len(corners)):
        a0, a1, a2 = corners[t, 0, 0], corners[t, 0, 1], corners[t, 0, 2]
        e0, e1, e2 = corners[t, 1, 0] - a0, corners[t, 1, 1] - a1, corners[t, 1, 2] - a2
        f0, f1, f2 = corners[t, 2, 0] - a0, corners[t, 2, 1] - a1, corners[t, 2, 2] - a2
        x, y, z = e1 * f2 - e2 * f1, e2 * f0 - e0 * f2, e0 * f1 - e1 * f0
        out[t] = np.sqrt(x * x + y * y + z * z)
    return out


def _quadrature(d_corner, d_edge, d_centroid, weights, power):
    per_triangle = (_W_CORNER * (d_corner ** power).sum(axis=1)
                    + _W_EDGE * (d_edge ** power).sum(axis=1) + _W_CENTROID * d_centroid ** power)
    return (weights * per_triangle).sum() / weights.sum()


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
