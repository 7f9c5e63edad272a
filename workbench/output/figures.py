"""Figures from rendered images: PNGs, field images with a labelled colour bar, comparison grids.

matplotlib is used through ``Figure`` + ``FigureCanvasAgg`` only (never pyplot), so nothing
opens a window and no global state changes. Rendered images are placed at their native
resolution (one image pixel = one figure pixel, 100 dpi; images under 160 pixels high are
enlarged by repeating each pixel k × k) so figures show exactly what was measured. Every
file is written atomically.
"""

from __future__ import annotations

import io
import os
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from .tables import atomic_write_bytes

if TYPE_CHECKING:
    from matplotlib.colors import Colormap
    from numpy.typing import ArrayLike

DPI = 100
MARGIN = 10  # pixels around panels
TITLE_HEIGHT = 28
BAR_GAP, BAR_WIDTH, BAR_LABELS = 12, 18, 110  # colour bar: gap, bar, ticks + label (pixels)
NO_RESULT_KEY = 30  # pixels of the bar's column the no-result swatch and its two lines take
MIN_PANEL_HEIGHT = 160  # smaller images are enlarged by pixel repetition


def _check_image(image, name: str = "image") -> np.ndarray:
    image = np.asarray(image)
    if image.dtype != np.uint8 or image.ndim != 3 or image.shape[2] not in (3, 4):
        raise ValueError(f"{name} must be a uint8 (H, W, 3) or (H, W, 4) array, "
                         f"got {image.dtype} {image.shape}")
    return image


def _rgba(image: np.ndarray) -> np.ndarray:
    if image.shape[2] == 4:
        return np.ascontiguousarray(image)
    return np.concatenate([image, np.full(image.shape[:2] + (1,), 255, np.uint8)], axis=2)


def save_png(path: str | os.PathLike[str], image: ArrayLike) -> Path:
    """Write a uint8 (H, W, 3|4) image, row 0 at the top, as an RGBA PNG (atomically)."""
    from PIL import Image

    image = _rgba(_check_image(image))
    buffer = io.BytesIO()
    Image.fromarray(image, "RGBA").save(buffer, format="PNG")
    return atomic_write_bytes(path, buffer.getvalue())


def with_progress_bar(image: ArrayLike, done: int, total: int, height: int = 3) -> np.ndarray:
    """(H, W, 3) uint8 copy of ``image`` with a bar along its bottom ``height`` rows, dark over
    the share ``done / total`` of the width: it marks an animation's frames apart (GIF writers
    merge identical consecutive frames)."""
    frame = _check_image(image)[..., :3].copy()
    width = frame.shape[1]
    frame[-height:, :] = 255
    frame[-height:, : max(1, round(width * done / total))] = (40, 40, 40)
    return frame


def save_animation(path: str | os.PathLike[str], frames: Sequence[ArrayLike],
                   duration_ms: int = 100) -> Path:
    """Write uint8 (H, W, 3|4) ``frames`` (all of one size) atomically: an animated GIF (one
    frame every ``duration_ms``, looping) for a ``.gif`` path, else the frames side by side as a
    PNG strip. Refuses no frames and frames of different sizes."""
    from PIL import Image

    frames = [_rgba(_check_image(f))[..., :3] for f in frames]
    if not frames:
        raise ValueError("no frames to write")
    if any(f.shape != frames[0].shape for f in frames):
        raise ValueError("animation frames differ in size")
    path = Path(path)
    if path.suffix.lower() != ".gif":
        return save_png(path, np.concatenate(frames, axis=1))
    images = [Image.fromarray(np.ascontiguousarray(f)) for f in frames]
    buffer = io.BytesIO()
    images[0].save(buffer, format="GIF", save_all=True, append_images=images[1:],
                   duration=int(duration_ms), loop=0)
    return atomic_write_bytes(path, buffer.getvalue())


