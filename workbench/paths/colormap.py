"""Colour scales for the render paths: the 1-D colormap texture and its exact CPU twin.

A scalar value ``v`` is first normalised in float64 on the CPU, ``t = (v − lo) / (hi − lo)``
with ``(lo, hi)`` the value range, and uploaded as float32. The shaders turn ``t`` into a
texture coordinate ``s = t·scale + offset`` and look the colour up in a one-row RGBA8 texture
with clamp-to-edge wrapping (values outside the range take the colour of the nearest end):

* **smooth** contours (``bands == 0``): 256 texels, linear filtering, texel ``i`` holding the
  matplotlib colour of ``t = i/255``; ``scale = 255/256, offset = 0.5/256`` put ``t = 0`` and
  ``t = 1`` on the first and last texel centres, so the colour is the piecewise-linear
  interpolation of the 256 colormap entries at ``t·255``.
* **band** contours (``bands = n``): ``n`` texels, nearest filtering, ``scale = 1, offset = 0``;
  band ``k = min(⌊t·n⌋, n − 1)`` has the colormap colour at ``k/(n − 1)`` (the first band the
  colormap's first colour, the last band its last; one band takes the middle colour).

The transfer function (crash2000 §5) sets α = 0 in every texel whose value lies in
``hide_range``: smooth texel ``i`` stands for ``lo + (i/255)(hi − lo)``, band ``k`` for the
value at its centre, ``lo + ((k + ½)/n)(hi − lo)``. Fragments whose looked-up α is below ½ are
discarded (the alpha test), so a hidden range ends halfway between the texel values on either
side of its bounds.

:meth:`ColorScale.evaluate` computes in float64 exactly what the texture lookup returns
(linear filtering with exact weights; GPUs quantise the filter weights, typically to 8 bits,
which moves a colour by at most ``|c[i+1] − c[i]|/512``, far below 1/255 for a 256-entry map).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from numpy.typing import ArrayLike

    from ..scene.mesh import FEMesh

LUT_SIZE = 256
ALPHA_TEST = 0.5


@cache
def _lut(name: str) -> np.ndarray:
    import matplotlib

    try:
        cmap = matplotlib.colormaps[name]
    except KeyError:
        raise ValueError(f"unknown colormap {name!r}; any name in matplotlib.colormaps is "
                         f"accepted, e.g. viridis, plasma, jet, coolwarm") from None
    # integer input indexes the resampled table directly (no rounding of float positions)
    table = cmap.resampled(LUT_SIZE)(np.arange(LUT_SIZE), bytes=True)
    table.setflags(write=False)
    return table


def colormap_lut(name: str) -> np.ndarray:
    """(256, 4) uint8 RGBA table of the matplotlib colormap ``name`` (entry i at t = i/255).

    Refuses an unknown name with ValueError.
    """
    return _lut(name).copy()


def _lerp_table(table: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Piecewise-linear interpolation of (256, C) table rows at t·255, t clamped to [0, 1]."""
    u = np.clip(t, 0.0, 1.0) * (LUT_SIZE - 1)
    i = np.minimum(np.floor(u).astype(np.int64), LUT_SIZE - 2)
    w = (u - i)[..., None]
    lo = table[i].astype(np.float64)
    hi = table[i + 1].astype(np.float64)
    return lo + w * (hi - lo)


NO_VALUE = -1.0e30  # uploaded for a non-finite field value; shaders draw it in the missing colour


