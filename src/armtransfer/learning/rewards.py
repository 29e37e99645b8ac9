"""From transferred trajectories to per-state indices: what every shaping method pays by.

``pseudo`` is the paper's (section III.B): r'(s') = i*K when the robot reaches a state
labelled with the i-th trajectory cell s_ti (i = 1..n; when a cell occurs more than once
in the trajectory the largest i counts, so a loop is bypassed towards the goal).

A plain state bonus can be farmed: if ``step_reward + n*K >= 0``, standing on s_tn (for
instance by bumping a wall) pays at least as much as moving on, and an agent can loop
there forever. ``armtransfer.learning.methods`` defines every method on these indices.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from armtransfer.errors import InvalidParameterError
from armtransfer.tasks.robot import DiscreteRobot
from armtransfer.learning.trajectory import Trajectory


def as_list(trajs: Trajectory | Sequence[Trajectory]) -> list[Trajectory]:
    out = [trajs] if isinstance(trajs, Trajectory) else list(trajs)
    if not out:
        raise InvalidParameterError("a transfer method needs at least one trajectory")
    return out


def longest_n(trajs: Trajectory | Sequence[Trajectory]) -> int:
    """N, the largest index n over the trajectories: pseudo rewards go up to N*K."""
    return max(max(t.n, 1) for t in as_list(trajs))


def farming_bound(step_reward: float, trajs: Trajectory | Sequence[Trajectory]) -> float:
    """The K at and above which ``pseudo`` can be farmed: -step_reward / N."""
    return -step_reward / longest_n(trajs)


def trajectory_index(robot: DiscreteRobot, traj: Trajectory) -> np.ndarray:
    """For every robot state, the largest i >= 1 with label == s_ti (-1 when none)."""
    index_of_cell: dict[int, int] = {}
    for i, cell in enumerate(traj.cells):
        if i >= 1:
            index_of_cell[cell] = i  # later occurrences overwrite earlier ones
    index = np.full(robot.n_states, -1, np.int64)
    for cell, i in index_of_cell.items():
        index[robot.label == cell] = i
    return index


def union_index(robot: DiscreteRobot, trajs: Sequence[Trajectory]) -> tuple[np.ndarray, np.ndarray]:
    """(effective index, cell id) of every state over several trajectories.

    Each trajectory's index is taken as a fraction of its length, i/n, and scaled by the
    longest N, so one trajectory gives exactly its own i. A state on several trajectories
    takes the largest. The id numbers the distinct trajectory cells 1, 2, ... (-1: none),
    for methods that pay each cell once."""
    N = longest_n(trajs)
    eff = np.zeros(robot.n_states)
    for traj in trajs:
        idx = trajectory_index(robot, traj)
        eff = np.maximum(eff, np.where(idx > 0, idx * (N / max(traj.n, 1)), 0.0))
    on = eff > 0
    ids = np.full(robot.n_states, -1, np.int64)
    _, inverse = np.unique(robot.label[on], return_inverse=True)
    ids[on] = inverse + 1
    return eff, ids

