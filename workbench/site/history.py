"""The history pages: per experiment with claims, per claim, every numeric column the claim
reads (:attr:`Claim.reads <workbench.experiment.declare.Claim.reads>`) over the stored runs,
from :func:`workbench.results.history.histories`: a plot (value per run with its interval,
change points as dashed lines) and per measurement a table of its runs (folded away where the
measurement has no change point), the first run after each change point marked (class
``change-point``) and listed with its step (the ratio of the medians after and before).

Interval bounds (``_lo``/``_hi``) and pair counts are not columns of their own here: a
history carries its run's interval with each value.
"""

from __future__ import annotations

from dataclasses import dataclass
from html import escape
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..output.tables import finite_number
from .contents import ClaimView, ExperimentView
from .markup import claim_anchor, experiment_page, link, machine_page, page, run_link, safe, table
from .plots import MAX_LINES, history_plot

if TYPE_CHECKING:
    from ..results.history import History

_NOT_OWN = ("_lo", "_hi", "_pairs", "_samples_ms")


@dataclass(frozen=True)
class Quantity:
    """One column a claim reads, over runs: its ``table`` and ``column``, its ``unit`` (from
    the declaration; "" where none), its histories (one per measurement, machine and size) and
    the site-relative path of its plot (None where it has no history)."""

    table: str
    column: str
    unit: str
    histories: tuple[History, ...]
    png: str | None


def read_columns(view: ExperimentView, claim: ClaimView) -> list[tuple[str, str]]:
    """The (table, column) pairs ``claim`` reads that hold numbers in the experiment's stored
    run (its interval bounds and pair counts left out), in the order declared."""
    stored = {t.name: t.rows for t in view.tables}
    found = []
    for table_name, columns in claim.claim.reads.items():
        rows = stored.get(table_name, [])
        for column in columns:
            if column.endswith(_NOT_OWN):
                continue
            if any(finite_number(r.get(column)) is not None for r in rows):
                found.append((table_name, column))
    return found


def _unit(view: ExperimentView, table_name: str, column: str) -> str:
    if view.declared is None or table_name not in {t.name for t in view.declared.tables}:
        return ""
    declared = view.declared.table(table_name).column(column)
    return declared.unit if declared is not None else ""


def quantities(store: Any, view: ExperimentView, plots: Path,
               ) -> list[tuple[ClaimView, list[Quantity]]]:
    """Per claim of ``view`` its :class:`Quantity` s, each column's histories asked of
    ``store`` once and its plot written into ``plots`` (a folder of the site being built;
    its path relative to the site is ``plots/<file>``)."""
    from ..results.history import histories

    done: dict[tuple[str, str], Quantity] = {}
    out = []
    for claim in view.claims:
        found = []
        for table_name, column in read_columns(view, claim):
            key = (table_name, column)
            if key not in done:
                found_histories = tuple(histories(store, f"{view.name}/{table_name}/{column}"))
                png = None
                if found_histories and not constant(found_histories):
                    name = f"history-{safe(view.name)}-{safe(table_name)}-{safe(column)}.png"
                    history_plot(plots / name, found_histories,
                                 f"{view.name}/{table_name}/{column}",
                                 _unit(view, table_name, column))
                    png = f"plots/{name}"
                done[key] = Quantity(table_name, column, _unit(view, table_name, column),
                                     found_histories, png)
            found.append(done[key])
        out.append((claim, found))
    return out


def constant(found: tuple[History, ...]) -> bool:
    """Whether every history of ``found`` holds one value in all its runs (a parameter such
    as a triangle count: nothing to plot)."""
    return all(len({p.value for p in h.points}) == 1 for h in found)


def _anchor(quantity: Quantity) -> str:
    return f"quantity-{safe(quantity.table)}-{safe(quantity.column)}"


def _summary(claims: list[tuple[ClaimView, list[Quantity]]]) -> str:
    """The change points of the whole page, each linking to its column's section."""
    items, seen = [], set()
    for _, found in claims:
        for quantity in found:
            if _anchor(quantity) in seen:
                continue
            seen.add(_anchor(quantity))
            for history in quantity.histories:
                for index, step in zip(history.changes, history.steps()):
                    run_id = history.points[index].run_id
                    items.append(f'<li><a href="#{_anchor(quantity)}">{escape(quantity.table)}'
                                 f" / {escape(quantity.column)}</a> "
                                 f"[{escape(history.measurement or 'all rows')}]: from run "
                                 f"{run_link(run_id)} on, ×{step:.3g}</li>")
    if not items:
        return "<h2>Change points</h2><p>none found in any history below</p>"
    return "<h2>Change points</h2><ul>" + "".join(items) + "</ul>"