@dataclass(frozen=True)
class ColorScale:
    """A value range mapped through a colormap, smooth or in bands, with an optional hidden range.

    ``value_range`` must be finite with ``lo < hi`` (a constant field gets ``hi = lo + 1``
    from :func:`scale_for`); ``bands`` must be 0 (smooth) or a positive count up to 256;
    ``hide_range`` must have ``lo ≤ hi``. Anything else is refused with ValueError.
    """

    colormap: str = "viridis"
    value_range: tuple[float, float] = (0.0, 1.0)
    bands: int = 0
    hide_range: tuple[float, float] | None = None

    def __post_init__(self) -> None:
        lo, hi = (float(v) for v in self.value_range)
        if not (np.isfinite(lo) and np.isfinite(hi) and lo < hi):
            raise ValueError(f"value_range must be finite with lo < hi, got {self.value_range}")
        object.__setattr__(self, "value_range", (lo, hi))
        if int(self.bands) != self.bands or not 0 <= self.bands <= LUT_SIZE:
            raise ValueError(f"bands must be 0 (smooth) or 1..{LUT_SIZE}, got {self.bands}")
        object.__setattr__(self, "bands", int(self.bands))
        if self.hide_range is not None:
            a, b = (float(v) for v in self.hide_range)
            if not a <= b:
                raise ValueError(f"hide_range must have lo <= hi, got {self.hide_range}")
            object.__setattr__(self, "hide_range", (a, b))
        _lut(self.colormap)  # refuse an unknown name now, not at the first draw

    # ------------------------------------------------------------------ mapping
    def normalise(self, values: ArrayLike) -> np.ndarray:
        """float64 t = (v − lo)/(hi − lo), not clamped (the texture clamps). What is uploaded."""
        lo, hi = self.value_range
        return (np.asarray(values, np.float64) - lo) / (hi - lo)

    @property
    def texture_width(self) -> int:
        return self.bands if self.bands else LUT_SIZE

    @property
    def linear(self) -> bool:
        """Linear texture filtering (smooth); nearest for bands."""
        return self.bands == 0

    @property
    def coord_transform(self) -> tuple[float, float]:
        """(scale, offset) of the texture coordinate s = t·scale + offset."""
        if self.bands:
            return 1.0, 0.0
        return (LUT_SIZE - 1) / LUT_SIZE, 0.5 / LUT_SIZE

    def texel_values(self) -> np.ndarray:
        """float64 value each texel stands for (used by the transfer function)."""
        lo, hi = self.value_range
        if self.bands:
            t = (np.arange(self.bands) + 0.5) / self.bands
        else:
            t = np.arange(LUT_SIZE) / (LUT_SIZE - 1)
        return lo + t * (hi - lo)

    def texture_data(self) -> np.ndarray:
        """(width, 4) uint8 RGBA texels: colours, with α = 0 where the transfer function hides."""
        table = _lut(self.colormap)
        if self.bands:
            n = self.bands
            t = np.arange(n) / (n - 1) if n > 1 else np.array([0.5])
            texels = np.rint(_lerp_table(table, t)).astype(np.uint8)
        else:
            texels = table.copy()
        texels[:, 3] = 255
        if self.hide_range is not None:
            v = self.texel_values()
            texels[(v >= self.hide_range[0]) & (v <= self.hide_range[1]), 3] = 0
        return texels

    def lookup(self, t: ArrayLike) -> np.ndarray:
        """(..., 4) float64 RGBA in [0, 1] that the texture returns for normalised values ``t``."""
        texels = self.texture_data()
        t = np.asarray(t, np.float64)
        if self.bands:
            k = np.clip(np.floor(t * self.bands), 0, self.bands - 1).astype(np.int64)
            return texels[k].astype(np.float64) / 255.0
        return _lerp_table(texels, t) / 255.0

    def evaluate(self, values: ArrayLike) -> np.ndarray:
        """(..., 4) float64 RGBA in [0, 1] for float64 field ``values``: colour before lighting."""
        return self.lookup(self.normalise(values))

    def visible(self, values: ArrayLike) -> np.ndarray:
        """bool: which values pass the alpha test (all of them without a hide_range)."""
        return self.evaluate(values)[..., 3] >= ALPHA_TEST


def scale_for(mesh: FEMesh, field: str, colormap: str = "viridis",
              value_range: tuple[float, float] | None = None, bands: int = 0,
              hide_range: tuple[float, float] | None = None) -> ColorScale:
    """The :class:`ColorScale` of a mesh field; the value range defaults to the field's range
    over all steps (a constant field gets ``(v, v + 1)``)."""
    if value_range is None:
        lo, hi = mesh.field_range(field)
        value_range = (lo, hi if hi > lo else lo + 1.0)
    return ColorScale(colormap, tuple(value_range), bands, hide_range)
