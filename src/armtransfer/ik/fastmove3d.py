"""The spatial continuous arm's move (``ik.continuous3d.SpatialContinuousArm.move``) compiled
with numba, so that a learner's whole episode runs without Python per step.

The same steps as the Python move, in the same order, with the same arithmetic: the joint's
new angle from the lattice, the tool point's arc through free voxels and the swept check of the
turn (``ik.swept``, the same compiled functions the Python move calls), then one
``mj_kinematics`` + ``mj_collision`` at the end, called by address on the bindings' own
``MjModel`` and ``MjData`` as ``ik.fastmove`` calls them (its :func:`ik.fastmove.layout` finds
and checks the raw views), and the voxel of the tool point MuJoCo computed. A move that meets a
contact it cannot read undoes itself and returns :data:`PYTHON`; the caller takes that move in
Python. So a move reaches MuJoCo only when the tool's arc and the swept check have let it, and
then once.
"""

from __future__ import annotations

import numba

from armtransfer.ik import handles, swept
from armtransfer.ik.fastmove import BLOCKED, PYTHON, _call, _touches_now


@numba.njit(cache=True, nogil=True)
def move(a, arm):
    """``SpatialContinuousArm.move(a)`` on the arm's arrays ``arm`` (``SpatialContinuousArm.fast``),
    without noise, on the lattice: the voxel reached, :data:`BLOCKED`, or :data:`PYTHON`."""
    (raw, qpos, site_xpos, geom_xpos, geom_xmat, xanchor, xaxis, tip_id, qidx, joints, q, q0, nn, nlo, nhi, step,
     lo, hi, cell, shape, vfree, tip, frames, sizes, kinds, carried, boxes, pairs, geoms, offset, anchors, axes,
     stack, work, work2, label, moves) = arm
    i = a >> 1
    sign = 1 - 2 * (a & 1)
    moves[0] += 1
    n = nn[i] + sign
    if n < nlo[i] or n > nhi[i]:
        return BLOCKED
    old = q[i]
    new = q0[i] + n * step
    if new < lo[i] or new > hi[i]:
        return BLOCKED
    theta = new - old
    c = anchors[i]
    ax = axes[i]
    if swept.tip_arc(tip, c, ax, theta, cell, shape[0], shape[1], shape[2], shape[3], shape[4], vfree, work) < 0:
        return BLOCKED
    if not swept.rotation_clear(frames, sizes, kinds, carried[i], c, ax, theta, boxes, pairs, stack, work2):
        return BLOCKED
    j = qidx[i]
    qpos[j] = new
    _call(raw[0], raw[2], raw[3])
    _call(raw[1], raw[2], raw[3])
    t = _touches_now(raw)
    if t != 0:
        qpos[j] = old
        if t < 0:
            moves[0] -= 1
            return PYTHON
        return BLOCKED
    v = swept.voxel(site_xpos[tip_id], cell, shape[0], shape[1], shape[2], shape[3], shape[4])
    if v < 0 or not vfree[v]:
        qpos[j] = old
        return BLOCKED
    q[i] = new
    nn[i] = n
    tip[0] = site_xpos[tip_id, 0]
    tip[1] = site_xpos[tip_id, 1]
    tip[2] = site_xpos[tip_id, 2]
    label[0] = v
    swept.capture(geom_xpos, geom_xmat, geoms, offset, xanchor, xaxis, joints, frames, anchors, axes)
    return v


SPATIAL = handles.RAW + (" f8:1 f8:2 f8:2 f8:2 f8:2 f8:2 int i8:1 i8:1 f8:1 f8:1 i8:1 i8:1 i8:1 float f8:1 f8:1 float i8:1"
                 " b:1 f8:1 f8:3 f8:2 i8:1 b:2 f8:2 b:2 i8:1 f8:2 f8:2 f8:2 f8:2 f8:1 f8:2 i8:1 i8:1")
"""What :func:`spatial_move` reads: ``SpatialContinuousArm.fast``'s tuple, ``raw`` spread out."""


@numba.njit(cache=True, nogil=True)
def spatial_move(a, t):
    """``ik.fastmove3d.move(a, arm)`` on the arm of the table ``t`` (:data:`SPATIAL`)."""
    k = 48
    arm = (handles._raw(t), handles._f1(t, k), handles._f2(t, k + 4), handles._f2(t, k + 8), handles._f2(t, k + 12), handles._f2(t, k + 16), handles._f2(t, k + 20),
           t[k + 24], handles._i1(t, k + 28), handles._i1(t, k + 32), handles._f1(t, k + 36), handles._f1(t, k + 40), handles._i1(t, k + 44),
           handles._i1(t, k + 48), handles._i1(t, k + 52), handles._float(t, k + 56), handles._f1(t, k + 60), handles._f1(t, k + 64), handles._float(t, k + 68),
           handles._i1(t, k + 72), handles._b1(t, k + 76), handles._f1(t, k + 80), handles._f3(t, k + 84), handles._f2(t, k + 88), handles._i1(t, k + 92),
           handles._b2(t, k + 96), handles._f2(t, k + 100), handles._b2(t, k + 104), handles._i1(t, k + 108), handles._f2(t, k + 112), handles._f2(t, k + 116),
           handles._f2(t, k + 120), handles._f2(t, k + 124), handles._f1(t, k + 128), handles._f2(t, k + 132), handles._i1(t, k + 136), handles._i1(t, k + 140))
    return move(a, arm)
