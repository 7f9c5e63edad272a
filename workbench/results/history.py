"""A stored quantity's history: one measurement's value in every stored run on one machine,
oldest first, with the change points found in it (:mod:`workbench.results.changepoints`).

A *quantity* is a stored column, named ``COLUMN``, ``EXPERIMENT/COLUMN`` or
``EXPERIMENT/TABLE/COLUMN``. Its rows are grouped into *measurements* as
``workbench results compare`` pairs them (:func:`~workbench.results.compare.measurement_key`:
experiment, table, size and the text-valued parameters, and the position among equal rows of
one run), and each measurement's rows are grouped by machine: a history never mixes two
machines or renderers, nor a quick run with a full one. Tiny runs (whose numbers mean
nothing) are left out unless ``size="tiny"`` asks for them.

Each run gives one :class:`RunValue`: the column's value with its interval where the run
stored one (``COLUMN_lo``/``COLUMN_hi``, or for a time with its raw samples
``X_samples_ms`` the median's 95 % interval). A run that stored the measurement twice (two
rows with the same parameters in the same place) cannot happen by construction; rows whose
value is missing or not finite are left out of the series and counted in
:attr:`History.missing`.

Times measured in separate runs move with the machine's speed (see
:mod:`workbench.results.compare`): a change point in an absolute time may be the machine's;
ratios measured interleaved within one run are free of that drift.
"""

from __future__ import annotations

import difflib
import statistics
from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from ..output.tables import finite_number
from .changepoints import ALPHA, change_points
from .compare import measurement_key

if TYPE_CHECKING:
    from .store import ResultsStore

_RUN = ("_run_started", "_run_commit", "_run_machine")


@dataclass(frozen=True)
class RunValue:
    """One run's value of one measurement, with the run's interval where it stored one."""

    run_id: str
    started: str
    commit: str | None
    size: str | None
    value: float
    lo: float | None = None
    hi: float | None = None


@dataclass(frozen=True)
class History:
    """One measurement's values over the runs of one machine, oldest first; ``changes``: the
    index into ``points`` of the first run after each change point; ``missing``: the runs
    whose row held no finite value."""

    experiment: str
    table: str
    measurement: str
    quantity: str
    machine_id: str
    size: str | None
    points: tuple[RunValue, ...]
    changes: tuple[int, ...] = ()
    missing: int = 0

    def steps(self) -> list[float]:
        """Per change point, the ratio of the median value of the runs after it (up to the next
        change) to that of the runs before it (from the previous one); NaN where the before
        median is 0."""
        bounds = [0, *self.changes, len(self.points)]
        medians = [statistics.median(p.value for p in self.points[a:b])
                   for a, b in zip(bounds, bounds[1:])]
        return [after / before if before else float("nan")
                for before, after in zip(medians, medians[1:])]

    @property
    def name(self) -> str:
        """``experiment/table/quantity [measurement]``."""
        text = f"{self.experiment}/{self.table}/{self.quantity}"
        return f"{text} [{self.measurement}]" if self.measurement else text


def parse_quantity(quantity: str) -> tuple[str | None, str | None, str]:
    """``(experiment, table, column)`` of ``COLUMN``, ``EXPERIMENT/COLUMN`` or
    ``EXPERIMENT/TABLE/COLUMN``; ValueError for an empty part or more than three."""
    parts = str(quantity).split("/")
    if len(parts) > 3 or not all(parts):
        raise ValueError(f"a quantity is COLUMN, EXPERIMENT/COLUMN or EXPERIMENT/TABLE/COLUMN, "
                         f"got {quantity!r}")
    experiment = parts[0] if len(parts) > 1 else None
    table = parts[1] if len(parts) == 3 else None
    return experiment, table, parts[-1]


def _quoted(text: str) -> str:
    return "'" + str(text).replace("'", "''") + "'"


def _column(name: str) -> str:
    return '"' + name.replace('"', '""') + '"'


def _interval(row: dict[str, Any], column: str) -> tuple[float | None, float | None]:
    """The run's interval of ``column`` in ``row``: its ``_lo``/``_hi`` columns, else the 95 %
    interval of the median of its raw samples (``wall_ms`` → ``wall_samples_ms``)."""
    lo, hi = finite_number(row.get(f"{column}_lo")), finite_number(row.get(f"{column}_hi"))
    if lo is not None and hi is not None:
        return lo, hi
    samples = row.get(f"{column[:-3]}_samples_ms") if column.endswith("_ms") else None
    if isinstance(samples, list) and len(samples) >= 2:
        from ..measurement.stats import median_interval

        found = median_interval([float(s) for s in samples])
        return found.lo, found.hi
    return None, None


