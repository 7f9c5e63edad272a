"""What a scene derives for the render paths drawn on it: only what they declare, once.

Every render path declares ``needs``, a subset of :data:`workbench.paths.base.NEEDS`; before a
path is prepared, :func:`derive` computes the items it names on the mesh (which caches them) and
reports what that cost. The items:

* ``triangles`` — the triangulation (quads split along the shorter diagonal);
* ``edges`` — the unique element edges of a wire frame;
* ``gouraud`` — the crease-split vertices at ``Style.crease_deg`` (the triangulation included);
* ``fepatch`` — the fe2003 model of ``Style.fepatch`` (patches, simplified surface, textures);
* ``part_distances`` — every node's distance to the nearest other part within
  ``Style.cutoff`` at ``Style.step`` (crash2000 §4.1; the flange path's field).

:func:`derived_items` lists what a mesh holds, so that a caller can check that preparing a path
derived nothing it had not declared, and :func:`derivation_cost` measures on a fresh copy what
deriving a set of items costs, so that a table can state what a path's ``needs`` saved.
"""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass

import numpy as np

# the items derived for the mesh paths; "fepatch" is the texture paths' own and far costlier
MESH_ITEMS = ("triangles", "edges", "gouraud")


@dataclass(frozen=True)
class Derivation:
    """What one :func:`derive` call computed: ``items`` (name → (ms, bytes)) of the items that
    were not cached yet; ``ms`` and ``nbytes`` are their totals (0 when all were cached)."""

    items: dict

    @property
    def ms(self) -> float:
        return float(sum(ms for ms, _ in self.items.values()))

    @property
    def nbytes(self) -> int:
        return int(sum(nbytes for _, nbytes in self.items.values()))


def _key(item: str, style) -> tuple:
    if item == "gouraud":
        return item, float(getattr(style, "crease_deg", 30.0))
    if item == "fepatch":
        return item, str(getattr(style, "fepatch", "A"))
    if item == "part_distances":
        return item, float(getattr(style, "cutoff", 50.0)), int(getattr(style, "step", 0))
    return (item,)


def derived_items(mesh) -> set[tuple]:
    """The items ``mesh`` holds now, as keys ``("triangles",)``, ``("edges",)``,
    ``("gouraud", crease_deg)`` and ``("fepatch", parameters)``."""
    held = {(name,) for name in ("triangulation", "edges") if name in mesh.__dict__}
    held = {("triangles",) if k == ("triangulation",) else k for k in held}
    held |= {("gouraud", float(c)) for c in mesh.__dict__.get("_gouraud_cache", {})}
    held |= {("fepatch", p) for p in mesh.__dict__.get("_fepatch_cache", {})}
    held |= {("part_distances", *k) for k in mesh.__dict__.get("_part_distance_cache", {})}
    return held


def needed_items(needs, style) -> set[tuple]:
    """The keys (as :func:`derived_items` names them) that ``needs`` asks for under ``style``;
    ``gouraud`` brings the triangulation it splits, ``fepatch`` nothing else."""
    keys = {_key(item, style) for item in needs}
    if "gouraud" in needs:
        keys.add(("triangles",))
    return keys


def nbytes_of(value, exclude=()) -> int:
    """Bytes of the numpy arrays held by ``value`` (an array, a dataclass or object of arrays,
    or a list/tuple/dict of them), shared arrays counted once and the arrays of ``exclude``
    (say, the mesh's own nodes and elements) not at all."""
    seen: set[int] = {id(a if a.base is None else a.base) for a in exclude}

    def walk(v) -> int:
        if isinstance(v, np.ndarray):
            base = v if v.base is None else v.base
            if id(base) in seen or not isinstance(base, np.ndarray):
                return 0 if id(base) in seen else v.nbytes
            seen.add(id(base))
            return base.nbytes
        if isinstance(v, (list, tuple)):
            return sum(walk(x) for x in v)
        if isinstance(v, dict):
            return sum(walk(x) for x in v.values())
        if dataclasses.is_dataclass(v) and not isinstance(v, type):
            return sum(walk(getattr(v, f.name)) for f in dataclasses.fields(v))
        if hasattr(v, "__dict__") and not isinstance(v, type):
            return sum(walk(x) for x in vars(v).values())
        return 0

    return walk(value)


def _compute(mesh, item: str, style):
    if item == "triangles":
        return mesh.triangulation
    if item == "edges":
        return mesh.edges
    if item == "gouraud":
        return mesh.gouraud(float(getattr(style, "crease_deg", 30.0)))
    if item == "fepatch":
        return mesh.fepatch_model(str(getattr(style, "fepatch", "A")))
    if item == "part_distances":
        return mesh.part_distances(float(getattr(style, "cutoff", 50.0)),
                                   int(getattr(style, "step", 0)))
    raise ValueError(f"no derived item {item!r}; known: triangles, edges, gouraud, fepatch, "
                     f"part_distances")


def derive(mesh, needs, style) -> Derivation:
    """Compute on ``mesh`` (an FEMesh, which caches them) the items of ``needs`` it does not hold
    yet, for ``style`` (crease angle, fe2003 parameters); returns their cost in ms and bytes.
    The triangulation goes first, so that a Gouraud split's cost excludes it. ValueError for an
    unknown item."""
    items = {}
    own = [a for a in (mesh.nodes, mesh.elements, mesh.parts, mesh.steps) if a is not None]
    order = sorted(set(needs) | ({"triangles"} if "gouraud" in needs else set()),
                   key=lambda n: (n != "triangles", n))
    for item in order:
        key = _key(item, style)
        if key in derived_items(mesh):
            continue
        start = time.perf_counter()
        value = _compute(mesh, item, style)
        ms = (time.perf_counter() - start) * 1e3
        # a Gouraud split refers to the triangulation, counted as its own item
        shared = own + ([a for a in vars(mesh.triangulation).values()
                         if isinstance(a, np.ndarray)] if item == "gouraud" else [])
        items[item] = (ms, nbytes_of(value, exclude=shared))
    return Derivation(items)


def derivation_cost(mesh, needs, style) -> Derivation:
    """What deriving ``needs`` costs from nothing: :func:`derive` on a fresh copy of ``mesh``
    (same arrays, no cached items), so the mesh given keeps its caches untouched."""
    fresh = dataclasses.replace(mesh)
    return derive(fresh, needs, style)
