"""Reliability suite for the mesh readers: ``workbench stress readers [--n N] [--seed S]``
(``stress render`` runs :mod:`workbench.render_stress`, ``stress all`` both).

Keyword decks (the shared car deck when present, and small generated decks in fixed and
comma format, with ``*ELEMENT_SHELL_THICKNESS``, ``*PART`` and ``*SECTION_SHELL``) are
mutated at random, deterministically from the seed, and read back with
:func:`workbench.scene.readers.keyword.read_keyword` under a time limit.

* A benign mutation (CRLF line ends, ``$`` comment lines, lower-case keywords, a UTF-8 byte
  order mark) must read the identical mesh: nodes, elements, parts, node and element ids.
* Any other mutation must either be refused with :class:`~workbench.scene.readers.ParseError`
  or read a consistent mesh: finite coordinates, node and element counts equal to the
  well-formed node and element cards that a strict, independent decoding of the mutated text
  finds, and node and element ids all among those cards' ids. A read that differs is a
  "wrong mesh"; any other exception and any read over the time limit are failures too.

Mutation ``i`` of seed ``s`` is drawn from ``random.Random(f"{s}:{i}")``, so every failure
is reproduced by its seed and index alone (:func:`mutated_deck`).
"""

from __future__ import annotations

import math
import random
import re
import signal
import sys
import tempfile
import threading
import time
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .scene.readers import ParseError

BENIGN = ("crlf", "comments", "lowercase", "bom")
HARMFUL = ("delete", "duplicate", "swap", "garble", "huge", "nonfinite", "truncate_card",
           "truncate_mid")
KINDS = BENIGN + HARMFUL
OUTCOMES = ("identical", "parse error", "consistent read", "wrong mesh", "other exception",
            "hang")
FAILING = ("wrong mesh", "other exception", "hang")
TIMEOUT_S = 10.0
BOM = b"\xef\xbb\xbf"
_GARBLE = b"abcxyzEeDd0123456789 .,-+*$&\t\x00\xff"
_NUMBER = re.compile(rb"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eEdD][-+]?\d+)?")
_KEYWORD = re.compile(rb"\*\s*([A-Za-z0-9_]+)\s*([%+-])?")


# --------------------------------------------------------------------------- decks
def _grid_nodes(nx: int, ny: int, z: float = 0.0) -> list[tuple[int, float, float, float]]:
    """(id, x, y, z) of an nx × ny grid of nodes, ids from 1, spacing 10."""
    return [(1 + i + nx * j, 10.0 * i, 10.0 * j, z) for j in range(ny) for i in range(nx)]


def _grid_quads(nx: int, ny: int, first_id: int = 1) -> list[tuple[int, int, int, int, int]]:
    """(eid, n1, n2, n3, n4) of the quads of an nx × ny node grid."""
    quads = []
    for j in range(ny - 1):
        for i in range(nx - 1):
            a = 1 + i + nx * j
            quads.append((first_id + len(quads), a, a + 1, a + 1 + nx, a + nx))
    return quads


def fixed_deck() -> bytes:
    """A standard-format deck: *PART, *SECTION_SHELL, *NODE and *ELEMENT_SHELL (with a triangle)."""
    lines = ["$ generated fixed-format deck", "*KEYWORD", "*PART", "plate",
             f"{1:>10}{1:>10}{1:>10}", "*SECTION_SHELL", f"{1:>10}{2:>10}",
             f"{1.5:>10}{1.5:>10}{1.5:>10}{1.5:>10}", "*NODE"]
    lines += [f"{n:>8}{x:>16}{y:>16}{z:>16}{0:>8}{0:>8}" for n, x, y, z in _grid_nodes(4, 4)]
    lines.append("*ELEMENT_SHELL")
    quads = _grid_quads(4, 4)
    lines += [f"{e:>8}{1:>8}{a:>8}{b:>8}{c:>8}{d:>8}" for e, a, b, c, d in quads[:-1]]
    e, a, b, c, _ = quads[-1]
    lines.append(f"{e:>8}{1:>8}{a:>8}{b:>8}{c:>8}{c:>8}")
    lines.append("*END")
    return ("\n".join(lines) + "\n").encode()


