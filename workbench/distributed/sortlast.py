"""Sort-last rendering on a Dask cluster (es2008, section 1): domains rendered on the workers,
their frames composited by depth on the workers, the final image brought to the client.

:func:`render_sortlast` submits one render task per domain, spread over the workers in turn
(domain i to the i-th worker, in address order, modulo their number; for ``"local"``, in
blocks of consecutive domains). Once every frame exists it composites them by a schedule of
:mod:`workbench.algo.composite.merge`, submitted as Dask tasks that take futures
(:mod:`.sortlast_schedules`), so that Dask itself moves the (sub-)images between workers.
Each rank of the schedule is the worker holding that domain's frame, and each compositing task
is placed on the worker of the rank that receives. Placements are preferences
(``allow_other_workers``): Dask follows them while the worker is up and runs a task elsewhere
rather than wait for a lost one; a task run elsewhere (also by work stealing) shows as extra
``bytes_moved``:

* ``"tree"``: one ``composite`` task per pair and round; the result ends on rank 0's worker.
* ``"swap"``: per pair and round, two crop tasks (each rank cuts out the half it gives up) and
  two merge tasks (each rank composites the half it keeps with the half it receives), after a
  fold of whole frames when the domain count is not a power of two; a final gather task on
  rank 0's worker assembles the image from every rank's region.
* ``"active-tree"``, ``"active-swap"``, ``"radix"``: each rank first turns its frame into its
  drawn pixels on its own worker (:class:`~workbench.algo.composite.active.ActivePixels`);
  the same exchanges (radix-k: :func:`~workbench.algo.composite.schedules.radix_plan`)
  send encoded pieces (bounding box and runs of drawn pixels), merged in domain order; rank 0
  paints every rank's part over its own frame. ``schedule_bytes`` is the pieces' bytes.
* ``"local"``: each worker composites its own consecutive domains' frames first (compiled,
  :mod:`workbench.algo.composite.kernels`); every worker but the first then sends
  its drawn pixels as one encoded piece to the first, which composites them over its own:
  two levels of tasks, W − 1 pieces for W workers, whatever the domain count.

The two phases do not overlap: compositing starts once every frame exists, so that render and
composite times are measured apart. The result equals ``functools.reduce(composite, frames)``
exactly, whatever the placement.
"""

from __future__ import annotations

import time
import uuid
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from dask.sizeof import sizeof
from distributed import Client, wait

from ..algo.composite.active import EncodedPiece
from ..algo.composite.merge import bytes_per_pixel
from ..algo.softraster.frame import Frame
from .schedules import (
    color_of,
    local_placement,
    piece_bytes,
    submit_active,
    submit_local,
    submit_swap,
    submit_tree,
)

if TYPE_CHECKING:
    from ..algo.softraster import RasterOptions
    from ..gl import Camera
    from ..paths.software import SoftwarePath
    from ..paths.style import Style

METHODS = ("tree", "swap", "active-tree", "active-swap", "radix", "local")
KEY_PREFIX = "sortlast"


@dataclass(frozen=True)
class SoftwareDomains:
    """A picklable ``render_domain`` for :func:`render_sortlast`: the triangles of one domain
    of ``scene`` (a built-in scene name or mesh file, loaded once per worker process) drawn by
    the software rasterizer as mesh path ``path`` with ``style``, ``camera``, ``size`` (W, H)
    and raster ``options``. Domains are index arrays into the path's triangle list (the
    mesh's triangles: :func:`workbench.distributed.domains.split_domains`)."""

    scene: str
    path: str
    style: Style | None
    camera: Camera
    size: tuple[int, int]
    options: RasterOptions | None = None
    quick: bool = False

    def prepared(self) -> SoftwarePath:
        """The prepared :class:`~workbench.paths.software.SoftwarePath` of this process."""
        key = (self.scene, self.path, repr(self.style), repr(self.camera), tuple(self.size),
               repr(self.options), self.quick)
        path = _PREPARED.get(key)
        if path is None:
            from ..algo.softraster import RasterOptions
            from ..paths import SoftwareRasterizer, prepared_path
            from ..scene.builtin import fresh_scene

            mesh = fresh_scene(self.scene, self.quick)
            path = prepared_path(SoftwareRasterizer(self.options or RasterOptions()), mesh,
                                 self.path, self.style, self.camera, size=self.size)
            _PREPARED.clear()  # one scene per process at a time: they can be large
            _PREPARED[key] = path
        return path

    def __call__(self, ids: np.ndarray) -> Frame:
        return self.prepared().render_triangles(ids)


