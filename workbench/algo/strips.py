"""Quad strips by bandification (crash2000 §3.1, Fig. 4) and meshoptimizer's triangle strips.

A **quad strip** is a vertex sequence v0 v1 v2 v3 … in ``GL_QUAD_STRIP`` order: quad k is
(v2k, v2k+1, v2k+3, v2k+2). The same sequence is a valid ``GL_TRIANGLE_STRIP`` of the same
vertices, each quad split along its diagonal v2k+1–v2k+2, so it is drawn as a triangle strip with
primitive restart. A strip of n quads costs 2n + 2 vertices instead of 4n.

**Bandification** (Sommer & Ertl's pseudo code, Fig. 4): repeated passes find, for every still
*active* quad that no band of the pass has covered yet, the maximal band through it; bands at
least ``cutoff`` quads long go into a list sorted by length, the longest are accepted while their
length is unchanged (none of their quads taken by an accepted band), and the next pass starts at
the first changed band. A quad whose maximal band is shorter than ``cutoff`` is left over.
Unlike triangle strips, quad strips never continue with a swap: it would cost four vertices, more
than starting anew (the paper's Fig. 3).

Rules that make the result well defined:

* Two quads join across an edge only if the edge is used by exactly these two non-degenerate
  elements and they traverse it in opposite directions (consistent winding), so each quad of a
  strip keeps the winding of its element. Non-manifold edges, edges shared with a triangle and
  edges between inconsistently wound neighbours end a band.
* The band through quad i in direction d ∈ {0, 1} enters i through its local edge d (corners d,
  d+1) and leaves through d+2; it is walked backward, then forward, over active quads, stopping
  at a quad already in the band (closed rings). The maximal band is direction 0's unless
  direction 1's is longer. Starts are visited in element order; equal lengths keep discovery order.
* Element kinds follow the mesh conventions (:mod:`workbench.scene.derived`): a **triangle**
  (one pair of adjacent corners on the same node, ``c == d`` as stored) is returned apart and
  drawn as its own three-vertex strip; a **degenerate** element (fewer than three distinct nodes,
  or opposite corners on one node) is reported in ``degenerate`` and drawn nowhere.
"""

from __future__ import annotations

import ctypes
from dataclasses import dataclass

import numba
import numpy as np

from ..scene.derived import as_elements, classify_elements, triangulate

__all__ = ["RESTART", "QuadStrips", "TriStrips", "join_strips", "quad_strips", "tri_strips",
           "unstripify"]

#: the primitive-restart index that separates strips in one index buffer
RESTART = 0xFFFFFFFF


