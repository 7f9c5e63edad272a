"""The numerical stress suite (:func:`run_numerics_stress`, ``workbench stress numerics [--n N]
[--seed S]``): the geometric kernels and the colour paths on adversarial inputs, each answer
checked against an exact rational reference written for the suite
(:mod:`~workbench.reliability.exact`, :mod:`~workbench.reliability.exact_planar`), never
against the production kernels.

The inputs come from seeded generators (:mod:`~workbench.reliability.numerics_cases`,
:mod:`~workbench.reliability.numerics_scenes`): slivers and needles over ε from 1e-2 to 1e-15,
collinear and repeated corners, fans of 1 000 thin triangles, near-coincident and touching
sheets, far offsets 1e3–1e7 (dyadic, so that the exact answer stays known), collapsed elements,
near-zero-volume tetrahedra, fields that are NaN, constant, on a band boundary or spanning
1e-30…1e30. The checks (:mod:`~workbench.reliability.numerics_checks`,
:mod:`~workbench.reliability.numerics_images`), one group of rows each:

a. point–triangle distance and closest point; b. part distances; c. Hausdorff brackets;
d. the simplifier's bounds; e. rasterizer coverage; f. GL against software images; g. spacetime
slice areas; h. fields through the colour paths.

Every row of the report is one check on one generator: how many answers were checked, how
many broke the promise, and the worst error in the row's unit (the promise's own where it is
a bound, ≤ 1 keeping it; for brackets and bounds the largest amount by which an exact value
lies outside, ≤ 0 keeping it; for pixels the count of wrong ones; the note or the check's
documentation names the promise). Case ``i``
of a generator is drawn from ``numpy.random.default_rng([seed, key, i])``, so every failure is
reproduced by the seed, the generator and the index named in its line
(:func:`~workbench.reliability.numerics_cases.case_rng`).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

from .numerics_cases import case_rng

__all__ = ["DEFAULT_N", "NumericsReport", "Tally", "case_rng", "run_numerics_stress"]

DEFAULT_N = 400  # distance cases per generator; the other checks scale with it (see run)
EXAMPLES = 3  # failing answers quoted per row


@dataclass
class Tally:
    """One row: ``check`` on the cases of generator ``case``; ``count`` answers checked,
    ``failed`` of them broke the promise; ``worst`` the largest error in ``unit`` (NaN where
    none was measured); ``note`` a second measure; ``examples`` the first failing answers."""

    check: str
    case: str
    unit: str
    count: int = 0
    failed: int = 0
    worst: float = math.nan
    note: str = ""
    examples: list[str] = field(default_factory=list)

    def record(self, error: float, ok: bool, what: str = "") -> None:
        """Count one answer with ``error`` (in ``unit``; NaN counts as the worst) and whether it
        kept the promise; ``what`` says which answer (quoted when it failed)."""
        self.count += 1
        error = math.inf if math.isnan(float(error)) else float(error)
        if math.isnan(self.worst) or error > self.worst:
            self.worst = error
        if not ok:
            self.failed += 1
            if len(self.examples) < EXAMPLES:
                self.examples.append(what)

    def skip(self, why: str) -> None:
        """Mark the row as not run (``note`` says why); it neither passes nor fails."""
        self.note = f"skipped: {why}"


@dataclass
class NumericsReport:
    """The rows (:class:`Tally`), the seed, ``n`` and the seconds taken."""

    n: int
    seed: int
    rows: list[Tally] = field(default_factory=list)
    seconds: float = 0.0

    def row(self, check: str, case: str, unit: str) -> Tally:
        """A new row, appended."""
        tally = Tally(check, case, unit)
        self.rows.append(tally)
        return tally

    @property
    def failures(self) -> list[str]:
        """One line per failing row: check, case, how many failed, the worst error and the
        first failing answers."""
        out = []
        for r in self.rows:
            if r.failed:
                out.append(f"{r.check}: {r.case}: {r.failed} of {r.count} broke the promise, "
                           f"worst {_number(r.worst)} {r.unit}; " + "; ".join(r.examples))
        return out

    @property
    def ok(self) -> bool:
        """True when every row kept its promise."""
        return not any(r.failed for r in self.rows)

    def failing(self, check: str | None = None) -> list[Tally]:
        """The failing rows (of ``check`` only, when given: a prefix such as "a." or "c.")."""
        return [r for r in self.rows if r.failed and (check is None or r.check.startswith(check))]

    def table(self) -> str:
        """The rows as a text table: check, case, count, failures, worst, unit, note."""
        cw = max([len(r.check) for r in self.rows] + [5])
        kw = max([len(r.case) for r in self.rows] + [4])
        uw = max([len(r.unit) for r in self.rows] + [4])
        head = (f"{'check':<{cw}}  {'case':<{kw}}  {'count':>7}  {'failed':>6}  {'worst':>10}  "
                f"{'unit':<{uw}}  note")
        lines = [head, "-" * (len(head) + 20)]
        for r in self.rows:
            mark = "   <- FAILED" if r.failed else ""
            lines.append(f"{r.check:<{cw}}  {r.case:<{kw}}  {r.count:>7}  {r.failed:>6}  "
                         f"{_number(r.worst):>10}  {r.unit:<{uw}}  {r.note}{mark}")
        return "\n".join(lines)


def _number(x: float) -> str:
    if math.isnan(x):
        return "-"
    if x == 0 or math.isinf(x):
        return f"{x:g}"
    return f"{x:.3g}" if 1e-3 <= abs(x) < 1e4 else f"{x:.2e}"


def run_numerics_stress(n: int = DEFAULT_N, seed: int = 0, *, gl: bool = True,
                        checks: str = "abcdefgh") -> NumericsReport:
    """Run the suite: ``n`` cases per generator of the distance check (8 queries each, so
    ``n = 400`` checks 25 600 queries over 8 generators), and per generator ``max(2, n // 8)``
    Hausdorff pairs, ``max(1, n // 40)`` part-distance and simplifier meshes, ``max(1, n // 20)``
    spacetime meshes, ``max(1, n // 200)`` raster scenes; ``gl`` whether the GL images are drawn
    (else their rows are skipped; they are also skipped where no GL context can be made);
    ``checks`` which of a–h to run. Refuses ``n < 1`` and letters other than a–h
    (ValueError)."""
    from . import numerics_checks as geometric
    from . import numerics_images as images

    if int(n) != n or n < 1:
        raise ValueError(f"n must be a positive integer, got {n!r}")
    if set(checks) - set("abcdefgh"):
        raise ValueError(f"checks are letters of a-h, got {checks!r}")
    n, seed = int(n), int(seed)
    start = time.perf_counter()
    report = NumericsReport(n=n, seed=seed)
    steps = {"a": lambda: geometric.check_distances(report, n, seed),
             "b": lambda: geometric.check_part_distances(report, max(1, n // 40), seed),
             "c": lambda: geometric.check_hausdorff(report, max(2, n // 8), seed),
             "d": lambda: geometric.check_simplifier(report, max(1, n // 40), seed),
             "e": lambda: images.check_coverage(report, max(1, n // 200), seed),
             "f": lambda: images.check_gl_against_software(report, seed, gl),
             "g": lambda: geometric.check_slices(report, max(1, n // 20), seed),
             "h": lambda: images.check_fields(report, seed, gl)}
    for key in "abcdefgh":
        if key in checks:
            steps[key]()
    report.seconds = time.perf_counter() - start
    return report
