"""Replays that reach: a 7-joint arm with its own position servos, and an arm with torque motors
only, each replayed with its own actuators to the goal within half a cell; a motor too weak for
the path is named in one line, and the scene's own servos take over."""

import json

import pytest

import menagerie_like as ml
from armtransfer.ik.replay import replay
from armtransfer.ik.scene import torque_motors
from armtransfer.tasks.arms import arm_robot
from armtransfer.tasks.catalog import TABLE_I
from armtransfer.worlds.layout import ROOMS

UR5E_CHAIN = list(ml.UR5E_JOINTS)
MOUNTS = {"iiwa": dict(base_pos=(0.0, 0.555, 0.15), base_yaw=-1.5708),
          "ur5e_motors": dict(base_pos=(0.405, -0.405, 0.0), base_yaw=-2.6208)}
"""The mounts the automatic search finds for these arms (the slow tests search them), given here
so that the quick tests compile without the search."""
WEAK = 10.0
"""A shoulder-lift motor of this many N m cannot hold the UR5e-style arm's upper arm up."""


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    out = tmp_path_factory.mktemp("reach")
    return {name: ml.ALL[name](out) for name in ("ur5e_motors", "iiwa", "ur5e")}


@pytest.fixture(scope="module")
def motors(files):
    return arm_robot(None, "cartesian", xml_path=files["ur5e_motors"], **ml.SUGGESTED["ur5e_motors"],
                     **MOUNTS["ur5e_motors"])


@pytest.fixture(scope="module")
def iiwa(files):
    return arm_robot(None, "cartesian", xml_path=files["iiwa"], **ml.SUGGESTED["iiwa"], **MOUNTS["iiwa"])


def _states(robot, task: int = 1):
    start, goal = TABLE_I[task].cells(ROOMS)
    path = robot.shortest_path(robot.start_state(start), goal)
    assert path is not None
    return [s for s, _ in path]


def test_the_files_torque_motors_are_found_with_their_limits(files):
    found = torque_motors(files["ur5e_motors"], UR5E_CHAIN)
    assert [m.joint for m in found] == UR5E_CHAIN
    assert [m.actuators for m in found] == [(a,) for a in ml.UR5E_ACTUATORS]
    assert [(m.lower, m.upper) for m in found] == [(-150.0, 150.0)] * 3 + [(-28.0, 28.0)] * 3
    assert torque_motors(files["ur5e"], UR5E_CHAIN) == []  # position servos: none
    assert torque_motors(files["iiwa"], [f"joint{i}" for i in range(1, 8)]) == []


def test_a_torque_only_arm_reaches_the_goal_by_computed_torque_within_its_motors(motors):
    rp = replay(motors, _states(motors))
    report = rp.report()
    assert report["servos"] == "file" and "file_servos" not in report
    assert set(report["torque_motors"]) == set(UR5E_CHAIN)
    assert rp.reached_goal and rp.goal_offset_cells <= 0.5 and rp.max_tracking_error_cells < 0.5, report
    assert rp.shortfall() == "" and "shortfall" not in report


def test_a_motor_too_weak_for_the_path_is_named_and_the_scenes_servos_take_over(tmp_path):
    path = ml.ur5e_style(tmp_path, motors=True)
    text = path.read_text()
    line = '<motor class="ur5e/size3" name="shoulder_lift" joint="shoulder_lift_joint" ctrlrange="-150 150"/>'
    assert line in text
    path.write_text(text.replace(line, line.replace("-150 150", f"-{WEAK:g} {WEAK:g}")))
    weak = arm_robot(None, "cartesian", xml_path=path, **MOUNTS["ur5e_motors"], **ml.SUGGESTED["ur5e_motors"])
    states = _states(weak)
    theirs = replay(weak, states, servos="file")
    assert not theirs.reached_goal and theirs.goal_offset_cells > 0.5
    why = theirs.report()["shortfall"]
    assert "\n" not in why and "half a cell" in why and "actuator shoulder_lift was at its force limit" in why
    assert theirs.report()["torque_motors"]["shoulder_lift_joint"]["torque_range"] == [-WEAK, WEAK]
    own = replay(weak, states)
    assert own.settings["servos"] == "scene" and own.reached_goal, own.report()
    assert own.report()["file_servos"]["shortfall"] == why


def test_a_seven_joint_arm_with_its_own_position_servos_reaches_the_goal_with_them(iiwa):
    assert iiwa.arm.dof == 7
    for task in (1, 4):
        rp = replay(iiwa, _states(iiwa, task))
        assert rp.settings["servos"] == "file" and "torque_motors" not in rp.settings
        assert rp.reached_goal and rp.max_tracking_error_cells < 0.5, rp.report()


@pytest.mark.slow  # three transfers with their physics replays
@pytest.mark.rendering
@pytest.mark.parametrize("name", ["ur5e_motors", "iiwa", "panda"])
def test_the_arm_transfers_from_planar2_with_both_replays_at_the_goal(files, tmp_path, name, capsys):
    from armtransfer.cli import main

    xml = files[name] if name in files else ml.ALL[name](tmp_path / "arm")
    tip = ml.SUGGESTED[name]
    options = ([f"--tip-site={tip['tip_site']}"] if "tip_site" in tip else [f"--tip-body={tip['tip_body']}"])
    options.append("--tip-offset=" + ",".join(str(v) for v in tip["tip_offset"]))
    out = tmp_path / "out"
    code = main(["arms", "--source", "planar2:joint", "--target", "custom:cartesian", "--arm-xml", str(xml),
                 *options, "--fast", "--out", str(out)])
    printed = capsys.readouterr().out
    assert code == 0, printed
    assert printed.count("reached the goal cell: yes") == 2, printed
    assert "missed the goal" not in printed and "the scene's own servos" not in printed, printed
    assert ("the file's torque motors, by computed torque" in printed) == (name == "ur5e_motors"), printed
    result = json.loads((out / "results.json").read_text())
    assert result["arms"]["target"]["dof"] == (6 if name == "ur5e_motors" else 7)
    for rp in result["rollout"]["replays"]:
        assert rp["reached_goal"] and rp["max_tracking_error_cells"] < 0.5, rp
