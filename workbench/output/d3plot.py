"""A time-dependent shell mesh written as an LS-DYNA d3plot with lasso-python, so that a
generated result goes through the same reader as a user's file."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..scene.conventions import ALIVE
from ..scene.mesh import FEMesh


def write_d3plot(mesh: FEMesh, folder: str | Path) -> Path:
    """``mesh`` as a d3plot in the existing ``folder``: its shells (quads; a triangle repeats
    its last node), parts, node coordinates at every state, the times, and where it has them
    the element fields ``plastic_strain`` (one layer) and ``alive`` (element deletion). Node
    and element ids are 1, 2, ... in the mesh's order; coordinates and fields are written in
    float32, as a d3plot stores them. Returns the path of the first file. Refused with
    ValueError: a mesh without states, or with elements other than shells."""
    from lasso.dyna import ArrayType, D3plot

    if mesh.steps is None:
        raise ValueError(f"{mesh.name}: a d3plot holds states; the mesh has none")
    elements = np.asarray(mesh.elements)
    if elements.ndim != 2 or elements.shape[1] not in (3, 4):
        raise ValueError(f"{mesh.name}: only shells (3 or 4 nodes) are written, got elements "
                         f"of shape {elements.shape}")
    if elements.shape[1] == 3:
        elements = np.concatenate([elements, elements[:, 2:]], axis=1)
    plot = D3plot()
    arrays = plot.arrays
    parts, part_index = np.unique(mesh.parts, return_inverse=True)
    arrays[ArrayType.node_coordinates] = mesh.nodes.astype(np.float32)
    arrays[ArrayType.node_ids] = np.arange(1, mesh.n_nodes + 1, dtype=np.int32)
    arrays[ArrayType.element_shell_node_indexes] = elements.astype(np.int32)
    arrays[ArrayType.element_shell_part_indexes] = part_index.ravel().astype(np.int32)
    arrays[ArrayType.element_shell_ids] = np.arange(1, mesh.n_elements + 1, dtype=np.int32)
    arrays[ArrayType.part_ids] = parts.astype(np.int32)
    times = mesh.times if mesh.times is not None else np.arange(len(mesh.steps))
    arrays[ArrayType.global_timesteps] = np.asarray(times, np.float32)
    arrays[ArrayType.node_displacement] = mesh.steps.astype(np.float32)
    if "plastic_strain" in mesh.element_fields:
        strain = np.asarray(mesh.element_fields["plastic_strain"], np.float32)
        arrays[ArrayType.element_shell_effective_plastic_strain] = strain[:, :, None]
    if ALIVE in mesh.element_fields:
        alive = np.asarray(mesh.element_fields[ALIVE], np.float32)
        arrays[ArrayType.element_shell_is_alive] = alive
    path = Path(folder) / "d3plot"
    plot.write_d3plot(str(path))
    return path
