"""An independent checker of continuous moves, written apart from the code that makes them.

A move from the whole configuration ``qa`` to ``qb`` (a straight line in joint space) is cut
into pieces so that the tool point travels at most ``MAX_TRAVEL`` between checked points (its
positions from MuJoCo's own kinematics: the pieces are halved until every one is short enough);
at each point ``mj_forward`` runs on a data of its own, and the deepest contact between a geom
of the arm and a geom of the table body (the table top or a wall) is recorded. A contact counts
when it is deeper than ``MIN_DEPTH``.
"""

from __future__ import annotations

import mujoco
import numpy as np

MAX_TRAVEL = 5e-4
"""Metres of tool-point travel between two checked points."""
MIN_DEPTH = 1e-4
"""Metres: a contact shallower than this is not counted."""


class SweepChecker:
    def __init__(self, model: mujoco.MjModel, tip_site: str, table_body: str = "table") -> None:
        self.model = model
        self.data = mujoco.MjData(model)
        self.site = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, tip_site)
        table = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, table_body)
        assert table >= 0 and self.site >= 0
        self.env = model.geom_bodyid == table
        self.arm = (~self.env) & (model.geom_bodyid != 0)

    def tip(self, q: np.ndarray) -> np.ndarray:
        self.data.qpos[:] = q
        mujoco.mj_forward(self.model, self.data)
        return self.data.site_xpos[self.site].copy()

    def depth(self, q: np.ndarray) -> float:
        """The deepest arm-table or arm-wall penetration at q (metres, 0: none)."""
        self.data.qpos[:] = q
        mujoco.mj_forward(self.model, self.data)
        deepest = 0.0
        for k in range(self.data.ncon):
            c = self.data.contact[k]
            g1, g2 = c.geom[0], c.geom[1]
            if (self.env[g1] and self.arm[g2]) or (self.env[g2] and self.arm[g1]):
                deepest = max(deepest, -float(c.dist))
        return deepest

    def points(self, qa: np.ndarray, qb: np.ndarray) -> list[float]:
        """The fractions of the move checked: 0, 1 and enough between them."""
        ts = [0.0, 1.0]
        tips = [self.tip(qa), self.tip(qb)]
        k = 0
        while k < len(ts) - 1:
            if np.linalg.norm(tips[k + 1] - tips[k]) <= MAX_TRAVEL:
                k += 1
                continue
            t = 0.5 * (ts[k] + ts[k + 1])
            ts.insert(k + 1, t)
            tips.insert(k + 1, self.tip(qa + t * (qb - qa)))
        return ts

    def move_depth(self, qa: np.ndarray, qb: np.ndarray) -> float:
        """The deepest penetration at any checked point of the move (0: none deeper than MIN_DEPTH)."""
        qa, qb = np.asarray(qa, float), np.asarray(qb, float)
        deepest = max(self.depth(qa + t * (qb - qa)) for t in self.points(qa, qb))
        return deepest if deepest > MIN_DEPTH else 0.0


def clearance(checker: SweepChecker, q: np.ndarray, reach: float = 0.01) -> float:
    """The least distance between a geom of the arm and a geom of the table body at q that
    MuJoCo's ``mj_geomDistance`` finds within ``reach`` metres (``reach`` when none is nearer)."""
    m, d = checker.model, checker.data
    d.qpos[:] = q
    mujoco.mj_forward(m, d)
    best = reach
    for g1 in np.flatnonzero(checker.arm):
        if not (m.geom_contype[g1] or m.geom_conaffinity[g1]):
            continue
        for g2 in np.flatnonzero(checker.env):
            best = min(best, mujoco.mj_geomDistance(m, d, int(g1), int(g2), reach, None))
    return best


def move_clearance(checker: SweepChecker, qa: np.ndarray, qb: np.ndarray, reach: float = 0.01) -> float:
    """The least :func:`clearance` over the checked points of the move."""
    qa, qb = np.asarray(qa, float), np.asarray(qb, float)
    return min(clearance(checker, qa + t * (qb - qa), reach) for t in checker.points(qa, qb))
