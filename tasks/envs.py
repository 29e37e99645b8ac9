"""Gymnasium environments over any discrete robot (rooms-world grid robots and arms).

``armtransfer.register_envs()`` registers ``armtransfer/Rooms-v0`` (a grid robot) and
``armtransfer/ArmRooms-v0`` (an arm robot); then ``gymnasium.make("armtransfer/Rooms-v0",
task=1, robot="fine")``. Registering is explicit: importing never registers. The observation is the robot's
own state index, the action an index into its action model; each step costs
``step_reward`` and reaching the goal cell pays ``goal_reward`` and terminates. With
``wind=p`` the robot is pushed one cell towards +x with probability p after its move.
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
from gymnasium import spaces

from armtransfer.tasks.catalog import Task, custom_task, table_task
from armtransfer.errors import InvalidParameterError
from armtransfer.tasks.robot import DiscreteRobot


class RobotRoomsEnv(gym.Env):
    """A start/goal task for one discrete robot, in the style of Gymnasium's toy_text."""

    metadata = {"render_modes": ["ansi"], "render_fps": 4}

    def __init__(
        self,
        robot: DiscreteRobot,
        task: Task,
        wind: float = 0.0,
        step_reward: float = -1.0,
        goal_reward: float = 0.0,
        render_mode: str | None = None,
    ) -> None:
        if not 0.0 <= wind <= 1.0:
            raise InvalidParameterError(f"wind must be a probability in [0, 1], got {wind}")
        self.robot = robot
        self.task = task
        start_cell, self.goal_cell = task.cells()
        self.start_state = robot.start_state(start_cell)
        robot.start_state(self.goal_cell, what="goal")  # the goal must be reachable by label
        self.wind = float(wind)
        self.step_reward = float(step_reward)
        self.goal_reward = float(goal_reward)
        self.render_mode = render_mode
        self.observation_space = spaces.Discrete(robot.n_states)
        self.action_space = spaces.Discrete(robot.n_actions)
        self.state = self.start_state

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None):
        super().reset(seed=seed)
        self.state = self.start_state
        return int(self.state), {"label": int(self.robot.label[self.state])}

    def step(self, action):
        s = int(self.robot.next_state[self.state, int(action)])
        if self.wind > 0.0 and self.np_random.random() < self.wind:
            s = int(self.robot.wind_state[s])
        self.state = s
        label = int(self.robot.label[s])
        terminated = label == self.goal_cell
        reward = self.step_reward + (self.goal_reward if terminated else 0.0)
        return s, reward, terminated, False, {"label": label}

    def render(self):
        if self.render_mode == "ansi":
            from armtransfer.tasks.layout import ROOMS

            x, y = ROOMS.xy(int(self.robot.label[self.state]))
            gx, gy = ROOMS.xy(self.goal_cell)
            return ROOMS.ascii({(x, y): "R", (gx, gy): "G"}) + "\n"
        return None


def make_rooms_env(
    task: int | None = 1,
    robot: str = "fine",
    start: tuple[int, int] | None = None,
    goal: tuple[int, int] | None = None,
    **kwargs: Any,
) -> RobotRoomsEnv:
    """Entry point of ``armtransfer/Rooms-v0``: a grid robot on a Table I or custom task."""
    from armtransfer.tasks.grid_robots import grid_robot

    the_task = custom_task(start, goal) if start is not None and goal is not None else table_task(task)
    return RobotRoomsEnv(grid_robot(robot), the_task, **kwargs)


_ARM_OPTIONS = ("cell_size", "xml_path", "tip_site", "base_pos", "base_yaw", "joint_step", "cache")


def make_arm_rooms_env(arm: str = "planar2", actions: str = "joint", task: int | None = 1,
                       start: tuple[int, int] | None = None,
                       goal: tuple[int, int] | None = None, **kwargs: Any) -> RobotRoomsEnv:
    """Entry point of ``armtransfer/ArmRooms-v0``: an arm robot (compiled or loaded from the
    cache) on a Table I or custom task. Bring-your-own arms: ``xml_path=`` and ``tip_site=``."""
    from armtransfer.tasks.arms import arm_robot, parse_robot_spec

    robot_kwargs = {k: kwargs.pop(k) for k in _ARM_OPTIONS if k in kwargs}
    if robot_kwargs.get("xml_path") is None:
        arm, actions = parse_robot_spec(f"{arm}:{actions}")
    the_task = custom_task(start, goal) if start is not None and goal is not None else table_task(task)
    return RobotRoomsEnv(arm_robot(arm, actions, **robot_kwargs), the_task, **kwargs)


def register_envs() -> None:
    """Register this project's environments with Gymnasium (idempotent)."""
    if "armtransfer/Rooms-v0" not in gym.registry:
        gym.register(
            id="armtransfer/Rooms-v0",
            entry_point="armtransfer.tasks.envs:make_rooms_env",
            max_episode_steps=100_000,
        )
    if "armtransfer/ArmRooms-v0" not in gym.registry:
        gym.register(
            id="armtransfer/ArmRooms-v0",
            entry_point="armtransfer.tasks.envs:make_arm_rooms_env",
            max_episode_steps=100_000,
        )
