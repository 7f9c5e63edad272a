"""The figures of the simplify_tradeoff experiment, drawn from its table rows: error against
triangles and time per mesh, and triangles against the certified distance at equal error."""

from __future__ import annotations

from pathlib import Path

from workbench.output.tables import atomic_open


def save_tradeoff_figure(path: Path, rows: list[dict], title: str) -> None:
    """One-sided Hausdorff distance (certified upper bound, model units) against triangles and
    against simplification time, one line per method and scope (log axes), as a PNG."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax_n, ax_t) = plt.subplots(1, 2, figsize=(14, 4.6), dpi=100, sharey=True)
    for ax in (ax_n, ax_t):  # more methods than the default ten colours
        ax.set_prop_cycle(color=plt.cm.tab20.colors)
    for method, scope in dict.fromkeys((r["method"], r["scope"]) for r in rows):
        sel = sorted((r for r in rows if r["method"] == method and r["scope"] == scope
                      and r.get("hausdorff_mm")), key=lambda r: r["triangles"])
        if not sel:
            continue
        style = "o-" if method.startswith("ours") else ("x--" if scope == "whole mesh" else "s:")
        error = [max(r["hausdorff_mm"], 1e-12) for r in sel]
        label = f"{method} ({scope})"
        ax_n.plot([r["triangles"] for r in sel], error, style, label=label, markersize=4)
        ax_t.plot([r["seconds"] for r in sel], error, style, label=label, markersize=4)
    ax_n.set_xlabel("triangles")
    ax_t.set_xlabel("simplification time (s)")
    for ax in (ax_n, ax_t):
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.grid(True, which="both", alpha=0.3)
    ax_n.set_ylabel("one-sided Hausdorff, original → simplified\n"
                    "(upper bound; model units, mm for the car and panels)")
    ax_t.legend(fontsize=7, loc="center left", bbox_to_anchor=(1.02, 0.5))
    fig.suptitle(title)
    fig.tight_layout()
    with atomic_open(path, "wb") as fh:
        fig.savefig(fh, format="png")
    plt.close(fig)


def save_equal_error_figure(path: Path, rows: list[dict]) -> None:
    """Triangles against the certified one-sided distance, one panel per mesh, one line per
    method and scope (log axes)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    meshes = list(dict.fromkeys(r["scene"] for r in rows))
    series = list(dict.fromkeys((r["method"], r["scope"]) for r in rows))
    colours = plt.get_cmap("tab20")
    fig, axes = plt.subplots(1, len(meshes), figsize=(5.5 * len(meshes) + 3, 4.6), dpi=100,
                             squeeze=False)
    handles = {}
    for ax, mesh in zip(axes[0], meshes):
        mine = [r for r in rows if r["scene"] == mesh]
        for i, (method, scope) in enumerate(series):
            sel = sorted((r for r in mine if r["method"] == method and r["scope"] == scope
                          and not r.get("failure")), key=lambda r: r["error"])
            if not sel:
                continue
            style = "o-" if method.startswith("ours") else ("x--" if scope == "whole mesh"
                                                            else "s:")
            line, = ax.plot([r["error"] for r in sel], [r["triangles"] for r in sel], style,
                            color=colours(i % 20), label=f"{method} ({scope})", markersize=4)
            handles.setdefault(line.get_label(), line)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("certified one-sided Hausdorff distance, original → simplified\n"
                      "(model units: mm for the car and the panels)")
        ax.set_ylabel("triangles reached")
        ax.set_title(mesh)
        ax.grid(True, which="both", alpha=0.3)
    fig.legend(list(handles.values()), list(handles), fontsize=7, loc="center right")
    fig.tight_layout(rect=(0, 0, 1 - 3 / (5.5 * len(meshes) + 3), 1))
    with atomic_open(path, "wb") as fh:
        fig.savefig(fh, format="png")
    plt.close(fig)
