"""Constant-time slices of a tetrahedral spacetime mesh (st2005 §4.1) and their quadrisection.

The plane t = const cuts a tetrahedron in a triangle or a convex quadrilateral. A half-open rule
makes a slice tile the spatial domain exactly once, even through a non-conforming mesh or at a
time shared by many vertices: a vertex is *below* when t_v < t and *above* otherwise, and a
tetrahedron is cut iff it has vertices on both sides (tmin < t <= tmax). Every intersection
point lies on an edge from a below vertex b to an above vertex a,

    p = x_b + (t − t_b) / (t_a − t_b) · (x_a − x_b),   t_a − t_b > 0,

so no division by zero occurs even when t passes exactly through a vertex, an edge or a face
(the polygon may then have zero area, never a NaN).

`TimeSlicer` follows the paper's access pattern: tetrahedra sorted by their minimum time once,
then an active set updated incrementally as t advances frame by frame.

Polygons use the workbench's FE convention: (P, 4, 2) corners, counter-clockwise, a triangle
repeating its third corner in slot 3. Spatial coordinates in the mesh's length unit. Polygon
edge k runs from corner k to corner k + 1 (mod 4); for a triangle edge 2 is the zero-length
(c2, c3) and edge 3 is (c2, c0).
"""

from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np

from .mesh import SpacetimeMesh
from .state import CutCases, Points, Polygons

__all__ = ["Slice", "slice_at", "TimeSlicer", "quadrisect", "polygon_areas"]


@dataclass
class Slice:
    """Polygons of the slice t = const through a spacetime mesh.

    corners: (P, 4, 2) float64 (x, y), counter-clockwise; for a triangle corners[:, 3] ==
    corners[:, 2]. element: (P,) int64 index of the tetrahedron a polygon lies in.
    is_quad: (P,) bool. outer: (P, 4) bool or None (not derived) — edge k lies on a tetrahedron
    face that no other tetrahedron shares: the boundary of the spatial domain (or a
    non-conforming face), where no neighbouring polygon continues the surface; always False
    for the zero-length edge 2 of a triangle.
    """

    t: float
    corners: np.ndarray
    element: np.ndarray
    is_quad: np.ndarray
    outer: np.ndarray | None = None

    @property
    def n_polygons(self) -> int:
        return len(self.element)


def _check_mesh(mesh: SpacetimeMesh) -> None:
    if not isinstance(mesh, SpacetimeMesh):
        raise TypeError(f"expected a SpacetimeMesh, got {type(mesh).__name__}")
    if mesh.dim != 2:
        raise ValueError("only 2-D space domains (tetrahedral spacetime meshes) are sliced; "
                         "a 1-D bar is drawn as its spacetime triangles")


def _check_t(t) -> float:
    t = float(t)
    if not np.isfinite(t):
        raise ValueError(f"slice time must be finite, got {t}")
    return t


def polygon_areas(s: Slice) -> np.ndarray:
    """(P,) signed shoelace areas of the slice polygons (>= 0 for CCW), in length²."""
    c = s.corners
    d02 = c[:, 0] - c[:, 2]
    d13 = c[:, 1] - c[:, 3]
    # half the cross product of the diagonals: exact for any quadrilateral, and for a triangle
    # stored with its third corner repeated
    return 0.5 * (d02[:, 0] * d13[:, 1] - d02[:, 1] * d13[:, 0])


