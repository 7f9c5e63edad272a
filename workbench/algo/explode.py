"""Ghosted exploded views (ghost2013, Wutscher): an object of interest stays in place while the
rest of the assembly is drawn twice, clipped by a split plane into two halves that move apart
along ± the plane normal until the object is revealed.

Everything here is geometry and bookkeeping, no GL: the render path draws the three passes and
measures the occlusion ratio, this module turns that ratio into the next offset, the front
half's opacity, its culling, and chooses split planes.

* **Occlusion ratio.** Each frame the object's pixels are counted drawn alone (``p_unocc``) and
  drawn with both halves (``p_occ``); ``r = (p_unocc − p_occ)/p_unocc`` (eq. 2.1) is 0 when the
  object is fully visible and 1 when it is fully hidden (:func:`occlusion_ratio`).
* **Dynamics** (:func:`next_state`, eq. 2.2 with the dynamic ratio). While the object is
  occluded (``r > revealed_below``) the ideal offset is ``o_max`` and the offset moves toward it
  at ``s = s_u·(o_max − offset)·r^p``; ``p = 1`` is the thesis's ratio, the default is 1/2
  (below). One frame adds
  ``s·dt``; the offset stays in ``[0, o_max]``. The first frame that finds the object revealed
  halts the movement and makes the current offset the ideal one (the thesis's "setting the
  current offset as the ideal offset"): from rest the offset therefore rises monotonically and
  stops within one step of the reveal offset (no step is longer than ``s_u·dt·o_max``). A
  released state (:func:`release`, after the view or the plane changed) collapses toward 0 at
  ``s = s_u·(0 − offset)`` while the object stays revealed, and grows again once it is
  occluded.
* **Ratio exponent** ``p`` (beyond the thesis). Where the halves slide off the object at a
  steady rate, ``r`` falls linearly to 0 at the reveal offset ``o*``; a speed proportional to
  ``r`` then approaches ``o*`` only exponentially (``o* − offset`` shrinks by a constant factor
  per frame), so the last percent of the object takes most of the frames. With ``p < 1`` the
  speed falls as ``(o* − offset)^p`` and the offset arrives in a finite number of frames
  (``p = 1/2``: ``o' = c·√(o* − o)`` reaches ``o*`` at ``2·√(o*)/c``), still decelerating.
* **Maximum offset.** ``o_max`` is the assembly's bounding-box diagonal (:func:`o_max_of`), so
  the halves never separate by more than twice the assembly's diameter.
* **Ghosting** (:func:`ghost_alpha`, eq. 2.3). Above ``ghost_start·o_max`` the front half fades
  linearly from opaque to half transparent at ``o_max``, the fade scaled by ``r``.
* **Front half and culling** (:func:`front_sign`, :func:`cull_back_faces`).
* **Split planes** (:func:`auto_plane`, :func:`manual_plane`) through the object's bounding-box
  centre, automatic ones chosen by a geometric estimate of the reveal offset
  (:func:`reveal_offset`).
* A **uniform explosion** (:func:`uniform_explosion`), every part pushed away from the assembly
  centre by the same distance, for comparison.

Lengths (offsets, ``o_max``, distances, displacements) are model units; ``dt`` is seconds per
frame and ``speed`` (``s_u``) is per second. Every refusal is a ValueError with one line.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

AXES = {"x": (1.0, 0.0, 0.0), "y": (0.0, 1.0, 0.0), "z": (0.0, 0.0, 1.0)}


# ---------------------------------------------------------------------------- validation
def _vector(v, name: str) -> np.ndarray:
    a = np.asarray(v, dtype=np.float64)
    if a.shape != (3,):
        raise ValueError(f"{name} must be a 3-vector, got shape {a.shape}")
    if not np.isfinite(a).all():
        raise ValueError(f"{name} must be finite, got {a.tolist()}")
    return a


def _unit(v, name: str) -> np.ndarray:
    a = _vector(v, name)
    n = float(np.linalg.norm(a))
    if n == 0.0 or not math.isfinite(n):
        raise ValueError(f"{name} must be a non-zero vector, got {a.tolist()}")
    return a / n


def _points(points, name: str) -> np.ndarray:
    a = np.asarray(points, dtype=np.float64)
    if a.ndim == 1 and a.shape == (3,):
        a = a[None, :]
    if a.ndim != 2 or a.shape[1] != 3:
        raise ValueError(f"{name} must be (N, 3), got shape {a.shape}")
    if len(a) == 0:
        raise ValueError(f"{name} is empty")
    if not np.isfinite(a).all():
        bad = np.flatnonzero(~np.isfinite(a).all(axis=1))
        raise ValueError(f"{name} must be finite, non-finite rows {bad[:5].tolist()}")
    return a


def _scalar(x, name: str) -> float:
    v = float(x)
    if not math.isfinite(v):
        raise ValueError(f"{name} must be finite, got {x}")
    return v


def _ratio(r) -> float:
    v = float(r)
    if not (0.0 <= v <= 1.0):  # also refuses NaN
        raise ValueError(f"occlusion ratio r must be in [0, 1], got {r}")
    return v


def _centre(points: np.ndarray) -> np.ndarray:
    return 0.5 * (points.min(axis=0) + points.max(axis=0))


# ---------------------------------------------------------------------------- types
@dataclass(frozen=True, eq=False)
class SplitPlane:
    """The plane through ``point`` (3,) with unit ``normal`` (3,), float64, model units.

    The normal is normalised on construction; a zero or non-finite normal or point is refused.
    The "+" half is the side the normal points to (signed distance > 0).
    """

    point: np.ndarray
    normal: np.ndarray

    def __post_init__(self) -> None:
        point = _vector(self.point, "split plane point")
        normal = _unit(self.normal, "split plane normal")
        point.flags.writeable = False
        normal.flags.writeable = False
        object.__setattr__(self, "point", point)
        object.__setattr__(self, "normal", normal)

    def signed_distance(self, points) -> np.ndarray:
        """(N,) float64 signed distances (model units) of ``points`` (N, 3) or (3,) from the
        plane, positive on the normal's side; a single point gives a 0-d array. Non-finite
        points are refused."""
        a = np.asarray(points, dtype=np.float64)
        single = a.shape == (3,)
        p = _points(a, "points")
        d = (p - self.point) @ self.normal
        return d[0] if single else d


@dataclass(frozen=True)
class ExplodeSettings:
    """Parameters of the explosion.

    ``o_max``: largest offset of either half (model units, > 0; see :func:`o_max_of`).
    ``speed``: ``s_u`` of eq. 2.2 (per second, ≥ 0). ``dt``: seconds per frame (≥ 0).
    ``ghost_start``: fraction of ``o_max`` above which the front half fades (0.7 in the thesis;
    in [0, 1)). ``revealed_below``: ``r`` at or below which the object counts as fully revealed
    (in [0, 1)). ``ratio_exponent``: ``p`` in the growth speed ``s_u·Δoffset·r^p`` (in (0, 1];
    1 is the thesis, the default 0.5 arrives in finitely many frames). Anything else is
    refused.
    """

    o_max: float
    speed: float = 1.0
    dt: float = 0.1
    ghost_start: float = 0.7
    revealed_below: float = 0.0
    ratio_exponent: float = 0.5

    def __post_init__(self) -> None:
        o_max = _scalar(self.o_max, "o_max")
        if o_max <= 0.0:
            raise ValueError(f"o_max must be > 0 (model units), got {self.o_max}")
        if _scalar(self.speed, "speed") < 0.0:
            raise ValueError(f"speed must be >= 0, got {self.speed}")
        if _scalar(self.dt, "dt") < 0.0:
            raise ValueError(f"dt must be >= 0 (seconds per frame), got {self.dt}")
        if not 0.0 <= _scalar(self.ghost_start, "ghost_start") < 1.0:
            raise ValueError(f"ghost_start must be in [0, 1), got {self.ghost_start}")
        if not 0.0 <= _scalar(self.revealed_below, "revealed_below") < 1.0:
            raise ValueError(f"revealed_below must be in [0, 1), got {self.revealed_below}")
        if not 0.0 < _scalar(self.ratio_exponent, "ratio_exponent") <= 1.0:
            raise ValueError(f"ratio_exponent must be in (0, 1], got {self.ratio_exponent}")

    @property
    def max_step(self) -> float:
        """The longest single step of :func:`next_state`, ``speed·dt·o_max`` (model units)."""
        return self.speed * self.dt * self.o_max


PHASES = ("collapse", "grow", "hold")


@dataclass(frozen=True)
class ExplodeState:
    """The animation state: current ``offset`` of each half (model units), the ``ideal``
    offset it moves toward, the ``phase`` and the ``frame`` count.

    ``phase``: ``"grow"`` while the object is occluded (ideal ``o_max``), ``"hold"`` once a
    growing explosion has revealed it (ideal = the held offset), ``"collapse"`` at rest or after
    :func:`release` (ideal 0 while revealed). An unknown phase is refused.
    """

    offset: float = 0.0
    ideal: float = 0.0
    frame: int = 0
    phase: str = "collapse"

    def __post_init__(self) -> None:
        if self.phase not in PHASES:
            raise ValueError(f"phase must be one of {PHASES}, got {self.phase!r}")


# ---------------------------------------------------------------------------- dynamics
def occlusion_ratio(p_unoccluded, p_occluded) -> float:
    """``r = (p_unocc − p_occ)/p_unocc`` (eq. 2.1) from the two pixel counts, clamped to
    [0, 1] (a few more pixels with the halves than alone counts as unoccluded). An object with
    no pixels at all (off screen) gives 0: there is nothing to reveal. Negative or non-finite
    counts are refused."""
    pu = _scalar(p_unoccluded, "p_unoccluded")
    po = _scalar(p_occluded, "p_occluded")
    if pu < 0 or po < 0:
        raise ValueError(f"pixel counts must be >= 0, got {p_unoccluded}, {p_occluded}")
    if pu == 0:
        return 0.0
    return float(min(1.0, max(0.0, (pu - po) / pu)))


def next_state(state: ExplodeState, r, settings: ExplodeSettings) -> ExplodeState:
    """The state one frame later given this frame's occlusion ratio ``r`` in [0, 1].

    Occluded (``r > revealed_below``): phase ``"grow"``, ideal ``o_max``,
    ``s = speed·(o_max − offset)·r^p`` (``p`` = ``ratio_exponent``).
    Revealed after growing or holding: phase ``"hold"``, the offset stays and becomes the ideal.
    Revealed otherwise (at rest, or released): phase ``"collapse"``, ideal 0,
    ``s = speed·(0 − offset)`` (no factor ``r``, which is ~0 there).
    The new offset is ``offset + s·dt`` clipped to ``[0, o_max]`` (an incoming offset outside
    that range, e.g. after ``o_max`` shrank, is clipped first); ``frame`` counts up by one.

    With an occlusion that falls to 0 at a reveal offset ``o*`` the offset rises monotonically
    from rest and halts at the first revealing step, within one step (``speed·dt·o_max`` at
    most) above ``o*``. If the object is never revealed the offset approaches ``o_max``
    monotonically (for ``speed·dt ≤ 1``). ``r`` outside [0, 1] or NaN is refused.
    """
    rr = _ratio(r)
    offset = min(max(_scalar(state.offset, "offset"), 0.0), settings.o_max)
    frame = int(state.frame) + 1
    if rr > settings.revealed_below:
        s = settings.speed * (settings.o_max - offset) * rr ** settings.ratio_exponent
        new = min(max(offset + s * settings.dt, 0.0), settings.o_max)
        return ExplodeState(offset=float(new), ideal=float(settings.o_max), frame=frame,
                            phase="grow")
    if state.phase in ("grow", "hold"):
        return ExplodeState(offset=float(offset), ideal=float(offset), frame=frame, phase="hold")
    new = min(max(offset - settings.speed * offset * settings.dt, 0.0), settings.o_max)
    return ExplodeState(offset=float(new), ideal=0.0, frame=frame, phase="collapse")


def release(state: ExplodeState) -> ExplodeState:
    """``state`` set to collapse while the object stays revealed (phase ``"collapse"``, ideal
    0): what a change of view or split plane calls for, so that an explosion larger than the
    new view needs shrinks back until the object is just revealed again."""
    return ExplodeState(offset=state.offset, ideal=0.0, frame=state.frame, phase="collapse")


def ghost_alpha(offset, settings: ExplodeSettings, r=1.0) -> float:
    """Opacity in [0.5, 1] of the front half at ``offset`` (model units) for occlusion ``r``.

    Eq. 2.3: α = 1 up to ``ghost_start·o_max``; above it falls linearly,
    ``α = (o_max − o)/((1 − ghost_start)·o_max)·0.5 + 0.5`` (1 at 0.7·o_max, 0.5 at o_max
    with the thesis's 0.7); offsets past ``o_max`` are taken as ``o_max``.

    The thesis then multiplies α by ``r`` "so that the object stays solid while it's not
    occluding anything and is most translucent if the whole object is occluded". Taken
    literally α·r would make the half vanish exactly when it occludes nothing, the opposite of
    the stated intent; this function scales the *translucency* by ``r`` instead:
    ``opacity = 1 − (1 − α)·r`` (solid at r = 0, α at r = 1). Negative or non-finite offsets
    and ``r`` outside [0, 1] are refused.
    """
    o = _scalar(offset, "offset")
    if o < 0.0:
        raise ValueError(f"offset must be >= 0, got {offset}")
    rr = _ratio(r)
    o = min(o, settings.o_max)
    start = settings.ghost_start * settings.o_max
    if o <= start:
        alpha = 1.0
    else:
        alpha = (settings.o_max - o) / ((1.0 - settings.ghost_start) * settings.o_max) * 0.5 + 0.5
    return float(1.0 - (1.0 - alpha) * rr)


def front_sign(plane: SplitPlane, offset, eye) -> int:
    """+1 when the half on the normal's side is the front half (between the viewer and the
    split plane), −1 otherwise: the sign of ``normal·(eye − point)`` for the original plane,
    +1 for an eye exactly on it. The front half is drawn last and translucently.

    ``eye`` (3,) is the camera position in model units; for an orthographic camera pass a point
    far back along the view direction (``point − 1e6·o_max·view_dir``). ``offset`` does not
    change the answer (the thesis decides on the original plane) and is only checked to be
    finite and ≥ 0. Non-finite input is refused.
    """
    o = _scalar(offset, "offset")
    if o < 0.0:
        raise ValueError(f"offset must be >= 0, got {offset}")
    e = _vector(eye, "eye")
    return 1 if float((e - plane.point) @ plane.normal) >= 0.0 else -1


def cull_back_faces(plane: SplitPlane, offset, eye, side: int) -> bool:
    """Whether the back faces of the half on ``side`` (+1: the normal's side, −1: the other)
    may be culled when drawn translucently.

    The half occupies the region beyond its translated plane ``point + side·offset·normal``.
    Culling is safe when the camera lies on the half's own side of that plane
    (``side·normal·(eye − point) ≥ offset``): the half's open cut faces away from the camera,
    so its back faces would only show through its translucent surface. It is not safe when the
    camera lies between the original and the translated plane (``0 < side·d < offset``), where
    the camera looks into the cut — the thesis's case — nor for the back half (``side·d ≤ 0``),
    whose cut opens toward the camera. ``side`` other than ±1, a negative offset and non-finite
    input are refused.
    """
    if side not in (1, -1):
        raise ValueError(f"side must be +1 or -1, got {side}")
    o = _scalar(offset, "offset")
    if o < 0.0:
        raise ValueError(f"offset must be >= 0, got {offset}")
    e = _vector(eye, "eye")
    d = float((e - plane.point) @ plane.normal)
    return bool(side * d >= o)


# ---------------------------------------------------------------------------- planes
def o_max_of(mesh_or_bounds) -> float:
    """The maximum offset: the diagonal (model units) of the assembly's axis-aligned bounding
    box. Takes a scene (its ``bounds()``: an FEMesh's reference nodes) or a ``(lo, hi)`` pair
    of 3-vectors. A zero or non-finite diagonal is refused."""
    if isinstance(mesh_or_bounds, (tuple, list, np.ndarray)):
        b = np.asarray(mesh_or_bounds, dtype=np.float64)
        if b.shape != (2, 3):
            raise ValueError(f"bounds must be a (lo, hi) pair of 3-vectors, got shape {b.shape}")
        lo, hi = b
    else:
        lo, hi = mesh_or_bounds.bounds()
    lo, hi = _vector(lo, "bounds lo"), _vector(hi, "bounds hi")
    diagonal = float(np.linalg.norm(hi - lo))
    if diagonal <= 0.0:
        raise ValueError("the assembly's bounding box is a single point: o_max would be 0")
    return diagonal


def reveal_offset(object_points, plane: SplitPlane, view_dir) -> float:
    """A geometric estimate (model units) of the offset at which neither half covers the
    object any more.

    On screen the halves slide along ``n⊥``, the part of the normal perpendicular to the view,
    by ``|n⊥|`` per unit of offset. Geometry of a half may overlap the whole silhouette, so the
    half has to slide by the object's full extent along ``n⊥``:
    ``o* ≈ (max u − min u)/|n⊥|`` with ``u`` the object's points projected on ``n⊥/|n⊥|``
    (both sides of the plane together); ``inf`` when the normal is parallel to the view
    (the halves then only move in depth). This ignores perspective and the halves' actual
    shape: it ranks candidate planes, it is not the measured answer (that is ``r``).
    Empty or non-finite points and a zero view direction are refused.
    """
    p = _points(object_points, "object points")
    v = _unit(view_dir, "view direction")
    n_perp = plane.normal - float(plane.normal @ v) * v
    length = float(np.linalg.norm(n_perp))
    if length < 1e-12:
        return math.inf
    u = p @ (n_perp / length)
    return float((u.max() - u.min()) / length)


def _canonical(n: np.ndarray) -> np.ndarray:
    """The unit vector ``n`` with its largest-magnitude component made positive."""
    n = n / np.linalg.norm(n)
    return -n if n[int(np.argmax(np.abs(n)))] < 0 else n


def _principal_axes(points: np.ndarray) -> list[np.ndarray]:
    if len(points) < 2:
        return []
    _, vecs = np.linalg.eigh(np.cov(points.T))
    return [vecs[:, i] for i in range(3)]


def auto_plane(object_points, assembly_points, view_dir, *, reject_deg: float = 20.0) -> SplitPlane:
    """The split plane through the object's bounding-box centre whose normal minimises
    :func:`reveal_offset`.

    Candidate normals: the principal axes (covariance eigenvectors) of the object's points, of
    the assembly's points, and the coordinate axes; those within ``reject_deg`` degrees of the
    view direction (either sign) are rejected, since their halves would have to move mostly in
    depth. Ties go to the earlier candidate in that order; the normal's largest component is
    made positive. Refused: every candidate rejected, ``reject_deg`` outside [0, 90), empty or
    non-finite points, a zero view direction.
    """
    obj = _points(object_points, "object points")
    asm = _points(assembly_points, "assembly points")
    v = _unit(view_dir, "view direction")
    reject = _scalar(reject_deg, "reject_deg")
    if not 0.0 <= reject < 90.0:
        raise ValueError(f"reject_deg must be in [0, 90), got {reject_deg}")
    centre = _centre(obj)
    cos_reject = math.cos(math.radians(reject))
    candidates = _principal_axes(obj) + _principal_axes(asm) + [np.array(a) for a in AXES.values()]
    best, best_offset = None, math.inf
    for n in candidates:
        n = _canonical(np.asarray(n, dtype=np.float64))
        if abs(float(n @ v)) >= cos_reject:
            continue
        o = reveal_offset(obj, SplitPlane(centre, n), v)
        if best is None or o < best_offset - 1e-12 * max(1.0, abs(best_offset)):
            best, best_offset = n, o
    if best is None:
        raise ValueError(f"every candidate normal lies within {reject} degrees of the view "
                         "direction")
    return SplitPlane(centre, best)


def manual_plane(spec, object_points) -> SplitPlane:
    """The split plane through the object's bounding-box centre with the normal ``spec``:
    ``"x"``, ``"y"`` or ``"z"`` (any case) or three numbers ``(a, b, c)`` (normalised).
    Refused: an unknown spec, a zero or non-finite normal, empty or non-finite points."""
    obj = _points(object_points, "object points")
    if isinstance(spec, str):
        key = spec.strip().lower()
        if key not in AXES:
            raise ValueError(f"unknown split plane {spec!r}: expected 'x', 'y', 'z' or (a, b, c)")
        normal = np.array(AXES[key])
    else:
        try:
            normal = np.asarray(spec, dtype=np.float64)
        except (TypeError, ValueError):
            raise ValueError(f"unknown split plane {spec!r}: expected 'x', 'y', 'z' or "
                             "(a, b, c)") from None
        if normal.shape != (3,):
            raise ValueError(f"unknown split plane {spec!r}: expected 'x', 'y', 'z' or (a, b, c)")
    return SplitPlane(_centre(obj), normal)


# ---------------------------------------------------------------------------- positions
def point_sides(plane: SplitPlane, points) -> np.ndarray:
    """(N,) int8: +1 for points on the normal's side or on the plane, −1 on the other side."""
    return np.where(plane.signed_distance(np.atleast_2d(points)) >= 0.0, 1, -1).astype(np.int8)


def explode_positions(points, sides, offset, plane: SplitPlane) -> np.ndarray:
    """(N, 3) float64 ``points + sides·offset·normal``: each point moved with its half.
    ``sides`` (N,) holds +1 or −1 per point (0 keeps a point in place, as for the object of
    interest); ``offset`` in model units, ≥ 0. Other side values, a shape mismatch and
    non-finite input are refused."""
    p = _points(points, "points")
    s = np.asarray(sides)
    if s.shape != (len(p),):
        raise ValueError(f"sides must be ({len(p)},), got shape {s.shape}")
    if not np.isin(s, (-1, 0, 1)).all():
        raise ValueError("sides must be +1, -1 (or 0 for points that stay)")
    o = _scalar(offset, "offset")
    if o < 0.0:
        raise ValueError(f"offset must be >= 0, got {offset}")
    return p + s.astype(np.float64)[:, None] * (o * plane.normal)[None, :]


def uniform_explosion(part_centres, assembly_centre, displacement) -> np.ndarray:
    """(P, 3) float64 translations pushing every part away from ``assembly_centre`` by the
    same distance ``displacement`` (model units, ≥ 0) along the direction from the assembly
    centre to the part's centre; a part centred on the assembly centre stays (zero vector).
    Non-finite input and a negative displacement are refused."""
    c = _points(part_centres, "part centres")
    centre = _vector(assembly_centre, "assembly centre")
    d = _scalar(displacement, "displacement")
    if d < 0.0:
        raise ValueError(f"displacement must be >= 0, got {displacement}")
    delta = c - centre
    norms = np.linalg.norm(delta, axis=1)
    out = np.zeros_like(delta)
    moving = norms > 0.0
    out[moving] = delta[moving] / norms[moving, None] * d
    return out
