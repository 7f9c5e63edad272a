"""The arrays the slicing kernel (:func:`~.slicing._cut_kernel`) takes, grouped by what they
hold.

Each group is a NamedTuple, which numba passes to a compiled function as one argument and reads
field by field at no cost (the kernel takes each field with its own assignment, never by
unpacking a tuple of them, see :mod:`workbench.algo.softraster.state`); every field keeps one
type from call to call, so that one compiled version serves every slice. Coordinates are the
mesh's (x, y in mm, t in µs).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np


class Points(NamedTuple):
    """The mesh points' coordinates, one contiguous array each."""

    x: np.ndarray   # (P,) float64
    y: np.ndarray   # (P,) float64
    tv: np.ndarray  # (P,) float64 time


class CutCases(NamedTuple):
    """The case tables of a tetrahedron cut by a plane of constant t, indexed by the 4-bit code
    of the corners below the plane, and the corner orders that turn a clockwise polygon
    counter-clockwise."""

    tb: np.ndarray               # (16, 4) intp corner below the plane of each polygon corner
    ta: np.ndarray               # (16, 4) intp corner above it
    n_below: np.ndarray          # (16,) intp corners below (2: a quad)
    opp: np.ndarray              # (16, 4) intp face opposite each polygon edge, -1 inside
    quad_flip: np.ndarray        # (4,) corner order of a flipped quad
    tri_flip: np.ndarray         # (4,) of a flipped triangle
    quad_flip_edges: np.ndarray  # (4,) where a flipped quad's edges go
    tri_flip_edges: np.ndarray   # (4,) a flipped triangle's


class Polygons(NamedTuple):
    """The cut's output, one row per cut tetrahedron."""

    corners: np.ndarray  # (n, 4, 2) float64 counter-clockwise corners (a triangle repeats one)
    is_quad: np.ndarray  # (n,) bool
    outer: np.ndarray    # (n, 4) bool edges on the domain boundary, or (0, 4) when not asked
