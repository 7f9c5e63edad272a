"""Tables from measurement rows: CSV for machines, aligned Markdown for people, written atomically.

A row is a plain dict; a table's columns are the union of its rows' keys in first-seen order.
Every file is written to a temporary file in the target folder and moved into place with
``os.replace``, so an interrupted run leaves the previous table (or none), never half of one.
A target that exists and is not a regular file (a device, FIFO, socket, directory or symbolic
link) is refused before anything is written (:func:`~workbench.output.targets.output_target`).
"""

from __future__ import annotations

import csv
import math
import os
import tempfile
from collections.abc import Iterable, Iterator, Sequence
from contextlib import contextmanager
from numbers import Integral, Real
from pathlib import Path
from typing import IO, Any

import numpy as np

from .targets import output_target

SIGNIFICANT_DIGITS = 4


def current_umask() -> int:
    """The process's file-mode creation mask (read without changing it for good)."""
    mask = os.umask(0)
    os.umask(mask)
    return mask


@contextmanager
def atomic_open(path: str | os.PathLike[str], mode: str = "w",
                **kwargs: Any) -> Iterator[IO[Any]]:
    """Open a temporary file beside ``path`` for writing; move it onto ``path`` on success.

    On an exception the temporary file is removed and ``path`` is left as it was.
    ``mode`` must be ``"w"`` or ``"wb"``; extra arguments go to ``open``. An existing ``path``
    that is not a regular file (device, FIFO, socket, directory, symbolic link) is refused with
    a ValueError, before the temporary file is made and again just before it would replace
    ``path``.
    """
    if mode not in ("w", "wb"):
        raise ValueError(f"mode must be 'w' or 'wb', got {mode!r}")
    path = output_target(path)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    os.chmod(tmp, 0o666 & ~current_umask())  # mkstemp makes 0600; a table is readable as any
    try:
        with os.fdopen(fd, mode, **kwargs) as handle:
            yield handle
            handle.flush()
            os.fsync(handle.fileno())
        os.replace(tmp, output_target(path))
    except BaseException:
        try:
            os.unlink(tmp)
        except FileNotFoundError:
            pass
        raise


def atomic_write_text(path: str | os.PathLike[str], text: str) -> Path:
    """Write ``text`` (UTF-8) to ``path`` atomically; returns the path."""
    with atomic_open(path, "w", encoding="utf-8", newline="") as handle:
        handle.write(text)
    return Path(path)


def atomic_write_bytes(path: str | os.PathLike[str], data: bytes) -> Path:
    """Write ``data`` to ``path`` atomically; returns the path."""
    with atomic_open(path, "wb") as handle:
        handle.write(data)
    return Path(path)


def _plain(value):
    """numpy scalars → Python scalars; everything else unchanged."""
    return value.item() if isinstance(value, np.generic) else value


# raw repetitions (lists of ms) go to the results store, not into a CSV or Markdown cell
STORE_ONLY_SUFFIX = "_samples_ms"


def table_columns(rows: Iterable[dict[str, Any]]) -> list[str]:
    """The union of the rows' keys in first-seen order, without the store-only columns of raw
    samples (names ending in ``_samples_ms``)."""
    columns: dict[str, None] = {}
    for row in rows:
        for key in row:
            columns.setdefault(key, None)
    return [c for c in columns if not str(c).endswith(STORE_ONLY_SUFFIX)]


def _check_rows(rows) -> list[dict]:
    rows = list(rows)
    for i, row in enumerate(rows):
        if not isinstance(row, dict):
            raise TypeError(f"row {i} is a {type(row).__name__}, rows must be dicts")
    return rows


def format_number(value: float, digits: int = SIGNIFICANT_DIGITS) -> str:
    """A float for people: ``digits`` significant digits, fixed-point between 1e-3 and 1e6.

    Infinities read ``∞``/``-∞``, NaN reads ``n/a``.
    """
    value = float(value)
    if math.isnan(value):
        return "n/a"
    if math.isinf(value):
        return "∞" if value > 0 else "-∞"
    if value == 0.0:
        return "0"
    magnitude = math.floor(math.log10(abs(value)))
    if magnitude >= 6 or magnitude < -3:
        return f"{value:.{digits - 1}e}"
    return f"{value:.{max(0, digits - 1 - magnitude)}f}"


def format_value(value: object) -> str:
    """One Markdown cell: numbers formatted readably, None empty, ``|`` escaped."""
    value = _plain(value)
    if value is None:
        return ""
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, Integral):
        return str(int(value))
    if isinstance(value, Real):
        return format_number(value)
    return str(value).replace("|", "\\|").replace("\n", " ")


def finite_number(value: Any) -> float | None:
    """``value`` as a float where it is a finite int or float (not a bool), else None."""
    value = _plain(value)
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return None
    return float(value) if math.isfinite(value) else None


