"""Progress along the transferred trajectories, and the score it gives a label position.

A trajectory's progress is the furthest index whose cell the label came within ``reach`` cells
of in this episode; after ``give_up`` moves without progress the next cell is given up on (it
may be out of reach), and after ``give_up`` moves at the last one, s_tg, without the episode
ending, the trajectory is (its goal is not this task's: a control trajectory, or a wrong one);
once every trajectory is, Algorithm 1 chooses alone (``exhausted``). The score of a label
position q is the min over the trajectory cells c_j ahead of the progress index, within
``window`` cells of trajectory length, of |q - c_j| + (the trajectory's length from c_j to its
end); lower is better. With several trajectories the smallest score counts."""

from __future__ import annotations

from typing import NamedTuple

import numba
import numpy as np


class Progress(NamedTuple):
    """Where robot 2 is along each trajectory (``new``)."""

    index: np.ndarray  # type: ignore[assignment]  # a field shadowing tuple.index: the name is read in numba-compiled bodies
    """int64 [n_traj]: the progress index of each trajectory (into the guide's tx, ty, trem)."""
    wait: np.ndarray
    """int64 [n_traj]: moves without progress on each trajectory."""
    epoch: np.ndarray
    """int64 [1]: +1 at an episode's start and whenever a trajectory's progress moves."""


def new(n_traj: int) -> Progress:
    """Progress on ``n_traj`` trajectories, before the first episode."""
    return Progress(np.zeros(max(n_traj, 1), np.int64), np.zeros(max(n_traj, 1), np.int64), np.zeros(1, np.int64))


@numba.njit(cache=True)
def reset(g, p):
    """At an episode's start: progress at each trajectory's first cell."""
    tstart = g.tstart
    for t in range(tstart.shape[0] - 1):
        p.index[t] = tstart[t]
        p.wait[t] = 0
    p.epoch[0] += 1


@numba.njit(cache=True)
def update(g, p, s):
    """Advance each trajectory's progress index to the furthest cell within reach of s's
    label, looking up to ``window + reach`` cells of trajectory length ahead. After
    ``give_up`` moves without progress on a trajectory its next cell is given up on (robot 2
    may be unable to reach it: a wall, a joint limit, a cell out of its reach); after
    ``give_up`` moves at its last cell, s_tg, the trajectory itself is: its progress goes one
    past its cells."""
    lxy, tx, ty, trem, tstart = g.lxy, g.tx, g.ty, g.trem, g.tstart
    prog, wait = p.index, p.wait
    reach = g.params.reach
    horizon = g.params.window + reach
    give_up = g.params.give_up
    x = lxy[s, 0]
    y = lxy[s, 1]
    for t in range(tstart.shape[0] - 1):
        i0 = prog[t]
        if i0 >= tstart[t + 1]:
            continue  # given up on
        for j in range(i0 + 1, tstart[t + 1]):
            if trem[i0] - trem[j] > horizon:
                break
            dx = tx[j] - x
            dy = ty[j] - y
            if np.sqrt(dx * dx + dy * dy) <= reach:
                prog[t] = j
        if prog[t] != i0:
            wait[t] = 0
            p.epoch[0] += 1
        else:
            wait[t] += 1
            if give_up > 0 and wait[t] >= give_up:
                prog[t] += 1
                wait[t] = 0
                p.epoch[0] += 1


@numba.njit(cache=True)
def exhausted(g, p):
    """Every trajectory given up on (``update``): the model has nothing to say."""
    tstart = g.tstart
    for t in range(tstart.shape[0] - 1):
        if p.index[t] < tstart[t + 1]:
            return False
    return True


@numba.njit(cache=True)
def score(g, p, x, y):
    """How far (cells) a label at (x, y) is from the goal along the trajectories ahead."""
    tx, ty, trem, tstart = g.tx, g.ty, g.trem, g.tstart
    window = g.params.window
    best = np.inf
    for t in range(tstart.shape[0] - 1):
        i0 = p.index[t]
        for j in range(i0, tstart[t + 1]):
            if trem[i0] - trem[j] > window:
                break
            dx = tx[j] - x
            dy = ty[j] - y
            v = np.sqrt(dx * dx + dy * dy) + trem[j]
            if v < best:
                best = v
    return best
