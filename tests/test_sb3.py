"""The stable-baselines3 learners (armtransfer.learning.sb3): the Model protocol, determinism on
the CPU, the missing extra in one line, and torch kept out of ``import armtransfer``.

The tests that train need the ``sb3`` extra (stable-baselines3 and torch), which the default
test environment does not install: they skip, saying so, where it is absent."""

from __future__ import annotations

import subprocess
import sys

import gymnasium as gym
import numpy as np
import pytest

import armtransfer  # noqa: F401  (registers the environments)
from armtransfer.errors import ArmTransferError, MissingExtraError
from armtransfer.learning import sb3

needs_sb3 = pytest.mark.skipif(not sb3.available(), reason="the sb3 extra (stable-baselines3, torch) is not "
                                                         "installed: pip install 'armtransfer[sb3]'")
MAKERS = {"dqn": sb3.make_dqn, "ppo": sb3.make_ppo}


def env(seed: int = 0) -> gym.Env:
    e = gym.make("armtransfer/Rooms-v0", world="rooms11", task=1, robot="fine")
    e.reset(seed=seed)
    return e


class Steps(gym.Wrapper):
    def __init__(self, inner: gym.Env) -> None:
        super().__init__(inner)
        self.n = 0
        self.actions: list[int] = []

    def step(self, action):
        self.n += 1
        self.actions.append(int(action))
        return self.env.step(action)


def test_import_armtransfer_and_the_adapters_never_import_torch():
    code = ("import sys, armtransfer, armtransfer.learning.sb3 as s; "
            "print('torch' in sys.modules, 'stable_baselines3' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120, check=True)
    assert out.stdout.split() == ["False", "False"]


@pytest.mark.parametrize("name", sorted(MAKERS))
def test_without_the_extra_making_a_model_is_one_line_naming_it(monkeypatch, name):
    monkeypatch.setattr(sb3, "available", lambda: False)
    with pytest.raises(MissingExtraError) as err:
        MAKERS[name](env(), 0)
    message = str(err.value)
    assert isinstance(err.value, ArmTransferError) and "\n" not in message
    assert f"learner {name!r}" in message and "armtransfer[sb3]" in message


@needs_sb3
@pytest.mark.parametrize("name", sorted(MAKERS))
def test_a_model_learns_on_and_predicts_actions_of_the_env(name):
    e = Steps(env())
    model = MAKERS[name](e, 3)
    assert callable(model.learn) and callable(model.predict)
    model.learn(100)
    first = e.n
    assert first >= 100 and model.num_timesteps == first
    model.learn(100)  # goes on: steps add up, not restart
    assert e.n >= first + 100 and model.num_timesteps == e.n
    action, state = model.predict(0, deterministic=True)
    assert e.action_space.contains(int(action)) and state is None


@needs_sb3
@pytest.mark.parametrize("name", sorted(MAKERS))
def test_same_seed_same_actions_however_models_interleave(name):
    def greedy(model) -> list[int]:
        return [int(model.predict(s, deterministic=True)[0]) for s in range(0, 121, 7)]

    a_env, b_env, c_env = Steps(env()), Steps(env()), Steps(env())
    a, b, c = MAKERS[name](a_env, 11), MAKERS[name](b_env, 11), MAKERS[name](c_env, 12)
    a.learn(600)
    np.random.seed(123)  # the global generators are not the models'
    b.learn(300)
    c.learn(300)
    b.learn(300)
    c.learn(300)
    assert a_env.actions == b_env.actions
    assert greedy(a) == greedy(b)
    assert a_env.actions != c_env.actions  # another seed, other actions: the check can fail
