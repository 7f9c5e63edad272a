"""workbench: comparable OpenGL render paths for finite-element visualization, measured side by
side."""

__version__ = "0.1.0"


def __getattr__(name: str):
    """``workbench.view``: the live Jupyter view (:func:`workbench.viewer.view`), imported on
    first use so that ``import workbench`` stays light."""
    if name == "view":
        from .viewer import view

        return view
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
