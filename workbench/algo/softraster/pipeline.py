"""The es2008 software rasterizer: triangles in, a :class:`~.frame.Frame` out, no GL.

Kawai et al. render the contour and deformation plots of huge FE results without graphics
hardware by running a classical pipeline as long loops over triangles or fragments. This
module runs their steps (their Table 2) in that order, each a compiled kernel of
:mod:`.kernels`, timed one by one:

=====================  ===========  =========================================================
step                   parallel     what
=====================  ===========  =========================================================
transform and light    vertices     float32 placement, snapping, per-vertex or flat lighting
clip triangle          triangles    drop unplaced, zero-area, off-image, near/far, clipped
depth gradient         triangles    depth plane over pixel centres
scalar gradient        triangles    planes of the shading attributes and clip distances
range and TC           triangles    box, vertices oriented (triangle coordinates)
collect table-fit      triangles    which triangles the span table holds
bin                    —            triangles into screen tiles, in order (extra step)
generate fragment      tiles        span table or half-space (edge-function) tests
interpolate z          tiles        depth per fragment, fragment-wise clipping
interpolate color      tiles        colour through the 1-D texture, alpha test
write fragment         tiles        depth-tested write
=====================  ===========  =========================================================

Triangles go through the steps in sessions of ``RasterOptions.session`` triangles (the
paper's fragment pool), so memory stays bounded on a 16 M-triangle model. The two steps the
paper keeps scalar run tile by tile — a tile is owned by one thread and its triangles are
visited in index order — so the image does not depend on the thread count, and of two
fragments at one depth the lower triangle index wins, as under GL's ``LESS`` test.

Pixels follow :mod:`.rule` (llvmpipe's: 8 sub-pixel bits, pixel centres, top-left rule in
its row order). The span table needs 0 sub-pixel bits (vertices on pixel centres): that
choice, ``RasterOptions(generator="table", subpixel_bits=0)``, is the paper's renderer and
deviates from GL's coverage by the snapping; the half-space generator runs with any bits.
Only orthographic projections are drawn (the paper's; attributes are interpolated linearly in the
image). A vertex more than 2^21 pixels outside the image (2^29 fixed-point units, where the exact
integer edge functions would overflow) counts as unplaced and its triangles are dropped, where GL
would clip them: with a camera fitted to the scene no vertex is that far. Refused with ValueError: a
perspective projection, a table generator with sub-pixel bits, arrays of the wrong shapes.
"""

from __future__ import annotations

import time
from contextlib import contextmanager
from dataclasses import dataclass, field
from types import SimpleNamespace

import numba
import numpy as np

from . import fused, kernels
from .frame import Frame
from .rule import GL_SUBPIXEL_BITS, check_bits
from .state import Camera, Fragments, Geometry, Lit, Look, Setup, Span, Target

SHADINGS = ("constant", "flat", "gouraud", "vertex_color", "pixel_color", "element_color")
GENERATORS = ("halfspace", "table")
TABLE_SIZES = (10, 15, 20)
STEPS = (("transform and light", True), ("clip triangle", True), ("depth gradient", True),
         ("scalar gradient", True), ("range and TC", True), ("collect table-fit", True),
         ("bin", False), ("generate fragment", False), ("interpolate z", True),
         ("interpolate color", True), ("write fragment", False))
_ATTRS = {"constant": 0, "flat": 0, "gouraud": 1, "vertex_color": 4, "pixel_color": 2,
          "element_color": 0}
_KERNELS = ("transform", "light_vertices", "light_triangles", "clip_triangles",
            "depth_gradient", "scalar_gradient", "range_and_tc", "collect_table_fit",
            "bin_triangles", "generate_fragments", "interpolate_z", "interpolate_color",
            "write_fragments")
_HELPERS = ("texel_rgba", "unorm8", "pack", "headlight", "_plane", "_eye", "_flat_light",
            "_edges", "_edge_at")


