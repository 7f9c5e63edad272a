"""st2005 spacetime scenes: the data a spacetime render path draws, and the built-in ones.

A :class:`SpacetimeScene` is a set of polygons, each showing the cubic solution of one
spacetime element: a constant-time slice of a tetrahedral spacetime mesh, or the (x, t)
triangles of a 1-D bar. The built-in scenes (:func:`spacetime_scene`, registered as
``spacetime:radial`` and ``spacetime:bar`` in :mod:`workbench.scene.builtin`) are least-squares
cubic fits of closed-form elastodynamic fields on tent-pitched meshes (st2005 §3):

* ``radial`` — a radial P pulse on a 100 mm steel plate meshed n×n cells, refined along the
  front, sliced at t = 5 µs (``cells`` per side, default 28, 12 quick: ~10⁴ and ~2·10³
  polygons);
* ``bar`` — the st2005 Fig. 3 bar: 100 mm, fixed at x = 0, its whole (x, t) spacetime.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from ...scene.builtin import builtin
from .fields import BAR, STEEL, RadialPulse, ReflectingWave
from .mesh import front_refined, interval_mesh, rect_triangulation
from .poly import evaluate, fit_cubic, local_frames
from .slicing import Slice, polygon_areas, quadrisect, slice_at

DOMAIN = 100.0  # mm, the square plate
PULSE = dict(centre=(30.0, 35.0), a=2.0, t0=2.0)
T_SLICE = 5.0  # µs: the ring is ~40 mm out
SCENES = ("radial", "bar")


@dataclass
class SpacetimeScene:
    """What a spacetime path draws: polygons, each with the element whose solution it shows.

    corners: (P, 4, 2) float64 convex polygons, a triangle repeating its third corner — (x, y)
    in mm of a slice at time ``t`` (µs), or (x, t) spacetime triangles of a 1-D bar with
    ``t=None``. element: (P,) indices into the solution arrays: ``coeffs`` (M, 20, 2)
    displacement coefficients in element-local coordinates, ``centre`` and ``extent`` (M, 3)
    float64 local frames in (x, y, t), and ``lam``/``mu`` the Lamé constants in GPa. outer:
    (P, 4) bool, edge k (corner k to k + 1) on the domain boundary, where edge overdraw draws
    nothing (:attr:`workbench.algo.spacetime.slicing.Slice.outer`); None: every edge is
    treated as shared. name: how tables name the scene.
    """

    corners: np.ndarray
    element: np.ndarray
    coeffs: np.ndarray
    centre: np.ndarray
    extent: np.ndarray
    lam: float
    mu: float
    t: float | None = None
    outer: np.ndarray | None = None
    name: str = "spacetime"

    kind: ClassVar[str] = "spacetime"

    @property
    def is_bar(self) -> bool:
        return self.t is None

    def check(self) -> None:
        """ValueError for inconsistent shapes, an empty scene, element indices out of range,
        non-positive extents or non-finite corners, coefficients or centres."""
        P = len(self.corners)
        if self.corners.shape != (P, 4, 2) or self.element.shape != (P,):
            raise ValueError(f"corners must be (P, 4, 2) and element (P,), got "
                             f"{self.corners.shape} and {self.element.shape}")
        if P == 0:
            raise ValueError("nothing to draw: the scene has no polygons")
        M = len(self.coeffs)
        if (self.coeffs.shape != (M, 20, 2) or self.centre.shape != (M, 3)
                or self.extent.shape != (M, 3)):
            raise ValueError("coeffs must be (M, 20, 2), centre and extent (M, 3)")
        if self.element.min() < 0 or self.element.max() >= M:
            raise ValueError(f"element indices must lie in [0, {M})")
        if not np.isfinite(self.corners).all():
            raise ValueError("polygon corners must be finite")
        outer = self.outer
        if outer is not None and (np.shape(outer) != (P, 4) or np.asarray(outer).dtype != bool):
            raise ValueError(f"outer must be (P, 4) bool, got {np.shape(self.outer)}")
        used = np.unique(self.element)
        if (self.extent[used] <= 0).any():
            raise ValueError("element extents must be positive")
        if not (np.isfinite(self.coeffs[used]).all() and np.isfinite(self.centre[used]).all()):
            raise ValueError("element coefficients and centres must be finite")

    def max_speed(self) -> float:
        """The largest velocity magnitude at the polygon corners (mm/µs); 0 for the bar, which
        is drawn flat in (x, t)."""
        if self.is_bar:
            return 0.0
        c = self.corners.reshape(-1, 2)
        speed = evaluate(self.coeffs, self.centre, self.extent, np.repeat(self.element, 4),
                         c[:, 0], c[:, 1], self.t)["speed"]
        return float(speed.max())

    def quadrisected(self, fraction: float) -> SpacetimeScene:
        """The scene with every polygon larger than ``fraction`` × the mean polygon area split
        through its edge midpoints, recursively (st2005 §4.2,
        :func:`workbench.algo.spacetime.slicing.quadrisect`); children keep their element and
        outer edges. ValueError for a fraction that is not positive and finite."""
        if not (np.isfinite(fraction) and fraction > 0):
            raise ValueError(f"quadrisection fraction must be positive, got {fraction}")
        is_quad = ~np.all(self.corners[:, 3] == self.corners[:, 2], axis=1)
        s = Slice(0.0 if self.t is None else self.t, self.corners, self.element, is_quad,
                  self.outer)
        q = quadrisect(s, float(fraction) * float(polygon_areas(s).mean()))
        return SpacetimeScene(q.corners, q.element, self.coeffs, self.centre, self.extent,
                              self.lam, self.mu, t=self.t,
                              outer=None if self.outer is None else q.outer,
                              name=f"{self.name} quadrisected {fraction:g}")

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """(lo, hi) of the polygons in the drawing plane (x, y) or (x, t), float64."""
        flat = self.corners.reshape(-1, 2)
        return flat.min(axis=0), flat.max(axis=0)



@dataclass
class Solution:
    """A fitted spacetime solution: mesh, cubic coefficients, local frames and timings."""

    label: str
    mesh: object
    coeffs: np.ndarray
    centre: np.ndarray
    extent: np.ndarray
    field: object
    material: object
    mesh_s: float
    fit_s: float


def plate_solution(n: int, t_lo: float, t_hi: float, *, offset=(0.0, 0.0), bands: int = 2,
                   refine: bool = True, seed: int = 0) -> Solution:
    """The radial pulse on the plate meshed with n×n cells over [t_lo, t_hi] µs, refined along
    the front in ``bands`` bands (non-conforming at band boundaries), fitted per element."""
    offset = np.asarray(offset, np.float64)
    field = RadialPulse(origin=tuple(offset), **PULSE)
    start = time.perf_counter()
    pts, tris = rect_triangulation(n, n, size=(DOMAIN, DOMAIN), origin=tuple(offset),
                                   jitter=0.25, seed=seed)
    h = DOMAIN / n
    mesh = front_refined(pts, tris, t_hi, STEEL.p_wave_speed, t_start=t_lo, bands=bands,
                         front_distance=field.front_distance if refine else None,
                         width=1.5 * h, levels=1, rng_seed=seed)
    mesh_s = time.perf_counter() - start
    start = time.perf_counter()
    coeffs = fit_cubic(mesh.points, mesh.simplices, field.displacement)
    centre, extent = local_frames(mesh.points, mesh.simplices)
    fit_s = time.perf_counter() - start
    return Solution(f"plate {n}x{n}", mesh, coeffs, centre, extent, field, STEEL, mesh_s, fit_s)


def window(n: int, layers: float = 1.0) -> tuple[float, float]:
    """A time window about ``layers`` tent layers deep for n×n cells, with T_SLICE at 60 % of
    it — off the flat front between its two bands, which lies at 50 %."""
    depth = layers * (DOMAIN / n) / STEEL.p_wave_speed
    return T_SLICE - 0.6 * depth, T_SLICE + 0.4 * depth


def slice_scene(sol: Solution, s) -> SpacetimeScene:
    m = sol.material
    return SpacetimeScene(s.corners, s.element, sol.coeffs, sol.centre, sol.extent, m.lam, m.mu,
                          t=s.t, outer=s.outer)


def bar_scene(n: int = 24, t_end: float = 16.0):
    """The st2005 Fig. 3 bar: 100 mm, fixed at x = 0, a pulse starting at its centre, meshed in
    (x, t) by tent pitching; returns (scene, solution)."""
    field = ReflectingWave()
    pts, segs = interval_mesh(n, length=DOMAIN, jitter=0.25, seed=1)
    mesh = front_refined(pts, segs, t_end, BAR.p_wave_speed, bands=1, front_distance=None)
    coeffs = fit_cubic(mesh.points, mesh.simplices, field.displacement)
    centre, extent = local_frames(mesh.points, mesh.simplices)
    tri = mesh.points[mesh.simplices]  # (M, 3, 2) in (x, t)
    area = (tri[:, 1, 0] - tri[:, 0, 0]) * (tri[:, 2, 1] - tri[:, 0, 1]) - \
           (tri[:, 2, 0] - tri[:, 0, 0]) * (tri[:, 1, 1] - tri[:, 0, 1])
    tri[area < 0] = tri[area < 0][:, [0, 2, 1]]
    corners = np.concatenate([tri, tri[:, 2:3]], axis=1)
    scene = SpacetimeScene(corners, np.arange(len(corners)), coeffs, centre, extent,
                           BAR.lam, BAR.mu, t=None)
    sol = Solution(f"bar {n}", mesh, coeffs, centre, extent, field, BAR, 0.0, 0.0)
    return scene, sol


def spacetime_scene(name: str, cells: int | None = None, quick: bool = False) -> SpacetimeScene:
    """The built-in spacetime scene ``name`` ("radial" or "bar", see the module docstring) with
    ``cells`` space cells per side (default 28, 12 with ``quick``; 24 for the bar); KeyError
    for an unknown name, ValueError for fewer than 2 cells."""
    if name not in SCENES:
        raise KeyError(f"no spacetime scene {name!r}; built in: {', '.join(SCENES)}")
    if cells is not None and (int(cells) != cells or cells < 2):
        raise ValueError(f"a spacetime scene needs at least 2 cells per side, got {cells}")
    if name == "bar":
        n = 24 if cells is None else int(cells)
        scene = bar_scene(n)[0]
    else:
        n = (12 if quick else 28) if cells is None else int(cells)
        t_lo, t_hi = window(n)
        sol = plate_solution(n, t_lo, t_hi)
        scene = slice_scene(sol, slice_at(sol.mesh, T_SLICE, outer=True))
    scene.name = f"spacetime:{name}:{n}"
    return scene


@builtin("spacetime:radial", "st2005: a spacetime plate with a radially spreading pulse, N cells "
                             "per side", sized=True)
def radial_scene(size: int | None, quick: bool) -> SpacetimeScene:
    return spacetime_scene("radial", cells=size, quick=quick)


@builtin("spacetime:bar", "st2005: the (x, t) triangles of a 1-D bar", sized=True)
def bar_builtin(size: int | None, quick: bool) -> SpacetimeScene:
    return spacetime_scene("bar", cells=size, quick=quick)