# --------------------------------------------------------------------------- quad strips
@dataclass(eq=False)
class QuadStrips:
    """Quad strips of an element mesh, with the elements they leave out.

    ``elements`` (M, 4) int32: the input. ``vertices`` (V,) int32: the strips' vertex sequences
    concatenated; strip s is ``vertices[vertex_starts[s]:vertex_starts[s + 1]]``, 2·(quads + 1)
    long. ``quads`` (Q,) int32: the element of each strip quad, strip by strip, in strip order;
    strip s holds ``quads[quad_starts[s]:quad_starts[s + 1]]``; ``entry_edges`` (Q,) int8: the
    local edge j (corners j, j+1) through which the strip enters each quad, so that the quad is
    (c[j], c[j+1], c[j+2], c[j+3]) = (v2k, v2k+1, v2k+3, v2k+2). ``leftover``: quads in no band
    (their maximal band was shorter than ``cutoff``); ``triangles``: triangle elements;
    ``degenerate``: zero-area elements, drawn nowhere (all int32 element indices, ascending).
    ``passes``: bandification passes that accepted a band.
    """

    elements: np.ndarray
    vertices: np.ndarray
    vertex_starts: np.ndarray
    quads: np.ndarray
    quad_starts: np.ndarray
    entry_edges: np.ndarray
    leftover: np.ndarray
    triangles: np.ndarray
    degenerate: np.ndarray
    cutoff: int
    passes: int

    @property
    def n_strips(self) -> int:
        return len(self.quad_starts) - 1

    @property
    def strip_lengths(self) -> np.ndarray:
        """(S,) quads per strip."""
        return np.diff(self.quad_starts)

    def strip(self, s: int) -> np.ndarray:
        """The vertex sequence of strip ``s`` (GL_QUAD_STRIP order)."""
        return self.vertices[self.vertex_starts[s]:self.vertex_starts[s + 1]]

    @property
    def vertex_count(self) -> int:
        """Vertices sent to draw everything (the paper's "#verts"): the strips' vertices, 4 per
        leftover quad and 3 per triangle."""
        return len(self.vertices) + 4 * len(self.leftover) + 3 * len(self.triangles)

    @property
    def mean_triangles_per_strip(self) -> float:
        """Triangles per strip (2 per quad; the paper's "length"); 0.0 without strips."""
        return 2.0 * len(self.quads) / self.n_strips if self.n_strips else 0.0

    def _leftover_sequences(self) -> np.ndarray:
        """(L, 4) leftover quads (a, b, c, d) as the one-quad strips (a, b, d, c)."""
        return self.elements[self.leftover][:, [0, 1, 3, 2]]

    def triangle_nodes(self) -> np.ndarray:
        """(T, 3) int32 the distinct nodes of each triangle element, in winding order."""
        if not len(self.triangles):
            return np.zeros((0, 3), np.int32)
        return triangulate(self.elements[self.triangles],
                           np.zeros((int(self.elements.max()) + 1, 3))).triangles

    def draw_sequences(self) -> tuple[np.ndarray, np.ndarray]:
        """Everything as triangle-strip vertex sequences: (flat int32 vertices, int64 lengths).

        The strips, then each leftover quad (a, b, c, d) as (a, b, d, c), then each triangle as
        its three distinct nodes.
        """
        flat = np.concatenate([self.vertices, self._leftover_sequences().ravel(),
                               self.triangle_nodes().ravel()]).astype(np.int32)
        lengths = np.concatenate([np.diff(self.vertex_starts), np.full(len(self.leftover), 4),
                                  np.full(len(self.triangles), 3)]).astype(np.int64)
        return flat, lengths

    def triangle_list(self) -> np.ndarray:
        """(K, 3) int32 the triangles the strips draw, as an unstripped list.

        Strip quad k gives (v2k, v2k+1, v2k+2) and (v2k+2, v2k+1, v2k+3) -- split along the
        strip's diagonal, winding of the element -- then each leftover quad (a, b, c, d) gives
        (a, b, d), (d, b, c), then each triangle element its distinct nodes in winding order.
        """
        v = self.vertices
        # vertex index of v2k for every strip quad: two per quad plus two per earlier strip
        strip_of = np.repeat(np.arange(self.n_strips), self.strip_lengths)
        base = 2 * np.arange(len(self.quads)) + 2 * strip_of
        quads = np.empty((len(self.quads), 2, 3), np.int32)
        quads[:, 0] = np.stack([v[base], v[base + 1], v[base + 2]], axis=1)
        quads[:, 1] = np.stack([v[base + 2], v[base + 1], v[base + 3]], axis=1)
        left = self._leftover_sequences()
        left_tris = np.stack([left[:, [0, 1, 2]], left[:, [2, 1, 3]]], axis=1).reshape(-1, 3)
        return np.ascontiguousarray(np.concatenate(
            [quads.reshape(-1, 3), left_tris, self.triangle_nodes()]), dtype=np.int32)

    def restart_indices(self, restart: int = RESTART) -> np.ndarray:
        """(L,) uint32 ``GL_TRIANGLE_STRIP`` indices with primitive restart: the
        :meth:`draw_sequences` separated by ``restart`` (none at the end). Draws exactly
        :meth:`triangle_list`. Refuses (ValueError) a ``restart`` that is also a vertex index."""
        flat, lengths = self.draw_sequences()
        _check_restart(restart, int(flat.max()) if len(flat) else -1)
        return join_strips(flat, lengths, restart)


