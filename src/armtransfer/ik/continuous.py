"""A planar arm whose state is its joint configuration q: no table of states, MuJoCo at every move.

The ``joint`` action model without its lattice: action ``2j`` turns joint j by +delta, ``2j+1``
by -delta (``q1+``, ``q1-``, ...). Every move runs MuJoCo's kinematics and collision detection
on the arm in its table scene (``ik.scene``) at the configuration reached; nothing is
enumerated or stored. A move is blocked, and the arm stays where it was, when

- it leaves the joint limits (an unlimited joint: pi either side of where the arm started);
- MuJoCo reports a contact that ``ik.scene.ContactChecker`` counts (the table, a wall, the
  arm itself) at the configuration reached;
- a geom the moved joint carries would touch the table or a wall anywhere along the turn
  (``ik.swept``, from MuJoCo's kinematics at the end, turned back);
- the tool point, at the configuration reached or at any of the points the move's arc passes
  (spaced at most half a cell apart, as ``ik.compile``'s joint model spaces them), is over a
  wall cell or off the table; an arm that can touch itself is also asked for contacts at up to
  3 of those points.

The label is the cell under the tool point (``ik.labels.cells_of_xy``'s rule: the tip's
(x, y) divided by the cell size and rounded half to even). The configuration is kept as
q0 + n * delta with integer n, so a move and its reverse return to the same bits.

**Actuation noise** (``noise=sigma`` > 0, the arm's counterpart of the paper's wind): each
move turns its joint by delta * (1 + eps) instead of delta, eps ~ Normal(0, sigma^2) clipped
to [-NOISE_CLIP, NOISE_CLIP], drawn from the arm's own generator (:meth:`ContinuousArm.seed_noise`).
The configuration then leaves the lattice: q is q's previous value plus the noisy turn, the
limits are the same box, the arc's points are spaced for the longest turn, (1 + NOISE_CLIP) *
delta, and :meth:`ContinuousArm.place` starts at the IK solution itself (no snapping to the
lattice). Inside :meth:`ContinuousArm.noiseless` (a greedy path's roll-out) the moves are the
lattice's, from the start. With sigma = 0 nothing is drawn and every move is as without noise.

A planar arm's joint axes are vertical, so the points along a move's arc are the tip rotated
about the moved joint's anchor: they are computed from MuJoCo's tip and anchor at the end of
the move (``_sweep``), without another MuJoCo call.
"""

from __future__ import annotations

import itertools
import math
from typing import Any

import mujoco
import numpy as np

from armtransfer.errors import ArmModelError, InvalidCellError, UnreachableTableError
from armtransfer.ik import fastline, fastmove, handles, swept
from armtransfer.ik.arcs import _cell, _sweep, _sweep_turn
from armtransfer.ik.compile import joint_box, near_wall_mask
from armtransfer.ik.fastmove import PYTHON
from armtransfer.ik.labels import OFF_TABLE, cells_of_xy
from armtransfer.ik.scene import ArmScene, ContactChecker
from armtransfer.ik.solve import TipIK

BLOCKED = -2
"""What :meth:`ContinuousArm.move` returns for a blocked move (``OFF_TABLE`` is -1)."""
NOISE_CLIP = 0.5
"""The largest |eps| of a noisy move: it turns its joint by between 0.5 and 1.5 steps."""
MAX_NOISE = 0.5
"""The largest actuation noise sigma (the clip makes a larger one a uniform-like coin at the clip)."""
NOISE_BUFFER = 1024
"""Noise draws taken from the arm's generator at a time."""


def clearance_cells(layout) -> np.ndarray:
    """int64 over cell ids: the Chebyshev distance, in cells, from each cell to the nearest wall
    cell or cell off the table (a wall cell: 0). A point in a cell at distance k is at least
    (k - 1) cells from any point of a wall cell or off the table."""
    free = layout.wall_mask == False  # noqa: E712  (the layout's [y, x] mask)
    w = layout.width
    dist = np.where(free, w + 1, 0).astype(np.int64)
    padded = np.zeros((w + 2, w + 2), np.int64)  # off the table: distance 0
    for _ in range(w):  # relax until no distance shrinks (at most the grid's width passes)
        padded[1:-1, 1:-1] = dist
        nearest = dist.copy()
        for dy in (-1, 0, 1):
            for dx in (-1, 0, 1):
                nearest = np.minimum(nearest, padded[1 + dy:1 + dy + w, 1 + dx:1 + dx + w] + 1)
        if np.array_equal(nearest, dist):
            break
        dist = nearest
    return dist.reshape(-1)


