"""The trees of the element hierarchy: median splits of element centres (numba) and the forest
of one tree per part under a top level over the parts, laid out in flat arrays.

A tree over n centres is split top down at the median along the longest axis of the centres'
box (or, for OBB hierarchies, their principal axis) until a node holds at most ``leaf_size``
of them; nodes are numbered breadth first with siblings adjacent. :func:`build_forest`
numbers the top level first (``P - 1`` nodes for P parts), then each part's tree, and gives
every node its contiguous range of the elements in tree order.
"""

from __future__ import annotations

from typing import NamedTuple

import numba
import numpy as np


class Forest(NamedTuple):
    """The layout of :func:`build_forest`: ``left``/``right`` (nodes,) children (-1 for a
    leaf), ``start``/``end`` (nodes,) each node's range of ``order``, ``node_part`` (nodes,)
    the part index of a part-tree node (-1 at the top level), ``order`` (E,) the elements (rows
    of the input) in tree order, ``part_roots`` (P,) each part's root node, ``root`` the
    forest's root, ``n_top`` the top level's nodes, ``depth`` the most nodes on a root-to-leaf
    path."""

    left: np.ndarray
    right: np.ndarray
    start: np.ndarray
    end: np.ndarray
    node_part: np.ndarray
    order: np.ndarray
    part_roots: np.ndarray
    root: int
    n_top: int
    depth: int


def build_forest(verts: np.ndarray, pidx: np.ndarray, n_parts: int, leaf_size: int,
                 principal: bool) -> Forest:
    """One tree per part over the element centres (the mean of each element's nodes ``verts``
    (E, 4, 3)), ``leaf_size`` elements per leaf at most, under a top level with one part per
    leaf over the centres of the parts' node boxes (``pidx`` (E,) each element's part index in
    [0, ``n_parts``)); split along principal axes when ``principal``. Each top node encloses
    whole parts, each part's subtree only that part."""
    # top level over the parts: centres of the parts' node boxes
    lo = np.full((n_parts, 3), np.inf)
    hi = np.full((n_parts, 3), -np.inf)
    np.minimum.at(lo, pidx, verts.min(axis=1))
    np.maximum.at(hi, pidx, verts.max(axis=1))
    top_perm, top_left, top_start, top_end = _build_tree(0.5 * (lo + hi), 1, principal)
    part_order = top_perm  # parts in the order their elements are laid out
    trees = _part_trees(verts.mean(axis=1), pidx, n_parts, part_order, leaf_size, principal)
    n_top = n_parts - 1
    # element offsets and root nodes of the parts in layout position order
    part_first = np.concatenate([[0], np.cumsum([len(t[0]) for t in trees])]).astype(np.int64)
    sizes = np.array([len(t[1]) for t in trees], np.int64)
    roots = n_top + np.concatenate([[0], np.cumsum(sizes)[:-1]]).astype(np.int64)
    part_roots = np.empty(n_parts, np.int64)
    part_roots[part_order] = roots
    n_nodes = n_top + int(sizes.sum())
    left = np.full(n_nodes, -1, np.int64)
    right = np.full(n_nodes, -1, np.int64)
    start = np.empty(n_nodes, np.int64)
    end = np.empty(n_nodes, np.int64)
    node_part = np.full(n_nodes, -1, np.int64)
    if n_parts > 1:
        # top inner nodes keep their breadth-first order; top leaves are the part roots
        inner = np.flatnonzero(top_left >= 0)
        gid = np.empty(len(top_left), np.int64)
        gid[inner] = np.arange(len(inner))
        leaves = np.flatnonzero(top_left < 0)
        gid[leaves] = part_roots[part_order[top_start[leaves]]]
        left[gid[inner]] = gid[top_left[inner]]
        right[gid[inner]] = gid[top_left[inner] + 1]
        start[gid[inner]] = part_first[top_start[inner]]
        end[gid[inner]] = part_first[top_end[inner]]
    for k, (q, (_, lft, s, e)) in enumerate(zip(part_order, trees)):
        r0 = roots[k]
        idx = np.arange(r0, r0 + len(lft))
        left[idx] = np.where(lft >= 0, lft + r0, -1)
        right[idx] = np.where(lft >= 0, lft + r0 + 1, -1)
        start[idx] = s + part_first[k]
        end[idx] = e + part_first[k]
        node_part[idx] = q
    depth = max(int(_tree_depth(t[1])) for t in trees)
    if n_parts > 1:
        depth += int(_tree_depth(top_left)) - 1
    root = 0 if n_parts > 1 else int(part_roots[0])
    return Forest(left, right, start, end, node_part, np.concatenate([t[0] for t in trees]),
                  part_roots, root, n_top, depth)


def _part_trees(centres, pidx, n_parts, part_order, leaf_size, principal) -> list:
    """The tree of each part over its elements' ``centres``, in the order ``part_order``: a
    list of (the part's elements in tree order, left, start, end) as :func:`_build_tree`
    numbers them within the part."""
    by_part = np.argsort(pidx, kind="stable")
    bounds = np.concatenate([[0], np.cumsum(np.bincount(pidx, minlength=n_parts))])
    trees = []
    for q in part_order:
        members = by_part[bounds[q]:bounds[q + 1]]
        perm, left, start, end = _build_tree(centres[members], leaf_size, principal)
        trees.append((members[perm], left, start, end))
    return trees


