"""stable-baselines3's DQN and PPO as learners of the benchmark, for small discrete worlds.

``make_dqn(env, seed)`` and ``make_ppo(env, seed)`` build the SB3 model on ``env`` on the CPU
(``device="cpu"``, ``verbose=0``, torch on one thread) and return an :class:`SB3Model`, which
is what the benchmark's harness drives: ``learn(n)`` goes on learning ``n`` more environment
steps (``reset_num_timesteps=False``), ``predict(obs, deterministic=True)`` is SB3's.

Nothing here imports torch or stable-baselines3 until a model is made, so ``import
armtransfer`` and the learners' entry points stay light; where they are not installed,
making a model is a one-line :class:`~armtransfer.errors.MissingExtraError` naming the
extra to install (``pip install 'armtransfer[sb3]'``, torch first from its CPU index on a
machine without a GPU: docs/benchmark.md).

**Settings** (chosen on the dev cases only, rooms11 task 3 coarse -> fine, source seeds
100 and 101; every variant tried is in docs/research-log.md):

- observations are the robot's state index (``Discrete``), which SB3 one-hot encodes, so
  the networks are small MLPs over a one-hot state;
- DQN's exploration rate falls linearly from 1 to :data:`DQN_FINAL_EPS` over the model's
  first :data:`DQN_EXPLORATION_STEPS` environment steps, counted by the model itself. SB3's
  own schedule runs over the ``total_timesteps`` of each ``learn`` call, so under the
  harness's many small calls it would decay afresh inside every chunk;
- PPO collects :data:`PPO_N_STEPS` steps per update, so ``learn(n)`` may step up to
  ``PPO_N_STEPS - 1`` steps beyond ``n`` (SB3 finishes a rollout); the harness counts every
  step itself.

**Determinism**: SB3 draws from the global ``random``, ``numpy.random`` and torch generators.
An :class:`SB3Model` keeps its own copy of the three states and swaps it in for each
``learn`` (under a lock), so the same seed gives the same actions however models of one
process interleave their learning.
"""

from __future__ import annotations

import importlib.util
import random
import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any

import numpy as np

from armtransfer.errors import MissingExtraError
from armtransfer.learning.learners import Learner

EXTRA = "sb3"
"""The extra that installs stable-baselines3 and torch."""

INSTALL = (f"pip install 'armtransfer[{EXTRA}]' (on a CPU-only machine install torch first: "
           "pip install torch --index-url https://download.pytorch.org/whl/cpu)")

DQN_KWARGS: dict[str, Any] = {
    "learning_rate": 1e-3, "buffer_size": 50_000, "learning_starts": 500, "batch_size": 64, "gamma": 0.99,
    "train_freq": 4, "gradient_steps": 1, "target_update_interval": 500,
    "policy_kwargs": {"net_arch": [64, 64]},
}
"""DQN's settings beside its exploration (SB3's defaults otherwise)."""

DQN_EXPLORATION_STEPS = 10_000
"""Steps over which DQN's exploration rate falls from 1 to its final value."""

DQN_FINAL_EPS = 0.05

PPO_N_STEPS = 256

PPO_KWARGS: dict[str, Any] = {
    "learning_rate": 1e-3, "n_steps": PPO_N_STEPS, "batch_size": 64, "n_epochs": 4, "gamma": 0.99,
    "gae_lambda": 0.95, "ent_coef": 0.01, "policy_kwargs": {"net_arch": [64, 64]},
}
"""PPO's settings (SB3's defaults otherwise)."""

ORIGIN = "armtransfer (the sb3 extra)"

_RNG_LOCK = threading.Lock()


def available() -> bool:
    """Whether stable-baselines3 and torch are installed (found, not imported)."""
    return all(importlib.util.find_spec(m) is not None for m in ("stable_baselines3", "torch"))


def _require(name: str) -> None:
    if not available():
        raise MissingExtraError(f"learner {name!r} needs stable-baselines3 and torch, not installed here: {INSTALL}")


def _global_states() -> tuple[Any, Any, Any]:
    import torch  # the sb3 extra: only when its learners run

    return random.getstate(), np.random.get_state(), torch.get_rng_state()


