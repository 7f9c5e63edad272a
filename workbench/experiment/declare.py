"""What an experiment declares once: its tables (every column with its unit and legend) and the
claims the report states from them.

An experiment script registers with ``@experiment(name, description, declared=...)`` (see
:mod:`workbench.experiment.registry`), where ``declared`` is a :class:`Declaration`: the paper
it reproduces, its :class:`Table` s and its :class:`Claim` s. Everything else reads it:

* the harness checks every table an experiment writes against it before writing
  (:meth:`Declaration.check`): a column the rows carry that is not declared, a declared column
  no row carries, or a table not declared fails with one error naming the experiment, the table
  and the column, so the declaration cannot drift from the code;
* ``table.md`` and every further table's Markdown get a legend under the table (each column's
  unit and meaning, :meth:`Table.legend`);
* :mod:`workbench.experiment.report` states each experiment's claims from its stored rows,
  each claim reading only the declared columns it names, and its one headline (a claim of a
  single short sentence) in the README;
* the shape tests compare the tables written with the declared columns.

A column name may hold one placeholder in braces (``"{scene} es2008 pipeline ms"``) standing
for any text; its legend may use the same placeholder, filled in per column. Columns the
harness adds (:data:`HARNESS_COLUMNS`: ``egl_device``) need no declaration, and the raw
repetitions kept for the results store (names ending in ``_samples_ms``) are never checked.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

from ..output.tables import STORE_ONLY_SUFFIX

Tables = Callable[[str], list[Mapping[str, Any]]]
HEADLINE_CHARS = 160
"""The longest headline the README's table takes (characters of its one sentence)."""
_PLACEHOLDER = re.compile(r"\{([A-Za-z_][A-Za-z0-9_]*)\}")


class DeclarationError(ValueError):
    """A table whose rows do not match its declaration, or a declaration that contradicts
    itself (a claim reading a column no table declares)."""


@dataclass(frozen=True)
class Column:
    """One declared column: ``name`` (with at most one ``{placeholder}`` standing for any
    text), its ``unit`` ("ms", "mm", "%", "×" for a ratio; "" for labels, flags and counts)
    and ``legend`` (what it holds, one sentence). An ``optional`` column may be absent from a
    table (say, one that only rows of the shared car deck carry); any other declared column
    must be carried by at least one row of every non-empty table it is declared in."""

    name: str
    unit: str
    legend: str
    optional: bool = False

    def __post_init__(self) -> None:
        if not self.name or not isinstance(self.name, str):
            raise DeclarationError(f"a column needs a name, got {self.name!r}")
        if len(_PLACEHOLDER.findall(self.name)) > 1:
            raise DeclarationError(f"column {self.name!r} holds more than one placeholder")
        if not self.legend:
            raise DeclarationError(f"column {self.name!r} has no legend")

    @property
    def pattern(self) -> re.Pattern[str] | None:
        """The regular expression of a name with a placeholder; None for a plain name."""
        found = _PLACEHOLDER.search(self.name)
        if found is None:
            return None
        head, tail = self.name[:found.start()], self.name[found.end():]
        return re.compile(f"^{re.escape(head)}(?P<{found.group(1)}>.+?){re.escape(tail)}$")

    def matches(self, column: str) -> bool:
        """Whether the written column ``column`` is this declared column."""
        pattern = self.pattern
        return column == self.name if pattern is None else bool(pattern.match(column))

    def legend_of(self, column: str) -> str:
        """The legend of the written column ``column``, its placeholder filled in."""
        pattern = self.pattern
        found = pattern.match(column) if pattern is not None else None
        return self.legend.format(**found.groupdict()) if found else self.legend


def interval_columns(name: str, legend: str, unit: str = "×",
                     optional: bool = False) -> tuple[Column, ...]:
    """The four columns of a ratio measured interleaved
    (:mod:`workbench.measurement.interleave`): ``name`` (the median ratio, ``legend``), its 95 %
    interval ``name_lo``/``name_hi`` and the pairs drawn, ``name_pairs``."""
    return (Column(name, unit, legend, optional),
            Column(f"{name}_lo", unit, f"lower end of {name}'s 95 % interval", optional),
            Column(f"{name}_hi", unit, f"upper end of {name}'s 95 % interval", optional),
            Column(f"{name}_pairs", "", f"interleaved pairs timed for {name}", optional))


HARNESS_COLUMNS = (Column("egl_device", "", "the EGL device the row was drawn on "
                          "(\"egl0:software\", \"egl1:<uuid>\"), added by the harness",
                          optional=True),)


