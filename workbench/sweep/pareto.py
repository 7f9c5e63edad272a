"""The Pareto figure of a sweep: time against error per point, with the frontier of the
points no other is both faster and more exact than."""

from __future__ import annotations

import itertools
import math
from pathlib import Path

from ..output.tables import finite_number


def pareto_front(points: list[tuple[float, float]]) -> list[int]:
    """Indices of the non-dominated (time, error) pairs, both minimised, by increasing time:
    a pair is kept when no other is at most as slow and at most as wrong, and better in one."""
    order = sorted(range(len(points)), key=lambda i: points[i])
    front, best = [], math.inf
    for i in order:
        if points[i][1] < best:
            front.append(i)
            best = points[i][1]
    return front


def _axis_label(column: str, reference: str | None) -> str:
    against = f" against {reference}" if reference else ""
    return {
        "wall_ms": "wall time per draw (ms, median)",
        "point_ms": "wall time of the whole untimed point (ms)",
        "mean_diff_255": f"mean absolute difference{against} (1/255)",
        "max_diff_255": f"largest absolute difference{against} (1/255)",
        "share_differing": f"share of pixels differing{against} (0–1)",
        "hausdorff_pct_diag": "Hausdorff original → simplified (% of diagonal)",
        "hausdorff_lower_mm": "Hausdorff original → simplified, lower bound (model units)",
        "hausdorff_mm": "Hausdorff original → simplified, certified (model units)",
    }.get(column, column)


def save_pareto(path: Path, rows: list[dict], *, time_column: str, metric: str | None,
                title: str, reference: str | None = None) -> Path:
    """Time against error, one colour per path (and one marker per simplifier), the Pareto
    frontier as a step line through the non-dominated points; the time axis is logarithmic
    when it spans more than 10×. Written atomically; a sweep without an error column or
    without plottable points gets a figure saying so."""
    import io

    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from ..output.tables import atomic_write_bytes

    fig = Figure(figsize=(8, 5.5), dpi=100)
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    data = [(r, finite_number(r.get(time_column)), finite_number(r.get(metric)) if metric else None)
            for r in rows if not r.get("error")]
    data = [(r, x, y) for r, x, y in data if x is not None and x > 0 and y is not None]
    if not data:
        why = "no error column (set reference or sweep a simplifier)" if metric is None \
            else "no point with a time and an error"
        ax.text(0.5, 0.5, why, ha="center", va="center", transform=ax.transAxes)
    else:
        paths = dict.fromkeys(r["path"] for r, _, _ in data)
        colours = {p: f"C{i % 10}" for i, p in enumerate(paths)}
        simplifiers = dict.fromkeys(r.get("simplifier") for r, _, _ in data)
        markers = {s: "osD^v<>ph*"[i % 10] for i, s in enumerate(simplifiers)}
        for (path_name, simplifier), group in itertools.groupby(
                sorted(data, key=lambda d: (d[0]["path"], str(d[0].get("simplifier")))),
                key=lambda d: (d[0]["path"], d[0].get("simplifier"))):
            group = list(group)
            label = path_name if simplifier is None else f"{path_name}, {simplifier}"
            ax.scatter([x for _, x, _ in group], [y for _, _, y in group], s=28,
                       color=colours[path_name], marker=markers[simplifier], label=label,
                       zorder=3)
        front = pareto_front([(x, y) for _, x, y in data])
        fx = [data[i][1] for i in front]
        fy = [data[i][2] for i in front]
        ax.step(fx, fy, where="post", color="black", linewidth=1, zorder=2,
                label="Pareto frontier")
        ax.scatter(fx, fy, s=110, facecolors="none", edgecolors="black", linewidths=1,
                   zorder=4)
        xs = [x for _, x, _ in data]
        if max(xs) > 10 * min(xs):
            ax.set_xscale("log")
        positive = [y for _, _, y in data if y > 0]
        if positive and max(positive) > 100 * min(positive):
            # errors over decades; exact points (error 0) stay visible on a linear stretch
            if len(positive) == len(data):
                ax.set_yscale("log")
            else:
                ax.set_yscale("symlog", linthresh=min(positive))
        ax.legend(fontsize=8)
        ax.grid(True, which="both", alpha=0.3)
    ax.set_xlabel(_axis_label(time_column, None) + (" [log]" if ax.get_xscale() == "log" else ""))
    scale = {"log": " [log]", "symlog": " [symlog]"}
    ax.set_ylabel((_axis_label(metric, reference) if metric else "error")
                  + scale.get(ax.get_yscale(), ""))
    ax.set_title(title, fontsize=10)
    fig.tight_layout()
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png")
    return atomic_write_bytes(path, buffer.getvalue())
