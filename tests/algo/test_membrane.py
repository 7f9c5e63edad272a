"""Elastic membrane stress of shells (plane-stress Saint Venant–Kirchhoff, pushed forward to
Cauchy): rigid motions, closed forms for stretch and shear, objectivity, the quad average,
degenerate elements, the stress fields for force tubes, and the car deck's trace line."""

import numpy as np
import pytest
from meshes import quad_grid
from scipy.spatial.transform import Rotation

from workbench.algo.forcetube import (
    STRESS_FIELDS,
    force_tube,
    prismatic_tube,
    section_force,
    stress_tensor,
)
from workbench.algo.membrane import membrane_stress, with_membrane_stress
from workbench.scene.mesh import FEMesh

YOUNG, NU = 210000.0, 0.3
K = YOUNG / (1 - NU**2)          # plane-stress modulus
REL = 1e-12


def grid(nx=4, ny=3, hx=10.0, hy=7.0, z=None):
    """A flat (or, with ``z`` (N,), warped) plate of nx × ny quads of hx × hy in the x-y plane,
    node (i, j) at i * (ny + 1) + j."""
    return quad_grid(nx, ny, cell=(hx, hy), z=z, ij=True)


def two_step(nodes, elements, current) -> FEMesh:
    return FEMesh(nodes=nodes, elements=elements, steps=np.stack([nodes, current]))


def expect_all(sigma, tensor, scale):
    """Every element's stress equals ``tensor`` within REL · ``scale``."""
    assert np.abs(sigma - np.asarray(tensor)[None]).max() <= REL * scale


# --------------------------------------------------------------------------- rigid motions
def test_exact_rigid_motion_gives_zero_stress():
    """A rotation with rational entries (from the integer quaternion (1, 2, 3, 4), |q|² = 30)
    of integer coordinates that are multiples of 30, plus an integer shift: the moved
    coordinates are exact, so the stress must vanish to 1e-9 of E·1e-6."""
    a, b, c, d = 1, 2, 3, 4
    rot = np.array([[a*a + b*b - c*c - d*d, 2*(b*c - a*d), 2*(b*d + a*c)],
                    [2*(b*c + a*d), a*a - b*b + c*c - d*d, 2*(c*d - a*b)],
                    [2*(b*d - a*c), 2*(c*d + a*b), a*a - b*b - c*c + d*d]]) / 30.0
    assert np.allclose(rot @ rot.T, np.eye(3), atol=1e-15)
    rng = np.random.default_rng(0)
    nodes, elements = grid(5, 4, 30.0 * 7, 30.0 * 5, z=30.0 * rng.integers(-3, 4, 30))
    elements = np.concatenate([elements, [[0, 1, 6, 6]]])          # and a triangle
    moved = nodes @ rot.T + np.array([1234.0, -567.0, 89.0])
    assert np.array_equal(moved, np.round(moved))                  # exactly representable
    sigma = membrane_stress(two_step(nodes, elements, moved), 1)
    assert np.abs(sigma).max() <= 1e-9 * YOUNG * 1e-6


@pytest.mark.parametrize("seed", range(4))
def test_random_rigid_motion_gives_stress_at_the_rounding_of_the_input(seed):
    """A general rotation cannot be applied exactly in float64: the moved coordinates are off
    by about ε·|x|, a strain of ε·|x|/h for an edge of length h. The stress stays within a
    small multiple of that (here about 1e-15 of E for a car-sized model in mm)."""
    rng = np.random.default_rng(seed)
    nodes, elements = grid(6, 5, 50.0, 40.0, z=rng.uniform(-8, 8, 42))
    nodes = nodes + [800.0, 300.0, 200.0]
    rot = Rotation.random(random_state=seed).as_matrix()
    moved = nodes @ rot.T + rng.uniform(-1000, 1000, 3)
    sigma = membrane_stress(two_step(nodes, elements, moved), 1)
    scale = max(np.abs(nodes).max(), np.abs(moved).max()) / 40.0
    assert np.abs(sigma).max() <= 64 * np.finfo(float).eps * scale * YOUNG
    assert np.abs(sigma).max() <= 1e-12 * YOUNG


