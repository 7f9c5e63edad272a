"""Carry the vertices of a simplifier that moves them through the states of a time-dependent
result.

A reference simplifier that places its own vertices (quadric edge collapse with optimal
placement, say) gives coordinates for the one state it saw. To measure its output at the other
states of a result, each output vertex is carried along the original surface: at the reference
state it is attached to its closest point on the original triangles of its part
(:meth:`~workbench.algo.nearest.bvh.TriangleBVH.nearest`, exact in float64), as barycentric
coordinates on that triangle plus its offset from that point, and at every state it is placed
at the same barycentric point of the same triangle, at that state's coordinates, plus the same
offset expressed in the triangle's own frame (its first edge, its normal and their cross
product), so that it turns with the triangle. At the reference state the vertex comes back
where the simplifier put it (to rounding); a rigid motion of the mesh moves it rigidly; a
vertex on the surface stays on it. Where the triangle is degenerate (no normal: collinear or
repeated corners) at the reference state or at a later one, the offset is kept as it was in
model coordinates at the reference state.

Coordinates and distances are in model units. Refused with ValueError: ``steps`` that are not
(T, N, 3) finite floats, triangles that are not (K, 3) indices of its vertices, points that are
not (M, 3) finite floats, ``parts`` / ``point_parts`` of the wrong length, a point's part that
no triangle has, a reference state outside ``steps``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from workbench.algo.nearest.bvh import TriangleBVH

__all__ = ["Attachment", "attach", "carry_along"]

# a triangle whose normal is shorter than this share of the product of its two edge lengths
# (the sine of its angle) has no frame
_FLAT_SINE = 1e-12


@dataclass(frozen=True)
class Attachment:
    """Where each of M points sits on a triangle mesh: ``triangle`` (M,) the index of its
    nearest triangle (of its part), ``barycentric`` (M, 3) the closest point's barycentric
    coordinates on it (each in [0, 1], summing to 1), ``offset`` (M, 3) the point less that
    closest point in model coordinates, ``local`` (M, 3) the same in the triangle's frame
    (first edge, second axis, normal) where ``framed`` (M,) says the triangle has one, and
    ``distance`` (M,) the distance, all at the reference state (model units)."""

    triangle: np.ndarray
    barycentric: np.ndarray
    offset: np.ndarray
    local: np.ndarray
    framed: np.ndarray
    distance: np.ndarray

    def place(self, vertices, triangles) -> np.ndarray:
        """The (M, 3) positions of the points with the mesh's vertices at ``vertices`` (N, 3)
        (one state's coordinates; ``triangles`` as attached)."""
        corners = np.asarray(vertices, np.float64)[np.asarray(triangles, np.int64)[self.triangle]]
        foot = np.einsum("mi,mij->mj", self.barycentric, corners)
        axes, ok = _frames(corners)
        turned = np.einsum("mij,mi->mj", axes, self.local)  # the frame back to model axes
        return foot + np.where((self.framed & ok)[:, None], turned, self.offset)


def _frames(corners: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(K, 3, 3) orthonormal frames (rows: first edge, second axis, normal) of triangles
    ``corners`` (K, 3, 3) and (K,) whether each has one."""
    e1 = corners[:, 1] - corners[:, 0]
    e2 = corners[:, 2] - corners[:, 0]
    n = np.cross(e1, e2)
    l1 = np.linalg.norm(e1, axis=1)
    l2 = np.linalg.norm(e2, axis=1)
    ln = np.linalg.norm(n, axis=1)
    ok = (l1 > 0) & (l2 > 0) & (ln > _FLAT_SINE * l1 * l2)
    safe_l1 = np.where(ok, l1, 1.0)[:, None]
    safe_ln = np.where(ok, ln, 1.0)[:, None]
    t1 = e1 / safe_l1
    normal = n / safe_ln
    t2 = np.cross(normal, t1)
    return np.stack([t1, t2, normal], axis=1), ok


def _barycentric(corners: np.ndarray, points: np.ndarray) -> np.ndarray:
    """(M, 3) barycentric coordinates of ``points`` (M, 3), each on its triangle ``corners``
    (M, 3, 3), clipped to [0, 1] and normalised; on a degenerate triangle, those of the point's
    projection on its longest edge."""
    a = corners[:, 0]
    e1 = corners[:, 1] - a
    e2 = corners[:, 2] - a
    d = points - a
    g11 = np.einsum("ij,ij->i", e1, e1)
    g12 = np.einsum("ij,ij->i", e1, e2)
    g22 = np.einsum("ij,ij->i", e2, e2)
    r1 = np.einsum("ij,ij->i", d, e1)
    r2 = np.einsum("ij,ij->i", d, e2)
    det = g11 * g22 - g12 * g12
    flat = ~(det > (_FLAT_SINE ** 2) * g11 * g22) | (g11 <= 0) | (g22 <= 0)
    safe = np.where(flat, 1.0, det)
    u = (g22 * r1 - g12 * r2) / safe
    v = (g11 * r2 - g12 * r1) / safe
    bary = np.stack([1.0 - u - v, u, v], axis=1)
    if flat.any():
        bary[flat] = _edge_barycentric(corners[flat], points[flat])
    bary = np.clip(bary, 0.0, 1.0)
    return bary / bary.sum(axis=1, keepdims=True)


def _edge_barycentric(corners: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Barycentric coordinates of the projections of ``points`` on the longest edge of each
    (degenerate) triangle ``corners``; a triangle shrunk to a point gives its first corner."""
    ends = np.array([[0, 1], [1, 2], [2, 0]])
    vec = corners[:, ends[:, 1]] - corners[:, ends[:, 0]]  # (M, 3 edges, 3)
    length2 = np.einsum("mej,mej->me", vec, vec)
    e = np.argmax(length2, axis=1)
    rows = np.arange(len(points))
    i, j = ends[e, 0], ends[e, 1]
    span = length2[rows, e]
    t = np.einsum("mj,mj->m", points - corners[rows, i], vec[rows, e])
    t = np.clip(np.where(span > 0, t / np.where(span > 0, span, 1.0), 0.0), 0.0, 1.0)
    out = np.zeros((len(points), 3))
    out[rows, i] = 1.0 - t
    out[rows, j] += t
    return out


def _finite_floats(a, ndim: int, name: str, shape: str) -> np.ndarray:
    """``a`` as float64 with ``ndim`` dimensions, the last of 3; ValueError naming ``name``
    and its expected ``shape`` otherwise, or where a coordinate is not finite."""
    x = np.asarray(a)
    if x.ndim != ndim or x.shape[-1] != 3 or not np.issubdtype(x.dtype, np.floating):
        raise ValueError(f"{name} must be {shape} floats, got {x.shape} {x.dtype}")
    x = np.asarray(x, np.float64)
    if not np.isfinite(x).all():
        raise ValueError(f"{name}: non-finite coordinates")
    return x


def _check(steps, triangles, points, parts, point_parts):
    s = _finite_floats(steps, 3, "steps", "(T, N, 3)")
    t = np.asarray(triangles)
    if (t.ndim != 2 or t.shape[1] != 3 or not len(t) or not np.issubdtype(t.dtype, np.integer)
            or t.min() < 0 or t.max() >= s.shape[1]):
        raise ValueError(f"triangles must be (K, 3) indices of the {s.shape[1]} vertices, got "
                         f"{t.shape} {t.dtype}")
    p = _finite_floats(points, 2, "points", "(M, 3)")
    if (parts is None) != (point_parts is None):
        raise ValueError("give both parts and point_parts, or neither")
    if parts is not None:
        parts = np.asarray(parts)
        point_parts = np.asarray(point_parts)
        if parts.shape != (len(t),):
            raise ValueError(f"parts must be ({len(t)},), got {parts.shape}")
        if point_parts.shape != (len(p),):
            raise ValueError(f"point_parts must be ({len(p)},), got {point_parts.shape}")
        missing = np.setdiff1d(np.unique(point_parts), np.unique(parts))
        if len(missing):
            raise ValueError(f"points of parts {missing[:5].tolist()} that no triangle has")
    return s, t.astype(np.int64), p, parts, point_parts


def attach(vertices, triangles, points, *, parts=None, point_parts=None) -> Attachment:
    """The :class:`Attachment` of ``points`` (M, 3) to the triangles ``triangles`` (K, 3) of
    ``vertices`` (N, 3): each to its nearest triangle, among those of its own part where
    ``parts`` (K,) and ``point_parts`` (M,) give the part labels of both."""
    s, t, p, parts, point_parts = _check(np.asarray(vertices)[None], triangles, points, parts,
                                         point_parts)
    v = s[0]
    triangle = np.zeros(len(p), np.int64)
    closest = np.zeros_like(p)
    distance = np.zeros(len(p))
    groups = ([(np.arange(len(t)), np.arange(len(p)))] if parts is None else
              [(np.flatnonzero(parts == label), np.flatnonzero(point_parts == label))
               for label in np.unique(point_parts)])
    for own, which in groups:
        d, tri, c = TriangleBVH(v, t[own]).nearest(p[which])
        triangle[which], closest[which], distance[which] = own[tri], c, d
    corners = v[t[triangle]]
    axes, framed = _frames(corners)
    offset = p - closest
    local = np.where(framed[:, None], np.einsum("mij,mj->mi", axes, offset), 0.0)
    return Attachment(triangle, _barycentric(corners, closest), offset, local, framed, distance)


def carry_along(steps, triangles, points, *, parts=None, point_parts=None,
                reference: int = 0) -> np.ndarray:
    """(T, M, 3): ``points`` (M, 3), given at state ``reference`` of ``steps`` (T, N, 3),
    carried to every state along the triangles ``triangles`` (K, 3) (see the module notes);
    with ``parts`` (K,) and ``point_parts`` (M,), each point along its own part."""
    s, t, p, parts, point_parts = _check(steps, triangles, points, parts, point_parts)
    if not -len(s) <= int(reference) < len(s):
        raise ValueError(f"reference state {reference} is outside the {len(s)} states")
    at = attach(s[int(reference)], t, p, parts=parts, point_parts=point_parts)
    return np.stack([at.place(state, t) for state in s])
