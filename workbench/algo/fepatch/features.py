"""Feature lines, feature-divided patches and least-squares planar subpatches (fe2003 §3.1-3.2).

Rose & Ertl cut each FE component along its feature lines into patches and then split every
patch into nearly planar subpatches. This module computes, GL-free and in float64:

* :func:`feature_edges` -- the unique element edges (as
  :func:`workbench.scene.derived.unique_edges`) with a kind each: outer boundary (G0), angular edge
  (G1) or closing edge that completes a G1 line which ends in the middle of a surface;
* :func:`patches` -- connected components of elements joined across non-feature edges;
* :func:`planar_subpatches` -- region growing inside each patch; every subpatch keeps all its
  nodes within a distance ``d`` of the least-squares plane through them.

Inputs follow the mesh conventions: ``elements`` (M, 4) integer node indices (a triangle repeats
its third node), ``coords`` (N, 3) float64 in model units. G2 (curvature) features are not
detected explicitly, as in the paper: the planar subpatches pick them up implicitly.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components, dijkstra

from ...scene.derived import as_coords, as_elements, element_normals, unique_edges

__all__ = [
    "CLOSING",
    "G0",
    "G1",
    "SMOOTH",
    "FeatureEdges",
    "element_adjacency",
    "feature_edges",
    "patches",
    "planar_subpatches",
]

SMOOTH, G0, G1, CLOSING = 0, 1, 2, 3
KIND_NAMES = {SMOOTH: "smooth", G0: "G0", G1: "G1", CLOSING: "closing"}

_NEXT = np.array([1, 2, 3, 0])
# Cosines are compared with this slack, so that rounding in the normals does not flip an edge
# whose angle lies exactly on the threshold.
_COS_TOL = 1e-12


@dataclass(frozen=True, eq=False)
class FeatureEdges:
    """The unique element edges of a mesh and the feature kind of each.

    ``edges`` (E, 2) int32: rows (lo, hi) sorted lexicographically, exactly
    :func:`~workbench.scene.derived.unique_edges` of the elements. ``kind`` (E,) int8: one of
    :data:`SMOOTH`, :data:`G0`, :data:`G1`, :data:`CLOSING`. ``n_adjacent`` (E,) int32: number
    of element sides on each edge. ``angle_deg`` (E,) float64: angle between the two adjacent
    element normals in degrees (after orienting the second like the first, see
    :func:`feature_edges`); NaN where the edge does not have exactly two adjacent elements with
    non-zero normals. ``alpha_g1_deg``: the G1 threshold used, in degrees.
    """

    edges: np.ndarray
    kind: np.ndarray
    n_adjacent: np.ndarray
    angle_deg: np.ndarray
    alpha_g1_deg: float

    @property
    def feature(self) -> np.ndarray:
        """(E,) bool: edges of any feature kind (G0, G1 or closing)."""
        return self.kind != SMOOTH

    def of_kind(self, *kinds: int) -> np.ndarray:
        """(K, 2) int32 edges whose kind is one of ``kinds``."""
        return self.edges[np.isin(self.kind, np.asarray(kinds, np.int8))]

    def counts(self) -> dict[str, int]:
        """Number of edges per kind name ("smooth", "G0", "G1", "closing")."""
        return {name: int(np.count_nonzero(self.kind == k)) for k, name in KIND_NAMES.items()}


def _edge_keys(edges: np.ndarray) -> np.ndarray:
    return (edges[:, 0].astype(np.int64) << 32) | edges[:, 1].astype(np.int64)


def _incidence(e: np.ndarray, edges: np.ndarray):
    """Element sides: (element, unique edge id, traversed lo -> hi) per non-zero-length side."""
    u = e.ravel()
    v = e[:, _NEXT].ravel()
    keep = u != v
    elem = np.repeat(np.arange(len(e), dtype=np.int64), 4)[keep]
    u, v = u[keep].astype(np.int64), v[keep].astype(np.int64)
    keys = (np.minimum(u, v) << 32) | np.maximum(u, v)
    edge_id = np.searchsorted(_edge_keys(edges), keys)
    return elem, edge_id, u < v


def _check_angle(alpha_g1_deg) -> float:
    alpha = float(alpha_g1_deg)
    if not (0.0 <= alpha <= 180.0):
        raise ValueError(f"alpha_g1_deg must be within [0, 180] degrees, got {alpha_g1_deg!r}")
    return alpha


def feature_edges(elements, coords, alpha_g1_deg: float = 12.0, *,
                  close_lines: bool = True) -> FeatureEdges:
    """Classify every unique element edge as smooth, G0, G1 or closing (fe2003 §3.1).

    * **G0** -- an edge with exactly one adjacent element side (outer boundary).
    * **G1** -- an edge with three or more adjacent element sides (non-manifold), or with two
      whose element normals differ by more than ``alpha_g1_deg`` degrees. FE shells are often
      wound inconsistently, so the second normal is first turned to the first element's
      orientation, read from the topology: two elements are wound alike when they traverse the
      shared edge in opposite directions. An edge next to an element with a zero normal
      (degenerate, collinear nodes) gets no angle and is smooth.
    * **CLOSING** (only with ``close_lines``) -- edges added to complete open G1 lines. A
      *dangling end* is a node with exactly one feature edge (boundary nodes always have two G0
      edges, so no boundary node is one). Ends are processed in node order; an end that an
      earlier closing already connected is skipped. From an end:

      1. the *line* is the chain of nodes reached by walking back along the feature edges
         while the nodes have exactly two of them, plus the node where it stops (a junction or
         another end); the *targets* are all other nodes on feature edges, or, when there are
         none (a single open line on a closed surface), the far end of the line if it dangles;
      2. greedy walk: among the smooth edges at the current node whose other node is not on
         the line, take the one with the largest normal angle, as long as that angle exceeds
         ``alpha_g1_deg / 2``; mark it CLOSING, add its far node to the line, and stop when
         that node is a target;
      3. otherwise, the shortest path (Dijkstra over edge lengths, not through line nodes)
         from the current node to the nearest target; its smooth edges become CLOSING. When no
         target can be reached the line stays open.

    ``coords`` (N, 3) float64 in model units; the angle in degrees, within [0, 180]. Refused:
    elements or coordinates that are not of the mesh conventions, non-finite coordinates, an
    angle outside [0, 180].
    """
    e = as_elements(elements)
    c = as_coords(coords, e)
    alpha = _check_angle(alpha_g1_deg)
    edges = unique_edges(e)
    n_edges = len(edges)
    elem, edge_id, forward = _incidence(e, edges)
    n_adj = np.bincount(edge_id, minlength=n_edges).astype(np.int32)

    normals = element_normals(e, c)
    has_normal = np.einsum("ij,ij->i", normals, normals) > 0.5
    angle = np.full(n_edges, np.nan)
    order = np.argsort(edge_id, kind="stable")
    sid = edge_id[order]
    first = np.flatnonzero(np.r_[True, sid[1:] != sid[:-1]])
    two = first[n_adj[sid[first]] == 2]
    f, g = elem[order[two]], elem[order[two + 1]]
    agree = forward[order[two]] != forward[order[two + 1]]
    cos = np.einsum("ij,ij->i", normals[f], normals[g])
    cos = np.clip(np.where(agree, cos, -cos), -1.0, 1.0)
    ok = has_normal[f] & has_normal[g]
    angle[sid[two[ok]]] = np.degrees(np.arccos(cos[ok]))

    kind = np.full(n_edges, SMOOTH, np.int8)
    kind[n_adj == 1] = G0
    kind[n_adj >= 3] = G1
    cos_limit = np.cos(np.radians(alpha)) - _COS_TOL
    sharp = np.zeros(n_edges, bool)
    sharp[sid[two[ok]]] = cos[ok] < cos_limit
    kind[sharp] = G1

    if close_lines and np.any(kind == G1):
        _close_lines(edges, kind, angle, c, alpha)
    return FeatureEdges(edges=edges, kind=kind, n_adjacent=n_adj, angle_deg=angle,
                        alpha_g1_deg=alpha)


def _close_lines(edges: np.ndarray, kind: np.ndarray, angle: np.ndarray, coords: np.ndarray,
                 alpha: float) -> None:
    """Mark CLOSING edges in ``kind`` (in place) from every dangling end; see
    :func:`feature_edges`."""
    n_nodes = len(coords)
    lo, hi = edges[:, 0].astype(np.int64), edges[:, 1].astype(np.int64)
    both = np.concatenate([lo, hi])
    other = np.concatenate([hi, lo])
    ids = np.concatenate([np.arange(len(edges)), np.arange(len(edges))])
    order = np.argsort(both, kind="stable")
    start = np.searchsorted(both[order], np.arange(n_nodes + 1))
    nb_node, nb_edge = other[order], ids[order]          # CSR: node -> (neighbour, edge)

    length = np.linalg.norm(coords[hi] - coords[lo], axis=1)
    # Dijkstra needs positive weights (an explicit zero is no edge in scipy's sparse graphs)
    scale = float(np.max(length)) if len(length) else 1.0
    length = np.maximum(length, 1e-12 * max(scale, 1e-300))
    follow = np.where(np.isnan(angle), -np.inf, angle)
    half = alpha / 2.0

    degree = np.bincount(both[np.concatenate([kind, kind]) != SMOOTH], minlength=n_nodes)
    for end in np.flatnonzero(degree == 1):
        if degree[end] != 1:
            continue
        line, far_end = _trace_line(int(end), kind, degree, start, nb_node, nb_edge)
        on_feature = degree > 0
        targets = on_feature.copy()
        targets[line] = False
        if not targets.any():
            if far_end is None:
                continue
            targets[far_end] = True
        in_line = np.zeros(n_nodes, bool)
        in_line[line] = True
        in_line[targets] = False              # the far end, when it is the fallback target

        def mark(k: int) -> None:
            if kind[k] == SMOOTH:
                kind[k] = CLOSING
                degree[lo[k]] += 1
                degree[hi[k]] += 1

        current, reached = int(end), False
        while True:
            s, t = start[current], start[current + 1]
            cand_edges, cand_nodes = nb_edge[s:t], nb_node[s:t]
            usable = ((kind[cand_edges] == SMOOTH) & ~in_line[cand_nodes]
                      & (follow[cand_edges] > half))
            if not usable.any():
                break
            best = np.flatnonzero(usable)[np.argmax(follow[cand_edges[usable]])]
            mark(int(cand_edges[best]))
            current = int(cand_nodes[best])
            in_line[current] = True
            if targets[current]:
                reached = True
                break
        if reached:
            continue
        # shortest path from the current node to the nearest target, avoiding the line
        blocked = in_line.copy()
        blocked[current] = False
        allowed = ~blocked[lo] & ~blocked[hi]
        graph = coo_matrix((length[allowed], (lo[allowed], hi[allowed])),
                           shape=(n_nodes, n_nodes)).tocsr()
        dist, pred = dijkstra(graph, directed=False, indices=current, return_predecessors=True)
        reach = np.where(targets & np.isfinite(dist), dist, np.inf)
        goal = int(np.argmin(reach))
        if not np.isfinite(reach[goal]):
            continue
        node = goal
        while node != current:
            prev = int(pred[node])
            a, b = min(prev, node), max(prev, node)
            k = int(np.searchsorted(_edge_keys(edges), (a << 32) | b))
            mark(k)
            node = prev


def _trace_line(end: int, kind, degree, start, nb_node, nb_edge):
    """Nodes of the feature chain from dangling ``end`` up to (and including) the first node
    whose feature degree is not 2, and that node when it is another dangling end (else None)."""
    line = [end]
    prev_edge, node = -1, end
    while True:
        s, t = start[node], start[node + 1]
        feat = np.flatnonzero((kind[nb_edge[s:t]] != SMOOTH) & (nb_edge[s:t] != prev_edge))
        if len(feat) == 0:
            return line, None
        prev_edge = int(nb_edge[s + feat[0]])
        node = int(nb_node[s + feat[0]])
        if node in line:                      # a loop (cannot happen from a degree-1 start)
            return line, None
        line.append(node)
        if degree[node] != 2:
            return line, (node if degree[node] == 1 else None)


def _feature_edge_array(feature, edges: np.ndarray) -> np.ndarray:
    """(E,) bool: which of ``edges`` are feature edges, from a FeatureEdges or (K, 2) array."""
    if isinstance(feature, FeatureEdges):
        if len(feature.edges) != len(edges) or not np.array_equal(feature.edges, edges):
            raise ValueError("feature_edges belongs to other elements (its edges differ)")
        return feature.feature
    f = np.asarray(feature)
    if f.size == 0:
        return np.zeros(len(edges), bool)
    if f.ndim != 2 or f.shape[1] != 2 or f.dtype.kind not in "iu":
        raise ValueError("feature edges must be a FeatureEdges or (K, 2) node pairs, got "
                         f"{f.shape} {f.dtype}")
    f = np.sort(f.astype(np.int64), axis=1)
    keys = (f[:, 0] << 32) | f[:, 1]
    table = _edge_keys(edges)
    pos = np.minimum(np.searchsorted(table, keys), max(len(table) - 1, 0))
    missing = table[pos] != keys
    if missing.any():
        raise ValueError(f"{int(missing.sum())} feature edges are not element edges, first "
                         f"{f[missing][:5].tolist()}")
    out = np.zeros(len(edges), bool)
    out[pos] = True
    return out


def patches(elements, feature_edges) -> np.ndarray:
    """(M,) int64 patch label per element: connected components across non-feature edges.

    Two elements are joined when they share an edge that is not a feature edge (every element on
    such an edge is joined). ``feature_edges`` is a :class:`FeatureEdges` of these elements
    (every kind but SMOOTH cuts) or a (K, 2) array of node pairs, each an element edge in either
    order. Labels are 0..P-1, numbered in order of each patch's first element. Refused: bad
    elements, feature edges that are not element edges or belong to other elements.
    """
    e = as_elements(elements)
    edges = unique_edges(e)
    is_feature = _feature_edge_array(feature_edges, edges)
    elem, edge_id, _ = _incidence(e, edges)
    keep = ~is_feature[edge_id]
    elem, edge_id = elem[keep], edge_id[keep]
    order = np.argsort(edge_id, kind="stable")
    elem, edge_id = elem[order], edge_id[order]
    same = np.flatnonzero(edge_id[1:] == edge_id[:-1])
    m = len(e)
    graph = coo_matrix((np.ones(len(same), np.int8), (elem[same], elem[same + 1])), shape=(m, m))
    _, labels = connected_components(graph.tocsr(), directed=False)
    return _renumber(labels)


def _renumber(labels: np.ndarray) -> np.ndarray:
    """Labels 0..P-1 in order of first occurrence."""
    _, first, inverse = np.unique(labels, return_index=True, return_inverse=True)
    rank = np.empty(len(first), np.int64)
    rank[np.argsort(first)] = np.arange(len(first))
    return rank[inverse.ravel()]


def element_adjacency(elements, labels=None):
    """CSR (indptr, indices) of elements sharing an element edge, restricted to equal ``labels``.

    Every pair of elements on a shared edge is a neighbour pair (on a non-manifold edge, all of
    them that carry the same label). Elements are never their own neighbours.
    """
    e = as_elements(elements)
    m = len(e)
    edges = unique_edges(e)
    elem, edge_id, _ = _incidence(e, edges)
    lab = np.zeros(m, np.int64) if labels is None else np.asarray(labels, np.int64)
    order = np.lexsort((elem, lab[elem], edge_id))
    elem, edge_id = elem[order], edge_id[order]
    group = np.r_[True, (edge_id[1:] != edge_id[:-1]) | (lab[elem[1:]] != lab[elem[:-1]])]
    starts = np.flatnonzero(group)
    sizes = np.diff(np.r_[starts, len(elem)])
    src, dst = [], []
    for size in np.unique(sizes[sizes > 1]):
        block = starts[sizes == size][:, None] + np.arange(size)
        members = elem[block]                              # (G, size)
        i, j = np.nonzero(~np.eye(size, dtype=bool))
        src.append(members[:, i].ravel())
        dst.append(members[:, j].ravel())
    src = np.concatenate(src) if src else np.zeros(0, np.int64)
    dst = np.concatenate(dst) if dst else np.zeros(0, np.int64)
    keep = src != dst
    graph = coo_matrix((np.ones(int(keep.sum()), np.int8), (src[keep], dst[keep])),
                       shape=(m, m)).tocsr()
    graph.sum_duplicates()
    return graph.indptr, graph.indices


def planar_subpatches(elements, coords, patch_labels, d: float) -> np.ndarray:
    """(M,) int64 subpatch label per element: least-squares planar pieces of each patch
    (fe2003 §3.2).

    Patches are processed in order of first element; within a patch, subpatches are grown one
    after the other:

    * a subpatch starts at a seed element and keeps the sums of its distinct nodes (count,
      coordinate sum and sum of outer products, taken relative to the seed's first node);
      the plane is the least-squares plane: through the centroid, normal along the eigenvector
      of the smallest eigenvalue of the covariance;
    * neighbours (elements sharing an element edge and carrying the same patch label) are tried
      in breadth-first order; one is added when, with its nodes, every node of the subpatch lies
      within ``d`` of the refitted plane (so the final plane of a subpatch holds all its nodes
      within ``d``); otherwise it is set aside;
    * when no neighbour fits, the next seed is the earliest set-aside element that is still
      unassigned (so new subpatches start next to existing ones, leaving no isolated islands);
      only when there is none (a patch whose elements are not edge-connected) the lowest
      unassigned element of the patch seeds the next one.

    A seed is always accepted, so a warped quad deviating by more than ``d`` from its own plane
    forms a subpatch alone. Every element gets exactly one label; labels never cross patches,
    each subpatch is edge-connected, and labels are numbered 0..S-1 in order of creation.

    ``coords`` (N, 3) float64 and ``d`` in model units. Each accepted element costs one check of
    all the subpatch's nodes (vectorised), so the time grows with the square of subpatch size.
    Refused: bad elements or coordinates, ``patch_labels`` that is not (M,) integer, ``d``
    negative or not finite.
    """
    e = as_elements(elements)
    c = as_coords(coords, e)
    m = len(e)
    lab = np.asarray(patch_labels)
    if lab.shape != (m,) or lab.dtype.kind not in "iu":
        raise ValueError(f"patch_labels must be ({m},) integers, got {lab.shape} {lab.dtype}")
    d = float(d)
    if not np.isfinite(d) or d < 0.0:
        raise ValueError(f"d must be a finite distance >= 0 (model units), got {d!r}")
    indptr, indices = element_adjacency(e, lab)

    # distinct nodes per element (a triangle's repeated node, any repeated node, only once)
    distinct = np.ones(e.shape, bool)
    for k in range(1, 4):
        distinct[:, k] = (e[:, :k] != e[:, k:k + 1]).all(axis=1)

    out = np.full(m, -1, np.int64)
    node_mark = np.full(len(c), -1, np.int64)
    queued = np.full(m, -1, np.int64)
    order = np.argsort(lab, kind="stable")
    bounds = np.flatnonzero(np.r_[True, lab[order][1:] != lab[order][:-1], True])
    first_of_patch = order[bounds[:-1]]
    sp = 0
    for p in np.argsort(first_of_patch, kind="stable"):
        members = order[bounds[p]:bounds[p + 1]]
        pending: deque[int] = deque()
        cursor = 0
        while True:
            seed = -1
            while pending:
                cand = pending.popleft()
                if out[cand] < 0:
                    seed = cand
                    break
            if seed < 0:
                while cursor < len(members) and out[members[cursor]] >= 0:
                    cursor += 1
                if cursor == len(members):
                    break
                seed = int(members[cursor])
            _grow(seed, sp, e, c, distinct, indptr, indices, out, node_mark, queued, pending, d)
            sp += 1
    return out


def _grow(seed, sp, e, c, distinct, indptr, indices, out, node_mark, queued, pending, d) -> None:
    """Grow subpatch ``sp`` from ``seed``; rejected neighbours go to ``pending``."""
    ref = c[e[seed, 0]]
    nodes = e[seed][distinct[seed]]
    pts = c[nodes] - ref
    node_mark[nodes] = sp
    count = len(pts)
    total = pts.sum(axis=0)
    outer = pts.T @ pts
    out[seed] = sp
    queued[seed] = sp
    queue: deque[int] = deque()

    def push(f: int) -> None:
        for g in indices[indptr[f]:indptr[f + 1]]:
            if out[g] < 0 and queued[g] != sp:
                queued[g] = sp
                queue.append(int(g))

    push(seed)
    while queue:
        f = queue.popleft()
        if out[f] >= 0:
            continue
        cand = e[f][distinct[f]]
        new = cand[node_mark[cand] != sp]
        new_pts = c[new] - ref
        n2 = count + len(new_pts)
        t2 = total + new_pts.sum(axis=0)
        o2 = outer + new_pts.T @ new_pts
        trial = np.concatenate([pts, new_pts]) if len(new_pts) else pts
        if n2 > 3:
            centroid = t2 / n2
            cov = o2 / n2 - np.outer(centroid, centroid)
            normal = np.linalg.eigh(cov)[1][:, 0]
            fits = bool(np.max(np.abs((trial - centroid) @ normal)) <= d)
        else:
            fits = True                       # three points or fewer always lie in a plane
        if fits:
            out[f] = sp
            node_mark[new] = sp
            pts, count, total, outer = trial, n2, t2, o2
            push(f)
        else:
            pending.append(f)
