"""Four-room worlds drawn from a seed: ``generated:SEED`` (side 11) or ``generated:SEED:SIDE``.

Like the paper's rooms: one wall splits west from east, and each half is split again at its
own height, so there are four rooms and four one-cell doors in a ring; the walls lie in the middle half
of the grid, so that no room is thinner than a quarter of it. Walls
lie on odd coordinates and doors and tasks on even ones, so the ``coarse`` robot (two cells
a move, on the even cells) passes every door and reaches every task. Three tasks are drawn,
each from a cell of the room with the grid's centre to a cell in another room, the n-th
task's goal in the n-th other room. The same seed and side give the same world.
"""

from __future__ import annotations

import numpy as np

from armtransfer.checks import integer_text
from armtransfer.errors import InvalidWorldError
from armtransfer.worlds.check import check_world
from armtransfer.worlds.layout import Layout, NamedTask, WallSegment

PREFIX = "generated"
MAX_SEED = 10**18 - 1
"""The largest seed of a generated world (18 digits)."""
DEFAULT_SIDE = 11
SIDES = tuple(range(11, 52, 4))
"""Sides a generated world may have: 11, 15, ..., 51 (side = 4k + 3, so its edges are odd
and every room has even cells on both sides of each door)."""


def parse_generated(spec: str) -> tuple[int, int]:
    """``generated:SEED[:SIDE]`` -> (seed, side), with a one-line error."""
    parts = spec.split(":")
    usage = f"a generated world is {PREFIX}:SEED or {PREFIX}:SEED:SIDE (SIDE one of {', '.join(map(str, SIDES))})"
    numbers = [integer_text(p, signed=False) for p in parts[1:]]
    if parts[0] != PREFIX or len(parts) not in (2, 3) or any(n is None or n > MAX_SEED for n in numbers):
        shown = spec if len(spec) <= 80 else f"{spec[:60]}... ({len(spec)} characters)"
        raise InvalidWorldError(f"{usage}, SEED an integer 0..{MAX_SEED}, got {shown!r}")
    seed = numbers[0]
    side = numbers[1] if len(numbers) == 2 else DEFAULT_SIDE
    assert seed is not None and side is not None
    if side not in SIDES:
        raise InvalidWorldError(f"{usage}, got side {side}")
    return seed, side


def generated_world(seed: int, side: int = DEFAULT_SIDE) -> Layout:
    """The four-room world of ``seed`` and ``side`` (see the module's docstring)."""
    if side not in SIDES:
        raise InvalidWorldError(f"a generated world's side is one of {', '.join(map(str, SIDES))}, got {side}")
    rng = np.random.default_rng([seed, side])
    h = (side - 1) // 2  # cells run -h..h, h odd
    odd = [v for v in range(-h // 2, h // 2 + 1) if v % 2 != 0]  # wall lines in the middle half: no thin room
    x_wall = int(rng.choice(odd))
    y_west, y_east = (int(v) for v in rng.choice(odd, size=2))

    def door(lo: int, hi: int) -> int:
        return int(rng.choice([v for v in range(lo, hi + 1) if v % 2 == 0]))

    walls: tuple[WallSegment, ...] = (
        ((x_wall, -h), (x_wall, h)),
        ((-h, y_west), (x_wall - 1, y_west)),
        ((x_wall + 1, y_east), (h, y_east)),
    )
    doors = (  # a ring of four rooms, as the paper's: one door in each wall between two rooms
        (x_wall, door(max(y_west, y_east) + 1, h)),  # north-west <-> north-east
        (x_wall, door(-h, min(y_west, y_east) - 1)),  # south-west <-> south-east
        (door(-h, x_wall - 1), y_west),  # north-west <-> south-west
        (door(x_wall + 1, h), y_east),  # north-east <-> south-east
    )
    rooms = {
        1: (-h, x_wall - 1, y_west + 1, h),
        2: (x_wall + 1, h, y_east + 1, h),
        3: (-h, x_wall - 1, -h, y_west - 1),
        4: (x_wall + 1, h, -h, y_east - 1),
    }
    name = f"{PREFIX}:{seed}" if side == DEFAULT_SIDE else f"{PREFIX}:{seed}:{side}"
    plain = Layout(lo=-h, hi=h, walls=walls, doors=doors, rooms=rooms, name=name)
    home = plain.room_of(0, 0) or 1
    others = [r for r in rooms if r != home]
    tasks: list[NamedTask] = []
    for n, room in enumerate(others, 1):
        start = _even_cell(rng, rooms[home], plain)
        goal = _even_cell(rng, rooms[room], plain)
        tasks.append((str(n), start, goal))
    world = Layout(lo=-h, hi=h, walls=walls, doors=doors, rooms=rooms, name=name, tasks=tuple(tasks))
    return check_world(world, f"world {name!r}")


def _even_cell(rng: np.random.Generator, box: tuple[int, int, int, int], layout: Layout) -> tuple[int, int]:
    x0, x1, y0, y1 = box
    cells = [(x, y) for x in range(x0, x1 + 1) for y in range(y0, y1 + 1)
             if x % 2 == 0 and y % 2 == 0 and not layout.is_wall(x, y)]
    x, y = cells[int(rng.integers(len(cells)))]
    return x, y