def comma_deck() -> bytes:
    """A comma-separated deck that starts with its *NODE block (no *KEYWORD line)."""
    lines = ["*NODE"]
    lines += [f"{n},{x},{y},{z}" for n, x, y, z in _grid_nodes(3, 3, 5.0)]
    lines.append("*ELEMENT_SHELL")
    lines += [f"{e},2,{a},{b},{c},{d}" for e, a, b, c, d in _grid_quads(3, 3, 100)]
    lines += ["*PART", "shell part", "2,7,1", "*SECTION_SHELL", "7,16", "2.0,2.0,2.0,2.0"]
    return ("\n".join(lines) + "\n").encode()


def thickness_deck() -> bytes:
    """A standard-format deck with an *ELEMENT_SHELL block and an *ELEMENT_SHELL_THICKNESS block."""
    lines = ["*KEYWORD", "*NODE"]
    lines += [f"{n:>8}{x:>16}{y:>16}{z:>16}" for n, x, y, z in _grid_nodes(5, 3)]
    quads = _grid_quads(5, 3)
    lines.append("*ELEMENT_SHELL")
    lines += [f"{e:>8}{3:>8}{a:>8}{b:>8}{c:>8}{d:>8}" for e, a, b, c, d in quads[:4]]
    lines.append("*ELEMENT_SHELL_THICKNESS")
    for e, a, b, c, d in quads[4:]:
        lines.append(f"{e:>8}{3:>8}{a:>8}{b:>8}{c:>8}{d:>8}")
        lines.append(f"{0.8:>16}{0.9:>16}{1.0:>16}{1.1:>16}")
    lines += ["*PART", "thick part", f"{3:>10}{3:>10}{1:>10}",
              "*SECTION_SHELL", f"{3:>10}{2:>10}", f"{1.2:>10}", "*END"]
    return ("\n".join(lines) + "\n").encode()


def default_decks() -> dict[str, bytes]:
    """The decks the suite mutates: the generated ones, and the shared car deck when present."""
    from .data import CAR_DECK, shared_file

    decks = {"fixed": fixed_deck(), "comma": comma_deck(), "thickness": thickness_deck()}
    car = shared_file(CAR_DECK)
    if car is not None:
        decks["car6"] = car.read_bytes()
    return decks


# --------------------------------------------------------------------------- mutations
@dataclass
class Mutation:
    """One mutated deck: its kind, the deck it came from, what changed, and the new text."""

    index: int
    kind: str
    deck: str
    line: int  # 1-based line of the original deck the change is at (0: the whole file)
    change: str
    text: bytes


def _data_rows(lines: list[bytes]) -> list[int]:
    """Indices of the lines that are neither comments nor blank (cards and keywords)."""
    return [i for i, line in enumerate(lines) if line.strip() and not line.startswith(b"$")]


def _number_spans(line: bytes) -> list[tuple[int, int]]:
    """(start, end) of each number on ``line``, widened left over the blanks before it."""
    spans = []
    for match in _NUMBER.finditer(line):
        start = match.start()
        while start > 0 and line[start - 1:start] == b" ":
            start -= 1
        spans.append((max(start, spans[-1][1] if spans else 0), match.end()))
    return spans


def _replace_number(rng: random.Random, lines: list[bytes], values: list[bytes]):
    """(new lines, row, change) with one number of a card replaced by one of ``values``,
    right-aligned in its field when it fits; None when the deck has no number."""
    rows = [i for i in _data_rows(lines) if not lines[i].startswith(b"*") and _NUMBER.search(lines[i])]
    if not rows:
        return None
    row = rng.choice(rows)
    line = lines[row]
    start, end = rng.choice(_number_spans(line))
    value = rng.choice(values)
    width = end - start
    new = value.rjust(width) if len(value) < width else value
    if b"," in line and len(value) >= width:
        new = value
    out = list(lines)
    out[row] = line[:start] + new + line[end:]
    return out, row, f"{line[start:end].strip().decode()!r} -> {value.decode()!r}"


