"""How an arm file becomes a scene: the tool point, the chain, held joints,
servos of the scene's own, the file's own compiler settings, the base on a wall, sweep
files naming arms, the lattice guard and a camera that fits an arm mounted anywhere."""

import math

import mujoco
import numpy as np
import pytest

from armtransfer.errors import ArmModelError, ArmTransferError
from armtransfer.ik.replay import replay
from armtransfer.ik.scene import ContactChecker, build_scene
from armtransfer.ik.tool import Tool, parse_offset
from armtransfer.experiments import sweep as sweeps
from armtransfer.tasks.arms import arm_robot
from armtransfer.worlds.layout import ROOMS

# A SCARA with a two-finger gripper: slide fingers typed through a default class, a tendon
# over them driven by one actuator, a motor (no bias) on the elbow, degrees as the file says.
GRIPPER_SCARA = """<mujoco model="gripper_scara">
  <compiler angle="degree"/>
  <default>
    <default class="g/finger"><joint type="slide" axis="0 1 0" range="0 0.01"/></default>
  </default>
  <worldbody>
    <body name="upper" pos="0.05 0.02 0.15">
      <joint name="shoulder" axis="0 0 1" range="-170 170"/>
      <geom name="upper_geom" type="capsule" size="0.01" fromto="0 0 0 0.24 0 0"/>
      <body name="fore" pos="0.24 0 -0.03">
        <joint name="elbow" axis="0 0 1" range="-165 165"/>
        <geom name="fore_geom" type="capsule" size="0.01" fromto="0 0 0 0.2 0 0"/>
        <body name="pen" pos="0.2 0 0">
          <geom name="pen_geom" type="cylinder" size="0.0015" fromto="0 0 0 0 0 -0.115"/>
          <body name="left" pos="0 0.004 -0.02">
            <joint name="left_finger" class="g/finger"/>
            <geom name="left_geom" type="box" size="0.002 0.002 0.005" contype="0" conaffinity="0"/>
          </body>
          <body name="right" pos="0 -0.004 -0.02">
            <joint name="right_finger" class="g/finger"/>
            <geom name="right_geom" type="box" size="0.002 0.002 0.005" contype="0" conaffinity="0"/>
          </body>
        </body>
      </body>
    </body>
  </worldbody>
  <tendon><fixed name="split"><joint joint="left_finger" coef="0.5"/><joint joint="right_finger" coef="0.5"/></fixed></tendon>
  <equality><joint joint1="left_finger" joint2="right_finger"/></equality>
  <actuator>
    <general name="shoulder_servo" joint="shoulder" gainprm="50" biastype="affine" biasprm="0 -50 -5"/>
    <motor name="elbow_motor" joint="elbow" gear="20"/>
    <general name="grip" tendon="split" ctrlrange="0 255" gainprm="0.01" biastype="affine" biasprm="0 -1 -0.1"/>
  </actuator>
  <keyframe><key name="home" qpos="0.3 0.5 0.008 0.008"/></keyframe>
</mujoco>
"""


@pytest.fixture
def gripper_xml(tmp_path):
    path = tmp_path / "gripper_scara.xml"
    path.write_text(GRIPPER_SCARA)
    return path


def test_tip_offsets_are_three_finite_numbers():
    assert parse_offset("0,0,0.12") == (0.0, 0.0, 0.12)
    for bad in ("0,0", "0,0,0,0", "x,0,0", "0,inf,0", ""):
        with pytest.raises(ArmModelError, match="--tip-offset must be three finite numbers"):
            parse_offset(bad)
    with pytest.raises(ArmModelError, match="exactly one of a tip site or a tip body"):
        Tool(site="a", body="b")
    with pytest.raises(ArmModelError, match="three finite numbers"):
        Tool(site="a", offset=(0.0, float("nan"), 0.0))


