"""The force tube itself: section forces of a mesh through the planes of a trace line that
follows the deformation, per plane and time step (see :func:`force_tube`)."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from ...scene.mesh import FEMesh
from .planes import _control_points, section_planes
from .section import (
    STRESS_FIELDS,
    THICKNESS_FIELD,
    _candidates,
    _missing,
    _section,
    crossing_elements,
    stress_tensor,
)

BRUTE_FORCE = "brute force"  # force_tube(cut=BRUTE_FORCE): test every element against a plane


@dataclass(eq=False)
class ForceTube:
    """Section forces along a trace line, per computed step and plane.

    ``steps`` (T,) the mesh steps computed; ``control_points`` (T, K, 3) the trace line at
    each step; ``anchors`` (K,) the node each control point follows; ``points`` and
    ``normals`` (T, S, 3) the section planes (unit normals); ``force`` (T, S, 3) the force
    vector through each plane (:func:`section_force`; force units of the model);
    ``axial`` (T, S) its component along the normal (positive in tension); ``magnitude``
    (T, S) the length of the force vector; ``crossed`` (T, S) how many elements each plane
    cut. ``per_segment`` and ``blend`` are those of :func:`section_planes`.
    """

    steps: np.ndarray
    control_points: np.ndarray
    anchors: np.ndarray
    points: np.ndarray
    normals: np.ndarray
    force: np.ndarray
    axial: np.ndarray
    magnitude: np.ndarray
    crossed: np.ndarray
    per_segment: int
    blend: int
    units: str = "mm"

    @property
    def n_planes(self) -> int:
        return self.points.shape[1]

    def index(self, step: int) -> int:
        """Row of mesh step ``step`` in the arrays; ValueError when it was not computed."""
        rows = np.flatnonzero(self.steps == step)
        if len(rows) == 0:
            raise ValueError(f"step {step} was not computed; computed steps: "
                             f"{self.steps.tolist()}")
        return int(rows[0])


def _polyline_distance(x: np.ndarray, line: np.ndarray) -> np.ndarray:
    """(P,) distance of points ``x`` (P, 3) to the polyline through ``line`` (K, 3)."""
    best = np.full(len(x), np.inf)
    for a, b in zip(line[:-1], line[1:]):
        d = b - a
        t = np.clip(((x - a) @ d) / (d @ d), 0.0, 1.0)
        best = np.minimum(best, np.linalg.norm(x - (a + t[:, None] * d), axis=1))
    return best


def force_tube(mesh: FEMesh, control_points, *, steps=None, per_segment: int = 8,
               blend: int = 2, stress_fields: Sequence[str] = STRESS_FIELDS,
               thickness_field: str = THICKNESS_FIELD, parts=None,
               selection_radius: float | None = None,
               cut: Callable | str | None = None) -> ForceTube:
    """Section forces of ``mesh`` through the planes of the trace line ``control_points``
    (K, 3, model units, positions at step 0) for each of ``steps`` (default: every step).

    The control points follow the deformation: each is attached to its nearest node at step 0
    (among the nodes the elements use) and moves with that node's displacement, so at step k
    it lies at ``c + x_node(k) − x_node(0)``; the planes of each step are
    :func:`section_planes` of the moved points. The stress tensor comes from the six element
    fields ``stress_fields`` (see :func:`stress_tensor`), the thickness from
    ``thickness_field``; both may be static or per step.

    The section planes are unbounded: every counted element a plane crosses contributes,
    however far from the trace line. Elements that count (the paper's pre-selection and
    selection tube): those of the part ids ``parts`` (all when None), whose centroid at step
    0 lies within ``selection_radius`` (model units) of the step-0 trace line (all when None),
    and, where the mesh has an ``"alive"`` field, alive at the step (deleted elements carry
    no force). The others contribute nothing, also when their stress is missing (NaN); a
    counted crossed element with NaN stress makes that plane's force NaN.

    The elements a plane cuts are found through an AABB hierarchy of the step's coordinates
    (:meth:`workbench.algo.nearest.hierarchy.ElementHierarchy.cut_by_plane`, as crash2000 does), or,
    with ``cut=BRUTE_FORCE``, by testing every element; ``cut(step)`` may also return any plane
    query ``(point, normal) -> element indices`` for that step. A trace line that cuts nothing
    yields zero forces.

    Refused (ValueError): the trace-line refusals of :func:`section_planes` (also for a step
    where the moved control points make a zero-length segment), missing stress or thickness
    fields, steps out of range, an empty selection.
    """
    pts = _control_points(control_points)
    section_planes(pts, per_segment, blend)  # refuse a bad trace line before any work
    missing = _missing(mesh, tuple(stress_fields)) + _missing(mesh, (thickness_field,))
    if missing:
        raise ValueError(f"{mesh.name} has no element fields {missing} needed for section "
                         f"forces; its element fields: {sorted(mesh.element_fields)} (a d3plot "
                         f"with shell stresses has {', '.join(STRESS_FIELDS)} and "
                         f"{THICKNESS_FIELD})")
    steps = _checked_steps(mesh, steps)
    base = mesh.coordinates(0)
    used = mesh.used_nodes()
    d2 = ((base[used][None, :, :] - pts[:, None, :]) ** 2).sum(axis=2)
    anchors = used[np.argmin(d2, axis=1)]
    include = _selected_elements(mesh, base, pts, parts, selection_radius)

    n_planes = (len(pts) - 1) * int(per_segment)
    shape = (len(steps), n_planes)
    out_cp = np.empty((len(steps), len(pts), 3))
    out_p, out_n, out_f = (np.empty(shape + (3,)) for _ in range(3))
    crossed = np.zeros(shape, np.int64)
    elements = mesh.elements.astype(np.int64)
    for row, step in enumerate(steps):
        coords = mesh.finite_coordinates(int(step))
        moved = pts + coords[anchors] - base[anchors]
        points, normals = section_planes(moved, per_segment, blend)
        thickness = mesh.element_field(thickness_field, int(step))
        stress = stress_tensor(mesh, int(step), stress_fields)
        counted = include
        if "alive" in mesh.element_fields:
            counted = include & (mesh.element_field("alive", int(step)) != 0)
        query = _plane_query(mesh, int(step), cut)
        for i, (p, n) in enumerate(zip(points, normals)):
            if query is None:
                idx = crossing_elements(coords, elements, p, n)
            else:
                idx = _candidates(query(p, n), mesh.n_elements)
            idx = idx[counted[idx]]
            out_f[row, i], crossed[row, i] = _section(coords, elements, thickness, stress,
                                                      p, n, idx)
        out_cp[row], out_p[row], out_n[row] = moved, points, normals
    axial = np.einsum("tsi,tsi->ts", out_f, out_n)
    return ForceTube(steps=steps, control_points=out_cp, anchors=anchors, points=out_p,
                     normals=out_n, force=out_f, axial=axial,
                     magnitude=np.linalg.norm(out_f, axis=2), crossed=crossed,
                     per_segment=int(per_segment), blend=int(blend), units=mesh.units)


def _checked_steps(mesh: FEMesh, steps) -> np.ndarray:
    """(T,) int64 mesh steps to compute: ``steps``, or every step when None; refused
    (ValueError) unless integers in range."""
    if steps is None:
        steps = np.arange(mesh.n_steps)
    steps = np.atleast_1d(np.asarray(steps))
    if steps.dtype.kind not in "iu" or steps.ndim != 1 or len(steps) == 0 \
            or steps.min() < 0 or steps.max() >= mesh.n_steps:
        raise ValueError(f"steps must be integers in 0..{mesh.n_steps - 1}, got {steps.tolist()}")
    return steps.astype(np.int64)


def _selected_elements(mesh: FEMesh, base: np.ndarray, pts: np.ndarray, parts,
                       selection_radius: float | None) -> np.ndarray:
    """(M,) bool the elements that count: of the part ids ``parts`` (all when None), with the
    centroid at step 0 (``base`` coordinates) within ``selection_radius`` of the trace line
    ``pts`` (all when None); refused (ValueError) when none is or the radius is not positive."""
    include = np.ones(mesh.n_elements, bool)
    if parts is not None:
        include &= np.isin(mesh.parts, np.atleast_1d(np.asarray(parts, dtype=np.int64)))
    if selection_radius is not None:
        if not np.isfinite(selection_radius) or selection_radius <= 0:
            raise ValueError(f"selection_radius must be a positive length, got "
                             f"{selection_radius}")
        centroid = base[mesh.elements].mean(axis=1)
        include &= _polyline_distance(centroid, pts) <= selection_radius
    if not include.any():
        raise ValueError(f"no element of {mesh.name} is selected (parts={parts}, "
                         f"selection_radius={selection_radius})")
    return include


def _plane_query(mesh: FEMesh, step: int, cut) -> Callable | None:
    """The plane query ``(point, normal) -> element indices`` of mesh step ``step`` for
    :func:`force_tube`'s ``cut``: an AABB hierarchy of the step (``cut`` None), the
    caller's ``cut(step)``, or None for brute force (``cut`` :data:`BRUTE_FORCE`)."""
    if cut is None:  # the elements a plane cuts, found through a hierarchy of this step
        from ..nearest.hierarchy import ElementHierarchy

        query = ElementHierarchy(mesh, step=step).cut_by_plane
    else:
        query = None if cut == BRUTE_FORCE else cut(step)
    if query is not None and not callable(query):
        raise ValueError("cut(step) must return a callable (point, normal) -> element "
                         "indices")
    return query
