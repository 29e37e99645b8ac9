"""An arm's scene as a dm_control ``Physics``, with named accessors for its joints and tool point.

:class:`ArmPhysics` wraps the MuJoCo scene an arm robot was compiled in (the arm at its
mount, the table and the rooms' walls; ``armtransfer.ik.scene``). Its accessors name what a
task reads, ``joint_angles()`` (the chain joints, base to tool) and ``tool_point()`` (the
tool tip's position in the table frame), and ``set_configuration(q)`` puts the arm at a
configuration at rest. Its default (free) camera frames the table and the arm as the rollout
videos do, orthographic from the front, so ``physics.render()`` shows the whole task.
"""

from __future__ import annotations

import os

os.environ.setdefault("MUJOCO_GL", "egl")

import numpy as np  # noqa: E402
from dm_control import mujoco as dm_mujoco  # noqa: E402
from dm_control.mujoco import wrapper  # noqa: E402

from armtransfer.errors import ArmModelError  # noqa: E402
from armtransfer.ik.render import offscreen_model, table_camera  # noqa: E402
from armtransfer.ik.replay import _ctrl_of  # noqa: E402
from armtransfer.ik.scene import ArmScene  # noqa: E402

VIEW = (320, 240)
"""(width, height) whose aspect the default camera's view fits (dm_control renders 320x240 by default)."""
MAX_VIEW = (1280, 960)
"""The largest image ``render`` can make (MuJoCo's offscreen buffer)."""


class ArmPhysics(dm_mujoco.Physics):
    """The physics of one arm on the rooms table. Build it with :meth:`from_scene`."""

    _joints: tuple[str, ...] = ()
    _tool: str = ""

    @classmethod
    def from_scene(cls, scene: ArmScene) -> "ArmPhysics":
        """The physics of ``scene``; its free camera set up to show the table and the arm."""
        width, height = VIEW
        model = offscreen_model(scene, width, height)
        model.vis.global_.offwidth = max(int(model.vis.global_.offwidth), MAX_VIEW[0])
        model.vis.global_.offheight = max(int(model.vis.global_.offheight), MAX_VIEW[1])
        camera = table_camera(scene, width, height)
        model.stat.center[:] = camera.lookat  # the default free camera looks here ...
        model.stat.extent = camera.distance / 1.5  # ... from this far (1.5 extents) ...
        model.vis.global_.azimuth = camera.azimuth  # ... in this direction
        model.vis.global_.elevation = camera.elevation
        physics = cls.from_model(wrapper.MjModel(model))
        joints = tuple(model.joint(i).name for i in range(model.njnt))
        if not joints:
            raise ArmModelError(f"the scene of arm {scene.name!r} has no joints")
        physics._set_names(joints, scene.tip)
        return physics

    def _set_names(self, joints: tuple[str, ...], tool: str) -> None:
        self._joints, self._tool = joints, tool

    def copy(self, share_model: bool = False) -> "ArmPhysics":
        new = super().copy(share_model=share_model)
        new._set_names(self._joints, self._tool)
        return new

    def __getstate__(self):
        return self.data, self._joints, self._tool

    def __setstate__(self, state) -> None:
        data, joints, tool = state
        super().__setstate__(data)
        self._set_names(joints, tool)

    def joint_names(self) -> tuple[str, ...]:
        """The arm's joints, base to tool, as the scene names them (``arm/`` + the file's name)."""
        return self._joints

    def joint_angles(self) -> np.ndarray:
        """The arm's configuration: one value per joint of :meth:`joint_names` (rad, or m for a slide)."""
        return np.array(self.named.data.qpos[list(self._joints)], dtype=np.float64)

    def tool_point(self) -> np.ndarray:
        """The tool tip's position (m) in the table frame (tabletop z = 0, cell (x, y) at
        (x, y) times the cell size)."""
        return np.array(self.named.data.site_xpos[self._tool], dtype=np.float64)

    def tool_site(self) -> str:
        """The name of the tool tip's site in the scene."""
        return self._tool

    def set_configuration(self, qpos: np.ndarray) -> None:
        """Put the arm at ``qpos`` (one value per joint) at rest, its servos holding it there."""
        q = np.asarray(qpos, dtype=np.float64)
        if q.shape != (len(self._joints),):
            raise ArmModelError(f"a configuration of this arm has {len(self._joints)} values, got shape {q.shape}")
        self.named.data.qpos[list(self._joints)] = q
        self.data.qvel[:] = 0.0
        if self.model.nu:  # the scene's servos (one per joint) target where the arm is
            self.data.ctrl[:] = _ctrl_of(self.model, self.data.qpos)
        self.forward()


__all__ = ["ArmPhysics"]
