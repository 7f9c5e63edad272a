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

With ``threshold="thickness"`` the criterion is crash2000 §4.1's instead of one fixed distance:
a node is shown where it is closer to an element of a part it does not belong to than half the
sum of the two shell thicknesses, that is where its penetration depth
``(t_node + t_element)/2 − distance`` is > 0 for some such element (the derived item
``penetration_depths``, :func:`workbench.algo.nearest.penetrations.penetrations`: thickness
from the element field ``"thickness"``, a node's thickness the largest of its part's elements
around it). The node field ``"penetration_depth"`` is the largest depth over the other parts'
elements within ``depth_range`` of penetrating (clearances down to ``−depth_range``):

* ``show="flanges"``: colours over ``[−depth_range, depth_range]`` with ``[−depth_range, 0]``
  transparent, so what stays is every penetrating node's neighbourhood, coloured by depth
  (values above ``depth_range`` take the top colour); nodes farther than ``depth_range`` from
  penetrating are hidden too.
* ``show="distance"``: the signed depth over ``[−depth_range, depth_range]``, nothing hidden;
  nodes farther from penetrating have no value (no-result colour).

``cutoff`` does not apply there. A mesh without thickness, or whose thickness cannot be known
(an include deck read without its master deck), is refused, naming why.

Refused with ValueError: a threshold or cutoff that is not positive and finite (or
``"thickness"``), a threshold above the cutoff, a ``depth_range`` that is not positive and
finite, another ``field``, a ``value_range`` or ``hide_range`` (the path sets them), an
unknown ``show``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..algo.nearest.parts import flange_distances
from ..algo.nearest.penetrations import penetration_depths
from .fields import PixelColorPath
from .style import Style

if TYPE_CHECKING:
    from ..scene.mesh import FEMesh
    from .colormap import ColorScale

FIELD = "part_distance"
DEPTH_FIELD = "penetration_depth"
THICKNESS = "thickness"  # the threshold of crash2000 §4.1: half the sum of the thicknesses
SHOWS = ("flanges", "distance")


@dataclass
class FlangeStyle(Style):
    """:class:`Style` plus ``threshold`` (model units; 2 mm as the paper's Fig. 9, or
    ``"thickness"``: half the sum of the two shell thicknesses, see the module notes),
    ``cutoff`` (the distance of interest, model units; 50 mm), ``depth_range`` (with
    ``threshold="thickness"``: the depth of the top colour and the clearance shown or hidden
    below 0, model units; 1 mm) and ``show`` ("flanges" or "distance"); ``field``,
    ``value_range`` and ``hide_range`` follow from them."""

    threshold: float | str = 2.0
    cutoff: float = 50.0
    show: str = "flanges"
    depth_range: float = 1.0

    @property
    def by_thickness(self) -> bool:
        """Whether the threshold is the thickness-aware one of crash2000 §4.1."""
        return self.threshold == THICKNESS

    def __post_init__(self) -> None:
        names = ("cutoff", "depth_range") if self.by_thickness else (
            "threshold", "cutoff", "depth_range")
        for name in names:
            try:
                value = float(getattr(self, name))
            except (TypeError, ValueError):
                value = math.nan
            if not (math.isfinite(value) and value > 0):
                raise ValueError(f"{name} must be a positive distance"
                                 f"{' or ' + repr(THICKNESS) if name == 'threshold' else ''}, "
                                 f"got {getattr(self, name)!r}")
            setattr(self, name, value)
        if not self.by_thickness and self.threshold > self.cutoff:
            raise ValueError(f"threshold {self.threshold} exceeds the distance of interest "
                             f"cutoff {self.cutoff}: nothing beyond the cutoff is measured")
        if self.show not in SHOWS:
            raise ValueError(f"show must be one of {SHOWS}, got {self.show!r}")
        field = DEPTH_FIELD if self.by_thickness else FIELD
        if self.field not in (None, field):
            raise ValueError(f"the flange path draws the distance to another part; field "
                             f"{self.field!r} does not apply")
        derived = self._derived()
        for name in ("value_range", "hide_range"):
            value = getattr(self, name)
            if value is not None and tuple(float(v) for v in value) != derived[name]:
                raise ValueError(f"the flange path sets {name} from threshold and cutoff")
        self.field = field
        self.value_range, self.hide_range = derived["value_range"], derived["hide_range"]
        super().__post_init__()

    def _derived(self) -> dict:
        if self.by_thickness:
            d = self.depth_range
            return dict(value_range=(-d, d),
                        hide_range=(-d, 0.0) if self.show == "flanges" else None)
        if self.show == "flanges":
            return dict(value_range=(0.0, 2.0 * self.threshold),
                        hide_range=(self.threshold, 2.0 * self.threshold))
        return dict(value_range=(0.0, self.cutoff), hide_range=None)


class FlangePath(PixelColorPath):
    """The distance to another part per pixel, hidden beyond ``threshold`` (``show="flanges"``)
    or shown as a map up to ``cutoff`` (``show="distance"``); with ``threshold="thickness"``
    the penetration depth instead (module notes)."""

    name = "flange"
    needs = frozenset({"gouraud", "part_distances"})
    style_class = FlangeStyle
    style: FlangeStyle

    def __init__(self, style: FlangeStyle | None = None) -> None:
        super().__init__(style)
        if self.style.by_thickness:  # the depths, not the distances within the cutoff
            self.needs = (self.needs - {"part_distances"}) | {"penetration_depths"}

    def check_mesh(self, mesh: FEMesh) -> ColorScale | None:
        """Install the node field ``part_distance`` on ``mesh`` from its cached distances (far
        nodes hidden with the flanges, without a value on the map), or ``penetration_depth``
        from its cached depths with ``threshold="thickness"``, then check as ``pixel_color``
        does."""
        if getattr(mesh, "kind", None) != "mesh":
            raise ValueError(f"path {self.name!r} draws an FE mesh, got {type(mesh).__name__}")
        style = self.style
        if style.by_thickness:
            d = style.depth_range
            depth = penetration_depths(mesh, d, style.step).node_depth(fill=np.nan)
            # farther than depth_range from penetrating: hidden, or no value on the map
            depth[np.isnan(depth)] = -d if style.show == "flanges" else np.nan
            mesh.node_fields[DEPTH_FIELD] = depth
            return super().check_mesh(mesh)
        distance = np.array(flange_distances(mesh, style.cutoff, style.step).distance,
                            np.float64)
        far = ~np.isfinite(distance)
        # beyond the distance of interest: hidden with the flanges, no value on the map
        distance[far] = 2.0 * style.threshold if style.show == "flanges" else np.nan
        mesh.node_fields[FIELD] = distance
        return super().check_mesh(mesh)