_PREPARED: dict = {}


@dataclass(frozen=True)
class GLDomains:
    """A picklable ``render_domain`` for :func:`render_sortlast` drawn by OpenGL: each worker
    process opens its own headless (EGL) context, loads ``scene`` once and prepares GL mesh
    path ``path`` with ``style`` and ``camera`` at ``size`` (W, H); a domain (indices into the
    path's triangle list) is drawn alone into a colour and depth target, then its triangles
    again into an integer target that records which triangle won each pixel
    (:meth:`~workbench.paths.mesh.MeshPath.draw_triangles`). The frame holds the read-back
    colour, the window depth (24-bit, as the paths draw) and the global triangle indices, so
    frames composite by depth, ties to the lower index, to the image one context draws. Paths
    drawn as strips, with a wire frame or a hidden range are refused."""

    scene: str
    path: str
    style: Style | None
    camera: Camera
    size: tuple[int, int]
    quick: bool = False

    def prepared(self):
        """(context, prepared GL path, colour framebuffer, id framebuffer) of this process."""
        key = ("gl", self.scene, self.path, repr(self.style), repr(self.camera),
               tuple(self.size), self.quick)
        held = _PREPARED.get(key)
        if held is None:
            from ..gl import Framebuffer
            from ..gl.context import create_context
            from ..paths import prepared_path
            from ..scene.builtin import fresh_scene

            _PREPARED.clear()
            mesh = fresh_scene(self.scene, self.quick)
            ctx = create_context()
            path = prepared_path(ctx, mesh, self.path, self.style, self.camera)
            target = Framebuffer(ctx, self.size)
            ids = ctx.framebuffer(color_attachments=[ctx.renderbuffer(self.size, 1,
                                                                      dtype="u4")],
                                  depth_attachment=ctx.depth_renderbuffer(self.size))
            held = _PREPARED[key] = (ctx, path, target, ids)
        return held

    def __call__(self, ids: np.ndarray) -> Frame:
        ctx, path, target, id_target = self.prepared()
        ids = np.asarray(ids, np.int64)
        target.use()
        target.clear()
        path.draw_triangles(ids)
        color, depth = target.read(), target.read_depth()
        id_target.use()
        id_target.clear(depth=1.0)
        path.draw_triangles(ids, triangle_ids=True)
        width, height = self.size
        won = np.frombuffer(id_target.read(components=1, dtype="u4"), np.uint32)
        won = won.reshape(height, width)[::-1].astype(np.int64)
        triangle = np.where(won > 0, ids[np.maximum(won - 1, 0)] if len(ids) else -1, -1)
        depth = np.where(won > 0, depth, np.float32(1.0)).astype(np.float32)
        return Frame(color, depth, triangle.astype(np.int64))


@dataclass(frozen=True)
class ChunkDomains:
    """A picklable ``render_domain`` for :func:`render_sortlast` over a chunked scene on disk
    (:mod:`workbench.distributed.chunked`): called with a domain number, a worker loads only that
    domain's files from ``folder`` and draws it with ``camera``, ``size`` (W, H) and raster
    ``options`` — no worker holds the whole scene. ``folder`` must be readable by every
    worker (a shared file system on a real cluster)."""

    folder: str
    camera: Camera
    size: tuple[int, int]
    options: RasterOptions | None = None

    def __call__(self, index: int) -> Frame:
        from .chunked import ChunkedScene

        chunk = ChunkedScene(self.folder).load(int(index))
        return chunk.render(self.camera, self.size, self.options)


def peak_memory_mib(client: Client) -> dict[str, float]:
    """Peak resident memory (MiB) of every worker process of ``client``'s cluster since it
    started or since :func:`reset_peak_memory`, by worker address: the process's own
    high-water mark (``VmHWM``; ``getrusage``'s maximum where there is no ``/proc``, which a
    process may inherit from the one that started it)."""
    return client.run(_peak_rss_mib)


def reset_peak_memory(client: Client) -> dict[str, float]:
    """Reset every worker's high-water mark to its present resident memory (Linux
    ``/proc/self/clear_refs``); that memory (MiB) by worker address."""
    return client.run(_reset_peak_rss)


