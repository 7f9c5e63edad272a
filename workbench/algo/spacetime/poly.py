"""Per-element complete cubic displacement polynomials in element-local spacetime coordinates
(st2005 §4.2.1).

Within each spacetime simplex the displacement is u(p) = Σ_α c_α m^α(p) over the 20 cubic
monomials m^α in the paper's order (``EXPONENTS``), with local coordinates

    p = diag(1/w_x, 1/w_y, 1/w_t) (p̂ − ĉ),

ĉ the centre and (w_x, w_y, w_t) the side lengths of the element's axis-aligned bounding box in
global (x, y, t), so each element spans [−½, ½] per axis. Coordinates in mm and µs,
displacement in mm, velocity in mm/µs, strain energy density in kJ/m³ (see ``fields``).

1-D problems (spacetime triangles in (x, t)) use the same 20-slot layout: y centre 0, y extent 1
and only the 10 monomials without y; their y coefficients are 0.

Everything here is float64 except ``evaluate_float32_global`` / ``evaluate_float32_local``,
which repeat the evaluation in float32 arithmetic to measure what a GPU loses when the local
transform is applied to global float32 coordinates rather than to coordinates taken relative to a
float64 scene origin.
"""

from __future__ import annotations

from functools import lru_cache
from itertools import product

import numpy as np

from .fields import Material, strain_energy_density

__all__ = [
    "DERIVATIVES",
    "EXPONENTS",
    "evaluate",
    "evaluate_float32_global",
    "evaluate_float32_local",
    "fit_cubic",
    "height_normal",
    "local_frames",
    "monomials",
]

EXPONENTS = np.array(
    [
        (0, 0, 0),
        (1, 0, 0), (0, 1, 0), (0, 0, 1),
        (2, 0, 0), (1, 1, 0), (1, 0, 1), (0, 2, 0), (0, 1, 1), (0, 0, 2),
        (3, 0, 0), (2, 1, 0), (2, 0, 1), (1, 2, 0), (1, 1, 1), (1, 0, 2),
        (0, 3, 0), (0, 2, 1), (0, 1, 2), (0, 0, 3),
    ],
    dtype=np.int64,
)  # fmt: skip
"""(20, 3) exponents of x, y, t of the complete cubic monomials, in the st2005 order
(1, x, y, t, x², xy, xt, y², yt, t², x³, x²y, x²t, xy², xyt, xt², y³, y²t, yt², t³)."""
EXPONENTS.flags.writeable = False

DERIVATIVES = ("x", "y", "t", "xt", "yt")
"""The derivatives ``evaluate`` uses; ``monomials`` accepts any string of up to three of x, y, t."""

_NO_Y = np.flatnonzero(EXPONENTS[:, 1] == 0)  # the 10 monomials of a 1-D (x, t) problem


# --------------------------------------------------------------------------- monomials
def _monomial_table(exps: np.ndarray, orders) -> tuple[np.ndarray, np.ndarray]:
    """Coefficients and reduced exponents of ∂^orders m^α for monomials with exponents ``exps``."""
    orders = np.asarray(orders, dtype=np.int64)
    coef = np.ones(len(exps))
    for k, d in enumerate(orders):
        for j in range(d):
            coef = coef * np.maximum(exps[:, k] - j, 0)
    return coef, np.maximum(exps - orders, 0)


def _monomial_list(cols, exps: np.ndarray, orders=None) -> list:
    """The monomials with exponents ``exps`` (n, d) (or their ∂^orders) at the coordinate arrays
    ``cols`` (d arrays of one shape), as a list of n arrays (None for an identically zero
    derivative). Products of cached powers: far faster than gathering from a power table."""
    d = exps.shape[1]
    coef, red = _monomial_table(exps, np.zeros(d, np.int64) if orders is None else orders)
    dtype = cols[0].dtype.type
    powers = [[None, c, c * c, c * c * c] for c in cols]
    out = []
    for a in range(len(exps)):
        if coef[a] == 0:
            out.append(None)
            continue
        term = None
        for k in range(d):
            e = red[a, k]
            if e:
                term = powers[k][e] if term is None else term * powers[k][e]
        if term is None:
            term = np.ones_like(cols[0])
        if coef[a] != 1:
            term = term * dtype(coef[a])
        out.append(term)
    return out