def _colormap(colormap):
    import matplotlib
    from matplotlib.colors import Colormap, ListedColormap

    if isinstance(colormap, Colormap):
        return colormap
    if isinstance(colormap, str):
        try:
            return matplotlib.colormaps[colormap]
        except KeyError:
            raise ValueError(f"unknown matplotlib colour map {colormap!r}") from None
    colors = np.asarray(colormap)
    if colors.ndim != 2 or colors.shape[1] not in (3, 4) or len(colors) < 2:
        raise ValueError("colormap must be a name, a matplotlib Colormap or an (N, 3|4) colour "
                         f"table with N >= 2, got shape {colors.shape}")
    if np.issubdtype(colors.dtype, np.integer):
        colors = colors / 255.0
    return ListedColormap(np.asarray(colors, np.float64))


def _mappable(value_range, colormap, bands: int, log: bool):
    from matplotlib.cm import ScalarMappable
    from matplotlib.colors import BoundaryNorm, LogNorm, Normalize

    lo, hi = (float(v) for v in value_range)
    if not (np.isfinite(lo) and np.isfinite(hi) and lo < hi):
        raise ValueError(f"value_range must be finite with low < high, got {value_range}")
    if log and lo <= 0:
        raise ValueError(f"a logarithmic colour bar needs a positive range, got {value_range}")
    if int(bands) != bands or bands < 0:
        raise ValueError(f"bands must be a non-negative integer, got {bands}")
    cmap = _colormap(colormap)
    if bands:
        cmap = cmap.resampled(int(bands))
        edges = np.geomspace(lo, hi, bands + 1) if log else np.linspace(lo, hi, bands + 1)
        return ScalarMappable(BoundaryNorm(edges, int(bands)), cmap), edges
    norm = LogNorm(lo, hi) if log else Normalize(lo, hi)
    return ScalarMappable(norm, cmap), None


def new_figure(width_px: int, height_px: int):
    """A matplotlib figure of ``width_px`` × ``height_px`` pixels on the Agg canvas (no display)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(width_px / DPI, height_px / DPI), dpi=DPI)
    FigureCanvasAgg(fig)
    return fig


def axes_px(fig, left: int, bottom: int, width: int, height: int):
    """Axes at a pixel rectangle (origin at the figure's bottom left)."""
    fw, fh = fig.get_size_inches() * DPI
    return fig.add_axes((left / fw, bottom / fh, width / fw, height / fh))


def show(ax, image, **kwargs) -> None:
    """``image`` drawn pixel for pixel into ``ax``, without axes."""
    ax.imshow(image, interpolation="none", aspect="auto", resample=False, **kwargs)
    ax.set_axis_off()


def _write_figure(fig, path) -> Path:
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=DPI)
    return atomic_write_bytes(path, buffer.getvalue())


