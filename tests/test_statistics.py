"""Censoring-honest statistics: no trial left out of a mean, paired CIs, one learning curve."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

from armtransfer.experiments.reports import figures

from armtransfer.experiments.stats import learning_metrics, metrics
from armtransfer.experiments.experiment import MethodResult, summarize
from armtransfer.experiments.tables import method_table
from armtransfer.learning.trial_result import TrialResult
from armtransfer.experiments.reports.summary import summarize as sweep_summarize, summary_markdown


def test_t_quantiles_come_from_scipy():
    assert metrics.t95(1) == pytest.approx(12.7062, abs=1e-4)
    assert metrics.t95(9) == pytest.approx(2.2622, abs=1e-4)
    assert metrics.t95(1000) == pytest.approx(1.9623, abs=1e-4)
    assert np.isnan(metrics.t95(0))


def test_unreached_trials_count_at_the_cap_and_the_mean_is_a_lower_bound():
    cap = 1000
    values = [100, 200, None, 300, None]
    st = metrics.exploration_stats(values, cap)
    assert st["n"] == 5 and st["reached"] == 3 and st["censored"] and st["mean_is_lower_bound"]
    assert st["mean"] == pytest.approx((100 + 200 + 300 + 2 * cap) / 5)
    # not below the cap's share: a method with failures can never look better than that
    assert st["mean"] >= cap * 2 / 5
    # the old mean over successes only (200) would have flattered it
    assert st["mean"] > metrics.mean_ci(values)[0]
    # the t-interval of these skewed counts would reach below zero steps; the bootstrap's stays
    # within the values and holds the mean
    half = stats.t.ppf(0.975, 4) * np.std([100, 200, 1000, 300, 1000], ddof=1) / np.sqrt(5)
    assert st["mean"] - half < 0
    assert 100 <= st["ci95"][0] < st["mean"] < st["ci95"][1] <= cap
    assert st["median"] == 300 and not st["median_is_lower_bound"]


def test_a_median_at_exactly_half_censored_is_a_lower_bound():
    st = metrics.exploration_stats([100, 200, None, None], 1000)
    assert st["median"] == 600 and st["median_is_lower_bound"]
    st = metrics.exploration_stats([100, 200, 300, None], 1000)
    assert st["median"] == 250 and not st["median_is_lower_bound"]
    assert metrics.median_is_lower_bound(3, 5) and not metrics.median_is_lower_bound(2, 5)


def test_an_improvement_interval_stays_below_100_percent():
    # a method 20x faster, with one slow trial: an interval on the ratio itself went below 0
    base = [1000, 1200, 900, 1100, 1000]
    other = [10, 12, 9, 11, 500]
    p = metrics.paired_improvement(base, other, 10_000)
    assert p["ci95"][0] < p["percent"] < p["ci95"][1] < 100.0
    r = 1 - p["percent"] / 100
    d = np.array(other) - r * np.array(base)
    half = stats.t.ppf(0.975, 4) * np.std(d, ddof=1) / np.sqrt(5) / np.mean(base)
    assert r - half < 0  # where the old interval on r would have reached


def test_a_mean_made_mostly_of_the_cap_is_flagged():
    st = metrics.exploration_stats([100, 200, None], 1000)
    assert st["cap_dominated"]
    assert not metrics.exploration_stats([100, 200, 300, None], 400)["cap_dominated"]  # 400 of 1000
    p = metrics.paired_improvement([100, 200, None], [100, 200, 300], 1000)
    assert p["censored"] and p["cap_dominated"]
    p = metrics.paired_improvement([100, 200, 300], [100, 200, 250], 1000)
    assert not p["censored"] and not p["cap_dominated"]


def test_all_unreached_is_the_cap_not_n_a():
    st = metrics.exploration_stats([None] * 10, 5000)
    assert st["mean"] == 5000 and st["reached"] == 0 and st["mean_is_lower_bound"]
    assert st["median"] == 5000 and st["median_is_lower_bound"]


def test_all_reached_is_not_flagged():
    st = metrics.exploration_stats([3, 4, 5], 10)
    assert not st["mean_is_lower_bound"] and st["mean"] == 4


@pytest.mark.parametrize("n", [6, 10, 20, 50])
def test_median_ci_has_its_stated_coverage_and_is_order_statistics(n):
    xs = np.arange(1.0, n + 1)
    ci, cov = metrics.median_ci(xs)
    assert cov >= 0.95
    l = int(ci[0])  # values are 1..n, so the value is the rank
    assert ci[1] == n + 1 - l
    # one rank narrower would fall below 95%
    assert 1 - 2 * stats.binom.cdf(l, n, 0.5) < 0.95
    # coverage by simulation, continuous distribution
    rng = np.random.default_rng(0)
    samples = np.sort(rng.exponential(size=(4000, n)), axis=1)
    hit = (samples[:, l - 1] <= np.log(2)) & (np.log(2) <= samples[:, n - l])
    assert abs(hit.mean() - cov) < 0.02


def test_median_ci_below_six_trials_says_its_coverage():
    ci, cov = metrics.median_ci(np.array([5.0, 1.0, 3.0]))
    assert ci == [1.0, 5.0] and cov == pytest.approx(0.75)


def test_paired_improvement_uses_the_pairing():
    """Trial-by-trial the other method is 50% better, but trials vary a lot: the paired CI
    is tight around 50%, the independent one is wide."""
    rng = np.random.default_rng(1)
    base = list(rng.integers(1000, 100000, 12))
    other = [b // 2 for b in base]
    p = metrics.paired_improvement(base, other, cap=10**6)
    i = metrics.paired_improvement(base, other, cap=10**6, paired=False)
    assert p["percent"] == pytest.approx(50, abs=0.01) and p["design"] == metrics.PAIRED_DESIGN
    assert p["ci95"][0] < p["percent"] < p["ci95"][1] and p["ci95"][1] - p["ci95"][0] < 0.1
    assert i["ci95"][1] - i["ci95"][0] > 10 * (p["ci95"][1] - p["ci95"][0])
    with pytest.raises(ValueError):
        metrics.paired_improvement([1, 2], [1], cap=10)


def test_paired_improvement_censors_failures():
    imp = metrics.paired_improvement([100, 100, 100], [50, None, 50], cap=400)
    assert imp["censored"]
    assert imp["percent"] == pytest.approx(100 * (1 - (500 / 3) / 100))


def _trial(first: int | None, cap: int, greedy: int | None, episodes: list[int]) -> TrialResult:
    steps = np.array(episodes if first is not None else [-cap], np.int64)
    conv = greedy is not None
    return TrialResult(exploration_steps=first, converged=conv, total_steps=int(abs(steps).sum()) if conv else None,
                       greedy_steps=greedy, episodes=len(steps), episode_steps=steps,
                       greedy_lengths=np.zeros(len(steps), np.int64), macro_steps=np.zeros(len(steps), np.int64),
                       greedy_path=[])


def test_summarize_reports_reached_and_a_censored_mean():
    cap = 10_000
    none = MethodResult("none", [_trial(1000, cap, 20, [1000, 50, 20]), _trial(2000, cap, 20, [2000, 20]),
                                 _trial(3000, cap, 20, [3000, 20])])
    bad = MethodResult("pseudo [random]", [_trial(None, cap, None, []), _trial(None, cap, None, []),
                                           _trial(500, cap, 20, [500, 20])])
    out = summarize([none, bad])
    e = out["pseudo [random]"]
    assert e["reached"] == 1 and e["mean_is_lower_bound"] and e["cap"] == cap
    assert e["mean"] == pytest.approx((2 * cap + 500) / 3)
    assert e["mean"] >= 2 * cap / 3
    assert e["improvement_percent"] < 0  # worse than none, as it is
    assert e["improvement_design"] == metrics.PAIRED_DESIGN
    assert e["improvement_censored"] and e["improvement_cap_dominated"] and e["mean_cap_dominated"]
    assert out["none"]["improvement_design"] is None and not out["none"]["mean_is_lower_bound"]
    for key in ("exploration_steps", "mean", "ci95", "improvement_percent", "improvement_ci95", "greedy_steps",
                "greedy_mean", "greedy_ci95", "total_steps", "total_mean", "total_ci95", "converged",
                "episodes", "episode_steps", "greedy_path_states", "median", "median_ci95"):
        assert key in e
    table = method_table(out)
    assert "1/3" in table and f"≥ {e['mean']:,.1f}" in table and "lower bound" in table
    assert "common random numbers" in table
    assert f"{e['improvement_percent']:,.1f}‡" in table and "more than half of a mean" in table


def test_sweep_summary_counts_unreached_trials():
    def rec(method, seed, ex):
        cfg = {"task": 1, "start": [0, 0], "goal": [1, 1], "source": "coarse", "target": "fine", "wind": 0.0,
               "epsilon": 0.1, "lam": 0.9, "alpha": 0.1, "gamma": 0.99, "trials": len(ex), "patience": 20,
               "max_episodes": 2000, "trajectory": "optimal", "method": method, "seed": seed,
               "K": None if method == "none" else "auto"}
        return {"config": cfg, "result": {"exploration_steps": ex, "greedy_steps": [1] * len(ex),
                                          "total_steps": [1] * len(ex), "converged": [v is not None for v in ex]}}
    rows = sweep_summarize([rec("none", 0, [100, 200]), rec("none", 1, [300, 400]),
                            rec("pseudo", 1, [None, 40]), rec("pseudo", 0, [10, 20])])
    p = next(r for r in rows if r["method"] == "pseudo")
    assert p["reached"] == 3 and p["trials"] == 4 and p["mean_is_lower_bound"]
    assert p["mean"] == pytest.approx((10 + 20 + 20_000_000 + 40) / 4)
    assert p["improvement_design"] == metrics.PAIRED_DESIGN
    assert p["improvement_censored"] and p["improvement_cap_dominated"]
    assert next(r for r in rows if r["method"] == "none")["improvement_censored"] is None
    text = summary_markdown(rows)
    assert "3/4" in text and "≥" in text and "‡" in text and "more than half of a mean" in text


def test_learning_curve_means_include_converged_trials():
    """A trial that converged after 2 episodes keeps counting its greedy length; the
    figure's mean is the transfer metrics' curve, not the mean of the slow trials only."""
    fast = [50, 10]
    slow = [400, 300, 200, 100, 90]
    means = figures.curve_means({"m": [fast, slow]}, greedy={"m": [10, None]})["m"]
    assert len(means) == 5
    assert means[4] == pytest.approx((10 + 90) / 2)  # not 90: the converged trial counts
    expected = np.mean([learning_metrics.curve(fast, 10, 5), learning_metrics.curve(slow, None, 5)], axis=0)
    assert means == pytest.approx(expected)


def test_learning_curves_figure_draws(tmp_path):
    figures.learning_curves({"a": [[50, 10], [400, 300, 200]]}, "t", tmp_path / "c.png", greedy={"a": [10, None]})
    assert (tmp_path / "c.png").stat().st_size > 0


def test_learning_curve_bands_stay_inside_the_trials_steps():
    """On a log axis a symmetric interval around a skewed mean reaches below one step; the
    band is the trials' middle half, so it stays within the steps observed."""
    trials = [[5000, 40, 20], [30, 20], [25, 20], [20]]
    mean, low, high = figures.curve_band(trials, greedy=[20, 20, 20, 20])
    arr = np.array([[5000, 40, 20], [30, 20, 20], [25, 20, 20], [20, 20, 20]], dtype=float)
    assert np.allclose(mean, arr.mean(axis=0))
    assert np.all(low >= arr.min(axis=0)) and np.all(high <= arr.max(axis=0))
    assert low[0] == np.percentile(arr[:, 0], 25) and high[0] == np.percentile(arr[:, 0], 75)
    t_low = mean[0] - 3.182 * arr[:, 0].std(ddof=1) / 2  # the old t-band: below zero here
    assert t_low < 0 < low[0]
