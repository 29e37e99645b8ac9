"""Control trajectories, so that a speed-up is known to come from the transferred knowledge.

``shuffled``: the same (cell, action) steps in a random order (same cells, same length,
no order). ``random``: a random walk of the source robot from the same start, as many steps
as the real trajectory, ending at the same goal label (the goal is only where the task says;
the walk need not reach it). Both take an injected generator.
"""

from __future__ import annotations

import numpy as np

from armtransfer.tasks.robot import DiscreteRobot
from armtransfer.learning.trajectory import Trajectory

CONTROLS = ("shuffled", "random")


def shuffled(traj: Trajectory, rng: np.random.Generator) -> Trajectory:
    """The start stays first (it is where every robot starts); the rest is permuted."""
    order = np.concatenate([[0], 1 + rng.permutation(len(traj) - 1)]).astype(int)
    return Trajectory(
        tuple(traj.cells[i] for i in order), tuple(traj.actions[i] for i in order), traj.goal,
        source=f"{traj.source} (shuffled)",
    )


def random_walk(source: DiscreteRobot, traj: Trajectory, rng: np.random.Generator) -> Trajectory:
    s = source.start_state(traj.start)
    cells, actions = [], []
    for _ in range(len(traj)):
        a = int(rng.integers(source.n_actions))
        cells.append(int(source.label[s]))
        actions.append(a)
        s = int(source.next_state[s, a])
    return Trajectory(tuple(cells), tuple(actions), traj.goal, source=f"{source.name} (random walk)")
