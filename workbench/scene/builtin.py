"""Built-in scenes by name, so every command and experiment runs without arguments.

``car``: the LS-DYNA car deck of the shared data; ``d3plot``: the shared d3plot result;
``semicylinders``: the es2008 benchmark (1 M triangles; ``quick`` gives a 64×64-per-sheet
version); ``panels``: generated stamped panels. A name that is not built in is read as a file.
"""

from __future__ import annotations

from pathlib import Path

from ..data import CAR_DECK, D3PLOT, shared_file
from .mesh import FEMesh

BUILTIN = ("car", "d3plot", "semicylinders", "panels")


def builtin_scene(name: str, quick: bool = False) -> FEMesh:
    """The built-in scene ``name`` (see the module docstring); FileNotFoundError if its data is absent."""
    from . import generators, io

    if name in ("car", "d3plot"):
        path = shared_file(CAR_DECK if name == "car" else D3PLOT)
        if path is None:
            raise FileNotFoundError(
                f"built-in scene {name!r} needs the shared data folder (set WORKBENCH_DATA to the folder "
                f"holding {CAR_DECK if name == 'car' else D3PLOT})"
            )
        return io.load(path)
    if name == "semicylinders":
        return generators.semicylinders(n=64 if quick else 250)
    if name == "panels":
        return generators.stamped_panels(26_284 if quick else 255_641)
    raise KeyError(f"no built-in scene {name!r}; built in: {', '.join(BUILTIN)}")


def load_scene(spec: str, quick: bool = False) -> FEMesh:
    """A built-in scene by name, else a mesh file read by :func:`workbench.scene.io.load`."""
    if spec in BUILTIN and not Path(spec).exists():
        return builtin_scene(spec, quick)
    from .io import load

    return load(spec)