def _joined(lines: list[bytes]) -> bytes:
    """The text of ``lines``, each ended with a line feed."""
    return b"\n".join(lines) + b"\n"


def _mutate(kind: str, rng: random.Random, lines: list[bytes]):
    """(new text, 0-based row or -1, change) for one mutation of ``kind``."""
    n = len(lines)
    if kind == "crlf":
        return b"\r\n".join(lines) + b"\r\n", -1, "CRLF line ends"
    if kind == "bom":
        return BOM + _joined(lines), -1, "UTF-8 byte order mark"
    if kind == "lowercase":
        return _joined([ln.lower() if ln.startswith(b"*") else ln for ln in lines]), -1, \
            "keywords in lower case"
    if kind == "comments":
        out = list(lines)
        rows = sorted(rng.randrange(n + 1) for _ in range(rng.randint(1, 5)))
        for k, row in enumerate(rows):
            out.insert(row + k, b"$ inserted comment *NODE 1,2,3")
        return _joined(out), rows[0], f"{len(rows)} comment line(s) inserted"
    rows = _data_rows(lines) or list(range(n))
    if kind == "delete":
        row = rng.choice(rows)
        return _joined(lines[:row] + lines[row + 1:]), row, f"deleted {lines[row][:40]!r}"
    if kind == "duplicate":
        row = rng.choice(rows)
        return _joined(lines[:row + 1] + lines[row:]), row, f"duplicated {lines[row][:40]!r}"
    if kind == "swap":
        a = rng.choice(rows)
        b = min(n - 1, a + rng.randint(1, 3)) if rng.random() < 0.5 else rng.choice(rows)
        out = list(lines)
        out[a], out[b] = out[b], out[a]
        return _joined(out), a, f"swapped lines {a + 1} and {b + 1}"
    if kind == "garble":
        row = rng.choice(rows)
        line = bytearray(lines[row] or b" ")
        for _ in range(rng.randint(1, 3)):
            at = rng.randrange(len(line))
            line[at] = rng.choice(_GARBLE)
        out = list(lines)
        out[row] = bytes(line)
        return _joined(out), row, f"{lines[row]!r} -> {bytes(line)!r}"
    if kind in ("huge", "nonfinite"):
        values = [b"1e300", b"-1e300", b"1.0e+300"] if kind == "huge" else \
            [b"nan", b"inf", b"-inf", b"NaN", b"Infinity"]
        replaced = _replace_number(rng, lines, values)
        if replaced is None:
            return _joined(lines), -1, "no number to replace"
        out, row, change = replaced
        return _joined(out), row, change
    if kind == "truncate_card":
        row = rng.randrange(1, n + 1)
        return _joined(lines[:row]), row, f"cut after line {row}"
    if kind == "truncate_mid":
        row = rng.choice([i for i in range(n) if len(lines[i]) > 1] or [0])
        cut = rng.randrange(1, max(2, len(lines[row])))
        text = _joined(lines[:row]) + lines[row][:cut]
        return text, row, f"cut line {row + 1} after column {cut}"
    raise ValueError(f"unknown mutation kind {kind!r}")


def mutated_deck(index: int, seed: int, decks: dict[str, bytes]) -> Mutation:
    """Mutation ``index`` of run ``seed`` over ``decks``: deck and kind drawn from its own
    ``random.Random(f"{seed}:{index}")``."""
    rng = random.Random(f"{seed}:{index}")
    name = rng.choice(sorted(decks))
    kind = rng.choice(KINDS)
    lines = decks[name].split(b"\n")
    if lines and not lines[-1]:
        lines.pop()
    text, row, change = _mutate(kind, rng, lines)
    return Mutation(index, kind, name, row + 1, change, text)


