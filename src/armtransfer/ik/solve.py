"""Inverse kinematics with mink: put the tool tip over a point of the table.

A ``FrameTask`` on the tip site (position; for spatial arms also "tool pointing down",
leaving the rotation about the tool axis free), a low-weight ``PostureTask`` towards the
home configuration to pick among redundant solutions, and the joint limits
(``ConfigurationLimit``), solved with ``mink.solve_ik(..., solver="daqp")`` and iterated
as Gauss-Newton steps until the tip is within ``tol`` of the target.

Pointing down is exact (within ``TILT_TOL``) for an arm of six joints or more. An arm with
fewer has no joint to spare: holding the tool straight down takes two of them, and a
5-joint arm is then left with a thin ring of the table (the SO-ARM100: 6-32 cm from its
axis). Such an arm keeps its tool within ``TILT_CONE`` of straight down instead: IK first
tries straight down, and where that fails it solves again with a light downward pull, so
the tip's position comes first and the tool tilts only as far as the position needs.
"""

from __future__ import annotations

from dataclasses import dataclass

import mink
import numpy as np

from armtransfer.ik.scene import ArmScene

TIP_HEIGHT = 0.004
"""Height IK puts the tool's lowest point at above the tabletop (m): the tool point itself,
or higher by ``ArmScene.clearance`` when the tool's geometry reaches past the point. Planar
arms keep their own."""
MAX_TIP_HEIGHT = 0.01
"""A tool whose lowest point is higher than this above the tabletop (m) is not on the table."""

TILT_TOL = 0.05
"""Largest tilt (rad) of the tool axis from straight down, for an arm of six joints or more."""
TILT_CONE = 0.5
"""Largest tilt (rad, about 29 degrees) for a spatial arm of fewer than six joints. The
wrist then stays high over the table: a tool 13 cm long tilted this far still holds its
far end 11 cm above the tip."""
CONE_COST = 1e-3
"""Weight of "pointing down" for those arms, against 1 for the tip's position."""
FULL_DOF = 6
"""Joints an arm needs to put its tool tip anywhere within reach pointing straight down."""


def tilt_limit(scene: ArmScene) -> float:
    """The largest tilt of the tool from straight down that IK accepts for this arm."""
    return TILT_TOL if scene.nq >= FULL_DOF else TILT_CONE


# Tool z axis pointing down: a rotation of pi about the world x axis.
_DOWN = mink.SO3.from_x_radians(np.pi)


@dataclass
class IKResult:
    q: np.ndarray
    error: float
    """Distance from the tip to the target (m)."""
    tilt: float
    """Angle between the tool axis and straight down (rad; 0 for planar arms)."""
    iterations: int
    height: float = TIP_HEIGHT
    """Height of the tool point above the tabletop (m)."""


