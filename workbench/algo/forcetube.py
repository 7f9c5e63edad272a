"""Force tubes (crash2000, §4.2 and Fig. 7): how much force a structure carries along a trace
line, per section plane and time step, drawn as a tube whose rings grow and colour with it.

The engineer picks two or more **control points** (the trace line, model units). Each segment
carries section planes equally spaced along it and orthogonal to it; near each joint the
normals are blended between the two segments' directions (:func:`section_planes`). For every
plane the shell elements it cuts are found (by default with a vectorised test of the nodes'
signed distances; a bounding-volume hierarchy can be plugged in as ``cut``) and the **section
force** through the plane is integrated (:func:`section_force`). :func:`force_tube` does this
for every plane and step, with the control points following the deformation;
:func:`tube_mesh` turns one step (or all) into an :class:`~workbench.scene.mesh.FEMesh` tube
with a node field ``"section_force"`` for the colour map, and :func:`with_tube` appends it to
the model.

**The section force.** For a shell element with mid-surface stress tensor σ (3 × 3, global
coordinates, stress units) and thickness t (model units), the force transmitted across a cut
line of the mid-surface is ``t · ∫ σ·m dl``, with m the unit normal of the cut line inside the
element's surface, pointing to the side the plane normal points to. The stress is uniform per
element (one value per shell, as a d3plot stores it), so the integral is ``t · σ · (m L)`` with
L the cut length, and ``m L = c × ν`` for the cut segment c (oriented counter-clockwise about
the triangle normal ν as part of the boundary of the triangle's negative part). Quads are
split into the triangles (0, 1, 2) and (0, 2, 3); a triangle element (third node repeated)
is its first triangle. The cut is exact in float64 (no sampling): the crossing points of the
edges are the linear interpolation of the nodes by their signed distances. The result is the
force that the material on the positive side of the plane exerts on the material on the
negative side: a structure in tension along the normal gives a positive **axial force**
(the force's component along the unit normal); the axial force does not depend on which way
the normal points, the force vector flips with it.

**Nodes on the plane (the tie rule).** Every node is classified once per plane by its signed
distance s = (x − p)·n: negative (s < 0) or not (s ≥ 0; a node exactly on the plane counts
as positive). An element contributes the cut of its negative part; hence

* an element whose nodes are all negative, or all non-negative, contributes nothing;
* an element touching the plane only at a node contributes nothing (either side);
* an edge lying in the plane is counted exactly once, by the element on the negative side
  (the element on the positive side touches the plane along that edge and contributes
  nothing); an element lying in the plane contributes nothing.

Because the classification is per node, neighbouring elements always agree, so a closed
cross-section is cut along one closed line whatever nodes happen to lie on the plane.

**How this differs from the paper.** crash2000 accumulates the *nodal* forces of the vertices
on the normal side of the plane that belong to elements with vertices on the other side.
A d3plot holds element stresses, not nodal internal forces, so here the traction of each cut
element's membrane stress is integrated across the cut instead. For a uniform stress the
two agree; on a coarse mesh with varying stress the paper's sum depends on how the elements
straddle the plane, this integral on the stress per element.

Refused with ValueError (one clear message each): fewer than two control points, non-finite
control points or coordinates, a zero-length segment, a trace line that turns straight back
on itself, a zero plane normal, missing stress or thickness fields, bad shapes.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from ..scene.mesh import FEMesh

STRESS_FIELDS = ("stress_xx", "stress_yy", "stress_zz", "stress_xy", "stress_yz", "stress_zx")
THICKNESS_FIELD = "thickness"
TUBE_FIELD = "section_force"

# (row, column) of each of the six components in the 3 × 3 tensor, in STRESS_FIELDS order.
_VOIGT = ((0, 0), (1, 1), (2, 2), (0, 1), (1, 2), (2, 0))


# --------------------------------------------------------------------------- section planes
BRUTE_FORCE = "brute force"  # force_tube(cut=BRUTE_FORCE): test every element against a plane


def _control_points(control_points) -> np.ndarray:
    try:
        pts = np.asarray(control_points, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError("control points must be a (K, 3) array of numbers") from None
    if pts.ndim != 2 or pts.shape[1] != 3:
        raise ValueError(f"control points must be (K, 3), got shape {pts.shape}")
    if len(pts) < 2:
        raise ValueError(f"a trace line needs at least 2 control points, got {len(pts)}")
    if not np.isfinite(pts).all():
        bad = np.flatnonzero(~np.isfinite(pts).all(axis=1))
        raise ValueError(f"control points must be finite; not finite: {bad.tolist()}")
    return pts


def _slerp(a: np.ndarray, b: np.ndarray, w: float) -> np.ndarray:
    """Unit vector a fraction ``w`` of the way from unit ``a`` to unit ``b`` along the great
    circle (the angle to ``a`` grows linearly with ``w``)."""
    cos = float(np.clip(a @ b, -1.0, 1.0))
    theta = np.arccos(cos)
    if theta < 1e-12:
        v = (1.0 - w) * a + w * b
    else:
        v = (np.sin((1.0 - w) * theta) * a + np.sin(w * theta) * b) / np.sin(theta)
    return v / np.linalg.norm(v)


def section_planes(control_points, per_segment: int = 8,
                   blend: int = 2) -> tuple[np.ndarray, np.ndarray]:
    """Section planes along the trace line through ``control_points`` (K, 3), K ≥ 2.

    Returns ``(points, normals)``, each (S, 3) float64 with S = (K − 1)·per_segment, in order
    along the line. Segment k (from control point k to k + 1, length L_k) carries
    ``per_segment`` planes at ``P_k + (i + ½)/per_segment · (P_{k+1} − P_k)``, i = 0 …
    per_segment − 1: equally spaced (L_k / per_segment apart), none on a control point, so
    that no plane sits on a joint. Each plane's normal is the unit segment direction d_k,
    except near a joint:

    **Blend.** At the joint between segments k and k + 1 the last ``blend`` planes of segment
    k and the first ``blend`` of segment k + 1 (2·blend planes, numbered q = 0 … 2·blend − 1
    along the line) get the normal ``slerp(d_k, d_{k+1}, (q + 1) / (2·blend + 1))``: spherical
    interpolation, so the normals are unit vectors in the plane of d_k and d_{k+1} and turn from
    d_k to d_{k+1} in 2·blend + 1 equal angular steps (the first step from the last unblended
    plane of segment k, the last onto the first unblended plane of segment k + 1). ``blend = 0``
    keeps every plane orthogonal to its own segment. The two ends of the line are not blended.

    Refused (ValueError): fewer than 2 control points, non-finite ones, a zero-length segment,
    a joint where the line turns straight back (directions opposite: no unique blend),
    ``per_segment`` < 1, ``blend`` < 0 or ``2·blend > per_segment`` (a plane would belong to
    two joints).
    """
    pts = _control_points(control_points)
    if int(per_segment) != per_segment or per_segment < 1:
        raise ValueError(f"per_segment must be an integer ≥ 1, got {per_segment}")
    if int(blend) != blend or blend < 0:
        raise ValueError(f"blend must be an integer ≥ 0, got {blend}")
    n, b = int(per_segment), int(blend)
    if 2 * b > n:
        raise ValueError(f"blend {b} needs per_segment ≥ {2 * b} (got {n}): each joint blends "
                         f"{b} planes on each side")
    seg = np.diff(pts, axis=0)
    length = np.linalg.norm(seg, axis=1)
    if (length == 0).any():
        k = int(np.flatnonzero(length == 0)[0])
        raise ValueError(f"zero-length segment between control points {k} and {k + 1} "
                         f"(both at {pts[k].tolist()})")
    direction = seg / length[:, None]
    cos = np.einsum("ij,ij->i", direction[:-1], direction[1:])
    if (cos <= -1.0 + 1e-12).any():
        k = int(np.flatnonzero(cos <= -1.0 + 1e-12)[0])
        raise ValueError(f"the trace line turns straight back at control point {k + 1}: "
                         f"no unique blend of opposite directions")
    frac = (np.arange(n) + 0.5) / n
    points = (pts[:-1, None, :] + frac[None, :, None] * seg[:, None, :]).reshape(-1, 3)
    normals = np.repeat(direction, n, axis=0)
    for k in range(len(direction) - 1):
        around = [k * n + n - b + i for i in range(b)] + [(k + 1) * n + i for i in range(b)]
        for q, plane in enumerate(around):
            normals[plane] = _slerp(direction[k], direction[k + 1], (q + 1) / (2 * b + 1))
    return points, normals


# --------------------------------------------------------------------------- section force
def _signed(x: np.ndarray, point: np.ndarray, normal: np.ndarray) -> np.ndarray:
    """Signed distances (x − p)·n, element-wise so that a node gets the same value in every
    array it appears in (the classification must not depend on the summation order)."""
    return ((x[..., 0] - point[0]) * normal[0] + (x[..., 1] - point[1]) * normal[1]
            + (x[..., 2] - point[2]) * normal[2])


def _plane(point, normal) -> tuple[np.ndarray, np.ndarray]:
    p = np.asarray(point, dtype=np.float64).reshape(-1)
    n = np.asarray(normal, dtype=np.float64).reshape(-1)
    if p.shape != (3,) or n.shape != (3,):
        raise ValueError(f"plane point and normal must be 3-vectors, got {p.shape} and {n.shape}")
    if not (np.isfinite(p).all() and np.isfinite(n).all()):
        raise ValueError("plane point and normal must be finite")
    length = np.linalg.norm(n)
    if length == 0:
        raise ValueError("plane normal must not be zero")
    return p, n / length


def crossing_elements(coords, elements, point, normal) -> np.ndarray:
    """(C,) int64 indices of the elements the plane crosses: at least one node with signed
    distance < 0 and one ≥ 0 (the tie rule of the module notes; elements that only touch the
    plane from the positive side are not listed). Brute force over all elements, vectorised."""
    p, n = _plane(point, normal)
    s = _signed(np.asarray(coords, dtype=np.float64), p, n)[np.asarray(elements)]
    return np.flatnonzero((s.min(axis=1) < 0) & (s.max(axis=1) >= 0)).astype(np.int64)


def _cut_vectors(x: np.ndarray, s: np.ndarray) -> np.ndarray:
    """(C, 3) Σ over an element's triangles of c × ν̂: the cut length times its in-surface unit
    normal. ``x`` (C, 4, 3) node positions, ``s`` (C, 4) signed distances."""
    total = np.zeros((len(x), 3))
    for tri in ((0, 1, 2), (0, 2, 3)):
        xt, st = x[:, tri], s[:, tri]
        nu = np.cross(xt[:, 1] - xt[:, 0], xt[:, 2] - xt[:, 0])
        area2 = np.linalg.norm(nu, axis=1)
        ok = area2 > 0
        nu[ok] /= area2[ok, None]
        nu[~ok] = 0.0
        neg = st < 0
        cut = np.zeros((len(x), 3))
        for a, b in ((0, 1), (1, 2), (2, 0)):
            mixed = neg[:, a] != neg[:, b]
            if not mixed.any():
                continue
            a_neg = neg[:, a][mixed]
            xa, xb, sa, sb = xt[mixed, a], xt[mixed, b], st[mixed, a], st[mixed, b]
            # canonical order (negative end first) so a shared edge gives one crossing point
            xn = np.where(a_neg[:, None], xa, xb)
            xp = np.where(a_neg[:, None], xb, xa)
            sn = np.where(a_neg, sa, sb)
            sp = np.where(a_neg, sb, sa)
            gap = sp - sn
            crossing = (sp / gap)[:, None] * xn + (-sn / gap)[:, None] * xp
            # entering the negative part (a ≥ 0 → b < 0) ends the cut, leaving it starts it
            sign = np.where(a_neg, -1.0, 1.0)
            cut[mixed] += sign[:, None] * crossing
        total += np.cross(cut, nu)
    return total


def _section(coords, elements, thickness, stress, p, n, candidates) -> tuple[np.ndarray, int]:
    """(force (3,), number of elements crossed) over the ``candidates`` (element indices)."""
    if len(candidates) == 0:
        return np.zeros(3), 0
    conn = elements[candidates]
    x = coords[conn]
    s = _signed(x, p, n)
    w = _cut_vectors(x, s)
    crossed = (w != 0).any(axis=1)
    if not crossed.any():
        return np.zeros(3), 0
    idx = candidates[crossed]
    force = np.einsum("e,eij,ej->i", thickness[idx], stress[idx], w[crossed])
    return force, int(crossed.sum())


def _check_arrays(coords, elements, thickness, stress):
    coords = np.asarray(coords, dtype=np.float64)
    elements = np.asarray(elements)
    thickness = np.asarray(thickness, dtype=np.float64)
    stress = np.asarray(stress, dtype=np.float64)
    if coords.ndim != 2 or coords.shape[1] != 3:
        raise ValueError(f"coords must be (N, 3), got {coords.shape}")
    if elements.ndim != 2 or elements.shape[1] != 4 or elements.dtype.kind not in "iu":
        raise ValueError(f"elements must be (M, 4) integers, got {elements.shape} "
                         f"{elements.dtype}")
    m = len(elements)
    if thickness.shape != (m,):
        raise ValueError(f"thickness must be ({m},), got {thickness.shape}")
    if stress.shape != (m, 3, 3):
        raise ValueError(f"stress must be ({m}, 3, 3), got {stress.shape}")
    if m and (elements.min() < 0 or elements.max() >= len(coords)):
        raise ValueError("elements reference nodes outside coords")
    if not np.isfinite(coords).all():
        bad = np.flatnonzero(~np.isfinite(coords).all(axis=1))
        raise ValueError(f"coords must be finite; not finite at nodes {bad[:5].tolist()}")
    return coords, elements.astype(np.int64, copy=False), thickness, stress


def _candidates(found, m: int) -> np.ndarray:
    idx = np.asarray(found)
    if idx.dtype == bool:
        if idx.shape != (m,):
            raise ValueError(f"cut returned a mask of shape {idx.shape}, expected ({m},)")
        return np.flatnonzero(idx)
    idx = idx.reshape(-1)
    if idx.size and idx.dtype.kind not in "iu":
        raise ValueError(f"cut must return element indices (integers), got {idx.dtype}")
    idx = np.unique(idx.astype(np.int64))
    if idx.size and (idx[0] < 0 or idx[-1] >= m):
        raise ValueError(f"cut returned element indices outside 0..{m - 1}")
    return idx


def section_force(coords, elements, thickness, stress, point, normal,
                  cut: Callable | None = None) -> np.ndarray:
    """(3,) float64 force transmitted through the plane (``point``, ``normal``) by the shells
    it cuts: Σ t_e · σ_e · (m L)_e over the crossed elements (see the module notes), in
    thickness × stress × length units (N for mm and MPa). It is the force the material on the
    side ``normal`` points to exerts on the other side; its component along the unit normal
    is the axial force (positive in tension).

    ``coords`` (N, 3) node positions, ``elements`` (M, 4) node indices (a triangle repeats its
    third node), ``thickness`` (M,) shell thicknesses, ``stress`` (M, 3, 3) symmetric
    mid-surface stress tensors in global coordinates. ``normal`` need not be unit length.

    ``cut(point, normal)`` may return the candidate element indices (a bounding-volume
    hierarchy's plane query, or a bool mask of length M); any superset of the crossed
    elements gives the same force (elements that do not cross contribute exactly zero,
    duplicates are dropped). By default all elements are tested (:func:`crossing_elements`).
    A plane that cuts nothing gives a zero vector. A crossed element with a non-finite stress
    or thickness (a rigid shell in a d3plot) makes the force NaN.

    Refused (ValueError): bad shapes, node indices out of range, non-finite coordinates, a
    non-finite plane or a zero normal.
    """
    coords, elements, thickness, stress = _check_arrays(coords, elements, thickness, stress)
    p, n = _plane(point, normal)
    if cut is None:
        idx = crossing_elements(coords, elements, p, n)
    else:
        idx = _candidates(cut(p, n), len(elements))
    return _section(coords, elements, thickness, stress, p, n, idx)[0]


# --------------------------------------------------------------------------- mesh fields
def _missing(mesh: FEMesh, names: Sequence[str]) -> list[str]:
    return [name for name in names if name not in mesh.element_fields]


def stress_tensor(mesh: FEMesh, step: int | None = None,
                  fields: Sequence[str] = STRESS_FIELDS) -> np.ndarray:
    """(M, 3, 3) float64 symmetric stress tensors of ``step`` from the six element fields
    ``fields`` (xx, yy, zz, xy, yz, zx, in that order; the d3plot reader's
    ``stress_xx`` … ``stress_zx`` by default, global coordinates, stress units).

    Refused (ValueError): fields missing from the mesh (the message lists its element fields),
    or not six names.
    """
    fields = tuple(fields)
    if len(fields) != 6:
        raise ValueError(f"stress fields must name 6 components (xx, yy, zz, xy, yz, zx), "
                         f"got {len(fields)}")
    missing = _missing(mesh, fields)
    if missing:
        raise ValueError(f"{mesh.name} has no stress fields {missing}; its element fields: "
                         f"{sorted(mesh.element_fields)} (a d3plot with shell stresses has "
                         f"{', '.join(STRESS_FIELDS)})")
    out = np.empty((mesh.n_elements, 3, 3))
    for name, (i, j) in zip(fields, _VOIGT):
        values = mesh.element_field(name, step)
        out[:, i, j] = values
        out[:, j, i] = values
    return out


# --------------------------------------------------------------------------- force tube
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
    (:meth:`workbench.algo.hierarchy.ElementHierarchy.cut_by_plane`, as crash2000 does), or,
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
    if steps is None:
        steps = np.arange(mesh.n_steps)
    steps = np.atleast_1d(np.asarray(steps))
    if steps.dtype.kind not in "iu" or steps.ndim != 1 or len(steps) == 0 \
            or steps.min() < 0 or steps.max() >= mesh.n_steps:
        raise ValueError(f"steps must be integers in 0..{mesh.n_steps - 1}, got {steps.tolist()}")
    steps = steps.astype(np.int64)

    base = mesh.coordinates(0)
    used = mesh.used_nodes()
    d2 = ((base[used][None, :, :] - pts[:, None, :]) ** 2).sum(axis=2)
    anchors = used[np.argmin(d2, axis=1)]

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

    n_planes = (len(pts) - 1) * int(per_segment)
    shape = (len(steps), n_planes)
    out_cp = np.empty((len(steps), len(pts), 3))
    out_p, out_n, out_f = (np.empty(shape + (3,)) for _ in range(3))
    crossed = np.zeros(shape, np.int64)
    elements = mesh.elements.astype(np.int64)
    for row, step in enumerate(steps):
        coords = mesh.coordinates(int(step))
        if not np.isfinite(coords).all():
            bad = np.flatnonzero(~np.isfinite(coords).all(axis=1))
            raise ValueError(f"{mesh.name}: non-finite coordinates at step {int(step)}, nodes "
                             f"{bad[:5].tolist()}")
        moved = pts + coords[anchors] - base[anchors]
        points, normals = section_planes(moved, per_segment, blend)
        thickness = mesh.element_field(thickness_field, int(step))
        stress = stress_tensor(mesh, int(step), stress_fields)
        counted = include
        if "alive" in mesh.element_fields:
            counted = include & (mesh.element_field("alive", int(step)) != 0)
        if cut is None:  # the elements a plane cuts, found through a hierarchy of this step
            from .hierarchy import ElementHierarchy

            query = ElementHierarchy(mesh, step=int(step)).cut_by_plane
        else:
            query = None if cut == BRUTE_FORCE else cut(int(step))
        if query is not None and not callable(query):
            raise ValueError("cut(step) must return a callable (point, normal) -> element "
                             "indices")
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


# --------------------------------------------------------------------------- tube geometry
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
    ``part_id`` ("force tube"). The radius maps |axial force| linearly: ``force_range`` (lo, hi)
    to ``radius_range`` (r_lo, r_hi), clipped; by default lo = 0 and hi = the largest finite
    |axial force| over all computed steps (so rings are comparable between steps; all rings
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


# --------------------------------------------------------------------------- synthetic case
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
