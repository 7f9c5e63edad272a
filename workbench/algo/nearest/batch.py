"""Exact float64 nearest triangles for many points at once, each point ignoring some parts: a
4-wide AABB tree searched by groups of nearby points.

The part-distance query (crash2000 §4.1, :func:`workbench.algo.nearest.parts.part_distances`)
asks, for every node of a model, for the nearest triangle of *another* part within a cut-off.
Most nodes have none that near, and neighbouring nodes exclude the same parts and meet the same
triangles, so :class:`BatchedTriangleTree` answers them together:

* **Tree.** The binary median-split tree of :class:`~workbench.algo.nearest.bvh.TriangleBVH` (long
  triangles entered as several references), collapsed to four children per node (a node's
  children are its binary grandchildren). A node keeps its four children's boxes side by side
  (lo x, y, z, hi x, y, z, four slots each: 192 contiguous bytes), their indices (a leaf as
  ``-(leaf + 1)``) and the part of each child's subtree when all its triangles have one part
  (-1 otherwise), so that a subtree of an excluded part is skipped without looking at its
  box. Each reference keeps its triangle's corners, box and part in tree order, so that a leaf
  is read in one sweep.
* **Groups.** Each point gets the key ``set << 30 | Morton code`` (1024 cells a side over the
  tree's box). One counting sort buckets the points by set and coarse cell (the key's top
  bits); each bucket is then sorted along the curve on its own. Within a bucket, a group is
  the largest octree cell of the curve holding at most ``group`` points, so a group's points
  are close together and exclude the same parts.
* **Search.** A group's bounding box walks the tree once, skipping excluded subtrees and
  children whose box is farther from the group's box than the cut-off; the leaves it reaches
  are the group's candidates (none, for most groups: their points are then done). Every point
  then tests the candidates' boxes, the boxes of their triangles and the exact distance of
  those still nearer than its best so far. Buckets run in parallel over the numba threads,
  handed out one by one (their costs differ); the bucketing before is serial: on a busy
  machine one more parallel region costs more than it saves.

Exact: a point's result is the smallest squared distance
:func:`~workbench.algo.nearest.triangle.closest_point_on_triangle` computes, over the triangles not
of
its excluded parts, strictly below the bound -- the same float64 value, to the last bit, that
every point against every triangle gives. Pruning never drops a triangle that could win: boxes
are widened by 2**-40 of the largest corner coordinate (far more than the rounding of a computed
closest point) and a box is pruned only when its squared distance exceeds the best so far by a
relative 1e-12 as well. The group box holds its points, so its distance to a box is at most
theirs (float64 subtraction is monotone).

Measured on the car deck refined 8 x 8 (279 726 nodes, 558 848 triangles, cut-off 1.5 mm;
single-thread CPU time of the query on a shared 2-core machine, so +-10 %): the crash2000
element hierarchy takes about 60 ms, 15 of them for the nodes' own parts, 210 ns a node from
the top of one tree per part. What this module's choices did: groups in node order had boxes
of about 100 mm (1.2 M candidate leaves; 60-100 ms), Morton order about 30 ms, octree cells as
groups cut the box tests from 2.6 M to 1.1 M; numba counting references of arrays reassigned
inside the search loops had doubled the tree walk (so the candidate arrays are sized ahead, and
a group that overflows them is searched again); triangle boxes before the exact distance cut
those from 124 000 to 24 000; leaves of about 8 references and groups of 48 beat 4 and 16-32
by 5-15 %. The query now takes about 20 ms: own parts 2, bucketing 2, sorting and grouping in
the buckets 2-3, the tree walks 5-6, the points 6. Tried and dropped, no gain beyond the
noise: float32 or depth-first-ordered node boxes, branch-free box tests (numba does not
vectorize them), halving groups whose candidate lists are long, candidates ordered nearest the
group first (7 % fewer exact distances at 1.5 mm, 27 % at 50 mm, the same time). With 2
threads, ``benchmarks/distance_fcpw_bench.py`` (7 interleaved rounds, two runs on the shared
machine): 14 and 30 ms a query (medians), 0.36 and 0.59 of fcpw's time (float32, the cut-off as
its search radius), 0.19 and 0.21 of the element hierarchy's.

Lengths are in the units of the corners; translate coordinates near the origin first
(:func:`workbench.algo.nearest.hierarchy.local_origin`) so that they keep their digits.
"""