# --------------------------------------------------------------------------- closed forms
@pytest.mark.parametrize("lam", [0.7, 0.999, 1.001, 1.3, 2.0])
def test_uniaxial_stretch_with_the_lateral_direction_held(lam):
    """x → λx, y unchanged: E₁₁ = (λ² − 1)/2, E₂₂ = 0; S₁₁ = k E₁₁, S₂₂ = k ν E₁₁
    (k = E/(1 − ν²)); J = λ, so σ_xx = λ² S₁₁/λ = λ k (λ² − 1)/2 and
    σ_yy = S₂₂/λ = k ν (λ² − 1)/(2λ)."""
    nodes, elements = grid()
    moved = nodes * [lam, 1.0, 1.0]
    sigma = membrane_stress(two_step(nodes, elements, moved), 1)
    sxx = lam * K * (lam**2 - 1) / 2
    syy = K * NU * (lam**2 - 1) / (2 * lam)
    expect_all(sigma, np.diag([sxx, syy, 0.0]), abs(sxx))


@pytest.mark.parametrize("lam", [0.8, 1.001, 1.25])
def test_uniaxial_stretch_with_the_lateral_direction_free(lam):
    """x → λx, y → μy with σ_yy = 0: S₂₂ = 0 needs E₂₂ = −ν E₁₁, i.e.
    μ² = 1 − ν(λ² − 1); then S₁₁ = k (E₁₁ + ν E₂₂) = E (λ² − 1)/2 and, with J = λμ,
    σ_xx = λ² S₁₁/(λμ) = λ E (λ² − 1)/(2μ)."""
    mu = np.sqrt(1 - NU * (lam**2 - 1))
    nodes, elements = grid()
    moved = nodes * [lam, mu, 1.0]
    sigma = membrane_stress(two_step(nodes, elements, moved), 1)
    sxx = lam * YOUNG * (lam**2 - 1) / (2 * mu)
    expect_all(sigma, np.diag([sxx, 0.0, 0.0]), abs(sxx))


@pytest.mark.parametrize("gamma", [1e-3, 0.2, -0.5])
def test_simple_shear(gamma):
    """x → x + γy: F = [[1, γ], [0, 1]], J = 1, E = [[0, γ/2], [γ/2, γ²/2]], tr E = γ²/2;
    S₁₁ = k ν γ²/2, S₂₂ = k γ²/2, S₁₂ = k (1 − ν) γ/2 = G γ; σ = F S Fᵀ:
    σ_xx = S₁₁ + 2γ S₁₂ + γ² S₂₂, σ_xy = S₁₂ + γ S₂₂, σ_yy = S₂₂."""
    nodes, elements = grid()
    moved = nodes + gamma * nodes[:, 1:2] * [1.0, 0.0, 0.0]
    sigma = membrane_stress(two_step(nodes, elements, moved), 1)
    s11, s22, s12 = K * NU * gamma**2 / 2, K * gamma**2 / 2, K * (1 - NU) * gamma / 2
    expected = np.zeros((3, 3))
    expected[0, 0] = s11 + 2 * gamma * s12 + gamma**2 * s22
    expected[1, 1] = s22
    expected[0, 1] = expected[1, 0] = s12 + gamma * s22
    expect_all(sigma, expected, np.abs(expected).max())
    if abs(gamma) < 1e-2:                                   # small strain: τ = G γ
        assert sigma[0, 0, 1] == pytest.approx(YOUNG / (2 * (1 + NU)) * gamma, rel=2 * abs(gamma))


@pytest.mark.parametrize("lam", [1.001, 1.2])
def test_pure_shear(lam):
    """Stretch λ along (1, 1)/√2 and 1/λ along (−1, 1)/√2 (J = 1). In those axes
    E₁ = (λ² − 1)/2, E₂ = (λ⁻² − 1)/2, S_i = k[(1 − ν) E_i + ν(E₁ + E₂)], σ_i = λ_i² S_i; in x-y:
    σ_xx = σ_yy = (σ₁ + σ₂)/2, σ_xy = (σ₁ − σ₂)/2."""
    q = np.array([[1.0, -1.0], [1.0, 1.0]]) / np.sqrt(2)     # columns: the principal axes
    f2 = q @ np.diag([lam, 1 / lam]) @ q.T
    nodes, elements = grid()
    moved = nodes.copy()
    moved[:, :2] = nodes[:, :2] @ f2.T
    sigma = membrane_stress(two_step(nodes, elements, moved), 1)
    e1, e2 = (lam**2 - 1) / 2, (lam**-2 - 1) / 2
    s1 = lam**2 * K * ((1 - NU) * e1 + NU * (e1 + e2))
    s2 = lam**-2 * K * ((1 - NU) * e2 + NU * (e1 + e2))
    expected = np.zeros((3, 3))
    expected[0, 0] = expected[1, 1] = (s1 + s2) / 2
    expected[0, 1] = expected[1, 0] = (s1 - s2) / 2
    expect_all(sigma, expected, np.abs(expected).max())


