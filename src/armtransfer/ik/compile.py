"""Compile (arm scene, action model) into the arrays of a discrete robot.

``cartesian``: one canonical configuration per reachable free cell, found by mink IK in a
breadth-first sweep over cells from the home cell (each IK warm-started from the
neighbour it was reached from). A move of k cells is a table lookup, blocked when the
target or a cell passed over is a wall or off the table, when IK found no configuration
for the target, when the tip, at 3k points of the straight joint-space move between the two
configurations, passes over a wall cell, leaves the table or strays more than 0.75 cell from
the straight line between the cells, or when the arm touches the table, a wall or itself
anywhere along the move (the swept check of ``ik.sweep``). (A self-contact is
one between two arm bodies that MuJoCo reports and that is not there at home already; see
``ik.scene.ContactChecker``.)

``joint`` (planar arms): states are the points of a joint lattice (home + n * delta,
inside the joint limits) reachable from home by +-delta moves, whose tip is over a free
cell and not touching a wall or itself. The lattice's forward kinematics is vectorised with numpy
(vertical joint axes: the tip is a sum of rotated link vectors taken from MuJoCo at
q = 0; the tests check it against mink). A move is blocked when it leaves the limits,
the tip passes over a wall cell or off the table at any of the interpolated points
(spaced at most half a cell apart), or the arm touches the table, a wall or itself anywhere
along the move (the swept check of ``ik.sweep``). Only the arm's geoms that reach below the
walls' tops can touch them (a planar arm's heights never change), and when all of those are
fixed to the tool they ride within ``extent`` of the tool point (``wall_reach``): a lattice
point is asked about contacts only over a cell that near a wall, and a move only when its tip
passes that near one and cannot be shown clear in 2D (the tip sampled every ``FINE_SPACING``,
each sample's distance from the wall boxes less ``extent`` a stretch it is clear for, and the
stretches meeting). Any other low geom, or arm geoms that may collide with each other
(``ContactChecker.can_self_collide``; the built-in arms' may not), make every lattice point
and move asked.

Wind pushes the tip one cell towards +x: for cartesian robots it is the 1-cell +x move;
for joint robots it is the lattice state labelled with the cell to the right that is
nearest to the joint step a Jacobian step predicts (blocked when none is).
"""

from __future__ import annotations

import itertools
import math
import sys
from collections import deque

import mujoco
import numpy as np

from armtransfer.errors import ArmModelError, UnreachableTableError
from armtransfer.ik.diagnose import why_unreachable
from armtransfer.ik.labels import OFF_TABLE, cells_of_xy
from armtransfer.ik.scene import ArmScene, ContactChecker, _support
from armtransfer.ik.seeds import RING, SEED_RESTARTS, _cells_by_distance, reach_bound, seed_cells  # noqa: F401
from armtransfer.ik.solve import MAX_TIP_HEIGHT, TIP_HEIGHT, TipIK
from armtransfer.ik.sweep import SweepChecker


def near_wall_mask(layout) -> np.ndarray:
    """Boolean over cell ids: a wall cell or one of its 8 neighbours."""
    w = layout.wall_mask
    pad = np.pad(w, 1)
    near = np.zeros_like(w)
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            near |= pad[1 + dy:1 + dy + w.shape[0], 1 + dx:1 + dx + w.shape[1]]
    return near.reshape(-1)


def near_wall_cells(layout, k: int) -> np.ndarray:
    """Boolean over cell ids: a wall cell or a cell within ``k`` cells of one (along x and y)."""
    w = layout.wall_mask
    pad = np.pad(w, k)
    near = np.zeros_like(w)
    for dy in range(-k, k + 1):
        for dx in range(-k, k + 1):
            near |= pad[k + dy:k + dy + w.shape[0], k + dx:k + dx + w.shape[1]]
    return near.reshape(-1)


