"""How far a spatial arm's tool may tilt from straight down (``ik.solve.tilt_limit``), and
where the compile looks for its first cell (``ik.compile.seed_cells``).

An arm of six joints or more holds its tool straight down (within ``TILT_TOL``). One with
fewer keeps it within ``TILT_CONE``: IK tries straight down first and tilts only where that
fails, so wherever straight down works the cone gives the very same configuration.
"""

import numpy as np
import pytest

import menagerie_like as ml
from armtransfer.ik.compile import RING, reach_bound, seed_cells
from armtransfer.ik.mount import _Placer
from armtransfer.ik.solve import TILT_CONE, TILT_TOL, TipIK, tilt_limit
from armtransfer.tasks.arms import arm_robot, arm_scene, compile_order

SO100 = dict(tip_body="Fixed_Jaw", tip_offset=(0.0, 0.0, ml.SO100_JAW))


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    out = tmp_path_factory.mktemp("tilt")
    return {"so100": ml.ALL["so100"](out), "ur5e": ml.ALL["ur5e"](out)}


@pytest.fixture(scope="module")
def so100_scene(files):
    s = ml.SUGGESTED["so100"]
    return arm_scene(xml_path=files["so100"], base_pos=s["base_pos"], base_yaw=s["base_yaw"], **SO100)


def test_the_tilt_limit_follows_the_number_of_joints(files, so100_scene):
    ur5e = arm_scene(xml_path=files["ur5e"], tip_site="attachment_site", tip_offset=(0.0, 0.0, 0.12))
    assert ur5e.nq == 6 and tilt_limit(ur5e) == TILT_TOL
    assert so100_scene.nq == 5 and tilt_limit(so100_scene) == TILT_CONE
    assert TipIK(so100_scene, tip_down=True).cone and not TipIK(ur5e, tip_down=True).cone
    assert not TipIK(so100_scene, tip_down=False).cone


def test_the_cone_changes_nothing_where_straight_down_works_and_reaches_more(so100_scene):
    strict = TipIK(so100_scene, tip_down=True, tilt_tol=TILT_TOL)
    cone = TipIK(so100_scene, tip_down=True)
    points = [np.array([x, y]) for x in np.linspace(-0.24, 0.24, 7) for y in np.linspace(-0.24, 0.24, 7)]
    only_cone = 0
    for xy in points:
        a = strict.solve_any(xy, so100_scene.home, np.random.default_rng(1))
        b = cone.solve_any(xy, so100_scene.home, np.random.default_rng(1))
        if strict.ok(a):
            assert cone.ok(b) and np.array_equal(a.q, b.q) and b.tilt <= TILT_TOL
        elif cone.ok(b):  # the second try may also end straight down: it iterates further
            assert b.tilt <= TILT_CONE and b.error <= cone.tol
            only_cone += b.tilt > TILT_TOL
    assert only_cone > 0  # beyond the ring straight down allows, the tilted tool still reaches


@pytest.mark.slow  # 10 s: a 5-joint lattice compiled with its swept checks; the cone itself is tested above
def test_a_compiled_five_joint_arm_keeps_its_tool_within_the_cone(files):
    s = ml.SUGGESTED["so100"]
    robot = arm_robot(None, "cartesian", xml_path=files["so100"], base_pos=s["base_pos"], base_yaw=s["base_yaw"],
                      **SO100)
    scene = arm_scene(xml_path=files["so100"], base_pos=s["base_pos"], base_yaw=s["base_yaw"], **SO100)
    ik = TipIK(scene, tip_down=True)
    tilts = []
    for q in robot.arm.qpos:
        ik.configuration.update(q)
        z = ik.configuration.get_transform_frame_to_world(scene.tip, "site").rotation().as_matrix()[:, 2]
        tilts.append(np.arccos(np.clip(-z[2], -1.0, 1.0)))
    tilts = np.array(tilts)
    assert tilts.max() <= TILT_CONE + 1e-9
    assert (tilts <= TILT_TOL).mean() > 0.5  # most cells still straight down