def _changes(history: History) -> str:
    if not history.changes:
        return '<p class="note">no change point</p>'
    steps = history.steps()
    items = []
    for k, index in enumerate(history.changes):
        point = history.points[index]
        step = f"×{steps[k]:.3g}" if k < len(steps) else "?"
        items.append(f'<li class="change-point" data-run="{escape(point.run_id)}">change point '
                     f"at run {run_link(point.run_id)} (commit "
                     f"{escape((point.commit or 'none')[:10])}, {escape(point.started[:19])}): "
                     f"median after / before {escape(step)}</li>")
    return "<ul>" + "".join(items) + "</ul>"


def _points(history: History, machines: set[str]) -> str:
    changed = set(history.changes)
    rows = [{"run": run_link(p.run_id), "started": p.started, "commit": (p.commit or "")[:10],
             "size": p.size, "value": p.value, "lo": p.lo, "hi": p.hi}
            for p in history.points]
    classes = ["change-point" if i in changed else "" for i in range(len(rows))]
    machine = (link(machine_page(history.machine_id), history.machine_id[:12])
               if history.machine_id in machines else escape(history.machine_id[:12]))
    runs = table(rows, raw=("run",), row_classes=classes)
    if not history.changes:  # folded: a claim may read hundreds of steady measurements
        runs = f"<details><summary>its {len(rows)} runs</summary>{runs}</details>"
    return (f"<h4>{escape(history.measurement or 'all rows')}</h4>"
            f'<p class="source">machine {machine}, size {escape(str(history.size))}, '
            f"{len(history.points)} runs</p>" + _changes(history) + runs)


def history_body(view: ExperimentView, claims: list[tuple[ClaimView, list[Quantity]]],
                 machines: set[str]) -> str:
    """The history page of ``view``'s experiment: per claim its sentences (from the latest
    run), and per column it reads the plot and the runs of each measurement."""
    parts = [f'<p class="note">Each claim of {link(experiment_page(view.name), view.name)}'
             " over the stored runs, per measurement, machine and size: the value of each run "
             "with its interval where stored; a change point marks the first run of a new "
             "level.</p>"]
    parts.append(_summary(claims))
    anchors: set[str] = set()
    for claim, found in claims:
        parts.append(f'<h2 id="{claim_anchor(claim.claim.quantity)}">'
                     f"{escape(claim.claim.quantity)}</h2><ul>"
                     + "".join(f"<li>{escape(s)}</li>" for s in claim.sentences) + "</ul>")
        if not found:
            parts.append('<p class="note">it reads no numeric column</p>')
        for quantity in found:
            unit = f" ({escape(quantity.unit)})" if quantity.unit else ""
            ident = "" if _anchor(quantity) in anchors else f' id="{_anchor(quantity)}"'
            anchors.add(_anchor(quantity))
            parts.append(f"<h3{ident}>{escape(quantity.table)} / "
                         f"{escape(quantity.column)}{unit}</h3>")
            if not quantity.histories:
                parts.append('<p class="note">fewer than two runs hold it</p>')
                continue
            if constant(quantity.histories):
                values = ", ".join(sorted({f"{h.points[0].value:g}"
                                           for h in quantity.histories}))
                parts.append(f'<p class="note">the same in every run ({escape(values)})</p>')
                continue
            shown = (f"; the plot shows the first {MAX_LINES} of its "
                     f"{len(quantity.histories)} measurements"
                     if len(quantity.histories) > MAX_LINES else "")
            parts.append(f'<figure><img src="{escape(quantity.png or "")}" '
                         f'alt="history of {escape(quantity.column)}"><figcaption>each run\'s '
                         f"value with its interval; dashed: change points{shown}</figcaption>"
                         "</figure>")
            parts += [_points(h, machines) for h in quantity.histories]
    return page(f"History of {view.name}", "\n".join(parts))
