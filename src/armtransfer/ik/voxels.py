"""The ``joint`` action model of a spatial arm, over the 3D workspace (``worlds.voxels``).

Voxels: the plan's cells at ``LEVELS`` levels, each one cell size high, so the tool point at
(x, y, z) is in the voxel of the cell ``rint((x, y) / cell)`` at level ``floor(z / cell)``
(levels 0..LEVELS-1; below the tabletop or above the top level it is outside the workspace).
A wall cell is solid at the levels its box reaches into (``ceil(WALL_HEIGHT / cell)``: 2 of
3 on the rooms' 1 cm cells, 1 on a small world's larger cells), so the arm may lift its tool
over a wall; the MuJoCo scene is the 2D one, unchanged, and contact with it blocks a move.

States: the points of a joint lattice (origin + n * delta) on ``MOVED`` joints of the
chain, the others held at the origin's values, reached from the origin by +-delta moves
through configurations whose tool point is in a free voxel and whose arm touches neither
the table, a wall nor itself. The origin is an IK configuration (tool pointing down) over
the free cell nearest the table's centre. The moved joints are the ``MOVED`` of the chain
whose position Jacobian at the origin has the largest smallest singular value (the joints
that move the tool point in every direction: shoulder and elbow, not the wrist). Holding the
rest keeps the lattice about three-dimensional: with every joint moving, a 6-joint arm's
lattice over the same voxels has the orientations of its wrist besides, 10^5 to 10^7 times
as many points. The search is a breadth-first search from the origin and stops with an
error past ``MAX_STATES`` states.

A move is blocked when it leaves the joint limits, when the tool point, at interpolated
points no more than half a cell apart, leaves the workspace or enters a solid voxel, or when
any arm geometry comes into the table, a wall or the arm itself anywhere along it (the swept
check of ``ik.sweep``; the end is checked with MuJoCo's contacts too). Wind pushes the tool one cell towards
+x at its level: to the lattice neighbour in that voxel whose tool point is nearest the
voxel's centre (blocked when no neighbour is there).
"""

from __future__ import annotations

import itertools
import math
from collections import deque

import mujoco
import numpy as np

from armtransfer.errors import ArmModelError, UnreachableTableError
from armtransfer.ik.compile import _progress
from armtransfer.ik.labels import cells_of_xy
from armtransfer.ik.scene import ArmScene, ContactChecker
from armtransfer.ik.seeds import _cells_by_distance
from armtransfer.ik.solve import TipIK
from armtransfer.ik.sweep import SweepChecker
from armtransfer.ik.workspace import WALL_HEIGHT
from armtransfer.worlds.voxels import LEVELS, Voxels

MOVED = 3
"""How many joints of a spatial arm the ``joint`` model moves (the rest are held)."""
MAX_STATES = 200_000
"""The most lattice states the search keeps (memory and time grow with them)."""
SPATIAL_STEPS = (0.01, 0.015, 0.02, 0.03, 0.05, 0.08, 0.12)
"""Lattice steps (rad) a spatial arm's step is chosen from when not given: the coarsest whose
largest tool move per step is at most ``STEP_CELLS`` of a cell at the origin."""
STEP_CELLS = 1.0


def workspace_voxels(layout, cell: float) -> Voxels:
    """The voxels of ``layout`` at cell size ``cell``: walls solid at the levels their boxes
    (``WALL_HEIGHT`` tall) reach into."""
    return Voxels(layout, LEVELS, min(LEVELS, int(math.ceil(WALL_HEIGHT / cell - 1e-9))))


def voxels_of_points(p: np.ndarray, cell: float, vox: Voxels) -> np.ndarray:
    """Voxel ids of points [..., 3] (metres, table frame); -1 outside the workspace."""
    p = np.asarray(p, dtype=float)
    cells = cells_of_xy(p[..., :2], cell, vox.layout)
    levels = np.floor(p[..., 2] / cell).astype(np.int64)
    return vox.ids(cells, levels)


def voxel_of_point(p, cell: float, vox: Voxels) -> int:
    """``voxels_of_points`` of one point, in plain Python (the search asks it for every point)."""
    lay = vox.layout
    x, y = round(float(p[0]) / cell), round(float(p[1]) / cell)  # rint's rounding: half to even
    k = math.floor(float(p[2]) / cell)
    if not (lay.lo <= x <= lay.hi and lay.lo <= y <= lay.hi and 0 <= k < vox.levels):
        return -1
    return k * lay.n_cells + (y - lay.lo) * lay.width + (x - lay.lo)


