"""One point of a sweep: what it names (:class:`Point`) and what a worker does to measure it
(:func:`run_point`).

A point loads a fresh copy of its scene (so ``derive_ms``/``derive_bytes`` do not depend on
which points a worker ran before), optionally simplifies it, draws it with its path through
:func:`workbench.measurement.rows.measure` (timed under the host's draw lock, or once
untimed) and compares the image with the reference path's image of the unsimplified scene
with the same options. Simplification, the certified Hausdorff distance and the reference
image are error-only work and take no lock.
"""

from __future__ import annotations

import json
import socket
import time
from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np

# simplifier names a grid may use: ours, the references of workbench.references.simplifiers,
# and "none" (the scene as it is: Hausdorff distance 0)
OURS = "ours"
NO_SIMPLIFIER = "none"
# width of the Hausdorff bracket, share of the original's bounding-box diagonal
HAUSDORFF_BRACKET = 1e-6


def simplifier_names() -> tuple[str, ...]:
    """Every simplifier a grid may name: "none", "ours" (Hausdorff-bounded decimation), then
    the reference simplifiers of :data:`workbench.references.simplifiers.SIMPLIFIERS`."""
    from ..references.simplifiers import SIMPLIFIERS

    return (NO_SIMPLIFIER, OURS, *SIMPLIFIERS)


@dataclass(frozen=True)
class Point:
    """One grid point: ``scene`` (built-in name or mesh file), ``path`` (registry name),
    ``options`` (the style options this path takes, by name), ``size`` (W, H) pixels,
    ``samples`` (MSAA), ``view`` (azimuth, elevation in degrees), ``simplifier`` and
    ``tolerance`` (% of each part's bounding-sphere diameter; both None without
    simplification), ``quadrisection`` (a spacetime scene's polygons split down to this fraction
    of their mean area, None: not split), ``reference`` (path name whose image gives the error,
    or None) with ``reference_options`` (the grid's options that path takes), ``repeats``
    (timed draws), ``timed`` and ``quick`` (smaller built-in scenes), ``rasterizer`` ("gl", or
    "software": the es2008 rasterizer draws the path,
    :class:`~workbench.paths.software.SoftwarePath`).
    ``index`` is the position in the grid.
    """

    index: int
    scene: str
    path: str
    options: dict = field(default_factory=dict)
    size: tuple[int, int] = (400, 300)
    samples: int = 0
    view: tuple[float, float] = (30.0, 25.0)
    simplifier: str | None = None
    tolerance: float | None = None
    quadrisection: float | None = None
    reference: str | None = None
    reference_options: dict = field(default_factory=dict)
    repeats: int = 7
    timed: bool = True
    quick: bool = False
    rasterizer: str = "gl"

    def params(self) -> dict:
        """Everything that decides the point's result, as plain JSON values (lists, not tuples);
        ``rasterizer`` only when it is not GL (the keys of GL points predate it)."""
        extra = {} if self.rasterizer == "gl" else {"rasterizer": self.rasterizer}
        return json.loads(json.dumps(dict(**extra,
            scene=self.scene, path=self.path, options=self.options, size=list(self.size),
            samples=self.samples, view=list(self.view), simplifier=self.simplifier,
            tolerance=self.tolerance, quadrisection=self.quadrisection, reference=self.reference,
            reference_options=self.reference_options if self.reference else {},
            repeats=self.repeats if self.timed else None, timed=self.timed, quick=self.quick)))

    def columns(self) -> dict:
        """The point's own table columns: index, scene, path, rasterizer, its options, size,
        samples and view (every grid key, so that no two points' rows look alike), and the
        simplifier and tolerance when it has them. Sequence values are written compactly."""
        row = dict(point=self.index, scene=self.scene, path=self.path,
                   rasterizer=self.rasterizer)
        row.update({k: cell_value(v) for k, v in self.options.items()})
        row["size"] = f"{self.size[0]}x{self.size[1]}"
        row.update(samples=self.samples, view=cell_value(list(self.view)))
        if self.simplifier is not None:
            row.update(simplifier=self.simplifier, tolerance=self.tolerance)
        if self.quadrisection is not None:
            row["quadrisection"] = self.quadrisection
        return row


def cell_value(value):
    """A table cell for an option value: tuples and lists as compact JSON text."""
    if isinstance(value, (tuple, list)):
        return json.dumps(value, separators=(",", ":"))
    return value