@dataclass(frozen=True)
class Shading:
    """How fragments are coloured, after the mesh render path of the same name.

    ``kind``: "constant" (``base_color``), "flat" (face-normal headlight), "gouraud"
    (per-vertex headlight), "vertex_color" (colour looked up per vertex, lit, interpolated),
    "pixel_color" (texture coordinate and light interpolated, looked up per pixel),
    "element_color" (one looked-up colour per triangle, flat lit). ``texels`` (n, 4) uint8 is
    the 1-D colour texture with ``linear`` filtering or nearest, ``coord`` the (scale, offset)
    from normalised value to texture coordinate, ``alpha_test`` discards α < ½,
    ``missing_color`` is the colour of a triangle with a non-finite value (:func:`render`;
    default the no-result colour of :data:`workbench.paths.colormap.NO_RESULT_COLOR`, pure
    green). Colours RGB in [0, 1].
    """

    kind: str = "constant"
    base_color: tuple = (0.75, 0.75, 0.78)
    missing_color: tuple = (0.0, 1.0, 0.0)
    texels: np.ndarray | None = None
    linear: bool = False
    coord: tuple = (1.0, 0.0)
    alpha_test: bool = False

    def __post_init__(self) -> None:
        if self.kind not in SHADINGS:
            raise ValueError(f"shading must be one of {SHADINGS}, got {self.kind!r}")
        if self.kind in ("vertex_color", "pixel_color", "element_color"):
            if self.texels is None or np.asarray(self.texels).ndim != 2 \
                    or np.asarray(self.texels).shape[1] != 4 or not len(self.texels):
                raise ValueError(f"shading {self.kind!r} needs texels of shape (n, 4)")


@dataclass(frozen=True)
class RasterOptions:
    """``generator``: "halfspace" or "table" (the span table for table-fit triangles, the
    half-space tests for the others); ``table_size``: the table's S in pixels;
    ``subpixel_bits``: 8 as llvmpipe, 0 for the table; ``threads``: numba threads (None: all);
    ``tile``: screen tile edge in pixels (a power of two); ``session``: triangles per session;
    ``early_depth``: skip generating fragments that already fail the depth test (the image
    is the same; es2008 generates them all); ``fused``: the half-space generator runs set-up,
    coverage, depth test and shading per tile in one compiled loop (:mod:`.fused`; the same
    image, no sessions) instead of the steps; the span table always runs the steps."""

    generator: str = "halfspace"
    table_size: int = 10
    subpixel_bits: int = GL_SUBPIXEL_BITS
    threads: int | None = None
    tile: int = 64
    session: int = 1 << 16
    early_depth: bool = True
    fused: bool = True

    def __post_init__(self) -> None:
        if self.generator not in GENERATORS:
            raise ValueError(f"generator must be one of {GENERATORS}, got {self.generator!r}")
        check_bits(self.subpixel_bits)
        if self.generator == "table" and self.subpixel_bits != 0:
            raise ValueError("the span table indexes integer pixel offsets: the table generator "
                             f"needs subpixel_bits=0, got {self.subpixel_bits}")
        if int(self.table_size) != self.table_size or not 2 <= self.table_size <= 63:
            raise ValueError(f"table_size must be an integer in 2..63, got {self.table_size}")
        if self.threads is not None and (int(self.threads) != self.threads or self.threads < 1):
            raise ValueError(f"threads must be a positive integer, got {self.threads}")
        if int(self.session) != self.session or self.session < 1:
            raise ValueError(f"session must be a positive integer, got {self.session}")
        if int(self.tile) != self.tile or self.tile < 1 or self.tile & (self.tile - 1):
            raise ValueError(f"tile must be a power of two, got {self.tile}")


@dataclass
class RenderStats:
    """What one render did: triangle counts (``triangles`` given, ``kept`` after clipping,
    ``table_fit``), ``fragments`` generated, ``seconds`` per step (the order of
    :data:`STEPS`), ``sessions``, ``threads``, ``table_bytes`` (0 without the table) and
    ``fragment_bytes`` (the largest session's fragment pool)."""

    triangles: int = 0
    kept: int = 0
    table_fit: int = 0
    fragments: int = 0
    seconds: dict = field(default_factory=lambda: {name: 0.0 for name, _ in STEPS})
    sessions: int = 0
    threads: int = 1
    table_bytes: int = 0
    fragment_bytes: int = 0

    @property
    def total_s(self) -> float:
        return float(sum(self.seconds.values()))


