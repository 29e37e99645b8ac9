"""The swept check of a spatial arm's joint rotation, in numba, without MuJoCo.

A move turns one joint by theta; every body the joint carries rotates rigidly about the joint's
axis. The move is clear when, anywhere along it, no geometry the arm moves penetrates a box of
the workspace (the table top and the walls: axis-aligned boxes, ``ik.scene``), and the tool point
stays in free voxels.

Each moving geom is bounded by a shape: a capsule by itself (a core segment and a radius; a
sphere: a segment of length 0), any other geom by the oriented box MuJoCo bounds it with
(``geom_aabb``, in the geom's frame; a cylinder's is tight on its flat end). D(t) is a lower
bound on the shape's distance to a box at the fraction t of the turn (a capsule: the core's
distance minus the radius; an oriented box: the largest gap along the 15 axes of the
separating-axis test), 0 or less when they may meet. The true distance is Lipschitz in t with
constant ``speed * |theta|``, ``speed`` the largest distance from the axis of a point of the
core (the segment or the box; the distance to a line is convex, so at a vertex); so
D(t0) - speed * |theta| * |t - t0| is a lower bound on it at t.
An interval [t0, t1] is clear when D(t0) + D(t1) > (t1 - t0) * speed * |theta| (D cannot reach
0 in between); an interval that is not is split in two at its middle, where D is computed
again; the move is blocked when D <= 0 at a point computed, or when an interval that is not
clear has a travel below :data:`RESOLUTION` (the geometry comes within RESOLUTION / 2 of the box).
So the resolution is the geometry's own: a geom far from every box is cleared by the distances
at the two ends, a geom that grazes a box is checked more finely the closer it comes.

Before the distances, two cheaper tests clear a geom and a box: the ball around the geom's
centre that holds its shape, grown by its travel, misses the box; or along one world axis the
shape's extent and the box's are apart by more than the shape's vertices can move along that
axis in the turn (a point turning about an axis moves along world axis k at most at the
amplitude of its k-th coordinate's oscillation: 0 along a vertical axis's own direction, so a
planar arm's turn never nears the table top).

The distance from a segment to a box is convex along the segment; it is found by golden-section
search and lowered by the search's remaining bracket times the segment's length (a lower bound).
"""

from __future__ import annotations

import math

import numba
import numpy as np

RESOLUTION = 1e-4
"""Metres of geometry travel: an interval of the turn not cleared at this travel blocks the move."""
MAX_EVALS = 256
"""The most distances computed for one geom and box in one move (more: the move is blocked)."""
GOLDEN = 30
"""Golden-section steps of the segment-to-box distance (the bracket left: 0.618**30, 5e-7, of the segment)."""
_STACK = 64


@numba.njit(cache=True, nogil=True)
def rotate(p, c, a, angle, out):
    """``out`` = the point ``p`` turned by ``angle`` about the axis ``a`` (a unit vector) through ``c``."""
    vx = p[0] - c[0]
    vy = p[1] - c[1]
    vz = p[2] - c[2]
    cs = math.cos(angle)
    sn = math.sin(angle)
    d = (a[0] * vx + a[1] * vy + a[2] * vz) * (1.0 - cs)
    out[0] = c[0] + vx * cs + (a[1] * vz - a[2] * vy) * sn + a[0] * d
    out[1] = c[1] + vy * cs + (a[2] * vx - a[0] * vz) * sn + a[1] * d
    out[2] = c[2] + vz * cs + (a[0] * vy - a[1] * vx) * sn + a[2] * d


@numba.njit(cache=True, nogil=True)
def voxel(p, cell, lo, hi, width, n_cells, levels):
    """``ik.voxels.voxel_of_point``: the voxel id of the point, -1 outside the workspace."""
    x = int(np.rint(p[0] / cell))
    y = int(np.rint(p[1] / cell))
    k = int(math.floor(p[2] / cell))
    if x < lo or x > hi or y < lo or y > hi or k < 0 or k >= levels:
        return -1
    return k * n_cells + (y - lo) * width + (x - lo)


