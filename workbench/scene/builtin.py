"""Built-in scenes by name, so every command and experiment runs without arguments.

``car``: the LS-DYNA car deck of the shared data; ``d3plot``: the shared d3plot result;
``semicylinders``: the es2008 benchmark (1 M triangles; ``quick`` gives a 64×64-per-sheet
version, ``semicylinders:N`` N×N quads per sheet); ``panels``: generated stamped panels
(``panels:Q`` about Q quads); ``spacetime:radial`` and ``spacetime:bar`` (``spacetime:radial:N``
with N cells per side): the st2005 spacetime scenes of :mod:`workbench.scene.spacetime`. A name
that is not built in is read as a file.
"""

from __future__ import annotations

from pathlib import Path

from ..data import CAR_DECK, D3PLOT, shared_file

BUILTIN = ("car", "d3plot", "semicylinders", "panels", "spacetime:radial", "spacetime:bar")
SIZED = ("semicylinders", "panels", "spacetime:radial", "spacetime:bar")  # take ":size"


def builtin_scene(name: str, quick: bool = False, size: int | None = None):
    """The built-in scene ``name`` (see the module docstring), ``size`` its size parameter
    where it takes one; FileNotFoundError if its data is absent."""
    from . import generators, readers

    if name.startswith("spacetime:"):
        from .spacetime import spacetime_scene

        return spacetime_scene(name.split(":", 1)[1], cells=size, quick=quick)
    if size is not None and name not in SIZED:
        raise ValueError(f"built-in scene {name!r} takes no size")
    if name in ("car", "d3plot"):
        path = shared_file(CAR_DECK if name == "car" else D3PLOT)
        if path is None:
            raise FileNotFoundError(
                f"built-in scene {name!r} needs the shared data folder (set WORKBENCH_DATA to the folder "
                f"holding {CAR_DECK if name == 'car' else D3PLOT})"
            )
        return readers.load(path)
    if name == "semicylinders":
        return generators.semicylinders(n=size or (64 if quick else 250))
    if name == "panels":
        return generators.stamped_panels(size or (26_284 if quick else 255_641))
    raise KeyError(f"no built-in scene {name!r}; built in: {', '.join(BUILTIN)}")


def parse_scene_spec(spec: str) -> tuple[str, int | None] | None:
    """(name, size) when ``spec`` names a built-in scene (``car``, ``semicylinders:32``,
    ``spacetime:radial:20`` …), None otherwise; ValueError for a size that is not a positive
    integer."""
    name, size = spec, None
    head, _, tail = spec.rpartition(":")
    if spec.startswith("spacetime:") and spec not in BUILTIN and head not in SIZED:
        known = ", ".join(n for n in BUILTIN if n.startswith("spacetime:"))
        raise KeyError(f"no spacetime scene {spec!r}; built in: {known} (with an optional :N)")
    if spec not in BUILTIN and head in SIZED:
        name = head
        try:
            size = int(tail)
        except ValueError:
            raise ValueError(f"scene {spec!r}: the size after ':' must be an integer") from None
        if size <= 0:
            raise ValueError(f"scene {spec!r}: the size must be positive")
    return (name, size) if name in BUILTIN else None


def load_scene(spec: str, quick: bool = False, all_faces: bool = False):
    """A built-in scene by name (see :func:`parse_scene_spec`), else a mesh file read by
    :func:`workbench.scene.load` (``all_faces``: every face of its solids, not only their
    boundary); an existing file wins over a built-in name."""
    parsed = parse_scene_spec(spec)
    if parsed is not None and not Path(spec).exists():
        return builtin_scene(parsed[0], quick, parsed[1])
    from .readers import load

    return load(spec, all_faces=all_faces)
