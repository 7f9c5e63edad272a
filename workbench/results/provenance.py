"""Where a result comes from: the machine, the renderer, the code and the libraries of a run.

A *machine fingerprint* names the hardware and the renderer a time holds for (CPU model,
logical cores, memory, OS, Python, GL renderer, vendor, version, driver and EGL device); its
``machine_id`` is a hash of those fields, so two runs on the same machine and renderer share
it. A *run record* names one command's run: ``run_id``, ``machine_id``, when it started, the
command, the workbench version, its git commit and whether the tree was dirty, the versions of
the libraries measured against, and the load average when it started. The results store keeps
each fingerprint once and each run once; rows carry only the ``run_id`` (see
:mod:`workbench.results.store`).
"""

from __future__ import annotations

import hashlib
import json
import os
import platform
import re
import secrets
import subprocess
from datetime import UTC, datetime
from importlib import metadata
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    import moderngl

# the libraries the workbench draws, reads or compares with; their versions go into every run
LIBRARIES = ("numpy", "scipy", "numba", "moderngl", "PyOpenGL", "trimesh", "meshio",
             "lasso-python", "libigl", "pymeshlab", "open3d", "pyrender", "pyvista", "vtk",
             "meshoptimizer", "coal", "scikit-image", "matplotlib", "distributed", "pyarrow",
             "duckdb", "fcpw", "imageio-ffmpeg")
MACHINE_FIELDS = ("cpu", "logical_cores", "memory_gib", "os", "python", "renderer",
                  "gl_vendor", "gl_version", "driver", "egl_device")
_RUN_ID = re.compile(r"^[A-Za-z0-9_-][A-Za-z0-9_.-]*$")


def cpu_model() -> str:
    """The CPU's model name (``/proc/cpuinfo`` on Linux, else :func:`platform.processor`)."""
    try:
        for line in Path("/proc/cpuinfo").read_text(encoding="utf-8").splitlines():
            if line.lower().startswith(("model name", "hardware", "cpu model")):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def memory_gib() -> float | None:
    """Physical memory in GiB (to 0.1), None where the system does not say."""
    try:
        return round(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES") / 2**30, 1)
    except (ValueError, OSError, AttributeError):
        return None


def renderer_description(ctx: moderngl.Context | None = None) -> dict[str, str | None]:
    """The renderer fields of a fingerprint from ``ctx`` (default: a context made for the
    question and released); all None where no GL context can be made."""
    from ..gl.context import GLUnavailable, create_context, describe, keeping_current

    if ctx is not None:
        return describe(ctx)
    try:
        with keeping_current() as restore:
            from ..gl.context import egl

            own = create_context()
            restore.display = egl().eglGetCurrentDisplay()
            try:
                return describe(own)
            finally:
                own.release()
    except GLUnavailable:
        return dict.fromkeys(("renderer", "gl_vendor", "gl_version", "driver", "egl_device"))


def machine_fingerprint(ctx: moderngl.Context | None = None,
                        renderer: dict[str, str | None] | None = None) -> dict[str, Any]:
    """This machine's fingerprint (:data:`MACHINE_FIELDS`) and its ``machine_id`` (16 hex
    digits of a SHA-256 over the fields). The renderer fields come from ``renderer`` if given,
    else from ``ctx`` (see :func:`renderer_description`)."""
    fields: dict[str, Any] = {
        "cpu": cpu_model(), "logical_cores": os.cpu_count(), "memory_gib": memory_gib(),
        "os": f"{platform.system()} {platform.release()}",
        "python": platform.python_version(),
        **(renderer if renderer is not None else renderer_description(ctx)),
    }
    fields = {name: fields.get(name) for name in MACHINE_FIELDS}
    digest = hashlib.sha256(json.dumps(fields, sort_keys=True).encode()).hexdigest()[:16]
    return {"machine_id": digest, **fields}


def code_state(root: str | os.PathLike[str] | None = None) -> dict[str, Any]:
    """The workbench's ``version``, its git ``commit`` and whether the tree is ``dirty``
    (uncommitted changes to tracked files) for the checkout at ``root`` (default the one the
    package was imported from); commit and dirty are None outside a git checkout."""
    root = Path(root) if root is not None else Path(__file__).resolve().parents[2]
    state: dict[str, Any] = {"version": metadata.version("workbench"), "commit": None,
                             "dirty": None}

    def git(*args: str) -> str | None:
        try:
            done = subprocess.run(["git", "-C", str(root), *args], capture_output=True,
                                  text=True, timeout=10, check=False)
        except (OSError, subprocess.TimeoutExpired):
            return None
        return done.stdout.strip() if done.returncode == 0 else None

    if git("rev-parse", "--show-toplevel") not in (None, str(root)):
        return state  # the package lies inside some other repository: not its own commit
    commit = git("rev-parse", "HEAD")
    if commit:
        status = git("status", "--porcelain", "--untracked-files=no")
        state.update(commit=commit, dirty=None if status is None else bool(status))
    return state


def library_versions(names: tuple[str, ...] = LIBRARIES) -> dict[str, str | None]:
    """The installed version of each library in ``names`` (None where it is missing)."""
    found: dict[str, str | None] = {}
    for name in names:
        try:
            found[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            found[name] = None
    return found


def new_run_id(now: datetime | None = None) -> str:
    """A run id that sorts by start time and is unique across processes:
    ``YYYYmmddTHHMMSS-<8 hex digits>`` (UTC)."""
    now = now or datetime.now(UTC)
    return f"{now:%Y%m%dT%H%M%S}-{secrets.token_hex(4)}"


def check_run_id(run_id: str) -> str:
    """``run_id`` if it is letters, digits, ``_ . -`` (not a leading dot); ValueError
    otherwise."""
    if not isinstance(run_id, str) or not _RUN_ID.match(run_id):
        raise ValueError(f"run id must be letters, digits, '_', '.' or '-', got {run_id!r}")
    return run_id


def run_record(machine: dict[str, Any], command: str, size: str | None = None,
               run_id: str | None = None, **extra: Any) -> dict[str, Any]:
    """The record of one run on ``machine`` (a fingerprint): ``run_id`` (new unless given),
    ``machine_id``, ``started`` (UTC, ISO 8601), ``command``, ``size`` (the experiments' size,
    if any), the workbench ``version``, ``commit`` and ``dirty``, ``load_1m``/``load_5m``/
    ``load_15m`` (load average when it started), ``libraries`` (JSON: name → version) and
    ``extra`` columns."""
    now = datetime.now(UTC)
    try:
        load = os.getloadavg()
    except OSError:
        load = (None, None, None)
    return {"run_id": check_run_id(run_id) if run_id else new_run_id(now),
            "machine_id": machine["machine_id"], "started": now.isoformat(timespec="seconds"),
            "command": command, "size": size, **code_state(),
            "load_1m": load[0], "load_5m": load[1], "load_15m": load[2],
            "libraries": json.dumps(library_versions(), sort_keys=True), **extra}