def _compiled() -> SimpleNamespace:
    return SimpleNamespace(**{name: getattr(kernels, name) for name in _KERNELS})


@contextmanager
def _interpreted():
    """The kernels as plain Python (``py_func``), their helpers too, for the block."""
    saved = {name: getattr(kernels, name) for name in _HELPERS}
    try:
        for name in _HELPERS:
            setattr(kernels, name, saved[name].py_func)
        yield SimpleNamespace(**{name: getattr(kernels, name).py_func for name in _KERNELS})
    finally:
        for name, value in saved.items():
            setattr(kernels, name, value)


@contextmanager
def _threads(count: int | None):
    before = numba.get_num_threads()
    numba.set_num_threads(min(count or numba.config.NUMBA_NUM_THREADS,
                              numba.config.NUMBA_NUM_THREADS))
    try:
        yield numba.get_num_threads()
    finally:
        numba.set_num_threads(before)


def _checked(positions, triangles, ids, normals, values, triangle_values, shading):
    pos = np.asarray(positions)
    if pos.dtype != np.float32:
        pos = pos.astype(np.float64, copy=False)
    if pos.ndim != 2 or pos.shape[1] != 3:
        raise ValueError(f"positions must be (V, 3), got {pos.shape}")
    tris = np.ascontiguousarray(triangles, np.int64)
    if tris.ndim != 2 or tris.shape[1] != 3:
        raise ValueError(f"triangles must be (K, 3), got {tris.shape}")
    if len(tris) and (tris.min() < 0 or tris.max() >= len(pos)):
        raise ValueError(f"triangle indices must lie in 0..{len(pos) - 1}")
    ids = np.arange(len(tris), dtype=np.int64) if ids is None else \
        np.ascontiguousarray(ids, np.int64)
    if ids.shape != (len(tris),):
        raise ValueError(f"ids must be ({len(tris)},), got {ids.shape}")
    kind = shading.kind
    if kind in ("gouraud", "vertex_color", "pixel_color"):
        if normals is None or np.shape(normals) != pos.shape:
            raise ValueError(f"shading {kind!r} needs normals of shape {pos.shape}")
    if kind in ("vertex_color", "pixel_color"):
        if values is None or np.shape(values) != (len(pos),):
            raise ValueError(f"shading {kind!r} needs values of shape ({len(pos)},)")
    if kind == "element_color":
        if triangle_values is None or np.shape(triangle_values) != (len(tris),):
            raise ValueError(f"shading 'element_color' needs triangle_values of shape "
                             f"({len(tris)},)")
    return pos, tris, ids


def check_orthographic(projection) -> np.ndarray:
    """``projection`` (4, 4) float64, refused (ValueError) unless orthographic."""
    proj = np.asarray(projection, np.float64)
    if proj.shape != (4, 4):
        raise ValueError(f"projection must be (4, 4), got {proj.shape}")
    if not np.array_equal(proj[3], [0.0, 0.0, 0.0, 1.0]):
        raise ValueError("the software rasterizer draws orthographic views only (es2008's "
                         "projection); got a perspective projection")
    return proj


