"""What every world must hold before anything runs on it: each task's start and goal on the
grid, free, apart, and joined by a path of free cells (one-cell moves, as the ``fine`` robot's)."""

from __future__ import annotations

from collections import deque

import numpy as np

from armtransfer.errors import InvalidWorldError
from armtransfer.worlds.layout import Layout


def check_world(layout: Layout, where: str) -> Layout:
    """``layout`` when every one of its tasks can be solved, else a one-line error naming the
    world (``where``), the task and the fault. A world needs at least one task."""
    if not layout.tasks:
        raise InvalidWorldError(f"{where}: the world has no task; give at least one (a name, a start and a goal)")
    names = [t[0] for t in layout.tasks]
    twice = next((n for n in names if names.count(n) > 1), None)
    if twice is not None:
        raise InvalidWorldError(f"{where}: task {twice!r} is given twice")
    for name, start, goal in layout.tasks:
        for what, (x, y) in (("start", start), ("goal", goal)):
            if not layout.in_grid(x, y):
                raise InvalidWorldError(f"{where}: task {name!r}: its {what} ({x},{y}) is off the grid; x and y "
                                        f"lie in [{layout.lo}, {layout.hi}]")
            if layout.is_wall(x, y):
                raise InvalidWorldError(f"{where}: task {name!r}: its {what} ({x},{y}) is in a wall")
        if start == goal:
            raise InvalidWorldError(f"{where}: task {name!r}: its start and goal are the same cell {start}")
        if distance(layout, start, goal) is None:
            raise InvalidWorldError(f"{where}: task {name!r}: no path of free cells from its start {start} to its "
                                    f"goal {goal}")
    return layout


def distance(layout: Layout, start: tuple[int, int], goal: tuple[int, int]) -> int | None:
    """The fewest one-cell moves (up, down, left, right over free cells) from start to goal,
    or None when there is no such path."""
    free = ~layout.wall_mask
    seen = np.zeros_like(free)
    lo = layout.lo
    queue = deque([(start, 0)])
    seen[start[1] - lo, start[0] - lo] = True
    while queue:
        (x, y), d = queue.popleft()
        if (x, y) == goal:
            return d
        for nx, ny in ((x + 1, y), (x - 1, y), (x, y + 1), (x, y - 1)):
            if layout.in_grid(nx, ny) and free[ny - lo, nx - lo] and not seen[ny - lo, nx - lo]:
                seen[ny - lo, nx - lo] = True
                queue.append(((nx, ny), d + 1))
    return None
