"""Initial penetrations of a shell model (crash2000 §4.1): nodes closer to an element of another
part than half the sum of the two shell thicknesses.

A shell element stands for a sheet of its thickness around its mid surface; two sheets touch
where the distance between their mid surfaces is less than half the sum of their thicknesses.
For every node and each part it belongs to, and every element of a part it does not belong to:

    depth = (t_node + t_element) / 2 - distance(node, element)

and the pair is a penetration where ``depth > 0``. Per (node, its part, other part) the
element of the largest depth is reported (the nearest element of the other part need not be
it: a farther, thicker element can reach deeper), with its distance and depth.

Definitions:

* **Thickness** is the element field ``"thickness"`` (section or element thickness, model
  units; NaN where unknown), at the step measured when it varies by step.
* **A node's thickness in a part** is the largest thickness of that part's elements that use the
  node. In the usual model, one section per part, every element around a node has the same
  thickness and the choice does not matter; where it changes across a node (a tailored blank),
  the largest is the sheet's surface nearest to the neighbour, so no penetration that one of
  the node's elements implies is missed (the mean would hide half of the step).
* **A node in several parts** (a seam) is checked once per part, with that part's thickness,
  against the parts it does not belong to (never against its own parts, to which its distance
  is zero by construction).
* **Unknown thickness** is never taken as zero: elements with NaN thickness are not measured
  against, nodes of a part whose elements there all have NaN thickness are not checked, and
  both are named in one :class:`PenetrationWarning` (counts and the first ids).
* **Self-contact** (``self_contact=True``): a node is also checked against the elements of its
  own part, except its own neighbourhood: every element that uses the node, and every element
  connected to those (through shared nodes) by a chain of elements each closer to the node than
  ``R = t_node / 2 + t_max / 2`` (``t_max`` the part's largest thickness). That chain covers a
  flat or gently curved sheet around the node (the sheet within a ball of radius R is one
  connected patch while its radius of curvature exceeds R), so a sheet never reports itself;
  what remains within reach is a fold or another region of the part that comes back near the
  node. A fold sharper than R (the bend itself within R of the node) is part of the
  neighbourhood and not reported.
* **Distances** are exact float64 (the element hierarchy of
  :mod:`workbench.algo.nearest.hierarchy`, elements as the triangles of
  :attr:`FEMesh.triangulation`), in model units (millimetres for crash decks), computed
  relative to the centre of the model, so that a model far from the origin gives the same
  answer. A degenerate element (no triangle) and an element deleted at the step (erosion) are
  not measured against.

Refused with ValueError (one line): a mesh without the element field ``"thickness"``, a mesh
whose thickness cannot be known (``FEMesh.unavailable["thickness"]``: an include deck whose
section thickness names a parameter of the master deck; the message names the parameter and
the deck to read), a negative or infinite thickness, a negative or non-finite ``margin``, an
unknown hierarchy ``kind``, a step outside the mesh's steps.
"""

from __future__ import annotations

import time
import warnings
from dataclasses import dataclass, field
from typing import NamedTuple

import numba
import numpy as np

from ...scene.needs import derived_item
from .hierarchy import KINDS, ElementHierarchy, distinct, local_origin, used_nodes
from .hierarchy.queries import bv_distance_sq
from .parts import node_parts
from .triangle import closest_point_on_triangle

__all__ = ["PenetrationWarning", "Penetrations", "node_thickness", "penetration_depths",
           "penetrations"]

_CHUNK = 32  # queries per parallel work item
# a box is pruned only when its squared distance exceeds the reach squared by this share
_SLACK_DIV = 1.0 / (1.0 + 1e-12)
_SHOWN_IDS = 8  # ids a warning lists


class PenetrationWarning(UserWarning):
    """Nodes or elements left out of a penetration check for want of a thickness."""


# --------------------------------------------------------------------------- kernel state
class Queries(NamedTuple):
    """The points searched, one per (node, part) pair, in the hierarchy's local coordinates."""

    points: np.ndarray  # (Q, 3) float64
    reach: np.ndarray   # (Q,) float64 the node's half thickness (+ margin); < 0: not searched
    ptr: np.ndarray     # (Q + 1,) int64 CSR: query i ignores the parts own[ptr[i]:ptr[i + 1]]
    own: np.ndarray     # (ptr[-1],) int64 part indices of the hierarchy (-1: not in it)
    only: np.ndarray    # (Q,) int64 search only this part index; -1: every part not ignored


