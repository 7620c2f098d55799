"""Statistics over seeds: t confidence intervals, paired differences, demos needed to reach a level.

Seeds are the independent replicates (not evaluation episodes); with one seed the interval is NaN.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy import stats as scipy_stats

CONFIDENCE = 0.95


@dataclass(frozen=True)
class Interval:
    """A mean over ``n`` seeds with its confidence interval ``[low, high]`` (NaN below two seeds)."""

    mean: float
    low: float
    high: float
    n: int

    @property
    def half_width(self) -> float:
        """Half the interval's width (NaN with fewer than two seeds)."""
        return (self.high - self.low) / 2.0

    def excludes_zero(self) -> bool:
        """Whether the whole interval lies on one side of zero."""
        return bool(self.n > 1 and (self.low > 0.0 or self.high < 0.0))


def format_difference(interval: Interval) -> str:
    """``+0.012 [-0.004, +0.028]``, with `` *`` when the interval excludes 0 (one seed: no interval)."""
    if math.isnan(interval.low):
        return f"{interval.mean:+.3f} (one seed, no interval)"
    mark = " *" if interval.excludes_zero() else ""
    return f"{interval.mean:+.3f} [{interval.low:+.3f}, {interval.high:+.3f}]{mark}"


def mean_interval(values: Sequence[float], confidence: float = CONFIDENCE) -> Interval:
    """Mean of ``values`` with a Student-t interval (ValueError: empty, a NaN, confidence outside (0, 1))."""
    array = np.asarray(values, dtype=np.float64)
    if array.size == 0:
        raise ValueError("No values: a mean over seeds needs at least one seed.")
    if np.isnan(array).any():
        raise ValueError(f"NaN among the values {array.tolist()}: drop or resolve it first.")
    if not 0.0 < confidence < 1.0:
        raise ValueError(f"confidence must be in (0, 1), got {confidence}.")
    mean = float(array.mean())
    if array.size < 2:
        return Interval(mean, math.nan, math.nan, int(array.size))
    sem = float(array.std(ddof=1)) / math.sqrt(array.size)
    t = float(scipy_stats.t.ppf(0.5 + confidence / 2.0, df=array.size - 1))
    return Interval(mean, mean - t * sem, mean + t * sem, int(array.size))


def paired_difference(
    first: Sequence[float], second: Sequence[float], confidence: float = CONFIDENCE
) -> Interval:
    """Mean of ``first[i] - second[i]`` over paired seeds with its t interval (ValueError: lengths differ)."""
    if len(first) != len(second):
        raise ValueError(f"Paired values need one pair per seed, got {len(first)} and {len(second)}.")
    return mean_interval(np.asarray(first, float) - np.asarray(second, float), confidence)


def demos_to_reach(demos: Sequence[float], success: Sequence[float], level: float) -> float | None:
    """Expert demos at which one seed's curve first reaches ``level``, linearly interpolated (None: never).

    Raises:
        ValueError: On sequences of different lengths or demos that do not increase.
    """
    x = np.asarray(demos, dtype=np.float64)
    y = np.asarray(success, dtype=np.float64)
    if x.shape != y.shape or x.ndim != 1:
        raise ValueError(f"demos and success must be 1-d of the same length, got {x.shape}, {y.shape}.")
    if np.any(np.diff(x) <= 0):
        raise ValueError(f"demos must increase along a curve, got {x.tolist()}.")
    reached = np.nonzero(y >= level)[0]
    if reached.size == 0:
        return None
    k = int(reached[0])
    if k == 0:
        return float(x[0])
    fraction = (level - y[k - 1]) / (y[k] - y[k - 1])
    return float(x[k - 1] + fraction * (x[k] - x[k - 1]))


def correlation(first: Sequence[float], second: Sequence[float]) -> float:
    """Pearson correlation coefficient (NaN when either side is constant or has < 2 values)."""
    a, b = np.asarray(first, float), np.asarray(second, float)
    if a.size < 2 or a.std() == 0.0 or b.std() == 0.0:
        return math.nan
    return float(np.corrcoef(a, b)[0, 1])
