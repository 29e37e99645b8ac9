"""``tabular-q``: one-step Q-learning over the environment's discrete states, in numpy.

The model the benchmark's harness asks for: ``learn(n)`` goes on for n more environment steps
(epsilon-greedy, ties broken at random), ``predict(obs)`` returns the greedy action. Every random
draw comes from its own ``numpy.random.Generator`` seeded by ``make``'s seed. Q starts at 0, so
with a negative step reward every untried action looks better than a tried one.
"""

from __future__ import annotations

import numpy as np

import armtransfer


class TabularQ:
    def __init__(self, env, seed: int, alpha: float = 0.5, gamma: float = 0.99, epsilon: float = 0.1) -> None:
        self.env = env
        self.rng = np.random.default_rng(seed)
        self.q = np.zeros((env.observation_space.n, env.action_space.n))
        self.alpha, self.gamma, self.epsilon = alpha, gamma, epsilon
        self.obs: int | None = None

    def _greedy(self, s: int) -> int:
        row = self.q[s]
        return int(self.rng.choice(np.flatnonzero(row == row.max())))

    def learn(self, total_timesteps: int) -> "TabularQ":
        for _ in range(int(total_timesteps)):
            if self.obs is None:
                self.obs, _ = self.env.reset()
            s = int(self.obs)
            explore = self.rng.random() < self.epsilon
            a = int(self.rng.integers(self.q.shape[1])) if explore else self._greedy(s)
            obs, reward, terminated, truncated, _ = self.env.step(a)
            target = reward + (0.0 if terminated else self.gamma * self.q[int(obs)].max())
            self.q[s, a] += self.alpha * (target - self.q[s, a])
            self.obs = None if terminated or truncated else obs
        return self

    def predict(self, observation, deterministic: bool = True):
        row = self.q[int(observation)]
        return int(np.argmax(row)), None  # the first best action: the same answer every time


TABULAR_Q = armtransfer.Learner(
    "tabular-q", "example plugin: one-step Q-learning in a numpy table, epsilon 0.1, alpha 0.5",
    lambda env, seed: TabularQ(env, seed))
