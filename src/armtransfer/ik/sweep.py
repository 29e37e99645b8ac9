"""Swept contact check of a straight joint-space move, at a resolution set by the geometry.

A move ``qa -> qb`` (every joint interpolated linearly, ``q(t) = qa + t (qb - qa)``) is clear
when no moving arm geom comes within ``-TOLERANCE`` of the table or a wall (penetrates it by
more than ``TOLERANCE``), nor of another arm geom it may collide with (a pair not already in
contact at home; see ``ContactChecker``), anywhere along it.

It is checked by conservative advancement on MuJoCo's own distances. On a copy of the model
whose moving arm geoms have a collision margin of ``QUERY``, ``mj_collision`` reports every
counted pair closer than ``QUERY`` with its distance. A point of geom ``g`` moves, per unit of
``t``, at most ``rate_g = sum_j |dq_j| R[g, j]``, where ``R[g, j]`` bounds the distance of
the geom's points from joint ``j``'s anchor over every configuration (the lengths between the
anchors of joints ``j .. m`` along the chain, plus the geom's distance from joint ``m``'s
anchor and its bounding radius; ``m`` the last joint that moves it). So a pair at distance
``d`` cannot meet before ``t`` has advanced ``d / rate`` (the sum of both geoms' rates for an
arm-arm pair), a geom with no reported pair not before ``QUERY / rate``. The check steps by
the smallest of these, and by no less than ``TOLERANCE / rate``, so no point of the move is
checked farther than ``TOLERANCE`` of geometry travel from a point found clear: between two
checks a geom penetrates by at most ``TOLERANCE``. Far from everything a move is one or two
checks; near a wall the checks close in as the gap closes. MuJoCo's general convex collider
(cylinders, meshes, ellipsoids) reports no pair it finds apart, whatever the margin: those
geoms' distances to the partners whose boxes are near are asked of ``mj_geomDistance``.

The tabletop is horizontal: a joint whose axis stays vertical (the first joints of the chain
while their axes are vertical: every joint of a planar arm) moves nothing up or down, so
against the tabletop (a contact with a vertical normal, the geom inside the table's edge) only
the other joints count. A planar arm's tool rides at one height and never nears the table
along a move.
"""

from __future__ import annotations

import copy

import mujoco
import numpy as np

from armtransfer.ik.scene import ArmScene, ContactChecker

TOLERANCE = 2.5e-4
"""Deepest penetration (m) of a wall, the table or the arm itself a clear move may hide between
two checks: the geometry travel between checks when a gap is smaller than this."""
QUERY = 0.02
"""Distance (m) within which MuJoCo reports a pair's distance (the moving geoms' margin)."""


def anchors(model: mujoco.MjModel, data: mujoco.MjData) -> np.ndarray:
    """Each joint's anchor [njnt, 3] in chain (qpos) order, from the kinematics in ``data``."""
    order = np.argsort(model.jnt_qposadr)
    return data.xanchor[order].copy()


def reach_bounds(scene: ArmScene) -> np.ndarray:
    """``R[g, j]`` [ngeom, nq]: a bound on the distance of geom ``g``'s points from joint ``j``'s
    anchor at every configuration (0 when joint ``j`` does not move the geom)."""
    model = scene.model
    data = mujoco.MjData(model)
    data.qpos[:] = scene.home
    mujoco.mj_kinematics(model, data)
    order = np.argsort(model.jnt_qposadr)
    a = anchors(model, data)
    links = np.linalg.norm(np.diff(a, axis=0), axis=1)  # anchor j to anchor j + 1: fixed by the chain
    joint_body = model.jnt_bodyid[order]
    n = model.nq
    out = np.zeros((model.ngeom, n))
    for g in np.flatnonzero(scene.arm_geoms):
        ancestors = set()
        b = int(model.geom_bodyid[g])
        while b > 0:
            ancestors.add(b)
            b = int(model.body_parentid[b])
        moved_by = [j for j in range(n) if int(joint_body[j]) in ancestors]
        if not moved_by:
            continue
        last = max(moved_by)
        own = float(np.linalg.norm(data.geom_xpos[g] - a[last]) + model.geom_rbound[g])
        for j in moved_by:
            out[g, j] = float(links[j:last].sum()) + own
    return out


