"""Elastic membrane stress of shell elements from their deformation, for section forces on
models whose results carry no stresses (a synthetic crash sequence, say).

:func:`membrane_stress` gives, for every shell element, the plane-stress Cauchy stress of a
Saint Venant–Kirchhoff membrane deformed from the geometry of ``reference_step`` to that of
``step``; :func:`with_membrane_stress` stores it, for every step, in the element fields
``stress_xx`` … ``stress_zx`` that :func:`~workbench.algo.forcetube.force_tube` reads.

**Kinematics, per triangle.** Quads are split into the triangles (0, 1, 2) and (0, 2, 3), as
:mod:`~workbench.algo.forcetube` splits them; a triangle element (third node repeated) is
its first triangle. With reference edges A₁ = X₁ − X₀, A₂ = X₂ − X₀ and current edges
a₁, a₂, the reference triangle gets the orthonormal in-plane frame ``e₁ = A₁/|A₁|``,
e₂ = ν̂ × e₁ (ν̂ the unit reference normal), in which its edges are the columns of

    ``D = [[|A₁|, A₂·e₁], [0, A₂·e₂]]``.

The in-plane deformation gradient (3 × 2, from the reference frame to the current tangent
plane, in global coordinates) is F = [a₁ a₂] D⁻¹ — uniform over the triangle, exact for
linear interpolation. The Green–Lagrange strain E = ½(FᵀF − I) is computed as
E = ½ D⁻ᵀ (g − G) D⁻¹ from the difference of the current and reference Gram matrices of the
edges (g_ij = a_i·a_j, G_ij = A_i·A_j) so that a rigid motion gives a strain at the level of
the coordinates' rounding.

**Material.** Plane-stress Saint Venant–Kirchhoff with Young's modulus Y and Poisson's
ratio ν, second Piola–Kirchhoff stress in the reference frame

    S = Y/(1 − ν²) · [(1 − ν) E + ν tr(E) I]        (2 × 2),

i.e. plane-stress Hooke's law applied to the Green–Lagrange strain (S₁₁ = Y/(1−ν²)(E₁₁ +
νE₂₂), S₁₂ = Y/(1+ν) E₁₂). It is elastic at any strain: there is no yield, so the stresses of
a large deformation far exceed a real metal's.

**Push-forward.** The Cauchy stress is σ = F S Fᵀ / J, a 3 × 3 tensor in global coordinates
whose components along the current normal are zero (F maps into the tangent plane). **The
thickness is assumed unchanged**, so the volume ratio J is the area ratio of the triangle,
``|a₁ × a₂| / |A₁ × A₂|``, and σ · t (t the undeformed thickness) is the force per unit current
length of a cut, as :func:`~workbench.algo.forcetube.section_force` integrates it. Units: the
modulus' (N/mm² = MPa for the default steel values and a model in mm).

**Per element.** The element's stress is the mean of its triangles' Cauchy stresses weighted
by their current areas (the area-average of σ over the current element). A triangle is
degenerate when its reference or current doubled area ``|A₁ × A₂|`` is at most 1e-12 times the
square of its longest edge (zero-length edges included); it gets weight 0, and an element
with no non-degenerate triangle gets the zero tensor.

Refused with ValueError: steps out of range, non-finite coordinates at either step, a
non-positive or non-finite modulus, a Poisson's ratio outside (−1, ½].
"""

from __future__ import annotations

import dataclasses

import numpy as np

from ..scene.mesh import FEMesh
from .forcetube import STRESS_FIELDS

# (row, column) of each stress field in the 3 × 3 tensor, in STRESS_FIELDS order
_VOIGT = ((0, 0), (1, 1), (2, 2), (0, 1), (1, 2), (2, 0))
_TRIANGLES = ((0, 1, 2), (0, 2, 3))
_DEGENERATE = 1e-12


def _check_material(young: float, poisson: float) -> tuple[float, float]:
    young, poisson = float(young), float(poisson)
    if not (np.isfinite(young) and young > 0):
        raise ValueError(f"young (Young's modulus) must be positive and finite, got {young}")
    if not (np.isfinite(poisson) and -1.0 < poisson <= 0.5):
        raise ValueError(f"poisson (Poisson's ratio) must be in (-1, 0.5], got {poisson}")
    return young, poisson


