"""Colour scales for the render paths: the 1-D colormap texture and its exact CPU twin.

A scalar value ``v`` is first normalised in float64 on the CPU, ``t = (v − lo) / (hi − lo)``
with ``(lo, hi)`` the value range, clamped to ±:data:`T_LIMIT` and uploaded as float32. The
shaders turn ``t`` into a texture coordinate ``s = t·scale + offset``, clamp it to [0, 1] and
look the colour up in a one-row RGBA8 texture with clamp-to-edge wrapping (values outside the
range take the colour of the nearest end; the clamps change no texel, they keep far
coordinates out of float32 overflow and llvmpipe's fixed-point texel addressing):

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

:meth:`ColorScale.evaluate` computes what the texture lookup returns from the float32 value
the paths upload (a band index in float32, as drawn; linear filtering with exact weights: GPUs
quantise the filter weights, typically to 8 bits, which moves a colour by at most
``|c[i+1] − c[i]|/512``, far below 1/255 for a 256-entry map).

**No result.** A field value that is not finite (NaN or ±inf: the stress of a rigid shell in a
d3plot, a distance beyond the flange path's cutoff) has no colour of the scale. The rule, the
same on GL and in the software rasterizer:

* a **triangle** any of whose vertex values (node field) or whose element value (element
  field) is not finite is drawn **entirely** in :data:`NO_RESULT_COLOR`, lit as the path lights
  its other triangles (the interpolated Gouraud factor, or the flat face light of
  ``element_color``); interpolation is undefined there, and every pixel of such a triangle has
  a positive weight of a value that does not exist;
* such a triangle is never hidden by the transfer function (it has no value to hide) and never
  takes a colour of the scale; its pixels go through the clip planes and the depth test as any.

The mechanism carries no number through the interpolation: the values of missing nodes are
uploaded as 0 (:func:`mark_missing`) and the missing flag travels beside them, per triangle —
on GL a per-vertex 0/1 attribute that a geometry shader turns into one ``flat`` flag per
triangle (the maximum of its three vertices', exact), or for elements a ``flat`` attribute of
the element's provoking vertex; in the software rasterizer a per-triangle array. Paths whose
field has no non-finite value at any step compile neither (nothing changes for them).

:data:`NO_RESULT_COLOR` is pure green, (0, 1, 0). Lit by any headlight factor in [0.25, 1] it
stays at least 24/255 (in the largest channel difference) from every colour of viridis, plasma,
inferno, magma, cividis, turbo, jet, coolwarm, RdBu, Spectral, rainbow, hot, gray, cool and
spring lit by any factor in [0.25, 1] (tests/paths/test_no_result.py checks it); maps that hold pure
green themselves (hsv, brg, Greens, …) cannot tell it apart. Legends state it with the count of
values that had none (:func:`no_result_label`). :func:`scale_colour_pixels` counts the pixels
of a scale's colours in and around a region of an image: the check that no rim of scale colours
surrounds a missing region (:func:`legacy_mark_missing` injects the old sentinel for a fault
test).
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


NO_RESULT_COLOR = (0.0, 1.0, 0.0)  #: RGB in [0, 1] of what has no value (module notes)
# the largest |t| uploaded: a value a million ranges beyond the scale takes its end colour
# either way, and float32 (largest number 3.4e38) would turn t = 1e60 into an infinity that
# GL and the software rasterizer interpolate differently (a range of (0, 1e-30) and values 1e30)
T_LIMIT = 1.0e6
# the sentinel a non-finite value was uploaded as before the no-result rule; interpolated, it
# drew rims of scale colours around missing regions. Only :func:`legacy_mark_missing` (a fault
# to inject) and chunked scenes written before (read as NaN) still hold it.
NO_VALUE = -1.0e30


@dataclass(frozen=True)
class ColorScale:
    """A value range mapped through a colormap, smooth or in bands, with an optional hidden range.

    ``value_range`` must be finite with ``lo < hi`` (a constant field gets
    :func:`constant_range` from :func:`scale_for`); ``bands`` must be 0 (smooth) or a positive
    count up to 256; ``hide_range`` must have ``lo ≤ hi``. Anything else is refused with
    ValueError.
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
        """float64 t = (v − lo)/(hi − lo), not clamped (the texture clamps); non-finite values
        stay NaN or ±inf. Computed on halves, so that no finite value and range overflow (a
        range of ±1e308 gives finite t)."""
        lo, hi = self.value_range
        v = np.asarray(values, np.float64)
        with np.errstate(over="ignore", invalid="ignore"):
            return (0.5 * v - 0.5 * lo) / (0.5 * hi - 0.5 * lo)

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
        return lo * (1.0 - t) + hi * t  # no overflow of hi − lo for a range of ±1e308

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
        """(..., 4) float64 RGBA in [0, 1] that the texture returns for normalised values ``t``,
        as the paths draw them: t clamped to ±:data:`T_LIMIT` and rounded to float32 (what is
        uploaded), a band's index ``⌊t·n⌋`` taken in float32 (as the shaders and the software
        rasterizer take it, so that a value within float32 rounding of a band edge lands in
        the band they draw); a non-finite t takes :data:`NO_RESULT_COLOR`, opaque."""
        texels = self.texture_data()
        t = np.asarray(t, np.float64)
        finite = np.isfinite(t)
        t32 = np.clip(np.where(finite, t, 0.0), -T_LIMIT, T_LIMIT).astype(np.float32)
        if self.bands:
            k = np.floor(t32 * np.float32(self.bands))
            k = np.clip(k, 0, self.bands - 1).astype(np.int64)
            out = texels[k].astype(np.float64) / 255.0
        else:
            out = _lerp_table(texels, t32.astype(np.float64)) / 255.0
        out[~finite] = (*NO_RESULT_COLOR, 1.0)
        return out

    def evaluate(self, values: ArrayLike) -> np.ndarray:
        """(..., 4) float64 RGBA in [0, 1] for float64 field ``values``: colour before lighting
        (:meth:`lookup` of the normalised values; :data:`NO_RESULT_COLOR` where not finite)."""
        return self.lookup(self.normalise(values))

    def visible(self, values: ArrayLike) -> np.ndarray:
        """bool: which values pass the alpha test (all of them without a hide_range)."""
        return self.evaluate(values)[..., 3] >= ALPHA_TEST


