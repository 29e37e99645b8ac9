"""Summaries over trials: means with 95% confidence intervals, and improvement in percent.

Exploration steps are *censored*: a trial that never reaches the goal stops at the step cap
(``LearnerConfig.max_total_steps``) and has no exploration count (None). Dropping such
trials flatters a method that sometimes fails, so :func:`exploration_stats` and
:func:`paired_improvement` count them at the cap: the mean is then a lower bound of the
true mean (``mean_is_lower_bound``), and the median is given with a distribution-free
confidence interval, which censoring affects only when it reaches the upper half.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from armtransfer.experiments.lazy import scipy_stats
from armtransfer.experiments.stats.survival import bootstrap_ci

PAIRED_DESIGN = "paired: methods share random streams trial by trial (common random numbers)"
INDEPENDENT_DESIGN = "independent samples"


def t95(df: int) -> float:
    """The two-sided 95% Student t quantile for ``df`` degrees of freedom (nan for df < 1)."""
    if df < 1:
        return math.nan
    return float(scipy_stats().t.ppf(0.975, df))


def mean_ci(values: Sequence[float | None]) -> tuple[float | None, list[float] | None]:
    """Mean and 95% percentile-bootstrap interval of the values that are not None (None when
    none are); the interval stays within the values' range.

    For quantities defined only for some trials (e.g. greedy path lengths of converged
    trials). Exploration steps are censored: use :func:`exploration_stats`."""
    xs = np.array([v for v in values if v is not None], dtype=np.float64)
    if len(xs) == 0:
        return None, None
    m = float(xs.mean())
    if len(xs) == 1:
        return m, [m, m]
    return m, bootstrap_ci(xs)


def censor(values: Sequence[int | float | None], cap: float) -> np.ndarray:
    """The values with None (the goal not reached within ``cap`` steps) counted at ``cap``."""
    return np.array([cap if v is None else v for v in values], dtype=np.float64)


def median_ci(xs: np.ndarray, level: float = 0.95) -> tuple[list[float] | None, float | None]:
    """Distribution-free interval [x_(l), x_(n+1-l)] for the median, from the binomial
    B(n, 1/2): the largest l whose coverage 1 - 2 P(B <= l-1) is at least ``level``.
    Below n = 6 no l reaches 95%: then the range [min, max] and its smaller coverage.
    Returns (interval, its exact coverage)."""
    n = len(xs)
    if n == 0:
        return None, None
    x = np.sort(xs)
    best = 1
    for l in range(1, n // 2 + 1):
        if 1.0 - 2.0 * scipy_stats().binom.cdf(l - 1, n, 0.5) >= level:
            best = l
        else:
            break
    coverage = float(1.0 - 2.0 * scipy_stats().binom.cdf(best - 1, n, 0.5))
    return [float(x[best - 1]), float(x[n - best])], coverage


def median_is_lower_bound(censored: int, n: int) -> bool:
    """Whether the median of ``n`` values of which ``censored`` are counted at the cap touches
    a censored value (and so is only a lower bound): the upper of the middle order statistics
    is censored once at least half of the values are (exactly half, for an even n, included)."""
    return n > 0 and censored >= math.ceil(n / 2)


def cap_share(values: Sequence[int | float | None], cap: float) -> float:
    """The share of a censored mean's sum that the unreached trials contribute at ``cap``;
    above one half the mean says more about the cap than about the method (cap-dominated)."""
    xs = censor(values, cap)
    total = float(xs.sum())
    return float(cap * sum(v is None for v in values) / total) if total > 0 else 0.0


def exploration_stats(values: Sequence[int | None], cap: int) -> dict:
    """Censoring-honest statistics of exploration steps (None: goal not reached in ``cap``).

    mean and ci95 are over all trials with unreached ones counted at ``cap``; when any is
    unreached they are lower bounds (``mean_is_lower_bound``), and ``cap_dominated`` says the
    unreached trials make up more than half of the mean. ci95 is a percentile bootstrap, so it
    never leaves the range of the values (a t-interval of skewed step counts reached below
    zero). The median and its order-statistic interval are exact unless censoring reaches them
    (``median_is_lower_bound``, set from exactly half censored on)."""
    n = len(values)
    reached = sum(v is not None for v in values)
    out: dict[str, object] = {
        "n": n, "reached": reached, "censored": reached < n, "cap": cap,
        "mean": None, "ci95": None, "mean_is_lower_bound": reached < n,
        "median": None, "median_ci95": None, "median_ci_coverage": None,
        "median_is_lower_bound": False, "cap_dominated": False}
    if n == 0:
        return out
    xs = censor(values, cap)
    mean = float(xs.mean())
    ci = [mean, mean] if n == 1 else bootstrap_ci(xs)
    med = float(np.median(xs))
    mci, cov = median_ci(xs)
    out.update(mean=mean, ci95=ci, median=med, median_ci95=mci, median_ci_coverage=cov,
               median_is_lower_bound=median_is_lower_bound(n - reached, n),
               cap_dominated=cap_share(values, cap) > 0.5)
    return out


def improvement_percent(baseline: float | None, value: float | None) -> float | None:
    """Percentage improvement of ``value`` over ``baseline`` (fewer steps is better)."""
    if baseline is None or value is None or baseline == 0:
        return None
    return 100.0 * (baseline - value) / baseline


def paired_improvement(base: Sequence[float | None], other: Sequence[float | None], cap: int,
                       paired: bool = True) -> dict:
    """Improvement in percent of ``other``'s mean over ``base``'s, 100 (1 - mean(o)/mean(b)),
    both censored at ``cap``, with a 95% interval.

    ``paired``: trial i of both came from the same random stream (common random numbers,
    ``experiment.trial_rng``), so the interval is the delta method on the paired residuals
    d_i = o_i - r b_i (r the ratio of means), var(r) ~ var(d) / (n mean(b)^2), t with n-1
    df. Otherwise the two samples are independent: delta method on both variances. The
    interval is a t-interval on log r (standard error se(r)/r), so the ratio's stays positive
    and the improvement's below 100%, which an interval on r itself did not.
    ``censored`` says a cap entered either mean (then the percent is that of the censored
    means, not of the true ones)."""
    b = censor(base, cap)
    o = censor(other, cap)
    if paired and len(b) != len(o):
        raise ValueError(f"a paired comparison needs as many trials in both ({len(b)} vs {len(o)})")
    out: dict[str, object] = {
        "percent": None, "ci95": None, "design": PAIRED_DESIGN if paired else INDEPENDENT_DESIGN,
        "n": [len(b), len(o)], "censored": bool(any(v is None for v in base) or any(v is None for v in other)),
        "cap_dominated": bool(len(b) and len(o) and max(cap_share(base, cap), cap_share(other, cap)) > 0.5)}
    if len(b) == 0 or len(o) == 0 or b.mean() == 0:
        return out
    r = float(o.mean() / b.mean())
    out["percent"] = 100.0 * (1.0 - r)
    if paired:
        n = len(b)
        if n < 2:
            return out
        d = o - r * b
        se = math.sqrt(float(d.var(ddof=1)) / n) / float(b.mean())
        df = n - 1
    else:
        if len(b) < 2 or len(o) < 2:
            return out
        se = r * math.sqrt(o.var(ddof=1) / len(o) / o.mean() ** 2 + b.var(ddof=1) / len(b) / b.mean() ** 2) \
            if o.mean() > 0 else math.sqrt(o.var(ddof=1) / len(o)) / b.mean()
        df = min(len(b), len(o)) - 1
    if r <= 0:
        return out
    half = t95(df) * se / r  # on log r: the ratio's interval stays positive, the percent below 100
    out["ci95"] = [100.0 * (1.0 - r * math.exp(half)), 100.0 * (1.0 - r * math.exp(-half))]
    return out


SEED_DESIGN = "paired trial by trial; the interval resamples whole source seeds (their trials with them)"
SEED_RESAMPLES = 9999


def seed_improvement(base: Sequence[Sequence[float | None]], other: Sequence[Sequence[float | None]], cap: int,
                     min_seeds: int = 6, resamples: int = SEED_RESAMPLES, seed: int = 0) -> dict:
    """Improvement in percent of ``other``'s mean over ``base``'s, 100 (1 - sum(o) / sum(b)), both
    censored at ``cap``, per source seed a list of paired trials: trials from one source seed share
    its trajectory, so they are not independent, and the 95% interval is a percentile bootstrap
    over whole source seeds (each drawn with its trials of both). None below ``min_seeds`` seeds:
    too few to resample (``too_few``)."""
    b = [censor(s, cap) for s in base]
    o = [censor(s, cap) for s in other]
    if len(b) != len(o) or any(len(x) != len(y) for x, y in zip(b, o)):
        raise ValueError("a seed-paired comparison needs the same trials per seed in both")
    sb = np.array([x.sum() for x in b], dtype=np.float64)
    so = np.array([x.sum() for x in o], dtype=np.float64)
    out: dict[str, object] = {"percent": None, "ci95": None, "design": SEED_DESIGN, "seeds": len(b),
                              "too_few": len(b) < min_seeds,
                              "censored": bool(any(v is None for s in (*base, *other) for v in s))}
    if not len(sb) or sb.sum() == 0:
        return out
    out["percent"] = float(100.0 * (1.0 - so.sum() / sb.sum()))
    if len(sb) < min_seeds:
        return out
    rng = np.random.default_rng(seed)
    pick = rng.integers(0, len(sb), size=(resamples, len(sb)))
    den = sb[pick].sum(axis=1)
    ok = den > 0
    boot = 100.0 * (1.0 - so[pick].sum(axis=1)[ok] / den[ok])
    lo, hi = np.quantile(boot, [0.025, 0.975])
    out["ci95"] = [float(lo), float(hi)]
    return out
