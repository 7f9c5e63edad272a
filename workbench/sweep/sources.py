"""The content key of a sweep point (:func:`point_key`): a hash over what decides its row, above
all the source files its path, the measurement and the scene's making read
(:func:`point_sources`), so that a cached row is used only while that code is unchanged."""

from __future__ import annotations

import hashlib
import inspect
import json
import re
from importlib import resources
from pathlib import Path

from .points import Point

PACKAGE = Path(__file__).resolve().parents[1]
_SHADER_NAME = re.compile(r'"([\w.-]+\.glsl)"')
_INCLUDE = re.compile(r'^\s*#include\s+"([^"]+)"\s*$', re.MULTILINE)
_DIGESTS: dict[tuple, str] = {}  # (path, size, mtime) -> sha256


def _file_digest(path: Path) -> str:
    """sha256 of a file's bytes, cached by path, size and modification time."""
    stat = path.stat()
    memo = (str(path), stat.st_size, stat.st_mtime_ns)
    digest = _DIGESTS.get(memo)
    if digest is None:
        digest = hashlib.sha256(path.read_bytes()).hexdigest()
        _DIGESTS[memo] = digest
    return digest


def glsl_folder() -> Path:
    """The folder of the workbench's shaders (the package ``workbench.glsl``)."""
    return Path(str(resources.files("workbench.glsl")))


def _shader_files(module_files: list[Path], glsl: Path) -> list[Path]:
    """The shaders named in the modules' source (as "name.glsl" literals) and, transitively,
    those they #include."""
    names = set()
    for module in module_files:
        names |= set(_SHADER_NAME.findall(module.read_text(encoding="utf-8")))
    todo, found = sorted(names), {}
    while todo:
        name = todo.pop()
        if name in found or not (glsl / name).is_file():
            continue
        found[name] = glsl / name
        todo += _INCLUDE.findall(found[name].read_text(encoding="utf-8"))
    return [found[n] for n in sorted(found)]


def package_modules(*names: str) -> set[Path]:
    """The source files of workbench modules named relative to the package, without ``.py``
    (``"paths/base"``, ``"algo/simplify"``): the module's file, or every ``.py`` file of a
    package folder (so that a module split into a package keeps its whole code in a key).
    FileNotFoundError names a module that is neither."""
    files = set()
    for name in names:
        module, folder = PACKAGE / f"{name}.py", PACKAGE / name
        if module.is_file():
            files.add(module)
        elif folder.is_dir():
            files |= set(folder.rglob("*.py"))
        else:
            raise FileNotFoundError(f"no workbench module or package {name!r} in {PACKAGE}")
    return files


# what every point's row depends on: the path protocol and the mesh paths' common code, the
# measurement function and the worker's side of a sweep point
POINT_MODULES = ("paths/base", "paths/colormap", "paths/mesh", "paths/drawdata", "paths/style",
                 "paths/backends", "measurement/rows", "sweep/points")
REFERENCE_MODULES = ("measurement/images",)
SIMPLIFIER_MODULES = ("algo/simplify", "algo/hausdorff", "references/simplifiers")
SOFTWARE_MODULES = ("paths/software", "algo/softraster")


def point_sources(point: Point, glsl_dir=None) -> dict[str, str]:
    """The source files whose text decides ``point``'s row, name → sha256 of the text: the
    modules of its path and of the reference path, :data:`POINT_MODULES` (``paths/base.py``,
    ``paths/colormap.py``, ``measurement/rows.py``, ``sweep/points.py`` …),
    ``measurement/images.py`` with a reference, the decimation, Hausdorff and simplifier
    modules with a simplifier, the software rasterizer with ``rasterizer = "software"``, the
    modules that make the scene and derive from it (:func:`_scene_modules`), and the shaders
    those path modules name, with their includes, from ``glsl_dir`` (default the workbench's
    glsl folder)."""
    from ..paths import path_class

    glsl = Path(glsl_dir) if glsl_dir is not None else glsl_folder()
    paths = [point.path] + ([point.reference] if point.reference else [])
    # the modules of the path classes and of every workbench class they derive from
    modules = {Path(inspect.getsourcefile(cls)).resolve() for name in paths
               for cls in path_class(name).__mro__ if cls.__module__.startswith("workbench.")}
    shaders = _shader_files(sorted(modules | package_modules("paths/base")), glsl)
    modules |= package_modules(*POINT_MODULES)
    if point.reference:
        modules |= package_modules(*REFERENCE_MODULES)
    if point.simplifier:
        modules |= package_modules(*SIMPLIFIER_MODULES)
    if point.rasterizer == "software":
        modules |= package_modules(*SOFTWARE_MODULES)
    modules |= _scene_modules(point.scene)
    sources = {f"workbench/{m.relative_to(PACKAGE).as_posix()}": _file_digest(m)
               for m in sorted(modules)}
    sources.update({f"glsl/{s.name}": _file_digest(s) for s in shaders})
    return sources


def _scene_modules(spec: str) -> set[Path]:
    """The modules that make scene ``spec`` and what the paths derive from it: the built-in
    scenes with the spacetime builders, the generators or the readers, and the derived-data
    modules."""
    modules = package_modules("scene/mesh", "scene/derived", "scene/crease", "scene/needs",
                              "scene/builtin")
    name = spec.split(":")[0]
    if name == "spacetime" and not Path(spec).is_file():
        return modules | package_modules("algo/spacetime")
    if name in ("semicylinders", "panels") and not Path(spec).is_file():
        return modules | package_modules("scene/generators")
    return modules | package_modules("scene/readers", "scene/solids")


def scene_digest(spec: str) -> str | None:
    """sha256 of the scene's file: the mesh file, or the shared data file of ``car`` and
    ``d3plot``; None for a generated scene."""
    from ..data import CAR_DECK, D3PLOT, shared_file

    if Path(spec).is_file():
        return _file_digest(Path(spec).resolve())
    data = {"car": CAR_DECK, "d3plot": D3PLOT}.get(spec)
    found = shared_file(data) if data is not None else None
    return None if found is None else _file_digest(found)


def point_key(point: Point, renderer: str, *, glsl_dir=None) -> str:
    """The content key of ``point`` drawn on ``renderer``: sha256 (hex) over the workbench
    version, :func:`point_sources`, the scene spec and :func:`scene_digest`, the point's
    parameters (quick flag and repeats included) and the renderer string."""
    from .. import __version__

    payload = dict(version=__version__, sources=point_sources(point, glsl_dir),
                   scene=point.scene, scene_file=scene_digest(point.scene),
                   params=point.params(), renderer=renderer)
    return hashlib.sha256(json.dumps(payload, sort_keys=True).encode()).hexdigest()
