"""The rooms world, the shared workspace cells, discrete robots and start/goal tasks."""

from armtransfer.tasks.catalog import TABLE_I, Task, custom_task, table_task
from armtransfer.tasks.grid_robots import grid_robot
from armtransfer.worlds.layout import ROOMS, Layout
from armtransfer.tasks.robot import DiscreteRobot

__all__ = ["ROOMS", "TABLE_I", "DiscreteRobot", "Layout", "Task", "custom_task", "grid_robot", "table_task"]
