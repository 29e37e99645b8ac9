"""Compiling arms into discrete robots: Table I solvability, walls, wind, cache, BYO arms."""

import numpy as np
import pytest

from armtransfer.ik import cache
from armtransfer.ik.compile import PlanarFK
from armtransfer.errors import ArmModelError, UnreachableTableError
from armtransfer.ik.labels import Labeller, cells_of_xy
from armtransfer.tasks.arms import arm_robot, arm_scene
from armtransfer.ik.scene import ContactChecker
from armtransfer.tasks.catalog import TABLE_I
from armtransfer.errors import ArmTransferError
from armtransfer.worlds.layout import ROOMS

DEFAULT_ROBOTS = [("planar2", "joint"), ("planar2", "cartesian"), ("ur5e_like", "cartesian"),
                  ("panda_like", "cartesian")]


@pytest.fixture(scope="module")
def robots():
    return {f"{a}:{m}": arm_robot(a, m) for a, m in DEFAULT_ROBOTS}


@pytest.mark.parametrize("spec", [f"{a}:{m}" for a, m in DEFAULT_ROBOTS])
def test_default_robots_solve_every_table_i_task(spec, robots):
    robot = robots[spec]
    assert robot.name == spec
    for task in TABLE_I.values():
        start, goal = task.cells()
        path = robot.shortest_path(robot.start_state(start), goal)
        assert path is not None, (spec, task.name)
        assert robot.label[path[-1][0]] == goal


@pytest.mark.parametrize("spec", [f"{a}:{m}" for a, m in DEFAULT_ROBOTS])
def test_states_are_free_cells_and_mink_agrees_with_their_labels(spec, robots):
    robot = robots[spec]
    assert ROOMS.free[robot.label].all()
    assert robot.arm.qpos.shape == (robot.n_states, robot.arm.dof)
    assert 0.5 < robot.arm.reach <= 1.0
    labeller = Labeller(arm_scene(robot.arm.name))
    rng = np.random.default_rng(2)
    for s in rng.choice(robot.n_states, 40, replace=False):
        assert labeller.label(robot.arm.qpos[s]) == robot.label[s]
    can = robot.canonical[robot.canonical >= 0]
    assert np.array_equal(np.sort(robot.label[can]), np.unique(robot.label))


@pytest.mark.slow  # 6 s; test_walls_hold.py checks door crossings of cartesian moves against the walls by default
def test_walls_block_cartesian_moves(robots):
    robot = robots["planar2:cartesian"]
    F, B, R, L = range(4)
    s = robot.start_state(ROOMS.cell(-2, 0))  # room 1, against the wall x = -3
    assert robot.next_state[s, L] == s
    t = robot.next_state[s, R]
    assert ROOMS.xy(int(robot.label[t])) == (-1, 0)
    west = robot.start_state(ROOMS.cell(-4, 0))
    assert robot.wind_state[west] == west  # the wind cannot push through the wall either
    assert ROOMS.xy(int(robot.label[robot.wind_state[s]])) == (-1, 0)
    door = robot.start_state(ROOMS.cell(-2, 10))  # through the door (-3, 10)
    assert ROOMS.xy(int(robot.label[robot.next_state[door, L]])) == (-3, 10)
    coarse = arm_robot("planar2", "cartesian2")
    c = coarse.start_state(ROOMS.cell(-2, 0))
    assert coarse.next_state[c, L] == c  # a 2-cell move cannot jump the wall
    c = coarse.start_state(ROOMS.cell(-2, 10))
    assert ROOMS.xy(int(coarse.label[coarse.next_state[c, L]])) == (-4, 10)