@numba.njit(cache=True, nogil=True)
def tip_arc(tip, c, a, theta, cell, lo, hi, width, n_cells, levels, free, work):
    """The voxel of the tool point turned by ``theta`` (the end of the move, predicted), or -1
    when it or any of the points of the arc before it (the fractions k / (m + 1) of the turn,
    m = ceil(2 * chord / cell): at most half a cell apart) is outside the workspace or solid."""
    rotate(tip, c, a, theta, work)
    v = voxel(work, cell, lo, hi, width, n_cells, levels)
    if v < 0 or not free[v]:
        return -1
    dx = work[0] - tip[0]
    dy = work[1] - tip[1]
    dz = work[2] - tip[2]
    m = max(1, int(math.ceil(2.0 * math.sqrt(dx * dx + dy * dy + dz * dz) / cell)))
    for k in range(1, m + 1):
        rotate(tip, c, a, theta * (k / (m + 1)), work)
        u = voxel(work, cell, lo, hi, width, n_cells, levels)
        if u < 0 or not free[u]:
            return -1
    return v


@numba.njit(cache=True, nogil=True)
def _point_box(x, y, z, b):
    """The distance from (x, y, z) to the box ``b`` (centre b[0:3], half sizes b[3:6]); 0 inside."""
    dx = abs(x - b[0]) - b[3]
    dy = abs(y - b[1]) - b[4]
    dz = abs(z - b[2]) - b[5]
    dx = dx if dx > 0.0 else 0.0
    dy = dy if dy > 0.0 else 0.0
    dz = dz if dz > 0.0 else 0.0
    return math.sqrt(dx * dx + dy * dy + dz * dz)


@numba.njit(cache=True, nogil=True)
def segment_box(p, q, b):
    """A lower bound on the distance from the segment p-q to the box ``b`` (0: they may meet)."""
    ux = q[0] - p[0]
    uy = q[1] - p[1]
    uz = q[2] - p[2]
    length = math.sqrt(ux * ux + uy * uy + uz * uz)
    if length == 0.0:
        return _point_box(p[0], p[1], p[2], b)
    r = 0.6180339887498949
    lo, hi = 0.0, 1.0
    t1 = hi - r * (hi - lo)
    t2 = lo + r * (hi - lo)
    f1 = _point_box(p[0] + t1 * ux, p[1] + t1 * uy, p[2] + t1 * uz, b)
    f2 = _point_box(p[0] + t2 * ux, p[1] + t2 * uy, p[2] + t2 * uz, b)
    for _ in range(GOLDEN):
        if f1 == 0.0 or f2 == 0.0:
            return 0.0
        if f1 < f2:
            hi = t2
            t2, f2 = t1, f1
            t1 = hi - r * (hi - lo)
            f1 = _point_box(p[0] + t1 * ux, p[1] + t1 * uy, p[2] + t1 * uz, b)
        else:
            lo = t1
            t1, f1 = t2, f2
            t2 = lo + r * (hi - lo)
            f2 = _point_box(p[0] + t2 * ux, p[1] + t2 * uy, p[2] + t2 * uz, b)
    best = min(f1, f2, _point_box(p[0], p[1], p[2], b), _point_box(q[0], q[1], q[2], b))
    return max(0.0, best - (hi - lo) * length)


@numba.njit(cache=True, nogil=True)
def _box_gap(f, e, b):
    """A lower bound on the distance from the oriented box (centre f[0], axes f[1:4], half sizes
    ``e``) to the axis-aligned box ``b``: the largest gap along the 15 axes of the separating-axis
    test (projections are 1-Lipschitz), 0 or less when they may meet."""
    best = -np.inf
    for n in range(15):
        if n < 3:
            lx, ly, lz = 1.0 if n == 0 else 0.0, 1.0 if n == 1 else 0.0, 1.0 if n == 2 else 0.0
        elif n < 6:
            lx, ly, lz = f[n - 2, 0], f[n - 2, 1], f[n - 2, 2]
        else:
            i = (n - 6) // 3  # world axis i crossed with the box's axis k
            k = (n - 6) % 3
            ux, uy, uz = f[1 + k, 0], f[1 + k, 1], f[1 + k, 2]
            if i == 0:
                lx, ly, lz = 0.0, -uz, uy
            elif i == 1:
                lx, ly, lz = uz, 0.0, -ux
            else:
                lx, ly, lz = -uy, ux, 0.0
        norm = math.sqrt(lx * lx + ly * ly + lz * lz)
        if norm < 1e-9:
            continue
        ra = 0.0
        for k in range(3):
            ra += e[k] * abs(f[1 + k, 0] * lx + f[1 + k, 1] * ly + f[1 + k, 2] * lz)
        rb = b[3] * abs(lx) + b[4] * abs(ly) + b[5] * abs(lz)
        dist = abs((f[0, 0] - b[0]) * lx + (f[0, 1] - b[1]) * ly + (f[0, 2] - b[2]) * lz)
        gap = (dist - ra - rb) / norm
        if gap > best:
            best = gap
    return best