class NoisyJointMoves:
    """Actuation noise of an arm's joint moves: each move turns delta * (1 + eps), eps drawn from
    the arm's own generator (:meth:`seed_noise`) in buffers of NOISE_BUFFER, Normal(0, noise^2)
    clipped to [-NOISE_CLIP, NOISE_CLIP]; :meth:`noiseless` turns it off for a roll-out. The arm
    sets ``noise`` and ``_noisy``."""

    noise: float
    _noisy: bool
    _rng: np.random.Generator
    _eps: list[float]
    _k: int
    dof: int

    def seed_noise(self, rng: np.random.Generator) -> None:
        """Draw the actuation noise from ``rng`` from now on (nothing is drawn when sigma is 0)."""
        if not isinstance(rng, np.random.Generator):
            raise ArmModelError(f"the noise generator must be a numpy.random.Generator, got {rng!r}")
        self._rng, self._eps, self._k = rng, [], 0

    def _next_eps(self) -> float:
        k = self._k
        if k >= len(self._eps):
            self._eps = np.clip(self._rng.normal(0.0, self.noise, NOISE_BUFFER), -NOISE_CLIP, NOISE_CLIP).tolist()
            k = 0
        self._k = k + 1
        return self._eps[k]

    def move_by(self, dq: np.ndarray) -> int:
        """Turn every moved joint at once, joint j by ``dq[j]`` radians (times 1 + eps_j with
        actuation noise, one draw per joint), along the straight line in joint space: the cell
        (or voxel) under the tool point after the move, or ``BLOCKED`` (the arm has not moved).
        It leaves the lattice: :meth:`key` then names the angles; :meth:`reset` goes back to the
        start. How the line is checked is the arm's ``_move_by``."""
        turn = np.asarray(dq, dtype=np.float64).reshape(-1)
        if turn.shape != (self.dof,) or not np.all(np.isfinite(turn)):
            raise ArmModelError(f"a joint move of this arm is {self.dof} finite angles, got {dq!r}")
        if self._noisy:
            turn = turn * (1.0 + np.array([self._next_eps() for _ in range(self.dof)]))
        return self._move_by(turn)

    def _move_by(self, turn: np.ndarray) -> int:
        raise NotImplementedError

    def noiseless(self) -> "_Noiseless":
        """A context in which the moves have no noise (a greedy path's roll-out: reset first,
        the moves are then the lattice's from the start); no draw is taken inside it."""
        return _Noiseless(self)


class _Noiseless:
    def __init__(self, arm: NoisyJointMoves) -> None:
        self.arm, self.was = arm, arm._noisy

    def __enter__(self) -> NoisyJointMoves:
        self.arm._noisy = False
        return self.arm

    def __exit__(self, *exc: object) -> None:
        self.arm._noisy = self.was


