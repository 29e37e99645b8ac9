"""Summaries over trials: means with 95% confidence intervals, and improvement in percent."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

# Two-sided 95% quantiles of Student's t for df = 1..30; above 30 the normal 1.96 is close.
_T95 = (
    12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306, 2.262, 2.228,
    2.201, 2.179, 2.160, 2.145, 2.131, 2.120, 2.110, 2.101, 2.093, 2.086,
    2.080, 2.074, 2.069, 2.064, 2.060, 2.056, 2.052, 2.048, 2.045, 2.042,
)


def t95(df: int) -> float:
    """The two-sided 95% Student t quantile for ``df`` degrees of freedom."""
    if df < 1:
        return math.nan
    if df <= len(_T95):
        return _T95[df - 1]
    # Cornish-Fisher expansion around the normal quantile; within 1e-3 for df > 30
    z = 1.959964
    return z + (z**3 + z) / (4 * df) + (5 * z**5 + 16 * z**3 + 3 * z) / (96 * df**2)


def mean_ci(values: Sequence[float | None]) -> tuple[float | None, list[float] | None]:
    """Mean and 95% t-interval of the values that are not None (None when none are)."""
    xs = np.array([v for v in values if v is not None], dtype=np.float64)
    if len(xs) == 0:
        return None, None
    m = float(xs.mean())
    if len(xs) == 1:
        return m, [m, m]
    half = t95(len(xs) - 1) * float(xs.std(ddof=1)) / math.sqrt(len(xs))
    return m, [m - half, m + half]


def improvement_percent(baseline: float | None, value: float | None) -> float | None:
    """Percentage improvement of ``value`` over ``baseline`` (fewer steps is better)."""
    if baseline is None or value is None or baseline == 0:
        return None
    return 100.0 * (baseline - value) / baseline


def improvement_ci(
    baseline: Sequence[float | None], values: Sequence[float | None]
) -> list[float] | None:
    """95% interval of the improvement in percent, by the delta method on the ratio of means.

    improvement = 100 (1 - mean(values)/mean(baseline)); the two samples are independent.
    """
    b = np.array([v for v in baseline if v is not None], dtype=np.float64)
    x = np.array([v for v in values if v is not None], dtype=np.float64)
    if len(b) < 2 or len(x) < 2 or b.mean() == 0:
        return None
    r = x.mean() / b.mean()
    var_r = r**2 * (x.var(ddof=1) / len(x) / x.mean() ** 2 + b.var(ddof=1) / len(b) / b.mean() ** 2)
    df = min(len(b), len(x)) - 1
    half = t95(df) * math.sqrt(var_r)
    return [100.0 * (1 - (r + half)), 100.0 * (1 - (r - half))]
