"""One results store for every measurement: a folder of Parquet files, queried with DuckDB.

Layout under the root (one file per write, so concurrent writers never touch the same file)::

    machines/<machine_id>.parquet              one row per machine fingerprint
    runs/<run_id>.parquet                      one row per run
    rows/run_id=<run_id>/<uuid4 hex>.parquet   one file per ``append_rows`` call

Every file is written to a hidden temporary file in its folder (``.<name>.<pid>@<host>.<hex>.tmp``),
flushed, fsync'd and then moved into place (``os.replace``; ``os.link`` where an existing file
must win). Readers only list ``*.parquet`` names not starting with ``.``, so a writer killed
mid-write leaves at most a hidden temporary file, which ``ResultsStore.clean`` removes. A file
to be written that exists and is not a regular file, and a folder under the root that is a
symbolic link or not a folder, are refused (ValueError) before anything is written
(:mod:`workbench.output.targets`); the root itself may be a link to the store's folder.

Types. Within one ``append_rows`` call each column is normalised: numpy scalars become Python
values; all-bool → BOOLEAN; all-int → BIGINT; ints and floats → DOUBLE (NaN and ±inf kept);
all-str → VARCHAR; lists, tuples and 1-D arrays of numbers → DOUBLE[]; all-None → the Parquet
NULL type; any other mixture → VARCHAR (``str`` of each value, bools as ``true``/``false`` and
sequences as ``[a, b]``, as DuckDB casts them). Across files DuckDB's ``union_by_name`` settles
a column's type: BIGINT+DOUBLE → DOUBLE, BOOLEAN+number → the number, anything+VARCHAR →
VARCHAR, and NULL-typed columns take the other files' type. That is why an all-None column is
written as the NULL type rather than as VARCHAR nulls: a VARCHAR column in one file would turn
the column into VARCHAR everywhere. DuckDB 2.0 refuses only one mixture, a list in one file
and a scalar in another ("Unimplemented type for cast"); for such columns ``connect`` reads the
footers of every file (cached by path, size and mtime), groups the files by which side they
are on, casts the column to VARCHAR in each group and joins the groups with
``UNION ALL BY NAME``. A column NULL-typed in every file reads as VARCHAR.

``connect`` sees the files present when it is called (the views name them one by one, with
``hive_partitioning=false``, so ``run_id`` comes once, from the files, as VARCHAR).
"""

from __future__ import annotations

import os
import re
import secrets
import socket
import time
import uuid
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ..output.swap import process_alive
from ..output.targets import output_folder, output_target

if TYPE_CHECKING:
    import duckdb
    import pyarrow as pa

RESULTS_ENV = "WORKBENCH_RESULTS"
TEMP_MAX_AGE_S = 3600.0
"""Age (seconds) after which ``clean`` removes a temporary file even if its writer lives."""

_ID = re.compile(r"[A-Za-z0-9_-][A-Za-z0-9_.-]*")
_HOST = re.sub(r"[^A-Za-z0-9-]", "-", socket.gethostname())[:63]
_TEMP = re.compile(r"\.(?P<name>.+)\.(?P<pid>\d+)@(?P<host>[A-Za-z0-9-]*)\.[0-9a-f]+\.tmp")
_JOINED = ("cpu", "renderer")
_READ = "union_by_name=true, hive_partitioning=false"


def results_root(explicit: str | os.PathLike | None = None,
                 figures: str | os.PathLike = "figures") -> Path:
    """The store's root folder: ``explicit`` if given, else ``$WORKBENCH_RESULTS`` if set and
    non-empty, else ``<figures>/results``. Creates nothing."""
    if explicit is not None:
        return Path(explicit)
    env = os.environ.get(RESULTS_ENV, "")
    return Path(env) if env else Path(figures) / "results"


def _check_id(value: Any, what: str) -> str:
    if not isinstance(value, str) or not _ID.fullmatch(value):
        raise ValueError(f"{what} must be a str of [A-Za-z0-9_.-] not starting with '.', "
                         f"got {value!r}")
    return value


def _plain(value):
    """numpy scalars → Python scalars; everything else unchanged."""
    return value.item() if isinstance(value, np.generic) else value


def _text(value) -> str:
    value = _plain(value)
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (list, tuple, np.ndarray)):
        return str([_plain(v) for v in value])
    return str(value)