def test_no_joint_move_passes_over_a_wall(robots):
    robot = robots["planar2:joint"]
    scene = arm_scene("planar2")
    fk = PlanarFK(scene)
    q = robot.arm.qpos
    for a in range(robot.n_actions):
        moved = robot.next_state[:, a] != np.arange(robot.n_states)
        qa, qb = q[moved], q[robot.next_state[moved, a]]
        for t in np.linspace(0, 1, 21):
            cells = cells_of_xy(fk.tip(qa + (qb - qa) * t), scene.cell, ROOMS)
            assert (cells >= 0).all() and ROOMS.free[cells].all()
    # and MuJoCo sees the stylus in a wall: the lattice point over wall cell (-3, 0)
    contact = ContactChecker(scene)
    labeller = Labeller(scene)
    from armtransfer.ik.solve import TipIK

    res = TipIK(scene, False).solve(np.array([-0.03, -0.05]), scene.home)
    assert ROOMS.wall_mask[-5 - ROOMS.lo, -3 - ROOMS.lo] and labeller.label(res.q) == ROOMS.cell(-3, -5)
    assert contact.touches(res.q)


def test_wind_pushes_one_cell_towards_plus_x(robots):
    for spec, robot in robots.items():
        pushed = robot.wind_state != np.arange(robot.n_states)
        assert pushed.mean() > 0.5, spec
        src = np.array([ROOMS.xy(int(c)) for c in robot.label[pushed]])
        dst = np.array([ROOMS.xy(int(c)) for c in robot.label[robot.wind_state[pushed]]])
        assert np.array_equal(dst - src, np.tile([1, 0], (len(src), 1))), spec


