"""Derived data of an FE shell mesh: triangles, unique edges and normals.

Everything here is GL-free and vectorised with numpy; inputs follow the mesh conventions:
``elements`` are (M, 4) integer node indices with a triangle repeating its third node
(``e[3] == e[2]``), coordinates are (N, 3) float64 in model units. (M, 3) triangle arrays are
accepted and padded to that convention.

Element kinds, decided from node indices alone (topology, not geometry):

* **quad** -- four distinct nodes;
* **triangle** -- exactly one pair of cyclically adjacent corners share a node (``c == d`` is
  the stored triangle; ``a == b``, ``b == c`` and ``d == a`` are collapsed quads). It stands for
  the triangle of its distinct nodes in winding order;
* **degenerate** -- anything else: fewer than three distinct nodes, or a node repeated at
  opposite corners (``a == c`` or ``b == d``), whose polygon folds back onto itself and has zero
  area. A degenerate element yields no triangle, a zero normal and no smooth-group links.

The crease split of the vertices, which builds on these, is :mod:`workbench.scene.crease`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from numpy.typing import ArrayLike

__all__ = [
    "Triangulation",
    "as_coords",
    "as_elements",
    "classify_elements",
    "element_normals",
    "node_normals",
    "triangulate",
    "unique_edges",
]

# A cross product shorter than this share of the largest it could be for the given vectors is
# rounding noise (collinear nodes), not a direction: the normal is reported as zero instead.
_ZERO_REL = 1e-12
# Cosines are compared with this slack so that rounding in the normals does not split flat
# neighbours at a crease angle of 0 or at angles exactly on the limit.
_COS_TOL = 1e-12

_QUAD_SPLIT_AC = np.array([[0, 1, 2], [0, 2, 3]], np.int8)  # |a-c| <= |b-d|
_QUAD_SPLIT_BD = np.array([[0, 1, 3], [1, 2, 3]], np.int8)
_NEXT = np.array([1, 2, 3, 0])


# --------------------------------------------------------------------------- input checks
def as_elements(elements: ArrayLike) -> np.ndarray:
    """``elements`` as (M, 4) int32 C-contiguous node indices (a view where it already is one).

    (M, 3) triangles are padded by repeating their third node. Refuses with ValueError any other
    shape, a non-integer dtype (an empty float array is accepted), negative node indices and
    indices beyond the int32 range.
    """
    e = np.asarray(elements)
    if e.ndim != 2 or e.shape[1] not in (3, 4):
        raise ValueError(f"elements must be (M, 4) or (M, 3) node indices, got shape {e.shape}")
    if e.dtype.kind not in "iu" and not (e.size == 0 and e.dtype.kind == "f"):
        raise ValueError(f"elements must be integer node indices, got dtype {e.dtype}")
    if e.size:
        lo, hi = int(e.min()), int(e.max())
        if lo < 0:
            bad = np.flatnonzero((e < 0).any(axis=1))
            raise ValueError(f"{len(bad)} elements have negative node indices, "
                             f"first {bad[:5].tolist()}")
        if hi > np.iinfo(np.int32).max:
            raise ValueError(f"node index {hi} does not fit int32")
    if e.shape[1] == 3:
        e = np.concatenate([e, e[:, 2:3]], axis=1)
    return np.ascontiguousarray(e, dtype=np.int32)


def as_coords(coords: ArrayLike, elements: np.ndarray, what: str = "coords") -> np.ndarray:
    """``coords`` as (N, 3) float64 coordinates in model units (a view where it already is one).

    ``elements`` are node indices as returned by :func:`as_elements`. Refuses with ValueError,
    naming the argument as ``what``, any other shape, fewer nodes than ``elements`` reference
    and non-finite coordinates.
    """
    c = np.asarray(coords, dtype=np.float64)
    if c.ndim != 2 or c.shape[1] != 3:
        raise ValueError(f"{what} must be (N, 3), got shape {c.shape}")
    if elements.size and int(elements.max()) >= len(c):
        raise ValueError(f"elements reference node {int(elements.max())} but {what} has "
                         f"{len(c)} nodes")
    if not np.isfinite(c).all():
        bad = np.flatnonzero(~np.isfinite(c).all(axis=1))
        raise ValueError(f"{what}: non-finite coordinates at nodes {bad[:5].tolist()}")
    return c


def classify_elements(e: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Element kinds and canonical corners of ``e``, (M, 4) integer node indices.

    Returns ``quad`` (M,) bool, ``tri`` (M,) bool (an element that is neither is degenerate, see
    the module docstring) and ``canon`` (M, 4) int8: for each corner the first corner of the same
    element holding the same node (its own index when unrepeated). Checks and refuses nothing:
    ``e`` must already have that shape, as :func:`as_elements` returns.
    """
    a, b, c, d = e[:, 0], e[:, 1], e[:, 2], e[:, 3]
    eq01, eq12, eq23, eq30 = a == b, b == c, c == d, d == a
    eq02, eq13 = a == c, b == d
    n_adjacent = eq01.astype(np.int8) + eq12 + eq23 + eq30
    opposite = eq02 | eq13
    quad = (n_adjacent == 0) & ~opposite
    tri = (n_adjacent == 1) & ~opposite
    canon = np.empty(e.shape, np.int8)
    canon[:, 0] = 0
    canon[:, 1] = np.where(eq01, 0, 1)
    canon[:, 2] = np.where(eq02, 0, np.where(eq12, 1, 2))
    canon[:, 3] = np.where(eq30, 0, np.where(eq13, 1, np.where(eq23, 2, 3)))
    return quad, tri, canon


