"""Synthetic results stores and figure folders for the site's tests: runs of ``render_paths``
(a registered experiment, so its claims and legends come from its declaration) and of
unregistered experiments, written with ``ResultsStore.record_machine``/``record_run``/
``append_rows``, and figure folders with a ``provenance.json``."""

from __future__ import annotations

import hashlib
import json
import struct
import zlib
from pathlib import Path

import numpy as np

from workbench.results.store import ResultsStore

MACHINE = {"machine_id": "m0test", "cpu": "Test CPU 3000", "logical_cores": 4,
           "memory_gib": 15.5, "os": "Linux-6.1", "python": "3.12.1",
           "renderer": "llvmpipe (LLVM 15.0.6, 256 bits)", "gl_vendor": "Mesa",
           "gl_version": "4.5 (Core Profile) Mesa 22.3.6", "driver": "Mesa 22.3.6",
           "egl_device": "0"}
PATHS = ("position", "flat", "gouraud")


def png_bytes(width: int = 4, height: int = 3, colour: tuple[int, int, int] = (200, 30, 30)
              ) -> bytes:
    """A valid RGB PNG of ``width`` × ``height`` pixels of one colour."""
    def chunk(kind: bytes, data: bytes) -> bytes:
        return (struct.pack(">I", len(data)) + kind + data
                + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF))
    raw = b"".join(b"\x00" + bytes(colour) * width for _ in range(height))
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2,
                                                              0, 0, 0))
            + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))


def targets_rows(scale: float, rng: np.random.Generator) -> list[dict]:
    """The ``targets`` table of ``render_paths``: its ratios ``scale`` times 1.25 and 0.5."""
    rows = []
    for scene, triangles in (("car", 80_000), ("semicylinders", 8_192)):
        noise = float(rng.normal(1.0, 0.01))
        over = 1.25 * scale * noise
        rows.append({"scene": scene, "size": "640x480", "triangles": triangles,
                     "contour_wall_ms": 2.0 * scale * noise, "contour_over_position_only": over,
                     "contour_over_position_only_lo": over * 0.97,
                     "contour_over_position_only_hi": over * 1.03,
                     "contour_msaa_over_pyrender": 0.5, "contour_msaa_over_pyrender_lo": 0.45,
                     "contour_msaa_over_pyrender_hi": 0.55, "pyrender_ssim": 0.99})
    return rows


def paths_rows(scale: float, rng: np.random.Generator) -> list[dict]:
    """The main table of ``render_paths``: three paths with times, samples and errors."""
    rows = []
    for k, path in enumerate(PATHS):
        samples = (1.0 + k) * scale * rng.lognormal(0, 0.03, 9)
        rows.append({"scene": "car", "path": path, "triangles": 80_000,
                     "wall_ms": float(np.median(samples)), "wall_ms_lo": float(samples.min()),
                     "wall_ms_hi": float(samples.max()), "wall_samples_ms": samples.tolist(),
                     "max_diff_255": float(3 - k), "ssim": 0.9 + 0.03 * k})
    return rows


def add_run(store: ResultsStore, run_id: str, *, size: str, started: str, commit: str,
            scale: float = 1.0, experiments: tuple[str, ...] = ("render_paths",),
            seed: int = 0) -> None:
    """Record run ``run_id`` storing ``render_paths`` (its ``table`` and ``targets``, times
    and ratios ``scale`` times their base) and, per other name in ``experiments``, one table
    with a time and an error column."""
    rng = np.random.default_rng(seed)
    store.record_machine(MACHINE)
    store.record_run({"run_id": run_id, "machine_id": MACHINE["machine_id"], "started": started,
                      "command": f"reproduce --{size}", "size": size, "commit": commit,
                      "dirty": False, "load_1m": 0.25})
    for name in experiments:
        common = {"experiment": name, "experiment_size": size}
        if name == "render_paths":
            store.append_rows(run_id, paths_rows(scale, rng), table="table", **common)
            store.append_rows(run_id, targets_rows(scale, rng), table="targets", **common)
        else:
            rows = [{"case": f"c{k}", "seconds": 0.5 * (k + 1) * scale,
                     "max_abs_error_mm": 1.0 / (k + 1), "note": "<b>escaped</b>"}
                    for k in range(4)]
            store.append_rows(run_id, rows, table="table", **common)


def reproduce_store(root: Path, experiments: tuple[str, ...] = ("render_paths",)
                    ) -> ResultsStore:
    """One full ``reproduce`` and two quick ones (runs ``full-1``, ``quick-1``, ``quick-2``)."""
    store = ResultsStore(root)
    for i, (run_id, size) in enumerate((("quick-1", "quick"), ("full-1", "full"),
                                        ("quick-2", "quick"))):
        add_run(store, run_id, size=size, started=f"2026-12-0{i + 1}T10:00:00",
                commit=f"{i + 1:x}" * 40, experiments=experiments, seed=i)
    return store


def step_store(root: Path, runs: int = 20, step: float = 1.3) -> ResultsStore:
    """``runs`` full runs of ``render_paths`` (``step-00`` …), its ratios ``step`` times
    higher from run ``runs // 2`` on (the run named :func:`first_after_step`)."""
    store = ResultsStore(root)
    for i in range(runs):
        add_run(store, f"step-{i:02d}", size="full", started=f"2026-11-{i + 1:02d}T10:00:00",
                commit=f"{i:02x}" + "c0ffee" * 6 + "00", scale=step if i >= runs // 2 else 1.0,
                seed=i)
    return store


def first_after_step(runs: int = 20) -> str:
    """The run of :func:`step_store` where the step begins."""
    return f"step-{runs // 2:02d}"


def figure_folder(figures: Path, experiment: str, run_id: str) -> dict[str, Path]:
    """Write figures of ``experiment`` under ``figures``: ``made.png`` listed in its
    ``provenance.json`` (by ``run_id``), ``changed.png`` listed with another hash,
    ``unlisted.svg`` not listed, ``movie.mp4`` (linked, not shown); their paths by name."""
    folder = figures / experiment
    (folder / "sub").mkdir(parents=True, exist_ok=True)
    files = {"made.png": folder / "made.png", "changed.png": folder / "sub" / "changed.png",
             "unlisted.svg": folder / "unlisted.svg", "movie.mp4": folder / "movie.mp4"}
    files["made.png"].write_bytes(png_bytes())
    files["changed.png"].write_bytes(png_bytes(colour=(0, 90, 200)))
    files["unlisted.svg"].write_text('<svg xmlns="http://www.w3.org/2000/svg" width="20" '
                                     'height="10"><rect width="20" height="10" fill="green"/>'
                                     "</svg>")
    files["movie.mp4"].write_bytes(b"\x00\x00\x00\x18ftypmp42")
    listed = {"made.png": hashlib.sha256(files["made.png"].read_bytes()).hexdigest(),
              "sub/changed.png": "0" * 64}
    (folder / "provenance.json").write_text(json.dumps(
        {"run_id": run_id, "experiment": experiment, "size": "full", "files": listed}))
    return files
