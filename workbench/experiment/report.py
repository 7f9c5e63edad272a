"""The measured claims of the README and ``docs/results.md``, written from the results store.

Nothing in them is typed: each experiment's latest stored run (full size where there is one,
else quick) gives its claims (the :class:`~workbench.experiment.declare.Claim` s its
declaration holds, each reading only the declared columns it names from that run's tables,
:class:`ClaimRow`) and its tables; each names the run, the machine and renderer it ran on, its
size, the commit and the load on the machine when it started. A ratio measured interleaved is
given with its 95 % interval (``1.13× [1.07, 1.22]``); a ratio of two separate measurements
says so. The README lists the experiments with claims ordered by paper.

:func:`write_report` rewrites the part of the README between ``<!-- results:begin -->`` and
``<!-- results:end -->`` (one headline per experiment), the whole of ``docs/results.md`` (every
claim, every stored table with its declared legend) and the benchmarks section of
``docs/history.md`` (between ``<!-- benchmarks:begin -->`` and ``<!-- benchmarks:end -->``: each
benchmark's latest stored run), each atomically.
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..output.tables import atomic_write_text, format_number, markdown_table, table_columns

if TYPE_CHECKING:
    from ..results.store import ResultsStore
    from .declare import Claim, Declaration

BEGIN, END = "<!-- results:begin -->", "<!-- results:end -->"
BENCH_BEGIN, BENCH_END = "<!-- benchmarks:begin -->", "<!-- benchmarks:end -->"


@dataclass(frozen=True)
class Source:
    """The stored run an experiment's claims come from, and where it ran."""

    experiment: str
    run_id: str
    size: str
    started: str
    commit: str | None
    dirty: bool | None
    cpu: str | None
    cores: int | None
    renderer: str | None
    driver: str | None
    load_1m: float | None

    @property
    def where(self) -> str:
        """``renderer (driver); CPU, N cores`` of the run."""
        gl = f"{self.renderer} ({self.driver})" if self.driver else str(self.renderer)
        return f"{gl}; {self.cpu}, {self.cores} cores"

    @property
    def which(self) -> str:
        """``size, commit abc1234 (dirty), 2026-12-03, load 0.4``."""
        commit = (self.commit or "no commit")[:7] + (" (dirty)" if self.dirty else "")
        load = "" if self.load_1m is None else f", load {self.load_1m:.1f}"
        return f"{self.size} size, commit {commit}, {self.started[:10]}{load}"


def latest_sources(store: ResultsStore, benchmarks: bool = False) -> dict[str, Source]:
    """Per experiment, its latest stored run at full size, else at quick size (tiny runs and
    sweeps are not reported); with ``benchmarks`` the same per benchmark (``bench:<name>``)
    instead of per experiment."""
    if not {"experiment", "experiment_size"} <= set(
            store.query("SELECT * FROM rows LIMIT 0").column_names):
        return {}  # nothing an experiment wrote
    which = ("r.experiment LIKE 'bench:%'" if benchmarks
             else "r.experiment NOT LIKE 'bench:%'")
    found = store.query(
        "SELECT r.experiment, r.experiment_size, r.run_id, any_value(u.started) AS started, "
        "any_value(u.\"commit\") AS \"commit\", any_value(u.dirty) AS dirty, "
        "any_value(m.cpu) AS cpu, any_value(m.logical_cores) AS cores, "
        "any_value(m.renderer) AS renderer, any_value(m.driver) AS driver, "
        "any_value(u.load_1m) AS load_1m "
        "FROM rows r JOIN runs u USING (run_id) LEFT JOIN machines m USING (machine_id) "
        "WHERE r.experiment_size IN ('full', 'quick') AND r.experiment NOT LIKE 'sweep:%' "
        f"AND {which} GROUP BY ALL").to_pylist()
    best: dict[str, Source] = {}
    for row in found:
        source = Source(row["experiment"], row["run_id"], row["experiment_size"],
                        str(row["started"]), row["commit"], row["dirty"], row["cpu"],
                        row["cores"], row["renderer"], row["driver"], row["load_1m"])
        old = best.get(source.experiment)
        if old is None or (source.size == "full", source.started) > (old.size == "full",
                                                                     old.started):
            best[source.experiment] = source
    return dict(sorted(best.items()))


