"""The arrays the decimation kernels share, grouped by what they hold, and their set-up.

Each group is a NamedTuple of arrays, which numba passes to a compiled function as one
argument and reads field by field at no cost. Vertices are indices into the (N, 3) vertex
array, faces rows of the (M, 3) face array, originals rows of the (K, 3, 3) input triangles.
The decimation changes the arrays in place; only the support entry lists grow, and then a new
:class:`Supports` holds them.
"""

from __future__ import annotations

from typing import NamedTuple

import numba
import numpy as np
from numba import types
from numba.typed import Dict

# most faces one original triangle may be certified by
_MAX_SUPPORT = 12


class Surface(NamedTuple):
    """The current mesh: coordinates (centred), faces and what each face descends from. The
    rules and the collapse order see ``V``; the certificates hold at every row of ``Vs``."""

    V: np.ndarray         # (N, 3) float64 vertex coordinates, never changed
    Vs: np.ndarray        # (S, N, 3) float64 the coordinates of every certified state (Vs[0] = V)
    F: np.ndarray         # (M, 3) int32 face corners, rewritten by collapses
    fpart: np.ndarray     # (M,) int32 group of each face: its part (and pattern of drawn states)
    alive: np.ndarray     # (M,) bool, False once a collapse removed the face
    n_origin: np.ndarray  # (M, 3) float64 unit normal of the input face (zero if degenerate)


class Originals(NamedTuple):
    """The input triangles that must stay within tolerance of the surface."""

    corners: np.ndarray   # (K, 3, 3) float64 corner coordinates (centred), at ``Surface.V``
    tol: np.ndarray       # (K,) float64 tolerance of each (its part's), model units
    face: np.ndarray      # (K,) int64 the face of the Surface it was on input
    depth: np.ndarray     # (K,) int64 subdivision depth of its certification
    index: np.ndarray     # (K, 3) int32 their vertices (their corners at ``Surface.Vs[s]``)
    live: np.ndarray      # (S, K) bool: whether each must be certified at each state


class Quadrics(NamedTuple):
    """Area-weighted plane quadrics of the input faces around each vertex, summed over the
    vertices collapsed into it."""

    Q: np.ndarray         # (N, 10) float64: xx, yy, zz, xy, xz, yz, xd, yd, zd, dd
    area: np.ndarray      # (N,) float64 summed face area


class Constraints(NamedTuple):
    """What may move, as prepared from the input."""

    fixed: np.ndarray     # (N,) bool: vertices that never move
    ckeys: np.ndarray     # (C,) int64 keys ``min * N + max`` of the feature/boundary edges
    cdeg: np.ndarray      # (N,) int32 how many of those edges each vertex is on


class Lines(NamedTuple):
    """The feature/boundary polylines as the decimation changes them."""

    fixed: np.ndarray     # (N,) bool: vertices that never move
    cdeg: np.ndarray      # (N,) int32 constrained edges at each vertex, updated as u slides
    constrained: Dict     # int64 edge key -> 1 for every constrained edge


class Links(NamedTuple):
    """Per vertex, a singly linked list of its corner slots ``3 f + k`` (see
    :func:`~workbench.algo.simplify.topology._gather`)."""

    head: np.ndarray      # (N,) int64 first slot, -1 for none
    tail: np.ndarray      # (N,) int64 last slot, -1 for none
    nxt: np.ndarray       # (3 M,) int64 next slot of the same vertex, -1 at the end


class Supports(NamedTuple):
    """Per original triangle the faces that certify it; per face the original triangles it
    (may) support, as entry lists whose stale entries are deleted lazily."""

    sup: np.ndarray       # (K, _MAX_SUPPORT) int32 supporting faces, -1 beyond sup_n
    sup_n: np.ndarray     # (K,) int32 how many
    s_head: np.ndarray    # (M,) int64 first entry of each face's list, -1 for none
    e_tri: np.ndarray     # (E,) int32 the original triangle of each entry
    e_next: np.ndarray    # (E,) int64 the next entry of the same face, -1 at the end


class Marks(NamedTuple):
    """Per-vertex state of the collapse loop."""

    dead: np.ndarray      # (N,) bool: collapsed away
    version: np.ndarray   # (N,) int32 stamp of the vertex's queue entries still valid
    retry: np.ndarray     # (N,) bool: a collapse out of it was refused since last queued
    near_u: np.ndarray    # (N,) int64 the last collapse whose u it neighboured
    near_v: np.ndarray    # (N,) int64 the last collapse whose v it neighboured