def test_cache_hits_misses_and_rebuilds(tmp_path, monkeypatch):
    monkeypatch.setenv("ARMTRANSFER_CACHE", str(tmp_path))
    first = arm_robot("planar2", "joint")
    assert first.arm.cache == "miss"
    second = arm_robot("planar2", "joint")
    assert second.arm.cache == "hit"
    assert np.array_equal(first.next_state, second.next_state)
    assert np.array_equal(first.arm.qpos, second.arm.qpos)
    (entry,) = list(tmp_path.glob("*.npz"))
    # a flipped byte is a corrupt entry: detected and rebuilt
    data = bytearray(entry.read_bytes())
    data[len(data) // 2] ^= 0xFF
    entry.write_bytes(bytes(data))
    rebuilt = arm_robot("planar2", "joint")
    assert rebuilt.arm.cache == "corrupt"
    assert np.array_equal(rebuilt.next_state, first.next_state)
    assert arm_robot("planar2", "joint").arm.cache == "hit"
    # a truncated entry too
    entry.write_bytes(entry.read_bytes()[:100])
    assert arm_robot("planar2", "joint").arm.cache == "corrupt"
    # an entry written for other inputs (stale) is detected by its stored key
    arrays, status = cache.load("planar2:joint", first.arm.key)
    assert status == "hit"
    cache.save("planar2:joint", first.arm.key, {**arrays})
    other = "0" * 64
    np.savez(entry, **arrays, __key__=np.array(other), __checksum__=np.array("x"))
    assert arm_robot("planar2", "joint").arm.cache == "stale"
    # a different workspace (cell size) is a different key: a miss, not a hit
    assert arm_robot("planar2", "joint", cell_size=0.02).arm.cache == "miss"
    assert arm_robot("planar2", "joint", cache=False).arm.cache == "off"



def test_two_processes_that_want_one_arm_at_once_compile_it_once(tmp_path):
    """The cache's build lock: the second process waits for the first, then loads its entry."""
    import os
    import subprocess
    import sys

    code = ("from armtransfer.tasks.arms import arm_robot\n"
            "print(arm_robot('planar2', 'joint', progress=True).arm.cache)\n")
    env = dict(os.environ, ARMTRANSFER_CACHE=str(tmp_path / "cache"))
    procs = [subprocess.Popen([sys.executable, "-c", code], env=env, stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, text=True) for _ in range(2)]
    outs = [p.communicate(timeout=300) for p in procs]
    assert [p.returncode for p in procs] == [0, 0], [err[-1000:] for _, err in outs]
    assert sorted(out.strip() for out, _ in outs) == ["hit", "miss"]
    assert sum(err.count("compiling planar2:joint") for _, err in outs) == 1
    assert len(list((tmp_path / "cache").glob("*.npz"))) == 1

BYO_ARM = """
<mujoco model="my_scara"><compiler angle="radian"/>
  <worldbody>
    <body name="column" pos="0.05 0.02 0.2">
      <geom name="column_geom" type="cylinder" size="0.02 0.01" contype="1" conaffinity="0"/>
      <body name="upper" pos="0 0 -0.05">
        <joint name="shoulder" type="hinge" axis="0 0 1" range="-3 3"/>
        <geom name="upper_geom" type="capsule" size="0.01" fromto="0 0 0 0.24 0 0" contype="1" conaffinity="0"/>
        <body name="fore" pos="0.24 0 -0.03">
          <joint name="elbow" type="hinge" axis="0 0 1" range="-2.9 2.9"/>
          <geom name="fore_geom" type="capsule" size="0.01" fromto="0 0 0 0.2 0 0" contype="1" conaffinity="0"/>
          <geom name="pen" type="cylinder" size="0.0015" fromto="0.2 0 0 0.2 0 -0.115" contype="1" conaffinity="0"/>
          <site name="pen_tip" pos="0.2 0 -0.116"/>
        </body>
      </body>
    </body>
  </worldbody>
  <actuator>
    <position name="shoulder" joint="shoulder" kp="10"/>
    <position name="elbow" joint="elbow" kp="10"/>
  </actuator>
</mujoco>
"""


def test_a_bring_your_own_arm_compiles_into_a_working_robot(tmp_path):
    xml = tmp_path / "my_scara.xml"
    xml.write_text(BYO_ARM)
    robot = arm_robot(None, "cartesian", xml_path=xml, tip_site="pen_tip", base_pos=(-0.1, 0.0, 0.0))
    assert robot.name == "my_scara:cartesian"
    assert robot.n_states > 1000 and robot.arm.dof == 2
    start, goal = TABLE_I[4].cells()  # the longest task, across three rooms
    assert robot.shortest_path(robot.start_state(start), goal) is not None
    joint = arm_robot(None, "joint", xml_path=xml, tip_site="pen_tip", base_pos=(-0.1, 0.0, 0.0))
    assert joint.n_states > 100 and joint.n_actions == 4


@pytest.mark.parametrize("mutate, message", [
    (lambda s: s.replace('name="pen_tip"', 'name="nib"'), "has no site 'pen_tip'; its sites: nib"),
    (lambda s: s.replace('type="hinge"', 'type="slide"').replace('range="-3 3"', 'range="0 0.1"')
     .replace('range="-2.9 2.9"', 'range="0 0.1"'), "only hinge joints|no hinge joints"),
    (lambda s: s.replace("<worldbody>", "<worldbody", 1), "cannot load arm MJCF"),
    (lambda s: s.replace('pos="0.05 0.02 0.2"', 'pos="0.05 0.02 1.5"'), "cannot reach"),
])
def test_bad_arms_raise_one_line_errors(tmp_path, mutate, message):
    xml = tmp_path / "arm.xml"
    xml.write_text(mutate(BYO_ARM))
    with pytest.raises(ArmTransferError, match=message) as err:  # mounted where the user put it
        arm_robot(None, "cartesian", xml_path=xml, tip_site="pen_tip", base_pos=(-0.1, 0.0, 0.0), cache=False)
    assert "\n" not in str(err.value)


def test_an_unreadable_file_is_an_arm_model_error(tmp_path):
    with pytest.raises(ArmModelError, match="cannot read arm MJCF"):
        arm_robot(None, "cartesian", xml_path=tmp_path / "missing.xml", tip_site="tip")
    with pytest.raises(UnreachableTableError):
        raise UnreachableTableError("x")
