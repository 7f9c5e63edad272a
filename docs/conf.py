"""Sphinx configuration: the guide pages (Markdown, through MyST) and the API reference,
generated from the docstrings of every module of ``workbench`` on each build
(``api.rst``: autosummary, recursive), so that a new module appears without editing the docs.

Build: ``.venv/bin/python -m sphinx -W --keep-going -b html docs docs/_build/html``.
"""

from __future__ import annotations

import os
import sys
from importlib import metadata

sys.path.insert(0, os.path.abspath(".."))

project = "workbench"
author = "workbench authors"
copyright = "the workbench authors, BSD-3-Clause"
release = metadata.version("workbench")
version = release

extensions = [
    "sphinxarg.ext",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.napoleon",
    "sphinx.ext.viewcode",
    "myst_parser",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
templates_path = ["_templates"]
exclude_patterns = ["_build", "api/generated", "*.ipynb", "Thumbs.db", ".DS_Store"]


def _drop_stale_pages(folder: str = "api") -> None:
    """Delete the generated page of every module that no longer exists (a module moved or
    removed since the last build), which autosummary would otherwise leave to fail its import."""
    import importlib.util

    if not os.path.isdir(folder):
        return
    for page in os.listdir(folder):
        name, ext = os.path.splitext(page)
        if ext != ".rst":
            continue
        try:
            found = importlib.util.find_spec(name) is not None
        except (ImportError, ValueError):
            found = False
        if not found:
            os.remove(os.path.join(folder, page))


_drop_stale_pages()

# the API reference: every module of the package, one page each, written at build time
autosummary_generate = True
autosummary_ignore_module_all = True
autodoc_member_order = "bysource"
autodoc_typehints = "signature"
autodoc_preserve_defaults = True
# undocumented public members too (dataclass and NamedTuple fields: ``Slice.outer``)
autodoc_default_options = {"show-inheritance": True, "undoc-members": True}

myst_heading_anchors = 3
myst_enable_extensions = ["colon_fence"]

html_theme = "furo"
html_title = f"workbench {release}"

# Each object is documented once, in the module that defines it: a package's page shows its
# docstring (the map of its modules) and links the modules, not the names it re-exports. A
# reference to a re-exported name (``workbench.paths.Style``) is resolved to the defining module
# (``workbench.paths.style.Style``) by :func:`_resolve_reexport`.
autodoc_default_options["ignore-module-all"] = True

# Broken references into the package fail the build: every fully qualified ``workbench.…``
# target must exist. Names of other libraries (numpy, moderngl, the standard library …) are not
# checked (their inventories are not fetched: the build runs offline), nor are unqualified names
# in signatures, which autodoc takes as written.
nitpicky = True
nitpick_ignore_regex = [
    (r"py:.*", r"(?!workbench\.).*"),
    # private names (``_gather``, ``_Query``) and type variables (``T``) have no page
    (r"py:.*", r"workbench\.(.*\.)?(_\w*|[A-Z])"),
]


def _documented_name(target: str, domain) -> str | None:
    """The documented name of the object ``target`` (``workbench.pkg.Name``) imports as: the
    module that defines it and its qualified name (``workbench.pkg.module.Name``); for data,
    which knows no module, the one documented name below ``workbench`` that holds the very same
    object. None where ``target`` does not import, or names nothing documented."""
    import importlib

    module_name, _, attr = target.rpartition(".")
    obj, rest = None, []
    while module_name:
        try:
            obj = importlib.import_module(module_name)
            break
        except ImportError:
            module_name, _, head = module_name.rpartition(".")
            rest.insert(0, head)
        except Exception:  # a module that fails to import is autodoc's warning, not ours
            return None
    if obj is None:
        return None
    try:
        for name in [*rest, attr]:
            obj = getattr(obj, name)
    except AttributeError:
        return None
    defined = getattr(obj, "__module__", None)
    qualname = getattr(obj, "__qualname__", None)
    if isinstance(obj, type(importlib)):
        defined, qualname = obj.__name__, None
    elif not (isinstance(defined, str) and isinstance(qualname, str)):
        same = []
        for name in domain.objects:
            holder, _, last = name.rpartition(".")
            if last == attr and name.startswith("workbench."):
                try:
                    if getattr(importlib.import_module(holder), last) is obj:
                        same.append(name)
                except (ImportError, AttributeError):
                    continue
        if len(same) != 1:
            return None
        defined, qualname = same[0].rpartition(".")[0], attr
    if not isinstance(defined, str) or not defined.startswith("workbench."):
        return None
    return f"{defined}.{qualname}" if qualname else defined


def _resolve_reexport(app, env, node, contnode):
    """A ``py`` reference that Sphinx did not find, resolved the way Python would: a fully
    qualified ``workbench.pkg.Name`` that ``pkg`` re-exports from one of its modules, or a short
    name written in a docstring or signature of module ``m`` (``:func:`section_planes``` in a
    package's notes, ``Camera`` imported under ``TYPE_CHECKING``) that ``m`` defines or
    imports; resolved to the documented name. None where neither applies."""
    target = node.get("reftarget", "")
    if node.get("refdomain") != "py" or not target or target.startswith("."):
        return None
    module, cls = node.get("py:module"), node.get("py:class")
    if target.startswith("workbench."):
        candidates = [target]
    elif module and module.startswith("workbench."):
        candidates = [f"{module}.{cls}.{target}" if cls else None, f"{module}.{target}",
                      _bound_name(module, target)]
    else:
        return None
    domain = env.get_domain("py")
    for candidate in filter(None, candidates):
        canonical = _documented_name(candidate, domain)
        if canonical is None or canonical == target:
            continue
        found = domain.resolve_xref(env, node["refdoc"], app.builder, node["reftype"],
                                    canonical, node, contnode)
        if found is not None:
            return found
    return None


def _bound_name(modname: str, name: str) -> str | None:
    """The full name that ``name`` (its first component) is bound to by an import in module
    ``modname``'s source, ``TYPE_CHECKING`` imports included; None where no import binds it."""
    import ast
    import importlib.util

    head, _, tail = name.partition(".")
    try:
        spec = importlib.util.find_spec(modname)
    except (ImportError, ValueError):
        return None
    if spec is None or not spec.origin or not spec.origin.endswith(".py"):
        return None
    with open(spec.origin, encoding="utf-8") as source:
        tree = ast.parse(source.read())
    package = modname if spec.submodule_search_locations else modname.rpartition(".")[0]
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parts = package.split(".")
                parts = parts[:len(parts) - node.level + 1]
                base = ".".join([*parts, base] if base else parts)
            for alias in node.names:
                if (alias.asname or alias.name) == head:
                    return ".".join(p for p in (base, alias.name, tail) if p)
        elif isinstance(node, ast.Import):
            for alias in node.names:
                if alias.asname == head:
                    return ".".join(p for p in (alias.name, tail) if p)
    return None


def _canonical(name: str) -> str:
    """``name`` (``workbench.gl.Camera``) as the module that defines the object names it
    (``workbench.gl.camera.Camera``); ``name`` itself where it cannot be imported."""
    import importlib

    module_name, _, attr = name.rpartition(".")
    try:
        obj = getattr(importlib.import_module(module_name), attr)
    except (ImportError, AttributeError, ValueError):
        return name
    defined, qualname = getattr(obj, "__module__", None), getattr(obj, "__qualname__", None)
    return f"{defined}.{qualname}" if defined and qualname else name


def _common_prefix(a: str, b: str) -> int:
    """How many leading dotted components ``a`` and ``b`` share."""
    n = 0
    for x, y in zip(a.split("."), b.split(".")):
        if x != y:
            break
        n += 1
    return n


def _python_domain():
    """The Python domain, resolving a short name that several objects share the way Python
    does: to what the referring module imports under that name (signatures are written with
    the names a module imports, often under ``TYPE_CHECKING``), else to the candidate nearest
    the referring module (``:mod:`pipeline``` in ``workbench.algo.softraster.kernels`` is
    ``workbench.algo.softraster.pipeline``)."""
    from sphinx.domains.python import PythonDomain

    class Domain(PythonDomain):
        def find_obj(self, env, modname, classname, name, type, searchmode=0):
            matches = super().find_obj(env, modname, classname, name, type, searchmode)
            if len(matches) < 2 or not modname:
                return matches
            bound = _bound_name(modname, name)
            if bound is not None:
                wanted = {bound, _canonical(bound)}
                chosen = [m for m in matches if m[0] in wanted]
                if len(chosen) == 1:
                    return chosen
            nearness = [_common_prefix(modname, m[0]) for m in matches]
            best = max(nearness)
            chosen = [m for m, n in zip(matches, nearness) if n == best]
            return chosen if len(chosen) == 1 else matches

    return Domain


def _readme_links():
    """A post-transform that sends a page's link to ``../README.md`` to the front page, which
    includes the README (``index.md``), before MyST resolves links."""
    from sphinx.addnodes import pending_xref
    from sphinx.transforms.post_transforms import SphinxPostTransform

    class ReadmeLinks(SphinxPostTransform):
        default_priority = 5  # before MyST's reference resolver

        def run(self, **kwargs):
            for node in self.document.findall(pending_xref):
                target = str(node.get("reftarget", ""))
                if (node.get("reftype") == "myst" and target.rpartition("/")[2] == "README"
                        and target not in self.env.all_docs):
                    node["reftarget"] = "index"

    return ReadmeLinks


def setup(app):
    """Register the re-export resolver, the Python domain that resolves shared short names
    and the README link transform."""
    app.connect("missing-reference", _resolve_reexport)
    app.add_domain(_python_domain(), override=True)
    app.add_post_transform(_readme_links())