def _eval_monomials(p: np.ndarray, exps: np.ndarray, orders=None) -> np.ndarray:
    """Monomials (or a derivative of them) with exponents ``exps`` (n, d) at ``p`` (..., d),
    stacked to (..., n) in the dtype of ``p``."""
    cols = [p[..., k] for k in range(exps.shape[1])]
    zero = np.zeros_like(cols[0])
    return np.stack([zero if m is None else m for m in _monomial_list(cols, exps, orders)], axis=-1)


def _orders(derivative: str | None) -> np.ndarray:
    if derivative is None:
        return np.zeros(3, np.int64)
    if not isinstance(derivative, str) or len(derivative) > 3 or set(derivative) - set("xyt"):
        raise ValueError("derivative must be None or up to three of 'x', 'y', 't' (e.g. 'xt'), "
                         f"got {derivative!r}")
    return np.array([derivative.count(a) for a in "xyt"], np.int64)


def monomials(p, derivative: str | None = None) -> np.ndarray:
    """The 20 cubic monomials (in ``EXPONENTS`` order) at local points ``p`` (..., 3), or their
    partial derivative in local coordinates named by ``derivative`` (a string of up to three of
    'x', 'y', 't', e.g. 'x', 't', 'xt', 'yt'). Returns (..., 20), float32 if ``p`` is float32,
    else float64. Refused: a trailing axis other than 3, an unknown derivative."""
    p = np.asarray(p)
    if p.dtype != np.float32:
        p = p.astype(np.float64, copy=False)
    if p.ndim < 1 or p.shape[-1] != 3:
        raise ValueError(f"p must have shape (..., 3), got {p.shape}")
    return _eval_monomials(p, EXPONENTS, _orders(derivative))


# --------------------------------------------------------------------------- frames
def _check_mesh(points, simplices) -> tuple[np.ndarray, np.ndarray, int]:
    pts = np.asarray(points, dtype=np.float64)
    if pts.ndim != 2 or pts.shape[1] not in (2, 3):
        raise ValueError("points must have shape (P, 2) for (x, t) or (P, 3) for (x, y, t), got "
                         f"{pts.shape}")
    d = pts.shape[1]
    simp = np.asarray(simplices)
    if simp.ndim != 2 or simp.shape[1] != d + 1:
        raise ValueError(f"simplices must have shape (M, {d + 1}) for points with {d} columns, "
                         f"got {simp.shape}")
    if not np.issubdtype(simp.dtype, np.integer):
        raise ValueError(f"simplices must be integer indices, got dtype {simp.dtype}")
    if simp.size and (simp.min() < 0 or simp.max() >= len(pts)):
        raise ValueError(f"simplices index outside 0..{len(pts) - 1}")
    if not np.all(np.isfinite(pts)):
        raise ValueError("points must be finite")
    return pts, simp.astype(np.int64, copy=False), d


def local_frames(points, simplices) -> tuple[np.ndarray, np.ndarray]:
    """Element-local frames: ``centre`` (M, 3) = midpoint and ``extent`` (M, 3) = side lengths
    (w_x, w_y, w_t) of each simplex's axis-aligned bounding box in global (x, y, t), mm and µs.

    ``points`` (P, 3) with columns (x, y, t) and ``simplices`` (M, 4) tetrahedra, or ``points``
    (P, 2) with columns (x, t) and ``simplices`` (M, 3) triangles; for the latter the y centre is 0
    and the y extent 1. Local coordinates are p = (p̂ − centre) / extent. Refused: other shapes,
    indices out of range, non-finite points, a zero extent (a flat, degenerate simplex).
    """
    pts, simp, d = _check_mesh(points, simplices)
    v = pts[simp]  # (M, d+1, d)
    lo = v.min(axis=1)
    hi = v.max(axis=1)
    c = 0.5 * (lo + hi)
    w = hi - lo
    if np.any(w <= 0.0):
        bad = int(np.flatnonzero(np.any(w <= 0.0, axis=1))[0])
        raise ValueError(f"simplex {bad} is flat along an axis (zero bounding-box extent)")
    if d == 3:
        return c, w
    m = len(simp)
    centre = np.stack([c[:, 0], np.zeros(m), c[:, 1]], axis=1)
    extent = np.stack([w[:, 0], np.ones(m), w[:, 1]], axis=1)
    return centre, extent


