"""Control trajectories, so that a speed-up is known to come from the transferred knowledge.

``shuffled``: the same (cell, action) steps in a random order (same cells, same length,
no order). ``random``: a random walk of the source robot from the same start, as many steps
as the real trajectory. Both take an injected generator.

A trajectory is the paper's ``{(s_t0, a_t0), ..., (s_tn, a_tn), s_tg}``: its goal cell
``s_tg`` is part of what robot 1 hands over, and robot 2 knows where the goal is only from
it. So a control replaces it too: the shuffled one ends where its order ends (its goal is
its own last cell), the random walk where the walk ends (the label of its last state). A
control keeps the task's goal only when asked (``keep_goal=True``): that is an ablation
(does the path's order add anything to knowing the goal?), not a control for transfer.
``pseudo`` and ``dense`` never read ``s_tg``, so for them the two are the same, bit for bit.

The reports draw a control per trial (``experiment.run_control``): a control's mean is then
over its own randomness, where one draw shared by every trial would stand for it by luck (a
shuffle that happens to begin beside the goal is nearly the real trajectory).
"""

from __future__ import annotations

import numpy as np

from armtransfer.tasks.robot import DiscreteRobot
from armtransfer.learning.trajectory import Trajectory

CONTROLS = ("shuffled", "random")


def label(kind: str, keep_goal: bool = False) -> str:
    """How results name a control: ``shuffled``, or ``shuffled, goal kept`` for the ablation."""
    return f"{kind}, goal kept" if keep_goal else kind


def shuffled(traj: Trajectory, rng: np.random.Generator, keep_goal: bool = False) -> Trajectory:
    """The start stays first (it is where every robot starts); the rest is permuted."""
    order = np.concatenate([[0], 1 + rng.permutation(len(traj) - 1)]).astype(int)
    cells = tuple(traj.cells[i] for i in order)
    return Trajectory(
        cells, tuple(traj.actions[i] for i in order), traj.goal if keep_goal else cells[-1],
        source=f"{traj.source} (shuffled{', goal kept' if keep_goal else ''})",
    )


def random_walk(source: DiscreteRobot, traj: Trajectory, rng: np.random.Generator,
                keep_goal: bool = False) -> Trajectory:
    s = source.start_state(traj.start)
    cells, actions = [], []
    for _ in range(len(traj)):
        a = int(rng.integers(source.n_actions))
        cells.append(int(source.label[s]))
        actions.append(a)
        s = int(source.next_state[s, a])
    goal = traj.goal if keep_goal else int(source.label[s])
    return Trajectory(tuple(cells), tuple(actions), goal,
                      source=f"{source.name} (random walk{', goal kept' if keep_goal else ''})")
