"""The mount search's quick IK accepts a configuration by the compile's own rule, and finds
the cells the compile's IK finds."""

import mujoco
import numpy as np
import pytest

import menagerie_like as ml
from armtransfer.ik.quick import QuickIK
from armtransfer.ik.scene import build_scene
from armtransfer.ik.solve import MAX_TIP_HEIGHT, TIP_HEIGHT, TipIK, tilt_limit
from armtransfer.ik.tool import Tool
from armtransfer.worlds.layout import ROOMS

CASES = {  # a tool its geometry reaches past (7 joints), and a 5-joint arm whose tool may tilt
    "panda_tcp": (Tool(site="tcp"), (0.0, -0.40, 0.0), np.pi / 2),
    "so100": (Tool(site=None, body="Fixed_Jaw", offset=(0.0, 0.0, ml.SO100_JAW)),
              ml.SUGGESTED["so100"]["base_pos"], ml.SUGGESTED["so100"]["base_yaw"]),
}


@pytest.mark.parametrize("name", list(CASES))
def test_quick_ik_agrees_with_the_compiles_ik(tmp_path, name):
    tool, pos, yaw = CASES[name]
    scene = build_scene(ml.ALL[name](tmp_path), tool, pos, yaw, layout=ROOMS)
    quick, exact = QuickIK(scene, tip_down=True), TipIK(scene, tip_down=True)
    data = mujoco.MjData(scene.model)
    site = mujoco.mj_name2id(scene.model, mujoco.mjtObj.mjOBJ_SITE, scene.tip)
    cells = [ROOMS.cell(x, y) for x in range(-20, 21, 10) for y in range(-20, 21, 10)]
    cells = [c for c in cells if ROOMS.free[c]]
    both = exact_only = 0
    for c in cells:
        target = np.array(ROOMS.xy(c)) * scene.cell
        q, ok = quick.solve(target, scene.home)
        if ok:  # the compile's rule, checked by MuJoCo's own forward kinematics
            data.qpos[:] = q
            mujoco.mj_kinematics(scene.model, data)
            tip, z = data.site_xpos[site], data.site_xmat[site].reshape(3, 3)[:, 2]
            assert np.linalg.norm(tip - [*target, TIP_HEIGHT + scene.clearance]) <= quick.tol
            assert np.arccos(-z[2]) <= tilt_limit(scene) + 1e-9
            assert -1e-3 <= tip[2] - scene.clearance <= MAX_TIP_HEIGHT
        if exact.ok(exact.solve(target, scene.home)):
            both += ok
            exact_only += not ok
    assert both >= 10 and both >= 4 * exact_only  # it misses at most a fifth of what the compile finds