def test_first_cells_include_a_ring_around_a_base_standing_on_the_table(files):
    place = _Placer(arm_scene(xml_path=files["so100"], **SO100))
    pose = place(0.1, 0.0, None, None).lifted(0.05)
    scene = arm_scene(xml_path=files["so100"], base_pos=pose.pos, base_yaw=pose.yaw, **SO100)
    anchor, reach = reach_bound(scene)
    seeds = seed_cells(scene, np.array([9.0, 9.0, 9.0]))  # a home tip far off the table
    layout = scene.layout
    free = np.flatnonzero(layout.free)
    centres = layout.xy_of(free) * scene.cell
    for t in np.arange(RING) * 2 * np.pi / RING:  # the free cell nearest each point at half the reach
        point = anchor[:2] + 0.5 * reach * np.array([np.cos(t), np.sin(t)])
        assert int(free[np.argmin(np.linalg.norm(centres - point, axis=1))]) in seeds
    # and the first seeds are still those nearest the home tip, then halfway to the centre
    assert seeds[0] == int(free[np.argmin(np.linalg.norm(centres - 9.0, axis=1))])


def test_the_automatic_mount_compiles_the_best_ranked_then_the_best_estimates():
    scored = [(8, 0.50, "a"), (8, 0.40, "b"), (7, 0.90, "c"), (7, 0.30, "d"), (6, 0.95, "e"), (6, 0.10, "f")]
    order = [pose for *_, pose in compile_order(scored, 2)]
    assert order == ["a", "b", "e", "c"]
    assert [pose for *_, pose in compile_order(scored[:2], 3)] == ["a", "b"]
    same = [(8, 0.9, "a"), (8, 0.8, "b"), (8, 0.7, "c")]  # ranked by the estimate alone: nothing to add
    assert [pose for *_, pose in compile_order(same, 2)] == ["a", "b"]
    assert compile_order([], 3) == []


def test_a_tool_without_offset_says_its_axis_is_the_frames_z_axis():
    from armtransfer.ik.tool import Tool

    assert "site's z axis" in Tool(site="tcp").axis_hint() and "--tip-offset" in Tool(site="tcp").axis_hint()
    assert "body's z axis" in Tool(site=None, body="jaw").axis_hint()
    assert Tool(site="tcp", offset=(0.0, 0.0, 0.1)).axis_hint() == ""


def test_a_base_on_a_pedestal_stands_on_a_drawn_column_that_touches_nothing(files):
    import mujoco

    from armtransfer.ik.scene import PEDESTAL, PEDESTAL_RADIUS, base_footing

    place = _Placer(arm_scene(xml_path=files["so100"], **SO100))
    standing = place(0.1, 0.0, None, None)  # on the tabletop, its base's axis at (0.1, 0) m
    lifted = standing.lifted(0.05)
    beside = place(0.1 + 1.0, 0.0, None, None).lifted(0.05)  # off the table: nothing to stand on
    low, high, off = (arm_scene(xml_path=files["so100"], base_pos=p.pos, base_yaw=p.yaw, **SO100)
                      for p in (standing, lifted, beside))
    for scene in (low, off):
        assert mujoco.mj_name2id(scene.model, mujoco.mjtObj.mjOBJ_GEOM, PEDESTAL) == -1
    g = mujoco.mj_name2id(high.model, mujoco.mjtObj.mjOBJ_GEOM, PEDESTAL)
    assert g >= 0
    data = mujoco.MjData(high.model)
    mujoco.mj_kinematics(high.model, data)
    centre, half = data.geom_xpos[g], high.model.geom_size[g][1]
    anchor, bottom = base_footing(high.model, high.home)  # the pedestal itself does not count
    assert base_footing(low.model, low.home)[1] == pytest.approx(0.0, abs=1e-9)  # standing on the tabletop
    assert bottom == pytest.approx(0.05, abs=1e-6)
    assert centre[2] - half == pytest.approx(0.0, abs=1e-9) and centre[2] + half == pytest.approx(bottom)
    assert np.allclose(centre[:2], anchor[:2]) and np.allclose(anchor[:2], (0.1, 0.0), atol=1e-4)
    assert high.model.geom_size[g][0] == PEDESTAL_RADIUS
    assert high.model.geom_contype[g] == 0 and high.model.geom_conaffinity[g] == 0  # drawn only
    assert not high.env_geoms[g] and not high.arm_geoms[g]
    assert high.model.geom_matid[g] >= 0  # in the walls' material
    # the placer finds the same base with the column there
    assert _Placer(high).bottom == pytest.approx(bottom)