def scale_for(mesh: FEMesh, field: str, colormap: str = "viridis",
              value_range: tuple[float, float] | None = None, bands: int = 0,
              hide_range: tuple[float, float] | None = None) -> ColorScale:
    """The :class:`ColorScale` of a mesh field; the value range defaults to the field's range
    of finite values over all steps (:func:`constant_range` where it is one value; (0, 1) for a
    field without a finite value)."""
    if value_range is None:
        lo, hi = mesh.field_range(field)
        value_range = (lo, hi) if hi > lo else constant_range(lo)
    return ColorScale(colormap, tuple(value_range), bands, hide_range)


def constant_range(v: float) -> tuple[float, float]:
    """The value range of a field whose finite values all equal ``v``: ``(v, v + 1)``; where
    ``v + 1`` rounds to ``v`` (``|v| ≥ 2^53``) ``(v, v + |v|)``, so the field takes the scale's
    first colour (t = 0); where ``v + |v|`` overflows (``v`` above 8.9e307) the float64 number
    below ``v`` and ``v``, so it takes the last. Refuses a non-finite ``v`` (ValueError)."""
    v = float(v)
    if not np.isfinite(v):
        raise ValueError(f"a constant field's value must be finite, got {v}")
    if v + 1.0 > v:
        return v, v + 1.0
    if np.isfinite(v + abs(v)):
        return v, v + abs(v)
    return float(np.nextafter(v, -np.inf)), v


