"""Spatial arms in their own joint space over the 3D workspace (``worlds.voxels``, ``ik.voxels``)."""

from __future__ import annotations

import hashlib
import re

import numpy as np
import pytest

from armtransfer.ik.labels import Labeller
from armtransfer.ik.scene import ContactChecker
from armtransfer.ik.voxels import voxels_of_points, workspace_voxels
from armtransfer.tasks.arms import arm_robot, arm_scene, is_spatial_joint, parse_robot_spec
from armtransfer.worlds.resolve import world
from armtransfer.worlds.voxels import Voxels

SMALL = world("rooms11")
STEP = 0.08


@pytest.fixture(scope="module")
def ur5e_joint():
    return arm_robot("ur5e_like", "joint", layout=SMALL, joint_step=STEP)


def test_level_0_voxels_are_the_plans_cells_and_walls_are_solid_up_to_their_height():
    rooms = world("rooms")
    assert workspace_voxels(rooms, 0.01).wall_levels == 2  # 2 cm walls, 1 cm levels
    vox = workspace_voxels(SMALL, 0.51 / 11)
    assert (vox.levels, vox.wall_levels) == (3, 1)
    cells = np.arange(SMALL.n_cells)
    assert np.array_equal(vox.ids(cells, np.zeros_like(cells)), cells)
    assert np.array_equal(vox.free[:SMALL.n_cells], SMALL.free)  # walls solid at level 0, doors open
    assert vox.free[SMALL.n_cells:].all()  # over the low walls
    wall = int(np.flatnonzero(~SMALL.free)[0])
    up = int(vox.ids(np.array(wall), np.array(1)))
    assert vox.xyk(up) == (*SMALL.xy(wall), 1) and vox.cell_of(up) == wall and vox.level_of(up) == 1
    two, rw = Voxels(rooms, 3, 2), int(np.flatnonzero(~rooms.free)[0])
    assert not two.free[rooms.n_cells + rw] and two.free[2 * rooms.n_cells + rw]
    cell = 0.01
    x, y = SMALL.xy(5)
    p = np.array([[x * cell, y * cell, 0.5 * cell], [x * cell, y * cell, 2.5 * cell],
                  [x * cell, y * cell, 3.2 * cell], [x * cell, y * cell, -0.1 * cell]])
    assert voxels_of_points(p, cell, Voxels(SMALL)).tolist() == [5, 2 * SMALL.n_cells + 5, -1, -1]


def test_a_spatial_arms_joint_spec_parses_and_a_planar_arms_joint_robot_is_as_before():
    assert parse_robot_spec("ur5e_like:joint") == ("ur5e_like", "joint")
    assert parse_robot_spec("panda_like:joint") == ("panda_like", "joint")
    planar = arm_robot("planar2", "joint", layout=SMALL)
    assert not is_spatial_joint(planar) and planar.arm is not None and planar.arm.levels == 0
    # the key and arrays of the swept move check: main's before the 3D workspace (2026-12-04,
    # commit 5659c26) less the one move (both ways) whose stylus went 0.73 mm into wall_7; the key
    # holds the compiling modules' source, so it changes with them (the arrays must not)
    assert planar.arm.key == "3df35518986fd1177012dab128bc362f1a993495cd0a6bf544ff6cba33edb5eb"
    digest = hashlib.sha256(planar.next_state.tobytes() + planar.label.tobytes()).hexdigest()
    assert digest == "71d88ac99a2d6dee1e0586650caaa3f77f26086ec109da870212b9bc59be7585"