def _status_mib(field: str) -> float | None:
    try:
        for line in open("/proc/self/status"):
            if line.startswith(field + ":"):
                return int(line.split()[1]) / 1024
    except OSError:
        return None
    return None


def _peak_rss_mib() -> float:
    import resource
    import sys

    peak = _status_mib("VmHWM")
    if peak is not None:
        return peak
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return peak / (1024 * 1024) if sys.platform == "darwin" else peak / 1024


def _reset_peak_rss() -> float:
    try:
        with open("/proc/self/clear_refs", "w") as f:
            f.write("5")
    except OSError:
        pass
    return _status_mib("VmRSS") or float("nan")


@sizeof.register(Frame)
def _sizeof_frame(frame: Frame) -> int:
    """A frame's size to Dask (memory accounting, placement, transfer logs): its array bytes."""
    return int(frame.nbytes)


@sizeof.register(EncodedPiece)
def _sizeof_piece(piece: EncodedPiece) -> int:
    """An encoded piece's size to Dask: its encoded bytes."""
    return int(piece.nbytes)


@dataclass
class SortLastStats:
    """One sort-last run: ``domains`` frames composited by ``method`` (one of :data:`METHODS`),
    rendered on ``workers`` distinct workers.

    ``render_s``: wall seconds from submitting the render tasks until every domain frame
    exists. ``composite_s``: wall seconds from then until the final frame (or its colour) is in
    the client (frame-size check where the schedule needs one, compositing tasks, fetching).
    ``bytes_moved``: bytes of compositing-task inputs that travelled from one worker to
    another, summed from every worker's log of received dependencies
    (``distributed.Worker.transfer_incoming_log``; a frame counts its colour + depth + triangle
    array bytes). Inputs already on the worker that runs a task count nothing, so this is
    below ``schedule_bytes`` when several ranks share a worker; the index arrays shipped with
    the render tasks and the final frame fetched by the client are not worker-to-worker
    transfers and do not count. A worker's log keeps its last
    ``distributed.admin.low-level-log-length`` transfers (1000 by default), which bounds the
    runs this can count. ``schedule_bytes``: what the schedule itself sends between
    ranks (:class:`~workbench.algo.composite.merge.CompositeStats`)."""

    domains: int
    method: str
    workers: int
    render_s: float
    composite_s: float
    bytes_moved: int
    schedule_bytes: int


