"""LS-DYNA keyword-deck reader: the shell model of a ``.k`` deck (and its includes) as an FEMesh.

What is read:

* ``*NODE`` (and ``*NODE_MERGE``): node id and x, y, z;
* ``*ELEMENT_SHELL`` with the options ``_THICKNESS``, ``_BETA``, ``_MCID`` (a thickness card after
  each element card) and ``_OFFSET`` (one more card): element id, part id and n1..n4. A triangle
  repeats its third node (``n3 == n4``, or n4 left blank); its nodes n5..n8 (8-node shells) are
  not kept. The mean nodal thickness (thickness cards, else the part's ``*SECTION_SHELL`` T1..T4)
  becomes the element field ``"thickness"`` (NaN where neither gives one);
* ``*ELEMENT_SOLID``: element id, part id and n1..n8 on one card, or (the two-card layout of
  newer decks) element id and part id, then n1..n8 on the next card; tetrahedra, pentahedra and
  hexahedra by LS-DYNA's repeated-node conventions. Solids are drawn by their boundary faces
  (faces used by one solid only; every face with ``all_faces``), each face keeping its solid's
  id in ``element_ids`` and its part (:mod:`workbench.scene.solids`); their thickness is NaN;
* ``*PART`` (title line, then the card with pid and secid; several parts per keyword), the
  part-definition options (``_CONTACT``, ``_PRINT``, ...), titles becoming ``part_names``;
* ``*SECTION_SHELL`` (and ``_TITLE``) T1..T4, with ``&name`` references to ``*PARAMETER`` values;
* ``*INCLUDE`` (file names relative to the including file's folder, the master deck's folder or
  the folders of ``*INCLUDE_PATH``; recursive; a cycle is refused), ``*END`` (ends its file).

Fields are fixed width (blank = 0) or, on a card that holds a comma, comma-separated. The
standard, I10 (``*KEYWORD I10=Y`` or a ``%`` after a keyword) and long (``*KEYWORD LONG=Y`` or a
``+`` after a keyword; all fields 20 wide) formats are read; an ``*INCLUDE`` is read in the
master deck's format unless its keyword names another one (``%``, ``+``, ``-``). Lines starting
with ``$`` are comments; keywords are case-insensitive; any other keyword is skipped with its
data. Node and element ids may be any integers; they are kept in ``node_ids`` / ``element_ids``
and mapped to indices. Coordinates are taken as they are (millimetres by default).

Refused with :class:`~workbench.scene.parse.ParseError` (file, 1-based line, card text and what was
expected): a malformed card, an element that names an undefined node, duplicate node or element
ids, a deck without shell or solid elements, an undefined parameter, a missing or cyclic include, and
the variants that would change the geometry if ignored (``*INCLUDE_TRANSFORM``,
``*ELEMENT_SHELL_COMPOSITE``, ...). Large blocks are converted column by column with numpy; the
per-card Python path only runs for free-format cards and to locate an error.
"""

from __future__ import annotations

import ast
import math
import operator
import re
import warnings
from dataclasses import dataclass, field
from operator import itemgetter
from pathlib import Path

import numpy as np

from .mesh import FEMesh
from .parse import ParseError, ParseWarning, build_mesh

# Card layouts in standard-format column widths; I10 widens fields under 10 to 10, long to 20.
_NODE = (8, 16, 16, 16, 8, 8)
_SHELL = (8,) * 10
_THICKNESS = (16,) * 5
_TEN = (10,) * 8  # *PART card 2, *SECTION_SHELL cards, *PARAMETER pairs
_THICKNESS_OPTIONS = {"THICKNESS", "BETA", "MCID"}
# *PART options that define parts: cards each adds after the title and the part card; the
# second set has a variable number of cards, so only the first part of such a block is read.
_PART_EXTRA_CARDS = {"CONTACT": 1, "PRINT": 1, "ATTACHMENT-NODES": 1, "REPOSITION": 1,
                     "AVERAGED": 0}
_PART_SINGLE = {"INERTIA", "COMPOSITE", "LONG", "TSHELL"}
_INCLUDE_REFUSED = ("INCLUDE_TRANSFORM", "INCLUDE_AUTO_OFFSET", "INCLUDE_NASTRAN",
                    "INCLUDE_BINARY")
_KEYWORD_LINE = re.compile(r"\*\s*([A-Za-z0-9_]+)\s*([%+-])?(.*)$")
_SUFFIX_FORMAT = {"%": "i10", "+": "long", "-": "small"}


