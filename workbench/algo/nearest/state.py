"""The arrays the nearest-point kernels share, grouped by what they hold.

Each group is a NamedTuple, which numba passes to a compiled function as one argument and reads
field by field at no cost; a kernel takes the fields it needs before its loops, one assignment
each (``stack = search.stack``), never by unpacking a tuple of them: numba's dead-code pass
keeps the writes to an array read from an argument's field, but may drop those to one unpacked
from a tuple (a parallel kernel lost the last write of its loop body that way). Every field
keeps one type from call to call (the arrays their dtype and C order, the counts int), so that
one compiled version serves every call. Lengths are in the units of the triangles' corners.

* :class:`Tree` -- the flat :class:`~workbench.algo.nearest.bvh.TriangleBVH` (what
  :meth:`~workbench.algo.nearest.bvh.TriangleBVH.arrays` returns);
* :class:`Search` -- the scratch of one branch-and-bound search in that tree
  (:func:`~workbench.algo.nearest.bvh.nearest_one`), made by :func:`new_search`;
* :class:`WideTree`, :class:`Buckets`, :class:`Batch`, :class:`Groups`, :class:`GroupScratch`,
  :class:`Found` -- the 4-wide tree of :class:`~workbench.algo.nearest.batch.BatchedTriangleTree`
  and the state of its grouped search.
"""

from __future__ import annotations

from typing import NamedTuple

import numba
import numpy as np


class Tree(NamedTuple):
    """An AABB tree over triangles, flat: node boxes, children, leaf ranges of references."""

    box_lo: np.ndarray    # (nodes, 3) float64 lower corner of each node's box
    box_hi: np.ndarray    # (nodes, 3) float64 upper corner
    child: np.ndarray     # (nodes,) int64 first child of an inner node (second: + 1), -1 a leaf
    first: np.ndarray     # (nodes,) int64 a leaf's first reference
    count: np.ndarray     # (nodes,) int64 a leaf's references
    ref_tri: np.ndarray   # (R,) int64 the triangle of each reference, in tree order
    corners: np.ndarray   # (K, 3, 3) float64 triangle corners
    depth: int            # levels of the tree


class Search(NamedTuple):
    """Scratch of one nearest-triangle search (:func:`~.bvh.nearest_one`)."""

    stack: np.ndarray       # (depth + 2,) int64 nodes to visit
    stack_d: np.ndarray     # (depth + 2,) float64 their squared box distances
    tmp: np.ndarray         # (3,) float64 a closest point being measured
    best_point: np.ndarray  # (3,) float64 the closest point found (the result)


@numba.njit(cache=True)
def new_search(depth):
    """A :class:`Search` for a tree of ``depth`` levels (best_point NaN)."""
    return Search(np.empty(depth + 2, np.int64), np.empty(depth + 2), np.empty(3),
                  np.full(3, np.nan))


class WideTree(NamedTuple):
    """The 4-wide tree of :class:`~.batch.BatchedTriangleTree` and its references in tree
    order."""

    box: np.ndarray          # (W, 6, 4) float64 children's boxes: lo xyz, hi xyz per slot
    child: np.ndarray        # (W, 4) int64 child node, a leaf as -(leaf + 1)
    part: np.ndarray         # (W, 4) int64 part of a child's subtree, -1 for several
    leaf_first: np.ndarray   # (binary nodes,) int64 a leaf's first reference
    leaf_count: np.ndarray   # (binary nodes,) int64 a leaf's references
    leaf_part: np.ndarray    # (binary nodes,) int64 part of a leaf, -1 for several
    ref_tri: np.ndarray      # (R,) int64 triangle of each reference
    ref_part: np.ndarray     # (R,) int64 its part
    ref_box: np.ndarray      # (R, 6) float64 its padded box
    ref_corners: np.ndarray  # (R, 3, 3) float64 its corners
    depth: int               # levels of the binary tree


class Buckets(NamedTuple):
    """The searched points bucketed by set and coarse cell (:func:`~.batch._bucket_points`)."""

    vals: np.ndarray   # (M,) int64 ``key << index_bits | point index``, bucket by bucket
    starts: np.ndarray  # (B + 1,) int64 each bucket's first value
    index_bits: int    # bits of the point index
    bits: int          # Morton levels of the key
    below: int         # key bits below a bucket's


class Batch(NamedTuple):
    """The query: points, the parts each set excludes (CSR), the bound and the group size."""

    points: np.ndarray     # (P, 3) float64
    set_ptr: np.ndarray    # (S + 1,) int64
    set_parts: np.ndarray  # (set_ptr[-1],) int64 part indices
    best0: float           # squared bound: only nearer triangles are found
    group: int             # most points per group


class Found(NamedTuple):
    """The results, per point."""

    d2: np.ndarray   # (P,) float64 squared distance (inf: none found)
    tri: np.ndarray  # (P,) int64 triangle (-1: none found)


class Groups(NamedTuple):
    """One bucket's points sorted along the curve and cut into groups."""

    spts: np.ndarray     # (m, 3) float64 the points in curve order
    order: np.ndarray    # (m,) int64 their indices in the query
    g_start: np.ndarray  # (groups + 1,) int64 each group's first point


class GroupScratch(NamedTuple):
    """Work arrays of a bucket's search; ``cand``/``cbox`` sized ahead (a group that overflows
    them is searched again with more)."""

    stack: np.ndarray  # (3 depth + 8,) int64 wide nodes to visit
    cand: np.ndarray   # (room,) int64 candidate leaves of a group
    cbox: np.ndarray   # (room, 6) float64 their boxes
    g: np.ndarray      # (6,) float64 a group's box
    tmp: np.ndarray    # (3,) float64 a closest point being measured
