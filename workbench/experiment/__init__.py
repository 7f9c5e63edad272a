"""Measurement harness: timing, image error, tables, figures, the experiment registry and the
pyrender reference renderer. Heavy libraries (scikit-image, matplotlib, pyrender) load on use."""

from .compare import ImageDiff, compare_images, coverage, difference_map
from .figures import save_field_figure, save_image_grid, save_png
from .measure import Measurement, default_camera, measure
from .reference import PyrenderReference
from .registry import EXPERIMENTS, Experiment, discover, experiment, get_experiment, run_experiment
from .tables import (
    atomic_open,
    atomic_write_bytes,
    atomic_write_text,
    format_number,
    markdown_table,
    read_table,
    write_table,
)
from .timing import MIN_REPEATS, Timing, time_call, time_draw

__all__ = [
    "EXPERIMENTS", "Experiment", "ImageDiff", "MIN_REPEATS", "Measurement", "default_camera",
    "measure", "PyrenderReference", "Timing",
    "atomic_open", "atomic_write_bytes", "atomic_write_text", "compare_images", "coverage",
    "difference_map", "discover", "experiment", "format_number", "get_experiment",
    "markdown_table", "read_table", "run_experiment", "save_field_figure", "save_image_grid",
    "save_png", "time_call", "time_draw", "write_table",
]
