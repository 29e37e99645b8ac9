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
MuJoCo's kinematics there) and at the end, then at the middles of the intervals split; the shapes and the tool point
along the line come from the start's by the product of exponentials (each joint's turn about its
axis at the start, the deepest first), without MuJoCo, so all of this runs before MuJoCo is
asked, once, at the end;
an interval [t0, t1] is clear when D_g(t0) + D_g(t1) > (t1 - t0) * rate_g for every g, else it is
split at its middle (where only the geoms not yet cleared are computed) (kinematics there) until its largest travel is under ``swept.RESOLUTION``
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
                      " f8:2 i8:1 f8:2 b:2 f8:3 bool i8:1 f8:2 f8:2 f8:1 f8:1 i8:1 f8:1 f8:3 f8:2 f8:1 f8:2 f8:2"
                      " bool b:2 i8:1 i8:1 b:2 b:1 f8:2 f8:2 f8:3 f8:1 f8:1 f8:1 f8:1 b:1")
"""What :func:`line_move` reads (the arms' ``_line`` build it)."""


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


@numba.njit(cache=True, nogil=True, inline="always")
def _rot(p, c0, c1, c2, a, cs, sn):
    """Turn the point p (in place) by the angle of cosine cs and sine sn about the axis a through
    (c0, c1, c2)."""
    vx = p[0] - c0
    vy = p[1] - c1
    vz = p[2] - c2
    d = (a[0] * vx + a[1] * vy + a[2] * vz) * (1.0 - cs)
    p[0] = c0 + vx * cs + (a[1] * vz - a[2] * vy) * sn + a[0] * d
    p[1] = c1 + vy * cs + (a[2] * vx - a[0] * vz) * sn + a[1] * d
    p[2] = c2 + vz * cs + (a[0] * vy - a[1] * vx) * sn + a[2] * d


@numba.njit(cache=True, nogil=True)
def _pose(tt, turn, movers, a0, x0, carried, tip_carried, frames0, tip0, cs, sn, fr, tip_out, need):
    """The geoms' frames and the tool point at the fraction ``tt`` of the straight move, from the
    start's (``frames0``, ``tip0``, the movers' anchors ``a0`` and axes ``x0``): the product of
    exponentials, each mover's turn about its axis at the start, the deepest first."""
    m = movers.shape[0]
    for i in range(m):
        ang = tt * turn[movers[i]]
        cs[i] = math.cos(ang)
        sn[i] = math.sin(ang)
    for g in range(frames0.shape[0]):
        if not need[g]:
            continue
        for r in range(4):
            for d in range(3):
                fr[g, r, d] = frames0[g, r, d]
        for i in range(m - 1, -1, -1):
            if carried[i, g] and turn[movers[i]] != 0.0:
                _rot(fr[g, 0], a0[i, 0], a0[i, 1], a0[i, 2], x0[i], cs[i], sn[i])
                for r in range(1, 4):
                    _rot(fr[g, r], 0.0, 0.0, 0.0, x0[i], cs[i], sn[i])
    for d in range(3):
        tip_out[d] = tip0[d]
    for i in range(m - 1, -1, -1):
        if tip_carried[i] and turn[movers[i]] != 0.0:
            _rot(tip_out, a0[i, 0], a0[i, 1], a0[i, 2], x0[i], cs[i], sn[i])


