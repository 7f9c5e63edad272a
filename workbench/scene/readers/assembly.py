"""The FEMesh of a read keyword deck: node and element ids mapped to indices, duplicates and
undefined references refused, the shell thickness from thickness cards and sections, and the
solids drawn by their faces (:mod:`workbench.scene.solids`).

Every refusal is a :class:`~workbench.scene.readers.errors.ParseError` at the card that causes
it (its file and 1-based line), found again from the chunks of lines each block was read from.
"""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np

from ..mesh import FEMesh
from .cards import _Chunk, _locate
from .errors import ParseError, ParseWarning, build_mesh

if TYPE_CHECKING:
    from .parameters import _Parameters


class KeywordDeck(Protocol):
    """What :func:`deck_mesh` reads of a deck walk (the keyword reader's deck, which is not
    imported here: :mod:`~workbench.scene.readers.keyword` imports this module). Per block in
    reading order: the node ids and coordinates, the shell and solid ids, part ids, node ids
    and the shells' nodal thickness, each with the chunk of lines it came from; the parts and
    sections by id, the parameters, the keywords skipped (name → data cards) and the master
    file. Thick shells are read as solids; ``solid_keywords`` tells each solid block's keyword."""

    master: Path
    node_ids: list[np.ndarray]
    node_xyz: list[np.ndarray]
    node_chunks: list[_Chunk]
    shell_ids: list[np.ndarray]
    shell_parts: list[np.ndarray]
    shell_nodes: list[np.ndarray]
    shell_thickness: list[np.ndarray]
    shell_chunks: list[_Chunk]
    solid_ids: list[np.ndarray]
    solid_parts: list[np.ndarray]
    solid_nodes: list[np.ndarray]
    solid_chunks: list[_Chunk]
    solid_keywords: list[str]
    parts: dict[int, Any]
    sections: dict[object, Any]
    parameters: _Parameters
    skipped: dict[str, int]


