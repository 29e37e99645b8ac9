"""A continuous arm's straight joint move (``move_by``, the ``Box`` environment's step), compiled.

Every joint turns at once, along the straight line from q to q + turn in joint space. The move
is blocked (the arm stays) when it leaves the joint box, when MuJoCo reports a contact at its end
(``mj_kinematics`` + ``mj_collision``, by address as in ``ik.fastmove``), when the tool point at
its end is not over a free cell (a planar arm) or in a free voxel (a spatial arm), when the tool
point at any of n points of the line (the fractions k / (n + 1); n = ceil(2 * sweep / cell),
sweep = sum_j |turn_j| * tip_reach_j, so at most half a cell of tool travel apart) is not, or
when the swept check fails. A planar arm's move that ends this many cells from every wall
(``ik.continuous.clearance_cells`` >= ceil(sweep / cell) + 3) skips the tool points, as the
planar move does.

The swept check along a line: D_g(t), geom g's least lower-bound distance to the table and wall
boxes (``ik.swept``), is Lipschitz in t with constant rate_g = sum_j |turn_j| * reach[j, g]
(``reach``: a bound on the distance of g's shape from joint j's axis in any configuration; a
planar arm's geoms keep their heights, so a box apart from a geom in height is left out). D is
computed at the start (a spatial arm: from the frames its last move left; a planar arm: from
MuJoCo's kinematics there), at each tool point and at the end, from the kinematics run there;
an interval [t0, t1] is clear when D_g(t0) + D_g(t1) > (t1 - t0) * rate_g for every g, else it is
split at its middle (kinematics there) until its largest travel is under ``swept.RESOLUTION``
(then the move is blocked), as ``ik.swept`` does for a turn. An arm that can touch itself is also
asked for contacts at up to 3 of the tool points.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from armtransfer.ik import handles, swept
from armtransfer.ik.fastmove import BLOCKED, PYTHON, _call, _touches, _touches_now

MAX_POINTS = 128
"""The most configurations of one move whose clearances are kept (more: the move is blocked)."""

LINE = handles.RAW + (" f8:1 f8:2 f8:2 f8:2 f8:2 f8:2 int int float i8:1 b:1 i8:1 bool f8:1 f8:1 f8:1 f8:2 i8:1 f8:2"
                      " f8:2 i8:1 f8:2 b:2 f8:3 bool i8:1 f8:2 f8:2 i8:1 f8:1 f8:1 i8:1 f8:1 f8:3 f8:2 f8:1"
                      " f8:2 f8:2 f8:3 f8:2 bool b:2")
"""What :func:`line_move` reads (see ``tables``)."""


@numba.njit(cache=True, nogil=True)
def _label(p, levels, cell, grid, free):
    """The cell (planar: ``levels`` 0) or voxel of the point p, -1 when not free or outside."""
    if levels == 0:
        cx = int(np.rint(p[0] / cell)) - grid[0]
        cy = int(np.rint(p[1] / cell)) - grid[0]
        if cx < 0 or cy < 0 or cx >= grid[2] or cy >= grid[2]:
            return -1
        c = cy * grid[2] + cx
    else:
        c = swept.voxel(p, cell, grid[0], grid[1], grid[2], grid[3], levels)
    if c < 0 or not free[c]:
        return -1
    return c


@numba.njit(cache=True, nogil=True)
def _clear_at(geom_xpos, geom_xmat, geoms, offset, sizes, kinds, boxes, pairs, frames, work, cap, out):
    """``out[g]``: geom g's least D to the boxes at the configuration whose kinematics just ran."""
    dummy = np.zeros((0, 3))
    swept.capture(geom_xpos, geom_xmat, geoms, offset, dummy, dummy, np.zeros(0, np.int64), frames, dummy, dummy)
    swept.clearances(frames, sizes, kinds, boxes, pairs, work, cap, out)


