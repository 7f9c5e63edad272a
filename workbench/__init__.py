"""workbench: comparable OpenGL render paths for finite-element visualization, measured side by
side.

From Python, four names (each imported on first use, so that ``import workbench`` stays light:
no GL, no numba):

* ``workbench.load(path_or_name)`` — a scene: a mesh file (a keyword deck, a d3plot, …) or a
  built-in name (``car``, ``crash``, ``semicylinders``, …) (:func:`workbench.paths.facade.load`);
* ``workbench.render(scene, path="gouraud", *, size=(640, 480), camera=None, step=0,
  backend="gl", **style)`` — its image, (H, W, 4) uint8 RGBA, untimed
  (:func:`workbench.paths.facade.render`);
* ``workbench.measure(backend, scene, path, ...)`` — the same image with its timing and a table
  row (:func:`workbench.measurement.rows.measure`);
* ``workbench.view(scene, path, **style)`` — a live Jupyter view (:func:`workbench.viewer.view`).
"""

__version__ = "0.1.0"

__all__ = ["__version__", "load", "measure", "render", "view"]


def __getattr__(name: str):
    """``workbench.load``, ``render``, ``measure`` and ``view`` (see the module notes), imported
    on first use so that ``import workbench`` stays light; AttributeError for any other
    name."""
    if name == "load":
        from .paths.facade import load

        return load
    if name == "render":
        from .paths.facade import render

        return render
    if name == "measure":
        from .measurement.rows import measure

        return measure
    if name == "view":
        from .viewer import view

        return view
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