from __future__ import annotations

import numba
import numpy as np

from .bvh import TriangleBVH
from .hierarchy import squared_bound
from .state import Batch, Buckets, Found, Groups, GroupScratch, WideTree
from .triangle import closest_point_on_triangle

__all__ = ["GROUP", "LEAF_SIZE", "BatchedTriangleTree"]

GROUP = 48  # most points per group
LEAF_SIZE = 16  # most references per leaf of the binary tree (median splits leave 8 to 16)
_MORTON_BITS = 10  # cells a side: 2**_MORTON_BITS at most (_spread takes 10 bits)
_PAD = 2.0 ** -40  # boxes widened by this share of the largest corner coordinate
_SLACK = 1.0 + 1e-12  # a box is pruned when its squared distance is >= best * _SLACK
_BUCKET_BITS = 16  # the points are bucketed by set and coarse cell: at most 2**16 buckets
_RADIX = 11  # bits a pass of the sort within a bucket


class BatchedTriangleTree:
    """4-wide AABB tree over triangles with parts, for batched nearest-triangle queries.

    ``corners`` (K, 3, 3) float64 triangle corners (local coordinates, model units);
    ``triangle_part`` (K,) integer part index of each triangle (>= 0); ``leaf_size``,
    ``split_factor``, ``max_splits`` as for :class:`~workbench.algo.nearest.bvh.TriangleBVH` (the
    binary tree this one is collapsed from). Refused (ValueError): corners not (K, 3, 3) or not
    finite, no triangles, parts not (K,) integers >= 0, and what TriangleBVH refuses.

    Attributes: ``n_triangles``, ``n_nodes`` (4-wide nodes), ``n_boxes`` (child slots in use),
    ``pad`` the box widening (model units), ``depth`` the binary tree's levels.
    """

    def __init__(self, corners, triangle_part, leaf_size: int = LEAF_SIZE,
                 split_factor: float = 4.0, max_splits: int = 6):
        c = np.asarray(corners)
        if c.ndim != 3 or c.shape[1:] != (3, 3):
            raise ValueError(f"corners must be (K, 3, 3), got shape {c.shape}")
        if len(c) == 0:
            raise ValueError("corners: no triangles")
        c = np.ascontiguousarray(c, dtype=np.float64)
        if not np.isfinite(c).all():
            raise ValueError("corners: non-finite coordinates")
        part = np.asarray(triangle_part)
        if part.shape != (len(c),) or not np.issubdtype(part.dtype, np.integer):
            raise ValueError(f"triangle_part must be ({len(c)},) integers, got "
                             f"{part.shape} {part.dtype}")
        if (part < 0).any():
            raise ValueError("triangle_part: part indices must be >= 0")
        k = len(c)
        binary = TriangleBVH(c.reshape(-1, 3), np.arange(3 * k).reshape(k, 3),
                             leaf_size=leaf_size, split_factor=split_factor,
                             max_splits=max_splits)
        self.n_triangles = k
        triangle_part = np.ascontiguousarray(part, dtype=np.int64)
        self.ref_tri = binary.ref_tri
        self.leaf_first = binary.first
        self.leaf_count = binary.count
        self.depth = binary.depth
        self.pad = _PAD * float(np.abs(c).max())
        self.leaf_part = _subtree_parts(binary.child, binary.first, binary.count,
                                        binary.ref_tri, triangle_part)
        self.box, self.child, self.part = _collapse(binary.child, binary.box_lo, binary.box_hi,
                                                    self.leaf_part, self.pad)
        # the Morton grid of the queries: 2**_MORTON_BITS cells a side over the tree's box
        self.grid_lo = c.reshape(-1, 3).min(axis=0)
        self.grid_extent = float((c.reshape(-1, 3).max(axis=0) - self.grid_lo).max())
        # per reference, in tree order: corners, padded box, part (a leaf reads them in a row)
        self.ref_corners = np.ascontiguousarray(binary.corners[self.ref_tri])
        self.ref_box = np.ascontiguousarray(np.concatenate(
            [self.ref_corners.min(axis=1) - self.pad, self.ref_corners.max(axis=1) + self.pad],
            axis=1))
        self.ref_part = triangle_part[self.ref_tri]

    @property
    def n_nodes(self) -> int:
        return len(self.child)

    @property
    def n_boxes(self) -> int:
        return int(np.isfinite(self.box[:, 0, :]).sum())

    def nearest(self, points, point_set, set_ptr, set_parts, cutoff: float,
                group: int = GROUP):
        """Nearest triangle of every point among those not of its excluded parts, within
        ``cutoff``: ``(d2, triangle, counters)``.

        ``points`` (P, 3) float64 (the tree's coordinates); ``point_set`` (P,) the set of parts
        each point ignores, an index into the CSR ``(set_ptr, set_parts)`` (set s is
        ``set_parts[set_ptr[s]:set_ptr[s + 1]]``, part indices as in ``triangle_part``), -1 for
        a point not to search; ``cutoff`` finite > 0 (model units). Returns (P,) float64 exact
        squared distances (inf where no triangle is at most ``cutoff`` away, or not searched),
        (P,) int64 triangle indices (-1 there) and ``counters``: a dict of ``box_tests``
        (child boxes against a group's or a point's box), ``triangle_tests`` and ``groups``.
        Refused (ValueError): bad shapes, non-finite points that are searched, set indices
        outside the CSR, a cutoff that is not finite and > 0, ``group`` < 1.
        """
        p = np.ascontiguousarray(points, dtype=np.float64)
        if p.ndim != 2 or p.shape[1] != 3:
            raise ValueError(f"points must be (P, 3), got shape {p.shape}")
        s = np.asarray(point_set)
        if s.shape != (len(p),) or not np.issubdtype(s.dtype, np.integer):
            raise ValueError(f"point_set must be ({len(p)},) integers, got {s.shape} {s.dtype}")
        ptr = np.ascontiguousarray(set_ptr, dtype=np.int64)
        parts = np.ascontiguousarray(set_parts, dtype=np.int64)
        if ptr.ndim != 1 or len(ptr) < 1 or ptr[0] != 0 or (np.diff(ptr) < 0).any() \
                or ptr[-1] != len(parts):
            raise ValueError("set_ptr must start at 0, not decrease and end at len(set_parts)")
        try:
            cutoff = float(cutoff)
        except (TypeError, ValueError):
            raise ValueError(f"cutoff must be finite and > 0, got {cutoff!r}") from None
        if not (np.isfinite(cutoff) and cutoff > 0):
            raise ValueError(f"cutoff must be finite and > 0, got {cutoff!r}")
        if isinstance(group, bool) or int(group) != group or group < 1:
            raise ValueError(f"group must be an integer >= 1, got {group!r}")
        s = np.ascontiguousarray(s, dtype=np.int64)
        n_sets = len(ptr) - 1
        vals, starts, index_bits, bits, below, bad = _bucket_points(
            p, s, n_sets, self.grid_lo, self.grid_extent)
        if bad >= 0:
            if not -1 <= s[bad] < n_sets:
                raise ValueError(f"point_set: set indices must be -1 or in [0, {n_sets}), got "
                                 f"{s[bad]} at point {bad}")
            raise ValueError(f"points: non-finite coordinates at point {bad}")
        best0 = float(np.nextafter(squared_bound(cutoff), np.inf))
        d2 = np.full(len(p), np.inf)
        tri = np.full(len(p), -1, np.int64)
        stats = np.zeros((len(starts) - 1, 3), np.int64)
        tree = WideTree(self.box, self.child, self.part, self.leaf_first, self.leaf_count,
                        self.leaf_part, self.ref_tri, self.ref_part, self.ref_box,
                        self.ref_corners, int(self.depth))
        buckets = Buckets(vals, starts, int(index_bits), int(bits), int(below))
        with numba.parallel_chunksize(1):  # buckets differ in cost: hand them out one by one
            _search(buckets, Batch(p, ptr, parts, best0, int(group)), tree, Found(d2, tri),
                    stats)
        total = stats.sum(axis=0)
        return d2, tri, {"box_tests": int(total[0]), "triangle_tests": int(total[1]),
                         "groups": int(total[2])}


