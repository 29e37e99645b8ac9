"""Start/goal tasks: the paper's Table I, a world's named tasks, and tasks given by coordinates."""

from __future__ import annotations

import numbers
from dataclasses import dataclass, field

from armtransfer.checks import integer_text
from armtransfer.errors import InvalidTaskError
from armtransfer.worlds.layout import ROOMS, Layout


@dataclass(frozen=True)
class Task:
    name: str
    start: tuple[int, int]
    goal: tuple[int, int]
    paper_distance: int | None = None
    """The optimal 1-cell distance Table I gives, where the task is one of the paper's."""
    layout: Layout = field(default=ROOMS, compare=False, repr=False)
    """The world the task is in (the paper's rooms unless it says otherwise)."""

    def cells(self, layout: Layout | None = None) -> tuple[int, int]:
        """(start cell id, goal cell id) in ``layout`` (the task's own world when None); both
        must be free and differ."""
        layout = self.layout if layout is None else layout
        s = layout.free_cell(*self.start, what="start")
        g = layout.free_cell(*self.goal, what="goal")
        if s == g:
            raise InvalidTaskError(f"start and goal are the same cell {self.start}")
        return s, g


TABLE_I = {
    1: Task("task 1", (0, 0), (-8, 12), 20),
    2: Task("task 2", (2, -2), (-12, 18), 34),
    3: Task("task 3", (2, 6), (-6, -6), 40),
    4: Task("task 4", (20, 18), (-22, -16), 76),
}
"""Table I of the paper: start in room 1; goal in room 2 (tasks 1, 2) or room 3 (3, 4)."""

TABLE_I_ROOMS = {1: (1, 2), 2: (1, 2), 3: (1, 3), 4: (1, 3)}


def table_task(number: int | str) -> Task:
    if number not in TABLE_I:
        raise InvalidTaskError(
            f"unknown task {number}; valid tasks: {', '.join(str(k) for k in TABLE_I)}"
        )
    return TABLE_I[number]


def parse_xy(text: str, what: str) -> tuple[int, int]:
    """Parse 'X,Y' into integers, with a one-line error naming ``what``."""
    parts = text.split(",") if isinstance(text, str) else []
    xy = [integer_text(p.strip()) for p in parts]
    if len(xy) != 2 or xy[0] is None or xy[1] is None:
        shown = text if not isinstance(text, str) or len(text) <= 80 else f"{text[:60]}... ({len(text)} characters)"
        raise InvalidTaskError(f"{what} must be two integers 'X,Y', got {shown!r}")
    return xy[0], xy[1]


def as_xy(value: object, what: str) -> tuple[int, int]:
    """A cell given as 'X,Y' or as two integers (numpy's included), with a one-line error."""
    if isinstance(value, str):
        return parse_xy(value, what)
    xy = list(value) if isinstance(value, (tuple, list)) else None
    if xy is None or len(xy) != 2 or any(isinstance(v, bool) or not isinstance(v, numbers.Integral) for v in xy):
        raise InvalidTaskError(f"{what} must be a cell of two integers (x, y), got {value!r}")
    return int(xy[0]), int(xy[1])


def world_task(layout: Layout, task: object = None) -> Task:
    """The task named ``task`` (a name, or a number for the paper's rooms) of the world
    ``layout``; its first task when None. Table I's tasks keep their paper distances."""
    if not layout.tasks:
        raise InvalidTaskError(f"world {layout.name or 'unnamed'} has no named task; give a start and a goal")
    if task is None:
        name = layout.tasks[0][0]
    elif isinstance(task, bool) or not isinstance(task, (str, numbers.Integral)):
        raise InvalidTaskError(f"a task is one of the world's task names, got {task!r}")
    else:
        name = str(task)
    if layout is ROOMS or layout == ROOMS:
        number = integer_text(name, signed=False)
        if number is not None:
            return table_task(number)  # the one-line error listing Table I's tasks when unknown
        raise InvalidTaskError(f"unknown task {name[:40]!r}; valid tasks: {', '.join(str(k) for k in TABLE_I)}")
    found = layout.task(name)
    if found is None:
        raise InvalidTaskError(f"unknown task {name[:40]!r} in world {layout.name}; valid tasks: "
                               f"{', '.join(t[0] for t in layout.tasks)}")
    return Task(f"task {found[0]}", found[1], found[2], layout=layout)


def world_tasks(layout: Layout) -> list[Task]:
    """Every named task of the world ``layout``, in order (Table I's on the rooms)."""
    return [world_task(layout, t[0]) for t in layout.tasks]


def custom_task(start: tuple[int, int], goal: tuple[int, int], layout: Layout = ROOMS) -> Task:
    task = Task(f"({start[0]},{start[1]})->({goal[0]},{goal[1]})", start, goal, layout=layout)
    task.cells(layout)  # validate now, so errors come before any work
    return task
