"""A live view of an FE mesh in Jupyter: ``workbench.view(scene, path, **style)``.

The view is drawn by the workbench's own headless EGL context (moderngl) through any mesh
render path, and shown by a jupyter_rfb remote frame buffer with ipywidgets controls:

* :mod:`.orbit` — the interactive camera (orbit, pan, zoom), float64, no GL;
* :mod:`.live` — :class:`LiveView`: the path prepared once, drawn per frame into an offscreen
  framebuffer, changed by camera, step and style (no Jupyter);
* :mod:`.widget` — the canvas, the controls and :func:`view` (imports jupyter_rfb and
  ipywidgets, so it is imported only when :func:`view` is called).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from .live import LiveView
from .orbit import Orbit

if TYPE_CHECKING:
    from .widget import Viewer

__all__ = ["LiveView", "Orbit", "view"]


def view(scene: Any, path: str | None = None, *, size: tuple[int, int] = (800, 600),
         device: int | str | None = None, **style: Any) -> Viewer:
    """A live view of ``scene`` (an FE mesh, or a spec string read by
    :func:`workbench.scene.builtin.load_scene`: ``"car"``, ``"semicylinders:64"``, a mesh file)
    drawn through mesh render path ``path`` (default ``gouraud``; with a ``field``
    ``pixel_color`` for a node field, ``element_color`` for an element field) with the style
    options ``style`` (``field``, ``bands``, ``value_range``, ``step``, ``threshold``,
    ``focus`` … as the path's style takes them; also ``angles=(azimuth, elevation)``,
    ``projection`` and ``up`` of the first view), in frames of ``size`` (W, H) pixels, on EGL
    device ``device``.

    Returns a :class:`~workbench.viewer.widget.Viewer` (an ipywidgets VBox): its ``canvas``
    is the jupyter_rfb widget (left drag orbits, right or Shift drag pans, the wheel zooms, a
    double click resets, a click on the exploded path picks the focus part), ``controls`` the
    step and style controls, ``live`` the :class:`LiveView`. Refused as the path and its style
    refuse (ValueError, KeyError for an unknown field); ImportError where jupyter_rfb or
    ipywidgets is missing.
    """
    from .widget import view as make_view

    return make_view(scene, path, size=size, device=device, **style)