def test_the_chain_is_base_to_tool_and_the_fingers_are_held_at_home(gripper_xml):
    original = mujoco.MjModel.from_xml_path(str(gripper_xml))
    scene = build_scene(gripper_xml, Tool(site=None, body="pen", offset=(0, 0, -0.116)), layout=ROOMS)
    assert scene.chain == ("shoulder", "elbow") and scene.nq == 2
    assert dict(scene.held) == pytest.approx({"left_finger": 0.008, "right_finger": 0.008})
    # angles as the file says (degrees), not re-read in the scene's radians
    assert scene.lower == pytest.approx(np.radians([-170, -165])) and scene.home == pytest.approx([0.3, 0.5])
    # a held finger sits where its home value puts it in the file's own model
    d0 = mujoco.MjData(original)
    d0.qpos[:] = original.key_qpos[0]
    mujoco.mj_kinematics(original, d0)
    d1 = mujoco.MjData(scene.model)
    d1.qpos[:] = scene.home
    mujoco.mj_kinematics(scene.model, d1)
    for finger in ("left", "right"):
        here = d1.xpos[mujoco.mj_name2id(scene.model, mujoco.mjtObj.mjOBJ_BODY, f"arm/{finger}")]
        there = d0.xpos[mujoco.mj_name2id(original, mujoco.mjtObj.mjOBJ_BODY, finger)]
        assert here == pytest.approx(there, abs=1e-9)
    # the tendon, its actuator and the equality went with the fingers
    assert scene.model.ntendon == 0 and scene.model.neq == 0


def test_every_chain_joint_gets_a_position_servo(gripper_xml):
    scene = build_scene(gripper_xml, Tool(site=None, body="pen", offset=(0, 0, -0.116)), layout=ROOMS)
    names = [mujoco.mj_id2name(scene.model, mujoco.mjtObj.mjOBJ_ACTUATOR, a) for a in range(scene.model.nu)]
    assert names == ["arm/shoulder_servo", "arm/servo_elbow"]  # the motor cannot hold a position
    assert np.all(scene.model.actuator_biastype == mujoco.mjtBias.mjBIAS_AFFINE)
    assert np.all(scene.model.actuator_trntype == mujoco.mjtTrn.mjTRN_JOINT)


def test_a_gripper_arm_with_a_motor_compiles_and_replays(gripper_xml):
    robot = arm_robot(None, "cartesian", xml_path=gripper_xml, tip_body="pen", tip_offset=(0, 0, -0.116),
                      base_pos=(-0.1, 0.0, 0.0), base_yaw=0.0)
    assert robot.name == "gripper_scara:cartesian" and robot.arm.dof == 2
    assert robot.arm.held == (("left_finger", 0.008), ("right_finger", 0.008))
    start, goal = ROOMS.free_cell(10, 10), ROOMS.free_cell(15, 16)
    path = robot.shortest_path(robot.start_state(start), goal)
    rp = replay(robot, [s for s, _ in path])
    assert rp.reached_goal, rp.report()


def test_a_base_standing_in_a_wall_is_seen(tmp_path):
    path = tmp_path / "post.xml"
    path.write_text("""<mujoco model="post"><compiler angle="radian"/><worldbody>
      <body name="base"><geom name="foot" type="box" size="0.02 0.02 0.01" pos="0 0 0.01"/>
        <body name="link" pos="0 0 0.2"><joint name="turn" axis="0 0 1"/>
          <geom name="bar" type="capsule" size="0.005" fromto="0 0 0 0.1 0 0"/>
          <site name="tip" pos="0.1 0 -0.198"/></body></body></worldbody></mujoco>""")
    on_wall = ContactChecker(build_scene(path, "tip", (-0.03, 0.1, 0.0), 0.0, layout=ROOMS))
    in_room = ContactChecker(build_scene(path, "tip", (0.1, 0.1, 0.0), 0.0, layout=ROOMS))
    assert on_wall.base_on_wall() and not in_room.base_on_wall()


def test_a_lattice_too_large_is_refused_in_one_line(scara_xml):
    with pytest.raises(ArmTransferError, match="joint lattice .* points") as err:
        arm_robot(None, "joint", xml_path=scara_xml, tip_site="pen_tip", base_pos=(-0.1, 0.0, 0.0),
                  joint_step=0.001, cache=False)
    assert "\n" not in str(err.value)


