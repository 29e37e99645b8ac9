"""The trials of one method run on threads (the learner's kernel releases the GIL); the
results are the same, bit for bit, for any number of threads."""

import numpy as np
import pytest

from armtransfer import cpus
from armtransfer.errors import InvalidParameterError
from armtransfer.experiments import experiment
from armtransfer.learning.config import LearnerConfig
from armtransfer.tasks.catalog import TABLE_I
from armtransfer.tasks.grid_robots import grid_robot


def _same(a, b) -> None:
    assert len(a.trials) == len(b.trials)
    for x, y in zip(a.trials, b.trials):
        assert x.exploration_steps == y.exploration_steps and x.total_steps == y.total_steps
        assert np.array_equal(x.episode_steps, y.episode_steps)
        assert np.array_equal(x.greedy_lengths, y.greedy_lengths)
        assert x.greedy_path == y.greedy_path and x.first_path == y.first_path


@pytest.mark.parametrize("method", ["none", "pseudo", "guided"])
def test_threads_do_not_change_a_result(method):
    coarse, fine = grid_robot("coarse"), grid_robot("fine")
    start, goal = TABLE_I[1].cells()
    traj = experiment.source_trajectory("optimal", coarse, start, goal, LearnerConfig(), 0)
    config = LearnerConfig(max_episodes=40)
    runs = [experiment.run_method(method, fine, start, goal, [traj], 6, 3, config, threads=n) for n in (1, 2, 3)]
    _same(runs[0], runs[1])
    _same(runs[0], runs[2])
    # and the trials differ from each other: the check above compares something
    assert len({t.exploration_steps for t in runs[0].trials}) > 1


def test_every_trial_is_reported_once_whatever_the_threads():
    fine = grid_robot("fine")
    start, goal = TABLE_I[1].cells()
    ticks = []
    experiment.run_method("none", fine, start, goal, None, 5, 0, LearnerConfig(max_episodes=3), threads=2,
                          on_trial=lambda: ticks.append(1))
    assert len(ticks) == 5


def test_the_thread_count_comes_from_the_environment(monkeypatch):
    monkeypatch.setenv(cpus.ENV, "3")
    assert experiment.trial_threads() == cpus.cpus() == 3
    monkeypatch.delenv(cpus.ENV)
    assert cpus.cpus() >= 1
    for bad in ("0", "-2", "two"):
        monkeypatch.setenv(cpus.ENV, bad)
        with pytest.raises(InvalidParameterError, match=cpus.ENV) as err:
            cpus.cpus()
        assert "\n" not in str(err.value)


def test_an_error_in_a_trial_reaches_the_caller(monkeypatch):
    from armtransfer.learning import sarsa

    def broken(*args, **kwargs):
        raise RuntimeError("trial failed")

    monkeypatch.setattr(sarsa, "learn", broken)
    fine = grid_robot("fine")
    start, goal = TABLE_I[1].cells()
    with pytest.raises(RuntimeError, match="trial failed"):
        experiment.run_method("none", fine, start, goal, None, 4, 0, LearnerConfig(max_episodes=3), threads=2)


def test_a_bad_thread_count_is_one_line_and_exit_2(tmp_path):
    import os
    import subprocess
    import sys

    env = {**os.environ, cpus.ENV: "zero"}
    proc = subprocess.run([sys.executable, "-m", "armtransfer.cli", "rooms", "--trials", "2", "--no-controls",
                           "--method", "none", "--max-episodes", "2", "--json", str(tmp_path / "r.json")],
                          capture_output=True, text=True, env=env, timeout=120, cwd=tmp_path)
    assert proc.returncode == 2 and len(proc.stderr.strip().splitlines()) == 1, proc.stderr
    assert cpus.ENV in proc.stderr and "Traceback" not in proc.stderr
    assert list(tmp_path.iterdir()) == []
