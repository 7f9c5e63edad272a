"""Baking the normal map of fe2003 §4.1: rasterise the original elements into the atlas.

Each element, given by its corners in texel units, is split into the triangles (0, 1, 2) and
(0, 2, 3) (a triangle element (a, b, c, c) gives only the first; the second has no area) and
rasterised at texel centres, interpolating its per-corner unit normals barycentrically and
normalising. The two-component encoding and the border dilation are those of
:mod:`workbench.algo.fepatch.normalmap`.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from workbench.algo.fepatch.normalmap import dilate_texels, encode_normals

__all__ = ["bake_normals", "normal_map"]

_INSIDE = 1e-9  # barycentric slack: texel centres on a triangle's edge count as inside
_EMPTY_BYTE = 128  # bytes of texels no element covers (kept components ~0)


@njit(cache=True)
def _raster_normals(uv, nrm, w, h, eps, out, owner):  # pragma: no cover - compiled
    for m in range(uv.shape[0]):
        for t in range(2):
            i0, i1, i2 = 0, 1 + t, 2 + t
            ax, ay = uv[m, i0, 0], uv[m, i0, 1]
            bx, by = uv[m, i1, 0], uv[m, i1, 1]
            cx, cy = uv[m, i2, 0], uv[m, i2, 1]
            area2 = (bx - ax) * (cy - ay) - (cx - ax) * (by - ay)
            if abs(area2) <= 1e-12:
                continue
            x_lo = max(int(np.ceil(min(ax, bx, cx) - 0.5 - 1e-6)), 0)
            x_hi = min(int(np.floor(max(ax, bx, cx) - 0.5 + 1e-6)) + 1, w)
            y_lo = max(int(np.ceil(min(ay, by, cy) - 0.5 - 1e-6)), 0)
            y_hi = min(int(np.floor(max(ay, by, cy) - 0.5 + 1e-6)) + 1, h)
            for i in range(y_lo, y_hi):
                py = i + 0.5
                for j in range(x_lo, x_hi):
                    px = j + 0.5
                    la = ((bx - px) * (cy - py) - (cx - px) * (by - py)) / area2
                    lb = ((cx - px) * (ay - py) - (ax - px) * (cy - py)) / area2
                    lc = 1.0 - la - lb
                    if la < -eps or lb < -eps or lc < -eps:
                        continue
                    nx = la * nrm[m, i0, 0] + lb * nrm[m, i1, 0] + lc * nrm[m, i2, 0]
                    ny = la * nrm[m, i0, 1] + lb * nrm[m, i1, 1] + lc * nrm[m, i2, 1]
                    nz = la * nrm[m, i0, 2] + lb * nrm[m, i1, 2] + lc * nrm[m, i2, 2]
                    length = np.sqrt(nx * nx + ny * ny + nz * nz)
                    if length <= 1e-12:
                        continue
                    out[i, j, 0] = nx / length
                    out[i, j, 1] = ny / length
                    out[i, j, 2] = nz / length
                    owner[i, j] = m


def _check(corners_uv, corner_normals, size):
    from workbench.algo.fepatch.wiretex import _check_corners, _check_size

    uv = _check_corners(corners_uv)
    n = np.asarray(corner_normals, np.float64)
    if n.shape != (len(uv), 4, 3):
        raise ValueError(f"corner_normals must be ({len(uv)}, 4, 3), got {n.shape}")
    if not np.isfinite(n).all():
        raise ValueError("corner_normals must be finite")
    return uv, n, _check_size(size)


def bake_normals(corners_uv, corner_normals, size) -> tuple[np.ndarray, np.ndarray]:
    """Rasterise elements into a (H, W) atlas: (normals (H, W, 3) float64 unit vectors, owner
    (H, W) int32 the element that wrote each texel, −1 where none did; normals there are 0).

    ``corners_uv`` (M, 4, 2) corners in texel units (texel (row i, column j) has its centre at
    (j + ½, i + ½)); ``corner_normals`` (M, 4, 3) unit normals at the corners; ``size`` = (W, H).
    A texel is covered by a triangle of an element when its centre lies inside or on the edge
    (barycentric coordinates ≥ −1e-9); its normal is the barycentric mix of the corner normals,
    normalised (a mix of length ≤ 1e-12, opposite corner normals, leaves the texel empty).
    Where several elements cover a texel the last in element order wins. Refuses bad shapes,
    non-finite input and a non-positive size.
    """
    uv, n, (w, h) = _check(corners_uv, corner_normals, size)
    out = np.zeros((h, w, 3), np.float64)
    owner = np.full((h, w), -1, np.int32)
    _raster_normals(uv, n, w, h, _INSIDE, out, owner)
    return out, owner


def normal_map(corners_uv, corner_normals, axis_per_element, size, dilate: int = 2) -> np.ndarray:
    """The (H, W, 2) uint8 two-component normal map of the elements: :func:`bake_normals`, each
    texel encoded by :func:`~workbench.algo.fepatch.normalmap.encode_normals` with the dropped
    axis of the element that wrote it (``axis_per_element`` (M,) in 0..2), then grown by
    ``dilate`` rings of :func:`~workbench.algo.fepatch.normalmap.dilate_texels`. Texels beyond
    the rings hold bytes 128 (kept components ≈ 0). Refuses what :func:`bake_normals` refuses,
    axes of the wrong shape or outside 0..2 and a negative ``dilate``."""
    uv, n, (w, h) = _check(corners_uv, corner_normals, size)
    axis = np.asarray(axis_per_element)
    if axis.shape != (len(uv),) or not np.issubdtype(axis.dtype, np.integer):
        raise ValueError(f"axis_per_element must be ({len(uv)},) integers, got {axis.shape} "
                         f"{axis.dtype}")
    if len(axis) and (axis.min() < 0 or axis.max() > 2):
        raise ValueError("axis_per_element must hold 0, 1 or 2")
    if int(dilate) != dilate or dilate < 0:
        raise ValueError(f"dilate must be a non-negative integer, got {dilate}")
    normals, owner = bake_normals(uv, n, (w, h))
    mask = owner >= 0
    texels = np.full((h, w, 2), _EMPTY_BYTE, np.uint8)
    texels[mask] = encode_normals(normals[mask], axis[owner[mask]])
    if dilate:
        texels, _ = dilate_texels(texels, mask, passes=int(dilate))
    return texels