def read_keyword(path, units: str = "mm", all_faces: bool = False) -> FEMesh:
    """Read the LS-DYNA keyword deck ``path`` (with its includes) into an :class:`FEMesh`.

    See the module notes for what is read and what is refused. ``units`` labels the
    coordinates (they are not scaled); ``all_faces`` draws every face of the solids instead
    of their boundary.
    """
    deck = _Deck(Path(path))
    deck.read_file(Path(path), None)
    return deck.build(units, all_faces)


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
    kind: str  # "i" integer, "f" float
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

    An integer field also takes an integral float in any notation (``0.000E+00``, ``8.``), as
    LS-DYNA reads it; a fractional or non-finite one is refused. Underscores (which Python's
    number parsing would accept as digit separators) are refused in every field."""
    text = text.strip()
    if not text:
        return 0 if kind == "i" else 0.0
    if b"_" in text:
        raise ValueError(text)
    if kind == "i":
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
    ``D`` exponent as ``E``, and an integer field takes an integral float (``0.000E+00``); all
    three are only looked for when the plain conversion fails. Underscores are refused
    (``underscores=False``: the caller knows there are none).
    """
    sub = np.ascontiguousarray(chars[:, start:start + width])
    if underscores and (sub == ord("_")).any():
        raise ValueError("underscore in a numeric field")
    text = sub.view(f"S{width}").ravel()
    dtype = np.int64 if kind == "i" else np.float64
    try:
        return text.astype(dtype)
    except ValueError:
        pass
    blank = (sub <= 32).all(axis=1)
    if blank.any():
        if width not in _BLANK_FIELD:
            _BLANK_FIELD[width] = np.frombuffer(b" " * (width - 1) + b"0", np.uint8)
        sub[blank] = _BLANK_FIELD[width]
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
    out = [np.zeros(len(rows), np.int64 if f.kind == "i" else np.float64) for f in fields]
    if len(rows) == 0:
        return rows, out
    if block.src.unterminated and int(rows[-1]) == len(block.src.lines) - 1:
        _check_complete(block, int(rows[-1]), widths, fields, span)
    raw = chars.tobytes()
    if raw.find(b",") < 0:  # memchr: cheaper than a per-row test when none
        free = np.zeros(len(rows), bool)
    else:
        free = (chars == ord(",")).any(axis=1)
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


def _check_complete(block: _Block, row: int, widths, fields: list[_Field], span: int) -> None:
    """Refuse the file's last card when the file ends inside it: no line end after it, and
    fewer columns (or comma-separated fields) than the fields read from it."""
    line = block.src.lines[row].rstrip()
    if b"," in line:
        complete = len(line.split(b",")) > max(f.index for f in fields)
    else:
        complete = len(line) >= span
    if not complete:
        raise block.error("the file ends inside this card (no line end after it): "
                          "it was cut off", row)


class _Undefined(LookupError):
    """A parameter that no *PARAMETER of the deck defines (its name in ``args[0]``)."""


_FUNCTIONS = {"sin": math.sin, "cos": math.cos, "tan": math.tan, "asin": math.asin,
              "acos": math.acos, "atan": math.atan, "atan2": math.atan2, "sqrt": math.sqrt,
              "exp": math.exp, "log": math.log, "log10": math.log10, "abs": abs, "min": min,
              "max": max, "mod": math.fmod, "int": lambda x: float(math.trunc(x)),
              "nint": lambda x: float(round(x)), "sign": math.copysign,
              "sinh": math.sinh, "cosh": math.cosh, "tanh": math.tanh}
_OPERATORS = {ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul,
              ast.Div: operator.truediv, ast.Pow: operator.pow, ast.USub: operator.neg,
              ast.UAdd: operator.pos}


@dataclass
class _Expression:
    """A ``*PARAMETER_EXPRESSION`` right-hand side: arithmetic (+ − * / ** or ^) of numbers,
    other parameters (by name, or ``&name``) and the functions of :data:`_FUNCTIONS`."""

    text: str
    src: "_Source"
    row: int

    def evaluate(self, lookup) -> float:
        """The float value, names resolved by ``lookup(name)``; ParseError for anything else
        (unknown functions, text, division by zero), naming the expression's line."""
        source = self.text.replace("&", "").replace("^", "**")
        try:
            tree = ast.parse(source, mode="eval")
            return float(self._value(tree.body, lookup))
        except _Undefined:
            raise
        except ParseError:
            raise
        except (SyntaxError, ValueError, TypeError, ZeroDivisionError, OverflowError) as exc:
            raise self.src.error(f"cannot evaluate the expression {self.text!r}: {exc}",
                                 self.row, "PARAMETER_EXPRESSION") from None

    def _value(self, node, lookup):
        if isinstance(node, ast.Constant) and isinstance(node.value, (int, float)):
            return node.value
        if isinstance(node, ast.Name):
            if node.id.lower() == "pi":
                return math.pi
            return lookup(node.id)
        if isinstance(node, ast.BinOp) and type(node.op) in _OPERATORS:
            return _OPERATORS[type(node.op)](self._value(node.left, lookup),
                                             self._value(node.right, lookup))
        if isinstance(node, ast.UnaryOp) and type(node.op) in _OPERATORS:
            return _OPERATORS[type(node.op)](self._value(node.operand, lookup))
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) \
                and node.func.id.lower() in _FUNCTIONS and not node.keywords:
            return _FUNCTIONS[node.func.id.lower()](*(self._value(a, lookup) for a in node.args))
        raise ValueError(f"{ast.unparse(node)!r} is not arithmetic of numbers and parameters")


