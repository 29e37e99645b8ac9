"""The benchmark's runs in the result store: a crash mid-way resumes to the same bytes, the
store rebuilds its report, a trial run alone is that trial of the whole method, and a run
names its learner. The slow tests: `--suite paper` killed with SIGKILL at three moments, and
a Ray cluster given by `--address`."""

from __future__ import annotations

import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
import types
from pathlib import Path

import numpy as np
import pytest

from armtransfer.cli import main
from armtransfer.errors import ArmTransferError
from armtransfer.experiments import benchmark_runs, experiment
from armtransfer.experiments.store import ResultStore
from armtransfer.learning.config import LearnerConfig
from armtransfer.parallel.reaper import descendants, start_time
from armtransfer.tasks.catalog import TABLE_I
from armtransfer.tasks.grid_robots import grid_robot
from contract import session, settle

REPORT = ("report.md", "results.json", "survival_fast.png", "learning_curves_fast.png")


def _run_files(out: Path) -> list[str]:
    return sorted(p.name for p in (out / "runs").glob("*.json"))


@pytest.fixture(scope="module")
def whole(benchmark_fast):
    """The fast suite, uninterrupted, on 2 workers (never written to here: tests copy it)."""
    codes, root = benchmark_fast
    assert codes == [0, 0]
    return root / "two"


def test_a_crash_mid_run_resumes_to_the_same_bytes(whole, tmp_path, monkeypatch, capsys):
    """The driver dies after its 7th run is written (robot 1's two paths and trials of the
    methods that need none; one path's file is then taken away, as if it had been under way),
    with a half-written temporary file left in the store; the same command again runs each
    missing run once, and nothing else."""
    real_write, written, keys = ResultStore.write_run, [], []

    def crash_after_seven(self, run, result, elapsed):
        if len(written) == 7:
            raise KeyboardInterrupt  # the driver stops here, its workers with it
        real_write(self, run, result, elapsed)
        written.append(run.FORMAT)
        keys.append(run.key())

    def counted(self, run, result, elapsed):
        real_write(self, run, result, elapsed)
        keys.append(run.key())

    out = tmp_path / "store"
    monkeypatch.setattr(ResultStore, "write_run", crash_after_seven)
    assert main(["benchmark", "--suite", "fast", "--out", str(out), "--workers", "1"]) == 130
    monkeypatch.undo()
    assert written.count(benchmark_runs.SOURCE_FORMAT) == 2 and benchmark_runs.TRIAL_FORMAT in written
    assert len(_run_files(out)) == 7 and not (out / "report.md").exists()
    # as if robot 1's second path had been under way at the kill, while later runs were done
    late = keys.pop(written.index(benchmark_runs.SOURCE_FORMAT, 1))
    (out / "runs" / f"{late}.json").unlink()
    (out / "runs" / ".deadbeef.json.tmp").write_text('{"key": "dead')  # what a kill mid-write leaves
    capsys.readouterr()
    monkeypatch.setattr(ResultStore, "write_run", counted)
    assert main(["benchmark", "--suite", "fast", "--out", str(out), "--workers", "2"]) == 0
    total = len(_run_files(whole))
    assert f"{total} runs, 6 already done, {total - 6} to run" in capsys.readouterr().out
    assert _run_files(out) == _run_files(whole)  # nothing lost
    assert len(keys) == len(set(keys)) == total  # and every run ran once, over both
    assert not list((out / "runs").glob(".*"))
    for name in REPORT:
        assert (out / name).read_bytes() == (whole / name).read_bytes(), name


def test_a_finished_store_resumes_to_nothing_and_summarize_rebuilds_its_report(whole, tmp_path, capsys):
    out = tmp_path / "copy"
    subprocess.run(["cp", "-r", str(whole), str(out)], check=True)
    for name in (*REPORT, "timings.json"):
        (out / name).unlink()
    assert main(["summarize", str(out)]) == 0
    for name in REPORT:
        assert (out / name).read_bytes() == (whole / name).read_bytes(), name
    capsys.readouterr()
    assert main(["benchmark", "--suite", "fast", "--out", str(out), "--workers", "1"]) == 0
    assert "0 to run" in capsys.readouterr().out
    assert (out / "report.md").read_bytes() == (whole / "report.md").read_bytes()


