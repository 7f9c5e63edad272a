"""The flange path (crash2000 §5, Fig. 9): every node's distance to another part as a colour,
and the geometry farther than a threshold hidden by an RGBα 1-D texture and the alpha test.

The distance is the derived item ``part_distances``
(:func:`workbench.algo.nearest.parts.flange_distances`: exact, float64, to the nearest element of
any part the node does not belong to, up to the distance of interest ``cutoff``), installed on the
mesh as the node field ``"part_distance"`` and drawn per pixel like ``pixel_color`` (Gouraud light,
the scalar interpolated and looked up per fragment):

* ``show="flanges"`` (the default): colours over ``[0, 2·threshold]`` with every texel above
  ``threshold`` transparent, so a fragment whose interpolated distance exceeds the threshold is
  discarded; the linear texture filter puts the edge at the threshold itself. Nodes with no
  other part within ``cutoff`` are hidden too. What stays are the potential flanges.
* ``show="distance"``: the distance map over ``[0, cutoff]``, nothing hidden; nodes with no
  other part within ``cutoff`` have no value (NaN), so the triangles that use them are drawn
  in the no-result colour (:mod:`~workbench.paths.colormap`).

Refused with ValueError: a threshold or cutoff that is not positive and finite, a threshold
above the cutoff, another ``field``, a ``value_range`` or ``hide_range`` (the path sets
them), an unknown ``show``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..algo.nearest.parts import flange_distances
from .fields import PixelColorPath
from .style import Style

if TYPE_CHECKING:
    from ..scene.mesh import FEMesh
    from .colormap import ColorScale

FIELD = "part_distance"
SHOWS = ("flanges", "distance")


@dataclass
class FlangeStyle(Style):
    """:class:`Style` plus ``threshold`` (model units; 2 mm as the paper's Fig. 9), ``cutoff``
    (the distance of interest, model units; 50 mm) and ``show`` ("flanges" or "distance");
    ``field``, ``value_range`` and ``hide_range`` follow from them."""

    threshold: float = 2.0
    cutoff: float = 50.0
    show: str = "flanges"

    def __post_init__(self) -> None:
        for name in ("threshold", "cutoff"):
            value = float(getattr(self, name))
            if not (math.isfinite(value) and value > 0):
                raise ValueError(f"{name} must be a positive distance, got {getattr(self, name)}")
            setattr(self, name, value)
        if self.threshold > self.cutoff:
            raise ValueError(f"threshold {self.threshold} exceeds the distance of interest "
                             f"cutoff {self.cutoff}: nothing beyond the cutoff is measured")
        if self.show not in SHOWS:
            raise ValueError(f"show must be one of {SHOWS}, got {self.show!r}")
        if self.field not in (None, FIELD):
            raise ValueError(f"the flange path draws the distance to another part; field "
                             f"{self.field!r} does not apply")
        derived = self._derived()
        for name in ("value_range", "hide_range"):
            value = getattr(self, name)
            if value is not None and tuple(float(v) for v in value) != derived[name]:
                raise ValueError(f"the flange path sets {name} from threshold and cutoff")
        self.field = FIELD
        self.value_range, self.hide_range = derived["value_range"], derived["hide_range"]
        super().__post_init__()

    def _derived(self) -> dict:
        if self.show == "flanges":
            return dict(value_range=(0.0, 2.0 * self.threshold),
                        hide_range=(self.threshold, 2.0 * self.threshold))
        return dict(value_range=(0.0, self.cutoff), hide_range=None)


class FlangePath(PixelColorPath):
    """The distance to another part per pixel, hidden beyond ``threshold`` (``show="flanges"``)
    or shown as a map up to ``cutoff`` (``show="distance"``)."""

    name = "flange"
    needs = frozenset({"gouraud", "part_distances"})
    style_class = FlangeStyle
    style: FlangeStyle

    def check_mesh(self, mesh: FEMesh) -> ColorScale | None:
        """Install the node field ``part_distance`` on ``mesh`` from its cached distances (far
        nodes hidden with the flanges, without a value on the map), then check as
        ``pixel_color`` does."""
        if getattr(mesh, "kind", None) != "mesh":
            raise ValueError(f"path {self.name!r} draws an FE mesh, got {type(mesh).__name__}")
        style = self.style
        distance = np.array(flange_distances(mesh, style.cutoff, style.step).distance,
                            np.float64)
        far = ~np.isfinite(distance)
        # beyond the distance of interest: hidden with the flanges, no value on the map
        distance[far] = 2.0 * style.threshold if style.show == "flanges" else np.nan
        mesh.node_fields[FIELD] = distance
        return super().check_mesh(mesh)
