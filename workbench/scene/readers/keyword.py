"""LS-DYNA keyword-deck reader: the shell model of a ``.k`` deck (and its includes) as an FEMesh.

What is read:

* ``*NODE`` (and ``*NODE_MERGE``): node id and x, y, z;
* ``*ELEMENT_SHELL`` with the options ``_THICKNESS``, ``_BETA``, ``_MCID`` (a thickness card after
  each element card) and ``_OFFSET`` (one more card): element id, part id and n1..n4. A triangle
  repeats its third node (``n3 == n4``, or n4 left blank); its nodes n5..n8 (8-node shells) are
  not kept. The mean nodal thickness (thickness cards, else the part's ``*SECTION_SHELL`` T1..T4)
  becomes the element field ``"thickness"`` (NaN where neither gives one);
* ``*ELEMENT_SOLID`` (and its options ``_H8TOH20``, ``_H8TOH27``, ``_H8TOH64``,
  ``_TET4TOTET10``, whose cards are the same), ``*ELEMENT_TSHELL`` (thick shells, read as the
  8-node solids they are): element id, part id and n1..n8 on one card, or (the two-card layout
  of newer decks) element id and part id, then n1..n8 on the next card; tetrahedra (n5..n8
  repeating n4, or blank), pentahedra and hexahedra by LS-DYNA's repeated-node conventions.
  They are drawn by their boundary faces (faces used by one solid only; every face with
  ``all_faces``), each face keeping its element's id in ``element_ids`` and its part
  (:mod:`workbench.scene.solids`); their thickness is NaN;
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
data; ``*ELEMENT_BEAM`` and ``*ELEMENT_SPH`` are read as the mesh's beams and SPH particles
(:mod:`~workbench.scene.readers.keyword_kinds`, which says what radius a particle is drawn
with), and every other ``*ELEMENT_...`` keyword (discrete elements, masses, seat belts ...)
is named in one :class:`~workbench.scene.readers.errors.ParseWarning` with its count. Node and
element ids may be any integers (written as integers, or integral decimals such as ``101.0``;
never with an exponent); they are kept in ``node_ids`` / ``element_ids`` and mapped to
indices. Coordinates are taken as they are (millimetres by default).

A section thickness that names a parameter defined nowhere (an include read without the master
deck that defines it) is read as missing (NaN, the no-result colour) with one
:class:`~workbench.scene.readers.errors.ParseWarning` per parameter naming it, its line, what is
defined and the parts: the geometry is drawn.

Refused with :class:`~workbench.scene.readers.errors.ParseError` (file, 1-based line, card text
and what was expected): a malformed card, a NUL byte, the file's last card when the file may
end inside it (no line end after it, and fewer columns, or no comma after the last field read),
an element that names an undefined node, a blank, negative or undefined part id (a deck without
any ``*PART`` is a mesh file whose part ids are kept), duplicate node or element ids, a deck
without shell or solid elements, an undefined parameter in an expression, a missing or cyclic
include or one nested deeper than :data:`MAX_INCLUDE_DEPTH` files, and the variants that would
change the geometry if ignored
(``*INCLUDE_TRANSFORM``, ``*ELEMENT_SHELL_COMPOSITE``, ...). Large blocks are converted column by
column with numpy; the per-card Python path only runs for free-format cards and to locate an
error.

This module walks the deck and its includes and reads each keyword's blocks; the cards are
split into fields and converted in :mod:`~workbench.scene.readers.cards`, parameters and their
expressions are kept in :mod:`~workbench.scene.readers.parameters`, and what was read becomes
the FEMesh in :mod:`~workbench.scene.readers.assembly`.
"""

from __future__ import annotations

import os
import re
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..mesh import FEMesh
from .assembly import deck_mesh
from .cards import (
    _TEN,
    _Block,
    _card_fields,
    _Chunk,
    _convert,
    _Field,
    _refuse_zero_ids,
    _shown,
    _Source,
    _table,
)
from .errors import ParseWarning
from .keyword_kinds import KindBlocks
from .parameters import _Parameters