class Reach(NamedTuple):
    """What each element adds to a query's reach: an element j is found when
    ``distance < reach[i] + half[j]``."""

    half: np.ndarray       # (E,) float64 half thickness in tree order; -inf: never found
    node_half: np.ndarray  # (forest nodes,) the largest ``half`` under each bounding volume


@numba.njit(cache=True)
def _subtree_max(start, end, half):
    """(nodes,) the largest of ``half[start[i]:end[i]]`` (-inf for an empty range)."""
    out = np.full(len(start), -np.inf)
    for i in range(len(start)):
        m = -np.inf
        for j in range(start[i], end[i]):
            if half[j] > m:
                m = half[j]
        out[i] = m
    return out


@numba.njit(cache=True, inline="always")
def _ignored(q, own, o0, o1):
    for k in range(o0, o1):
        if own[k] == q:
            return True
    return False


@numba.njit(cache=True, parallel=True)
def _within_many(queries, forest, elements, reach_of, offsets, counts, out_elem, out_d2, fill):
    """For each query i, every element j (tree order) of a part it does not ignore with
    ``sqrt(d2) < queries.reach[i] + reach_of.half[j]``, d2 the exact squared distance. First
    pass (``fill`` False): how many into ``counts``; second: (j, d2) at ``offsets[i]`` on."""
    points = queries.points
    reach = queries.reach
    ptr = queries.ptr
    own = queries.own
    only = queries.only
    half = reach_of.half
    node_half = reach_of.node_half
    bv = forest.bv
    obb = forest.obb
    left = forest.left
    right = forest.right
    start = forest.start
    end = forest.end
    node_part = forest.node_part
    root = forest.root
    depth = forest.depth
    corners = elements.corners
    n_tri = elements.n_tri
    n = len(points)
    n_chunks = (n + _CHUNK - 1) // _CHUNK
    for chunk in numba.prange(n_chunks):
        stack = np.empty(2 * depth + 4, np.int64)
        tmp = np.empty(3)
        for i in range(chunk * _CHUNK, min(n, (chunk + 1) * _CHUNK)):
            k = 0
            r = reach[i]
            if r >= 0.0:
                p = points[i]
                stack[0] = root
                top = 1
                while top > 0:
                    top -= 1
                    node = stack[top]
                    q = node_part[node]
                    if q >= 0 and ((only[i] >= 0 and q != only[i])
                                   or _ignored(q, own, ptr[i], ptr[i + 1])):
                        continue
                    lim = r + node_half[node]
                    if not lim > 0.0:
                        continue
                    d2 = bv_distance_sq(bv, node, p[0], p[1], p[2], obb)
                    if d2 * _SLACK_DIV >= lim * lim:
                        continue
                    c = left[node]
                    if c >= 0:
                        stack[top] = c
                        stack[top + 1] = right[node]
                        top += 2
                        continue
                    for j in range(start[node], end[node]):
                        lj = r + half[j]
                        if not lj > 0.0:
                            continue
                        best = np.inf
                        for t in range(n_tri[j]):
                            dt = closest_point_on_triangle(p, corners[j, t, 0], corners[j, t, 1],
                                                           corners[j, t, 2], tmp)
                            if dt < best:
                                best = dt
                        if np.sqrt(best) < lj:
                            if fill:
                                out_elem[offsets[i] + k] = j
                                out_d2[offsets[i] + k] = best
                            k += 1
            if not fill:
                counts[i] = k