@numba.njit(cache=True, nogil=True)
def _tip_at(tt, turn, movers, a0, x0, tip_carried, tip0, tip_out):
    """The tool point alone at the fraction ``tt`` of the move (as :func:`_pose`)."""
    for d in range(3):
        tip_out[d] = tip0[d]
    for i in range(movers.shape[0] - 1, -1, -1):
        if tip_carried[i] and turn[movers[i]] != 0.0:
            ang = tt * turn[movers[i]]
            _rot(tip_out, a0[i, 0], a0[i, 1], a0[i, 2], x0[i], math.cos(ang), math.sin(ang))


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
    q = handles._f1(t, k + 112)
    tip = handles._f1(t, k + 116)
    label = handles._i1(t, k + 120)
    old = handles._f1(t, k + 124)
    fr = handles._f3(t, k + 128)
    dstore = handles._f2(t, k + 132)
    rate = handles._f1(t, k + 136)
    work = handles._f2(t, k + 140)
    stack = handles._f2(t, k + 144)
    flat = t[k + 148] != 0
    act = handles._b2(t, k + 152)
    movers = handles._i1(t, k + 156)
    mover_jnt = handles._i1(t, k + 160)
    carried = handles._b2(t, k + 164)
    tip_carried = handles._b1(t, k + 168)
    a0 = handles._f2(t, k + 172)
    x0 = handles._f2(t, k + 176)
    fr0 = handles._f3(t, k + 180)
    tip0 = handles._f1(t, k + 184)
    cs = handles._f1(t, k + 188)
    sn = handles._f1(t, k + 192)
    ptip = handles._f1(t, k + 196)
    need = handles._b1(t, k + 200)

    nq = qpos.shape[0]
    n_g = geoms.shape[0]
    m = movers.shape[0]
    for j in range(nq):
        old[j] = qpos[j]
        v = qpos[j] + turn[j]
        if v < box_lo[j] or v > box_hi[j]:
            return BLOCKED
    # the start: the shapes, tool point and the movers' axes the arm's last move left, or MuJoCo's
    # kinematics there
    if stored:
        for g in range(n_g):
            for r in range(4):
                for d in range(3):
                    fr0[g, r, d] = frames[g, r, d]
        for d in range(3):
            tip0[d] = tip[d]
        for i in range(m):
            for d in range(3):
                a0[i, d] = anchors[i, d]
                x0[i, d] = axes[i, d]
    else:
        _call(raw[0], raw[2], raw[3])
        swept.capture(geom_xpos, geom_xmat, geoms, offset, xanchor, xaxis, mover_jnt, fr0, a0, x0)
        for d in range(3):
            tip0[d] = site_xpos[tip_id, d]
    sweep = 0.0
    for j in range(nq):
        sweep += abs(turn[j]) * tip_reach[j]
    for g in range(n_g):
        r = 0.0
        for j in range(nq):
            r += abs(turn[j]) * reach[j, g]
        rate[g] = r
    # the end, predicted: the tool point over a free cell or in a free voxel
    for g in range(n_g):
        need[g] = True
    _pose(1.0, turn, movers, a0, x0, carried, tip_carried, fr0, tip0, cs, sn, fr, ptip, need)
    end = _label(ptip, levels, cell, grid, free)
    if end < 0:
        return BLOCKED
    # a planar arm's geoms keep their heights: a box apart from a geom in height stays apart
    for g in range(n_g):
        for o in range(boxes.shape[0]):
            act[g, o] = pairs[g, o] and (not flat or swept.axis_gap(fr0[g], sizes[g], kinds[g], boxes[o], 2) <= 0.0)
    swept.clearances(fr, sizes, kinds, boxes, act, work, rate, need, dstore[1])
    swept.clearances(fr0, sizes, kinds, boxes, act, work, rate, need, dstore[0])
    for g in range(n_g):
        if dstore[0, g] <= 0.0 or dstore[1, g] <= 0.0:
            return BLOCKED
    n = max(1, int(math.ceil(2.0 * sweep / cell)))
    if levels == 0 and clear[end] >= int(math.ceil(sweep / cell)) + 3 and not always_probe:
        n = 0
    for kk in range(1, n + 1):  # the tool points
        _tip_at(kk / (n + 1), turn, movers, a0, x0, tip_carried, tip0, ptip)
        if _label(ptip, levels, cell, grid, free) < 0:
            return BLOCKED
    # the swept check: [0, 1] cleared, or split
    pts = 2
    stack[0, 0], stack[0, 1], stack[0, 2], stack[0, 3] = 0.0, 1.0, 0, 1
    depth = 1
    while depth > 0:
        depth -= 1
        t0, t1 = stack[depth, 0], stack[depth, 1]
        ia, ib = int(stack[depth, 2]), int(stack[depth, 3])
        worst = 0.0
        for g in range(n_g):
            span = (t1 - t0) * rate[g]
            need[g] = dstore[ia, g] + dstore[ib, g] <= span
            if need[g] and span > worst:
                worst = span
        if worst == 0.0:
            continue
        if worst < swept.RESOLUTION or pts >= MAX_POINTS or depth + 2 > stack.shape[0]:
            return BLOCKED
        tm = 0.5 * (t0 + t1)
        im = pts
        pts += 1
        # a geom cleared over [t0, t1] is cleared over both halves: inf at the middle
        _pose(tm, turn, movers, a0, x0, carried, tip_carried, fr0, tip0, cs, sn, fr, ptip, need)
        swept.clearances(fr, sizes, kinds, boxes, act, work, rate, need, dstore[im])
        for g in range(n_g):
            if dstore[im, g] <= 0.0:
                return BLOCKED
        stack[depth, 0], stack[depth, 1], stack[depth, 2], stack[depth, 3] = tm, t1, im, ib
        stack[depth + 1, 0], stack[depth + 1, 1], stack[depth + 1, 2], stack[depth + 1, 3] = t0, tm, ia, im
        depth += 2
    # MuJoCo at the end: no contact, and the tool point it computes over a free cell or voxel
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
    if stored:  # the end's state for the next move (the kinematics just run)
        swept.capture(geom_xpos, geom_xmat, geoms, offset, xanchor, xaxis, joints, frames, anchors, axes)
        for i in range(m):
            q[i] = qpos[movers[i]]
    if always_probe and n > 0:  # an arm that can touch itself: MuJoCo at up to 3 tool points
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
        for j in range(nq):
            qpos[j] = old[j] + turn[j]
    tip[0] = ex
    tip[1] = ey
    tip[2] = ez
    label[0] = end
    return end
