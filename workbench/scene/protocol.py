"""What every scene a render path draws offers: the :class:`Scene` protocol.

FE meshes (:class:`~workbench.scene.mesh.FEMesh`), spacetime scenes
(:class:`~workbench.algo.spacetime.scene.SpacetimeScene`) and textured surfaces
(:class:`~workbench.algo.fepatch.surface.TexturedSurface`) meet it without naming it: it is a
structural type for annotations, checked by type checkers only (not at run time).
"""

from __future__ import annotations

from typing import Protocol

import numpy as np


class Scene(Protocol):
    """Any scene: ``name`` (how tables name it), ``kind`` ("mesh", "spacetime", "surface": which
    paths draw it) and :meth:`bounds`. Both attributes are read-only here, so that a class
    attribute, a dataclass field and a frozen dataclass field all meet the protocol."""

    @property
    def name(self) -> str: ...

    @property
    def kind(self) -> str: ...

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """(lo, hi) float64 corners of the scene's axis-aligned bounding box in model units
        (in its drawing plane for a spacetime scene)."""
        ...
