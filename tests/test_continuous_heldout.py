"""research/continuous_heldout.py's statistics on small synthetic cases (no MuJoCo): the paired
factor none / pseudo recovers a factor put in, a pair censored in both trials is a tie (counted
and left out), one censored trial is a bound, and the verdict follows the interval."""

import importlib.util
import math
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def heldout():
    spec = importlib.util.spec_from_file_location("continuous_heldout", ROOT / "research" / "continuous_heldout.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def trial(first, conv, episodes=50, curve_total=None):
    """A trial record as ``trial_record`` makes it (None: censored at the cap)."""
    per = (curve_total if curve_total is not None else (conv if conv is not None else 10_000_000)) / 100
    return {"first_exposure": first, "convergence": conv, "converged": conv is not None, "episodes": episodes,
            "curve": [per] * 100}


CAP = 1_000_000
NOISE = [0.3, -0.3, 0.1, -0.1, 0.2, -0.2, 0.05, -0.05, 0.15, -0.15]
"""Log noise summing to zero: the geometric mean of the seeds' factors is exactly the factor put in."""


def known_case(factor):
    seeds = range(5000, 5010)
    none = {s: trial(int(20_000 * factor * math.exp(e)), int(200_000 * factor * math.exp(e))) for s, e in zip(seeds, NOISE)}
    pseudo = {s: trial(20_000, 200_000) for s in seeds}
    return none, pseudo


def test_a_known_factor_is_recovered_with_an_interval_around_it(heldout):
    none, pseudo = known_case(2.0)
    st = heldout.case_stats(none, pseudo, CAP)
    for metric in ("convergence", "first_exposure"):
        f = st[metric]
        assert f["factor"] == pytest.approx(2.0, rel=1e-4)
        assert f["ci95"][0] < 2.0 < f["ci95"][1] and f["ci95"][0] > 1.0
        assert f["worst"] == pytest.approx(2.0 * math.exp(-0.3), rel=1e-4)
        assert f["ties"] == 0 and f["bounds"] == 0 and f["pairs"] == 10
    assert heldout.verdict(st["convergence"]) == "pseudo cheaper"
    # the transfer ratio of the cost metric: pseudo saves half of none's cost (factor 2)
    assert st["cost"]["transfer_ratio"] == pytest.approx(0.5, rel=1e-3)
    assert st["methods"]["none"]["converged"] == 10 and st["methods"]["pseudo"]["failed"] == 0
    # the docs' figure: 100 (1 - mean(pseudo) / mean(none))
    mean_none = sum(t["first_exposure"] for t in none.values()) / 10
    assert st["improvement"]["percent"] == pytest.approx(100 * (1 - 20_000 / mean_none))


def test_the_factor_swaps_when_pseudo_is_dearer(heldout):
    none, pseudo = known_case(0.5)
    st = heldout.case_stats(none, pseudo, CAP)
    assert st["convergence"]["factor"] == pytest.approx(0.5, rel=1e-4)
    assert heldout.verdict(st["convergence"]) == "pseudo dearer"


def test_a_pair_censored_in_both_is_a_tie_left_out_and_one_censored_is_a_bound(heldout):
    none, pseudo = known_case(2.0)
    none[5000] = trial(30_000, None)
    pseudo[5000] = trial(20_000, None)  # both unconverged: a tie
    none[5001] = trial(30_000, None)    # only none unconverged: a bound at the cap
    st = heldout.case_stats(none, pseudo, CAP)
    conv = st["convergence"]
    assert conv["ties"] == 1 and conv["bounds"] == 1 and conv["pairs"] == 10
    assert conv["seeds"] == 9  # the tied seed informs nothing and is left out
    kept = [math.log(none[s]["convergence"] / 200_000) for s in range(5002, 5010)] + [math.log(CAP / 200_000)]
    assert conv["factor"] == pytest.approx(math.exp(sum(kept) / len(kept)), rel=1e-6)
    assert st["methods"]["none"]["converged"] == 8 and st["methods"]["pseudo"]["converged"] == 9
    assert st["first_exposure"]["ties"] == 0  # first exposure was reached in every trial


def test_every_pair_tied_gives_no_factor_and_says_so(heldout):
    seeds = range(3)
    none = {s: trial(10_000 + s, None) for s in seeds}
    pseudo = {s: trial(9_000 + s, None) for s in seeds}
    st = heldout.case_stats(none, pseudo, 150_000)
    assert st["convergence"]["factor"] is None and st["convergence"]["ties"] == 3
    assert heldout.verdict(st["convergence"]) == "no pairs (all ties)"
    row = heldout.markdown([{"pair": "a->b", "task": 1, "cap": 150_000, "stats": st}])
    assert "all 3 pairs tied" in row and "0/3 / 0/3" in row


def test_overlapping_seeds_are_required(heldout):
    none, pseudo = known_case(2.0)
    del pseudo[5000]
    with pytest.raises(ValueError, match="same source seeds"):
        heldout.case_stats(none, pseudo, CAP)