def _is_number(value) -> bool:
    value = _plain(value)
    return isinstance(value, Real) and not isinstance(value, bool)


def markdown_table(rows: Sequence[dict[str, Any]], columns: Sequence[str] | None = None,
                   title: str | None = None, notes: Sequence[str] = (),
                   legend: Sequence[tuple[str, str, str]] = ()) -> str:
    """An aligned Markdown pipe table (numeric columns right-aligned), with an optional heading
    and ``notes`` (one paragraph each) between heading and table, and under it the ``legend``:
    one line per ``(column, unit, meaning)`` (unit "" for labels and counts)."""
    rows = _check_rows(rows)
    columns = list(table_columns(rows) if columns is None else columns)
    lines = [f"# {title}", ""] if title else []
    for note in notes:
        lines += [f"_{note}_", ""]
    if not columns:
        return "\n".join(lines + ["_no rows_", ""])
    cells = [[format_value(row.get(c)) for c in columns] for row in rows]
    header = [str(c).replace("|", "\\|") for c in columns]
    widths = [max([len(header[j]), 3] + [len(r[j]) for r in cells]) for j in range(len(columns))]
    numeric = [any(c in row for row in rows)
               and all(_is_number(row[c]) for row in rows if row.get(c) is not None)
               for c in columns]

    def line(values, right):
        padded = [v.rjust(w) if r else v.ljust(w) for v, w, r in zip(values, widths, right)]
        return "| " + " | ".join(padded) + " |"

    lines.append(line(header, [False] * len(columns)))
    lines.append("| " + " | ".join("-" * (w - 1) + ":" if r else "-" * w
                                   for w, r in zip(widths, numeric)) + " |")
    lines.extend(line(r, numeric) for r in cells)
    if legend:
        lines += ["", "Columns:", ""] + [legend_line(*entry) for entry in legend]
    return "\n".join(lines) + "\n"


def legend_line(column: str, unit: str, meaning: str) -> str:
    """One legend line under a Markdown table: ``- `column` (unit): meaning``."""
    unit = f" ({unit})" if unit else ""
    return f"- `{column}`{unit}: {meaning}".replace("\n", " ")


def _csv_value(value):
    value = _plain(value)
    return "" if value is None else value


def write_table(rows: Sequence[dict[str, Any]], directory: str | os.PathLike[str],
                name: str = "table",
                columns: Sequence[str] | None = None,
                title: str | None = None, notes: Sequence[str] = (),
                legend: Sequence[tuple[str, str, str]] = ()) -> tuple[Path, Path]:
    """Write ``rows`` as ``<directory>/<name>.csv`` and ``<name>.md``; returns both paths.

    ``columns`` picks and orders the columns (missing values stay empty); by default all keys in
    first-seen order, less the raw-sample lists (see :func:`table_columns`); ``notes`` go under
    the Markdown title and ``legend`` (``(column, unit, meaning)`` each) under its table.
    Floats are written to the CSV at full precision and to Markdown with four significant
    digits. Both files are replaced atomically; the Markdown is formatted before
    either is touched, so a row that cannot be formatted leaves the previous table in place.
    Refuses rows that are not dicts, a missing directory and (before writing either file) a
    ``.csv`` or ``.md`` target that exists and is not a regular file.
    """
    rows = _check_rows(rows)
    directory = Path(directory)
    if not directory.is_dir():
        raise FileNotFoundError(f"table directory {directory} does not exist")
    columns = list(table_columns(rows) if columns is None else columns)
    md_text = markdown_table(rows, columns, title, notes, legend)
    csv_path = output_target(directory / f"{name}.csv")
    md_path = output_target(directory / f"{name}.md")
    with atomic_open(csv_path, "w", encoding="utf-8", newline="") as handle:
        writer = csv.writer(handle)
        if columns:
            writer.writerow(columns)
        for row in rows:
            writer.writerow([_csv_value(row.get(c)) for c in columns])
    atomic_write_text(md_path, md_text)
    return csv_path, md_path


def _parse(text: str):
    if text == "":
        return None
    if text in ("True", "False"):
        return text == "True"
    try:
        return int(text)
    except ValueError:
        pass
    try:
        return float(text)
    except ValueError:
        return text


def read_table(csv_path: str | os.PathLike[str]) -> list[dict[str, Any]]:
    """Rows of a table written by :func:`write_table`.

    Empty cells come back as None, ``True``/``False`` as bools, cells that parse as int or float
    (``inf``, ``nan`` included) as numbers, everything else as strings.
    """
    with open(csv_path, newline="", encoding="utf-8") as handle:
        return [{k: _parse(v) for k, v in row.items()} for row in csv.DictReader(handle)]

