"""Faces and boundary surface of LS-DYNA solid meshes (hexahedra, pentahedra, tetrahedra).

The workbench draws surface meshes (:class:`workbench.scene.mesh.FEMesh`); a solid model is shown
by its *boundary surface*, the faces used by exactly one solid. This module extracts them, GL-free:
numpy for the face tables and bookkeeping, three small numba kernels where a per-solid or
per-face loop beats numpy's temporaries (node-pattern check, signed volume) or sorting (the exact
shared-face count: counting sort by smallest node, O(F + N)). About 3 M hexahedra or 4 M
tetrahedra per second on 2 slow cores (``benchmarks/solid_faces_bench.py``).

Input
-----
``solids``: (S, 8) integer array of **0-based node indices** in the LS-DYNA ``*ELEMENT_SOLID``
layout, one of three node patterns per row (``n1 .. n8`` are the eight columns):

* hexahedron   ``n1 n2 n3 n4 n5 n6 n7 n8``, all eight distinct; ``n1 n2 n3 n4`` is one face
  ("bottom"), ``n5 .. n8`` the opposite face with ``n5`` joined to ``n1``, ``n6`` to ``n2`` ...;
* pentahedron  ``n1 n2 n3 n4 n5 n5 n6 n6`` (six distinct nodes): quad ``n1 n2 n3 n4``,
  triangles ``n1 n2 n5`` and ``n3 n4 n6``, quads ``n2 n3 n6 n5`` and ``n4 n1 n5 n6``;
* tetrahedron  ``n1 n2 n3 n4 n4 n4 n4 n4`` (four distinct nodes).

``nodes``: (N, 3) float coordinates (any length unit; only the sign of volumes is used, so the
result does not depend on the unit). ``parts``: optional (S,) integer part id per solid.

Faces
-----
Local face numbers (``local``) follow the hexahedron; a pentahedron keeps the numbers of the hex
faces that survive its repeated nodes (its collapsed ``n5 n5 n6 n6`` face 5 is dropped: it has
zero area), a tetrahedron has its own four:

====  ===================  ===================  ==================
face  hexahedron           pentahedron          tetrahedron
====  ===================  ===================  ==================
0     n1 n4 n3 n2          n1 n4 n3 n2          n1 n3 n2
1     n1 n2 n6 n5          n1 n2 n5 (tri)       n1 n2 n4
2     n2 n3 n7 n6          n2 n3 n6 n5          n2 n3 n4
3     n3 n4 n8 n7          n3 n4 n6 (tri)       n1 n4 n3
4     n4 n1 n5 n8          n4 n1 n5 n6
5     n5 n6 n7 n8
====  ===================  ===================  ==================

The table is the winding for a solid of **positive** signed volume, i.e. one whose face
``n1 n2 n3 n4`` (tet: ``n1 n2 n3``) turns counter-clockwise seen from the side of ``n5``
(tet: ``n4``). Each solid's signed volume is computed from its faces (divergence theorem,
``sum((c_f - g) . A_f) / 3`` with face vector areas ``A_f`` and centroids); a solid with negative
volume (an "inverted" numbering) gets every face reversed, so all faces are **outward**:
counter-clockwise seen from outside the solid, right-hand normal pointing out. A solid of exactly
zero volume keeps the table's winding.

Output faces follow the FEMesh convention: (F, 4) int32, a triangle repeats its third node
(``e[3] == e[2]``). Faces are listed solid by solid, in local-face order.

Shared faces are found exactly, independent of node order and rotation: the key of a face is
its sorted distinct node ids; a triangle and a quad are never the same face even when they share
three nodes. A face is on the boundary when its key occurs once among all faces of all solids.

Refused (``ValueError``, one message naming the first offending rows): ``solids`` not (S, 8)
of an integer dtype, ``nodes`` not (N, 3) or with non-finite coordinates, node indices negative
or ``>= N`` (or beyond int32), ``parts`` not (S,) integers, and any solid whose node pattern is
none of the three above (e.g. a pyramid, a hex with one repeated node, a tet written
``n1 n2 n3 n3 n4 n4 n4 n4``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np

__all__ = ["HEX", "PENTA", "TET", "SolidFaces", "boundary_surface", "solid_faces", "solid_kinds"]

TET, PENTA, HEX = 4, 6, 8  # kind codes = number of distinct nodes

# Face tables in column indices of the 8-column LS-DYNA row, outward for positive volume.
_HEX_FACES = np.array([[0, 3, 2, 1], [0, 1, 5, 4], [1, 2, 6, 5],
                       [2, 3, 7, 6], [3, 0, 4, 7], [4, 5, 6, 7]], np.intp)
_PENTA_FACES = np.array([[0, 3, 2, 1], [0, 1, 4, 4], [1, 2, 6, 4],
                         [2, 3, 6, 6], [3, 0, 4, 6]], np.intp)
_TET_FACES = np.array([[0, 2, 1, 1], [0, 1, 3, 3], [1, 2, 3, 3], [0, 3, 2, 2]], np.intp)
_TABLES = {HEX: _HEX_FACES, PENTA: _PENTA_FACES, TET: _TET_FACES}
_LOCAL = {HEX: np.arange(6, dtype=np.int8), PENTA: np.arange(5, dtype=np.int8),
          TET: np.arange(4, dtype=np.int8)}
# Reversing a face keeps its first node: quad a b c d -> a d c b, triangle a b c c -> a c b b.
_REV_QUAD = np.array([0, 3, 2, 1], np.intp)
_REV_TRI = np.array([0, 2, 1, 1], np.intp)


@dataclass(frozen=True, eq=False)
class SolidFaces:
    """Every face of every solid, once per solid (see the module docstring for conventions).

    ``faces`` (F, 4) int32 node indices, outward, triangle repeats its third node;
    ``element`` (F,) int64 index of the solid (row of ``solids``); ``local`` (F,) int8 face
    number within the solid; ``boundary`` (F,) bool, True where no other solid has that face.
    """

    faces: np.ndarray
    element: np.ndarray
    local: np.ndarray
    boundary: np.ndarray

    def __len__(self) -> int:
        return len(self.faces)


def _check_solids(solids, nodes) -> tuple[np.ndarray, np.ndarray]:
    nodes = np.asarray(nodes)
    if nodes.ndim != 2 or nodes.shape[1] != 3 or not (
            np.issubdtype(nodes.dtype, np.floating) or np.issubdtype(nodes.dtype, np.integer)):
        raise ValueError(f"nodes must be a (N, 3) float array, got shape {nodes.shape} "
                         f"dtype {nodes.dtype}")
    nodes = np.ascontiguousarray(nodes, dtype=np.float64)
    if not np.isfinite(nodes).all():
        bad = np.flatnonzero(~np.isfinite(nodes).all(axis=1))
        raise ValueError(f"nodes: {len(bad)} non-finite coordinates, first rows {bad[:5].tolist()}")
    solids = np.asarray(solids)
    if solids.ndim != 2 or solids.shape[1] != 8:
        raise ValueError(f"solids must be (S, 8) node indices in the LS-DYNA *ELEMENT_SOLID "
                         f"layout, got shape {solids.shape}")
    if not np.issubdtype(solids.dtype, np.integer):
        raise ValueError(f"solids must hold integer node indices, got dtype {solids.dtype}")
    n = len(nodes)
    if n > np.iinfo(np.int32).max:
        raise ValueError(f"{n} nodes: node indices must fit int32")
    if solids.size:
        lo, hi = solids.min(), solids.max()
        if lo < 0 or hi >= n:
            bad = np.flatnonzero(((solids < 0) | (solids >= n)).any(axis=1))
            raise ValueError(
                f"solids: {len(bad)} solids reference node indices outside 0..{n - 1}, first "
                f"{[(int(i), solids[i].tolist()) for i in bad[:5]]}")
    return np.ascontiguousarray(solids, dtype=np.int32), nodes


def solid_kinds(solids: np.ndarray) -> np.ndarray:
    """(S,) int8 kind per solid: :data:`HEX` (8), :data:`PENTA` (6), :data:`TET` (4), 0 if none.

    ``solids`` is an (S, 8) integer array in the LS-DYNA layout (not range-checked here).
    """
    s = np.asarray(solids)
    if s.ndim != 2 or s.shape[1] != 8 or not np.issubdtype(s.dtype, np.integer):
        raise ValueError(f"solids must be (S, 8) integer node indices, got {s.shape} {s.dtype}")
    dtype = s.dtype if s.dtype in (np.int32, np.int64) else np.int64
    return _kinds(np.ascontiguousarray(s, dtype=dtype))


@numba.njit(cache=True, nogil=True)
def _kinds(s):  # pragma: no cover - compiled
    kind = np.zeros(s.shape[0], np.int8)
    for e in range(s.shape[0]):
        distinct = 0
        for i in range(8):
            new = True
            for j in range(i):
                if s[e, j] == s[e, i]:
                    new = False
                    break
            if new:
                distinct += 1
        if distinct == 8:
            kind[e] = HEX
        elif distinct == 6 and s[e, 4] == s[e, 5] and s[e, 6] == s[e, 7]:
            kind[e] = PENTA
        elif (distinct == 4 and s[e, 3] == s[e, 4] and s[e, 3] == s[e, 5]
              and s[e, 3] == s[e, 6] and s[e, 3] == s[e, 7]):
            kind[e] = TET
    return kind


@numba.njit(cache=True, nogil=True, inline="always")
def _face_key(faces, i):  # pragma: no cover - compiled
    """Sorted node ids ``a < b < c < d`` of face ``i``; ``d = -1`` for a triangle."""
    a = faces[i, 0]
    b = faces[i, 1]
    c = faces[i, 2]
    d = faces[i, 3]
    if a > b:
        a, b = b, a
    if d == c:  # triangle a b c c
        if b > c:
            b, c = c, b
        if a > b:
            a, b = b, a
        d = -1
    else:  # sorting network (0,1) (2,3) (0,2) (1,3) (1,2)
        if c > d:
            c, d = d, c
        if a > c:
            a, c = c, a
        if b > d:
            b, d = d, b
        if b > c:
            b, c = c, b
    return a, b, c, d


@numba.njit(cache=True, nogil=True)
def _face_multiplicity(faces, n_nodes):  # pragma: no cover - compiled
    """How many rows of ``faces`` have the same sorted node set as each row, exactly.

    Faces are bucketed by their smallest node (counting sort, O(F + N)) with the rest of their
    key (``b * (N + 1) + c`` and ``d``) stored in bucket order; within a bucket the keys are
    sorted (insertion sort for small buckets, a stable two-key sort for large ones) and equal
    runs counted.
    """
    nf = faces.shape[0]
    m = np.int64(n_nodes) + 1
    start = np.zeros(n_nodes + 1, np.int64)
    for i in range(nf):
        a, b, c, d = _face_key(faces, i)
        start[a + 1] += 1
    for v in range(n_nodes):
        start[v + 1] += start[v]
    fill = start[:-1].copy()
    order = np.empty(nf, np.int64)
    bk1 = np.empty(nf, np.int64)
    bk2 = np.empty(nf, np.int32)
    for i in range(nf):
        a, b, c, d = _face_key(faces, i)
        p = fill[a]
        fill[a] = p + 1
        order[p] = i
        bk1[p] = b * m + c
        bk2[p] = d
    mult = np.ones(nf, np.int32)
    for v in range(n_nodes):
        s = start[v]
        e = start[v + 1]
        size = e - s
        if size < 2:
            continue
        if size <= 64:  # insertion sort of the bucket by (k1, k2), then count the runs
            for p in range(s + 1, e):
                x1 = bk1[p]
                x2 = bk2[p]
                xo = order[p]
                q = p - 1
                while q >= s and (bk1[q] > x1 or (bk1[q] == x1 and bk2[q] > x2)):
                    bk1[q + 1] = bk1[q]
                    bk2[q + 1] = bk2[q]
                    order[q + 1] = order[q]
                    q -= 1
                bk1[q + 1] = x1
                bk2[q + 1] = x2
                order[q + 1] = xo
            r = s
            while r < e:
                t = r + 1
                while t < e and bk1[t] == bk1[r] and bk2[t] == bk2[r]:
                    t += 1
                if t - r > 1:
                    for u in range(r, t):
                        mult[order[u]] = t - r
                r = t
        else:
            a1 = bk1[s:e]
            a2 = bk2[s:e]
            o = np.argsort(a2, kind="mergesort")
            o = o[np.argsort(a1[o], kind="mergesort")]
            r = 0
            while r < size:
                t = r + 1
                while t < size and a1[o[t]] == a1[o[r]] and a2[o[t]] == a2[o[r]]:
                    t += 1
                for u in range(r, t):
                    mult[order[s + o[u]]] = t - r
                r = t
    return mult


@numba.njit(cache=True, nogil=True)
def _signed_volume(s, nodes, table, cols):  # pragma: no cover - compiled
    """Signed volume x 6 of solids ``s`` (k, 8) bounded by the faces ``table`` (nf, 4).

    Divergence theorem about the solid's centroid ``g`` (mean of the distinct nodes ``cols``):
    ``6 V = 2 sum_f (c_f - g) . A_f`` with ``2 A_f = (p2 - p0) x (p3 - p1)`` (the exact vector
    area of a quad, and of a triangle ``p0 p1 p2 p2``) and ``4 c_f = p0 + p1 + p2 + p3``, a point
    of the face's plane when it is planar (exact there); only the sign is used.
    """
    k = s.shape[0]
    vol = np.empty(k)
    nc = cols.shape[0]
    pts = np.empty((8, 3))
    for e in range(k):
        gx = 0.0
        gy = 0.0
        gz = 0.0
        for c in cols:
            v = s[e, c]
            gx += nodes[v, 0]
            gy += nodes[v, 1]
            gz += nodes[v, 2]
        gx /= nc
        gy /= nc
        gz /= nc
        for c in cols:
            v = s[e, c]
            pts[c, 0] = nodes[v, 0] - gx
            pts[c, 1] = nodes[v, 1] - gy
            pts[c, 2] = nodes[v, 2] - gz
        acc = 0.0
        for f in range(table.shape[0]):
            i0 = table[f, 0]
            i1 = table[f, 1]
            i2 = table[f, 2]
            i3 = table[f, 3]
            ux = pts[i2, 0] - pts[i0, 0]
            uy = pts[i2, 1] - pts[i0, 1]
            uz = pts[i2, 2] - pts[i0, 2]
            wx = pts[i3, 0] - pts[i1, 0]
            wy = pts[i3, 1] - pts[i1, 1]
            wz = pts[i3, 2] - pts[i1, 2]
            cx = pts[i0, 0] + pts[i1, 0] + pts[i2, 0] + pts[i3, 0]
            cy = pts[i0, 1] + pts[i1, 1] + pts[i2, 1] + pts[i3, 1]
            cz = pts[i0, 2] + pts[i1, 2] + pts[i2, 2] + pts[i3, 2]
            acc += cx * (uy * wz - uz * wy) + cy * (uz * wx - ux * wz) + cz * (ux * wy - uy * wx)
        vol[e] = acc / 4.0
    return vol


def solid_faces(solids: np.ndarray, nodes: np.ndarray) -> SolidFaces:
    """All faces of LS-DYNA solids, outward, with their solid, local number and boundary flag.

    ``solids`` (S, 8) 0-based node indices (hex, penta ``n1..n5 n5 n6 n6`` or tet
    ``n1..n4 n4 n4 n4 n4`` patterns), ``nodes`` (N, 3) coordinates (any unit). Returns a
    :class:`SolidFaces` with 6 faces per hex, 5 per penta and 4 per tet. Raises ``ValueError``
    for the inputs listed in the module docstring.
    """
    solids, nodes = _check_solids(solids, nodes)
    kind = solid_kinds(solids)
    bad = np.flatnonzero(kind == 0)
    if len(bad):
        raise ValueError(
            f"solids: {len(bad)} solids match none of the LS-DYNA node patterns (hexahedron "
            f"n1..n8 distinct, pentahedron n1 n2 n3 n4 n5 n5 n6 n6, tetrahedron n1 n2 n3 n4 n4 "
            f"n4 n4 n4), first {[(int(i), solids[i].tolist()) for i in bad[:5]]}")
    nface = np.array([0, 0, 0, 0, 4, 0, 5, 0, 6], np.int64)[kind]
    offset = np.zeros(len(solids) + 1, np.int64)
    np.cumsum(nface, out=offset[1:])
    total = int(offset[-1])
    faces = np.empty((total, 4), np.int32)
    element = np.empty(total, np.int64)
    local = np.empty(total, np.int8)
    uniform = len(solids) > 0 and (kind == kind[0]).all()
    for k, table in _TABLES.items():
        if uniform:
            if k != kind[0]:
                continue
            ids = None
            s = solids
        else:
            ids = np.flatnonzero(kind == k)
            if not len(ids):
                continue
            s = solids[ids]
        f = s[:, table]  # (n, nf, 4)
        neg = np.flatnonzero(_signed_volume(s, nodes, table, np.unique(table)) < 0)
        if len(neg):
            rev = np.where((table[:, 3] == table[:, 2])[:, None], _REV_TRI, _REV_QUAD)
            fn = f[neg]
            f[neg] = np.take_along_axis(fn, np.broadcast_to(rev, fn.shape), axis=2)
        nf = len(table)
        if ids is None:
            faces[:] = f.reshape(-1, 4)
            element[:] = np.repeat(np.arange(len(s), dtype=np.int64), nf)
            local[:] = np.tile(_LOCAL[k], len(s))
        else:
            pos = (offset[ids][:, None] + np.arange(nf)).ravel()
            faces[pos] = f.reshape(-1, 4)
            element[pos] = np.repeat(ids.astype(np.int64), nf)
            local[pos] = np.tile(_LOCAL[k], len(s))
    boundary = _face_multiplicity(faces, len(nodes)) == 1
    return SolidFaces(faces, element, local, boundary)


def boundary_surface(solids: np.ndarray, nodes: np.ndarray, parts: np.ndarray | None = None,
                     all_faces: bool = False) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The outward boundary faces of a solid mesh as FEMesh arrays.

    Returns ``(elements (F, 4) int32, parts (F,) int32, element_of (F,) int64)``: the faces used
    by exactly one solid (or, with ``all_faces``, every face once per solid, 6 per hex, 5 per
    penta, 4 per tet), each with its solid's part id (``parts`` (S,) integers, default 0) and
    the index of its solid, so element fields of the solids colour the faces
    (``field[element_of]``). ``FEMesh(nodes, elements, parts)`` draws the result. Refusals as
    :func:`solid_faces`, plus ``parts`` that is not (S,) integers.
    """
    n_solids = np.shape(solids)[0] if np.ndim(solids) == 2 else None
    if parts is not None:
        parts = np.asarray(parts)
        if (parts.ndim != 1 or (n_solids is not None and len(parts) != n_solids)
                or not np.issubdtype(parts.dtype, np.integer)):
            raise ValueError(f"parts must be ({n_solids},) integer part ids, got shape "
                             f"{parts.shape} dtype {parts.dtype}")
    sf = solid_faces(solids, nodes)
    if all_faces:
        elements, element_of = sf.faces, sf.element
    else:
        elements, element_of = sf.faces[sf.boundary], sf.element[sf.boundary]
    if parts is None:
        face_parts = np.zeros(len(elements), np.int32)
    else:
        face_parts = parts.astype(np.int32, copy=False)[element_of]
    return elements, face_parts, element_of
