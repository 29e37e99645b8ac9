"""Bring-your-own arms written the way MuJoCo Menagerie writes them: untouched
files with ``/`` in class names, meshes in a meshdir, affine ``general`` actuators, a
tendon-driven slide gripper, a flange site or no site, a tip given by body and offset,
no keyframe, a singular qpos0, and an automatically chosen mount.

The contract (``armtransfer.tasks.arms.arm_robot``): ``tip_site=`` or ``tip_body=`` plus
``tip_offset=`` (metres, in that frame); without ``base_pos`` the mount is chosen and
recorded as ``robot.arm.mount`` (x, y, z) and ``robot.arm.yaw``; the robot is named after
the MJCF ``model`` attribute unless ``arm_name=`` is given; joints that are not the arm's
(the Panda's fingers) are not counted in ``robot.arm.dof``.
"""

import math

import numpy as np
import pytest

import armtransfer
import menagerie_like as ml
from armtransfer.tasks.arms import tasks_solvable
from armtransfer.tasks.arms import arm_robot
from armtransfer.tasks.catalog import TABLE_I
from armtransfer.worlds.layout import ROOMS
from test_cli import run_cli  # a fresh interpreter; it inherits the session's ARMTRANSFER_CACHE

UR5E_TOOL = (0.0, 0.0, 0.12)
PANDA_TCP = (0.0, 0.0, ml.PANDA_TCP)  # 0.1034: the closed fingertips
SO100_TIP = (0.0, 0.0, ml.SO100_JAW)  # 0.18: the jaw tips, on the wrist-roll axis


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    out = tmp_path_factory.mktemp("menagerie_like")
    return {name: make(out) for name, make in ml.ALL.items()}


@pytest.fixture(scope="module")
def ur5e(files):
    return arm_robot(None, "cartesian", xml_path=files["ur5e"], tip_site="attachment_site", tip_offset=UR5E_TOOL)


@pytest.fixture(scope="module")
def panda(files):
    return arm_robot(None, "cartesian", xml_path=files["panda"], tip_body="hand", tip_offset=PANDA_TCP)


@pytest.fixture(scope="module")
def so100(files):
    return arm_robot(None, "cartesian", xml_path=files["so100"], tip_body="Fixed_Jaw", tip_offset=SO100_TIP)


def _solved(robot) -> int:
    return tasks_solvable(robot)


def _check_auto_mount(robot):
    mount = robot.arm.mount
    assert isinstance(mount, tuple) and len(mount) == 3
    assert all(isinstance(v, float) and math.isfinite(v) for v in mount)
    assert isinstance(robot.arm.yaw, float) and math.isfinite(robot.arm.yaw)


# --------------------------------------------------------------------------- compiling


def test_ur5e_style_by_flange_site_and_tool_offset(ur5e):
    assert ur5e.name == "ur5e:cartesian"
    assert ur5e.arm.dof == 6 and ur5e.arm.qpos.shape == (ur5e.n_states, 6)
    _check_auto_mount(ur5e)
    assert ur5e.arm.reach >= 0.8
    assert _solved(ur5e) == 4


@pytest.mark.slow
def test_panda_with_hand_by_body_and_offset(panda):
    assert panda.name == "panda:cartesian"
    assert panda.arm.dof == 7  # the fingers are not the arm's
    assert panda.n_actions == 4
    _check_auto_mount(panda)
    assert panda.arm.reach >= 0.8
    assert _solved(panda) == 4


@pytest.mark.slow  # 7 s for the so100 file alone
def test_so100_style_by_fixed_jaw_and_offset(so100):
    assert so100.name == "so_arm100:cartesian"
    # the arm's joints are those that move the tip: the Jaw, below the tip body, is not one
    assert so100.arm.dof == 5
    _check_auto_mount(so100)
    # mounted beside the table: the base is not over the table's walls
    assert so100.arm.reach >= 0.6
    assert _solved(so100) >= 3


@pytest.mark.slow  # 7 s; the Panda-style file is compiled by default with its hand (test_panda_with_hand_by_body_and_offset)
def test_panda_without_hand_by_flange_site(files):
    r = arm_robot(None, "cartesian", xml_path=files["panda_nohand"], tip_site="attachment_site",
                   tip_offset=(0.0, 0.0, 0.1))
    assert r.name == "panda:cartesian" and r.arm.dof == 7
    _check_auto_mount(r)
    assert r.arm.reach >= 0.8 and _solved(r) == 4


