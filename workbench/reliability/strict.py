"""An independent, strict decoding of a keyword deck's text (:func:`strict_decode`) and the
mesh a correct read of it must give (:func:`expected_mesh`), written card by card in plain
Python without the reader's code. The reader suite checks every successful read against it
(:func:`mesh_differences`).

It decodes what the reader reads of the suite's decks — ``*KEYWORD`` formats, ``*NODE``,
``*ELEMENT_SHELL`` with its thickness and offset options, plain ``*PART``, ``*SECTION_SHELL``
and plain ``*PARAMETER`` — and applies the reader's documented rules (see
:mod:`workbench.scene.readers.keyword`): what the reader must refuse, a triangle's blank n4,
the mean nodal thickness with the section's T1..T4 where a card gives none. A deck with a
keyword it does not decode (solids, thick shells, beams, SPH particles, includes, expressions,
part and section variants) is :class:`BeyondReference`, so that no check passes by decoding
less.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field

import numpy as np

from .decks import BOM

_KEYWORD = re.compile(rb"\*\s*([A-Za-z0-9_]+)\s*([%+-])?(.*)$")
_NODE = (8, 16, 16, 16)
_SHELL = (8,) * 10
_THICK = (16,) * 4
_TEN = (10,) * 8
_SHELL_OPTIONS = {"THICKNESS", "BETA", "MCID", "OFFSET"}
_BEYOND = ("ELEMENT_SOLID", "ELEMENT_TSHELL", "ELEMENT_BEAM", "ELEMENT_SPH", "INCLUDE",
           "PARAMETER_EXPRESSION")


class Refused(ValueError):
    """The deck must be refused: a correct reader reads no mesh from it."""


class BeyondReference(ValueError):
    """The deck holds a keyword the strict decoding does not decode."""


@dataclass
class StrictDeck:
    """A deck's text decoded card by card: nodes (id, x, y, z), shells (id, part id, n1..n4,
    nodal thickness or None), parts (id → section key), sections (key → T1..T4 texts) and
    parameters (name → value), in the order of the text."""

    nodes: list[tuple[int, float, float, float]] = field(default_factory=list)
    shells: list[tuple[int, int, tuple[int, ...], tuple[float, ...] | None]] = \
        field(default_factory=list)
    parts: dict[int, object] = field(default_factory=dict)
    sections: dict[object, list[bytes]] = field(default_factory=dict)
    parameters: dict[str, object] = field(default_factory=dict)


@dataclass
class Expected:
    """The mesh a correct read gives, by id: coordinates per node id, then per shell (in deck
    order) its id, part id, node ids n1..n4 (n4 = n3 for a triangle) and thickness (NaN where
    neither a card nor a section gives one; ``thickness`` is None when the mesh has no
    thickness field)."""

    node_ids: np.ndarray
    nodes: np.ndarray
    element_ids: np.ndarray
    parts: np.ndarray
    connectivity: np.ndarray
    thickness: np.ndarray | None


# --------------------------------------------------------------------------- fields
def _widths(widths: tuple[int, ...], fmt: str) -> tuple[int, ...]:
    """Field widths of a standard layout in format ``fmt`` (small, i10 or long)."""
    if fmt == "long":
        return tuple(max(w, 20) for w in widths)
    if fmt == "i10":
        return tuple(max(w, 10) for w in widths)
    return widths


def _fields(line: bytes, widths: tuple[int, ...], fmt: str) -> list[bytes]:
    """A card's field texts: comma-separated when it holds a comma, else fixed columns."""
    if b"," in line:
        parts = line.split(b",")
        return (parts + [b""] * len(widths))[:len(widths)]
    out, at = [], 0
    for w in _widths(widths, fmt):
        out.append(line[at:at + w])
        at += w
    return out


def _real(text: bytes) -> float:
    """A float field (blank = 0, ``D`` exponents as ``E``); Refused when it is none."""
    text = text.strip()
    if not text:
        return 0.0
    if b"_" in text or b"\x00" in text:
        raise Refused(f"{text!r} is no number")
    try:
        return float(text.replace(b"D", b"E").replace(b"d", b"e"))
    except ValueError:
        raise Refused(f"{text!r} is no number") from None


