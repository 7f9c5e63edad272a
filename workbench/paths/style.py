"""The style of the mesh render paths: what every option means and what is refused.

:class:`Style` holds how a mesh path draws (field, colour scale, clip planes, deformation plot,
wire frame, strips, the fe2003 parameter set); other path families subclass it
(:class:`~workbench.paths.flange.FlangeStyle`, :class:`~workbench.paths.exploded.ExplodeStyle`)
or have their own (:class:`~workbench.paths.spacetime.SpacetimeStyle`). The conventions each
option follows when drawn are at the top of :mod:`workbench.paths.base`.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from _typeshed import DataclassInstance

MAX_CLIP_PLANES = 4
STRIPS = ("none", "triangle", "quad")
QUAD_DIAGONALS = ("auto", "shorter", "strip")
DELETED = ("hide", "ghost")
GHOST_ALPHA = 0.25  # opacity of a deleted element drawn with deleted="ghost"


@dataclass
class Style:
    """How a path draws; every field is optional.

    field: name of a node field ((N,) or (T, N)) or element field ((M,) or (T, M)) of the mesh.
    step: time step drawn. colormap: a matplotlib colormap name. value_range: (lo, hi) of the
    colour scale, default the field's range over all steps. bands: 0 for smooth contours, n > 0
    for n constant-colour bands. hide_range: field values in [lo, hi] get α = 0 in the 1-D
    texture and are discarded by the alpha test (crash2000 §5). crease_deg: Gouraud crease angle
    in degrees. clip_planes: up to 4 world-space planes (a, b, c, d) keeping a·x+b·y+c·z+d ≥ 0.
    magnification / reference_step: deformation plot, shown = reference + magnification·(step −
    reference). wireframe: line-overdraw element wire frame in ``wire_color``. base_color: RGB in
    [0, 1] of the uncoloured paths. cull_back: cull back faces (default off: shells are two-sided).
    strips: "none" (triangle list), "triangle" (meshoptimizer triangle strips) or "quad" (quad
    strips by bandification, quads shorter than ``strip_cutoff`` drawn one by one).
    quad_diagonal: how quads are split, "shorter" (the shorter diagonal), "strip" (the diagonal
    of the quad's strip) or "auto" ("strip" for quad strips, else "shorter").
    fepatch: the fe2003 parameter set of the texture paths, "A" or "B" (their Table 1), or
    "alpha_g1,d,l_outer,l_inner" in degrees and model units. deleted: what is drawn of an
    element deleted at the step (erosion, the mesh's ``"alive"`` field): "hide" (nothing) or
    "ghost" (``base_color`` at opacity :data:`GHOST_ALPHA`, over the live elements).

    Refused with ValueError: more than 4 clip planes, a plane that is not 4 finite numbers with a
    non-zero normal, a negative step, a non-finite magnification, a crease angle outside
    [0, 180], colours that are not 3 numbers in [0, 1], a negative band count.
    """

    field: str | None = None
    step: int = 0
    colormap: str = "viridis"
    value_range: tuple[float, float] | None = None
    bands: int = 0
    hide_range: tuple[float, float] | None = None
    crease_deg: float = 30.0
    clip_planes: tuple = ()
    magnification: float = 1.0
    reference_step: int = 0
    wireframe: bool = False
    wire_color: tuple = (0.0, 0.0, 0.0)
    base_color: tuple = (0.75, 0.75, 0.78)
    cull_back: bool = False
    strips: str = "none"
    strip_cutoff: int = 1
    quad_diagonal: str = "auto"
    fepatch: str = "A"
    deleted: str = "hide"

    def __post_init__(self) -> None:
        planes = np.asarray(self.clip_planes, np.float64).reshape(-1, 4) if len(self.clip_planes) \
            else np.zeros((0, 4))
        if len(planes) > MAX_CLIP_PLANES:
            raise ValueError(f"at most {MAX_CLIP_PLANES} clip planes, got {len(planes)}")
        if not np.isfinite(planes).all() or (np.abs(planes[:, :3]).sum(axis=1) == 0).any():
            raise ValueError(f"clip planes must be finite (a, b, c, d) with a non-zero normal, "
                             f"got {self.clip_planes}")
        self.clip_planes = tuple(tuple(float(v) for v in p) for p in planes)
        for name in ("step", "reference_step", "bands"):
            value = getattr(self, name)
            if int(value) != value or value < 0:
                raise ValueError(f"{name} must be a non-negative integer, got {value}")
            setattr(self, name, int(value))
        if not math.isfinite(self.magnification):
            raise ValueError(f"magnification must be finite, got {self.magnification}")
        if not 0.0 <= self.crease_deg <= 180.0:
            raise ValueError(f"crease_deg must be in [0, 180], got {self.crease_deg}")
        for name in ("wire_color", "base_color"):
            color = tuple(float(c) for c in getattr(self, name))
            if len(color) != 3 or not all(0.0 <= c <= 1.0 for c in color):
                raise ValueError(f"{name} must be 3 numbers in [0, 1], got {getattr(self, name)}")
            setattr(self, name, color)
        if self.strips not in STRIPS:
            raise ValueError(f"strips must be one of {STRIPS}, got {self.strips!r}")
        if self.deleted not in DELETED:
            raise ValueError(f"deleted must be one of {DELETED}, got {self.deleted!r}")
        if self.quad_diagonal not in QUAD_DIAGONALS:
            raise ValueError(f"quad_diagonal must be one of {QUAD_DIAGONALS}, "
                             f"got {self.quad_diagonal!r}")
        if self.strips == "quad" and self.quad_diagonal == "shorter":
            raise ValueError("quad strips split each quad along the strip's diagonal: "
                             "quad_diagonal='shorter' cannot be drawn with strips='quad'")
        if int(self.strip_cutoff) != self.strip_cutoff or self.strip_cutoff < 1:
            raise ValueError(f"strip_cutoff must be an integer >= 1, got {self.strip_cutoff}")
        self.strip_cutoff = int(self.strip_cutoff)

    @property
    def diagonal(self) -> str:
        """The quad split in use: "strip" or "shorter" (``quad_diagonal`` with "auto" resolved)."""
        if self.quad_diagonal != "auto":
            return self.quad_diagonal
        return "strip" if self.strips == "quad" else "shorter"

    def summary(self) -> str:
        """The fields that differ from the defaults, as ``name=value`` words (for table rows)."""
        default = type(self)()
        return " ".join(f"{name}={_word(getattr(self, name))}" for name in self.__dataclass_fields__
                        if getattr(self, name) != getattr(default, name))


def _word(value) -> str:
    """A value written without spaces: floats to 6 significant digits, tuples as (a,b,...)."""
    if isinstance(value, tuple):
        return "(" + ",".join(_word(v) for v in value) + ")"
    return f"{value:.6g}" if isinstance(value, float) else str(value)


def style_summary(style: DataclassInstance) -> str:
    """The fields of ``style`` (any path's style dataclass) that differ from its class's
    defaults, as ``name=value`` words: :meth:`Style.summary` for the mesh styles."""
    if isinstance(style, Style):
        return style.summary()
    default = type(style)()
    return " ".join(f"{f.name}={getattr(style, f.name)}" for f in dataclasses.fields(style)
                    if getattr(style, f.name) != getattr(default, f.name))