@pytest.mark.slow  # 6 s: a second 5-joint file compiled; tests/test_tool_tilt.py and the walls tests compile others
def test_planar5_straight_cartesian_from_its_singular_qpos0(files):
    # no keyframe: home is qpos0, the straight arm, where IK's Jacobian loses a rank
    r = arm_robot(None, "cartesian", xml_path=files["planar5"], tip_body="stylus")
    assert r.name == "planar5:cartesian" and r.arm.dof == 5
    _check_auto_mount(r)
    assert r.arm.reach >= 0.6
    assert tasks_solvable(r, [TABLE_I[1]]) == 1


@pytest.mark.slow
@pytest.mark.hours  # a 5-joint lattice, every move swept: over 40 minutes on 2 loaded cores
def test_planar5_straight_joint_model_automatic_mount(files):
    r = arm_robot(None, "joint", xml_path=files["planar5"], tip_body="stylus")
    assert r.name == "planar5:joint" and r.arm.dof == 5 and r.n_actions == 10
    _check_auto_mount(r)
    assert r.arm.reach >= 0.6
    assert tasks_solvable(r, [TABLE_I[1]]) == 1


@pytest.mark.parametrize("which, reach, solved", [("ur5e", 0.8, 4), pytest.param("so100", 0.6, 3, marks=pytest.mark.slow)])
def test_an_explicit_mount_is_the_file_frame_pose(files, which, reach, solved):
    # base_pos/base_yaw place the file's own frame: the SO100-style arm stands on a body 1.5 m
    # from that frame, and its suggested mount brings the base beside the table
    tip = {k: v for k, v in ml.SUGGESTED[which].items() if k.startswith("tip")}
    mount, yaw = ml.SUGGESTED[which]["base_pos"], ml.SUGGESTED[which]["base_yaw"]
    r = arm_robot(None, "cartesian", xml_path=files[which], base_pos=mount, base_yaw=yaw, **tip)
    assert r.arm.mount == pytest.approx(mount) and r.arm.yaw == pytest.approx(yaw)
    assert r.arm.reach >= reach and _solved(r) >= solved


def test_arm_name_overrides_the_model_attribute(files, ur5e):
    r = arm_robot(None, "cartesian", xml_path=files["ur5e"], tip_site="attachment_site", tip_offset=UR5E_TOOL,
                   arm_name="myarm")
    assert r.name == "myarm:cartesian"
    assert r.n_states == ur5e.n_states and np.array_equal(r.label, ur5e.label)


@pytest.mark.slow
def test_the_tip_is_the_offset_from_the_named_frame(ur5e, panda):
    import mujoco

    from armtransfer.ik.replay import robot_scene

    for robot, frame, offset in ((ur5e, "attachment_site", UR5E_TOOL), (panda, "hand", PANDA_TCP)):
        scene = robot_scene(robot)
        model, data = scene.model, mujoco.MjData(scene.model)
        s = int(robot.canonical[ROOMS.free_cell(0, 0)])
        data.qpos[:] = robot.arm.qpos[s]
        mujoco.mj_kinematics(model, data)
        kind = mujoco.mjtObj.mjOBJ_SITE if frame.endswith("site") else mujoco.mjtObj.mjOBJ_BODY
        ids = [i for i in range(model.nsite if kind == mujoco.mjtObj.mjOBJ_SITE else model.nbody)
               if (mujoco.mj_id2name(model, kind, i) or "").endswith(frame)]
        assert len(ids) == 1
        if kind == mujoco.mjtObj.mjOBJ_SITE:
            pos, mat = data.site_xpos[ids[0]], data.site_xmat[ids[0]].reshape(3, 3)
        else:
            pos, mat = data.xpos[ids[0]], data.xmat[ids[0]].reshape(3, 3)
        tip = pos + mat @ np.array(offset)
        assert np.allclose(tip, robot.arm.tip[s], atol=1e-6)
        assert np.allclose(tip[:2], (0.0, 0.0), atol=0.5 * robot.arm.cell_size)  # over cell (0, 0)
        assert -1e-3 <= tip[2] <= 0.01


# --------------------------------------------------------------------------- using them


@pytest.mark.slow
def test_transfer_both_ways_between_menagerie_style_arms(ur5e, panda):
    for source, target in ((ur5e, panda), (panda, ur5e)):
        r = armtransfer.transfer(source=source, target=target, task=1, methods=["none", "pseudo"], trials=2,
                                 seed=0, max_episodes=60, trajectory="optimal", controls=False)
        assert r.source.name == source.name and r.target.name == target.name
        for method in ("none", "pseudo"):
            steps = r.methods[method].column("exploration_steps")
            assert len(steps) == 2 and all(s is None or s > 0 for s in steps)
        assert any(s is not None for s in r.methods["pseudo"].column("exploration_steps"))


