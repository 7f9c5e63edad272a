"""Upper bounds per triangle of A and their refinement (steps 3 and 4 of
:mod:`workbench.algo.hausdorff`).

* :func:`_sample_upper` -- the first bound of every triangle, against the nearest faces of its
  samples.
* :func:`_tighten` -- plane cuts against those faces and their neighbours only (no tree
  queries); :func:`_refine_planes` -- plane cuts against every face near a triangle, which also
  raises the lower bound (both through :func:`~.polygon._polygon_bounds`).
* :func:`_refine` and :func:`_locate_in` -- the ``split="midpoint"`` refinement by 4-way
  subdivision (:func:`~workbench.algo.nearest.triangle.triangle_bounds`), and the point where the
  lower bound it reports is attained.

The numba kernels take the flat tree of :meth:`~workbench.algo.nearest.bvh.TriangleBVH.arrays`
(a :class:`~workbench.algo.nearest.state.Tree`, ``tree``); distances are in model units.
"""

from __future__ import annotations

import numba
import numpy as np

from ..nearest.bvh import PARALLEL_MIN, within
from ..nearest.triangle import closest_point_on_triangle, triangle_bounds
from .pieces import _ball_radius
from .polygon import _polygon_bounds

# the triangles with the largest upper bounds refined one by one before the rest in parallel
_SERIAL_HEAD = 16


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
def _refine(tri, order, upper, lower, tol, max_depth, tree):
    """Bound the triangles ``order`` (largest upper bound first) by subdivision against the
    faces near them; updates ``upper`` in place and returns (lower, triangle that set it, its
    subdivision target, its candidate radius, triangles refined)."""
    corners = tree.corners
    buffer = np.empty(len(tree.ref_tri), np.int64)
    best_t, best_target, best_radius = -1, 0.0, 0.0
    refined = 0
    for t in order:
        target = lower + tol
        if upper[t] <= target:
            continue
        c, radius = _ball_radius(tri[t], upper[t])
        n = within(c, radius * radius, tree, buffer)
        if n == 0:  # cannot happen when upper[t] is a true bound; keep it as it is
            continue
        lo, up = triangle_bounds(tri[t], corners[buffer[:n]], target, max_depth)
        refined += 1
        upper[t] = min(upper[t], up)
        if lo > lower:
            lower, best_t, best_target, best_radius = lo, t, target, radius
    return lower, best_t, best_target, best_radius, refined


@numba.njit(cache=True)
def _tighten_range(begin, end, tri, order, sample_faces, neighbours, upper, target, max_splits,
                   eps, tree):
    corners = tree.corners
    width = sample_faces.shape[1] * (1 + neighbours.shape[1])
    candidates = np.empty(width, np.int64)
    point = np.empty(3)
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
                      tree):
    n = len(order)
    for chunk in numba.prange((n + 63) // 64):
        _tighten_range(chunk * 64, min(n, (chunk + 1) * 64), tri, order, sample_faces,
                       neighbours, upper, target, max_splits, eps, tree)


def _tighten(tri, order, sample_faces, neighbours, upper, target, max_splits, eps, tree):
    """Upper bounds of the triangles ``order`` by plane cuts against the nearest faces of their
    samples and those faces' neighbours only (no tree queries): cheap, valid, and exact
    wherever those faces cover the triangle, which leaves few triangles for the full
    refinement."""
    args = (tri, order, sample_faces, neighbours, upper, target, max_splits, eps, tree)
    if len(order) >= PARALLEL_MIN // 16:
        _tighten_parallel(*args)
    else:
        _tighten_range(0, len(order), *args)


@numba.njit(cache=True)
def _refine_range(begin, end, tri, order, upper, target, max_splits, eps, tree, out_lower,
                  out_point):
    """Bound the triangles ``order[begin:end]`` by plane cuts against every face near them
    (:func:`_polygon_bounds`), those whose upper bound exceeds ``target``: updates ``upper``,
    writes each one's lower bound and the point attaining it (-1 where skipped)."""
    corners = tree.corners
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
def _refine_parallel(tri, order, upper, target, max_splits, eps, tree, out_lower, out_point):
    n = len(order)
    for chunk in numba.prange((n + 7) // 8):
        _refine_range(chunk * 8, min(n, (chunk + 1) * 8), tri, order, upper, target, max_splits,
                      eps, tree, out_lower, out_point)


def _refine_planes(tri, order, upper, lower, tol, max_splits, eps, tree):
    """Bound the triangles ``order`` (largest upper bound first) by plane cuts against every
    face near them; updates ``upper``; returns (lower, the point attaining it or None, how
    many triangles were refined). The largest few go one by one, each raising the target for
    the next; the rest in parallel against the target reached."""
    out_lower = np.full(len(order), -1.0)
    out_point = np.zeros((len(order), 3))
    point = None
    head = min(len(order), _SERIAL_HEAD)
    for k in range(head):
        _refine_range(k, k + 1, tri, order, upper, lower + tol, max_splits, eps, tree,
                      out_lower, out_point)
        if out_lower[k] > lower:
            lower, point = float(out_lower[k]), out_point[k]
    if len(order) > head:
        rest = order[head:]
        tail_lower = np.full(len(rest), -1.0)
        tail_point = np.zeros((len(rest), 3))
        args = (tri, rest, upper, lower + tol, max_splits, eps, tree, tail_lower, tail_point)
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
def _locate_in(t, radius, target, max_depth, tree):
    """A point of triangle t whose exact distance is at least the lower bound that
    ``triangle_bounds(t, faces, target, max_depth)`` reports, found by descending into the
    subdivision piece with the largest lower bound (a piece bounded on its own is subdivided at
    least as far as inside the whole, so its lower bound is never smaller)."""
    c, _ = _ball_radius(t, 0.0)
    buffer = np.empty(len(tree.ref_tri), np.int64)
    n = within(c, radius * radius, tree, buffer)
    faces = tree.corners[buffer[:n]]
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
