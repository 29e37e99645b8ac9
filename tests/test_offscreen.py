"""A machine where offscreen OpenGL does not work: every rendering entry point says, in one
line and before any learning, which system packages to install and how to go on without.

The backends this machine lacks are chosen with MUJOCO_GL (osmesa and glfw: no libOSMesa, no
display), in child processes, since a process's backend is fixed at its first import of mujoco.
"""

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from armtransfer.cli import main
from armtransfer.ik import offscreen

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("libegl1", "libgl1", "libosmesa6", "mesa-libEGL", "mesa-libOSMesa")


def _missing(backend: str) -> None:
    """Skip when ``backend`` works here after all (then it cannot stand for a missing one)."""
    if offscreen.probe(backend) is None:
        pytest.skip(f"MUJOCO_GL={backend} works on this machine")


def _child(args: list[str], tmp_path: Path, **env) -> subprocess.CompletedProcess:
    full = {**os.environ, **env}
    for name, value in env.items():
        if value is None:
            full.pop(name)
    return subprocess.run([sys.executable, *args], capture_output=True, text=True, timeout=600, cwd=tmp_path,
                          env=full)


def _names_the_fix(line: str, backend: str, without: str) -> None:
    assert f"MUJOCO_GL={backend}:" in line, line
    for package in PACKAGES:
        assert package in line, (package, line)
    assert without in line, line


@pytest.mark.parametrize("backend", ["osmesa", "glfw"])
def test_arms_without_the_backend_stops_in_one_line_before_learning(tmp_path, backend):
    _missing(backend)
    out = tmp_path / "D"
    proc = _child(["-m", "armtransfer", "arms", "--fast", "--out", str(out)], tmp_path, MUJOCO_GL=backend)
    assert proc.returncode == 2, proc.stderr
    assert proc.stderr.count("\n") == 1 and proc.stderr.startswith("armtransfer arms: error: offscreen rendering"), \
        proc.stderr
    _names_the_fix(proc.stderr, backend, "--no-video")
    assert proc.stdout == ""  # nothing learned: the results table would be here
    assert not out.exists()


def test_the_main_script_without_the_backend_stops_in_one_line(tmp_path):
    _missing("osmesa")
    proc = _child([str(ROOT / "scripts" / "transfer_arms.py"), "--fast", "--out", "D"], tmp_path, MUJOCO_GL="osmesa")
    assert proc.returncode == 2, proc.stderr
    assert proc.stderr.count("\n") == 1 and "Traceback" not in proc.stderr
    _names_the_fix(proc.stderr, "osmesa", "--no-video")
    assert proc.stdout == "" and list(tmp_path.iterdir()) == []


LIBRARY = """
import json, sys
import gymnasium as gym
import armtransfer
from armtransfer.errors import ArmTransferError
from armtransfer.tasks.arms import robot
from armtransfer.ik.render import rollout_video

out = {}
try:
    gym.make("armtransfer/ArmRooms-v0", arm="planar2", actions="joint", task=1, render_mode="rgb_array")
except ArmTransferError as err:
    out["env"] = [type(err).__name__, str(err)]
try:
    rollout_video([(robot("planar2:joint"), [0, 1])], sys.argv[1])
except ArmTransferError as err:
    out["api"] = [type(err).__name__, str(err)]
print(json.dumps(out))
"""


@pytest.fixture(scope="module")
def library_without_opengl(tmp_path_factory):
    _missing("osmesa")
    tmp = tmp_path_factory.mktemp("library")
    proc = _child(["-c", LIBRARY, str(tmp / "v.gif")], tmp, MUJOCO_GL="osmesa")
    assert proc.returncode == 0, proc.stderr
    return json.loads(proc.stdout.splitlines()[-1]), tmp


def test_an_arm_env_with_rgb_array_says_what_to_install(library_without_opengl):
    caught, _ = library_without_opengl
    kind, message = caught["env"]
    assert kind == "OffscreenError" and "\n" not in message
    _names_the_fix(message, "osmesa", "render_mode='ansi'")


def test_the_rendering_api_says_what_to_install_and_writes_nothing(library_without_opengl):
    caught, tmp = library_without_opengl
    kind, message = caught["api"]
    assert kind == "OffscreenError" and "\n" not in message
    _names_the_fix(message, "osmesa", "draw nothing")
    assert list(tmp.iterdir()) == []


def test_without_a_named_backend_egl_then_osmesa_are_tried(monkeypatch):
    tried = []

    def fake_probe(backend):
        tried.append(backend)
        return None if backend == "osmesa" else "libEGL is not installed"

    monkeypatch.setattr(offscreen, "probe", fake_probe)
    monkeypatch.setattr(offscreen, "imported_backend", lambda: None)
    monkeypatch.setattr(offscreen, "_defaulted", True)
    monkeypatch.setenv("MUJOCO_GL", "egl")
    assert offscreen.require("run with --no-video") == "osmesa"
    assert tried == ["egl", "osmesa"] and os.environ["MUJOCO_GL"] == "osmesa"
    assert offscreen.named() == "osmesa"  # from now on the backend is settled


