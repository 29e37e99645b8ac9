"""The Menagerie-style test arms (tests/menagerie_like.py) are valid MuJoCo models with the
traits they stand for: plain MuJoCo loads and simulates them without a warning, as
Menagerie's own tests require of its models."""

import re
import xml.etree.ElementTree as ET

import mujoco
import numpy as np
import pytest

import menagerie_like as ml


@pytest.fixture(scope="module")
def arms(tmp_path_factory):
    out = tmp_path_factory.mktemp("menagerie_like")
    return {name: make(out) for name, make in ml.ALL.items()}


def _model(path):
    return mujoco.MjModel.from_xml_path(str(path))


def _names(model, kind, count):
    return [mujoco.mj_id2name(model, kind, i) for i in range(count)]


@pytest.mark.parametrize("name", list(ml.ALL))
def test_compiles_and_steps_under_random_controls_without_warnings(arms, name):
    model = _model(arms[name])
    data = mujoco.MjData(model)
    key = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_KEY, "home")
    if key >= 0:
        mujoco.mj_resetDataKeyframe(model, data, key)
    rng = np.random.default_rng(0)
    lo, hi = model.actuator_ctrlrange.T
    assert model.nu > 0 and np.all(lo < hi)
    for _ in range(int(round(1.0 / model.opt.timestep))):
        data.ctrl[:] = rng.uniform(lo, hi)
        mujoco.mj_step(model, data)
    warnings = {mujoco.mjtWarning(i).name: data.warning[i].number for i in range(len(data.warning))
                if data.warning[i].number}
    assert warnings == {}
    assert data.time == pytest.approx(1.0) and np.all(np.isfinite(data.qpos))


@pytest.mark.parametrize("name", list(ml.ALL))
def test_no_contacts_at_the_home_pose(arms, name):
    model = _model(arms[name])
    data = mujoco.MjData(model)
    key = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_KEY, "home")
    if key >= 0:
        mujoco.mj_resetDataKeyframe(model, data, key)
    mujoco.mj_forward(model, data)
    bodies = [(model.geom_bodyid[c.geom1], model.geom_bodyid[c.geom2]) for c in data.contact[:data.ncon]]
    assert data.ncon == 0, bodies


@pytest.mark.parametrize("name, mass", [("ur5e", 20.6), ("panda", 18.0), ("panda_nohand", 17.2)])
def test_masses_are_the_real_arms(arms, name, mass):
    model = _model(arms[name])
    assert model.body_subtreemass[0] == pytest.approx(mass, rel=0.1)
    assert np.all(model.body_mass[1:] > 0) and np.all(model.body_inertia[1:] > 0)
    assert np.all(model.dof_armature > 0)


@pytest.mark.parametrize("name", list(ml.ALL))
def test_meshes_live_in_the_meshdir_folder(arms, name):
    path = arms[name]
    root = ET.parse(path).getroot()
    meshdir = root.find("compiler").get("meshdir")
    files = [m.get("file") for m in root.iter("mesh")]
    assert meshdir and files
    for f in files:
        mesh = path.parent / meshdir / f
        assert mesh.is_file() and mesh.stat().st_size < 4096, mesh
    assert not any((path.parent / f).exists() for f in files)  # only through meshdir
    model = _model(path)
    assert model.nmesh == len(files) and np.all(model.mesh_vertnum >= 8)


def test_class_names_have_slashes_that_dm_control_rejects(arms):
    from dm_control import mjcf

    for name in ("ur5e", "panda", "so100", "planar5"):
        classes = [d.get("class") for d in ET.parse(arms[name]).getroot().iter("default") if d.get("class")]
        assert any("/" in c for c in classes), name
    with pytest.raises(Exception, match="cannot contain a '/'"):
        mjcf.from_path(str(arms["ur5e"]))


def test_ur5e_style(arms):
    model = _model(arms["ur5e"])
    assert model.nq == 6 and set(model.jnt_type.tolist()) == {int(mujoco.mjtJoint.mjJNT_HINGE)}
    assert _names(model, mujoco.mjtObj.mjOBJ_SITE, model.nsite) == ["attachment_site"]
    assert "ur5e" in ET.parse(arms["ur5e"]).getroot().get("model")
    joints = _names(model, mujoco.mjtObj.mjOBJ_JOINT, model.njnt)
    actuators = _names(model, mujoco.mjtObj.mjOBJ_ACTUATOR, model.nu)
    assert not set(joints) & set(actuators)
    assert np.all(model.actuator_biastype == mujoco.mjtBias.mjBIAS_AFFINE)
    assert np.allclose(model.actuator_biasprm[:, 1], -model.actuator_gainprm[:, 0])
    assert model.nkey == 1 and np.allclose(model.key_qpos[0], ml.UR5E_HOME)
    # the flange is d6 beyond the wrist-3 joint, its z axis along the wrist-3 axis
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, 0)
    mujoco.mj_kinematics(model, data)
    site_z = data.site_xmat[0].reshape(3, 3)[:, 2]
    assert np.allclose(site_z, data.xaxis[5], atol=1e-9)
    assert np.dot(data.site_xpos[0] - data.xanchor[5], site_z) == pytest.approx(0.0996)
    # the home pose points the flange down
    assert site_z[2] == pytest.approx(-1.0, abs=1e-3)


