"""A hierarchical bootstrap-t interval for a mean over nested units: cases, then source seeds,
then trials.

The benchmark's data are nested: a trial belongs to a source seed (robot 1 learned the task
once for it), and a seed to a case. A statistic averaged over (case, seed) pairs as if they
were independent claims a precision the design does not have: two seeds of one case share
the case. Here the statistic is the mean over cases of the mean over their seeds of the mean
over their trials (each level weighted equally), and every resample draws, with replacement,
cases, then within each drawn case its seeds, then within each drawn seed its trials.

The interval is a bootstrap-t (studentized): each resample's statistic is divided by its own
standard error across the top-level units (cases; seeds when there is one case), and the
quantiles of that ratio set the interval around the estimate. It is the union of the
equal-tailed bootstrap-t interval and the symmetric one (the 95% quantile of |t|): the
equal-tailed one alone covered 91-93% on heavy-tailed data (t with 3 degrees of freedom) and the
symmetric one alone 92-94% on skewed data; their union covers at least 93% on normal,
heavy-tailed and skewed data at 6 to 24 units (simulated:
``tests/test_hierarchical.py``, ``research/interval_coverage.py``). A percentile interval covered about
92% at ten normal units.

No interval from fewer than ``MIN_UNITS`` top-level units: with fewer, the standard error of
the units is itself too uncertain (an interval from 2 cases spanned five orders of magnitude),
so ``ci95`` and ``p`` are None and a report says "too few".

Power is stated as the smallest factor detectable at 80% power with the standard error seen
(two-sided 5%, a t with the top level's degrees of freedom: an approximation, as the studentized
resamples' tails can be heavier than t's). Each interval comes with the two-sided p-value of "no
difference" that inverts it (twice the share of studentized resamples beyond the observed
t in the estimate's direction: 0 lies outside the (1 - p) interval), which the report corrects
for multiplicity (``multiplicity.holm``). With ``RESAMPLES`` = 9999 the smallest p would be
1/5000, which Holm's correction over a hundred verdicts cannot take below 0.02; so a p below
``REFINE_BELOW`` is computed again from ``FINE_RESAMPLES`` resamples (its smallest value about
1e-5), the interval staying that of the ``RESAMPLES``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from armtransfer.experiments.lazy import scipy_stats

LEVEL = 0.95
POWER = 0.80
RESAMPLES = 9999
SEED = 0
MIN_UNITS = 6
"""The fewest top-level units (cases; seeds when there is one case) an interval and a p-value are
computed from."""
FINE_RESAMPLES = 199_999
"""Resamples of a p-value below ``REFINE_BELOW``: resolution 1e-5, so that Holm's correction over a
few hundred verdicts can still reach 0.01."""
REFINE_BELOW = 0.005
CHUNK = 50_000
"""Resamples drawn at once (memory)."""

Nested = Sequence[Sequence[Sequence[float]]]
"""cases -> source seeds -> trial values (each seed with at least one value)."""


def _pad(seeds: Sequence[Sequence[float]]) -> tuple[np.ndarray, np.ndarray]:
    counts = np.array([len(s) for s in seeds], dtype=np.int64)
    arr = np.zeros((len(seeds), int(counts.max())))
    for i, s in enumerate(seeds):
        arr[i, :len(s)] = np.asarray(s, dtype=np.float64)
    return arr, counts


def _seed_means(arr: np.ndarray, counts: np.ndarray, m: int, rng: np.random.Generator) -> np.ndarray:
    """``m`` resamples of one case: seeds drawn with replacement, then each drawn seed's trials
    with replacement; the [m, seeds] means of the drawn seeds."""
    ns, width = arr.shape
    si = rng.integers(0, ns, size=(m, ns))
    cnt = counts[si]
    ti = (rng.random((m, ns, width)) * cnt[..., None]).astype(np.int64)
    valid = np.arange(width)[None, None, :] < cnt[..., None]
    vals = arr[si[..., None], ti]
    return (vals * valid).sum(axis=-1) / cnt


def _observed_units(cases: list[tuple[np.ndarray, np.ndarray]]) -> np.ndarray:
    if len(cases) == 1:
        arr, cnt = cases[0]
        return arr.sum(axis=1) / cnt
    return np.array([float(np.mean(a.sum(axis=1) / c)) for a, c in cases])


def bootstrap_t(data: Nested, resamples: int = RESAMPLES, seed: int = SEED, refine: bool = True) -> dict:
    """The mean of means of ``data`` (cases -> seeds -> trials) with its hierarchical bootstrap-t
    95% interval, standard error, p-value of a zero mean and the effect detectable at 80% power.

    Returns ``estimate``, ``ci95`` (None below ``MIN_UNITS`` top-level units), ``se``, ``df``,
    ``p`` (two-sided, from the studentized resamples; None below ``MIN_UNITS``), ``detectable``
    (the absolute mean detectable at 80% power), ``units`` (top-level units: cases, or seeds when
    there is one case), ``cases``, ``seeds`` and ``trials``, and ``too_few`` (True below
    ``MIN_UNITS``). ``refine``: a p below ``REFINE_BELOW`` from ``FINE_RESAMPLES`` (False: a
    p that enters no multiplicity correction). Deterministic: generators seeded with ``seed``."""
    cases = [_pad([s for s in c if len(s)]) for c in data if any(len(s) for s in c)]
    seeds = sum(len(c) for c, _ in cases)
    trials = int(sum(int(n.sum()) for _, n in cases))
    out: dict = {"estimate": None, "ci95": None, "se": None, "df": None, "p": None, "detectable": None,
                 "units": 0, "cases": len(cases), "seeds": seeds, "trials": trials, "too_few": True}
    if not cases:
        return out
    units = _observed_units(cases)
    n = len(units)
    est = float(units.mean())
    out.update(estimate=est, units=n, too_few=n < MIN_UNITS)
    if n < MIN_UNITS:
        return out
    se0 = float(units.std(ddof=1) / math.sqrt(n))
    df = n - 1
    t = scipy_stats().t
    out.update(se=se0, df=df, detectable=float((t.ppf(1 - (1 - LEVEL) / 2, df) + t.ppf(POWER, df)) * se0))
    if se0 == 0.0:
        out.update(ci95=[est, est], p=0.0 if est != 0.0 else 1.0)
        return out
    stud = _studentized(cases, est, n, resamples, np.random.default_rng(seed))
    hi_q, lo_q = np.quantile(stud, [1 - (1 - LEVEL) / 2, (1 - LEVEL) / 2])
    sym_q = float(np.quantile(np.abs(stud), LEVEL))
    t0 = est / se0
    p = _p_value(stud, t0, est)
    if refine and p < REFINE_BELOW:  # a p this small: its resolution from more resamples (the interval stays)
        p = _p_value(_studentized(cases, est, n, FINE_RESAMPLES, np.random.default_rng([seed, 1])), t0, est)
    lo = min(est - hi_q * se0, est - sym_q * se0)
    hi = max(est - lo_q * se0, est + sym_q * se0)
    out.update(ci95=[float(lo), float(hi)], p=float(min(1.0, p)))
    return out


def _studentized(cases: list[tuple[np.ndarray, np.ndarray]], est: float, n: int, resamples: int,
                 rng: np.random.Generator) -> np.ndarray:
    """The studentized statistic (theta* - estimate) / se* of ``resamples`` hierarchical resamples
    (cases, then within each its seeds, then their trials), drawn ``CHUNK`` at a time."""
    parts = []
    for start in range(0, resamples, CHUNK):
        m = min(CHUNK, resamples - start)
        if len(cases) == 1:
            arr, cnt = cases[0]
            boot = _seed_means(arr, cnt, m, rng)
        else:
            pick = rng.integers(0, len(cases), size=(m, len(cases)))
            boot = np.empty(pick.shape)
            for c, (arr, cnt) in enumerate(cases):  # every drawn copy of a case draws its seeds anew
                where = np.nonzero(pick == c)
                if len(where[0]):
                    boot[where] = _seed_means(arr, cnt, len(where[0]), rng).mean(axis=1)
        theta = boot.mean(axis=1)
        se = boot.std(axis=1, ddof=1) / math.sqrt(n)
        ok = se > 0
        parts.append((theta[ok] - est) / se[ok])
    return np.concatenate(parts)


def _p_value(stud: np.ndarray, t0: float, est: float) -> float:
    """The two-sided p-value of a zero mean that inverts the union interval: the larger of the
    equal-tailed one (twice the share of resamples beyond t0 on the estimate's side) and the
    symmetric one (the share with |t| at least |t0|), so 0 lies outside the (1 - p) interval."""
    beyond = int(np.sum(stud >= t0)) if est > 0 else int(np.sum(stud <= t0))
    tail = 2.0 * (1 + beyond) / (len(stud) + 1)
    sym = (1 + int(np.sum(np.abs(stud) >= abs(t0)))) / (len(stud) + 1)
    return max(tail, sym)


def as_factor(summary: dict) -> dict:
    """``bootstrap_t`` of log factors as factors: ``factor`` = exp(estimate), its interval, and
    ``detectable``: the factors below and above which a true factor would have been detected
    with 80% power."""
    est, ci, det = summary["estimate"], summary["ci95"], summary["detectable"]
    return {
        "factor": None if est is None else math.exp(est),
        "ci95": None if ci is None else [math.exp(ci[0]), math.exp(ci[1])],
        "detectable": None if det is None else [math.exp(-det), math.exp(det)],
        **{k: summary[k] for k in ("p", "se", "df", "units", "cases", "seeds", "trials", "too_few")},
    }
