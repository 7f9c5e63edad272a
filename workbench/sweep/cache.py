"""The row cache of a sweep: one JSON file per point under ``DIR/points``, named by the point's
content key and written whole (temporary file, then rename)."""

from __future__ import annotations

import json
from pathlib import Path

from ..output.tables import atomic_write_text
from ..output.targets import output_folder
from .points import Point


def json_default(value):
    """``value`` as a plain JSON value (numpy scalars and arrays); TypeError for anything else
    (``json.dumps``'s ``default``)."""
    import numpy as np

    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    raise TypeError(f"cannot store {type(value).__name__} in a sweep row")


def cached_row(points_dir: Path, key: str) -> dict | None:
    """The stored row of point ``key``, None when absent or unreadable."""
    try:
        with open(points_dir / f"{key}.json", encoding="utf-8") as handle:
            row = json.load(handle).get("row")
    except (FileNotFoundError, ValueError, AttributeError):
        return None
    return row if isinstance(row, dict) else None


def store_row(points_dir: Path, key: str, point: Point, row: dict) -> dict:
    """Write point ``key``'s row (and parameters) whole; returns the row as stored (plain JSON
    values, so computed and cached rows read the same)."""
    text = json.dumps(dict(key=key, params=point.params(), row=row), default=json_default,
                      indent=1)
    atomic_write_text(output_folder(points_dir) / f"{key}.json", text)
    return json.loads(text)["row"]
