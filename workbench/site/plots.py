"""The site's figures, drawn with matplotlib (Agg, no display) into PNG files: a Pareto plot of
time against error per stored table that has both (through
:func:`workbench.sweep.pareto.save_pareto`), and a history plot per measured quantity a claim
reads (each measurement's value per run with its interval, change points marked).

Only what a page shows is drawn; each figure is closed (garbage) once written, none is kept.
"""

from __future__ import annotations

import io
import math
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..output.tables import atomic_write_bytes, finite_number
from ..results.compare import ERROR_COLUMNS
from ..sweep.pareto import save_pareto

if TYPE_CHECKING:
    from ..results.history import History

MAX_LINES = 8
"""The most histories one history plot draws (the tables under it list them all)."""
_MINIMISED = tuple(c for c in ERROR_COLUMNS if c not in ("psnr_db", "ssim"))  # higher is better
_ERROR_WORDS = ("error", "diff", "hausdorff", "deviation")
_BOUNDS = ("_lo", "_hi", "_min", "_max", "_samples_ms", "_pairs")
_LABELS = ("path", "case", "function", "scene", "style")


def _numeric(rows: Sequence[dict[str, Any]], column: str) -> bool:
    values = [r.get(column) for r in rows if r.get(column) is not None]
    return bool(values) and all(finite_number(v) is not None or isinstance(v, float)
                                for v in values)


def pareto_columns(rows: Sequence[dict[str, Any]]) -> tuple[str, str] | None:
    """The (time, error) columns of a table for its Pareto plot, or None where it lacks one:
    the time is ``wall_ms`` where the rows carry it, else the first numeric column ending in
    ``_ms``, ``_s`` or ``seconds`` (not an interval bound); the error is the first of
    ``max_diff_255``, ``mean_diff_255``, ``share_differing`` the rows carry, else the first
    numeric column naming an error, difference, Hausdorff distance or deviation. Needs two rows
    with a positive time and a finite error."""
    columns = list(dict.fromkeys(c for r in rows for c in r))
    plain = [c for c in columns if not c.endswith(_BOUNDS) and _numeric(rows, c)]
    times = (["wall_ms"] if "wall_ms" in plain else []) + [
        c for c in plain if c.endswith(("_ms", "_s", "seconds")) and c != "wall_ms"]
    errors = [c for c in _MINIMISED if c in plain] + [
        c for c in plain if any(w in c.lower() for w in _ERROR_WORDS) and c not in _MINIMISED
        and c not in times]
    if not times or not errors:
        return None
    time, error = times[0], errors[0]
    points = [r for r in rows if (finite_number(r.get(time)) or 0) > 0
              and finite_number(r.get(error)) is not None]
    return (time, error) if len(points) >= 2 else None


def pareto_plot(path: Path, rows: Sequence[dict[str, Any]], time: str, error: str,
                title: str) -> Path:
    """Write the Pareto PNG of ``rows`` (``error`` against ``time``, each point named by its
    path, case, function, scene or style, else its row number, and its scene where the table
    holds several) to ``path`` atomically."""
    named = []
    scenes = {row.get("scene") for row in rows} - {None}
    for i, row in enumerate(rows):
        label = next((str(row[c]) for c in _LABELS if row.get(c) is not None), f"row {i}")
        if len(scenes) > 1 and row.get("scene") is not None and label != str(row["scene"]):
            label += f" ({row['scene']})"  # a table of several scenes: name each point's
        named.append({**row, "path": label})
    return save_pareto(path, named, time_column=time, metric=error, title=title)


def history_plot(path: Path, histories: Sequence[History], title: str, unit: str = "") -> Path:
    """Write the PNG of ``histories`` (at most :data:`MAX_LINES`) to ``path`` atomically: per
    history its value per run (oldest first, numbered from 1) with the run's interval as an
    error bar where stored (a bound on the wrong side of the value drawn as none), and a
    dashed vertical line before the first run after each change point. The value axis is
    logarithmic where the values span more than 10×; ``unit`` labels it."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(8, 4), dpi=80)
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    values = []
    for k, history in enumerate(histories[:MAX_LINES]):
        colour = f"C{k % 10}"
        xs = list(range(1, len(history.points) + 1))
        ys = [p.value for p in history.points]
        values += [v for v in ys if v is not None and math.isfinite(v) and v > 0]
        low = [max(p.value - p.lo, 0.0) if p.lo is not None else 0.0 for p in history.points]
        high = [max(p.hi - p.value, 0.0) if p.hi is not None else 0.0 for p in history.points]
        label = f"{history.measurement} ({history.machine_id[:8]}, {history.size})"
        ax.errorbar(xs, ys, yerr=[low, high], color=colour, marker="o", markersize=3,
                    linewidth=1, capsize=2, label=label)
        for i, change in enumerate(history.changes):
            ax.axvline(change + 0.5, color=colour, linestyle="--", linewidth=1.2,
                       label="change point" if k == 0 and i == 0 else None)
    if not values:
        ax.text(0.5, 0.5, "no values", ha="center", va="center", transform=ax.transAxes)
    elif max(values) > 10 * min(values):
        ax.set_yscale("log")
    ax.set_xlabel("run (oldest first)")
    ax.set_ylabel(f"{title.rsplit('/', 1)[-1]}" + (f" ({unit})" if unit else ""))
    ax.set_title(title, fontsize=10)
    ax.grid(True, alpha=0.3)
    if values:
        ax.legend(fontsize=7)
    # fixed margins: tight_layout gives up on a legend of long measurement names
    fig.subplots_adjust(left=0.1, right=0.98, top=0.92, bottom=0.12)
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png")
    return atomic_write_bytes(path, buffer.getvalue())
