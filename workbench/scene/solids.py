"""Faces and boundary surface of LS-DYNA solid meshes (hexahedra, pentahedra, tetrahedra).

The workbench draws surface meshes (:class:`workbench.scene.mesh.FEMesh`); a solid model is shown
by its *boundary surface*, the faces used by exactly one solid. This module extracts them, GL-free:
numpy for the face tables and bookkeeping and, for models of :data:`COMPILED_FROM` solids or
more, three small numba kernels (:mod:`workbench.scene.solid_kernels`) where a per-solid or
per-face loop beats numpy's temporaries (node-pattern check, signed volume) or sorting (the exact
shared-face count: counting sort by smallest node, O(F + N)). About 3 M hexahedra or 4 M
tetrahedra per second on 2 slow cores (``benchmarks/solid_faces_bench.py``). Smaller models use
the numpy versions of the same three steps, so that reading a small deck in a fresh process does
not import numba.

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

import numpy as np

__all__ = ["HEX", "PENTA", "TET", "SolidFaces", "boundary_surface", "solid_faces", "solid_kinds"]

TET, PENTA, HEX = 4, 6, 8  # kind codes = number of distinct nodes
#: From this many solids on, the compiled kernels (workbench.scene.solid_kernels) are used:
#: below it numpy is as quick, and a fresh process does not pay ``import numba`` (~0.5 s) and
#: the loading of the kernels for a small model.
COMPILED_FROM = 100_000

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
    s = np.ascontiguousarray(s, dtype=dtype)
    if len(s) >= COMPILED_FROM:
        from .solid_kernels import _kinds

        return _kinds(s)
    return _kinds_numpy(s)


def _kinds_numpy(s: np.ndarray) -> np.ndarray:
    """:func:`solid_kinds` in numpy: distinct nodes per row, then the pattern checks."""
    distinct = 1 + (np.diff(np.sort(s, axis=1), axis=1) != 0).sum(axis=1)
    kind = np.zeros(len(s), np.int8)
    kind[distinct == 8] = HEX
    kind[(distinct == 6) & (s[:, 4] == s[:, 5]) & (s[:, 6] == s[:, 7])] = PENTA
    kind[(distinct == 4) & (s[:, 3:4] == s[:, 4:]).all(axis=1)] = TET
    return kind


def _volume_and_multiplicity(n_solids: int):
    """(signed volume, face multiplicity) functions for a model of ``n_solids``: the compiled
    kernels from :data:`COMPILED_FROM` solids on, else the numpy versions."""
    if n_solids >= COMPILED_FROM:
        from .solid_kernels import _face_multiplicity, _signed_volume

        return _signed_volume, _face_multiplicity
    return _signed_volume_numpy, _face_multiplicity_numpy


def _face_multiplicity_numpy(faces: np.ndarray, n_nodes: int = 0) -> np.ndarray:
    """How many rows of ``faces`` have the same node set as each row (a triangle ``a b c c``
    is keyed ``-1 a b c``, so it never equals a quad): sorted keys, runs counted. ``n_nodes``
    is unused (the compiled kernel's signature)."""
    keys = faces.astype(np.int64)
    keys[keys[:, 3] == keys[:, 2], 3] = -1
    keys.sort(axis=1)
    order = np.lexsort(keys.T[::-1])
    ordered = keys[order]
    new = np.ones(len(keys), bool)
    new[1:] = (ordered[1:] != ordered[:-1]).any(axis=1)
    run = np.cumsum(new) - 1
    counts = np.bincount(run)
    mult = np.empty(len(keys), np.int32)
    mult[order] = counts[run]
    return mult


def _signed_volume_numpy(s: np.ndarray, nodes: np.ndarray, table: np.ndarray,
                         cols: np.ndarray) -> np.ndarray:
    """Signed volume x 6 of solids ``s`` bounded by the faces ``table``, as the compiled
    ``_signed_volume`` (divergence theorem about the mean of the distinct nodes ``cols``)."""
    p = nodes[s[:, cols]]
    p -= p.mean(axis=1, keepdims=True)
    points = np.zeros((len(s), 8, 3))
    points[:, cols] = p
    i0, i1, i2, i3 = table.T
    u = points[:, i2] - points[:, i0]
    w = points[:, i3] - points[:, i1]
    c = points[:, i0] + points[:, i1] + points[:, i2] + points[:, i3]
    return (c * np.cross(u, w)).sum(axis=(1, 2)) / 4.0


def solid_faces(solids: np.ndarray, nodes: np.ndarray) -> SolidFaces:
    """All faces of LS-DYNA solids, outward, with their solid, local number and boundary flag.

    ``solids`` (S, 8) 0-based node indices (hex, penta ``n1..n5 n5 n6 n6`` or tet
    ``n1..n4 n4 n4 n4 n4`` patterns), ``nodes`` (N, 3) coordinates (any unit). Returns a
    :class:`SolidFaces` with 6 faces per hex, 5 per penta and 4 per tet. Raises ``ValueError``
    for the inputs listed in the module docstring.
    """
    solids, nodes = _check_solids(solids, nodes)
    kind = solid_kinds(solids)
    volume, multiplicity = _volume_and_multiplicity(len(solids))
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
        neg = np.flatnonzero(volume(s, nodes, table, np.unique(table)) < 0)
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
    boundary = multiplicity(faces, len(nodes)) == 1
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
