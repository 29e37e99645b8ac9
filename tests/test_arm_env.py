"""armtransfer/ArmRooms-v0: a Gymnasium environment per arm robot."""

import gymnasium as gym
import pytest
from gymnasium.utils.env_checker import check_env

from armtransfer.tasks.envs import register_envs

register_envs()
from armtransfer.errors import ArmTransferError


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
