"""A transfer method's shaping as a reward term paid move by move, for learners outside the project.

:class:`TransferTerm` holds the shaping arrays the method registry builds for a robot and its
transferred trajectories, and the state the learner kernel keeps (which trajectory cells
``first-visit`` has paid in the trial, how far ``progress`` got in the episode); each move's term is computed by the
kernel's own shaping function (``armtransfer.learning.sarsa.shaping_term``), so a learner that adds
it sees exactly the rewards the project's SARSA(lambda) sees. The Gymnasium wrapper
(``armtransfer.wrappers.TransferReward``) and the dm_control one (``armtransfer.dmc``) add it.
"""

from __future__ import annotations

import os
from collections.abc import Sequence

import numpy as np

import armtransfer.checks as checks
from armtransfer.errors import InvalidParameterError, InvalidTrajectoryError
from armtransfer.learning import methods as registry
from armtransfer.learning import trajectory as trajectories
from armtransfer.learning.config import LearnerConfig
from armtransfer.learning.sarsa import shaping_term
from armtransfer.learning.shaping import MODE_NONE
from armtransfer.learning.trajectory import Trajectory
from armtransfer.tasks.grid_robots import GRID_ROBOTS
from armtransfer.tasks.robot import DiscreteRobot

TrajectoryLike = Trajectory | str | os.PathLike


class TransferTerm:
    """Method ``method``'s shaping from ``trajectory`` for ``robot``, one move at a time.

    ``trajectory``: a :class:`Trajectory`, a trajectory JSON file, or a list of them.
    ``step_reward`` is the environment's (K='auto' scales with it); ``gamma`` is the discount
    of the potential-based methods' F = gamma*phi(s') - phi(s): set it to the learner's.
    ``task`` (start cell, goal cell): the trajectories must be of that task.
    Call :meth:`reset` at the start of every episode, then ``term(s, s2, terminated)`` for
    every move from state ``s`` to ``s2``.
    """

    def __init__(self, robot: DiscreteRobot, trajectory: TrajectoryLike | Sequence[TrajectoryLike],
                 method: str = "pseudo", K: float | str = "auto", step_reward: float = LearnerConfig().step_reward,
                 gamma: float = LearnerConfig().gamma, beta: float | None = None,
                 task: tuple[int, int] | None = None) -> None:
        m = registry.get(method)
        if m.name not in registry.REWARD_ONLY:
            why = "adds no reward" if not m.shaped else "changes how the learner chooses actions, not a reward"
            raise InvalidParameterError(f"method {method!r} {why}; valid methods: {', '.join(registry.REWARD_ONLY)}")
        gamma = checks.real(gamma, "gamma", 0.0, 1.0)
        self.robot = robot
        self.trajectories = [self._load(t, task) for t in _as_list(trajectory)]
        self.method = m.name
        self.gamma = float(gamma)
        self.shaping = registry.build_shaping(m.name, robot, self.trajectories, K, step_reward, beta=beta,
                                              gamma=self.gamma)
        n_ids = int(self.shaping.traj_index.max()) + 1 if len(self.shaping.traj_index) else 1
        self._paid = np.full(max(n_ids, 1), -1, np.int64)
        self._episode = -1
        self._best = 0.0

    def _load(self, t: TrajectoryLike, task: tuple[int, int] | None) -> Trajectory:
        """A trajectory on the robot's layout and, with ``task`` (start cell, goal cell), of that
        task: the shaping pays towards the trajectory's goal, so it must be the task's."""
        if not isinstance(t, (Trajectory, str, os.PathLike)):
            raise InvalidTrajectoryError(f"a trajectory is a Trajectory or a trajectory JSON file, got {t!r}")
        layout = self.robot.layout
        traj = t if isinstance(t, Trajectory) else trajectories.load(t, layout)
        n_cells = layout.n_cells * max(1, self.robot.arm.levels if self.robot.arm is not None else 1)  # voxels: 3D
        if any(not 0 <= c < n_cells for c in (*traj.cells, traj.goal)):
            raise InvalidTrajectoryError(f"the trajectory names cells outside this robot's layout (0..{n_cells - 1})")
        if self.robot.arm is not None and traj.source in GRID_ROBOTS:
            raise InvalidTrajectoryError(
                f"the trajectory is of the grid robot {traj.source!r} but this environment's robot "
                f"{self.robot.name} is an arm; give a trajectory of an arm (robot 1 of an arm-to-arm transfer)")
        if task is not None:
            trajectories.check_task(traj, task[0], task[1], layout)
        return traj

    @property
    def K(self) -> float:
        return self.shaping.K

    def reset(self) -> None:
        """A new episode: no progress yet (the cells ``first-visit`` paid stay paid for the term's life)."""
        self._episode += 1
        self._best = 0.0

    def term(self, s: int, s2: int, terminated: bool) -> float:
        """The shaping term of the move from state ``s`` to ``s2`` (``terminated``: ``s2`` ends
        the episode at the goal)."""
        if self._episode < 0:
            raise InvalidParameterError("call reset() before step()")
        sh = self.shaping
        if sh.mode == MODE_NONE:
            return 0.0
        value, self._best = shaping_term(sh.mode, int(s), int(s2), bool(terminated), sh.bonus, sh.traj_index, sh.phi,
                                     self.gamma, self._paid, self._episode, self._best)
        return float(value)


def _as_list(trajectory) -> list:
    if isinstance(trajectory, (Trajectory, str, os.PathLike)):
        return [trajectory]
    try:
        out = list(trajectory)
    except TypeError:
        raise InvalidTrajectoryError(
            f"a trajectory is a Trajectory, a trajectory JSON file or a list of them, got {trajectory!r}") from None
    if not out:
        raise InvalidParameterError("transfer shaping needs at least one trajectory")
    return out
