"""armtransfer benchmark: the fast suite end to end, its determinism, its errors, and the
statistics it reports (Kaplan-Meier, intervals inside the data, paired factors)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from armtransfer.cli import main
from armtransfer.errors import InvalidParameterError
from armtransfer.experiments import benchmark, suites
from armtransfer.experiments.reports import benchmark_report
from armtransfer.experiments.stats import benchmark_stats, metrics, multiplicity, survival
from armtransfer.learning import methods
from armtransfer.tasks.grid_robots import grid_robot


@pytest.fixture(scope="module")
def fast_runs(benchmark_fast):
    """The fast suite, run twice with the same seed through the command: on 1 worker (one),
    then on 2 (two)."""
    codes, root = benchmark_fast
    return root, codes


REPORT = ("report.md", "results.json", "survival_fast.png", "learning_curves_fast.png")
"""What the fast suite's report is, byte for byte (timings.json holds wall times)."""


def test_fast_suite_writes_one_whole_report(fast_runs):
    root, codes = fast_runs
    assert codes == [0, 0]
    out = root / "one"
    names = {p.name for p in out.iterdir()}
    assert names == {*REPORT, "timings.json", "sweep.json", "runs", "failed", "timings"}  # no .lock: a finished store keeps none
    suite = suites.get("fast")
    ran, _ = benchmark.methods_to_run()
    section = suite.sections[0]  # a source run per (case, source seed) and a run per trial of every method
    pairs = len(section.cases) * section.source_seeds
    assert len(list((out / "runs").glob("*.json"))) == pairs * (1 + section.trials * len(ran))
    assert not list((out / "failed").iterdir())
    data = json.loads((out / "results.json").read_text())
    assert len(data["records"]) == len(section.cases) * section.source_seeds * len(ran)
    for rec in data["records"]:
        assert len(rec["first_exposure"]) == section.trials and rec["cap"] == section.max_total_steps
    assert data["suite"]["held_out"] is False
    timings = json.loads((out / "timings.json").read_text())
    assert timings["total_seconds"] > 0 and "_seconds" not in (out / "results.json").read_text()


def test_same_seed_same_bytes_on_one_or_two_workers(fast_runs):
    root, _ = fast_runs
    for name in REPORT:
        assert (root / "one" / name).read_bytes() == (root / "two" / name).read_bytes(), name
    # the runs too: the same keys, the same results
    runs = sorted(p.name for p in (root / "one" / "runs").glob("*.json"))
    assert runs == sorted(p.name for p in (root / "two" / "runs").glob("*.json"))
    for name in runs:
        assert (root / "one" / "runs" / name).read_bytes() == (root / "two" / "runs" / name).read_bytes()


def test_the_store_gives_what_one_process_gives(fast_runs):
    """The records of the runs in the store, run on workers, are those of the suite run in this
    process, trial runs on threads."""
    root, _ = fast_runs
    records, timings = benchmark.run_suite(suites.get("fast"), 0, threads=2)
    assert json.loads((root / "one" / "results.json").read_text())["records"] == records
    assert timings["total_seconds"] > 0


def test_report_names_each_methods_baseline(fast_runs):
    root, _ = fast_runs
    report = (root / "one" / "report.md").read_text()
    data = json.loads((root / "one" / "results.json").read_text())
    named = 0
    for m in data["methods"]:
        bases = list(benchmark.baselines_of(m))
        assert data["baselines"][m] == bases
        listed, row = [line for line in report.splitlines() if line.startswith(f"| {m} ")]  # methods, case
        assert listed.split("|")[2].strip().startswith(", ".join(bases) or "-")
        assert row.split("|")[2].strip() == (", ".join(bases) or "-")
        for base in bases:
            named += 1
            assert f"`{m}` against `{base}`" in report
            assert f"{base}: " in row.split("|")[10] and f"{base}: " in row.split("|")[11]  # good path, settled
    assert named >= 3
    # two source seeds: the numbers, but no claim
    assert "too few pairs for a claim (2 < 10)" in report


