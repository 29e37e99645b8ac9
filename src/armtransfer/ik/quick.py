"""A quick inverse kinematics for estimates: damped least squares on MuJoCo's own Jacobians.

The compile's IK (``ik.solve.TipIK``, mink with a QP per step) is exact about joint limits
and the posture it prefers, and costs about half a millisecond a step in Python. A mount
search asks where the tool can go from dozens of base poses; it needs the same answer
(can the tool point be put over this cell, pointing down, with its lowest point
``TIP_HEIGHT`` above the table?) far more cheaply. ``QuickIK`` takes damped least-squares
steps on ``mj_jacSite`` (position, and for a spatial arm the tool axis's two components
across straight down), clips to the joint limits, and accepts a result by the compile's own
rule (``TipIK.ok``: within ``tol`` of the target, tilted at most ``tilt_limit``, lowest
point on the table). An arm of fewer than ``FULL_DOF`` joints weighs the tool's direction
lightly (``CONE_WEIGHT``), so that the position comes first and the tool tilts only as far
as it needs, as ``TipIK`` does for those arms.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from armtransfer.ik.scene import ArmScene
from armtransfer.ik.solve import FULL_DOF, MAX_TIP_HEIGHT, TIP_HEIGHT, tilt_limit

DAMPING = 1e-3
"""Damping of the least-squares step (m, rad)."""
CONE_WEIGHT = 0.05
"""Weight of the tool's direction against the tip's position, for arms of fewer than
``FULL_DOF`` joints."""
MAX_STEP = 0.4
"""Largest change of any joint in one step (rad)."""
STALL_EVERY = 8
STALL_RATIO = 0.9
"""A solve stops when its position error has not fallen below ``STALL_RATIO`` of what it was
``STALL_EVERY`` steps before (a target out of reach)."""


class QuickIK:
    def __init__(self, scene: ArmScene, tip_down: bool, tol: float = 5e-4, max_iters: int = 40) -> None:
        self.scene = scene
        self.model = scene.model
        self.data = mujoco.MjData(scene.model)
        self.site = mujoco.mj_name2id(scene.model, mujoco.mjtObj.mjOBJ_SITE, scene.tip)
        self.tip_down = tip_down and not scene.planar
        self.tol = tol
        self.max_iters = max_iters
        self.tilt_limit = tilt_limit(scene) if self.tip_down else np.inf
        self.weight = 1.0 if scene.nq >= FULL_DOF else CONE_WEIGHT
        self.lower = np.maximum(scene.lower, -2 * np.pi)
        self.upper = np.minimum(scene.upper, 2 * np.pi)
        self._jacp = np.zeros((3, scene.model.nv))
        self._jacr = np.zeros((3, scene.model.nv))

    def _forward(self, q: np.ndarray) -> None:
        self.data.qpos[:] = q
        mujoco.mj_kinematics(self.model, self.data)
        mujoco.mj_comPos(self.model, self.data)

    def tip(self) -> np.ndarray:
        return self.data.site_xpos[self.site].copy()

    def solve(self, xy: np.ndarray, q0: np.ndarray) -> tuple[np.ndarray, bool]:
        """(configuration, accepted) for the tool point over ``xy`` starting from ``q0``."""
        q = np.clip(np.asarray(q0, dtype=float), self.lower, self.upper)
        self._forward(q)
        height = TIP_HEIGHT + self.scene.clearance if not self.scene.planar else float(self.tip()[2])
        target = np.array([xy[0], xy[1], height])
        rows = 2 if self.scene.planar else 3
        stop_tilt = math.cos(self.tilt_limit * 0.5) if self.tip_down else -1.0  # as -z[2]: half the limit
        spatial = self.tip_down
        regular = DAMPING ** 2 * np.eye(rows + (2 if spatial else 0))
        xpos, xmat = self.data.site_xpos[self.site], self.data.site_xmat[self.site]
        jacp, jacr, w = self._jacp, self._jacr, self.weight
        last = math.inf
        for it in range(self.max_iters):
            e_pos = target[:rows] - xpos[:rows]
            err = math.sqrt(float(e_pos @ e_pos))
            down_ok = (not spatial) or -xmat[8] >= stop_tilt
            if err <= self.tol * 0.5 and down_ok:
                break
            if it % STALL_EVERY == 0:  # stalled: no real progress over the last steps
                if err > STALL_RATIO * last:
                    break
                last = err
            mujoco.mj_jacSite(self.model, self.data, jacp, jacr, self.site)
            if spatial:  # turn the tool axis z towards straight down: the rotation z x down
                e = np.array([*e_pos, -xmat[5] * w, xmat[2] * w])  # (z x (0, 0, -1))[:2]
                jac = np.vstack([jacp[:rows], jacr[:2] * w])
            else:
                e, jac = e_pos, jacp[:rows]
            dq = jac.T @ np.linalg.solve(jac @ jac.T + regular, e)
            biggest = float(np.max(np.abs(dq)))
            if biggest > MAX_STEP:
                dq *= MAX_STEP / biggest
            q = np.minimum(np.maximum(q + dq, self.lower), self.upper)
            self._forward(q)
        return q, self.ok(target)

    def ok(self, target: np.ndarray) -> bool:
        """The compile's acceptance rule at the current configuration."""
        p = self.data.site_xpos[self.site]
        rows = 2 if self.scene.planar else 3
        err = float(np.linalg.norm((p - target)[:rows]))
        if err > self.tol:
            return False
        if self.tip_down:
            z = self.data.site_xmat[self.site].reshape(3, 3)[:, 2]
            if np.arccos(np.clip(-z[2], -1.0, 1.0)) > self.tilt_limit:
                return False
        low = float(p[2]) - self.scene.clearance
        return -1e-3 <= low <= MAX_TIP_HEIGHT

    def solve_any(self, xy: np.ndarray, q0: np.ndarray, rng: np.random.Generator,
                  restarts: int) -> tuple[np.ndarray, bool]:
        """``solve`` from q0, then home, then ``restarts`` random configurations in the limits."""
        lo, hi = np.maximum(self.lower, -np.pi), np.minimum(self.upper, np.pi)
        seeds = [q0, self.scene.home] + [rng.uniform(lo, hi) for _ in range(restarts)]
        q, ok = q0, False
        for seed in seeds:
            q, ok = self.solve(xy, seed)
            if ok:
                break
        return q, ok


__all__ = ["QuickIK"]
