"""The Jupyter side of a live view: a jupyter_rfb canvas drawn by a
:class:`~workbench.viewer.live.LiveView`, and ipywidgets controls beside it.

:class:`ViewCanvas` turns jupyter_rfb events into view changes: a left drag orbits, a right
drag or a drag with Shift pans, the wheel zooms, a double click returns to the fitted view, a
resize draws at the new size (physical pixels: the logical size times the pixel ratio). A press
that moves less than :data:`CLICK_PX` (logical pixels) is a click, not a drag, and moves
nothing; a left click on the exploded path picks the part under the pointer as the new focus.

Each change asks for a frame (``request_draw``); jupyter_rfb calls
:meth:`ViewCanvas.get_frame` when the browser is ready for it (at most ``max_buffered_frames``
unconfirmed), sends it as a JPEG of the canvas's ``quality`` (80 by default) while frames keep
coming, and sends the last frame again as a lossless PNG 0.3 s after it (jupyter_rfb's own
"lossless at rest"; ``quality = 100`` sends every frame as a PNG).

:class:`Viewer` lays the canvas out with the controls that apply to the path drawn: a time-step
slider (a mesh with several steps), colour bands and value range (a path with a colour scale;
the flange path sets its own range), the flange threshold, and the exploded path's focus part.
A refused control value is shown as one line under the canvas; the view stays as it was.
"""

from __future__ import annotations

from typing import Any

import ipywidgets as widgets
import numpy as np
from jupyter_rfb import RemoteFrameBuffer

from ..paths.exploded import ExplodedPath
from ..paths.flange import FlangePath
from .live import LiveView

CLICK_PX = 3.0  # pointer travel (logical pixels) below which a press and release is a click
MAX_BANDS = 32
LEFT, RIGHT = 1, 2  # jupyter_rfb button numbers


class ViewCanvas(RemoteFrameBuffer):
    """The remote frame buffer of ``live`` (see the module docstring); ``on_pick(part)`` is
    called with the part id a click picked on the exploded path."""

    def __init__(self, live: LiveView, **kwargs: Any) -> None:
        width, height = live.size
        super().__init__(css_width=f"{width}px", css_height=f"{height}px", **kwargs)
        self.live = live
        self.on_pick = None
        self._ratio = 1.0
        self._drag: dict | None = None

    # ------------------------------------------------------------------ events
    def handle_event(self, event: dict) -> None:
        """Apply one jupyter_rfb event (new-style ``type`` or old-style ``event_type``)."""
        kind = event.get("type", event.get("event_type"))
        handler = getattr(self, f"_on_{kind}", None)
        if handler is not None and self.live.ctx is not None:
            handler(event)

    def _pixels(self, event: dict) -> tuple[float, float]:
        """The event's pointer position in frame pixels."""
        return float(event["x"]) * self._ratio, float(event["y"]) * self._ratio

    def _on_resize(self, event: dict) -> None:
        self._ratio = float(event.get("ratio", event.get("pixel_ratio", 1.0)) or 1.0)
        width = event.get("pwidth", float(event["width"]) * self._ratio)
        height = event.get("pheight", float(event["height"]) * self._ratio)
        width, height = int(round(width)), int(round(height))
        if width > 0 and height > 0:
            self.live.resize((width, height))
            self.request_draw()

    def _on_pointer_down(self, event: dict) -> None:
        button = int(event.get("button", 0))
        shifted = "Shift" in tuple(event.get("modifiers", ()))
        mode = "pan" if button == RIGHT or (button == LEFT and shifted) else \
            "orbit" if button == LEFT else None
        if mode is not None:
            x, y = float(event["x"]), float(event["y"])
            self._drag = dict(mode=mode, start=(x, y), last=(x, y), moving=False)

    def _on_pointer_move(self, event: dict) -> None:
        drag = self._drag
        if drag is None:
            return
        x, y = float(event["x"]), float(event["y"])
        if not drag["moving"]:  # a press moving less than a click's travel changes nothing
            if np.hypot(x - drag["start"][0], y - drag["start"][1]) < CLICK_PX:
                return
            drag["moving"] = True
        dx, dy = (x - drag["last"][0]) * self._ratio, (y - drag["last"][1]) * self._ratio
        drag["last"] = (x, y)
        if dx or dy:
            if drag["mode"] == "orbit":
                self.live.orbit_by(dx, dy)
            else:
                self.live.pan_by(dx, dy)
            self.request_draw()

    def _on_pointer_up(self, event: dict) -> None:
        drag, self._drag = self._drag, None
        if drag is None or drag["mode"] != "orbit" or drag["moving"]:
            return
        part = self.live.pick(*self._pixels(event))
        if part is not None and self.on_pick is not None:
            self.on_pick(part)

    def _on_wheel(self, event: dict) -> None:
        dy = float(event.get("dy", 0.0))
        if dy:
            self.live.zoom_by(dy)
            self.request_draw()

    def _on_double_click(self, event: dict) -> None:
        self.live.reset_view()
        self.request_draw()

    def _on_close(self, event: dict) -> None:
        self.live.release()

    # ------------------------------------------------------------------ frames
    def get_frame(self) -> np.ndarray | None:
        """The current (H, W, 3) uint8 frame; asks for the next one while an explosion moves.
        None once the view is released."""
        if self.live.ctx is None:
            return None
        frame = self.live.frame()
        if self.live.animating:
            self.request_draw()
        return frame