def _quoted(text: str) -> str:
    """``text`` as an SQL string literal."""
    return "'" + str(text).replace("'", "''") + "'"


def stored_table(store: ResultsStore, source: Source, table: str) -> list[dict[str, Any]]:
    """The rows of ``table`` of ``source``'s experiment in its run, in their order, with only
    the columns that table has (the store's views hold every table's columns)."""
    result = store.query(f"SELECT * FROM rows WHERE run_id = {_quoted(source.run_id)} AND "
                         f"experiment = {_quoted(source.experiment)} AND \"table\" = "
                         f"{_quoted(table)} ORDER BY row_index")
    rows = result.to_pylist()
    keep = [c for c in result.column_names
            if c not in ("run_id", "row_index", "experiment", "table", "experiment_size")
            and not c.endswith("_samples_ms") and any(r[c] is not None for r in rows)]
    return [{c: r[c] for c in keep} for r in rows]


def stored_table_names(store: ResultsStore, source: Source) -> list[str]:
    """The tables ``source``'s experiment stored in its run, main table first."""
    names = store.query(
        f"SELECT DISTINCT \"table\" FROM rows WHERE run_id = {_quoted(source.run_id)} AND "
        f"experiment = {_quoted(source.experiment)}").column("table").to_pylist()
    return sorted(names, key=lambda n: (n != "table", n))


# ---------------------------------------------------------------- formatting
def num(value: Any, digits: int = 3) -> str:
    """A number for a sentence (``digits`` significant digits); "n/a" for None."""
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "n/a"
    return format_number(float(value), digits)


def interval(row: dict[str, Any], name: str) -> str:
    """``1.13× [1.07, 1.22]`` from the columns ``name``, ``name_lo``, ``name_hi``."""
    return (f"{num(row.get(name))}× [{num(row.get(f'{name}_lo'))}, "
            f"{num(row.get(f'{name}_hi'))}]")


def span(values: list[float], digits: int = 3) -> str:
    """``a`` or ``a–b``: the range of ``values`` (None left out); "n/a" for none."""
    values = sorted(v for v in values if v is not None)
    if not values:
        return "n/a"
    lo, hi = num(values[0], digits), num(values[-1], digits)
    return lo if lo == hi else f"{lo}–{hi}"


# ---------------------------------------------------------------- the claims
class ClaimRow(dict):
    """A stored row as a claim sees it: the columns the claim declares it reads (those the
    run stored); reading any other column raises KeyError naming it, so a claim cannot use a
    column it does not declare."""

    def __init__(self, row: dict[str, Any], reads: Sequence[str], quantity: str) -> None:
        super().__init__({c: row[c] for c in reads if c in row})
        self._reads, self._quantity = frozenset(reads), quantity

    def _refuse(self, key: str) -> KeyError:
        return KeyError(f"claim {self._quantity!r} reads column {key!r} without declaring it")

    def __missing__(self, key: str) -> Any:
        if key not in self._reads:
            raise self._refuse(key)
        raise KeyError(key)

    def get(self, key: str, default: Any = None) -> Any:
        """The column ``key`` (``default`` where the run did not store it); KeyError for a
        column the claim does not declare."""
        if key not in self._reads:
            raise self._refuse(key)
        return super().get(key, default)


def declared_claims() -> dict[str, tuple[str, tuple[Claim, ...]]]:
    """Experiment → (paper, claims) of every registered experiment whose declaration holds
    claims, ordered by paper."""
    found = {name: (declared.paper, declared.claims)
             for name, declared in _declarations().items() if declared.claims}
    return dict(sorted(found.items(), key=lambda item: (item[1][0], item[0])))


