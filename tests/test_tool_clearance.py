"""A tool whose own geometry reaches past the tool point rides clear of the table by itself.

Files name a TCP between gripper fingers that reach past it, or a site at the end of a
round pen's axis. The scene measures how far the tool's geometry (the tool's body and what
hangs from it without a joint) reaches past the point along the tool axis; IK rides the
lowest point ``TIP_HEIGHT`` above the table and the cell is read at the point.
"""

import mujoco
import numpy as np
import pytest

import menagerie_like as ml
from armtransfer.ik.labels import cells_of_xy
from armtransfer.ik.scene import build_scene, tool_reach
from armtransfer.ik.solve import MAX_TIP_HEIGHT, TIP_HEIGHT
from armtransfer.ik.tool import Tool
from armtransfer.tasks.arms import arm_robot, tasks_solvable
from armtransfer.worlds.layout import ROOMS


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    out = tmp_path_factory.mktemp("tools")
    return {name: ml.ALL[name](out) for name in ("panda", "panda_tcp", "ur5e", "ur5e_gripper", "planar5_pen")}


def _tool(name) -> Tool:
    tip = ml.SUGGESTED[name]
    if "tip_body" in tip:
        return Tool(site=None, body=tip["tip_body"], offset=tip.get("tip_offset", (0.0, 0.0, 0.0)))
    return Tool(site=tip["tip_site"], offset=tip.get("tip_offset", (0.0, 0.0, 0.0)))


@pytest.mark.parametrize("name, reach, body", [
    ("panda_tcp", ml.FINGERTIP, "finger"),        # the fingertips, 2 cm past the TCP site
    ("ur5e_gripper", ml.GRIPPER_PAST, "_pad"),    # the finger slides' tips, 1.5 cm past it
    ("planar5_pen", ml.PEN_RADIUS, "pen"),        # the pen's round end, its radius past the site
    ("panda", 0.0, ""),                          # the tool point at the fingertips
    ("ur5e", 0.0, ""),                           # a 12 cm tool past the flange, no geometry there
])
def test_the_scene_measures_how_far_the_tool_reaches_past_its_point(files, name, reach, body):
    scene = build_scene(files[name], _tool(name), layout=ROOMS)
    assert scene.clearance == pytest.approx(reach, abs=1e-6)
    assert (body in scene.clearance_geom) if body else scene.clearance_geom == ""


def test_tool_reach_counts_only_the_tool_and_what_hangs_from_it():
    xml = """<mujoco><worldbody>
      <body name="link"><joint name="j" axis="0 0 1"/>
        <geom type="box" size="0.01 0.01 0.3" pos="0 0 -0.3"/>
        <body name="tool" pos="0.1 0 0">
          <site name="tip" pos="0 0 0" zaxis="0 0 -1"/>
          <geom type="sphere" size="0.005" pos="0 0 -0.002"/>
          <body name="finger" pos="0 0 0"><geom type="capsule" size="0.002" fromto="0 0 0 0 0 -0.01"/></body>
          <body name="loose" pos="0 0 0"><joint name="slide" type="slide" axis="0 0 1"/>
            <geom type="sphere" size="0.05" pos="0 0 -0.1"/></body>
          <geom type="sphere" size="0.03" pos="0 0 -0.1" contype="0" conaffinity="0"/>
        </body>
      </body></worldbody></mujoco>"""
    model = mujoco.MjModel.from_xml_string(xml)
    site = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, "tip")
    reach, geom = tool_reach(model, np.zeros(model.nq), site)
    # the finger's round end (0.012) beats the sphere (0.007); the link (no: it is the tool's
    # parent), the jointed body and the geom that collides with nothing do not count
    assert reach == pytest.approx(0.012)
    assert model.geom_bodyid[geom] == mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "finger")


def _lowest_point(scene, q) -> float:
    """The lowest point of the tool's geometry above the tabletop at q (MuJoCo distances to a
    plane far below, minus how far below it is)."""
    model, data = scene.model, mujoco.MjData(scene.model)
    data.qpos[:] = q
    mujoco.mj_kinematics(model, data)
    tip = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, scene.tip)
    reach, _ = tool_reach(model, q, tip, np.array([0.0, 0.0, -1.0]), scene.arm_geoms)
    return float(data.site_xpos[tip][2] - reach)


@pytest.mark.slow
def test_fingers_past_a_tcp_ride_clear_and_the_cell_is_read_at_the_tcp(files):
    mount = {k: v for k, v in ml.SUGGESTED["panda"].items() if k.startswith("base")}
    robot = arm_robot(None, "cartesian", xml_path=files["panda_tcp"], tip_site="tcp", **mount)
    assert robot.arm.reach >= 0.8 and tasks_solvable(robot) == 4
    assert robot.arm.clearance == pytest.approx(ml.FINGERTIP, abs=1e-6)
    # the TCP rides 2 cm higher than a bare point; the cell is the one under the TCP
    assert np.allclose(robot.arm.tip[:, 2], TIP_HEIGHT + ml.FINGERTIP, atol=1e-3)
    assert np.array_equal(cells_of_xy(robot.arm.tip, robot.arm.cell_size, ROOMS), robot.label)
    scene = build_scene(files["panda_tcp"], Tool(site="tcp"), robot.arm.mount, robot.arm.yaw, layout=ROOMS)
    for s in np.linspace(0, robot.n_states - 1, 12).astype(int):
        assert 0.002 <= _lowest_point(scene, robot.arm.qpos[s]) <= MAX_TIP_HEIGHT
    assert "reaches 20.0 mm past its point" in robot.arm.clearance_note()


def test_a_round_pen_at_a_mount_that_puts_it_in_the_table_says_how_far_to_raise_it(files):
    from armtransfer.errors import UnreachableTableError

    # the base frame on the tabletop puts the pen's site 1 mm up, its round end 2 mm into the table
    with pytest.raises(UnreachableTableError, match=r"pen.*reaches 3\.0 mm past the point; raise the base by 6\.0 mm"):
        arm_robot(None, "cartesian", xml_path=files["planar5_pen"], tip_site="pen_tip", base_pos=(-0.1, 0.0, 0.0),
                  base_yaw=0.0, cache=False)
