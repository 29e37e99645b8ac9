"""Sweeps: resume after kill -9, idempotent re-runs, identical summaries, crashes, errors."""

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from armtransfer.cli import main
from armtransfer.experiments.execute import execute
from armtransfer.parallel.executors import run_local
from armtransfer.tasks.grid_robots import grid_robot
from armtransfer.experiments import sweep as sweeps
from armtransfer.experiments.store import ResultStore
from armtransfer.experiments.reports.summary import summarize

SWEEP = """
[sweep]
name = "test"
tasks = [1, 2]
pairs = [["coarse", "fine"], ["fine", "coarse"]]
methods = ["none", "pseudo"]
seeds = [0, 1]
trials = 2
patience = 5
"""


@pytest.fixture
def sweep_file(tmp_path):
    path = tmp_path / "s.toml"
    path.write_text(SWEEP)
    return path


def summary_rows(out):
    return summarize(ResultStore.open_existing(out).records())


def test_grid_expands_to_every_combination_and_none_ignores_k(tmp_path):
    path = tmp_path / "k.toml"
    path.write_text(SWEEP.replace('trials = 2', 'trials = 2\nK = ["auto", 0.01]'))
    sw = sweeps.load(path)
    # 2 tasks x 2 pairs x 2 seeds x (none + pseudo x 2 K)
    assert len(sw.runs) == 2 * 2 * 2 * 3
    assert len({r.key() for r in sw.runs}) == len(sw.runs)


def test_sweep_runs_then_rerun_is_idempotent(sweep_file, tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["sweep", str(sweep_file), "--out", str(out), "--workers", "2"]) == 0
    files = sorted((out / "runs").glob("*.json"))
    assert len(files) == 16
    before = {f.name: f.read_bytes() for f in files}
    assert main(["sweep", str(sweep_file), "--out", str(out), "--workers", "2"]) == 0
    assert "16 already done, 0 to run" in capsys.readouterr().out
    assert {f.name: f.read_bytes() for f in sorted((out / "runs").glob("*.json"))} == before
    assert main(["summarize", str(out)]) == 0
    data = json.loads((out / "summary.json").read_text())
    assert data["runs"] == 16 and len(data["rows"]) == 8
    assert (out / "summary.png").stat().st_size > 0
    pseudo = [r for r in data["rows"] if r["method"] == "pseudo"]
    assert all(r["trials"] == 4 and r["improvement_percent"] is not None for r in pseudo)


def test_kill_9_mid_sweep_then_resume_gives_the_uninterrupted_summary(sweep_file, tmp_path):
    whole = tmp_path / "whole"
    assert main(["sweep", str(sweep_file), "--out", str(whole), "--workers", "1"]) == 0
    out = tmp_path / "killed"
    proc = subprocess.Popen(
        [sys.executable, "-m", "armtransfer.cli", "sweep", str(sweep_file), "--out", str(out), "--workers", "1"],
        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True,
    )
    deadline = time.time() + 120
    while time.time() < deadline and len(list((out / "runs").glob("*.json"))) < 3:
        time.sleep(0.05)
    os.killpg(proc.pid, signal.SIGKILL)  # the driver and its workers, mid-sweep
    proc.wait()
    done = sorted((out / "runs").glob("*.json"))
    assert 3 <= len(done) < 16, "the kill should land mid-sweep"
    for f in done:  # everything that finished is whole
        assert json.loads(f.read_text())["result"]["exploration_steps"]
    assert main(["sweep", str(sweep_file), "--out", str(out), "--workers", "2"]) == 0
    assert len(list((out / "runs").glob("*.json"))) == 16
    assert not list((out / "runs").glob(".*"))  # no temporary file left behind
    assert summary_rows(out) == summary_rows(whole)


def crash_once(run, robots):
    """A worker that dies (SIGKILL) the first time it meets a run, then works."""
    marker = Path(os.environ["CRASH_DIR"]) / run.key()
    if not marker.exists():
        marker.write_text("x")
        os.kill(os.getpid(), signal.SIGKILL)
    return execute(run, robots)


def crash_always(run, robots):
    os.kill(os.getpid(), signal.SIGKILL)


@pytest.mark.parametrize("fn,expect_failed", [(crash_once, 0),
                                              pytest.param(crash_always, 2, marks=pytest.mark.slow)])