def histories(store: ResultsStore, quantity: str, *, machine: str | None = None,
              size: str | None = None, where: Mapping[str, str] | None = None,
              min_runs: int = 2, alpha: float = ALPHA) -> list[History]:
    """The history of every measurement of ``quantity`` (see :func:`parse_quantity`) in
    ``store``: one :class:`History` per measurement and machine with at least ``min_runs``
    runs, change points found at significance ``alpha``. ``machine`` keeps the machines whose
    id starts with it, ``size`` one experiment size, ``where`` the rows whose column equals the
    given text (``{"scene": "car"}``). ValueError for a column the store does not hold (naming
    the closest ones)."""
    import pyarrow as pa

    experiment, table, column = parse_quantity(quantity)
    schema = store.query("SELECT * FROM rows LIMIT 0").schema
    stored = schema.names
    if column not in stored:
        close = difflib.get_close_matches(column, stored, n=4)
        hint = f" (closest: {', '.join(close)})" if close else ""
        raise ValueError(f"the results store {store.root} holds no column {column!r}{hint}")
    missing = [c for c in (where or {}) if c not in stored]
    if missing:
        raise ValueError(f"the results store {store.root} holds no column {missing[0]!r}")
    conditions = [f"r.{_column(column)} IS NOT NULL"]
    if experiment is not None:
        conditions.append(f"r.experiment = {_quoted(experiment)}")
    if table is not None:
        conditions.append(f"r.\"table\" = {_quoted(table)}")
    if "experiment_size" in stored:
        conditions.append(f"r.experiment_size = {_quoted(size)}" if size is not None
                          else "r.experiment_size IS DISTINCT FROM 'tiny'")
    if machine is not None:
        conditions.append(f"starts_with(CAST(u.machine_id AS VARCHAR), {_quoted(machine)})")
    # the text columns (the measurement's parameters) and the quantity's own, not the rest
    wanted = {"run_id", "row_index", "experiment", "table", "experiment_size", column,
              f"{column}_lo", f"{column}_hi", f"{column[:-3]}_samples_ms", *(where or {})}
    keep = [f.name for f in schema if f.name in wanted or pa.types.is_string(f.type)]
    rows = store.query(
        f"SELECT {', '.join('r.' + _column(c) for c in keep)}, "
        f"CAST(u.started AS VARCHAR) AS {_RUN[0]}, "
        f"CAST(u.\"commit\" AS VARCHAR) AS {_RUN[1]}, CAST(u.machine_id AS VARCHAR) AS "
        f"{_RUN[2]} FROM rows r JOIN runs u ON r.run_id = u.run_id "
        f"WHERE {' AND '.join(conditions)} "
        f"ORDER BY {_RUN[0]}, r.run_id, r.row_index").to_pylist()
    series: dict[tuple, list[dict[str, Any]]] = {}
    seen: dict[tuple, int] = {}
    for row in rows:
        if any(str(row.get(c)) != str(v) for c, v in (where or {}).items()):
            continue
        run_key = {k: v for k, v in row.items() if k not in _RUN}
        key = measurement_key(run_key)
        occurrence = seen.get((row["run_id"], key), 0)
        seen[(row["run_id"], key)] = occurrence + 1
        series.setdefault((key, occurrence, row[_RUN[2]]), []).append(row)
    found = []
    for (key, occurrence, machine_id), group in series.items():
        points, missing_values = [], 0
        for row in group:
            value = finite_number(row.get(column))
            if value is None:
                missing_values += 1
                continue
            lo, hi = _interval(row, column)
            points.append(RunValue(str(row["run_id"]), str(row[_RUN[0]]), row[_RUN[1]],
                                   row.get("experiment_size"), value, lo, hi))
        if len(points) < min_runs:
            continue
        exp, tab, size_of, params = key
        measurement = ", ".join(f"{c}={v}" for c, v in params if v)
        measurement += f" #{occurrence + 1}" if occurrence else ""
        changes = tuple(change_points([p.value for p in points], alpha=alpha))
        found.append(History(str(exp), str(tab), measurement, column, str(machine_id), size_of,
                             tuple(points), changes, missing_values))
    return sorted(found, key=lambda h: (h.experiment, h.table, h.measurement, h.machine_id,
                                        h.size or ""))
