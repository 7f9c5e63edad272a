"""Timing statistics: interval coverage on known distributions, exact order-statistic ranks,
the bootstrap ratio of medians, the stopping rule and the inputs each function refuses."""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.stats import norm

from workbench.measurement.stats import (
    CONFIDENCE,
    Interval,
    StoppingRule,
    median_interval,
    paired_ratio_interval,
    ratio_of_medians_interval,
)

TRIALS = 2000
MC_TOL = 0.02  # ~4.5 Monte-Carlo standard errors at 2000 trials and coverage ~0.95
SIZES = (5, 9, 15, 31)
OUTLIER_SHARE = 0.1


def _coverage(intervals, truth) -> float:
    return float(np.mean([iv.lo <= truth <= iv.hi for iv in intervals]))


def _lognormal(rng, n):
    mu, sigma = math.log(4.0), 0.5
    return rng.lognormal(mu, sigma, size=(TRIALS, n)), math.exp(mu)


def _exponential(rng, n):
    rate = 0.25
    return rng.exponential(1 / rate, size=(TRIALS, n)), math.log(2) / rate


def _normal_with_outliers(rng, n):
    # slow outliers, always far above the bulk: the median solves (1 - share) * Phi(m - 10) = 1/2
    x = rng.normal(10.0, 1.0, size=(TRIALS, n))
    slow = rng.random((TRIALS, n)) < OUTLIER_SHARE
    x[slow] = 20.0 + rng.exponential(30.0, size=int(slow.sum()))
    return x, 10.0 + float(norm.ppf(0.5 / (1 - OUTLIER_SHARE)))


def _exact_coverage(n: int, j: int) -> Fraction:
    """1 - 2 P(Bin(n, 1/2) <= j - 1), exactly."""
    return 1 - 2 * Fraction(sum(math.comb(n, i) for i in range(j)), 2**n)


# --- coverage on known distributions ---------------------------------------------------------


@pytest.mark.parametrize("draw", [_lognormal, _exponential, _normal_with_outliers])
@pytest.mark.parametrize("n", SIZES)
def test_median_interval_covers_true_median_at_stated_confidence(draw, n):
    rng = np.random.default_rng(1000 + n)
    samples, truth = draw(rng, n)
    intervals = [median_interval(row) for row in samples]
    stated = intervals[0].confidence
    assert all(iv.confidence == stated for iv in intervals)
    if n >= 6:
        assert stated >= CONFIDENCE
    else:
        assert stated == pytest.approx(0.9375)
    covered = _coverage(intervals, truth)
    # order statistics give exact coverage for continuous samples: neither below nor above
    assert covered >= stated - MC_TOL
    assert covered <= stated + MC_TOL
    if n == 31:
        assert covered < 0.995


@pytest.mark.parametrize("n", SIZES)
def test_paired_ratio_interval_covers_true_ratio(n):
    rng = np.random.default_rng(2000 + n)
    r = 1.7
    b = rng.lognormal(math.log(3.0), 0.4, size=(TRIALS, n))  # drift shared by each pair
    noise = rng.lognormal(0.0, 0.2, size=(TRIALS, n))  # median 1
    a = r * b * noise
    intervals = [paired_ratio_interval(x, y) for x, y in zip(a, b, strict=True)]
    stated = intervals[0].confidence
    covered = _coverage(intervals, r)
    assert covered >= stated - MC_TOL
    assert covered <= stated + MC_TOL
    assert np.median([iv.estimate for iv in intervals]) == pytest.approx(r, rel=0.02)


# --- exact order statistics ------------------------------------------------------------------


def test_five_samples_give_min_max_at_0_9375():
    iv = median_interval([3.0, 1.0, 5.0, 2.0, 4.0])
    assert (iv.lo, iv.estimate, iv.hi, iv.n) == (1.0, 3.0, 5.0, 5)
    assert iv.confidence == pytest.approx(0.9375)
    assert iv.confidence < CONFIDENCE  # the achievable level, below the requested one


def test_nine_samples_give_ranks_2_and_8():
    values = np.random.default_rng(0).permutation(np.arange(1.0, 10.0))
    iv = median_interval(values, 0.95)
    assert (iv.lo, iv.estimate, iv.hi) == (2.0, 5.0, 8.0)
    assert iv.confidence == pytest.approx(1 - 20 / 512)
    assert iv.confidence == pytest.approx(0.9609, abs=1e-4)


@pytest.mark.parametrize("confidence", [0.8, 0.9, 0.95, 0.99])
def test_ranks_are_the_narrowest_reaching_the_confidence(confidence):
    for n in range(1, 80):
        iv = median_interval(np.arange(1.0, n + 1.0), confidence)
        j = int(iv.lo)
        assert iv.hi == n + 1 - j
        assert iv.confidence == pytest.approx(float(_exact_coverage(n, j)), abs=1e-12)
        if _exact_coverage(n, 1) < confidence:
            assert j == 1  # too few samples: (min, max) at the achievable level
            continue
        assert _exact_coverage(n, j) >= confidence
        if j + 1 <= (n + 1) // 2:
            assert _exact_coverage(n, j + 1) < confidence


