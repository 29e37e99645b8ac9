"""A benchmark case whose robot 2 is a continuous arm (``suites.Case.state``): the voxels suite's
``voxels-continuous`` section, run through ``benchmark.run_suite`` with a small step cap."""

from __future__ import annotations

import json
from dataclasses import replace

import pytest

from armtransfer.errors import InvalidParameterError
from armtransfer.experiments import benchmark, benchmark_runs, continuous, suites
from armtransfer.learning.config import LearnerConfig

CAP = 4_000
"""The step cap of the tests' trials: a few seconds for both cases, first exposures included."""


def small_suite(trials: int = 1, cap: int = CAP) -> suites.Suite:
    section = replace(suites.VOXELS_CONTINUOUS, source_seeds=1, trials=trials, max_total_steps=cap)
    return suites.Suite("t", 1, True, "", (section,))


@pytest.fixture(scope="module")
def records():
    return benchmark.run_suite(small_suite(), seed=0, threads=1)[0]


def test_the_voxels_suite_has_the_continuous_cases_beside_the_table_ones():
    suite = suites.get("voxels")
    assert suite.version == 2 and suite.held_out
    assert [s.name for s in suite.sections] == ["voxels", "voxels-continuous"]
    table, cont = suite.sections
    assert all(c.state == "discrete" and c.noise == 0 for c in table.cases)
    assert [(c.source, c.target, c.task, c.world, c.state, c.noise) for c in cont.cases] == [
        ("planar2:joint", "ur5e_like:joint", 2, "rooms11", "continuous", 0.1),
        ("ur5e_like:joint", "panda_like:joint", 2, "rooms11", "continuous", 0.1)]
    assert cont.source_seeds >= 10 and cont.methods == ("none", "pseudo")
    # a discrete case is stored as before states: no state, no noise
    assert all("state" not in c and "noise" not in c for c in table.to_dict()["cases"])
    assert [(c["state"], c["noise"]) for c in cont.to_dict()["cases"]] == [("continuous", 0.1)] * 2
    assert cont.cases[0].label == "planar2:joint -> ur5e_like:joint continuous (noise 0.1), task 2, in rooms11"


def test_one_source_seed_of_the_continuous_cases_gives_records_of_none_and_pseudo(records):
    assert sorted((r["case"], r["method"]) for r in records) == [(0, "none"), (0, "pseudo"), (1, "none"),
                                                                 (1, "pseudo")]
    for r in records:
        assert r["error"] is None and r["state"] == "continuous" and r["noise"] == 0.1, r
        assert r["source_failure"] is None and r["source_steps"] > 1 and r["cap"] == CAP
        assert len(r["first_exposure"]) == 1 and len(r["curves"]) == 1 and r["episodes"][0] >= 1
        fe = r["first_exposure"][0]
        assert fe is None or 0 < fe <= CAP
        if r["converged"][0]:
            assert r["convergence_steps"][0] <= CAP and r["greedy_steps"][0] >= r["optimal"]
    assert any(r["first_exposure"][0] is not None for r in records)  # the goal is reached within the cap


def test_a_continuous_trial_is_the_linear_learners_trial_with_the_runs_seed_and_trajectory(records):
    """The record's trial is ``experiments.continuous.run_method``'s trial of the same arm, seed
    and handed-over path (what ``transfer(state="continuous")`` runs), and not the table robot's."""
    from armtransfer.tasks.continuous import continuous_arm

    robots = benchmark.Robots({})
    p = benchmark.plan(small_suite(), 0, robots)
    pair = p.pairs[0]
    src = pair.source_run()
    source_result, _ = benchmark_runs.execute(src, robots.resolved)
    run = next(r for r in p.all_trial_runs(pair, source_result) if r.method == "pseudo")
    assert run.state == "continuous" and run.noise == 0.1 and run.learner == benchmark_runs.LEARNER
    target = robots(pair.case.target, pair.case.world)
    arm = continuous_arm("ur5e_like:joint", layout=target.layout, noise=0.1)
    start, goal = target.layout.cell(*pair.start), target.layout.cell(*pair.goal)
    arm.place(start)
    traj = benchmark_runs.trajectory_of(source_result["trajectory"])
    direct = continuous.run_method("pseudo", arm, goal, [traj], 1, pair.seed, pair.config,
                                   approx=continuous.approximation_for(arm))
    rec = next(r for r in records if r["case"] == 0 and r["method"] == "pseudo")
    t = direct.trials[0]
    assert rec["first_exposure"] == [t.exploration_steps] and rec["episodes"] == [t.episodes]
    table = benchmark_runs.trial_result(replace(run, state="discrete", noise=None), target)  # on the table: differs
    assert table["curve"] != rec["curves"][0]


def test_same_seed_same_records_on_one_or_two_threads_and_another_seed_differs():
    """Two trials per method: run one by one on two threads, trial k is trial k of the method
    (``run_method(first_trial=k)``), so the records are the bytes of one thread's."""
    suite = small_suite(trials=2, cap=1_500)
    one = benchmark.run_suite(suite, seed=3, threads=1)[0]
    two = benchmark.run_suite(suite, seed=3, threads=2)[0]
    assert json.dumps(one, sort_keys=True) == json.dumps(two, sort_keys=True)
    other = benchmark.run_suite(suite, seed=4, threads=2)[0]
    assert [r["curves"] for r in other] != [r["curves"] for r in one]


