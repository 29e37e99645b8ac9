"""A hand that holds a pen (``--tool stylus``), and the cause named when a tool cannot pass.

Two arm files a user brings, each failing at default settings for its tool's width: a gripper
whose 22 mm fingers reach past its own TCP site (they ride just above the table, into the 2 cm
walls), and a planar arm holding a 12 mm pen (wider than a 1 cm door). For each, the cause is
named with the remedy, the remedy works, and (in the slow set) the arm then transfers from
``planar2:joint`` with both physics replays at the goal.
"""

import json

import numpy as np
import pytest

import menagerie_like as ml
from armtransfer.errors import ArmModelError
from armtransfer.ik.scene import STYLUS, build_scene
from armtransfer.ik.tool import STYLUS_LENGTH, STYLUS_RADIUS, Stylus, Tool, parse_held
from armtransfer.tasks.arms import arm_robot, tasks_solvable, walls_cause
from armtransfer.tasks.catalog import TABLE_I
from armtransfer.worlds.layout import ROOMS

from contract import refused

GRIPPER = dict(tip_site="pinch")
PEN = dict(tip_site="pen_tip")


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    out = tmp_path_factory.mktemp("held")
    return {name: ml.ALL[name](out) for name in ("ur5e_wide_gripper", "planar5_wide_pen", "planar5")}


@pytest.fixture(scope="module")
def gripper(files):
    return arm_robot(None, "cartesian", xml_path=files["ur5e_wide_gripper"], **GRIPPER)


@pytest.fixture(scope="module")
def pen(files):
    return arm_robot(None, "cartesian", xml_path=files["planar5_wide_pen"], **PEN)


def test_the_gripper_is_named_with_its_width_and_the_held_pen_as_remedy(gripper):
    assert gripper.arm.reach < 0.8 and tasks_solvable(gripper) < len(TABLE_I)
    cause = walls_cause(gripper)
    assert "_pad" in cause and "meets the walls (wall_" in cause
    width = float(cause.split(" mm across")[0].rsplit(", ", 1)[1])
    assert width == pytest.approx(2000 * ml.WIDE_PAD, abs=0.5)
    assert "a door is 10.0 mm wide" in cause and "--tool stylus" in cause and "--tip-offset" in cause


def test_the_pen_is_named_with_its_width_and_wider_cells_as_remedy(pen):
    assert pen.arm.reach < 0.8 and tasks_solvable(pen) < len(TABLE_I)
    cause = walls_cause(pen)
    assert cause.startswith("a geom of pen, 12.0 mm across at the walls' height")
    assert "--cell-size 0.016" in cause and "--tool" not in cause


def test_the_held_pen_lets_the_gripper_reach_every_task(files):
    robot = arm_robot(None, "cartesian", xml_path=files["ur5e_wide_gripper"], tool="stylus", **GRIPPER)
    assert robot.arm.reach >= 0.8 and tasks_solvable(robot) == len(TABLE_I)
    assert walls_cause(robot) == ""
    assert robot.arm.tool.held == Stylus() and "holding a 50 mm stylus 3 mm wide" in robot.arm.tool.describe()


@pytest.mark.slow  # 5 s: the remedy of a second cell size, compiled again; the held pen reaches by default
def test_wider_cells_let_the_pen_reach_every_task(files):
    robot = arm_robot(None, "cartesian", xml_path=files["planar5_wide_pen"], cell_size=0.016, **PEN)
    assert robot.arm.reach >= 0.8 and tasks_solvable(robot) == len(TABLE_I)


def test_the_scene_holds_a_capsule_from_the_tool_point_and_reads_the_cell_at_its_end(files):
    bare = build_scene(files["ur5e_wide_gripper"], Tool(site="pinch"), layout=ROOMS)
    held = build_scene(files["ur5e_wide_gripper"], Tool(site="pinch", held=Stylus(0.04, 0.002)), layout=ROOMS)
    import mujoco

    g = mujoco.mj_name2id(held.model, mujoco.mjtObj.mjOBJ_GEOM, "arm/" + STYLUS)
    assert g >= 0 and held.model.geom_type[g] == mujoco.mjtGeom.mjGEOM_CAPSULE
    assert held.model.geom_size[g][0] == pytest.approx(0.002) and held.model.geom_size[g][1] == pytest.approx(0.02)
    tips = []
    for scene in (bare, held):
        data = mujoco.MjData(scene.model)
        data.qpos[:] = scene.home
        mujoco.mj_kinematics(scene.model, data)
        site = mujoco.mj_name2id(scene.model, mujoco.mjtObj.mjOBJ_SITE, scene.tip)
        tips.append((data.site_xpos[site].copy(), data.site_xmat[site].reshape(3, 3)[:, 2].copy()))
    (p0, axis), (p1, _) = tips
    assert np.allclose(p1, p0 + 0.04 * axis, atol=1e-9)  # the pen's end, 4 cm along the tool axis
    assert held.clearance == pytest.approx(0.002)        # its round end, a radius past the point