# --------------------------------------------------------------------------- objectivity
def deformed_plate(seed):
    rng = np.random.default_rng(seed)
    nodes, elements = grid(5, 4, 20.0, 15.0, z=rng.uniform(-3, 3, 30))
    elements = np.concatenate([elements, [[0, 1, 5, 5], [24, 25, 29, 29]]])
    current = nodes * [1.1, 0.95, 1.0] + rng.uniform(-2, 2, nodes.shape)
    return nodes, elements, current


@pytest.mark.parametrize("seed", range(3))
def test_a_rotated_copy_gives_the_rotated_tensor(seed):
    nodes, elements, current = deformed_plate(seed)
    sigma = membrane_stress(two_step(nodes, elements, current), 1)
    scale = np.abs(sigma).max()
    assert scale > 1e3
    rot = Rotation.random(random_state=100 + seed).as_matrix()
    expected = rot @ sigma @ rot.T
    shift = np.array([300.0, -20.0, 55.0])
    # the whole problem rotated (reference and current) …
    both = membrane_stress(two_step(nodes @ rot.T + shift, elements, current @ rot.T - shift), 1)
    assert np.abs(both - expected).max() <= 1e-9 * scale
    # … and only the current configuration rotated (objectivity of the push-forward)
    current_only = membrane_stress(two_step(nodes, elements, current @ rot.T + shift), 1)
    assert np.abs(current_only - expected).max() <= 1e-9 * scale


def test_the_stress_lies_in_the_current_tangent_plane():
    nodes, elements, current = deformed_plate(7)
    sigma = membrane_stress(two_step(nodes, elements, current), 1)
    assert np.array_equal(sigma, np.swapaxes(sigma, 1, 2))
    x = current[elements]
    normal = np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0])
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    tri = elements[:, 3] == elements[:, 2]                      # flat: one normal
    traction = np.einsum("mij,mj->mi", sigma[tri], normal[tri])
    assert np.abs(traction).max() <= 1e-12 * np.abs(sigma).max()


def test_a_quad_is_the_area_weighted_mean_of_its_two_triangles():
    nodes, elements, current = deformed_plate(3)
    quads = elements[elements[:, 3] != elements[:, 2]]
    halves = np.concatenate([quads[:, [0, 1, 2, 2]], quads[:, [0, 2, 3, 3]]])
    sq = membrane_stress(two_step(nodes, quads, current), 1)
    st = membrane_stress(two_step(nodes, halves, current), 1)
    x = current[halves]
    area = np.linalg.norm(np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0]), axis=1)
    m = len(quads)
    w1, w2 = area[:m, None, None], area[m:, None, None]
    mean = (w1 * st[:m] + w2 * st[m:]) / (w1 + w2)
    assert np.abs(sq - mean).max() <= 1e-12 * np.abs(sq).max()
    assert np.abs(st[:m] - st[m:]).max() > 1e-3 * np.abs(sq).max()   # the halves differ


# --------------------------------------------------------------------------- edge cases
def test_degenerate_elements_get_zeros_and_leave_the_others_alone():
    nodes, elements = grid(2, 1)           # elements [0, 2, 3, 1] and [2, 4, 5, 3]
    nodes = np.concatenate([nodes, [[0.0, 0, 50], [10.0, 0, 50], [20.0, 0, 50]]])
    elements = np.concatenate([elements, [[6, 6, 6, 6],            # a point
                                          [6, 7, 8, 8]]])          # collinear nodes
    moved = nodes * [1.2, 1.1, 1.0]
    moved[1] = 0.5 * (moved[0] + moved[3])   # element 0's triangle (0, 3, 1) collapses
    sigma = membrane_stress(two_step(nodes, elements, moved), 1)
    assert np.isfinite(sigma).all()
    assert np.array_equal(sigma[2:], np.zeros((2, 3, 3)))
    # element 0 is its other triangle (0, 2, 3) alone; element 1 the plain stretch
    first = membrane_stress(two_step(nodes, np.array([[0, 2, 3, 3]]), moved), 1)
    assert np.array_equal(sigma[0], first[0]) and np.abs(first).max() > 1e3
    stretch = membrane_stress(two_step(nodes, elements[1:2], nodes * [1.2, 1.1, 1.0]), 1)
    assert np.array_equal(sigma[1], stretch[0])
    flat = nodes.copy()
    flat[:, 1] = 0.0                                               # every element collapses
    assert np.array_equal(membrane_stress(two_step(nodes, elements, flat), 1),
                          np.zeros((4, 3, 3)))