def _diagonal_cross(e: np.ndarray, coords: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """cross(c - a, d - b) per element (twice the vector area) and whether it is a direction.

    For a triangle (a, b, c, c) this equals cross(b - a, c - a); for a collapsed quad it is the
    cross product of its triangle; for every degenerate element it is exactly zero.
    """
    p = coords[e[:, 0]]
    d1 = coords[e[:, 2]] - p
    d2 = coords[e[:, 3]] - coords[e[:, 1]]
    n = np.empty_like(d1)
    n[:, 0] = d1[:, 1] * d2[:, 2] - d1[:, 2] * d2[:, 1]
    n[:, 1] = d1[:, 2] * d2[:, 0] - d1[:, 0] * d2[:, 2]
    n[:, 2] = d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]
    length = np.sqrt(np.einsum("ij,ij->i", n, n))
    scale = np.sqrt(np.einsum("ij,ij->i", d1, d1) * np.einsum("ij,ij->i", d2, d2))
    ok = length > _ZERO_REL * scale
    return n, ok


def _unit_or_zero(n: np.ndarray, ok: np.ndarray) -> np.ndarray:
    """Rows of ``n`` scaled to unit length where ``ok``, zero elsewhere."""
    out = np.zeros_like(n)
    # scaled by the largest component first: the squares of tiny components (1e-160) would
    # underflow to subnormals and lose the unit length
    v = n[ok] / np.abs(n[ok]).max(axis=1)[:, None]
    out[ok] = v / np.sqrt(np.einsum("ij,ij->i", v, v))[:, None]
    return out


def _normalise(v: np.ndarray, magnitude: np.ndarray) -> np.ndarray:
    """Unit rows of ``v``; rows whose length is rounding noise next to ``magnitude`` become 0."""
    length = np.sqrt(np.einsum("ij,ij->i", v, v))
    ok = (length > _ZERO_REL * magnitude) & (length > 0)
    out = np.zeros_like(v)
    out[ok] = v[ok] / length[ok, None]
    return out


def _bincount3(index: np.ndarray, values: np.ndarray, n: int) -> np.ndarray:
    """(n, 3) sums of the rows of ``values`` grouped by ``index``."""
    return np.stack([np.bincount(index, weights=values[:, k], minlength=n) for k in range(3)],
                    axis=1)


# --------------------------------------------------------------------------- triangulation
@dataclass(eq=False)
class Triangulation:
    """Triangles of an element mesh, with the element and element corners each came from.

    ``triangles`` (K, 3) int32 node indices, winding as in the element; ``element_of`` (K,) int32
    element index of each triangle (non-decreasing: element 0's triangles first);
    ``corners`` (K, 3) int8, for each triangle corner the element corner 0..3 it is.
    """

    triangles: np.ndarray
    element_of: np.ndarray
    corners: np.ndarray

    @property
    def n_triangles(self) -> int:
        return len(self.triangles)


