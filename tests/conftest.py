import fcntl
import json
import os
from pathlib import Path

import pytest

# Offscreen rendering needs the GL backend named before mujoco is first imported (by a test
# module, at collection): armtransfer.ik names EGL unless MUJOCO_GL is set.
from armtransfer.ik import offscreen

SCARA_XML = """<mujoco model="my_scara"><compiler angle="radian"/><worldbody>
  <body name="upper" pos="0.05 0.02 0.15">
    <joint name="shoulder" type="hinge" axis="0 0 1" range="-3 3"/>
    <geom name="upper_geom" type="capsule" size="0.01" fromto="0 0 0 0.24 0 0"/>
    <body name="fore" pos="0.24 0 -0.03">
      <joint name="elbow" type="hinge" axis="0 0 1" range="-2.9 2.9"/>
      <geom name="fore_geom" type="capsule" size="0.01" fromto="0 0 0 0.2 0 0"/>
      <geom name="pen" type="cylinder" size="0.0015" fromto="0.2 0 0 0.2 0 -0.115"/>
      <site name="pen_tip" pos="0.2 0 -0.116"/>
    </body>
  </body></worldbody></mujoco>"""
"""A bring-your-own 2-joint SCARA with its tip site named ``pen_tip``."""


RENDER_WITHOUT = "deselect the tests that render with -m 'not rendering'"


def pytest_configure(config):
    """With MUJOCO_GL unset, find the backend that works here (EGL, else OSMesa) before any
    test module imports mujoco; the tests marked ``rendering`` are skipped when none does."""
    if offscreen.named() is None:
        try:
            offscreen.require(RENDER_WITHOUT)
        except offscreen.OffscreenError:
            pass  # pytest_collection_modifyitems skips the tests that render, saying why


HEAVY = frozenset({
    "test_api.py", "test_arm_files.py", "test_arm_transfer.py", "test_arms_cli.py", "test_benchmark.py",
    "test_benchmark_continuous.py", "test_benchmark_store.py", "test_byo_arms.py", "test_compile.py",
    "test_docs.py", "test_first_exposure.py", "test_generated_arms.py", "test_held_tool.py",
    "test_hostile_audit.py", "test_hostile_kills.py", "test_learner_commands.py", "test_learners.py",
    "test_plugins.py", "test_render.py", "test_replay_reach.py", "test_script_errors.py", "test_sweep.py",
    "test_sweep_guards.py", "test_voxels.py",
})
"""Test modules whose default-suite tests compile arms, start processes or learn for seconds:
marked ``heavy``, so that ``-m "not slow and not heavy"`` is the quick subset (docs/setup.md).
Chosen from the default suite's measured durations (2026-12-06), the heaviest modules first, until
the rest summed to under 150 s of test time."""


def pytest_collection_modifyitems(config, items):
    for item in items:
        if item.path.name in HEAVY:
            item.add_marker(pytest.mark.heavy)
    rendering = [item for item in items if item.get_closest_marker("rendering")]
    if not rendering:
        return
    try:
        offscreen.require(RENDER_WITHOUT)
    except offscreen.OffscreenError as err:
        skip = pytest.mark.skip(reason=f"no offscreen OpenGL backend works here: {err}")
        for item in rendering:
            item.add_marker(skip)


def run_dir(tmp_path_factory) -> Path:
    """A folder all the run's xdist workers share (each worker's own basetemp is below it)."""
    base = tmp_path_factory.getbasetemp()
    return base.parent if os.environ.get("PYTEST_XDIST_WORKER") else base


@pytest.fixture(scope="session", autouse=True)
def arm_cache(tmp_path_factory):
    """Compiled arm robots go to one cache for the whole run, never the user's own: the
    workers share it, and the cache's build lock makes each arm compile once per run."""
    mp = pytest.MonkeyPatch()
    mp.setenv("ARMTRANSFER_CACHE", str(run_dir(tmp_path_factory) / "armcache"))
    yield
    mp.undo()


@pytest.fixture
def scara_xml(tmp_path):
    path = tmp_path / "my_scara.xml"
    path.write_text(SCARA_XML)
    return path


@pytest.fixture(scope="session")
def reproduce_fast(tmp_path_factory):
    """One fast `armtransfer reproduce --trials 2` shared by the tests that read its output."""
    from armtransfer.cli import main

    shared = run_dir(tmp_path_factory) / "reproduce"
    (shared / "out").mkdir(parents=True, exist_ok=True)
    out, done = shared / "out" / "rep", shared / "exit-code.json"  # rep alone in its folder
    with open(shared / "lock", "a") as lock:  # the first worker runs it; the others wait, then read it
        fcntl.flock(lock, fcntl.LOCK_EX)
        if not done.exists():
            # a lower step cap keeps the controls that never find the goal from dominating the time
            code = main(["reproduce", "--trials", "2", "--max-total-steps", "2000000", "--out", str(out)])
            done.write_text(json.dumps(code))
    return json.loads(done.read_text()), out


@pytest.fixture(scope="session")
def benchmark_fast(tmp_path_factory):
    """`armtransfer benchmark --suite fast` run twice with the same seed, on 1 worker (``one``)
    and on 2 (``two``), shared by the tests that read the stores: (exit codes, root folder)."""
    from armtransfer.cli import main

    shared = run_dir(tmp_path_factory) / "benchmark-fast"
    shared.mkdir(parents=True, exist_ok=True)
    done = shared / "exit-codes.json"
    with open(shared / "lock", "a") as lock:  # the first worker runs them; the others wait, then read them
        fcntl.flock(lock, fcntl.LOCK_EX)
        if not done.exists():
            codes = [main(["benchmark", "--suite", "fast", "--out", str(shared / name), "--workers", workers])
                     for name, workers in (("one", "1"), ("two", "2"))]
            done.write_text(json.dumps(codes))
    return json.loads(done.read_text()), shared
