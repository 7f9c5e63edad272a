"""What the site shows, gathered from the results store before any page is written: per
experiment its latest stored run (:func:`~workbench.experiment.report.latest_sources`), its
declaration, its claims stated from that run and its stored tables with their legends; every
run and every machine fingerprint.

The store's Parquet files are read once per build: :class:`OnceStore` copies its three views
into an in-memory DuckDB database when it is made, and answers every query of the build from
that copy (each distinct query once), so the site shows the store as it was at one moment even
while runs go on writing to it.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..experiment.report import (
    Source,
    declared_claims,
    latest_sources,
    stated,
    stored_legend,
    stored_table,
    stored_table_names,
)

if TYPE_CHECKING:
    import pyarrow as pa

    from ..experiment.declare import Claim, Declaration
    from ..results.store import ResultsStore


class OnceStore:
    """A snapshot of a :class:`~workbench.results.store.ResultsStore` for one build: its views
    ``rows``, ``runs`` and ``machines`` copied into tables of an in-memory DuckDB database, each
    distinct SQL text answered once. ``root`` and every other attribute are the store's."""

    def __init__(self, store: ResultsStore) -> None:
        self._store, self._answers = store, {}
        self._con = store.connect()
        for view in ("rows", "runs", "machines"):
            self._con.execute(f"CREATE TABLE snapshot_{view} AS SELECT * FROM {view}")
        for view in ("rows", "runs", "machines"):
            self._con.execute(f"DROP VIEW {view}")
            self._con.execute(f"ALTER TABLE snapshot_{view} RENAME TO {view}")

    def query(self, sql: str) -> pa.Table:
        """The answer to ``sql`` over the snapshot (computed the first time only)."""
        if sql not in self._answers:
            self._answers[sql] = self._con.sql(sql).to_arrow_table()
        return self._answers[sql]

    def close(self) -> None:
        """Release the snapshot's database."""
        self._con.close()

    def __getattr__(self, name: str) -> Any:
        return getattr(self._store, name)


@dataclass(frozen=True)
class StoredTable:
    """One stored table of a run: its ``name``, its ``rows`` (only the columns it has), and
    its ``legend`` (``(column, unit, meaning)`` from the declaration; empty where none)."""

    name: str
    rows: list[dict[str, Any]]
    legend: list[tuple[str, str, str]]


@dataclass(frozen=True)
class ClaimView:
    """One declared claim with the sentences it states from the run's tables."""

    claim: Claim
    sentences: list[str]


@dataclass
class ExperimentView:
    """One experiment as the site shows it: the run its tables and claims come from
    (``source``), its description and paper (None where it is not registered or declares
    nothing), its claims and its tables."""

    name: str
    source: Source
    machine_id: str | None
    description: str | None
    paper: str | None
    declared: Declaration | None
    claims: list[ClaimView] = field(default_factory=list)
    tables: list[StoredTable] = field(default_factory=list)


@dataclass
class Contents:
    """Everything the pages need: the experiments (by name, sorted), every run (by run id,
    oldest first, each a dict of the ``runs`` view without its library versions), every
    machine fingerprint (by machine id) and per run the experiments it stored (``a, b``)."""

    root: Path
    experiments: dict[str, ExperimentView]
    runs: dict[str, dict[str, Any]]
    machines: dict[str, dict[str, Any]]
    stored_by: dict[str, str]


def _registered() -> dict[str, Any]:
    from ..experiment.registry import EXPERIMENTS, discover

    discover()
    return dict(EXPERIMENTS)


def gather(store: ResultsStore | OnceStore) -> Contents:
    """The :class:`Contents` of ``store``; refuses (ValueError naming the store) one that
    holds no quick or full experiment run."""
    store = store if isinstance(store, OnceStore) else OnceStore(store)
    sources = latest_sources(store)
    if not sources:
        raise ValueError(f"the results store {store.root} holds no experiment run at quick or "
                         f"full size (run `workbench reproduce` or `workbench run NAME` first)")
    runs_table = store.query("SELECT * FROM runs")
    keep = [c for c in runs_table.column_names if c != "libraries"]
    runs = sorted(runs_table.select(keep).to_pylist(),
                  key=lambda r: (str(r.get("started") or ""), str(r["run_id"])))
    machines = {str(m["machine_id"]): m for m in store.query("SELECT * FROM machines").to_pylist()}
    registered, claims = _registered(), declared_claims()
    experiments = {}
    for name, source in sources.items():
        known = registered.get(name)
        declared = known.declared if known is not None else None
        run = next((r for r in runs if r["run_id"] == source.run_id), {})
        view = ExperimentView(name, source, run.get("machine_id"),
                              known.description if known is not None else None,
                              declared.paper if declared is not None else None, declared)
        for table in stored_table_names(store, source):
            rows = stored_table(store, source, table)
            view.tables.append(StoredTable(table, rows, stored_legend(declared, table, rows)))
        for claim in claims.get(name, ("", ()))[1]:
            view.claims.append(ClaimView(claim, stated(store, source, claim)))
        experiments[name] = view
    stored_by = {str(r["run_id"]): r["names"] for r in store.query(
        "SELECT run_id, string_agg(DISTINCT experiment, ', ' ORDER BY experiment) AS names "
        "FROM rows GROUP BY run_id").to_pylist()}
    return Contents(Path(store.root), experiments, {str(r["run_id"]): r for r in runs},
                    machines, stored_by)