def render_sortlast(client: Client, render_domain: Callable[[np.ndarray], Frame],
                    domains: Sequence[np.ndarray], method: str = "tree",
                    factors: Sequence[int] | None = None, color_only: bool = False,
                    ) -> tuple[Frame | np.ndarray, SortLastStats]:
    """Render each domain with ``render_domain`` on the cluster of ``client`` and composite
    the frames by ``method`` on the workers: ``"tree"`` (binary tree) and ``"swap"`` (binary
    swap) send whole (sub-)frames; ``"active-tree"``, ``"active-swap"`` and ``"radix"``
    (radix-k with round sizes ``factors``, default direct send) send only drawn pixels, as
    encoded pieces (:mod:`workbench.algo.composite.active`), each rank's pixels staying on
    its worker; ``"local"`` renders consecutive domains on each worker, composites them
    there and sends each worker's drawn pixels once, to the first worker
    (:func:`~workbench.distributed.schedules.submit_local`).

    ``render_domain`` is a picklable callable taking one domain and returning that domain's
    :class:`Frame` of the whole image; ``domains`` lists them, frame i coming from domain i:
    int64 arrays of triangle indices (e.g. from :func:`workbench.distributed.domains.split_domains`,
    for :class:`SoftwareDomains`) or domain numbers (for :class:`ChunkDomains`).
    Returns the composite — exactly ``functools.reduce(composite, frames)``, or only its
    colour (H, W, 4) when ``color_only`` (what a display needs: the depth and triangle
    indices are not fetched) — and its :class:`SortLastStats`.

    Refused (ValueError): an unknown ``method``; no domains; a domain that is neither a 1-D
    array of integers nor an integer; domain frames of different sizes. An error raised by
    ``render_domain`` reaches the caller as raised.
    """
    if method not in METHODS:
        raise ValueError(f"unknown compositing method {method!r}: expected one of "
                         f"{', '.join(METHODS)}")
    arrays = [_domain(d, i) for i, d in enumerate(domains)]
    if not arrays:
        raise ValueError("need at least one domain, got none")
    addresses = sorted(client.scheduler_info(n_workers=-1)["workers"])
    if not addresses:
        raise ValueError("the cluster has no workers")
    client.run(_ensure_sizeof)  # every worker sizes frames by their array bytes from now on
    run = f"{KEY_PREFIX}-{uuid.uuid4().hex[:10]}"
    placement = [addresses[w] for w in domain_workers(method, len(arrays), len(addresses))]

    start = time.perf_counter()
    frames = [client.submit(render_domain, tris, key=f"{run}-render-d{i}", pure=False,
                            workers=[placement[i]], allow_other_workers=True)
              for i, tris in enumerate(arrays)]
    wait(frames)
    rendered = time.perf_counter()
    for frame in frames:
        if frame.status != "finished":
            frame.result()  # raises the render error

    if method == "local":  # sizes are checked where the frames meet
        final, pieces = submit_local(client, run, frames, placement, color_only)
        result = final.result()
        done = time.perf_counter()
        holders = client.who_has(frames)  # where the frames were drawn (after the timing)
        where = [min(holders[f.key]) for f in frames]
    else:
        holders = client.who_has(frames)
        where = [min(holders[f.key]) for f in frames]
        sizes = client.gather([client.submit(_frame_shape, f, key=f"{run}-shape-d{i}",
                                             pure=False, workers=[where[i]],
                                             allow_other_workers=True)
                               for i, f in enumerate(frames)])
        if len(set(shape for shape, _ in sizes)) > 1:
            raise ValueError(f"domain frames differ in size: "
                             f"{sorted(set(shape for shape, _ in sizes))} "
                             f"(rows, columns, channels)")
        (height, width, _), pixel_bytes = sizes[0]
        if method in ("tree", "swap"):
            schedule = submit_tree if method == "tree" else submit_swap
            final, schedule_pixels = schedule(client, run, frames, where, height, width)
            pieces = []
        else:
            final, pieces = submit_active(client, run, frames, where, height, width, method,
                                          factors)
        if color_only:
            final = client.submit(color_of, final, key=f"{run}-color", pure=False,
                                  workers=[where[0]], allow_other_workers=True)
        result = final.result()
        done = time.perf_counter()
    if method in ("tree", "swap"):
        schedule_bytes = schedule_pixels * pixel_bytes
    else:
        schedule_bytes = sum(client.gather([client.submit(piece_bytes, piece, pure=False,
                                                          key=f"{run}-bytes-{i}")
                                            for i, piece in enumerate(pieces)]))

    moved = client.run(_received_bytes, run)
    stats = SortLastStats(len(arrays), method, len(set(where)), rendered - start, done - rendered,
                          int(sum(moved.values())), int(schedule_bytes))
    return result, stats


def domain_workers(method: str, domains: int, workers: int) -> list[int]:
    """The worker (by rank in address order, 0 … ``workers`` − 1) that :func:`render_sortlast`
    asks to render each of ``domains`` domains for ``method``: in turn (domain i on worker
    i mod ``workers``), or for ``"local"`` in blocks of consecutive domains."""
    if method == "local":
        return local_placement(domains, workers)
    return [i % workers for i in range(domains)]


def _domain(d, i: int):
    """A domain as ``render_domain`` takes it: an int64 array of triangle indices, or a domain
    number (a chunked scene's, :class:`ChunkDomains`)."""
    if isinstance(d, (int, np.integer)) and not isinstance(d, bool):
        return int(d)
    a = np.asarray(d)
    if a.ndim != 1 or not (np.issubdtype(a.dtype, np.integer) or a.size == 0):
        raise ValueError(f"domain {i} must be a 1-D array of triangle indices, got "
                         f"shape {a.shape} dtype {a.dtype}")
    return a.astype(np.int64)



def _ensure_sizeof() -> None:
    """Run on every worker: importing this module registers the frame size with Dask."""


def _frame_shape(frame: Frame) -> tuple[tuple[int, int, int], int]:
    """A frame's (rows, columns, channels) and its bytes per pixel."""
    return tuple(int(s) for s in frame.color.shape), bytes_per_pixel(frame)


def _received_bytes(run: str, dask_worker=None) -> int:
    """Bytes of this run's keys the worker received from other workers (its transfer log)."""
    total = 0
    for entry in list(dask_worker.transfer_incoming_log):
        total += sum(int(n or 0) for key, n in entry["keys"].items()
                     if isinstance(key, str) and key.startswith(run + "-"))
    return total
