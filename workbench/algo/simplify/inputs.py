"""The checks of the decimation's input and its normal form: triangles with a repeated vertex
dropped, one tolerance per part, coordinates relative to the centre of the bounding box,
duplicate faces kept once, unit normals, areas and plane quadrics of the faces.
"""

from __future__ import annotations

import numpy as np

from .rules import _AREA_REL
from .state import Quadrics


def _check_inputs(vertices, triangles, tol, parts, feature_deg, max_normal_deg, max_depth,
                  passes, feature_min_length=None):
    """The arguments of :func:`~workbench.algo.simplify.hausdorff_decimate` checked: (vertices
    (N, 3) float64, triangles (K, 3) int32, tol float, parts (K,) int32, zeros without parts);
    ValueError for what that function refuses."""
    v = np.asarray(vertices)
    if v.ndim != 2 or v.shape[1] != 3 or v.dtype.kind not in "fiu":
        raise ValueError(f"vertices must be a numeric (N, 3) array, got {v.dtype} {v.shape}")
    v = np.ascontiguousarray(v, np.float64)
    if not np.isfinite(v).all():
        raise ValueError("vertices must be finite")
    t = np.asarray(triangles)
    if t.ndim != 2 or t.shape[1] != 3 or (t.size and t.dtype.kind not in "iu"):
        raise ValueError(f"triangles must be (K, 3) integer vertex indices, got {t.dtype} "
                         f"{t.shape}")
    if len(t) == 0:
        raise ValueError("no triangles to decimate")
    if t.min() < 0 or t.max() >= len(v):
        bad = np.flatnonzero(((t < 0) | (t >= len(v))).any(axis=1))
        raise ValueError(f"{len(bad)} triangles index missing vertices, first {bad[:5].tolist()}")
    t = np.ascontiguousarray(t, np.int32)
    tol = float(tol)
    if not np.isfinite(tol) or tol <= 0:
        raise ValueError(f"tol must be a positive finite number, got {tol!r}")
    if parts is None:
        p = np.zeros(len(t), np.int32)
    else:
        p = np.asarray(parts)
        if p.shape != (len(t),) or (p.size and p.dtype.kind not in "iu"):
            raise ValueError(f"parts must be ({len(t)},) integer labels, got {p.dtype} {p.shape}")
        p = np.ascontiguousarray(p, np.int32)
    if not 0.0 <= float(feature_deg) <= 180.0:
        raise ValueError(f"feature_deg must be within [0, 180] degrees, got {feature_deg}")
    if not 0.0 < float(max_normal_deg) <= 180.0:
        raise ValueError(f"max_normal_deg must be within (0, 180] degrees, got {max_normal_deg}")
    if max_depth is not None and (int(max_depth) != max_depth or not 0 <= max_depth <= 12):
        raise ValueError(f"max_depth must be an integer within [0, 12], got {max_depth}")
    if int(passes) != passes or passes < 1:
        raise ValueError(f"passes must be a positive integer, got {passes}")
    if feature_min_length is not None and not (np.isfinite(feature_min_length)
                                               and feature_min_length >= 0):
        raise ValueError(f"feature_min_length must be None or a finite number >= 0, got "
                         f"{feature_min_length!r}")
    return v, t, tol, p


def _repeated_index(t: np.ndarray) -> np.ndarray:
    """(K,) bool: the triangles of (K, 3) ``t`` that repeat a vertex index; ValueError when
    every one does."""
    repeated = (t[:, 0] == t[:, 1]) | (t[:, 1] == t[:, 2]) | (t[:, 2] == t[:, 0])
    if repeated.all():
        raise ValueError("every triangle repeats a vertex index: nothing to decimate")
    return repeated