@numba.njit(cache=True, nogil=True)
def shape_gap(f, size, kind, b, work):
    """D: a lower bound on the distance from a geom's shape to the box ``b`` (module docstring):
    ``kind`` 0, a capsule (the frame's z axis, ``size`` = (half length, radius, -)), else the
    oriented box of half sizes ``size``."""
    if kind == 0:
        h = size[0]
        for d in range(3):
            work[0, d] = f[0, d] - h * f[3, d]
            work[1, d] = f[0, d] + h * f[3, d]
        return segment_box(work[0], work[1], b) - size[1]
    return _box_gap(f, size, b)


@numba.njit(cache=True, nogil=True)
def turn_frame(f, c, a, angle, out):
    """The frame ``f`` (centre, then three axes) turned by ``angle`` about the axis a through c."""
    rotate(f[0], c, a, angle, out[0])
    for k in range(1, 4):
        rotate(f[k], ZERO, a, angle, out[k])


ZERO = np.zeros(3)


@numba.njit(cache=True, nogil=True)
def _pair_clear(f, size, kind, c, a, theta, travel, b, stack, work):
    """Whether the geom turned through ``theta`` keeps clear of the box (module docstring)."""
    fr = work[2:6]
    d0 = shape_gap(f, size, kind, b, work)
    if d0 <= 0.0:
        return False
    if d0 > travel:
        return True
    turn_frame(f, c, a, theta, fr)
    d1 = shape_gap(fr, size, kind, b, work)
    if d1 <= 0.0:
        return False
    stack[0, 0], stack[0, 1], stack[0, 2], stack[0, 3] = 0.0, 1.0, d0, d1
    n = 1
    evals = 2
    while n > 0:
        n -= 1
        t0, t1, da, db = stack[n, 0], stack[n, 1], stack[n, 2], stack[n, 3]
        span = (t1 - t0) * travel
        if da + db > span:
            continue
        if span < RESOLUTION or evals >= MAX_EVALS or n + 2 > _STACK:
            return False
        tm = 0.5 * (t0 + t1)
        turn_frame(f, c, a, tm * theta, fr)
        dm = shape_gap(fr, size, kind, b, work)
        evals += 1
        if dm <= 0.0:
            return False
        stack[n, 0], stack[n, 1], stack[n, 2], stack[n, 3] = tm, t1, dm, db
        stack[n + 1, 0], stack[n + 1, 1], stack[n + 1, 2], stack[n + 1, 3] = t0, tm, da, dm
        n += 2
    return True


@numba.njit(cache=True, nogil=True)
def _axis_distance(x, y, z, c, a):
    vx = x - c[0]
    vy = y - c[1]
    vz = z - c[2]
    d = a[0] * vx + a[1] * vy + a[2] * vz
    s = vx * vx + vy * vy + vz * vz - d * d
    return math.sqrt(s) if s > 0.0 else 0.0


@numba.njit(cache=True, nogil=True)
def speed(f, size, kind, c, a):
    """The largest distance from the axis of a point of the geom's core (a capsule: its segment's
    ends; a box: its corners; convex along segments, so largest at a vertex), and the radius of
    the box around the frame's centre that holds the core."""
    best = 0.0
    if kind == 0:
        for s in (-1.0, 1.0):
            h = s * size[0]
            best = max(best, _axis_distance(f[0, 0] + h * f[3, 0], f[0, 1] + h * f[3, 1], f[0, 2] + h * f[3, 2], c, a))
        return best, size[0]
    for s0 in (-1.0, 1.0):
        for s1 in (-1.0, 1.0):
            for s2 in (-1.0, 1.0):
                x = f[0, 0] + s0 * size[0] * f[1, 0] + s1 * size[1] * f[2, 0] + s2 * size[2] * f[3, 0]
                y = f[0, 1] + s0 * size[0] * f[1, 1] + s1 * size[1] * f[2, 1] + s2 * size[2] * f[3, 1]
                z = f[0, 2] + s0 * size[0] * f[1, 2] + s1 * size[1] * f[2, 2] + s2 * size[2] * f[3, 2]
                best = max(best, _axis_distance(x, y, z, c, a))
    return best, math.sqrt(size[0] * size[0] + size[1] * size[1] + size[2] * size[2])


