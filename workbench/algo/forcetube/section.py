"""The force through one section plane (see the package notes: the cut integral and the tie
rule), and the stress tensors of a mesh's element fields."""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from ...scene.mesh import FEMesh

#: the element fields of the membrane stress tensor (global axes) the section force reads
STRESS_FIELDS = ("stress_xx", "stress_yy", "stress_zz", "stress_xy", "stress_yz", "stress_zx")
THICKNESS_FIELD = "thickness"

# (row, column) of each of the six components in the 3 × 3 tensor, in STRESS_FIELDS order.
_VOIGT = ((0, 0), (1, 1), (2, 2), (0, 1), (1, 2), (2, 0))


def _signed(x: np.ndarray, point: np.ndarray, normal: np.ndarray) -> np.ndarray:
    """Signed distances (x − p)·n, element-wise so that a node gets the same value in every
    array it appears in (the classification must not depend on the summation order)."""
    return ((x[..., 0] - point[0]) * normal[0] + (x[..., 1] - point[1]) * normal[1]
            + (x[..., 2] - point[2]) * normal[2])


def _plane(point, normal) -> tuple[np.ndarray, np.ndarray]:
    p = np.asarray(point, dtype=np.float64).reshape(-1)
    n = np.asarray(normal, dtype=np.float64).reshape(-1)
    if p.shape != (3,) or n.shape != (3,):
        raise ValueError(f"plane point and normal must be 3-vectors, got {p.shape} and {n.shape}")
    if not (np.isfinite(p).all() and np.isfinite(n).all()):
        raise ValueError("plane point and normal must be finite")
    length = np.linalg.norm(n)
    if length == 0:
        raise ValueError("plane normal must not be zero")
    return p, n / length


def crossing_elements(coords, elements, point, normal) -> np.ndarray:
    """(C,) int64 indices of the elements the plane crosses: at least one node with signed
    distance < 0 and one ≥ 0 (the tie rule of the module notes; elements that only touch the
    plane from the positive side are not listed). Brute force over all elements, vectorised."""
    p, n = _plane(point, normal)
    s = _signed(np.asarray(coords, dtype=np.float64), p, n)[np.asarray(elements)]
    return np.flatnonzero((s.min(axis=1) < 0) & (s.max(axis=1) >= 0)).astype(np.int64)


def _cut_vectors(x: np.ndarray, s: np.ndarray) -> np.ndarray:
    """(C, 3) Σ over an element's triangles of c × ν̂: the cut length times its in-surface unit
    normal. ``x`` (C, 4, 3) node positions, ``s`` (C, 4) signed distances."""
    total = np.zeros((len(x), 3))
    for tri in ((0, 1, 2), (0, 2, 3)):
        xt, st = x[:, tri], s[:, tri]
        nu = np.cross(xt[:, 1] - xt[:, 0], xt[:, 2] - xt[:, 0])
        area2 = np.linalg.norm(nu, axis=1)
        ok = area2 > 0
        nu[ok] /= area2[ok, None]
        nu[~ok] = 0.0
        neg = st < 0
        cut = np.zeros((len(x), 3))
        for a, b in ((0, 1), (1, 2), (2, 0)):
            mixed = neg[:, a] != neg[:, b]
            if not mixed.any():
                continue
            a_neg = neg[:, a][mixed]
            xa, xb, sa, sb = xt[mixed, a], xt[mixed, b], st[mixed, a], st[mixed, b]
            # canonical order (negative end first) so a shared edge gives one crossing point
            xn = np.where(a_neg[:, None], xa, xb)
            xp = np.where(a_neg[:, None], xb, xa)
            sn = np.where(a_neg, sa, sb)
            sp = np.where(a_neg, sb, sa)
            gap = sp - sn
            crossing = (sp / gap)[:, None] * xn + (-sn / gap)[:, None] * xp
            # entering the negative part (a ≥ 0 → b < 0) ends the cut, leaving it starts it
            sign = np.where(a_neg, -1.0, 1.0)
            cut[mixed] += sign[:, None] * crossing
        total += np.cross(cut, nu)
    return total


def _section(coords, elements, thickness, stress, p, n, candidates) -> tuple[np.ndarray, int]:
    """(force (3,), number of elements crossed) over the ``candidates`` (element indices)."""
    if len(candidates) == 0:
        return np.zeros(3), 0
    conn = elements[candidates]
    x = coords[conn]
    s = _signed(x, p, n)
    w = _cut_vectors(x, s)
    crossed = (w != 0).any(axis=1)
    if not crossed.any():
        return np.zeros(3), 0
    idx = candidates[crossed]
    force = np.einsum("e,eij,ej->i", thickness[idx], stress[idx], w[crossed])
    return force, int(crossed.sum())


