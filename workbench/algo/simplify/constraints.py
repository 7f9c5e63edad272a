"""Which vertices of the input never move, and along which edges the others may slide.

Feature edges (a crease between two faces of one part on a long enough connected run of
creases), the common boundaries of parts and, on request, open boundary edges are the
*constrained* edges, kept as polylines: a vertex on two of them only slides along them, a
vertex on one or on three or more, or where its polyline turns by more than ``feature_deg``, is
a corner and never moves. Nor do the vertices of zero-area faces or of non-manifold edges.

The common boundary of two parts (edges with one face of each part) is a feature polyline of
both. A vertex inside it -- used by exactly those two parts, on exactly two constrained edges
which are both common edges, on no open edge -- slides along it in both parts at once: the
half-edge collapse u → v along the common boundary is applied to the faces of both parts
together, so the shared vertex buffer stays shared and no crack opens. Such a collapse must
also keep the link condition within each part on its own, and re-certifies the original
triangles of both parts, each against the faces of its own part and its own part's tolerance.
Where three or more parts meet, where the common boundary ends or turns by more than
``feature_deg``, or where a part's own boundary or feature lines meet it, the vertex is a
corner and stays.

Edges are identified by their undirected key ``min * N + max`` over N vertices.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .inputs import _group_rows
from .state import Constraints


class _Edges(NamedTuple):
    """Per face corner k, the edge to the next corner."""

    a: np.ndarray         # (3 M,) int64 its first vertex
    b: np.ndarray         # (3 M,) int64 its second vertex
    face: np.ndarray      # (3 M,) its face
    key: np.ndarray       # (3 M,) int64 undirected key ``min * n_vert + max``
    forward: np.ndarray   # (3 M,) bool: it runs from the lower vertex


def _constraints(V, F, fpart, n_origin, degenerate, tol_of_label, feature_deg: float,
                 keep_boundary: bool, slide_shared: bool,
                 feature_min_length: float | None) -> Constraints:
    """The fixed vertices and the constrained edges of the faces F (parts ``fpart``, unit
    normals ``n_origin``, zero-area mask ``degenerate``) over vertices V, for the arguments of
    :func:`~workbench.algo.simplify.hausdorff_decimate` (``tol_of_label`` each part's
    tolerance, in the order of the sorted part labels)."""
    n_vert = len(V)
    fixed = np.zeros(n_vert, bool)
    _, fpart_index = np.unique(fpart, return_inverse=True)
    n_labels = len(tol_of_label)
    vp = np.unique(F.ravel().astype(np.int64) * n_labels + np.repeat(fpart_index.ravel(), 3))
    parts_at = np.bincount(vp // n_labels, minlength=n_vert)
    fixed[F[degenerate].ravel()] = True

    edges = _edges_of(F, n_vert)
    a, b, key = edges.a, edges.b, edges.key
    edge_part = np.repeat(fpart, 3).astype(np.int64)
    # count faces per edge over all parts (non-manifold) and per (part, edge)
    _, ui, uc = np.unique(key, return_inverse=True, return_counts=True)
    ui = ui.ravel()
    nonmanifold = uc[ui] > 2
    fixed[a[nonmanifold]] = True
    fixed[b[nonmanifold]] = True
    pi, _ = _group_rows(np.stack([edge_part, key], 1))
    per_part = np.bincount(pi)[pi]
    constrained = np.zeros(len(key), bool)
    if keep_boundary:
        constrained |= per_part == 1
    two = np.flatnonzero((per_part == 2) & ~nonmanifold)
    face_tol = tol_of_label[fpart_index]
    constrained |= _creases(V, edges, edge_part, two, n_origin, face_tol, feature_deg,
                            feature_min_length)
    # the common boundary of two parts (edges with one face of each) is always a polyline
    common = (uc[ui] == 2) & (per_part == 1)
    constrained |= common
    ckeys = np.unique(key[constrained])
    cdeg = _key_degree(ckeys, n_vert)
    fixed[_turning_corners(V, ckeys, cdeg, feature_deg)] = True
    fixed[(parts_at > 1) & ~(_sliding_shared(key, common, uc[ui] == 1, cdeg, parts_at)
                             & bool(slide_shared))] = True
    return Constraints(fixed, ckeys, cdeg)


def _edges_of(F: np.ndarray, n_vert: int) -> _Edges:
    """Per face corner k, the edge to the next corner: its two vertices a, b, the face, the
    undirected key ``min * n_vert + max`` and whether it runs from the lower vertex."""
    a = F.ravel().astype(np.int64)
    b = F[:, [1, 2, 0]].ravel().astype(np.int64)
    face = np.repeat(np.arange(len(F)), 3)
    key = np.minimum(a, b) * n_vert + np.maximum(a, b)
    return _Edges(a, b, face, key, a < b)


def _creases(V, edges: _Edges, edge_part, two, n_origin, face_tol, feature_deg: float,
             feature_min_length: float | None) -> np.ndarray:
    """(3 M,) bool: the feature edges among the edges ``two`` (each with exactly two faces of
    one part): the angle between the normals of their faces, oriented by the winding, above
    ``feature_deg``, on a connected run of such edges at least ``feature_min_length`` times the
    tolerance (``face_tol`` per face) long (None: any run)."""
    crease_mask = np.zeros(len(edges.key), bool)
    if len(two) == 0:
        return crease_mask
    key, face, forward = edges.key, edges.face, edges.forward
    order = two[np.lexsort((key[two], edge_part[two]))]
    g1, g2 = order[0::2], order[1::2]
    n1, n2 = n_origin[face[g1]], n_origin[face[g2]]
    cos = np.einsum("ij,ij->i", n1, n2)
    cos = np.where(forward[g1] != forward[g2], cos, -cos)
    crease = cos < np.cos(np.radians(float(feature_deg))) - 1e-12
    if feature_min_length is not None and crease.any():
        runs = g1[crease]
        reach = float(feature_min_length) * face_tol[face[runs]]
        crease[np.flatnonzero(crease)[~_long_chains(edges.a[runs], edges.b[runs], V,
                                                    reach)]] = False
    crease_mask[g1[crease]] = True
    crease_mask[g2[crease]] = True
    return crease_mask


def _long_chains(a: np.ndarray, b: np.ndarray, V: np.ndarray, reach: np.ndarray) -> np.ndarray:
    """(E,) bool: whether each edge (a, b) lies on a connected set of these edges (joined at
    shared vertices) whose summed length is at least its ``reach``."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    nodes, inverse = np.unique(np.r_[a, b], return_inverse=True)
    ia, ib = inverse[:len(a)], inverse[len(a):]
    graph = coo_matrix((np.ones(len(a)), (ia, ib)), shape=(len(nodes), len(nodes)))
    _, label = connected_components(graph, directed=False)
    length = np.linalg.norm(V[a] - V[b], axis=1)
    total = np.bincount(label[ia], weights=length)
    return total[label[ia]] >= reach


