"""Sort-last rendering on a Dask cluster (es2008, section 1): domains rendered on the workers,
their frames composited by depth on the workers, the final image brought to the client.

:func:`render_sortlast` submits one render task per domain, spread over the workers in turn
(domain i to the i-th worker, in address order, modulo their number). Once every frame exists
it composites them by the schedule of :mod:`workbench.algo.softraster.composite`, as Dask tasks
that take futures, so that Dask itself moves the (sub-)images between workers. Each rank of
the schedule is the worker holding that domain's frame, and each compositing task is placed on
the worker of the rank that receives. Placements are preferences (``allow_other_workers``):
Dask follows them while the worker is up and runs a task elsewhere rather than wait for a lost
one; a task run elsewhere (also by work stealing) shows as extra ``bytes_moved``:

* ``"tree"``: one ``composite`` task per pair and round; the result ends on rank 0's worker.
* ``"swap"``: per pair and round, two crop tasks (each rank cuts out the half it gives up) and
  two merge tasks (each rank composites the half it keeps with the half it receives), after a
  fold of whole frames when the domain count is not a power of two; a final gather task on
  rank 0's worker assembles the image from every rank's region.
* ``"active-tree"``, ``"active-swap"``, ``"radix"``: each rank first turns its frame into its
  drawn pixels on its own worker (:class:`~workbench.algo.softraster.active.ActivePixels`);
  the same exchanges (radix-k: :func:`~workbench.algo.softraster.active_schedules.radix_plan`)
  send encoded pieces (bounding box and runs of drawn pixels), merged in domain order; rank 0
  paints every rank's part over its own frame. ``schedule_bytes`` is the pieces' bytes.

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

from ..algo.softraster.active import EncodedPiece
from ..algo.softraster.composite import (
    Region,
    assemble,
    bytes_per_pixel,
    composite,
    crop,
    swap_plan,
    tree_plan,
)
from ..algo.softraster.frame import Frame

if TYPE_CHECKING:
    from ..algo.softraster import RasterOptions
    from ..gl import Camera
    from ..paths.software import SoftwarePath
    from ..paths.style import Style

METHODS = ("tree", "swap", "active-tree", "active-swap", "radix")
KEY_PREFIX = "sortlast"


@dataclass(frozen=True)
class SoftwareDomains:
    """A picklable ``render_domain`` for :func:`render_sortlast`: the triangles of one domain
    of ``scene`` (a built-in scene name or mesh file, loaded once per worker process) drawn by
    the software rasterizer as mesh path ``path`` with ``style``, ``camera``, ``size`` (W, H)
    and raster ``options``. Domains are index arrays into the path's triangle list (the
    mesh's triangles: :func:`workbench.scene.domains.split_domains`)."""

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
            from ..paths.software import SoftwarePath
            from ..scene.builtin import fresh_scene
            from ..scene.needs import derive

            mesh = fresh_scene(self.scene, self.quick)
            path = SoftwarePath(self.path, self.style, self.options or RasterOptions())
            derive(mesh, path.needs, path.style)
            path.prepare(None, mesh, self.camera)
            path.make_target(self.size)
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
            from ..paths import make_path
            from ..scene.builtin import fresh_scene
            from ..scene.needs import derive

            _PREPARED.clear()
            mesh = fresh_scene(self.scene, self.quick)
            ctx = create_context()
            path = make_path(self.path, self.style)
            derive(mesh, path.needs, path.style)
            path.prepare(ctx, mesh, self.camera)
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
    (:mod:`workbench.paths.chunked`): called with a domain number, a worker loads only that
    domain's files from ``folder`` and draws it with ``camera``, ``size`` (W, H) and raster
    ``options`` — no worker holds the whole scene. ``folder`` must be readable by every
    worker (a shared file system on a real cluster)."""

    folder: str
    camera: Camera
    size: tuple[int, int]
    options: RasterOptions | None = None

    def __call__(self, index: int) -> Frame:
        from ..paths.chunked import ChunkedScene

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
    """One sort-last run: ``domains`` frames composited by ``method`` (``"tree"`` or
    ``"swap"``), rendered on ``workers`` distinct workers.

    ``render_s``: wall seconds from submitting the render tasks until every domain frame
    exists. ``composite_s``: wall seconds from then until the final frame is in the client
    (frame-size check, compositing tasks, fetching the result).
    ``bytes_moved``: bytes of compositing-task inputs that travelled from one worker to
    another, summed from every worker's log of received dependencies
    (``distributed.Worker.transfer_incoming_log``; a frame counts its colour + depth + triangle
    array bytes). Inputs already on the worker that runs a task count nothing, so this is
    below ``schedule_bytes`` when several ranks share a worker; the index arrays shipped with
    the render tasks and the final frame fetched by the client are not worker-to-worker
    transfers and do not count. A worker's log keeps its last
    ``distributed.admin.low-level-log-length`` transfers (1000 by default), which bounds the
    runs this can count. ``schedule_bytes``: what the schedule itself sends between
    ranks (:class:`~workbench.algo.softraster.composite.CompositeStats`)."""

    domains: int
    method: str
    workers: int
    render_s: float
    composite_s: float
    bytes_moved: int
    schedule_bytes: int


def render_sortlast(client: Client, render_domain: Callable[[np.ndarray], Frame],
                    domains: Sequence[np.ndarray], method: str = "tree",
                    factors: Sequence[int] | None = None) -> tuple[Frame, SortLastStats]:
    """Render each domain with ``render_domain`` on the cluster of ``client`` and composite
    the frames by ``method`` on the workers: ``"tree"`` (binary tree) and ``"swap"`` (binary
    swap) send whole (sub-)frames; ``"active-tree"``, ``"active-swap"`` and ``"radix"``
    (radix-k with round sizes ``factors``, default direct send) send only drawn pixels, as
    encoded pieces (:mod:`workbench.algo.softraster.active`), each rank's pixels staying on
    its worker.

    ``render_domain`` is a picklable callable taking one domain and returning that domain's
    :class:`Frame` of the whole image; ``domains`` lists them, frame i coming from domain i:
    int64 arrays of triangle indices (e.g. from :func:`workbench.scene.domains.split_domains`,
    for :class:`SoftwareDomains`) or domain numbers (for :class:`ChunkDomains`).
    Returns the composite — exactly ``functools.reduce(composite, frames)`` — and its
    :class:`SortLastStats`.

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

    start = time.perf_counter()
    frames = [client.submit(render_domain, tris, key=f"{run}-render-d{i}", pure=False,
                            workers=[addresses[i % len(addresses)]], allow_other_workers=True)
              for i, tris in enumerate(arrays)]
    wait(frames)
    rendered = time.perf_counter()
    for frame in frames:
        if frame.status != "finished":
            frame.result()  # raises the render error

    holders = client.who_has(frames)
    where = [min(holders[f.key]) for f in frames]
    sizes = client.gather([client.submit(_frame_shape, f, key=f"{run}-shape-d{i}", pure=False,
                                         workers=[where[i]], allow_other_workers=True)
                           for i, f in enumerate(frames)])
    if len(set(sizes)) > 1:
        raise ValueError(f"domain frames differ in size: {sorted(set(sizes))} "
                         f"(rows, columns, channels)")
    height, width, _ = sizes[0]
    if method in ("tree", "swap"):
        schedule = _tree if method == "tree" else _swap
        final, schedule_pixels = schedule(client, run, frames, where, height, width)
        result = final.result()
        done = time.perf_counter()
        schedule_bytes = schedule_pixels * bytes_per_pixel(result)
    else:
        final, pieces = _active(client, run, frames, where, height, width, method, factors)
        result = final.result()
        done = time.perf_counter()
        schedule_bytes = sum(client.gather([client.submit(_piece_bytes, piece, pure=False,
                                                          key=f"{run}-bytes-{i}")
                                            for i, piece in enumerate(pieces)]))

    moved = client.run(_received_bytes, run)
    stats = SortLastStats(len(arrays), method, len(set(where)), rendered - start, done - rendered,
                          int(sum(moved.values())), int(schedule_bytes))
    return result, stats


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