@numba.njit(cache=True, nogil=True)
def _amplitudes(x, y, z, c, a, out):
    """Per world axis k, the most |dp_k / dangle| of the point (x, y, z) turning about the axis a
    through c, over any turn: p_k oscillates as cos and sin with amplitude sqrt(u_k^2 + w_k^2),
    u = v - a (a . v), w = a x v, v = p - c. Kept as the running maximum in ``out``."""
    vx = x - c[0]
    vy = y - c[1]
    vz = z - c[2]
    d = a[0] * vx + a[1] * vy + a[2] * vz
    ux = vx - a[0] * d
    uy = vy - a[1] * d
    uz = vz - a[2] * d
    wx = a[1] * vz - a[2] * vy
    wy = a[2] * vx - a[0] * vz
    wz = a[0] * vy - a[1] * vx
    out[0] = max(out[0], math.sqrt(ux * ux + wx * wx))
    out[1] = max(out[1], math.sqrt(uy * uy + wy * wy))
    out[2] = max(out[2], math.sqrt(uz * uz + wz * wz))


@numba.njit(cache=True, nogil=True)
def axis_speeds(f, size, kind, c, a, out):
    """``out[k]``: the most a vertex of the geom's core (a capsule's segment ends, a box's corners)
    moves along world axis k per radian of a turn about a through c; the shape's extent along k
    is set by its vertices, so it moves no faster."""
    out[0] = 0.0
    out[1] = 0.0
    out[2] = 0.0
    if kind == 0:
        for s in (-1.0, 1.0):
            h = s * size[0]
            _amplitudes(f[0, 0] + h * f[3, 0], f[0, 1] + h * f[3, 1], f[0, 2] + h * f[3, 2], c, a, out)
        return
    for s0 in (-1.0, 1.0):
        for s1 in (-1.0, 1.0):
            for s2 in (-1.0, 1.0):
                x = f[0, 0] + s0 * size[0] * f[1, 0] + s1 * size[1] * f[2, 0] + s2 * size[2] * f[3, 0]
                y = f[0, 1] + s0 * size[0] * f[1, 1] + s1 * size[1] * f[2, 1] + s2 * size[2] * f[3, 1]
                z = f[0, 2] + s0 * size[0] * f[1, 2] + s1 * size[1] * f[2, 2] + s2 * size[2] * f[3, 2]
                _amplitudes(x, y, z, c, a, out)


@numba.njit(cache=True, nogil=True)
def axis_gap(f, size, kind, b, k):
    """The gap between the shape's extent along world axis k and the box's (0 or less: overlap)."""
    if kind == 0:
        lo = min(f[0, k] - size[0] * f[3, k], f[0, k] + size[0] * f[3, k]) - size[1]
        hi = max(f[0, k] - size[0] * f[3, k], f[0, k] + size[0] * f[3, k]) + size[1]
    else:
        half = size[0] * abs(f[1, k]) + size[1] * abs(f[2, k]) + size[2] * abs(f[3, k])
        lo = f[0, k] - half
        hi = f[0, k] + half
    return max(lo - (b[k] + b[3 + k]), (b[k] - b[3 + k]) - hi)


@numba.njit(cache=True, nogil=True)
def rotation_clear(frames, sizes, kinds, carried, c, a, theta, boxes, pairs, stack, work):
    """Whether turning the geoms ``carried`` (bool over the rows of ``frames``) by ``theta``
    about the axis ``a`` through ``c`` keeps every one of them clear of every box it may touch
    (``pairs[g, o]``); ``frames`` [G, 4, 3] are the geoms' frames at the start of the turn."""
    for g in range(frames.shape[0]):
        if not carried[g]:
            continue
        f = frames[g]
        v, hold = speed(f, sizes[g], kinds[g], c, a)
        travel = abs(theta) * v
        reach = travel + hold + (sizes[g, 1] if kinds[g] == 0 else 0.0)
        axes_done = False
        for o in range(boxes.shape[0]):
            if not pairs[g, o]:
                continue
            b = boxes[o]
            # the ball around the geom's centre, grown by the travel, misses the box: clear
            if _point_box(f[0, 0], f[0, 1], f[0, 2], b) > reach:
                continue
            # separated along a world axis by more than the shape can move along it: clear
            if not axes_done:
                axis_speeds(f, sizes[g], kinds[g], c, a, work[6])
                axes_done = True
            apart = False
            for k in range(3):
                if axis_gap(f, sizes[g], kinds[g], b, k) > abs(theta) * work[6, k]:
                    apart = True
                    break
            if apart:
                continue
            if not _pair_clear(f, sizes[g], kinds[g], c, a, theta, travel, b, stack, work):
                return False
    return True


