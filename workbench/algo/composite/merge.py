"""Sort-last depth compositing of domain frames (es2008, section 1): the per-pixel merge and the
two classic exchange schedules, simulated in one process.

Each domain of a partitioned mesh renders a :class:`~.frame.Frame` of the whole image; the
frames are merged pixel by pixel, keeping the nearest fragment. The merge orders fragments by
the key (drawn, depth, triangle): a drawn pixel (``triangle != NO_TRIANGLE``) beats an empty
one, then the smaller window depth wins, then the smaller global triangle index — the fragment
one renderer drawing every triangle in index order with the ``LESS`` depth test keeps. Where
both keys are equal (both pixels empty, or one triangle in two frames) the first frame wins.
The merge is thus an associative minimum with ties going left, so any schedule that keeps the
frames in domain order — as both here do — gives exactly ``functools.reduce(composite, frames)``
and, for frames of disjoint triangle sets, exactly the one-process image.

Schedules (D frames, rank i holding frame i):

* **binary tree** — the paper's scheme: in each round ranks are paired in order, (0, 1), (2, 3),
  …; the second of a pair sends its whole frame to the first, which composites; an unpaired
  last rank waits for the next round. ``ceil(log2 D)`` rounds, ``D − 1`` frames sent; the
  result ends on rank 0.
* **binary swap** — every rank stays busy: in round k, rank r pairs with ``r XOR 2^k``; both
  hold the same image region, split it in halves (rows in even rounds, columns in odd ones: top
  or left half to the lower rank), send the half they give up and composite the half they keep.
  After ``log2 D`` rounds each rank owns a 1/D-th of the image; a gather sends every region to
  rank 0. D that is not a power of two is first folded down to the largest power of two P ≤ D:
  the first ``D − P`` adjacent pairs (0, 1), (2, 3), … composite whole frames onto their first
  rank, which keeps domain order.

:class:`CompositeStats` reports what a schedule sends between ranks; :func:`tree_plan` and
:func:`swap_plan` describe the exchanges themselves, so that a distributed run
(:mod:`workbench.distributed.sortlast`) follows the same schedule. GL-free and Dask-free.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from ..softraster.frame import NO_TRIANGLE, Frame


@dataclass
class CompositeStats:
    """What compositing ``domains`` frames cost: ``rounds`` communication rounds (binary swap:
    the fold, the swap rounds and the final gather each count as one), ``bytes_moved`` the bytes
    the schedule sends between ranks (colour + depth + triangle bytes of every image or
    sub-image sent, the final gather included for binary swap; nothing a rank keeps counts) and
    ``seconds`` the wall time of the in-process simulation."""

    domains: int
    rounds: int
    bytes_moved: int
    seconds: float


class Region(NamedTuple):
    """Rows ``top:bottom`` and columns ``left:right`` of an image (pixels, row 0 at the top)."""

    top: int
    bottom: int
    left: int
    right: int

    @property
    def pixels(self) -> int:
        return (self.bottom - self.top) * (self.right - self.left)

    def within(self, outer: Region) -> Region:
        """This region in the coordinates of ``outer``'s sub-image (which must contain it)."""
        return Region(self.top - outer.top, self.bottom - outer.top,
                      self.left - outer.left, self.right - outer.left)


def bytes_per_pixel(frame: Frame) -> int:
    """Bytes one pixel of ``frame`` takes: colour channels + depth + triangle index (16 for the
    uint8 RGBA / float32 / int64 frames of the rasterizer)."""
    return (frame.color.dtype.itemsize * frame.color.shape[2] + frame.depth.dtype.itemsize
            + frame.triangle.dtype.itemsize)


def _check(frame: Frame, what: str) -> tuple[int, int]:
    """``frame``'s (height, width); ValueError when its arrays do not make one frame."""
    h, w = frame.depth.shape if frame.depth.ndim == 2 else (-1, -1)
    if (frame.depth.ndim != 2 or frame.triangle.shape != (h, w) or frame.color.ndim != 3
            or frame.color.shape[:2] != (h, w)):
        raise ValueError(f"{what}: colour {frame.color.shape}, depth {frame.depth.shape} and "
                         f"triangle {frame.triangle.shape} do not make one (H, W) frame")
    return h, w


def composite(a: Frame, b: Frame) -> Frame:
    """The per-pixel merge of two frames of one size: a new :class:`Frame` holding at every
    pixel the fragment of ``a`` or ``b`` with the smaller key (drawn before empty, then depth,
    then global triangle index), ``a``'s where the keys are equal (so ``a``'s background where
    both are empty). Refused (ValueError): frames of different sizes, or arrays that do not
    make one frame."""
    shape_a, shape_b = _check(a, "first frame"), _check(b, "second frame")
    if shape_a != shape_b or a.color.shape != b.color.shape:
        raise ValueError(f"cannot composite frames of different sizes: {a.color.shape[:2]} "
                         f"and {b.color.shape[:2]} (rows, columns)")
    drawn_a, drawn_b = a.triangle != NO_TRIANGLE, b.triangle != NO_TRIANGLE
    nearer = (b.depth < a.depth) | ((b.depth == a.depth) & (b.triangle < a.triangle))
    take_b = drawn_b & (~drawn_a | nearer)
    return Frame(np.where(take_b[..., None], b.color, a.color),
                 np.where(take_b, b.depth, a.depth),
                 np.where(take_b, b.triangle, a.triangle))