def test_refusals():
    nodes, elements = grid()
    bad = nodes.copy()
    bad[3, 1] = np.nan
    mesh = two_step(nodes, elements, bad)
    with pytest.raises(ValueError, match="non-finite coordinates at step 1"):
        membrane_stress(mesh, 1)
    with pytest.raises(ValueError, match="non-finite"):
        membrane_stress(mesh, 0, reference_step=1)
    with pytest.raises(ValueError, match="non-finite"):
        with_membrane_stress(mesh)
    good = two_step(nodes, elements, nodes * 1.1)
    for kwargs, message in (({"young": 0.0}, "young"), ({"young": np.inf}, "young"),
                            ({"poisson": 0.6}, "poisson"), ({"poisson": -1.0}, "poisson"),
                            ({"reference_step": 2}, "out of range")):
        with pytest.raises(ValueError, match=message):
            membrane_stress(good, 1, **kwargs)
    with pytest.raises(ValueError, match="out of range"):
        membrane_stress(good, -1)
    with pytest.raises(ValueError, match="integer"):
        membrane_stress(good, 0.5)


# --------------------------------------------------------------------------- mesh fields
def test_with_membrane_stress_stores_every_step_in_the_force_tube_fields():
    nodes, elements, current = deformed_plate(5)
    steps = np.stack([nodes, 0.5 * (nodes + current), current])
    mesh = FEMesh(nodes=nodes, elements=elements, steps=steps,
                  element_fields={"thickness": np.full(len(elements), 1.5),
                                  "stress_xx": np.ones(len(elements))})
    out = with_membrane_stress(mesh, poisson=0.25)
    assert out is not mesh and out.n_steps == 3
    assert np.array_equal(mesh.element_fields["stress_xx"], np.ones(len(elements)))
    assert out.element_fields["thickness"] is mesh.element_fields["thickness"]
    for name in STRESS_FIELDS:
        assert out.element_fields[name].shape == (3, len(elements))
    for step in range(3):
        assert np.array_equal(stress_tensor(out, step),
                              membrane_stress(mesh, step, poisson=0.25))
    assert np.array_equal(stress_tensor(out, 0), np.zeros((len(elements), 3, 3)))
    shifted = with_membrane_stress(mesh, reference_step=2)
    assert np.array_equal(stress_tensor(shifted, 2), np.zeros((len(elements), 3, 3)))
    static = with_membrane_stress(FEMesh(nodes=nodes, elements=elements))
    assert static.element_fields["stress_zx"].shape == (len(elements),)
    assert not np.any([static.element_fields[name] for name in STRESS_FIELDS])


@pytest.mark.parametrize("sides, lam", [(3, 1.05), (8, 1.2), (13, 0.9)])
def test_a_stretched_prismatic_tube_carries_sigma_t_perimeter(sides, lam):
    """Each face is a flat quad stretched by λ along the axis with its width held, so
    σ_axial = λ k (λ² − 1)/2 (the held-lateral closed form) and the axial force through a
    cross-section is σ_axial · t · perimeter (the perimeter does not change). The held width
    also brings a hoop stress k ν (λ² − 1)/(2λ); it adds nothing across a cross-section, but
    an oblique cut crosses each face at a slant and picks up some of it sideways, so there
    only the force's axial (x) component is σ_axial · t · perimeter."""
    t, radius = 1.7, 12.0
    tube, _ = prismatic_tube(sides, length=120.0, radius=radius, thickness=t, segments=12,
                             steps=2, stretch=lam - 1)
    mesh = with_membrane_stress(tube)
    perimeter = sides * 2 * radius * np.sin(np.pi / sides)
    sigma_axial = lam * K * (lam**2 - 1) / 2
    exact = sigma_axial * t * perimeter
    stress = stress_tensor(mesh, 1)
    assert np.abs(stress[:, 0, 0] - sigma_axial).max() <= REL * abs(sigma_axial)
    hoop = np.einsum("mii->m", stress) - stress[:, 0, 0]
    assert np.abs(hoop - K * NU * (lam**2 - 1) / (2 * lam)).max() <= REL * abs(sigma_axial)
    args = (mesh.coordinates(1), mesh.elements, mesh.element_field("thickness", 1), stress)
    for x, sign in ((55.0 * lam, 1.0), (72.0 * lam, -1.0)):
        f = section_force(*args, [x, 0, 0], [sign, 0, 0])
        assert np.abs(f - sign * exact * np.array([1.0, 0, 0])).max() <= 1e-9 * abs(exact)
        assert abs(f[0] * sign - exact) <= 1e-9 * abs(exact)      # the axial force
    oblique = section_force(*args, [31.0 * lam, 0, 0], [-1.0, 0.2, 0.1])
    assert abs(oblique[0] + exact) <= 1e-9 * abs(exact)
    result = force_tube(mesh, [[5.0, 0, 0], [60.0, 0, 0], [115.0, 0, 0]])
    assert np.array_equal(result.axial[0], np.zeros(result.n_planes))
    assert np.abs(result.axial[1] - exact).max() <= 1e-9 * abs(exact)