def declared_headlines() -> dict[str, tuple[str, Claim]]:
    """Experiment → (paper, headline) of every registered experiment that declares a
    headline, ordered by paper."""
    found = {name: (declared.paper, declared.headline)
             for name, declared in _declarations().items() if declared.headline is not None}
    return dict(sorted(found.items(), key=lambda item: (item[1][0], item[0])))


def _declarations() -> dict[str, Declaration]:
    from .registry import EXPERIMENTS, discover

    discover()
    return {name: exp.declared for name, exp in EXPERIMENTS.items() if exp.declared is not None}


def stated(store: ResultsStore, source: Source, claim: Claim) -> list[str]:
    """The sentences of ``claim`` from ``source``'s stored tables, each table's rows holding
    only the columns the claim declares; a claim the run's tables cannot give is named as
    missing."""
    def tables(table: str) -> list[ClaimRow]:
        reads = claim.reads.get(table)
        if reads is None:
            raise KeyError(f"claim {claim.quantity!r} reads table {table!r} without declaring it")
        return [ClaimRow(r, reads, claim.quantity) for r in stored_table(store, source, table)]
    try:
        return claim.state(tables)
    except (KeyError, TypeError) as exc:
        return [f"(not in this run's tables: {exc})"]


def claims_of(store: ResultsStore, source: Source) -> list[str]:
    """The claims of ``source``'s experiment, from its declaration (none for an experiment
    that declares none), each reading the declared columns of its stored tables."""
    entry = declared_claims().get(source.experiment)
    return [] if entry is None else [s for claim in entry[1] for s in stated(store, source, claim)]


# ---------------------------------------------------------------- the two documents
def headline_of(store: ResultsStore, source: Source, claim: Claim) -> str:
    """The one sentence of the headline ``claim`` from ``source``'s run (a note saying so where
    its tables hold no rows for it); ValueError naming the experiment where the claim states
    more than one sentence or one longer than
    :data:`~workbench.experiment.declare.HEADLINE_CHARS` characters."""
    from .declare import HEADLINE_CHARS

    sentences = stated(store, source, claim)
    if not sentences:
        return "(no rows for the headline in this run's tables)"
    if len(sentences) != 1 or len(sentences[0]) > HEADLINE_CHARS:
        raise ValueError(f"the headline of {source.experiment} must be one sentence of at most "
                         f"{HEADLINE_CHARS} characters; it states {sentences!r}")
    return sentences[0]


def ran_on(source: Source) -> str:
    """The short ``full, llvmpipe, 2 cores, a5f26a0`` of a run (the README's last column)."""
    gl = (source.renderer or "no renderer").split(" (")[0]
    commit = (source.commit or "no commit")[:7] + (" (dirty)" if source.dirty else "")
    return f"{source.size}, {gl}, {source.cores} cores, {commit}"


def readme_section(store: ResultsStore) -> str:
    """The README's table of headline results, one short row per experiment that declares a
    headline (its other claims are in ``docs/results.md``), and the machines they ran on."""
    sources = latest_sources(store)
    rows, machines = [], {}
    for experiment, (paper, claim) in declared_headlines().items():
        source = sources.get(experiment)
        if source is None:
            rows.append({"paper": paper, "experiment": f"`{experiment}`",
                         "headline": "not in the results store yet", "ran on": ""})
            continue
        rows.append({"paper": paper, "experiment": f"`{experiment}`",
                     "headline": headline_of(store, source, claim), "ran on": ran_on(source)})
        machines.setdefault(source.where, []).append(experiment)
    note = ("Written by `workbench results report` from the latest stored run of each "
            "experiment (full size where there is one); a ratio measured interleaved carries "
            "its 95 % interval. Every claim and table: [docs/results.md](docs/results.md).")
    where = "".join(f"\n- {place}: " + ("every experiment above" if len(names) == len(sources)
                                         else ", ".join(f"`{e}`" for e in names))
                    for place, names in machines.items())
    where = f"\nMachines (renderer; CPU):{where}\n" if where else ""
    return f"{BEGIN}\n{note}\n\n{markdown_table(rows)}{where}{END}"