@numba.njit(cache=True, nogil=True)
def line_move(t, turn):
    """The straight joint move by ``turn`` (the whole configuration's) of the arm of table ``t``
    (:data:`LINE`): its label, :data:`BLOCKED` or :data:`PYTHON` (nothing changed)."""
    raw = handles._raw(t)
    k = 48
    qpos = handles._f1(t, k)
    site_xpos = handles._f2(t, k + 4)
    geom_xpos = handles._f2(t, k + 8)
    geom_xmat = handles._f2(t, k + 12)
    xanchor = handles._f2(t, k + 16)
    xaxis = handles._f2(t, k + 20)
    tip_id = t[k + 24]
    levels = t[k + 28]
    cell = handles._float(t, k + 32)
    grid = handles._i1(t, k + 36)
    free = handles._b1(t, k + 40)
    clear = handles._i1(t, k + 44)
    always_probe = t[k + 48] != 0
    box_lo = handles._f1(t, k + 52)
    box_hi = handles._f1(t, k + 56)
    tip_reach = handles._f1(t, k + 60)
    reach = handles._f2(t, k + 64)
    geoms = handles._i1(t, k + 68)
    offset = handles._f2(t, k + 72)
    sizes = handles._f2(t, k + 76)
    kinds = handles._i1(t, k + 80)
    boxes = handles._f2(t, k + 84)
    pairs = handles._b2(t, k + 88)
    frames = handles._f3(t, k + 92)
    stored = t[k + 96] != 0
    joints = handles._i1(t, k + 100)
    anchors = handles._f2(t, k + 104)
    axes = handles._f2(t, k + 108)
    qidx = handles._i1(t, k + 112)
    q = handles._f1(t, k + 116)
    tip = handles._f1(t, k + 120)
    label = handles._i1(t, k + 124)
    old = handles._f1(t, k + 128)
    fr = handles._f3(t, k + 132)
    dstore = handles._f2(t, k + 136)
    rate = handles._f1(t, k + 140)
    work = handles._f2(t, k + 144)
    stack = handles._f2(t, k + 148)
    fr_end = handles._f3(t, k + 152)
    end_axes = handles._f2(t, k + 156)
    flat = t[k + 160] != 0
    act = handles._b2(t, k + 164)
    dof = joints.shape[0]

    nq = qpos.shape[0]
    n_g = geoms.shape[0]
    for j in range(nq):
        old[j] = qpos[j]
        v = qpos[j] + turn[j]
        if v < box_lo[j] or v > box_hi[j]:
            return BLOCKED
    for g in range(n_g):
        r = 0.0
        for j in range(nq):
            r += abs(turn[j]) * reach[j, g]
        rate[g] = r
    if stored:  # the start's clearances, from the shapes the arm's last move left
        swept.clearances(frames, sizes, kinds, boxes, pairs, work, rate, dstore[0])
    for j in range(nq):
        qpos[j] = old[j] + turn[j]
    _call(raw[0], raw[2], raw[3])
    _call(raw[1], raw[2], raw[3])
    hit = _touches_now(raw)
    if hit != 0:
        qpos[:] = old
        return PYTHON if hit < 0 else BLOCKED
    end = _label(site_xpos[tip_id], levels, cell, grid, free)
    if end < 0:
        qpos[:] = old
        return BLOCKED
    ex = site_xpos[tip_id, 0]
    ey = site_xpos[tip_id, 1]
    ez = site_xpos[tip_id, 2]
    # the end's shapes (a spatial arm keeps them, with its joints' anchors and axes) and clearances
    swept.capture(geom_xpos, geom_xmat, geoms, offset, xanchor, xaxis, joints, fr_end, end_axes[0:dof],
                  end_axes[dof:2 * dof])
    # a planar arm's geoms keep their heights: a box apart from a geom in height stays apart
    for g in range(n_g):
        for o in range(boxes.shape[0]):
            act[g, o] = pairs[g, o] and (not flat or swept.axis_gap(fr_end[g], sizes[g], kinds[g], boxes[o], 2) <= 0.0)
    swept.clearances(fr_end, sizes, kinds, boxes, act, work, rate, dstore[1])
    sweep = 0.0
    for j in range(nq):
        sweep += abs(turn[j]) * tip_reach[j]
    n = max(1, int(math.ceil(2.0 * sweep / cell)))
    if levels == 0 and clear[end] >= int(math.ceil(sweep / cell)) + 3 and not always_probe:
        n = 0
    if not stored:  # the start's clearances, from MuJoCo's kinematics there
        qpos[:] = old
        _call(raw[0], raw[2], raw[3])
        _clear_at(geom_xpos, geom_xmat, geoms, offset, sizes, kinds, boxes, act, fr, work, rate, dstore[0])
    pts = 2
    ok = True
    for g in range(n_g):
        if dstore[0, g] <= 0.0 or dstore[1, g] <= 0.0:
            ok = False
    # the tool points, each a point of the swept check too
    prev_t = 0.0
    prev_i = 0
    kk = 1
    while ok and kk <= n + 1:
        if kk <= n:
            tk = kk / (n + 1)
            for j in range(nq):
                qpos[j] = old[j] + tk * turn[j]
            _call(raw[0], raw[2], raw[3])
            if _label(site_xpos[tip_id], levels, cell, grid, free) < 0:
                ok = False
                break
            if pts >= MAX_POINTS:
                ok = False
                break
            cur = pts
            pts += 1
            _clear_at(geom_xpos, geom_xmat, geoms, offset, sizes, kinds, boxes, act, fr, work, rate, dstore[cur])
            for g in range(n_g):
                if dstore[cur, g] <= 0.0:
                    ok = False
            if not ok:
                break
        else:
            tk = 1.0
            cur = 1
        # the interval [prev_t, tk]: cleared, or split
        stack[0, 0], stack[0, 1], stack[0, 2], stack[0, 3] = prev_t, tk, prev_i, cur
        depth = 1
        while ok and depth > 0:
            depth -= 1
            t0, t1 = stack[depth, 0], stack[depth, 1]
            ia, ib = int(stack[depth, 2]), int(stack[depth, 3])
            worst = 0.0
            for g in range(n_g):
                span = (t1 - t0) * rate[g]
                if dstore[ia, g] + dstore[ib, g] <= span and span > worst:
                    worst = span
            if worst == 0.0:
                continue
            if worst < swept.RESOLUTION or pts >= MAX_POINTS or depth + 2 > stack.shape[0]:
                ok = False
                break
            tm = 0.5 * (t0 + t1)
            for j in range(nq):
                qpos[j] = old[j] + tm * turn[j]
            _call(raw[0], raw[2], raw[3])
            im = pts
            pts += 1
            _clear_at(geom_xpos, geom_xmat, geoms, offset, sizes, kinds, boxes, act, fr, work, rate, dstore[im])
            for g in range(n_g):
                if dstore[im, g] <= 0.0:
                    ok = False
            stack[depth, 0], stack[depth, 1], stack[depth, 2], stack[depth, 3] = tm, t1, im, ib
            stack[depth + 1, 0], stack[depth + 1, 1], stack[depth + 1, 2], stack[depth + 1, 3] = t0, tm, ia, im
            depth += 2
        prev_t = tk
        prev_i = cur
        kk += 1
    if ok and always_probe and n > 0:
        probes = min(n, 3)
        q_try = old.copy()
        last = -1
        for p in range(probes):
            kp = int(np.rint(1.0 + p * (n - 1) / (probes - 1))) if probes > 1 else 1
            if kp == last:
                continue
            last = kp
            for j in range(nq):
                q_try[j] = old[j] + (kp / (n + 1)) * turn[j]
            h = _touches(raw, qpos, q_try)
            if h != 0:
                qpos[:] = old
                return PYTHON if h < 0 else BLOCKED
    if not ok:
        qpos[:] = old
        return BLOCKED
    for j in range(nq):
        qpos[j] = old[j] + turn[j]
    # the end's state
    tip[0] = ex
    tip[1] = ey
    tip[2] = ez
    label[0] = end
    if stored:
        frames[:] = fr_end
        anchors[:] = end_axes[0:dof]
        axes[:] = end_axes[dof:2 * dof]
        for i in range(qidx.shape[0]):
            q[i] = qpos[qidx[i]]
    return end
