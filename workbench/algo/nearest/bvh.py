"""An axis-aligned bounding-box hierarchy over triangles, with exact float64 nearest-point queries.

:class:`TriangleBVH` is built with numpy: the triangles' references (one box per triangle, or
per piece of a long triangle) are split top down at the median of their box centres along the
longest axis of the centres' box, level by level, until a node holds at most ``leaf_size``
references. The tree is kept in flat arrays (node boxes, the first child of each inner node,
each leaf's range of references, the triangle of each reference) and queried by numba:

* :meth:`TriangleBVH.nearest` -- for every point, the nearest triangle, the closest point on it
  and the distance, exact in float64 through
  :func:`~workbench.algo.nearest.triangle.closest_point_on_triangle`. Branch and bound: the nearer
  child
  is visited first and a box farther than the best triangle so far is pruned. A hint (a triangle
  thought to be near) or a distance cap starts the search with a small bound and prunes more.
* :meth:`TriangleBVH.triangles_within` -- every triangle within a distance of a point (the
  candidate faces for a certified bound on a piece of surface, :mod:`workbench.algo.hausdorff`).

Distances are in the units of the vertices. Coordinates far from the origin keep their digits
best when translated near it first (:func:`workbench.algo.hausdorff.hausdorff` does).

Why a second hierarchy beside :class:`~workbench.algo.nearest.hierarchy.ElementHierarchy`: this tree
serves the certified Hausdorff metric, whose inputs are bare triangle meshes (decimated ones
with long slivers, no elements or parts), and holds what that hierarchy cannot: split references
of long triangles, so that a sliver's box does not contain most queries; a hint per query (a
neighbour's nearest triangle) that prunes from the first box; every triangle within a radius,
the candidate lists of the certified bounds; and kernels (:func:`nearest_one`, :func:`within`)
that those bounds call inside their own numba loops. It has no parts to exclude, no oriented
boxes, no slab test and no test counters: those are crash2000 §4's, in the element hierarchy.
Measured by ``benchmarks/bvh_compare.py`` (7 interleaved rounds, run twice, 2 cores) on the car
deck refined 4 x 4 (139 712 triangles, 70 002 nearest-point queries per set, no part excluded):
the AABB element hierarchy builds in 0.36-0.37x the BVH's time and answers queries within a 1.5
mm cut-off in 0.94-0.99x its time (medians; single rounds 0.49-1.60x), unbounded ones in
1.07-1.28x; the OBB hierarchy in 1.2-1.5x. Neither is faster at what both do, so each stays for
what only it does.
"""

from __future__ import annotations

import numba
import numpy as np

from .state import Tree, new_search
from .triangle import closest_point_on_triangle

__all__ = ["TriangleBVH", "bounding_box", "check_triangles", "compacted", "corner_boxes",
           "used_vertices"]

_CHUNK = 256  # points per parallel work item
PARALLEL_MIN = 1024  # fewer queries than this run on one thread