def _integer(text: bytes, exponent: bool = True) -> int:
    """An integer field (blank = 0): digits, or an integral finite float — with an exponent
    only where ``exponent`` (ids never take one); Refused otherwise."""
    stripped = text.strip()
    if stripped.lstrip(b"+-").isdigit():
        value = int(stripped)
    else:
        if not exponent and any(c in stripped for c in b"eEdD"):
            raise Refused(f"id {stripped!r} written with an exponent")
        number = _real(text)
        if not math.isfinite(number) or number != math.floor(number):
            raise Refused(f"{stripped!r} is no integer")
        value = int(number)
    if not -2 ** 63 <= value < 2 ** 63:
        raise Refused(f"{stripped!r} does not fit in 64 bits")
    return value


def _ident(text: bytes) -> int:
    """A node, element or part id field."""
    return _integer(text, exponent=False)


def _check_whole(line: bytes, widths: tuple[int, ...], fmt: str, used: int) -> None:
    """Refused when the file ends (with no line end) inside the first ``used`` fields of
    ``line``: fixed columns shorter than them, or no comma after the last of them."""
    line = line.rstrip()
    if b"," in line:
        whole = len(line.split(b",")) > used
    else:
        whole = len(line) >= sum(_widths(widths, fmt)[:used])
    if not whole:
        raise Refused("the file ends inside its last card")


def _section_key(text: bytes):
    """A section id as written on a part or section card: an integer, else its label."""
    if not text.strip():
        return ""
    try:
        return _integer(text)
    except Refused:
        return text.strip().decode("utf-8", "replace").upper()


# --------------------------------------------------------------------------- blocks
def _lines(text: bytes) -> tuple[list[bytes], bool]:
    """The lines of a deck's text and whether its last line has no line end."""
    text = text.removeprefix(BOM)
    if b"\r" in text:
        if b"\n" not in text:
            text = text.replace(b"\r", b"\n")
        text = text.replace(b"\r\n", b"\n")
        if b"\r" in text:
            raise Refused("a carriage return inside a line")
    if b"\x00" in text:
        raise Refused("a NUL byte")
    unterminated = bool(text) and not text.endswith(b"\n")
    lines = text.split(b"\n")
    if len(lines) > 1 and not lines[-1]:
        lines.pop()
    return lines, unterminated


def _blocks(lines: list[bytes]):
    """(name, format, [(line index, text)]) of each keyword block up to ``*END``; comment
    lines left out, blank lines kept."""
    fmt, blocks = "small", []
    for i, line in enumerate(lines):
        if line.startswith(b"*"):
            match = _KEYWORD.match(line.strip())
            if match is None:
                raise Refused(f"line {i + 1}: no keyword name after '*'")
            name = match.group(1).decode().upper()
            if name == "END":
                break
            if name == "KEYWORD":
                options = match.group(3).upper().replace(b" ", b"")
                long = re.search(rb"LONG=([A-Z])", options)
                i10 = re.search(rb"I10=([A-Z])", options)
                if long:
                    fmt = "long" if long.group(1) == b"Y" else "small"
                elif i10:
                    fmt = "i10" if i10.group(1) == b"Y" else "small"
                blocks.append((name, fmt, []))
                continue
            suffix = match.group(2)
            blocks.append((name, {b"%": "i10", b"+": "long", b"-": "small"}.get(suffix, fmt),
                           []))
        elif blocks and not line.startswith(b"$"):
            blocks[-1][2].append((i, line))
    return blocks


def _trimmed(rows: list, period: int) -> list:
    """``rows`` less trailing blank lines while their count is no multiple of ``period``."""
    while len(rows) % period and rows and not rows[-1][1].strip():
        rows = rows[:-1]
    return rows


