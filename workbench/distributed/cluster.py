"""The Dask cluster a sweep runs on, the GL context each worker keeps, and the per-host draw lock.

:func:`sweep_cluster` starts a :class:`~distributed.LocalCluster` of worker processes on this
machine (one thread each) or connects to an existing scheduler, registers
:class:`GLContextPlugin` (every worker creates one headless EGL context, in the thread its tasks
run on, and reuses it for every task) and closes what it started on the way out, also on
KeyboardInterrupt; inside :func:`~workbench.distributed.kept.kept_clusters` a local cluster is
kept for the whole block instead. A task reaches its worker's context with
:func:`worker_context`.

Each worker is pinned to one EGL device before its first context exists (:func:`pin_devices`:
round-robin over each host's devices, or an explicit list), so the workers of a multi-GPU node
spread over its GPUs; :attr:`SweepCluster.devices` says which device each worker draws on.
Dask's own log lines are kept at WARNING unless ``verbose``.

Timed draws disturb each other, so a task holds :func:`draw_lock` (one
:class:`distributed.Lock` per host name, held through the scheduler) around its timed
measurement; error-only work takes no lock and runs in parallel.
"""

from __future__ import annotations

import asyncio
import importlib
import logging
import os
import socket
import threading
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from typing import TYPE_CHECKING

import dask
from distributed import Client, LocalCluster, Lock, WorkerPlugin, get_worker

from .kept import innermost_kept

if TYPE_CHECKING:
    import moderngl
    from distributed import Worker

PLUGIN_NAME = "workbench-gl"
VERBOSE_ENV = "WORKBENCH_VERBOSE"  # "1": Dask's INFO log lines (the commands' --verbose)
# a scheduler that answers at all answers within a second; one that does not is refused soon
CONNECT_TIMEOUT_S = 5
WORKER_WAIT_S = 60


class GLContextPlugin(WorkerPlugin):
    """Gives a worker one EGL context per task thread (one in all with ``threads_per_worker=1``).

    An EGL context is current in the thread that created it only, so :meth:`setup` creates the
    first one in the worker's task executor; a worker running tasks in more threads gets one
    more context per thread, on first use. ``renderer`` is the renderer string of the first
    context. A worker without EGL fails :meth:`setup` with
    :class:`~workbench.gl.GLUnavailable`.
    """

    name = PLUGIN_NAME

    def __init__(self, imports: tuple[str, ...] = ()) -> None:
        self.renderer: str | None = None
        self.device: str | None = None  # the EGL device identity of the first context
        self.imports = tuple(imports)
        self._contexts: dict[int, moderngl.Context] = {}

    async def setup(self, worker: Worker) -> None:
        _import_in_main_thread()
        executor = worker.executors.get("default")
        await asyncio.get_running_loop().run_in_executor(executor, self._start)

    def _start(self) -> None:
        """Create the first context and import what every task uses (the paths, the
        measurement, the image comparison, and the caller's ``imports``), so that the first
        task's time is not spent importing."""
        self.context()
        from skimage.metrics import structural_similarity  # noqa: F401

        from .. import paths  # noqa: F401  (registers every path)
        from ..measurement import images as compare  # noqa: F401

        for module in self.imports:
            importlib.import_module(module)

    def context(self) -> moderngl.Context:
        """The moderngl context of the calling thread, created on first use."""
        thread = threading.get_ident()
        ctx = self._contexts.get(thread)
        if ctx is None:
            from ..gl import create_context, renderer
            from ..gl.devices import current_device

            ctx = create_context()
            self._contexts[thread] = ctx
            if self.renderer is None:
                self.renderer = renderer(ctx)
                device = current_device()
                self.device = device.identity if device is not None else None
        return ctx

    def teardown(self, worker: Worker) -> None:
        self._contexts.clear()  # the process exits with its contexts; releasing needs their threads


def _import_in_main_thread() -> None:
    """Import the libraries that must first be imported in a process's main thread (the
    worker's event loop runs there; tasks run in executor threads). pymeshlab imported first
    in another thread makes the process abort at exit (glibc: "malloc_consolidate(): unaligned
    fastbin chunk detected")."""
    if threading.current_thread() is not threading.main_thread():
        return
    try:
        import pymeshlab  # noqa: F401
    except ImportError:
        pass


def worker_context() -> moderngl.Context:
    """The GL context of the worker running the calling task (RuntimeError elsewhere)."""
    try:
        plugin = get_worker().plugins[PLUGIN_NAME]
    except (ValueError, KeyError):
        raise RuntimeError("no workbench GL context: not running on a sweep worker") from None
    return plugin.context()