def crop(frame: Frame, region: Region) -> Frame:
    """The sub-image ``region`` of ``frame`` (views into its arrays, not copies)."""
    rows, cols = slice(region.top, region.bottom), slice(region.left, region.right)
    return Frame(frame.color[rows, cols], frame.depth[rows, cols], frame.triangle[rows, cols])


def assemble(height: int, width: int, regions: Sequence[Region], pieces: Sequence[Frame]) -> Frame:
    """The (height, width) frame made of ``pieces``, piece i covering ``regions[i]``; the
    regions must tile the image (ValueError when their pixels do not add up to it)."""
    if sum(r.pixels for r in regions) != height * width or len(regions) != len(pieces):
        raise ValueError(f"{len(pieces)} pieces over {len(regions)} regions do not tile "
                         f"a {height} x {width} image")
    first = pieces[0]
    out = Frame(np.empty((height, width) + first.color.shape[2:], first.color.dtype),
                np.empty((height, width), first.depth.dtype),
                np.empty((height, width), first.triangle.dtype))
    for region, piece in zip(regions, pieces):
        rows, cols = slice(region.top, region.bottom), slice(region.left, region.right)
        out.color[rows, cols] = piece.color
        out.depth[rows, cols] = piece.depth
        out.triangle[rows, cols] = piece.triangle
    return out


# ------------------------------------------------------------------------------- schedules
@dataclass(frozen=True)
class TreePlan:
    """The binary-tree schedule for ``domains`` frames: ``rounds[k]`` lists the
    (receiver, sender) domain indices of round k; the sender's whole frame goes to the
    receiver, which composites (receiver's frame first)."""

    domains: int
    rounds: tuple[tuple[tuple[int, int], ...], ...]

    def bytes_moved(self, height: int, width: int, pixel_bytes: int) -> int:
        """Bytes sent, one whole frame per pair: ``(domains − 1) · height · width · pixel_bytes``
        (``pixel_bytes`` as from :func:`bytes_per_pixel`)."""
        return sum(len(r) for r in self.rounds) * height * width * pixel_bytes


def tree_plan(domains: int) -> TreePlan:
    """The binary-tree schedule of ``domains`` ≥ 1 frames (ValueError otherwise)."""
    domains = _count(domains)
    active, rounds = list(range(domains)), []
    while len(active) > 1:
        pairs = tuple((active[i], active[i + 1]) for i in range(0, len(active) - 1, 2))
        rounds.append(pairs)
        active = active[::2]
    return TreePlan(domains, tuple(rounds))


class Exchange(NamedTuple):
    """One pair of one binary-swap round: ranks ``lower`` < ``upper`` (positions among the
    ranks left after the fold) both hold region ``held``; ``lower`` keeps ``lower_keeps``,
    ``upper`` keeps ``upper_keeps`` (the two halves of ``held``), each receiving its half of
    the other's sub-image."""

    lower: int
    upper: int
    held: Region
    lower_keeps: Region
    upper_keeps: Region


@dataclass(frozen=True)
class SwapPlan:
    """The binary-swap schedule for ``domains`` frames of ``height`` × ``width`` pixels.

    ``fold``: (keeper, sender) domain pairs composited whole before the swap (empty when
    ``domains`` is a power of two); ``ranks``: the domain index each of the P swap ranks holds
    a frame of afterwards, in domain order; ``rounds[k]``: the exchanges of swap round k;
    ``regions[i]``: the region swap rank i owns at the end (rank 0 gathers them all)."""

    domains: int
    height: int
    width: int
    fold: tuple[tuple[int, int], ...]
    ranks: tuple[int, ...]
    rounds: tuple[tuple[Exchange, ...], ...]
    regions: tuple[Region, ...]

    @property
    def round_count(self) -> int:
        """Communication rounds: the fold (if any), the swap rounds, the gather (if P > 1)."""
        return bool(self.fold) + len(self.rounds) + (len(self.ranks) > 1)

    def bytes_moved(self, pixel_bytes: int) -> int:
        """Bytes sent: a whole frame per fold pair, both halves of every exchange, and every
        final region but rank 0's in the gather."""
        pixels = len(self.fold) * self.height * self.width
        pixels += sum(e.lower_keeps.pixels + e.upper_keeps.pixels for r in self.rounds for e in r)
        pixels += sum(r.pixels for r in self.regions[1:])
        return pixels * pixel_bytes