class TipIK:
    def __init__(self, scene: ArmScene, tip_down: bool, posture_cost: float = 1e-3,
                 damping: float = 1e-4, tol: float = 5e-4, tilt_tol: float | None = None,
                 max_iters: int = 40) -> None:
        """``tilt_tol`` None: ``tilt_limit(scene)``."""
        self.scene = scene
        self.tip_down = tip_down
        self.configuration = mink.Configuration(scene.model)
        tilt_tol = tilt_limit(scene) if tilt_tol is None else tilt_tol
        self.frame = mink.FrameTask(
            frame_name=scene.tip, frame_type="site",
            position_cost=np.array([1.0, 1.0, 0.0]) if scene.planar else 1.0,
            orientation_cost=np.array([1.0, 1.0, 0.0]) if tip_down else 0.0,
            lm_damping=1e-3,
        )
        self.posture = mink.PostureTask(scene.model, cost=posture_cost)
        self.posture.set_target(scene.home)
        self.limits = [mink.ConfigurationLimit(scene.model)]
        self.damping = damping
        self.tol = tol
        self.tilt_tol = tilt_tol
        self.cone = tip_down and tilt_tol > TILT_TOL
        """Tool within a cone: where pointing straight down fails, a second solve with a light
        downward pull from the first's result."""
        self.max_iters = max_iters
        self.tasks = [self.frame, self.posture]

    def target_height(self, q: np.ndarray) -> float:
        if not self.scene.planar:
            return TIP_HEIGHT + self.scene.clearance
        self.configuration.update(q)
        return float(self.configuration.get_transform_frame_to_world(self.scene.tip, "site").translation()[2])

    def solve(self, xy: np.ndarray, q0: np.ndarray) -> IKResult:
        """Tip over (x, y) starting from q0; returns the best configuration found. An arm whose
        tool may tilt (``cone``) first tries straight down, and only where that fails lets
        the tool tilt, starting from where the first try ended."""
        q0 = np.clip(np.asarray(q0, dtype=float), self.scene.lower + 1e-6, self.scene.upper - 1e-6)
        target = np.array([xy[0], xy[1], self.target_height(q0)])
        self.configuration.update(q0)
        self.frame.set_target(mink.SE3.from_rotation_and_translation(_DOWN, target))
        res = self._iterate(target, min(self.tilt_tol, TILT_TOL) * 0.2)
        if self.cone and not (res.error <= self.tol and res.tilt <= TILT_TOL):
            self.frame.set_orientation_cost(np.array([CONE_COST, CONE_COST, 0.0]))
            try:  # within the cone any tilt will do: the light pull leaves the position exact
                tilted = self._iterate(target, self.tilt_tol, res.iterations)
            finally:
                self.frame.set_orientation_cost(np.array([1.0, 1.0, 0.0]))
            res = tilted
        return res

    def _iterate(self, target: np.ndarray, tilt_stop: float, done: int = 0) -> IKResult:
        cfg = self.configuration
        err = tilt = np.inf
        it = 0
        for it in range(1, self.max_iters + 1):
            if not self.tip_down:  # orientation free: aim at the tool's own rotation, so the
                # frame error (an SE(3) logarithm) is the position error alone
                rotation = cfg.get_transform_frame_to_world(self.scene.tip, "site").rotation()
                self.frame.set_target(mink.SE3.from_rotation_and_translation(rotation, target))
            v = mink.solve_ik(cfg, self.tasks, 1.0, solver="daqp", damping=self.damping,
                              limits=self.limits)
            cfg.integrate_inplace(v, 1.0)
            err, tilt = self._residual(target)
            if err < self.tol * 0.2 and tilt < tilt_stop:
                break
        height = float(cfg.get_transform_frame_to_world(self.scene.tip, "site").translation()[2])
        return IKResult(cfg.q.copy(), float(err), float(tilt), done + it, height)

    def solve_any(self, xy: np.ndarray, q0: np.ndarray, rng: np.random.Generator,
                  restarts: int = 8) -> IKResult:
        """``solve`` from q0, then from home, then from random configurations drawn with
        ``rng`` inside the joint limits, until one succeeds; returns the best found."""
        lo = np.maximum(self.scene.lower, -np.pi)
        hi = np.minimum(self.scene.upper, np.pi)
        seeds = [q0, self.scene.home] + [rng.uniform(lo, hi) for _ in range(restarts)]
        best = self.solve(xy, seeds[0])
        if self.ok(best):
            return best
        for seed in seeds[1:]:
            res = self.solve(xy, seed)
            if self.ok(res):
                return res
            if res.error < best.error:
                best = res
        return best

    def _residual(self, target: np.ndarray) -> tuple[float, float]:
        pose = self.configuration.get_transform_frame_to_world(self.scene.tip, "site")
        err = float(np.linalg.norm(pose.translation() - target))
        if not self.tip_down:
            return err, 0.0
        z = pose.rotation().as_matrix()[:, 2]
        return err, float(np.arccos(np.clip(-z[2], -1.0, 1.0)))

    def ok(self, result: IKResult) -> bool:
        low = result.height - self.scene.clearance  # the tool's lowest point
        return result.error <= self.tol and result.tilt <= self.tilt_tol and -1e-3 <= low <= MAX_TIP_HEIGHT
