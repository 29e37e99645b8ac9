"""Knowledge transfer for any Gymnasium learner: a reward wrapper over the project's envs.

    import gymnasium as gym
    import armtransfer
    from armtransfer.wrappers import TransferReward

    env = gym.make("armtransfer/Rooms-v0", task=1, robot="fine")
    env = TransferReward(env, "trajectory.json", method="pseudo", K="auto")

Every step's reward is the environment's plus the chosen method's shaping term for the move
just made, computed by the learner kernel's own shaping function
(``armtransfer.learning.sarsa._shaping``) on arrays built by the method registry, so an
agent learning on the wrapped env sees exactly the rewards the project's SARSA(lambda) sees.
The term is also in ``info["shaping"]``. Per-episode state (which trajectory cells
``first-visit`` has paid, how far ``progress`` got) starts afresh at every ``reset``.
"""

from __future__ import annotations

import os
from collections.abc import Sequence

import gymnasium as gym
import numpy as np

from armtransfer.errors import InvalidParameterError, InvalidTrajectoryError
from armtransfer.learning import methods as registry
from armtransfer.learning import trajectory as trajectories
from armtransfer.learning.config import LearnerConfig
from armtransfer.learning.sarsa import _shaping
from armtransfer.learning.shaping import MODE_NONE
from armtransfer.learning.trajectory import Trajectory

TrajectoryLike = Trajectory | str | os.PathLike


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
        base = env.unwrapped
        missing = [a for a in ("robot", "step_reward", "goal_cell") if not hasattr(base, a)]
        if missing:
            raise InvalidParameterError(
                f"TransferReward needs one of armtransfer's environments (no {', '.join(missing)} on "
                f"{type(base).__name__})")
        m = registry.get(method)
        if m.name not in registry.REWARD_ONLY:
            why = "adds no reward" if not m.shaped else "changes how the learner chooses actions, not a reward"
            raise InvalidParameterError(f"method {method!r} {why}; valid methods: {', '.join(registry.REWARD_ONLY)}")
        if not (isinstance(gamma, (int, float)) and 0.0 <= gamma <= 1.0):
            raise InvalidParameterError(f"gamma must be in [0, 1], got {gamma!r}")
        self.robot = base.robot
        self.trajectories = [self._load(t) for t in _as_list(trajectory)]
        self.method = m.name
        self.gamma = float(gamma)
        self.shaping = registry.build_shaping(m.name, self.robot, self.trajectories, K, base.step_reward, beta=beta,
                                              gamma=self.gamma)
        self.goal_cell = int(base.goal_cell)
        n_ids = int(self.shaping.traj_index.max()) + 1 if len(self.shaping.traj_index) else 1
        self._paid = np.full(max(n_ids, 1), -1, np.int64)
        self._episode = -1
        self._best = 0.0
        self._state: int | None = None

    def _load(self, t: TrajectoryLike) -> Trajectory:
        traj = t if isinstance(t, Trajectory) else trajectories.load(t)
        n_cells = self.robot.layout.n_cells
        if any(not 0 <= c < n_cells for c in (*traj.cells, traj.goal)):
            raise InvalidTrajectoryError(f"the trajectory names cells outside this robot's layout (0..{n_cells - 1})")
        return traj

    @property
    def K(self) -> float:
        return self.shaping.K

    def reset(self, **kwargs):
        obs, info = self.env.reset(**kwargs)
        self._episode += 1
        self._best = 0.0
        self._state = int(obs)
        return obs, info

    def step(self, action):
        if self._state is None:
            raise InvalidParameterError("call reset() before step()")
        obs, reward, terminated, truncated, info = self.env.step(action)
        s, s2 = self._state, int(obs)
        term = 0.0
        if self.shaping.mode != MODE_NONE:
            sh = self.shaping
            term, self._best = _shaping(sh.mode, s, s2, bool(terminated), sh.bonus, sh.traj_index, sh.phi,
                                        self.gamma, self._paid, self._episode, self._best)
        self._state = s2
        info = dict(info, shaping=float(term))
        return obs, reward + term, terminated, truncated, info


def _as_list(trajectory) -> list:
    if isinstance(trajectory, (Trajectory, str, os.PathLike)):
        return [trajectory]
    out = list(trajectory)
    if not out:
        raise InvalidParameterError("TransferReward needs at least one trajectory")
    return out