# --------------------------------------------------------------------------- fitting
def _lattice(d: int, n: int) -> np.ndarray:
    """Barycentric coordinates (k, d+1) of the order-n lattice of a d-simplex."""
    rows = [c for c in product(range(n + 1), repeat=d) if sum(c) <= n]
    rows = np.array(rows, dtype=np.float64)
    return np.column_stack([n - rows.sum(axis=1), rows]) / n


@lru_cache(maxsize=8)
def _fit_operators(d: int, n: int):
    """Fixed matrices of the fit in spacetime dimension d (2: (x, t), 3: (x, y, t)) at lattice
    order n.

    The least-squares cubic through the lattice samples does not depend on how the cubic space is
    parametrised, so it is solved once on the reference simplex (barycentric ξ, well conditioned)
    and re-expressed in local monomials by evaluating it at ``n_loc`` fixed local points Q and
    interpolating there with the fixed inverse local Vandermonde W.
    """
    exps = EXPONENTS if d == 3 else EXPONENTS[_NO_Y][:, [0, 2]]
    bary = _lattice(d, n)  # (k, d+1)
    xi = bary[:, 1:] - 1.0 / (d + 1)
    v_ref = _eval_monomials(xi, exps)
    p_ref = np.linalg.pinv(v_ref)  # (n_mono, k)
    # Q: the order-3 lattice of the corner simplex of [-1/2, 1/2]^d, unisolvent for cubics.
    corner = np.vstack([np.zeros(d), np.eye(d)]) - 0.5
    q = _lattice(d, 3) @ corner
    v_loc = _eval_monomials(q, exps)
    w = np.linalg.inv(v_loc)
    return exps, bary, p_ref, q, w, float(np.linalg.cond(v_ref)), float(np.linalg.cond(v_loc))


def fit_conditioning(dimension: int = 3, lattice: int = 4) -> tuple[float, float]:
    """2-norm condition numbers of the two fixed matrices ``fit_cubic`` solves with: the
    reference-simplex Vandermonde at the lattice, and the local Vandermonde at the fixed points
    in [−½, ½]^d. ``dimension`` is 2 for (x, t) or 3 for (x, y, t)."""
    if dimension not in (2, 3):
        raise ValueError(f"dimension must be 2 or 3, got {dimension}")
    return _fit_operators(dimension, int(lattice))[5:]


