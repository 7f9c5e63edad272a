"""Section planes along a trace line: equally spaced on each segment, orthogonal to it, with
the normals blended near each joint (see :func:`section_planes`). Model units."""

from __future__ import annotations

import numpy as np


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
