"""Closed-form elastodynamic displacement fields in 2-D (plane strain) for the st2005 examples.

Units throughout: lengths in mm, time in µs, Lamé constants and moduli in GPa, density in g/cm³.
With these, wave speeds come out in mm/µs (= km/s, since 1 GPa / (1 g/cm³) = 1e6 m²/s²),
velocities in mm/µs, strains are dimensionless and the strain energy density is reported in
kJ/m³ (1 GPa = 1e6 kJ/m³).

Every field is an exact solution of Navier's equations of isotropic linear elastodynamics,

    ρ ü = (λ + μ) ∇(∇·u) + μ Δu,

and gives the displacement u, the velocity ∂u/∂t and the displacement gradient ∂u_i/∂x_j in
closed form, vectorised over arrays x, y, t of any common broadcast shape (float64).

Every field takes an ``origin``: the field with origin ``o`` evaluated at ``x + o`` equals the
field with origin (0, 0) evaluated at ``x``, so the same solution can sit far from the
coordinate origin. The offset is removed in float64 before anything else is computed.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from dataclasses import dataclass

import numpy as np

__all__ = [
    "BAR",
    "STEEL",
    "ElasticField",
    "Material",
    "PlaneWave",
    "RadialPulse",
    "ReflectingWave",
    "strain_energy_density",
]

GPA_TO_KJ_PER_M3 = 1.0e6  # 1 GPa × (strain)² = 1e9 J/m³ = 1e6 kJ/m³


def _finite(name: str, value) -> float:
    v = float(value)
    if not math.isfinite(v):
        raise ValueError(f"{name} must be finite, got {value!r}")
    return v


def _positive(name: str, value) -> float:
    v = _finite(name, value)
    if v <= 0.0:
        raise ValueError(f"{name} must be > 0, got {value!r}")
    return v


def _vec2(name: str, value) -> tuple[float, float]:
    a = np.asarray(value, dtype=np.float64)
    if a.shape != (2,) or not np.all(np.isfinite(a)):
        raise ValueError(f"{name} must be two finite numbers, got {value!r}")
    return (float(a[0]), float(a[1]))


@dataclass(frozen=True)
class Material:
    """Isotropic linear elastic material under plane strain.

    ``lam`` and ``mu`` are the Lamé constants in GPa, ``rho`` the density in g/cm³. Refused:
    non-finite values, ``mu <= 0``, ``rho <= 0`` and ``lam + mu <= 0`` (the plane-strain bulk
    modulus must be positive, i.e. Poisson's ratio in (−1, ½)).
    """

    lam: float
    mu: float
    rho: float

    def __post_init__(self) -> None:
        lam = _finite("lam", self.lam)
        mu = _positive("mu", self.mu)
        rho = _positive("rho", self.rho)
        if lam + mu <= 0.0:
            raise ValueError(f"lam + mu must be > 0 (Poisson's ratio in (-1, 1/2)), got {lam + mu}")
        object.__setattr__(self, "lam", lam)
        object.__setattr__(self, "mu", mu)
        object.__setattr__(self, "rho", rho)

    @classmethod
    def from_young(cls, E: float, nu: float, rho: float) -> Material:
        """Material from Young's modulus ``E`` (GPa), Poisson's ratio ``nu`` (refused outside
        (−1, ½)) and density ``rho`` (g/cm³): λ = Eν / ((1 + ν)(1 − 2ν)), μ = E / (2(1 + ν))."""
        E = _positive("E", E)
        nu = _finite("nu", nu)
        if not -1.0 < nu < 0.5:
            raise ValueError(f"Poisson's ratio must lie in (-1, 1/2), got {nu}")
        return cls(lam=E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)), mu=E / (2.0 * (1.0 + nu)), rho=rho)

    @property
    def p_wave_speed(self) -> float:
        """Longitudinal (P) wave speed sqrt((λ + 2μ)/ρ) in mm/µs."""
        return math.sqrt((self.lam + 2.0 * self.mu) / self.rho)

    @property
    def s_wave_speed(self) -> float:
        """Shear (S) wave speed sqrt(μ/ρ) in mm/µs."""
        return math.sqrt(self.mu / self.rho)


STEEL = Material.from_young(210.0, 0.3, 7.85)
"""Structural steel: E = 210 GPa, ν = 0.3, ρ = 7.85 g/cm³ (P-wave speed ≈ 6.0 mm/µs)."""

BAR = Material.from_young(210.0, 0.0, 7.85)
"""Steel with ν = 0: a 1-D bar is the 2-D field with no y dependence, U = ½ E ε² and the wave
speed is sqrt(E/ρ) ≈ 5.17 mm/µs."""


def strain_energy_density(grad_u, material: Material) -> np.ndarray:
    """Strain energy density U = ½ ε : C ε = ½ (λ tr(ε)² + 2μ ε:ε) in kJ/m³ (plane strain).

    ``grad_u`` has shape (..., 2, 2) with ``grad_u[..., i, j] = ∂u_i/∂x_j`` (dimensionless);
    ε = ½(∇u + ∇uᵀ). Computed in float32 when ``grad_u`` is float32 (to measure what single
    precision loses), otherwise in float64. Refused: a trailing shape other than (2, 2).
    """
    g = np.asarray(grad_u)
    if g.dtype != np.float32:
        g = g.astype(np.float64, copy=False)
    if g.ndim < 2 or g.shape[-2:] != (2, 2):
        raise ValueError(f"grad_u must have shape (..., 2, 2), got {g.shape}")
    dt = g.dtype.type
    exx = g[..., 0, 0]
    eyy = g[..., 1, 1]
    exy = dt(0.5) * (g[..., 0, 1] + g[..., 1, 0])
    tr = exx + eyy
    eps_eps = exx * exx + eyy * eyy + dt(2.0) * exy * exy
    u = dt(0.5) * (dt(material.lam) * tr * tr + dt(2.0 * material.mu) * eps_eps)
    return u * dt(GPA_TO_KJ_PER_M3)


def _broadcast(x, y, t) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    x, y, t = np.broadcast_arrays(
        np.asarray(x, dtype=np.float64), np.asarray(y, dtype=np.float64),
        np.asarray(t, dtype=np.float64)
    )
    return x, y, t


@dataclass(frozen=True)
class ElasticField(ABC):
    """A closed-form displacement field u(x, y, t) of 2-D plane-strain elastodynamics.

    Subclasses implement the field in their own coordinates (``origin`` already removed);
    the public methods take global coordinates x, y (mm) and t (µs) of any common broadcast
    shape and return float64 arrays of that shape with the trailing axes documented per method.
    """

    material: Material
    origin: tuple[float, float]

    def _shift(self, x, y, t):
        x, y, t = _broadcast(x, y, t)
        return x - self.origin[0], y - self.origin[1], t

    # -- to implement, in field coordinates -------------------------------------------------
    @abstractmethod
    def _displacement(self, x, y, t) -> np.ndarray: ...

    @abstractmethod
    def _velocity(self, x, y, t) -> np.ndarray: ...

    @abstractmethod
    def _gradient(self, x, y, t) -> np.ndarray: ...

    @abstractmethod
    def _front_distance(self, x, y, t: float) -> np.ndarray: ...

    # -- public API ---------------------------------------------------------------------------
    def displacement(self, x, y, t) -> np.ndarray:
        """Displacement u in mm, shape (..., 2)."""
        return self._displacement(*self._shift(x, y, t))

    def velocity(self, x, y, t) -> np.ndarray:
        """Velocity ∂u/∂t in mm/µs, shape (..., 2)."""
        return self._velocity(*self._shift(x, y, t))

    def displacement_gradient(self, x, y, t) -> np.ndarray:
        """Displacement gradient ``g[..., i, j] = ∂u_i/∂x_j`` (dimensionless), shape (..., 2, 2)."""
        return self._gradient(*self._shift(x, y, t))

    def speed(self, x, y, t) -> np.ndarray:
        """Velocity magnitude ``|∂u/∂t|`` in mm/µs, shape (...)."""
        v = self.velocity(x, y, t)
        return np.hypot(v[..., 0], v[..., 1])

    def strain_energy(self, x, y, t) -> np.ndarray:
        """Strain energy density U in kJ/m³, shape (...)."""
        return strain_energy_density(self.displacement_gradient(x, y, t), self.material)

    def front_distance(self, xy, t: float) -> np.ndarray:
        """Distance in mm from each point ``xy`` (N, 2) (global, mm) to the nearest wave front
        (the centre line of the pulse) at time ``t`` (µs); shape (N,). Meant for refining meshes
        along the front. Refused: ``xy`` not of shape (N, 2), non-finite ``t``."""
        p = np.asarray(xy, dtype=np.float64)
        if p.ndim != 2 or p.shape[1] != 2:
            raise ValueError(f"xy must have shape (N, 2), got {p.shape}")
        t = _finite("t", t)
        return self._front_distance(p[:, 0] - self.origin[0], p[:, 1] - self.origin[1], t)


def _gauss(s: np.ndarray, width: float):
    """Pulse f(s) = exp(−(s/w)²) and its first two derivatives."""
    z = s / width
    f = np.exp(-z * z)
    f1 = -2.0 * z / width * f
    f2 = (4.0 * z * z - 2.0) / (width * width) * f
    return f, f1, f2


@dataclass(frozen=True)
class PlaneWave(ElasticField):
    """Plane longitudinal (P) wave u = A n f(n·(x − x0) − c t), f(s) = exp(−(s/w)²).

    ``direction`` n (normalised here; refused if zero) is the propagation direction,
    ``x0`` (mm, field coordinates) where the pulse centre is at t = 0, ``amplitude`` A in mm,
    ``width`` w in mm, c the material's P-wave speed in mm/µs. The defaults give a peak strain
    of about 0.86e-3 (A · max|f'| = A · 0.858/w) and U up to ≈ 100 kJ/m³ for steel.
    """

    material: Material = STEEL
    origin: tuple[float, float] = (0.0, 0.0)
    direction: tuple[float, float] = (1.0, 0.0)
    x0: tuple[float, float] = (0.0, 0.0)
    amplitude: float = 0.005
    width: float = 5.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "origin", _vec2("origin", self.origin))
        n = np.asarray(_vec2("direction", self.direction))
        norm = float(np.hypot(n[0], n[1]))
        if norm == 0.0:
            raise ValueError("direction must be non-zero")
        object.__setattr__(self, "direction", (float(n[0] / norm), float(n[1] / norm)))
        object.__setattr__(self, "x0", _vec2("x0", self.x0))
        object.__setattr__(self, "amplitude", _finite("amplitude", self.amplitude))
        object.__setattr__(self, "width", _positive("width", self.width))

    def _phase(self, x, y, t):
        n = self.direction
        return n[0] * (x - self.x0[0]) + n[1] * (y - self.x0[1]) - self.material.p_wave_speed * t

    def _displacement(self, x, y, t):
        f, _, _ = _gauss(self._phase(x, y, t), self.width)
        a = self.amplitude * f
        return np.stack([a * self.direction[0], a * self.direction[1]], axis=-1)

    def _velocity(self, x, y, t):
        _, f1, _ = _gauss(self._phase(x, y, t), self.width)
        a = -self.material.p_wave_speed * self.amplitude * f1
        return np.stack([a * self.direction[0], a * self.direction[1]], axis=-1)

    def _gradient(self, x, y, t):
        _, f1, _ = _gauss(self._phase(x, y, t), self.width)
        a = self.amplitude * f1
        n = self.direction
        g = np.empty(a.shape + (2, 2))
        for i in range(2):
            for j in range(2):
                g[..., i, j] = a * n[i] * n[j]
        return g

    def _front_distance(self, x, y, t):
        return np.abs(self._phase(x, y, t))


@dataclass(frozen=True)
class ReflectingWave(ElasticField):
    """P wave running towards a fixed end at x = ``wall_x`` and reflecting out of phase:

        u_x = A [f(X + c t − s0) − f(−X + c t − s0)],  u_y = 0,  X = x − wall_x,

    f(s) = exp(−(s/w)²). The physical domain is x ≥ wall_x; the incident pulse is centred at
    X = s0 − c t (moving towards the wall), the reflection at X = c t − s0, and u = 0 at the wall
    for all t. With material ``BAR`` and y ignored this is the st2005 Fig. 3 bar fixed at one
    end. ``wall_x``, ``s0`` and ``width`` in mm, ``amplitude`` A in mm. Defaults: a 100 mm bar
    with the pulse starting at its centre, peak strain ≈ 0.86e-3 (≈ 1.7e-3 at the wall during
    reflection), U up to ≈ 80 kJ/m³ (≈ 300 kJ/m³ at the wall).
    """

    material: Material = BAR
    origin: tuple[float, float] = (0.0, 0.0)
    wall_x: float = 0.0
    s0: float = 50.0
    amplitude: float = 0.005
    width: float = 5.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "origin", _vec2("origin", self.origin))
        object.__setattr__(self, "wall_x", _finite("wall_x", self.wall_x))
        object.__setattr__(self, "s0", _finite("s0", self.s0))
        object.__setattr__(self, "amplitude", _finite("amplitude", self.amplitude))
        object.__setattr__(self, "width", _positive("width", self.width))

    def _phases(self, x, t):
        X = x - self.wall_x
        ct = self.material.p_wave_speed * t - self.s0
        return X + ct, -X + ct

    def _displacement(self, x, y, t):
        a, b = self._phases(x, t)
        ux = self.amplitude * (_gauss(a, self.width)[0] - _gauss(b, self.width)[0])
        return np.stack([ux, np.zeros_like(ux)], axis=-1)

    def _velocity(self, x, y, t):
        a, b = self._phases(x, t)
        c = self.material.p_wave_speed
        vx = c * self.amplitude * (_gauss(a, self.width)[1] - _gauss(b, self.width)[1])
        return np.stack([vx, np.zeros_like(vx)], axis=-1)

    def _gradient(self, x, y, t):
        a, b = self._phases(x, t)
        g = np.zeros(a.shape + (2, 2))
        g[..., 0, 0] = self.amplitude * (_gauss(a, self.width)[1] + _gauss(b, self.width)[1])
        return g

    def _front_distance(self, x, y, t):
        a, b = self._phases(x, t)
        return np.minimum(np.abs(a), np.abs(b))


@dataclass(frozen=True)
class RadialPulse(ElasticField):
    """Radially spreading P pulse in 2-D, exact: u = ∇φ with

        φ = A Re[(s² − r²)^(−1/2)],  s = c (t + t0) − i a,  r = ``|x − centre|``.

    (s² − r²)^(−1/2) is the 2-D fundamental solution of the scalar wave equation continued to
    complex time, so φ_tt = c² Δφ and u = ∇φ solves Navier's equations with the P-wave speed c.
    With τ = t + t0 > 0, Im(s² − r²) = −2 a c τ < 0, so w = s² − r² stays in the open lower half
    plane where the principal square root is analytic: φ is smooth for all t > −t0. The pulse
    ring sits at r ≈ c τ with a radial width of order a (for a ≪ c τ).

    ``centre`` and ``a`` in mm, ``t0`` in µs, ``amplitude`` A in mm³. Refused: ``a <= 0``,
    ``t0 <= 0`` and, at evaluation, any t <= −t0. Defaults (steel): ring radius ≈ 12 mm at t = 0,
    peak strain ≈ 0.83e-3 at t = 0 (decaying as the ring spreads), U up to ≈ 1e2 kJ/m³.
    """

    material: Material = STEEL
    origin: tuple[float, float] = (0.0, 0.0)
    centre: tuple[float, float] = (0.0, 0.0)
    amplitude: float = 0.035
    a: float = 2.0
    t0: float = 2.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "origin", _vec2("origin", self.origin))
        object.__setattr__(self, "centre", _vec2("centre", self.centre))
        object.__setattr__(self, "amplitude", _finite("amplitude", self.amplitude))
        object.__setattr__(self, "a", _positive("a", self.a))
        object.__setattr__(self, "t0", _positive("t0", self.t0))

    def _terms(self, x, y, t):
        tau = t + self.t0
        if np.any(tau <= 0.0):
            raise ValueError(f"RadialPulse is defined for t > -t0 = {-self.t0} µs only")
        X = x - self.centre[0]
        Y = y - self.centre[1]
        s = self.material.p_wave_speed * tau - 1j * self.a
        w = s * s - (X * X + Y * Y)
        q = 1.0 / np.sqrt(w)  # principal branch: w^(-1/2), analytic for Im w < 0
        q3 = q * q * q
        q5 = q3 * q * q
        return X, Y, s, q3, q5

    def _displacement(self, x, y, t):
        X, Y, _, q3, _ = self._terms(x, y, t)
        r3 = self.amplitude * q3.real
        return np.stack([X * r3, Y * r3], axis=-1)

    def _velocity(self, x, y, t):
        X, Y, s, _, q5 = self._terms(x, y, t)
        k = -3.0 * self.amplitude * self.material.p_wave_speed * (s * q5).real
        return np.stack([X * k, Y * k], axis=-1)

    def _gradient(self, x, y, t):
        X, Y, _, q3, q5 = self._terms(x, y, t)
        A = self.amplitude
        r3 = q3.real
        r5 = 3.0 * q5.real
        g = np.empty(X.shape + (2, 2))
        g[..., 0, 0] = A * (r3 + X * X * r5)
        g[..., 1, 1] = A * (r3 + Y * Y * r5)
        g[..., 0, 1] = g[..., 1, 0] = A * X * Y * r5
        return g

    def _front_distance(self, x, y, t):
        return np.abs(np.hypot(x - self.centre[0], y - self.centre[1])
                      - self.material.p_wave_speed * (t + self.t0))