def test_panda_style_with_hand(arms):
    path = arms["panda"]
    model = _model(path)
    assert model.nsite == 0
    assert model.nq == 9 and model.njnt == 9
    types = model.jnt_type
    assert list(types[:7]) == [mujoco.mjtJoint.mjJNT_HINGE] * 7
    assert list(types[7:]) == [mujoco.mjtJoint.mjJNT_SLIDE] * 2
    root = ET.parse(path).getroot()
    fingers = [j for j in root.iter("joint") if j.get("name", "").startswith("finger")]
    assert fingers and all(j.get("type") is None for j in fingers)  # the type comes from the class
    assert model.ntendon == 1 and model.neq == 1 and model.nkey == 1 and model.key_qpos.shape == (1, 9)
    tendon = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_TENDON, "split")
    assert tendon >= 0
    trn = model.actuator_trntype
    assert list(trn).count(mujoco.mjtTrn.mjTRN_TENDON) == 1 and model.actuator_trnid[-1, 0] == tendon
    assert mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "hand") >= 0
    # the fingertips are PANDA_TCP along the hand's z; the hand points down at home
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, 0)
    mujoco.mj_forward(model, data)
    hand = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "hand")
    z = data.xmat[hand].reshape(3, 3)[:, 2]
    assert z[2] == pytest.approx(-1.0, abs=1e-3)
    lowest = min(data.geom_xpos[g][2] - model.geom_size[g][2] for g in range(model.ngeom)
                 if model.geom_bodyid[g] in (hand + 1, hand + 2) and model.geom_contype[g])
    assert lowest == pytest.approx(data.xpos[hand][2] - ml.PANDA_TCP, abs=1e-6)


def test_panda_fingers_open_together(arms):
    model = _model(arms["panda"])
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, 0)
    data.ctrl[-1] = 255  # fully open
    for _ in range(500):
        mujoco.mj_step(model, data)
    assert data.qpos[7] == pytest.approx(0.04, abs=2e-3) and data.qpos[8] == pytest.approx(data.qpos[7], abs=1e-3)


def test_panda_style_without_hand(arms):
    model = _model(arms["panda_nohand"])
    assert model.nq == 7 and model.ntendon == 0 and model.neq == 0
    assert _names(model, mujoco.mjtObj.mjOBJ_SITE, model.nsite) == ["attachment_site"]
    assert model.key_qpos.shape == (1, 7)


def test_so100_style(arms):
    model = _model(arms["so100"])
    assert ET.parse(arms["so100"]).getroot().get("model") == "so_arm100"
    joints = _names(model, mujoco.mjtObj.mjOBJ_JOINT, model.njnt)
    assert joints == ["Rotation", "Pitch", "Elbow", "Wrist_Pitch", "Wrist_Roll", "Jaw"]
    assert set(model.jnt_type.tolist()) == {int(mujoco.mjtJoint.mjJNT_HINGE)}
    assert model.nsite == 0 and model.nkey == 0
    jaw = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, "Jaw")
    fixed = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "Fixed_Jaw")
    assert model.body_parentid[model.jnt_bodyid[jaw]] == fixed
    assert model.jnt_bodyid[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, "Wrist_Roll")] == fixed
    # at qpos0 the jaws point down and the roll axis is the jaw axis
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    z = data.xmat[fixed].reshape(3, 3)[:, 2]
    assert z[2] == pytest.approx(-1.0) and np.allclose(data.xaxis[4], z)
    tip = data.xpos[fixed] + ml.SO100_JAW * z
    lowest = min(data.geom_xpos[g][2] - model.geom_size[g][2] for g in range(model.ngeom)
                 if model.geom_contype[g] and model.geom_type[g] == mujoco.mjtGeom.mjGEOM_BOX)
    assert lowest == pytest.approx(tip[2], abs=1e-6)


def test_planar5_is_straight_and_singular_at_qpos0(arms):
    model = _model(arms["planar5"])
    assert model.nq == 5 and model.nkey == 0 and model.nsite == 0
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    assert np.allclose(np.abs(data.xaxis[:, 2]), 1.0)
    stylus = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "stylus")
    assert data.xpos[stylus] == pytest.approx([sum(ml.PLANAR5_LINKS), 0.0, ml.PLANAR5_TIP_CLEARANCE])
    jacp = np.zeros((3, model.nv))
    mujoco.mj_jacBody(model, data, jacp, None, stylus)
    assert np.linalg.matrix_rank(jacp[:2], tol=1e-9) == 1  # straight: the tip cannot move radially
    assert not re.search(r"<key", arms["planar5"].read_text())




def test_iiwa_style_has_seven_joints_and_position_servos_of_its_own(arms):
    model = _model(arms["iiwa"])
    root = ET.parse(arms["iiwa"]).getroot()
    assert model.nq == 7 and model.nu == 7 and root.find("default") is None  # no classes
    assert [a.tag for a in root.find("actuator")] == ["position"] * 7
    assert np.all(model.actuator_biastype == mujoco.mjtBias.mjBIAS_AFFINE)
    assert np.allclose(model.actuator_gainprm[:, 0], ml.IIWA_KP)
    assert np.allclose(model.actuator_forcerange[:, 1], ml.IIWA_FORCE)
    assert _names(model, mujoco.mjtObj.mjOBJ_SITE, model.nsite) == ["attachment_site"]
    assert model.key_qpos.shape == (1, 7)


def test_ur5e_motors_has_torque_motors_only(arms):
    model = _model(arms["ur5e_motors"])
    root = ET.parse(arms["ur5e_motors"]).getroot()
    assert root.get("model") == "ur5e_motors" and [a.tag for a in root.find("actuator")] == ["motor"] * 6
    assert np.all(model.actuator_biastype == mujoco.mjtBias.mjBIAS_NONE)
    assert np.allclose(model.actuator_ctrlrange[:, 1], [150] * 3 + [28] * 3)
    assert model.nkey == 1 and np.allclose(model.key_qpos[0], ml.UR5E_HOME)
