"""TransferReward: any Gymnasium agent on the wrapped env gets exactly the kernel's rewards.

The check that matters: a plain Python SARSA(lambda) written here, stepping the wrapped
environment and drawing from the same generator as the compiled learner, ends with a Q
table bit-identical to the kernel's with the same method's shaping. Any reward of the
wrapper that differs from the kernel's, on any transition of any episode, would change Q.
"""

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

from armtransfer.errors import ArmTransferError
from armtransfer.io import write_json_atomic
from armtransfer.learning import methods as registry
from armtransfer.learning import sarsa
from armtransfer.learning import trajectory as trajectories
from armtransfer.learning.config import LearnerConfig
from armtransfer.tasks.catalog import table_task
import armtransfer  # noqa: F401  (registers the environments)
from armtransfer.tasks.grid_robots import grid_robot
from armtransfer.wrappers import TransferReward

SHAPED = list(registry.REWARD_ONLY)


def _egreedy(Q, s, eps, rng):
    """The kernel's epsilon-greedy, draw for draw (sarsa.py's module docstring)."""
    n = Q.shape[1]
    if rng.random() < eps:
        return int(rng.random() * n)
    best = Q[s].max()
    ties = np.flatnonzero(Q[s] == best)
    if len(ties) == 1:
        return int(ties[0])
    return int(ties[int(rng.random() * len(ties))])


def sarsa_on_env(env, episodes, config, rng):
    """Algorithm 1 with dense traces, learning from whatever rewards ``env`` gives."""
    n_s, n_a = env.observation_space.n, env.action_space.n
    Q = np.zeros((n_s, n_a))
    steps = []
    for _ in range(episodes):
        E = np.zeros_like(Q)
        s, _ = env.reset()
        a = _egreedy(Q, s, config.epsilon, rng)
        n = 0
        while True:
            s2, r, terminated, truncated, _ = env.step(a)
            n += 1
            if terminated:
                q_next, a2 = 0.0, 0
            else:
                a2 = _egreedy(Q, s2, config.epsilon, rng)
                q_next = Q[s2, a2]
            delta = r + config.gamma * q_next - Q[s, a]
            E[s, a] += 1.0
            Q += config.alpha * delta * E
            E *= config.gamma * config.lam
            s, a = s2, a2
            if terminated:
                break
            assert not truncated
        steps.append(n)
    return Q, steps


@pytest.fixture(scope="module")
def traj():
    coarse = grid_robot("coarse")
    start, goal = table_task(1).cells()
    return trajectories.shortest(coarse, start, goal)


@pytest.mark.parametrize("method", SHAPED)
def test_sarsa_on_the_wrapped_env_is_bit_identical_to_the_kernel(method, traj):
    config = LearnerConfig(trace_cutoff=0.0, max_episodes=4, patience=100)
    env = TransferReward(gym.make("armtransfer/Rooms-v0", task=1, robot="fine", max_episode_steps=10**7),
                         traj, method=method, gamma=config.gamma)
    Q, steps = sarsa_on_env(env, 4, config, np.random.default_rng(7))
    fine = grid_robot("fine")
    start, goal = table_task(1).cells()
    shaping = registry.build_shaping(method, fine, [traj], "auto", config.step_reward)
    res = sarsa.learn(fine, fine.start_state(start), goal, config, np.random.default_rng(7), shaping=shaping,
                      keep_q=True)
    assert res.episodes == 4
    assert list(res.episode_steps) == steps
    assert np.array_equal(res.Q, Q)
    assert env.K == shaping.K


@pytest.mark.parametrize("method", ["first-visit", "progress"])
def test_per_episode_state_starts_afresh_at_reset_and_first_visit_pays_once(method, traj):
    env = TransferReward(gym.make("armtransfer/Rooms-v0", task=1, robot="fine"), traj, method=method, K=1.0)
    paid = []
    for _ in range(2):
        env.reset(seed=0)
        total = 0.0
        for a in [0] * 12:  # forward along x = 0: the first trajectory cells of task 1
            _, _, _, _, info = env.step(a)
            total += info["shaping"]
        paid.append(total)
    assert paid[0] > 0
    assert paid[1] == (0.0 if method == "first-visit" else paid[0])  # first-visit: once per trial


def test_reward_is_the_env_reward_plus_the_shaping_term(traj):
    env = TransferReward(gym.make("armtransfer/Rooms-v0", task=1, robot="fine"), traj, method="pseudo", K=0.01)
    env.reset(seed=0)
    seen = set()
    for a in [0, 0, 0, 3, 3, 2]:
        _, r, _, _, info = env.step(a)
        assert r == pytest.approx(-1.0 + info["shaping"])
        seen.add(info["shaping"])
    assert len(seen) > 1  # some moves paid a bonus, some did not


def test_wrapped_env_passes_check_env(traj):
    env = TransferReward(gym.make("armtransfer/Rooms-v0", task=1, robot="fine", wind=0.01), traj, method="dense")
    with pytest.warns(UserWarning, match="different from the unwrapped"):  # check_env's note on any wrapper
        check_env(env, skip_render_check=True)
    assert env.spec.additional_wrappers[-1].name == "TransferReward"


def test_trajectory_files_and_several_trajectories(tmp_path, traj):
    path = tmp_path / "t.json"
    write_json_atomic(path, traj.to_json())
    a = TransferReward(gym.make("armtransfer/Rooms-v0", task=1, robot="fine"), str(path), method="pseudo", K=0.01)
    b = TransferReward(gym.make("armtransfer/Rooms-v0", task=1, robot="fine"), [traj, traj], method="pseudo",
                       K=0.01)
    assert np.array_equal(a.shaping.bonus, b.shaping.bonus)


@pytest.mark.parametrize("kwargs,message", [
    (dict(method="nope"), "unknown method 'nope'; valid methods:"),
    (dict(method="none"), "adds no reward; valid methods: pseudo"),
    (dict(method="guided"), "changes how the learner chooses actions"),
    (dict(K=5.0), "can be farmed"),
    (dict(gamma=2.0), "gamma must be in [0, 1]"),
])
def test_bad_wrapper_input_is_a_one_line_error(kwargs, message, traj):
    with pytest.raises(ArmTransferError) as err:
        TransferReward(gym.make("armtransfer/Rooms-v0", task=1, robot="fine"), traj, **kwargs)
    assert message in str(err.value) and "\n" not in str(err.value)


def test_a_foreign_env_is_refused(traj):
    with pytest.raises(ArmTransferError, match="needs one of armtransfer's environments"):
        TransferReward(gym.make("CliffWalking-v1"), traj)
