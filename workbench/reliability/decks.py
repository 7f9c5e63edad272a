"""The keyword decks the reader suite mutates and the mutations (:func:`mutated_deck`).

The decks are the shared car deck when present and small generated decks in fixed, comma and
long format, with ``*ELEMENT_SHELL_THICKNESS``, ``*PART``, ``*SECTION_SHELL`` and
``*PARAMETER``. A mutation is
benign (CRLF line ends, ``$`` comment lines, lower-case keywords, a UTF-8 byte order mark:
the same mesh must be read) or harmful (lines deleted, duplicated, swapped or garbled, huge or
non-finite numbers, a deck cut after a card or inside one).

Mutation ``i`` of seed ``s`` is drawn from ``random.Random(f"{s}:{i}")``, so every failure
is reproduced by its seed and index alone.
"""

from __future__ import annotations

import random
import re
from dataclasses import dataclass

BENIGN = ("crlf", "comments", "lowercase", "bom")
HARMFUL = ("delete", "duplicate", "swap", "garble", "huge", "nonfinite", "truncate_card",
           "truncate_mid")
KINDS = BENIGN + HARMFUL
BOM = b"\xef\xbb\xbf"
_GARBLE = b"abcxyzEeDd0123456789 .,-+*$&\t\x00\xff"
_NUMBER = re.compile(rb"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eEdD][-+]?\d+)?")


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
    """A standard-format deck: ``*PART``, ``*SECTION_SHELL``, ``*NODE`` and ``*ELEMENT_SHELL`` (with
    a triangle)."""
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
    """A comma-separated deck that starts with its ``*NODE`` block (no ``*KEYWORD`` line)."""
    lines = ["*NODE"]
    lines += [f"{n},{x},{y},{z}" for n, x, y, z in _grid_nodes(3, 3, 5.0)]
    lines.append("*ELEMENT_SHELL")
    lines += [f"{e},2,{a},{b},{c},{d}" for e, a, b, c, d in _grid_quads(3, 3, 100)]
    lines += ["*PART", "shell part", "2,7,1", "*SECTION_SHELL", "7,16", "2.0,2.0,2.0,2.0"]
    return ("\n".join(lines) + "\n").encode()


def thickness_deck() -> bytes:
    """A standard-format deck with an ``*ELEMENT_SHELL`` block and an
    ``*ELEMENT_SHELL_THICKNESS`` block."""
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


def long_deck() -> bytes:
    """A long-format deck (``*KEYWORD LONG=Y``: every field 20 columns) with ``*PARAMETER``,
    ``*PART``, ``*SECTION_SHELL`` (thickness by a parameter), ``*NODE`` and
    ``*ELEMENT_SHELL_THICKNESS``."""
    lines = ["*KEYWORD LONG=Y", "*PARAMETER", f"{'Rtlong':<20}{0.75:>20}", "*PART",
             "long part", f"{4:>20}{9:>20}{1:>20}", "*SECTION_SHELL", f"{9:>20}{2:>20}",
             f"{'&tlong':<20}", "*NODE"]
    lines += [f"{n + 1000:>20}{x + 0.125:>20}{y:>20}{z - 3.5:>20}"
              for n, x, y, z in _grid_nodes(4, 3)]
    lines.append("*ELEMENT_SHELL_THICKNESS")
    for e, a, b, c, d in _grid_quads(4, 3, 500):
        lines.append("".join(f"{v:>20}" for v in (e, 4, a + 1000, b + 1000, c + 1000,
                                                    d + 1000)))
        lines.append("".join(f"{t:>20}" for t in (0.5, 0.0, 0.6, 0.0)))
    lines.append("*END")
    return ("\n".join(lines) + "\n").encode()


def default_decks() -> dict[str, bytes]:
    """The decks the suite mutates: the generated ones (standard, comma and long format), and
    the shared car deck when present."""
    from ..data import CAR_DECK, shared_file

    decks = {"fixed": fixed_deck(), "comma": comma_deck(), "thickness": thickness_deck(),
             "long": long_deck()}
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
    rows = [i for i in _data_rows(lines)
            if not lines[i].startswith(b"*") and _NUMBER.search(lines[i])]
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
