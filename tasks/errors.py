"""Errors raised for bad user input. Each message is one line that names the problem."""


class ArmTransferError(Exception):
    """Base class: the CLI turns any of these into a one-line message and exit code 2."""


class InvalidCellError(ArmTransferError):
    """A cell is off the grid or inside a wall."""


class InvalidTaskError(ArmTransferError):
    """A task is unknown or malformed (e.g. start equals goal)."""


class UnknownRobotError(ArmTransferError):
    """A robot or action model name is not known."""


class InvalidTrajectoryError(ArmTransferError):
    """A transferred trajectory is malformed or names cells off the grid."""


class InvalidParameterError(ArmTransferError):
    """A learning parameter is out of range (e.g. a farmable K, non-positive trials)."""


class InvalidMappingError(ArmTransferError):
    """An action sequence mapping file is malformed or made for another robot pair."""
