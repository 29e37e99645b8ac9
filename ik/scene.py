"""An arm attached to the tabletop workspace with ``dm_control.mjcf``, compiled to MuJoCo.

The arm's own MJCF is loaded, renamed ``arm`` (so every arm element is ``arm/<name>`` in
the scene), stripped of its keyframes (the scene keeps the arm's ``home`` separately) and
attached to the workspace at the arm's mounting pose.
"""

from __future__ import annotations

import hashlib
import math
from dataclasses import dataclass
from pathlib import Path

import mujoco
import numpy as np

from armtransfer.errors import ArmModelError
from armtransfer.ik.workspace import DEFAULT_CELL, WALL_HEIGHT, build_workspace

from typing import TYPE_CHECKING

if TYPE_CHECKING:  # the layout is passed in from armtransfer.tasks, never imported
    from armtransfer.tasks.layout import Layout

PREFIX = "arm/"


@dataclass(frozen=True)
class ArmScene:
    model: mujoco.MjModel
    xml: str
    """The composed scene's MJCF (what the cache key hashes)."""
    tip: str
    """Full name of the tool-tip site in the scene."""
    home: np.ndarray
    lower: np.ndarray
    upper: np.ndarray
    env_geoms: np.ndarray
    """Boolean mask over geoms: True for table and wall geoms."""
    arm_geoms: np.ndarray
    cell: float
    layout: Layout
    planar: bool
    """All joint axes vertical: the tip moves in a horizontal plane at a fixed height."""

    @property
    def nq(self) -> int:
        return int(self.model.nq)

    def digest(self) -> str:
        return hashlib.sha256(self.xml.encode()).hexdigest()


def _load_arm(xml_path: Path):
    from dm_control import mjcf

    path = Path(xml_path)
    if not path.is_file():
        raise ArmModelError(f"cannot read arm MJCF {str(path)!r}: no such file")
    try:
        mujoco.MjModel.from_xml_path(str(path))
        arm = mjcf.from_path(str(path))
    except Exception as err:  # noqa: BLE001 - any parse failure is a bad input file
        first = str(err).strip().splitlines()[0] if str(err).strip() else type(err).__name__
        raise ArmModelError(f"cannot load arm MJCF {str(path)!r}: {first}") from None
    return arm


def arm_home(xml_path: Path) -> np.ndarray:
    """The arm's ``home`` keyframe qpos, else its qpos0 clipped into the joint ranges."""
    model = mujoco.MjModel.from_xml_path(str(xml_path))
    key = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_KEY, "home")
    q = model.key_qpos[key].copy() if key >= 0 else model.qpos0.copy()
    limited = model.jnt_limited.astype(bool)
    lo, hi = model.jnt_range[:, 0], model.jnt_range[:, 1]
    adr = model.jnt_qposadr
    q[adr[limited]] = np.clip(q[adr[limited]], lo[limited], hi[limited])
    return q


def build_scene(xml_path: Path, tip_site: str = "tip", mount_pos=(0.0, 0.0, 0.0),
                mount_yaw: float = 0.0, cell: float = DEFAULT_CELL, *, layout: Layout,
                wall_height: float = WALL_HEIGHT) -> ArmScene:
    """Attach the arm at ``xml_path`` to the workspace; validate it is a hinge-joint arm."""
    arm = _load_arm(xml_path)
    sites = [s.name for s in arm.find_all("site") if s.name]
    if tip_site not in sites:
        valid = ", ".join(sites) if sites else "none"
        raise ArmModelError(f"arm MJCF {str(xml_path)!r} has no site {tip_site!r}; its sites: {valid}")
    joints = arm.find_all("joint")
    if any(j.tag == "freejoint" or j.type == "free" for j in joints):
        raise ArmModelError(f"arm MJCF {str(xml_path)!r} has a free joint; a fixed-base serial arm is needed")
    kinds = [(j.type or "hinge") for j in joints if j.tag == "joint"]
    if not joints or "hinge" not in kinds:
        raise ArmModelError(f"arm MJCF {str(xml_path)!r} has no hinge joints")
    if any(k != "hinge" for k in kinds):
        bad = sorted({k for k in kinds if k != "hinge"})
        raise ArmModelError(
            f"arm MJCF {str(xml_path)!r} has {', '.join(bad)} joints; only hinge joints are supported")
    home = arm_home(xml_path)
    for key in list(arm.keyframe.key):
        key.remove()
    arm.model = "arm"
    scene = build_workspace(layout, cell, wall_height)
    frame = scene.attach(arm)
    frame.pos = tuple(float(v) for v in mount_pos)
    frame.quat = (math.cos(mount_yaw / 2), 0.0, 0.0, math.sin(mount_yaw / 2))
    xml = scene.to_xml_string()
    try:
        model = mujoco.MjModel.from_xml_string(xml, assets=scene.get_assets())
    except Exception as err:  # noqa: BLE001
        first = str(err).strip().splitlines()[0]
        raise ArmModelError(f"arm MJCF {str(xml_path)!r} does not compile in the scene: {first}") from None
    if model.nq != len(home):
        raise ArmModelError(f"arm MJCF {str(xml_path)!r}: home has {len(home)} values for {model.nq} joints")
    table_body = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "table")
    env = model.geom_bodyid == table_body
    arm_geoms = np.array([
        (mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_GEOM, g) or "").startswith(PREFIX)
        or (model.geom_bodyid[g] != table_body and model.geom_bodyid[g] != 0)
        for g in range(model.ngeom)
    ], dtype=bool)
    lower = np.full(model.nq, -np.inf)
    upper = np.full(model.nq, np.inf)
    for j in range(model.njnt):
        adr = model.jnt_qposadr[j]
        if model.jnt_limited[j]:
            lower[adr], upper[adr] = model.jnt_range[j]
    data = mujoco.MjData(model)
    data.qpos[:] = home
    mujoco.mj_kinematics(model, data)
    planar = bool(np.all(np.abs(np.abs(data.xaxis[:, 2]) - 1.0) < 1e-6))
    return ArmScene(model=model, xml=xml, tip=PREFIX + tip_site, home=home, lower=lower,
                    upper=upper, env_geoms=env, arm_geoms=arm_geoms, cell=cell, layout=layout,
                    planar=planar)


class ContactChecker:
    """Does the arm touch the table or a wall at configuration q? (MuJoCo collision.)"""

    def __init__(self, scene: ArmScene) -> None:
        self.scene = scene
        self.model = scene.model
        self.data = mujoco.MjData(scene.model)
        self._env = scene.env_geoms
        self._tip = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_SITE, scene.tip)

    def touches(self, q: np.ndarray) -> bool:
        d = self.data
        d.qpos[:] = q
        mujoco.mj_kinematics(self.model, d)
        mujoco.mj_collision(self.model, d)
        n = d.ncon
        if n == 0:
            return False
        g1 = d.contact.geom1[:n]
        g2 = d.contact.geom2[:n]
        e1, e2 = self._env[g1], self._env[g2]
        return bool(np.any(e1 != e2))

    def tip(self, q: np.ndarray) -> np.ndarray:
        """The tip position after the last ``touches`` call at q (or computed now)."""
        d = self.data
        d.qpos[:] = q
        mujoco.mj_kinematics(self.model, d)
        return d.site_xpos[self._tip].copy()

    def touches_and_tip(self, q: np.ndarray) -> tuple[bool, np.ndarray]:
        hit = self.touches(q)
        return hit, self.data.site_xpos[self._tip].copy()