def render(positions, triangles, view, projection, size: tuple[int, int],
           shading: Shading = Shading(), options: RasterOptions = RasterOptions(), *,
           ids=None, normals=None, values=None, triangle_values=None, clip_planes=(),
           background=(255, 255, 255, 255), frame: Frame | None = None,
           vectorized: bool = True, workspace: dict | None = None) -> tuple[Frame, RenderStats]:
    """Draw ``triangles`` (K, 3) vertex indices of ``positions`` (V, 3) model units relative to
    the camera's upload origin (float64, cast to float32 as GL uploads them, or that float32
    upload itself), with the ``view`` and orthographic ``projection``
    (4, 4) float64 matrices into a ``size`` (W, H) frame cleared to ``background`` (RGBA
    0–255), or on top of ``frame``.

    ``ids`` (K,) int64 are the triangles' global indices (default 0..K−1): they break depth
    ties and are written to ``Frame.triangle``. ``normals`` (V, 3), ``values`` (V,)
    normalised field values and ``triangle_values`` (K,) are needed by the shadings that use
    them (see :class:`Shading`). The no-result rule of :mod:`workbench.paths.colormap`: a
    triangle with a non-finite value at any of its vertices (``values``) or of its own
    (``triangle_values``) is drawn whole in ``Shading.missing_color``, lit as the shading
    lights the others (the interpolated Gouraud light, the flat light), never alpha tested;
    no number of it is interpolated. ``clip_planes``
    (P, 4) relative to the origin keep ``a·x + b·y + c·z + d ≥ 0``. ``vectorized=False`` runs
    every step as plain Python (slow; for the step table on small cases). ``workspace``, a
    dict kept by the caller, lends the per-vertex arrays from one draw to the next (no fresh
    pages for every frame of a large model). Degenerate, non-finite and wholly clipped
    triangles draw nothing.

    Takes more than 12 arguments because it is the public draw call: the geometry, the
    camera, the shading and the options are the positional ones, and every optional array
    (``ids``, ``normals``, ``values``, ``triangle_values``, ``clip_planes``) and draw setting
    is a keyword that a caller names or leaves out, as a GL draw's state; the kernels take them
    grouped (:mod:`.state`).
    """
    pos, tris, ids = _checked(positions, triangles, ids, normals, values, triangle_values, shading)
    proj = check_orthographic(projection)
    view = np.asarray(view, np.float64)
    width, height = (int(v) for v in size)
    if width < 1 or height < 1:
        raise ValueError(f"size must be positive, got {size}")
    planes = np.asarray(clip_planes, np.float64).reshape(-1, 4)
    if frame is None:
        frame = Frame.empty(width, height, background)
    elif frame.size != (width, height):
        raise ValueError(f"frame is {frame.size}, size is {(width, height)}")
    color32 = frame.color.view(np.uint32).reshape(height, width)
    stats = RenderStats(triangles=len(tris))
    table = _fragment_table(options)
    stats.table_bytes = table.nbytes
    look = _look_of(shading)
    with _threads(options.threads if vectorized else 1) as threads, \
            (_interpreted() if not vectorized else _null(_compiled())) as k:
        stats.threads = threads
        clock = _Clock(stats.seconds)
        fuse = options.fused and options.generator == "halfspace"
        lit = _transform_and_light(
            k, Geometry(pos, tris, normals, values, triangle_values, planes),
            Camera(view, proj, (width, height), options.subpixel_bits), shading, look,
            workspace, flat_light=not fuse)
        clock.lap("transform and light")
        if fuse:
            fused.draw(tris, ids, lit, frame, color32, options, look, threads, stats, clock,
                       vectorized, workspace)
            return frame, stats
        sessions = _Sessions(k, tris, ids, lit, frame, color32, options, table, look, threads,
                             stats, clock)
        for k0 in range(0, len(tris), options.session):
            sessions.draw(k0, min(k0 + options.session, len(tris)))
    return frame, stats


class _Clock:
    """Adds the seconds since the previous lap (or since it was made) to a step of
    ``seconds``."""

    def __init__(self, seconds: dict):
        self.seconds = seconds
        self.t0 = time.perf_counter()

    def lap(self, step: str) -> None:
        now = time.perf_counter()
        self.seconds[step] += now - self.t0
        self.t0 = now


@dataclass(frozen=True)
class _Table:
    """The span table's arrays as the kernels take them (``lo``, ``hi`` flattened, ``size``
    its S; one -1 each and the options' S without the table), ``present`` whether the
    generator uses it and ``nbytes`` its memory (0 without)."""

    present: bool
    lo: np.ndarray
    hi: np.ndarray
    size: int
    nbytes: int


def _fragment_table(options: RasterOptions) -> _Table:
    """The span table of ``options`` (:mod:`.spantable`), or the placeholder of the half-space
    generator."""
    if options.generator == "table":
        from .spantable import span_table

        table = span_table(options.table_size)
        return _Table(True, table.lo.reshape(-1), table.hi.reshape(-1), table.size, table.nbytes)
    none = np.full(1, -1, np.int8)
    return _Table(False, none, none, options.table_size, 0)