def strict_decode(text: bytes) -> StrictDeck:
    """The nodes, shells, parts, sections and parameters of a deck's text, card by card;
    :class:`Refused` for what a correct reader refuses, :class:`BeyondReference` for a
    keyword this decoding does not decode."""
    lines, unterminated = _lines(text)
    last = len(lines) - 1 if unterminated else -1
    deck = StrictDeck()
    for name, fmt, rows in _blocks(lines):
        if name.startswith(_BEYOND) or (name.startswith("PART_") and _defines_parts(name)) \
                or (name.startswith("SECTION_SHELL_") and name != "SECTION_SHELL_TITLE"):
            raise BeyondReference(f"*{name}")
        if name in ("NODE", "NODE_MERGE"):
            for i, line in rows:
                if line.strip():
                    deck.nodes.append(_node(line, fmt, i == last))
        elif name.startswith("ELEMENT_SHELL"):
            deck.shells += _shells(name, fmt, rows, last)
        elif name == "PART":
            _parts(deck, fmt, rows, last)
        elif name in ("SECTION_SHELL", "SECTION_SHELL_TITLE"):
            _sections(deck, fmt, rows, name.endswith("TITLE"), last)
        elif name in ("PARAMETER", "PARAMETER_LOCAL", "PARAMETER_NOECHO"):
            _parameters(deck, fmt, rows)
    return deck


def _defines_parts(name: str) -> bool:
    """Whether a ``*PART_...`` keyword defines parts (rather than moving or listing them)."""
    tokens = name[5:].replace("ATTACHMENT_NODES", "ATTACHMENT-NODES").split("_")
    known = {"CONTACT", "PRINT", "ATTACHMENT-NODES", "REPOSITION", "AVERAGED", "INERTIA",
             "COMPOSITE", "LONG", "TSHELL"}
    return all(t in known for t in tokens if t)


def _node(line: bytes, fmt: str, is_last: bool) -> tuple[int, float, float, float]:
    if is_last:
        _check_whole(line, _NODE, fmt, 4)
    texts = _fields(line, _NODE, fmt)
    nid = _ident(texts[0])
    xyz = [_real(t) for t in texts[1:4]]
    if nid == 0:
        raise Refused("node id 0")
    if not all(math.isfinite(v) for v in xyz):
        raise Refused(f"node {nid}: non-finite coordinates")
    return (nid, *xyz)


def _shells(name: str, fmt: str, rows: list, last: int) -> list:
    """The shell records of an ``*ELEMENT_SHELL`` block (any option the reader reads)."""
    options = set(filter(None, name[len("ELEMENT_SHELL"):].split("_")))
    if options - _SHELL_OPTIONS:
        raise Refused(f"*{name} is not read")
    thick = bool(options & {"THICKNESS", "BETA", "MCID"})
    per = 1 + thick + ("OFFSET" in options)
    rows = [r for r in rows if r[1].strip()] if per == 1 else _trimmed(rows, per)
    if len(rows) % per:
        raise Refused(f"*{name}: {len(rows)} cards, not a multiple of {per}")
    out = []
    for k in range(0, len(rows), per):
        (i, card), *more = rows[k:k + per]
        if i == last:
            _check_whole(card, _SHELL, fmt, 6)
        texts = _fields(card, _SHELL, fmt)
        eid, pid = _ident(texts[0]), _ident(texts[1])
        nodes = tuple(_ident(t) for t in texts[2:6])
        if eid == 0:
            raise Refused("element id 0")
        if pid <= 0:
            raise Refused(f"element {eid}: part id {pid}")
        thickness = None
        if thick:
            if any(_ident(t) for t in texts[6:10]):
                raise Refused("an 8-node shell with thickness cards")
            j, values = more[0]
            if j == last:
                _check_whole(values, _THICK, fmt, 4)
            thickness = tuple(_real(t) for t in _fields(values, _THICK, fmt))
        out.append((eid, pid, nodes, thickness))
    return out


def _parts(deck: StrictDeck, fmt: str, rows: list, last: int) -> None:
    rows = _trimmed(rows, 2)
    for k in range(0, len(rows), 2):
        if k + 1 >= len(rows):
            raise Refused("a *PART title without its card")
        i, card = rows[k + 1]
        if i == last:
            _check_whole(card, _TEN, fmt, 2)
        texts = _fields(card, _TEN, fmt)
        deck.parts[_ident(texts[0])] = _section_key(texts[1])