# Card layouts in standard-format column widths; I10 widens fields under 10 to 10, long to 20.
_NODE = (8, 16, 16, 16, 8, 8)
_SHELL = (8,) * 10
_THICKNESS = (16,) * 5
_THICKNESS_OPTIONS = {"THICKNESS", "BETA", "MCID"}
# *PART options that define parts: cards each adds after the title and the part card; the
# second set has a variable number of cards, so only the first part of such a block is read.
_PART_EXTRA_CARDS = {"CONTACT": 1, "PRINT": 1, "ATTACHMENT-NODES": 1, "REPOSITION": 1,
                     "AVERAGED": 0}
_PART_SINGLE = {"INERTIA", "COMPOSITE", "LONG", "TSHELL"}
# *ELEMENT_SOLID options whose cards are those of *ELEMENT_SOLID (the solver adds the nodes of
# a higher-order element; the corners are drawn)
_SOLID_AS_LINEAR = {"ELEMENT_SOLID_H8TOH20", "ELEMENT_SOLID_H8TOH27", "ELEMENT_SOLID_H8TOH64",
                    "ELEMENT_SOLID_TET4TOTET10"}
# element keywords not drawn whose records are one card each (others are counted in cards)
_ONE_CARD_ELEMENTS = {"ELEMENT_BEAM", "ELEMENT_SPH", "ELEMENT_DISCRETE", "ELEMENT_MASS",
                      "ELEMENT_SEATBELT", "ELEMENT_PLOTEL"}
MAX_INCLUDE_DEPTH = 64
_INCLUDE_REFUSED = ("INCLUDE_TRANSFORM", "INCLUDE_AUTO_OFFSET", "INCLUDE_NASTRAN",
                    "INCLUDE_BINARY")
_KEYWORD_LINE = re.compile(r"\*\s*([A-Za-z0-9_]+)\s*([%+-])?(.*)$")
_SUFFIX_FORMAT = {"%": "i10", "+": "long", "-": "small"}


def read_keyword(path: str | os.PathLike[str], units: str = "mm",
                 all_faces: bool = False) -> FEMesh:
    """Read the LS-DYNA keyword deck ``path`` (with its includes) into an :class:`FEMesh`.

    See the module notes for what is read and what is refused. ``units`` labels the
    coordinates (they are not scaled); ``all_faces`` draws every face of the solids instead
    of their boundary.
    """
    deck = _Deck(Path(path))
    deck.read_file(Path(path), None)
    deck.kinds.refuse_alone(deck.master, sum(map(len, deck.shell_ids + deck.solid_ids)))
    mesh = deck_mesh(deck, units, all_faces)
    deck.kinds.attach(mesh, deck.parts)  # beams and SPH particles
    for name, cards in sorted(deck.skipped.items()):
        what = f"{cards} element(s)" if name in _ONE_CARD_ELEMENTS else f"{cards} card(s)"
        warnings.warn(ParseWarning(deck.master, f"{what} not drawn: *{name} is not read"),
                      stacklevel=2)
    return mesh