# --------------------------------------------------------------------------- strict decoding
@dataclass
class StrictCount:
    """What an independent strict decoding finds in a deck's text: the ids of its well-formed
    node cards and of its well-formed shell element records."""

    node_ids: list[int] = field(default_factory=list)
    element_ids: list[int] = field(default_factory=list)


def _widths(widths: tuple[int, ...], fmt: str) -> tuple[int, ...]:
    """Field widths of a standard layout in format ``fmt`` (small, i10 or long)."""
    if fmt == "long":
        return tuple(max(w, 20) for w in widths)
    if fmt == "i10":
        return tuple(max(w, 10) for w in widths)
    return widths


def _fields(line: bytes, widths: tuple[int, ...]) -> list[bytes]:
    """A card's field texts: comma-separated when it holds a comma, else fixed columns."""
    if b"," in line:
        parts = line.split(b",")
        return (parts + [b""] * len(widths))[:len(widths)]
    out, at = [], 0
    for w in widths:
        out.append(line[at:at + w])
        at += w
    return out


def _number(text: bytes, integer: bool):
    """The value of one field (blank = 0); None when it is not a number of that kind.
    Integer fields take integral floats; ``D`` exponents read as ``E``."""
    text = text.strip()
    if not text:
        return 0
    if b"_" in text:
        return None
    try:
        value = float(text.replace(b"D", b"E").replace(b"d", b"e"))
    except ValueError:
        return None
    if not integer:
        return value
    if not math.isfinite(value) or value != math.floor(value) or abs(value) >= 2.0 ** 63:
        return None
    return int(text) if text.lstrip(b"+-").isdigit() else int(value)


def _complete(line: bytes, widths: tuple[int, ...], used: int) -> bool:
    """Whether an unterminated last line holds all ``used`` leading fields."""
    line = line.rstrip()
    if b"," in line:
        return len(line.split(b",")) >= used
    return len(line) >= sum(widths[:used])


def _node_id(line: bytes, fmt: str, last: bool) -> int | None:
    """The id of a well-formed node card (nonzero id, three finite coordinates), else None."""
    widths = _widths((8, 16, 16, 16), fmt)
    if last and not _complete(line, widths, 4):
        return None
    texts = _fields(line, widths)
    nid = _number(texts[0], True)
    xyz = [_number(t, False) for t in texts[1:4]]
    if not nid or any(v is None or not math.isfinite(v) for v in xyz):
        return None
    return nid


def _element_id(cards: list[bytes], fmt: str, last: bool) -> int | None:
    """The id of a well-formed shell record (element card, then any thickness/offset cards)."""
    widths = _widths((8,) * 10, fmt)
    if last and not _complete(cards[-1], widths if len(cards) == 1 else _widths((16,) * 4, fmt),
                              6 if len(cards) == 1 else 4):
        return None
    texts = _fields(cards[0], widths)
    values = [_number(t, True) for t in texts[:6]]
    if any(v is None for v in values) or not values[0]:
        return None
    if len(cards) > 1:
        tail = [_number(t, True) for t in texts[6:10]]
        if any(v is None or v != 0 for v in tail):
            return None
        thickness = [_number(t, False) for t in _fields(cards[1], _widths((16,) * 4, fmt))]
        if any(v is None for v in thickness):
            return None
    return values[0]


def _shell_records(name: str, rows: list[bytes]) -> list[list[bytes]] | None:
    """The records (cards per element) of an *ELEMENT_SHELL block, None for options not read."""
    options = set(filter(None, name[len("ELEMENT_SHELL"):].split("_")))
    if options - {"THICKNESS", "BETA", "MCID", "OFFSET"}:
        return None
    per = 1 + bool(options & {"THICKNESS", "BETA", "MCID"}) + ("OFFSET" in options)
    if per == 1:
        return [[r] for r in rows if r.strip()]
    while len(rows) % per and rows and not rows[-1].strip():
        rows = rows[:-1]
    return [rows[i:i + per] for i in range(0, len(rows) - len(rows) % per, per)]


