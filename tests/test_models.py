"""The MJCF arms and the tabletop workspace."""

import math

import mujoco
import numpy as np
import pytest

from armtransfer.ik.scene import build_scene
from armtransfer.models import ARMS
from armtransfer.worlds.layout import ROOMS
from armtransfer.ik.workspace import wall_boxes

NAMED = [
    (mujoco.mjtObj.mjOBJ_BODY, "nbody"),
    (mujoco.mjtObj.mjOBJ_JOINT, "njnt"),
    (mujoco.mjtObj.mjOBJ_GEOM, "ngeom"),
    (mujoco.mjtObj.mjOBJ_SITE, "nsite"),
    (mujoco.mjtObj.mjOBJ_ACTUATOR, "nu"),
]


@pytest.mark.parametrize("arm", list(ARMS))
def test_arm_follows_the_naming_contract(arm):
    info = ARMS[arm]
    model = mujoco.MjModel.from_xml_path(str(info.xml_path))
    for obj, count in NAMED:
        for i in range(getattr(model, count)):
            assert mujoco.mj_id2name(model, obj, i), f"{arm}: unnamed {obj} {i}"
    assert mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, "tip") >= 0
    assert mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_KEY, "home") >= 0
    assert model.njnt == model.nq == info.dof == model.nu
    for j in range(model.njnt):
        assert model.jnt_type[j] == mujoco.mjtJoint.mjJNT_HINGE
        name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, j)
        a = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, name)
        assert a >= 0 and model.actuator_trnid[a, 0] == j
        assert model.actuator_biastype[a] == mujoco.mjtBias.mjBIAS_AFFINE  # a position servo
    assert (info.xml_path.parent / "README.md").is_file()


@pytest.mark.parametrize("arm", list(ARMS))
def test_one_second_of_random_control_has_no_warnings(arm):
    info = ARMS[arm]
    scene = build_scene(info.xml_path, "tip", info.mount_pos, info.mount_yaw, layout=ROOMS)
    model = scene.model
    data = mujoco.MjData(model)
    data.qpos[:] = scene.home
    data.ctrl[:] = scene.home
    mujoco.mj_forward(model, data)
    rng = np.random.default_rng(7)
    lo, hi = model.actuator_ctrlrange[:, 0], model.actuator_ctrlrange[:, 1]
    steps = int(round(1.0 / model.opt.timestep))
    for i in range(steps):
        if i % 50 == 0:
            data.ctrl[:] = rng.uniform(lo, hi)
        mujoco.mj_step(model, data)
    assert data.time == pytest.approx(1.0)
    warnings = {i: int(data.warning[i].number) for i in range(len(data.warning))}
    assert all(n == 0 for n in warnings.values()), warnings
    assert np.all(np.isfinite(data.qpos))


def _rot(axis, angle):
    c, s = math.cos(angle), math.sin(angle)
    if axis == "x":
        return np.array([[1, 0, 0, 0], [0, c, -s, 0], [0, s, c, 0], [0, 0, 0, 1]])
    return np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]])


def _trans(x, y, z):
    t = np.eye(4)
    t[:3, 3] = (x, y, z)
    return t


def _tip_of(model, data, q):
    data.qpos[:] = q
    mujoco.mj_kinematics(model, data)
    return data.site_xpos[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, "tip")].copy()


def test_ur5e_like_matches_the_published_standard_dh():
    d = (0.1625, 0, 0, 0.1333, 0.0997, 0.0996)
    a = (0, -0.425, -0.3922, 0, 0, 0)
    alpha = (math.pi / 2, 0, 0, math.pi / 2, -math.pi / 2, 0)
    model = mujoco.MjModel.from_xml_path(str(ARMS["ur5e_like"].xml_path))
    data = mujoco.MjData(model)
    rng = np.random.default_rng(0)
    site = model.site_pos[0]
    for _ in range(20):
        q = rng.uniform(-math.pi, math.pi, 6)
        t = np.eye(4)
        for i in range(6):
            t = t @ _rot("z", q[i]) @ _trans(0, 0, d[i]) @ _trans(a[i], 0, 0) @ _rot("x", alpha[i])
        # the tip site sits on the flange's z axis, `site[2] - d6` beyond it
        expected = (t @ np.array([0, 0, site[2] - d[5], 1]))[:3]
        assert np.allclose(_tip_of(model, data, q), expected, atol=1e-9)


def test_panda_like_matches_the_published_modified_dh():
    a = (0, 0, 0, 0.0825, -0.0825, 0, 0.088)
    d = (0.333, 0, 0.316, 0, 0.384, 0, 0)
    alpha = (0, -math.pi / 2, math.pi / 2, math.pi / 2, -math.pi / 2, math.pi / 2, math.pi / 2)
    model = mujoco.MjModel.from_xml_path(str(ARMS["panda_like"].xml_path))
    data = mujoco.MjData(model)
    rng = np.random.default_rng(1)
    tip_offset = model.site_pos[0][2]  # flange (0.107) + tool, along link 7's z
    assert tip_offset > 0.107
    for _ in range(20):
        q = rng.uniform(-2.5, 2.5, 7)
        t = np.eye(4)
        for i in range(7):
            t = t @ _rot("x", alpha[i]) @ _trans(a[i], 0, 0) @ _rot("z", q[i]) @ _trans(0, 0, d[i])
        expected = (t @ np.array([0, 0, tip_offset, 1]))[:3]
        assert np.allclose(_tip_of(model, data, q), expected, atol=1e-9)


@pytest.mark.parametrize("cell", [0.01, 0.02])
def test_mjcf_walls_cover_exactly_the_wall_cells(cell):
    mask = np.zeros_like(ROOMS.wall_mask)
    for centre, half in wall_boxes(ROOMS, cell):
        for y in range(ROOMS.lo, ROOMS.hi + 1):
            for x in range(ROOMS.lo, ROOMS.hi + 1):
                if np.all(np.abs(np.array([x, y]) * cell - centre[:2]) < half[:2]):
                    mask[y - ROOMS.lo, x - ROOMS.lo] = True
    assert np.array_equal(mask, ROOMS.wall_mask)


def test_scene_is_composed_with_every_element_named():
    info = ARMS["panda_like"]
    scene = build_scene(info.xml_path, "tip", info.mount_pos, info.mount_yaw, layout=ROOMS)
    model = scene.model
    for obj, count in NAMED:
        for i in range(getattr(model, count)):
            assert mujoco.mj_id2name(model, obj, i)
    assert scene.tip == "arm/tip"
    assert scene.env_geoms.sum() == 1 + len(wall_boxes(ROOMS))