def test_trial_k_alone_is_trial_k_of_a_run_of_them_all():
    from armtransfer.tasks.catalog import world_task
    from armtransfer.tasks.continuous import continuous_arm
    from armtransfer.worlds.resolve import world

    small = world("rooms11")
    arm = continuous_arm("ur5e_like:joint", layout=small, noise=0.1)
    start, goal = world_task(small, 2).cells()
    config = LearnerConfig(max_total_steps=3_000, max_episodes=3)
    arm.place(start)
    both = continuous.run_method("none", arm, goal, None, 2, 5, config)
    arm.place(start)
    alone = continuous.run_method("none", arm, goal, None, 1, 5, config, first_trial=1)
    assert alone.trials[0].episode_steps.tolist() == both.trials[1].episode_steps.tolist()
    assert both.trials[0].episode_steps.tolist() != both.trials[1].episode_steps.tolist()
    with pytest.raises(InvalidParameterError, match="first_trial must be an integer >= 0"):
        continuous.run_method("none", arm, goal, None, 1, 5, config, first_trial=-1)


def test_a_bad_continuous_case_is_one_line():
    with pytest.raises(InvalidParameterError, match="unknown state 'continous'; valid states: discrete, continuous"):
        suites.Case("planar2:joint", "ur5e_like:joint", 2, state="continous")
    with pytest.raises(InvalidParameterError, match="noise .* applies to a continuous target; valid noise: 0"):
        suites.Case("planar2:joint", "ur5e_like:joint", 2, noise=0.1)
    with pytest.raises(InvalidParameterError, match="a continuous target has no wind; valid wind: 0"):
        suites.Case("planar2:joint", "ur5e_like:joint", 2, wind=0.1, state="continuous")


def test_an_outside_learner_is_refused_on_a_continuous_case_before_anything_runs():
    with pytest.raises(InvalidParameterError, match="learner 'dqn' learns on a discrete target; .* continuous one; "
                                                    "valid learners for it: sarsa"):
        benchmark.plan(small_suite(), 0, learners=("sarsa", "dqn"))


def test_a_discrete_trial_run_names_no_state_and_keeps_its_key():
    """The keys of every table-based run are those from before continuous targets."""
    config = LearnerConfig(max_total_steps=1000)
    args = ("none", 0, "coarse", "fine", [0, 0], [5, 5], 0.0, 7, config, None)
    run = benchmark_runs.trial_run(*args)
    assert "state" not in run.to_dict() and "noise" not in run.to_dict()
    assert run == benchmark_runs.trial_run(*args, state="discrete")
    cont = benchmark_runs.trial_run(*args, state="continuous", noise=0.1)
    assert cont.key() != run.key() and {k: v for k, v in cont.to_dict().items() if k not in ("state", "noise")} \
        == run.to_dict()


def test_the_command_on_two_workers_writes_the_records_of_one_process(records, tmp_path, monkeypatch):
    """``armtransfer benchmark`` on a continuous section: its trial runs go to worker processes
    (which get the table robots by spec and make the arms themselves), through the store, and the
    report's records are those of :func:`benchmark.run_suite` in this process."""
    from armtransfer.cli import main

    suite = replace(small_suite(), name="tiny-continuous")
    monkeypatch.setitem(suites.SUITES, suite.name, suite)
    out = tmp_path / "store"
    assert main(["benchmark", "--suite", suite.name, "--out", str(out), "--workers", "2"]) == 0
    data = json.loads((out / "results.json").read_text())
    assert data["records"] == records
    assert "continuous (noise 0.1)" in (out / "report.md").read_text()


def test_a_continuous_target_that_cannot_be_placed_over_the_start_names_the_case(monkeypatch):
    from armtransfer.errors import InvalidTaskError, UnreachableTableError
    from armtransfer.ik.continuous3d import SpatialContinuousArm

    def nowhere(self, cell):
        raise UnreachableTableError("the arm cannot place its tool point in cell (9, 9)")

    monkeypatch.setattr(SpatialContinuousArm, "place", nowhere)
    with pytest.raises(InvalidTaskError, match=r"^planar2:joint -> ur5e_like:joint continuous \(noise 0.1\), task 2, "
                                               r"in rooms11: the arm cannot place its tool point in cell \(9, 9\)$"):
        benchmark.plan(small_suite(), 0)


def test_a_continuous_case_with_noise_out_of_range_names_the_case():
    case = replace(suites.VOXELS_CONTINUOUS.cases[0], noise=0.9)
    section = replace(suites.VOXELS_CONTINUOUS, cases=(case,), source_seeds=1)
    with pytest.raises(InvalidParameterError, match=r"^planar2:joint -> ur5e_like:joint continuous \(noise 0.9\), "
                                                    r"task 2, in rooms11: the actuation noise .*0\.9"):
        benchmark.plan(suites.Suite("t", 1, True, "", (section,)), 0)
