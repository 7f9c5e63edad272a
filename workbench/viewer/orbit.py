"""The interactive camera: orbit about a scene's box centre, pan in the view plane, zoom; float64,
no GL.

An :class:`Orbit` is the immutable state of a live view of the box ``lo``–``hi`` (model units):
azimuth and elevation in degrees (the convention of :class:`~workbench.gl.Camera`), a zoom
factor, a pan offset in the view plane and the image size. :meth:`Orbit.camera` turns it into a
:class:`~workbench.gl.Camera`:

* eye, target, up, near and far are those of :meth:`Camera.fit` on the box's bounding sphere at
  the current angles, so an orbit turns the eye about the box centre at a fixed distance and
  the sphere always lies between the near and far planes;
* the extent at zoom 1 is the one :meth:`Camera.fit_box` fits at the *initial* angles
  (``fit_angles``), kept while orbiting so that the image scale does not jump with the view;
  zoom ``z`` divides the orthographic half height by ``z`` (a perspective camera narrows its
  field of view to the same effect), the target fixed;
* the pan ``(right, up)`` (model units) moves eye and target together along the image's right
  and up axes: the box centre then shows that far from the image centre, against the pan.

The ``…ed`` methods return a new state; the pixel-based ones (:meth:`Orbit.dragged`,
:meth:`Orbit.panned`, :meth:`Orbit.wheeled`) translate pointer motion in image pixels: a drag
across the image height turns the view by 180°, a pan drag keeps the point under the pointer
(at the target's depth) under it, and wheel units zoom by a factor 2 per
:data:`WHEEL_PER_DOUBLING`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np

from ..gl import Camera
from ..gl.camera import PROJECTIONS, check_resolvable, up_frame

if TYPE_CHECKING:
    from numpy.typing import ArrayLike

DEGREES_PER_HEIGHT = 180.0  # a drag across the image height turns the view by this much
WHEEL_PER_DOUBLING = 400.0  # wheel units (CSS pixels; one notch is ~100) that zoom by 2


def _vector3(values: ArrayLike, name: str) -> tuple[float, float, float]:
    array = np.asarray(values, np.float64)
    if array.shape != (3,):
        raise ValueError(f"{name} must be 3 numbers, got shape {array.shape}")
    return tuple(float(v) for v in array)


def _finite(value: float, name: str) -> float:
    value = float(value)
    if not math.isfinite(value):
        raise ValueError(f"{name} must be finite, got {value}")
    return value


@dataclass(frozen=True)
class Orbit:
    """A view of the box ``lo``–``hi``: ``azimuth``/``elevation`` (degrees), ``zoom`` (> 0),
    ``pan`` (right, up; model units), ``size`` (W, H pixels), ``projection``, ``up`` ("y" or
    "z") and ``fit_angles`` (the azimuth and elevation the zoom-1 extent is fitted at).

    Refused with ValueError: a box :func:`~workbench.gl.camera.check_resolvable` refuses,
    non-finite angles or pan, a zoom that is not positive and finite, a size that is not two
    positive integers, an unknown projection or up axis.
    """

    lo: tuple[float, float, float]
    hi: tuple[float, float, float]
    azimuth: float = 30.0
    elevation: float = 25.0
    zoom: float = 1.0
    pan: tuple[float, float] = (0.0, 0.0)
    size: tuple[int, int] = (800, 600)
    projection: str = "orthographic"
    up: str = "z"
    fit_angles: tuple[float, float] = (30.0, 25.0)

    def __post_init__(self) -> None:
        lo, hi = _vector3(self.lo, "lo"), _vector3(self.hi, "hi")
        check_resolvable(lo, hi)
        object.__setattr__(self, "lo", lo)
        object.__setattr__(self, "hi", hi)
        for name in ("azimuth", "elevation"):
            object.__setattr__(self, name, _finite(getattr(self, name), name))
        zoom = _finite(self.zoom, "zoom")
        if zoom <= 0:
            raise ValueError(f"zoom must be positive, got {zoom}")
        object.__setattr__(self, "zoom", zoom)
        pan = tuple(_finite(v, "pan") for v in self.pan)
        if len(pan) != 2:
            raise ValueError(f"pan must be 2 numbers (right, up), got {self.pan}")
        object.__setattr__(self, "pan", pan)
        size = tuple(int(v) for v in self.size)
        if len(size) != 2 or min(size) <= 0 or size != tuple(self.size):
            raise ValueError(f"size must be two positive integers (W, H), got {self.size}")
        object.__setattr__(self, "size", size)
        object.__setattr__(self, "fit_angles",
                           tuple(_finite(v, "fit_angles") for v in self.fit_angles))
        if self.projection not in PROJECTIONS:
            raise ValueError(f"projection must be one of {PROJECTIONS}, got {self.projection!r}")
        up_frame(self.up)  # refuses an unknown axis

    @classmethod
    def fitted(cls, lo: ArrayLike, hi: ArrayLike, size: tuple[int, int], *,
               angles: tuple[float, float] = (30.0, 25.0), projection: str = "orthographic",
               up: str = "z") -> Orbit:
        """The view that :meth:`Camera.fit_box` gives at ``angles`` (azimuth, elevation), no
        zoom, no pan."""
        return cls(lo, hi, azimuth=angles[0], elevation=angles[1], size=size,
                   projection=projection, up=up, fit_angles=angles)

    # ------------------------------------------------------------------ the camera
    @property
    def center(self) -> np.ndarray:
        """(3,) float64 centre of the box: the point the view orbits about."""
        return (np.array(self.lo) + np.array(self.hi)) / 2.0

    @property
    def aspect(self) -> float:
        return self.size[0] / self.size[1]

    def _fit(self, azimuth: float, elevation: float, box: bool) -> Camera:
        lo, hi = np.array(self.lo), np.array(self.hi)
        options = dict(azimuth=azimuth, elevation=elevation, projection=self.projection,
                       aspect=self.aspect, up=self.up)
        if box:
            return Camera.fit_box(lo, hi, **options)
        return Camera.fit((lo + hi) / 2.0, float(np.linalg.norm(hi - lo) / 2.0), **options)

    def camera(self) -> Camera:
        """The float64 camera of this state (origin: the box centre)."""
        base = self._fit(*self.fit_angles, box=True)
        camera = self._fit(self.azimuth, self.elevation, box=False)
        if self.projection == "orthographic":
            camera.half_height = base.half_height / self.zoom
        else:
            half = math.radians(base.fov_deg) / 2.0
            camera.fov_deg = math.degrees(2.0 * math.atan(math.tan(half) / self.zoom))
        if self.pan != (0.0, 0.0):
            view = camera.view_matrix()
            shift = self.pan[0] * view[0, :3] + self.pan[1] * view[1, :3]
            camera.eye = np.asarray(camera.eye, np.float64) + shift
            camera.target = np.asarray(camera.target, np.float64) + shift
        return camera

    def pixel_size(self) -> float:
        """Model units per image pixel at the target's depth."""
        camera = self.camera()
        if self.projection == "orthographic":
            return 2.0 * camera.half_height / self.size[1]
        distance = float(np.linalg.norm(np.asarray(camera.eye) - np.asarray(camera.target)))
        return 2.0 * distance * math.tan(math.radians(camera.fov_deg) / 2.0) / self.size[1]

    # ------------------------------------------------------------------ new states
    def orbited(self, d_azimuth: float, d_elevation: float) -> Orbit:
        """Turned about the box centre by ``d_azimuth`` and ``d_elevation`` degrees."""
        return replace(self, azimuth=self.azimuth + d_azimuth,
                       elevation=self.elevation + d_elevation)

    def dragged(self, dx: float, dy: float) -> Orbit:
        """Orbited by a pointer drag of ``dx``, ``dy`` image pixels (right, down): the object
        follows the pointer, a drag across the image height turning it by 180°."""
        k = DEGREES_PER_HEIGHT / self.size[1]
        return self.orbited(-dx * k, dy * k)

    def panned(self, dx: float, dy: float) -> Orbit:
        """Panned by a pointer drag of ``dx``, ``dy`` image pixels (right, down): a point at
        the target's depth moves with the pointer."""
        pixel = self.pixel_size()
        return replace(self, pan=(self.pan[0] - dx * pixel, self.pan[1] + dy * pixel))

    def zoomed(self, factor: float) -> Orbit:
        """Zoomed in by ``factor`` (> 1 magnifies), about the target."""
        factor = _finite(factor, "zoom factor")
        if factor <= 0:
            raise ValueError(f"zoom factor must be positive, got {factor}")
        return replace(self, zoom=self.zoom * factor)

    def wheeled(self, dy: float) -> Orbit:
        """Zoomed by a wheel turn of ``dy`` units (positive: towards the user, zooming out)."""
        return self.zoomed(2.0 ** (-_finite(dy, "wheel delta") / WHEEL_PER_DOUBLING))

    def resized(self, size: tuple[int, int]) -> Orbit:
        """The same view in an image of ``size`` (W, H): the zoom-1 extent fitted anew to the
        new aspect."""
        return replace(self, size=tuple(int(v) for v in size))

    def reset(self) -> Orbit:
        """The fitted view: the initial angles, no zoom, no pan."""
        return replace(self, azimuth=self.fit_angles[0], elevation=self.fit_angles[1],
                       zoom=1.0, pan=(0.0, 0.0))
