"""Knowledge transfer for any Gymnasium learner: a reward wrapper over the project's envs.

    import gymnasium as gym
    import armtransfer
    from armtransfer.wrappers import TransferReward

    env = gym.make("armtransfer/Rooms-v0", task=1, robot="fine")
    env = TransferReward(env, "trajectory.json", method="pseudo", K="auto")

The wrapper is defined in ``armtransfer.learning.transfer_reward`` (below the experiments, so
that the benchmark's harness of outside learners wraps its environments in it too); this is
its public name.
"""

from __future__ import annotations

from armtransfer.learning.transfer_reward import TransferReward

__all__ = ["TransferReward"]
