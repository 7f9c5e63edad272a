"""Bounds of the largest distance from a triangle of A to surface B by cutting the triangle into
convex pieces (the plane-split refinement of :mod:`workbench.algo.hausdorff`).

:func:`_polygon_bounds` keeps a stack of pieces. Each piece is bounded first by the nearest
faces of its vertices (:func:`_vertex_bound`), then by every face near it (:func:`_gather`,
:func:`_face_bound`); a piece that neither settles is cut in two by a plane chosen where the
nearest face changes (:func:`_face_cut`) or across its middle (:func:`_halving_cut`). The
geometry of pieces and planes is in :mod:`.pieces`. The steps of the loop are small kernels
that numba inlines into it (``inline="always"``): the hot loop compiles to one function, with no
more calls or allocations per piece than written out in one body. Lengths are in model units;
the kernels compare squared distances where they can.
"""

from __future__ import annotations

import numba
import numpy as np

from ..nearest.bvh import nearest_one, within
from ..nearest.state import Search
from ..nearest.triangle import closest_point_on_triangle
from .pieces import (
    _BALL_SLACK,
    _MAX_POLY,
    _diameter_end,
    _farthest,
    _piece_ball,
    _secant_plane,
    _shared_edge_plane,
    _sides,
    _split_piece,
)

