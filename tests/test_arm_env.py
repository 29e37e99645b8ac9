"""armtransfer/ArmRooms-v0: a Gymnasium environment per arm robot."""

import gymnasium as gym
import pytest
from gymnasium.utils.env_checker import check_env

import numpy as np

from armtransfer.errors import ArmTransferError
import armtransfer  # noqa: F401  (registers the environments)



@pytest.mark.parametrize("arm, actions", [("planar2", "joint"), ("ur5e_like", "cartesian")])
def test_arm_env_passes_check_env_and_reaches_the_goal(arm, actions):
    env = gym.make("armtransfer/ArmRooms-v0", arm=arm, actions=actions, task=1)
    check_env(env.unwrapped, skip_render_check=True)
    robot = env.unwrapped.robot
    assert robot.name == f"{arm}:{actions}"
    obs, info = env.reset(seed=0)
    path = robot.shortest_path(obs, env.unwrapped.goal_cell)
    terminated = False
    for _, action in path[:-1]:
        obs, reward, terminated, truncated, info = env.step(action)
    assert terminated and info["label"] == env.unwrapped.goal_cell
    env.close()


def test_arm_env_takes_custom_tasks_and_wind():
    env = gym.make("armtransfer/ArmRooms-v0", arm="planar2", actions="joint", start=(12, 12),
                   goal=(-8, 12), wind=0.2)
    obs, _ = env.reset(seed=1)
    for _ in range(20):
        obs, *_ = env.step(env.action_space.sample())
    assert env.observation_space.contains(obs)


def test_unknown_arm_is_a_one_line_error():
    with pytest.raises(ArmTransferError, match="valid arms"):
        gym.make("armtransfer/ArmRooms-v0", arm="puma", actions="joint")


@pytest.mark.rendering
@pytest.mark.parametrize("arm, actions", [("planar2", "joint"), ("ur5e_like", "cartesian")])
def test_rgb_array_draws_the_arm_and_passes_check_env(arm, actions):
    env = gym.make("armtransfer/ArmRooms-v0", arm=arm, actions=actions, task=1, render_mode="rgb_array")
    check_env(env.unwrapped, skip_render_check=False)
    obs, _ = env.reset(seed=0)
    first = env.render()
    assert first.dtype == np.uint8 and first.shape == (240, 320, 3)
    assert first.std() > 10  # not a blank frame
    robot = env.unwrapped.robot
    path = robot.shortest_path(obs, env.unwrapped.goal_cell)
    for _, action in path[:-1]:
        env.step(action)
    last = env.render()
    changed = np.any(np.abs(first.astype(int) - last.astype(int)) > 30, axis=-1)
    assert changed.mean() > 0.002  # the arm (and the tip's tile) moved across the picture
    env.close()
    assert env.unwrapped._snapshot is None


def test_unknown_render_mode_is_refused():
    with pytest.raises(ArmTransferError, match="unknown render_mode 'human'; valid: ansi, rgb_array"):
        gym.make("armtransfer/ArmRooms-v0", arm="planar2", actions="joint", render_mode="human")
