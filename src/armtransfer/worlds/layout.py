"""The rooms world: a 51 x 51 grid of cells, x, y in [-25, 25], four rooms and four doors.

The paper's Fig. 3 is not in its text, so this layout is designed here. It is chosen so
that the four tasks of Table I have exactly the paper's optimal distances for the 1-cell
robot (20, 34, 40, 76) with start and goal in the rooms Table I names (checked by a
breadth-first-search test). Walls sit on odd coordinates and doors on even ones, so the
2-cell robot, which lives on the even lattice of the Table I tasks, passes every door.

Rooms (x right, y forward):
  room 1: x >= -2,  y >= -6    (the start room of every Table I task)
  room 2: x <= -4,  y >= 4
  room 3: x <= -4,  y <= 2
  room 4: x >= -2,  y <= -8

Cells are numbered ``id = (y - lo) * width + (x - lo)``; this cell id is the shared
label space in which every robot (grid or arm) reports where it is.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from armtransfer.errors import InvalidCellError

# A wall is a straight segment of cells; a door is one free cell in it.
# ((x0, y0), (x1, y1)) with x0 == x1 or y0 == y1, both ends included.
WallSegment = tuple[tuple[int, int], tuple[int, int]]
# A named task of a world: (name, start cell, goal cell), cells as (x, y).
NamedTask = tuple[str, tuple[int, int], tuple[int, int]]


@dataclass(frozen=True)
class Layout:
    """A square grid of cells with wall segments and doors (all in cell coordinates)."""

    lo: int
    hi: int
    walls: tuple[WallSegment, ...]
    doors: tuple[tuple[int, int], ...]
    rooms: dict[int, tuple[int, int, int, int]] = field(default_factory=dict)
    """Room number -> (xmin, xmax, ymin, ymax), inclusive, for naming rooms in reports."""
    name: str = ""
    """The world's name (``rooms``, ``rooms11``, ``generated:7``, a layout file's name)."""
    tasks: tuple[NamedTask, ...] = ()
    """The world's named tasks, in order; the first is the default task."""

    def task(self, name: str) -> NamedTask | None:
        """The named task, or None when the world has none of that name."""
        return next((t for t in self.tasks if t[0] == name), None)

    @property
    def width(self) -> int:
        return self.hi - self.lo + 1

    @property
    def n_cells(self) -> int:
        return self.width * self.width

    @cached_property
    def wall_mask(self) -> np.ndarray:
        """Boolean array ``[y_index, x_index]``: True where a cell is a wall."""
        mask = np.zeros((self.width, self.width), dtype=bool)
        for (x0, y0), (x1, y1) in self.walls:
            if x0 != x1 and y0 != y1:
                raise ValueError(f"wall segment {(x0, y0)}-{(x1, y1)} is not straight")
            for x in range(min(x0, x1), max(x0, x1) + 1):
                for y in range(min(y0, y1), max(y0, y1) + 1):
                    mask[y - self.lo, x - self.lo] = True
        for x, y in self.doors:
            if not mask[y - self.lo, x - self.lo]:
                raise ValueError(f"door {(x, y)} is not in a wall")
            mask[y - self.lo, x - self.lo] = False
        mask.setflags(write=False)
        return mask

    @cached_property
    def free(self) -> np.ndarray:
        """Boolean array over cell ids: True where the cell is free (not a wall)."""
        free = ~self.wall_mask.reshape(-1)
        free.setflags(write=False)
        return free

    def in_grid(self, x: int, y: int) -> bool:
        return self.lo <= x <= self.hi and self.lo <= y <= self.hi

    def is_wall(self, x: int, y: int) -> bool:
        """True for a wall cell; (x, y) must be on the grid."""
        return bool(self.wall_mask[y - self.lo, x - self.lo])

    def ids_of(self, xy: np.ndarray) -> np.ndarray:
        """Vectorised :meth:`cell` over integer cells [..., 2]: the cell ids, -1 off the grid."""
        c = np.asarray(xy, dtype=np.int64)
        inside = np.all((c >= self.lo) & (c <= self.hi), axis=-1)
        ids = (c[..., 1] - self.lo) * self.width + (c[..., 0] - self.lo)
        return np.where(inside, ids, -1)

    def xy_of(self, ids: np.ndarray) -> np.ndarray:
        """Vectorised :meth:`xy` over cell ids: int64 [..., 2] of (x, y)."""
        y, x = np.divmod(np.asarray(ids, dtype=np.int64), self.width)
        return np.stack([x + self.lo, y + self.lo], axis=-1)

    def cell(self, x: int, y: int) -> int:
        """The cell id of (x, y); raises InvalidCellError off the grid."""
        if not self.in_grid(x, y):
            raise InvalidCellError(
                f"cell ({x},{y}) is off the grid: x and y must lie in [{self.lo}, {self.hi}]"
            )
        return (y - self.lo) * self.width + (x - self.lo)

    def xy(self, cell: int) -> tuple[int, int]:
        """The (x, y) of a cell id."""
        if not 0 <= cell < self.n_cells:
            raise InvalidCellError(f"cell id {cell} is outside 0..{self.n_cells - 1}")
        y, x = divmod(int(cell), self.width)
        return x + self.lo, y + self.lo

    def free_cell(self, x: int, y: int, what: str = "cell") -> int:
        """The cell id of (x, y), which must be on the grid and not a wall."""
        c = self.cell(x, y)
        if not self.free[c]:
            raise InvalidCellError(f"{what} ({x},{y}) is inside a wall")
        return c

    def room_of(self, x: int, y: int) -> int | None:
        for number, (x0, x1, y0, y1) in self.rooms.items():
            if x0 <= x <= x1 and y0 <= y <= y1:
                return number
        return None

    def ascii(self, marks: dict[tuple[int, int], str] | None = None) -> str:
        """Top-down text map, +y up: '#' wall, '.' free, and any marks given."""
        marks = marks or {}
        rows = []
        for y in range(self.hi, self.lo - 1, -1):
            row = []
            for x in range(self.lo, self.hi + 1):
                if (x, y) in marks:
                    row.append(marks[(x, y)])
                else:
                    row.append("#" if self.wall_mask[y - self.lo, x - self.lo] else ".")
            rows.append("".join(row))
        return "\n".join(rows)


ROOMS = Layout(
    lo=-25,
    hi=25,
    walls=(
        ((-3, -25), (-3, 25)),  # the vertical wall splitting west from east
        ((-25, 3), (-4, 3)),  # west: room 2 above, room 3 below
        ((-2, -7), (25, -7)),  # east: room 1 above, room 4 below
    ),
    doors=(
        (-3, 10),  # room 1 <-> room 2
        (-12, 3),  # room 2 <-> room 3
        (-3, -18),  # room 3 <-> room 4
        (14, -7),  # room 1 <-> room 4
    ),
    rooms={
        1: (-2, 25, -6, 25),
        2: (-25, -4, 4, 25),
        3: (-25, -4, -25, 2),
        4: (-2, 25, -25, -8),
    },
    name="rooms",
    tasks=(  # the paper's Table I (tasks.catalog.TABLE_I gives their distances)
        ("1", (0, 0), (-8, 12)),
        ("2", (2, -2), (-12, 18)),
        ("3", (2, 6), (-6, -6)),
        ("4", (20, 18), (-22, -16)),
    ),
)
"""The rooms world every experiment in this project runs in."""