def triangulate(elements: ArrayLike, nodes: ArrayLike) -> Triangulation:
    """Split elements into triangles, quads along their shorter diagonal.

    A quad (a, b, c, d) becomes (a, b, c), (a, c, d) when ``|a - c| <= |b - d|`` (compared as
    squared float64 lengths of ``nodes``), else (a, b, d), (b, c, d). A triangle (a, b, c, c) -- or
    a quad with one pair of adjacent corners on the same node -- becomes the one triangle of its
    distinct nodes in winding order. Degenerate elements (see the module notes) give no triangle, so
    K = 2 * quads + triangles. Winding is kept; triangles come in element order.

    Refuses elements that are not (M, 4)/(M, 3) non-negative integers and ``nodes`` that are not
    finite (N, 3) covering every referenced node.
    """
    e = as_elements(elements)
    coords = as_coords(nodes, e, "nodes")
    quad, tri, canon = classify_elements(e)
    m = len(e)
    cand = np.zeros((m, 2, 3), np.int8)
    if quad.any():
        q = np.flatnonzero(quad)
        eq = e[q]
        ac = coords[eq[:, 2]] - coords[eq[:, 0]]
        bd = coords[eq[:, 3]] - coords[eq[:, 1]]
        use_ac = np.einsum("ij,ij->i", ac, ac) <= np.einsum("ij,ij->i", bd, bd)
        cand[q] = np.where(use_ac[:, None, None], _QUAD_SPLIT_AC, _QUAD_SPLIT_BD)
    if tri.any():
        t = np.flatnonzero(tri)
        # drop the one corner that repeats its predecessor; the rest keep their cyclic order
        repeated = np.flatnonzero((canon[t] != np.arange(4)).ravel()) % 4
        keep = np.ones((len(t), 4), bool)
        keep[np.arange(len(t)), repeated] = False
        cand[t, 0] = np.nonzero(keep)[1].reshape(-1, 3)
    count = quad.astype(np.int8) * 2 + tri
    valid = np.arange(2)[None, :] < count[:, None]
    element_of, slot = np.nonzero(valid)
    corners = np.ascontiguousarray(cand[element_of, slot])
    triangles = np.take_along_axis(e[element_of], corners.astype(np.intp), axis=1)
    return Triangulation(
        triangles=np.ascontiguousarray(triangles, dtype=np.int32),
        element_of=element_of.astype(np.int32),
        corners=corners,
    )


# --------------------------------------------------------------------------- edges
def unique_edges(elements: ArrayLike) -> np.ndarray:
    """(E, 2) int32 unique element edges: each row (lo, hi), rows sorted lexicographically.

    The edges are the element's cyclic corner pairs (a, b), (b, c), (c, d), (d, a) -- quad edges,
    never the diagonals a triangulation adds; a triangle (a, b, c, c) gives its three edges.
    Zero-length edges (a node repeated in consecutive corners) are dropped.
    """
    e = as_elements(elements)
    u = e.ravel()
    v = e[:, _NEXT].ravel()
    keep = u != v
    u, v = u[keep], v[keep]
    lo = np.minimum(u, v).astype(np.int64)
    hi = np.maximum(u, v).astype(np.int64)
    keys = np.sort((lo << 32) | hi)
    keys = keys[np.r_[True, keys[1:] != keys[:-1]]] if len(keys) else keys
    out = np.empty((len(keys), 2), np.int32)
    out[:, 0] = keys >> 32
    out[:, 1] = keys & 0xFFFFFFFF
    return out


# --------------------------------------------------------------------------- normals
def element_normals(elements: ArrayLike, coords: ArrayLike) -> np.ndarray:
    """(M, 3) float64 unit normals of the elements at ``coords`` (N, 3).

    Quad normal: normalised cross(c - a, d - b) of the diagonals; triangle (a, b, c, c):
    normalised cross(b - a, c - a) (the same formula). The direction follows the winding. An
    element whose cross product is zero or rounding noise (degenerate or collinear nodes) gets
    the zero vector, never NaN.
    """
    e = as_elements(elements)
    c = as_coords(coords, e)
    n, ok = _diagonal_cross(e, c)
    return _unit_or_zero(n, ok)


def node_normals(elements: ArrayLike, coords: ArrayLike) -> np.ndarray:
    """(N, 3) float64 unit node normals: area-weighted average of the adjacent element normals.

    Each element adds its vector area (area times unit normal, as oriented by its winding) once
    to each of its distinct nodes. No crease split and no orientation repair: elements of
    opposite winding cancel. Nodes no element references, and nodes whose sum cancels to
    rounding noise, get the zero vector (never NaN). N is ``len(coords)``.
    """
    e = as_elements(elements)
    c = as_coords(coords, e)
    n, ok = _diagonal_cross(e, c)
    w = np.where(ok[:, None], 0.5 * n, 0.0)
    _, _, canon = classify_elements(e)
    rows, cols = np.nonzero(canon == np.arange(4, dtype=np.int8))
    nodes = e[rows, cols]
    total = _bincount3(nodes, w[rows], len(c))
    magnitude = np.bincount(nodes, weights=np.sqrt(np.einsum("ij,ij->i", w, w))[rows],
                            minlength=len(c))
    return _normalise(total, magnitude)
