"""Suite files (``armtransfer benchmark --suite FILE``): the built-in suites are such files and
keep their definitions' bytes; a user's suite on a layout world runs, resumes and is summarized
back byte for byte; every bad key, world, robot or cell is one line; a run that fails keeps its
traceback and the report is written from the others; a learner's options are in its runs' keys;
a potential of one's own says what the bound did to it."""

from __future__ import annotations

import hashlib
import json
import shutil
from pathlib import Path

import numpy as np
import pytest

from armtransfer.cli import main
from armtransfer.experiments import benchmark, benchmark_runs, suite_files, suites
from armtransfer.experiments.store import ResultStore
from contract import refused

ROOT = Path(__file__).resolve().parents[1]
ZIGZAG = ROOT / "examples" / "worlds" / "zigzag.toml"

BUILT_IN = {"paper": "f7783f5b8b31ab32", "random": "d174ee2f40cca3af", "embodiment": "08b843d26432acf1",
            "wind": "2b4c9d6f8deeebf5", "standard": "5c59679a971e94fa", "dev": "7aba0e0c4f1952b9",
            "fast": "e2b80724a18642e2", "small": "fc9172b658a571eb", "voxels": "cb6e96905ba8a87e"}
"""sha256 of ``json.dumps(suite.to_dict())`` of each built-in suite, but for its ``methods`` (the
build's ``suites.METHODS``, not the file's), as the Python definitions made it before the suites
became files: a store's key and every run's follow from these bytes."""


def test_the_built_in_suites_are_files_with_the_bytes_they_had():
    def digest(suite):
        return hashlib.sha256(json.dumps({k: v for k, v in suite.to_dict().items() if k != "methods"}).encode())

    assert {n: digest(s).hexdigest()[:16] for n, s in suites.SUITES.items()} == BUILT_IN
    for name, suite in suites.SUITES.items():
        assert (suite_files.DATA / f"{name}.toml").is_file() and suite.to_dict()["methods"] == list(suites.METHODS)
        again = suite_files.from_dict(json.loads(json.dumps(suite.to_dict())), name)
        assert again.to_dict() == suite.to_dict() and suites.is_builtin(again)


def write_suite(tmp_path: Path, body: str) -> Path:
    shutil.copy(ZIGZAG, tmp_path / "zigzag.toml")
    path = tmp_path / "mine.toml"
    path.write_text('name = "mine"\nworld = "zigzag.toml"\nmethods = ["pseudo"]\nsource_seeds = 1\ntrials = 1\n'
                    'max_total_steps = 5_000\n' + body)
    return path


CASE = '[[cases]]\nsource = "coarse"\ntarget = "fine"\ntask = 1\n'


def test_a_suite_file_carries_its_world_by_content(tmp_path):
    suite = suite_files.load(write_suite(tmp_path, CASE))
    case = suite.sections[0].cases[0]
    assert case.world.startswith("zigzag#") and list(suite.worlds) == [case.world]
    assert suite.methods == ("pseudo",) and suite.sections[0].methods == ("pseudo",)
    assert suite_files.from_dict(json.loads(json.dumps(suite.to_dict())), "x").to_dict() == suite.to_dict()
    (tmp_path / "zigzag.toml").write_text(ZIGZAG.read_text().replace("goal = [6, -6]", "goal = [4, -6]"))
    other = suite_files.load(tmp_path / "mine.toml")  # another layout: another world id, so other run keys
    assert other.sections[0].cases[0].world != case.world


@pytest.mark.parametrize("body, said", [
    (CASE + "colour = 1\n", "unknown key 'colour'"),
    (CASE.replace('"fine"', '"finer"'), "unknown robot 'finer'"),
    (CASE.replace('"fine"', '"planar3:teleport"'), "action model 'teleport'"),
    (CASE.replace("task = 1", "task = 9"), "unknown task '9'"),
    (CASE.replace("task = 1", "start = [20, 0]\ngoal = [6, -6]"), "(20,0) is off the grid"),
    (CASE.replace("task = 1", "start = [-6, 6]\ngoal = [0, 2]"), "wall"),
    (CASE.replace("task = 1", "start = [-6, 6]"), "both start and goal"),
    (CASE + 'world = "nowhere.toml"\n', "no such file"),
    (CASE.replace("[[cases]]", "[[cases]]\nwind = 2"), "wind must be a number in [0, 1)"),
    ("", "has no case"),
])
def test_every_bad_suite_file_is_one_line(tmp_path, monkeypatch, capsys, body, said):
    path = write_suite(tmp_path, body)
    err = refused(["benchmark", "--suite", str(path), "--out", str(tmp_path / "out")], tmp_path, monkeypatch, capsys)
    assert said in err and ("mine.toml" in err or "mine" in err), err