# --------------------------------------------------------------------------- the deck
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
    """What the blocks of a deck and its includes hold, in reading order: one array per block
    and the chunk of lines it came from, the parts, sections and parameters by id or name, and
    the state of the walk (the deck format, the include folders, the files being read)."""

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
    solid_keywords: list[str] = field(default_factory=list)  # ELEMENT_SOLID or ELEMENT_TSHELL
    parts: dict[int, _Part] = field(default_factory=dict)
    sections: dict[object, _Section] = field(default_factory=dict)
    parameters: _Parameters = field(default_factory=_Parameters)
    skipped: dict[str, int] = field(default_factory=dict)  # keyword -> data cards not read
    kinds: KindBlocks = field(default_factory=KindBlocks)  # beams and SPH particles

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
        elif name in ("ELEMENT_SOLID", "ELEMENT_TSHELL") or name in _SOLID_AS_LINEAR:
            self._solids(block)
        elif name.startswith("ELEMENT_SOLID"):
            raise block.error(f"*{name} is not supported (read are *ELEMENT_SOLID and its "
                              f"options {', '.join(sorted(o[14:] for o in _SOLID_AS_LINEAR))})")
        elif self.kinds.read(block):
            pass
        elif name.startswith("ELEMENT_"):
            cards = sum(not block.blank(r) for r in block.rows.tolist())
            self.skipped[name] = self.skipped.get(name, 0) + cards
        elif name == "PART" or name.startswith("PART_"):
            self._parts(block)
        elif name == "SECTION_SHELL" or name.startswith("SECTION_SHELL_"):
            self._sections(block)
        elif name in ("PARAMETER", "PARAMETER_LOCAL", "PARAMETER_NOECHO"):
            self.parameters.read(block, expressions=False)
        elif name.startswith("PARAMETER_EXPRESSION"):
            self.parameters.read(block, expressions=True)
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
            if len(self.reading) >= MAX_INCLUDE_DEPTH:
                raise block.error(f"includes nested deeper than {MAX_INCLUDE_DEPTH} files "
                                  f"(a chain of includes that does not end?)", row)
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
            _Field(0, "id", "an integer node id"), _Field(1, "f", "3 coordinates"),
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
        """*ELEMENT_SOLID (and its options in ``_SOLID_AS_LINEAR``) and *ELEMENT_TSHELL: one
        card (eid, pid, n1..n8) or two (eid, pid; n1..n8) per element, the layout told by the
        first card (nodes on it or not). A tetrahedron may leave n5..n8 blank."""
        rows = np.array([r for r in block.rows.tolist() if not block.blank(r)], np.int64)
        if len(rows) == 0:
            return
        first = _card_fields(block.src.lines[int(rows[0])], _SHELL, block.fmt)
        two_cards = not any(t.strip() for t in first[2:])
        ids_fields = [_Field(0, "id", "an integer element id"),
                      _Field(1, "id", "an integer part id")]
        if two_cards:
            if len(rows) % 2:
                raise block.error("expected two cards per solid (eid pid; n1..n8), the block "
                                  "ends after one", int(rows[-1]))
            cards, values = _table(block, rows[0::2], _SHELL, ids_fields)
            _, nodes = _table(block, rows[1::2], (8,) * 8,
                              [_Field(i, "id", "8 integer node ids") for i in range(8)])
        else:
            cards, values = _table(block, rows, _SHELL, [
                *ids_fields, *[_Field(i, "id", "8 integer node ids") for i in range(2, 10)]])
            values, nodes = values[:2], values[2:]
        ids = values[0]
        _refuse_zero_ids(block, ids, cards, "an element id")
        _refuse_bad_part_ids(block, values[1], cards)
        nodes = np.column_stack(nodes)
        tetrahedra = (nodes[:, 4:] == 0).all(axis=1) & (nodes[:, :4] != 0).all(axis=1)
        nodes[tetrahedra, 4:] = nodes[tetrahedra, 3:4]  # n5..n8 blank: n4 repeated
        self.solid_ids.append(ids)
        self.solid_parts.append(values[1])
        self.solid_nodes.append(nodes)
        self.solid_chunks.append(_Chunk(block.src, cards))
        self.solid_keywords.append("ELEMENT_TSHELL" if block.keyword == "ELEMENT_TSHELL"
                                   else "ELEMENT_SOLID")

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
            _Field(0, "id", "an integer element id"), _Field(1, "id", "an integer part id"),
            *[_Field(i, "id", "4 integer node ids") for i in range(2, 6)]],
            drop_blank=per_element == 1)
        ids, pids = values[0], values[1]
        _refuse_zero_ids(block, ids, cards, "an element id")
        _refuse_bad_part_ids(block, pids, cards)
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

    # ------------------------------------------------------------- parts and sections
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
            block.refuse_if_cut(card_row, _TEN, 2)
            texts = _card_fields(block.src.lines[card_row], _TEN, block.fmt)
            try:
                pid = _convert(texts[0], "id")
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
            block.refuse_if_cut(second, _TEN, 4)
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


def _refuse_bad_part_ids(block: _Block, pids: np.ndarray, rows: np.ndarray) -> None:
    """ParseError at the first element card whose part id is blank, 0 or negative."""
    bad = pids <= 0
    if bad.any():
        i = int(np.argmax(bad))
        got = "a blank or 0" if pids[i] == 0 else str(int(pids[i]))
        raise block.error(f"expected a positive part id, got {got}", int(rows[i]))


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
    """The line of the first element card with a node among n5..n8, or None; ParseError at
    a card whose n5..n8 are not integers."""
    if len(cards) == 0:
        return None
    _, tail = _table(block, cards, _SHELL, [_Field(i, "id", "integer node ids n5..n8")
                                            for i in range(6, 10)])
    named = (np.column_stack(tail) != 0).any(axis=1)
    return int(cards[np.argmax(named)]) if named.any() else None


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
