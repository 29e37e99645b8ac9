"""A spatial arm whose state is its joint configuration, over the 3D workspace (``worlds.voxels``).

The continuous counterpart of a spatial arm's ``joint`` robot (``ik.voxels``): the same three
moved joints (the origin's best-conditioned, ``ik.voxels.moved_joints``), the others held at
the same origin (``ik.voxels.spatial_origin``), the same step (``ik.voxels.choose_step``
unless given), but no lattice laid out. Action ``2i`` turns moved joint i by +delta, ``2i+1``
by -delta (``q1+`` ... as the joint robot names them). A move is blocked, and the arm stays,
when it leaves the joint box (an unlimited joint: pi either side of the origin), when the tool
point at its end or at points of its arc at most half a cell of travel apart is outside the
workspace or in a solid voxel, when a geom the turn carries would touch the table or a wall
anywhere along it (``ik.swept``), or when MuJoCo reports a contact that
``ik.scene.ContactChecker`` counts at its end. The arc and the sweep are computed from the state
the last move left (the geoms' frames, the moved joints' anchors and axes), before MuJoCo is
asked; MuJoCo then runs once, at the end. An arm that can touch itself, or a workspace not made
of axis-aligned boxes, is checked by MuJoCo at the tool points instead
(``ik.voxels._move_clear``, the joint robot's own test). ``ik.fastmove3d`` compiles the move.

``q`` is the moved joints' angles (the held joints are not the learner's: they never change);
the label is the voxel of the tool point (``ik.voxels.voxel_of_point``), so a task's cells are
their level-0 voxels and a 2D source's path is paid where the tool is within one cell size of
the table. Without noise the configuration is kept as origin + n * delta with integer n: the
points and moves are those of the joint robot's lattice, bit for bit (a test walks both).

**Actuation noise** (``noise=sigma``), as ``ik.continuous``'s: a move turns its joint by
delta * (1 + eps), eps ~ Normal(0, sigma^2) clipped to [-NOISE_CLIP, NOISE_CLIP], drawn from
the arm's own generator (:meth:`SpatialContinuousArm.seed_noise`), one draw per move, blocked
ones too; the configuration leaves the lattice and :meth:`key` is q itself. The start is the
lattice point over the start cell with and without noise; inside :meth:`noiseless` (the greedy
roll-out) the moves are the lattice's.
"""

from __future__ import annotations

import itertools
import math
from typing import Any

import mujoco
import numpy as np

from armtransfer.errors import ArmModelError, InvalidCellError, UnreachableTableError
from armtransfer.ik import fastline, fastmove, fastmove3d, handles, swept
from armtransfer.ik.compile import joint_box
from armtransfer.ik.continuous import BLOCKED, MAX_NOISE, NoisyJointMoves
from armtransfer.ik.fastmove import PYTHON
from armtransfer.ik.scene import ArmScene, ContactChecker
from armtransfer.ik.voxels import (SpatialFK, _move_clear, choose_step, moved_joints, spatial_origin,
                                   voxel_of_point, workspace_voxels)

IK_ITERATIONS = 200
"""Damped least-squares iterations of :meth:`SpatialContinuousArm.place`'s IK on the moved joints."""
IK_RESTARTS = 8
"""Random starts (a fixed seed) tried after the one from the origin."""