timing_lists = st.lists(st.floats(1e-3, 1e6, allow_nan=False, allow_infinity=False),
                        min_size=1, max_size=80)


@settings(max_examples=150, deadline=None)
@given(timing_lists, st.randoms(use_true_random=False), st.floats(1e-3, 1e3))
def test_median_interval_properties(values, random, scale):
    iv = median_interval(values)
    assert iv.lo <= iv.estimate <= iv.hi
    assert iv.lo in values and iv.hi in values
    assert iv.n == len(values)

    shuffled = list(values)
    random.shuffle(shuffled)
    assert median_interval(shuffled) == iv

    scaled = median_interval([scale * v for v in values])
    assert scaled.lo == scale * iv.lo and scaled.hi == scale * iv.hi
    assert scaled.estimate == pytest.approx(scale * iv.estimate, rel=1e-12)
    assert scaled.confidence == iv.confidence


def test_interval_helpers():
    iv = Interval(estimate=10.0, lo=9.0, hi=12.0, confidence=0.95, n=9)
    assert iv.half_width == 1.5
    assert iv.relative_half_width == 0.15
    assert Interval(0.0, -1.0, 1.0, 0.95, 9).relative_half_width == math.inf
    assert Interval(-10.0, -12.0, -9.0, 0.95, 9).relative_half_width == 0.15
    assert iv.excludes(8.9) and iv.excludes(12.1)
    assert not iv.excludes(9.0) and not iv.excludes(12.0) and not iv.excludes(10.0)
    assert iv.overlaps(Interval(13.0, 12.0, 14.0, 0.95, 9))
    assert Interval(13.0, 12.0, 14.0, 0.95, 9).overlaps(iv)
    assert iv.overlaps(Interval(10.0, 9.5, 10.5, 0.95, 9))  # nested
    assert not iv.overlaps(Interval(13.0, 12.5, 14.0, 0.95, 9))
    assert not Interval(8.0, 7.0, 8.9, 0.95, 9).overlaps(iv)


# --- bootstrap ratio of medians --------------------------------------------------------------


def test_ratio_of_medians_covers_true_ratio():
    rng = np.random.default_rng(3000)
    trials, n, ratio = 300, 20, 1.3
    a = rng.lognormal(math.log(5.0), 0.3, size=(trials, n))
    b = rng.lognormal(math.log(5.0 * ratio), 0.3, size=(trials, n))
    pairs = enumerate(zip(a, b, strict=True))
    intervals = [ratio_of_medians_interval(x, y, seed=i) for i, (x, y) in pairs]
    assert all(iv.confidence == CONFIDENCE and iv.n == n for iv in intervals)
    covered = _coverage(intervals, ratio)
    # 300 trials: one standard error is ~0.013; the percentile bootstrap is only approximate
    assert covered >= CONFIDENCE - 0.04
    assert covered < 0.995


def test_ratio_of_medians_is_b_relative_to_a():
    a = np.random.default_rng(4).lognormal(math.log(8.0), 0.1, size=25)
    iv = ratio_of_medians_interval(a, 2.0 * a)
    assert iv.estimate == pytest.approx(2.0)
    assert iv.lo <= 2.0 <= iv.hi


def test_ratio_of_medians_identical_samples_contain_one():
    a = np.random.default_rng(5).lognormal(math.log(8.0), 0.3, size=30)
    iv = ratio_of_medians_interval(a, a.copy())
    assert iv.estimate == 1.0
    assert not iv.excludes(1.0)


def test_ratio_of_medians_detects_a_20_percent_shift():
    rng = np.random.default_rng(6)
    a = rng.lognormal(math.log(8.0), 0.05, size=30)
    b = rng.lognormal(math.log(8.0 * 1.2), 0.05, size=30)
    iv = ratio_of_medians_interval(a, b)
    assert iv.excludes(1.0)
    assert iv.lo > 1.1
    assert iv.estimate == pytest.approx(1.2, rel=0.05)


def test_ratio_of_medians_is_deterministic_for_a_seed():
    rng = np.random.default_rng(7)
    a, b = rng.lognormal(0, 0.5, size=15), rng.lognormal(0.2, 0.5, size=12)
    first = ratio_of_medians_interval(a, b, seed=11)
    assert ratio_of_medians_interval(a, b, seed=11) == first
    other = ratio_of_medians_interval(a, b, seed=12)
    assert other.estimate == first.estimate
    assert (other.lo, other.hi) != (first.lo, first.hi)


# --- stopping rule ---------------------------------------------------------------------------


