"""Built-in scenes by name, so every command and experiment runs without arguments.

Built-in scenes are a registry, like render paths and experiments: a function decorated with
:func:`builtin` makes the scene of one name. This module registers the FE meshes:

* ``car`` — the LS-DYNA car deck of the shared data; ``d3plot`` — the shared d3plot result;
* ``crash[:S]`` — the car through a synthetic frontal crush of S states (default 8), its rigid
  parts held still, with node field ``displacement`` and element field ``plastic_strain``;
  ``crash_eroded[:S]`` the same with erosion (element field ``alive``: a shell whose plastic
  strain reaches :data:`CRASH_FAILURE_STRAIN` is deleted from that state on);
* ``semicylinders[:N]`` — the es2008 benchmark, N×N quads per sheet (default 250: 1 M
  triangles; 64 quick);
* ``panels[:Q]`` — generated stamped panels, about Q quads.

Other packages register theirs in modules named by the ``workbench.scenes`` entry points
(``pyproject.toml``), imported the first time a name is looked up: the st2005 spacetime scenes
``spacetime:radial[:N]`` and ``spacetime:bar`` come from
:mod:`workbench.algo.spacetime.scene` that way. A name that is not built in is read as a file.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass
from functools import lru_cache
from importlib import metadata
from pathlib import Path
from typing import TYPE_CHECKING, TypeVar

from ..data import CAR_DECK, D3PLOT, shared_file
from .protocol import Scene

if TYPE_CHECKING:
    from .mesh import FEMesh

ENTRY_POINTS = "workbench.scenes"

# a scene's make(size, quick), kept with its own signature by the decorator
_Make = TypeVar("_Make", bound=Callable[[int | None, bool], Scene])


@dataclass(frozen=True)
class BuiltinScene:
    """A registered scene: ``make(size, quick)`` returns it; ``sized`` says whether it takes
    ``name:SIZE``; ``description`` is one line for listings."""

    name: str
    make: Callable[[int | None, bool], Scene]
    description: str
    sized: bool


SCENES: dict[str, BuiltinScene] = {}
_discovered = False


def builtin(name: str, description: str, *,
            sized: bool = False) -> Callable[[_Make], _Make]:
    """Decorator registering ``make(size, quick)`` as built-in scene ``name``; ``size`` is None
    unless the scene is ``sized`` and the spec gave one. Returns the function unchanged."""

    def register(make: _Make) -> _Make:
        SCENES[name] = BuiltinScene(name, make, description, sized)
        return make

    return register


def discover() -> dict[str, BuiltinScene]:
    """Import the modules named by the ``workbench.scenes`` entry points (they register on
    import), once; returns the registry."""
    global _discovered
    if not _discovered:
        _discovered = True
        for entry in metadata.entry_points(group=ENTRY_POINTS):
            entry.load()
    return SCENES


def scene_names() -> tuple[str, ...]:
    """Every built-in scene name, sorted."""
    return tuple(sorted(discover()))


def builtin_scene(name: str, quick: bool = False, size: int | None = None) -> Scene:
    """The built-in scene ``name`` (see the module docstring), ``size`` its size parameter
    where it takes one; KeyError for an unknown name, ValueError for a size it does not take,
    FileNotFoundError if its data is absent."""
    entry = discover().get(name)
    if entry is None:
        raise KeyError(f"no built-in scene {name!r}; built in: {', '.join(scene_names())}")
    if size is not None and not entry.sized:
        raise ValueError(f"built-in scene {name!r} takes no size")
    return entry.make(size, quick)


def parse_scene_spec(spec: str) -> tuple[str, int | None] | None:
    """(name, size) when ``spec`` names a built-in scene (``car``, ``semicylinders:32``,
    ``spacetime:radial:20`` …), None otherwise; ValueError for a size that is not a positive
    integer, KeyError for an unknown name in a family of built-in names (``spacetime:x``)."""
    scenes = discover()
    if spec in scenes:
        return spec, None
    head, _, tail = spec.rpartition(":")
    if head in scenes and scenes[head].sized:
        try:
            size = int(tail)
        except ValueError:
            raise ValueError(f"scene {spec!r}: the size after ':' must be an integer") from None
        if size <= 0:
            raise ValueError(f"scene {spec!r}: the size must be positive")
        return head, size
    family = spec.split(":", 1)[0] + ":"
    kin = [n for n in scenes if n.startswith(family)]
    if ":" in spec and kin and not Path(spec).exists():
        raise KeyError(f"no {family[:-1]} scene {spec!r}; built in: {', '.join(sorted(kin))} "
                       f"(with an optional :N)")
    return None


def load_scene(spec: str, quick: bool = False, all_faces: bool = False) -> Scene:
    """A built-in scene by name (see :func:`parse_scene_spec`), else a mesh file read by
    :func:`workbench.scene.readers.load` (``all_faces``: every face of its solids, not only
    their boundary); an existing file wins over a built-in name."""
    if not Path(spec).exists():
        parsed = parse_scene_spec(spec)
        if parsed is not None:
            return builtin_scene(parsed[0], quick, parsed[1])
    from .readers import load

    return load(spec, all_faces=all_faces)


def load_mesh(spec: str, quick: bool = False, all_faces: bool = False) -> FEMesh:
    """:func:`load_scene` for commands that take an FE mesh: ValueError naming the kind of a
    scene that is not one (a spacetime scene, say)."""
    scene = load_scene(spec, quick, all_faces)
    if scene.kind != "mesh":
        raise ValueError(f"{spec!r} is a {scene.kind} scene; this takes an FE mesh (a mesh file, "
                         f"car, crash[:S], crash_eroded[:S], d3plot, semicylinders[:N] or "
                         f"panels[:Q])")
    return scene


def fresh_scene(spec: str, quick: bool = False) -> Scene:
    """Scene ``spec`` as nobody has drawn it yet, so that what a path derives is computed (and
    counted) anew: loaded once per process (:func:`load_scene`), an FE mesh is handed out as a
    new instance sharing the loaded arrays without their derived caches; other scenes derive
    nothing and no path changes them, so the loaded one is handed out as it is."""
    scene = loaded_scene(spec, quick)
    if scene.kind == "mesh":
        return dataclasses.replace(scene, node_fields=dict(scene.node_fields),
                                   element_fields=dict(scene.element_fields))
    return scene


@lru_cache(maxsize=4)
def loaded_scene(spec: str, quick: bool = False) -> Scene:
    """Scene ``spec`` loaded once per process (the last four specs kept) and shared: what it
    derives is kept for every later caller, so treat it as read-only."""
    return load_scene(spec, quick)


# ------------------------------------------------------------------------- the FE meshes
def _shared_mesh(name: str, relative: Path):
    path = shared_file(relative)
    if path is None:
        raise FileNotFoundError(f"built-in scene {name!r} needs the shared data folder (set "
                                f"WORKBENCH_DATA to the folder holding {relative})")
    from .readers import load

    return load(path)


@builtin("car", "the shared LS-DYNA car deck")
def car(size: int | None, quick: bool) -> FEMesh:
    return _shared_mesh("car", CAR_DECK)


@builtin("d3plot", "the shared d3plot result")
def d3plot(size: int | None, quick: bool) -> FEMesh:
    return _shared_mesh("d3plot", D3PLOT)


@builtin("crash", "the car crushed from the front over S states (default 8)", sized=True)
def crash(size: int | None, quick: bool) -> FEMesh:
    from .generators import crash_sequence

    car = _shared_mesh("crash", CAR_DECK)
    rigid = [part for part, title in car.part_names.items() if "rigid" in title.lower()]
    crash = crash_sequence(car, steps=size or 8, still_parts=rigid)
    crash.name = "crash"
    return crash


CRASH_FAILURE_STRAIN = 2.5  # crash_eroded: about 2 % of the shells fail by the last state


@builtin("crash_eroded", "the crash with erosion: a shell whose plastic strain reaches "
                         f"{CRASH_FAILURE_STRAIN} is deleted from that state on", sized=True)
def crash_eroded(size: int | None, quick: bool) -> FEMesh:
    from .generators import crash_sequence

    car = _shared_mesh("crash_eroded", CAR_DECK)
    rigid = [part for part, title in car.part_names.items() if "rigid" in title.lower()]
    crash = crash_sequence(car, steps=size or 8, still_parts=rigid,
                           failure_strain=CRASH_FAILURE_STRAIN)
    crash.name = "crash_eroded"
    return crash


@builtin("semicylinders", "the es2008 benchmark, N×N quads per sheet (default 250: 1 M "
                          "triangles)", sized=True)
def semicylinders(size: int | None, quick: bool) -> FEMesh:
    from .generators import semicylinders

    return semicylinders(n=size or (64 if quick else 250))


@builtin("panels", "generated stamped sheet-metal parts, about Q quads", sized=True)
def panels(size: int | None, quick: bool) -> FEMesh:
    from .generators import stamped_panels

    return stamped_panels(size or (26_284 if quick else 255_641))