@numba.njit(cache=True)
def _tree_depth(left):
    """Most nodes on a root-to-leaf path of a breadth-first tree (children at left, left+1)."""
    depth = np.ones(len(left), np.int64)
    for i in range(len(left)):  # parents precede children in breadth-first order
        if left[i] >= 0:
            depth[left[i]] = depth[i] + 1
            depth[left[i] + 1] = depth[i] + 1
    return depth.max()


# --------------------------------------------------------------------------- build (numba)
@numba.njit(cache=True)
def _split_axis(centres, perm, s, e, principal):
    """Unit split direction for centres[perm[s:e]]: the longest axis of their box, or (when
    ``principal``) the dominant eigenvector of their covariance by power iteration from it."""
    lo0 = lo1 = lo2 = np.inf
    hi0 = hi1 = hi2 = -np.inf
    for i in range(s, e):
        j = perm[i]
        x, y, z = centres[j, 0], centres[j, 1], centres[j, 2]
        lo0, hi0 = min(lo0, x), max(hi0, x)
        lo1, hi1 = min(lo1, y), max(hi1, y)
        lo2, hi2 = min(lo2, z), max(hi2, z)
    v0, v1, v2 = 1.0, 0.0, 0.0
    if hi1 - lo1 > hi0 - lo0 and hi1 - lo1 >= hi2 - lo2:
        v0, v1 = 0.0, 1.0
    elif hi2 - lo2 > hi0 - lo0 and hi2 - lo2 > hi1 - lo1:
        v0, v2 = 0.0, 1.0
    if principal:
        n = e - s
        m0 = m1 = m2 = 0.0
        for i in range(s, e):
            j = perm[i]
            m0 += centres[j, 0]
            m1 += centres[j, 1]
            m2 += centres[j, 2]
        m0 /= n
        m1 /= n
        m2 /= n
        c00 = c01 = c02 = c11 = c12 = c22 = 0.0
        for i in range(s, e):
            j = perm[i]
            x, y, z = centres[j, 0] - m0, centres[j, 1] - m1, centres[j, 2] - m2
            c00 += x * x
            c01 += x * y
            c02 += x * z
            c11 += y * y
            c12 += y * z
            c22 += z * z
        for _ in range(32):
            w0 = c00 * v0 + c01 * v1 + c02 * v2
            w1 = c01 * v0 + c11 * v1 + c12 * v2
            w2 = c02 * v0 + c12 * v1 + c22 * v2
            length = np.sqrt(w0 * w0 + w1 * w1 + w2 * w2)
            if not length > 0:
                break
            v0, v1, v2 = w0 / length, w1 / length, w2 / length
    axis = np.empty(3)
    axis[0], axis[1], axis[2] = v0, v1, v2
    return axis


@numba.njit(cache=True)
def _select(keys, perm, s, e, k):
    """Reorder perm[s:e] (keys alongside) so that keys[s:k] <= keys[k] <= keys[k+1:e]: a
    three-way quickselect (many equal keys on regular meshes), pivot the median of three."""
    lo, hi = s, e - 1
    while lo < hi:
        a, b, c = keys[lo], keys[(lo + hi) // 2], keys[hi]
        pivot = max(min(a, b), min(max(a, b), c))
        lt, i, gt = lo, lo, hi
        while i <= gt:
            if keys[i] < pivot:
                keys[lt], keys[i] = keys[i], keys[lt]
                perm[lt], perm[i] = perm[i], perm[lt]
                lt += 1
                i += 1
            elif keys[i] > pivot:
                keys[gt], keys[i] = keys[i], keys[gt]
                perm[gt], perm[i] = perm[i], perm[gt]
                gt -= 1
            else:
                i += 1
        if k < lt:
            hi = lt - 1
        elif k > gt:
            lo = gt + 1
        else:
            return


@numba.njit(cache=True)
def _build_tree(centres, leaf_size, principal):
    """Median-split tree over the rows of ``centres``: (perm, left, start, end) with nodes in
    breadth-first order, children of node i at left[i] and left[i] + 1 (-1 for a leaf), and
    node i covering perm[start[i]:end[i]]."""
    n = len(centres)
    cap = 2 * n
    perm = np.arange(n)
    keys = np.empty(n)
    left = np.full(cap, -1, np.int64)
    start = np.empty(cap, np.int64)
    end = np.empty(cap, np.int64)
    start[0], end[0] = 0, n
    n_nodes = 1
    head = 0
    while head < n_nodes:
        s, e = start[head], end[head]
        count = e - s
        if count > leaf_size:
            axis = _split_axis(centres, perm, s, e, principal)
            for i in range(s, e):
                j = perm[i]
                keys[i] = centres[j, 0] * axis[0] + centres[j, 1] * axis[1] \
                    + centres[j, 2] * axis[2]
            mid = s + count // 2
            _select(keys, perm, s, e, mid)
            left[head] = n_nodes
            start[n_nodes], end[n_nodes] = s, mid
            start[n_nodes + 1], end[n_nodes + 1] = mid, e
            n_nodes += 2
        head += 1
    return perm, left[:n_nodes].copy(), start[:n_nodes].copy(), end[:n_nodes].copy()
