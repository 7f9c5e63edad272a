"""The HTML of the site's pages (each a str; :mod:`workbench.site.writing` writes them): the
index of experiments with their claims, one page per experiment (its claims, its tables with
their legends and Pareto plots, its figures inline), the runs, the machines and one page per
machine with its fingerprint.

Every value from the store is escaped; every link is relative (see
:mod:`workbench.site.markup`).
"""

from __future__ import annotations

from dataclasses import dataclass
from html import escape
from typing import Any

from ..experiment.report import ran_on
from ..results.provenance import MACHINE_FIELDS
from .contents import Contents, ExperimentView
from .figures import FigureFile
from .markup import (
    claim_anchor,
    experiment_page,
    history_page,
    legend,
    link,
    machine_page,
    page,
    run_anchor,
    run_link,
    table,
)


@dataclass(frozen=True)
class Extras:
    """What the writer made for an experiment's page: the site-relative paths of its figures
    (by figure name), of each table's Pareto plot (by table name), and whether it has a
    history page."""

    figures: list[tuple[FigureFile, str]]
    paretos: dict[str, tuple[str, str, str]]  # table -> (png, time column, error column)
    history: bool


def _machine_link(machine_id: str | None, contents: Contents) -> str:
    if machine_id is None:
        return "no machine"
    if machine_id not in contents.machines:
        return escape(machine_id[:12])
    return link(machine_page(machine_id), machine_id[:12])


def _claims(view: ExperimentView, history: bool = False) -> str:
    """The claims' sentences as a list; with ``history`` each claim's last sentence links to
    the claim's section of the history page."""
    items = []
    for claim in view.claims:
        for i, sentence in enumerate(claim.sentences):
            more = (" " + link(f"{history_page(view.name)}#{claim_anchor(claim.claim.quantity)}",
                               "history") if history and i == len(claim.sentences) - 1 else "")
            items.append(f"<li>{escape(sentence)}{more}</li>")
    if not items:
        return '<span class="note">no claims declared</span>'
    return "<ul>" + "".join(items) + "</ul>"


def index_page(contents: Contents, extras: dict[str, Extras]) -> str:
    """The index: one row per experiment with its claims (each ratio with its interval), the
    run they come from, its machine, commit and size, links to its page and history."""
    rows = []
    for name, view in contents.experiments.items():
        s, extra = view.source, extras[name]
        rows.append({
            "experiment": link(experiment_page(name), name)
            + (f"<br>{link(history_page(name), 'history')}" if extra.history else ""),
            "paper": view.paper or "", "claims": _claims(view, extra.history),
            "figures": len(extra.figures), "tables": len(view.tables),
            "run": run_link(s.run_id), "machine": _machine_link(view.machine_id, contents),
            "ran on": escape(ran_on(s)), "commit": escape((s.commit or "no commit")[:10]),
            "size": escape(s.size), "started": escape(s.started[:19])})
    body = (f'<p class="note">Written by <code>workbench results report --html</code> from the '
            f"results store <code>{escape(str(contents.root))}</code>: per experiment its "
            "latest stored run (full size where there is one, else quick). A ratio measured "
            "interleaved carries its 95 % interval.</p>"
            + table(rows, ["experiment", "paper", "claims", "run", "machine", "ran on",
                           "commit", "size", "started", "tables", "figures"],
                    raw=("experiment", "claims", "run", "machine", "ran on", "commit", "size",
                         "started"), table_id="experiments"))
    return page("Experiments", body)


def _figure(figure: FigureFile, href: str) -> str:
    made = (f"made by run {run_link(figure.run_id)}" if figure.run_id
            else '<span class="warning">not from a stored run</span> '
                 f'({escape(figure.note or "")})')
    shown = (f'<img src="{escape(href)}" alt="{escape(figure.name)}">'
             if figure.image else link(href, figure.name))
    return (f'<figure id="figure-{escape(figure.name)}">{shown}'
            f"<figcaption>{escape(figure.name)}: {made}</figcaption></figure>")


