"""Columns many experiments' tables share, declared once: the row of
:func:`workbench.measurement.rows.measure` (its timing columns those of
:data:`workbench.measurement.timing.TIMING_COLUMNS`), image comparisons and the wire-frame
overlap. :func:`columns` picks them by name; a table that means something else by a name
declares its own :class:`~workbench.experiment.declare.Column` instead."""

from __future__ import annotations

from workbench.experiment.declare import Column, DeclarationError

_COMMON = [
    # what was drawn
    Column("renderer", "", "the renderer the row was drawn on (GL_RENDERER, or the software "
           "rasterizer); its times hold for it only"),
    Column("scene", "", "the scene measured"),
    Column("case", "", "what was drawn: path and options, as the table's rows name them"),
    Column("path", "", "the render path (registry name)"),
    Column("style", "", "the path's style fields off their defaults"),
    Column("size", "", "framebuffer size, width x height in pixels"),
    Column("samples", "", "MSAA samples (0: none)"),
    Column("triangles", "", "triangles drawn"),
    Column("vertices", "", "vertices the path's buffers hold"),
    Column("vertices_sent", "", "vertices the draw sends through the vertex shader"),
    Column("strips", "", "strips drawn (0 for lists)"),
    Column("bytes_uploaded", "B", "bytes uploaded to the GPU when the path was prepared"),
    Column("bytes_per_step", "B", "bytes uploaded per time step"),
    Column("derive_ms", "ms", "time the scene took to derive what the path needs (0 when "
           "cached)"),
    Column("derive_bytes", "B", "bytes the scene derived for the path"),
    Column("prepare_ms", "ms", "time to prepare the path (buffers, shaders)"),
    # timing (measurement.timing.Timing.as_row)
    Column("gpu_ms", "ms", "median GPU time of a draw (timer queries; empty where the renderer "
           "rasterizes on the CPU)"),
    Column("gpu_ms_min", "ms", "fastest draw's GPU time"),
    Column("gpu_ms_max", "ms", "slowest draw's GPU time"),
    Column("wall_ms", "ms", "median wall time of a draw, draw + finish, read-back apart"),
    Column("wall_ms_min", "ms", "fastest draw's wall time"),
    Column("wall_ms_max", "ms", "slowest draw's wall time"),
    Column("readback_ms", "ms", "median time to read the image back"),
    Column("repeats", "", "timed draws (more until the median's interval is narrow enough)"),
    Column("wall_ms_lo", "ms", "lower end of the wall median's 95 % interval"),
    Column("wall_ms_hi", "ms", "upper end of the wall median's 95 % interval"),
    Column("covered_px", "px", "pixels that differ from the background"),
    Column("mtri_per_s", "M/s", "million triangles drawn per second of wall time"),
    # images against a reference
    Column("reference", "", "the image the row's errors are measured against"),
    Column("max_diff_255", "1/255", "largest colour difference from the reference, in 8-bit "
           "levels"),
    Column("differing_px", "px", "pixels whose colour differs from the reference"),
    Column("ssim", "", "structural similarity with the reference (1: same image)"),
    Column("psnr_db", "dB", "peak signal-to-noise ratio against the reference"),
    # the wire frame against the exact element edges
    Column("wire_pixels", "px", "pixels of the drawn wire frame"),
    Column("overdraw_wire_pixels", "px", "pixels of the wire frame drawn as line overdraw "
           "(the reference)"),
    Column("wire_recall_1px", "", "share of the reference wire pixels within 1 px of a drawn "
           "one"),
    Column("wire_precision_1px", "", "share of the drawn wire pixels within 1 px of a "
           "reference one"),
    Column("wire_iou_1px", "", "intersection over union of the two wire frames, within 1 px"),
    Column("wire_exact_overlap", "", "share of wire pixels drawn exactly where the reference "
           "draws them"),
]
COMMON = {column.name: column for column in _COMMON}


def columns(*names: str) -> list[Column]:
    """The shared columns ``names``, in that order; refuses a name not shared (declare it in
    the experiment's table instead)."""
    missing = [n for n in names if n not in COMMON]
    if missing:
        raise DeclarationError(f"no shared column {missing}; declare it with the table")
    return [COMMON[n] for n in names]


def timing(gpu: bool = True) -> list[Column]:
    """The timing columns of a measured row, ``gpu_ms`` … ``wall_ms_hi`` (without the GPU
    columns where ``gpu`` is false)."""
    names = ["gpu_ms", "gpu_ms_min", "gpu_ms_max"] if gpu else []
    return columns(*names, "wall_ms", "wall_ms_min", "wall_ms_max", "readback_ms", "repeats",
                   "wall_ms_lo", "wall_ms_hi")


WIRE = ("wire_pixels", "overdraw_wire_pixels", "wire_recall_1px", "wire_precision_1px",
        "wire_iou_1px", "wire_exact_overlap")