def test_a_held_tool_changes_the_cache_key_and_no_tool_keeps_the_old_one():
    assert Tool(site="tip").key() == {"site": "tip", "body": None, "offset": [0.0, 0.0, 0.0]}
    assert Tool(site="tip", held="stylus:0.03").key()["held"] == {"stylus": [0.03, STYLUS_RADIUS]}


@pytest.mark.parametrize("text, length, radius", [
    ("stylus", STYLUS_LENGTH, STYLUS_RADIUS), ("stylus:0.08", 0.08, STYLUS_RADIUS), ("stylus:0.08:0.004", 0.08, 0.004)])
def test_held_tools_parse(text, length, radius):
    assert parse_held(text) == Stylus(length, radius)
    assert parse_held(parse_held(text).spec()) == parse_held(text)


@pytest.mark.parametrize("text, words", [
    ("pencil", "unknown held tool 'pencil'; valid tools: stylus"), ("stylus:x", "stylus length must be a number"),
    ("stylus:0", "stylus length (metres) must be in (0, 0.5]"), ("stylus:0.05:0.06", "stylus radius"),
    ("stylus:1:2:3", "stylus[:LENGTH[:RADIUS]]"), ("stylus:nan", "stylus length (metres) must be")])
def test_bad_held_tools_are_one_line(text, words):
    with pytest.raises(ArmModelError) as err:
        parse_held(text)
    assert words in str(err.value) and "\n" not in str(err.value)


def test_a_planar_arm_cannot_hold_a_pen(files):
    with pytest.raises(ArmModelError, match="moves in a plane at a fixed height"):
        build_scene(files["planar5"], Tool(site=None, body="stylus", held=Stylus()), layout=ROOMS)


@pytest.mark.parametrize("argv", [
    ["arms", "list", "--arm-xml", "ARM", "--tool", "pencil"],
    ["arms", "list", "--tool", "stylus"],          # --tool goes with --arm-xml
    ["matrix", "--robots", "custom:cartesian,planar2:joint", "--arm-xml", "ARM", "--tool", "stylus:-1", "--out", "m"],
])
def test_the_commands_refuse_a_bad_tool_in_one_line(argv, files, tmp_path, monkeypatch, capsys):
    argv = [str(files["ur5e_wide_gripper"]) if a == "ARM" else a for a in argv]
    line = refused(argv, tmp_path, monkeypatch, capsys)
    assert "tool" in line or "stylus" in line


def test_a_sweep_arm_table_takes_a_tool_and_checks_it(files, tmp_path):
    from armtransfer.experiments.sweep import SweepFileError, load

    good = tmp_path / "good.toml"
    good.write_text(f'[sweep]\nname = "t"\ntasks = [1]\npairs = [["planar2:joint", "g"]]\nmethods = ["none"]\n'
                    f'seeds = [0]\ntrials = 1\n[arms.g]\nxml = "{files["ur5e_wide_gripper"]}"\ntip_site = "pinch"\n'
                    'tool = "stylus:0.05"\n')
    assert load(good).spec["arms"]["g"]["tool"] == "stylus:0.05"
    bad = tmp_path / "bad.toml"
    bad.write_text(good.read_text().replace('tool = "stylus:0.05"', 'tool = "crayon"'))
    with pytest.raises(SweepFileError, match="arms.g: tool: unknown held tool 'crayon'"):
        load(bad)


def test_the_api_and_the_environment_take_a_tool(files):
    import gymnasium as gym

    import armtransfer

    with pytest.raises(armtransfer.ArmTransferError) as err:  # the bare gripper: the cause, named
        armtransfer.transfer(source="planar2:joint", target="custom:cartesian", arm_xml=files["ur5e_wide_gripper"],
                             arm_options=GRIPPER, methods=["none"], trials=1, seed=0)
    assert "22.0 mm across" in str(err.value) and "--tool stylus" in str(err.value)
    env = gym.make("armtransfer/ArmRooms-v0", arm=None, actions="cartesian", xml_path=files["ur5e_wide_gripper"],
                   tool="stylus", **GRIPPER)
    obs, _ = env.reset(seed=0)
    assert env.unwrapped.robot.arm.tool.held == Stylus()
    env.close()


@pytest.mark.slow  # two transfers with their physics replays, about a minute
@pytest.mark.rendering
@pytest.mark.parametrize("name, options", [
    ("ur5e_wide_gripper", ["--tip-site", "pinch", "--tool", "stylus"]),
    ("planar5_wide_pen", ["--tip-site", "pen_tip", "--cell-size", "0.016"]),
])
def test_the_remedied_arm_transfers_from_planar2_with_both_replays_at_the_goal(files, tmp_path, name, options, capsys):
    from armtransfer.cli import main

    out = tmp_path / "out"
    code = main(["arms", "--source", "planar2:joint", "--target", "custom:cartesian", "--arm-xml", str(files[name]),
                 *options, "--fast", "--out", str(out)])
    printed = capsys.readouterr().out
    assert code == 0, printed
    assert "replay source: " in printed and "replay target: " in printed
    assert printed.count("reached the goal cell: yes") == 2, printed
    arms = json.loads((out / "results.json").read_text())["arms"]
    assert arms["target"]["name"] == name
