"""Knowledge transfer for any Gymnasium learner: a reward wrapper over the project's envs (public as
``armtransfer.wrappers.TransferReward``).

    import gymnasium as gym
    import armtransfer
    from armtransfer.wrappers import TransferReward

    env = gym.make("armtransfer/Rooms-v0", task=1, robot="fine")
    env = TransferReward(env, "trajectory.json", method="pseudo", K="auto")

Every step's reward is the environment's plus the chosen method's shaping term for the move
just made, computed by the learner kernel's own shaping function
(``armtransfer.learning.sarsa.shaping_term``) on arrays built by the method registry, so an
agent learning on the wrapped env sees exactly the rewards the project's SARSA(lambda) sees.
The term is also in ``info["shaping"]``. How far ``progress`` got starts afresh at every
``reset``; the cells ``first-visit`` has paid stay paid for the wrapper's life (one trial).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import gymnasium as gym

from armtransfer.errors import InvalidParameterError
from armtransfer.learning.config import LearnerConfig
from armtransfer.learning.reward_term import TrajectoryLike, TransferTerm


class TransferReward(gym.Wrapper, gym.utils.RecordConstructorArgs):
    """Adds method ``method``'s shaping from ``trajectory`` to the rewards of ``env``.

    ``env`` is one of the project's environments (``armtransfer/Rooms-v0``,
    ``armtransfer/ArmRooms-v0``) or anything whose unwrapped env has ``robot``,
    ``step_reward`` and ``goal_cell`` and reports the robot's state as its observation.
    ``trajectory``: a :class:`Trajectory`, a trajectory JSON file, or a list of them.
    ``gamma`` is the discount of the potential-based methods' F = gamma*phi(s') - phi(s):
    set it to your learner's discount (their potential is bounded for it, so that no move
    that leaves the state unchanged pays; ``potentials.bounded``).
    """

    def __init__(self, env: gym.Env, trajectory: TrajectoryLike | Sequence[TrajectoryLike], method: str = "pseudo",
                 K: float | str = "auto", gamma: float = LearnerConfig().gamma, beta: float | None = None) -> None:
        gym.utils.RecordConstructorArgs.__init__(self, trajectory=trajectory, method=method, K=K, gamma=gamma,
                                                 beta=beta)
        gym.Wrapper.__init__(self, env)
        base: Any = env.unwrapped  # any env with the attributes checked below
        missing = [a for a in ("robot", "step_reward", "goal_cell") if not hasattr(base, a)]
        if missing:
            raise InvalidParameterError(
                f"TransferReward needs one of armtransfer's environments (no {', '.join(missing)} on "
                f"{type(base).__name__})")
        start = getattr(base, "start_state", None)
        task = (int(base.robot.label[start]), int(base.goal_cell)) if start is not None else None
        self.transfer = TransferTerm(base.robot, trajectory, method, K, base.step_reward, gamma, beta, task=task)
        self.robot = base.robot
        self.goal_cell = int(base.goal_cell)
        self._state: int | None = None
        # the robot's state as the shaping indexes it: the observation, or what the env says it is
        # (the continuous arm's: the cell under its tool point, from info)
        self._state_of = getattr(base, "state_of", lambda obs, info: int(obs))

    @property
    def method(self) -> str:
        return self.transfer.method

    @property
    def trajectories(self) -> list:
        return self.transfer.trajectories

    @property
    def shaping(self):
        return self.transfer.shaping

    @property
    def gamma(self) -> float:
        return self.transfer.gamma

    @property
    def K(self) -> float:
        return self.transfer.K

    def reset(self, **kwargs):
        obs, info = self.env.reset(**kwargs)
        self.transfer.reset()
        self._state = self._state_of(obs, info)
        return obs, info

    def step(self, action):
        if self._state is None:
            raise InvalidParameterError("call reset() before step()")
        obs, reward, terminated, truncated, info = self.env.step(action)
        state = self._state_of(obs, info)
        term = self.transfer.term(self._state, state, bool(terminated))
        self._state = state
        info = dict(info, shaping=term)
        return obs, reward + term, terminated, truncated, info