def _look_of(shading: Shading) -> Look:
    """The :class:`~.state.Look` of ``shading``: its kind's index in :data:`SHADINGS`, the
    texture (one zero texel without one) as uint8 and float32 in [0, 1], the colours float32,
    the filter and the alpha test as bools."""
    texels = np.ascontiguousarray(shading.texels if shading.texels is not None
                                  else np.zeros((1, 4)), np.uint8)
    return Look(code=SHADINGS.index(shading.kind), texels=texels,
                texf=texels.astype(np.float32) / np.float32(255.0),
                base=np.asarray(shading.base_color, np.float32),
                missing=np.asarray(shading.missing_color, np.float32),
                linear=bool(shading.linear), alpha_test=bool(shading.alpha_test))


def _transform_and_light(k, geometry: Geometry, camera: Camera, shading: Shading, look: Look,
                         workspace, flat_light: bool = True) -> Lit:
    """The first step, all vertices once: float32 placement and snapping, per-vertex or flat
    lighting (unless not ``flat_light``) and colour look-up, the clip distances (see
    :func:`render` for what ``geometry`` and ``camera`` hold)."""
    pos, tris, normals, values, triangle_values, planes = geometry
    view, proj, (width, height), bits = camera
    kind, code = shading.kind, look.code
    rel32 = pos if pos.dtype == np.float32 else pos.astype(np.float32)
    mvp32 = (proj @ view).astype(np.float32)
    n_v = len(pos)
    lend = _lender(workspace)
    fx, fy = lend("fx", n_v, np.int64), lend("fy", n_v, np.int64)
    fz, ok = lend("fz", n_v, np.float32), lend("ok", n_v, bool)
    k.transform(rel32, mvp32, width, height, bits, fx, fy, fz, ok)
    scale, offset = (np.float32(v) for v in shading.coord)
    tri_missing, any_missing = np.zeros(1, np.uint8), False
    t = tv = None
    if kind in ("vertex_color", "pixel_color") and values is not None:
        t = np.asarray(values, np.float64)
        finite = np.isfinite(t)
        if not finite.all():  # the no-result rule: a triangle with a non-finite vertex value
            tri_missing = (~finite[tris]).any(axis=1).astype(np.uint8)
            any_missing = True
            t = np.where(finite, t, 0.0)
    if kind == "element_color":
        tv = np.asarray(triangle_values, np.float64)
        finite = np.isfinite(tv)
        if not finite.all():
            tri_missing, any_missing = (~finite).astype(np.uint8), True
            tv = np.where(finite, tv, 0.0)
    # vertex colours interpolate lit colours: the missing colour needs the light beside them
    n_attr = _ATTRS[kind] + int(kind == "vertex_color" and any_missing)
    attr = lend("attr", (n_v, n_attr), np.float32)
    if kind in ("gouraud", "vertex_color", "pixel_color"):
        s = np.zeros(n_v, np.float32)
        if t is not None:
            s = t.astype(np.float32) * scale + offset
        normals32 = np.asarray(normals)
        if normals32.dtype != np.float32:
            normals32 = normals32.astype(np.float32)
        k.light_vertices(code, np.ascontiguousarray(view[:3, :3], np.float32), normals32,
                         s, look.texels, look.texf, look.linear, attr)
    flat = flat_light and kind in ("flat", "element_color")
    tri_light = np.zeros(len(tris) if flat else 1, np.float32)
    view32 = view.astype(np.float32)
    if flat:
        k.light_triangles(rel32, tris, view32, fx, fy, bits, tri_light)
    tri_s = np.zeros(1, np.float32)
    if kind == "element_color":
        tri_s = tv.astype(np.float32) * scale + offset
    clipd = np.zeros((n_v, len(planes)), np.float32)
    if len(planes):
        p32, w32 = planes[:, :3].astype(np.float32), planes[:, 3].astype(np.float32)
        clipd = np.ascontiguousarray((rel32 @ p32.T) + w32, np.float32)
    return Lit(fx=fx, fy=fy, fz=fz, ok=ok, attr=attr, n_attr=n_attr, clipd=clipd,
               tri_light=tri_light, tri_s=tri_s, tri_missing=tri_missing,
               any_missing=any_missing, pos32=rel32, view32=view32)