def _tree(client, run, frames, where, height, width):
    """Binary-tree tasks; returns the final future and the schedule's pixels sent."""
    plan = tree_plan(len(frames))
    held = dict(enumerate(frames))
    for k, pairs in enumerate(plan.rounds):
        for receiver, sender in pairs:
            held[receiver] = client.submit(
                composite, held[receiver], held.pop(sender),
                key=f"{run}-tree-round{k}-d{receiver}-d{sender}", pure=False,
                workers=[where[receiver]], allow_other_workers=True)
    return held[0], plan.bytes_moved(height, width, 1)


def _swap(client, run, frames, where, height, width):
    """Binary-swap tasks; returns the final future and the schedule's pixels sent."""
    plan = swap_plan(len(frames), height, width)

    def submit(fn, *args, key, rank_domain):
        return client.submit(fn, *args, key=f"{run}-swap-{key}", pure=False,
                             workers=[where[rank_domain]], allow_other_workers=True)

    folded = {keeper: submit(composite, frames[keeper], frames[sender],
                             key=f"fold-d{keeper}-d{sender}", rank_domain=keeper)
              for keeper, sender in plan.fold}
    held = [folded.get(d, frames[d]) for d in plan.ranks]
    for k, exchanges in enumerate(plan.rounds):
        for e in exchanges:
            low_d, high_d = plan.ranks[e.lower], plan.ranks[e.upper]
            low_part, high_part = e.lower_keeps.within(e.held), e.upper_keeps.within(e.held)
            # each rank cuts out the half it gives up, on its own worker
            to_low = submit(_cut, held[e.upper], low_part,
                            key=f"round{k}-cut-d{high_d}-to-d{low_d}", rank_domain=high_d)
            to_high = submit(_cut, held[e.lower], high_part,
                             key=f"round{k}-cut-d{low_d}-to-d{high_d}", rank_domain=low_d)
            # and composites the half it keeps with the half it receives, lower domain first
            held[e.lower] = submit(_merge, held[e.lower], low_part, to_low, None,
                                   key=f"round{k}-merge-d{low_d}", rank_domain=low_d)
            held[e.upper] = submit(_merge, to_high, None, held[e.upper], high_part,
                                   key=f"round{k}-merge-d{high_d}", rank_domain=high_d)
    if len(held) == 1:
        final = held[0]
    else:
        final = submit(_gather, height, width, plan.regions, *held, key="gather",
                       rank_domain=plan.ranks[0])
    return final, plan.bytes_moved(1)


