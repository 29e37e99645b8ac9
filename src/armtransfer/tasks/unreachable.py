"""What to try when a robot cannot reach a goal of a world other than the paper's rooms: the
next step a one-line error names (the rooms' own tasks are reachable by every built-in robot)."""

from __future__ import annotations

from armtransfer.tasks.robot import DiscreteRobot
from armtransfer.worlds.layout import ROOMS


def hint(robot: DiscreteRobot) -> str:
    """``"; ..."`` to append to "robot R cannot reach ...", or "" on the rooms: a robot moving
    several cells a move names the doors on odd cells it cannot pass (the even-cell rule of
    docs/worlds.md); an arm names ``arms list --world`` (its reach and the tasks it solves there)
    and ``--cell-size`` (the size of the table under it)."""
    layout = robot.layout
    if layout is ROOMS or layout == ROOMS:
        return ""
    out = ""
    if robot.cell_step > 1:
        odd = [d for d in layout.doors if d[0] % 2 or d[1] % 2]
        if odd:
            out += (f"; the door at {odd[0]} is on an odd cell, which {robot.name} (moving {robot.cell_step} cells "
                    f"from even cells) cannot pass: put doors and tasks on even cells, walls on odd ones "
                    "(docs/worlds.md, layout files)")
    if robot.arm is not None:
        out += (f"; `armtransfer arms list --world WORLD` shows each arm's reach and the tasks it solves on this "
                "world, and --cell-size (cell_size=) sets the size of the table under the arm (docs/worlds.md)")
    return out