def test_a_bad_method_or_name_and_world_with_a_suite_are_one_line(tmp_path, monkeypatch, capsys):
    path = write_suite(tmp_path, CASE)
    path.write_text(path.read_text().replace('["pseudo"]', '["psuedo"]'))
    assert "unknown method 'psuedo'" in refused(["benchmark", "--suite", str(path)], tmp_path, monkeypatch, capsys)
    path.write_text(path.read_text().replace('["psuedo"]', '["pseudo"]').replace('"mine"', '"fast"'))
    assert "built-in suite" in refused(["benchmark", "--suite", str(path)], tmp_path, monkeypatch, capsys)
    err = refused(["benchmark", "--suite", "small", "--world", "rooms11"], tmp_path, monkeypatch, capsys)
    assert "rooms11, rooms15" in err and "suite file" in err


def test_a_suite_file_runs_resumes_and_is_summarized_byte_for_byte(tmp_path, capsys):
    path = write_suite(tmp_path, CASE + '\n[[cases]]\nsource = "fine"\ntarget = "coarse"\nstart = [6, 6]\n'
                       'goal = [-6, -6]\n')
    out = tmp_path / "store"
    assert main(["benchmark", "--suite", str(path), "--out", str(out), "--workers", "1"]) == 0
    report, results = (out / "report.md").read_bytes(), (out / "results.json").read_bytes()
    assert b"--suite FILE" in report and b"`zigzag`" in report and b"(6,6) -> (-6,-6)" in report
    data = json.loads(results)
    # pseudo beside its goal-only baseline (goal-dense) and none, on 2 cases
    assert {r["method"] for r in data["records"]} == {"none", "pseudo", "goal-dense"} and len(data["records"]) == 6
    # a run lost (as a kill loses the runs under way) is run again by the same command
    store = ResultStore.open_existing(out)
    lost = sorted(store.runs_dir.glob("*.json"))[-1]
    lost.unlink()
    capsys.readouterr()
    assert main(["benchmark", "--suite", str(path), "--out", str(out), "--workers", "1"]) == 0
    assert "1 to run" in capsys.readouterr().out
    assert (out / "report.md").read_bytes() == report and (out / "results.json").read_bytes() == results
    (out / "report.md").unlink()
    (tmp_path / "zigzag.toml").unlink()  # summarize needs no file: the suite carries its world
    assert main(["summarize", str(out)]) == 0
    assert (out / "report.md").read_bytes() == report and (out / "results.json").read_bytes() == results
    assert main(["summarize", str(out / "results.json"), "--out", str(tmp_path / "again")]) == 0
    assert (tmp_path / "again" / "report.md").read_bytes() == report


def test_a_failed_run_keeps_its_traceback_and_the_report_lists_it(tmp_path):
    suite = suite_files.parse({"name": "tiny", "world": "rooms11", "methods": ["pseudo"], "source_seeds": 2,
                               "trials": 1, "max_total_steps": 5_000,
                               "cases": [{"source": "coarse", "target": "fine", "task": 2}]}, "test")
    robots = benchmark.Robots({})
    plan = benchmark.plan(suite, 0, robots, *benchmark.methods_to_run(suite.methods))
    store = ResultStore.open_for(tmp_path / "s", benchmark_runs_sweep(plan))
    broken = None
    for pair in plan.pairs:
        src = pair.source_run()
        result, secs = benchmark_runs.execute(src, robots.resolved)
        store.write_run(src, result, secs)
        for run in plan.all_trial_runs(pair, result):
            if pair.source_seed == 1 and run.method == "pseudo":
                with pytest.raises(benchmark_runs.RunFailed) as caught:
                    benchmark_runs.execute_recorded(run, {})  # no robots: a KeyError in the worker
                broken = run
                store.write_failure(run, str(caught.value), 1)
            else:
                store.write_run(run, *benchmark_runs.execute(run, robots.resolved))
    store.unlock()
    failed = json.loads((store.failed_dir / f"{broken.key()}.json").read_text())
    assert failed["error"].startswith("KeyError") and "Traceback" in failed["traceback"]
    assert "in execute" in failed["traceback"]
    from armtransfer.commands.benchmark import write_report

    write_report(store, plan)
    data = json.loads((tmp_path / "s" / "results.json").read_text())
    assert [(f["method"], f["source_seed"]) for f in data["failed"]] == [("pseudo", 1)]
    assert [(r["method"], r["source_seed"]) for r in data["records"]] == [
        ("none", 0), ("pseudo", 0), ("goal-dense", 0), ("none", 1), ("goal-dense", 1)]
    report = (tmp_path / "s" / "report.md").read_text()
    assert "## Runs that failed" in report and "KeyError" in report