def benchmark_lines(rows: list[dict[str, Any]]) -> list[str]:
    """One line per timed row of a benchmark's stored case: ``function: 12.3 ms [12.1, 12.6]``
    with the row's interleaved ratios (``÷ fcpw 0.52× [0.50, 0.55]``). A function timed more
    than once in the case (say, per query set) is named with the columns that tell its rows
    apart: ``query (cutoff_mm 1.5, set nodes): …``."""
    timed = [r for r in rows if r.get("wall_ms") is not None]
    qualifiers = _qualifiers(timed)
    out = []
    for r in timed:
        ratios = [f"; ÷ {key[5:]} {interval(r, key)}" for key in r
                  if key.startswith("over_") and not key.endswith(("_lo", "_hi", "_pairs"))
                  and r[key] is not None]
        named = ", ".join(f"{key} {_value(r[key])}" for key in qualifiers
                          if r.get(key) is not None)
        label = f"{r.get('function')} ({named})" if named else f"{r.get('function')}"
        out.append(f"{label}: {num(r['wall_ms'])} ms [{num(r.get('wall_ms_lo'))}, "
                   f"{num(r.get('wall_ms_hi'))}]{''.join(ratios)}")
    return out


_MEASURED = ("wall_", "gpu_", "over_", "readback_")


def _qualifiers(timed: list[dict[str, Any]]) -> list[str]:
    """The columns, set in every row of every function timed more than once and not measured
    times, whose values differ between rows of one function: what tells a function's repeated
    rows apart (none when no function repeats). A counter that one repeated function's rows
    lack (a hierarchy's tests, which the BVH's rows do not carry) is not one."""
    by_function: dict[Any, list[dict[str, Any]]] = {}
    for r in timed:
        by_function.setdefault(r.get("function"), []).append(r)
    repeated = [group for group in by_function.values() if len(group) > 1]
    if not repeated:
        return []
    rows = [r for group in repeated for r in group]
    keys = [k for k in rows[0] if k not in ("function", "repeats", "row_index")
            and not k.startswith(_MEASURED) and all(r.get(k) is not None for r in rows)]
    return [k for k in keys
            if any(len({repr(r[k]) for r in group}) > 1 for group in repeated)]


def _value(value: Any) -> str:
    """A column value in a label: floats as :func:`num`, the rest as text."""
    if isinstance(value, float):
        return num(value)
    return str(value)


def benchmark_section(store: ResultsStore) -> str:
    """The benchmarks' section of ``docs/history.md`` (between :data:`BENCH_BEGIN` and
    :data:`BENCH_END`): per benchmark its latest stored run (full size where there is one),
    where it ran, and per case each timed function's median with its 95 % interval and its
    interleaved ratios."""
    parts = [BENCH_BEGIN, "Written by `workbench results report` from the latest stored run of "
             "each benchmark (`workbench bench`; full size where there is one): each timed "
             "function's median wall time with its 95 % interval, and its interleaved ratios "
             "with theirs. The rows, with every column: `workbench results query \"SELECT * "
             "FROM rows WHERE experiment = 'bench:NAME'\"`.", ""]
    sources = latest_sources(store, benchmarks=True)
    if not sources:
        parts += ["No benchmark run is stored yet.", ""]
    for experiment, source in sources.items():
        parts += [f"**{experiment[len('bench:'):]}**, run {source.run_id} ({source.where}; "
                  f"{source.which}):", ""]
        for case in stored_table_names(store, source):
            lines = benchmark_lines(stored_table(store, source, case))
            parts += [f"- {case}: " + ("; ".join(lines) if lines else "no timed rows")]
        parts.append("")
    return "\n".join(parts + [BENCH_END])