def strict_count(text: bytes) -> StrictCount:
    """The well-formed node cards and shell records of a deck's text, decoded card by card."""
    text = text.removeprefix(BOM)
    unterminated = bool(text) and not text.endswith((b"\n", b"\r"))
    lines = text.replace(b"\r\n", b"\n").replace(b"\r", b"\n").split(b"\n")
    if lines and not lines[-1]:
        lines.pop()
    count = StrictCount()
    fmt, block = "small", None  # block: (name, fmt, data lines, whether it holds the last line)
    blocks = []
    for i, line in enumerate(lines):
        if line.startswith(b"*"):
            match = _KEYWORD.match(line)
            name = match.group(1).decode().upper() if match else ""
            if name == "END":
                break
            if name == "KEYWORD":
                options = line.upper().replace(b" ", b"")
                if b"LONG=Y" in options:
                    fmt = "long"
                elif b"I10=Y" in options:
                    fmt = "i10"
            suffix = match.group(2) if match else None
            block_fmt = {b"%": "i10", b"+": "long", b"-": "small"}.get(suffix, fmt)
            block = [name, block_fmt, [], False]
            blocks.append(block)
        elif block is not None and not line.startswith(b"$"):
            block[2].append(line)
            block[3] = unterminated and i == len(lines) - 1
    for name, block_fmt, rows, has_last in blocks:
        if name in ("NODE", "NODE_MERGE"):
            kept = [r for r in rows if r.strip()]
            for k, row in enumerate(kept):
                nid = _node_id(row, block_fmt, has_last and k == len(kept) - 1)
                if nid is not None:
                    count.node_ids.append(nid)
        elif name.startswith("ELEMENT_SHELL"):
            records = _shell_records(name, rows) or []
            for k, cards in enumerate(records):
                eid = _element_id(cards, block_fmt, has_last and k == len(records) - 1)
                if eid is not None:
                    count.element_ids.append(eid)
    return count


# --------------------------------------------------------------------------- reading
class _Hang(BaseException):
    """A read that ran past the time limit."""


def _on_alarm(signum, frame):
    raise _Hang()


def _read(path: Path, timeout: float, reader=None):
    """(mesh or None, outcome, message) of one read of ``path`` by ``reader`` (default the
    keyword reader) under a ``timeout`` (seconds; enforced with SIGALRM where this runs in the
    main thread of a POSIX process)."""
    from .scene.readers.keyword import read_keyword

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
    """Whether two meshes have equal nodes, elements, parts, node ids and element ids."""
    pairs = [(a.nodes, b.nodes), (a.elements, b.elements), (a.parts, b.parts),
             (a.node_ids, b.node_ids), (a.element_ids, b.element_ids)]
    return all((x is None and y is None) or (x is not None and y is not None
                                             and np.array_equal(x, y)) for x, y in pairs)


def mesh_problem(mesh, text: bytes) -> str:
    """Why a read mesh disagrees with the strict decoding of ``text``; "" when it agrees."""
    expected = strict_count(text)
    if not np.isfinite(mesh.nodes).all():
        return "non-finite coordinates"
    if len(mesh.nodes) != len(expected.node_ids):
        return f"{len(mesh.nodes)} nodes read, {len(expected.node_ids)} well-formed node cards"
    if len(mesh.elements) != len(expected.element_ids):
        return (f"{len(mesh.elements)} elements read, {len(expected.element_ids)} well-formed "
                "element records")
    if mesh.node_ids is not None and not set(mesh.node_ids.tolist()) <= set(expected.node_ids):
        return "node ids that no well-formed node card defines"
    if mesh.element_ids is not None and \
            not set(mesh.element_ids.tolist()) <= set(expected.element_ids):
        return "element ids that no well-formed element record defines"
    if ((mesh.elements < 0) | (mesh.elements >= len(mesh.nodes))).any():
        return "an element names a node that does not exist"
    return ""


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