def level_joints(scene: ArmScene) -> int:
    """How many joints, from the base, keep their axes vertical at every configuration (the
    longest prefix of the chain with vertical axes at home)."""
    model = scene.model
    data = mujoco.MjData(model)
    data.qpos[:] = scene.home
    mujoco.mj_kinematics(model, data)
    axes = data.xaxis[np.argsort(model.jnt_qposadr)]
    vertical = np.abs(np.abs(axes[:, 2]) - 1.0) < 1e-9
    return int(np.argmin(vertical)) if not vertical.all() else len(vertical)


def _not_filtered(model: mujoco.MjModel) -> np.ndarray:
    """[ngeom, ngeom]: the geom pairs MuJoCo's collision does not filter out by their bodies
    (not on one welded body, not a body and its parent unless the parent is the world, not an
    ``<exclude>`` pair)."""
    weld = model.body_weldid[model.geom_bodyid]
    parent = model.body_weldid[model.body_parentid[model.body_weldid[model.geom_bodyid]]]
    keep = weld[:, None] != weld[None, :]
    if not model.opt.disableflags & mujoco.mjtDisableBit.mjDSBL_FILTERPARENT:
        keep &= ~((parent[:, None] == weld[None, :]) & (weld[None, :] != 0))
        keep &= ~((parent[None, :] == weld[:, None]) & (weld[:, None] != 0))
    body = model.geom_bodyid
    for sig in model.exclude_signature:
        b1, b2 = int(sig) >> 16, int(sig) & 0xFFFF
        pair = (body[:, None] == b1) & (body[None, :] == b2)
        keep &= ~(pair | pair.T)
    return keep


