"""The figures an experiment wrote into ``<figures>/<experiment>/`` and the run that made each.

A recorded run writes ``provenance.json`` into its figure folder: ``{"run_id": …,
"experiment": …, "size": …, "files": {"name.png": "<sha256 hex>", …}}``. A figure is linked
to that run where the file's SHA-256 is the one listed and the run is in the store; otherwise
it carries a note saying why it is not from a stored run (no ``provenance.json``, a file not
listed, changed since, or a run the store does not hold). Images (PNG, SVG, GIF, JPEG, WebP)
are shown inline, videos (MP4, WebM) and PDFs are linked. Hidden files and folders are left
out, as is the store's own folder.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

from ..results.recording import PROVENANCE, file_sha256

IMAGES = (".png", ".svg", ".gif", ".jpg", ".jpeg", ".webp")
LINKED = (".mp4", ".webm", ".pdf")


@dataclass(frozen=True)
class FigureFile:
    """One figure file: ``name`` (its path under the experiment's folder, with ``/``),
    ``path`` (where it is on disk), whether it is an ``image`` (else a linked file), the
    ``run_id`` that made it (None where that cannot be told) and a ``note`` saying why not."""

    name: str
    path: Path
    image: bool
    run_id: str | None
    note: str | None


def _provenance(folder: Path) -> tuple[dict | None, str | None]:
    """The folder's ``provenance.json`` (None with the reason where it is absent or
    unreadable)."""
    path = folder / PROVENANCE
    if not path.is_file():
        return None, f"no {PROVENANCE}"
    try:
        found = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        return None, f"{PROVENANCE} unreadable ({exc})"
    if not isinstance(found, dict) or not isinstance(found.get("files"), dict):
        return None, f"{PROVENANCE} lists no files"
    return found, None


def experiment_figures(folder: Path, runs: set[str] | frozenset[str]) -> list[FigureFile]:
    """The figure files under ``folder`` (an experiment's figure folder; none where it is
    missing or not a real folder), sorted by name, each with the run of ``runs`` that made
    it (see the module docstring)."""
    if not folder.is_dir() or folder.is_symlink():
        return []
    provenance, why = _provenance(folder)
    found = []
    for path in sorted(folder.rglob("*")):
        relative = path.relative_to(folder)
        if (path.suffix.lower() not in IMAGES + LINKED or not path.is_file()
                or path.is_symlink() or any(p.startswith(".") for p in relative.parts)
                or relative.parts[0] == "results"):
            continue
        name = relative.as_posix()
        run_id, note = None, why
        if provenance is not None:
            listed = provenance["files"].get(name)
            if listed is None:
                note = f"not listed in {PROVENANCE}"
            elif listed != file_sha256(path):
                note = f"changed since run {provenance.get('run_id')} wrote it"
            elif provenance.get("run_id") not in runs:
                note = f"run {provenance.get('run_id')} is not in the results store"
            else:
                run_id, note = str(provenance["run_id"]), None
        found.append(FigureFile(name, path, path.suffix.lower() in IMAGES, run_id, note))
    return found
