"""Compiled depth compositing (es2008, section 1): the merge rule of
:func:`.composite.composite` as one pass over the pixels instead of whole-array temporaries.

:func:`composite_frames` is ``functools.reduce(composite, frames)`` — what one process holding
several domains' frames composites before sending anything — and :func:`composite_pixels` a
frame composited with drawn pixels received from later domains
(:class:`~.active.ActivePixels`), at a cost in those pixels only. Both give the same arrays,
bit for bit, as the numpy merge: drawn beats empty, then the smaller depth, then the smaller
triangle index, the earlier operand's fragment where the keys are equal (``NaN`` depths compare
as numpy compares them: never nearer). GL-free and Dask-free.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numba
import numpy as np

from ..softraster.frame import NO_TRIANGLE, Frame
from .active import _rows
from .merge import _check

if TYPE_CHECKING:
    from .active import ActivePixels


@numba.njit(cache=True, inline="always")
def _later_wins(depth_a, triangle_a, depth_b, triangle_b) -> bool:
    """Whether the later fragment (b) replaces the earlier (a): b drawn, and a empty or b
    nearer, or as near with a smaller triangle index."""
    if triangle_b == NO_TRIANGLE:
        return False
    return (triangle_a == NO_TRIANGLE or depth_b < depth_a
            or (depth_b == depth_a and triangle_b < triangle_a))


@numba.njit(cache=True)
def _merge_frame(color, depth, triangle, color_b, depth_b, triangle_b):
    """Pixel arrays (1-D, one element per pixel) of frame a overwritten in place where
    frame b wins."""
    for i in range(depth.shape[0]):
        if _later_wins(depth[i], triangle[i], depth_b[i], triangle_b[i]):
            color[i] = color_b[i]
            depth[i] = depth_b[i]
            triangle[i] = triangle_b[i]


@numba.njit(cache=True)
def _merge_pixels(color, depth, triangle, index, color_b, depth_b, triangle_b):
    """As :func:`_merge_frame` for the drawn pixels b at flat indices ``index``."""
    for k in range(index.shape[0]):
        i = index[k]
        if _later_wins(depth[i], triangle[i], depth_b[k], triangle_b[k]):
            color[i] = color_b[k]
            depth[i] = depth_b[k]
            triangle[i] = triangle_b[k]


def _flat(frame: Frame) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """1-D views of ``frame``'s colour (one element per pixel), depth and triangle."""
    return (_rows(frame.color.reshape(-1, frame.color.shape[2])), frame.depth.reshape(-1),
            frame.triangle.reshape(-1))


def _copy(frame: Frame) -> Frame:
    return Frame(np.ascontiguousarray(frame.color).copy(),
                 np.ascontiguousarray(frame.depth).copy(),
                 np.ascontiguousarray(frame.triangle).copy())


def composite_frames(frames: Sequence[Frame]) -> Frame:
    """A new frame equal to ``functools.reduce(composite, frames)``: the frames of one size
    merged in their order. Refused (ValueError): no frames, frames of different sizes or
    dtypes, arrays that do not make one frame."""
    if not frames:
        raise ValueError("need at least one frame to composite, got none")
    shape = _check(frames[0], "frame 0")
    out = _copy(frames[0])
    target = _flat(out)
    for k, frame in enumerate(frames[1:], 1):
        if (_check(frame, f"frame {k}") != shape or frame.color.shape != out.color.shape):
            raise ValueError(f"cannot composite frames of different sizes: "
                             f"{out.color.shape[:2]} and {frame.color.shape[:2]} (rows, columns)")
        _same_dtypes(out, frame.color.dtype, frame.depth.dtype, frame.triangle.dtype)
        _merge_frame(*target, *_flat(_copy(frame) if not _contiguous(frame) else frame))
    return out


def composite_pixels(frame: Frame, parts: Sequence[ActivePixels]) -> Frame:
    """A new frame: ``frame`` (a whole image) composited with the drawn pixels of each of
    ``parts`` in their order (``frame`` first) — ``functools.reduce(composite, …)`` of the
    frame and each part drawn over an empty image. Refused (ValueError): parts of another
    image size or dtypes."""
    height, width = _check(frame, "frame")
    out = _copy(frame)
    color, depth, triangle = _flat(out)
    for part in parts:
        if (part.height, part.width) != (height, width):
            raise ValueError(f"pixels of a {part.height} x {part.width} image cannot be "
                             f"composited with a {height} x {width} frame")
        _same_dtypes(out, part.color.dtype, part.depth.dtype, part.triangle.dtype)
        if part.color.shape[1:] != out.color.shape[2:]:
            raise ValueError(f"pixels of {part.color.shape[1]} colour channels cannot be "
                             f"composited with a frame of {out.color.shape[2]}")
        _merge_pixels(color, depth, triangle, np.ascontiguousarray(part.index, np.int64),
                      _rows(part.color), np.ascontiguousarray(part.depth),
                      np.ascontiguousarray(part.triangle))
    return out


def _contiguous(frame: Frame) -> bool:
    return all(a.flags.c_contiguous for a in (frame.color, frame.depth, frame.triangle))


def _same_dtypes(out: Frame, color, depth, triangle) -> None:
    ours = (out.color.dtype, out.depth.dtype, out.triangle.dtype)
    if ours != (color, depth, triangle):
        raise ValueError(f"cannot composite pixels of dtypes {(color, depth, triangle)} with "
                         f"a frame of {ours} (colour, depth, triangle)")