def benchmark_runs_sweep(plan):
    from armtransfer.experiments.sweep import Sweep

    return Sweep(plan.name, plan.spec(), ())


def test_a_learners_options_are_in_its_runs_keys():
    run = dict(method="none", trial=0, source="coarse", target="fine", start=[0, 0], goal=[2, 2], wind=0.0, seed=1,
               config=benchmark.SOURCE_CONFIG, source_result=None, learner="q")
    plain = benchmark_runs.trial_run(**run)
    a = benchmark_runs.trial_run(**run, learner_options={"alpha": 0.5})
    b = benchmark_runs.trial_run(**run, learner_options={"alpha": 0.25})
    assert len({plain.key(), a.key(), b.key()}) == 3 and a.learner_options == {"alpha": 0.5}
    assert "learner_options" not in plain.to_dict()  # a learner without options keeps the keys it had


def test_a_potential_of_ones_own_says_what_the_bound_did_to_it():
    from armtransfer.learning import methods
    from armtransfer.learning.plugins import potential_method
    from armtransfer.learning.potentials import bound
    from armtransfer.tasks.grid_robots import grid_robot
    from armtransfer.tasks.catalog import table_task
    from armtransfer.learning.trajectory import Trajectory

    assert bound(0.99, -1.0) == pytest.approx(35.0)
    robot = grid_robot("fine")
    start, goal = table_task(1).cells()
    traj = Trajectory((start,), (0,), goal)
    said = {}
    for name, fn in (("steps", lambda c, t: -np.abs(c - t[-1]).sum(axis=1).astype(float)),
                     ("scaled", lambda c, t: -1e9 * np.abs(c - t[-1]).sum(axis=1)),
                     ("flat", lambda c, t: np.full(len(c), -3.0)),
                     ("offset", lambda c, t: 1000.0 - np.abs(c - t[-1]).sum(axis=1) / 1e3)):
        m = potential_method(name, "a test potential", fn)
        try:
            methods.METHODS[name] = m
            said[name] = methods.build_shaping(name, robot, [traj], 1.0, -1.0).notes
        finally:
            del methods.METHODS[name]
    assert any("below -B = -35" in n for n in said["steps"])  # most of the 51x51 rooms lie over 35 steps away
    assert any("below -B = -35 on 100%" in n for n in said["scaled"])
    assert any("on every one" in n for n in said["flat"]) and any("not 0, at the goal" in n for n in said["flat"])
    assert any("1000, not 0, at the goal" in n for n in said["offset"])
    assert not methods.build_shaping("dense", robot, [traj], "auto", -1.0).notes  # the built-in ones say nothing


@pytest.mark.slow  # examples/suites/zigzag.toml whole, then killed and resumed: about a minute on 2 cores
def test_a_suite_file_killed_by_sigkill_resumes_to_the_uninterrupted_report(tmp_path):
    import os
    import signal
    import subprocess
    import sys
    import time

    from contract import settle

    suite = ROOT / "examples" / "suites" / "zigzag.toml"
    whole, out = tmp_path / "whole", tmp_path / "killed"
    assert main(["benchmark", "--suite", str(suite), "--out", str(whole), "--workers", "2"]) == 0
    argv = [sys.executable, "-m", "armtransfer.cli", "benchmark", "--suite", str(suite), "--out", str(out),
            "--workers", "2"]
    proc = subprocess.Popen(argv, cwd=tmp_path, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                            start_new_session=True)
    deadline = time.time() + 600
    while time.time() < deadline and proc.poll() is None and len(list(out.glob("runs/*.json"))) < 8:
        time.sleep(0.05)
    assert proc.poll() is None, "the run ended before its kill"
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait()
    assert settle(proc.pid, 30) == [], "processes outlived the killed benchmark"
    assert not (out / "report.md").exists()
    last = subprocess.Popen(argv, cwd=tmp_path, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                            start_new_session=True)
    assert last.wait(timeout=600) == 0 and settle(last.pid, 30) == []
    for name in ("report.md", "results.json"):
        assert (out / name).read_bytes() == (whole / name).read_bytes(), name
    (out / "report.md").unlink()
    assert main(["summarize", str(out)]) == 0
    assert (out / "report.md").read_bytes() == (whole / "report.md").read_bytes()


