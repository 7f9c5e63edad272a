"""FE scene model: the FEMesh data model, derived data, readers and generators."""

from .io import ParseError, load
from .mesh import FEMesh, MeshError

__all__ = ["FEMesh", "MeshError", "ParseError", "load"]