def _check_restart(restart: int, largest_index: int) -> None:
    if not largest_index < restart <= RESTART:
        raise ValueError(f"restart index {restart} must exceed every vertex index (largest "
                         f"{largest_index}) and fit 32 bits")


def join_strips(flat: np.ndarray, lengths: np.ndarray, restart: int = RESTART) -> np.ndarray:
    """(L,) uint32: sequences of the given ``lengths``, concatenated in ``flat``, joined by
    ``restart`` (none at the end)."""
    n = len(lengths)
    if n == 0:
        return np.zeros(0, np.uint32)
    out = np.full(len(flat) + n - 1, restart, np.uint32)
    # an entry of sequence i moves right by the i restarts before it
    out[np.arange(len(flat)) + np.repeat(np.arange(n), lengths)] = flat
    return out


def quad_strips(elements, cutoff: int = 1) -> QuadStrips:
    """Bandify the quads of ``elements`` ((M, 4) or (M, 3) node or vertex indices) into strips.

    ``cutoff``: the shortest band, in quads, that becomes a strip (≥ 1); quads whose maximal band
    is shorter are returned in ``leftover``. Refuses (ValueError) elements that are not
    non-negative integer (M, 4)/(M, 3) arrays and a cutoff below 1.
    """
    if int(cutoff) != cutoff or cutoff < 1:
        raise ValueError(f"cutoff must be an integer >= 1, got {cutoff}")
    e = as_elements(elements)
    quad, tri, _ = classify_elements(e)
    degenerate = ~(quad | tri)
    neighbour, neighbour_edge = _quad_neighbours(e, quad, tri)
    order, entry, lengths, leftover, passes = _bandify(neighbour, neighbour_edge, quad, int(cutoff))
    # vertex sequences: (c[E], c[E+1]) of each strip's first quad, then (c[E+3], c[E+2]) per quad
    n_strips, n_quads = len(lengths), len(order)
    quad_starts = np.zeros(n_strips + 1, np.int64)
    np.cumsum(lengths, out=quad_starts[1:])
    corners = e[order]
    ent = entry.astype(np.intp)
    rows = np.arange(n_quads)
    vertices = np.empty(2 * n_quads + 2 * n_strips, np.int32)
    strip_of = np.repeat(np.arange(n_strips), lengths)
    tail = 2 * rows + 2 * strip_of + 2
    vertices[tail] = corners[rows, (ent + 3) % 4]
    vertices[tail + 1] = corners[rows, (ent + 2) % 4]
    first = quad_starts[:-1]
    head = 2 * first + 2 * np.arange(n_strips)
    vertices[head] = corners[first, ent[first]]
    vertices[head + 1] = corners[first, (ent[first] + 1) % 4]
    return QuadStrips(
        elements=e,
        vertices=vertices,
        vertex_starts=(2 * quad_starts + 2 * np.arange(n_strips + 1)).astype(np.int64),
        quads=order.astype(np.int32),
        quad_starts=quad_starts,
        entry_edges=entry.astype(np.int8),
        leftover=np.flatnonzero(leftover).astype(np.int32),
        triangles=np.flatnonzero(tri).astype(np.int32),
        degenerate=np.flatnonzero(degenerate).astype(np.int32),
        cutoff=int(cutoff),
        passes=int(passes),
    )


