"""Gymnasium entry point of ``armtransfer/ArmRooms-v0``: an arm robot on a rooms task.

``gymnasium.make("armtransfer/ArmRooms-v0", arm="planar2", actions="joint", task=1)``
(after ``import tasks``). Observations are the robot's own state indices; see
``tasks.envs.RobotRoomsEnv``.
"""

from __future__ import annotations

from typing import Any

from ik.robots import arm_robot, parse_robot_spec
from tasks.catalog import custom_task, table_task
from tasks.envs import RobotRoomsEnv

_ROBOT_OPTIONS = ("cell_size", "xml_path", "tip_site", "base_pos", "base_yaw", "joint_step",
                  "cache")


def make_arm_rooms_env(arm: str = "planar2", actions: str = "joint", task: int | None = 1,
                       start: tuple[int, int] | None = None,
                       goal: tuple[int, int] | None = None, **kwargs: Any) -> RobotRoomsEnv:
    robot_kwargs = {k: kwargs.pop(k) for k in _ROBOT_OPTIONS if k in kwargs}
    if robot_kwargs.get("xml_path") is None:
        arm, actions = parse_robot_spec(f"{arm}:{actions}")
    the_task = custom_task(start, goal) if start is not None and goal is not None else table_task(task)
    return RobotRoomsEnv(arm_robot(arm, actions, **robot_kwargs), the_task, **kwargs)
