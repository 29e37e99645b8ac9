"""Gymnasium environments pass check_env and are deterministic under reset(seed=...)."""

import gymnasium as gym
import pytest
from gymnasium.utils.env_checker import check_env

import armtransfer  # noqa: F401  (registers the environments)



@pytest.mark.parametrize("robot", ["fine", "coarse"])
@pytest.mark.parametrize("task", [1, 4])
def test_rooms_env_passes_check_env(robot, task):
    env = gym.make("armtransfer/Rooms-v0", task=task, robot=robot, wind=0.01)
    check_env(env.unwrapped, skip_render_check=False)
    env.close()


def test_rooms_env_reaches_the_goal_along_the_shortest_path():
    env = gym.make("armtransfer/Rooms-v0", task=1, robot="fine")
    base = env.unwrapped
    obs, info = env.reset(seed=0)
    path = base.robot.shortest_path(obs, base.goal_cell)
    total = 0.0
    for _, action in path[:-1]:
        obs, reward, terminated, truncated, info = env.step(action)
        total += reward
    assert terminated and info["label"] == base.goal_cell
    assert total == -20.0


def test_wind_is_reproducible_from_the_reset_seed():
    def rollout(seed):
        env = gym.make("armtransfer/Rooms-v0", task=1, robot="fine", wind=0.5)
        env.reset(seed=seed)
        return [env.step(2)[0] for _ in range(20)]

    assert rollout(3) == rollout(3)
    assert rollout(3) != rollout(4)


def test_rooms_rgb_array_shows_the_robot_and_goal():
    import numpy as np

    env = gym.make("armtransfer/Rooms-v0", task=1, robot="fine", render_mode="rgb_array")
    check_env(env.unwrapped, skip_render_check=False)
    env.reset(seed=0)
    image = env.render()
    assert image.dtype == np.uint8 and image.shape == (51 * 6, 51 * 6, 3)
    blue = np.all(image == (40, 90, 230), axis=-1)
    green = np.all(image == (30, 190, 50), axis=-1)
    assert blue.sum() == 36 and green.sum() == 36  # one cell each, 6 x 6 pixels
    # the robot starts at (0, 0): column 25 from the left, row 25 from the top
    assert blue[25 * 6 + 3, 25 * 6 + 3]
    env.step(0)  # F: +y, one row up in the picture
    assert np.all(env.render()[24 * 6 + 3, 25 * 6 + 3] == (40, 90, 230))


@pytest.mark.parametrize("imports", ["import gymnasium as gym, armtransfer",
                                     "import armtransfer, sys; assert 'gymnasium' not in sys.modules; "
                                     "import gymnasium as gym"])
def test_importing_armtransfer_registers_the_environments(imports):
    """As in Gymnasium's ecosystem: the import alone registers, in a fresh process, in either
    order (imported first, armtransfer waits for Gymnasium rather than loading it)."""
    import subprocess
    import sys

    code = (f"{imports}\n"
            "env = gym.make('armtransfer/Rooms-v0', task=1, robot='fine')\n"
            "print(env.spec.id, type(env.unwrapped).__name__, env.unwrapped.robot.name, env.spec.max_episode_steps)\n")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert proc.stdout.split() == ["armtransfer/Rooms-v0", "RobotRoomsEnv", "fine", "100000"]
