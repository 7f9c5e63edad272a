"""Sort-last compositing against a synthetic renderer: axis-aligned rectangles, each with a
depth and a global index, drawn in index order with a strict ``<`` depth test. Rendering the
rectangles in domains and compositing the frames must give the one-pass image exactly (colour,
depth and triangle index), for both schedules and any partition, depth ties included."""

from __future__ import annotations

import functools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from workbench.algo.composite.merge import (
    CompositeStats,
    Region,
    binary_swap,
    binary_tree,
    composite,
    swap_plan,
    tree_plan,
)
from workbench.algo.softraster.frame import CLEAR_DEPTH, NO_TRIANGLE, Frame

SCHEDULES = [binary_tree, binary_swap]


def random_scene(rng, count: int, width: int, height: int, depths=None):
    """(rects (n, 4) [x0, x1, y0, y1], depth (n,) float32, colour (n, 4) uint8)."""
    xs = np.sort(rng.integers(0, width + 1, (count, 2)), axis=1)
    ys = np.sort(rng.integers(0, height + 1, (count, 2)), axis=1)
    depth = (rng.choice(np.float32(depths), count) if depths is not None
             else rng.uniform(0.05, 0.95, count).astype(np.float32))
    color = rng.integers(0, 256, (count, 4)).astype(np.uint8)
    return np.c_[xs, ys], depth, color


