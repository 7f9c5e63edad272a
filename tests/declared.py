"""The shape tests' reading of an experiment's declaration
(:mod:`workbench.experiment.declare`): the tables a run wrote must be declared tables, and each
one's columns the declared columns, in the declared order (optional columns may be absent, the
harness's ``egl_device`` is left out)."""

from __future__ import annotations

import csv
from pathlib import Path

from workbench.experiment.declare import Declaration


def declaration(name: str) -> Declaration:
    """The declaration experiment ``name`` registered with."""
    from workbench.experiment.registry import discover, get_experiment

    discover()
    declared = get_experiment(name).declared
    assert declared is not None, f"experiment {name} declares no tables"
    return declared


def header(path: Path) -> list[str]:
    """The column names of a written CSV table."""
    with open(path, encoding="utf-8", newline="") as handle:
        return next(csv.reader(handle))


def assert_declared_tables(name: str, out_dir: Path, expect: set[str] | None = None) -> set[str]:
    """Every CSV table in ``out_dir`` is a table experiment ``name`` declares, with exactly the
    declared columns in the declared order and a legend line per column in its Markdown;
    ``expect`` (default: every declared table) names the tables that must be there. Returns
    the names of the tables written."""
    declared = declaration(name)
    written = {p.stem for p in out_dir.glob("*.csv")}
    wanted = {t.name for t in declared.tables} if expect is None else set(expect)
    assert written == wanted, (name, sorted(written ^ wanted))
    for table_name in sorted(written):
        table = declared.table(table_name)
        columns = header(out_dir / f"{table_name}.csv")
        got = table.declared_names(columns)
        assert got == [c.name for c in table.columns if not c.optional or c.name in got], (
            name, table_name, got)
        markdown = (out_dir / f"{table_name}.md").read_text(encoding="utf-8")
        legend = markdown[markdown.index("\nColumns:\n"):]
        for column in columns:
            assert f"- `{column}`" in legend, (name, table_name, column)
    return written