def _case_tables() -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """For each of the 16 below/above patterns of a tetrahedron's 4 vertices (bit i set when
    vertex i is below): the vertex column of the below end b and of the above end a of the edge
    under each of the 4 polygon corners, the number of below vertices, and for each polygon
    edge k the column of the vertex opposite the face it lies on (−1: the zero-length edge)."""
    tb = np.zeros((16, 4), dtype=np.intp)
    ta = np.zeros((16, 4), dtype=np.intp)
    nb = np.zeros(16, dtype=np.intp)
    opp = np.full((16, 4), -1, dtype=np.intp)
    for code in range(16):
        below = [i for i in range(4) if code >> i & 1]
        above = [i for i in range(4) if not code >> i & 1]
        nb[code] = len(below)
        if len(below) == 1:
            tb[code], ta[code] = [below[0]] * 4, [above[0], above[1], above[2], above[2]]
        elif len(below) == 2:
            b0, b1 = below
            a0, a1 = above
            tb[code], ta[code] = [b0, b0, b1, b1], [a0, a1, a1, a0]
        elif len(below) == 3:
            tb[code], ta[code] = [below[0], below[1], below[2], below[2]], [above[0]] * 4
        if 0 < len(below) < 4:
            for k in range(4):
                j = (k + 1) % 4
                on_face = {tb[code, k], ta[code, k], tb[code, j], ta[code, j]}
                if len(on_face) == 3:  # two corners on edges of one face
                    opp[code, k] = ({0, 1, 2, 3} - on_face).pop()
    return tb, ta, nb, opp


_TB, _TA, _NB, _OPP = _case_tables()
# corner orders that turn a clockwise polygon counter-clockwise, and where its edges go
_QUAD_FLIP, _QUAD_FLIP_EDGES = np.array([0, 3, 2, 1]), np.array([3, 2, 1, 0])
_TRI_FLIP, _TRI_FLIP_EDGES = np.array([0, 2, 1, 1]), np.array([3, 1, 2, 0])
_CASES = CutCases(_TB, _TA, _NB, _OPP, _QUAD_FLIP, _TRI_FLIP, _QUAD_FLIP_EDGES, _TRI_FLIP_EDGES)


@numba.njit(cache=True)
def _cut_kernel(simplices, points, elements, t, shared, cases, out):
    """One pass over the cut tetrahedra ``elements`` of ``simplices`` (coordinates ``points``, a
    :class:`~.state.Points`; case tables ``cases``, a :class:`~.state.CutCases`) into ``out``
    (a :class:`~.state.Polygons`): corners, quad flag, outer edges (when ``shared`` has rows),
    counter-clockwise order. The arithmetic is the module docstring's, term by term."""
    x = points.x
    y = points.y
    tv = points.tv
    tb_col = cases.tb
    ta_col = cases.ta
    n_below = cases.n_below
    opp_col = cases.opp
    quad_flip = cases.quad_flip
    tri_flip = cases.tri_flip
    quad_flip_edges = cases.quad_flip_edges
    tri_flip_edges = cases.tri_flip_edges
    corners = out.corners
    is_quad = out.is_quad
    outer = out.outer
    want_outer = shared.shape[0] > 0
    c = np.empty((4, 2))
    o = np.zeros(4, np.bool_)
    for p in range(elements.shape[0]):
        e = elements[p]
        code = 0
        for i in range(4):
            if tv[simplices[e, i]] < t:
                code |= 1 << i
        for k in range(4):
            vb = simplices[e, tb_col[code, k]]
            va = simplices[e, ta_col[code, k]]
            tb = tv[vb]
            w = (t - tb) / (tv[va] - tb)
            xb, yb = x[vb], y[vb]
            c[k, 0] = xb + w * (x[va] - xb)
            c[k, 1] = yb + w * (y[va] - yb)
            if want_outer:
                f = opp_col[code, k]
                o[k] = f >= 0 and not shared[e, max(f, 0)]
        quad = n_below[code] == 2
        is_quad[p] = quad
        # twice the signed area: the cross product of the diagonals (see polygon_areas)
        area = (c[0, 0] - c[2, 0]) * (c[1, 1] - c[3, 1]) - (c[0, 1] - c[2, 1]) * (c[1, 0] - c[3, 0])
        order = quad_flip if quad else tri_flip
        edge_order = quad_flip_edges if quad else tri_flip_edges
        for k in range(4):
            src = order[k] if area < 0.0 else k
            corners[p, k, 0] = c[src, 0]
            corners[p, k, 1] = c[src, 1]
            if want_outer:
                outer[p, k] = o[edge_order[k] if area < 0.0 else k]


