"""Where to mount an arm that came without a base pose: candidates and a quick reach estimate.

An arm file says nothing of where it stands relative to the table. ``candidates`` lists
base poses worth trying:

- an arm whose joint axes are all vertical (a SCARA-like arm, its tip riding at one height)
  is hung at the height that puts its tool's lowest point ``TIP_HEIGHT`` above the tabletop, over points of a grid
  across and around the table;
- any other arm stands on the table's plane beside it, on the four sides and at the four
  corners, at a few distances, turned so that its home tip points at the table's centre;
  an arm too small to cover the table from beside it may also stand on the table, inside
  a room (``on_table``): its fixed base then stands on cells, never on a wall, on the
  tabletop and on a pedestal (its links turn a few centimetres from the 2 cm walls, and
  the pedestal lifts them clear); and its best few poses are also tried on each pedestal
  of ``LIFTS``.

``estimate_reach`` scores one pose: inverse kinematics (``ik.quick.QuickIK``, the compile's
acceptance rule at a fraction of its cost; tool pointing down for spatial arms) over a
sparse lattice of free cells, warm-started from neighbour to neighbour as the compile does,
and contact-checked; the score is the share of those cells reached. The caller (``armtransfer.tasks.arms``) compiles the best few poses in
full and keeps the one that reaches the most free cells with the tasks solvable.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import mujoco
import numpy as np

from armtransfer.ik.seeds import reach_bound, seed_cells
from armtransfer.ik.labels import cells_of_xy
from armtransfer.ik.scene import ArmScene, ContactChecker, base_footing, build_scene
from armtransfer.ik.quick import QuickIK
from armtransfer.ik.solve import TIP_HEIGHT
from armtransfer.ik.tool import Tool

if TYPE_CHECKING:  # the layout is passed in from armtransfer.tasks, never imported
    from armtransfer.worlds.layout import Layout

STRIDE = 4
"""Cells between the lattice points the estimate tries (every 4th cell each way)."""
SEEDS = 2
"""Cells nearest the home tip and nearest the point halfway to the table's centre that the
estimate tries first (``seeds.seed_cells``; then one at each point around the base)."""
RESTARTS = 4
"""Random configurations the estimate tries for a first cell, after home."""
LIGHT_RESTARTS = 1
"""The same, for a light estimate."""
PLANAR_GRID = (-0.2, -0.1, 0.0, 0.1, 0.2)
"""Base positions (m, each axis) tried for an arm with vertical joint axes."""
GAPS = (-0.04, 0.0, 0.05, 0.15, 0.3)
"""Distances (m) of the base's axis from the table's edge tried for a spatial arm standing beside it
(negative: on the table, inside its edge)."""
LIFTS = (0.05, 0.1)
"""Heights (m) of a pedestal tried under the best few poses of a spatial arm that does not
cover the table standing at the tabletop's height."""


@dataclass(frozen=True)
class Pose:
    pos: tuple[float, float, float]
    yaw: float

    def lifted(self, height: float) -> "Pose":
        return Pose((self.pos[0], self.pos[1], round(self.pos[2] + height, 4)), self.yaw)

    def describe(self) -> str:
        return f"base at ({self.pos[0]:.3f}, {self.pos[1]:.3f}, {self.pos[2]:.3f}) m, yaw {self.yaw:.3f} rad"


def _tip_at(scene: ArmScene, q: np.ndarray) -> np.ndarray:
    data = mujoco.MjData(scene.model)
    data.qpos[:] = q
    mujoco.mj_kinematics(scene.model, data)
    return data.site_xpos[mujoco.mj_name2id(scene.model, mujoco.mjtObj.mjOBJ_SITE, scene.tip)].copy()


def _base(scene: ArmScene) -> tuple[np.ndarray, float]:
    """Where the arm's base is in its file's frame (``ik.scene.base_footing``): a file may put
    its base far from its origin."""
    anchor, bottom = base_footing(scene.model, scene.home)
    return anchor[:2].copy(), bottom


class _Placer:
    """Mounts (the file frame's pose) that stand the base's axis at a point of the table frame,
    its bottom on the tabletop (or at a given height), turned so that home points at the
    table's centre. The base and its home direction are found once per arm."""

    def __init__(self, scene: ArmScene) -> None:
        self.anchor, self.bottom = _base(scene)
        tip = _tip_at(scene, scene.home)
        self.tip_z = float(tip[2])
        d = tip[:2] - self.anchor
        self.facing = math.atan2(d[1], d[0]) if np.linalg.norm(d) > 1e-6 else 0.0

    def __call__(self, x: float, y: float, z: float | None, yaw: float | None) -> Pose:
        if yaw is None:
            yaw = (math.atan2(-y, -x) if (x, y) != (0.0, 0.0) else 0.0) - self.facing
        yaw = (yaw + math.pi) % (2 * math.pi) - math.pi
        c, s = math.cos(yaw), math.sin(yaw)
        ax, ay = c * self.anchor[0] - s * self.anchor[1], s * self.anchor[0] + c * self.anchor[1]
        height = -self.bottom if z is None else z
        return Pose((round(x - ax, 4), round(y - ay, 4), round(height, 4)), round(yaw, 4))


