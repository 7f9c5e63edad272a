"""The compiled depth compositing equals the numpy merge bit for bit: ``composite_frames`` is
``functools.reduce(composite, frames)`` and ``composite_pixels`` the same reduction with drawn
pixels received from later domains, for any frames — tied depths, equal keys across frames,
noisy empty pixels, NaN and signed-zero depths — and refuses what does not make one image."""

from __future__ import annotations

import functools

import numpy as np
import pytest
from hypothesis import given, settings
from test_softraster_active import assert_identical, frame_sets, random_frame

from workbench.algo.composite.active import ActivePixels
from workbench.algo.composite.kernels import composite_frames, composite_pixels
from workbench.algo.composite.merge import composite
from workbench.algo.softraster.frame import Frame


@settings(max_examples=150, deadline=None)
@given(frame_sets())
def test_composite_frames_is_the_reduction(frames):
    before = [(f.color.copy(), f.depth.copy(), f.triangle.copy()) for f in frames]
    assert_identical(composite_frames(frames), functools.reduce(composite, frames))
    for f, (color, depth, triangle) in zip(frames, before):  # inputs are never written
        assert_identical(f, Frame(color, depth, triangle))


@settings(max_examples=150, deadline=None)
@given(frame_sets())
def test_composite_pixels_is_the_reduction_of_the_frames_they_came_from(frames):
    base, later = frames[0], frames[1:]
    parts = [ActivePixels.from_frame(f) for f in later]  # empty pixels never win a merge
    expected = functools.reduce(composite, [base] + later)
    assert_identical(composite_pixels(base, parts), expected)


def test_nan_and_signed_zero_depths_merge_as_numpy_compares():
    rng = np.random.default_rng(3)
    frames = [random_frame(rng, 9, 7, 0.7, None, (0, 4)) for _ in range(4)]
    for f in frames:
        drawn = f.triangle >= 0
        f.depth[drawn] = rng.choice(np.float32([np.nan, 0.0, -0.0, 0.5]), int(drawn.sum()))
    assert_identical(composite_frames(frames), functools.reduce(composite, frames))
    parts = [ActivePixels.from_frame(f) for f in frames[1:]]
    assert_identical(composite_pixels(frames[0], parts), functools.reduce(composite, frames))


def test_a_strided_frame_composites_like_a_contiguous_one():
    rng = np.random.default_rng(5)
    big = [random_frame(rng, 12, 10, 0.5, [0.25, 0.5], (0, 5)) for _ in range(3)]
    views = [Frame(f.color[::2, 1::2], f.depth[::2, 1::2], f.triangle[::2, 1::2]) for f in big]
    assert_identical(composite_frames(views), functools.reduce(composite, views))


def test_refusals():
    rng = np.random.default_rng(1)
    a, b = random_frame(rng, 5, 4, 0.5, None, (0, 9)), random_frame(rng, 6, 4, 0.5, None, (0, 9))
    with pytest.raises(ValueError, match="at least one frame"):
        composite_frames([])
    with pytest.raises(ValueError, match="different sizes"):
        composite_frames([a, b])
    wide = Frame(a.color, a.depth.astype(np.float64), a.triangle)
    with pytest.raises(ValueError, match="dtypes"):
        composite_frames([a, wide])
    with pytest.raises(ValueError, match="cannot be composited with a 4 x 5 frame"):
        composite_pixels(a, [ActivePixels.from_frame(b)])