# --------------------------------------------------------------------------- the car deck
def test_the_car_trace_line_follows_a_front_rail(car):
    from workbench.scene.car_views import (
        car_barrier_parts,
        car_selection_radius,
        car_trace_line,
        longitudinal_members,
    )
    members = longitudinal_members(car)
    assert [m.part for m in members] == [5, 5, 6, 6]
    points, parts = car_trace_line(car)
    assert parts == (5, 6)
    assert np.allclose(points[:, 0], [112.5, 1016.0, 4318.0], atol=0.1)
    assert np.allclose(points[:, 1:], [209.7, 42.5], atol=0.1)
    other, _ = car_trace_line(car, side="+y")
    assert np.allclose(other[:, 1], 1187.3, atol=0.1)
    assert car_selection_radius(car) == pytest.approx((1187.3 - 209.7) / 2, abs=0.2)
    assert car_barrier_parts(car) == (8,)
    with pytest.raises(ValueError, match="side"):
        car_trace_line(car, side="x")


@pytest.mark.parametrize("still", [False, True])
def test_force_tubes_on_the_crushed_car(car, still):
    from workbench.scene.car_views import car_barrier_parts, car_trace_line
    from workbench.scene.generators import crash_sequence
    crash = crash_sequence(car, steps=8, still_parts=car_barrier_parts(car) if still else ())
    points, parts = car_trace_line(car)
    tube = force_tube(with_membrane_stress(crash), points, parts=parts)
    assert np.isfinite(tube.axial).all()
    assert np.array_equal(tube.axial[0], np.zeros(tube.n_planes))
    assert (tube.crossed >= 16).all()                     # both rails' 2 × 8 faces, or more
    peak = np.abs(tube.axial).max(axis=1)
    assert peak[-1] > 1e6                                 # N: well beyond rounding
    assert np.all(np.abs(np.diff(tube.axial[2:], axis=0)).max(axis=1) > 1e3)  # it changes
    assert tube.axial[2].min() < 0                        # the crush starts in compression


def test_yield_cap_scales_only_the_tensors_above_it():
    from workbench.algo.forcetube import prismatic_tube
    from workbench.algo.membrane import membrane_stress, von_mises

    mesh, _ = prismatic_tube(8, 100.0, 20.0, 2.0, 1.0, 4, steps=1)
    stretched = mesh.nodes.copy()
    stretched[:, 0] *= 1.01  # 1 % axial strain: about 2 100 MPa elastic
    moved = type(mesh)(nodes=mesh.nodes, elements=mesh.elements, parts=mesh.parts,
                       steps=np.stack([mesh.nodes, stretched]))
    free = membrane_stress(moved, 1)
    capped = membrane_stress(moved, 1, yield_stress=300.0)
    assert von_mises(free).min() > 1000.0
    assert np.allclose(von_mises(capped), 300.0, rtol=1e-12)
    ratio = capped / np.where(free == 0, 1, free)
    assert np.allclose(ratio[free != 0], 300.0 / von_mises(free)[0], rtol=1e-12)
    assert np.array_equal(membrane_stress(moved, 1, yield_stress=1e9), free)
    with pytest.raises(ValueError, match="yield_stress"):
        membrane_stress(moved, 1, yield_stress=-1.0)
