"""Which polygon each pixel centre of an axis-aligned pixel grid falls in (exact, float64).

The exact images of st2005 are evaluated at pixel centres; this finds, for every centre, the
slice polygon (or spacetime triangle) whose element polynomial applies there.
"""

from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np


@dataclass(frozen=True)
class PixelGrid:
    """A ``width`` × ``height`` image of the plane: pixel (i, j) (row i from the top) covers
    x ∈ [left + j·dx, left + (j+1)·dx) and y ∈ (top − (i+1)·dy, top − i·dy]; model units.

    Refuses non-positive sizes and non-finite coordinates.
    """

    left: float
    top: float
    dx: float
    dy: float
    width: int
    height: int

    def __post_init__(self) -> None:
        if not (self.width > 0 and self.height > 0):
            raise ValueError("pixel grid must have a positive size, got "
                             f"{self.width}×{self.height}")
        if not (self.dx > 0 and self.dy > 0
                and np.isfinite([self.left, self.top, self.dx, self.dy]).all()):
            raise ValueError(f"pixel sizes must be positive and coordinates finite: {self}")

    @classmethod
    def fit(cls, lo, hi, width: int, height: int | None = None, margin: float = 0.02) -> PixelGrid:
        """Square pixels showing the box ``lo``–``hi`` (2-D, model units) with ``margin`` (a
        fraction of the larger side) on every side, centred; ``height`` defaults to the box's
        aspect."""
        lo, hi = np.asarray(lo, np.float64), np.asarray(hi, np.float64)
        size = hi - lo
        if not (size > 0).all():
            raise ValueError(f"box must have positive extent, got {lo} – {hi}")
        pad = margin * size.max()
        if height is None:
            height = max(1, int(round(width * (size[1] + 2 * pad) / (size[0] + 2 * pad))))
        d = max((size[0] + 2 * pad) / width, (size[1] + 2 * pad) / height)
        centre = (lo + hi) / 2.0
        return cls(float(centre[0] - d * width / 2), float(centre[1] + d * height / 2), d, d,
                   int(width), int(height))

    @property
    def lo(self) -> np.ndarray:
        return np.array([self.left, self.top - self.dy * self.height])

    @property
    def hi(self) -> np.ndarray:
        return np.array([self.left + self.dx * self.width, self.top])

    def centres(self) -> tuple[np.ndarray, np.ndarray]:
        """(xs (W,), ys (H,)) float64 pixel-centre coordinates, ys from the top row down."""
        return (self.left + (np.arange(self.width) + 0.5) * self.dx,
                self.top - (np.arange(self.height) + 0.5) * self.dy)


@numba.njit(cache=True)
def _locate(corners, left, top, dx, dy, width, height, out):
    for p in range(corners.shape[0]):
        twice_area = 0.0
        for k in range(4):
            ax, ay = corners[p, k, 0] - left, corners[p, k, 1] - top
            bx, by = corners[p, (k + 1) % 4, 0] - left, corners[p, (k + 1) % 4, 1] - top
            twice_area += ax * by - bx * ay
        if not twice_area > 0.0:
            continue  # degenerate (a slice through a vertex or a flat front): covers nothing
        xmin = xmax = corners[p, 0, 0] - left
        ymin = ymax = top - corners[p, 0, 1]  # y measured downwards from the top
        for k in range(1, 4):
            x, y = corners[p, k, 0] - left, top - corners[p, k, 1]
            xmin, xmax = min(xmin, x), max(xmax, x)
            ymin, ymax = min(ymin, y), max(ymax, y)
        # one pixel of slack: the edge test below decides centres on the bounding box
        j0 = max(int(np.ceil(xmin / dx - 0.5)) - 1, 0)
        j1 = min(int(np.floor(xmax / dx - 0.5)) + 1, width - 1)
        i0 = max(int(np.ceil(ymin / dy - 0.5)) - 1, 0)
        i1 = min(int(np.floor(ymax / dy - 0.5)) + 1, height - 1)
        for i in range(i0, i1 + 1):
            py = top - (i + 0.5) * dy
            for j in range(j0, j1 + 1):
                px = left + (j + 0.5) * dx
                inside = True
                for k in range(4):
                    ax, ay = corners[p, k, 0], corners[p, k, 1]
                    bx, by = corners[p, (k + 1) % 4, 0], corners[p, (k + 1) % 4, 1]
                    if (bx - ax) * (py - ay) - (by - ay) * (px - ax) < 0.0:
                        inside = False
                        break
                if inside:
                    out[i, j] = p


def locate_pixels(corners, grid: PixelGrid) -> np.ndarray:
    """(H, W) int64: the polygon containing each pixel centre, −1 where none does.

    ``corners`` (P, 4, 2) float64 are convex counter-clockwise polygons, a triangle repeating
    its third corner; polygons of zero area (degenerate slices) contain nothing. A centre on an
    edge shared by two polygons goes to the later one. The
    test runs in float64 on coordinates relative to the grid, so far-from-origin polygons are
    located as exactly as ones at the origin.
    """
    corners = np.ascontiguousarray(corners, np.float64)
    if corners.ndim != 3 or corners.shape[1:] != (4, 2):
        raise ValueError(f"corners must be (P, 4, 2), got {corners.shape}")
    out = np.full((grid.height, grid.width), -1, np.int64)
    _locate(corners, grid.left, grid.top, grid.dx, grid.dy, grid.width, grid.height, out)
    return out