def one_line(exc: BaseException) -> str:
    """``Type: message`` on one line (a KeyError's message without its quotes)."""
    message = exc.args[0] if isinstance(exc, KeyError) and exc.args else str(exc)
    return f"{type(exc).__name__}: {' '.join(str(message).split())}"


def failure_row(point: Point, exc: BaseException, **extra) -> dict:
    """The row of a point that raised: its columns, ``error`` and ``extra`` (workers, host …)."""
    return {**point.columns(), **extra, "error": one_line(exc)}


# ------------------------------------------------------------------------- worker side
@lru_cache(maxsize=16)
def _our_decimation(spec: str, quick: bool, tolerance: float):
    """:func:`~workbench.algo.simplify.hausdorff_decimate` of the scene at ``tolerance`` %,
    per part (cached per worker: the reference simplifiers aim at its triangle count)."""
    from ..algo.simplify import hausdorff_decimate
    from ..scene.builtin import loaded_scene

    mesh = loaded_scene(spec, quick)
    tri = mesh.triangulation
    return hausdorff_decimate(mesh.nodes, tri.triangles, tolerance / 100.0, relative=True,
                              parts=mesh.parts[tri.element_of])


def simplified_scene(mesh, point: Point):
    """(simplified FE mesh, columns) for ``point.simplifier`` at ``point.tolerance`` % of each
    part's bounding-sphere diameter.

    The reference simplifiers aim at the triangle count ours reaches at that tolerance. The
    columns: ``triangles_before``, ``triangles_after``, ``target_triangles`` (references),
    ``simplify_s`` (wall seconds of the simplifier's own call), and the certified one-sided
    Hausdorff distance original → simplified: ``hausdorff_lower_mm`` (the attained lower end of
    the bracket, model units), ``hausdorff_mm`` (its certified upper end), ``hausdorff_pct_diag``
    (the upper end in % of the bounding-box diagonal) and ``hausdorff_s``. A simplifier that
    fails or returns nothing raises RuntimeError; a scene that is no FE mesh, ValueError.
    """
    from ..algo.hausdorff import hausdorff
    from ..references.simplifiers import simplify_with
    from ..scene.mesh import FEMesh
    if mesh.kind != "mesh":
        raise ValueError(f"simplifier {point.simplifier!r} needs an FE mesh scene, "
                         f"{point.scene!r} is a {mesh.kind} scene")
    if point.simplifier == NO_SIMPLIFIER:  # drawn as it is, quads included
        triangles = mesh.n_elements + mesh.n_quads
        return mesh, dict(triangles_before=triangles, triangles_after=triangles, simplify_s=0.0,
                          hausdorff_lower_mm=0.0, hausdorff_mm=0.0, hausdorff_pct_diag=0.0,
                          hausdorff_s=0.0)
    tri = mesh.triangulation
    v, f = mesh.nodes, tri.triangles.astype(np.int64)
    used = v[np.unique(f)]
    diagonal = float(np.linalg.norm(used.max(axis=0) - used.min(axis=0)))
    columns = dict(triangles_before=len(f))
    shares, parts = True, None
    if point.simplifier == OURS:
        ours = _our_decimation(point.scene, point.quick, point.tolerance)
        u, g, seconds, parts = v, ours.triangles.astype(np.int64), ours.seconds, ours.parts
    else:
        target = len(_our_decimation(point.scene, point.quick, point.tolerance).triangles)
        out = simplify_with(point.simplifier, v, f, target)
        if out.failure:
            raise RuntimeError(f"{point.simplifier}: {out.failure}")
        u, g, seconds, shares = out.vertices, out.triangles, out.seconds, out.shares_vertices
        columns["target_triangles"] = target
    h = hausdorff(v, f, u, g, tol=HAUSDORFF_BRACKET * diagonal, estimates=False)
    columns.update(triangles_after=len(g), simplify_s=seconds, hausdorff_lower_mm=h.lower,
                   hausdorff_mm=h.upper, hausdorff_pct_diag=100.0 * h.upper / diagonal,
                   hausdorff_s=h.seconds)
    simplified = FEMesh(nodes=u, elements=g, parts=parts,
                        steps=mesh.steps if shares else None,
                        node_fields=dict(mesh.node_fields) if shares else {},
                        name=f"{mesh.name} ({point.simplifier} {point.tolerance:g} %)",
                        units=mesh.units)
    return simplified, columns