# ----------------------------------------------------------------------------- no result
def mark_missing(t: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """``(values, missing)`` of normalised field values ``t`` (float64, per node or element):
    ``values`` float64 with every non-finite entry replaced by 0 (a number no interpolation
    can carry into a drawn pixel: the triangles that use it are drawn in the no-result colour)
    and the others clamped to ±:data:`T_LIMIT`, ``missing`` bool, where ``t`` was not finite.
    What every path uploads or rasterizes (looked up on this module at each call, so a fault
    test may replace it)."""
    t = np.asarray(t, np.float64)
    missing = ~np.isfinite(t)
    return np.clip(np.where(missing, 0.0, t), -T_LIMIT, T_LIMIT), missing


def legacy_mark_missing(t: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """The behaviour before the no-result rule, as a fault to inject in place of
    :func:`mark_missing` (``monkeypatch.setattr(colormap, "mark_missing",
    legacy_mark_missing)``): non-finite values become the sentinel :data:`NO_VALUE` and no
    value is flagged missing, so the sentinel is interpolated into the scale's colours (the
    rims and scale-coloured regions :func:`scale_colour_pixels` counts)."""
    t = np.asarray(t, np.float64)
    return np.where(np.isfinite(t), t, NO_VALUE), np.zeros(t.shape, bool)


def missing_count(mesh: FEMesh, field: str, step: int = 0) -> tuple[int, str]:
    """``(count, per)``: how many values of ``mesh``'s node or element ``field`` at ``step``
    are not finite, and "node" or "element"; KeyError for a field the mesh lacks."""
    if field in mesh.node_fields:
        return int((~np.isfinite(mesh.node_field(field, step))).sum()), "node"
    return int((~np.isfinite(mesh.element_field(field, step))).sum()), "element"


def no_result_label(count: int, per: str | None = "node", parts=()) -> str:
    """The legend text of the no-result colour: ``no result: 1 node``, ``no result: 12
    elements`` (``per`` "node" or "element"; None or a count below 0 gives ``no result``),
    followed by the ``parts`` that have no value at all (a rigid part of a d3plot):
    ``no result: 120 elements, part 8`` (at most :data:`LISTED_PARTS` named, then ``+K``)."""
    count = int(count)
    if per is None or count < 0:
        return "no result"
    text = f"no result: {count} {per}{'s' * (count != 1)}"
    parts = [int(p) for p in parts]
    if parts:
        named = ", ".join(str(p) for p in parts[:LISTED_PARTS])
        more = f" +{len(parts) - LISTED_PARTS}" if len(parts) > LISTED_PARTS else ""
        text += f", part{'s' * (len(parts) > 1)} {named}{more}"
    return text


LISTED_PARTS = 3  # parts named in a no-result label before the rest are counted


def parts_without_result(mesh: FEMesh, field: str, step: int = 0) -> list[int]:
    """The part ids (ascending) of ``mesh`` none of whose elements has a finite value of
    ``field`` at ``step`` (the rigid parts of a d3plot, which carry no stress, strain or
    thickness): for an element field its elements' values; for a node field an element has a
    value where all its nodes have one (a triangle with a node without one is drawn whole in
    the no-result colour). Deleted elements (erosion) count as neither. KeyError for a field
    the mesh lacks."""
    if field in mesh.node_fields:
        finite = np.isfinite(mesh.node_field(field, step))[mesh.elements].all(axis=1)
    else:
        finite = np.isfinite(mesh.element_field(field, step))
    live = mesh.alive(step)
    parts = mesh.parts[live]
    with_value = np.unique(parts[finite[live]])
    return [int(p) for p in np.setdiff1d(np.unique(parts), with_value)]


def no_result_text(mesh: FEMesh, field: str, step: int = 0) -> str | None:
    """The no-result legend text of ``field`` drawn on ``mesh`` at ``step``
    (:func:`no_result_label` with :func:`missing_count` and :func:`parts_without_result`), or
    None where every value is finite."""
    count, per = missing_count(mesh, field, step)
    if not count:
        return None
    return no_result_label(count, per, parts_without_result(mesh, field, step))


def scale_colour_mask(image: ArrayLike, scale: ColorScale, *, light: tuple[float, float] = (
        0.25, 1.0), tolerance: int = 3) -> np.ndarray:
    """(H, W) bool: which pixels of ``image`` ((H, W, 3|4) uint8) hold a colour of ``scale``
    lit by a factor in ``light`` (the headlight's range: 0.25 … 1): within ``tolerance`` (in
    1/255, the largest channel difference) of ``round(L · c)`` for a texel colour ``c`` of the
    scale's texture and the factor ``L`` in the range that fits the pixel best. Colours between
    neighbouring texels (linear filtering, interpolated vertex colours) lie within a few 1/255
    of one; :data:`NO_RESULT_COLOR` lies at least 24/255 from the listed maps' colours."""
    image = np.asarray(image)
    if image.dtype != np.uint8 or image.ndim != 3 or image.shape[2] not in (3, 4):
        raise ValueError(f"image must be uint8 (H, W, 3|4), got {image.dtype} {image.shape}")
    lo, hi = (float(v) for v in light)
    if not 0.0 <= lo <= hi:
        raise ValueError(f"light must be a range 0 <= lo <= hi, got {light}")
    px = image[..., :3].reshape(-1, 3).astype(np.float64)
    found = np.zeros(len(px), bool)
    for c in np.unique(scale.texture_data()[:, :3], axis=0).astype(np.float64):
        cc = float(c @ c)
        factor = np.clip(px @ c / cc, lo, hi) if cc > 0 else np.full(len(px), lo)
        found |= np.abs(px - np.rint(factor[:, None] * c)).max(axis=1) <= tolerance
    return found.reshape(image.shape[:2])


def scale_colour_pixels(image: ArrayLike, region: ArrayLike, scale: ColorScale, k: int = 2, *,
                        light: tuple[float, float] = (0.25, 1.0), tolerance: int = 3,
                        background: tuple[int, int, int] | None = (255, 255, 255)) -> int:
    """How many pixels of ``image`` ((H, W, 3|4) uint8) within ``k`` pixels (the square
    neighbourhood: Chebyshev distance) of ``region`` ((H, W) bool, say the pixels whose value
    depends on a non-finite node value) hold a colour of ``scale`` (:func:`scale_colour_mask`,
    ``light`` and ``tolerance`` as there); pixels equal to ``background`` (None: none) are not
    counted. 0 for an honest image of a region drawn in the no-result colour whose
    ``k``-neighbourhood lies within it; a rim of scale colours around or inside the region (the
    interpolated sentinel) counts its pixels. Refuses a region of another shape than the image
    or a negative ``k`` (ValueError)."""
    from scipy import ndimage

    image = np.asarray(image)
    region = np.asarray(region, bool)
    if region.shape != image.shape[:2]:
        raise ValueError(f"region must be {image.shape[:2]}, got {region.shape}")
    if int(k) != k or k < 0:
        raise ValueError(f"k must be a non-negative integer, got {k}")
    near = ndimage.binary_dilation(region, np.ones((2 * k + 1,) * 2, bool)) if k else region
    near = near & scale_colour_mask(image, scale, light=light, tolerance=tolerance)
    if background is not None:
        near &= ~(image[..., :3] == np.asarray(background, np.uint8)).all(axis=-1)
    return int(near.sum())
