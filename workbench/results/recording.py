"""A command's run, recorded in the results store: its machine, its run record and its rows.

``workbench run``, ``reproduce`` and ``sweep`` start a :class:`Recorder` (see
:func:`start_run`); every table an experiment writes and every sweep point computed is appended
to the store under the run's id, beside the CSV/Markdown tables written from the same rows.
"""

from __future__ import annotations

import hashlib
import json
import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from .provenance import machine_fingerprint, run_record
from .store import ResultsStore

if TYPE_CHECKING:
    import moderngl


PROVENANCE = "provenance.json"
"""The file in an experiment's output folder that names the run which wrote the folder."""


def file_sha256(path: str | os.PathLike[str]) -> str:
    """The SHA-256 of the file at ``path``, as 64 hex digits."""
    digest = hashlib.sha256()
    with open(path, "rb") as handle:
        for block in iter(lambda: handle.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


@dataclass
class Recorder:
    """Appends the rows of one run (``run``, its record; ``machine``, its fingerprint) to
    ``store``."""

    store: ResultsStore
    run: dict[str, Any]
    machine: dict[str, Any]
    appended: int = 0

    @property
    def run_id(self) -> str:
        return self.run["run_id"]

    def write_provenance(self, folder: str | os.PathLike[str], experiment: str,
                         size: str) -> Path:
        """Write :data:`PROVENANCE` into ``folder`` (an experiment's output folder, before it
        is swapped into place): this run's id, ``experiment``, ``size`` and the SHA-256 of
        every regular file under ``folder`` by its ``/``-separated relative path, so that a
        figure can be traced to the run that made it (and one changed since be told apart).
        Hidden files are left out. Returns the path written."""
        from ..output.tables import atomic_write_text

        folder = Path(folder)
        files = {}
        for path in sorted(folder.rglob("*")):
            relative = path.relative_to(folder)
            if (path.is_file() and not path.is_symlink() and relative.as_posix() != PROVENANCE
                    and not any(part.startswith(".") for part in relative.parts)):
                files[relative.as_posix()] = file_sha256(path)
        record = {"run_id": self.run_id, "experiment": experiment, "size": size,
                  "commit": self.run.get("commit"), "machine_id": self.machine["machine_id"],
                  "files": files}
        return atomic_write_text(folder / PROVENANCE, json.dumps(record, indent=1) + "\n")

    def append(self, rows: Sequence[dict[str, Any]], **common: Any) -> Path | None:
        """Append ``rows`` with the ``common`` columns (``experiment``, ``table`` …) under this
        run; returns the file written (None for no rows)."""
        written = self.store.append_rows(self.run_id, list(rows), **common)
        self.appended += len(rows)
        return written


def start_run(root: str | os.PathLike[str], command: str, size: str | None = None,
              ctx: moderngl.Context | None = None, **extra: Any) -> Recorder:
    """Record this machine (once) and a new run of ``command`` in the store at ``root``;
    the renderer is described from ``ctx`` (default: a context made for the question). Returns
    the run's :class:`Recorder`."""
    store = ResultsStore(root)
    machine = machine_fingerprint(ctx)
    run = run_record(machine, command, size=size, **extra)
    store.record_machine(machine)
    store.record_run(run)
    return Recorder(store, run, machine)