def _set_global_states(states: tuple[Any, Any, Any]) -> None:
    import torch  # the sb3 extra: only when its learners run

    random.setstate(states[0])
    np.random.set_state(states[1])
    torch.set_rng_state(states[2])


class SB3Model:
    """An SB3 model as the benchmark's :class:`~armtransfer.learning.learners.Model`: learns on,
    predicts, with its own random states."""

    def __init__(self, build: Callable[[], Any]) -> None:
        self._states: tuple[Any, Any, Any] | None = None
        with self._own_generators(fresh=True):
            self.algorithm = build()

    @contextmanager
    def _own_generators(self, fresh: bool = False) -> Iterator[None]:
        import torch  # the sb3 extra: only when its learners run

        with _RNG_LOCK:
            outer = _global_states()
            threads = torch.get_num_threads()
            torch.set_num_threads(1)
            try:
                if not fresh:
                    assert self._states is not None
                    _set_global_states(self._states)
                yield
                self._states = _global_states()
            finally:
                _set_global_states(outer)
                torch.set_num_threads(threads)

    @property
    def num_timesteps(self) -> int:
        """Environment steps learned so far."""
        return int(self.algorithm.num_timesteps)

    def learn(self, total_timesteps: int) -> SB3Model:
        """Learn ``total_timesteps`` more environment steps (PPO: rounded up to whole rollouts)."""
        with self._own_generators():
            self.algorithm.learn(int(total_timesteps), reset_num_timesteps=False, progress_bar=False)
        return self

    def predict(self, observation: Any, deterministic: bool = True) -> tuple[Any, Any]:
        with self._own_generators():
            return self.algorithm.predict(observation, deterministic=deterministic)


def _linear_exploration(algorithm: Any) -> Callable[[float], float]:
    """Epsilon from the model's own step count (SB3's progress argument is ignored)."""

    def rate(_progress_remaining: float) -> float:
        done = min(algorithm.num_timesteps / DQN_EXPLORATION_STEPS, 1.0)
        return 1.0 + done * (DQN_FINAL_EPS - 1.0)

    return rate


def make_dqn(env: Any, seed: int) -> SB3Model:
    """SB3's DQN on ``env`` (CPU, seeded by ``seed``), settings :data:`DQN_KWARGS`."""
    _require("dqn")

    def build() -> Any:
        from stable_baselines3 import DQN  # the sb3 extra

        algorithm = DQN("MlpPolicy", env, seed=int(seed), device="cpu", verbose=0, exploration_initial_eps=1.0,
                        exploration_final_eps=DQN_FINAL_EPS, **DQN_KWARGS)
        algorithm.exploration_schedule = _linear_exploration(algorithm)
        return algorithm

    return SB3Model(build)


def make_ppo(env: Any, seed: int) -> SB3Model:
    """SB3's PPO on ``env`` (CPU, seeded by ``seed``), settings :data:`PPO_KWARGS`."""
    _require("ppo")

    def build() -> Any:
        from stable_baselines3 import PPO  # the sb3 extra

        return PPO("MlpPolicy", env, seed=int(seed), device="cpu", verbose=0, **PPO_KWARGS)

    return SB3Model(build)


_NOTE = "" if available() else f" (unavailable here: {INSTALL})"

DQN = Learner("dqn", f"stable-baselines3 DQN on the CPU: an MLP (64, 64) over the one-hot state, epsilon 1 -> "
                     f"{DQN_FINAL_EPS} over {DQN_EXPLORATION_STEPS:,} steps{_NOTE}", make_dqn, origin=ORIGIN)
"""The ``dqn`` learner (entry point ``dqn`` of ``armtransfer.learners``)."""

PPO = Learner("ppo", f"stable-baselines3 PPO on the CPU: an MLP (64, 64) over the one-hot state, rollouts of "
                     f"{PPO_N_STEPS} steps{_NOTE}", make_ppo, origin=ORIGIN)
"""The ``ppo`` learner (entry point ``ppo`` of ``armtransfer.learners``)."""
