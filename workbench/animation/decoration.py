"""What is drawn around the frames of an animation: the state's time stamp above the image and,
where a field is shown, the colour bar of the frame's scale beside it (with the no-result
colour and its count under it in a frame whose field has non-finite values).

The layout is that of ``workbench render``'s field images
(:func:`~workbench.output.figures.field_figure`: the image at its native resolution, or each pixel
repeated k × k under 160 pixels of height, the bar and its labels to the right, a title row on top);
a frame without a field gets the same title row and margins without the bar. Frames are drawn by
matplotlib's Agg canvas alone, so the same frame gives the same pixels every time, and a fixed scale
gives the same bar on every frame.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..output.figures import (
    BAR_GAP,
    BAR_LABELS,
    BAR_WIDTH,
    MARGIN,
    TITLE_HEIGHT,
    axes_px,
    display_scale,
    enlarge,
    field_figure,
    new_figure,
    show,
)

if TYPE_CHECKING:
    from .frames import Frame


def state_stamp(step: int, time: float | None, deleted: int = 0, time_units: str = "") -> str:
    """:func:`time_stamp`, then ``, deleted: N`` where the state deletes elements (erosion)."""
    stamp = time_stamp(step, time, time_units)
    return stamp + (f", deleted: {deleted}" if deleted else "")


def time_stamp(step: int, time: float | None, time_units: str = "") -> str:
    """``state K, t = T UNITS`` (T to 6 significant digits; no unit where none is given, the
    reader's time unit then being the model's), or ``state K`` for a mesh without times."""
    if time is None:
        return f"state {step}"
    unit = f" {time_units}" if time_units else ""
    return f"state {step}, t = {time:.6g}{unit}"


@dataclass(frozen=True)
class Box:
    """A pixel rectangle of a decorated frame: columns ``left`` ≤ x < ``right``, rows ``top``
    ≤ y < ``bottom`` (row 0 at the top)."""

    left: int
    top: int
    right: int
    bottom: int

    def of(self, image: np.ndarray) -> np.ndarray:
        """The pixels of ``image`` inside the box."""
        return image[self.top:self.bottom, self.left:self.right]


@dataclass(frozen=True)
class Decoration:
    """How the frames of one animation are decorated: ``title`` (say, the scene and path)
    before each frame's :func:`time_stamp` (``time_units`` its unit), and where ``field`` is
    not None a colour bar ``field [units]`` of ``colormap`` in ``bands`` bands (0: smooth) over
    each frame's value range."""

    title: str
    field: str | None = None
    units: str = ""
    colormap: str = "viridis"
    bands: int = 0
    time_units: str = ""

    def __call__(self, frame: Frame) -> np.ndarray:
        """(H', W', 3) uint8: ``frame.image`` with its time stamp ("deleted: N" after it where
        the state deletes elements), and its colour bar where the decoration has a field and
        the frame a value range."""
        title = (f"{self.title}, "
                 f"{state_stamp(frame.step, frame.time, frame.deleted, self.time_units)}")
        if self.field is not None and frame.value_range is not None:
            fig = field_figure(frame.image, value_range=frame.value_range,
                               colormap=self.colormap, label=self.field, units=self.units,
                               title=title, bands=self.bands, no_result=frame.no_result)
        else:
            fig = _titled_figure(frame.image, title)
        fig.canvas.draw()
        return np.asarray(fig.canvas.buffer_rgba())[..., :3].copy()

    def image_box(self, size: tuple[int, int]) -> Box:
        """Where a frame of ``size`` (W, H) lies in its decorated frame."""
        k = display_scale(size[1])
        return Box(MARGIN, TITLE_HEIGHT, MARGIN + size[0] * k, TITLE_HEIGHT + size[1] * k)

    def bar_box(self, size: tuple[int, int]) -> Box:
        """Where the colour bar with its ticks and label lies beside a frame of ``size``
        (W, H), below the title row."""
        image = self.image_box(size)
        return Box(image.right + BAR_GAP, image.top, image.right + BAR_GAP + BAR_WIDTH +
                   BAR_LABELS, image.bottom + MARGIN)


def _titled_figure(image: np.ndarray, title: str):
    """The Figure of ``image`` (enlarged as :func:`field_figure` enlarges it) under ``title``,
    with :func:`field_figure`'s margins and no colour bar."""
    image = enlarge(image, display_scale(image.shape[0]))
    h, w = image.shape[:2]
    fig = new_figure(2 * MARGIN + w, MARGIN + h + TITLE_HEIGHT)
    show(axes_px(fig, MARGIN, MARGIN, w, h), image)
    fig.text(0.5, 1.0 - (TITLE_HEIGHT / 2) / (MARGIN + h + TITLE_HEIGHT), title, ha="center",
             va="center")
    return fig
