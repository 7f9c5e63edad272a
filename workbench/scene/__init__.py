"""FE scene model: FEMesh, the Scene protocol, derived data, readers and generators."""

from .mesh import FEMesh, MeshError
from .protocol import Scene
from .readers import ParseError, load

__all__ = ["FEMesh", "MeshError", "ParseError", "Scene", "load"]