def _turning_corners(V: np.ndarray, ckeys: np.ndarray, cdeg: np.ndarray,
                     feature_deg: float) -> np.ndarray:
    """The vertices on two constrained edges (keys ``ckeys``, ``cdeg`` per vertex) where their
    polyline turns by more than ``feature_deg``; coincident vertices (zero-length edges) count
    as such a corner."""
    n_vert = len(cdeg)
    lo_v, hi_v = ckeys // n_vert, ckeys % n_vert
    ends = np.concatenate([lo_v, hi_v])
    others = np.concatenate([hi_v, lo_v])
    on_line = cdeg[ends] == 2
    ends, others = ends[on_line], others[on_line]
    order = np.argsort(ends, kind="stable")
    ends, others = ends[order], others[order]
    if len(ends) == 0:
        return ends
    mid = ends[0::2]
    d1 = V[others[0::2]] - V[mid]
    d2 = V[others[1::2]] - V[mid]
    # the turn is 180° minus the angle between the two edges seen from the vertex
    lengths = np.linalg.norm(d1, axis=1) * np.linalg.norm(d2, axis=1)
    cos_turn = -np.einsum("ij,ij->i", d1, d2) / np.where(lengths > 0, lengths, 1.0)
    cos_turn[lengths == 0] = -1.0
    return mid[cos_turn < np.cos(np.radians(float(feature_deg))) - 1e-12]


def _sliding_shared(key, common, union_boundary, cdeg, parts_at) -> np.ndarray:
    """(N,) True for the vertices that may slide along the common boundary of two parts:
    used by exactly two parts, on exactly two constrained edges which are both common-boundary
    edges (one face of each part), and on no edge with a single face over all parts. Every
    other vertex used by several parts is a corner of the part structure."""
    n_vert = len(cdeg)
    common_deg = _key_degree(np.unique(key[common]), n_vert)
    open_deg = _key_degree(np.unique(key[union_boundary]), n_vert)
    return (parts_at == 2) & (cdeg == 2) & (common_deg == 2) & (open_deg == 0)


def _key_degree(keys: np.ndarray, n_vert: int) -> np.ndarray:
    """(N,) int32 how many of the undirected edges ``keys`` (``min * n_vert + max``, each once)
    each vertex is on."""
    return (np.bincount(keys // n_vert, minlength=n_vert)
            + np.bincount(keys % n_vert, minlength=n_vert)).astype(np.int32)
