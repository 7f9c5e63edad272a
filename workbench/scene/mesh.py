"""The finite-element surface model shared by every reader, generator, algorithm and render path.

Conventions (see the design notes): nodes are float64, elements are (M, 4) int32 with a
triangle repeating its third node (``e[3] == e[2]``), one part id per element, optional
(T, N, 3) coordinates of every time step sharing one topology, and fields per node
((N,) or (T, N)) or per element ((M,) or (T, M)).

Derived data (triangulation, unique edges, crease-split "Gouraud edges", and what algorithms
register) is computed on first request and kept in the mesh's one cache, ``derived``; see
:mod:`workbench.scene.needs` (the registry) and :mod:`workbench.scene.derived` (the geometry).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np

from .conventions import ALIVE, MeshError

if TYPE_CHECKING:
    from numpy.typing import ArrayLike

    from .crease import GouraudSplit
    from .derived import Triangulation
    from .kinds import Beams, Particles


@dataclass(eq=False)
class FEMesh:
    """A shell FE model: float64 nodes, (M, 4) int32 elements, part ids, time steps and fields.

    Construction validates and normalises the arrays; an empty mesh, an element that names a
    node outside ``nodes``, or a step array whose shape does not match is refused with
    :class:`MeshError` (the first few offending elements are listed).

    ``beams`` and ``particles`` (:mod:`workbench.scene.kinds`) hold the line elements and SPH
    particles beside the surface, sharing its nodes; they are validated here too. A mesh needs
    at least one surface element (shell or face): one of only beams or particles is refused.
    The box of :meth:`bounds` includes their nodes.
    """

    nodes: np.ndarray
    elements: np.ndarray
    parts: np.ndarray | None = None
    steps: np.ndarray | None = None
    node_fields: dict[str, np.ndarray] = field(default_factory=dict)
    element_fields: dict[str, np.ndarray] = field(default_factory=dict)
    part_names: dict[int, str] = field(default_factory=dict)
    times: np.ndarray | None = None
    node_ids: np.ndarray | None = None
    element_ids: np.ndarray | None = None
    name: str = "mesh"
    units: str = "mm"
    # fields whose values cannot be known from this file, with why (a thickness parameter
    # defined in a master deck not read): drawn nowhere, refused where used
    unavailable: dict[str, str] = field(default_factory=dict)
    # beams and SPH particles beside the surface (workbench.scene.kinds), None without
    beams: Beams | None = None
    particles: Particles | None = None
    # what render paths made the mesh derive, by cache key (see workbench.scene.needs)
    derived: dict[tuple[Any, ...], Any] = field(default_factory=dict, init=False, repr=False)

    kind: ClassVar[str] = "mesh"

    def __post_init__(self) -> None:
        self.nodes = np.ascontiguousarray(self.nodes, dtype=np.float64)
        if self.nodes.ndim != 2 or self.nodes.shape[1] != 3:
            raise MeshError(f"{self.name}: nodes must be (N, 3), got {self.nodes.shape}")
        elements = np.asarray(self.elements)
        if elements.ndim == 2 and elements.shape[1] == 3:
            elements = np.concatenate([elements, elements[:, 2:3]], axis=1)
        if elements.ndim != 2 or elements.shape[1] != 4:
            raise MeshError(f"{self.name}: elements must be (M, 4) or (M, 3), got {elements.shape}")
        self.elements = np.ascontiguousarray(elements, dtype=np.int32)
        if len(self.nodes) == 0 or len(self.elements) == 0:
            raise MeshError(
                f"{self.name}: empty mesh ({len(self.nodes)} nodes, {len(self.elements)} elements)"
            )
        if not np.isfinite(self.nodes).all():
            bad = np.flatnonzero(~np.isfinite(self.nodes).all(axis=1))
            raise MeshError(f"{self.name}: non-finite coordinates at nodes {bad[:5].tolist()}")
        bad = np.flatnonzero(((self.elements < 0) | (self.elements >= len(self.nodes))).any(axis=1))
        if len(bad):
            raise MeshError(
                f"{self.name}: {len(bad)} elements reference missing nodes, first "
                f"{[(int(i), self.elements[i].tolist()) for i in bad[:5]]}"
            )
        if self.parts is None:
            self.parts = np.zeros(len(self.elements), np.int32)
        self.parts = np.ascontiguousarray(self.parts, dtype=np.int32)
        if self.parts.shape != (len(self.elements),):
            raise MeshError(f"{self.name}: parts must be ({len(self.elements)},), "
                            f"got {self.parts.shape}")
        if self.steps is not None:
            self.steps = np.ascontiguousarray(self.steps, dtype=np.float64)
            if self.steps.ndim != 3 or self.steps.shape[1:] != self.nodes.shape:
                raise MeshError(
                    f"{self.name}: steps must be (T, {len(self.nodes)}, 3), got {self.steps.shape}"
                )
        for kind, fields, n in (("node", self.node_fields, len(self.nodes)),
                                ("element", self.element_fields, len(self.elements))):
            for key, values in list(fields.items()):
                values = np.asarray(values, dtype=np.float64)
                ok = values.shape == (n,) or (values.ndim == 2 and values.shape[1] == n
                                              and values.shape[0] == self.n_steps)
                if not ok:
                    raise MeshError(
                        f"{self.name}: {kind} field {key!r} must be ({n},) or "
                        f"({self.n_steps}, {n}), got {values.shape}"
                    )
                fields[key] = values
        from .kinds import check_kinds

        check_kinds(self)

    # ----------------------------------------------------------------- sizes
    @property
    def n_nodes(self) -> int:
        return len(self.nodes)

    @property
    def n_elements(self) -> int:
        return len(self.elements)

    @property
    def n_steps(self) -> int:
        """Number of time steps (1 for a static mesh)."""
        return 1 if self.steps is None else len(self.steps)

    @cached_property
    def is_triangle(self) -> np.ndarray:
        """(M,) bool: elements stored as triangles (third node repeated)."""
        return self.elements[:, 3] == self.elements[:, 2]

    @property
    def n_quads(self) -> int:
        return int((~self.is_triangle).sum())

    # ----------------------------------------------------------------- geometry
    def coordinates(self, step: int | None = None) -> np.ndarray:
        """(N, 3) float64 node coordinates of ``step`` (the reference nodes when None or static)."""
        if step is None or self.steps is None:
            return self.nodes
        return self.steps[step]

    def step_index(self, step: Any, what: str = "step") -> int:
        """``step`` as an int in [0, n_steps); ValueError naming ``what`` for anything but a
        Python or numpy integer (a bool or a float such as 1.0 included) or a step out of
        range."""
        if isinstance(step, (bool, np.bool_)) or not isinstance(step, (int, np.integer)):
            raise ValueError(f"{what} must be an integer step, got {step!r}")
        if not 0 <= int(step) < self.n_steps:
            raise ValueError(f"{what} {step} out of range: {self.name} has steps "
                             f"0..{self.n_steps - 1}")
        return int(step)

    def finite_coordinates(self, step: int | None = None) -> np.ndarray:
        """:meth:`coordinates` of ``step``, refused (ValueError naming the step and the first
        nodes) where any is not finite."""
        coords = self.coordinates(step)
        finite = np.isfinite(coords).all(axis=1)
        if not finite.all():
            bad = np.flatnonzero(~finite)
            raise ValueError(f"{self.name}: non-finite coordinates at step {step}, nodes "
                             f"{bad[:5].tolist()} ({len(bad)} in all)")
        return coords

    def node_field(self, name: str, step: int | None = None) -> np.ndarray:
        """(N,) values of a per-node field at ``step`` (static fields ignore the step)."""
        values = self.node_fields[name]
        return values if values.ndim == 1 else values[0 if step is None else step]

    def element_field(self, name: str, step: int | None = None) -> np.ndarray:
        """(M,) values of a per-element field at ``step`` (static fields ignore the step)."""
        values = self.element_fields[name]
        return values if values.ndim == 1 else values[0 if step is None else step]

    def field_range(self, name: str, step: int | None = None) -> tuple[float, float]:
        """(min, max) of a field over all steps (or at ``step`` only), finite values of live
        elements only: with erosion (:attr:`erodes`) a deleted element's value, and a node's
        value at a step where no live element uses it, take no part (a deleted shell keeps its
        failure value). (0, 1) where no value is left."""
        values = self.node_fields.get(name)
        per_node = values is not None
        if values is None:
            values = self.element_fields[name]
        steps = range(self.n_steps) if step is None else [step]
        if values.ndim == 2:
            values = values[list(steps)]
        keep = np.isfinite(values)
        if self.erodes:
            live = np.stack([self.live_nodes(t) if per_node else self.alive(t) for t in steps])
            keep = keep & (live if values.ndim == 2 else live.any(axis=0))
        finite = values[keep]
        return (float(finite.min()), float(finite.max())) if finite.size else (0.0, 1.0)

    # ----------------------------------------------------------------- erosion
    @property
    def erodes(self) -> bool:
        """Whether an element is deleted at some step: the element field ``"alive"`` (1 in
        use, 0 deleted, as the d3plot reader gives it) holds a 0."""
        alive = self.element_fields.get(ALIVE)
        return alive is not None and bool((alive == 0).any())

    def alive(self, step: int | None = None) -> np.ndarray:
        """(M,) bool, the elements in use at ``step``: all of them without an ``"alive"``
        field; with one, those whose value is not 0 (a missing value counts as in use)."""
        if ALIVE not in self.element_fields:
            return np.ones(self.n_elements, bool)
        return self.element_field(ALIVE, step) != 0

    def triangles_alive(self) -> np.ndarray | None:
        """(T, K) bool: whether each triangle of :attr:`triangulation` is in use at each of
        the T states (that of its element); None without erosion."""
        if not self.erodes:
            return None
        element_of = self.triangulation.element_of
        return np.stack([self.alive(k)[element_of] for k in range(self.n_steps)])

    def n_deleted(self, step: int | None = None) -> int:
        """The number of elements deleted at ``step`` (0 without erosion)."""
        return self.n_elements - int(self.alive(step).sum())

    def deleted_count(self, step: int | None = None) -> dict[int, int]:
        """{part id: number of elements deleted at ``step``}, parts without one left out."""
        deleted = ~self.alive(step)
        parts, counts = np.unique(self.parts[deleted], return_counts=True)
        return {int(p): int(c) for p, c in zip(parts, counts)}

    def live_nodes(self, step: int | None = None) -> np.ndarray:
        """(N,) bool, the nodes used by an element in use at ``step``."""
        used = np.zeros(self.n_nodes, bool)
        used[self.elements[self.alive(step)].ravel()] = True
        return used

    def live_edges(self, step: int | None = None) -> np.ndarray:
        """(E,) bool over :attr:`edges`: the edges of an element in use at ``step``."""
        from .derived import unique_edges

        def keys(edges: np.ndarray) -> np.ndarray:
            return (edges[:, 0].astype(np.int64) << 32) | edges[:, 1].astype(np.int64)

        everything, live = keys(self.edges), keys(unique_edges(self.elements[self.alive(step)]))
        at = np.minimum(np.searchsorted(live, everything), max(len(live) - 1, 0))
        return (live[at] == everything) if len(live) else np.zeros(len(everything), bool)

    def used_nodes(self) -> np.ndarray:
        """Sorted indices of the nodes referenced by at least one element."""
        return np.unique(self.elements)

    def bounds(self, step: int | None = None,
               all_steps: bool = False) -> tuple[np.ndarray, np.ndarray]:
        """(lo, hi) float64 corners of the axis-aligned box of the referenced nodes."""
        used = self.used_nodes()
        if self.beams is not None or self.particles is not None:
            from .kinds import kind_nodes

            used = np.union1d(used, kind_nodes(self))
        if all_steps and self.steps is not None:
            pts = self.steps[:, used].reshape(-1, 3)
        else:
            pts = self.coordinates(step)[used]
        return pts.min(axis=0), pts.max(axis=0)

    def bounding_sphere(self, step: int | None = None,
                        all_steps: bool = False) -> tuple[np.ndarray, float]:
        """(centre, radius) of the sphere around the bounding box of the referenced nodes."""
        lo, hi = self.bounds(step, all_steps)
        return (lo + hi) / 2.0, float(np.linalg.norm(hi - lo) / 2.0)

    def translated(self, offset: ArrayLike) -> FEMesh:
        """A copy moved by ``offset`` (model units); topology and fields are shared."""
        offset = np.asarray(offset, dtype=np.float64)
        return FEMesh(
            nodes=self.nodes + offset,
            elements=self.elements,
            parts=self.parts,
            steps=None if self.steps is None else self.steps + offset,
            node_fields=dict(self.node_fields),
            element_fields=dict(self.element_fields),
            part_names=dict(self.part_names),
            times=self.times,
            node_ids=self.node_ids,
            element_ids=self.element_ids,
            name=self.name,
            units=self.units,
            unavailable=dict(self.unavailable),
            beams=self.beams,
            particles=self.particles,
        )

    def part(self, part_id: int) -> FEMesh:
        """The sub-mesh of one part, with its nodes compacted (fields follow)."""
        keep = self.parts == part_id
        if not keep.any():
            raise MeshError(f"{self.name}: no part {part_id}")
        return self.subset(keep, name=f"{self.name}:{self.part_names.get(part_id, part_id)}")

    def subset(self, element_mask: np.ndarray, name: str | None = None) -> FEMesh:
        """The sub-mesh of the selected elements, with unreferenced nodes removed; beams and
        particles are kept where their nodes are."""
        elements = self.elements[element_mask]
        used, inverse = np.unique(elements, return_inverse=True)
        node_map = np.full(self.n_nodes, -1, np.int64)
        node_map[used] = np.arange(len(used))
        return FEMesh(
            nodes=self.nodes[used],
            elements=inverse.reshape(elements.shape).astype(np.int32),
            parts=self.parts[element_mask],
            steps=None if self.steps is None else self.steps[:, used],
            node_fields={k: v[..., used] for k, v in self.node_fields.items()},
            element_fields={k: v[..., element_mask] for k, v in self.element_fields.items()},
            part_names=dict(self.part_names),
            times=self.times,
            node_ids=None if self.node_ids is None else self.node_ids[used],
            element_ids=None if self.element_ids is None else self.element_ids[element_mask],
            name=name or self.name,
            units=self.units,
            unavailable=dict(self.unavailable),
            beams=None if self.beams is None else self.beams.remapped(node_map),
            particles=None if self.particles is None else self.particles.remapped(node_map),
        )

    # ----------------------------------------------------------------- derived (cached)
    @property
    def triangulation(self) -> Triangulation:
        """:class:`~workbench.scene.derived.Triangulation`: quads split along the shorter
        diagonal (derived once, see :mod:`workbench.scene.needs`)."""
        from .needs import triangulation

        return triangulation(self)

    @property
    def triangles(self) -> np.ndarray:
        """(K, 3) int32 triangles into ``nodes`` (quads split along the shorter diagonal)."""
        return self.triangulation.triangles

    @property
    def edges(self) -> np.ndarray:
        """(E, 2) int32 unique element edges (quad edges only, no diagonals), sorted per row
        (derived once)."""
        from .needs import edges

        return edges(self)

    def face_normals(self, step: int | None = None) -> np.ndarray:
        """(M, 3) float64 unit normals per element (zero for degenerate elements)."""
        from .derived import element_normals

        return element_normals(self.elements, self.coordinates(step))

    def vertex_normals(self, step: int | None = None) -> np.ndarray:
        """(N, 3) float64 area-weighted unit normals per node, no crease split."""
        from .derived import node_normals

        return node_normals(self.elements, self.coordinates(step))

    def gouraud(self, crease_deg: float = 30.0) -> GouraudSplit:
        """:class:`~workbench.scene.crease.GouraudSplit` for this crease angle (derived once
        per angle). Creases are detected on the first and last time steps together
        (crash2000, Fig. 2)."""
        from .needs import gouraud

        return gouraud(self, crease_deg)

    def __repr__(self) -> str:
        return (f"FEMesh({self.name!r}: {self.n_nodes} nodes, {self.n_elements} elements "
                f"({self.n_quads} quads), {len(np.unique(self.parts))} parts, "
                f"{self.n_steps} steps)")