def _quad_neighbours(e: np.ndarray, quad: np.ndarray, tri: np.ndarray):
    """(M, 4) neighbour quad across each local edge j (corners j, j+1) and that neighbour's
    local edge index, -1 where the edge does not join (see the module notes)."""
    m = len(e)
    neighbour = np.full((m, 4), -1, np.int32)
    neighbour_edge = np.full((m, 4), -1, np.int8)
    used = quad | tri
    if not quad.any():
        return neighbour, neighbour_edge
    element = np.repeat(np.arange(m), 4)
    local = np.tile(np.arange(4, dtype=np.int8), m)
    u = e.ravel().astype(np.int64)
    v = e[:, [1, 2, 3, 0]].ravel().astype(np.int64)
    keep = used[element] & (u != v)  # zero-length edges of triangles are no edges
    element, local, u, v = element[keep], local[keep], u[keep], v[keep]
    key = (np.minimum(u, v) << 32) | np.maximum(u, v)
    order = np.argsort(key, kind="stable")
    key = key[order]
    starts = np.flatnonzero(np.r_[True, key[1:] != key[:-1]])
    counts = np.diff(np.r_[starts, len(key)])
    pair = starts[counts == 2]
    a, b = order[pair], order[pair + 1]
    ok = (quad[element[a]] & quad[element[b]] & (element[a] != element[b])
          & (u[a] == v[b]) & (v[a] == u[b]))
    a, b = a[ok], b[ok]
    neighbour[element[a], local[a]] = element[b]
    neighbour_edge[element[a], local[a]] = local[b]
    neighbour[element[b], local[b]] = element[a]
    neighbour_edge[element[b], local[b]] = local[a]
    return neighbour, neighbour_edge


@numba.njit(cache=True)
def _walk_away(cur, edge, neighbour, neighbour_edge, active, seen, stamp, out_q, out_e, n,
               backward):
    """Append to out_q/out_e from index n the quads met leaving ``cur`` through ``edge`` and
    onwards; return the new n. Walking backward, a quad's entry edge in band order is the one
    opposite the edge it was reached through."""
    while True:
        r = neighbour[cur, edge]
        if r < 0 or not active[r] or seen[r] == stamp:
            return n
        k = neighbour_edge[cur, edge]
        seen[r] = stamp
        out_q[n] = r
        out_e[n] = (k + 2) % 4 if backward else k
        n += 1
        cur, edge = r, (k + 2) % 4