@numba.njit(cache=True, parallel=True)
def _outside_neighbourhood(query_node, ball_ptr, ball_elem, element_nodes, cand_ptr, cand_elem,
                           keep):
    """Self-contact: for each query, the elements of its ball (``ball_elem[ball_ptr[i]:...]``,
    tree order) connected through shared nodes to an element that uses ``query_node[i]``,
    within the ball, are its neighbourhood; ``keep[c]`` is set for each candidate
    ``cand_elem[c]`` (of ``cand_ptr[i]:cand_ptr[i + 1]``) outside it."""
    for i in numba.prange(len(query_node)):
        b0 = ball_ptr[i]
        m = ball_ptr[i + 1] - b0
        reached = np.zeros(m, np.bool_)
        v = query_node[i]
        for a in range(m):
            for s in range(4):
                if element_nodes[ball_elem[b0 + a], s] == v:
                    reached[a] = True
        changed = True
        while changed:
            changed = False
            for a in range(m):
                if reached[a]:
                    continue
                ea = ball_elem[b0 + a]
                for b in range(m):
                    if not reached[b]:
                        continue
                    eb = ball_elem[b0 + b]
                    share = False
                    for s in range(4):
                        for u in range(4):
                            if element_nodes[ea, s] == element_nodes[eb, u]:
                                share = True
                    if share:
                        reached[a] = True
                        changed = True
                        break
        for c in range(cand_ptr[i], cand_ptr[i + 1]):
            inside = False
            for a in range(m):
                if reached[a] and ball_elem[b0 + a] == cand_elem[c]:
                    inside = True
                    break
            keep[c] = not inside


def _within(h: ElementHierarchy, queries: Queries, reach_of: Reach):
    """(query, tree-order element, squared distance) of every element a query reaches, sorted
    by query (two passes of :func:`_within_many`)."""
    n = len(queries.points)
    forest, elements = h._forest(), h._elements()
    counts = np.zeros(n, np.int64)
    offsets = np.zeros(n + 1, np.int64)
    _within_many(queries, forest, elements, reach_of, offsets, counts, np.zeros(0, np.int64),
                 np.zeros(0), False)
    offsets[1:] = np.cumsum(counts)
    out_elem = np.empty(offsets[-1], np.int64)
    out_d2 = np.empty(offsets[-1])
    _within_many(queries, forest, elements, reach_of, offsets, counts, out_elem, out_d2, True)
    return np.repeat(np.arange(n, dtype=np.int64), counts), out_elem, out_d2, offsets


def _reach(h: ElementHierarchy, half_tree: np.ndarray) -> Reach:
    half_tree = np.ascontiguousarray(half_tree, dtype=np.float64)
    return Reach(half_tree, _subtree_max(h.start, h.end, half_tree))


