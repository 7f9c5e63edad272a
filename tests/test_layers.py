"""The shape of the package: every layer imports only downward, no module imports another in a
circle, and no private name is imported across packages.

Layers, bottom to top: ``gl`` (with the shaders, ``glsl``), ``scene`` (with ``data``) →
``algo`` → ``paths`` → ``measurement`` and ``output`` → ``references``, ``results``,
``distributed`` and ``animation`` → ``experiment`` → ``sweep`` and ``site`` (the static
results site) → ``reliability`` → ``cli``
(beside it the live Jupyter view, ``viewer``), and the experiment scripts (``reproductions``)
on top. A module
may import its own layer and the layers below. Imports inside functions count: a lazy import
that points up, or closes a circle, is the same coupling. The one exception is named in
``ROOT_FACADE``: the package root (layer 0, since ``sweep`` reads its ``__version__``) hands
out ``workbench.load`` and ``workbench.render`` (``paths.facade``), ``workbench.measure``
(``measurement.rows``) and ``workbench.view`` (the viewer) through a module ``__getattr__``;
those edges still count for the circle check. No module outside ``paths`` prepares a path by
hand: a call of ``.prepare(`` (a path's or a backend's) belongs in
:mod:`workbench.paths.drawing`, which everything else goes through. The checks are tested on a
small package with the faults they exist to catch.
"""

import ast
import textwrap
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
LAYERS = {"gl": 0, "scene": 0, "data": 0, "glsl": 0, "__init__": 0, "algo": 1, "paths": 2,
          "measurement": 3, "output": 3, "references": 4, "results": 4, "distributed": 4,
          "animation": 4, "experiment": 5, "sweep": 6, "site": 6, "reliability": 7, "cli": 8,
          "viewer": 8, "reproductions": 9}
# upward imports allowed by name: the package root's lazy facade (``workbench.load``,
# ``render``, ``measure``, ``view``)
ROOT_FACADE = {("workbench", "workbench.paths.facade"), ("workbench", "workbench.measurement.rows"),
               ("workbench", "workbench.viewer")}
PACKAGE_DIRS = {"workbench": ROOT / "workbench"}


def modules_of(package: str, folder: Path) -> dict[str, Path]:
    """Every module of ``package`` (in ``folder``) by dotted name."""
    found = {}
    for path in sorted(folder.rglob("*.py")):
        parts = path.relative_to(folder).with_suffix("").parts
        if parts[-1] == "__init__":
            parts = parts[:-1]
        found[".".join((package, *parts))] = path
    return found


def imports_of(module: str, path: Path, known: set[str]) -> set[str]:
    """The modules of ``known`` that ``module`` (its source at ``path``) imports, at module
    level or inside functions: for ``from X import name`` the module ``X.name`` where it is one,
    else ``X``."""
    is_package = path.name == "__init__.py"
    parent = module if is_package else module.rsplit(".", 1)[0]
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = parent.rsplit(".", node.level - 1)[0] if node.level > 1 else parent
                target = f"{base}.{node.module}" if node.module else base
            else:
                target = node.module or ""
            for alias in node.names:
                sub = f"{target}.{alias.name}"
                found.add(sub if sub in known else target)
        elif isinstance(node, ast.Import):
            found |= {alias.name for alias in node.names}
    return {name for name in found if name in known and name != module}


def layer_of(module: str) -> str:
    """The layer of a dotted module name (``workbench.paths.mesh`` → ``paths``)."""
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else "__init__"


def import_graph(dirs: dict[str, Path]) -> dict[str, set[str]]:
    modules = {}
    for package, folder in dirs.items():
        modules.update(modules_of(package, folder))
    known = set(modules)
    return {name: imports_of(name, path, known) for name, path in modules.items()}


