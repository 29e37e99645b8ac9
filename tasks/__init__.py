"""The rooms world, the shared workspace cells, discrete robots and start/goal tasks."""

from tasks.catalog import TABLE_I, Task, custom_task, table_task
from tasks.errors import (
    ArmTransferError,
    InvalidCellError,
    InvalidParameterError,
    InvalidTaskError,
    InvalidTrajectoryError,
    UnknownRobotError,
)
from tasks.grid_robots import grid_robot
from tasks.layout import ROOMS, Layout
from tasks.robot import DiscreteRobot

__all__ = [
    "ROOMS",
    "TABLE_I",
    "ArmTransferError",
    "DiscreteRobot",
    "InvalidCellError",
    "InvalidParameterError",
    "InvalidTaskError",
    "InvalidTrajectoryError",
    "Layout",
    "Task",
    "UnknownRobotError",
    "custom_task",
    "grid_robot",
    "table_task",
]

from tasks.envs import register_envs as _register_envs

_register_envs()