def _outcome(mutation: Mutation, original, path: Path, timeout: float) -> tuple[str, str]:
    """(outcome, why it fails or "") of reading one mutated deck written to ``path``."""
    path.write_bytes(mutation.text)
    mesh, outcome, message = _read(path, timeout)
    if mesh is None:
        if mutation.kind in BENIGN and outcome == "parse error":
            return outcome, f"a benign change was refused: {message}"
        return outcome, message if outcome in FAILING else ""
    if same_mesh(mesh, original):
        return "identical", ""
    if mutation.kind in BENIGN:
        return "wrong mesh", "a benign change read a different mesh"
    problem = mesh_problem(mesh, mutation.text)
    return ("wrong mesh", problem) if problem else ("consistent read", "")


def run_reader_stress(n: int, seed: int, decks=None, timeout: float = TIMEOUT_S) -> StressReport:
    """Read ``n`` mutated decks (drawn from ``seed``) and count the outcomes per mutation kind.

    ``decks`` maps names to deck texts (bytes) or paths; by default :func:`default_decks`.
    """
    from .scene.readers.keyword import read_keyword

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
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                originals[name] = read_keyword(path)
        target = Path(folder) / "mutated.k"
        for index in range(n):
            mutation = mutated_deck(index, seed, decks)
            outcome, why = _outcome(mutation, originals[mutation.deck], target, timeout)
            counts[mutation.kind][outcome] += 1
            if why and (outcome in FAILING or mutation.kind in BENIGN):
                failures.append(Failure(seed, index, mutation.kind, mutation.deck,
                                        mutation.line, mutation.change, outcome, why))
    return StressReport(n, seed, counts, failures, time.perf_counter() - start)


# --------------------------------------------------------------------------- d3plot files
D3PLOT_KINDS = ("truncate", "garble", "zero block")


@dataclass
class D3plotStressReport:
    """Outcomes of ``n`` damaged copies of a d3plot: ``counts`` (kind → outcome → count; the
    outcomes are "read" — whole, or with the sections that failed named in warnings —, "parse
    error", "other exception" and "hang"), ``failures`` (one line each, with the seed and
    index that reproduce it) and ``seconds``."""

    n: int
    seed: int
    counts: dict
    failures: list
    seconds: float

    @property
    def ok(self) -> bool:
        return not self.failures

    def table(self) -> str:
        outcomes = ("read", "parse error", "other exception", "hang")
        rows = [f"{'d3plot damage':<14}" + "".join(f"{o:>17}" for o in outcomes)]
        rows.append("-" * len(rows[0]))
        for kind in D3PLOT_KINDS:
            rows.append(f"{kind:<14}" + "".join(f"{self.counts[kind][o]:>17}" for o in outcomes))
        return "\n".join(rows)


def damaged_d3plot(data: bytes, index: int, seed: int) -> tuple[str, bytes]:
    """(kind, bytes) of damage ``index`` of ``seed`` to the d3plot ``data``: cut at a random
    byte, 1–16 random bytes overwritten, or a block of up to 4 KiB zeroed."""
    rng = random.Random(f"d3plot:{seed}:{index}")
    kind = rng.choice(D3PLOT_KINDS)
    damaged = bytearray(data)
    if kind == "truncate":
        del damaged[rng.randrange(64, len(damaged)):]
    elif kind == "garble":
        for _ in range(rng.randint(1, 16)):
            damaged[rng.randrange(len(damaged))] = rng.randrange(256)
    else:
        start = rng.randrange(len(damaged))
        end = min(len(damaged), start + rng.randint(1, 4096))
        damaged[start:end] = bytes(end - start)
    return kind, bytes(damaged)