def experiment_body(contents: Contents, view: ExperimentView, extra: Extras) -> str:
    """The page of one experiment: its run, claims, tables (each with its legend, the run it
    came from and its Pareto plot where it has time and error) and its figures."""
    s = view.source
    parts = []
    if view.description or view.paper:
        parts.append(f"<p>{escape(view.description or '')}"
                     + (f" ({escape(view.paper)})" if view.paper else "") + "</p>")
    parts.append(f'<p class="source">Run {run_link(s.run_id)} on '
                 f"{_machine_link(view.machine_id, contents)}: {escape(s.where)}; "
                 f"{escape(s.which)}.</p>")
    parts.append("<h2>Claims</h2>" + _claims(view, extra.history)
                 + (f"<p>{link(history_page(view.name), 'history of these claims')}</p>"
                    if extra.history else ""))
    parts.append("<h2>Tables</h2>" if view.tables else "<h2>Tables</h2><p>none stored</p>")
    for stored in view.tables:
        ident = f"table-{stored.name}"
        parts.append(f'<h3 id="{escape(ident)}">{escape(stored.name)}</h3>'
                     f'<p class="source">{len(stored.rows)} rows from run '
                     f"{run_link(s.run_id)}</p>"
                     + table(stored.rows, table_id=f"rows-{stored.name}")
                     + legend(stored.legend))
        if stored.name in extra.paretos:
            png, time, error = extra.paretos[stored.name]
            parts.append(f'<figure class="pareto"><img src="{escape(png)}" '
                         f'alt="Pareto plot of {escape(stored.name)}">'
                         f"<figcaption>{escape(error)} against {escape(time)}, rows of run "
                         f"{run_link(s.run_id)}; the black steps are the Pareto front."
                         "</figcaption></figure>")
    parts.append("<h2>Figures</h2>")
    if not extra.figures:
        parts.append('<p class="note">no figures in this experiment\'s folder</p>')
    parts += [_figure(f, href) for f, href in extra.figures]
    return page(f"{view.name}", "\n".join(parts))


def runs_page(contents: Contents, experiments: dict[str, str]) -> str:
    """Every run of the store, oldest first, each row with an anchor (``#run-<id>``): when it
    started, its command, size, commit, machine, load and the experiments it stored."""
    rows, ids = [], []
    for run_id, run in contents.runs.items():
        ids.append(run_anchor(run_id))
        rows.append({"run": escape(run_id), "started": run.get("started"),
                     "command": run.get("command"), "size": run.get("size"),
                     "commit": (run.get("commit") or "")[:10], "dirty": run.get("dirty"),
                     "machine": _machine_link(run.get("machine_id"), contents),
                     "load_1m": run.get("load_1m"),
                     "experiments": experiments.get(run_id, "")})
    return page("Runs", table(rows, raw=("run", "machine"), row_ids=ids, table_id="runs"))


def machines_page(contents: Contents) -> str:
    """Every machine of the store with its CPU, cores, renderer and number of runs."""
    counts: dict[str, int] = {}
    for run in contents.runs.values():
        counts[str(run.get("machine_id"))] = counts.get(str(run.get("machine_id")), 0) + 1
    rows = [{"machine": link(machine_page(mid), mid), "cpu": m.get("cpu"),
             "cores": m.get("logical_cores"), "renderer": m.get("renderer"),
             "runs": counts.get(mid, 0)} for mid, m in contents.machines.items()]
    return page("Machines", table(rows, raw=("machine",), table_id="machines"))


def machine_body(contents: Contents, machine_id: str) -> str:
    """One machine's page: every fingerprint field (those of
    ``MACHINE_FIELDS`` of :mod:`workbench.results.provenance` first) and the runs made on it."""
    machine = contents.machines[machine_id]
    fields = [f for f in MACHINE_FIELDS if f in machine] + sorted(
        f for f in machine if f not in MACHINE_FIELDS and f != "machine_id")
    rows: list[dict[str, Any]] = [{"field": "machine_id", "value": machine_id}]
    rows += [{"field": f, "value": machine.get(f)} for f in fields]
    runs = [{"run": run_link(r), "started": run.get("started"), "size": run.get("size"),
             "commit": (run.get("commit") or "")[:10]}
            for r, run in contents.runs.items() if run.get("machine_id") == machine_id]
    return page(f"Machine {machine_id[:12]}",
                "<h2>Fingerprint</h2>" + table(rows, sortable=False, table_id="fingerprint")
                + "<h2>Runs on it</h2>" + table(runs, raw=("run",), table_id="machine-runs"))

