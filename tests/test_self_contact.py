"""The arm may not touch itself: a configuration in which two of its links collide is no
state, and a move through one is blocked. Pairs already in contact at home are the file's
own design and are allowed. (Real Menagerie arms fold into themselves: before this check
239 of the UR5e's 2,504 compiled states did.)"""

import mujoco
import numpy as np
import pytest

from armtransfer.ik.scene import ContactChecker, build_scene
from armtransfer.tasks.arms import arm_robot
from armtransfer.worlds.layout import ROOMS

# Three planar links at one height, so that a fold puts link3 across link1 (a pair MuJoCo
# does not filter: they are not parent and child). A tail on link2 sits inside the base's
# foot at home (j2 = 0): that pair is in contact by design.
FOLDER = """<mujoco model="folder"><compiler angle="radian"/><worldbody>
  <body name="base"><geom name="foot" type="cylinder" size="0.02 0.05" pos="0 0 0.05"/>
    <body name="link1" pos="0 0 0.12"><joint name="j1" axis="0 0 1" range="-3.1 3.1"/>
      <geom name="bar1" type="capsule" size="0.01" fromto="0 0 0 0.1 0 0"/>
      <body name="link2" pos="0.1 0 0"><joint name="j2" axis="0 0 1" range="-2.9 2.9"/>
        <geom name="bar2" type="capsule" size="0.01" fromto="0 0 0 0.08 0 0"/>
        <geom name="tail" type="sphere" size="0.01" pos="-0.1 0 -0.07"/>
        <body name="link3" pos="0.08 0 0"><joint name="j3" axis="0 0 1" range="-2.9 2.9"/>
          <geom name="bar3" type="capsule" size="0.01" fromto="0 0 0 0.08 0 0"/>
          <geom name="pen" type="cylinder" size="0.0015" fromto="0.08 0 0 0.08 0 -0.116"/>
          <site name="tip" pos="0.08 0 -0.116"/>
        </body></body></body></body></worldbody></mujoco>"""

MOUNT = (0.1, 0.1, 0.0)  # the base inside a room, clear of the walls
FOLDED = np.array([0.0, 2.6, 2.6])  # link3 comes back across link1


@pytest.fixture()
def folder(tmp_path):
    path = tmp_path / "folder.xml"
    path.write_text(FOLDER)
    return path


def _mujoco_contacts(checker: ContactChecker, q) -> list[tuple[int, int]]:
    """The geom pairs MuJoCo reports in contact at q, asked directly (not through the checker)."""
    m, d = checker.model, mujoco.MjData(checker.model)
    d.qpos[:] = q
    mujoco.mj_kinematics(m, d)
    mujoco.mj_collision(m, d)
    return [(int(d.contact.geom1[i]), int(d.contact.geom2[i])) for i in range(d.ncon)]


def test_a_fold_into_itself_is_a_contact_and_the_home_overlap_is_not(folder):
    checker = ContactChecker(build_scene(folder, "tip", MOUNT, 0.0, layout=ROOMS))
    assert checker.can_self_collide
    home = checker.scene.home
    assert not checker.touches(home) and checker.self_contacts(home) == []
    # the tail and the foot do touch at home: MuJoCo reports them, the checker allows them
    names = {tuple(sorted(mujoco.mj_id2name(checker.model, mujoco.mjtObj.mjOBJ_GEOM, g) for g in pair))
             for pair in _mujoco_contacts(checker, home)}
    assert names == {("arm/foot", "arm/tail")}

    env = checker.scene.env_geoms
    assert not any(env[a] or env[b] for a, b in _mujoco_contacts(checker, FOLDED))  # not the table, not a wall
    assert checker.self_contacts(FOLDED) == [("arm/link1", "arm/link3")]
    assert checker.touches(FOLDED)
    # a half fold keeps link3 clear of link1 (and the tail clear of the foot)
    assert not checker.touches(np.array([0.0, 1.2, 1.2]))


@pytest.mark.slow
def test_no_compiled_state_of_an_arm_touches_itself(folder, monkeypatch, arm_cache):
    options = dict(xml_path=folder, tip_site="tip", base_pos=MOUNT, base_yaw=0.0, joint_step=0.25,
                   cache=False)
    robot = arm_robot(None, "joint", **options)
    checker = ContactChecker(build_scene(folder, "tip", MOUNT, 0.0, layout=ROOMS))
    qs = np.asarray(robot.arm.qpos).reshape(robot.n_states, -1)
    assert all(checker.self_contacts(q) == [] for q in qs)
    # without the self-contact check the same lattice has folded states: the check is what removed them
    monkeypatch.setattr(ContactChecker, "_own", lambda self, g1, g2: np.zeros(len(g1), dtype=bool))
    unchecked = arm_robot(None, "joint", **options)
    monkeypatch.undo()
    folded = [q for q in np.asarray(unchecked.arm.qpos).reshape(unchecked.n_states, -1) if checker.self_contacts(q)]
    assert len(folded) > 0 and unchecked.n_states > robot.n_states


def test_the_built_in_arms_cannot_touch_themselves():
    """Their link geoms have contype 1 and conaffinity 0: MuJoCo never pairs two of them, so
    their compiled robots are what they were before the check."""
    from armtransfer.models import ARMS

    for name, info in ARMS.items():
        checker = ContactChecker(build_scene(info.xml_path, info.tip_site, (0.0, -0.4, 0.0), 0.0, layout=ROOMS))
        assert not checker.can_self_collide, name
