"""What a scene derives for the render paths drawn on it: one registry of derived items, one cache
on the mesh, and what deriving them costs.

A render path declares ``needs``, a set of item names. Each item is registered once, by the
module that computes it, with the :func:`derived_item` decorator; the decorated function
becomes the item's cached accessor: ``gouraud(mesh, 30.0)`` computes the crease split once per
mesh and angle and keeps it in the mesh's cache (``FEMesh.derived``). Before a path is
prepared, :func:`derive` computes the items it needs on the mesh and reports what that cost.

The items registered here are the mesh's own:

* ``triangles`` — the triangulation (quads split along the shorter diagonal);
* ``edges`` — the unique element edges of a wire frame;
* ``gouraud`` — the crease-split vertices at ``Style.crease_deg`` (brings the triangulation).

Algorithms register theirs next to their code: ``fepatch`` (the fe2003 model of
``Style.fepatch``, :mod:`workbench.algo.fepatch.mesh_model`) and ``part_distances`` (every node's
distance to the nearest other part, :mod:`workbench.algo.nearest.parts`).

Cache keys are tuples ``(name, *parameters)``: ``("triangles",)``, ``("gouraud", 30.0)``,
``("fepatch", "A")``, ``("part_distances", 50.0, 0)``. :func:`derived_items` lists the keys a
mesh holds, so that a caller can check that preparing a path derived nothing it had not
declared, and :func:`derivation_cost` measures on a fresh copy what deriving a set of items
costs, so that a table can state what a path's ``needs`` saved.
"""

from __future__ import annotations

import dataclasses
import functools
import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, ClassVar, Protocol, TypeVar, cast

import numpy as np

if TYPE_CHECKING:
    from .crease import GouraudSplit
    from .derived import Triangulation

# the items derived for the mesh paths; "fepatch" is the texture paths' own and far costlier
MESH_ITEMS = ("triangles", "edges", "gouraud")

_Compute = TypeVar("_Compute", bound=Callable[..., Any])


class MeshLike(Protocol):
    """What this module reads of a mesh; an :class:`~workbench.scene.mesh.FEMesh` meets it.
    (The mesh class is not imported here: :mod:`workbench.scene.mesh` imports this module.)"""

    __dataclass_fields__: ClassVar[dict[str, Any]]
    nodes: np.ndarray
    elements: np.ndarray
    parts: np.ndarray | None
    steps: np.ndarray | None
    derived: dict[tuple[Any, ...], Any]

    @property
    def n_steps(self) -> int: ...

    def coordinates(self, step: int | None = None) -> np.ndarray: ...


@dataclass(frozen=True)
class DerivedItem:
    """A registered item: ``compute(mesh, *parameters)``, ``key(*arguments)`` (the parameters
    normalised, as they appear in the cache key), ``from_style(style)`` (the arguments a path's
    style gives) and ``brings`` (items derived first and counted apart, e.g. the triangulation
    a Gouraud split refers to)."""

    name: str
    compute: Callable[..., Any]
    key: Callable[..., tuple]
    from_style: Callable[[Any], tuple]
    brings: tuple[str, ...] = ()

    def cache_key(self, *arguments: Any) -> tuple:
        return (self.name, *self.key(*arguments))


ITEMS: dict[str, DerivedItem] = {}


def _no_parameters() -> tuple:
    return ()


def derived_item(name: str, *, key: Callable[..., tuple] = _no_parameters,
                 from_style: Callable[[Any], tuple] = lambda style: (),
                 brings: tuple[str, ...] = ()) -> Callable[[_Compute], _Compute]:
    """Register ``compute(mesh, *parameters)`` as derived item ``name`` and return its cached
    accessor (same signature): the first call per mesh and parameters computes, later calls
    return the value kept in ``mesh.derived``. ``key`` normalises the accessor's arguments into
    the cache key's parameters (say ``lambda crease_deg=30.0: (float(crease_deg),)``);
    ``from_style`` gives those arguments from a path's style. Refuses (ValueError) a name that
    is already registered by another function."""

    def register(compute: _Compute) -> _Compute:
        old = ITEMS.get(name)
        if old is not None and (old.compute.__module__, old.compute.__qualname__) != (
                compute.__module__, compute.__qualname__):
            raise ValueError(f"derived item {name!r} is already registered by "
                             f"{old.compute.__module__}.{old.compute.__qualname__}")
        item = DerivedItem(name, compute, key, from_style, tuple(brings))
        ITEMS[name] = item

        @functools.wraps(compute)
        def cached(mesh, *arguments):
            return _value(mesh, item, item.key(*arguments))

        return cast(_Compute, cached)

    return register


def _value(mesh, item: DerivedItem, parameters: tuple):
    cache = mesh.derived
    full = (item.name, *parameters)
    if full not in cache:
        cache[full] = item.compute(mesh, *parameters)
    return cache[full]


