"""Mesh readers through other libraries: FE formats through meshio (``.vtk``, ``.vtu``, ``.inp``,
``.msh``, ...; their quad and triangle cells) and triangle surfaces through trimesh (``.stl``,
``.obj``, ``.ply``, ``.off``, ``.glb``, ``.gltf``).

Errors raised inside meshio and trimesh are wrapped into
:class:`~workbench.scene.readers.errors.ParseError` naming the file, with the original exception
chained.
"""

from __future__ import annotations

import contextlib
import io
import os
from pathlib import Path

import numpy as np

from ..mesh import FEMesh
from .errors import ParseError, build_mesh

_MESHIO_SHELLS = {"quad": 4, "quad8": 4, "quad9": 4, "triangle": 3, "triangle6": 3, "triangle7": 3}


# --------------------------------------------------------------------------- meshio
def read_meshio(path: str | os.PathLike[str], units: str = "mm") -> FEMesh:
    """Read a meshio-supported FE file: its quad and triangle cells become elements.

    Higher-order quads and triangles (quad8/9, triangle6/7) keep their corner nodes; other cells
    (lines, vertices, volumes) are ignored. Points with two coordinates get z = 0. Scalar point
    data ((N,) or (N, 1)) become node fields and scalar cell data element fields (only when every
    kept cell block carries it). Parts come from ``gmsh:physical`` tags (names from the Gmsh
    physical names), else from cell sets (numbered 1.. in their order, named after the set; later
    sets win where they overlap), else all 0. Refuses a file without quad or triangle cells.
    """
    import meshio

    path = Path(path)
    said = io.StringIO()  # meshio prints its reasons instead of raising them
    try:
        with contextlib.redirect_stdout(said), contextlib.redirect_stderr(said):
            raw = meshio.read(path)
    # meshio raises many types, and calls sys.exit when no reader accepts the file
    except (Exception, SystemExit) as exc:
        if isinstance(exc, SystemExit):
            printed = " ".join(said.getvalue().split())
            reason = "no meshio reader accepted it" + (f" ({printed})" if printed else "")
        else:
            reason = f"{type(exc).__name__}: {str(exc).strip()}"
        raise ParseError(path, f"meshio could not read it: {reason}") from exc
    points = np.asarray(raw.points, dtype=np.float64)
    if points.ndim != 2 or points.shape[1] not in (2, 3):
        raise ParseError(path, f"points must be (N, 2) or (N, 3), got {points.shape}")
    if points.shape[1] == 2:
        points = np.column_stack([points, np.zeros(len(points))])

    kept = [i for i, block in enumerate(raw.cells) if block.type in _MESHIO_SHELLS]
    if not kept:
        found = sorted({block.type for block in raw.cells}) or ["no cells"]
        raise ParseError(path, f"no quad or triangle cells (found {', '.join(found)})")
    chunks = []
    for i in kept:
        block = raw.cells[i]
        corners = np.asarray(block.data, dtype=np.int64)[:, :_MESHIO_SHELLS[block.type]]
        if corners.shape[1] == 3:
            corners = np.column_stack([corners, corners[:, 2]])
        chunks.append(corners)
    elements = np.concatenate(chunks)

    def kept_cell_values(per_block) -> np.ndarray | None:
        arrays = []
        for i in kept:
            values = np.asarray(per_block[i])
            if values.ndim == 2 and values.shape[1] == 1:
                values = values[:, 0]
            if values.ndim != 1 or not np.issubdtype(values.dtype, np.number):
                return None
            arrays.append(values)
        return np.concatenate(arrays)

    parts = None
    part_names: dict[int, str] = {}
    if "gmsh:physical" in raw.cell_data:
        parts = kept_cell_values(raw.cell_data["gmsh:physical"])
        for name, (tag, *_dim) in getattr(raw, "field_data", {}).items():
            part_names[int(tag)] = str(name)
    elif raw.cell_sets:
        parts = np.zeros(len(elements), np.int64)
        offsets = np.cumsum([0] + [len(raw.cells[i].data) for i in kept])
        for number, (name, per_block) in enumerate(raw.cell_sets.items(), start=1):
            for k, i in enumerate(kept):
                if i < len(per_block) and per_block[i] is not None and len(per_block[i]):
                    parts[offsets[k] + np.asarray(per_block[i], dtype=np.int64)] = number
            part_names[number] = str(name)
    if parts is not None:
        parts = parts.astype(np.int64)

    node_fields = {}
    for name, values in raw.point_data.items():
        values = np.asarray(values)
        if values.ndim == 2 and values.shape[1] == 1:
            values = values[:, 0]
        if values.ndim == 1 and np.issubdtype(values.dtype, np.number):
            node_fields[str(name)] = values.astype(np.float64)
    element_fields = {}
    for name, per_block in raw.cell_data.items():
        if str(name).startswith("gmsh:"):
            continue
        values = kept_cell_values(per_block)
        if values is not None:
            element_fields[str(name)] = values.astype(np.float64)
    return build_mesh(path, nodes=points, elements=elements, parts=parts, node_fields=node_fields,
                      element_fields=element_fields, part_names=part_names, name=path.name,
                      units=units)


# --------------------------------------------------------------------------- trimesh
def read_trimesh(path: str | os.PathLike[str], units: str = "mm") -> FEMesh:
    """Read a triangle surface through trimesh; every element is a triangle (``e[3] == e[2]``).

    A scene with several geometries (glTF) gives one part per geometry (1.., named after it),
    with the scene's transforms applied. STL stores every triangle with its own corners: exactly
    coincident vertices are merged so that the surface is connected; the other formats keep
    their vertex indexing. Refuses a file without triangles.
    """
    import trimesh

    path = Path(path)
    try:
        scene = trimesh.load_scene(path, process=False)
        geometries = [g for g in scene.dump(concatenate=False)
                      if isinstance(g, trimesh.Trimesh) and len(g.faces)]
    except Exception as exc:  # trimesh raises many types; all mean "cannot read this file"
        raise ParseError(path, f"trimesh could not read it: {type(exc).__name__}: {exc}") from exc
    if not geometries:
        raise ParseError(path, "no triangles")
    nodes, faces, parts, names, offset = [], [], [], {}, 0
    for number, geometry in enumerate(geometries, start=1):
        vertices = np.asarray(geometry.vertices, dtype=np.float64)
        nodes.append(vertices)
        faces.append(np.asarray(geometry.faces, dtype=np.int64) + offset)
        parts.append(np.full(len(geometry.faces), number))
        names[number] = str(geometry.metadata.get("name", f"geometry {number}"))
        offset += len(vertices)
    nodes = np.concatenate(nodes)
    faces = np.concatenate(faces)
    if path.name.lower().endswith(".stl"):
        nodes = nodes + 0.0  # -0.0 -> 0.0, so that the bitwise merge below sees them equal
        nodes, inverse = np.unique(nodes, axis=0, return_inverse=True)
        faces = inverse.reshape(-1)[faces]
    elements = np.column_stack([faces, faces[:, 2]])
    return build_mesh(path, nodes=nodes, elements=elements, parts=np.concatenate(parts),
                      part_names=names, name=path.name, units=units)
