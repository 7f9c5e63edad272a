"""A synthetic load case with a closed-form section force: a straight prismatic tube under
uniform axial stress (see :func:`prismatic_tube`)."""

from __future__ import annotations

import numpy as np

from ...scene.mesh import FEMesh
from .section import STRESS_FIELDS, THICKNESS_FIELD


def prismatic_tube(sides: int = 8, length: float = 100.0, radius: float = 10.0,
                   thickness: float = 1.0, stress=100.0, segments: int = 10, steps: int = 1, *,
                   stretch: float = 0.0, shift=(0.0, 0.0, 0.0)) -> tuple[FEMesh, np.ndarray]:
    """A load case with a closed-form section force: a straight prismatic tube along the x axis.

    The cross-section is a regular ``sides``-gon of circumradius ``radius`` (corners at angles
    2πk/sides in the y-z plane, corners on an axis exactly on it); ``segments`` rings of quads
    span x = 0 … ``length`` (model units), each face a flat quad, all of part 1. The element
    fields are the uniform axial stress ``stress_xx`` = σ (``stress``: one value, or one per
    step), the five other components 0 and ``thickness``. Step k is the tube stretched along
    x by the factor 1 + k·``stretch`` and moved by k·``shift`` (rings stay flat and parallel).

    Returns ``(mesh, exact)``: exact (T,) = σ_k · thickness · perimeter, perimeter = sides ·
    2·radius·sin(π/sides). Every plane that cuts all faces from one long edge to the other
    (any plane through the tube's length with n_x ≠ 0, oblique ones included: each face
    contributes σ·t times its width, whatever the tilt) transmits exactly the force vector
    ``exact[k] · sign(n_x) · e_x``; its axial component is ``exact[k] · |n_x|`` for a unit
    normal n.

    Refused (ValueError): sides < 3, segments < 1, steps < 1, non-positive length, radius or
    thickness, a stress sequence whose length is not ``steps``.
    """
    if int(sides) != sides or sides < 3:
        raise ValueError(f"sides must be an integer ≥ 3, got {sides}")
    if int(segments) != segments or segments < 1:
        raise ValueError(f"segments must be an integer ≥ 1, got {segments}")
    if int(steps) != steps or steps < 1:
        raise ValueError(f"steps must be an integer ≥ 1, got {steps}")
    for name, value in (("length", length), ("radius", radius), ("thickness", thickness)):
        if not (np.isfinite(value) and value > 0):
            raise ValueError(f"{name} must be positive, got {value}")
    sides, segments, steps = int(sides), int(segments), int(steps)
    sigma = np.asarray(stress, dtype=np.float64)
    sigma = np.full(steps, float(sigma)) if sigma.ndim == 0 else sigma.reshape(-1)
    if len(sigma) != steps:
        raise ValueError(f"stress must be one value or {steps} (one per step), got {len(sigma)}")
    angle = 2.0 * np.pi * np.arange(sides) / sides
    y, z = radius * np.cos(angle), radius * np.sin(angle)
    y[np.abs(y) < 1e-12 * radius] = 0.0
    z[np.abs(z) < 1e-12 * radius] = 0.0
    x = length * np.arange(segments + 1) / segments
    nodes = np.stack([np.repeat(x, sides), np.tile(y, segments + 1), np.tile(z, segments + 1)],
                     axis=1)
    i, k = np.meshgrid(np.arange(segments), np.arange(sides), indexing="ij")
    k1 = (k + 1) % sides
    elements = np.stack([i * sides + k, i * sides + k1, (i + 1) * sides + k1,
                         (i + 1) * sides + k], axis=-1).reshape(-1, 4)  # normals outward
    m = len(elements)
    shift = np.asarray(shift, dtype=np.float64)
    coords = []
    for step in range(steps):
        c = nodes.copy()
        c[:, 0] *= 1.0 + step * stretch
        coords.append(c + step * shift)
    per_step = steps > 1
    fields = {name: np.zeros((steps, m) if per_step else m) for name in STRESS_FIELDS}
    fields["stress_xx"] = np.repeat(sigma[:, None], m, axis=1) if per_step \
        else np.full(m, sigma[0])
    fields[THICKNESS_FIELD] = np.full(m, float(thickness))
    mesh = FEMesh(nodes=coords[0], elements=elements, parts=np.ones(m, np.int32),
                  steps=np.stack(coords) if per_step else None, element_fields=fields,
                  part_names={1: "prismatic tube"}, name=f"prismatic tube {sides}-gon")
    perimeter = sides * 2.0 * radius * np.sin(np.pi / sides)
    return mesh, sigma * float(thickness) * perimeter