class ContinuousArm(NoisyJointMoves):
    """A planar arm in its table scene, moved by joint increments of ``step`` radians.

    ``q`` is the configuration (a view of MuJoCo's ``qpos``: read it, never write it),
    ``label`` the cell under the tool point, :meth:`tool_point` the point (x, y, z) in metres.
    Place the arm with :meth:`place` (over a cell, by IK) or :meth:`set_configuration`."""

    def __init__(self, scene: ArmScene, step: float, noise: float = 0.0) -> None:
        if not scene.planar:
            raise ArmModelError("the continuous arm moves its joints, which needs a planar arm (all joint axes "
                                "vertical); this arm is spatial")
        model = scene.model
        if model.njnt != model.nq or np.any(model.jnt_type != mujoco.mjtJoint.mjJNT_HINGE):
            raise ArmModelError("the continuous arm needs an arm with hinge joints only")
        if not (math.isfinite(step) and 0.0 < step <= math.pi):
            raise ArmModelError(f"the joint step must be in (0, pi] radians, got {step!r}")
        if isinstance(noise, bool) or not isinstance(noise, (int, float, np.floating, np.integer)) \
                or not (math.isfinite(noise) and 0.0 <= noise <= MAX_NOISE):
            raise ArmModelError(f"the actuation noise sigma must be a number in [0, {MAX_NOISE}], got {noise!r}")
        self.noise = float(noise)
        """sigma of the actuation noise (0: none); see the module docstring."""
        self._noisy = self.noise > 0.0
        self._rng = np.random.default_rng(0)
        self._eps: list[float] = []
        self._k = 0
        self.scene = scene
        self.step = float(step)
        self.checker = ContactChecker(scene)
        self.model, self.data = model, self.checker.data
        self.dof = int(model.nq)
        self.n_actions = 2 * self.dof
        layout = scene.layout
        self.layout = layout
        self._free = np.ascontiguousarray(layout.free)
        self._near = np.ascontiguousarray(near_wall_mask(layout))
        self._cell_size, self._lo, self._width = float(scene.cell), int(layout.lo), int(layout.width)
        self._clear = clearance_cells(layout).tolist()
        self._tip_id = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, scene.tip)
        self._jnt = np.argsort(model.jnt_qposadr)  # joint ids in qpos order
        self._qpos = self.data.qpos  # views into MuJoCo's buffers: no copy per move
        self._site_xpos = self.data.site_xpos
        self._xanchor = self.data.xanchor
        self._always_probe = self.checker.can_self_collide
        # the arc's points of each action, as rotations back from the end (``_sweep``)
        data = mujoco.MjData(model)
        mujoco.mj_kinematics(model, data)
        axis_sign = np.sign(data.xaxis[self._jnt, 2])
        points = np.vstack([data.xanchor[self._jnt, :2], data.site_xpos[self._tip_id, :2]])
        links = np.linalg.norm(np.diff(points, axis=0), axis=1)
        reach = [float(links[j:].sum()) for j in range(self.dof)]  # how far the tip can be from joint j
        self._m = np.zeros(self.n_actions, np.int64)
        # a move whose end is this many cells (Chebyshev) from every wall and the table's edge
        # has all its arc's points over free cells that are not near a wall (see clearance_cells)
        self._clear_needed = [int(math.ceil(self.step * reach[a // 2] / scene.cell)) + 3 for a in range(self.n_actions)]
        width = max(1, max(int(math.ceil(2.0 * self.step * r / scene.cell)) for r in reach))
        self._cos = np.zeros((self.n_actions, width))
        self._sin = np.zeros((self.n_actions, width))
        self._probe = []
        for a in range(self.n_actions):
            j, sign = a // 2, 1.0 - 2.0 * (a % 2)
            m = max(1, int(math.ceil(2.0 * self.step * reach[j] / scene.cell)))
            ts = np.arange(1, m + 1) / (m + 1)
            back = -(1.0 - ts) * sign * self.step * axis_sign[j]  # from the end back to the point at t
            self._m[a] = m
            self._cos[a, :m], self._sin[a, :m] = np.cos(back), np.sin(back)
            self._probe.append(tuple(float(t) for t in ts[np.unique(np.linspace(0, m - 1, min(m, 3)).round().astype(int))]))
        lo = np.where(np.isfinite(scene.lower), scene.lower, -np.inf)
        hi = np.where(np.isfinite(scene.upper), scene.upper, np.inf)
        self._limits = (lo, hi)
        # a noisy move's arc: points spaced for the longest turn, and the clearance it needs
        longest = (1.0 + NOISE_CLIP) * self.step
        self._axis_sign = axis_sign.tolist()
        self._m_noisy = [max(1, int(math.ceil(2.0 * longest * reach[a // 2] / scene.cell)))
                         for a in range(self.n_actions)]
        self._clear_noisy = [int(math.ceil(longest * reach[a // 2] / scene.cell)) + 3 for a in range(self.n_actions)]
        self._box: tuple[list[float], list[float]] = ([0.0] * self.dof, [0.0] * self.dof)
        self._reach = np.array(reach)
        self._q0: list[float] = [0.0] * self.dof  # lists: indexing them is cheaper than numpy's
        self._n: list[int] = [0] * self.dof
        self._nlo: list[int] = [0] * self.dof
        self._nhi: list[int] = [0] * self.dof
        self.label = OFF_TABLE
        self._tip: tuple[float, float, float] = (math.nan, math.nan, math.nan)
        self._start: tuple[np.ndarray, int, tuple[float, float, float]] | None = None
        self.moves = 0
        """MuJoCo kinematics + collision calls made by :meth:`move` (blocked ones too)."""
        self._fast: tuple | None | bool = False  # False: not built yet; None: not available
        self._table: np.ndarray | None = None  # the compiled move's state by address (``ik.handles``)
        self._kernel: Any = None
        self._line_table: np.ndarray | None = None  # the compiled straight move's (``_line``)
        self._line_keep: list = []
        self._line_move: Any = None
        self._line_tip = np.zeros(3)
        self._box_lo, self._box_hi = np.zeros(self.dof), np.zeros(self.dof)
        self._fresh = False  # the compiled move's arrays hold the arm's state (:meth:`fast_step`)
        # the swept check of a turn (``ik.swept``): every geom the joint carries, against the
        # table and wall boxes, along the whole turn; from the end's kinematics, turned back
        (self._sw_geoms, self._sw_sizes, self._sw_kinds, self._sw_offset, self._sw_boxes, self._sw_pairs,
         self._sw_carried, aligned) = swept.shapes(scene, self.checker, self._jnt.astype(np.int64), scene.home)
        if not aligned:
            raise ArmModelError("the continuous arm needs a workspace of axis-aligned boxes (the table and walls)")
        self._sw_frames = np.zeros((len(self._sw_geoms), 4, 3))
        self._sw_joint = [self._jnt[j:j + 1].astype(np.int64) for j in range(self.dof)]
        self._sw_anchor, self._sw_axis = np.zeros((1, 3)), np.zeros((1, 3))
        self._sw_stack, self._sw_work = np.zeros((64, 4)), np.zeros((7, 3))

    # ------------------------------------------------------------------ placing the arm

    def set_configuration(self, q: np.ndarray) -> int:
        """Put the arm at ``q`` (it becomes q0 of the moves that follow) and return its label.
        A configuration that touches something, or whose tool point is not over a free cell,
        is refused."""
        self._fresh = False
        q = np.array(q, dtype=np.float64).reshape(-1)
        if q.shape != (self.dof,) or not np.all(np.isfinite(q)):
            raise ArmModelError(f"a configuration of this arm is {self.dof} finite joint angles, got {q.tolist()}")
        lo, hi = self._limits
        if np.any(q < lo - 1e-9) or np.any(q > hi + 1e-9):
            raise ArmModelError("the configuration is outside the joint limits")
        if self.checker.touches(q):
            raise ArmModelError("the arm touches the table, a wall or itself at this configuration")
        tip = self.data.site_xpos[self._tip_id].copy()
        x, y, z = tip.tolist()
        cell = int(cells_of_xy(tip, self.scene.cell, self.layout))
        if cell < 0 or not self.layout.free[cell]:
            raise InvalidCellError("the arm's tool point is not over a free cell at this configuration")
        lo, hi = joint_box(self.scene, q)
        self._box = (lo.tolist(), hi.tolist())
        self._box_lo[:], self._box_hi[:] = lo, hi
        self._q0 = q.tolist()
        self._n = [0] * self.dof
        self._nlo = np.ceil((lo - q) / self.step - 1e-9).astype(np.int64).tolist()
        self._nhi = np.floor((hi - q) / self.step + 1e-9).astype(np.int64).tolist()
        self._qpos[:] = q
        self._start = (q.copy(), cell, (x, y, z))
        self._tip = (x, y, z)
        self.label = cell
        return cell

    def reset(self) -> int:
        """Back to the configuration last set (:meth:`set_configuration`, :meth:`place`); its label."""
        self._fresh = False
        if self._start is None:
            raise ArmModelError("place the arm (place or set_configuration) before resetting it")
        q, cell, tip = self._start
        self._qpos[:] = q
        self._n = [0] * self.dof
        self._tip = tip
        self.label = cell
        return cell

    @property
    def q(self) -> np.ndarray:
        return self._qpos

    @property
    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """(lowest, highest) configuration the moves from the current q0 can reach (with noise:
        the joint box itself)."""
        if self._noisy:
            return np.array(self._box[0]), np.array(self._box[1])
        q0 = np.array(self._q0)
        return q0 + np.array(self._nlo) * self.step, q0 + np.array(self._nhi) * self.step

    def place(self, cell: int) -> np.ndarray:
        """A configuration with the tool point over ``cell``, set as the arm's configuration;
        returns it. It lies on the arm's home lattice (home + n * step, the points the ``joint``
        model's moves reach from home), so that the moves from it reach what the joint model's
        moves reach: mink IK (from home, then from random starts of a fixed seed) gives a
        configuration over the cell, and of the lattice points around it (each joint rounded
        to the lattice, then one step either way) the one whose tool point is nearest the
        cell's centre, over the cell and touching nothing, is taken; the IK configuration
        itself when none is."""
        ik = TipIK(self.scene, False)
        x, y = self.layout.xy(int(cell))
        target = np.array([x * self.scene.cell, y * self.scene.cell])
        res = ik.solve(target, self.scene.home)
        if not ik.ok(res):
            res = ik.solve_any(target, self.scene.home, np.random.default_rng(0))
        if ik.ok(res) and self._noisy:  # no lattice to snap to
            try:
                if self.set_configuration(res.q) == cell:
                    return self.q.copy()
            except (ArmModelError, InvalidCellError):
                pass
        elif ik.ok(res):
            home = self.scene.home.astype(float)
            base = np.rint((res.q - home) / self.step)
            best, best_d = None, np.inf
            for off in itertools.product((0, -1, 1), repeat=self.dof):
                q = home + (base + np.array(off)) * self.step
                try:
                    if self.set_configuration(q) != cell:
                        continue
                except (ArmModelError, InvalidCellError):
                    continue
                d = float(np.linalg.norm(self.tool_point()[:2] - target))
                if d < best_d:
                    best, best_d = q, d
            for q in ([best] if best is not None else []) + [res.q]:
                try:
                    if self.set_configuration(q) == cell:
                        return self.q.copy()
                except (ArmModelError, InvalidCellError):
                    pass
        raise UnreachableTableError(f"the arm cannot place its tool point over cell {(x, y)} without touching "
                                    "anything")

    def key(self) -> tuple:
        """The configuration as integer steps from q0 (with noise, the joint angles themselves):
        equal keys are equal configurations."""
        if self._noisy:
            return tuple(self._qpos.tolist())
        return tuple(self._n)

    # ------------------------------------------------------------------ moving

    def move(self, a: int) -> int:
        """Take action ``a`` (0 .. 2 * dof - 1): the cell under the tool point after the move,
        or ``BLOCKED`` when the move is blocked (the arm has not moved)."""
        self._fresh = False
        if self._noisy:
            return self._move_noisy(a)
        j = a >> 1
        n = self._n[j] + 1 - 2 * (a & 1)
        self.moves += 1
        if n < self._nlo[j] or n > self._nhi[j]:
            return BLOCKED
        qpos = self._qpos
        old = qpos[j]
        qpos[j] = self._q0[j] + n * self.step
        m, d = self.model, self.data
        mujoco.mj_kinematics(m, d)
        mujoco.mj_collision(m, d)
        if (d.ncon and self.checker.touches_now()) or not self._swept_clear(j, qpos[j] - old):
            qpos[j] = old  # a contact at the end (the kinematics and contacts just computed), or along the turn
            return BLOCKED
        x, y, z = self._site_xpos[self._tip_id].tolist()
        cx, cy = round(x / self._cell_size) - self._lo, round(y / self._cell_size) - self._lo
        width = self._width
        cell = cy * width + cx if 0 <= cx < width and 0 <= cy < width else -1
        if cell < 0 or self._clear[cell] < self._clear_needed[a]:  # near a wall or the edge: check the arc
            anchor = self._xanchor[self._jnt[j]]
            cell, close = _sweep(x, y, anchor[0], anchor[1], self._cos[a], self._sin[a], self._m[a],
                                 self._cell_size, self._lo, width, self._free, self._near)
            if cell < 0 or (self._always_probe and self._probe_touches(a, old)):
                qpos[j] = old
                return BLOCKED
        elif self._always_probe and self._probe_touches(a, old):
            qpos[j] = old
            return BLOCKED
        self._n[j] = n
        self._tip = (x, y, z)
        self.label = cell
        return cell

    def _move_noisy(self, a: int) -> int:
        """:meth:`move` with actuation noise: the turn is step * (1 + eps) (one draw per move,
        blocked moves included), from q itself."""
        j = a >> 1
        sign = 1.0 - 2.0 * (a & 1)
        turn = sign * self.step * (1.0 + self._next_eps())
        self.moves += 1
        qpos = self._qpos
        old = float(qpos[j])
        new = old + turn
        if new < self._box[0][j] or new > self._box[1][j]:
            return BLOCKED
        qpos[j] = new
        m, d = self.model, self.data
        mujoco.mj_kinematics(m, d)
        mujoco.mj_collision(m, d)
        if (d.ncon and self.checker.touches_now()) or not self._swept_clear(j, new - old):
            qpos[j] = old
            return BLOCKED
        x, y, z = self._site_xpos[self._tip_id].tolist()
        cx, cy = round(x / self._cell_size) - self._lo, round(y / self._cell_size) - self._lo
        width = self._width
        cell = cy * width + cx if 0 <= cx < width and 0 <= cy < width else -1
        if cell < 0 or self._clear[cell] < self._clear_noisy[a]:
            anchor = self._xanchor[self._jnt[j]]
            cell, close = _sweep_turn(x, y, anchor[0], anchor[1], -turn * self._axis_sign[j], self._m_noisy[a],
                                      self._cell_size, self._lo, width, self._free, self._near)
            if cell < 0 or (self._always_probe and self._probe_touches(a, old)):
                qpos[j] = old
                return BLOCKED
        elif self._always_probe and self._probe_touches(a, old):
            qpos[j] = old
            return BLOCKED
        self._tip = (x, y, z)
        self.label = cell
        return cell

    @property
    def box(self) -> tuple[np.ndarray, np.ndarray]:
        """(lowest, highest) configuration any move may reach: the joint box about the start
        (an unlimited joint: pi either side of it)."""
        return np.array(self._box[0]), np.array(self._box[1])

    def _line(self) -> np.ndarray | None:
        """The table ``ik.fastline.line_move`` reads, or None (no compiled move)."""
        if self._line_table is not None:
            return self._line_table
        if self._fast is False:
            self._fast = self._build_fast()
        if not isinstance(self._fast, tuple):
            return None
        model, d, n_g = self.model, self.data, len(self._sw_geoms)
        reach, tip_reach = swept.reaches(model, self.scene.home.astype(float), self._sw_geoms, self._sw_sizes,
                                         self._sw_offset, self._tip_id)
        w = self._width
        jnt = self._jnt.astype(np.int64)
        tip_carried, ordered = swept.chain_tables(model, jnt, self._tip_id)
        if not ordered:
            return None
        nq = model.nq
        items = list(self._fast[0]) + [
            self._qpos, self._site_xpos, d.geom_xpos, d.geom_xmat, d.xanchor, d.xaxis, int(self._tip_id), 0,
            self._cell_size, np.array([self._lo, self._lo + w - 1, w, w * w], np.int64),
            np.ascontiguousarray(self._free, dtype=np.bool_), np.array(self._clear, np.int64),
            bool(self._always_probe), self._box_lo, self._box_hi, tip_reach, reach, self._sw_geoms, self._sw_offset,
            self._sw_sizes, self._sw_kinds, self._sw_boxes, self._sw_pairs, np.zeros((n_g, 4, 3)), False,
            np.zeros(0, np.int64), np.zeros((0, 3)), np.zeros((0, 3)), np.zeros(0), self._line_tip,
            np.zeros(1, np.int64), np.zeros(nq), np.zeros((n_g, 4, 3)), np.zeros((fastline.MAX_POINTS, n_g)),
            np.zeros(n_g), np.zeros((7, 3)), np.zeros((64, 4)), True, np.zeros((n_g, len(self._sw_boxes)), np.bool_),
            np.arange(nq, dtype=np.int64), jnt, self._sw_carried, tip_carried, np.zeros((nq, 3)), np.zeros((nq, 3)),
            np.zeros((n_g, 4, 3)), np.zeros(3), np.zeros(nq), np.zeros(nq), np.zeros(3), np.zeros(n_g, np.bool_)]
        self._line_keep = items
        self._line_move = fastline.line_move
        self._line_table = handles.table(fastline.LINE, items)
        return self._line_table

    def _move_by(self, turn: np.ndarray) -> int:
        """:meth:`move_by` of a checked turn (noise applied): ``BLOCKED`` when it leaves the joint
        box, MuJoCo reports a contact at its end, or the tool point at its end or at points along
        the straight line in joint space (spaced so that the tip moves at most half a cell between
        them, by ``sum_j |dq_j| * reach_j``) is over a wall or off the table, or a geom would touch
        the table or a wall anywhere along the line (``ik.fastline``, compiled; an arm that can
        touch itself is also asked for contacts at up to 3 of the tool points). A move whose
        contacts the compiled code cannot read (more than ``ik.fastmove.CONTACTS``) is checked
        here in Python, by the tool points and MuJoCo at up to 3 of them near a wall."""
        self._fresh = False
        self.moves += 1
        line = self._line_table if self._line_table is not None else self._line()
        if line is not None:
            v = self._line_move(line, turn)
            if v != PYTHON:
                if v >= 0:
                    t = self._line_tip.tolist()
                    self._tip = (t[0], t[1], t[2])
                    self.label = v
                return v
        qpos = self._qpos
        old = qpos.copy()
        new = old + turn
        if np.any(new < self._box[0]) or np.any(new > self._box[1]):
            return BLOCKED
        qpos[:] = new
        m, d = self.model, self.data
        mujoco.mj_kinematics(m, d)
        mujoco.mj_collision(m, d)
        if d.ncon and self.checker.touches_now():
            qpos[:] = old
            return BLOCKED
        x, y, z = self._site_xpos[self._tip_id].tolist()
        cx, cy = round(x / self._cell_size) - self._lo, round(y / self._cell_size) - self._lo
        width = self._width
        cell = cy * width + cx if 0 <= cx < width and 0 <= cy < width else -1
        sweep = float(np.abs(turn) @ self._reach)  # how far the tip can go along the move (metres)
        if cell < 0 or self._clear[cell] < int(math.ceil(sweep / self.scene.cell)) + 3 or self._always_probe:
            if cell < 0 or not self._free[cell]:
                qpos[:] = old
                return BLOCKED
            close = bool(self._near[cell])
            n = max(1, int(math.ceil(2.0 * sweep / self.scene.cell)))
            for k in range(1, n + 1):
                qpos[:] = old + (k / (n + 1)) * turn
                mujoco.mj_kinematics(m, d)
                px, py = self._site_xpos[self._tip_id, 0], self._site_xpos[self._tip_id, 1]
                c = int(_cell(px, py, self._cell_size, self._lo, width))
                if c < 0 or not self._free[c]:
                    qpos[:] = old
                    return BLOCKED
                close = close or bool(self._near[c])
            if close or self._always_probe:
                for k in np.unique(np.linspace(1, n, min(n, 3)).round().astype(int)):
                    if self.checker.touches(old + (k / (n + 1)) * turn):
                        qpos[:] = old
                        return BLOCKED
            qpos[:] = new
        self._tip = (x, y, z)
        self.label = cell
        return cell

    # ------------------------------------------------------------------ the compiled move

    def fast(self) -> tuple | None:
        """The arm's arrays for ``ik.fastmove.move`` (the compiled :meth:`move`), synced with
        the arm; None when there is no compiled move (actuation noise on, or MuJoCo's memory not
        as ``ik.fastmove.layout`` expects). Call :meth:`fast_done` after moving with it."""
        if self._noisy:
            return None
        if self._fast is False:
            self._fast = self._build_fast()
        if self._fast is None or not isinstance(self._fast, tuple):
            return None
        state = self._fast
        state[6][:] = self._q0
        state[7][:] = self._n
        state[7 + 1][:] = self._nlo
        state[7 + 2][:] = self._nhi
        state[24][:] = self._tip
        state[25][0] = self.label
        state[26][0] = self.moves
        return state

    def fast_step(self, a: int) -> int:
        """:meth:`move` by the compiled move (``ik.handles.planar_move``; the same result), when
        the arm has one."""
        if self._noisy:
            return self.move(a)
        if not self._fresh:  # the arm moved in Python since: the arrays from its state
            state = self.fast()
            if state is None:
                return self.move(a)
            if self._table is None:
                self._table = handles.of_state(fastmove.PLANAR, state)
                self._kernel = fastmove.planar_move
            self._fresh = True
        v = self._kernel(a, self._table)
        if v == PYTHON:
            return self.move(a)
        self.moves += 1
        if v >= 0:
            arrays = self._fast
            assert isinstance(arrays, tuple)
            self._n[a >> 1] = int(arrays[7][a >> 1])
            t = arrays[24]
            self._tip = (float(t[0]), float(t[1]), float(t[2]))
            self.label = v
        return v

    def fast_done(self) -> None:
        """Take back the arm's state from the compiled move's arrays."""
        state = self._fast
        assert isinstance(state, tuple)
        self._n = state[7].tolist()
        tip = state[24].tolist()
        self._tip = (tip[0], tip[1], tip[2])
        self.label = int(state[25][0])
        self.moves = int(state[26][0])

    def _build_fast(self) -> tuple | None:
        c = self.checker
        g = np.arange(self.model.ngeom)
        grid1, grid2 = np.meshgrid(g, g, indexing="ij")
        g1, g2 = grid1.ravel(), grid2.ravel()
        counts = ((c._env[g1] & c._moving[g2]) | (c._env[g2] & c._moving[g1]) | c._own(g1, g2))
        rng = np.random.default_rng(0)
        lo, hi = joint_box(self.scene, self.scene.home.astype(float))
        qs = rng.uniform(lo, hi, (400, self.dof))
        raw = fastmove.layout(self.model, self.data, counts.reshape(self.model.ngeom, self.model.ngeom), qs)
        if raw is None:
            return None
        probe = np.zeros((self.n_actions, 3))
        n_probe = np.zeros(self.n_actions, np.int64)
        for a, ts in enumerate(self._probe):
            probe[a, :len(ts)] = ts
            n_probe[a] = len(ts)
        return (raw, self._qpos, self._site_xpos, self._xanchor, int(self._tip_id), self._jnt.astype(np.int64),
                np.zeros(self.dof), np.zeros(self.dof, np.int64), np.zeros(self.dof, np.int64),
                np.zeros(self.dof, np.int64), self.step, self._cell_size, self._lo, self._width, self._free,
                self._near, np.array(self._clear, np.int64), np.array(self._clear_needed, np.int64), self._cos,
                self._sin, self._m, probe, n_probe, bool(self._always_probe), np.zeros(3), np.zeros(1, np.int64),
                np.zeros(1, np.int64), self.data.geom_xpos, self.data.geom_xmat, self.data.xaxis, self._sw_geoms,
                self._sw_offset, self._sw_sizes, self._sw_kinds, self._sw_carried, self._sw_boxes, self._sw_pairs,
                self._sw_frames, self._sw_anchor, self._sw_axis, self._sw_stack, self._sw_work)

    def _swept_clear(self, j: int, theta: float) -> bool:
        """Whether the turn of joint j by ``theta`` that ends at the configuration whose kinematics
        MuJoCo just ran keeps every geom it carries clear of the table and walls (``ik.swept``)."""
        d = self.data
        swept.capture(d.geom_xpos, d.geom_xmat, self._sw_geoms, self._sw_offset, d.xanchor, d.xaxis,
                      self._sw_joint[j], self._sw_frames, self._sw_anchor, self._sw_axis)
        return swept.rotation_clear(self._sw_frames, self._sw_sizes, self._sw_kinds, self._sw_carried[j],
                                    self._sw_anchor[0], self._sw_axis[0], -theta, self._sw_boxes, self._sw_pairs,
                                    self._sw_stack, self._sw_work)

    def _probe_touches(self, a: int, old: float) -> bool:
        """MuJoCo contact at up to 3 points along the move from ``old`` (joint a // 2)."""
        j = a >> 1
        end = float(self._qpos[j])
        q = self._qpos.copy()
        hit = False
        for t in self._probe[a]:
            q[j] = old + t * (end - old)
            if self.checker.touches(q):
                hit = True
                break
        q[j] = end
        self._qpos[:] = q  # the data's configuration is the end's again (kinematics are refreshed by the next move)
        return hit

    def tip(self) -> tuple[float, float, float]:
        """The tool point (x, y, z) at the current configuration, as the kinematics of the move
        (or placement) that reached it computed it: no MuJoCo call. The same numbers as
        :meth:`tool_point` (MuJoCo's kinematics are deterministic)."""
        return self._tip

    def tool_point(self) -> np.ndarray:
        """The tool point at the current configuration (MuJoCo's kinematics, run now)."""
        mujoco.mj_kinematics(self.model, self.data)
        return self._site_xpos[self._tip_id].copy()
