"""Cards of an LS-DYNA keyword deck: the lines of a file, its keyword blocks, and the splitting
of cards into fields and of fields into numbers.

A card is fixed width (the standard, I10 and long formats, :func:`field_width`; a blank field
reads as 0) or, when it holds a comma, comma-separated. Large blocks are converted column by
column with numpy (:func:`_table`); the per-card Python path (:func:`_card_fields`,
:func:`_convert`) only runs for free-format cards and to locate an error, which is a
:class:`~workbench.scene.readers.errors.ParseError` naming the file, the 1-based line and the card.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from operator import itemgetter
from pathlib import Path

import numpy as np

from .errors import ParseError

# Eight fields of 10 columns (standard format): *PART card 2, *SECTION_SHELL cards and
# *PARAMETER pairs.
_TEN = (10,) * 8


def field_width(width: int, fmt: str) -> int:
    """The width of a standard-format field of ``width`` columns in format ``fmt``.

    ``fmt`` is "small" (standard), "i10" (fields under 10 columns become 10) or "long" (every
    field becomes 20 columns).
    """
    if fmt == "i10":
        return max(width, 10)
    if fmt == "long":
        return max(width, 20)
    return width


# --------------------------------------------------------------------------- source files
class _Source:
    """The lines of one file, with the first byte of each line for fast classification."""

    def __init__(self, path: Path):
        self.path = path
        try:
            data = path.read_bytes()
        except OSError as exc:
            raise ParseError(path, f"cannot read: {exc.strerror or exc}") from exc
        data = data.removeprefix(b"\xef\xbb\xbf")  # a UTF-8 byte order mark is no text
        if b"\r" in data:
            if b"\n" not in data:  # classic Mac line ends
                data = data.replace(b"\r", b"\n")
            data = data.replace(b"\r\n", b"\n")
            stray = data.find(b"\r")
            if stray >= 0:
                line = data.count(b"\n", 0, stray) + 1
                raise ParseError(path, "a carriage return inside a line (a line end of another "
                                 "system, or a damaged file)", line=line)
        nul = data.find(b"\x00")
        if nul >= 0:
            raise ParseError(path, "a NUL byte (binary data, or a damaged file)",
                             line=data.count(b"\n", 0, nul) + 1)
        # a file that does not end with a line end may have been cut off: _table checks its
        # last card
        self.unterminated = bool(data) and not data.endswith(b"\n")
        self.lines = data.split(b"\n")
        if len(self.lines) > 1 and not self.lines[-1]:
            self.lines.pop()  # what follows the final newline is no line
        buf = np.frombuffer(data, np.uint8)
        starts = np.empty(len(self.lines), np.int64)
        starts[0] = 0
        starts[1:] = np.flatnonzero(buf == 10)[:len(self.lines) - 1] + 1
        first = np.zeros(len(starts), np.uint8)
        inside = starts < len(buf)
        first[inside] = buf[starts[inside]]
        self.first = first

    def card(self, row: int) -> str:
        return self.lines[row].decode("utf-8", "replace").rstrip()

    def pick(self, rows: np.ndarray) -> list[bytes]:
        """The lines at ``rows`` (0-based indices)."""
        if len(rows) == 0:
            return []
        if rows[-1] - rows[0] + 1 == len(rows):
            return self.lines[int(rows[0]):int(rows[-1]) + 1]
        picked = itemgetter(*rows.tolist())(self.lines)
        return list(picked) if len(rows) > 1 else [picked]

    def error(self, message: str, row: int | None = None, keyword: str | None = None) -> ParseError:
        if row is None:
            return ParseError(self.path, message, keyword=keyword)
        return ParseError(self.path, message, line=int(row) + 1, card=self.card(row),
                          keyword=keyword)


@dataclass
class _Block:
    src: _Source
    keyword: str  # upper case, without the star
    fmt: str
    row: int  # 0-based index of the keyword line
    rows: np.ndarray  # 0-based indices of its data lines, comments left out

    def error(self, message: str, row: int | None = None) -> ParseError:
        return self.src.error(message, self.row if row is None else row, self.keyword)

    def blank(self, row) -> bool:
        return not self.src.lines[row].strip()

    def refuse_if_cut(self, row: int, widths, used: int) -> None:
        """Refuse the card at ``row`` when it is the file's last line, no line end follows it,
        and the file may end inside the first ``used`` fields read from it: fixed columns
        shorter than those fields, or comma-separated fields with no comma after the last one
        read (``5,0.,0.,17`` may be the start of ``5,0.,0.,1778``: nothing tells them apart)."""
        if not self.src.unterminated or row != len(self.src.lines) - 1:
            return
        line = self.src.lines[row].rstrip()
        if b"," in line:
            complete = len(line.split(b",")) > used
        else:
            complete = len(line) >= _layout(widths[:used], self.fmt)[1][-1]
        if not complete:
            raise self.error("the file ends inside this card (no line end after it, and the "
                             "last field read may be cut short)", row)

    def trimmed(self, period: int) -> np.ndarray:
        """The data rows less trailing blank lines, as many as keep the count off a multiple of
        ``period`` (a blank card is valid data; a stray blank line before the next keyword is not).
        """
        rows = self.rows
        end = len(rows)
        while end % period and end and self.blank(rows[end - 1]):
            end -= 1
        return rows[:end]


# --------------------------------------------------------------------------- field conversion
@dataclass(frozen=True)
class _Field:
    index: int  # position of the field on its card
    kind: str  # "i" integer, "id" integer written as one (an id), "f" float
    what: str  # what was expected, for messages


def _layout(widths, fmt: str) -> tuple[list[int], list[int]]:
    widths = [field_width(w, fmt) for w in widths]
    return widths, np.concatenate([[0], np.cumsum(widths)]).astype(int).tolist()


def _card_fields(line: bytes, widths, fmt: str) -> list[bytes]:
    """The field texts of one card (fixed columns, or comma-separated when it holds a comma)."""
    if b"," in line:
        parts = line.split(b",")
        parts += [b""] * (len(widths) - len(parts))
        return parts[:len(widths)]
    widths, starts = _layout(widths, fmt)
    return [line[starts[i]:starts[i + 1]] for i in range(len(widths))]


def _convert(text: bytes, kind: str):
    """One field's value (blank = 0); ValueError when it is not a number of that kind.

    An integer field ("i") also takes an integral float in any notation (``0.000E+00``,
    ``8.``), as LS-DYNA reads it; a fractional or non-finite one is refused. An id field ("id":
    node, element and part ids) takes integral floats in decimal notation only (``101.0``, as
    other pre-processors write ids), never an exponent, so that ``1e1`` is no node 10.
    Underscores (which Python's number parsing would accept as digit separators) are refused in
    every field."""
    text = text.strip()
    if not text:
        return 0.0 if kind == "f" else 0
    if b"_" in text:
        raise ValueError(text)
    if kind == "id" and any(c in text for c in b"eEdD"):
        raise ValueError(text)
    if kind in ("i", "id"):
        if text.lstrip(b"+-").isdigit():
            value = int(text)
        else:
            number = float(text.replace(b"D", b"E").replace(b"d", b"e"))
            if not math.isfinite(number) or number != math.floor(number):
                raise ValueError(text)
            value = int(number)
        if not -2**63 <= value < 2**63:
            raise ValueError(text)
        return value
    return float(text.replace(b"D", b"E").replace(b"d", b"e"))


def _shown(text: bytes) -> str:
    return text.strip().decode("utf-8", "replace")


def _diagnose(block: _Block, rows: np.ndarray, widths, fields: list[_Field]) -> ParseError:
    """The error for the first card of ``rows`` (in file order) that does not convert."""
    for row in rows.tolist():
        texts = _card_fields(block.src.lines[row], widths, block.fmt)
        for f in fields:
            try:
                _convert(texts[f.index], f.kind)
            except ValueError:
                return block.error(f"expected {f.what}, got {_shown(texts[f.index])!r}", row)
    return block.error("a card could not be converted", int(rows[0]) if len(rows) else None)


_BLANK_FIELD: dict[int, np.ndarray] = {}


def _fixed_column(chars: np.ndarray, start: int, width: int, kind: str,
                  underscores: bool = True) -> np.ndarray:
    """Convert columns ``start:start+width`` of the (n, W) byte array; ValueError when one fails.

    Blank fields (spaces, or NUL padding past the end of a short line) read as 0, a Fortran
    ``D`` exponent as ``E``, and an integer field takes an integral float (``0.000E+00``; an id
    field, ``kind`` "id", without an exponent only); all three are only looked for when the
    plain conversion fails. Underscores are refused (``underscores=False``: the caller knows
    there are none).
    """
    sub = np.ascontiguousarray(chars[:, start:start + width])
    if underscores and (sub == ord("_")).any():
        raise ValueError("underscore in a numeric field")
    text = sub.view(f"S{width}").ravel()
    dtype = np.float64 if kind == "f" else np.int64
    try:
        return text.astype(dtype)
    except ValueError:
        pass
    blank = (sub <= 32).all(axis=1)
    if blank.any():
        if width not in _BLANK_FIELD:
            _BLANK_FIELD[width] = np.frombuffer(b" " * (width - 1) + b"0", np.uint8)
        sub[blank] = _BLANK_FIELD[width]
    if kind == "id":
        letters = (sub == ord("e")) | (sub == ord("E")) | (sub == ord("d")) | (sub == ord("D"))
        if letters.any():
            raise ValueError("an id written with an exponent")
    exponent = (sub == ord("D")) | (sub == ord("d"))
    if exponent.any():
        sub[exponent] = ord("E")
    if kind == "f":
        return text.astype(dtype)  # ``text`` views ``sub``: the repairs show through
    try:
        return text.astype(dtype)
    except ValueError:
        number = text.astype(np.float64)  # integral floats, as LS-DYNA reads them
    if not (np.isfinite(number).all() and (number == np.floor(number)).all()
            and (np.abs(number) < 2.0**63).all()):
        raise ValueError("an integer field holds a fractional or non-finite number")
    return number.astype(np.int64)


def _table(block: _Block, rows: np.ndarray, widths, fields: list[_Field],
           drop_blank: bool = False) -> tuple[np.ndarray, list[np.ndarray]]:
    """Convert ``fields`` of the cards at ``rows``: (rows read, one array per field).

    Fixed-width cards are converted column by column with numpy; comma-separated cards one by
    one. ``drop_blank`` leaves out blank lines (keywords whose records are single cards). The
    first card that does not convert raises :class:`ParseError` with its line.
    """
    cols, starts = _layout(widths, block.fmt)
    span = starts[max(f.index for f in fields) + 1]
    lines = block.src.pick(rows)
    chars = np.array(lines, dtype=f"S{span}").view(np.uint8).reshape(len(lines), span)
    if drop_blank and len(rows):
        maybe = np.flatnonzero((chars <= 32).all(axis=1))
        blank = [i for i in maybe.tolist() if not lines[i].strip()]
        if blank:
            keep = np.ones(len(rows), bool)
            keep[blank] = False
            rows, chars = rows[keep], chars[keep]
            lines = [line for line, k in zip(lines, keep.tolist()) if k]
    out = [np.zeros(len(rows), np.float64 if f.kind == "f" else np.int64) for f in fields]
    if len(rows) == 0:
        return rows, out
    block.refuse_if_cut(int(rows[-1]), widths, max(f.index for f in fields) + 1)
    raw = chars.tobytes()
    # a comma anywhere on the line makes the card comma-separated, also past the fields read
    if b"\n".join(lines).find(b",") < 0:  # memchr: cheaper than a per-row test when none
        free = np.zeros(len(rows), bool)
    else:
        free = np.array([b"," in line for line in lines], bool)
    fixed = ~free
    underscores = raw.find(b"_") >= 0
    try:
        if fixed.all():
            for f, values in zip(fields, out):
                values[:] = _fixed_column(chars, starts[f.index], cols[f.index], f.kind,
                                          underscores)
        elif fixed.any():
            subset = chars[fixed]
            for f, values in zip(fields, out):
                values[fixed] = _fixed_column(subset, starts[f.index], cols[f.index], f.kind,
                                              underscores)
        for i in np.flatnonzero(free).tolist():
            texts = _card_fields(lines[i], widths, block.fmt)
            for f, values in zip(fields, out):
                values[i] = _convert(texts[f.index], f.kind)
    except (ValueError, OverflowError):
        raise _diagnose(block, rows, widths, fields) from None
    return rows, out


def _refuse_zero_ids(block: _Block, ids: np.ndarray, rows: np.ndarray, what: str) -> None:
    """ParseError at the first card whose id is 0 (a blank field reads as 0)."""
    if not ids.all():
        raise block.error(f"expected {what}, got a blank or 0", int(rows[np.argmin(ids != 0)]))


# --------------------------------------------------------------------------- records
@dataclass
class _Chunk:
    """The records one keyword block added: their file and the line of each one's first card."""

    src: _Source
    rows: np.ndarray  # line of each record (its first card)


def _locate(chunks: list[_Chunk], index: int) -> tuple[_Source, int]:
    """The file and 0-based line of the ``index``-th record over ``chunks``."""
    for chunk in chunks:
        if index < len(chunk.rows):
            return chunk.src, int(chunk.rows[index])
        index -= len(chunk.rows)
    raise IndexError(index)

