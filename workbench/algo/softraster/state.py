"""The arrays the rasterizer's kernels share, grouped by what they hold.

Each group is a NamedTuple, which numba passes to a compiled function as one argument and reads
field by field at no cost (and which the interpreted kernels, ``py_func``, read as any tuple); a
kernel takes the fields it needs before its parallel loop, one assignment each (``depth =
target.depth``), never by unpacking a tuple of them: numba's dead-code pass keeps the writes to
an array read from an argument's field, but may drop those to one unpacked from a tuple (the
fragment generator lost its per-tile counts that way). Every field keeps one type from call to
call (the arrays their dtype and order, counts int, flags bool), so that one compiled version
serves every draw. Positions are in pixels, fixed-point ones in units of ``2^-bits`` pixel.

* :class:`Look` -- the shading as the kernels take it;
* :class:`Lit` -- the transform-and-light step's output, per vertex and per triangle;
* :class:`Screen` -- the image and its tiles;
* :class:`Target` -- the buffers drawn into;
* :class:`Bins` -- the fused rasterizer's tile lists;
* :class:`Setup`, :class:`Span`, :class:`Fragments` -- the steps' kept triangles, span table and
  fragment pool;
* :class:`Geometry`, :class:`Camera` -- what the transform-and-light step reads (Python level).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np


class Look(NamedTuple):
    """The shading as the kernels take it."""

    code: int            # the shading kind, its index in ``pipeline.SHADINGS``
    texels: np.ndarray   # (n, 4) uint8 the 1-D colour texture (one zero texel without one)
    texf: np.ndarray     # (n, 4) float32 the same in [0, 1]
    base: np.ndarray     # (3,) float32 the base colour, RGB in [0, 1]
    missing: np.ndarray  # (3,) float32 the colour of a triangle without a value
    linear: bool         # linear texture filtering (else nearest)
    alpha_test: bool     # discard fragments of alpha < 1/2


class Lit(NamedTuple):
    """The transform-and-light step's output. Per vertex: window positions ``fx``, ``fy``
    (fixed point) and depth ``fz``, ``ok`` (placed), ``attr`` (V, n_attr) the shading
    attributes, ``clipd`` (V, P) the clip distances. Per triangle where the shading uses them
    (else one entry): ``tri_light`` the flat light (one entry where it is left to the fused
    draw), ``tri_s`` the texture coordinate; ``tri_missing`` (K,) uint8, 1 for a triangle
    drawn in the missing colour (one 0 entry where ``any_missing`` is False: none is).
    ``pos32`` and ``view32``: the float32 vertices and view the flat light is computed from."""

    fx: np.ndarray           # (V,) int64
    fy: np.ndarray           # (V,) int64
    fz: np.ndarray           # (V,) float32 window depth
    ok: np.ndarray           # (V,) bool
    attr: np.ndarray         # (V, n_attr) float32
    n_attr: int
    clipd: np.ndarray        # (V, P) float32
    tri_light: np.ndarray    # (K,) or (1,) float32
    tri_s: np.ndarray        # (K,) or (1,) float32
    tri_missing: np.ndarray  # (K,) or (1,) uint8
    any_missing: bool
    pos32: np.ndarray        # (V, 3) float32 model units relative to the upload origin
    view32: np.ndarray       # (4, 4) float32


class Screen(NamedTuple):
    """The image: its size in pixels, the sub-pixel bits and the screen tiles."""

    width: int
    height: int
    bits: int     # sub-pixel bits of the fixed-point positions
    shift: int    # a tile is 2^shift pixels a side
    tiles_x: int  # tiles per row


class Target(NamedTuple):
    """The buffers drawn into, (H, W) each."""

    depth: np.ndarray     # float32 window depth
    color: np.ndarray     # uint32 packed RGBA8
    triangle: np.ndarray  # int64 global index of the triangle seen


class Bins(NamedTuple):
    """The fused rasterizer's tile lists: per slot a triangle as the tile reads it."""

    members: np.ndarray  # (slots,) int32 triangle index (in the session)
    mxy: np.ndarray      # (slots, 6) int32 fixed-point vertices
    mz: np.ndarray       # (slots, 3) float32 their depths


class Setup(NamedTuple):
    """The kept triangles of a session as the steps set them up."""

    verts: np.ndarray   # (n, 6) int64 fixed-point vertices, oriented
    box: np.ndarray     # (n, 4) int32 first/last pixel column and row of the box
    fit: np.ndarray     # (n,) bool: the span table holds it
    zplane: np.ndarray  # (n, 1, 3) float64 depth plane over pixel centres


class Span(NamedTuple):
    """The span table as the fragment generator reads it (:mod:`.spantable`)."""

    lo: np.ndarray  # flattened first covered offset of each row, -1 for none (int8)
    hi: np.ndarray  # flattened last covered offset (int8)
    size: int       # its S in pixels


class Fragments(NamedTuple):
    """The fragment pool of a session, tile by tile."""

    start: np.ndarray  # (tiles + 1,) int64 each tile's first slot
    count: np.ndarray  # (tiles,) int64 fragments each tile generated
    tri: np.ndarray    # (slots,) int32 kept-triangle index
    i: np.ndarray      # (slots,) int32 pixel column
    j: np.ndarray      # (slots,) int32 pixel row


class Geometry(NamedTuple):
    """What :func:`~.pipeline.render` draws (checked): see its arguments."""

    pos: np.ndarray                  # (V, 3) float64 or float32
    tris: np.ndarray                 # (K, 3) int64
    normals: np.ndarray | None       # (V, 3)
    values: np.ndarray | None        # (V,)
    triangle_values: np.ndarray | None  # (K,)
    planes: np.ndarray               # (P, 4) float64 clip planes


class Camera(NamedTuple):
    """The view of a draw."""

    view: np.ndarray   # (4, 4) float64
    proj: np.ndarray   # (4, 4) float64 orthographic
    size: tuple        # (W, H) pixels
    bits: int          # sub-pixel bits
