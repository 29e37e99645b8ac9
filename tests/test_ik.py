"""mink labelling, mink IK, and the joint action model's arcs."""

import mujoco
import numpy as np
import pytest

from armtransfer.ik.compile import PlanarFK
from armtransfer.errors import UnknownArmError
from armtransfer.ik.labels import Labeller, cells_of_xy
from armtransfer.tasks.arms import arm_robot, arm_scene, parse_robot_spec
from armtransfer.ik.solve import TipIK
from armtransfer.models import ARMS
from armtransfer.tasks.catalog import TABLE_I
from armtransfer.errors import ArmTransferError
from armtransfer.worlds.layout import ROOMS


@pytest.fixture(scope="module")
def scenes():
    return {arm: arm_scene(arm) for arm in ARMS}


@pytest.mark.parametrize("arm", list(ARMS))
def test_mink_label_equals_mujoco_site_label(arm, scenes):
    scene = scenes[arm]
    labeller = Labeller(scene)
    data = mujoco.MjData(scene.model)
    site = mujoco.mj_name2id(scene.model, mujoco.mjtObj.mjOBJ_SITE, scene.tip)
    rng = np.random.default_rng(3)
    lo = np.maximum(scene.lower, -np.pi)
    hi = np.minimum(scene.upper, np.pi)
    on_table = 0
    for _ in range(200):
        q = rng.uniform(lo, hi)
        data.qpos[:] = q
        mujoco.mj_kinematics(scene.model, data)
        expected = int(cells_of_xy(data.site_xpos[site], scene.cell, ROOMS))
        assert labeller.label(q) == expected
        on_table += expected >= 0
    assert on_table > 0


@pytest.mark.parametrize("arm", list(ARMS))
def test_ik_reaches_table_i_cell_centres(arm, scenes):
    scene = scenes[arm]
    ik = TipIK(scene, ARMS[arm].tip_down)
    labeller = Labeller(scene)
    q = scene.home
    for task in TABLE_I.values():
        for x, y in (task.start, task.goal):
            centre = np.array([x, y]) * scene.cell
            # warm-started from the previous solution, with restarts where that is stuck
            res = ik.solve_any(centre, q, np.random.default_rng(11))
            assert ik.ok(res), (arm, (x, y), res.error, res.tilt)
            tip = labeller.tip(res.q)
            assert np.linalg.norm(tip[:2] - centre) < 1e-3
            assert labeller.label(res.q) == ROOMS.cell(x, y)
            assert np.all(res.q >= scene.lower - 1e-6) and np.all(res.q <= scene.upper + 1e-6)
            if ARMS[arm].tip_down:
                assert abs(tip[2] - 0.004) < 1e-3 and res.tilt < 0.05
            q = res.q


@pytest.mark.parametrize("arm", ["planar2", "planar3", "planar4"])
def test_vectorised_planar_kinematics_agrees_with_mink(arm, scenes):
    scene = scenes[arm]
    fk = PlanarFK(scene)
    labeller = Labeller(scene)
    rng = np.random.default_rng(5)
    qs = rng.uniform(scene.lower, scene.upper, size=(50, scene.nq))
    xy = fk.tip(qs)
    for q, p in zip(qs, xy):
        assert np.allclose(labeller.tip(q)[:2], p, atol=1e-9)
    # and the analytic Jacobian matches finite differences
    q = qs[0]
    eps = 1e-6
    num = np.stack([(fk.tip(q + eps * e) - fk.tip(q - eps * e)) / (2 * eps) for e in np.eye(len(q))], 1)
    assert np.allclose(fk.jacobian(q), num, atol=1e-6)


def test_a_joint_action_traces_an_arc(scenes):
    robot = arm_robot("planar2", "joint")
    scene = scenes["planar2"]
    labeller = Labeller(scene)
    step = robot.arm.joint_step
    model = scene.model
    data = mujoco.MjData(model)
    data.qpos[:] = 0
    mujoco.mj_kinematics(model, data)
    axes = data.xanchor[:, :2].copy()  # joint axes in the table plane
    s = robot.start_state(ROOMS.cell(12, 12))  # mid room 1, clear of walls and limits
    for joint in range(2):
        for action in (2 * joint, 2 * joint + 1):
            tips, qs = [], []
            state = s
            for _ in range(6):
                qs.append(robot.arm.qpos[state])
                tips.append(labeller.tip(qs[-1])[:2])
                nxt = int(robot.next_state[state, action])
                if nxt == state:
                    break
                state = nxt
            assert len(tips) >= 4, "the arc should run a few steps from the Task 1 start"
            tips = np.array(tips)
            qs = np.array(qs)
            # only the moved joint changes, by exactly one lattice step per action
            dq = np.diff(qs, axis=0)
            assert np.allclose(np.abs(dq[:, joint]), step)
            assert np.allclose(np.delete(dq, joint, axis=1), 0)
            # the tip stays on a circle about that joint's axis ...
            if joint == 0:
                centre = axes[0]
            else:
                # the elbow is fixed while only joint 2 turns: it is where joint 2's axis is
                data.qpos[:] = qs[0]
                mujoco.mj_kinematics(model, data)
                centre = data.xanchor[1, :2]
            radii = np.linalg.norm(tips - centre, axis=1)
            assert np.ptp(radii) < 1e-9 and radii[0] > 0.01
            # ... sweeping equal angles, so it is an arc and not a straight line
            angles = np.unwrap(np.arctan2(*(tips - centre).T[::-1]))
            assert np.allclose(np.abs(np.diff(angles)), step)
            chord = tips[-1] - tips[0]
            rel = tips[1:-1] - tips[0]
            offsets = np.abs(chord[0] * rel[:, 1] - chord[1] * rel[:, 0]) / np.linalg.norm(chord)
            assert offsets.max() > 1e-4


def test_robot_specs_parse_and_reject_unknown_names():
    assert parse_robot_spec("planar2:joint") == ("planar2", "joint")
    assert parse_robot_spec("ur5e_like") == ("ur5e_like", "cartesian")
    with pytest.raises(UnknownArmError, match="valid arms: planar2, planar3"):
        parse_robot_spec("puma:joint")
    assert parse_robot_spec("panda_like:joint") == ("panda_like", "joint")  # over the 3D workspace
    with pytest.raises(UnknownArmError, match="valid action models: joint, cartesian, cartesian2"):
        parse_robot_spec("panda_like:polar")
    with pytest.raises(ArmTransferError, match="valid action models"):
        parse_robot_spec("planar2:polar")
