"""The displacement model: what each of robot 2's moves did to the label it perceives.

After every move s --a--> s' robot 2 records the displacement of its label, xy(label[s']) -
xy(label[s]), for the pair (s, a) (a running mean: with wind the push is part of what it sees),
and remembers s among the last ``memory`` states at which it tried a. The predicted displacement
of a at s is the recorded mean when (s, a) was tried; else the mean over the ``knn`` remembered
states nearest to s in robot 2's own configuration space (an arm's joints, a grid robot's cell)
at which a was tried: the same action moves the tip by about the same cells in neighbouring
configurations."""

from __future__ import annotations

from typing import NamedTuple

import numba
import numpy as np


class Displacement(NamedTuple):
    """What the displacement model has learned (``new``)."""

    sums: np.ndarray
    """float64 [S, A, 2]: the summed label displacement of each pair."""
    tries: np.ndarray
    """int64 [S, A]: how often each pair was tried."""
    tried_at: np.ndarray
    """int64 [A, memory]: a ring buffer of the states each action was tried at (generalised)."""
    pushes: np.ndarray
    """int64 [A]: states pushed into each action's ring buffer."""
    generalised: np.ndarray
    """bool [S, A]: the pair is in its action's ring buffer."""
    moved: np.ndarray
    """bool [S, A]: the pair moved the robot at least once."""


def new(n_states: int, n_actions: int, memory: int) -> Displacement:
    """An empty displacement model."""
    return Displacement(np.zeros((n_states, n_actions, 2)), np.zeros((n_states, n_actions), np.int64),
                        np.zeros((n_actions, memory), np.int64), np.zeros(n_actions, np.int64),
                        np.zeros((n_states, n_actions), np.bool_), np.zeros((n_states, n_actions), np.bool_))


@numba.njit(cache=True)
def record(g, d, s, a, s2):
    """Record the move s --a--> s2; a blocked move (s2 == s) is generalised only with ``blocked``."""
    lxy = g.lxy
    if s2 != s:
        d.moved[s, a] = True
    d.sums[s, a, 0] += lxy[s2, 0] - lxy[s, 0]
    d.sums[s, a, 1] += lxy[s2, 1] - lxy[s, 1]
    d.tries[s, a] += 1
    if (s2 != s or g.params.blocked) and not d.generalised[s, a]:
        d.generalised[s, a] = True
        memory = g.params.memory
        d.tried_at[a, d.pushes[a] % memory] = s
        d.pushes[a] += 1


@numba.njit(cache=True)
def nearest(g, d, s, a, k):
    """The (at most) k remembered states where a was tried that are nearest to s in robot 2's
    configuration space, nearest first (ties: the earlier ring-buffer slot)."""
    feat = g.feat
    buf = d.tried_at
    n = min(d.pushes[a], g.params.memory)
    k = min(k, n)
    dist = np.empty(n)
    for i in range(n):
        u = buf[a, i]
        dd = 0.0
        for c in range(feat.shape[1]):
            diff = feat[u, c] - feat[s, c]
            dd += diff * diff
        dist[i] = dd
    taken = np.zeros(n, np.bool_)
    out = np.empty(k, np.int64)
    for j in range(k):
        best = -1
        for i in range(n):
            if not taken[i] and (best < 0 or dist[i] < dist[best]):
                best = i
        taken[best] = True
        out[j] = buf[a, best]
    return out


@numba.njit(cache=True)
def predict(g, d, s, a):
    """(known, dx, dy): the predicted label displacement of a at s; known is False when a
    was never tried anywhere."""
    sums, tries = d.sums, d.tries
    if tries[s, a] > 0:
        return True, sums[s, a, 0] / tries[s, a], sums[s, a, 1] / tries[s, a]
    near = nearest(g, d, s, a, g.params.knn)
    k = near.shape[0]
    if k == 0:
        return False, 0.0, 0.0
    sx = 0.0
    sy = 0.0
    for u in near:
        sx += sums[u, a, 0] / tries[u, a]
        sy += sums[u, a, 1] / tries[u, a]
    return True, sx / k, sy / k


@numba.njit(cache=True)
def near_blocked(g, d, s, a):
    """Whether a was blocked at each of the ``tip_nearest`` remembered states nearest to s in
    configuration space where it was tried (ties: the earlier slot), i.e. a joint limit or a
    wall is predicted; False when a was tried nowhere."""
    near = nearest(g, d, s, a, g.params.tip_nearest)
    if near.shape[0] == 0:
        return False
    for u in near:
        if d.moved[u, a]:
            return False
    return True
