"""Reliability suite for the mesh readers (:func:`run_reader_stress`, ``workbench stress
readers [--n N] [--seed S]``).

Keyword decks (:mod:`workbench.reliability.decks`) are mutated at random, deterministically
from the seed, and read back with :func:`workbench.scene.readers.keyword.read_keyword` (or an
injected ``reader``) under a time limit. Every successful read — of the unmutated decks too —
is checked against an independent reference, the strict card-by-card decoding of the text
(:mod:`workbench.reliability.strict`): node ids, coordinates, element ids, connectivity, part
ids and thickness must all equal it, and a deck it refuses must not be read at all.

* A benign mutation (CRLF line ends, ``$`` comment lines, lower-case keywords, a UTF-8 byte
  order mark) must read the identical mesh.
* Any other mutation must be refused with :class:`~workbench.scene.readers.ParseError` or read
  the mesh the reference decodes ("consistent read"). A read that differs is a "wrong mesh"
  (the failure names each quantity that differs); a deck the reference cannot decode is
  "unchecked"; any other exception and any read over the time limit are failures too.

Mutation ``i`` of seed ``s`` is drawn from ``random.Random(f"{s}:{i}")``, so every failure
is reproduced by its seed and index alone (:func:`~workbench.reliability.decks.mutated_deck`).
"""

from __future__ import annotations

import signal
import tempfile
import threading
import time
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..scene.readers import ParseError
from .decks import BENIGN, KINDS, Mutation, default_decks, mutated_deck
from .strict import BeyondReference, Refused, expected_mesh, mesh_differences

OUTCOMES = ("identical", "parse error", "consistent read", "wrong mesh", "unchecked",
            "other exception", "hang")
FAILING = ("wrong mesh", "unchecked", "other exception", "hang")
TIMEOUT_S = 10.0


# --------------------------------------------------------------------------- reading
class _Hang(BaseException):
    """A read that ran past the time limit."""


def _on_alarm(signum, frame):
    raise _Hang()


def read_outcome(path: Path, timeout: float, reader=None):
    """(mesh or None, outcome, message) of one read of ``path`` by ``reader`` (default the
    keyword reader) under a ``timeout`` (seconds; enforced with SIGALRM where this runs in the
    main thread of a POSIX process)."""
    from ..scene.readers.keyword import read_keyword

    reader = reader or read_keyword
    timed = hasattr(signal, "setitimer") and threading.current_thread() is threading.main_thread()
    if timed:
        previous = signal.signal(signal.SIGALRM, _on_alarm)
        signal.setitimer(signal.ITIMER_REAL, timeout)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return reader(path), "read", ""
    except _Hang:
        return None, "hang", f"no answer within {timeout:g} s"
    except ParseError as exc:
        return None, "parse error", str(exc)
    except Exception as exc:  # noqa: BLE001 - every other exception type is what is counted
        return None, "other exception", f"{type(exc).__name__}: {exc}"
    finally:
        if timed:
            signal.setitimer(signal.ITIMER_REAL, 0)
            signal.signal(signal.SIGALRM, previous)


def same_mesh(a, b) -> bool:
    """Whether two meshes have equal nodes, elements, parts, node ids, element ids and element
    fields (NaN equal to NaN)."""
    pairs = [(a.nodes, b.nodes), (a.elements, b.elements), (a.parts, b.parts),
             (a.node_ids, b.node_ids), (a.element_ids, b.element_ids)]
    if a.element_fields.keys() != b.element_fields.keys():
        return False
    pairs += [(a.element_fields[k], b.element_fields[k]) for k in a.element_fields]
    return all((x is None and y is None) or (x is not None and y is not None
                                             and np.array_equal(x, y, equal_nan=True))
               for x, y in pairs)


def mesh_problem(mesh, text: bytes) -> str:
    """What a read mesh gets wrong against the strict decoding of the deck ``text`` (each
    quantity that differs, or that the deck must be refused); "" when it agrees. Raises
    :class:`~workbench.reliability.strict.BeyondReference` for a deck the decoding cannot
    judge."""
    try:
        expected = expected_mesh(text)
    except Refused as exc:
        return f"read a deck that must be refused ({exc})"
    return "; ".join(mesh_differences(mesh, expected))