def test_stopping_rule_never_done_before_min_samples():
    rule = StoppingRule(min_samples=8, max_samples=30)
    constant = [5.0] * 30
    assert not any(rule.done(constant[:k]) for k in range(8))
    assert not any(rule.done_ratio(constant[:k], constant[:k]) for k in range(8))
    assert rule.done(constant[:8])


def test_stopping_rule_always_done_at_max_samples():
    noisy = np.random.default_rng(8).lognormal(0.0, 2.0, size=40)
    rule = StoppingRule(max_samples=20)
    assert rule.done(noisy[:20]) and rule.done(noisy)
    assert rule.done_ratio(noisy[:20], noisy[20:])


def test_stopping_rule_stops_early_on_steady_samples():
    steady = 10.0 + 1e-4 * np.random.default_rng(9).standard_normal(60)
    rule = StoppingRule()
    # five samples reach only 0.9375 < 0.95 however tight they are; six reach 0.96875
    assert not rule.done(steady[:5])
    assert rule.done(steady[:6])
    assert rule.done_ratio(1.5 * steady[:6] * (1 + 1e-4 * steady[6:12]), steady[12:18])


def test_stopping_rule_keeps_going_on_noisy_samples():
    rng = np.random.default_rng(10)
    noisy = rng.lognormal(0.0, 1.0, size=60)
    rule = StoppingRule()
    assert not any(rule.done(noisy[:k]) for k in range(rule.max_samples))
    b = rng.lognormal(0.0, 1.0, size=60)
    assert not any(rule.done_ratio(noisy[:k], b[:k]) for k in range(rule.max_samples))


@pytest.mark.parametrize("kwargs", [
    {"min_samples": 4}, {"min_samples": 10, "max_samples": 9}, {"rel_half_width": 0.0},
    {"rel_half_width": -0.1}, {"rel_half_width": math.nan}, {"confidence": 0.0},
    {"confidence": 1.0}, {"confidence": 1.5},
])
def test_stopping_rule_refuses_bad_parameters(kwargs):
    with pytest.raises(ValueError):
        StoppingRule(**kwargs)


# --- refused inputs --------------------------------------------------------------------------


@pytest.mark.parametrize("samples, match", [
    ([], "empty"), ([1.0, math.nan, 2.0], "non-finite"), ([1.0, math.inf], "non-finite"),
    ([[1.0, 2.0], [3.0, 4.0]], "1-D"),
])
def test_median_interval_refuses(samples, match):
    with pytest.raises(ValueError, match=match):
        median_interval(samples)


@pytest.mark.parametrize("confidence", [0.0, 1.0, -0.5, 2.0])
def test_confidence_outside_unit_interval_refused(confidence):
    with pytest.raises(ValueError, match="confidence"):
        median_interval([1.0, 2.0, 3.0], confidence)
    with pytest.raises(ValueError, match="confidence"):
        ratio_of_medians_interval([1.0, 2.0, 3.0], [1.0, 2.0, 3.0], confidence)


def test_paired_ratio_interval_refuses():
    with pytest.raises(ValueError, match="equal lengths"):
        paired_ratio_interval([1.0, 2.0, 3.0], [1.0, 2.0])
    with pytest.raises(ValueError, match="positive"):
        paired_ratio_interval([1.0, 2.0, 3.0], [1.0, 0.0, 2.0])
    with pytest.raises(ValueError, match="positive"):
        paired_ratio_interval([1.0, 2.0, 3.0], [1.0, -1.0, 2.0])
    with pytest.raises(ValueError, match="non-finite"):
        paired_ratio_interval([1.0, math.nan, 3.0], [1.0, 1.0, 2.0])
    with pytest.raises(ValueError, match="empty"):
        paired_ratio_interval([], [])
    with pytest.raises(ValueError, match="equal lengths"):
        StoppingRule().done_ratio([1.0] * 6, [1.0] * 5)


def test_ratio_of_medians_refuses():
    with pytest.raises(ValueError, match="at least 2"):
        ratio_of_medians_interval([1.0], [1.0, 2.0])
    with pytest.raises(ValueError, match="at least 2"):
        ratio_of_medians_interval([1.0, 2.0], [1.0])
    with pytest.raises(ValueError, match="positive"):
        ratio_of_medians_interval([-1.0, 0.0, 1.0], [1.0, 2.0])
    with pytest.raises(ValueError, match="positive"):
        ratio_of_medians_interval([1.0, 2.0], [-3.0, -1.0])
    with pytest.raises(ValueError, match="<= 0"):  # positive median, but resamples reach 0
        ratio_of_medians_interval([0.0, 0.0, 5.0, 6.0, 7.0], [1.0, 2.0])
    with pytest.raises(ValueError, match="resamples"):
        ratio_of_medians_interval([1.0, 2.0], [1.0, 2.0], resamples=10)
    with pytest.raises(ValueError, match="non-finite"):
        ratio_of_medians_interval([1.0, math.inf], [1.0, 2.0])
