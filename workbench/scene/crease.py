"""The crease vertex split of an FE shell mesh: the "Gouraud edge" vertex duplication of
crash2000 (Sommer & Ertl, section 2 and Fig. 2).

Coordinates of a node are stored once per distinct normal it needs, so that one index set
serves coordinates and normals of every time step. Inputs follow the conventions of
:mod:`workbench.scene.derived` (elements (M, 4) with a triangle repeating its third node,
float64 coordinates in model units, degenerate elements yielding no smooth-group links).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numba
import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from .derived import (
    _COS_TOL,
    _NEXT,
    _ZERO_REL,
    Triangulation,
    _diagonal_cross,
    _unit_or_zero,
    as_coords,
    as_elements,
    classify_elements,
)

if TYPE_CHECKING:
    from numpy.typing import ArrayLike

__all__ = ["GouraudSplit", "gouraud_split"]


@dataclass(eq=False)
class GouraudSplit:
    """Crease-split vertices of a mesh ("Gouraud edges", crash2000 Fig. 2).

    ``vertex_node`` (V,) int32: the node of each output vertex. Vertices are numbered in node
    order and the vertices of one node are contiguous (``vertex_node`` is non-decreasing); among
    the vertices of a node, the one whose first element corner comes first (element-major) comes
    first. ``elements`` (M, 4) int32: the elements with corners re-pointed to vertices (a
    triangle still repeats its third entry). ``triangles`` (K, 3) int32 into vertices: the given
    triangulation's triangles, same order. ``added``: V minus the number of referenced nodes.
    ``crease_deg``: the crease angle used, in degrees.

    Draw with ``coords[vertex_node]`` and :meth:`normals` of the same time step.
    """

    vertex_node: np.ndarray
    elements: np.ndarray
    triangles: np.ndarray
    added: int
    crease_deg: float
    # per distinct, non-degenerate element corner: its element, vertex and orientation sign
    corner_element: np.ndarray = field(repr=False)
    corner_vertex: np.ndarray = field(repr=False)
    corner_sign: np.ndarray = field(repr=False)
    node_elements: np.ndarray = field(repr=False)  # the (M, 4) elements in node indices

    @property
    def n_vertices(self) -> int:
        return len(self.vertex_node)

    def normals(self, coords: ArrayLike) -> np.ndarray:
        """(V, 3) float64 unit vertex normals for node coordinates ``coords`` (N, 3) of any step.

        Per vertex: the area-weighted average of the normals of the elements in its smooth
        group, each element normal turned to its smooth patch's common orientation (elements
        wound against their patch's majority are flipped, see :func:`gouraud_split`). Vertices
        whose group has no area, or whose sum cancels to rounding noise, get the zero vector.
        """
        c = as_coords(coords, self.node_elements)
        # the per-step hot path of every Gouraud render path: one compiled pass
        return _split_normals(self.node_elements, c, self.corner_element, self.corner_vertex,
                              self.corner_sign.astype(np.float64), self.n_vertices, _ZERO_REL)


@numba.njit(cache=True, nogil=True)
def _split_normals(elements, coords, corner_element, corner_vertex, corner_sign, n_vertices,
                   zero_rel):
    """Compiled :meth:`GouraudSplit.normals`: the numpy formulation of ``_diagonal_cross`` and
    ``_normalise`` summed per vertex in one pass (same arithmetic, same zero rules)."""
    m = elements.shape[0]
    area = np.zeros((m, 3))
    for i in range(m):
        a, b, c, d = elements[i, 0], elements[i, 1], elements[i, 2], elements[i, 3]
        d1x, d1y, d1z = (coords[c, 0] - coords[a, 0], coords[c, 1] - coords[a, 1],
                         coords[c, 2] - coords[a, 2])
        d2x, d2y, d2z = (coords[d, 0] - coords[b, 0], coords[d, 1] - coords[b, 1],
                         coords[d, 2] - coords[b, 2])
        nx = d1y * d2z - d1z * d2y
        ny = d1z * d2x - d1x * d2z
        nz = d1x * d2y - d1y * d2x
        length = np.sqrt(nx * nx + ny * ny + nz * nz)
        scale = np.sqrt((d1x * d1x + d1y * d1y + d1z * d1z) * (d2x * d2x + d2y * d2y + d2z * d2z))
        if length > zero_rel * scale:
            area[i, 0], area[i, 1], area[i, 2] = 0.5 * nx, 0.5 * ny, 0.5 * nz
    total = np.zeros((n_vertices, 3))
    magnitude = np.zeros(n_vertices)
    for k in range(corner_element.shape[0]):
        e, v, sign = corner_element[k], corner_vertex[k], corner_sign[k]
        wx, wy, wz = area[e, 0], area[e, 1], area[e, 2]
        total[v, 0] += wx * sign
        total[v, 1] += wy * sign
        total[v, 2] += wz * sign
        magnitude[v] += np.sqrt(wx * wx + wy * wy + wz * wz)
    out = np.zeros((n_vertices, 3))
    for v in range(n_vertices):
        length = np.sqrt(total[v, 0] ** 2 + total[v, 1] ** 2 + total[v, 2] ** 2)
        if length > zero_rel * magnitude[v] and length > 0:
            out[v, 0], out[v, 1], out[v, 2] = (total[v, 0] / length, total[v, 1] / length,
                                               total[v, 2] / length)
    return out


def gouraud_split(elements: ArrayLike, coords_list: np.ndarray | Sequence[ArrayLike],
                  crease_deg: float, triangulation: Triangulation) -> GouraudSplit:
    """Duplicate vertices along creases so that each side of a crease gets its own normal.

    An edge shared by two elements is a crease when the angle between their element normals
    exceeds ``crease_deg`` (degrees, 0..180) in any of the coordinate sets of ``coords_list``
    (crash2000 uses the first and last time step; a single (N, 3) array is one set). Around each
    node, the incident element corners fall into smooth groups: the corners of f and g at node v
    are in one group when f and g share an edge through v that is not a crease (transitively).
    Each group is one output vertex. Consequences:

    * a boundary edge (one element) separates nothing; a node without creases keeps one vertex,
      a node on a crease line gets one vertex per side;
    * elements that touch only at a node (a non-manifold "bowtie" vertex) are in different
      groups even without a crease, since no edge joins them;
    * a non-manifold edge (three or more elements) links each element to the next one in element
      order along that edge, when that pair is smooth;
    * an element whose normal is zero (degenerate, or collinear nodes) in any set is smooth with
      no neighbour; corners of degenerate elements join the group of the node's first
      non-degenerate corner (one shared vertex when there is none).

    Orientation: inconsistently wound neighbours are common in FE shells. The angle between f
    and g is measured after turning g's normal to f's orientation, read from the topology: two
    elements agree when they traverse the shared edge in opposite directions. A flipped element
    is therefore not split from its neighbours, while a fold-back beyond 90 degrees (a hem) still
    is -- which ``|cos|`` of unoriented normals would get wrong (it merges a hem, and with it a
    crease angle of 90 degrees or more splits nothing). For :meth:`GouraudSplit.normals`, every
    element gets a sign that orients its smooth patch (elements joined by smooth links)
    consistently, in the orientation of the patch's area majority in the first coordinate set (by
    element count where that is undecided), fixed for all time steps; so flipped elements add to,
    not cancel, their neighbours' normals. Where a patch cannot be oriented as a whole (a Moebius
    band, some non-manifold joints), each vertex's group is oriented on its own the same way, and a
    group whose links contradict each other keeps its elements as wound.

    ``triangulation`` must be :func:`triangulate` of these elements; its triangles are re-pointed
    to vertices in the same order. Refuses bad elements, coordinates that are not finite (N, 3)
    covering the referenced nodes, an empty ``coords_list``, a crease angle outside [0, 180] and
    a triangulation of other elements.
    """
    e = as_elements(elements)
    m = len(e)
    crease = float(crease_deg)
    if not (0.0 <= crease <= 180.0):
        raise ValueError(f"crease_deg must be within [0, 180] degrees, got {crease_deg}")
    if isinstance(coords_list, np.ndarray) and coords_list.ndim == 2:
        coords_list = [coords_list]
    sets = [as_coords(c, e, f"coords_list[{i}]") for i, c in enumerate(coords_list)]
    if not sets:
        raise ValueError("coords_list must hold at least one (N, 3) coordinate set")
    tri_elem, tri_corner = _check_triangulation(triangulation, e)

    quad, tri, canon = classify_elements(e)
    good = quad | tri
    cid = 4 * np.arange(m, dtype=np.int64)[:, None] + canon  # canonical corner id per corner
    f, g, agree, lo_corners, hi_corners = _edge_pairs(e, good, cid)

    smooth = np.ones(len(f), bool)
    cos_limit = np.cos(np.radians(crease)) - _COS_TOL
    for coords in sets:
        n, has_normal = _diagonal_cross(e, coords)
        n = _unit_or_zero(n, has_normal)
        cos = np.einsum("ij,ij->i", n[f], n[g])
        cos = np.where(agree, cos, -cos)
        smooth &= has_normal[f] & has_normal[g] & (cos >= cos_limit)

    group, group_sign = _corner_groups(e, good, cid, lo_corners[smooth], hi_corners[smooth],
                                       agree[smooth])
    vert, vertex_node = _number_vertices(e, group)

    # per distinct corner of a non-degenerate element: element, vertex, orientation sign
    keep = good[:, None] & (canon == np.arange(4, dtype=np.int8))
    c_elem, c_pos = np.nonzero(keep)
    c_vert = vert[c_elem, c_pos]
    n0, ok0 = _diagonal_cross(e, sets[0])
    area0 = np.where(ok0, 0.5 * np.sqrt(np.einsum("ij,ij->i", n0, n0)), 0.0)
    e_sign, orientable = _patch_orientation(m, f[smooth], g[smooth], agree[smooth], area0)
    c_sign = e_sign[c_elem]
    local = ~orientable[c_elem]
    if local.any():
        # a patch that cannot be oriented as a whole is oriented around each vertex instead
        l_sign, l_vert = group_sign[c_elem, c_pos][local], c_vert[local]
        vote = _majority(l_vert, l_sign, area0[c_elem[local]], len(vertex_node))
        c_sign[local] = l_sign * vote[l_vert]

    return GouraudSplit(
        vertex_node=vertex_node,
        elements=vert,
        triangles=np.ascontiguousarray(vert[tri_elem[:, None], tri_corner]),
        added=int(len(vertex_node) - np.count_nonzero(np.bincount(e.ravel()))),
        crease_deg=crease,
        corner_element=c_elem.astype(np.int32),
        corner_vertex=c_vert,
        corner_sign=c_sign,
        node_elements=e,
    )


def _edge_pairs(e: np.ndarray, good: np.ndarray, cid: np.ndarray):
    """Pairs of non-degenerate elements along shared edges.

    Edge keys (lo, hi) are sorted stably, so the elements along one edge come in element order
    and each is paired with the next. Returns f, g (element indices), ``agree`` (the two traverse
    the edge in opposite directions, i.e. are wound alike) and the (P, 2) canonical corner ids
    of f and g at the edge's lower and at its higher node.
    """
    nxt = e[:, _NEXT]
    rows, cols = np.nonzero(good[:, None] & (e != nxt))
    u, v = e[rows, cols].astype(np.int64), nxt[rows, cols].astype(np.int64)
    cu, cv = cid[rows, cols], cid[rows, _NEXT[cols]]
    forward = u < v
    keys = np.minimum(u, v) * (int(e.max()) + 1 if e.size else 1) + np.maximum(u, v)
    order = _stable_order(keys)
    sorted_keys = keys[order]
    shared = np.flatnonzero(sorted_keys[1:] == sorted_keys[:-1])
    i, j = order[shared], order[shared + 1]
    c_lo, c_hi = np.where(forward, cu, cv), np.where(forward, cv, cu)
    lo_corners = np.stack([c_lo[i], c_lo[j]], axis=1)
    hi_corners = np.stack([c_hi[i], c_hi[j]], axis=1)
    return rows[i], rows[j], forward[i] != forward[j], lo_corners, hi_corners


def _corner_groups(e: np.ndarray, good: np.ndarray, cid: np.ndarray, lo_corners: np.ndarray,
                   hi_corners: np.ndarray, agree: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(M, 4) smooth-group label and (M, 4) orientation sign within the group, per corner.

    The corner graph is doubled: id k is "corner k as wound", k + C "corner k flipped". A link
    between elements wound alike joins (k, l) and (k + C, l + C), otherwise (k, l + C) and
    (k + C, l); so a group is two components, one per orientation, or one when its links
    contradict each other (then every sign is +1).
    """
    n_ids = cid.size
    a = np.concatenate([lo_corners[:, 0], hi_corners[:, 0]])
    b = np.concatenate([lo_corners[:, 1], hi_corners[:, 1]])
    s = np.concatenate([agree, agree])
    src = np.concatenate([a, a + n_ids])
    dst = np.concatenate([np.where(s, b, b + n_ids), np.where(s, b + n_ids, b)])
    graph = coo_matrix((np.ones(len(src), np.int8), (src, dst)),
                       shape=(2 * n_ids, 2 * n_ids)).tocsr()
    n_labels, labels = connected_components(graph, directed=False)
    as_wound, flipped = labels[cid], labels[cid + n_ids]
    group = np.minimum(as_wound, flipped).astype(np.int64)
    sign = np.where(as_wound <= flipped, 1.0, -1.0)
    if not good.all():
        group[~good] = _degenerate_groups(e, good, group, n_labels)
        sign[~good] = 1.0
    return group, sign


