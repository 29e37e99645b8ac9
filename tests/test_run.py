"""The typed run (``experiments.run``): its store keys are the keys every store written so far
holds, it round-trips through its stored form, older forms migrate, and a malformed one is one
line naming the valid values."""

from dataclasses import replace
from pathlib import Path

import pytest

from armtransfer.errors import ArmTransferError
from armtransfer.experiments import benchmark_runs, sweep as sweeps
from armtransfer.experiments.run import (SCHEMA, Run, RunError, SourceRun, SweepRun, TrialRun, content_key, key_of,
                                         migrate)
from armtransfer.learning.config import LearnerConfig

ROOT = Path(__file__).resolve().parents[1]

SWEEPS = {
    "plain": {"tasks": [1], "methods": ["none", "pseudo"], "seeds": [0]},
    "grid": {"tasks": [2], "start_goal": [["0,0", "-8,12"]], "pairs": [["fine", "coarse"]], "methods": ["pseudo"],
             "K": ["auto", 0.5], "wind": [0.0, 0.01], "trials": 3, "trajectory": "learned"},
    "preset": {"tasks": [1], "methods": ["none"], "preset": "paper-calibrated"},
    "world": {"tasks": ["2"], "methods": ["none"], "world": "rooms11"},
    "learner": {"tasks": [1], "methods": ["none", "pseudo"], "learner": ["sarsa", "dqn"], "max_total_steps": 5000},
}
SWEEP_KEYS = {  # computed by the code before runs were typed (the dict runs), on 2026-12-06
    "plain": ["705a48a04c0f05cff988", "95b1cfadc3ee4ec243cb"],
    "grid": ["f47b35f352ff55295671", "fdb7cc5e47e9c8797868", "8b89022e32deab998be3", "c2b7cfe15c9d92f688fc",
             "5bb032c1148627b92074", "3ce96478fed40689a47d", "85f822fa32e46186fdc5", "f42d19d7bdcb5d2ce1f3"],
    "preset": ["63af846a13f1b808c4ab"],
    "world": ["73b932628c66d4123d3c"],
    "learner": ["f6c4976d6b01d3e149af", "50629562891fdacb4fa8", "d17fb6cb442a8bbaf6d8", "4b9b66b4c64cf7030722"],
}
PATH = {"trajectory": {"cells": [1, 2, 3], "actions": [0, 1], "goal": 3, "source": "coarse"}, "failure": None}
NOTHING = {"trajectory": None, "failure": "robot 1 (coarse) did not converge"}
CONFIG = LearnerConfig(max_total_steps=20_000)
TASK = ("coarse", "fine", [0, 0], [-8, 12])


def benchmark_runs_pinned() -> dict[str, tuple[Run, str]]:
    """Benchmark runs with and without their optional fields, and the keys the dict runs had."""
    return {
        "source": (benchmark_runs.source_run(*TASK, 7, LearnerConfig()), "dc0f300112f802dd9c17"),
        "source in a world": (benchmark_runs.source_run("coarse", "fine", [0, 0], [4, 4], 7, LearnerConfig(),
                                                        world="rooms11"), "4eea78d964684c2124d3"),
        "none": (benchmark_runs.trial_run("none", 0, *TASK, 0.0, 7, CONFIG, None), "61ee36e4624ce8cdd9c6"),
        "pseudo": (benchmark_runs.trial_run("pseudo", 2, *TASK, 0.01, 7, CONFIG, PATH), "db2293fee66b85e5d88b"),
        "told nothing": (benchmark_runs.trial_run("pseudo", 1, *TASK, 0.0, 7, CONFIG, NOTHING), "55cbd6c59d1165b19a2f"),
        "outside": (benchmark_runs.trial_run("none", 0, *TASK, 0.0, 7, CONFIG, None, learner="tabular-q",
                                             learner_options={"alpha": 0.5}), "6c189187eb8be7e8431c"),
        "continuous": (benchmark_runs.trial_run("pseudo", 0, "planar2:joint", "planar3:joint", [0, 0], [-8, 12], 0.0,
                                                7, CONFIG, PATH, world="rooms11", state="continuous", noise=0.1),
                       "e67904e1afab50c86434"),
    }


@pytest.mark.parametrize("name", SWEEPS)
def test_sweep_runs_keep_the_keys_of_the_dict_runs(name):
    runs = sweeps.expand(sweeps.normalise({"sweep": SWEEPS[name]}))
    assert [r.key() for r in runs] == SWEEP_KEYS[name]
    assert all(r.key() == content_key(r.to_dict()) for r in runs)  # schema 1: the version is not hashed


def test_benchmark_runs_keep_the_keys_of_the_dict_runs():
    for name, (run, key) in benchmark_runs_pinned().items():
        assert run.key() == key == key_of(run.to_dict(), 1), name
        assert "schema" not in run.to_dict() and SCHEMA == 1
        assert key_of(run.to_dict(), 2) != key  # a later schema keys the same fields apart