def on_table(scene: ArmScene, yaw: float | None = None) -> list[Pose]:
    """Base poses on the table itself, over the grid of ``PLANAR_GRID`` (spatial arms)."""
    place = _Placer(scene)
    return [place(x, y, None, yaw) for x in PLANAR_GRID for y in PLANAR_GRID]


def candidates(scene: ArmScene, table_half: float, yaw: float | None = None) -> list[Pose]:
    """Base poses to try for the arm of ``scene`` (built at the origin, yaw 0)."""
    place = _Placer(scene)
    if scene.planar:  # hung so that the tip rides just above the tabletop
        z = TIP_HEIGHT + scene.clearance - place.tip_z  # the tool's lowest point 4 mm up
        return [place(x, y, z, 0.0 if yaw is None else yaw) for x in PLANAR_GRID for y in PLANAR_GRID]
    _, reach = reach_bound(scene)
    out = []
    for gap in GAPS:
        d = table_half + gap
        for k in range(8):
            theta = -math.pi / 2 + k * math.pi / 4  # start in front of the table (-y side)
            r = d * (math.sqrt(2) if k % 2 == 1 else 1.0)
            if r - table_half > reach:  # cannot reach even the nearest edge
                continue
            out.append(place(r * math.cos(theta), r * math.sin(theta), None, yaw))
    return out


def _lattice(layout: Layout, extra: list[int]) -> list[int]:
    ids = [layout.cell(x, y) for x in range(layout.lo, layout.hi + 1, STRIDE)
           for y in range(layout.lo, layout.hi + 1, STRIDE) if layout.free[layout.cell(x, y)]]
    return sorted(set(ids) | {int(c) for c in extra if layout.free[int(c)]})


def estimate_reach(xml_path, tool: Tool, pose: Pose, layout: Layout, cell: float, *,
                   must: Sequence[int] = (), rng: np.random.Generator | None = None,
                   light: bool = False) -> tuple[float, int]:
    """(share of the sparse lattice's free cells reached, how many of ``must`` were reached),
    with the quick IK (``ik.quick.QuickIK``) and the compile's contact check. The first cell
    is sought from the seeds of ``SEEDS`` and ``RESTARTS``, or with ``light`` from one cell
    per seed point and one random configuration (a pose that reaches much of the table
    finds it at once)."""
    scene = build_scene(xml_path, tool, pose.pos, pose.yaw, cell, layout=layout)
    ik = QuickIK(scene, tip_down=not scene.planar)
    contact = ContactChecker(scene)
    if contact.base_on_wall():
        return 0.0, 0
    rng = rng if rng is not None else np.random.default_rng(0)
    cells = _lattice(layout, list(must))
    xy = layout.xy_of(np.array(cells)) * cell
    found: dict[int, np.ndarray] = {}

    def attempt(i: int, q0: np.ndarray, restarts: int = 0) -> bool:
        q, ok = ik.solve_any(xy[i], q0, rng, restarts=restarts) if restarts else ik.solve(xy[i], q0)
        if not ok or contact.touches(q):
            return False
        if int(cells_of_xy(contact.tip(q), cell, layout)) != cells[i]:
            return False
        found[i] = q
        return True

    queue: deque[int] = deque()
    index = {c: i for i, c in enumerate(cells)}
    n, restarts = (1, LIGHT_RESTARTS) if light else (SEEDS, RESTARTS)
    for c in seed_cells(scene, _tip_at(scene, scene.home), n=n):  # from home or random configurations
        i = index.get(c)
        if i is None:
            i = int(np.argmin(np.linalg.norm(xy - np.array(layout.xy(c)) * cell, axis=1)))
        if i not in found and attempt(i, scene.home, restarts=restarts):
            queue.append(i)
            break
    spacing = STRIDE * cell * 1.5
    tries = np.zeros(len(cells), dtype=int)
    while queue:
        i = queue.popleft()
        near = np.flatnonzero(np.linalg.norm(xy - xy[i], axis=1) <= spacing)
        for k in near:
            j = int(k)
            if j in found or tries[j] >= 2:
                continue
            tries[j] += 1
            if attempt(j, found[i]):
                queue.append(j)
    share = len(found) / max(1, len(cells))
    must_set = {int(c) for c in must}
    reached_must = sum(1 for i in found if cells[i] in must_set)
    return share, reached_must


__all__ = ["Pose", "candidates", "estimate_reach"]