class SweepChecker:
    """Whether straight joint moves of a scene's arm are clear along their whole sweep (see the
    module docstring). Counts the contacts ``ContactChecker`` counts."""

    def __init__(self, scene: ArmScene, contact: ContactChecker | None = None) -> None:
        contact = contact or ContactChecker(scene)
        model = copy.copy(scene.model)
        model.geom_margin[:] = 0.0
        model.geom_margin[scene.arm_geoms] = QUERY
        model.geom_gap[:] = 0.0
        self.model = model
        self.data = mujoco.MjData(model)
        self.checks = 0
        """Collision queries made so far."""
        self._env = scene.env_geoms
        self._moving = scene.arm_geoms
        table_body = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "table")
        self._table = (model.geom_bodyid == table_body) & ~contact.walls
        self._half = scene.layout.width * scene.cell / 2
        self._R = reach_bounds(scene)
        self._Rz = self._R.copy()
        self._Rz[:, :level_joints(scene)] = 0.0  # level joints move nothing up or down
        self._rb = model.geom_rbound.copy()
        # MuJoCo's general convex collider (cylinders, meshes, ellipsoids) reports no pair it
        # finds apart, whatever the margin: those geoms' distances are asked of mj_geomDistance
        kind = model.geom_type
        special = [mujoco.mjtGeom.mjGEOM_PLANE, mujoco.mjtGeom.mjGEOM_SPHERE, mujoco.mjtGeom.mjGEOM_CAPSULE,
                   mujoco.mjtGeom.mjGEOM_BOX]
        self._gjk = [int(g) for g in np.flatnonzero(scene.arm_geoms & ~np.isin(kind, special))]
        self._fromto = np.zeros(6)
        self._level = level_joints(scene)
        kind = model.geom_type
        self._size = np.where((kind == mujoco.mjtGeom.mjGEOM_SPHERE)[:, None], [1.0, 0.0, 0.0], 1.0) * model.geom_size
        self._round = np.isin(kind, [mujoco.mjtGeom.mjGEOM_SPHERE, mujoco.mjtGeom.mjGEOM_CAPSULE,
                                     mujoco.mjtGeom.mjGEOM_CYLINDER])
        self._jnt = np.argsort(model.jnt_qposadr)
        env, moving = self._env, self._moving
        g1, g2 = (g.reshape(-1) for g in np.meshgrid(np.arange(model.ngeom), np.arange(model.ngeom), indexing="ij"))
        own = contact._own(g1, g2).reshape(model.ngeom, model.ngeom)  # the self-contacts the checker counts
        self._count = (env[:, None] & moving[None, :]) | (moving[:, None] & env[None, :]) | own
        collide = ((model.geom_contype[:, None] & model.geom_conaffinity[None, :])
                   | (model.geom_conaffinity[:, None] & model.geom_contype[None, :])) != 0
        collide &= _not_filtered(model)
        partners = {g: np.flatnonzero(self._count[g] & collide[g]) for g in self._gjk}
        data = mujoco.MjData(model)
        mujoco.mj_kinematics(model, data)
        self._boxes = {}  # the scenery's partners of each: ids, world box centres and half sizes (fixed)
        for g, hs in partners.items():
            fixed = hs[env[hs]]
            rot = np.abs(data.geom_xmat[fixed].reshape(-1, 3, 3))
            centre = data.geom_xpos[fixed] + np.einsum("nij,nj->ni", data.geom_xmat[fixed].reshape(-1, 3, 3),
                                                       model.geom_aabb[fixed, :3])
            self._boxes[g] = (fixed, centre, np.einsum("nij,nj->ni", rot, model.geom_aabb[fixed, 3:]))
        self._arm_partners = {g: hs[~env[hs]] for g, hs in partners.items()}
        # the same pairs as rows, so that one pass of numpy finds the near ones of every geom:
        # (geom, scenery partner) with the partner's fixed box, and (geom, arm partner)
        self._fg = np.array([g for g in self._gjk for _ in self._boxes[g][0]], dtype=np.int64)
        self._fh = np.concatenate([self._boxes[g][0] for g in self._gjk] or [np.zeros(0, np.int64)]).astype(np.int64)
        self._fc = np.concatenate([self._boxes[g][1] for g in self._gjk] or [np.zeros((0, 3))])
        self._fhalf = np.concatenate([self._boxes[g][2] for g in self._gjk] or [np.zeros((0, 3))])
        self._ag = np.array([g for g in self._gjk for _ in self._arm_partners[g]], dtype=np.int64)
        self._ah = np.concatenate([self._arm_partners[g] for g in self._gjk] or [np.zeros(0, np.int64)]).astype(np.int64)

    def clear(self, qa: np.ndarray, qb: np.ndarray) -> bool:
        """No counted contact deeper than ``TOLERANCE`` anywhere on the move ``qa -> qb``."""
        qa = np.asarray(qa, dtype=float)
        dq = np.asarray(qb, dtype=float) - qa
        moved = np.flatnonzero(dq)
        m, d = self.model, self.data
        d.qpos[:] = qa
        mujoco.mj_kinematics(m, d)
        if len(moved) == 1:  # one joint turns: each point keeps its distance from that axis
            j = int(moved[0])
            rate = self._turn_rate(j) * abs(float(dq[j]))
            rate_z = rate if j >= self._level else np.zeros_like(rate)
        else:
            rate = self._R @ np.abs(dq)  # [ngeom] travel per unit t
            rate_z = self._Rz @ np.abs(dq)
        top = float(rate.max())
        if top <= 0.0:
            return not self._blocked(d)
        far = QUERY / top
        t = 0.0
        while True:
            mujoco.mj_collision(m, d)
            self.checks += 1
            step = far
            n = d.ncon
            if n:
                con = d.contact
                g1, g2 = con.geom1[:n], con.geom2[:n]
                counted = self._count[g1, g2]
                if counted.any():
                    dist = con.dist[:n][counted]
                    if float(dist.min()) < 0.0:
                        return False
                    g1, g2 = g1[counted], g2[counted]
                    r = rate[g1] + rate[g2]
                    table = self._table[g1] | self._table[g2]
                    if table.any():
                        arm_g = np.where(self._table[g1], g2, g1)
                        level = np.abs(con.frame[:n, 2][counted]) > 1.0 - 1e-9
                        inside = np.all(np.abs(d.geom_xpos[arm_g, :2]) + self._rb[arm_g, None] < self._half, axis=1)
                        r = np.where(table & level & inside, rate_z[arm_g], r)
                    step = min(step, float(np.min(np.maximum(dist, TOLERANCE) / np.maximum(r, 1e-12))))
            if self._gjk:
                near = self._apart_all()
                if near is None:
                    return False
                for g, h, dist_h, level in near:
                    r_h = rate[g] + rate[h] if not self._env[h] else (rate_z[g] if level else rate[g])
                    step = min(step, max(dist_h, TOLERANCE) / max(r_h, 1e-12))
            if t >= 1.0:
                return True
            t = min(1.0, t + step)
            d.qpos[:] = qa + t * dq
            mujoco.mj_kinematics(m, d)

    def _apart_all(self) -> list[tuple[int, int, float, bool]] | None:
        """(geom, partner, distance, against the tabletop from above) of every geom whose distances
        are asked of ``mj_geomDistance`` and each of its counted partners within ``QUERY`` (by
        their bounding boxes, all pairs in one pass, then ``mj_geomDistance``); None when a pair
        is in contact."""
        m, d = self.model, self.data
        xpos, rb = d.geom_xpos, self._rb
        pairs: list[tuple[int, int]] = []
        if self._fg.size:
            diff = np.abs(xpos[self._fg] - self._fc) - self._fhalf
            np.maximum(diff, 0.0, out=diff)
            gap = np.sqrt(np.einsum("ij,ij->i", diff, diff)) - rb[self._fg]
            sel = np.flatnonzero(gap < QUERY)
            pairs += zip(self._fg[sel].tolist(), self._fh[sel].tolist())
        if self._ag.size:
            diff = np.abs(xpos[self._ag] - xpos[self._ah]) - rb[self._ah, None]
            np.maximum(diff, 0.0, out=diff)
            gap = np.sqrt(np.einsum("ij,ij->i", diff, diff)) - rb[self._ag]
            sel = np.flatnonzero(gap < QUERY)
            pairs += zip(self._ag[sel].tolist(), self._ah[sel].tolist())
        out = []
        for g, h in pairs:
            dist = mujoco.mj_geomDistance(m, d, g, h, QUERY, self._fromto)
            if dist < 0.0:
                return None
            if dist < QUERY:
                centre, radius = xpos[g], rb[g]
                way = self._fromto[3:] - self._fromto[:3]
                level = bool(self._table[h] and dist > 0 and abs(way[2]) > (1.0 - 1e-9) * np.linalg.norm(way)
                             and np.all(np.abs(centre[:2]) + radius < self._half))
                out.append((g, h, float(dist), level))
        return out

    def _turn_rate(self, j: int) -> np.ndarray:
        """Per geom, a bound on its points' distance from joint ``j``'s axis at the configuration
        in :attr:`data` (0 for geoms the joint does not move)."""
        d = self.data
        a, w = d.xanchor[self._jnt[j]], d.xaxis[self._jnt[j]]
        r = d.geom_xpos - a
        along = r @ w
        dist = np.sqrt(np.maximum(np.einsum("ij,ij->i", r, r) - along * along, 0.0))
        # how far a geom reaches from its centre across the axis: a sphere its radius, a
        # capsule or cylinder its radius plus its half length times the sine of its tilt from
        # the axis, anything else its bounding radius
        cos = d.geom_xmat[:, 2::3] @ w
        ext = np.where(self._round, self._size[:, 0] + self._size[:, 1] * np.sqrt(np.maximum(1.0 - cos * cos, 0.0)),
                       self._rb)
        return np.where(self._R[:, j] > 0, dist + ext, 0.0)

    def _blocked(self, d: mujoco.MjData) -> bool:
        mujoco.mj_collision(self.model, d)
        self.checks += 1
        n = d.ncon
        counted = self._count[d.contact.geom1[:n], d.contact.geom2[:n]]
        return bool(np.any(d.contact.dist[:n][counted] < 0.0))


__all__ = ["QUERY", "TOLERANCE", "SweepChecker", "level_joints", "reach_bounds"]
