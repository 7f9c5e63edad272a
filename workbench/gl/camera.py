"""Cameras fitted to a bounding sphere, in float64, with a float64 upload origin.

Vertices are uploaded as float32 *relative to* ``Camera.origin`` (the scene centre), and the
matrices are composed in float64 with that origin folded in before the final cast to float32,
so that a model 10⁶ mm from the world origin keeps the precision of one at the origin.

View angles: azimuth 0 and elevation 0 look down −Z with +Y up (the eye is on the +Z side);
azimuth turns the eye about +Y towards +X, elevation lifts it towards +Y, roll turns the image
counter-clockwise about the viewing direction. Angles in degrees. With ``up="z"`` (the usual
convention of CAE models) the same angles apply to a frame turned so that +Z is up: azimuth 0
and elevation 0 then look along +Y from the −Y side.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from numpy.typing import ArrayLike

PROJECTIONS = ("orthographic", "perspective")
# columns: the world directions of the Y-up frame's x, y, z axes
_UP_FRAMES = {"y": np.eye(3), "z": np.array([[1.0, 0, 0], [0, 0, -1], [0, 1, 0]])}


def check_resolvable(lo: ArrayLike, hi: ArrayLike) -> None:
    """Refuse (ValueError) a bounding box ``lo``–``hi`` (float64, model units) that cannot be
    drawn: not finite, of zero extent, or so far from the origin that float64 coordinates
    cannot tell its points apart to 1/10 000 of its extent (they would draw as one point)."""
    lo, hi = np.asarray(lo, np.float64), np.asarray(hi, np.float64)
    if not (np.isfinite(lo).all() and np.isfinite(hi).all()):
        raise ValueError("the scene's coordinates are not finite")
    extent = float(np.max(hi - lo))
    magnitude = float(np.max(np.abs(np.concatenate([lo, hi]))))
    if extent <= 0:
        raise ValueError("the scene has zero extent: every point lies at one place")
    if np.spacing(magnitude) > 1e-4 * extent:
        raise ValueError(f"coordinates of magnitude {magnitude:.3g} are resolved to "
                         f"{np.spacing(magnitude):.3g} in float64, too coarse for a scene "
                         f"{extent:.3g} wide: translate it nearer the origin")


def up_frame(up: str) -> np.ndarray:
    """(3, 3) float64: the world directions (columns) of the Y-up frame's x, y, z axes for the
    ``up`` axis "y" or "z" (the frame :meth:`Camera.fit` turns its angles in)."""
    if up not in _UP_FRAMES:
        raise ValueError(f"up must be 'y' or 'z', got {up!r}")
    return _UP_FRAMES[up].copy()


def _look_at(eye: np.ndarray, target: np.ndarray, up: np.ndarray) -> np.ndarray:
    forward = target - eye
    forward /= np.linalg.norm(forward)
    side = np.cross(forward, up)
    side /= np.linalg.norm(side)
    true_up = np.cross(side, forward)
    view = np.eye(4)
    view[0, :3], view[1, :3], view[2, :3] = side, true_up, -forward
    view[:3, 3] = -view[:3, :3] @ eye
    return view


@dataclass
class Camera:
    """A float64 camera: eye/target/up relative to ``origin``, projection and tight near/far."""

    origin: np.ndarray
    eye: np.ndarray
    target: np.ndarray
    up: np.ndarray
    projection: str = "orthographic"
    half_height: float = 1.0  # orthographic half extent of the view, model units
    fov_deg: float = 30.0  # perspective vertical field of view
    aspect: float = 1.0  # width / height
    near: float = 0.1
    far: float = 10.0

    @classmethod
    def fit(cls, center: ArrayLike, radius: float, *, azimuth: float = 0.0,
            elevation: float = 0.0, roll: float = 0.0, projection: str = "orthographic",
            fov_deg: float = 30.0, aspect: float = 1.0, margin: float = 1.05,
            origin: ArrayLike | None = None, up: str = "y") -> Camera:
        """A camera that sees the whole sphere (``center``, ``radius``) from the given angles.

        Near and far planes enclose the sphere tightly (``margin`` times its radius); the
        upload origin defaults to the sphere centre; ``up`` is the world axis shown upwards at
        elevation 0 ("y" or "z"). Refuses a non-positive or non-finite radius.
        """
        if up not in _UP_FRAMES:
            raise ValueError(f"up must be 'y' or 'z', got {up!r}")
        if projection not in PROJECTIONS:
            raise ValueError(f"projection must be one of {PROJECTIONS}, got {projection!r}")
        if not (np.isfinite(radius) and radius > 0):
            raise ValueError(f"bounding radius must be positive and finite, got {radius}")
        center = np.asarray(center, np.float64)
        origin = center.copy() if origin is None else np.asarray(origin, np.float64)
        az, el, ro = np.radians([azimuth, elevation, roll])
        direction = np.array([np.sin(az) * np.cos(el), np.sin(el), np.cos(az) * np.cos(el)])
        # up: +Y tilted with the elevation, then rolled about the viewing direction
        up_axis = up
        up = np.array([-np.sin(az) * np.sin(el), np.cos(el), -np.cos(az) * np.sin(el)])
        side = np.cross(up, direction)
        up = np.cos(ro) * up + np.sin(ro) * side
        frame = _UP_FRAMES[up_axis]
        direction, up = frame @ direction, frame @ up
        r = radius * margin
        half_height = r if aspect >= 1.0 else r / aspect
        if projection == "orthographic":
            distance = 2.0 * r
        else:
            half_fov = np.radians(fov_deg) / 2.0
            narrow = half_fov if aspect >= 1.0 else np.arctan(np.tan(half_fov) * aspect)
            distance = r / np.sin(narrow)
        near = (max(distance - r, 1e-4 * (distance + r)) if projection == "perspective"
                else distance - r)
        return cls(origin=origin, eye=center - origin + distance * direction,
                   target=center - origin, up=up, projection=projection, half_height=half_height,
                   fov_deg=fov_deg, aspect=aspect, near=near, far=distance + r)

    @classmethod
    def fit_box(cls, lo: ArrayLike, hi: ArrayLike, **kwargs: Any) -> Camera:
        """A camera fitted to the axis-aligned box ``lo``–``hi`` (float64 corners).

        Like :meth:`fit` on the box's bounding sphere (same keywords, same near/far), but an
        orthographic view is then narrowed to the box's projected outline (times ``margin``),
        so long, flat models such as car bodies fill the image.
        """
        lo, hi = np.asarray(lo, np.float64), np.asarray(hi, np.float64)
        center, radius = (lo + hi) / 2.0, float(np.linalg.norm(hi - lo) / 2.0)
        camera = cls.fit(center, radius, **kwargs)
        if camera.projection == "orthographic":
            corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1])
                                for z in (lo[2], hi[2])]) - camera.origin
            eye = corners @ camera.view_matrix()[:3, :3].T + camera.view_matrix()[:3, 3]
            target = camera.view_matrix()[:3, :3] @ camera.target + camera.view_matrix()[:3, 3]
            half_x = np.abs(eye[:, 0] - target[0]).max()
            half_y = np.abs(eye[:, 1] - target[1]).max()
            margin = kwargs.get("margin", 1.05)
            camera.half_height = max(half_y, half_x / camera.aspect, 1e-12 * radius) * margin
        return camera

    def view_matrix(self) -> np.ndarray:
        """(4, 4) float64: coordinates relative to ``origin`` → eye space."""
        return _look_at(np.asarray(self.eye, np.float64), np.asarray(self.target, np.float64),
                        np.asarray(self.up, np.float64))

    def projection_matrix(self) -> np.ndarray:
        """(4, 4) float64 OpenGL clip-space projection."""
        n, f = self.near, self.far
        proj = np.zeros((4, 4))
        if self.projection == "orthographic":
            h, w = self.half_height, self.half_height * self.aspect
            proj[0, 0], proj[1, 1], proj[2, 2] = 1.0 / w, 1.0 / h, -2.0 / (f - n)
            proj[2, 3], proj[3, 3] = -(f + n) / (f - n), 1.0
        else:
            t = 1.0 / np.tan(np.radians(self.fov_deg) / 2.0)
            proj[0, 0], proj[1, 1] = t / self.aspect, t
            proj[2, 2], proj[2, 3] = -(f + n) / (f - n), -2.0 * f * n / (f - n)
            proj[3, 2] = -1.0
        return proj

    def mvp(self) -> np.ndarray:
        """(4, 4) float64 view-projection for coordinates relative to ``origin``."""
        return self.projection_matrix() @ self.view_matrix()

    def mvp_bytes(self) -> bytes:
        """The view-projection as float32 column-major bytes for a ``mat4`` uniform."""
        return self.mvp().T.astype(np.float32).tobytes()

    def view_bytes(self) -> bytes:
        """The view matrix as float32 column-major bytes for a ``mat4`` uniform."""
        return self.view_matrix().T.astype(np.float32).tobytes()

    def relative(self, points: ArrayLike) -> np.ndarray:
        """float32 coordinates relative to ``origin``: what is uploaded for float64 ``points``."""
        return (np.asarray(points, np.float64) - self.origin).astype(np.float32)

    def project(self, points: ArrayLike, size: tuple[int, int]) -> np.ndarray:
        """(N, 3) float64 window coordinates (x right, y down from the top, depth in [0, 1]).

        Pixel (i, j) of a read-back image covers x in [j, j+1), y in [i, i+1); its centre is
        (j + 0.5, i + 0.5).
        """
        rel = np.asarray(points, np.float64) - self.origin
        clip = np.c_[rel, np.ones(len(rel))] @ self.mvp().T
        ndc = clip[:, :3] / clip[:, 3:4]
        width, height = size
        return np.c_[(ndc[:, 0] + 1) * width / 2, (1 - ndc[:, 1]) * height / 2, (ndc[:, 2] + 1) / 2]