# --------------------------------------------------------------------------- the run
@dataclass
class Failure:
    """A failing read with its reproducer: ``mutated_deck(index, seed, decks)``."""

    seed: int
    index: int
    kind: str
    deck: str
    line: int
    change: str
    outcome: str
    message: str

    def __str__(self) -> str:
        where = f"line {self.line}" if self.line else "whole file"
        return (f"[seed {self.seed} #{self.index}] {self.kind} on {self.deck} ({where}: "
                f"{self.change}): {self.outcome}: {self.message}")


@dataclass
class StressReport:
    """Outcome counts per mutation kind, the failures, and the run's size and time."""

    n: int
    seed: int
    counts: dict[str, dict[str, int]]
    failures: list[Failure]
    seconds: float

    @property
    def totals(self) -> dict[str, int]:
        """Outcome counts over all kinds."""
        return {o: sum(row[o] for row in self.counts.values()) for o in OUTCOMES}

    @property
    def ok(self) -> bool:
        """True when no read failed."""
        return not self.failures

    def table(self) -> str:
        """The counts as a text table: one row per mutation kind, one column per outcome."""
        head = f"{'mutation':<14}" + "".join(f"{o:>17}" for o in OUTCOMES)
        rows = [head, "-" * len(head)]
        for kind in KINDS:
            rows.append(f"{kind:<14}" + "".join(f"{self.counts[kind][o]:>17}" for o in OUTCOMES))
        rows.append("-" * len(head))
        rows.append(f"{'total':<14}" + "".join(f"{self.totals[o]:>17}" for o in OUTCOMES))
        return "\n".join(rows)


def _checked(mesh, text: bytes) -> tuple[str, str]:
    """(outcome, why it fails or "") of a successful read of ``text`` against the reference."""
    try:
        problem = mesh_problem(mesh, text)
    except BeyondReference as exc:
        return "unchecked", f"the strict reference does not decode {exc}"
    return ("wrong mesh", problem) if problem else ("consistent read", "")


def _outcome(mutation: Mutation, original, path: Path, timeout: float,
             reader) -> tuple[str, str]:
    """(outcome, why it fails or "") of reading one mutated deck written to ``path``."""
    path.write_bytes(mutation.text)
    mesh, outcome, message = read_outcome(path, timeout, reader)
    if mesh is None:
        if mutation.kind in BENIGN and outcome == "parse error":
            return outcome, f"a benign change was refused: {message}"
        return outcome, message if outcome in FAILING else ""
    outcome, problem = _checked(mesh, mutation.text)
    if outcome != "consistent read":
        return outcome, problem
    if original is not None and same_mesh(mesh, original):
        return "identical", ""
    if mutation.kind in BENIGN:
        return "wrong mesh", "a benign change read a different mesh"
    return outcome, ""


def run_reader_stress(n: int, seed: int, decks=None, timeout: float = TIMEOUT_S,
                      reader=None) -> StressReport:
    """Read ``n`` mutated decks (drawn from ``seed``) and count the outcomes per mutation kind.

    ``decks`` maps names to deck texts (bytes) or paths; by default :func:`default_decks`.
    ``reader`` (a function of a path returning an FEMesh; default the keyword reader) is what is
    checked: each unmutated deck must read and agree with the strict reference (a failure of
    kind "original" otherwise), then every mutation is read and checked.
    """
    from ..scene.readers.keyword import read_keyword

    reader = reader or read_keyword
    decks = {name: Path(d).read_bytes() if isinstance(d, (str, Path)) else bytes(d)
             for name, d in (decks or default_decks()).items()}
    counts = {kind: dict.fromkeys(OUTCOMES, 0) for kind in KINDS}
    failures = []
    start = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="workbench-stress-") as folder:
        originals = {}
        for name, text in decks.items():
            path = Path(folder) / f"{name}.k"
            path.write_bytes(text)
            mesh, outcome, message = read_outcome(path, timeout, reader)
            if mesh is not None:
                outcome, message = _checked(mesh, text)
            if outcome != "consistent read":
                failures.append(Failure(seed, -1, "original", name, 0, "unmutated", outcome,
                                        message))
            originals[name] = mesh
        target = Path(folder) / "mutated.k"
        for index in range(n):
            mutation = mutated_deck(index, seed, decks)
            outcome, why = _outcome(mutation, originals[mutation.deck], target, timeout, reader)
            counts[mutation.kind][outcome] += 1
            if why and (outcome in FAILING or mutation.kind in BENIGN):
                failures.append(Failure(seed, index, mutation.kind, mutation.deck,
                                        mutation.line, mutation.change, outcome, why))
    return StressReport(n, seed, counts, failures, time.perf_counter() - start)