# --------------------------------------------------------------------------- build
@numba.njit(cache=True)
def _subtree_parts(child, first, count, ref_tri, tri_part):
    """Part of each binary node's triangles when they all have one, else -1."""
    n = len(child)
    out = np.full(n, -1, np.int64)
    for i in range(n - 1, -1, -1):  # children come after their parent
        c = child[i]
        if c < 0:
            q = tri_part[ref_tri[first[i]]]
            for r in range(first[i] + 1, first[i] + count[i]):
                if tri_part[ref_tri[r]] != q:
                    q = -1
                    break
            out[i] = q
        else:
            out[i] = out[c] if out[c] == out[c + 1] else -1
    return out


@numba.njit(cache=True)
def _collapse(child, box_lo, box_hi, node_part, pad):
    """The 4-wide tree of a binary one: (box (W, 6, 4), child (W, 4), part (W, 4)); slot k of
    node w holds a binary grandchild (or a child that is a leaf) of w's binary node. Leaves
    keep their binary index, stored as -(index + 1); empty slots have an empty box (lo inf,
    hi -inf) that no distance passes."""
    n = len(child)
    box = np.empty((n, 6, 4))
    wchild = np.zeros((n, 4), np.int64)
    wpart = np.full((n, 4), -1, np.int64)
    queue = np.empty(n, np.int64)  # binary node of each wide node
    queue[0] = 0
    n_wide = 1
    slots = np.empty(4, np.int64)
    w = 0
    while w < n_wide:
        b = queue[w]
        m = 0
        if child[b] < 0:  # only for a root that is a leaf
            slots[0] = b
            m = 1
        else:
            for cc in (child[b], child[b] + 1):
                if child[cc] < 0:
                    slots[m] = cc
                    m += 1
                else:
                    slots[m] = child[cc]
                    slots[m + 1] = child[cc] + 1
                    m += 2
        for k in range(4):
            if k >= m:
                for a in range(3):
                    box[w, a, k] = np.inf
                    box[w, 3 + a, k] = -np.inf
                continue
            x = slots[k]
            for a in range(3):
                box[w, a, k] = box_lo[x, a] - pad
                box[w, 3 + a, k] = box_hi[x, a] + pad
            wpart[w, k] = node_part[x]
            if child[x] < 0:
                wchild[w, k] = -(x + 1)
            else:
                wchild[w, k] = n_wide
                queue[n_wide] = x
                n_wide += 1
        w += 1
    return box[:n_wide].copy(), wchild[:n_wide].copy(), wpart[:n_wide].copy()


