"""The rasterization rule of the software rasterizer: fixed-point vertices, pixel centres and
the top-left fill rule — the rule Mesa llvmpipe applies to GL framebuffers, so that the images
can be compared with the EGL paths pixel by pixel.

Coordinates are **image** coordinates: x to the right, y *down* from the top row, pixel (i, j)
(column i, row j) covering [i, i + 1) × [j, j + 1) with its centre at (i + ½, j + ½).

* **Snapping.** A GL window coordinate ``w`` (x right, y *up*, as the viewport transform
  yields it) becomes the integer ``round((w − ½)·2^b)`` (round half to even) with ``b``
  sub-pixel bits, and the y axis is then turned over: ``Y = (H − 1)·2^b − round((w_y − ½)·2^b)``
  for an image ``H`` rows high. In these fixed-point units the centre of pixel (i, j) lies at
  ``(i·2^b, j·2^b)``. (Rounding before the turn matters: halves round to even in GL's
  coordinates.) llvmpipe uses ``b = 8``; the span look-up table of es2008 needs ``b = 0``
  (vertices on pixel centres, integer offsets), which is this module's one deviation from GL
  when it is chosen.
* **Inside.** A triangle is normalised to positive area
  ``A = (x1 − x0)(y2 − y0) − (y1 − y0)(x2 − x0) > 0`` (v1 and v2 swapped otherwise; ``A = 0``
  covers nothing). Edge a → b has the edge function
  ``E(p) = (bx − ax)(py − ay) − (by − ay)(px − ax)``, positive inside. A pixel centre is covered
  when every edge has ``E > 0``, or ``E = 0`` on an edge that is *bottom* (horizontal,
  ``dy = 0``, ``dx < 0``: the other vertex lies above it in the image) or *left* (``dy < 0``).
  Triangles that tile a region therefore cover each pixel centre exactly once; a shared edge
  is drawn once.

This is the top-left rule of Direct3D and of llvmpipe's rasterizer applied in llvmpipe's
memory-row order, which for a GL framebuffer (row 0 at the bottom) shows as bottom-left in
the image; it was checked against llvmpipe on random triangles (exact coverage, also with
vertices and horizontal edges exactly on pixel centres).
Everything is exact integer arithmetic in int64 (fixed coordinates below 2^31 keep the edge
functions below 2^63).
"""

from __future__ import annotations

import numba
import numpy as np

GL_SUBPIXEL_BITS = 8  # llvmpipe's FIXED_ORDER
MAX_SUBPIXEL_BITS = 8


def check_bits(bits: int) -> int:
    """``bits`` as an int in 0..8; ValueError otherwise."""
    if int(bits) != bits or not 0 <= bits <= MAX_SUBPIXEL_BITS:
        raise ValueError(f"sub-pixel bits must be an integer in 0..{MAX_SUBPIXEL_BITS}, got {bits}")
    return int(bits)


def snap(window, height: int, bits: int = GL_SUBPIXEL_BITS) -> np.ndarray:
    """(..., 2) int64 fixed-point image coordinates of GL window coordinates ``window``
    (..., 2) (pixels, y up) in an image ``height`` rows high: ``round((w − ½)·2^bits)`` (half
    to even), y turned over. Non-finite input is refused."""
    w = np.asarray(window, np.float64)
    if w.shape[-1:] != (2,):
        raise ValueError(f"window coordinates must be (..., 2), got {w.shape}")
    if not np.isfinite(w).all():
        raise ValueError("window coordinates must be finite")
    bits = check_bits(bits)
    fixed = np.rint((w - 0.5) * float(1 << bits)).astype(np.int64)
    fixed[..., 1] = ((int(height) - 1) << bits) - fixed[..., 1]
    return fixed


@numba.njit(cache=True, inline="always")
def includes_tie(dx, dy) -> bool:
    """Whether a pixel centre exactly on edge (dx, dy) of a positive-area triangle is covered:
    bottom edges (dy = 0, dx < 0) and left edges (dy < 0)."""
    return dy < 0 or (dy == 0 and dx < 0)


@numba.njit(cache=True, inline="always")
def edge_bias(dx, dy):
    """0 where a tie is covered, 1 where it is not: covered ⇔ ``E − bias ≥ 0`` (integers)."""
    return 0 if (dy < 0 or (dy == 0 and dx < 0)) else 1


def oriented(fixed) -> np.ndarray:
    """(3, 2) int64 triangle with positive area (v1 and v2 swapped if needed); ``fixed`` is
    (3, 2) fixed-point vertices. A zero-area triangle comes back unchanged."""
    t = np.array(fixed, np.int64).reshape(3, 2)
    (x0, y0), (x1, y1), (x2, y2) = t
    if (x1 - x0) * (y2 - y0) - (y1 - y0) * (x2 - x0) < 0:
        t = t[[0, 2, 1]]
    return t


def coverage_mask(fixed, width: int, height: int, bits: int = GL_SUBPIXEL_BITS) -> np.ndarray:
    """(height, width) bool: the pixels whose centres the triangle covers, by brute force.

    ``fixed`` is (3, 2) int fixed-point image coordinates (see :func:`snap`). The reference every
    generator of :mod:`workbench.algo.softraster` is tested against: each pixel centre of the
    image tested against the three edge functions with the tie rule."""
    bits = check_bits(bits)
    t = oriented(fixed)
    (x0, y0), (x1, y1), (x2, y2) = t
    if (x1 - x0) * (y2 - y0) - (y1 - y0) * (x2 - x0) == 0:
        return np.zeros((height, width), bool)
    jj, ii = np.mgrid[0:height, 0:width].astype(np.int64)
    px, py = ii << bits, jj << bits
    inside = np.ones((height, width), bool)
    for (ax, ay), (bx, by) in ((t[0], t[1]), (t[1], t[2]), (t[2], t[0])):
        dx, dy = int(bx - ax), int(by - ay)
        e = dx * (py - ay) - dy * (px - ax)
        inside &= (e > 0) | ((e == 0) & includes_tie(dx, dy))
    return inside
