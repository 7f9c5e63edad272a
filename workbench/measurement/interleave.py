"""Ratios measured interleaved: A B A B … in one process and one warm state, with an interval.

Two timings taken one after the other see different machines: another process wakes, the
clock steps, a cache cools. A ratio that a table or the README states is therefore measured in
pairs — one draw of the numerator, one of the denominator, repeated — and reported as the
median of the per-pair ratios with its distribution-free 95 % interval
(:func:`~workbench.measurement.stats.paired_ratio_interval`). The pairs go on until that interval
is narrow enough (a :class:`~workbench.measurement.stats.StoppingRule`).

A side is a :class:`Clock`: an untimed ``setup`` (clear the target, bind it) and the timed
``run`` (draw and wait). :func:`draw_clock` makes one for a prepared path
(:func:`workbench.paths.drawing.prepared`); any callable can be one (pyrender's render).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from .stats import CONFIDENCE, Interval, StoppingRule, paired_ratio_interval

if TYPE_CHECKING:
    from ..paths.drawing import Prepared

WHITE = (1.0, 1.0, 1.0, 1.0)


@dataclass(frozen=True)
class Clock:
    """One side of an interleaved measurement: ``setup()`` runs untimed before each timed
    ``run()``."""

    run: Callable[[], Any]
    setup: Callable[[], Any] | None = None


def draw_clock(ready: Prepared,
               background: tuple[float, float, float, float] = WHITE) -> Clock:
    """The clock of a prepared path: setup binds its target, clears it to ``background`` and
    waits; run draws and waits for the backend (as
    :func:`~workbench.measurement.timing.time_draw` times a draw)."""
    def setup() -> None:
        ready.bind()
        ready.target.clear(background)
        ready.backend.finish()

    def run() -> None:
        ready.path.draw()
        ready.backend.finish()

    return Clock(run, setup)


@dataclass(frozen=True)
class Ratio:
    """``numerator`` ÷ ``denominator`` measured interleaved: the median per-pair ratio with its
    interval (``interval``), the pairs' wall times in ms (``numerator_ms``,
    ``denominator_ms``)."""

    numerator: str
    denominator: str
    interval: Interval
    numerator_ms: tuple[float, ...]
    denominator_ms: tuple[float, ...]

    def as_row(self, name: str) -> dict[str, Any]:
        """Columns ``<name>``, ``<name>_lo``, ``<name>_hi`` (the 95 % interval) and
        ``<name>_pairs``."""
        i = self.interval
        return {name: i.estimate, f"{name}_lo": i.lo, f"{name}_hi": i.hi,
                f"{name}_pairs": i.n}

    def __str__(self) -> str:
        i = self.interval
        return (f"{self.numerator} / {self.denominator} = {i.estimate:.3f} "
                f"[{i.lo:.3f}, {i.hi:.3f}] ({i.n} pairs)")


def time_interleaved(clocks: Mapping[str, Clock], ratios: Sequence[tuple[str, str]],
                     stop: StoppingRule, warmup: int = 2) -> dict[str, list[float]]:
    """Run every clock of ``clocks`` once per round, in order, ``warmup`` untimed rounds first,
    until ``stop`` is satisfied for every (numerator, denominator) pair of ``ratios`` (their
    per-round ratios' median interval narrow enough, or ``stop.max_samples`` rounds). Returns
    each clock's wall times (ms), one per timed round. Refuses ratios naming unknown clocks
    and a negative ``warmup``."""
    unknown = {name for pair in ratios for name in pair} - set(clocks)
    if unknown:
        raise ValueError(f"ratios name clocks that are not given: {sorted(unknown)}")
    if warmup < 0:
        raise ValueError(f"warmup must be a non-negative integer, got {warmup}")
    times: dict[str, list[float]] = {name: [] for name in clocks}
    rounds = 0
    while True:
        for name, clock in clocks.items():
            if clock.setup is not None:
                clock.setup()
            start = time.perf_counter()
            clock.run()
            elapsed = (time.perf_counter() - start) * 1e3
            if rounds >= warmup:
                times[name].append(elapsed)
        rounds += 1
        if rounds > warmup and all(stop.done_ratio(times[a], times[b]) for a, b in ratios):
            return times


def interleaved_ratios(clocks: Mapping[str, Clock], ratios: Sequence[tuple[str, str]],
                       stop: StoppingRule, warmup: int = 2,
                       confidence: float = CONFIDENCE) -> dict[tuple[str, str], Ratio]:
    """:func:`time_interleaved`, then each of ``ratios`` as a :class:`Ratio` (keyed by its
    pair)."""
    times = time_interleaved(clocks, ratios, stop, warmup)
    return {(a, b): Ratio(a, b, paired_ratio_interval(times[a], times[b], confidence),
                          tuple(times[a]), tuple(times[b]))
            for a, b in ratios}