def _column(values: list) -> pa.Array:
    """One normalised Arrow column from raw Python values (see the module docstring)."""
    import pyarrow as pa

    types = set(map(type, values))
    if any(issubclass(t, np.generic) for t in types):
        values = [_plain(v) for v in values]
        types = set(map(type, values))
    types.discard(type(None))
    try:
        if not types:
            return pa.nulls(len(values))
        if types == {bool}:
            return pa.array(values, pa.bool_())
        if types == {int}:
            return pa.array(values, pa.int64())
        if types == {int, float}:
            values = [None if v is None else float(v) for v in values]
        if types <= {int, float}:
            return pa.array(values, pa.float64())
        if types == {str}:
            return pa.array(values, pa.string())
        if types <= {list, tuple, np.ndarray}:
            return pa.array(values, pa.list_(pa.float64()))
    except (pa.ArrowInvalid, pa.ArrowTypeError, OverflowError):
        pass  # e.g. an int beyond int64, a list holding strings: keep it as text
    return pa.array([None if v is None else _text(v) for v in values], pa.string())


def _table(rows: Sequence[dict], fixed: dict[str, Any], index: bool = False) -> pa.Table:
    """Rows plus the ``fixed`` columns (same value in every row) as one Arrow table; with
    ``index``, ``run_id`` and ``row_index`` (0, 1, ...) come first."""
    import pyarrow as pa

    names: dict[str, None] = {}
    for i, row in enumerate(rows):
        if not isinstance(row, dict):
            raise TypeError(f"row {i} is a {type(row).__name__}, rows must be dicts")
        names.update(dict.fromkeys(row))
    if index and ("row_index" in names or "row_index" in fixed):
        raise ValueError("row_index is set by append_rows; rows and common must not set it")
    for name in names:
        if not isinstance(name, str):
            raise TypeError(f"column names must be str, got {name!r}")
        if name in fixed and any(row.get(name, fixed[name]) != fixed[name] for row in rows):
            raise ValueError(f"rows set column {name!r}, which this call sets to {fixed[name]!r}")
    columns = {name: _column([value] * len(rows)) for name, value in fixed.items()}
    if index:
        columns = {"run_id": columns.pop("run_id"),
                   "row_index": pa.array(np.arange(len(rows), dtype=np.int64)), **columns}
    for name in names:
        if name not in columns:
            columns[name] = _column([row.get(name) for row in rows])
    return pa.table(columns)


def _fsync_dir(folder: Path) -> None:
    try:
        fd = os.open(folder, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)
    except OSError:
        pass  # not every file system syncs folders; the file itself is synced


def _write(table: pa.Table, path: Path, root: Path, exclusive: bool = False) -> bool:
    """Write ``table`` to ``path`` (a file under the store's ``root``) atomically; returns
    False (writing nothing) where ``exclusive`` and ``path`` already exists. The folders
    between ``root`` and ``path`` are made as needed; one that is a symbolic link or not a
    folder is refused (ValueError), as is a ``path`` that exists and is not a regular file."""
    import pyarrow.parquet as pq

    root.mkdir(parents=True, exist_ok=True)
    for folder in reversed(path.relative_to(root).parents[:-1]):
        output_folder(root / folder, create=True)
    output_target(path)
    tmp = path.with_name(f".{path.name}.{os.getpid()}@{_HOST}.{secrets.token_hex(4)}.tmp")
    try:
        with open(tmp, "xb") as handle:
            pq.write_table(table, handle)
            handle.flush()
            os.fsync(handle.fileno())
        if exclusive:
            try:
                os.link(tmp, path)  # fails if path exists: the first writer wins
            except FileExistsError:
                output_target(path)
                return False
            except OSError:  # no hard links on this file system: check, then move
                if os.path.lexists(output_target(path)):
                    return False
                os.replace(tmp, path)
        else:
            os.replace(tmp, output_target(path))
    finally:
        try:
            os.unlink(tmp)
        except FileNotFoundError:
            pass
    _fsync_dir(path.parent)
    return True


def _quote(name: str) -> str:
    return '"' + name.replace('"', '""') + '"'


def _paths(files: Sequence[Path]) -> str:
    return "[" + ", ".join("'" + str(f).replace("'", "''") + "'" for f in files) + "]"


