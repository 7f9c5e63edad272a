"""A command's run, recorded in the results store: its machine, its run record and its rows.

``workbench run``, ``reproduce`` and ``sweep`` start a :class:`Recorder` (see
:func:`start_run`); every table an experiment writes and every sweep point computed is appended
to the store under the run's id, beside the CSV/Markdown tables written from the same rows.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from .provenance import machine_fingerprint, run_record
from .store import ResultsStore

if TYPE_CHECKING:
    import moderngl


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
