"""Faults injected on purpose, so that a check shows it can fail: a render path whose draw is
slower by a known share (for ``workbench results compare`` and its detection benchmark)."""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any


def slowed(path: Any, finish: Callable[[], Any], share: float) -> Any:
    """``path`` with its ``draw`` made ``1 + share`` times as long: after drawing and waiting
    for the draw (``finish``), it spins for ``share`` of the time that took (a spin, not a
    sleep, so that the clock sees busy time). Returns ``path``; refuses a negative share."""
    if not share >= 0:
        raise ValueError(f"share must be >= 0, got {share}")
    draw = path.draw

    def slow_draw() -> None:
        start = time.perf_counter()
        draw()
        finish()
        end = time.perf_counter() + share * (time.perf_counter() - start)
        while time.perf_counter() < end:
            pass

    path.draw = slow_draw
    return path