def _active(client, run, frames, where, height, width, method, factors):
    """Active-pixel schedules (:mod:`workbench.algo.softraster.active`): every rank turns its
    frame into its drawn pixels on its own worker; what travels are encoded pieces. Returns
    the final frame's future and the futures of every piece sent."""
    from ..algo.softraster.active import ActivePixels
    from ..algo.softraster.active_schedules import radix_plan

    pieces = []

    def submit(fn, *args, key, rank_domain):
        return client.submit(fn, *args, key=f"{run}-{method}-{key}", pure=False,
                             workers=[where[rank_domain]], allow_other_workers=True)

    def send(held_of, rank_domain, region, key):
        piece = submit(_pack, held_of, region, key=f"{key}-pack", rank_domain=rank_domain)
        pieces.append(piece)
        return piece

    held = {d: submit(ActivePixels.from_frame, f, key=f"active-d{d}", rank_domain=d)
            for d, f in enumerate(frames)}
    ranks = list(range(len(frames)))
    if method == "active-tree":
        for k, pairs in enumerate(tree_plan(len(frames)).rounds):
            for receiver, sender in pairs:
                piece = send(held.pop(sender), sender, None, f"round{k}-d{sender}")
                held[receiver] = submit(_merge_in, held[receiver], None, piece,
                                        key=f"round{k}-merge-d{receiver}",
                                        rank_domain=receiver)
        parts, ranks = {0: held[0]}, [0]  # the tree ends on rank 0: nothing to gather
    elif method == "active-swap":
        plan = swap_plan(len(frames), height, width)
        for keeper, sender in plan.fold:
            piece = send(held.pop(sender), sender, None, f"fold-d{sender}")
            held[keeper] = submit(_merge_in, held[keeper], None, piece,
                                  key=f"fold-merge-d{keeper}", rank_domain=keeper)
        ranks = list(plan.ranks)
        for k, exchanges in enumerate(plan.rounds):
            for e in exchanges:
                low_d, high_d = ranks[e.lower], ranks[e.upper]
                to_low = send(held[high_d], high_d, e.lower_keeps, f"round{k}-d{high_d}")
                to_high = send(held[low_d], low_d, e.upper_keeps, f"round{k}-d{low_d}")
                held[low_d] = submit(_merge_in, held[low_d], e.lower_keeps, to_low,
                                     key=f"round{k}-merge-d{low_d}", rank_domain=low_d)
                held[high_d] = submit(_merge_upper, to_high, held[high_d], e.upper_keeps,
                                      key=f"round{k}-merge-d{high_d}", rank_domain=high_d)
        parts = {d: held[d] for d in ranks}
    else:
        plan = radix_plan(len(frames), height, width, factors)
        for k, groups in enumerate(plan.rounds):
            new = {}
            for g in groups:
                for j, part in enumerate(g.parts):
                    receiver = g.members[j]
                    received = [send(held[m], m, part, f"round{k}-d{m}-to-d{receiver}")
                                for m in g.members if m != receiver]
                    new[receiver] = submit(_merge_group, j, part, held[receiver], *received,
                                           key=f"round{k}-merge-d{receiver}",
                                           rank_domain=receiver)
            held.update(new)
        parts = {d: held[d] for d in ranks}
    first = ranks[0]
    gathered = [send(parts[d], d, None, f"gather-d{d}") for d in ranks[1:]]
    final = submit(_paint, frames[0], parts[first], *gathered, key="paint", rank_domain=0)
    return final, pieces