@dataclass(frozen=True)
class Table:
    """One declared table: its file ``name`` (``<name>.csv``/``<name>.md``; the main table
    is ``"table"``) and its ``columns`` (nested sequences of :class:`Column` are flattened, in
    the order the table writes them). Refuses a column declared twice."""

    name: str
    columns: tuple[Column, ...]

    def __init__(self, name: str, *columns: Column | Iterable[Column]) -> None:
        flat: list[Column] = []
        for item in columns:
            flat.extend([item] if isinstance(item, Column) else item)
        names = [c.name for c in flat]
        twice = sorted({n for n in names if names.count(n) > 1})
        if twice:
            raise DeclarationError(f"table {name!r} declares {twice} more than once")
        bad = [c for c in flat if not isinstance(c, Column)]
        if bad:
            raise DeclarationError(f"table {name!r}: {bad[:1]} is not a Column")
        object.__setattr__(self, "name", name)
        object.__setattr__(self, "columns", tuple(flat))

    @property
    def names(self) -> list[str]:
        """The declared column names, in order (placeholders as declared)."""
        return [c.name for c in self.columns]

    def column(self, written: str) -> Column | None:
        """The declared (or harness) column the written column ``written`` is; None if none."""
        for column in (*self.columns, *HARNESS_COLUMNS):
            if column.matches(written):
                return column
        return None

    def declared_names(self, header: Sequence[str]) -> list[str]:
        """The declared names of the written columns ``header`` (harness columns left out),
        each once, in first-written order: what a shape test compares with :attr:`names`."""
        found: dict[str, None] = {}
        for written in header:
            column = self.column(written)
            if column is None:
                found.setdefault(f"<undeclared {written}>", None)
            elif column not in HARNESS_COLUMNS:
                found.setdefault(column.name, None)
        return list(found)

    def check(self, rows: Sequence[Mapping[str, Any]], experiment: str,
              columns: Sequence[str] | None = None) -> None:
        """Refuse (:class:`DeclarationError`, naming ``experiment``, this table and the column)
        rows that carry a column not declared, or that leave out a declared column that is not
        optional; where ``columns`` picks the columns written, those are checked instead of
        the rows' keys. Columns ending in ``_samples_ms`` (kept for the store only) are not
        checked; an empty table is not either."""
        written: dict[str, None] = {}
        if columns is not None and rows:
            written.update(dict.fromkeys(str(c) for c in columns))
        for row in rows if columns is None else ():
            written.update(dict.fromkeys(str(k) for k in row))
        written = {k: None for k in written if not k.endswith(STORE_ONLY_SUFFIX)}
        if not written:
            return
        where = f"experiment {experiment!r}, table {self.name!r}"
        undeclared = [c for c in written if self.column(c) is None]
        if undeclared:
            raise DeclarationError(f"{where}: column {undeclared[0]!r} is not declared"
                                   + (f" (nor {undeclared[1:]})" if undeclared[1:] else "")
                                   + "; declare it with its unit and legend")
        missing = [c.name for c in self.columns
                   if not c.optional and not any(c.matches(w) for w in written)]
        if missing:
            raise DeclarationError(f"{where}: declared column {missing[0]!r} is missing from "
                                   f"its rows" + (f" (and {missing[1:]})" if missing[1:] else "")
                                   + "; write it or declare it optional")

    def legend(self, header: Sequence[str]) -> list[tuple[str, str, str]]:
        """``(column, unit, legend)`` of each written column of ``header`` (columns not
        declared are left out: :meth:`check` refuses them first)."""
        out = []
        for written in header:
            column = self.column(written)
            if column is not None:
                out.append((written, column.unit, column.legend_of(written)))
        return out


@dataclass(frozen=True)
class Claim:
    """One statement the report makes from an experiment's latest stored run: ``quantity``
    (what it states, a few words), ``reads`` (table name → the declared columns it reads;
    its rows hold those columns only) and ``state(tables) -> list[str]`` (the sentences, from
    ``tables(name)``, the stored rows of a table)."""

    quantity: str
    reads: Mapping[str, Sequence[str]]
    state: Callable[[Tables], list[str]]


@dataclass(frozen=True)
class Declaration:
    """What an experiment declares: the ``paper`` it reproduces (as the report names it, say
    "es2008 Tables 2–3"), its ``tables``, its ``claims`` (``docs/results.md`` states them all)
    and its ``headline``: the one claim the README's table states, a single sentence of at
    most :data:`HEADLINE_CHARS` characters. Refuses two tables of one name and a claim or
    headline reading a table or column not declared."""

    paper: str
    tables: tuple[Table, ...]
    claims: tuple[Claim, ...] = field(default=())
    headline: Claim | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "tables", tuple(self.tables))
        object.__setattr__(self, "claims", tuple(self.claims))
        names = [t.name for t in self.tables]
        if len(set(names)) != len(names):
            raise DeclarationError(f"tables declared twice: {names}")
        for claim in (*self.claims, *([self.headline] if self.headline else [])):
            for table, columns in claim.reads.items():
                spec = self.table(table)
                for column in columns:
                    if column not in spec.names and spec.column(column) is None:
                        raise DeclarationError(f"claim {claim.quantity!r} reads column "
                                               f"{column!r} that table {table!r} does not "
                                               f"declare")

    def table(self, name: str) -> Table:
        """The declared table ``name``; :class:`DeclarationError` naming the declared ones."""
        for table in self.tables:
            if table.name == name:
                return table
        raise DeclarationError(f"table {name!r} is not declared (declared: "
                               f"{', '.join(t.name for t in self.tables) or 'none'})")

    def check(self, experiment: str, name: str, rows: Sequence[Mapping[str, Any]],
              columns: Sequence[str] | None = None) -> Table:
        """The declared table ``name`` after :meth:`Table.check` of ``rows`` (or of the
        ``columns`` written); refuses a table not declared, naming ``experiment``."""
        try:
            table = self.table(name)
        except DeclarationError as exc:
            raise DeclarationError(f"experiment {experiment!r}: {exc}") from None
        table.check(rows, experiment, columns)
        return table
