"""Errors of the arm layer; each message is one line (the CLI prints it and exits 2)."""

from tasks.errors import ArmTransferError, UnknownRobotError


class ArmModelError(ArmTransferError):
    """An arm's MJCF cannot be used: unreadable, no hinge joints, missing tip site."""


class UnknownArmError(UnknownRobotError):
    """An arm or action model name is not known (the message lists the valid ones)."""


class UnreachableTableError(ArmTransferError):
    """The arm's tool tip cannot reach any free cell of the table."""