def test_goal_only_is_at_least_as_fast_as_plan_on_every_case(fast_runs):
    """Knowing the goal never hurts: on every case of the fast suite `goal-only` reaches the goal
    first at least as fast as `plan` (told nothing), on every source seed."""
    root, _ = fast_runs
    data = json.loads((root / "one" / "results.json").read_text())
    for section in data["summary"].values():
        for case in section["cases"]:
            fe = case["methods"]["goal-only"]["against"]["plan"]["first_exposure"]
            assert fe["factor"] >= 1.0 and fe["worst"] >= 1.0, case["label"]


def test_a_bad_suite_name_is_one_line_listing_the_suites(tmp_path, capsys):
    out = tmp_path / "never"
    assert main(["benchmark", "--suite", "nope", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "unknown suite 'nope'" in err
    for name in suites.SUITES:
        assert name in err
    assert not out.exists()


def test_a_used_output_directory_is_refused_before_any_work(tmp_path, capsys):
    (tmp_path / "keep.txt").write_text("x")
    assert main(["benchmark", "--suite", "fast", "--out", str(tmp_path)]) == 2
    assert "not empty" in capsys.readouterr().err
    assert [p.name for p in tmp_path.iterdir()] == ["keep.txt"]


def test_suites_are_versioned_and_marked_held_out_or_not():
    for s in suites.SUITES.values():
        assert s.version >= 1 and s.sections
    assert not suites.get("dev").held_out and not suites.get("fast").held_out
    standard = suites.get("standard")
    assert standard.held_out
    assert [x.name for x in standard.sections] == ["paper", "random", "embodiment", "wind"]
    assert all(x.source_seeds >= 10 for x in standard.sections)
    held = {c for x in standard.sections for c in x.cases}
    dev = suites.get("dev").sections[0]
    assert not {c for c in dev.cases if c.task is not None} & held
    # dev draws on the cells every choice was made on (even); random on cells none saw (odd)
    fine, coarse = grid_robot("fine"), grid_robot("coarse")
    rnd = suites.get("random").sections[0]
    assert len(rnd.cases) >= 10 and all(c.cells == "odd" for c in rnd.cases)
    drawn_case = next(c for c in dev.cases if c.task is None)
    assert drawn_case.cells == "even"
    ci = dev.cases.index(drawn_case)
    for j in range(3):
        for cell in benchmark.case_cells(drawn_case, coarse, fine, 0, dev.name, ci, j):
            assert all(v % 2 == 0 for v in fine.layout.xy(cell))
    case = rnd.cases[0]
    for j in range(3):
        start, goal = benchmark.case_cells(case, fine if case.source == "fine" else coarse,
                                           fine if case.target == "fine" else coarse, 0, rnd.name, 0, j)
        for cell in (start, goal):
            assert any(v % 2 for v in fine.layout.xy(cell))
        d = len(fine.shortest_path(fine.start_state(start), goal)) - 1
        assert case.distance[0] <= d < case.distance[1]
    emb = suites.get("embodiment").sections[0]
    assert {c.task for c in emb.cases} == {1, 2, 3, 4}
    assert sorted({c.wind for c in suites.get("wind").sections[0].cases}) == [0.01, 0.05, 0.1]
    with pytest.raises(InvalidParameterError, match="valid suites: paper, random"):
        suites.get("Standard")


def test_kaplan_meier_matches_a_hand_computed_example():
    # reached at 3, 5, 5, 8; unreached (censored) at the cap 10 twice... and one censored at 6
    # is not expressible with one cap, so: 3, 5, 5, 8 reached, two censored at 10.
    km = survival.kaplan_meier([3, 5, 5, 8, None, None], cap=10)
    # at 3: 5/6; at 5: two of five at risk -> 5/6 * 3/5 = 1/2; at 8: one of three -> 1/2 * 2/3 = 1/3
    assert km["times"] == [3.0, 5.0, 8.0, 10.0]
    assert km["survival"] == pytest.approx([5 / 6, 1 / 2, 1 / 3, 1 / 3])
    assert km["median"] == 5.0 and not km["median_beyond_cap"]
    lo, hi = km["median_ci95"]
    assert lo == 3.0 and hi is None  # the upper band never falls to one half within the data
    assert km["n"] == 6 and km["events"] == 4


def test_kaplan_meier_of_all_reached_trials_stays_within_the_data():
    km = survival.kaplan_meier([30, 10, 20, 40], cap=1000)
    assert km["survival"][-1] == 0.0 and km["median"] == 20.0
    lo, hi = km["median_ci95"]
    assert 10.0 <= lo <= 20.0 <= hi <= 40.0


def test_kaplan_meier_of_mostly_unreached_trials_has_no_median():
    km = survival.kaplan_meier([4, None, None], cap=100)
    assert km["median"] is None and km["median_beyond_cap"]
    assert survival.kaplan_meier([None, None], cap=100)["median"] is None


@pytest.mark.parametrize("seed", range(5))
def test_intervals_stay_within_the_datas_range(seed):
    rng = np.random.default_rng(seed)
    x = rng.lognormal(3, 2, size=8)  # skewed, as step counts are
    for stat in (np.mean, np.median):
        lo, hi = survival.bootstrap_ci(x, stat)
        assert x.min() <= lo <= stat(x) <= hi <= x.max()
    mean, ci = metrics.mean_ci(list(x))
    assert x.min() <= ci[0] <= mean <= ci[1] <= x.max()
    r = survival.ratio_summary(np.log(x / x.mean()))
    ratios = x / x.mean()
    assert ratios.min() == pytest.approx(r["worst"]) and r["ci95"][0] >= r["worst"] - 1e-12
    assert r["ci95"][1] <= ratios.max() + 1e-12 and r["ci95"][0] > 0


def test_bootstrap_is_deterministic_and_handles_small_samples():
    x = [5.0, 9.0, 1.0, 40.0]
    assert survival.bootstrap_ci(x) == survival.bootstrap_ci(x)
    assert survival.bootstrap_ci([3.0]) is None
    assert survival.bootstrap_ci([2.0, 2.0, 2.0]) == [2.0, 2.0]


def _rec(method, seed, fe, cap=1000, case=0, baseline="none", conv=None):
    return {"section": "s", "case": case, "label": "c", "method": method, "baselines": [] if method == "none"
            else [baseline], "source_seed": seed, "cap": cap, "budget": 100, "optimal": 10, "error": None,
            "source_failure": None, "first_exposure": fe, "converged": [c is not None for c in (conv or [None] * len(fe))],
            "convergence_steps": conv or [None] * len(fe), "episodes": [3] * len(fe),
            "curves": [[float(v or cap)] * 3 for v in fe]}


def test_paired_factor_is_per_trial_and_ties_at_the_cap_are_counted_apart():
    recs = []
    for seed in range(10):
        base = [100 * (seed + 1), 300 * (seed + 1)]
        recs += [_rec("none", seed, base, cap=10_000), _rec("pseudo", seed, [v // 4 for v in base], cap=10_000)]
    # one seed converged in both, so the cost of 100 episodes is known there; elsewhere ties
    recs[0]["converged"] = recs[1]["converged"] = [True, True]
    out = benchmark_stats.summarize(recs)
    ab = out["s"]["cases"][0]["methods"]["pseudo"]["against"]["none"]
    assert ab["first_exposure"]["factor"] == pytest.approx(4.0)
    assert ab["first_exposure"]["ci95"] == pytest.approx([4.0, 4.0])
    # no trial converged in either: every pair is a tie, counted and left out (no factor of 1.00)
    conv = ab["convergence"]
    assert conv["factor"] is None and conv["ties"] == 20 and conv["pairs"] == 20
    assert ab["cost"]["ties"] == 18 and ab["cost"]["factor"] == pytest.approx(4.0)
    pooled = out["s"]["pooled"]["pseudo"]["none"]
    assert pooled["baseline"] == "none" and pooled["first_exposure"]["seeds"] == 10
    assert benchmark_report.judgement(pooled["first_exposure"]).startswith("faster than its baseline")
    text = benchmark_report.sentence("pseudo", pooled, "s")
    assert text.index("Good path") < text.index("Settled clock") < text.index("First exposure") \
        < text.index("Transfer ratio")
    assert "Good path: not measured" in text  # these records have no good-path clock
    assert "4.00x [4.00x, 4.00x] as fast" in text and "20 trial pairs capped in both are ties" in text


def test_a_first_episode_won_and_lost_back_is_said():
    recs = []
    for seed in range(10):
        recs += [_rec("none", seed, [400 + seed, 500], conv=[1000 - seed, 900]),
                 _rec("pseudo", seed, [40 + seed, 50], conv=[2000 + seed, 1800], cap=5000)]
    for r in recs:
        r["cap"] = 5000
    pooled = benchmark_stats.summarize(recs)["s"]["pooled"]["pseudo"]["none"]
    assert pooled["first_exposure"]["factor"] > 5 and pooled["convergence"]["factor"] < 1
    text = benchmark_report.sentence("pseudo", pooled, "s")
    assert "wins the first episode" in text and "loses it back" in text
    assert benchmark_report.judgement(pooled["convergence"]).startswith("slower")


def test_failures_are_counted_and_censored_pairs_are_bounds():
    recs = [_rec("none", s, [100, 200]) for s in range(10)]
    recs += [_rec("pseudo", s, [None, None] if s < 3 else [50, 100]) for s in range(10)]
    e = benchmark_stats.summarize(recs)["s"]["cases"][0]["methods"]["pseudo"]
    assert e["failure_rate"] == pytest.approx(6 / 20)
    fe = e["against"]["none"]["first_exposure"]
    assert fe["bounds"] == 6 and fe["ties"] == 0
    assert fe["worst"] == pytest.approx(math.sqrt(100 / 1000 * 200 / 1000))


def test_holm_adjusts_every_verdict_of_a_run():
    recs = []
    for seed in range(10):
        recs += [_rec("none", seed, [100 + seed, 300], conv=[900, 950 + seed]),
                 _rec("pseudo", seed, [50 + 3 * seed, 200 - seed], conv=[700 + 20 * seed, 990])]
    pooled = benchmark_stats.summarize(recs)["s"]["pooled"]["pseudo"]["none"]
    fe, conv = pooled["first_exposure"], pooled["convergence"]
    assert fe["verdicts"] == conv["verdicts"] == 3  # both, and the cost of 100 episodes
    assert multiplicity.holm([fe["p"], conv["p"], pooled["cost"]["p"]]) == [fe["p_holm"], conv["p_holm"],
                                                                              pooled["cost"]["p_holm"]]
    smallest = min((fe, conv, pooled["cost"]), key=lambda v: v["p"])
    assert smallest["p_holm"] == pytest.approx(min(1.0, 3 * smallest["p"]))


def test_an_interval_spanning_one_makes_no_claim_and_says_what_it_could_detect():
    ab = {"factor": 1.2, "ci95": [0.8, 1.7], "seeds": 10, "worst": 0.5, "p_holm": 0.4, "verdicts": 3,
          "detectable": [0.76, 1.32]}
    text = benchmark_report.judgement(ab)
    assert text.startswith("cannot be told apart") and "below 0.76x or above 1.32x" in text


def test_baseline_comes_from_the_registry_when_it_names_one(monkeypatch):
    class Named:
        baselines = ("pseudo", "dense")

    class Unnamed:
        pass

    assert benchmark.baseline_of("none") is None
    monkeypatch.setitem(methods.METHODS, "guided", Named())
    monkeypatch.setitem(methods.METHODS, "dense", Unnamed())
    assert benchmark.baselines_of("guided") == ("pseudo", "dense") and benchmark.registered_baseline("guided")
    assert benchmark.baselines_of("dense") == ("none",) and not benchmark.registered_baseline("dense")
    ran, _ = benchmark.methods_to_run(("guided",))
    assert ran == ["none", "pseudo", "dense", "guided", "goal-dense"]  # and their own baselines: pseudo's goal-only


def test_drawn_tasks_are_deterministic_and_long_enough():
    fine, coarse = grid_robot("fine"), grid_robot("coarse")
    draws = [benchmark.draw_task(coarse, fine, np.random.default_rng(7)) for _ in range(2)]
    assert draws[0] == draws[1]
    start, goal = draws[0]
    paths = [r.shortest_path(r.start_state(start), goal) for r in (fine, coarse)]
    assert all(p is not None for p in paths) and len(paths[0]) - 1 >= benchmark.MIN_DISTANCE
    rooms = set()
    for k in range(30):
        s, g = benchmark.draw_task(coarse, fine, np.random.default_rng(k))
        rooms |= {fine.layout.room_of(*fine.layout.xy(s)), fine.layout.room_of(*fine.layout.xy(g))}
    assert rooms == {1, 2, 3, 4}
    assert math.isfinite(benchmark.run_seed(0, "paper", 0, 0))


def test_a_source_that_does_not_converge_is_counted_not_dropped(monkeypatch):
    """Robot 1 hands nothing over: the pair is kept, and every method that reads a trajectory
    learns as its baseline told nothing, byte for byte that baseline's trials."""
    from dataclasses import replace

    from armtransfer.experiments import experiment

    def never(*args, **kwargs):
        raise InvalidParameterError("did not converge")

    monkeypatch.setattr(experiment, "source_trajectory", never)
    section = replace(suites.FAST, source_seeds=1, trials=1, max_total_steps=50_000)
    records, _ = benchmark.run_suite(suites.Suite("t", 1, False, "", (section,)), threads=1)
    by = {r["method"]: r for r in records}
    assert set(by) == set(benchmark.methods_to_run()[0])
    fields = ("first_exposure", "converged", "convergence_steps", "greedy_steps", "episodes", "area", "curves")
    told = 0
    for name, rec in by.items():
        m = methods.get(name)
        assert rec["error"] is None and rec["episodes"][0] > 0
        assert rec["source_failure"].startswith("robot 1 (coarse) did not converge")
        if m.shaped and getattr(m, "uses_trajectory", True):
            told += 1
            base = by[rec["told_nothing"]]
            assert rec["told_nothing"] == m.baselines[0] and "told_nothing" not in base
            assert [rec[f] for f in fields] == [base[f] for f in fields], name
        else:  # none (and a baseline that reads no trajectory) runs as always
            assert "told_nothing" not in rec
    assert told >= 3
    summary = benchmark_stats.summarize(records)["fast"]
    assert summary["cases"][0]["source_failures"] == 1
    assert summary["with_trajectory"]["told_nothing"] and summary["with_trajectory"]["pairs"] == 0
    pseudo = summary["cases"][0]["methods"]["pseudo"]
    assert pseudo["errors"] == [] and pseudo["failure_rate"] == summary["cases"][0]["methods"]["none"]["failure_rate"]


def test_a_run_written_before_told_nothing_keeps_its_error():
    """A stored trial run from before the rule (no ``told_nothing``) is an error, as it was."""
    from armtransfer.experiments import benchmark_runs
    from armtransfer.experiments.run import Run
    from armtransfer.learning.config import LearnerConfig

    nothing = {"trajectory": None, "failure": "robot 1 did not converge"}
    stored = benchmark_runs.trial_run("pseudo", 0, "coarse", "fine", [0, 0], [-8, 12], 0.0, 1, LearnerConfig(),
                                      nothing).to_dict()
    del stored["told_nothing"]  # as a run written before the rule was stored
    run = Run.from_dict(stored)
    assert benchmark_runs.trial_result(run, None) == {"error": "no trajectory: robot 1 did not converge"}


def test_every_record_carries_the_good_path_clock_and_the_report_leads_with_it(fast_runs):
    """Every trial of every record has good_path_steps and settled_ratio; a trial with a
    good_path_steps ended on a good path (its final greedy path within ceil(quality x shortest));
    the claims state the good path first, with the settled quality beside it, and lazy's control."""
    root, _ = fast_runs
    data = json.loads((root / "one" / "results.json").read_text())
    for rec in data["records"]:
        n = len(rec["first_exposure"])
        assert len(rec["good_path_steps"]) == len(rec["settled_ratio"]) == len(rec["final_ratio"]) == n
        good_len = math.ceil(round(1.05 * rec["optimal"], 9))
        for g, final, run in zip(rec["good_path_steps"], rec["final_ratio"], rec["steps_run"]):
            if g is not None:
                assert final is not None and round(final * rec["optimal"]) <= good_len and g <= run
    assert {"lazy", "goal-dense"} <= set(data["methods"])
    report = (root / "one" / "report.md").read_text()
    claim = next(line for line in report.splitlines() if line.startswith("- fast: `corridor` against `plan`"))
    assert claim.index("Good path:") < claim.index("Settled clock") and "settled at" in claim
    assert "- fast: `corridor` against `goal-only`" in report and "- fast: `pseudo` against `goal-dense`" in report
    assert "- fast, control: `lazy`" in report
