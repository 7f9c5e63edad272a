"""The exact shading of a time slice (st2005 §4.2.3), in float64: what a pixel should show.

The render paths evaluate the same model in float32 on the GPU; this module is the reference
their images are measured against. One model, written out so both sides agree to the bit of
arithmetic that matters:

* **colour scale** — strain energy density ``U`` (kJ/m³) maps to ``s = log(U + 1)/log(U_max + 1)``
  clamped to [0, 1] (the paper's log scale), and ``s`` to a colour by piecewise-linear
  interpolation of a 256-entry RGB ramp at ``s·255`` (a 1-D texture with linear filtering
  and texel centres at ``i/255``);
* **height field** — ``z = height_scale·|v|`` (mm, with ``|v|`` in mm/µs); its exact normal is
  ``normalize(−h ∂|v|/∂x, −h ∂|v|/∂y, 1)``, and ``(0, 0, 1)`` where the gradient vanishes;
* **Phong lighting** with diffuse and specular reflectances that are multiples of the colour
  (the paper's choice):
  ``rgb = c·(AMBIENT + DIFFUSE·max(n·l, 0) + SPECULAR·max(r·e, 0)^SHININESS)``,
  ``r = 2(n·l)n − l`` the reflected light, ``l`` the fixed unit light direction ``LIGHT`` and
  ``e`` the unit direction towards the eye (``(0, 0, 1)`` for the top view the exact images
  use), clamped to [0, 1] per channel.
"""

from __future__ import annotations

import numpy as np

from .poly import height_normal

AMBIENT, DIFFUSE, SPECULAR, SHININESS = 0.3, 0.6, 0.25, 16.0
LIGHT = np.array([-0.35, 0.45, 1.0]) / np.linalg.norm([-0.35, 0.45, 1.0])
TOP_EYE = np.array([0.0, 0.0, 1.0])


def log_scale(U, U_max: float) -> np.ndarray:
    """s = log(U + 1)/log(U_max + 1) clamped to [0, 1]; U and U_max in kJ/m³.

    Refuses a U_max that is not positive and finite (the scale would divide by log 1 = 0).
    """
    if not (np.isfinite(U_max) and U_max > 0):
        raise ValueError(f"U_max must be positive and finite, got {U_max}")
    s = np.log1p(np.maximum(np.asarray(U, np.float64), 0.0)) / np.log1p(U_max)
    return np.clip(s, 0.0, 1.0)


def ramp_color(s, table) -> np.ndarray:
    """(..., 3) float64 RGB in [0, 1] of scale positions ``s`` through ``table``.

    ``table`` is (K, 3 or 4) with entries in [0, 255] (uint8 like
    :func:`workbench.paths.colormap.colormap_lut`) or floats in [0, 1]; entry i sits at
    ``s = i/(K − 1)`` and colours in between are interpolated linearly.
    """
    table = np.asarray(table)
    rgb = table[:, :3].astype(np.float64)
    if table.dtype == np.uint8:
        rgb = rgb / 255.0
    x = np.clip(np.asarray(s, np.float64), 0.0, 1.0) * (len(rgb) - 1)
    i = np.minimum(np.floor(x).astype(np.int64), len(rgb) - 2)
    f = (x - i)[..., None]
    return rgb[i] * (1.0 - f) + rgb[i + 1] * f


def phong(color, normal, eye=TOP_EYE, light=LIGHT) -> np.ndarray:
    """(K, 3) lit RGB in [0, 1]: the module's Phong model for colours (K, 3) and unit normals."""
    color = np.asarray(color, np.float64)
    n = np.asarray(normal, np.float64)
    nl = n @ light
    r = 2.0 * nl[..., None] * n - light
    spec = np.maximum(r @ np.asarray(eye, np.float64), 0.0) ** SHININESS
    factor = AMBIENT + DIFFUSE * np.maximum(nl, 0.0) + SPECULAR * spec
    return np.clip(color * factor[..., None], 0.0, 1.0)


def shade(U, grad_speed, *, U_max: float, table, height_scale: float, lighting: bool = True,
          eye=TOP_EYE) -> np.ndarray:
    """(K, 3) float64 RGB in [0, 1] of points with strain energy density ``U`` (kJ/m³) and
    speed gradient ``grad_speed`` ((K, 2), 1/µs): ramp colour of the log scale, lit by
    :func:`phong` with the exact height-field normal when ``lighting``."""
    color = ramp_color(log_scale(U, U_max), table)
    if not lighting:
        return color
    return phong(color, height_normal(grad_speed, height_scale), eye)