class _Seen:
    """A learner that records what ``make`` is handed and steps at random."""

    seen: list = []

    def __init__(self, env, seed, transfer=None):
        self.env, self.rng, self.obs = env, np.random.default_rng(seed), None
        _Seen.seen.append(transfer)

    def learn(self, total_timesteps):
        for _ in range(total_timesteps):
            if self.obs is None:
                self.obs, _ = self.env.reset()
            self.obs, _, done, cut, _ = self.env.step(int(self.rng.integers(self.env.action_space.n)))
            if done or cut:
                self.obs = None
        return self

    def predict(self, observation, deterministic=True):
        return 0, None


@pytest.fixture
def seen_learner():
    import armtransfer
    from armtransfer.learning.learners import LEARNERS

    _Seen.seen = []
    learner = armtransfer.register_learner(armtransfer.Learner("seen", "records its transfer", _Seen,
                                                               options={"alpha": 0.5}, transfer=True), replace=True)
    yield learner
    del LEARNERS["seen"]


def test_a_learner_receives_the_transfer_and_its_options_key_its_runs(seen_learner, capsys):
    suite = suite_files.parse({"name": "tiny", "world": "rooms11", "methods": ["pseudo"], "source_seeds": 1,
                               "trials": 1, "max_total_steps": 400, "learners": ["seen"],
                               "cases": [{"source": "coarse", "target": "fine", "task": 2}]}, "test")
    plan = benchmark.plan(suite, 0, None, *benchmark.methods_to_run(suite.methods))
    runs = plan.all_trial_runs(plan.pairs[0], None)  # those that wait for no trajectory: none's
    assert [r.method for r in runs] == ["none"] and runs[0].learner_options == {"alpha": 0.5}
    records, _ = benchmark.run_suite(suite, 0, learners=["seen"])
    assert {r["method"] for r in records} == {"none@seen", "pseudo@seen", "goal-dense@seen"}
    shaped = [t for t in _Seen.seen if t.method == "pseudo"]
    assert shaped and all(len(t.trajectories) == 1 and t.trajectories[0].shape[1] == 2 for t in shaped)
    assert all(t.shaping is not None and len(t.shaping.bonus) > 0 for t in shaped)
    plain = [t for t in _Seen.seen if t.method == "none"]
    assert plain and all(t.shaping is None and t.trajectories == () for t in plain)
    assert main(["bench", "--learner", "seen", "--steps", "300", "--repeats", "1"]) == 0
    assert "learner seen: median" in capsys.readouterr().out


def test_a_sweeps_learner_options_key_its_runs_and_its_store(seen_learner):
    from dataclasses import replace

    from armtransfer.experiments import sweep
    from armtransfer.learning.learners import LEARNERS

    raw = {"sweep": {"name": "o", "world": "rooms11", "tasks": ["1"], "pairs": [["coarse", "fine"]],
                     "methods": ["none"], "learner": ["sarsa", "seen"], "max_total_steps": 400, "trials": 1,
                     "trajectory": "optimal"}}
    spec = sweep.normalise(raw)
    assert spec["learner_options"] == {"seen": {"alpha": 0.5}}
    runs = sweep.expand(spec)
    assert [r.learner_options for r in runs] == [None, {"alpha": 0.5}]  # sarsa's run keeps its key
    stored = json.loads(json.dumps(spec))
    assert sweep.check_stored(stored, "store") == stored
    LEARNERS["seen"] = replace(LEARNERS["seen"], options={"alpha": 0.25})
    with pytest.raises(sweep.SweepFileError, match=r"had the options \{'seen': \{'alpha': 0.5\}\}"):
        sweep.check_stored(stored, "store")
    assert [r.learner_options for r in sweep.expand(sweep.normalise(raw))] == [None, {"alpha": 0.25}]


def test_an_unreachable_goal_behind_a_door_on_an_odd_cell_names_the_even_cell_rule(tmp_path, monkeypatch, capsys):
    world = tmp_path / "odd.toml"
    world.write_text('name = "odd"\ngrid = """\n.......\n.......\n.......\n##D####\n.......\n.......\n.......\n"""\n'
                     '[tasks]\n1 = { start = [0, 2], goal = [0, -2] }\n')
    err = refused(["rooms", "--world", str(world), "--trials", "1"], tmp_path, monkeypatch, capsys)
    assert "robot coarse cannot reach the goal" in err and "door at (-1, 0) is on an odd cell" in err
    assert "docs/worlds.md" in err