def _part_tolerances(v: np.ndarray, t: np.ndarray, p: np.ndarray, tol: float, relative: bool):
    """The sorted part labels of ``p``, each triangle's index among them, and each part's
    tolerance in model units: ``tol`` times the diagonal of the bounding box of the part's
    triangles with ``relative``, else ``tol``."""
    labels, part_index = np.unique(p, return_inverse=True)
    part_index = part_index.ravel()
    corner_part = np.repeat(part_index, 3)
    lo = np.full((len(labels), 3), np.inf)
    hi = np.full((len(labels), 3), -np.inf)
    np.minimum.at(lo, corner_part, v[t.ravel()])
    np.maximum.at(hi, corner_part, v[t.ravel()])
    diagonal = np.linalg.norm(hi - lo, axis=1)
    tol_of_label = tol * diagonal if relative else np.full(len(labels), tol)
    return labels, part_index, tol_of_label


def _box_centre(v: np.ndarray, t: np.ndarray) -> np.ndarray:
    """(3,) the centre of the bounding box of the vertices of ``v`` that ``t`` uses."""
    used_all = np.unique(t)
    return 0.5 * (v[used_all].min(axis=0) + v[used_all].max(axis=0))


def _distinct_faces(t: np.ndarray, p: np.ndarray):
    """The faces of triangles ``t`` with part labels ``p``, duplicates (the same vertex set
    within a part) kept once, in the order of their first occurrence: faces (M, 3) int32,
    their parts (M,) int32 and the face of each triangle (K,) int64."""
    sorted_t = np.sort(t, axis=1).astype(np.int64)
    fkey = np.stack([p.astype(np.int64), sorted_t[:, 0], sorted_t[:, 1], sorted_t[:, 2]], 1)
    group, first = _group_rows(fkey)
    order = np.argsort(first)          # faces in the order of their first occurrence
    rank = np.empty(len(first), np.int64)
    rank[order] = np.arange(len(first))
    orig_face = rank[group]
    first = first[order]
    F = np.ascontiguousarray(t[first], np.int32)
    fpart = np.ascontiguousarray(p[first], np.int32)
    return F, fpart, orig_face


def _unit_normals(corners: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Unit normals (zero where degenerate), areas and a degenerate mask of (K, 3, 3) corners."""
    cross = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    length = np.linalg.norm(cross, axis=1)
    edges = corners[:, [1, 2, 0]] - corners
    longest = (edges ** 2).sum(axis=2).max(axis=1)
    degenerate = ~(length > _AREA_REL * longest)
    unit = np.where(degenerate[:, None], 0.0, cross / np.where(degenerate, 1.0, length)[:, None])
    return unit, 0.5 * length, degenerate


def _group_rows(rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Equal rows of an (R, C) int64 array: a group id per row and each group's first row."""
    order = np.lexsort(rows.T[::-1])
    ordered = rows[order]
    new = np.ones(len(rows), bool)
    new[1:] = (ordered[1:] != ordered[:-1]).any(axis=1)
    group = np.empty(len(rows), np.int64)
    group[order] = np.cumsum(new) - 1
    return group, order[new]     # lexsort is stable: the first of a group is its smallest row


def _quadrics(V: np.ndarray, F: np.ndarray, n_origin: np.ndarray,
              face_area: np.ndarray) -> Quadrics:
    """Plane quadrics of the faces F (unit normals ``n_origin``), area weighted, accumulated
    per vertex of V."""
    n_vert = len(V)
    d = -np.einsum("ij,ij->i", n_origin, V[F[:, 0]])
    nx, ny, nz = n_origin[:, 0], n_origin[:, 1], n_origin[:, 2]
    q = np.stack([nx * nx, ny * ny, nz * nz, nx * ny, nx * nz, ny * nz, nx * d, ny * d, nz * d,
                  d * d], 1) * face_area[:, None]
    Q = np.zeros((n_vert, 10))
    area = np.zeros(n_vert)
    for k in range(3):
        np.add.at(Q, F[:, k], q)
        np.add.at(area, F[:, k], face_area)
    return Quadrics(Q, area)
