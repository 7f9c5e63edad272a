"""What the software rasterizer draws into and what sort-last compositing exchanges.

A :class:`Frame` holds, per pixel of an image (row 0 at the top): the colour, the window depth
of the visible fragment and the global index of the triangle it came from. The index makes
depth ties deterministic: of two fragments at one depth the lower triangle index wins — the
fragment a single GL-style renderer drawing the triangles in index order with the ``LESS``
depth test keeps — so a composite of domains equals the one-process image exactly.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

CLEAR_DEPTH = 1.0  # as glClearDepth(1): a fragment must be nearer than the far plane
NO_TRIANGLE = -1


@dataclass
class Frame:
    """``color`` (H, W, 4) uint8 RGBA, row 0 at the top; ``depth`` (H, W) float32 window depth
    in [0, 1] (``CLEAR_DEPTH`` where nothing is drawn); ``triangle`` (H, W) int64 global index
    of the triangle seen (``NO_TRIANGLE`` where nothing is drawn)."""

    color: np.ndarray
    depth: np.ndarray
    triangle: np.ndarray

    @classmethod
    def empty(cls, width: int, height: int, background=(255, 255, 255, 255)) -> Frame:
        """A cleared frame: ``background`` RGBA (0–255) everywhere, nothing drawn."""
        color = np.empty((height, width, 4), np.uint8)
        color[...] = np.asarray(background, np.uint8)
        return cls(color, np.full((height, width), CLEAR_DEPTH, np.float32),
                   np.full((height, width), NO_TRIANGLE, np.int64))

    @property
    def size(self) -> tuple[int, int]:
        """(width, height) in pixels."""
        return self.color.shape[1], self.color.shape[0]

    @property
    def nbytes(self) -> int:
        return self.color.nbytes + self.depth.nbytes + self.triangle.nbytes