def _check_arrays(coords, elements, thickness, stress):
    coords = np.asarray(coords, dtype=np.float64)
    elements = np.asarray(elements)
    thickness = np.asarray(thickness, dtype=np.float64)
    stress = np.asarray(stress, dtype=np.float64)
    if coords.ndim != 2 or coords.shape[1] != 3:
        raise ValueError(f"coords must be (N, 3), got {coords.shape}")
    if elements.ndim != 2 or elements.shape[1] != 4 or elements.dtype.kind not in "iu":
        raise ValueError(f"elements must be (M, 4) integers, got {elements.shape} "
                         f"{elements.dtype}")
    m = len(elements)
    if thickness.shape != (m,):
        raise ValueError(f"thickness must be ({m},), got {thickness.shape}")
    if stress.shape != (m, 3, 3):
        raise ValueError(f"stress must be ({m}, 3, 3), got {stress.shape}")
    if m and (elements.min() < 0 or elements.max() >= len(coords)):
        raise ValueError("elements reference nodes outside coords")
    if not np.isfinite(coords).all():
        bad = np.flatnonzero(~np.isfinite(coords).all(axis=1))
        raise ValueError(f"coords must be finite; not finite at nodes {bad[:5].tolist()}")
    return coords, elements.astype(np.int64, copy=False), thickness, stress


def _candidates(found, m: int) -> np.ndarray:
    idx = np.asarray(found)
    if idx.dtype == bool:
        if idx.shape != (m,):
            raise ValueError(f"cut returned a mask of shape {idx.shape}, expected ({m},)")
        return np.flatnonzero(idx)
    idx = idx.reshape(-1)
    if idx.size and idx.dtype.kind not in "iu":
        raise ValueError(f"cut must return element indices (integers), got {idx.dtype}")
    idx = np.unique(idx.astype(np.int64))
    if idx.size and (idx[0] < 0 or idx[-1] >= m):
        raise ValueError(f"cut returned element indices outside 0..{m - 1}")
    return idx


def section_force(coords, elements, thickness, stress, point, normal,
                  cut: Callable | None = None) -> np.ndarray:
    """(3,) float64 force transmitted through the plane (``point``, ``normal``) by the shells
    it cuts: Σ t_e · σ_e · (m L)_e over the crossed elements (see the module notes), in
    thickness × stress × length units (N for mm and MPa). It is the force the material on the
    side ``normal`` points to exerts on the other side; its component along the unit normal
    is the axial force (positive in tension).

    ``coords`` (N, 3) node positions, ``elements`` (M, 4) node indices (a triangle repeats its
    third node), ``thickness`` (M,) shell thicknesses, ``stress`` (M, 3, 3) symmetric
    mid-surface stress tensors in global coordinates. ``normal`` need not be unit length.

    ``cut(point, normal)`` may return the candidate element indices (a bounding-volume
    hierarchy's plane query, or a bool mask of length M); any superset of the crossed
    elements gives the same force (elements that do not cross contribute exactly zero,
    duplicates are dropped). By default all elements are tested (:func:`crossing_elements`).
    A plane that cuts nothing gives a zero vector. A crossed element with a non-finite stress
    or thickness (a rigid shell in a d3plot) makes the force NaN.

    Refused (ValueError): bad shapes, node indices out of range, non-finite coordinates, a
    non-finite plane or a zero normal.
    """
    coords, elements, thickness, stress = _check_arrays(coords, elements, thickness, stress)
    p, n = _plane(point, normal)
    if cut is None:
        idx = crossing_elements(coords, elements, p, n)
    else:
        idx = _candidates(cut(p, n), len(elements))
    return _section(coords, elements, thickness, stress, p, n, idx)[0]


# --------------------------------------------------------------------------- mesh fields
def _missing(mesh: FEMesh, names: Sequence[str]) -> list[str]:
    return [name for name in names if name not in mesh.element_fields]


def stress_tensor(mesh: FEMesh, step: int | None = None,
                  fields: Sequence[str] = STRESS_FIELDS) -> np.ndarray:
    """(M, 3, 3) float64 symmetric stress tensors of ``step`` from the six element fields
    ``fields`` (xx, yy, zz, xy, yz, zx, in that order; the d3plot reader's
    ``stress_xx`` … ``stress_zx`` by default, global coordinates, stress units).

    Refused (ValueError): fields missing from the mesh (the message lists its element fields),
    or not six names.
    """
    fields = tuple(fields)
    if len(fields) != 6:
        raise ValueError(f"stress fields must name 6 components (xx, yy, zz, xy, yz, zx), "
                         f"got {len(fields)}")
    missing = _missing(mesh, fields)
    if missing:
        raise ValueError(f"{mesh.name} has no stress fields {missing}; its element fields: "
                         f"{sorted(mesh.element_fields)} (a d3plot with shell stresses has "
                         f"{', '.join(STRESS_FIELDS)})")
    out = np.empty((mesh.n_elements, 3, 3))
    for name, (i, j) in zip(fields, _VOIGT):
        values = mesh.element_field(name, step)
        out[:, i, j] = values
        out[:, j, i] = values
    return out