class Viewer(widgets.VBox):
    """The state's ``stamp`` (state, time, deleted elements: :meth:`LiveView.stamp`) above the
    canvas (``canvas``, a :class:`ViewCanvas`) and its colour bar (``bar``, a PNG image of
    :meth:`LiveView.legend`, hidden for a path without a colour scale), then the controls that
    apply to its path (``controls``: name → ipywidget, among "step", "bands", "value_range",
    "threshold", "focus") and a one-line ``status``; ``live`` is the :class:`LiveView` drawn.
    The stamp and the bar follow every change of step or style."""

    def __init__(self, live: LiveView, **kwargs: Any) -> None:
        canvas = ViewCanvas(live)
        status = widgets.Label("")
        self.stamp, self.bar = widgets.Label(""), widgets.Image(format="png")
        controls = _controls(live)
        super().__init__([self.stamp, widgets.HBox([canvas, self.bar]),
                          widgets.HBox(list(controls.values())), status], **kwargs)
        self.live, self.canvas, self.controls, self.status = live, canvas, controls, status
        self._show_legend()
        actions = dict(step=live.set_step, bands=lambda v: live.restyle(bands=v),
                       value_range=lambda v: live.restyle(value_range=tuple(v)),
                       threshold=lambda v: live.restyle(threshold=v),
                       depth_range=lambda v: live.restyle(depth_range=v),
                       focus=lambda v: live.restyle(focus=v))
        for name, control in controls.items():
            control.observe(self._applying(actions[name]), names="value")
        if "focus" in controls:
            canvas.on_pick = lambda part: setattr(controls["focus"], "value", part)

    def __repr__(self) -> str:
        width, height = self.live.size
        return f"Viewer({self.live.scene.name}, path {self.live.path_name}, {width}x{height})"

    def _applying(self, action):
        """An observer calling ``action(new value)`` and asking for a frame; a refusal goes to
        ``status``."""

        def observe(change: dict) -> None:
            try:
                action(change["new"])
            except (ValueError, KeyError) as exc:
                self.status.value = f"refused: {exc}"
                return
            self.status.value = ""
            self._show_legend()
            self.canvas.request_draw()

        return observe

    def _show_legend(self) -> None:
        """The stamp and the colour bar of the current state and style."""
        self.stamp.value = f"{self.live.scene.name}, {self.live.stamp()}"
        legend = self.live.legend()
        self.bar.layout.display = "none" if legend is None else None
        if legend is not None:
            self.bar.value = _png(legend)

    def close(self) -> None:
        """Free the view's GL objects and context and close the canvas and this box; closing
        again does nothing."""
        self.live.release()
        if self.canvas.comm is not None:
            self.canvas.close()
        super().close()


def _controls(live: LiveView) -> dict[str, widgets.Widget]:
    """The controls that apply to ``live``'s path, by name, set to its current style."""
    path, style, controls = live.path, live.path.style, {}
    if live.n_steps > 1:
        controls["step"] = widgets.IntSlider(value=live.step, min=0, max=live.n_steps - 1,
                                             description="step")
    scale = getattr(path, "scale", None)
    if scale is not None:
        controls["bands"] = widgets.IntSlider(
            value=style.bands, min=0, max=max(MAX_BANDS, style.bands), description="bands",
            continuous_update=False, tooltip="0: smooth contours")
    if scale is not None and not isinstance(path, FlangePath):
        lo, hi = live.scene.field_range(style.field)
        lo, hi = min(lo, scale.value_range[0]), max(hi, scale.value_range[1])
        hi = hi if hi > lo else lo + 1.0
        controls["value_range"] = widgets.FloatRangeSlider(
            value=scale.value_range, min=lo, max=hi, step=(hi - lo) / 200,
            description="range", continuous_update=False, readout_format=".3g")
    if isinstance(path, FlangePath) and style.by_thickness:  # the threshold is the thickness
        controls["depth_range"] = widgets.FloatSlider(
            value=style.depth_range, min=style.depth_range / 50, max=10 * style.depth_range,
            step=style.depth_range / 50, description="depth range", continuous_update=False,
            readout_format=".3g")
    elif isinstance(path, FlangePath):
        controls["threshold"] = widgets.FloatSlider(
            value=style.threshold, min=style.cutoff / 500, max=style.cutoff,
            step=style.cutoff / 500, description="threshold", continuous_update=False,
            readout_format=".3g")
    if isinstance(path, ExplodedPath):
        controls["focus"] = widgets.Dropdown(options=[int(p) for p in path.part_ids],
                                             value=style.focus, description="focus part")
    return controls


def _png(image: np.ndarray) -> bytes:
    """``image`` (H, W, 3) uint8 as PNG bytes."""
    import io

    from PIL import Image

    buffer = io.BytesIO()
    Image.fromarray(image).save(buffer, format="PNG")
    return buffer.getvalue()


def view(scene: Any, path: str | None = None, *, size: tuple[int, int] = (800, 600),
         device: int | str | None = None, **options: Any) -> Viewer:
    """A live view of ``scene`` in Jupyter: :class:`LiveView` (its arguments: ``angles``,
    ``projection``, ``up`` and the path's style options) laid out in a :class:`Viewer`."""
    live = LiveView(scene, path, size=size, device=device, **options)
    try:
        return Viewer(live)
    except BaseException:
        live.release()
        raise