class SpatialContinuousArm(NoisyJointMoves):
    """A spatial arm in its table scene, moved by turns of ``step`` radians of three of its joints.

    The interface of ``ik.continuous.ContinuousArm`` that the linear learner, the runs and the
    environments use: ``q``, ``label``, ``place``, ``reset``, ``move``, ``move_by``, ``key``,
    ``bounds``, ``box``, ``seed_noise``, ``noiseless``, ``tip``, ``tool_point``."""

    def __init__(self, scene: ArmScene, step: float | None = None, noise: float = 0.0) -> None:
        if scene.planar:
            raise ArmModelError("this arm is planar: its continuous arm is ik.continuous.ContinuousArm")
        model = scene.model
        if model.njnt != model.nq or np.any(model.jnt_type != mujoco.mjtJoint.mjJNT_HINGE):
            raise ArmModelError("the continuous arm needs an arm with hinge joints only")
        if step is not None and not (math.isfinite(step) and 0.0 < step <= math.pi):
            raise ArmModelError(f"the joint step must be in (0, pi] radians, got {step!r}")
        if isinstance(noise, bool) or not isinstance(noise, (int, float, np.floating, np.integer)) \
                or not (math.isfinite(noise) and 0.0 <= noise <= MAX_NOISE):
            raise ArmModelError(f"the actuation noise sigma must be a number in [0, {MAX_NOISE}], got {noise!r}")
        self.scene = scene
        self.layout = scene.layout
        self.cell = float(scene.cell)
        self.vox = workspace_voxels(self.layout, self.cell)
        self.levels = self.vox.levels
        """Labels are voxel ids of this many levels (``learning.cells`` pays by them)."""
        self.checker = ContactChecker(scene)
        self.model = scene.model
        self._fk = SpatialFK(scene)
        self.origin = spatial_origin(scene)
        jac = self._fk.jacobian(self.origin)
        self.moved = moved_joints(jac)
        self.step = float(step) if step is not None else choose_step(jac, self.moved, self.cell)
        self.dof = len(self.moved)
        """The joints the learner moves (the others are held at the origin)."""
        self.n_actions = 2 * self.dof
        self.action_names = tuple(f"q{j + 1}{s}" for j in self.moved for s in "+-")
        self.noise = float(noise)
        self._noisy = self.noise > 0.0
        self._rng = np.random.default_rng(0)
        self._eps: list[float] = []
        self._k = 0
        lo, hi = joint_box(scene, self.origin)
        idx = list(self.moved)
        self._lo, self._hi = lo[idx].astype(float), hi[idx].astype(float)
        self._q0 = self.origin[idx].astype(float)
        self._nlo = np.ceil((self._lo - self._q0) / self.step - 1e-9).astype(np.int64)
        self._nhi = np.floor((self._hi - self._q0) / self.step + 1e-9).astype(np.int64)
        self._full = self.origin.astype(float).copy()  # the whole configuration; only the moved joints change
        self._q = self._q0.copy()  # what ``q`` returns: updated in place (the learner keeps the array)
        self._n = np.zeros(self.dof, np.int64)
        self._off = False  # a box move left the lattice
        self._tip = np.full(3, np.nan)
        self.label = -1
        self._start: tuple | None = None
        self.moves = 0
        """Moves asked of :meth:`move` and :meth:`move_by` (blocked ones too)."""
        self._setup_sweep()

    def _setup_sweep(self) -> None:
        """The arrays of the swept check (``ik.swept``) and of the move's MuJoCo call."""
        model, checker = self.model, self.checker
        self.data = checker.data
        self._qpos = self.data.qpos
        self._site_xpos = self.data.site_xpos
        self._tip_id = int(mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, self.scene.tip))
        self._qidx = [int(j) for j in self.moved]
        by_adr = {int(model.jnt_qposadr[j]): j for j in range(model.njnt)}
        self._joints = np.array([by_adr[j] for j in self._qidx], np.int64)
        lay = self.vox.layout
        self._shape = (int(lay.lo), int(lay.hi), int(lay.width), int(lay.n_cells), int(self.vox.levels))
        self._vfree = np.ascontiguousarray(self.vox.free, dtype=np.bool_)
        arrays = swept.shapes(self.scene, checker, self._joints, self.origin)
        (self._geoms, self._sizes, self._kinds, self._offset, self._boxes, self._pairs, self._carried,
         aligned) = arrays
        geoms = self._geoms.tolist()
        self._reach, self._tip_reach = swept.reaches(model, self.origin, self._geoms, self._sizes, self._offset,
                                                     self._tip_id)
        self._sampled = bool(checker.can_self_collide or not aligned)
        """Self-contacts or a workspace not made of axis-aligned boxes: the moves are checked by
        MuJoCo at points of the move instead (``ik.voxels._move_clear``), in Python."""
        self._frames = np.zeros((len(geoms), 4, 3))
        self._anchors = np.zeros((self.dof, 3))
        self._axes = np.zeros((self.dof, 3))
        self._work = np.zeros(3)
        self._work2 = np.zeros((7, 3))
        self._stack = np.zeros((64, 4))
        self._fast: tuple | None | bool = False
        self._table: np.ndarray | None = None  # the compiled move's state by address (``ik.handles``)
        self._kernel: Any = None
        self._line_table: np.ndarray | None = None  # the compiled straight move's (``_line``)
        self._line_keep: list = []
        self._line_move: Any = None
        self._line_turn = np.zeros(0)

    # ------------------------------------------------------------------ configurations

    def _full_of(self, qm: np.ndarray) -> np.ndarray:
        full = self._full.copy()
        full[list(self.moved)] = qm
        return full

    def _voxel(self, full: np.ndarray) -> tuple[int, np.ndarray]:
        """(voxel, tip) of a whole configuration; voxel -1 when it touches, is outside or solid."""
        hit, tip = self.checker.touches_and_tip(full)
        v = voxel_of_point(tip, self.cell, self.vox)
        return (-1 if hit or v < 0 or not self.vox.free[v] else v), tip

    def _set(self, qm: np.ndarray, n: np.ndarray | None, tip: np.ndarray, label: int) -> None:
        self._q[:] = qm
        self._full[list(self.moved)] = qm
        if n is not None:
            self._n[:] = n
        self._tip[:] = tip
        self.label = label

    def set_configuration(self, q: np.ndarray) -> int:
        """Put the moved joints at ``q`` (a lattice point, origin + n * step, keeps the lattice;
        any other leaves it) as the start, and return its voxel. A configuration that touches
        something or whose tool point is not in a free voxel is refused."""
        qm = np.array(q, dtype=np.float64).reshape(-1)
        if qm.shape != (self.dof,) or not np.all(np.isfinite(qm)):
            raise ArmModelError(f"a configuration of this arm's moved joints is {self.dof} finite angles, got "
                                f"{np.asarray(q).tolist()}")
        if np.any(qm < self._lo - 1e-9) or np.any(qm > self._hi + 1e-9):
            raise ArmModelError("the configuration is outside the joint limits")
        v, tip = self._voxel(self._full_of(qm))
        if v < 0:
            raise InvalidCellError("the arm touches something or its tool point is not in a free voxel at this "
                                   "configuration")
        n = np.rint((qm - self._q0) / self.step).astype(np.int64)
        on = bool(np.array_equal(self._q0 + n * self.step, qm))
        self._off = not on
        self._set(qm, n if on else np.zeros(self.dof, np.int64), tip, v)
        self._capture()  # the kinematics ``_voxel`` ran at this configuration
        self._start = (qm.copy(), v, tip.copy(), (self._frames.copy(), self._anchors.copy(), self._axes.copy()))
        return v

    def reset(self) -> int:
        """Back to the configuration last set (:meth:`set_configuration`, :meth:`place`); its voxel."""
        if self._start is None:
            raise ArmModelError("place the arm (place or set_configuration) before resetting it")
        qm, v, tip, (frames, anchors, axes) = self._start
        n = np.rint((qm - self._q0) / self.step).astype(np.int64)
        self._off = not bool(np.array_equal(self._q0 + n * self.step, qm))
        self._set(qm, n, tip.copy(), v)
        self._qpos[:] = self._full
        self._frames[:], self._anchors[:], self._axes[:] = frames, anchors, axes
        return v

    @property
    def q(self) -> np.ndarray:
        """The moved joints' angles (read it, never write it)."""
        return self._q

    @property
    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """(lowest, highest) moved-joint configuration the moves can reach: the lattice's extent
        in the joint box (with noise: the box itself)."""
        if self._noisy:
            return self._lo.copy(), self._hi.copy()
        return self._q0 + self._nlo * self.step, self._q0 + self._nhi * self.step

    @property
    def box(self) -> tuple[np.ndarray, np.ndarray]:
        """(lowest, highest) moved-joint configuration any move may reach: the joint box."""
        return self._lo.copy(), self._hi.copy()

    def key(self) -> tuple:
        """Lattice steps from the origin (with noise or off the lattice: the angles themselves)."""
        if self._noisy or self._off:
            return tuple(self._q.tolist())
        return tuple(self._n.tolist())

    def place(self, cell: int) -> np.ndarray:
        """The lattice point (origin + n * step) with the tool point in ``cell``'s level-0
        voxel, nearest its centre and touching nothing, set as the start; returns its moved
        joints. Damped least squares on the moved joints (from the origin, then from
        ``IK_RESTARTS`` random starts of a fixed seed) gives a configuration with the tool at
        the cell, at the origin's height; the lattice points around it (each joint rounded,
        then one step either way) are tried."""
        cell = int(cell)
        x, y = self.layout.xy(cell)
        target = np.array([x * self.cell, y * self.cell, float(self._fk.tip(self.origin)[2])])
        centre = np.array([x * self.cell, y * self.cell, 0.5 * self.cell])
        rng = np.random.default_rng(0)
        starts = [self._q0] + [rng.uniform(np.maximum(self._lo, self._q0 - 1.5), np.minimum(self._hi, self._q0 + 1.5))
                               for _ in range(IK_RESTARTS)]
        for start in starts:
            qm = self._ik(target, start)
            if qm is None:
                continue
            base = np.rint((qm - self._q0) / self.step)
            best, best_d = None, np.inf
            for off in itertools.product((0, -1, 1), repeat=self.dof):
                cand = self._q0 + (base + np.array(off)) * self.step
                if np.any(cand < self._lo - 1e-9) or np.any(cand > self._hi + 1e-9):
                    continue
                v, tip = self._voxel(self._full_of(cand))
                if v != cell:
                    continue
                d = float(np.linalg.norm(tip - centre))
                if d < best_d:
                    best, best_d = cand, d
            if best is not None:
                self.set_configuration(best)
                return self._q.copy()
        raise UnreachableTableError(f"the arm cannot place its tool point in cell {(x, y)} at the table level with "
                                    "its moved joints without touching anything")

    def _ik(self, target: np.ndarray, start: np.ndarray) -> np.ndarray | None:
        idx = list(self.moved)
        qm = start.copy()
        for _ in range(IK_ITERATIONS):
            full = self._full_of(qm)
            err = target - self._fk.tip(full)
            if float(np.linalg.norm(err)) < 0.05 * self.cell:
                return qm
            J = self._fk.jacobian(full)[:, idx]
            dq = J.T @ np.linalg.solve(J @ J.T + (0.01 ** 2) * np.eye(3), err)
            qm = np.clip(qm + np.clip(dq, -0.2, 0.2), self._lo, self._hi)
        return None

    # ------------------------------------------------------------------ moving

    def move(self, a: int) -> int:
        """Take action ``a`` (0 .. 2 * dof - 1): the voxel of the tool point after the move, or
        ``BLOCKED`` (the arm has not moved)."""
        i, sign = a >> 1, 1 - 2 * (a & 1)
        self.moves += 1
        n = None
        old = float(self._q[i])
        if self._noisy:
            new = old + sign * self.step * (1.0 + self._next_eps())
        elif self._off:
            new = old + sign * self.step
        else:
            n = int(self._n[i]) + sign
            if n < self._nlo[i] or n > self._nhi[i]:
                return BLOCKED
            new = float(self._q0[i] + n * self.step)
        if new < self._lo[i] or new > self._hi[i]:
            return BLOCKED
        if self._sampled:
            qm = self._q.copy()
            qm[i] = new
            nn = None
            if n is not None:
                nn = self._n.copy()
                nn[i] = n
            return self._go(qm, nn)
        return self._turn(i, old, new, n)

    def _turn(self, i: int, old: float, new: float, n: int | None) -> int:
        """Moved joint i from ``old`` to ``new``: the tool point's arc through free voxels, the
        swept check (``ik.swept``), both on the state the last move left; then MuJoCo at the end."""
        theta = new - old
        c, ax = self._anchors[i], self._axes[i]
        sh = self._shape
        if swept.tip_arc(self._tip, c, ax, theta, self.cell, sh[0], sh[1], sh[2], sh[3], sh[4], self._vfree,
                         self._work) < 0:
            return BLOCKED
        if not swept.rotation_clear(self._frames, self._sizes, self._kinds, self._carried[i], c, ax, theta,
                                    self._boxes, self._pairs, self._stack, self._work2):
            return BLOCKED
        m, d = self.model, self.data
        qpos = self._qpos
        j = self._qidx[i]
        qpos[j] = new
        mujoco.mj_kinematics(m, d)
        mujoco.mj_collision(m, d)
        if d.ncon and self.checker.touches_now():
            qpos[j] = old
            return BLOCKED
        tip = self._site_xpos[self._tip_id]
        v = swept.voxel(tip, self.cell, sh[0], sh[1], sh[2], sh[3], sh[4])
        if v < 0 or not self._vfree[v]:
            qpos[j] = old
            return BLOCKED
        self._q[i] = new
        self._full[j] = new
        if n is not None:
            self._n[i] = n
        self._tip[:] = tip
        self.label = v
        self._capture()
        return v

    def _capture(self) -> None:
        """The swept check's state at the configuration whose kinematics MuJoCo last ran on data."""
        d = self.data
        swept.capture(d.geom_xpos, d.geom_xmat, self._geoms, self._offset, d.xanchor, d.xaxis, self._joints,
                      self._frames, self._anchors, self._axes)

    def _move_by(self, turn: np.ndarray) -> int:
        """:meth:`move_by` of a checked turn (noise applied): by ``ik.fastline.line_move`` when
        the arm has it (the same rule as :meth:`_go`, compiled)."""
        self.moves += 1
        line = self._line_table if self._line_table is not None else self._line()
        if line is not None:
            whole = self._line_turn
            for i, j in enumerate(self._qidx):
                whole[j] = turn[i]
            v = self._line_move(line, whole)
            if v != PYTHON:
                if v >= 0:
                    self._full[:] = self._qpos
                    self.label = v
                    self._off = True
                return v
        qm = self._q + turn
        if np.any(qm < self._lo) or np.any(qm > self._hi):
            return BLOCKED
        label = self._go(qm, None)
        if label >= 0:
            self._off = True
        return label

    def _line(self) -> np.ndarray | None:
        """The table ``ik.fastline.line_move`` reads, or None (moves checked by sampling, or no
        compiled move)."""
        if self._line_table is not None or self._sampled or self._start is None:
            return self._line_table
        if self._fast is False:
            self._fast = self._build_fast()
        if not isinstance(self._fast, tuple):
            return None
        model, d, n_g = self.model, self.data, len(self._geoms)
        lo = np.full(model.nq, -np.inf)
        hi = np.full(model.nq, np.inf)
        lo[self._qidx], hi[self._qidx] = self._lo, self._hi
        self._line_turn = np.zeros(model.nq)
        tip_carried, ordered = swept.chain_tables(model, self._joints, self._tip_id)
        if not ordered:
            return None
        dof = self.dof
        items = list(self._fast[0]) + [
            self._qpos, self._site_xpos, d.geom_xpos, d.geom_xmat, d.xanchor, d.xaxis, self._tip_id, self.levels,
            self.cell, np.array(self._shape[:4], np.int64), self._vfree, np.zeros(1, np.int64), False, lo, hi,
            self._tip_reach, self._reach, self._geoms, self._offset, self._sizes, self._kinds, self._boxes,
            self._pairs, self._frames, True, self._joints, self._anchors, self._axes, self._q, self._tip,
            np.zeros(1, np.int64), np.zeros(model.nq), np.zeros((n_g, 4, 3)), np.zeros((fastline.MAX_POINTS, n_g)),
            np.zeros(n_g), np.zeros((7, 3)), np.zeros((64, 4)), False, np.zeros((n_g, len(self._boxes)), np.bool_),
            np.array(self._qidx, np.int64), self._joints, self._carried, tip_carried, np.zeros((dof, 3)),
            np.zeros((dof, 3)), np.zeros((n_g, 4, 3)), np.zeros(3), np.zeros(dof), np.zeros(dof), np.zeros(3), np.zeros(n_g, np.bool_)]
        self._line_keep = items
        self._line_move = fastline.line_move
        self._line_table = handles.table(fastline.LINE, items)
        return self._line_table

    def _go(self, qm: np.ndarray, n: np.ndarray | None) -> int:
        """The straight joint move to ``qm``: MuJoCo at its end, the tool point at points at most
        half a cell apart in free voxels, and the swept check along the line (``_line_clear``)."""
        old = self._full.copy()
        new = self._full_of(qm)
        v, tip = self._voxel(new)
        if v < 0:
            self.data.qpos[:] = old
            return BLOCKED
        ok = self._line_clear(old, new, tip)
        if ok:
            ok = _move_clear(self.checker, self._fk, old, new, self._tip, tip, self.cell, self.vox) \
                if self._sampled else self._tip_line_clear(old, new, tip)
        self.data.qpos[:] = new if ok else old
        mujoco.mj_kinematics(self.model, self.data)
        if not ok:
            return BLOCKED
        if n is None and not self._noisy and not self._off:
            self._off = True
        self._set(qm, n, tip, v)
        self._capture()
        return v

    def _tip_line_clear(self, qa: np.ndarray, qb: np.ndarray, pb: np.ndarray) -> bool:
        """The tool point at points of the straight move at most half a cell of its travel apart
        (``ik.voxels._move_clear``'s points) in free voxels (kinematics only)."""
        m = max(1, int(math.ceil(2.0 * float(np.linalg.norm(pb - self._tip)) / self.cell)))
        for t in np.arange(1, m + 1) / (m + 1):
            tip = self._fk.tip(qa + (qb - qa) * t)
            v = voxel_of_point(tip, self.cell, self.vox)
            if v < 0 or not self.vox.free[v]:
                return False
        return True

    def _line_clear(self, qa: np.ndarray, qb: np.ndarray, pb: np.ndarray) -> bool:
        """The swept check of a straight joint move qa -> qb (several joints at once): D_g(t), the
        least clearance of geom g to the boxes (``swept``), is Lipschitz in t with constant
        sum_j |qb_j - qa_j| * reach[j, g] (``reach``: a bound on the distance of g's core from
        joint j's axis in any configuration); intervals are split as in ``ik.swept``, the cores at
        a point from MuJoCo's kinematics there."""
        if not len(self._geoms):
            return True
        rate = np.abs(qb - qa) @ self._reach  # per geom: metres per unit t
        d0 = self._clearances(qa)
        d1 = self._clearances(qb)
        todo = [(0.0, 1.0, d0, d1)]
        evals = 2
        while todo:
            t0, t1, da, db = todo.pop()
            bad = (da + db <= (t1 - t0) * rate)
            if not bad.any():
                continue
            if float(((t1 - t0) * rate)[bad].max()) < swept.RESOLUTION or evals >= swept.MAX_EVALS:
                return False
            tm = 0.5 * (t0 + t1)
            dm = self._clearances(qa + (qb - qa) * tm)
            evals += 1
            if np.any(dm <= 0.0):
                return False
            todo += [(tm, t1, dm, db), (t0, tm, da, dm)]
        return bool(np.all(d0 > 0.0) and np.all(d1 > 0.0))

    def _clearances(self, full: np.ndarray) -> np.ndarray:
        """Per swept geom, its least D to the boxes at the whole configuration ``full``."""
        d = self._fk.data
        d.qpos[:] = full
        mujoco.mj_kinematics(self.model, d)
        frames = np.empty_like(self._frames)
        swept.capture(d.geom_xpos, d.geom_xmat, self._geoms, self._offset, d.xanchor, d.xaxis, self._joints,
                      frames, np.empty_like(self._anchors), np.empty_like(self._axes))
        out = np.empty(len(self._geoms))
        swept.clearances(frames, self._sizes, self._kinds, self._boxes, self._pairs, self._work2,
                         np.full(len(self._geoms), np.inf), np.ones(len(self._geoms), np.bool_), out)
        return out

    # ------------------------------------------------------------------ the compiled move

    def fast(self) -> tuple | None:
        """The arm's arrays for ``ik.fastmove3d.move`` (the compiled :meth:`move`), or None when
        there is none (actuation noise, off the lattice, moves checked by sampling, or MuJoCo's
        memory not as ``ik.fastmove.layout`` expects). Call :meth:`fast_done` after moving with it."""
        if self._noisy or self._off or self._sampled or self._start is None:
            return None
        if self._fast is False:
            self._fast = self._build_fast()
        if not isinstance(self._fast, tuple):
            return None
        state = self._fast
        state[-2][0] = self.label
        state[-1][0] = self.moves
        return state

    def fast_step(self, a: int) -> int:
        """:meth:`move` by the compiled move (``ik.handles.spatial_move``; the same result), when
        the arm has one."""
        if self._table is None:
            state = self.fast()
            if state is None:
                return self.move(a)
            self._table = handles.of_state(fastmove3d.SPATIAL, state)
            self._kernel = fastmove3d.spatial_move
        elif self._noisy or self._off:
            return self.move(a)
        v = self._kernel(a, self._table)  # the arrays it reads are the arm's own
        if v == PYTHON:
            return self.move(a)
        self.moves += 1
        if v >= 0:
            j = self._qidx[a >> 1]
            self._full[j] = self._qpos[j]
            self.label = v
        return v

    def fast_done(self) -> None:
        """Take back the arm's state from the compiled move's arrays."""
        state = self._fast
        assert isinstance(state, tuple)
        self.label = int(state[-2][0])
        self.moves = int(state[-1][0])
        self._full[self._qidx] = self._q

    def _build_fast(self) -> tuple | None:
        c = self.checker
        g = np.arange(self.model.ngeom)
        g1, g2 = (x.ravel() for x in np.meshgrid(g, g, indexing="ij"))
        counts = ((c._env[g1] & c._moving[g2]) | (c._env[g2] & c._moving[g1]) | c._own(g1, g2))
        full = np.tile(self._full, (400, 1))
        full[:, self._qidx] = np.random.default_rng(0).uniform(self._lo, self._hi, (400, self.dof))
        raw = fastmove.layout(self.model, self.data, counts.reshape(self.model.ngeom, self.model.ngeom), full)
        if raw is None:
            return None
        d = self.data
        return (raw, self._qpos, self._site_xpos, d.geom_xpos, d.geom_xmat, d.xanchor, d.xaxis, self._tip_id,
                np.array(self._qidx, np.int64), self._joints, self._q, self._q0, self._n, self._nlo, self._nhi,
                self.step, self._lo, self._hi, self.cell, np.array(self._shape, np.int64), self._vfree, self._tip,
                self._frames, self._sizes, self._kinds, self._carried, self._boxes, self._pairs, self._geoms,
                self._offset, self._anchors, self._axes, self._stack, self._work, self._work2,
                np.zeros(1, np.int64), np.zeros(1, np.int64))

    def tip(self) -> tuple[float, float, float]:
        """The tool point (x, y, z) the last move or placement computed: no MuJoCo call."""
        x, y, z = self._tip.tolist()
        return (x, y, z)

    def tool_point(self) -> np.ndarray:
        """The tool point at the current configuration (MuJoCo's kinematics, run now)."""
        return self._fk.tip(self._full)