def bounding_box(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(lo, hi) (3,) of ``points`` (N, 3), N >= 1: ``points.min(axis=0)``, ``.max(axis=0)``,
    one column at a time (numpy reduces a C-ordered (N, 3) array along its first axis about
    twenty times slower)."""
    lo = np.array([points[:, k].min() for k in range(3)])
    hi = np.array([points[:, k].max() for k in range(3)])
    return lo, hi


def corner_boxes(corners: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(lo, hi) (K, 3) of the triangles ``corners`` (K, 3, 3): their boxes, elementwise
    (``corners.min(axis=1)`` reduces slowly over an axis of three)."""
    a, b, c = corners[:, 0], corners[:, 1], corners[:, 2]
    return np.minimum(np.minimum(a, b), c), np.maximum(np.maximum(a, b), c)


def used_vertices(triangles: np.ndarray, n_vertices: int) -> np.ndarray:
    """Sorted indices of the vertices that ``triangles`` (K, 3) use, of ``n_vertices``: the
    same as ``np.unique(triangles)``, by a mask (linear time, no sort)."""
    mask = np.zeros(n_vertices, np.bool_)
    mask[triangles.ravel()] = True
    return np.flatnonzero(mask)


def compacted(triangles: np.ndarray, n_vertices: int) -> tuple[np.ndarray, np.ndarray]:
    """``(used, renumbered)``: the vertices ``triangles`` (K, 3) use (sorted, as
    :func:`used_vertices`) and the triangles renumbered into them (int64), as
    ``np.unique(triangles, return_inverse=True)`` gives them, in linear time."""
    mask = np.zeros(n_vertices, np.bool_)
    mask[triangles.ravel()] = True
    new_index = np.cumsum(mask, dtype=np.int64) - 1
    return np.flatnonzero(mask), new_index[triangles]


def check_triangles(vertices, triangles, what: str = "mesh") -> tuple[np.ndarray, np.ndarray]:
    """``vertices`` as (N, 3) float64 and ``triangles`` as (K, 3) int64, checked.

    Refused with ValueError naming ``what``: shapes other than (N, 3) / (K, 3), no triangles,
    non-integer indices, indices outside ``vertices``, non-finite coordinates of a vertex that a
    triangle uses (unreferenced vertices are not looked at).
    """
    v = np.asarray(vertices)
    t = np.asarray(triangles)
    if v.ndim != 2 or v.shape[1] != 3:
        raise ValueError(f"{what}: vertices must be (N, 3), got shape {v.shape}")
    if t.ndim != 2 or t.shape[1] != 3:
        raise ValueError(f"{what}: triangles must be (K, 3), got shape {t.shape}")
    if len(t) == 0:
        raise ValueError(f"{what}: no triangles")
    if not np.issubdtype(t.dtype, np.integer):
        raise ValueError(f"{what}: triangle indices must be integers, got {t.dtype}")
    if not np.issubdtype(v.dtype, np.number) or np.issubdtype(v.dtype, np.complexfloating):
        raise ValueError(f"{what}: vertices must be real numbers, got {v.dtype}")
    t = t.astype(np.int64, copy=False)
    if t.min() < 0 or t.max() >= len(v):  # the per-triangle search only where it finds some
        bad = np.flatnonzero(((t < 0) | (t >= len(v))).any(axis=1))
        raise ValueError(f"{what}: {len(bad)} triangles index missing vertices (there are "
                         f"{len(v)}), first {[t[i].tolist() for i in bad[:3]]}")
    v = np.ascontiguousarray(v, dtype=np.float64)
    used = used_vertices(t, len(v))
    if not np.isfinite(v[used]).all():
        finite = np.isfinite(v[used]).all(axis=1)
        raise ValueError(f"{what}: non-finite coordinates at vertices {used[~finite][:5].tolist()}")
    return v, t


def _references(corners: np.ndarray, split_factor: float, max_splits: int):
    """Boxes (lo, hi) and triangle indices of the references: one per triangle, or the pieces
    of repeated longest-edge bisection for triangles whose box diagonal exceeds
    ``split_factor`` times the median. A piece's box is widened by a few units in the last
    place so that the rounded midpoints never leave part of the triangle outside every box."""
    box_lo, box_hi = corner_boxes(corners)
    extent = np.linalg.norm(box_hi - box_lo, axis=1)
    limit = split_factor * float(np.median(extent))
    pieces, owner = corners, np.arange(len(corners))
    out_lo, out_hi, out_tri = [], [], []
    for level in range(max_splits + 1):
        lo, hi = corner_boxes(pieces)
        big = np.linalg.norm(hi - lo, axis=1) > limit if level < max_splits else \
            np.zeros(len(pieces), bool)
        keep = ~big
        pad = 1e-14 * (np.abs(lo[keep]) + np.abs(hi[keep])) if level else 0.0
        out_lo.append(lo[keep] - pad)
        out_hi.append(hi[keep] + pad)
        out_tri.append(owner[keep])
        if not big.any():
            break
        p, o = pieces[big], owner[big]
        edge = np.stack([((p[:, 1] - p[:, 0]) ** 2).sum(1), ((p[:, 2] - p[:, 1]) ** 2).sum(1),
                         ((p[:, 0] - p[:, 2]) ** 2).sum(1)], axis=1)
        k = np.argmax(edge, axis=1)
        q = p[np.arange(len(p))[:, None], (k[:, None] + np.arange(3)) % 3]  # longest edge 0-1
        mid = 0.5 * (q[:, 0] + q[:, 1])
        pieces = np.concatenate([np.stack([q[:, 0], mid, q[:, 2]], axis=1),
                                 np.stack([mid, q[:, 1], q[:, 2]], axis=1)])
        owner = np.concatenate([o, o])
    return np.concatenate(out_lo), np.concatenate(out_hi), np.concatenate(out_tri)


class TriangleBVH:
    """AABB tree over the triangles ``vertices[triangles]`` ((N, 3) float, (K, 3) int).

    Long triangles (slivers spanning a part, as quadric decimation leaves on flat panels) would
    give boxes that contain most queries; a triangle whose box diagonal exceeds ``split_factor``
    times the median is therefore entered as several references, the boxes of its pieces by
    repeated longest-edge bisection (at most ``2**max_splits`` references). Queries test the
    whole triangle, so results do not depend on the split.

    Degenerate triangles (repeated or collinear corners) are allowed and measured as their
    edges. Refused (ValueError): bad shapes, no triangles, indices outside ``vertices``,
    non-finite coordinates of used vertices, ``leaf_size`` < 1, ``split_factor`` <= 0 or NaN,
    ``max_splits`` outside [0, 16].

    Attributes: ``corners`` (K, 3, 3) float64 triangle corners, ``ref_tri`` (R,) the triangle
    of each reference in tree order, ``box_lo``/``box_hi`` (nodes, 3) node boxes, ``child``
    (nodes,) the first child of an inner node (the second is ``child + 1``; -1 for a leaf),
    ``first``/``count`` each leaf's range of references, ``depth`` the number of levels.
    """

    def __init__(self, vertices, triangles, leaf_size: int = 4, split_factor: float = 4.0,
                 max_splits: int = 6):
        if int(leaf_size) != leaf_size or leaf_size < 1:
            raise ValueError(f"leaf_size must be a positive integer, got {leaf_size!r}")
        if not split_factor > 0:
            raise ValueError(f"split_factor must be > 0, got {split_factor!r}")
        if int(max_splits) != max_splits or not 0 <= max_splits <= 16:
            raise ValueError(f"max_splits must be an integer in [0, 16], got {max_splits!r}")
        leaf_size = int(leaf_size)
        v, t = check_triangles(vertices, triangles)
        self.corners = np.ascontiguousarray(v[t])  # (K, 3, 3)
        ref_lo, ref_hi, ref_tri = _references(self.corners, split_factor, int(max_splits))
        centres = 0.5 * (ref_lo + ref_hi)
        order = np.arange(len(ref_tri))
        # level by level: node ranges [start, start + size) of `order`
        starts, sizes = np.zeros(1, np.int64), np.full(1, len(order), np.int64)
        level_starts, level_sizes, level_child = [], [], []
        n_nodes = 1
        while True:
            split = sizes > leaf_size
            child = np.full(len(sizes), -1, np.int64)
            if split.any():
                ss, cs = starts[split], sizes[split]
                offsets = np.concatenate([[0], np.cumsum(cs)[:-1]])
                seg = np.repeat(np.arange(len(cs)), cs)
                pos = ss[seg] + np.arange(len(seg)) - offsets[seg]
                c = centres[order[pos]]
                extent = np.maximum.reduceat(c, offsets) - np.minimum.reduceat(c, offsets)
                axis = np.argmax(extent, axis=1)
                key = c[np.arange(len(seg)), axis[seg]]
                order[pos] = order[pos][np.lexsort((key, seg))]
                child[split] = n_nodes + 2 * np.arange(len(cs))
                n_nodes += 2 * len(cs)
            level_starts.append(starts)
            level_sizes.append(sizes)
            level_child.append(child)
            if not split.any():
                break
            left = cs // 2
            starts = np.stack([ss, ss + left], axis=1).ravel()
            sizes = np.stack([left, cs - left], axis=1).ravel()

        self.leaf_size = leaf_size
        self.depth = len(level_starts)
        self.ref_tri = np.ascontiguousarray(ref_tri[order])
        self.child = np.concatenate(level_child)
        all_starts = np.concatenate(level_starts)
        all_sizes = np.concatenate(level_sizes)
        leaf = self.child < 0
        self.first = np.where(leaf, all_starts, 0)
        self.count = np.where(leaf, all_sizes, 0)
        # boxes: leaves from their references (leaves partition them), inner nodes from their
        # children, deepest level first
        self.box_lo = np.empty((n_nodes, 3))
        self.box_hi = np.empty((n_nodes, 3))
        leaves = np.flatnonzero(leaf)
        leaves = leaves[np.argsort(all_starts[leaves])]
        self.box_lo[leaves] = np.minimum.reduceat(ref_lo[order], all_starts[leaves])
        self.box_hi[leaves] = np.maximum.reduceat(ref_hi[order], all_starts[leaves])
        level_first = np.concatenate([[0], np.cumsum([len(s) for s in level_starts])])
        for d in range(self.depth - 1, -1, -1):
            nodes = np.arange(level_first[d], level_first[d + 1])
            nodes = nodes[self.child[nodes] >= 0]
            c = self.child[nodes]
            self.box_lo[nodes] = np.minimum(self.box_lo[c], self.box_lo[c + 1])
            self.box_hi[nodes] = np.maximum(self.box_hi[c], self.box_hi[c + 1])

    # ----------------------------------------------------------------- sizes
    @property
    def n_triangles(self) -> int:
        return len(self.corners)

    @property
    def n_references(self) -> int:
        return len(self.ref_tri)

    @property
    def n_nodes(self) -> int:
        return len(self.child)

    def arrays(self) -> Tree:
        """The flat tree for numba code, a :class:`~workbench.algo.nearest.state.Tree`
        (box_lo, box_hi, child, first, count, ref_tri, corners, depth)."""
        return Tree(self.box_lo, self.box_hi, self.child, self.first, self.count, self.ref_tri,
                    self.corners, int(self.depth))

    # ----------------------------------------------------------------- queries
    def nearest(self, points, hint=None, max_distance: float = np.inf):
        """Nearest triangle of every point: ``(distance, triangle, closest)``.

        ``points`` (P, 3) float; returns (P,) float64 distances, (P,) int64 original triangle
        indices and (P, 3) float64 closest points, exact in float64. ``hint`` (P,) optional
        triangle indices (-1 for none) to start each search from: a near triangle makes the
        search prune from the start, any triangle gives the same result (without hints, each
        search starts from the previous point's triangle). Points at ``max_distance`` or farther
        from every triangle get distance inf, triangle -1 and NaN closest points. Refused: bad
        shapes, non-finite points, a hint outside the triangles, a negative or NaN ``max_distance``.
        """
        p = np.asarray(points, dtype=np.float64)
        if p.ndim != 2 or p.shape[1] != 3:
            raise ValueError(f"points must be (P, 3), got shape {p.shape}")
        if not np.isfinite(p).all():
            raise ValueError("points: non-finite coordinates")
        if not max_distance >= 0:
            raise ValueError(f"max_distance must be >= 0, got {max_distance!r}")
        if hint is None:
            hint = np.full(len(p), -1, np.int64)
        else:
            h = np.asarray(hint)
            if h.shape != (len(p),) or not np.issubdtype(h.dtype, np.integer):
                raise ValueError(f"hint must be ({len(p)},) integers, got {h.shape} {h.dtype}")
            if ((h < -1) | (h >= self.n_triangles)).any():
                raise ValueError(f"hint: triangle indices must be -1 or in [0, {self.n_triangles})")
            hint = h.astype(np.int64)
        d2 = np.empty(len(p))
        tri = np.empty(len(p), np.int64)
        closest = np.empty((len(p), 3))
        cap = float(max_distance) ** 2 if np.isfinite(max_distance) else np.inf
        _nearest_many(np.ascontiguousarray(p), hint, cap, self.arrays(), d2, tri, closest)
        found = tri >= 0
        dist = np.where(found, np.sqrt(d2), np.inf)
        closest[~found] = np.nan
        return dist, tri, closest

    def triangles_within(self, point, radius: float) -> np.ndarray:
        """Sorted original indices of the triangles at distance <= ``radius`` from ``point`` (3,).

        Exact float64 distances; refused: a non-finite point or radius, a negative radius.
        """
        p = np.asarray(point, dtype=np.float64).reshape(-1)
        if p.shape != (3,) or not np.isfinite(p).all():
            raise ValueError(f"point must be 3 finite coordinates, got {point!r}")
        if not (np.isfinite(radius) and radius >= 0):
            raise ValueError(f"radius must be finite and >= 0, got {radius!r}")
        out = np.empty(self.n_references, np.int64)
        n = within(p, float(radius) ** 2, self.arrays(), out)
        return out[:n].copy()


# --------------------------------------------------------------------------- numba kernels
@numba.njit(cache=True, inline="always")
def _box_distance_sq(p, lo, hi):
    d = 0.0
    for k in range(3):
        if p[k] < lo[k]:
            e = lo[k] - p[k]
            d += e * e
        elif p[k] > hi[k]:
            e = p[k] - hi[k]
            d += e * e
    return d


@numba.njit(cache=True)
def nearest_one(p, start, bound_sq, tree, search):
    """Squared distance and index of the triangle of ``tree`` (a
    :class:`~workbench.algo.nearest.state.Tree`) nearest to p, closest point into
    ``search.best_point``.

    Triangle ``start`` (>= 0) is tried first; only triangles strictly nearer than ``bound_sq``
    are returned (index -1 when none is). ``search`` (a
    :class:`~workbench.algo.nearest.state.Search`) holds the scratch: ``stack``/``stack_d`` of
    ``depth + 2`` entries, ``tmp`` (3,).
    """
    box_lo = tree.box_lo
    box_hi = tree.box_hi
    child = tree.child
    first = tree.first
    count = tree.count
    ref_tri = tree.ref_tri
    corners = tree.corners
    stack = search.stack
    stack_d = search.stack_d
    tmp = search.tmp
    best_point = search.best_point
    best = bound_sq
    best_tri = -1
    if start >= 0:
        t = corners[start]
        d = closest_point_on_triangle(p, t[0], t[1], t[2], tmp)
        if d < best:
            best, best_tri = d, start
            best_point[:] = tmp
    top = 0
    d = _box_distance_sq(p, box_lo[0], box_hi[0])
    if d < best:
        stack[0], stack_d[0] = 0, d
        top = 1
    while top > 0:
        top -= 1
        node = stack[top]
        if stack_d[top] >= best:
            continue
        c = child[node]
        if c < 0:
            previous = start
            for r in range(first[node], first[node] + count[node]):
                k = ref_tri[r]
                if k == previous:  # pieces of one triangle often share a leaf
                    continue
                previous = k
                t = corners[k]
                d = closest_point_on_triangle(p, t[0], t[1], t[2], tmp)
                if d < best:
                    best, best_tri = d, k
                    best_point[:] = tmp
            continue
        d0 = _box_distance_sq(p, box_lo[c], box_hi[c])
        d1 = _box_distance_sq(p, box_lo[c + 1], box_hi[c + 1])
        # push the farther child first so that the nearer one is searched first
        if d0 <= d1:
            near, far, dn, df = c, c + 1, d0, d1
        else:
            near, far, dn, df = c + 1, c, d1, d0
        if df < best:
            stack[top], stack_d[top] = far, df
            top += 1
        if dn < best:
            stack[top], stack_d[top] = near, dn
            top += 1
    return best, best_tri


@numba.njit(cache=True)
def _nearest_range(begin, end, points, hint, bound_sq, tree, out_d2, out_tri, out_point):
    search = new_search(tree.depth)
    best_point = search.best_point
    previous = -1
    for i in range(begin, end):
        # without a hint, start from the previous point's triangle: neighbouring queries are
        # usually near each other, and a near start prunes from the first box on
        start = hint[i] if hint[i] >= 0 else previous
        d, k = nearest_one(points[i], start, bound_sq, tree, search)
        out_d2[i] = d
        out_tri[i] = k
        out_point[i] = best_point
        if k >= 0:
            previous = k


@numba.njit(cache=True, parallel=True)
def _nearest_parallel(points, hint, bound_sq, tree, out_d2, out_tri, out_point):
    n = len(points)
    for chunk in numba.prange((n + _CHUNK - 1) // _CHUNK):
        _nearest_range(chunk * _CHUNK, min(n, (chunk + 1) * _CHUNK), points, hint, bound_sq,
                       tree, out_d2, out_tri, out_point)


def _nearest_many(points, *args):
    # starting the thread pool costs about as much as a few hundred queries
    if len(points) >= PARALLEL_MIN:
        _nearest_parallel(points, *args)
    else:
        _nearest_range(0, len(points), points, *args)


@numba.njit(cache=True)
def within(p, radius_sq, tree, out, limit=-1):
    """Sorted indices of the triangles of ``tree`` (a :class:`~workbench.algo.nearest.state.Tree`)
    at squared distance <= ``radius_sq`` from p, written to ``out`` (room for every reference);
    returns how many, or -1 as soon as more than ``limit`` (when >= 0) references are found."""
    box_lo = tree.box_lo
    box_hi = tree.box_hi
    child = tree.child
    first = tree.first
    count = tree.count
    ref_tri = tree.ref_tri
    corners = tree.corners
    stack = np.empty(tree.depth + 2, np.int64)
    tmp = np.empty(3)
    n = 0
    top = 0
    if _box_distance_sq(p, box_lo[0], box_hi[0]) <= radius_sq:
        stack[0] = 0
        top = 1
    while top > 0:
        top -= 1
        node = stack[top]
        c = child[node]
        if c < 0:
            previous = -1
            for r in range(first[node], first[node] + count[node]):
                k = ref_tri[r]
                if k == previous:
                    continue
                previous = k
                t = corners[k]
                if closest_point_on_triangle(p, t[0], t[1], t[2], tmp) <= radius_sq:
                    if n == limit:
                        return -1
                    out[n] = k
                    n += 1
            continue
        for j in range(2):
            if _box_distance_sq(p, box_lo[c + j], box_hi[c + j]) <= radius_sq:
                stack[top] = c + j
                top += 1
    if n > 1:  # a triangle entered as several references may have been found more than once
        out[:n] = np.sort(out[:n])
        m = 1
        for i in range(1, n):
            if out[i] != out[m - 1]:
                out[m] = out[i]
                m += 1
        n = m
    return n