def test_a_sweep_file_names_its_own_arms(tmp_path, scara_xml):
    raw = {"arms": {"scara": {"xml": scara_xml.name, "tip_site": "pen_tip", "base_pos": [-0.1, 0, 0]}},
           "sweep": {"start_goal": [["10,10", "15,15"]], "pairs": [["fine", "scara:cartesian"]],
                     "methods": ["none"]}}
    spec = sweeps.normalise(raw, base=scara_xml.parent)
    assert spec["arms"]["scara"]["xml"] == str(scara_xml.resolve())
    run = sweeps.expand(spec)[0]
    assert run.arms == spec["arms"]
    other = dict(raw, arms={"scara": dict(raw["arms"]["scara"], base_pos=[-0.12, 0, 0])})
    assert sweeps.expand(sweeps.normalise(other, base=scara_xml.parent))[0].key() != run.key()
    from armtransfer.commands.sweep import check_runs

    robots = check_runs([run])
    assert robots["scara:cartesian"].name == "scara:cartesian" and robots["scara:cartesian"].arm.dof == 2
    for arms, message in (({"a": {"tip_site": "t"}}, "needs xml"), ({"a": {"xml": "x", "colour": 1}}, "unknown key"),
                          ({"a": {"xml": "x", "tip_offset": [0, 0]}}, "three finite numbers"),
                          ({"a": {"xml": "x", "tip_site": "t", "tip_body": "b"}}, "not both")):
        with pytest.raises(sweeps.SweepFileError, match=message):
            sweeps.normalise(dict(raw, arms=arms))


def test_the_camera_fits_an_arm_mounted_far_from_the_table(scara_xml):
    from armtransfer.ik.render import _camera_axes, scene_points, table_camera, view_extent

    near = build_scene(scara_xml, "pen_tip", (-0.1, 0.0, 0.0), 0.0, layout=ROOMS)
    far = build_scene(scara_xml, "pen_tip", (-0.6, 0.0, 0.0), 0.0, layout=ROOMS)
    assert view_extent(far, 320, 240) > view_extent(near, 320, 240)
    _, right, up = _camera_axes(-70.0)
    cam = table_camera(far, 320, 240)
    half_v = view_extent(far, 320, 240) / 2
    half_h = half_v * 320 / 240
    points, radii = scene_points(far)
    rel = points - np.array(cam.lookat)
    assert np.all(np.abs(rel @ up) + radii <= half_v) and np.all(np.abs(rel @ right) + radii <= half_h)
    assert math.isfinite(cam.distance) and cam.distance > 0


def test_arm_rooms_env_takes_the_tool_and_mount_options(gripper_xml):
    import gymnasium as gym
    from gymnasium.utils.env_checker import check_env

    import armtransfer

    env = gym.make("armtransfer/ArmRooms-v0", xml_path=str(gripper_xml), actions="cartesian", tip_body="pen",
                   tip_offset=(0, 0, -0.116), base_pos=(-0.1, 0.0, 0.0), base_yaw=0.0, arm_name="grip",
                   start=(10, 10), goal=(15, 16))
    robot = env.unwrapped.robot
    assert robot.name == "grip:cartesian" and robot.arm.tool.body == "pen" and robot.arm.mount_source == "given"
    check_env(env.unwrapped, skip_render_check=True)
    env.close()


def test_mount_candidates_script_lists_and_compiles(scara_xml, capsys):
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parent.parent / "research" / "mount_candidates.py"
    spec = importlib.util.spec_from_file_location("mount_candidates", path)
    script = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(script)
    assert script.main([str(scara_xml), "--tip-site", "pen_tip", "--compile", "1"]) == 0
    out = capsys.readouterr().out
    assert "25 candidates estimated" in out and out.count("reach ") == 1 and "Table I solvable" in out
    assert out.count("estimate ") == 25
