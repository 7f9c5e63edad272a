"""Bounding-volume hierarchies over FE shell elements, one tree per part under one top level.

:class:`ElementHierarchy` is the per-part hierarchy of crash2000 (Sommer & Ertl, §4): for a set
of elements of an :class:`~workbench.scene.mesh.FEMesh` it builds one tree per part and a top
level over the parts, all in one forest of flat arrays that numba traverses.

* **Geometry.** An element is the triangles :attr:`FEMesh.triangulation` gives it (a quad split
  along its shorter diagonal, a triangle as itself, nothing for a topologically degenerate
  element); its bounding volume encloses its corner nodes, which for every element with
  triangles are exactly the triangles' vertices.
* **Bounding volumes** (``kind``): ``"aabb"`` axis-aligned boxes, or ``"obb"`` oriented boxes
  after Gottschalk, Lin & Manocha (*OBBTree*, 1996): the frame is the eigenvector basis of the
  area-weighted covariance of the node's triangles (the vertex covariance where they have no
  area), made exactly right-handed and orthonormal (a node whose elements span no plane, a
  segment or a point, takes its parent's frame); the extents come from projecting every
  corner node onto that frame. Any orthonormal frame encloses the nodes, so degenerate and
  planar parts only change how tight the box is: a planar part gets one axis along its normal
  with (nearly) zero extent. Every box is widened by a few units in the last place of the
  coordinates so that rounding never excludes a point it should contain.
* **Trees.** Top down, a node's elements (its parts, at the top level) are split at the median
  of their centres along the longest axis of the centres' box (``"aabb"``) or the principal
  axis of the centres (``"obb"``, as Gottschalk splits), until a node holds at most
  ``leaf_size`` elements. A tree over n elements therefore has the same number of nodes for both
  kinds (2n − 1 with one element per leaf). The top level is a tree of the same kind over the
  parts whose leaves *are* the parts' roots: each top node encloses whole parts, each part's
  subtree only that part, so a query can skip a part (its own, say) at its root.
* **Layout.** Nodes are numbered top level first (``P − 1`` nodes for P parts, breadth first),
  then each part's tree, breadth first with siblings adjacent. Every node covers a contiguous
  range ``start[i]:end[i]`` of the elements in tree order (:attr:`element_order` gives their
  mesh indices), so a leaf's elements are read in one sweep.

Queries (exact in float64; lengths in the mesh's units, millimetres for crash decks):

* :meth:`ElementHierarchy.nearest` -- for each point the nearest element within a cut-off,
  optionally skipping some parts per point (crash2000 §4.1, also the counters of its Table 2).
  Branch and bound, iterative with a small stack, the nearer child first; inside a leaf an
  element whose *slab* (the element between two parallel planes along its normal, see
  :attr:`slab`) is already farther than the best distance so far is skipped without computing
  its exact distance (the paper's point-to-plane test).
* :meth:`ElementHierarchy.cut_by_plane` -- the elements a plane cuts (crash2000 §4.2, section
  planes of force tubes), visiting only the bounding volumes the plane meets.

The hierarchy is built in coordinates relative to a float64 origin near the model (the centre
of the bounding box of its nodes unless given), so that models far from the origin keep their
digits; queries take and return the mesh's own coordinates.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numba
import numpy as np

from .distance import closest_point_on_triangle

__all__ = ["KINDS", "ElementHierarchy", "NearestElements", "distinct", "local_origin",
           "squared_bound", "used_nodes"]

KINDS = ("aabb", "obb")
_CHUNK = 64  # points per parallel work item
_EPS = np.finfo(np.float64).eps
# boxes and slabs are widened by this many units in the last place of the largest coordinate
_PAD_ULPS = 64.0
# and a box or slab is pruned only when its squared distance exceeds the bound by this share
_SLACK = 1.0 + 1e-12
_SLACK_DIV = 1.0 / _SLACK  # pruned when d2 * _SLACK_DIV >= best


def local_origin(coordinates: np.ndarray, nodes: np.ndarray) -> np.ndarray:
    """(3,) float64 centre of the axis-aligned bounding box of ``coordinates[nodes]``: the origin
    every query here subtracts before it computes, so that results keep their digits far from
    the global origin. Two computations on the same nodes with the same origin see bitwise the
    same local coordinates."""
    pts = coordinates[nodes]
    return 0.5 * (pts.min(axis=0) + pts.max(axis=0))


def squared_bound(cutoff: float) -> float:
    """The largest float64 b with sqrt(b) <= ``cutoff`` (inf for inf): a squared distance d2 is
    within the cut-off exactly when d2 <= b, so a search may compare squared distances."""
    if cutoff == np.inf:
        return np.inf
    b = float(cutoff) * float(cutoff)
    while b > 0 and np.sqrt(b) > cutoff:
        b = float(np.nextafter(b, 0.0))
    while np.sqrt(np.nextafter(b, np.inf)) <= cutoff:
        b = float(np.nextafter(b, np.inf))
    return b


@dataclass
class NearestElements:
    """Result of :meth:`ElementHierarchy.nearest`.

    ``distance`` (P,) float64 exact distance to the nearest eligible element within the cut-off
    (inf when there is none or the point was not queried), ``element`` (P,) int64 its mesh
    element index (-1 where none), ``part`` (P,) int64 its part id (-1 where none) and the
    per-point counters summed: ``bv_tests`` point/bounding-volume distances computed,
    ``element_tests`` exact point/element distances computed, ``plane_skips`` elements skipped
    by the slab test, ``leaf_elements`` elements of the leaves the search opened (every one of
    them is either tested or skipped, so ``element_tests + plane_skips == leaf_elements`` for a
    hierarchy of elements with triangles).
    """

    distance: np.ndarray
    element: np.ndarray
    part: np.ndarray
    bv_tests: int
    element_tests: int
    plane_skips: int
    leaf_elements: int


class ElementHierarchy:
    """A forest of bounding-volume trees over elements of ``mesh``, one tree per part under a
    top level over the parts (see the module notes for the layout).

    ``kind`` "aabb" or "obb"; ``leaf_size`` the most elements per leaf (1 as in the upper half
    of crash2000's Table 2, 10 as in the lower); ``step`` the time step whose coordinates are
    used (the quads are split as :attr:`FEMesh.triangles` splits them, on the reference nodes,
    so that every step has the same triangles); ``elements`` the mesh indices of the elements to
    enclose (default all, degenerate ones included: they take part in :meth:`cut_by_plane` and
    have no triangles for :meth:`nearest`); ``origin`` the float64 point subtracted from every
    coordinate (default :func:`local_origin` of the enclosed elements' nodes).

    Refused with ValueError: an unknown ``kind``, ``leaf_size`` < 1 or not an integer, a step
    outside the mesh's steps, an empty, repeated or out-of-range ``elements`` selection,
    NaN/inf coordinates of a node the selected elements use, a non-finite ``origin``.

    Attributes: ``kind``, ``leaf_size``, ``step``, ``origin`` (3,), ``part_ids`` (P,) the part
    ids in the hierarchy (sorted; a part's *index* is its position here), ``part_roots`` (P,)
    each part's root node, ``root`` the forest's root, ``element_order`` (E,) mesh element
    indices in tree order, ``left``/``right`` (nodes,) children (-1 for a leaf),
    ``start``/``end`` (nodes,) each node's range in ``element_order``, ``node_part`` (nodes,)
    the part index of a part-tree node (-1 at the top level), ``bv`` the packed boxes
    (AABB: lo, hi; OBB: centre, three axes as rows, half extents; local coordinates),
    ``slab`` (E, 5) each element's unit normal and the interval of normal·x over its nodes
    (local coordinates), ``corners`` (E, 2, 3, 3) and ``n_tri`` (E,) each element's triangles
    (local coordinates), ``element_part`` (E,) and ``element_nodes`` (E, 4) each element's part
    index and nodes, ``n_bvs`` bounding volumes in the part trees (the count of crash2000's
    Table 2), ``n_top_bvs`` those of the top level, ``depth`` the most nodes on a root-to-leaf
    path, ``max_leaf`` the most elements in a leaf, ``scale`` the largest local coordinate and
    ``pad`` the widening of boxes and slabs, ``build_s`` seconds the build took. The
    hierarchy keeps the step's coordinates it was built from (for :meth:`cut_by_plane`); it
    bounds those coordinates only, so another step needs its own hierarchy.
    """

    def __init__(self, mesh, *, kind: str = "aabb", leaf_size: int = 1, step: int = 0,
                 elements=None, origin=None):
        t0 = time.perf_counter()
        if kind not in KINDS:
            raise ValueError(f"kind must be one of {KINDS}, got {kind!r}")
        if isinstance(leaf_size, (bool, np.bool_)) or int(leaf_size) != leaf_size or leaf_size < 1:
            raise ValueError(f"leaf_size must be an integer >= 1, got {leaf_size!r}")
        self.kind = kind
        self.leaf_size = int(leaf_size)
        self.step = check_step(mesh, step)
        m = len(mesh.elements)
        if elements is None:
            sel = np.arange(m, dtype=np.int64)
        else:
            sel = np.asarray(elements)
            if sel.ndim != 1 or (sel.size and not np.issubdtype(sel.dtype, np.integer)):
                raise ValueError(f"elements must be a 1-D array of element indices, got "
                                 f"{sel.dtype} {sel.shape}")
            sel = sel.astype(np.int64)
            if sel.size and (sel.min() < 0 or sel.max() >= m):
                raise ValueError(f"elements must lie in [0, {m}), got {sel.min()}..{sel.max()}")
            if len(distinct(sel)) != len(sel):
                raise ValueError("elements must not repeat an element")
        if len(sel) == 0:
            raise ValueError("an element hierarchy needs at least one element; got none")
        coords = mesh.coordinates(self.step)
        enodes = np.asarray(mesh.elements, dtype=np.int64)[sel]  # (E, 4)
        used = used_nodes(enodes, len(mesh.nodes))
        check_finite(coords, used)
        if origin is None:
            origin = local_origin(coords, used)
        origin = np.asarray(origin, dtype=np.float64).reshape(-1)
        if origin.shape != (3,) or not np.isfinite(origin).all():
            raise ValueError(f"origin must be 3 finite coordinates, got {origin!r}")
        self.origin = origin.copy()
        self._coords = np.ascontiguousarray(coords, dtype=np.float64)
        local = np.zeros_like(self._coords)
        local[used] = self._coords[used] - origin
        self.scale = float(np.abs(local[used]).max())
        pad = _PAD_ULPS * _EPS * max(self.scale, np.finfo(np.float64).tiny)
        self.pad = pad

        # triangles of each selected element (the mesh's own triangulation)
        tr = mesh.triangulation
        tri_count_all = np.bincount(tr.element_of, minlength=m)
        tri_first_all = np.concatenate([[0], np.cumsum(tri_count_all)[:-1]])
        n_tri = tri_count_all[sel].astype(np.int64)
        corners = np.zeros((len(sel), 2, 3, 3))
        for t in range(2):
            has = n_tri > t
            k = tri_first_all[sel[has]] + t
            corners[has, t] = local[np.asarray(tr.triangles)[k].astype(np.int64)]
        verts = local[enodes]  # (E, 4, 3)
        slab = _slabs(corners, n_tri, verts, pad)

        parts_all = np.asarray(mesh.parts)[sel]
        self.part_ids = distinct(parts_all).astype(np.int64)
        pidx = np.searchsorted(self.part_ids, parts_all)
        n_parts = len(self.part_ids)
        principal = kind == "obb"

        # top level over the parts: centres of the parts' node boxes
        lo = np.full((n_parts, 3), np.inf)
        hi = np.full((n_parts, 3), -np.inf)
        np.minimum.at(lo, pidx, verts.min(axis=1))
        np.maximum.at(hi, pidx, verts.max(axis=1))
        top_perm, top_left, top_start, top_end = _build_tree(0.5 * (lo + hi), 1, principal)
        part_order = top_perm  # parts in the order their elements are laid out
        centres = verts.mean(axis=1)
        by_part = np.argsort(pidx, kind="stable")
        bounds = np.concatenate([[0], np.cumsum(np.bincount(pidx, minlength=n_parts))])
        n_top = n_parts - 1
        order_parts, lefts, starts, ends, node_parts = [], [], [], [], []
        part_roots = np.empty(n_parts, np.int64)
        offset_nodes, offset_elems = n_top, 0
        depth_parts = 0
        for q in part_order:
            members = by_part[bounds[q]:bounds[q + 1]]
            perm, left, start, end = _build_tree(centres[members], self.leaf_size, principal)
            order_parts.append(members[perm])
            lefts.append(np.where(left >= 0, left + offset_nodes, -1))
            starts.append(start + offset_elems)
            ends.append(end + offset_elems)
            node_parts.append(np.full(len(left), q, np.int64))
            part_roots[q] = offset_nodes
            depth_parts = max(depth_parts, int(_tree_depth(left)))
            offset_nodes += len(left)
            offset_elems += len(members)
        # element offsets of the parts in layout position order
        sizes = np.array([bounds[q + 1] - bounds[q] for q in part_order], np.int64)
        part_first = np.concatenate([[0], np.cumsum(sizes)])
        n_nodes = offset_nodes
        left = np.full(n_nodes, -1, np.int64)
        right = np.full(n_nodes, -1, np.int64)
        start = np.empty(n_nodes, np.int64)
        end = np.empty(n_nodes, np.int64)
        node_part = np.full(n_nodes, -1, np.int64)
        if n_parts > 1:
            # top inner nodes keep their breadth-first order; top leaves are the part roots
            inner = np.flatnonzero(top_left >= 0)
            gid = np.empty(len(top_left), np.int64)
            gid[inner] = np.arange(len(inner))
            leaves = np.flatnonzero(top_left < 0)
            gid[leaves] = part_roots[part_order[top_start[leaves]]]
            left[gid[inner]] = gid[top_left[inner]]
            right[gid[inner]] = gid[top_left[inner] + 1]
            start[gid[inner]] = part_first[top_start[inner]]
            end[gid[inner]] = part_first[top_end[inner]]
        for q, lft, s, e, npart in zip(part_order, lefts, starts, ends, node_parts):
            r0 = part_roots[q]
            idx = np.arange(r0, r0 + len(lft))
            left[idx] = lft
            right[idx] = np.where(lft >= 0, lft + 1, -1)
            start[idx] = s
            end[idx] = e
            node_part[idx] = npart
        tree_order = np.concatenate(order_parts)
        self.element_order = sel[tree_order]
        self.root = 0 if n_parts > 1 else int(part_roots[0])
        self.part_roots = part_roots
        self.left, self.right, self.start, self.end = left, right, start, end
        self.node_part = node_part
        self.n_top_bvs = n_top
        is_leaf = left < 0
        self.max_leaf = int((end[is_leaf] - start[is_leaf]).max())
        self.n_bvs = n_nodes - n_top
        self.depth = depth_parts + (int(_tree_depth(top_left)) - 1 if n_parts > 1 else 0)
        self.element_part = pidx[tree_order].astype(np.int64)
        self.n_tri = np.ascontiguousarray(n_tri[tree_order])
        self.corners = np.ascontiguousarray(corners[tree_order])
        self.slab = np.ascontiguousarray(slab[tree_order])
        self.element_nodes = np.ascontiguousarray(enodes[tree_order])
        v = np.ascontiguousarray(verts[tree_order])
        if kind == "aabb":
            self.bv = _aabb_boxes(v, left, right, start, end, pad)
        else:
            cov, ref = _covariances(self.corners, self.n_tri, v, start, end)
            val, vec = np.linalg.eigh(cov)  # ascending eigenvalues, vectors in columns
            axes = np.ascontiguousarray(vec[:, :, ::-1].transpose(0, 2, 1))  # rows, major first
            # a node whose elements span no plane (a segment, a point) has no normal of its
            # own: it takes its parent's frame, which on a planar part is the part's plane
            flat = ~(val[:, 1] > 1e-12 * val[:, 2])
            _inherit_frames(axes, flat, left, right)
            self.bv = _obb_boxes(v, start, end, axes, ref, pad)
        self.build_s = time.perf_counter() - t0

    # ----------------------------------------------------------------- sizes and boxes
    @property
    def n_parts(self) -> int:
        return len(self.part_ids)

    @property
    def n_elements(self) -> int:
        return len(self.element_order)

    @property
    def n_nodes(self) -> int:
        return len(self.left)

    def boxes(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(centres (nodes, 3) in the mesh's coordinates, axes (nodes, 3, 3) unit rows,
        half extents (nodes, 3)) of every bounding volume; an AABB has the identity axes."""
        n = self.n_nodes
        if self.kind == "aabb":
            lo, hi = self.bv[:, 0:3], self.bv[:, 3:6]
            axes = np.broadcast_to(np.eye(3), (n, 3, 3)).copy()
            return 0.5 * (lo + hi) + self.origin, axes, 0.5 * (hi - lo)
        return (self.bv[:, 0:3] + self.origin, self.bv[:, 3:12].reshape(n, 3, 3).copy(),
                self.bv[:, 12:15].copy())

    def part_nodes(self, part_id: int) -> np.ndarray:
        """Indices of the nodes of part ``part_id``'s tree (its root first)."""
        q = np.searchsorted(self.part_ids, part_id)
        if q >= self.n_parts or self.part_ids[q] != part_id:
            raise ValueError(f"part {part_id} is not in the hierarchy")
        return np.flatnonzero(self.node_part == q)

    # ----------------------------------------------------------------- queries
    def nearest(self, points, cutoff: float = np.inf, *, exclude=None, active=None,
                plane_test: bool = True) -> NearestElements:
        """The nearest element within ``cutoff`` of every point (crash2000 §4.1).

        ``points`` (P, 3) float64 in the mesh's coordinates; ``cutoff`` the distance of interest
        (elements farther are not reported; inf for none); ``exclude`` an optional pair
        ``(ptr, part_ids)`` in CSR form: point i ignores the parts
        ``part_ids[ptr[i]:ptr[i + 1]]`` (ids not in the hierarchy are ignored); ``active``
        optional (P,) bool, points not active are not searched (inf, -1, no counts);
        ``plane_test`` whether the slab test may skip elements. Distances are exact float64
        (the elements' triangles through
        :func:`~workbench.algo.distance.closest_point_on_triangle`, local coordinates); among
        elements at exactly the same distance the first one the search meets wins. The search
        runs in parallel over points; results and counters do not depend on the thread count.

        Refused with ValueError: points that are not (P, 3) or not finite where active, a
        NaN, negative or zero cutoff, a malformed ``exclude`` or ``active``.
        """
        p, act = self._points(points, active)
        n = len(p)
        if not cutoff > 0:
            raise ValueError(f"cutoff must be > 0, got {cutoff!r}")
        ptr, own = self._exclusion(exclude, n)
        local = np.where(act[:, None], p - self.origin, 0.0)
        bound = squared_bound(cutoff)
        best0 = float(np.nextafter(bound, np.inf))
        d2 = np.empty(n)
        elem = np.empty(n, np.int64)
        counters = np.zeros((n, 4), np.int64)
        _nearest_many(np.ascontiguousarray(local), act, ptr, own, best0, self.bv,
                      self.kind == "obb", self.left, self.right, self.start, self.end,
                      self.node_part, self.root, self.corners, self.n_tri, self.slab,
                      bool(plane_test), self.depth, self.max_leaf, d2, elem, counters)
        found = elem >= 0
        distance = np.where(found, np.sqrt(np.where(found, d2, 0.0)), np.inf)
        element = np.where(found, self.element_order[np.maximum(elem, 0)], -1)
        part = np.where(found, self.part_ids[self.element_part[np.maximum(elem, 0)]], -1)
        c = counters.sum(axis=0)
        return NearestElements(distance, element.astype(np.int64), part.astype(np.int64),
                               int(c[0]), int(c[1]), int(c[2]), int(c[3]))

    @staticmethod
    def _points(points, active) -> tuple[np.ndarray, np.ndarray]:
        """Checked (P, 3) float64 points and (P,) bool active mask."""
        p = np.asarray(points, dtype=np.float64)
        if p.ndim != 2 or p.shape[1] != 3:
            raise ValueError(f"points must be (P, 3), got shape {p.shape}")
        n = len(p)
        if active is None:
            act = np.ones(n, bool)
        else:
            act = np.asarray(active)
            if act.shape != (n,) or act.dtype != bool:
                raise ValueError(f"active must be ({n},) bool, got {act.dtype} {act.shape}")
        if not np.isfinite(p[act]).all():
            raise ValueError("points: non-finite coordinates")
        return p, act

    def _exclusion(self, exclude, n: int) -> tuple[np.ndarray, np.ndarray]:
        """Checked CSR ``(ptr, part indices)`` of the parts each of n points ignores."""
        if exclude is None:
            return np.zeros(n + 1, np.int64), np.zeros(0, np.int64)
        ptr, ids = (np.asarray(a) for a in exclude)
        if ptr.shape != (n + 1,) or not np.issubdtype(ptr.dtype, np.integer) \
                or ptr[0] != 0 or (np.diff(ptr) < 0).any() or ptr[-1] != len(ids) \
                or ids.ndim != 1 or (len(ids) and not np.issubdtype(ids.dtype, np.integer)):
            raise ValueError(f"exclude: ptr must be ({n + 1},) non-decreasing integers from 0 to "
                             f"len(part_ids), part_ids 1-D integers")
        return ptr.astype(np.int64), self.part_index(ids)

    def part_index(self, part_ids) -> np.ndarray:
        """(K,) int64 position of each id in :attr:`part_ids`, -1 for ids not in the
        hierarchy."""
        ids = np.asarray(part_ids).astype(np.int64).reshape(-1)
        q = np.minimum(np.searchsorted(self.part_ids, ids), self.n_parts - 1)
        return np.where(self.part_ids[q] == ids, q, -1).astype(np.int64)

    def nearest_per_part(self, points, cutoff: float, *, exclude=None, active=None):
        """For every point, each part (not excluded) within ``cutoff`` and the exact distance to
        its nearest element: ``(point, part_id, distance)`` arrays sorted by point, then part.
        The connectivity matrices of crash2000 §4.1 come from these rows. Arguments and
        refusals as in :meth:`nearest` (``cutoff`` must be finite here)."""
        p, act = self._points(points, active)
        n = len(p)
        if not (np.isfinite(cutoff) and cutoff > 0):
            raise ValueError(f"cutoff must be finite and > 0, got {cutoff!r}")
        ptr, own = self._exclusion(exclude, n)
        local = np.ascontiguousarray(np.where(act[:, None], p - self.origin, 0.0))
        best0 = float(np.nextafter(squared_bound(cutoff), np.inf))
        args = (local, act, ptr, own, best0, self.bv, self.kind == "obb", self.left,
                self.right, self.start, self.end, self.node_part, self.root, self.corners,
                self.n_tri, self.slab, self.depth, self.max_leaf)
        counts = np.zeros(n, np.int64)
        dummy_p = np.zeros(0, np.int64)
        dummy_d = np.zeros(0)
        _per_part_many(*args, np.zeros(n + 1, np.int64), counts, dummy_p, dummy_d, False)
        offsets = np.concatenate([[0], np.cumsum(counts)])
        out_p = np.empty(offsets[-1], np.int64)
        out_d = np.empty(offsets[-1])
        _per_part_many(*args, offsets, counts, out_p, out_d, True)
        point = np.repeat(np.arange(n, dtype=np.int64), counts)
        key = np.lexsort((out_p, point))
        return point[key], self.part_ids[out_p[key]], np.sqrt(out_d[key])

    def cut_by_plane(self, point, normal) -> np.ndarray:
        """Sorted int64 mesh indices of the enclosed elements whose nodes are not all strictly on
        one side of the plane through ``point`` (3,) with ``normal`` (3,) (crash2000 §4.2).

        A node's side is the sign of ``s = (x − px)·nx + (y − py)·ny + (z − pz)·nz``, evaluated
        in float64 in that order on the mesh's coordinates with ``normal`` as given (not
        normalised); an element is cut unless all its nodes have s > 0 or all have s < 0 (a
        node on the plane cuts). Only bounding volumes the plane meets are opened (their test
        errs on the side of opening). Refused with ValueError: a non-finite point or normal, a
        zero normal.
        """
        q = np.asarray(point, dtype=np.float64).reshape(-1)
        nrm = np.asarray(normal, dtype=np.float64).reshape(-1)
        if q.shape != (3,) or not np.isfinite(q).all():
            raise ValueError(f"point must be 3 finite coordinates, got {point!r}")
        if nrm.shape != (3,) or not np.isfinite(nrm).all():
            raise ValueError(f"normal must be 3 finite numbers, got {normal!r}")
        big = float(np.abs(nrm).max())
        if not big > 0:
            raise ValueError("normal must not be zero")
        unit = nrm / big  # scaled first: no overflow or underflow in the length
        unit = unit / np.sqrt((unit * unit).sum())
        ql = q - self.origin
        tol = 1e-12 * (float(np.abs(q).max()) + float(np.abs(self.origin).max()) + self.scale)
        out = np.empty(self.n_elements, np.int64)
        k = _cut(ql, unit, tol, q, nrm, self.bv, self.kind == "obb", self.left, self.right,
                 self.start, self.end, self.root, self.depth, self.element_nodes, self._coords,
                 out)
        return np.sort(self.element_order[out[:k]])


# --------------------------------------------------------------------------- validation helpers
def check_step(mesh, step) -> int:
    """``step`` as an int in [0, mesh.n_steps); ValueError otherwise."""
    if isinstance(step, (bool, np.bool_)) or int(step) != step or not 0 <= step < mesh.n_steps:
        raise ValueError(f"step must be an integer in [0, {mesh.n_steps}), got {step!r}")
    return int(step)


def distinct(values) -> np.ndarray:
    """Sorted distinct values of an integer array (by sorting, quick for integer ids)."""
    v = np.sort(np.asarray(values).ravel())
    return v[np.r_[True, v[1:] != v[:-1]]] if len(v) else v


def used_nodes(elements, n_nodes: int) -> np.ndarray:
    """Sorted int64 indices of the nodes that ``elements`` (any shape of node indices) use."""
    mask = np.zeros(n_nodes, bool)
    mask[np.asarray(elements).ravel()] = True
    return np.flatnonzero(mask)


def check_finite(coords: np.ndarray, used: np.ndarray) -> None:
    """ValueError naming the first few of ``used`` nodes whose coordinates are NaN or inf."""
    ok = np.isfinite(coords[used]).all(axis=1)
    if not ok.all():
        raise ValueError(f"non-finite coordinates at used nodes {used[~ok][:5].tolist()}")


# --------------------------------------------------------------------------- build (numpy)
def _slabs(corners, n_tri, verts, pad) -> np.ndarray:
    """(E, 5): unit normal and [lo, hi] of normal·x over each element's nodes, widened by pad.
    The normal is the sum of the triangles' cross products; an element without area takes a
    direction across its longest edge (any unit vector bounds the distance)."""
    a, b, c = corners[:, :, 0], corners[:, :, 1], corners[:, :, 2]
    cross = np.cross(b - a, c - a) * (np.arange(2)[None, :] < n_tri[:, None])[:, :, None]
    n = cross.sum(axis=1)
    length = np.sqrt((n * n).sum(axis=1))
    ok = length > 0
    normal = np.zeros_like(n)
    normal[ok] = n[ok] / length[ok, None]
    if not ok.all():
        v = verts[~ok]
        edges = v[:, [1, 2, 3, 0]] - v
        longest = edges[np.arange(len(v)), np.argmax((edges * edges).sum(axis=2), axis=1)]
        helper = np.eye(3)[np.argmin(np.abs(longest), axis=1)]
        alt = np.cross(longest, helper)
        alt_len = np.sqrt((alt * alt).sum(axis=1))
        alt = np.where(alt_len[:, None] > 0, alt / np.where(alt_len > 0, alt_len, 1)[:, None],
                       np.array([1.0, 0.0, 0.0]))
        normal[~ok] = alt
    s = np.einsum("eij,ej->ei", verts, normal)
    return np.concatenate([normal, (s.min(axis=1) - pad)[:, None],
                           (s.max(axis=1) + pad)[:, None]], axis=1)


@numba.njit(cache=True)
def _tree_depth(left):
    """Most nodes on a root-to-leaf path of a breadth-first tree (children at left, left+1)."""
    depth = np.ones(len(left), np.int64)
    for i in range(len(left)):  # parents precede children in breadth-first order
        if left[i] >= 0:
            depth[left[i]] = depth[i] + 1
            depth[left[i] + 1] = depth[i] + 1
    return depth.max()


# --------------------------------------------------------------------------- build (numba)
@numba.njit(cache=True)
def _split_axis(centres, perm, s, e, principal):
    """Unit split direction for centres[perm[s:e]]: the longest axis of their box, or (when
    ``principal``) the dominant eigenvector of their covariance by power iteration from it."""
    lo0 = lo1 = lo2 = np.inf
    hi0 = hi1 = hi2 = -np.inf
    for i in range(s, e):
        j = perm[i]
        x, y, z = centres[j, 0], centres[j, 1], centres[j, 2]
        lo0, hi0 = min(lo0, x), max(hi0, x)
        lo1, hi1 = min(lo1, y), max(hi1, y)
        lo2, hi2 = min(lo2, z), max(hi2, z)
    v0, v1, v2 = 1.0, 0.0, 0.0
    if hi1 - lo1 > hi0 - lo0 and hi1 - lo1 >= hi2 - lo2:
        v0, v1 = 0.0, 1.0
    elif hi2 - lo2 > hi0 - lo0 and hi2 - lo2 > hi1 - lo1:
        v0, v2 = 0.0, 1.0
    if principal:
        n = e - s
        m0 = m1 = m2 = 0.0
        for i in range(s, e):
            j = perm[i]
            m0 += centres[j, 0]
            m1 += centres[j, 1]
            m2 += centres[j, 2]
        m0 /= n
        m1 /= n
        m2 /= n
        c00 = c01 = c02 = c11 = c12 = c22 = 0.0
        for i in range(s, e):
            j = perm[i]
            x, y, z = centres[j, 0] - m0, centres[j, 1] - m1, centres[j, 2] - m2
            c00 += x * x
            c01 += x * y
            c02 += x * z
            c11 += y * y
            c12 += y * z
            c22 += z * z
        for _ in range(32):
            w0 = c00 * v0 + c01 * v1 + c02 * v2
            w1 = c01 * v0 + c11 * v1 + c12 * v2
            w2 = c02 * v0 + c12 * v1 + c22 * v2
            length = np.sqrt(w0 * w0 + w1 * w1 + w2 * w2)
            if not length > 0:
                break
            v0, v1, v2 = w0 / length, w1 / length, w2 / length
    axis = np.empty(3)
    axis[0], axis[1], axis[2] = v0, v1, v2
    return axis


@numba.njit(cache=True)
def _select(keys, perm, s, e, k):
    """Reorder perm[s:e] (keys alongside) so that keys[s:k] <= keys[k] <= keys[k+1:e]: a
    three-way quickselect (many equal keys on regular meshes), pivot the median of three."""
    lo, hi = s, e - 1
    while lo < hi:
        a, b, c = keys[lo], keys[(lo + hi) // 2], keys[hi]
        pivot = max(min(a, b), min(max(a, b), c))
        lt, i, gt = lo, lo, hi
        while i <= gt:
            if keys[i] < pivot:
                keys[lt], keys[i] = keys[i], keys[lt]
                perm[lt], perm[i] = perm[i], perm[lt]
                lt += 1
                i += 1
            elif keys[i] > pivot:
                keys[gt], keys[i] = keys[i], keys[gt]
                perm[gt], perm[i] = perm[i], perm[gt]
                gt -= 1
            else:
                i += 1
        if k < lt:
            hi = lt - 1
        elif k > gt:
            lo = gt + 1
        else:
            return


@numba.njit(cache=True)
def _build_tree(centres, leaf_size, principal):
    """Median-split tree over the rows of ``centres``: (perm, left, start, end) with nodes in
    breadth-first order, children of node i at left[i] and left[i] + 1 (-1 for a leaf), and
    node i covering perm[start[i]:end[i]]."""
    n = len(centres)
    cap = 2 * n
    perm = np.arange(n)
    keys = np.empty(n)
    left = np.full(cap, -1, np.int64)
    start = np.empty(cap, np.int64)
    end = np.empty(cap, np.int64)
    start[0], end[0] = 0, n
    n_nodes = 1
    head = 0
    while head < n_nodes:
        s, e = start[head], end[head]
        count = e - s
        if count > leaf_size:
            axis = _split_axis(centres, perm, s, e, principal)
            for i in range(s, e):
                j = perm[i]
                keys[i] = centres[j, 0] * axis[0] + centres[j, 1] * axis[1] \
                    + centres[j, 2] * axis[2]
            mid = s + count // 2
            _select(keys, perm, s, e, mid)
            left[head] = n_nodes
            start[n_nodes], end[n_nodes] = s, mid
            start[n_nodes + 1], end[n_nodes + 1] = mid, e
            n_nodes += 2
        head += 1
    return perm, left[:n_nodes].copy(), start[:n_nodes].copy(), end[:n_nodes].copy()


@numba.njit(cache=True)
def _aabb_boxes(verts, left, right, start, end, pad):
    """(nodes, 6) boxes lo, hi: leaves from their elements' nodes (widened by pad), inner
    nodes from their children (children have larger indices than their parents)."""
    n = len(start)
    bv = np.empty((n, 6))
    for i in range(n - 1, -1, -1):
        if left[i] >= 0:
            c0, c1 = left[i], right[i]
            for k in range(3):
                bv[i, k] = min(bv[c0, k], bv[c1, k])
                bv[i, 3 + k] = max(bv[c0, 3 + k], bv[c1, 3 + k])
            continue
        for k in range(3):
            lo = np.inf
            hi = -np.inf
            for j in range(start[i], end[i]):
                for c in range(4):
                    x = verts[j, c, k]
                    lo = min(lo, x)
                    hi = max(hi, x)
            bv[i, k] = lo - pad
            bv[i, 3 + k] = hi + pad
    return bv


@numba.njit(cache=True, parallel=True)
def _covariances(corners, n_tri, verts, start, end):
    """(nodes, 3, 3) covariance of each node's surface (area-weighted over its triangles,
    Gottschalk's continuous formula; the vertex covariance where the area is zero) and the
    reference point (nodes, 3) it was taken about."""
    n = len(start)
    cov = np.zeros((n, 3, 3))
    ref = np.empty((n, 3))
    for i in numba.prange(n):
        r0, r1, r2 = verts[start[i], 0, 0], verts[start[i], 0, 1], verts[start[i], 0, 2]
        ref[i, 0], ref[i, 1], ref[i, 2] = r0, r1, r2
        area = 0.0
        s0 = s1 = s2 = 0.0
        q00 = q01 = q02 = q11 = q12 = q22 = 0.0
        for j in range(start[i], end[i]):
            for t in range(n_tri[j]):
                ax, ay, az = corners[j, t, 0, 0] - r0, corners[j, t, 0, 1] - r1, \
                    corners[j, t, 0, 2] - r2
                bx, by, bz = corners[j, t, 1, 0] - r0, corners[j, t, 1, 1] - r1, \
                    corners[j, t, 1, 2] - r2
                cx, cy, cz = corners[j, t, 2, 0] - r0, corners[j, t, 2, 1] - r1, \
                    corners[j, t, 2, 2] - r2
                ux, uy, uz = bx - ax, by - ay, bz - az
                wx, wy, wz = cx - ax, cy - ay, cz - az
                x0 = uy * wz - uz * wy
                x1 = uz * wx - ux * wz
                x2 = ux * wy - uy * wx
                ar = 0.5 * np.sqrt(x0 * x0 + x1 * x1 + x2 * x2)
                if ar == 0.0:
                    continue
                mx, my, mz = (ax + bx + cx) / 3.0, (ay + by + cy) / 3.0, (az + bz + cz) / 3.0
                area += ar
                s0 += ar * mx
                s1 += ar * my
                s2 += ar * mz
                f = ar / 12.0
                q00 += f * (9.0 * mx * mx + ax * ax + bx * bx + cx * cx)
                q01 += f * (9.0 * mx * my + ax * ay + bx * by + cx * cy)
                q02 += f * (9.0 * mx * mz + ax * az + bx * bz + cx * cz)
                q11 += f * (9.0 * my * my + ay * ay + by * by + cy * cy)
                q12 += f * (9.0 * my * mz + ay * az + by * bz + cy * cz)
                q22 += f * (9.0 * mz * mz + az * az + bz * bz + cz * cz)
        if not area > 0.0:  # no area: the covariance of the corner nodes
            area = 0.0
            s0 = s1 = s2 = 0.0
            q00 = q01 = q02 = q11 = q12 = q22 = 0.0
            for j in range(start[i], end[i]):
                for c in range(4):
                    x, y, z = verts[j, c, 0] - r0, verts[j, c, 1] - r1, verts[j, c, 2] - r2
                    area += 1.0
                    s0 += x
                    s1 += y
                    s2 += z
                    q00 += x * x
                    q01 += x * y
                    q02 += x * z
                    q11 += y * y
                    q12 += y * z
                    q22 += z * z
        m0, m1, m2 = s0 / area, s1 / area, s2 / area
        cov[i, 0, 0] = q00 / area - m0 * m0
        cov[i, 0, 1] = cov[i, 1, 0] = q01 / area - m0 * m1
        cov[i, 0, 2] = cov[i, 2, 0] = q02 / area - m0 * m2
        cov[i, 1, 1] = q11 / area - m1 * m1
        cov[i, 1, 2] = cov[i, 2, 1] = q12 / area - m1 * m2
        cov[i, 2, 2] = q22 / area - m2 * m2
    return cov, ref


@numba.njit(cache=True)
def _inherit_frames(axes, flat, left, right):
    """axes[c] = axes[parent] for every child c marked ``flat`` (parents precede children)."""
    for i in range(len(left)):
        if left[i] >= 0:
            for c in (left[i], right[i]):
                if flat[c]:
                    axes[c] = axes[i]


@numba.njit(cache=True, parallel=True)
def _obb_boxes(verts, start, end, axes_in, ref, pad):
    """(nodes, 15) OBBs: centre, three orthonormal axes (rows, right-handed) and half extents
    from projecting every node of the node's elements onto the frame ``axes_in``."""
    n = len(start)
    bv = np.empty((n, 15))
    for i in numba.prange(n):
        # re-orthonormalise: a0 unit, a1 unit and orthogonal to a0, a2 = a0 x a1
        a0 = axes_in[i, 0].copy()
        a1 = axes_in[i, 1].copy()
        l0 = np.sqrt(a0[0] * a0[0] + a0[1] * a0[1] + a0[2] * a0[2])
        if not l0 > 0.5:
            a0[:] = 0.0
            a0[0] = 1.0
        else:
            a0 /= l0
        a1 -= (a1[0] * a0[0] + a1[1] * a0[1] + a1[2] * a0[2]) * a0
        l1 = np.sqrt(a1[0] * a1[0] + a1[1] * a1[1] + a1[2] * a1[2])
        if not l1 > 0.5:
            # any unit vector across a0
            k = 0
            if abs(a0[1]) < abs(a0[k]):
                k = 1
            if abs(a0[2]) < abs(a0[k]):
                k = 2
            a1[:] = 0.0
            a1[k] = 1.0
            a1 -= a0[k] * a0
            a1 /= np.sqrt(a1[0] * a1[0] + a1[1] * a1[1] + a1[2] * a1[2])
        else:
            a1 /= l1
        a2 = np.empty(3)
        a2[0] = a0[1] * a1[2] - a0[2] * a1[1]
        a2[1] = a0[2] * a1[0] - a0[0] * a1[2]
        a2[2] = a0[0] * a1[1] - a0[1] * a1[0]
        a2 /= np.sqrt(a2[0] * a2[0] + a2[1] * a2[1] + a2[2] * a2[2])
        lo = np.full(3, np.inf)
        hi = np.full(3, -np.inf)
        r = ref[i]
        for j in range(start[i], end[i]):
            for c in range(4):
                d0 = verts[j, c, 0] - r[0]
                d1 = verts[j, c, 1] - r[1]
                d2 = verts[j, c, 2] - r[2]
                t0 = a0[0] * d0 + a0[1] * d1 + a0[2] * d2
                t1 = a1[0] * d0 + a1[1] * d1 + a1[2] * d2
                t2 = a2[0] * d0 + a2[1] * d1 + a2[2] * d2
                lo[0] = min(lo[0], t0)
                hi[0] = max(hi[0], t0)
                lo[1] = min(lo[1], t1)
                hi[1] = max(hi[1], t1)
                lo[2] = min(lo[2], t2)
                hi[2] = max(hi[2], t2)
        m0, m1, m2 = 0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), 0.5 * (lo[2] + hi[2])
        for k in range(3):
            bv[i, k] = r[k] + m0 * a0[k] + m1 * a1[k] + m2 * a2[k]
            bv[i, 3 + k] = a0[k]
            bv[i, 6 + k] = a1[k]
            bv[i, 9 + k] = a2[k]
        for k in range(3):
            bv[i, 12 + k] = 0.5 * (hi[k] - lo[k]) + pad
    return bv


# --------------------------------------------------------------------------- queries (numba)
@numba.njit(cache=True, inline="always")
def _bv_distance_sq(bv, node, p0, p1, p2, obb):
    """Squared distance from (p0, p1, p2) to bounding volume ``node`` (0 inside)."""
    d = 0.0
    if obb:
        x0 = p0 - bv[node, 0]
        x1 = p1 - bv[node, 1]
        x2 = p2 - bv[node, 2]
        for k in range(3):
            t = abs(bv[node, 3 + 3 * k] * x0 + bv[node, 4 + 3 * k] * x1
                    + bv[node, 5 + 3 * k] * x2) - bv[node, 12 + k]
            if t > 0.0:
                d += t * t
    else:
        e = bv[node, 0] - p0
        if e > 0.0:
            d += e * e
        else:
            e = p0 - bv[node, 3]
            if e > 0.0:
                d += e * e
        e = bv[node, 1] - p1
        if e > 0.0:
            d += e * e
        else:
            e = p1 - bv[node, 4]
            if e > 0.0:
                d += e * e
        e = bv[node, 2] - p2
        if e > 0.0:
            d += e * e
        else:
            e = p2 - bv[node, 5]
            if e > 0.0:
                d += e * e
    return d


@numba.njit(cache=True, inline="always")
def _is_excluded(node, node_part, own, o0, o1):
    q = node_part[node]
    for k in range(o0, o1):
        if own[k] == q:
            return True
    return False


@numba.njit(cache=True)
def _nearest_one(p, best, root, own, o0, o1, bv, obb, left, right, start, end, node_part,
                 corners, n_tri, slab, plane_test, stack, stack_d, tmp, leaf_g, leaf_j, counts):
    """Squared distance and tree-order index of the nearest element to p strictly nearer than
    ``best`` (-1 when none), searching from ``root`` and skipping the part trees whose index is
    in own[o0:o1]. Adds to counts: bv tests, element tests, plane skips, leaf elements.
    ``stack``/``stack_d`` scratch of depth + 2 entries, ``tmp`` (3,), ``leaf_g``/``leaf_j``
    scratch of the largest leaf's size."""
    best_e = -1
    p0, p1, p2 = p[0], p[1], p[2]
    if node_part[root] >= 0 and _is_excluded(root, node_part, own, o0, o1):
        return best, best_e
    d = _bv_distance_sq(bv, root, p0, p1, p2, obb)
    counts[0] += 1
    if d * _SLACK_DIV >= best:
        return best, best_e
    stack[0] = root
    stack_d[0] = d
    top = 1
    while top > 0:
        top -= 1
        node = stack[top]
        if stack_d[top] * _SLACK_DIV >= best:
            continue
        c = left[node]
        if c < 0:
            s0 = start[node]
            m = end[node] - s0
            counts[3] += m
            if not plane_test:
                for j in range(s0, s0 + m):
                    counts[1] += 1
                    for t in range(n_tri[j]):
                        dt = closest_point_on_triangle(p, corners[j, t, 0], corners[j, t, 1],
                                                       corners[j, t, 2], tmp)
                        if dt < best:
                            best = dt
                            best_e = j
                continue
            # the leaf's elements by increasing slab distance (insertion sort, stable): the
            # nearest candidates first, and all the rest skipped once a slab is too far
            for k in range(m):
                j = s0 + k
                s = slab[j, 0] * p0 + slab[j, 1] * p1 + slab[j, 2] * p2
                g = slab[j, 3] - s
                g = max(g, s - slab[j, 4])
                g2 = g * g if g > 0.0 else 0.0
                pos = k
                while pos > 0 and leaf_g[pos - 1] > g2:
                    leaf_g[pos] = leaf_g[pos - 1]
                    leaf_j[pos] = leaf_j[pos - 1]
                    pos -= 1
                leaf_g[pos] = g2
                leaf_j[pos] = j
            for k in range(m):
                if leaf_g[k] * _SLACK_DIV >= best:
                    counts[2] += m - k
                    break
                j = leaf_j[k]
                counts[1] += 1
                for t in range(n_tri[j]):
                    dt = closest_point_on_triangle(p, corners[j, t, 0], corners[j, t, 1],
                                                   corners[j, t, 2], tmp)
                    if dt < best:
                        best = dt
                        best_e = j
            continue
        c1 = right[node]
        check = node_part[node] < 0  # children of a top node may be (excluded) part roots
        use0 = not (check and node_part[c] >= 0 and _is_excluded(c, node_part, own, o0, o1))
        use1 = not (check and node_part[c1] >= 0 and _is_excluded(c1, node_part, own, o0, o1))
        d0 = np.inf
        d1 = np.inf
        if use0:
            d0 = _bv_distance_sq(bv, c, p0, p1, p2, obb)
            counts[0] += 1
        if use1:
            d1 = _bv_distance_sq(bv, c1, p0, p1, p2, obb)
            counts[0] += 1
        if d0 <= d1:
            near, far, dn, df = c, c1, d0, d1
        else:
            near, far, dn, df = c1, c, d1, d0
        if df * _SLACK_DIV < best:
            stack[top] = far
            stack_d[top] = df
            top += 1
        if dn * _SLACK_DIV < best:
            stack[top] = near
            stack_d[top] = dn
            top += 1
    return best, best_e


@numba.njit(cache=True, parallel=True)
def _nearest_many(points, active, ptr, own, best0, bv, obb, left, right, start, end, node_part,
                  root, corners, n_tri, slab, plane_test, depth, max_leaf, out_d2, out_elem,
                  counts):
    n = len(points)
    n_chunks = (n + _CHUNK - 1) // _CHUNK
    for chunk in numba.prange(n_chunks):
        stack = np.empty(2 * depth + 4, np.int64)
        stack_d = np.empty(2 * depth + 4)
        tmp = np.empty(3)
        leaf_g = np.empty(max_leaf)
        leaf_j = np.empty(max_leaf, np.int64)
        for i in range(chunk * _CHUNK, min(n, (chunk + 1) * _CHUNK)):
            if not active[i]:
                out_d2[i] = np.inf
                out_elem[i] = -1
                continue
            d, e = _nearest_one(points[i], best0, root, own, ptr[i], ptr[i + 1], bv, obb, left,
                                right, start, end, node_part, corners, n_tri, slab, plane_test,
                                stack, stack_d, tmp, leaf_g, leaf_j, counts[i])
            out_d2[i] = d
            out_elem[i] = e


@numba.njit(cache=True, parallel=True)
def _per_part_many(points, active, ptr, own, best0, bv, obb, left, right, start, end,
                   node_part, root, corners, n_tri, slab, depth, max_leaf, offsets, counts,
                   out_part, out_d2, fill):
    """For each point, walk the top level to every part root within ``best0`` (not excluded)
    and search that part for its nearest element. First pass (fill False) counts the parts
    found per point into ``counts``; the second writes (part index, squared distance) at
    ``offsets``."""
    n = len(points)
    n_chunks = (n + _CHUNK - 1) // _CHUNK
    for chunk in numba.prange(n_chunks):
        stack = np.empty(2 * depth + 4, np.int64)
        stack2 = np.empty(2 * depth + 4, np.int64)
        stack_d = np.empty(2 * depth + 4)
        tmp = np.empty(3)
        scratch = np.zeros(4, np.int64)
        leaf_g = np.empty(max_leaf)
        leaf_j = np.empty(max_leaf, np.int64)
        for i in range(chunk * _CHUNK, min(n, (chunk + 1) * _CHUNK)):
            k = 0
            if active[i]:
                p = points[i]
                stack2[0] = root
                top = 1
                while top > 0:
                    top -= 1
                    node = stack2[top]
                    if node_part[node] >= 0:
                        if _is_excluded(node, node_part, own, ptr[i], ptr[i + 1]):
                            continue
                        d, e = _nearest_one(p, best0, node, own, 0, 0, bv, obb, left, right,
                                            start, end, node_part, corners, n_tri, slab, True,
                                            stack, stack_d, tmp, leaf_g, leaf_j, scratch)
                        if e >= 0:
                            if fill:
                                out_part[offsets[i] + k] = node_part[node]
                                out_d2[offsets[i] + k] = d
                            k += 1
                        continue
                    if _bv_distance_sq(bv, node, p[0], p[1], p[2], obb) * _SLACK_DIV >= best0:
                        continue
                    stack2[top] = left[node]
                    stack2[top + 1] = right[node]
                    top += 2
            if not fill:
                counts[i] = k


@numba.njit(cache=True)
def _cut(ql, unit, tol, q, nrm, bv, obb, left, right, start, end, root, depth, element_nodes,
         coords, out):
    """Tree-order indices of the elements cut by the plane (see cut_by_plane) into ``out``;
    returns how many."""
    stack = np.empty(2 * depth + 4, np.int64)
    stack[0] = root
    top = 1
    k = 0
    while top > 0:
        top -= 1
        node = stack[top]
        if obb:
            s = (unit[0] * (bv[node, 0] - ql[0]) + unit[1] * (bv[node, 1] - ql[1])
                 + unit[2] * (bv[node, 2] - ql[2]))
            r = 0.0
            for a in range(3):
                r += bv[node, 12 + a] * abs(unit[0] * bv[node, 3 + 3 * a]
                                            + unit[1] * bv[node, 4 + 3 * a]
                                            + unit[2] * bv[node, 5 + 3 * a])
        else:
            s = 0.0
            r = 0.0
            for a in range(3):
                c = 0.5 * (bv[node, a] + bv[node, 3 + a])
                h = 0.5 * (bv[node, 3 + a] - bv[node, a])
                s += unit[a] * (c - ql[a])
                r += abs(unit[a]) * h
        if abs(s) > r + tol:
            continue
        c = left[node]
        if c >= 0:
            stack[top] = c
            stack[top + 1] = right[node]
            top += 2
            continue
        for j in range(start[node], end[node]):
            pos = False
            neg = False
            for m in range(4):
                v = element_nodes[j, m]
                sd = ((coords[v, 0] - q[0]) * nrm[0] + (coords[v, 1] - q[1]) * nrm[1]
                      + (coords[v, 2] - q[2]) * nrm[2])
                if sd > 0.0:
                    pos = True
                elif sd < 0.0:
                    neg = True
                else:
                    pos = True
                    neg = True
            if pos and neg:
                out[k] = j
                k += 1
    return k