def upward_imports(graph: dict[str, set[str]], layers: dict[str, int]) -> list[str]:
    """``"a imports b (x over y)"`` for every import of a higher layer; a module outside every
    layer is reported too."""
    found = []
    for module, targets in sorted(graph.items()):
        layer = layer_of(module)
        if layer not in layers:
            found.append(f"{module} belongs to no layer")
            continue
        for target in sorted(targets):
            other = layer_of(target)
            if layers.get(other, -1) > layers[layer]:
                found.append(f"{module} imports {target} ({other} over {layer})")
    return found


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The import circles of ``graph``: one module list per strongly connected set of more than
    one module (Tarjan)."""
    index, low, stack, on_stack, found = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in sorted(graph.get(v, ())):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                found.append(sorted(component))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return found


def prepares_by_hand(dirs: dict[str, Path]) -> list[str]:
    """``"module:line"`` for every call of ``X.prepare(...)`` in a module outside the ``paths``
    layer: a path prepared by hand instead of through ``workbench.paths.drawing``."""
    found = []
    for package, folder in dirs.items():
        for module, path in sorted(modules_of(package, folder).items()):
            if layer_of(module) == "paths":
                continue
            for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
                if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) \
                        and node.func.attr == "prepare":
                    found.append(f"{module}:{node.lineno}")
    return found


@pytest.fixture(scope="module")
def graph():
    return import_graph(PACKAGE_DIRS)


def test_every_layer_imports_only_downward(graph):
    checked = {module: {t for t in targets if (module, t) not in ROOT_FACADE}
               for module, targets in graph.items()}
    assert upward_imports(checked, LAYERS) == []


def test_no_path_prepared_outside_paths():
    assert prepares_by_hand(PACKAGE_DIRS) == []


def test_the_prepare_check_finds_a_path_prepared_by_hand(tmp_path):
    """The check itself: a path prepared in ``paths`` passes, one prepared in the CLI (inside
    a function, through any name) is found."""
    root = tmp_path / "workbench"
    files = {
        "__init__.py": "",
        "paths/__init__.py": "",
        "paths/drawing.py": "def prepared(backend, path):\n    backend.prepare(path)\n",
        "cli/__init__.py": "",
        "cli/render.py": "from ..paths.drawing import prepared\n\n"
                         "def run(ctx, path, scene):\n    path.draw()\n"
                         "    path.prepare(ctx, scene, None)\n",
    }
    for name, text in files.items():
        (root / name).parent.mkdir(parents=True, exist_ok=True)
        (root / name).write_text(text)
    assert prepares_by_hand({"workbench": root}) == ["workbench.cli.render:5"]


def test_no_import_cycles(graph):
    assert cycles(graph) == []


def test_no_private_names_imported_across_packages():
    offenders = []
    for path in ROOT.joinpath("workbench").rglob("*.py"):
        package = ".".join(path.relative_to(ROOT).parent.parts)
        for node in ast.walk(ast.parse(path.read_text())):
            if not isinstance(node, ast.ImportFrom):
                continue
            if node.level:
                base = package.rsplit(".", node.level - 1)[0] if node.level > 1 else package
                target = f"{base}.{node.module}" if node.module else base
            else:
                target = node.module
            private = [a.name for a in node.names if a.name.startswith("_")
                       and not a.name.startswith("__")]
            if private and target.rsplit(".", 1)[0] != package:
                offenders.append(f"{path.relative_to(ROOT)}: {target} {private}")
    assert offenders == []


def test_the_checks_find_an_upward_import_and_a_cycle(tmp_path):
    """The checks themselves, on a package with one upward import (algo → paths, inside a
    function) and one circle (scene.a → scene.b → scene.a)."""
    root = tmp_path / "workbench"
    files = {
        "__init__.py": "",
        "scene/__init__.py": "",
        "scene/a.py": "from . import b\n",
        "scene/b.py": "def f():\n    from .a import thing\n",
        "algo/__init__.py": "",
        "algo/x.py": "from ..scene import a\n\ndef g():\n    from ..paths.p import draw\n",
        "paths/__init__.py": "",
        "paths/p.py": "from ..algo.x import g\n",
        "extra.py": "",
    }
    for name, text in files.items():
        (root / name).parent.mkdir(parents=True, exist_ok=True)
        (root / name).write_text(textwrap.dedent(text))
    found = import_graph({"workbench": root})
    assert upward_imports(found, LAYERS) == [
        "workbench.algo.x imports workbench.paths.p (paths over algo)",
        "workbench.extra belongs to no layer"]
    assert sorted(cycles(found)) == [["workbench.algo.x", "workbench.paths.p"],
                                     ["workbench.scene.a", "workbench.scene.b"]]
