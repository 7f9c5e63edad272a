"""Scalars of a symmetric stress tensor, on batches: principal stresses, maximum shear,
pressure, von Mises, signed von Mises and triaxiality (pure numpy, nothing of OpenGL).

A tensor is given as its six components on the last axis, ordered xx, yy, zz, xy, yz, zx (the
d3plot order, as lasso-python reads it), in any
Cartesian system: every scalar here is invariant under rotation. Results are float64 in the
stress units of the input (MPa for a mm/ms/kg deck), triaxiality and the sign dimensionless.

A tensor with a missing component (NaN, as the shells of a rigid part) gives NaN for every
scalar, never an exception; an infinite component is treated the same way (the scalars of
such a tensor are not defined). Arrays whose last axis is not 6 are refused with ValueError.

**Accuracy.** Differences of the normal components are exact for float32 input (the d3plot's
precision) held in float64, so :func:`von_mises` (from those differences and the shear terms)
and :func:`pressure` are accurate to a few units in the last place of their own value, also
for a large hydrostatic part. The principal stresses are the mean normal stress plus the
eigenvalues of the deviator (``numpy.linalg.eigvalsh``): each is accurate to a few ulps of the
tensor's magnitude; their differences (:func:`max_shear`) to a few ulps of the deviator's, so a
small shear under a large pressure keeps its digits.
"""

from __future__ import annotations

import numpy as np

# the derived scalars by name, with what each is (for help texts and ``workbench info``)
SCALARS = {
    "von_mises": "von Mises equivalent stress sqrt(3 J2)",
    "signed_von_mises": "von Mises stress with the sign of the trace (tension +, compression -)",
    "principal_max": "largest principal stress s1",
    "principal_mid": "middle principal stress s2",
    "principal_min": "smallest principal stress s3",
    "max_shear": "maximum shear stress (s1 - s3) / 2",
    "pressure": "pressure -(sxx + syy + szz) / 3 (compression positive)",
    "triaxiality": "stress triaxiality -pressure / von Mises (NaN where von Mises is 0)",
}


def _components(stress) -> np.ndarray:
    """``stress`` as float64 with the six components on the last axis, a tensor with a
    component that is not finite all NaN; ValueError for another shape."""
    s = np.asarray(stress, dtype=np.float64)
    if s.ndim == 0 or s.shape[-1] != 6:
        raise ValueError(f"stress must be (..., 6) ordered xx, yy, zz, xy, yz, zx, "
                         f"got shape {s.shape}")
    bad = ~np.isfinite(s).all(axis=-1)
    if bad.any():
        s = s.copy()
        s[bad] = np.nan
    return s


def pressure(stress) -> np.ndarray:
    """Pressure ``-(sxx + syy + szz) / 3`` of (..., 6) tensors, shape (...); compression is
    positive. Stress units. NaN where a component is NaN."""
    s = _components(stress)
    return -(s[..., 0] + s[..., 1] + s[..., 2]) / 3.0


def von_mises(stress) -> np.ndarray:
    """Von Mises equivalent stress of (..., 6) tensors, shape (...):
    sqrt(((sxx - syy)^2 + (syy - szz)^2 + (szz - sxx)^2) / 2 + 3 (sxy^2 + syz^2 + szx^2)), in the
    stress units of the input; 0 for a hydrostatic tensor, NaN where a component is NaN."""
    xx, yy, zz, xy, yz, zx = np.moveaxis(_components(stress), -1, 0)
    return np.sqrt(0.5 * ((xx - yy) ** 2 + (yy - zz) ** 2 + (zz - xx) ** 2)
                   + 3.0 * (xy ** 2 + yz ** 2 + zx ** 2))


def signed_von_mises(stress) -> np.ndarray:
    """:func:`von_mises` with the sign of the trace (of the mean normal stress), shape (...).

    The sign of the trace is chosen, not that of the principal stress of largest magnitude,
    because it is continuous wherever the trace is not 0 and agrees with :func:`pressure` and
    :func:`triaxiality` (positive signed von Mises = tension = negative pressure), while the
    largest-magnitude principal jumps between s1 and s3 where they are of equal size. A trace
    of exactly 0 (pure shear) counts as positive. Stress units; NaN where a component is NaN.
    """
    s = _components(stress)
    trace = s[..., 0] + s[..., 1] + s[..., 2]
    return np.where(trace < 0, -1.0, 1.0) * von_mises(s)


