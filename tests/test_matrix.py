"""The cross-embodiment matrix: one command, every ordered pair, resumable, local = Ray."""

import json
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

from armtransfer.cli import main
from armtransfer.experiments import matrix

ARGS = ["--robots", "coarse,fine", "--tasks", "1,2", "--methods", "pseudo", "--trials", "2"]


def _cells(out):
    return json.loads((out / "matrix.json").read_text())["cells"]


def test_matrix_runs_every_ordered_pair_and_writes_the_heatmap(tmp_path, capsys):
    out = tmp_path / "m"
    assert main(["matrix", *ARGS, "--out", str(out), "--workers", "2"]) == 0
    # 2 robots -> 4 ordered pairs (each to itself too) x 2 tasks x (none, pseudo)
    assert len(list((out / "runs").glob("*.json"))) == 16
    cells = _cells(out)
    assert {(c["source"], c["target"]) for c in cells} == {("coarse", "coarse"), ("coarse", "fine"),
                                                          ("fine", "coarse"), ("fine", "fine")}
    for c in cells:
        assert c["tasks"] == 2 and c["trials"] == 4
        lo, hi = c["ci95"]
        assert lo <= c["improvement"] <= hi
    png = (out / "matrix.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 5000
    text = (out / "matrix.md").read_text()
    assert "| source \\ target | coarse" in text and "interpolation" in text
    printed = capsys.readouterr().out
    assert "16 of 16 runs finished" in printed
    # summarize on a matrix store draws the same matrix
    before = (out / "matrix.json").read_bytes()
    (out / "matrix.json").unlink()
    assert main(["summarize", str(out)]) == 0
    assert (out / "matrix.json").read_bytes() == before


def test_improvement_is_the_pooled_ratio_and_unreached_trials_count_at_the_cap():
    def rec(source, target, method, task, steps):
        return {"config": {"source": source, "target": target, "method": method, "task": task,
                           "start": [0, 0], "goal": [task, 0]}, "result": {"exploration_steps": steps}}

    records = [rec("a", "b", "none", 1, [100, 100]), rec("a", "b", "none", 2, [300, 300]),
               rec("a", "b", "pseudo", 1, [50, 50]), rec("a", "b", "pseudo", 2, [150, 150])]
    (cell,) = matrix.cells(records, cap=1000)
    assert cell.improvement == pytest.approx(50.0)
    assert cell.ci95 == pytest.approx((50.0, 50.0))
    records[2] = rec("a", "b", "pseudo", 1, [None, 50])
    (cell,) = matrix.cells(records, cap=1000)
    # (525 + 150) / (100 + 300): worse than none, because the unreached trial counts at the cap
    assert cell.improvement == pytest.approx(100 * (1 - 675 / 400))
    assert cell.reached == 3 and cell.trials == 4


def test_families_group_interpolation_against_extrapolation():
    assert matrix.family("coarse") == matrix.family("fine") == "grid"
    assert matrix.family("planar2:joint") == matrix.family("planar4:cartesian") == "planar"
    assert matrix.family("ur5e_like:cartesian") == "spatial"
    cells = [matrix.Cell("coarse", "fine", "pseudo", 40.0, (30.0, 50.0), 1, 2, 2),
             matrix.Cell("coarse", "planar2:joint", "pseudo", 10.0, (0.0, 20.0), 1, 2, 2),
             matrix.Cell("fine", "planar2:joint", "pseudo", -900.0, (-1200.0, -600.0), 1, 2, 2),
             matrix.Cell("fine", "planar3:joint", "pseudo", 30.0, (20.0, 40.0), 1, 2, 2),
             matrix.Cell("fine", "fine", "pseudo", 20.0, (10.0, 30.0), 1, 2, 2)]
    rows = {r["group"]: r for r in matrix.family_rows(cells)}
    assert rows["within family"]["median_improvement"] == 40.0 and rows["within family"]["pairs"] == 1
    across = rows["across families"]
    # the median is not dragged to -287% by one failed pair; helped/hurt count the CIs
    assert across["pairs"] == 3 and across["median_improvement"] == 10.0
    assert across["helped"] == 1 and across["hurt"] == 1
    assert rows["self"]["median_improvement"] == 20.0


@pytest.mark.parametrize("args,message", [
    (["--robots", "coarse"], "at least two robots"),
    (["--robots", "coarse,coarse"], "each robot once"),
    (["--robots", "coarse,fine", "--methods", "none"], "a transfer method beside 'none'"),
    (["--robots", "coarse,fine", "--methods", "nope"], "unknown method 'nope'"),
    (["--robots", "coarse,fine", "--tasks", "9"], "unknown task 9"),
    (["--robots", "coarse,fine", "--tasks", "x"], "tasks are numbers or ranges"),
])
def test_bad_matrix_input_is_one_line_and_writes_nothing(tmp_path, capsys, args, message):
    out = tmp_path / "m"
    try:
        code = main(["matrix", *args, "--out", str(out)])
    except SystemExit as exc:  # argparse's own usage errors
        code = exc.code
    assert code == 2
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1
    assert not out.exists()


@pytest.mark.slow  # the store's resume after SIGKILL runs by default in test_sweep's kill -9 test
def test_sigkill_mid_matrix_then_resume_gives_the_same_matrix(tmp_path):
    whole = tmp_path / "whole"
    assert main(["matrix", *ARGS, "--out", str(whole), "--workers", "1"]) == 0
    out = tmp_path / "killed"
    proc = subprocess.Popen([sys.executable, "-m", "armtransfer.cli", "matrix", *ARGS, "--out", str(out),
                             "--workers", "1"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                            start_new_session=True)
    deadline = time.time() + 120
    while time.time() < deadline and len(list((out / "runs").glob("*.json"))) < 3:
        time.sleep(0.05)
    os.killpg(proc.pid, signal.SIGKILL)
    proc.wait()
    assert 3 <= len(list((out / "runs").glob("*.json"))) < 16, "the kill should land mid-matrix"
    assert not (out / "matrix.json").exists()
    assert main(["matrix", *ARGS, "--out", str(out), "--workers", "2"]) == 0
    assert (out / "matrix.md").read_text() == (whole / "matrix.md").read_text()
    assert _cells(out) == _cells(whole)


@pytest.mark.slow  # Ray against the local pool runs by default in test_sweep
def test_ray_executor_gives_the_same_matrix(tmp_path):
    ray = pytest.importorskip("ray")
    local, remote = tmp_path / "local", tmp_path / "ray"
    assert main(["matrix", *ARGS, "--out", str(local), "--workers", "2"]) == 0
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False, configure_logging=False)
    try:
        assert main(["matrix", *ARGS, "--out", str(remote), "--executor", "ray"]) == 0
    finally:
        ray.shutdown()
    assert _cells(local) == _cells(remote)
    assert np.isfinite([c["improvement"] for c in _cells(local)]).all()