def test_summarize_of_an_unfinished_benchmark_says_how_to_finish_it(whole, tmp_path, capsys):
    out = tmp_path / "part"
    subprocess.run(["cp", "-r", str(whole), str(out)], check=True)
    (out / "report.md").unlink()
    for path in _run_files(out)[:3]:
        (out / "runs" / path).unlink()
    assert main(["summarize", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "runs are not in yet" in err
    assert f"armtransfer benchmark --suite fast --seed 0 --out {out}" in err
    assert not (out / "report.md").exists()


def test_another_seed_is_refused_on_a_store(whole, tmp_path, capsys):
    out = tmp_path / "copy"
    subprocess.run(["cp", "-r", str(whole), str(out)], check=True)
    before = _run_files(out)
    assert main(["benchmark", "--suite", "fast", "--seed", "1", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "holds another sweep ('benchmark-fast')" in err
    assert _run_files(out) == before


def test_a_broken_run_file_is_set_aside_and_redone(whole, tmp_path, capsys):
    out = tmp_path / "copy"
    subprocess.run(["cp", "-r", str(whole), str(out)], check=True)
    store = ResultStore(out)
    trial = next(r for r in store.records() if r["config"]["format"] == benchmark_runs.TRIAL_FORMAT)
    broken = dict(trial, result=dict(trial["result"], first_exposure="many"))
    store.run_path(trial["key"]).write_text(json.dumps(broken))
    assert main(["benchmark", "--suite", "fast", "--out", str(out), "--workers", "1"]) == 0
    assert "has no 'first_exposure' of a trial" in capsys.readouterr().err
    assert store.run_path(trial["key"]).read_bytes() == (whole / "runs" / f"{trial['key']}.json").read_bytes()
    assert (out / "results.json").read_bytes() == (whole / "results.json").read_bytes()


@pytest.mark.parametrize("method, episodes", [("none", 40), ("pseudo", 40), ("guided", 6)])
def test_a_trial_run_alone_is_that_trial_of_the_whole_method(method, episodes):
    coarse, fine = grid_robot("coarse"), grid_robot("fine")
    start, goal = TABLE_I[1].cells()
    traj = experiment.source_trajectory("optimal", coarse, start, goal, LearnerConfig(), 0)
    config = LearnerConfig(max_episodes=episodes)  # guided plans after every episode: a few suffice
    whole = experiment.run_method(method, fine, start, goal, [traj], 3, 5, config, threads=1)
    for k in range(3):
        alone = experiment.run_method(method, fine, start, goal, [traj], 1, 5, config, threads=1, first_trial=k)
        a, b = whole.trials[k], alone.trials[0]
        assert a.exploration_steps == b.exploration_steps and a.total_steps == b.total_steps
        assert np.array_equal(a.episode_steps, b.episode_steps) and a.greedy_path == b.greedy_path
    assert len({t.exploration_steps for t in whole.trials}) > 1  # the trials differ: the check compares something


def test_a_run_names_its_learner_and_another_learner_runs_through_the_store(monkeypatch):
    """A learner given an engine of its own (``engines.BY_LEARNER``) runs its trial runs as the
    built-in one does: the same configuration but for ``learner``, another key, and its result
    goes into the record."""
    from armtransfer.experiments import engines
    from armtransfer.learning.trial_result import TrialResult

    fine = grid_robot("fine")
    args = ("none", 1, "coarse", "fine", [0, 0], [-8, 12], 0.0, 7, LearnerConfig(max_episodes=30), None)
    ours = benchmark_runs.trial_run(*args)
    assert ours.learner == benchmark_runs.LEARNER
    seen = []

    class Other(engines.Engine):
        name = "other"

        def trials(self, work, target, trajectories):
            seen.append((work.method, work.first_trial, work.trials, target.name))
            steps = np.array([12, -12, -12])
            none = np.zeros(0, dtype=np.int64)
            return experiment.MethodResult(work.method, [TrialResult(12, False, None, None, 3, steps, none, none)])

    monkeypatch.setitem(engines.BY_LEARNER, "other", Other())
    theirs = benchmark_runs.trial_run(*args, learner="other")
    assert theirs.key() != ours.key() and {k: v for k, v in theirs.to_dict().items() if k != "learner"} == \
        {k: v for k, v in ours.to_dict().items() if k != "learner"}
    result, _ = benchmark_runs.execute(theirs, {"fine": fine})
    assert seen == [("none", 1, 1, "fine")] and benchmark_runs.result_problem(theirs.to_dict(), result) is None
    assert result["first_exposure"] == 12 and result["episodes"] == 3
    built_in, _ = benchmark_runs.execute(ours, {"fine": fine})
    assert benchmark_runs.result_problem(ours.to_dict(), built_in) is None and built_in["first_exposure"] != 12
    with pytest.raises(ArmTransferError, match="unknown learner 'gone'; valid learners: sarsa, other"):
        benchmark_runs.execute(benchmark_runs.trial_run(*args, learner="gone"), {"fine": fine})


# -- slow: SIGKILL at three moments, and a Ray cluster -------------------------------------------

def _start(argv: list[str], cwd: Path) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-m", "armtransfer.cli", *argv], cwd=cwd, stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL, start_new_session=True)


def _kill_when(proc: subprocess.Popen, ready, timeout: float = 1800) -> None:
    """SIGKILL the driver alone once ``ready()``; its workers must end with it."""
    deadline = time.time() + timeout
    while time.time() < deadline and not ready() and proc.poll() is None:
        time.sleep(0.05)
    assert proc.poll() is None, "the run ended before the moment of its kill"
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait()
    assert settle(proc.pid, 30) == [], "processes outlived the killed benchmark"


@pytest.mark.slow  # the paper suite, whole and then killed three times: minutes on 2 cores
def test_paper_killed_at_three_moments_resumes_to_the_uninterrupted_report(tmp_path):
    whole = tmp_path / "whole"
    assert main(["benchmark", "--suite", "paper", "--out", str(whole), "--workers", "2"]) == 0
    total = len(_run_files(whole))
    out = tmp_path / "killed"
    argv = ["benchmark", "--suite", "paper", "--out", str(out), "--workers", "2"]
    counts = []
    moments = [
        lambda: len(session(proc.pid)) >= 3,  # the workers are starting: no run is in yet
        lambda: len(_run_files(out)) >= counts[-1] + 40,  # robot 1's paths and the first trials
        lambda: len(_run_files(out)) >= total * 2 // 3,  # most trials in
    ]
    for ready in moments:
        counts.append(len(_run_files(out)) if out.exists() else 0)
        proc = _start(argv, tmp_path)
        _kill_when(proc, ready)
    assert counts[0] == 0 and counts[1] < counts[2] < total, counts  # each kill met the run at work
    assert not (out / "report.md").exists()
    last = _start(argv, tmp_path)
    assert last.wait(timeout=1800) == 0
    assert settle(last.pid, 30) == []
    assert _run_files(out) == _run_files(whole)
    for name in ("report.md", "results.json", "survival_paper.png", "learning_curves_paper.png"):
        assert (out / name).read_bytes() == (whole / name).read_bytes(), name


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.mark.slow  # a Ray head node's start-up alone is 10-20 s of CPU
def test_a_ray_cluster_by_address_gives_the_same_bytes(whole, tmp_path, monkeypatch):
    pytest.importorskip("ray")
    ray = Path(sys.executable).with_name("ray")
    port = _free_port()
    temp = tempfile.mkdtemp(prefix="r", dir="/tmp")  # Ray's socket paths must stay short
    # Ray turns token authentication on for a new cluster, with a token file in the user's home
    # that is not this test's to read or write: this local cluster and the command run without
    monkeypatch.setenv("RAY_AUTH_MODE", "disabled")
    started: dict = {}
    head = subprocess.Popen([str(ray), "start", "--head", "--block", f"--port={port}", "--num-cpus=2",
                             "--include-dashboard=false", f"--temp-dir={temp}"],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
    try:
        deadline = time.time() + 180
        while time.time() < deadline:  # the head node answers once its GCS is up
            try:
                socket.create_connection(("127.0.0.1", port), timeout=1).close()
                break
            except OSError:
                time.sleep(0.5)
        started = {pid: start_time(pid) for pid in descendants({head.pid})}  # the head's GCS, raylet, ...
        out = tmp_path / "store"
        code = main(["benchmark", "--suite", "fast", "--out", str(out), "--executor", "ray", "--address",
                     f"127.0.0.1:{port}"])
    finally:
        started.update({pid: start_time(pid) for pid in descendants({head.pid})})
        head.send_signal(signal.SIGTERM)  # --block: the head stops what it started
        try:
            head.wait(timeout=60)
        except subprocess.TimeoutExpired:
            pass
        time.sleep(5)
        left = [pid for pid, t in started.items() if t is not None and start_time(pid) == t]
        for pid in left:  # whatever the head left, and only that, by its pid
            try:
                os.kill(pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
        settle(head.pid, 10)
        shutil.rmtree(temp, ignore_errors=True)
    assert code == 0 and left == [], left
    assert _run_files(out) == _run_files(whole)
    for name in REPORT:
        assert (out / name).read_bytes() == (whole / name).read_bytes(), name


class _InlineRay:
    """Ray's calls that ``run_ray`` makes, done in this process: enough to see which robots a
    task is handed, without starting Ray."""

    def is_initialized(self):
        return True

    def put(self, value):
        return ("ref", value)

    def remote(self, **options):
        def wrap(f):
            def call(run, robots, fn):
                return ("done", f(run, {key: ref[1] for key, ref in dict.items(robots)}, fn))
            return types.SimpleNamespace(remote=call)
        return wrap

    def wait(self, pending, num_returns=1):
        return pending[:num_returns], pending[num_returns:]

    def get(self, ref):
        return ref[1]

    def shutdown(self):
        pass


def test_ray_tasks_get_the_robots_of_a_case_in_another_world(monkeypatch):
    """A benchmark's robots are keyed by spec in their world ('coarse in rooms11'); a Ray task
    of such a run is handed them (it used to look them up by the bare spec, a KeyError)."""
    from armtransfer.parallel import executors

    monkeypatch.setattr(executors, "import_ray", lambda: _InlineRay())
    robots = {"coarse in rooms11": grid_robot("coarse"), "fine in rooms11": grid_robot("fine"),
              "fine": grid_robot("fine")}
    runs = [types.SimpleNamespace(source="coarse", target="fine", world="rooms11", key=lambda: "k0")]
    seen, failed = [], []

    def fn(run, handed):
        return tuple(sorted(handed)), 0.0

    executors.run_ray(runs, robots, 1, None, lambda run, result, secs: seen.append(result),
                      lambda run, why, tries: failed.append(why), fn=fn)
    assert failed == [] and seen == [("coarse in rooms11", "fine", "fine in rooms11")]
