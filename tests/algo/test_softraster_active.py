"""Active-pixel compositing: the encoding round trip is exact, every schedule (binary tree,
binary swap, radix-k with each factorisation) gives exactly ``functools.reduce(composite,
frames)`` for any number of frames, and the bytes sent are never above — and for sparse frames
far below — what the same schedule sends as whole (sub-)images."""

from __future__ import annotations

import functools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from workbench.algo.composite.active import (
    ActivePixels,
    EncodedPiece,
    decode,
    encode,
    merge,
    merge_ordered,
    paint,
)
from workbench.algo.composite.merge import Region, binary_swap, composite, crop, swap_plan
from workbench.algo.composite.schedules import (
    ActiveStats,
    active_radix,
    active_swap,
    active_tree,
    radix_plan,
)
from workbench.algo.softraster.frame import CLEAR_DEPTH, Frame


def factorisations(n: int) -> list[tuple[int, ...]]:
    """Every ordered factorisation of ``n`` into factors >= 2 (``[()]`` for 1)."""
    if n == 1:
        return [()]
    return [(k,) + rest for k in range(2, n + 1) if n % k == 0
            for rest in factorisations(n // k)]


def schedules(domains: int):
    """(name, schedule) of every active-pixel schedule for ``domains`` frames."""
    yield "tree", active_tree
    yield "swap", active_swap
    for factors in factorisations(domains):
        yield f"radix {factors}", functools.partial(active_radix, factors=factors)


def assert_identical(a: Frame, b: Frame) -> None:
    """Same shapes, dtypes and bits (so -0.0 and 0.0 differ)."""
    for x, y in ((a.color, b.color), (a.depth, b.depth), (a.triangle, b.triangle)):
        assert x.dtype == y.dtype and x.shape == y.shape
        assert x.tobytes() == y.tobytes()


def random_frame(rng, width: int, height: int, coverage: float, depths, triangles,
                 background: str = "uniform") -> Frame:
    """A frame with each pixel drawn with probability ``coverage``: depth from ``depths`` (a
    list to draw from, or None for any value in [0, 1)), triangle index from ``triangles``
    ((low, high) range); empty pixels cleared to one random colour, or (``"noisy"``) each
    with its own colour and depth."""
    frame = Frame.empty(width, height, background=tuple(int(v) for v in rng.integers(0, 256, 4)))
    drawn = rng.random((height, width)) < coverage
    n = int(drawn.sum())
    if background == "noisy":
        frame.color[...] = rng.integers(0, 256, frame.color.shape)
        frame.depth[...] = rng.choice(np.float32([0.0, -0.0, 0.5, CLEAR_DEPTH]), (height, width))
    frame.color[drawn] = rng.integers(0, 256, (n, 4))
    frame.color[drawn, 3] = 255  # opaque, as the rasterizer draws
    frame.depth[drawn] = (rng.choice(np.float32(depths), n) if depths is not None
                          else rng.random(n, np.float32))
    frame.triangle[drawn] = rng.integers(triangles[0], triangles[1], n)
    return frame


@st.composite
def frame_sets(draw, max_domains: int = 9):
    """(frames, seed): 1 to ``max_domains`` frames of one size (0 to 13 pixels a side), each
    with its own coverage (none, sparse, half, all), depths tied or not, triangle indices from a
    few (equal keys across frames) or from a range wider than 32 bits, and cleared or noisy
    empty pixels."""
    width, height = draw(st.integers(0, 13)), draw(st.integers(1, 13))
    domains = draw(st.integers(1, max_domains))
    seed = draw(st.integers(0, 2**32 - 1))
    tied = draw(st.booleans())
    triangles = draw(st.sampled_from([(0, 3), (0, 10**6), (-3, 2**40)]))
    rng = np.random.default_rng(seed)
    frames = []
    for _ in range(domains):
        coverage = draw(st.sampled_from([0.0, 0.05, 0.5, 1.0]))
        background = draw(st.sampled_from(["uniform", "uniform", "noisy"]))
        frames.append(random_frame(rng, width, height, coverage, [0.25, 0.5] if tied else None,
                                   triangles, background))
    return frames


# ------------------------------------------------------------------------------- encoding
@settings(max_examples=200, deadline=None)
@given(frame_sets(max_domains=1), st.data())
def test_encode_decode_round_trip_is_exact(frames, data):
    frame = frames[0]
    height, width = frame.depth.shape
    top = data.draw(st.integers(0, height))
    bottom = data.draw(st.integers(top, height))
    left = data.draw(st.integers(0, width))
    right = data.draw(st.integers(left, width))
    for region in (None, Region(top, bottom, left, right)):
        whole = Region(0, height, 0, width) if region is None else region
        piece = encode(frame, region)
        assert isinstance(piece, EncodedPiece) and piece.region == whole
        assert_identical(decode(piece), crop(frame, whole))
        # never larger than the plain sub-image
        assert piece.nbytes <= whole.pixels * 16
        # the compositing form: exactly the drawn pixels, and decoded over any frame
        active = ActivePixels.from_frame(frame, region)
        back = active.pack().unpack()
        for name in ("index", "color", "depth", "triangle"):
            x, y = getattr(active, name), getattr(back, name)
            assert x.dtype == y.dtype and x.tobytes() == y.tobytes(), name
        under = crop(Frame.empty(width, height, (1, 2, 3, 4)), whole)
        expected = crop(composite(Frame.empty(width, height, (1, 2, 3, 4)), frame), whole)
        assert_identical(decode(active.pack(), under), expected)


def test_encoding_of_a_cleared_frame_with_sparse_pixels_is_small():
    frame = Frame.empty(200, 100)
    frame.triangle[40:42, 10:30] = np.arange(40).reshape(2, 20) + 7 * 10**6
    frame.depth[40:42, 10:30] = 0.5
    frame.color[40:42, 10:30, 0] = np.arange(40).reshape(2, 20)  # the only varying channel
    piece = encode(frame)
    assert piece.box == Region(40, 42, 10, 30)
    assert piece.runs.tolist() == [0, 20, 0, 20]  # no run crosses a box row
    # 40 pixels: 1 varying colour channel + 4 depth + 1 triangle offset byte
    assert piece.color.shape == (40, 1) and piece.triangle.dtype == np.uint8
    assert piece.nbytes < 40 * (1 + 4 + 1) + 64
    assert_identical(decode(piece), frame)


def test_refusals():
    frame = Frame.empty(4, 3)
    with pytest.raises(ValueError, match="not inside"):
        ActivePixels.from_frame(frame, Region(0, 4, 0, 4))
    pixels = ActivePixels.from_frame(frame, Region(0, 2, 0, 4))
    with pytest.raises(ValueError, match="not inside"):
        pixels.cut(Region(0, 3, 0, 4))
    with pytest.raises(ValueError, match="cannot merge"):
        merge(pixels, ActivePixels.from_frame(frame))
    with pytest.raises(ValueError, match="none"):
        merge_ordered([])
    with pytest.raises(ValueError, match="no background"):
        decode(pixels.pack())
    with pytest.raises(ValueError, match="not \\(2, 4\\)"):
        decode(pixels.pack(), Frame.empty(4, 3))
    with pytest.raises(ValueError, match="cannot be painted"):
        paint(Frame.empty(5, 3), [pixels])
    drawn = Frame.empty(4, 3)
    drawn.triangle[1, :] = 5
    piece = encode(drawn)
    assert piece.plain is None
    bad = EncodedPiece(**{**piece.__dict__, "runs": np.array([0, 8], np.uint8)})
    with pytest.raises(ValueError, match="crosses the end of a row"):
        bad.unpack()
    for schedule in (active_tree, active_swap, active_radix):
        with pytest.raises(ValueError, match="none"):
            schedule([])
        with pytest.raises(ValueError, match="differ in size"):
            schedule([Frame.empty(4, 3), Frame.empty(3, 4)])
    with pytest.raises(ValueError, match="product"):
        active_radix([frame] * 6, factors=(2, 2))
    with pytest.raises(ValueError, match="product"):
        radix_plan(4, 3, 4, factors=(1, 4))


# ------------------------------------------------------------------------------- merging
def test_merge_keeps_drawn_then_nearer_then_lower_index_then_first():
    a, b = Frame.empty(5, 1, (1, 1, 1, 255)), Frame.empty(5, 1, (2, 2, 2, 255))
    # 0: b nearer; 1: equal depth, b lower index; 2: equal keys (one triangle in two frames):
    # a's colour; 3: only b drawn; 4: neither
    a.depth[0, :3], a.triangle[0, :3], a.color[0, :3] = [0.5, 0.5, 0.5], [7, 7, 4], 100
    b.depth[0, :4], b.triangle[0, :4], b.color[0, :4] = [0.25, 0.5, 0.5, 0.9], [9, 3, 4, 6], 200
    merged = merge(ActivePixels.from_frame(a), ActivePixels.from_frame(b))
    assert merged.triangle.tolist() == [9, 3, 4, 6]
    assert merged.color[:, 0].tolist() == [200, 200, 100, 200]
    assert_identical(paint(a, [merged]), composite(a, b))


@settings(max_examples=100, deadline=None)
@given(frame_sets())
def test_merge_ordered_equals_reduce(frames):
    parts = [ActivePixels.from_frame(f) for f in frames]
    assert_identical(paint(frames[0], [merge_ordered(parts)]),
                     functools.reduce(composite, frames))


# ------------------------------------------------------------------------------- schedules
@settings(max_examples=150, deadline=None)
@given(frame_sets())
def test_every_schedule_equals_reduce_and_sends_no_more_than_full_frames(frames):
    expected = functools.reduce(composite, frames)
    for name, schedule in schedules(len(frames)):
        out, stats = schedule(frames)
        assert_identical(out, expected)
        assert isinstance(stats, ActiveStats) and stats.domains == len(frames), name
        assert stats.rounds == len(stats.round_bytes) == len(stats.full_round_bytes), name
        assert stats.bytes_moved == sum(stats.round_bytes), name
        assert all(a <= f for a, f in zip(stats.round_bytes, stats.full_round_bytes)), name
        assert stats.full_frame_bytes == sum(stats.full_round_bytes), name


@pytest.mark.parametrize("domains", range(1, 10))
def test_schedules_on_tied_frames(domains):
    # every pixel drawn in most frames at one of two depths by one of three triangles, so
    # equal keys meet at nearly every pixel in every round
    rng = np.random.default_rng(domains)
    frames = [random_frame(rng, 11, 7, 0.8, [0.25, 0.5], (0, 3)) for _ in range(domains)]
    expected = functools.reduce(composite, frames)
    first_wins = sum(((f.triangle == expected.triangle) & (f.depth == expected.depth)
                      & (f.color != expected.color).any(axis=-1)).sum() for f in frames[1:])
    assert domains == 1 or first_wins > 0  # the tie rule decides visible pixels
    for name, schedule in schedules(domains):
        assert_identical(schedule(frames)[0], expected)
        if domains == 1:
            assert schedule(frames)[1].bytes_moved == 0, name


def test_full_frame_bytes_match_the_full_frame_swap():
    frames = [Frame.empty(6, 8) for _ in range(6)]
    full = binary_swap(frames)[1].bytes_moved
    stats = active_swap(frames)[1]
    assert stats.full_frame_bytes == full
    assert stats.rounds == binary_swap(frames)[1].rounds


def bands(domains: int, size: int, rows: bool) -> list[Frame]:
    """``domains`` frames of ``size`` × ``size``, frame d drawing the d-th of ``domains``
    disjoint bands (of rows, or of columns) with random colours, depths and triangle indices."""
    rng = np.random.default_rng(7)
    frames = []
    for d in range(domains):
        frame = Frame.empty(size, size)
        band = slice(d * size // domains, (d + 1) * size // domains)
        window = (band, slice(None)) if rows else (slice(None), band)
        shape = frame.depth[window].shape
        frame.color[window] = rng.integers(0, 256, shape + (4,))
        frame.color[window + (3,)] = 255
        frame.depth[window] = rng.random(shape, np.float32)
        frame.triangle[window] = rng.integers(0, 2 * 10**6, shape)
        frames.append(frame)
    return frames


@pytest.mark.parametrize("rows", [True, False], ids=["row bands", "column bands"])
def test_disjoint_bands_send_under_a_quarter_of_the_full_frame_swap(rows):
    frames = bands(8, 1000, rows)
    full_swap = binary_swap(frames)[1].bytes_moved
    assert full_swap == 126_000_000
    expected = functools.reduce(composite, frames)
    for name, schedule in schedules(8):
        out, stats = schedule(frames)
        assert_identical(out, expected)
        assert stats.bytes_moved <= 0.25 * full_swap, (name, stats.bytes_moved)
        assert stats.bytes_moved <= 0.25 * stats.full_frame_bytes, name


def test_sparse_frames_send_a_small_fraction():
    rng = np.random.default_rng(3)
    frames = [random_frame(rng, 300, 200, 0.01, None, (0, 10**6)) for _ in range(8)]
    for name, schedule in schedules(8):
        stats = schedule(frames)[1]
        assert stats.bytes_moved <= 0.02 * stats.full_frame_bytes, name


# ------------------------------------------------------------------------------- radix-k plan
def test_radix_plan_regions_and_groups():
    # factors of two: binary swap's regions
    assert radix_plan(8, 9, 7, (2, 2, 2)).regions == swap_plan(8, 9, 7).regions
    plan = radix_plan(12, 10, 9, (3, 4))
    assert plan.factors == (3, 4) and plan.round_count == 3
    # round 0: consecutive triples split across rows; round 1: ranks 3 apart across columns
    assert plan.rounds[0][1].members == (3, 4, 5)
    assert plan.rounds[0][1].parts == (Region(0, 3, 0, 9), Region(3, 6, 0, 9),
                                       Region(6, 10, 0, 9))
    assert plan.rounds[1][0].members == (0, 3, 6, 9)
    assert plan.rounds[1][0].held == Region(0, 3, 0, 9)
    assert [p.right - p.left for p in plan.rounds[1][0].parts] == [2, 2, 2, 3]
    covered = np.zeros((10, 9), int)
    for r in plan.regions:
        covered[r.top:r.bottom, r.left:r.right] += 1
    assert (covered == 1).all()
    # direct send by default; as whole sub-images each rank sends the 11 parts it does not
    # keep (11 images in all), then the gather brings all but rank 0's part — 10 rows in 12
    # bands leave rank 0 none, so the whole image
    direct = radix_plan(12, 10, 9)
    assert direct.factors == (12,) and direct.regions[0].pixels == 0
    assert direct.round_pixels() == (11 * 90, 90) and direct.bytes_moved(16) == 12 * 90 * 16
    assert radix_plan(1, 3, 3).factors == () and radix_plan(1, 3, 3).round_count == 0