# --------------------------------------------------------------------------- result
@dataclass
class Penetrations:
    """Result of :func:`penetrations`: one row per (node, its part, other part) that
    penetrates (``depth > -margin``, so ``depth > 0`` by default), the element of the largest
    depth of the other part.

    Rows (K,): ``node`` node index, ``part`` the node's part id it was checked with,
    ``other_part`` the other part's id (== ``part`` for self-contact), ``element`` the element
    index reached, ``distance`` node to element, ``depth`` = (``node_thickness`` +
    ``element_thickness``)/2 − ``distance`` (model units). Sorted by depth, deepest first.
    Summary: ``nodes_checked`` nodes checked with a known thickness, ``pairs_checked`` (node,
    part) pairs, ``unchecked_nodes`` node indices with no known thickness in any of their
    parts, ``unknown_elements`` element indices with NaN thickness (not measured against),
    ``self_contact``, ``margin``, ``units``, ``seconds`` (wall clock, hierarchy and
    searches), ``node_ids``/``element_ids`` of the mesh (None where it has none).
    """

    node: np.ndarray
    part: np.ndarray
    other_part: np.ndarray
    element: np.ndarray
    distance: np.ndarray
    depth: np.ndarray
    node_thickness: np.ndarray
    element_thickness: np.ndarray
    nodes_checked: int
    pairs_checked: int
    unchecked_nodes: np.ndarray
    unknown_elements: np.ndarray
    self_contact: bool
    margin: float
    units: str
    seconds: float
    n_nodes: int
    node_ids: np.ndarray | None = field(default=None, repr=False)
    element_ids: np.ndarray | None = field(default=None, repr=False)

    def __len__(self) -> int:
        return len(self.node)

    def penetrating(self) -> Penetrations:
        """The rows with ``depth > 0`` only (all of them when ``margin`` is 0)."""
        keep = self.depth > 0
        fields = ("node", "part", "other_part", "element", "distance", "depth",
                  "node_thickness", "element_thickness")
        kept = {name: getattr(self, name)[keep] for name in fields}
        return Penetrations(**kept, **{name: getattr(self, name) for name in (
            "nodes_checked", "pairs_checked", "unchecked_nodes", "unknown_elements",
            "self_contact", "units", "seconds", "n_nodes", "node_ids", "element_ids")},
            margin=0.0)

    def node_depth(self, fill: float = np.nan) -> np.ndarray:
        """(N,) the largest depth of each node over its rows, ``fill`` where it has none."""
        out = np.full(self.n_nodes, -np.inf)
        np.maximum.at(out, self.node, self.depth)
        out[out == -np.inf] = fill
        return out

    def _node_id(self, index: np.ndarray) -> np.ndarray:
        return index + 1 if self.node_ids is None else self.node_ids[index]

    def _element_id(self, index: np.ndarray) -> np.ndarray:
        return index + 1 if self.element_ids is None else self.element_ids[index]

    def rows(self, limit: int | None = None) -> list[dict]:
        """The table: one dict per row (deepest first, at most ``limit``): node id, part,
        other part, element id, distance, depth, both thicknesses."""
        k = len(self) if limit is None else min(len(self), int(limit))
        nid, eid = self._node_id(self.node[:k]), self._element_id(self.element[:k])
        return [{"node": int(nid[i]), "part": int(self.part[i]),
                 "other_part": int(self.other_part[i]), "element": int(eid[i]),
                 "distance": float(self.distance[i]), "depth": float(self.depth[i]),
                 "node_thickness": float(self.node_thickness[i]),
                 "element_thickness": float(self.element_thickness[i])} for i in range(k)]

    def pairs(self) -> list[dict]:
        """Per (part, other part) with a row: the number of distinct nodes and the largest
        depth, most nodes first."""
        if len(self) == 0:
            return []
        key = np.stack([self.part, self.other_part], axis=1)
        pairs, inverse = np.unique(key, axis=0, return_inverse=True)
        inverse = inverse.ravel()
        out = []
        for g, (a, b) in enumerate(pairs.tolist()):
            rows = inverse == g
            out.append({"part": a, "other_part": b,
                        "nodes": int(len(np.unique(self.node[rows]))),
                        "max_depth": float(self.depth[rows].max())})
        return sorted(out, key=lambda r: (-r["nodes"], -r["max_depth"], r["part"],
                                          r["other_part"]))


# --------------------------------------------------------------------------- the check
def _thickness(mesh, step: int) -> np.ndarray:
    """The checked (M,) element thickness at ``step``; ValueError where it cannot be used."""
    name = "thickness"
    if name in getattr(mesh, "unavailable", {}):
        raise ValueError(f"penetrations need the shell thickness, which {mesh.name} cannot "
                         f"give: {mesh.unavailable[name]}")
    if name not in mesh.element_fields:
        raise ValueError(f"penetrations need the shell thickness: {mesh.name} has no element "
                         f"field 'thickness' (element fields: {sorted(mesh.element_fields)})")
    t = np.asarray(mesh.element_field(name, step), dtype=np.float64)
    bad = np.isinf(t) | (t < 0)
    if bad.any():
        e = np.flatnonzero(bad)
        raise ValueError(f"{mesh.name}: thickness must be finite and >= 0; {len(e)} elements "
                         f"are not, first at element index {int(e[0])} ({t[e[0]]})")
    return t


def node_thickness(mesh, thickness: np.ndarray):
    """Each (node, part) pair of ``mesh`` and the node's thickness in that part (the largest
    known thickness of the part's elements that use it, NaN where none is known):
    ``(node, part_index, t)`` sorted by node, then part; ``part_index`` into the sorted
    distinct part ids."""
    e = np.asarray(mesh.elements, dtype=np.int64)
    ids = distinct(mesh.parts)
    cp = np.searchsorted(ids, np.asarray(mesh.parts)).astype(np.int64)
    key = (e * len(ids) + cp[:, None]).ravel()
    t = np.repeat(thickness, e.shape[1])
    pairs, inverse = np.unique(key, return_inverse=True)
    best = np.full(len(pairs), -np.inf)
    known = np.isfinite(t)
    np.maximum.at(best, inverse.ravel()[known], t[known])
    best[best == -np.inf] = np.nan
    return pairs // len(ids), pairs % len(ids), best