def _number_vertices(e: np.ndarray, group: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(M, 4) int32 vertex per corner and (V,) int32 node per vertex.

    Vertices are ordered by node, then by the first corner (element-major) of their group.
    """
    node_flat = e.ravel()
    flat = group.ravel()
    n_labels = int(flat.max()) + 1 if flat.size else 0
    first = _first_index(flat, n_labels)
    present = np.flatnonzero(first < flat.size)
    first = first[present]
    order = np.lexsort((first, node_flat[first]))
    lut = np.empty(n_labels, np.int32)
    lut[present[order]] = np.arange(len(order), dtype=np.int32)
    return lut[group], np.ascontiguousarray(node_flat[first[order]], dtype=np.int32)


def _first_index(values: np.ndarray, n: int) -> np.ndarray:
    """(n,) position of the first occurrence of each value 0..n-1 in ``values``; len(values)
    where it does not occur."""
    first = np.full(n, len(values), np.int64)
    np.minimum.at(first, values, np.arange(len(values), dtype=np.int64))
    return first


def _stable_order(keys: np.ndarray) -> np.ndarray:
    """Stable argsort of non-negative int64 ``keys``.

    Equal keys keep their input order. When the keys are small enough, key and position are
    packed into one int64 and sorted by value, several times faster than a stable argsort.
    """
    n = len(keys)
    if n == 0:
        return np.zeros(0, np.intp)
    lo, hi = int(keys.min()), int(keys.max())
    if (hi - lo + 1) * n < 2**62:
        packed = np.sort((keys - lo) * n + np.arange(n, dtype=np.int64))
        return packed % n
    return np.argsort(keys, kind="stable")


def _majority(label: np.ndarray, sign: np.ndarray, area: np.ndarray, n: int) -> np.ndarray:
    """(n,) +1/-1 per label: -1 where the members signed -1 outweigh the others.

    Weighed by area; where that is undecided by member count; a tie keeps the sign.
    """
    vote = np.bincount(label, weights=sign * area, minlength=n)
    count = np.bincount(label, weights=sign, minlength=n)
    return np.where((vote < 0) | ((vote == 0) & (count < 0)), -1.0, 1.0)


def _patch_orientation(m: int, f: np.ndarray, g: np.ndarray, agree: np.ndarray,
                       area: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Orientation sign per element within its smooth patch, and whether the patch has one.

    A patch is a set of elements joined by smooth links; ``agree`` says whether a link's two
    elements are wound alike. Signs make the patch consistently oriented, in the orientation of
    its area majority (see :func:`_majority`). A patch whose links contradict each other (a
    Moebius band, some non-manifold joints) is reported as not orientable, all signs +1.
    """
    src = np.concatenate([f, f + m])
    dst = np.concatenate([np.where(agree, g, g + m), np.where(agree, g + m, g)])
    graph = coo_matrix((np.ones(len(src), np.int8), (src, dst)), shape=(2 * m, 2 * m)).tocsr()
    _, labels = connected_components(graph, directed=False)
    as_wound, flipped = labels[:m], labels[m:]
    patch = np.minimum(as_wound, flipped)
    orientable = as_wound != flipped
    sign = np.where(as_wound < flipped, 1.0, -1.0)
    sign[~orientable] = 1.0
    sign *= _majority(patch, sign, area, 2 * m)[patch]
    return sign, orientable


def _check_triangulation(triangulation, e: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The triangulation's element and corner arrays, refused unless its triangles are corners
    of ``e``."""
    tris = np.asarray(triangulation.triangles)
    elem = np.asarray(triangulation.element_of).astype(np.intp)
    corner = np.asarray(triangulation.corners).astype(np.intp)
    k = len(tris)
    if tris.shape != (k, 3) or elem.shape != (k,) or corner.shape != (k, 3):
        raise ValueError("triangulation arrays disagree in shape")
    if k and (elem.min() < 0 or elem.max() >= len(e) or corner.min() < 0 or corner.max() > 3):
        raise ValueError("triangulation refers to elements or corners that do not exist")
    if k and not np.array_equal(e[elem[:, None], corner], tris):
        raise ValueError("triangulation does not belong to these elements")
    return elem, corner


def _degenerate_groups(e: np.ndarray, good: np.ndarray, group: np.ndarray,
                       n_labels: int) -> np.ndarray:
    """Group labels for the corners of degenerate elements.

    A corner joins the group of its node's first non-degenerate corner; nodes referenced by
    degenerate elements only get one fresh label each (numbered after ``n_labels``).
    """
    good_nodes = e[good].ravel()
    first = _first_index(good_nodes, int(e.max()) + 1)
    seen = first < len(good_nodes)
    rep = np.full(len(first), -1, np.int64)
    rep[seen] = group[good].ravel()[first[seen]]
    bad_nodes = e[~good]
    out = rep[bad_nodes]
    lonely = out < 0
    if lonely.any():
        _, inverse = np.unique(bad_nodes[lonely], return_inverse=True)
        out[lonely] = n_labels + inverse.ravel()
    return out
