"""Every error a user can cause, in one hierarchy.

Each message is one line that names the problem and, where there is a choice, lists the
valid names. The command prints it as ``armtransfer COMMAND: error: MESSAGE`` and exits
with code 2; a library user catches ``ArmTransferError``. This module imports nothing of
the project, so every layer can raise these.
"""


class ArmTransferError(Exception):
    """Base class of every error caused by bad input."""


class InvalidCellError(ArmTransferError):
    """A cell is off the grid or inside a wall."""


class InvalidWorldError(ArmTransferError):
    """A world is unknown or its layout is malformed (ragged grid, no path from start to goal)."""


class InvalidTaskError(ArmTransferError):
    """A task is unknown or malformed (e.g. start equals goal)."""


class UnknownRobotError(ArmTransferError):
    """A robot or action model name is not known."""


class UnknownArmError(UnknownRobotError):
    """An arm or action model name is not known (the message lists the valid ones)."""


class InvalidActionError(ArmTransferError):
    """An action outside an environment's action spec."""


class ArmModelError(ArmTransferError):
    """An arm's MJCF cannot be used: unreadable, no hinge joints, missing tip site."""


class UnreachableTableError(ArmTransferError):
    """The arm's tool tip cannot reach any free cell of the table."""


class InvalidTrajectoryError(ArmTransferError):
    """A transferred trajectory is malformed or names cells off the grid."""


class InvalidParameterError(ArmTransferError):
    """A learning parameter is out of range (e.g. a farmable K, non-positive trials)."""


class InvalidMappingError(ArmTransferError):
    """An action sequence mapping file is malformed or made for another robot pair."""


class OutputError(ArmTransferError):
    """An output path cannot be written."""


class PluginError(ArmTransferError):
    """A transfer method from outside the package cannot be used: it fails to import, raises,
    returns the wrong shape or a non-finite number, or takes a name already taken."""


class MissingExtraError(ArmTransferError):
    """An optional dependency is not installed (the message names the extra that installs it)."""