def triaxiality(stress) -> np.ndarray:
    """Stress triaxiality ``-pressure / von Mises`` = mean normal stress over von Mises of
    (..., 6) tensors, shape (...), dimensionless (1/3 in uniaxial tension, 0 in pure shear).
    NaN where von Mises is 0 (a zero or purely hydrostatic tensor, where it is undefined) and
    where a component is NaN."""
    s = _components(stress)
    mises = von_mises(s)
    mean = -pressure(s)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(mises > 0, mean / np.where(mises > 0, mises, 1.0), np.nan)


def principal_stresses(stress) -> np.ndarray:
    """Principal stresses of (..., 6) tensors, shape (..., 3), ordered s1 >= s2 >= s3 (max, mid,
    min): the mean normal stress plus the eigenvalues (``numpy.linalg.eigvalsh``) of the
    deviator, in stress units. All three NaN where a component is not finite."""
    s = _components(stress)
    shape = s.shape[:-1]
    flat = s.reshape(-1, 6)
    out = np.full((len(flat), 3), np.nan)
    good = np.isfinite(flat).all(axis=1)
    if good.any():
        mean, deviator = _deviator(flat[good])
        eigen = np.linalg.eigvalsh(deviator)  # ascending
        out[good] = mean[:, None] + eigen[:, ::-1]
    return out.reshape(*shape, 3)


def max_shear(stress) -> np.ndarray:
    """Maximum shear stress ``(s1 - s3) / 2`` of (..., 6) tensors, shape (...), stress units,
    from the eigenvalues of the deviator (so a large hydrostatic part costs no digits); NaN
    where a component is not finite."""
    s = _components(stress)
    shape = s.shape[:-1]
    flat = s.reshape(-1, 6)
    out = np.full(len(flat), np.nan)
    good = np.isfinite(flat).all(axis=1)
    if good.any():
        eigen = np.linalg.eigvalsh(_deviator(flat[good])[1])
        out[good] = (eigen[:, 2] - eigen[:, 0]) / 2.0
    return out.reshape(shape)


def _deviator(flat: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(mean normal stress (K,), deviator (K, 3, 3)) of (K, 6) finite tensors. The diagonal is
    formed from differences of the normal components, ((sxx - syy) + (sxx - szz)) / 3 and so
    on, which are exact for float32 values, so it keeps its digits under a large mean."""
    xx, yy, zz, xy, yz, zx = flat.T
    matrix = np.empty((len(flat), 3, 3))
    matrix[:, 0, 0] = ((xx - yy) + (xx - zz)) / 3.0
    matrix[:, 1, 1] = ((yy - zz) + (yy - xx)) / 3.0
    matrix[:, 2, 2] = ((zz - xx) + (zz - yy)) / 3.0
    matrix[:, 0, 1] = matrix[:, 1, 0] = xy
    matrix[:, 1, 2] = matrix[:, 2, 1] = yz
    matrix[:, 2, 0] = matrix[:, 0, 2] = zx
    return (xx + yy + zz) / 3.0, matrix


def stress_scalar(name: str, stress) -> np.ndarray:
    """The scalar ``name`` of :data:`SCALARS` of (..., 6) tensors, shape (...); KeyError naming
    the known ones for another name."""
    if name.startswith("principal_"):
        index = {"principal_max": 0, "principal_mid": 1, "principal_min": 2}.get(name)
        if index is not None:
            return principal_stresses(stress)[..., index]
    functions = {"von_mises": von_mises, "signed_von_mises": signed_von_mises,
                 "max_shear": max_shear, "pressure": pressure, "triaxiality": triaxiality}
    if name not in functions:
        raise KeyError(f"no stress scalar {name!r}; known: {', '.join(SCALARS)}")
    return functions[name](stress)
