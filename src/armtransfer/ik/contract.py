"""The arm contract every built-in and generated arm meets, checked on its MJCF file.

- every body, joint, geom, site and actuator is named;
- a site named ``tip`` (the tool tip) and a keyframe named ``home``;
- hinge joints only, one per degree of freedom, each driven by a position servo (an actuator
  with an affine bias) named like the joint;
- it compiles on the table at its mount, and one second of random controls in the scene
  raises no MuJoCo warning and leaves the state finite.

:func:`problems` returns what is wrong, one line each (an empty list: the arm meets it), so
the generator can say why it rejected a draw and the tests can assert on it.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING

import mujoco
import numpy as np

from armtransfer.errors import ArmModelError
from armtransfer.ik.scene import build_scene

if TYPE_CHECKING:  # the layout is passed in from armtransfer.tasks, never imported
    from armtransfer.worlds.layout import Layout

NAMED = (
    (mujoco.mjtObj.mjOBJ_BODY, "nbody", "body"),
    (mujoco.mjtObj.mjOBJ_JOINT, "njnt", "joint"),
    (mujoco.mjtObj.mjOBJ_GEOM, "ngeom", "geom"),
    (mujoco.mjtObj.mjOBJ_SITE, "nsite", "site"),
    (mujoco.mjtObj.mjOBJ_ACTUATOR, "nu", "actuator"),
)


def problems(xml_path: str | os.PathLike, layout: Layout, *, mount=(0.0, 0.0, 0.0), yaw: float = 0.0,
             cell: float = 0.01, seconds: float = 1.0, seed: int = 7) -> list[str]:
    """Everything about the arm at ``xml_path`` that breaks the contract, one line each."""
    try:
        model = mujoco.MjModel.from_xml_path(str(xml_path))
    except Exception as err:  # noqa: BLE001 - any parse failure is a broken file
        return [f"does not compile: {str(err).strip().splitlines()[0]}"]
    out = []
    for obj, count, what in NAMED:
        unnamed = [i for i in range(getattr(model, count)) if not mujoco.mj_id2name(model, obj, i)]
        if unnamed:
            out.append(f"{len(unnamed)} unnamed {what}(s)")
    if mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, "tip") < 0:
        out.append("no site named 'tip'")
    if mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_KEY, "home") < 0:
        out.append("no keyframe named 'home'")
    if not model.njnt == model.nq == model.nu:
        out.append(f"{model.njnt} joints, {model.nq} positions and {model.nu} actuators should be equal")
    for j in range(model.njnt):
        name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, j) or f"#{j}"
        if model.jnt_type[j] != mujoco.mjtJoint.mjJNT_HINGE:
            out.append(f"joint {name} is not a hinge")
        a = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, name)
        if a < 0 or model.actuator_trnid[a, 0] != j:
            out.append(f"no actuator named {name} drives joint {name}")
        elif model.actuator_biastype[a] != mujoco.mjtBias.mjBIAS_AFFINE:
            out.append(f"actuator {name} is not a position servo")
    if out:
        return out
    return _random_control(Path(xml_path), layout, mount, yaw, cell, seconds, seed)


def _random_control(xml_path: Path, layout: Layout, mount, yaw: float, cell: float, seconds: float,
                    seed: int) -> list[str]:
    try:
        scene = build_scene(xml_path, "tip", mount, yaw, cell, layout=layout)
    except ArmModelError as err:
        return [str(err)]
    model = scene.model
    data = mujoco.MjData(model)
    data.qpos[:] = scene.home
    data.ctrl[:] = scene.home
    mujoco.mj_forward(model, data)
    rng = np.random.default_rng(seed)
    lo, hi = model.actuator_ctrlrange[:, 0], model.actuator_ctrlrange[:, 1]
    for i in range(int(round(seconds / model.opt.timestep))):
        if i % 50 == 0:
            data.ctrl[:] = rng.uniform(lo, hi)
        mujoco.mj_step(model, data)
    warned = [mujoco.mjtWarning(i).name for i in range(len(data.warning)) if data.warning[i].number]
    out = [f"{seconds:g} s of random control raised MuJoCo warnings: {', '.join(warned)}"] if warned else []
    if not np.all(np.isfinite(data.qpos)):
        out.append("the state became non-finite under random control")
    return out
