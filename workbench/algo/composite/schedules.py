"""Active-pixel compositing schedules (:mod:`.active`): the radix-k plan and the tree, binary
swap and radix-k schedules run in one process over encoded pieces.

:func:`radix_plan`: D = k_1 · k_2 · …; in round i groups of k_i ranks split the region they
hold into k_i parts, each member keeping one and receiving it from the other k_i − 1; then
rank 0 gathers ((2, 2, …) is binary swap, (D,) direct send). :func:`active_tree`,
:func:`active_swap` and :func:`active_radix` return the composite — exactly
``functools.reduce(composite, frames)`` for depths that are not NaN — and :class:`ActiveStats`:
encoded bytes sent per round and in all, beside what the same schedule sends as whole
(sub-)images. GL-free and Dask-free.
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import NamedTuple

from ..softraster.frame import Frame
from .active import ActivePixels, merge, merge_ordered, paint
from .merge import CompositeStats, Region, _count, _frames, bytes_per_pixel, swap_plan, tree_plan


# ------------------------------------------------------------------------------- radix-k plan
class RadixGroup(NamedTuple):
    """One group of one radix-k round: ranks ``members`` (ascending, so in domain order) all
    hold region ``held``; member j keeps ``parts[j]`` and receives it from every other
    member."""

    members: tuple[int, ...]
    held: Region
    parts: tuple[Region, ...]


@dataclass(frozen=True)
class RadixPlan:
    """The radix-k schedule for ``domains`` frames of ``height`` × ``width`` pixels with round
    sizes ``factors`` (their product is ``domains``): ``rounds[i]`` the groups of round i,
    ``regions[r]`` the region rank r (= domain r) owns at the end; rank 0 gathers them all."""

    domains: int
    height: int
    width: int
    factors: tuple[int, ...]
    rounds: tuple[tuple[RadixGroup, ...], ...]
    regions: tuple[Region, ...]

    @property
    def round_count(self) -> int:
        """Communication rounds: one per factor, and the gather when ``domains`` > 1."""
        return len(self.rounds) + (self.domains > 1)

    def round_pixels(self) -> tuple[int, ...]:
        """Pixels sent per round as whole sub-images: every member's part to each of the other
        k − 1 members, then every region but rank 0's in the gather."""
        out = [sum((len(g.members) - 1) * g.held.pixels for g in groups)
               for groups in self.rounds]
        if self.domains > 1:
            out.append(sum(r.pixels for r in self.regions[1:]))
        return tuple(out)

    def bytes_moved(self, pixel_bytes: int) -> int:
        """Bytes sent as whole sub-images (``pixel_bytes`` as from :func:`bytes_per_pixel`)."""
        return sum(self.round_pixels()) * pixel_bytes


