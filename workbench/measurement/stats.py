"""Statistics for timing samples (milliseconds): confidence intervals and a stopping rule.

* :class:`Interval`: an estimate (a median, or a ratio of timings) with its confidence interval.
* :func:`median_interval`: distribution-free interval for the median from order statistics.
* :func:`paired_ratio_interval`: median of the ratios a_i / b_i of measurements taken in pairs.
* :func:`ratio_of_medians_interval`: median(b) / median(a) of two independent runs, interval by a
  seeded percentile bootstrap.
* :class:`StoppingRule`: when a repeated measurement has enough samples.

Pure numpy/scipy; times are in milliseconds, ratios are dimensionless.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from scipy.stats import binom

CONFIDENCE = 0.95

# most index entries one bootstrap draw holds at once (bounds memory for long sample lists)
_BOOTSTRAP_CHUNK = 1 << 22


@dataclass(frozen=True)
class Interval:
    """An estimate with a confidence interval [lo, hi] in the estimate's units.

    ``confidence`` is the coverage the method gives: for order statistics the discrete level
    reached (>= the requested one where ``n`` allows, else the largest achievable, below it);
    for the bootstrap the requested (nominal) level. ``n`` is the number of samples (pairs for
    a paired ratio, the smaller side for independent samples).
    """

    estimate: float
    lo: float
    hi: float
    confidence: float
    n: int

    @property
    def half_width(self) -> float:
        """Half the interval's width, ``(hi - lo) / 2``, in the estimate's units."""
        return (self.hi - self.lo) / 2

    @property
    def relative_half_width(self) -> float:
        """``half_width / |estimate|`` (dimensionless); ``inf`` where the estimate is 0."""
        if self.estimate == 0:
            return math.inf
        return self.half_width / abs(self.estimate)

    def excludes(self, value: float) -> bool:
        """True where ``value`` lies outside [lo, hi]."""
        return value < self.lo or value > self.hi

    def overlaps(self, other: Interval) -> bool:
        """True where this interval and ``other`` share at least one point."""
        return self.lo <= other.hi and other.lo <= self.hi


def _check_confidence(confidence: float) -> float:
    if not 0 < confidence < 1:
        raise ValueError(f"confidence must lie strictly between 0 and 1, got {confidence}")
    return float(confidence)


def _samples(samples, name: str = "samples") -> np.ndarray:
    x = np.asarray(samples, dtype=float)
    if x.ndim != 1:
        raise ValueError(f"{name} must be a 1-D sequence of numbers, got shape {x.shape}")
    if x.size == 0:
        raise ValueError(f"{name} is empty: an interval needs at least one sample")
    if not np.all(np.isfinite(x)):
        raise ValueError(f"{name} holds non-finite values (nan or inf): {x[~np.isfinite(x)]}")
    return x


@lru_cache(maxsize=1024)
def _median_ranks(n: int, confidence: float) -> tuple[int, float]:
    """1-based lower rank j of the interval [x_(j), x_(n+1-j)] and its coverage."""
    j = np.arange(1, (n + 1) // 2 + 1)
    coverage = 1.0 - 2.0 * binom.cdf(j - 1, n, 0.5)
    ok = np.nonzero(coverage >= confidence)[0]
    if ok.size == 0:  # too few samples: (min, max) is the best there is
        return 1, float(coverage[0])
    k = ok[-1]  # coverage falls as j grows: the largest j that still reaches it is narrowest
    return int(j[k]), float(coverage[k])


def median_interval(samples, confidence: float = CONFIDENCE) -> Interval:
    """Distribution-free confidence interval for the median of ``samples``.

    Returns an :class:`Interval` in the samples' units (milliseconds for timings): the sample
    median and the order statistics x_(j), x_(n+1-j) for the largest j (narrowest symmetric
    pair) whose coverage 1 - 2 P(Bin(n, 1/2) <= j - 1) is >= ``confidence``. Where even
    (min, max) falls short, returns (min, max) with its coverage 1 - 2 * 0.5**n (below the
    requested level; e.g. 0.9375 for n = 5). The coverage holds for independent samples of a
    continuous distribution. Raises ValueError on empty or non-1-D input, nan or inf, or a
    confidence outside (0, 1).
    """
    confidence = _check_confidence(confidence)
    x = np.sort(_samples(samples))
    n = x.size
    j, coverage = _median_ranks(n, confidence)
    return Interval(estimate=float(np.median(x)), lo=float(x[j - 1]), hi=float(x[n - j]),
                    confidence=coverage, n=n)


def paired_ratio_interval(a, b, confidence: float = CONFIDENCE) -> Interval:
    """Median of the ratios a_i / b_i of measurements taken in pairs (A B A B ...).

    Returns the :func:`median_interval` of the ratios (dimensionless; "a relative to b", > 1
    where a is slower). Pairing cancels drift shared by neighbouring measurements. Raises
    ValueError where ``a`` and ``b`` differ in length, any b_i is <= 0, or on what
    :func:`median_interval` refuses.
    """
    x, y = _samples(a, "a"), _samples(b, "b")
    if x.size != y.size:
        raise ValueError(f"paired samples need equal lengths, got {x.size} (a) and {y.size} (b)")
    if np.any(y <= 0):
        raise ValueError(f"b must be positive to divide by, got {y[y <= 0]}")
    return median_interval(x / y, confidence)


def _bootstrap_medians(x: np.ndarray, resamples: int, rng: np.random.Generator) -> np.ndarray:
    out = np.empty(resamples)
    rows = max(1, _BOOTSTRAP_CHUNK // x.size)
    for start in range(0, resamples, rows):  # one chunk for sample lists up to ~1000 long
        stop = min(start + rows, resamples)
        idx = rng.integers(0, x.size, size=(stop - start, x.size))
        out[start:stop] = np.median(x[idx], axis=1)
    return out


def ratio_of_medians_interval(a, b, confidence: float = CONFIDENCE, resamples: int = 4000,
                              seed: int = 0) -> Interval:
    """median(b) / median(a) of two independent runs ("b relative to a"), with an interval.

    Returns a dimensionless :class:`Interval` whose bounds are the percentile bootstrap
    quantiles (a and b resampled independently, ``resamples`` times, from
    ``numpy.random.default_rng(seed)``, so the result is deterministic); its ``confidence`` is
    the requested (nominal) level and ``n`` the smaller sample count. Raises ValueError where
    either side has fewer than 2 samples, either median is <= 0 (or a resampled median of a
    is), ``resamples`` < 100, or on nan, inf or a confidence outside (0, 1).
    """
    confidence = _check_confidence(confidence)
    x, y = _samples(a, "a"), _samples(b, "b")
    if x.size < 2 or y.size < 2:
        raise ValueError(f"the bootstrap needs at least 2 samples on each side, got {x.size} (a) "
                         f"and {y.size} (b)")
    if int(resamples) != resamples or resamples < 100:
        raise ValueError(f"resamples must be an integer >= 100, got {resamples}")
    med_a, med_b = float(np.median(x)), float(np.median(y))
    if med_a <= 0 or med_b <= 0:
        raise ValueError(f"medians must be positive for a ratio, got {med_a} (a) and {med_b} (b)")
    rng = np.random.default_rng(seed)
    boot_a = _bootstrap_medians(x, int(resamples), rng)
    boot_b = _bootstrap_medians(y, int(resamples), rng)
    if np.any(boot_a <= 0):
        raise ValueError("a resampled median of a is <= 0: too many samples of a are <= 0 for a "
                         "ratio")
    alpha = 1.0 - confidence
    lo, hi = np.quantile(boot_b / boot_a, [alpha / 2, 1 - alpha / 2])
    return Interval(estimate=med_b / med_a, lo=float(lo), hi=float(hi), confidence=confidence,
                    n=int(min(x.size, y.size)))


@dataclass(frozen=True)
class StoppingRule:
    """When to stop repeating a measurement: the median's interval is tight enough, or enough.

    ``rel_half_width`` is the target relative half-width of the median's interval at
    ``confidence``; a measurement takes at least ``min_samples`` and at most ``max_samples``.
    Construction raises ValueError where min_samples < 5, max_samples < min_samples,
    rel_half_width <= 0 or confidence is outside (0, 1).
    """

    rel_half_width: float = 0.02
    min_samples: int = 5
    max_samples: int = 60
    confidence: float = CONFIDENCE

    def __post_init__(self) -> None:
        if self.min_samples < 5:
            raise ValueError(f"min_samples must be >= 5, got {self.min_samples}")
        if self.max_samples < self.min_samples:
            raise ValueError(f"max_samples ({self.max_samples}) must be >= min_samples "
                             f"({self.min_samples})")
        if not self.rel_half_width > 0:
            raise ValueError(f"rel_half_width must be > 0, got {self.rel_half_width}")
        _check_confidence(self.confidence)

    def _reached(self, interval: Interval) -> bool:
        return (interval.confidence >= self.confidence
                and interval.relative_half_width <= self.rel_half_width)

    def done(self, samples) -> bool:
        """True where ``samples`` (milliseconds) suffice: at least ``max_samples`` of them, or
        at least ``min_samples`` with a :func:`median_interval` that reaches ``confidence`` and
        ``rel_half_width``. Raises ValueError on what :func:`median_interval` refuses."""
        n = len(samples)
        if n >= self.max_samples:
            return True
        if n < self.min_samples:
            return False
        return self._reached(median_interval(samples, self.confidence))

    def done_ratio(self, a, b) -> bool:
        """As :meth:`done`, on the :func:`paired_ratio_interval` of pairs (a_i, b_i). Raises
        ValueError where ``a`` and ``b`` differ in length, or on what that function refuses."""
        if len(a) != len(b):
            raise ValueError(f"paired samples need equal lengths, got {len(a)} (a) and "
                             f"{len(b)} (b)")
        n = len(a)
        if n >= self.max_samples:
            return True
        if n < self.min_samples:
            return False
        return self._reached(paired_ratio_interval(a, b, self.confidence))