# ------------------------------------------------------------------------ worker-side tasks
def _pack(pixels, region):
    """The encoded piece a rank sends: its drawn pixels (in ``region`` where given)."""
    return (pixels if region is None else pixels.cut(region)).pack()


def _merge_in(own, region, piece):
    """A rank's drawn pixels (cut to ``region`` where given) merged with a piece received from
    a later domain: the lower domain first."""
    from ..algo.softraster.active import merge

    return merge(own if region is None else own.cut(region), piece.unpack())


def _merge_upper(piece, own, region):
    """The upper rank of a swap pair: the piece of the lower domain first, then its own part."""
    from ..algo.softraster.active import merge

    return merge(piece.unpack(), own.cut(region))


def _merge_group(j: int, part, own, *pieces):
    """Radix-k member ``j`` of its group: the group's parts of ``part`` in member order, its own
    in place ``j``."""
    from ..algo.softraster.active import merge_ordered

    items = [p.unpack() for p in pieces]
    items.insert(j, own.cut(part))
    return merge_ordered(items)


def _paint(frame0: Frame, own, *pieces) -> Frame:
    """Rank 0's final frame: every rank's drawn pixels painted over frame 0."""
    from ..algo.softraster.active import paint

    return paint(frame0, [own] + [p.unpack() for p in pieces])


def _piece_bytes(piece) -> int:
    return int(piece.nbytes)

def _ensure_sizeof() -> None:
    """Run on every worker: importing this module registers the frame size with Dask."""


def _frame_shape(frame: Frame) -> tuple[int, int, int]:
    return tuple(int(s) for s in frame.color.shape)


def _cut(frame: Frame, region: Region) -> Frame:
    """A compact copy of the sub-image ``region`` of ``frame`` (what one rank sends)."""
    part = crop(frame, region)
    return Frame(np.ascontiguousarray(part.color), np.ascontiguousarray(part.depth),
                 np.ascontiguousarray(part.triangle))


def _merge(lower: Frame, lower_region: Region | None, upper: Frame,
           upper_region: Region | None) -> Frame:
    """``composite`` of the lower rank's and the upper rank's sub-images of one region, each
    cropped first where a region is given."""
    if lower_region is not None:
        lower = crop(lower, lower_region)
    if upper_region is not None:
        upper = crop(upper, upper_region)
    return composite(lower, upper)


def _gather(height: int, width: int, regions: tuple[Region, ...], *pieces: Frame) -> Frame:
    return assemble(height, width, regions, pieces)


def _received_bytes(run: str, dask_worker=None) -> int:
    """Bytes of this run's keys the worker received from other workers (its transfer log)."""
    total = 0
    for entry in list(dask_worker.transfer_incoming_log):
        total += sum(int(n or 0) for key, n in entry["keys"].items()
                     if isinstance(key, str) and key.startswith(run + "-"))
    return total