def test_every_state_is_labelled_with_the_voxel_of_its_tool_point_by_mink(ur5e_joint):
    robot = ur5e_joint
    arm = robot.arm
    assert arm is not None and is_spatial_joint(robot) and arm.levels == 3
    assert arm.moved == (0, 1, 2) and robot.action_names == ("q1+", "q1-", "q2+", "q2-", "q3+", "q3-")
    scene = arm_scene("ur5e_like", layout=SMALL)
    vox = workspace_voxels(SMALL, scene.cell)
    mink = Labeller(scene)
    contact = ContactChecker(scene)
    rng = np.random.default_rng(0)
    sample = rng.choice(robot.n_states, size=60, replace=False)
    for s in sample:
        tip = mink.tip(arm.qpos[s])
        assert np.allclose(tip, arm.tip[s], atol=1e-9)
        assert int(voxels_of_points(tip, scene.cell, vox)) == int(robot.label[s])
        assert not contact.touches(arm.qpos[s])
    assert vox.free[robot.label].all() and set(np.unique(robot.label // SMALL.n_cells)) == {0, 1, 2}
    held = [j for j in range(arm.dof) if j not in arm.moved]
    assert np.ptp(arm.qpos[:, held], axis=0).max() == 0.0  # the wrist is held
    for s in sample:  # each action moves its joint by +-delta, or is blocked
        for a in range(robot.n_actions):
            t = int(robot.next_state[s, a])
            if t == s:
                continue
            dq = arm.qpos[t] - arm.qpos[s]
            j, sign = arm.moved[a // 2], 1 if a % 2 == 0 else -1
            expect = np.zeros(arm.dof)
            expect[j] = sign * STEP
            assert np.allclose(dq, expect, atol=1e-12)
    assert robot.label[robot.start_state(SMALL.cell(0, 0))] == SMALL.cell(0, 0)  # a task cell starts at level 0
    blown = robot.wind_state != np.arange(robot.n_states)  # wind: one cell towards +x at the same level
    assert blown.any() and np.array_equal(robot.label[robot.wind_state[blown]], robot.label[blown] + 1)
    assert all(int(robot.wind_state[s]) in robot.next_state[s] for s in np.flatnonzero(blown)[:200])


def test_a_planar_arms_cell_path_transfers_to_a_spatial_arm_in_joint_space(ur5e_joint):
    """planar2:joint -> ur5e_like:joint via the API: the source's 2D cells are the target's
    level-0 voxels, so the pseudo reward pays the 3D robot for reaching them."""
    import armtransfer

    r = armtransfer.transfer("planar2:joint", ur5e_joint, world=SMALL, task="2", methods=["none", "pseudo"],
                             trials=2, controls=False)
    traj = r.trajectories[0]
    assert all(0 <= c < SMALL.n_cells for c in traj.cells)  # a 2D path: level 0
    on_path = np.isin(ur5e_joint.label, traj.cells)
    assert on_path.any() and (ur5e_joint.label[on_path] < SMALL.n_cells).all()
    assert set(traj.cells) & set(ur5e_joint.label.tolist())
    for m in ("none", "pseudo"):
        steps = r.methods[m].column("exploration_steps")
        assert len(steps) == 2 and all(s is not None for s in steps)  # every trial reached the goal
    assert r.distance == ur5e_joint.distance(ur5e_joint.start_state(r.start_cell), r.goal_cell)


def test_a_lattice_too_large_is_one_line_naming_the_remedy(monkeypatch, tmp_path, capsys):
    from armtransfer.cli import main
    from armtransfer.errors import ArmModelError
    from armtransfer.ik import voxels

    monkeypatch.setattr(voxels, "MAX_STATES", 40)
    with pytest.raises(ArmModelError, match=r"more than 40 states over the 3D workspace; give a coarser joint step"):
        arm_robot("ur5e_like", "joint", layout=SMALL, joint_step=STEP, cache=False)
    out = tmp_path / "out"
    assert main(["arms", "--source", "planar2:joint", "--target", "ur5e_like:joint", "--world", "rooms11", "--fast",
                 "--no-video", "--no-cache", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "more than 40 states" in err and "coarser joint step" in err
    assert not out.exists()


@pytest.mark.slow
@pytest.mark.rendering
def test_armtransfer_arms_planar_to_spatial_joint_with_a_replay_video(tmp_path):
    """The command end to end, planar2:joint -> ur5e_like:joint on rooms11, with the physics
    replay of both arms (about 10 s with the arms compiled, 2026-12-04)."""
    import json

    import imageio.v3 as iio

    from armtransfer.cli import main

    out = tmp_path / "run"
    assert main(["arms", "--source", "planar2:joint", "--target", "ur5e_like:joint", "--world", "rooms11",
                 "--task", "2", "--fast", "--method", "none", "pseudo", "--out", str(out)]) == 0
    data = json.loads((out / "results.json").read_text())
    assert data["target"] == "ur5e_like:joint" and set(data["results"]) == {"none", "pseudo"}
    assert all(len(r["exploration_steps"]) == 2 for r in data["results"].values())
    rollout = data["rollout"]
    assert rollout["panels"] == 2 and len(iio.imread(out / "rollout.mp4")) == rollout["frames"] > 10
    for rp in rollout["replays"]:
        assert rp["reached_goal"] and rp["max_deviation_cells"] < 1.0


def test_a_voxel_path_round_trips_through_the_trajectory_json():
    from armtransfer.errors import InvalidTrajectoryError
    from armtransfer.learning import trajectory as trajectories

    n = SMALL.n_cells
    cells = (SMALL.cell(2, 2), n + SMALL.cell(2, 3), 2 * n + SMALL.cell(3, 3), SMALL.cell(3, 4))
    traj = trajectories.Trajectory(cells, (0, 1, 2, 3), SMALL.cell(4, 4), source="ur5e_like:joint")
    data = traj.to_json(SMALL)
    assert [s["cell"] for s in data["steps"]] == [[2, 2], [2, 3, 1], [3, 3, 2], [3, 4]]
    back = trajectories.parse(data, SMALL)
    assert back.cells == cells and back.goal == traj.goal and back.actions == traj.actions
    data["steps"][1]["cell"] = [2, 3, 3]
    with pytest.raises(InvalidTrajectoryError, match=r"step 1 cell level 3 is outside 0..2"):
        trajectories.parse(data, SMALL)


def test_a_spatial_arms_voxel_path_transfers_to_another_spatial_arm(ur5e_joint):
    """ur5e_like:joint -> panda_like:joint via the API: the source's path climbs off the
    table (voxels above level 0) and the target is paid for the same voxels."""
    import armtransfer

    panda = arm_robot("panda_like", "joint", layout=SMALL, joint_step=STEP)
    assert panda.arm is not None and panda.arm.moved == (0, 1, 3)  # shoulder, upper arm, elbow
    r = armtransfer.transfer(ur5e_joint, panda, world=SMALL, task="2", methods=["none", "pseudo"], trials=2,
                             controls=False)
    traj = r.trajectories[0]
    assert traj.source == "ur5e_like:joint" and set(traj.cells) <= set(ur5e_joint.label.tolist())
    assert any(c >= SMALL.n_cells for c in traj.cells)  # it leaves level 0 on the way
    assert set(traj.cells) & set(panda.label[panda.label >= SMALL.n_cells].tolist())  # voxels both arms reach
    for m in ("none", "pseudo"):
        steps = r.methods[m].column("exploration_steps")
        assert len(steps) == 2 and all(s is not None for s in steps)


@pytest.mark.slow
def test_the_voxels_suite_runs_on_one_source_seed():
    """A smoke test of the held-out 3D suite: one source seed, one trial per method; both
    cases, only none and pseudo (the section's methods), and pseudo's goal-only baseline goal-dense."""
    from dataclasses import replace

    from armtransfer.experiments import benchmark, suites

    suite = suites.get("voxels")
    assert suite.held_out and suite.sections[0].source_seeds >= 10
    section = replace(suite.sections[0], source_seeds=1, trials=1)
    records, _ = benchmark.run_suite(suites.Suite("t", 1, True, "", (section,)), threads=1)
    assert sorted((r["case"], r["method"]) for r in records) == [(0, "goal-dense"), (0, "none"), (0, "pseudo"),
                                                                 (1, "goal-dense"), (1, "none"), (1, "pseudo")]
    for r in records:
        assert r["error"] is None and r["first_exposure"][0] is not None, r


def test_a_bring_your_own_6_joint_file_gets_the_same_3d_joint_robot(ur5e_joint):
    """custom:joint on a spatial arm file: the built-in ur5e_like's file, mounted as it is, gives
    the built-in's 3D robot state for state."""
    import math

    from armtransfer.models import ARMS

    info = ARMS["ur5e_like"]
    mine = arm_robot(None, "joint", xml_path=info.xml_path, arm_name="my_ur5e", base_pos=info.mount_pos,
                     base_yaw=-math.pi / 2, layout=SMALL, joint_step=STEP)
    assert mine.name == "my_ur5e:joint" and is_spatial_joint(mine) and mine.action_names == ur5e_joint.action_names
    for a, b in ((mine.label, ur5e_joint.label), (mine.next_state, ur5e_joint.next_state),
                 (mine.arm.qpos, ur5e_joint.arm.qpos)):
        assert np.array_equal(a, b)


def test_a_task_cell_out_of_reach_at_the_table_level_names_the_remedy(ur5e_joint):
    from armtransfer.errors import InvalidCellError

    level0 = set(ur5e_joint.label[ur5e_joint.label < SMALL.n_cells].tolist())
    missing = [c for c in np.flatnonzero(SMALL.free) if int(c) not in level0]
    assert missing  # at 0.08 rad the tool skips a few cells' table level
    x, y = SMALL.xy(int(missing[0]))
    with pytest.raises(InvalidCellError, match=rf"cannot reach the goal cell \({x}, {y}\) with its tool at the table "
                                               r"level \(level 0 of the 3D workspace\); give a finer joint step"):
        ur5e_joint.start_state(int(missing[0]), what="goal")


def test_a_bring_your_own_7_joint_file_compiles_as_custom_joint_and_transfers(tmp_path):
    """A Menagerie-style iiwa file (7 joints, a flange site, no keyframe, mount chosen by the
    compiler) is a 3D robot as ``custom:joint``, and planar2:joint's cell path transfers to it
    on rooms11 via the API with ``none`` and ``pseudo``."""
    import sys
    from pathlib import Path

    import armtransfer

    sys.path.insert(0, str(Path(__file__).parent))
    import menagerie_like as ml

    xml = ml.iiwa_style(tmp_path)
    tip = ml.SUGGESTED["iiwa"]
    robot = arm_robot(None, "joint", xml_path=xml, layout=SMALL, **tip)
    arm = robot.arm
    assert arm is not None and is_spatial_joint(robot) and arm.dof == 7 and arm.levels == 3
    assert len(arm.moved) == 3 and robot.n_actions == 6
    assert robot.action_names == tuple(f"q{j + 1}{s}" for j in arm.moved for s in "+-")
    vox = workspace_voxels(SMALL, arm_scene(None, xml_path=xml, layout=SMALL, base_pos=arm.mount,
                                            base_yaw=arm.yaw, **tip).cell)
    assert vox.free[robot.label].all() and (robot.label >= SMALL.n_cells).any()  # it leaves the table level
    held = [j for j in range(arm.dof) if j not in arm.moved]
    assert np.ptp(arm.qpos[:, held], axis=0).max() == 0.0

    r = armtransfer.transfer("planar2:joint", "custom:joint", arm_xml=xml, arm_options=dict(tip),
                             world="rooms11", task="2", methods=["none", "pseudo"], trials=2, controls=False)
    assert r.target.name == robot.name == "iiwa14:joint" and np.array_equal(r.target.label, robot.label)
    traj = r.trajectories[0]
    assert traj.source == "planar2:joint" and all(0 <= c < SMALL.n_cells for c in traj.cells)
    assert set(traj.cells) & set(robot.label.tolist())  # the 2D path is voxels the 7-joint arm reaches
    for m in ("none", "pseudo"):
        steps = r.methods[m].column("exploration_steps")
        assert len(steps) == 2 and all(s is not None for s in steps)  # every trial reached the goal
    assert r.distance == robot.distance(robot.start_state(r.start_cell), r.goal_cell)


def test_arms_list_lists_the_spatial_joint_robots(capsys, monkeypatch, tmp_path):
    from armtransfer import cli

    monkeypatch.setenv("ARMTRANSFER_CACHE", str(tmp_path / "cache"))
    assert cli.main(["arms", "list", "--arm", "planar2,ur5e_like,panda_like", "--actions", "joint",
                     "--world", "rooms11"]) == 0
    out = capsys.readouterr().out.splitlines()
    table = out[1:out.index("")]  # the rows, then a blank line and the notes
    rows = {line.split()[0]: line.split() for line in table}
    assert list(rows) == ["planar2:joint", "ur5e_like:joint", "panda_like:joint"]
    assert rows["ur5e_like:joint"][1:3] == ["6", "6"] and rows["panda_like:joint"][1:3] == ["7", "6"]
    ur5e = arm_robot("ur5e_like", "joint", layout=SMALL)
    assert rows["ur5e_like:joint"][3] == str(ur5e.n_states) and rows["ur5e_like:joint"][5] == "3/3"
    notes = [line for line in out if line.endswith("its reach is of the free voxels")]
    assert notes == ["ur5e_like:joint: joint space over the 3D workspace (3 levels); moves joints 1, 2, 3 and holds "
                     "the others; its reach is of the free voxels",
                     "panda_like:joint: joint space over the 3D workspace (3 levels); moves joints 1, 2, 4 and holds "
                     "the others; its reach is of the free voxels"]


def test_the_gymnasium_env_with_a_3d_robot_passes_check_env_and_reaches_the_goal():
    import gymnasium as gym
    from gymnasium.utils.env_checker import check_env

    import armtransfer  # noqa: F401  (registers the environments)

    env = gym.make("armtransfer/ArmRooms-v0", arm="ur5e_like", actions="joint", world="rooms11", task="2")
    check_env(env.unwrapped, skip_render_check=True)
    u = env.unwrapped
    assert u.robot.name == "ur5e_like:joint" and is_spatial_joint(u.robot) and u.action_space.n == 6
    obs, info = env.reset(seed=0)
    assert info["label"] == SMALL.cell(2, 2)  # rooms11 task 2 starts at (2, 2), at the table level
    terminated = False
    for _, action in u.robot.shortest_path(obs, u.goal_cell)[:-1]:
        obs, reward, terminated, truncated, info = env.step(action)
    assert terminated and info["label"] == u.goal_cell
    env.close()


def test_armtransfer_matrix_runs_with_a_3d_robot(tmp_path, capsys):
    import json

    from armtransfer.cli import main

    out = tmp_path / "m"
    assert main(["matrix", "--robots", "planar2:joint,ur5e_like:joint", "--world", "rooms11", "--tasks", "2",
                 "--methods", "pseudo", "--trials", "1", "--out", str(out), "--workers", "1"]) == 0
    assert "8 of 8 runs finished" in capsys.readouterr().out
    cells = json.loads((out / "matrix.json").read_text())["cells"]
    pairs = {(c["source"], c["target"]) for c in cells}
    assert ("planar2:joint", "ur5e_like:joint") in pairs and ("ur5e_like:joint", "planar2:joint") in pairs
    for c in cells:
        assert c["tasks"] == 1 and c["trials"] == 1 and c["improvement"] is not None
    header = r"\| source \\ target +\| planar2:joint +\| ur5e_like:joint +\|"  # columns padded to their widest cell
    assert re.search(header, (out / "matrix.md").read_text())


def test_armtransfer_sweep_runs_with_a_3d_robot(tmp_path, capsys):
    import json

    from armtransfer.cli import main

    sweep = tmp_path / "s.toml"
    sweep.write_text('[sweep]\nname = "spatial"\nworld = "rooms11"\ntasks = ["2"]\n'
                     'pairs = [["planar2:joint", "ur5e_like:joint"]]\nmethods = ["none", "pseudo"]\n'
                     'seeds = [0]\ntrials = 2\n')
    out = tmp_path / "out"
    assert main(["sweep", str(sweep), "--out", str(out), "--workers", "1"]) == 0
    assert "2/2 runs" in capsys.readouterr().out and not any((out / "failed").iterdir())
    assert main(["summarize", str(out)]) == 0
    data = json.loads((out / "summary.json").read_text())
    assert data["runs"] == 2
    rows = {r["method"]: r for r in data["rows"]}
    assert set(rows) == {"none", "pseudo"} and all(r["trials"] == 2 for r in rows.values())
    assert rows["pseudo"]["improvement_percent"] is not None
