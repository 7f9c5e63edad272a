"""Per-node minimum distance to the other parts of a crash model, and part connectivity.

crash2000 (Sommer & Ertl, §4.1) finds, for every node of a crash FE model, the nearest element
of *another* part up to a distance of interest (1.5 mm in the paper; initial penetrations and
flanges show up as nodes closer than the sheet thickness), with a bounding-volume hierarchy per
part, and compares axis-aligned and oriented boxes with one and up to ten elements per leaf by
the number of bounding volumes, point/box tests, point/element tests and seconds (its Table 2).

* :func:`part_distances` -- the per-node distances through an
  :class:`~workbench.algo.hierarchy.ElementHierarchy`, with the Table 2 counters.
* :func:`connectivity` -- for every pair of parts the smallest node-to-element distance between
  them when it is within a given distance, and how many nodes are that close: the connectivity
  matrix the paper suggests for checking a model's assembly.
* :func:`brute_force_part_distances` -- the reference: every node against every triangle.

Conventions, shared by all three:

* An element is the triangles :attr:`FEMesh.triangles` gives it (quads split along the shorter
  diagonal); a topologically degenerate element (fewer than three distinct nodes, or a node at
  opposite corners) has no triangle and is never a target, although its nodes are measured.
* A node's **own parts** are every part of an element that uses the node. A node on the seam of
  two parts (shared by both) is therefore measured against the third parts only: its distance
  to either of its own parts is zero by construction and says nothing. A node that no element
  uses gets distance inf and part -1.
* Distances are exact float64 (the closest point on each triangle,
  :func:`~workbench.algo.distance.closest_point_on_triangle`), in the mesh's units
  (millimetres for crash decks), computed relative to the centre of the used nodes' bounding box
  (:func:`~workbench.algo.hierarchy.local_origin`), so that a model far from the origin keeps
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

import numpy as np

from ..scene.needs import derived_item
from .distance import points_triangles_distance
from .hierarchy import (
    KINDS,
    ElementHierarchy,
    check_finite,
    distinct,
    local_origin,
    used_nodes,
)

__all__ = ["Connectivity", "PartDistances", "brute_force_part_distances", "connectivity",
           "node_parts", "part_distances", "flange_distances"]


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


def _csr_rows(ptr: np.ndarray, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For the CSR rows ``rows``: (position in ``rows``, index into the CSR values) of every
    entry, row by row."""
    reps = ptr[rows + 1] - ptr[rows]
    pos = np.repeat(np.arange(len(rows)), reps)
    within = np.arange(reps.sum()) - np.repeat(np.cumsum(reps) - reps, reps)
    return pos, ptr[rows][pos] + within


def _with_triangles(mesh) -> np.ndarray:
    """Indices of the elements that have at least one triangle."""
    return np.flatnonzero(np.bincount(mesh.triangulation.element_of, minlength=len(mesh.elements)))


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
    targets = _with_triangles(mesh)
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
    trees under the top level of an :class:`~workbench.algo.hierarchy.ElementHierarchy`), so a
    node near two other parts counts for both. Own parts, units and refusals as in the module
    notes (``distance`` plays the cut-off's role).
    """
    distance, step, coords, used = _check(mesh, distance, kind, leaf_size, step, "distance")
    parts = distinct(mesh.parts).astype(np.int64)
    p = len(parts)
    best = np.full((p, p), np.inf)
    count = np.zeros((p, p), np.int64)
    targets = _with_triangles(mesh)
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
    corners = np.ascontiguousarray(local[np.asarray(tr.triangles, dtype=np.int64)])
    ids = distinct(mesh.parts)
    cp = np.searchsorted(ids, np.asarray(mesh.parts))
    tri_part = cp.ravel()[tr.element_of]
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
