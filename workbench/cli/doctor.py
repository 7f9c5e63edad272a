"""``workbench doctor``: check what the workbench needs on this machine — EGL, its devices, an
OpenGL 3.3 context on the chosen device, the shared data, numba's cache, a Dask round trip — and
name the fix of each failure in one line. Exit status 0 when every check passes, 1 otherwise.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from .arguments import add_device_argument

MESA = "apt-get install libegl1 libegl-mesa0 libgl1-mesa-dri"


@dataclass(frozen=True)
class Check:
    """One check's outcome: ``ok``, what was found (``detail``) and, on failure, the ``fix``."""

    name: str
    ok: bool
    detail: str
    fix: str = ""

    def line(self) -> str:
        status = "ok  " if self.ok else "FAIL"
        text = f"{status} {self.name:<12} {self.detail}"
        return text if self.ok else f"{text}\n     {'':<12} fix: {self.fix}"


def check_egl() -> Check:
    import ctypes

    try:
        ctypes.CDLL("libEGL.so.1")
    except OSError as exc:
        return Check("EGL", False, f"libEGL.so.1 not loadable ({exc})", MESA)
    return Check("EGL", True, "libEGL.so.1 loaded")


def check_devices(device: str | None) -> Check:
    from ..gl.devices import device_index, egl_devices

    devices = egl_devices()
    if not devices:
        return Check("devices", False, "EGL lists no device (EGL_EXT_device_enumeration)",
                     f"{MESA} (Mesa's software device), or install the GPU's EGL driver")
    listed = ", ".join(d.identity for d in devices)
    try:
        index = device_index(device)
    except ValueError as exc:
        return Check("devices", False, f"{listed}; {exc}",
                     "choose one of the listed indices with --device or WORKBENCH_EGL_DEVICE")
    return Check("devices", True, f"{listed}; drawing on device {index}")


def check_gl(device: str | None) -> Check:
    from ..gl.context import (
        GLUnavailable,
        create_context,
        egl,
        gl_version,
        keeping_current,
        renderer,
    )

    with keeping_current() as restore:  # the caller's context (if any) current again after
        try:
            ctx = create_context(device=device)
        except (GLUnavailable, ValueError) as exc:
            return Check("OpenGL", False, str(exc),
                         f"{MESA}, or a GPU driver with OpenGL 3.3 core through EGL")
        restore.display = egl().eglGetCurrentDisplay()
        try:
            return Check("OpenGL", True, f"{gl_version(ctx)} on {renderer(ctx)}")
        finally:
            ctx.release()


def check_shared_data() -> Check:
    from ..data import CAR_DECK, D3PLOT, shared_data_dir

    root = shared_data_dir()
    if root is None:
        return Check("shared data", False, "no shared data folder found",
                     "set WORKBENCH_DATA to the folder holding lsopt_car6/ and "
                     "lasso_simple_d3plot/ (or put shared/data beside the checkout)")
    missing = [str(p) for p in (CAR_DECK, D3PLOT) if not (root / p).is_file()]
    if missing:
        return Check("shared data", False, f"{root} lacks {', '.join(missing)}",
                     "point WORKBENCH_DATA at the complete shared data folder")
    return Check("shared data", True, f"{root}")


def numba_cache_dirs() -> list[Path]:
    """Where numba keeps the workbench's compiled functions: ``NUMBA_CACHE_DIR`` if set, else
    the ``__pycache__`` folders beside the package's modules."""
    configured = os.environ.get("NUMBA_CACHE_DIR")
    if configured:
        return [Path(configured)]
    package = Path(__file__).resolve().parents[1]
    return sorted({p.parent / "__pycache__" for p in package.rglob("*.py")})


def check_numba_cache() -> Check:
    dirs = numba_cache_dirs()
    configured = os.environ.get("NUMBA_CACHE_DIR")
    for folder in dirs:
        probe = folder if folder.exists() else folder.parent
        if not (probe.is_dir() and os.access(probe, os.W_OK)):
            fix = ("set NUMBA_CACHE_DIR to a writable folder" if not configured else
                   f"make NUMBA_CACHE_DIR={configured} a writable folder (or unset it)")
            return Check("numba cache", False, f"{folder} cannot be written: every run "
                         f"compiles again", fix)
    cached = sum(len(list(folder.rglob("*.nbi"))) for folder in dirs if folder.is_dir())
    where = configured or "__pycache__ beside the modules"
    state = (f"{cached} compiled functions cached" if cached else
             "empty: the first run compiles (tens of seconds)")
    return Check("numba cache", True, f"{where}, writable; {state}")


def check_dask(scheduler: str | None) -> Check:
    from ..distributed.cluster import sweep_cluster

    start = time.perf_counter()
    try:
        with sweep_cluster(1 if scheduler is None else None, scheduler, gl=False) as cluster:
            pid = cluster.client.submit(os.getpid, pure=False).result(timeout=60)
            devices = ", ".join(f"{d}" for d in cluster.devices.values())
    except (OSError, ValueError, TimeoutError) as exc:
        where = f"scheduler {scheduler}" if scheduler else "a local cluster"
        return Check("Dask", False, f"no round trip to {where} ({exc})",
                     "give a reachable --scheduler tcp://host:port with workers" if scheduler
                     else "allow local TCP connections on 127.0.0.1 (firewall, sandbox)")
    where = f"scheduler {scheduler}" if scheduler else "a 1-worker local cluster"
    return Check("Dask", True, f"round trip to {where} in {time.perf_counter() - start:.1f} s "
                 f"(worker process {pid}, EGL device {devices or '(none)'})")


def add_parser(subparsers) -> None:
    """Add ``doctor`` to the ``workbench`` command's subparsers."""
    p = subparsers.add_parser(
        "doctor", help="check EGL, devices, OpenGL, shared data, numba's cache and Dask",
        description="Check what the workbench needs on this machine and name the fix of each "
                    "failure. Exit status 0 when every check passes, 1 otherwise.")
    add_device_argument(p)
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help="check a round trip to this Dask scheduler (tcp://host:port) instead "
                        "of a local cluster")
    p.set_defaults(func=cmd_doctor)


def cmd_doctor(args) -> int:
    """Run every check, print a line each (and the fix of a failure); 0 if all pass, else 1."""
    checks: list[Callable[[], Check]] = [
        check_egl, lambda: check_devices(args.device), lambda: check_gl(args.device),
        check_shared_data, check_numba_cache, lambda: check_dask(args.scheduler)]
    results = []
    for check in checks:
        result = check()
        results.append(result)
        print(result.line(), flush=True)
    failed = [r.name for r in results if not r.ok]
    print(f"{len(results) - len(failed)} of {len(results)} checks passed"
          + (f"; failed: {', '.join(failed)}" if failed else ""))
    return 1 if failed else 0