@numba.njit(cache=True, nogil=True)
def capture(geom_xpos, geom_xmat, geoms, offset, xanchor, xaxis, joints, frames, anchors, axes):
    """Copy the state the next moves start from out of MuJoCo's kinematics: the frames of
    ``geoms`` (centre: the geom's position plus its ``offset`` in the geom's frame; axes: the
    columns of its orientation), the anchors and axes of ``joints``."""
    for g in range(geoms.shape[0]):
        k = geoms[g]
        for d in range(3):
            frames[g, 0, d] = geom_xpos[k, d] + (geom_xmat[k, 3 * d] * offset[g, 0] + geom_xmat[k, 3 * d + 1]
                                                 * offset[g, 1] + geom_xmat[k, 3 * d + 2] * offset[g, 2])
            for col in range(3):
                frames[g, 1 + col, d] = geom_xmat[k, 3 * d + col]
    for i in range(joints.shape[0]):
        for d in range(3):
            anchors[i, d] = xanchor[joints[i], d]
            axes[i, d] = xaxis[joints[i], d]


@numba.njit(cache=True, nogil=True)
def clearances(frames, sizes, kinds, boxes, pairs, work, cap, need, out):
    """``out[g]``: a lower bound on geom g's least D to the boxes it may touch (inf: none, or g
    not in ``need``), exact (``shape_gap``) where it is below ``cap[g]``: the largest gap along a
    world axis first, the distance search only for a box that gap leaves nearer than the cap and
    the best so far."""
    for g in range(frames.shape[0]):
        best = np.inf
        if not need[g]:
            out[g] = best
            continue
        f = frames[g]
        hold = (sizes[g, 0] + sizes[g, 1]) if kinds[g] == 0 else \
            math.sqrt(sizes[g, 0] * sizes[g, 0] + sizes[g, 1] * sizes[g, 1] + sizes[g, 2] * sizes[g, 2])
        for o in range(boxes.shape[0]):
            if not pairs[g, o]:
                continue
            # the ball around the centre that holds the shape: its distance is a lower bound too
            lb = _point_box(f[0, 0], f[0, 1], f[0, 2], boxes[o]) - hold
            if lb >= best or lb > cap[g]:
                if lb < best:
                    best = lb
                continue
            lb = max(lb, axis_gap(frames[g], sizes[g], kinds[g], boxes[o], 0),
                     axis_gap(frames[g], sizes[g], kinds[g], boxes[o], 1),
                     axis_gap(frames[g], sizes[g], kinds[g], boxes[o], 2))
            if lb >= best:
                continue
            if lb <= cap[g]:
                lb = max(lb, shape_gap(frames[g], sizes[g], kinds[g], boxes[o], work))
            if lb < best:
                best = lb
        out[g] = best


def shapes(scene, checker, joints: np.ndarray, q: np.ndarray) -> tuple:
    """The arrays of the swept check for the arm of ``scene`` moving ``joints`` (joint ids):
    (geoms: the arm's geoms that may touch a box of the table body; sizes and kinds of their
    shapes; offsets of the shapes' centres in the geoms' frames; boxes [O, 6]: the table body's
    geoms as centre and half sizes; pairs [G, O]: which of them a geom's contact counts with
    (``ContactChecker``); carried [len(joints), G]: the geoms each joint turns; whether every
    box is an axis-aligned box, at the configuration ``q``)."""
    import mujoco  # here: the compiled moves import this module without MuJoCo's bindings

    model = scene.model
    d = mujoco.MjData(model)
    d.qpos[:] = q
    mujoco.mj_kinematics(model, d)
    env = np.flatnonzero(scene.env_geoms)
    box = mujoco.mjtGeom.mjGEOM_BOX
    aligned = all(model.geom_type[g] == box and np.allclose(d.geom_xmat[g], np.eye(3).ravel(), atol=1e-12)
                  for g in env)
    boxes = np.array([np.concatenate([d.geom_xpos[g], model.geom_size[g]]) for g in env]).reshape(-1, 6)
    counted = checker._env[:, None] & checker._moving[None, :]  # [env geom, arm geom]
    geoms = [g for g in range(model.ngeom) if checker._moving[g] and counted[env, g].any()]
    pairs = np.ascontiguousarray(counted[np.ix_(env, np.array(geoms, np.int64))].T).reshape(len(geoms), len(env))
    # a capsule (a sphere: of length 0) is its own shape; any other geom, MuJoCo's box around it
    kind = model.geom_type
    capsule = [kind[g] in (mujoco.mjtGeom.mjGEOM_CAPSULE, mujoco.mjtGeom.mjGEOM_SPHERE) for g in geoms]
    kinds = np.array([0 if c else 1 for c in capsule], np.int64)
    sizes = np.array([[model.geom_size[g, 1] if kind[g] == mujoco.mjtGeom.mjGEOM_CAPSULE else 0.0,
                       model.geom_size[g, 0], 0.0] if c else model.geom_aabb[g, 3:6]
                      for g, c in zip(geoms, capsule)]).reshape(-1, 3)
    offset = np.array([np.zeros(3) if c else model.geom_aabb[g, :3] for g, c in zip(geoms, capsule)]).reshape(-1, 3)
    below = np.zeros((model.njnt, model.nbody), bool)  # joint j turns body b
    for b in range(model.nbody):
        k = b
        while k > 0:
            below[model.jnt_bodyid == k, b] = True
            k = model.body_parentid[k]
    carried = np.ascontiguousarray(below[np.ix_(np.asarray(joints, np.int64), model.geom_bodyid[geoms])]
                                   ).reshape(len(joints), len(geoms))
    return (np.array(geoms, np.int64), sizes, kinds, offset, boxes, pairs, carried, bool(aligned))


