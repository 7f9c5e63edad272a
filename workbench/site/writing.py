"""Writing the whole site at once: :func:`write_site` builds it in a hidden folder beside the
target and only then puts it in the target's place with renames
(:mod:`workbench.output.swap`), so a reader sees the old site or the new one, never half of
one; a build that fails removes its folder and leaves the old site as it was.

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
the target is cleaned up by the next (:func:`~workbench.output.swap.clean_dead_swaps`).
"""

from __future__ import annotations

import os
import shutil
from pathlib import Path
from urllib.parse import quote

from ..output.swap import clean_dead_swaps, staging_folder, swap_in
from ..output.targets import output_folder
from ..results.store import ResultsStore
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
    clean_dead_swaps(out)
    staging = staging_folder(out)
    try:
        build(staging, store, figures)
        swap_in(staging, out)
    finally:
        shutil.rmtree(staging, ignore_errors=True)
    return out / "index.html"
