"""`armtransfer arms`: the end-to-end arm-to-arm transfer, its outputs and its bad input."""

import json
import subprocess
import sys
from pathlib import Path

import imageio.v3 as iio
import pytest

from armtransfer.cli import main

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def fast_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("arms") / "run"
    code = main(["arms", "--fast", "--out", str(out), "--seed", "3"])
    return code, out


@pytest.mark.rendering
def test_fast_mode_writes_every_output_file(fast_run):
    code, out = fast_run
    assert code == 0
    names = sorted(p.name for p in out.iterdir())
    assert names == ["learning_curves.png", "map.png", "results.json", "rollout.mp4", "table.md", "timings.json"]
    data = json.loads((out / "results.json").read_text())
    assert data["source"] == "planar2:joint" and data["target"] == "ur5e_like:cartesian"
    assert set(data["results"]) == {"none", "pseudo", "dense"}
    assert all(len(r["exploration_steps"]) == 2 for r in data["results"].values())
    rollout = data["rollout"]
    assert rollout["panels"] == 2 and rollout["frames"] > 10
    frames = iio.imread(out / "rollout.mp4")
    assert len(frames) == rollout["frames"]
    for rp in rollout["replays"]:
        assert rp["reached_goal"] and rp["max_deviation_cells"] < 1.0
    assert "| pseudo" in (out / "table.md").read_text()
    for png in ("learning_curves.png", "map.png"):
        assert (out / png).read_bytes()[:4] == b"\x89PNG"
    assert not list(out.parent.glob(".*.tmp"))  # the temporary directory was renamed away


@pytest.mark.rendering
def test_same_seed_same_results_byte_for_byte(fast_run, tmp_path):
    """Timings and temporary paths stay out of results.json, so a re-run gives the same bytes
    (but for the output directory it names as the video's place)."""
    code, out = fast_run
    again = tmp_path / "again"
    assert main(["arms", "--fast", "--out", str(again), "--seed", "3", "--json", str(tmp_path / "r.json")]) == 0
    first = (out / "results.json").read_text().replace(str(out), "OUT")
    assert first == (again / "results.json").read_text().replace(str(again), "OUT")
    assert (tmp_path / "r.json").read_bytes() == (again / "results.json").read_bytes()
    data = json.loads((again / "results.json").read_text())
    assert data["rollout"]["video"] == str(again / "rollout.mp4") and Path(data["rollout"]["video"]).is_file()
    assert data["arms"]["target"]["mount_source"] == "built-in" and data["arms"]["target"]["dof"] == 6
    assert json.loads((again / "timings.json").read_text())["rollout"]["seconds"] > 0


def test_the_demo_script_has_a_fast_mode(tmp_path):
    proc = subprocess.run([sys.executable, str(ROOT / "scripts" / "transfer_arms.py"), "--fast", "--no-video",
                           "--out", str(tmp_path / "demo"), "--method", "none", "pseudo"],
                          capture_output=True, text=True, timeout=600, cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert (tmp_path / "demo" / "results.json").exists()


BAD = [
    (["--source", "octopus:joint"], "unknown arm 'octopus'; valid arms:"),
    (["--target", "ur5e_like:polar"], "unknown action model 'polar'"),
    (["--source", "custom"], "needs --arm-xml"),
    (["--start", "20,-20", "--goal", "0,0"], "cannot reach the start cell"),  # planar2:joint misses room 4
    (["--render", "video.avi"], "format"),
]


@pytest.mark.parametrize("args,message", BAD, ids=[m for _, m in BAD])
def test_bad_input_is_one_line_exit_2_and_leaves_nothing(tmp_path, capsys, args, message):
    out = tmp_path / "out"
    code = main(["arms", "--fast", "--no-video", "--out", str(out), *args])
    err = capsys.readouterr().err
    assert code == 2, err
    assert message in err and len(err.strip().splitlines()) == 1, err
    assert not out.exists()
    assert not list(tmp_path.glob(".*"))


def test_unwritable_output_path(tmp_path, capsys):
    blocker = tmp_path / "file"
    blocker.write_text("x")
    assert main(["arms", "--fast", "--out", str(blocker / "run")]) == 2
    err = capsys.readouterr().err
    assert "cannot write" in err and len(err.strip().splitlines()) == 1
    nonempty = tmp_path / "full"
    nonempty.mkdir()
    (nonempty / "x").write_text("x")
    assert main(["arms", "--fast", "--out", str(nonempty)]) == 2
    assert "is not empty" in capsys.readouterr().err


@pytest.mark.parametrize("side", ["--source", "--target"])
def test_a_bring_your_own_arm_on_either_side(tmp_path, scara_xml, side):
    """Task 4: this SCARA cannot reach the cells round its own shoulder, where task 1 starts."""
    xml = scara_xml
    out = tmp_path / "run"
    other = "--target" if side == "--source" else "--source"
    code = main(["arms", "--fast", "--no-video", "--out", str(out), side, "custom:cartesian",
                 other, "planar2:cartesian", "--arm-xml", str(xml), "--tip-site", "pen_tip",
                 "--base-pos=-0.1,0,0", "--source-planner", "bfs", "--task", "4"])
    assert code == 0
    data = json.loads((out / "results.json").read_text())
    # a bring-your-own arm is named after its file's model (my_scara), not "custom"
    assert data["source" if side == "--source" else "target"] == "my_scara:cartesian"
    assert all(x is not None for x in data["results"]["pseudo"]["exploration_steps"])