def reaches(model, q: np.ndarray, geoms: np.ndarray, sizes: np.ndarray, offset: np.ndarray,
            site: int) -> tuple[np.ndarray, np.ndarray]:
    """(reach [nq, G], tip_reach [nq]): bounds, in any configuration, on the distance from joint
    q's axis of any point of geom g's shape, and of the site ``site``: the distances from the
    joint's anchor to the next joint's anchor below it, and so on (each fixed in a body), then to
    the shape's centre, plus the shape's half diagonal. Measured at the configuration ``q``."""
    import mujoco  # here: the compiled moves import this module without MuJoCo's bindings

    d = mujoco.MjData(model)
    d.qpos[:] = q
    mujoco.mj_kinematics(model, d)
    frames = np.empty((len(geoms), 4, 3))
    capture(d.geom_xpos, d.geom_xmat, np.asarray(geoms, np.int64), offset, d.xanchor, d.xaxis,
            np.zeros(0, np.int64), frames, np.zeros((0, 3)), np.zeros((0, 3)))

    def depth(body: int) -> int:
        n = 0
        while body > 0:
            body, n = int(model.body_parentid[body]), n + 1
        return n

    def bound(body: int, centre: np.ndarray, radius: float, out: np.ndarray) -> None:
        chain = []
        b = body
        while b > 0:
            chain += [j for j in range(model.njnt) if model.jnt_bodyid[j] == b]
            b = int(model.body_parentid[b])
        chain.sort(key=lambda j: (depth(int(model.jnt_bodyid[j])), j))
        for a, j in enumerate(chain):
            path = sum(float(np.linalg.norm(d.xanchor[chain[k + 1]] - d.xanchor[chain[k]]))
                       for k in range(a, len(chain) - 1))
            out[model.jnt_qposadr[j]] = path + float(np.linalg.norm(centre - d.xanchor[chain[-1]])) + radius

    reach = np.zeros((model.nq, len(geoms)))
    for gi, g in enumerate(geoms):
        col = np.zeros(model.nq)
        bound(int(model.geom_bodyid[g]), frames[gi, 0], float(np.linalg.norm(sizes[gi])), col)
        reach[:, gi] = col
    tip = np.zeros(model.nq)
    bound(int(model.site_bodyid[site]), d.site_xpos[site].copy(), 0.0, tip)
    return reach, tip


def chain_tables(model, joints: np.ndarray, site: int) -> tuple[np.ndarray, bool]:
    """(whether each of ``joints`` turns the body of ``site``, whether ``joints`` are in chain
    order, each below the ones before it or on another branch), for ``ik.fastline``'s product of
    exponentials, which turns the deepest joint first."""
    depth = np.zeros(model.nbody, np.int64)
    for b in range(1, model.nbody):
        depth[b] = depth[model.body_parentid[b]] + 1
    order = [int(depth[model.jnt_bodyid[j]]) for j in joints]
    carries = np.zeros(len(joints), bool)
    for i, j in enumerate(joints):
        b = int(model.site_bodyid[site])
        while b > 0:
            if b == model.jnt_bodyid[j]:
                carries[i] = True
            b = int(model.body_parentid[b])
    return carries, bool(all(a <= b for a, b in zip(order, order[1:])))