# --------------------------------------------------------------------------- grouping
@numba.njit(cache=True, inline="always")
def _spread(x):
    """The low 10 bits of x moved to every third bit (one axis of a Morton code)."""
    x &= 0x3FF
    x = (x | (x << 16)) & 0x030000FF
    x = (x | (x << 8)) & 0x0300F00F
    x = (x | (x << 4)) & 0x030C30C3
    x = (x | (x << 2)) & 0x09249249
    return x


@numba.njit(cache=True)
def _bucket_points(points, point_set, n_sets, lo, extent):
    """The searched points (set >= 0) as ``key << index bits | index``, key ``set << 3 * bits
    | Morton code``, bucketed by their set and coarse cell (the key's top bits) with one
    counting sort: (values, bucket starts (B + 1,), index bits, bits, bits below a bucket,
    the first refused point or -1). Refused: a set outside [-1, n_sets), non-finite
    coordinates. The grid has 2**bits cells a side over the tree's box (points outside take
    the nearest cell); bits is _MORTON_BITS unless key and index would not fit in 63 bits."""
    n = len(points)
    index_bits = 1
    while (1 << index_bits) < n:
        index_bits += 1
    set_bits = 0
    while (1 << set_bits) < n_sets:
        set_bits += 1
    bits = max(0, min(_MORTON_BITS, (63 - index_bits - set_bits) // 3))
    coarse = max(0, min(bits, (_BUCKET_BITS - set_bits) // 3))  # levels that pick a bucket
    below = 3 * (bits - coarse)
    top = float((1 << bits) - 1)
    scale = top / extent if extent > 0 else 0.0
    vals = np.empty(n, np.int64)
    counts = np.zeros((n_sets << (3 * coarse)) + 1, np.int64)
    m = 0
    for i in range(n):
        s = point_set[i]
        if s == -1:
            continue
        if not 0 <= s < n_sets:
            return vals[:0], counts[:1], index_bits, bits, below, i
        code = 0
        for a in range(3):
            c = (points[i, a] - lo[a]) * scale
            if not np.isfinite(c):
                return vals[:0], counts[:1], index_bits, bits, below, i
            code |= _spread(int(min(max(c, 0.0), top))) << a
        key = (s << (3 * bits)) | code
        vals[m] = (key << index_bits) | i
        counts[(key >> below) + 1] += 1
        m += 1
    for b in range(len(counts) - 1):
        counts[b + 1] += counts[b]
    out = np.empty(m, np.int64)
    at = counts[:-1].copy()
    for j in range(m):
        b = vals[j] >> (index_bits + below)
        out[at[b]] = vals[j]
        at[b] += 1
    n_buckets = 0
    for b in range(len(counts) - 1):
        if counts[b + 1] > counts[b]:
            n_buckets += 1
    starts = np.empty(n_buckets + 1, np.int64)
    k = 0
    for b in range(len(counts) - 1):
        if counts[b + 1] > counts[b]:
            starts[k] = counts[b]
            k += 1
    starts[n_buckets] = m
    return out, starts, index_bits, bits, below, -1


@numba.njit(cache=True, inline="always")
def _top_level(x):
    """The largest level L with x >> 3L != 0 (-1 for x == 0)."""
    level = -1
    while level < 21 and (x >> (3 * (level + 1))) != 0:
        level += 1
    return level


@numba.njit(cache=True)
def _groups(keys, group, bits, start):
    """Groups of sorted keys of one set into ``start`` (room for len(keys) + 1); returns how
    many. A group is the largest cell of the octree the Morton code describes holding at most
    ``group`` points (a cell of the finest level with more is cut into runs of ``group``),
    ``bits`` levels, in key order. Built greedily: from each group's first point, the largest
    cell that starts there and holds at most ``group`` points (the same cells as splitting the
    set's cell top down)."""
    m = len(keys)
    n = 0
    b = 0
    while b < m:
        level = bits
        if b > 0:  # a cell starting at b: the previous key is outside it
            level = min(level, _top_level(keys[b - 1] ^ keys[b]))
        if b + group < m:  # at most `group` points: the key `group` on is outside it
            level = min(level, _top_level(keys[b + group] ^ keys[b]))
        shift = 3 * max(level, 0)
        prefix = keys[b] >> shift
        e = b + 1
        while e < m and e < b + group and (keys[e] >> shift) == prefix:
            e += 1
        start[n] = b
        n += 1
        b = e
    start[n] = m
    return n


# --------------------------------------------------------------------------- search
@numba.njit(cache=True, inline="always")
def _gap2(lo0, lo1, lo2, hi0, hi1, hi2, g0, g1, g2, g3, g4, g5):
    """Squared distance between box (lo, hi) and box g (lo xyz, hi xyz); a point is a box of
    zero size."""
    d = 0.0
    e = max(lo0 - g3, g0 - hi0)
    if e > 0.0:
        d += e * e
    e = max(lo1 - g4, g1 - hi1)
    if e > 0.0:
        d += e * e
    e = max(lo2 - g5, g2 - hi2)
    if e > 0.0:
        d += e * e
    return d


@numba.njit(cache=True, inline="always")
def _is_in(value, values, s0, s1):
    for k in range(s0, s1):
        if values[k] == value:
            return True
    return False


@numba.njit(cache=True)
def _search_groups(ga, gb, groups, s0, s1, set_parts, best0, tree, found, stats, scratch):
    """Groups ga .. gb - 1 of ``groups`` (:class:`~workbench.algo.nearest.state.Groups`) in the
    :class:`~workbench.algo.nearest.state.WideTree` ``tree``, ignoring the parts
    ``set_parts[s0:s1]``, into ``found`` (see the module notes; ``scratch`` a
    :class:`~workbench.algo.nearest.state.GroupScratch`). Returns gb, or the group at which
    ``scratch.cand`` ran out of room (that group is to be searched again with more)."""
    box = tree.box
    child = tree.child
    part = tree.part
    leaf_first = tree.leaf_first
    leaf_count = tree.leaf_count
    leaf_part = tree.leaf_part
    ref_tri = tree.ref_tri
    ref_part = tree.ref_part
    ref_box = tree.ref_box
    corners = tree.ref_corners
    spts = groups.spts
    order = groups.order
    g_start = groups.g_start
    out_d2 = found.d2
    out_tri = found.tri
    stack = scratch.stack
    cand = scratch.cand
    cbox = scratch.cbox
    g = scratch.g
    tmp = scratch.tmp
    bound = best0 * _SLACK  # a box is pruned when its squared distance is >= this
    for grp in range(ga, gb):
        b0, b1 = g_start[grp], g_start[grp + 1]
        _points_box(spts, b0, b1, g)
        g0, g1, g2, g3, g4, g5 = g[0], g[1], g[2], g[3], g[4], g[5]
        n_box = n_tri = nc = 0
        stack[0] = 0
        top = 1
        while top > 0:  # the group's box down the tree: candidate leaves
            top -= 1
            node = stack[top]
            for k in range(4):
                if part[node, k] >= 0 and _is_in(part[node, k], set_parts, s0, s1):
                    continue
                n_box += 1
                if _gap2(box[node, 0, k], box[node, 1, k], box[node, 2, k], box[node, 3, k],
                         box[node, 4, k], box[node, 5, k], g0, g1, g2, g3, g4, g5) >= bound:
                    continue
                c = child[node, k]
                if c >= 0:
                    stack[top] = c
                    top += 1
                    continue
                if nc == len(cand):
                    return grp
                cand[nc] = -c - 1
                for a in range(6):
                    cbox[nc, a] = box[node, a, k]
                nc += 1
        for j in range(b0, b1):  # each point against the candidates
            p = spts[j]
            p0, p1, p2 = p[0], p[1], p[2]
            best = best0
            limit = bound
            best_tri = -1
            for m in range(nc):
                n_box += 1
                if _gap2(cbox[m, 0], cbox[m, 1], cbox[m, 2], cbox[m, 3], cbox[m, 4],
                         cbox[m, 5], p0, p1, p2, p0, p1, p2) >= limit:
                    continue
                leaf = cand[m]
                mixed = leaf_part[leaf] < 0
                for r in range(leaf_first[leaf], leaf_first[leaf] + leaf_count[leaf]):
                    # in a leaf of several parts the point's own are near: skip them first
                    if mixed and _is_in(ref_part[r], set_parts, s0, s1):
                        continue
                    if _gap2(ref_box[r, 0], ref_box[r, 1], ref_box[r, 2], ref_box[r, 3],
                             ref_box[r, 4], ref_box[r, 5], p0, p1, p2, p0, p1, p2) >= limit:
                        continue
                    n_tri += 1
                    d = closest_point_on_triangle(p, corners[r, 0], corners[r, 1],
                                                  corners[r, 2], tmp)
                    if d < best:
                        best = d
                        limit = best * _SLACK
                        best_tri = ref_tri[r]
            if best_tri >= 0:
                out_d2[order[j]] = best
                out_tri[order[j]] = best_tri
        stats[grp, 0] = n_box
        stats[grp, 1] = n_tri
    return gb


@numba.njit(cache=True)
def _points_box(spts, b0, b1, g):
    """Bounding box of spts[b0:b1] into g (lo xyz, hi xyz)."""
    for a in range(3):
        g[a] = np.inf
        g[3 + a] = -np.inf
    for j in range(b0, b1):
        for a in range(3):
            g[a] = min(g[a], spts[j, a])
            g[3 + a] = max(g[3 + a], spts[j, a])


@numba.njit(cache=True)
def _search_bucket(buckets, b, batch, tree, found):
    """Bucket b's points: sorted along the curve (radix, _RADIX bits a pass, in cache),
    grouped, searched. Returns (box tests, triangle tests, groups)."""
    vals = buckets.vals
    index_bits = buckets.index_bits
    bits = buckets.bits
    below = buckets.below
    b0, b1 = buckets.starts[b], buckets.starts[b + 1]
    points = batch.points
    set_ptr = batch.set_ptr
    set_parts = batch.set_parts
    best0 = batch.best0
    m = b1 - b0
    v = vals[b0:b1].copy()
    v2 = np.empty(m, np.int64)
    mask = (1 << _RADIX) - 1
    counts = np.empty(mask + 2, np.int64)
    for shift in range(index_bits, index_bits + below, _RADIX):
        counts[:] = 0
        for j in range(m):
            counts[((v[j] >> shift) & mask) + 1] += 1
        for r in range(mask + 1):
            counts[r + 1] += counts[r]
        for j in range(m):
            d = (v[j] >> shift) & mask
            v2[counts[d]] = v[j]
            counts[d] += 1
        v, v2 = v2, v
    order = np.empty(m, np.int64)
    keys = np.empty(m, np.int64)
    spts = np.empty((m, 3))
    for j in range(m):
        i = v[j] & ((1 << index_bits) - 1)
        order[j] = i
        keys[j] = v[j] >> index_bits
        for a in range(3):
            spts[j, a] = points[i, a]
    g_start = np.empty(m + 1, np.int64)
    n_groups = _groups(keys, batch.group, bits, g_start)
    groups = Groups(spts, order, g_start)
    s = keys[0] >> (3 * bits)
    stats = np.zeros((n_groups, 2), np.int64)
    # the candidate arrays are never reassigned inside the search loops: numba would count
    # references at every step there (measured: twice the time)
    stack = np.empty(3 * tree.depth + 8, np.int64)
    g = np.empty(6)
    tmp = np.empty(3)
    room = 512
    grp = 0
    while grp < n_groups:
        cand = np.empty(room, np.int64)
        cbox = np.empty((room, 6))
        grp = _search_groups(grp, n_groups, groups, set_ptr[s], set_ptr[s + 1], set_parts,
                             best0, tree, found, stats, GroupScratch(stack, cand, cbox, g, tmp))
        room *= 4
    return stats[:, 0].sum(), stats[:, 1].sum(), n_groups


@numba.njit(cache=True, parallel=True)
def _search(buckets, batch, tree, found, stats):
    """Every bucket of ``buckets`` (:class:`~workbench.algo.nearest.state.Buckets`) in parallel:
    the query ``batch`` in ``tree`` into ``found``; per bucket (box tests, triangle tests,
    groups) into ``stats``."""
    for b in numba.prange(len(buckets.starts) - 1):
        n_box, n_tri, n_groups = _search_bucket(buckets, b, batch, tree, found)
        stats[b, 0] = n_box
        stats[b, 1] = n_tri
        stats[b, 2] = n_groups