def _named(what: str, index: np.ndarray, ids: np.ndarray | None) -> str:
    shown = (index[:_SHOWN_IDS] + 1) if ids is None else ids[index[:_SHOWN_IDS]]
    more = ", ..." if len(index) > _SHOWN_IDS else ""
    return f"{len(index)} {what} (ids {', '.join(map(str, shown.tolist()))}{more})"


def penetrations(mesh, *, self_contact: bool = False, step: int = 0, margin: float = 0.0,
                 kind: str = "aabb", leaf_size: int = 1) -> Penetrations:
    """Every node closer to an element of another part (and, with ``self_contact``, to a
    non-neighbouring element of its own part) than half the sum of the two thicknesses, at
    time step ``step`` (crash2000 §4.1; definitions, units and refusals in the module notes).

    ``margin`` >= 0 (model units) also reports the pairs within ``margin`` of penetrating
    (``depth > -margin``; a clearance map, as the thickness-aware flange path draws it).
    ``kind`` and ``leaf_size`` choose the element hierarchy (AABB, one element per leaf by
    default). A :class:`PenetrationWarning` names the elements with unknown thickness and the
    nodes that could not be checked.
    """
    t0 = time.perf_counter()
    margin = float(margin)
    if not (np.isfinite(margin) and margin >= 0):
        raise ValueError(f"margin must be a finite distance >= 0, got {margin!r}")
    if kind not in KINDS:
        raise ValueError(f"kind must be one of {KINDS}, got {kind!r}")
    step = mesh.step_index(step)
    thickness = _thickness(mesh, step)
    coords = mesh.coordinates(step)
    used = used_nodes(mesh.elements, mesh.n_nodes)
    ids = distinct(mesh.parts).astype(np.int64)
    unknown_elements = np.flatnonzero(np.isnan(thickness))
    qnode, qpart, qt = node_thickness(mesh, thickness)
    checked = np.isfinite(qt)
    unchecked = np.setdiff1d(qnode[~checked], qnode[checked])
    _warn_unknown(mesh, unknown_elements, unchecked)
    empty = np.zeros(0, np.int64)
    result = dict(nodes_checked=int(len(np.unique(qnode[checked]))),
                  pairs_checked=int(checked.sum()), unchecked_nodes=unchecked,
                  unknown_elements=unknown_elements, self_contact=bool(self_contact),
                  margin=margin, units=mesh.units, n_nodes=mesh.n_nodes,
                  node_ids=mesh.node_ids, element_ids=mesh.element_ids)
    has_triangles = np.bincount(mesh.triangulation.element_of, minlength=mesh.n_elements) > 0
    targets = np.flatnonzero(has_triangles & mesh.alive(step))
    if len(targets) == 0 or not checked.any():
        return Penetrations(empty, empty, empty, empty, np.zeros(0), np.zeros(0), np.zeros(0),
                            np.zeros(0), seconds=time.perf_counter() - t0, **result)
    h = ElementHierarchy(mesh, kind=kind, leaf_size=leaf_size, step=step, elements=targets,
                         origin=local_origin(coords, used))
    half_node = np.where(checked, 0.5 * qt, -1.0)  # -1: not searched
    half_tree = 0.5 * thickness[h.element_order]
    half_tree[np.isnan(half_tree)] = -np.inf
    reach_of = _reach(h, half_tree)
    local = np.ascontiguousarray(coords[qnode] - h.origin)
    # other parts: each pair ignores every part of its node
    ptr, own = node_parts(mesh)
    own_ptr = np.concatenate([[0], np.cumsum(ptr[qnode + 1] - ptr[qnode])]).astype(np.int64)
    rows_of = np.repeat(ptr[qnode], ptr[qnode + 1] - ptr[qnode]) \
        + (np.arange(own_ptr[-1]) - np.repeat(own_ptr[:-1], ptr[qnode + 1] - ptr[qnode]))
    own_idx = h.part_index(own[rows_of])
    anywhere = np.full(len(qnode), -1, np.int64)
    queries = Queries(local, np.where(checked, half_node + margin, -1.0), own_ptr, own_idx,
                      anywhere)
    qi, j, d2, _ = _within(h, queries, reach_of)
    found = [(qi, j, d2)]
    if self_contact:
        found.append(_self_contact(h, mesh, qnode, qpart, ids, half_node, margin, checked,
                                   local, half_tree))
    qi, j, d2 = (np.concatenate(a) for a in zip(*found))
    distance = np.sqrt(d2)
    depth = (half_node[qi] + half_tree[j]) - distance
    keep = depth > -margin
    qi, j, distance, depth = qi[keep], j[keep], distance[keep], depth[keep]
    other = h.element_part[j]
    element = h.element_order[j]
    # per (pair, other part): the deepest element (ties: the lowest element index)
    order = np.lexsort((element, -depth, other, qi))
    sq, so = qi[order], other[order]
    first = np.ones(len(order), bool)
    first[1:] = (sq[1:] != sq[:-1]) | (so[1:] != so[:-1])
    pick = order[first]
    pick = pick[np.lexsort((element[pick], qnode[qi[pick]], -depth[pick]))]
    qp = qi[pick]
    return Penetrations(qnode[qp], ids[qpart[qp]], h.part_ids[other[pick]], element[pick],
                        distance[pick], depth[pick], qt[qp], thickness[element[pick]],
                        seconds=time.perf_counter() - t0, **result)


