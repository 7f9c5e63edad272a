"""Texture atlas of planar subpatches (fe2003 §4): plane frames, texel scale, shelf packing.

Each subpatch is projected onto its least-squares plane (the two eigenvectors of the largest
eigenvalues of its nodes' covariance span the plane); one scale in texels per model unit serves
the whole model, chosen by the paper's Nyquist rule so that the smallest element still gets at
least ``texels_per_edge`` × ``texels_per_edge`` texels (every projected element edge at least that
long in texels), or, per subpatch and axis, so that a quantile of its element extents does (a
few small elements then no longer set the texture memory of a whole subpatch). The subpatch
rectangles, each with a ``border`` of texels for the dilation of
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


def quantile_of(values: np.ndarray, q: float) -> float:
    """``np.quantile(values, q)`` (its default "linear" method) of a non-empty 1-D array of
    finite values, the same float64 value to the last bit, without numpy's general machinery
    (a subpatch asks for two of these; the atlas of a car asks some 10⁵). The same arithmetic
    as numpy's: index (n − 1)·q, the two order statistics around it, and its interpolation
    ``a + (b − a)·γ`` (``b − (b − a)·(1 − γ)`` from γ = 0.5 on)."""
    n = len(values)
    if q == 0.0:
        return float(values.min())
    index = (n - 1) * q
    if index >= n - 1:
        return float(values.max())
    below = int(np.floor(index))
    a, b = np.partition(values, (below, below + 1))[below:below + 2]
    a, b = float(a), float(b)
    gamma = index - below
    diff = b - a
    return b - diff * (1 - gamma) if gamma >= 0.5 else a + diff * gamma


def _min_extents(c2: np.ndarray, elements_local: np.ndarray, quantile: float = 0.0) -> np.ndarray:
    """(2,) the smallest (``quantile`` 0) or the ``quantile``-quantile of the non-zero extents
    of the elements along each plane axis; inf along an axis where none is positive."""
    corners = c2[elements_local]
    ext = corners.max(axis=1) - corners.min(axis=1)
    out = np.full(2, np.inf)
    for k in range(2):
        positive = ext[:, k][ext[:, k] > 0]
        if positive.size:
            out[k] = quantile_of(positive, quantile)  # quantile 0: the smallest
    return out


def _axis_scales(c2: np.ndarray, corners: np.ndarray, texels: float, quantile: float,
                 scale_by: str, fallback: float, max_scale: float | None) -> np.ndarray:
    """(2,) texels per model unit along the plane axes of one subpatch, nodes at ``c2``,
    elements ``corners`` (local node indices): see :func:`build_atlas`."""
    ext = _min_extents(c2, corners, quantile)
    su = np.where(np.isfinite(ext), texels / ext, fallback)
    if scale_by == "width":
        su = su * _width_factor(c2 * su, corners, texels, quantile)
    if max_scale is not None:
        su = np.minimum(su, max_scale)
    return su


def _width_factor(t2: np.ndarray, elements_local: np.ndarray, texels: float,
                  quantile: float) -> float:
    """The factor that makes the ``quantile`` of the element widths at texel coordinates ``t2``
    equal ``texels`` (1 where no element has a width)."""
    from .wiretex import element_widths

    width = element_widths(t2[elements_local])
    width = width[width > 0]
    if not width.size:
        return 1.0
    return float(texels / quantile_of(width, quantile))


def build_atlas(coords, elements, labels, *, texels_per_edge: float = 2.0, border: int = 2,
                width: int | None = None, per_subpatch: bool = False,
                max_scale: float | None = None, quantile: float = 0.0,
                multiple: int = 1, scale_by: str = "extent", turns: int = 1) -> Atlas:
    """Project every subpatch of ``labels`` ((M,) per element) onto its plane and pack them.

    With ``per_subpatch`` each subpatch gets its own scale per plane axis, so that its smallest
    element extent along that axis spans ``texels_per_edge`` texels (the paper's per-dimension
    factors); ``scales`` then holds {label: (s_u, s_v)} and ``scale`` their smallest value.
    With ``quantile`` q in [0, 1) the ``q``-quantile of the subpatch's element extents along
    each axis spans ``texels_per_edge`` instead (q = 0: the smallest, the paper's rule), so that
    a few small elements do not set the scale of a whole subpatch; the elements below it get
    fewer texels (see :func:`workbench.algo.fepatch.wiretex.element_widths`).
    With ``scale_by`` "width", the ratio of the two axis scales stays that of the extent rule
    and both are then scaled together so that the ``quantile`` of the element widths in texels
    (:func:`workbench.algo.fepatch.wiretex.element_widths`, the smaller height of an element,
    which a sheared element has far below its extents) is ``texels_per_edge``: at most that
    share of a subpatch's elements is narrower.
    With ``turns`` > 1 (``per_subpatch`` only), the plane axes of each subpatch are also tried
    turned by k/``turns`` of a right angle, k = 0..turns-1, and the turn whose rectangle is
    smallest is kept (``uv`` then lies in the turned axes; ``plane_frames`` is unchanged).
    ``max_scale`` (texels per model unit) caps the scales, for elements collapsed along an axis.
    ``multiple``: the atlas width and height are rounded up to a multiple of it (a coarser
    texture that shares the texture coordinates needs sizes it divides).

    ``coords`` (N, 3) float64, ``elements`` (M, 4) node indices (a triangle repeats its third
    node). ``width`` of the atlas in texels defaults to the one, among 0.9 to 1.5 times the
    square root of the rectangles' total area (rounded up to a multiple of 4), whose shelves
    leave the smallest atlas. Refuses mismatched shapes and meshes whose
    projected edges are all of zero length, a ``quantile`` outside [0, 1) and a ``multiple``
    below 1.
    """
    if scale_by not in ("extent", "width"):
        raise ValueError(f"scale_by must be 'extent' or 'width', got {scale_by!r}")
    if int(turns) != turns or turns < 1:
        raise ValueError(f"turns must be a positive integer, got {turns!r}")
    turns = int(turns)
    if not 0.0 <= quantile < 1.0:
        raise ValueError(f"quantile must be in [0, 1), got {quantile!r}")
    if int(multiple) != multiple or multiple < 1:
        raise ValueError(f"multiple must be a positive integer, got {multiple!r}")
    multiple = int(multiple)
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
    for label, (nodes, c2) in list(local.items()):
        if not per_subpatch:
            scales[label] = (scale, scale)
            continue
        corners = np.searchsorted(nodes, e[lab == label])
        best = None
        for k in range(turns):
            # the plane axes turned by k/turns of a right angle (a right angle swaps them)
            a = 0.5 * np.pi * k / turns
            turned = c2 @ np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])
            su = _axis_scales(turned, corners, texels_per_edge, quantile, scale_by, scale,
                              max_scale)
            area = np.prod(np.ceil(np.ptp(turned, axis=0) * su) + 1 + 2 * border)
            if best is None or area < best[0]:
                best = (area, turned, su)
        local[label] = (nodes, best[1])
        scales[label] = (float(best[2][0]), float(best[2][1]))
    rects = {}
    for label, (_, c2) in local.items():
        lo, hi = c2.min(axis=0), c2.max(axis=0)
        w, h = np.ceil((hi - lo) * np.array(scales[label])).astype(int) + 1 + 2 * border
        rects[label] = (int(w), int(h), lo)
    total = sum(w * h for w, h, _ in rects.values())
    widest = max(w for w, _, _ in rects.values())
    # shelves: tallest first, left to right, a new shelf when the row is full
    order = sorted(rects, key=lambda k: (-rects[k][1], -rects[k][0], k))
    sizes = [rects[k][:2] for k in order]
    if width is None:
        # the width (a multiple of 4) whose shelves leave the smallest atlas
        candidates = {max(int(np.ceil(np.sqrt(total) * f / 4) * 4), widest)
                      for f in (0.9, 1.0, 1.1, 1.25, 1.5)}
        width = min(sorted(candidates),
                    key=lambda wd: _round_up(wd, multiple) * _shelf_pack(sizes, wd, multiple)[1])
    width = _round_up(max(width, widest), multiple)
    places, height = _shelf_pack(sizes, width, multiple)
    offsets, extents, uv = {}, {}, {}
    for label, (x, y) in zip(order, places):
        w, h, lo = rects[label]
        offsets[label] = (x, y)
        extents[label] = (w, h)
        nodes, c2 = local[label]
        uv[label] = (nodes, (c2 - lo) * np.array(scales[label]) + border + np.array([x, y]))
    return Atlas(size=(int(width), int(height)),
                 scale=float(min(min(v) for v in scales.values())), scales=scales,
                 border=int(border),
                 offsets=offsets, extents=extents, uv=uv,
                 texels_per_element=width * height / len(e), fill=total / (width * height))


def _round_up(n: int, multiple: int) -> int:
    return -(-int(n) // multiple) * multiple


def _shelf_pack(sizes, width: int, multiple: int = 1) -> tuple[list, int]:
    """([(x, y)] of rectangles ``sizes`` [(w, h)] placed left to right on shelves of ``width``
    texels, in the given order; the height, rounded up to ``multiple``)."""
    x = y = shelf = 0
    places = []
    for w, h in sizes:
        if x + w > width:
            x, y, shelf = 0, y + shelf, 0
        places.append((x, y))
        x += w
        shelf = max(shelf, h)
    return places, _round_up(y + shelf, multiple)
