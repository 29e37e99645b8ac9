"""Where inverse kinematics starts: a bound on an arm's reach and the cells to try first.

The compile, the mount search's estimate and the diagnosis of a failure all start from the
same cells (``seed_cells``), and bound the arm's reach the same way (``reach_bound``).
"""

from __future__ import annotations

import mujoco
import numpy as np

from armtransfer.ik.scene import ArmScene


def reach_bound(scene: ArmScene) -> tuple[np.ndarray, float]:
    """The first joint's anchor and the sum of the distances from joint to joint to the tip
    at home: no tip position lies farther from the anchor than that."""
    data = mujoco.MjData(scene.model)
    data.qpos[:] = scene.home
    mujoco.mj_kinematics(scene.model, data)
    tip = data.site_xpos[mujoco.mj_name2id(scene.model, mujoco.mjtObj.mjOBJ_SITE, scene.tip)]
    points = np.vstack([data.xanchor[np.argsort(scene.model.jnt_qposadr)], tip])
    return points[0].copy(), float(np.sum(np.linalg.norm(np.diff(points, axis=0), axis=1)))


SEED_RESTARTS = 8
"""Random configurations (inside the joint limits) IK tries for a first cell, after home."""


def seed_cells(scene: ArmScene, home_tip: np.ndarray, n: int = 6) -> list[int]:
    """Cells to try first: those nearest the tip at home, then those nearest the point halfway
    from the arm's base to the table's centre (a straight or folded home may put the tip
    far off the table, or at a singular pose, where IK from home cannot start), then the
    cell nearest each of 8 points around the base at half its reach (a base standing on the
    table near its centre: the halfway point is then inside the circle no tool-down pose
    reaches)."""
    layout, cell = scene.layout, scene.cell
    anchor, reach = reach_bound(scene)  # the first joint's anchor at home: the base
    base = anchor[:2]
    ring = [(base + 0.5 * reach * np.array([np.cos(t), np.sin(t)]), 1)
            for t in np.arange(RING) * 2 * np.pi / RING]
    out: list[int] = []
    for point, k in [(home_tip[:2], n), (base / 2, n), *ring]:
        for c in _cells_by_distance(point, cell, layout)[:k]:
            if int(c) not in out:
                out.append(int(c))
    return out


RING = 8
"""Points around the base, at half its reach, that ``seed_cells`` also tries."""


def _cells_by_distance(xy, cell, layout) -> np.ndarray:
    ids = np.flatnonzero(layout.free)
    centres = layout.xy_of(ids) * cell
    return ids[np.argsort(np.linalg.norm(centres - np.asarray(xy)[:2], axis=1), kind="stable")]


__all__ = ["RING", "SEED_RESTARTS", "reach_bound", "seed_cells"]
