"""Writing a triangle surface (a simplified mesh, say) to a mesh file, atomically."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from .tables import atomic_write_bytes, atomic_write_text


def write_surface(path: str | os.PathLike[str], vertices: np.ndarray,
                  triangles: np.ndarray) -> Path:
    """Write the triangles ``triangles`` (T × 3 indices into ``vertices``, N × 3) to ``path``
    in the format its suffix names (``.ply``, the default without one, ``.obj``, ``.stl`` and
    the other formats trimesh exports); only the vertices the triangles use are written,
    renumbered in their order. The folder is created; the file is replaced whole. Returns
    ``path``. A suffix trimesh does not export is refused with its ValueError."""
    import trimesh

    used = np.unique(triangles)
    remap = np.full(len(vertices), -1, np.int64)
    remap[used] = np.arange(len(used))
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    data = trimesh.Trimesh(vertices[used], remap[triangles], process=False).export(
        file_type=out.suffix.lstrip(".") or "ply")
    if isinstance(data, str):
        atomic_write_text(out, data)
    else:
        atomic_write_bytes(out, data)
    return out
