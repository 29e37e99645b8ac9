"""Robot specs as users type them: grid robots by name, arms as ``ARM:ACTIONS``."""

from __future__ import annotations

from armtransfer.errors import UnknownRobotError
from armtransfer.tasks.grid_robots import GRID_ROBOTS, grid_robot
from armtransfer.tasks.robot import DiscreteRobot


def resolve(spec: str, **arm_options) -> DiscreteRobot:
    """``fine`` / ``coarse`` -> grid robot; ``ARM:ACTIONS`` (e.g. ``planar2:joint``) -> arm robot."""
    if spec in GRID_ROBOTS:
        return grid_robot(spec)
    if ":" in spec or arm_options.get("xml_path"):
        from armtransfer.tasks.arms import arm_robot, parse_robot_spec

        arm, actions = parse_robot_spec(spec)
        return arm_robot(arm, actions, **arm_options)
    raise UnknownRobotError(
        f"unknown robot {spec!r}; valid: {', '.join(sorted(GRID_ROBOTS))} or ARM:ACTIONS "
        "(see `armtransfer arms list`)"
    )