def worker_device() -> str | None:
    """The EGL device identity of the worker running the calling task (None elsewhere or
    before its context exists)."""
    try:
        return get_worker().plugins[PLUGIN_NAME].device
    except (ValueError, KeyError):
        return None


def _worker_renderer(dask_worker) -> str | None:
    plugin = dask_worker.plugins.get(PLUGIN_NAME)
    return None if plugin is None else plugin.renderer


def _device_count() -> int:
    from ..gl.devices import egl_devices

    return len(egl_devices())


def _pin(index: int) -> int:
    """Pin the calling worker process to EGL device ``index`` (its contexts made from now on)."""
    from ..gl.devices import DEVICE_ENV

    os.environ[DEVICE_ENV] = str(index)
    return index


def _pinned_device(dask_worker) -> str | None:
    """The identity of the EGL device the worker draws on: its GL context's, else the one it
    is pinned to; None where it has no EGL device."""
    from ..gl.devices import DEVICE_ENV, egl_devices

    plugin = dask_worker.plugins.get(PLUGIN_NAME)
    if plugin is not None and plugin.device is not None:
        return plugin.device
    devices = egl_devices()
    index = int(os.environ.get(DEVICE_ENV) or 0)
    return devices[index].identity if index < len(devices) else None


def device_assignment(counts: dict[str, int], hosts: dict[str, str],
                      devices: Sequence[int] | None = None) -> dict[str, int]:
    """{worker address: EGL device index}: the workers of each host (``hosts``: address → host
    name), in address order, take that host's ``counts[address]`` devices round-robin, or the
    indices ``devices`` in turn. Workers whose host has no EGL device are left out.

    Refused (ValueError): an index in ``devices`` that a host with workers does not have,
    whether or not a worker of that host would be dealt it."""
    by_host: dict[str, list[str]] = {}
    for address in sorted(counts):
        by_host.setdefault(hosts.get(address, address), []).append(address)
    assigned = {}
    for host, addresses in by_host.items():
        count = max(counts[address] for address in addresses)
        if count == 0:
            continue
        wrong = [index for index in devices or () if not 0 <= index < count]
        if wrong:
            raise ValueError(f"--worker-devices {wrong[0]}: host {host} has {count} EGL "
                             f"device{'s' if count != 1 else ''}")
        for i, address in enumerate(addresses):
            assigned[address] = devices[i % len(devices)] if devices else i % count
    return assigned


def pin_devices(client: Client, devices: Sequence[int] | None = None) -> dict[str, int]:
    """Pin every worker of ``client`` to one EGL device of its host
    (:func:`device_assignment`: round-robin, or ``devices`` in turn); returns {worker address:
    device index}. A worker restarted by its nanny starts unpinned (device 0, or its
    environment's choice)."""
    counts = client.run(_device_count)
    info = client.scheduler_info(n_workers=-1)["workers"]
    hosts = {address: info.get(address, {}).get("host", address) for address in counts}
    assigned = device_assignment(counts, hosts, devices)
    for address, index in assigned.items():
        client.run(_pin, index, workers=[address])
    return assigned


def draw_lock_name(host: str | None = None) -> str:
    """The name of the lock serializing timed draws on ``host`` (default this machine)."""
    return f"workbench-draw-{host or socket.gethostname()}"


@contextmanager
def draw_lock() -> Iterator[None]:
    """Hold this host's draw lock for the block (inside a task on a sweep worker)."""
    lock = Lock(draw_lock_name())
    lock.acquire()
    try:
        yield
    finally:
        lock.release()


@dataclass
class SweepCluster:
    """A connected client, the number of workers it found, the renderer they draw with, the
    scheduler's address and the EGL device identity each worker draws on ({address: identity},
    None for a worker without EGL)."""

    client: Client
    workers: int
    renderer: str
    address: str
    devices: dict[str, str | None]


def _renderer_of(client: Client) -> str:
    """The one renderer string every worker reports; ValueError when they differ (times drawn
    on different renderers are not comparable, nor are their cache keys)."""
    found = client.run(_worker_renderer)
    names = sorted({r for r in found.values() if r is not None})
    if len(names) != 1:
        raise ValueError(f"the cluster's workers report renderers {names or ['(none)']}; "
                         f"a sweep needs workers on one renderer")
    return names[0]