def _sections(deck: StrictDeck, fmt: str, rows: list, titled: bool, last: int) -> None:
    at = 0
    while at < len(rows) and any(line.strip() for _, line in rows[at:]):
        at += titled
        if at + 1 >= len(rows):
            raise Refused("a *SECTION_SHELL without its two cards")
        first = _fields(rows[at][1], _TEN, fmt)
        elform, nip, icomp = (_integer(first[k]) for k in (1, 3, 6))
        i, second = rows[at + 1]
        if i == last:
            _check_whole(second, _TEN, fmt, 4)
        deck.sections[_section_key(first[0])] = _fields(second, _TEN, fmt)[:4]
        at += 2
        if icomp == 1:
            at += -(-(nip or 2) // 8)
        if elform >= 101:  # a user element: more cards, which end what is read
            break


def _parameters(deck: StrictDeck, fmt: str, rows: list) -> None:
    for _, line in rows:
        if not line.strip():
            continue
        texts = _fields(line, _TEN, fmt)
        for name, value in zip(texts[0::2], texts[1::2]):
            name = name.decode("utf-8", "replace").strip()
            if not name:
                continue
            kind = name[0].upper()
            if kind in "RIC" and len(name) > 1:
                name = name[1:].strip()
            else:
                kind = "R"
            if kind == "C":
                deck.parameters[name] = value.decode("utf-8", "replace").strip()
                continue
            number = _real(value)
            if not math.isfinite(number):
                raise Refused(f"parameter {name!r} is not finite")
            deck.parameters[name] = number


# --------------------------------------------------------------------------- the mesh
def _thickness_value(deck: StrictDeck, text: bytes) -> float:
    """A section thickness field: a number or a (signed) ``&name`` parameter reference; NaN
    (no thickness, the geometry still read) for a parameter the deck defines nowhere."""
    text = text.strip()
    sign = -1.0 if text.startswith(b"-") else 1.0
    bare = text.lstrip(b"+-")
    if bare.startswith(b"&"):
        name = bare[1:].decode("utf-8", "replace").strip()
        folded = {k.lower(): k for k in deck.parameters}
        key = name if name in deck.parameters else folded.get(name.lower())
        if key is None:
            return math.nan
        value = deck.parameters[key]
        if not isinstance(value, float):
            raise Refused(f"parameter {name!r} is not a number")
        return sign * value
    value = _real(text)
    if not math.isfinite(value):
        raise Refused("a non-finite section thickness")
    return value


def expected_mesh(text: bytes) -> Expected:
    """The mesh a correct read of ``text`` gives; :class:`Refused` when a correct reader
    refuses it, :class:`BeyondReference` when this decoding cannot tell."""
    deck = strict_decode(text)
    if not deck.shells:
        raise Refused("no shell elements")
    node_ids = [n[0] for n in deck.nodes]
    if len(set(node_ids)) != len(node_ids):
        raise Refused("a node id defined twice")
    shell_ids = [s[0] for s in deck.shells]
    if len(set(shell_ids)) != len(shell_ids):
        raise Refused("an element id defined twice")
    defined = set(node_ids)
    connectivity = []
    for eid, pid, nodes, _ in deck.shells:
        n1, n2, n3, n4 = nodes
        if n4 == 0:
            n4 = n3
        if not {n1, n2, n3, n4} <= defined:
            raise Refused(f"element {eid} names an undefined node")
        if pid >= 2 ** 31:
            raise Refused(f"part id {pid} beyond 32 bits")
        if deck.parts and pid not in deck.parts:
            raise Refused(f"part id {pid} is not defined by a *PART")
        connectivity.append((n1, n2, n3, n4))
    section_t, sections_used = {}, False
    for pid in sorted({s[1] for s in deck.shells}):
        key = deck.parts.get(pid)
        texts = deck.sections.get(key) if pid in deck.parts else None
        if texts is None:
            continue
        t = [_thickness_value(deck, x) for x in texts]
        section_t[pid] = [t[0]] + [v if v != 0 else t[0] for v in t[1:]]
        sections_used = True
    thickness = []
    for (_, pid, _, cards), nodes in zip(deck.shells, connectivity):
        fallback = section_t.get(pid, [math.nan] * 4)
        nodal = [c if cards is not None and not math.isnan(c) and c != 0 else f
                 for c, f in zip(cards or [math.nan] * 4, fallback)]
        used = nodal[:3] if nodes[3] == nodes[2] else nodal
        thickness.append(math.fsum(used) / len(used))
    has_thickness = sections_used or any(math.isfinite(t) for t in thickness)
    return Expected(np.array(node_ids, np.int64), np.array([n[1:] for n in deck.nodes], float),
                    np.array(shell_ids, np.int64), np.array([s[1] for s in deck.shells]),
                    np.array(connectivity, np.int64),
                    np.array(thickness) if has_thickness else None)


def mesh_differences(mesh, expected: Expected) -> list[str]:
    """What a read mesh gets wrong against the expected one, one short line per quantity
    (node ids, coordinates, element ids, connectivity, part ids, thickness); [] when none."""
    out = []
    read_ids = np.asarray(mesh.node_ids if mesh.node_ids is not None
                          else np.arange(1, mesh.n_nodes + 1))
    if sorted(read_ids.tolist()) != sorted(expected.node_ids.tolist()):
        missing = sorted(set(expected.node_ids.tolist()) - set(read_ids.tolist()))
        extra = sorted(set(read_ids.tolist()) - set(expected.node_ids.tolist()))
        return [f"node ids: {len(missing)} missing {missing[:3]}, {len(extra)} not in the deck "
                f"{extra[:3]}"]
    order = np.argsort(read_ids)
    at = order[np.searchsorted(read_ids[order], expected.node_ids)]
    xyz = mesh.nodes[at]
    wrong = np.flatnonzero((xyz != expected.nodes).any(axis=1))
    if len(wrong):
        k = int(wrong[0])
        out.append(f"coordinates of {len(wrong)} node(s): node {int(expected.node_ids[k])} "
                   f"read {xyz[k].tolist()}, expected {expected.nodes[k].tolist()}")
    eids = np.asarray(mesh.element_ids if mesh.element_ids is not None
                      else np.arange(1, mesh.n_elements + 1))
    if eids.tolist() != expected.element_ids.tolist():
        missing = sorted(set(expected.element_ids.tolist()) - set(eids.tolist()))
        extra = sorted(set(eids.tolist()) - set(expected.element_ids.tolist()))
        out.append(f"element ids: {len(missing)} missing {missing[:3]}, {len(extra)} not in "
                   f"the deck {extra[:3]}" if missing or extra else "element ids: other order")
        return out
    connectivity = read_ids[mesh.elements]
    for what, got, want in (("connectivity", connectivity, expected.connectivity),
                            ("part ids", mesh.parts, expected.parts)):
        bad = np.flatnonzero((np.asarray(got).reshape(len(eids), -1)
                              != np.asarray(want).reshape(len(eids), -1)).any(axis=1))
        if len(bad):
            k = int(bad[0])
            out.append(f"{what} of {len(bad)} element(s): element {int(eids[k])} read "
                       f"{np.asarray(got)[k].tolist()}, expected {np.asarray(want)[k].tolist()}")
    read_t = mesh.element_fields.get("thickness")
    if (read_t is None) != (expected.thickness is None):
        out.append("thickness: " + ("no field read, the deck gives one" if read_t is None
                                    else "a field read, the deck gives none"))
    elif read_t is not None:
        same = np.isclose(read_t, expected.thickness, rtol=1e-12, atol=0, equal_nan=True)
        if not same.all():
            k = int(np.argmin(same))
            out.append(f"thickness of {int((~same).sum())} element(s): element {int(eids[k])} "
                       f"read {float(read_t[k])!r}, expected {float(expected.thickness[k])!r}")
    return out
