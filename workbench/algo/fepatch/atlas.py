"""Texture atlas of planar subpatches (fe2003 §4): plane frames, texel scale, shelf packing.

Each subpatch is projected onto its least-squares plane (the two eigenvectors of the largest
eigenvalues of its nodes' covariance span the plane); one scale in texels per model unit serves
the whole model, chosen by the paper's Nyquist rule so that the smallest element still gets at
least ``texels_per_edge`` × ``texels_per_edge`` texels (every projected element edge at least that
long in texels). The subpatch rectangles, each with a ``border`` of texels for the dilation of
:func:`workbench.algo.fepatch.normalmap.dilate_texels`, are packed into one atlas by shelves
(tallest first, rows of a fixed width).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["Atlas", "plane_frames", "build_atlas"]


def plane_frames(coords, elements, labels) -> dict[int, tuple[np.ndarray, np.ndarray]]:
    """Per subpatch label: (origin (3,), axes (3, 3)) with rows u, v, normal -- the eigenvectors
    of the covariance of the subpatch's nodes, largest eigenvalue first; u × v = normal."""
    c = np.asarray(coords, np.float64)
    e = np.asarray(elements)
    lab = np.asarray(labels)
    frames = {}
    for label in np.unique(lab):
        nodes = np.unique(e[lab == label])
        p = c[nodes]
        origin = p.mean(axis=0)
        q = p - origin
        w, vec = np.linalg.eigh(q.T @ q)
        u, v = vec[:, 2], vec[:, 1]
        frames[int(label)] = (origin, np.stack([u, v, np.cross(u, v)]))
    return frames


@dataclass
class Atlas:
    """A packed atlas. ``size`` (width, height) in texels; ``scale`` texels per model unit;
    ``offsets`` {label: (x0, y0)} of each subpatch's rectangle (border included) and ``extents``
    {label: (w, h)}; ``uv`` {label: (nodes, (n, 2) texel coordinates)} of the subpatch's nodes;
    ``texels_per_element``: atlas texels over element count (the paper's memory measure)."""

    size: tuple[int, int]
    scale: float
    scales: dict  # {label: (s_u, s_v)} texels per model unit along the plane axes
    border: int
    offsets: dict
    extents: dict
    uv: dict
    texels_per_element: float
    fill: float  # share of the atlas covered by subpatch rectangles


def _min_projected_edge(c2: np.ndarray, elements_local: np.ndarray) -> float:
    e = elements_local
    nxt = e[:, [1, 2, 3, 0]]
    d = np.linalg.norm(c2[e] - c2[nxt], axis=2)
    d = d[(e != nxt)]  # the zero-length edge of a triangle (c == d) is not an edge
    return float(d.min()) if d.size else np.inf


def _min_extents(c2: np.ndarray, elements_local: np.ndarray) -> np.ndarray:
    """(2,) the smallest non-zero extent of any element along each plane axis."""
    corners = c2[elements_local]
    ext = corners.max(axis=1) - corners.min(axis=1)
    out = np.full(2, np.inf)
    for k in range(2):
        positive = ext[:, k][ext[:, k] > 0]
        if positive.size:
            out[k] = positive.min()
    return out


def build_atlas(coords, elements, labels, *, texels_per_edge: float = 2.0, border: int = 2,
                width: int | None = None, per_subpatch: bool = False,
                max_scale: float | None = None) -> Atlas:
    """Project every subpatch of ``labels`` ((M,) per element) onto its plane and pack them.

    With ``per_subpatch`` each subpatch gets its own scale per plane axis, so that its smallest
    element extent along that axis spans ``texels_per_edge`` texels (the paper's per-dimension
    factors); ``scales`` then holds {label: (s_u, s_v)} and ``scale`` their smallest value.
    ``max_scale`` (texels per model unit) caps the scales, for elements collapsed along an axis.

    ``coords`` (N, 3) float64, ``elements`` (M, 4) node indices (a triangle repeats its third
    node). ``width`` of the atlas in texels defaults to the square root of the rectangles' total
    area, times 1.1, rounded up to a multiple of 4. Refuses mismatched shapes and meshes whose
    projected edges are all of zero length.
    """
    c = np.asarray(coords, np.float64)
    e = np.asarray(elements, np.int64)
    lab = np.asarray(labels)
    if e.ndim != 2 or e.shape[1] != 4 or lab.shape != (len(e),):
        raise ValueError(f"elements must be (M, 4) with (M,) labels, got {e.shape} and {lab.shape}")
    frames = plane_frames(c, e, lab)
    local = {}
    min_edge = np.inf
    for label, (origin, axes) in frames.items():
        sel = e[lab == label]
        nodes, inverse = np.unique(sel, return_inverse=True)
        c2 = (c[nodes] - origin) @ axes[:2].T
        local[label] = (nodes, c2)
        min_edge = min(min_edge, _min_projected_edge(c2, inverse.reshape(sel.shape)))
    if not np.isfinite(min_edge) or min_edge <= 0:
        raise ValueError("no element has a projected edge of non-zero length")
    scale = texels_per_edge / min_edge
    if max_scale is not None:
        scale = min(scale, max_scale)
    scales = {}
    for label, (nodes, c2) in local.items():
        if per_subpatch:
            sel = e[lab == label]
            ext = _min_extents(c2, np.searchsorted(nodes, sel))
            su = np.where(np.isfinite(ext), texels_per_edge / ext, scale)
            if max_scale is not None:
                su = np.minimum(su, max_scale)
            scales[label] = (float(su[0]), float(su[1]))
        else:
            scales[label] = (scale, scale)
    rects = {}
    for label, (nodes, c2) in local.items():
        lo, hi = c2.min(axis=0), c2.max(axis=0)
        w, h = np.ceil((hi - lo) * np.array(scales[label])).astype(int) + 1 + 2 * border
        rects[label] = (int(w), int(h), lo)
    total = sum(w * h for w, h, _ in rects.values())
    if width is None:
        width = int(np.ceil(np.sqrt(total) * 1.1 / 4) * 4)
    width = max(width, max(w for w, _, _ in rects.values()))
    # shelves: tallest first, left to right, a new shelf when the row is full
    order = sorted(rects, key=lambda k: (-rects[k][1], -rects[k][0], k))
    x = y = shelf = 0
    offsets, extents, uv = {}, {}, {}
    for label in order:
        w, h, lo = rects[label]
        if x + w > width:
            x, y, shelf = 0, y + shelf, 0
        offsets[label] = (x, y)
        extents[label] = (w, h)
        nodes, c2 = local[label]
        uv[label] = (nodes, (c2 - lo) * np.array(scales[label]) + border + np.array([x, y]))
        x += w
        shelf = max(shelf, h)
    height = y + shelf
    return Atlas(size=(int(width), int(height)),
                 scale=float(min(min(v) for v in scales.values())), scales=scales,
                 border=int(border),
                 offsets=offsets, extents=extents, uv=uv,
                 texels_per_element=width * height / len(e), fill=total / (width * height))