def test_killed_workers_are_retried_or_reported_never_lost(tmp_path, monkeypatch, fn, expect_failed):
    monkeypatch.setenv("CRASH_DIR", str(tmp_path))
    sw_path = tmp_path / "s.toml"
    sw_path.write_text(SWEEP.replace("tasks = [1, 2]", "tasks = [1]").replace(
        'pairs = [["coarse", "fine"], ["fine", "coarse"]]', 'pairs = [["coarse", "fine"]]').replace(
        "seeds = [0, 1]", "seeds = [0]"))
    runs = list(sweeps.load(sw_path).runs)
    robots = {"coarse": grid_robot("coarse"), "fine": grid_robot("fine")}
    done, failed = [], []
    run_local(runs, robots, 2, lambda r, res, s: done.append(r.key()),
              lambda r, err, n: failed.append((r.key(), err, n)), retries=1, fn=fn)
    assert len(done) + len(failed) == len(runs) == 2
    assert len(failed) == expect_failed
    for _, err, attempts in failed:
        assert "died" in err and attempts == 2


SWEEP_ERRORS = [
    ("[sweep\nname=", "not valid TOML"),
    ("[sweep]\ntasks = [1]\ncolour = 'red'", "unknown key 'colour'; valid keys:"),
    ("[sweep]\ntasks = [9]", "unknown task 9"),
    ("[sweep]\ntasks = [1]\nmethods = ['magic']", "unknown method 'magic'"),
    ("[sweep]\ntasks = [1]\nwind = [3]", "wind: must be a number in [0, 1]"),
    ("[sweep]\ntasks = [1]\ntrials = 0", "trials: must be an integer"),
    ("[other]\ntasks = [1]", "unknown table 'other'"),
    ("[sweep]\nname = 'x'", "give tasks or start_goal"),
    ("[sweep]\nstart_goal = [['0,0', 'a']]", "two integers"),
]


@pytest.mark.parametrize("text,message", SWEEP_ERRORS, ids=[m for _, m in SWEEP_ERRORS])
def test_malformed_sweep_files_are_one_line_errors(tmp_path, capsys, text, message):
    path = tmp_path / "bad.toml"
    path.write_text(text)
    assert main(["sweep", str(path), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1, err
    assert not (tmp_path / "o").exists()


def test_an_output_directory_holding_another_sweep_is_refused(sweep_file, tmp_path, capsys):
    out = tmp_path / "out"
    other = tmp_path / "other.toml"
    other.write_text(SWEEP.replace('name = "test"', 'name = "other"').replace("seeds = [0, 1]", "seeds = [0]")
                     .replace("tasks = [1, 2]", "tasks = [1]"))
    assert main(["sweep", str(other), "--out", str(out), "--workers", "1"]) == 0
    capsys.readouterr()
    assert main(["sweep", str(sweep_file), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "holds another sweep ('other')" in err and len(err.strip().splitlines()) == 1
    assert main(["summarize", str(tmp_path)]) == 2
    assert "holds no sweep" in capsys.readouterr().err


@pytest.mark.slow  # Ray's start-up alone is 10-20 s of CPU
def test_ray_executor_matches_the_local_executor(sweep_file, tmp_path):
    ray = pytest.importorskip("ray")
    local, remote = tmp_path / "local", tmp_path / "ray"
    assert main(["sweep", str(sweep_file), "--out", str(local), "--workers", "2"]) == 0
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False, configure_logging=False)
    try:
        assert main(["sweep", str(sweep_file), "--out", str(remote), "--executor", "ray"]) == 0
    finally:
        ray.shutdown()
    for f in sorted((local / "runs").glob("*.json")):
        a = json.loads(f.read_text())
        b = json.loads((remote / "runs" / f.name).read_text())
        assert a["result"] == b["result"] and a["config"] == b["config"]


def test_ray_executor_without_ray_says_how_to_install_it(sweep_file, tmp_path, capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "ray", None)  # as if Ray were not installed
    assert main(["sweep", str(sweep_file), "--out", str(tmp_path / "o"), "--executor", "ray"]) == 2
    err = capsys.readouterr().err
    assert 'pip install -e ".[cluster]"' in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize("path", sorted((Path(__file__).resolve().parents[1] / "examples" / "sweeps").glob("*.toml")),
                         ids=lambda p: p.name)
def test_every_example_sweep_file_is_valid(path):
    sw = sweeps.load(path)
    assert sw.runs and len({r.key() for r in sw.runs}) == len(sw.runs)
    if path.name == "paper.toml":  # the paper's whole protocol: 4 tasks x 2 directions x 2 winds
        assert {r.task for r in sw.runs} == {1, 2, 3, 4}
        assert {(r.source, r.target) for r in sw.runs} == {("coarse", "fine"), ("fine", "coarse")}
        assert {r.wind for r in sw.runs} == {0.0, 0.01}
