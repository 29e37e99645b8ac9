"""Knowledge transfer for any dm_env learner: a reward wrapper over the arm tasks' environments.

Every step's reward is the task's plus the chosen method's shaping term for the move just
made (``armtransfer.learning.reward_term.TransferTerm``, the term the Gymnasium wrapper
``armtransfer.wrappers.TransferReward`` adds too, computed by the learner kernel's own shaping
function). Per-episode state starts afresh at every FIRST step.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import dm_env

from armtransfer.errors import InvalidParameterError
from armtransfer.learning.config import LearnerConfig
from armtransfer.learning.reward_term import TrajectoryLike, TransferTerm


class TransferShaping(dm_env.Environment):
    """Adds method ``method``'s shaping from ``trajectory`` to the rewards of ``environment``,
    a ``dm_control.rl.control.Environment`` of a :class:`armtransfer.dmc.task.RoomsTask`.
    ``gamma``: the discount of the potential-based methods' F = gamma*phi(s') - phi(s); set
    it to your learner's discount."""

    def __init__(self, environment: dm_env.Environment, trajectory: TrajectoryLike | Sequence[TrajectoryLike],
                 method: str = "pseudo", K: float | str = "auto", gamma: float = LearnerConfig().gamma,
                 beta: float | None = None) -> None:
        task: Any = getattr(environment, "task", None)  # any task with these attributes
        if not all(hasattr(task, a) for a in ("robot", "step_reward", "goal_cell")):
            raise InvalidParameterError(
                f"TransferShaping needs an environment of armtransfer.dmc.load, got {type(environment).__name__}")
        self._environment = environment
        cells = (int(task.robot.label[task.start_state]), int(task.goal_cell))  # the trajectories must be of this task
        self.transfer = TransferTerm(task.robot, trajectory, method, K, task.step_reward, gamma, beta, task=cells)
        self._state: int | None = None

    @property
    def environment(self) -> dm_env.Environment:
        return self._environment

    @property
    def physics(self):
        return self._environment.physics

    @property
    def task(self):
        return self._environment.task

    def reset(self) -> dm_env.TimeStep:
        return self._first(self._environment.reset())

    def step(self, action) -> dm_env.TimeStep:
        timestep = self._environment.step(action)
        if timestep.first():  # stepped after the end of an episode (or before any): a new one
            return self._first(timestep)
        s2 = int(timestep.observation["state"])
        if self._state is None:  # no FIRST step seen, so the term was never reset either
            raise InvalidParameterError("call reset() before step()")
        term = self.transfer.term(self._state, s2, timestep.last() and timestep.discount == 0.0)
        self._state = s2
        return timestep._replace(reward=timestep.reward + term)

    def _first(self, timestep: dm_env.TimeStep) -> dm_env.TimeStep:
        self.transfer.reset()
        self._state = int(timestep.observation["state"])
        return timestep

    def action_spec(self):
        return self._environment.action_spec()

    def observation_spec(self):
        return self._environment.observation_spec()

    def reward_spec(self):
        return self._environment.reward_spec()

    def discount_spec(self):
        return self._environment.discount_spec()

    def close(self) -> None:
        self._environment.close()


__all__ = ["TransferShaping"]