def wall_reach(scene: ArmScene, contact: ContactChecker) -> tuple[np.ndarray, bool, float]:
    """(the cells over which a planar arm's tip may bring its geometry into a wall, whether it
    may anywhere, how far (m) across the table that geometry reaches from the tool point).
    Only geoms that reach below the walls' tops can meet them; a planar arm's heights never
    change. Those rigid with the tool point reach at most their horizontal
    extent from it: the cells within that (plus the three quarters of a cell a tip sampled
    every half cell may be from the samples' cells) of a wall. Any other such geom, or geoms
    of the arm that may collide with each other, make every cell count."""
    m = scene.model
    data = mujoco.MjData(m)
    data.qpos[:] = scene.home
    mujoco.mj_kinematics(m, data)
    walls = np.flatnonzero(contact.walls)
    if contact.can_self_collide:
        return np.ones(scene.layout.n_cells, dtype=bool), True, np.inf
    if len(walls) == 0:
        return np.zeros(scene.layout.n_cells, dtype=bool), False, 0.0
    up, down = np.array([0.0, 0.0, 1.0]), np.array([0.0, 0.0, -1.0])
    top = float(max(data.geom_xpos[w, 2] + _support(m, data, int(w), up) for w in walls))
    tip = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, scene.tip)
    tool_weld = m.body_weldid[m.site_bodyid[tip]]
    point = data.site_xpos[tip]
    hits = np.zeros(m.ngeom, dtype=bool)
    for w in walls:
        hits |= ((m.geom_contype & m.geom_conaffinity[w]) | (m.geom_conaffinity & m.geom_contype[w])) != 0
    extent = 0.0
    for g in np.flatnonzero(hits & scene.arm_geoms):
        if data.geom_xpos[g, 2] - _support(m, data, int(g), down) >= top:
            continue  # rides above the walls
        if m.body_weldid[m.geom_bodyid[g]] != tool_weld:
            return np.ones(scene.layout.n_cells, dtype=bool), True, np.inf
        if m.geom_type[g] in (mujoco.mjtGeom.mjGEOM_SPHERE, mujoco.mjtGeom.mjGEOM_CAPSULE,
                              mujoco.mjtGeom.mjGEOM_CYLINDER):  # its radius, and its half length as it tilts
            tilt = float(data.geom_xmat[g].reshape(3, 3)[2, 2])
            half = 0.0 if m.geom_type[g] == mujoco.mjtGeom.mjGEOM_SPHERE else float(m.geom_size[g, 1])
            side = float(m.geom_size[g, 0]) + half * math.sqrt(max(0.0, 1.0 - tilt * tilt))
        else:  # a support function is sublinear: along any horizontal direction at most sqrt(2)
            # times the largest along +-x, +-y
            side = math.sqrt(2.0) * max(_support(m, data, int(g), np.array(u, dtype=float))
                                        for u in ((1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0)))
        extent = max(extent, float(np.linalg.norm(data.geom_xpos[g, :2] - point[:2]) + side))
    k = max(1, int(np.ceil(extent / scene.cell + 0.75)))
    return near_wall_cells(scene.layout, k), False, extent


def wall_boxes(scene: ArmScene, contact: ContactChecker) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """The walls across the table: (centre [2], rotation [2, 2], half sizes [2]) of each box."""
    m = scene.model
    data = mujoco.MjData(m)
    mujoco.mj_kinematics(m, data)
    return [(data.geom_xpos[w, :2].copy(), data.geom_xmat[w].reshape(3, 3)[:2, :2].copy(), m.geom_size[w, :2].copy())
            for w in np.flatnonzero(contact.walls)]


def wall_distance(boxes, xy: np.ndarray) -> np.ndarray:
    """Distance (m) across the table from points ``xy`` [..., 2] to the nearest of the wall
    ``boxes`` (:func:`wall_boxes`; 0 inside one)."""
    best = np.full(xy.shape[:-1], np.inf)
    for centre, rot, half in boxes:
        gap = np.maximum(np.abs((xy - centre) @ rot) - half, 0.0)  # in the box's frame (it stands upright)
        best = np.minimum(best, np.hypot(gap[..., 0], gap[..., 1]))
    return best