def run_d3plot_stress(n: int, seed: int, source=None,
                      timeout: float = TIMEOUT_S) -> D3plotStressReport | None:
    """Read ``n`` damaged copies of the d3plot ``source`` (default: the first file of the
    shared d3plot; None when it is absent): each must be read or refused with ParseError,
    never another exception, never past ``timeout`` seconds."""
    from .data import D3PLOT, shared_file
    from .scene.readers.d3plot import read_d3plot

    source = shared_file(D3PLOT) if source is None else Path(source)
    if source is None:
        return None
    data = Path(source).read_bytes()
    counts = {kind: dict.fromkeys(("read", "parse error", "other exception", "hang"), 0)
              for kind in D3PLOT_KINDS}
    failures = []
    start = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="workbench-stress-") as folder:
        target = Path(folder) / "d3plot"
        for index in range(n):
            kind, damaged = damaged_d3plot(data, index, seed)
            target.write_bytes(damaged)
            _, outcome, why = _read(target, timeout, read_d3plot)
            counts[kind][outcome] += 1
            if outcome in ("other exception", "hang"):
                failures.append(f"d3plot seed {seed} index {index} ({kind}): {outcome}: {why}")
    return D3plotStressReport(n, seed, counts, failures, time.perf_counter() - start)


# --------------------------------------------------------------------------- command line
def _print_report(title: str, report, unit: str) -> bool:
    """Print a suite's title line, table and failures, then OK or FAILED; returns ``ok``."""
    print(title)
    print(report.table())
    for failure in report.failures:
        print(failure)
    print("OK" if report.ok else f"FAILED: {len(report.failures)} failing {unit}")
    return report.ok


def cmd_stress(args) -> int:
    """``workbench stress readers|render|all``: print each suite's table and failures; 1 when
    any check failed."""
    ok = True
    if args.suite in ("readers", "all"):
        report = run_reader_stress(args.n, args.seed)
        ok &= _print_report(f"reader stress: {report.n} mutations, seed {report.seed}, "
                            f"{report.seconds:.1f} s", report, "read(s)")
        damaged = run_d3plot_stress(args.n, args.seed)
        if damaged is None:
            print("d3plot stress: skipped (the shared d3plot is absent: set WORKBENCH_DATA)")
        else:
            ok &= _print_report(f"d3plot stress: {damaged.n} damaged copies, seed "
                                f"{damaged.seed}, {damaged.seconds:.1f} s", damaged, "read(s)")
    if args.suite in ("render", "all"):
        from .render_stress import run_render_stress

        render = run_render_stress(args.cycles)
        ok &= _print_report(f"render stress: far offset, {args.cycles} soak cycles, "
                            f"determinism, {render.seconds:.1f} s", render, "check(s)")
    sys.stdout.flush()
    return 0 if ok else 1


def add_stress_parser(subparsers) -> None:
    """Add the ``stress`` command to the ``workbench`` command's subparsers."""
    p = subparsers.add_parser(
        "stress", help="reliability suites: mutated decks for the readers, far-offset, soak and "
                       "determinism checks for the render paths",
        description="readers: mutate keyword decks at random and check every read (identical for "
                    "benign changes, else ParseError or a mesh consistent with the mutated text). "
                    "render: images 10^3 and 10^7 units from the origin equal to those at it, "
                    "prepare/draw/release cycles that keep no GL object and no memory, the same "
                    "image in other processes. all: both. Exit status 1 on any failure.")
    p.add_argument("suite", choices=["readers", "render", "all"], help="which suite to run")
    p.add_argument("--n", type=int, default=200, help="reader mutations (default 200)")
    p.add_argument("--seed", type=int, default=0, help="random seed of the mutations (default 0)")
    p.add_argument("--cycles", type=int, default=300,
                   help="prepare/draw/release cycles of the render soak (default 300)")
    p.set_defaults(func=cmd_stress)