def swap_plan(domains: int, height: int, width: int) -> SwapPlan:
    """The binary-swap schedule of ``domains`` ≥ 1 frames of ``height`` × ``width`` ≥ 0 pixels
    (ValueError otherwise). A half of an odd length n gets n // 2 to the lower rank; a region
    one pixel (or zero) thick along the round's axis leaves the lower rank an empty half."""
    domains = _count(domains)
    if int(height) != height or int(width) != width or height < 0 or width < 0:
        raise ValueError(f"image size must be non-negative integers, got {height} x {width}")
    height, width = int(height), int(width)
    size = 1 << (domains.bit_length() - 1)  # largest power of two <= domains
    extra = domains - size
    fold = tuple((2 * i, 2 * i + 1) for i in range(extra))
    ranks = tuple(range(0, 2 * extra, 2)) + tuple(range(2 * extra, domains))
    held = [Region(0, height, 0, width)] * size
    rounds = []
    for k in range(size.bit_length() - 1):
        bit, exchanges = 1 << k, []
        for lower in range(size):
            if lower & bit:
                continue
            upper, region = lower | bit, held[lower]
            if k % 2 == 0:
                middle = region.top + (region.bottom - region.top) // 2
                first = region._replace(bottom=middle)
                second = region._replace(top=middle)
            else:
                middle = region.left + (region.right - region.left) // 2
                first = region._replace(right=middle)
                second = region._replace(left=middle)
            exchanges.append(Exchange(lower, upper, region, first, second))
            held[lower], held[upper] = first, second
        rounds.append(tuple(exchanges))
    return SwapPlan(domains, height, width, fold, ranks, tuple(rounds), tuple(held))


def _count(domains) -> int:
    if int(domains) != domains or domains < 1:
        raise ValueError(f"need at least one domain frame, got {domains}")
    return int(domains)


def _frames(frames) -> tuple[list[Frame], int, int]:
    """The frames as a list and their common (height, width); ValueError when there are none
    or their sizes differ."""
    frames = list(frames)
    if not frames:
        raise ValueError("need at least one domain frame, got none")
    sizes = [_check(f, f"frame {i}") + f.color.shape[2:] for i, f in enumerate(frames)]
    if len(set(sizes)) > 1:
        raise ValueError(f"domain frames differ in size: {sorted({s[:2] for s in sizes})} "
                         f"(rows, columns)")
    return frames, sizes[0][0], sizes[0][1]


# ------------------------------------------------------------------------------- simulation
def binary_tree(frames: Sequence[Frame]) -> tuple[Frame, CompositeStats]:
    """Composite ``frames`` (frame i from domain i) by the binary-tree schedule, simulated in
    one process: the composite — exactly ``functools.reduce(composite, frames)``; with one
    frame, that frame itself — and its :class:`CompositeStats`. Refused (ValueError): no
    frames, frames of different sizes."""
    start = time.perf_counter()
    frames, height, width = _frames(frames)
    plan = tree_plan(len(frames))
    held = dict(enumerate(frames))
    for pairs in plan.rounds:
        for receiver, sender in pairs:
            held[receiver] = composite(held[receiver], held.pop(sender))
    stats = CompositeStats(len(frames), len(plan.rounds),
                           plan.bytes_moved(height, width, bytes_per_pixel(frames[0])),
                           time.perf_counter() - start)
    return held[0], stats


def binary_swap(frames: Sequence[Frame]) -> tuple[Frame, CompositeStats]:
    """Composite ``frames`` (frame i from domain i) by binary swap, simulated in one process:
    the composite — exactly ``functools.reduce(composite, frames)``; with one frame, that frame
    itself — and its :class:`CompositeStats`.

    Any count D ≥ 1 works: when D is not a power of two, the first D − P adjacent pairs of
    frames (P the largest power of two ≤ D) are folded — composited whole onto the pair's first
    rank — before the swap rounds (see :func:`swap_plan`). Refused (ValueError): no frames,
    frames of different sizes."""
    start = time.perf_counter()
    frames, height, width = _frames(frames)
    plan = swap_plan(len(frames), height, width)
    folded = {keeper: composite(frames[keeper], frames[sender]) for keeper, sender in plan.fold}
    held = [folded.get(d, frames[d]) for d in plan.ranks]  # sub-image of each rank's region
    for exchanges in plan.rounds:
        for e in exchanges:
            lower, upper = held[e.lower], held[e.upper]
            low_part, high_part = e.lower_keeps.within(e.held), e.upper_keeps.within(e.held)
            held[e.lower] = composite(crop(lower, low_part), crop(upper, low_part))
            held[e.upper] = composite(crop(lower, high_part), crop(upper, high_part))
    result = held[0] if len(held) == 1 else assemble(height, width, plan.regions, held)
    stats = CompositeStats(len(frames), plan.round_count,
                           plan.bytes_moved(bytes_per_pixel(frames[0])),
                           time.perf_counter() - start)
    return result, stats