def background(domain: int) -> tuple[int, int, int, int]:
    """A background colour per domain: where every frame is empty, the composite must show
    the first frame's (the one-pass render uses domain 0's)."""
    return ((10 + 40 * domain) % 256, 20 + domain // 6, 30, 255)


def draw(scene, indices, width: int, height: int, domain: int = 0) -> Frame:
    """The rectangles ``indices`` of ``scene`` drawn in index order, LESS depth test, on
    ``domain``'s background."""
    rects, depth, color = scene
    frame = Frame.empty(width, height, background=background(domain))
    for i in sorted(int(i) for i in indices):
        x0, x1, y0, y1 = rects[i]
        window = (slice(y0, y1), slice(x0, x1))
        passed = depth[i] < frame.depth[window]
        frame.color[window][passed] = color[i]
        frame.depth[window][passed] = depth[i]
        frame.triangle[window][passed] = i
    return frame


def assert_same(a: Frame, b: Frame) -> None:
    assert a.color.dtype == b.color.dtype and a.depth.dtype == b.depth.dtype
    assert a.triangle.dtype == b.triangle.dtype
    np.testing.assert_array_equal(a.triangle, b.triangle)
    np.testing.assert_array_equal(a.depth, b.depth)
    np.testing.assert_array_equal(a.color, b.color)


def interleaved(count: int, domains: int) -> list[np.ndarray]:
    """Rectangle i to domain i mod ``domains``: neighbours in index order land in different
    domains, so tied depths meet only in compositing."""
    return [np.arange(d, count, domains) for d in range(domains)]


# ------------------------------------------------------------------------------- composite
def test_composite_keeps_nearer_then_lower_index_then_drawn():
    a, b = Frame.empty(4, 1, (1, 1, 1, 255)), Frame.empty(4, 1, (2, 2, 2, 255))
    # pixel 0: b nearer; 1: equal depth, b lower index; 2: a empty (though at depth 0), b drawn
    # behind it; 3: both empty
    a.depth[0, :3] = [0.5, 0.5, 0.0]
    a.triangle[0, :2] = [7, 7]
    a.color[0, :2] = 100
    b.depth[0, :3] = [0.25, 0.5, 0.9]
    b.triangle[0, :3] = [9, 3, 4]
    b.color[0, :3] = 200
    out = composite(a, b)
    assert out.triangle[0].tolist() == [9, 3, 4, NO_TRIANGLE]
    assert out.depth[0].tolist() == [0.25, 0.5, np.float32(0.9), CLEAR_DEPTH]
    assert out.color[0, :, 0].tolist() == [200, 200, 200, 1]  # a's background where both empty
    # arguments swapped: the same fragments win; only where both are empty the first one shows
    back = composite(b, a)
    assert back.triangle[0].tolist() == [9, 3, 4, NO_TRIANGLE]
    assert back.color[0, 3, 0] == 2


def test_depth_tie_across_domains_goes_to_lower_index():
    # two rectangles over the same pixels at one depth; index 0 in domain 1, index 1 in domain 0
    rects = np.array([[0, 4, 0, 3], [1, 5, 0, 3]])
    scene = rects, np.float32([0.5, 0.5]), np.array([[255, 0, 0, 255], [0, 255, 0, 255]], np.uint8)
    frames = [draw(scene, [1], 6, 3), draw(scene, [0], 6, 3, 1)]
    whole = draw(scene, [0, 1], 6, 3)
    assert (whole.triangle[:, 1:4] == 0).all()
    for schedule in SCHEDULES:
        assert_same(schedule(frames)[0], whole)


@pytest.mark.parametrize("domains", [1, 2, 3, 4, 8])
@pytest.mark.parametrize("schedule", SCHEDULES, ids=lambda f: f.__name__)
@pytest.mark.parametrize("ties", [False, True], ids=["distinct", "tied"])
def test_schedules_equal_one_pass_render(schedule, domains, ties):
    rng = np.random.default_rng(100 * domains + ties)
    width, height = 23, 17
    scene = random_scene(rng, 60, width, height, depths=[0.25, 0.5, 0.75] if ties else None)
    whole = draw(scene, range(60), width, height)
    frames = [draw(scene, part, width, height, d)
              for d, part in enumerate(interleaved(60, domains))]
    out, stats = schedule(frames)
    assert_same(out, whole)
    assert_same(out, functools.reduce(composite, frames))
    assert isinstance(stats, CompositeStats) and stats.domains == domains
    assert stats.seconds >= 0
    if ties:  # the property is exercised: tied fragments of different domains meet
        tied = sum(((f.triangle != NO_TRIANGLE) & (f.depth == whole.depth)
                    & (f.triangle != whole.triangle)).sum() for f in frames)
        assert domains == 1 or tied > 0


# --------------------------------------------------------------------------- schedule costs
FRAME_8x6 = 8 * 6 * (4 + 4 + 8)  # 768 bytes: 48 pixels of RGBA uint8 + float32 + int64


def blank(domains: int, width: int = 6, height: int = 8) -> list[Frame]:
    return [Frame.empty(width, height) for _ in range(domains)]


def test_tree_bytes_and_rounds_by_hand():
    # D = 2: rank 1 sends its frame to rank 0
    assert binary_tree(blank(2))[1].bytes_moved == FRAME_8x6
    # D = 4: round 0 sends 1 -> 0 and 3 -> 2, round 1 sends 2 -> 0
    stats = binary_tree(blank(4))[1]
    assert (stats.bytes_moved, stats.rounds) == (3 * FRAME_8x6, 2)
    assert binary_tree(blank(1))[1].bytes_moved == 0 and binary_tree(blank(1))[1].rounds == 0
    assert tree_plan(5).rounds == (((0, 1), (2, 3)), ((0, 2),), ((0, 4),))


def test_swap_bytes_and_rounds_by_hand():
    # D = 2: both send the half they give up (4 + 4 rows), then rank 1 its 4 rows to rank 0
    stats = binary_swap(blank(2))[1]
    assert (stats.bytes_moved, stats.rounds) == (FRAME_8x6 + FRAME_8x6 // 2, 2)
    # D = 4: round 0 (rows) two pairs swap 4 + 4 rows each = 2 frames; round 1 (columns) the
    # pairs (0, 2) on the top and (1, 3) on the bottom half swap 4 x 3 + 4 x 3 pixels each =
    # 1 frame; the gather brings 3 quarters of a frame to rank 0
    stats = binary_swap(blank(4))[1]
    assert (stats.bytes_moved, stats.rounds) == (2 * FRAME_8x6 + FRAME_8x6 + 3 * FRAME_8x6 // 4, 3)
    # D = 3: fold 1 -> 0 (a frame), then the D = 2 swap
    stats = binary_swap(blank(3))[1]
    assert (stats.bytes_moved, stats.rounds) == (FRAME_8x6 + FRAME_8x6 + FRAME_8x6 // 2, 3)
    # odd sizes: 7 rows split 3 | 4; the gather sends rank 1's 4 rows of 5 pixels
    stats = binary_swap(blank(2, width=5, height=7))[1]
    assert stats.bytes_moved == (7 * 5 + 4 * 5) * 16
    assert binary_swap(blank(1))[1].bytes_moved == 0


def test_swap_plan_regions_alternate_axes_and_tile():
    plan = swap_plan(8, 8, 6)
    assert plan.fold == () and plan.ranks == tuple(range(8))
    assert [e.lower_keeps for e in plan.rounds[0][:1]] == [Region(0, 4, 0, 6)]
    assert [e.lower_keeps for e in plan.rounds[1][:1]] == [Region(0, 4, 0, 3)]
    assert [e.lower_keeps for e in plan.rounds[2][:1]] == [Region(0, 2, 0, 3)]
    covered = np.zeros((8, 6), int)
    for r in plan.regions:
        covered[r.top:r.bottom, r.left:r.right] += 1
    assert (covered == 1).all()
    six = swap_plan(6, 8, 6)
    assert six.fold == ((0, 1), (2, 3)) and six.ranks == (0, 2, 4, 5)


# ------------------------------------------------------------------------------- refusals
def test_refusals():
    with pytest.raises(ValueError, match="different sizes"):
        composite(Frame.empty(4, 3), Frame.empty(3, 4))
    for schedule in SCHEDULES:
        with pytest.raises(ValueError, match="none"):
            schedule([])
        with pytest.raises(ValueError, match="differ in size"):
            schedule([Frame.empty(4, 3), Frame.empty(4, 3), Frame.empty(5, 3)])
    broken = Frame.empty(4, 3)
    broken.depth = broken.depth[:2]
    with pytest.raises(ValueError, match="one \\(H, W\\) frame"):
        composite(broken, Frame.empty(4, 3))
    with pytest.raises(ValueError):
        swap_plan(0, 4, 4)


# ------------------------------------------------------------------------------- property
@st.composite
def scenes_and_partitions(draw_):
    width, height = draw_(st.integers(1, 9)), draw_(st.integers(1, 9))
    count = draw_(st.integers(0, 14))
    domains = draw_(st.integers(1, 7))
    seed = draw_(st.integers(0, 2**32 - 1))
    owner = draw_(st.lists(st.integers(0, domains - 1), min_size=count, max_size=count))
    return width, height, count, domains, seed, owner


@settings(max_examples=150, deadline=None)
@given(scenes_and_partitions())
def test_property_random_scenes_and_partitions(case):
    width, height, count, domains, seed, owner = case
    rng = np.random.default_rng(seed)
    scene = random_scene(rng, count, width, height, depths=[0.3, 0.6])
    owner = np.asarray(owner, int)
    frames = [draw(scene, np.flatnonzero(owner == d), width, height, d) for d in range(domains)]
    whole = draw(scene, range(count), width, height)
    for schedule in SCHEDULES:
        assert_same(schedule(frames)[0], whole)