@pytest.mark.parametrize("which", ["ur5e", pytest.param("panda", marks=pytest.mark.slow),  # panda: 11 s
                                   pytest.param("so100", marks=pytest.mark.slow)])
def test_physics_replay_reaches_the_goal(request, which):
    from armtransfer.ik.replay import replay

    robot = request.getfixturevalue(which)
    start, goal = ROOMS.free_cell(0, 0), ROOMS.free_cell(4, 5)
    path = robot.shortest_path(robot.start_state(start), goal)
    assert path is not None
    rp = replay(robot, [s for s, _ in path], segment_seconds=0.06, settle_seconds=0.2)
    assert rp.reached_goal, rp.report()
    assert rp.max_deviation_cells < 1.0


# --------------------------------------------------------------------------- bad input


def _one_line_exit_2(proc, *fragments):
    err = proc.stderr
    assert proc.returncode == 2, (proc.returncode, err)
    assert len(err.strip().splitlines()) == 1 and err.endswith("\n"), err
    assert "Traceback" not in err and err.startswith("armtransfer arms: error:"), err
    for f in fragments:
        assert f in err, err
    return err


FREE_JOINT_XML = """<mujoco model="flying">
  <worldbody>
    <body name="platform" pos="0 0 0.3">
      <freejoint name="float"/>
      <geom type="box" size="0.05 0.05 0.01" mass="1"/>
      <body name="arm" pos="0 0 0.01">
        <joint name="swing" axis="0 0 1" range="-3 3"/>
        <geom type="capsule" size="0.01" fromto="0 0 0 0.2 0 0" mass="0.2"/>
        <site name="tip" pos="0.2 0 -0.3"/>
      </body>
    </body>
  </worldbody>
  <actuator><position joint="swing" kp="10"/></actuator>
</mujoco>
"""


@pytest.mark.slow
def test_cli_lists_a_menagerie_style_arm(files, ur5e):
    proc = run_cli("arms", "list", "--arm", "planar2", "--actions", "cartesian", "--arm-xml", str(files["ur5e"]),
                   "--tip-site", "attachment_site", "--tip-offset=0,0,0.12")
    assert proc.returncode == 0, proc.stderr
    table, _, notes = proc.stdout.partition("\n\n")
    rows = {line.split()[0]: line.split() for line in table.splitlines()[1:]}
    assert set(rows) == {"planar2:cartesian", "ur5e:cartesian"}
    assert rows["ur5e:cartesian"][1] == "6" and rows["ur5e:cartesian"][5] == "4/4"
    assert "automatic mount --base-pos=" in notes and "tool site attachment_site + (0, 0, 0.12) m" in notes


def test_cli_unknown_tip_site_lists_the_sites(files):
    proc = run_cli("arms", "list", "--arm-xml", str(files["ur5e"]), "--tip-site", "flange")
    _one_line_exit_2(proc, "'flange'", "attachment_site")


def test_cli_unknown_tip_site_on_a_file_without_sites(files):
    proc = run_cli("arms", "list", "--arm-xml", str(files["panda"]), "--tip-site", "tcp")
    _one_line_exit_2(proc, "'tcp'")


def test_cli_unknown_tip_body_lists_the_bodies(files):
    proc = run_cli("arms", "list", "--arm-xml", str(files["panda"]), "--tip-body", "gripper")
    _one_line_exit_2(proc, "'gripper'", "hand", "link7", "left_finger")


def test_cli_tip_site_and_tip_body_together_are_refused(files):
    proc = run_cli("arms", "list", "--arm-xml", str(files["ur5e"]), "--tip-site", "attachment_site",
                   "--tip-body", "wrist_3_link")
    _one_line_exit_2(proc, "--tip-site", "--tip-body")


@pytest.mark.parametrize("offset", ["0,0", "0,0,0.1,0", "a,0,0", "0,nan,0"])
def test_cli_tip_offset_must_be_three_finite_numbers(files, offset):
    proc = run_cli("arms", "list", "--arm-xml", str(files["ur5e"]), "--tip-site", "attachment_site",
                   f"--tip-offset={offset}")
    _one_line_exit_2(proc, "--tip-offset")


def test_cli_a_free_joint_is_refused(tmp_path):
    path = tmp_path / "flying.xml"
    path.write_text(FREE_JOINT_XML)
    proc = run_cli("arms", "list", "--arm-xml", str(path), "--tip-site", "tip")
    _one_line_exit_2(proc, "free joint")