def test_when_neither_works_the_line_names_both(monkeypatch):
    monkeypatch.setattr(offscreen, "probe", lambda backend: f"lib{backend} is missing")
    monkeypatch.setattr(offscreen, "imported_backend", lambda: None)
    monkeypatch.setattr(offscreen, "_defaulted", True)
    monkeypatch.setenv("MUJOCO_GL", "egl")
    with pytest.raises(offscreen.OffscreenError) as err:
        offscreen.require("run with --no-video")
    message = str(err.value)
    assert "MUJOCO_GL=egl: libegl is missing; MUJOCO_GL=osmesa: libosmesa is missing" in message
    _names_the_fix(message, "osmesa", "run with --no-video")
    assert os.environ["MUJOCO_GL"] == "egl"


def test_a_named_backend_is_the_only_one_tried(monkeypatch):
    tried = []
    monkeypatch.setattr(offscreen, "probe", lambda backend: tried.append(backend) or "missing")
    monkeypatch.setattr(offscreen, "imported_backend", lambda: None)
    monkeypatch.setattr(offscreen, "_defaulted", False)
    monkeypatch.setenv("MUJOCO_GL", "osmesa")
    with pytest.raises(offscreen.OffscreenError):
        offscreen.require("x")
    assert tried == ["osmesa"]


def test_without_a_named_backend_a_machine_without_egl_or_osmesa_stops_before_learning(tmp_path):
    """MUJOCO_GL unset, and EGL without a vendor library (as where Mesa's EGL is not installed)."""
    _missing("osmesa")
    proc = _child(["-m", "armtransfer", "arms", "--fast", "--out", "D"], tmp_path, MUJOCO_GL=None,
                  __EGL_VENDOR_LIBRARY_FILENAMES=str(tmp_path / "no-vendor.json"))
    assert proc.returncode == 2, proc.stderr
    assert proc.stderr.count("\n") == 1
    assert "MUJOCO_GL=egl:" in proc.stderr and "MUJOCO_GL=osmesa: libOSMesa is not installed" in proc.stderr
    _names_the_fix(proc.stderr, "osmesa", "--no-video")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.rendering
def test_without_a_named_backend_the_one_that_works_is_chosen(tmp_path):
    code = "from armtransfer.ik import offscreen; import os; print(offscreen.require('x'), os.environ['MUJOCO_GL'])"
    proc = _child(["-c", code], tmp_path, MUJOCO_GL=None)
    assert proc.returncode == 0, proc.stderr
    backend, variable = proc.stdout.split()
    assert backend == variable and backend in offscreen.UNSET_ORDER


def test_a_render_that_fails_after_learning_keeps_everything_else(tmp_path, monkeypatch, capsys):
    import mujoco

    def no_context(*args, **kwargs):
        raise mujoco.FatalError("an OpenGL platform library has not been loaded into this process")

    monkeypatch.setattr(offscreen, "probe", lambda backend: None)  # the check before learning passes ...
    monkeypatch.setattr(mujoco, "Renderer", no_context)  # ... and the GL context fails anyway
    out = tmp_path / "run"
    code = main(["arms", "--fast", "--method", "none", "pseudo", "--out", str(out)])
    err = capsys.readouterr().err
    assert code == 1
    assert sorted(p.name for p in out.iterdir()) == ["learning_curves.png", "map.png", "results.json", "table.md"]
    assert "rollout" not in json.loads((out / "results.json").read_text())
    assert err.count("\n") == 1
    assert err.startswith("armtransfer arms: wrote the results, table and figures but not the video: ")
    assert "FatalError: an OpenGL platform library" in err
    _names_the_fix(err, "egl", "--no-video")


@pytest.mark.rendering
def test_opengl_failing_while_drawing_is_an_offscreen_error_and_leaves_nothing(tmp_path, monkeypatch):
    import mujoco

    from armtransfer.ik import render
    from armtransfer.ik.replay import replay
    from armtransfer.tasks.arms import robot
    from armtransfer.worlds.layout import ROOMS

    r = robot("planar2:cartesian")
    path = r.shortest_path(r.start_state(ROOMS.free_cell(0, 0)), ROOMS.free_cell(2, 1))
    rp = replay(r, [s for s, _ in path], segment_seconds=0.05, settle_seconds=0.0)

    def lost(self, qpos):
        raise mujoco.FatalError("gl error 0x505 (out of memory)")

    monkeypatch.setattr(render.PanelRenderer, "render", lost)
    with pytest.raises(offscreen.OffscreenError) as err:
        render.render_rollouts([render.RolloutPanel(rp)], tmp_path / "v.gif", width=32, height=32)
    assert "FatalError: gl error 0x505" in str(err.value) and "\n" not in str(err.value)
    _names_the_fix(str(err.value), offscreen.imported_backend(), "draw nothing")
    assert list(tmp_path.iterdir()) == []