def _shown_clear(q0: np.ndarray, j: int, step: float, n: int, reach: float, extent: float, boxes,
                 fk: PlanarFK) -> np.ndarray:
    """Which of the moves from ``q0`` [k, dof] by ``step`` on joint ``j`` keep a planar arm's low
    geometry (within ``extent`` of the tip) clear of the wall boxes, shown in 2D.

    The tip travels at most ``step * reach`` along a move, evenly in the joint angle. At ``n + 1``
    evenly spaced samples it is ``g_i`` from the walls, so it may travel ``g_i - extent`` from
    there clear of them: an interval between two samples is clear when their two stretches
    meet. An interval that is not is cut into pieces of at most ``FINE_SPACING`` of travel
    and asked the same of those; the move is clear when every interval is."""
    k = len(q0)
    if k == 0:
        return np.zeros(0, dtype=bool)
    travel = step * reach
    room = np.empty((k, n + 1))
    for s in range(n + 1):
        q = q0.copy()
        q[:, j] += step * s / n
        room[:, s] = wall_distance(boxes, fk.tip(q)) - extent
    inside = (room[:, :-1] > 0) & (room[:, 1:] > 0)
    open_ = inside & (room[:, :-1] + room[:, 1:] > travel / n)
    edge, at = np.nonzero(inside & ~open_)  # intervals to look at more finely
    pieces = max(1, int(np.ceil(travel / n / FINE_SPACING)))
    for chunk in np.array_split(np.arange(len(edge)), max(1, len(edge) * (pieces + 1) // 200_000)):
        ec, ic = edge[chunk], at[chunk]
        q = np.repeat(q0[ec][:, None, :], pieces + 1, axis=1)
        q[:, :, j] += step * (ic[:, None] + np.linspace(0.0, 1.0, pieces + 1)[None, :]) / n
        r = wall_distance(boxes, fk.tip(q)) - extent
        open_[ec, ic] = np.all(r > 0, axis=1) & np.all(r[:, 1:] + r[:, :-1] > travel / n / pieces, axis=1)
    return np.all(open_, axis=1)


def _progress(enabled: bool, text: str) -> None:
    if enabled:
        print(text, file=sys.stderr, flush=True)


# --------------------------------------------------------------------------- cartesian


def _check_tip_height(scene: ArmScene, z: float) -> None:
    """A planar arm's tip rides at one height: its tool's lowest point must be on the table,
    not in it."""
    low = z - scene.clearance
    if low < -1e-3 and scene.clearance > 0:
        raise UnreachableTableError(
            f"the arm's tool is in the table: its point rides {z * 1000:.1f} mm above the tabletop and its geom "
            f"{scene.clearance_geom} reaches {scene.clearance * 1000:.1f} mm past the point; raise the base by "
            f"{(TIP_HEIGHT - low) * 1000:.1f} mm")
    if not -1e-3 <= low <= MAX_TIP_HEIGHT:
        where = "" if scene.clearance == 0 else f" (its lowest point {low:.3f} m)"
        raise UnreachableTableError(
            f"the arm's tip cannot reach the table: it moves {z:.3f} m above the tabletop{where} "
            f"(at most {MAX_TIP_HEIGHT} m allowed); move the base by {-(low - TIP_HEIGHT):+.3f} m in z")


def _check_table_in_reach(scene: ArmScene, home_tip: np.ndarray) -> None:
    """Fail at once, not after thousands of IK solves, when the tip cannot reach the table."""
    if scene.planar:
        _check_tip_height(scene, float(home_tip[2]))
        return
    anchor, reach = reach_bound(scene)
    half = scene.layout.width * scene.cell / 2
    nearest = np.array([np.clip(anchor[0], -half, half), np.clip(anchor[1], -half, half), 0.0])
    if np.linalg.norm(anchor - nearest) > reach:
        raise UnreachableTableError(
            f"the arm's tip cannot reach the table: the table is {np.linalg.norm(anchor - nearest):.2f} m from "
            f"its base, and the arm reaches at most {reach:.2f} m")


def compile_cartesian(scene: ArmScene, tip_down: bool, k: int, progress: bool = False) -> dict:
    layout, cell = scene.layout, scene.cell
    free = layout.free
    ik = TipIK(scene, tip_down)
    contact = ContactChecker(scene)
    sweep = SweepChecker(scene, contact)

    home_tip = ik.configuration
    home_tip.update(scene.home)
    p = home_tip.get_transform_frame_to_world(scene.tip, "site").translation()
    _check_table_in_reach(scene, p)

    q_of: dict[int, np.ndarray] = {}
    attempts = np.zeros(layout.n_cells, dtype=np.int8)

    def try_cell(c: int, q0: np.ndarray, rng: np.random.Generator | None = None) -> bool:
        """IK for cell c from q0 (and, given ``rng``, from random configurations too)."""
        attempts[c] += 1
        x, y = layout.xy(c)
        target = np.array([x * cell, y * cell])
        res = ik.solve(target, q0) if rng is None else ik.solve_any(target, q0, rng, restarts=SEED_RESTARTS)
        if not ik.ok(res):
            return False
        tip = ik.configuration.get_transform_frame_to_world(scene.tip, "site").translation()
        if int(cells_of_xy(tip, cell, layout)) != c or contact.touches(res.q):
            return False
        q_of[c] = res.q
        return True

    queue: deque[int] = deque()
    rng = np.random.default_rng(0)
    for c in seed_cells(scene, p):
        if free[c] and attempts[c] == 0 and (try_cell(c, scene.home) or try_cell(c, scene.home, rng)):
            queue.append(c)
            break
    while queue:
        c = queue.popleft()
        x, y = layout.xy(c)
        for dx, dy in ((1, 0), (-1, 0), (0, 1), (0, -1)):
            nx, ny = x + dx, y + dy
            if not layout.in_grid(nx, ny):
                continue
            n = layout.cell(nx, ny)
            if free[n] and n not in q_of and attempts[n] < 3 and try_cell(n, q_of[c]):
                queue.append(n)
    if not q_of:
        cause = why_unreachable(scene, tip_down)
        hint = scene.tool.axis_hint() if tip_down else ""
        raise UnreachableTableError(
            "the arm's tip cannot reach the table: IK finds no configuration with the tip "
            "over a free cell, at most 1 cm above the tabletop" + "".join(f"; {t}" for t in (cause, hint) if t))
    _progress(progress, f"  IK: {len(q_of)} cells reached")

    cells = np.array(sorted(q_of), dtype=np.int64)
    index = np.full(layout.n_cells, -1, dtype=np.int64)
    index[cells] = np.arange(len(cells))
    qpos = np.stack([q_of[int(c)] for c in cells])
    n = len(cells)

    checked: dict[tuple[int, int], bool] = {}

    def move_ok(s: int, dx: int, dy: int, steps: int) -> int:
        x, y = layout.xy(int(cells[s]))
        for i in range(1, steps + 1):
            if not layout.in_grid(x + dx * i, y + dy * i) or not free[layout.cell(x + dx * i, y + dy * i)]:
                return s
        t = int(index[layout.cell(x + dx * steps, y + dy * steps)])
        if t < 0:
            return s
        key = (min(s, t), max(s, t))
        if key not in checked:
            checked[key] = _segment_clear(contact, sweep, qpos[s], qpos[t], np.array([x, y]) * cell,
                                          np.array([x + dx * steps, y + dy * steps]) * cell,
                                          3 * steps, cell, layout)
        return t if checked[key] else s

    next_state = np.empty((n, 4), dtype=np.int32)
    wind = np.empty(n, dtype=np.int32)
    for s in range(n):
        for a, (dx, dy) in enumerate(((0, 1), (0, -1), (1, 0), (-1, 0))):
            next_state[s, a] = move_ok(s, dx, dy, k)
        wind[s] = move_ok(s, 1, 0, 1)
    tips = np.array([contact.tip(q) for q in qpos])
    canonical = np.full(layout.n_cells, -1, dtype=np.int32)
    canonical[cells] = np.arange(n)
    return dict(next_state=next_state, wind_state=wind, label=cells.astype(np.int32),
                canonical=canonical, qpos=qpos, tip=tips)


def _segment_clear(contact: ContactChecker, sweep: SweepChecker, qa, qb, pa, pb, n_points: int, cell,
                   layout) -> bool:
    d = pb - pa
    length2 = float(d @ d)
    for t in np.linspace(0.0, 1.0, n_points + 2)[1:-1]:
        tip = contact.tip(qa + (qb - qa) * t)
        c = int(cells_of_xy(tip, cell, layout))
        if c == OFF_TABLE or not layout.free[c]:
            return False
        u = np.clip(((tip[:2] - pa) @ d) / length2, 0.0, 1.0)
        if np.linalg.norm(tip[:2] - (pa + u * d)) > 0.75 * cell:
            return False
    return sweep.clear(qa, qb)


# --------------------------------------------------------------------------- joint lattice


class PlanarFK:
    """Vectorised forward kinematics of an arm whose joint axes are all vertical."""

    def __init__(self, scene: ArmScene) -> None:
        model = scene.model
        data = mujoco.MjData(model)
        data.qpos[:] = 0.0
        mujoco.mj_kinematics(model, data)
        if model.njnt != model.nq:
            raise ArmModelError("the joint action model needs an arm with hinge joints only")
        axes = data.xaxis[: model.njnt]
        if np.any(np.abs(np.abs(axes[:, 2]) - 1.0) > 1e-6):
            raise ArmModelError(
                "the joint action model needs a planar arm (all joint axes vertical); "
                "use the cartesian action model")
        self.sign = np.sign(axes[:, 2])
        order = np.argsort(model.jnt_qposadr)
        anchors = data.xanchor[order][:, :2]
        site = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, scene.tip)
        tip = data.site_xpos[site]
        self.origin = anchors[0].copy()
        self.offsets = np.diff(np.vstack([anchors, tip[:2]]), axis=0)  # [n, 2]
        self.tip_z = float(tip[2])
        self.sign = self.sign[order]

    def angles(self, q: np.ndarray) -> np.ndarray:
        return np.cumsum(q * self.sign, axis=-1)

    def tip(self, q: np.ndarray) -> np.ndarray:
        """Tip (x, y) for configurations q [..., n]."""
        th = self.angles(q)
        c, s = np.cos(th), np.sin(th)
        ox, oy = self.offsets[:, 0], self.offsets[:, 1]
        x = self.origin[0] + np.sum(c * ox - s * oy, axis=-1)
        y = self.origin[1] + np.sum(s * ox + c * oy, axis=-1)
        return np.stack([x, y], axis=-1)

    def jacobian(self, q: np.ndarray) -> np.ndarray:
        """d tip / d q, shape [..., 2, n]."""
        th = self.angles(q)
        c, s = np.cos(th), np.sin(th)
        ox, oy = self.offsets[:, 0], self.offsets[:, 1]
        vx, vy = c * ox - s * oy, s * ox + c * oy  # rotated link vectors
        # Joint i moves every link vector from i on: d/dq_i = sign_i * z x (sum_{k>=i} v_k).
        rx = np.flip(np.cumsum(np.flip(vx, -1), -1), -1)
        ry = np.flip(np.cumsum(np.flip(vy, -1), -1), -1)
        return np.stack([-ry * self.sign, rx * self.sign], axis=-2)

    def reach_from(self, j: int) -> float:
        return float(np.sum(np.linalg.norm(self.offsets[j:], axis=1)))


def _lattice_origin(scene: ArmScene, fk: PlanarFK) -> np.ndarray:
    """Home if its tip is over a free cell, else an IK configuration over the free cell
    nearest home's tip (the joint lattice is laid out from this configuration)."""
    layout, cell = scene.layout, scene.cell
    home = scene.home.astype(float)
    c = int(cells_of_xy(fk.tip(home), cell, layout))
    if c >= 0 and layout.free[c]:
        return home
    ik = TipIK(scene, False)
    for c in _cells_by_distance(fk.tip(home), cell, layout)[:50]:
        x, y = layout.xy(int(c))
        res = ik.solve(np.array([x * cell, y * cell]), home)
        if ik.ok(res):
            return res.q
    rng = np.random.default_rng(0)  # a straight (singular) home: start IK elsewhere too
    for c in seed_cells(scene, np.append(fk.tip(home), fk.tip_z)):
        x, y = layout.xy(int(c))
        res = ik.solve_any(np.array([x * cell, y * cell]), home, rng, restarts=SEED_RESTARTS)
        if ik.ok(res):
            return res.q
    raise UnreachableTableError("the arm's tip cannot reach the table near its home configuration")


FINE_SPACING = 5e-4
"""Most tip travel (m) between the samples at which a planar joint move near a wall is shown
clear of the walls without MuJoCo (``compile_joint``)."""
MAX_LATTICE = 1_000_000
"""The most joint-lattice points the ``joint`` model lays out (memory grows with them)."""
STEP_LADDER = (0.05, 0.08, 0.12, 0.18, 0.25, 0.35, 0.5)
"""Lattice steps (rad) tried, finest first, when the arm's step is not given."""


def _lattice_dims(lo: np.ndarray, hi: np.ndarray, home: np.ndarray, step: float):
    n_lo = np.ceil((lo - home) / step - 1e-9).astype(int)
    n_hi = np.floor((hi - home) / step + 1e-9).astype(int)
    return n_lo, tuple(int(v) for v in n_hi - n_lo + 1)


def joint_box(scene: ArmScene, centre: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(lowest, highest) configuration: the joint limits, or pi either side of ``centre`` for
    a joint without limits."""
    return (np.where(np.isfinite(scene.lower), scene.lower, centre - np.pi),
            np.where(np.isfinite(scene.upper), scene.upper, centre + np.pi))


def ladder_step(lo: np.ndarray, hi: np.ndarray, home: np.ndarray) -> float:
    """The finest of ``STEP_LADDER`` whose lattice about ``home`` within [lo, hi] has at most
    ``MAX_LATTICE`` points (the coarsest when none has)."""
    sizes = {s: int(np.prod(_lattice_dims(lo, hi, home, s)[1], dtype=float)) for s in STEP_LADDER}
    return next((s for s in STEP_LADDER if sizes[s] <= MAX_LATTICE), STEP_LADDER[-1])


def compile_joint(scene: ArmScene, step: float | None, progress: bool = False) -> dict:
    """The ``joint`` model's arrays; ``step`` None: the finest of ``STEP_LADDER`` whose lattice
    has at most ``MAX_LATTICE`` points (the step used is returned as ``joint_step``)."""
    layout, cell = scene.layout, scene.cell
    fk = PlanarFK(scene)
    contact = ContactChecker(scene)
    free = layout.free
    sweep = SweepChecker(scene, contact)
    near, everywhere, extent = wall_reach(scene, contact)
    boxes = wall_boxes(scene, contact)
    _check_tip_height(scene, fk.tip_z)
    home = _lattice_origin(scene, fk)
    dof = len(home)
    lo, hi = joint_box(scene, home)
    if step is None:
        step = ladder_step(lo, hi, home)
    n_lo, dims = _lattice_dims(lo, hi, home, step)
    total = int(np.prod(dims, dtype=float))
    if total > MAX_LATTICE:
        raise ArmModelError(
            f"the joint lattice of this {dof}-joint arm at a step of {step:g} rad has {total:.3g} points "
            f"(at most {MAX_LATTICE:,}); use a coarser joint step or the cartesian action model")
    grids = np.indices(dims).reshape(dof, -1).T  # lattice indices [total, dof]
    Q = home + (grids + n_lo) * step
    cells = cells_of_xy(fk.tip(Q), cell, layout)
    valid = (cells >= 0) & free[np.maximum(cells, 0)]
    ask = np.ones(total, dtype=bool) if everywhere else near[np.maximum(cells, 0)]
    check = np.flatnonzero(valid & ask)
    for i in check:
        if contact.touches(Q[i]):
            valid[i] = False
    _progress(progress, f"  lattice {dims} = {total} points, {int(valid.sum())} over free cells")

    strides = np.array([int(np.prod(dims[j + 1:])) for j in range(dof)])
    plus = np.full((total, dof), -1, dtype=np.int64)  # neighbour along +step of joint j
    for j in range(dof):
        has = (grids[:, j] < dims[j] - 1) & valid
        idx = np.flatnonzero(has)
        idx = idx[valid[idx + strides[j]]]
        m = max(1, int(np.ceil(2.0 * step * fk.reach_from(j) / cell)))
        ok = np.ones(len(idx), dtype=bool)
        near_any = np.zeros(len(idx), dtype=bool)
        ts = np.arange(1, m + 1) / (m + 1)
        for t in ts:
            Qt = Q[idx].copy()
            Qt[:, j] += t * step
            c = cells_of_xy(fk.tip(Qt), cell, layout)
            inside = c >= 0
            ok &= inside & free[np.maximum(c, 0)]
            near_any |= inside & near[np.maximum(c, 0)]
        # Shown clear of the walls without MuJoCo: geometry within ``extent`` of the tip, the
        # tip ``g_i`` from the walls at sample i, so clear while it travels less than g_i - extent
        # from there; the tip travels at most ``step * reach_from(j)`` in all, evenly in t, so
        # the move is clear when each two neighbouring samples' clear stretches meet.
        certain = np.zeros(len(idx), dtype=bool)
        if not everywhere:
            rest = np.flatnonzero(ok & near_any)
            certain[rest] = _shown_clear(Q[idx[rest]], j, step, m + 1, fk.reach_from(j), extent, boxes, fk)
        for e in np.flatnonzero(ok & (near_any | everywhere) & ~certain):
            q = Q[idx[e]]
            if not sweep.clear(q, Q[idx[e] + strides[j]]):
                ok[e] = False
        plus[idx[ok], j] = idx[ok] + strides[j]

    # Breadth-first search from home over the valid edges.
    home_flat = int(np.ravel_multi_index(tuple(-n_lo), dims))
    if not valid[home_flat]:
        raise UnreachableTableError("the arm's home configuration is not over a free cell of the table")
    minus, states = _reachable(plus, home_flat)
    n = len(states)
    index = np.full(total, -1, dtype=np.int64)
    index[states] = np.arange(n)
    _progress(progress, f"  {n} lattice states reachable from home")

    next_state = np.repeat(np.arange(n, dtype=np.int64)[:, None], 2 * dof, axis=1)
    for j in range(dof):
        for a, table in ((2 * j, plus), (2 * j + 1, minus)):
            t = table[states, j]
            has = t >= 0
            next_state[has, a] = index[t[has]]
    qpos = Q[states]
    label = cells[states]
    tip_xy = fk.tip(qpos)

    wind = _joint_wind(fk, qpos, label, tip_xy, scene, (home, step, n_lo, dims, strides), index)
    lx, ly = layout.xy_of(label).T
    centres = np.stack([lx * cell, ly * cell], axis=1)
    err = np.linalg.norm(tip_xy - centres, axis=1)
    canonical = np.full(layout.n_cells, -1, dtype=np.int32)
    order = np.lexsort((np.arange(n), err))  # closest to the cell centre first
    for s in order[::-1]:
        canonical[label[s]] = s
    tips = np.column_stack([tip_xy, np.full(n, fk.tip_z)])
    return dict(next_state=next_state.astype(np.int32), wind_state=wind.astype(np.int32),
                label=label.astype(np.int32), canonical=canonical, qpos=qpos, tip=tips,
                lattice=(grids[states] + n_lo).astype(np.int32), joint_step=np.array(step))


def _reachable(plus: np.ndarray, home: int) -> tuple[np.ndarray, np.ndarray]:
    """(minus, states): the lattice's edges along -step of each joint (``plus`` reversed), and
    the lattice points a breadth-first search from ``home`` reaches over the edges both ways."""
    total, dof = plus.shape
    minus = np.full((total, dof), -1, dtype=np.int64)
    for j in range(dof):
        src = np.flatnonzero(plus[:, j] >= 0)
        minus[plus[src, j], j] = src
    seen = np.zeros(total, dtype=bool)
    seen[home] = True
    frontier = np.array([home])
    while len(frontier):
        nb = np.concatenate([plus[frontier].ravel(), minus[frontier].ravel()])
        nb = np.unique(nb[nb >= 0])
        nb = nb[~seen[nb]]
        seen[nb] = True
        frontier = nb
    return minus, np.flatnonzero(seen)


def _joint_wind(fk: PlanarFK, qpos: np.ndarray, label: np.ndarray, tip_xy: np.ndarray, scene: ArmScene,
                grid: tuple, index: np.ndarray) -> np.ndarray:
    """Where the wind pushes each state: the state labelled with the cell to the right nearest a
    Jacobian step towards it (itself when none is). ``grid``: the lattice's (home, step, lowest
    index, dims, strides)."""
    layout, cell, free = scene.layout, scene.cell, scene.layout.free
    home, step, n_lo, dims, strides = grid
    n, dof = qpos.shape
    wind = np.arange(n, dtype=np.int64)
    lx, ly = layout.xy_of(label).T
    right = np.where(lx + 1 <= layout.hi, label + 1, -1)
    has_right = (right >= 0) & free[np.maximum(right, 0)]
    target = np.stack([(lx + 1) * cell, ly * cell], axis=1)
    J = fk.jacobian(qpos)
    dq = np.einsum("nij,nj->ni", np.linalg.pinv(J), target - tip_xy)
    base = np.rint((qpos + dq - home) / step).astype(int) - n_lo
    best = np.full(n, np.inf)
    for off in itertools.product((-1, 0, 1), repeat=dof):
        g = base + np.array(off)
        inside = np.all((g >= 0) & (g < np.array(dims)), axis=1) & has_right
        flat = np.where(inside, (np.clip(g, 0, np.array(dims) - 1) * strides).sum(axis=1), 0)
        s2 = np.where(inside, index[flat], -1)
        good = (s2 >= 0) & (label[np.maximum(s2, 0)] == right) & inside
        dist = np.where(good, np.linalg.norm(qpos[np.maximum(s2, 0)] - qpos, axis=1), np.inf)
        better = dist < best
        best[better] = dist[better]
        wind[better] = s2[better]

    return wind