def _self_contact(h, mesh, qnode, qpart, ids, half_node, margin, checked, local, half_tree):
    """(query, tree-order element, squared distance) of the self-contact candidates of every
    (node, part) pair: elements of its own part within reach and outside its neighbourhood
    (module notes)."""
    n = len(qnode)
    none = np.zeros(n + 1, np.int64)
    in_tree = h.part_index(ids[qpart])
    reach = np.where(checked & (in_tree >= 0), half_node + margin, -1.0)
    cand_q, cand_j, cand_d2, cand_ptr = _within(
        h, Queries(local, reach, none, np.zeros(0, np.int64), in_tree), _reach(h, half_tree))
    if len(cand_q) == 0:
        return cand_q, cand_j, cand_d2
    # the ball: every element of the part closer than t_node/2 + t_max/2 (+ margin)
    part_max = np.full(h.n_parts, -np.inf)
    np.maximum.at(part_max, h.element_part, np.where(np.isfinite(half_tree), half_tree,
                                                     -np.inf))
    has = np.diff(cand_ptr) > 0
    ball_reach = np.where(has, reach + part_max[np.maximum(in_tree, 0)], -1.0)
    ball_reach[~np.isfinite(ball_reach)] = -1.0
    zero = np.zeros(h.n_elements)
    _, ball_j, _, ball_ptr = _within(h, Queries(local, ball_reach, none, np.zeros(0, np.int64),
                                                in_tree), _reach(h, zero))
    keep = np.zeros(len(cand_j), bool)
    _outside_neighbourhood(qnode.astype(np.int64), ball_ptr, ball_j, h.element_nodes, cand_ptr,
                           cand_j, keep)
    return cand_q[keep], cand_j[keep], cand_d2[keep]


def _warn_unknown(mesh, unknown_elements: np.ndarray, unchecked: np.ndarray) -> None:
    """One :class:`PenetrationWarning` naming what unknown thickness leaves out."""
    if len(unknown_elements) == 0 and len(unchecked) == 0:
        return
    words = []
    if len(unknown_elements):
        parts = np.unique(mesh.parts[unknown_elements]).tolist()
        words.append(f"{_named('elements', unknown_elements, mesh.element_ids)} of part"
                     f"{'s' * (len(parts) > 1)} {', '.join(map(str, parts))} have no thickness "
                     f"(NaN) and are not measured against")
    if len(unchecked):
        words.append(f"{_named('nodes', unchecked, mesh.node_ids)} have no element of known "
                     f"thickness and are not checked")
    warnings.warn(PenetrationWarning(f"{mesh.name}: " + "; ".join(words)), stacklevel=3)


@derived_item("penetration_depths", key=lambda margin=0.0, step=0: (float(margin), int(step)),
              from_style=lambda style: (getattr(style, "depth_range", 0.0),
                                        getattr(style, "step", 0)))
def penetration_depths(mesh, margin: float = 0.0, step: int = 0) -> Penetrations:
    """The derived item ``penetration_depths`` (what the thickness-aware flange path needs):
    :func:`penetrations` of step ``step`` with ``margin`` (model units), other parts only,
    kept in the mesh's cache per (margin, step)."""
    return penetrations(mesh, margin=margin, step=step)