def results_document(store: ResultsStore) -> str:
    """``docs/results.md``: per experiment its claims, its run and every stored table."""
    from .registry import EXPERIMENTS, discover

    discover()
    sources = latest_sources(store)
    parts = ["# Measured results", "",
             "Written by `workbench results report` from the results store; do not edit. Each "
             "experiment's latest stored run (full size where there is one) is shown with the "
             "machine it ran on. Times hold for that renderer only; compare ratios. Ratios "
             "measured interleaved carry `_lo`/`_hi` (95 % interval) and `_pairs` columns.", ""]
    runs = [{"experiment": s.experiment, "run": s.run_id, "size": s.size,
             "started": s.started, "commit": (s.commit or "")[:10], "dirty": s.dirty,
             "renderer": s.renderer, "driver": s.driver, "cpu": s.cpu, "cores": s.cores,
             "load_1m": s.load_1m} for s in sources.values()]
    parts += ["## The runs", "", markdown_table(runs)]
    for experiment, source in sources.items():
        known = EXPERIMENTS.get(experiment)
        title = f"{experiment}: {known.description}" if known else experiment
        parts += [f"## {title}", "", f"Run {source.run_id}: {source.where}; {source.which}.",
                  ""]
        parts += [f"- {claim}" for claim in claims_of(store, source)] + [""]
        for table in stored_table_names(store, source):
            rows = stored_table(store, source, table)
            parts += [f"### {table}", "", markdown_table(rows, legend=stored_legend(
                known.declared if known else None, table, rows))]
    return "\n".join(parts)


def stored_legend(declared: Declaration | None, table: str,
                  rows: list[dict[str, Any]]) -> list[tuple[str, str, str]]:
    """The legend of the stored ``table``'s columns from the experiment's declaration (none
    where it declares no such table: a run stored before the declaration changed keeps its
    columns, only their legends go)."""
    if declared is None or table not in {t.name for t in declared.tables}:
        return []
    return declared.table(table).legend(table_columns(rows))


def replace_section(text: str, section: str, name: str = "README",
                    markers: tuple[str, str] = (BEGIN, END)) -> str:
    """``text`` with the part from the first of ``markers`` to the second replaced by
    ``section``; ValueError naming ``name`` where the markers are missing or out of order."""
    begin, end_marker = markers
    start, end = text.find(begin), text.find(end_marker)
    if start < 0 or end < start:
        raise ValueError(f"{name} has no '{begin}' … '{end_marker}' section to write the "
                         f"results into")
    return text[:start] + section + text[end + len(end_marker):]


def write_report(store: ResultsStore, readme: str | os.PathLike[str],
                 doc: str | os.PathLike[str],
                 history: str | os.PathLike[str] | None = None) -> list[Path]:
    """Rewrite the results section of ``readme``, the whole of ``doc`` and, where ``history``
    is given, its benchmarks section (:func:`benchmark_section`) from ``store``; returns the
    paths written. Refuses an empty store and a README or history without its markers, before
    writing any."""
    if not latest_sources(store):
        raise ValueError(f"the results store {store.root} holds no experiment run "
                         f"(run `workbench reproduce` or `workbench run NAME` first)")
    readme, doc = Path(readme), Path(doc)
    texts = {readme: replace_section(readme.read_text(encoding="utf-8"),
                                     readme_section(store), str(readme))}
    if history is not None:
        history = Path(history)
        texts[history] = replace_section(history.read_text(encoding="utf-8"),
                                         benchmark_section(store), str(history),
                                         (BENCH_BEGIN, BENCH_END))
    document = results_document(store)
    for path, text in texts.items():
        atomic_write_text(path, text)
    doc.parent.mkdir(parents=True, exist_ok=True)
    atomic_write_text(doc, document)
    return [readme, doc, *([history] if history is not None else [])]
