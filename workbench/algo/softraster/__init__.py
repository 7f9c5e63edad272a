"""The es2008 software rasterizer: GL-free, numpy + numba.

:func:`render` draws triangles into a :class:`Frame` through the paper's steps
(:mod:`.pipeline`), with fragments from the span look-up table (:mod:`.spantable`) or from
half-space tests — by default the same image fused per screen tile (:mod:`.fused`) — under the
pixel rule of :mod:`.rule`; :mod:`workbench.algo.composite` merges frames of domains by depth
(sort-last). The kernels (:mod:`.kernels`, :mod:`.fused`) take the arrays that travel
together as the NamedTuples of :mod:`.state`.
"""

from .frame import CLEAR_DEPTH, NO_TRIANGLE, Frame
from .pipeline import (
    GENERATORS,
    SHADINGS,
    STEPS,
    TABLE_SIZES,
    RasterOptions,
    RenderStats,
    Shading,
    render,
)

__all__ = ["CLEAR_DEPTH", "NO_TRIANGLE", "Frame", "GENERATORS", "SHADINGS", "STEPS",
           "TABLE_SIZES", "RasterOptions", "RenderStats", "Shading", "render"]
