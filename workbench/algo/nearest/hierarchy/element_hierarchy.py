"""The element hierarchy itself: :class:`ElementHierarchy`, built in named steps (selection,
local coordinates, element triangles and slabs, the forest, the bounding volumes), and its
query methods with their result :class:`NearestElements` (see
:mod:`workbench.algo.nearest.hierarchy`
for the method). Lengths are in the mesh's units.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from .inputs import check_elements, check_finite, distinct, local_origin, squared_bound, used_nodes
from .queries import _cut, _nearest_many, _per_part_many
from .state import Elements, Exclusion, Forest
from .trees import build_forest
from .volumes import _slabs, bounding_volumes

KINDS = ("aabb", "obb")
_EPS = np.finfo(np.float64).eps
# boxes and slabs are widened by this many units in the last place of the largest coordinate
_PAD_ULPS = 64.0


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
    top level over the parts (see :mod:`workbench.algo.nearest.hierarchy` for the layout).

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
        self.step = mesh.step_index(step)
        sel = check_elements(elements, len(mesh.elements))
        coords = mesh.coordinates(self.step)
        enodes = np.asarray(mesh.elements, dtype=np.int64)[sel]  # (E, 4)
        local = self._local_coordinates(coords, enodes, len(mesh.nodes), origin)
        n_tri, corners = _element_triangles(mesh.triangulation, sel, local, len(mesh.elements))
        verts = local[enodes]  # (E, 4, 3)
        slab = _slabs(corners, n_tri, verts, self.pad)
        parts_all = np.asarray(mesh.parts)[sel]
        self.part_ids = distinct(parts_all).astype(np.int64)
        pidx = np.searchsorted(self.part_ids, parts_all)
        forest = build_forest(verts, pidx, len(self.part_ids), self.leaf_size, kind == "obb")
        self._adopt(forest)
        tree_order = forest.order
        self.element_order = sel[tree_order]
        self.element_part = pidx[tree_order].astype(np.int64)
        self.n_tri = np.ascontiguousarray(n_tri[tree_order])
        self.corners = np.ascontiguousarray(corners[tree_order])
        self.slab = np.ascontiguousarray(slab[tree_order])
        self.element_nodes = np.ascontiguousarray(enodes[tree_order])
        self.bv = bounding_volumes(kind, np.ascontiguousarray(verts[tree_order]), self.corners,
                                   self.n_tri, self.left, self.right, self.start, self.end,
                                   self.pad)
        self.build_s = time.perf_counter() - t0

    def _local_coordinates(self, coords, enodes, n_nodes: int, origin) -> np.ndarray:
        """Check the nodes the elements ``enodes`` use and set :attr:`origin` (default
        :func:`local_origin` of those nodes), the coordinates kept for :meth:`cut_by_plane`,
        :attr:`scale` and :attr:`pad`; returns every node's coordinates relative to the origin
        (zero at the nodes not used)."""
        used = used_nodes(enodes, n_nodes)
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
        self.pad = _PAD_ULPS * _EPS * max(self.scale, np.finfo(np.float64).tiny)
        return local

    def _adopt(self, forest) -> None:
        """Take the layout of ``forest`` (:func:`~.trees.build_forest`) and its counts."""
        self.root, self.part_roots = forest.root, forest.part_roots
        self.left, self.right = forest.left, forest.right
        self.start, self.end = forest.start, forest.end
        self.node_part = forest.node_part
        self.n_top_bvs = forest.n_top
        self.n_bvs = len(forest.left) - forest.n_top
        is_leaf = forest.left < 0
        self.max_leaf = int((forest.end[is_leaf] - forest.start[is_leaf]).max())
        self.depth = forest.depth

    def _forest(self) -> Forest:
        """The forest as the kernels take it."""
        return Forest(self.bv, self.kind == "obb", self.left, self.right, self.start, self.end,
                      self.node_part, int(self.root), int(self.depth), int(self.max_leaf))

    def _elements(self) -> Elements:
        """The elements as the nearest-element kernels take them."""
        return Elements(self.corners, self.n_tri, self.slab)

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
        :func:`~workbench.algo.nearest.triangle.closest_point_on_triangle`, local coordinates);
        among
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
        _nearest_many(np.ascontiguousarray(local), act, Exclusion(ptr, own), best0,
                      self._forest(), self._elements(), bool(plane_test), d2, elem, counters)
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
        args = (local, act, Exclusion(ptr, own), best0, self._forest(), self._elements())
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
        k = _cut(ql, unit, tol, q, nrm, self._forest(), self.element_nodes, self._coords, out)
        return np.sort(self.element_order[out[:k]])



def _element_triangles(triangulation, sel, local, m: int) -> tuple[np.ndarray, np.ndarray]:
    """The triangles of each selected element (the mesh's own triangulation, ``m`` elements):
    (``n_tri`` (E,) int64 how many, ``corners`` (E, 2, 3, 3) their corners in ``local``
    coordinates, zero where an element has fewer than two)."""
    tri_count_all = np.bincount(triangulation.element_of, minlength=m)
    tri_first_all = np.concatenate([[0], np.cumsum(tri_count_all)[:-1]])
    n_tri = tri_count_all[sel].astype(np.int64)
    corners = np.zeros((len(sel), 2, 3, 3))
    for t in range(2):
        has = n_tri > t
        k = tri_first_all[sel[has]] + t
        corners[has, t] = local[np.asarray(triangulation.triangles)[k].astype(np.int64)]
    return n_tri, corners