def item(name: str) -> DerivedItem:
    """The registered item ``name``; ValueError listing the registered items otherwise."""
    try:
        return ITEMS[name]
    except KeyError:
        raise ValueError(f"no derived item {name!r}; registered: {', '.join(sorted(ITEMS))}") \
            from None


def known_items() -> frozenset[str]:
    """The names of every registered item."""
    return frozenset(ITEMS)


# ------------------------------------------------------------------------- the mesh's own items
@derived_item("triangles")
def triangulation(mesh: MeshLike) -> Triangulation:
    """:class:`~workbench.scene.derived.Triangulation` of ``mesh``: quads split along the shorter
    diagonal."""
    from .derived import triangulate

    return triangulate(mesh.elements, mesh.nodes)


@derived_item("edges")
def edges(mesh: MeshLike) -> np.ndarray:
    """(E, 2) int32 unique element edges of ``mesh`` (quad edges only, no diagonals)."""
    from .derived import unique_edges

    return unique_edges(mesh.elements)


@derived_item("gouraud", key=lambda crease_deg=30.0: (float(crease_deg),),
              from_style=lambda style: (getattr(style, "crease_deg", 30.0),),
              brings=("triangles",))
def gouraud(mesh: MeshLike, crease_deg: float) -> GouraudSplit:
    """:class:`~workbench.scene.crease.GouraudSplit` of ``mesh`` at ``crease_deg`` degrees.
    Creases are detected on the first and last time steps together (crash2000, Fig. 2)."""
    from .crease import gouraud_split

    coords = [mesh.coordinates(0)]
    if mesh.n_steps > 1:
        coords.append(mesh.coordinates(mesh.n_steps - 1))
    return gouraud_split(mesh.elements, coords, crease_deg, triangulation(mesh))


# ------------------------------------------------------------------------- what deriving costs
@dataclass(frozen=True)
class Derivation:
    """What one :func:`derive` call computed: ``items`` (name → (ms, bytes)) of the items that
    were not cached yet; ``ms`` and ``nbytes`` are their totals (0 when all were cached)."""

    items: dict[str, tuple[float, int]]

    @property
    def ms(self) -> float:
        return float(sum(ms for ms, _ in self.items.values()))

    @property
    def nbytes(self) -> int:
        return int(sum(nbytes for _, nbytes in self.items.values()))


def derived_items(mesh: MeshLike) -> set[tuple]:
    """The cache keys ``mesh`` holds now (see the module docstring)."""
    return set(mesh.derived)


def _order(needs: Iterable[str]) -> list[str]:
    """``needs`` with what each item brings, the brought items first."""
    order: list[str] = []

    def visit(name: str) -> None:
        for first in item(name).brings:
            visit(first)
        if name not in order:
            order.append(name)

    for name in sorted(needs):
        visit(name)
    return order


def needed_items(needs: Iterable[str], style: object) -> set[tuple]:
    """The cache keys that ``needs`` asks for under ``style``, with what the items bring."""
    keys = set()
    for name in _order(needs):
        entry = item(name)
        keys.add(entry.cache_key(*entry.from_style(style)))
    return keys


def nbytes_of(value: object, exclude: Iterable[np.ndarray] = ()) -> int:
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


def derive(mesh: MeshLike, needs: Iterable[str], style: object) -> Derivation:
    """Compute on ``mesh`` the items of ``needs`` (and what they bring) it does not hold yet,
    with the parameters ``style`` gives (crease angle, fe2003 parameters …); returns their cost
    in ms and bytes. A brought item goes first, so that, say, a Gouraud split's cost excludes
    the triangulation. ValueError for an unregistered item."""
    items = {}
    own = [a for a in (mesh.nodes, mesh.elements, mesh.parts, mesh.steps) if a is not None]
    for name in _order(needs):
        entry = item(name)
        parameters = entry.key(*entry.from_style(style))
        if (name, *parameters) in mesh.derived:
            continue
        start = time.perf_counter()
        value = _value(mesh, entry, parameters)
        ms = (time.perf_counter() - start) * 1e3
        # arrays of the items it brings are counted as their own items
        shared = own + [a for first in entry.brings for a in _arrays_of(mesh, first, style)]
        items[name] = (ms, nbytes_of(value, exclude=shared))
    return Derivation(items)


def _arrays_of(mesh, name: str, style) -> list[np.ndarray]:
    entry = item(name)
    value = mesh.derived.get(entry.cache_key(*entry.from_style(style)))
    return [] if value is None else [a for a in vars(value).values() if isinstance(a, np.ndarray)]


def derivation_cost(mesh: MeshLike, needs: Iterable[str], style: object) -> Derivation:
    """What deriving ``needs`` costs from nothing: :func:`derive` on a fresh copy of ``mesh``
    (same arrays, no cached items), so the mesh given keeps its caches untouched."""
    fresh = dataclasses.replace(mesh)
    return derive(fresh, needs, style)
