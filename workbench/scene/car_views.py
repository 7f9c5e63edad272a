"""What to look at in the shared LS-DYNA car deck (``builtin_scene("car")``): its longitudinal
members and a trace line for force tubes along one of them.

**The deck.** Car-body coordinates in mm: x runs rearwards (the bumper, part 2, spans
x = 0 … 112.5; the rear ends at x = 4318), y across the car (0 … 1397), z up. Part 8 is a rigid
barrier (material type 20) in front of the car, at negative x. The part names are only the
material types, so the members are found from the geometry (:func:`longitudinal_members`): a
**member** is a connected piece of one part (elements linked through shared nodes) that is
long along the longitudinal axis and narrow across it (its extent across at most ``slender``
times its length, and its length at least a tenth of the model's). In this deck there are
four: two front rails (part 5, x = 112.5 … 1016, thickness 5 mm, rectangular box sections
about 70 × 85 mm at y ≈ 210 and y ≈ 1187, z = 0 … 85) and their rearward continuations
(part 6, x = 1016 … 4318, thickness 2 mm). The other parts (body, bumper, panels, roof,
barrier) are not slender.

:func:`~workbench.scene.generators.crash_sequence` with its default ``axis="-x"`` pushes the
front (smallest x) rearwards along x, so these rails carry the crush: the front rails first,
their continuations as the crush zone (2.5 times the crush depth) reaches past x = 1016.
With the barrier free to move (the default ``still_parts=()``) the barrier is the front and
the car's own front sits 355 mm behind it; ``still_parts=car_barrier_parts(mesh)`` keeps the
barrier in place and makes the bumper the front.

**The trace line** (:func:`car_trace_line`): the centre line of the members on one side, in
slices along the axis. The members' nodes are grouped into slices (node stations along the
axis, split where consecutive stations are more than ``1e-3`` of the length apart); the
centroid of each slice's nodes is a point of the centre line (for a box section: the centre of
the box). The control points are the centroids at the ends of the chain of members (front end,
joints between parts, rear end) and any slice whose centroid leaves the straight line between
its neighbours among the control points by more than 1 % of the section's width (a bent
member; the rails of this deck are straight, so the line is front end, joint, rear end:
x = 112.5, 1016, 4318).

**Both rails are cut.** The section planes of a force tube are unbounded and both rails are
of the same parts, so ``force_tube(mesh, points, parts=parts)`` gives the force of the two
rails together. For one rail alone pass ``selection_radius=car_selection_radius(mesh)`` (half
the distance between the rails' centre lines).
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import pairwise

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from .mesh import FEMesh

_AXES = {"x": 0, "y": 1, "z": 2}


@dataclass(frozen=True)
class Member:
    """A longitudinal member: ``part`` id, ``elements`` (indices into the mesh), ``nodes``
    (indices), its range ``lo`` … ``hi`` along the axis and the ``centroid`` (3,) of its
    nodes, all at step 0."""

    part: int
    elements: np.ndarray
    nodes: np.ndarray
    lo: float
    hi: float
    centroid: np.ndarray


def _axis(axis: str) -> int:
    key = str(axis).lower().lstrip("+-")
    if key not in _AXES:
        raise ValueError(f"axis must be one of x, y, z, got {axis!r}")
    return _AXES[key]


def _components(elements: np.ndarray, n_nodes: int) -> tuple[int, np.ndarray]:
    """Connected components of ``elements`` (E, 4) through shared nodes: (count, label per
    element)."""
    rows = np.repeat(np.arange(len(elements)), 4)
    graph = coo_matrix((np.ones(rows.size), (rows, elements.ravel() + len(elements))),
                       shape=(len(elements) + n_nodes,) * 2)
    _, labels = connected_components(graph.tocsr(), directed=False)
    element_labels = labels[:len(elements)]
    unique, compact = np.unique(element_labels, return_inverse=True)
    return len(unique), compact


def longitudinal_members(mesh: FEMesh, axis: str = "x", slender: float = 0.25) -> list[Member]:
    """The connected pieces of single parts that are long along ``axis`` and narrow across it
    (see the module notes), ordered by part id and then by their centroid across the axis."""
    a = _axis(axis)
    nodes = mesh.coordinates(0)
    used = nodes[mesh.used_nodes()]
    model_length = float(used[:, a].max() - used[:, a].min())
    members = []
    for part in np.unique(mesh.parts):
        idx = np.flatnonzero(mesh.parts == part)
        count, label = _components(mesh.elements[idx].astype(np.int64), mesh.n_nodes)
        for c in range(count):
            elements = idx[label == c]
            node_idx = np.unique(mesh.elements[elements])
            x = nodes[node_idx]
            extent = x.max(axis=0) - x.min(axis=0)
            length = float(extent[a])
            across = float(np.delete(extent, a).max())
            if length >= 0.1 * model_length and across <= slender * length:
                members.append(Member(int(part), elements, node_idx, float(x[:, a].min()),
                                      float(x[:, a].max()), x.mean(axis=0)))
    cross = [i for i in range(3) if i != a]
    members.sort(key=lambda m: (m.part, *m.centroid[cross]))
    return members


def _side(side: str, a: int) -> tuple[int, float]:
    key = str(side).lower()
    sign = -1.0 if key.startswith("-") else 1.0
    b = _AXES.get(key.lstrip("+-"))
    if b is None or b == a:
        raise ValueError(f"side must be a signed axis across the longitudinal one "
                         f"(e.g. '-y', '+y'), got {side!r}")
    return b, sign


def _chain(members: list[Member], side: str, a: int) -> list[Member]:
    """The members on ``side`` of the middle of all members, in order along the axis."""
    b, sign = _side(side, a)
    centres = np.array([m.centroid[b] for m in members])
    middle = 0.5 * (centres.min() + centres.max())
    chosen = [m for m, c in zip(members, centres) if sign * (c - middle) > 0]
    if not chosen:
        raise ValueError(f"no longitudinal member on the {side} side")
    return sorted(chosen, key=lambda m: m.lo)


def car_trace_line(mesh: FEMesh, *, side: str = "-y", axis: str = "x",
                   slender: float = 0.25) -> tuple[np.ndarray, tuple[int, ...]]:
    """``(control_points (K, 3), parts)``: the centre line of the longitudinal members on
    ``side`` (a signed axis across ``axis``: "-y" the rail at small y, "+y" the other) and
    the part ids of all longitudinal members, for
    :func:`~workbench.algo.forcetube.force_tube` (see the module notes: how the points are
    found, and that the planes cut the rails of both sides). For the shared car deck: the
    rail at y ≈ 210, points at x = 112.5, 1016 and 4318, parts (5, 6).

    Refused (ValueError): a mesh without longitudinal members, or none on ``side``.
    """
    a = _axis(axis)
    members = longitudinal_members(mesh, axis, slender)
    if not members:
        raise ValueError(f"{mesh.name} has no longitudinal member along {axis} (no connected "
                         f"piece of a part at most {slender} as wide as long)")
    chain = _chain(members, side, a)
    nodes = mesh.coordinates(0)
    idx = np.unique(np.concatenate([m.nodes for m in chain]))
    x = nodes[idx]
    along = x[:, a]
    length = float(along.max() - along.min())
    order = np.argsort(along, kind="stable")
    gaps = np.flatnonzero(np.diff(along[order]) > 1e-3 * length)
    slices = np.split(order, gaps + 1)
    stations = np.array([along[s].mean() for s in slices])
    centroids = np.array([x[s].mean(axis=0) for s in slices])
    width = float(np.delete(x.max(axis=0) - x.min(axis=0), a).max())

    ends = sorted({m.lo for m in chain} | {m.hi for m in chain})
    keep = {int(np.argmin(np.abs(stations - e))) for e in ends}
    # split the line where a slice's centroid leaves it (Douglas–Peucker between kept points)
    changed = True
    while changed:
        changed = False
        kept = sorted(keep)
        for i, j in pairwise(kept):
            if j - i < 2:
                continue
            p, q = centroids[i], centroids[j]
            d = q - p
            inner = centroids[i + 1:j]
            t = ((inner - p) @ d) / (d @ d)
            off = np.linalg.norm(inner - (p + t[:, None] * d), axis=1)
            k = int(np.argmax(off))
            if off[k] > 0.01 * width:
                keep.add(i + 1 + k)
                changed = True
    points = centroids[sorted(keep)]
    parts = tuple(sorted({m.part for m in members}))
    return points, parts


def car_selection_radius(mesh: FEMesh, *, axis: str = "x", slender: float = 0.25) -> float:
    """Half the smallest distance, across ``axis``, between the centroids of two longitudinal
    members whose ranges along the axis overlap (the two front rails, say): a
    ``selection_radius`` for :func:`~workbench.algo.forcetube.force_tube` that keeps one
    member's elements and drops its neighbour's. Refused (ValueError) with fewer than two
    such members."""
    a = _axis(axis)
    members = longitudinal_members(mesh, axis, slender)
    best = np.inf
    for i, m in enumerate(members):
        for n in members[i + 1:]:
            if min(m.hi, n.hi) > max(m.lo, n.lo):
                gap = np.delete(m.centroid - n.centroid, a)
                best = min(best, float(np.linalg.norm(gap)))
    if not np.isfinite(best):
        raise ValueError(f"{mesh.name} has no two side-by-side longitudinal members")
    return 0.5 * best


def car_barrier_parts(mesh: FEMesh, *, axis: str = "x") -> tuple[int, ...]:
    """Part ids that lie entirely in front of the car along ``axis`` (below the smallest
    coordinate of every other part — the deck's rigid barrier, part 8), for
    ``crash_sequence(..., still_parts=...)``."""
    a = _axis(axis)
    nodes = mesh.coordinates(0)
    lo, hi = {}, {}
    for part in np.unique(mesh.parts):
        x = nodes[np.unique(mesh.elements[mesh.parts == part])][:, a]
        lo[int(part)], hi[int(part)] = float(x.min()), float(x.max())
    front = [p for p in lo if all(hi[p] < lo[q] for q in lo if q != p)]
    return tuple(sorted(front))