def _cut(simplices: np.ndarray, x: np.ndarray, y: np.ndarray, tv: np.ndarray,
         elements: np.ndarray, t: float, shared: np.ndarray | None = None) -> Slice:
    """Cut the given tetrahedra (all with tmin < t <= tmax) with the plane at t.
    x, y, tv: (P,) contiguous coordinates of the mesh points.
    shared: the mesh's (M, 4) shared faces, to derive ``outer``; None leaves it out."""
    elements = np.ascontiguousarray(elements, dtype=np.int64)
    P = len(elements)
    corners = np.empty((P, 4, 2))
    is_quad = np.empty(P, dtype=bool)
    outer = np.empty((P, 4), dtype=bool) if shared is not None else np.empty((0, 4), dtype=bool)
    _cut_kernel(simplices, Points(x, y, tv), elements, float(t),
                shared if shared is not None else np.empty((0, 4), dtype=bool), _CASES,
                Polygons(corners, is_quad, outer))
    return Slice(t=t, corners=corners, element=elements, is_quad=is_quad,
                 outer=outer if shared is not None else None)


def slice_at(mesh: SpacetimeMesh, t: float, elements=None, *, outer: bool = False) -> Slice:
    """The slice of `mesh` at time t, brute force over all tetrahedra (or the given indices).

    Polygons come in increasing element order (restricted to the given ones). With ``outer``
    the slice says which polygon edges lie on the domain boundary (the mesh's shared faces are
    derived once, on first use). Refuses D = 1 meshes and non-finite t (ValueError).
    """
    _check_mesh(mesh)
    t = _check_t(t)
    if elements is None:
        cand = np.flatnonzero((mesh.tmin < t) & (mesh.tmax >= t))
    else:
        elements = np.asarray(elements, dtype=np.int64).ravel()
        if elements.size and (elements.min() < 0 or elements.max() >= mesh.n_simplices):
            raise ValueError("element index out of range")
        cand = elements[(mesh.tmin[elements] < t) & (mesh.tmax[elements] >= t)]
    x, y, tv = (np.ascontiguousarray(mesh.points[:, i]) for i in range(3))
    return _cut(mesh.simplices, x, y, tv, cand, t, mesh.shared_facets if outer else None)


class TimeSlicer:
    """Successive slices of one mesh as t advances (the paper's animation access pattern).

    The tetrahedra are sorted by tmin once (stable). Each `slice(t)` with t at or after the
    previous one adds the tetrahedra whose tmin passed since (a pointer into the sorted order)
    and drops those with tmax < t, so a frame costs O(active + added) rather than O(mesh).
    A t before the previous one restarts from a binary search. Polygons come in the order of
    the active set, not by element; the set of (element, corners) equals `slice_at`'s. With
    ``outer`` every slice carries its domain-boundary edges (the shared faces are derived here).
    """

    def __init__(self, mesh: SpacetimeMesh, *, outer: bool = False):
        _check_mesh(mesh)
        self.mesh = mesh
        self._shared = mesh.shared_facets if outer else None
        self._order = np.argsort(mesh.tmin, kind="stable")
        self._sorted_tmin = mesh.tmin[self._order]
        self._tmax = mesh.tmax
        self._x, self._y, self._tv = (np.ascontiguousarray(mesh.points[:, i]) for i in range(3))
        self._ptr = 0
        self._active = np.zeros(0, dtype=np.int64)
        self._last_t: float | None = None

    @property
    def active(self) -> np.ndarray:
        """Indices of the tetrahedra cut at the last slice time (tmin < t <= tmax)."""
        return self._active

    def slice(self, t: float) -> Slice:
        t = _check_t(t)
        ptr = int(np.searchsorted(self._sorted_tmin, t, side="left"))  # tmin < t
        if self._last_t is None or t < self._last_t:
            cand = self._order[:ptr]
        else:
            cand = np.concatenate([self._active, self._order[self._ptr:ptr]])
        self._active = cand[self._tmax[cand] >= t]
        self._ptr = ptr
        self._last_t = t
        return _cut(self.mesh.simplices, self._x, self._y, self._tv, self._active, t, self._shared)


