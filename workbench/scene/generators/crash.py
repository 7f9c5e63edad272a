"""Time steps of a smooth progressive front crush of a static mesh, with per-node displacement
and per-element plastic strain."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..derived import element_normals, node_normals
from ..mesh import FEMesh, MeshError
from .common import _positive_float, _positive_int, _smoothstep

_AXES = {"x": 0, "y": 1, "z": 2}


def crash_sequence(mesh: FEMesh, steps: int = 20, crush: float = 0.25, axis: str = "-x", *,
                   fold_wavelength: float | None = None, duration: float = 0.1,
                   still_parts: Sequence[int] = (), failure_strain: float | None = None
                   ) -> FEMesh:
    """A copy of ``mesh`` with ``steps`` time steps of a smooth, progressive front crush.

    The impactor comes from the ``axis`` side (one of "x", "y", "z", "-x", "-y", "-z": "x" makes
    the nodes of largest x the front, "-x" those of smallest x) and pushes the front back along
    the axis. The default "-x" suits car body coordinates, where x points rearwards (the shared
    LS-DYNA car deck has its bumper at x = 0 and the barrier at negative x).
    With depth d of a node behind the front, extent E of the model along the axis, progress
    τ = i / (steps - 1) and the smooth ramp c(τ) = crush · E · smoothstep(τ) (the crush depth):

    - axial: the front moves back by c; the crush zone of depth Z = 2.5 c is compressed smoothly,
      a node moving by c · φ(d / Z) with φ(r) = 1 - smoothstep(r) (nodes behind Z stay put);
    - buckling: folds of wavelength λ (``fold_wavelength``, default 8 % of E) across the axis,
      along each node's normal projected off the axis, of amplitude 0.25 λ tanh(c / λ) ·
      sin(2π d / λ) · φ(d / Z).

    Both parts only grow with τ and are perpendicular, so every node's displacement grows
    monotonically with time; nodes nearest the impact move most. Adds ``steps`` (T, N, 3),
    ``times`` (T,) in seconds over ``duration``, node field ``"displacement"`` (T, N): distance
    from step 0 in model units, and element field ``"plastic_strain"`` (T, M): a proxy from the
    element edges' stretch and the rotation of the element normal since step 0, beyond a 0.2 %
    yield, accumulated (it never decreases). Step 0 equals the input geometry; topology, parts and
    static fields are kept. ``still_parts``: part ids that do not move (a rigid barrier or pole);
    the front and extent are those of the other parts, and a node moves unless only still parts
    use it. ``failure_strain`` (> 0): erosion as a crash code writes it, an element whose
    plastic strain reaches it is deleted from that state on (element field ``"alive"``, 1 in
    use and 0 deleted) and keeps the value it failed with (its ``plastic_strain`` is frozen).
    Refused: meshes that already have time steps, steps < 2, crush not in (0, 1), an
    unknown axis, a model with no extent along the axis, only still parts, a failure strain
    that is not a positive number.
    """
    if mesh.steps is not None:
        raise MeshError(f"{mesh.name}: already has {mesh.n_steps} time steps; crash a static mesh")
    steps = _positive_int(steps, "steps", 2)
    crush = float(crush)
    if not 0.0 < crush < 1.0:
        raise ValueError(f"crush must be in (0, 1) (a fraction of the model's extent), got {crush}")
    duration = _positive_float(duration, "duration")
    a_idx, a = _impact_axis(axis)
    nodes = mesh.nodes
    coords = _crushed_coordinates(mesh, a_idx, a, steps, crush, fold_wavelength, still_parts,
                                  axis)
    displacement = np.linalg.norm(coords - nodes[None], axis=2)
    strain = _plastic_strain(mesh.elements, nodes, coords)
    node_fields = {key: (np.broadcast_to(v[0], (steps,) + v.shape[1:]).copy() if v.ndim == 2 else v)
                   for key, v in mesh.node_fields.items()}
    element_fields = {key: (np.broadcast_to(v[0], (steps,) + v.shape[1:]).copy() if v.ndim == 2
                            else v)
                      for key, v in mesh.element_fields.items()}
    node_fields["displacement"] = displacement
    element_fields["plastic_strain"] = strain
    if failure_strain is not None:
        failure_strain = _positive_float(failure_strain, "failure_strain")
        failed = np.maximum.accumulate(strain >= failure_strain, axis=0)
        first = np.argmax(failed, axis=0)  # the state each failed element failed in
        strain[failed] = np.broadcast_to(strain[first, np.arange(strain.shape[1])],
                                         strain.shape)[failed]
        element_fields["alive"] = (~failed).astype(np.float64)
    return FEMesh(
        nodes=nodes.copy(),
        elements=mesh.elements,
        parts=mesh.parts,
        steps=coords,
        node_fields=node_fields,
        element_fields=element_fields,
        part_names=dict(mesh.part_names),
        times=np.linspace(0.0, duration, steps),
        node_ids=mesh.node_ids,
        element_ids=mesh.element_ids,
        name=f"{mesh.name}_crash",
        units=mesh.units,
    )


def _impact_axis(axis: str) -> tuple[int, np.ndarray]:
    """(coordinate index, unit vector a) of ``axis`` ("x", "-x", ...): the front is where
    ``nodes @ a`` is largest."""
    key = str(axis).lower()
    sign = -1.0 if key.startswith("-") else 1.0
    if key.lstrip("+-") not in _AXES:
        raise ValueError(f"axis must be one of x, y, z, -x, -y, -z, got {axis!r}")
    a_idx = _AXES[key.lstrip("+-")]
    a = np.zeros(3)
    a[a_idx] = sign
    return a_idx, a


def _crushed_coordinates(mesh: FEMesh, a_idx: int, a: np.ndarray, steps: int, crush: float,
                         fold_wavelength: float | None, still_parts, axis) -> np.ndarray:
    """(steps, N, 3) node coordinates of the crush along ``a`` (see :func:`crash_sequence`);
    step 0 is the input geometry."""
    nodes = mesh.nodes
    moving = np.zeros(len(nodes), bool)
    moving[mesh.elements[~np.isin(mesh.parts, np.asarray(still_parts, np.int64))].ravel()] = True
    if not moving.any():
        raise MeshError(f"{mesh.name}: every part is in still_parts {tuple(still_parts)}; "
                        "nothing to crush")
    used = np.flatnonzero(moving)
    along = nodes @ a
    front, back = along[used].max(), along[used].min()
    extent = front - back
    if not extent > 0:
        raise MeshError(f"{mesh.name}: no extent along {axis!r} to crush")
    lam = (0.08 * extent if fold_wavelength is None
           else _positive_float(fold_wavelength, "fold_wavelength"))
    depth = np.maximum(front - along, 0.0)

    # lateral direction: the node normal with its axial part removed (a fixed perpendicular axis
    # where the normal is along the axis), so that lateral and axial motion are perpendicular
    fallback = np.zeros(3)
    fallback[(a_idx + 2) % 3] = 1.0
    normal = node_normals(mesh.elements, nodes)
    lateral = normal - np.outer(normal @ a, a) + 0.05 * fallback
    norm = np.linalg.norm(lateral, axis=1, keepdims=True)
    lateral = np.where(norm > 1e-9, lateral / np.maximum(norm, 1e-300), fallback)
    wave = np.sin(2.0 * np.pi * depth / lam)

    tau = np.linspace(0.0, 1.0, steps)
    c = crush * extent * _smoothstep(tau)
    coords = np.empty((steps, len(nodes), 3))
    coords[0] = nodes
    for i in range(1, steps):
        phi = (1.0 - _smoothstep(depth / (2.5 * c[i]))) * moving
        amp = 0.25 * lam * np.tanh(c[i] / lam)
        coords[i] = nodes - np.outer(c[i] * phi, a) + (amp * wave * phi)[:, None] * lateral
    return coords


def _plastic_strain(e: np.ndarray, nodes: np.ndarray, coords: np.ndarray) -> np.ndarray:
    """(T, M) plastic strain proxy per element, accumulated over the steps ``coords``: the
    largest edge stretch plus half the turn of the element normal since ``nodes``, beyond a
    0.2 % yield."""
    steps = len(coords)
    tri = e[:, 3] == e[:, 2]

    def edges_and_normals(p):
        corners = p[e]                                        # (M, 4, 3)
        following = corners[:, [1, 2, 3, 0]]
        following[tri, 2] = corners[tri, 0]                   # triangle edges 0-1, 1-2, 2-0
        d = following - corners
        lengths = np.sqrt(np.einsum("mkc,mkc->mk", d, d))
        return lengths, element_normals(e, p)

    l0, n0 = edges_and_normals(nodes)
    strain = np.zeros((steps, len(e)))
    for i in range(1, steps):
        lengths, n = edges_and_normals(coords[i])
        stretch = np.abs(np.divide(lengths, l0, out=np.ones_like(l0), where=l0 > 0) - 1.0)
        turn = 1.0 - np.clip(np.einsum("mc,mc->m", n, n0), -1.0, 1.0)
        now = np.maximum(stretch.max(axis=1) + 0.5 * turn - 0.002, 0.0)
        strain[i] = np.maximum(strain[i - 1], now)
    return strain
