"""The tip model, for a robot whose actions move a joint: where its tip is, from its joints.

One move of a joint shifts the tip by a fraction of a cell, so the label rarely changes and a
move tried at a state mostly records "no effect". Robot 2 therefore learns where its tip is as a
smooth function of its own joint configuration q: ridge least squares of the label's xy on
products of cos and sin of up to ``TIP_ORDER`` of its moving joints (exact for any planar chain
of up to 3 joints), one recursive step per newly visited state, in the exploration phase. A move
not yet tried at s is predicted as tip(q_s + the mean joint displacement robot 2 observed for
that action) - tip(q_s): a sub-cell displacement (``move``)."""

from __future__ import annotations

import itertools
from typing import NamedTuple

import numba
import numpy as np

from armtransfer.learning.guide.params import TIP_ORDER
from armtransfer.tasks.robot import DiscreteRobot


class TipModel(NamedTuple):
    """What the tip model has learned (``new``; empty arrays without it)."""

    P: np.ndarray
    """float64 [F, F]: the inverse of (ridge I + the sum of f f^T)."""
    W: np.ndarray
    """float64 [F, 2]: the weights, tip xy relative to the first label learned from."""
    first: np.ndarray
    """float64 [2]: the first label learned from."""
    has_first: np.ndarray
    """bool [1]: whether ``first`` is set."""
    seen: np.ndarray
    """bool [S] (or [0] without the model): states already learned from."""
    dq: np.ndarray
    """float64 [A, C]: the summed joint displacement of each action's moves."""
    dq_n: np.ndarray
    """int64 [A]: the moves summed in ``dq``."""
    f_here: np.ndarray
    """float64 [F]: scratch, the features of the state learned from or chosen at."""
    f_move: np.ndarray
    """float64 [F]: scratch, the features after a predicted move."""
    px: np.ndarray
    """float64 [F]: scratch, P times the features."""
    q: np.ndarray
    """float64 [C]: scratch, a joint configuration."""


def tip_features(n_joints: int, order: int = TIP_ORDER) -> tuple[np.ndarray, np.ndarray]:
    """(fj, fk) of the tip model: the constant 1, then for k = 1 .. order every set of k joints
    (in index order) times every choice of cos or sin for each of them. Any serial chain of
    revolute joints has a tip whose coordinates are sums of such products of all its joints; up to
    ``order`` joints at a time this is exact for up to ``order`` joints and a smooth basis beyond."""
    fj, fk = [[-1] * order], [[0] * order]
    for k in range(1, min(order, n_joints) + 1):
        for joints in itertools.combinations(range(n_joints), k):
            for kinds in itertools.product((0, 1), repeat=k):
                fj.append(list(joints) + [-1] * (order - k))
                fk.append(list(kinds) + [0] * (order - k))
    return np.array(fj, np.int64), np.array(fk, np.int64)


def uses_tip(robot: DiscreteRobot) -> bool:
    """Whether the tip model is on by default: robots whose actions move a joint."""
    return robot.arm is not None and robot.arm.joint_step is not None


def new(n_states: int, n_actions: int, n_features: int, n_joints: int, ridge: float) -> TipModel:
    """An empty tip model (P the identity over the ridge); n_features 0: none."""
    P = np.eye(n_features)
    P[...] /= ridge if n_features else 1.0
    return TipModel(P, np.zeros((n_features, 2)), np.zeros(2), np.zeros(1, np.bool_),
                    np.zeros(n_states if n_features else 0, np.bool_), np.zeros((n_actions, n_joints)),
                    np.zeros(n_actions, np.int64), np.zeros(n_features), np.zeros(n_features),
                    np.zeros(n_features), np.zeros(n_joints))


@numba.njit(cache=True)
def features(g, q, out):
    """The tip model's features of joint configuration q (``tip_features``) into out."""
    fj, fk = g.fj, g.fk
    for i in range(fj.shape[0]):
        v = 1.0
        for k in range(fj.shape[1]):
            j = fj[i, k]
            if j < 0:
                break
            if fk[i, k] == 0:
                v *= np.cos(q[j])
            else:
                v *= np.sin(q[j])
        out[i] = v


@numba.njit(cache=True)
def learn(g, t, s):
    """Learn from state s, once per state: one recursive least-squares step (Sherman-Morrison)
    towards label xy(s) - (the first label it learned from), on the features of s's moving
    joints. P stays the inverse of (ridge I + sum of f f^T)."""
    lxy = g.lxy
    P, W, y0, f, px = t.P, t.W, t.first, t.f_here, t.px
    if t.seen[s]:
        return
    t.seen[s] = True
    if not t.has_first[0]:
        y0[0] = lxy[s, 0]
        y0[1] = lxy[s, 1]
        t.has_first[0] = True
    features(g, g.tq[s], f)
    n = f.shape[0]
    denom = 1.0
    for i in range(n):
        acc = 0.0
        for j in range(n):
            acc += P[i, j] * f[j]
        px[i] = acc
    for i in range(n):
        denom += f[i] * px[i]
    for c in range(2):
        fit = 0.0
        for i in range(n):
            fit += f[i] * W[i, c]
        err = (lxy[s, c] - y0[c]) - fit
        for i in range(n):
            W[i, c] += px[i] / denom * err
    for i in range(n):
        k = px[i] / denom
        for j in range(n):
            P[i, j] -= k * px[j]


@numba.njit(cache=True)
def observe(g, t, s, a, s2):
    """The move s --a--> s2: its joint displacement joins a's mean, and the model learns s2."""
    tq = g.tq
    if s2 != s:
        for c in range(tq.shape[1]):
            t.dq[a, c] += tq[s2, c] - tq[s, c]
        t.dq_n[a] += 1
    learn(g, t, s2)


@numba.njit(cache=True)
def at(t, f):
    """(x, y) the tip model predicts (relative to the first label) for features f."""
    W = t.W
    x = 0.0
    y = 0.0
    for i in range(f.shape[0]):
        x += f[i] * W[i, 0]
        y += f[i] * W[i, 1]
    return x, y


@numba.njit(cache=True)
def here(g, t, s):
    """(x, y) the tip model predicts at s (relative to the first label)."""
    features(g, g.tq[s], t.f_here)
    return at(t, t.f_here)


@numba.njit(cache=True)
def move(g, t, s, a, x0, y0):
    """(dx, dy): the displacement of a at s: the tip at s's joints plus a's mean observed joint
    displacement, minus (x0, y0), the tip at s; (0, 0) when a never moved."""
    tq, dq, dqn, f, q = g.tq, t.dq, t.dq_n, t.f_move, t.q
    if dqn[a] == 0:
        return 0.0, 0.0
    for c in range(tq.shape[1]):
        q[c] = tq[s, c] + dq[a, c] / dqn[a]
    features(g, q, f)
    x1, y1 = at(t, f)
    return x1 - x0, y1 - y0