class Scratch(NamedTuple):
    """Work arrays, allocated once per decimation."""

    fu: np.ndarray        # (M,) faces around u
    fv: np.ndarray        # (M,) faces around v
    fw: np.ndarray        # (M,) faces of the new fan around v
    nbu: np.ndarray       # (2 M + 2,) neighbours of u, and further lists after them
    cntu: np.ndarray      # (2 M + 2,) faces on each edge to them
    nbv: np.ndarray       # (2 M + 2,) neighbours of v
    cntv: np.ndarray      # (2 M + 2,)
    nbp: np.ndarray       # (2 M + 2,) neighbours within one part (link condition per part)
    cntp: np.ndarray      # (2 M + 2,)
    nbq: np.ndarray       # (2 M + 2,)
    cntq: np.ndarray      # (2 M + 2,)
    pos: np.ndarray       # (N,) int64, -1 everywhere between uses
    seen: np.ndarray      # (M,) bool, for the fan walk
    queue: np.ndarray     # (M,) int64, for the fan walk
    aff: np.ndarray       # (K,) int64 original triangles to re-certify
    stamp: np.ndarray     # (K,) int64 the attempt that last listed each in aff
    tri: np.ndarray       # (3, 3) corners of one face
    nrm: np.ndarray       # (3,) its cross product
    old: np.ndarray       # (3,) the cross product before the collapse
    tc: np.ndarray        # (3,) centre of an original triangle
    stack: np.ndarray     # (4 D + 4, 3, 3) pieces of the certification, D the deepest depth
    depth: np.ndarray     # (4 D + 4,) int64 their levels
    piece: np.ndarray     # (3, 3) one piece
    corners: np.ndarray   # (5, 3) points of one distance query
    at_state: np.ndarray  # (3, 3) corners of an original triangle at one state
    hint: np.ndarray      # (1,) int64 the state whose certificate failed last (tried first)


@numba.njit(cache=True)
def _corner_links(F, alive, n_vert):
    """The Links of the alive faces of F."""
    m = F.shape[0]
    head = np.full(n_vert, -1, np.int64)
    tail = np.full(n_vert, -1, np.int64)
    nxt = np.full(3 * m, -1, np.int64)
    for f in range(m):
        if not alive[f]:
            continue
        for k in range(3):
            s = 3 * f + k
            x = F[f, k]
            if head[x] < 0:
                head[x] = s
            else:
                nxt[tail[x]] = s
            tail[x] = s
    return Links(head, tail, nxt)


@numba.njit(cache=True)
def _initial_supports(orig_face, m):
    """Supports where each original triangle is certified by the face it is on (``orig_face``,
    of m faces); returns them and the number of entries used."""
    k_orig = orig_face.shape[0]
    sup = np.full((k_orig, _MAX_SUPPORT), -1, np.int32)
    sup_n = np.zeros(k_orig, np.int32)
    e_tri = np.empty(2 * k_orig + 16, np.int32)
    e_next = np.empty(2 * k_orig + 16, np.int64)
    n_e = 0
    s_head = np.full(m, -1, np.int64)
    for t in range(k_orig):
        f = orig_face[t]
        sup[t, 0] = f
        sup_n[t] = 1
        e_tri[n_e] = t
        e_next[n_e] = s_head[f]
        s_head[f] = n_e
        n_e += 1
    return Supports(sup, sup_n, s_head, e_tri, e_next), n_e


@numba.njit(cache=True)
def _lines_of(constraints):
    """The Lines of the prepared Constraints (the edge keys as a set)."""
    constrained = Dict.empty(key_type=types.int64, value_type=types.int8)
    ckeys = constraints.ckeys
    for i in range(len(ckeys)):
        constrained[ckeys[i]] = np.int8(1)
    return Lines(constraints.fixed, constraints.cdeg, constrained)


@numba.njit(cache=True)
def _new_marks(n_vert):
    """Marks of n_vert vertices before the first collapse."""
    return Marks(np.zeros(n_vert, np.bool_), np.zeros(n_vert, np.int32),
                 np.zeros(n_vert, np.bool_), np.full(n_vert, -1, np.int64),
                 np.full(n_vert, -1, np.int64))


@numba.njit(cache=True)
def _new_scratch(n_vert, m, k_orig, max_depth):
    """Scratch for n_vert vertices, m faces, k_orig originals, certification depths up to
    max_depth."""
    return Scratch(
        np.empty(m, np.int64), np.empty(m, np.int64), np.empty(m, np.int64),
        np.empty(2 * m + 2, np.int64), np.empty(2 * m + 2, np.int64),
        np.empty(2 * m + 2, np.int64), np.empty(2 * m + 2, np.int64),
        np.empty(2 * m + 2, np.int64), np.empty(2 * m + 2, np.int64),
        np.empty(2 * m + 2, np.int64), np.empty(2 * m + 2, np.int64),
        np.full(n_vert, -1, np.int64), np.empty(m, np.bool_), np.empty(m, np.int64),
        np.empty(k_orig, np.int64), np.zeros(k_orig, np.int64),
        np.empty((3, 3)), np.empty(3), np.empty(3), np.empty(3),
        np.empty((4 * max_depth + 4, 3, 3)), np.empty(4 * max_depth + 4, np.int64),
        np.empty((3, 3)), np.empty((5, 3)), np.empty((3, 3)), np.zeros(1, np.int64))
