"""How often ``workbench results history`` finds a step in a quantity's history, and how often
it reports one that is not there: synthetic histories of 30 runs, each run's value the median
of its timed draws, each draw lognormal with a coefficient of variation (CV) of 0.1 or 0.2 (the
spread of one path's draws on this 2-core llvmpipe machine), with and without a 10 % step.

Draws per run: 41 as a full-size run takes them at that spread (its stopping rule wants the
median's 95 % interval within ±2 %, which such a spread never reaches before its 41st draw),
and 9 as a quick run takes them (±5 %, at most 9). The step lies at a run drawn uniformly from
5 to 25 and counts as found when a change point lies within two runs of it. Changes are found by
:func:`~workbench.results.changepoints.change_points` at its default significance (0.02).

One case per (draws, CV): a row ``detection`` with ``detected_share`` (trials with a step in
which it is found), ``false_alarm_share`` (trials without a step that report any change),
``trials`` and the case's parameters; and the timed ``change_points`` call on one 30-run
series. Full: 100 trials of each kind; quick: 20.

Run: ``workbench bench changepoint_detection [--quick]``.
"""

from __future__ import annotations

import numpy as np

from workbench.measurement.bench import Case, benchmark

RUNS, STEP, FIRST, LAST, WITHIN = 30, 0.10, 5, 25, 2
CASES = [Case(f"draws={draws}, cv={cv}", {"draws": draws, "cv": cv, "trials": 100},
              {"draws": draws, "cv": cv, "trials": 20})
         for draws in (41, 9) for cv in (0.1, 0.2)]


def history(rng: np.random.Generator, draws: int, cv: float, at: int | None) -> np.ndarray:
    """One synthetic history: ``RUNS`` medians of ``draws`` lognormal draws of CV ``cv``,
    times 1 + ``STEP`` from run ``at`` on (no step for None)."""
    sigma = np.sqrt(np.log(1.0 + cv * cv))
    medians = np.median(np.exp(rng.normal(0.0, sigma, size=(RUNS, draws))), axis=1)
    if at is not None:
        medians[at:] *= 1.0 + STEP
    return medians


@benchmark("changepoint_detection", "detection and false alarms of the change points of "
                                    "`results history` on synthetic 30-run histories",
           cases=CASES)
def changepoint_detection(bench, draws: int, cv: float, trials: int) -> None:
    from workbench.results.changepoints import change_points

    rng = np.random.default_rng(20261208)
    found = false = 0
    for _ in range(trials):
        at = int(rng.integers(FIRST, LAST + 1))
        found += any(abs(c - at) <= WITHIN for c in change_points(history(rng, draws, cv, at)))
        false += bool(change_points(history(rng, draws, cv, None)))
    bench.record("detection", detected_share=found / trials, false_alarm_share=false / trials,
                 trials=trials, step=STEP, runs=RUNS)
    series = history(rng, draws, cv, RUNS // 2)
    bench.time("change_points", lambda: change_points(series))
