"""FE scene model: the FEMesh data model, derived data, readers and generators."""

from .mesh import FEMesh, MeshError
from .readers import ParseError, load

__all__ = ["FEMesh", "MeshError", "ParseError", "load"]