@dataclass
class _Sessions:
    """The steps after transform and light, run on one session of triangles at a time into
    ``frame`` (``color32`` its colour as one uint32 per pixel), with the kernels ``k``; counts
    and seconds go to ``stats`` and ``clock``."""

    k: SimpleNamespace
    tris: np.ndarray
    ids: np.ndarray
    lit: Lit
    frame: Frame
    color32: np.ndarray
    options: RasterOptions
    table: _Table
    look: Look
    threads: int
    stats: RenderStats
    clock: _Clock

    def draw(self, k0: int, k1: int) -> None:
        """Draw triangles ``k0`` .. ``k1 - 1``."""
        k, tris, lit, frame, options, table = (self.k, self.tris, self.lit, self.frame,
                                               self.options, self.table)
        stats, clock, look = self.stats, self.clock, self.look
        width, height = frame.size
        bits = options.subpixel_bits
        n_attr = lit.n_attr
        shift = options.tile.bit_length() - 1
        tiles_x = -(-width // options.tile)
        n_tiles = tiles_x * (-(-height // options.tile))
        stats.sessions += 1
        keep = np.empty(k1 - k0, bool)
        k.clip_triangles(tris, k0, lit.fx, lit.fy, lit.fz, lit.ok, lit.clipd, width, height,
                         bits, keep)
        kept = np.flatnonzero(keep) + k0
        n = len(kept)
        stats.kept += n
        clock.lap("clip triangle")
        if n == 0:
            return
        zplane = np.empty((n, 1, 3))
        k.depth_gradient(kept, tris, lit.fx, lit.fy, lit.fz, bits, zplane)
        clock.lap("depth gradient")
        planes_m = np.empty((n, n_attr + lit.clipd.shape[1], 3))
        k.scalar_gradient(kept, tris, lit.fx, lit.fy, bits, lit.attr, lit.clipd, planes_m)
        clock.lap("scalar gradient")
        verts = np.empty((n, 6), np.int64)
        box = np.empty((n, 4), np.int32)
        k.range_and_tc(kept, tris, lit.fx, lit.fy, width, height, bits, verts, box)
        clock.lap("range and TC")
        fit = np.zeros(n, bool)
        if table.present:
            k.collect_table_fit(verts, table.size, fit)
            stats.table_fit += int(fit.sum())
        clock.lap("collect table-fit")
        start, members, frag_start = k.bin_triangles(box, shift, tiles_x, n_tiles, self.threads)
        slots = int(frag_start[-1])
        frag_tri = np.empty(slots, np.int32)
        frag_i, frag_j = np.empty(slots, np.int32), np.empty(slots, np.int32)
        frag_count = np.zeros(n_tiles, np.int64)
        frags = Fragments(frag_start, frag_count, frag_tri, frag_i, frag_j)
        clock.lap("bin")
        k.generate_fragments(start, members, frags, Setup(verts, box, fit, zplane),
                             Span(table.lo, table.hi, int(table.size)), options.tile, tiles_x,
                             bits, options.early_depth, frame.depth)
        stats.fragments += int(frag_count.sum())
        clock.lap("generate fragment")
        frag_z = np.empty(slots, np.float32)
        k.interpolate_z(frags, zplane, planes_m, n_attr, frag_z)
        clock.lap("interpolate z")
        frag_rgba = np.empty(slots, np.uint32)
        k.interpolate_color(frags, planes_m, kept, lit, look, frag_z, frag_rgba)
        clock.lap("interpolate color")
        k.write_fragments(frags, frag_z, frag_rgba, kept, self.ids,
                          Target(frame.depth, self.color32, frame.triangle))
        clock.lap("write fragment")
        stats.fragment_bytes = max(stats.fragment_bytes, slots * 20)


@contextmanager
def _null(value):
    yield value


def _lender(workspace: dict | None):
    """``lend(name, shape, dtype)``: an uninitialised array, reused from ``workspace`` when it
    holds one of that shape and dtype."""
    def lend(name, shape, dtype):
        if workspace is None:
            return np.empty(shape, dtype)
        held = workspace.get(name)
        if held is None or held.shape != (shape if isinstance(shape, tuple) else (shape,)) \
                or held.dtype != dtype:
            held = workspace[name] = np.empty(shape, dtype)
        return held
    return lend
