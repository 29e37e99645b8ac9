"""The paper's two grid robots: ``fine`` (1 cell per action) and ``coarse`` (2 cells).

Actions, in index order: forward (+y), backward (-y), right (+x), left (-x). The paper
names them F, B, R, L for the fine robot and 1, 2, 3, 4 for the coarse one (its example
trajectory moves +y with 1, -y with 2 and -x with 4). A move is blocked, and the robot
stays, when it would leave the grid or enter a wall, including any cell it passes over.
Grid robots' states are the free cells; their labels are those cells' ids.
"""

from __future__ import annotations

import numpy as np

from armtransfer.errors import UnknownRobotError
from armtransfer.worlds.layout import ROOMS, Layout
from armtransfer.tasks.robot import DiscreteRobot

DIRECTIONS = ((0, 1), (0, -1), (1, 0), (-1, 0))
GRID_ROBOTS = {"fine": (1, ("F", "B", "R", "L")), "coarse": (2, ("1", "2", "3", "4"))}


def _blocked_move(layout: Layout, x: int, y: int, dx: int, dy: int, k: int) -> tuple[int, int]:
    for step in range(1, k + 1):
        nx, ny = x + dx * step, y + dy * step
        if not layout.in_grid(nx, ny) or layout.is_wall(nx, ny):
            return x, y
    return x + dx * k, y + dy * k


def grid_robot(name: str, layout: Layout = ROOMS) -> DiscreteRobot:
    """Build the ``fine`` or ``coarse`` robot over ``layout``."""
    if name not in GRID_ROBOTS:
        raise UnknownRobotError(
            f"unknown grid robot {name!r}; valid names: {', '.join(sorted(GRID_ROBOTS))}"
        )
    k, action_names = GRID_ROBOTS[name]
    cells = np.flatnonzero(layout.free)
    index = np.full(layout.n_cells, -1, dtype=np.int32)
    index[cells] = np.arange(len(cells), dtype=np.int32)
    next_state = np.empty((len(cells), len(DIRECTIONS)), dtype=np.int32)
    wind_state = np.empty(len(cells), dtype=np.int32)
    for s, c in enumerate(cells):
        x, y = layout.xy(int(c))
        for a, (dx, dy) in enumerate(DIRECTIONS):
            next_state[s, a] = index[layout.cell(*_blocked_move(layout, x, y, dx, dy, k))]
        wind_state[s] = index[layout.cell(*_blocked_move(layout, x, y, 1, 0, 1))]
    return DiscreteRobot(
        name=name,
        next_state=next_state,
        wind_state=wind_state,
        label=cells.astype(np.int32),
        action_names=action_names,
        cell_step=k,
        canonical=index,
        layout=layout,
    )
