"""An independent check that an arm robot's moves keep out of the walls and the table.

Written apart from the compile code (``armtransfer.ik.compile``, ``ik.voxels``, ``ik.sweep``):
it takes only the robot's compiled configurations and its rebuilt MuJoCo scene, and none of
the compile's helpers. Each move ``qa -> qb`` is interpolated linearly in joint space, at
points chosen so that the tool point (the scene's tip site) travels at most ``TRAVEL`` between
two consecutive points (the spacing is refined until every chord is that short); at each point
``mj_forward`` runs and every contact between a geom of the arm that a joint moves and a geom
of the table body (the tabletop or a wall) deeper than ``DEPTH`` is counted. The deepest such
contact along the move is its penetration.

Door-crossing moves: those whose two ends lie in different rooms (connected free cells once
the doors, free cells between two opposite walls, are taken out) or either end over a door.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass

import mujoco
import numpy as np

TRAVEL = 5e-4
"""Largest tool-point travel (m) between two checked points of a move."""
DEPTH = 1e-4
"""Contacts shallower than this (m) are not counted."""


@dataclass
class MoveResult:
    state: int
    action: int
    target: int
    depth: float
    """Deepest arm-wall or arm-table penetration along the move (m; 0 when none counted)."""
    what: str
    points: int


class WallChecker:
    def __init__(self, model: mujoco.MjModel, tip_site: str) -> None:
        self.model = model
        self.data = mujoco.MjData(model)
        self.tip = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, tip_site)
        assert self.tip >= 0, tip_site
        table = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "table")
        self.scenery = model.geom_bodyid == table
        self.moving = (model.body_weldid[model.geom_bodyid] != 0) & ~self.scenery

    def _tips(self, qa, qb, ts) -> np.ndarray:
        out = np.empty((len(ts), 3))
        for i, t in enumerate(ts):
            self.data.qpos[:] = qa + (qb - qa) * t
            mujoco.mj_kinematics(self.model, self.data)
            out[i] = self.data.site_xpos[self.tip]
        return out

    def samples(self, qa, qb) -> np.ndarray:
        """Interpolation parameters in [0, 1] whose tool points are at most ``TRAVEL`` apart."""
        n = 16
        while True:
            ts = np.linspace(0.0, 1.0, n + 1)
            tips = self._tips(qa, qb, ts)
            chord = np.linalg.norm(np.diff(tips, axis=0), axis=1)
            if chord.max() <= TRAVEL * 0.8 or n >= 1 << 16:
                return ts
            n = max(2 * n, int(np.ceil(chord.sum() / (TRAVEL * 0.5))))

    def depth_at(self, q) -> tuple[float, str]:
        d = self.data
        d.qpos[:] = q
        mujoco.mj_forward(self.model, d)
        n = d.ncon
        if n == 0:
            return 0.0, ""
        g1, g2, dist = d.contact.geom1[:n], d.contact.geom2[:n], d.contact.dist[:n]
        counted = ((self.scenery[g1] & self.moving[g2]) | (self.scenery[g2] & self.moving[g1])) & (-dist > DEPTH)
        if not counted.any():
            return 0.0, ""
        i = int(np.argmin(np.where(counted, dist, np.inf)))
        names = [mujoco.mj_id2name(self.model, mujoco.mjtObj.mjOBJ_GEOM, int(g)) or f"geom {g}" for g in (g1[i], g2[i])]
        return float(-dist[i]), " with ".join(names)

    def move(self, qa, qb) -> tuple[float, str, int]:
        qa, qb = np.asarray(qa, float), np.asarray(qb, float)
        ts = self.samples(qa, qb)
        deepest, what = 0.0, ""
        for t in ts:
            depth, name = self.depth_at(qa + (qb - qa) * t)
            if depth > deepest:
                deepest, what = depth, name
        return deepest, what, len(ts)


def checker_for(robot) -> WallChecker:
    """The checker of an arm robot, on its scene rebuilt from its description."""
    from armtransfer.ik.replay import robot_scene

    scene = robot_scene(robot)
    return WallChecker(scene.model, scene.tip)


def moves(robot) -> np.ndarray:
    """Every move [k, 3] (state, action, next state) that changes the state, each unordered
    pair of states once."""
    ns = np.asarray(robot.next_state)
    s, a = np.nonzero(ns != np.arange(len(ns))[:, None])
    t = ns[s, a]
    keep = np.unique(np.stack([np.minimum(s, t), np.maximum(s, t)], axis=1), axis=0, return_index=True)[1]
    return np.stack([s, a, t], axis=1)[np.sort(keep)]


def rooms_and_doors(layout) -> tuple[np.ndarray, np.ndarray]:
    """(room id per cell id, -1 for walls and doors; door mask per cell id)."""
    wall = np.asarray(layout.wall_mask, dtype=bool)
    h, w = wall.shape
    pad = np.pad(wall, 1)
    across = (pad[1:-1, :-2] & pad[1:-1, 2:]) | (pad[:-2, 1:-1] & pad[2:, 1:-1])
    door = across & ~wall
    room = np.full((h, w), -1)
    k = 0
    for y0 in range(h):
        for x0 in range(w):
            if wall[y0, x0] or door[y0, x0] or room[y0, x0] >= 0:
                continue
            room[y0, x0] = k
            queue = deque([(y0, x0)])
            while queue:
                y, x = queue.popleft()
                for dy, dx in ((1, 0), (-1, 0), (0, 1), (0, -1)):
                    yy, xx = y + dy, x + dx
                    if 0 <= yy < h and 0 <= xx < w and not wall[yy, xx] and not door[yy, xx] and room[yy, xx] < 0:
                        room[yy, xx] = k
                        queue.append((yy, xx))
            k += 1
    return room.reshape(-1), door.reshape(-1)


def door_crossing(robot, all_moves: np.ndarray) -> np.ndarray:
    """Boolean over ``all_moves``: the door-crossing ones."""
    layout = robot.layout
    room, door = rooms_and_doors(layout)
    cells = np.asarray(robot.label) % layout.n_cells
    a, b = cells[all_moves[:, 0]], cells[all_moves[:, 2]]
    return door[a] | door[b] | (room[a] != room[b])


def check(robot, chosen: np.ndarray, checker: WallChecker | None = None) -> list[MoveResult]:
    checker = checker or checker_for(robot)
    q = np.asarray(robot.arm.qpos, dtype=float)
    out = []
    for s, a, t in chosen:
        depth, what, n = checker.move(q[s], q[t])
        out.append(MoveResult(int(s), int(a), int(t), depth, what, n))
    return out


def sample(robot, n_random: int, rng: np.random.Generator, doors: bool = True,
           max_doors: int | None = None) -> np.ndarray:
    """Door-crossing moves (all, or ``max_doors`` of them drawn at random) and ``n_random``
    of the rest drawn at random."""
    every = moves(robot)
    crossing = door_crossing(robot, every)
    door_moves = every[crossing] if doors else every[:0]
    if max_doors is not None and len(door_moves) > max_doors:
        door_moves = door_moves[np.sort(rng.choice(len(door_moves), max_doors, replace=False))]
    rest = every[~crossing]
    pick = rest[np.sort(rng.choice(len(rest), min(n_random, len(rest)), replace=False))] if len(rest) else rest
    return np.concatenate([door_moves, pick])