@contextmanager
def sweep_cluster(workers: int | None = None, scheduler: str | None = None, *,
                  raster_threads: int | None = None, gl: bool = True,
                  imports: tuple[str, ...] = (), devices: Sequence[int] | None = None,
                  verbose: bool | None = None) -> Iterator[SweepCluster]:
    """A :class:`SweepCluster`: a new LocalCluster of ``workers`` processes (default
    ``os.cpu_count()``, one thread each), or the cluster at ``scheduler``
    (``tcp://host:port``), with :class:`GLContextPlugin` registered on every worker.

    ``imports`` names the modules (``"package.module"``) every worker imports once its GL
    context exists, so that the first task does not spend its time importing them (with
    ``gl=True`` only).

    ``gl=False`` registers no GL context on the workers (work that draws with the software
    rasterizer only: the workers need no EGL; ``renderer`` is then "software").

    Every worker is pinned to an EGL device first (:func:`pin_devices`; ``devices`` lists the
    indices to deal out, default each host's devices round-robin). Dask's log lines (scheduler,
    nanny, worker, client) print at WARNING and above, at INFO with ``verbose`` (default: the
    environment's ``WORKBENCH_VERBOSE=1``, which the commands' ``--verbose`` sets).

    ``raster_threads`` sets llvmpipe's rasterizer threads (``LP_NUM_THREADS``) in the local
    workers, unless the environment sets it already: 1 suits error-only sweeps, whose workers
    fill the cores by themselves; None leaves llvmpipe one thread per core, as timed draws
    (one at a time per host) want.

    Everything started here is closed on the way out, except inside
    :func:`~workbench.distributed.kept.kept_clusters`,
    where a local cluster of the same arguments is started once and shared until that block
    ends. Refused: ``workers`` < 1 and ``workers`` together with ``scheduler`` (ValueError), a
    scheduler that cannot be reached or has no workers within a minute (OSError).
    """
    if scheduler is not None and workers is not None:
        raise ValueError("--workers sizes a local cluster; an existing scheduler keeps its workers")
    if workers is not None and (int(workers) != workers or workers < 1):
        raise ValueError(f"workers must be a positive integer, got {workers}")
    arguments = dict(workers=workers, scheduler=scheduler, raster_threads=raster_threads, gl=gl,
                     imports=tuple(imports), devices=None if devices is None else tuple(devices),
                     verbose=verbose)
    kept = innermost_kept() if scheduler is None else None
    if kept is None:
        with _started_cluster(**arguments) as cluster:
            yield cluster
        return
    key = tuple(arguments.items())
    if key not in kept.clusters:
        kept.clusters[key] = kept.stack.enter_context(_started_cluster(**arguments))
    yield kept.clusters[key]


@contextmanager
def _started_cluster(workers: int | None, scheduler: str | None, raster_threads: int | None,
                     gl: bool, imports: tuple[str, ...], devices: Sequence[int] | None,
                     verbose: bool | None) -> Iterator[SweepCluster]:
    """The cluster :func:`sweep_cluster` describes, started (or connected to) here and closed
    on the way out."""
    if scheduler is not None and workers is not None:
        raise ValueError("--workers sizes a local cluster; an existing scheduler keeps its workers")
    if workers is not None and (int(workers) != workers or workers < 1):
        raise ValueError(f"workers must be a positive integer, got {workers}")
    cluster = client = None
    if verbose is None:
        verbose = os.environ.get(VERBOSE_ENV) == "1"
    level = logging.INFO if verbose else logging.WARNING
    logging.getLogger("distributed").setLevel(level)
    try:
        if scheduler is None:
            # the statistical profiler samples every task thread's stack every 10 ms, holding
            # the GIL: it would slow down and disturb what the workers time
            env = {}
            if raster_threads is not None and "LP_NUM_THREADS" not in os.environ:
                env["LP_NUM_THREADS"] = str(int(raster_threads))
            with dask.config.set({"distributed.worker.profile.enabled": False}):
                cluster = LocalCluster(n_workers=int(workers or os.cpu_count() or 1),
                                       processes=True, threads_per_worker=1,
                                       dashboard_address=None, silence_logs=level,
                                       env=env)
            client = Client(cluster)
        else:
            try:
                client = Client(scheduler, timeout=CONNECT_TIMEOUT_S)
                client.wait_for_workers(1, timeout=WORKER_WAIT_S)
            except TimeoutError as exc:
                raise OSError(f"scheduler {scheduler}: {exc or 'no workers'}") from None
        pin_devices(client, devices)
        if gl:
            client.register_plugin(GLContextPlugin(imports), name=PLUGIN_NAME)
        count = len(client.scheduler_info(n_workers=-1)["workers"])
        yield SweepCluster(client, count, _renderer_of(client) if gl else "software",
                           client.scheduler.address, client.run(_pinned_device))
    finally:
        if client is not None:
            client.close()
        if cluster is not None:
            cluster.close()
