"""The hierarchical bootstrap-t: its coverage at ten units on known distributions (simulated),
its resampling of whole cases and seeds, Holm's correction, and the seed-clustered KM interval."""

from __future__ import annotations

import numpy as np
import pytest

from armtransfer.experiments.stats import hierarchical, multiplicity, survival


def _coverage(make, datasets: int, seed: int) -> float:
    rng = np.random.default_rng(seed)
    hits = 0
    for i in range(datasets):
        lo, hi = hierarchical.bootstrap_t(make(rng), resamples=999, seed=i)["ci95"]
        hits += lo <= 0.0 <= hi
    return hits / datasets


@pytest.mark.parametrize("between, within", [(1.0, 0.5), (0.3, 1.0)])
def test_coverage_at_ten_seeds_is_93_to_97_percent(between, within):
    """Ten source seeds of two trials each, log factors normal around 0 with a seed effect and
    trial noise: the interval holds 0 in 93-97% of 1000 simulated data sets (measured 94.5% and
    94.9% on 1500 others; a percentile interval of the same resamples held it in about 92%, or
    97.5% when the trials' noise dominates)."""
    def make(rng):
        return [(rng.normal(0.0, between, (10, 1)) + rng.normal(0.0, within, (10, 2))).tolist()]

    assert 0.93 <= _coverage(make, 1000, 7) <= 0.97


@pytest.mark.slow
def test_coverage_at_ten_cases_is_93_to_97_percent():
    def make(rng):
        return [(rng.normal() + rng.normal(0.0, 0.5, (5, 2))).tolist() for _ in range(10)]

    assert 0.93 <= _coverage(make, 400, 11) <= 0.97


def test_cases_weigh_equally_and_the_result_is_deterministic():
    data = [[[1.0, 3.0], [5.0]], [[10.0], [10.0], [10.0]]]
    a, b = hierarchical.bootstrap_t(data), hierarchical.bootstrap_t(data)
    assert a == b
    assert a["estimate"] == pytest.approx((np.mean([2.0, 5.0]) + 10.0) / 2)
    assert a["cases"] == 2 and a["seeds"] == 5 and a["trials"] == 6 and a["df"] == 1
    lo, hi = a["ci95"]
    assert lo < a["estimate"] < hi


def test_one_case_has_its_seeds_as_units_and_a_power_statement():
    rng = np.random.default_rng(0)
    data = [rng.normal(0.5, 0.2, (10, 3)).tolist()]
    out = hierarchical.bootstrap_t(data)
    assert out["units"] == 10 and out["df"] == 9 and out["p"] < 0.01
    f = hierarchical.as_factor(out)
    lo, hi = f["detectable"]
    assert lo < 1 < hi and lo == pytest.approx(1 / hi)
    # the detectable effect is (t_.975 + t_.80) standard errors
    from scipy import stats

    assert np.log(hi) == pytest.approx((stats.t.ppf(0.975, 9) + stats.t.ppf(0.8, 9)) * out["se"])


def test_no_difference_is_not_significant():
    rng = np.random.default_rng(1)
    out = hierarchical.bootstrap_t([rng.normal(0.0, 1.0, (10, 2)).tolist()])
    assert out["p"] > 0.05 and out["ci95"][0] < 0 < out["ci95"][1]


def test_holm_matches_the_step_down_by_hand():
    assert multiplicity.holm([0.01, 0.04, 0.03, 0.005]) == pytest.approx([0.03, 0.06, 0.06, 0.02])
    assert multiplicity.holm([0.5, 0.9]) == [1.0, 1.0]
    assert multiplicity.holm([]) == []


def test_km_median_interval_resamples_whole_seeds():
    # two seeds that always reach the goal fast, two that never do: the median is uncertain
    # between the seeds' behaviours, not within the trials of one
    seeds = [[10, 12, 11], [9, 10, 11], [None, None, None], [None, None, 1000]]
    lo, hi = survival.cluster_median_ci(seeds)
    assert lo is not None and lo <= 12 and hi is None
    km_flat = survival.kaplan_meier([v for s in seeds for v in s], cap=5000)
    assert km_flat["median"] == 12.0
    same = [[5, 5], [5, 5], [5, 5]]
    assert survival.cluster_median_ci(same) == [5.0, 5.0]
