"""Mesh readers: ``load(path)`` turns an FE result or surface file into an :class:`FEMesh`.

The reader is chosen by the file name:

* LS-DYNA keyword decks (``.k``, ``.key``, ``.dyn``, ``.kw``):
  :mod:`workbench.scene.readers.keyword`;
* LS-DYNA binary results (a file named ``d3plot`` or ``d3plot*`` without a known suffix):
  :mod:`workbench.scene.readers.d3plot`, through lasso-python;
* other FE formats (``.vtk``, ``.vtu``, ``.inp``, ``.msh``, ``.xdmf``, ...) through meshio:
  quad and triangle cells (corner nodes of their higher-order variants), scalar point and
  cell data as node and element fields, Gmsh physical tags or cell sets as parts;
* triangle surfaces (``.stl``, ``.obj``, ``.ply``, ``.off``, ``.glb``, ``.gltf``) through trimesh.

The meshio and trimesh readers are in :mod:`workbench.scene.readers.meshio_trimesh`.

Coordinates are taken as they are in the file and labelled with ``units`` (millimetres unless
told otherwise); nothing is scaled. Every refusal is a :class:`ParseError` that names the file
(and, for keyword decks, the line and the card), except a missing file, which is a
:class:`FileNotFoundError`. Errors raised inside meshio, trimesh and lasso-python are wrapped
into :class:`ParseError` with the original exception chained. :class:`ParseError`,
:class:`ParseWarning` and :func:`build_mesh` live in :mod:`workbench.scene.readers.errors` and
are re-exported here.
"""

from __future__ import annotations

import errno
import os
from pathlib import Path

from ..mesh import FEMesh
from .d3plot import read_d3plot
from .errors import ParseError, ParseWarning, build_mesh
from .keyword import read_keyword
from .meshio_trimesh import read_meshio, read_trimesh

__all__ = ["FORMATS", "KEYWORD_SUFFIXES", "MESHIO_SUFFIXES", "TRIMESH_SUFFIXES", "ParseError",
           "ParseWarning", "build_mesh", "detect_format", "load", "read_d3plot", "read_keyword",
           "read_meshio", "read_trimesh", "supported_formats"]

KEYWORD_SUFFIXES = (".k", ".key", ".dyn", ".kw")
TRIMESH_SUFFIXES = (".stl", ".obj", ".ply", ".off", ".glb", ".gltf")
# meshio formats that can hold surface cells (obj/ply/off/stl go to trimesh instead).
MESHIO_SUFFIXES = (
    ".vtk", ".vtu", ".inp", ".msh", ".xdmf", ".xmf", ".med", ".mesh", ".meshb", ".bdf",
    ".nas", ".fem", ".su2", ".ugrid", ".f3grid", ".h5m", ".cgns", ".e", ".exo", ".ex2",
    ".avs", ".tec", ".vol", ".vol.gz", ".post", ".post.gz", ".mdpa", ".hmf",
)
FORMATS = ("keyword", "d3plot", "meshio", "trimesh")


def supported_formats() -> str:
    """A one-line description of the file names :func:`load` accepts."""
    return (f"LS-DYNA keyword decks ({', '.join(KEYWORD_SUFFIXES)}), LS-DYNA d3plot results "
            f"(files named d3plot*), meshio formats ({', '.join(MESHIO_SUFFIXES)}) and "
            f"trimesh surfaces ({', '.join(TRIMESH_SUFFIXES)})")


def detect_format(path: str | os.PathLike[str]) -> str:
    """The reader for ``path`` by its name: "keyword", "d3plot", "meshio" or "trimesh".

    Refuses an unknown suffix with :class:`ParseError` listing the supported formats.
    """
    path = Path(path)
    name = path.name.lower()
    for suffixes, fmt in ((KEYWORD_SUFFIXES, "keyword"), (TRIMESH_SUFFIXES, "trimesh"),
                          (MESHIO_SUFFIXES, "meshio")):
        if any(name.endswith(s) for s in suffixes):
            return fmt
    if name.startswith("d3plot"):
        return "d3plot"
    raise ParseError(path, f"unknown mesh format {path.suffix or '(no suffix)'!r}; "
                           f"supported: {supported_formats()}")


def load(path: str | os.PathLike[str], *, format: str | None = None, units: str = "mm",
         all_faces: bool = False) -> FEMesh:
    """Read the shell mesh in ``path`` (a str or Path) into an :class:`FEMesh`.

    ``format`` forces a reader ("keyword", "d3plot", "meshio", "trimesh"); by default it is
    chosen by :func:`detect_format`. ``units`` labels the coordinates (they are not scaled).
    Solid elements of a keyword deck are drawn by their boundary faces, or by every face with
    ``all_faces``.
    Raises FileNotFoundError when the file does not exist and :class:`ParseError` for anything
    that cannot be read; nothing partially read is returned.
    """
    path = Path(os.fspath(path))
    if not path.exists():
        raise FileNotFoundError(errno.ENOENT, "mesh file not found", str(path))
    if not path.is_file():
        raise ParseError(path, "not a file")
    fmt = detect_format(path) if format is None else format
    if fmt == "keyword":
        return read_keyword(path, units=units, all_faces=all_faces)
    if fmt == "d3plot":
        return read_d3plot(path, units=units, all_faces=all_faces)
    if fmt == "meshio":
        return read_meshio(path, units=units)
    if fmt == "trimesh":
        return read_trimesh(path, units=units)
    raise ValueError(f"unknown format {fmt!r}; choose one of {FORMATS}")
