"""The names every part of the FE model shares: the erosion field and the model's refusal.

Kept apart from :mod:`workbench.scene.mesh` so that the element kinds beside the surface
(:mod:`workbench.scene.kinds`) follow the same rules without importing the mesh that holds
them; :mod:`workbench.scene.mesh` re-exports both names.
"""

from __future__ import annotations

ALIVE = "alive"  # the element field of erosion: 1 in use, 0 deleted


class MeshError(ValueError):
    """An FE mesh that cannot be drawn or measured: empty, or with dangling node references."""