# a piece near more faces than this is halved before its conflicts are resolved
_MANY_FACES = 48
# a piece near more faces than this is halved without measuring it
_HUGE_FACES = 1024


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
    and ``full``, from the tree (``tree``: a :class:`~workbench.algo.nearest.state.Tree` over
    ``corners``; ``scratch``: room for every reference).
    """
    c, rho = _piece_ball(poly, n)
    tmp = np.empty(3)
    if full and (len(parent) == 0 or len(parent) > _MANY_FACES):
        search = Search(np.empty(tree.depth + 2, np.int64), np.empty(tree.depth + 2), tmp,
                        np.empty(3))
        d_sq, _ = nearest_one(c, -1, np.inf, tree, search)
        radius = min(bound + rho, np.sqrt(d_sq) + 2.0 * rho) * (1.0 + _BALL_SLACK)
        m = within(c, radius * radius, tree, scratch, _HUGE_FACES)
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
    faces ``corners`` (F, 3, 3) in the tree ``tree`` (a :class:`~workbench.algo.nearest.state.Tree`
    over them), given a valid upper bound ``start_upper``.

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
    depth = tree.depth
    ref_tri = tree.ref_tri
    size = max_splits + 4
    poly, count_v, depth_v, kind, bound, parent_start, parent_n = _piece_stack(size)
    tmp = np.empty(3)
    normal = np.empty(3)
    point = np.empty(3)
    side = np.empty(_MAX_POLY)
    quick = np.empty(_MAX_POLY, np.int64)
    search = Search(np.empty(depth + 2, np.int64), np.empty(depth + 2), tmp, np.empty(3))
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
            best_max, piece_lower, lower_sq, hint = _vertex_bound(
                poly[top], n, best_max, lower_sq, hint, best_point, corners, tree, search, quick)
            if _settled(best_max, piece_lower, target_sq, eps, depth_v[top], max_splits, n):
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
            if _final(depth_v[top], max_splits, n):
                upper_sq = max(upper_sq, best_max)
                continue
            n_faces = 0
            worst_v = _diameter_end(poly[top], n)
            done = False
        else:
            faces = pool[free:free + n_faces]
            if n_faces > dist.shape[1]:
                dist = np.empty((_MAX_POLY, 2 * n_faces))
            best_max, piece_lower, lower_sq, best_f, worst_v = _face_bound(
                poly[top], n, faces, corners, dist, tmp, best_max, piece_lower, lower_sq, full,
                best_point)
            done = _settled(best_max, piece_lower, target_sq, eps, depth_v[top], max_splits, n)
            if not done:
                cut, n_pos, n_neg, worst_v = _face_cut(poly[top], n, faces, best_f, worst_v,
                                                       dist, kind[top], rho, corners, point,
                                                       normal, side)
        if not done and (n_pos == 0 or n_neg == 0):
            cut = 3
            n_pos, n_neg = _halving_cut(poly[top], n, worst_v, rho, point, normal, side)
            done = n_pos == 0 or n_neg == 0
        if done:
            upper_sq = max(upper_sq, best_max)
            continue
        _split_piece(poly, count_v, depth_v, kind, bound, top, side, cut, np.sqrt(best_max))
        parent_start[top], parent_start[top + 1] = free, free
        parent_n[top], parent_n[top + 1] = n_faces, n_faces
        top += 2
    return np.sqrt(max(lower_sq, 0.0)), np.sqrt(max(upper_sq, lower_sq))


@numba.njit(cache=True, inline="always")
def _piece_stack(size):
    """Empty stack of ``size`` pieces for :func:`_polygon_bounds`: (poly (size, _MAX_POLY, 3)
    vertices, count_v vertex counts, depth_v cuts from the triangle, kind how a piece was cut
    from its parent (2: secant), bound a valid upper bound over the piece (its parent's),
    parent_start and parent_n the parent's faces ``pool[parent_start[k]:parent_start[k] +
    parent_n[k]]``, from which a piece takes its own (written after them) when it needs
    them)."""
    poly = np.empty((size, _MAX_POLY, 3))
    count_v = np.empty(size, np.int64)
    depth_v = np.empty(size, np.int64)
    kind = np.zeros(size, np.int64)
    bound = np.empty(size)
    parent_start = np.zeros(size, np.int64)
    parent_n = np.zeros(size, np.int64)
    return poly, count_v, depth_v, kind, bound, parent_start, parent_n


@numba.njit(cache=True, inline="always")
def _final(level, max_splits, n):
    """Whether a piece of n vertices, ``level`` cuts from its triangle, may not be cut again:
    ``max_splits`` cuts made, or no room for the two vertices a cut can add."""
    return level >= max_splits or n + 2 > _MAX_POLY


@numba.njit(cache=True, inline="always")
def _settled(best_max, piece_lower, target_sq, eps, level, max_splits, n):
    """Whether a piece stops: its squared bound ``best_max`` is <= ``target_sq``, or its bound
    within ``eps`` of its largest vertex distance (squared ``piece_lower``), or it is final
    (:func:`_final`)."""
    return (best_max <= target_sq or np.sqrt(best_max) <= np.sqrt(piece_lower) + eps
            or _final(level, max_splits, n))


@numba.njit(cache=True, inline="always")
def _vertex_bound(piece, n, best_max, lower_sq, hint, best_point, corners, tree, search, quick):
    """The nearest faces of a piece's n vertices (from the tree): exact distances, and a bound
    that often settles the piece without gathering the faces near it.

    Returns (``best_max`` lowered to the least over those faces of the largest squared vertex
    distance, the piece's largest squared vertex distance, ``lower_sq`` raised to it (the
    vertex written to ``best_point``), the last nearest face, where the next search starts).
    ``search`` (a :class:`~workbench.algo.nearest.state.Search`) is the tree search's scratch,
    ``quick`` room for n faces.
    """
    tmp = search.tmp
    piece_lower = 0.0
    n_quick = 0
    for i in range(n):
        d, f = nearest_one(piece[i], hint, np.inf, tree, search)
        hint = f
        piece_lower = max(piece_lower, d)
        if d > lower_sq:
            lower_sq = d
            best_point[:] = piece[i]
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
            worst = max(worst, closest_point_on_triangle(piece[i], face[0], face[1], face[2],
                                                         tmp))
            if worst >= best_max:
                break
        best_max = min(best_max, worst)
    return best_max, piece_lower, lower_sq, hint


@numba.njit(cache=True, inline="always")
def _face_bound(piece, n, faces, corners, dist, tmp, best_max, piece_lower, lower_sq, full,
                best_point):
    """A piece's n vertices against the faces near it: their squared distances into
    ``dist[:n, :len(faces)]``, the best single face, the vertex that spoils it most, the exact
    vertex distances.

    Returns (``best_max`` lowered to the best face's largest squared vertex distance,
    ``piece_lower`` raised to the largest squared vertex distance, ``lower_sq`` raised likewise
    when ``full`` (the vertex written to ``best_point``), the best face's position in
    ``faces``, the vertex farthest from it).
    """
    n_faces = len(faces)
    for i in range(n):
        for k in range(n_faces):
            face = corners[faces[k]]
            dist[i, k] = closest_point_on_triangle(piece[i], face[0], face[1], face[2], tmp)
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
            best_point[:] = piece[i]
    return best_max, piece_lower, lower_sq, best_f, worst_v


@numba.njit(cache=True, inline="always")
def _face_cut(piece, n, faces, best_f, worst_v, dist, parent_cut, rho, corners, point, normal,
              side):
    """A plane across a piece (radius ``rho``) on whose sides one face tends to be nearest:
    the bisector of the edge that the best face ``faces[best_f]`` shares with the nearest face g
    of the vertex ``worst_v`` that spoils it, else (unless the piece itself came from such a
    cut, ``parent_cut`` 2) the zero line of ``d(·, best) - d(·, g)``. Writes the plane to
    ``point``/``normal`` and the vertices' signed sides to ``side``; returns (how it was cut:
    0 not, 1 bisector, 2 secant; vertices above; vertices below; the vertex to halve the piece
    from when neither plane separates). Among more than ``_MANY_FACES`` faces no plane is tried
    and the piece is to be halved across its diameter (cheaper than resolving the conflicts of
    many faces in one piece, whose cost grows with their square).
    """
    n_faces = len(faces)
    g, g_d = 0, np.inf
    for k in range(n_faces):
        if dist[worst_v, k] < g_d:
            g, g_d = k, dist[worst_v, k]
    cut = 0
    n_pos = n_neg = 0
    if n_faces > _MANY_FACES:
        worst_v = _diameter_end(piece, n)
    else:
        on = _shared_edge_plane(corners[faces[best_f]], corners[faces[g]], normal)
        if on >= 0:
            cut = 1
            n_pos, n_neg = _sides(piece, n, corners[faces[best_f], on], normal, rho, side)
        if (n_pos == 0 or n_neg == 0) and parent_cut != 2:
            cut = 2
            n_pos, n_neg = _secant_plane(piece, dist, n, best_f, g, point, normal)
            if n_pos > 0:
                n_pos, n_neg = _sides(piece, n, point, normal, rho, side)
    return cut, n_pos, n_neg, worst_v


@numba.njit(cache=True, inline="always")
def _halving_cut(piece, n, v, rho, point, normal, side):
    """The plane halfway between vertex v of a piece (radius ``rho``) and its vertex farthest
    from v, across their segment: written to ``point``/``normal``, the vertices' signed sides
    to ``side``; returns (vertices above, vertices below)."""
    far = _farthest(piece, n, v)
    normal[:] = piece[far] - piece[v]
    point[:] = 0.5 * (piece[far] + piece[v])
    return _sides(piece, n, point, normal, rho, side)