def _split(region: Region, k: int, rows: bool) -> tuple[Region, ...]:
    """``region`` cut into ``k`` bands across rows (or columns): band j starts at
    ``start + (length · j) // k`` (for k = 2 the halves of :func:`.composite.swap_plan`)."""
    start, stop = (region.top, region.bottom) if rows else (region.left, region.right)
    cuts = [start + (stop - start) * j // k for j in range(k + 1)]
    if rows:
        return tuple(region._replace(top=a, bottom=b) for a, b in zip(cuts, cuts[1:]))
    return tuple(region._replace(left=a, right=b) for a, b in zip(cuts, cuts[1:]))


def radix_plan(domains: int, height: int, width: int,
               factors: Sequence[int] | None = None) -> RadixPlan:
    """The radix-k schedule of ``domains`` ≥ 1 frames of ``height`` × ``width`` ≥ 0 pixels.

    ``factors`` (default ``(domains,)``: direct send; ``()`` for one domain) are the group
    sizes of the rounds, each ≥ 2, their product ``domains``. Rank r's digits are its
    mixed-radix digits, the first round's the fastest: round i groups the ranks differing only
    in digit i, whose frames so far cover consecutive blocks of domains, so merging a group in
    member order keeps domain order. The held region is cut into bands across rows in even
    rounds and across columns in odd ones (as binary swap); factors (2, 2, …) give
    :func:`.composite.swap_plan`'s regions. Refused (ValueError): a bad count or size, factors
    below 2 or whose product is not ``domains``."""
    domains = _count(domains)
    if int(height) != height or int(width) != width or height < 0 or width < 0:
        raise ValueError(f"image size must be non-negative integers, got {height} x {width}")
    factors = (domains,) if factors is None and domains > 1 else tuple(factors or ())
    if any(int(k) != k or k < 2 for k in factors) or math.prod(factors) != domains:
        raise ValueError(f"radix-k factors must be integers >= 2 whose product is the domain "
                         f"count {domains}, got {factors}")
    factors = tuple(int(k) for k in factors)
    held = [Region(0, int(height), 0, int(width))] * domains
    rounds, stride = [], 1
    for i, k in enumerate(factors):
        groups = []
        for first in range(domains):
            if (first // stride) % k:
                continue  # each group once: from its member with digit i = 0
            members = tuple(first + j * stride for j in range(k))
            parts = _split(held[first], k, rows=i % 2 == 0)
            groups.append(RadixGroup(members, held[first], parts))
            for rank, part in zip(members, parts):
                held[rank] = part
        rounds.append(tuple(groups))
        stride *= k
    return RadixPlan(domains, int(height), int(width), factors, tuple(rounds), tuple(held))


# ------------------------------------------------------------------------------- simulation
@dataclass
class ActiveStats(CompositeStats):
    """:class:`.composite.CompositeStats` of an active-pixel schedule (``bytes_moved``: the
    encoded bytes, :attr:`EncodedPiece.nbytes`, of every piece sent), with ``method``,
    ``round_bytes`` the encoded bytes sent in each round, and ``full_round_bytes`` /
    ``full_frame_bytes`` what the same schedule sends per round / in all as whole
    (sub-)images."""

    method: str = ""
    round_bytes: tuple[int, ...] = ()
    full_round_bytes: tuple[int, ...] = ()
    full_frame_bytes: int = 0


def _send(sent: list[int], pixels: ActivePixels) -> ActivePixels:
    """What a rank receives of ``pixels`` sent as a piece, its bytes added to ``sent[-1]``."""
    piece = pixels.pack()
    sent[-1] += piece.nbytes
    return piece.unpack()


def _run(frames, method: str, schedule) -> tuple[Frame, ActiveStats]:
    """Runs ``schedule(held, sent, height, width)`` → (final parts, full-frame pixels sent
    per round) over the frames' drawn pixels; paints the parts over frame 0."""
    start = time.perf_counter()
    frames, height, width = _frames(frames)
    sent: list[int] = []  # encoded bytes per round
    result, full = frames[0], ()
    if len(frames) > 1:
        held = [ActivePixels.from_frame(f) for f in frames]
        parts, full = schedule(held, sent, height, width)
        result = paint(frames[0], parts)
    full = tuple(p * bytes_per_pixel(frames[0]) for p in full)
    return result, ActiveStats(len(frames), len(sent), sum(sent), time.perf_counter() - start,
                               method, tuple(sent), full, sum(full))


def _tree(held, sent, height, width):
    plan = tree_plan(len(held))
    for pairs in plan.rounds:
        sent.append(0)
        for receiver, sender in pairs:
            held[receiver] = merge(held[receiver], _send(sent, held[sender]))
    return [held[0]], tuple(len(pairs) * height * width for pairs in plan.rounds)


def _swap(held, sent, height, width):
    plan = swap_plan(len(held), height, width)
    full = []
    if plan.fold:
        sent.append(0)
        for keeper, sender in plan.fold:
            held[keeper] = merge(held[keeper], _send(sent, held[sender]))
        full.append(len(plan.fold) * height * width)
    held = [held[d] for d in plan.ranks]
    for exchanges in plan.rounds:
        sent.append(0)
        for e in exchanges:
            lower, upper = held[e.lower], held[e.upper]
            to_lower = _send(sent, upper.cut(e.lower_keeps))
            to_upper = _send(sent, lower.cut(e.upper_keeps))
            held[e.lower] = merge(lower.cut(e.lower_keeps), to_lower)
            held[e.upper] = merge(to_upper, upper.cut(e.upper_keeps))
        full.append(sum(e.held.pixels for e in exchanges))
    return _gather(held, sent, full)


def _gather(held, sent, full):
    """Ranks 1… send their final parts to rank 0 (one round)."""
    if len(held) > 1:
        sent.append(0)
        held = [held[0]] + [_send(sent, part) for part in held[1:]]
        full.append(sum(part.region.pixels for part in held[1:]))
    return held, tuple(full)


def active_tree(frames: Sequence[Frame]) -> tuple[Frame, ActiveStats]:
    """``frames`` (frame i from domain i) composited by the binary tree
    (:func:`.composite.tree_plan`), simulated in one process, every image sent as an
    :class:`EncodedPiece`: exactly ``functools.reduce(composite, frames)`` (one frame: that
    frame itself), and its :class:`ActiveStats`. Refused (ValueError): no frames, frames of
    different sizes."""
    return _run(frames, "active tree", _tree)


def active_swap(frames: Sequence[Frame]) -> tuple[Frame, ActiveStats]:
    """As :func:`active_tree`, by binary swap (:func:`.composite.swap_plan`: any count,
    folded to a power of two)."""
    return _run(frames, "active swap", _swap)


def active_radix(frames: Sequence[Frame], factors: Sequence[int] | None = None,
                 ) -> tuple[Frame, ActiveStats]:
    """As :func:`active_tree`, by radix-k with round sizes ``factors`` (:func:`radix_plan`;
    default: direct send). Also refused (ValueError): factors whose product is not the frame
    count."""
    frames = list(frames)
    plan = radix_plan(len(frames), *(_frames(frames)[1:]), factors)

    def schedule(held, sent, height, width):
        for groups in plan.rounds:
            sent.append(0)
            for g in groups:
                kept = [merge_ordered([held[m].cut(part) if i == j else
                                       _send(sent, held[m].cut(part))
                                       for i, m in enumerate(g.members)])
                        for j, part in enumerate(g.parts)]
                for rank, part in zip(g.members, kept):
                    held[rank] = part
        return _gather(held, sent, list(plan.round_pixels()[:len(plan.rounds)]))

    name = "active radix-k " + "x".join(map(str, plan.factors))
    return _run(frames, name, schedule)