def test_defaults_stay_out_of_the_stored_form_and_values_go_in():
    runs = benchmark_runs_pinned()
    assert "world" not in runs["source"][0].to_dict() and runs["source in a world"][0].to_dict()["world"] == "rooms11"
    none = runs["none"][0].to_dict()
    assert not {"state", "noise", "learner_options", "trajectory", "told_nothing"} & set(none)
    assert runs["continuous"][0].to_dict()["noise"] == 0.1 and runs["outside"][0].to_dict()["learner_options"]
    told = runs["told nothing"][0].to_dict()
    assert told["trajectory"] is None and told["told_nothing"] == "none" and "told_nothing" not in runs["pseudo"][0].to_dict()
    plain, learner = (sweeps.expand(sweeps.normalise({"sweep": SWEEPS[n]})) for n in ("plain", "learner"))
    assert not {"preset", "learner", "world", "arms", "max_total_steps"} & set(plain[0].to_dict())
    assert learner[-1].to_dict()["learner"] == "dqn" and learner[0].to_dict()["max_total_steps"] == 5000


def test_every_run_round_trips_through_its_stored_form():
    examples = [r for path in sorted((ROOT / "examples" / "sweeps").glob("*.toml")) for r in sweeps.load(path).runs]
    runs = [r for r, _ in benchmark_runs_pinned().values()] + examples
    assert len(examples) > 10
    for run in runs:
        back = Run.from_dict(run.stored())
        assert back == run and type(back) is type(run) and back.key() == run.key()
        assert list(back.stored()) == list(run.stored())  # the same fields in the same order: the same bytes


def test_an_older_stored_form_migrates_into_the_current_fields():
    """A trial run written before the told-nothing rule (it has no ``told_nothing``) and a sweep
    run written before presets and learners read back with their defaults, keeping their keys."""
    old = benchmark_runs.trial_run("pseudo", 1, *TASK, 0.0, 7, CONFIG, NOTHING).to_dict()
    del old["told_nothing"]
    key = content_key(old)
    current = migrate(dict(old, key=key))
    assert current["handed"] and current["told_nothing"] is None and current["world"] == "rooms"
    run = Run.from_dict(old)
    assert isinstance(run, TrialRun) and run.key() == key and run.told_nothing is None
    assert benchmark_runs.trial_result(run, None) == {"error": f"no trajectory: {NOTHING['failure']}"}  # as then
    sweep_run = Run.from_dict(sweeps.expand(sweeps.normalise({"sweep": SWEEPS["plain"]}))[0].to_dict())
    assert isinstance(sweep_run, SweepRun) and (sweep_run.preset, sweep_run.learner, sweep_run.world) == \
        ("default", "sarsa", None) and sweep_run.key() == SWEEP_KEYS["plain"][0]
    source = Run.from_dict(benchmark_runs_pinned()["source"][0].stored())
    assert isinstance(source, SourceRun) and source.world == "rooms" and source.learner_config() == LearnerConfig()


@pytest.mark.parametrize("change,message", [
    ({"format": "armtransfer-run/9"}, "unknown format 'armtransfer-run/9' of a run; valid formats: armtransfer-run/1, "
                                      "armtransfer-benchmark-source/1, armtransfer-benchmark-trial/1"),
    ({"state": "voxel"}, "unknown state 'voxel' of a run; valid states: discrete, continuous"),
    ({"colour": "red"}, "unknown field 'colour' of a run of format armtransfer-benchmark-trial/1; valid fields: format, "),
    ({"schema": 2}, "a run of schema 2; this build reads schema 1"),
    ({"start": [0]}, "a run's start must be a cell [X, Y] of two integers, got [0]"),
    ({"trial": -1}, "a run's trial must be an integer >= 0, got -1"),
    ({"noise": 0.1}, "a run's noise goes with a continuous state"),
    ({"config": {"alpha": 2.0}}, "alpha"),
])
def test_a_malformed_run_is_one_line_naming_the_valid_values(change, message):
    stored = benchmark_runs.trial_run("none", 0, *TASK, 0.0, 7, CONFIG, None).to_dict()
    with pytest.raises(ArmTransferError) as err:
        Run.from_dict({**stored, **change})
    assert "\n" not in str(err.value) and message in str(err.value)


def test_a_sweep_run_checks_its_trajectory_kind_and_its_learner_settings_come_from_its_preset():
    run = sweeps.expand(sweeps.normalise({"sweep": SWEEPS["preset"]}))[0]
    with pytest.raises(RunError, match="unknown trajectory kind 'best' of a run; valid trajectory kinds: optimal, learned"):
        replace(run, trajectory="best")
    capped = sweeps.expand(sweeps.normalise({"sweep": SWEEPS["learner"]}))[0]
    assert capped.learner_config().max_total_steps == 5000
    assert capped.learner_config(own_cap=True).max_total_steps == LearnerConfig.max_total_steps
