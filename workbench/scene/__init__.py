"""FE scene model: the FEMesh data model, derived data, readers and generators."""

from .mesh import FEMesh, MeshError

__all__ = ["FEMesh", "MeshError"]
