"""The sweep figure of the fig_pixel_exact experiment, drawn from its table rows."""

from __future__ import annotations

from workbench.output.tables import atomic_open


def plot_sweep(rows: list[dict], path) -> None:
    """Mean colour error (1/255) against wall time per frame (ms), per vertex and per pixel,
    over the quadrisection and the resolution sweeps (log error axis), as a PNG at ``path``."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(10, 4), dpi=100)
    for ax, sweep, label in zip(axes, ("quadrisection", "resolution"),
                                ("quadrisection threshold", "mesh resolution")):
        for shading, marker in (("per_vertex", "o"), ("per_pixel", "s")):
            pts = [(row["wall_ms"], row["mean_diff_255"]) for row in rows
                   if row["sweep"] == sweep and row["path"] == shading]
            if pts:
                x, y = zip(*pts)
                ax.plot(x, y, marker=marker, label=shading.replace("_", " "))
        ax.axhline(1.0, color="grey", lw=0.8, ls="--")
        ax.set_xlabel("wall time per frame [ms]")
        ax.set_ylabel("mean colour error [1/255]")
        ax.set_yscale("log")
        ax.set_title(f"run time against error: {label}")
        ax.legend()
    fig.tight_layout()
    with atomic_open(path, "wb") as fh:
        fig.savefig(fh, format="png")
    plt.close(fig)