# --------------------------------------------------------------------------- the deck
@dataclass
class _Chunk:
    src: _Source
    rows: np.ndarray  # line of each record (its first card)


@dataclass
class _Part:
    title: str
    secid: object


@dataclass
class _Section:
    thickness: list[bytes]  # T1..T4 field texts (numbers or &parameter references)
    src: _Source
    row: int


@dataclass
class _Deck:
    master: Path
    default_fmt: str = "small"
    include_dirs: list[Path] = field(default_factory=list)
    reading: list[Path] = field(default_factory=list)
    node_ids: list[np.ndarray] = field(default_factory=list)
    node_xyz: list[np.ndarray] = field(default_factory=list)
    node_chunks: list[_Chunk] = field(default_factory=list)
    shell_ids: list[np.ndarray] = field(default_factory=list)
    shell_parts: list[np.ndarray] = field(default_factory=list)
    shell_nodes: list[np.ndarray] = field(default_factory=list)
    shell_thickness: list[np.ndarray] = field(default_factory=list)
    shell_chunks: list[_Chunk] = field(default_factory=list)
    solid_ids: list[np.ndarray] = field(default_factory=list)
    solid_parts: list[np.ndarray] = field(default_factory=list)
    solid_nodes: list[np.ndarray] = field(default_factory=list)
    solid_chunks: list[_Chunk] = field(default_factory=list)
    parts: dict[int, _Part] = field(default_factory=dict)
    sections: dict[object, _Section] = field(default_factory=dict)
    parameters: dict[str, object] = field(default_factory=dict)
    skipped: dict[str, int] = field(default_factory=dict)
    sections_used: bool = False  # a part's *SECTION_SHELL gave the thickness of its shells

    # ------------------------------------------------------------- files and blocks
    def read_file(self, path: Path, fmt: str | None) -> None:
        """Read one file's blocks; ``fmt`` None means the master deck (its format may change)."""
        src = _Source(path)
        self.reading.append(path.resolve())
        keyword_rows = np.flatnonzero(src.first == ord("*"))
        comment = src.first == ord("$")
        ends = np.append(keyword_rows[1:], len(src.lines))
        for row, end in zip(keyword_rows.tolist(), ends.tolist()):
            header = src.lines[row].decode("utf-8", "replace").strip()
            match = _KEYWORD_LINE.match(header)
            if match is None:
                raise src.error("expected a keyword name after '*'", row)
            name = match.group(1).upper()
            if name == "END":
                break
            options = match.group(3).strip()
            if name == "KEYWORD":
                if fmt is None:
                    self.default_fmt = _keyword_format(options, self.default_fmt)
                continue
            suffix = match.group(2)
            block_fmt = _SUFFIX_FORMAT[suffix] if suffix else (fmt or self.default_fmt)
            rows = np.arange(row + 1, end)
            block = _Block(src, name, block_fmt, row, rows[~comment[row + 1:end]])
            self._dispatch(block, suffix)
        self.reading.pop()

    def _dispatch(self, block: _Block, suffix: str | None) -> None:
        name = block.keyword
        if name in ("NODE", "NODE_MERGE"):
            self._nodes(block)
        elif name.startswith("ELEMENT_SHELL"):
            self._shells(block)
        elif name == "ELEMENT_SOLID":
            self._solids(block)
        elif name.startswith("ELEMENT_SOLID"):
            raise block.error(f"*{name} is not supported (read is *ELEMENT_SOLID)")
        elif name.startswith("ELEMENT_"):
            self.skipped[name] = self.skipped.get(name, 0) + 1
        elif name == "PART" or name.startswith("PART_"):
            self._parts(block)
        elif name == "SECTION_SHELL" or name.startswith("SECTION_SHELL_"):
            self._sections(block)
        elif name in ("PARAMETER", "PARAMETER_LOCAL", "PARAMETER_NOECHO"):
            self._parameters(block, expressions=False)
        elif name.startswith("PARAMETER_EXPRESSION"):
            self._parameters(block, expressions=True)
        elif name in ("INCLUDE_PATH", "INCLUDE_PATH_RELATIVE"):
            for text in _file_names(block):
                folder = Path(text)
                self.include_dirs.append(folder if folder.is_absolute()
                                         else block.src.path.parent / folder)
        elif name == "INCLUDE":
            self._include(block, suffix)
        elif name.startswith(_INCLUDE_REFUSED):
            raise block.error(f"*{name} is not supported (it would renumber or move what it "
                              "includes); include the file with plain *INCLUDE")

    def _include(self, block: _Block, suffix: str | None) -> None:
        include_fmt = _SUFFIX_FORMAT[suffix] if suffix else self.default_fmt
        for text, row in _file_names(block, with_rows=True):
            target = self._resolve(block.src.path.parent, text)
            if target is None:
                raise block.error(f"included file {text!r} not found", row)
            if target.resolve() in self.reading:
                chain = " -> ".join(p.name for p in self.reading)
                raise block.error(f"include cycle: {text!r} is already being read ({chain})", row)
            self.read_file(target, include_fmt)

    def _resolve(self, folder: Path, text: str) -> Path | None:
        names = [text] if "\\" not in text else [text, text.replace("\\", "/")]
        for name in names:
            candidate = Path(name)
            if candidate.is_absolute():
                if candidate.is_file():
                    return candidate
                continue
            for base in [folder, self.master.parent, *self.include_dirs]:
                if (base / candidate).is_file():
                    return base / candidate
        return None

    # ------------------------------------------------------------- nodes and shells
    def _nodes(self, block: _Block) -> None:
        rows, (ids, x, y, z) = _table(block, block.rows, _NODE, [
            _Field(0, "i", "an integer node id"), _Field(1, "f", "3 coordinates"),
            _Field(2, "f", "3 coordinates"), _Field(3, "f", "3 coordinates")], drop_blank=True)
        _refuse_zero_ids(block, ids, rows, "a node id")
        xyz = np.column_stack([x, y, z])
        bad = ~np.isfinite(xyz).all(axis=1)
        if bad.any():
            raise block.error("expected 3 finite coordinates", int(rows[np.argmax(bad)]))
        self.node_ids.append(ids)
        self.node_xyz.append(xyz)
        self.node_chunks.append(_Chunk(block.src, rows))

    def _solids(self, block: _Block) -> None:
        """*ELEMENT_SOLID: one card (eid, pid, n1..n8) or two (eid, pid; n1..n8) per solid,
        the layout told by the first card (nodes on it or not)."""
        rows = np.array([r for r in block.rows.tolist() if not block.blank(r)], np.int64)
        if len(rows) == 0:
            return
        first = _card_fields(block.src.lines[int(rows[0])], _SHELL, block.fmt)
        two_cards = not any(t.strip() for t in first[2:])
        ids_fields = [_Field(0, "i", "an integer element id"), _Field(1, "i", "an integer part id")]
        if two_cards:
            if len(rows) % 2:
                raise block.error("expected two cards per solid (eid pid; n1..n8), the block "
                                  "ends after one", int(rows[-1]))
            cards, values = _table(block, rows[0::2], _SHELL, ids_fields)
            _, nodes = _table(block, rows[1::2], (8,) * 8,
                              [_Field(i, "i", "8 integer node ids") for i in range(8)])
        else:
            cards, values = _table(block, rows, _SHELL, [
                *ids_fields, *[_Field(i, "i", "8 integer node ids") for i in range(2, 10)]])
            values, nodes = values[:2], values[2:]
        ids = values[0]
        _refuse_zero_ids(block, ids, cards, "an element id")
        self.solid_ids.append(ids)
        self.solid_parts.append(values[1])
        self.solid_nodes.append(np.column_stack(nodes))
        self.solid_chunks.append(_Chunk(block.src, cards))

    def _shells(self, block: _Block) -> None:
        options = set(filter(None, block.keyword[len("ELEMENT_SHELL"):].split("_")))
        unknown = options - _THICKNESS_OPTIONS - {"OFFSET"}
        if unknown:
            raise block.error(f"*{block.keyword} is not supported (read are *ELEMENT_SHELL and "
                              "its options THICKNESS, BETA, MCID and OFFSET)")
        has_thickness = bool(options & _THICKNESS_OPTIONS)
        per_element = 1 + has_thickness + ("OFFSET" in options)
        rows = block.trimmed(per_element) if per_element > 1 else block.rows
        if len(rows) % per_element:
            broken = _first_break(block, rows, per_element)
            if broken is not None:
                row, expected = broken
                raise block.error(f"expected {expected}: a card is missing or extra before this "
                                  f"line ({per_element} cards per element)", row)
            start = int(rows[len(rows) - len(rows) % per_element])
            raise block.error(f"expected {per_element} cards per element, the block ends "
                              f"after {len(rows) % per_element}", start)
        cards = rows[::per_element]
        cards, values = _table(block, cards, _SHELL, [
            _Field(0, "i", "an integer element id"), _Field(1, "i", "an integer part id"),
            *[_Field(i, "i", "4 integer node ids") for i in range(2, 6)]],
            drop_blank=per_element == 1)
        ids, pids = values[0], values[1]
        _refuse_zero_ids(block, ids, cards, "an element id")
        nodes = np.column_stack(values[2:6])
        thickness = np.full((len(cards), 4), np.nan)
        if has_thickness:
            eight = _eight_node(block, cards)
            if eight is not None:  # n5..n8 would add a card: refuse rather than misread the rest
                raise block.error("8-node shells with thickness cards are not supported", eight)
            thickness[:] = np.column_stack(_table(block, rows[1::per_element], _THICKNESS, [
                _Field(i, "f", "4 thicknesses") for i in range(4)])[1])
        self.shell_ids.append(ids)
        self.shell_parts.append(pids)
        self.shell_nodes.append(nodes)
        self.shell_thickness.append(thickness)
        self.shell_chunks.append(_Chunk(block.src, cards))

    # ------------------------------------------------------------- parts, sections, parameters
    def _parts(self, block: _Block) -> None:
        options = block.keyword[len("PART"):].replace("ATTACHMENT_NODES", "ATTACHMENT-NODES")
        tokens = [t for t in options.split("_") if t]
        if any(t not in _PART_EXTRA_CARDS and t not in _PART_SINGLE for t in tokens):
            return  # *PART_MOVE, *PART_DUPLICATE, *PART_SENSOR, ...: not part definitions
        if any(t in _PART_SINGLE for t in tokens):
            period = None
        else:
            period = 2 + sum(_PART_EXTRA_CARDS[t] for t in tokens)
        rows = block.trimmed(period or 1)
        starts = [0] if period is None else range(0, len(rows), period)
        for start in starts:
            if start + 1 >= len(rows):
                raise block.error("expected a part card (pid, secid, mid, ...) after the title",
                                  int(rows[start]) if len(rows) else None)
            title_row, card_row = int(rows[start]), int(rows[start + 1])
            texts = _card_fields(block.src.lines[card_row], _TEN, block.fmt)
            try:
                pid = _convert(texts[0], "i")
            except ValueError:
                raise block.error(f"expected an integer part id, got {_shown(texts[0])!r}",
                                  card_row) from None
            title = block.src.lines[title_row].decode("utf-8", "replace").strip()
            secid = None if "COMPOSITE" in tokens else _section_key(texts[1])
            self.parts[pid] = _Part(title, secid)

    def _sections(self, block: _Block) -> None:
        options = set(block.keyword[len("SECTION_SHELL"):].split("_")) - {""}
        titled = "TITLE" in options
        repeatable = options <= {"TITLE"}
        rows = block.rows
        at = 0
        while at < len(rows) and not all(block.blank(r) for r in rows[at:].tolist()):
            at += titled
            if at + 1 >= len(rows):
                raise block.error("expected two section cards (secid ...; t1 t2 t3 t4 ...)",
                                  int(rows[min(at, len(rows) - 1)]))
            first, second = int(rows[at]), int(rows[at + 1])
            texts = _card_fields(block.src.lines[first], _TEN, block.fmt)
            values = []
            for i, name in ((1, "ELFORM"), (3, "NIP"), (6, "ICOMP")):
                try:
                    values.append(_convert(texts[i], "i"))
                except ValueError:
                    raise block.error(f"expected an integer {name}, got {_shown(texts[i])!r}",
                                      first) from None
            elform, nip, icomp = values
            thickness = _card_fields(block.src.lines[second], _TEN, block.fmt)[:4]
            self.sections[_section_key(texts[0])] = _Section(thickness, block.src, second)
            at += 2
            if icomp == 1:  # one card of 8 layer angles per 8 integration points
                at += -(-(nip or 2) // 8)
            if not repeatable or elform >= 101:  # user elements carry more cards
                break

    def _parameters(self, block: _Block, expressions: bool) -> None:
        for row in block.rows.tolist():
            line = block.src.lines[row]
            if not line.strip():
                continue
            if expressions:  # a name, then the expression (which may hold commas itself)
                if b"," in line[:field_width(10, block.fmt)]:
                    head, expression = line.split(b",", 1)
                else:
                    width = field_width(10, block.fmt)
                    head, expression = line[:width], line[width:]
                names = [head]
                values = [_Expression(expression.decode("utf-8", "replace").strip(),
                                      block.src, row)]
            else:
                texts = _card_fields(line, _TEN, block.fmt)
                names, values = texts[0::2], texts[1::2]
            for name, value in zip(names, values):
                name = name.decode("utf-8", "replace").strip()
                if not name:
                    continue
                kind = name[0].upper()
                if kind in "RIC" and len(name) > 1:
                    name = name[1:].strip()
                else:
                    kind = "R"
                if isinstance(value, _Expression):
                    self.parameters[name] = value  # evaluated when used
                elif kind == "C":
                    self.parameters[name] = value.decode("utf-8", "replace").strip()
                else:
                    try:
                        self.parameters[name] = _convert(value, "f")
                    except ValueError:
                        raise block.error(f"expected a number for parameter {name!r}, got "
                                          f"{_shown(value)!r}", row) from None

    def _parameter(self, text: bytes, src: _Source, row: int) -> float:
        """A section thickness field: a number or a (signed) ``&name`` reference, evaluated
        when its parameter is an expression. A parameter defined nowhere (an include read on its
        own, whose including deck defines it) is NaN with a :class:`ParseWarning` naming file,
        line and parameter: the geometry is still drawn, the thickness is missing."""
        text = text.strip()
        sign = -1.0 if text.startswith(b"-") else 1.0
        if text.lstrip(b"+-").startswith(b"&"):
            name = text.lstrip(b"+-")[1:].decode("utf-8", "replace").strip()
            try:
                value = self._parameter_value(name, src, row, ())
            except _Undefined as undefined:
                warnings.warn(ParseWarning(src.path, f"parameter {undefined.args[0]!r} is not "
                                           f"defined by *PARAMETER in this deck or its includes: "
                                           f"the thickness is missing", row + 1,
                                           "SECTION_SHELL"), stacklevel=2)
                return float("nan")
            return sign * value
        try:
            return _convert(text, "f")
        except ValueError:
            raise src.error(f"expected a thickness, got {_shown(text)!r}", row,
                            "SECTION_SHELL") from None

    def _parameter_value(self, name: str, src: _Source, row: int, chain: tuple) -> float:
        """The number parameter ``name`` stands for (names are case-insensitive), evaluating
        ``*PARAMETER_EXPRESSION`` arithmetic; _Undefined for a name defined nowhere, ParseError
        for a text parameter, a bad expression or a cycle."""
        if name not in self.parameters:
            folded = {k.lower(): k for k in self.parameters}
            if name.lower() not in folded:
                raise _Undefined(name)
            name = folded[name.lower()]
        value = self.parameters[name]
        if isinstance(value, _Expression):
            if name in chain:
                raise value.src.error(f"parameter {name!r} is defined through itself: "
                                      f"{' -> '.join((*chain, name))}", value.row,
                                      "PARAMETER_EXPRESSION")
            value = value.evaluate(lambda n: self._parameter_value(n, src, row, (*chain, name)))
            self.parameters[name] = value
        if not isinstance(value, float):
            raise src.error(f"parameter {name!r} is not a number", row, "SECTION_SHELL")
        return value

    # ------------------------------------------------------------- assembly
    def build(self, units: str, all_faces: bool = False) -> FEMesh:
        n_shells = sum(len(ids) for ids in self.shell_ids)
        if n_shells + sum(len(ids) for ids in self.solid_ids) == 0:
            others = ", ".join(f"*{k}" for k in sorted(self.skipped))
            raise ParseError(self.master, "no shell or solid elements (*ELEMENT_SHELL, "
                             "*ELEMENT_SOLID) in the deck"
                             + (f"; it has {others}, which are not read" if others else ""))
        node_ids = np.concatenate(self.node_ids) if self.node_ids else np.zeros(0, np.int64)
        xyz = np.concatenate(self.node_xyz) if self.node_xyz else np.zeros((0, 3))
        order, sorted_ids = _unique_or_raise(node_ids, self.node_chunks, "node")
        element_ids = np.concatenate([*self.shell_ids, *self.solid_ids])
        # shells and solids number their elements apart, as LS-DYNA's element types do
        _unique_or_raise(element_ids[:n_shells], self.shell_chunks, "element")
        _unique_or_raise(element_ids[n_shells:], self.solid_chunks, "solid element")

        shell_ids = element_ids[:n_shells]
        pids = np.concatenate(self.shell_parts) if n_shells else np.zeros(0, np.int64)
        refs = np.concatenate(self.shell_nodes) if n_shells else np.zeros((0, 4), np.int64)
        if not (node_ids == 0).any():  # n4 left blank on a triangle
            blank4 = refs[:, 3] == 0
            refs[blank4, 3] = refs[blank4, 2]
        elements = _node_indices(refs, order, sorted_ids, shell_ids, self.shell_chunks,
                                 "ELEMENT_SHELL")
        _check_part_ids(pids, self.shell_chunks, "ELEMENT_SHELL")
        thickness = self._thickness(pids, elements) if n_shells else np.zeros(0)
        if self.solid_ids:
            from .solids import boundary_surface, solid_kinds

            solid_ids = element_ids[n_shells:]
            solid_pids = np.concatenate(self.solid_parts)
            _check_part_ids(solid_pids, self.solid_chunks, "ELEMENT_SOLID")
            node_refs = np.concatenate(self.solid_nodes)
            solids = _node_indices(node_refs, order, sorted_ids, solid_ids, self.solid_chunks,
                                   "ELEMENT_SOLID")
            unknown = np.flatnonzero(solid_kinds(solids) == 0)
            if len(unknown):
                src, row = _locate(self.solid_chunks, int(unknown[0]))
                raise src.error(f"{len(unknown)} solid(s) of a node pattern LS-DYNA does not "
                                f"define; expected a hexahedron (n1..n8 distinct), pentahedron "
                                f"(n1 n2 n3 n4 n5 n5 n6 n6) or tetrahedron (n1 n2 n3 n4 n4 n4 "
                                f"n4 n4)", row, "ELEMENT_SOLID")
            try:
                faces, face_pids, face_of = boundary_surface(solids, xyz, solid_pids, all_faces)
            except ValueError as exc:
                raise ParseError(self.master, f"*ELEMENT_SOLID: {exc}") from None
            elements = np.concatenate([elements, faces])
            pids = np.concatenate([pids, face_pids])
            shell_ids = np.concatenate([shell_ids, solid_ids[face_of]])
            thickness = np.concatenate([thickness, np.full(len(faces), np.nan)])

        element_fields = {}
        if np.isfinite(thickness).any() or self.sections_used:  # a section gave no number:
            element_fields["thickness"] = thickness  # missing (NaN), not absent
        used_parts = set(np.unique(pids).tolist())
        part_names = {pid: part.title for pid, part in self.parts.items()
                      if part.title and pid in used_parts}
        return build_mesh(self.master, nodes=xyz, elements=elements, parts=pids,
                          element_fields=element_fields, part_names=part_names,
                          node_ids=node_ids, element_ids=shell_ids, name=self.master.name,
                          units=units)

    def _thickness(self, pids: np.ndarray, elements: np.ndarray) -> np.ndarray:
        """(M,) mean nodal thickness: element thickness cards, zeros and gaps from the section."""
        nodal = np.concatenate(self.shell_thickness)
        unique, inverse = np.unique(pids, return_inverse=True)
        section_of_part = {}
        for pid in unique.tolist():
            part = self.parts.get(pid)
            section = None if part is None else self.sections.get(part.secid)
            if section is None:
                continue
            t = np.array([self._parameter(text, section.src, section.row)
                          for text in section.thickness])
            t[1:][t[1:] == 0] = t[0]  # T2..T4 default to T1
            section_of_part[pid] = t
        self.sections_used = bool(section_of_part)
        fallback = np.full((len(pids), 4), np.nan)
        if section_of_part:
            table = np.array([section_of_part.get(p, [np.nan] * 4) for p in unique.tolist()])
            fallback = table[inverse.reshape(-1)]
        use_section = np.isnan(nodal) | (nodal == 0)
        nodal = np.where(use_section, fallback, nodal)
        triangle = elements[:, 3] == elements[:, 2]
        return np.where(triangle, nodal[:, :3].mean(axis=1), nodal.mean(axis=1))


def _first_break(block: _Block, rows: np.ndarray, per_element: int) -> tuple[int, str] | None:
    """(line, what was expected) of the first card of a multi-card element block whose kind
    breaks the record layout — an element card (integer element and part ids) where a
    following card belongs, or the reverse — or None when every card looks right."""
    for k, row in enumerate(rows.tolist()):
        texts = _card_fields(block.src.lines[row], _SHELL, block.fmt)[:2]
        element_like = all(t.strip().lstrip(b"+-").isdigit() and int(t) != 0 for t in texts)
        if k % per_element == 0 and not element_like:
            return row, "an element card (element id, part id, n1..n4)"
        if k % per_element and element_like:
            return row, "the element's next card (thicknesses or offset), not an element card"
    return None


def _eight_node(block: _Block, cards: np.ndarray) -> int | None:
    """The line of the first element card with a node among n5..n8, or None."""
    if len(cards) == 0:
        return None
    _, starts = _layout(_SHELL, block.fmt)
    lines = block.src.pick(cards)
    chars = np.array(lines, dtype=f"S{starts[10]}").view(np.uint8).reshape(len(lines), -1)
    tail = chars[:, starts[6]:]
    suspect = np.flatnonzero(((tail > 32) & (tail != ord("0"))).any(axis=1))
    for i in suspect.tolist():
        texts = _card_fields(lines[i], _SHELL, block.fmt)[6:10]
        try:
            if any(_convert(t, "i") for t in texts):
                return int(cards[i])
        except ValueError:
            shown = ", ".join(repr(_shown(t)) for t in texts)
            raise block.error(f"expected integer node ids n5..n8, got {shown}",
                              int(cards[i])) from None
    return None


def _keyword_format(options: str, current: str) -> str:
    """The deck format set by the options of a ``*KEYWORD`` line (LONG=Y/S, I10=Y/N)."""
    text = options.upper().replace(" ", "")
    match = re.search(r"LONG=([A-Z])", text)
    if match:
        return "long" if match.group(1) == "Y" else "small"
    match = re.search(r"I10=([A-Z])", text)
    if match:
        return "i10" if match.group(1) == "Y" else "small"
    return current


def _section_key(text: bytes):
    """A section id as a part and a section card name it: an integer (integral floats
    included, so ``8`` and ``8.000E+00`` name one section), else the upper-cased label."""
    try:
        return _convert(text, "i") if text.strip() else ""
    except ValueError:
        return text.strip().decode("utf-8", "replace").upper()


def _file_names(block: _Block, with_rows: bool = False):
    """The file or folder names of an ``*INCLUDE``-like block (a trailing " +" continues a name)."""
    names, pending, pending_row = [], "", None
    for row in block.rows.tolist():
        text = block.src.lines[row].decode("utf-8", "replace").strip()
        if not text and not pending:
            continue
        if pending_row is None:
            pending_row = row
        if text.endswith(" +"):
            pending += text[:-2].strip()
            continue
        names.append((pending + text, pending_row))
        pending, pending_row = "", None
    if pending:
        names.append((pending, pending_row))
    return names if with_rows else [n for n, _ in names]


def _locate(chunks: list[_Chunk], index: int) -> tuple[_Source, int]:
    """The file and 0-based line of the ``index``-th record over ``chunks``."""
    for chunk in chunks:
        if index < len(chunk.rows):
            return chunk.src, int(chunk.rows[index])
        index -= len(chunk.rows)
    raise IndexError(index)


def _node_indices(refs: np.ndarray, order: np.ndarray, sorted_ids: np.ndarray,
                  element_ids: np.ndarray, chunks: list[_Chunk], keyword: str) -> np.ndarray:
    """The node indices of the node ids ``refs`` (E, k); ParseError at the first element that
    names an undefined node, listing up to five (element id, node id) pairs."""
    if len(sorted_ids):
        pos = np.searchsorted(sorted_ids, refs).clip(max=len(sorted_ids) - 1)
        found = sorted_ids[pos] == refs
        indices = order[pos]
    else:
        found = np.zeros(refs.shape, bool)
        indices = np.zeros(refs.shape, np.int64)
    if not found.all():
        bad = np.flatnonzero(~found.all(axis=1))
        pairs = [(int(element_ids[e]), int(refs[e][~found[e]][0])) for e in bad[:5]]
        src, row = _locate(chunks, int(bad[0]))
        listed = ", ".join(f"({e}, {n})" for e, n in pairs)
        raise src.error(f"{len(bad)} element(s) reference undefined node ids; first "
                        f"(element id, node id): {listed}", row, keyword)
    return indices


def _check_part_ids(pids: np.ndarray, chunks: list[_Chunk], keyword: str) -> None:
    """ParseError at the first part id that does not fit in 32 bits (FEMesh keeps int32)."""
    limits = np.iinfo(np.int32)
    too_big = (pids < limits.min) | (pids > limits.max)
    if too_big.any():
        src, row = _locate(chunks, int(np.argmax(too_big)))
        raise src.error(f"part id {int(pids[too_big][0])} does not fit in 32 bits", row, keyword)


def _unique_or_raise(ids: np.ndarray, chunks: list[_Chunk], what: str):
    """(order, sorted ids) of ``ids``; a repeated id raises ParseError at its second definition."""
    order = np.argsort(ids, kind="stable")
    sorted_ids = ids[order]
    repeated = np.flatnonzero(sorted_ids[1:] == sorted_ids[:-1])
    if len(repeated):
        later = order[repeated + 1]
        second = int(later.min())
        first = int(order[np.searchsorted(sorted_ids, ids[second])])
        src0, row0 = _locate(chunks, first)
        src, row = _locate(chunks, second)
        keyword = {"node": "NODE", "element": "ELEMENT_SHELL"}.get(what, "ELEMENT_SOLID")
        raise src.error(f"{what} id {int(ids[second])} is defined twice (first at "
                        f"{src0.path.name}:{row0 + 1}); {len(repeated)} repeated id(s)", row,
                        keyword)
    return order, sorted_ids