def _inverse_small(a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Batched inverse and determinant of (m, d, d) matrices, d in (2, 3), by the adjugate."""
    if a.shape[-1] == 2:
        det = a[:, 0, 0] * a[:, 1, 1] - a[:, 0, 1] * a[:, 1, 0]
        adj = np.empty_like(a)
        adj[:, 0, 0] = a[:, 1, 1]
        adj[:, 1, 1] = a[:, 0, 0]
        adj[:, 0, 1] = -a[:, 0, 1]
        adj[:, 1, 0] = -a[:, 1, 0]
    else:
        c0 = np.cross(a[:, 1], a[:, 2])
        c1 = np.cross(a[:, 2], a[:, 0])
        c2 = np.cross(a[:, 0], a[:, 1])
        det = np.einsum("mi,mi->m", a[:, 0], c0)
        adj = np.stack([c0, c1, c2], axis=2)  # columns are the cofactor rows
    return adj / det[:, None, None], det


MIN_LOCAL_VOLUME = 1e-6
"""Simplices whose volume in local coordinates (bounding box → unit cube) is below this fraction
of the unit cube are refused by ``fit_cubic``: the cubic fit on such slivers is meaningless."""


def fit_cubic(points, simplices, displacement, *, lattice: int = 4,
              chunk: int = 50_000) -> np.ndarray:
    """Least-squares complete cubic per element of ``displacement(x, y, t) -> (..., 2)`` (mm),
    sampled at the order-``lattice`` barycentric lattice of each simplex (35 points for a
    tetrahedron at order 4, 15 for a triangle).

    ``points``/``simplices`` as in ``local_frames``: (P, 3) (x, y, t) with (M, 4) tetrahedra, or
    (P, 2) (x, t) with (M, 3) triangles (then the callable gets y = 0 and only the 10 monomials
    without y are fitted; the other coefficients are 0). Returns ``coeffs`` (M, 20, 2) float64 in
    the element-local coordinates of ``local_frames``, ``coeffs[e, α, i]`` multiplying m^α for
    component u_i. Samples are drawn ``chunk`` elements at a time: the callable gets x, y, t of
    shape (lattice points, elements in the chunk) and must return that shape plus (2,).

    Refused: bad shapes, ``lattice`` < 3 (fewer samples than monomials), ``chunk`` < 1, flat or
    sliver simplices (local volume below ``MIN_LOCAL_VOLUME``), a callable returning the wrong
    shape or non-finite values.
    """
    pts, simp, d = _check_mesh(points, simplices)
    if isinstance(lattice, bool) or int(lattice) != lattice or lattice < 3:
        raise ValueError("lattice must be an integer >= 3 (a cubic needs the order-3 lattice), "
                         f"got {lattice!r}")
    if isinstance(chunk, bool) or int(chunk) != chunk or chunk < 1:
        raise ValueError(f"chunk must be a positive integer, got {chunk!r}")
    if not callable(displacement):
        raise TypeError("displacement must be a callable (x, y, t) -> (..., 2)")
    centre, extent = local_frames(pts, simp)
    exps, bary, p_ref, q, w, _, _ = _fit_operators(d, int(lattice))
    axes = [0, 1, 2] if d == 3 else [0, 2]
    active = np.arange(20) if d == 3 else _NO_Y
    m_total = len(simp)
    n_mono, n_lat, n_q = len(exps), len(bary), len(q)
    out = np.zeros((m_total, 20, 2))
    fact = 1.0 / np.prod(np.arange(1, d + 1))
    for s in range(0, m_total, int(chunk)):
        e = slice(s, min(s + int(chunk), m_total))
        v = pts[simp[e]]  # (m, d+1, d) global
        m = len(v)
        # lattice points, (k, m, d): one GEMM over all elements of the chunk
        at = (bary @ np.swapaxes(v, 0, 1).reshape(d + 1, m * d)).reshape(n_lat, m, d)
        cols = [at[..., j] for j in range(d)]
        if d == 2:
            cols = [cols[0], np.zeros_like(cols[0]), cols[1]]
        u = np.asarray(displacement(*cols), dtype=np.float64)
        if u.shape != (n_lat, m, 2):
            raise ValueError(f"displacement returned shape {u.shape} for inputs of shape "
                             f"{(n_lat, m)}, expected {(n_lat, m, 2)}")
        if not np.all(np.isfinite(u)):
            raise ValueError("displacement returned non-finite values")
        # reference-monomial coefficients
        r = (p_ref @ u.reshape(n_lat, 2 * m)).reshape(n_mono, m, 2)
        c = centre[e][:, axes]
        wl = extent[e][:, axes]
        vl = (v - c[:, None, :]) / wl[:, None, :]  # local vertices
        edges = np.swapaxes(vl[:, 1:] - vl[:, :1], 1, 2)  # (m, d, d), columns v_k − v_0
        inv, det = _inverse_small(edges)
        small = np.abs(det) * fact < MIN_LOCAL_VOLUME
        if np.any(small):
            bad = int(np.flatnonzero(small)[0])
            raise ValueError(f"simplex {s + bad} is degenerate "
                             f"(local volume {abs(det[bad]) * fact:.3g})")
        rel = [q[:, j, None] - vl[None, :, 0, j] for j in range(d)]  # (n_q, m) each
        xi = [sum(inv[None, :, i, j] * rel[j] for j in range(d)) - 1.0 / (d + 1) for i in range(d)]
        rc = np.ascontiguousarray(np.moveaxis(r, 2, 0))  # (2, n_mono, m)
        g = np.zeros((2, n_q, m))
        tmp = np.empty((n_q, m))
        for a, term in enumerate(_monomial_list(xi, exps)):
            for i in range(2):
                np.multiply(term, rc[i, a], out=tmp)
                g[i] += tmp
        local = (w @ g.reshape(2, n_q, m)).reshape(2, n_mono, m)  # (2, n_mono, m)
        out[e][:, active] = np.moveaxis(local, 0, 2).swapaxes(0, 1)
    return out


# --------------------------------------------------------------------------- evaluation
def _check_eval(coeffs, centre, extent, element, x, y, t):
    c = np.asarray(coeffs, dtype=np.float64)
    if c.ndim != 3 or c.shape[1:] != (20, 2):
        raise ValueError(f"coeffs must have shape (M, 20, 2), got {c.shape}")
    ce = np.asarray(centre, dtype=np.float64)
    ex = np.asarray(extent, dtype=np.float64)
    if ce.shape != (len(c), 3) or ex.shape != (len(c), 3):
        raise ValueError(f"centre and extent must have shape ({len(c)}, 3), got {ce.shape} and "
                         f"{ex.shape}")
    if np.any(ex <= 0.0):
        raise ValueError("extent must be > 0")
    el = np.asarray(element)
    if el.ndim != 1 or not np.issubdtype(el.dtype, np.integer):
        raise ValueError(f"element must be a 1-D integer array, got shape {el.shape} "
                         f"dtype {el.dtype}")
    if el.size and (el.min() < 0 or el.max() >= len(c)):
        raise ValueError(f"element index outside 0..{len(c) - 1}")
    xyt = [np.asarray(a, dtype=np.float64) for a in (x, y, t)]
    k = len(el)
    for name, a in zip("xyt", xyt):
        if a.shape != (k,) and a.shape != ():
            raise ValueError(f"{name} must have shape ({k},) or be a scalar, got {a.shape}")
    xyt = [np.broadcast_to(a, (k,)) for a in xyt]
    return c, ce, ex, el, np.stack(xyt, axis=1)


def _derived(c: np.ndarray, p: np.ndarray, w: np.ndarray, material: Material | None) -> dict:
    """All derived quantities at local points ``p`` (K, 3) of elements with coefficients ``c``
    (K, 20, 2) and extents ``w`` (K, 3), in the dtype of the inputs."""
    def contract(deriv):
        return np.einsum("ka,kai->ki", _eval_monomials(p, EXPONENTS, _orders(deriv)), c)

    u = contract(None)
    v = contract("t") / w[:, 2:3]
    grad = np.stack([contract("x") / w[:, 0:1], contract("y") / w[:, 1:2]], axis=2)  # (K, i, j)
    dv = np.stack([contract("xt"), contract("yt")], axis=2) / (w[:, 2:3, None] * w[:, None, 0:2])
    speed = np.hypot(v[:, 0], v[:, 1])
    moving = speed > 0
    grad_speed = np.zeros((len(p), 2), dtype=p.dtype)
    grad_speed[moving] = np.einsum("ki,kij->kj", v[moving], dv[moving]) / speed[moving, None]
    out = {"displacement": u, "velocity": v, "grad_u": grad, "speed": speed,
           "grad_speed": grad_speed}
    if material is not None:
        out["U"] = strain_energy_density(grad, material)
    return out


def evaluate(coeffs, centre, extent, element, x, y, t, material: Material | None = None) -> dict:
    """Evaluate the element polynomials at K global points (x, y, t) (mm, µs), point k lying in
    element ``element[k]``; x, y, t of shape (K,) or scalars (e.g. the slice time).

    Returns a dict of float64 arrays: "displacement" (K, 2) mm, "velocity" (K, 2) mm/µs, "grad_u"
    (K, 2, 2) with grad_u[k, i, j] = ∂u_i/∂x_j, "speed" (K,) ``|v|`` in mm/µs, "grad_speed" (K, 2)
    the spatial gradient of ``|v|`` in (mm/µs)/mm (0 where ``|v| == 0``, never NaN) and, when a
    ``material`` is given, "U" (K,) the strain energy density in kJ/m³. Derivatives follow the chain
    rule ∂/∂x̂ = (1/w_x) ∂/∂x_local etc. Refused: bad shapes, element indices out of range.
    """
    c, ce, ex, el, xyt = _check_eval(coeffs, centre, extent, element, x, y, t)
    p = (xyt - ce[el]) / ex[el]
    return _derived(c[el], p, ex[el], material)


def speed(coeffs, centre, extent, element, x, y, t) -> np.ndarray:
    """``|v|`` (K,) in mm/µs at K global points (x, y, t) (mm, µs), point k in element
    ``element[k]``: the "speed" of :func:`evaluate`, the same float64 arithmetic, without the
    other fields (one contraction of the time derivative instead of six). Refused as
    :func:`evaluate` refuses."""
    c, ce, ex, el, xyt = _check_eval(coeffs, centre, extent, element, x, y, t)
    p = (xyt - ce[el]) / ex[el]
    v = np.einsum("ka,kai->ki", _eval_monomials(p, EXPONENTS, _orders("t")), c[el])
    v = v / ex[el][:, 2:3]
    return np.hypot(v[:, 0], v[:, 1])


def evaluate_float32(coeffs, centre, extent, element, x, y, t, material: Material,
                     origin=None) -> dict:
    """"U" (kJ/m³) and "speed" (mm/µs) computed entirely in float32, as a GPU would.

    ``origin`` None: the global coordinates and element centres are rounded to float32 and the
    local transform p = (p̂ − ĉ)/w is applied to them. ``origin`` given (2 numbers: x, y — the
    slice time stays global — or 3: x, y, t): point and centre are first made relative to the
    float64 origin and then rounded, p = ((p̂ − o) − (ĉ − o))/w in float32. Coefficients, extents
    and material constants are float32 in both cases. Returns float32 arrays (K,).
    """
    c, ce, ex, el, xyt = _check_eval(coeffs, centre, extent, element, x, y, t)
    if origin is not None:
        o = np.asarray(origin, dtype=np.float64).ravel()
        if o.shape not in ((2,), (3,)) or not np.all(np.isfinite(o)):
            raise ValueError("origin must be 2 (x, y) or 3 (x, y, t) finite numbers, got "
                             f"{origin!r}")
        o = np.concatenate([o, [0.0]]) if len(o) == 2 else o
        xyt = xyt - o
        ce = ce - o
    f32 = np.float32
    p = (xyt.astype(f32) - ce[el].astype(f32)) / ex[el].astype(f32)
    res = _derived(c[el].astype(f32), p, ex[el].astype(f32), material)
    return {"U": res["U"], "speed": res["speed"]}


def evaluate_float32_global(coeffs, centre, extent, element, x, y, t, material: Material) -> dict:
    """``evaluate_float32`` on global float32 coordinates (what precision is lost far from the
    coordinate origin). Returns float32 "U" (kJ/m³) and "speed" (mm/µs), shape (K,)."""
    return evaluate_float32(coeffs, centre, extent, element, x, y, t, material, origin=None)


def evaluate_float32_local(coeffs, centre, extent, element, x, y, t, material: Material,
                           origin=None) -> dict:
    """``evaluate_float32`` on float32 coordinates relative to a float64 scene ``origin``
    ((x, y) or (x, y, t)); None takes the centre of the bounding box of all element centres
    (spatial part). Returns float32 "U" (kJ/m³) and "speed" (mm/µs), shape (K,)."""
    if origin is None:
        ce = np.asarray(centre, dtype=np.float64)
        if ce.ndim != 2 or ce.shape[1] != 3 or len(ce) == 0:
            raise ValueError(f"centre must have shape (M, 3) with M >= 1, got {ce.shape}")
        origin = 0.5 * (ce[:, :2].min(axis=0) + ce[:, :2].max(axis=0))
    return evaluate_float32(coeffs, centre, extent, element, x, y, t, material, origin=origin)


def height_normal(grad_speed, height_scale: float) -> np.ndarray:
    """Unit normals (K, 3) of the height field ``z = height_scale · |v|``:
    ``normalize(−h ∂|v|/∂x, −h ∂|v|/∂y, 1)``; exactly (0, 0, 1) where the gradient is zero.
    ``grad_speed`` (K, 2) in (mm/µs)/mm, ``height_scale`` h in mm per (mm/µs). Refused: bad
    shape, non-finite values."""
    g = np.asarray(grad_speed, dtype=np.float64)
    if g.ndim != 2 or g.shape[1] != 2:
        raise ValueError(f"grad_speed must have shape (K, 2), got {g.shape}")
    h = float(height_scale)
    if not np.isfinite(h) or not np.all(np.isfinite(g)):
        raise ValueError("grad_speed and height_scale must be finite")
    n = np.column_stack([-h * g[:, 0], -h * g[:, 1], np.ones(len(g))])
    return n / np.linalg.norm(n, axis=1, keepdims=True)
