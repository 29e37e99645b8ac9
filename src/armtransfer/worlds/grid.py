"""A world drawn as a character grid: the text of a layout file becomes a :class:`Layout`.

The grid is square, its side odd, so that cell (0, 0) is its centre: a side of n gives
x, y in [-(n - 1) / 2, (n - 1) / 2]. The first row is the top (+y), as
:meth:`Layout.ascii` prints it. Characters:

    .   a free cell
    #   a wall cell
    D   a door: a free cell in a wall (walls and doors are drawn on the table alike)

Blank lines before and after the grid, and spaces at the ends of rows, are ignored.
"""

from __future__ import annotations

from armtransfer.errors import InvalidWorldError
from armtransfer.worlds.layout import Layout, NamedTask, WallSegment

FREE, WALL, DOOR = ".", "#", "D"
CHARACTERS = (FREE, WALL, DOOR)
MAX_SIDE = 201
"""The largest side a grid may have (the rooms world's is 51)."""


def grid_rows(text: str, where: str) -> list[str]:
    """The rows of a character grid, checked: square, odd side, known characters only."""
    rows = [row.strip() for row in text.strip("\n").splitlines()]
    while rows and not rows[0]:
        rows.pop(0)
    while rows and not rows[-1]:
        rows.pop()
    if not rows:
        raise InvalidWorldError(f"{where}: the grid is empty")
    for i, row in enumerate(rows, 1):
        bad = next((c for c in row if c not in CHARACTERS), None)
        if bad is not None:
            raise InvalidWorldError(f"{where}: unknown character {bad!r} in grid row {i}; valid characters: "
                                    f"'{FREE}' free, '{WALL}' wall, '{DOOR}' door")
    side = len(rows[0])
    for i, row in enumerate(rows, 1):
        if len(row) != side:
            raise InvalidWorldError(f"{where}: the grid is ragged: row {i} has {len(row)} cells, row 1 has {side}")
    if len(rows) != side:
        raise InvalidWorldError(f"{where}: the grid must be square: {len(rows)} rows of {side} cells")
    if side % 2 == 0 or not 3 <= side <= MAX_SIDE:
        raise InvalidWorldError(f"{where}: the grid's side must be odd, 3 to {MAX_SIDE} (cell (0, 0) is its "
                                f"centre), got {side}")
    return rows


def layout_from_rows(rows: list[str], name: str, tasks: tuple[NamedTask, ...] = ()) -> Layout:
    """The layout of checked grid rows (:func:`grid_rows`): walls as straight segments (runs
    along rows, single cells joined down columns), doors as free cells in them."""
    side = len(rows)
    lo = -(side - 1) // 2
    blocked = {(x + lo, lo + side - 1 - j) for j, row in enumerate(rows) for x, c in enumerate(row)
               if c in (WALL, DOOR)}
    doors = tuple(sorted((x + lo, lo + side - 1 - j) for j, row in enumerate(rows) for x, c in enumerate(row)
                         if c == DOOR))
    walls: list[WallSegment] = []
    single: set[tuple[int, int]] = set()
    for y in range(lo + side - 1, lo - 1, -1):  # runs along each row
        x = lo
        while x < lo + side:
            if (x, y) not in blocked:
                x += 1
                continue
            end = x
            while (end + 1, y) in blocked:
                end += 1
            if end > x:
                walls.append(((x, y), (end, y)))
            else:
                single.add((x, y))
            x = end + 1
    for x in range(lo, lo + side):  # the single cells, joined down each column
        y = lo + side - 1
        while y >= lo:
            if (x, y) not in single:
                y -= 1
                continue
            end = y
            while (x, end - 1) in single:
                end -= 1
            walls.append(((x, y), (x, end)))
            y = end - 1
    return Layout(lo=lo, hi=lo + side - 1, walls=tuple(walls), doors=doors, name=name, tasks=tasks)
