"""Closed-form elastodynamic fields: Navier's equations by finite differences (and a wrong wave
speed failing them), derivatives against finite differences, the fixed end, radial symmetry and
smoothness of the radial pulse, strain energy against the plane-strain stiffness matrix, and
translation invariance."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from workbench.algo.spacetime.fields import (
    BAR,
    STEEL,
    Material,
    PlaneWave,
    RadialPulse,
    ReflectingWave,
    strain_energy_density,
)

PROPERTY = settings(max_examples=100, deadline=None)
RNG_SEED = 20050601


# --------------------------------------------------------------------------- point sets
def _near_front(field, n: int, rng: np.random.Generator, t_max: float = 6.0):
    """Random (x, y, t) where the pulse is, so residuals are measured where the field is not ~0."""
    t = rng.uniform(0.0, t_max, n)
    if isinstance(field, PlaneWave):
        nx, ny = field.direction
        along = field.material.p_wave_speed * t + rng.uniform(-2.0, 2.0, n) * field.width
        across = rng.uniform(-50.0, 50.0, n)
        x = field.x0[0] + along * nx - across * ny
        y = field.x0[1] + along * ny + across * nx
    elif isinstance(field, ReflectingWave):
        c = field.material.p_wave_speed
        # alternately near the incident and the reflected pulse, inside the bar (x >= wall)
        centre = np.where(rng.random(n) < 0.5, field.s0 - c * t, c * t - field.s0)
        x = field.wall_x + np.abs(centre + rng.uniform(-2.0, 2.0, n) * field.width)
        y = rng.uniform(-10.0, 10.0, n)
    else:
        radius = field.material.p_wave_speed * (t + field.t0) + rng.uniform(-3.0, 3.0, n) * field.a
        phi = rng.uniform(0.0, 2.0 * math.pi, n)
        x = field.centre[0] + np.abs(radius) * np.cos(phi)
        y = field.centre[1] + np.abs(radius) * np.sin(phi)
    return x + field.origin[0], y + field.origin[1], t


FIELDS = [
    PlaneWave(),
    PlaneWave(direction=(0.6, -0.8), x0=(10.0, 5.0), width=3.0),
    ReflectingWave(),
    ReflectingWave(material=STEEL, wall_x=-20.0, s0=15.0, width=4.0),
    RadialPulse(),
    RadialPulse(centre=(5.0, -3.0), a=1.0, t0=1.0),
]
IDS = ["plane", "plane-oblique", "reflecting-bar", "reflecting-steel", "radial", "radial-narrow"]


def _fd_step(field) -> float:
    """Spatial step of the central differences: 1/200 of the pulse width."""
    return (field.a if isinstance(field, RadialPulse) else field.width) / 200.0


def _navier_residual(field, material: Material, x, y, t) -> tuple[np.ndarray, np.ndarray]:
    """ρ ü and (λ+μ)∇(∇·u) + μΔu, both by central differences of the displacement."""
    h = _fd_step(field)
    dt = h / field.material.p_wave_speed
    u = field.displacement

    def d2(dx, dy, dtt):
        return (u(x + dx, y + dy, t + dtt) - 2.0 * u(x, y, t) + u(x - dx, y - dy, t - dtt))

    u_tt = d2(0, 0, dt) / dt**2
    u_xx = d2(h, 0, 0) / h**2
    u_yy = d2(0, h, 0) / h**2
    u_xy = (u(x + h, y + h, t) - u(x + h, y - h, t) - u(x - h, y + h, t)
            + u(x - h, y - h, t)) / (4 * h * h)
    grad_div = np.stack([u_xx[..., 0] + u_xy[..., 1], u_xy[..., 0] + u_yy[..., 1]], axis=-1)
    lap = u_xx + u_yy
    lhs = material.rho * u_tt
    rhs = (material.lam + material.mu) * grad_div + material.mu * lap
    return lhs, rhs


@pytest.mark.parametrize("field", FIELDS, ids=IDS)
def test_navier_equations_hold_and_a_wrong_speed_breaks_them(field):
    rng = np.random.default_rng(RNG_SEED)
    x, y, t = _near_front(field, 300, rng)
    lhs, rhs = _navier_residual(field, field.material, x, y, t)
    scale = np.linalg.norm(lhs)
    assert scale > 0.0
    assert np.linalg.norm(lhs - rhs) / scale < 1e-4
    # the same displacement against a material whose P-wave speed is 1 % off must fail
    m = field.material
    wrong = Material(lam=m.lam * 1.02, mu=m.mu * 1.02, rho=m.rho)
    lhs_w, rhs_w = _navier_residual(field, wrong, x, y, t)
    assert np.linalg.norm(lhs_w - rhs_w) / np.linalg.norm(lhs_w) > 5e-3


@pytest.mark.parametrize("field", FIELDS, ids=IDS)
def test_velocity_and_gradient_agree_with_finite_differences(field):
    rng = np.random.default_rng(RNG_SEED + 1)
    x, y, t = _near_front(field, 300, rng)
    h = _fd_step(field)
    dt = h / field.material.p_wave_speed
    u = field.displacement

    def d1(dx, dy, dtt, step):  # fourth-order central difference
        return (-u(x + 2 * dx, y + 2 * dy, t + 2 * dtt) + 8 * u(x + dx, y + dy, t + dtt)
                - 8 * u(x - dx, y - dy, t - dtt)
                + u(x - 2 * dx, y - 2 * dy, t - 2 * dtt)) / (12 * step)  # fmt: skip

    v_fd = d1(0, 0, dt, dt)
    g_fd = np.stack([d1(h, 0, 0, h), d1(0, h, 0, h)], axis=-1)  # [..., i, j] = ∂u_i/∂x_j
    v = field.velocity(x, y, t)
    g = field.displacement_gradient(x, y, t)
    assert v.shape == (300, 2) and g.shape == (300, 2, 2)
    assert np.abs(v - v_fd).max() <= 1e-6 * np.abs(v).max()
    assert np.abs(g - g_fd).max() <= 1e-6 * np.abs(g).max()
    np.testing.assert_allclose(field.speed(x, y, t), np.hypot(v[:, 0], v[:, 1]), rtol=1e-15)
    np.testing.assert_allclose(field.strain_energy(x, y, t),
                               strain_energy_density(g, field.material), rtol=1e-15)


@pytest.mark.parametrize("field", FIELDS, ids=IDS)
def test_broadcasting_and_float64(field):
    x = np.linspace(-20, 20, 5)[:, None]
    t = np.linspace(0, 3, 4)[None, :]
    u = field.displacement(x, 1.5, t)
    assert u.shape == (5, 4, 2) and u.dtype == np.float64
    assert field.velocity(x, 1.5, t).shape == (5, 4, 2)
    assert field.displacement_gradient(x, 1.5, t).shape == (5, 4, 2, 2)
    assert field.strain_energy(x, 1.5, t).shape == (5, 4)
    np.testing.assert_array_equal(u[2, 3], field.displacement(x[2, 0], 1.5, t[0, 3]))


@pytest.mark.parametrize("field", FIELDS, ids=IDS)
def test_translation_by_origin(field):
    """The field with origin o at x + o equals the field with origin 0 at x (o ≈ 10⁴ element
    sizes)."""
    rng = np.random.default_rng(RNG_SEED + 2)
    o = (12345.678, -9876.54321)
    moved = type(field)(**{**field.__dict__, "origin": o})
    x, y, t = _near_front(field, 200, rng)
    for name in ("displacement", "velocity", "displacement_gradient"):
        a = getattr(field, name)(x, y, t)
        b = getattr(moved, name)(x + o[0], y + o[1], t)
        assert np.abs(a - b).max() <= 1e-9 * np.abs(a).max(), name
    np.testing.assert_allclose(
        moved.front_distance(np.column_stack([x + o[0], y + o[1]]), 1.0),
        field.front_distance(np.column_stack([x, y]), 1.0),
        atol=1e-9,
    )


def test_reflecting_wave_is_fixed_at_the_wall_and_reflects_out_of_phase():
    f = ReflectingWave()
    c = f.material.p_wave_speed
    t = np.linspace(0.0, 4.0 * f.s0 / c, 2001)
    np.testing.assert_array_equal(f.displacement(f.wall_x, 7.0, t), 0.0)
    np.testing.assert_array_equal(f.velocity(f.wall_x, -3.0, t), 0.0)
    # not trivially zero: the pulse does reach the wall, where the strain doubles
    strain_wall = f.displacement_gradient(f.wall_x, 0.0, t)[:, 0, 0]
    peak = f.amplitude * math.sqrt(2.0) / f.width * math.exp(-0.5)  # A max|f'|
    assert abs(strain_wall).max() == pytest.approx(2.0 * peak, rel=1e-3)
    # long after the reflection: a single inverted pulse moving away from the wall
    t_late = 3.0 * f.s0 / c
    x = np.linspace(f.wall_x, f.wall_x + 300.0, 3001)
    u = f.displacement(x, 0.0, t_late)[:, 0]
    centre = x[np.argmin(u)]
    assert centre == pytest.approx(f.wall_x + c * t_late - f.s0, abs=0.2)
    assert u.min() == pytest.approx(-f.amplitude, rel=1e-3) and u.max() < 1e-12
    np.testing.assert_array_equal(f.displacement(x, 0.0, t_late)[:, 1], 0.0)


def test_bar_is_one_dimensional():
    f = ReflectingWave()
    x = np.linspace(0, 100, 50)
    for t in (0.0, 5.0):
        np.testing.assert_array_equal(f.displacement(x, 0.0, t), f.displacement(x, 42.0, t))
        g = f.displacement_gradient(x, 3.0, t)
        np.testing.assert_array_equal(g[:, 0, 1], 0.0)
        np.testing.assert_array_equal(g[:, 1, :], 0.0)
        np.testing.assert_allclose(
            f.strain_energy(x, 3.0, t), 0.5 * 210.0 * g[:, 0, 0] ** 2 * 1e6, rtol=1e-12, atol=0
        )


def test_radial_pulse_is_radially_symmetric():
    f = RadialPulse(centre=(3.0, -2.0))
    r = np.linspace(0.0, 60.0, 241)
    for t in (0.0, 2.5, 7.0):
        u_ref = None
        for phi in (0.0, 0.7, 2.0, 4.4):
            x = f.centre[0] + r * math.cos(phi)
            y = f.centre[1] + r * math.sin(phi)
            u = f.displacement(x, y, t)
            radial = u[:, 0] * math.cos(phi) + u[:, 1] * math.sin(phi)
            tangential = -u[:, 0] * math.sin(phi) + u[:, 1] * math.cos(phi)
            assert np.abs(tangential).max() <= 1e-12 * np.abs(radial).max()
            if u_ref is None:
                u_ref = radial
            np.testing.assert_allclose(radial, u_ref, rtol=1e-10, atol=1e-14 * np.abs(u_ref).max())
            speed = f.speed(x, y, t)
            np.testing.assert_allclose(speed, f.speed(f.centre[0] + r, f.centre[1], t), rtol=1e-10,
                                       atol=1e-18)
        # the pulse is a ring at r ≈ c (t + t0)
        peak_r = r[np.argmax(np.abs(u_ref))]
        assert abs(peak_r - f.material.p_wave_speed * (t + f.t0)) < 3.0 * f.a


def test_radial_pulse_is_finite_and_smooth_for_t_ge_0():
    """Along fine lines in t (crossing the ring) the displacement never jumps by more than the
    largest velocity allows: a wrong branch of the square root would flip signs there."""
    f = RadialPulse()
    t = np.linspace(0.0, 20.0, 40001)
    dt = t[1] - t[0]
    for r in (0.0, 1e-9, 5.0, f.material.p_wave_speed * f.t0, 30.0, 100.0):
        u = f.displacement(r, 0.0, t)
        v = f.velocity(r, 0.0, t)
        g = f.displacement_gradient(r, 0.0, t)
        assert np.all(np.isfinite(u)) and np.all(np.isfinite(v)) and np.all(np.isfinite(g))
        jumps = np.abs(np.diff(u[:, 0]))
        assert jumps.max() <= 1.01 * np.abs(v[:, 0]).max() * dt + 1e-18
        # and the trapezoid rule over v reproduces the displacement change
        integral = np.sum(0.5 * (v[1:, 0] + v[:-1, 0])) * dt
        assert integral == pytest.approx(u[-1, 0] - u[0, 0],
                                         abs=1e-6 * np.abs(u[:, 0]).max() + 1e-18)


def test_radial_pulse_refuses_bad_parameters_and_times():
    with pytest.raises(ValueError, match="t0"):
        RadialPulse(t0=0.0)
    with pytest.raises(ValueError, match="t0"):
        RadialPulse(t0=-1.0)
    with pytest.raises(ValueError, match="a must"):
        RadialPulse(a=0.0)
    f = RadialPulse(t0=1.0)
    f.displacement(0.0, 0.0, -0.5)  # defined for t > -t0
    with pytest.raises(ValueError, match="t > -t0"):
        f.displacement(1.0, 0.0, np.array([0.0, -1.0]))


def test_default_fields_have_strains_of_order_1e_3():
    x, y = np.meshgrid(np.linspace(0, 100, 401), np.linspace(-50, 50, 401))
    for f in (PlaneWave(x0=(50.0, 0.0)), ReflectingWave(), RadialPulse(centre=(50.0, 0.0))):
        g = f.displacement_gradient(x, y, 0.0)
        U = f.strain_energy(x, y, 0.0)
        assert 3e-4 < np.abs(g).max() < 3e-3
        assert 10.0 < U.max() < 1e3


def test_front_distance():
    f = PlaneWave(direction=(3.0, 4.0), x0=(1.0, 2.0))
    c = f.material.p_wave_speed
    xy = np.array([[1.0 + 0.6 * c * 2.0, 2.0 + 0.8 * c * 2.0],
                   [1.0 + 0.6 * (c * 2.0 + 7.0), 2.0 + 0.8 * (c * 2.0 + 7.0)]])
    np.testing.assert_allclose(f.front_distance(xy, 2.0), [0.0, 7.0], atol=1e-12)
    r = RadialPulse(centre=(1.0, 1.0))
    R = r.material.p_wave_speed * (3.0 + r.t0)
    np.testing.assert_allclose(
        r.front_distance(np.array([[1.0 + R, 1.0], [1.0, 1.0 + R - 4.0], [1.0, 1.0]]), 3.0),
        [0.0, 4.0, R])
    w = ReflectingWave()
    c = w.material.p_wave_speed
    np.testing.assert_allclose(w.front_distance(np.array([[w.s0 - c * 1.0, 0.0], [0.0, 0.0]]), 1.0),
                               [0.0, w.s0 - c])
    # the energy of the field is concentrated near the front
    for fld in (f, r, w):
        xs, ys = np.meshgrid(np.linspace(-80, 80, 321), np.linspace(-80, 80, 321))
        pts = np.column_stack([xs.ravel(), ys.ravel()])
        U = fld.strain_energy(pts[:, 0], pts[:, 1], 3.0)
        width = fld.a if isinstance(fld, RadialPulse) else fld.width
        assert fld.front_distance(pts, 3.0)[np.argmax(U)] < 2.0 * width
    with pytest.raises(ValueError, match=r"\(N, 2\)"):
        f.front_distance(np.zeros((3, 3)), 0.0)


# --------------------------------------------------------------------------- material and U
def test_materials():
    assert STEEL.p_wave_speed == pytest.approx(math.sqrt(210 * 0.7 / (1.3 * 0.4) / 7.85), rel=1e-12)
    assert BAR.lam == 0.0 and BAR.mu == pytest.approx(105.0)
    # ≈ 5.17 mm/µs = km/s
    assert BAR.p_wave_speed == pytest.approx(math.sqrt(210.0 / 7.85), rel=1e-12)
    for bad in ({"E": 0.0, "nu": 0.3, "rho": 1.0}, {"E": 1.0, "nu": 0.5, "rho": 1.0},
                {"E": 1.0, "nu": -1.0, "rho": 1.0}, {"E": 1.0, "nu": 0.2, "rho": 0.0},
                {"E": float("nan"), "nu": 0.2, "rho": 1.0}):  # fmt: skip
        with pytest.raises(ValueError):
            Material.from_young(**bad)
    with pytest.raises(ValueError):
        Material(lam=-2.0, mu=1.0, rho=1.0)
    with pytest.raises(ValueError, match="direction"):
        PlaneWave(direction=(0.0, 0.0))
    with pytest.raises(ValueError, match="width"):
        ReflectingWave(width=-1.0)


@PROPERTY
@given(
    hnp.arrays(np.float64, (2, 2), elements=st.floats(-1e-2, 1e-2)),
    st.floats(1.0, 400.0),
    st.floats(-0.9, 0.49),
)
def test_strain_energy_matches_plane_strain_stiffness(grad, E, nu):
    """U from the Lamé form against ½ eᵀ C e with the plane-strain Voigt matrix (engineering
    shear)."""
    m = Material.from_young(E, nu, 7.0)
    U = strain_energy_density(grad, m)
    eps = 0.5 * (grad + grad.T)
    e = np.array([eps[0, 0], eps[1, 1], 2.0 * eps[0, 1]])
    k = E / ((1 + nu) * (1 - 2 * nu))
    C = k * np.array([[1 - nu, nu, 0], [nu, 1 - nu, 0], [0, 0, (1 - 2 * nu) / 2]])
    ref = 0.5 * e @ C @ e * 1e6
    assert U >= 0.0
    assert U == pytest.approx(ref, rel=1e-9,
                              abs=1e-9 * (E * np.abs(grad).max() ** 2 * 1e6) + 1e-300)
    # rotation-free: a pure rotation (antisymmetric gradient) stores no energy
    assert strain_energy_density(np.array([[0.0, 1e-3], [-1e-3, 0.0]]), m) == 0.0


def test_strain_energy_of_the_bar_and_shapes():
    eps = np.array([1e-3, -2e-3, 5e-4])
    g = np.zeros((3, 2, 2))
    g[:, 0, 0] = eps
    np.testing.assert_allclose(strain_energy_density(g, BAR), 0.5 * 210.0 * eps**2 * 1e6,
                               rtol=1e-14)
    assert strain_energy_density(g.astype(np.float32), BAR).dtype == np.float32
    with pytest.raises(ValueError, match=r"\(\.\.\., 2, 2\)"):
        strain_energy_density(np.zeros((3, 3)), BAR)
