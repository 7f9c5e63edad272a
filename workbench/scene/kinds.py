"""The element kinds of an FE model beside its surface: beams and SPH particles.

An :class:`~workbench.scene.mesh.FEMesh` draws shells and the faces of solids and thick shells
as its (M, 4) surface elements; beams (line elements: beams, trusses, spot welds and rods are
all beams in LS-DYNA) and SPH particles (one node each) have no faces, so they ride beside the
surface as the optional attributes ``FEMesh.beams`` (:class:`Beams`) and ``FEMesh.particles``
(:class:`Particles`). They share the mesh's nodes (their node indices index ``FEMesh.nodes``,
so their coordinates at each state come from ``FEMesh.steps``) and its part ids.

Fields follow the mesh's conventions: (K,) static or (T, K) per state, float64, NaN where a
value is missing. The field ``"alive"`` is erosion as for the surface elements: 1 in use, 0
deleted at that state (a missing value counts as in use); :meth:`alive` reads it.

A particle's ``radius`` (model units, (P,) or (T, P)) is the radius drawn; the readers say
where it comes from (the d3plot's per-state SPH radius, or for a keyword deck half the spacing
to the nearest other particle).

A mesh of only beams or particles is refused by :class:`FEMesh` (it needs at least one surface
element: every render path and algorithm draws triangles); validation refuses node indices out
of range and array shapes that do not fit (:func:`check_kinds`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from .conventions import ALIVE, MeshError


@dataclass(frozen=True, eq=False)
class _Kind:
    """What beams and particles share: part ids, user ids and per-item fields."""

    parts: np.ndarray  # (K,) int32 user part ids
    ids: np.ndarray | None = None  # (K,) int64 user element ids, None when unknown
    fields: dict[str, np.ndarray] = field(default_factory=dict)  # (K,) or (T, K) float64

    label: ClassVar[str] = "element"  # the kind's name in messages

    def __post_init__(self) -> None:
        object.__setattr__(self, "parts", np.ascontiguousarray(self.parts, np.int32))
        object.__setattr__(self, "fields", _float_fields(self.fields))
        if self.ids is not None:
            object.__setattr__(self, "ids", np.asarray(self.ids, np.int64))

    @property
    def count(self) -> int:
        return len(self.parts)

    def remapped(self, node_map: np.ndarray):
        """The items whose nodes ``node_map`` ((N,) new index, −1 dropped) all keeps,
        renumbered, as a new object of the same kind; None when none is left."""
        nodes = node_map[self._node_columns()]
        keep = (nodes >= 0).reshape(self.count, -1).all(axis=1)
        if not keep.any():
            return None
        return self._kept(keep, nodes[keep])

    def _kept(self, keep: np.ndarray, nodes: np.ndarray):
        """The items ``keep`` selects, with their renumbered ``nodes``."""
        raise NotImplementedError

    def _kept_common(self, keep: np.ndarray) -> dict:
        """The shared attributes of the items ``keep`` selects."""
        return dict(parts=self.parts[keep], ids=None if self.ids is None else self.ids[keep],
                    fields={k: v[..., keep] for k, v in self.fields.items()})

    def field(self, name: str, step: int | None = None) -> np.ndarray:
        """(K,) values of ``name`` at ``step`` (static fields ignore the step)."""
        values = self.fields[name]
        return values if values.ndim == 1 else values[0 if step is None else step]

    def alive(self, step: int | None = None) -> np.ndarray:
        """(K,) bool, in use at ``step``: all without an ``"alive"`` field, else where it is
        not 0 (a missing value counts as in use)."""
        if ALIVE not in self.fields:
            return np.ones(self.count, bool)
        return self.field(ALIVE, step) != 0

    def n_deleted(self, step: int | None = None) -> int:
        return self.count - int(self.alive(step).sum())

    def field_range(self, name: str) -> tuple[float, float] | None:
        """(min, max) of the finite values of live items over every state; None without one."""
        values = self.fields[name]
        steps = values.shape[0] if values.ndim == 2 else 1
        live = np.stack([self.alive(t) for t in range(steps)]) if values.ndim == 2 \
            else self.alive(None)
        finite = values[np.isfinite(values) & live]
        return (float(finite.min()), float(finite.max())) if finite.size else None

    def _node_columns(self) -> np.ndarray:
        raise NotImplementedError

    def _check(self, n_nodes: int, n_steps: int, mesh: str) -> None:
        nodes = self._node_columns()
        k = self.count
        if self.parts.shape != (k,) or len(nodes) != k:
            raise MeshError(f"{mesh}: {self.label}s: {len(nodes)} node rows but parts "
                            f"{self.parts.shape}")
        if self.ids is not None and np.shape(self.ids) != (k,):
            raise MeshError(f"{mesh}: {self.label} ids must be ({k},), got "
                            f"{np.shape(self.ids)}")
        bad = np.flatnonzero(((nodes < 0) | (nodes >= n_nodes)).reshape(k, -1).any(axis=1))
        if len(bad):
            raise MeshError(f"{mesh}: {len(bad)} {self.label}s reference missing nodes, first "
                            f"{[(int(i), np.atleast_1d(nodes[i]).tolist()) for i in bad[:5]]}")
        for key, values in self.fields.items():
            _check_per_item(values, k, n_steps, f"{mesh}: {self.label} field {key!r}")


def _check_per_item(values: np.ndarray, k: int, n_steps: int, what: str) -> None:
    if not (values.shape == (k,) or (values.ndim == 2 and values.shape == (n_steps, k))):
        raise MeshError(f"{what} must be ({k},) or ({n_steps}, {k}), got {values.shape}")


def _float_fields(fields: dict) -> dict[str, np.ndarray]:
    return {name: np.asarray(values, np.float64) for name, values in fields.items()}


@dataclass(frozen=True, eq=False)
class Beams(_Kind):
    """Line elements: ``nodes`` (B, 2) int32 end nodes (indices into ``FEMesh.nodes``),
    ``parts`` (B,) user part ids, ``ids`` (B,) user ids or None, ``fields`` per beam, e.g.
    ``"axial_force"`` (force units of the model) and ``"alive"``. A beam's third (orientation)
    node is not kept: it is not drawn."""

    nodes: np.ndarray = field(default_factory=lambda: np.zeros((0, 2), np.int32))
    label: ClassVar[str] = "beam"

    def __post_init__(self) -> None:
        super().__post_init__()
        object.__setattr__(self, "nodes", np.ascontiguousarray(
            np.asarray(self.nodes).reshape(-1, 2), np.int32))

    def _node_columns(self) -> np.ndarray:
        return self.nodes

    def _kept(self, keep: np.ndarray, nodes: np.ndarray) -> Beams:
        return Beams(**self._kept_common(keep), nodes=nodes)


@dataclass(frozen=True, eq=False)
class Particles(_Kind):
    """SPH particles: ``node`` (P,) int32 the node of each (index into ``FEMesh.nodes``),
    ``parts`` (P,) user part ids, ``ids`` (P,) user ids (a deck's particle id is its node id)
    or None, ``radius`` (P,) or (T, P) float64 drawn radius in model units (finite, > 0;
    the reader says where it comes from), ``fields`` per particle (``"alive"`` included)."""

    node: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int32))
    radius: np.ndarray = field(default_factory=lambda: np.zeros(0))
    label: ClassVar[str] = "SPH particle"

    def __post_init__(self) -> None:
        super().__post_init__()
        object.__setattr__(self, "node", np.ascontiguousarray(self.node, np.int32).ravel())
        object.__setattr__(self, "radius", np.asarray(self.radius, np.float64))

    def _node_columns(self) -> np.ndarray:
        return self.node

    def radius_at(self, step: int | None = None) -> np.ndarray:
        """(P,) radius drawn at ``step`` (model units)."""
        return self.radius if self.radius.ndim == 1 else self.radius[0 if step is None else step]

    def _check(self, n_nodes: int, n_steps: int, mesh: str) -> None:
        super()._check(n_nodes, n_steps, mesh)
        _check_per_item(self.radius, self.count, n_steps, f"{mesh}: SPH radius")
        bad = ~(np.isfinite(self.radius) & (self.radius > 0))
        if bad.any():
            raise MeshError(f"{mesh}: SPH radius must be finite and > 0, got "
                            f"{self.radius[bad][:5].tolist()}")

    def _kept(self, keep: np.ndarray, nodes: np.ndarray) -> Particles:
        return Particles(**self._kept_common(keep), node=nodes,
                         radius=self.radius[..., keep])


def check_kinds(mesh) -> None:
    """Refuse (MeshError) beams or particles of ``mesh`` that do not fit its nodes and steps:
    node indices out of range, arrays of the wrong shape, a radius not finite and > 0, an
    attribute of the wrong type."""
    for name, kind in (("beams", Beams), ("particles", Particles)):
        value = getattr(mesh, name)
        if value is None:
            continue
        if not isinstance(value, kind):
            raise MeshError(f"{mesh.name}: {name} must be a {kind.__name__}, got "
                            f"{type(value).__name__}")
        if value.count == 0:
            setattr(mesh, name, None)
            continue
        value._check(mesh.n_nodes, mesh.n_steps, mesh.name)


def kind_counts(mesh) -> dict[str, int]:
    """{kind: count} of what ``mesh`` holds beside its surface elements (beams, SPH
    particles), kinds it lacks left out."""
    out = {}
    for kind in (mesh.beams, mesh.particles):
        if kind is not None:
            out[f"{kind.label}s"] = kind.count
    return out


def kind_nodes(mesh) -> np.ndarray:
    """Sorted node indices used by the beams and particles of ``mesh`` (empty without)."""
    parts = [np.zeros(0, np.int64)]
    if mesh.beams is not None:
        parts.append(mesh.beams.nodes.ravel())
    if mesh.particles is not None:
        parts.append(mesh.particles.node)
    return np.unique(np.concatenate(parts))


def kind_lines(mesh) -> list[str]:
    """A line per kind ``mesh`` holds beside its surface (for ``workbench info MESH``): the
    surface elements, then beams and SPH particles with their count, parts and, where some are
    deleted, the count deleted per state; nothing for a mesh of surface elements only."""
    kinds = [kind for kind in (mesh.beams, mesh.particles) if kind is not None]
    if not kinds:
        return []
    lines = [f"element kinds: {mesh.n_elements} surface elements (shells and the faces of "
             f"solids and thick shells), " + ", ".join(f"{k.count} {k.label}s" for k in kinds)]
    for kind in kinds:
        parts = ", ".join(str(p) for p in np.unique(kind.parts).tolist())
        deleted = [kind.n_deleted(t) for t in range(mesh.n_steps)]
        line = f"{kind.label}s: {kind.count} in parts {parts}"
        if any(deleted):
            line += f"; deleted per state: {', '.join(map(str, deleted))}"
        if kind.fields:
            line += f"; fields: {', '.join(sorted(kind.fields))}"
        lines.append(line)
    return lines
