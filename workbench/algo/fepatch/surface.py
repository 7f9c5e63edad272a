"""The textured surface that fe2003's render paths draw: triangles with atlas coordinates, the
two-component normal map and the wire frame, as fe2003's distance texture or as element ids
and corners.

Both the original mesh (every element, split into triangles) and its simplification are
described this way; vertices are duplicated per subpatch, since a node on a subpatch border has
one atlas position in each chart.

Texture conventions (shared with the shaders):

* ``uv`` is in texel units: texel (row i, column j) has its centre at (j + ½, i + ½); the GL
  texture coordinate is ``uv / (W, H)`` with row 0 of the arrays uploaded first.
* ``normal_map`` (H/k, W/k, 2) uint8, k a positive integer (the normal map may be coarser than the
  wire map; both are sampled at ``uv / (W, H)``, the wire map's size), holds two components of the
  unit normal in model coordinates, ``q = round((c + 1)·127.5)``, see
  :mod:`workbench.algo.fepatch.normalmap`; the vertex's ``normal_axis`` says which component was
  dropped (0, 1, 2) and is restored as the positive square root.
* ``wire_map`` (H, W, 4) uint8 holds signed distances in texels, positive inside the outlining
  element: byte ``b`` stands for ``(b − 127.5)/127.5 · wire_range``. Elements of checkerboard
  colour 0 write the channel pair (G, B), colour 1 the pair (R, A); in each pair the first channel
  is the distance to the nearer of the element's edges 0 and 2, the second to the nearer of
  edges 1 and 3 (a triangle (a, b, c, c): its edges ab and ca, element edges 0 and 3, in the
  first, bc alone in the second). Where elements of one pair overlap, a texel inside one keeps
  that element's channels, a texel outside all of them the smallest value per channel; texels
  no element writes hold −wire_range (byte 0). A fragment is on an outline when, in either
  pair, one channel is within half a pixel of zero (inclusive) while the other is not below
  minus half a pixel.
* ``element_map`` (H, W) uint16 or uint32 and ``corner_table`` (M, 4, 2) uint16 hold the wire
  frame the other way (:mod:`workbench.algo.fepatch.wireid`): per texel the index of the
  element under it within its subpatch (the all-ones value for none), the vertex's
  ``element_base`` (V,) the row of its subpatch's first element in ``corner_table``, whose
  rows hold each element's corners in texels times ``corner_frac``. A fragment is on an
  outline where its distance to the nearest edge of the elements of the four texels around it
  is within half a pixel. A surface has one wire frame or the other, not both.
* ``line_edges`` are element edges the wire frame cannot show -- two neighbours of the same
  colour in the distance texture, elements too narrow for the atlas scale, and the outer
  boundary, which either encoding would draw on its inner half only: they are drawn as lines
  in the same frame.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

__all__ = ["CORNER_ROW", "TexturedSurface", "WIRE_PAIRS", "corner_rows"]

WIRE_PAIRS = ((1, 2), (0, 3))  # channels of checkerboard colour 0 (G, B) and colour 1 (R, A)
CORNER_ROW = 1024  # elements per row of the uploaded corner table (one RGBA32UI texel each)


def corner_rows(n_elements: int) -> int:
    """Rows of the uploaded corner table of ``n_elements`` elements (at least one)."""
    return max(1, -(-int(n_elements) // CORNER_ROW))


@dataclass
class TexturedSurface:
    """Triangles in model units with atlas coordinates and textures (see the module docstring).

    ``positions`` (V, 3) float64 model units; ``triangles`` (T, 3) int32; ``uv`` (V, 2) float64
    texels; ``normal_axis`` (V,) int8 in 0..2; ``normals`` (V, 3) float64 unit vertex normals or
    None (needed by per-vertex shading only); ``normal_map`` (H, W, 2) uint8 or None;
    ``wire_map`` (H, W, 4) uint8 or None; ``wire_range`` texels of byte 0/255; or the
    element-id wire frame: ``element_map`` (H, W) uint16/uint32, ``corner_table`` (M, 4, 2)
    uint16, ``corner_frac`` steps per texel and ``element_base`` (V,) int32; ``line_edges``
    (E, 2) int32 vertex pairs drawn as lines. ``name`` is how tables name the surface.
    """

    positions: np.ndarray
    triangles: np.ndarray
    uv: np.ndarray
    normal_axis: np.ndarray
    normals: np.ndarray | None = None
    normal_map: np.ndarray | None = None
    wire_map: np.ndarray | None = None
    wire_range: float = 2.0
    line_edges: np.ndarray | None = None
    element_map: np.ndarray | None = None
    corner_table: np.ndarray | None = None
    corner_frac: int = 1
    element_base: np.ndarray | None = None
    name: str = "TexturedSurface"

    kind: ClassVar[str] = "surface"

    def __post_init__(self) -> None:
        self.positions = np.asarray(self.positions, np.float64)
        self.triangles = np.asarray(self.triangles, np.int32).reshape(-1, 3)
        self.uv = np.asarray(self.uv, np.float64)
        self.normal_axis = np.asarray(self.normal_axis, np.int8)
        v = len(self.positions)
        if self.positions.shape != (v, 3) or self.uv.shape != (v, 2) or \
                self.normal_axis.shape != (v,):
            raise ValueError(f"positions (V, 3), uv (V, 2) and normal_axis (V,) must agree, got "
                             f"{self.positions.shape}, {self.uv.shape}, {self.normal_axis.shape}")
        if len(self.triangles) and (self.triangles.min() < 0 or self.triangles.max() >= v):
            raise ValueError(f"triangles index outside 0..{v - 1}")
        if self.normals is not None:
            self.normals = np.asarray(self.normals, np.float64)
            if self.normals.shape != (v, 3):
                raise ValueError(f"normals must be (V, 3), got {self.normals.shape}")
        for name, channels in (("normal_map", 2), ("wire_map", 4)):
            tex = getattr(self, name)
            if tex is not None:
                tex = np.asarray(tex)
                if tex.dtype != np.uint8 or tex.ndim != 3 or tex.shape[2] != channels:
                    raise ValueError(f"{name} must be (H, W, {channels}) uint8, got "
                                     f"{tex.shape} {tex.dtype}")
                setattr(self, name, tex)
        self._check_element_wire(v)
        wire = self.wire_map if self.wire_map is not None else self.element_map
        if self.normal_map is not None and wire is not None:
            (nh, nw), (wh, ww) = self.normal_map.shape[:2], wire.shape[:2]
            if ww % nw or wh % nh or ww // nw != wh // nh:
                raise ValueError("the wire_map size must be the normal_map size times one "
                                 f"integer for both axes, got {ww}x{wh} and {nw}x{nh}")
        if self.line_edges is None:
            self.line_edges = np.zeros((0, 2), np.int32)
        self.line_edges = np.asarray(self.line_edges, np.int32).reshape(-1, 2)
        if not self.wire_range > 0:
            raise ValueError(f"wire_range must be positive, got {self.wire_range}")

    def _check_element_wire(self, v: int) -> None:
        parts = (self.element_map, self.corner_table, self.element_base)
        if all(p is None for p in parts):
            return
        if any(p is None for p in parts):
            raise ValueError("the element-id wire frame needs element_map, corner_table and "
                             "element_base together")
        if self.wire_map is not None:
            raise ValueError("a surface has a wire_map or an element-id wire frame, not both")
        emap = np.asarray(self.element_map)
        if emap.ndim != 2 or emap.dtype not in (np.uint16, np.uint32):
            raise ValueError(f"element_map must be (H, W) uint16 or uint32, got {emap.shape} "
                             f"{emap.dtype}")
        table = np.asarray(self.corner_table)
        if table.dtype != np.uint16 or table.ndim != 3 or table.shape[1:] != (4, 2):
            raise ValueError(f"corner_table must be (M, 4, 2) uint16, got {table.shape} "
                             f"{table.dtype}")
        base = np.asarray(self.element_base, np.int32)
        if base.shape != (v,):
            raise ValueError(f"element_base must be ({v},), got {base.shape}")
        if len(base) and (base.min() < 0 or base.max() > max(len(table) - 1, 0)):
            raise ValueError(f"element_base outside 0..{len(table) - 1}")
        if int(self.corner_frac) != self.corner_frac or self.corner_frac < 1:
            raise ValueError(f"corner_frac must be a positive integer, got {self.corner_frac!r}")
        self.element_map, self.corner_table, self.element_base = emap, table, base
        self.corner_frac = int(self.corner_frac)

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """(lo, hi) float64 corners of the box of the positions, model units."""
        return self.positions.min(axis=0), self.positions.max(axis=0)

    @property
    def no_element(self) -> int:
        """The element map's value for texels under no element (all ones)."""
        return int(np.iinfo(self.element_map.dtype).max) if self.element_map is not None else 0

    @property
    def size(self) -> tuple[int, int] | None:
        """(W, H) of the atlas, the wire frame's where there is one (``uv`` is in its texels);
        None without textures."""
        tex = next((t for t in (self.wire_map, self.element_map, self.normal_map)
                    if t is not None), None)
        return None if tex is None else (tex.shape[1], tex.shape[0])

    @property
    def texture_bytes(self) -> int:
        """Bytes of the textures: the normal map and the wire frame (the corner table counted
        as uploaded, in rows of :data:`CORNER_ROW` elements)."""
        total = sum(t.nbytes for t in (self.normal_map, self.wire_map, self.element_map)
                    if t is not None)
        if self.corner_table is not None:
            total += corner_rows(len(self.corner_table)) * CORNER_ROW * 16
        return total
