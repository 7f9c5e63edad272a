"""Reliability of the render paths: far from the origin, drawn many times, in another process.

Three checks, each through the one measurement function (:func:`workbench.measurement.rows`):

* **far offset** — every checked path draws a scene and the same scene moved 10³ and 10⁷ model
  units away (the camera follows): geometry is uploaded relative to a float64 origin, so the
  images must be the same, pixel for pixel;
* **soak** — ``n`` prepare → draw → read back → release cycles of one path: after each release
  the path holds no GL object, and the resident memory of the process (RSS, from
  ``/proc/self/statm``) may grow by at most :data:`RSS_LIMIT_MIB` after a warm-up;
* **determinism** — the same image drawn in two fresh processes and in this one has the same
  SHA-256.

:func:`run_render_stress` returns a :class:`RenderStressReport` (``ok``, a table, failures).
"""

from __future__ import annotations

import hashlib
import json
import os
import subprocess
import sys
import time
from dataclasses import dataclass, field

import numpy as np

OFFSETS = (1.0e3, 1.0e7)  # model units (mm): a car body's coordinates, and ten kilometres
SIZE = (160, 120)
RSS_LIMIT_MIB = 32.0
WARMUP_CYCLES = 20
CHECKED_PATHS = ("position", "flat", "gouraud", "pixel_color", "vertex_color", "quad_wire")
# the child process of check_determinism: prints the digest of its argument path's image
_DIGEST_CHILD = ("import json, sys; from workbench.reliability.render import image_digest; "
                 "print(json.dumps({'sha256': image_digest(sys.argv[1])}))")


@dataclass
class RenderStressReport:
    """Rows of the checks (``check``, ``case``, ``result``, ``ok``), the failures (one line
    each) and the seconds taken."""

    rows: list = field(default_factory=list)
    failures: list = field(default_factory=list)
    seconds: float = 0.0

    @property
    def ok(self) -> bool:
        return not self.failures

    def add(self, check: str, case: str, result: str, ok: bool) -> None:
        self.rows.append(dict(check=check, case=case, result=result, ok=ok))
        if not ok:
            self.failures.append(f"{check}: {case}: {result}")

    def table(self) -> str:
        width = max((len(r["case"]) for r in self.rows), default=4)
        lines = [f"{'check':<12} {'case':<{width}}  result"]
        lines.append("-" * len(lines[0]) + "-" * 30)
        for r in self.rows:
            mark = "" if r["ok"] else "   <- FAILED"
            lines.append(f"{r['check']:<12} {r['case']:<{width}}  {r['result']}{mark}")
        return "\n".join(lines)


def stress_scene():
    """The scene every check draws: the es2008 semicylinders, 8 × 8 quads per sheet, with its
    node field ``distance``."""
    from ..scene import generators

    return generators.semicylinders(n=8)


def _style(name: str):
    from ..paths import Style

    return Style(field="distance", bands=6) if name in ("pixel_color", "vertex_color") else Style()


def _image(ctx, mesh, name: str) -> np.ndarray:
    from ..measurement.rows import measure

    return measure(ctx, mesh, name, _style(name), size=SIZE, timed=False).image


def check_far_offset(ctx, report: RenderStressReport, paths=CHECKED_PATHS) -> None:
    """Each path's image of the scene against its image 10³ and 10⁷ units away."""
    mesh = stress_scene()
    for name in paths:
        near = _image(ctx, mesh, name)
        for offset in OFFSETS:
            far = _image(ctx, mesh.translated([offset, -offset, 0.5 * offset]), name)
            differing = int((far != near).any(axis=-1).sum())
            report.add("far offset", f"{name} at {offset:.0e}",
                       f"{differing} pixels differ" if differing else "identical",
                       differing == 0)


def resident_mib() -> float:
    """The resident set size of this process in MiB (``/proc/self/statm``)."""
    with open("/proc/self/statm") as statm:
        pages = int(statm.read().split()[1])
    return pages * os.sysconf("SC_PAGE_SIZE") / 2**20


def check_soak(ctx, report: RenderStressReport, cycles: int, name: str = "pixel_color") -> None:
    """``cycles`` prepare/draw/read/release cycles of path ``name``: no GL object kept after a
    release, RSS growth after :data:`WARMUP_CYCLES` within :data:`RSS_LIMIT_MIB`."""
    from ..measurement.rows import measure
    from ..paths import make_path

    mesh = stress_scene()
    kept, start = 0, None
    for i in range(cycles + WARMUP_CYCLES):
        if i == WARMUP_CYCLES:
            start = resident_mib()
        path = make_path(name, _style(name))
        measure(ctx, mesh, path, size=SIZE, timed=False)
        kept += len(path._objects) + (path.ctx is not None)
    growth = resident_mib() - start
    report.add("soak", f"{name} x {cycles}", f"{kept} GL objects kept after release, "
               f"RSS {growth:+.1f} MiB", kept == 0 and growth <= RSS_LIMIT_MIB)


def image_digest(name: str) -> str:
    """SHA-256 of path ``name``'s image of :func:`stress_scene` on a new context."""
    from ..gl import create_context

    return hashlib.sha256(_image(create_context(), stress_scene(), name).tobytes()).hexdigest()


def check_determinism(ctx, report: RenderStressReport, name: str = "gouraud",
                      processes: int = 2) -> None:
    """The image's SHA-256 here and in ``processes`` fresh Python processes."""
    here = hashlib.sha256(_image(ctx, stress_scene(), name).tobytes()).hexdigest()
    digests = []
    for _ in range(processes):
        out = subprocess.run([sys.executable, "-c", _DIGEST_CHILD, name],
                             capture_output=True, text=True, timeout=300)
        digests.append(json.loads(out.stdout.strip().splitlines()[-1])["sha256"]
                       if out.returncode == 0 else f"exit {out.returncode}: {out.stderr[-200:]}")
    same = all(d == here for d in digests)
    report.add("determinism", f"{name} in {processes} processes",
               "same SHA-256" if same else f"{here[:12]} here, {[d[:12] for d in digests]}", same)


def run_render_stress(cycles: int = 300) -> RenderStressReport:
    """All three checks on one new context; ``cycles`` soak cycles."""
    from ..gl import create_context

    start = time.perf_counter()
    ctx = create_context()
    report = RenderStressReport()
    check_far_offset(ctx, report)
    check_soak(ctx, report, cycles)
    check_determinism(ctx, report)
    report.seconds = time.perf_counter() - start
    return report