class SpatialFK:
    """MuJoCo forward kinematics of the tool point (the labelling ``ik.labels`` does with mink)."""

    def __init__(self, scene: ArmScene) -> None:
        self.model = scene.model
        self.data = mujoco.MjData(scene.model)
        self.site = mujoco.mj_name2id(scene.model, mujoco.mjtObj.mjOBJ_SITE, scene.tip)

    def tip(self, q: np.ndarray) -> np.ndarray:
        self.data.qpos[:] = q
        mujoco.mj_kinematics(self.model, self.data)
        return self.data.site_xpos[self.site].copy()

    def jacobian(self, q: np.ndarray) -> np.ndarray:
        """d tip / d q [3, nq]."""
        self.data.qpos[:] = q
        mujoco.mj_kinematics(self.model, self.data)
        mujoco.mj_comPos(self.model, self.data)
        jacp = np.zeros((3, self.model.nv))
        mujoco.mj_jacSite(self.model, self.data, jacp, None, self.site)
        return jacp


def spatial_origin(scene: ArmScene) -> np.ndarray:
    """An IK configuration, tool pointing down, over the free cell nearest the table's centre
    that IK reaches (of the 50 nearest)."""
    layout, cell = scene.layout, scene.cell
    ik = TipIK(scene, True)
    for c in _cells_by_distance(np.zeros(2), cell, layout)[:50]:
        x, y = layout.xy(int(c))
        res = ik.solve(np.array([x * cell, y * cell]), scene.home)
        if ik.ok(res):
            return res.q
    raise UnreachableTableError("the arm's tool cannot reach the table near its centre with IK, so its joint "
                                "lattice has no start; use the cartesian action model")


def moved_joints(jac: np.ndarray, k: int = MOVED) -> tuple[int, ...]:
    """The ``k`` columns of ``jac`` [3, n] whose 3 x k block has the largest smallest singular
    value (lowest indices on ties)."""
    n = jac.shape[1]
    if n <= k:
        return tuple(range(n))
    best, best_s = tuple(range(k)), -1.0
    for combo in itertools.combinations(range(n), k):
        s = float(np.linalg.svd(jac[:, combo], compute_uv=False)[-1])
        if s > best_s + 1e-12:
            best, best_s = combo, s
    return best


def choose_step(jac: np.ndarray, moved: tuple[int, ...], cell: float) -> float:
    lever = float(max(np.linalg.norm(jac[:, j]) for j in moved))
    fits = [s for s in SPATIAL_STEPS if s * lever <= STEP_CELLS * cell]
    return fits[-1] if fits else SPATIAL_STEPS[0]


def compile_spatial_joint(scene: ArmScene, step: float | None, progress: bool = False) -> dict:
    """The arrays of a spatial arm's ``joint`` robot; labels are voxel ids."""
    layout, cell = scene.layout, scene.cell
    vox = workspace_voxels(layout, cell)
    free = vox.free
    fk = SpatialFK(scene)
    contact = ContactChecker(scene)
    sweep = SweepChecker(scene, contact)
    origin = spatial_origin(scene)
    jac = fk.jacobian(origin)
    moved = moved_joints(jac)
    if step is None:
        step = choose_step(jac, moved, cell)
    k = len(moved)
    lo = np.where(np.isfinite(scene.lower), scene.lower, -np.inf)
    hi = np.where(np.isfinite(scene.upper), scene.upper, np.inf)

    def config(idx: tuple[int, ...]) -> np.ndarray:
        q = origin.copy()
        for j, n in zip(moved, idx):
            q[j] += n * step
        return q

    def voxel(q: np.ndarray) -> tuple[int, np.ndarray]:
        """(voxel id, tip) of q; -1 when outside, solid or touching."""
        hit, tip = contact.touches_and_tip(q)
        v = voxel_of_point(tip, cell, vox)
        return (-1 if hit or v < 0 or not free[v] else v), tip

    v0, tip0 = voxel(origin)
    if v0 < 0:
        raise UnreachableTableError("the arm's joint lattice has no start: its IK configuration over the table's "
                                    "centre touches the table or a wall; use the cartesian action model")
    start = (0,) * k
    index: dict[tuple[int, ...], int] = {start: 0}
    qs, labels, tips = [origin], [v0], [tip0]
    edges: list[tuple[int, int, int]] = []  # (state, action, next state)
    clear: dict[tuple[int, int], bool] = {}  # (lower state, higher state): the move between them is clear
    queue: deque[tuple[int, ...]] = deque([start])
    while queue:
        idx = queue.popleft()
        s = index[idx]
        for a in range(2 * k):
            j, sign = a // 2, (1 if a % 2 == 0 else -1)
            nidx = idx[:j] + (idx[j] + sign,) + idx[j + 1:]
            if nidx in index:
                t = index[nidx]
                if t >= 0:
                    pair = (min(s, t), max(s, t))
                    if pair not in clear:
                        clear[pair] = _swept_clear(sweep, fk, qs[s], qs[t], tips[s], tips[t], cell, vox)
                    if clear[pair]:
                        edges.append((s, a, t))
                continue
            q = config(nidx)
            if not lo[moved[j]] - 1e-9 <= q[moved[j]] <= hi[moved[j]] + 1e-9:
                continue
            v, tip = voxel(q)
            if v < 0:
                index[nidx] = -1
                continue
            if not _swept_clear(sweep, fk, qs[s], q, tips[s], tip, cell, vox):
                continue  # this move is blocked; the point may still be reached another way
            clear[(s, len(qs))] = True
            index[nidx] = len(qs)
            qs.append(q)
            labels.append(v)
            tips.append(tip)
            edges.append((s, a, index[nidx]))
            queue.append(nidx)
            if len(qs) > MAX_STATES:
                raise ArmModelError(
                    f"the joint lattice of this arm at a step of {step:g} rad has more than {MAX_STATES:,} states "
                    "over the 3D workspace; give a coarser joint step (joint_step=, e.g. 0.08) or a smaller world")
    n = len(qs)
    _progress(progress, f"  3D lattice: joints {[m + 1 for m in moved]} at {step:g} rad, {n} states")
    next_state = np.repeat(np.arange(n, dtype=np.int32)[:, None], 2 * k, axis=1)
    for s, a, t in edges:
        next_state[s, a] = t
    qpos = np.array(qs)
    label = np.array(labels, dtype=np.int64)
    tip = np.array(tips)
    lattice = np.zeros((n, k), dtype=np.int32)
    for idx, s in index.items():
        if s >= 0:
            lattice[s] = idx
    wind, canonical = _wind_and_canonical(next_state, label, tip, vox, cell)
    return dict(next_state=next_state, wind_state=wind, label=label.astype(np.int32), canonical=canonical,
                qpos=qpos, tip=tip, lattice=lattice, joint_step=np.array(step),
                moved=np.array(moved, dtype=np.int32), levels=np.array(vox.levels),
                wall_levels=np.array(vox.wall_levels))