def _reference_image(ctx, point: Point, scene, camera, measured):
    """The reference path's image of the unsimplified, unsplit scene with the point's options:
    the point's own image when it draws the reference path on that very scene."""
    from ..measurement.rows import measure

    if point.reference == point.path and point.simplifier in (None, NO_SIMPLIFIER) \
            and point.quadrisection is None:
        return measured.image
    from ..paths import make_path

    path = make_path(point.reference, **point.reference_options)
    return measure(ctx, scene, path, camera=camera, size=point.size, samples=point.samples,
                   timed=False).image


def measured_columns(point: Point, ctx) -> dict:
    """The columns of a point drawn on ``ctx``: :func:`measure`'s row (its ``scene`` renamed
    ``scene_name``; ``lock_wait_ms`` is how long the timed draw waited for the host's draw
    lock), the simplification columns, and the image differences (:meth:`ImageDiff.as_row`: max and
    mean absolute difference in 1/255, share of pixels differing, PSNR in dB, SSIM) against the
    reference image. ValueError when the image shows nothing of the scene (no pixel differs
    from the background)."""
    from ..distributed.cluster import draw_lock
    from ..measurement.images import compare_images
    from ..measurement.rows import measure
    from ..paths import SoftwareRasterizer, make_path
    from ..scene.builtin import fresh_scene

    original = fresh_scene(point.scene, point.quick)
    path = make_path(point.path, **point.options)
    backend = SoftwareRasterizer() if point.rasterizer == "software" else ctx
    kind = original.kind
    if kind not in path.scene_kinds:
        raise ValueError(f"path {point.path!r} draws {' or '.join(sorted(path.scene_kinds))} "
                         f"scenes; {point.scene!r} is a {kind} scene")
    camera = path.default_camera(original, point.size, view=point.view, style=path.style)
    scene, columns = original, {}
    if point.simplifier is not None:
        scene, columns = simplified_scene(original, point)
    if point.quadrisection is not None:
        if kind != "spacetime":
            raise ValueError(f"quadrisection splits spacetime polygons; {point.scene!r} is a "
                             f"{kind} scene")
        scene = original.quadrisected(point.quadrisection)
        columns["polygons"] = len(scene.corners)
    kwargs = dict(camera=camera, size=point.size, samples=point.samples)
    if point.timed:
        waited = time.perf_counter()
        with draw_lock():
            columns["lock_wait_ms"] = (time.perf_counter() - waited) * 1e3
            measured = measure(backend, scene, path, repeats=point.repeats, **kwargs)
    else:
        measured = measure(backend, scene, path, timed=False, **kwargs)
    if measured.row["covered_px"] == 0:
        # a point that draws nothing (a view turned by NaN degrees, a scene outside the view)
        # has no image to time or compare: counted as failed, not as a result
        raise ValueError(f"the image shows nothing of the scene: no pixel of the "
                         f"{point.size[0]}x{point.size[1]} image differs from the background")
    row = {("scene_name" if k == "scene" else k): v for k, v in measured.row.items()
           if k != "path"}
    row.update(columns)
    if point.reference is not None:
        reference = _reference_image(ctx, point, original, camera, measured)
        row.update(compare_images(reference, measured.image).as_row())
    return row


def run_point(point: Point, workers: int, run_id: str) -> dict:
    """The row of ``point``, measured on this worker: :meth:`Point.columns`, then
    :func:`measured_columns`, ``point_ms`` (wall ms of the whole point), ``workers`` (the
    cluster's worker count), ``host``, ``egl_device`` (the identity of the worker's EGL
    device), ``run_id`` (the run that computed it) — or, when the point raises, its columns
    with ``error`` (one line ``Type: message``)."""
    from ..distributed.cluster import worker_context, worker_device

    start = time.perf_counter()
    extra = dict(workers=workers, host=socket.gethostname(), egl_device=worker_device(),
                 run_id=run_id)
    try:
        columns = measured_columns(point, worker_context())
    except Exception as exc:  # a failing point is a result of the sweep, not its end
        return failure_row(point, exc, **extra)
    return {**point.columns(), **columns, "point_ms": (time.perf_counter() - start) * 1e3,
            **extra}
