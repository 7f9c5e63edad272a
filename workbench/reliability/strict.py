"""An independent, strict decoding of a keyword deck's text (:func:`strict_count`): the ids of
its well-formed node cards and shell element records, card by card, without the reader's code.
The reader suite checks a read of a mutated deck against it."""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field

from .decks import BOM

_KEYWORD = re.compile(rb"\*\s*([A-Za-z0-9_]+)\s*([%+-])?")


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