def _wind_and_canonical(next_state: np.ndarray, label: np.ndarray, tip: np.ndarray, vox: Voxels,
                        cell: float) -> tuple[np.ndarray, np.ndarray]:
    """(wind state, canonical state): where the wind pushes each state (one of its moves onto the +x
    voxel at its level, the one whose tip is nearest that voxel's centre; itself when none is, or
    on the east edge), and each voxel's state whose tip is nearest its centre (-1: unreached)."""
    n = len(label)
    centres = _centres(label, vox, cell)
    err = np.linalg.norm(tip - centres, axis=1)
    wind = np.arange(n, dtype=np.int32)
    lx = label + 1  # the +x voxel at the same level, when the cell is not on the east edge
    east = (vox.layout.xy_of(vox.cell_of(label))[:, 0] < vox.layout.hi)
    for s in range(n):
        if not east[s]:
            continue
        cands = [int(t) for t in next_state[s] if label[t] == lx[s]]
        if cands:
            wind[s] = min(cands, key=lambda t: (err[t], t))
    canonical = np.full(vox.n_voxels, -1, dtype=np.int32)
    for s in np.lexsort((np.arange(n), err))[::-1]:
        canonical[label[s]] = s
    return wind, canonical


def _centres(label: np.ndarray, vox: Voxels, cell: float) -> np.ndarray:
    xy = vox.layout.xy_of(vox.cell_of(label)) * cell
    z = (vox.level_of(label) + 0.5) * cell
    return np.column_stack([xy, z])


def _move_clear(contact: ContactChecker, fk: SpatialFK, qa, qb, pa, pb, cell: float, vox: Voxels) -> bool:
    """The straight joint move qa -> qb: at points at most half a cell of tool travel apart,
    the tool in a free voxel and no contact (the ends are checked by the caller)."""
    m = max(1, int(math.ceil(2.0 * float(np.linalg.norm(np.asarray(pb) - np.asarray(pa))) / cell)))
    for t in np.arange(1, m + 1) / (m + 1):
        hit, tip = contact.touches_and_tip(qa + (qb - qa) * t)
        v = voxel_of_point(tip, cell, vox)
        if hit or v < 0 or not vox.free[v]:
            return False
    return True


def _swept_clear(sweep: SweepChecker, fk: SpatialFK, qa, qb, pa, pb, cell: float, vox: Voxels) -> bool:
    """The straight joint move qa -> qb: at points at most half a cell of tool travel apart,
    the tool in a free voxel (the ends are checked by the caller), and no contact anywhere
    along it (``ik.sweep``)."""
    m = max(1, int(math.ceil(2.0 * float(np.linalg.norm(np.asarray(pb) - np.asarray(pa))) / cell)))
    for t in np.arange(1, m + 1) / (m + 1):
        v = voxel_of_point(fk.tip(qa + (qb - qa) * t), cell, vox)
        if v < 0 or not vox.free[v]:
            return False
    return sweep.clear(qa, qb)

