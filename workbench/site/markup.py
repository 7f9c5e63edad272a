"""The HTML pieces every page is made of, each escaped with :func:`html.escape`: the page shell
(relative links to the style sheet and the sorter, no network), links, sortable tables with
their legends, and the file names of the pages.

Every page lies in the site's top folder, so a link is a bare file name (``run.html#…``) and
works from disk. Names in file names come from the store: experiment names, run ids and
machine ids are ``[A-Za-z0-9_.-]`` there; anything else is replaced by ``_`` all the same.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable, Sequence
from html import escape
from numbers import Integral, Real
from typing import Any

from ..output.tables import format_number
from .assets import CSS_NAME, JS_NAME

_UNSAFE = re.compile(r"[^A-Za-z0-9_.-]")


def safe(name: str) -> str:
    """``name`` with every character outside ``[A-Za-z0-9_.-]`` replaced by ``_`` (a leading
    dot too), for file names and anchors."""
    text = _UNSAFE.sub("_", str(name))
    return "_" + text[1:] if text.startswith(".") else text


def experiment_page(name: str) -> str:
    """The file name of experiment ``name``'s page."""
    return f"experiment-{safe(name)}.html"


def history_page(name: str) -> str:
    """The file name of experiment ``name``'s history page."""
    return f"history-{safe(name)}.html"


def claim_anchor(quantity: str) -> str:
    """The anchor of the claim stating ``quantity`` on its experiment's history page."""
    return f"claim-{safe(quantity)}"


def machine_page(machine_id: str) -> str:
    """The file name of machine ``machine_id``'s page."""
    return f"machine-{safe(machine_id)}.html"


def run_anchor(run_id: str) -> str:
    """The id of run ``run_id``'s row on the runs page."""
    return f"run-{safe(run_id)}"


def run_link(run_id: str | None, text: str | None = None) -> str:
    """A link to run ``run_id``'s row of ``runs.html`` (plain text "no run" for None)."""
    if run_id is None:
        return "no run"
    return f'<a href="runs.html#{run_anchor(run_id)}">{escape(text or run_id)}</a>'


def link(href: str, text: str) -> str:
    """``<a href=…>text</a>``, both escaped."""
    return f'<a href="{escape(href)}">{escape(text)}</a>'


def cell(value: Any) -> tuple[str, bool]:
    """One value as table-cell text and whether it is a number: floats to 4 significant
    digits, bools yes/no, None empty, lists shortened."""
    if value is None:
        return "", False
    if isinstance(value, bool):
        return ("yes" if value else "no"), False
    if isinstance(value, Integral):
        return str(int(value)), True
    if isinstance(value, Real):
        return format_number(float(value)), not math.isnan(float(value))
    if isinstance(value, (list, tuple)):
        text = ", ".join(cell(v)[0] for v in value[:8]) + (", …" if len(value) > 8 else "")
        return f"[{text}]", False
    return str(value), False


def table(rows: Sequence[dict[str, Any]], columns: Sequence[str] | None = None, *,
          sortable: bool = True, raw: Iterable[str] = (), row_classes: Sequence[str] = (),
          row_ids: Sequence[str] = (), table_id: str | None = None) -> str:
    """An HTML table of ``rows`` with a ``<thead>`` (``columns``: default every key in first
    seen order) and one ``<tbody>`` row per row; sortable on a click on a heading (numbers by
    value: each numeric cell carries its exact value in ``data-value``). Cells of the ``raw``
    columns are HTML already (links) and are not escaped; ``row_classes`` gives each row a
    class and ``row_ids`` an id. A table without rows says so instead."""
    columns = list(dict.fromkeys(c for r in rows for c in r) if columns is None else columns)
    if not rows:
        return '<p class="note">no rows</p>'
    raw = set(raw)
    head = "".join(f'<th scope="col">{escape(str(c))}</th>' for c in columns)
    body = []
    for i, row in enumerate(rows):
        cells = []
        for c in columns:
            value = row.get(c)
            if c in raw:
                cells.append(f"<td>{'' if value is None else value}</td>")
                continue
            text, number = cell(value)
            if number:
                cells.append(f'<td class="num" data-value="{escape(repr(value))}">'
                             f"{escape(text)}</td>")
            else:
                cells.append(f"<td>{escape(text)}</td>")
        klass = row_classes[i] if i < len(row_classes) else ""
        ident = row_ids[i] if i < len(row_ids) else ""
        attributes = (f' id="{escape(ident)}"' if ident else "") + (
            f' class="{escape(klass)}"' if klass else "")
        body.append(f"<tr{attributes}>" + "".join(cells) + "</tr>")
    ident = f' id="{escape(table_id)}"' if table_id else ""
    klass = ' class="sortable"' if sortable else ""
    return (f'<div class="scroll"><table{ident}{klass}><thead><tr>{head}</tr></thead>'
            f"<tbody>{''.join(body)}</tbody></table></div>")


def legend(entries: Sequence[tuple[str, str, str]]) -> str:
    """The legend under a table: one line per ``(column, unit, meaning)`` (none: empty)."""
    if not entries:
        return ""
    lines = "".join(f"<div><dt>{escape(c)}</dt><dd>{f'({escape(u)}) ' if u else ''}"
                    f"{escape(m)}</dd></div>" for c, u, m in entries)
    return f'<dl class="legend">{lines}</dl>'


def page(title: str, body: str) -> str:
    """A whole page: ``title`` (escaped) as its title and heading, the navigation, ``body``
    (HTML), the style sheet and the sorter linked relatively, and an empty icon so that no
    browser asks for ``favicon.ico``."""
    nav = (f'<nav>{link("index.html", "experiments")}{link("runs.html", "runs")}'
           f'{link("machines.html", "machines")}</nav>')
    return ("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
            f"<title>{escape(title)}</title>"
            '<meta name="viewport" content="width=device-width, initial-scale=1">'
            '<link rel="icon" href="data:,">'
            f'<link rel="stylesheet" href="{CSS_NAME}">'
            f'<script src="{JS_NAME}" defer></script></head>\n'
            f"<body>{nav}<h1>{escape(title)}</h1>\n{body}\n</body></html>\n")