def quadrisect(s: Slice, max_area: float) -> Slice:
    """Split every polygon with area > max_area through its edge midpoints, recursively.

    A triangle becomes 4 triangles; a quad becomes 4 quads meeting at the mean of its corners.
    Children keep their parent's `element`, are counter-clockwise and lie inside the parent;
    areas add up to the parent's; a child edge on an outer edge of its parent is outer. Neighbours
    split to different depths meet at T-junctions (the fixed pattern does not close them). Done
    level by level, vectorised. max_area in length² must be positive (ValueError otherwise).
    """
    if not (np.isfinite(max_area) and max_area > 0):
        raise ValueError(f"max_area must be positive, got {max_area}")
    done_c, done_e, done_q, done_o = [], [], [], []
    c = s.corners
    e = s.element
    q = s.is_quad
    o = s.outer if s.outer is not None else np.zeros((len(e), 4), bool)
    for _ in range(200):
        area = polygon_areas(Slice(s.t, c, e, q))
        big = area > max_area
        done_c.append(c[~big])
        done_e.append(e[~big])
        done_q.append(q[~big])
        done_o.append(o[~big])
        if not big.any():
            break
        c, e, q, o = c[big], e[big], q[big], o[big]
        tc, te = c[~q], e[~q]
        m01, m12, m20 = (0.5 * (tc[:, i] + tc[:, j]) for i, j in ((0, 1), (1, 2), (2, 0)))
        c0, c1, c2 = tc[:, 0], tc[:, 1], tc[:, 2]
        tri = np.concatenate([np.stack([c0, m01, m20, m20], 1), np.stack([m01, c1, m12, m12], 1),
                              np.stack([m20, m12, c2, c2], 1), np.stack([m01, m12, m20, m20], 1)])
        qc, qe = c[q], e[q]
        g = qc.mean(axis=1)
        m = [0.5 * (qc[:, i] + qc[:, (i + 1) % 4]) for i in range(4)]
        quads = np.concatenate([np.stack([qc[:, 0], m[0], g, m[3]], 1),
                                np.stack([m[0], qc[:, 1], m[1], g], 1),
                                np.stack([g, m[1], qc[:, 2], m[2]], 1),
                                np.stack([m[3], g, m[2], qc[:, 3]], 1)])
        # which parent edge each child edge lies on (-1: inside the parent), child by child
        to, qo = o[~q], o[q]
        tri_o = np.concatenate([_child_outer(to, parent) for parent in _TRI_CHILD_EDGES])
        quad_o = np.concatenate([_child_outer(qo, parent) for parent in _QUAD_CHILD_EDGES])
        c = np.concatenate([tri, quads])
        e = np.concatenate([np.tile(te, 4), np.tile(qe, 4)])
        q = np.concatenate([np.zeros(len(tri), bool), np.ones(len(quads), bool)])
        o = np.concatenate([tri_o, quad_o])
    else:  # pragma: no cover - areas shrink geometrically per level
        raise RuntimeError("quadrisection did not converge")
    return Slice(t=s.t, corners=np.concatenate(done_c), element=np.concatenate(done_e),
                 is_quad=np.concatenate(done_q),
                 outer=None if s.outer is None else np.concatenate(done_o))


# for the four children of a triangle and of a quad (in quadrisect's order): the parent edge
# under each child edge, −1 where the child edge runs inside the parent or has zero length
_TRI_CHILD_EDGES = ([0, -1, -1, 3], [0, 1, -1, -1], [-1, 1, -1, 3], [-1, -1, -1, -1])
_QUAD_CHILD_EDGES = ([0, -1, -1, 3], [0, 1, -1, -1], [-1, 1, 2, -1], [-1, -1, 2, 3])


def _child_outer(outer: np.ndarray, parent_edges) -> np.ndarray:
    idx = np.asarray(parent_edges)
    return np.where(idx >= 0, outer[:, np.maximum(idx, 0)], False)