class ResultsStore:
    """Measurement rows, runs and machines under one root folder (see the module docstring)."""

    def __init__(self, root: str | os.PathLike):
        self.root = Path(root)
        self._schemas: dict[tuple, dict[str, str]] = {}

    # writing -------------------------------------------------------------------------------

    def record_machine(self, machine: dict) -> None:
        """Record a machine fingerprint as ``machines/<machine_id>.parquet``; returns None.

        Writes nothing if that id is recorded already (same id = same fingerprint). Refuses a
        non-dict, or a missing or malformed ``machine_id`` (ValueError).
        """
        if not isinstance(machine, dict):
            raise TypeError(f"machine must be a dict, got {type(machine).__name__}")
        machine_id = _check_id(machine.get("machine_id"), "machine_id")
        path = self.root / "machines" / f"{machine_id}.parquet"
        if not output_target(path).exists():
            _write(_table([machine], {}), path, self.root, exclusive=True)

    def record_run(self, run: dict) -> None:
        """Record one run as ``runs/<run_id>.parquet``; returns None.

        Needs ``run_id`` and ``machine_id`` (str of ``[A-Za-z0-9_.-]``). Refuses a run_id that
        is recorded already (ValueError), even one recorded by another process at the same time.
        """
        if not isinstance(run, dict):
            raise TypeError(f"run must be a dict, got {type(run).__name__}")
        run_id = _check_id(run.get("run_id"), "run_id")
        _check_id(run.get("machine_id"), "machine_id")
        path = self.root / "runs" / f"{run_id}.parquet"
        if (output_target(path).exists()
                or not _write(_table([run], {}), path, self.root, exclusive=True)):
            raise ValueError(f"run {run_id!r} is recorded already in {self.root}")

    def append_rows(self, run_id: str, rows: Sequence[dict], **common: Any) -> Path | None:
        """Write ``rows`` of run ``run_id`` as one new file; returns its path (None for no rows).

        Each row gets ``run_id``, ``row_index`` (0, 1, ... within this call) and every key of
        ``common`` (e.g. ``experiment="render_paths"``); values are normalised as the module
        docstring says. Refuses a malformed ``run_id``, a ``row_index`` key in rows or
        ``common`` and rows that set ``run_id`` or a ``common`` key to another value
        (ValueError), rows that are not dicts and column names that are not str (TypeError).
        """
        _check_id(run_id, "run_id")
        rows = list(rows)
        if not rows:
            return None
        table = _table(rows, {"run_id": run_id, **common}, index=True)
        path = self.root / "rows" / f"run_id={run_id}" / f"{uuid.uuid4().hex}.parquet"
        _write(table, path, self.root)
        return path

    # reading -------------------------------------------------------------------------------

    def _files(self, kind: str) -> list[Path]:
        """The published Parquet files of ``kind`` ("machines", "runs" or "rows"), sorted."""
        base = self.root / kind
        found = base.glob("*/*.parquet" if kind == "rows" else "*.parquet")
        return sorted(p for p in found
                      if not any(part.startswith(".") for part in p.relative_to(base).parts))

    def _kinds(self, path: Path) -> dict[str, str]:
        """Column name → "list", "null" or "scalar" for one file, from its footer (cached)."""
        import pyarrow as pa
        import pyarrow.parquet as pq

        stat = path.stat()
        key = (str(path), stat.st_size, stat.st_mtime_ns)
        if key not in self._schemas:
            self._schemas[key] = {
                f.name: "list" if pa.types.is_list(f.type) or pa.types.is_large_list(f.type)
                else "null" if pa.types.is_null(f.type) else "scalar"
                for f in pq.read_schema(path)}
        return self._schemas[key]

    def _union(self, files: Sequence[Path], empty: str) -> tuple[str, set[str]]:
        """SQL reading ``files`` by name (see the module docstring), and its column names;
        ``empty`` (SQL) where there are no files."""
        if not files:
            return empty, set()
        kinds = [self._kinds(f) for f in files]
        seen: dict[str, set[str]] = {}
        for file_kinds in kinds:
            for name, kind in file_kinds.items():
                seen.setdefault(name, set()).add(kind)
        mixed = sorted(n for n, k in seen.items() if {"list", "scalar"} <= k)
        groups: dict[tuple, list[Path]] = {}
        for path, file_kinds in zip(files, kinds):
            groups.setdefault(tuple(n in file_kinds and file_kinds[n] == "list" for n in mixed),
                              []).append(path)
        parts = []
        for group in groups.values():
            present = [n for n in mixed if any(n in self._kinds(f) for f in group)]
            cast = ", ".join(f"CAST({_quote(n)} AS VARCHAR) AS {_quote(n)}" for n in present)
            parts.append(f"SELECT *{f' REPLACE ({cast})' if cast else ''} "
                         f"FROM read_parquet({_paths(group)}, {_READ})")
        sql = " UNION ALL BY NAME ".join(parts)
        nulls = [n for n, k in seen.items() if k == {"null"}]
        if nulls or len(parts) > 1:
            cast = ", ".join(f"CAST({_quote(n)} AS VARCHAR) AS {_quote(n)}" for n in nulls)
            sql = f"SELECT *{f' REPLACE ({cast})' if cast else ''} FROM ({sql})"
        return sql, set(seen)

    def _runs_sql(self, machines_sql: str, machine_cols: set[str]) -> str:
        """SQL for the ``runs`` view: every run with its machine's ``cpu`` and ``renderer``."""
        runs_sql, run_cols = self._union(
            self._files("runs"),
            "SELECT NULL::VARCHAR AS run_id, NULL::VARCHAR AS machine_id WHERE false")
        run_cols = run_cols or {"run_id", "machine_id"}
        exclude, joined = [], []
        for name in _JOINED:
            quoted = _quote(name)
            if name in machine_cols and name in run_cols:
                exclude.append(quoted)
                joined.append(f"COALESCE(m.{quoted}, r.{quoted}) AS {quoted}")
            elif name in machine_cols:
                joined.append(f"m.{quoted}")
            elif name not in run_cols:
                joined.append(f"NULL::VARCHAR AS {quoted}")
        star = f"r.* EXCLUDE ({', '.join(exclude)})" if exclude else "r.*"
        return (f"SELECT {', '.join([star, *joined])} FROM ({runs_sql}) r "
                f"LEFT JOIN ({machines_sql}) m "
                "ON CAST(r.machine_id AS VARCHAR) = CAST(m.machine_id AS VARCHAR)")

    def connect(self) -> duckdb.DuckDBPyConnection:
        """An in-memory DuckDB connection with views ``machines``, ``runs`` and ``rows``.

        ``runs`` is every run LEFT JOINed with its machine's ``cpu`` and ``renderer``
        (VARCHAR nulls where no machine has them). The views see the files present now; on an
        empty store they are empty, ``rows`` with ``run_id`` and ``row_index``, ``runs`` with
        ``run_id``, ``machine_id``, ``cpu`` and ``renderer``, ``machines`` with ``machine_id``.
        """
        import duckdb

        machines_sql, machine_cols = self._union(
            self._files("machines"), "SELECT NULL::VARCHAR AS machine_id WHERE false")
        runs_sql = self._runs_sql(machines_sql, machine_cols)
        rows_sql, _ = self._union(
            self._files("rows"),
            "SELECT NULL::VARCHAR AS run_id, NULL::BIGINT AS row_index WHERE false")
        con = duckdb.connect()
        try:
            con.execute(f"CREATE VIEW machines AS {machines_sql}")
            con.execute(f"CREATE VIEW runs AS {runs_sql}")
            con.execute(f"CREATE VIEW rows AS {rows_sql}")
        except BaseException:
            con.close()
            raise
        return con

    def query(self, sql: str) -> pa.Table:
        """The result of one SQL query over the views of ``connect``, as a pyarrow Table
        (``con.sql(sql).to_arrow_table()``, DuckDB 2.0's copy-free way); DuckDB errors pass."""
        con = self.connect()
        try:
            return con.sql(sql).to_arrow_table()
        finally:
            con.close()

    def run_ids(self) -> list[str]:
        """The recorded run ids, oldest first: by ``started`` where runs have one (runs
        without come after), then by the run file's mtime."""
        import duckdb

        files = self._files("runs")
        if not files:
            return []
        sql, cols = self._union(files, "")
        started = "started" if "started" in cols else "NULL"
        con = duckdb.connect()
        try:
            found = con.sql(f"SELECT CAST(run_id AS VARCHAR), {started} FROM ({sql})").fetchall()
        finally:
            con.close()
        mtimes = {f.name[:-len(".parquet")]: f.stat().st_mtime for f in files}
        found.sort(key=lambda r: (r[1] is None, r[1] if r[1] is not None else 0,
                                  mtimes.get(r[0], 0.0), r[0]))
        return [run_id for run_id, _ in found]

    def clean(self) -> list[Path]:
        """Remove temporary files left by writers that died (same host, pid gone) or older than
        ``TEMP_MAX_AGE_S``; returns the removed paths. Published files are never touched."""
        now, removed = time.time(), []
        for pattern in ("machines/.*.tmp", "runs/.*.tmp", "rows/*/.*.tmp"):
            for path in self.root.glob(pattern):
                match = _TEMP.fullmatch(path.name)
                dead = bool(match and match["host"] == _HOST
                            and not process_alive(int(match["pid"])))
                try:
                    if dead or now - path.stat().st_mtime > TEMP_MAX_AGE_S:
                        path.unlink()
                        removed.append(path)
                except FileNotFoundError:
                    pass  # its writer finished (or another clean got there first)
        return removed
