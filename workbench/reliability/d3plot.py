"""Damaged copies of a d3plot (:func:`run_d3plot_stress`): cut at a random byte, random bytes
overwritten, a block zeroed; each copy must be read (whole, or with the sections that failed
named in warnings) or refused with ParseError, never raise another exception, never hang."""

from __future__ import annotations

import random
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

from .readers import TIMEOUT_S, read_outcome

D3PLOT_KINDS = ("truncate", "garble", "zero block")


@dataclass
class D3plotStressReport:
    """Outcomes of ``n`` damaged copies of a d3plot: ``counts`` (kind → outcome → count; the
    outcomes are "read" — whole, or with the sections that failed named in warnings —, "parse
    error", "other exception" and "hang"), ``failures`` (one line each, with the seed and
    index that reproduce it) and ``seconds``."""

    n: int
    seed: int
    counts: dict
    failures: list
    seconds: float

    @property
    def ok(self) -> bool:
        return not self.failures

    def table(self) -> str:
        outcomes = ("read", "parse error", "other exception", "hang")
        rows = [f"{'d3plot damage':<14}" + "".join(f"{o:>17}" for o in outcomes)]
        rows.append("-" * len(rows[0]))
        for kind in D3PLOT_KINDS:
            rows.append(f"{kind:<14}" + "".join(f"{self.counts[kind][o]:>17}" for o in outcomes))
        return "\n".join(rows)


def damaged_d3plot(data: bytes, index: int, seed: int) -> tuple[str, bytes]:
    """(kind, bytes) of damage ``index`` of ``seed`` to the d3plot ``data``: cut at a random
    byte, 1–16 random bytes overwritten, or a block of up to 4 KiB zeroed."""
    rng = random.Random(f"d3plot:{seed}:{index}")
    kind = rng.choice(D3PLOT_KINDS)
    damaged = bytearray(data)
    if kind == "truncate":
        del damaged[rng.randrange(64, len(damaged)):]
    elif kind == "garble":
        for _ in range(rng.randint(1, 16)):
            damaged[rng.randrange(len(damaged))] = rng.randrange(256)
    else:
        start = rng.randrange(len(damaged))
        end = min(len(damaged), start + rng.randint(1, 4096))
        damaged[start:end] = bytes(end - start)
    return kind, bytes(damaged)


def run_d3plot_stress(n: int, seed: int, source=None,
                      timeout: float = TIMEOUT_S) -> D3plotStressReport | None:
    """Read ``n`` damaged copies of the d3plot ``source`` (default: the first file of the
    shared d3plot; None when it is absent): each must be read or refused with ParseError,
    never another exception, never past ``timeout`` seconds."""
    from ..data import D3PLOT, shared_file
    from ..scene.readers.d3plot import read_d3plot

    source = shared_file(D3PLOT) if source is None else Path(source)
    if source is None:
        return None
    data = Path(source).read_bytes()
    counts = {kind: dict.fromkeys(("read", "parse error", "other exception", "hang"), 0)
              for kind in D3PLOT_KINDS}
    failures = []
    start = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="workbench-stress-") as folder:
        target = Path(folder) / "d3plot"
        for index in range(n):
            kind, damaged = damaged_d3plot(data, index, seed)
            target.write_bytes(damaged)
            _, outcome, why = read_outcome(target, timeout, read_d3plot)
            counts[kind][outcome] += 1
            if outcome in ("other exception", "hang"):
                failures.append(f"d3plot seed {seed} index {index} ({kind}): {outcome}: {why}")
    return D3plotStressReport(n, seed, counts, failures, time.perf_counter() - start)
