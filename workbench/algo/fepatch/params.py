"""fe2003's parameters and rules: the Table 1 parameter sets (G1 angle, subpatch distance
``d``, line bounds), the paper's own distance and texture rules as :func:`build_model`
keywords, and the names of the preprocessing stages and wire-frame encodings.

Lengths are model units, angles degrees.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

STAGES = ("features, subpatches, lines", "retriangulation", "textures")
WIRE_ENCODINGS = ("corners", "distance")


@dataclass(frozen=True)
class FEPatchParams:
    """fe2003 Table 1 parameters: G1 angle (degrees), subpatch distance ``d`` and line bounds
    ``l_outer``/``l_inner`` (model units)."""

    alpha_g1_deg: float
    d: float
    l_outer: float
    l_inner: float
    name: str = ""

    def __post_init__(self) -> None:
        if not 0.0 < self.alpha_g1_deg < 180.0:
            raise ValueError(f"alpha_g1_deg must be in (0, 180), got {self.alpha_g1_deg}")
        for key in ("d", "l_outer", "l_inner"):
            if not np.isfinite(getattr(self, key)) or getattr(self, key) < 0:
                raise ValueError(f"{key} must be finite and >= 0, got {getattr(self, key)}")

    @property
    def label(self) -> str:
        return self.name or (f"{self.alpha_g1_deg:g},{self.d:g},{self.l_outer:g},"
                             f"{self.l_inner:g}")


#: the paper's parameter sets A and B by name
PARAMETER_SETS = {"A": FEPatchParams(12.0, 1.0, 0.5, 8.0, "A"),
                  "B": FEPatchParams(18.0, 3.0, 2.5, 15.0, "B")}

# build_model's keywords for the paper's own construction, which the defaults improve on:
# the distance bound (subpatch nodes within d of their plane, not certified; the new surface
# may lie up to 2d from the original) and the texture scale (the smallest element extent
# spans 3 texels per axis, a full-resolution normal map, a 3-texel border)
PAPER_DISTANCE_RULE = {"fit_share": 1.0, "certify": False}
PAPER_TEXTURE_RULE = {"wire_encoding": "distance", "texels_per_edge": 3.0, "border": 3,
                      "scale_quantile": 0.0, "scale_by": "extent", "atlas_turns": 1,
                      "normal_reduction": 1, "min_width": None}
PAPER_RULES = {**PAPER_DISTANCE_RULE, **PAPER_TEXTURE_RULE}


def parse_params(spec) -> FEPatchParams:
    """``"A"``, ``"B"``, ``"alpha_g1,d,l_outer,l_inner"`` or an :class:`FEPatchParams`."""
    if isinstance(spec, FEPatchParams):
        return spec
    text = str(spec).strip()
    if text.upper() in PARAMETER_SETS:
        return PARAMETER_SETS[text.upper()]
    try:
        values = [float(v) for v in text.split(",")]
    except ValueError:
        values = []
    if len(values) != 4:
        raise ValueError(f"fe2003 parameters must be 'A', 'B' or 'alpha_g1,d,l_outer,l_inner', "
                         f"got {spec!r}")
    return FEPatchParams(*values)