def deck_mesh(deck: KeywordDeck, units: str, all_faces: bool = False) -> FEMesh:
    """The FEMesh of what ``deck`` (the deck walk of :mod:`~workbench.scene.readers.keyword`)
    read: shells, then the faces of its solids (every face with
    ``all_faces``), with ids, parts, part titles and the element field ``"thickness"``.

    Refused: a deck without shell or solid elements, a node or element id defined twice, an
    element naming an undefined node, a part id beyond 32 bits, a part id that no ``*PART``
    defines (in a deck that defines parts; a deck without any ``*PART`` is a mesh file, whose
    part ids are used as they are), a solid of an unknown node pattern, and what
    :class:`FEMesh` refuses.
    """
    n_shells = sum(len(ids) for ids in deck.shell_ids)
    if n_shells + sum(len(ids) for ids in deck.solid_ids) == 0:
        others = ", ".join(f"*{k}" for k in sorted(deck.skipped))
        raise ParseError(deck.master, "no shell or solid elements (*ELEMENT_SHELL, "
                         "*ELEMENT_SOLID) in the deck"
                         + (f"; it has {others}, which are not read" if others else ""))
    node_ids = np.concatenate(deck.node_ids) if deck.node_ids else np.zeros(0, np.int64)
    xyz = np.concatenate(deck.node_xyz) if deck.node_xyz else np.zeros((0, 3))
    order, sorted_ids = _unique_or_raise(node_ids, deck.node_chunks, "node")
    element_ids = np.concatenate([*deck.shell_ids, *deck.solid_ids])
    # shells, solids and thick shells number their elements apart, as LS-DYNA's types do
    _unique_or_raise(element_ids[:n_shells], deck.shell_chunks, "element")
    for keyword in ("ELEMENT_SOLID", "ELEMENT_TSHELL"):
        blocks = [i for i, k in enumerate(deck.solid_keywords) if k == keyword]
        if blocks:
            _unique_or_raise(np.concatenate([deck.solid_ids[i] for i in blocks]),
                             [deck.solid_chunks[i] for i in blocks],
                             "solid element" if keyword == "ELEMENT_SOLID" else "thick shell")
    _check_parts_defined(deck)

    shell_ids = element_ids[:n_shells]
    pids = np.concatenate(deck.shell_parts) if n_shells else np.zeros(0, np.int64)
    refs = np.concatenate(deck.shell_nodes) if n_shells else np.zeros((0, 4), np.int64)
    if not (node_ids == 0).any():  # n4 left blank on a triangle
        blank4 = refs[:, 3] == 0
        refs[blank4, 3] = refs[blank4, 2]
    elements = _node_indices(refs, order, sorted_ids, shell_ids, deck.shell_chunks,
                             "ELEMENT_SHELL")
    _check_part_ids(pids, deck.shell_chunks, "ELEMENT_SHELL")
    thickness, sections_used, unknown = (_shell_thickness(deck, pids, elements) if n_shells
                                         else (np.zeros(0), False, ""))
    if deck.solid_ids:
        faces, face_pids, face_ids = _solid_faces(deck, element_ids[n_shells:], xyz, order,
                                                  sorted_ids, all_faces)
        elements = np.concatenate([elements, faces])
        pids = np.concatenate([pids, face_pids])
        shell_ids = np.concatenate([shell_ids, face_ids])
        thickness = np.concatenate([thickness, np.full(len(faces), np.nan)])

    element_fields = {}
    if np.isfinite(thickness).any() or sections_used:  # a section gave no number:
        element_fields["thickness"] = thickness  # missing (NaN), not absent
    used_parts = set(np.unique(pids).tolist())
    part_names = {pid: part.title for pid, part in deck.parts.items()
                  if part.title and pid in used_parts}
    return build_mesh(deck.master, nodes=xyz, elements=elements, parts=pids,
                      element_fields=element_fields, part_names=part_names,
                      node_ids=node_ids, element_ids=shell_ids, name=deck.master.name,
                      units=units, unavailable={"thickness": unknown} if unknown else {})


def _solid_faces(deck, solid_ids: np.ndarray, xyz: np.ndarray, order: np.ndarray,
                 sorted_ids: np.ndarray, all_faces: bool):
    """(faces (F, 4) node indices, their part ids, their solids' ids) of the boundary faces
    of the deck's solids, or of every face with ``all_faces``."""
    from ..solids import boundary_surface, solid_kinds

    solid_pids = np.concatenate(deck.solid_parts)
    _check_part_ids(solid_pids, deck.solid_chunks, "ELEMENT_SOLID")
    node_refs = np.concatenate(deck.solid_nodes)
    solids = _node_indices(node_refs, order, sorted_ids, solid_ids, deck.solid_chunks,
                           "ELEMENT_SOLID")
    unknown = np.flatnonzero(solid_kinds(solids) == 0)
    if len(unknown):
        src, row = _locate(deck.solid_chunks, int(unknown[0]))
        raise src.error(f"{len(unknown)} solid(s) of a node pattern LS-DYNA does not "
                        f"define; expected a hexahedron (n1..n8 distinct), pentahedron "
                        f"(n1 n2 n3 n4 n5 n5 n6 n6) or tetrahedron (n1 n2 n3 n4 n4 n4 "
                        f"n4 n4)", row, "ELEMENT_SOLID")
    try:
        faces, face_pids, face_of = boundary_surface(solids, xyz, solid_pids, all_faces)
    except ValueError as exc:
        raise ParseError(deck.master, f"*ELEMENT_SOLID: {exc}") from None
    return faces, face_pids, solid_ids[face_of]