def _edges(x: np.ndarray, elements: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(2, M, 3) edge vectors x₁ − x₀ and x₂ − x₀ of the elements' two triangles."""
    a1 = np.stack([x[elements[:, t[1]]] - x[elements[:, t[0]]] for t in _TRIANGLES])
    a2 = np.stack([x[elements[:, t[2]]] - x[elements[:, t[0]]] for t in _TRIANGLES])
    return a1, a2


def _dot(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    return np.einsum("...i,...i->...", u, v)


def _doubled_area(a1: np.ndarray, a2: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(|a₁ × a₂|, whether the triangle is non-degenerate) per triangle."""
    cross = np.linalg.norm(np.cross(a1, a2), axis=-1)
    longest = np.maximum(np.maximum(_dot(a1, a1), _dot(a2, a2)), _dot(a2 - a1, a2 - a1))
    return cross, (cross > _DEGENERATE * longest) & (longest > 0)


def _membrane(ref: np.ndarray, cur: np.ndarray, elements: np.ndarray, young: float,
              poisson: float) -> np.ndarray:
    """(M, 3, 3) element Cauchy stresses for reference coordinates ``ref`` and current ``cur``."""
    A1, A2 = _edges(ref, elements)
    a1, a2 = _edges(cur, elements)
    area0, ok0 = _doubled_area(A1, A2)
    area, ok1 = _doubled_area(a1, a2)
    ok = ok0 & ok1
    safe0 = np.where(ok, area0, 1.0)

    # reference in-plane frame and edge matrix D = [[l, p], [0, h]] (upper triangular)
    length = np.sqrt(_dot(A1, A1))
    length = np.where(ok, length, 1.0)
    e1 = A1 / length[..., None]
    p = _dot(A2, e1)
    h = safe0 / length                           # A₂·e₂ = |A₁ × A₂| / |A₁|
    # D⁻¹ = [[1/l, −p/(l h)], [0, 1/h]]
    inv = np.zeros(A1.shape[:2] + (2, 2))
    inv[..., 0, 0] = 1.0 / length
    inv[..., 0, 1] = -p / (length * h)
    inv[..., 1, 1] = 1.0 / h

    # Green–Lagrange strain from the change of the edges' Gram matrix
    dg = np.empty_like(inv)
    dg[..., 0, 0] = _dot(a1, a1) - _dot(A1, A1)
    dg[..., 1, 1] = _dot(a2, a2) - _dot(A2, A2)
    dg[..., 0, 1] = dg[..., 1, 0] = _dot(a1, a2) - _dot(A1, A2)
    strain = 0.5 * np.einsum("...ki,...kl,...lj->...ij", inv, dg, inv)

    # plane-stress Saint Venant–Kirchhoff second Piola–Kirchhoff stress
    k = young / (1.0 - poisson * poisson)
    trace = strain[..., 0, 0] + strain[..., 1, 1]
    pk2 = k * (1.0 - poisson) * strain
    pk2[..., 0, 0] += k * poisson * trace
    pk2[..., 1, 1] += k * poisson * trace

    # push forward: σ = F S Fᵀ / J with F = [a₁ a₂] D⁻¹ (3 × 2), J the area ratio
    edges = np.stack([a1, a2], axis=-1)                           # (2, M, 3, 2)
    grad = np.einsum("...ik,...kj->...ij", edges, inv)            # (2, M, 3, 2)
    ratio = np.where(ok, area, 1.0) / safe0
    cauchy = np.einsum("...ik,...kl,...jl->...ij", grad, pk2, grad) / ratio[..., None, None]

    # current-area weighted mean over the element's triangles
    weight = np.where(ok, area, 0.0)
    total = weight.sum(axis=0)
    out = np.einsum("tm,tmij->mij", weight, np.where(ok[..., None, None], cauchy, 0.0))
    has = total > 0
    out[has] /= total[has, None, None]
    out[~has] = 0.0
    return 0.5 * (out + np.swapaxes(out, 1, 2))


def membrane_stress(mesh: FEMesh, step: int, *, reference_step: int = 0,
                    young: float = 210000.0, poisson: float = 0.3,
                    yield_stress: float | None = None) -> np.ndarray:
    """(M, 3, 3) float64 Cauchy stress of each shell element of ``mesh`` at ``step``, for the
    elastic membrane (plane-stress Saint Venant–Kirchhoff) deformation from the geometry of
    ``reference_step`` (stress-free) — see the module notes for the formulas.

    Symmetric tensors in global coordinates with no component along the element's current
    normal, in the units of ``young`` (MPa by default: steel, E = 210 000 N/mm², ν = 0.3, for a
    model in mm). The thickness is assumed unchanged by the deformation. Degenerate elements
    (no triangle with a non-zero area at both steps) get zeros. With ``yield_stress`` (same
    units), a tensor whose von Mises stress exceeds it is scaled down to it: a cap that keeps
    folded sheet metal at plausible stresses, not a plasticity model (no history, no
    hardening).

    Refused (ValueError): ``step`` or ``reference_step`` out of range, non-finite coordinates at
    either step, ``young`` not positive and finite, ``poisson`` outside (−1, ½], a
    ``yield_stress`` that is not positive and finite.
    """
    young, poisson = _check_material(young, poisson)
    step = mesh.step_index(step)
    reference_step = mesh.step_index(reference_step, "reference_step")
    ref = mesh.finite_coordinates(reference_step)
    cur = ref if step == reference_step else mesh.finite_coordinates(step)
    return _capped(_membrane(ref, cur, mesh.elements.astype(np.int64), young, poisson),
                   _check_yield(yield_stress))


def _check_yield(yield_stress):
    if yield_stress is None:
        return None
    value = float(yield_stress)
    if not (np.isfinite(value) and value > 0):
        raise ValueError(f"yield_stress must be positive and finite, got {yield_stress}")
    return value


def von_mises(sigma: np.ndarray) -> np.ndarray:
    """(M,) von Mises stress of (M, 3, 3) symmetric tensors."""
    s = np.asarray(sigma, np.float64)
    dev = s - np.trace(s, axis1=1, axis2=2)[:, None, None] * np.eye(3) / 3.0
    return np.sqrt(1.5 * np.einsum("kij,kij->k", dev, dev))


def _capped(sigma: np.ndarray, yield_stress) -> np.ndarray:
    if yield_stress is None:
        return sigma
    vm = von_mises(sigma)
    scale = np.where(vm > yield_stress, yield_stress / np.where(vm > 0, vm, 1.0), 1.0)
    return sigma * scale[:, None, None]


def with_membrane_stress(mesh: FEMesh, *, reference_step: int = 0, young: float = 210000.0,
                         poisson: float = 0.3, yield_stress: float | None = None) -> FEMesh:
    """A copy of ``mesh`` with the element fields ``stress_xx``, ``stress_yy``, ``stress_zz``,
    ``stress_xy``, ``stress_yz``, ``stress_zx`` (:data:`~workbench.algo.forcetube.STRESS_FIELDS`)
    holding :func:`membrane_stress` of every step — (T, M) for a mesh with T time steps, (M,)
    (all zero) for a static one — so that :func:`~workbench.algo.forcetube.force_tube` reads
    them. Stress fields the mesh already has are replaced; everything else (topology, steps,
    other fields, ids) is kept and shared with ``mesh``. ``yield_stress`` caps each tensor as in
    :func:`membrane_stress`. Refusals as :func:`membrane_stress`.
    """
    young, poisson = _check_material(young, poisson)
    yield_stress = _check_yield(yield_stress)
    reference_step = mesh.step_index(reference_step, "reference_step")
    ref = mesh.finite_coordinates(reference_step)
    elements = mesh.elements.astype(np.int64)
    values = np.empty((mesh.n_steps, len(STRESS_FIELDS), mesh.n_elements))
    for step in range(mesh.n_steps):
        cur = ref if step == reference_step else mesh.finite_coordinates(step)
        sigma = _capped(_membrane(ref, cur, elements, young, poisson), yield_stress)
        for c, (i, j) in enumerate(_VOIGT):
            values[step, c] = sigma[:, i, j]
    fields = dict(mesh.element_fields)
    for c, name in enumerate(STRESS_FIELDS):
        fields[name] = values[:, c].copy() if mesh.steps is not None else values[0, c].copy()
    return dataclasses.replace(mesh, node_fields=dict(mesh.node_fields), element_fields=fields,
                               part_names=dict(mesh.part_names))
