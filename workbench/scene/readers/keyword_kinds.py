"""Beams and SPH particles of a keyword deck, for :mod:`~workbench.scene.readers.keyword`.

* ``*ELEMENT_BEAM`` and its options ``_THICKNESS``, ``_SECTION``, ``_PID``, ``_OFFSET`` and
  ``_ORIENTATION`` (one more card each, not read): element id, part id, n1, n2 (the orientation
  node n3 is not kept) → :class:`~workbench.scene.kinds.Beams`. Other options (``_SCALAR``,
  ``_ELBOW`` ...) are named with their card count and not drawn, as other element keywords.
* ``*ELEMENT_SPH``: node id (the particle's id), part id, MASS, NEND (the last node of a series
  NID..NEND of particles with the same part and mass; blank or 0: one particle) →
  :class:`~workbench.scene.kinds.Particles`, their ids the node ids.

**The SPH radius drawn.** A deck gives a particle's mass (MASS) and its section's smoothing
length factor and bounds (``*SECTION_SPH`` CSLH, HMIN, HMAX), none of them its extent: the
smoothing length h = CSLH × (initial spacing) is the kernel's support, about 1.2 spacings,
and a radius from the mass needs the material's density (``*MAT_...``, not read). Drawn is
half the initial distance to the nearest other particle of the same part (the particles of a
regular lattice then touch), computed with
:func:`~workbench.scene.readers.d3plot_kinds.spacing_radius`; a part of one particle takes
1/200 of the model's box diagonal.

Refused (ParseError at the card): a beam or particle naming an undefined node, a blank, zero or
negative part id, a part id no ``*PART`` defines (where the deck defines parts), a blank element
id, a series whose NEND is below NID, and a deck with beams or particles but no shell, solid or
thick shell (a mesh is drawn from its surface elements: the message names what it holds).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..kinds import Beams, Particles, check_kinds
from .cards import _Block, _Chunk, _Field, _locate, _refuse_zero_ids, _table
from .errors import ParseError

_BEAM = (8,) * 10
_SPH = (8, 8, 16, 8)
# *ELEMENT_BEAM options that add one card per element, which is skipped
BEAM_OPTIONS = {"THICKNESS", "SECTION", "PID", "OFFSET", "ORIENTATION"}


@dataclass
class KindBlocks:
    """What the beam and SPH blocks of a deck read, in reading order, with their lines."""

    beam_ids: list[np.ndarray] = field(default_factory=list)
    beam_parts: list[np.ndarray] = field(default_factory=list)
    beam_nodes: list[np.ndarray] = field(default_factory=list)  # (B, 2) node ids
    beam_chunks: list[_Chunk] = field(default_factory=list)
    sph_nodes: list[np.ndarray] = field(default_factory=list)  # node ids
    sph_parts: list[np.ndarray] = field(default_factory=list)
    sph_chunks: list[_Chunk] = field(default_factory=list)  # one row per particle

    def counts(self) -> dict[str, int]:
        return {"beams": sum(len(i) for i in self.beam_ids),
                "SPH particles": sum(len(i) for i in self.sph_nodes)}

    # ------------------------------------------------------------------ blocks
    def read(self, block: _Block) -> bool:
        """Read ``block`` if it is a beam or SPH block this module reads; False otherwise."""
        name = block.keyword
        if name == "ELEMENT_SPH":
            self._sph(block)
            return True
        if name == "ELEMENT_BEAM" or name.startswith("ELEMENT_BEAM_"):
            options = set(filter(None, name[len("ELEMENT_BEAM"):].split("_")))
            if options <= BEAM_OPTIONS:
                self._beams(block, 1 + len(options))
                return True
        return False

    def _beams(self, block: _Block, per_element: int) -> None:
        rows = block.trimmed(per_element) if per_element > 1 else block.rows
        if per_element > 1 and len(rows) % per_element:
            raise block.error(f"expected {per_element} cards per beam, the block ends after "
                              f"{len(rows) % per_element}", int(rows[-1]))
        cards, values = _table(block, rows[::per_element], _BEAM, [
            _Field(0, "id", "an integer element id"), _Field(1, "id", "an integer part id"),
            _Field(2, "id", "integer node ids n1, n2"),
            _Field(3, "id", "integer node ids n1, n2")], drop_blank=per_element == 1)
        _refuse_zero_ids(block, values[0], cards, "an element id")
        _refuse_bad_parts(block, values[1], cards)
        self.beam_ids.append(values[0])
        self.beam_parts.append(values[1])
        self.beam_nodes.append(np.column_stack(values[2:4]))
        self.beam_chunks.append(_Chunk(block.src, cards))

    def _sph(self, block: _Block) -> None:
        cards, (nid, pid, _mass, nend) = _table(block, block.rows, _SPH, [
            _Field(0, "id", "an integer node id"), _Field(1, "id", "an integer part id"),
            _Field(2, "f", "a mass"), _Field(3, "id", "an integer last node id (NEND)")],
            drop_blank=True)
        _refuse_zero_ids(block, nid, cards, "a node id")
        _refuse_bad_parts(block, pid, cards)
        nend = np.where(nend == 0, nid, nend)
        if (nend < nid).any():
            i = int(np.argmax(nend < nid))
            raise block.error(f"NEND {int(nend[i])} is below the node id {int(nid[i])}",
                              int(cards[i]))
        count = nend - nid + 1
        series = np.repeat(np.arange(len(nid)), count)
        offset = np.arange(len(series)) - np.repeat(np.cumsum(count) - count, count)
        self.sph_nodes.append(nid[series] + offset)
        self.sph_parts.append(pid[series])
        self.sph_chunks.append(_Chunk(block.src, cards[series]))

    # ------------------------------------------------------------------ the mesh's kinds
    def refuse_alone(self, master, n_surface: int) -> None:
        """ParseError for a deck of beams or particles without surface elements."""
        held = [f"{n} {what}" for what, n in self.counts().items() if n]
        if n_surface == 0 and held:
            raise ParseError(master, f"no shell, solid or thick shell elements in the deck: it "
                                     f"holds {' and '.join(held)} only, and a mesh is drawn "
                                     f"from its surface elements")

    def attach(self, mesh, parts: dict) -> None:
        """Give ``mesh`` (the deck's FEMesh) its beams and particles, validated, and their
        parts' titles (``parts``: the deck's parts by id); refusals as the module notes say."""
        kinds = self.kinds(mesh.node_ids, mesh.nodes, parts)
        if kinds["beams"] is None and kinds["particles"] is None:
            return
        mesh.beams, mesh.particles = kinds["beams"], kinds["particles"]
        check_kinds(mesh)
        for kind in (mesh.beams, mesh.particles):
            for pid in [] if kind is None else np.unique(kind.parts).tolist():
                if pid in parts and parts[pid].title:
                    mesh.part_names.setdefault(pid, parts[pid].title)

    def kinds(self, node_ids: np.ndarray, nodes: np.ndarray,
              defined_parts: dict) -> dict[str, Beams | Particles | None]:
        """``{"beams": ..., "particles": ...}`` with node ids mapped to indices of
        ``node_ids``; refusals as the module notes say."""
        order = np.argsort(node_ids, kind="stable")
        sorted_ids = node_ids[order]
        beams = particles = None
        if self.beam_ids:
            ids, pids = np.concatenate(self.beam_ids), np.concatenate(self.beam_parts)
            _parts_defined(pids, defined_parts, self.beam_chunks, "ELEMENT_BEAM")
            index = _indices(np.concatenate(self.beam_nodes), order, sorted_ids,
                             self.beam_chunks, "ELEMENT_BEAM", ids)
            beams = Beams(parts=pids, ids=ids, nodes=index)
        if self.sph_nodes:
            ids, pids = np.concatenate(self.sph_nodes), np.concatenate(self.sph_parts)
            _parts_defined(pids, defined_parts, self.sph_chunks, "ELEMENT_SPH")
            index = _indices(ids[:, None], order, sorted_ids, self.sph_chunks, "ELEMENT_SPH",
                             ids)[:, 0]
            radius = np.empty(len(ids))
            for pid in np.unique(pids):
                mine = pids == pid
                radius[mine] = _spacing(nodes[index[mine]], nodes)
            particles = Particles(parts=pids, ids=ids, node=index, radius=radius)
        return {"beams": beams, "particles": particles}


def _spacing(points: np.ndarray, nodes: np.ndarray) -> np.ndarray:
    from .d3plot_kinds import spacing_radius

    if len(points) > 1:
        return spacing_radius(points)
    diagonal = float(np.linalg.norm(np.ptp(nodes, axis=0)))
    return np.full(len(points), diagonal / 200.0 if diagonal > 0 else 1.0)


def _refuse_bad_parts(block: _Block, pids: np.ndarray, rows: np.ndarray) -> None:
    bad = pids <= 0
    if bad.any():
        i = int(np.argmax(bad))
        got = "a blank or 0" if pids[i] == 0 else str(int(pids[i]))
        raise block.error(f"expected a positive part id, got {got}", int(rows[i]))


def _parts_defined(pids: np.ndarray, defined: dict, chunks: list[_Chunk], keyword: str) -> None:
    if not defined:
        return
    undefined = ~np.isin(pids, np.array(sorted(defined), np.int64))
    if undefined.any():
        src, row = _locate(chunks, int(np.argmax(undefined)))
        raise src.error(f"part id {int(pids[undefined][0])} is not defined by any *PART",
                        row, keyword)


def _indices(refs: np.ndarray, order: np.ndarray, sorted_ids: np.ndarray,
             chunks: list[_Chunk], keyword: str, ids: np.ndarray) -> np.ndarray:
    """Node indices of the node ids ``refs`` (K, k); ParseError at the first record naming an
    undefined node."""
    if len(sorted_ids):
        pos = np.searchsorted(sorted_ids, refs).clip(max=len(sorted_ids) - 1)
        found = sorted_ids[pos] == refs
        index = order[pos]
    else:
        found, index = np.zeros(refs.shape, bool), np.zeros(refs.shape, np.int64)
    if not found.all():
        bad = np.flatnonzero(~found.all(axis=1))
        src, row = _locate(chunks, int(bad[0]))
        raise src.error(f"{len(bad)} record(s) reference undefined node ids; first (id, node "
                        f"id): ({int(ids[bad[0]])}, {int(refs[bad[0]][~found[bad[0]]][0])})",
                        row, keyword)
    return index