def _shell_thickness(deck, pids: np.ndarray,
                     elements: np.ndarray) -> tuple[np.ndarray, bool, str]:
    """(M,) mean nodal thickness: element thickness cards, zeros and gaps from the section;
    whether a part's ``*SECTION_SHELL`` gave the thickness of its shells; and why some
    thickness cannot be known ("" where all can): a section naming a parameter defined
    nowhere in the deck, warned once a parameter (its parts' thickness NaN)."""
    nodal = np.concatenate(deck.shell_thickness)
    unique, inverse = np.unique(pids, return_inverse=True)
    section_of_part = {}
    undefined: dict[str, tuple[Any, list[int]]] = {}  # name: (first section, its parts)
    for pid in unique.tolist():
        part = deck.parts.get(pid)
        section = None if part is None else deck.sections.get(part.secid)
        if section is None:
            continue
        names = list(map(deck.parameters.undefined, section.thickness))
        for name in {n for n in names if n}:  # an include read without its master deck
            undefined.setdefault(name, (section, []))[1].append(pid)
        t = np.array([np.nan if name else
                      deck.parameters.thickness(text, section.src, section.row)
                      for name, text in zip(names, section.thickness)])
        t[1:][t[1:] == 0] = t[0]  # T2..T4 default to T1
        section_of_part[pid] = t
    fallback = np.full((len(pids), 4), np.nan)
    if section_of_part:
        table = np.array([section_of_part.get(p, [np.nan] * 4) for p in unique.tolist()])
        fallback = table[inverse.reshape(-1)]
    for name, (section, parts) in undefined.items():  # one warning a parameter
        warnings.warn(ParseWarning(
            section.src.path, f"{deck.parameters.undefined_message(name)}: the geometry is "
            f"read, the shells of part{'s' * (len(parts) > 1)} {', '.join(map(str, parts))} "
            f"have no thickness (read the master deck that defines it for that)",
            section.row + 1, "SECTION_SHELL"), stacklevel=2)
    unknown = "; ".join(
        f"{section.src.path}:{section.row + 1}: the thickness of part"
        f"{'s' * (len(parts) > 1)} {', '.join(map(str, parts))} uses parameter {name!r}, "
        f"defined nowhere in this deck or its includes: read the master deck that defines it"
        for name, (section, parts) in undefined.items())
    use_section = np.isnan(nodal) | (nodal == 0)
    nodal = np.where(use_section, fallback, nodal)
    triangle = elements[:, 3] == elements[:, 2]
    return (np.where(triangle, nodal[:, :3].mean(axis=1), nodal.mean(axis=1)),
            bool(section_of_part), unknown)


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


def _check_parts_defined(deck) -> None:
    """ParseError at the first element whose part id no ``*PART`` defines, when the deck
    defines parts (a deck that defines none is a mesh file read without its parts)."""
    groups = [(deck.shell_parts, deck.shell_chunks, "ELEMENT_SHELL"),
              (deck.solid_parts, deck.solid_chunks, "ELEMENT_SOLID")]
    if not deck.parts:
        return
    defined = np.array(sorted(deck.parts), np.int64)
    for parts, chunks, keyword in groups:
        if not parts:
            continue
        pids = np.concatenate(parts)
        undefined = ~np.isin(pids, defined)
        if undefined.any():
            first = int(np.argmax(undefined))
            src, row = _locate(chunks, first)
            missing = np.unique(pids[undefined])
            shown = ", ".join(str(int(p)) for p in defined[:8]) + (" ..." * (len(defined) > 8))
            raise src.error(f"part id {int(pids[first])} is not defined by any *PART "
                            f"({len(missing)} undefined part id(s); defined: {shown})", row,
                            keyword)


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
        keyword = {"node": "NODE", "element": "ELEMENT_SHELL",
                   "thick shell": "ELEMENT_TSHELL"}.get(what, "ELEMENT_SOLID")
        raise src.error(f"{what} id {int(ids[second])} is defined twice (first at "
                        f"{src0.path.name}:{row0 + 1}); {len(repeated)} repeated id(s)", row,
                        keyword)
    return order, sorted_ids
