"""Two-component normal maps (fe2003 §4.1) and the border dilation that keeps them valid.

A unit normal is stored as two of its components; the third is restored as
``+sqrt(1 - a² - b²)``, which loses only its sign, harmless under two-sided lighting (a normal
whose dropped component is negative is stored inverted). The dropped component is the one of
largest magnitude of the subpatch's plane normal, so that within a planar subpatch it stays large
and the restore is well conditioned; there are three restore cases (x, y or z dropped), and
subpatches are clustered by case.

Texels hold the kept components quantised to bytes over [-1, 1]: ``q = round((c + 1) · 127.5)``,
a step of 2/255 and an error of at most 1/255 per component. :func:`restore_error_bound` gives the
resulting worst-case angle.
"""

from __future__ import annotations

import numpy as np

__all__ = ["dropped_axis", "encode_normals", "decode_normals", "restore_error_bound",
           "dilate_texels"]

KEPT = np.array([[1, 2], [0, 2], [0, 1]])  # kept components for dropped axis 0, 1, 2


def dropped_axis(normals) -> np.ndarray:
    """(N,) int8 the axis (0, 1, 2) of each normal's largest-magnitude component."""
    n = np.asarray(normals, np.float64).reshape(-1, 3)
    return np.argmax(np.abs(n), axis=1).astype(np.int8)


def _check_axis(axis, n: int) -> np.ndarray:
    a = np.broadcast_to(np.asarray(axis, np.int64), (n,))
    if a.size and (a.min() < 0 or a.max() > 2):
        raise ValueError(f"dropped axis must be 0, 1 or 2, got values in [{a.min()}, {a.max()}]")
    return a


def encode_normals(normals, axis) -> np.ndarray:
    """(N, 2) uint8 texels of unit ``normals`` (N, 3) with component ``axis`` (scalar or (N,))
    dropped. A normal whose dropped component is negative is inverted first. Refuses normals that
    are not finite unit vectors (to 1e-6) and axes outside 0..2."""
    n = np.asarray(normals, np.float64).reshape(-1, 3)
    if not np.isfinite(n).all():
        raise ValueError("normals must be finite")
    length = np.linalg.norm(n, axis=1)
    if len(n) and np.abs(length - 1.0).max() > 1e-6:
        bad = np.flatnonzero(np.abs(length - 1.0) > 1e-6)
        raise ValueError(f"{len(bad)} normals are not unit vectors, first {bad[:5].tolist()}")
    a = _check_axis(axis, len(n))
    rows = np.arange(len(n))
    flip = np.where(n[rows, a] < 0, -1.0, 1.0)
    kept = n[rows[:, None], KEPT[a]] * flip[:, None]
    return np.clip(np.rint((kept + 1.0) * 127.5), 0, 255).astype(np.uint8)


def decode_normals(texels, axis) -> np.ndarray:
    """(N, 3) float64 unit normals from (N, 2) texels (bytes, or bilinearly interpolated floats in
    byte units) with component ``axis`` restored as ``+sqrt(max(0, 1 - a² - b²))``; kept
    components whose squares exceed 1 (interpolation, quantisation) are scaled back onto the
    unit circle, so the result is always a unit vector."""
    t = np.asarray(texels, np.float64).reshape(-1, 2)
    a = _check_axis(axis, len(t))
    kept = t / 127.5 - 1.0
    sq = (kept ** 2).sum(axis=1)
    over = sq > 1.0
    kept[over] /= np.sqrt(sq[over])[:, None]
    restored = np.sqrt(np.maximum(0.0, 1.0 - (kept ** 2).sum(axis=1)))
    out = np.empty((len(t), 3))
    rows = np.arange(len(t))
    out[rows, a] = restored
    out[rows[:, None], KEPT[a]] = kept
    return out / np.linalg.norm(out, axis=1)[:, None]


def restore_error_bound(min_dropped: float) -> float:
    """Worst angle (radians) between a unit normal and its decoded texel when the dropped
    component has magnitude at least ``min_dropped`` (1/√3 when it is the largest).

    Each kept component is off by at most e = 1/255; the restored one by at most
    ``(|a| + |b|)·e / c_min`` plus the second-order term, bounded here by the first-order chord
    length ``e·sqrt(2 + (sqrt(2)/c_min)²)`` with a 10 % margin for the square root's curvature.
    """
    e = 1.0 / 255.0
    return 1.1 * e * np.sqrt(2.0 + (np.sqrt(2.0) / min_dropped) ** 2)


def dilate_texels(texels, mask, passes: int = 2) -> tuple[np.ndarray, np.ndarray]:
    """Grow the texels of ``mask`` (H, W bool) into their surroundings by ``passes`` rings.

    Each ring takes the texels next to the filled region (8-neighbourhood, a morphological
    dilation by scikit-image) and gives each the mean of its filled neighbours, so that
    bilinear lookups just outside a subpatch's border read values of the subpatch, not of the
    empty atlas. ``texels`` (H, W, C); returns (texels, mask) grown. Texels inside ``mask``
    never change.
    """
    from scipy.ndimage import convolve
    from skimage.morphology import dilation, footprint_rectangle

    values = np.asarray(texels, np.float64).copy()
    filled = np.asarray(mask, bool).copy()
    if values.shape[:2] != filled.shape:
        raise ValueError(f"texels {values.shape[:2]} and mask {filled.shape} differ in size")
    squeeze = values.ndim == 2
    if squeeze:
        values = values[..., None]
    kernel = np.ones((3, 3))
    kernel[1, 1] = 0.0
    square = footprint_rectangle((3, 3))
    for _ in range(int(passes)):
        ring = dilation(filled, square) & ~filled
        if not ring.any():
            break
        count = convolve(filled.astype(np.float64), kernel, mode="constant")
        for ch in range(values.shape[2]):
            total = convolve(np.where(filled, values[..., ch], 0.0), kernel, mode="constant")
            values[..., ch][ring] = total[ring] / count[ring]
        filled |= ring
    out = values[..., 0] if squeeze else values
    if np.issubdtype(np.asarray(texels).dtype, np.integer):
        out = np.clip(np.rint(out), 0, 255).astype(np.asarray(texels).dtype)
    return out, filled
