"""Per-node minimum distance to the other parts of a crash model, and part connectivity.

crash2000 (Sommer & Ertl, §4.1) finds, for every node of a crash FE model, the nearest element
of *another* part up to a distance of interest (1.5 mm in the paper; initial penetrations and
flanges show up as nodes closer than the sheet thickness), with a bounding-volume hierarchy per
part, and compares axis-aligned and oriented boxes with one and up to ten elements per leaf by
the number of bounding volumes, point/box tests, point/element tests and seconds (its Table 2).

* :func:`part_distances` -- the per-node distances through an
  :class:`~workbench.algo.nearest.hierarchy.ElementHierarchy`, with the Table 2 counters.
* :func:`connectivity` -- for every pair of parts the smallest node-to-element distance between
  them when it is within a given distance, and how many nodes are that close: the connectivity
  matrix the paper suggests for checking a model's assembly.
* :func:`batched_part_distances` -- the same distances through one 4-wide triangle tree
  searched by groups of nearby nodes (:mod:`workbench.algo.nearest.batch`): equal to the others to
  the last bit, several times faster on large models, without the Table 2 counters.
* :func:`brute_force_part_distances` -- the reference: every node against every triangle.

Conventions, shared by all four:

* An element is the triangles :attr:`FEMesh.triangles` gives it (quads split along the shorter
  diagonal); a topologically degenerate element (fewer than three distinct nodes, or a node at
  opposite corners) has no triangle and is never a target, although its nodes are measured.
* **Erosion**: an element deleted at the step measured (its ``"alive"`` field 0) is no
  target, and a node that only deleted elements use is not measured (inf, part -1).
* A node's **own parts** are every part of an element that uses the node (a deleted one
  too). A node on the seam of two parts (shared by both) is therefore measured against the
  third parts only: its distance to either of its own parts is zero by construction and says
  nothing. A node that no element
  uses gets distance inf and part -1.
* Distances are exact float64 (the closest point on each triangle,
  :func:`~workbench.algo.nearest.triangle.closest_point_on_triangle`), in the mesh's units
  (millimetres for crash decks), computed relative to the centre of the used nodes' bounding box
  (:func:`~workbench.algo.nearest.hierarchy.local_origin`), so that a model far from the origin
  keeps
  its digits. A distance is reported when it is at most the cut-off (inf and -1 beyond).
  Among elements at exactly the same distance the hierarchy and the brute force may name
  different parts.

Refused with ValueError (one line): a cut-off that is not a finite number > 0, an unknown
``kind``, ``leaf_size`` < 1, a mesh without elements, a step outside the mesh's steps, NaN/inf
coordinates of a node an element uses.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numba
import numpy as np

from ...scene.needs import derived_item
from .batch import LEAF_SIZE, BatchedTriangleTree
from .hierarchy import KINDS, ElementHierarchy, check_finite, distinct, local_origin, used_nodes
from .triangle import points_triangles_distance

__all__ = ["Connectivity", "PartDistances", "batched_part_distances",
           "brute_force_part_distances", "connectivity", "flange_distances", "node_parts",
           "own_part_sets", "part_distances"]


@dataclass
class PartDistances:
    """Result of :func:`part_distances`.

    ``distance`` (N,) float64 distance from each node to the nearest element of another part
    within ``cutoff`` (inf beyond, and for unused nodes); ``other_part`` (N,) int64 that
    element's part id (-1 where none); ``other_element`` (N,) int64 its element index (-1).
    The counters of crash2000's Table 2, summed over the nodes: ``n_bvs`` bounding volumes in
    the part trees (``n_top_bvs`` more in the level over the parts), ``bv_tests`` point/BV
    distances computed, ``element_tests`` exact point/element distances computed,
    ``plane_skips`` elements skipped by the point-to-plane test, ``leaf_elements`` elements in
    the leaves the searches opened (= ``element_tests + plane_skips``), ``nodes_queried`` the
    nodes searched. ``build_s`` seconds to build the hierarchy, ``query_s`` seconds for the
    searches (both wall clock), and the parameters ``kind``, ``leaf_size``, ``cutoff``.
    """

    distance: np.ndarray
    other_part: np.ndarray
    other_element: np.ndarray
    n_bvs: int
    n_top_bvs: int
    bv_tests: int
    element_tests: int
    plane_skips: int
    leaf_elements: int
    nodes_queried: int
    build_s: float
    query_s: float
    kind: str
    leaf_size: int
    cutoff: float

    @property
    def queries_per_s(self) -> float:
        """Node searches per second of ``query_s``."""
        return self.nodes_queried / self.query_s if self.query_s > 0 else float("inf")

    def row(self) -> dict:
        """The Table 2 columns as a flat dict (for experiment tables)."""
        return {"kind": self.kind, "leaf_size": self.leaf_size, "cutoff": self.cutoff,
                "n_bvs": self.n_bvs, "bv_tests": self.bv_tests,
                "element_tests": self.element_tests, "plane_skips": self.plane_skips,
                "build_s": self.build_s, "query_s": self.query_s,
                "queries_per_s": self.queries_per_s,
                "nodes_within": int(np.isfinite(self.distance).sum())}


@dataclass
class Connectivity:
    """Result of :func:`connectivity`: ``parts`` (P,) every part id of the mesh (sorted);
    ``min_distance`` (P, P) float64 symmetric, the smallest distance from a node of one part to
    an element of the other (either direction) when it is at most ``distance``, inf otherwise
    (and on the diagonal); ``nodes_within`` (P, P) int64 symmetric, how many nodes of either
    part are within ``distance`` of the other (a node of two parts counts once for each of
    them)."""

    parts: np.ndarray
    min_distance: np.ndarray
    nodes_within: np.ndarray
    distance: float
    kind: str

    def rows(self) -> list[dict]:
        """One dict per pair of parts within ``distance`` (part_a < part_b):
        ``part_a``, ``part_b``, ``min_distance``, ``nodes_within``."""
        a, b = np.nonzero(np.triu(self.nodes_within > 0, 1))
        return [{"part_a": int(self.parts[i]), "part_b": int(self.parts[j]),
                 "min_distance": float(self.min_distance[i, j]),
                 "nodes_within": int(self.nodes_within[i, j])} for i, j in zip(a, b)]


# --------------------------------------------------------------------------- helpers
def _check(mesh, cutoff, kind, leaf_size, step, what="cutoff"):
    """Validated (cutoff, step, coordinates, used nodes); ValueError for bad input."""
    try:
        c = float(cutoff)
    except (TypeError, ValueError):
        raise ValueError(f"{what} must be a finite number > 0, got {cutoff!r}") from None
    if isinstance(cutoff, (bool, np.bool_)) or not (np.isfinite(c) and c > 0):
        raise ValueError(f"{what} must be a finite number > 0, got {cutoff!r}")
    if kind not in KINDS:
        raise ValueError(f"kind must be one of {KINDS}, got {kind!r}")
    if isinstance(leaf_size, (bool, np.bool_)) or not isinstance(leaf_size, (int, np.integer)) \
            or leaf_size < 1:
        raise ValueError(f"leaf_size must be an integer >= 1, got {leaf_size!r}")
    if len(mesh.elements) == 0:
        raise ValueError(f"{mesh.name}: the mesh has no elements")
    step = mesh.step_index(step)
    coords = mesh.coordinates(step)
    used = used_nodes(mesh.elements, mesh.n_nodes)
    check_finite(coords, used)
    if mesh.erodes:  # the nodes of elements in use at the step (module notes)
        used = used[mesh.live_nodes(step)[used]]
    return c, step, coords, used


def node_parts(mesh) -> tuple[np.ndarray, np.ndarray]:
    """Each node's own parts in CSR form ``(ptr, part_ids)``: node i belongs to the sorted part
    ids ``part_ids[ptr[i]:ptr[i + 1]]``, every part of an element that uses it."""
    e = np.asarray(mesh.elements, dtype=np.int64)
    ids = distinct(mesh.parts)
    cp = np.searchsorted(ids, np.asarray(mesh.parts))
    key = np.sort(e.ravel() * len(ids) + np.repeat(cp.ravel(), e.shape[1]))
    key = key[np.r_[True, key[1:] != key[:-1]]]
    node, part = key // len(ids), key % len(ids)
    ptr = np.searchsorted(node, np.arange(mesh.n_nodes + 1)).astype(np.int64)
    return ptr, ids[part].astype(np.int64)


def own_part_sets(mesh, element_part: np.ndarray | None = None):
    """Each node's own parts as one of the distinct sets they form: ``(node_set, set_ptr,
    set_parts)``.

    ``node_set`` (N,) int64: the set of node i, -1 for a node no element uses; set s holds the
    part *indices* (into the sorted distinct part ids, as ``element_part`` gives them)
    ``set_parts[set_ptr[s]:set_ptr[s + 1]]``, sorted. Sets 0 .. P - 1 are the single parts
    (set p = {p}); the sets of nodes shared by several parts follow. ``element_part`` (M,)
    the part index of each element (computed when not given).
    """
    if element_part is None:
        element_part = np.searchsorted(distinct(mesh.parts), mesh.parts)
    element_part = np.ascontiguousarray(element_part, dtype=np.int64)
    elements = np.ascontiguousarray(mesh.elements)
    n_parts = int(element_part.max()) + 1 if len(element_part) else 0
    node_set, multi, other = _first_parts(elements, element_part, mesh.n_nodes)
    set_ptr = np.arange(n_parts + 1, dtype=np.int64)
    set_parts = np.arange(n_parts, dtype=np.int64)
    if other.any():
        # the parts of a node of several: the one it holds, and those of the elements found
        # with another
        e = np.flatnonzero(other)
        corner = elements[e].astype(np.int64)
        corner_part = np.broadcast_to(element_part[e][:, None], corner.shape)
        node = np.flatnonzero(multi)
        key = np.unique(np.r_[node * n_parts + node_set[node],
                              (corner * n_parts + corner_part)[multi[corner]]])
        node, part = key // n_parts, key % n_parts
        starts = np.flatnonzero(np.r_[True, node[1:] != node[:-1]])
        sizes = np.diff(np.r_[starts, len(node)])
        rows = np.full((len(starts), int(sizes.max())), -1, np.int64)
        rows[np.repeat(np.arange(len(starts)), sizes),
             np.arange(len(node)) - np.repeat(starts, sizes)] = part
        if rows.shape[1] * np.log2(n_parts + 1) < 62:  # each row as one integer: quicker
            code = ((rows + 1) * (n_parts + 1) ** np.arange(rows.shape[1])).sum(axis=1)
            _, first, inverse = np.unique(code, return_index=True, return_inverse=True)
            sets = rows[first]
        else:
            sets, inverse = np.unique(rows, axis=0, return_inverse=True)
        node_set[node[starts]] = n_parts + inverse.ravel()
        sizes = (sets >= 0).sum(axis=1)
        set_ptr = np.concatenate([set_ptr, n_parts + np.cumsum(sizes)])
        set_parts = np.concatenate([set_parts, sets[sets >= 0]])
    return node_set, set_ptr, set_parts


@numba.njit(cache=True)
def _first_parts(elements, element_part, n_nodes):
    """(the part index of each node's first element (-1 unused), whether the node has
    several, whether each element holds a node whose first part is not the element's): one
    pass, element by element. An element with the node's first part is not flagged, and
    needs not be: that part is the node's first."""
    part = np.full(n_nodes, -1, np.int64)
    multi = np.zeros(n_nodes, np.bool_)
    other = np.zeros(len(elements), np.bool_)
    for e in range(len(elements)):
        q = element_part[e]
        for j in range(elements.shape[1]):
            v = elements[e, j]
            if part[v] < 0:
                part[v] = q
            elif part[v] != q:
                multi[v] = True
                other[e] = True
    return part, multi, other


def _csr_rows(ptr: np.ndarray, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For the CSR rows ``rows``: (position in ``rows``, index into the CSR values) of every
    entry, row by row."""
    reps = ptr[rows + 1] - ptr[rows]
    pos = np.repeat(np.arange(len(rows)), reps)
    within = np.arange(reps.sum()) - np.repeat(np.cumsum(reps) - reps, reps)
    return pos, ptr[rows][pos] + within


def _with_triangles(mesh, step: int) -> np.ndarray:
    """Indices of the elements measured against at ``step``: those with at least one triangle,
    in use at the step (erosion)."""
    has = np.bincount(mesh.triangulation.element_of, minlength=len(mesh.elements)) > 0
    return np.flatnonzero(has & mesh.alive(step))


# --------------------------------------------------------------------------- the queries
def part_distances(mesh, cutoff: float, *, kind: str = "aabb", leaf_size: int = 1,
                   step: int = 0, plane_test: bool = True) -> PartDistances:
    """For every node of ``mesh``, the exact distance to the nearest element of another part
    within ``cutoff`` (crash2000 §4.1; see the module notes for own parts and units).

    ``kind`` "aabb" or "obb" and ``leaf_size`` (most elements per leaf) choose the hierarchy;
    ``step`` the time step whose coordinates are measured; ``plane_test`` whether an element
    may be skipped by its point-to-plane (slab) distance before its exact distance is computed.
    The search is parallel over nodes; distances, parts and counters do not depend on the
    number of threads. Refusals: see the module notes.
    """
    cutoff, step, coords, used = _check(mesh, cutoff, kind, leaf_size, step)
    n = mesh.n_nodes
    active = np.zeros(n, bool)
    active[used] = True
    targets = _with_triangles(mesh, step)
    if len(targets) == 0:  # only degenerate elements: nothing to measure against
        return PartDistances(np.full(n, np.inf), np.full(n, -1, np.int64),
                             np.full(n, -1, np.int64), 0, 0, 0, 0, 0, 0, int(active.sum()),
                             0.0, 0.0, kind, int(leaf_size), cutoff)
    h = ElementHierarchy(mesh, kind=kind, leaf_size=leaf_size, step=step, elements=targets,
                         origin=local_origin(coords, used))
    t0 = time.perf_counter()
    own = node_parts(mesh)
    r = h.nearest(coords, cutoff, exclude=own, active=active, plane_test=plane_test)
    query_s = time.perf_counter() - t0
    return PartDistances(r.distance, r.part, r.element, h.n_bvs, h.n_top_bvs, r.bv_tests,
                         r.element_tests, r.plane_skips, r.leaf_elements, int(active.sum()),
                         h.build_s, query_s, kind, int(leaf_size), cutoff)


def batched_part_distances(mesh, cutoff: float, *, step: int = 0,
                           leaf_size: int = LEAF_SIZE) -> PartDistances:
    """:func:`part_distances` through one 4-wide triangle tree searched by groups of nearby
    nodes (:class:`~workbench.algo.nearest.batch.BatchedTriangleTree`): the same distances, exact
    float64 to the last bit, and the same conventions (module notes), at a fraction of the
    time on large models.

    ``leaf_size`` most triangle references per leaf; ``step`` the time step measured. The
    counters differ in meaning from the crash2000 hierarchy's: ``n_bvs`` the boxes of the tree,
    ``bv_tests`` box-against-box and box-against-node tests, ``element_tests`` exact
    point/triangle distances (``leaf_elements`` the same, no plane skips); ``kind`` is
    "batched". ``build_s`` covers the local coordinates, the triangles' parts and the tree;
    ``query_s`` each node's own parts, the grouping and the search. Refusals as in
    :func:`part_distances`.
    """
    cutoff, step, coords, used = _check(mesh, cutoff, "aabb", leaf_size, step)
    n = mesh.n_nodes
    n_used = len(used)
    tr = mesh.triangulation
    if tr.n_triangles == 0:
        return PartDistances(np.full(n, np.inf), np.full(n, -1, np.int64),
                             np.full(n, -1, np.int64), 0, 0, 0, 0, 0, 0, n_used, 0.0, 0.0,
                             "batched", int(leaf_size), cutoff)
    t0 = time.perf_counter()
    ids = distinct(mesh.parts)
    element_part = np.searchsorted(ids, mesh.parts).astype(np.int64)
    local = coords - local_origin(coords, used)
    live = mesh.alive(step)[tr.element_of]  # erosion: deleted elements are no target
    element_of = np.ascontiguousarray(tr.element_of[live])
    corners = local[np.asarray(tr.triangles, dtype=np.int64)[live]]
    tree = BatchedTriangleTree(corners, element_part[element_of], leaf_size=int(leaf_size))
    t1 = time.perf_counter()
    node_set, set_ptr, set_parts = own_part_sets(mesh, element_part)
    d2, tri, counts = tree.nearest(local, node_set, set_ptr, set_parts, cutoff)
    distance, element, other = _results(d2, tri, element_of, element_part,
                                        ids.astype(np.int64))
    if mesh.erodes:  # a node only deleted elements use is not measured
        unused = np.ones(n, bool)
        unused[used] = False
        distance[unused], element[unused], other[unused] = np.inf, -1, -1
    query_s = time.perf_counter() - t1
    return PartDistances(distance, other, element, tree.n_boxes, 0, counts["box_tests"],
                         counts["triangle_tests"], 0, counts["triangle_tests"], n_used,
                         t1 - t0, query_s, "batched", int(leaf_size), cutoff)


@numba.njit(cache=True)
def _results(d2, tri, element_of, element_part, part_ids):
    """(distance, element, part id) of each node from its squared distance and triangle."""
    n = len(d2)
    distance = np.empty(n)
    element = np.empty(n, np.int64)
    other = np.empty(n, np.int64)
    for i in range(n):
        t = tri[i]
        if t >= 0:
            distance[i] = np.sqrt(d2[i])
            element[i] = element_of[t]
            other[i] = part_ids[element_part[element_of[t]]]
        else:
            distance[i] = np.inf
            element[i] = -1
            other[i] = -1
    return distance, element, other


@derived_item("part_distances", key=lambda cutoff, step=0: (float(cutoff), int(step)),
              from_style=lambda style: (getattr(style, "cutoff", 50.0), getattr(style, "step", 0)))
def flange_distances(mesh, cutoff: float, step: int = 0) -> PartDistances:
    """The derived item ``part_distances`` (what the flange path needs): :func:`part_distances`
    of step ``step`` within ``cutoff`` (model units) through AABB trees of one element per
    leaf, kept in the mesh's cache per (cutoff, step)."""
    return part_distances(mesh, cutoff, step=step)


def connectivity(mesh, distance: float, *, kind: str = "aabb", leaf_size: int = 1,
                 step: int = 0) -> Connectivity:
    """The connectivity matrix of crash2000 §4.1: for every pair of parts, the smallest
    node-to-element distance between them (either direction) when it is at most ``distance``,
    and the number of nodes that close.

    Every node searches each other part within ``distance`` for its nearest element (the part
    trees under the top level of an :class:`~workbench.algo.nearest.hierarchy.ElementHierarchy`),
    so a
    node near two other parts counts for both. Own parts, units and refusals as in the module
    notes (``distance`` plays the cut-off's role).
    """
    distance, step, coords, used = _check(mesh, distance, kind, leaf_size, step, "distance")
    parts = distinct(mesh.parts).astype(np.int64)
    p = len(parts)
    best = np.full((p, p), np.inf)
    count = np.zeros((p, p), np.int64)
    targets = _with_triangles(mesh, step)
    if len(targets):
        active = np.zeros(mesh.n_nodes, bool)
        active[used] = True
        h = ElementHierarchy(mesh, kind=kind, leaf_size=leaf_size, step=step,
                             elements=targets, origin=local_origin(coords, used))
        ptr, own = node_parts(mesh)
        node, other, d = h.nearest_per_part(coords, distance, exclude=(ptr, own),
                                            active=active)
        rows, at = _csr_rows(ptr, node)
        a = np.searchsorted(parts, own[at])
        b = np.searchsorted(parts, other[rows])
        dd = d[rows]
        np.minimum.at(best, (a, b), dd)
        np.add.at(count, (a, b), 1)
    return Connectivity(parts, np.minimum(best, best.T), count + count.T, distance, kind)


def brute_force_part_distances(mesh, cutoff: float, *, step: int = 0,
                               chunk_pairs: int = 4_000_000) -> tuple[np.ndarray, np.ndarray]:
    """The reference for :func:`part_distances`: ``(distance, other_part)``, every used node
    against every triangle of another part, exact float64, in chunks of about ``chunk_pairs``
    node/triangle pairs (fine up to some 10^8 pairs). Conventions and refusals as in the module
    notes; among triangles at the same distance the first in element order wins."""
    cutoff, step, coords, used = _check(mesh, cutoff, "aabb", 1, step)
    n = mesh.n_nodes
    distance = np.full(n, np.inf)
    other = np.full(n, -1, np.int64)
    tr = mesh.triangulation
    if tr.n_triangles == 0:
        return distance, other
    origin = local_origin(coords, used)
    local = np.zeros((n, 3))
    local[used] = coords[used] - origin
    live = mesh.alive(step)[tr.element_of]  # erosion: deleted elements are no target
    if not live.any():
        return distance, other
    corners = np.ascontiguousarray(local[np.asarray(tr.triangles, dtype=np.int64)[live]])
    ids = distinct(mesh.parts)
    cp = np.searchsorted(ids, np.asarray(mesh.parts))
    tri_part = cp.ravel()[tr.element_of[live]]
    ptr, own = node_parts(mesh)
    own_cp = np.searchsorted(ids, own)
    step_nodes = max(1, int(chunk_pairs) // len(corners))
    for s in range(0, len(used), step_nodes):
        nodes = used[s:s + step_nodes]
        d = points_triangles_distance(local[nodes], corners)  # (C, K)
        member = np.zeros((len(nodes), len(ids)), bool)
        rows, at = _csr_rows(ptr, nodes)
        member[rows, own_cp[at]] = True
        d[member[:, tri_part]] = np.inf
        j = np.argmin(d, axis=1)
        dj = d[np.arange(len(nodes)), j]
        ok = dj <= cutoff
        distance[nodes[ok]] = dj[ok]
        other[nodes[ok]] = ids[tri_part[j[ok]]]
    return distance, other