def display_scale(height: int) -> int:
    """Integer enlargement so that a small image (and its colour bar) stays legible."""
    return max(1, -(-MIN_PANEL_HEIGHT // height))


def enlarge(image: np.ndarray, scale: int) -> np.ndarray:
    """``image`` with every pixel repeated ``scale`` × ``scale`` times."""
    return image if scale == 1 else np.repeat(np.repeat(image, scale, axis=0), scale, axis=1)


def save_field_figure(path: str | os.PathLike[str], image: ArrayLike, *,
                      value_range: tuple[float, float], colormap: str | Colormap | ArrayLike,
                      label: str, units: str, title: str | None = None, bands: int = 0,
                      log: bool = False, no_result: str | None = None) -> Path:
    """A rendered field image with a colour bar ``label [units]`` (:func:`field_figure`)
    written as a PNG; returns the path."""
    return _write_figure(field_figure(image, value_range=value_range, colormap=colormap,
                                      label=label, units=units, title=title, bands=bands,
                                      log=log, no_result=no_result), path)


def field_figure(image: ArrayLike, *, value_range: tuple[float, float],
                 colormap: str | Colormap | ArrayLike, label: str, units: str,
                 title: str | None = None, bands: int = 0, log: bool = False,
                 no_result: str | None = None):
    """The matplotlib ``Figure`` (on an Agg canvas, 100 dpi) of a rendered field image with a
    colour bar ``label [units]``, as :func:`save_field_figure` writes it.

    ``value_range`` = (low, high) is the field range the render mapped onto ``colormap`` (a
    matplotlib name, a ``Colormap`` or the (N, 3|4) colour table the render path used);
    ``bands`` > 0 shows a colour bar of that many equal bands (band contours), ticked at the
    band edges; ``log`` a logarithmic scale. ``no_result`` (the drawn field had non-finite
    values: :func:`~workbench.paths.colormap.no_result_label`, say ``no result: 12 nodes``)
    adds under the bar a swatch of :data:`~workbench.paths.colormap.NO_RESULT_COLOR` with that
    text (the bar shortened by :data:`NO_RESULT_KEY` pixels). The image keeps its pixels
    (native resolution, or each pixel repeated k × k when it is under 160 pixels high); axes
    are hidden. Refuses a
    non-uint8 image, an empty or non-finite range, a non-positive range with ``log`` and a
    negative band count.
    """
    image = _check_image(image)
    mappable, edges = _mappable(value_range, colormap, bands, log)
    image = enlarge(image, display_scale(image.shape[0]))
    h, w = image.shape[:2]
    top = TITLE_HEIGHT if title else MARGIN
    fig = new_figure(MARGIN + w + BAR_GAP + BAR_WIDTH + BAR_LABELS, MARGIN + h + top)
    show(axes_px(fig, MARGIN, MARGIN, w, h), image)
    _bar(fig, MARGIN + w + BAR_GAP, h, mappable, edges, bands, label, units, no_result)
    if title:
        fig.text(0.5, 1.0 - (TITLE_HEIGHT / 2) / (MARGIN + h + top), title, ha="center",
                 va="center")
    return fig


def colour_bar(height: int, *, value_range: tuple[float, float],
               colormap: str | Colormap | ArrayLike, label: str, units: str = "",
               bands: int = 0, log: bool = False, no_result: str | None = None) -> np.ndarray:
    """(H, W, 3) uint8: the colour bar of :func:`field_figure` alone, for an image ``height``
    pixels high (its bar as tall as the image, the margins around it), on white: what a live
    view shows beside its frames. Refuses what :func:`field_figure` refuses and a height under
    ``2 * NO_RESULT_KEY`` pixels."""
    if height < 2 * NO_RESULT_KEY:
        raise ValueError(f"a colour bar needs a height of {2 * NO_RESULT_KEY} pixels or more, "
                         f"got {height}")
    mappable, edges = _mappable(value_range, colormap, bands, log)
    fig = new_figure(BAR_GAP + BAR_WIDTH + BAR_LABELS, height + 2 * MARGIN)
    _bar(fig, BAR_GAP, height, mappable, edges, bands, label, units, no_result)
    fig.canvas.draw()
    return np.asarray(fig.canvas.buffer_rgba())[..., :3].copy()


def _bar(fig, left: int, height: int, mappable, edges, bands: int, label: str, units: str,
         no_result: str | None) -> None:
    """The colour bar of ``mappable`` at pixel column ``left``, ``height`` pixels from the
    bottom margin up, ticked at the band ``edges`` (up to 12 bands), labelled ``label
    [units]``, the no-result key under it where ``no_result`` is given."""
    from matplotlib.ticker import FuncFormatter

    key = NO_RESULT_KEY if no_result else 0
    bar = fig.colorbar(mappable, cax=axes_px(fig, left, MARGIN + key, BAR_WIDTH, height - key))
    if no_result:
        _no_result_key(fig, left, MARGIN, no_result)
    if edges is not None and bands <= 12:
        bar.set_ticks(edges)
        bar.ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:.3g}"))
    bar.set_label(f"{label} [{units}]" if units else label)


def _no_result_key(fig, left: int, bottom: int, text: str) -> None:
    """The no-result swatch (:data:`~workbench.paths.colormap.NO_RESULT_COLOR`, the bar's width,
    12 pixels high) at pixel (``left``, ``bottom``) with ``text`` beside it, broken after its
    colon onto two small lines."""
    from matplotlib.patches import Rectangle

    from ..paths.colormap import NO_RESULT_COLOR

    fw, fh = fig.get_size_inches() * DPI
    fig.add_artist(Rectangle((left / fw, (bottom + 2) / fh), BAR_WIDTH / fw, 12 / fh,
                             facecolor=NO_RESULT_COLOR, edgecolor="black", linewidth=0.5,
                             transform=fig.transFigure))
    fig.text((left + BAR_WIDTH + 4) / fw, (bottom + 8) / fh, text.replace(": ", ":\n", 1),
             fontsize=7, va="center", ha="left", linespacing=1.0)


def save_image_grid(path: str | os.PathLike[str], images: Sequence[ArrayLike],
                    titles: Sequence[str], *, columns: int | None = None,
                    colormap: str = "magma", scalar_label: str = "|difference| [1/255]") -> Path:
    """Images side by side, each under its title; returns the path.

    ``images`` are uint8 (H, W, 3|4) renders or (H, W) scalar maps (e.g. a difference image from
    :func:`workbench.measurement.images.difference_map`), all of one size; scalar maps are shown
    with ``colormap`` from 0 to their maximum and a colour bar ``scalar_label``. ``columns``
    panels per row (default: all in one row). Pixels are kept as in
    :func:`save_field_figure`. Refuses mismatched counts or sizes and non-finite maps.
    """
    images = [np.asarray(im) for im in images]
    if not images:
        raise ValueError("no images to show")
    if len(titles) != len(images):
        raise ValueError(f"{len(images)} images but {len(titles)} titles")
    for i, im in enumerate(images):
        if im.ndim == 3:
            _check_image(im, f"image {i}")
        elif im.ndim != 2 or not np.isfinite(im).all():
            raise ValueError(f"image {i} must be (H, W, 3|4) uint8 or a finite (H, W) map, "
                             f"got shape {im.shape}")
    if any(im.shape[:2] != images[0].shape[:2] for im in images):
        raise ValueError(f"images differ in size: {[im.shape[:2] for im in images]}")
    columns = len(images) if columns is None else int(columns)
    if columns < 1:
        raise ValueError(f"columns must be positive, got {columns}")
    scale = display_scale(images[0].shape[0])
    images = [enlarge(im, scale) for im in images]
    h, w = images[0].shape[:2]
    bar_w = BAR_GAP + BAR_WIDTH + BAR_LABELS
    grid = [images[i:i + columns] for i in range(0, len(images), columns)]
    widths = [[w + MARGIN + (bar_w if im.ndim == 2 else 0) for im in row] for row in grid]
    cell_h = h + TITLE_HEIGHT
    fig_w = MARGIN + max(sum(row) for row in widths)
    fig_h = MARGIN + len(grid) * cell_h
    fig = new_figure(fig_w, fig_h)
    titles = iter(titles)
    for r, (row, row_widths) in enumerate(zip(grid, widths)):
        bottom = MARGIN + (len(grid) - 1 - r) * cell_h
        left = MARGIN
        for im, cell_w in zip(row, row_widths):
            ax = axes_px(fig, left, bottom, w, h)
            if im.ndim == 2:
                show(ax, im, cmap=colormap, vmin=0.0, vmax=float(max(im.max(), 1)))
                bar = fig.colorbar(ax.images[0],
                                   cax=axes_px(fig, left + w + BAR_GAP, bottom, BAR_WIDTH, h))
                bar.set_label(scalar_label)
            else:
                show(ax, im)
            fig.text((left + w / 2) / fig_w, (bottom + h + TITLE_HEIGHT / 2) / fig_h,
                     next(titles), ha="center", va="center")
            left += cell_w
    return _write_figure(fig, path)