@numba.njit(cache=True)
def _walk(i, d, neighbour, neighbour_edge, active, seen, stamp, out_q, out_e):
    """The band through quad i in direction d into out_q/out_e (quads, entry edges); its length.

    ``seen[q] == stamp`` marks the quads already in this band.
    """
    seen[i] = stamp
    nb = _walk_away(i, d, neighbour, neighbour_edge, active, seen, stamp, out_q, out_e, 0, True)
    # the backward part was collected farthest-last: reverse it, then append i and walk forward
    for j in range(nb // 2):
        out_q[j], out_q[nb - 1 - j] = out_q[nb - 1 - j], out_q[j]
        out_e[j], out_e[nb - 1 - j] = out_e[nb - 1 - j], out_e[j]
    out_q[nb] = i
    out_e[nb] = d
    return _walk_away(i, (d + 2) % 4, neighbour, neighbour_edge, active, seen, stamp, out_q,
                      out_e, nb + 1, False)


@numba.njit(cache=True)
def _bandify(neighbour, neighbour_edge, is_quad, cutoff):
    """Fig. 4 of crash2000: strips as (quads, entry edges, lengths), leftover mask, passes."""
    m = len(is_quad)
    active = is_quad.copy()
    leftover = np.zeros(m, np.bool_)
    available = np.zeros(m, np.bool_)
    seen = np.full(m, -1, np.int64)
    n_quads = 0
    for i in range(m):
        if is_quad[i]:
            n_quads += 1
    out_q = np.empty(n_quads, np.int32)
    out_e = np.empty(n_quads, np.int8)
    out_len = np.empty(n_quads, np.int64)
    n_out = 0
    n_strips = 0
    tq0 = np.empty(n_quads + 1, np.int32)
    te0 = np.empty(n_quads + 1, np.int8)
    tq1 = np.empty(n_quads + 1, np.int32)
    te1 = np.empty(n_quads + 1, np.int8)
    # the bands of one pass, concatenated (they may overlap: grown on demand)
    cap = max(16, n_quads)
    band_q = np.empty(cap, np.int32)
    band_e = np.empty(cap, np.int8)
    band_start = np.empty(n_quads + 1, np.int64)
    band_len = np.empty(n_quads + 1, np.int64)
    stamp = 0
    passes = 0
    while True:
        for q in range(m):
            available[q] = active[q]
        n_bands = 0
        used = 0
        for i in range(m):
            if not (active[i] and available[i]):
                continue
            n0 = _walk(i, 0, neighbour, neighbour_edge, active, seen, stamp, tq0, te0)
            stamp += 1
            n1 = _walk(i, 1, neighbour, neighbour_edge, active, seen, stamp, tq1, te1)
            stamp += 1
            if n0 >= n1:
                n, bq, be = n0, tq0, te0
            else:
                n, bq, be = n1, tq1, te1
            if n < cutoff:
                active[i] = False
                leftover[i] = True
                continue
            if used + n > cap:
                while used + n > cap:
                    cap *= 2
                grown_q = np.empty(cap, np.int32)
                grown_e = np.empty(cap, np.int8)
                grown_q[:used] = band_q[:used]
                grown_e[:used] = band_e[:used]
                band_q, band_e = grown_q, grown_e
            for j in range(n):
                band_q[used + j] = bq[j]
                band_e[used + j] = be[j]
                available[bq[j]] = False
            band_start[n_bands] = used
            band_len[n_bands] = n
            used += n
            n_bands += 1
        if n_bands == 0:
            break
        passes += 1
        order = np.argsort(-band_len[:n_bands], kind="mergesort")
        for b in order:
            s, n = band_start[b], band_len[b]
            unchanged = True
            for j in range(n):
                if not active[band_q[s + j]]:
                    unchanged = False
                    break
            if not unchanged:
                break
            for j in range(n):
                q = band_q[s + j]
                active[q] = False
                out_q[n_out] = q
                out_e[n_out] = band_e[s + j]
                n_out += 1
            out_len[n_strips] = n
            n_strips += 1
    return out_q[:n_out].copy(), out_e[:n_out].copy(), out_len[:n_strips].copy(), leftover, passes


# --------------------------------------------------------------------------- triangle strips
@dataclass(eq=False)
class TriStrips:
    """Triangle strips with primitive restart.

    ``indices`` (L,) uint32: strips separated by ``restart``. ``n_strips``; ``n_vertices``: the
    indices that are not restart markers (vertices sent); ``n_triangles``: input triangles.
    """

    indices: np.ndarray
    n_strips: int
    n_vertices: int
    n_triangles: int
    restart: int = RESTART

    @property
    def mean_triangles_per_strip(self) -> float:
        """(vertices − 2·strips) / strips: triangles per strip as drawn, swaps included."""
        return (self.n_vertices - 2 * self.n_strips) / self.n_strips if self.n_strips else 0.0

    def triangle_list(self) -> np.ndarray:
        """(K, 3) int32 the non-degenerate triangles the strips draw, in GL winding order."""
        return unstripify(self.indices, self.restart)


def unstripify(indices, restart: int = RESTART) -> np.ndarray:
    """(K, 3) int32 triangles of ``GL_TRIANGLE_STRIP`` indices with primitive restart.

    Triangle i of a strip is (v_i, v_i+1, v_i+2) for even i and (v_i+1, v_i, v_i+2) for odd i
    (the winding OpenGL gives it); triangles with a repeated vertex (swaps) are dropped.
    """
    idx = np.asarray(indices, np.int64)
    if not len(idx):
        return np.zeros((0, 3), np.int32)
    is_restart = idx == restart
    strip_id = np.cumsum(is_restart)
    position = np.arange(len(idx)) - np.concatenate([[0], np.flatnonzero(is_restart) + 1])[strip_id]
    i = np.arange(len(idx) - 2)
    ok = (strip_id[i] == strip_id[i + 2]) & ~is_restart[i] & ~is_restart[i + 2]
    i = i[ok]
    odd = (position[i] % 2) == 1
    a = np.where(odd, idx[i + 1], idx[i])
    b = np.where(odd, idx[i], idx[i + 1])
    tris = np.stack([a, b, idx[i + 2]], axis=1)
    distinct = (tris[:, 0] != tris[:, 1]) & (tris[:, 1] != tris[:, 2]) & (tris[:, 0] != tris[:, 2])
    return tris[distinct].astype(np.int32)


def _meshopt():
    """(optimizeVertexCacheStrip, stripify, stripifyBound) from meshoptimizer's C library."""
    from meshoptimizer._loader import lib

    uint_p = ctypes.POINTER(ctypes.c_uint)
    size_t = ctypes.c_size_t
    cache = ctypes.CFUNCTYPE(None, uint_p, uint_p, size_t, size_t)(
        ("meshopt_optimizeVertexCacheStrip", lib))
    stripify = ctypes.CFUNCTYPE(size_t, uint_p, uint_p, size_t, size_t, ctypes.c_uint)(
        ("meshopt_stripify", lib))
    bound = ctypes.CFUNCTYPE(size_t, size_t)(("meshopt_stripifyBound", lib))
    return cache, stripify, bound


def tri_strips(triangles, vertex_count: int | None = None, restart: int = RESTART) -> TriStrips:
    """meshoptimizer's triangle strips of ``triangles`` ((K, 3) vertex indices).

    The triangles are first reordered by ``meshopt_optimizeVertexCacheStrip`` (the order the
    library recommends for stripping), then ``meshopt_stripify`` joins them into strips separated
    by ``restart``; swaps inside a strip are degenerate triangles. ``vertex_count`` defaults to
    max index + 1. Refuses (ValueError) arrays that are not (K, 3) non-negative integers below
    ``vertex_count``, triangles with a repeated vertex and a ``restart`` below ``vertex_count``.
    """
    t = np.asarray(triangles)
    if t.ndim != 2 or t.shape[1] != 3 or (t.size and t.dtype.kind not in "iu"):
        raise ValueError(f"triangles must be (K, 3) integer vertex indices, got shape {t.shape} "
                         f"dtype {t.dtype}")
    if not len(t):
        return TriStrips(np.zeros(0, np.uint32), 0, 0, 0, restart)
    if t.min() < 0:
        raise ValueError("triangles have negative vertex indices")
    n = int(t.max()) + 1 if vertex_count is None else int(vertex_count)
    if t.max() >= n:
        raise ValueError(f"triangles reference vertex {int(t.max())} but vertex_count is {n}")
    _check_restart(restart, n - 1)
    repeated = (t[:, 0] == t[:, 1]) | (t[:, 1] == t[:, 2]) | (t[:, 0] == t[:, 2])
    if repeated.any():
        raise ValueError(f"{int(repeated.sum())} triangles repeat a vertex, first "
                         f"{np.flatnonzero(repeated)[:5].tolist()}")
    cache, stripify, bound = _meshopt()
    uint_p = ctypes.POINTER(ctypes.c_uint)
    src = np.ascontiguousarray(t, dtype=np.uint32).ravel()
    ordered = np.empty_like(src)
    cache(ordered.ctypes.data_as(uint_p), src.ctypes.data_as(uint_p), len(src), n)
    out = np.empty(bound(len(src)), np.uint32)
    size = stripify(out.ctypes.data_as(uint_p), ordered.ctypes.data_as(uint_p), len(src), n,
                    restart)
    indices = out[:size].copy()
    markers = int((indices == restart).sum())
    return TriStrips(indices=indices, n_strips=markers + 1, n_vertices=len(indices) - markers,
                     n_triangles=len(t), restart=restart)
