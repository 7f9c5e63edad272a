"""Writing the whole site at once: :func:`write_site` builds it in a hidden folder beside the
target (``.<name>.<pid>.<hex>.partial``) and only then puts it in the target's place with
renames, so a reader sees the old site or the new one, never half of one; a build that fails
removes its folder and leaves the old site as it was.

Layout of the site (every page in its top folder, every link relative, so it opens from disk)::

    index.html                       experiments and their claims
    experiment-<name>.html           claims, tables, Pareto plots, figures of one experiment
    history-<name>.html              its claims over the stored runs, change points marked
    runs.html, machines.html         every run (anchors run-<id>), every machine
    machine-<machine_id>.html        one machine's fingerprint and runs
    site.css, sort.js                the style sheet and the table sorter
    plots/*.png                      Pareto and history plots
    figures/<experiment>/...         copies of the experiments' figure files

Refused before anything is written (ValueError naming the path): a target that exists and is
not a folder or is a symbolic link (:func:`workbench.output.targets.output_folder`), and a
store holding no experiment run at quick or full size. What a build killed midway left beside
the target is cleaned up by the next (:func:`clean_dead_builds`).
"""

from __future__ import annotations

import glob
import os
import secrets
import shutil
from pathlib import Path
from urllib.parse import quote

from ..output.targets import output_folder
from ..results.store import ResultsStore, process_alive
from .assets import CSS, CSS_NAME, JS, JS_NAME
from .contents import Contents, OnceStore, gather
from .figures import experiment_figures
from .history import history_body, quantities
from .markup import experiment_page, history_page, machine_page, safe
from .pages import Extras, experiment_body, index_page, machine_body, machines_page, runs_page
from .plots import pareto_columns, pareto_plot


def _write(path: Path, text: str) -> None:
    path.write_text(text, encoding="utf-8")


def _experiment(staging: Path, store: OnceStore, contents: Contents, name: str,
                figures: Path) -> Extras:
    """Copy ``name``'s figures, draw its Pareto plots and write its history page (where a
    claim's column has a history) into ``staging``; what its page links to."""
    view = contents.experiments[name]
    shown = []
    for figure in experiment_figures(figures / name, frozenset(contents.runs)):
        target = staging / "figures" / safe(name) / figure.name
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(figure.path, target)
        shown.append((figure, quote(f"figures/{safe(name)}/{figure.name}")))
    paretos = {}
    for stored in view.tables:
        columns = pareto_columns(stored.rows)
        if columns is not None:
            png = f"pareto-{safe(name)}-{safe(stored.name)}.png"
            pareto_plot(staging / "plots" / png, stored.rows, *columns,
                        title=f"{name} / {stored.name}\n{columns[1]} against {columns[0]}")
            paretos[stored.name] = (f"plots/{png}", *columns)
    history = False
    if view.claims:
        claims = quantities(store, view, staging / "plots")
        history = any(q.histories for _, found in claims for q in found)
        if history:
            _write(staging / history_page(name), history_body(view, claims,
                                                              set(contents.machines)))
    return Extras(shown, paretos, history)


def build(staging: Path, store: ResultsStore | OnceStore, figures: Path) -> None:
    """Write every page, plot, figure and asset of ``store``'s site into the empty folder
    ``staging``, taking the experiments' figures from ``figures/<experiment>/``."""
    store = store if isinstance(store, OnceStore) else OnceStore(store)
    contents = gather(store)
    (staging / "plots").mkdir()
    _write(staging / CSS_NAME, CSS)
    _write(staging / JS_NAME, JS)
    extras = {name: _experiment(staging, store, contents, name, figures)
              for name in contents.experiments}
    for name, view in contents.experiments.items():
        _write(staging / experiment_page(name), experiment_body(contents, view, extras[name]))
    _write(staging / "runs.html", runs_page(contents, contents.stored_by))
    _write(staging / "machines.html", machines_page(contents))
    for machine_id in contents.machines:
        _write(staging / machine_page(machine_id), machine_body(contents, machine_id))
    _write(staging / "index.html", index_page(contents, extras))


def clean_dead_builds(out: Path) -> list[Path]:
    """Remove what builds of the site ``out`` that died left beside it (their
    ``.<name>.<pid>.<hex>.partial`` folders, and ``.old`` ones: an old site set aside is put
    back where ``out`` is missing, the build having died between its two renames). Folders of
    builds still running are left alone. Returns what was removed or put back."""
    done = []
    for entry in sorted(out.parent.glob(f".{glob.escape(out.name)}.*.*")):
        parts = entry.name[len(out.name) + 2:].split(".")
        if (len(parts) != 3 or parts[2] not in ("partial", "old") or not parts[0].isdigit()
                or (process_alive(int(parts[0])) and int(parts[0]) != os.getpid())
                or entry.is_symlink() or not entry.is_dir()):
            continue
        if parts[2] == "old" and not os.path.lexists(out):
            os.replace(entry, out)
        else:
            shutil.rmtree(entry, ignore_errors=True)
        done.append(entry)
    return done


def write_site(store: ResultsStore, out: str | os.PathLike[str],
               figures: str | os.PathLike[str] = "figures") -> Path:
    """Write the site of ``store`` into the folder ``out`` (made with its parents where
    missing, replaced whole where it exists), taking each experiment's figures from
    ``figures/<experiment>/``; returns the path of its ``index.html``. Refuses (ValueError)
    an ``out`` that exists and is a symbolic link or not a folder, and a store without an
    experiment run at quick or full size, before anything is written."""
    out = output_folder(out)
    snapshot = OnceStore(store)
    try:
        return _write_site(snapshot, out, Path(figures))
    finally:
        snapshot.close()


def _write_site(store: OnceStore, out: Path, figures: Path) -> Path:
    """:func:`write_site` from the snapshot ``store``."""
    gather(store)  # refuse an empty store before making anything (its answers are kept)
    parent = out.parent
    parent.mkdir(parents=True, exist_ok=True)
    clean_dead_builds(out)
    staging = parent / f".{out.name}.{os.getpid()}.{secrets.token_hex(4)}.partial"
    staging.mkdir()
    try:
        build(staging, store, figures)
        if os.path.lexists(output_folder(out)):
            old = parent / f".{out.name}.{os.getpid()}.{secrets.token_hex(4)}.old"
            os.replace(out, old)
            os.replace(staging, out)
            shutil.rmtree(old, ignore_errors=True)
        else:
            os.replace(staging, out)
    finally:
        shutil.rmtree(staging, ignore_errors=True)
    return out / "index.html"
