"""Statistics of censored step counts and intervals that stay inside the data.

A trial that has not reached the goal when its step cap stops it has a *censored* first
exposure: all we know is that it would have taken more than the cap. The Kaplan-Meier
estimate (``scipy.stats.ecdf`` on ``scipy.stats.CensoredData``) uses such a trial for as long
as it was observed, so neither the cap nor the failures distort the curve below the cap; its
median's interval is a cluster bootstrap over source seeds (:func:`cluster_median_ci`: the
trials of one seed share its trajectory, so they are resampled together), and a median that the
data cannot reach is ``None`` and flagged as lying beyond the cap. The curve's pointwise band
(log-log) treats trials as independent and is drawn only.

Intervals of summary statistics are percentile bootstraps (``scipy.stats.bootstrap`` with a
fixed seed), so they are deterministic and never leave the range of the values resampled: a
count's interval cannot go below zero, a ratio's cannot go below the smallest ratio seen.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING

import numpy as np

from armtransfer.experiments.lazy import scipy_stats

if TYPE_CHECKING:
    from scipy.stats import CensoredData

LEVEL = 0.95
BOOTSTRAP_RESAMPLES = 2000
BOOTSTRAP_SEED = 0


def censored_data(values: Sequence[float | None], cap: float) -> "CensoredData":
    """``values`` as right-censored data: None (never reached) is censored at ``cap``."""
    seen = [float(v) for v in values if v is not None]
    return scipy_stats().CensoredData(uncensored=seen, right=[float(cap)] * sum(v is None for v in values))


def kaplan_meier(values: Sequence[float | None], cap: float) -> dict:
    """The Kaplan-Meier survival curve of first-exposure steps (None: censored at ``cap``).

    Returns ``times`` and ``survival`` (the step function: the share of trials still without
    the goal just after each time), the 95% band (``low``, ``high``), ``median`` with its
    interval ``median_ci95`` (None where the curve or band never falls to one half: the
    median, or that end of its interval, lies beyond ``cap``), ``n`` and ``events``."""
    n = len(values)
    events = sum(v is not None for v in values)
    out = {"n": n, "events": events, "cap": cap, "times": [], "survival": [], "low": [], "high": [],
           "median": None, "median_beyond_cap": True, "median_ci95": [None, None]}
    if events == 0:
        return out
    sf = scipy_stats().ecdf(censored_data(values, cap)).sf
    with warnings.catch_warnings():  # undefined where the curve is 0: nan, set below
        warnings.simplefilter("ignore", RuntimeWarning)
        band = sf.confidence_interval(LEVEL, method="log-log")
    times = [float(t) for t in sf.quantiles]
    surv = [float(p) for p in sf.probabilities]
    # the log-log band is undefined where the curve is 0 (after the last trial reached the goal):
    # there it is 0 too, so the median's interval ends at most at the last time observed
    empty = np.asarray(sf.probabilities) <= 0
    low = [float(p) for p in np.where(empty, 0.0, np.nan_to_num(band.low.probabilities, nan=0.0))]
    high = [float(p) for p in np.where(empty, 0.0, np.nan_to_num(band.high.probabilities, nan=1.0))]
    median = first_time_at_or_below(times, surv, 0.5)
    out.update(times=times, survival=surv, low=low, high=high, median=median,
               median_beyond_cap=median is None,
               median_ci95=[first_time_at_or_below(times, low, 0.5), first_time_at_or_below(times, high, 0.5)])
    return out


def km_median_of_sorted(x: np.ndarray) -> np.ndarray:
    """The Kaplan-Meier median of rows of sorted times with every censored value at one cap at
    or above all events (``inf`` for censored): below the cap the curve is the empirical one, so
    the median is the ceil(n/2)-th smallest value (``inf``: beyond the cap)."""
    n = x.shape[-1]
    return x[..., (n + 1) // 2 - 1]


def cluster_median_ci(seeds: Sequence[Sequence[float | None]], seed: int = BOOTSTRAP_SEED,
                      resamples: int = BOOTSTRAP_RESAMPLES) -> list[float | None]:
    """Percentile 95% interval of the Kaplan-Meier median resampling whole source seeds (each a
    list of trials, None: censored at the cap), so that trials sharing a seed's trajectory are
    not counted as independent. An end that lies beyond the cap is None; fewer than two seeds:
    [None, None]."""
    groups = [np.array([np.inf if v is None else float(v) for v in s]) for s in seeds if len(s)]
    if len(groups) < 2:
        return [None, None]
    rng = np.random.default_rng(seed)
    pick = rng.integers(0, len(groups), size=(resamples, len(groups)))
    if len({len(g) for g in groups}) == 1:
        arr = np.stack(groups)
        draws = np.sort(arr[pick].reshape(resamples, -1), axis=1)
        med = km_median_of_sorted(draws)
    else:
        med = np.array([km_median_of_sorted(np.sort(np.concatenate([groups[i] for i in row]))) for row in pick])
    lo, hi = np.quantile(med, [(1 - LEVEL) / 2, 1 - (1 - LEVEL) / 2], method="inverted_cdf")
    return [None if not np.isfinite(lo) else float(lo), None if not np.isfinite(hi) else float(hi)]


def first_time_at_or_below(times: Sequence[float], curve: Sequence[float], level: float) -> float | None:
    """The first time at which the step function ``curve`` is at or below ``level`` (None: never)."""
    for t, p in zip(times, curve):
        if p <= level + 1e-12:
            return float(t)
    return None


def bootstrap_ci(values: Sequence[float] | np.ndarray, statistic: Callable = np.mean, seed: int = BOOTSTRAP_SEED,
                 resamples: int = BOOTSTRAP_RESAMPLES) -> list[float] | None:
    """Percentile bootstrap 95% interval of ``statistic`` of ``values`` (a 1-d sample).

    Deterministic (a generator seeded with ``seed``) and inside [min, max] of the values for
    any statistic that is (mean, median, ...). None for fewer than two values; a sample whose
    values are all equal gives that value twice."""
    x = np.asarray(values, dtype=np.float64)
    if len(x) < 2:
        return None
    if np.ptp(x) == 0:
        return [float(x[0]), float(x[0])]
    res = scipy_stats().bootstrap((x,), lambda a, axis: statistic(a, axis=axis), n_resamples=resamples,
                          confidence_level=LEVEL, method="percentile", vectorized=True,
                          random_state=np.random.default_rng(seed))
    lo, hi = float(res.confidence_interval.low), float(res.confidence_interval.high)
    return [max(lo, float(x.min())), min(hi, float(x.max()))]


def ratio_summary(log_ratios: Sequence[float]) -> dict:
    """Paired factors exp(log ratio), one per source seed: their geometric mean, its percentile
    bootstrap interval over the seeds (on the log scale, so it stays positive and within the
    smallest and largest factor), and the worst (smallest) and best factor."""
    x = np.asarray(log_ratios, dtype=np.float64)
    if len(x) == 0:
        return {"n": 0, "factor": None, "ci95": None, "worst": None, "best": None}
    ci = bootstrap_ci(x)
    return {"n": int(len(x)), "factor": float(np.exp(x.mean())),
            "ci95": None if ci is None else [float(np.exp(ci[0])), float(np.exp(ci[1]))],
            "worst": float(np.exp(x.min())), "best": float(np.exp(x.max()))}
