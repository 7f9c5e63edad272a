"""Exact images of spacetime solutions: the shading model evaluated in float64 at pixel centres.

For a slice seen from the top (orthographic, looking down −z) a pixel centre (x, y) shows the
polygon containing it, whatever the heights, so the exact colour is the shading of the
element's polynomial at (x, y, t). The 1-D bar is drawn in its (x, t) plane and a pixel centre
is the spacetime point itself. These are the references of st2005's per-vertex/per-pixel
comparison (its Fig. 3, 5 and 8).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .poly import evaluate
from .raster import PixelGrid, locate_pixels
from .shading import shade


@dataclass
class ExactImage:
    """rgb (H, W, 3) float64 in [0, 1], NaN-free, background where ``covered`` is False;
    ``polygon`` (H, W) the polygon each centre lies in (−1: none); ``U`` and ``speed`` (H, W)
    float64 (NaN outside the polygons) in kJ/m³ and mm/µs."""

    rgb: np.ndarray
    covered: np.ndarray
    polygon: np.ndarray
    U: np.ndarray
    speed: np.ndarray

    def rgba8(self, background=(1.0, 1.0, 1.0)) -> np.ndarray:
        """(H, W, 4) uint8 rounded image with ``background`` outside the polygons."""
        rgb = np.where(self.covered[..., None], self.rgb, np.asarray(background, np.float64))
        out = np.empty(rgb.shape[:2] + (4,), np.uint8)
        out[..., :3] = np.round(rgb * 255.0)
        out[..., 3] = 255
        return out


def exact_image(corners, element, coeffs, centre, extent, material, grid: PixelGrid, *,
                t: float | None, U_max: float, table, height_scale: float = 1.0,
                lighting: bool = True, chunk: int = 1 << 18) -> ExactImage:
    """The exact top-view image of polygons ``corners`` (P, 4, 2) showing elements ``element``.

    ``t`` is the slice time in µs (corners in (x, y) mm), or None for the spacetime triangles
    of a 1-D bar (corners in (x, t), drawn without lighting). The solution is given as
    :func:`workbench.algo.spacetime.poly.evaluate` takes it; ``table`` is the colour ramp.

    Takes more than 12 arguments because it mirrors its two halves' own signatures: the
    polygons and the solution are passed on as :func:`~workbench.algo.spacetime.poly.evaluate`
    takes them, the shading settings (``U_max``, ``table``, ``height_scale``, ``lighting``) as
    :func:`~workbench.algo.spacetime.shading.shade` takes them, all keyword-only; it is plain
    Python over numpy, no compiled kernel.
    """
    polygon = locate_pixels(corners, grid)
    covered = polygon >= 0
    xs, ys = grid.centres()
    X, Y = np.meshgrid(xs, ys)
    rows = np.flatnonzero(covered)
    elem = np.asarray(element)[polygon.ravel()[rows]]
    px, py = X.ravel()[rows], Y.ravel()[rows]
    if t is None:
        x, y, tt = px, np.zeros_like(px), py
    else:
        x, y, tt = px, py, np.full_like(px, float(t))
    H, W = polygon.shape
    rgb = np.zeros((H * W, 3))
    U = np.full(H * W, np.nan)
    speed = np.full(H * W, np.nan)
    lit = lighting and t is not None
    for start in range(0, len(rows), chunk):
        s = slice(start, start + chunk)
        values = evaluate(coeffs, centre, extent, elem[s], x[s], y[s], tt[s], material)
        rgb[rows[s]] = shade(values["U"], values["grad_speed"], U_max=U_max, table=table,
                             height_scale=height_scale, lighting=lit)
        U[rows[s]] = values["U"]
        speed[rows[s]] = values["speed"]
    return ExactImage(rgb.reshape(H, W, 3), covered, polygon, U.reshape(H, W), speed.reshape(H, W))


def colour_error(image, exact: ExactImage) -> dict:
    """Per-channel colour error of a rendered uint8 image against the exact one, in 1/255.

    Over the pixels the exact image covers: ``max`` and ``mean`` of the largest channel error
    ``|image − 255·exact|``, ``share_over_1`` the share of covered pixels whose error exceeds
    1/255, ``uncovered`` covered pixels the image left in the background colour (white) and
    ``covered`` their count. Errors include the ±½ of rounding to 8 bits.
    """
    img = np.asarray(image)
    if img.shape[:2] != exact.covered.shape:
        raise ValueError(f"image {img.shape[:2]} and exact image {exact.covered.shape} differ in "
                         "size")
    err = np.abs(img[..., :3].astype(np.float64) - 255.0 * exact.rgb).max(axis=2)[exact.covered]
    n = int(exact.covered.sum())
    if n == 0:
        raise ValueError("the exact image covers no pixel")
    white = (img[..., :3] == 255).all(axis=2) & exact.covered
    return {"max": float(err.max()), "mean": float(err.mean()),
            "share_over_1": float((err > 1.0).mean()), "covered": n, "uncovered": int(white.sum())}


def element_boundary(labels: np.ndarray) -> np.ndarray:
    """(H, W) bool: pixels whose 4-neighbourhood holds another label (element index, −1 for
    none) — where a rasteriser may legitimately pick the neighbour's element."""
    p = np.pad(labels, 1, mode="edge")
    centre = p[1:-1, 1:-1]
    return ((p[:-2, 1:-1] != centre) | (p[2:, 1:-1] != centre)
            | (p[1:-1, :-2] != centre) | (p[1:-1, 2:] != centre))


def edge_distance(corners, polygon, x, y) -> np.ndarray:
    """Distance (model units) from points (x, y) to the boundary of their polygons
    ``corners[polygon]`` — how close a pixel centre lies to an element edge, where a rasteriser
    with finite sub-pixel precision may hand it to the neighbour. float64; (K,)."""
    c = np.asarray(corners, np.float64)[np.asarray(polygon)]
    p = np.stack([np.asarray(x, np.float64), np.asarray(y, np.float64)], axis=-1)[:, None, :]
    a, b = c, np.roll(c, -1, axis=1)
    ab = b - a
    length2 = (ab ** 2).sum(axis=2)
    u = np.where(length2 > 0, ((p - a) * ab).sum(axis=2) / np.where(length2 > 0, length2, 1.0), 0.0)
    closest = a + np.clip(u, 0.0, 1.0)[..., None] * ab
    return np.sqrt(((p - closest) ** 2).sum(axis=2)).min(axis=1)
