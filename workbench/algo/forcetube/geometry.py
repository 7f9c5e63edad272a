"""The force tube as geometry: rings around the section planes whose radius grows with the
axial force (:func:`tube_mesh`), appended to the model as one more part (:func:`with_tube`)."""

from __future__ import annotations

import numpy as np

from ...scene.mesh import FEMesh
from .tube import ForceTube

TUBE_FIELD = "section_force"


def _ring_frames(normals: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(S, 3) u and v = n × u spanning each plane, u carried along by parallel transport
    (projected from the previous ring's u) so that the rings do not twist."""
    u = np.empty_like(normals)
    first = normals[0]
    axis = np.eye(3)[np.argmin(np.abs(first))]
    u[0] = axis - (axis @ first) * first
    u[0] /= np.linalg.norm(u[0])
    for i in range(1, len(normals)):
        n = normals[i]
        cand = u[i - 1] - (u[i - 1] @ n) * n
        length = np.linalg.norm(cand)
        if length < 1e-9:  # the previous u is along this normal: start afresh
            axis = np.eye(3)[np.argmin(np.abs(n))]
            cand, length = axis - (axis @ n) * n, np.linalg.norm(axis - (axis @ n) * n)
        u[i] = cand / length
    return u, np.cross(normals, u)


def tube_mesh(tube: ForceTube, step: int | None, *, radius_range, sides: int = 16,
              force_range=None, part_id: int = 1) -> FEMesh:
    """The force tube of mesh step ``step`` as an :class:`FEMesh` (or, with ``step=None``, of
    every computed step, with (T, N, 3) steps and a (T, N) field).

    Ring i is a regular ``sides``-gon of nodes around plane i's point, in the plane (radius
    r_i, model units); consecutive rings are joined by ``sides`` quads each (normals outward),
    so the tube has ``sides × planes`` nodes and ``sides × (planes − 1)`` quads, all of part
    ``part_id`` ("force tube"). The radius maps ``|axial force|`` linearly: ``force_range`` (lo, hi)
    to ``radius_range`` (r_lo, r_hi), clipped; by default lo = 0 and hi = the largest finite
    ``|axial force|`` over all computed steps (so rings are comparable between steps; all rings
    get r_lo when that is 0). The node field ``"section_force"`` holds the axial force of the
    node's ring (NaN rings get r_lo and NaN), for drawing with the colour map.

    Refused (ValueError): a step not computed, fewer than 2 planes, ``sides`` < 3, a radius
    range that is not 0 ≤ r_lo ≤ r_hi with r_hi > 0, a force range with hi ≤ lo.
    """
    if int(sides) != sides or sides < 3:
        raise ValueError(f"sides must be an integer ≥ 3, got {sides}")
    sides = int(sides)
    r_lo, r_hi = (float(v) for v in radius_range)
    if not (np.isfinite(r_lo) and np.isfinite(r_hi) and 0 <= r_lo <= r_hi and r_hi > 0):
        raise ValueError(f"radius_range must be (r_lo, r_hi) with 0 ≤ r_lo ≤ r_hi, r_hi > 0; "
                         f"got {radius_range}")
    if tube.n_planes < 2:
        raise ValueError(f"a tube needs at least 2 planes, the force tube has {tube.n_planes}")
    magnitude = np.abs(tube.axial)
    if force_range is None:
        finite = magnitude[np.isfinite(magnitude)]
        f_lo, f_hi = 0.0, (float(finite.max()) if finite.size else 0.0)
    else:
        f_lo, f_hi = (float(v) for v in force_range)
        if not (np.isfinite(f_lo) and np.isfinite(f_hi) and f_hi > f_lo):
            raise ValueError(f"force_range must be (lo, hi) with hi > lo, got {force_range}")
    rows = range(len(tube.steps)) if step is None else [tube.index(step)]

    theta = 2.0 * np.pi * np.arange(sides) / sides
    cos, sin = np.cos(theta), np.sin(theta)
    coords, values = [], []
    for row in rows:
        a = magnitude[row]
        if f_hi > f_lo:
            t = np.clip((a - f_lo) / (f_hi - f_lo), 0.0, 1.0)
        else:
            t = np.zeros_like(a)
        radius = r_lo + np.where(np.isfinite(t), t, 0.0) * (r_hi - r_lo)
        u, v = _ring_frames(tube.normals[row])
        ring = (cos[None, :, None] * u[:, None, :] + sin[None, :, None] * v[:, None, :])
        coords.append((tube.points[row][:, None, :] + radius[:, None, None] * ring)
                      .reshape(-1, 3))
        values.append(np.repeat(tube.axial[row], sides))
    n_planes = tube.n_planes
    i, k = np.meshgrid(np.arange(n_planes - 1), np.arange(sides), indexing="ij")
    k1 = (k + 1) % sides
    elements = np.stack([i * sides + k, i * sides + k1, (i + 1) * sides + k1,
                         (i + 1) * sides + k], axis=-1).reshape(-1, 4)
    single = step is not None
    return FEMesh(
        nodes=coords[0], elements=elements,
        parts=np.full(len(elements), int(part_id), np.int32),
        steps=None if single else np.stack(coords),
        node_fields={TUBE_FIELD: values[0] if single else np.stack(values)},
        part_names={int(part_id): "force tube"},
        name="force tube", units=tube.units)


def _extend(first: np.ndarray | None, second: np.ndarray | None, n1: int, n2: int,
            n_steps: int) -> np.ndarray:
    """Concatenate two field arrays (static or per step) along the entity axis, NaN where one
    side lacks the field; per step if either is."""
    per_step = any(v is not None and v.ndim == 2 for v in (first, second))
    parts = []
    for values, n in ((first, n1), (second, n2)):
        if values is None:
            values = np.full((n_steps, n) if per_step else (n,), np.nan)
        elif per_step and values.ndim == 1:
            values = np.broadcast_to(values, (n_steps, n))
        parts.append(values)
    return np.concatenate(parts, axis=-1)


def with_tube(mesh: FEMesh, tube: FEMesh) -> FEMesh:
    """``mesh`` with the tube mesh ``tube`` (from :func:`tube_mesh`) appended.

    The model's nodes, elements, parts, fields and ids come first, unchanged; the tube's
    elements get one new part id (one more than the largest in the model), named "force
    tube"; its node and element ids (when the model has ids) continue after the model's
    largest. Node fields the other side lacks are NaN there (so the model's nodes have NaN
    ``"section_force"`` and are drawn in the base colour); element fields likewise. A static
    tube is repeated over the model's steps; a tube with steps must have as many as the model.
    """
    n1, n2 = mesh.n_nodes, tube.n_nodes
    m1, m2 = mesh.n_elements, tube.n_elements
    if tube.steps is not None and mesh.steps is not None and tube.n_steps != mesh.n_steps:
        raise ValueError(f"the tube has {tube.n_steps} steps, the model {mesh.n_steps}")
    n_steps = max(mesh.n_steps, tube.n_steps)
    steps = None
    if mesh.steps is not None or tube.steps is not None:
        a = mesh.steps if mesh.steps is not None else np.broadcast_to(mesh.nodes, (n_steps, n1, 3))
        b = tube.steps if tube.steps is not None else np.broadcast_to(tube.nodes, (n_steps, n2, 3))
        steps = np.concatenate([a, b], axis=1)
    new_part = int(mesh.parts.max()) + 1 if m1 else 1
    node_fields = {name: _extend(mesh.node_fields.get(name), tube.node_fields.get(name),
                                 n1, n2, n_steps)
                   for name in dict.fromkeys([*mesh.node_fields, *tube.node_fields])}
    element_fields = {name: _extend(mesh.element_fields.get(name),
                                    tube.element_fields.get(name), m1, m2, n_steps)
                      for name in dict.fromkeys([*mesh.element_fields, *tube.element_fields])}
    node_ids = element_ids = None
    if mesh.node_ids is not None:
        start = int(mesh.node_ids.max()) + 1 if n1 else 1
        node_ids = np.concatenate([mesh.node_ids, start + np.arange(n2)])
    if mesh.element_ids is not None:
        start = int(mesh.element_ids.max()) + 1 if m1 else 1
        element_ids = np.concatenate([mesh.element_ids, start + np.arange(m2)])
    return FEMesh(
        nodes=np.concatenate([mesh.nodes, tube.nodes]),
        elements=np.concatenate([mesh.elements, tube.elements + n1]),
        parts=np.concatenate([mesh.parts, np.full(m2, new_part, np.int32)]),
        steps=steps, node_fields=node_fields, element_fields=element_fields,
        part_names={**mesh.part_names, new_part: "force tube"},
        times=mesh.times if mesh.times is not None else tube.times,
        node_ids=node_ids, element_ids=element_ids, name=mesh.name, units=mesh.units)
